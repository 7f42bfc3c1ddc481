//! Lowering a checked [`ModelFile`] into the expression arena: symbols for parameters,
//! coordinates, rates and time; point positions; `T`, `V` and the generalized forces `Q`
//! assembled from bodies, gravity, springs, dampers, forces and torques.

use rustc_hash::FxHashMap;

use super::constraints::{ConstraintEquations, linear_in_rates, redundant_rows};
use super::frames::{Frames, Vector3};
use crate::expr::{Constant, ExprArena, ExprId, Func, SymbolId, SymbolKind};
use crate::model::ast::{BinOp, Expr, ExprKind};
use crate::model::checks::FloquetReference;
use crate::model::diagnostic::Diagnostic;
use crate::model::diagnostic::short;
use crate::model::elements::{self, contact::ContactInfo, frame, gravity, point};
use crate::model::file::{GROUND_FRAME, ModelFile};
use crate::model::located::{Located, Location};

mod bodies;
mod constraint_rows;
mod contacts;
mod expressions;
mod loads;
mod sections;
#[cfg(test)]
mod tests;

/// A parameter of a lowered model.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterInfo {
    /// Name.
    pub name: String,
    /// Default value.
    pub default: f64,
    /// Unit from the model file's comment.
    pub unit: Option<String>,
    /// Its symbol.
    pub symbol: SymbolId,
}

pub use crate::model::elements::body::{BodyInfo, SpatialBody};

/// A load of the kinematic form, kept as a force or torque (not a potential), for the
/// momentum-balance derivation.
#[derive(Debug, Clone, PartialEq)]
pub enum LoadInfo {
    /// A force vector at a point (index into [`SymbolicModel::points`]).
    Force {
        /// Point of application.
        point: usize,
        /// Components (N).
        vector: Vec<ExprId>,
    },
    /// A torque (N·m) on a body whose angle is `angle`.
    Torque {
        /// Index into [`SymbolicModel::bodies`] of the body it acts on.
        body: usize,
        /// The body's angle expression.
        angle: ExprId,
        /// Torque, counter-clockwise.
        value: ExprId,
    },
    /// A torque vector (N·m) on a 3-D rigid body, in the body frame's components.
    SpatialTorque {
        /// Index into [`SymbolicModel::bodies`] of the body it acts on.
        body: usize,
        /// Components along the body frame's axes.
        vector: Vector3,
    },
    /// A linear spring between two points (equal and opposite forces along the line).
    Spring {
        /// End points.
        between: [usize; 2],
        /// Stiffness (N/m).
        stiffness: ExprId,
        /// Rest length (m); `None` for zero.
        rest_length: Option<ExprId>,
    },
    /// A viscous damper along the line of two points.
    Damper {
        /// End points.
        between: [usize; 2],
        /// Coefficient (N·s/m).
        coefficient: ExprId,
    },
}

/// A set of the user's balances: one derivation of the equations of motion.
#[derive(Debug, Clone, PartialEq)]
pub struct BalanceSet {
    /// Its name; `balances` for the plain list form.
    pub name: String,
    /// Its entries' range in [`SymbolicModel::balances`].
    pub range: std::ops::Range<usize>,
    /// Whether the file states that it disagrees with Lagrange (`expect: disagree`).
    pub expect_disagreement: bool,
}

/// A user-chosen momentum balance (`balances:`), as expressions.
#[derive(Debug, Clone, PartialEq)]
pub enum BalanceInfo {
    /// Angular momentum balance about point `about` (index into [`SymbolicModel::points`]) of
    /// the bodies `bodies` (indices into [`SymbolicModel::bodies`]).
    Amb {
        /// The point.
        about: usize,
        /// The bodies.
        bodies: Vec<usize>,
        /// How the balance is written.
        form: crate::model::file::AmbForm,
        /// The axis `e` of a 3-D balance, in the ground frame's components; `None` in the
        /// plane.
        axis: Option<Vec<ExprId>>,
    },
    /// Linear momentum balance of `bodies` along `along`.
    Lmb {
        /// The direction.
        along: Vec<ExprId>,
        /// The bodies.
        bodies: Vec<usize>,
    },
}

