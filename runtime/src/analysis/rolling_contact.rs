//! `eomgen study rolling-contact` as one call (lectures 8–11 on constraint forces, HW36): a
//! rigid body rolling on the ground, held there by constraints until it lifts off; the
//! friction coefficient it needs, `μ(t) = |F_t|/N`, from the constraint forces, checked
//! against Newton–Euler; and, with a second model of the same body in free flight, what
//! happens after the lift-off: the flight to the next touch-down, joined to the rolling phase.
//!
//! # The rolling phase
//! The rolling model (`models/eccentric_cylinder.yaml`) has coordinates that translate the
//! body along the ground (`x`, the ground's direction) and along its normal (`y`), and
//! constraints that hold it on the ground; it stops at a terminal event where the normal
//! force reaches zero (`lift_off`). The constraints' total force on the body, resolved along
//! `x` and `y`, is their generalized force `Q_c = −Jᵀλ` along those two coordinates (a force
//! on a rigid body has the generalized force of its component along a coordinate that
//! translates the body): the friction force `F_t = Q_c,x` and the normal force `N = Q_c,y`,
//! whatever the constraints are called or how their multipliers are signed. Then
//! `μ(t) = |F_t|/N` while `N > 0`.
//!
//! The check is Newton's second law for the centre of mass G, with nothing of the constraint
//! solve in it: `m a_G = F + N + m g`, so `(F_t, N) = m a_G − m g`, where `a_G` is the second
//! derivative of G's position along the simulated trajectory (its velocity `dr_G/dq · q̇` by
//! a central difference along `q̇`, at five states around each sample from the integrator's
//! dense output, then a five-point central difference in time), `m = 2T` at the rate
//! `ẋ = 1` (all others 0) and
//! `m g = −∂V/∂(x, y)` (central differences; exact for uniform gravity, in which `V` is
//! linear in a translation). The model's only applied force must be gravity.
//!
//! At the lift-off `N = 0` while `F_t` is in general not 0: `μ(t) → ∞` as the lift-off
//! approaches (near it `μ ≈ |F_t| / (|Ṅ| (t_lift − t))`), so no finite friction coefficient
//! keeps the body rolling all the way to the lift-off — it slips first. The study reports the
//! local maxima of `μ(t)` before that final rise (the largest is the most the rolling needs
//! before it), where the final rise starts, and for each friction coefficient asked for the
//! time at which `μ(t)` first reaches it (an event `F_t² − μ² N² = 0`, rising, located by
//! Brent's method on the dense output as every model event is).
//!
//! # The flight phase
//! The flight model (`models/eccentric_cylinder_flight.yaml`) is the same body with the same
//! coordinates and no constraints; it starts from the rolling model's state at the lift-off,
//! unchanged (positions and velocities are continuous: the normal force is zero there, so no
//! impulse acts; the energy of the two models at that state must agree), and runs until its
//! terminal landing event (the body touches the ground again). The run stops there: the
//! impact is beyond both models. Checks against closed forms: G moves on the parabola
//! `r_G(τ) = r_G(0) + v_G(0) τ + g τ²/2`, the angular velocity stays constant (gravity has no
//! moment about G), and `T + V` is conserved across the join.
//!
//! # References
//! Course HW36 (the eccentric cylinder that rolls and skips); lectures 8–11 (the multipliers
//! as constraint forces, `M q̈ = F − Jᵀλ`); B. Fornberg, "Generation of finite difference
//! formulas on arbitrarily spaced grids", Math. Comp. 51 (1988) 699–706 (the five-point
//! stencil).
//!
//! This file holds the options, the report's types and the run and event helpers both phases
//! use; the rolling phase is in `rolling`, the flight in `flight`, the study that runs them in
//! `study`.

use serde::Serialize;

use crate::analysis::methods::Method;
use crate::analysis::outcome::{RunTally, StudyRuns};
use crate::analysis::simulation::{
    AddedEvents, Simulation, SimulationError, SimulationOptions, simulate_with_events,
};
use crate::integrate::{Event, IntegrationError, OutputTimes};
use crate::model_info::ModelInfo;
use crate::ode::{EventDirection, EventSpec, RhsError};

