eomgen::model!("rotation-bad-axis.yaml");

fn main() {}
