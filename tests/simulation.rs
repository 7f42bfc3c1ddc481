//! `eomgen::analysis::simulate`, the library call behind `eomgen simulate`: its options, its
//! typed errors, a failure with the samples before it, and the drift measures of its report.

use eomgen::analysis::{Method, SimulationError, SimulationOptions, simulate};
use eomgen::{IntegrationError, ModelInfo, OutputTimes, Stabilization};

fn model(name: &str) -> Box<dyn ModelInfo> {
    (eomgen::models::find(name).expect("bundled model").make)()
}

/// The small-angle pendulum sampled at given times follows `q = q0 cos(√(g/l) t)` up to the
/// O(q0³) amplitude correction: with q0 = 1e-3 the difference is below 1e-9 (relative
/// 1e-6) besides the integration error at rtol 1e-10.
#[test]
fn sampled_times_follow_the_small_angle_solution() {
    let mut m = model("simple_pendulum");
    let hanging = -std::f64::consts::FRAC_PI_2;
    let q0 = 1e-3;
    let times = vec![0.5, 1.0, 2.5];
    let options = SimulationOptions {
        t_end: 3.0,
        rtol: 1e-10,
        atol: 1e-12,
        output: OutputTimes::At(times.clone()),
        initial_state: Some(vec![hanging + q0, 0.0]),
        ..SimulationOptions::default()
    };
    let run = simulate(m.as_mut(), &options).unwrap();
    assert_eq!(run.method, Method::Dp54);
    assert_eq!(run.integrator, "dp54");
    assert_eq!(run.solution.t, times);
    let omega = 10f64.sqrt();
    for (t, y) in run.solution.iter() {
        let exact = q0 * (omega * t).cos();
        assert!(
            (y[0] - hanging - exact).abs() < 1e-9,
            "t = {t}: {}",
            y[0] - hanging
        );
    }
    assert_eq!(run.energy.energy.len(), 3);
    assert!(run.constraints.is_empty());
}

/// Bad options are typed errors before any step.
#[test]
fn invalid_options_are_typed_errors() {
    let mut m = model("double_pendulum");
    let options = SimulationOptions {
        t_end: -1.0,
        ..SimulationOptions::default()
    };
    assert_eq!(
        simulate(m.as_mut(), &options).unwrap_err(),
        SimulationError::InvalidEndTime { t_end: -1.0 }
    );
    let options = SimulationOptions {
        initial_state: Some(vec![0.0; 3]),
        ..SimulationOptions::default()
    };
    assert_eq!(
        simulate(m.as_mut(), &options).unwrap_err(),
        SimulationError::DimensionMismatch {
            expected: 4,
            found: 3
        }
    );
    // The cartesian pendulum off its circle, with no coordinate marked as a guess.
    let mut m = model("simple_pendulum_cartesian");
    let mut y0 = m.initial_state();
    y0[0] = 5.0;
    let options = SimulationOptions {
        initial_state: Some(y0),
        ..SimulationOptions::default()
    };
    match simulate(m.as_mut(), &options).unwrap_err() {
        SimulationError::InconsistentInitialState {
            constraint,
            residual,
            ..
        } => {
            assert_eq!(constraint, "rod");
            assert!(residual > 1.0);
        }
        other => panic!("{other:?}"),
    }
}

/// Explicit Euler with a step far beyond its stability limit blows up: the report keeps the
/// failure (with its time) and the samples before it; the JSON gives `{t, message}`.
#[test]
fn a_failed_integration_keeps_the_samples_before_it() {
    let mut m = model("double_pendulum");
    let options = SimulationOptions {
        method: Method::Euler,
        dt: Some(1.0),
        t_end: 100.0,
        ..SimulationOptions::default()
    };
    let run = simulate(m.as_mut(), &options).unwrap();
    let failure = run.failure.as_ref().expect("blows up");
    assert!(matches!(
        failure,
        IntegrationError::RhsNonFinite { .. } | IntegrationError::NonFiniteState { .. }
    ));
    let t = failure.t().unwrap();
    assert!(!run.solution.is_empty());
    assert!(run.solution.t.iter().all(|&s| s <= t));
    let json = serde_json::to_value(&run).unwrap();
    assert_eq!(json["failure"]["t"], t);
    assert_eq!(json["method"], "euler");
}

