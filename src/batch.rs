//! A batch of simulations of one model over initial states and parameter sets, spread over
//! the machine's cores (rayon) and stacked into arrays: what a sweep, a Monte Carlo study or a
//! basin-of-attraction chart runs. Each run is [`simulate`] on an instance of its own, so a
//! batch gives the bits of the serial loop whatever the number of threads. Python's
//! `Model.simulate_many` calls [`simulate_batch`].

use serde::Serialize;

use crate::analysis::{SimulationError, SimulationOptions, simulate};
use crate::{ModelInfo, OutputTimes, Stats};

/// Most worker threads a batch may ask for (`threads = 10000` would spawn that many).
pub const MAX_BATCH_THREADS: usize = 256;

/// Most numbers a batch returns (its states and energies): 800 MB of `f64`.
pub const MAX_BATCH_VALUES: usize = 100_000_000;

/// The runs of a batch: one per row of `initial_states`, one per entry of `parameters`, or
/// one per pair of both (then of equal length).
#[derive(Debug, Clone, Default)]
pub struct BatchRuns {
    /// Run `i`'s initial state `[q; q̇]` (`2n` values each); `None`: the model's own.
    pub initial_states: Option<Vec<Vec<f64>>>,
    /// Run `i`'s parameters, `(name, value)` set in order over the model's; `None`: the
    /// model's own.
    pub parameters: Option<Vec<Vec<(String, f64)>>>,
}

/// What every run of a batch shares.
#[derive(Debug, Clone)]
pub struct BatchOptions {
    /// The simulation of each run; its output must be [`OutputTimes::At`] (the batch stacks
    /// the runs at the same times), its `initial_state` is each run's.
    pub simulation: SimulationOptions,
    /// Worker threads, `1 … MAX_BATCH_THREADS`; `None`: rayon's pool (one per core).
    pub threads: Option<usize>,
    /// Keep a run whose initial state the constraints cannot accept as a failure of its own
    /// ([`BatchReport::failures`], at `t` NaN); `false`: the batch stops with it
    /// ([`BatchError::Run`]). A run whose integration fails is always kept, with its samples
    /// before the failure.
    pub keep_failures: bool,
}

/// A batch's results, `b` runs at `k` output times of a state of `d = 2n` values.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BatchReport {
    /// The output times (s), `k`.
    pub t: Vec<f64>,
    /// The state's size `d = 2n`.
    pub state_dimension: usize,
    /// The states, run by run and time by time: `b × k × d` values, NaN past a run's end.
    pub y: Vec<f64>,
    /// The energy (J) at each output time, `b × k`, NaN past a run's end.
    pub energy: Vec<f64>,
    /// Whether run `i` reached its end (`t_end` or a terminal event).
    pub ok: Vec<bool>,
    /// Where run `i` ended (s): `t_end`, the event's time, the failure's; NaN for a run that
    /// did not start.
    pub t_final: Vec<f64>,
    /// Accepted steps of run `i`.
    pub steps: Vec<u64>,
    /// Rejected step attempts of run `i`.
    pub rejected: Vec<u64>,
    /// Right-hand side evaluations of run `i`.
    pub rhs_evals: Vec<u64>,
    /// The runs kept as failures, in order.
    pub failures: Vec<RunFailure>,
    /// The runs a terminal event of the model file ended, in order.
    pub stopped_by_event: Vec<RunStop>,
}

/// A run of a batch that failed: its integration stopped, or (kept with
/// [`BatchOptions::keep_failures`]) it could not start.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunFailure {
    /// The run's index.
    pub run: usize,
    /// Where it stopped (s); NaN when it did not start.
    pub t: f64,
    /// Why.
    pub reason: String,
    /// For a run whose initial state the constraints could not accept: whether the model
    /// marks coordinates of its initial state as guesses that Newton solves from (then other
    /// guesses may start it; else consistent values must be given). `None` for a run that
    /// started.
    pub not_started_with_guesses: Option<bool>,
}

/// A run of a batch that a terminal event ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunStop {
    /// The run's index.
    pub run: usize,
    /// The event's time (s).
    pub t: f64,
    /// The event's name.
    pub event: String,
}

/// Why a batch gave no results.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// Options or runs refused before any run (the message says which and what is allowed).
    #[error("{0}")]
    Refused(String),
    /// A run that could not start, without [`BatchOptions::keep_failures`].
    #[error("run {run}: {source}")]
    Run {
        /// The run's index.
        run: usize,
        /// Why.
        #[source]
        source: SimulationError,
    },
    /// A parameter of a run that the model does not have.
    #[error("run {run}: {reason}")]
    Parameter {
        /// The run's index.
        run: usize,
        /// The model's message.
        reason: String,
    },
    /// The caller asked to stop between chunks of runs.
    #[error("stopped between runs")]
    Stopped,
    /// The thread pool could not be built.
    #[error("the thread pool: {0}")]
    ThreadPool(String),
}

