//! The checks of a model file (`eomgen report`'s pass/fail rows): the derivations agree, the
//! energy and the constraints do not drift, and the reference values the file states in its
//! `checks:` block (natural frequencies, damping ratios, an event's period, the state at a
//! time, conserved quantities; see [`eomgen_symbolic::model::Checks`]) are met.
//!
//! A check passes when `|computed − expected| ≤ tolerance · max(1, |expected|)`; drifts and
//! residuals are "computed" with expected 0 and their bound as tolerance. The simulations run
//! through [`analysis::simulate`](crate::analysis::simulate) from the model's consistent
//! initial state, without drift control; the modal values come from an operating point the
//! caller computes (see [`ModesAt`]).

use serde::Serialize;

use crate::ModelSource;
use crate::expressions::{evaluate, parameter_lookup, split_assignment};
use crate::text::fixed;
use eomgen_runtime::analysis::vibration::{
    EquilibriumStart, ModalAnalysis, ModalOptions, OperatingPointOptions, modal_analysis,
};
use eomgen_runtime::analysis::{EnergyDrift, RunTally, StudyRuns, constraint_drift};
use eomgen_runtime::description::checks::ModalCheck;
use eomgen_runtime::{Linearization, ModelInfo, Solution, damped_modes};
use eomgen_symbolic::mechanics::cross_check::check_model;
use eomgen_symbolic::model::parser::eval_expr;
use eomgen_symbolic::model::parser::parse_expr;
use eomgen_symbolic::model::{
    DEFAULT_CONSTRAINT_DRIFT, DEFAULT_ENERGY_DRIFT, Diagnostic, Expr, Location, ModelFile,
};

/// Relative tolerance of the derivation cross-checks, as `eomgen check`'s.
pub const DERIVATION_TOLERANCE: f64 = eomgen_symbolic::mechanics::cross_check::CHECK_TOLERANCE;
/// Random states of the report's derivation cross-checks: half of `eomgen check`'s default
/// ([`eomgen_symbolic::mechanics::cross_check::DEFAULT_CHECK_STATES`]), as the report runs
/// every model.
pub const DERIVATION_STATES: usize = 100;
/// Seed of the derivation cross-checks' random states, as `eomgen check`'s.
pub const DERIVATION_SEED: u64 = eomgen_symbolic::mechanics::cross_check::CHECK_SEED;
/// Expected periods a `period:` check integrates at least, when its file gives no `t_end:`
/// (two zeros one period apart fit whatever the phase of the first, with a period to spare).
pub const PERIODS_PER_RUN: f64 = 3.0;

/// One row of a model's pass/fail table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CheckRow {
    /// What was checked, with its unit or settings.
    pub check: String,
    /// The computed value; `None` when it could not be computed (see `note`).
    pub computed: Option<f64>,
    /// The expected value (NaN, serialised `null`, when it could not be evaluated).
    pub expected: f64,
    /// The tolerance: passes when `|computed − expected| ≤ tolerance · max(1, |expected|)`.
    pub tolerance: f64,
    /// Whether it passed.
    pub passed: bool,
    /// Why it could not be computed, if so.
    pub note: Option<String>,
}

impl CheckRow {
    /// Why the check failed, in words (`None` when it passed): the reason it could not be
    /// computed, or the computed value against the expected one and the tolerance.
    ///
    /// # Examples
    /// ```
    /// use eomgen::checks::CheckRow;
    ///
    /// let row = CheckRow::compare("ω (rad/s)", Ok(3.2), 3.1, 1e-7);
    /// assert_eq!(
    ///     row.failure_reason().unwrap(),
    ///     "computed 3.2, expected 3.1, |difference| 1.000e-1 > tolerance 1e-7 × max(1, |expected|)"
    /// );
    /// assert_eq!(CheckRow::compare("ω", Ok(3.1), 3.1, 1e-7).failure_reason(), None);
    /// let row = CheckRow::compare("ω", Err("no equilibrium".into()), 1.0, 1.0);
    /// assert_eq!(row.failure_reason().unwrap(), "not computed: no equilibrium");
    /// ```
    pub fn failure_reason(&self) -> Option<String> {
        if self.passed {
            return None;
        }
        Some(match (self.computed, &self.note) {
            (_, Some(note)) => format!("not computed: {note}"),
            (Some(c), None) if !c.is_finite() => format!("computed {c}, not a finite number"),
            (Some(c), None) if self.expected.is_nan() => {
                format!("computed {c}, but the expected value is undefined")
            }
            (Some(c), None) => format!(
                "computed {c}, expected {}, |difference| {:.3e} > tolerance {:e} × max(1, |expected|)",
                self.expected,
                (c - self.expected).abs(),
                self.tolerance
            ),
            (None, None) => "not computed".to_string(),
        })
    }

