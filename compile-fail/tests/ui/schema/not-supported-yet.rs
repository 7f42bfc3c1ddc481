eomgen::model!("not-supported-yet.yaml");

fn main() {}