mod flight;
mod rolling;
mod study;

pub use study::rolling_contact;

/// Why a rolling-contact study could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RollingContactError {
    /// A coordinate the options name is not a coordinate of the model.
    #[error("`{model}` has no {role} coordinate `{name}`; its coordinates are {}", known.join(", "))]
    UnknownCoordinate {
        /// The model.
        model: String,
        /// `ground`, `normal` or `angle`.
        role: &'static str,
        /// The name given.
        name: String,
        /// The model's coordinates.
        known: Vec<String>,
    },
    /// An event the options name is not an event of the model.
    #[error("`{model}` has no event `{name}`; its events are {}", if known.is_empty() { "none".to_string() } else { known.join(", ") })]
    UnknownEvent {
        /// The model.
        model: String,
        /// The name given.
        name: String,
        /// The model's events.
        known: Vec<String>,
    },
    /// A model is in generalized speeds: the study reads the contact force as `−Jᵀλ` on
    /// the coordinates and the velocity as the coordinates' rates, which its state does not
    /// hold.
    #[error(
        "`{model}` is in generalized speeds, and the rolling-contact study reads the contact force and the velocity on the coordinates' rates: study the model in the rates (remove `speeds`)"
    )]
    InSpeeds {
        /// The model's name.
        model: String,
    },
    /// The rolling model has no constraints, so no contact force.
    #[error("`{model}` has no constraints: nothing holds it on the ground")]
    NoConstraints {
        /// The model.
        model: String,
    },
    /// The model is not one body (its centre of mass is what Newton–Euler follows).
    #[error("`{model}` has {bodies} bodies; the study follows one rigid body")]
    NotOneBody {
        /// The model.
        model: String,
        /// How many it has.
        bodies: usize,
    },
    /// The two translation coordinates do not move the body as a whole (`2T` at a unit
    /// rate of each differ, or is not positive).
    #[error(
        "in `{model}`, `{ground}` and `{normal}` do not both translate the body: 2T at a unit rate of each is {mass_ground} and {mass_normal} kg"
    )]
    NotATranslation {
        /// The model.
        model: String,
        /// The ground coordinate.
        ground: String,
        /// The normal coordinate.
        normal: String,
        /// `2T` at `q̇ = e_ground` (kg).
        mass_ground: f64,
        /// `2T` at `q̇ = e_normal` (kg).
        mass_normal: f64,
    },
    /// The flight model's coordinates differ from the rolling model's, so the state at the
    /// lift-off cannot be carried over unchanged.
    #[error("the flight model `{flight}` has coordinates {} where `{rolling}` has {}", flight_coordinates.join(", "), rolling_coordinates.join(", "))]
    CoordinatesDiffer {
        /// The rolling model.
        rolling: String,
        /// Its coordinates.
        rolling_coordinates: Vec<String>,
        /// The flight model.
        flight: String,
        /// Its coordinates.
        flight_coordinates: Vec<String>,
    },
    /// An option out of its range.
    #[error("{name} must be {requirement}, got {value}")]
    InvalidOption {
        /// The option.
        name: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// Given.
        value: f64,
    },
    /// A simulation could not start.
    #[error("`{model}`: {source}")]
    Simulation {
        /// The model.
        model: String,
        /// Why.
        source: SimulationError,
    },
    /// An integration failed.
    #[error("`{model}`: the integration failed: {source}")]
    IntegrationFailed {
        /// The model.
        model: String,
        /// Why.
        source: IntegrationError,
    },
    /// The rolling phase did not reach its lift-off event within the longest phase.
    #[error("`{model}`: `{event}` did not occur within {t_end} s (the body never lifts off)")]
    NoLiftOff {
        /// The model.
        model: String,
        /// The lift-off event.
        event: String,
        /// The longest phase (s).
        t_end: f64,
    },
    /// Another terminal event ended a phase first.
    #[error("`{model}`: the terminal event `{other}` ended the run at t = {t} s, before `{event}`")]
    OtherEvent {
        /// The model.
        model: String,
        /// The event the phase runs to.
        event: String,
        /// The event that ended it.
        other: String,
        /// Its time (s).
        t: f64,
    },
    /// The constraint forces could not be computed at a sample.
    #[error("`{model}`: the constraint forces at t = {t} s: {source}")]
    ConstraintForces {
        /// The model.
        model: String,
        /// The time (s).
        t: f64,
        /// Why.
        source: RhsError,
    },
    /// A computed quantity is not a finite number.
    #[error("`{model}`: the {what} is not finite ({value})")]
    NonFinite {
        /// The model.
        model: String,
        /// What.
        what: &'static str,
        /// The value.
        value: f64,
    },
}