    /// Compares `computed` with `expected` (a failure to compute is a failed check, with
    /// its reason as the note).
    ///
    /// # Examples
    /// ```
    /// use eomgen::checks::CheckRow;
    ///
    /// assert!(CheckRow::compare("ω (rad/s)", Ok(3.1622776), 10f64.sqrt(), 1e-7).passed);
    /// assert!(!CheckRow::compare("ω (rad/s)", Ok(3.2), 10f64.sqrt(), 1e-7).passed);
    /// assert!(!CheckRow::compare("ω", Err("no equilibrium".into()), 1.0, 1.0).passed);
    /// ```
    pub fn compare(
        check: impl Into<String>,
        computed: Result<f64, String>,
        expected: f64,
        tolerance: f64,
    ) -> Self {
        let (computed, note) = match computed {
            Ok(v) => (Some(v), None),
            Err(e) => (None, Some(e)),
        };
        let passed = computed.is_some_and(|c| {
            c.is_finite() && (c - expected).abs() <= tolerance * expected.abs().max(1.0)
        });
        Self {
            check: check.into(),
            computed,
            expected,
            tolerance,
            passed,
            note,
        }
    }
}

/// The modal values at an operating point, as the caller found them (`eomgen modes --at`):
/// the input of the `natural_frequencies:` and `damping_ratios:` checks.
#[derive(Debug, Clone)]
pub struct ModesAt {
    /// The operating point's name (`hanging`) or guesses, as the rows name it.
    pub label: String,
    /// The undamped natural frequencies (rad/s, ascending).
    pub natural_frequencies: Vec<f64>,
    /// The exact linearisation there (for the damping ratios).
    pub linearization: Linearization,
}

/// The rows of the derivation cross-checks (the checks of `eomgen check`: Lagrange against
/// momentum balance, user balances and hand equations, and the power balance), and the notes
/// of the comparison.
///
/// # Errors
/// The model file's diagnostics, when it cannot be derived.
pub fn derivation_checks(
    file: &ModelFile,
) -> Result<(Vec<CheckRow>, Vec<String>), Vec<Diagnostic>> {
    let r = check_model(file, DERIVATION_STATES, DERIVATION_SEED)?;
    // A comparison over no state is never a pass: each of its rows fails with the reason.
    let nothing_compared = r.states.nothing_compared();
    let sampled = |value: f64| nothing_compared.clone().map_or(Ok(value), Err);
    let mut rows = Vec::new();
    for c in &r.comparisons {
        if c.expect_disagreement {
            // A set of balances kept to show a wrong form: it must differ from Lagrange.
            let computed = sampled(c.max_rel_residual);
            rows.push(CheckRow {
                check: format!(
                    "derivations disagree, as the file states: {} vs {} (max relative q̈ difference, above the tolerance)",
                    c.a, c.b
                ),
                computed: computed.as_ref().ok().copied(),
                expected: 0.0,
                tolerance: DERIVATION_TOLERANCE,
                passed: computed.is_ok() && c.passed(DERIVATION_TOLERANCE),
                note: computed.err(),
            });
            continue;
        }
        let computed = sampled(c.max_rel_residual).and_then(|v| {
            if v.is_nan() {
                Err(format!(
                    "{} is not finite at some of the states where {} is",
                    c.b, c.a
                ))
            } else {
                Ok(v)
            }
        });
        rows.push(CheckRow::compare(
            format!(
                "derivations agree: {} vs {} (max relative q̈ difference)",
                c.a, c.b
            ),
            computed,
            0.0,
            DERIVATION_TOLERANCE,
        ));
    }
    if let Some(p) = &r.power_balance {
        rows.push(CheckRow::compare(
            "power balance dE/dt = Q·q̇ (max relative residual)",
            sampled(p.max_rel_residual),
            0.0,
            DERIVATION_TOLERANCE,
        ));
    }
    // A model that only Lagrange derives is not cross-checked: a failed row, never a pass.
    if let Some(reason) = r.not_cross_checked() {
        rows.push(CheckRow::compare(
            "derivations cross-checked",
            Err(reason.to_string()),
            0.0,
            DERIVATION_TOLERANCE,
        ));
    }
    if rows.is_empty()
        && let Some(reason) = &nothing_compared
    {
        rows.push(CheckRow::compare(
            "Lagrange's equations evaluated at random states",
            Err(reason.clone()),
            0.0,
            DERIVATION_TOLERANCE,
        ));
    }
    if let Some(c) = &r.initial_constraints {
        let kind = if c.velocity {
            "velocity residual"
        } else {
            "residual"
        };
        rows.push(CheckRow::compare(
            format!(
                "initial state satisfies the constraints (largest {kind}, of `{}`)",
                c.constraint
            ),
            Ok(c.residual),
            0.0,
            eomgen_symbolic::mechanics::cross_check::INITIAL_CONSTRAINT_TOLERANCE,
        ));
    }
    // The reason of "not cross-checked" is its row's; not a note as well.
    let reason = r.not_cross_checked();
    let notes = r
        .notes
        .iter()
        .filter(|n| Some(n.as_str()) != reason)
        .cloned()
        .collect();
    Ok((rows, notes))
}

