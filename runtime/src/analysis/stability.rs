//! Where each integration method fails (issue 6; syllabus lecture 4, HW9), measured by
//! running it, against the theory of its stability function:
//!
//! a. Stability limits on `ẍ = −ω²x` (`hω`) and `ẋ = −λx` (`hλ`), measured by bisection on
//!    constant-step runs, against the intervals of `R(z) = 1 + z bᵀ(I − zA)⁻¹𝟙`; per-step
//!    amplification where the interval is empty (explicit Euler and midpoint) and for the
//!    A-stable implicit methods at large `hω`.
//! b. Energy of explicit Euler, RK4 and Störmer–Verlet over many periods of the oscillator.
//! c. The stiff two-mass spring (HW9's `two_masses` with large `k/m`): steps of explicit and
//!    implicit methods at one tolerance, against a tight DOP853 reference.
//! d. A step-size underflow (`ẏ = y²` blows up at `t = 1`), reported as the integration
//!    reports it.
//!
//! References: E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed.,
//! Springer, 1996, §IV.2 (stability functions, A-stability); E. Hairer, C. Lubich,
//! G. Wanner, *Geometric Numerical Integration*, 2nd ed., Springer, 2006, §I.1 and §IX.8
//! (Störmer–Verlet's modified energy).

use std::f64::consts::PI;

use nalgebra::Complex;
use serde::Serialize;

use crate::UnknownParameter;
use crate::integrate::stability_function::{
    GrowthTest, StabilityPolynomial, TestEquation, amplification, explicit_tableau_methods,
    implicit_midpoint_stability, measured_limit, partitioned_oscillator_growth_limit,
    partitioned_oscillator_spectral_radius, radau_iia5_stability,
};
use crate::integrate::{
    BogackiShampine32, DormandPrince54, DormandPrince853, ExplicitEuler, ImplicitMidpoint,
    IntegrationFailure, Integrator, IntegratorOptions, OutputTimes, RadauIIA5, RungeKutta4,
    Solution, StormerVerlet, SymplecticEuler, Tableau, verner_methods,
};
use crate::model_info::ModelInfo;
use crate::ode::OdeFn;

/// Options of [`stability_study`].
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

/// Everything [`stability_study`] measured (the parts a–d of the module docs).
#[derive(Serialize)]
pub struct StabilityStudy {
    /// The bisection's growth test (part a).
    #[serde(skip)]
    pub test: GrowthTest,
    /// Part a.
    pub limits: Limits,
    /// Part b: one row per run.
    pub energy: Vec<EnergyRow>,
    /// Part c: the stiff mode at every `k/m` and start.
    pub stiff_modes: Vec<StiffMode>,
    /// Part c: every method at every `k/m` and start.
    pub stiff: Vec<StiffRow>,
    /// Part d.
    pub underflow: UnderflowRun,
}

impl StabilityStudy {
    /// The study as `eomgen study stability --json` prints it ([`StabilitySummary`]);
    /// `stiff_model` is the two-mass spring of part c and `options` those the study ran with.
    pub fn summary<'a>(
        &'a self,
        stiff_model: &dyn ModelInfo,
        options: &StabilityOptions,
    ) -> StabilitySummary<'a> {
        StabilitySummary {
            limits: LimitsSummary {
                growth_threshold: GROWTH_THRESHOLD,
                steps: options.steps,
                smallest_detected_growth: self.test.smallest_detected_growth(),
                bisection_tolerance: BISECTION_TOLERANCE,
                rows: &self.limits.rows,
                amplification: &self.limits.amplification,
                polynomials: &self.limits.polynomials,
            },
            energy: EnergySummary {
                periods: options.periods,
                runs: &self.energy,
            },
            stiff: StiffSummary {
                model: stiff_model.description().name.to_string(),
                t_end: options.t_end,
                tol: options.tol,
                reference: StiffReferenceSummary {
                    method: "dop853",
                    tol: STIFF_REFERENCE_TOL,
                },
                modes: &self.stiff_modes,
                runs: &self.stiff,
            },
            underflow: &self.underflow,
        }
    }
}

/// A [`StabilityStudy`] as `eomgen study stability --json` prints it
/// ([`StabilityStudy::summary`]): each part with the settings it ran with.
#[derive(Debug, Serialize)]
pub struct StabilitySummary<'a> {
    /// Part a.
    pub limits: LimitsSummary<'a>,
    /// Part b.
    pub energy: EnergySummary<'a>,
    /// Part c.
    pub stiff: StiffSummary<'a>,
    /// Part d.
    pub underflow: &'a UnderflowRun,
}

