//! Lowering a checked [`ModelFile`] into the expression arena: symbols for parameters,
//! coordinates, rates and time; point positions; `T`, `V` and the generalized forces `Q`
//! assembled from bodies, gravity, springs, dampers, forces and torques.

use rustc_hash::FxHashMap;

use super::constraints::{ConstraintEquations, linear_in_rates, redundant_rows};
use super::frames::{Frames, Vector3};
use crate::expr::{Constant, ExprArena, ExprId, Func, SymbolId, SymbolKind};
use crate::model::ast::{BinOp, Expr, ExprKind};
use crate::model::diagnostic::Diagnostic;
use crate::model::file::{BodyKind, FloquetReference, GROUND_FRAME, ModelFile, TorqueValue};
use crate::model::located::{Located, Location};
use crate::model::rules::short;

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

/// A body of the kinematic form, as expressions.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyInfo {
    /// Name.
    pub name: String,
    /// Mass (kg).
    pub mass: ExprId,
    /// Index into [`SymbolicModel::points`] of the centre of mass (or the particle).
    pub com: usize,
    /// `(centroidal inertia, angle)` of a planar rigid body; `None` for a particle.
    pub rotation: Option<(ExprId, ExprId)>,
    /// The orientation and inertia of a 3-D rigid body; `None` for a particle or a planar
    /// body.
    pub spatial: Option<SpatialBody>,
}

