//! Work–precision (issue 6): error against work for integration methods on a model.
//!
//! Every method runs at a sequence of tolerances (adaptive methods, `rtol = atol = tol`) or
//! step sizes `h = T/N` (fixed-step methods). Each run's state at `S` equally spaced output
//! times (dense output, [`OutputTimes::At`]) is compared with a reference solution computed
//! by DOP853 at a far tighter tolerance and accepted only if a second, different method
//! (Dormand–Prince 5(4)) at the same tolerance agrees with it far below the target error.
//!
//! The error of a run is
//!
//! ```text
//! error = max over k = 1…S, i = 1…2n of |yᵢ(t_k) − y_refᵢ(t_k)|,   t_k = k T / S,
//! ```
//!
//! the largest absolute deviation over the output times and over *all* state components,
//! the coordinates `q` and the rates `q̇` alike (each in its own unit: m or rad, m/s or
//! rad/s). Work is the RHS evaluations and steps of [`Stats`](crate::Stats), and the median
//! wall time of repeated identical runs (one short run is too noisy to time). The work
//! needed to reach a target error is interpolated log–log between the two settings whose
//! errors bracket it.
//!
//! References: E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations
//! I*, 2nd ed., Springer, 1993, §II.10 (work–precision diagrams of the kind drawn here);
//! the MuJoCo anchor of issue 6 (RK4 at `dt = 1e-3`: about 60 ms for 10 s of the double
//! pendulum at a state error of about 5e-4).
//!
//! The study's `Serialize` summaries, its run tally and its unresolved counts are in
//! `summary`.

use serde::Serialize;

use crate::analysis::drift::energy_drift;
use crate::analysis::methods::Method;
use crate::analysis::outcome::{RunTally, StudyRuns};
use crate::analysis::simulation::SimulationError;
use crate::integrate::{IntegrationFailure, Integrator, IntegratorOptions, OutputTimes, Solution};
use crate::model_info::ModelInfo;

mod summary;

pub use summary::{
    MethodRunsSummary, ReferenceSummary, RunSummary, TargetSummary, TimingSummary,
    WorkPrecisionSummary,
};

/// The methods compared by default: every adaptive method (the Taylor method's runs fail, each
/// with the reason, on a model without recurrences), and the fixed-step RK4 and
/// Störmer–Verlet.
pub const DEFAULT_METHODS: [Method; 11] = [
    Method::Bs32,
    Method::Dp54,
    Method::Dop853,
    Method::Vern6,
    Method::Vern7,
    Method::Vern8,
    Method::Vern9,
    Method::Taylor,
    Method::Radau5,
    Method::Rk4,
    Method::StormerVerlet,
];

/// Most step attempts of one adaptive run; far more than any default setting needs, small
/// enough that a method that cannot cope fails in seconds rather than minutes.
pub const MAX_STEPS: usize = 5_000_000;

/// Most timed repetitions of one setting, whatever the minimum time asks.
pub const MAX_REPEATS: usize = 1000;

/// The smallest tolerance a run may ask for: about 5 units of round-off of `f64`
/// (`ε = 2.2e-16`). Below it no step can meet the tolerance, and a run either collapses its
/// step or creeps to the step limit (`--tols 1e-30..1e-40` failed every run after minutes).
/// Hairer's DOP853 likewise refuses `rtol ≤ 10 · 1.1e-16` (Hairer, Nørsett, Wanner, *Solving
/// Ordinary Differential Equations I*, 2nd ed., 1993, the code's documentation of `RTOL`).
pub const SMALLEST_TOLERANCE: f64 = 1e-15;

/// Options of [`work_precision`].
///
/// # Solver limits
/// An adaptive run gives up after [`MAX_STEPS`] step attempts, a fixed-step run after its
/// step count (plus two); a run that fails is reported in its row, never an error of the
/// study. The reference gets [`MAX_STEPS`] too.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkPrecisionOptions {
    /// The methods compared, in order, each once (default: [`DEFAULT_METHODS`]).
    pub methods: Vec<Method>,
    /// Tolerances of the adaptive methods (`rtol = atol = tol`), loosest first, each in
    /// (0, 1) (default: the decades 1e-3 … 1e-12).
    pub tolerances: Vec<f64>,
    /// Step counts `N` of the fixed-step methods (step `h = t_end / N`), increasing (`None`:
    /// [`default_steps`] by the method's order).
    pub steps: Option<Vec<usize>>,
    /// End time `T` (s) (default: 10).
    pub t_end: f64,
    /// Number `S` of equally spaced output times `k T / S`, k = 1…S (default: 100).
    pub samples: usize,
    /// Error at which the work of every method is interpolated (default: 5e-4).
    pub target_error: f64,
    /// A wall time (ms) to compare the time at the target error with (default: none).
    pub baseline_ms: Option<f64>,
    /// Tolerance of the reference solution, in (0, 1e-6) (default: 1e-14).
    pub reference_tol: f64,
    /// Fewest timed runs per setting; the reported time is their median (default: 3).
    pub repeats: usize,
    /// Runs of one setting are repeated until their total wall time reaches this (s), at most
    /// [`MAX_REPEATS`] times (default: 0.02).
    pub min_time_s: f64,
}