/// Part a of a [`StabilitySummary`]: the bisection's settings and the limits found.
#[derive(Debug, Serialize)]
pub struct LimitsSummary<'a> {
    /// [`GROWTH_THRESHOLD`].
    pub growth_threshold: f64,
    /// Steps of each growth test.
    pub steps: usize,
    /// [`GrowthTest::smallest_detected_growth`].
    pub smallest_detected_growth: f64,
    /// [`BISECTION_TOLERANCE`].
    pub bisection_tolerance: f64,
    /// [`Limits::rows`].
    pub rows: &'a [LimitRow],
    /// [`Limits::amplification`].
    pub amplification: &'a [AmplificationRow],
    /// [`Limits::polynomials`].
    pub polynomials: &'a [PolynomialRow],
}

/// Part b of a [`StabilitySummary`].
#[derive(Debug, Serialize)]
pub struct EnergySummary<'a> {
    /// Periods integrated.
    pub periods: usize,
    /// One row per run.
    pub runs: &'a [EnergyRow],
}

/// Part c of a [`StabilitySummary`].
#[derive(Debug, Serialize)]
pub struct StiffSummary<'a> {
    /// The two-mass spring's name.
    pub model: String,
    /// The end time (s).
    pub t_end: f64,
    /// The adaptive methods' tolerance.
    pub tol: f64,
    /// The reference solution.
    pub reference: StiffReferenceSummary,
    /// The stiff mode at every `k/m` and start.
    pub modes: &'a [StiffMode],
    /// Every method at every `k/m` and start.
    pub runs: &'a [StiffRow],
}

/// The reference of part c: DOP853 at [`STIFF_REFERENCE_TOL`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StiffReferenceSummary {
    /// `"dop853"`.
    pub method: &'static str,
    /// Its tolerance.
    pub tol: f64,
}

// Not a `StudyRuns` report: the rule that a study whose every run failed measured nothing
// cannot apply here. Part a always measures: its methods are a fixed list, run on test
// equations the options do not reach (only the number of steps), and a failure there fails
// the whole study (`StabilityError::TestEquation`, …) rather than a row, so every report
// holds the limits. Parts b and c record a failed run in its row (`failure`), which the
// tables print as `failed` with its reason; part d demonstrates a failure.

/// Runs the stability study (see the module docs); `stiff_model` is a two-mass spring (HW9's)
/// with the names of [`StabilityOptions::stiff_spring`], whose stiffness is set to each
/// `k/m · m₁` of part c.
///
/// # Errors
/// The errors of [`StabilityOptions::validate`]; [`StabilityError::PolynomialStep`],
/// [`StabilityError::TestEquation`] and [`StabilityError::Amplification`] when a method fails
/// on the test equations; [`StabilityError::MissingParameter`],
/// [`StabilityError::MissingCoordinate`] or [`StabilityError::UnknownParameter`] for a
/// stiff model without those names; [`StabilityError::Reference`] when a stiff
/// reference fails.
///
/// # Examples
/// ```
/// use eomgen::analysis::{StabilityOptions, stability_study};
///
/// let mut two_masses = (eomgen::models::find("two_masses").unwrap().make)();
/// let options = StabilityOptions { steps: 200, periods: 2, stiffness: vec![1e2], ..Default::default() };
/// let study = stability_study(two_masses.as_mut(), &options)?;
/// let rk4 = study.limits.rows.iter().find(|r| r.method == "rk4" && r.axis == "imaginary").unwrap();
/// assert!((rk4.theory - 2.0 * 2f64.sqrt()).abs() < 1e-9); // |R(iy)| = 1 at y = 2√2
/// # Ok::<(), eomgen::analysis::StabilityError>(())
/// ```
pub fn stability_study(
    stiff_model: &mut dyn ModelInfo,
    options: &StabilityOptions,
) -> Result<StabilityStudy, StabilityError> {
    options.validate()?;
    let test = GrowthTest {
        steps: options.steps,
        threshold: GROWTH_THRESHOLD,
    };
    let limits = stability_limits(&test)?;
    let energy = energy_runs(options.periods);
    let (stiff_modes, stiff) = stiff_runs(stiff_model, options)?;
    let underflow = underflow_run(options.tol);
    Ok(StabilityStudy {
        test,
        limits,
        energy,
        stiff_modes,
        stiff,
        underflow,
    })
}

