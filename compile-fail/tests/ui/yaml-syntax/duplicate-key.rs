eomgen::model!("duplicate-key.yaml");

fn main() {}
