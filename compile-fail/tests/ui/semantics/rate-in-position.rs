eomgen::model!("rate-in-position.yaml");

fn main() {}
