eomgen::model!("sum-of-unlike-units.yaml");

fn main() {}
