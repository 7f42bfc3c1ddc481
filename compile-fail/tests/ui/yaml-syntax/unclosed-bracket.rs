eomgen::model!("unclosed-bracket.yaml");

fn main() {}