/// What a model with generalized speeds keeps of them ([`SymbolicModel::speeds`]; built and
/// used by `super::speeds`).
#[derive(Debug, Clone, PartialEq)]
pub struct Speeds {
    /// The speeds' names, one per coordinate: the file's, in file order, then the constraint
    /// rows' (their auxiliary speeds, held at 0 by the constraints).
    pub names: Vec<String>,
    /// How many of [`Self::names`] are the constraint rows' auxiliary speeds (the last ones):
    /// `uᵣ = A q̇ + b` (`J q̇ + Φ_t` of a holonomic row), held at 0 by its multiplier.
    pub auxiliary: usize,
    /// Whether the model's expressions (and the equations listed with it) have been taken on
    /// the constraints, the auxiliary speeds at 0 ([`super::on_the_constraints`]), to be read.
    pub on_the_constraints: bool,
    /// The kinematic equations: `q̇ⱼ` as an expression of `q`, `u` and `t`, per coordinate.
    pub kinematic_equations: Vec<ExprId>,
    /// `Y`, `n × n` row-major: `u = Y q̇ + Z` (the auxiliary speeds' rows are the
    /// constraints' `A`).
    pub coefficients: Vec<ExprId>,
    /// `W = Y⁻¹`, `n × n` row-major: `q̇ = W (u − Z)`.
    pub inverse: Vec<ExprId>,
    /// `Z(q, t)`, per speed: its value with every rate 0.
    pub offsets: Vec<ExprId>,
    /// Lagrange's equations carried into the speeds: `M` (`n × n`, row-major) and `F`.
    pub lagrange: (Vec<ExprId>, Vec<ExprId>),
    /// `det(Y)`, multiplied out.
    pub(crate) determinant: ExprId,
    /// `adj(Y)`, `n × n` row-major, each entry multiplied out.
    pub(crate) adjugate: Vec<ExprId>,
}

/// A model file turned into expressions: everything a [`super::Formulation`] needs.
#[derive(Debug, Clone)]
pub struct SymbolicModel {
    /// The arena that owns every expression below.
    pub arena: ExprArena,
    /// Model name (snake_case).
    pub name: String,
    /// One-line description.
    pub description: String,
    /// Parameters in file order.
    pub parameters: Vec<ParameterInfo>,
    /// Coordinate names in order.
    pub coordinate_names: Vec<String>,
    /// `[q, q̇, q̈]` expressions per coordinate.
    pub coordinates: Vec<[ExprId; 3]>,
    /// The time symbol.
    pub time: ExprId,
    /// The time symbol's id.
    pub time_id: SymbolId,
    /// Named points and their position components (2 or 3) in the ground frame.
    pub points: Vec<(String, Vec<ExprId>)>,
    /// The reference frames (3-D models; only the ground frame otherwise).
    pub frames: Frames,
    /// Kinetic energy `T(q, q̇, t)` (J).
    pub kinetic: ExprId,
    /// Potential energy `V(q, t)` (J): gravity, springs and the file's `potential`.
    pub potential: ExprId,
    /// Non-potential generalized forces `Q` (one per coordinate): dampers, forces, torques
    /// and the file's `generalized_forces`, projected on the partial velocities.
    pub generalized_forces: Vec<ExprId>,
    /// Initial `q(0)` per coordinate (expressions of the parameters; 0 if not given).
    pub initial_q: Vec<ExprId>,
    /// Initial `q̇(0)` per coordinate.
    pub initial_qdot: Vec<ExprId>,
    /// Whether `T + V` is conserved: no dampers, forces, torques or generalized forces, no
    /// explicit time dependence in `T` or `V`, `T` a quadratic form in the rates, and
    /// workless constraints (no `t` in a holonomic `Φ`, `b = 0` in a non-holonomic one).
    pub conservative: bool,
    /// Spatial dimension of the points (2 or 3; 2 when there are none).
    pub dimension: usize,
    /// Line segments to draw, as point-index pairs.
    pub draw_lines: Vec<[usize; 2]>,
    /// Points whose trajectories are traced (`draw: trace`), as point indices.
    pub trace_points: Vec<usize>,
    /// Bodies of the kinematic form.
    pub bodies: Vec<BodyInfo>,
    /// The file's `draw: shapes:`, by body name, as the model's description keeps them.
    pub shapes: Vec<(String, eomgen_description::Shape)>,
    /// Gravity vector (m/s²), if given.
    pub gravity: Option<Vec<ExprId>>,
    /// Springs, dampers, forces and torques as loads.
    pub loads: Vec<LoadInfo>,
    /// The user's balances (empty if none), every set's in file order.
    pub balances: Vec<BalanceInfo>,
    /// The sets of [`Self::balances`], in file order.
    pub balance_sets: Vec<BalanceSet>,
    /// Whether the file uses the energy form (`kinetic`, `potential` or
    /// `generalized_forces`), which a derivation from the kinematics alone cannot use.
    pub uses_energy_form: bool,
    /// Whether the file writes `kinetic:` (which momentum balance, deriving the inertia of
    /// the bodies from their kinematics, cannot use).
    pub kinetic_written: bool,
    /// The file's `potential:` alone (0 if none): momentum balance adds `−∂V/∂qᵢ` to `Fᵢ`.
    pub written_potential: ExprId,
    /// The file's `generalized_forces:` alone, per coordinate (0 where none): momentum
    /// balance adds them to `F`.
    pub written_forces: Vec<ExprId>,
    /// The residuals `lhs − rhs` of the file's equations of motion written by hand
    /// (`checks: equations_of_motion`), in the coordinates, rates and accelerations; empty
    /// when the file gives none.
    pub hand_equations: Vec<ExprId>,
    /// Holonomic and non-holonomic constraints at the acceleration level (empty if none).
    pub constraints: ConstraintEquations,
    /// Unilateral contacts (`contacts:`), in file order.
    pub contacts: Vec<ContactInfo>,
    /// Coordinates whose initial value is a guess to be solved from the constraints.
    pub initial_guesses: Vec<usize>,
    /// The file's `events:` (empty if none).
    pub events: Vec<EventInfo>,
    /// The file's `equilibria:`, in file order.
    pub equilibria: Vec<Equilibrium>,
    /// With `speeds:`, the generalized speeds: the state is `(q, u)`, the coordinates'
    /// triples hold `(q, u, u̇)`, and every expression above is in them
    /// (`mechanics/speeds.rs`); `None`: the state is `(q, q̇)`.
    pub speeds: Option<Speeds>,
    /// The file's `checks:` reference results, as the model's description keeps them.
    pub checks: eomgen_description::checks::Checks,
    /// The file's `floquet:` references, as the model's description keeps them.
    pub floquet: Vec<eomgen_description::floquet::FloquetReference>,
    /// The file's `outputs:`, as the model's description keeps them (an output that uses
    /// the vector functions written out in the coordinates and rates).
    pub outputs: Vec<eomgen_description::outputs::OutputSpec>,
}

