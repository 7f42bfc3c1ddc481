//! Event location (issue 6, item 2; lecture 17, HW21): zeros of g(t, y) found on each
//! method's dense output, with direction and terminal events.

use eomgen_runtime::analysis::Method;
use eomgen_runtime::{
    DormandPrince853, EventDirection, EventSpec, ExplicitEuler, IntegrationError, Integrator,
    IntegratorOptions, OdeFn, OdeSystem, OutputTimes, RhsError, RungeKutta4, Solution, WithEvents,
};

/// Complete elliptic integral of the first kind `K(k) = π / (2 AGM(1, √(1 − k²)))`
/// (Abramowitz & Stegun 17.6), to machine precision.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0_f64, (1.0 - k * k).sqrt());
    for _ in 0..40 {
        let (a1, b1) = (0.5 * (a + b), (a * b).sqrt());
        a = a1;
        b = b1;
    }
    std::f64::consts::PI / (a + b)
}

/// The pendulum θ̈ = −(g/l) sin θ with g/l = 10 1/s², released at rest from `theta0`; its
/// period is `4 √(l/g) K(sin(θ₀/2))`.
fn pendulum() -> OdeFn<impl FnMut(f64, &[f64], &mut [f64])> {
    OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
        dy[0] = y[1];
        dy[1] = -10.0 * y[0].sin();
    })
}

fn exact_period(theta0: f64) -> f64 {
    4.0 * (0.1_f64).sqrt() * elliptic_k((theta0 / 2.0).sin())
}

/// Integrates the pendulum with `method`, locating "θ̇ reaches zero from above" (HW21: the
/// velocity's falling zeros are the returns to θ₀, one per period).
fn returns(method: &mut dyn Integrator, theta0: f64, options: &IntegratorOptions) -> Solution {
    let mut p = pendulum();
    let spec = EventSpec::new("return", EventDirection::Falling, false);
    let mut system = WithEvents::new(
        &mut p,
        vec![spec],
        |_: &mut _, _t, y: &[f64], g: &mut [f64]| {
            g[0] = y[1];
            Ok(())
        },
    );
    let t_end = 5.5 * exact_period(theta0);
    method
        .integrate(
            &mut system,
            0.0,
            &[theta0, 0.0],
            t_end,
            &OutputTimes::At(vec![t_end]),
            options,
        )
        .unwrap_or_else(|f| panic!("{}: {f}", method.name()))
}

/// The test: the pendulum period from events against the exact elliptic-integral
/// period to 1e-10 (relative), for a large amplitude (θ₀ = 2.5 rad, T = 3.28 × the small-angle
/// period's 1.99 s). DOP853 at tol 1e-13 has global errors ~1e-12 over 5 periods and its
/// order-7 dense output is as accurate, so 1e-10 leaves room while failing for any error in
/// the root finding or interpolation (a Hermite-cubic location would be off by ~1e-8 here).
#[test]
fn pendulum_period_from_events_matches_the_elliptic_integral() {
    let theta0 = 2.5;
    let exact = exact_period(theta0);
    let options = IntegratorOptions::default()
        .with_rtol(1e-13)
        .with_atol(1e-13);
    let solution = returns(&mut DormandPrince853::new(), theta0, &options);
    let times: Vec<f64> = solution.events.iter().map(|e| e.t).collect();
    assert_eq!(times.len(), 5, "five returns in 5.5 periods: {times:?}");
    for (k, t) in times.iter().enumerate() {
        let expected = (k + 1) as f64 * exact;
        assert!(
            ((t - expected) / expected).abs() < 1e-10,
            "return {k}: {t} vs {expected}"
        );
        let e = &solution.events[k];
        assert_eq!(e.direction, EventDirection::Falling);
        assert!(!e.terminal);
        // The state at the event: θ back at θ₀, θ̇ = 0 (to the solution's accuracy).
        assert!(
            (e.y[0] - theta0).abs() < 1e-9 && e.y[1].abs() < 1e-9,
            "{:?}",
            e.y
        );
    }
    // Successive periods agree with each other, too.
    let periods: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    for p in &periods {
        assert!(((p - exact) / exact).abs() < 1e-10);
    }
    assert_eq!(solution.terminated_by_event, None);
    assert!(solution.stats.event_evals > solution.stats.steps);
}

