eomgen::model!("division-by-zero.yaml");

fn main() {}
