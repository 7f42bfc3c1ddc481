eomgen::model!("cos-of-a-length.yaml");

fn main() {}
