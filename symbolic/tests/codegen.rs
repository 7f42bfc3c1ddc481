//! Generated code is deterministic: two independent derivations of the same file print
//! byte-identical Rust (no hash-map iteration order reaches the output).

use eomgen_symbolic::codegen::{self, EmitOptions};
use eomgen_symbolic::mechanics::{Formulation, Jacobians, Lagrange, SymbolicModel};

fn generate(source: &str) -> String {
    let file = eomgen_symbolic::model::load("m.yaml", source).expect("loads");
    let mut model = SymbolicModel::from_file(&file).expect("lowers");
    let eom = Lagrange.derive(&mut model);
    let jac = Jacobians::of(&mut model, &eom);
    let (tokens, stats) =
        codegen::emit(&model, &eom, &jac, &EmitOptions::default()).expect("emits");
    assert!(stats.ops_after_cse <= stats.ops_before_cse);
    tokens.to_string()
}

#[test]
fn generation_is_deterministic() {
    for source in [
        include_str!("../../models/double_pendulum.yaml"),
        include_str!("../../models/three_masses.yaml"),
        include_str!("../../models/two_masses.yaml"),
    ] {
        let a = generate(source);
        let b = generate(source);
        assert_eq!(a, b);
        assert!(a.contains("impl :: eomgen :: MechanicalSystem <"));
    }
}

/// Every trigonometric call of the double pendulum's right-hand side is one `sin_cos` per
/// angle: its equations need cos θ1, cos θ2 and both functions of θ1 − θ2, and the latter come
/// from the addition theorems (`expr::trig`), as in a hand-written double pendulum.
#[test]
fn one_sin_cos_per_angle_and_none_for_their_difference() {
    let code = generate(include_str!("../../models/double_pendulum.yaml"));
    let start = code
        .find("fn mass_matrix_and_forcing")
        .expect("function present");
    let end = code[start..]
        .find("fn forcing_jacobian_q")
        .map_or(code.len(), |e| start + e);
    let body = &code[start..end];
    for angle in ["theta1", "theta2"] {
        assert_eq!(
            body.matches(&format!("__private :: sin_cos ({angle})"))
                .count(),
            1,
            "{body}"
        );
    }
    assert_eq!(body.matches("__private :: sin_cos (").count(), 2, "{body}");
    assert!(!body.contains("__private :: sin ("), "{body}");
    assert!(!body.contains("__private :: cos ("), "{body}");
}
