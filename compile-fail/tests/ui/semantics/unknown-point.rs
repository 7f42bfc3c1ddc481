eomgen::model!("unknown-point.yaml");

fn main() {}