/// Options of [`rolling_contact`].
///
/// # Solver limits
/// Each phase is integrated by DOP853 at `rtol` (= `atol`) for at most `t_end` seconds
/// (10⁶ step attempts); it is integrated twice, once to locate its end event and the friction
/// thresholds, once to sample it at `samples` uniform times up to that event.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RollingContactOptions {
    /// The coordinate that translates the body along the ground (m) (default: `x`).
    pub ground: String,
    /// The coordinate that translates the body along the ground's normal, away from it (m)
    /// (default: `y`).
    pub normal: String,
    /// The body's rotation angle (rad), whose rate the flight checks (default: `theta`).
    pub angle: String,
    /// The rolling model's terminal event where the normal force reaches zero (default:
    /// `lift_off`).
    pub lift_off: String,
    /// The flight model's terminal event where the body touches the ground again (default:
    /// `landing`).
    pub landing: String,
    /// Friction coefficients (≥ 0) whose first exceedance by `μ(t)` is located (default:
    /// 0.2, 0.5, 1).
    pub thresholds: Vec<f64>,
    /// Uniform samples of each phase, both ends included (≥ 5, for the five-point stencil)
    /// (default: 2001).
    pub samples: usize,
    /// The longest phase (s), positive (default: 10).
    pub t_end: f64,
    /// Relative and absolute tolerance of DOP853, in (0, 1) (default: 1e-12).
    pub rtol: f64,
    /// Newton–Euler agreement: the largest difference of `F_t` and `N` from the two
    /// computations, over the interior samples, relative to the largest `|N|`, must not
    /// exceed this (default: 1e-6; measured 6e-9 to 5e-8 on `eccentric_cylinder` at any
    /// sampling and over a range of its parameters, the rounding of DOP853's dense output
    /// at 1e-12 differenced over `h`; a wrong sign or a missing term is O(1)).
    pub newton_euler_tolerance: f64,
    /// Flight checks (the parabola of G relative to max(1, its largest displacement), the
    /// spin relative to max(1, |θ̇|), the energy relative to max(T + |V|)) must not exceed
    /// this (default: 1e-9, a hundred times DOP853's drift at 1e-12).
    pub flight_tolerance: f64,
}

impl RollingContactOptions {
    /// The default number of samples per phase.
    pub const DEFAULT_SAMPLES: usize = 2001;
    /// The default tolerance.
    pub const DEFAULT_RTOL: f64 = 1e-12;
    /// The default longest phase (s).
    pub const DEFAULT_T_END: f64 = 10.0;
}

impl Default for RollingContactOptions {
    fn default() -> Self {
        Self {
            ground: "x".to_string(),
            normal: "y".to_string(),
            angle: "theta".to_string(),
            lift_off: "lift_off".to_string(),
            landing: "landing".to_string(),
            thresholds: vec![0.2, 0.5, 1.0],
            samples: Self::DEFAULT_SAMPLES,
            t_end: Self::DEFAULT_T_END,
            rtol: Self::DEFAULT_RTOL,
            newton_euler_tolerance: 1e-6,
            flight_tolerance: 1e-9,
        }
    }
}

