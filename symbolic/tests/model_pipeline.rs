//! Loaded models go on through lowering and derivation without a panic, whatever the edits.

use eomgen_symbolic::mechanics::{Formulation, Jacobians, Lagrange, SymbolicModel};
use eomgen_symbolic::model::load;
use proptest::prelude::*;

const DOUBLE_PENDULUM: &str = include_str!("fixtures/double_pendulum.yaml");

fn pipeline(src: &str) {
    if let Ok(file) = load("fuzz.yaml", src)
        && let Ok(mut model) = SymbolicModel::from_file(&file)
    {
        let eom = Lagrange.derive(&mut model);
        let _ = Jacobians::of(&mut model, &eom);
    }
}

#[test]
fn the_double_pendulum_lowers_without_errors() {
    let file = load("double_pendulum.yaml", DOUBLE_PENDULUM).expect("loads");
    assert!(SymbolicModel::from_file(&file).is_ok());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, .. ProptestConfig::default() })]

    /// Arbitrary text never panics the loader, lowering or derivation.
    #[test]
    fn arbitrary_text_never_panics(src in "\\PC{0,200}") {
        pipeline(&src);
    }

    /// Random edits of a valid model never panic load, lowering or derivation.
    #[test]
    fn edited_model_never_panics(edits in prop::collection::vec((0usize..2000, prop::sample::select(vec!["", "[", "]", "{", "}", ":", "-", "*", "^", "(", ")", "x", "theta1", "0", "#", "\n", " ", "'", "\"", "&a", "*a", "/0"])), 1..6)) {
        let mut src = DOUBLE_PENDULUM.to_string();
        for (pos, text) in edits {
            let mut p = pos % (src.len() + 1);
            while !src.is_char_boundary(p) { p -= 1; }
            src.insert_str(p, text);
        }
        pipeline(&src);
    }
}
