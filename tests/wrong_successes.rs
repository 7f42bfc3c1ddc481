//! Settings that used to give a wrong result with a success (exit 0) now give a usage error
//! (exit 2), a warning, a failure (exit 1) or a hint that names the real cause. Each of these
//! commands was run before the change and did what its test's comment says.

use crate::common;
use common::eomgen;

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Runs `eomgen args`, which must be a usage error (status 2) whose message contains `says`;
/// returns its standard error.
fn usage_error(args: &[&str], says: &str) -> String {
    let out = eomgen(args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains(says), "{args:?}: {err}");
    err
}

/// Relative tolerances of 1 or more, and negative ones written after a space (which clap
/// used to take for an unknown option), are usage errors in every command that takes one.
#[test]
fn tolerances_out_of_range_are_usage_errors_everywhere() {
    let cases: [&[&str]; 11] = [
        &["simulate", "simple_pendulum", "--rtol", "1"],
        // Issue 28: the documented range is (0, 1), and 0 was accepted.
        &["simulate", "simple_pendulum", "--rtol", "0"],
        &[
            "animate",
            "simple_pendulum",
            "-o",
            "unwritten.html",
            "--rtol",
            "0",
        ],
        &["simulate", "simple_pendulum", "--rtol", "-1"],
        &["simulate", "simple_pendulum", "--atol", "-1e-9"],
        &[
            "study",
            "constraint-methods",
            "simple_pendulum_cartesian",
            "--tol",
            "2",
        ],
        &["study", "free-response", "three_masses", "--tol", "1"],
        &["study", "modal-damping", "three_masses", "--tol", "-0.5"],
        &["study", "floquet", "mathieu_pendulum", "--tol", "1"],
        &["study", "stability", "--tol", "1.5"],
        &["frf", "forced_oscillator", "--input", "F0", "--rtol", "1"],
    ];
    for args in cases {
        let out = eomgen(args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("tolerance"), "{args:?}: {err}");
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
    }
}

/// Non-positive stiffnesses were accepted by `constraint-methods` (a spring of stiffness −1
/// pushes the constraint apart).
#[test]
fn non_positive_stiffnesses_are_usage_errors() {
    for args in [
        &[
            "study",
            "constraint-methods",
            "simple_pendulum_cartesian",
            "--stiffness",
            "0,-1",
        ][..],
        &["study", "stability", "--stiffness", "1e4,-5"],
    ] {
        let out = eomgen(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains("positive"), "{}", stderr(&out));
    }
}

/// `simulate --method rk4 --dt 100` took the double pendulum's energy from 5 J to 3.4e33 J
/// with exit 0 and no word: it now warns, on standard error and in the JSON, naming the
/// stability limit; a step longer than the span warns too; a step well inside the limit
/// gives no warning.
#[test]
fn a_fixed_step_past_the_stability_limit_warns() {
    let out = eomgen(&[
        "simulate",
        "double_pendulum",
        "--method",
        "rk4",
        "--dt",
        "100",
        "--t-end",
        "1000",
        "--json",
    ]);
    let err = stderr(&out);
    assert!(
        err.contains("warning: the step 100 s is past the stability limit of RK4"),
        "{err}"
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let warning = &json["warnings"][0];
    assert_eq!(warning["kind"], "step_past_stability_limit");
    let suggested = warning["suggested_dt"].as_f64().unwrap();
    // The start's linearisation has modes of |λ| ~ 1/s: the limit is of the order of 1 s.
    assert!(suggested > 0.01 && suggested < 10.0, "{suggested}");

    let out = eomgen(&[
        "simulate",
        "simple_pendulum",
        "--method",
        "euler",
        "--dt",
        "20",
        "--t-end",
        "10",
    ]);
    assert!(
        stderr(&out).contains("longer than the whole run"),
        "{}",
        stderr(&out)
    );

    let out = eomgen(&[
        "simulate",
        "double_pendulum",
        "--method",
        "rk4",
        "--dt",
        "0.01",
    ]);
    assert_eq!(out.status.code(), Some(0));
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));

    // The pendulum released from the horizontal: A = 0 at the start, so the linearisation
    // sees nothing, but the energy (0 J) goes to 3.6e6 J: the conservation law warns.
    let out = eomgen(&[
        "simulate",
        "simple_pendulum",
        "--method",
        "rk4",
        "--dt",
        "100",
        "--t-end",
        "1000",
    ]);
    let err = stderr(&out);
    assert!(
        err.contains("warning: the energy of this conservative model drifted by"),
        "{err}"
    );
    // A model with damping is not conservative: no energy warning however it drifts.
    let out = eomgen(&["simulate", "three_masses_damped", "--t-end", "5"]);
    assert!(
        !stderr(&out).contains("energy of this conservative"),
        "{}",
        stderr(&out)
    );
}

