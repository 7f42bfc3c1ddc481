//! The `eomgen` binary end to end: `list --json`, `simulate --json` output contract, dense
//! output at requested times, expressions in options, and clear usage errors.

use crate::common;
use common::{eomgen, eomgen_ok};

/// The CLI reference (docs/cli.md) describes every method of the method table under its
/// command-line name, and `simulate --help` lists each with its summary.
#[test]
fn the_cli_reference_and_the_help_name_every_method() {
    let reference = include_str!("../docs/cli.md");
    let out = eomgen_ok(&["simulate", "--help"]);
    let words = |s: &str| s.split_whitespace().collect::<Vec<_>>().join(" ");
    let help = words(&String::from_utf8_lossy(&out.stdout));
    for row in eomgen::Method::table() {
        assert!(
            reference.contains(&format!("`{}`", row.name)),
            "docs/cli.md does not describe `{}`",
            row.name
        );
        assert!(
            help.contains(&format!("- {}: {}", row.name, words(row.summary))),
            "`simulate --help` does not list `{}` with its summary",
            row.name
        );
    }
}

#[test]
fn list_json_names_every_model() {
    let out = eomgen(&["list", "--json"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let items = v.as_array().unwrap();
    assert_eq!(items.len(), eomgen::models::ALL.len());
    let dp = items
        .iter()
        .find(|i| i["name"] == "double_pendulum")
        .unwrap();
    assert_eq!(dp["dof"], 2);
    assert!(dp["description"].as_str().unwrap().contains("HW19"));
}

#[test]
fn simulate_json_samples_exactly_at_requested_times() {
    let out = eomgen(&[
        "simulate",
        "simple_pendulum",
        "--t-end",
        "2",
        "--t-out",
        "0.5,1,pi/2",
        "--rtol",
        "1e-12",
        "--atol",
        "1e-12",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["model"], "simple_pendulum");
    assert_eq!(v["coordinates"], serde_json::json!(["q"]));
    assert_eq!(v["method"], "dp54");
    let samples = v["samples"].as_array().unwrap();
    let times: Vec<f64> = samples.iter().map(|s| s["t"].as_f64().unwrap()).collect();
    assert_eq!(times, [0.5, 1.0, std::f64::consts::FRAC_PI_2]);
    for s in samples {
        assert_eq!(s["q"].as_array().unwrap().len(), 1);
        assert_eq!(s["qdot"].as_array().unwrap().len(), 1);
        // Conservative: E = 0 (starts horizontal at rest); drift at 1e-12 is < 1e-10 J.
        assert!(s["energy"].as_f64().unwrap().abs() < 1e-10);
    }
    for key in ["steps", "rejected", "rhs_evals"] {
        assert!(v["stats"][key].is_number(), "stats.{key}");
    }
    assert!(
        v["stats"]["wall_time_s"].is_null(),
        "no timing without --timing"
    );
}

#[test]
fn init_and_set_accept_expressions() {
    let out = eomgen(&[
        "simulate",
        "simple_pendulum",
        "--init",
        "q=-pi/2",
        "--set",
        "g=2*5",
        "--t-end",
        "1",
        "--t-out",
        "1",
        "--json",
    ]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // Released at the hanging equilibrium it stays there.
    let q = v["samples"][0]["q"][0].as_f64().unwrap();
    assert!((q + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert_eq!(v["parameters"]["g"], 10.0);
}

/// `--init` takes a comma list as `--at` does (a function's arguments stay together), in
/// `simulate` and in the studies: the same run as the repeated option, to the bit.
#[test]
fn init_takes_a_comma_list() {
    let run = |init: &[&str]| {
        let mut args = vec!["simulate", "simple_pendulum", "--t-end", "0.5", "--json"];
        for i in init {
            args.extend(["--init", i]);
        }
        let out = eomgen(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v["samples"].clone()
    };
    let listed = run(&["q=atan2(1, 2),q_dot=0.25"]);
    assert_eq!(listed[0]["q"][0].as_f64(), Some(0.5f64.atan()));
    assert_eq!(listed[0]["qdot"][0].as_f64(), Some(0.25));
    assert_eq!(listed, run(&["q=atan2(1, 2)", "q_dot=0.25"]));
    let out = eomgen(&[
        "study",
        "free-response",
        "three_masses",
        "--init",
        "x1=0.1,x3_dot=atan2(1, 1)",
        "--t-end",
        "0.1",
        "--samples",
        "3",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["initial"]["q"], serde_json::json!([0.1, 0.0, 0.0]));
    assert_eq!(
        v["initial"]["qdot"],
        serde_json::json!([0.0, 0.0, std::f64::consts::FRAC_PI_4])
    );
}

#[test]
fn usage_errors_are_clear_and_exit_2() {
    let out = eomgen(&["simulate", "double_pendulm"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("did you mean `double_pendulum`"), "{err}");
    let out = eomgen(&["simulate", "double_pendulum", "--init", "theta3=1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("theta1_dot"));
    let out = eomgen(&["simulate", "double_pendulum", "--set", "k=1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("has no parameter `k`"));
}

#[test]
fn rk4_and_plots_and_csv() {
    let dir = std::env::temp_dir().join(format!("eomgen-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("p.svg");
    let png = dir.join("p.png");
    let csv = dir.join("p.csv");
    for plot in [&svg, &png] {
        let out = eomgen(&[
            "simulate",
            "two_masses",
            "--method",
            "rk4",
            "--dt",
            "0.01",
            "--t-end",
            "1",
            "--plot",
            plot.to_str().unwrap(),
            "--csv",
            csv.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(std::fs::metadata(plot).unwrap().len() > 1000);
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("t,x1,x2,x1_dot,x2_dot,energy\n"));
    assert_eq!(text.lines().count(), 1 + 101, "header + t0 + 100 steps");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_singular_mass_matrix_is_an_error_with_t_and_exit_1() {
    let out = eomgen(&["simulate", "simple_pendulum", "--set", "m=0", "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("mass matrix is not positive definite at t = 0"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["error"]["t"], 0.0);
}

/// Failed equilibrium searches say why Newton stopped and what to try, in every command that
/// needs an equilibrium, and exit 1: a cannonball has none (its forces do not depend on q),
/// and a simple pendulum started at q = 1e308 cannot reach one.
#[test]
fn failed_equilibrium_searches_explain_themselves() {
    for args in [
        &["modes", "cannonball"][..],
        &["frf", "cannonball", "--input", "x"],
        &["study", "free-response", "cannonball"],
        &["study", "modal-damping", "cannonball"],
    ] {
        let out = eomgen(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("no equilibrium found"), "{err}");
        assert!(err.contains("the forces do not depend on q"), "{err}");
        assert!(err.contains("help: ") && err.contains("free fall"), "{err}");
    }
    let out = eomgen(&["modes", "simple_pendulum", "--at", "q=1e308"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no step reduces |F|"), "{err}");
    assert!(
        err.contains("help: start Newton nearer an equilibrium"),
        "{err}"
    );
    assert!(
        err.contains("(hanging, upright)"),
        "the file's equilibria are named: {err}"
    );
    // A non-holonomic model is linearised with its constraint (issue 30): the rate the
    // constraint gives is solved, not a state.
    let out = eomgen(&["modes", "braking_car"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("reduced state  x, y, theta, x_dot, theta_dot")
            && text.contains("dependent rates: y_dot"),
        "{text}"
    );
}

/// `eomgen check` passes on every bundled model (Lagrange ≡ momentum balance where the model
/// is kinematic; power balance), by name and by path, with the documented JSON keys.
#[test]
fn check_passes_on_every_model_and_accepts_paths() {
    for entry in eomgen::models::ALL {
        let out = eomgen(&["check", entry.name, "--states", "100", "--json"]);
        assert!(
            out.status.success(),
            "{}: {}",
            entry.name,
            String::from_utf8_lossy(&out.stdout)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["model"], entry.name);
        assert_eq!(v["passed"], true);
        assert!(v["derivation"]["lagrange"]["ops_after_cse"].is_number());
        for c in v["checks"].as_array().unwrap() {
            // A set of balances kept to show a wrong form (`expect: disagree`) must differ.
            let residual = c["max_rel_residual"].as_f64().unwrap();
            if c["expect_disagreement"] == true {
                assert!(residual > 1e-8, "{c}");
            } else {
                assert!(residual < 1e-8, "{c}");
            }
            assert_eq!(c["a"], "lagrange");
            // Every derivation compared is one `check` timed: the fixed formulations or a
            // set of balances by its name.
            let b = c["b"].as_str().unwrap();
            assert!(v["derivation"][b]["ops"].is_number(), "{c}");
        }
    }
    let out = eomgen(&[
        "check",
        concat!(env!("CARGO_MANIFEST_DIR"), "/models/double_pendulum.yaml"),
        "--json",
    ]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["checks"][0]["symbolic_equal"], true);
    assert!(v["power_balance"]["max_rel_residual"].as_f64().unwrap() < 1e-8);
}

/// A broken file given by path: the loader's diagnostics with file:line:col, exit 1.
#[test]
fn check_reports_model_file_errors() {
    let dir = std::env::temp_dir().join(format!("eomgen-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.yaml");
    std::fs::write(
        &path,
        "name: bad\ncoordinates: [q]\nkinetic: q_dot^2/2 + k\n",
    )
    .unwrap();
    // A model file with mistakes is a usage error (exit 2), as every command reports it.
    let out = eomgen(&["check", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.yaml:3:22: unknown name `k`"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `eomgen new` prints files that load and check; `eomgen equations` prints M and F by either
/// method, as text and LaTeX.
#[test]
fn new_and_equations() {
    let out = eomgen(&["new", "n-link-pendulum", "3"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("name: n_link_pendulum_3"));
    let dir = std::env::temp_dir().join(format!("eomgen-new-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("triple.yaml");
    std::fs::write(&path, &text).unwrap();
    let out = eomgen(&["check", path.to_str().unwrap(), "--states", "50"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let _ = std::fs::remove_dir_all(&dir);

    let out = eomgen(&["equations", "double_pendulum"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("M[0,0] = l1^2*(m2 + m1/3)"), "{text}");
    let out = eomgen(&[
        "equations",
        "cart_pendulum",
        "--method",
        "momentum",
        "--latex",
    ]);
    assert!(out.status.success());
    assert!(
        String::from_utf8(out.stdout)
            .unwrap()
            .contains("\\begin{bmatrix}")
    );
    let out = eomgen(&["equations", "simple_pendulum", "--method", "momentum"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(eomgen(&["new", "n-mass-chain", "0"]).status.code(), Some(2));
}

/// cond(M) = 4e9 (a 1 kg mass at u + v, a 1e-9 kg mass at u): Lagrange and momentum balance
/// are symbolically equal, but their q̈ differ by ε·cond(M) ≈ 4e-7, and `check` failed them
/// at 1e-8. Judged by the residual of each derivation's equations at Lagrange's q̈ (a
/// backward error, 2e-16 here), they pass; a hand-written set with the spring dropped from
/// the second equation still fails, that equation named.
#[test]
fn an_ill_conditioned_mass_matrix_passes_check() {
    let fixture = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/near_dependent.yaml"
    );
    let out = eomgen(&["check", fixture]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("ok   lagrange vs momentum"),
        "{text}"
    );
    let source = std::fs::read_to_string(fixture).unwrap();
    let wrong = source.replace(
        "initial:",
        "checks:\n  equations_of_motion:\n    - (m1 + m2)*u_ddot + m1*v_ddot = -(m1 + m2)*g - k*(u + v)\n    - m1*u_ddot + m1*v_ddot = -m1*g\ninitial:",
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("near_dependent.yaml");
    std::fs::write(&path, wrong).unwrap();
    let out = eomgen(&["check", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(
        text.contains("FAIL lagrange vs by_hand") && text.contains("in equation 2 (line 20)"),
        "{text}"
    );
}

/// Deliberately wrong derivations are detected, each with exit 1 and a note saying why: a
/// reaction left in (AMB about the elbow of both bars), dependent balances (the same AMB
/// twice), AMB about the moving elbow without the `v_E × m v_G` correction (HW4, HW15), hand
/// equations with a dropped Coriolis term (HW20) and with a spring force of the wrong sign
/// (HW9), each wrong equation named. HW19's own balances pass.
#[test]
fn check_detects_wrong_derivations() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/wrong");
    for (file, note) in [
        ("reaction_left_in.yaml", "leaves a reaction force in"),
        ("dependent_balances.yaml", "not independent"),
        ("h_dot_about_elbow.yaml", "misses v_A × m v_G"),
        // The note names the wrong equation (the one that fails at Lagrange's q̈).
        (
            "dropped_coriolis.yaml",
            "written by hand disagree with Lagrange in equation 1 (line 35)",
        ),
        (
            "spring_sign.yaml",
            "written by hand disagree with Lagrange in equation 1 (line 33)",
        ),
    ] {
        let path = format!("{dir}/{file}");
        let out = eomgen(&["check", &path, "--states", "50", "--json"]);
        assert_eq!(out.status.code(), Some(1), "{file} must fail");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["passed"], false);
        let notes = v["notes"].to_string();
        assert!(notes.contains(note), "{file}: {notes}");
    }
    let out = eomgen(&["check", "double_pendulum", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let balances = v["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["b"] == "balances")
        .expect("HW19 balances checked");
    assert!(balances["max_rel_residual"].as_f64().unwrap() < 1e-10);
    assert!(balances["symbolic_equal"].is_null());
}

/// A constrained model: `simulate` reports the constraint forces and drift (text, JSON, CSV),
/// a start that violates the constraints is an error naming the residual (exit 1), and the
/// drift chart is written next to the plot.
#[test]
fn simulate_reports_constraint_forces_and_rejects_inconsistent_starts() {
    let out = eomgen(&[
        "simulate",
        "simple_pendulum_cartesian",
        "--t-end",
        "1",
        "--json",
    ]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["constraints"][0], "rod");
    let first = &v["samples"][0];
    // At rest, horizontal: λ = m l q̇² + m g sin q = 0 at the start.
    assert!(first["constraint_forces"][0].as_f64().unwrap().abs() < 1e-12);
    assert!(v["max_constraint_drift"]["position"].as_f64().unwrap() < 1e-6);
    let out = eomgen(&["simulate", "simple_pendulum_cartesian", "--init", "x=1.1"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("violates its constraints"), "{err}");
    let dir = std::env::temp_dir().join(format!("eomgen-drift-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let plot = dir.join("p.svg");
    let csv = dir.join("p.csv");
    let out = eomgen(&[
        "simulate",
        "four_bar",
        "--t-end",
        "1",
        "--stabilization",
        "baumgarte",
        "--plot",
        plot.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.join("p-drift.svg").exists());
    let header = std::fs::read_to_string(&csv).unwrap();
    assert!(header.starts_with("t,theta1,theta2,theta3,theta1_dot,theta2_dot,theta3_dot,energy,lambda_loop_x,lambda_loop_y,drift_position,drift_velocity"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `check` tests the start too (issue 20): a copy of the Cartesian pendulum whose `initial:`
/// puts the bob at x = 2 m on a rod of 1 m violates its constraint by exactly 1 m, which is a
/// failing row naming the constraint and the residual (text and JSON) and exit 1; the bundled
/// model's start passes the same row (residual 0, tolerance 1e-9 as at run time).
#[test]
fn check_fails_on_an_initial_state_that_violates_a_constraint() {
    let source = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/models/simple_pendulum_cartesian.yaml"
    ))
    .unwrap();
    let bad = source.replace("initial: { x: l, y: 0 }", "initial: { x: 2*l, y: 0 }");
    assert_ne!(bad, source, "the initial state line changed");
    let dir = std::env::temp_dir().join(format!("eomgen-initial-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("pendulum_off_rod.yaml");
    std::fs::write(&path, bad).unwrap();
    let out = eomgen(&["check", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(
            "FAIL initial state satisfies the constraints: largest residual 1.00 (residual of `rod`"
        ),
        "{text}"
    );
    let out = eomgen(&["check", path.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["passed"], false);
    assert_eq!(v["initial_constraints"]["constraint"], "rod");
    assert!((v["initial_constraints"]["residual"].as_f64().unwrap() - 1.0).abs() < 1e-12);
    let out = eomgen(&["check", "simple_pendulum_cartesian", "--json"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["initial_constraints"]["passed"], true);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `study constraint-methods` renders the study (its numbers are tested through the library
/// in `tests/constraints.rs`): the minimal twin the file names gets its row, and a model
/// without constraints is a usage error.
#[test]
fn study_constraint_methods_compares_springs_dae_and_minimal() {
    let out = eomgen(&["study", "constraint-methods", "double_pendulum"]);
    assert_eq!(out.status.code(), Some(2));
    let out = eomgen(&[
        "study",
        "constraint-methods",
        "simple_pendulum_cartesian",
        "--t-end",
        "2",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(
        v["methods"]
            .as_array()
            .unwrap()
            .iter()
            .any(|m| m["method"].as_str().unwrap().starts_with("II.3"))
    );
}

/// A failed integration (issue 8, item 3): exit 1, the reason with t, a `help:` line that
/// fits the reason and the method, and the samples before the failure kept in `--json`
/// (all finite: nothing non-finite is written). Explicit Euler at h = 100 on the cannonball
/// (drag rate c/m = 0.5/s, so h·c/m = 50 is far beyond Euler's limit 2) diverges
/// geometrically until it overflows.
#[test]
fn failed_integrations_explain_themselves_and_keep_their_samples() {
    let args = [
        "simulate",
        "cannonball",
        "--method",
        "euler",
        "--dt",
        "100",
        "--t-end",
        "1e6",
    ];
    let out = eomgen(&args);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("is not finite at t = "), "{err}");
    assert!(err.contains("help: the state blew up"), "{err}");
    let mut json_args = args.to_vec();
    json_args.push("--json");
    let out = eomgen(&json_args);
    assert_eq!(out.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let t_fail = v["error"]["t"].as_f64().unwrap();
    let samples = v["samples"].as_array().unwrap();
    assert!(samples.len() > 10);
    for s in samples {
        assert!(s["t"].as_f64().unwrap() < t_fail);
        for x in s["q"]
            .as_array()
            .unwrap()
            .iter()
            .chain(s["qdot"].as_array().unwrap())
        {
            assert!(x.as_f64().is_some_and(f64::is_finite), "{s}");
        }
    }
    // A singular mass matrix at the start: the coordinate's own singularity is named.
    let out = eomgen(&["simulate", "simple_pendulum_y", "--init", "y=1"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("help: "));
}

/// `eomgen check` (which derives the file at run time) and `eomgen simulate` (which compiles
/// it at run time) on every broken file of the compile-fail suite
/// (`compile-fail/tests/ui/<category>/`) print the diagnostics recorded in its `.stderr`
/// (for the few with a `.rs`, the compile error of `model!`, which trybuild checks; for the
/// others the loader's diagnostics alone): each diagnostic's `error: FILE:line:col: message`
/// headline appears in the output for that file (the path prefix differs: the macro names the
/// file as written in `model!`), followed by the same source excerpt, caret and `help:` lines
/// (the indentation differs), the exit status is 2, and with `--json` standard output is the
/// JSON object of the diagnostics, one entry per headline.
#[test]
fn check_and_simulate_print_the_compile_errors_of_every_ui_case() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/compile-fail/tests/ui");
    let mut checked = 0;
    let mut categories: Vec<_> = std::fs::read_dir(root).unwrap().flatten().collect();
    categories.sort_by_key(|e| e.path());
    for category in categories {
        let mut files: Vec<_> = std::fs::read_dir(category.path())
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
            .collect();
        files.sort();
        for yaml in files {
            let expected = std::fs::read_to_string(yaml.with_extension("stderr")).unwrap();
            let blocks = diagnostic_blocks(&expected);
            let headlines: Vec<&str> = blocks.iter().map(|(headline, _)| *headline).collect();
            assert!(
                !headlines.is_empty(),
                "{}: no diagnostic recorded",
                yaml.display()
            );
            let path = yaml.to_str().unwrap();
            for command in ["check", "simulate"] {
                let out = eomgen(&[command, path]);
                assert_eq!(out.status.code(), Some(2), "{command} {}", yaml.display());
                let got = String::from_utf8_lossy(&out.stderr);
                let lines: Vec<&str> = got.lines().map(str::trim).collect();
                for (rest, body) in &blocks {
                    let headline = format!(".yaml:{rest}");
                    let found = lines.iter().enumerate().any(|(i, line)| {
                        line.ends_with(&headline)
                            && lines.get(i + 1..i + 1 + body.len()) == Some(&body[..])
                    });
                    assert!(
                        found,
                        "{}: `{command}` does not print `{rest}` followed by {body:?}:\n{got}",
                        yaml.display()
                    );
                }
            }
            let out = eomgen(&["simulate", path, "--json"]);
            assert_eq!(out.status.code(), Some(2), "{}", yaml.display());
            let json: serde_json::Value = serde_json::from_slice(&out.stdout)
                .unwrap_or_else(|e| panic!("{}: not JSON ({e})", yaml.display()));
            let diagnostics = json["diagnostics"].as_array().unwrap();
            assert!(json["error"].is_string());
            for rest in &headlines {
                assert!(
                    diagnostics.iter().any(|d| {
                        let (line, column) =
                            (d["line"].as_u64().unwrap(), d["column"].as_u64().unwrap());
                        let message = d["message"].as_str().unwrap();
                        *rest == format!("{line}:{column}: {message}")
                            && d["file"].as_str() == Some(path)
                    }),
                    "{}: JSON lacks `{rest}`: {json}",
                    yaml.display()
                );
            }
            checked += 1;
        }
    }
    assert!(checked >= 28, "only {checked} ui cases");
}

/// The diagnostics of a recorded `.stderr`: each `error: FILE.yaml:line:col: message`
/// headline (from `line:`) with the lines that follow it up to the next diagnostic, rustc's
/// location of the `model!` call (`-->`) or a blank line, trimmed.
fn diagnostic_blocks(stderr: &str) -> Vec<(&str, Vec<&str>)> {
    let mut blocks: Vec<(&str, Vec<&str>)> = Vec::new();
    let mut open = false;
    for line in stderr.lines() {
        if let Some(rest) = line
            .strip_prefix("error: ")
            .and_then(|l| l.split_once(".yaml:").map(|(_, rest)| rest))
        {
            blocks.push((rest, Vec::new()));
            open = true;
        } else if line.trim().is_empty() || line.starts_with(" --> ") {
            open = false;
        } else if open && let Some((_, body)) = blocks.last_mut() {
            body.push(line.trim());
        }
    }
    blocks
}

/// Files are written to a temporary file beside them and renamed into place: after a run the
/// directory holds exactly the files asked for (no temporary file left), readable by others
/// as any new file is (not a temporary file's 0600), and a file in a missing directory is an
/// error naming the path the user gave (exit 1).
#[test]
fn files_are_replaced_whole() {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("a.html");
    std::fs::write(&page, "previous").unwrap();
    let out = eomgen(&[
        "animate",
        "simple_pendulum",
        "-o",
        page.to_str().unwrap(),
        "--t-end",
        "1",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["a.html"]);
    assert!(
        std::fs::read_to_string(&page)
            .unwrap()
            .ends_with("</html>\n")
    );
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&page).unwrap().permissions().mode();
        assert_ne!(mode & 0o044, 0, "mode {mode:o}");
    }
    let missing = dir.path().join("no_such_dir").join("a.html");
    let out = eomgen(&[
        "animate",
        "simple_pendulum",
        "-o",
        missing.to_str().unwrap(),
    ]);
    // A missing directory is found before the simulation (issue 28): a usage error.
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&format!(
            "--output `{}`: the directory `{}` does not exist",
            missing.display(),
            dir.path().join("no_such_dir").display()
        )),
        "{stderr}"
    );
    assert!(!stderr.contains(".eomgen-"), "{stderr}");
}

/// With `--json`, a model that cannot be opened (a missing file, an unknown name) is still
/// JSON on standard output, `{"error": …}` with the message of standard error, exit 2: a
/// script that reads the output never gets nothing.
#[test]
fn json_output_of_a_model_that_cannot_be_opened() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.yaml");
    let missing = missing.to_str().unwrap();
    for args in [
        vec!["check", "--json", missing],
        vec!["simulate", missing, "--json"],
        vec!["modes", "no_such_model", "--json"],
    ] {
        let out = eomgen(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let json: serde_json::Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{args:?}: not JSON ({e})"));
        let error = json["error"].as_str().unwrap();
        assert!(
            String::from_utf8_lossy(&out.stderr).contains(error),
            "{args:?}: {error}"
        );
    }
}

/// A file written by `eomgen new` runs through `simulate` with no rebuild (issue 18): the
/// 5-link pendulum's file is derived and compiled at run time, integrated, and keeps its
/// energy (a conservative chain: drift below 1e-6 at the default tolerances); an unknown name
/// that is not a file says so and that a path works too (exit 2).
#[test]
fn a_file_from_new_simulates_and_an_unknown_name_says_a_path_works() {
    let dir = std::env::temp_dir().join(format!("eomgen-new-p5-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = eomgen_ok(&["new", "n-link-pendulum", "5"]);
    let path = dir.join("p5.yaml");
    std::fs::write(&path, &out.stdout).unwrap();
    let out = eomgen_ok(&["simulate", path.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["model"], "n_link_pendulum_5");
    assert_eq!(v["coordinates"].as_array().map(Vec::len), Some(5));
    let drift = v["energy_drift"]
        .as_f64()
        .unwrap_or_else(|| panic!("no energy drift in {v}"));
    assert!(drift < 1e-6, "drift {drift}");
    let out = eomgen(&["simulate", "n_link_pendulum_5"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("no model named `n_link_pendulum_5`"),
        "{stderr}"
    );
    assert!(stderr.contains("a path to a model file"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `modes --plot PREFIX` prints its chart paths after the results (the last lines).
#[test]
fn modes_prints_its_chart_paths_after_the_results() {
    let dir = std::env::temp_dir().join(format!("eomgen-modes-order-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let prefix = dir.join("shape");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args([
            "modes",
            "double_pendulum",
            "--plot",
            prefix.to_str().unwrap(),
        ])
        .output()
        .expect("binary runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    let first_chart = lines
        .iter()
        .position(|l| l.starts_with("chart"))
        .expect("charts");
    assert!(
        first_chart > 0 && lines[first_chart - 1].starts_with("check"),
        "{text}"
    );
    assert!(
        lines[first_chart..].iter().all(|l| l.starts_with("chart")),
        "{text}"
    );
    assert_eq!(lines.len() - first_chart, 2, "one chart per mode: {text}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// An installed program (`cargo install`, a copied binary, a moved checkout) needs no source
/// tree (issue 28, item 3): the bundled models' files are embedded in the binary, so every
/// command that reads a bundled model's file — `check`, `equations`, `report`, `study floquet`,
/// `study constraint-methods` — works from a copy of the binary run in an empty directory.
/// (Before, `build.rs` recorded each file's absolute path and these commands read it: "cannot
/// read models/double_pendulum.yaml" once the checkout had moved.) The registry holds no path
/// any more (`ModelEntry` has the file's text and its display name only), so nothing can read
/// the build-time tree; this run also catches a read relative to the working directory.
#[test]
fn issue_28_bundled_models_run_without_the_source_tree() {
    let dir = tempfile::tempdir().unwrap();
    let binary = dir.path().join("eomgen");
    std::fs::copy(env!("CARGO_BIN_EXE_eomgen"), &binary).unwrap();
    let runs: [&[&str]; 6] = [
        &["check", "double_pendulum"],
        &["equations", "simple_pendulum_cartesian", "--latex"],
        &["equations", "double_pendulum", "--rust"],
        &["report", "--models", "simple_pendulum", "--out", "report"],
        &["study", "floquet", "mathieu_pendulum", "--tol", "1e-6"],
        &[
            "study",
            "constraint-methods",
            "simple_pendulum_cartesian",
            "--t-end",
            "0.5",
        ],
    ];
    for args in runs {
        // The copy's file descriptor was open for writing while other tests forked: a child
        // holds it until it executes its own program, and until then this one cannot run
        // ("Text file busy", ETXTBSY). Waiting out that instant is all it takes.
        let mut tries = 0;
        let out = loop {
            match std::process::Command::new(&binary)
                .args(args)
                .current_dir(dir.path())
                .output()
            {
                Err(e) if e.kind() == std::io::ErrorKind::ExecutableFileBusy && tries < 100 => {
                    tries += 1;
                    std::thread::sleep(std::time::Duration::from_millis(20));
                }
                other => break other.unwrap(),
            }
        };
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{args:?}: {err}");
        assert!(!err.contains("cannot read"), "{args:?}: {err}");
    }
    assert!(dir.path().join("report/index.html").is_file());
}

/// `equations` of a constrained model prints the equations the runtime solves (issue 28,
/// item 8: it printed `M q'' = F`, a free-falling particle, for the Cartesian pendulum):
/// `M q̈ + Jᵀλ = F` and `J q̈ = γ` with the constraint `Φ = 0`. Each printed expression is
/// parsed back and evaluated at random states against the closed forms of the pendulum on a
/// rod, `Φ = r − l` with `r = √(x² + y²)`: `J = (x, y)/r` and
/// `γ = −(ẋ² + ẏ²)/r + (x ẋ + y ẏ)²/r³` (to 1e-12 relative: a few roundings). The sign of
/// `λ` is the one `simulate` reports: hanging at rest, `Jᵀλ = F` gives `λ = m g`, the tension
/// `simulate --json` prints as the constraint force.
#[test]
fn issue_28_equations_of_a_constrained_model_show_the_constraint_forces() {
    use eomgen_symbolic::model::parser::{eval_expr, parse_expr};
    let out = eomgen(&["equations", "simple_pendulum_cartesian"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        text.contains("M q'' + J^T lambda = F and J q'' = gamma"),
        "{text}"
    );
    assert!(
        text.contains("rod: sqrt(x^2 + y^2) - l = 0 (holonomic"),
        "{text}"
    );
    let latex = stdout(eomgen_ok(&[
        "equations",
        "simple_pendulum_cartesian",
        "--latex",
    ]));
    assert!(latex.contains("\\lambda_{\\mathrm{rod}}"), "{latex}");
    let nonholonomic = stdout(eomgen_ok(&["equations", "chaplygin_sleigh"]));
    assert!(
        nonholonomic.contains("(non-holonomic: A q' + b = 0)"),
        "{nonholonomic}"
    );

    let json = stdout(eomgen_ok(&[
        "equations",
        "simple_pendulum_cartesian",
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let e = &v["equations"];
    let rod = &e["constraints"][0];
    assert_eq!(rod["name"], "rod");
    assert_eq!(rod["kind"], "holonomic");
    let (m, l, g) = (1.0, 1.0, 10.0);
    let mut rng = common::seeded_rng(28);
    for _ in 0..20 {
        use rand::RngExt as _;
        let [x, y, xd, yd]: [f64; 4] = std::array::from_fn(|_| rng.random_range(-2.0..2.0));
        let value = |text: &serde_json::Value| {
            let expr = parse_expr(text.as_str().unwrap(), Default::default()).unwrap();
            eval_expr(&expr, &|name| match name {
                "x" => Some(x),
                "y" => Some(y),
                "x_dot" => Some(xd),
                "y_dot" => Some(yd),
                "m" => Some(m),
                "l" => Some(l),
                "g" => Some(g),
                _ => None,
            })
            .unwrap()
        };
        let r = x.hypot(y);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        assert!(close(value(&rod["equation"]), r - l));
        assert!(close(value(&rod["jacobian"][0]), x / r));
        assert!(close(value(&rod["jacobian"][1]), y / r));
        let gamma = -(xd * xd + yd * yd) / r + (x * xd + y * yd).powi(2) / r.powi(3);
        assert!(
            close(value(&rod["gamma"]), gamma),
            "{} {gamma}",
            value(&rod["gamma"])
        );
        assert!(close(value(&e["forcing"][1]), -m * g));
        assert!(close(value(&e["mass_matrix"][0][0]), m));
    }
    // Hanging at rest: q̈ = 0, so Jᵀλ = F with J = (0, −1) gives λ = m g, as simulated.
    let run = stdout(eomgen_ok(&[
        "simulate",
        "simple_pendulum_cartesian",
        "--init",
        "x=0,y=-l",
        "--t-end",
        "0.01",
        "--json",
    ]));
    let run: serde_json::Value = serde_json::from_str(&run).unwrap();
    let lambda = run["samples"][0]["constraint_forces"][0].as_f64().unwrap();
    assert!((lambda - m * g).abs() < 1e-12, "{lambda}");
}

fn stdout(out: std::process::Output) -> String {
    String::from_utf8(out.stdout).unwrap()
}

/// Issue 49: `--set` values meet the rules the model file's defaults meet (masses positive, a
/// positive definite inertia, `I₃ ≤ I₁ + I₂` within 0.1 %), with the file check's words and
/// the assignments named, exit 2. Before, `heavy_top --set l=1` (centroidal moments
/// `I1 − m l² = −0.98`) simulated with exit 0, `whipple_bicycle --set IBxz=100` (an indefinite
/// frame) failed at t = 0.23 blaming the constraints, and `free_rigid_body --set I3=3.5`
/// (17 % beyond the triangle inequality) ran. Within the margin it runs, and so does a value
/// that passes through an impossible body on the way (`I3`, then `I1`).
#[test]
fn set_values_meet_the_body_rules() {
    for (model, set, body, what) in [
        ("heavy_top", "l=1", "top", "not positive definite"),
        (
            "whipple_bicycle",
            "IBxz=100",
            "rear_frame",
            "not positive definite",
        ),
        ("free_rigid_body", "I3=3.5", "body", "triangle inequality"),
        ("double_pendulum", "m1=-1", "upper", "non-positive mass"),
    ] {
        for command in [&["simulate", model][..], &["modes", model]] {
            let out = eomgen(&[command, &["--set", set]].concat());
            assert_eq!(out.status.code(), Some(2), "{command:?} {set}");
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(
                err.contains(&format!("body `{body}`"))
                    && err.contains(what)
                    && err.contains(&format!("--set {set}")),
                "{err}"
            );
        }
    }
    eomgen_ok(&[
        "simulate",
        "free_rigid_body",
        "--set",
        "I3=3.002",
        "--t-end",
        "0.1",
    ]);
    // I1 = 1, I2 = 2, I3 = 3 by default: I3 = 5 alone breaks the inequality, with I1 = 3 too
    // it holds (5 ≤ 3 + 2).
    eomgen_ok(&[
        "simulate",
        "free_rigid_body",
        "--set",
        "I3=5",
        "--set",
        "I1=3",
        "--t-end",
        "0.1",
    ]);
}

/// Issue 49: settings that make a run impossible are named before guesses about the model.
/// An end time of 1e300 s (f64 resolves t there to 3.6e285 s) was "the model may divide by
/// zero" for dp54 and dop853, with a time of 300 digits, and a Newton failure for radau5;
/// `--rtol 1e-15 --atol 0` from rest was "the model may be stiff".
#[test]
fn impossible_settings_are_blamed_not_the_model() {
    for method in ["dp54", "dop853", "radau5", "taylor"] {
        let out = eomgen(&[
            "simulate",
            "simple_pendulum",
            "--t-end",
            "1e300",
            "--method",
            method,
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{method}: {err}");
        assert!(
            err.contains("the end time 1e300 s is so large"),
            "{method}: {err}"
        );
        assert!(
            !err.contains("divide by zero") && err.lines().all(|l| l.len() < 400),
            "{method}: {err}"
        );
    }
    let out = eomgen(&[
        "simulate",
        "simple_pendulum",
        "--rtol",
        "1e-15",
        "--atol",
        "0",
        "--method",
        "dop853",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("give --atol above 0") && !err.contains("stiff"),
        "{err}"
    );
}

/// After a failed integration the help names what the model shows where it stopped, before
/// any guess about the method (issue 28, item 7): "the model may be stiff; try radau5" was
/// given for a mass matrix singular because of a parameter (`l1 = 0`, then described as
/// "the coordinates are singular"), for a negative mass (also to a run already using radau5)
/// and for a solution that runs into a singularity; a fixed-step run out of steps was told to
/// loosen `--rtol`; radau5 with `--atol 0` reported "Newton … residual norm inf".
#[test]
fn issue_28_failure_hints_name_the_model_cause() {
    let help = |args: &[&str]| {
        let out = eomgen(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        err.lines()
            .find_map(|l| l.strip_prefix("help: "))
            .unwrap_or_else(|| panic!("{args:?}: no help in {err}"))
            .to_string()
    };
    // l1 = 0: M = [[m1/3 + m2, 0], [0, m2 l2²/3]] loses its first row everywhere.
    let h = help(&["simulate", "double_pendulum", "--set", "l1=0"]);
    assert!(
        h.contains("every configuration") && h.contains("l1 = 0"),
        "{h}"
    );
    assert!(
        !h.contains("coordinates are singular") && !h.contains("stiff"),
        "{h}"
    );
    // m1 = −1: det M = m2²/9 − m2² cos²(θ1 − θ2)/4 + m1 m2/9 vanishes when cos² = 8/9. The
    // double pendulum in energy form: with bodies, `--set m1=-1` is refused before the run
    // (`set_values_meet_the_body_rules`).
    let energy_form = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/energy_double_pendulum.yaml"
    );
    for method in ["dp54", "radau5"] {
        let h = help(&[
            "simulate",
            energy_form,
            "--set",
            "m1=-1",
            "--method",
            method,
        ]);
        assert!(
            h.contains("negative mass") && h.contains("m1 = -1"),
            "{method}: {h}"
        );
        assert!(!h.contains("try --method radau5"), "{method}: {h}");
    }
    let well = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/log_well.yaml");
    for method in ["dp54", "radau5"] {
        let h = help(&["simulate", well, "--method", method]);
        assert!(h.starts_with("not stiffness"), "{method}: {h}");
        assert!(!h.contains("try --method radau5"), "{method}: {h}");
    }
    // An inertia m (x − d)² that vanishes at x = d, reached with unbounded speed: the unit-
    // diagonal test of M cannot see a diagonal entry collapse, and this was "not stiffness"
    // with no cause. The entry is measured against its value at the start and named; a
    // negative offset d is no negative mass.
    let slider = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/vanishing_inertia.yaml"
    );
    for set in [&[][..], &["--set", "d=-1", "--set", "F0=-1"][..]] {
        let h = help(&[&["simulate", slider, "--t-end", "2"][..], set].concat());
        assert!(h.starts_with("the inertia of `x` vanishes"), "{set:?}: {h}");
        assert!(
            !h.contains("not stiffness") && !h.contains("negative"),
            "{set:?}: {h}"
        );
    }
    // 10⁷ fixed steps wanted, 10⁶ allowed: the step is the setting to change, not --rtol.
    let h = help(&[
        "simulate",
        "simple_pendulum",
        "--method",
        "rk4",
        "--dt",
        "1e-7",
        "--t-end",
        "1",
        "--t-out",
        "1",
    ]);
    assert!(h.contains("larger --dt") && !h.contains("rtol"), "{h}");
    for method in ["radau5", "implicit-midpoint"] {
        let out = eomgen(&[
            "simulate",
            "double_pendulum",
            "--method",
            method,
            "--atol",
            "0",
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{method}: {err}");
        assert!(
            err.contains("absolute tolerance above 0"),
            "{method}: {err}"
        );
        assert!(!err.contains("inf"), "{method}: {err}");
    }
}

/// The CLI's two layers (issue 29, item 4): a command in `src/cli/commands/` imports the
/// library and the shared pieces beside `src/cli/mod.rs` (`crate::cli::…`), never another
/// command. Checked over every file below `src/cli/` (folders included), in the code before
/// the file's test module (`#[cfg(test)]` followed by `mod`):
/// - inside `commands/`, neither `super::` (a sibling command) nor the word `commands` (a
///   path to the commands, or an alias of it) may appear;
/// - outside it, only `src/cli/mod.rs` (which dispatches) may name `commands`, so that no
///   shared piece re-exports a command.
#[test]
fn commands_import_no_other_command() {
    fn files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                files(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/src/cli"));
    let mut all = Vec::new();
    files(root, &mut all);
    let mut commands = 0;
    for path in &all {
        let relative = path.strip_prefix(root).unwrap();
        let in_commands = relative.starts_with("commands");
        if relative == std::path::Path::new("mod.rs")
            || relative == std::path::Path::new("commands/mod.rs")
        {
            continue;
        }
        let text = std::fs::read_to_string(path).unwrap();
        let code = text.split("#[cfg(test)]\nmod ").next().unwrap_or_default();
        for (k, line) in code.lines().enumerate() {
            let names_commands = line
                .split(|c: char| !(c.is_alphanumeric() || c == '_'))
                .any(|word| word == "commands");
            let bad = if in_commands {
                line.contains("super::") || names_commands
            } else {
                names_commands && !line.trim_start().starts_with("//")
            };
            assert!(
                !bad,
                "{}:{}: a command imports another command, or a shared piece names the \
                 commands: `{}`; move what they share to a file beside src/cli/mod.rs",
                path.display(),
                k + 1,
                line.trim()
            );
        }
        commands += usize::from(in_commands);
    }
    assert!(
        commands >= 10,
        "only {commands} command files found below {}",
        root.display()
    );
}

/// Constraints that fix every coordinate leave no degree of freedom: the modal analyses say
/// so (exit 1) instead of panicking on a 0 × 0 eigenproblem, and the model still simulates.
#[test]
fn issue_31_a_model_without_freedom_has_no_modes_and_no_panic() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/fully_constrained.yaml"
    );
    for args in [
        &["modes", file][..],
        &[
            "study",
            "parameter-sweep",
            file,
            "--parameter",
            "g",
            "--values",
            "1..2:3",
        ][..],
        &["study", "free-response", file][..],
    ] {
        let out = eomgen(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(
            stderr.contains("no degree of freedom"),
            "{args:?}: {stderr}"
        );
    }
    let out = eomgen(&["simulate", file, "--t-end", "1"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