/// One sample of the rolling phase.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactSample {
    /// Time (s).
    pub t: f64,
    /// The coordinates `q` (m, rad).
    pub q: Vec<f64>,
    /// The rates `q̇`.
    pub qdot: Vec<f64>,
    /// `T + V` (J).
    pub energy: f64,
    /// The normal force `N` from the multipliers (N), positive pushing the body off the
    /// ground.
    pub normal_force: f64,
    /// The friction force `F_t` from the multipliers (N), along the ground coordinate.
    pub friction_force: f64,
    /// `μ = |F_t|/N` (1); `None` where `N ≤ 0` (at the lift-off).
    pub mu: Option<f64>,
    /// `N` from Newton–Euler, `m a_G,y − m g_y` (N); `None` at the first and last samples,
    /// where the five-point stencil does not fit.
    pub normal_force_newton_euler: Option<f64>,
    /// `F_t` from Newton–Euler, `m a_G,x − m g_x` (N); `None` as above.
    pub friction_force_newton_euler: Option<f64>,
}

/// A local maximum of `μ(t)` (refined by the parabola through the three samples around it).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MuPeak {
    /// Time (s).
    pub t: f64,
    /// `μ` there (1).
    pub mu: f64,
}

/// When `μ(t)` first reaches a friction coefficient: where a body with that coefficient
/// would start to slip.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Exceedance {
    /// The friction coefficient (1).
    pub mu: f64,
    /// The first time `|F_t| = μ N`, rising (s), or the start if `μ(0) ≥ μ` already (the
    /// body slips from the first instant); `None` if `μ(t)` stays below it up to the
    /// lift-off (only possible when `F_t = 0` there).
    pub t: Option<f64>,
}

/// Newton–Euler against the multipliers, over the interior samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NewtonEulerAgreement {
    /// The body's mass `m = 2T(ẋ = 1)` (kg).
    pub mass: f64,
    /// Gravity `g = −∇V/m` along the ground and the normal (m/s²).
    pub gravity: [f64; 2],
    /// Largest `|N_λ − N_NE|` (N).
    pub max_normal_difference: f64,
    /// Largest `|F_λ − F_NE|` (N).
    pub max_friction_difference: f64,
    /// Largest `|N_λ|` (N), the scale of the comparison.
    pub max_normal_force: f64,
    /// The larger difference over the scale.
    pub relative: f64,
    /// The tolerance ([`RollingContactOptions::newton_euler_tolerance`]).
    pub tolerance: f64,
    /// `relative ≤ tolerance`.
    pub passed: bool,
}

/// The rolling phase, from the initial state to the lift-off.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RollingPhase {
    /// The model.
    pub model: String,
    /// Its coordinates.
    pub coordinates: Vec<String>,
    /// The coordinate along the ground ([`RollingContactOptions::ground`]).
    pub ground: String,
    /// The coordinate along the ground's normal ([`RollingContactOptions::normal`]).
    pub normal: String,
    /// The samples, uniform in `t` from 0 to the lift-off (the last is the lift-off state).
    pub samples: Vec<ContactSample>,
    /// The lift-off time (s).
    pub lift_off_time: f64,
    /// The state `[q; q̇]` there.
    pub lift_off_state: Vec<f64>,
    /// `N` there (N; zero to the event's accuracy).
    pub normal_force_at_lift_off: f64,
    /// `F_t` there (N).
    pub friction_force_at_lift_off: f64,
    /// `dN/dt` there (N/s; a one-sided second-order difference of the last three samples).
    pub normal_force_rate_at_lift_off: f64,
    /// Whether `μ(t) → ∞` at the lift-off (`F_t ≠ 0` there, above 1e-9 of the largest `N`).
    pub mu_diverges: bool,
    /// The local maxima of `μ(t)`, in time order.
    pub peaks: Vec<MuPeak>,
    /// The largest of them: the most friction the rolling needs before the final rise.
    pub max_peak: Option<MuPeak>,
    /// The time of the last local minimum of `μ`, from which it rises to the lift-off (s).
    pub final_rise_from: Option<f64>,
    /// When `μ(t)` first reaches each of the options' thresholds.
    pub exceedances: Vec<Exceedance>,
    /// The Newton–Euler check.
    pub newton_euler: NewtonEulerAgreement,
    /// `max |E − E(0)| / max(T + |V|)` over the samples.
    pub energy_drift: f64,
}