/// A 3-D rigid body's frame, angular velocity and inertia, all in the body frame's axes.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialBody {
    /// Index of its frame in [`SymbolicModel::frames`].
    pub frame: usize,
    /// `^N ω^B` (rad/s) in the body frame's components, linear in the rates.
    pub angular_velocity: Vector3,
    /// The inertia tensor about the centre of mass (kg·m²): `[xx, yy, zz, xy, yz, xz]`.
    pub inertia: [ExprId; 6],
}

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
    /// Coordinates whose initial value is a guess to be solved from the constraints.
    pub initial_guesses: Vec<usize>,
    /// The file's `events:` (empty if none).
    pub events: Vec<EventInfo>,
    /// The file's `equilibria:`, in file order.
    pub equilibria: Vec<Equilibrium>,
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

    /// Lowers a checked model file.
    ///
    /// # Errors
    /// A diagnostic for anything the checks should have rejected (unknown name, wrong
    /// dimension); with a model that passed [`crate::model::load`] this does not happen.
    pub fn from_file(file: &ModelFile) -> Result<Self, Vec<Diagnostic>> {
        Lowering::new(file).run()
    }
}

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
        }
    }

    /// Lowers `constraints:` and `nonholonomic:`, differentiates them, and reports a
    /// non-holonomic constraint that is not linear in the rates and constraints that are
    /// redundant (dependent Jacobian rows at every sampled configuration).
    fn constraints(
        &mut self,
        file: &ModelFile,
        parameters: &[ParameterInfo],
        kinematics: Kinematics<'_>,
    ) -> ConstraintEquations {
        let before = self.errors.len();
        let mut holonomic: Vec<(String, ExprId)> = file
            .constraints
            .iter()
            .map(|(k, e)| (k.value.clone(), self.expr(e)))
            .collect();
        for c in &file.point_constraints {
            let (Some(p), Some(frame)) = (
                point(kinematics.points, &c.point.value),
                match &c.frame {
                    Some(f) => kinematics.frames.index(&f.value),
                    None => Some(0),
                },
            ) else {
                self.errors.push(Diagnostic::new(
                    c.name.location,
                    format!(
                        "constraint `{}` names an unknown point or frame",
                        c.name.value
                    ),
                ));
                continue;
            };
            let r = kinematics.points[p].1.clone();
            let (zero, one) = (self.arena.int(0), self.arena.int(1));
            let mut e = vec![zero; r.len()];
            if let Some(slot) = e.get_mut(c.along.value.index()) {
                *slot = one;
            }
            if r.len() == 3 {
                e = kinematics
                    .frames
                    .express(&mut self.arena, [e[0], e[1], e[2]], frame, 0)
                    .to_vec();
            }
            let phi = self.dot(&r, &e);
            holonomic.push((c.name.value.clone(), phi));
        }
        let mut nonholonomic: Vec<(String, ExprId)> = file
            .nonholonomic
            .iter()
            .map(|(k, e)| (k.value.clone(), self.expr(e)))
            .collect();
        for r in &file.rolling {
            nonholonomic.extend(self.rolling_contact(r, kinematics));
        }
        if holonomic.is_empty() && nonholonomic.is_empty() {
            return ConstraintEquations::default();
        }
        let symbols: Vec<[SymbolId; 3]> = self.arena.coordinates().to_vec();
        for ((k, _), (_, g)) in file.nonholonomic.iter().zip(&nonholonomic) {
            if !linear_in_rates(&mut self.arena, *g, &symbols) {
                self.errors.push(
                    Diagnostic::new(k.location, format!("non-holonomic constraint `{}` is not linear in the rates", k.value))
                        .with_help("write it as A(q, t) q̇ + b(q, t) = 0: each `x_dot` to the first power, times a function of q and t"),
                );
            }
        }
        let eqs = ConstraintEquations::derive(&mut self.arena, &symbols, &holonomic, &nonholonomic);
        let (m, n) = (eqs.len(), symbols.len());
        // (More constraints than coordinates is the loader's error; after an error in the
        // constraints themselves the rank test would only repeat it. An error elsewhere does
        // not stop it: every diagnostic at once.)
        if self.errors.len() > before {
            return eqs;
        }
        // Rank of J at a few random configurations (parameters at their defaults).
        let mut evaluator = crate::expr::eval::Evaluator::new(&self.arena, &eqs.jacobian);
        let mut rng = <rand::rngs::Xoshiro256PlusPlus as rand::SeedableRng>::seed_from_u64(
            0x9E37_79B9_7F4A_7C15,
        );
        let mut uniform = move || rand::RngExt::random_range(&mut rng, -2.0..2.0);
        let mut samples = Vec::new();
        for _ in 0..60 {
            if samples.len() == 6 {
                break;
            }
            let mut bindings = vec![0.0; self.arena.symbols().len()];
            for (i, s) in self.arena.symbols().iter().enumerate() {
                if s.kind != SymbolKind::Parameter {
                    bindings[i] = uniform();
                }
            }
            // Parameters at their defaults, by symbol (not a search by name per symbol).
            for p in parameters {
                bindings[p.symbol.index()] = p.default;
            }
            let values = evaluator.eval(&bindings).to_vec();
            if values.iter().all(|v| v.is_finite()) {
                samples.push(values);
            }
        }
        let all: Vec<Located<String>> = file.constraint_names();
        let dependent = redundant_rows(&samples, m, n);
        let independent: Vec<usize> = (0..eqs.holonomic)
            .filter(|i| dependent.iter().all(|(d, _)| d != i))
            .collect();
        for (i, with) in dependent {
            let k = &all[i];
            let others: Vec<String> = with
                .iter()
                .map(|j| format!("`{}`", all[*j].value))
                .collect();
            // A holonomic constraint that repeats holonomic ones: redundant if it holds where
            // they hold, contradictory if not.
            // (The constraints it combines come before it, so they are holonomic too.)
            if i < eqs.holonomic
                && let Some(found) =
                    self.residual_where_others_hold(&eqs, parameters, &independent, i)
                && found.contradicts()
            {
                let residual = found.residual;
                let message = if others.is_empty() {
                    format!(
                        "constraint `{}` can never hold: it does not depend on the coordinates, and it is {} (not 0)",
                        k.value,
                        short(residual)
                    )
                } else {
                    let hold = if others.len() == 1 { "holds" } else { "hold" };
                    format!(
                        "constraint `{}` contradicts {}: where {} {hold}, it is {} (not 0), so no configuration satisfies them all",
                        k.value,
                        others.join(", "),
                        others.join(" and "),
                        short(residual)
                    )
                };
                self.errors.push(Diagnostic::new(k.location, message).with_help(
                    "inconsistent constraints leave no motion to compute (with the parameters at their defaults); correct the value or remove the constraint",
                ));
                continue;
            }
            let message = if others.is_empty() {
                format!(
                    "constraint `{}` constrains nothing: its Jacobian row is zero",
                    k.value
                )
            } else {
                format!(
                    "constraint `{}` is redundant with {}: its Jacobian row is a combination of theirs at every configuration tried",
                    k.value,
                    others.join(", ")
                )
            };
            self.errors.push(
                Diagnostic::new(k.location, message)
                    .with_help("redundant constraints make the constraint forces indeterminate (the planar-loop trap); remove it"),
            );
        }
        eqs
    }

    /// The residual of the dependent holonomic constraint `dependent` where the
    /// `independent` holonomic constraints hold (see
    /// [`super::constraints::residual_where_others_hold`]), from up to six random
    /// configurations at a random `t` (parameters at their defaults); `None` if Newton
    /// converges from none of them.
    fn residual_where_others_hold(
        &mut self,
        eqs: &ConstraintEquations,
        parameters: &[ParameterInfo],
        independent: &[usize],
        dependent: usize,
    ) -> Option<super::constraints::DependentResidual> {
        let n = self.arena.coordinates().len();
        let h = eqs.holonomic;
        let roots: Vec<ExprId> = eqs
            .phi
            .iter()
            .chain(&eqs.jacobian[..h * n])
            .copied()
            .collect();
        let mut evaluator = crate::expr::eval::Evaluator::new(&self.arena, &roots);
        let mut rng = <rand::rngs::Xoshiro256PlusPlus as rand::SeedableRng>::seed_from_u64(
            0xC0FF_EE15_5EED_1234,
        );
        let mut uniform = move || rand::RngExt::random_range(&mut rng, -2.0..2.0);
        let symbols = self.arena.symbols().to_vec();
        // Random values for t (and the rates, unused), the parameters' defaults.
        let mut bindings: Vec<f64> = symbols.iter().map(|_| uniform()).collect();
        for p in parameters {
            bindings[p.symbol.index()] = p.default;
        }
        let slots: Vec<usize> = (0..n)
            .map(|c| {
                symbols
                    .iter()
                    .position(|s| s.kind == SymbolKind::Coordinate(c as u32))
                    .unwrap_or(usize::MAX)
            })
            .collect();
        for _ in 0..6 {
            let q0: Vec<f64> = (0..n).map(|_| uniform()).collect();
            let mut eval = |q: &[f64]| {
                for (slot, v) in slots.iter().zip(q) {
                    if let Some(b) = bindings.get_mut(*slot) {
                        *b = *v;
                    }
                }
                let values = evaluator.eval(&bindings);
                (values[..h].to_vec(), values[h..].to_vec())
            };
            if let Some(r) = super::constraints::residual_where_others_hold(
                &mut eval,
                &q0,
                independent,
                dependent,
            ) {
                return Some(r);
            }
        }
        None
    }

    /// Whether `T` is a quadratic form in the rates (`T₀ = T(q, 0, t)` and
    /// `T₁ = ∂T/∂q̇ (q, 0, t)` vanish): otherwise, as for a point carried by a prescribed
    /// motion (`r cos ωt`), `T + V` is not conserved even without explicit `t` in `T` (the
    /// Jacobi integral `T₂ − T₀ + V` is).
    fn kinetic_is_quadratic_in_rates(&mut self, kinetic: ExprId) -> bool {
        let symbols: Vec<[SymbolId; 3]> = self.arena.coordinates().to_vec();
        let zero = self.arena.int(0);
        let at_rest: FxHashMap<SymbolId, ExprId> = symbols.iter().map(|s| (s[1], zero)).collect();
        let mut parts = vec![kinetic];
        parts.extend(symbols.iter().map(|s| self.arena.diff(kinetic, s[1])));
        parts.into_iter().all(|p| {
            let p = self.arena.substitute(p, &at_rest);
            if self.arena.is_zero(p) {
                return true;
            }
            let p = self.arena.expand(p);
            self.arena.is_zero(p)
        })
    }

    /// Whether the constraint forces do no work on the motion: no holonomic `Φ` depends on
    /// `t` (the power of the constraint forces is `λᵀ Φ_t`) and every non-holonomic
    /// constraint has `b = 0` (power `−λᵀ b`). A rod spun at a prescribed rate drives its
    /// bead, and `T + V` is then not conserved.
    fn constraints_are_workless(&mut self, c: &ConstraintEquations) -> bool {
        let time = self.arena.time_id();
        let symbols: Vec<[SymbolId; 3]> = self.arena.coordinates().to_vec();
        let zero = self.arena.int(0);
        let at_rest: FxHashMap<SymbolId, ExprId> = symbols.iter().map(|s| (s[1], zero)).collect();
        c.phi.iter().all(|&phi| !self.arena.depends_on(phi, time))
            && c.velocity[c.holonomic..].iter().all(|&g| {
                let b = self.arena.substitute(g, &at_rest);
                let b = self.arena.expand(b);
                self.arena.is_zero(b)
            })
    }

    /// The expression `e` of the model file in the arena. Constants must come out exact or
    /// not at all: an operation on constants that is undefined (division by zero, `0^0`, the
    /// logarithm of a non-positive number, a root of a negative one), that overflows `f64`
    /// or that underflows from non-zero numbers (`1e-300*1e-300`, `exp(-1000)`) is a located
    /// error at its operator (see [`Self::check_constants`] and [`crate::expr::fold`]), never
    /// a silent 0, NaN or ∞ in the equations.
    fn expr(&mut self, e: &Expr) -> ExprId {
        // The record may be left from an expression built outside a model file's.
        self.arena.take_fold_error();
        self.lower(e)
    }

    /// [`Self::expr`] of a sub-expression.
    fn lower(&mut self, e: &Expr) -> ExprId {
        match &e.kind {
            ExprKind::Number { value, text } => {
                let c = Constant::parse_decimal(text)
                    .or_else(|| Constant::float(*value))
                    .unwrap_or(Constant::ZERO);
                self.arena.constant(c)
            }
            ExprKind::Ident(name) => match name.as_str() {
                // `t` is the first symbol declared (in `run`), so it is found like the others.
                "pi" => self.arena.pi(),
                _ if self.locals.iter().any(|(n, _)| n == name) => self
                    .locals
                    .iter()
                    .rev()
                    .find(|(n, _)| n == name)
                    .map_or_else(|| self.arena.int(0), |(_, e)| *e),
                _ if self.arena.symbol_id(name).is_none()
                    && self.angular_velocities.contains_key(name) =>
                {
                    self.angular_velocities[name]
                }
                _ => match self.arena.symbol_id(name) {
                    Some(s)
                        if self.allow_accelerations
                            || !matches!(
                                self.arena.symbol_info(s).kind,
                                SymbolKind::Acceleration(_)
                            ) =>
                    {
                        self.arena.symbol_expr(s)
                    }
                    _ => {
                        self.errors.push(Diagnostic::new(
                            e.location,
                            format!("unknown name `{name}` in an expression"),
                        ));
                        self.arena.int(0)
                    }
                },
            },
            ExprKind::Neg(a) => {
                let a = self.lower(a);
                self.arena.neg(a)
            }
            ExprKind::Binary {
                op,
                lhs,
                rhs,
                op_location,
            } => {
                let before = self.errors.len();
                let (a, b) = (self.lower(lhs), self.lower(rhs));
                // Folds of the operands were reported there, and what follows from a mistake
                // in an operand (`10^400/10^399` is then `10^400 · 10^-399`) is not another.
                self.arena.take_fold_error();
                let reported = self.errors.len() > before;
                let undefined = reported || self.check_constants(*op_location, *op, a, b);
                let result = match op {
                    BinOp::Add => self.arena.plus(a, b),
                    BinOp::Sub => self.arena.minus(a, b),
                    BinOp::Mul => self.arena.times(a, b),
                    BinOp::Div => self.arena.divide(a, b),
                    BinOp::Pow => self.arena.pow(a, b),
                };
                // The arena did not form a number it could not hold; that is an error of the
                // file only if the numbers written in this operation alone fail.
                if self.arena.take_fold_error().is_some()
                    && !undefined
                    && let Some(error) = crate::model::parser::written_fold_error(*op, lhs, rhs)
                {
                    self.errors.push(crate::model::parser::fold_diagnostic(
                        *op_location,
                        *op,
                        error,
                    ));
                }
                result
            }
            ExprKind::Call { func, args } if crate::model::vectors::is_vector_function(func) => {
                self.vector_call(e, func, args)
            }
            ExprKind::Call { func, args } => {
                let args: Vec<ExprId> = args.iter().map(|a| self.lower(a)).collect();
                if let [a] = args.as_slice()
                    && let Some(x) = self.arena.as_constant(*a).map(Constant::to_f64)
                    && let Some(Err(error)) = crate::model::parser::fold_call(func, x)
                {
                    self.errors.push(crate::model::parser::call_fold_diagnostic(
                        e.location, func, x, error,
                    ));
                }
                match (func.as_str(), args.as_slice()) {
                    ("sqrt", [a]) => self.arena.sqrt(*a),
                    ("atan2", [y, x]) => self.arena.atan2(*y, *x),
                    (name, [a]) => match Func::from_name(name) {
                        Some(f) => self.arena.func(f, *a),
                        None => self.unknown_function(e, name),
                    },
                    (name, _) => self.unknown_function(e, name),
                }
            }
        }
    }

    /// Reports `a op b` (its operator at `at`) when its value is undefined for the numbers it
    /// is given: `a / 0`, `0 ^ b` with `b ≤ 0`, a negative number to a non-integer power;
    /// whether it did. (Overflow and underflow are the arena's fold errors.)
    fn check_constants(&mut self, at: Location, op: BinOp, a: ExprId, b: ExprId) -> bool {
        let (x, y) = (
            self.arena.as_constant(a).map(Constant::to_f64),
            self.arena.as_constant(b).map(Constant::to_f64),
        );
        match (op, x, y) {
            (BinOp::Div, _, Some(0.0)) => {
                self.undefined(at, "division by zero", "the divisor is 0 here");
            }
            (BinOp::Pow, Some(x), Some(y)) if x == 0.0 && y <= 0.0 => {
                self.undefined(
                    at,
                    &format!("`0^{y}` is undefined"),
                    "zero has no power of a non-positive exponent",
                );
            }
            (BinOp::Pow, Some(x), Some(y)) if x < 0.0 && y.fract() != 0.0 => {
                self.undefined(
                    at,
                    &format!("`({x})^{y}` is not a real number"),
                    "a negative number has only integer powers",
                );
            }
            _ => return false,
        }
        true
    }

    /// A located error: an operation on numbers whose result is undefined.
    fn undefined(&mut self, at: Location, what: &str, help: &str) {
        self.errors
            .push(Diagnostic::new(at, what.to_string()).with_help(help.to_string()));
    }

    fn unknown_function(&mut self, e: &Expr, name: &str) -> ExprId {
        self.errors.push(Diagnostic::new(
            e.location,
            format!("unknown function or wrong number of arguments in `{name}(…)`"),
        ));
        self.arena.int(0)
    }

    /// A call of a vector function that gives a number: `dot(a, b)`, `cross(a, b)` in the
    /// plane (`a_x b_y − a_y b_x`), `norm(a)`, `distance(A, B)`.
    fn vector_call(&mut self, e: &Expr, func: &str, args: &[Expr]) -> ExprId {
        let vectors: Vec<Vec<ExprId>> = args.iter().map(|a| self.vector(a)).collect();
        match (func, vectors.as_slice()) {
            ("dot", [a, b]) => self.dot(a, b),
            ("cross", [a, b]) if a.len() == 2 && b.len() == 2 => {
                let ab = self.arena.times(a[0], b[1]);
                let ba = self.arena.times(a[1], b[0]);
                self.arena.minus(ab, ba)
            }
            ("norm", [a]) => {
                let a2 = self.dot(a, a);
                self.arena.sqrt(a2)
            }
            ("distance", [a, b]) => {
                let d = self.difference(a, b);
                let d2 = self.dot(&d, &d);
                self.arena.sqrt(d2)
            }
            _ => {
                self.errors.push(Diagnostic::new(
                    e.location,
                    format!("`{func}(…)` is a vector here, where a number is expected"),
                ));
                self.arena.int(0)
            }
        }
    }

    /// A vector expression of the points' positions (ground-frame components), as the
    /// rules of [`crate::model::vectors`] shape it.
    fn vector(&mut self, e: &Expr) -> Vec<ExprId> {
        let names: Vec<&str> = self.points.iter().map(|(n, _)| n.as_str()).collect();
        let dimension = self.points.first().map_or(2, |(_, r)| r.len());
        let is_vector = |e: &Expr| {
            crate::model::vectors::shape_of(e, &names, dimension)
                == Some(crate::model::vectors::Shape::Vector)
        };
        let (lhs_vector, rhs_vector) = match &e.kind {
            ExprKind::Binary { lhs, rhs, .. } => (is_vector(lhs), is_vector(rhs)),
            _ => (false, false),
        };
        match &e.kind {
            ExprKind::Ident(n) if point(&self.points, n).is_some() => self.points
                [point(&self.points, n).unwrap_or_default()]
            .1
            .clone(),
            ExprKind::Neg(a) => {
                let a = self.vector(a);
                a.iter().map(|c| self.arena.neg(*c)).collect()
            }
            ExprKind::Binary {
                op: op @ (BinOp::Add | BinOp::Sub),
                lhs,
                rhs,
                ..
            } => {
                let (a, b) = (self.vector(lhs), self.vector(rhs));
                a.iter()
                    .zip(&b)
                    .map(|(x, y)| match op {
                        BinOp::Add => self.arena.plus(*x, *y),
                        _ => self.arena.minus(*x, *y),
                    })
                    .collect()
            }
            ExprKind::Binary {
                op: op @ (BinOp::Mul | BinOp::Div),
                lhs,
                rhs,
                ..
            } if lhs_vector || rhs_vector => {
                let (v, s) = if lhs_vector {
                    (self.vector(lhs), self.lower(rhs))
                } else {
                    (self.vector(rhs), self.lower(lhs))
                };
                v.iter()
                    .map(|c| match op {
                        BinOp::Mul => self.arena.times(*c, s),
                        _ => self.arena.divide(*c, s),
                    })
                    .collect()
            }
            ExprKind::Call { func, args } if func == "vel" && args.len() == 1 => {
                let v = self.vector(&args[0]);
                v.iter().map(|c| self.arena.time_derivative(*c)).collect()
            }
            ExprKind::Call { func, args } if func == "cross" && args.len() == 2 => {
                let (a, b) = (self.vector(&args[0]), self.vector(&args[1]));
                if let ([a0, a1, a2], [b0, b1, b2]) = (&a[..], &b[..]) {
                    let mut component = |p: ExprId, q: ExprId, u: ExprId, v: ExprId| {
                        let pq = self.arena.times(p, q);
                        let uv = self.arena.times(u, v);
                        self.arena.minus(pq, uv)
                    };
                    vec![
                        component(*a1, *b2, *a2, *b1),
                        component(*a2, *b0, *a0, *b2),
                        component(*a0, *b1, *a1, *b0),
                    ]
                } else {
                    self.errors.push(Diagnostic::new(
                        e.location,
                        "`cross(a, b)` is a number in the plane, where a vector is expected",
                    ));
                    vec![self.arena.int(0); dimension]
                }
            }
            _ => {
                self.errors.push(Diagnostic::new(
                    e.location,
                    format!("`{e}` is a number, where a vector of points is expected"),
                ));
                vec![self.arena.int(0); dimension]
            }
        }
    }

    /// The expression as the model's description keeps it: as written, or, when it uses
    /// the vector functions or a frame's angular velocity (`omega_B_x`), lowered (the points'
    /// positions and velocities written out in the coordinates and rates) and printed back in
    /// the file's syntax, so that it is evaluated from the state alone.
    fn state_text(&mut self, e: &Expr) -> String {
        // A frame's angular velocity (`omega_B_x`) is no name of the state either.
        let mut ids = Vec::new();
        crate::model::parser::identifiers(e, &mut ids);
        let reads_angular_velocity = ids.iter().any(|(n, _)| {
            self.arena.symbol_id(n).is_none() && self.angular_velocities.contains_key(n)
        });
        if !crate::model::vectors::uses_vectors(e) && !reads_angular_velocity {
            return e.to_string();
        }
        let lowered = self.expr(e);
        crate::expr::print::Printer::new(&self.arena, crate::expr::print::Syntax::Text)
            .print(lowered)
    }

    /// `interactions:` — equal and opposite forces `f e` on `B` and `−f e` on `A` along
    /// `e = d/r`, `d = r_B − r_A`, `r = |d|`, `ṙ = d·ḋ/r`. A magnitude that is a sum of
    /// powers of `r` times factors constant in the motion (parameters, `t`) is integrated to
    /// a potential, `V(r) = −∫ f dr` (`−c ln r` for `c/r`), so that `T + V` stays the
    /// energy; any other enters `Q` as `Qᵢ = f d·∂d/∂qᵢ / r` (its virtual work `f e·δd`).
    /// Either way momentum balance gets the two forces at the points.
    ///
    /// Returns the loads and, per interaction, `(r, f)` at the points' positions, for the
    /// check of the initial state.
    fn interactions(
        &mut self,
        points: &Points,
        q_symbols: &[SymbolId],
        terms: &mut Terms,
    ) -> (Vec<LoadInfo>, Vec<(ExprId, ExprId)>) {
        let mut loads = Vec::new();
        let mut at_start = Vec::new();
        if self.file.interactions.is_empty() {
            return (loads, at_start);
        }
        // Names no model symbol can have (a space is not in a name), substituted away below.
        let r_symbol = self.arena.declare("interaction r", SymbolKind::Auxiliary);
        let rdot_symbol = self
            .arena
            .declare("interaction r_dot", SymbolKind::Auxiliary);
        for it in &self.file.interactions {
            let (Some(a), Some(b)) = (
                point(points, &it.between[0].value),
                point(points, &it.between[1].value),
            ) else {
                self.errors.push(Diagnostic::new(
                    it.name.location,
                    format!("interaction `{}` names an unknown point", it.name.value),
                ));
                continue;
            };
            let d = self.difference(&points[b].1, &points[a].1);
            let dd: Vec<ExprId> = d.iter().map(|c| self.arena.time_derivative(*c)).collect();
            let d2 = self.dot(&d, &d);
            let r = self.arena.sqrt(d2);
            let d_dd = self.dot(&d, &dd);
            let rdot = self.arena.divide(d_dd, r);
            let (r_local, rdot_local) = (
                self.arena.symbol_expr(r_symbol),
                self.arena.symbol_expr(rdot_symbol),
            );
            self.locals = vec![
                ("r".to_string(), r_local),
                ("r_dot".to_string(), rdot_local),
            ];
            let f_of_r = self.expr(&it.magnitude);
            self.locals.clear();
            let mut values = FxHashMap::default();
            values.insert(r_symbol, r);
            values.insert(rdot_symbol, rdot);
            let f = self.arena.substitute(f_of_r, &values);
            // f e on B, −f e on A.
            let scale = self.arena.divide(f, r);
            let on_b: Vec<ExprId> = d.iter().map(|c| self.arena.times(scale, *c)).collect();
            let on_a: Vec<ExprId> = on_b.iter().map(|c| self.arena.neg(*c)).collect();
            loads.push(LoadInfo::Force {
                point: b,
                vector: on_b,
            });
            loads.push(LoadInfo::Force {
                point: a,
                vector: on_a,
            });
            at_start.push((r, f));
            match self.power_law_potential(f_of_r, r_symbol, rdot_symbol) {
                Some(v_of_r) => {
                    let v = self.arena.substitute(v_of_r, &values);
                    terms.potential.push(v);
                }
                None => {
                    for (i, qs) in q_symbols.iter().enumerate() {
                        let partial: Vec<ExprId> =
                            d.iter().map(|x| self.arena.diff(*x, *qs)).collect();
                        let proj = self.dot(&d, &partial);
                        if !self.arena.is_zero(proj) {
                            terms.forces[i].push(self.arena.times(scale, proj));
                        }
                    }
                }
            }
        }
        (loads, at_start)
    }

    /// `V(r) = −∫ f dr` of a magnitude `f` that is a sum of terms `c rᵏ`, `k` a number and
    /// `c` free of `r`, `ṙ`, the coordinates and the rates: `−c r^(k+1)/(k+1)`, or `−c ln r`
    /// for `k = −1`. `None` for any other magnitude (it is not, or not visibly, the
    /// derivative of a potential of `r`).
    fn power_law_potential(
        &mut self,
        f: ExprId,
        r_symbol: SymbolId,
        rdot_symbol: SymbolId,
    ) -> Option<ExprId> {
        use crate::expr::Node;
        if self.arena.depends_on(f, rdot_symbol) {
            return None;
        }
        let motion: Vec<SymbolId> = self
            .arena
            .coordinates()
            .iter()
            .flat_map(|c| [c[0], c[1]])
            .collect();
        let f = self.arena.expand(f);
        let terms: Vec<ExprId> = match self.arena.node(f) {
            Node::Add(ts) => ts.to_vec(),
            _ => vec![f],
        };
        let mut potential = Vec::new();
        for term in terms {
            let factors: Vec<ExprId> = match self.arena.node(term) {
                Node::Mul(fs) => fs.to_vec(),
                _ => vec![term],
            };
            let mut power = vec![self.arena.int(0)];
            let mut coefficient = Vec::new();
            for factor in factors {
                if !self.arena.depends_on(factor, r_symbol) {
                    if motion.iter().any(|s| self.arena.depends_on(factor, *s)) {
                        return None;
                    }
                    coefficient.push(factor);
                    continue;
                }
                match self.arena.node(factor).clone() {
                    Node::Symbol(s) if s == r_symbol => power.push(self.arena.int(1)),
                    Node::Pow([base, exponent])
                        if matches!(self.arena.node(base), Node::Symbol(s) if *s == r_symbol)
                            && self.arena.as_constant(exponent).is_some() =>
                    {
                        power.push(exponent);
                    }
                    _ => return None,
                }
            }
            let c = self.arena.product(&coefficient);
            let k = self.arena.sum(&power);
            let one = self.arena.int(1);
            let k1 = self.arena.plus(k, one);
            let r = self.arena.symbol_expr(r_symbol);
            let integral = if self.arena.is_zero(k1) {
                let ln = self.arena.func(Func::Ln, r);
                self.arena.times(c, ln)
            } else {
                let rk1 = self.arena.pow(r, k1);
                let crk1 = self.arena.times(c, rk1);
                self.arena.divide(crk1, k1)
            };
            potential.push(self.arena.neg(integral));
        }
        Some(self.arena.sum(&potential))
    }

    /// Reports an interaction whose points coincide at the initial state (`r = 0`: no
    /// direction), or whose magnitude is not a finite number there; the parameters at
    /// their defaults.
    fn check_interactions_at_start(
        &mut self,
        at_start: &[(ExprId, ExprId)],
        parameters: &[ParameterInfo],
        initial: (&[ExprId], &[ExprId]),
    ) {
        if at_start.is_empty() {
            return;
        }
        let mut bindings = vec![0.0; self.arena.symbols().len()];
        for p in parameters {
            bindings[p.symbol.index()] = p.default;
        }
        let starts: Vec<ExprId> = initial.0.iter().chain(initial.1).copied().collect();
        let start = crate::expr::eval::Evaluator::new(&self.arena, &starts).eval(&bindings);
        let n = initial.0.len();
        for (i, s) in self.arena.symbols().iter().enumerate() {
            match s.kind {
                SymbolKind::Coordinate(k) => bindings[i] = start[k as usize],
                SymbolKind::Velocity(k) => bindings[i] = start[n + k as usize],
                _ => {}
            }
        }
        let roots: Vec<ExprId> = at_start.iter().flat_map(|(r, f)| [*r, *f]).collect();
        let values = crate::expr::eval::Evaluator::new(&self.arena, &roots).eval(&bindings);
        for (it, v) in self.file.interactions.iter().zip(values.chunks(2)) {
            let (r, f) = (v[0], v[1]);
            let [a, b] = &it.between;
            if r == 0.0 {
                self.errors.push(
                    Diagnostic::new(
                        b.location,
                        format!(
                            "the points `{}` and `{}` of interaction `{}` coincide at the initial state (r = 0): the line of its force is undefined there",
                            a.value, b.value, it.name.value
                        ),
                    )
                    .with_help("start the points apart (`initial:`), or check their positions under `points:`"),
                );
            } else if !f.is_finite() && r.is_finite() {
                self.errors.push(
                    Diagnostic::new(
                        it.magnitude.location,
                        format!(
                            "the magnitude of interaction `{}` is {f} at the initial state (r = {})",
                            it.name.value,
                            short(r)
                        ),
                    )
                    .with_help("a magnitude must be a finite number where the motion starts; check the formula and the initial state"),
                );
            }
        }
    }

    fn dot(&mut self, a: &[ExprId], b: &[ExprId]) -> ExprId {
        let terms: Vec<ExprId> = a
            .iter()
            .zip(b)
            .map(|(x, y)| self.arena.times(*x, *y))
            .collect();
        self.arena.sum(&terms)
    }

    fn difference(&mut self, a: &[ExprId], b: &[ExprId]) -> Vec<ExprId> {
        a.iter()
            .zip(b)
            .map(|(x, y)| self.arena.minus(*x, *y))
            .collect()
    }

    /// Lowers the whole file, section by section, into a [`SymbolicModel`]; every error of
    /// every section is reported.
    ///
    /// The sections are lowered in a fixed order, which this function spells out: the arena
    /// interns each new expression at its first use, so the order fixes every [`ExprId`],
    /// hence the canonical order of sums and products and the generated code.
    fn run(mut self) -> Result<SymbolicModel, Vec<Diagnostic>> {
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
        let q_symbols: Vec<SymbolId> = self.arena.coordinates().iter().map(|c| c[0]).collect();
        let mut frames = self.frames();
        for f in &file.frames {
            if let Some(index) = frames.index(&f.name.value) {
                let w = frames.angular_velocity(&mut self.arena, index);
                for (axis, c) in ['x', 'y', 'z'].into_iter().zip(w) {
                    self.angular_velocities
                        .insert(format!("omega_{}_{axis}", f.name.value), c);
                }
            }
        }
        let points = self.points(&frames);
        self.points = points.clone();
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
        let gravity: Option<Vec<ExprId>> = file
            .gravity
            .as_ref()
            .map(|g| g.value.iter().map(|c| self.expr(c)).collect());
        let (body_infos, angles) =
            self.bodies(&points, &mut frames, gravity.as_deref(), &mut terms);
        let mut loads = self.springs(&points, &mut terms);
        loads.extend(self.dampers(&points, &q_symbols, &mut terms));
        loads.extend(self.forces(&points, &frames, &q_symbols, &mut terms));
        loads.extend(self.torques(&angles, &body_infos, &frames, &q_symbols, &mut terms));
        let (interaction_loads, interactions_at_start) =
            self.interactions(&points, &q_symbols, &mut terms);
        loads.extend(interaction_loads);
        let balances = self.balances(&points, &body_infos, &frames);
        let balance_sets = balance_sets(self.file);
        let hand_equations = self.hand_equations();

        let kinematics = Kinematics {
            points: &points,
            bodies: &body_infos,
            frames: &frames,
        };
        let constraints = self.constraints(file, &parameters, kinematics);
        if !file.events.is_empty() {
            for (i, name) in constraints.names.iter().enumerate() {
                self.arena
                    .symbol(&format!("lambda_{name}"), SymbolKind::Multiplier(i as u32));
            }
        }
        let events = self.events();
        let equilibria = self.equilibria(&coordinate_names);
        let initial_guesses: Vec<usize> = file
            .initial_guesses
            .iter()
            .filter_map(|g| coordinate_names.iter().position(|c| *c == g.value))
            .collect();

        let kinetic = self.arena.sum(&terms.kinetic);
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
        let conservative = file.dampers.is_empty()
            && file.forces.is_empty()
            && file.torques.is_empty()
            && generalized_forces.iter().all(|q| self.arena.is_zero(*q))
            && !explicit_time
            && self.kinetic_is_quadratic_in_rates(kinetic)
            && self.constraints_are_workless(&constraints);

        let mut draw_lines: Vec<[usize; 2]> = file
            .draw
            .lines
            .iter()
            .filter_map(|[a, b]| Some([point(&points, &a.value)?, point(&points, &b.value)?]))
            .collect();
        let mut points = points;
        for w in &file.draw.wheels {
            draw_lines.extend(self.drawn_wheel(w, &mut points, &frames));
        }
        let trace_points = file
            .draw
            .trace
            .iter()
            .filter_map(|p| point(&points, &p.value))
            .collect();

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

        if !self.errors.is_empty() {
            return Err(self.errors);
        }
        Ok(SymbolicModel {
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
        })
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
            let rotations = f
                .rotations
                .iter()
                .map(|r| (r.axis.value.index(), self.expr(&r.angle)))
                .collect();
            frames.add(&f.name.value, parent, rotations);
        }
        frames
    }

    /// The points' positions in the ground frame, by name, in file order: a list of
    /// components as written, or a point plus vectors in frames carried into the ground
    /// frame's components.
    fn points(&mut self, frames: &Frames) -> Points {
        let mut points: Points = Vec::new();
        for p in &self.file.points {
            if let Some(wheel) = &p.wheel {
                let r = self.wheel_contact(wheel, &points, frames);
                points.push((p.name.value.clone(), r));
                continue;
            }
            let Some(relative) = &p.relative else {
                let r = p.position.iter().map(|c| self.expr(c)).collect();
                points.push((p.name.value.clone(), r));
                continue;
            };
            let zero = self.arena.int(0);
            let mut r: Vec<ExprId> = match &relative.from {
                Some(from) => match point(&points, &from.value) {
                    Some(i) => points[i].1.clone(),
                    None => {
                        self.errors.push(Diagnostic::new(
                            from.location,
                            format!("unknown point `{}`", from.value),
                        ));
                        vec![zero; 3]
                    }
                },
                None => vec![zero; 3],
            };
            for (frame, v) in &relative.vectors {
                let Some(f) = frames.index(&frame.value) else {
                    self.errors.push(Diagnostic::new(
                        frame.location,
                        format!("unknown frame `{}`", frame.value),
                    ));
                    continue;
                };
                let v = [&v[0], &v[1], &v[2]].map(|c| self.expr(c));
                let v = frames.express(&mut self.arena, v, f, 0);
                for (x, c) in r.iter_mut().zip(v) {
                    *x = self.arena.plus(*x, c);
                }
            }
            points.push((p.name.value.clone(), r));
        }
        points
    }

    /// A wheel's contact point: its centre less the radius along the unit vector of the
    /// wheel's plane (normal to the axle `a`) nearest the ground frame's `z`:
    /// `r_C = r_centre − r (n − (n·a) a)/|n − (n·a) a|`, `n = N.z`, computed in the wheel
    /// frame's components (where `a` is a unit axis and the projection drops one component)
    /// and carried into the ground frame's.
    fn wheel_contact(
        &mut self,
        wheel: &crate::model::file::WheelContact,
        points: &Points,
        frames: &Frames,
    ) -> Vec<ExprId> {
        let (Some(centre), Some(frame)) = (
            point(points, &wheel.centre.value),
            frames.index(&wheel.frame.value),
        ) else {
            self.errors.push(Diagnostic::new(
                wheel.centre.location,
                "a wheel contact names an unknown point or frame",
            ));
            return vec![self.arena.int(0); 3];
        };
        let (zero, one) = (self.arena.int(0), self.arena.int(1));
        let mut n = frames.express(&mut self.arena, [zero, zero, one], 0, frame);
        n[wheel.axle.value.index()] = zero;
        let n2 = self.dot(&n, &n);
        // The wheel's plane has no direction nearest the ground's z when its axle is that z
        // in every configuration (a disc lying flat): `r/|n|` times components that are all 0
        // would put the contact point at the centre, silently.
        if self.arena.is_zero(n2) {
            self.errors.push(
                Diagnostic::new(
                    wheel.axle.location,
                    format!(
                        "the wheel centred at `{}` has its axle `{}` of frame `{}` along the ground's z in every configuration: a wheel lying flat has no lowest point of its rim",
                        wheel.centre.value,
                        wheel.axle.value.letter(),
                        wheel.frame.value
                    ),
                )
                .with_help("a wheel contact needs an axle that is not vertical (the axle `y` of a frame that leans and steers); for a disc sliding flat, write its contact point directly"),
            );
            return vec![zero; 3];
        }
        let length = self.arena.sqrt(n2);
        let radius = self.expr(&wheel.radius);
        let scale = self.arena.divide(radius, length);
        let down = n.map(|c| {
            let t = self.arena.times(scale, c);
            self.arena.neg(t)
        });
        let down = frames.express(&mut self.arena, down, frame, 0);
        points[centre]
            .1
            .iter()
            .zip(down)
            .map(|(c, d)| self.arena.plus(*c, d))
            .collect()
    }

    /// Points on the rim of a drawn wheel (every 15°, named `<centre>.rim<k>`, added after the
    /// file's points) and the segments that draw it: the rim and four spokes, which turn
    /// with the wheel's frame.
    fn drawn_wheel(
        &mut self,
        wheel: &crate::model::file::WheelContact,
        points: &mut Points,
        frames: &Frames,
    ) -> Vec<[usize; 2]> {
        const RIM: usize = 24;
        let (Some(centre), Some(frame)) = (
            point(points, &wheel.centre.value),
            frames.index(&wheel.frame.value),
        ) else {
            return Vec::new();
        };
        let axle = wheel.axle.value.index();
        let (u, v) = ((axle + 1) % 3, (axle + 2) % 3);
        let radius = self.expr(&wheel.radius);
        let zero = self.arena.int(0);
        let first = points.len();
        for k in 0..RIM {
            let angle = std::f64::consts::TAU * k as f64 / RIM as f64;
            let mut r = [zero; 3];
            for (slot, f) in [(u, angle.cos()), (v, angle.sin())] {
                let c = self
                    .arena
                    .constant(Constant::float(f).unwrap_or(Constant::ZERO));
                r[slot] = self.arena.times(radius, c);
            }
            let r = frames.express(&mut self.arena, r, frame, 0);
            let position: Vec<ExprId> = points[centre]
                .1
                .iter()
                .zip(r)
                .map(|(a, b)| self.arena.plus(*a, b))
                .collect();
            points.push((format!("{}.rim{k}", wheel.centre.value), position));
        }
        (0..RIM)
            .map(|k| [first + k, first + (k + 1) % RIM])
            .chain((0..4).map(|s| [centre, first + s * RIM / 4]))
            .collect()
    }

    /// The energies and generalized forces written as such (`kinetic:`, `potential:`,
    /// `generalized_forces:`).
    fn energies_written(&mut self, terms: &mut Terms, coordinate_names: &[String]) {
        let file = self.file;
        if let Some(k) = &file.kinetic {
            let e = self.expr(k);
            terms.kinetic.push(e);
        }
        if let Some(v) = &file.potential {
            let e = self.expr(v);
            terms.potential.push(e);
        }
        for (name, q) in &file.generalized_forces {
            let e = self.expr(q);
            match coordinate_names.iter().position(|c| *c == name.value) {
                Some(i) => terms.forces[i].push(e),
                None => self.errors.push(Diagnostic::new(
                    name.location,
                    format!("`{}` is not a coordinate", name.value),
                )),
            }
        }
    }

    /// Bodies: T = ½ m v_G·v_G (+ ½ I ω² for planar rigid bodies, + ½ ω·I_G ω for 3-D
    /// ones), V = −m g·r_G. Returns the bodies and the angle of each planar rigid body, by
    /// name.
    fn bodies(
        &mut self,
        points: &Points,
        frames: &mut Frames,
        gravity: Option<&[ExprId]>,
        terms: &mut Terms,
    ) -> (Vec<BodyInfo>, Vec<(String, ExprId)>) {
        let half = terms.half;
        let mut angles: Vec<(String, ExprId)> = Vec::new();
        let mut body_infos: Vec<BodyInfo> = Vec::new();
        for body in &self.file.bodies {
            let (mass, at, rigid) = match &body.kind {
                BodyKind::Particle { mass, at } => (mass, at, None),
                BodyKind::Rigid {
                    mass,
                    inertia,
                    com,
                    angle,
                } => (mass, com, Some((inertia, angle))),
                BodyKind::Spatial { mass, com, .. } => (mass, com, None),
            };
            let m = self.expr(mass);
            let Some(ip) = point(points, &at.value) else {
                self.errors.push(Diagnostic::new(
                    at.location,
                    format!("unknown point `{}`", at.value),
                ));
                continue;
            };
            let r = points[ip].1.clone();
            let v: Vec<ExprId> = r.iter().map(|c| self.arena.time_derivative(*c)).collect();
            let v2 = self.dot(&v, &v);
            terms.kinetic.push(self.arena.product(&[half, m, v2]));
            if let Some(g) = gravity {
                let gr = self.dot(g, &r);
                let mgr = self.arena.times(m, gr);
                terms.potential.push(self.arena.neg(mgr));
            }
            let mut rotation = None;
            if let Some((inertia, angle)) = rigid {
                let i = self.expr(inertia);
                let th = self.expr(angle);
                rotation = Some((i, th));
                let w = self.arena.time_derivative(th);
                let two = self.arena.int(2);
                let w2 = self.arena.pow(w, two);
                terms.kinetic.push(self.arena.product(&[half, i, w2]));
                angles.push((body.name.value.clone(), th));
            }
            let spatial = match &body.kind {
                BodyKind::Spatial { frame, inertia, .. } => {
                    self.spatial_body(frames, frame, inertia, terms)
                }
                _ => None,
            };
            body_infos.push(BodyInfo {
                name: body.name.value.clone(),
                mass: m,
                com: ip,
                rotation,
                spatial,
            });
        }
        (body_infos, angles)
    }

    /// A 3-D body's angular velocity (from its frame's rotations) and inertia tensor, with
    /// its rotational kinetic energy `½ ω·I_G ω` (body components) added to `T`.
    fn spatial_body(
        &mut self,
        frames: &mut Frames,
        frame: &Located<String>,
        inertia: &crate::model::file::InertiaTensor,
        terms: &mut Terms,
    ) -> Option<SpatialBody> {
        let Some(f) = frames.index(&frame.value) else {
            self.errors.push(Diagnostic::new(
                frame.location,
                format!("unknown frame `{}`", frame.value),
            ));
            return None;
        };
        let zero = self.arena.int(0);
        let inertia = inertia
            .entries
            .clone()
            .map(|e| e.map_or(zero, |e| self.expr(&e)));
        let w = frames.angular_velocity(&mut self.arena, f);
        let iw = super::frames::tensor_times(&mut self.arena, &inertia, &w);
        let wiw = self.dot(&w, &iw);
        terms.kinetic.push(self.arena.times(terms.half, wiw));
        Some(SpatialBody {
            frame: f,
            angular_velocity: w,
            inertia,
        })
    }

    /// Springs: V = ½ k (|r_A − r_B| − ℓ₀)², or ½ k |r_A − r_B|² for zero rest length.
    fn springs(&mut self, points: &Points, terms: &mut Terms) -> Vec<LoadInfo> {
        let mut loads = Vec::new();
        for s in &self.file.springs {
            let (Some(a), Some(b)) = (
                point(points, &s.between[0].value),
                point(points, &s.between[1].value),
            ) else {
                self.errors.push(Diagnostic::new(
                    s.name.location,
                    format!("spring `{}` names an unknown point", s.name.value),
                ));
                continue;
            };
            let d = self.difference(&points[a].1, &points[b].1);
            let d2 = self.dot(&d, &d);
            let k = self.expr(&s.stiffness);
            let rest = s.rest_length.as_ref().map(|l| self.expr(l));
            loads.push(LoadInfo::Spring {
                between: [a, b],
                stiffness: k,
                rest_length: rest,
            });
            let stretch2 = match rest {
                None => d2,
                Some(l0) => {
                    let len = self.arena.sqrt(d2);
                    let st = self.arena.minus(len, l0);
                    let two = self.arena.int(2);
                    self.arena.pow(st, two)
                }
            };
            terms
                .potential
                .push(self.arena.product(&[terms.half, k, stretch2]));
        }
        loads
    }

    /// Dampers along the line AB: F_A = −c (ḋ·e) e with d = r_A − r_B, e = d/|d|, so
    /// Qᵢ = F_A·∂d/∂qᵢ = −c (d·ḋ)(d·∂d/∂qᵢ)/(d·d).
    fn dampers(
        &mut self,
        points: &Points,
        q_symbols: &[SymbolId],
        terms: &mut Terms,
    ) -> Vec<LoadInfo> {
        let mut loads = Vec::new();
        for dmp in &self.file.dampers {
            let (Some(a), Some(b)) = (
                point(points, &dmp.between[0].value),
                point(points, &dmp.between[1].value),
            ) else {
                self.errors.push(Diagnostic::new(
                    dmp.name.location,
                    format!("damper `{}` names an unknown point", dmp.name.value),
                ));
                continue;
            };
            let d = self.difference(&points[a].1, &points[b].1);
            let dd: Vec<ExprId> = d.iter().map(|c| self.arena.time_derivative(*c)).collect();
            let c = self.expr(&dmp.coefficient);
            loads.push(LoadInfo::Damper {
                between: [a, b],
                coefficient: c,
            });
            let d2 = self.dot(&d, &d);
            let rate = self.dot(&d, &dd);
            let c_rate = self.arena.times(c, rate);
            let scale = self.arena.divide(c_rate, d2);
            let scale = self.arena.neg(scale);
            for (i, qs) in q_symbols.iter().enumerate() {
                let partial: Vec<ExprId> = d.iter().map(|x| self.arena.diff(*x, *qs)).collect();
                let proj = self.dot(&d, &partial);
                if !self.arena.is_zero(proj) {
                    terms.forces[i].push(self.arena.times(scale, proj));
                }
            }
        }
        loads
    }

    /// Forces at points: Qᵢ = F·∂r_P/∂qᵢ (the partial velocity ∂v_P/∂q̇ᵢ); a force written
    /// in a frame (`in: B`) is carried into the ground frame's components first.
    fn forces(
        &mut self,
        points: &Points,
        frames: &Frames,
        q_symbols: &[SymbolId],
        terms: &mut Terms,
    ) -> Vec<LoadInfo> {
        let mut loads = Vec::new();
        for f in &self.file.forces {
            let Some(ip) = point(points, &f.at.value) else {
                self.errors.push(Diagnostic::new(
                    f.at.location,
                    format!("unknown point `{}`", f.at.value),
                ));
                continue;
            };
            let mut force: Vec<ExprId> = f.vector.iter().map(|c| self.expr(c)).collect();
            if let Some(frame) = &f.frame
                && let (Some(from), &[x, y, z]) = (frames.index(&frame.value), &force[..])
            {
                force = frames.express(&mut self.arena, [x, y, z], from, 0).to_vec();
            }
            loads.push(LoadInfo::Force {
                point: ip,
                vector: force.clone(),
            });
            let r = &points[ip].1;
            for (i, qs) in q_symbols.iter().enumerate() {
                let partial: Vec<ExprId> = r.iter().map(|x| self.arena.diff(*x, *qs)).collect();
                let proj = self.dot(&force, &partial);
                if !self.arena.is_zero(proj) {
                    terms.forces[i].push(proj);
                }
            }
        }
        loads
    }

    /// Torques on planar bodies: Qᵢ = τ ∂θ/∂qᵢ (partial angular velocity); on 3-D bodies
    /// Qᵢ = τ·∂ω/∂q̇ᵢ, both in the body frame's components.
    fn torques(
        &mut self,
        angles: &[(String, ExprId)],
        body_infos: &[BodyInfo],
        frames: &Frames,
        q_symbols: &[SymbolId],
        terms: &mut Terms,
    ) -> Vec<LoadInfo> {
        let mut loads = Vec::new();
        for tq in &self.file.torques {
            let value = match &tq.value {
                TorqueValue::Planar(value) => value,
                TorqueValue::Spatial { vector, frame, .. } => {
                    let body = body_infos.iter().position(|b| b.name == tq.body.value);
                    let Some((b, Some(spatial))) =
                        body.map(|b| (b, body_infos[b].spatial.as_ref()))
                    else {
                        self.errors.push(Diagnostic::new(
                            tq.body.location,
                            format!("`{}` is not a 3-D rigid body", tq.body.value),
                        ));
                        continue;
                    };
                    let from = match frame {
                        Some(f) => frames.index(&f.value).unwrap_or(0),
                        None => 0,
                    };
                    let [x, y, z] = &vector[..] else { continue };
                    let v = [x, y, z].map(|c| self.expr(c));
                    let v = frames.express(&mut self.arena, v, from, spatial.frame);
                    for i in 0..q_symbols.len() {
                        let rate = self.arena.coordinates()[i][1];
                        let partial: Vec<ExprId> = spatial
                            .angular_velocity
                            .iter()
                            .map(|w| self.arena.diff(*w, rate))
                            .collect();
                        let proj = self.dot(&v, &partial);
                        if !self.arena.is_zero(proj) {
                            terms.forces[i].push(proj);
                        }
                    }
                    loads.push(LoadInfo::SpatialTorque { body: b, vector: v });
                    continue;
                }
            };
            let Some(th) = angles
                .iter()
                .find(|(b, _)| *b == tq.body.value)
                .map(|(_, a)| *a)
            else {
                self.errors.push(Diagnostic::new(
                    tq.body.location,
                    format!("`{}` is not a planar rigid body", tq.body.value),
                ));
                continue;
            };
            let tau = self.expr(value);
            loads.push(LoadInfo::Torque {
                body: body_infos
                    .iter()
                    .position(|b| b.name == tq.body.value)
                    .unwrap_or(0),
                angle: th,
                value: tau,
            });
            for (i, qs) in q_symbols.iter().enumerate() {
                let partial = self.arena.diff(th, *qs);
                if !self.arena.is_zero(partial) {
                    terms.forces[i].push(self.arena.times(tau, partial));
                }
            }
        }
        loads
    }

    /// The momentum balances chosen in `balances:`, with their points and bodies by index.
    fn balances(
        &mut self,
        points: &Points,
        body_infos: &[BodyInfo],
        frames: &Frames,
    ) -> Vec<BalanceInfo> {
        let mut balances = Vec::new();
        for b in &self.file.balances {
            let bodies: Vec<usize> = b
                .bodies
                .iter()
                .filter_map(|name| body_infos.iter().position(|x| x.name == name.value))
                .collect();
            match &b.kind {
                crate::model::file::BalanceKind::Amb {
                    about,
                    form,
                    axis,
                    frame,
                } => {
                    // A 3-D axis, carried into the ground frame's components.
                    let axis = axis.as_ref().and_then(|axis| {
                        let [x, y, z] = &axis.value[..] else {
                            return None;
                        };
                        let e = [x, y, z].map(|c| self.expr(c));
                        let from = match frame {
                            Some(f) => frames.index(&f.value)?,
                            None => 0,
                        };
                        Some(frames.express(&mut self.arena, e, from, 0).to_vec())
                    });
                    match point(points, &about.value) {
                        Some(about) => balances.push(BalanceInfo::Amb {
                            about,
                            bodies,
                            form: *form,
                            axis,
                        }),
                        None => self.errors.push(Diagnostic::new(
                            about.location,
                            format!("unknown point `{}`", about.value),
                        )),
                    }
                }
                crate::model::file::BalanceKind::Lmb { along } => {
                    let along = along.iter().map(|e| self.expr(e)).collect();
                    balances.push(BalanceInfo::Lmb { along, bodies });
                }
            }
        }
        balances
    }

    /// The equations of motion written by hand in `checks:`, each as `lhs − rhs`; reports one
    /// that is not linear in the accelerations.
    fn hand_equations(&mut self) -> Vec<ExprId> {
        let file = self.file;
        self.allow_accelerations = true;
        let hand_equations: Vec<ExprId> = file
            .checks
            .equations_of_motion
            .iter()
            .map(|e| {
                let lhs = self.expr(&e.lhs);
                match &e.rhs {
                    Some(rhs) => {
                        let rhs = self.expr(rhs);
                        self.arena.minus(lhs, rhs)
                    }
                    None => lhs,
                }
            })
            .collect();
        self.allow_accelerations = false;
        // Each must be linear in the accelerations: no coefficient of a q̈ⱼ may depend on one.
        let accelerations: Vec<SymbolId> = self.arena.coordinates().iter().map(|c| c[2]).collect();
        for (e, r) in file.checks.equations_of_motion.iter().zip(&hand_equations) {
            let nonlinear = accelerations.iter().any(|a| {
                let c = self.arena.diff(*r, *a);
                let c = self.arena.expand(c);
                accelerations.iter().any(|b| self.arena.depends_on(c, *b))
            });
            if nonlinear {
                self.errors.push(
                    Diagnostic::new(e.location, "this equation of motion is not linear in the accelerations")
                        .with_help("equations of motion are M(q, t) q̈ = f(q, q̇, t): each `x_ddot` appears only to the first power, times a function of q, q̇ and t"),
                );
            }
        }
        hand_equations
    }

    /// The events' functions, which may use the accelerations.
    fn events(&mut self) -> Vec<EventInfo> {
        self.allow_accelerations = true;
        let events = self
            .file
            .events
            .iter()
            .map(|e| EventInfo {
                name: e.name.value.clone(),
                function: self.expr(&e.when),
                direction: e.direction,
                terminal: e.terminal,
            })
            .collect();
        self.allow_accelerations = false;
        events
    }

    /// The named equilibria, each a value per coordinate (0 for one it does not give), with
    /// the rates of a steady motion (0 where not given) and its ignorable coordinates.
    fn equilibria(&mut self, coordinate_names: &[String]) -> Vec<Equilibrium> {
        self.file
            .equilibria
            .iter()
            .map(|q| {
                let mut guess = vec![self.arena.int(0); coordinate_names.len()];
                let mut rates = guess.clone();
                for (c, e) in &q.values {
                    let value = self.expr(e);
                    if let Some(i) = coordinate_names.iter().position(|x| *x == c.value) {
                        guess[i] = value;
                    } else if let Some(i) = coordinate_names
                        .iter()
                        .position(|x| c.value.strip_suffix("_dot") == Some(x.as_str()))
                    {
                        rates[i] = value;
                    }
                }
                let ignorable = q
                    .ignorable
                    .iter()
                    .filter_map(|c| coordinate_names.iter().position(|x| *x == c.value))
                    .collect();
                Equilibrium {
                    name: q.name.value.clone(),
                    guess,
                    rates,
                    ignorable,
                }
            })
            .collect()
    }

    /// The initial coordinates and rates of `initial:` (0 for one it does not give).
    fn initial_state(&mut self, coordinate_names: &[String]) -> (Vec<ExprId>, Vec<ExprId>) {
        let n = coordinate_names.len();
        let mut initial_q = vec![self.arena.int(0); n];
        let mut initial_qdot = vec![self.arena.int(0); n];
        for (name, value) in &self.file.initial {
            let e = self.expr(value);
            if let Some(i) = coordinate_names.iter().position(|c| *c == name.value) {
                initial_q[i] = e;
            } else if let Some(i) = coordinate_names
                .iter()
                .position(|c| name.value.strip_suffix("_dot") == Some(c.as_str()))
            {
                initial_qdot[i] = e;
            } else {
                self.errors.push(Diagnostic::new(
                    name.location,
                    format!("`{}` is neither a coordinate nor a rate", name.value),
                ));
            }
        }
        (initial_q, initial_qdot)
    }
}

