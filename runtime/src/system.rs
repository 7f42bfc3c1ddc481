//! The interface between generated equations of motion and the runtime.
//!
//! [`MechanicalSystem`] is what `eomgen::model!` implements for every model file: the mass
//! matrix `M(q, t)`, the forcing `F(q, q̇, t)` of `M q̈ = F`, their exact Jacobians, energies and
//! point positions, all with compile-time sizes. Its first-order form is
//! [`FirstOrder`](crate::FirstOrder), which erases the size so that the CLI can hold any model
//! as a `Box<dyn ModelInfo>` ([`ModelInfo`](crate::ModelInfo)).

use nalgebra::{SMatrix, SVector};

use crate::taylor::{TaylorFunctions, TaylorUnsupported};

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

pub use eomgen_description::{BodyCentre, FrameSpec, ModelDescription, RotationSpec, Shape};

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
    /// Everything about the model that is not a function of the state: names of the
    /// coordinates (`N` of them), parameters and their defaults, points, constraints,
    /// equilibria, events, drawing and the derived equations as text. Generated code returns
    /// a `static`.
    fn description(&self) -> &ModelDescription;
    /// Current parameter values, in the order of [`ModelDescription::parameters`].
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
    /// Positions of the points (m), `[x, y, z]` with `z = 0` for 2-D models, written into
    /// `out` (length `description().points.len()`).
    fn point_positions(&self, q: &SVector<f64, N>, t: f64, out: &mut [[f64; 3]]);

    /// `Φ(q, t)` of the holonomic constraints, written into `out` (length
    /// [`ModelDescription::holonomic_constraints`]); units of the file's expressions.
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

    /// The guesses of [`ModelDescription::equilibria`], `N` coordinates each, one after the other
    /// (`out` has `N · description().equilibria.len()` entries).
    fn equilibrium_guesses(&self, out: &mut [f64]) {
        let _ = out;
    }

    /// The gaps `g(q, t)` (m) of the unilateral contacts ([`ModelDescription::contacts`],
    /// `m_c` of them), their rates `ġ = G q̇ + ∂g/∂t` (m/s), `γ` of `G q̈ = γ` (the closed
    /// contact's acceleration condition `g̈ = 0`, m/s²), `γ_T` of `T q̈ = γ_T` (a
    /// sticking contact's `v̇_t = 0`, m/s²; 0 without friction), then `v_s`, the speed of the
    /// surface's material along it (a belt's, m/s; the slip is `v_t = T q̇ − v_s`), into
    /// `out` (`5 m_c` entries). A contact is open while `g > 0` and strikes when `g` reaches 0 with `ġ < 0`
    /// (Pfeiffer & Glocker 1996, ch. 4).
    fn contact_gaps(&self, q: &SVector<f64, N>, qdot: &SVector<f64, N>, t: f64, out: &mut [f64]) {
        let _ = (q, qdot, t, out);
    }
    /// The contacts' Jacobian `G = ∂g/∂q` (`m_c × N`), then the rows `T` of their slips
    /// `v_t = T q̇ − v_s` (`m_c × N`; zeros for a frictionless contact), row-major into `out`
    /// (`2 m_c × N`): the rows of the impact law `M (q̇⁺ − q̇⁻) = Gᵀ Λ_N + Tᵀ Λ_T`
    /// ([`crate::hybrid::impact()`]).
    fn contact_jacobian(&self, q: &SVector<f64, N>, t: f64, out: &mut [f64]) {
        let _ = (q, t, out);
    }
    /// Each contact's coefficient of restitution `e ∈ [0, 1]` and of Coulomb friction
    /// `μ ≥ 0` (0 when frictionless) and its static coefficient `μ_s ≥ μ` (`μ` unless the file
    /// gives `static_friction:`), `[e₁, μ₁, μ_s1, e₂, …]` into `out` (`3 m_c` entries), at
    /// the model's parameters.
    fn contact_coefficients(&self, out: &mut [f64]) {
        let _ = out;
    }
    /// The values of each change of support ([`ModelDescription::supports`]), in contact
    /// order, into `out` (`eomgen_symbolic::model::elements::support::block_len(N)` each):
    /// the total mass, the ground's normal, the first moment of mass (before and after) and
    /// the landing foot with their Jacobians, the matrices `M(q⁺)` and `H` of the impact law
    /// `M(q⁺) q̇⁺ = H q̇⁻` and their derivatives, the relabelling `R(q)` and its Jacobian, and
    /// `when` ([`crate::hybrid::support`]).
    fn support_changes(&self, q: &SVector<f64, N>, t: f64, out: &mut [f64]) {
        let _ = (q, t, out);
    }

    /// The event functions `gᵢ(q, q̇, q̈, λ, t)` into `out` (one per [`ModelDescription::events`]
    /// entry).
    ///
    /// # Shapes
    /// `qddot`: `N` (zeros unless [`ModelDescription::events_need_accelerations`]); `lambda`: the `m`
    /// constraint forces (see [`ModelDescription::constraints`]; empty unless needed, and a function
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

    /// The coordinates' rates `q̇` from the state's second half: `q̇ = W(q, t) (u − Z(q, t))`
    /// for a model in generalized speeds ([`ModelDescription::speeds`]: `qdot` then holds the
    /// speeds `u`), the second half itself otherwise (the default).
    ///
    /// # Source
    /// The kinematic differential equations of Kane and Levinson, *Dynamics: Theory and
    /// Applications* (McGraw-Hill, 1985), §2.12.
    fn coordinate_rates(
        &self,
        q: &SVector<f64, N>,
        qdot: &SVector<f64, N>,
        t: f64,
    ) -> SVector<f64, N> {
        let _ = (q, t);
        *qdot
    }
    /// The exact Jacobians `(∂q̇/∂q, ∂q̇/∂u)` of [`Self::coordinate_rates`], `N × N` each
    /// (`∂q̇/∂u = W`); `(0, I)` for a model in the coordinates' rates (the default).
    fn coordinate_rates_jacobian(
        &self,
        q: &SVector<f64, N>,
        qdot: &SVector<f64, N>,
        t: f64,
    ) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>) {
        let _ = (q, qdot, t);
        (SMatrix::zeros(), SMatrix::identity())
    }

    /// The model's Taylor method ([`crate::taylor::TaylorFunctions`]: the recurrences of the
    /// Taylor series of `M q̈ = F` and the code that runs them), or why the model has none
    /// (constraints, a piecewise function). Generated by `model!`; a hand-written model has
    /// none unless it writes them.
    ///
    /// # Errors
    /// [`TaylorUnsupported`] naming what is missing.
    fn taylor(&self) -> Result<&dyn TaylorFunctions, TaylorUnsupported> {
        Err(TaylorUnsupported::NotGenerated)
    }
}
