//! `eomgen study euler-roundoff` (HW1; syllabus lecture 4, "Euler's method vs midpoint
//! method: truncation (method) errors and roundoff errors … the random cancellation, thus
//! √n, aspect of roundoff error").
//!
//! `ẋ = x`, `x(0) = 1` on `[0, 1]` (`x(1) = e`) with explicit Euler, explicit midpoint and
//! RK4 at `h = 10⁻ⁿ`, `n = 0 … N`. The error at `t = 1` splits exactly into
//!
//! ```text
//! x_N − e = (Φ(h)ᴺ − e)   +   (x_N − Φ(h)ᴺ)
//!           truncation        roundoff
//! ```
//!
//! where `Φ(h)` is the method's step factor in exact arithmetic (`1 + h`, `1 + h + h²/2`,
//! `1 + h + … + h⁴/24`, the stability polynomial at `z = h`) and `Φ(h)ᴺ` is evaluated as
//! `exp(N ln(1 + (Φ − 1)))` with `ln_1p`, accurate to a few units of `ε e` (`ε = 2⁻⁵²`).
//! Truncation falls as `e h/2` (Euler), `e h²/6` (midpoint), `e h⁴/120` (RK4); roundoff
//! grows with the number of steps, as `ε √N` if the rounding errors of the steps were
//! independent and as `ε N` if they keep one sign.

//!
//! References: N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM,
//! 2002, §1.12 and §2.6 (rounding-error accumulation, √n and n behaviour); E. Hairer,
//! S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., Springer,
//! 1993, §II.3 (truncation error of Runge–Kutta methods).

use std::f64::consts::E;

use serde::Serialize;

use crate::analysis::outcome::{RunTally, StudyRuns};
use crate::integrate::stability_function::StabilityPolynomial;
use crate::integrate::{
    ExplicitEuler, ExplicitMidpoint, Integrator, IntegratorOptions, OutputTimes, RungeKutta4,
    Tableau,
};
use crate::ode::OdeFn;

/// Options of [`euler_roundoff`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoundoffOptions {
    /// Largest `n`: steps `h = 10⁻ⁿ` for `n = 0 … N`, so `10ᴺ` steps per method at the end,
    /// at most [`LARGEST_N`] (default: 7).
    pub max_n: u32,
}

impl RoundoffOptions {
    /// The default largest n (steps h = 10⁻ⁿ).
    pub const DEFAULT_MAX_N: u32 = 7;
}

impl Default for RoundoffOptions {
    fn default() -> Self {
        Self {
            max_n: Self::DEFAULT_MAX_N,
        }
    }
}

/// Why the round-off study could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RoundoffError {
    /// `max_n` above [`LARGEST_N`].
    #[error("the largest n must be at most {largest} (10ⁿ steps per method), got {max_n}")]
    MaxNTooLarge {
        /// The value given.
        max_n: u32,
        /// [`LARGEST_N`].
        largest: u32,
    },
    /// A method failed on `ẋ = x`.
    #[error("{method} with h = {h:e}: {message}")]
    Integration {
        /// The integrator's name.
        method: &'static str,
        /// The step (s).
        h: f64,
        /// The integration's failure.
        message: String,
    },
}

/// The result of [`euler_roundoff`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EulerRoundoff {
    /// One row per `n = 0 … max_n`.
    pub rows: Vec<RoundoffRow>,
    /// One summary per method (explicit Euler, midpoint, RK4).
    pub summary: Vec<RoundoffSummary>,
    /// What the figures show, in words that follow the figures.
    pub notes: Vec<String>,
}

impl EulerRoundoff {
    /// The study as `eomgen study euler-roundoff --json` prints it
    /// ([`EulerRoundoffSummary`]): the problem, its exact answer and the machine epsilon with
    /// the rows.
    pub fn summary(&self) -> EulerRoundoffSummary<'_> {
        EulerRoundoffSummary {
            problem: "x' = x, x(0) = 1 on [0, 1]; x(1) = e",
            exact: E,
            epsilon: f64::EPSILON,
            rows: &self.rows,
            summary: &self.summary,
            notes: &self.notes,
        }
    }
}

/// An [`EulerRoundoff`] study as `eomgen study euler-roundoff --json` prints it
/// ([`EulerRoundoff::summary`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EulerRoundoffSummary<'a> {
    /// The problem, in words.
    pub problem: &'static str,
    /// Its exact answer `x(1) = e`.
    pub exact: f64,
    /// The machine epsilon of `f64`.
    pub epsilon: f64,
    /// [`EulerRoundoff::rows`].
    pub rows: &'a [RoundoffRow],
    /// [`EulerRoundoff::summary`].
    pub summary: &'a [RoundoffSummary],
    /// [`EulerRoundoff::notes`].
    pub notes: &'a [String],
}

