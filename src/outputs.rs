//! A model's `outputs:` along a simulation: each named expression of the state evaluated at
//! every sample, and for the outputs the file declares conserved (`conserved: true`) their
//! drift `max |Q(t) − Q(0)| / max(1, |Q(0)|)` against the file's bound — the measure of a
//! `checks: conserved:` entry, beside the energy drift (lectures 3–7: the angular momentum
//! of a central force and of many particles is a constant of the motion).
//!
//! `eomgen simulate` prints the drift of every conserved output and writes every output to
//! its CSV and JSON; `eomgen report` checks the conserved ones
//! ([`crate::checks::motion_checks`]). The expressions are the model's description's
//! ([`eomgen_runtime::description::outputs::OutputSpec`]), so a compiled model and a file
//! loaded at run time give the same values.

use eomgen_runtime::{ModelInfo, Solution};
use eomgen_symbolic::model::parser::{eval_expr, parse_expr};
use eomgen_symbolic::model::{Expr, Location};
use serde::Serialize;

use crate::expressions::parameter_lookup;

/// One output along a simulation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OutputSeries {
    /// Its name in the model file (`L`).
    pub name: String,
    /// Its expression, as the model's description keeps it.
    pub value: String,
    /// Whether the file declares it a constant of the motion.
    pub conserved: bool,
    /// The bound on [`Self::drift`] (conserved outputs only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// Its value `Q(0)` at the initial state (units of the expression), the reference of
    /// [`Self::drift`]: a run's samples need not include `t = 0` (`--t-out 1000`).
    pub initial: f64,
    /// Its value at each sample of the solution (units of the expression).
    pub values: Vec<f64>,
    /// `max |Q(t) − Q(0)| / max(1, |Q(0)|)` over the samples, `Q(0)` the value at the
    /// initial state (conserved outputs with at least one sample only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drift: Option<f64>,
    /// Whether [`Self::drift`] is within [`Self::tolerance`] (conserved outputs only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub within_tolerance: Option<bool>,
}

impl OutputSeries {
    /// Whether the output is declared conserved but drifted beyond its bound.
    pub fn drifted(&self) -> bool {
        self.within_tolerance == Some(false)
    }
}

/// Why an output could not be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// The expression does not parse or names something the model lacks (a model
    /// description not built from its file).
    #[error("output `{name}`: {message} in `{value}`")]
    Expression {
        /// The output.
        name: String,
        /// Its expression.
        value: String,
        /// What is wrong.
        message: String,
    },
    /// The value is not a finite number at a sample.
    #[error("output `{name}` is {value} at t = {t}, not a finite number")]
    NotFinite {
        /// The output.
        name: String,
        /// The time of the sample.
        t: f64,
        /// The value.
        value: f64,
    },
}

/// Evaluates `model`'s outputs at the initial state `y0` (at `t = 0`) and at every sample of
/// `solution` (a solution of `model` from `y0`, with its current parameter values); for a
/// conserved output also its drift `max |Q(t) − Q(0)| / max(1, |Q(0)|)` from the initial
/// value, as [`crate::analysis::energy_drift`] measures the energy's, and whether it is within
/// the file's bound.
///
/// `y0` and `solution`'s states are `[q; q̇]` of `model` (length `2n`). An empty `solution`
/// gives empty series without drift.
///
/// # Errors
/// [`OutputError::Expression`] if an expression does not evaluate,
/// [`OutputError::NotFinite`] at the first sample where a value is infinite or NaN.
///
/// # Examples
/// ```
/// use eomgen::analysis::{SimulationOptions, simulate};
///
/// let source = eomgen::ModelSource::open("two_body")?;
/// let mut model = source.instantiate();
/// let options = SimulationOptions {
///     method: eomgen::Method::Dop853,
///     t_end: 1.0,
///     rtol: 1e-12,
///     atol: 1e-12,
///     ..SimulationOptions::default()
/// };
/// let run = simulate(model.as_mut(), &options).unwrap();
/// let outputs =
///     eomgen::outputs::evaluate_outputs(model.as_ref(), &run.initial_state, &run.solution)
///         .unwrap();
/// let l = outputs.iter().find(|o| o.name == "angular_momentum").unwrap();
/// // L = m1 m2/(m1 + m2) d² ω = 2/√3 (the file's header), kept to the integration's error.
/// assert!((l.values[0] - 2.0 / 3f64.sqrt()).abs() < 1e-15);
/// assert!(l.within_tolerance == Some(true), "{:?}", l.drift);
/// # Ok::<(), eomgen::OpenError>(())
/// ```
pub fn evaluate_outputs(
    model: &dyn ModelInfo,
    y0: &[f64],
    solution: &Solution,
) -> Result<Vec<OutputSeries>, OutputError> {
    let description = model.description();
    let parameters = parameter_lookup(model);
    let mut series = Vec::with_capacity(description.outputs.len());
    for output in description.outputs.iter() {
        let (name, value) = (output.name.to_string(), output.value.to_string());
        let expression_error = |message: String| OutputError::Expression {
            name: name.clone(),
            value: value.clone(),
            message,
        };
        let e: Expr = parse_expr(&value, Location { line: 1, column: 1 })
            .map_err(|d| expression_error(d.message))?;
        let mut values = Vec::with_capacity(solution.len());
        let mut initial = None;
        // The initial state only with samples to compare with it: an empty solution gives an
        // empty series (and `initial` NaN), whatever the output is at the start.
        let start = (!solution.is_empty()).then_some((0.0, y0));
        if start.is_none() {
            initial = Some(f64::NAN);
        }
        for (t, y) in start.into_iter().chain(solution.iter()) {
            let v = eval_expr(&e, &|k| {
                if k == "t" {
                    return Some(t);
                }
                if let Some(v) = parameters(k) {
                    return Some(v);
                }
                description.state_index(k).map(|i| y[i])
            })
            .map_err(|d| expression_error(d.message))?;
            if !v.is_finite() {
                return Err(OutputError::NotFinite { name, t, value: v });
            }
            match initial {
                None => initial = Some(v),
                Some(_) => values.push(v),
            }
        }
        let initial = initial.unwrap_or(f64::NAN);
        let drift = match (output.conserved, values.is_empty()) {
            (true, false) => Some({
                let q0 = initial;
                values
                    .iter()
                    .map(|q| (q - q0).abs() / q0.abs().max(1.0))
                    .fold(0.0, f64::max)
            }),
            _ => None,
        };
        series.push(OutputSeries {
            name,
            value,
            initial,
            conserved: output.conserved,
            tolerance: output.conserved.then_some(output.tolerance),
            values,
            drift,
            within_tolerance: drift.map(|d| d <= output.tolerance),
        });
    }
    Ok(series)
}
