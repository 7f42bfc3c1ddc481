//! The derivations a model file writes by hand — its `balances:` and its
//! `checks: equations_of_motion` — go through `check_model` and are compared with Lagrange:
//! every bundled set agrees, a set that is not there is not compared, and each term the
//! balances take (gravity, a torque on a body, `form: h_dot`) is needed for the agreement.

use crate::common;

use eomgen_symbolic::mechanics::cross_check::{CheckReport, check_model};

fn check(source: &str) -> CheckReport {
    let file = eomgen_symbolic::model::load("m.yaml", source).expect("loads");
    check_model(&file, 20, 7).expect("checks")
}

/// The largest relative residual of the comparison of Lagrange with the derivation `name`.
fn residual(report: &CheckReport, name: &str) -> Option<f64> {
    report
        .comparisons
        .iter()
        .find(|c| c.b == name)
        .map(|c| c.max_rel_residual)
}

/// Every bundled model with `balances:` is compared with each of its sets of them, and with
/// its hand equations if it has them, and each agrees with Lagrange to 1e-9 relative (each is
/// an exact rearrangement of the same q̈: rounding only, ~1e-14) — except a set the file states
/// to be wrong (`expect: disagree`), which must differ; a model without them is not compared
/// with them.
#[test]
fn every_bundled_balance_set_and_hand_equation_set_agrees_with_lagrange() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    let (mut balances, mut by_hand, mut stated_wrong) = (0, 0, 0);
    const DERIVED: [&str; 4] = ["momentum", "by_hand", "energy", "power"];
    for path in entries {
        let source = std::fs::read_to_string(&path).unwrap();
        let report = check(&source);
        let has_balances = source.contains("\nbalances:");
        let has_hand = source.contains("equations_of_motion:");
        let sets: Vec<_> = report
            .comparisons
            .iter()
            .filter(|c| !DERIVED.contains(&c.b.as_str()))
            .collect();
        assert_eq!(!sets.is_empty(), has_balances, "{}", path.display());
        for c in sets {
            if c.expect_disagreement {
                assert!(c.max_rel_residual > 1e-2, "{}: {}", path.display(), c.b);
                stated_wrong += 1;
            } else {
                assert!(c.max_rel_residual < 1e-9, "{}: {}", path.display(), c.b);
                balances += 1;
            }
        }
        match residual(&report, "by_hand") {
            Some(r) => {
                assert!(has_hand, "{}: compared with by_hand", path.display());
                assert!(r < 1e-9, "{}: by_hand residual {r}", path.display());
                by_hand += 1;
            }
            None => assert!(!has_hand, "{}: by_hand not compared", path.display()),
        }
        assert!(report.passed(1e-9), "{}: {report:?}", path.display());
        assert!(
            report
                .notes
                .iter()
                .all(|n| !n.contains("disagree") || n.contains("as the file states")),
            "{}: {:?}",
            path.display(),
            report.notes
        );
    }
    assert!(
        balances >= 6 && by_hand >= 12 && stated_wrong >= 2,
        "{balances} {by_hand} {stated_wrong}"
    );
}

/// A compound pendulum (a bar of mass m and length L hinged at its end O) driven by a torque
/// τ: AMB about O, `I_O θ̈ = −m g (L/2) cos θ + τ` with θ from +x, is right only with both the
/// gravity moment and the torque; `lmb` along the bar's normal through the centre of mass is a
/// second balance that keeps the reaction (so it may not be chosen alone).
const DRIVEN_BAR: &str = "
name: driven_bar
parameters: { m: 2.0, L: 1.5, g: 9.81, tau0: 3.0 }
coordinates: [theta]
points:
  O: [0, 0]
  G: [L/2*cos(theta), L/2*sin(theta)]
bodies:
  bar: { mass: m, inertia: m*L^2/12, com: G, angle: theta }
gravity: [0, -g]
torques: { motor: { body: bar, value: tau0*cos(2*t) } }
balances:
  - { amb: { about: O, bodies: [bar] FORM } }
initial: { theta: 0.3 }
";

#[test]
fn a_balance_about_the_hinge_takes_the_gravity_moment_and_the_torque() {
    let report = check(&DRIVEN_BAR.replace(" FORM", ""));
    let r = residual(&report, "balances").expect("compared");
    assert!(r < 1e-9, "{r}");
}

