//! Equations of motion whose size is known only at run time.
//!
//! [`DynMechanicalSystem`] is [`MechanicalSystem`](crate::MechanicalSystem) with slices in
//! place of nalgebra's static vectors and matrices: what a model compiled at run time (from any
//! model file, with no rebuild) implements. Its first-order form is
//! [`DynFirstOrder`](crate::DynFirstOrder), which implements [`ModelInfo`](crate::ModelInfo),
//! so every analysis that takes a `Box<dyn ModelInfo>` takes such a model unchanged.

use crate::ode::EventSpec;
use crate::system::{BodyCentre, UnknownParameter};

/// Equations of motion `M(q, t) q̈ = F(q, q̇, t)` of a mechanism with `n` degrees of freedom,
/// `n` known at run time.
///
/// Every method means what the method of the same name of
/// [`MechanicalSystem`](crate::MechanicalSystem) means; values are written into caller-owned
/// slices so that an evaluation allocates nothing.
///
/// # Shapes
/// `q`, `qdot`, `a`: length `n = num_dofs()`. Matrices (`mass`, the Jacobians): `n × n`,
/// **column-major** (nalgebra's storage order: entry `(i, j)` is `out[i + j n]`). Other outputs
/// as documented per method.
///
/// # Units
/// SI, angles in rad; `F` in N or N·m per coordinate; energies in J.
pub trait DynMechanicalSystem {
    /// The model's name, as in its file.
    fn name(&self) -> &str;
    /// One-line description from the model file.
    fn description(&self) -> &str;
    /// Number of degrees of freedom `n`.
    fn num_dofs(&self) -> usize;
    /// Names of the generalized coordinates `q`, in order (length `n`).
    fn coordinate_names(&self) -> Vec<&str>;
    /// Names of the parameters, in file order.
    fn parameter_names(&self) -> Vec<&str>;
    /// Current parameter values, in the order of [`Self::parameter_names`].
    fn parameter_values(&self) -> Vec<f64>;
    /// Sets parameter `name` to `value`.
    ///
    /// # Errors
    /// [`UnknownParameter`] if the model has no such parameter.
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter>;
    /// Initial state `q(0)`, `q̇(0)` from the file's `initial:` block, with the current
    /// parameter values, written into `q` and `qdot` (length `n` each).
    fn initial_state(&self, q: &mut [f64], qdot: &mut [f64]);

    /// `M(q, t)` (`n × n`, column-major) into `mass` and `F(q, q̇, t)` (length `n`) into
    /// `forcing`, sharing subexpressions (the hot path of every integrator). Every entry is
    /// written, both triangles of `M`: callers reuse their buffers.
    fn mass_matrix_and_forcing(
        &self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        mass: &mut [f64],
        forcing: &mut [f64],
    );
    /// Exact `∂F/∂q` (`n × n`, column-major; entry `(i, j)` is `∂Fᵢ/∂qⱼ`) into `out`.
    fn forcing_jacobian_q(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]);
    /// Exact `∂F/∂q̇` (`n × n`, column-major) into `out`.
    fn forcing_jacobian_qdot(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]);
    /// Exact `∂(M(q, t) a)/∂q` for a fixed `a` (`n × n`, column-major; entry `(i, k)` is
    /// `Σⱼ ∂Mᵢⱼ/∂qₖ aⱼ`) into `out`.
    fn mass_matrix_product_jacobian(&self, q: &[f64], t: f64, a: &[f64], out: &mut [f64]);
    /// Kinetic energy `T(q, q̇, t)` (J).
    fn kinetic_energy(&self, q: &[f64], qdot: &[f64], t: f64) -> f64;
    /// Potential energy `V(q, t)` (J).
    fn potential_energy(&self, q: &[f64], t: f64) -> f64;
    /// Whether `T + V` is a constant of the motion.
    fn is_conservative(&self) -> bool;
    /// Names of the model's points, in file order.
    fn point_names(&self) -> Vec<&str>;
    /// Positions of the points (m), `[x, y, z]` (`z = 0` for 2-D models), into `out` (length
    /// `point_names().len()`).
    fn point_positions(&self, q: &[f64], t: f64, out: &mut [[f64; 3]]);
    /// The file's `draw: lines` as pairs of point names.
    fn draw_lines(&self) -> Vec<[&str; 2]>;
    /// The file's `draw: trace` point names.
    fn trace_points(&self) -> Vec<&str>;
    /// The bodies' centres of mass.
    fn body_centres(&self) -> Vec<BodyCentre<'_>>;
    /// The derived equations as plain text.
    fn equations_text(&self) -> &str;
    /// The derived equations as LaTeX.
    fn equations_latex(&self) -> &str;

    /// Names of the constraints, holonomic first (`m` of them).
    fn constraint_names(&self) -> Vec<&str>;
    /// How many of [`Self::constraint_names`] are holonomic (they come first).
    fn holonomic_constraint_count(&self) -> usize;
    /// `Φ(q, t)` of the holonomic constraints into `out` (length
    /// [`Self::holonomic_constraint_count`]).
    fn constraint_residuals(&self, q: &[f64], t: f64, out: &mut [f64]);
    /// The constraint Jacobian `J` (`m × n`, **row-major**, as
    /// [`MechanicalSystem::constraint_jacobian`](crate::MechanicalSystem::constraint_jacobian))
    /// into `out`.
    fn constraint_jacobian(&self, q: &[f64], t: f64, out: &mut [f64]);
    /// Velocity-level residuals (length `m`) into `out`.
    fn constraint_velocity_residuals(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]);
    /// `γ` of `J q̈ = γ` (length `m`) into `out`.
    fn constraint_gamma(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]);
    /// Indices of the coordinates whose initial values are guesses.
    fn initial_guesses(&self) -> &[usize];
    /// The file's `equilibria:` names, in file order.
    fn equilibrium_names(&self) -> Vec<&str>;
    /// The guesses of [`Self::equilibrium_names`], `n` coordinates each, one after the other.
    fn equilibrium_guesses(&self, out: &mut [f64]);
    /// The file's `events:` (names, directions, terminal flags).
    fn event_specs(&self) -> Vec<EventSpec>;
    /// Whether an event function uses `q̈` or `λ`.
    fn events_need_accelerations(&self) -> bool;
    /// The event functions `gᵢ(q, q̇, q̈, λ, t)` into `out` (one per event); `lambda` may be
    /// shorter than `m` (a function that reads a missing multiplier gets NaN).
    fn event_values(
        &self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        qddot: &[f64],
        lambda: &[f64],
        out: &mut [f64],
    );
}
