//! The interface between generated equations of motion and the runtime.
//!
//! [`MechanicalSystem`] is what `eomgen::model!` implements for every model file: the mass
//! matrix `M(q, t)`, the forcing `F(q, q̇, t)` of `M q̈ = F`, their exact Jacobians, energies and
//! point positions, all with compile-time sizes. Its first-order form is
//! [`FirstOrder`](crate::FirstOrder), which erases the size so that the CLI can hold any model
//! as a `Box<dyn ModelInfo>` ([`ModelInfo`](crate::ModelInfo)).

use nalgebra::{SMatrix, SVector};

use crate::ode::EventSpec;

/// A parameter name that the model does not have.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("model `{model}` has no parameter `{name}` (it has: {known})")]
pub struct UnknownParameter {
    /// The model's name.
    pub model: String,
    /// The name that was asked for.
    pub name: String,
    /// The model's parameter names, comma separated.
    pub known: String,
}

/// A body of a model's kinematic form and the point at its centre of mass, for drawings
/// (`eomgen animate` marks it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BodyCentre<'a> {
    /// The body's name in the model file.
    pub body: &'a str,
    /// The point at its centre of mass (one of [`MechanicalSystem::point_names`]).
    pub point: &'a str,
    /// A planar rigid body (`true`) or a particle.
    pub rigid: bool,
}

/// Equations of motion `M(q, t) q̈ = F(q, q̇, t)` of a mechanism with `N` degrees of freedom.
///
/// Implemented by the code that `eomgen::model!` generates from a model file; the runtime
/// never inverts `M` symbolically but factors it numerically at each state.
///
/// # Shapes
/// `q`, `q̇` and `a` are `N`-vectors (generalized coordinates, velocities, and an arbitrary
/// acceleration-like vector); matrices are `N × N`.
///
/// # Units
/// SI, angles in rad; `F` and `Q` in N or N·m per coordinate; energies in J.
///
/// # References
/// Lagrange's equations in the form of lecture 9 (syllabus), with
/// `M = ∂²T/∂q̇∂q̇ᵀ` and `F = ∂T/∂q − ∂V/∂q − (∂²T/∂q̇∂qᵀ) q̇ − ∂²T/∂q̇∂t + Q`.
pub trait MechanicalSystem<const N: usize> {
    /// The model's name, as in its file (`double_pendulum`).
    fn name(&self) -> &'static str;
    /// One-line description from the model file.
    fn description(&self) -> &'static str;
    /// Names of the generalized coordinates `q`, in order.
    fn coordinate_names(&self) -> [&'static str; N];
    /// Names of the parameters, in file order.
    fn parameter_names(&self) -> &'static [&'static str];
    /// Current parameter values, in the order of [`Self::parameter_names`].
    fn parameter_values(&self) -> Vec<f64>;
    /// Sets parameter `name` to `value`.
    ///
    /// # Errors
    /// [`UnknownParameter`] if the model has no such parameter.
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter>;
    /// Initial state `(q(0), q̇(0))` from the file's `initial:` block, evaluated with the
    /// current parameter values (unlisted coordinates and rates start at 0).
    fn initial_state(&self) -> (SVector<f64, N>, SVector<f64, N>);

