//! Broken model files: each gives exactly the diagnostics its header announces.
//!
//! Every file in `tests/fixtures/broken/` starts with one `# expect: LINE:COL fragment` line
//! per diagnostic, in file order, each optionally followed by `# help: fragment`. The
//! loader must report exactly these: the same number, at these locations, with messages
//! (and help) containing these fragments. Adding a case is adding a file.

use std::path::Path;

use eomgen_symbolic::model::{Diagnostic, load};

struct Expected {
    line: u32,
    column: u32,
    message: String,
    help: Vec<String>,
}

fn expectations(source: &str) -> Vec<Expected> {
    let mut out: Vec<Expected> = Vec::new();
    for line in source.lines() {
        if let Some(rest) = line.strip_prefix("# expect: ") {
            let (at, message) = rest.split_once(' ').expect("`# expect: L:C message`");
            let (l, c) = at.split_once(':').expect("`L:C`");
            out.push(Expected {
                line: l.parse().expect("line"),
                column: c.parse().expect("column"),
                message: message.to_string(),
                help: Vec::new(),
            });
        } else if let Some(help) = line.strip_prefix("# help: ") {
            out.last_mut()
                .expect("`# help:` follows an `# expect:`")
                .help
                .push(help.to_string());
        }
    }
    out
}