/// Every method locates the events: the period error is what its order and the dense output
/// allow. Tolerances are 2–5 times the errors measured when this was written, per method
/// (fixed steps h = T/200 for the fixed-step methods, tol 1e-8 for the adaptive ones): from
/// 5e-2 for explicit Euler to 2e-11 for Radau IIA over five periods.
#[test]
fn every_method_locates_the_returns() {
    let theta0 = 1.0;
    let exact = exact_period(theta0);
    let h = exact / 200.0;
    let adaptive = IntegratorOptions::default().with_rtol(1e-8).with_atol(1e-8);
    let fixed = IntegratorOptions::default()
        .with_dt(h)
        .with_rtol(1e-10)
        .with_atol(1e-10);
    // Every method of the registry (the match is exhaustive: a new method needs its bound).
    for method in Method::ALL {
        let (options, tolerance) = match method {
            // Needs a model's recurrences, not a closure: tests/taylor.rs locates its events.
            Method::Taylor => continue,
            Method::Euler => (&fixed, 0.1),
            Method::Midpoint => (&fixed, 5e-4),
            Method::Rk4 => (&fixed, 3e-8),
            Method::SymplecticEuler => (&fixed, 1e-4),
            Method::StormerVerlet => (&fixed, 2e-4),
            Method::ImplicitMidpoint => (&fixed, 2e-4),
            Method::Bs32 => (&adaptive, 2e-7),
            Method::Dp54 => (&adaptive, 5e-8),
            Method::Dop853 => (&adaptive, 2e-9),
            Method::Vern6 => (&adaptive, 1e-9),
            Method::Vern7 => (&adaptive, 3e-11),
            Method::Vern8 => (&adaptive, 2e-9),
            Method::Vern9 => (&adaptive, 1e-10),
            Method::Radau5 => (&adaptive, 1e-10),
        };
        let mut method = method.integrator();
        let solution = returns(method.as_mut(), theta0, options);
        let name = method.name();
        assert_eq!(solution.events.len(), 5, "{name}");
        let last = solution.events[4].t;
        let error = ((last - 5.0 * exact) / (5.0 * exact)).abs();
        assert!(error < tolerance, "{name}: relative error {error:e} of 5 T");
    }
}

/// A terminal event ends the integration at the event: samples stop there (every-step
/// output ends with the event's state; requested times up to it are sampled, none after), and the
/// location is exact for a solution the interpolant represents exactly (a parabola).
#[test]
fn terminal_events_stop_the_integration() {
    let mut ball = OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
        dy[0] = y[1];
        dy[1] = -10.0;
    });
    let specs = vec![
        EventSpec::new("apex", EventDirection::Falling, false),
        EventSpec::new("landing", EventDirection::Falling, true),
        EventSpec::new("below", EventDirection::Both, false),
    ];
    let mut system = WithEvents::new(
        &mut ball,
        specs,
        |_: &mut _, _t, y: &[f64], g: &mut [f64]| {
            g[0] = y[1];
            g[1] = y[0];
            g[2] = y[0] + 1.0;
            Ok(())
        },
    );
    let options = IntegratorOptions::default().with_dt(0.3);
    // Requested times on both sides of the landing, and all before it (none left to record
    // in the landing's step).
    for output in [
        OutputTimes::Steps,
        OutputTimes::At(vec![0.5, 1.0, 1.9, 2.5, 3.0]),
        OutputTimes::At(vec![0.5, 1.0]),
    ] {
        let solution = RungeKutta4::new()
            .integrate(&mut system, 0.0, &[0.0, 10.0], 5.0, &output, &options)
            .unwrap();
        let names: Vec<&str> = solution.events.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(
            names,
            ["apex", "landing"],
            "the event after landing is never reached"
        );
        assert!((solution.events[0].t - 1.0).abs() < 1e-14);
        assert!((solution.events[1].t - 2.0).abs() < 1e-14);
        assert_eq!(solution.terminated_by_event, Some(1));
        let (t_last, y_last) = solution.last().unwrap();
        match output {
            OutputTimes::Steps => {
                assert_eq!(t_last, solution.events[1].t);
                assert!(y_last[0].abs() < 1e-13 && (y_last[1] + 10.0).abs() < 1e-13);
            }
            OutputTimes::At(ref times) => {
                let before: Vec<f64> = times.iter().copied().filter(|&t| t <= 2.0).collect();
                assert_eq!(solution.t, before);
            }
        }
    }
}

