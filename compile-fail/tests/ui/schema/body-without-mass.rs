eomgen::model!("body-without-mass.yaml");

fn main() {}
