eomgen::model!("mass-matrix-singular-at-start.yaml");

fn main() {}
