//! `eomgen study launch` as one call (lecture 2's cannon ball, lectures 3–4's
//! velocity-dependent forces, HW2): for each launch speed `v0`, the range as a function of the
//! launch angle `θ`, the best angle `θ*(v0)` found by golden-section search on the range, and
//! the shape of the best path (its apex and the angle at which it lands), which shows what
//! the path tends to as `v0 → ∞`.
//!
//! The study works on any model with a launch-angle parameter, a launch-speed parameter (both
//! used by the model's `initial:`) and an event that marks the landing, all named by the
//! options (defaults `theta0`, `v0`, `ground`): each range is one integration (DOP853) from
//! the model's initial state at those parameter values to the first zero of the event, which
//! the integrator locates by Brent's method on its dense output (made terminal for the study
//! and restored afterwards). The range is the change of the horizontal coordinate (default
//! `x`) from launch to landing; the apex is where the rate of the height coordinate (default
//! `y`) falls through 0.
//!
//! With `g` the gravity, `m` the mass and the drag `−c₁ v − c₂ |v| v`
//! (`models/projectile_drag.yaml`):
//!
//! ```text
//! no drag:        R(θ) = v0² sin 2θ / g, θ* = 45°, symmetric parabola (apex at R/2,
//!                 landing angle θ)
//! linear drag:    x(t) = v0 cos θ τ (1 − e^{−t/τ}), τ = m/c₁, so R < x∞ = v0 cos θ m/c₁;
//!                 T = τ (k + W₀(−k e^{−k})), k = 1 + v0 sin θ/(g τ), R = v0 cos θ T/k;
//!                 as v0 → ∞ at a fixed θ: R → x∞ and the path tends to a straight rise
//!                 at θ and a vertical fall at x∞ (apex over the landing point, landing
//!                 angle 90°); θ* → 0, as θ* ≈ W₀(V²/e)/V ~ 2 ln V/V, V = v0/(g τ)
//!                 (from dR/dθ = 0 with R ≈ v0 τ cos θ (1 − e^{−1−Vθ}) for large V)
//! quadratic drag: terminal speed √(m g/c₂); θ* < 45° and R grows only logarithmically
//!                 in v0 (the speed decays as e^{−c₂ s/m} along the path length s)
//! ```
//!
//! # References
//! R. D. H. Warburton, J. Wang, "Analysis of asymptotic projectile motion with air resistance
//! using the Lambert W function", Am. J. Phys. 72 (2004) 1404–1407 (the linear-drag landing
//! time and range); J. Kiefer, "Sequential minimax search for a maximum", Proc. Amer. Math.
//! Soc. 4 (1953) 502–506 (golden-section search).

use serde::Serialize;

use crate::analysis::methods::Method;
use crate::analysis::outcome::{RunTally, StudyRuns};
use crate::analysis::simulation::{
    AddedEvents, Simulation, SimulationError, SimulationOptions, simulate_with_events,
};
use crate::integrate::{IntegrationError, OutputTimes};
use crate::model_info::ModelInfo;
use crate::ode::{EventDirection, EventSpec, RhsError};

