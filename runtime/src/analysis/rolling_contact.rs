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
//! long: the rolling phase (contact forces, the friction needed, the Newton–Euler agreement)
//! and the flight phase after lift-off share the run and event helpers; each phase could be a
//! module of its own, a split left to the issue on the code's shape.

use serde::Serialize;

use crate::analysis::methods::Method;
use crate::analysis::outcome::{RunTally, StudyRuns};
use crate::analysis::simulation::{
    AddedEvents, Simulation, SimulationError, SimulationOptions, simulate_with_events,
};
use crate::integrate::{Event, IntegrationError, OutputTimes};
use crate::model_info::ModelInfo;
use crate::ode::{EventDirection, EventSpec, RhsError};

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

/// Runs the study: the rolling phase of `rolling` to its lift-off with the friction it needs
/// and the Newton–Euler check, then, when `flight` is given, the flight from the lift-off
/// state to the landing with its closed-form checks (see the module documentation).
///
/// The lift-off and landing events are made terminal for the study and restored afterwards.
/// A check that fails does not make an error: [`RollingContact::failed_checks`] lists it.
///
/// # Shapes and units
/// Every state is `[q; q̇]` (`2n` entries) in the model's units (m, rad, s); forces in N.
///
/// # Errors
/// [`RollingContactError`]: options out of range, names the models do not have, a rolling
/// model without constraints or not one body translated by the two coordinates, a flight
/// model with other coordinates, a failed integration, no lift-off within `t_end`, or
/// constraint forces that cannot be computed.
///
/// # Examples
/// ```
/// use eomgen::analysis::rolling_contact::{RollingContactOptions, rolling_contact};
///
/// let mut rolling = (eomgen::models::find("eccentric_cylinder").unwrap().make)();
/// let mut flight = (eomgen::models::find("eccentric_cylinder_flight").unwrap().make)();
/// let options = RollingContactOptions { samples: 401, ..Default::default() };
/// let study = rolling_contact(rolling.as_mut(), Some(flight.as_mut()), &options)?;
/// assert!((study.rolling.lift_off_time - 2.21505).abs() < 1e-5);
/// assert!(study.rolling.mu_diverges);            // F_t ≠ 0 where N = 0
/// assert!(study.failed_checks().is_empty(), "{:?}", study.failed_checks());
/// // Released there, the cylinder presses on the ramp at once: no flight.
/// let release = study.flight.unwrap().release_normal_acceleration;
/// assert!(release < -1.8);
///
/// // A ring-like cylinder on a steeper ramp flies and lands.
/// for model in [&mut rolling, &mut flight] {
///     model.set_parameter("e", 0.2).unwrap();
///     model.set_parameter("IG", 0.6).unwrap();
///     model.set_parameter("gamma", 0.9).unwrap();
/// }
/// let study = rolling_contact(rolling.as_mut(), Some(flight.as_mut()), &options)?;
/// let flight = study.flight.unwrap();
/// assert!(flight.flies && flight.checks.iter().all(|c| c.passed));
/// assert!((flight.flight_time.unwrap() - 0.4953).abs() < 1e-4);
/// # Ok::<(), eomgen::analysis::rolling_contact::RollingContactError>(())
/// ```
pub fn rolling_contact(
    rolling: &mut dyn ModelInfo,
    flight: Option<&mut dyn ModelInfo>,
    options: &RollingContactOptions,
) -> Result<RollingContact, RollingContactError> {
    check_options(options)?;
    let name = rolling.description().name.to_string();
    let ground = coordinate(rolling, "ground", &options.ground)?;
    let normal = coordinate(rolling, "normal", &options.normal)?;
    let angle = coordinate(rolling, "angle", &options.angle)?;
    if rolling.description().constraints.is_empty() {
        return Err(RollingContactError::NoConstraints { model: name });
    }
    let centre = centre_of_mass(rolling)?;
    let was_terminal = event(rolling, &options.lift_off)?;
    if let Some(flight) = &flight {
        let (a, b) = (
            rolling.description().coordinate_names(),
            flight.description().coordinate_names(),
        );
        if a != b {
            return Err(RollingContactError::CoordinatesDiffer {
                rolling: name,
                rolling_coordinates: a.iter().map(|s| s.to_string()).collect(),
                flight: flight.description().name.to_string(),
                flight_coordinates: b.iter().map(|s| s.to_string()).collect(),
            });
        }
        event(&**flight, &options.landing)?;
        centre_of_mass(&**flight)?;
    }

    rolling.set_event_terminal(&options.lift_off, true);
    let mut thresholds = Thresholds {
        mu: &options.thresholds,
        ground,
        normal,
    };
    let phase = run_phase(
        rolling,
        None,
        &options.lift_off,
        None,
        options,
        Some(&mut thresholds),
    );
    let accelerations = match &phase {
        Ok((samples, Some(_), _)) => Some(centre_accelerations(rolling, samples, centre, options)),
        _ => None,
    };
    rolling.set_event_terminal(&options.lift_off, was_terminal);
    let (samples, end, events) = phase?;
    let (Some(end), Some(accelerations)) = (end, accelerations) else {
        return Err(RollingContactError::NoLiftOff {
            model: name,
            event: options.lift_off.clone(),
            t_end: options.t_end,
        });
    };
    let rolling_phase = rolling_phase(
        rolling,
        &samples,
        &end,
        &events,
        &accelerations?,
        [ground, normal],
        options,
    )?;
    let flight_phase = match flight {
        Some(flight) => Some(flight_phase(
            flight,
            rolling,
            &rolling_phase,
            angle,
            normal,
            options,
        )?),
        None => None,
    };
    Ok(RollingContact {
        rolling: rolling_phase,
        flight: flight_phase,
    })
}

