eomgen::model!("spring-stiffness-in-newtons.yaml");

fn main() {}
