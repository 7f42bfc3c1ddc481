eomgen::model!("minimal-twin-itself.yaml");

fn main() {}
