//! The typed model file: what the schema pass builds from YAML and the checks validate.
//!
//! Every name and expression keeps its [`Location`] so that later stages can still report
//! `file:line:col`. Maps of the YAML file keep file order (vectors here).

use super::ast::Expr;
pub use super::elements::body::{Body, BodyKind, InertiaTensor};
pub use super::elements::constraint::PointConstraint;
pub use super::elements::contact::{Contact, Gap};
pub use super::elements::damper::Damper;
pub use super::elements::force::Force;
pub use super::elements::interaction::{INTERACTION_NAMES, Interaction};
pub use super::elements::nonholonomic::RollingContact;
pub use super::elements::point::{Point, RelativePosition, WheelContact};
pub use super::elements::speed::Speed;
pub use super::elements::spring::Spring;
pub use super::elements::torque::{Torque, TorqueValue};
// The `checks:` and `floquet:` types live in `checks.rs`; they are named here too, where
// they were first defined.
pub use super::checks::{
    CHECK_METHODS, Checks, ConservedCheck, DEFAULT_CHECK_TOLERANCE, DEFAULT_CONSTRAINT_DRIFT,
    DEFAULT_ENERGY_DRIFT, DriftCheck, FinalStateCheck, FloquetReference, FloquetThreshold,
    HandEquation, ModalCheck, PeriodCheck, ReferenceCurve, RunSettings,
};
use super::located::{Located, Location};

/// The unit system a model file declares with `units:` (see [`ModelFile::units`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnitSystem {
    /// `units: SI` — coherent SI units (m, kg, s, and the derived N, J, W, Pa; rad is a pure
    /// number), checked by [`super::unit_check`].
    Si,
}

/// A parameter with its default value: `m1: 1.0  # kg, upper arm` or
/// `m1: { value: 1.0, unit: kg }`.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Name (an identifier).
    pub name: Located<String>,
    /// Default as written (a constant expression: numbers, `pi`, functions).
    pub default: Expr,
    /// Default evaluated.
    pub value: f64,
    /// The unit as written, with where it starts: the `unit:` of the map form, else the
    /// trailing YAML comment of the value's line when no other parameter shares the line
    /// (`kg, upper arm` in `m1: 1.0  # kg, upper arm`). In a file with `units: SI` the text
    /// before the first `,` is the binding unit ([`super::units::parse_unit`]); otherwise it
    /// is documentation only.
    pub unit: Option<Located<String>>,
}

/// A generalized coordinate `q`: `- q  # rad, from +x` or `- { name: q, unit: rad }`. Its
/// rate is written `<name>_dot`.
#[derive(Debug, Clone, PartialEq)]
pub struct Coordinate {
    /// Name (an identifier).
    pub name: Located<String>,
    /// The text of a trailing YAML comment, if any (`# angle from +x`).
    pub comment: Option<String>,
    /// The `unit:` of the map form `{ name: x, unit: m }`, if given. In a file with
    /// `units: SI` a coordinate's unit is this, else the start of its comment (before the
    /// first `,`) when that parses as a unit, else inferred from its use
    /// ([`super::unit_check`]).
    pub unit: Option<Located<String>>,
}

pub use super::elements::frame::{Frame, SimpleRotation};
pub use super::elements::{Axis, GROUND_FRAME};

/// One `outputs:` entry: a named expression of the state evaluated along a simulation,
/// `name: expr` or `name: { value: expr, conserved: true, tolerance: 1e-9 }`.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputDef {
    /// Its name.
    pub name: Located<String>,
    /// The expression: parameters, coordinates, rates, `t` and the vector functions of
    /// points.
    pub value: Expr,
    /// Whether it is a constant of the motion, which `eomgen simulate` measures the drift of
    /// and `eomgen report` checks.
    pub conserved: bool,
    /// Bound on the drift `max |Q(t) − Q(0)| / max(1, |Q(0)|)` of a conserved output.
    pub tolerance: f64,
}

/// Which momentum balance a [`Balance`] writes.
#[derive(Debug, Clone, PartialEq)]
pub enum BalanceKind {
    /// Angular momentum balance about a point (fixed or moving), planar models:
    /// `Σ (r_G − r_A) × m a_G + I θ̈ = Σ (r_P − r_A) × F + Σ τ` over the chosen bodies.
    Amb {
        /// The point A.
        about: Located<String>,
        /// How the balance is written (`form:`; default [`AmbForm::RCrossMa`]).
        form: AmbForm,
        /// In a 3-D model, the axis `e` the moments are taken about (`axis: [0, 0, 1]`,
        /// components in the frame `in`): `Σ M_A·e = (dH_A/dt)·e`. `None` in the plane.
        axis: Option<Located<Vec<Expr>>>,
        /// The frame of the axis's components (`in: B`); `None`: the ground frame.
        frame: Option<Located<String>>,
    },
    /// Linear momentum balance of the chosen bodies along a direction `e`:
    /// `Σ m a_G·e = Σ F·e`.
    Lmb {
        /// The direction `e` (expressions of `q` and `t`, as many components as the points).
        along: Vec<Expr>,
    },
}