/// Parses an expression of the model's description (printed from the parsed file, so it
/// parses back; the error is the parser's message).
fn parse(text: &str) -> Result<Expr, String> {
    parse_expr(text, Location { line: 1, column: 1 }).map_err(|d| d.message)
}

/// Evaluates an expected value (an expression of the parameters).
fn expected(text: &str, model: &dyn ModelInfo) -> Result<f64, String> {
    eval_expr(&parse(text)?, &parameter_lookup(model)).map_err(|d| d.message)
}

/// Evaluates a function of the parameters (`parameters`), coordinates, rates and `t` at
/// `(t, y)` of `model`.
fn state_value(
    e: &Expr,
    model: &dyn ModelInfo,
    parameters: &dyn Fn(&str) -> Option<f64>,
    t: f64,
    y: &[f64],
) -> Result<f64, String> {
    let description = model.description();
    eval_expr(e, &|name| {
        if name == "t" {
            return Some(t);
        }
        if let Some(v) = parameters(name) {
            return Some(v);
        }
        description.state_index(name).map(|i| y[i])
    })
    .map_err(|d| d.message)
}

/// Rows comparing a list of computed modal values with a `natural_frequencies:` or
/// `damping_ratios:` entry.
fn modal_rows(
    key: &str,
    unit: &str,
    check: &ModalCheck,
    model: &dyn ModelInfo,
    computed: Result<(String, Vec<f64>), String>,
) -> Vec<CheckRow> {
    let at = check.at.as_deref().unwrap_or("");
    let (label, values) = match computed {
        Ok(c) => c,
        Err(e) => {
            return vec![CheckRow::compare(
                format!("{key} at {at}"),
                Err(e),
                f64::NAN,
                check.tolerance,
            )];
        }
    };
    let mut rows = Vec::new();
    for (k, e) in check.values.iter().enumerate() {
        let what = format!("{key}[{}] at {label}{unit}", k + 1);
        let value = values.get(k).copied().ok_or_else(|| {
            format!(
                "the model has {} value(s), the file states {}",
                values.len(),
                check.values.len()
            )
        });
        match expected(e, model) {
            Ok(x) => rows.push(CheckRow::compare(what, value, x, check.tolerance)),
            Err(err) => rows.push(CheckRow::compare(what, Err(err), f64::NAN, check.tolerance)),
        }
    }
    if values.len() > check.values.len() {
        rows.push(CheckRow::compare(
            format!("number of {key} at {label}"),
            Ok(values.len() as f64),
            check.values.len() as f64,
            0.0,
        ));
    }
    rows
}