/// `form: h_dot` about the fixed hinge is right (dH_O/dt = Σ M_O there); about the moving
/// elbow of the double pendulum it misses v_E × m v_G, which the check reports.
#[test]
fn h_dot_is_right_about_a_fixed_point_and_reported_about_a_moving_one() {
    let report = check(&DRIVEN_BAR.replace(" FORM", ", form: h_dot"));
    let r = residual(&report, "balances").expect("compared");
    assert!(r < 1e-9, "{r}");

    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");
    let source = std::fs::read_to_string(format!("{dir}/double_pendulum.yaml")).unwrap();
    let moving = source.replace(
        "{ amb: { about: E, bodies: [fore] } }",
        "{ amb: { about: E, bodies: [fore], form: h_dot } }",
    );
    assert_ne!(moving, source);
    let report = check(&moving);
    let r = residual(&report, "balances").expect("compared");
    assert!(r > 1e-3, "{r}");
    assert!(
        report.notes.iter().any(|n| n.contains("h_dot")),
        "{:?}",
        report.notes
    );
    // The same balance in the default form, r × m a, is right about the moving elbow.
    let report = check(&source);
    assert!(residual(&report, "balances").unwrap() < 1e-9);
}

/// A hand equation with a wrong sign is reported as a disagreement, one with a wrong factor
/// too; the right one agrees.
#[test]
fn a_wrong_hand_equation_is_reported() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");
    let source = std::fs::read_to_string(format!("{dir}/simple_pendulum.yaml")).unwrap();
    let right = "m*l^2*q_ddot = -m*g*l*cos(q)";
    assert!(source.contains(right));
    assert!(residual(&check(&source), "by_hand").unwrap() < 1e-9);
    for wrong in [
        "m*l^2*q_ddot = m*g*l*cos(q)",
        "m*l^2*q_ddot = -m*g*l*cos(q)/2",
    ] {
        let report = check(&source.replace(right, wrong));
        let r = residual(&report, "by_hand").unwrap();
        assert!(r > 1e-3, "{wrong}: {r}");
        assert!(
            report.notes.iter().any(|n| n.contains("by hand disagree")),
            "{:?}",
            report.notes
        );
    }
}

/// The file's `initial:` against its constraints: the Cartesian pendulum starts on its circle
/// (passes); moved 1 cm off it, or 1e-10 off (inside the 1e-9 bound), it fails and passes;
/// a rate across the circle fails the velocity constraint.
#[test]
fn the_initial_state_is_checked_against_the_constraints() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");
    let source = std::fs::read_to_string(format!("{dir}/simple_pendulum_cartesian.yaml")).unwrap();
    let start = "initial: { x: l, y: 0 }";
    assert!(source.contains(start));
    for (initial, residual, passed) in [
        (start, 0.0, true),
        // On the circle, moving along it (|v| = 1 m/s, tangent) and across it.
        (
            "initial: { x: 0.6*l, y: -0.8*l, x_dot: 0.8, y_dot: 0.6 }",
            0.0,
            true,
        ),
        (
            "initial: { x: 0.6*l, y: -0.8*l, x_dot: 0.6, y_dot: -0.8 }",
            1.0,
            false,
        ),
        ("initial: { x: 1.01*l, y: 0 }", 0.01, false),
        ("initial: { x: (1 + 1e-10)*l, y: 0 }", 1e-10, true),
    ] {
        let report = check(&source.replace(start, initial));
        let found = report.initial_constraints.as_ref().expect("checked");
        assert!(
            (found.residual - residual).abs() <= 1e-12 && found.passed() == passed,
            "{initial}: {found:?}"
        );
        assert_eq!(report.passed(1e-8), passed, "{initial}");
    }
}

/// A block on an incline at angle α (s down the slope): linear momentum balance along the
/// slope, `m s̈ = m g sin α`, is right only with the weight's component along it.
#[test]
fn a_linear_momentum_balance_takes_the_weight_along_its_direction() {
    let source = "
name: incline
parameters: { m: 2.0, g: 9.81, alpha: 0.4 }
coordinates: [s]
points:
  P: [s*cos(alpha), -s*sin(alpha)]
bodies:
  block: { mass: m, at: P }
gravity: [0, -g]
balances:
  - { lmb: { along: [cos(alpha), -sin(alpha)], bodies: [block] } }
checks:
  equations_of_motion:
    - m*s_ddot = m*g*sin(alpha)
initial: { s: 0 }
";
    let report = check(source);
    for name in ["balances", "by_hand"] {
        let r = residual(&report, name).expect("compared");
        assert!(r < 1e-9, "{name}: {r}");
    }
}

