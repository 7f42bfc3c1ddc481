//! One simulation of a model from its initial state, as `eomgen simulate` runs it: the
//! consistent initial state, the drift control, the integration with the model's events and
//! any added ones, and the drift measures of the result.

use std::collections::BTreeMap;

use serde::{Serialize, Serializer};

use crate::analysis::drift::{ConstraintDrift, EnergyDrift, constraint_drift, energy_drift};
use crate::analysis::failure::{FailureCause, failure_cause};
use crate::analysis::fixed_step::{ENERGY_DRIFT_LIMIT, SimulationWarning, fixed_step_warnings};
use crate::analysis::methods::Method;
use crate::constrained::{ProjectionError, Stabilization, StabilizationError};
use crate::hybrid::{ContactStop, HybridRecord, Transition, integrate_through_impacts};
use crate::integrate::{
    IntegrationError, IntegrationFailure, Integrator, IntegratorOptions, OutputTimes, Solution,
    Stats,
};
use crate::model_info::ModelInfo;
use crate::ode::WithEvents;

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

pub use crate::model_info::AddedEvents;

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
    /// Projection asked of a model in generalized speeds with holonomic constraints: its
    /// constraint Jacobian is over the speeds (`J = [0 I]`, the auxiliary speeds), not the
    /// `∂Φ/∂q` that the projection of the coordinates onto `Φ = 0` steps along.
    #[error(
        "`{model}` is in generalized speeds beside holonomic constraints, whose Jacobian is over the speeds: projection, which steps the coordinates along ∂Φ/∂q, is not available; take Baumgarte's stabilisation or none"
    )]
    ProjectionInSpeeds {
        /// The model.
        model: String,
    },
    /// The initial state is inside a unilateral contact: its gap is negative.
    #[error(
        "the initial state is inside contact `{contact}`: its gap is {gap:e} (a gap is 0 or more, 0 where the contact touches)"
    )]
    StartsInsideContact {
        /// The contact.
        contact: String,
        /// Its gap there (m).
        gap: f64,
    },
    /// An entry of the initial state is not finite: the model file's `initial:` expression
    /// is outside its domain at these parameters, or the state given has it.
    #[error(
        "the initial value of `{name}` is {value}{}",
        if *given { " in the initial state given" } else { ": its expression in the model file's `initial:` is outside its domain at these parameters (a root or logarithm of a negative number, a division by zero)" }
    )]
    InitialStateNotFinite {
        /// The coordinate or rate (`x`, `x_dot`).
        name: String,
        /// The value (NaN or ±inf).
        value: f64,
        /// Whether the state was given ([`SimulationOptions::initial_state`]) rather than
        /// the model's.
        given: bool,
    },
}

/// The result of [`simulate`]: the samples, the drift measures and the events, and the
/// failure if the integration stopped early.
#[derive(Debug, Clone, Serialize)]
pub struct Simulation {
    /// The method used.
    pub method: Method,
    /// The integrator's own name ([`Integrator::name`], `"dopri5"`).
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
    /// The options the simulation ran with (not serialised: [`Simulation::summary`] reports
    /// the tolerances and the drift control).
    #[serde(skip)]
    pub options: SimulationOptions,
    /// How many event functions were added to the model's own ([`AddedEvents::specs`]; 0
    /// for [`simulate`]; not serialised).
    #[serde(skip)]
    pub num_added_events: usize,
    /// The impacts at the model's contacts, in time order (a model with `contacts:`;
    /// [`integrate_through_impacts`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub transitions: Vec<Transition>,
    /// Why the run stopped at a contact before `t_end`, if it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_stop: Option<ContactStop>,
}

