//! Events in model files and on the command line (issue 6, item 2): the pendulum period
//! (exact elliptic integral), HW21's damped period and logarithmic decrement from successive
//! peaks, HW36's lift-off where the normal force reaches zero, and `--stop-when`/`--event`.

use crate::common;
use common::{eomgen, eomgen_ok};

use eomgen::analysis::{SimulationOptions, simulate_with_events};
use eomgen::expressions::{ExpressionError, ExpressionEvents};
use eomgen::{
    DormandPrince853, EventDirection, Integrator, IntegratorOptions, ModelInfo, OutputTimes,
    RadauIIA5, Solution,
};

fn model(name: &str) -> Box<dyn ModelInfo> {
    (eomgen::models::find(name).expect("bundled model").make)()
}

fn run(model: &mut dyn ModelInfo, method: &mut dyn Integrator, t_end: f64, tol: f64) -> Solution {
    let y0 = model.consistent_initial_state().expect("consistent");
    let options = IntegratorOptions::default().with_rtol(tol).with_atol(tol);
    method
        .integrate(
            model.as_ode_mut(),
            0.0,
            &y0,
            t_end,
            &OutputTimes::Steps,
            &options,
        )
        .unwrap_or_else(|f| panic!("{f}"))
}

/// `K(k)` by the arithmetic–geometric mean (Abramowitz & Stegun 17.6).
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0_f64, (1.0 - k * k).sqrt());
    for _ in 0..40 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    std::f64::consts::PI / (a + b)
}

/// `simple_pendulum`'s `return` event (q̇ reaches zero from above) once a period: amplitude
/// π/2 about the hanging position, so T = 4 √(l/g) K(sin(π/4)) = 2.3452 s. The issue asks for
/// 1e-10; DOP853 at tol 1e-13 gives ~1e-13 (the located zero is as accurate as the order-7
/// dense output).
#[test]
fn pendulum_period_from_the_model_event() {
    let mut pendulum = model("simple_pendulum");
    let exact = 4.0 * (1.0_f64 / 10.0).sqrt() * elliptic_k((std::f64::consts::FRAC_PI_4).sin());
    let solution = run(
        pendulum.as_mut(),
        &mut DormandPrince853::new(),
        3.5 * exact,
        1e-13,
    );
    let returns: Vec<f64> = solution.events.iter().map(|e| e.t).collect();
    assert_eq!(returns.len(), 3);
    assert!(solution.events.iter().all(|e| e.name == "return"));
    for (k, t) in returns.iter().enumerate() {
        let expected = (k + 1) as f64 * exact;
        assert!(
            ((t - expected) / expected).abs() < 1e-10,
            "{t} vs {expected}"
        );
    }
}

/// HW21: free decay of `forced_oscillator` (A = B = 0, x(0) = 1, c = 0.1 so ζ = 0.05): the
/// `peak` events are a damped period 2π/ω_d apart, and ln(x_k / x_{k+1}) = 2πζ/√(1 − ζ²)
/// exactly for the linear oscillator. Tolerance 1e-9: DOP853 at 1e-12 over ten periods.
#[test]
fn damped_period_and_log_decrement_from_peaks() {
    let mut oscillator = model("forced_oscillator");
    for (name, value) in [("A", 0.0), ("B", 0.0), ("c", 0.1)] {
        oscillator.set_parameter(name, value).unwrap();
    }
    let y0 = [1.0, 0.0];
    let options = IntegratorOptions::default()
        .with_rtol(1e-12)
        .with_atol(1e-12);
    let solution = DormandPrince853::new()
        .integrate(
            oscillator.as_ode_mut(),
            0.0,
            &y0,
            70.0,
            &OutputTimes::Steps,
            &options,
        )
        .unwrap();
    let zeta: f64 = 0.1 / 2.0;
    let omega_d = (1.0 - zeta * zeta).sqrt();
    let peaks: Vec<(f64, f64)> = solution.events.iter().map(|e| (e.t, e.y[0])).collect();
    assert_eq!(peaks.len(), 11, "peaks every 2π/ω_d ≈ 6.29 s up to 70 s");
    for w in peaks.windows(2) {
        let period = w[1].0 - w[0].0;
        let decrement = (w[0].1 / w[1].1).ln();
        let exact_period = 2.0 * std::f64::consts::PI / omega_d;
        let exact_decrement = 2.0 * std::f64::consts::PI * zeta / omega_d;
        assert!(
            (period - exact_period).abs() < 1e-9,
            "{period} vs {exact_period}"
        );
        assert!(
            (decrement - exact_decrement).abs() < 1e-9,
            "{decrement} vs {exact_decrement}"
        );
    }
    assert!(
        solution
            .events
            .iter()
            .all(|e| e.direction == EventDirection::Falling)
    );
}

