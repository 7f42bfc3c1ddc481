//! Constraint methods compared (issue 5, item 6; lectures 8–11, HW10's "which one is faster?
//! more accurate?"): the holonomic constraints of a model handled as stiff springs (method I,
//! several stiffnesses `k`), as a DAE without and with Baumgarte stabilisation (II.1), with
//! the multipliers and dependent coordinates eliminated symbolically (II.2, where the caller
//! gives the reduced model: `eomgen_symbolic::model::reduce`), and in minimal coordinates
//! (II.3) where the model has a minimal-coordinate twin, side by side.
//!
//! Every run is Dormand–Prince 5(4) at `rtol = atol = tol`, sampled at 200 equally spaced
//! times. Its accuracy is the largest distance of any point from its position in a reference
//! run (the DAE with Baumgarte at `rtol = atol = 1e-13`, whose agreement with the
//! unstabilised DAE at that tolerance is reported), over the samples.
//!
//! References: J. Baumgarte, "Stabilization of constraints and integrals of motion in
//! dynamical systems", *Computer Methods in Applied Mechanics and Engineering* 1 (1972) 1–16,
//! doi:10.1016/0045-7825(72)90018-7; E. Hairer, G. Wanner, *Solving Ordinary Differential
//! Equations II*, 2nd ed., Springer, 1996, §VII.2 (index reduction, stabilisation) and
//! §VI.1 (stiff springs as singular perturbations of constraints).

use serde::Serialize;

use crate::analysis::outcome::{RunTally, StudyRuns};
use crate::constrained::Stabilization;
use crate::integrate::{
    DormandPrince54, IntegrationFailure, Integrator, IntegratorOptions, OutputTimes, Solution,
};
use crate::model_info::ModelInfo;

/// Tolerance of the reference runs.
pub const REFERENCE_TOL: f64 = 1e-13;
/// Number of output times (uniform in `(0, t_end]`).
pub const OUTPUT_TIMES: u32 = 200;
/// Most steps of one run.
pub const MAX_STEPS: usize = 2_000_000;

/// Options of [`constraint_methods`].
///
/// # Solver limits
/// Every run gives up after [`MAX_STEPS`] steps; a failed run is a row with its failure.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintMethodsOptions {
    /// End time (s), positive (default: 10).
    pub t_end: f64,
    /// Relative and absolute tolerance of every run, positive (default: 1e-8).
    pub tol: f64,
    /// Spring stiffnesses of method I (N/m per unit of the constraint) (default: 1e2, 1e4,
    /// 1e6).
    pub stiffness: Vec<f64>,
}

impl ConstraintMethodsOptions {
    /// The default end time (s).
    pub const DEFAULT_T_END: f64 = 10.0;
    /// The default relative and absolute tolerance of every run.
    pub const DEFAULT_TOL: f64 = 1e-8;
    /// The default spring stiffnesses of method I.
    pub const DEFAULT_STIFFNESS: [f64; 3] = [1e2, 1e4, 1e6];
}

impl Default for ConstraintMethodsOptions {
    fn default() -> Self {
        Self {
            t_end: Self::DEFAULT_T_END,
            tol: Self::DEFAULT_TOL,
            stiffness: Self::DEFAULT_STIFFNESS.to_vec(),
        }
    }
}

/// Why the comparison could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ConstraintMethodsError {
    /// The model has no holonomic constraint to handle.
    #[error("`{model}` has no holonomic constraints to compare methods on")]
    NoHolonomicConstraints {
        /// The model's name.
        model: String,
    },
    /// `t_end` or `tol` is not a positive number.
    #[error("the end time and the tolerance must be positive, got {t_end} and {tol}")]
    InvalidOptions {
        /// The end time (s).
        t_end: f64,
        /// The tolerance.
        tol: f64,
    },
    /// A stiffness of method I is not a positive number.
    #[error("every stiffness must be positive, got {stiffness}")]
    InvalidStiffness {
        /// The offending stiffness.
        stiffness: f64,
    },
    /// The model's initial state could not be made consistent with its constraints (every
    /// run starts from the consistent state, so that the methods are compared on the same
    /// motion).
    #[error("the initial state cannot be made consistent with the constraints: {0}")]
    InconsistentStart(crate::constrained::ProjectionError),
    /// The reference run failed.
    #[error("the reference solution failed: {message}")]
    ReferenceFailed {
        /// The integration's failure.
        message: String,
    },
}

