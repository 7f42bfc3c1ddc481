//! Issue 6: the `study stability` and `study euler-roundoff` commands end to end. The
//! studies themselves (stability limits against the theory of the stability functions,
//! Radau IIA on the stiff two-mass spring, round-off) are tested in the runtime crate,
//! `runtime/tests/stability.rs`.

use crate::common;
use common::{eomgen, eomgen_ok};

use std::f64::consts::E;

/// `study euler-roundoff --max-n 2 --json` renders the library's study
/// (`runtime/tests/stability.rs`): the documented keys.
#[test]
fn euler_roundoff_cli_json() {
    let out = eomgen_ok(&["study", "euler-roundoff", "--max-n", "2", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["exact"].as_f64().unwrap(), E);
    for key in ["epsilon", "notes", "rows", "summary"] {
        assert!(!v[key].is_null(), "{key}");
    }
}

/// `study stability --json --plot` renders the study: the documented keys and three charts;
/// bad options are usage errors.
#[test]
fn stability_study_runs_and_writes_its_charts() {
    let dir = std::env::temp_dir().join(format!("eomgen-stability-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let prefix = dir.join("s.svg");
    let prefix = prefix.to_str().unwrap();
    let out = eomgen(&[
        "study",
        "stability",
        "--steps",
        "2000",
        "--periods",
        "100",
        "--stiffness",
        "1e2",
        "--json",
        "--plot",
        prefix,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in ["rows", "amplification", "polynomials", "growth_threshold"] {
        assert!(!v["limits"][key].is_null(), "limits.{key}");
    }
    // A row per explicit method's stability polynomial and per partitioned method, as
    // runtime/tests/stability.rs counts them (18 with the four Verner pairs).
    assert_eq!(v["limits"]["rows"].as_array().unwrap().len(), 18);
    assert!(v["energy"]["runs"].is_array());
    assert_eq!(v["stiff"]["runs"].as_array().unwrap().len(), 2 * 4);
    assert!(v["underflow"]["failure"]["error"].is_string());
    for name in ["limits", "energy", "stiff"] {
        let path = dir.join(format!("s-{name}.svg"));
        assert!(std::fs::metadata(&path).unwrap().len() > 1000, "{path:?}");
    }
    let bad = eomgen(&["study", "stability", "--steps", "5"]);
    assert_eq!(bad.status.code(), Some(2));
    let bad = eomgen(&["study", "euler-roundoff", "--max-n", "11"]);
    assert_eq!(bad.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).unwrap();
}