fn show(d: &[Diagnostic]) -> String {
    d.iter()
        .map(|d| {
            format!(
                "  {}: {}{}",
                d.location,
                d.message,
                d.help
                    .as_ref()
                    .map(|h| format!("\n      help: {h}"))
                    .unwrap_or_default()
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Checks one broken file; `Err` describes the mismatch.
fn check_case(path: &Path) -> Result<(), String> {
    let source = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let expected = expectations(&source);
    if expected.is_empty() {
        return Err(format!("{name}: no `# expect:` header"));
    }
    let got = match load(&name, &source) {
        Ok(_) => return Err(format!("{name}: loaded without errors")),
        Err(d) => d,
    };
    let ok = got.len() == expected.len()
        && got.iter().zip(&expected).all(|(d, e)| {
            d.location.line == e.line
                && d.location.column == e.column
                && d.message.contains(&e.message)
                && e.help
                    .iter()
                    .all(|h| d.help.as_deref().is_some_and(|dh| dh.contains(h.as_str())))
        });
    if ok {
        Ok(())
    } else {
        let want = expected
            .iter()
            .map(|e| format!("  {}:{}: {} {:?}", e.line, e.column, e.message, e.help))
            .collect::<Vec<_>>()
            .join("\n");
        Err(format!("{name}:\n expected\n{want}\n got\n{}", show(&got)))
    }
}

#[test]
fn every_broken_file_gives_exactly_its_expected_diagnostics() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../symbolic/tests/fixtures/broken");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .expect("fixtures/broken exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 20, "only {} broken files", paths.len());
    let failures: Vec<String> = paths.iter().filter_map(|p| check_case(p).err()).collect();
    assert!(
        failures.is_empty(),
        "{} of {} broken files do not match:\n\n{}",
        failures.len(),
        paths.len(),
        failures.join("\n\n")
    );
}

#[test]
fn a_diagnostic_renders_with_the_line_and_a_caret() {
    let src = "name: pendulum\ncoordinates: [theta]\nkinetic: theta_dot^2/2 + l*\n";
    let d = load("models/pendulum.yaml", src).unwrap_err();
    assert_eq!(d.len(), 1);
    assert_eq!(
        d[0].render("models/pendulum.yaml", src),
        "models/pendulum.yaml:3:28: expected an operand after `*`, found the end of the expression\n  \
         |\n3 | kinetic: theta_dot^2/2 + l*\n  |                            ^\n\
         = help: write a number, a name or a parenthesised expression after `*`"
    );
}

#[test]
fn schema_and_cross_object_errors_are_reported_together() {
    // An unknown key (schema) and an unknown name (checks) in one run.
    let src = "name: x\ncoordinates: [q]\nkinetic: q_dot^2/2 + a\npotential: b\nbogus: 1\n";
    let errors = load("x.yaml", src).unwrap_err();
    let at: Vec<String> = errors.iter().map(|d| d.location.to_string()).collect();
    assert_eq!(at, ["3:22", "4:12", "5:1"], "{}", show(&errors));
}

#[test]
fn a_point_left_out_by_the_schema_is_not_reported_again() {
    // `P` has a malformed expression: one error, not also "unknown point `P`" for the body,
    // the spring and the drawing.
    let src = "name: x\nparameters: { m: 1, k: 1 }\ncoordinates: [q]\npoints: { O: [0, 0], P: [q +, 0] }\nbodies: { b: { mass: m, at: P } }\nsprings: { s: { between: [O, P], stiffness: k } }\ndraw: { lines: [[O, P]] }\n";
    let errors = load("x.yaml", src).unwrap_err();
    assert_eq!(errors.len(), 1, "{}", show(&errors));
    assert_eq!(errors[0].location.to_string(), "4:29");
}

#[test]
fn a_broken_parameter_is_not_an_unknown_name_later() {
    let src = "name: x\nparameters: { m: , k: 2*m }\ncoordinates: [q]\nkinetic: m*q_dot^2/2\npotential: k*q^2/2\n";
    let errors = load("x.yaml", src).unwrap_err();
    let messages: Vec<&str> = errors.iter().map(|d| d.message.as_str()).collect();
    assert_eq!(errors.len(), 2, "{}", show(&errors));
    assert!(messages[0].contains("parameter `m` has no default value"));
    assert!(messages[1].contains("parameter defaults must be constant"));
}

/// A constraint that repeats another is redundant or contradicts it by its residual where
/// the other holds, measured against the size of its terms: at lengths of 3.3e8 (a rounding
/// residual of ~1e-7) `2*x - 2*l` is still redundant with `x - l`, and `x - l*(1 + 1e-6)`,
/// 330 away, still contradicts it (offsets below 1e-8 of the terms are taken for rounding).
#[test]
fn redundant_or_contradictory_at_any_length_scale() {
    use eomgen_symbolic::mechanics::SymbolicModel;
    let lower = |second: &str| -> String {
        let src = format!(
            "name: x\nparameters: {{ m: 1.0, l: 3.3e8 }}\ncoordinates: [x, y]\npoints: {{ P: [x, y] }}\nbodies: {{ bob: {{ mass: m, at: P }} }}\nconstraints:\n  at_l: x - l\n  again: {second}\n"
        );
        let file = load("x.yaml", &src).expect("loads");
        let errors = SymbolicModel::from_file(&file).expect_err("refused");
        assert_eq!(errors.len(), 1, "{}", show(&errors));
        errors[0].message.clone()
    };
    for (second, verdict) in [
        ("2*x - 2*l", "is redundant with `at_l`"),
        ("x/3 - l/3", "is redundant with `at_l`"),
        ("x - l*(1 + 1e-6)", "contradicts `at_l`"),
        ("x - 2*l", "contradicts `at_l`"),
    ] {
        let message = lower(second);
        assert!(message.contains(verdict), "{second}: {message}");
    }
}

/// The other cases of a dependent constraint: a velocity constraint implied by a holonomic
/// one is redundant (x = 1 gives ẋ = 0); one that contradicts two others names both ("hold");
/// a constraint on no coordinate can never hold unless it is 0.
#[test]
fn dependent_constraints_of_every_kind_are_named() {
    use eomgen_symbolic::mechanics::SymbolicModel;
    let lower = |coordinates: &str, constraints: &str| -> Vec<String> {
        let src = format!(
            "name: x\nparameters: {{ m: 1.0, l: 1.0 }}\ncoordinates: [{coordinates}]\npoints: {{ P: [x, 0] }}\nbodies: {{ bob: {{ mass: m, at: P }} }}\n{constraints}"
        );
        let file = load("x.yaml", &src).expect("loads");
        match SymbolicModel::from_file(&file) {
            Ok(_) => Vec::new(),
            Err(errors) => errors.into_iter().map(|d| d.message).collect(),
        }
    };
    let found = lower(
        "x, y",
        "constraints:\n  a: x - l\nnonholonomic:\n  n: x_dot\n",
    );
    assert!(
        found.len() == 1 && found[0].contains("`n` is redundant with `a`"),
        "{found:?}"
    );
    let found = lower(
        "x, y, z",
        "constraints:\n  a: x - l\n  b: y - l\n  c: x + y - 3*l\n",
    );
    assert!(
        found.len() == 1
            && found[0].contains("`c` contradicts `a`, `b`: where `a` and `b` hold, it is -1"),
        "{found:?}"
    );
    // A long coordinate does not scale another's constraint: with x at 3.3e8, θ = 0.5 and
    // 2θ = 1.001 still contradict (by 1e-3 rad).
    let found = lower(
        "x, theta, z",
        "constraints:\n  far: x - 3.3e8\n  b: theta - 0.5\n  c: 2*theta - 1.001\n",
    );
    assert!(
        found.len() == 1 && found[0].contains("`c` contradicts `b`"),
        "{found:?}"
    );
    let found = lower("x", "constraints:\n  c: l - 2\n");
    assert!(
        found.len() == 1 && found[0].contains("`c` can never hold") && found[0].contains("-1"),
        "{found:?}"
    );
    let found = lower("x", "constraints:\n  c: l - 1\n");
    assert!(
        found.len() == 1 && found[0].contains("`c` constrains nothing"),
        "{found:?}"
    );
}

/// Operations on numbers whose value is undefined or overflows are located errors with a
/// help that names the rule; their defined neighbours are not errors.
#[test]
fn undefined_constant_operations_are_located_errors() {
    use eomgen_symbolic::mechanics::SymbolicModel;
    let errors = |expr: &str| -> Vec<Diagnostic> {
        let src = format!(
            "name: x\nparameters: {{ k: 1.0 }}\ncoordinates: [x]\nkinetic: x_dot^2/2\npotential: k*x^2/2 + x*{expr}\n"
        );
        match load("x.yaml", &src) {
            Err(errors) => errors,
            Ok(file) => SymbolicModel::from_file(&file).err().unwrap_or_default(),
        }
    };
    for (expr, message, help) in [
        ("1/0", "division by zero", "the divisor is 0"),
        ("0^0", "`0^0` is undefined", "non-positive exponent"),
        ("0^(-1)", "`0^-1` is undefined", "non-positive exponent"),
        ("(-8)^(1/3)", "is not a real number", "only integer powers"),
        ("10^400", "power overflow", "exponent"),
        ("1e300*1e300", "product overflow", "exponent"),
        ("10^(-400)", "power underflow", "exponent"),
        ("(1e-200*1e-200)", "product underflow", "exponent"),
        ("(1e-300/1e10)", "product underflow", "exponent"),
        ("exp(-1000)", "`exp(-1000)` underflows", "argument"),
        ("1e-400", "the number `1e-400` is too small", "write 0"),
        (
            "ln(-1)",
            "`ln(-1)` is not a finite real number",
            "positive argument",
        ),
        (
            "sqrt(-1)",
            "`sqrt(-1)` is not a finite real number",
            "non-negative argument",
        ),
        (
            "asin(2)",
            "`asin(2)` is not a finite real number",
            "[-1, 1]",
        ),
        (
            "acos(-2)",
            "`acos(-2)` is not a finite real number",
            "[-1, 1]",
        ),
        ("tan(pi/2)", "", ""),
    ] {
        let found = errors(expr);
        if message.is_empty() {
            // tan(π/2) in f64 is 1.6e16: finite, not an error.
            assert!(found.is_empty(), "{expr}: {found:?}");
            continue;
        }
        assert!(
            found.len() == 1
                && found[0].message.contains(message)
                && found[0].help.as_deref().is_some_and(|h| h.contains(help))
                && found[0].location.line == 5,
            "{expr}: {found:?}"
        );
    }
    for defined in [
        "(-8)^2",
        "0^2",
        "0^0.5",
        "2^(-1)",
        "2^0.5",
        "2^3",
        "1/2",
        "ln(2)",
        "sqrt(0)",
        "(1e-150*1e-150)",
        "exp(-700)",
        "(1e-300 - 1e-300)",
        "0e-400",
        "step(-1)",
        "ln(1)",
    ] {
        let found = errors(defined);
        assert!(found.is_empty(), "{defined}: {found:?}");
    }
}

/// Issue 28: `k*x^2/2*1e-300*1e-300*1e300*1e300` folded `1e-300*1e-300` to 0, so that
/// `V = 0` and `F = 0` and every command went on. An operation on non-zero numbers whose
/// result underflows (to 0, or to a subnormal number with fewer significant bits) is a
/// located error at its operator, as overflow is; in a parameter's default too.
#[test]
fn issue_28_underflow_of_constants_is_a_located_error() {
    use eomgen_symbolic::mechanics::SymbolicModel;
    let src = "name: x\nparameters: { k: 1.0 }\ncoordinates: [x]\nkinetic: x_dot^2/2\npotential: k*x^2/2*1e-300*1e-300*1e300*1e300\n";
    let file = load("x.yaml", src).expect("loads");
    let errors = SymbolicModel::from_file(&file).expect_err("refused");
    assert_eq!(errors.len(), 1, "{}", show(&errors));
    // 1/2 · 1e-300 = 5e-301 is normal; times 1e-300 it underflows, at the second `*1e-300`.
    assert_eq!(errors[0].location.to_string(), "5:26", "{}", show(&errors));
    assert!(
        errors[0]
            .message
            .contains("the numbers in this product underflow")
            && errors[0].message.contains("2.2e-308"),
        "{}",
        show(&errors)
    );
    // A default: refused at load, at its operator.
    let src = "name: x\nparameters: { k: 1e-200*1e-200 }\ncoordinates: [x]\nkinetic: x_dot^2/2\npotential: k*x^2/2\n";
    let errors = load("x.yaml", src).expect_err("refused");
    assert_eq!(errors.len(), 1, "{}", show(&errors));
    assert_eq!(errors[0].location.to_string(), "2:24", "{}", show(&errors));
    assert!(errors[0].message.contains("underflow"), "{}", show(&errors));
}

/// Issue 28: `(x*1e-20)^16` was refused as an underflow, because the power was first pushed
/// into its factors and `1e-20^16 = 1e-320` is below the normal range, although the
/// potential evaluated as written is of order 1 for `x` near 1e20. A rewrite that would form
/// a number beyond `f64` or below its normal range is not done: the file loads and derives,
/// and `V`, `F` and `∂F/∂x` at `x = 3e20` are their closed forms (relative 1e-12). Only
/// numbers written in one operation alone are refused, as before.
#[test]
fn issue_28_a_power_of_a_scaled_coordinate_is_evaluated_as_written() {
    use eomgen_symbolic::expr::eval::Evaluator;
    use eomgen_symbolic::mechanics::{
        EquationsOfMotion, Formulation, Jacobians, Lagrange, SymbolicModel, preferred_equations,
    };
    let src = "name: x\nparameters: { k: 2.0 }\ncoordinates: [x]\nkinetic: x_dot^2/2\npotential: k*(x*1e-20)^16\n";
    let file = load("x.yaml", src).unwrap_or_else(|e| panic!("{}", show(&e)));
    let (k, x) = (2.0_f64, 3e20_f64);
    // V = k (1e-20 x)^16, F = −∂V/∂x = −16 k 1e-20 (1e-20 x)^15, ∂F/∂x = −240 k 1e-40 (1e-20 x)^14.
    let s = x * 1e-20;
    let expected = [
        k * s.powi(16),
        -16.0 * k * 1e-20 * s.powi(15),
        -240.0 * k * 1e-40 * s.powi(14),
    ];
    type Derive = fn(&mut SymbolicModel) -> EquationsOfMotion;
    let derivations: [(&str, Derive); 2] = [
        ("preferred", |m| preferred_equations(m).0),
        ("Lagrange", |m| Lagrange.derive(m)),
    ];
    for (name, derive) in derivations {
        let mut model = SymbolicModel::from_file(&file).unwrap_or_else(|e| panic!("{}", show(&e)));
        let eom = derive(&mut model);
        let jacobians = Jacobians::of(&mut model, &eom);
        let mut bindings = vec![0.0; model.arena.symbols().len()];
        bindings[model.arena.symbol_id("k").unwrap().index()] = k;
        bindings[model.arena.symbol_id("x").unwrap().index()] = x;
        let roots = [
            model.potential,
            eom.forcing[0],
            jacobians.forcing_q[0],
            eom.mass_matrix[0],
        ];
        let found = Evaluator::new(&model.arena, &roots).eval(&bindings);
        for (what, (f, e)) in ["V", "F", "dF/dx"].iter().zip(found.iter().zip(expected)) {
            assert!(
                ((f - e) / e).abs() < 1e-12,
                "{name}: {what} = {f:e}, expected {e:e}"
            );
        }
        assert_eq!(found[3], 1.0, "{name}: M");
    }
    // Numbers written in one operation alone are still refused at their operator.
    for (potential, column) in [
        ("(x*1e-20)^16*1e-300*1e-300", 31),
        ("x^2*(1e-20)^16", 23),
        ("x^2 + x*(1e-20*1e-300)", 26),
        ("(1e300*x)*1e300*1e300", 21),
    ] {
        let src =
            format!("name: x\ncoordinates: [x]\nkinetic: x_dot^2/2\npotential: {potential}\n");
        let file = load("x.yaml", &src).expect("loads");
        let errors = SymbolicModel::from_file(&file).expect_err(potential);
        assert_eq!(errors.len(), 1, "{potential}: {}", show(&errors));
        assert_eq!(
            errors[0].location.to_string(),
            format!("4:{column}"),
            "{potential}: {}",
            show(&errors)
        );
    }
}

/// A singular mass matrix is refused with its reason; a model whose `M` is singular only
/// where it never starts, or only off its constraints, is not.
#[test]
fn singular_mass_matrices_are_refused_with_their_reason() {
    use eomgen_symbolic::mechanics::cross_check::check_model;
    let check = |body: &str| -> Vec<String> {
        let src = format!("name: x\nparameters: {{ m: 1.0, k: 1.0 }}\n{body}");
        let file = load("x.yaml", &src).expect("loads");
        match check_model(&file, 5, 1) {
            Ok(_) => Vec::new(),
            Err(errors) => errors.into_iter().map(|d| d.message).collect(),
        }
    };
    let one = |found: Vec<String>, fragment: &str| {
        assert!(
            found.len() == 1 && found[0].contains(fragment),
            "{fragment}: {found:?}"
        );
    };
    one(
        check("coordinates: [x, y]\nkinetic: m*x_dot^2/2\npotential: k*(x^2 + y^2)/2\n"),
        "coordinate `y` has no inertia",
    );
    one(
        check("coordinates: [x, y]\nkinetic: m*(x_dot + y_dot)^2/2\npotential: k*(x^2 + y^2)/2\n"),
        "singular at every state tried",
    );
    one(
        check(
            "coordinates: [q]\nkinetic: m*cos(q)^2*q_dot^2/2\npotential: k*q^2/2\ninitial: { q: pi/2 }\n",
        ),
        "singular or not finite at the initial state (q = 1.57",
    );
    // Singular at t = 0 only (the start), regular at the random times in [0, 5].
    one(
        check(
            "coordinates: [q]\nkinetic: m*t^2*q_dot^2/2\npotential: k*q^2/2\ninitial: { q: 1 }\n",
        ),
        "singular or not finite at the initial state",
    );
    // A coordinate with a load but no energy has no inertia (it is not unused).
    one(
        check(
            "coordinates: [x, y]\nkinetic: m*x_dot^2/2\npotential: k*x^2/2\ngeneralized_forces: { y: -k*y }\n",
        ),
        "coordinate `y` has no inertia",
    );
    // A coordinate in no energy and no load.
    one(
        check("coordinates: [x, y]\nkinetic: m*x_dot^2/2\npotential: k*x^2/2\n"),
        "coordinate `y` appears in no energy and no load",
    );
    // M = m (1e-14 + q²), started at q = 0, is 1e-14 there, below 1e-12 of its median size
    // over the random states (about 1, q in [−2, 2]), though not of its smallest (~1e-3): the
    // reference is the median.
    one(
        check("coordinates: [q]\nkinetic: m*(1e-14 + q^2)*q_dot^2/2\npotential: k*q^2/2\n"),
        "singular or not finite at the initial state",
    );
    // M = m e^(4q) started at q = -8 is 1.3e-14 there, but the states are drawn about the
    // start (q in [−24, 8]), where that is its typical size: a light mass, not a singularity.
    assert_eq!(
        check(
            "coordinates: [q]\nkinetic: m*exp(4*q)*q_dot^2/2\npotential: k*q^2/2\ninitial: { q: -8 }\n",
        ),
        Vec::<String>::new()
    );
    // Singular only at q = 0, which the random states and the start (q = 1) avoid.
    assert_eq!(
        check(
            "coordinates: [q]\nkinetic: m*q^2*q_dot^2/2\npotential: k*q^2/2\ninitial: { q: 1 }\n"
        ),
        Vec::<String>::new()
    );
    // With x = y enforced, only x + y moves, which has inertia: the constrained system is
    // regular, and M alone is not tested.
    assert_eq!(
        check(
            "coordinates: [x, y]\npoints: { P: [x + y, 0] }\nbodies: { b: { mass: m, at: P } }\nconstraints:\n  same: x - y\n"
        ),
        Vec::<String>::new()
    );
}

/// Issue 28: a redundant constraint was reported only after an unrelated error was fixed.
/// Mistakes the derivation finds (here a constant that overflows and an equation written by
/// hand that is not linear in the accelerations) no longer stop the constraint checks: every
/// diagnostic at once. (With a unit mistake, the loader reports them together:
/// `fixtures/broken/redundant-constraint-with-a-unit-error.yaml`.)
#[test]
fn issue_28_a_redundant_constraint_is_reported_with_other_mistakes() {
    use eomgen_symbolic::mechanics::SymbolicModel;
    let src = "name: rails\nparameters: { m: 1.0, l: 1.0 }\ncoordinates: [x, y]\npoints: { P: [x, y] }\nbodies: { bead: { mass: m, at: P } }\npotential: m*y*1e300*1e300\nconstraints:\n  rail: x - l\n  again: 2*x - 2*l\nchecks:\n  equations_of_motion:\n    - m*y_ddot^2 = 0\n    - m*x_ddot = 0\n";
    let file = load("rails.yaml", src).expect("loads");
    let errors = SymbolicModel::from_file(&file).expect_err("refused");
    let at: Vec<String> = errors.iter().map(|d| d.location.to_string()).collect();
    assert_eq!(errors.len(), 3, "{}", show(&errors));
    assert!(errors[0].message.contains("overflow"), "{}", show(&errors));
    assert!(
        errors
            .iter()
            .any(|d| d.message.contains("not linear in the accelerations")),
        "{}",
        show(&errors)
    );
    assert!(
        errors.iter().any(|d| d.location.to_string() == "9:3"
            && d.message.contains("`again` is redundant with `rail`")),
        "{at:?}: {}",
        show(&errors)
    );
}
