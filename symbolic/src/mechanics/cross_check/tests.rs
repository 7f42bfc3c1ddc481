//! The unit tests of `cross_check.rs`.

use super::*;

/// The text of the bundled model `name` (`models/` beside the package that builds these tests).
fn source(name: &str) -> String {
    let path = format!("{}/../models/{name}.yaml", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(path).unwrap()
}

fn model(name: &str) -> SymbolicModel {
    let file = crate::model::load("m.yaml", &source(name)).unwrap();
    SymbolicModel::from_file(&file).unwrap()
}

/// The comparison is the oracle of every derivation, so it must see a wrong one: on the
/// double pendulum, Lagrange's equations agree with momentum balance and the power
/// balance holds to rounding (below 1e-12), and with `F₂` scaled by 1.01 (a 1 % error in
/// one term, as a dropped or wrong term would give) both fail by more than 1e-5, well
/// above `check`'s 1e-8.
#[test]
fn the_sampled_comparison_sees_a_one_percent_error_in_one_equation() {
    let mut m = model("double_pendulum");
    let lagrange = Lagrange.derive(&mut m);
    let momentum = MomentumBalance.derive(&mut m);
    let others = vec![("momentum".to_string(), momentum)];
    let right = sample_states(&mut m, &lagrange, &others, 30, 3);
    assert_eq!(right.states.compared, 30);
    assert!(right.quadratic);
    assert!(
        right.max_rel[0] < 1e-12 && right.power_rel < 1e-12,
        "{right:?}"
    );

    // Relative to the size of q̈: with g = 1e6, q̈ ~ 1e6, and the differences of rounding
    // (~1e-10 absolute) between equations and their multiple are still ~1e-16 relative.
    let source = source("double_pendulum");
    let heavy = source.replace("  g: 10.0 ", "  g: 1e6  ");
    assert_ne!(heavy, source);
    let file = crate::model::load("m.yaml", &heavy).unwrap();
    let mut h = SymbolicModel::from_file(&file).unwrap();
    let hl = Lagrange.derive(&mut h);
    // The same equations times 7.1: equal q̈ up to rounding.
    let factor = h.arena.float(7.1);
    let mut scaled = hl.clone();
    for e in scaled
        .mass_matrix
        .iter_mut()
        .chain(scaled.forcing.iter_mut())
    {
        *e = h.arena.times(factor, *e);
    }
    let found = sample_states(&mut h, &hl, &[("scaled".to_string(), scaled)], 30, 3);
    assert!(
        found.max_rel[0] < 1e-12 && found.power_rel < 1e-12,
        "{found:?}"
    );

    let mut wrong = lagrange.clone();
    let factor = m.arena.float(1.01);
    wrong.forcing[1] = m.arena.times(factor, wrong.forcing[1]);
    let found = sample_states(&mut m, &wrong, &others, 30, 3);
    assert!(
        found.max_rel[0] > 1e-5 && found.power_rel > 1e-5,
        "{found:?}"
    );
    // The other way round: a wrong other derivation, the right Lagrange.
    let mut bad_other = others.clone();
    bad_other[0].1.forcing[0] = m.arena.times(factor, bad_other[0].1.forcing[0]);
    let found = sample_states(&mut m, &lagrange, &bad_other, 30, 3);
    assert!(
        found.max_rel[0] > 1e-5 && found.power_rel < 1e-12,
        "{found:?}"
    );
}

/// A singular `M′` of the other derivation is an infinite residual, not a skipped state;
/// a singular Lagrange `M` skips the state.
#[test]
fn a_singular_mass_matrix_is_infinite_or_skipped() {
    let mut m = model("double_pendulum");
    let lagrange = Lagrange.derive(&mut m);
    let mut singular = lagrange.clone();
    singular.mass_matrix = vec![m.arena.int(0); 4];
    let found = sample_states(
        &mut m,
        &lagrange,
        &[("x".to_string(), singular.clone())],
        5,
        1,
    );
    assert!(
        found.max_rel[0].is_infinite() && found.states.compared == 5,
        "{found:?}"
    );
    let found = sample_states(&mut m, &singular, &[("x".to_string(), lagrange)], 5, 1);
    assert_eq!((found.states.compared, found.states.singular), (0, 5));
}

/// Parameters are drawn within ±10 % of their defaults: `M = sqrt(m − 0.6) sqrt(1.2 − m)`
/// is real for m = 1 ± 10 % (not for m + 1, nor for the [0.1, 0.5] of a zero default), so
/// every state is compared and no note says otherwise; time in `V` alone skips the power
/// balance, with its note.
#[test]
fn parameters_near_their_defaults_and_explicit_time() {
    let base = "name: p\nparameters: { m: 1.0, k: 2.0 }\ncoordinates: [x]\nkinetic: sqrt(m - 0.6)*sqrt(1.2 - m)*x_dot^2/2\npotential: k*x^2/2\ninitial: { x: 1 }\n";
    let file = crate::model::load("m.yaml", base).unwrap();
    let report = check_model(&file, 20, 1).unwrap();
    assert!(
        report.states.compared == 20 && report.notes.iter().all(|n| !n.contains("states")),
        "{:?}",
        report.notes
    );
    assert!(report.power_balance.unwrap().max_rel_residual < 1e-12);
    let timed = base.replace("potential: k*x^2/2", "potential: k*x^2/2*(2 + cos(t))");
    let file = crate::model::load("m.yaml", &timed).unwrap();
    let report = check_model(&file, 20, 1).unwrap();
    assert!(report.power_balance.is_none());
    assert!(
        report
            .notes
            .iter()
            .any(|n| n == "power balance skipped: T or V depends explicitly on t"),
        "{:?}",
        report.notes
    );
    // M = m [[1, 1], [1, 1]] is singular at every state (only x + y carries inertia). With
    // the constraint `x − y` the KKT system is regular, and the derivations are compared
    // through it (as a model in Euler parameters is); with `x + y − 1`, which constrains the
    // direction that has inertia, it is singular too: nothing to compare, the note says so
    // and the check fails.
    let constrained = "name: s\nparameters: { m: 1.0 }\ncoordinates: [x, y]\npoints: { P: [x + y, 0] }\nbodies: { b: { mass: m, at: P } }\nconstraints:\n  same: x - y\n";
    let file = crate::model::load("m.yaml", constrained).unwrap();
    let report = check_model(&file, 5, 1).unwrap();
    assert_eq!(report.states.compared, 5, "{report:?}");
    let stuck = constrained.replace("same: x - y", "same: x + y - 1");
    let file = crate::model::load("m.yaml", &stuck).unwrap();
    let report = check_model(&file, 5, 1).unwrap();
    let reason = report.states.nothing_compared().expect("nothing compared");
    assert!(
        reason.starts_with("no state compared: of 5 random states")
            && reason.contains("5 had a singular Lagrange M"),
        "{reason}"
    );
    assert!(!report.passed(1e-8), "{report:?}");
}

/// `T` with a term linear in the rate (a point carried by a prescribed motion has one) is
/// not a quadratic form: the power balance is then skipped, with a note.
#[test]
fn a_kinetic_energy_linear_in_the_rates_skips_the_power_balance() {
    let source = "name: lin\nparameters: { m: 1.0, c: 0.5, k: 2.0 }\ncoordinates: [x]\nkinetic: m*x_dot^2/2 + c*x*x_dot + c^2\npotential: k*x^2/2\ninitial: { x: 1 }\n";
    let file = crate::model::load("m.yaml", source).unwrap();
    let report = check_model(&file, 10, 1).unwrap();
    assert!(report.power_balance.is_none(), "{report:?}");
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("not a quadratic form"))
    );
    let quadratic = source.replace(" + c*x*x_dot + c^2", "");
    let file = crate::model::load("m.yaml", &quadratic).unwrap();
    let report = check_model(&file, 10, 1).unwrap();
    let p = report.power_balance.expect("checked");
    assert!(p.max_rel_residual < 1e-12, "{p:?}");
}

