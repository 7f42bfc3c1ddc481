//! `eomgen study work-precision` end to end (issue 6): the reference is verified and its
//! agreement reported; adaptive errors fall with the tolerance; fixed-step errors fall at the
//! method's order; the JSON contract; charts in SVG and PNG; failures in rows; usage errors.
//!
//! Every run here uses the small `simple_pendulum` (or `double_pendulum` over 3 s), a few
//! settings and `--repeats 1 --min-time-ms 0`, so the file stays fast in the debug profile.
//! No assertion involves a wall time.

use crate::common;
use common::{eomgen, eomgen_ok};

use eomgen::analysis::{
    Measured, Method, Setting, WorkPrecision, WorkPrecisionOptions, work_precision,
};
use serde_json::Value;

/// Runs the study with the fastest timing (one run per setting); it must succeed.
fn study(args: &[&str]) -> std::process::Output {
    let mut all = vec!["study", "work-precision"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--repeats", "1", "--min-time-ms", "0"]);
    eomgen_ok(&all)
}

/// Runs the study with `--json` and the fastest timing, and parses its output.
fn study_json(args: &[&str]) -> Value {
    let mut all = args.to_vec();
    all.push("--json");
    serde_json::from_slice(&study(&all).stdout).expect("valid JSON")
}

/// Simple pendulum over 2 s, Dormand–Prince 5(4) at 1e-3…1e-6 and RK4 (steps to be added).
const DP54_AND_RK4: [&str; 7] = [
    "simple_pendulum",
    "--t-end",
    "2",
    "--methods",
    "dp54,rk4",
    "--tols",
    "1e-3..1e-6",
];

/// The method entry named `name` (command-line name).
fn method<'v>(v: &'v Value, name: &str) -> &'v Value {
    v["methods"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["method"] == name)
        .unwrap_or_else(|| panic!("no method {name} in {v}"))
}

/// Simple pendulum released horizontally, 2 s (one swing): the reference (DOP853 at 1e-14)
/// and its Dormand–Prince 5(4) check agree to about 2e-13 (seen: 1.6e-13), so the bound
/// 1e-11 leaves two orders of margin while still failing for a wrong or unchecked reference.
/// Between tol 1e-4 and 1e-10 the errors fall by 1e6 (seen: 1.0e6 for bs32 up to 2.4e6 for
/// radau5), so requiring 100× allows for any non-monotone wobble but not for a tolerance
/// that is ignored. Each error stays within 100× of its tolerance (seen: ≤ 46×), and the
/// smallest ones (~1e-9) are resolved by the reference.
#[test]
fn reference_is_verified_and_adaptive_errors_fall_with_the_tolerance() {
    let methods = [Method::Bs32, Method::Dp54, Method::Dop853, Method::Radau5];
    let study = library_study(WorkPrecisionOptions {
        methods: methods.to_vec(),
        tolerances: vec![1e-4, 1e-7, 1e-10],
        ..fast_options()
    });
    assert!(
        (0.0..1e-11).contains(&study.agreement),
        "agreement {}",
        study.agreement
    );
    for (r, method) in study.results.iter().zip(methods) {
        assert_eq!(r.method, method);
        let tols: Vec<f64> = r
            .runs
            .iter()
            .map(|run| match run.setting {
                Setting::Tolerance(tol) => tol,
                other => panic!("{method}: {other:?}"),
            })
            .collect();
        assert_eq!(tols, [1e-4, 1e-7, 1e-10], "{method}: loosest first");
        let measured: Vec<&Measured> = r
            .runs
            .iter()
            .map(|run| run.outcome.as_ref().unwrap())
            .collect();
        let e: Vec<f64> = measured.iter().map(|m| m.error).collect();
        assert!(e[2] * 100.0 <= e[0], "{method}: errors {e:?}");
        for (err, tol) in e.iter().zip(&tols) {
            assert!(
                *err > 0.0 && *err < 100.0 * tol,
                "{method}: {err} at tol {tol}"
            );
        }
        for m in measured {
            assert!(!study.unresolved(m), "{method}: {m:?}");
        }
    }
}