/// Why a launch study could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LaunchError {
    /// The launch-angle or launch-speed parameter is not a parameter of the model.
    #[error("`{model}` has no {role} parameter `{name}`; its parameters are {}", known.join(", "))]
    UnknownParameter {
        /// The model.
        model: String,
        /// `angle` or `speed`.
        role: &'static str,
        /// The name given.
        name: String,
        /// The model's parameters.
        known: Vec<String>,
    },
    /// The landing event is not an event of the model.
    #[error("`{model}` has no event `{name}`; its events are {}", if known.is_empty() { "none".to_string() } else { known.join(", ") })]
    UnknownEvent {
        /// The model.
        model: String,
        /// The name given.
        name: String,
        /// The model's events.
        known: Vec<String>,
    },
    /// The range or height coordinate is not a coordinate of the model.
    #[error("`{model}` has no {role} coordinate `{name}`; its coordinates are {}", known.join(", "))]
    UnknownCoordinate {
        /// The model.
        model: String,
        /// `range` or `height`.
        role: &'static str,
        /// The name given.
        name: String,
        /// The model's coordinates.
        known: Vec<String>,
    },
    /// The model is in generalized speeds: the study reads the launch's velocity (the apex,
    /// the landing angle) as the coordinates' rates, which its state does not hold.
    #[error(
        "`{model}` is in generalized speeds, and the launch study reads the velocity as the coordinates' rates: study the model in the rates (remove `speeds`)"
    )]
    InSpeeds {
        /// The model's name.
        model: String,
    },
    /// A launch speed that is not a positive finite number.
    #[error("a launch speed must be a positive number, got {speed}")]
    InvalidSpeed {
        /// Given (m/s).
        speed: f64,
    },
    /// Fewer than 3 angles on the grid.
    #[error("the angle grid needs at least 3 angles, got {angles}")]
    TooFewAngles {
        /// Given.
        angles: usize,
    },
    /// A tolerance that is not a positive finite number (below 1 for `rtol`).
    #[error("{name} must be a positive number, got {value}")]
    InvalidTolerance {
        /// `angle_tol` or `rtol`.
        name: &'static str,
        /// Given.
        value: f64,
    },
    /// The longest flight allowed is not a positive finite number.
    #[error("the longest flight must be a positive number of seconds, got {t_max}")]
    InvalidMaxTime {
        /// Given (s).
        t_max: f64,
    },
    /// Fewer than 2 samples of a path.
    #[error("a path needs at least 2 samples, got {samples}")]
    TooFewSamples {
        /// Given.
        samples: usize,
    },
    /// A shape angle outside `(0, π/2)`.
    #[error("the shape angle must lie in (0, π/2) rad, got {angle}")]
    InvalidShapeAngle {
        /// Given (rad).
        angle: f64,
    },
    /// A simulation could not start.
    #[error("v0 = {speed}, θ = {angle} rad: {source}")]
    Simulation {
        /// Launch speed (m/s).
        speed: f64,
        /// Launch angle (rad).
        angle: f64,
        /// Why.
        source: SimulationError,
    },
    /// An integration failed before the landing.
    #[error("v0 = {speed}, θ = {angle} rad: the integration failed before `{event}`: {source}")]
    IntegrationFailed {
        /// Launch speed (m/s).
        speed: f64,
        /// Launch angle (rad).
        angle: f64,
        /// The landing event.
        event: String,
        /// Why.
        source: IntegrationError,
    },
    /// The flight never reached the landing event within the longest flight allowed.
    #[error(
        "v0 = {speed}, θ = {angle} rad: `{event}` did not occur within {t_max} s (the path never reaches the ground)"
    )]
    NoLanding {
        /// Launch speed (m/s).
        speed: f64,
        /// Launch angle (rad).
        angle: f64,
        /// The landing event.
        event: String,
        /// The longest flight allowed (s).
        t_max: f64,
    },
    /// Another terminal event of the model ended the flight first.
    #[error(
        "v0 = {speed}, θ = {angle} rad: the terminal event `{other}` ended the run at t = {t} s, before `{event}`"
    )]
    OtherEvent {
        /// Launch speed (m/s).
        speed: f64,
        /// Launch angle (rad).
        angle: f64,
        /// The landing event.
        event: String,
        /// The event that ended the run.
        other: String,
        /// Its time (s).
        t: f64,
    },
    /// The range or the time of flight is not a finite number.
    #[error("v0 = {speed}, θ = {angle} rad: the {what} is not finite ({value})")]
    NonFinite {
        /// Launch speed (m/s).
        speed: f64,
        /// Launch angle (rad).
        angle: f64,
        /// `range` or `time of flight`.
        what: &'static str,
        /// The value.
        value: f64,
    },
}

