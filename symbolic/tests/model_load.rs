//! The model loader on valid files, and never a panic on any input.

use eomgen_symbolic::mechanics::{Formulation, Jacobians, Lagrange, SymbolicModel};
use eomgen_symbolic::model::{BodyKind, Location, load};
use proptest::prelude::*;

const DOUBLE_PENDULUM: &str = include_str!("../../models/double_pendulum.yaml");

#[test]
fn double_pendulum_file_loads_with_locations_and_units() {
    let file = load("double_pendulum.yaml", DOUBLE_PENDULUM).expect("loads");
    assert_eq!(file.name.value, "double_pendulum");
    let coords: Vec<&str> = file
        .coordinates
        .iter()
        .map(|c| c.name.value.as_str())
        .collect();
    assert_eq!(coords, ["theta1", "theta2"]);
    assert_eq!(file.parameters[0].unit.as_deref(), Some("kg, upper arm"));
    assert_eq!(file.dimension, Some(2));
    assert_eq!(file.points.len(), 5);
    assert!(matches!(file.bodies[0].kind, BodyKind::Rigid { .. }));
    // `name:` is on the first line after the header comment.
    let line = DOUBLE_PENDULUM
        .lines()
        .position(|l| l.starts_with("name:"))
        .unwrap() as u32
        + 1;
    assert_eq!(file.name.location, Location { line, column: 7 });
}

#[test]
fn all_errors_of_a_file_are_reported_together() {
    let src = "name: x\ncoordinates: [q]\nkinetic: q_dot^2/2 + a\npotential: b\nbogus: 1\n";
    let errors = load("x.yaml", src).unwrap_err();
    // Schema errors come first (the unknown key); semantic ones need a clean schema pass.
    assert_eq!(errors.len(), 1, "{errors:?}");
    let src = "name: x\ncoordinates: [q]\nkinetic: q_dot^2/2 + a\npotential: b\n";
    let errors = load("x.yaml", src).unwrap_err();
    let at: Vec<(u32, u32)> = errors
        .iter()
        .map(|d| (d.location.line, d.location.column))
        .collect();
    assert_eq!(at, [(3, 22), (4, 12)]);
}

fn pipeline(src: &str) {
    if let Ok(file) = load("fuzz.yaml", src) {
        if let Ok(mut model) = SymbolicModel::from_file(&file) {
            let eom = Lagrange.derive(&mut model);
            let _ = Jacobians::of(&mut model, &eom);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, .. ProptestConfig::default() })]

    /// Arbitrary text never panics the loader.
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
