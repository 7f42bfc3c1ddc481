//! `eomgen study convolution` as a library call (lecture 21: the response to impulse and step
//! forcing by convolution): the linearised model `M δq̈ + C δq̇ + K δq = b f(t)` about an
//! equilibrium, forced through one input by an arbitrary `f(t)`, solved by Duhamel's integral
//! over the impulse response and, independently, by DOP853.
//!
//! This file holds the options, the report, the impulse response, the quadrature and the
//! closed forms; the study's steps are in `response`.
//!
//! # The impulse response
//!
//! The input `p` is what [`frequency_response_analysis`](super::frequency_response_analysis)
//! takes: a parameter that enters the forcing linearly (its column `b = ∂F/∂p` at the
//! equilibrium, `t = 0`), or a coordinate's name (a unit generalized force on it). Its
//! impulse response is the free response from `δq = 0`, `δq̇ = M⁻¹b`:
//!
//! ```text
//! [h(t); ḣ(t)] = e^{At} [0; M⁻¹b],   A = [0 I; −M⁻¹K −M⁻¹C]      (n-vector h, m or rad per N·s)
//! ```
//!
//! evaluated on the grid `t_k = kΔ` by powers of one matrix exponential, `z_{k+1} = e^{AΔ} z_k`
//! (exact up to rounding, damped or not, any number of degrees of freedom).
//!
//! # Duhamel's integral
//!
//! From rest, `δq(t) = ∫₀ᵗ h(t − τ) f(τ) dτ`. On the grid the integrand `h(t_j − t_i) f(t_i)`
//! is known at every `t_i ≤ t_j`, and the integral is taken by composite Simpson's rule
//! (order 4, error `O(Δ⁴)` for a smooth `f`), with Simpson's 3/8 rule on the last three
//! intervals when `j` is odd (also order 4) and, at `j = 1`, Simpson's rule on `[0, Δ]` with
//! the midpoint `h(Δ/2) f(Δ/2)` (one more matrix exponential; the trapezoid there would be
//! off by `Δ³/12`, order 2, which dominated everything else). The error is estimated by
//! Richardson's rule from the same sum on every other and every fourth grid point: the order
//! seen, `p = log₂(|x_{2Δ} − x_{4Δ}|/|x_Δ − x_{2Δ}|)` (4 for a smooth `f`; 1 for an `f` that
//! jumps after `t = 0`, such as `step(t − 1)`, where Simpson's rule is of lower order), and
//! the error `|x_Δ − x_{2Δ}|/(2ᵖ − 1)`. At interior grid points `f` is sampled as the mean of
//! its values `10⁻⁷Δ` before and after — `f(t)` for a smooth `f`, the mean of the one-sided
//! limits at a jump on the grid, which keeps the rule second order there. The unit impulse `f = δ(t)` needs no quadrature: the response is `h`
//! itself; the unit step `f = H(t)` is the integral of `h`.
//!
//! # The check
//!
//! The same linear equations with the forcing `b f(t)` (or, for the impulse, from
//! `δq̇(0) = M⁻¹b`) are integrated by DOP853 at a tight tolerance and compared at every grid
//! point. For one degree of freedom with an impulse or a step, the closed forms are compared
//! too: with `ω = √(k/m)`, `ζ = c/(2√(km))`, `σ = ζω`,
//!
//! ```text
//! h(t) = b e^{−σt} sin(ω_d t)/(m ω_d),             ω_d = ω √(1 − ζ²)   (ζ < 1)
//! h(t) = b t e^{−ωt}/m                                                 (ζ = 1)
//! h(t) = b e^{−σt} sinh(ω_* t)/(m ω_*),            ω_* = ω √(ζ² − 1)   (ζ > 1)
//! s(t) = b (1 − m ḣ₁(t) − c h₁(t))/k  = (b/k)(1 − e^{−σt}(cos ω_d t + ζ/√(1 − ζ²) sin ω_d t))
//! ```
//!
//! (`h₁ = h/b`; the step response follows from `m s̈ + c ṡ + k s = b`, `ṡ = h`).

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::operating_point::{OperatingPoint, OperatingPointError, OperatingPointOptions};
use crate::integrate::{
    DormandPrince853, IntegrationError, Integrator, IntegratorOptions, OutputTimes,
};
use crate::linear::frequency_response::{
    ForcedLinearization, FrfError, linearize_with_input_rates, linearize_with_inputs,
};
use crate::linear::modal::{Linearization, matrix_exponential, normal_modes};
use crate::linear::response::modal_damping;
use crate::model_info::ModelInfo;
use crate::ode::{OdeSystem, RhsError};

