eomgen::model!("inertia-not-positive-definite.yaml");

fn main() {}
