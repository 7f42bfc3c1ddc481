eomgen::model!(models / double_pendulum);

fn main() {}