/// One method's run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConstraintMethodRow {
    /// The method, as the table names it (`I: stiff spring k = 1e4`).
    pub method: String,
    /// Largest distance (m) of any point from its reference position at the output times.
    pub position_error: f64,
    /// Largest `|Φ|` at the output times (`None` in minimal coordinates: no constraint).
    pub drift: Option<f64>,
    /// RHS evaluations.
    pub rhs_evals: usize,
    /// Accepted steps.
    pub steps: usize,
    /// Wall time (s).
    pub wall_time_s: f64,
    /// `(t, position error)` at every output time (for a chart).
    pub error_history: Vec<(f64, f64)>,
    /// Why the run stopped early, if it did.
    pub failure: Option<String>,
}

/// The result of [`constraint_methods`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConstraintMethods {
    /// The model's name.
    pub model: String,
    /// The tolerance of the reference runs ([`REFERENCE_TOL`]).
    pub reference_tol: f64,
    /// Largest point distance (m) between the reference and the unstabilised DAE at the
    /// reference tolerance.
    pub agreement: f64,
    /// Method I at every stiffness, II.1 without and with Baumgarte, II.2 if a reduced model
    /// is given and II.3 if there is a twin, in that order.
    pub rows: Vec<ConstraintMethodRow>,
}

impl ConstraintMethods {
    /// The study as `eomgen study constraint-methods --json` prints it
    /// ([`ConstraintMethodsSummary`]); `options` are those the study ran with.
    pub fn summary(&self, options: &ConstraintMethodsOptions) -> ConstraintMethodsSummary {
        ConstraintMethodsSummary {
            model: self.model.clone(),
            t_end: options.t_end,
            tol: options.tol,
            reference: ConstraintReferenceSummary {
                method: "dp54, DAE with Baumgarte α = β = 10/s",
                tol: self.reference_tol,
                agreement_with_unstabilised_dae_m: self.agreement,
            },
            methods: self
                .rows
                .iter()
                .map(|r| {
                    // A failed run measured nothing: its error and drift are null, not 0.
                    let measured = r.failure.is_none();
                    ConstraintMethodSummary {
                        method: r.method.clone(),
                        position_error_m: measured.then_some(r.position_error),
                        max_constraint_drift: r.drift.filter(|_| measured),
                        rhs_evals: r.rhs_evals,
                        steps: r.steps,
                        wall_time_s: r.wall_time_s,
                        error: r.failure.clone(),
                    }
                })
                .collect(),
        }
    }
}

/// A [`ConstraintMethods`] study as `eomgen study constraint-methods --json` prints it
/// ([`ConstraintMethods::summary`]): the rows without their error histories.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConstraintMethodsSummary {
    /// The model's name.
    pub model: String,
    /// The end time (s).
    pub t_end: f64,
    /// The tolerance of every run.
    pub tol: f64,
    /// The reference solution.
    pub reference: ConstraintReferenceSummary,
    /// One entry per method, in the study's order.
    pub methods: Vec<ConstraintMethodSummary>,
}

/// The reference of a [`ConstraintMethodsSummary`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ConstraintReferenceSummary {
    /// How it is computed, in words.
    pub method: &'static str,
    /// Its tolerance ([`REFERENCE_TOL`]).
    pub tol: f64,
    /// [`ConstraintMethods::agreement`] (m).
    pub agreement_with_unstabilised_dae_m: f64,
}

/// One method of a [`ConstraintMethodsSummary`]; a failed run has null error and drift.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConstraintMethodSummary {
    /// [`ConstraintMethodRow::method`].
    pub method: String,
    /// [`ConstraintMethodRow::position_error`] (m; null for a failed run).
    pub position_error_m: Option<f64>,
    /// [`ConstraintMethodRow::drift`] (null for a failed run).
    pub max_constraint_drift: Option<f64>,
    /// [`ConstraintMethodRow::rhs_evals`].
    pub rhs_evals: usize,
    /// [`ConstraintMethodRow::steps`].
    pub steps: usize,
    /// [`ConstraintMethodRow::wall_time_s`] (s).
    pub wall_time_s: f64,
    /// [`ConstraintMethodRow::failure`].
    pub error: Option<String>,
}

/// Every method's run is a run of the study; the reference is not (it fails the study as a
/// whole, [`ConstraintMethodsError::ReferenceFailed`]).
impl StudyRuns for ConstraintMethods {
    fn study(&self) -> &'static str {
        "constraint-methods"
    }

    fn tally(&self) -> RunTally {
        let mut tally = RunTally::default();
        for row in &self.rows {
            tally.add(row.failure.as_ref().map(|f| format!("{}: {f}", row.method)));
        }
        tally
    }
}

