//! `simulate_many`: a batch of simulations of one model over initial states and parameter
//! sets, the library's [`eomgen::batch::simulate_batch`] with its results as numpy arrays.

use eomgen::OutputTimes;
use eomgen::analysis::SimulationOptions;
use eomgen::batch::{
    BatchError, BatchOptions, BatchReport, BatchRuns, check_batch, simulate_batch,
};
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::convert::matrix;
use crate::model::{
    CoreModel, MAX_OUTPUT_TIMES, RunError, check_bodies, method, not_started_hint, set_parameter,
    simulation_error, stabilization,
};

/// Runs `b` simulations of `model` and stacks them: see `eomgen.Model.simulate_many`.
///
/// Returns `{"t" (k,), "y" (b, k, 2n), "energy" (b, k), "ok" (b,), "t_final" (b,), "steps",
/// "rejected", "rhs_evals" (b,), "failures": [(index, t, reason)], "stopped_by_event":
/// [(index, t, event)]}`. Options every run shares that are refused raise `ValueError`; a
/// run whose initial state the constraints cannot accept raises `AnalysisError`, or with
/// `keep_failures` is a failure with `t` NaN.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (model, initial_states, parameters, t_end, t_out, method_name, rtol, atol, dt, stabilization_name, baumgarte, threads, keep_failures))]
pub fn simulate_many<'py>(
    py: Python<'py>,
    model: &CoreModel,
    initial_states: Option<PyReadonlyArray2<'py, f64>>,
    parameters: Option<Vec<Vec<(String, f64)>>>,
    t_end: f64,
    t_out: Vec<f64>,
    method_name: &str,
    rtol: f64,
    atol: f64,
    dt: Option<f64>,
    stabilization_name: &str,
    baumgarte: (f64, f64),
    threads: Option<usize>,
    keep_failures: bool,
) -> PyResult<Bound<'py, PyDict>> {
    if t_out.len() > MAX_OUTPUT_TIMES {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "t_out has {} times, at most {MAX_OUTPUT_TIMES} are allowed (as `eomgen simulate --t-out`)",
            t_out.len()
        )));
    }
    let dim = 2 * model.fresh()?.num_dofs();
    let runs = BatchRuns {
        initial_states: initial_states.as_ref().map(|a| {
            a.as_array()
                .rows()
                .into_iter()
                .map(|r| r.to_vec())
                .collect()
        }),
        parameters,
    };
    let mut options = BatchOptions {
        simulation: SimulationOptions {
            t_end,
            rtol,
            atol,
            dt,
            output: OutputTimes::At(t_out),
            ..SimulationOptions::default()
        },
        threads,
        keep_failures,
    };
    // The batch's shape first, then the method and every run's parameters.
    check_batch(&runs, &options, dim).map_err(|e| RunError::Value(e.to_string()).into_py())?;
    options.simulation.method = method(method_name)?;
    options.simulation.stabilization = stabilization(stabilization_name, baumgarte)?;
    // Every run's parameters are checked before any runs.
    if let Some(sets) = &runs.parameters {
        for set in sets {
            let mut probe = model.fresh()?;
            for (name, value) in set {
                set_parameter(probe.as_mut(), name, *value)?;
            }
            let all: Vec<(String, f64)> = model.overrides.iter().chain(set).cloned().collect();
            check_bodies(probe.as_ref(), &all)?;
        }
    }
    let (loaded, overrides) = (model.loaded.clone(), model.overrides.clone());
    let make = move || {
        let mut instance = loaded.source.instantiate_send();
        for (name, value) in &overrides {
            // Checked when the model was made.
            let _ = instance.set_parameter(name, *value);
        }
        instance
    };
    // Ctrl-C raises KeyboardInterrupt between chunks of runs, not at the batch's end.
    let mut interrupted = None;
    let report =
        py.detach(|| {
            simulate_batch(&make, &runs, &options, &mut || match Python::attach(|py| {
                py.check_signals()
            }) {
                Ok(()) => true,
                Err(e) => {
                    interrupted = Some(e);
                    false
                }
            })
        });
    let report = report.map_err(|e| batch_error(e, interrupted))?;
    stacked(py, report)
}

/// A batch's error as the Python layer raises it: the interpreter's own exception when it
/// stopped the batch (`interrupted`), `AnalysisError` for a run that cannot start (with what
/// to do) and for a thread pool that cannot be built, `ValueError` for the rest.
fn batch_error(e: BatchError, interrupted: Option<PyErr>) -> PyErr {
    match e {
        BatchError::Stopped => {
            interrupted.unwrap_or_else(|| pyo3::exceptions::PyKeyboardInterrupt::new_err(()))
        }
        BatchError::Run { run, source } => simulation_error(source)
            .context(&format!("run {run}"))
            .into_py(),
        e @ BatchError::ThreadPool(_) => RunError::Analysis(e.to_string()).into_py(),
        e => RunError::Value(e.to_string()).into_py(),
    }
}

/// The report of a batch as the dictionary `simulate_many` returns.
///
/// # Errors
/// A Python object that cannot be built.
fn stacked(py: Python<'_>, report: BatchReport) -> PyResult<Bound<'_, PyDict>> {
    let (batch, k, dim) = (report.ok.len(), report.t.len(), report.state_dimension);
    let out = PyDict::new(py);
    out.set_item("t", PyArray1::from_vec(py, report.t))?;
    let y = matrix(py, report.y, batch, k * dim)?.call_method1("reshape", (batch, k, dim))?;
    out.set_item("y", y)?;
    out.set_item("energy", matrix(py, report.energy, batch, k)?)?;
    out.set_item("ok", PyArray1::from_vec(py, report.ok))?;
    out.set_item("steps", PyArray1::from_vec(py, report.steps))?;
    out.set_item("rejected", PyArray1::from_vec(py, report.rejected))?;
    out.set_item("rhs_evals", PyArray1::from_vec(py, report.rhs_evals))?;
    let failures = PyList::empty(py);
    for f in report.failures {
        let reason = match f.not_started_with_guesses {
            Some(guesses) => format!("{}; {}", f.reason, not_started_hint(guesses)),
            None => f.reason,
        };
        failures.append((f.run, f.t, reason))?;
    }
    out.set_item("failures", failures)?;
    out.set_item("t_final", PyArray1::from_vec(py, report.t_final))?;
    let stopped = PyList::empty(py);
    for s in report.stopped_by_event {
        stopped.append((s.run, s.t, s.event))?;
    }
    out.set_item("stopped_by_event", stopped)?;
    Ok(out)
}
