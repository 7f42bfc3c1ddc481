eomgen::model!("unknown-frame.yaml");

fn main() {}