/// Fixed steps h = 2 s/N, N = 32, 64, 128, 256: the error ratio between halvings tends to
/// 2ᵖ. Seen on this model: RK4 16.0, 15.8, 14.3; Störmer–Verlet 3.99, 4.00, 4.00; explicit
/// Euler 1.79, 2.11, 2.07; implicit midpoint 3.99, 4.00, 4.01. The accepted band is 2ᵖ
/// within a factor 1.4 either way (RK4 11.4…22.4, order-2 2.9…5.6, Euler 1.4…2.8): an
/// order-one-lower method (ratio 2ᵖ⁻¹) or a step not applied would fail it. Errors are
/// taken by cubic Hermite dense output, whose own error is O(h⁴), so the ratios hold at the
/// output times too.
#[test]
fn fixed_step_errors_fall_at_the_method_order() {
    let methods = [
        (Method::Rk4, 4),
        (Method::StormerVerlet, 2),
        (Method::Euler, 1),
        (Method::ImplicitMidpoint, 2),
    ];
    let study = library_study(WorkPrecisionOptions {
        methods: methods.iter().map(|(m, _)| *m).collect(),
        steps: Some(vec![32, 64, 128, 256]),
        ..fast_options()
    });
    for (r, (method, order)) in study.results.iter().zip(methods) {
        assert_eq!(r.method, method);
        assert!(!method.is_adaptive());
        assert_eq!(method.integrator().order(), order);
        let steps: Vec<usize> = r
            .runs
            .iter()
            .map(|run| match run.setting {
                Setting::Steps { steps, .. } => steps,
                other => panic!("{method}: {other:?}"),
            })
            .collect();
        assert_eq!(steps, [32, 64, 128, 256], "{method}");
        let expected = f64::from(1u32 << order);
        let e: Vec<f64> = r
            .runs
            .iter()
            .map(|run| run.outcome.as_ref().unwrap().error)
            .collect();
        for pair in e.windows(2) {
            let ratio = pair[0] / pair[1];
            assert!(
                ratio > expected / 1.4 && ratio < expected * 1.4,
                "{method}: error ratio {ratio} between halvings, expected ≈ {expected} ({e:?})"
            );
        }
    }
}

/// The library's options for the simple pendulum over 2 s with the fastest timing.
fn fast_options() -> WorkPrecisionOptions {
    WorkPrecisionOptions {
        t_end: 2.0,
        repeats: 1,
        min_time_s: 0.0,
        ..WorkPrecisionOptions::default()
    }
}

/// The study of the simple pendulum through the library the CLI calls.
fn library_study(options: WorkPrecisionOptions) -> WorkPrecision {
    let mut model = (eomgen::models::find("simple_pendulum").unwrap().make)();
    work_precision(model.as_mut(), &options, &mut |_, _| {}).expect("the study runs")
}

/// The JSON contract: the promised keys at the top, per method, per run and at the target;
/// a target between the first and last errors is bracketed, and its interpolated RHS
/// evaluations lie between those of the runs around it.
#[test]
fn json_has_the_promised_keys() {
    let mut args = DP54_AND_RK4.to_vec();
    args.extend(["--steps", "16,32,64", "--target-error", "1e-4"]);
    args.extend(["--baseline-ms", "60"]);
    let v = study_json(&args);
    for key in [
        "model",
        "t_end",
        "samples",
        "error_norm",
        "conservative",
        "target_error",
        "baseline_ms",
        "timing",
        "reference",
        "methods",
    ] {
        assert!(v.get(key).is_some(), "missing `{key}` in {v}");
    }
    assert_eq!(v["model"], "simple_pendulum");
    assert_eq!(v["samples"], 100);
    assert_eq!(v["conservative"], true);
    assert_eq!(v["timing"]["statistic"], "median");
    for key in [
        "method",
        "rtol",
        "atol",
        "steps",
        "check_method",
        "agreement",
    ] {
        assert!(v["reference"].get(key).is_some(), "reference lacks `{key}`");
    }
    let dp54 = method(&v, "dp54");
    assert_eq!(dp54["name"], "Dormand–Prince 5(4)");
    assert_eq!(dp54["runs"].as_array().unwrap().len(), 4);
    for m in v["methods"].as_array().unwrap() {
        for key in ["method", "name", "order", "adaptive", "runs", "at_target"] {
            assert!(m.get(key).is_some(), "method lacks `{key}`: {m}");
        }
        for r in m["runs"].as_array().unwrap() {
            for key in [
                "tol",
                "num_steps",
                "dt",
                "error",
                "resolved",
                "rhs_evals",
                "steps",
                "rejected",
                "jacobian_evals",
                "lu_decompositions",
                "wall_time_s",
                "repeats",
                "energy_drift",
                "failure",
            ] {
                assert!(r.get(key).is_some(), "run lacks `{key}`: {r}");
            }
            assert!(r["failure"].is_null());
            assert!(r["wall_time_s"].as_f64().unwrap() > 0.0);
            assert!(r["energy_drift"].as_f64().unwrap() >= 0.0);
            assert!(r["rhs_evals"].as_u64().unwrap() > 0);
        }
    }
    // dp54 errors at 1e-3…1e-6 span about 1e-2…2e-5, so 1e-4 is bracketed.
    let target = &dp54["at_target"];
    assert_eq!(target["reached"], true, "{target}");
    let evals = target["rhs_evals"].as_f64().unwrap();
    let runs = dp54["runs"].as_array().unwrap();
    let bracket = runs
        .windows(2)
        .find(|w| {
            w[0]["error"].as_f64().unwrap() >= 1e-4 && w[1]["error"].as_f64().unwrap() <= 1e-4
        })
        .expect("a bracketing pair");
    let (lo, hi) = (
        bracket[0]["rhs_evals"].as_f64().unwrap(),
        bracket[1]["rhs_evals"].as_f64().unwrap(),
    );
    assert!(lo <= evals && evals <= hi, "{lo} ≤ {evals} ≤ {hi}");
    assert!(target["baseline_ratio"].as_f64().unwrap() > 0.0);
}