/// A row whose expected value is an expression: evaluated against `model`'s parameters, or
/// the failure to evaluate it.
fn against_expected(
    what: String,
    computed: Result<f64, String>,
    e: &str,
    model: &dyn ModelInfo,
    tolerance: f64,
) -> CheckRow {
    match expected(e, model) {
        Ok(x) => CheckRow::compare(what, computed, x, tolerance),
        Err(err) => CheckRow::compare(what, Err(err), f64::NAN, tolerance),
    }
}

/// The rows of the checks that need a motion or an equilibrium of `model`, in this order:
/// energy drift (conservative models, or where the file asks), constraint drift (constrained
/// models), `natural_frequencies:`, `damping_ratios:`, `period:`, `final_state:` and
/// `conserved:`, then the `outputs:` declared conserved — the file's entries as the model's
/// description carries them
/// ([`eomgen_runtime::description::checks`]), so a compiled model is checked as a file
/// loaded at run time.
///
/// `y0` is the model's consistent initial state; `simulations` runs (and keeps) the
/// simulations of the model; `modes(at)` gives the modal values at the operating point `at`
/// (an `equilibria:` name, `None` for the default) or why there are none.
///
/// # Examples
/// ```
/// use eomgen::checks::{Simulations, motion_checks};
///
/// let source = eomgen::ModelSource::open("simple_pendulum")?;
/// let mut model = source.instantiate();
/// let y0 = model.consistent_initial_state().unwrap();
/// let mut simulations = Simulations::new(source);
/// let rows = motion_checks(model.as_mut(), &y0, &mut simulations,
///                          &mut |_| Err("not computed here".to_string()));
/// let period = rows.iter().find(|r| r.check.starts_with("period")).unwrap();
/// assert!(period.passed, "{period:?}");
/// # Ok::<(), eomgen::OpenError>(())
/// ```
pub fn motion_checks(
    model: &mut dyn ModelInfo,
    y0: &[f64],
    simulations: &mut Simulations,
    modes: &mut dyn FnMut(Option<&str>) -> Result<ModesAt, String>,
) -> Vec<CheckRow> {
    let mut checks = Vec::new();
    // The file's reference results, from the model's description (a copy: the model is
    // borrowed mutably below).
    let file_checks = model.description().checks.clone();

    checks.extend(drift_rows(model, simulations, &file_checks));

    // Reference values stated in the file.
    let at_of = |check: &ModalCheck| check.at.as_ref().map(|a| a.to_string());
    if let Some(check) = &file_checks.natural_frequencies {
        let computed = modes(at_of(check).as_deref()).map(|m| (m.label, m.natural_frequencies));
        checks.extend(modal_rows(
            "natural_frequencies",
            " (rad/s)",
            check,
            model,
            computed,
        ));
    }
    if let Some(check) = &file_checks.damping_ratios {
        let computed = modes(at_of(check).as_deref()).and_then(|m| {
            damped_modes(&m.linearization)
                .map(|d| (m.label, d.iter().map(|mode| mode.1).collect()))
                .map_err(|e| e.to_string())
        });
        checks.extend(modal_rows("damping_ratios", "", check, model, computed));
    }
    if let Some(check) = &file_checks.period {
        checks.push(period_row(model, simulations, check));
    }
    if let Some(check) = &file_checks.final_state {
        checks.extend(final_state_rows(model, simulations, check));
    }
    checks.extend(conserved_rows(
        model,
        y0,
        simulations,
        &file_checks.conserved,
    ));
    checks
}

