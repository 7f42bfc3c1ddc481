//! The study as `eomgen study work-precision --json` prints it ([`WorkPrecision::summary`] and
//! its `Serialize` types), its run tally, and its counts of unresolved runs.

use super::*;

impl WorkPrecision {
    /// Whether a run's error is within 10× of the reference's agreement, so that it measures
    /// the reference as much as the method.
    pub fn unresolved(&self, m: &Measured) -> bool {
        m.error < 10.0 * self.agreement
    }

    /// The number of runs whose error the reference does not resolve ([`Self::unresolved`]).
    pub fn num_unresolved(&self) -> usize {
        self.results
            .iter()
            .flat_map(|r| &r.runs)
            .filter(|r| r.outcome.as_ref().is_ok_and(|m| self.unresolved(m)))
            .count()
    }
}

impl WorkPrecision {
    /// The study as `eomgen study work-precision --json` prints it
    /// ([`WorkPrecisionSummary`]); `model` is the model studied and `options` those the
    /// study ran with.
    pub fn summary(
        &self,
        model: &dyn ModelInfo,
        options: &WorkPrecisionOptions,
    ) -> WorkPrecisionSummary {
        let samples = options.samples;
        WorkPrecisionSummary {
            model: model.description().name.to_string(),
            t_end: options.t_end,
            samples,
            error_norm: format!(
                "max over the {samples} output times k·T/{samples} (k = 1…{samples}) and over all {} components of y = [q; q̇] of |y − y_ref|",
                self.dim
            ),
            conservative: model.description().conservative,
            target_error: options.target_error,
            baseline_ms: options.baseline_ms,
            timing: TimingSummary {
                statistic: "median",
                min_repeats: self.min_repeats,
                min_total_s: self.min_time_s,
                max_repeats: MAX_REPEATS,
            },
            reference: ReferenceSummary {
                method: Method::Dop853.name(),
                rtol: options.reference_tol,
                atol: options.reference_tol,
                steps: self.reference_steps,
                check_method: Method::Dp54.name(),
                agreement: self.agreement,
            },
            methods: self
                .results
                .iter()
                .map(|r| MethodRunsSummary {
                    method: r.method.name(),
                    name: r.method.display_name(),
                    order: r.method.integrator().order(),
                    adaptive: r.method.is_adaptive(),
                    runs: r.runs.iter().map(|run| self.run_summary(run)).collect(),
                    at_target: target_summary(&r.at_target, options.baseline_ms),
                })
                .collect(),
        }
    }

    /// One run: every key present, null where a failed run has no value.
    fn run_summary(&self, run: &SettingRun) -> RunSummary {
        let (tol, num_steps, dt) = match run.setting {
            Setting::Tolerance(tol) => (Some(tol), None, None),
            Setting::Steps { steps, dt } => (None, Some(steps), Some(dt)),
        };
        let m = run.outcome.as_ref().ok();
        RunSummary {
            tol,
            num_steps,
            dt,
            error: m.map(|m| m.error),
            resolved: m.map(|m| !self.unresolved(m)),
            rhs_evals: m.map(|m| m.rhs_evals),
            steps: m.map(|m| m.steps),
            rejected: m.map(|m| m.rejected),
            jacobian_evals: m.map(|m| m.jacobian_evals),
            lu_decompositions: m.map(|m| m.lu_decompositions),
            wall_time_s: m.map(|m| m.wall_time_s),
            repeats: m.map(|m| m.repeats),
            energy_drift: m.and_then(|m| m.energy_drift),
            failure: run.outcome.as_ref().err().map(|f| RunFailure {
                t: f.t.filter(|t| t.is_finite()),
                message: f.message.clone(),
            }),
        }
    }
}

/// The work at the target error: interpolated values, or nulls and a note.
fn target_summary(target: &AtTarget, baseline_ms: Option<f64>) -> TargetSummary {
    match *target {
        AtTarget::Reached {
            rhs_evals,
            steps,
            wall_time_s,
        } => TargetSummary {
            reached: true,
            rhs_evals,
            steps: Some(steps),
            wall_time_s: Some(wall_time_s),
            baseline_ratio: baseline_ms.map(|b| b * 1e-3 / wall_time_s),
            note: None,
        },
        AtTarget::BelowAtLoosest { .. } | AtTarget::NotReached => TargetSummary {
            reached: !matches!(target, AtTarget::NotReached),
            rhs_evals: None,
            steps: None,
            wall_time_s: None,
            baseline_ratio: None,
            note: Some(target.note()),
        },
    }
}

