eomgen::model!("rate-of-a-parameter.yaml");

fn main() {}