/// An entry of the file's `equilibria:`: an equilibrium or a steady motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Equilibrium {
    /// Its name.
    pub name: String,
    /// A guess per coordinate (0 where not given), an expression of the parameters.
    pub guess: Vec<ExprId>,
    /// The rate per coordinate that a steady motion holds (0 where not given; all 0 for an
    /// equilibrium).
    pub rates: Vec<ExprId>,
    /// Indices of the coordinates the linearisation leaves out (`ignorable:`).
    pub ignorable: Vec<usize>,
    /// Indices of the coordinates the search holds at their value (`{ held: … }`).
    pub held: Vec<usize>,
    /// Indices of the coordinates whose rates the search finds (`{ guess: … }`).
    pub solved: Vec<usize>,
    /// A steady turn's frame (`turning:`): the turning angle's index and the two plane
    /// coordinates' indices.
    pub turning: Option<[usize; 3]>,
}

/// The box in which the derivation checks draw random states (`eomgen check`, the mass
/// matrix's diagnostics): coordinate or rate `i` at `cᵢ + sᵢ r` for a draw `r` in [−2, 2],
/// where `cᵢ` is its value in `initial:` (the parameters at their defaults) and
/// `sᵢ = max(1, |cᵢ|)`.
///
/// About the start, because a model's domain need not hold the origin (`ln(x − 10)` started
/// at `x = 12` is defined nowhere in [−2, 2]). In proportion to the start's size, because a
/// coordinate started at 1e6 m varies on that scale, and ±2 m about it would sample one
/// point as far as its terms can tell; its sign may change within the box as it may at the
/// origin. Never narrower than ±2, so that an angle started at 0.1 rad still sweeps its
/// sines and cosines over radians. A start at 0 gives the box [−2, 2] and the very states
/// drawn before the box followed the start (`0 + 1·r` is `r`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct StateBox {
    /// Per symbol, by index: `(centre, scale)`; `(0, 1)` for a symbol that is neither a
    /// coordinate nor a rate.
    axes: Vec<(f64, f64)>,
}

impl StateBox {
    /// The value of the symbol of index `k` for a draw `r` in [−2, 2] (`r` itself for a
    /// symbol that is neither a coordinate nor a rate).
    pub(crate) fn at(&self, k: usize, r: f64) -> f64 {
        let (centre, scale) = self.axes[k];
        centre + scale * r
    }
}

/// One lowered `events:` entry.
#[derive(Debug, Clone, PartialEq)]
pub struct EventInfo {
    /// Its name.
    pub name: String,
    /// The event function `g(q, q̇, q̈, λ, t)`.
    pub function: ExprId,
    /// Which crossings count.
    pub direction: crate::model::file::Crossing,
    /// Whether it ends the integration.
    pub terminal: bool,
}