/// Growth of `‖y‖` that counts as unstable in the bisection: far above the bounded transient
/// of a stable non-normal step (symplectic Euler: `1/√(1 − hω/2)`, 100 at 10⁻⁴ below its
/// limit).
pub const GROWTH_THRESHOLD: f64 = 1e4;
/// Relative width of the final bisection bracket.
pub const BISECTION_TOLERANCE: f64 = 1e-6;
/// `hω` at which the per-step amplification of the methods with an empty imaginary interval
/// is measured.
pub const EMPTY_INTERVAL_STEPS: [f64; 4] = [0.1, 0.5, 1.0, 2.0];
/// Multiples of the imaginary limit at which a method too weakly unstable beyond it for the
/// bisection's `N` (Dormand–Prince 5(4)) is shown by its amplification.
pub const WEAK_INSTABILITY_FACTORS: [f64; 4] = [1.01, 1.2, 1.5, 2.0];
/// `hω` at which the A-stable methods are run.
pub const A_STABLE_STEPS: [f64; 3] = [10.0, 100.0, 1000.0];
/// Steps of each amplification run (`N` in `(‖y_N‖/‖y₀‖)^(1/N)`): few enough that Radau
/// IIA's amplitude (`≈ (3/hω)ᴺ`) stays above the `atol` of 1e-14 of its Newton iterations.
pub const AMPLIFICATION_STEPS: usize = 3;
/// Steps of the long run that shows the A-stable methods stable.
pub const LONG_RUN_STEPS: usize = 1000;
/// Steps per period in the energy study.
pub const STEPS_PER_PERIOD: usize = 32;
/// Number of output times of the stiff runs (uniform in `(0, t_end]`).
pub const STIFF_OUTPUT_TIMES: usize = 100;
/// Tolerance of the DOP853 reference of the stiff runs.
pub const STIFF_REFERENCE_TOL: f64 = 1e-12;

/// A stability interval, measured and in theory (part a).
#[derive(Debug, Serialize)]
pub struct LimitRow {
    /// The integrator's name.
    pub method: &'static str,
    /// `"imaginary"` (`hω` on `ẍ = −ω²x`) or `"real"` (`hλ` on `ẋ = −λx`).
    pub axis: &'static str,
    /// The value the stability function predicts.
    pub theory: f64,
    /// The measured value.
    pub measured: Option<f64>,
    /// `(measured − theory)/theory`.
    pub relative_difference: Option<f64>,
    /// The limit a run of `steps_used` steps can see: the first `h` where the per-step growth
    /// exceeds the smallest detected one (theory, for this `N`).
    pub theory_at_detection: f64,
    /// `(measured − theory_at_detection)/theory_at_detection`.
    pub relative_difference_at_detection: Option<f64>,
    /// Per-step growth `|R| − 1` one percent above the theoretical limit.
    pub growth_one_percent_above: f64,
    /// Steps needed to see that growth exceed the threshold.
    pub steps_needed_one_percent_above: usize,
    /// Steps `N` of each bisection run.
    pub steps_used: usize,
}

/// A measured per-step amplification against `|R(ihω)|` (part a).
#[derive(Debug, Serialize)]
pub struct AmplificationRow {
    /// The integrator's name.
    pub method: &'static str,
    /// `hω`.
    pub h_omega: f64,
    /// Steps.
    pub steps: usize,
    /// The measured value.
    pub measured: f64,
    /// The value the stability function predicts.
    pub theory: f64,
    /// `(measured − theory)/theory`.
    pub relative_difference: f64,
    /// `‖y‖` after 1000 steps, from 1 (A-stable methods only).
    pub norm_after_long_run: Option<f64>,
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
    fn of(failure: &IntegrationFailure) -> Self {
        Self {
            error: failure.error.to_string(),
            t: failure.error.t(),
            last_sample_t: failure.partial.last().map(|(t, _)| t),
        }
    }
}