fn integrate(
    model: &mut dyn ModelInfo,
    y0: &[f64],
    t_end: f64,
    times: &[f64],
    tol: f64,
) -> (Solution, Option<String>) {
    let options = IntegratorOptions::default()
        .with_rtol(tol)
        .with_atol(tol)
        .with_max_steps(MAX_STEPS);
    match DormandPrince54::new().integrate(
        model.as_ode_mut(),
        0.0,
        y0,
        t_end,
        &OutputTimes::At(times.to_vec()),
        &options,
    ) {
        Ok(s) => (s, None),
        Err(IntegrationFailure { error, partial }) => (*partial, Some(error.to_string())),
    }
}

/// Positions of the points named in `names`, in that order, at every sample (NaN for a
/// point the model does not have).
fn positions(model: &dyn ModelInfo, solution: &Solution, names: &[&str]) -> Vec<Vec<[f64; 3]>> {
    let own = model.description().point_names();
    solution
        .iter()
        .map(|(t, y)| {
            let all = model.point_positions(t, y);
            names
                .iter()
                .map(|n| {
                    own.iter()
                        .position(|p| p == n)
                        .map_or([f64::NAN; 3], |i| all[i])
                })
                .collect()
        })
        .collect()
}

fn row(
    method: String,
    model: &mut dyn ModelInfo,
    solution: &Solution,
    failure: Option<String>,
    reference: &[Vec<[f64; 3]>],
    names: &[&str],
    constrained: bool,
) -> ConstraintMethodRow {
    let here = positions(model, solution, names);
    let mut error_history = Vec::new();
    let mut position_error: f64 = 0.0;
    for ((t, p), r) in solution.t.iter().zip(&here).zip(reference) {
        let e = p
            .iter()
            .zip(r)
            // hypot: no overflow of the squares for positions beyond 1e154 m.
            .map(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1]).hypot(a[2] - b[2]))
            .fold(0.0f64, |m, e| if e.is_nan() { e } else { m.max(e) });
        position_error = if e.is_nan() { e } else { position_error.max(e) };
        error_history.push((*t, e));
    }
    // A distance that is not finite measured nothing: the run failed there.
    let failure = failure.or_else(|| {
        (!position_error.is_finite()).then(|| {
            let at = error_history
                .iter()
                .find(|(_, e)| !e.is_finite())
                .map_or(f64::NAN, |(t, _)| *t);
            format!("the position error is not finite at t = {at} s (the positions overflow)")
        })
    });
    let drift = constrained.then(|| {
        solution
            .iter()
            .map(|(t, y)| model.constraint_drift(t, y).0)
            .fold(0.0f64, f64::max)
    });
    ConstraintMethodRow {
        method,
        position_error,
        drift,
        rhs_evals: solution.stats.rhs_evals,
        steps: solution.stats.steps,
        wall_time_s: solution.stats.wall_time_s,
        error_history,
        failure,
    }
}

/// Compares the ways of handling the holonomic constraints of a model (see the module
/// docs). `make` builds a fresh instance of the model (one per run); `twin` is its
/// minimal-coordinate twin with its name (the model file's `minimal_twin:`), whose points
/// of the same names are compared.
///
/// Every constrained run (and the reference) starts from the model's initial state made
/// consistent with its constraints ([`ModelInfo::consistent_initial_state`]: the coordinates
/// the file marks `{ guess: … }` solved by Newton), so that a file whose `initial:` only
/// guesses the dependent coordinates is compared on the motion it describes; the minimal twin
/// starts from its own initial state.
///
/// # Errors
/// [`ConstraintMethodsError::NoHolonomicConstraints`],
/// [`ConstraintMethodsError::InvalidOptions`], [`ConstraintMethodsError::InvalidStiffness`],
/// [`ConstraintMethodsError::InconsistentStart`], [`ConstraintMethodsError::ReferenceFailed`].
/// A method whose run fails is a row with its failure; a study whose every run failed
/// measured nothing ([`StudyRuns::check_measured`]).
///
/// # Examples
/// ```
/// use eomgen::analysis::{ConstraintMethodsOptions, constraint_methods};
///
/// let entry = eomgen::models::find("simple_pendulum_cartesian").unwrap();
/// let twin = (eomgen::models::find("simple_pendulum").unwrap().make)();
/// let options = ConstraintMethodsOptions { t_end: 1.0, stiffness: vec![1e4], ..Default::default() };
/// let study = constraint_methods(&mut || (entry.make)(), Some(("simple_pendulum", twin)), &options)?;
/// assert_eq!(study.rows.len(), 4);
/// // The DAE and the minimal coordinates are far more accurate than the spring.
/// assert!(study.rows[1].position_error < 1e-6 && study.rows[3].position_error < 1e-6);
/// assert!(study.rows[0].position_error > 1e-4);
/// # Ok::<(), eomgen::analysis::ConstraintMethodsError>(())
/// ```
pub fn constraint_methods(
    make: &mut dyn FnMut() -> Box<dyn ModelInfo>,
    twin: Option<(&str, Box<dyn ModelInfo>)>,
    options: &ConstraintMethodsOptions,
) -> Result<ConstraintMethods, ConstraintMethodsError> {
    constraint_methods_with_reduced(make, None, twin, options)
}

