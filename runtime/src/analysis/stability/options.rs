//! The stability study's options, its errors, and how a run that stopped early is reported.

use serde::Serialize;

use crate::UnknownParameter;
use crate::integrate::IntegrationFailure;

/// Options of [`stability_study`](super::stability_study).
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityOptions {
    /// Constant steps of each run of the stability-limit bisection (part a), in
    /// `[100, 10⁶]` (default: 10⁴). The bisection makes ~400 runs of this many steps over
    /// the methods, ~50 s of CPU time at 10⁶.
    pub steps: usize,
    /// Periods of the oscillator in the energy study (part b), in `[1, 10⁵]` (default: 10⁴):
    /// `3296` steps per period over the four runs, every step of the three coarse ones kept,
    /// ~19 s of CPU time and 90 MB at 10⁵.
    pub periods: usize,
    /// Stiffness ratios `k/m` (1/s²) of the stiff two-mass spring (part c), each in
    /// `(0, 1e10]`, at least one (default: 1e2, 1e4, 1e6, 1e8).
    pub stiffness: Vec<f64>,
    /// End time of the stiff runs (s), in `[1e-6, 100]` (default: 1; shorter spans put the
    /// steps among subnormal numbers, where Radau's Newton iteration breaks down).
    pub t_end: f64,
    /// Relative and absolute tolerance of the stiff runs and of the underflow run, in
    /// `[1e-13, 1)` (default: 1e-6).
    pub tol: f64,
    /// The names of the stiff model's masses, spring, force and stretched coordinate (part
    /// c; default: those of HW9's two-mass spring file).
    pub stiff_spring: StiffSpring,
}

/// The names in the stiff model of part c: two masses `m₁`, `m₂` (kg) joined by a spring of
/// stiffness `k` (N/m) under a constant force `F₀` (N), whose static stretch
/// `F₀ m₁/(k (m₁ + m₂))` is added to the stretched coordinate in the run from equilibrium;
/// the stiff mode's frequency is `√(k (m₁ + m₂)/(m₁ m₂))`.
#[derive(Debug, Clone, PartialEq)]
pub struct StiffSpring {
    /// The first mass's parameter (default `m1`).
    pub mass_1: String,
    /// The second mass's parameter (default `m2`).
    pub mass_2: String,
    /// The spring's stiffness parameter, set to `k/m · m₁` (default `k`).
    pub stiffness: String,
    /// The constant force's parameter (default `F0`).
    pub force: String,
    /// The coordinate displaced by the static stretch in the run from equilibrium (default
    /// `x2`).
    pub stretched: String,
}

impl Default for StiffSpring {
    fn default() -> Self {
        Self {
            mass_1: "m1".to_string(),
            mass_2: "m2".to_string(),
            stiffness: "k".to_string(),
            force: "F0".to_string(),
            stretched: "x2".to_string(),
        }
    }
}

impl StabilityOptions {
    /// The default number of constant steps of each stability-limit run.
    pub const DEFAULT_STEPS: usize = 10_000;
    /// The default number of periods of the energy study.
    pub const DEFAULT_PERIODS: usize = 10_000;
    /// The default stiffness ratios k/m (1/s²) of the stiff two-mass spring.
    pub const DEFAULT_STIFFNESS: [f64; 4] = [1e2, 1e4, 1e6, 1e8];
    /// The default end time of the stiff runs (s).
    pub const DEFAULT_T_END: f64 = 1.0;
    /// The default tolerance of the stiff runs and of the underflow run.
    pub const DEFAULT_TOL: f64 = 1e-6;
}

impl Default for StabilityOptions {
    fn default() -> Self {
        Self {
            steps: Self::DEFAULT_STEPS,
            periods: Self::DEFAULT_PERIODS,
            stiffness: Self::DEFAULT_STIFFNESS.to_vec(),
            t_end: Self::DEFAULT_T_END,
            tol: Self::DEFAULT_TOL,
            stiff_spring: StiffSpring::default(),
        }
    }
}