mod response;

pub use response::convolution_response;

/// The forcing `f(t)` of [`convolution_response`] (units of the input; for the impulse, of the
/// input times s).
#[derive(Clone, Copy)]
pub enum Forcing<'a> {
    /// The unit impulse `δ(t)`: the response is the impulse response `h` itself.
    Impulse,
    /// The unit step `H(t)`: 1 for `t ≥ 0`.
    Step,
    /// Any function of `t` (s), evaluated at every grid point and wherever DOP853 asks; a value
    /// that is not finite is an error.
    Function {
        /// What to call it in the report (the expression as typed, `sin(2*t)`).
        label: &'a str,
        /// `f(t)`.
        f: &'a dyn Fn(f64) -> f64,
    },
}

impl Forcing<'_> {
    /// Its name in the report: `impulse`, `step`, or the function's label.
    pub fn label(&self) -> String {
        match self {
            Self::Impulse => "impulse".to_string(),
            Self::Step => "step".to_string(),
            Self::Function { label, .. } => label.to_string(),
        }
    }

    /// `f(t)` for `t ≥ 0` (0 for the impulse, which acts only at `t = 0`).
    fn value(&self, t: f64) -> f64 {
        match self {
            Self::Impulse => 0.0,
            Self::Step => 1.0,
            Self::Function { f, .. } => f(t),
        }
    }
}

impl std::fmt::Debug for Forcing<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Forcing({})", self.label())
    }
}

/// Options of [`convolution_response`].
#[derive(Debug, Clone)]
pub struct ConvolutionOptions<'a> {
    /// Where the equilibrium search starts (it runs with the input set to 0).
    pub operating_point: OperatingPointOptions,
    /// The input: a parameter that enters the forcing linearly (a load amplitude, `A` in
    /// `A*cos(w*t)`, whose time function is replaced by `forcing`), or a coordinate's name (a
    /// unit generalized force on it).
    pub input: String,
    /// The forcing `f(t)`.
    pub forcing: Forcing<'a>,
    /// The end time (s), finite and `> 0` (default: 10 periods of the lowest positive natural
    /// frequency).
    pub t_end: Option<f64>,
    /// Intervals of the grid on `[0, t_end]`, `≥ 4` (default: 2000); the quadrature's error
    /// falls as `intervals⁻⁴`, its cost grows as `intervals²`. (Below 4 the grids `Δ` and `2Δ`
    /// share no point where their sums differ, and Richardson's estimate would be 0.)
    pub intervals: usize,
    /// Relative tolerance of the DOP853 check, in `(0, 1)` (default: 1e-12); its absolute
    /// tolerance is `rtol` times the largest `|δq|` of the convolution.
    pub rtol: f64,
}

impl ConvolutionOptions<'_> {
    /// The default number of grid intervals.
    pub const DEFAULT_INTERVALS: usize = 2000;
    /// The default relative tolerance of the DOP853 check.
    pub const DEFAULT_RTOL: f64 = 1e-12;
}

impl Default for ConvolutionOptions<'_> {
    fn default() -> Self {
        Self {
            operating_point: OperatingPointOptions::default(),
            input: String::new(),
            forcing: Forcing::Step,
            t_end: None,
            intervals: Self::DEFAULT_INTERVALS,
            rtol: Self::DEFAULT_RTOL,
        }
    }
}

