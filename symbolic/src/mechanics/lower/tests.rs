//! The unit tests of `lower.rs`.

use super::*;

/// `equilibria:` (coordinates, rates and ignorable coordinates) and `{ guess: … }` map to
/// their coordinates by name, in any order.
#[test]
fn equilibria_and_guesses_go_to_their_coordinates() {
    let src = "name: x\nparameters: { m: 1.0 }\ncoordinates: [a, b, c]\npoints: { P: [a, b], Q: [c, 0] }\nbodies: { p: { mass: m, at: P }, q: { mass: m, at: Q } }\nconstraints:\n  k: a + b + c - 6\ninitial: { a: 1, c: { guess: 3 }, b: { guess: 2 } }\nequilibria:\n  e: { c: 3, a: 1 }\n  s: { b_dot: 2, a: 1, ignorable: [c] }\n";
    let file = crate::model::load("m.yaml", src).expect("loads");
    let model = SymbolicModel::from_file(&file).unwrap();
    assert_eq!(model.initial_guesses, [2, 1]);
    let numbers = |values: &[ExprId]| -> Vec<Option<f64>> {
        values
            .iter()
            .map(|e| model.arena.as_constant(*e).map(Constant::to_f64))
            .collect()
    };
    let e = &model.equilibria[0];
    assert_eq!(
        (e.name.as_str(), numbers(&e.guess)),
        ("e", vec![Some(1.0), Some(0.0), Some(3.0)])
    );
    // A steady motion: its rates go to their coordinates, and its ignorable coordinates.
    let s = &model.equilibria[1];
    assert_eq!(numbers(&s.guess), [Some(1.0), Some(0.0), Some(0.0)]);
    assert_eq!(numbers(&s.rates), [Some(0.0), Some(2.0), Some(0.0)]);
    assert_eq!(s.ignorable, [2]);
    assert!(model.has_steady_motions());
}
