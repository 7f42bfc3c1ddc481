eomgen::model!("wrong-arity.yaml");

fn main() {}
