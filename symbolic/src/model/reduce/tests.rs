//! The unit tests of `reduce.rs`.

use super::*;

fn load(text: &str) -> ModelFile {
    crate::model::load("test.yaml", text).unwrap_or_else(|d| panic!("{d:?}"))
}

const PENDULUM: &str = "name: p\nparameters: { m: 1.0, l: 2.0, g: 10.0 }\ncoordinates: [x, y]\n\
    points: { O: [0, 0], P: [x, y] }\nbodies: { bob: { mass: m, at: P } }\ngravity: [0, -g]\n\
    constraints: { rod: sqrt(x^2 + y^2) - l }\ninitial: { x: l, y: 0 }\n\
    equilibria: { hanging: { x: 0, y: -l }, upright: { x: 0, y: l } }\n";

/// The rod is squared, and the branch comes from the hanging equilibrium (the start
/// `x = ℓ` is where the branches meet): `y = −√(ℓ² − x²)`. That start is singular for
/// the reduced file, which needs another.
#[test]
fn pendulum_keep_x_takes_the_hanging_branch() {
    let err = reduce(&load(PENDULUM), &["x"], &ReduceOptions::default()).unwrap_err();
    assert!(
        matches!(&err, ReduceError::SingularStart { detail } if detail.contains("l^2 - x^2")),
        "{err}"
    );
    let options = ReduceOptions {
        initial: vec![("x".into(), "l/2".into())],
        ..ReduceOptions::default()
    };
    let r = reduce(&load(PENDULUM), &["x"], &options).unwrap();
    let e = &r.eliminations[0];
    assert_eq!(e.solution, "-sqrt(l^2 - x^2)");
    assert!(e.squared);
    assert_eq!(
        e.branch,
        Some((Branch::Minus, BranchReason::Equilibrium("hanging".into())))
    );
    assert!(
        r.notes.iter().any(|n| n.contains("upright")),
        "{:?}",
        r.notes
    );
}

/// Keeping y from the start x = ℓ, y = 0 gives x = +√(ℓ² − y²) by the initial state.
#[test]
fn pendulum_keep_y_takes_the_initial_branch() {
    let r = reduce(&load(PENDULUM), &["y"], &ReduceOptions::default()).unwrap();
    let e = &r.eliminations[0];
    assert_eq!(e.solution, "sqrt(l^2 - y^2)");
    assert_eq!(e.branch, Some((Branch::Plus, BranchReason::InitialState)));
}

#[test]
fn transcendental_constraint_is_a_clear_error() {
    let text = PENDULUM.replace("sqrt(x^2 + y^2) - l", "y - l*sin(x + y)");
    let err = reduce(&load(&text), &["x"], &ReduceOptions::default()).unwrap_err();
    let ReduceError::Unsolvable {
        constraint,
        coordinate,
        ..
    } = &err
    else {
        panic!("{err}")
    };
    assert_eq!((constraint.as_str(), coordinate.as_str()), ("rod", "y"));
    assert!(err.to_string().contains("sin("), "{err}");
}
