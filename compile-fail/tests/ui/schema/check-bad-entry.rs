eomgen::model!("check-bad-entry.yaml");

fn main() {}
