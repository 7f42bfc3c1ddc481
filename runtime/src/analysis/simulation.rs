//! One simulation of a model from its initial state, as `eomgen simulate` runs it: the
//! consistent initial state, the drift control, the integration with the model's events and
//! any added ones, and the drift measures of the result.

use serde::{Serialize, Serializer};

use crate::analysis::drift::{ConstraintDrift, EnergyDrift, constraint_drift, energy_drift};
use crate::analysis::failure::{FailureCause, failure_cause};
use crate::analysis::fixed_step::{ENERGY_DRIFT_LIMIT, SimulationWarning, fixed_step_warnings};
use crate::analysis::methods::Method;
use crate::constrained::{ProjectionError, Stabilization, StabilizationError};
use crate::integrate::{
    EventSpec, IntegrationError, IntegrationFailure, IntegratorOptions, OutputTimes, Solution,
};
use crate::model_info::ModelInfo;
use crate::ode::{RhsError, WithEvents};

/// Options of [`simulate`]: method, end time, step control, output times, drift control and
/// initial state.
///
/// The defaults are those of `eomgen simulate` without options: Dormand–Prince 5(4) to
/// `t_end = 10` s at `rtol = 1e-8`, `atol = 1e-10`, every accepted step recorded, no drift
/// control, the model's own initial state.
///
/// # Solver limits
/// The integration gives up as the chosen [`Method`] does under [`IntegratorOptions`]'
/// defaults (step-size underflow, the maximum number of steps, a non-finite state); the
/// failure and the samples before it are in the report ([`Simulation::failure`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SimulationOptions {
    /// The integration method (default: [`Method::Dp54`]).
    pub method: Method,
    /// End time (s), finite and positive (default: 10).
    pub t_end: f64,
    /// Relative tolerance of the adaptive methods (default: 1e-8).
    pub rtol: f64,
    /// Absolute tolerance of the adaptive methods; implicit midpoint's scale for components
    /// near 0 (default: 1e-10).
    pub atol: f64,
    /// The fixed step (s) of a fixed-step method (`None`: `t_end / 1000`), the first step of
    /// an adaptive one (`None`: automatic).
    pub dt: Option<f64>,
    /// Where the solution is sampled (default: every accepted step).
    pub output: OutputTimes,
    /// Drift control of a constrained model (default: none; ignored without constraints).
    pub stabilization: Stabilization,
    /// The initial state `[q; q̇]` (`2n` entries) before it is made consistent with the
    /// constraints (`None`: the model's [`ModelInfo::initial_state`]).
    pub initial_state: Option<Vec<f64>>,
}

impl SimulationOptions {
    /// The default method, Dormand–Prince 5(4): what `eomgen simulate` uses without `--method`.
    pub const DEFAULT_METHOD: Method = Method::Dp54;
    /// The default end time (s).
    pub const DEFAULT_T_END: f64 = 10.0;
    /// The default relative tolerance, tighter than [`IntegratorOptions::DEFAULT_RTOL`]: a
    /// simulation reports its energy drift and constraint drift, which a looser tolerance would
    /// swamp.
    pub const DEFAULT_RTOL: f64 = 1e-8;
    /// The default absolute tolerance (see [`Self::DEFAULT_RTOL`]).
    pub const DEFAULT_ATOL: f64 = 1e-10;
}

impl Default for SimulationOptions {
    fn default() -> Self {
        Self {
            method: Self::DEFAULT_METHOD,
            t_end: Self::DEFAULT_T_END,
            rtol: Self::DEFAULT_RTOL,
            atol: Self::DEFAULT_ATOL,
            dt: None,
            output: OutputTimes::Steps,
            stabilization: Stabilization::None,
            initial_state: None,
        }
    }
}

impl SimulationOptions {
    /// The integrator options these settings give: `rtol`, `atol` and, if set, `dt` (a
    /// fixed-step method without `dt` takes `t_end / 1000` from the driver).
    pub fn integrator_options(&self) -> IntegratorOptions {
        let options = IntegratorOptions::default()
            .with_rtol(self.rtol)
            .with_atol(self.atol);
        match self.dt {
            Some(dt) => options.with_dt(dt),
            None => options,
        }
    }
}

/// Event functions added to a model's own `events:` for one simulation (the CLI's
/// `--stop-when` and `--event`, compiled from expressions by the facade crate).
pub trait AddedEvents {
    /// The specs of the added events, in order.
    fn specs(&self) -> Vec<EventSpec>;
    /// The added functions' values at `(t, y)` into `g` (one entry per spec); may read the
    /// model (for `q̈` or the constraint forces).
    ///
    /// # Errors
    /// As the right-hand side, when a quantity the functions need cannot be computed.
    fn values(
        &mut self,
        model: &mut dyn ModelInfo,
        t: f64,
        y: &[f64],
        g: &mut [f64],
    ) -> Result<(), RhsError>;
}