/// Why [`convolution_response`] failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ConvolutionError {
    /// No input was named.
    #[error("no input: name a load parameter (like `A` in `A*cos(w*t)`) or a coordinate")]
    NoInput,
    /// The input is neither a parameter nor a coordinate.
    #[error(
        "`{model}` has no parameter or coordinate `{input}` (parameters: {parameters}; coordinates: {coordinates})"
    )]
    UnknownInput {
        /// The model.
        model: String,
        /// The input asked for.
        input: String,
        /// Its parameters, comma separated.
        parameters: String,
        /// Its coordinates, comma separated.
        coordinates: String,
    },
    /// The input is a parameter but not a load amplitude (nonlinear, absent at `t = 0`, or
    /// in the mass matrix).
    #[error(transparent)]
    Input(FrfError),
    /// The input also enters through its rate (a base motion through a dashpot): the forcing
    /// would be `B₀ f + B₁ ḟ`, which needs `ḟ`.
    #[error(
        "input `{input}` also enters through its rate (a base motion through a dashpot, B₁ ≠ 0): the convolution takes a load b f(t)"
    )]
    InputEntersThroughRate {
        /// The input.
        input: String,
    },
    /// The operating point's start is unknown.
    #[error(transparent)]
    OperatingPoint(#[from] OperatingPointError),
    /// The equilibrium search or the linearisation failed (or the model has constraints).
    #[error(transparent)]
    Linearization(FrfError),
    /// An option is out of range.
    #[error("option `{option}` = {value} is out of range ({expected})")]
    InvalidOption {
        /// The option's name.
        option: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// No end time was given and no natural frequency is positive to choose one from.
    #[error(
        "`{model}` has no positive natural frequency at `{operating_point}` to choose the duration from; give an end time"
    )]
    NoDuration {
        /// The model.
        model: String,
        /// The operating point's name.
        operating_point: String,
    },
    /// The forcing is not finite at a grid point.
    #[error("the forcing is {value} at t = {t} s, not a finite number")]
    NonFiniteForcing {
        /// Where (s).
        t: f64,
        /// Its value.
        value: f64,
    },
    /// The impulse response or the convolution overflowed (an unstable equilibrium over a long
    /// time).
    #[error("the {what} is not finite at t = {t} s (an unstable equilibrium grows beyond f64)")]
    NotFinite {
        /// `impulse response` or `convolution`.
        what: &'static str,
        /// Where (s).
        t: f64,
    },
    /// The DOP853 check failed: a forcing not finite between grid points, or one (or a
    /// response) that varies faster than the grid, beyond the check's step budget.
    #[error("the direct integration failed{cause}: {error}", cause = integration_cause(.0), error = .0)]
    Integration(IntegrationError),
    /// The forcing varies within the grid's intervals: between grid points it is not the
    /// cubic through its grid values (sampled at two irrational fractions of each interval),
    /// in more than a tenth of the intervals. Sampled at the grid alone it would alias
    /// (`sin(1000 t)` on `Δ = π/100` is 0 at every grid point).
    #[error(
        "the forcing varies faster than the grid resolves: at t = {t} s it is {value:e}, the cubic through the grid gives {interpolated:e} ({intervals} of {total} intervals differ by more than 1 % of max |f|); raise --intervals above {suggested} or shorten the end time"
    )]
    ForcingUnresolved {
        /// Where the difference is largest (s).
        t: f64,
        /// The forcing there.
        value: f64,
        /// The cubic through the four nearest grid values there.
        interpolated: f64,
        /// Intervals where they differ by more than 1 % of `max |f|`.
        intervals: usize,
        /// Intervals of the grid.
        total: usize,
        /// Ten times the intervals given, a start for a grid that may resolve it.
        suggested: usize,
    },
    /// The convolution and the DOP853 check disagree by more than either's error allows: the
    /// result is not trusted.
    #[error(
        "the convolution and the direct integration disagree by {max_difference:e} (largest |δq| {scale:e}), beyond the quadrature's error estimate {error_estimate:e} and the check's tolerance: the forcing or the response varies faster than the grid resolves; raise --intervals"
    )]
    Disagreement {
        /// `max |convolution − DOP853|` (units of q).
        max_difference: f64,
        /// The larger of the two results' largest `|δq|`.
        scale: f64,
        /// The quadrature's Richardson estimate.
        error_estimate: f64,
    },
}

