eomgen::model!("negative-mass.yaml");

fn main() {}
