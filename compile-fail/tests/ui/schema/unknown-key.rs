eomgen::model!("unknown-key.yaml");

fn main() {}