/// Why a simulation could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SimulationError {
    /// `t_end` is not a finite positive number.
    #[error("the end time must be a positive number of seconds, got {t_end}")]
    InvalidEndTime {
        /// The end time given (s).
        t_end: f64,
    },
    /// The given initial state has the wrong length.
    #[error("the initial state has {found} entries, the model's state has {expected}")]
    DimensionMismatch {
        /// `2n`.
        expected: usize,
        /// The length given.
        found: usize,
    },
    /// No state consistent with the constraints was found from the initial state.
    #[error(
        "the initial state of `{model}` violates constraint `{constraint}` (residual {residual:.3e} after {iterations} Newton iteration(s))"
    )]
    InconsistentInitialState {
        /// The model's name.
        model: String,
        /// The name of the constraint with the largest residual.
        constraint: String,
        /// Its residual.
        residual: f64,
        /// Newton iterations done (0 when the model marks no coordinate as a guess).
        iterations: usize,
        /// Whether the model file marks coordinates `{ guess: … }` (then Newton ran from
        /// them; otherwise the state had to satisfy the constraints as given).
        has_guesses: bool,
    },
    /// The drift control's gains cannot be used (a negative Baumgarte gain).
    #[error(transparent)]
    InvalidStabilization(#[from] StabilizationError),
}

/// The result of [`simulate`]: the samples, the drift measures and the events, and the
/// failure if the integration stopped early.
#[derive(Debug, Clone, Serialize)]
pub struct Simulation {
    /// The method used.
    pub method: Method,
    /// The integrator's own name ([`Integrator::name`](crate::Integrator::name), `"dopri5"`).
    pub integrator: &'static str,
    /// The consistent initial state `[q; q̇]` the integration started from.
    pub initial_state: Vec<f64>,
    /// The samples (all of them, or those before the failure), with the located events
    /// ([`Solution::events`]) and the work done.
    pub solution: Solution,
    /// The energy at every sample and its drift.
    pub energy: EnergyDrift,
    /// The constraint forces and drift at every sample (empty without constraints).
    pub constraints: ConstraintDrift,
    /// Warnings about the settings found before the run (a fixed step longer than the span
    /// or past the method's stability limit on the linearisation at the start:
    /// [`fixed_step_warnings`]) and after it (a conservative model whose energy drifted by
    /// more than [`ENERGY_DRIFT_LIMIT`]: [`SimulationWarning::EnergyNotConserved`]).
    pub warnings: Vec<SimulationWarning>,
    /// Why the integration stopped before `t_end`, if it did (serialised as `{"t",
    /// "message"}`); `solution` then holds the samples computed before it.
    #[serde(serialize_with = "serialize_failure")]
    pub failure: Option<IntegrationError>,
    /// What the model shows where the integration stopped ([`failure_cause`]): a mass matrix
    /// that is not positive definite, or a forcing that leaves a function's domain; `None`
    /// without a failure, or when the model shows nothing wrong there.
    pub cause: Option<FailureCause>,
}

fn serialize_failure<S: Serializer>(
    failure: &Option<IntegrationError>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    #[derive(Serialize)]
    struct Failure {
        t: Option<f64>,
        message: String,
    }
    failure
        .as_ref()
        .map(|e| Failure {
            t: e.t(),
            message: e.to_string(),
        })
        .serialize(serializer)
}

/// Simulates `model` from its initial state with `options` (see [`simulate_with_events`],
/// without added events).
///
/// # Errors
/// As [`simulate_with_events`].
///
/// # Examples
/// ```
/// use eomgen::analysis::{SimulationOptions, simulate};
///
/// let mut model = (eomgen::models::find("simple_pendulum").unwrap().make)();
/// let options = SimulationOptions { t_end: 2.0, ..SimulationOptions::default() };
/// let run = simulate(model.as_mut(), &options)?;
/// assert!(run.failure.is_none());
/// assert_eq!(run.solution.t.last(), Some(&2.0));
/// assert!(run.energy.drift.unwrap() < 1e-7);
/// # Ok::<(), eomgen::analysis::SimulationError>(())
/// ```
pub fn simulate(
    model: &mut dyn ModelInfo,
    options: &SimulationOptions,
) -> Result<Simulation, SimulationError> {
    simulate_with_events(model, options, None)
}