/// Projection keeps the cartesian pendulum on its circle to the projection's tolerance,
/// while the unstabilised run drifts (both at rtol 1e-6 over 10 s).
#[test]
fn projection_removes_the_constraint_drift() {
    let drift = |stabilization| {
        let mut m = model("simple_pendulum_cartesian");
        let options = SimulationOptions {
            rtol: 1e-6,
            atol: 1e-8,
            stabilization,
            ..SimulationOptions::default()
        };
        simulate(m.as_mut(), &options)
            .unwrap()
            .constraints
            .max_drift()
            .0
    };
    let free = drift(Stabilization::None);
    let projected = drift(Stabilization::Projection);
    assert!(projected < 1e-9, "projected drift {projected}");
    assert!(
        free > 100.0 * projected,
        "free {free}, projected {projected}"
    );
}

/// Issue 28: quadratic drag `|v| v` started from rest stopped RADAU5 and implicit midpoint
/// with "the right-hand side is not finite": the exact Jacobian has `vₓ²/|v|`, 0/0 at rest,
/// where `F` and its derivative are 0. Both methods now difference `F` there, and follow
/// the closed form `ẏ(t) = −v_t tanh(g t / v_t)`, `v_t = √(m g / c)`, to 1e-5 (RADAU5 at
/// rtol 1e-8) and 1e-4 (implicit midpoint, dt = 1e-3: its error is O(dt²) ≈ 1e-6 here).
#[test]
fn issue_28_quadratic_drag_from_rest_runs_on_the_implicit_methods() {
    let source = eomgen::ModelSource::open(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/quadratic_drag.yaml"
    ))
    .expect("loads");
    let (m, c, g) = (1.0_f64, 0.5_f64, 9.81_f64);
    let terminal = (m * g / c).sqrt();
    for (method, tolerance) in [(Method::Radau5, 1e-5), (Method::ImplicitMidpoint, 1e-4)] {
        let mut model = source.instantiate();
        let options = SimulationOptions {
            method,
            t_end: 2.0,
            output: OutputTimes::At(vec![0.5, 1.0, 2.0]),
            initial_state: Some(vec![0.0, 0.0, 0.0, 0.0]),
            ..SimulationOptions::default()
        };
        let run = simulate(model.as_mut(), &options).unwrap_or_else(|e| panic!("{method:?}: {e}"));
        for (t, y) in run.solution.iter() {
            let exact = -terminal * (g * t / terminal).tanh();
            assert!(
                (y[3] - exact).abs() < tolerance && y[0].abs() < 1e-12 && y[2].abs() < 1e-12,
                "{method:?} at t = {t}: y_dot = {} (exact {exact}), x = {}",
                y[3],
                y[0]
            );
        }
    }
}

/// `eomgen::batch::simulate_batch` over six initial states of the double pendulum, on one
/// thread, two, and rayon's pool: every run's samples and energies are those of `simulate`
/// called on its own, to the bit (each run has an instance of its own), and the work of
/// each run is reported.
#[test]
fn a_batch_is_the_serial_loop_to_the_bit() {
    use eomgen::batch::{BatchOptions, BatchRuns, simulate_batch};
    let source = eomgen::ModelSource::open("double_pendulum").unwrap();
    let make = || source.instantiate_send();
    let y0 = make().initial_state();
    let states: Vec<Vec<f64>> = (0..6)
        .map(|i| {
            let mut y = y0.clone();
            y[0] += 0.05 * i as f64;
            y
        })
        .collect();
    let simulation = SimulationOptions {
        t_end: 2.0,
        rtol: 1e-10,
        atol: 1e-10,
        output: OutputTimes::At(vec![0.5, 1.0, 2.0]),
        ..SimulationOptions::default()
    };
    let runs = BatchRuns {
        initial_states: Some(states.clone()),
        parameters: None,
    };
    for threads in [Some(1), Some(2), None] {
        let options = BatchOptions {
            simulation: simulation.clone(),
            threads,
            keep_failures: false,
        };
        let report = simulate_batch(&make, &runs, &options, &mut || true).unwrap();
        assert_eq!(report.state_dimension, 4);
        assert!(report.ok.iter().all(|&ok| ok) && report.failures.is_empty());
        assert_eq!(report.t_final, vec![2.0; 6]);
        for (i, y0) in states.iter().enumerate() {
            let one = SimulationOptions {
                initial_state: Some(y0.clone()),
                ..simulation.clone()
            };
            let alone = simulate(make().as_mut(), &one).unwrap();
            assert_eq!(
                report.y[i * 12..(i + 1) * 12],
                alone.solution.y[..],
                "run {i}"
            );
            assert_eq!(report.energy[i * 3..(i + 1) * 3], alone.energy.energy[..]);
            assert_eq!(report.steps[i], alone.solution.stats.steps as u64);
        }
    }
}

