//! Generated code is deterministic: two independent derivations of the same file print
//! byte-identical Rust (no hash-map iteration order reaches the output).

use eomgen_symbolic::codegen::plan::EmitPlans;
use eomgen_symbolic::codegen::{self, EmitOptions};
use eomgen_symbolic::mechanics::{Formulation, Lagrange, SymbolicModel};

fn generate(source: &str) -> String {
    let file = eomgen_symbolic::model::load("m.yaml", source).expect("loads");
    let mut model = SymbolicModel::from_file(&file).expect("lowers");
    let eom = Lagrange.derive(&mut model);
    let plans = EmitPlans::of(&model, &eom);
    let (tokens, stats) =
        codegen::emit(&model, &eom, &plans, &EmitOptions::default()).expect("emits");
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

/// Issue 28: a parameter or model named `self`, `Self`, `super` or `crate` passed the loader
/// and then the generated code did not compile. Every Rust keyword (strict, reserved, the
/// 2024 edition's `gen`) as the model's name, a parameter, a coordinate, a point or a body
/// either loads and generates code that parses, or is a located error of the loader that
/// names it: never accepted by `check` and rejected by the code generator.
#[test]
fn issue_28_every_rust_keyword_as_a_name_loads_and_generates_or_is_a_located_error() {
    use eomgen_symbolic::model::schema::RUST_KEYWORDS;
    let (mut accepted, mut refused) = (0, 0);
    for keyword in RUST_KEYWORDS {
        for role in ["name", "parameter", "coordinate", "point", "body"] {
            let pick = |r: &str, default: &str| {
                if r == role {
                    keyword.to_string()
                } else {
                    default.to_string()
                }
            };
            let (name, m, x, p, b) = (
                pick("name", "keyword_test"),
                pick("parameter", "m"),
                pick("coordinate", "x"),
                pick("point", "P"),
                pick("body", "bob"),
            );
            // The parameter is used in the mass and the coordinate in the potential, so that
            // both are bound as locals in the generated functions.
            let source = format!(
                "name: {name}\nparameters: {{ {m}: 1.0, k: 2.0 }}\ncoordinates: [{x}]\npoints: {{ {p}: [{x}, 0] }}\nbodies: {{ {b}: {{ mass: {m}, at: {p} }} }}\npotential: k*{x}^2/2 + {m}*{x}\n"
            );
            let case = format!("`{keyword}` as {role}");
            match eomgen_symbolic::model::load("m.yaml", &source) {
                Err(diagnostics) => {
                    refused += 1;
                    assert!(
                        diagnostics
                            .iter()
                            .any(|d| d.location.line >= 1
                                && d.message.contains(&format!("`{keyword}`"))),
                        "{case}: {diagnostics:?}"
                    );
                }
                Ok(file) => {
                    accepted += 1;
                    let tokens = codegen::generate(&file, &EmitOptions::default())
                        .unwrap_or_else(|e| panic!("{case}: {e:?}"));
                    if let Err(e) = syn::parse2::<syn::File>(tokens) {
                        panic!("{case}: the generated code does not parse: {e}");
                    }
                }
            }
        }
    }
    // Only the four keywords that are not raw identifiers, and names that are no
    // snake_case model name (`Self`), are refused.
    assert!(
        accepted > 4 * RUST_KEYWORDS.len(),
        "{accepted} accepted, {refused} refused"
    );
}