/// The energy of one run over many periods (part b).
#[derive(Debug, Serialize)]
pub struct EnergyRow {
    /// The integrator's name.
    pub method: &'static str,
    /// The constant step (s; the oscillator's period is 2π).
    pub h: f64,
    /// Steps per period `2π/h`.
    pub steps_per_period: usize,
    /// Periods reached (fewer than asked if the run failed).
    pub periods_reached: f64,
    /// `E/E₀` at the last sample (`None` if it overflows a double).
    pub final_energy_ratio: Option<f64>,
    /// `log₁₀(E/E₀)` at the last sample.
    pub log10_final_energy_ratio: f64,
    /// `log₁₀(E/E₀)` the stability function predicts there: `2n log₁₀|R(ih)|` after `n`
    /// steps (Runge–Kutta methods).
    pub theory_log10_final_energy_ratio: Option<f64>,
    /// Largest `|E/E₀ − 1|` over the samples (`None` if it overflows).
    pub max_energy_error: Option<f64>,
    /// The modified-energy bound on it (Störmer–Verlet: `(h²/4)/(1 − h²/4)`).
    pub theory_max_energy_error: Option<f64>,
    /// Why the run stopped early, if it did.
    pub failure: Option<Failure>,
    /// `(t/T, E/E₀)` for the chart (not serialised).
    #[serde(skip)]
    pub history: Vec<(f64, f64)>,
}

/// One method on the stiff spring at one `k/m` (part c).
#[derive(Debug, Serialize)]
pub struct StiffRow {
    /// The stiffness ratio `k/m` (1/s²).
    pub k_over_m: f64,
    /// `"equilibrium"` (spring pre-stretched by the step force's static share: the stiff
    /// mode is not excited) or `"rest"` (the model's initial state, spring at rest length).
    pub start: &'static str,
    /// The integrator's name.
    pub method: &'static str,
    /// Steps.
    pub steps: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// RHS evaluations.
    pub rhs_evals: usize,
    /// Jacobian evaluations.
    pub jacobian_evals: usize,
    /// LU factorisations.
    pub lu_decompositions: usize,
    /// Largest position error (m) at the output times against the reference.
    pub position_error: Option<f64>,
    /// Largest velocity error (m/s) at the output times against the reference.
    pub velocity_error: Option<f64>,
    /// Why the run stopped early, if it did.
    pub failure: Option<Failure>,
}

/// The stiff mode at one `k/m` (part c).
#[derive(Debug, Serialize)]
pub struct StiffMode {
    /// The stiffness ratio `k/m` (1/s²).
    pub k_over_m: f64,
    /// `equilibrium` or `rest` (see [`StiffRow::start`]).
    pub start: &'static str,
    /// Its angular frequency `ω = √(k (m₁ + m₂)/(m₁ m₂))` (rad/s).
    pub omega: f64,
    /// Largest amplitude of a mass's oscillation about the slow motion (m): from rest with
    /// the spring at rest length, the static stretch `F₀ m₁/(k (m₁ + m₂))` times
    /// `max(m₁, m₂)/(m₁ + m₂)`; 0 from the equilibrium start.
    pub position_amplitude: f64,
    /// Its velocity amplitude `ω ·` that (m/s).
    pub velocity_amplitude: f64,
    /// Steps of the DOP853 reference.
    pub reference_steps: usize,
}

/// The runs of part d.
#[derive(Debug, Serialize)]
pub struct UnderflowRun {
    /// The problem, in words.
    pub problem: &'static str,
    /// The integrator's name.
    pub method: &'static str,
    /// End time (s).
    pub t_end: f64,
    /// Relative and absolute tolerance.
    pub tol: f64,
    /// Why the run stopped early, if it did.
    pub failure: Option<Failure>,
}

/// A stability function `R(z)`.
type StabilityFunction = fn(Complex<f64>) -> Complex<f64>;

/// An explicit method with its stability polynomial.
pub struct ExplicitMethod {
    /// The integrator's name.
    pub name: &'static str,
    /// The integrator.
    pub method: Box<dyn Integrator>,
    /// Its stability polynomial `R(z)`.
    pub polynomial: StabilityPolynomial,
    /// Largest difference between the coefficients from the tableau and those read off one
    /// step of the implementation (`None` for DOP853, whose polynomial is the latter).
    pub implementation_difference: Option<f64>,
}

