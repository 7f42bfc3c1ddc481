eomgen::model!("spatial-amb-without-axis.yaml");

fn main() {}