/// Each method at each `h` is a run; a failed one fails the study as a whole
/// ([`RoundoffError::Integration`]), so every run of a report measured something.
impl StudyRuns for EulerRoundoff {
    fn study(&self) -> &'static str {
        "euler-roundoff"
    }

    fn tally(&self) -> RunTally {
        RunTally {
            measured: self.rows.iter().map(|r| r.runs.len()).sum(),
            ..RunTally::default()
        }
    }
}

/// Runs HW1's round-off study (see the module docs): explicit Euler, explicit midpoint and
/// RK4 on `ẋ = x` at `h = 10⁻ⁿ`, `n = 0 … max_n`, each error split into truncation and
/// roundoff, with a single-precision Euler loop beside them.
///
/// # Errors
/// [`RoundoffError::MaxNTooLarge`]; [`RoundoffError::Integration`] if a run fails.
///
/// # Examples
/// ```
/// use eomgen::analysis::{RoundoffOptions, euler_roundoff};
///
/// let study = euler_roundoff(&RoundoffOptions { max_n: 3 })?;
/// let euler = &study.rows[3].runs[0];
/// assert_eq!(euler.method, "euler");
/// // Truncation e h/2 at h = 1e-3, to first order.
/// assert!((euler.truncation + std::f64::consts::E * 1e-3 / 2.0).abs() < 1e-5);
/// # Ok::<(), eomgen::analysis::RoundoffError>(())
/// ```
pub fn euler_roundoff(options: &RoundoffOptions) -> Result<EulerRoundoff, RoundoffError> {
    if options.max_n > LARGEST_N {
        return Err(RoundoffError::MaxNTooLarge {
            max_n: options.max_n,
            largest: LARGEST_N,
        });
    }
    let tableaus = [Tableau::euler(), Tableau::midpoint(), Tableau::rk4()];
    let polynomials: Vec<StabilityPolynomial> = tableaus
        .iter()
        .map(StabilityPolynomial::of_tableau)
        .collect();
    let mut rows = Vec::new();
    for n in 0..=options.max_n {
        // Parsed rather than computed, so that h is the double nearest to 10⁻ⁿ.
        let h: f64 = format!("1e-{n}").parse().unwrap_or(10f64.powi(-(n as i32)));
        let steps = 10usize.pow(n);
        let methods: [Box<dyn Integrator>; 3] = [
            Box::new(ExplicitEuler::new()),
            Box::new(ExplicitMidpoint::new()),
            Box::new(RungeKutta4::new()),
        ];
        let mut runs = Vec::new();
        for (mut method, polynomial) in methods.into_iter().zip(&polynomials) {
            let x = x_at_one(method.as_mut(), h, steps)?;
            let exact_arithmetic = exact_arithmetic(polynomial, steps);
            runs.push(RoundoffRun {
                method: method.name(),
                x,
                error: x - E,
                truncation: exact_arithmetic - E,
                roundoff: x - exact_arithmetic,
            });
        }
        let epsilon = f64::EPSILON;
        rows.push(RoundoffRow {
            n,
            h,
            steps,
            epsilon_sqrt_steps: epsilon * (steps as f64).sqrt(),
            epsilon_steps: epsilon * steps as f64,
            runs,
            single_precision_euler: single_precision_euler(steps),
        });
    }
    let summaries: Vec<RoundoffSummary> = (0..tableaus.len()).map(|i| summary(&rows, i)).collect();
    let notes = notes(&rows, &summaries);

    Ok(EulerRoundoff {
        rows,
        summary: summaries,
        notes,
    })
}

/// Largest accepted `max_n`: the three methods then take `1.11 × 10⁸` steps each, about half
/// a minute of CPU time (~85 ns a step through the integrators' driver); each further `n`
/// multiplies that by ten (`n = 10` took well over an hour), so the limit is what finishes in
/// bounded time.
pub const LARGEST_N: u32 = 8;
/// Roundoff below this multiple of `ε` is within the accuracy of `Φ(h)ᴺ` and is left out of
/// the fitted growth exponent.
pub const ROUNDOFF_FLOOR: f64 = 100.0;

/// One method at one `h`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RoundoffRun {
    /// The integrator's name.
    pub method: &'static str,
    /// `x(1)` computed.
    pub x: f64,
    /// `x(1) − e`.
    pub error: f64,
    /// `Φ(h)ᴺ − e`, the error in exact arithmetic.
    pub truncation: f64,
    /// `x(1) − Φ(h)ᴺ`, the accumulated rounding error.
    pub roundoff: f64,
}