/// What [`ConvolutionError::Integration`] says of its cause.
fn integration_cause(error: &IntegrationError) -> &'static str {
    match error {
        IntegrationError::RhsNonFinite { .. } | IntegrationError::NonFiniteState { .. } => {
            " (a forcing that is not finite between grid points stops it)"
        }
        IntegrationError::TooManySteps { .. } | IntegrationError::StepSizeTooSmall { .. } => {
            " (the forcing or the response varies faster than the grid resolves)"
        }
        _ => "",
    }
}

/// The fraction of a grid's intervals where an unresolved forcing is refused
/// ([`ConvolutionError::ForcingUnresolved`]): a jump (`step(t − 1)`) or a square wave's
/// twenty jumps differ from the cubic in a few intervals each, aliasing in nearly all.
const UNRESOLVED_FRACTION: f64 = 0.1;

/// How far the convolution may stray from the DOP853 check before it is refused
/// ([`ConvolutionError::Disagreement`]): more than this times the quadrature's estimate,
/// plus [`CHECK_SLACK`] times the check's tolerance, and more than [`DISAGREEMENT_FLOOR`]
/// of the response.
const ESTIMATE_SLACK: f64 = 100.0;
/// See [`ESTIMATE_SLACK`].
const CHECK_SLACK: f64 = 1e3;
/// See [`ESTIMATE_SLACK`].
const DISAGREEMENT_FLOOR: f64 = 1e-6;

/// Refuses a forcing that varies within the grid's intervals: `f` at `t_k + c Δ`,
/// `c ∈ {0.381966, 0.723607}` (irrational, so that neither a grid-periodic nor a
/// midpoint-periodic forcing hides), against the cubic through the four nearest grid values
/// `values` and against the interval's own two grid values; more than
/// [`UNRESOLVED_FRACTION`] of the intervals off by 1 % of `max |f|` from all three is an
/// error (a square wave sampled anywhere equals one of its interval's grid values, so one of
/// ten points per half period is taken; a sine of five points per period is not). Cost: two
/// evaluations of `f` per interval.
fn check_resolution(
    forcing: &Forcing<'_>,
    times: &[f64],
    values: &[f64],
    step: f64,
) -> Result<(), ConvolutionError> {
    let total = values.len().saturating_sub(1);
    if total < 3 {
        return Ok(());
    }
    let mut largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut samples = Vec::with_capacity(2 * total);
    for k in 0..total {
        for c in [0.381966, 0.723607] {
            let t = times[k] + c * step;
            let value = forcing.value(t);
            if !value.is_finite() {
                return Err(ConvolutionError::NonFiniteForcing { t, value });
            }
            largest = largest.max(value.abs());
            // The cubic through the four grid values nearest the interval.
            let start = k.saturating_sub(1).min(total - 3);
            let s = (t - times[start]) / step;
            let w = [
                -(s - 1.0) * (s - 2.0) * (s - 3.0) / 6.0,
                s * (s - 2.0) * (s - 3.0) / 2.0,
                -s * (s - 1.0) * (s - 3.0) / 2.0,
                s * (s - 1.0) * (s - 2.0) / 6.0,
            ];
            let cubic: f64 = (0..4).map(|i| w[i] * values[start + i]).sum();
            // At one of the interval's own grid values (a square wave's flat parts, either
            // side of a jump) the grid holds what the rules need; elsewhere it missed the
            // forcing's shape.
            let (a, b) = (values[k], values[k + 1]);
            let away = (value - a).abs().min((value - b).abs());
            samples.push((k, t, value, cubic, away));
        }
    }
    let off = |(_, _, v, c, away): &&(usize, f64, f64, f64, f64)| {
        (v - c).abs() > 1e-2 * largest && *away > 1e-2 * largest
    };
    let mut unresolved: Vec<usize> = samples.iter().filter(off).map(|s| s.0).collect();
    unresolved.dedup();
    let worst = samples
        .iter()
        .max_by(|a, b| (a.2 - a.3).abs().total_cmp(&(b.2 - b.3).abs()));
    if let Some(worst) = worst
        && largest > 0.0
        && unresolved.len() as f64 > UNRESOLVED_FRACTION * total as f64
    {
        return Err(ConvolutionError::ForcingUnresolved {
            t: worst.1,
            value: worst.2,
            interpolated: worst.3,
            intervals: unresolved.len(),
            total,
            suggested: 10 * total,
        });
    }
    Ok(())
}

