//! The Taylor method (`eomgen_runtime::Taylor`): its step rule against heyoka's, accuracy
//! against closed forms over long runs, its dense output and events, the order of its
//! fixed-step form, constrained models (`[M Jᵀ; J 0][q̈; λ] = [F; γ]` as series), and its
//! refusals (a closure, a piecewise function, Baumgarte's stabilisation, a constrained model
//! compiled by `model!`).
//!
//! The coefficients themselves are checked against an independent high-precision computation
//! in `tests/taylor_coefficients.rs`.

use eomgen::{
    DormandPrince853, DynFirstOrder, IntegrationError, Integrator, IntegratorOptions, JitModel,
    OdeFn, OdeSystem, OutputTimes, Taylor,
};

/// A model file compiled at run time, as the first-order form the integrators take.
fn model(source: &str) -> DynFirstOrder<JitModel> {
    let model = JitModel::from_source("test.yaml", source).expect("the model loads");
    DynFirstOrder::new(model)
}

/// `ẍ = −9.8 sin x`: heyoka's pendulum example.
const PENDULUM: &str = "
name: pendulum
description: x'' = -9.8 sin x.
parameters: { g: 9.8 }
coordinates: [x]
kinetic: x_dot^2/2
potential: -g*cos(x)
initial: { x: 0.05, x_dot: 0.025 }
events:
  turn: { when: x_dot, direction: falling }
";

/// `ẍ = −x`: `x = cos t` from `(1, 0)`.
const OSCILLATOR: &str = "
name: oscillator
description: x'' = -x.
parameters: { k: 1 }
coordinates: [x]
kinetic: x_dot^2/2
potential: k*x^2/2
initial: { x: 1, x_dot: 0 }
";

fn tolerance(tol: f64) -> IntegratorOptions {
    IntegratorOptions::default().with_rtol(tol).with_atol(tol)
}

/// The order rule is heyoka's `taylor_order_from_tol`: ⌈−½ ln ε + 1⌉ (its table: 8, 12, 15,
/// 20 at 1e-6, 1e-9, 1e-12 and machine epsilon).
#[test]
fn the_order_follows_the_tolerance_as_in_heyoka() {
    for (tol, order) in [(1e-6, 8), (1e-9, 12), (1e-12, 15), (f64::EPSILON, 20)] {
        assert_eq!(Taylor::order_for_tolerance(tol), order, "tol {tol:e}");
    }
    assert_eq!(Taylor::order_for_tolerance(0.9), 2);
}

/// heyoka's first step on its pendulum example (x₀ = (0.05, 0.025), tol 1e-9) is
/// h = 0.2024724481278614 (integrators-and-python reference, §1.5, re-run there): ours, from
/// the same rule on our coefficients, agrees to a few ulps (the ∞-norms and powers may round
/// differently).
#[test]
fn the_first_step_is_heyokas() {
    let mut system = model(PENDULUM);
    let solution = Taylor::new()
        .integrate(
            &mut system,
            0.0,
            &[0.05, 0.025],
            1.0,
            &OutputTimes::Steps,
            &tolerance(1e-9),
        )
        .unwrap();
    let h = solution.t[1] - solution.t[0];
    assert!((h / 0.2024724481278614 - 1.0).abs() < 1e-14, "h = {h:?}");
}

/// Over 1,000 periods of `ẍ = −x` the state stays on `(cos t, −sin t)`: the error grows
/// like the number of steps times the local error, far below 1e-8 at tol 1e-14, and the
/// energy error stays at rounding level.
#[test]
fn a_thousand_periods_of_the_oscillator_stay_on_the_circle() {
    let mut system = model(OSCILLATOR);
    let t_end = 2000.0 * std::f64::consts::PI;
    let solution = Taylor::new()
        .integrate(
            &mut system,
            0.0,
            &[1.0, 0.0],
            t_end,
            &OutputTimes::Steps,
            &tolerance(1e-14),
        )
        .unwrap();
    let mut worst = 0.0f64;
    for (t, y) in solution.iter() {
        worst = worst
            .max((y[0] - t.cos()).abs())
            .max((y[1] + t.sin()).abs());
    }
    assert!(worst < 1e-8, "worst error {worst:e}");
    let y = solution.state(solution.len() - 1);
    let energy = (y[0] * y[0] + y[1] * y[1]) / 2.0;
    assert!((energy - 0.5).abs() < 1e-11, "energy {energy}");
}