/// A [`WorkPrecision`] study as `eomgen study work-precision --json` prints it
/// ([`WorkPrecision::summary`]). Non-finite figures (an error or a time that overflowed)
/// serialise as null.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WorkPrecisionSummary {
    /// The model's name.
    pub model: String,
    /// The end time (s).
    pub t_end: f64,
    /// The number of output times the error is taken over.
    pub samples: usize,
    /// The error norm, in words.
    pub error_norm: String,
    /// Whether the model declares itself conservative.
    pub conservative: bool,
    /// The error at which the work is interpolated.
    pub target_error: f64,
    /// The baseline wall time (ms) the work at the target is compared with, if given.
    pub baseline_ms: Option<f64>,
    /// How the wall times were measured.
    pub timing: TimingSummary,
    /// The reference solution.
    pub reference: ReferenceSummary,
    /// One entry per method.
    pub methods: Vec<MethodRunsSummary>,
}

/// How a [`WorkPrecisionSummary`]'s wall times were measured.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TimingSummary {
    /// The statistic over the repeats (`"median"`).
    pub statistic: &'static str,
    /// [`WorkPrecision::min_repeats`].
    pub min_repeats: usize,
    /// [`WorkPrecision::min_time_s`] (s).
    pub min_total_s: f64,
    /// [`MAX_REPEATS`].
    pub max_repeats: usize,
}

/// The reference solution of a [`WorkPrecisionSummary`]: DOP853, checked by DP5(4) at the
/// same tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReferenceSummary {
    /// The reference's method (`"dop853"`).
    pub method: &'static str,
    /// Its relative tolerance.
    pub rtol: f64,
    /// Its absolute tolerance.
    pub atol: f64,
    /// Its accepted steps.
    pub steps: usize,
    /// The check's method (`"dp54"`).
    pub check_method: &'static str,
    /// [`WorkPrecision::agreement`].
    pub agreement: f64,
}

/// One method of a [`WorkPrecisionSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodRunsSummary {
    /// [`Method::name`].
    pub method: &'static str,
    /// [`Method::display_name`].
    pub name: &'static str,
    /// The method's order.
    pub order: u32,
    /// Whether it controls its step size.
    pub adaptive: bool,
    /// Its runs, loosest setting first.
    pub runs: Vec<RunSummary>,
    /// Its work at the target error.
    pub at_target: TargetSummary,
}

/// One run of a [`MethodRunsSummary`]: every key present, null where it does not apply or a
/// failed run has no value.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSummary {
    /// The tolerance (adaptive methods).
    pub tol: Option<f64>,
    /// The number of steps (fixed-step methods).
    pub num_steps: Option<usize>,
    /// The step (s; fixed-step methods).
    pub dt: Option<f64>,
    /// [`Measured::error`].
    pub error: Option<f64>,
    /// Whether the reference resolves the error ([`WorkPrecision::unresolved`]).
    pub resolved: Option<bool>,
    /// [`Measured::rhs_evals`].
    pub rhs_evals: Option<usize>,
    /// [`Measured::steps`].
    pub steps: Option<usize>,
    /// [`Measured::rejected`].
    pub rejected: Option<usize>,
    /// [`Measured::jacobian_evals`].
    pub jacobian_evals: Option<usize>,
    /// [`Measured::lu_decompositions`].
    pub lu_decompositions: Option<usize>,
    /// [`Measured::wall_time_s`] (s).
    pub wall_time_s: Option<f64>,
    /// [`Measured::repeats`].
    pub repeats: Option<usize>,
    /// [`Measured::energy_drift`].
    pub energy_drift: Option<f64>,
    /// Why the run failed (null when it did not; `t` null when not finite).
    pub failure: Option<RunFailure>,
}

/// The work of a [`MethodRunsSummary`] at the target error ([`AtTarget`]): the interpolated
/// figures, or nulls and a note.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetSummary {
    /// Whether the target error is reached (bracketed, or below at the loosest setting).
    pub reached: bool,
    /// Interpolated RHS evaluations.
    pub rhs_evals: Option<f64>,
    /// Interpolated steps.
    pub steps: Option<f64>,
    /// Interpolated wall time (s).
    pub wall_time_s: Option<f64>,
    /// The baseline's time over this wall time (with a baseline).
    pub baseline_ratio: Option<f64>,
    /// [`AtTarget::note`] when nothing was interpolated.
    pub note: Option<String>,
}

/// Every setting of every method is a run; one that failed is counted with its message.
impl StudyRuns for WorkPrecision {
    fn study(&self) -> &'static str {
        "work-precision"
    }

    fn tally(&self) -> RunTally {
        let mut tally = RunTally::default();
        for (method, run) in self
            .results
            .iter()
            .flat_map(|r| r.runs.iter().map(move |run| (r.method, run)))
        {
            tally.add(run.outcome.as_ref().err().map(|f| {
                format!(
                    "{} at {}: {}",
                    method.display_name(),
                    run.setting.label(),
                    f.message
                )
            }));
        }
        tally
    }
}
