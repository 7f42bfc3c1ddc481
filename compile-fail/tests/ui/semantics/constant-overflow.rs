eomgen::model!("constant-overflow.yaml");

fn main() {}
