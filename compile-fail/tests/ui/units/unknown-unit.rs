eomgen::model!("unknown-unit.yaml");

fn main() {}
