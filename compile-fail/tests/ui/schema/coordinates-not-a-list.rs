eomgen::model!("coordinates-not-a-list.yaml");

fn main() {}