/// The explicit methods, their polynomials from their tableaus (DOP853's from one step of it,
/// its tableau being private), each checked against one step of its implementation; Verner's
/// pairs follow DOP853.
fn explicit_methods() -> Result<Vec<ExplicitMethod>, StabilityError> {
    let failed = |e: IntegrationFailure| StabilityError::PolynomialStep {
        message: e.to_string(),
    };
    let mut methods = Vec::new();
    for (tableau, mut method) in explicit_tableau_methods() {
        let polynomial = StabilityPolynomial::of_tableau(&tableau);
        let stepped = StabilityPolynomial::of_method(method.as_mut(), tableau.num_stages())
            .map_err(failed)?;
        let difference = polynomial
            .coefficients()
            .iter()
            .zip(stepped.coefficients())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        methods.push(ExplicitMethod {
            name: method.name(),
            method,
            polynomial,
            implementation_difference: Some(difference),
        });
    }
    let mut dop853: Box<dyn Integrator> = Box::new(DormandPrince853::new());
    let polynomial = StabilityPolynomial::of_method(dop853.as_mut(), 12).map_err(failed)?;
    methods.push(ExplicitMethod {
        name: dop853.name(),
        method: dop853,
        polynomial,
        implementation_difference: None,
    });
    // Verner's pairs: the polynomial of each tableau, checked like the public tableaus'.
    for (polynomial, stages, mut method) in verner_methods() {
        let stepped = StabilityPolynomial::of_method(method.as_mut(), stages).map_err(failed)?;
        let difference = polynomial
            .coefficients()
            .iter()
            .zip(stepped.coefficients())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        methods.push(ExplicitMethod {
            name: method.name(),
            method,
            polynomial,
            implementation_difference: Some(difference),
        });
    }
    Ok(methods)
}

/// Everything part a measures.
#[derive(Serialize)]
pub struct Limits {
    /// The explicit methods with their stability polynomials.
    #[serde(skip)]
    pub explicit: Vec<ExplicitMethod>,
    /// The measured stability intervals against theory.
    pub rows: Vec<LimitRow>,
    /// The measured per-step amplifications against `|R(ihω)|`.
    pub amplification: Vec<AmplificationRow>,
    /// The explicit methods' polynomials (one entry per [`Limits::explicit`]).
    pub polynomials: Vec<PolynomialRow>,
}

/// An explicit method's stability polynomial `R(z) = Σ cₖ zᵏ`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PolynomialRow {
    /// The integrator's name.
    pub method: &'static str,
    /// The coefficients `c₀, c₁, …`.
    pub coefficients: Vec<f64>,
    /// The order `p` the coefficients match `e^z` to.
    pub order: usize,
    /// Largest difference between the coefficients from the tableau and those read off one
    /// step of the implementation (`None` for DOP853).
    pub implementation_difference: Option<f64>,
}

impl ExplicitMethod {
    /// The per-step amplification on `ẍ = −ω²x` measured over 10 steps at each `hω` of
    /// `h_omegas` (the points where the run fails are left out): `(hω, amplification)`.
    pub fn measured_amplifications(&mut self, h_omegas: &[f64]) -> Vec<(f64, f64)> {
        h_omegas
            .iter()
            .filter_map(|&h| {
                amplification(self.method.as_mut(), TestEquation::Oscillator, h, 10)
                    .ok()
                    .map(|a| (h, a))
            })
            .collect()
    }
}

/// The theoretical limits of one method on one axis: strict (`|R| ≤ 1`), at the test's
/// detection threshold, and the per-step growth one percent above the strict limit.
struct Theory {
    limit: f64,
    at_detection: f64,
    growth_one_percent_above: f64,
}

fn limit_row(
    method: &mut dyn Integrator,
    axis: &'static str,
    theory: Theory,
    test: &GrowthTest,
) -> Result<LimitRow, StabilityError> {
    let Theory {
        limit: theory,
        at_detection,
        growth_one_percent_above: growth,
    } = theory;
    let equation = if axis == "real" {
        TestEquation::Decay
    } else {
        TestEquation::Oscillator
    };
    let measured = measured_limit(method, equation, test, BISECTION_TOLERANCE).map_err(|e| {
        StabilityError::TestEquation {
            method: method.name(),
            message: e.to_string(),
        }
    })?;
    Ok(LimitRow {
        method: method.name(),
        axis,
        theory,
        measured,
        relative_difference: measured.map(|m| (m - theory) / theory),
        theory_at_detection: at_detection,
        relative_difference_at_detection: measured.map(|m| (m - at_detection) / at_detection),
        growth_one_percent_above: growth,
        steps_needed_one_percent_above: test.steps_to_detect(growth),
        steps_used: test.steps,
    })
}