/// The drift checks: the energy's for a conservative model (or where the file bounds it),
/// the constraints' for a constrained one, each over its run without stabilisation.
fn drift_rows(
    model: &mut dyn ModelInfo,
    simulations: &mut Simulations,
    file_checks: &eomgen_runtime::description::checks::Checks,
) -> Vec<CheckRow> {
    let mut rows = Vec::new();
    let default_run = CheckRun::default();
    // Generic: energy conservation (conservative models, or where the file asks for it).
    let energy = &file_checks.energy_drift;
    if model.description().conservative || energy.is_some() {
        let (bound, run) = energy
            .as_ref()
            .map_or((DEFAULT_ENERGY_DRIFT, default_run), |d| {
                (d.max, CheckRun::of(&d.run))
            });
        // Of `E` plus the energy lost at impacts (and the datum's moves at changes of
        // support), as `eomgen simulate` measures it.
        let computed = simulations
            .simulation(run)
            .and_then(|s| (s.energy.drift).ok_or_else(|| "no samples".to_string()));
        rows.push(CheckRow::compare(
            format!(
                "energy drift max|E − E(0)|/max(T + |V|) ({})",
                run.describe()
            ),
            computed,
            0.0,
            bound,
        ));
    }

    // Generic: constraint drift (constrained models).
    let constraint = &file_checks.constraint_drift;
    if !model.description().constraint_names().is_empty() || constraint.is_some() {
        let (bound, run) = constraint
            .as_ref()
            .map_or((DEFAULT_CONSTRAINT_DRIFT, default_run), |d| {
                (d.max, CheckRun::of(&d.run))
            });
        let computed = simulations.get(run).map(|s| {
            let (p, v) = constraint_drift(model, s).max_drift();
            p.max(v)
        });
        rows.push(CheckRow::compare(
            format!(
                "constraint drift max(|Φ|, |Φ̇|), no stabilisation ({})",
                run.describe()
            ),
            computed,
            0.0,
            bound,
        ));
    }
    rows
}

/// The period between the last two occurrences of the check's event, against its
/// expected value.
fn period_row(
    model: &mut dyn ModelInfo,
    simulations: &mut Simulations,
    check: &eomgen_runtime::description::checks::PeriodCheck,
) -> CheckRow {
    let mut run = CheckRun::of(&check.run);
    // Without `t_end:`, long enough for two zeros a period apart whatever the phase of
    // the first: at least PERIODS_PER_RUN expected periods.
    if check.run.t_end.is_none()
        && let Ok(period) = expected(&check.value, model)
        && period.is_finite()
        && period > 0.0
    {
        run.t_end = run.t_end.max(PERIODS_PER_RUN * period);
    }
    let event = &*check.event;
    let computed = simulations.get(run).and_then(|s| {
        let times: Vec<f64> = s
            .events
            .iter()
            .filter(|e| e.name == event)
            .map(|e| e.t)
            .collect();
        match times.as_slice() {
            [.., a, b] => Ok(b - a),
            _ => Err(format!(
                "event `{event}` occurred {} time(s) in {} s; a period needs two",
                times.len(),
                run.t_end
            )),
        }
    });
    let what = format!(
        "period between the last two `{event}` events (s) ({})",
        run.describe()
    );
    against_expected(what, computed, &check.value, model, check.tolerance)
}

/// Each coordinate or rate of the check at its time, against its expected value.
fn final_state_rows(
    model: &mut dyn ModelInfo,
    simulations: &mut Simulations,
    check: &eomgen_runtime::description::checks::FinalStateCheck,
) -> Vec<CheckRow> {
    let mut rows = Vec::new();
    match expected(&check.t, model) {
        Ok(t) if t.is_finite() && t > 0.0 => {
            let run = CheckRun {
                t_end: t,
                ..CheckRun::of(&check.run)
            };
            let state = simulations.run(run, Some(vec![t])).and_then(|s| {
                s.last()
                    .filter(|(ts, _)| *ts == t)
                    .map(|(_, y)| y.to_vec())
                    .ok_or_else(|| format!("the integration stopped before t = {t}"))
            });
            for (k, e) in check.values.iter() {
                let index = model.description().state_index(k);
                let computed = state.clone().and_then(|y| {
                    index
                        .map(|i| y[i])
                        .ok_or_else(|| format!("`{k}` is not a coordinate or rate"))
                });
                let what = format!("{k} at t = {} s ({})", fixed(t, 6), run.describe());
                rows.push(against_expected(what, computed, e, model, check.tolerance));
            }
        }
        Ok(t) => rows.push(CheckRow::compare(
            "final_state",
            Err(format!("t = {t} is not a positive time")),
            f64::NAN,
            check.tolerance,
        )),
        Err(e) => rows.push(CheckRow::compare(
            "final_state",
            Err(e),
            f64::NAN,
            check.tolerance,
        )),
    }
    rows
}

