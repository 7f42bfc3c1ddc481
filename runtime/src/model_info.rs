//! The size-erased model, as the CLI and every analysis hold it: [`ModelInfo`], and the
//! constraint functions at one state it returns ([`ConstraintValues`]).
//!
//! [`ModelInfo`] is implemented once, for every first-order form that lends its system as a
//! [`DynMechanicalSystem`] with its constraint workspace, drift control and events (the
//! crate-private `FirstOrderForm`): [`FirstOrder`](crate::FirstOrder) is one (its compiled
//! system through the crate-private adapter `StaticSystem`),
//! [`DynFirstOrder`](crate::DynFirstOrder) the other.

use nalgebra::{DMatrix, DVector};

use crate::constrained::{ConstraintWorkspace, ProjectionError, Stabilization};
use crate::dynamic::DynMechanicalSystem;
use crate::ode::{EventSpec, OdeSystem, RhsError};
use crate::system::{ModelDescription, UnknownParameter};

/// A model as `eomgen list --json` lists it: `{"name", "dof", "description"}`.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct ModelSummary {
    /// The model's name.
    pub name: String,
    /// Its degrees of freedom `n`.
    pub dof: usize,
    /// Its one-line description (the file's `description:`).
    pub description: String,
}

impl ModelSummary {
    /// The summary of `model`.
    pub fn of(model: &dyn ModelInfo) -> Self {
        Self {
            name: model.description().name.to_string(),
            dof: model.num_dofs(),
            description: model.description().summary.to_string(),
        }
    }
}

