eomgen::model!("mass-matrix-singular-everywhere.yaml");

fn main() {}