impl WorkPrecisionOptions {
    /// The default end time (s).
    pub const DEFAULT_T_END: f64 = 10.0;
    /// The default number of output times at which errors are taken.
    pub const DEFAULT_SAMPLES: usize = 100;
    /// The default error at which the work of every method is interpolated.
    pub const DEFAULT_TARGET_ERROR: f64 = 5e-4;
    /// The default tolerance of the reference solution.
    pub const DEFAULT_REFERENCE_TOL: f64 = 1e-14;
    /// The default fewest timed runs per setting.
    pub const DEFAULT_REPEATS: usize = 3;
    /// The default total wall time (s) the runs of one setting reach.
    pub const DEFAULT_MIN_TIME_S: f64 = 0.02;
    /// The default tolerances, as `eomgen study work-precision --tols` writes a range: every
    /// decade from the first to the second ([`Self::default_tolerances`]).
    pub const DEFAULT_TOLERANCE_RANGE: (f64, f64) = (1e-3, 1e-12);

    /// Every decade of [`Self::DEFAULT_TOLERANCE_RANGE`], loosest first.
    pub fn default_tolerances() -> Vec<f64> {
        let (a, b) = Self::DEFAULT_TOLERANCE_RANGE;
        decades(a, b).unwrap_or_else(|| vec![a, b])
    }
}

impl Default for WorkPrecisionOptions {
    fn default() -> Self {
        Self {
            methods: DEFAULT_METHODS.to_vec(),
            tolerances: Self::default_tolerances(),
            steps: None,
            t_end: Self::DEFAULT_T_END,
            samples: Self::DEFAULT_SAMPLES,
            target_error: Self::DEFAULT_TARGET_ERROR,
            baseline_ms: None,
            reference_tol: Self::DEFAULT_REFERENCE_TOL,
            repeats: Self::DEFAULT_REPEATS,
            min_time_s: Self::DEFAULT_MIN_TIME_S,
        }
    }
}

/// Options of [`work_precision`] that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum WorkPrecisionError {
    /// `t_end` is not a finite positive number.
    #[error("the end time must be a positive number of seconds, got {t_end}")]
    InvalidEndTime {
        /// The end time (s).
        t_end: f64,
    },
    /// No output times.
    #[error("the number of output times must be at least 1")]
    NoSamples,
    /// The target error is not a finite positive number.
    #[error("the target error must be positive, got {target_error}")]
    InvalidTargetError {
        /// The target error.
        target_error: f64,
    },
    /// The reference tolerance is not in (0, 1e-6).
    #[error(
        "the reference tolerance must be in (0, 1e-6), far tighter than the tolerances studied, got {reference_tol}"
    )]
    InvalidReferenceTolerance {
        /// The reference tolerance.
        reference_tol: f64,
    },
    /// The baseline is not a finite positive time.
    #[error("the baseline must be a positive time (ms), got {baseline_ms}")]
    InvalidBaseline {
        /// The baseline (ms).
        baseline_ms: f64,
    },
    /// The minimum time is negative or not finite.
    #[error("the minimum time must be ≥ 0, got {min_time_s} s")]
    InvalidMinTime {
        /// The minimum time (s).
        min_time_s: f64,
    },
    /// A tolerance not in `[SMALLEST_TOLERANCE, 1)`.
    #[error("{tol} is not a tolerance in [1e-15, 1) (f64 cannot deliver less)")]
    InvalidTolerance {
        /// The tolerance.
        tol: f64,
    },
    /// A step count of 0.
    #[error("a step count must be positive")]
    InvalidStepCount,
    /// No consistent initial state.
    #[error(transparent)]
    InitialState(#[from] SimulationError),
    /// The reference (or its check) failed.
    #[error(
        "{role} ({} at rtol = atol = {rtol:e}) failed: {message}",
        method.display_name()
    )]
    ReferenceFailed {
        /// `the reference solution` or `the check of the reference`.
        role: &'static str,
        /// The method.
        method: Method,
        /// Its tolerance.
        rtol: f64,
        /// Why it failed.
        message: String,
    },
    /// The reference moves less than its own tolerance over `[0, t_end]`: every component
    /// stays within `tol (1 + |y₀ᵢ|)` of its start (an end time of `1e-320` s, or a state at
    /// rest at an equilibrium), so the reference cannot resolve any run's error, and every
    /// run would report about 0.
    #[error(
        "the reference solution moves less than its tolerance {reference_tol:e} over 0 ≤ t ≤ {t_end:e} s (every component within tol·(1 + |y₀|) of its start): there is no motion whose error could be measured; choose a longer --t-end or a state that moves"
    )]
    NoMotion {
        /// The end time (s).
        t_end: f64,
        /// The reference tolerance.
        reference_tol: f64,
    },
    /// The reference and its check disagree by more than a hundredth of the target error.
    #[error(
        "the reference is not verified: DOP853 and Dormand–Prince 5(4) at rtol = atol = {reference_tol:e} differ by {agreement:.3e}, not far below the target error {target_error:e} (need ≤ 1/100 of it)"
    )]
    ReferenceNotVerified {
        /// The reference tolerance.
        reference_tol: f64,
        /// The error norm between the two.
        agreement: f64,
        /// The target error.
        target_error: f64,
    },
}