/// A step-size underflow caused by an end time of 1e12 s (where f64 resolves t only to
/// ~3.6e-3 s) was blamed on stiffness; the hint now names the end time.
#[test]
fn an_underflow_from_a_huge_end_time_blames_the_end_time() {
    let out = eomgen(&[
        "simulate",
        "double_pendulum",
        "--t-end",
        "1e12",
        "--t-out",
        "1e12",
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("shorten --t-end"), "{err}");
    assert!(!err.contains("stiff"), "{err}");
}

/// An end time of 1e300 s, where the smallest step that moves t is 3.6e285 s: the first step
/// was raised to it, so the state overflowed and dp54 and DOP853 reported a right-hand side
/// not finite at t = 1e285, Radau IIA a Newton failure. Every method now stops at t = 0 with
/// a step too small, which the hint blames on the end time.
#[test]
fn an_end_time_of_1e300_stops_every_method_at_the_start() {
    for method in ["dp54", "dop853", "vern9", "radau5", "taylor"] {
        let out = eomgen(&[
            "simulate",
            "simple_pendulum",
            "--t-end",
            "1e300",
            "--method",
            method,
        ]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{method}: {err}");
        assert!(
            err.contains("fell below the smallest usable step at t = 0")
                && err.contains("the end time 1e300 s is so large"),
            "{method}: {err}"
        );
    }
}

/// A work–precision study with tolerances far below round-off failed every run (after
/// minutes) and exited 0: such tolerances are now a usage error (a study whose every run
/// fails exits 1: `WorkPrecision::every_run_failed`, tested in the library).
#[test]
fn tolerances_below_round_off_are_refused_by_work_precision() {
    let out = eomgen(&[
        "study",
        "work-precision",
        "simple_pendulum",
        "--methods",
        "dp54",
        "--tols",
        "1e-30..1e-31",
        "--t-end",
        "1",
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("f64 cannot deliver less"), "{err}");
}

/// `study floquet --period-parameter` must name an angular frequency: in a file that
/// declares its units, a parameter in m (the Mathieu pendulum's amplitude `a`) or in Hz is a
/// located usage error (the double pendulum's `g`, in m/s², too; that its equations do not
/// depend on t is refused by the numerical check in the library, `tests/floquet.rs`). These
/// used to report multipliers ("marginal") of a meaningless period.
#[test]
fn floquet_period_parameter_is_an_angular_frequency() {
    let out = eomgen(&[
        "study",
        "floquet",
        "mathieu_pendulum",
        "--period-parameter",
        "a",
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("mathieu_pendulum.yaml:") && err.contains("is in m, not a frequency"),
        "{err}"
    );

    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string("models/mathieu_pendulum.yaml").unwrap();
    assert!(text.contains("w: 60.0    # rad/s,"));
    let hertz = dir.path().join("mathieu_hz.yaml");
    std::fs::write(
        &hertz,
        text.replace("w: 60.0    # rad/s,", "w: 60.0    # Hz,"),
    )
    .unwrap();
    let out = eomgen(&["study", "floquet", hertz.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("is in Hz"), "{err}");

    let out = eomgen(&[
        "study",
        "floquet",
        "double_pendulum",
        "--period-parameter",
        "g",
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("`g` is in m/s^2, not a frequency"), "{err}");
}

/// Any negative number after a space reaches the option's own check (clap took `-1` and
/// `-0.1` for options: "unexpected argument '-1' found").
#[test]
fn negative_numbers_reach_the_options_checks() {
    for (args, says) in [
        (
            &["simulate", "simple_pendulum", "--t-end", "-1"][..],
            "--t-end must be a positive",
        ),
        (
            &[
                "simulate",
                "simple_pendulum",
                "--method",
                "rk4",
                "--dt",
                "-0.1",
            ],
            "`dt` is -0.1",
        ),
        (
            &["simulate", "simple_pendulum", "--atol", "-1e-9"],
            "absolute tolerance",
        ),
    ] {
        let out = eomgen(args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(says) && !err.contains("unexpected argument"),
            "{args:?}: {err}"
        );
    }
}

/// Issue 28, item 6: out-of-range options were computation failures (exit 1) or ran: each
/// is now a usage error (exit 2) found when the options are read, with the option's range.
/// `animate --dt 0` exited 1 where `simulate --dt 0` exited 2.
#[test]
fn issue_28_out_of_range_options_are_usage_errors() {
    let cases: &[(&[&str], &str)] = &[
        (
            &[
                "frf",
                "forced_oscillator",
                "--input",
                "A",
                "--freqs",
                "1e-320..10",
            ],
            // A subnormal literal is refused where numbers are read (expr::fold), before
            // the frequency range.
            "--freqs LO: `1e-320` is not an expression (column 1): the number `1e-320` is too small",
        ),
        (
            &[
                "frf",
                "forced_oscillator",
                "--input",
                "A",
                "--frequency",
                "1e155",
            ],
            "[1e-12, 1e12] rad/s or 0",
        ),
        (
            &[
                "study",
                "constraint-methods",
                "two_masses_rod",
                "--t-end",
                "1e308",
            ],
            "[1e-6, 1e6]",
        ),
        (
            &[
                "study",
                "work-precision",
                "double_pendulum",
                "--t-end",
                "1e-320",
            ],
            "[1e-6, 1e6]",
        ),
        (
            &["study", "free-response", "three_masses", "--t-end", "1e308"],
            "[1e-6, 1e6]",
        ),
        (
            &["study", "modal-damping", "three_masses", "--t-end", "1e308"],
            "[1e-6, 1e6]",
        ),
        (
            &["study", "stability", "--stiffness", "1e-320"],
            "[1e-6, 1e10]",
        ),
        (
            &[
                "study",
                "constraint-methods",
                "simple_pendulum_cartesian",
                "--stiffness",
                "1e-320",
            ],
            "[1e-6, 1e10]",
        ),
        (
            &[
                "simulate",
                "simple_pendulum",
                "--method",
                "rk4",
                "--dt",
                "0",
            ],
            "`dt` is 0",
        ),
        (
            &[
                "animate",
                "simple_pendulum",
                "-o",
                "unwritten.html",
                "--method",
                "rk4",
                "--dt",
                "0",
            ],
            "`dt` is 0",
        ),
        (
            &[
                "animate",
                "simple_pendulum",
                "-o",
                "unwritten.html",
                "--dt",
                "0",
            ],
            "`dt` is 0",
        ),
    ];
    for (args, says) in cases {
        usage_error(args, says);
    }
    assert!(!std::path::Path::new("unwritten.html").exists());
}

/// Issue 28, item 7: `-inf` and ranges such as `-1..10` were taken for options by clap
/// ("unexpected argument"); they now reach the option's own check. A huge value is quoted
/// as typed or in exponent form, never as its 309 digits.
#[test]
fn issue_28_values_starting_with_a_minus_reach_the_checks_and_numbers_print_short() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["simulate", "simple_pendulum", "--t-end", "-inf"],
            "--t-end must be a positive number of seconds, got -inf",
        ),
        (
            &[
                "frf",
                "forced_oscillator",
                "--input",
                "A",
                "--freqs",
                "-1..10",
            ],
            "--freqs LO `-1`",
        ),
        (
            &["study", "stability", "--stiffness", "-inf"],
            "a stiffness must be",
        ),
        (
            &[
                "animate",
                "simple_pendulum",
                "-o",
                "unwritten.html",
                "--t-end",
                "1e308",
            ],
            "--t-end 1e308 at --fps 30 gives more than 100000 frames",
        ),
        (
            &[
                "study",
                "work-precision",
                "simple_pendulum",
                "--target-error",
                "-1e308",
            ],
            "got -1e308",
        ),
    ];
    for (args, says) in cases {
        let err = usage_error(args, says);
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
        assert!(!err.contains("000000000000"), "{args:?}: {err}");
    }
    // An option after an option that takes a value is still an option: the value is missing.
    // So is a mistyped option: `--csv --plot-phse` wrote a file named `--plot-phse`.
    for typo in ["--plot-phse", "--plot-phse=p.svg", "--"] {
        let out = eomgen(&["simulate", "simple_pendulum", "--t-end", "1", "--csv", typo]);
        assert_eq!(out.status.code(), Some(2), "{typo}: {}", stderr(&out));
        assert!(!std::path::Path::new(typo).exists(), "{typo} was written");
    }
    let out = eomgen(&["simulate", "simple_pendulum", "--csv", "--json"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("a value is required for '--csv <FILE>'"),
        "{}",
        stderr(&out)
    );
}

/// Issue 28: `check` passed "over 0 states" (`"passed": true`) when no random state could be
/// compared — a grossly wrong hand equation of a model whose potential is outside `sqrt`'s
/// domain at every state drawn (`tests/wrong/sqrt_outside_domain.yaml`), and a constrained
/// model with a coordinate of no inertia that cannot be simulated
/// (`tests/wrong/massless_coordinate.yaml`); `report` counted both as passed. A check over no
/// state now fails, in both commands, with the number of states drawn and why each was
/// skipped, and prints no residual for it.
#[test]
fn issue_28_a_check_over_no_state_is_never_a_pass() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/wrong");
    for (file, why) in [
        (
            "sqrt_outside_domain.yaml",
            "200 had a non-finite Lagrange M or F",
        ),
        ("massless_coordinate.yaml", "200 had a singular Lagrange M"),
    ] {
        let path = format!("{dir}/{file}");
        let out = eomgen(&["check", &path]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{file}: {err}");
        assert!(
            err.contains("no state compared: of 200 random states") && err.contains(why),
            "{file}: {err}"
        );
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(!text.contains("over 0 states"), "{file}: {text}");
        let out = eomgen(&["check", &path, "--json"]);
        assert_eq!(out.status.code(), Some(1), "{file}");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["passed"], false, "{v}");
        assert_eq!(v["states"]["compared"], 0, "{v}");
        assert_eq!(v["states"]["drawn"], 200, "{v}");
        assert!(v["failure"].as_str().unwrap().contains(why), "{v}");
        assert!(v["checks"][0]["max_rel_residual"].is_null(), "{v}");
    }

    let out_dir = std::env::temp_dir().join(format!("eomgen-no-state-{}", std::process::id()));
    let models = format!("{dir}/sqrt_outside_domain.yaml,{dir}/massless_coordinate.yaml");
    let out = eomgen(&[
        "report",
        "--models",
        &models,
        "-o",
        out_dir.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    for model in ["sqrt_outside_domain", "massless_coordinate"] {
        assert!(
            err.contains(&format!(
                "{model}: derivations agree: lagrange vs momentum (max relative q̈ difference): not computed: no state compared"
            )) || err.contains(&format!(
                "{model}: derivations agree: lagrange vs by_hand (max relative q̈ difference): not computed: no state compared"
            )),
            "{model}: {err}"
        );
    }
    let _ = std::fs::remove_dir_all(&out_dir);
}

/// Issue 28: `check` drew q and q̇ in [−2, 2] only, so a model defined for x > 10 and started
/// at x = 12 (`tests/wrong/far_domain.yaml`) failed "over no state" whatever its equations.
/// States are drawn about the start: its grossly wrong hand equation is compared, at a real
/// number of states, and caught.
#[test]
fn issue_28_check_draws_about_the_start_and_catches_a_wrong_equation() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/wrong/far_domain.yaml");
    let out = eomgen(&["check", path, "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["passed"], false, "{v}");
    assert!(v["failure"].is_null(), "{v}");
    assert!(v["states"]["compared"].as_u64().unwrap() >= 50, "{v}");
    assert!(
        v["notes"]
            .to_string()
            .contains("written by hand disagree with Lagrange"),
        "{v}"
    );
}

/// Issue 28: negative Baumgarte gains were accepted (`--baumgarte -10 -10` took the pendulum's
/// constraint residual to 8.4e34 with exit 0), `nan` was a failed computation rather than a
/// usage error, and the documented `--baumgarte 10,10` was refused. Gains must be finite and
/// ≥ 0 (status 2), and `ALPHA,BETA` is the syntax.
#[test]
fn issue_28_baumgarte_gains_are_finite_and_non_negative() {
    let run = |gains: &str| {
        eomgen(&[
            "simulate",
            "simple_pendulum_cartesian",
            "--stabilization",
            "baumgarte",
            "--baumgarte",
            gains,
            "--t-end",
            "1",
        ])
    };
    for gains in [
        "-10,-10", "-10,10", "10,-1", "nan,nan", "inf,1", "10", "1,2,3",
    ] {
        let out = run(gains);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{gains}: {err}");
        assert!(err.contains("--baumgarte"), "{gains}: {err}");
    }
    for gains in ["10,10", "0,0", "2.5,40"] {
        let out = run(gains);
        assert_eq!(out.status.code(), Some(0), "{gains}: {}", stderr(&out));
    }
}

/// Issue 28: expression values that start with `-` and the letter of a short option
/// (`-height + q`, with `-h` for help; `-omega`, with `animate -o`) were taken for that
/// option. A word with one dash counts as an option only when it is exactly `-x`; the
/// expressions reach `--stop-when`, whose run then stops where the expression says.
#[test]
fn issue_28_expressions_starting_with_a_short_option_letter_reach_the_option() {
    let out = eomgen(&[
        "simulate",
        "simple_pendulum",
        "--t-end",
        "5",
        "--init",
        "q=1",
        "--stop-when",
        "-q + 0.5",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("stopped    at t = "), "{text}");
    // Names the model does not have: the option's own check reports them.
    let cases: &[(&[&str], &str)] = &[
        (
            &["simulate", "simple_pendulum", "--stop-when", "-height + q"],
            "--stop-when `-height + q`: column 2: unknown name `height`",
        ),
        (
            &[
                "animate",
                "simple_pendulum",
                "-o",
                "unwritten.html",
                "--stop-when",
                "-omega",
            ],
            "--stop-when `-omega`: column 2: unknown name `omega`",
        ),
    ];
    for (args, says) in cases {
        usage_error(args, says);
    }
    assert!(!std::path::Path::new("unwritten.html").exists());
}

/// Issue 28, after review: `study floquet --tol 0.05` left no stability tolerance in
/// `[√tol, 0.1]` and was refused naming `--stability-tolerance`, an option not given; a
/// looser `--tol` than 1e-12 refused the default stability tolerance; a Baumgarte gain of
/// 1e200 overflowed `β² Φ` into a NaN blamed on the model. Each is now a usage error naming
/// the option given, and `--tol 1e-6` runs with the stability tolerance √tol = 1e-3.
#[test]
fn issue_28_floquet_tolerance_and_baumgarte_gain_ranges() {
    let out = eomgen(&["study", "floquet", "mathieu_pendulum", "--tol", "0.05"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("'--tol <TOL>'"), "{}", stderr(&out));
    let out = eomgen(&["study", "floquet", "mathieu_pendulum", "--tol", "1e-6"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("(tolerance 0.001 on |μ| = 1)"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let out = eomgen(&[
        "simulate",
        "simple_pendulum_cartesian",
        "--stabilization",
        "baumgarte",
        "--baumgarte",
        "10,1e200",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("[0, 1e6]"), "{}", stderr(&out));
}

/// Issue 30: a kinematic file with a written `potential:` and `generalized_forces:` lost its
/// momentum-balance cross-check and `check` still said "passed" having compared nothing.
/// Now the written terms enter momentum balance, which agrees with Lagrange symbolically;
/// and a file where no second derivation applies (the energy form with no hand-derived
/// equations) is "not cross-checked", exit 1, never passed.
#[test]
fn check_never_passes_without_a_second_derivation() {
    let dir = tempfile::tempdir().unwrap();
    let kinematic = dir.path().join("spring_cart.yaml");
    std::fs::write(
        &kinematic,
        "name: spring_cart\nparameters: { m: 2.0, k: 4.0, c: 0.3 }\ncoordinates: [x]\n\
         points: { P: [x, 0] }\nbodies: { cart: { mass: m, at: P } }\n\
         potential: k*x^2/2\ngeneralized_forces: { x: -c*x_dot }\ninitial: { x: 0.1 }\n",
    )
    .unwrap();
    let out = eomgen(&["check", kinematic.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let checks = report["checks"].as_array().unwrap();
    let momentum = checks
        .iter()
        .find(|c| c["b"] == "momentum")
        .unwrap_or_else(|| panic!("{report}"));
    assert_eq!(momentum["symbolic_equal"], true, "{report}");

    let energy = dir.path().join("energy_only.yaml");
    std::fs::write(
        &energy,
        "name: energy_only\nparameters: { m: 1.0, k: 4.0 }\ncoordinates: [x]\n\
         kinetic: m*x_dot^2/2\npotential: k*x^2/2\ninitial: { x: 0.1 }\n",
    )
    .unwrap();
    let out = eomgen(&["check", energy.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("not cross-checked"), "{text}");
}

/// A start whose expression is NaN at the parameters (`sqrt(a − 1)` at a < 1) is named, not
/// reported as "the right-hand side is not finite" (the sweep's rows) or as forcing that is
/// not finite at t = 0 (`simulate`): the rows below a = 1 and the run at a = 0 say which
/// value of which start; the rows at and above a = 1 have the spring's ±2i.
#[test]
fn a_start_that_is_nan_at_the_parameters_is_named() {
    let file = format!(
        "{}/tests/fixtures/nan_start.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let out = eomgen(&[
        "study",
        "parameter-sweep",
        &file,
        "--parameter",
        "a",
        "--values",
        "0..2:5",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<&str> = text.lines().filter(|l| l.starts_with("    ")).collect();
    assert_eq!(rows.len(), 5, "{text}");
    for row in &rows[..2] {
        assert!(
            row.contains("failed") && row.contains("the start `rest` of `nan_guess` has x = NaN"),
            "{row}"
        );
    }
    for row in &rows[2..] {
        assert!(row.contains("±2.00000000i"), "{row}");
    }
    // A held rate that is NaN at the parameters (the top's precession rate, a root of a
    // negative number below w3 ≈ 8.9 rad/s) is named too.
    let out = eomgen(&["modes", "heavy_top", "--set", "w3=1"]);
    assert!(
        stderr(&out).contains("the start `precessing` of `heavy_top` has phi_dot = NaN"),
        "{}",
        stderr(&out)
    );
    let out = eomgen(&["simulate", &file, "--set", "a=0"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains(
            "the initial value of `x` is NaN: its expression in the model file's `initial:`"
        ),
        "{}",
        stderr(&out)
    );
}

/// A load that is not finite at t = 0 only (`F0 ln(w1 t)` on the two masses) was reported as
/// "the linearisation is not finite at q", with a hint to choose another configuration; it
/// is the instant, and the error says so (the equations are finite at the next time sampled).
#[test]
fn a_load_not_finite_at_the_start_only_blames_the_instant() {
    let amplitude = "  F0: 1.0    # N, step force amplitude";
    let edits = |load: &'static str| {
        common::edited_model(
            "two_masses",
            &[
                ("vector: [F0*step(t), 0]", load),
                (
                    amplitude,
                    "  F0: 1.0    # N, step force amplitude\n  w1: 1.0    # 1/s",
                ),
            ],
        )
    };
    let (_dir, path) = edits("vector: [F0*ln(t*w1), 0]");
    let out = eomgen(&["modes", &path, "--at", "x1=0,x2=1"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the equations are not finite at t = 0 s")
            && err.contains("a load is outside its domain at that instant")
            && !err.contains("choose another operating point"),
        "{err}"
    );
    // A load defined only from t = 1/w1 on, `ln(w1 t − 1)`, is the instant's too (finite at
    // a later sample, not at every one).
    let (_later, path) = edits("vector: [F0*ln(t*w1 - 1), 0]");
    let out = eomgen(&["modes", &path, "--at", "x1=0,x2=1"]);
    let err = stderr(&out);
    assert!(
        err.contains("the equations are not finite at t = 0 s")
            && err.contains("though they are at t = 1.5237 s"),
        "{err}"
    );
}

/// Ziegler's pendulum under a follower force (K not symmetric): the modes table used K's
/// symmetric part, which is indefinite from p = 2 while the system is stable up to flutter at
/// p = (7 − 2√2)/2 = 2.0858, so at p = 2.05 it said "unstable, grows as e^(0.131 t)" beside
/// a "marginally stable" verdict. The modes are now those of `M⁻¹K`, whose ω² are the roots of
/// `2ω⁴ − (7 − 2p)ω² + 1 = 0` (to 1e-9: an eigenvalue solve); at p = 2.1 (flutter) the table
/// says it is of the symmetric part only and no row is a verdict.
#[test]
fn a_follower_load_has_the_modes_of_m_inv_k() {
    let file = format!(
        "{}/tests/fixtures/ziegler_pendulum.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let p: f64 = 2.05;
    let b = 7.0 - 2.0 * p;
    let root = (b * b - 8.0).sqrt();
    let expected = [((b - root) / 4.0).sqrt(), ((b + root) / 4.0).sqrt()];
    let out = eomgen(&["modes", &file, "--set", "P=2.05", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let w: Vec<f64> = json["natural_frequencies"]
        .as_array()
        .unwrap_or_else(|| panic!("{json}"))
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    for (w, e) in w.iter().zip(expected) {
        assert!((w - e).abs() < 1e-9, "{w:?} against {expected:?}");
    }
    let out = eomgen(&["modes", &file, "--set", "P=2.05"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("unstable"), "{text}");
    let out = eomgen(&["modes", &file, "--set", "P=2.1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("flutter")
            && text.contains("ω² < 0 for K's symmetric part (no verdict")
            && text.contains("stability  unstable"),
        "{text}"
    );
}

/// A stability change where an eigenvalue passes through infinity (a spring of stiffness
/// `k/(a − 1)`: ±2/√(1 − a) real below a = 1, ±2i/√(a − 1) above) was described as "a real
/// eigenvalue crosses 0"; it is a pole, said so, at a = 1 to 1e-9.
#[test]
fn a_pole_in_a_sweep_is_not_a_crossing_of_zero() {
    use eomgen::analysis::vibration::{
        Crossing, ParameterSweepOptions, SweepAxis, parameter_sweep,
    };
    let file = format!(
        "{}/tests/fixtures/stiffness_pole.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut model = eomgen::ModelSource::open(&file).unwrap().instantiate();
    let options = ParameterSweepOptions {
        axis: SweepAxis::linear("a", 0.0, 2.0, 4).unwrap(),
        operating_point: eomgen::analysis::vibration::OperatingPointOptions::default(),
        refine: true,
    };
    let sweep = parameter_sweep(model.as_mut(), &options, |_, _| {}).unwrap();
    let changes = &sweep.stability_changes;
    assert_eq!(changes.len(), 1, "{changes:?}");
    let change = &changes[0];
    assert_eq!(change.eigenvalue, Crossing::Pole);
    assert!((change.value - 1.0).abs() < 1e-9, "{}", change.value);
    let out = eomgen(&[
        "study",
        "parameter-sweep",
        &file,
        "--parameter",
        "a",
        "--values",
        "0..2:4",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("passes through infinity") && !text.contains("crosses 0"),
        "{text}"
    );
}

/// The modes of a non-symmetric K are not M-orthogonal, and everything built on them uses
/// their left eigenvectors `Ψ⁻¹M⁻¹` (from the review): a double ω² (two uncoupled Ziegler
/// pendulums) has two independent shapes, where one null vector was taken twice; the free
/// response by modes equals the exponential's to 1e-12, where it was 62 % off with exit 0;
/// and the FRF's modal sum equals the direct solve to 1e-12 (it was 0.197 off).
#[test]
fn the_modes_of_a_follower_load_are_used_with_their_left_eigenvectors() {
    let dir = format!("{}/tests/fixtures", env!("CARGO_MANIFEST_DIR"));
    let pair = format!("{dir}/ziegler_pair.yaml");
    let out = eomgen(&["modes", &pair, "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let shapes: Vec<Vec<f64>> = serde_json::from_value(json["mode_shapes"].clone())
        .unwrap_or_else(|e| panic!("{e}: {json}"));
    let psi = nalgebra::DMatrix::from_fn(4, 4, |i, j| shapes[i][j]);
    let sigma = psi.singular_values();
    assert!(sigma.min() > 1e-3 * sigma.max(), "dependent shapes: {psi}");
    let single = format!("{dir}/ziegler_pendulum.yaml");
    let out = eomgen(&["study", "free-response", &single, "--set", "P=1", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let pairs = json["max_differences"]
        .as_array()
        .unwrap_or_else(|| panic!("{json}"));
    let normal = pairs
        .iter()
        .find(|d| d["a"] == "exponential" && d["b"] == "normal_modes")
        .unwrap_or_else(|| panic!("{json}"));
    let dq = normal["displacement_relative"]
        .as_f64()
        .unwrap_or_else(|| panic!("{normal}"));
    assert!(dq < 1e-12, "{normal}");
    let out = eomgen(&[
        "frf",
        &single,
        "--input",
        "a",
        "--modal",
        "--frequency",
        "0.3",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text
        .lines()
        .find(|l| l.contains("modal sum vs direct solve"))
        .unwrap_or_else(|| panic!("{text}"));
    let difference: f64 = line
        .split("max difference ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    assert!(difference < 1e-12, "{line}");
}