/// Options of [`launch_study`].
///
/// # Solver limits
/// Each flight is integrated by DOP853 at `rtol` (= `atol`) for at most `t_max` seconds and
/// 10⁶ step attempts; a flight that does not land fails the study
/// ([`LaunchError::NoLanding`]), and so does any failed integration: a maximum over angles
/// with a missing value is not a maximum.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LaunchOptions {
    /// Launch speeds (m/s), each positive (default: empty, the model's own value of the
    /// speed parameter).
    pub speeds: Vec<f64>,
    /// The launch-angle parameter (rad, from the horizontal) (default: `theta0`).
    pub angle_parameter: String,
    /// The launch-speed parameter (m/s) (default: `v0`).
    pub speed_parameter: String,
    /// The event whose first zero is the landing (default: `ground`).
    pub event: String,
    /// The horizontal coordinate, whose change is the range (m) (default: `x`).
    pub range_coordinate: String,
    /// The vertical coordinate, whose rate falls through 0 at the apex (default: `y`).
    pub height_coordinate: String,
    /// Angles of the range curve, evenly spaced strictly inside `(0, π/2)`:
    /// `θᵢ = i (π/2)/(angles + 1)`, `i = 1 … angles` (default: 89, every degree; at least 3).
    /// The search looks for `θ*` between the neighbours of the grid's best angle, so the grid
    /// must be fine enough that no other local maximum of `R(θ)` hides between its points.
    pub angles: usize,
    /// Width of the final bracket of the golden-section search (rad) (default: 1e-7). The
    /// range is flat at its maximum, `R(θ* + δ) ≈ R* − ½|R''| δ²`, so an integration error
    /// `ε R*` in the range leaves `θ*` uncertain by about `√(2 ε R*/|R''|)`: 1e-6 rad at the
    /// default `rtol` on the bundled models.
    pub angle_tol: f64,
    /// Relative and absolute tolerance of DOP853 (default: 1e-12; in `(0, 1)`).
    pub rtol: f64,
    /// The longest flight (s) (default: 1e6).
    pub t_max: f64,
    /// Samples of each path, evenly spaced in time from launch to landing (default: 201;
    /// at least 2).
    pub path_samples: usize,
    /// A launch angle (rad) at which each speed's path is also reported, in `(0, π/2)`:
    /// the shape HW2 asks for as `v0 → ∞` at a fixed angle (default: `Some(π/4)`).
    pub shape_angle: Option<f64>,
}

impl LaunchOptions {
    /// The default angle grid: 1°, 2°, …, 89°.
    pub const DEFAULT_ANGLES: usize = 89;
    /// The default width of the golden-section search's final bracket (rad).
    pub const DEFAULT_ANGLE_TOL: f64 = 1e-7;
    /// The default integration tolerance.
    pub const DEFAULT_RTOL: f64 = 1e-12;
    /// The default longest flight (s).
    pub const DEFAULT_T_MAX: f64 = 1e6;
    /// The default number of samples of a best path.
    pub const DEFAULT_PATH_SAMPLES: usize = 201;
}

impl Default for LaunchOptions {
    fn default() -> Self {
        Self {
            speeds: Vec::new(),
            angle_parameter: "theta0".to_string(),
            speed_parameter: "v0".to_string(),
            event: "ground".to_string(),
            range_coordinate: "x".to_string(),
            height_coordinate: "y".to_string(),
            angles: Self::DEFAULT_ANGLES,
            angle_tol: Self::DEFAULT_ANGLE_TOL,
            rtol: Self::DEFAULT_RTOL,
            t_max: Self::DEFAULT_T_MAX,
            path_samples: Self::DEFAULT_PATH_SAMPLES,
            shape_angle: Some(std::f64::consts::FRAC_PI_4),
        }
    }
}

/// One flight: its angle, range and time of flight.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RangePoint {
    /// Launch angle (rad).
    pub angle: f64,
    /// Range: the horizontal coordinate's change from launch to landing (m).
    pub range: f64,
    /// Time of flight (s).
    pub flight_time: f64,
}

/// The top of a path: where the vertical rate first falls through 0.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Apex {
    /// Time (s).
    pub t: f64,
    /// Horizontal distance from the launch point (m).
    pub x: f64,
    /// Height above the launch point (m).
    pub y: f64,
}

/// One flight with the shape of its path: the best one at a speed, or the one at the
/// options' `shape_angle`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Shot {
    /// Launch angle (rad): `θ*` for the best flight.
    pub angle: f64,
    /// Range (m): the largest, `R(θ*)`, for the best flight.
    pub range: f64,
    /// Its time of flight (s).
    pub flight_time: f64,
    /// The apex (`None` if the height never had a maximum: a path launched downwards).
    pub apex: Option<Apex>,
    /// The apex's share of the range, `x_apex/R`: ½ for a parabola, → 1 as the fall
    /// becomes vertical (`None` without an apex or with a zero range).
    pub apex_fraction: Option<f64>,
    /// The angle of the velocity below the horizontal at landing (rad): the launch angle
    /// for a parabola, → π/2 for a vertical fall.
    pub landing_angle: f64,
    /// The path `(x, y)` relative to the launch point (m), at `path_samples` times evenly
    /// spaced from launch to landing, the landing point last.
    pub path: Vec<[f64; 2]>,
}