impl WorkPrecisionOptions {
    /// Checks the scalar options, in this order: `t_end`, `samples`, `target_error`,
    /// `reference_tol`, `baseline_ms`, `min_time_s`; then the tolerances and step counts.
    ///
    /// # Errors
    /// The first [`WorkPrecisionError`] found.
    pub fn validate(&self) -> Result<(), WorkPrecisionError> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !positive(self.t_end) {
            return Err(WorkPrecisionError::InvalidEndTime { t_end: self.t_end });
        }
        if self.samples == 0 {
            return Err(WorkPrecisionError::NoSamples);
        }
        if !positive(self.target_error) {
            return Err(WorkPrecisionError::InvalidTargetError {
                target_error: self.target_error,
            });
        }
        if !(positive(self.reference_tol) && self.reference_tol < 1e-6) {
            return Err(WorkPrecisionError::InvalidReferenceTolerance {
                reference_tol: self.reference_tol,
            });
        }
        if let Some(b) = self.baseline_ms
            && !positive(b)
        {
            return Err(WorkPrecisionError::InvalidBaseline { baseline_ms: b });
        }
        if !(self.min_time_s.is_finite() && self.min_time_s >= 0.0) {
            return Err(WorkPrecisionError::InvalidMinTime {
                min_time_s: self.min_time_s,
            });
        }
        if let Some(&tol) = self
            .tolerances
            .iter()
            .find(|&&t| !(t.is_finite() && (SMALLEST_TOLERANCE..1.0).contains(&t)))
        {
            return Err(WorkPrecisionError::InvalidTolerance { tol });
        }
        if self.steps.as_ref().is_some_and(|s| s.contains(&0)) {
            return Err(WorkPrecisionError::InvalidStepCount);
        }
        Ok(())
    }
}

/// How one run is set up: a tolerance for an adaptive method, a step count for a fixed-step
/// one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum Setting {
    /// `rtol = atol = tol`.
    Tolerance(f64),
    /// `steps` constant steps `h = T / steps` (s).
    Steps {
        /// The number of steps `N`.
        steps: usize,
        /// The step `h = T / N` (s).
        dt: f64,
    },
}

impl Setting {
    /// The integrator options of this setting.
    pub fn options(self) -> IntegratorOptions {
        let options = IntegratorOptions::default();
        match self {
            Setting::Tolerance(tol) => options
                .with_rtol(tol)
                .with_atol(tol)
                .with_max_steps(MAX_STEPS),
            // Room for the requested steps and a rounding-shortened last one.
            Setting::Steps { steps, dt } => options.with_dt(dt).with_max_steps(steps + 2),
        }
    }

    /// `tol 1e-6` or `h 1.563e-2`, as tables name the setting.
    pub fn label(self) -> String {
        match self {
            Setting::Tolerance(tol) => format!("tol {tol:.0e}"),
            Setting::Steps { dt, .. } => format!("h {dt:.3e}"),
        }
    }
}

