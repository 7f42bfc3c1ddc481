eomgen::model!("coordinate-in-no-energy.yaml");

fn main() {}