/// The drift `max |E − E(0)| / max(T + |V|)` of `(energy, T + |V|)` pairs.
fn drift(values: &[(f64, f64)]) -> f64 {
    let e0 = values.first().map_or(0.0, |v| v.0);
    let scale = values.iter().fold(0.0_f64, |m, v| m.max(v.1));
    let worst = values.iter().fold(0.0_f64, |m, v| m.max((v.0 - e0).abs()));
    if scale > 0.0 { worst / scale } else { worst }
}

/// `a_G` (m/s²) at every sample but the first and the last: a five-point central
/// difference in time of `v_G` over the states at `t_i + k h`, `k = −2..2`, from a further
/// run sampled there, with `h = min(Δt/5, 1e-4 t_lift)` whatever the sampling (so that the
/// truncation `h⁴ a⁽⁵⁾/30` and the rounding of the dense output over `h` both stay near
/// 1e-9 of the forces).
fn centre_accelerations(
    model: &mut dyn ModelInfo,
    samples: &[(f64, Vec<f64>)],
    centre: usize,
    options: &RollingContactOptions,
) -> Result<Vec<Option<[f64; 2]>>, RollingContactError> {
    let name = model.description().name.to_string();
    let count = samples.len();
    let t_last = samples[count - 1].0;
    let h = (t_last / (count - 1) as f64 / 5.0).min(1e-4 * t_last);
    let mut times = Vec::with_capacity(5 * count);
    for (t, _) in &samples[1..count - 1] {
        times.extend((-2..=2).map(|k| t + f64::from(k) * h));
    }
    let sampled = SimulationOptions {
        method: Method::Dop853,
        t_end: options.t_end,
        rtol: options.rtol,
        atol: options.rtol,
        output: OutputTimes::At(times),
        ..SimulationOptions::default()
    };
    let run = run(model, &name, &sampled, None)?;
    let solution = &run.solution;
    let velocity = |j: usize| {
        point_velocity(
            model,
            &solution.y[j * solution.dim..(j + 1) * solution.dim],
            centre,
        )
    };
    let mut out = vec![None; count];
    for (i, slot) in out.iter_mut().enumerate().take(count - 1).skip(1) {
        let first = 5 * (i - 1);
        if first + 5 > solution.t.len() {
            break;
        }
        let v: Vec<[f64; 2]> = (first..first + 5).map(velocity).collect();
        let a = |k: usize| (-v[4][k] + 8.0 * v[3][k] - 8.0 * v[1][k] + v[0][k]) / (12.0 * h);
        *slot = Some([a(0), a(1)]);
    }
    Ok(out)
}

