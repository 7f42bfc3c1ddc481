eomgen::model!("event-unknown-name.yaml");

fn main() {}