/// Simulates `model` from the initial state with `options`, locating the model's own events
/// and `added` ones: the initial state is made consistent with the constraints
/// ([`ModelInfo::make_consistent`]), the drift control set
/// ([`ModelInfo::set_stabilization`], it stays set on the model), the model integrated by
/// `options.method` and the energy and constraint drift measured at every sample.
///
/// A failed integration is not an error: the report holds the failure and the samples
/// computed before it.
///
/// # Shapes
/// `options.initial_state`, when given, has `2n` entries (`n = model.num_dofs()`).
///
/// # Errors
/// [`SimulationError::InvalidStabilization`] for unusable drift-control gains
/// ([`Stabilization::validate`]), [`SimulationError::DimensionMismatch`] for an initial state
/// of the wrong length, [`SimulationError::InconsistentInitialState`] when the constraints
/// cannot be satisfied, [`SimulationError::InvalidEndTime`] for a `t_end` that is not a
/// positive number (checked in this order).
///
/// # Examples
/// A pendulum released from the horizontal, stopped when it swings back (`q̇ = 0`, falling,
/// as `--stop-when "q_dot = 0, falling"` would add it):
/// ```
/// use eomgen::analysis::{AddedEvents, SimulationOptions, simulate_with_events};
/// use eomgen::{EventDirection, EventSpec, ModelInfo, RhsError};
///
/// struct Turn;
/// impl AddedEvents for Turn {
///     fn specs(&self) -> Vec<EventSpec> {
///         vec![EventSpec::new("turn", EventDirection::Falling, true)]
///     }
///     fn values(&mut self, _: &mut dyn ModelInfo, _: f64, y: &[f64], g: &mut [f64])
///         -> Result<(), RhsError> {
///         g[0] = y[1];
///         Ok(())
///     }
/// }
/// let mut model = (eomgen::models::find("simple_pendulum").unwrap().make)();
/// let options = SimulationOptions { initial_state: Some(vec![0.5, 0.0]), ..Default::default() };
/// let run = simulate_with_events(model.as_mut(), &options, Some(&mut Turn))?;
/// let stop = &run.solution.events[run.solution.terminated_by_event.unwrap()];
/// assert_eq!(stop.name, "turn");
/// assert!((stop.y[0] - 0.5).abs() < 1e-6);
/// # Ok::<(), eomgen::analysis::SimulationError>(())
/// ```
pub fn simulate_with_events(
    model: &mut dyn ModelInfo,
    options: &SimulationOptions,
    added: Option<&mut dyn AddedEvents>,
) -> Result<Simulation, SimulationError> {
    options.stabilization.validate()?;
    let mut y0 = match &options.initial_state {
        Some(y0) => y0.clone(),
        None => model.initial_state(),
    };
    let expected = 2 * model.num_dofs();
    if y0.len() != expected {
        return Err(SimulationError::DimensionMismatch {
            expected,
            found: y0.len(),
        });
    }
    model
        .make_consistent(&mut y0)
        .map_err(|e| inconsistent(model, &e))?;
    model.set_stabilization(options.stabilization);
    if !(options.t_end.is_finite() && options.t_end > 0.0) {
        return Err(SimulationError::InvalidEndTime {
            t_end: options.t_end,
        });
    }
    let warnings = fixed_step_warnings(model, options.method, &y0, options.dt, options.t_end);
    let integrator_options = options.integrator_options();
    let mut integrator = options.method.integrator();
    let result = match added {
        Some(added) => {
            let specs = added.specs();
            let mut system = WithEvents::new(
                model,
                specs,
                |m: &mut (dyn ModelInfo + '_), t: f64, y: &[f64], g: &mut [f64]| {
                    added.values(m, t, y, g)
                },
            );
            integrator.integrate(
                &mut system,
                0.0,
                &y0,
                options.t_end,
                &options.output,
                &integrator_options,
            )
        }
        None => integrator.integrate(
            model.as_ode_mut(),
            0.0,
            &y0,
            options.t_end,
            &options.output,
            &integrator_options,
        ),
    };
    let (solution, failure) = match result {
        Ok(s) => (s, None),
        Err(IntegrationFailure { error, partial }) => (*partial, Some(error)),
    };
    let cause = failure.as_ref().and_then(|e| {
        let t = e.t()?;
        let y = match solution.last() {
            Some((last, y)) if last == t => y.to_vec(),
            _ if solution.is_empty() => y0.clone(),
            _ => return None,
        };
        failure_cause(model, e, t, &y, &y0)
    });
    let energy = energy_drift(model, &y0, &solution);
    let constraints = constraint_drift(model, &solution);
    let mut warnings = warnings;
    if model.description().conservative
        && let Some(drift) = energy.drift
        && drift > ENERGY_DRIFT_LIMIT
    {
        warnings.push(SimulationWarning::EnergyNotConserved {
            drift,
            initial_energy: energy.initial_energy,
            final_energy: energy
                .energy
                .last()
                .copied()
                .unwrap_or(energy.initial_energy),
        });
    }
    Ok(Simulation {
        method: options.method,
        integrator: integrator.name(),
        initial_state: y0,
        solution,
        energy,
        constraints,
        warnings,
        failure,
        cause,
    })
}

/// The typed error of a failed [`ModelInfo::make_consistent`].
pub(crate) fn inconsistent(model: &dyn ModelInfo, e: &ProjectionError) -> SimulationError {
    SimulationError::InconsistentInitialState {
        model: model.description().name.to_string(),
        constraint: model
            .description()
            .constraint_names()
            .get(e.constraint)
            .copied()
            .unwrap_or("?")
            .to_string(),
        residual: e.residual,
        iterations: e.iterations,
        has_guesses: !model.description().initial_guesses.is_empty(),
    }
}
