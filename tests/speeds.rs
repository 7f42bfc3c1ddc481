//! Generalized speeds: `equations` lists Kane's equations in the speeds with the kinematic
//! equations, `check` compares them with Lagrange's carried into the speeds, the model runs
//! in the state `(q, u)` (simulations, equilibria, modes, frequency response), and what takes
//! the state `(q, q̇)` refuses it with a typed or located message instead of a wrong result.

use eomgen::analysis::{Method, SimulationError, SimulationOptions, simulate};
use eomgen::{DynFirstOrder, JitModel, ModalError, ModelInfo, OutputTimes, Stabilization};
use rand::RngExt;

use crate::common::{eomgen, eomgen_ok, seeded_rng};

mod compiled {
    eomgen::model!("fixtures/heavy_top_speeds.yaml");
}

/// A model file's text loaded at run time.
fn load(name: &str, text: &str) -> Box<dyn ModelInfo> {
    let model = JitModel::from_source(name, text).unwrap_or_else(|e| panic!("{name}: {e}"));
    Box::new(DynFirstOrder::new(model))
}

/// A fixture's text without its `speeds:` block (the same model in the coordinates' rates),
/// its `initial:` speed `w1` written as the rate it equals at the start (`theta_dot`: at
/// phi = psi = 0 in z-x-y angles the body's x axis is the axis theta turns about).
fn in_rates(text: &str) -> String {
    let mut out = String::new();
    let mut skipping = false;
    for line in text.lines() {
        if line.starts_with("speeds:") {
            skipping = true;
            continue;
        }
        if skipping && line.starts_with("  ") {
            continue;
        }
        skipping = false;
        out.push_str(&line.replace("w1: 0.5", "theta_dot: 0.5"));
        out.push('\n');
    }
    out
}

