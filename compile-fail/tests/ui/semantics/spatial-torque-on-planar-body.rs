eomgen::model!("spatial-torque-on-planar-body.yaml");

fn main() {}