/// One explicit Euler step of the clock `y' = 1` over [0, 1] (so `y = t` exactly, its
/// dense output linear) with the events `specs` whose values `g(t, y)` computes.
fn one_step_of_the_clock(
    specs: Vec<EventSpec>,
    g: impl FnMut(f64, &[f64], &mut [f64]),
) -> Solution {
    one_step_of_the_clock_from(0.0, specs, g)
}

/// [`one_step_of_the_clock`] over `[start, start + 1]`, from `y = start` (for `start` in
/// `[0, 1]` still `y = t` exactly: `start + (t − start)` rounds to `t`).
fn one_step_of_the_clock_from(
    start: f64,
    specs: Vec<EventSpec>,
    g: impl FnMut(f64, &[f64], &mut [f64]),
) -> Solution {
    let mut g = g;
    let mut clock = OdeFn::new(1, |_t: f64, _y: &[f64], dy: &mut [f64]| dy[0] = 1.0);
    let mut system = WithEvents::new(
        &mut clock,
        specs,
        |_: &mut _, t: f64, y: &[f64], values: &mut [f64]| {
            g(t, y, values);
            Ok(())
        },
    );
    let options = IntegratorOptions::default().with_dt(1.0);
    ExplicitEuler::new()
        .integrate(
            &mut system,
            start,
            &[start],
            start + 1.0,
            &OutputTimes::Steps,
            &options,
        )
        .unwrap()
}

/// The located zero of `g(y − start)` over [`one_step_of_the_clock_from`] `start` and the
/// times at which the search evaluated `g`, after the two evaluations at the step's ends.
fn zero_search_from(start: f64, g: impl Fn(f64) -> f64) -> (f64, Vec<f64>) {
    let mut times = Vec::new();
    let specs = vec![EventSpec::new("zero", EventDirection::Rising, false)];
    let solution = one_step_of_the_clock_from(start, specs, |t, y, values| {
        times.push(t);
        values[0] = g(y[0] - start);
    });
    (solution.events[0].t, times.split_off(2))
}

/// The located zero of `g(y)` over [`one_step_of_the_clock`], the number of evaluations of
/// `g` after the two at the step's ends, and how many of them fell outside the step.
fn located_zero(g: impl Fn(f64) -> f64) -> (f64, usize, usize) {
    let (t, times) = zero_search_from(0.0, g);
    let outside = times.iter().filter(|t| !(0.0..=1.0).contains(*t)).count();
    (t, times.len(), outside)
}

/// Zeros located by Brent's method: each root to 4ε (absolute), and the evaluations of `g`
/// it takes.
///
/// `g(y)` over one Euler step of `y' = 1` on [0, 1], whose linear dense output is `y = t`
/// exactly, for simple roots of smooth functions, a steep one, a jump and a square-root
/// zero. The bounds are the counts of the method as implemented (its interpolation is
/// deterministic): superlinear convergence needs 6–20 where bisection of the step to a few
/// rounding units takes more than 50, and the jump, where no interpolation helps, about 50.
/// A worse interpolation or a weaker safeguard shows as more evaluations on at least one of
/// them.
#[test]
fn zeros_are_located_in_few_evaluations() {
    type G = fn(f64) -> f64;
    let cases: [(&str, G, f64, usize); 7] = [
        ("t³ − 0.1", |t| t.powi(3) - 0.1, 0.1f64.cbrt(), 10),
        ("eᵗ − 2", |t| t.exp() - 2.0, 2f64.ln(), 6),
        ("t² − 1e-4", |t| t * t - 1e-4, 1e-2, 17),
        (
            "(t − 0.3)(1 + 10⁶ (t − 0.31)²)",
            |t| (t - 0.3) * (1.0 + 1e6 * (t - 0.31).powi(2)),
            0.3,
            20,
        ),
        ("tanh(10⁴ (t − 0.3))", |t| (1e4 * (t - 0.3)).tanh(), 0.3, 17),
        (
            "sign(t − 0.3) √|t − 0.3|",
            |t| (t - 0.3).signum() * (t - 0.3).abs().sqrt(),
            0.3,
            30,
        ),
        (
            "a jump at 0.3",
            |t| if t < 0.3 { -1.0 } else { 1.0 + t },
            0.3,
            54,
        ),
    ];
    for (name, g, root, most) in cases {
        let (t, search, outside) = located_zero(g);
        assert!((t - root).abs() < 4.0 * f64::EPSILON, "{name}: {t}");
        assert_eq!(outside, 0, "{name}: trial points outside the step");
        assert!(search <= most, "{name}: {search} evaluations");
    }
}

