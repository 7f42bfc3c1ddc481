//! Generalized speeds from the command line: `equations` lists Kane's equations in the speeds
//! with the kinematic equations, `check` compares them with Lagrange's carried into the speeds,
//! and the commands that would run the model in the state `(q, q̇)` refuse it with a located
//! message (exit 2) instead of a wrong result.

use crate::common::{eomgen, eomgen_ok};

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

/// `simulate`, `modes` and the exported code refuse a model in speeds, naming the line of
/// its first speed, with exit 2.
#[test]
fn a_model_in_speeds_is_not_run_in_the_wrong_state() {
    let body = fixture("free_rigid_body_speeds.yaml");
    for args in [
        vec!["simulate", body.as_str()],
        vec!["modes", body.as_str()],
        vec!["equations", body.as_str(), "--c"],
    ] {
        let out = eomgen(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("free_rigid_body_speeds.yaml:20:3: a model with generalized speeds is derived and printed"),
            "{args:?}: {err}"
        );
    }
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
