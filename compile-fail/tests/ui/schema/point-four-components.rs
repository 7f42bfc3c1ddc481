eomgen::model!("point-four-components.yaml");

fn main() {}