/// The study at one launch speed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpeedStudy {
    /// Launch speed `v0` (m/s).
    pub speed: f64,
    /// The range curve on the angle grid.
    pub curve: Vec<RangePoint>,
    /// The best flight.
    pub best: Shot,
    /// The flight at the options' `shape_angle` (`None` without one).
    pub at_shape_angle: Option<Shot>,
    /// The final bracket `[a, b]` of the golden-section search (rad), `b − a ≤ angle_tol`.
    pub bracket: [f64; 2],
    /// Integrations done by the search (besides the grid's).
    pub search_evaluations: usize,
}

/// What [`launch_study`] computed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LaunchStudy {
    /// The model's name.
    pub model: String,
    /// The launch-angle parameter.
    pub angle_parameter: String,
    /// The launch-speed parameter.
    pub speed_parameter: String,
    /// The landing event.
    pub event: String,
    /// The horizontal coordinate.
    pub range_coordinate: String,
    /// The vertical coordinate.
    pub height_coordinate: String,
    /// The golden-section search's final bracket width (rad).
    pub angle_tol: f64,
    /// The integration tolerance.
    pub rtol: f64,
    /// One study per speed, in the order given.
    pub speeds: Vec<SpeedStudy>,
}

/// Each speed is a run; any failure fails the study as a whole, so a report holds only
/// measured speeds.
impl StudyRuns for LaunchStudy {
    fn study(&self) -> &'static str {
        "launch"
    }

    fn tally(&self) -> RunTally {
        let mut tally = RunTally::default();
        for _ in &self.speeds {
            tally.measured();
        }
        tally
    }
}

/// The apex event added to the model's own: the height coordinate's rate falling through 0.
struct ApexEvent {
    rate_index: usize,
}

impl AddedEvents for ApexEvent {
    fn specs(&self) -> Vec<EventSpec> {
        vec![EventSpec::new(
            "launch_apex",
            EventDirection::Falling,
            false,
        )]
    }

    fn values(
        &mut self,
        _: &mut dyn ModelInfo,
        _: f64,
        y: &[f64],
        g: &mut [f64],
    ) -> Result<(), RhsError> {
        g[0] = y[self.rate_index];
        Ok(())
    }
}

/// A flight integrated to the landing: the run, its range point, the launch point and the
/// landing event.
struct Flight {
    run: Simulation,
    point: RangePoint,
    launch: [f64; 2],
    landing: usize,
}

/// What every flight of one study shares.
struct Launcher<'a> {
    options: &'a LaunchOptions,
    range_index: usize,
    height_index: usize,
    num_dofs: usize,
    num_model_events: usize,
}