/// One sample of the flight phase.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlightSample {
    /// Time (s), continuing the rolling phase's.
    pub t: f64,
    /// The coordinates `q` (m, rad).
    pub q: Vec<f64>,
    /// The rates `q̇`.
    pub qdot: Vec<f64>,
    /// `T + V` (J).
    pub energy: f64,
    /// The centre of mass G (m), integrated.
    pub centre_of_mass: [f64; 2],
    /// G on the closed-form parabola `r_G(0) + v_G(0) τ + g τ²/2` (m).
    pub parabola: [f64; 2],
}

/// One check of the flight phase against its closed form.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlightCheck {
    /// What is checked.
    pub name: &'static str,
    /// The measured deviation (relative, see [`RollingContactOptions::flight_tolerance`]).
    pub value: f64,
    /// The tolerance.
    pub tolerance: f64,
    /// `value ≤ tolerance`.
    pub passed: bool,
}

/// The flight phase, from the lift-off to the landing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlightPhase {
    /// The flight model.
    pub model: String,
    /// The acceleration of the normal coordinate at the release (m/s²; it is 0 while
    /// rolling): positive, the body leaves the ground; negative, it presses on it at once —
    /// the friction force, which no friction coefficient supplies at `N = 0`, vanishes with
    /// the normal force, and the body would keep contact (and slide) rather than fly.
    pub release_normal_acceleration: f64,
    /// Whether the body rose off the ground ([`RISEN`]); `false` when the release
    /// acceleration is negative (nothing is integrated then) or it never rose.
    pub flies: bool,
    /// The samples, uniform in `t` from the lift-off to the landing (or the longest phase);
    /// empty when the body does not fly.
    pub samples: Vec<FlightSample>,
    /// The landing time (s, on the rolling phase's clock), `None` if the body had not come
    /// down within the longest phase.
    pub landing_time: Option<f64>,
    /// The state `[q; q̇]` at the landing.
    pub landing_state: Option<Vec<f64>>,
    /// The time in the air (s).
    pub flight_time: Option<f64>,
    /// The largest rise of the normal coordinate above its value at the lift-off (m).
    pub max_height: f64,
    /// The rate of the normal coordinate at the landing (m/s, negative: coming down).
    pub landing_normal_velocity: Option<f64>,
    /// Zeros of the landing event skipped at the start, before the body had risen
    /// ([`RISEN`]): rounding of the contact at the lift-off.
    pub skipped_touches: usize,
    /// `E_flight − E_rolling` at the lift-off state (J): zero when the two models describe
    /// the same body and no impulse acts.
    pub energy_jump: f64,
    /// The checks: energy across the join, the parabola of G, the constant spin.
    pub checks: Vec<FlightCheck>,
}

/// The result of [`rolling_contact`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RollingContact {
    /// The rolling phase.
    pub rolling: RollingPhase,
    /// The flight phase, when a flight model was given.
    pub flight: Option<FlightPhase>,
}

impl RollingContact {
    /// The checks that failed, in words (empty when all passed): the Newton–Euler
    /// agreement, and the flight's checks.
    pub fn failed_checks(&self) -> Vec<String> {
        let mut failed = Vec::new();
        let ne = &self.rolling.newton_euler;
        if !ne.passed {
            failed.push(format!(
                "Newton–Euler: the contact forces differ by {:.3e} of max |N|, above {:.0e}",
                ne.relative, ne.tolerance
            ));
        }
        if let Some(flight) = &self.flight {
            for c in flight.checks.iter().filter(|c| !c.passed) {
                failed.push(format!(
                    "{}: {:.3e}, above {:.0e}",
                    c.name, c.value, c.tolerance
                ));
            }
        }
        failed
    }
}

/// Each phase is a run; a study without a result is an error, so every run measured.
impl StudyRuns for RollingContact {
    fn study(&self) -> &'static str {
        "rolling-contact"
    }

    fn tally(&self) -> RunTally {
        let mut tally = RunTally::default();
        tally.measured();
        if self.flight.is_some() {
            tally.measured();
        }
        tally
    }
}

/// How far (relative to max(1, |y|)) the normal coordinate must rise above its lift-off value
/// before a zero of the landing event counts (m per m): the gap grows as `|Ṅ| τ³/(6 m)`, so
/// this is reached within about a millisecond of flight, far above the rounding of the
/// lift-off state (~1e-16).
pub const RISEN: f64 = 1e-9;

