//! Lecture 10's routes to an equation of motion (HW11) and HW4/HW15's definitions of the
//! angular momentum about a moving point, through `eomgen check`'s comparison with Lagrange:
//! the energy equation `Ė = Q q̇` and the power balance `P = dT/dt` for one coordinate, named
//! sets of balances, and the `h_dot` and `h_rel_dot` forms right about fixed points and wrong,
//! with the reason, about a moving one.

use eomgen_symbolic::mechanics::cross_check::{CHECK_TOLERANCE, CheckReport, check_model};

fn check(source: &str) -> CheckReport {
    let file = eomgen_symbolic::model::load("m.yaml", source).expect("loads");
    check_model(&file, 100, 11).expect("lowers")
}

fn residual(report: &CheckReport, name: &str) -> f64 {
    report
        .comparisons
        .iter()
        .find(|c| c.b == name)
        .unwrap_or_else(|| panic!("`{name}` compared in {:?}", report.comparisons))
        .max_rel_residual
}

/// The bundled kinematic pendulum shows all of lecture 10's routes, each equal to Lagrange's
/// to rounding (1e-8: the derivations differ by a few ulps of q̈).
#[test]
fn the_pendulum_is_derived_six_ways() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../models/pendulum_routes.yaml"
    ))
    .unwrap();
    let report = check(&text);
    let names: Vec<&str> = report.comparisons.iter().map(|c| c.b.as_str()).collect();
    for route in [
        "momentum",
        "amb_O",
        "r_x_lmb",
        "lmb_e_theta",
        "by_hand",
        "energy",
        "power",
    ] {
        assert!(names.contains(&route), "{route} missing from {names:?}");
        assert!(residual(&report, route) < CHECK_TOLERANCE, "{route}");
    }
    assert!(report.passed(CHECK_TOLERANCE), "{:?}", report.notes);
}

/// One coordinate with every kind of load: gravity on a bar, a spring of non-zero rest length
/// and a dashpot from a fixed point to the bar's tip, a time-dependent force at the tip and a
/// motor torque. The power route sums each load's power from the point velocities, so a load
/// it dropped or a sign it got wrong would leave an O(1) difference from Lagrange's; the energy
/// route (Ė = Q q̇) is checked on the same model.
const LOADED_BAR: &str = r#"
name: loaded_bar
parameters: { m: 1.3, l: 0.8, g: 9.81, k: 7.0, l0: 0.3, c: 0.4, F: 2.0, w: 1.7, tau: 0.5 }
coordinates: [th]
points:
  O: [0, 0]
  G: [l/2*cos(th), l/2*sin(th)]
  P: [l*cos(th), l*sin(th)]
  A: [0.2, 1.1]
bodies:
  bar: { mass: m, inertia: m*l^2/12, com: G, angle: th }
gravity: [0, -g]
springs:
  s: { between: [A, P], stiffness: k, rest_length: l0 }
dampers:
  d: { between: [A, P], coefficient: c }
forces:
  push: { at: P, vector: [F*cos(w*t), 0] }
torques:
  motor: { body: bar, value: tau }
initial: { th: 0.3, th_dot: 0.2 }
"#;

#[test]
fn energy_and_power_routes_see_every_load() {
    let report = check(LOADED_BAR);
    for route in ["momentum", "energy", "power"] {
        let r = residual(&report, route);
        assert!(r < CHECK_TOLERANCE, "{route}: {r:e}");
    }
    assert!(report.passed(CHECK_TOLERANCE), "{:?}", report.notes);
}

/// Routes that need one coordinate and no explicit `t` in `T` or `V` say why they are skipped.
#[test]
fn energy_routes_are_skipped_with_a_reason() {
    let driven = r#"
name: driven
parameters: { m: 1.0, l: 1.0, g: 10.0, a: 0.1, w: 3.0 }
coordinates: [q]
points:
  O: [0, a*sin(w*t)]
  P: [l*sin(q), a*sin(w*t) - l*cos(q)]
bodies:
  bob: { mass: m, at: P }
gravity: [0, -g]
initial: { q: 0.2, q_dot: 0 }
"#;
    let report = check(driven);
    assert!(!report.comparisons.iter().any(|c| c.b == "energy"));
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("energy and power routes skipped: T or V depends explicitly on t")),
        "{:?}",
        report.notes
    );
}

const ELBOW: &str = r#"
name: points2
parameters: { m: 1.0, l: 1.0, g: 10.0 }
coordinates: [a, b]
points:
  O: [0, 0]
  E: [l*sin(a), -l*cos(a)]
  H: [l*sin(a) + l*sin(b), -l*cos(a) - l*cos(b)]
