//! Generalized speeds (`speeds:`): Kane's equations in the speeds against closed forms
//! (Euler's equations), against Lagrange's equations carried into the speeds, and against the
//! same mechanism derived in its coordinates' rates; the kinematic equations against the
//! definitions; and the model file's mistakes.

use crate::common;
use crate::common::accelerations;

use eomgen_symbolic::expr::eval::Evaluator;
use eomgen_symbolic::expr::{ExprId, SymbolKind};
use eomgen_symbolic::mechanics::{Formulation, Kane, Lagrange, SymbolicModel};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

const FREE_BODY: &str = include_str!("../../tests/fixtures/free_rigid_body_speeds.yaml");
const TOP: &str = include_str!("../../tests/fixtures/heavy_top_speeds.yaml");

fn lowered(source: &str) -> SymbolicModel {
    let file = eomgen_symbolic::model::load("m.yaml", source).expect("loads");
    SymbolicModel::from_file(&file).expect("lowers")
}

/// Symbol values (by symbol id): parameters at their defaults, coordinate `i` at `q[i]`, the
/// second half of the state (rates, or speeds) at `v[i]`, `t`; every other symbol 0.
fn bindings(model: &SymbolicModel, q: &[f64], v: &[f64], t: f64) -> Vec<f64> {
    (model.arena.symbols().iter())
        .map(|s| match s.kind {
            SymbolKind::Parameter => (model.parameters.iter())
                .find(|p| p.name == s.name)
                .map_or(0.0, |p| p.default),
            SymbolKind::Coordinate(i) => q[i as usize],
            SymbolKind::Velocity(i) => v[i as usize],
            SymbolKind::Time => t,
            // A rate left in an expression after the switch would be a wrong value: NaN.
            SymbolKind::Retired => f64::NAN,
            _ => 0.0,
        })
        .collect()
}

/// Whether every expression of `eom` is free of the rates the switch to speeds retired.
fn free_of_retired(
    model: &SymbolicModel,
    eom: &eomgen_symbolic::mechanics::EquationsOfMotion,
) -> bool {
    let roots: Vec<ExprId> = eom
        .mass_matrix
        .iter()
        .chain(&eom.forcing)
        .copied()
        .collect();
    model
        .arena
        .reachable(&roots)
        .iter()
        .all(|&e| match model.arena.node(e) {
            eomgen_symbolic::expr::Node::Symbol(s) => {
                model.arena.symbol_info(*s).kind != SymbolKind::Retired
            }
            _ => true,
        })
}

fn values(model: &SymbolicModel, roots: &[ExprId], b: &[f64]) -> Vec<f64> {
    Evaluator::new(&model.arena, roots).eval(b)
}

fn random(rng: &mut Xoshiro256PlusPlus, n: usize, r: f64) -> Vec<f64> {
    (0..n).map(|_| rng.random_range(-r..r)).collect()
}