fn amplification_row(
    method: &mut dyn Integrator,
    h_omega: f64,
    theory: f64,
    long_run: bool,
) -> Result<AmplificationRow, StabilityError> {
    let name = method.name();
    let failed = |e: IntegrationFailure| StabilityError::Amplification {
        method: name,
        h_omega,
        message: e.to_string(),
    };
    let measured = amplification(
        method,
        TestEquation::Oscillator,
        h_omega,
        AMPLIFICATION_STEPS,
    )
    .map_err(failed)?;
    let norm_after_long_run = if long_run {
        Some(
            TestEquation::Oscillator
                .final_norm(method, h_omega, LONG_RUN_STEPS)
                .map_err(failed)?,
        )
    } else {
        None
    };
    Ok(AmplificationRow {
        norm_after_long_run,
        method: name,
        h_omega,
        steps: AMPLIFICATION_STEPS,
        measured,
        theory,
        relative_difference: (measured - theory) / theory,
    })
}

fn stability_limits(test: &GrowthTest) -> Result<Limits, StabilityError> {
    let mut explicit = explicit_methods()?;
    let mut rows = Vec::new();
    let mut amplification = Vec::new();
    let detected = test.smallest_detected_growth();
    for m in &mut explicit {
        let r = &m.polynomial;
        let imaginary = r.imaginary_axis_limit();
        if imaginary == 0.0 {
            for h in EMPTY_INTERVAL_STEPS {
                let theory = r.eval(Complex::new(0.0, h)).norm();
                amplification.push(amplification_row(m.method.as_mut(), h, theory, false)?);
            }
        } else {
            let growth = r.eval(Complex::new(0.0, 1.01 * imaginary)).norm() - 1.0;
            let theory = Theory {
                limit: imaginary,
                at_detection: r.imaginary_axis_growth_limit(detected),
                growth_one_percent_above: growth,
            };
            rows.push(limit_row(m.method.as_mut(), "imaginary", theory, test)?);
            if test.steps_to_detect(growth) > test.steps {
                // Too weakly unstable just beyond the limit for N steps to see: show the
                // growth there directly.
                for factor in WEAK_INSTABILITY_FACTORS {
                    let h = factor * imaginary;
                    let theory = r.eval(Complex::new(0.0, h)).norm();
                    amplification.push(amplification_row(m.method.as_mut(), h, theory, false)?);
                }
            }
        }
        let real = r.real_axis_limit();
        let theory = Theory {
            limit: real,
            at_detection: r.real_axis_growth_limit(detected),
            growth_one_percent_above: r.eval_real(-1.01 * real).abs() - 1.0,
        };
        rows.push(limit_row(m.method.as_mut(), "real", theory, test)?);
    }
    let partitioned: [Box<dyn Integrator>; 2] = [
        Box::new(SymplecticEuler::new()),
        Box::new(StormerVerlet::new()),
    ];
    for mut method in partitioned {
        let theory = Theory {
            limit: 2.0,
            at_detection: partitioned_oscillator_growth_limit(detected),
            growth_one_percent_above: partitioned_oscillator_spectral_radius(2.02) - 1.0,
        };
        rows.push(limit_row(method.as_mut(), "imaginary", theory, test)?);
    }
    let implicit: [(Box<dyn Integrator>, StabilityFunction); 2] = [
        // Its default Newton tolerance (1e-12 relative) is below the rounding of h·F at
        // h = 1000 (about 1000 ε), where Newton would report non-convergence.
        (
            Box::new(ImplicitMidpoint::new().with_newton_tolerance(1e-10)),
            implicit_midpoint_stability,
        ),
        (Box::new(RadauIIA5::new()), radau_iia5_stability),
    ];
    for (mut method, stability) in implicit {
        for h in A_STABLE_STEPS {
            let theory = stability(Complex::new(0.0, h)).norm();
            amplification.push(amplification_row(method.as_mut(), h, theory, true)?);
        }
    }
    let polynomials = explicit
        .iter()
        .map(|m| PolynomialRow {
            method: m.name,
            coefficients: m.polynomial.coefficients().to_vec(),
            order: m.polynomial.order(),
            implementation_difference: m.implementation_difference,
        })
        .collect();
    Ok(Limits {
        explicit,
        rows,
        amplification,
        polynomials,
    })
}

/// `E/E₀ = x² + ẋ²` of the oscillator `ẍ = −x` started at `(1, 0)`.
fn energy_ratio(y: &[f64]) -> f64 {
    y[0] * y[0] + y[1] * y[1]
}