/// The drift of each `conserved:` quantity and each output declared conserved over the
/// default run, against its bound.
fn conserved_rows(
    model: &mut dyn ModelInfo,
    y0: &[f64],
    simulations: &mut Simulations,
    conserved: &[eomgen_runtime::description::checks::ConservedCheck],
) -> Vec<CheckRow> {
    let mut rows = Vec::new();
    let default_run = CheckRun::default();
    let parameters = parameter_lookup(model);
    for c in conserved {
        let value = parse(&c.value);
        let computed = simulations.get(default_run).and_then(|s| {
            let value = value.clone()?;
            // Q(0) at the initial state, as `simulate` measures an output's drift (the run's
            // samples need not begin at t = 0).
            let q0 = state_value(&value, model, &parameters, 0.0, y0)?;
            let mut worst: f64 = 0.0;
            for (t, y) in s.iter() {
                let q = state_value(&value, model, &parameters, t, y)?;
                worst = worst.max((q - q0).abs() / q0.abs().max(1.0));
            }
            Ok(worst)
        });
        rows.push(CheckRow::compare(
            format!(
                "conserved `{}`: max |Q − Q(0)|/max(1, |Q(0)|) ({})",
                c.name,
                default_run.describe()
            ),
            computed,
            0.0,
            c.tolerance,
        ));
    }
    // `outputs:` declared conserved: the drift of each over the default run, as a
    // `conserved:` entry's, against the output's bound.
    let conserved_outputs: Vec<(String, f64)> = model
        .description()
        .outputs
        .iter()
        .filter(|o| o.conserved)
        .map(|o| (o.name.to_string(), o.tolerance))
        .collect();
    if !conserved_outputs.is_empty() {
        let series = simulations.get(default_run).and_then(|s| {
            crate::outputs::evaluate_outputs(&*model, y0, s).map_err(|e| e.to_string())
        });
        for (name, tolerance) in conserved_outputs {
            let computed = series.clone().and_then(|all| {
                all.iter()
                    .find(|o| o.name == name)
                    .and_then(|o| o.drift)
                    .ok_or_else(|| "no samples".to_string())
            });
            rows.push(CheckRow::compare(
                format!(
                    "conserved output `{name}`: max |Q − Q(0)|/max(1, |Q(0)|) ({})",
                    default_run.describe()
                ),
                computed,
                0.0,
                tolerance,
            ));
        }
    }
    rows
}

/// The default run of a model's checks, with what a report draws of it.
#[derive(Debug, Clone)]
pub struct DefaultRun {
    /// Its settings ([`CheckRun::default`]).
    pub run: CheckRun,
    /// The solution, sampled at [`SAMPLES`] uniform times.
    pub solution: Solution,
    /// `E(t) = T + V` at every sample and `E(0)`.
    pub energy: EnergyDrift,
    /// `(max |Φ|, max |Φ̇|)` at every sample, for a constrained model (`None` without
    /// constraints).
    pub constraint_drift: Option<Vec<(f64, f64)>>,
}

/// Everything [`model_report`] found for one model: the rows of its pass/fail table and the
/// data of its figures.
#[derive(Debug, Clone)]
pub struct ModelChecks {
    /// The rows: the derivation cross-checks, then energy and constraint drift and the
    /// file's `checks:` ([`derivation_checks`], [`motion_checks`]).
    pub rows: Vec<CheckRow>,
    /// The notes of the derivation cross-checks.
    pub notes: Vec<String>,
    /// The default run, or why it failed; `None` when the model has no consistent initial
    /// state (a failed row says why).
    pub default_run: Option<Result<DefaultRun, String>>,
    /// The modal analysis at the equilibrium of the `natural_frequencies:` check (the first
    /// named one without), or why it failed; `None` unless the model names equilibria and has
    /// points to draw the mode shapes on.
    pub mode_shapes: Option<Result<ModalAnalysis, String>>,
    /// Wall time of the checks (s).
    pub time_s: f64,
}