/// A model with its size erased, as the CLI holds it: `Box<dyn ModelInfo>`.
///
/// Implemented once, for both first-order forms: [`FirstOrder`](crate::FirstOrder) for every
/// model compiled by `eomgen::model!` and [`DynFirstOrder`](crate::DynFirstOrder) for a model
/// compiled at run time; names are borrowed from the model (which owns them in the second
/// case).
///
/// Vectors here are runtime-sized; `y = [q; q̇]` has length `2 num_dofs()`.
pub trait ModelInfo: OdeSystem {
    /// Everything about the model that is not a function of the state: names of the
    /// coordinates, parameters, points and constraints, equilibria, events, drawing and the
    /// derived equations as text ([`MechanicalSystem::description`](crate::MechanicalSystem::description)).
    fn description(&self) -> &ModelDescription;
    /// Number of degrees of freedom `n` (the description's coordinates).
    fn num_dofs(&self) -> usize {
        self.description().num_dofs()
    }
    /// Current parameter values.
    fn parameter_values(&self) -> Vec<f64>;
    /// Sets a parameter by name.
    ///
    /// # Errors
    /// [`UnknownParameter`] if there is no parameter `name`.
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter>;
    /// Initial state `y(0) = [q(0); q̇(0)]` (length `2n`).
    fn initial_state(&self) -> Vec<f64>;
    /// Kinetic energy `T` at `(t, y)` (J).
    fn kinetic_energy(&self, t: f64, y: &[f64]) -> f64;
    /// Potential energy `V` at `(t, y)` (J).
    fn potential_energy(&self, t: f64, y: &[f64]) -> f64;
    /// Total mechanical energy `T + V` (J).
    fn energy(&self, t: f64, y: &[f64]) -> f64 {
        self.kinetic_energy(t, y) + self.potential_energy(t, y)
    }
    /// Positions of the points at `(t, y)`, `[x, y, z]` each (m).
    fn point_positions(&self, t: f64, y: &[f64]) -> Vec<[f64; 3]>;
    /// Upcast to the first-order system for an integrator.
    fn as_ode_mut(&mut self) -> &mut dyn OdeSystem;
    /// The first-order system, borrowed.
    fn as_ode(&self) -> &dyn OdeSystem;
    /// `M` (`n × n`) and `F` (`n`) at `(t, y)`.
    fn mass_matrix_and_forcing(&self, t: f64, y: &[f64]) -> (DMatrix<f64>, DVector<f64>);
    /// The exact Jacobians `(∂F/∂q, ∂F/∂q̇)`, each `n × n`, at `(t, y)`.
    fn forcing_jacobians(&self, t: f64, y: &[f64]) -> (DMatrix<f64>, DMatrix<f64>);
    /// The exact `∂(M a)/∂q` (`n × n`) at `(t, q)` for the vector `a` (length `n`).
    fn mass_matrix_product_jacobian(&self, t: f64, y: &[f64], a: &[f64]) -> DMatrix<f64>;
    /// The coordinates' rates `q̇` (`n`) at `(t, y)`: the kinematic equations of a model in
    /// generalized speeds ([`ModelDescription::speeds`]), `y`'s second half otherwise.
    fn coordinate_rates(&self, t: f64, y: &[f64]) -> DVector<f64>;
    /// The exact `(∂q̇/∂q, ∂q̇/∂u)` of [`Self::coordinate_rates`], each `n × n`, at `(t, y)`
    /// (`(0, I)` in the coordinates' rates).
    fn coordinate_rates_jacobian(&self, t: f64, y: &[f64]) -> (DMatrix<f64>, DMatrix<f64>);
    /// Selects the drift control of a constrained model.
    fn set_stabilization(&mut self, stabilization: Stabilization);
    /// The constraint forces `λ` (length `m`; see [`ModelDescription::constraints`] for
    /// their meaning and sign) and `q̈` at `(t, y)`.
    ///
    /// # Errors
    /// As the right-hand side.
    fn constraint_forces(&mut self, t: f64, y: &[f64]) -> Result<Vec<f64>, RhsError>;
    /// Largest `|Φᵢ|` and largest velocity-level residual at `(t, y)`; `(0, 0)` without
    /// constraints.
    fn constraint_drift(&mut self, t: f64, y: &[f64]) -> (f64, f64);
    /// Projects `y = [q; q̇]` onto the constraint manifold at `t`, moving only the coordinates
    /// `free` (all when empty); see [`ConstraintWorkspace::project`].
    ///
    /// # Errors
    /// [`ProjectionError`] when Newton does not converge.
    fn project(&mut self, t: f64, y: &mut [f64], free: &[usize]) -> Result<usize, ProjectionError>;
    /// The model's named equilibrium guesses `(name, q)` ([`ModelDescription::equilibria`]).
    fn equilibrium_guesses(&self) -> Vec<(&str, Vec<f64>)>;
    /// The rates `q̇` (length `n`) each entry of [`ModelDescription::equilibria`] holds: a
    /// steady motion's, all 0 for an equilibrium.
    fn equilibrium_rates(&self) -> Vec<Vec<f64>>;
    /// Makes the model event `name` terminal or not (`eomgen simulate --stop-when NAME`);
    /// returns `false` if the model has no event `name`.
    fn set_event_terminal(&mut self, name: &str, terminal: bool) -> bool;
    /// `Φ` (length `m_h`), `J` (`m × n`), the velocity residuals and `γ` (length `m`) at
    /// `(t, y)`; see [`constraint_jacobian`](crate::MechanicalSystem::constraint_jacobian) and siblings.
    fn constraint_equations(&self, t: f64, y: &[f64]) -> ConstraintValues;
    /// The unilateral contacts at `(t, y)` ([`ModelDescription::contacts`]): gaps, their
    /// rates, rows and coefficients ([`crate::MechanicalSystem::contact_gaps`] and
    /// siblings); empty without contacts.
    fn contact_values(&self, t: f64, y: &[f64]) -> ContactValues;
    /// The contacts' gaps `g`, their rates `ġ`, `γ`, `γ_T` and the surfaces' speeds `v_s` at
    /// `(t, y)` into `out` (`5 m_c` entries): [`crate::MechanicalSystem::contact_gaps`] alone.
    fn contact_gaps(&self, t: f64, y: &[f64], out: &mut [f64]);
    /// The changes of support's values at `(t, q)` into `out`
    /// ([`crate::MechanicalSystem::support_changes`]; read them with
    /// [`crate::hybrid::support::SupportValues::of`]).
    fn support_changes(&self, t: f64, q: &[f64], out: &mut [f64]);
    /// Makes `y = [q; q̇]` (at `t = 0`) consistent with the constraints (issue 5, item 3): the
    /// coordinates marked `{ guess: … }` and their rates are solved by Newton from
    /// `Φ(q, 0) = 0` and the velocity constraints, the others held. Without guesses, `y` must
    /// already satisfy the constraints to 1e-9. Nothing to do without constraints.
    ///
    /// # Errors
    /// [`ProjectionError`] naming the constraint with the largest residual: Newton did not
    /// converge, or (without guesses, `iterations` = 0) the given state violates it.
    fn make_consistent(&mut self, y: &mut [f64]) -> Result<(), ProjectionError> {
        if self.description().constraints.is_empty() {
            return Ok(());
        }
        let guesses = self.description().initial_guesses.to_vec();
        if !guesses.is_empty() {
            return self.project(0.0, y, &guesses).map(|_| ());
        }
        let c = self.constraint_equations(0.0, y);
        let worst = c
            .phi
            .iter()
            .map(|v| v.abs())
            .enumerate()
            .chain(c.velocity.iter().map(|v| v.abs()).enumerate())
            // A NaN residual is the worst (it must not pass as consistent).
            .fold((0, 0.0f64), |best, x| {
                if x.1.is_nan() || (x.1 > best.1 && !best.1.is_nan()) {
                    x
                } else {
                    best
                }
            });
        if worst.1 > 1e-9 || worst.1.is_nan() {
            return Err(ProjectionError {
                constraint: worst.0,
                residual: worst.1,
                iterations: 0,
            });
        }
        Ok(())
    }
    /// [`Self::initial_state`] made consistent by [`Self::make_consistent`].
    ///
    /// # Errors
    /// As [`Self::make_consistent`].
    fn consistent_initial_state(&mut self) -> Result<Vec<f64>, ProjectionError> {
        let mut y = self.initial_state();
        self.make_consistent(&mut y)?;
        Ok(y)
    }
}