bodies:
  elbow: { mass: m, at: E }
  hand: { mass: m, at: H }
gravity: [0, -g]
initial: { a: 0.5, b: 1.0 }
"#;

fn with_balances(balances: &str) -> String {
    format!("{ELBOW}balances:\n{balances}")
}

/// HW4/HW15: about the fixed shoulder every form is right; about the moving elbow only
/// `r_x_ma` is. A wrong form without `expect: disagree` fails, with the term it misses named.
#[test]
fn angular_momentum_forms_about_a_moving_point() {
    let sets = |form: &str, stated_wrong: bool| {
        let expect = if stated_wrong {
            "expect: disagree\n    "
        } else {
            ""
        };
        with_balances(&format!(
            "  right:\n    - {{ amb: {{ about: O, bodies: [elbow, hand] }} }}\n    - {{ amb: {{ about: E, bodies: [hand] }} }}\n  tried:\n    {expect}balances:\n      - {{ amb: {{ about: O, bodies: [elbow, hand], form: {form} }} }}\n      - {{ amb: {{ about: E, bodies: [hand], form: {form} }} }}\n"
        ))
    };
    for (form, misses) in [
        ("h_dot", "misses v_A × m v_G"),
        ("h_rel_dot", "misses r_G/A × m a_A"),
    ] {
        // Stated as right: the check fails and says why.
        let report = check(&sets(form, false));
        assert!(residual(&report, "right") < CHECK_TOLERANCE);
        assert!(residual(&report, "tried") > 1e-2, "{form}");
        assert!(!report.passed(CHECK_TOLERANCE), "{form}");
        assert!(
            report
                .notes
                .iter()
                .any(|n| n.contains("the balances `tried` disagree") && n.contains(misses)),
            "{form}: {:?}",
            report.notes
        );
        // Stated as wrong: the check passes.
        let report = check(&sets(form, true));
        assert!(report.passed(CHECK_TOLERANCE), "{form}: {:?}", report.notes);
    }
    // A right set stated as wrong fails.
    let report = check(&sets("r_x_ma", true));
    assert!(!report.passed(CHECK_TOLERANCE));
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("agree with Lagrange, but the file states")),
        "{:?}",
        report.notes
    );
}

/// About the fixed shoulder alone (one coordinate), `h_dot` and `h_rel_dot` are right.
#[test]
fn angular_momentum_forms_about_a_fixed_point() {
    let pendulum = r#"
name: p
parameters: { m: 1.0, l: 1.0, g: 10.0 }
coordinates: [q]
points:
  O: [0, 0]
  P: [l*cos(q), l*sin(q)]
bodies:
  bob: { mass: m, at: P }
gravity: [0, -g]
initial: { q: 0.1 }
balances:
  a: [ { amb: { about: O, bodies: [bob], form: h_dot } } ]
  b: [ { amb: { about: O, bodies: [bob], form: h_rel_dot } } ]
"#;
    let report = check(pendulum);
    assert!(residual(&report, "a") < CHECK_TOLERANCE);
    assert!(residual(&report, "b") < CHECK_TOLERANCE);
}

/// A set with the wrong count of balances, an unknown key in a set and a wrong `expect` are
/// located diagnostics.
#[test]
fn balance_sets_are_diagnosed() {
    let short = with_balances("  one:\n    - { amb: { about: O, bodies: [elbow, hand] } }\n");
    let errors = eomgen_symbolic::model::load("m.yaml", &short).unwrap_err();
    assert!(
        errors.iter().any(|d| d
            .message
            .contains("the set `one` has 1 balance(s) for 2 coordinate(s)")),
        "{errors:?}"
    );
    let unknown = with_balances(
        "  one:\n    expected: disagree\n    balances:\n      - { amb: { about: O, bodies: [elbow, hand] } }\n      - { amb: { about: E, bodies: [hand] } }\n",
    );
    let errors = eomgen_symbolic::model::load("m.yaml", &unknown).unwrap_err();
    let d = errors
        .iter()
        .find(|d| d.message.contains("unknown key `expected`"))
        .expect("unknown key diagnosed");
    assert_eq!(d.location.line, 16, "{d:?}");
    let wrong = with_balances(
        "  one:\n    expect: wrong\n    balances:\n      - { amb: { about: O, bodies: [elbow, hand] } }\n      - { amb: { about: E, bodies: [hand] } }\n",
    );
    let errors = eomgen_symbolic::model::load("m.yaml", &wrong).unwrap_err();
    assert!(
        errors.iter().any(|d| d
            .message
            .contains("`expect` of a set of balances is `disagree`")),
        "{errors:?}"
    );
}

