eomgen::model!("event-direction.yaml");

fn main() {}