/// The constraint functions of a model at one state ([`ModelInfo::constraint_equations`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintValues {
    /// `Φ(q, t)` of the holonomic constraints (length `m_h`).
    pub phi: DVector<f64>,
    /// `J`, `m × n`: `∂Φ/∂q` rows, then the non-holonomic `A` rows.
    pub jacobian: DMatrix<f64>,
    /// Velocity residuals `J q̇ + Φ_t` and `A q̇ + b` (length `m`).
    pub velocity: DVector<f64>,
    /// `γ` of `J q̈ = γ` (length `m`).
    pub gamma: DVector<f64>,
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

/// A model's unilateral contacts at one state ([`ModelInfo::contact_values`]).
///
/// # Shapes
/// `m_c` contacts and `n` coordinates: `gaps`, `rates`, `gamma`, `tangent_gamma`,
/// `restitution`, `friction` have `m_c`
/// entries; `normal` (`G = ∂g/∂q`) and `tangent` (the slips' rows `T`) `m_c × n`, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactValues {
    /// `g(q, t)` (m).
    pub gaps: Vec<f64>,
    /// `ġ = G q̇ + ∂g/∂t` (m/s).
    pub rates: Vec<f64>,
    /// `γ` of `G q̈ = γ` (m/s²).
    pub gamma: Vec<f64>,
    /// `γ_T` of `T q̈ = γ_T` (m/s²; 0 without friction).
    pub tangent_gamma: Vec<f64>,
    /// `v_s`, the speed of each surface's material along it (m/s; a belt's, else 0).
    pub surface_velocity: Vec<f64>,
    /// `G`, row-major.
    pub normal: Vec<f64>,
    /// `T`, row-major (zeros for a frictionless contact).
    pub tangent: Vec<f64>,
    /// Newton's coefficients of restitution `e`.
    pub restitution: Vec<f64>,
    /// Coulomb's coefficients `μ` (0: frictionless), with which a contact slides.
    pub friction: Vec<f64>,
    /// The static coefficients `μ_s ≥ μ` of the sticking cones (`μ` unless given).
    pub static_friction: Vec<f64>,
}

