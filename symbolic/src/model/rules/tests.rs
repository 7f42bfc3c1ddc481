//! The unit tests of `rules.rs`.

use super::*;

use crate::model::{schema, yaml};

fn errors(src: &str) -> Vec<String> {
    let root = yaml::parse(src).unwrap();
    let file = schema::build("t.yaml", src, &root).unwrap();
    match check(&file) {
        Ok(()) => Vec::new(),
        Err(d) => d
            .iter()
            .map(|d| format!("{}: {}", d.location, d.message))
            .collect(),
    }
}

const HEAD: &str = "name: a\nparameters: { m: 1, l: 2 }\ncoordinates: [q]\n";

#[test]
fn a_valid_model_passes() {
    let src = format!(
        "{HEAD}points: {{ O: [0, 0], P: [l*sin(q), -l*cos(q)] }}\nbodies: {{ bob: {{ mass: m, at: P }} }}\ngravity: [0, -9.81]\ninitial: {{ q: pi/4, q_dot: 0 }}\n"
    );
    assert_eq!(errors(&src), Vec::<String>::new());
}

#[test]
fn dependencies_are_enforced() {
    let src =
        format!("{HEAD}kinetic: m*q_dot^2/2 + q_ddot\npotential: q_dot\ninitial: {{ q: l*q }}\n");
    assert_eq!(
        errors(&src),
        [
            "4:24: accelerations such as `q_ddot` cannot appear in a model file",
            "5:12: `potential` cannot depend on the rate `q_dot`",
            "6:17: the initial value of `q` must be constant, but it uses the coordinate `q`",
        ]
    );
}

#[test]
fn reserved_and_duplicate_names() {
    let src = "name: a\nparameters: { t: 1, q: 2, sin: 3, x_dot: 4 }\ncoordinates: [q]\nkinetic: q_dot^2\n";
    assert_eq!(
        errors(src),
        [
            "2:15: parameter name `t` is reserved: `t` is time",
            "2:27: parameter name `sin` is reserved: `sin` is a function",
            "2:35: parameter name `x_dot` ends in `_dot` or `_ddot`, which spell rates",
            "3:15: duplicate name `q`: already a parameter at 2:21",
        ]
    );
}

/// Issue 28: the keywords that are not raw identifiers cannot name a parameter, a
/// coordinate or (as `Self`) the model; any other keyword can, and any name a point.
#[test]
fn keywords_that_generated_code_cannot_spell_are_reserved() {
    let src = "name: self\nparameters: { super: 1, type: 2 }\ncoordinates: [crate, Self]\npoints: { self: [crate, Self] }\nkinetic: crate_dot^2 + Self_dot^2\n";
    assert_eq!(
        errors(src),
        [
            "1:7: model name `self` is reserved: its struct would be `Self`, a Rust keyword",
            "2:15: parameter name `super` is reserved: `super` is a Rust keyword, which generated code cannot use as a name (not even as `r#super`)",
            "3:15: coordinate name `crate` is reserved: `crate` is a Rust keyword, which generated code cannot use as a name (not even as `r#crate`)",
            "3:22: coordinate name `Self` is reserved: `Self` is a Rust keyword, which generated code cannot use as a name (not even as `r#Self`)",
        ]
    );
}

#[test]
fn the_evaluator_uses_parameter_defaults() {
    let src = "name: a\nparameters: { m: 2, l: 3 }\ncoordinates: [q]\nkinetic: q_dot^2\n";
    let root = yaml::parse(src).unwrap();
    let file = schema::build("t.yaml", src, &root).unwrap();
    let e = crate::model::parser::parse_expr("m*l^2/12 + cos(pi)", Location::default()).unwrap();
    assert_eq!(evaluate(&e, &file.parameters), Some(2.0 * 9.0 / 12.0 - 1.0));
    let e = crate::model::parser::parse_expr("m*q", Location::default()).unwrap();
    assert_eq!(evaluate(&e, &file.parameters), None);
}

#[test]
fn masses_and_inertias() {
    let src = format!(
        "{HEAD}points: {{ P: [q, 0] }}\nbodies:\n  a: {{ mass: m - 1, at: P }}\n  b: {{ mass: m, inertia: -l, com: P, angle: q }}\n"
    );
    assert_eq!(
        errors(&src),
        [
            "6:14: body `a` has non-positive mass `0.0` (kg)",
            "7:26: body `b` has negative inertia `-2.0` (kg·m²)",
        ]
    );
}

