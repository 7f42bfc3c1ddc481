eomgen::model!("hand-equation-not-linear.yaml");

fn main() {}
