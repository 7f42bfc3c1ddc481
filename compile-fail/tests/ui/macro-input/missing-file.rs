eomgen::model!("no-such-model.yaml");

fn main() {}
