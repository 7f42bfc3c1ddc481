eomgen::model!("unknown-name.yaml");

fn main() {}