/// A batch over parameters: a run whose integration fails (RK4 with a step of 0.5 s on the
/// triple pendulum) is a failure with NaN samples past its end; a run that cannot start (a
/// state off the Cartesian pendulum's circle) is kept as a failure at `t` NaN or stops the
/// batch with the run's index; an unknown parameter, options no run could use, and a caller
/// that stops the batch are typed errors.
#[test]
fn a_batch_keeps_or_reports_failures_and_refuses_what_no_run_could_use() {
    use eomgen::batch::{BatchError, BatchOptions, BatchRuns, simulate_batch};
    let source = eomgen::ModelSource::open("triple_pendulum").unwrap();
    let make = || source.instantiate_send();
    let runs = BatchRuns {
        initial_states: None,
        parameters: Some(vec![
            vec![("g".to_string(), 9.81)],
            vec![("g".to_string(), 1.62)],
        ]),
    };
    let options = BatchOptions {
        simulation: SimulationOptions {
            method: Method::Rk4,
            dt: Some(0.5),
            t_end: 10.0,
            output: OutputTimes::At(vec![1.0, 10.0]),
            ..SimulationOptions::default()
        },
        threads: Some(2),
        keep_failures: true,
    };
    let report = simulate_batch(&make, &runs, &options, &mut || true).unwrap();
    assert_eq!(report.ok, vec![false, false]);
    assert_eq!(report.failures.len(), 2);
    assert!(
        report
            .failures
            .iter()
            .all(|f| f.t.is_finite() && f.t < 10.0)
    );
    assert!(report.y[report.y.len() - 6..].iter().all(|v| v.is_nan()));
    assert!(
        report
            .failures
            .iter()
            .all(|f| f.not_started_with_guesses.is_none())
    );
    let cartesian = eomgen::ModelSource::open("simple_pendulum_cartesian").unwrap();
    let make_cartesian = || cartesian.instantiate_send();
    let y0 = make_cartesian().initial_state();
    let off_the_circle = BatchRuns {
        initial_states: Some(vec![y0.clone(), vec![5.0, 5.0, 0.0, 0.0], y0]),
        parameters: None,
    };
    let mut cartesian_options = BatchOptions {
        simulation: SimulationOptions {
            t_end: 1.0,
            output: OutputTimes::At(vec![1.0]),
            ..SimulationOptions::default()
        },
        threads: Some(2),
        keep_failures: true,
    };
    let report = simulate_batch(
        &make_cartesian,
        &off_the_circle,
        &cartesian_options,
        &mut || true,
    )
    .unwrap();
    assert_eq!(report.ok, vec![true, false, true]);
    assert_eq!(report.failures.len(), 1);
    assert!(report.failures[0].run == 1 && report.failures[0].t.is_nan());
    assert!(report.failures[0].not_started_with_guesses.is_some());
    assert!(report.y[4..8].iter().all(|v| v.is_nan()));
    cartesian_options.keep_failures = false;
    let error = simulate_batch(
        &make_cartesian,
        &off_the_circle,
        &cartesian_options,
        &mut || true,
    )
    .unwrap_err();
    assert!(matches!(error, BatchError::Run { run: 1, .. }), "{error}");
    assert!(error.to_string().starts_with("run 1: "), "{error}");
    let unknown = BatchRuns {
        initial_states: None,
        parameters: Some(vec![vec![("nope".to_string(), 1.0)]]),
    };
    let error = simulate_batch(&make, &unknown, &options, &mut || true).unwrap_err();
    assert!(
        matches!(error, BatchError::Parameter { run: 0, .. }),
        "{error}"
    );
    assert!(matches!(
        simulate_batch(&make, &runs, &options, &mut || false),
        Err(BatchError::Stopped)
    ));
    let refused = |runs: &BatchRuns, options: &BatchOptions, says: &str| match simulate_batch(
        &make,
        runs,
        options,
        &mut || true,
    ) {
        Err(BatchError::Refused(m)) => assert!(m.contains(says), "{m}"),
        other => panic!("refused ({says}) expected, got {:?}", other.map(|r| r.ok)),
    };
    let mut bad = options.clone();
    bad.threads = Some(0);
    refused(&runs, &bad, "threads must be 1 to 256");
    bad = options.clone();
    bad.simulation.output = OutputTimes::Steps;
    refused(&runs, &bad, "same output times");
    bad.simulation.output = OutputTimes::At(Vec::new());
    refused(&runs, &bad, "at least one output time");
    let wrong_size = BatchRuns {
        initial_states: Some(vec![vec![0.0; 5]]),
        parameters: None,
    };
    refused(&wrong_size, &options, "must have 6 columns");
    refused(&BatchRuns::default(), &options, "give initial_states");
    let unequal = BatchRuns {
        initial_states: Some(vec![make().initial_state()]),
        parameters: runs.parameters.clone(),
    };
    refused(&unequal, &options, "give one per run");
}
