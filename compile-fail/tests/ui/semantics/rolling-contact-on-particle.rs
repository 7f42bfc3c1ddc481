eomgen::model!("rolling-contact-on-particle.yaml");

fn main() {}