impl SymbolicModel {
    /// Whether an event function uses an acceleration or a constraint force, so that the
    /// runtime must solve for them before evaluating it.
    pub fn events_need_accelerations(&self) -> bool {
        let roots: Vec<ExprId> = self.events.iter().map(|e| e.function).collect();
        self.arena.reachable(&roots).iter().any(|e| {
            matches!(
                self.arena.node(*e),
                crate::expr::Node::Symbol(s) if matches!(
                    self.arena.symbol_info(*s).kind,
                    SymbolKind::Acceleration(_) | SymbolKind::Multiplier(_)
                )
            )
        })
    }
}

impl SymbolicModel {
    /// Whether an entry of `equilibria:` is a steady motion: it gives a rate that is not
    /// identically 0.
    pub fn has_steady_motions(&self) -> bool {
        self.equilibria
            .iter()
            .any(|e| e.rates.iter().any(|r| !self.arena.is_zero(*r)))
    }

    /// Number of degrees of freedom `n`.
    pub fn num_dofs(&self) -> usize {
        self.coordinates.len()
    }

    /// Symbol ids `(q, q̇, q̈)` of coordinate `i`.
    pub fn coordinate_symbols(&self, i: usize) -> [SymbolId; 3] {
        self.arena.coordinates()[i]
    }

    /// Whether the model is in generalized speeds with an offset `Z(q, t) ≠ 0` in one of them
    /// (`u = Y q̇ + Z`) or coefficients `Y` that depend on `t`: its `T(q, u)` then shows neither
    /// `T`'s degree in `q̇` nor whether `T(q, q̇)` depends on `t`, and the energy routes and
    /// the power balance, which ask that, do not apply.
    pub fn speeds_hide_the_energy_form(&self) -> bool {
        self.speeds_have_offsets()
            || (self.speeds.iter())
                .flat_map(|s| &s.inverse)
                .any(|w| self.arena.depends_on(*w, self.time_id))
    }

    /// Whether the model is in generalized speeds whose coefficients `Y` or offsets `Z`
    /// depend on `t` explicitly: rest, `q̇ = 0`, is then `u = Z(q, t)` moving with `t`, and
    /// `u̇ = Y q̈ + Ż` there.
    pub fn speeds_depend_on_time(&self) -> bool {
        (self.speeds.iter())
            .flat_map(|s| s.inverse.iter().chain(&s.offsets))
            .any(|e| self.arena.depends_on(*e, self.time_id))
    }

    /// Whether the model is in generalized speeds with an offset `Z(q, t) ≠ 0` in one of them.
    pub fn speeds_have_offsets(&self) -> bool {
        (self.speeds.iter())
            .flat_map(|s| &s.offsets)
            .any(|z| !self.arena.is_zero(*z))
    }

    /// The time symbol id.
    pub fn time_symbol(&self) -> SymbolId {
        self.time_id
    }

    /// Where the derivation checks draw their random states: around the file's start (see
    /// [`StateBox`]).
    pub(crate) fn state_box(&self) -> StateBox {
        let symbols = self.arena.symbols();
        // The start with the parameters at their defaults, every other symbol 0.
        let mut bindings = vec![0.0; symbols.len()];
        for p in &self.parameters {
            bindings[p.symbol.index()] = p.default;
        }
        let starts: Vec<ExprId> = self
            .initial_q
            .iter()
            .chain(&self.initial_qdot)
            .copied()
            .collect();
        let start = crate::expr::eval::Evaluator::new(&self.arena, &starts).eval(&bindings);
        let n = self.num_dofs();
        let axes = symbols
            .iter()
            .map(|s| {
                let centre = match s.kind {
                    SymbolKind::Coordinate(i) => start[i as usize],
                    SymbolKind::Velocity(i) => start[n + i as usize],
                    _ => 0.0,
                };
                // A start that is not a number (a default outside a function's domain) gives
                // no centre: the box about 0.
                let centre = if centre.is_finite() { centre } else { 0.0 };
                (centre, centre.abs().max(1.0))
            })
            .collect();
        StateBox { axes }
    }
}

/// A checked model file lowered as it is written, in the coordinates' rates
/// ([`SymbolicModel::from_file`] then switches a file with `speeds:` to them), with the
/// speeds' definitions (in the rates, file order) and their `initial:` values if the file
/// gives any.
///
/// # Errors
/// A diagnostic for anything the checks should have rejected (unknown name, wrong
/// dimension); with a model that passed [`crate::model::load`] this does not happen.
pub(super) fn lower_file(file: &ModelFile) -> Result<Lowered, Vec<Diagnostic>> {
    Lowering::new(file).run()
}