/// How a run ended.
enum Ended {
    Reached,
    Event(f64, String),
    Failed(f64, String),
    NotStarted(String, bool),
}

/// One run's samples, energies, work and end.
struct Outcome {
    y: Vec<f64>,
    energy: Vec<f64>,
    stats: Stats,
    end: Ended,
}

/// Runs the batch `runs` of the model that `make` instantiates, with `options`, and stacks the
/// results ([`BatchReport`]).
///
/// The runs go in chunks of four per worker; `keep_going` is called on the calling thread
/// after each chunk (an interpreter checks its signals there), and `false` stops the batch
/// ([`BatchError::Stopped`]).
///
/// # Errors
/// [`BatchError::Refused`] for a thread count out of `1 …` [`MAX_BATCH_THREADS`], output times
/// that are not [`OutputTimes::At`] or none, states of the wrong size, runs of unequal counts
/// or none, a result of more than [`MAX_BATCH_VALUES`] numbers, or options every run would
/// refuse; [`BatchError::Parameter`] for an unknown parameter; [`BatchError::Run`] for a run
/// that cannot start, without [`BatchOptions::keep_failures`].
pub fn simulate_batch(
    make: &(dyn Fn() -> Box<dyn ModelInfo + Send> + Sync),
    runs: &BatchRuns,
    options: &BatchOptions,
    keep_going: &mut dyn FnMut() -> bool,
) -> Result<BatchReport, BatchError> {
    use rayon::prelude::*;
    let dim = 2 * make().num_dofs();
    let batch = check_batch(runs, options, dim)?;
    let OutputTimes::At(t_out) = &options.simulation.output else {
        return Err(BatchError::Refused("no output times".into()));
    };
    let k = t_out.len();
    let one = |i: usize| -> Result<Outcome, BatchError> {
        let mut model = make();
        for (name, value) in runs.parameters.iter().flat_map(|p| &p[i]) {
            model
                .set_parameter(name, *value)
                .map_err(|e| BatchError::Parameter {
                    run: i,
                    reason: e.to_string(),
                })?;
        }
        let mut simulation_options = options.simulation.clone();
        simulation_options.initial_state = runs.initial_states.as_ref().map(|s| s[i].clone());
        run(
            model.as_mut(),
            &simulation_options,
            (i, k, dim),
            options.keep_failures,
        )
    };
    let pool = match options.threads {
        Some(n) => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| BatchError::ThreadPool(e.to_string()))?,
        ),
        None => None,
    };
    let workers = pool.as_ref().map_or_else(
        rayon::current_num_threads,
        rayon::ThreadPool::current_num_threads,
    );
    let chunk = 4 * workers.max(1);
    let mut outcomes = Vec::with_capacity(batch);
    for start in (0..batch).step_by(chunk) {
        let runs = start..(start + chunk).min(batch);
        let part: Result<Vec<Outcome>, BatchError> = match &pool {
            Some(pool) => pool.install(|| runs.into_par_iter().map(&one).collect()),
            None => runs.into_par_iter().map(&one).collect(),
        };
        outcomes.extend(part?);
        if !keep_going() {
            return Err(BatchError::Stopped);
        }
    }
    Ok(stacked(
        outcomes,
        t_out.to_vec(),
        options.simulation.t_end,
        dim,
    ))
}