fn serialize_failure<S: Serializer>(
    failure: &Option<IntegrationError>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    failure
        .as_ref()
        .map(FailureSummary::from)
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

/// Refuses an initial state `y0 = (q, q̇)` with an entry that is not finite, naming it:
/// `given` says whether the state was given by the caller (else the model file's
/// `initial:` gave it, at the model's current parameters).
///
/// # Errors
/// [`SimulationError::InitialStateNotFinite`] for the first such entry.
pub fn check_initial_state(
    description: &crate::ModelDescription,
    y0: &[f64],
    given: bool,
) -> Result<(), SimulationError> {
    match y0.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(SimulationError::InitialStateNotFinite {
            name: description.state_name(i),
            value: y0[i],
            given,
        }),
        None => Ok(()),
    }
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
    let d = model.description();
    if options.stabilization == Stabilization::Projection
        && d.has_speeds()
        && d.holonomic_constraints > 0
    {
        return Err(SimulationError::ProjectionInSpeeds {
            model: d.name.to_string(),
        });
    }
    let y0 = consistent_start(model, options)?;
    model.set_stabilization(options.stabilization);
    if !(options.t_end.is_finite() && options.t_end > 0.0) {
        return Err(SimulationError::InvalidEndTime {
            t_end: options.t_end,
        });
    }
    starts_outside_contacts(model, &y0, options.atol)?;
    let warnings = fixed_step_warnings(model, options.method, &y0, options.dt, options.t_end);
    let integrator_options = options.integrator_options();
    let mut integrator = options.method.integrator();
    let num_added_events = added.as_ref().map_or(0, |added| added.specs().len());
    let (result, hybrid) = if model.description().contacts.is_empty() {
        let run = integrate_run(
            integrator.as_mut(),
            model,
            added,
            &y0,
            options,
            &integrator_options,
        );
        (run, HybridRecord::default())
    } else {
        integrate_through_impacts(
            integrator.as_mut(),
            model,
            added,
            (0.0, &y0),
            options.t_end,
            &options.output,
            &integrator_options,
        )
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
    let mut energy = energy_drift(model, &y0, &solution);
    if !hybrid.transitions.is_empty() {
        energy.add_losses(
            hybrid
                .transitions
                .iter()
                .map(|tr| (tr.sample, tr.energy_drop())),
        );
    }
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
        options: options.clone(),
        num_added_events,
        transitions: hybrid.transitions,
        contact_stop: hybrid.stop,
    })
}

/// Refuses an initial state inside a contact: a gap below `−atol` (the run's absolute
/// tolerance, the rounding a gap written as 0 may carry).
///
/// # Errors
/// [`SimulationError::StartsInsideContact`] for the first such contact.
fn starts_outside_contacts(
    model: &dyn ModelInfo,
    y0: &[f64],
    atol: f64,
) -> Result<(), SimulationError> {
    let contacts = &model.description().contacts;
    if contacts.is_empty() {
        return Ok(());
    }
    let mut values = vec![0.0; 5 * contacts.len()];
    model.contact_gaps(0.0, y0, &mut values);
    match values[..contacts.len()]
        .iter()
        .position(|&g| g.is_nan() || g < -atol)
    {
        Some(c) => Err(SimulationError::StartsInsideContact {
            contact: contacts[c].to_string(),
            gap: values[c],
        }),
        None => Ok(()),
    }
}

/// The initial state of a [`simulate_with_events`] run: the given one or the model's, of
/// `2 n` entries, checked and made consistent with the model's constraints.
///
/// # Errors
/// [`SimulationError::DimensionMismatch`], the errors of [`check_initial_state`], and an
/// initial state that cannot be made consistent.
fn consistent_start(
    model: &mut dyn ModelInfo,
    options: &SimulationOptions,
) -> Result<Vec<f64>, SimulationError> {
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
    check_initial_state(model.description(), &y0, options.initial_state.is_some())?;
    model
        .make_consistent(&mut y0)
        .map_err(|e| inconsistent(model, &e))?;
    Ok(y0)
}

/// Integrates `model`, with the `added` events if any, from `y0` over `[0, t_end]` with
/// `integrator`, sampled at `options.output`.
fn integrate_run(
    integrator: &mut dyn Integrator,
    model: &mut dyn ModelInfo,
    added: Option<&mut dyn AddedEvents>,
    y0: &[f64],
    options: &SimulationOptions,
    integrator_options: &IntegratorOptions,
) -> Result<Solution, IntegrationFailure> {
    match added {
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
                y0,
                options.t_end,
                &options.output,
                integrator_options,
            )
        }
        None => integrator.integrate(
            model.as_ode_mut(),
            0.0,
            y0,
            options.t_end,
            &options.output,
            integrator_options,
        ),
    }
}

