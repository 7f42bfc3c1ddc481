eomgen::model!("missing-operand.yaml");

fn main() {}
