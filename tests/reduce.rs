//! Method II.2 (lectures 8–10, HW13): `eomgen_symbolic::model::reduce::reduce` eliminates the
//! holonomic constraints and the dependent coordinates of a model file. Each reduced file is
//! compiled at run time and compared with an independent model: the bundled pendulum in its
//! horizontal coordinate (`simple_pendulum_y`, written by hand), the DAE of the Cartesian
//! pendulum (the KKT solve with the rod's multiplier), and the closed forms of the two masses
//! joined by a rod.

use eomgen::{
    DormandPrince54, DynFirstOrder, Integrator, IntegratorOptions, JitModel, ModelInfo, OutputTimes,
};
use eomgen_symbolic::model::reduce::{
    Branch, BranchReason, ReduceError, ReduceOptions, reduce, write_model,
};
use eomgen_symbolic::model::{Contact, Expr, Gap, ModelFile};

fn source(name: &str) -> &'static str {
    eomgen::models::find(name).expect("bundled model").source()
}

fn file(name: &str, text: &str) -> ModelFile {
    eomgen_symbolic::model::load(name, text).unwrap_or_else(|d| panic!("{name}: {d:?}"))
}

fn bundled(name: &str) -> ModelFile {
    file(name, source(name))
}

fn compile(text: &str) -> Box<dyn ModelInfo> {
    let model =
        JitModel::from_source("reduced.yaml", text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    Box::new(DynFirstOrder::new(model))
}

fn bundled_model(name: &str) -> Box<dyn ModelInfo> {
    (eomgen::models::find(name).expect("bundled model").make)()
}

/// `(q̇, q̈)` of the first-order form at `y`.
fn rhs(m: &mut dyn ModelInfo, t: f64, y: &[f64]) -> Vec<f64> {
    let mut dy = vec![0.0; y.len()];
    m.as_ode_mut()
        .rhs(t, y, &mut dy)
        .expect("finite right-hand side");
    dy
}

/// Deterministic states: `u` in `(−0.9 ℓ, 0.9 ℓ)` and `u̇` in `(−3, 3)` m/s on a
/// low-discrepancy sequence (the golden-ratio additive recurrence).
fn states(l: f64, n: usize) -> Vec<(f64, f64)> {
    let phi = 0.618_033_988_749_895_f64;
    (0..n)
        .map(|k| {
            let a = (0.5 + k as f64 * phi).fract();
            let b = (0.25 + k as f64 * phi * phi).fract();
            (0.9 * l * (2.0 * a - 1.0), 3.0 * (2.0 * b - 1.0))
        })
        .collect()
}

fn keep_x() -> eomgen_symbolic::model::reduce::ReducedModel {
    let options = ReduceOptions {
        initial: vec![("x".into(), "l/2".into())],
        ..ReduceOptions::default()
    };
    reduce(&bundled("simple_pendulum_cartesian"), &["x"], &options).expect("reduces")
}

/// HW13: the Cartesian pendulum reduced to `x` is the bundled pendulum in its horizontal
/// coordinate, `simple_pendulum_y` (written by hand). The branch is the hanging one, chosen
/// by the equilibrium `hanging` because the file's start `x = ℓ` is where the branches meet;
/// that start is singular for the reduced file (an error without a new start).
///
/// Equations: symbolically, the printed `M` and `F` are `simple_pendulum_y`'s with `y`
/// renamed `x`; numerically, `ẍ` of both compiled models at 400 states agree to 1e-12
/// relative (the same rational function; M ≤ 1/(1 − 0.81) ≈ 5 keeps rounding near 1e-15).
/// Trajectories: both from `x = ℓ/2` at rest, Dormand–Prince 5(4) at 1e-10 over 3 s, agree
/// to 1e-7 m (each is within ~1e-9 of the exact motion).
#[test]
fn cartesian_pendulum_in_x_is_simple_pendulum_y() {
    let reduced = keep_x();
    let e = &reduced.eliminations[0];
    assert_eq!((e.coordinate.as_str(), e.constraint.as_str()), ("y", "rod"));
    assert_eq!(e.solution, "-sqrt(l^2 - x^2)");
    assert_eq!(
        e.branch,
        Some((Branch::Minus, BranchReason::Equilibrium("hanging".into())))
    );
    assert!(e.squared && e.degree == 2);
    assert!(matches!(
        reduce(
            &bundled("simple_pendulum_cartesian"),
            &["x"],
            &ReduceOptions::default()
        ),
        Err(ReduceError::SingularStart { .. })
    ));

    let rename = |text: &String| -> String {
        // Whole identifiers only: `y` → `x`, `y_dot` → `x_dot`.
        let mut out = String::new();
        let mut word = String::new();
        for c in text.chars().chain(std::iter::once(' ')) {
            if c.is_ascii_alphanumeric() || c == '_' {
                word.push(c);
                continue;
            }
            out.push_str(match word.as_str() {
                "y" => "x",
                "y_dot" => "x_dot",
                w => w,
            });
            word.clear();
            out.push(c);
        }
        out.pop();
        out
    };
    let (m, f) = equations(&bundled("simple_pendulum_y"));
    let renamed = (
        m.iter()
            .map(|row| row.iter().map(rename).collect())
            .collect::<Vec<Vec<String>>>(),
        f.iter().map(rename).collect::<Vec<String>>(),
    );
    assert_eq!(equations(&reduced.file), renamed);

    let mut mine = compile(&reduced.text);
    let mut hand = bundled_model("simple_pendulum_y");
    assert_eq!(mine.num_dofs(), 1);
    for (x, xd) in states(1.0, 400) {
        let (a, b) = (
            rhs(mine.as_mut(), 0.0, &[x, xd]),
            rhs(hand.as_mut(), 0.0, &[x, xd]),
        );
        assert!(
            (a[1] - b[1]).abs() <= 1e-12 * b[1].abs().max(1.0),
            "x = {x}, x_dot = {xd}: {} vs {}",
            a[1],
            b[1]
        );
    }

    let y0 = mine.initial_state();
    assert_eq!(y0, hand.initial_state());
    let times: Vec<f64> = (1..=30).map(|k| 0.1 * f64::from(k)).collect();
    let options = IntegratorOptions::default()
        .with_rtol(1e-10)
        .with_atol(1e-10);
    let run = |m: &mut dyn ModelInfo| {
        DormandPrince54::new()
            .integrate(
                m.as_ode_mut(),
                0.0,
                &y0,
                3.0,
                &OutputTimes::At(times.clone()),
                &options,
            )
            .expect("integrates")
    };
    let (a, b) = (run(mine.as_mut()), run(hand.as_mut()));
    for ((t, ya), (_, yb)) in a.iter().zip(b.iter()) {
        assert!(
            (ya[0] - yb[0]).abs() <= 1e-7,
            "t = {t}: {} vs {}",
            ya[0],
            yb[0]
        );
    }
}

/// Both reduced forms against the DAE they came from: at consistent states (the dependent
/// coordinate and rate from the constraint, by hand), the kept coordinate's acceleration of
/// the reduced model equals the DAE's (the KKT solve with the rod tension). Keeping `y` takes
/// the branch `x = +√(ℓ² − y²)` of the start `(ℓ, 0)`. Tolerance 1e-10 relative: the KKT solve
/// of a well-conditioned 3 × 3 system against a closed-form quotient.
#[test]
fn reduced_forms_agree_with_the_dae() {
    let mut dae = bundled_model("simple_pendulum_cartesian");
    let l = 1.0;
    // Keep x: y = −√(ℓ² − x²).
    let mut x_form = compile(&keep_x().text);
    for (x, xd) in states(l, 200) {
        let y = -(l * l - x * x).sqrt();
        let yd = -x * xd / y;
        let full = rhs(dae.as_mut(), 0.0, &[x, y, xd, yd]);
        let mine = rhs(x_form.as_mut(), 0.0, &[x, xd]);
        assert!(
            (mine[1] - full[2]).abs() <= 1e-10 * full[2].abs().max(1.0),
            "x = {x}: {} vs {}",
            mine[1],
            full[2]
        );
    }
    // Keep y: x = +√(ℓ² − y²), from the initial state.
    let reduced = reduce(
        &bundled("simple_pendulum_cartesian"),
        &["y"],
        &ReduceOptions::default(),
    )
    .expect("reduces");
    let e = &reduced.eliminations[0];
    assert_eq!(e.solution, "sqrt(l^2 - y^2)");
    assert_eq!(e.branch, Some((Branch::Plus, BranchReason::InitialState)));
    let mut y_form = compile(&reduced.text);
    for (y, yd) in states(l, 200) {
        let x = (l * l - y * y).sqrt();
        let xd = -y * yd / x;
        let full = rhs(dae.as_mut(), 0.0, &[x, y, xd, yd]);
        let mine = rhs(y_form.as_mut(), 0.0, &[y, yd]);
        assert!(
            (mine[1] - full[3]).abs() <= 1e-10 * full[3].abs().max(1.0),
            "y = {y}: {} vs {}",
            mine[1],
            full[3]
        );
    }
}

/// The linearisation of the reduced pendulum at `hanging` (x = 0) gives `ω = √(g/ℓ)`, the
/// file's `natural_frequencies` check, which the reduced file keeps: `K/M` from
/// `−∂F/∂x` and `M` at rest, to 1e-12 relative.
#[test]
fn reduced_pendulum_has_the_natural_frequency() {
    let reduced = keep_x();
    assert!(
        reduced
            .file
            .checks
            .natural_frequencies
            .as_ref()
            .is_some_and(|c| c.at.as_ref().is_some_and(|a| a.value == "hanging"))
    );
    let m = compile(&reduced.text);
    let (mass, _) = m.mass_matrix_and_forcing(0.0, &[0.0, 0.0]);
    let (dq, _) = m.forcing_jacobians(0.0, &[0.0, 0.0]);
    let omega = (-dq[(0, 0)] / mass[(0, 0)]).sqrt();
    let expected = (10.0f64 / 1.0).sqrt();
    assert!((omega - expected).abs() <= 1e-12 * expected, "{omega}");
}

/// HW10's rod `x2 − x1 − l0 = 0` is linear: `x2 = x1 + l0`, and the reduced model is one
/// mass `m1 + m2` pushed by `F0`: `M = m1 + m2`, `ẍ1 = F0/(m1 + m2)` for `t ≥ 0`, and at
/// `t1` the file's `final_state` value `x1 = F0 t1²/(2 (m1 + m2))` (Dormand–Prince 5(4) at
/// 1e-10 on a quadratic: exact to rounding, 1e-9).
#[test]
fn two_masses_rod_reduces_to_the_combined_mass() {
    let reduced = reduce(
        &bundled("two_masses_rod"),
        &["x1"],
        &ReduceOptions::default(),
    )
    .expect("reduces");
    let e = &reduced.eliminations[0];
    assert_eq!(
        (e.solution.as_str(), e.rate.as_str()),
        ("x1 + l0", "x1_dot")
    );
    assert_eq!((e.degree, e.branch.clone()), (1, None));
    let mut m = compile(&reduced.text);
    let (m1, m2, f0, t1) = (1.0, 1.0, 1.0, 2.0);
    let (mass, forcing) = m.mass_matrix_and_forcing(0.5, &[0.3, -0.2]);
    assert!((mass[(0, 0)] - (m1 + m2)).abs() <= 1e-15);
    assert!((forcing[0] - f0).abs() <= 1e-15);
    assert!((rhs(m.as_mut(), 0.5, &[0.3, -0.2])[1] - f0 / (m1 + m2)).abs() <= 1e-15);
    let y0 = m.initial_state();
    let options = IntegratorOptions::default()
        .with_rtol(1e-10)
        .with_atol(1e-10);
    let s = DormandPrince54::new()
        .integrate(
            m.as_ode_mut(),
            0.0,
            &y0,
            t1,
            &OutputTimes::At(vec![t1]),
            &options,
        )
        .expect("integrates");
    let (_, y) = s.iter().last().expect("a sample");
    let expected = f0 * t1 * t1 / (2.0 * (m1 + m2));
    assert!((y[0] - expected).abs() <= 1e-9, "{} vs {expected}", y[0]);
}

/// A constraint the elimination cannot solve is an error naming the constraint and the
/// coordinate: transcendental in it, or of degree 3; and the argument errors.
#[test]
fn unsolvable_constraints_are_clear_errors() {
    let text = source("simple_pendulum_cartesian");
    for (constraint, says) in [
        ("x - l*sin(y/l)", "sin(y/l)"),
        ("x^3 + y^3 - l^3", "degree 3"),
    ] {
        let changed = text.replace("sqrt(x^2 + y^2) - l", constraint);
        let err = reduce(
            &file("changed.yaml", &changed),
            &["x"],
            &ReduceOptions::default(),
        )
        .unwrap_err();
        match &err {
            ReduceError::Unsolvable {
                constraint,
                coordinate,
                ..
            } => assert_eq!((constraint.as_str(), coordinate.as_str()), ("rod", "y")),
            other => panic!("{other}"),
        }
        let message = err.to_string();
        assert!(
            message.contains("`rod`") && message.contains("`y`") && message.contains(says),
            "{message}"
        );
    }
    let pendulum = bundled("simple_pendulum_cartesian");
    assert!(matches!(
        reduce(&pendulum, &["x", "y"], &ReduceOptions::default()),
        Err(ReduceError::WrongCount { .. })
    ));
    assert!(matches!(
        reduce(&pendulum, &["z"], &ReduceOptions::default()),
        Err(ReduceError::UnknownCoordinate { .. })
    ));
    assert!(matches!(
        reduce(
            &bundled("simple_pendulum"),
            &["q"],
            &ReduceOptions::default()
        ),
        Err(ReduceError::NoConstraints { .. })
    ));
}

/// The equations a model file gives, printed (Lagrange or momentum balance, as generated code
/// uses): `(M, F)` as text.
fn equations(file: &ModelFile) -> (Vec<Vec<String>>, Vec<String>) {
    use eomgen_symbolic::codegen::EquationsListing;
    use eomgen_symbolic::expr::print::Syntax;
    let mut model = eomgen_symbolic::mechanics::SymbolicModel::from_file(file).expect("lowers");
    let (eom, _) = eomgen_symbolic::mechanics::preferred_equations(&mut model);
    let listing = EquationsListing::of(&model, &eom, Syntax::Text);
    (listing.mass_matrix, listing.forcing)
}

/// The written file round-trips: the reduced text loaded and written again
/// ([`write_model`]) is the same text but for the header comments, and loads to the same
/// equations (printed `M` and `F` equal). A bundled file with its constraint
/// (`two_masses_rod`) written as it is gives its own equations back too.
#[test]
fn written_file_round_trips() {
    let reduced = keep_x();
    let (again, _) = write_model(&reduced.file).expect("writes");
    let body: String = reduced
        .text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(again, body);
    let reloaded = file("again.yaml", &again);
    assert_eq!(equations(&reduced.file), equations(&reloaded));

    let rod = bundled("two_masses_rod");
    let (text, _) = write_model(&rod).expect("writes");
    assert_eq!(equations(&rod), equations(&file("rod.yaml", &text)));
}

fn eomgen(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args(args)
        .output()
        .expect("runs")
}

/// The command line: `reduce -o` writes a file that `check`, `simulate` and `modes` accept
/// (exit 0; `modes` prints `√(g/ℓ)` = 3.1622776602 rad/s); the singular start is exit 1
/// naming `--initial`, an unsolvable constraint exit 1 naming it, a wrong `--keep` exit 2.
#[test]
fn the_command_writes_a_file_the_other_commands_run() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let out = dir.path().join("pendulum_x.yaml");
    let out = out.to_str().expect("a UTF-8 path");
    let made = eomgen(&[
        "reduce",
        "simple_pendulum_cartesian",
        "--keep",
        "x",
        "--initial",
        "x=l/2",
        "-o",
        out,
    ]);
    assert!(made.status.success(), "{made:?}");
    for args in [vec!["check", out], vec!["simulate", out, "--t-end", "1"]] {
        let run = eomgen(&args);
        assert!(run.status.success(), "{args:?}: {run:?}");
    }
    let modes = eomgen(&["modes", out]);
    assert!(modes.status.success(), "{modes:?}");
    assert!(String::from_utf8_lossy(&modes.stdout).contains("3.1622776602"));

    let singular = eomgen(&["reduce", "simple_pendulum_cartesian", "--keep", "x"]);
    assert_eq!(singular.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&singular.stderr).contains("--initial x="));
    let unsolvable = eomgen(&["reduce", "four_bar", "--keep", "theta1"]);
    assert_eq!(unsolvable.status.code(), Some(1), "{unsolvable:?}");
    assert!(String::from_utf8_lossy(&unsolvable.stderr).contains("cannot be solved for"));
    let wrong = eomgen(&["reduce", "simple_pendulum_cartesian", "--keep", "z"]);
    assert_eq!(wrong.status.code(), Some(2));
    // Usage errors of the options, each named, exit 2: a name that is not one, a start where
    // the eliminated `y = −√(ℓ² − x²)` is not real (x = 2 > ℓ = 1), a branch given twice.
    for (extra, says) in [
        (
            &["--name", "Bad-Name"][..],
            "`Bad-Name` is not a model name",
        ),
        (&["--initial", "x=2"][..], "l^2 - x^2 = -3 < 0: no real `y`"),
        (
            &["--branch", "y=-", "--branch", "y=+"][..],
            "a branch is given twice for `y`",
        ),
    ] {
        let mut args = vec!["reduce", "simple_pendulum_cartesian", "--keep", "x"];
        if extra[0] != "--initial" {
            args.extend(["--initial", "x=0.3"]);
        }
        args.extend(extra);
        let out = eomgen(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
}

/// `study constraint-methods`' II.2 row, through the library: the reduced model compiled at
/// run time ([`eomgen::reduction::reduced_twin`]). On HW10's rod (`x2 = x1 + l0`) it is exact:
/// the motion is a quadratic in t, which Dormand–Prince 5(4) integrates to rounding, so its
/// point error against the reference is below 1e-10 m (the DAE's is ~3e-14). On the pendulum
/// released horizontally the start `x = ℓ` is singular for the x-form, so `y` is kept, with
/// `x = +√(ℓ² − y²)`: it follows the reference to 1e-4 m over 0.5 s, and fails before 1 s,
/// at the bottom (a quarter period, 0.586 s), where `x` reaches 0 and the coordinate fails.
#[test]
fn the_study_runs_the_reduced_model_as_method_ii_2() {
    use eomgen::analysis::{ConstraintMethodsOptions, constraint_methods_with_reduced};
    let study = |name: &str, t_end: f64| {
        let source = eomgen::ModelSource::open(name).expect("bundled");
        let reduced = eomgen::reduction::reduced_twin(&source).expect("reduces");
        let options = ConstraintMethodsOptions {
            t_end,
            stiffness: vec![1e4],
            ..ConstraintMethodsOptions::default()
        };
        let label = reduced.label();
        let study = constraint_methods_with_reduced(
            &mut || source.instantiate(),
            Some((&label, reduced.instantiate())),
            None,
            &options,
        )
        .expect("runs");
        (label, study.rows.last().expect("the II.2 row").clone())
    };
    let (kept, row) = study("two_masses_rod", 5.0);
    assert_eq!(kept, "x1");
    assert!(row.method.starts_with("II.2"), "{}", row.method);
    assert!(
        row.failure.is_none() && row.position_error < 1e-10,
        "{row:?}"
    );
    assert!(row.drift.is_none());

    let (kept, row) = study("simple_pendulum_cartesian", 0.5);
    assert_eq!(kept, "y");
    assert!(
        row.failure.is_none() && row.position_error < 1e-4,
        "{row:?}"
    );
    let (_, row) = study("simple_pendulum_cartesian", 1.0);
    assert!(row.failure.is_some(), "{row:?}");
}

/// Two constraints eliminated one after the other: a double pendulum in Cartesian
/// coordinates keeps `x1, x2`; `y1 = −√(ℓ1² − x1²)` is substituted into the second rod before
/// it is solved, `y2 = y1 − √(ℓ2² − (x2 − x1)²)` (both hanging branches, the start's). At
/// 100 consistent states near the start (dependent values and rates by hand) the kept
/// accelerations equal the DAE's (KKT solve, two multipliers) to 1e-9 relative.
#[test]
fn two_constraints_are_eliminated_in_turn() {
    let text = "name: double_pendulum_cartesian
description: Two bobs on rods in Cartesian coordinates.
parameters: { m1: 1.0, m2: 2.0, l1: 1.0, l2: 0.5, g: 10.0 }
coordinates: [x1, y1, x2, y2]
points: { O: [0, 0], P1: [x1, y1], P2: [x2, y2] }
bodies: { b1: { mass: m1, at: P1 }, b2: { mass: m2, at: P2 } }
gravity: [0, -g]
constraints:
  upper: x1^2 + y1^2 - l1^2
  lower: sqrt((x2 - x1)^2 + (y2 - y1)^2) - l2
initial: { x1: 0.6, y1: -0.8, x2: 0.9, y2: -1.2 }
";
    let reduced = reduce(
        &file("dp.yaml", text),
        &["x1", "x2"],
        &ReduceOptions::default(),
    )
    .expect("reduces");
    let solved: Vec<&str> = reduced
        .eliminations
        .iter()
        .map(|e| e.coordinate.as_str())
        .collect();
    assert_eq!(solved, ["y1", "y2"]);
    let mut dae = compile(text);
    let mut mine = compile(&reduced.text);
    let (l1, l2) = (1.0f64, 0.5f64);
    for (k, (u, ud)) in states(1.0, 100).into_iter().enumerate() {
        let x1 = 0.6 + 0.2 * u;
        let x2 = x1 + 0.3 + 0.1 * (k as f64 * 0.37).sin();
        let (x1d, x2d) = (ud, -0.5 * ud + 0.3);
        let y1 = -(l1 * l1 - x1 * x1).sqrt();
        let y2 = y1 - (l2 * l2 - (x2 - x1).powi(2)).sqrt();
        let y1d = -x1 * x1d / y1;
        let y2d = y1d - (x2 - x1) * (x2d - x1d) / (y2 - y1);
        let full = rhs(dae.as_mut(), 0.0, &[x1, y1, x2, y2, x1d, y1d, x2d, y2d]);
        let kept = rhs(mine.as_mut(), 0.0, &[x1, x2, x1d, x2d]);
        for (a, b) in [(kept[2], full[4]), (kept[3], full[6])] {
            assert!(
                (a - b).abs() <= 1e-9 * b.abs().max(1.0),
                "x1 = {x1}, x2 = {x2}: {a} vs {b}"
            );
        }
    }
}

/// The writer on every bundled model: writing the text read back gives the same text; the
/// text, compiled, describes the same model (names, points, drawing with its wheels' rims,
/// bodies' centres, constraints, equilibria with their guesses, rates and ignorable
/// coordinates, events by name and direction, outputs; `checks: equations_of_motion`,
/// `floquet:` and `balances:` left out as the writer notes) and gives the same points'
/// positions, kinetic and potential energy, `M`, `F`, constraint values `Φ`, Jacobian `J`,
/// velocity residuals and `γ` at 20 states about the start (to 1e-12 relative: the same
/// expressions, derived from sections in another order). Event functions are compared by
/// name only.
/// Every section is covered: the energy form, frames, points in frames and wheel contacts,
/// planar and 3-D bodies, springs, dampers, forces and torques (in frames too), interactions,
/// outputs, constraints on expressions and on points, rolling contacts and other
/// non-holonomic constraints, drawn wheels, events, equilibria and checks.
#[test]
fn the_writer_round_trips_the_bundled_models() {
    for entry in eomgen::models::ALL {
        let original = bundled(entry.name);
        let (text, _) = write_model(&original).unwrap_or_else(|e| panic!("{}: {e}", entry.name));
        let again = file(entry.name, &text);
        let (twice, _) = write_model(&again).expect("writes again");
        assert_eq!(twice, text, "{}", entry.name);
        let (a, b) = (bundled_model(entry.name), compile(&text));
        let y0 = a.initial_state();
        assert_eq!(y0, b.initial_state(), "{}", entry.name);
        let (da, db) = (a.description(), b.description());
        assert_eq!(
            (&da.name, &da.coordinates, &da.parameters, &da.points),
            (&db.name, &db.coordinates, &db.parameters, &db.points),
            "{}",
            entry.name
        );
        assert_eq!(
            (
                &da.draw_lines,
                &da.trace_points,
                &da.body_centres,
                &da.constraints
            ),
            (
                &db.draw_lines,
                &db.trace_points,
                &db.body_centres,
                &db.constraints
            ),
            "{}",
            entry.name
        );
        assert_eq!(
            (
                da.holonomic_constraints,
                &da.initial_guesses,
                &da.equilibria
            ),
            (
                db.holonomic_constraints,
                &db.initial_guesses,
                &db.equilibria
            ),
            "{}",
            entry.name
        );
        assert_eq!(
            (&da.events, &da.outputs, da.conservative),
            (&db.events, &db.outputs, db.conservative),
            "{}",
            entry.name
        );
        assert_eq!(
            (&da.ignorable_coordinates, da.equilibrium_rates),
            (&db.ignorable_coordinates, db.equilibrium_rates),
            "{}",
            entry.name
        );
        let (ga, gb) = (a.equilibrium_guesses(), b.equilibrium_guesses());
        let (ra, rb) = (a.equilibrium_rates(), b.equilibrium_rates());
        assert_eq!((ga.len(), ra.len()), (gb.len(), rb.len()), "{}", entry.name);
        let equilibria = |g: &[(&str, Vec<f64>)], r: &[Vec<f64>]| -> Vec<f64> {
            g.iter()
                .flat_map(|(_, q)| q.clone())
                .chain(r.iter().flatten().copied())
                .collect()
        };
        for (p, q) in equilibria(&ga, &ra).into_iter().zip(equilibria(&gb, &rb)) {
            assert!(
                p == q || (p - q).abs() <= 1e-12 * p.abs().max(1.0),
                "{}: equilibrium {p} vs {q}",
                entry.name
            );
        }
        for k in 0..20 {
            let y: Vec<f64> = y0
                .iter()
                .enumerate()
                .map(|(i, v)| v + 0.1 * ((k * 7 + i * 3) as f64).sin())
                .collect();
            let t = 0.05 * k as f64;
            let ((ma, fa), (mb, fb)) = (
                a.mass_matrix_and_forcing(t, &y),
                b.mass_matrix_and_forcing(t, &y),
            );
            let energies = |m: &dyn ModelInfo| [m.kinetic_energy(t, &y), m.potential_energy(t, &y)];
            for (p, q) in energies(a.as_ref()).into_iter().zip(energies(b.as_ref())) {
                assert!(
                    p == q || (p - q).abs() <= 1e-12 * p.abs().max(1.0),
                    "{}: energy {p} vs {q} at {y:?}",
                    entry.name
                );
            }
            let (pa, pb) = (a.point_positions(t, &y), b.point_positions(t, &y));
            assert_eq!(pa.len(), pb.len(), "{}", entry.name);
            for (p, q) in pa.iter().flatten().zip(pb.iter().flatten()) {
                assert!(
                    p == q || (p - q).abs() <= 1e-12 * p.abs().max(1.0),
                    "{}: point {p} vs {q} at {y:?}",
                    entry.name
                );
            }
            let (ca, cb) = (a.constraint_equations(t, &y), b.constraint_equations(t, &y));
            let a_values = ma.iter().chain(fa.iter()).chain(ca.phi.iter());
            let a_values = a_values.chain(ca.jacobian.iter()).chain(ca.velocity.iter());
            let b_values = mb.iter().chain(fb.iter()).chain(cb.phi.iter());
            let b_values = b_values.chain(cb.jacobian.iter()).chain(cb.velocity.iter());
            assert_eq!(ca.gamma.len(), cb.gamma.len(), "{}", entry.name);
            let (a_values, b_values) = (
                a_values.chain(ca.gamma.iter()).collect::<Vec<_>>(),
                b_values.chain(cb.gamma.iter()).collect::<Vec<_>>(),
            );
            assert_eq!(a_values.len(), b_values.len(), "{}", entry.name);
            for (p, q) in a_values.into_iter().zip(b_values) {
                assert!(
                    p == q || (p - q).abs() <= 1e-12 * p.abs().max(1.0),
                    "{}: {p} vs {q} at {y:?}",
                    entry.name
                );
            }
        }
    }
}

/// A contact as written, locations aside: its name, the form and parts of its gap, `e` and
/// `μ` (expressions by `Display`, which parses back to the same tree).
fn contact_parts(c: &Contact) -> Vec<String> {
    let list = |v: &[Expr]| {
        let parts: Vec<String> = v.iter().map(ToString::to_string).collect();
        format!("[{}]", parts.join(", "))
    };
    let gap = match &c.gap {
        Gap::Written(g) => format!("gap {g}"),
        Gap::Above {
            point,
            normal,
            through,
            disc,
        } => format!(
            "{} above normal {} through {:?} disc {:?}",
            point.value,
            list(&normal.value),
            through.as_ref().map(|o| list(&o.value)),
            disc.as_ref().map(|d| format!("{} {}", d.radius, d.angle))
        ),
        Gap::Circle {
            point,
            inside,
            centre,
            radius,
        } => format!(
            "{} {} centre {} radius {radius}",
            point.value,
            if *inside { "inside" } else { "outside" },
            list(&centre.value)
        ),
    };
    vec![
        c.name.value.clone(),
        gap,
        c.restitution.to_string(),
        format!("{:?}", c.friction.as_ref().map(ToString::to_string)),
    ]
}

/// `contacts:` round-trips: a model with a written gap and a point above a line (with and
/// without `through`), inside and outside a circle, a disc on a line, with and without
/// friction, written
/// ([`write_model`]) and read back has the same contacts (names, forms, points, vectors, `e`
/// and `μ`), and writing that again gives the same text.
#[test]
fn the_writer_round_trips_contacts() {
    let source = "name: ball_in_a_bowl\nparameters: { m: 1.0, g: 9.81, R: 2.0, e: 0.8, mu: 0.3 }\ncoordinates: [x, y]\npoints: { B: [x, y] }\nbodies: { ball: { mass: m, at: B } }\ngravity: [0, -g]\ncontacts:\n  floor: { gap: y + R/2, restitution: e }\n  wall: { point: B, above: { normal: [-1, 0], through: [R/2, 0] }, restitution: 0, friction: mu }\n  roof: { point: B, above: { normal: [0, -1] }, restitution: e^2 }\n  bowl: { point: B, inside: { centre: [0, 0], radius: R }, restitution: 1, friction: 0 }\n  post: { point: B, outside: { centre: [0, -R/2], radius: R/8 }, restitution: e/2, friction: 2*mu }\n  wheel: { disc: { centre: B, radius: R/4, angle: -x/R }, above: { normal: [0, 1], through: [0, -R] }, restitution: 0, friction: mu }\ninitial: { x: 0, y: -R/4 }\n";
    let original = file("ball_in_a_bowl.yaml", source);
    assert_eq!(original.contacts.len(), 6);
    let (text, _) = write_model(&original).expect("writes");
    let again = file("again.yaml", &text);
    let (twice, _) = write_model(&again).expect("writes again");
    assert_eq!(twice, text);
    assert!(text.contains("\ncontacts:\n"), "{text}");
    let parts = |f: &ModelFile| f.contacts.iter().map(contact_parts).collect::<Vec<_>>();
    assert_eq!(parts(&again), parts(&original), "{text}");
}

/// A dependent coordinate started as `{ guess: … }` is only near the constraint (the run
/// projects it onto it): the branch is the root nearest the guess, here the hanging
/// `y = −√(ℓ² − x²)` for a guess of −0.7 at x = 0.6 (root −0.8; the other, +0.8, is 1.5 away),
/// and the upright one for a guess of +0.7, each checked on the reduced file's start.
#[test]
fn a_guessed_start_chooses_the_nearest_branch() {
    let text = |guess: f64| {
        format!(
            "name: guessed\nparameters: {{ m: 1.0, l: 1.0, g: 10.0 }}\ncoordinates: [x, y]\npoints:\n  O: [0, 0]\n  P: [x, y]\nbodies:\n  bob: {{ mass: m, at: P }}\ngravity: [0, -g]\nconstraints:\n  rod: sqrt(x^2 + y^2) - l\ninitial: {{ x: 0.6, y: {{ guess: {guess} }} }}\n"
        )
    };
    for (guess, branch, solution) in [
        (-0.7, Branch::Minus, "-sqrt(l^2 - x^2)"),
        (0.7, Branch::Plus, "sqrt(l^2 - x^2)"),
    ] {
        let reduced = reduce(
            &file("guessed.yaml", &text(guess)),
            &["x"],
            &ReduceOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{guess}: {e}"));
        let e = &reduced.eliminations[0];
        assert_eq!(
            e.branch,
            Some((branch, BranchReason::InitialState)),
            "{guess}"
        );
        assert_eq!(e.solution, solution);
    }
}

/// Eliminating y of the spun rod divides by cos(w t): the reduced model is singular at
/// t = π/(2w), where x no longer determines the bead's place and every solution `a s + b s²`
/// (s = t − π/(2w)) passes the pole, so the motion after it is not unique. DOP853 stepped over
/// the pole and printed x(3) = −42.05 (exact r0 cosh 3 cos 3 = −9.967) with exit 0. Reduce
/// now says so (a note, a line in the file's header) and writes a terminal event that ends
/// runs there, to 1e-9 s of π/2.
#[test]
fn a_moving_singularity_is_noted_and_stops_runs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rod_x.yaml");
    let file = path.to_str().unwrap();
    let out = eomgen(&["reduce", "bead_spinning_rod", "--keep", "x", "-o", file]);
    // The notes go to standard output when the file goes to `-o`.
    let err = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{out:?}");
    assert!(
        err.contains("singular where -cos(w*t) = 0") && err.contains("`y_singular`"),
        "{err}"
    );
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("#   singular where -cos(w*t) = 0")
            && text.contains("y_singular: { when: -cos(w*t), direction: both, terminal: true }"),
        "{text}"
    );
    let out = eomgen(&[
        "simulate", file, "--t-end", "3", "--method", "dop853", "--json",
    ]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["terminated_by_event"], "y_singular", "{json}");
    let samples = json["samples"].as_array().expect("samples");
    let last = samples.last().unwrap()["t"].as_f64().unwrap();
    assert!(
        (last - std::f64::consts::FRAC_PI_2).abs() < 1e-9,
        "ran to t = {last}"
    );
}
