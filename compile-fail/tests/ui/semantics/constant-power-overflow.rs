eomgen::model!("constant-power-overflow.yaml");

fn main() {}
