eomgen::model!("parameter-without-unit.yaml");

fn main() {}