/// The constraint tested is the right row when holonomic ones come first (a knife edge
/// after `y = 2x`; the test is made in the full space of (q, t), where the knife edge is
/// not integrable, although on `y = 2x` it would be), and with two coordinates (three
/// variables with t) the test is made:
/// `ẋ − t ẏ` is not integrable (ω ∧ dω = dx ∧ dy ∧ dt).
#[test]
fn integrability_after_holonomic_constraints_and_in_two_coordinates() {
    let sleigh = "name: s\nparameters: { m: 1.0, I: 0.1, d: 0.5 }\ncoordinates: [x, y, theta]\npoints:\n  P: [x, y]\n  G: [x + d*cos(theta), y + d*sin(theta)]\nbodies:\n  s: { mass: m, inertia: I, com: G, angle: theta }\nconstraints:\n  line: y - 2*x\nnonholonomic:\n  knife: -sin(theta)*x_dot + cos(theta)*y_dot\n";
    let file = crate::model::load("m.yaml", sleigh).unwrap();
    let mut m = SymbolicModel::from_file(&file).unwrap();
    assert!(integrable_nonholonomic(&mut m, 7).is_empty());
    let plane = "name: p\nparameters: { m: 1.0 }\ncoordinates: [x, y]\npoints: { P: [x, y] }\nbodies: { b: { mass: m, at: P } }\nnonholonomic:\n  n: x_dot - t*y_dot\n";
    let file = crate::model::load("m.yaml", plane).unwrap();
    let mut m = SymbolicModel::from_file(&file).unwrap();
    assert!(integrable_nonholonomic(&mut m, 7).is_empty());
    let exact = plane.replace("x_dot - t*y_dot", "x_dot - 2*y_dot");
    let file = crate::model::load("m.yaml", &exact).unwrap();
    let mut m = SymbolicModel::from_file(&file).unwrap();
    assert_eq!(integrable_nonholonomic(&mut m, 7), ["n"]);
    // ω = dx + x dy + (y − 3) dz: ω ∧ dω = (y − 2) dx ∧ dy ∧ dz, whose terms 1 and y − 3
    // partly cancel at every state: the bound is relative to the largest term.
    let three = "name: t\nparameters: { m: 1.0 }\ncoordinates: [x, y, z]\npoints: { P: [x, y], Q: [z, 0] }\nbodies: { b: { mass: m, at: P }, c: { mass: m, at: Q } }\nnonholonomic:\n  n: x_dot + x*y_dot + (y - 3)*z_dot\n";
    let file = crate::model::load("m.yaml", three).unwrap();
    let mut m = SymbolicModel::from_file(&file).unwrap();
    assert!(integrable_nonholonomic(&mut m, 7).is_empty());
}

