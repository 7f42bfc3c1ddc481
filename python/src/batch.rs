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
    CoreModel, MAX_OUTPUT_TIMES, RunError, RunOptions, check_bodies, method, run_simulation,
    set_parameter, stabilization,
};

/// Most worker threads a batch may ask for (`threads=10000` spawned that many).
const MAX_THREADS: usize = 256;
/// Most numbers a batch returns (states and energies): 800 MB of `f64`.
const MAX_RESULT_VALUES: usize = 100_000_000;

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
    let dim = 2 * model.fresh()?.num_dofs();
    let (states, batch) = runs(
        initial_states.as_ref(),
        parameters.as_deref(),
        &t_out,
        threads,
        dim,
    )?;
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
    // In chunks of a few runs per thread, with the interpreter's signals checked between
    // them: Ctrl-C raises KeyboardInterrupt within a chunk's time, not at the batch's end.
    let outcomes: PyResult<Vec<Outcome>> = py.detach(|| {
        let pool = match threads {
            Some(n) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .map_err(|e| RunError::Analysis(format!("the thread pool: {e}")).into_py())?,
            ),
            None => None,
        };
        let workers = pool.as_ref().map_or_else(
            rayon::current_num_threads,
            rayon::ThreadPool::current_num_threads,
        );
        let chunk = 4 * workers.max(1);
        let mut all = Vec::with_capacity(batch);
        for start in (0..batch).step_by(chunk) {
            let runs = start..(start + chunk).min(batch);
            let part: Result<Vec<Outcome>, RunError> = match &pool {
                Some(pool) => pool.install(|| runs.into_par_iter().map(&one).collect()),
                None => runs.into_par_iter().map(&one).collect(),
            };
            all.extend(part.map_err(RunError::into_py)?);
            Python::attach(|py| py.check_signals())?;
        }
        Ok(all)
    });
    stacked(py, outcomes?, t_out, t_end, dim)
}

/// The initial states of a batch (one row of `dim` per run) and its number of runs, checked
/// with the options every run shares.
///
/// # Errors
/// `ValueError` for a thread count, output times, states or parameter sets that are refused,
/// or a result too large to return.
fn runs(
    initial_states: Option<&PyReadonlyArray2<'_, f64>>,
    parameters: Option<&[Vec<(String, f64)>]>,
    t_out: &[f64],
    threads: Option<usize>,
    dim: usize,
) -> PyResult<(Option<Vec<Vec<f64>>>, usize)> {
    if let Some(n) = threads
        && !(1..=MAX_THREADS).contains(&n)
    {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "threads must be 1 to {MAX_THREADS}, got {n} (None: one per core)"
        )));
    }
    if t_out.len() > MAX_OUTPUT_TIMES {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "t_out has {} times, at most {MAX_OUTPUT_TIMES} are allowed (as `eomgen simulate --t-out`)",
            t_out.len()
        )));
    }
    let states: Option<Vec<Vec<f64>>> = match initial_states {
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
    let batch = match (&states, parameters) {
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
    // The states and energies returned: refused before any run when they would not fit
    // (1e5 runs of 1e5 times aborted the interpreter on a failed allocation).
    let values = batch
        .checked_mul(t_out.len())
        .and_then(|v| v.checked_mul(dim + 1));
    if values.is_none_or(|v| v > MAX_RESULT_VALUES) {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "{batch} runs × {} output times × {} values per sample is more than the {MAX_RESULT_VALUES} numbers (800 MB) a batch may return; run it in parts",
            t_out.len(),
            dim + 1
        )));
    }
    Ok((states, batch))
}

/// The outcomes of a batch stacked into the dictionary `simulate_many` returns.
///
/// # Errors
/// A Python object that cannot be built.
fn stacked(
    py: Python<'_>,
    outcomes: Vec<Outcome>,
    t_out: Vec<f64>,
    t_end: f64,
    dim: usize,
) -> PyResult<Bound<'_, PyDict>> {
    let (batch, k) = (outcomes.len(), t_out.len());
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
