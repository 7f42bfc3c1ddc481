eomgen::model!("redundant-constraint.yaml");

fn main() {}