impl ModelChecks {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.rows.iter().all(|c| c.passed)
    }
}

/// The checks of the models of one report (`eomgen report`), each model's name with its
/// rows: a report none of whose checks could be computed measured nothing.
pub struct ReportRows<'a>(pub Vec<(&'a str, &'a [CheckRow])>);

/// Every row is a run: computed (whether it passed or not), or not computed with its reason.
impl StudyRuns for ReportRows<'_> {
    fn study(&self) -> &'static str {
        "report"
    }

    fn tally(&self) -> RunTally {
        let mut tally = RunTally::default();
        for (model, rows) in &self.0 {
            for row in *rows {
                match row.computed {
                    Some(_) => tally.measured(),
                    None => tally.failed(format!(
                        "{model}: {}: {}",
                        row.check,
                        row.note.as_deref().unwrap_or("not computed")
                    )),
                }
            }
        }
        tally
    }
}

/// The diagnostics of a model file as one text: how many, then each with its source line
/// (as the CLI prints them).
pub fn diagnostics_text(path: &str, source: &str, diagnostics: &[Diagnostic]) -> String {
    let text: Vec<String> = diagnostics.iter().map(|d| d.render(path, source)).collect();
    format!(
        "{} error(s) in the model file `{path}`\n{}",
        diagnostics.len(),
        text.join("\n")
    )
}

/// The start of the equilibrium search that a check's `at:` names: a name of the file's
/// `equilibria:`, or guesses `q1=VALUE,…` (expressions of the parameters; others 0);
/// without `at:`, the first named equilibrium.
fn check_start(model: &dyn ModelInfo, at: Option<&str>) -> Result<EquilibriumStart, String> {
    let Some(at) = at else {
        return Ok(EquilibriumStart::FirstNamed);
    };
    if !at.contains('=') || model.equilibrium_guesses().iter().any(|(n, _)| *n == at) {
        return Ok(EquilibriumStart::Named(at.to_string()));
    }
    let lookup = parameter_lookup(model);
    let mut q = vec![0.0; model.num_dofs()];
    for part in crate::expressions::split_list(at) {
        let (name, text) = split_assignment(part, "at").map_err(|e| e.to_string())?;
        let index = model
            .description()
            .coordinate_names()
            .iter()
            .position(|c| *c == name)
            .ok_or_else(|| {
                format!(
                    "at: `{name}` is not a coordinate of `{}`",
                    model.description().name
                )
            })?;
        q[index] = evaluate(text, &format!("at {name}"), &lookup).map_err(|e| e.to_string())?;
    }
    Ok(EquilibriumStart::Guess {
        label: at.to_string(),
        q,
    })
}

/// The rows and notes of the derivation cross-checks of `file` ([`derivation_checks`]), or
/// one failed row with the diagnostics of the file at `path` (text `text`) when they fail.
fn derivation_rows(path: &str, text: &str, file: &ModelFile) -> (Vec<CheckRow>, Vec<String>) {
    derivation_checks(file).unwrap_or_else(|d| {
        let row = CheckRow::compare(
            "derivations agree",
            Err(diagnostics_text(path, text, &d)),
            0.0,
            DERIVATION_TOLERANCE,
        );
        (vec![row], Vec::new())
    })
}

