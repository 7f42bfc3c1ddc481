eomgen::model!("too-many-constraints.yaml");

fn main() {}