/// What one successful setting measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measured {
    /// The study's error norm against the reference (see the module docs).
    pub error: f64,
    /// RHS evaluations of one run.
    pub rhs_evals: usize,
    /// Accepted steps of one run.
    pub steps: usize,
    /// Rejected steps of one run.
    pub rejected: usize,
    /// Jacobians `∂F/∂y` of the implicit methods (0 for explicit ones).
    pub jacobian_evals: usize,
    /// LU factorisations of the implicit methods (0 for explicit ones).
    pub lu_decompositions: usize,
    /// Median wall time over `repeats` identical runs (s).
    pub wall_time_s: f64,
    /// The number of timed runs.
    pub repeats: usize,
    /// `max |E − E(0)| / max(T + |V|)` over the output times ([`energy_drift`]), if finite.
    pub energy_drift: Option<f64>,
}

/// A run that stopped: where and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunFailure {
    /// The time it stopped at (s), if known.
    pub t: Option<f64>,
    /// Why.
    pub message: String,
}

/// One setting of one method.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SettingRun {
    /// The setting.
    pub setting: Setting,
    /// What it measured, or why it failed.
    pub outcome: Result<Measured, RunFailure>,
}

/// The work interpolated at the target error, or why there is none.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum AtTarget {
    /// Two consecutive settings bracket the target: RHS evaluations, steps and time (s).
    Reached {
        /// RHS evaluations; `None` for a method that evaluates none (the Taylor method,
        /// which computes series of the motion), whose work is its steps and time.
        rhs_evals: Option<f64>,
        /// Steps.
        steps: f64,
        /// Wall time (s).
        wall_time_s: f64,
    },
    /// Already below the target at the loosest setting: at most this work.
    BelowAtLoosest {
        /// RHS evaluations of the loosest setting.
        rhs_evals: usize,
        /// Its wall time (s).
        wall_time_s: f64,
    },
    /// No pair of consecutive settings brackets the target.
    NotReached,
}

impl AtTarget {
    /// Why there is no interpolated work (empty when there is).
    pub fn note(&self) -> String {
        match *self {
            AtTarget::Reached { .. } => String::new(),
            AtTarget::BelowAtLoosest {
                rhs_evals,
                wall_time_s,
            } => {
                let evals = match rhs_evals {
                    0 => String::new(),
                    n => format!("≤ {n} RHS evals, "),
                };
                format!(
                    "below the target already at the loosest setting ({evals}≤ {:.3} ms): add looser settings",
                    wall_time_s * 1e3
                )
            }
            AtTarget::NotReached => {
                "not bracketed by two consecutive settings: add tighter settings or smaller steps"
                    .to_string()
            }
        }
    }
}

/// Every setting of one method, and its work at the target error.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodRuns {
    /// The method.
    pub method: Method,
    /// Its runs, loosest setting first.
    pub runs: Vec<SettingRun>,
    /// Its work at the target error.
    pub at_target: AtTarget,
}

/// The result of [`work_precision`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WorkPrecision {
    /// State dimension `2n`.
    pub dim: usize,
    /// The study's error norm between the reference and its check.
    pub agreement: f64,
    /// Accepted steps of the reference.
    pub reference_steps: usize,
    /// Fewest timed runs per setting (at least 1).
    pub min_repeats: usize,
    /// Total wall time (s) the runs of a setting reach.
    pub min_time_s: f64,
    /// One entry per method, in the options' order without repeats.
    pub results: Vec<MethodRuns>,
}

/// The decades from `a` to `b` (either order), loosest first: `1e-3, 1e-4, …, 1e-12` for
/// `(1e-3, 1e-12)`, each computed from its exponent so that the values are exact; `None`
/// when the ends are not a whole number of decades apart.
pub fn decades(a: f64, b: f64) -> Option<Vec<f64>> {
    let (hi, lo) = (a.max(b), a.min(b));
    let decades = (hi / lo).log10().round() as i32;
    if ((hi / lo).log10() - f64::from(decades)).abs() > 1e-9 {
        return None;
    }
    Some(
        (0..=decades)
            .map(|k| {
                let exponent = hi.log10() - f64::from(k);
                if (exponent - exponent.round()).abs() < 1e-9 {
                    10f64.powi(exponent.round() as i32)
                } else {
                    hi / 10f64.powi(k)
                }
            })
            .collect(),
    )
}

