eomgen::model!("zero-to-the-zero.yaml");

fn main() {}