    /// Mass matrix `M(q, t)`, `N × N`, symmetric and (for a well-posed model) positive definite.
    fn mass_matrix(&self, q: &SVector<f64, N>, t: f64) -> SMatrix<f64, N, N>;
    /// Forcing `F(q, q̇, t)`: everything in `M q̈ = F` that is not inertia times `q̈`.
    fn forcing(&self, q: &SVector<f64, N>, qdot: &SVector<f64, N>, t: f64) -> SVector<f64, N>;
    /// `M` and `F` together, sharing subexpressions (the hot path of every integrator).
    fn mass_matrix_and_forcing(
        &self,
        q: &SVector<f64, N>,
        qdot: &SVector<f64, N>,
        t: f64,
    ) -> (SMatrix<f64, N, N>, SVector<f64, N>);
    /// Exact Jacobian `∂F/∂q`, `N × N` (entry `(i, j)` is `∂Fᵢ/∂qⱼ`).
    fn forcing_jacobian_q(
        &self,
        q: &SVector<f64, N>,
        qdot: &SVector<f64, N>,
        t: f64,
    ) -> SMatrix<f64, N, N>;
    /// Exact Jacobian `∂F/∂q̇`, `N × N`.
    fn forcing_jacobian_qdot(
        &self,
        q: &SVector<f64, N>,
        qdot: &SVector<f64, N>,
        t: f64,
    ) -> SMatrix<f64, N, N>;
    /// Exact `∂(M(q, t) a)/∂q` for a fixed vector `a`, `N × N` (entry `(i, k)` is
    /// `Σⱼ ∂Mᵢⱼ/∂qₖ aⱼ`), so that the Jacobian of `q̈ = M⁻¹F` is
    /// `M⁻¹(∂F/∂q − ∂(M a)/∂q)` at `a = q̈`.
    fn mass_matrix_product_jacobian(
        &self,
        q: &SVector<f64, N>,
        t: f64,
        a: &SVector<f64, N>,
    ) -> SMatrix<f64, N, N>;
    /// Kinetic energy `T(q, q̇, t)` (J).
    fn kinetic_energy(&self, q: &SVector<f64, N>, qdot: &SVector<f64, N>, t: f64) -> f64;
    /// Potential energy `V(q, t)` (J) of gravity and springs, plus the file's `potential`.
    fn potential_energy(&self, q: &SVector<f64, N>, t: f64) -> f64;
    /// Whether every load is conservative and nothing depends explicitly on `t`, so that
    /// `T + V` is a constant of the motion.
    fn is_conservative(&self) -> bool;
    /// Names of the model's points, in file order (empty for the energy form).
    fn point_names(&self) -> &'static [&'static str];
    /// Positions of the points (m), `[x, y, z]` with `z = 0` for 2-D models, written into
    /// `out` (length `point_names().len()`).
    fn point_positions(&self, q: &SVector<f64, N>, t: f64, out: &mut [[f64; 3]]);
    /// The file's `draw: lines`: segments between named points (names from
    /// [`Self::point_names`]), in file order; empty by default.
    fn draw_lines(&self) -> &'static [[&'static str; 2]] {
        &[]
    }
    /// The file's `draw: trace`: points whose trajectories are traced, in file order; empty by
    /// default.
    fn trace_points(&self) -> &'static [&'static str] {
        &[]
    }
    /// Where each body of the kinematic form sits: its centre of mass (a rigid body's `com`,
    /// a particle's `at`), in file order; empty for the energy form.
    fn body_centres(&self) -> &'static [BodyCentre<'static>] {
        &[]
    }
    /// The derived equations as plain text (`M`, `F`, `T`, `V`).
    fn equations_text(&self) -> &'static str;
    /// The derived equations as LaTeX.
    fn equations_latex(&self) -> &'static str;

    /// Names of the constraints, holonomic (`constraints:`) first, then non-holonomic
    /// (`nonholonomic:`); `m` of them, none for an unconstrained model (the default).
    ///
    /// With constraints, the equations of motion are the index-1 DAE
    /// `[M Jᵀ; J 0][q̈; λ] = [F; γ]` (lectures 8–11), so `M q̈ = F − Jᵀλ`: `λᵢ` is the
    /// generalized force of constraint `i` along `−∇Φᵢ` — for a rod written
    /// `Φ = |r_A − r_B| − ℓ`, its tension in N, positive in tension.
    fn constraint_names(&self) -> &'static [&'static str] {
        &[]
    }
    /// How many of [`Self::constraint_names`] are holonomic (they come first).
    fn holonomic_constraint_count(&self) -> usize {
        0
    }
    /// `Φ(q, t)` of the holonomic constraints, written into `out` (length
    /// [`Self::holonomic_constraint_count`]); units of the file's expressions.
    fn constraint_residuals(&self, q: &SVector<f64, N>, t: f64, out: &mut [f64]) {
        let _ = (q, t, out);
    }
    /// The constraint Jacobian `J` (`m × N`, row-major into `out`): `∂Φ/∂q` rows, then the
    /// rows `A(q, t)` of the non-holonomic constraints `A q̇ + b = 0`.
    fn constraint_jacobian(&self, q: &SVector<f64, N>, t: f64, out: &mut [f64]) {
        let _ = (q, t, out);
    }
    /// Velocity-level residuals (length `m`): `Φ̇ = J q̇ + Φ_t`, then `A q̇ + b`; zero on the
    /// constraint manifold.
    fn constraint_velocity_residuals(
        &self,
        q: &SVector<f64, N>,
        qdot: &SVector<f64, N>,
        t: f64,
        out: &mut [f64],
    ) {
        let _ = (q, qdot, t, out);
    }
    /// `γ` (length `m`) of `J q̈ = γ`: `−(J q̇)_q q̇ − 2 J_t q̇ − Φ_tt` for holonomic rows and
    /// `−(Ȧ q̇ + ḃ)` for non-holonomic rows.
    fn constraint_gamma(
        &self,
        q: &SVector<f64, N>,
        qdot: &SVector<f64, N>,
        t: f64,
        out: &mut [f64],
    ) {
        let _ = (q, qdot, t, out);
    }
    /// Indices of the coordinates whose initial values are guesses (`{ guess: … }` in the
    /// file), to be solved with their rates from the constraints.
    fn initial_guesses(&self) -> &'static [usize] {
        &[]
    }

    /// The model file's `equilibria:` names, in file order (issue 7; lecture 25); empty by
    /// default.
    fn equilibrium_names(&self) -> &'static [&'static str] {
        &[]
    }

    /// The guesses of [`Self::equilibrium_names`], `N` coordinates each, one after the other
    /// (`out` has `N · equilibrium_names().len()` entries).
    fn equilibrium_guesses(&self, out: &mut [f64]) {
        let _ = out;
    }

    /// The model file's `events:` (issue 6, item 2; lecture 17, HW21, HW36): names,
    /// directions and whether each ends the integration, in file order; empty by default.
    fn event_specs(&self) -> &'static [EventSpec] {
        &[]
    }

    /// Whether an event function uses the accelerations `q̈` or the constraint forces `λ`
    /// (then [`FirstOrder`](crate::FirstOrder) solves for them before calling [`Self::event_values`]).
    fn events_need_accelerations(&self) -> bool {
        false
    }

    /// The event functions `gᵢ(q, q̇, q̈, λ, t)` into `out` (one per [`Self::event_specs`]
    /// entry).
    ///
    /// # Shapes
    /// `qddot`: `N` (zeros unless [`Self::events_need_accelerations`]); `lambda`: the `m`
    /// constraint forces (see [`Self::constraint_names`]; empty unless needed, and a function
    /// that reads a missing one gets NaN); `out`: one entry per event.
    fn event_values(
        &self,
        q: &SVector<f64, N>,
        qdot: &SVector<f64, N>,
        t: f64,
        qddot: &SVector<f64, N>,
        lambda: &[f64],
        out: &mut [f64],
    ) {
        let _ = (q, qdot, t, qddot, lambda, out);
    }
}