/// All methods at one `n`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RoundoffRow {
    /// `n`, the step being `h = 10⁻ⁿ`.
    pub n: u32,
    /// The step `h = 10⁻ⁿ` (the double nearest to it).
    pub h: f64,
    /// The number of steps `N = 10ⁿ`.
    pub steps: usize,
    /// `ε √N`.
    pub epsilon_sqrt_steps: f64,
    /// `ε N`.
    pub epsilon_steps: f64,
    /// Explicit Euler, midpoint and RK4, in that order.
    pub runs: Vec<RoundoffRun>,
    /// Explicit Euler as a hand-written loop `x ← x + h x` in single precision (`f32`,
    /// `ε₃₂ = 2⁻²³`): `x(1)` and `x(1) − e`.
    pub single_precision_euler: SinglePrecision,
}

/// The single-precision Euler loop at one `n`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SinglePrecision {
    /// `x(1)` computed (as a double).
    pub x: f64,
    /// `x(1) − e`.
    pub error: f64,
    /// `x(1) − (1 + h)ᴺ` with the `f32` step `h` in exact arithmetic: the accumulated rounding
    /// of the additions alone.
    pub roundoff: f64,
    /// `ε₃₂ √N`.
    pub epsilon_sqrt_steps: f64,
    /// `ε₃₂ N`.
    pub epsilon_steps: f64,
}

/// Explicit Euler on `ẋ = x` in single precision: `steps` steps of `x ← x + h x`, `h` the
/// `f32` nearest to `1/steps` (its representation error, up to `2⁻²⁴` relative, shifts the
/// end time by as much and is part of the roundoff).
pub fn single_precision_euler(steps: usize) -> SinglePrecision {
    let h = (1.0 / steps as f64) as f32;
    let mut x = 1.0f32;
    for _ in 0..steps {
        x += h * x;
    }
    let epsilon = f64::from(f32::EPSILON);
    let exact_arithmetic = (steps as f64 * f64::from(h).ln_1p()).exp();
    SinglePrecision {
        x: f64::from(x),
        error: f64::from(x) - E,
        roundoff: f64::from(x) - exact_arithmetic,
        epsilon_sqrt_steps: epsilon * (steps as f64).sqrt(),
        epsilon_steps: epsilon * steps as f64,
    }
}

/// The smallest error of a method over `n`, and how its roundoff grows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RoundoffSummary {
    /// The integrator's name.
    pub method: &'static str,
    /// The `n` of the smallest `|x(1) − e|`.
    pub optimal_n: u32,
    /// That smallest `|x(1) − e|`.
    pub smallest_error: f64,
    /// The first `n` whose error is below `100 ε` (rounding level), if any.
    pub first_n_at_rounding_level: Option<u32>,
    /// Exponent `a` of `|roundoff| ∝ Nᵃ` fitted (least squares in log–log) over the `n` whose
    /// roundoff exceeds `100 ε` (`None` with fewer than two such `n`).
    pub roundoff_exponent: Option<f64>,
}

/// `x(1)` by `steps` constant steps of size `h` (the last snapped to `t = 1`).
fn x_at_one(method: &mut dyn Integrator, h: f64, steps: usize) -> Result<f64, RoundoffError> {
    let mut growth = OdeFn::new(1, |_t: f64, x: &[f64], dx: &mut [f64]| dx[0] = x[0]);
    let options = IntegratorOptions::default()
        .with_dt(h)
        .with_max_steps(steps + 10);
    let solution = method
        .integrate(
            &mut growth,
            0.0,
            &[1.0],
            1.0,
            &OutputTimes::At(vec![1.0]),
            &options,
        )
        .map_err(|e| RoundoffError::Integration {
            method: method.name(),
            h,
            message: e.to_string(),
        })?;
    Ok(solution.state(0)[0])
}

/// `Φ(1/N)ᴺ` in exact arithmetic, to a few `ε e`: `exp(N ln_1p(Φ − 1))` with `Φ − 1` summed
/// from the small terms up (no cancellation against 1).
pub fn exact_arithmetic(polynomial: &StabilityPolynomial, steps: usize) -> f64 {
    let h = 1.0 / steps as f64;
    let increment: f64 = polynomial
        .coefficients()
        .iter()
        .enumerate()
        .skip(1)
        .rev()
        .map(|(k, r)| r * h.powi(k as i32))
        .sum();
    (steps as f64 * increment.ln_1p()).exp()
}

