eomgen::model!("unclosed-paren.yaml");

fn main() {}
