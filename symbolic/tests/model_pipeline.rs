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

/// An equation of motion written by hand must be linear in the accelerations: lowering
/// rejects `x_ddot^2` and `x_ddot*y_ddot` at the entry's location, and accepts a linear
/// equation written with a product that only cancels after expansion.
#[test]
fn hand_equations_must_be_linear_in_accelerations() {
    let head = "name: a\nparameters: { m: 1.0, k: 1.0 }\ncoordinates: [x, y]\nkinetic: m*(x_dot^2 + y_dot^2)/2\npotential: k*(x^2 + y^2)/2\nchecks:\n  equations_of_motion:\n";
    let bad =
        format!("{head}    - m*x_ddot^2 + k*x = 0\n    - m*y_ddot + k*y + x_ddot*y_ddot = 0\n");
    let file = load("a.yaml", &bad).expect("loads");
    let errors = SymbolicModel::from_file(&file).unwrap_err();
    let found: Vec<String> = errors
        .iter()
        .map(|d| format!("{}: {}", d.location, d.message))
        .collect();
    assert_eq!(
        found,
        [
            "8:7: this equation of motion is not linear in the accelerations",
            "9:7: this equation of motion is not linear in the accelerations"
        ]
    );
    let good =
        format!("{head}    - (x_ddot + 1)^2 - x_ddot^2 + 2*k*x/m - 1 = 0\n    - m*y_ddot = -k*y\n");
    let file = load("a.yaml", &good).expect("loads");
    assert!(SymbolicModel::from_file(&file).is_ok());
}