fn summary(rows: &[RoundoffRow], index: usize) -> RoundoffSummary {
    let mut best = (0, f64::INFINITY);
    let mut points = Vec::new();
    let mut method = "";
    for r in rows {
        let run = &r.runs[index];
        method = run.method;
        if run.error.abs() < best.1 {
            best = (r.n, run.error.abs());
        }
        if run.roundoff.abs() > ROUNDOFF_FLOOR * f64::EPSILON {
            points.push(((r.steps as f64).log10(), run.roundoff.abs().log10()));
        }
    }
    let first_n_at_rounding_level = rows
        .iter()
        .find(|r| r.runs[index].error.abs() < ROUNDOFF_FLOOR * f64::EPSILON)
        .map(|r| r.n);
    RoundoffSummary {
        method,
        first_n_at_rounding_level,
        optimal_n: best.0,
        smallest_error: best.1,
        roundoff_exponent: slope(&points),
    }
}

/// Least-squares slope of `points`, `None` with fewer than two.
pub fn slope(points: &[(f64, f64)]) -> Option<f64> {
    if points.len() < 2 {
        return None;
    }
    let count = points.len() as f64;
    let mean_x = points.iter().map(|p| p.0).sum::<f64>() / count;
    let mean_y = points.iter().map(|p| p.1).sum::<f64>() / count;
    let sxy: f64 = points.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
    let sxx: f64 = points.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
    Some(sxy / sxx)
}

/// What the figures show, in words that follow the figures.
fn notes(rows: &[RoundoffRow], summaries: &[RoundoffSummary]) -> Vec<String> {
    let max_n = rows.last().map_or(0, |r| r.n);
    let mut notes = vec![
        "truncation is the exact-arithmetic error Φ(h)^N − e; it falls as e h/2 (euler), e h²/6 (midpoint), e h⁴/120 (rk4) until it is below the roundoff".to_string(),
        "roundoff is x(1) − Φ(h)^N: each step rounds x + h·F to the nearest double (error ≤ ε x/2), and an error made at t is amplified by e^(1−t)".to_string(),
    ];
    for s in summaries {
        let exponent = s.roundoff_exponent.map_or_else(
            || "too few n with roundoff above 100 ε to fit its growth".to_string(),
            |a| format!("fitted roundoff ∝ N^{a:.2} (0.5 for independent rounding errors, 1 for errors of one sign)"),
        );
        let optimum = if let Some(n) = s.first_n_at_rounding_level {
            format!(
                "|error| below 100 ε from n = {n} on (smallest {:.2e} at n = {}): truncation is below roundoff there, and the optimum is wherever the rounding happens to cancel",
                s.smallest_error, s.optimal_n
            )
        } else if s.optimal_n == max_n {
            format!(
                "smallest error at the largest n tried ({max_n}): roundoff has not overtaken truncation"
            )
        } else {
            format!(
                "optimal n = {} (|error| {:.2e})",
                s.optimal_n, s.smallest_error
            )
        };
        notes.push(format!("{} in f64: {optimum}; {exponent}", s.method));
    }
    let single = |r: &RoundoffRow| r.single_precision_euler.error.abs();
    if let Some(best) = rows.iter().min_by(|a, b| single(a).total_cmp(&single(b))) {
        notes.push(format!(
            "euler in f32 (ε₃₂ = {:.2e}): optimal n = {} (|error| {:.2e}), the textbook trade-off at a reachable n",
            f32::EPSILON,
            best.n,
            single(best)
        ));
    }
    let roundoff = |r: &RoundoffRow| r.single_precision_euler.roundoff.abs();
    if let Some(r) = rows
        .iter()
        .find(|r| r.n > 0 && roundoff(r) > 0.1 * r.single_precision_euler.epsilon_steps)
    {
        notes.push(format!(
            "euler in f32 at n = {}: roundoff {:.2e}, of the size ε₃₂N = {:.2e} rather than ε₃₂√N = {:.2e}: h·x is within a few units in the last place of x, so every x + h·x rounds the same way (systematic, not random)",
            r.n,
            roundoff(r),
            r.single_precision_euler.epsilon_steps,
            r.single_precision_euler.epsilon_sqrt_steps
        ));
    }
    if let Some(r) = rows
        .iter()
        .find(|r| r.n > 0 && r.single_precision_euler.x == 1.0)
    {
        notes.push(format!(
            "euler in f32 from n = {}: h·x is below half a unit in the last place of x = 1, x + h·x rounds back to x, and x never leaves 1 (error 1 − e)",
            r.n
        ));
    }
    notes
}
