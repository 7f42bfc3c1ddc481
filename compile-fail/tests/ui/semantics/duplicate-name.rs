eomgen::model!("duplicate-name.yaml");

fn main() {}