/// A sleigh's velocity constraints written in several forms: the knife edge
/// `−sin θ ẋ + cos θ ẏ` is not integrable (Frobenius fails); `ẏ − 2ẋ` (y = 2x),
/// `ẏ − 2 x ẋ − cos t` (y = x² + sin t) and `cos θ θ̇ + ẋ` (x + sin θ = const) are;
/// `c (−sin θ ẋ + cos θ ẏ) + ẋ` is at the file's `c = 0` (x = const) and not at c = 1.
#[test]
fn integrable_velocity_constraints_are_told_from_a_knife_edge() {
    let source = source("chaplygin_sleigh");
    let knife = "no_side_slip: -sin(theta)*x_dot + cos(theta)*y_dot";
    assert!(source.contains(knife));
    for (constraint, c, integrable) in [
        (knife, "0", false),
        ("line: y_dot - 2*x_dot", "0", true),
        ("parabola: y_dot - 2*x*x_dot - cos(t)", "0", true),
        ("hidden: cos(theta)*theta_dot + x_dot", "0", true),
        (
            "switched: c*(-sin(theta)*x_dot + cos(theta)*y_dot) + x_dot",
            "0",
            true,
        ),
        (
            "switched: c*(-sin(theta)*x_dot + cos(theta)*y_dot) + x_dot",
            "1",
            false,
        ),
        // The differential of x y sin θ + t x (exact), and the same times 1 + x²
        // (integrable with an integrating factor): every ∂aᵢ/∂xⱼ is used, none is 0; times
        // 1e3 the terms are 1e6 times larger, and so is the rounding the bound allows.
        (
            "exact: (y*sin(theta) + t)*x_dot + x*sin(theta)*y_dot + x*y*cos(theta)*theta_dot + x",
            "0",
            true,
        ),
        (
            "factor: (1 + x^2)*((y*sin(theta) + t)*x_dot + x*sin(theta)*y_dot + x*y*cos(theta)*theta_dot + x)",
            "0",
            true,
        ),
        (
            "large: 1e3*(1 + x^2)*((y*sin(theta) + t)*x_dot + x*sin(theta)*y_dot + x*y*cos(theta)*theta_dot + x)",
            "0",
            true,
        ),
    ] {
        // Without `units: SI`, so that the constraints need not be in m/s.
        let text = source
            .replace("units: SI\n", "")
            .replace(knife, constraint)
            .replace("  m: 1.0     # kg", &format!("  m: 1.0     # kg\n  c: {c}"));
        let file = crate::model::load("m.yaml", &text).unwrap();
        let mut m = SymbolicModel::from_file(&file).unwrap();
        let found = integrable_nonholonomic(&mut m, 7);
        assert_eq!(
            found.len(),
            usize::from(integrable),
            "{constraint} (c = {c}): {found:?}"
        );
    }
}