fn energy_runs(periods: usize) -> Vec<EnergyRow> {
    let period = 2.0 * PI;
    let t_end = periods as f64 * period;
    // Explicit Euler a hundred times finer too, since with h = T/32 it overflows.
    let fine = 100 * STEPS_PER_PERIOD;
    let runs: [(Box<dyn Integrator>, usize); 4] = [
        (Box::new(ExplicitEuler::new()), STEPS_PER_PERIOD),
        (Box::new(ExplicitEuler::new()), fine),
        (Box::new(RungeKutta4::new()), STEPS_PER_PERIOD),
        (Box::new(StormerVerlet::new()), STEPS_PER_PERIOD),
    ];
    let rk4 = StabilityPolynomial::of_tableau(&Tableau::rk4());
    let euler = StabilityPolynomial::of_tableau(&Tableau::euler());
    runs.into_iter()
        .map(|(mut method, steps_per_period)| {
            let h_run = period / steps_per_period as f64;
            let options = IntegratorOptions::default()
                .with_dt(h_run)
                .with_max_steps(periods * steps_per_period + 10);
            // Every step of the coarse runs (the energy of Störmer–Verlet oscillates within a
            // period); once per period for the fine run (3.2 · 10⁷ steps).
            let output = if steps_per_period == STEPS_PER_PERIOD {
                OutputTimes::Steps
            } else {
                OutputTimes::At((0..=periods).map(|k| k as f64 * period).collect())
            };
            let mut oscillator = OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
                dy[0] = y[1];
                dy[1] = -y[0];
            });
            let (solution, failure) =
                match method.integrate(&mut oscillator, 0.0, &[1.0, 0.0], t_end, &output, &options)
                {
                    Ok(s) => (s, None),
                    Err(f) => {
                        let failure = Failure::of(&f);
                        (*f.partial, Some(failure))
                    }
                };
            energy_row(method.name(), h_run, &solution, failure, &rk4, &euler)
        })
        .collect()
}

fn energy_row(
    method: &'static str,
    h: f64,
    solution: &Solution,
    failure: Option<Failure>,
    rk4: &StabilityPolynomial,
    euler: &StabilityPolynomial,
) -> EnergyRow {
    let period = 2.0 * PI;
    let steps_per_period = (period / h).round() as usize;
    let (t_last, y_last) = solution.last().unwrap_or((0.0, &[1.0, 0.0][..]));
    let steps_done = (t_last / h).round();
    let log_amplitude = |r: &StabilityPolynomial| r.eval(Complex::new(0.0, h)).norm().log10();
    let theory_log10_final_energy_ratio = match method {
        "euler" => Some(2.0 * steps_done * log_amplitude(euler)),
        "rk4" => Some(2.0 * steps_done * log_amplitude(rk4)),
        _ => None,
    };
    let theory_max_energy_error =
        (method == "stormer-verlet").then(|| (h * h / 4.0) / (1.0 - h * h / 4.0));
    let max_energy_error = solution
        .iter()
        .map(|(_, y)| (energy_ratio(y) - 1.0).abs())
        .fold(0.0, f64::max);
    let stride = if solution.len() > 1 && solution.t[1] < 0.99 * period {
        steps_per_period
    } else {
        1
    };
    // E/E₀ above 1e200 is left out of the chart (its axis padding would overflow).
    let history = solution
        .iter()
        .step_by(stride)
        .map(|(t, y)| (t / period, energy_ratio(y)))
        .filter(|(_, e)| *e <= 1e200)
        .collect();
    let final_energy_ratio = energy_ratio(y_last);
    EnergyRow {
        method,
        h,
        steps_per_period,
        periods_reached: t_last / period,
        final_energy_ratio: final_energy_ratio.is_finite().then_some(final_energy_ratio),
        log10_final_energy_ratio: 2.0 * y_last[0].hypot(y_last[1]).log10(),
        theory_log10_final_energy_ratio,
        max_energy_error: max_energy_error.is_finite().then_some(max_energy_error),
        theory_max_energy_error,
        failure,
        history,
    }
}