/// States are drawn over time too: a forcing term written as `B*sin(2*w*t)` instead of
/// `B*sin(w*t)` agrees at t = 0 only, and is reported.
#[test]
fn a_hand_equation_wrong_only_away_from_t_0_is_reported() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");
    let source = std::fs::read_to_string(format!("{dir}/forced_oscillator.yaml")).unwrap();
    // The hand equation's right-hand side (the generalized force has the same terms).
    let right = "= A*cos(w*t) + B*sin(w*t)";
    assert_eq!(source.matches(right).count(), 1);
    assert!(residual(&check(&source), "by_hand").unwrap() < 1e-9);
    let wrong = source.replace(right, "= A*cos(w*t) + B*sin(2*w*t)");
    let r = residual(&check(&wrong), "by_hand").unwrap();
    assert!(r > 1e-3, "{r}");
}

/// The initial-state check names the constraint with the largest residual, position or
/// velocity, and prefers a NaN (a start outside a constraint's domain) to any number.
#[test]
fn the_initial_check_names_the_worst_constraint() {
    let model = |a: &str, initial: &str| {
        format!(
            "name: three\nparameters: {{ m: 1.0 }}\ncoordinates: [x, y, z]\npoints: {{ P: [x, y], Q: [z, 0] }}\nbodies: {{ p: {{ mass: m, at: P }}, q: {{ mass: m, at: Q }} }}\nconstraints:\n  a: {a}\n  b: y - 2\nnonholonomic:\n  n: z_dot - x_dot\ninitial: {{ {initial} }}\n"
        )
    };
    for (a, initial, name, residual, velocity) in [
        ("x - 1", "x: 1, y: 2.5, z: 0", "b", 0.5, false),
        ("x - 1", "x: 1.2, y: 2.5, z: 0", "b", 0.5, false),
        ("x - 1", "x: 1.5, y: 2.2, z: 0", "a", 0.5, false),
        ("x - 1", "x: 1, y: 2, z: 0, z_dot: 0.3", "n", 0.3, true),
        ("x - 1", "x: 1, y: 2, z: 0, y_dot: 0.7", "b", 0.7, true),
        ("sqrt(x) - 1", "x: -1, y: 2.5, z: 0", "a", f64::NAN, false),
        ("y - 2 + sqrt(x)", "x: 4, y: 1, z: 0", "a", 1.0, false),
    ] {
        let report = check(&model(a, initial));
        let found = report.initial_constraints.expect("checked");
        let same = if residual.is_nan() {
            found.residual.is_nan()
        } else {
            (found.residual - residual).abs() < 1e-12
        };
        assert!(
            found.constraint == name && same && found.velocity == velocity,
            "{initial}: {found:?}"
        );
    }
}

/// An event that uses an acceleration or a constraint force needs them solved first; one in
/// the state alone does not.
#[test]
fn events_on_accelerations_or_constraint_forces_are_told_apart() {
    use eomgen_symbolic::mechanics::SymbolicModel;
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");
    let source = std::fs::read_to_string(format!("{dir}/simple_pendulum_cartesian.yaml")).unwrap();
    assert!(source.contains("\n  rod: "));
    for (event, needs) in [
        ("x", false),
        ("x_dot - y", false),
        ("x_ddot", true),
        ("lambda_rod", true),
    ] {
        let text = format!("{}\nevents:\n  e: {{ when: {event} }}\n", source.trim_end())
            .replace("units: SI\n", "");
        let file = eomgen_symbolic::model::load("m.yaml", &text).expect("loads");
        let model = SymbolicModel::from_file(&file).unwrap();
        assert_eq!(model.events_need_accelerations(), needs, "{event}");
    }
}

/// A velocity constraint that is not linear in the rates is one error, not also "redundant"
/// (its row `∂g/∂q̇ = (2ẋ, 0)` is parallel to the holonomic one's).
#[test]
fn a_nonlinear_velocity_constraint_is_one_error() {
    let src = "name: x\nparameters: { m: 1.0 }\ncoordinates: [x, y]\npoints: { P: [x, y] }\nbodies: { b: { mass: m, at: P } }\nconstraints:\n  a: x - 1\nnonholonomic:\n  n: x_dot*x_dot\n";
    let file = eomgen_symbolic::model::load("m.yaml", src).expect("loads");
    let errors = eomgen_symbolic::mechanics::SymbolicModel::from_file(&file).expect_err("refused");
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(
        errors[0].message.contains("not linear in the rates"),
        "{errors:?}"
    );
}

/// A torque on the second body (the forearm of the double pendulum) enters the balances
/// that take that body, and only those: both balances still agree with Lagrange.
#[test]
fn a_torque_on_the_second_body_enters_its_balances() {
    let driven = common::double_pendulum_with_forearm_torque();
    let report = check(&driven);
    let r = residual(&report, "balances").expect("compared");
    assert!(r < 1e-9, "{r}: {:?}", report.notes);
}