/// Brent's search keeps every trial point inside the step and finds the root, on 3,000
/// functions with one simple root `r ∈ [0.02, 0.98]` in one Euler step of `y' = 1` (so
/// `y = t`), drawn from four families by a fixed linear congruential sequence: `eᵏᵗ − eᵏʳ`
/// (steep and convex), `(t − r)(0.01 + a (t − s)²)` (nearly flat beside the root),
/// `atan(k (t − r)) + 0.3 a (t − r)³`, and `sign(t − r) |t − r|^p` with `p ∈ [0.1, 3.1]`
/// (infinite or zero slope at the root). The root to 1e-9: the search ends on a bracket a
/// few rounding units wide around the sign change, or where `g` rounds to 0 (within about
/// 1e-15 of `r` for these families), so 1e-9 only leaves margin; a trial point outside the
/// step, or a root elsewhere, is what a broken safeguard produces.
#[test]
fn brent_keeps_its_trial_points_in_the_step() {
    let mut state: u64 = 12345;
    let mut uniform = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for case in 0..3000 {
        let r = 0.02 + 0.96 * uniform();
        let k = 1.0 + 60.0 * uniform();
        let (a, s) = (50.0 * uniform(), uniform());
        let family = case % 4;
        let g = move |t: f64| match family {
            0 => (k * t).exp() - (k * r).exp(),
            1 => (t - r) * (0.01 + a * (t - s).powi(2)),
            2 => (k * (t - r)).atan() + 0.3 * a * (t - r).powi(3),
            _ => (t - r).signum() * (t - r).abs().powf(0.1 + 3.0 * s),
        };
        let (t, _, outside) = located_zero(g);
        assert!(
            (t - r).abs() < 1e-9,
            "case {case} (family {family}): {t} vs {r}"
        );
        assert_eq!(outside, 0, "case {case} (family {family})");
    }
}

/// Test function `k` of `tools/brent_reference/problems.f90`, with the same operations in
/// the same order: ten chosen ones (smooth, convex, flat beside the root, a jump, square-root
/// and ninth-order zeros, a root at `10⁻³¹⁰` below the absolute tolerance, a pole beside the
/// root, `t²⁰`, and one built so that an interpolated point falls within rounding of the
/// acceptance test's bound), then 400 from four families with parameters `frac(k c)` for three
/// irrational `c`: `(t − r)(0.01 + a (t − s)²)`, `sign(t − r) √|t − r| (1 + a t)`,
/// `(t − r)³ + 10⁻³ a (t − r)` and `(t − r)/(0.01 + (t − s)²)`.
fn brent_case(k: usize) -> impl Fn(f64) -> f64 {
    let frac = |c: f64| (k as f64 * c).fract();
    let r = 0.02 + 0.96 * frac(0.6180339887498949);
    let a = 50.0 * frac(0.7548776662466927);
    let s = frac(0.5698402909980532);
    move |t: f64| match k {
        1 => t * t * t - 0.1,
        2 => t * t - 1e-4,
        3 => {
            let x = t - 0.31;
            (t - 0.3) * (1.0 + 1e6 * (x * x))
        }
        4 => {
            if t < 0.3 {
                -1.0
            } else {
                1.0 + t
            }
        }
        5 => {
            let x = t - 0.3;
            x.abs().sqrt().copysign(x)
        }
        6 => {
            let x = t - 0.3;
            x * x * x * x * x * x * x * x * x
        }
        7 => t - 1e-310,
        8 => 50.0 - 1.0 / (t + 0.01),
        9 => {
            let t2 = t * t;
            let t4 = t2 * t2;
            let t16 = (t4 * t4) * (t4 * t4);
            t16 * t4 - 0.5
        }
        // Over the step from 0, its value at 0.6, the secant point from (0, −1.5) and (1, 1),
        // puts the next (inverse quadratic) point 0.45 from 0.6, a few rounding units short
        // of three quarters of the bracket [0, 0.6]: rejected by the test
        // `2p < 3mq − |tol q|`, accepted without the `− |tol q|`. (From 1 the secant point is
        // 1.6, and 1.6 − 1 is not 0.6: there it is `t − 0.1`.)
        10 => match t {
            0.0 => -1.5,
            1.0 => 1.0,
            0.6 => 0.6131299792238182,
            _ => t - 0.1,
        },
        _ => {
            let x = t - r;
            match k % 4 {
                0 => x * (0.01 + a * ((t - s) * (t - s))),
                1 => x.abs().sqrt().copysign(x) * (1.0 + a * t),
                2 => x * x * x + (1e-3 * a) * x,
                _ => x / (0.01 + (t - s) * (t - s)),
            }
        }
    }
}