/// How an angular momentum balance about a point A is written (`form:` of an `amb` entry).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AmbForm {
    /// `form: r_x_ma` (the default): `Σ M_A = Σ (r_G − r_A) × m a_G + I θ̈`, with absolute
    /// accelerations, which holds about any point, fixed or moving (HW4, HW15 a).
    #[default]
    RCrossMa,
    /// `form: h_dot`: `Σ M_A = dH_A/dt` with `H_A = Σ (r_G − r_A) × m v_G + I θ̇`, the
    /// fixed-point form. It holds only when `v_A × v_G = 0` (A fixed, A the centre of mass, or
    /// moving parallel to it); about any other moving point it misses `v_A × m v_G`, the
    /// classic mistake of HW4 and HW15 that `eomgen check` detects.
    HDot,
    /// `form: h_rel_dot`: `Σ M_A = dH_A/rel/dt` with the angular momentum of the motion
    /// relative to A, `H_A/rel = Σ (r_G − r_A) × m (v_G − v_A) + I θ̇`. Since
    /// `dH_A/rel/dt = Σ (r_G − r_A) × m a_G + I θ̈ − Σ (r_G − r_A) × m a_A`, it holds only when
    /// `(r_G − r_A) × a_A = 0` summed with the masses: A fixed or moving at constant velocity,
    /// A the centre of mass, or A accelerating toward or away from it (a disc's contact point
    /// rolling on flat ground; HW4, HW15).
    HRelDot,
}

/// One momentum-balance equation chosen by the user (`balances:`), as the course writes them:
/// `{ amb: { about: O, bodies: [upper, fore] } }` or `{ lmb: { bodies: [slider], along: [..] } }`.
#[derive(Debug, Clone, PartialEq)]
pub struct Balance {
    /// AMB or LMB.
    pub kind: BalanceKind,
    /// The bodies whose momentum is balanced.
    pub bodies: Vec<Located<String>>,
    /// The named set the balance belongs to (`balances: { NAME: [...] }`); `None` in the
    /// plain list form, one set.
    pub set: Option<Located<String>>,
    /// Whether its set is stated to disagree with Lagrange (`{ expect: disagree, balances:
    /// [...] }`): a wrong form kept to show why it is wrong; `eomgen check` then passes it
    /// only when it does disagree.
    pub expect_disagreement: bool,
    /// Where the entry starts.
    pub location: Location,
}

impl Balance {
    /// The name of the set the balance belongs to; `None` in the plain list form.
    pub fn set_name(&self) -> Option<&str> {
        self.set.as_ref().map(|s| s.value.as_str())
    }
}

/// What an animation draws (`draw:`): the lines and traced points of `eomgen animate`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Draw {
    /// Line segments between named points.
    pub lines: Vec<[Located<String>; 2]>,
    /// Points whose trajectories are traced.
    pub trace: Vec<Located<String>>,
    /// Wheels drawn as circles with four spokes (3-D models): each a circle of `radius`
    /// about `centre` in the plane normal to the axis `axle` of `frame`, turning with it.
    pub wheels: Vec<WheelContact>,
    /// The shapes the 3-D view draws bodies as (`shapes:`).
    pub shapes: Vec<super::elements::shape::DrawnShape>,
}

/// Which zero crossings of an event function count (`direction:` of an `events:` entry).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Crossing {
    /// From negative to non-negative.
    Rising,
    /// From positive to non-positive ("reaches zero from above").
    Falling,
    /// Either (the default).
    #[default]
    Both,
}

impl Crossing {
    /// `rising`, `falling` or `both`.
    pub fn name(self) -> &'static str {
        match self {
            Crossing::Rising => "rising",
            Crossing::Falling => "falling",
            Crossing::Both => "both",
        }
    }
}