/// The name of the added event that marks the rise.
const RISEN_EVENT: &str = "rolling_contact_risen";

/// The normal coordinate above its lift-off value by [`RISEN`], rising.
struct Risen {
    normal: usize,
    level: f64,
}

impl AddedEvents for Risen {
    fn specs(&self) -> Vec<EventSpec> {
        vec![EventSpec::new(RISEN_EVENT, EventDirection::Rising, false)]
    }

    fn values(
        &mut self,
        _: &mut dyn ModelInfo,
        _: f64,
        y: &[f64],
        g: &mut [f64],
    ) -> Result<(), RhsError> {
        g[0] = y[self.normal] - self.level;
        Ok(())
    }
}

/// The friction coefficients' events: `F_t² − μ² N²`, rising.
struct Thresholds<'a> {
    mu: &'a [f64],
    ground: usize,
    normal: usize,
}

impl AddedEvents for Thresholds<'_> {
    fn specs(&self) -> Vec<EventSpec> {
        (0..self.mu.len())
            .map(|i| {
                EventSpec::new(
                    format!("rolling_contact_mu_{i}"),
                    EventDirection::Rising,
                    false,
                )
            })
            .collect()
    }

    fn values(
        &mut self,
        model: &mut dyn ModelInfo,
        t: f64,
        y: &[f64],
        g: &mut [f64],
    ) -> Result<(), RhsError> {
        let [friction, normal] = contact_force(model, t, y, self.ground, self.normal)?;
        for (g, mu) in g.iter_mut().zip(self.mu) {
            *g = friction * friction - (mu * normal) * (mu * normal);
        }
        Ok(())
    }
}

/// The constraints' total force on the body along the ground and the normal coordinate,
/// `−Jᵀλ` at those coordinates: `[F_t, N]` (N).
fn contact_force(
    model: &mut dyn ModelInfo,
    t: f64,
    y: &[f64],
    ground: usize,
    normal: usize,
) -> Result<[f64; 2], RhsError> {
    let lambda = model.constraint_forces(t, y)?;
    let jacobian = model.constraint_equations(t, y).jacobian;
    let force = |k: usize| -> f64 {
        -lambda
            .iter()
            .enumerate()
            .map(|(i, l)| jacobian[(i, k)] * l)
            .sum::<f64>()
    };
    Ok([force(ground), force(normal)])
}

fn coordinate(
    model: &dyn ModelInfo,
    role: &'static str,
    name: &str,
) -> Result<usize, RollingContactError> {
    let names = model.description().coordinate_names();
    names
        .iter()
        .position(|c| *c == name)
        .ok_or_else(|| RollingContactError::UnknownCoordinate {
            model: model.description().name.to_string(),
            role,
            name: name.to_string(),
            known: names.iter().map(|s| s.to_string()).collect(),
        })
}

/// The index of the event `name` and whether it is terminal in the file.
fn event(model: &dyn ModelInfo, name: &str) -> Result<bool, RollingContactError> {
    let events = &model.description().events;
    events
        .iter()
        .find(|e| e.name == name)
        .map(|e| e.terminal)
        .ok_or_else(|| RollingContactError::UnknownEvent {
            model: model.description().name.to_string(),
            name: name.to_string(),
            known: events.iter().map(|e| e.name.to_string()).collect(),
        })
}

/// The point index of the one body's centre of mass.
fn centre_of_mass(model: &dyn ModelInfo) -> Result<usize, RollingContactError> {
    let d = model.description();
    let name = d.name.to_string();
    if d.body_centres.len() != 1 {
        return Err(RollingContactError::NotOneBody {
            model: name,
            bodies: d.body_centres.len(),
        });
    }
    let point = &d.body_centres[0].point;
    d.points
        .iter()
        .position(|p| p == point)
        .ok_or(RollingContactError::NotOneBody {
            model: name,
            bodies: 0,
        })
}