/// What [`lower_file`] gives: the model, the speeds' definitions and their initial values.
pub(super) type Lowered = (SymbolicModel, Vec<ExprId>, Option<Vec<ExprId>>);

struct Lowering<'f> {
    file: &'f ModelFile,
    arena: ExprArena,
    /// `omega_<frame>_<axis>` by name: the components of the frames' angular velocities in
    /// their own axes, once the frames are lowered.
    angular_velocities: FxHashMap<String, ExprId>,
    errors: Vec<Diagnostic>,
    /// Whether accelerations (`x_ddot`) may appear: only in equations written by hand.
    allow_accelerations: bool,
    /// The points' positions, once lowered, for the vector functions (`dot(P - O, …)`).
    points: Points,
    /// Names bound while lowering one expression: an interaction's `r` and `r_dot`.
    locals: Vec<(String, ExprId)>,
    /// The frames, once lowered (before the points, the bodies and the loads), for the
    /// elements ([`elements::Lower`]).
    frames: Frames,
    /// The bodies, once lowered, for the elements.
    bodies: Vec<BodyInfo>,
    /// The generalized speeds by name, as their definitions in the rates (`speeds:`).
    speeds: FxHashMap<String, ExprId>,
}

impl<'f> Lowering<'f> {
    fn new(file: &'f ModelFile) -> Self {
        Self {
            file,
            arena: ExprArena::new(),
            angular_velocities: FxHashMap::default(),
            errors: Vec::new(),
            allow_accelerations: false,
            points: Vec::new(),
            locals: Vec::new(),
            frames: Frames::default(),
            bodies: Vec::new(),
            speeds: FxHashMap::default(),
        }
    }