impl ContactValues {
    /// The slip of contact `c` at speeds `qdot` (`n` entries): `v_t = T q̇ − v_s` (m/s), its
    /// velocity along the surface relative to the surface's material.
    pub fn slip(&self, c: usize, qdot: &[f64]) -> f64 {
        let n = qdot.len();
        let row = &self.tangent[c * n..(c + 1) * n];
        row.iter().zip(qdot).map(|(a, b)| a * b).sum::<f64>() - self.surface_velocity[c]
    }
}

/// A first-order form `y = [q; q̇]` of a mechanical system, as [`ModelInfo`] is written over
/// it: the system seen as a [`DynMechanicalSystem`], and the state a model carries besides its
/// equations (constraint workspace, drift control, events).
///
/// # Why
/// [`FirstOrder<S, N>`](crate::FirstOrder) (compiled, `S: MechanicalSystem<N>`) and
/// [`DynFirstOrder`](crate::DynFirstOrder) (compiled at run time) are the same model behind
/// two interfaces. Their right-hand sides stay their own (the compiled one on stack vectors
/// and matrices of size `N`, the hot path of every integration), but everything else the
/// size-erased [`ModelInfo`] offers (metadata, energies, points, constraint functions and
/// forces, projection, equilibrium guesses, events) is the same computation, written once in
/// the blanket `impl<F: FirstOrderForm> ModelInfo for F` over [`DynMechanicalSystem`]. A
/// compiled system takes part through the adapter [`StaticSystem`](crate::dynamic::StaticSystem),
/// which copies its static vectors to and from slices (those calls are not on the hot path).
pub(crate) trait FirstOrderForm: OdeSystem {
    /// The system, seen through the run-time interface.
    type System: DynMechanicalSystem + ?Sized;
    /// The system.
    fn dyn_system(&self) -> &Self::System;
    /// The system and the state beside it, mutably and at once.
    fn parts_mut(&mut self) -> FirstOrderParts<'_, Self::System>;
}

/// What a [`FirstOrderForm`] lends mutably ([`FirstOrderForm::parts_mut`]).
#[derive(Debug)]
pub(crate) struct FirstOrderParts<'a, S: ?Sized> {
    /// The system.
    pub system: &'a mut S,
    /// Drift control of a constrained system.
    pub stabilization: &'a mut Stabilization,
    /// Buffers and the last multipliers `λ` of a constrained system.
    pub constraints: &'a mut ConstraintWorkspace,
    /// The model's events.
    pub events: &'a mut Vec<EventSpec>,
}

/// The values of each entry of `equilibria:` as the system's `equilibrium_guesses` gives
/// them: `n` coordinates, followed by `n` rates when the model has a steady motion
/// ([`ModelDescription::equilibrium_rates`]).
fn equilibrium_values<S: DynMechanicalSystem + ?Sized>(system: &S) -> Vec<Vec<f64>> {
    let d = system.description();
    let per = system.num_dofs() * if d.equilibrium_rates { 2 } else { 1 };
    let mut values = vec![0.0; per * d.equilibria.len()];
    system.equilibrium_guesses(&mut values);
    values.chunks(per.max(1)).map(<[f64]>::to_vec).collect()
}