impl Launcher<'_> {
    /// The first step of a flight (s): a thousandth of `v/|a|`, the height rate over its
    /// rate of change at launch, which bounds the time to the apex from below when the
    /// deceleration is largest at launch (gravity plus a drag growing with speed).
    ///
    /// Why: the landing counts a change of the event function from positive to
    /// non-positive, and the launch is at its zero. A first step across the whole flight
    /// (DOP853 is exact on a parabola, so nothing stops its step from growing past the
    /// landing) would start from 0 and miss it; this one leaves the ground first, and the
    /// step then grows at most tenfold per step. `None` (the automatic first step) when the
    /// launch is not upwards against a downward acceleration, and never below the
    /// integrator's smallest usable step.
    fn first_step(&self, model: &mut dyn ModelInfo) -> Option<f64> {
        let y0 = model.initial_state();
        let mut rate = vec![0.0; y0.len()];
        model.rhs(0.0, &y0, &mut rate).ok()?;
        let i = self.num_dofs + self.height_index;
        let (v, a) = (y0[i], rate[i]);
        let dt = 1e-3 * v / -a;
        let floor = 1e3 * f64::EPSILON * self.options.t_max;
        (v > 0.0 && a < 0.0 && dt.is_finite()).then_some(dt.max(floor))
    }

    /// Integrates the flight at `speed` and `angle` to the landing, sampled at `output`.
    fn fly(
        &self,
        model: &mut dyn ModelInfo,
        speed: f64,
        angle: f64,
        output: OutputTimes,
    ) -> Result<Flight, LaunchError> {
        let o = self.options;
        // Both names were checked, so setting them cannot fail.
        let _ = model.set_parameter(&o.angle_parameter, angle);
        let _ = model.set_parameter(&o.speed_parameter, speed);
        let options = SimulationOptions {
            method: Method::Dop853,
            t_end: o.t_max,
            rtol: o.rtol,
            atol: o.rtol,
            dt: self.first_step(model),
            output,
            ..SimulationOptions::default()
        };
        let mut apex = ApexEvent {
            rate_index: self.num_dofs + self.height_index,
        };
        let run = simulate_with_events(model, &options, Some(&mut apex)).map_err(|source| {
            LaunchError::Simulation {
                speed,
                angle,
                source,
            }
        })?;
        let event = o.event.clone();
        if let Some(source) = run.failure.clone() {
            return Err(LaunchError::IntegrationFailed {
                speed,
                angle,
                event,
                source,
            });
        }
        let Some(landing) = run.solution.terminated_by_event else {
            return Err(LaunchError::NoLanding {
                speed,
                angle,
                event,
                t_max: o.t_max,
            });
        };
        let stop = &run.solution.events[landing];
        if stop.name != o.event {
            return Err(LaunchError::OtherEvent {
                speed,
                angle,
                event,
                other: stop.name.clone(),
                t: stop.t,
            });
        }
        let y0 = &run.initial_state;
        let launch = [y0[self.range_index], y0[self.height_index]];
        let range = stop.y[self.range_index] - launch[0];
        let flight_time = stop.t;
        for (what, value) in [("range", range), ("time of flight", flight_time)] {
            if !value.is_finite() {
                return Err(LaunchError::NonFinite {
                    speed,
                    angle,
                    what,
                    value,
                });
            }
        }
        let point = RangePoint {
            angle,
            range,
            flight_time,
        };
        Ok(Flight {
            run,
            point,
            launch,
            landing,
        })
    }

    /// The range and time of flight at `speed` and `angle`.
    fn range(
        &self,
        model: &mut dyn ModelInfo,
        speed: f64,
        angle: f64,
    ) -> Result<RangePoint, LaunchError> {
        Ok(self
            .fly(model, speed, angle, OutputTimes::At(vec![0.0]))?
            .point)
    }

    /// The flight of `best` again, sampled, with its apex and landing angle.
    fn shot(
        &self,
        model: &mut dyn ModelInfo,
        speed: f64,
        best: RangePoint,
    ) -> Result<Shot, LaunchError> {
        let count = self.options.path_samples;
        // Times before the landing; the landing itself is the event's state.
        let times = (0..count - 1)
            .map(|i| best.flight_time * i as f64 / (count - 1) as f64)
            .collect();
        let flight = self.fly(model, speed, best.angle, OutputTimes::At(times))?;
        let solution = &flight.run.solution;
        let stop = &solution.events[flight.landing];
        let [x0, h0] = flight.launch;
        let (ix, iy) = (self.range_index, self.height_index);
        let apex = solution
            .events
            .iter()
            .find(|e| e.index == self.num_model_events)
            .map(|e| Apex {
                t: e.t,
                x: e.y[ix] - x0,
                y: e.y[iy] - h0,
            });
        let n = self.num_dofs;
        let (vx, vy) = (stop.y[n + ix], stop.y[n + iy]);
        let range = flight.point.range;
        let mut path: Vec<[f64; 2]> = solution
            .iter()
            .filter(|(t, _)| *t < stop.t)
            .map(|(_, y)| [y[ix] - x0, y[iy] - h0])
            .collect();
        path.push([range, stop.y[iy] - h0]);
        Ok(Shot {
            angle: flight.point.angle,
            range,
            flight_time: flight.point.flight_time,
            apex,
            // No share of a zero range (a flight that lands where it started).
            apex_fraction: apex.filter(|_| range != 0.0).map(|a| a.x / range),
            landing_angle: (-vy).atan2(vx),
            path,
        })
    }

    /// The range curve, `θ*` by golden-section search and the best path at `speed`.
    fn study_speed(
        &self,
        model: &mut dyn ModelInfo,
        speed: f64,
    ) -> Result<SpeedStudy, LaunchError> {
        let o = self.options;
        let step = std::f64::consts::FRAC_PI_2 / (o.angles + 1) as f64;
        let mut curve = Vec::with_capacity(o.angles);
        for i in 1..=o.angles {
            curve.push(self.range(model, speed, i as f64 * step)?);
        }
        // The grid's best angle brackets the maximum between its neighbours (0 and π/2 at
        // the ends: the search evaluates only inside its bracket).
        let k = (0..curve.len())
            .max_by(|&a, &b| curve[a].range.total_cmp(&curve[b].range))
            .unwrap_or(0);
        let (mut a, mut b) = (k as f64 * step, (k + 2) as f64 * step);
        let mut best = curve[k];
        let mut evaluations = 0;
        let mut range = |model: &mut dyn ModelInfo, angle: f64| {
            evaluations += 1;
            self.range(model, speed, angle)
        };
        // Golden-section search (Kiefer 1953): the bracket shrinks by 1/φ per evaluation.
        let r = (5f64.sqrt() - 1.0) / 2.0;
        let mut c = b - r * (b - a);
        let mut d = a + r * (b - a);
        let mut fc = range(model, c)?;
        let mut fd = range(model, d)?;
        for _ in 0..200 {
            if b - a <= o.angle_tol {
                break;
            }
            if fc.range > fd.range {
                (b, d, fd) = (d, c, fc);
                c = b - r * (b - a);
                fc = range(model, c)?;
            } else {
                (a, c, fc) = (c, d, fd);
                d = a + r * (b - a);
                fd = range(model, d)?;
            }
        }
        for p in [fc, fd] {
            if p.range > best.range {
                best = p;
            }
        }
        let at_shape_angle = match o.shape_angle {
            Some(angle) => {
                let point = self.range(model, speed, angle)?;
                Some(self.shot(model, speed, point)?)
            }
            None => None,
        };
        Ok(SpeedStudy {
            speed,
            best: self.shot(model, speed, best)?,
            at_shape_angle,
            curve,
            bracket: [a, b],
            search_evaluations: evaluations,
        })
    }
}