    /// Lowers the whole file, section by section, into a [`SymbolicModel`]; every error of
    /// every section is reported.
    ///
    /// The sections are lowered in a fixed order, which this function spells out: the arena
    /// interns each new expression at its first use, so the order fixes every [`ExprId`],
    /// hence the canonical order of sums and products and the generated code.
    // Long: it calls each section's lowering in the order they depend on each other, then
    // gathers the forty fields of the lowered model; the work of each is in its own method.
    fn run(mut self) -> Result<Lowered, Vec<Diagnostic>> {
        let file = self.file;
        let time_id = self.arena.time_id();
        let time = self.arena.symbol_expr(time_id);
        let parameters = self.parameters();
        let coordinates: Vec<[ExprId; 3]> = file
            .coordinates
            .iter()
            .map(|c| self.arena.coordinate(&c.name.value))
            .collect();
        let n = coordinates.len();
        let coordinate_names: Vec<String> = file
            .coordinates
            .iter()
            .map(|c| c.name.value.clone())
            .collect();
        // The frames and then the points, as the elements read them (`elements::Lower`).
        self.frames = self.frames_with_rates();
        let points = point::lower(&file.points, &mut self);
        self.points = points.clone();
        // The speeds' definitions, which the expressions below may name.
        let speed_definitions: Vec<ExprId> = (file.speeds.iter())
            .map(|sp| {
                let d = self.expr(&sp.value);
                self.speeds.insert(sp.name.value.clone(), d);
                d
            })
            .collect();
        let dimension = file.dimension.unwrap_or(2);

        let mut terms = Terms {
            kinetic: Vec::new(),
            potential: Vec::new(),
            forces: vec![Vec::new(); n],
            half: self.arena.constant(Constant::Rational { num: 1, den: 2 }),
        };
        self.energies_written(&mut terms, &coordinate_names);
        // The written pieces alone, for momentum balance (which derives the rest from the
        // kinematics): they are the first terms of `V` and of each `Q`.
        let written_potential = self.arena.sum(&terms.potential);
        let written_forces: Vec<ExprId> = terms
            .forces
            .iter()
            .map(|terms| self.arena.sum(terms))
            .collect();
        let gravity: Option<Vec<ExprId>> =
            file.gravity.as_ref().map(|g| gravity::lower(g, &mut self));
        let body_infos = self.bodies(gravity.as_deref(), &mut terms);
        let mut loads = self.springs(&mut terms);
        loads.extend(self.dampers(&mut terms));
        let frames = self.frames.clone();
        self.bodies = body_infos.clone();
        loads.extend(self.forces(&mut terms));
        loads.extend(self.torques(&mut terms));
        let (interaction_loads, interactions_at_start) = self.interactions(&mut terms);
        loads.extend(interaction_loads);
        let balances = self.balances(&points, &body_infos, &frames);
        let balance_sets = balance_sets(self.file);
        let hand_equations = self.hand_equations();

        let constraints = self.constraints(file, &parameters);
        if !file.events.is_empty() {
            for (i, name) in constraints.names.iter().enumerate() {
                self.arena
                    .symbol(&format!("lambda_{name}"), SymbolKind::Multiplier(i as u32));
            }
        }
        let contacts: Vec<ContactInfo> = file
            .contacts
            .iter()
            .filter_map(|c| c.lower(&mut self))
            .collect();
        let events = self.events();
        let equilibria = self.equilibria(&coordinate_names);
        let initial_guesses: Vec<usize> = file
            .initial_guesses
            .iter()
            .filter_map(|g| coordinate_names.iter().position(|c| *c == g.value))
            .collect();

        let kinetic = self.arena.sum(&terms.kinetic);
        let contacts = self.support_blocks(contacts, &body_infos, &points);
        let potential = self.arena.sum(&terms.potential);
        let generalized_forces: Vec<ExprId> = terms
            .forces
            .iter()
            .map(|terms| self.arena.sum(terms))
            .collect();
        let (initial_q, initial_qdot) = self.initial_state(&coordinate_names);
        self.check_interactions_at_start(
            &interactions_at_start,
            &parameters,
            (&initial_q, &initial_qdot),
        );

        let explicit_time =
            self.arena.depends_on(kinetic, time_id) || self.arena.depends_on(potential, time_id);
        // Impacts lose energy (unless `e = 1` without friction, which a parameter may change).
        let conservative = file.dampers.is_empty()
            && file.contacts.is_empty()
            && file.forces.is_empty()
            && file.torques.is_empty()
            && generalized_forces.iter().all(|q| self.arena.is_zero(*q))
            && !explicit_time
            && self.kinetic_is_quadratic_in_rates(kinetic)
            && self.constraints_are_workless(&constraints);

        let (draw_lines, points, trace_points) = self.drawing(points, &frames);

        let (checks, outputs) = self.described_checks_and_outputs();

        let initial_speeds = self.initial_speeds();
        if !self.errors.is_empty() {
            return Err(self.errors);
        }
        let model = SymbolicModel {
            arena: self.arena,
            name: file.name.value.clone(),
            description: file.description.clone(),
            parameters,
            coordinate_names,
            coordinates,
            time,
            time_id,
            points,
            frames,
            kinetic,
            potential,
            generalized_forces,
            initial_q,
            initial_qdot,
            conservative,
            dimension,
            draw_lines,
            trace_points,
            bodies: body_infos,
            shapes: (file.draw.shapes.iter())
                .map(|s| (s.body.value.clone(), s.describe()))
                .collect(),
            gravity,
            loads,
            balances,
            balance_sets,
            uses_energy_form: file.kinetic.is_some()
                || file.potential.is_some()
                || !file.generalized_forces.is_empty(),
            kinetic_written: file.kinetic.is_some(),
            written_potential,
            written_forces,
            hand_equations,
            constraints,
            contacts,
            initial_guesses,
            events,
            equilibria,
            checks,
            outputs,
            floquet: file
                .floquet
                .iter()
                .map(FloquetReference::describe)
                .collect(),
            speeds: None,
        };
        Ok((model, speed_definitions, initial_speeds))
    }

    /// The initial speeds `initial:` gives (0 for one it does not give), or `None` if it
    /// gives none (the speeds then start from the initial rates).
    fn initial_speeds(&mut self) -> Option<Vec<ExprId>> {
        let file = self.file;
        let given: Vec<(usize, &crate::model::ast::Expr)> = (file.initial.iter())
            .filter_map(|(k, v)| {
                let r = file.speeds.iter().position(|s| s.name.value == k.value)?;
                Some((r, v))
            })
            .collect();
        if given.is_empty() {
            return None;
        }
        let mut u0 = vec![self.arena.int(0); file.speeds.len()];
        for (r, v) in given {
            u0[r] = self.expr(v);
        }
        Some(u0)
    }