/// The default step counts of a fixed-step method of order `order`: doublings over ranges
/// chosen so that first- and second-order methods reach errors comparable to the
/// higher-order ones (their errors fall by only 2× or 4× per doubling): `1024 … 4194304`
/// for order 1, `256 … 4194304` for order 2, `64 … 65536` above.
pub fn default_steps(order: u32) -> Vec<usize> {
    let (lo, hi) = match order {
        0 | 1 => (10, 22),
        2 => (8, 22),
        _ => (6, 16),
    };
    (lo..=hi).map(|k| 1usize << k).collect()
}

/// The study's error norm: the largest `|yᵢ − y_refᵢ|` over every sample and component.
pub fn state_error(solution: &Solution, reference: &Solution) -> f64 {
    solution
        .y
        .iter()
        .zip(&reference.y)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// The median of `values` (sorted in place); NaN for none.
pub fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    let mid = values.len() / 2;
    if values.len() % 2 == 1 {
        values[mid]
    } else {
        0.5 * (values[mid - 1] + values[mid])
    }
}

/// Interpolates `log work` linearly in `log error` between the first two consecutive
/// `(error, work)` points (loosest first) whose errors bracket `target`; a point with a
/// non-positive or NaN entry breaks the bracketing.
pub fn interpolate(points: &[(f64, f64)], target: f64) -> Option<f64> {
    points.windows(2).find_map(|pair| {
        let [(e0, w0), (e1, w1)] = [pair[0], pair[1]];
        if !(e0 > 0.0 && e1 > 0.0 && w0 > 0.0 && w1 > 0.0) {
            return None;
        }
        let (lo, hi) = (e0.min(e1), e0.max(e1));
        if !(lo <= target && target <= hi) {
            return None;
        }
        if hi == lo {
            return Some(w0.min(w1));
        }
        let s = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
        Some((w0.ln() + s * (w1.ln() - w0.ln())).exp())
    })
}

/// A measure of work of a run: RHS evaluations, steps or wall time.
type Work = fn(&Measured) -> f64;

/// The work of `runs` (loosest first) at `target`; a failed run breaks the bracketing.
pub fn at_target(runs: &[SettingRun], target: f64) -> AtTarget {
    let measured: Vec<Option<&Measured>> = runs.iter().map(|r| r.outcome.as_ref().ok()).collect();
    if let Some(Some(first)) = measured.first()
        && first.error < target
    {
        return AtTarget::BelowAtLoosest {
            rhs_evals: first.rhs_evals,
            wall_time_s: first.wall_time_s,
        };
    }
    let series = |work: Work| -> Vec<(f64, f64)> {
        measured
            .iter()
            .map(|m| m.map_or((f64::NAN, f64::NAN), |m| (m.error, work(m))))
            .collect()
    };
    let evals = interpolate(&series(|m| m.rhs_evals as f64), target);
    let steps = interpolate(&series(|m| m.steps as f64), target);
    let time = interpolate(&series(|m| m.wall_time_s), target);
    // A method that evaluates no right-hand side has no evaluations to interpolate.
    let no_evals = measured.iter().flatten().all(|m| m.rhs_evals == 0);
    match (steps, time) {
        (Some(steps), Some(wall_time_s)) if evals.is_some() || no_evals => AtTarget::Reached {
            rhs_evals: evals,
            steps,
            wall_time_s,
        },
        _ => AtTarget::NotReached,
    }
}

/// Problem shared by every run: the model, its initial state, the interval and the output
/// times.
struct Problem<'a> {
    model: &'a mut dyn ModelInfo,
    y0: Vec<f64>,
    t_end: f64,
    times: OutputTimes,
}