/// The dense output is the step's series: between steps it is as accurate as at the steps
/// (here against `cos t` at 1,000 times that fall inside steps), and a requested time that
/// is a step's end gives that step's end.
#[test]
fn dense_output_is_as_accurate_as_the_steps() {
    let times: Vec<f64> = (1..=1000).map(|i| i as f64 * 0.0123).collect();
    let t_end = 12.3;
    for tol in [1e-6, 1e-10, 1e-14] {
        let mut system = model(OSCILLATOR);
        let dense = Taylor::new()
            .integrate(
                &mut system,
                0.0,
                &[1.0, 0.0],
                t_end,
                &OutputTimes::At(times.clone()),
                &tolerance(tol),
            )
            .unwrap();
        let mut system = model(OSCILLATOR);
        let steps = Taylor::new()
            .integrate(
                &mut system,
                0.0,
                &[1.0, 0.0],
                t_end,
                &OutputTimes::Steps,
                &tolerance(tol),
            )
            .unwrap();
        let error = |(t, y): (f64, &[f64])| (y[0] - t.cos()).abs().max((y[1] + t.sin()).abs());
        let dense_error = dense.iter().map(error).fold(0.0, f64::max);
        let step_error = steps.iter().map(error).fold(0.0, f64::max);
        // Within a factor 10 of the error at the steps, and of the tolerance's order.
        assert!(
            dense_error <= 10.0 * step_error.max(tol),
            "tol {tol:e}: dense {dense_error:e}, steps {step_error:e}"
        );
        assert!(dense_error < 100.0 * tol, "tol {tol:e}: {dense_error:e}");
        assert_eq!(dense.state(dense.len() - 1), steps.state(steps.len() - 1));
    }
}

/// Events are located on the series: the pendulum's turning points (`ẋ` falling through 0)
/// come every period `T = 4 K(sin²(a/2)) / √g` of the amplitude `a`; the time between the
/// first and the eleventh matches ten periods to 1e-11 s. The amplitude comes from the
/// energy, `1 − cos a = (ẋ₀²/2 + g (1 − cos x₀)) / g`, and K by the arithmetic–geometric mean.
#[test]
fn events_are_located_to_the_accuracy_of_the_series() {
    let mut system = model(PENDULUM);
    let (x0, v0, g) = (0.05f64, 0.025f64, 9.8f64);
    let solution = Taylor::new()
        .integrate(
            &mut system,
            0.0,
            &[x0, v0],
            25.0,
            &OutputTimes::Steps,
            &tolerance(1e-13),
        )
        .unwrap();
    let turns: Vec<f64> = solution
        .events
        .iter()
        .filter(|e| e.index == 0)
        .map(|e| e.t)
        .collect();
    assert!(turns.len() >= 11, "{} turns", turns.len());
    let cos_a = 1.0 - (v0 * v0 / 2.0 + g * (1.0 - x0.cos())) / g;
    let k2 = (1.0 - cos_a) / 2.0; // sin²(a/2)
    // K(m) = π / (2 AGM(1, √(1 − m))).
    let (mut a, mut b) = (1.0f64, (1.0 - k2).sqrt());
    for _ in 0..10 {
        (a, b) = ((a + b) / 2.0, (a * b).sqrt());
    }
    let period = 4.0 * (std::f64::consts::PI / (2.0 * a)) / g.sqrt();
    let measured = (turns[10] - turns[0]) / 10.0;
    assert!(
        (measured - period).abs() < 1e-12,
        "period {measured} against {period}"
    );
}

