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
    CoreModel, RunOptions, instantiate, method, run_simulation, set_parameter, stabilization,
};

/// One run's outcome: the samples at the output times (NaN past a failure), the energy,
/// the work, and the failure if any.
struct Outcome {
    y: Vec<f64>,
    energy: Vec<f64>,
    stats: eomgen::Stats,
    /// `(t, message)` of a failed integration (`t` NaN before the first step).
    failure: Option<(f64, String)>,
}

/// Runs `b` simulations of `model` and stacks them: see `eomgen.Model.simulate_many`.
///
/// Returns `{"t" (k,), "y" (b, k, 2n), "energy" (b, k), "ok" (b,), "steps", "rejected",
/// "rhs_evals" (b,), "failures": [(index, t, message)]}`; a run that could not start (an
/// unknown parameter, constraints that cannot be met) raises.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (model, initial_states, parameters, t_end, t_out, method_name, rtol, atol, dt, stabilization_name, baumgarte, threads))]
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
) -> PyResult<Bound<'py, PyDict>> {
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
        let mut probe = model.fresh()?;
        for set in sets {
            for (name, value) in set {
                set_parameter(probe.as_mut(), name, *value)?;
            }
        }
    }
    let loaded = model.loaded.clone();
    let overrides = model.overrides.clone();
    let k = t_out.len();
    let one = |i: usize| -> Result<Outcome, String> {
        let mut instance = instantiate(&loaded, &overrides).map_err(|e| e.to_string())?;
        if let Some(sets) = &parameters {
            for (name, value) in &sets[i] {
                instance
                    .set_parameter(name, *value)
                    .map_err(|e| e.to_string())?;
            }
        }
        let run = RunOptions {
            options: SimulationOptions {
                initial_state: states.as_ref().map(|s| s[i].clone()),
                ..base.clone()
            },
            stop_when: Vec::new(),
            event: Vec::new(),
        };
        let simulation =
            run_simulation(instance.as_mut(), &run).map_err(|e| format!("run {i}: {e}"))?;
        let mut y = simulation.solution.y;
        let mut energy = simulation.energy.energy;
        y.resize(k * dim, f64::NAN);
        energy.resize(k, f64::NAN);
        Ok(Outcome {
            y,
            energy,
            stats: simulation.solution.stats,
            failure: simulation
                .failure
                .map(|e| (e.t().unwrap_or(f64::NAN), e.to_string())),
        })
    };
    let outcomes: Result<Vec<Outcome>, String> = py.detach(|| {
        let run_all = || (0..batch).into_par_iter().map(one).collect();
        match threads {
            Some(n) => rayon::ThreadPoolBuilder::new()
                .num_threads(n.max(1))
                .build()
                .map_err(|e| format!("the thread pool: {e}"))?
                .install(run_all),
            None => run_all(),
        }
    });
    let outcomes = outcomes.map_err(|message| match message.split_once(": ") {
        Some((_, rest)) if rest.starts_with("analysis: ") => {
            crate::errors::analysis_error(message.replacen("analysis: ", "", 1))
        }
        _ => pyo3::exceptions::PyValueError::new_err(message.replacen("value: ", "", 1)),
    })?;
    let out = PyDict::new(py);
    out.set_item("t", PyArray1::from_vec(py, t_out))?;
    let mut y = Vec::with_capacity(batch * k * dim);
    let mut energy = Vec::with_capacity(batch * k);
    let failures = PyList::empty(py);
    let (mut ok, mut steps, mut rejected, mut rhs_evals) = (
        Vec::with_capacity(batch),
        Vec::with_capacity(batch),
        Vec::with_capacity(batch),
        Vec::with_capacity(batch),
    );
    for (i, o) in outcomes.into_iter().enumerate() {
        y.extend_from_slice(&o.y);
        energy.extend_from_slice(&o.energy);
        ok.push(o.failure.is_none());
        steps.push(o.stats.steps as u64);
        rejected.push(o.stats.rejected as u64);
        rhs_evals.push(o.stats.rhs_evals as u64);
        if let Some((t, message)) = o.failure {
            failures.append((i, t, message))?;
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
    Ok(out)
}