/// [`constraint_methods()`] with method II.2 too: `reduced` is the model with its
/// constraints, multipliers and dependent coordinates eliminated symbolically (the kept
/// coordinates named in its label, `x`), whose points of the same names are compared. It
/// starts from its own initial state (the kept coordinates of the model's); a reduced model
/// whose coordinates become singular on the motion (where the branches of a quadratic
/// constraint meet, HW13) fails there, and its row says so.
///
/// # Errors
/// As [`constraint_methods()`].
///
/// # Examples
/// ```
/// use eomgen::analysis::{ConstraintMethodsOptions, constraint_methods_with_reduced};
///
/// let rod = eomgen::ModelSource::open("two_masses_rod").unwrap();
/// // x2 = x1 + l0 substituted, compiled at run time (what `eomgen reduce two_masses_rod
/// // --keep x1` writes).
/// let reduced = eomgen::reduction::reduced_twin(&rod).unwrap();
/// let options = ConstraintMethodsOptions { t_end: 1.0, stiffness: vec![1e4], ..Default::default() };
/// let study = constraint_methods_with_reduced(
///     &mut || rod.instantiate(),
///     Some((&reduced.label(), reduced.instantiate())),
///     None,
///     &options,
/// )?;
/// assert_eq!(study.rows.len(), 4);
/// // A linear constraint: the reduced model is exact, as accurate as the DAE.
/// assert!(study.rows[3].position_error < 1e-6);
/// assert!(study.rows[3].method.starts_with("II.2"));
/// # Ok::<(), eomgen::analysis::ConstraintMethodsError>(())
/// ```
pub fn constraint_methods_with_reduced(
    make: &mut dyn FnMut() -> Box<dyn ModelInfo>,
    reduced: Option<(&str, Box<dyn ModelInfo>)>,
    twin: Option<(&str, Box<dyn ModelInfo>)>,
    options: &ConstraintMethodsOptions,
) -> Result<ConstraintMethods, ConstraintMethodsError> {
    let mut model = make();
    check_study(model.as_ref(), options)?;
    let y0 = model
        .consistent_initial_state()
        .map_err(ConstraintMethodsError::InconsistentStart)?;
    let (t_end, tol) = (options.t_end, options.tol);
    let times: Vec<f64> = (1..=OUTPUT_TIMES)
        .map(|i| t_end * f64::from(i) / f64::from(OUTPUT_TIMES))
        .collect();
    let owned: Vec<String> = model
        .description()
        .point_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let names: Vec<&str> = owned.iter().map(String::as_str).collect();

    let (reference, agreement) = reference_run(model.as_mut(), &y0, t_end, &times, &names)?;

    let runs = MethodRuns {
        t_end,
        times: &times,
        tol,
        reference: &reference,
        names: &names,
    };
    let rows = runs.rows(make, reduced, twin, &options.stiffness, &y0);
    Ok(ConstraintMethods {
        model: model.description().name.to_string(),
        reference_tol: REFERENCE_TOL,
        agreement,
        rows,
    })
}

/// The checks of [`constraint_methods_with_reduced`] before any run, in its order: the model
/// has holonomic constraints, the end time and tolerance are positive, and so is every
/// stiffness.
fn check_study(
    model: &dyn ModelInfo,
    options: &ConstraintMethodsOptions,
) -> Result<(), ConstraintMethodsError> {
    if model.description().holonomic_constraints == 0 {
        return Err(ConstraintMethodsError::NoHolonomicConstraints {
            model: model.description().name.to_string(),
        });
    }
    let positive = |x: f64| x.is_finite() && x > 0.0;
    if !positive(options.t_end) || !positive(options.tol) {
        return Err(ConstraintMethodsError::InvalidOptions {
            t_end: options.t_end,
            tol: options.tol,
        });
    }
    if let Some(&stiffness) = options.stiffness.iter().find(|&&k| !positive(k)) {
        return Err(ConstraintMethodsError::InvalidStiffness { stiffness });
    }
    Ok(())
}