fn relative(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().chain(b).fold(1.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / scale
}

/// With the body-fixed components of `ω` as speeds, a free body's Kane equations are
/// Euler's: `M` is the diagonal of the principal moments, exactly (the parameters
/// themselves), and `F` equals `((I2 − I3) w2 w3, (I3 − I1) w3 w1, (I1 − I2) w1 w2)` at 100
/// random states to 1e-14 relative; Lagrange's equations carried into the speeds give the
/// same `u̇` to 1e-12.
#[test]
fn a_free_body_in_body_rates_has_eulers_equations() {
    let mut model = lowered(FREE_BODY);
    let kane = Kane.derive(&mut model);
    let lagrange = Lagrange.derive(&mut model);
    let zero = model.arena.int(0);
    let diagonal = ["I1", "I2", "I3"].map(|name| {
        let s = model.arena.symbol_id(name).expect("a parameter");
        model.arena.symbol_expr(s)
    });
    for (i, &d) in diagonal.iter().enumerate() {
        for j in 0..3 {
            let want = if i == j { d } else { zero };
            assert_eq!(kane.mass(i, j), want, "M[{i},{j}]");
        }
    }
    let (i1, i2, i3) = (1.0, 2.0, 3.0);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(53);
    for _ in 0..100 {
        let (q, w) = (random(&mut rng, 3, 1.2), random(&mut rng, 3, 3.0));
        let b = bindings(&model, &q, &w, 0.0);
        let f = values(&model, &kane.forcing, &b);
        let euler = [
            (i2 - i3) * w[1] * w[2],
            (i3 - i1) * w[2] * w[0],
            (i1 - i2) * w[0] * w[1],
        ];
        assert!(relative(&f, &euler) < 1e-14, "{f:?} against {euler:?}");
        let (a, c) = (
            accelerations(&model, &kane, &b),
            accelerations(&model, &lagrange, &b),
        );
        assert!(relative(&a, &c) < 1e-12, "{a:?} against {c:?}");
    }
}

/// The heavy top in body rates: Euler's equations about the fixed point with the moment of
/// gravity, `I1 ẇ1 = (I1 − I3) w2 w3 + m g l sin θ cos ψ`,
/// `I1 ẇ2 = (I3 − I1) w3 w1 − m g l sin θ sin ψ`, `I3 ẇ3 = 0` (Goldstein §5.7), at 100
/// random states (θ away from the angles' singularity at 0) to 1e-13 relative, from both
/// derivations.
#[test]
fn the_heavy_top_in_body_rates_has_eulers_equations_with_gravity() {
    let mut model = lowered(TOP);
    let kane = Kane.derive(&mut model);
    let lagrange = Lagrange.derive(&mut model);
    let (m, g, l, i1, i3) = (1.0, 9.81, 0.1, 0.02, 0.01);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    for _ in 0..100 {
        let q = [
            rng.random_range(-3.0..3.0),
            rng.random_range(0.2..2.9),
            rng.random_range(-3.0..3.0),
        ];
        let w = random(&mut rng, 3, 20.0);
        let b = bindings(&model, &q, &w, 0.0);
        let (st, sp, cp) = (q[1].sin(), q[2].sin(), q[2].cos());
        let want = [
            ((i1 - i3) * w[1] * w[2] + m * g * l * st * cp) / i1,
            ((i3 - i1) * w[2] * w[0] - m * g * l * st * sp) / i1,
            0.0,
        ];
        for eom in [&kane, &lagrange] {
            let a = accelerations(&model, eom, &b);
            assert!(relative(&a, &want) < 1e-13, "{a:?} against {want:?}");
        }
    }
}

/// The kinematic equations invert the definitions: at random `(q, u)`, the body's angular
/// velocity of the same file without `speeds:` (the derivation in the rates, whose `ω` is
/// built from the rotations) evaluated at `q̇ = W(q) u` is `u`, to 1e-13 relative.
#[test]
fn the_kinematic_equations_give_back_the_speeds() {
    for source in [FREE_BODY, TOP] {
        let with = lowered(source);
        let speeds = with.speeds.as_ref().expect("speeds");
        let without = lowered(&without_speeds(source));
        let omega = without.bodies[0]
            .spatial
            .as_ref()
            .expect("a 3-D body")
            .angular_velocity;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        for _ in 0..100 {
            let q = [
                rng.random_range(-3.0..3.0),
                rng.random_range(0.2..1.3),
                rng.random_range(-3.0..3.0),
            ];
            let u = random(&mut rng, 3, 5.0);
            let rates = values(
                &with,
                &speeds.kinematic_equations,
                &bindings(&with, &q, &u, 0.0),
            );
            let w = values(&without, &omega, &bindings(&without, &q, &rates, 0.0));
            assert!(relative(&w, &u) < 1e-13, "{w:?} against {u:?}");
        }
    }
}

/// `source` with its `speeds:` block and its `initial:` (the speeds' values) left out: the
/// same mechanism in the coordinates' rates.
fn without_speeds(source: &str) -> String {
    strip_section(&strip_section(source, "speeds:"), "initial:")
}

/// A planar chain in the upper arm's rate and the elbow's (relative) rate, with the bundled
/// double pendulum's time-dependent forearm torque: `u̇ = (θ̈₁, θ̈₂ − θ̈₁)` with `θ̈` of the
/// bundled model derived in its own rates (momentum balance and Lagrange), at 100 random
/// states, to 1e-12 relative, from both derivations in the speeds.
#[test]
fn a_chain_in_relative_rates_moves_as_in_absolute_ones() {
    let base = common::double_pendulum_with_forearm_torque();
    let base = strip_section(&base, "balances:");
    let with = base.replace(
        "coordinates:\n",
        "speeds:\n  u1: theta1_dot\n  u2: theta2_dot - theta1_dot\ncoordinates:\n",
    );
    assert!(with.contains("u2: theta2_dot - theta1_dot"));
    let mut speeds_model = lowered(&with);
    let kane = Kane.derive(&mut speeds_model);
    let carried = Lagrange.derive(&mut speeds_model);
    let mut rates_model = lowered(&base);
    let reference = Lagrange.derive(&mut rates_model);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(19);
    for _ in 0..100 {
        let q = random(&mut rng, 2, 3.0);
        let u = random(&mut rng, 2, 3.0);
        let t = rng.random_range(0.0..5.0);
        let qd = [u[0], u[0] + u[1]];
        let qdd = accelerations(
            &rates_model,
            &reference,
            &bindings(&rates_model, &q, &qd, t),
        );
        let want = [qdd[0], qdd[1] - qdd[0]];
        for eom in [&kane, &carried] {
            let a = accelerations(&speeds_model, eom, &bindings(&speeds_model, &q, &u, t));
            assert!(relative(&a, &want) < 1e-12, "{a:?} against {want:?}");
        }
    }
}

/// `source` without the top-level section `key` (its line and the indented lines below).
fn strip_section(source: &str, key: &str) -> String {
    let mut out = String::new();
    let mut inside = false;
    for line in source.lines() {
        if line.starts_with(key) {
            inside = true;
            continue;
        }
        if inside && (line.starts_with(' ') || line.starts_with('#')) {
            continue;
        }
        inside = false;
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// The messages of a file whose speeds are wrong, each at its place: nonlinear, dependent,
/// too few, beside constraints, with both initial rates and speeds; and a model with speeds
/// is exported with its kinematic equations (`coordinate_rates`).
#[test]
fn mistaken_speeds_are_located() {
    let lowering_error = |source: &str| -> String {
        let file = eomgen_symbolic::model::load("m.yaml", source).expect("loads");
        let errors = SymbolicModel::from_file(&file).expect_err("an error");
        format!(
            "{}:{}: {}",
            errors[0].location.line, errors[0].location.column, errors[0].message
        )
    };
    let load_error = |source: &str| -> String {
        let errors = eomgen_symbolic::model::load("m.yaml", source).expect_err("an error");
        errors
            .iter()
            .map(|d| format!("{}:{}: {}", d.location.line, d.location.column, d.message))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let planar = |speeds: &str, initial: &str| {
        format!(
            "name: p\ncoordinates: [x, y]\nspeeds: {{ {speeds} }}\nparameters: {{ m: 1 }}\npoints: {{ P: [x, y] }}\nbodies: {{ ball: {{ mass: m, at: P }} }}\ninitial: {{ {initial} }}\n"
        )
    };
    let e = lowering_error(&planar("a: x_dot^2, b: y_dot", "x: 1"));
    assert_eq!(e, "3:14: speed `a` is not linear in the rates");
    // Linear, though multiplying out leaves `√(2 + x)·√(2 + x)` apart from `2 + x`.
    let file = eomgen_symbolic::model::load(
        "m.yaml",
        &planar(
            "a: sqrt(2 + x)*(x_dot + sqrt(2 + x)*y_dot), b: y_dot",
            "x: 1",
        ),
    )
    .expect("loads");
    assert!(SymbolicModel::from_file(&file).is_ok());
    for nonlinear in [
        "a: abs(x_dot), b: y_dot",
        "a: x_dot + sign(x_dot), b: y_dot",
        "a: x_dot*y_dot, b: y_dot",
    ] {
        let file =
            eomgen_symbolic::model::load("m.yaml", &planar(nonlinear, "x: 1")).expect("loads");
        let errors = SymbolicModel::from_file(&file).expect_err("an error");
        assert_eq!(errors.len(), 1, "{nonlinear}: {errors:?}");
        assert!(
            errors[0]
                .message
                .contains("speed `a` is not linear in the rates"),
            "{nonlinear}: {errors:?}"
        );
    }
    let e = load_error(
        &FREE_BODY
            .replace("  w3: omega_B_z", "  omega_B_x: omega_B_z")
            .replace("w3: 1 }", "omega_B_x: 1 }"),
    );
    assert_eq!(
        e,
        "22:3: speed name `omega_B_x` is taken: it names a component of a frame's angular velocity"
    );
    let quartic = "name: quartic\nparameters: { m: 2, b: 0.3 }\ncoordinates: [x]\nkinetic: m*x_dot^2/2 + b*x_dot^4\nspeeds: { v: 2*x_dot }\n";
    let e = load_error(quartic);
    assert!(
        e.contains("5:11: generalized speeds need the kinematic form"),
        "{e}"
    );
    let e = load_error(&planar("a: x_dot, b: a + y_dot", "x: 1"));
    assert!(
        e.contains("3:24: speed `b` is defined through the speed `a`"),
        "{e}"
    );
    let e = lowering_error(&planar("a: x_dot + y_dot, b: 2*x_dot + 2*y_dot", "x: 1"));
    assert!(
        e.starts_with("3:11: the speeds do not determine the rates"),
        "{e}"
    );
    let e = load_error(&planar("a: x_dot", "x: 1"));
    assert!(
        e.contains("3:11: the model has 2 coordinates but 1 speed"),
        "{e}"
    );
    let e = load_error(&planar("a: x_dot, b: y_dot", "x_dot: 1, a: 2"));
    assert!(
        e.contains("7:12: `initial` gives the rate `x_dot` and the speed `a`"),
        "{e}"
    );
    let quaternion = include_str!("../../tests/fixtures/free_rigid_body_quaternion.yaml").replace(
        "coordinates:\n",
        "speeds: { a: e0_dot, b: e1_dot, c: e2_dot, d: e3_dot }\ncoordinates:\n",
    );
    let e = load_error(&quaternion);
    assert!(
        e.contains("19:11: the model has 4 coordinates and 1 constraint row but 4 speeds: `speeds` gives one per degree of freedom, 3"),
        "{e}"
    );
    // Beside non-holonomic constraints, one speed per degree of freedom: a point on a line
    // `y' = x'` has one.
    let sliding = |speeds: &str| {
        planar(speeds, "x: 1").replace("points:", "nonholonomic: { along: y_dot - x_dot }\npoints:")
    };
    let e = load_error(&sliding("a: x_dot, b: y_dot"));
    assert!(
        e.contains("3:11: the model has 2 coordinates and 1 constraint row but 2 speeds: `speeds` gives one per degree of freedom, 1"),
        "{e}"
    );
    let e = load_error(&sliding("along: x_dot"));
    assert!(
        e.contains("3:11: speed name `along` is taken: it names a constraint row"),
        "{e}"
    );
    // A row named as a speed's rate (each speed declares `<name>_dot`).
    let e = lowering_error(&sliding("a: x_dot").replace("along:", "a_dot:"));
    assert!(
        e.contains("constraint row `a_dot` (or its rate `a_dot_dot`) is taken"),
        "{e}"
    );
    let e = load_error(&sliding("a: x_dot").replace("x: 1", "x: { guess: 1 }"));
    assert!(
        e.contains("`x` is a guess, but a model in generalized speeds does not solve its initial state from the constraints"),
        "{e}"
    );
    let e = load_error(&format!("{}outputs: {{ along: x }}\n", sliding("a: x_dot")));
    assert!(e.contains("output name `along` is taken"), "{e}");
    let e = lowering_error(&sliding("a: x_dot - y_dot"));
    assert!(
        e.starts_with("3:11: the speeds do not determine the rates"),
        "{e}"
    );
    let model = SymbolicModel::from_file(
        &eomgen_symbolic::model::load("m.yaml", &sliding("a: x_dot")).expect("loads"),
    )
    .expect("derives");
    let speeds = model.speeds.as_ref().expect("in speeds");
    assert_eq!(
        (speeds.names.as_slice(), speeds.auxiliary),
        (["a".to_string(), "along".to_string()].as_slice(), 1)
    );
    let file = eomgen_symbolic::model::load("m.yaml", FREE_BODY).expect("loads");
    let exported = eomgen_symbolic::codegen::export::export(
        &file,
        "m.yaml",
        eomgen_symbolic::codegen::export::Language::C,
        &[],
    )
    .expect("a model in speeds is exported");
    assert!(exported.contains("_coordinate_rates("), "{exported}");
}

/// A speed with an offset, `u = ẋ + v0` for a point at `x + v0 t` pulled by `−k x`:
/// `u̇ = ẍ = −k x/m` from both derivations at 50 random states and times to 1e-13,
/// no rate left in either, and `check` passes, its energy routes and power balance skipped
/// (the speeds in `T` do not show its degree in `ẋ`).
#[test]
fn a_speed_with_an_offset_moves_as_its_rate() {
    let source = "name: belt\nparameters: { m: 2, k: 5, v0: 0.7 }\ncoordinates: [x]\nspeeds: { u: x_dot + v0 }\npoints: { O: [0, 0], P: [x + v0*t, 0] }\nbodies: { ball: { mass: m, at: P } }\nforces: { pull: { at: P, vector: [-k*x, 0] } }\ninitial: { x: 1 }\n";
    let mut model = lowered(source);
    let kane = Kane.derive(&mut model);
    let carried = Lagrange.derive(&mut model);
    assert!(free_of_retired(&model, &kane) && free_of_retired(&model, &carried));
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(29);
    for _ in 0..50 {
        let (x, u, t) = (
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(0.0..5.0),
        );
        let want = [-5.0 * x / 2.0];
        for eom in [&kane, &carried] {
            let a = accelerations(&model, eom, &bindings(&model, &[x], &[u], t));
            assert!(relative(&a, &want) < 1e-13, "{a:?} against {want:?}");
        }
    }
    let file = eomgen_symbolic::model::load("m.yaml", source).expect("loads");
    let report =
        eomgen_symbolic::mechanics::cross_check::check_model(&file, 50, 1).expect("checks");
    let summary = report.summary(1e-9, false);
    assert!(report.passed(1e-9), "{summary:?}");
    assert!(
        summary.notes.iter().any(|n| n.contains("offset")),
        "{summary:?}"
    );
    // A speed whose coefficient depends on `t`: `T(q, u)` then has no `t` where `T(q, q̇)`
    // has, or the other way round; the routes that ask are skipped, and `check` passes.
    let pendulum = "name: swing\nparameters: { m: 1, l: 1, g: 9.8, w: 2 }\ncoordinates: [q]\nspeeds: { u: (2 + sin(w*t))*q_dot }\npoints: { O: [0, 0], P: [l*sin(q), -l*cos(q)] }\nbodies: { bob: { mass: m, at: P } }\ngravity: [0, -g]\ninitial: { q: 1 }\n";
    let file = eomgen_symbolic::model::load("m.yaml", pendulum).expect("loads");
    let report =
        eomgen_symbolic::mechanics::cross_check::check_model(&file, 50, 1).expect("checks");
    let summary = report.summary(1e-9, false);
    assert!(report.passed(1e-9), "{summary:?}");
    assert!(
        summary
            .notes
            .iter()
            .any(|n| n.contains("depends on t (u = Y")),
        "{summary:?}"
    );
}