/// `m = 2T` at a unit rate of the ground coordinate (checked against the normal one) and
/// `g = −∇V/m` along the two, at `y`.
fn mass_and_gravity(
    model: &dyn ModelInfo,
    y: &[f64],
    ground: usize,
    normal: usize,
    options: &RollingContactOptions,
) -> Result<(f64, [f64; 2]), RollingContactError> {
    let n = model.num_dofs();
    let unit_rate = |k: usize| {
        let mut state = y.to_vec();
        state[n..].iter_mut().for_each(|v| *v = 0.0);
        state[n + k] = 1.0;
        2.0 * model.kinetic_energy(0.0, &state)
    };
    let (mass_ground, mass_normal) = (unit_rate(ground), unit_rate(normal));
    if !(mass_ground > 0.0
        && mass_ground.is_finite()
        && (mass_ground - mass_normal).abs() <= 1e-12 * mass_ground)
    {
        return Err(RollingContactError::NotATranslation {
            model: model.description().name.to_string(),
            ground: options.ground.clone(),
            normal: options.normal.clone(),
            mass_ground,
            mass_normal,
        });
    }
    let h = 1e-3;
    let slope = |k: usize| {
        let (mut plus, mut minus) = (y.to_vec(), y.to_vec());
        plus[k] += h;
        minus[k] -= h;
        -(model.potential_energy(0.0, &plus) - model.potential_energy(0.0, &minus))
            / (2.0 * h)
            / mass_ground
    };
    Ok((mass_ground, [slope(ground), slope(normal)]))
}

/// The velocity of point `index` at `y`: `dr/dq · q̇` by a central difference along `q̇`.
fn point_velocity(model: &dyn ModelInfo, y: &[f64], index: usize) -> [f64; 2] {
    let n = model.num_dofs();
    let (q, qdot) = (&y[..n], &y[n..2 * n]);
    let rate = qdot.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if rate == 0.0 {
        return [0.0, 0.0];
    }
    let scale = q.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
    let s = 1e-5 * scale / rate;
    let at = |sign: f64| {
        let mut state = y.to_vec();
        for k in 0..n {
            state[k] = q[k] + sign * s * qdot[k];
        }
        model.point_positions(0.0, &state)[index]
    };
    let (plus, minus) = (at(1.0), at(-1.0));
    [
        (plus[0] - minus[0]) / (2.0 * s),
        (plus[1] - minus[1]) / (2.0 * s),
    ]
}

/// One phase: integrated once with `Steps` to locate `event` (and the added events), then
/// sampled at `samples` uniform times up to it (or to `t_end` without it). Returns the
/// samples `(t, y)` (the last the event's state when it occurred), the event and the first
/// run's events.
type Phase = (Vec<(f64, Vec<f64>)>, Option<Event>, Vec<Event>);

/// Where a phase ends: at `event`, terminal (the rolling phase), or at its first zero after
/// the added event `after`, with `event` left non-terminal (the flight, whose first zeros
/// at the lift-off are rounding).
fn run_phase(
    model: &mut dyn ModelInfo,
    initial: Option<Vec<f64>>,
    event_name: &str,
    after: Option<&str>,
    options: &RollingContactOptions,
    added: Option<&mut dyn AddedEvents>,
) -> Result<Phase, RollingContactError> {
    let name = model.description().name.to_string();
    let base = SimulationOptions {
        method: Method::Dop853,
        t_end: options.t_end,
        rtol: options.rtol,
        atol: options.rtol,
        initial_state: initial,
        ..SimulationOptions::default()
    };
    let first = run(model, &name, &base, added)?;
    let events = &first.solution.events;
    let stop = first
        .solution
        .terminated_by_event
        .map(|i| events[i].clone());
    if let Some(stop) = &stop
        && (stop.name != event_name || after.is_some())
    {
        return Err(RollingContactError::OtherEvent {
            model: name,
            event: event_name.to_string(),
            other: stop.name.clone(),
            t: stop.t,
        });
    }
    let end = match after {
        None => stop,
        Some(after) => events
            .iter()
            .find(|e| e.name == after)
            .and_then(|from| events.iter().find(|e| e.name == event_name && e.t > from.t))
            .cloned(),
    };
    let t_last = end.as_ref().map_or(options.t_end, |e| e.t);
    let times: Vec<f64> = (0..options.samples)
        .map(|i| t_last * i as f64 / (options.samples - 1) as f64)
        .collect();
    let sampled = SimulationOptions {
        output: OutputTimes::At(times),
        ..base
    };
    let second = run(model, &name, &sampled, None)?;
    let solution = &second.solution;
    let mut samples: Vec<(f64, Vec<f64>)> = solution
        .t
        .iter()
        .enumerate()
        .map(|(i, t)| {
            (
                *t,
                solution.y[i * solution.dim..(i + 1) * solution.dim].to_vec(),
            )
        })
        .filter(|(t, _)| *t <= t_last)
        .collect();
    if let Some(end) = &end {
        // The last sample is the event's state (the second run stops there too).
        if samples.last().is_some_and(|(t, _)| *t >= end.t) {
            samples.pop();
        }
        samples.push((end.t, end.y.clone()));
    }
    Ok((samples, end, first.solution.events))
}