fn fixture(name: &str) -> String {
    format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// `text` written as `name` in the temporary directory `dir`; its path.
fn written(dir: &tempfile::TempDir, name: &str, text: &str) -> String {
    let path = dir.path().join(name);
    std::fs::write(&path, text).expect("written");
    path.to_str().expect("a path").to_string()
}

/// The heavy top in body rates lists Euler's equations about its pivot (the closed form is
/// checked at random states in `symbolic/tests/speeds.rs`; here, what is printed) and the
/// kinematic equations of z-x-z angles; both derivations agree in `check`.
#[test]
fn a_top_in_body_rates_lists_and_checks_kanes_equations() {
    let top = fixture("heavy_top_speeds.yaml");
    let out = eomgen_ok(&["equations", &top]);
    let text = String::from_utf8_lossy(&out.stdout);
    for line in [
        "u = [w1, w2, w3]",
        "  theta' = cos(psi)*w1 - sin(psi)*w2",
        "M u' = F with",
        "  M[0,0] = I1",
        "  M[0,1] = 0",
        "  M[2,2] = I3",
        "  F[2] = 0",
    ] {
        assert!(
            text.lines().any(|l| l == line),
            "no line `{line}` in:\n{text}"
        );
    }
    let out = eomgen_ok(&["equations", &top, "--latex"]);
    let latex = String::from_utf8_lossy(&out.stdout);
    assert!(latex.contains("\\dot{\\theta} = "), "{latex}");
    let out = eomgen_ok(&["equations", &top, "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(
        json["equations"]["speeds"],
        serde_json::json!(["w1", "w2", "w3"])
    );
    assert_eq!(
        json["equations"]["kinematic_equations"]
            .as_array()
            .map(Vec::len),
        Some(3)
    );
    let out = eomgen_ok(&["check", &top]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("ok   lagrange vs kane: relative residual of kane at lagrange's u' "),
        "{text}"
    );
}

/// The exported code of a model in speeds says that `qd` holds the speeds and takes `q̇` from
/// `coordinate_rates` in `rhs`, in every language (the values are compared with eomgen's at
/// random states by `tests/export.rs` for C and `python/tests/test_export.py` for Python).
#[test]
fn exported_code_takes_the_rates_from_the_kinematic_equations() {
    let body = fixture("free_rigid_body_speeds.yaml");
    for (language, call) in [
        (
            "--c",
            "free_rigid_body_speeds_coordinate_rates(t, y, y + 3, p, ydot);",
        ),
        (
            "--matlab",
            "ydot = [coordinate_rates(t, q, qd, p); x(1:3)];",
        ),
        (
            "--python",
            "return np.concatenate((coordinate_rates(t, q, qd, p), np.linalg.solve(M, F)))",
        ),
    ] {
        let out = eomgen_ok(&["equations", body.as_str(), language]);
        let code = String::from_utf8_lossy(&out.stdout);
        assert!(
            code.contains("qd[0] = w1 (a generalized speed)")
                || code.contains("qd(1) = w1 (a generalized speed)"),
            "{language}: {code}"
        );
        assert!(code.contains(call), "{language}: no `{call}`");
    }
}

/// The top in body rates compiled by `model!` and at run time (native code and interpreter)
/// computes the same bits at random states: `M`, `F`, their Jacobians, the right-hand side
/// with its kinematic equations, and its exact Jacobian.
#[test]
fn the_macro_and_the_run_time_compile_speeds_to_the_same_bits() {
    use crate::runtime_models::{compare, runtime_model};
    let path = fixture("heavy_top_speeds.yaml");
    let mut compiled: Box<dyn ModelInfo> =
        Box::new(eomgen::FirstOrder::new(compiled::HeavyTopSpeeds::default()));
    let mut native = runtime_model(&path, None);
    compare("heavy_top_speeds", compiled.as_mut(), native.as_mut(), 50);
    let mut interpreted = runtime_model(&path, Some(eomgen_jit::Backend::Interpreter));
    compare(
        "heavy_top_speeds",
        native.as_mut(),
        interpreted.as_mut(),
        10,
    );
    assert_eq!(compiled.as_ode().second_order_dim(), None);
}

/// The free body in body rates moves as the bundled model in the angles' rates does: the
/// angles at t = 2 agree to 1e-9 (both at rtol 1e-12), with DOP853 and with Radau IIA (which
/// uses the exact Jacobian through the kinematic equations), and the energy stays at its
/// start to 1e-10.
#[test]
fn a_free_body_in_body_rates_moves_as_in_the_angles_rates() {
    let options = |method| SimulationOptions {
        method,
        t_end: 2.0,
        rtol: 1e-12,
        atol: 1e-14,
        output: OutputTimes::At(vec![2.0]),
        ..SimulationOptions::default()
    };
    let mut reference = (eomgen::models::find("free_rigid_body")
        .expect("bundled")
        .make)();
    let run = simulate(reference.as_mut(), &options(Method::Dop853)).expect("reference run");
    let q_ref = run.solution.last().expect("a sample").1[..3].to_vec();
    let text = std::fs::read_to_string(fixture("free_rigid_body_speeds.yaml")).expect("fixture");
    for method in [Method::Dop853, Method::Radau5] {
        let mut body = load("free_rigid_body_speeds.yaml", &text);
        let run = simulate(body.as_mut(), &options(method)).expect("run in speeds");
        let y = run.solution.last().expect("a sample").1;
        for i in 0..3 {
            let (a, b) = (y[i], q_ref[i]);
            assert!((a - b).abs() < 1e-9, "{method:?}: q[{i}] {a} vs {b}");
        }
        let e0 = body.energy(0.0, &body.initial_state());
        let e1 = body.energy(2.0, y);
        assert!(
            (e1 - e0).abs() < 1e-10 * e0,
            "{method:?}: energy {e0} → {e1}"
        );
    }
}

/// The exact first-order Jacobian of the top in body rates (with the kinematic equations'
/// `∂q̇/∂q` and `W`) against central differences of its right-hand side (step 1e-6: error
/// `O(h²)` and `ε/h`, about 1e-9 of the entries' size) at 20 random states away from
/// `sin θ = 0`, to 1e-6 of the largest entry.
#[test]
fn the_first_order_jacobian_in_speeds_matches_differences() {
    let text = std::fs::read_to_string(fixture("heavy_top_speeds.yaml")).expect("fixture");
    let mut top = load("heavy_top_speeds.yaml", &text);
    let mut random = seeded_rng(0x5EED5);
    let (dim, h) = (6, 1e-6);
    for _ in 0..20 {
        let mut y: Vec<f64> = (0..dim).map(|_| random.random_range(-2.0..2.0)).collect();
        y[1] = random.random_range(0.3..2.8);
        let mut jac = vec![0.0; dim * dim];
        assert_eq!(top.as_ode_mut().jacobian(0.0, &y, &mut jac), Ok(true));
        let largest = jac.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for j in 0..dim {
            let (mut plus, mut minus) = (y.clone(), y.clone());
            plus[j] += h;
            minus[j] -= h;
            let (mut fp, mut fm) = (vec![0.0; dim], vec![0.0; dim]);
            top.as_ode_mut().rhs(0.0, &plus, &mut fp).expect("rhs");
            top.as_ode_mut().rhs(0.0, &minus, &mut fm).expect("rhs");
            for i in 0..dim {
                let difference = (fp[i] - fm[i]) / (2.0 * h);
                let exact = jac[i + j * dim];
                assert!(
                    (exact - difference).abs() < 1e-6 * largest,
                    "({i}, {j}) at {y:?}: {exact} vs {difference}"
                );
            }
        }
    }
}

/// The box on a ball joint in body rates and in the angles' rates: the same equilibrium and,
/// linearised there, the same `M`, `C`, `K` (in the angles) and input column of the torque
/// `T0`, entry by entry to 1e-12 of each matrix's largest; the frequencies are the closed
/// forms of the fixture's header, and `C` has no gyroscopic part.
#[test]
fn a_body_in_speeds_linearises_as_in_the_rates() {
    let text = std::fs::read_to_string(fixture("hanging_body_speeds.yaml")).expect("fixture");
    let mut speeds = load("hanging_body_speeds.yaml", &text);
    let mut rates = load("hanging_body.yaml", &in_rates(&text));
    assert!(rates.description().speeds.is_empty());
    let guess = [0.1, 0.05, -0.05];
    let a = eomgen::linearize_with_inputs(speeds.as_mut(), &guess, &["T0"]).expect("speeds");
    let b = eomgen::linearize_with_inputs(rates.as_mut(), &guess, &["T0"]).expect("rates");
    let close = |what: &str, x: &nalgebra::DMatrix<f64>, y: &nalgebra::DMatrix<f64>| {
        let scale = y.amax().max(1e-300);
        assert!((x - y).amax() <= 1e-12 * scale, "{what}:\n{x}\nvs\n{y}");
    };
    for (x, y) in a.equilibrium.q.iter().zip(&b.equilibrium.q) {
        assert!(
            (x - y).abs() < 1e-12,
            "{:?} vs {:?}",
            a.equilibrium.q,
            b.equilibrium.q
        );
    }
    let (la, lb) = (&a.linearization, &b.linearization);
    close("M", &la.mass_matrix, &lb.mass_matrix);
    close("C", &la.damping_matrix, &lb.damping_matrix);
    close("K", &la.stiffness_matrix, &lb.stiffness_matrix);
    close("B", &a.input_matrix, &b.input_matrix);
    let modes = eomgen::normal_modes(la).expect("modes");
    let (m, g, l, k): (f64, f64, f64, f64) = (2.0, 9.81, 0.5, 3.0);
    let expected = [
        m * g * l / (0.4 + m * l * l),
        m * g * l / (0.3 + m * l * l),
        k / 0.2,
    ];
    for (w, w2) in modes.natural_frequencies.iter().zip(expected) {
        assert!((w - w2.sqrt()).abs() < 1e-12 * w, "{w} vs {}", w2.sqrt());
    }
    let stability = eomgen::linear_stability(la).expect("stability");
    assert!(
        stability.gyroscopic_frequencies.is_none(),
        "no gyroscopic part"
    );
}

/// A speed with an offset that depends on the coordinate, `u = x' + a x`: at rest `u = a x`,
/// not 0. The equilibrium under a push `F0` is `x = F0/k`, and the linearisation there is
/// `m x'' + c x' + k x = 0` whatever `a` (closed form; it would not be with `u = 0` read as
/// rest, nor without `∂Z/∂q` in `C` and `K`).
#[test]
fn rest_with_an_offset_speed_is_where_the_rates_vanish() {
    let text = "name: offset\nparameters: { m: 2, k: 5, c: 0.3, F0: 1.5, a: 0.7 }\ncoordinates: [x]\nspeeds: { u: x_dot + a*x }\npoints: { P: [x, 0] }\nbodies: { ball: { mass: m, at: P } }\nforces: { spring: { at: P, vector: [F0 - k*x - c*x_dot, 0] } }\n";
    let model = load("offset.yaml", text);
    let equilibrium = eomgen::find_equilibrium(model.as_ref(), &[0.0], 0.0).expect("equilibrium");
    assert!(
        (equilibrium.q[0] - 0.3).abs() < 1e-14,
        "{:?}",
        equilibrium.q
    );
    let lin = eomgen::linearize(model.as_ref(), &equilibrium.q, &[0.0], 0.0).expect("at rest");
    for (what, value, expected) in [
        ("M", lin.mass_matrix[(0, 0)], 2.0),
        ("C", lin.damping_matrix[(0, 0)], 0.3),
        ("K", lin.stiffness_matrix[(0, 0)], 5.0),
    ] {
        assert!((value - expected).abs() < 1e-14, "{what} = {value}");
    }
    // u = 1 at x = 0.3 is a motion, x' = 1 - 0.21: linearised at rest only.
    let moving = eomgen::linearize(model.as_ref(), &equilibrium.q, &[1.0], 0.0).unwrap_err();
    assert!(
        matches!(moving, ModalError::SpeedsInMotion { speed } if (speed - 0.79).abs() < 1e-14),
        "{moving}"
    );
}

/// What a model in speeds cannot take is refused with its reason: the Taylor method (its
/// recurrences have no kinematic equations), Störmer–Verlet (it needs `y = [q; q̇]`), steady
/// motions (they hold rates), and modes where the kinematic equations are singular (z-x-z
/// angles of the top at θ = 0).
#[test]
fn what_takes_the_rates_refuses_speeds_with_its_reason() {
    let top = fixture("heavy_top_speeds.yaml");
    for (args, expected) in [
        (
            vec!["simulate", top.as_str(), "--method", "taylor"],
            "the state is in generalized speeds, and the recurrences have no series of the kinematic equations",
        ),
        (
            vec![
                "simulate",
                top.as_str(),
                "--method",
                "stormer-verlet",
                "--dt",
                "0.01",
            ],
            "a model in generalized speeds has y = [q; u]",
        ),
        (
            vec!["modes", top.as_str()],
            "the kinematic equations q' = W (u - Z) are singular at q = [0.0, 0.0, 0.0]",
        ),
    ] {
        let out = eomgen(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        assert!(err.contains(expected), "{args:?}: {err}");
    }
    // The rolling-contact study reads the contact force on the coordinates' rates.
    let disc = fixture("rolling_disc_speeds.yaml");
    let out = eomgen(&["study", "rolling-contact", disc.as_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains(
            "`rolling_disc_speeds` is in generalized speeds, and the rolling-contact study reads"
        ),
        "{err}"
    );
    let text = std::fs::read_to_string(&top).expect("fixture");
    let mut model = load("heavy_top_speeds.yaml", &text);
    let y = model.initial_state();
    let error = eomgen::linearize_steady_motion(model.as_mut(), 0.0, &y, &[0, 2]).unwrap_err();
    assert!(
        matches!(error, eomgen::SteadyMotionError::InSpeeds),
        "{error}"
    );
}

/// The command line names the state's second half by the speeds: `simulate` prints `w1 = …`
/// and writes `w1` in its CSV header, `--init` takes a speed and refuses a rate.
#[test]
fn the_command_line_names_the_speeds() {
    let body = fixture("free_rigid_body_speeds.yaml");
    let dir = tempfile::tempdir().expect("a temporary directory");
    let csv = dir.path().join("run.csv");
    let csv = csv.to_str().expect("a path");
    let out = eomgen_ok(&[
        "simulate", &body, "--t-end", "0.5", "--init", "w3=2", "--csv", csv,
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.lines()
            .any(|l| l.trim_start().starts_with("phi =") && l.contains(" w1 = ")),
        "{text}"
    );
    let header = std::fs::read_to_string(csv).expect("CSV");
    assert!(
        header.starts_with("t,phi,theta,psi,w1,w2,w3,energy"),
        "{header}"
    );
    let out = eomgen(&["simulate", &body, "--init", "phi_dot=1"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("speeds: w1, w2, w3"), "{err}");
}

/// The partial angular velocities `kinematics --partial` lists for a model in speeds are
/// with respect to the speeds, and say so: the body's own rates give the unit vectors.
#[test]
fn partial_velocities_are_with_respect_to_the_speeds() {
    let top = fixture("heavy_top_speeds.yaml");
    let out = eomgen_ok(&["kinematics", &top, "--frame", "B", "--partial"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for line in [
        "  d omega/d w1 = [1, 0, 0]",
        "  d omega/d w2 = [0, 1, 0]",
        "  d omega/d w3 = [0, 0, 1]",
    ] {
        assert!(
            text.lines().any(|l| l == line),
            "no line `{line}` in:\n{text}"
        );
    }
}

/// Under `units: SI` a speed has its definition's unit: a force written as a speed in m/s is
/// refused at its place.
#[test]
fn a_speed_has_the_unit_of_its_definition() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = written(
        &dir,
        "units.yaml",
        "name: p\nunits: SI\nparameters: { m: 1.0 }  # kg\ncoordinates: [x]  # m\nspeeds: { v: x_dot }\npoints: { P: [x, 0] }\nbodies: { ball: { mass: m, at: P } }\nforces: { push: { at: P, vector: [v, 0] } }\n",
    );
    let out = eomgen(&["check", &path]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("units.yaml:8:35: the x component of force `push` is m/s, but a force is N"),
        "{err}"
    );
}

/// A speed with an offset prints its kinematic equation with it: `q' = W(q, t) (u - Z(q, t))`.
#[test]
fn the_kinematic_equations_name_an_offset() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = written(
        &dir,
        "belt.yaml",
        "name: belt\nparameters: { m: 2, k: 5, v0: 0.7 }\ncoordinates: [x]\nspeeds: { u: x_dot + v0 }\npoints: { O: [0, 0], P: [x + v0*t, 0] }\nbodies: { ball: { mass: m, at: P } }\nforces: { pull: { at: P, vector: [-k*x, 0] } }\n",
    );
    let out = eomgen_ok(&["equations", &path]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("q' = W(q, t) (u - Z(q, t)) (the kinematic equations) with\n  x' = u - v0\n"),
        "{text}"
    );
}

/// Where a name or a formula means the coordinates' rates, a model in speeds gets a message,
/// not the speeds read as rates: speeds that depend on `t` (rest moves with `t`) are not
/// linearised, `x_ddot` is not offered to an added event (the state's accelerations are
/// `u̇`), an output that reads a rate is refused at its place, and the free response's
/// `--init` takes the linearisation's `x_dot` (its state is `(δq, δq̇)`) and refuses a speed.
#[test]
fn what_means_the_rates_is_not_read_from_the_speeds() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let moving = written(
        &dir,
        "moving.yaml",
        "name: moving\nparameters: { m: 2, k: 5, v: 0.4 }\ncoordinates: [x]\nspeeds: { u: x_dot + v*t }\npoints: { P: [x, 0] }\nbodies: { ball: { mass: m, at: P } }\nforces: { spring: { at: P, vector: [-k*x, 0] } }\n",
    );
    let out = eomgen(&["modes", &moving]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("the generalized speeds depend on t"), "{err}");
    let body = fixture("free_rigid_body_speeds.yaml");
    let out = eomgen(&["simulate", &body, "--event", "theta_ddot"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("theta_ddot"), "{err}");
    let output = written(
        &dir,
        "output.yaml",
        "name: output\nparameters: { m: 2, k: 5 }\ncoordinates: [x]\nspeeds: { u: 2*x_dot }\npoints: { P: [x, 0] }\nbodies: { ball: { mass: m, at: P } }\nforces: { spring: { at: P, vector: [-k*x, 0] } }\noutputs: { e: m*x_dot^2/2 }\n",
    );
    let out = eomgen(&["simulate", &output]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("output.yaml:8:17: output `e` reads `x_dot`, a function of the rates, but a model in generalized speeds has the speeds in its state"),
        "{err}"
    );
    let hanging = fixture("hanging_body_speeds.yaml");
    eomgen_ok(&[
        "study",
        "free-response",
        &hanging,
        "--init",
        "theta_dot=0.1",
    ]);
    let out = eomgen(&["study", "free-response", &hanging, "--init", "w1=0.1"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("rates: phi_dot, theta_dot, psi_dot"), "{err}");
}

/// Speeds with large offsets in the coordinates (`u₁ = ẋ₁ + a x₂ + b x₁`, `a` = 300) make the
/// products `Yᵀ K Y` round to a skew part of 1e-12 where the model in rates has none: within
/// the products' rounding bound it is averaged out, so two uncoupled oscillators stay
/// symmetric (no flutter, no gyroscopic part) with `ω = √(k/m)` twice, to 1e-12, while a
/// real Coriolis coupling (a particle on a turntable in speeds with offsets `Ω (−y, x)`)
/// keeps its `G = 2 m Ω` exactly.
#[test]
fn rounding_of_the_speeds_is_not_a_coupling() {
    let twins = "name: twins\nparameters: { m: 1.3, k: 5.1, a: 300, b: 221.19 }\ncoordinates: [x1, x2]\nspeeds: { u1: x1_dot + a*x2 + b*x1, u2: x2_dot + b*x1 - a*x2 }\npoints: { P1: [x1, 0], P2: [x2, 1] }\nbodies: { b1: { mass: m, at: P1 }, b2: { mass: m, at: P2 } }\nforces: { s1: { at: P1, vector: [-k*x1, 0] }, s2: { at: P2, vector: [-k*x2, 0] } }\n";
    let model = load("twins.yaml", twins);
    let lin = eomgen::linearize(model.as_ref(), &[0.0, 0.0], &[0.0, 0.0], 0.0).expect("at rest");
    assert_eq!(lin.stiffness_asymmetry(), 0.0);
    let c = &lin.damping_matrix;
    assert_eq!(c[(0, 1)], c[(1, 0)]);
    let stability = eomgen::linear_stability(&lin).expect("stability");
    assert!(stability.gyroscopic_frequencies.is_none());
    let modes = eomgen::normal_modes(&lin).expect("modes");
    let omega = (5.1f64 / 1.3).sqrt();
    for w in &modes.natural_frequencies {
        assert!((w - omega).abs() < 1e-12 * omega, "{w} vs {omega}");
    }
    let turntable = "name: turntable\nparameters: { m: 1.0, k: 5.0, W: 1.0 }\ncoordinates: [x, y]\nspeeds: { u: x_dot - W*y, v: y_dot + W*x }\npoints: { P: [x*cos(W*t) - y*sin(W*t), x*sin(W*t) + y*cos(W*t)] }\nbodies: { ball: { mass: m, at: P } }\npotential: k*(x^2 + y^2)/2\n";
    let model = load("turntable.yaml", turntable);
    // The points turn with t; the speeds do not depend on it.
    let lin = eomgen::linearize(model.as_ref(), &[0.0, 0.0], &[0.0, 0.0], 0.0).expect("at rest");
    let g = (&lin.damping_matrix - lin.damping_matrix.transpose()) * 0.5;
    assert!(
        (g[(1, 0)].abs() - 2.0).abs() < 1e-14,
        "{}",
        lin.damping_matrix
    );
}

/// Kane's way for a non-holonomic system: the rolling disc in its body rates (three speeds
/// for five coordinates, the rolling contact's two rows its auxiliary speeds held at 0)
/// against the bundled disc in the rates with Lagrange's multipliers, from the same state
/// (the rates from the kinematic equations), with DOP853 at rtol 1e-12 over 2 s: the
/// coordinates agree to 1e-8 and the contact forces (the multipliers, the same rows in both)
/// to 1e-7 relative, with the auxiliary speeds held to rounding. Also with Radau IIA (its
/// Jacobian by differences, as for every constrained model).
#[test]
fn a_rolling_disc_in_speeds_moves_as_with_multipliers_in_the_rates() {
    let options = |method, initial_state| SimulationOptions {
        method,
        t_end: 2.0,
        rtol: 1e-12,
        atol: 1e-12,
        output: OutputTimes::At(vec![2.0]),
        initial_state,
        ..SimulationOptions::default()
    };
    let text = std::fs::read_to_string(fixture("rolling_disc_speeds.yaml")).expect("fixture");
    let disc = load("rolling_disc_speeds.yaml", &text);
    let speeds: Vec<&str> = disc
        .description()
        .speeds
        .iter()
        .map(|s| s.as_ref())
        .collect();
    assert_eq!(speeds, ["w1", "w2", "w3", "roll_x", "roll_y"]);
    let y0 = disc.initial_state();
    let rates = disc.coordinate_rates(0.0, &y0);
    let start: Vec<f64> = y0[..5].iter().chain(rates.iter()).copied().collect();
    // The fixture's start is a lean of 0.1 with no slip: x' = r (w2 − w3 tan(lean)).
    let expected = 0.2 * (10.0 - 0.5 * 0.1f64.tan());
    assert!((start[5] - expected).abs() < 1e-14, "x' = {}", start[5]);
    let mut reference = (eomgen::models::find("rolling_disc").expect("bundled").make)();
    let run =
        simulate(reference.as_mut(), &options(Method::Dop853, Some(start))).expect("reference run");
    let (_, y_ref) = run.solution.last().expect("a sample");
    let forces_ref = reference.constraint_forces(2.0, y_ref).expect("forces");
    for method in [Method::Dop853, Method::Radau5] {
        let mut disc = load("rolling_disc_speeds.yaml", &text);
        let run = simulate(disc.as_mut(), &options(method, None)).expect("run in speeds");
        let (_, y) = run.solution.last().expect("a sample");
        for i in 0..5 {
            assert!(
                (y[i] - y_ref[i]).abs() < 1e-8,
                "{method:?}: q[{i}] {} vs {}",
                y[i],
                y_ref[i]
            );
        }
        assert!(
            y[8].abs() < 1e-12 && y[9].abs() < 1e-12,
            "auxiliary speeds {y:?}"
        );
        let forces = disc.constraint_forces(2.0, y).expect("forces");
        for (a, b) in forces.iter().zip(&forces_ref) {
            assert!(
                (a - b).abs() < 1e-7 * b.abs().max(1.0),
                "{method:?}: λ {forces:?} vs {forces_ref:?}"
            );
        }
    }
}

/// The rolling disc in its body rates lists its equations on the constraints (the
/// auxiliary speeds at 0): the kinematic equations carry no slip, `x' = r cos(yaw) (…)` the
/// rolling condition, and `J` holds each auxiliary speed; `check` compares Kane's with
/// Lagrange's carried into the speeds.
#[test]
fn a_rolling_disc_in_speeds_lists_kanes_non_holonomic_equations() {
    let disc = fixture("rolling_disc_speeds.yaml");
    let listing =
        String::from_utf8_lossy(&eomgen_ok(&["equations", disc.as_str()]).stdout).to_string();
    assert!(
        listing.contains("on the constraints: the auxiliary speeds roll_x, roll_y at 0, where the rows of w1, w2, w3 are Kane's equations of the independent speeds"),
        "{listing}"
    );
    let kinematic: Vec<&str> = (listing.lines())
        .skip_while(|l| !l.starts_with("q' = "))
        .skip(1)
        .take(5)
        .collect();
    assert!(
        kinematic[0].starts_with("  x' = r*cos(yaw)*("),
        "{kinematic:?}"
    );
    assert!(
        kinematic.iter().all(|l| !l.contains("roll_")),
        "{kinematic:?}"
    );
    assert!(listing.contains("  J[roll_x,roll_x] = 1\n"), "{listing}");
    assert!(listing.contains("  J[roll_y,roll_y] = 1\n"), "{listing}");
    let check = String::from_utf8_lossy(&eomgen_ok(&["check", disc.as_str()]).stdout).to_string();
    assert!(check.contains("ok   lagrange vs kane"), "{check}");
    assert!(!check.contains("integrable"), "{check}");
}

/// Euler parameters with the body's angular velocity as the speeds (four coordinates, three
/// speeds, the unit norm an auxiliary speed held at 0): from the same state the parameters
/// move as those of the file in the rates, to 1e-9 at t = 2 with DOP853 at rtol 1e-12, the
/// norm drifts by no more than 1e-10 and the energy holds to 1e-11. Projection, which steps
/// along `∂Φ/∂q`, and linearisations in speeds beside constraints refuse with their reason.
#[test]
fn euler_parameters_in_body_rates_move_as_in_the_rates() {
    let options = |stabilization| SimulationOptions {
        method: Method::Dop853,
        t_end: 2.0,
        rtol: 1e-12,
        atol: 1e-12,
        output: OutputTimes::At(vec![2.0]),
        stabilization,
        ..SimulationOptions::default()
    };
    let read = |name: &str| std::fs::read_to_string(fixture(name)).expect("fixture");
    let mut rates = load(
        "free_rigid_body_quaternion.yaml",
        &read("free_rigid_body_quaternion.yaml"),
    );
    let reference = simulate(rates.as_mut(), &options(Stabilization::None)).expect("in rates");
    let (_, e_ref) = reference.solution.last().expect("a sample");
    let text = read("free_rigid_body_quaternion_speeds.yaml");
    let mut body = load("free_rigid_body_quaternion_speeds.yaml", &text);
    let run = simulate(body.as_mut(), &options(Stabilization::None)).expect("in speeds");
    let (_, y) = run.solution.last().expect("a sample");
    for i in 0..4 {
        assert!(
            (y[i] - e_ref[i]).abs() < 1e-9,
            "e{i}: {} vs {}",
            y[i],
            e_ref[i]
        );
    }
    let norm: f64 = y[..4].iter().map(|e| e * e).sum();
    assert!((norm - 1.0).abs() < 1e-10, "|e|² = {norm}");
    let (e0, e1) = (body.energy(0.0, &body.initial_state()), body.energy(2.0, y));
    assert!((e1 - e0).abs() < 1e-11 * e0, "energy {e0} → {e1}");
    let error = simulate(body.as_mut(), &options(Stabilization::Projection)).unwrap_err();
    assert!(
        matches!(error, SimulationError::ProjectionInSpeeds { .. }),
        "{error}"
    );
    let start = body.initial_state();
    let error = eomgen::linearize(body.as_ref(), &start[..4], &[0.0; 4], 0.0).unwrap_err();
    assert!(
        matches!(error, ModalError::SpeedsBesideConstraints { .. }),
        "{error}"
    );
}

/// `check` of a heavy top in Euler parameters with its tip pinned by holonomic constraints and
/// its body rates as the speeds, whose `M` is singular along the norm: both derivations agree
/// through the KKT system, and the power balance holds at states on the velocity constraints
/// (the constraint forces do no work there). Elimination (`reduce`) refuses speeds.
#[test]
fn a_pinned_top_in_euler_parameters_and_body_rates_checks() {
    let top = fixture("heavy_top_quaternion_speeds.yaml");
    let check = String::from_utf8_lossy(&eomgen_ok(&["check", top.as_str()]).stdout).to_string();
    assert!(check.contains("ok   lagrange vs kane"), "{check}");
    assert!(check.contains("ok   power balance"), "{check}");
    let dir = tempfile::tempdir().expect("a temporary directory");
    let pendulum = written(
        &dir,
        "pendulum.yaml",
        "name: p\nparameters: { m: 1, l: 1, g: 10 }\ncoordinates: [x, y]\npoints: { O: [0, 0], P: [x, y] }\nbodies: { bob: { mass: m, at: P } }\ngravity: [0, -g]\nconstraints: { rod: sqrt(x^2 + y^2) - l }\nspeeds: { u: x*y_dot - y*x_dot }\ninitial: { x: l, u: 0.5 }\n",
    );
    let out = eomgen(&["reduce", pendulum.as_str(), "--keep", "y"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("does not rewrite `speeds:`"), "{err}");
}