/// What a rolling contact reads of the lowered model: the points, the bodies and the frames.
#[derive(Clone, Copy)]
struct Kinematics<'a> {
    points: &'a Points,
    bodies: &'a [BodyInfo],
    frames: &'a Frames,
}

impl Lowering<'_> {
    /// The constraints of a rolling contact, `(v_G + ω × (r_C − r_G))·e_k = 0` for each axis
    /// `e_k` of its frame, by name; none (with an error) when its body, point or frame is
    /// unknown.
    fn rolling_contact(
        &mut self,
        r: &crate::model::file::RollingContact,
        k: Kinematics<'_>,
    ) -> Vec<(String, ExprId)> {
        let body = k.bodies.iter().find(|b| b.name == r.body.value);
        let contact = point(k.points, &r.point.value);
        let frame = match &r.frame {
            Some(f) => k.frames.index(&f.value),
            None => Some(0),
        };
        let (Some(body), Some(contact), Some(frame)) = (body, contact, frame) else {
            self.errors.push(Diagnostic::new(
                r.name.location,
                format!(
                    "rolling contact `{}` names an unknown body, point or frame",
                    r.name.value
                ),
            ));
            return Vec::new();
        };
        let centre = &k.points[body.com].1;
        let offset: Vec<ExprId> = k.points[contact]
            .1
            .iter()
            .zip(centre)
            .map(|(c, g)| self.arena.minus(*c, *g))
            .collect();
        let velocity: Vec<ExprId> = centre
            .iter()
            .map(|c| self.arena.time_derivative(*c))
            .collect();
        // ω × r: in 3-D with ω carried into the ground frame; in the plane ω = θ̇ about z.
        let spin: Vec<ExprId> = match (&body.spatial, body.rotation, offset.len()) {
            (Some(s), _, 3) => {
                let w = k
                    .frames
                    .express(&mut self.arena, s.angular_velocity, s.frame, 0);
                let r3 = [offset[0], offset[1], offset[2]];
                super::frames::cross(&mut self.arena, &w, &r3).to_vec()
            }
            (None, Some((_, angle)), 2) => {
                let w = self.arena.time_derivative(angle);
                let a = self.arena.times(w, offset[1]);
                let b = self.arena.times(w, offset[0]);
                vec![self.arena.neg(a), b]
            }
            _ => {
                self.errors.push(Diagnostic::new(
                    r.body.location,
                    format!(
                        "rolling contact `{}`: `{}` is not a rigid body of the model's dimension",
                        r.name.value, r.body.value
                    ),
                ));
                return Vec::new();
            }
        };
        let slip: Vec<ExprId> = velocity
            .iter()
            .zip(&spin)
            .map(|(v, s)| self.arena.plus(*v, *s))
            .collect();
        let (zero, one) = (self.arena.int(0), self.arena.int(1));
        r.along
            .iter()
            .zip(r.constraint_names())
            .map(|(axis, name)| {
                let mut e = vec![zero; slip.len()];
                e[axis.value.index()] = one;
                if slip.len() == 3 {
                    e = k
                        .frames
                        .express(&mut self.arena, [e[0], e[1], e[2]], frame, 0)
                        .to_vec();
                }
                (name.value, self.dot(&slip, &e))
            })
            .collect()
    }
}