/// One simulation; a failed integration is an error.
fn run(
    model: &mut dyn ModelInfo,
    name: &str,
    options: &SimulationOptions,
    added: Option<&mut dyn AddedEvents>,
) -> Result<Simulation, RollingContactError> {
    let run = simulate_with_events(model, options, added).map_err(|source| {
        RollingContactError::Simulation {
            model: name.to_string(),
            source,
        }
    })?;
    if let Some(source) = run.failure.clone() {
        return Err(RollingContactError::IntegrationFailed {
            model: name.to_string(),
            source,
        });
    }
    Ok(run)
}

fn check_options(options: &RollingContactOptions) -> Result<(), RollingContactError> {
    let invalid = |name, requirement, value| {
        Err(RollingContactError::InvalidOption {
            name,
            requirement,
            value,
        })
    };
    if options.samples < 5 {
        return invalid("samples", "at least 5", options.samples as f64);
    }
    if !(options.t_end.is_finite() && options.t_end > 0.0) {
        return invalid("t_end", "a positive number of seconds", options.t_end);
    }
    if !(options.rtol > 0.0 && options.rtol < 1.0) {
        return invalid("rtol", "in (0, 1)", options.rtol);
    }
    for (name, value) in [
        ("newton_euler_tolerance", options.newton_euler_tolerance),
        ("flight_tolerance", options.flight_tolerance),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return invalid(name, "a positive number", value);
        }
    }
    if let Some(mu) = options
        .thresholds
        .iter()
        .find(|mu| !(mu.is_finite() && **mu >= 0.0))
    {
        return invalid("a friction threshold", "a number ≥ 0", *mu);
    }
    Ok(())
}

/// The drift `max |E − E(0)| / max(T + |V|)` of `(energy, T + |V|)` pairs.
fn drift(values: &[(f64, f64)]) -> f64 {
    let e0 = values.first().map_or(0.0, |v| v.0);
    let scale = values.iter().fold(0.0_f64, |m, v| m.max(v.1));
    let worst = values.iter().fold(0.0_f64, |m, v| m.max((v.0 - e0).abs()));
    if scale > 0.0 { worst / scale } else { worst }
}

/// The rolling phase's samples and their `(T + V, T + |V|)` pairs (J), from
/// `rolling::contact_samples`.
type ContactRows = (Vec<ContactSample>, Vec<(f64, f64)>);

#[cfg(test)]
mod tests {
    use super::*;

    /// Options out of range are errors before anything runs.
    #[test]
    fn options_are_checked() {
        let bad = RollingContactOptions {
            samples: 4,
            ..Default::default()
        };
        assert!(matches!(
            check_options(&bad),
            Err(RollingContactError::InvalidOption {
                name: "samples",
                ..
            })
        ));
        let bad = RollingContactOptions {
            thresholds: vec![0.5, -1.0],
            ..Default::default()
        };
        assert!(matches!(
            check_options(&bad),
            Err(RollingContactError::InvalidOption { value, .. }) if value == -1.0
        ));
        assert!(check_options(&RollingContactOptions::default()).is_ok());
    }

    /// The drift is relative to the largest `T + |V|`.
    #[test]
    fn drift_is_relative() {
        assert_eq!(drift(&[(1.0, 4.0), (1.5, 4.0), (0.0, 2.0)]), 0.25);
    }
}
