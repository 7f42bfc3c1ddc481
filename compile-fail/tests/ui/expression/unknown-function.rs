eomgen::model!("unknown-function.yaml");

fn main() {}