/// Issue 28: `check` drew q and q̇ in [−2, 2] whatever the model, so a valid model whose
/// domain lies outside that box (`ln(x − 10)`, `sqrt(x − 5)`, started at `x = 12`) failed
/// "over no state", and a grossly wrong hand equation in it was never compared. States are
/// now drawn about the start in `initial:`, within `2 max(1, |start|)` of it: the valid model
/// passes with states compared, the wrong equation of `tests/wrong/far_domain.yaml` is
/// caught, the same seed draws the same states, and a model started at 0 keeps the box
/// [−2, 2] (a domain of |x| < 2.5 then loses no state).
#[test]
fn issue_28_check_draws_its_states_about_the_start() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/wrong/far_domain.yaml"
    );
    let wrong = std::fs::read_to_string(path).unwrap();
    let right = wrong.replace("-1000*k/(x - 10)", "-k/(x - 10)");
    assert_ne!(right, wrong);
    let report = check(&right);
    // About half of [−12, 36] is in the domain x > 10.
    assert!(
        report.states.compared >= 5 && report.states.compared + report.states.not_finite == 20,
        "{:?}",
        report.states
    );
    assert!(residual(&report, "by_hand").unwrap() < 1e-12, "{report:?}");
    assert!(report.passed(1e-8), "{report:?}");
    let report = check(&wrong);
    assert!(report.states.compared >= 5, "{:?}", report.states);
    assert!(residual(&report, "by_hand").unwrap() > 0.5, "{report:?}");
    assert!(!report.passed(1e-8));
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("written by hand disagree with Lagrange")),
        "{:?}",
        report.notes
    );
    // The same seed, the same states (and so the same residuals).
    let again = check(&wrong);
    assert_eq!(again.states, report.states);
    assert_eq!(residual(&again, "by_hand"), residual(&report, "by_hand"));
    // Started at 0, a model is drawn in [−2, 2]: defined for |x| < 2.5, it loses no state.
    let near = "name: near\nparameters: { m: 1.0, k: 2.0 }\ncoordinates: [x]\nkinetic: m*x_dot^2/2\npotential: -k*sqrt(6.25 - x^2)\n";
    let report = check(near);
    assert_eq!((report.states.compared, report.states.drawn), (20, 20));
}

/// Issue 28: a grossly wrong hand equation passed "over 0 states" when Lagrange's `F` was
/// outside `sqrt`'s domain at every random state (`tests/wrong/sqrt_outside_domain.yaml`):
/// a check over no state is never a pass, and it says how many states were drawn and why
/// they were skipped. And a hand equation that is not finite where Lagrange's is (`asin` of
/// a number below −1) was compared as agreeing, `max` dropping its NaN: it is now a failure
/// with its own note.
#[test]
fn issue_28_no_state_compared_and_a_non_finite_hand_equation_fail() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/wrong/sqrt_outside_domain.yaml"
    );
    let report = check(&std::fs::read_to_string(path).unwrap());
    assert_eq!(report.states.drawn, 20);
    assert_eq!((report.states.compared, report.states.not_finite), (0, 20));
    assert!(!report.passed(1e-8), "{report:?}");
    let reason = report.states.nothing_compared().expect("a reason");
    assert!(
        reason.starts_with("no state compared: of 20 random states")
            && reason.contains("20 had a non-finite Lagrange M or F"),
        "{reason}"
    );

    // cos(asin(u))² + u² = 1 where |u| ≤ 1, NaN elsewhere: x/10 − 3 is below −2.8 at every
    // state drawn (|x| ≤ 2), so the hand equation is NaN where Lagrange's is finite.
    let undefined = "name: u\nparameters: { m: 1.0, k: 10.0 }\ncoordinates: [x]\nkinetic: m*x_dot^2/2\npotential: k*x^2/2\nchecks:\n  equations_of_motion:\n    - m*x_ddot = -k*x*(cos(asin(x/10 - 3))^2 + (x/10 - 3)^2)\ninitial: { x: 1 }\n";
    let report = check(undefined);
    assert_eq!(report.states.compared, 20);
    assert!(residual(&report, "by_hand").unwrap().is_nan());
    assert!(!report.passed(1e-8));
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.starts_with("the equations of motion written by hand are not finite")),
        "{:?}",
        report.notes
    );
    // Where the hand equation is defined (x/10 − 3 in [−1, 1], here u = x/10 with |u| ≤ 0.2)
    // it is Lagrange's, and the check passes.
    let defined = undefined.replace("x/10 - 3", "x/10");
    assert!(check(&defined).passed(1e-8));
}