/// Why the stability study could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StabilityError {
    /// `steps` outside `[100, 10⁶]`.
    #[error("the bisection's steps must be in [100, 10⁶], got {steps}")]
    InvalidSteps {
        /// The value given.
        steps: usize,
    },
    /// `periods` outside `[1, 10⁵]`.
    #[error("the periods must be in [1, 10⁵], got {periods}")]
    InvalidPeriods {
        /// The value given.
        periods: usize,
    },
    /// No stiffness ratio, or one outside `(0, 1e10]`.
    #[error("the stiffness ratios k/m must be in (0, 1e10], at least one")]
    InvalidStiffness,
    /// `t_end` outside `[1e-6, 100]`.
    #[error("the end time must be in [1e-6, 100] s, got {t_end}")]
    InvalidEndTime {
        /// The value given (s).
        t_end: f64,
    },
    /// `tol` outside `[1e-13, 1)`.
    #[error("the tolerance must be in [1e-13, 1), got {tol}")]
    InvalidTolerance {
        /// The value given.
        tol: f64,
    },
    /// A method failed on one step of the test equation used to read off its polynomial.
    #[error("a polynomial step failed: {message}")]
    PolynomialStep {
        /// The integration's failure.
        message: String,
    },
    /// A method failed on the test equation during the bisection.
    #[error("{method} failed on the test equation: {message}")]
    TestEquation {
        /// The integrator's name.
        method: &'static str,
        /// The integration's failure.
        message: String,
    },
    /// A method failed on the oscillator at one `hω`.
    #[error("{method} at hω = {h_omega}: {message}")]
    Amplification {
        /// The integrator's name.
        method: &'static str,
        /// `hω`.
        h_omega: f64,
        /// The integration's failure.
        message: String,
    },
    /// The stiff model lacks a parameter of [`StiffSpring`].
    #[error("the stiff model `{model}` has no parameter `{name}` (its {role})")]
    MissingParameter {
        /// The model's name.
        model: String,
        /// The parameter.
        name: String,
        /// What it was to be (`first mass`, `spring stiffness`, …).
        role: &'static str,
    },
    /// The stiff model lacks the coordinate [`StiffSpring::stretched`].
    #[error("the stiff model `{model}` has no coordinate `{name}` (its stretched coordinate)")]
    MissingCoordinate {
        /// The model's name.
        model: String,
        /// The coordinate.
        name: String,
    },
    /// Setting `k` failed.
    #[error(transparent)]
    UnknownParameter(#[from] UnknownParameter),
    /// The DOP853 reference of a stiff run failed.
    #[error("the DOP853 reference at k/m = {k_over_m:e} from {start} failed: {message}")]
    Reference {
        /// `k/m` (1/s²).
        k_over_m: f64,
        /// `equilibrium` or `rest`.
        start: &'static str,
        /// The integration's failure.
        message: String,
    },
}

impl StabilityOptions {
    /// Checks the options in the order of the fields.
    ///
    /// # Errors
    /// The first of [`StabilityError::InvalidSteps`], [`StabilityError::InvalidPeriods`],
    /// [`StabilityError::InvalidStiffness`], [`StabilityError::InvalidEndTime`],
    /// [`StabilityError::InvalidTolerance`].
    pub fn validate(&self) -> Result<(), StabilityError> {
        if !(100..=1_000_000).contains(&self.steps) {
            return Err(StabilityError::InvalidSteps { steps: self.steps });
        }
        if !(1..=100_000).contains(&self.periods) {
            return Err(StabilityError::InvalidPeriods {
                periods: self.periods,
            });
        }
        if self.stiffness.is_empty()
            || self
                .stiffness
                .iter()
                .any(|k| !(k.is_finite() && *k > 0.0 && *k <= 1e10))
        {
            return Err(StabilityError::InvalidStiffness);
        }
        if !(self.t_end.is_finite() && (1e-6..=100.0).contains(&self.t_end)) {
            return Err(StabilityError::InvalidEndTime { t_end: self.t_end });
        }
        if !(self.tol.is_finite() && self.tol >= 1e-13 && self.tol < 1.0) {
            return Err(StabilityError::InvalidTolerance { tol: self.tol });
        }
        Ok(())
    }
}

/// Where an integration stopped early: the error as reported, its time, and the time of the
/// last sample recorded before it.
#[derive(Debug, Serialize)]
pub struct Failure {
    /// The error as the integration reports it.
    pub error: String,
    /// The time the integration stopped at, if known.
    pub t: Option<f64>,
    /// The time of the last sample recorded before it.
    pub last_sample_t: Option<f64>,
}

impl Failure {
    pub(super) fn of(failure: &IntegrationFailure) -> Self {
        Self {
            error: failure.error.to_string(),
            t: failure.error.t(),
            last_sample_t: failure.partial.last().map(|(t, _)| t),
        }
    }
}