/// The stiff two-mass spring at every `k/m`: the mode's figures and every method's run.
fn stiff_runs(
    model: &mut dyn ModelInfo,
    args: &StabilityOptions,
) -> Result<(Vec<StiffMode>, Vec<StiffRow>), StabilityError> {
    let times: Vec<f64> = (1..=STIFF_OUTPUT_TIMES)
        .map(|i| args.t_end * i as f64 / STIFF_OUTPUT_TIMES as f64)
        .collect();
    let output = OutputTimes::At(times);
    let mut modes = Vec::new();
    let mut rows = Vec::new();
    for &ratio in &args.stiffness {
        let names = &args.stiff_spring;
        let parameter = |name: &str, role: &'static str| {
            model
                .description()
                .parameter_names()
                .iter()
                .position(|p| *p == name)
                .map(|i| model.parameter_values()[i])
                .ok_or_else(|| StabilityError::MissingParameter {
                    model: model.description().name.to_string(),
                    name: name.to_string(),
                    role,
                })
        };
        let m1 = parameter(&names.mass_1, "first mass")?;
        let m2 = parameter(&names.mass_2, "second mass")?;
        let force = parameter(&names.force, "force")?;
        parameter(&names.stiffness, "spring stiffness")?;
        model.set_parameter(&names.stiffness, ratio * m1)?;
        let k = ratio * m1;
        let omega = (k * (m1 + m2) / (m1 * m2)).sqrt();
        let static_stretch = force * m1 / (k * (m1 + m2));
        let x2 = model
            .description()
            .coordinate_names()
            .iter()
            .position(|c| *c == names.stretched)
            .ok_or_else(|| StabilityError::MissingCoordinate {
                model: model.description().name.to_string(),
                name: names.stretched.clone(),
            })?;
        for start in ["equilibrium", "rest"] {
            let mut y0 = model.initial_state();
            let position_amplitude = if start == "equilibrium" {
                y0[x2] += static_stretch;
                0.0
            } else {
                static_stretch * m1.max(m2) / (m1 + m2)
            };
            let run = |method: &mut dyn Integrator,
                       model: &mut dyn ModelInfo,
                       tol: f64|
             -> Result<Solution, IntegrationFailure> {
                let options = IntegratorOptions::default()
                    .with_rtol(tol)
                    .with_atol(tol)
                    .with_max_steps(20_000_000);
                method.integrate(model.as_ode_mut(), 0.0, &y0, args.t_end, &output, &options)
            };
            let reference = run(
                &mut DormandPrince853::new(),
                &mut *model,
                STIFF_REFERENCE_TOL,
            )
            .map_err(|e| StabilityError::Reference {
                k_over_m: ratio,
                start,
                message: e.to_string(),
            })?;
            modes.push(StiffMode {
                k_over_m: ratio,
                start,
                omega,
                position_amplitude,
                velocity_amplitude: omega * position_amplitude,
                reference_steps: reference.stats.steps,
            });
            let methods: [Box<dyn Integrator>; 4] = [
                Box::new(BogackiShampine32::new()),
                Box::new(DormandPrince54::new()),
                Box::new(DormandPrince853::new()),
                Box::new(RadauIIA5::new()),
            ];
            for mut method in methods {
                let (solution, failure) = match run(method.as_mut(), &mut *model, args.tol) {
                    Ok(s) => (s, None),
                    Err(f) => {
                        let failure = Failure::of(&f);
                        (*f.partial, Some(failure))
                    }
                };
                let error = |offset: usize| {
                    failure.is_none().then(|| {
                        solution
                            .iter()
                            .zip(reference.iter())
                            .flat_map(|((_, y), (_, r))| {
                                (offset..offset + 2).map(move |i| (y[i] - r[i]).abs())
                            })
                            .fold(0.0, f64::max)
                    })
                };
                rows.push(StiffRow {
                    k_over_m: ratio,
                    start,
                    method: method.name(),
                    steps: solution.stats.steps,
                    rejected: solution.stats.rejected,
                    rhs_evals: solution.stats.rhs_evals,
                    jacobian_evals: solution.stats.jacobian_evals,
                    lu_decompositions: solution.stats.lu_decompositions,
                    position_error: error(0),
                    velocity_error: error(2),
                    failure,
                });
            }
        }
    }
    Ok((modes, rows))
}

/// `ẏ = y²`, `y(0) = 1` (`y = 1/(1 − t)`, infinite at `t = 1`) asked for on `[0, 2]` with
/// Dormand–Prince 5(4): the step size must shrink to nothing at the singularity.
fn underflow_run(tol: f64) -> UnderflowRun {
    let mut blow_up = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = y[0] * y[0]);
    let options = IntegratorOptions::default().with_rtol(tol).with_atol(tol);
    let mut method = DormandPrince54::new();
    let result = method.integrate(
        &mut blow_up,
        0.0,
        &[1.0],
        2.0,
        &OutputTimes::Steps,
        &options,
    );
    UnderflowRun {
        problem: "y' = y², y(0) = 1 on [0, 2] (y = 1/(1 − t) blows up at t = 1)",
        method: method.name(),
        t_end: 2.0,
        tol,
        failure: result.err().as_ref().map(Failure::of),
    }
}