impl<F: FirstOrderForm> ModelInfo for F {
    fn description(&self) -> &ModelDescription {
        self.dyn_system().description()
    }
    fn num_dofs(&self) -> usize {
        self.dyn_system().num_dofs()
    }
    fn parameter_values(&self) -> Vec<f64> {
        self.dyn_system().parameter_values()
    }
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter> {
        self.parts_mut().system.set_parameter(name, value)
    }
    fn initial_state(&self) -> Vec<f64> {
        let n = self.num_dofs();
        let mut y = vec![0.0; 2 * n];
        let (q, qdot) = y.split_at_mut(n);
        self.dyn_system().initial_state(q, qdot);
        y
    }
    fn kinetic_energy(&self, t: f64, y: &[f64]) -> f64 {
        let n = self.num_dofs();
        self.dyn_system().kinetic_energy(&y[..n], &y[n..2 * n], t)
    }
    fn potential_energy(&self, t: f64, y: &[f64]) -> f64 {
        let n = self.num_dofs();
        self.dyn_system().potential_energy(&y[..n], t)
    }
    fn point_positions(&self, t: f64, y: &[f64]) -> Vec<[f64; 3]> {
        let system = self.dyn_system();
        let mut out = vec![[0.0; 3]; system.description().points.len()];
        system.point_positions(&y[..system.num_dofs()], t, &mut out);
        out
    }
    fn as_ode_mut(&mut self) -> &mut dyn OdeSystem {
        self
    }
    fn as_ode(&self) -> &dyn OdeSystem {
        self
    }
    fn mass_matrix_and_forcing(&self, t: f64, y: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
        let n = self.num_dofs();
        let (mut mass, mut forcing) = (DMatrix::zeros(n, n), DVector::zeros(n));
        self.dyn_system().mass_matrix_and_forcing(
            &y[..n],
            &y[n..2 * n],
            t,
            mass.as_mut_slice(),
            forcing.as_mut_slice(),
        );
        (mass, forcing)
    }
    fn forcing_jacobians(&self, t: f64, y: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
        let n = self.num_dofs();
        let (mut jq, mut jqd) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
        let system = self.dyn_system();
        system.forcing_jacobian_q(&y[..n], &y[n..2 * n], t, jq.as_mut_slice());
        system.forcing_jacobian_qdot(&y[..n], &y[n..2 * n], t, jqd.as_mut_slice());
        (jq, jqd)
    }
    fn mass_matrix_product_jacobian(&self, t: f64, y: &[f64], a: &[f64]) -> DMatrix<f64> {
        let n = self.num_dofs();
        let mut out = DMatrix::zeros(n, n);
        self.dyn_system()
            .mass_matrix_product_jacobian(&y[..n], t, &a[..n], out.as_mut_slice());
        out
    }
    fn coordinate_rates(&self, t: f64, y: &[f64]) -> DVector<f64> {
        let n = self.num_dofs();
        let mut out = DVector::zeros(n);
        self.dyn_system()
            .coordinate_rates(&y[..n], &y[n..2 * n], t, out.as_mut_slice());
        out
    }
    fn coordinate_rates_jacobian(&self, t: f64, y: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
        let n = self.num_dofs();
        let (mut d_q, mut d_u) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
        self.dyn_system().coordinate_rates_jacobian(
            &y[..n],
            &y[n..2 * n],
            t,
            d_q.as_mut_slice(),
            d_u.as_mut_slice(),
        );
        (d_q, d_u)
    }
    fn set_stabilization(&mut self, stabilization: Stabilization) {
        *self.parts_mut().stabilization = stabilization;
    }
    fn constraint_forces(&mut self, t: f64, y: &[f64]) -> Result<Vec<f64>, RhsError> {
        let parts = self.parts_mut();
        if parts.constraints.is_empty() {
            return Ok(Vec::new());
        }
        let n = parts.system.num_dofs();
        let mut qddot = vec![0.0; n];
        parts.constraints.accelerations_into(
            &*parts.system,
            &y[..n],
            &y[n..2 * n],
            t,
            *parts.stabilization,
            &mut qddot,
        )?;
        Ok(parts.constraints.multipliers.clone())
    }
    fn constraint_drift(&mut self, t: f64, y: &[f64]) -> (f64, f64) {
        let parts = self.parts_mut();
        let n = parts.system.num_dofs();
        parts
            .constraints
            .drift(&*parts.system, &y[..n], &y[n..2 * n], t)
    }
    fn project(&mut self, t: f64, y: &mut [f64], free: &[usize]) -> Result<usize, ProjectionError> {
        let parts = self.parts_mut();
        let n = parts.system.num_dofs();
        // On a copy, so that a projection that fails leaves `y` as it was.
        let mut projected = y[..2 * n].to_vec();
        let (q, qdot) = projected.split_at_mut(n);
        let iterations = parts
            .constraints
            .project(&*parts.system, q, qdot, t, free, 1e-12)?;
        y[..2 * n].copy_from_slice(&projected);
        Ok(iterations)
    }
    fn equilibrium_guesses(&self) -> Vec<(&str, Vec<f64>)> {
        let n = self.num_dofs();
        let names = &self.description().equilibria;
        names
            .iter()
            .zip(equilibrium_values(self.dyn_system()))
            .map(|(name, values)| (name.as_ref(), values[..n].to_vec()))
            .collect()
    }
    fn equilibrium_rates(&self) -> Vec<Vec<f64>> {
        let n = self.num_dofs();
        equilibrium_values(self.dyn_system())
            .into_iter()
            .map(|values| values.get(n..).map_or(vec![0.0; n], <[f64]>::to_vec))
            .collect()
    }
    fn set_event_terminal(&mut self, name: &str, terminal: bool) -> bool {
        match self.parts_mut().events.iter_mut().find(|e| e.name == name) {
            Some(e) => {
                e.terminal = terminal;
                true
            }
            None => false,
        }
    }
    fn contact_gaps(&self, t: f64, y: &[f64], out: &mut [f64]) {
        let system = self.dyn_system();
        let n = system.num_dofs();
        system.contact_gaps(&y[..n], &y[n..2 * n], t, out);
    }
    fn support_changes(&self, t: f64, q: &[f64], out: &mut [f64]) {
        self.dyn_system().support_changes(q, t, out);
    }
    fn contact_values(&self, t: f64, y: &[f64]) -> ContactValues {
        let system = self.dyn_system();
        let n = system.num_dofs();
        let (q, qdot) = (&y[..n], &y[n..2 * n]);
        let m = system.description().contacts.len();
        let mut gaps = vec![0.0; 5 * m];
        let mut rows = vec![0.0; 2 * m * n];
        let mut coefficients = vec![0.0; 3 * m];
        if m > 0 {
            system.contact_gaps(q, qdot, t, &mut gaps);
            system.contact_jacobian(q, t, &mut rows);
            system.contact_coefficients(&mut coefficients);
        }
        let surface_velocity = gaps.split_off(4 * m);
        let tangent_gamma = gaps.split_off(3 * m);
        let gamma = gaps.split_off(2 * m);
        let rates = gaps.split_off(m);
        let tangent = rows.split_off(m * n);
        ContactValues {
            gaps,
            rates,
            gamma,
            tangent_gamma,
            surface_velocity,
            normal: rows,
            tangent,
            restitution: coefficients.iter().step_by(3).copied().collect(),
            friction: coefficients.iter().skip(1).step_by(3).copied().collect(),
            static_friction: coefficients.iter().skip(2).step_by(3).copied().collect(),
        }
    }
    fn constraint_equations(&self, t: f64, y: &[f64]) -> ConstraintValues {
        let system = self.dyn_system();
        let n = system.num_dofs();
        let (q, qdot) = (&y[..n], &y[n..2 * n]);
        let m = system.description().constraints.len();
        let h = system.description().holonomic_constraints;
        let mut phi = vec![0.0; h];
        let mut jacobian = vec![0.0; m * n];
        let mut velocity = vec![0.0; m];
        let mut gamma = vec![0.0; m];
        if m > 0 {
            system.constraint_residuals(q, t, &mut phi);
            system.constraint_jacobian(q, t, &mut jacobian);
            system.constraint_velocity_residuals(q, qdot, t, &mut velocity);
            system.constraint_gamma(q, qdot, t, &mut gamma);
        }
        ConstraintValues {
            phi: DVector::from_vec(phi),
            jacobian: DMatrix::from_row_slice(m, n, &jacobian),
            velocity: DVector::from_vec(velocity),
            gamma: DVector::from_vec(gamma),
        }
    }
}
