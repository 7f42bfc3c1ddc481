eomgen::model!("rigid-body-in-3d.yaml");

fn main() {}