/// With fixed steps the method is of the order its tolerance gives: halving the step of an
/// order-8 series (tol 1e-6) divides the error at t = 3 by about 2⁸.
#[test]
fn fixed_steps_converge_at_the_order_of_the_series() {
    let error = |dt: f64| {
        let mut system = model(OSCILLATOR);
        let options = tolerance(1e-6).with_fixed_step(true).with_dt(dt);
        let solution = Taylor::new()
            .integrate(
                &mut system,
                0.0,
                &[1.0, 0.0],
                3.0,
                &OutputTimes::Steps,
                &options,
            )
            .unwrap();
        let y = solution.state(solution.len() - 1);
        (y[0] - 3.0f64.cos()).abs().max((y[1] + 3.0f64.sin()).abs())
    };
    let (coarse, fine) = (error(0.6), error(0.3));
    let observed = (coarse / fine).log2();
    assert!((observed - 8.0).abs() < 0.6, "observed order {observed}");
}

/// Looser tolerances give larger errors, tighter ones smaller, roughly in proportion: the
/// error at t = 20 of the pendulum stays within two decades of the tolerance, falling
/// with it at every step.
#[test]
fn the_error_follows_the_tolerance() {
    let mut reference = model(PENDULUM);
    let exact = Taylor::new()
        .integrate(
            &mut reference,
            0.0,
            &[0.05, 0.025],
            20.0,
            &OutputTimes::At(vec![20.0]),
            &tolerance(1e-16),
        )
        .unwrap();
    let exact = exact.state(0).to_vec();
    let mut previous = f64::INFINITY;
    for tol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
        let mut system = model(PENDULUM);
        let solution = Taylor::new()
            .integrate(
                &mut system,
                0.0,
                &[0.05, 0.025],
                20.0,
                &OutputTimes::At(vec![20.0]),
                &tolerance(tol),
            )
            .unwrap();
        let y = solution.state(0);
        let error = (y[0] - exact[0]).abs().max((y[1] - exact[1]).abs());
        assert!(error < 100.0 * tol, "tol {tol:e}: error {error:e}");
        assert!(
            error < previous,
            "tol {tol:e}: {error:e} after {previous:e}"
        );
        previous = error;
    }
}

/// A pendulum released at rest from the horizontal, `ẍ = −9.8 cos x` from `x = 0` (exactly)
/// and `ẍ = −9.8 sin x` from `x = π/2` (where `cos x` is 6e-17, not 0): the force is even
/// about the release point, so the coefficients of `x` vanish but at orders 2, 6, 10, … and
/// those of `ẋ` but at 1, 5, 9, … (exactly, or to rounding). At orders 8 and 12 (tol 1e-6,
/// 1e-9) the last two orders of the series are then both zero, which Jorba & Zou's rule on
/// those two alone reads as an infinite radius of convergence: one step to the end with a
/// wrong polynomial (from π/2: one step, error 47 at t = 1.2 s, before the rule looked at
/// four orders). Against
/// the same model at tol 1e-15, the error must be within 100 × tol, as everywhere else.
#[test]
fn a_series_with_vanishing_last_orders_is_not_taken_to_end() {
    let from_horizontal = |potential: &str| {
        format!(
            "
name: released
description: released at rest from the horizontal.
parameters: {{ g: 9.8 }}
coordinates: [x]
kinetic: x_dot^2/2
potential: {potential}
"
        )
    };
    let cases = [
        (from_horizontal("g*sin(x)"), 0.0),
        (from_horizontal("-g*cos(x)"), std::f64::consts::FRAC_PI_2),
    ];
    for (source, x0) in cases {
        let run = |tol: f64| {
            let mut system = model(&source);
            Taylor::new()
                .integrate(
                    &mut system,
                    0.0,
                    &[x0, 0.0],
                    1.2,
                    &OutputTimes::At(vec![1.2]),
                    &tolerance(tol),
                )
                .unwrap()
        };
        let exact = run(1e-15).state(0).to_vec();
        for tol in [1e-6, 1e-9] {
            let solution = run(tol);
            let y = solution.state(0);
            let error = (y[0] - exact[0]).abs().max((y[1] - exact[1]).abs());
            assert!(
                error < 100.0 * tol,
                "x0 = {x0}, tol {tol:e}: error {error:e} in {} steps",
                solution.stats.steps
            );
        }
    }
}