/// One `events:` entry: `name: { when: g, direction: falling, terminal: true }`, or
/// `name: g` (both directions, not terminal). The integrators locate the zeros of `g`
/// (lecture 17, HW21, HW36).
#[derive(Debug, Clone, PartialEq)]
pub struct EventDef {
    /// The event's name.
    pub name: Located<String>,
    /// The event function `g`: parameters, coordinates, `t`, rates, accelerations (`x_ddot`)
    /// and constraint forces (`lambda_<constraint>`).
    pub when: Expr,
    /// Which crossings count.
    pub direction: Crossing,
    /// Whether the first crossing ends the integration.
    pub terminal: bool,
}

/// One `equilibria:` entry: a named starting guess for the equilibrium search (issue 7;
/// lecture 25), `hanging: { theta1: 0, theta2: 0 }`; coordinates not listed start at 0.
#[derive(Debug, Clone, PartialEq)]
pub struct EquilibriumDef {
    /// Its name (`hanging`, `upright`).
    pub name: Located<String>,
    /// Guessed coordinate values by coordinate name, and the constant rates of a steady
    /// motion by rate name (`phi_dot`), as constant expressions.
    pub values: Vec<(Located<String>, Expr)>,
    /// `ignorable: [phi]` — coordinates that a steady motion's linearisation leaves out
    /// (cyclic coordinates: nothing else depends on them).
    pub ignorable: Vec<Located<String>>,
    /// Coordinates written `{ held: value }`: kept at their value by the search instead of
    /// found (the lean of a bicycle's steady turn, whose speed is then found).
    pub held: Vec<Located<String>>,
    /// Rates written `{ guess: value }`: found by the search instead of held (the rates the
    /// rolling constraints fix, such as a bicycle's front wheel rate in a turn).
    pub solved: Vec<Located<String>>,
    /// `turning: { angle: yaw, plane: [x, y] }` — a steady turn: the rates of the `plane`
    /// coordinates are constant in the frame turned by `angle`, not in the ground.
    pub turning: Option<TurningDef>,
}

/// The turning frame of a steady turn (a relative equilibrium): the rates `(ȧ, ḃ)` of two
/// Cartesian coordinates are constant in the frame turned by the angle `angle` about the
/// normal of their plane, so that in the ground they turn at `angle`'s rate: `ä = −Ω ḃ`,
/// `b̈ = Ω ȧ`, `Ω` the angle's rate.
#[derive(Debug, Clone, PartialEq)]
pub struct TurningDef {
    /// The coordinate whose rate turns the frame (a heading).
    pub angle: Located<String>,
    /// The two coordinates whose rates are constant in the turning frame, in the order
    /// that makes a positive `angle` turn the first toward the second.
    pub plane: Vec<Located<String>>,
    /// Where the `turning:` key is.
    pub at: Location,
}