/// The closed form of a one-degree-of-freedom response, where one exists (an impulse or a
/// step on `m ẍ + c ẋ + k x = b f`, `m > 0`, `c ≥ 0`, `k > 0`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClosedForm {
    /// The formula, in the module docs' notation.
    pub formula: String,
    /// `ω = √(k/m)` (rad/s).
    pub natural_frequency: f64,
    /// `ζ = c/(2√(km))`.
    pub damping_ratio: f64,
    /// Its values on the grid (m or rad).
    pub values: Vec<f64>,
    /// `max |convolution − closed form|` over the grid (m or rad).
    pub max_difference: f64,
}

/// The quadrature of Duhamel's integral.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Quadrature {
    /// The rule.
    pub rule: &'static str,
    /// Its order (the error falls as `Δᵒʳᵈᵉʳ` for a smooth forcing).
    pub order: u32,
    /// The grid step `Δ` (s).
    pub step: f64,
    /// `max |x_Δ − x_{2Δ}|/(2ᵖ − 1)` over the even grid points, `p` the observed order
    /// (Richardson's estimate of the error; 0 for the impulse, which needs no quadrature)
    /// (m or rad).
    pub error_estimate: f64,
    /// The order `p = log₂(max|x_{2Δ} − x_{4Δ}| / max|x_Δ − x_{2Δ}|)` seen on the grids `Δ`,
    /// `2Δ`, `4Δ`, within `[1, 4]`: about 4 for a smooth forcing, 1 for one that jumps after
    /// `t = 0`; `None` for the impulse and below 8 intervals (then `p = 4` is assumed).
    pub observed_order: Option<f64>,
}

/// What [`convolution_response`] computed.
///
/// # Shapes
/// `n` coordinates, `N + 1` grid times: `impulse_response`, `convolution` and `direct` are
/// `N + 1` vectors of `n` entries each.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConvolutionStudy {
    /// The unforced equilibrium and its name.
    pub operating_point: OperatingPoint,
    /// The input.
    pub input: String,
    /// The forcing's name (`impulse`, `step` or the function's label).
    pub forcing: String,
    /// `M`, `C`, `K` at the equilibrium and the input column `b`.
    pub forced: ForcedLinearization,
    /// The undamped natural frequencies (rad/s, ascending).
    pub natural_frequencies: Vec<f64>,
    /// The modal damping ratios (the diagonal of `ΨᵀCΨ` over `2ωₖ`; `None` for a zero mode).
    pub damping_ratios: Vec<Option<f64>>,
    /// The grid `t_k = kΔ` (s).
    pub times: Vec<f64>,
    /// `h(t_k)`, the displacements per unit impulse (m or rad per unit input·s).
    pub impulse_response: Vec<Vec<f64>>,
    /// `δq(t_k)` by Duhamel's integral (m or rad).
    pub convolution: Vec<Vec<f64>>,
    /// `δq(t_k)` by DOP853 on the linear equations (m or rad).
    pub direct: Vec<Vec<f64>>,
    /// `max |convolution − direct|` over the grid and the coordinates (m or rad).
    pub max_difference: f64,
    /// `max |convolution|` (m or rad): the scale of the differences.
    pub max_response: f64,
    /// The quadrature and its error estimate.
    pub quadrature: Quadrature,
    /// The closed form, for one degree of freedom with an impulse or a step (stable, `k > 0`).
    pub closed_form: Option<ClosedForm>,
    /// DOP853's relative tolerance (its absolute tolerance is `direct_rtol · max_response`).
    pub direct_rtol: f64,
    /// DOP853's accepted steps.
    pub direct_steps: usize,
    /// DOP853's right-hand-side evaluations.
    pub direct_rhs_evals: usize,
}