/// Quadratic drag `−c₂ √(ẋ² + ẏ²) (ẋ, ẏ)` (`models/projectile_drag.yaml`): the speed is a
/// root of a near-perfect square at the top of a vertical throw (`ẋ` is 1.2e-15 there), so
/// its series reads as `ẏ`'s and a step over the top would continue it negative, the drag
/// pushing along the motion on the way down (the run used to land 5e-3 s early at tol 1e-6
/// and 8e-2 s late at 1e-9, in 8 steps). The series must not be taken off the root's branch
/// ([`eomgen::taylor::branch_step`]): the vertical throw ends at the top, t = 1.6805508526
/// (the model's closed form), with a step-size failure — the speed is not analytic there —
/// and an oblique throw, where the speed stays away from 0, agrees with DOP853 at 1e-13.
/// The same for a spring of potential `|x|³`.
#[test]
fn a_step_never_leaves_the_branch_of_a_square_root() {
    let source = include_str!("../models/projectile_drag.yaml");
    let throw = |angle: f64, tol: f64| {
        let model = JitModel::from_source("projectile_drag.yaml", source).expect("loads");
        let mut system = DynFirstOrder::new(model);
        let y0 = [0.0, 0.0, 20.0 * angle.cos(), 20.0 * angle.sin()];
        Taylor::new().integrate(
            &mut system,
            0.0,
            &y0,
            3.0,
            &OutputTimes::At(vec![3.0]),
            &tolerance(tol),
        )
    };
    for tol in [1e-6, 1e-9, 1e-12] {
        let failure = throw(std::f64::consts::FRAC_PI_2, tol).expect_err("the top is reached");
        match failure.error {
            IntegrationError::StepSizeTooSmall { t, .. } => {
                assert!(
                    (t - 1.6805508526).abs() < 1e-6,
                    "tol {tol:e}: stopped at {t}"
                )
            }
            other => panic!("tol {tol:e}: {other}"),
        }
    }
    let angle: f64 = 1.0;
    let drag = JitModel::from_source("projectile_drag.yaml", source).expect("loads");
    let mut system = DynFirstOrder::new(drag);
    let reference = DormandPrince853::new()
        .integrate(
            &mut system,
            0.0,
            &[0.0, 0.0, 20.0 * angle.cos(), 20.0 * angle.sin()],
            3.0,
            &OutputTimes::At(vec![3.0]),
            &tolerance(1e-13),
        )
        .unwrap();
    let solution = throw(angle, 1e-10).unwrap();
    let error = solution
        .state(0)
        .iter()
        .zip(reference.state(0))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(error < 1e-8, "oblique throw: error {error:e}");
    // The spring of potential |x|³, written (x²)^(3/2): its force −3x√(x²) hides |x| as x, and
    // x passes 0 at the quarter period (1/√2)·B(1/3, 1/2)/3 = 0.99149247513406 s from
    // x = 1 at rest (energy ẋ²/2 + x³ = 1; mpmath's quadrature agrees to 6e-18), where the
    // run must end rather than continue with the force pushing outward.
    let cubic = "
name: cubic_spring
description: the potential |x|^3.
parameters: { k: 1 }
coordinates: [x]
kinetic: x_dot^2/2
potential: k*(x^2)^1.5
";
    let mut system = model(cubic);
    let failure = Taylor::new()
        .integrate(
            &mut system,
            0.0,
            &[1.0, 0.0],
            5.0,
            &OutputTimes::At(vec![5.0]),
            &tolerance(1e-9),
        )
        .expect_err("x reaches 0");
    match failure.error {
        IntegrationError::StepSizeTooSmall { t, .. } => {
            assert!((t - 0.99149247513406).abs() < 1e-9, "stopped at {t}")
        }
        other => panic!("{other}"),
    }
}