/// Runs every check of one model (`eomgen report`'s section of it): the derivation
/// cross-checks of the file at `path` (whose text is `text`, for the diagnostics), then, from
/// the consistent initial state of `source`'s equations, the default run, energy and
/// constraint drift and the reference values of the file's `checks:`; the operating points of
/// the modal checks are found once each (Newton from the named equilibrium, at the
/// parameters' defaults). The mode shapes' analysis is returned for models that name
/// equilibria and have points.
///
/// Nothing fails: a check that cannot be computed is a failed row with its reason.
///
/// # Examples
/// ```
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/models/simple_pendulum.yaml");
/// let text = std::fs::read_to_string(path).unwrap();
/// let file = eomgen_symbolic::model::load(path, &text).unwrap();
/// let source = eomgen::ModelSource::open("simple_pendulum")?;
/// let checks = eomgen::checks::model_report(path, &text, &file, &source);
/// assert!(checks.passed(), "{:?}", checks.rows);
/// let frequency = checks.rows.iter().find(|r| r.check.starts_with("natural_frequencies")).unwrap();
/// assert!((frequency.computed.unwrap() - 10f64.sqrt()).abs() < 1e-12);
/// # Ok::<(), eomgen::OpenError>(())
/// ```
pub fn model_report(path: &str, text: &str, file: &ModelFile, source: &ModelSource) -> ModelChecks {
    let started = std::time::Instant::now();
    let (rows, notes) = derivation_rows(path, text, file);
    let mut out = ModelChecks {
        rows,
        notes,
        default_run: None,
        mode_shapes: None,
        time_s: 0.0,
    };
    let mut model = source.instantiate();
    let y0 = match model.consistent_initial_state() {
        Ok(y0) => y0,
        Err(e) => {
            out.rows.push(CheckRow::compare(
                "consistent initial state",
                Err(format!(
                    "constraint {} keeps a residual of {:.3e}",
                    e.constraint, e.residual
                )),
                0.0,
                0.0,
            ));
            out.time_s = started.elapsed().as_secs_f64();
            return out;
        }
    };
    let mut simulations = Simulations::new(source.clone());
    let run = CheckRun::default();
    out.default_run = Some(simulations.simulation(run).map(|simulation| {
        let solution = &simulation.solution;
        DefaultRun {
            run,
            solution: solution.clone(),
            energy: simulation.energy.clone(),
            constraint_drift: (!model.description().constraint_names().is_empty())
                .then(|| constraint_drift(model.as_mut(), solution).drift),
        }
    }));
    // The operating points, each found once (the modal checks and the mode shapes share them).
    let mut points: Vec<(Option<String>, Result<ModalAnalysis, String>)> = Vec::new();
    let mut analysis = |at: Option<&str>| -> Result<ModalAnalysis, String> {
        if let Some((_, done)) = points.iter().find(|(a, _)| a.as_deref() == at) {
            return done.clone();
        }
        // A fresh instance at the parameters' defaults.
        let model = source.instantiate();
        let result = check_start(model.as_ref(), at).and_then(|start| {
            let options = ModalOptions {
                operating_point: OperatingPointOptions {
                    start,
                    ..OperatingPointOptions::default()
                },
            };
            modal_analysis(model.as_ref(), &options)
                .map_err(|e| format!("`{}`: {e}", model.description().name))
        });
        points.push((at.map(str::to_string), result.clone()));
        result
    };
    out.rows.extend(motion_checks(
        model.as_mut(),
        &y0,
        &mut simulations,
        &mut |at| {
            analysis(at).map(|m| ModesAt {
                label: m.operating_point.name.clone(),
                natural_frequencies: m.normal_modes.natural_frequencies.clone(),
                linearization: m.linearization.clone(),
            })
        },
    ));
    if !model.equilibrium_guesses().is_empty() && !model.description().point_names().is_empty() {
        let at = model
            .description()
            .checks
            .natural_frequencies
            .as_ref()
            .and_then(|check| check.at.as_ref().map(|a| a.to_string()));
        // A steady motion (or any operating point of a non-holonomic model) has no mode
        // shapes of `M` and `K` to draw: its eigenvectors are those of the reduced state
        // matrix (`eomgen modes --at NAME`).
        let start = at.as_deref().map_or(EquilibriumStart::FirstNamed, |name| {
            EquilibriumStart::Named(name.to_string())
        });
        if !eomgen_runtime::analysis::vibration::is_steady_motion(model.as_ref(), &start) {
            out.mode_shapes = Some(analysis(at.as_deref()));
        }
    }
    out.time_s = started.elapsed().as_secs_f64();
    out
}

mod simulations;
pub use simulations::{CheckRun, DEFAULT_RTOL, DEFAULT_T_END, SAMPLES, Simulations};
#[cfg(test)]
mod tests;