/// The points of a model: name and position, in file order.
type Points = Vec<(String, Vec<ExprId>)>;

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

#[cfg(test)]
mod tests {
    use super::*;

    /// `equilibria:` (coordinates, rates and ignorable coordinates) and `{ guess: … }` map to
    /// their coordinates by name, in any order.
    #[test]
    fn equilibria_and_guesses_go_to_their_coordinates() {
        let src = "name: x\nparameters: { m: 1.0 }\ncoordinates: [a, b, c]\npoints: { P: [a, b], Q: [c, 0] }\nbodies: { p: { mass: m, at: P }, q: { mass: m, at: Q } }\nconstraints:\n  k: a + b + c - 6\ninitial: { a: 1, c: { guess: 3 }, b: { guess: 2 } }\nequilibria:\n  e: { c: 3, a: 1 }\n  s: { b_dot: 2, a: 1, ignorable: [c] }\n";
        let file = crate::model::load("m.yaml", src).expect("loads");
        let model = SymbolicModel::from_file(&file).unwrap();
        assert_eq!(model.initial_guesses, [2, 1]);
        let numbers = |values: &[ExprId]| -> Vec<Option<f64>> {
            values
                .iter()
                .map(|e| model.arena.as_constant(*e).map(Constant::to_f64))
                .collect()
        };
        let e = &model.equilibria[0];
        assert_eq!(
            (e.name.as_str(), numbers(&e.guess)),
            ("e", vec![Some(1.0), Some(0.0), Some(3.0)])
        );
        // A steady motion: its rates go to their coordinates, and its ignorable coordinates.
        let s = &model.equilibria[1];
        assert_eq!(numbers(&s.guess), [Some(1.0), Some(0.0), Some(0.0)]);
        assert_eq!(numbers(&s.rates), [Some(0.0), Some(2.0), Some(0.0)]);
        assert_eq!(s.ignorable, [2]);
        assert!(model.has_steady_motions());
    }
}