/// What the method cannot integrate is refused before any step, naming why: equations given
/// as a closure, equations with `step`, constraints stabilised by Baumgarte's terms.
#[test]
fn systems_without_recurrences_are_refused_with_the_reason() {
    let mut closure = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0]);
    let failure = Taylor::new()
        .integrate(
            &mut closure,
            0.0,
            &[1.0],
            1.0,
            &OutputTimes::Steps,
            &IntegratorOptions::default(),
        )
        .unwrap_err();
    assert!(
        matches!(failure.error, IntegrationError::NoTaylorRecurrences { .. }),
        "{failure}"
    );
    let piecewise = model(
        "
name: stop
description: a spring that only pushes.
parameters: { k: 1 }
coordinates: [x]
kinetic: x_dot^2/2
generalized_forces:
  x: -k*x*step(-x)
initial: { x: -1, x_dot: 0 }
",
    );
    let mut piecewise = piecewise;
    assert!(piecewise.taylor_support().is_err());
    let failure = Taylor::new()
        .integrate(
            &mut piecewise,
            0.0,
            &[-1.0, 0.0],
            1.0,
            &OutputTimes::Steps,
            &IntegratorOptions::default(),
        )
        .unwrap_err();
    let message = failure.to_string();
    assert!(message.contains("`step`"), "{message}");
    assert_eq!(failure.partial.len(), 0, "no step was taken");
    let mut constrained = DynFirstOrder::new(
        JitModel::load("models/simple_pendulum_cartesian.yaml").expect("bundled"),
    );
    assert!(constrained.taylor_support().is_ok());
    constrained.stabilization = eomgen::Stabilization::default_baumgarte();
    let message = constrained.taylor_support().unwrap_err().to_string();
    assert!(
        message.contains("`baumgarte`") && message.contains("projection"),
        "{message}"
    );
}

/// Tolerances that differ, or that are 0, size the buffers for the highest order either mode
/// asks for: `atol = 0` (relative only), `rtol = 0` (absolute only) and `rtol ≠ atol` with a
/// state that crosses between the modes all integrate the oscillator to the accuracy asked.
#[test]
fn zero_and_unequal_tolerances_work() {
    for (rtol, atol) in [(1e-10, 0.0), (0.0, 1e-10), (1e-6, 1e-12), (1e-12, 1e-6)] {
        let mut system = model(OSCILLATOR);
        let options = IntegratorOptions::default().with_rtol(rtol).with_atol(atol);
        let solution = Taylor::new()
            .integrate(
                &mut system,
                0.0,
                &[1.0, 0.0],
                20.0,
                &OutputTimes::Steps,
                &options,
            )
            .unwrap_or_else(|e| panic!("rtol {rtol:e}, atol {atol:e}: {e}"));
        let (t, y) = solution.last().unwrap();
        let error = (y[0] - t.cos()).abs().max((y[1] + t.sin()).abs());
        let asked = rtol.max(atol);
        assert!(
            error < 100.0 * asked,
            "rtol {rtol:e}, atol {atol:e}: {error:e}"
        );
    }
}

/// A step never exceeds `dt_max`, even the last one (which is not stretched past it to land
/// on the end).
#[test]
fn steps_respect_dt_max() {
    let mut system = model(OSCILLATOR);
    let options = tolerance(1e-8).with_dt_max(0.1);
    let solution = Taylor::new()
        .integrate(
            &mut system,
            0.0,
            &[1.0, 0.0],
            1.005,
            &OutputTimes::Steps,
            &options,
        )
        .unwrap();
    let longest = solution
        .t
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(0.0, f64::max);
    // Differences of rounded times: a few ulps over.
    assert!(longest <= 0.1 * (1.0 + 1e-12), "longest step {longest}");
    assert_eq!(*solution.t.last().unwrap(), 1.005);
}