/// What `eomgen simulate --json` prints: a [`Simulation`] summarised for a reader, with the
/// model's names, the settings and the drift measures next to the samples ([`Simulation::summary`]).
///
/// Keys that apply only to some runs are left out otherwise: `constraints`, `stabilization`
/// and `max_constraint_drift` without constraints, `events` and `terminated_by_event` when
/// no event was located nor added, `error` without a failure, `warnings` without warnings.
///
/// # Shapes
/// `coordinates` has `n` names (`n` = the model's degrees of freedom); every sample's `q` and
/// `qdot` have `n` entries, its `constraint_forces` (when the model has constraints) `m`.
#[derive(Debug, Clone, Serialize)]
pub struct SimulationSummary {
    /// The model's name.
    pub model: String,
    /// The generalized coordinates' names, in the state's order.
    pub coordinates: Vec<String>,
    /// With generalized speeds, their names (`n`): every sample's `qdot` then holds the
    /// speeds `u` rather than the rates. Left out for a model in the coordinates' rates.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub speeds: Vec<String>,
    /// The parameters' values, by name (units of the model file).
    pub parameters: BTreeMap<String, f64>,
    /// The integrator's name ([`Simulation::integrator`], `"dp54"`).
    pub method: &'static str,
    /// The relative tolerance the run used.
    pub rtol: f64,
    /// The absolute tolerance the run used.
    pub atol: f64,
    /// Every sample: time, state, energy (and the constraint forces and drift).
    pub samples: Vec<SimulationSample>,
    /// `E(0) = T + V` (J).
    pub initial_energy: f64,
    /// The energy drift `max |E − E(0)| / scale` ([`EnergyDrift::drift`]; null without samples).
    pub energy_drift: Option<f64>,
    /// Whether the model declares itself conservative (then the energy should not drift).
    pub conservative: bool,
    /// The integrator's work.
    pub stats: Stats,
    /// The constraints' names (constrained models only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub constraints: Option<Vec<String>>,
    /// The drift control ([`Stabilization::name`]; constrained models only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stabilization: Option<&'static str>,
    /// The largest constraint residuals over the samples (constrained models only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_constraint_drift: Option<DriftPair>,
    /// The located events, in time order (when events were located or added).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub events: Option<Vec<EventSummary>>,
    /// The name of the terminal event that stopped the run, null when none did (present with
    /// `events`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub terminated_by_event: Option<Option<String>>,
    /// Why the integration stopped early: `{"t", "message"}` (a failed run only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<FailureSummary>,
    /// The warnings, each serialised as [`SimulationWarning`] with its `message` added.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<WarningSummary>,
    /// The impacts at the model's contacts, in time order (models with contacts only).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub transitions: Vec<Transition>,
    /// Why the run stopped at a contact, `{"kind", …, "message"}` (when it did).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_stop: Option<ContactStopSummary>,
}

/// A [`ContactStop`] with its message.
#[derive(Debug, Clone, Serialize)]
pub struct ContactStopSummary {
    /// The stop.
    #[serde(flatten)]
    pub stop: ContactStop,
    /// Its message.
    pub message: String,
}

/// One sample of a [`SimulationSummary`].
#[derive(Debug, Clone, Serialize)]
pub struct SimulationSample {
    /// Time (s).
    pub t: f64,
    /// The generalized coordinates `q` (`n` entries).
    pub q: Vec<f64>,
    /// The generalized velocities `q̇` (`n` entries).
    pub qdot: Vec<f64>,
    /// The energy `T + V` (J).
    pub energy: f64,
    /// The Lagrange multipliers `λ` (`m` entries, null where the constrained system is
    /// singular; constrained models only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub constraint_forces: Option<Option<Vec<f64>>>,
    /// The largest constraint residuals at this sample (constrained models only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub constraint_drift: Option<DriftPair>,
}

/// The largest position-level and velocity-level constraint residuals, `max |Φ|` and
/// `max |Φ̇|` (units of the constraints: m or rad, per second for the velocity).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DriftPair {
    /// `max |Φᵢ|`.
    pub position: f64,
    /// `max |Φ̇ᵢ|`.
    pub velocity: f64,
}

impl From<(f64, f64)> for DriftPair {
    fn from((position, velocity): (f64, f64)) -> Self {
        Self { position, velocity }
    }
}

/// One located event of a [`SimulationSummary`].
#[derive(Debug, Clone, Serialize)]
pub struct EventSummary {
    /// The event's name.
    pub name: String,
    /// Time of the zero (s).
    pub t: f64,
    /// `"rising"` or `"falling"` ([`EventDirection::name`](crate::EventDirection::name)).
    pub direction: &'static str,
    /// Whether it ended the integration.
    pub terminal: bool,
    /// `q` at the event (`n` entries).
    pub q: Vec<f64>,
    /// `q̇` at the event (`n` entries).
    pub qdot: Vec<f64>,
}