fn invalid(option: &'static str, value: f64, expected: &'static str) -> ConvolutionError {
    ConvolutionError::InvalidOption {
        option,
        value,
        expected,
    }
}

/// `h(t_k)` (the first `n` entries of `e^{A t_k} z0`) by powers of `e^{AΔ}`; the last grid
/// point, at `t_end` exactly, from `e^{A(t_end − t_{N−1})}`.
fn impulse_response(
    a: &DMatrix<f64>,
    z0: &DVector<f64>,
    step: f64,
    intervals: usize,
    n: usize,
    times: &[f64],
) -> Result<Vec<Vec<f64>>, ConvolutionError> {
    let propagator = matrix_exponential(&(a * step));
    let mut z = z0.clone();
    let mut out = Vec::with_capacity(intervals + 1);
    for (k, &t) in times.iter().enumerate() {
        if k > 0 {
            z = &propagator * &z;
        }
        if !z.iter().all(|v| v.is_finite()) {
            return Err(ConvolutionError::NotFinite {
                what: "impulse response",
                t,
            });
        }
        out.push(z.as_slice()[..n].to_vec());
    }
    Ok(out)
}

/// `x_j = ∫₀^{t_j} h(t_j − τ) f(τ) dτ` at every grid point `j` from samples `h_k = h(kΔ)` and
/// `f_k = f(kΔ)`: composite Simpson for even `j`, Simpson on `[0, t_{j−3}]` plus the 3/8
/// rule on the last three intervals for odd `j ≥ 3`, and at `j = 1` Simpson on `[0, Δ]` with
/// the midpoint samples `(h(Δ/2), f(Δ/2))`.
fn duhamel(h: &[Vec<f64>], f: &[f64], step: f64, midpoint: (&[f64], f64)) -> Vec<Vec<f64>> {
    let n = h.first().map_or(0, Vec::len);
    let mut out = Vec::with_capacity(h.len());
    let mut weights = vec![0.0; h.len()];
    for j in 0..h.len() {
        if j == 1 {
            let (h_half, f_half) = midpoint;
            let x = (0..n)
                .map(|r| step / 6.0 * (h[1][r] * f[0] + 4.0 * h_half[r] * f_half + h[0][r] * f[1]))
                .collect();
            out.push(x);
            continue;
        }
        quadrature_weights(j, &mut weights[..=j]);
        let mut x = vec![0.0; n];
        for (i, w) in weights[..=j].iter().enumerate() {
            let g = w * f[i];
            if g == 0.0 {
                continue;
            }
            for (xr, hr) in x.iter_mut().zip(&h[j - i]) {
                *xr += g * hr;
            }
        }
        for v in &mut x {
            *v *= step;
        }
        out.push(x);
    }
    out
}