/// A set named after another derivation would share its row and its key in the summary
/// (`momentum` beside momentum balance), and an empty set would be dropped unseen: both are
/// errors located at the set's name (the name on line 15 of the file).
#[test]
fn balance_sets_need_their_own_names_and_balances() {
    let pair = "\n    - { amb: { about: O, bodies: [elbow, hand] } }\n    - { amb: { about: E, bodies: [hand] } }\n";
    for reserved in ["lagrange", "momentum", "by_hand", "energy", "power"] {
        let text = with_balances(&format!("  {reserved}:{pair}"));
        let errors = eomgen_symbolic::model::load("m.yaml", &text).unwrap_err();
        let d = errors
            .iter()
            .find(|d| d.message.contains("names another derivation"))
            .unwrap_or_else(|| panic!("{reserved}: {errors:?}"));
        assert_eq!((d.location.line, d.location.column), (15, 3), "{d:?}");
    }
    let empty = with_balances(&format!("  right:{pair}  none: []\n"));
    let errors = eomgen_symbolic::model::load("m.yaml", &empty).unwrap_err();
    let d = errors
        .iter()
        .find(|d| d.message.contains("the set of balances `none` is empty"))
        .unwrap_or_else(|| panic!("{errors:?}"));
    assert_eq!(d.location.line, 18, "{d:?}");
    // The same sets under their own names load and are compared under them.
    let report = check(&with_balances(&format!("  right:{pair}")));
    assert!(residual(&report, "right") < CHECK_TOLERANCE);
}

/// A damper to a driven base (`B` moves with `t`, `T` and `V` do not): the energy route
/// `Ė = Q q̇` holds, but the damper's power at `B` is the driver's, not drawn from `T`, so
/// `P = dT/dt` with every load's `F·v` would be wrong: the power route is not taken and the
/// check passes. A rod spun at a constant rate written as `T = ½ m (ṙ² + r² ω²)` has no
/// explicit `t`, but `T` is not a quadratic form in `ṙ`, so `Ė = 0` is not `ṙ` times the
/// equation of motion `r̈ = ω² r`: the energy route is skipped with that reason (the
/// hand-derived equation, right, still passes).
#[test]
fn energy_routes_need_undriven_loads_and_a_quadratic_t() {
    let base = r#"
name: base
parameters: { m: 1.0, c: 0.5, Y: 0.2, w: 2.0 }
coordinates: [x]
points:
  B: [Y*sin(w*t), 0]
  P: [x, 0]
bodies:
  mass: { mass: m, at: P }
dampers:
  d: { between: [B, P], coefficient: c }
initial: { x: 1 }
"#;
    let report = check(base);
    assert!(residual(&report, "energy") < CHECK_TOLERANCE);
    assert!(!report.comparisons.iter().any(|c| c.b == "power"));
    assert!(report.passed(CHECK_TOLERANCE), "{:?}", report.notes);

    let spun = r#"
name: spun
parameters: { m: 1.0, w: 1.5 }
coordinates: [r]
kinetic: m*(r_dot^2 + r^2*w^2)/2
initial: { r: 1 }
checks:
  equations_of_motion:
    - m*r_ddot = m*w^2*r
"#;
    let report = check(spun);
    assert!(!report.comparisons.iter().any(|c| c.b == "energy"));
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("T is not a quadratic form in q̇")),
        "{:?}",
        report.notes
    );
    assert!(report.passed(CHECK_TOLERANCE), "{:?}", report.notes);
}

/// A set stated to disagree whose equations are not finite (an `lmb` direction outside the
/// domain of `sqrt`) fails, and the note says so rather than that it agrees.
#[test]
fn a_set_stated_to_disagree_must_be_finite() {
    let text = with_balances(
        "  tried:\n    expect: disagree\n    balances:\n      - { amb: { about: O, bodies: [elbow, hand] } }\n      - { lmb: { bodies: [hand], along: [sqrt(-1 - a^2), 0] } }\n",
    );
    let report = check(&text);
    assert!(residual(&report, "tried").is_nan());
    assert!(!report.passed(CHECK_TOLERANCE));
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("the balances `tried` are not finite")),
        "{:?}",
        report.notes
    );
    assert!(
        !report
            .notes
            .iter()
            .any(|n| n.contains("agree with Lagrange, but"))
    );
}
