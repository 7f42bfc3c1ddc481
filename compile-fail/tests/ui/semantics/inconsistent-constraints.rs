eomgen::model!("inconsistent-constraints.yaml");

fn main() {}