/// For each launch speed: the range against the launch angle, the best angle `θ*` by
/// golden-section search, and the apex, landing angle and samples of the best path and of the
/// path at `shape_angle` (lecture 2, HW2; see the module documentation for the closed forms
/// it is tested against).
///
/// The model is integrated with its angle and speed parameters set to each flight's values;
/// both, and the landing event's terminal flag, are restored before returning.
///
/// # Shapes
/// Per speed: `curve` has `options.angles` points, each path `options.path_samples`.
///
/// # Units
/// Angles in rad, speeds in m/s, lengths in m (the model's units), times in s.
///
/// # Errors
/// [`LaunchError::UnknownParameter`], [`LaunchError::UnknownEvent`],
/// [`LaunchError::UnknownCoordinate`], [`LaunchError::InvalidSpeed`],
/// [`LaunchError::TooFewAngles`], [`LaunchError::InvalidTolerance`],
/// [`LaunchError::InvalidMaxTime`], [`LaunchError::InvalidShapeAngle`],
/// [`LaunchError::TooFewSamples`] for bad options; for any
/// flight, [`LaunchError::Simulation`], [`LaunchError::IntegrationFailed`],
/// [`LaunchError::NoLanding`], [`LaunchError::OtherEvent`] and [`LaunchError::NonFinite`].
///
/// # Examples
/// Without drag the best angle is 45° and the range `v0²/g`:
/// ```
/// use eomgen::ModelInfo;
/// use eomgen::analysis::launch::{LaunchOptions, launch_study};
///
/// let mut model = (eomgen::models::find("projectile_drag").unwrap().make)();
/// model.set_parameter("c1", 0.0)?;
/// model.set_parameter("c2", 0.0)?;
/// let options = LaunchOptions { speeds: vec![10.0], angles: 9, ..Default::default() };
/// let study = launch_study(model.as_mut(), &options)?;
/// let best = &study.speeds[0].best;
/// assert!((best.angle - std::f64::consts::FRAC_PI_4).abs() < 1e-5);
/// assert!((best.range - 100.0 / 9.81).abs() < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn launch_study(
    model: &mut dyn ModelInfo,
    options: &LaunchOptions,
) -> Result<LaunchStudy, LaunchError> {
    let d = model.description();
    let name = d.name.to_string();
    if d.has_speeds() {
        return Err(LaunchError::InSpeeds { model: name });
    }
    let parameters: Vec<String> = d.parameters.iter().map(|p| p.name.to_string()).collect();
    let coordinates: Vec<String> = d.coordinate_names().iter().map(|c| c.to_string()).collect();
    let parameter_index = |role: &'static str, wanted: &str| {
        parameters
            .iter()
            .position(|p| p == wanted)
            .ok_or_else(|| LaunchError::UnknownParameter {
                model: name.clone(),
                role,
                name: wanted.to_string(),
                known: parameters.clone(),
            })
    };
    let angle_index = parameter_index("angle", &options.angle_parameter)?;
    let speed_index = parameter_index("speed", &options.speed_parameter)?;
    let coordinate_index = |role: &'static str, wanted: &str| {
        coordinates
            .iter()
            .position(|c| c == wanted)
            .ok_or_else(|| LaunchError::UnknownCoordinate {
                model: name.clone(),
                role,
                name: wanted.to_string(),
                known: coordinates.clone(),
            })
    };
    let range_index = coordinate_index("range", &options.range_coordinate)?;
    let height_index = coordinate_index("height", &options.height_coordinate)?;
    let Some(event) = d.events.iter().find(|e| e.name == *options.event) else {
        return Err(LaunchError::UnknownEvent {
            model: name,
            name: options.event.clone(),
            known: d.events.iter().map(|e| e.name.to_string()).collect(),
        });
    };
    let was_terminal = event.terminal;
    let num_model_events = d.events.len();
    let values = model.parameter_values();
    let speeds = if options.speeds.is_empty() {
        vec![values[speed_index]]
    } else {
        options.speeds.clone()
    };
    check_options(options, &speeds)?;
    let launcher = Launcher {
        options,
        range_index,
        height_index,
        num_dofs: model.num_dofs(),
        num_model_events,
    };
    model.set_event_terminal(&options.event, true);
    let studies: Result<Vec<SpeedStudy>, LaunchError> = speeds
        .iter()
        .map(|&speed| launcher.study_speed(model, speed))
        .collect();
    model.set_event_terminal(&options.event, was_terminal);
    let _ = model.set_parameter(&options.angle_parameter, values[angle_index]);
    let _ = model.set_parameter(&options.speed_parameter, values[speed_index]);
    Ok(LaunchStudy {
        model: model.description().name.to_string(),
        angle_parameter: options.angle_parameter.clone(),
        speed_parameter: options.speed_parameter.clone(),
        event: options.event.clone(),
        range_coordinate: options.range_coordinate.clone(),
        height_coordinate: options.height_coordinate.clone(),
        angle_tol: options.angle_tol,
        rtol: options.rtol,
        speeds: studies?,
    })
}

