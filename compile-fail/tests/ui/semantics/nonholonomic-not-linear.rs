eomgen::model!("nonholonomic-not-linear.yaml");

fn main() {}