/// The event search is Brent's procedure `zero` (Brent 1973, §4.6) with `macheps = ε` and
/// `t = f64::MIN_POSITIVE`: on 410 functions `g(t − t₀)`, over steps `[t₀, t₀ + 1]` from
/// `t₀ = 0` and from `t₀ = 1` (where the step's end `b + a` differs from its length
/// `b − a`, and the tolerance `2ε|t|` from its absolute part), its evaluations of `g` have
/// the same fingerprint, to the bit, as those of `zero` itself, compiled from J. Burkardt's
/// Fortran transcription (`tools/brent_reference`, whose output is
/// `tests/data/brent_zero.txt`): per function and step the number of evaluations after the
/// two at the step's ends, the sum of their times in order and the last time. A different
/// sequence of times would have to agree in all three to pass. Every choice between interpolation and bisection shows in these
/// sequences: the step before last `e` that gates interpolation, its reset when the bracket
/// changes sides, which end is the best point, the acceptance test of an interpolated point
/// and the absolute part of the tolerance. The test functions use `+ − × /` and `√` only, so
/// both codes compute the same values.
#[test]
fn brent_takes_the_steps_of_brents_zero() {
    let reference = include_str!("data/brent_zero.txt");
    let mut cases = 0;
    for line in reference.lines() {
        let fields: Vec<&str> = line.split_whitespace().collect();
        let k: usize = fields[0].parse().unwrap();
        let start: f64 = fields[1].parse().unwrap();
        let count: usize = fields[2].parse().unwrap();
        let (sum, last): (f64, f64) = (fields[3].parse().unwrap(), fields[4].parse().unwrap());
        let (_, times) = zero_search_from(start, brent_case(k));
        let ours_sum = times.iter().fold(0.0, |total, t| total + t);
        let ours_last = times.last().copied().unwrap_or(0.0);
        assert_eq!(
            (times.len(), ours_sum.to_bits(), ours_last.to_bits()),
            (count, sum.to_bits(), last.to_bits()),
            "function {k} from {start}: {} evaluations, sum {ours_sum:e}, last {ours_last:e}; zero: {count}, {sum:e}, {last:e}",
            times.len()
        );
        cases += 1;
    }
    assert_eq!(cases, 2 * 410);
}

/// An event at the same instant as a terminal one is recorded with it (a later one is not):
/// `y − 0.5` (terminal) and `2y − 1` cross together, `y − 0.7` after.
#[test]
fn events_at_the_terminal_instant_are_recorded() {
    let specs = vec![
        EventSpec::new("stop", EventDirection::Rising, true),
        EventSpec::new("same", EventDirection::Rising, false),
        EventSpec::new("later", EventDirection::Rising, false),
    ];
    let solution = one_step_of_the_clock(specs, |_t, y, g| {
        g[0] = y[0] - 0.5;
        g[1] = 2.0 * y[0] - 1.0;
        g[2] = y[0] - 0.7;
    });
    let found: Vec<(&str, f64)> = solution
        .events
        .iter()
        .map(|e| (e.name.as_str(), e.t))
        .collect();
    assert_eq!(found.len(), 2, "{found:?}");
    assert_eq!((found[0].0, found[1].0), ("stop", "same"));
    assert_eq!(found[0].1, found[1].1);
    assert_eq!(solution.terminated_by_event, Some(0));
}