/// The checks of [`launch_study`]'s options, in its order, once the model's names are found:
/// every one of `speeds` positive, at least 3 angles, a positive angle tolerance, `rtol` in
/// `(0, 1)`, a positive maximum time, a shape angle in `(0, π/2)` and at least 2 path
/// samples.
///
/// # Errors
/// [`LaunchError::InvalidSpeed`], [`LaunchError::TooFewAngles`],
/// [`LaunchError::InvalidTolerance`], [`LaunchError::InvalidMaxTime`],
/// [`LaunchError::InvalidShapeAngle`], [`LaunchError::TooFewSamples`].
fn check_options(options: &LaunchOptions, speeds: &[f64]) -> Result<(), LaunchError> {
    if let Some(&speed) = speeds.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(LaunchError::InvalidSpeed { speed });
    }
    if options.angles < 3 {
        return Err(LaunchError::TooFewAngles {
            angles: options.angles,
        });
    }
    if !(options.angle_tol.is_finite() && options.angle_tol > 0.0) {
        return Err(LaunchError::InvalidTolerance {
            name: "angle_tol",
            value: options.angle_tol,
        });
    }
    if !(options.rtol.is_finite() && options.rtol > 0.0 && options.rtol < 1.0) {
        return Err(LaunchError::InvalidTolerance {
            name: "rtol",
            value: options.rtol,
        });
    }
    if !(options.t_max.is_finite() && options.t_max > 0.0) {
        return Err(LaunchError::InvalidMaxTime {
            t_max: options.t_max,
        });
    }
    if let Some(angle) = options.shape_angle
        && !(angle > 0.0 && angle < std::f64::consts::FRAC_PI_2)
    {
        return Err(LaunchError::InvalidShapeAngle { angle });
    }
    if options.path_samples < 2 {
        return Err(LaunchError::TooFewSamples {
            samples: options.path_samples,
        });
    }
    Ok(())
}