/// HW36 (c): the eccentric cylinder's `lift_off` event (λ_contact, the normal force, reaches
/// zero from above) ends the run. Checked independently of λ by the normal momentum balance
/// N = M (g cos γ + ÿ_G), y_G = y + e sin θ with y = R: at the event
/// g cos γ + e (cos θ θ̈ − sin θ θ̇²) = 0 to 1e-7 of g (λ is solved with the same KKT matrix
/// as q̈; the event is located to ~1e-12 in t by DOP853 at 1e-12). Radau IIA finds the same
/// time to 1e-8.
#[test]
fn eccentric_cylinder_lifts_off_where_the_normal_force_vanishes() {
    let mut cylinder = model("eccentric_cylinder");
    let solution = run(cylinder.as_mut(), &mut DormandPrince853::new(), 10.0, 1e-12);
    let k = solution.terminated_by_event.expect("lift-off within 10 s");
    let event = &solution.events[k];
    assert_eq!(event.name, "lift_off");
    assert_eq!(solution.last().map(|(t, _)| t), Some(event.t));
    let names: Vec<String> = cylinder
        .description()
        .parameter_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let values = cylinder.parameter_values();
    let p = |n: &str| values[names.iter().position(|x| *x == n).unwrap()];
    let mut dy = vec![0.0; 6];
    cylinder.rhs(event.t, &event.y, &mut dy).unwrap();
    let (theta, theta_dot, theta_ddot) = (event.y[2], event.y[5], dy[5]);
    let normal = p("M")
        * (p("g") * p("gamma").cos()
            + p("e") * (theta.cos() * theta_ddot - theta.sin() * theta_dot.powi(2)));
    assert!(normal.abs() < 1e-7 * p("M") * p("g"), "N = {normal}");
    let lambda = cylinder.constraint_forces(event.t, &event.y).unwrap();
    assert!(lambda[0].abs() < 1e-9, "λ_contact = {}", lambda[0]);
    let mut again = model("eccentric_cylinder");
    let radau = run(again.as_mut(), &mut RadauIIA5::new(), 10.0, 1e-10);
    let t_radau = radau.events[radau.terminated_by_event.unwrap()].t;
    assert!((t_radau - event.t).abs() < 1e-8, "{t_radau} vs {}", event.t);
}