/// The positions of the compared points at every sample, as [`positions`] gives them.
type PointPaths = Vec<Vec<[f64; 3]>>;

/// The reference positions of the points `names` at `times` and their agreement
/// ([`ConstraintMethods::agreement`]) with the unstabilised DAE at the same tolerance;
/// leaves `model` unstabilised.
fn reference_run(
    model: &mut dyn ModelInfo,
    y0: &[f64],
    t_end: f64,
    times: &[f64],
    names: &[&str],
) -> Result<(PointPaths, f64), ConstraintMethodsError> {
    // Reference: the DAE with Baumgarte at rtol = atol = 1e-13, checked against the
    // unstabilised DAE at the same tolerance.
    model.set_stabilization(Stabilization::default_baumgarte());
    let (reference_solution, failure) = integrate(model, y0, t_end, times, REFERENCE_TOL);
    if let Some(message) = failure {
        return Err(ConstraintMethodsError::ReferenceFailed { message });
    }
    let reference = positions(model, &reference_solution, names);
    model.set_stabilization(Stabilization::None);
    let (check, _) = integrate(model, y0, t_end, times, REFERENCE_TOL);
    let agreement = row(String::new(), model, &check, None, &reference, names, true).position_error;
    Ok((reference, agreement))
}

/// What every method's run shares: the end time, output times and tolerance, and the
/// reference positions of the points `names` it is measured against.
struct MethodRuns<'a> {
    t_end: f64,
    times: &'a [f64],
    tol: f64,
    reference: &'a [Vec<[f64; 3]>],
    names: &'a [&'a str],
}

impl MethodRuns<'_> {
    /// One method's row: `model` integrated from `y0` at the study's tolerance, measured
    /// against the reference (its drift too if `constrained`).
    fn run(
        &self,
        method: String,
        model: &mut dyn ModelInfo,
        y0: &[f64],
        constrained: bool,
    ) -> ConstraintMethodRow {
        let (s, f) = integrate(model, y0, self.t_end, self.times, self.tol);
        row(
            method,
            model,
            &s,
            f,
            self.reference,
            self.names,
            constrained,
        )
    }

    /// The rows of [`ConstraintMethods::rows`], in their order: method I at every
    /// `stiffness`, II.1 without and with Baumgarte (each a fresh model from `make`, started
    /// at `y0`), then II.2 and II.3 from their own initial states if given.
    fn rows(
        &self,
        make: &mut dyn FnMut() -> Box<dyn ModelInfo>,
        reduced: Option<(&str, Box<dyn ModelInfo>)>,
        twin: Option<(&str, Box<dyn ModelInfo>)>,
        stiffness: &[f64],
        y0: &[f64],
    ) -> Vec<ConstraintMethodRow> {
        let mut rows = Vec::new();
        for &k in stiffness {
            let mut m = make();
            m.set_stabilization(Stabilization::Penalty {
                stiffness: k,
                damping: 0.0,
            });
            rows.push(self.run(format!("I: stiff spring k = {k:e}"), m.as_mut(), y0, true));
        }
        let [alpha, beta] = Stabilization::DEFAULT_BAUMGARTE_GAINS;
        let baumgarte = if alpha == beta {
            format!("II.1: DAE, Baumgarte α = β = {alpha}/s")
        } else {
            format!("II.1: DAE, Baumgarte α = {alpha}/s, β = {beta}/s")
        };
        for (label, stab) in [
            (
                "II.1: DAE, no stabilisation".to_string(),
                Stabilization::None,
            ),
            (baumgarte, Stabilization::default_baumgarte()),
        ] {
            let mut m = make();
            m.set_stabilization(stab);
            rows.push(self.run(label, m.as_mut(), y0, true));
        }
        if let Some((kept, mut m)) = reduced {
            let y0 = m.initial_state();
            let label = format!("II.2: eliminated, keeping {kept}");
            rows.push(self.run(label, m.as_mut(), &y0, false));
        }
        if let Some((twin, mut m)) = twin {
            let y0 = m.initial_state();
            let label = format!("II.3: minimal coordinates ({twin})");
            rows.push(self.run(label, m.as_mut(), &y0, false));
        }
        rows
    }
}