/// A failed integration in a [`SimulationSummary`]: where and why.
#[derive(Debug, Clone, Serialize)]
pub struct FailureSummary {
    /// The time of the failure (s; null for a failure before the first step).
    pub t: Option<f64>,
    /// The error's message.
    pub message: String,
}

impl From<&IntegrationError> for FailureSummary {
    fn from(error: &IntegrationError) -> Self {
        Self {
            t: error.t(),
            message: error.to_string(),
        }
    }
}

/// A [`SimulationWarning`] with its message: the warning's own keys (`kind` and its fields)
/// and `message`.
#[derive(Debug, Clone, Serialize)]
pub struct WarningSummary {
    /// The warning.
    #[serde(flatten)]
    pub warning: SimulationWarning,
    /// Its message ([`SimulationWarning`]'s `Display`).
    pub message: String,
}

impl Simulation {
    /// The summary `eomgen simulate --json` prints (see [`SimulationSummary`]); `model` is
    /// the model simulated (for its names and parameters).
    pub fn summary(&self, model: &dyn ModelInfo) -> SimulationSummary {
        let n = model.num_dofs();
        let constrained = !self.constraints.is_empty();
        let samples = self
            .solution
            .iter()
            .zip(&self.energy.energy)
            .enumerate()
            .map(|(k, ((t, y), &energy))| SimulationSample {
                t,
                q: y[..n].to_vec(),
                qdot: y[n..].to_vec(),
                energy,
                constraint_forces: constrained
                    .then(|| self.constraints.lagrange_multipliers[k].clone()),
                constraint_drift: constrained.then(|| self.constraints.drift[k].into()),
            })
            .collect();
        SimulationSummary {
            samples,
            ..self.summary_without_samples(model)
        }
    }

    /// [`Self::summary`] with `samples` left empty: the names, settings, drift measures,
    /// events and work, for a front end that hands the samples over as arrays
    /// ([`Simulation::solution`], [`EnergyDrift::energy`], [`ConstraintDrift`]) rather than
    /// one object per sample.
    pub fn summary_without_samples(&self, model: &dyn ModelInfo) -> SimulationSummary {
        let n = model.num_dofs();
        let description = model.description();
        let constrained = !self.constraints.is_empty();
        let samples = Vec::new();
        let with_events = !self.solution.events.is_empty() || self.num_added_events > 0;
        SimulationSummary {
            model: description.name.to_string(),
            coordinates: description
                .coordinate_names()
                .iter()
                .map(|s| s.to_string())
                .collect(),
            speeds: description.speeds.iter().map(|s| s.to_string()).collect(),
            parameters: description
                .parameter_names()
                .iter()
                .zip(model.parameter_values())
                .map(|(k, v)| (k.to_string(), v))
                .collect(),
            method: self.integrator,
            rtol: self.options.rtol,
            atol: self.options.atol,
            samples,
            initial_energy: self.energy.initial_energy,
            energy_drift: self.energy.drift,
            conservative: description.conservative,
            stats: self.solution.stats,
            constraints: constrained.then(|| self.constraints.constraint_names.clone()),
            stabilization: constrained.then(|| self.options.stabilization.name()),
            max_constraint_drift: constrained.then(|| self.constraints.max_drift().into()),
            events: with_events.then(|| {
                self.solution
                    .events
                    .iter()
                    .map(|e| EventSummary {
                        name: e.name.clone(),
                        t: e.t,
                        direction: e.direction.name(),
                        terminal: e.terminal,
                        q: e.y[..n].to_vec(),
                        qdot: e.y[n..].to_vec(),
                    })
                    .collect()
            }),
            terminated_by_event: with_events.then(|| {
                self.solution
                    .terminated_by_event
                    .map(|k| self.solution.events[k].name.clone())
            }),
            error: self.failure.as_ref().map(FailureSummary::from),
            transitions: self.transitions.clone(),
            contact_stop: self.contact_stop.as_ref().map(|stop| ContactStopSummary {
                stop: stop.clone(),
                message: stop.to_string(),
            }),
            warnings: self
                .warnings
                .iter()
                .map(|w| WarningSummary {
                    warning: w.clone(),
                    message: w.to_string(),
                })
                .collect(),
        }
    }
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