    /// The contacts with each change of support's values derived
    /// ([`elements::support::block`]), from the bodies' masses, centres and angles. A change of support needs a mechanism of bodies free of constraints,
    /// else the mistake is reported at the contact.
    fn support_blocks(
        &mut self,
        mut contacts: Vec<ContactInfo>,
        bodies: &[BodyInfo],
        points: &Points,
    ) -> Vec<ContactInfo> {
        let file = self.file;
        for c in contacts.iter_mut() {
            let Some(support) = c.support.as_mut() else {
                continue;
            };
            let Some(written) = file.contacts.iter().find(|w| w.name.value == c.name) else {
                continue;
            };
            let at = written
                .support
                .as_ref()
                .map_or(written.name.location, |s| s.at);
            let what = format!("contact `{}` changes the support", c.name);
            let spatial = bodies.iter().any(|b| b.spatial.is_some());
            let reason = if file.kinetic.is_some() || bodies.is_empty() || spatial {
                Some((
                    "its kinetic energy is written, not its bodies",
                    "write the mechanism's masses as `bodies:` at points, so that the impulse at the landing foot can be derived",
                ))
            } else if !file.constraints.is_empty()
                || !file.point_constraints.is_empty()
                || !file.nonholonomic.is_empty()
                || !file.rolling.is_empty()
            {
                Some((
                    "the model has constraints",
                    "write the walker in minimal coordinates about its stance foot, without `constraints:`",
                ))
            } else {
                None
            };
            if let Some((why, help)) = reason {
                self.errors
                    .push(Diagnostic::new(at, format!("{what}, but {why}")).with_help(help));
                continue;
            }
            let masses: Vec<elements::support::Mass> = (bodies.iter())
                .map(|b| (b.mass, points[b.com].1.clone(), b.rotation))
                .collect();
            match elements::support::block(&mut self.arena, support, &masses) {
                Some(block) => support.block = block,
                None => self.errors.push(
                    Diagnostic::new(at, format!("{what}, but its `relabel` is not an invertible affine map of the coordinates"))
                        .with_help("write each coordinate after the change as a sum of the coordinates before times constants, plus a constant (`theta: theta - phi`, `phi: -phi`, `theta: theta - 2*alpha`), so that no two give the same"),
                ),
            }
        }
        contacts
    }

    /// The frames, with each frame's angular velocity components `omega_<frame>_<axis>` bound
    /// for the expressions that name them.
    fn frames_with_rates(&mut self) -> Frames {
        let mut frames = self.frames();
        for f in &self.file.frames {
            if let Some(index) = frames.index(&f.name.value) {
                let w = frames.angular_velocity(&mut self.arena, index);
                for (axis, c) in elements::AXES.into_iter().zip(w) {
                    self.angular_velocities
                        .insert(frame::angular_velocity_name(&f.name.value, axis), c);
                }
            }
        }
        frames
    }

    /// What `draw:` draws: its lines between points, the points with the wheels' rims added
    /// (and their lines), and the points traced.
    fn drawing(
        &mut self,
        points: Points,
        frames: &Frames,
    ) -> (Vec<[usize; 2]>, Points, Vec<usize>) {
        let file = self.file;
        let mut draw_lines: Vec<[usize; 2]> = file
            .draw
            .lines
            .iter()
            .filter_map(|[a, b]| Some([point(&points, &a.value)?, point(&points, &b.value)?]))
            .collect();
        let mut points = points;
        for w in &file.draw.wheels {
            draw_lines.extend(self.drawn_wheel(w, &mut points, frames));
        }
        let trace_points = file
            .draw
            .trace
            .iter()
            .filter_map(|p| point(&points, &p.value))
            .collect();

        (draw_lines, points, trace_points)
    }

    /// The file's `checks:` as the description keeps them, and its `outputs:`, with the
    /// conserved quantities and outputs that use the vector functions as text the runtime
    /// evaluates from the state.
    fn described_checks_and_outputs(
        &mut self,
    ) -> (
        eomgen_description::checks::Checks,
        Vec<eomgen_description::outputs::OutputSpec>,
    ) {
        let file = self.file;
        // The outputs, and conserved quantities that use the vector functions, as text the
        // runtime evaluates from the state; lowered last, so that they change no identifier
        // of the equations' expressions.
        let mut checks = file.checks.describe();
        for (c, described) in file.checks.conserved.iter().zip(checks.conserved.to_mut()) {
            if crate::model::vectors::uses_vectors(&c.value) {
                described.value = self.state_text(&c.value).into();
            }
        }
        let outputs = file
            .outputs
            .iter()
            .map(|o| eomgen_description::outputs::OutputSpec {
                name: o.name.value.clone().into(),
                value: self.state_text(&o.value).into(),
                conserved: o.conserved,
                tolerance: o.tolerance,
            })
            .collect();

        (checks, outputs)
    }