/// A whole model file after the schema pass.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelFile {
    /// The path as the user wrote it (used in messages).
    pub path: String,
    /// `name:` — a snake_case identifier; the generated struct is its UpperCamelCase.
    pub name: Located<String>,
    /// `description:` — one line.
    pub description: String,
    /// `minimal_twin:` — the bundled model with the same mechanism in minimal coordinates
    /// (`simple_pendulum` for `simple_pendulum_cartesian`), which `eomgen study
    /// constraint-methods` runs beside the constrained forms; `None` if the file names none.
    pub minimal_twin: Option<Located<String>>,
    /// `units: SI` — opts the file in to dimensional checks ([`super::unit_check`]): every
    /// parameter must then carry a unit, and every expression must be dimensionally
    /// consistent with its key. `None`: units are documentation only.
    pub units: Option<Located<UnitSystem>>,
    /// `parameters:`, in file order.
    pub parameters: Vec<Parameter>,
    /// `coordinates:`, in file order.
    pub coordinates: Vec<Coordinate>,
    /// `kinetic:` T (energy form).
    pub kinetic: Option<Expr>,
    /// `potential:` V (energy form).
    pub potential: Option<Expr>,
    /// `generalized_forces:` Q by coordinate name (energy form).
    pub generalized_forces: Vec<(Located<String>, Expr)>,
    /// `frames:` — reference frames by successive simple rotations, in file order (3-D
    /// models; the ground frame `N` is predefined).
    pub frames: Vec<Frame>,
    /// `points:`.
    pub points: Vec<Point>,
    /// `bodies:`.
    pub bodies: Vec<Body>,
    /// `gravity:` acceleration vector (m/s²).
    pub gravity: Option<Located<Vec<Expr>>>,
    /// `springs:`.
    pub springs: Vec<Spring>,
    /// `dampers:`.
    pub dampers: Vec<Damper>,
    /// `forces:`.
    pub forces: Vec<Force>,
    /// `torques:`.
    pub torques: Vec<Torque>,
    /// `interactions:` — forces between two points along their line, in file order.
    pub interactions: Vec<Interaction>,
    /// `outputs:` — named expressions of the state, in file order.
    pub outputs: Vec<OutputDef>,
    /// `speeds:` — generalized speeds, one per coordinate, in file order (empty: the state
    /// holds the coordinates' rates).
    pub speeds: Vec<Speed>,
    /// `initial:` by coordinate or rate name (`theta1`, `theta1_dot`); expressions of the
    /// parameters.
    pub initial: Vec<(Located<String>, Expr)>,
    /// `draw:`.
    pub draw: Draw,
    /// `balances:` — momentum-balance equations chosen by the user (empty if none).
    pub balances: Vec<Balance>,
    /// `constraints:` — holonomic constraints `Φ(q, t) = 0` by name, in file order.
    pub constraints: Vec<(Located<String>, Expr)>,
    /// `constraints:` entries on a point's position, in file order (after those of
    /// [`Self::constraints`]).
    pub point_constraints: Vec<PointConstraint>,
    /// `nonholonomic:` — constraints `A(q, t) q̇ + b(q, t) = 0` by name (the expression is the
    /// left-hand side, linear in the rates), in file order.
    pub nonholonomic: Vec<(Located<String>, Expr)>,
    /// `nonholonomic:` entries that are rolling contacts, in file order (their constraints
    /// come after those of [`Self::nonholonomic`]).
    pub rolling: Vec<RollingContact>,
    /// `contacts:` — unilateral contacts, in file order.
    pub contacts: Vec<Contact>,
    /// Coordinates whose `initial:` value is only a guess (`theta2: { guess: 0.5 }`): the
    /// runtime solves them, and their rates, from the constraints.
    pub initial_guesses: Vec<Located<String>>,
    /// `checks:` — the file's claims about its own model (empty if none).
    pub checks: Checks,
    /// `events:` — functions whose zeros the integrators locate, in file order.
    pub events: Vec<EventDef>,
    /// `equilibria:` — named guesses for equilibrium searches, in file order.
    pub equilibria: Vec<EquilibriumDef>,
    /// `floquet:` — reference results of Floquet charts by equilibrium, in file order.
    pub floquet: Vec<FloquetReference>,
    /// The spatial dimension of the points (2 or 3); `None` when there are no points.
    pub dimension: Option<usize>,
}

impl ModelFile {
    /// The energy form as written: `kinetic:` (J), `potential:` (J) and `generalized_forces:`
    /// by coordinate name.
    pub fn written_energies(&self) -> super::elements::energy::Written<'_> {
        (
            self.kinetic.as_ref(),
            self.potential.as_ref(),
            &self.generalized_forces,
        )
    }

    /// The frame and axis that `name` reads if it is `omega_<frame>_<axis>`, the component
    /// of the frame's angular velocity in the ground frame along its own axis (rad/s), with
    /// `<frame>` one of [`Self::frames`].
    pub fn angular_velocity_name(&self, name: &str) -> Option<(&Frame, Axis)> {
        super::elements::frame::angular_velocity_of(&self.frames, name)
    }

    /// The names of every non-holonomic constraint, located: the expressions', then each
    /// rolling contact's rows.
    pub fn nonholonomic_names(&self) -> Vec<Located<String>> {
        self.nonholonomic
            .iter()
            .map(|(k, _)| k.clone())
            .chain(
                self.rolling
                    .iter()
                    .flat_map(RollingContact::constraint_names),
            )
            .collect()
    }

    /// The sets of [`Self::balances`] in file order, by name (`None`: the plain list form,
    /// one set).
    pub fn balance_sets(&self) -> Vec<Option<&str>> {
        let mut sets: Vec<Option<&str>> = Vec::new();
        for b in &self.balances {
            if !sets.contains(&b.set_name()) {
                sets.push(b.set_name());
            }
        }
        sets
    }

    /// The names of every holonomic constraint, located: the expressions', then those on
    /// points.
    pub fn holonomic_names(&self) -> Vec<Located<String>> {
        self.constraints
            .iter()
            .map(|(k, _)| k.clone())
            .chain(self.point_constraints.iter().map(|c| c.name.clone()))
            .collect()
    }

    /// The names of every constraint, holonomic first, located.
    pub fn constraint_names(&self) -> Vec<Located<String>> {
        self.holonomic_names()
            .into_iter()
            .chain(self.nonholonomic_names())
            .collect()
    }
}