/// Event functions written as expressions (`--stop-when`, `--event`), through the library
/// the CLI calls: an expression with a direction, a model event made terminal by name, and
/// functions of the accelerations and constraint forces.
#[test]
fn stop_when_and_event_expressions() {
    // The double pendulum's forearm passes straight down (θ2 = 0) while turning clockwise.
    let mut m = model("double_pendulum");
    let mut events =
        ExpressionEvents::parse(m.as_mut(), &["theta2 = 0, falling"], &["theta1_dot"]).unwrap();
    let run =
        simulate_with_events(m.as_mut(), &SimulationOptions::default(), Some(&mut events)).unwrap();
    let s = &run.solution;
    let last = &s.events[s.terminated_by_event.expect("stopped")];
    assert_eq!(last.name, "stop_when_1");
    assert_eq!(last.direction, EventDirection::Falling);
    assert!(last.y[1].abs() < 1e-12, "theta2 = {}", last.y[1]);
    assert!(last.y[3] < 0.0);
    assert_eq!(s.t.last(), Some(&last.t));
    assert!(
        s.events
            .iter()
            .all(|e| ["stop_when_1", "event_2"].contains(&e.name.as_str()))
    );
    // A model event made terminal by name: nothing is added. The return of the pendulum
    // released from the horizontal comes after a whole period, 4 K(1/√2) √(l/g).
    let mut m = model("simple_pendulum");
    let mut events = ExpressionEvents::parse(m.as_mut(), &["return"], &[] as &[&str]).unwrap();
    assert!(events.is_empty());
    let run =
        simulate_with_events(m.as_mut(), &SimulationOptions::default(), Some(&mut events)).unwrap();
    let stop = &run.solution.events[run.solution.terminated_by_event.expect("stopped")];
    assert_eq!(stop.name, "return");
    let period = 4.0 * elliptic_k(1.0 / 2f64.sqrt()) * (1.0f64 / 10.0).sqrt();
    assert!((stop.t - period).abs() < 1e-7, "{} vs {period}", stop.t);
    // Accelerations and constraint forces are allowed in the functions too.
    let mut m = model("eccentric_cylinder");
    let mut events =
        ExpressionEvents::parse(m.as_mut(), &["lambda_contact - 5, falling"], &[] as &[&str])
            .unwrap();
    let run =
        simulate_with_events(m.as_mut(), &SimulationOptions::default(), Some(&mut events)).unwrap();
    assert_eq!(
        run.solution
            .terminated_by_event
            .map(|k| run.solution.events[k].name.as_str()),
        Some("stop_when_1")
    );
    let last = run
        .constraints
        .lagrange_multipliers
        .last()
        .unwrap()
        .as_ref()
        .unwrap();
    assert!((last[0] - 5.0).abs() < 1e-6, "lambda = {}", last[0]);
}

/// The CLI renders the events: the JSON names the terminal one, the text says where the run
/// stopped.
#[test]
fn stop_when_on_the_command_line() {
    let out = eomgen_ok(&[
        "simulate",
        "double_pendulum",
        "--stop-when",
        "theta2 = 0, falling",
        "--event",
        "theta1_dot",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["terminated_by_event"], "stop_when_1");
    let last = v["events"].as_array().unwrap().last().unwrap().clone();
    assert_eq!(last["name"], "stop_when_1");
    assert_eq!(last["direction"], "falling");
    assert_eq!(
        v["samples"].as_array().unwrap().last().unwrap()["t"],
        last["t"]
    );
    let out = eomgen(&["simulate", "simple_pendulum", "--stop-when", "return"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(text.contains("stopped    at t = 2.3452395"), "{text}");
}

/// Mistakes in event functions are typed errors naming the column and what would be right.
#[test]
fn bad_event_expressions_are_typed_errors() {
    let mut m = model("double_pendulum");
    let error =
        ExpressionEvents::parse(m.as_mut(), &["x + theta2_dott"], &[] as &[&str]).unwrap_err();
    match error {
        ExpressionError::EventUnknownName { column, name, .. } => {
            assert_eq!((column, name.as_str()), (1, "x"));
        }
        other => panic!("{other:?}"),
    }
    let error =
        ExpressionEvents::parse(m.as_mut(), &["theta2", "theta2, up"], &[] as &[&str]).unwrap_err();
    assert!(matches!(error, ExpressionError::EventDirection { ref word, .. } if word == "up"));
}

#[test]
fn bad_event_arguments_are_usage_errors() {
    for (arg, expected) in [
        (
            "theta2_dott",
            "unknown name `theta2_dott` for model `double_pendulum`; did you mean `theta2_dot`?",
        ),
        (
            "theta2, up",
            "the direction after the comma must be rising, falling or both, found `up`",
        ),
        ("theta2 = (1", "column"),
        ("lambda_rod", "unknown name `lambda_rod`"),
    ] {
        let out = eomgen(&["simulate", "double_pendulum", "--stop-when", arg]);
        assert_eq!(out.status.code(), Some(2), "{arg}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(expected), "{arg}: {stderr}");
    }
}