/// The weights (in units of `Δ`) of the rule of [`duhamel`] over the `j` intervals of
/// `[0, t_j]`, written into `w` (length `j + 1`); at `j = 1`, the trapezoid (which [`duhamel`]
/// replaces by Simpson's rule with a midpoint).
fn quadrature_weights(j: usize, w: &mut [f64]) {
    w.fill(0.0);
    match j {
        0 => {}
        1 => {
            w[0] = 0.5;
            w[1] = 0.5;
        }
        _ => {
            // Simpson on [0, t_m], m even; the 3/8 rule on [t_m, t_j] when j is odd.
            let m = if j.is_multiple_of(2) { j } else { j - 3 };
            for (i, wi) in w.iter_mut().enumerate().take(m + 1).skip(1) {
                *wi = if i == m {
                    1.0 / 3.0
                } else if i % 2 == 1 {
                    4.0 / 3.0
                } else {
                    2.0 / 3.0
                };
            }
            if m > 0 {
                w[0] = 1.0 / 3.0;
            }
            if j % 2 == 1 {
                for (offset, c) in [3.0 / 8.0, 9.0 / 8.0, 9.0 / 8.0, 3.0 / 8.0]
                    .into_iter()
                    .enumerate()
                {
                    w[m + offset] += c;
                }
            }
        }
    }
}

/// `ẏ = A y + z_b f(t)` with `z_b = [0; M⁻¹b]`: the linearised equations forced through the
/// input.
struct ForcedLinearOde<'a> {
    a: &'a DMatrix<f64>,
    input: &'a DVector<f64>,
    forcing: &'a Forcing<'a>,
}

impl OdeSystem for ForcedLinearOde<'_> {
    fn dim(&self) -> usize {
        self.a.nrows()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let f = self.forcing.value(t);
        for (i, d) in dy.iter_mut().enumerate() {
            let ay: f64 = self.a.row(i).iter().zip(y).map(|(a, y)| a * y).sum();
            *d = ay + self.input[i] * f;
            if !d.is_finite() {
                return Err(RhsError::NonFinite { index: i });
            }
        }
        Ok(())
    }

    fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        jac.copy_from_slice(self.a.as_slice());
        Ok(true)
    }
}

/// DOP853 on the linear equations from rest (from `z0` for the impulse) at `times`; the
/// absolute tolerance is `rtol` times the response's scale.
fn direct_response(
    a: &DMatrix<f64>,
    z0: &DVector<f64>,
    forcing: &Forcing<'_>,
    times: &[f64],
    rtol: f64,
    scale: f64,
) -> Result<(Vec<Vec<f64>>, usize, usize), ConvolutionError> {
    let n = a.nrows() / 2;
    let y0: Vec<f64> = match forcing {
        Forcing::Impulse => z0.as_slice().to_vec(),
        _ => vec![0.0; 2 * n],
    };
    let mut system = ForcedLinearOde {
        a,
        input: z0,
        forcing,
    };
    let options = IntegratorOptions::default()
        .with_rtol(rtol)
        .with_atol(rtol * scale.max(f64::MIN_POSITIVE))
        // Bounded by the grid: 2 million steps at the default 2000 intervals, about 20 s (an
        // impulse response over 1e5 s takes 5e5), and 4 million at most; a forcing that needs
        // more varies faster than the grid resolves.
        .with_max_steps((10_000 + 1000 * times.len()).min(4_000_000));
    let t_end = *times.last().unwrap_or(&0.0);
    let solution = DormandPrince853::new()
        .integrate(
            &mut system,
            0.0,
            &y0,
            t_end,
            &OutputTimes::At(times.to_vec()),
            &options,
        )
        .map_err(|failure| ConvolutionError::Integration(failure.error))?;
    let values = solution.iter().map(|(_, y)| y[..n].to_vec()).collect();
    Ok((values, solution.stats.steps, solution.stats.rhs_evals))
}

/// `t ↦ (h₁(t), ḣ₁(t))`, a closed-form unit impulse response and its rate.
type ImpulseResponse = Box<dyn Fn(f64) -> (f64, f64)>;

