// A model file that is not even valid YAML still defines its model's name (read off its
// `name:` line), so the use below adds no error to the file's own.
eomgen::model!("../yaml-syntax/unclosed-bracket.yaml");

fn main() {
    let _model = Bad::default();
}