impl Problem<'_> {
    /// Integrates the model once from `y0` over `[0, t_end]`, sampled at the output times.
    fn solve(
        &mut self,
        integrator: &mut dyn Integrator,
        options: &IntegratorOptions,
    ) -> Result<Solution, RunFailure> {
        integrator
            .integrate(
                self.model.as_ode_mut(),
                0.0,
                &self.y0,
                self.t_end,
                &self.times,
                options,
            )
            .map_err(|IntegrationFailure { error, .. }| RunFailure {
                t: error.t(),
                message: error.to_string(),
            })
    }

    /// Runs `method` at `setting`: the error against `reference` and the work of its first
    /// run, the median time of at least `repeats` repetitions totalling `min_time_s`.
    fn run(
        &mut self,
        method: Method,
        setting: Setting,
        (repeats, min_time_s): (usize, f64),
        reference: &Solution,
    ) -> SettingRun {
        let options = setting.options();
        let mut integrator = method.integrator();
        let first = self.solve(integrator.as_mut(), &options);
        let outcome = first.map(|solution| {
            let mut times = vec![solution.stats.wall_time_s];
            while times.len() < repeats.max(1)
                || (times.iter().sum::<f64>() < min_time_s && times.len() < MAX_REPEATS)
            {
                // The runs are identical (deterministic steps); only the clock differs.
                match self.solve(integrator.as_mut(), &options) {
                    Ok(again) => times.push(again.stats.wall_time_s),
                    Err(_) => break,
                }
            }
            let drift = energy_drift(self.model, &self.y0, &solution);
            Measured {
                error: state_error(&solution, reference),
                rhs_evals: solution.stats.rhs_evals,
                steps: solution.stats.steps,
                rejected: solution.stats.rejected,
                jacobian_evals: solution.stats.jacobian_evals,
                lu_decompositions: solution.stats.lu_decompositions,
                repeats: times.len(),
                wall_time_s: median(&mut times),
                energy_drift: drift.drift.filter(|d| d.is_finite()),
            }
        });
        SettingRun { setting, outcome }
    }
}

