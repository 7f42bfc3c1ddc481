//! `simulate_many`: a batch of simulations of one model over initial states and parameter
//! sets, spread over the machine's cores by rayon, stacked into arrays. Each run is the same
//! library call as `Model.simulate`, on an instance of its own, so a batch gives the bits of
//! the serial loop whatever the number of threads.

use eomgen::OutputTimes;
use eomgen::analysis::SimulationOptions;
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;

use crate::convert::matrix;
use crate::model::{
    CoreModel, RunError, RunOptions, check_bodies, method, run_simulation, set_parameter,
    stabilization,
};

/// How a run ended.
enum Ended {
    /// At `t_end`.
    Reached,
    /// At a terminal event of the model file: `(t, name)`.
    Event(f64, String),
    /// An integration failure: `(t, reason)`.
    Failed(f64, String),
    /// No start: the initial state does not satisfy the constraints (kept with
    /// `errors="keep"`).
    NotStarted(String),
}

/// One run's outcome: the samples at the output times (NaN past the run's end), the energy,
/// the work, and how it ended.
struct Outcome {
    y: Vec<f64>,
    energy: Vec<f64>,
    stats: eomgen::Stats,
    end: Ended,
}

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
    if threads == Some(0) {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "threads must be at least 1 (None: one per core)",
        ));
    }
    let dim = 2 * model.fresh()?.num_dofs();
    let states: Option<Vec<Vec<f64>>> = match &initial_states {
        Some(a) => {
            let view = a.as_array();
            if view.ncols() != dim {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "initial_states must have {dim} columns ([q; q̇]), got {}",
                    view.ncols()
                )));
            }
            Some(view.rows().into_iter().map(|r| r.to_vec()).collect())
        }
        None => None,
    };
    let batch = match (&states, &parameters) {
        (Some(s), Some(p)) if s.len() != p.len() => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "initial_states has {} rows and parameters {} entries: give one per run, or only one of them",
                s.len(),
                p.len()
            )));
        }
        (Some(s), _) => s.len(),
        (None, Some(p)) => p.len(),
        (None, None) => {
            return Err(pyo3::exceptions::PyValueError::new_err(
                "give initial_states (b × 2n), parameters (b dicts), or both",
            ));
        }
    };
    if batch == 0 {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "the batch is empty: a sweep of no run measures nothing",
        ));
    }
    if t_out.is_empty() {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "t_out must list at least one output time",
        ));
    }
    let base = SimulationOptions {
        method: method(method_name)?,
        t_end,
        rtol,
        atol,
        dt,
        output: OutputTimes::At(t_out.clone()),
        stabilization: stabilization(stabilization_name, baumgarte)?,
        initial_state: None,
    };
    // Every run's parameters are checked before any runs.
    if let Some(sets) = &parameters {
        for set in sets {
            let mut probe = model.fresh()?;
            for (name, value) in set {
                set_parameter(probe.as_mut(), name, *value)?;
            }
            let all: Vec<(String, f64)> = model.overrides.iter().chain(set).cloned().collect();
            check_bodies(probe.as_ref(), &all)?;
        }
    }
    let loaded = model.loaded.clone();
    let overrides = model.overrides.clone();
    let k = t_out.len();
    // One run on a thread of the pool: plain data in and out (no interpreter objects).
    let one = |i: usize| -> Result<Outcome, RunError> {
        let mut instance = loaded.source.instantiate_send();
        let sets = overrides
            .iter()
            .chain(parameters.iter().flat_map(|p| &p[i]));
        for (name, value) in sets {
            instance
                .set_parameter(name, *value)
                .map_err(|e| RunError::Value(e.to_string()))?;
        }
        let run = RunOptions {
            options: SimulationOptions {
                initial_state: states.as_ref().map(|s| s[i].clone()),
                ..base.clone()
            },
            stop_when: Vec::new(),
            event: Vec::new(),
        };
        let simulation = match run_simulation(instance.as_mut(), &run) {
            Ok(simulation) => simulation,
            // A state the constraints cannot accept is this run's; kept when asked.
            Err(RunError::Analysis(reason)) if keep_failures => {
                return Ok(Outcome {
                    y: vec![f64::NAN; k * dim],
                    energy: vec![f64::NAN; k],
                    stats: eomgen::Stats::default(),
                    end: Ended::NotStarted(reason),
                });
            }
            Err(e) => return Err(e.context(&format!("run {i}"))),
        };
        let end = match (&simulation.failure, simulation.solution.terminated_by_event) {
            // Options refused before the first step are every run's: not a run's failure.
            (Some(e), _) if e.t().is_none() => return Err(RunError::Value(e.to_string())),
            (Some(e), _) => Ended::Failed(e.t().unwrap_or(f64::NAN), e.to_string()),
            (None, Some(k)) => {
                let event = &simulation.solution.events[k];
                Ended::Event(event.t, event.name.clone())
            }
            (None, None) => Ended::Reached,
        };
        let mut y = simulation.solution.y;
        let mut energy = simulation.energy.energy;
        y.resize(k * dim, f64::NAN);
        energy.resize(k, f64::NAN);
        Ok(Outcome {
            y,
            energy,
            stats: simulation.solution.stats,
            end,
        })
    };
    let outcomes: Result<Vec<Outcome>, RunError> = py.detach(|| {
        let run_all = || (0..batch).into_par_iter().map(one).collect();
        match threads {
            Some(n) => rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| RunError::Analysis(format!("the thread pool: {e}")))?
                .install(run_all),
            None => run_all(),
        }
    });
    let outcomes = outcomes.map_err(RunError::into_py)?;
    let out = PyDict::new(py);
    out.set_item("t", PyArray1::from_vec(py, t_out))?;
    let mut y = Vec::with_capacity(batch * k * dim);
    let mut energy = Vec::with_capacity(batch * k);
    let failures = PyList::empty(py);
    let stopped = PyList::empty(py);
    let (mut ok, mut t_final, mut steps, mut rejected, mut rhs_evals) = (
        Vec::with_capacity(batch),
        Vec::with_capacity(batch),
        Vec::with_capacity(batch),
        Vec::with_capacity(batch),
        Vec::with_capacity(batch),
    );
    for (i, o) in outcomes.into_iter().enumerate() {
        y.extend_from_slice(&o.y);
        energy.extend_from_slice(&o.energy);
        steps.push(o.stats.steps as u64);
        rejected.push(o.stats.rejected as u64);
        rhs_evals.push(o.stats.rhs_evals as u64);
        match o.end {
            Ended::Reached => {
                ok.push(true);
                t_final.push(t_end);
            }
            Ended::Event(t, name) => {
                ok.push(true);
                t_final.push(t);
                stopped.append((i, t, name))?;
            }
            Ended::Failed(t, reason) => {
                ok.push(false);
                t_final.push(t);
                failures.append((i, t, reason))?;
            }
            Ended::NotStarted(reason) => {
                ok.push(false);
                t_final.push(f64::NAN);
                failures.append((i, f64::NAN, reason))?;
            }
        }
    }
    let y = matrix(py, y, batch, k * dim)?.call_method1("reshape", (batch, k, dim))?;
    out.set_item("y", y)?;
    out.set_item("energy", matrix(py, energy, batch, k)?)?;
    out.set_item("ok", PyArray1::from_vec(py, ok))?;
    out.set_item("steps", PyArray1::from_vec(py, steps))?;
    out.set_item("rejected", PyArray1::from_vec(py, rejected))?;
    out.set_item("rhs_evals", PyArray1::from_vec(py, rhs_evals))?;
    out.set_item("failures", failures)?;
    out.set_item("t_final", PyArray1::from_vec(py, t_final))?;
    out.set_item("stopped_by_event", stopped)?;
    Ok(out)
}