/// `ẍ = 0` from `x = 1000.1`, `ẋ = 0.1`: `x = 1000.1 + 0.1 t`, each step adding to `x` an
/// increment 10⁷ times smaller. Compensated summation (see [`Taylor`]) carries the rounding
/// of each step's sum `x + δ` (up to `ulp(1000)/2 = 5.7e-14` a step) into the next, so after
/// 10,000 steps (`dt_max` 1e-3 to t = 10) `x` is within an ulp or two of `1001.1` (the sum of
/// the steps' lengths is `t` exactly, and each increment `τ · 0.1` rounds at 1e-20; it ends
/// on the double nearest `1001.1`); the plain sum ends 2.5e-10 away (2,200 ulps; measured
/// with the carry disabled). The bound is three ulps of 1000 (3.4e-13).
#[test]
fn the_rounding_of_many_small_steps_does_not_accumulate() {
    const FREE: &str = "
name: free_particle
description: x'' = 0.
parameters: { m: 1 }
coordinates: [x]
kinetic: m*x_dot^2/2
potential: 0
initial: { x: 1000.1, x_dot: 0.1 }
";
    let mut system = model(FREE);
    let options = tolerance(1e-12).with_dt_max(1e-3);
    let solution = Taylor::new()
        .integrate(
            &mut system,
            0.0,
            &[1000.1, 0.1],
            10.0,
            &OutputTimes::Steps,
            &options,
        )
        .unwrap();
    let y = solution.state(solution.len() - 1);
    let error = (y[0] - 1001.1).abs();
    assert!(solution.len() > 9_000, "{} steps", solution.len());
    assert!(
        error <= 3.0 * 1.1368683772161603e-13,
        "x(10) = {}, error {error:e}",
        y[0]
    );
    assert_eq!(y[1], 0.1);
}

/// `simulate --method taylor` and `--method vern9` (the library's `simulate`, which the
/// command calls) on every bundled unconstrained model, compiled by `model!` (the thirteen of
/// `compiled_models`; the others interpreted) and loaded from its file, 0–1 s from the file's
/// initial state:
/// - the Taylor method either integrates to the end (or to the same terminal event, within
///   1e-9 s) or is refused before its first step with the reason (a function without a
///   recurrence applied to the state), the same for both builds;
/// - where it integrates, the compiled model and the file take the same steps to the same
///   bits (the same recurrences, printed by the macro or compiled at run time);
/// - both methods end within `1e-9 · max(1, |y|)` of DOP853 at `tol` 1e-13 (Taylor at 1e-11,
///   Verner 9(8) at 1e-12). The largest difference measured is 2.7e-11 (`heavy_top`, Taylor;
///   the triple pendulum 7.3e-12 with Verner 9(8)), so the bound leaves a factor 37, while a
///   wrong recurrence or stage is off by far more.
#[test]
fn taylor_and_verner_9_run_every_unconstrained_model_compiled_and_from_its_file() {
    use eomgen::analysis::{Simulation, SimulationOptions, simulate};
    use eomgen::{Method, ModelInfo};
    let run = |model: &mut dyn ModelInfo, method: Method, tol: f64| -> Simulation {
        let options = SimulationOptions {
            method,
            t_end: 1.0,
            rtol: tol,
            atol: tol,
            ..SimulationOptions::default()
        };
        simulate(model, &options).expect("the simulation starts")
    };
    let end = |s: &Simulation| {
        let (y, dim) = (&s.solution.y, s.solution.dim);
        (
            *s.solution.t.last().expect("a sample"),
            y[y.len() - dim..].to_vec(),
        )
    };
    let (mut integrated, mut refused, mut stopped) = (Vec::new(), Vec::new(), Vec::new());
    for entry in eomgen::models::ALL {
        // Compiled by `model!` for the models of `compiled_models`, else the file on the
        // run-time compiler's interpreter backend: another route than the native code of
        // `file` below.
        let mut compiled = crate::compiled_models::make_or_interpreted(entry);
        if !compiled.description().constraint_names().is_empty() {
            continue;
        }
        let path = format!("{}/{}", env!("CARGO_MANIFEST_DIR"), entry.file);
        // Its Taylor orders compiled by Cranelift from the first series: the native route,
        // against `model!`'s code or the interpreter's.
        let eager = eomgen::LoadOptions {
            eager_taylor: true,
            ..eomgen::LoadOptions::default()
        };
        let mut file =
            DynFirstOrder::new(JitModel::load_with(&path, eager).expect("a bundled file loads"));
        let name = entry.name;
        let reference = run(compiled.as_mut(), Method::Dop853, 1e-13);
        assert!(reference.failure.is_none(), "{name}: DOP853 failed");
        let (t_ref, y_ref) = end(&reference);
        let close = |label: &str, s: &Simulation| {
            let (t, y) = end(s);
            // A terminal event is located to about the tolerance.
            assert!(
                (t - t_ref).abs() <= 1e-9,
                "{name}, {label}: ends at t = {t}, DOP853 at {t_ref}"
            );
            for (i, (a, b)) in y.iter().zip(&y_ref).enumerate() {
                assert!(
                    (a - b).abs() <= 1e-9 * b.abs().max(1.0),
                    "{name}, {label}: y[{i}] = {a:e}, DOP853 {b:e}"
                );
            }
        };
        let taylor = [
            run(compiled.as_mut(), Method::Taylor, 1e-11),
            run(&mut file, Method::Taylor, 1e-11),
        ];
        let in_contact = |s: &Simulation| {
            matches!(
                s.contact_stop,
                Some(eomgen::hybrid::ContactStop::MethodInContact { .. })
            )
        };
        match compiled.as_ode_mut().taylor_support() {
            // The Taylor method integrates free flights only: a model that starts on a closed
            // contact (the rocking block) stops there, on both routes, before any step.
            Ok(()) if in_contact(&taylor[0]) => {
                for (label, s) in ["taylor", "taylor from the file"].iter().zip(&taylor) {
                    assert!(in_contact(s), "{name}, {label}: {:?}", s.contact_stop);
                    assert_eq!(s.solution.t.len(), 1, "{name}, {label}: a step in contact");
                }
                stopped.push(name);
            }
            Ok(()) => {
                for (label, s) in ["taylor", "taylor from the file"].iter().zip(&taylor) {
                    assert!(s.failure.is_none(), "{name}, {label}: {:?}", s.failure);
                    close(label, s);
                }
                let work = |s: &Simulation| {
                    let stats = &s.solution.stats;
                    (stats.steps, stats.rejected, stats.taylor_series)
                };
                assert_eq!(
                    work(&taylor[0]),
                    work(&taylor[1]),
                    "{name}: the compiled model and its file take other steps"
                );
                let bits = |s: &Simulation| -> Vec<u64> {
                    s.solution.y.iter().map(|v| v.to_bits()).collect()
                };
                assert!(
                    bits(&taylor[0]) == bits(&taylor[1]),
                    "{name}: the compiled model and its file differ in their bits"
                );
                integrated.push(name);
            }
            Err(reason) => {
                let reason = reason.to_string();
                for s in &taylor {
                    let failure = s.failure.as_ref().expect("refused").to_string();
                    assert!(failure.contains(&reason), "{name}: {failure} / {reason}");
                    assert!(
                        s.solution.t.len() <= 1,
                        "{name}: no step before the refusal"
                    );
                }
                refused.push(name);
            }
        }
        close("vern9", &run(compiled.as_mut(), Method::Vern9, 1e-12));
        close("vern9 from the file", &run(&mut file, Method::Vern9, 1e-12));
    }
    eprintln!("integrated {integrated:?}, refused {refused:?}, stopped in contact {stopped:?}");
    assert!(integrated.len() >= 35, "{integrated:?}");
}