    /// Declares the parameters' symbols, in file order.
    fn parameters(&mut self) -> Vec<ParameterInfo> {
        let mut parameters = Vec::new();
        for p in &self.file.parameters {
            let symbol = self.arena.declare(&p.name.value, SymbolKind::Parameter);
            // Interned now, in file order, as the expressions' canonical order follows it.
            self.arena.symbol_expr(symbol);
            parameters.push(ParameterInfo {
                name: p.name.value.clone(),
                default: p.value,
                unit: p.unit.as_ref().map(|u| u.value.clone()),
                symbol,
            });
        }
        parameters
    }

    /// The frames of `frames:`, after the ground frame `N`, each with its rotations.
    fn frames(&mut self) -> Frames {
        let mut frames = Frames::ground(GROUND_FRAME);
        for f in &self.file.frames {
            let Some(parent) = frames.index(&f.parent.value) else {
                self.errors.push(Diagnostic::new(
                    f.parent.location,
                    format!("unknown frame `{}`", f.parent.value),
                ));
                continue;
            };
            let rotations = frame::lower(f, self);
            frames.add(&f.name.value, parent, rotations);
        }
        frames
    }
}

/// The points of a model: name and position, in file order.
type Points = Vec<(String, Vec<ExprId>)>;

/// The lowering as an element's context ([`elements::Lower`]).
impl elements::Lower for Lowering<'_> {
    fn arena(&mut self) -> &mut ExprArena {
        &mut self.arena
    }
    fn expr(&mut self, e: &Expr) -> ExprId {
        Lowering::expr(self, e)
    }
    fn expr_with(&mut self, e: &Expr, locals: &[(&str, ExprId)]) -> ExprId {
        self.locals = (locals.iter())
            .map(|(name, value)| (name.to_string(), *value))
            .collect();
        let value = Lowering::expr(self, e);
        self.locals.clear();
        value
    }
    fn point(&self, name: &str) -> Option<Vec<ExprId>> {
        point(&self.points, name).map(|i| self.points[i].1.clone())
    }
    fn point_index(&self, name: &str) -> Option<usize> {
        point(&self.points, name)
    }
    fn point_at(&self, i: usize) -> Vec<ExprId> {
        self.points[i].1.clone()
    }
    fn frame_index(&self, name: &str) -> Option<usize> {
        self.frames.index(name)
    }
    fn express(&mut self, v: [ExprId; 3], from: usize, to: usize) -> [ExprId; 3] {
        self.frames.express(&mut self.arena, v, from, to)
    }
    fn angular_velocity(&mut self, frame: usize) -> [ExprId; 3] {
        self.frames.angular_velocity(&mut self.arena, frame)
    }
    fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }
    fn body_centre(&self, name: &str) -> Option<usize> {
        self.bodies.iter().find(|b| b.name == name).map(|b| b.com)
    }
    fn planar_angle(&self, name: &str) -> Option<ExprId> {
        let body = self.bodies.iter().find(|b| b.name == name)?;
        body.rotation.map(|(_, angle)| angle)
    }
    fn rigid_body_3d(&self, name: &str) -> Option<(usize, usize, [ExprId; 3])> {
        let index = self.body_index(name)?;
        let spatial = self.bodies[index].spatial.as_ref()?;
        Some((index, spatial.frame, spatial.angular_velocity))
    }
    fn coordinate_names(&self) -> Vec<String> {
        (self.file.coordinates.iter())
            .map(|c| c.name.value.clone())
            .collect()
    }
    fn error(&mut self, d: Diagnostic) {
        self.errors.push(d);
    }
}

/// The index of the point called `name`.
fn point(points: &Points, name: &str) -> Option<usize> {
    points.iter().position(|(p, _)| p == name)
}

/// `T`, `V` and the generalized forces `Q`, term by term as the sections add them.
struct Terms {
    /// Terms of the kinetic energy `T`.
    kinetic: Vec<ExprId>,
    /// Terms of the potential energy `V`.
    potential: Vec<ExprId>,
    /// Per coordinate, the terms of its generalized force `Qᵢ`.
    forces: Vec<Vec<ExprId>>,
    /// The constant ½.
    half: ExprId,
}

/// The sets of the file's `balances:` with their ranges in the lowered list: each set's
/// entries are consecutive (a set is one list under its name), and the plain list form is one
/// set named `balances`.
fn balance_sets(file: &ModelFile) -> Vec<BalanceSet> {
    let mut sets: Vec<BalanceSet> = Vec::new();
    for (i, b) in file.balances.iter().enumerate() {
        let name = b.set_name().unwrap_or("balances");
        match sets.last_mut() {
            Some(last) if last.name == name => last.range.end = i + 1,
            _ => sets.push(BalanceSet {
                name: name.to_string(),
                range: i..i + 1,
                expect_disagreement: b.expect_disagreement,
            }),
        }
    }
    sets
}