/// The closed form for one degree of freedom with an impulse or a step: `(formula, ω, ζ,
/// values)`; `None` otherwise, or unless `m > 0`, `c ≥ 0`, `k > 0`.
fn closed_form(
    lin: &Linearization,
    input_matrix: &DMatrix<f64>,
    forcing: &Forcing<'_>,
    times: &[f64],
) -> Option<(String, f64, f64, Vec<f64>)> {
    if lin.mass_matrix.nrows() != 1 || matches!(forcing, Forcing::Function { .. }) {
        return None;
    }
    let (m, c, k) = (
        lin.mass_matrix[(0, 0)],
        lin.damping_matrix[(0, 0)],
        lin.stiffness_matrix[(0, 0)],
    );
    let b = input_matrix[(0, 0)];
    if !(m > 0.0 && c >= 0.0 && k > 0.0) {
        return None;
    }
    let w = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    let sigma = zeta * w;
    // h₁(t) and ḣ₁(t), the unit impulse response of m ẍ + c ẋ + k x = δ and its rate.
    let (h, formula): (ImpulseResponse, &str) = if zeta < 1.0 {
        let wd = w * (1.0 - zeta * zeta).sqrt();
        (
            Box::new(move |t: f64| {
                let e = (-sigma * t).exp();
                let (s, co) = (wd * t).sin_cos();
                (e * s / (m * wd), e * (wd * co - sigma * s) / (m * wd))
            }),
            "e^{−ζωt} sin(ω_d t)/(m ω_d)",
        )
    } else if zeta == 1.0 {
        (
            Box::new(move |t: f64| {
                let e = (-w * t).exp();
                (t * e / m, e * (1.0 - w * t) / m)
            }),
            "t e^{−ωt}/m",
        )
    } else {
        let ws = w * (zeta * zeta - 1.0).sqrt();
        (
            Box::new(move |t: f64| {
                // e^{−σt} sinh(ω_* t) as a difference of decaying exponentials.
                let (e1, e2) = ((-(sigma - ws) * t).exp(), (-(sigma + ws) * t).exp());
                let sh = (e1 - e2) / 2.0;
                let ch = (e1 + e2) / 2.0;
                (sh / (m * ws), (ws * ch - sigma * sh) / (m * ws))
            }),
            "e^{−ζωt} sinh(ω_* t)/(m ω_*)",
        )
    };
    let (values, formula) = match forcing {
        Forcing::Impulse => (
            times.iter().map(|&t| b * h(t).0).collect(),
            format!("h(t) = b {formula}"),
        ),
        _ => (
            times
                .iter()
                .map(|&t| {
                    let (h1, h1_dot) = h(t);
                    b * (1.0 - m * h1_dot - c * h1) / k
                })
                .collect(),
            format!("s(t) = b (1 − m ḣ₁ − c h₁)/k, h₁ = {formula}"),
        ),
    };
    Some((formula, w, zeta, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The weights integrate cubics exactly (order 4) over every `[0, t_j]`.
    #[test]
    fn weights_are_exact_for_cubics() {
        for j in 0..12 {
            let mut w = vec![0.0; j + 1];
            quadrature_weights(j, &mut w);
            if j == 1 {
                continue;
            }
            let step = 0.37;
            let f = |x: f64| 1.0 - 2.0 * x + 3.0 * x * x - 0.5 * x * x * x;
            let exact = |x: f64| x - x * x + x * x * x - 0.125 * x.powi(4);
            let sum: f64 = w
                .iter()
                .enumerate()
                .map(|(i, wi)| wi * f(i as f64 * step))
                .sum::<f64>()
                * step;
            let t = j as f64 * step;
            assert!(
                (sum - exact(t)).abs() < 1e-13 * exact(t).abs().max(1.0),
                "j = {j}: {sum} vs {}",
                exact(t)
            );
        }
    }
}
