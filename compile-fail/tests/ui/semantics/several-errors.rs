eomgen::model!("several-errors.yaml");

fn main() {}