/// Runs the work–precision study on `model` from its consistent initial state (see the
/// module docs): the verified reference, then every method at every setting, and each
/// method's work at the target error. `progress(done, total)` is called after each run.
///
/// # Errors
/// The errors of [`WorkPrecisionOptions::validate`];
/// [`WorkPrecisionError::InitialState`] when the initial state cannot be made consistent;
/// [`WorkPrecisionError::ReferenceFailed`] and [`WorkPrecisionError::ReferenceNotVerified`]
/// when the reference cannot be computed or its check does not agree with it to a hundredth
/// of the target error; [`WorkPrecisionError::NoMotion`] when the reference moves less than
/// its tolerance. A method that fails at a setting is reported in its row; a study
/// whose every run failed measured nothing ([`StudyRuns::check_measured`]).
///
/// # Examples
/// RK4 at 64…256 steps over 2 s of the pendulum: the error falls about 16× per halving of
/// the step (order 4).
/// ```
/// use eomgen::analysis::{Method, WorkPrecisionOptions, work_precision};
///
/// let mut model = (eomgen::models::find("simple_pendulum").unwrap().make)();
/// let options = WorkPrecisionOptions {
///     methods: vec![Method::Rk4],
///     steps: Some(vec![64, 128, 256]),
///     t_end: 2.0,
///     repeats: 1,
///     min_time_s: 0.0,
///     ..WorkPrecisionOptions::default()
/// };
/// let study = work_precision(model.as_mut(), &options, &mut |_, _| {})?;
/// let errors: Vec<f64> = study.results[0].runs.iter()
///     .map(|r| r.outcome.as_ref().unwrap().error).collect();
/// for pair in errors.windows(2) {
///     let ratio = pair[0] / pair[1];
///     assert!(ratio > 12.0 && ratio < 20.0, "{ratio}");
/// }
/// # Ok::<(), eomgen::analysis::WorkPrecisionError>(())
/// ```
pub fn work_precision(
    model: &mut dyn ModelInfo,
    options: &WorkPrecisionOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<WorkPrecision, WorkPrecisionError> {
    options.validate()?;
    let mut methods: Vec<Method> = Vec::with_capacity(options.methods.len());
    for &m in &options.methods {
        if !methods.contains(&m) {
            methods.push(m);
        }
    }
    let mut y0 = model.initial_state();
    model
        .make_consistent(&mut y0)
        .map_err(|e| super::simulation::inconsistent(model, &e))?;
    let times = OutputTimes::At(
        (1..=options.samples)
            .map(|k| options.t_end * k as f64 / options.samples as f64)
            .collect(),
    );

    let mut problem = Problem {
        model,
        y0,
        t_end: options.t_end,
        times,
    };
    let (reference, agreement) = problem.verified_reference(options)?;

    let timing = (options.repeats.max(1), options.min_time_s);
    let plans = plans(&methods, options);
    let results = problem.run_plans(plans, timing, &reference, options.target_error, progress);
    Ok(WorkPrecision {
        dim: problem.y0.len(),
        agreement,
        reference_steps: reference.stats.steps,
        min_repeats: timing.0,
        min_time_s: timing.1,
        results,
    })
}

/// The settings each of `methods` runs at, in order: the tolerances for an adaptive method,
/// the step counts (given or [`default_steps`] of its order) for a fixed-step one.
fn plans(methods: &[Method], options: &WorkPrecisionOptions) -> Vec<(Method, Vec<Setting>)> {
    methods
        .iter()
        .map(|&method| {
            let settings: Vec<Setting> = if method.is_adaptive() {
                options
                    .tolerances
                    .iter()
                    .map(|&tol| Setting::Tolerance(tol))
                    .collect()
            } else {
                options
                    .steps
                    .clone()
                    .unwrap_or_else(|| default_steps(method.integrator().order()))
                    .into_iter()
                    .map(|steps| Setting::Steps {
                        steps,
                        dt: options.t_end / steps as f64,
                    })
                    .collect()
            };
            (method, settings)
        })
        .collect()
}

impl Problem<'_> {
    /// The reference solution and its agreement with its check ([`WorkPrecision::agreement`]).
    ///
    /// # Errors
    /// [`WorkPrecisionError::ReferenceFailed`], [`WorkPrecisionError::NoMotion`],
    /// [`WorkPrecisionError::ReferenceNotVerified`].
    fn verified_reference(
        &mut self,
        options: &WorkPrecisionOptions,
    ) -> Result<(Solution, f64), WorkPrecisionError> {
        // The reference, DOP853 at `reference_tol`, accepted only if Dormand–Prince 5(4) at the
        // same tolerance (another tableau, error estimator and dense output) agrees with it far
        // below the target error.
        let reference_options = IntegratorOptions::default()
            .with_rtol(options.reference_tol)
            .with_atol(options.reference_tol)
            .with_max_steps(MAX_STEPS);
        let mut solve = |method: Method, role: &'static str| {
            self.solve(method.integrator().as_mut(), &reference_options)
                .map_err(|f| WorkPrecisionError::ReferenceFailed {
                    role,
                    method,
                    rtol: options.reference_tol,
                    message: f.message,
                })
        };
        let reference = solve(Method::Dop853, "the reference solution")?;
        let check = solve(Method::Dp54, "the check of the reference")?;
        // The reference's own error is up to its tolerance per component (`atol + rtol |y|`):
        // a motion within it leaves no error to resolve.
        let tol = options.reference_tol;
        let moves = reference.iter().any(|(_, y)| {
            y.iter()
                .zip(&self.y0)
                .any(|(a, b)| (a - b).abs() > tol * (1.0 + b.abs()))
        });
        if !moves {
            return Err(WorkPrecisionError::NoMotion {
                t_end: options.t_end,
                reference_tol: tol,
            });
        }
        let agreement = state_error(&check, &reference);
        if agreement.is_nan() || agreement > options.target_error / 100.0 {
            return Err(WorkPrecisionError::ReferenceNotVerified {
                reference_tol: options.reference_tol,
                agreement,
                target_error: options.target_error,
            });
        }
        Ok((reference, agreement))
    }

    /// Every method's runs at its settings in `plans`, in order, and its work at
    /// `target_error`; `progress(done, total)` after each run.
    fn run_plans(
        &mut self,
        plans: Vec<(Method, Vec<Setting>)>,
        timing: (usize, f64),
        reference: &Solution,
        target_error: f64,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Vec<MethodRuns> {
        let total: usize = plans.iter().map(|(_, s)| s.len()).sum();
        let mut done = 0;
        plans
            .into_iter()
            .map(|(method, settings)| {
                let runs: Vec<SettingRun> = settings
                    .into_iter()
                    .map(|s| {
                        let run = self.run(method, s, timing, reference);
                        done += 1;
                        progress(done, total);
                        run
                    })
                    .collect();
                let at_target = at_target(&runs, target_error);
                MethodRuns {
                    method,
                    runs,
                    at_target,
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A study fails as a whole only when no run of any method measured anything.
    #[test]
    fn every_run_failed_only_when_no_run_measured() {
        let failed = SettingRun {
            setting: Setting::Tolerance(1e-6),
            outcome: Err(RunFailure {
                t: Some(0.5),
                message: "step size underflow".into(),
            }),
        };
        let measured = SettingRun {
            setting: Setting::Tolerance(1e-4),
            outcome: Ok(Measured {
                error: 1e-4,
                rhs_evals: 100,
                steps: 10,
                rejected: 0,
                jacobian_evals: 0,
                lu_decompositions: 0,
                wall_time_s: 1e-5,
                repeats: 1,
                energy_drift: None,
            }),
        };
        let study = |runs: Vec<Vec<SettingRun>>| WorkPrecision {
            dim: 2,
            agreement: 1e-13,
            reference_steps: 1000,
            min_repeats: 1,
            min_time_s: 0.0,
            results: runs
                .into_iter()
                .map(|runs| MethodRuns {
                    method: Method::Dp54,
                    runs,
                    at_target: AtTarget::NotReached,
                })
                .collect(),
        };
        let nothing = study(vec![
            vec![failed.clone()],
            vec![failed.clone(), failed.clone()],
        ])
        .check_measured()
        .unwrap_err();
        assert_eq!(nothing.failed, 3);
        assert_eq!(
            nothing.first_failure,
            "Dormand–Prince 5(4) at tol 1e-6: step size underflow"
        );
        assert!(
            study(vec![vec![failed.clone()], vec![failed, measured]])
                .check_measured()
                .is_ok()
        );
        assert!(study(vec![]).check_measured().is_err());
    }

    /// The Taylor method evaluates no right-hand side: its work at the target is its steps
    /// and time, with no evaluations, rather than "not reached"; a method whose evaluations
    /// cannot be interpolated while others can is still not reached.
    #[test]
    fn work_at_target_without_evaluations() {
        let run = |tol: f64, error: f64, rhs_evals: usize, steps: usize| SettingRun {
            setting: Setting::Tolerance(tol),
            outcome: Ok(Measured {
                error,
                rhs_evals,
                steps,
                rejected: 0,
                jacobian_evals: 0,
                lu_decompositions: 0,
                wall_time_s: steps as f64 * 1e-6,
                repeats: 1,
                energy_drift: None,
            }),
        };
        let taylor = [run(1e-4, 1e-3, 0, 10), run(1e-6, 1e-5, 0, 1000)];
        match at_target(&taylor, 1e-4) {
            AtTarget::Reached {
                rhs_evals, steps, ..
            } => {
                assert_eq!(rhs_evals, None);
                assert!((steps - 100.0).abs() < 1e-9, "{steps}");
            }
            other => panic!("{other:?}"),
        }
        let runge_kutta = [run(1e-4, 1e-3, 60, 10), run(1e-6, 1e-5, 6000, 1000)];
        assert!(matches!(
            at_target(&runge_kutta, 1e-4),
            AtTarget::Reached { rhs_evals: Some(e), .. } if (e - 600.0).abs() < 1e-6
        ));
        let broken = [run(1e-4, 1e-3, 0, 10), run(1e-6, 1e-5, 6000, 1000)];
        assert_eq!(at_target(&broken, 1e-4), AtTarget::NotReached);
        assert!(
            AtTarget::BelowAtLoosest {
                rhs_evals: 0,
                wall_time_s: 1e-3
            }
            .note()
            .contains("(≤ 1.000 ms)")
        );
    }

    #[test]
    fn decades_are_exact_and_loosest_first() {
        assert_eq!(decades(1e-3, 1e-6).unwrap(), [1e-3, 1e-4, 1e-5, 1e-6]);
        assert_eq!(decades(1e-6, 1e-3).unwrap(), [1e-3, 1e-4, 1e-5, 1e-6]);
        assert_eq!(decades(2e-3, 2e-5).unwrap().len(), 3);
        assert_eq!(decades(1e-3, 3e-5), None);
    }

    #[test]
    fn interpolation_is_log_log_between_the_bracketing_pair() {
        // error = work⁻², so at error 1e-4 the work is 100.
        let points = [(1.0, 1.0), (1e-2, 10.0), (1e-6, 1000.0)];
        let w = interpolate(&points, 1e-4).unwrap();
        assert!((w - 100.0).abs() < 1e-9, "{w}");
        assert_eq!(interpolate(&points, 1e-8), None);
        // A failed run (NaN) breaks the bracket rather than being interpolated across.
        let gap = [(1.0, 1.0), (f64::NAN, f64::NAN), (1e-6, 1000.0)];
        assert_eq!(interpolate(&gap, 1e-4), None);
    }

    #[test]
    fn median_of_even_and_odd() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn default_steps_span_by_order() {
        assert_eq!(default_steps(1).first(), Some(&1024));
        assert_eq!(default_steps(2).first(), Some(&256));
        assert_eq!(
            default_steps(4),
            (6..=16).map(|k| 1 << k).collect::<Vec<_>>()
        );
    }
}
