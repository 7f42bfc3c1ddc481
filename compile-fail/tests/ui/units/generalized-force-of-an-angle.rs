eomgen::model!("generalized-force-of-an-angle.yaml");

fn main() {}
