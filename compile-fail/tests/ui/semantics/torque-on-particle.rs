eomgen::model!("torque-on-particle.yaml");

fn main() {}