/// `--plot PREFIX` writes four charts; each must be a real image with data, not an empty
/// frame: an SVG with its lines drawn (a `<polyline` per method) and a PNG with the magic
/// bytes, over 10 kB (a blank 960 × 600 PNG compresses to a few kB).
#[test]
fn charts_are_written_as_svg_and_png() {
    let dir = std::env::temp_dir().join(format!("eomgen-wp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let prefix = dir.join("wp");
    let prefix = prefix.to_str().unwrap();
    let mut args = DP54_AND_RK4.to_vec();
    args.extend(["--steps", "16..128", "--plot", prefix]);
    let out = study(&args);
    for tag in ["evals", "time"] {
        let svg = std::fs::read_to_string(format!("{prefix}-{tag}.svg")).unwrap();
        assert!(svg.starts_with("<svg"), "{tag}.svg");
        assert!(svg.matches("<polyline").count() >= 2, "{tag}.svg: no lines");
        assert!(svg.contains("Dormand–Prince 5(4)") && svg.contains("RK4"));
        let png = std::fs::read(format!("{prefix}-{tag}.png")).unwrap();
        assert!(png.starts_with(b"\x89PNG"), "{tag}.png");
        assert!(png.len() > 10_000, "{tag}.png is only {} bytes", png.len());
    }
    let _ = std::fs::remove_dir_all(&dir);
    // The text table: a header, one row per run, the work at the target.
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("agrees to"), "{text}");
    assert!(text.contains("work to reach an error of 5e-4"), "{text}");
    assert_eq!(text.matches("Dormand–Prince 5(4)  ").count(), 5, "{text}");
}

/// A method that fails at a setting is reported in its row (error text with t and reason),
/// the others still run, and the study succeeds: Störmer–Verlet on the double pendulum with
/// h = 3 s/16 blows up (seen: a non-finite right-hand side at t = 2.25).
#[test]
fn a_failing_setting_is_a_row_not_a_crash() {
    let v = study_json(&[
        "double_pendulum",
        "--t-end",
        "3",
        "--methods",
        "stormer-verlet,dp54",
        "--steps",
        "16,4096",
        "--tols",
        "1e-6",
    ]);
    let runs = method(&v, "stormer-verlet")["runs"]
        .as_array()
        .unwrap()
        .clone();
    let failure = &runs[0]["failure"];
    assert!(failure["t"].as_f64().unwrap() > 0.0, "{failure}");
    assert!(
        failure["message"].as_str().unwrap().contains("not finite"),
        "{failure}"
    );
    assert!(runs[0]["error"].is_null() && runs[0]["wall_time_s"].is_null());
    assert!(runs[1]["error"].as_f64().unwrap() < 1.0);
    assert!(method(&v, "dp54")["runs"][0]["error"].as_f64().is_some());
}

/// A reference that cannot be verified far below the target is refused (exit 1, saying
/// why); runs below 10× the agreement are flagged, loudly, on stderr and in JSON.
#[test]
fn an_unverified_reference_is_refused_and_unresolved_runs_are_flagged() {
    // At 1e-8 DOP853 and Dormand–Prince 5(4) differ by ~2e-7 (seen), not ≤ 1e-6 / 100.
    let out = eomgen(&[
        "study",
        "work-precision",
        "simple_pendulum",
        "--t-end",
        "2",
        "--reference-tol",
        "1e-8",
        "--target-error",
        "1e-6",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("reference is not verified"), "{stderr}");

    // At 1e-10 they agree to ~1.6e-9 (seen): fine for a target of 1e-3, but dp54 at 1e-12
    // (error ~1e-11 against the truth) is below 10× that agreement.
    let out = study(&[
        "simple_pendulum",
        "--t-end=2",
        "--methods=dp54",
        "--tols=1e-4,1e-12",
        "--reference-tol=1e-10",
        "--target-error=1e-3",
        "--json",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("warning: 1 run(s)"), "{stderr}");
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let runs = method(&v, "dp54")["runs"].as_array().unwrap().clone();
    assert_eq!(runs[0]["resolved"], true);
    assert_eq!(runs[1]["resolved"], false);
}

/// Bad `--tols`, `--steps` or methods are usage errors (exit 2) naming the option, before any
/// integration.
#[test]
fn bad_options_are_usage_errors() {
    for (args, expected) in [
        (&["--tols", "1e-3..abc"][..], "--tols"),
        (&["--tols", "1e-3..3e-5"][..], "whole number of decades"),
        (&["--tols", "0"][..], "[1e-15, 1)"),
        (&["--tols", "1e-3;1e-4"][..], "--tols"),
        (&["--steps", "0..64"][..], "--steps"),
        (&["--steps", "1.5"][..], "--steps"),
        (&["--methods", "rk5"][..], "invalid value 'rk5'"),
        (&["--t-end=-1"][..], "--t-end"),
        (&["--samples", "0"][..], "--samples"),
        (&["--target-error", "0"][..], "--target-error"),
    ] {
        let mut all = vec!["study", "work-precision", "simple_pendulum"];
        all.extend_from_slice(args);
        let out = eomgen(&all);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}

/// Issue 28: `study work-precision double_pendulum --t-end 1e-320` exited 0 with a table of
/// 0.00 errors: the reference moved less than its own tolerance, so no error could be
/// measured. The library refuses it (`WorkPrecisionError::NoMotion`); the command refuses
/// end times outside [1e-6, 1e6] s when it reads its options (`tests/wrong_successes.rs`).
/// A study every run of which failed exits 1 with the first failure, and
/// `study constraint-methods --tol 1e-320` (every run underflows at t = 0) prints `failed`
/// in its error columns, never 0.00, and exits 1.
#[test]
fn issue_28_a_study_that_measured_nothing_is_a_failure() {
    use eomgen::analysis::WorkPrecisionError;
    let mut model = (eomgen::models::find("double_pendulum").unwrap().make)();
    let options = WorkPrecisionOptions {
        methods: vec![Method::Dp54],
        tolerances: vec![1e-3],
        t_end: 1e-320,
        repeats: 1,
        min_time_s: 0.0,
        ..WorkPrecisionOptions::default()
    };
    let refused = work_precision(model.as_mut(), &options, &mut |_, _| {});
    assert!(
        matches!(refused, Err(WorkPrecisionError::NoMotion { .. })),
        "{refused:?}"
    );
    // Every setting failing: RK4 in two steps of 5 s over 10 s of the double pendulum
    // overflows.
    let out = eomgen(&[
        "study",
        "work-precision",
        "double_pendulum",
        "--methods",
        "rk4",
        "--steps",
        "2",
        "--t-end",
        "10",
        "--repeats",
        "1",
        "--min-time-ms",
        "0",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}{err}");
    assert!(
        err.contains("work-precision: every run failed (1 of 1)")
            && err.contains("the first failed: RK4 at h 5.000e0: component 2 of the right-hand side is not finite"),
        "{err}"
    );

    let args = [
        "study",
        "constraint-methods",
        "two_masses_rod",
        "--tol",
        "1e-320",
        "--t-end",
        "1",
    ];
    // The table has wall times, which differ between the bundled model and its file: run
    // once, directly.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args(args)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&out.stderr);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}{err}");
    assert!(
        err.contains("constraint-methods: every run failed (6 of 6)"),
        "{err}"
    );
    // The method rows (the header's `II.2` line names the eliminated coordinate).
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("I:") || l.starts_with("II.1:") || l.starts_with("II.2:"))
        .collect();
    // Three springs, the DAE with and without Baumgarte, and the reduced model (II.2).
    assert_eq!(rows.len(), 6, "{text}");
    for line in rows {
        let columns: Vec<&str> = line.split_whitespace().collect();
        assert!(
            columns.windows(2).any(|w| w == ["failed", "failed"]),
            "{line}"
        );
        assert!(!line.contains("0.00 "), "{line}");
    }
    let out = eomgen(&[&args[..], &["--json"]].concat());
    assert_eq!(out.status.code(), Some(1));
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    for m in v["methods"].as_array().unwrap() {
        assert!(
            m["position_error_m"].is_null() && m["max_constraint_drift"].is_null(),
            "{m}"
        );
        assert!(
            m["error"]
                .as_str()
                .unwrap()
                .contains("smallest usable step"),
            "{m}"
        );
    }
}
