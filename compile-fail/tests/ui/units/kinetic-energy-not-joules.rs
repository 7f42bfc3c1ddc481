eomgen::model!("kinetic-energy-not-joules.yaml");

fn main() {}