/// A 3-D inertia whose largest principal moment exceeds the sum of the others (beyond 0.1 %) is refused,
/// also when products of inertia hide it (`diag(1, 1, 3)` rotated by 30° about `x`); a
/// flat body's (`I₃ = I₁ + I₂`, here `diag(1, 2, 3)` rotated) and an ordinary one pass.
#[test]
fn an_inertia_breaking_the_triangle_inequality_is_refused() {
    let body = |inertia: &str| {
        format!(
            "name: t\nparameters: {{ m: 1.0 }}\ncoordinates: [psi]\nframes:\n  B: {{ parent: N, axis: z, angle: psi }}\npoints:\n  G: [0, 0, 0]\nbodies:\n  disc: {{ mass: m, com: G, frame: B, inertia: {inertia} }}\n"
        )
    };
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    // diag(1, 1, 3) rotated about x: yy = c²·1 + s²·3, zz = s²·1 + c²·3, yz = (3 − 1)cs.
    let hidden = format!(
        "{{ xx: 1, yy: {}, zz: {}, yz: {} }}",
        c * c + 3.0 * s * s,
        s * s + 3.0 * c * c,
        2.0 * c * s
    );
    for inertia in ["{ xx: 1, yy: 1, zz: 3 }", hidden.as_str()] {
        let found = errors(&body(inertia));
        assert!(
            found.len() == 1 && found[0].contains("triangle inequality I₃ ≤ I₁ + I₂"),
            "{inertia}: {found:?}"
        );
    }
    let flat = format!(
        "{{ xx: 1, yy: {}, zz: {}, yz: {} }}",
        2.0 * c * c + 3.0 * s * s,
        2.0 * s * s + 3.0 * c * c,
        c * s
    );
    for inertia in [
        "{ xx: 1, yy: 2, zz: 3 }",
        "{ xx: 2, yy: 2, zz: 3 }",
        flat.as_str(),
    ] {
        assert_eq!(errors(&body(inertia)), Vec::<String>::new(), "{inertia}");
    }
}

/// Definiteness judged on the tensor scaled by its largest entry: `diag(1e300, 1e300,
/// 1e300)`, `diag(1e-300, …)` and needles whose axial moment is 1e-12 of the others (along
/// `x`, and rotated by 30° about `z`) are positive definite (before, each was refused: the
/// minors overflowed, underflowed or sat at a threshold of 1e-12 of the largest entry). A
/// rotated zero moment, `diag(0, 1, 1)` turned by 30°, is refused with its entries in six
/// digits; a NaN entry is named as not finite (before, skipped here and reported later as a
/// singular mass matrix).
#[test]
fn inertias_are_judged_at_their_own_scale() {
    let body = |inertia: &str| {
        format!(
            "name: t\nparameters: {{ m: 1.0, z: 0.0 }}\ncoordinates: [psi]\nframes:\n  B: {{ parent: N, axis: z, angle: psi }}\npoints:\n  G: [0, 0, 0]\nbodies:\n  disc: {{ mass: m, com: G, frame: B, inertia: {inertia} }}\n"
        )
    };
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    // diag(a, 1, 1) rotated about z: xx = c²a + s², yy = s²a + c², xy = (a − 1)cs.
    let rotated = |a: f64| {
        format!(
            "{{ xx: {:e}, yy: {:e}, zz: 1, xy: {:e} }}",
            c * c * a + s * s,
            s * s * a + c * c,
            (a - 1.0) * c * s
        )
    };
    for inertia in [
        "[1e300, 1e300, 1e300]".to_string(),
        "[1e-300, 1e-300, 1e-300]".to_string(),
        "[1e-12, 1, 1]".to_string(),
        "[1e-14, 1, 1]".to_string(),
        rotated(1e-12),
    ] {
        assert_eq!(errors(&body(&inertia)), Vec::<String>::new(), "{inertia}");
    }
    let found = errors(&body(&rotated(0.0)));
    assert!(
        found.len() == 1 && found[0].contains("is not positive definite: [[0.25, -0.433013, 0]"),
        "{found:?}"
    );
    let found = errors(&body("[z/z, 1, 1]"));
    assert!(
        found.len() == 1 && found[0].contains("is not finite: its entry xx is NaN"),
        "{found:?}"
    );
}