/// Several zeros in one step come out in time order, whatever the order of the functions.
#[test]
fn zeros_within_one_step_are_ordered() {
    let specs = vec![
        EventSpec::new("late", EventDirection::Rising, false),
        EventSpec::new("early", EventDirection::Rising, false),
    ];
    let solution = one_step_of_the_clock(specs, |_t, y, g| {
        g[0] = y[0] - 0.7;
        g[1] = y[0] - 0.2;
    });
    let found: Vec<(&str, f64)> = solution
        .events
        .iter()
        .map(|e| (e.name.as_str(), e.t))
        .collect();
    assert_eq!(found.len(), 2);
    assert_eq!(found[0].0, "early");
    assert!((found[0].1 - 0.2).abs() < 1e-15 && (found[1].1 - 0.7).abs() < 1e-15);
}

/// A zero at the start is not an event, and a rising-only event ignores falling crossings.
#[test]
fn start_zeros_and_directions() {
    let mut p = pendulum();
    let specs = vec![EventSpec::new("rising", EventDirection::Rising, false)];
    let mut system = WithEvents::new(&mut p, specs, |_: &mut _, _t, y: &[f64], g: &mut [f64]| {
        g[0] = y[1];
        Ok(())
    });
    let theta0 = 0.5;
    let exact = exact_period(theta0);
    let options = IntegratorOptions::default()
        .with_rtol(1e-12)
        .with_atol(1e-12);
    let solution = DormandPrince853::new()
        .integrate(
            &mut system,
            0.0,
            &[theta0, 0.0],
            1.2 * exact,
            &OutputTimes::Steps,
            &options,
        )
        .unwrap();
    // θ̇ starts at 0 (not an event), goes negative, rises through 0 at T/2, falls at T.
    assert_eq!(solution.events.len(), 1);
    assert!((solution.events[0].t - exact / 2.0).abs() < 1e-10);
    assert_eq!(solution.events[0].direction, EventDirection::Rising);
}

/// A NaN event function is an error with t and the function, keeping the samples.
#[test]
fn nan_event_functions_are_errors() {
    let mut clock = OdeFn::new(1, |_t: f64, _y: &[f64], dy: &mut [f64]| dy[0] = 1.0);
    let specs = vec![EventSpec::new("sqrt", EventDirection::Both, false)];
    let mut system = WithEvents::new(
        &mut clock,
        specs,
        |_: &mut _, _t, y: &[f64], g: &mut [f64]| {
            g[0] = (0.5 - y[0]).sqrt();
            Ok(())
        },
    );
    let options = IntegratorOptions::default().with_dt(0.1);
    let failure = RungeKutta4::new()
        .integrate(&mut system, 0.0, &[0.0], 1.0, &OutputTimes::Steps, &options)
        .unwrap_err();
    match failure.error {
        IntegrationError::EventNotFinite { t, index: 0 } => assert!((t - 0.6).abs() < 1e-12),
        other => panic!("{other:?}"),
    }
    assert_eq!(failure.partial.t.len(), 6, "samples up to t = 0.5 are kept");
    // And a system error in an event function is reported as such.
    let mut clock = OdeFn::new(1, |_t: f64, _y: &[f64], dy: &mut [f64]| dy[0] = 1.0);
    let specs = vec![EventSpec::new("fails", EventDirection::Both, false)];
    let mut system = WithEvents::new(
        &mut clock,
        specs,
        |_: &mut _, t: f64, _y: &[f64], _g: &mut [f64]| {
            if t > 0.25 {
                Err(RhsError::SingularMassMatrix)
            } else {
                Ok(())
            }
        },
    );
    let failure = RungeKutta4::new()
        .integrate(&mut system, 0.0, &[0.0], 1.0, &OutputTimes::Steps, &options)
        .unwrap_err();
    assert!(
        matches!(failure.error, IntegrationError::SingularMassMatrix { t } if (t - 0.3).abs() < 1e-12)
    );
    assert!(system.event_specs().len() == 1);
}