fn rolling_phase(
    model: &mut dyn ModelInfo,
    samples: &[(f64, Vec<f64>)],
    end: &Event,
    events: &[Event],
    accelerations: &[Option<[f64; 2]>],
    [ground, normal]: [usize; 2],
    options: &RollingContactOptions,
) -> Result<RollingPhase, RollingContactError> {
    let name = model.description().name.to_string();
    let n = model.num_dofs();
    let (mass, gravity) = mass_and_gravity(model, &samples[0].1, ground, normal, options)?;
    let mut out: Vec<ContactSample> = Vec::with_capacity(samples.len());
    let mut energies = Vec::with_capacity(samples.len());
    for (t, y) in samples {
        let [friction, normal_force] =
            contact_force(model, *t, y, ground, normal).map_err(|source| {
                RollingContactError::ConstraintForces {
                    model: name.clone(),
                    t: *t,
                    source,
                }
            })?;
        for (what, value) in [("normal force", normal_force), ("friction force", friction)] {
            if !value.is_finite() {
                return Err(RollingContactError::NonFinite {
                    model: name,
                    what,
                    value,
                });
            }
        }
        let (kinetic, potential) = (model.kinetic_energy(*t, y), model.potential_energy(*t, y));
        energies.push((kinetic + potential, kinetic + potential.abs()));
        out.push(ContactSample {
            t: *t,
            q: y[..n].to_vec(),
            qdot: y[n..2 * n].to_vec(),
            energy: kinetic + potential,
            normal_force,
            friction_force: friction,
            mu: (normal_force > 0.0).then(|| friction.abs() / normal_force),
            normal_force_newton_euler: None,
            friction_force_newton_euler: None,
        });
    }
    // Newton–Euler at the interior samples.
    let count = out.len();
    let dt = (samples[count - 1].0 - samples[0].0) / (count - 1) as f64;
    let (mut max_normal_difference, mut max_friction_difference) = (0.0_f64, 0.0_f64);
    for (s, a) in out.iter_mut().zip(accelerations) {
        let Some(a) = a else { continue };
        let friction = mass * (a[0] - gravity[0]);
        let normal_force = mass * (a[1] - gravity[1]);
        max_normal_difference = max_normal_difference.max((normal_force - s.normal_force).abs());
        max_friction_difference = max_friction_difference.max((friction - s.friction_force).abs());
        s.normal_force_newton_euler = Some(normal_force);
        s.friction_force_newton_euler = Some(friction);
    }
    let max_normal_force = out.iter().fold(0.0_f64, |m, s| m.max(s.normal_force.abs()));
    let relative =
        max_normal_difference.max(max_friction_difference) / max_normal_force.max(1e-300);
    if !relative.is_finite() {
        return Err(RollingContactError::NonFinite {
            model: name,
            what: "Newton–Euler difference",
            value: relative,
        });
    }
    let newton_euler = NewtonEulerAgreement {
        mass,
        gravity,
        max_normal_difference,
        max_friction_difference,
        max_normal_force,
        relative,
        tolerance: options.newton_euler_tolerance,
        passed: relative <= options.newton_euler_tolerance,
    };

    // The local maxima and the last local minimum of μ over consecutive finite samples.
    let mut peaks = Vec::new();
    let mut final_rise_from = None;
    for i in 1..count.saturating_sub(1) {
        let (Some(a), Some(b), Some(c)) = (out[i - 1].mu, out[i].mu, out[i + 1].mu) else {
            continue;
        };
        let curvature = a - 2.0 * b + c;
        let offset = if curvature != 0.0 {
            ((a - c) / (2.0 * curvature)).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        if b >= a && b > c {
            peaks.push(MuPeak {
                t: out[i].t + offset * dt,
                mu: b - (a - c) * offset / 4.0,
            });
        } else if b <= a && b < c {
            final_rise_from = Some(out[i].t + offset * dt);
        }
    }
    if let (Some(rise), Some(last)) = (final_rise_from, peaks.last())
        && last.t > rise
    {
        // μ does not rise to the end: the last extremum is a maximum.
        final_rise_from = None;
    }
    let max_peak = peaks.iter().copied().max_by(|a, b| a.mu.total_cmp(&b.mu));
    let exceedances = options
        .thresholds
        .iter()
        .enumerate()
        .map(|(i, mu)| Exceedance {
            mu: *mu,
            // Already reached at the start (`F_t² ≥ μ² N²` there, `μ(0) ≥ μ`): the rising
            // event cannot fire from a value ≥ 0, and the body slips from the first instant.
            t: if out[0].friction_force.powi(2) >= (mu * out[0].normal_force).powi(2) {
                Some(out[0].t)
            } else {
                events
                    .iter()
                    .find(|e| e.name == format!("rolling_contact_mu_{i}"))
                    .map(|e| e.t)
            },
        })
        .collect();
    let last = &out[count - 1];
    let rate = (3.0 * last.normal_force - 4.0 * out[count - 2].normal_force
        + out[count - 3].normal_force)
        / (2.0 * dt);
    Ok(RollingPhase {
        model: name,
        coordinates: model
            .description()
            .coordinate_names()
            .iter()
            .map(|s| s.to_string())
            .collect(),
        ground: options.ground.clone(),
        normal: options.normal.clone(),
        lift_off_time: end.t,
        lift_off_state: end.y.clone(),
        normal_force_at_lift_off: last.normal_force,
        friction_force_at_lift_off: last.friction_force,
        normal_force_rate_at_lift_off: rate,
        mu_diverges: last.friction_force.abs() > 1e-9 * max_normal_force,
        energy_drift: drift(&energies),
        samples: out,
        peaks,
        max_peak,
        final_rise_from,
        exceedances,
        newton_euler,
    })
}

fn flight_phase(
    flight: &mut dyn ModelInfo,
    rolling: &dyn ModelInfo,
    rolling_phase: &RollingPhase,
    angle: usize,
    normal: usize,
    options: &RollingContactOptions,
) -> Result<FlightPhase, RollingContactError> {
    let name = flight.description().name.to_string();
    let n = flight.num_dofs();
    let centre = centre_of_mass(flight)?;
    let ground = coordinate(flight, "ground", &options.ground)?;
    let y0 = rolling_phase.lift_off_state.clone();
    let t0 = rolling_phase.lift_off_time;
    let (_, gravity) = mass_and_gravity(flight, &y0, ground, normal, options)?;
    let energy_rolling = rolling.energy(t0, &y0);
    let energy_jump = flight.energy(0.0, &y0) - energy_rolling;

    // Released with no contact force, the normal coordinate's acceleration jumps from the
    // rolling value 0 to this: the friction force, which Coulomb's law cannot supply at
    // N = 0, is gone with the normal force.
    let mut dy = vec![0.0; 2 * n];
    flight
        .as_ode_mut()
        .rhs(0.0, &y0, &mut dy)
        .map_err(|source| RollingContactError::ConstraintForces {
            model: name.clone(),
            t: t0,
            source,
        })?;
    let release_normal_acceleration = dy[n + normal];
    if !release_normal_acceleration.is_finite() {
        return Err(RollingContactError::NonFinite {
            model: name,
            what: "acceleration at the release",
            value: release_normal_acceleration,
        });
    }
    let g_scale = gravity[0].hypot(gravity[1]).max(1e-300);
    let re_enters = release_normal_acceleration < -RISEN * g_scale;

    // The energy of the rolling phase, to which the flight's is joined.
    let mut energies: Vec<(f64, f64)> = rolling_phase
        .samples
        .iter()
        .map(|s| {
            let y: Vec<f64> = s.q.iter().chain(&s.qdot).copied().collect();
            let (k, v) = (
                rolling.kinetic_energy(s.t, &y),
                rolling.potential_energy(s.t, &y),
            );
            (k + v, k + v.abs())
        })
        .collect();
    let tolerance = options.flight_tolerance;
    let check = |name: &'static str, value: f64| FlightCheck {
        name,
        value,
        tolerance,
        passed: value <= tolerance,
    };
    let mut phase = FlightPhase {
        model: name.clone(),
        release_normal_acceleration,
        flies: false,
        samples: Vec::new(),
        landing_time: None,
        landing_state: None,
        flight_time: None,
        max_height: 0.0,
        landing_normal_velocity: None,
        skipped_touches: 0,
        energy_jump,
        checks: Vec::new(),
    };
    if re_enters {
        // No flight: the body presses on the ground at once (it would keep contact and
        // slide); nothing to integrate.
        let scale = energies.iter().fold(0.0_f64, |m, v| m.max(v.1)).max(1e-300);
        phase.checks = vec![check(
            "energy jump at the lift-off",
            energy_jump.abs() / scale,
        )];
        return Ok(phase);
    }

    // The gap grows as a_n τ²/2 (or as τ³ when a_n = 0) from the lift-off, so the landing
    // function starts at zero to rounding and may cross it at once: zeros before the body
    // has risen above its lift-off height by RISEN (relative) are skipped.
    let was_terminal = event(flight, &options.landing)?;
    flight.set_event_terminal(&options.landing, false);
    let mut risen = Risen {
        normal,
        level: y0[normal] + RISEN * y0[normal].abs().max(1.0),
    };
    let run = run_phase(
        flight,
        Some(y0.clone()),
        &options.landing,
        Some(RISEN_EVENT),
        options,
        Some(&mut risen),
    );
    flight.set_event_terminal(&options.landing, was_terminal);
    let (samples, end, events) = run?;
    let rise = events.iter().find(|e| e.name == RISEN_EVENT).map(|e| e.t);
    phase.flies = rise.is_some();
    phase.skipped_touches = events
        .iter()
        .filter(|e| e.name == options.landing && rise.is_none_or(|r| e.t < r))
        .count();

    let r0 = flight.point_positions(0.0, &y0)[centre];
    let v0 = point_velocity(flight, &y0, centre);
    let spin0 = y0[n + angle];
    let (mut parabola_error, mut displacement, mut spin_error) = (0.0_f64, 0.0_f64, 0.0_f64);
    for (tau, y) in &samples {
        let r = flight.point_positions(*tau, y)[centre];
        let closed = [
            r0[0] + v0[0] * tau + gravity[0] * tau * tau / 2.0,
            r0[1] + v0[1] * tau + gravity[1] * tau * tau / 2.0,
        ];
        parabola_error = parabola_error
            .max((r[0] - closed[0]).abs())
            .max((r[1] - closed[1]).abs());
        displacement = displacement
            .max((r[0] - r0[0]).abs())
            .max((r[1] - r0[1]).abs());
        spin_error = spin_error.max((y[n + angle] - spin0).abs());
        phase.max_height = phase.max_height.max(y[normal] - y0[normal]);
        phase.samples.push(FlightSample {
            t: t0 + tau,
            q: y[..n].to_vec(),
            qdot: y[n..2 * n].to_vec(),
            energy: flight.energy(*tau, y),
            centre_of_mass: [r[0], r[1]],
            parabola: closed,
        });
    }
    energies.extend(samples.iter().map(|(tau, y)| {
        let (k, v) = (
            flight.kinetic_energy(*tau, y),
            flight.potential_energy(*tau, y),
        );
        (k + v, k + v.abs())
    }));
    let scale = energies.iter().fold(0.0_f64, |m, v| m.max(v.1)).max(1e-300);
    phase.checks = vec![
        check("energy jump at the lift-off", energy_jump.abs() / scale),
        check("energy drift over both phases", drift(&energies)),
        check(
            "centre of mass off the parabola",
            parabola_error / displacement.max(1.0),
        ),
        check("angular velocity change", spin_error / spin0.abs().max(1.0)),
    ];
    if let Some(bad) = phase.checks.iter().find(|c| !c.value.is_finite()) {
        return Err(RollingContactError::NonFinite {
            model: name,
            what: bad.name,
            value: bad.value,
        });
    }
    phase.landing_time = end.as_ref().map(|e| t0 + e.t);
    phase.landing_state = end.as_ref().map(|e| e.y.clone());
    phase.flight_time = end.as_ref().map(|e| e.t);
    phase.landing_normal_velocity = end.as_ref().map(|e| e.y[n + normal]);
    Ok(phase)
}

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
