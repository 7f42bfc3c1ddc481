//! How a check integrates ([`CheckRun`]) and the simulations of one model that its checks and
//! a report's figures share ([`Simulations`]).

use serde::Serialize;

use crate::ModelSource;
use crate::analysis::{Method, SimulationOptions, simulate};
use crate::text::fixed;
use eomgen_runtime::analysis::Simulation;
use eomgen_runtime::description::checks::RunSettings;
use eomgen_runtime::{OutputTimes, Solution};

/// Default end time of a check's simulation (s).
pub const DEFAULT_T_END: f64 = 10.0;
/// Default relative and absolute tolerance of a check's simulation.
pub const DEFAULT_RTOL: f64 = 1e-12;
/// Samples of a check's simulation (uniform in t, both ends included).
pub const SAMPLES: usize = 1001;

/// How a check integrates: method, `rtol = atol`, end time (the file's `run:` settings).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CheckRun {
    /// The method (default: DOP853).
    pub method: Method,
    /// Relative and absolute tolerance (default: [`DEFAULT_RTOL`]).
    pub rtol: f64,
    /// End time (s) (default: [`DEFAULT_T_END`]).
    pub t_end: f64,
}

impl CheckRun {
    /// The run a check's `run:` settings ask for, the defaults filling in.
    pub fn of(settings: &RunSettings) -> Self {
        let method = settings
            .method
            .as_ref()
            .and_then(|m| m.parse::<Method>().ok())
            .unwrap_or(Method::Dop853);
        Self {
            method,
            rtol: settings.rtol.unwrap_or(DEFAULT_RTOL),
            t_end: settings.t_end.unwrap_or(DEFAULT_T_END),
        }
    }

    /// `dop853, rtol 1e-12, 10 s`, as the rows name their settings.
    pub fn describe(&self) -> String {
        let method = self.method.name();
        format!("{method}, rtol {:e}, {} s", self.rtol, fixed(self.t_end, 6))
    }
}

impl Default for CheckRun {
    fn default() -> Self {
        Self::of(&RunSettings::default())
    }
}

/// The simulations of one model that its checks (and a report's figures) share, each run
/// once: a fresh instance of the model from its consistent initial state, sampled at
/// [`SAMPLES`] uniform times, with the file's events located on the way.
pub struct Simulations {
    source: ModelSource,
    done: Vec<(CheckRun, Result<Simulation, String>)>,
}

impl Simulations {
    /// No simulation of `source` yet.
    pub fn new(source: ModelSource) -> Self {
        Self {
            source,
            done: Vec::new(),
        }
    }

    /// The solution of `run` (computed the first time it is asked for).
    ///
    /// # Errors
    /// Why the simulation could not start or did not reach its end, as text.
    pub fn get(&mut self, run: CheckRun) -> Result<&Solution, String> {
        self.simulation(run).map(|s| &s.solution)
    }

    /// The whole simulation of `run` (computed the first time it is asked for): its
    /// solution, and its energy drift with the energy lost at impacts added.
    ///
    /// # Errors
    /// As [`Self::get`].
    pub fn simulation(&mut self, run: CheckRun) -> Result<&Simulation, String> {
        let k = match self.done.iter().position(|(d, _)| *d == run) {
            Some(k) => k,
            None => {
                let simulation = self.simulate(run, None);
                self.done.push((run, simulation));
                self.done.len() - 1
            }
        };
        self.done[k].1.as_ref().map_err(Clone::clone)
    }

    /// Runs `run` sampled at `times` (default: [`SAMPLES`] uniform times), not kept.
    ///
    /// # Errors
    /// Why the simulation could not start or did not reach its end, as text.
    pub fn run(&self, run: CheckRun, times: Option<Vec<f64>>) -> Result<Solution, String> {
        self.simulate(run, times).map(|s| s.solution)
    }

    /// [`Self::run`], the whole simulation. A run that stopped at a contact (a transition
    /// without an answer) did not reach its end, and is an error.
    fn simulate(&self, run: CheckRun, times: Option<Vec<f64>>) -> Result<Simulation, String> {
        let times = times.unwrap_or_else(|| {
            (0..SAMPLES)
                .map(|k| run.t_end * k as f64 / (SAMPLES - 1) as f64)
                .collect()
        });
        let options = SimulationOptions {
            method: run.method,
            t_end: run.t_end,
            rtol: run.rtol,
            atol: run.rtol,
            output: OutputTimes::At(times),
            ..SimulationOptions::default()
        };
        let mut model = self.source.instantiate();
        let simulation = simulate(model.as_mut(), &options).map_err(|e| e.to_string())?;
        match (&simulation.failure, &simulation.contact_stop) {
            (Some(error), _) => Err(format!("the integration failed: {error}")),
            (None, Some(stop)) => Err(format!("the run stopped: {stop}")),
            (None, None) => Ok(simulation),
        }
    }
}