/// A constrained model's series are those of the index-1 system `[M Jᵀ; J 0][q̈; λ] = [F; γ]`
/// (`eomgen::taylor::series_of_motion` with the multipliers among the unknowns). For every
/// bundled model with constraints whose equations have recurrences, from its file:
/// - order 1 of the series is the right-hand side that the other integrators evaluate
///   (`ConstraintWorkspace`'s LU solve with pivoting, another code than the series' `L D Lᵀ`),
///   within `1e-14 · (1 + ‖f‖)` (measured: 5.4e-16 at most; a wrong block of `[M Jᵀ; J 0]`
///   or of `[F; γ]` is off by far more);
/// - Taylor at 1e-11 ends within `1e-9 · max(1, |y|)` of DOP853 at 1e-13 over 1 s, both
///   with no stabilisation or with projection (measured: 1.2e-11 at most);
/// - with projection after each step the constraints hold to 1e-12 over the run (measured:
///   1.6e-14).
///
/// The coefficients to order 12 are checked against an independent reference in
/// `tests/taylor_coefficients.rs` for all but the Whipple bicycle, whose equations are too
/// long to print for that reference; this test covers it.
#[test]
fn taylor_runs_every_constrained_model_from_its_file() {
    use eomgen::analysis::{Simulation, SimulationOptions, simulate};
    use eomgen::{Method, ModelInfo, Stabilization};
    let run = |model: &mut dyn ModelInfo, method, tol, stabilization| -> Simulation {
        let options = SimulationOptions {
            method,
            t_end: 1.0,
            rtol: tol,
            atol: tol,
            stabilization,
            ..SimulationOptions::default()
        };
        simulate(model, &options).expect("the simulation starts")
    };
    let mut integrated = Vec::new();
    // The largest differences met: order 1 against the right-hand side, the end against
    // DOP853's, the drift with projection.
    let mut worst = [0.0f64; 3];
    for entry in eomgen::models::ALL {
        let path = format!("{}/{}", env!("CARGO_MANIFEST_DIR"), entry.file);
        let mut file = DynFirstOrder::new(JitModel::load(&path).expect("a bundled file loads"));
        if file.description().constraint_names().is_empty() {
            continue;
        }
        let name = entry.name;
        if let Err(reason) = file.taylor_support() {
            // Only a function without a recurrence may stop it (`two_masses_rod`'s `step`).
            assert!(reason.to_string().contains("`step`"), "{name}: {reason}");
            continue;
        }
        let y0 = ModelInfo::initial_state(&file);
        let dim = y0.len();
        let mut series = vec![0.0; 2 * dim];
        file.taylor_coefficients(0.0, &y0, 1, &mut series)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut f = vec![0.0; dim];
        file.rhs(0.0, &y0, &mut f).expect("the right-hand side");
        let scale = 1.0 + f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..dim {
            let error = (series[dim + i] - f[i]).abs() / scale;
            worst[0] = worst[0].max(error);
            assert!(
                error <= 1e-14,
                "{name}: y'[{i}]: series {:e}, rhs {:e}",
                series[dim + i],
                f[i]
            );
        }
        let end = |s: &Simulation| {
            assert!(s.failure.is_none(), "{name}: {:?}", s.failure);
            s.solution.y[s.solution.y.len() - dim..].to_vec()
        };
        let reference = end(&run(&mut file, Method::Dop853, 1e-13, Stabilization::None));
        for stabilization in [Stabilization::None, Stabilization::Projection] {
            let taylor = run(&mut file, Method::Taylor, 1e-11, stabilization);
            for (i, (a, b)) in end(&taylor).iter().zip(&reference).enumerate() {
                worst[1] = worst[1].max((a - b).abs() / b.abs().max(1.0));
                assert!(
                    (a - b).abs() <= 1e-9 * b.abs().max(1.0),
                    "{name}, {stabilization:?}: y[{i}] = {a:e}, DOP853 {b:e}"
                );
            }
            if stabilization == Stabilization::Projection {
                let (position, velocity) = taylor.constraints.max_drift();
                worst[2] = worst[2].max(position.max(velocity));
                assert!(
                    position <= 1e-12 && velocity <= 1e-12,
                    "{name}: drift {position:e}, {velocity:e}"
                );
            }
        }
        integrated.push(name);
    }
    eprintln!(
        "integrated {integrated:?}; order 1, end, drift: {:.1e}, {:.1e}, {:.1e}",
        worst[0], worst[1], worst[2]
    );
    assert!(
        integrated.contains(&"whipple_bicycle") && integrated.len() >= 8,
        "{integrated:?}"
    );
}

/// A constrained model compiled by `model!` has no recurrences for its constraints (its fused
/// orders solve `M q̈ = F`), and says so; the same file compiled at run time has them.
#[test]
fn a_constrained_model_compiled_by_the_macro_points_to_its_file() {
    let entry = eomgen::models::ALL
        .iter()
        .find(|m| m.name == "whipple_bicycle")
        .expect("bundled");
    let mut compiled = crate::compiled_models::make_or_interpreted(entry);
    let reason = compiled
        .as_ode_mut()
        .taylor_support()
        .unwrap_err()
        .to_string();
    assert!(
        reason.contains("5 constraint(s)") && reason.contains("run time"),
        "{reason}"
    );
}