/// The number of runs of the batch `runs` with `options`, for a model whose state has
/// `state_dimension` values: what [`simulate_batch`] checks before any run, for a caller
/// that checks its own arguments after these.
///
/// # Errors
/// [`BatchError::Refused`] as [`simulate_batch`] says.
pub fn check_batch(
    runs: &BatchRuns,
    options: &BatchOptions,
    state_dimension: usize,
) -> Result<usize, BatchError> {
    let dim = state_dimension;
    let refused = |m: String| Err(BatchError::Refused(m));
    if let Some(n) = options.threads
        && !(1..=MAX_BATCH_THREADS).contains(&n)
    {
        return refused(format!(
            "threads must be 1 to {MAX_BATCH_THREADS}, got {n} (None: one per core)"
        ));
    }
    let OutputTimes::At(t_out) = &options.simulation.output else {
        return refused("a batch samples every run at the same output times: give them".into());
    };
    if t_out.is_empty() {
        return refused("t_out must list at least one output time".into());
    }
    if let Some(bad) = runs
        .initial_states
        .iter()
        .flatten()
        .find(|s| s.len() != dim)
    {
        return refused(format!(
            "initial_states must have {dim} columns ([q; q̇]), got {}",
            bad.len()
        ));
    }
    let batch = match (&runs.initial_states, &runs.parameters) {
        (Some(s), Some(p)) if s.len() != p.len() => {
            return refused(format!(
                "initial_states has {} rows and parameters {} entries: give one per run, or only one of them",
                s.len(),
                p.len()
            ));
        }
        (Some(s), _) => s.len(),
        (None, Some(p)) => p.len(),
        (None, None) => {
            return refused("give initial_states (b × 2n), parameters (b dicts), or both".into());
        }
    };
    if batch == 0 {
        return refused("the batch is empty: a sweep of no run measures nothing".into());
    }
    // The states and energies returned: refused before any run when they would not fit
    // (1e5 runs of 1e5 times aborted an interpreter on a failed allocation).
    let values = batch
        .checked_mul(t_out.len())
        .and_then(|v| v.checked_mul(dim + 1));
    if values.is_none_or(|v| v > MAX_BATCH_VALUES) {
        return refused(format!(
            "{batch} runs × {} output times × {} values per sample is more than the {MAX_BATCH_VALUES} numbers (800 MB) a batch may return; run it in parts",
            t_out.len(),
            dim + 1
        ));
    }
    Ok(batch)
}

/// Run `i` of `k` output times of a state of `dim` values, on `model`.
fn run(
    model: &mut dyn ModelInfo,
    options: &SimulationOptions,
    (i, k, dim): (usize, usize, usize),
    keep_failures: bool,
) -> Result<Outcome, BatchError> {
    let simulation = match simulate(model, options) {
        Ok(simulation) => simulation,
        // A state the constraints cannot accept is this run's; kept when asked.
        Err(e @ SimulationError::InconsistentInitialState { has_guesses, .. }) if keep_failures => {
            return Ok(Outcome {
                y: vec![f64::NAN; k * dim],
                energy: vec![f64::NAN; k],
                stats: Stats::default(),
                end: Ended::NotStarted(e.to_string(), has_guesses),
            });
        }
        Err(source) => return Err(BatchError::Run { run: i, source }),
    };
    let end = match (&simulation.failure, simulation.solution.terminated_by_event) {
        // Options refused before the first step are every run's: not a run's failure.
        (Some(e), _) if e.t().is_none() => return Err(BatchError::Refused(e.to_string())),
        (Some(e), _) => Ended::Failed(e.t().unwrap_or(f64::NAN), e.to_string()),
        (None, Some(event)) => {
            let event = &simulation.solution.events[event];
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
}

/// The outcomes stacked into a [`BatchReport`].
fn stacked(outcomes: Vec<Outcome>, t: Vec<f64>, t_end: f64, dim: usize) -> BatchReport {
    let (batch, k) = (outcomes.len(), t.len());
    let mut report = BatchReport {
        t,
        state_dimension: dim,
        y: Vec::with_capacity(batch * k * dim),
        energy: Vec::with_capacity(batch * k),
        ok: Vec::with_capacity(batch),
        t_final: Vec::with_capacity(batch),
        steps: Vec::with_capacity(batch),
        rejected: Vec::with_capacity(batch),
        rhs_evals: Vec::with_capacity(batch),
        failures: Vec::new(),
        stopped_by_event: Vec::new(),
    };
    for (run, o) in outcomes.into_iter().enumerate() {
        report.y.extend_from_slice(&o.y);
        report.energy.extend_from_slice(&o.energy);
        report.steps.push(o.stats.steps as u64);
        report.rejected.push(o.stats.rejected as u64);
        report.rhs_evals.push(o.stats.rhs_evals as u64);
        let (ok, t_final) = match o.end {
            Ended::Reached => (true, t_end),
            Ended::Event(t, event) => {
                report.stopped_by_event.push(RunStop { run, t, event });
                (true, t)
            }
            Ended::Failed(t, reason) => {
                report.failures.push(RunFailure {
                    run,
                    t,
                    reason,
                    not_started_with_guesses: None,
                });
                (false, t)
            }
            Ended::NotStarted(reason, has_guesses) => {
                let t = f64::NAN;
                report.failures.push(RunFailure {
                    run,
                    t,
                    reason,
                    not_started_with_guesses: Some(has_guesses),
                });
                (false, t)
            }
        };
        report.ok.push(ok);
        report.t_final.push(t_final);
    }
    report
}
