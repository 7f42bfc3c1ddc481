//! The interface between generated equations of motion and the runtime.
//!
//! [`MechanicalSystem`] is what `eomgen::model!` implements for every model file: the mass
//! matrix `M(q, t)`, the forcing `F(q, q̇, t)` of `M q̈ = F`, their exact Jacobians, energies and
//! point positions, all with compile-time sizes. [`FirstOrder`] turns it into the first-order
//! system `y = [q; q̇]`, `ẏ = [q̇; M⁻¹F]` that integrators take, and erases the size so the CLI
//! can hold any model as a `Box<dyn ModelInfo>`.

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

use crate::constrained::{ConstraintWorkspace, ProjectionError, Stabilization, StaticSystem};
use crate::integrate::EventSpec;
use crate::ode::{OdeSystem, RhsError};

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
    /// (then [`FirstOrder`] solves for them before calling [`Self::event_values`]).
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

/// The first-order form `y = [q; q̇]`, `ẏ = [q̇; M⁻¹F]` of a [`MechanicalSystem`].
///
/// `M q̈ = F` is solved at every evaluation by [`solve_spd`] (in closed form for one or two
/// degrees of freedom, else an `L D Lᵀ` factorisation); a mass matrix that is not
/// positive definite is [`RhsError::SingularMassMatrix`], a non-finite `q̈` is
/// [`RhsError::NonFinite`]. No heap allocation.
///
/// With constraints ([`MechanicalSystem::constraint_names`] not empty), `q̈` and the
/// multipliers `λ` come from the index-1 system `[M Jᵀ; J 0][q̈; λ] = [F; γ]` instead, solved by
/// LU with partial pivoting on buffers allocated in [`FirstOrder::new`]; the drift control is
/// [`FirstOrder::stabilization`].
#[derive(Debug, Clone)]
pub struct FirstOrder<S, const N: usize> {
    /// The wrapped system.
    pub system: S,
    /// Drift control of a constrained system (ignored without constraints).
    pub stabilization: Stabilization,
    /// Buffers and the last multipliers `λ` of a constrained system.
    pub constraints: ConstraintWorkspace,
    /// The model's events ([`MechanicalSystem::event_specs`]), whose `terminal` flags may be
    /// changed ([`ModelInfo::set_event_terminal`]).
    pub events: Vec<EventSpec>,
}

impl<S: MechanicalSystem<N>, const N: usize> FirstOrder<S, N> {
    /// Wraps `system`.
    pub fn new(system: S) -> Self {
        let m = system.constraint_names().len();
        let holonomic = system.holonomic_constraint_count();
        let events = system.event_specs().to_vec();
        Self {
            system,
            stabilization: Stabilization::None,
            constraints: ConstraintWorkspace::new(N, m, holonomic),
            events,
        }
    }

    /// Generalized accelerations `q̈ = M⁻¹F` at `(q, q̇, t)`.
    ///
    /// # Errors
    /// [`RhsError::SingularMassMatrix`] if `M` is not positive definite, [`RhsError::NonFinite`]
    /// if `q̈` has a NaN or infinite component (index counted in `y`, so `N + i`).
    pub fn generalized_accelerations(
        &self,
        q: &SVector<f64, N>,
        qdot: &SVector<f64, N>,
        t: f64,
    ) -> Result<SVector<f64, N>, RhsError> {
        let (m, f) = self.system.mass_matrix_and_forcing(q, qdot, t);
        let qdd = solve_spd(&m, &f).ok_or(RhsError::SingularMassMatrix)?;
        if let Some(i) = qdd.iter().position(|v| !v.is_finite()) {
            return Err(RhsError::NonFinite { index: N + i });
        }
        Ok(qdd)
    }

    /// The Jacobians `(∂q̈/∂q, ∂q̈/∂q̇)` of `q̈ = M⁻¹F` at `(q, q̇, t)`, from the generated exact
    /// derivatives.
    ///
    /// Differentiating `M(q, t) q̈ = F(q, q̇, t)` at fixed `t`:
    ///
    /// ```text
    /// ∂q̈/∂q = M⁻¹ (∂F/∂q − ∂(M a)/∂q |_(a = q̈)),     ∂q̈/∂q̇ = M⁻¹ ∂F/∂q̇
    /// ```
    ///
    /// where `∂(M a)/∂q` is [`MechanicalSystem::mass_matrix_product_jacobian`] (the derivative of
    /// `M(q) a` with `a` held fixed). One Cholesky factorisation serves `q̈` and both solves;
    /// no heap allocation.
    ///
    /// # Shapes
    /// Both matrices are `N × N`; entry `(i, j)` of the first is `∂q̈ᵢ/∂qⱼ`.
    ///
    /// # Errors
    /// [`RhsError::SingularMassMatrix`] if `M` is not positive definite; [`RhsError::NonFinite`]
    /// if `q̈` or an entry of the Jacobians is not finite (index `N + i` for row `i`).
    pub fn acceleration_jacobians(
        &self,
        q: &SVector<f64, N>,
        qdot: &SVector<f64, N>,
        t: f64,
    ) -> Result<(SMatrix<f64, N, N>, SMatrix<f64, N, N>), RhsError> {
        let (m, f) = self.system.mass_matrix_and_forcing(q, qdot, t);
        let chol = nalgebra::Cholesky::new(m).ok_or(RhsError::SingularMassMatrix)?;
        let qdd = chol.solve(&f);
        let d_forcing_q = self.system.forcing_jacobian_q(q, qdot, t)
            - self.system.mass_matrix_product_jacobian(q, t, &qdd);
        let d_qdd_q = chol.solve(&d_forcing_q);
        let d_qdd_qdot = chol.solve(&self.system.forcing_jacobian_qdot(q, qdot, t));
        if let Some(i) = qdd.iter().position(|v| !v.is_finite()) {
            return Err(RhsError::NonFinite { index: N + i });
        }
        for matrix in [&d_qdd_q, &d_qdd_qdot] {
            let bad = matrix
                .row_iter()
                .position(|row| row.iter().any(|v| !v.is_finite()));
            if let Some(i) = bad {
                return Err(RhsError::NonFinite { index: N + i });
            }
        }
        Ok((d_qdd_q, d_qdd_qdot))
    }
}

/// Solves `M x = f` for a symmetric positive definite `M` (`N × N`, lower triangle read) by
/// the square-root-free factorisation `M = L D Lᵀ` (`L` unit lower triangular, `D` diagonal;
/// Golub & Van Loan, *Matrix Computations*, 4th ed., §4.1.2), the hot path of every
/// unconstrained right-hand side ([`FirstOrder::rhs`](crate::OdeSystem::rhs)).
///
/// Returns `None` when a pivot `dⱼ` is not positive (or is NaN): `M` is not positive definite.
/// Like Cholesky, it needs no pivoting for a positive definite `M` and is backward stable;
/// unlike nalgebra's Cholesky it takes no square roots and one division per column (the
/// reciprocal pivots are reused), which on the double pendulum shortened the dependency chain
/// of `q̈ = M⁻¹F` from two square roots and five divisions to two divisions.
///
/// One and two degrees of freedom are solved in closed form instead: `x = f/m`, and for
/// `M = [a b; b c]` Cramer's rule `x = [c f₀ − b f₁, a f₁ − b f₀] / (a c − b²)`, positive
/// definite exactly when `a > 0` and `a c − b² > 0` (Sylvester's criterion). Its determinant
/// is the product `a · d₁` of the two pivots above, so it is as accurate, but the two
/// numerators are formed while the one division runs, where the factorisation divides twice
/// in sequence; an integration waits for each right-hand side before the next stage can
/// start, and this shorter chain made a DOP853 run of the double pendulum ~4 % faster.
pub fn solve_spd<const N: usize>(
    m: &SMatrix<f64, N, N>,
    f: &SVector<f64, N>,
) -> Option<SVector<f64, N>> {
    match N {
        1 => {
            let a = m[(0, 0)];
            // Not positive, or NaN.
            return (a > 0.0).then(|| f / a);
        }
        2 => {
            let (a, b, c) = (m[(0, 0)], m[(1, 0)], m[(1, 1)]);
            let det = a * c - b * b;
            // Not positive definite, or NaN.
            if a.is_nan() || a <= 0.0 || det.is_nan() || det <= 0.0 {
                return None;
            }
            let inverse = 1.0 / det;
            let mut x = *f;
            x[0] = (c * f[0] - b * f[1]) * inverse;
            x[1] = (a * f[1] - b * f[0]) * inverse;
            return Some(x);
        }
        _ => {}
    }
    let mut l = [[0.0f64; N]; N];
    let mut inv_d = [0.0f64; N];
    let mut d = [0.0f64; N];
    for j in 0..N {
        let mut dj = m[(j, j)];
        for k in 0..j {
            dj -= l[j][k] * l[j][k] * d[k];
        }
        // Not positive, or NaN.
        if dj.is_nan() || dj <= 0.0 {
            return None;
        }
        d[j] = dj;
        inv_d[j] = 1.0 / dj;
        for i in j + 1..N {
            let mut v = m[(i, j)];
            for k in 0..j {
                v -= l[i][k] * l[j][k] * d[k];
            }
            l[i][j] = v * inv_d[j];
        }
    }
    let mut x = *f;
    for i in 0..N {
        for k in 0..i {
            x[i] -= l[i][k] * x[k];
        }
    }
    for i in 0..N {
        x[i] *= inv_d[i];
    }
    for i in (0..N).rev() {
        for k in i + 1..N {
            x[i] -= l[k][i] * x[k];
        }
    }
    Some(x)
}

/// [`solve_spd`] for a size known at run time: solves `M x = f` in place (`f` becomes `x`)
/// for a symmetric positive definite `M` (`n × n`, column-major, lower triangle read), with
/// the same closed forms for `n = 1, 2` and the same `L D Lᵀ` factorisation in the same
/// operation order, so the two agree to the bit; `work` holds at least `n² + 2n` values.
/// No heap allocation.
///
/// `solve_spd` keeps its own copy with stack arrays and a compile-time `N`, which the
/// compiler unrolls for the hot path of the compiled models (`benches/rhs.rs`).
///
/// Returns `None` when `M` is not positive definite (a pivot is not positive, or is NaN).
///
/// # Panics
/// If `mass` has fewer than `n²` entries, `f` fewer than `n` or `work` fewer than `n² + 2n`.
pub fn solve_spd_in_place(n: usize, mass: &[f64], f: &mut [f64], work: &mut [f64]) -> Option<()> {
    let m = |i: usize, j: usize| mass[i + j * n];
    match n {
        1 => {
            let a = m(0, 0);
            // Not positive, or NaN.
            if a.is_nan() || a <= 0.0 {
                return None;
            }
            f[0] /= a;
            return Some(());
        }
        2 => {
            let (a, b, c) = (m(0, 0), m(1, 0), m(1, 1));
            let det = a * c - b * b;
            // Not positive definite, or NaN.
            if a.is_nan() || a <= 0.0 || det.is_nan() || det <= 0.0 {
                return None;
            }
            let inverse = 1.0 / det;
            let (f0, f1) = (f[0], f[1]);
            f[0] = (c * f0 - b * f1) * inverse;
            f[1] = (a * f1 - b * f0) * inverse;
            return Some(());
        }
        _ => {}
    }
    let (l, rest) = work.split_at_mut(n * n);
    let (d, inv_d) = rest.split_at_mut(n);
    // `l[i][k]` of `solve_spd` is `l[i * n + k]`.
    for j in 0..n {
        let mut dj = m(j, j);
        for k in 0..j {
            dj -= l[j * n + k] * l[j * n + k] * d[k];
        }
        // Not positive, or NaN.
        if dj.is_nan() || dj <= 0.0 {
            return None;
        }
        d[j] = dj;
        inv_d[j] = 1.0 / dj;
        for i in j + 1..n {
            let mut v = m(i, j);
            for k in 0..j {
                v -= l[i * n + k] * l[j * n + k] * d[k];
            }
            l[i * n + j] = v * inv_d[j];
        }
    }
    for i in 0..n {
        for k in 0..i {
            f[i] -= l[i * n + k] * f[k];
        }
    }
    for i in 0..n {
        f[i] *= inv_d[i];
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            f[i] -= l[k * n + i] * f[k];
        }
    }
    Some(())
}

fn split<const N: usize>(y: &[f64]) -> (SVector<f64, N>, SVector<f64, N>) {
    (
        SVector::<f64, N>::from_column_slice(&y[..N]),
        SVector::<f64, N>::from_column_slice(&y[N..2 * N]),
    )
}

impl<S: MechanicalSystem<N>, const N: usize> OdeSystem for FirstOrder<S, N> {
    fn dim(&self) -> usize {
        2 * N
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let (q, qdot) = split::<N>(y);
        let qdd = if self.constraints.is_empty() {
            self.generalized_accelerations(&q, &qdot, t)?
        } else {
            let qdd =
                self.constraints
                    .accelerations(&self.system, &q, &qdot, t, self.stabilization)?;
            if let Some(i) = qdd.iter().position(|v| !v.is_finite()) {
                return Err(RhsError::NonFinite { index: N + i });
            }
            qdd
        };
        dy[..N].copy_from_slice(qdot.as_slice());
        dy[N..2 * N].copy_from_slice(qdd.as_slice());
        Ok(())
    }

    fn after_step(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RhsError> {
        if self.constraints.is_empty() || self.stabilization != Stabilization::Projection {
            return Ok(false);
        }
        let (q, qdot) = y.split_at_mut(N);
        self.constraints
            .project(
                &StaticSystem(&self.system),
                q,
                &mut qdot[..N],
                t,
                &[],
                1e-12,
            )
            .map_err(|e| RhsError::ProjectionFailed {
                residual: e.residual,
            })?;
        Ok(true)
    }

    /// The exact Jacobian of `ẏ = [q̇; q̈]`, from [`FirstOrder::acceleration_jacobians`]:
    ///
    /// ```text
    /// ∂F/∂y = [ 0        I       ]
    ///         [ ∂q̈/∂q    ∂q̈/∂q̇   ]
    /// ```
    ///
    /// A constrained system returns `Ok(false)`: its `q̈` comes from the KKT system, whose
    /// derivative needs `∂J/∂q` and `∂γ/∂(q, q̇)`, which are not generated; the implicit
    /// methods then difference `F`.
    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        if !self.constraints.is_empty() {
            return Ok(false);
        }
        let (q, qdot) = split::<N>(y);
        let (d_q, d_qdot) = self.acceleration_jacobians(&q, &qdot, t)?;
        let dim = 2 * N;
        jac[..dim * dim].fill(0.0);
        for j in 0..N {
            // Column N + j of the upper block row: ∂q̇ᵢ/∂q̇ⱼ = δᵢⱼ.
            jac[j + (N + j) * dim] = 1.0;
            for i in 0..N {
                jac[N + i + j * dim] = d_q[(i, j)];
                jac[N + i + (N + j) * dim] = d_qdot[(i, j)];
            }
        }
        Ok(true)
    }

    fn second_order_dim(&self) -> Option<usize> {
        Some(N)
    }

    fn event_specs(&self) -> &[EventSpec] {
        &self.events
    }

    fn event_values(&mut self, t: f64, y: &[f64], g: &mut [f64]) -> Result<(), RhsError> {
        if self.events.is_empty() {
            return Ok(());
        }
        let (q, qdot) = split::<N>(y);
        if !self.system.events_need_accelerations() {
            let zero = SVector::<f64, N>::zeros();
            self.system.event_values(&q, &qdot, t, &zero, &[], g);
            return Ok(());
        }
        if self.constraints.is_empty() {
            let qdd = self.generalized_accelerations(&q, &qdot, t)?;
            self.system.event_values(&q, &qdot, t, &qdd, &[], g);
        } else {
            let qdd =
                self.constraints
                    .accelerations(&self.system, &q, &qdot, t, self.stabilization)?;
            self.system
                .event_values(&q, &qdot, t, &qdd, &self.constraints.multipliers, g);
        }
        Ok(())
    }
}

/// A model with its size erased, as the CLI holds it: `Box<dyn ModelInfo>`.
///
/// Implemented by [`FirstOrder`] for every model compiled by `eomgen::model!` and by
/// [`DynFirstOrder`](crate::DynFirstOrder) for a model compiled at run time; names are
/// borrowed from the model (which owns them in the second case).
///
/// Vectors here are runtime-sized; `y = [q; q̇]` has length `2 num_dofs()`.
pub trait ModelInfo: OdeSystem {
    /// The model's name.
    fn name(&self) -> &str;
    /// One-line description.
    fn description(&self) -> &str;
    /// Number of degrees of freedom `n`.
    fn num_dofs(&self) -> usize;
    /// Names of the generalized coordinates (length `n`).
    fn coordinate_names(&self) -> Vec<&str>;
    /// Parameter names, in file order.
    fn parameter_names(&self) -> Vec<&str>;
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
    /// Whether `T + V` is a constant of the motion.
    fn is_conservative(&self) -> bool;
    /// Names of the model's points.
    fn point_names(&self) -> Vec<&str>;
    /// Positions of the points at `(t, y)`, `[x, y, z]` each (m).
    fn point_positions(&self, t: f64, y: &[f64]) -> Vec<[f64; 3]>;
    /// The `draw: lines` segments as pairs of point names ([`MechanicalSystem::draw_lines`]).
    fn draw_lines(&self) -> Vec<[&str; 2]>;
    /// The `draw: trace` point names ([`MechanicalSystem::trace_points`]).
    fn trace_points(&self) -> Vec<&str>;
    /// The bodies' centres of mass ([`MechanicalSystem::body_centres`]).
    fn body_centres(&self) -> Vec<BodyCentre<'_>>;
    /// The derived equations as text.
    fn equations_text(&self) -> &str;
    /// The derived equations as LaTeX.
    fn equations_latex(&self) -> &str;
    /// Upcast to the first-order system for an integrator.
    fn as_ode_mut(&mut self) -> &mut dyn OdeSystem;
    /// `M` (`n × n`) and `F` (`n`) at `(t, y)`.
    fn mass_matrix_and_forcing(&self, t: f64, y: &[f64]) -> (DMatrix<f64>, DVector<f64>);
    /// The exact Jacobians `(∂F/∂q, ∂F/∂q̇)`, each `n × n`, at `(t, y)`.
    fn forcing_jacobians(&self, t: f64, y: &[f64]) -> (DMatrix<f64>, DMatrix<f64>);
    /// The exact `∂(M a)/∂q` (`n × n`) at `(t, q)` for the vector `a` (length `n`).
    fn mass_matrix_product_jacobian(&self, t: f64, y: &[f64], a: &[f64]) -> DMatrix<f64>;
    /// Names of the constraints (holonomic first); empty for an unconstrained model.
    fn constraint_names(&self) -> Vec<&str>;
    /// How many constraints are holonomic.
    fn holonomic_constraint_count(&self) -> usize;
    /// Selects the drift control of a constrained model.
    fn set_stabilization(&mut self, stabilization: Stabilization);
    /// The constraint forces `λ` (length `m`; see [`MechanicalSystem::constraint_names`] for
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
    /// Indices of the coordinates whose initial values are guesses.
    fn initial_guesses(&self) -> &[usize];
    /// The model's named equilibrium guesses `(name, q)` ([`MechanicalSystem::equilibrium_names`]).
    fn equilibrium_guesses(&self) -> Vec<(&str, Vec<f64>)>;
    /// Makes the model event `name` terminal or not (`eomgen simulate --stop-when NAME`);
    /// returns `false` if the model has no event `name`.
    fn set_event_terminal(&mut self, name: &str, terminal: bool) -> bool;
    /// `Φ` (length `m_h`), `J` (`m × n`), the velocity residuals and `γ` (length `m`) at
    /// `(t, y)`; see [`MechanicalSystem::constraint_jacobian`] and siblings.
    fn constraint_equations(&self, t: f64, y: &[f64]) -> ConstraintValues;
    /// Makes `y = [q; q̇]` (at `t = 0`) consistent with the constraints (issue 5, item 3): the
    /// coordinates marked `{ guess: … }` and their rates are solved by Newton from
    /// `Φ(q, 0) = 0` and the velocity constraints, the others held. Without guesses, `y` must
    /// already satisfy the constraints to 1e-9. Nothing to do without constraints.
    ///
    /// # Errors
    /// [`ProjectionError`] naming the constraint with the largest residual: Newton did not
    /// converge, or (without guesses, `iterations` = 0) the given state violates it.
    fn make_consistent(&mut self, y: &mut [f64]) -> Result<(), ProjectionError> {
        if self.constraint_names().is_empty() {
            return Ok(());
        }
        let guesses = self.initial_guesses().to_vec();
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
            .fold((0, 0.0f64), |best, x| if x.1 > best.1 { x } else { best });
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

impl<S: MechanicalSystem<N>, const N: usize> ModelInfo for FirstOrder<S, N> {
    fn name(&self) -> &str {
        self.system.name()
    }
    fn description(&self) -> &str {
        self.system.description()
    }
    fn num_dofs(&self) -> usize {
        N
    }
    fn coordinate_names(&self) -> Vec<&str> {
        self.system.coordinate_names().to_vec()
    }
    fn parameter_names(&self) -> Vec<&str> {
        self.system.parameter_names().to_vec()
    }
    fn parameter_values(&self) -> Vec<f64> {
        self.system.parameter_values()
    }
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter> {
        self.system.set_parameter(name, value)
    }
    fn initial_state(&self) -> Vec<f64> {
        let (q, qdot) = self.system.initial_state();
        q.iter().chain(qdot.iter()).copied().collect()
    }
    fn kinetic_energy(&self, t: f64, y: &[f64]) -> f64 {
        let (q, qdot) = split::<N>(y);
        self.system.kinetic_energy(&q, &qdot, t)
    }
    fn potential_energy(&self, t: f64, y: &[f64]) -> f64 {
        let (q, _) = split::<N>(y);
        self.system.potential_energy(&q, t)
    }
    fn is_conservative(&self) -> bool {
        self.system.is_conservative()
    }
    fn point_names(&self) -> Vec<&str> {
        self.system.point_names().to_vec()
    }
    fn point_positions(&self, t: f64, y: &[f64]) -> Vec<[f64; 3]> {
        let (q, _) = split::<N>(y);
        let mut out = vec![[0.0; 3]; self.system.point_names().len()];
        self.system.point_positions(&q, t, &mut out);
        out
    }
    fn draw_lines(&self) -> Vec<[&str; 2]> {
        self.system.draw_lines().to_vec()
    }
    fn trace_points(&self) -> Vec<&str> {
        self.system.trace_points().to_vec()
    }
    fn body_centres(&self) -> Vec<BodyCentre<'_>> {
        self.system.body_centres().to_vec()
    }
    fn equations_text(&self) -> &str {
        self.system.equations_text()
    }
    fn equations_latex(&self) -> &str {
        self.system.equations_latex()
    }
    fn as_ode_mut(&mut self) -> &mut dyn OdeSystem {
        self
    }
    fn mass_matrix_and_forcing(&self, t: f64, y: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
        let (q, qdot) = split::<N>(y);
        let (m, f) = self.system.mass_matrix_and_forcing(&q, &qdot, t);
        (
            DMatrix::from_column_slice(N, N, m.as_slice()),
            DVector::from_column_slice(f.as_slice()),
        )
    }
    fn forcing_jacobians(&self, t: f64, y: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
        let (q, qdot) = split::<N>(y);
        let jq = self.system.forcing_jacobian_q(&q, &qdot, t);
        let jqd = self.system.forcing_jacobian_qdot(&q, &qdot, t);
        (
            DMatrix::from_column_slice(N, N, jq.as_slice()),
            DMatrix::from_column_slice(N, N, jqd.as_slice()),
        )
    }
    fn mass_matrix_product_jacobian(&self, t: f64, y: &[f64], a: &[f64]) -> DMatrix<f64> {
        let (q, _) = split::<N>(y);
        let a = SVector::<f64, N>::from_column_slice(&a[..N]);
        let j = self.system.mass_matrix_product_jacobian(&q, t, &a);
        DMatrix::from_column_slice(N, N, j.as_slice())
    }
    fn constraint_names(&self) -> Vec<&str> {
        self.system.constraint_names().to_vec()
    }
    fn holonomic_constraint_count(&self) -> usize {
        self.system.holonomic_constraint_count()
    }
    fn set_stabilization(&mut self, stabilization: Stabilization) {
        self.stabilization = stabilization;
    }
    fn constraint_forces(&mut self, t: f64, y: &[f64]) -> Result<Vec<f64>, RhsError> {
        if self.constraints.is_empty() {
            return Ok(Vec::new());
        }
        let (q, qdot) = split::<N>(y);
        self.constraints
            .accelerations(&self.system, &q, &qdot, t, self.stabilization)?;
        Ok(self.constraints.multipliers.clone())
    }
    fn constraint_drift(&mut self, t: f64, y: &[f64]) -> (f64, f64) {
        self.constraints
            .drift(&StaticSystem(&self.system), &y[..N], &y[N..2 * N], t)
    }
    fn project(&mut self, t: f64, y: &mut [f64], free: &[usize]) -> Result<usize, ProjectionError> {
        // On a copy, so that a projection that fails leaves `y` as it was.
        let mut projected = y[..2 * N].to_vec();
        let (q, qdot) = projected.split_at_mut(N);
        let iterations =
            self.constraints
                .project(&StaticSystem(&self.system), q, qdot, t, free, 1e-12)?;
        y[..2 * N].copy_from_slice(&projected);
        Ok(iterations)
    }
    fn initial_guesses(&self) -> &[usize] {
        self.system.initial_guesses()
    }
    fn equilibrium_guesses(&self) -> Vec<(&str, Vec<f64>)> {
        let names = self.system.equilibrium_names();
        let mut values = vec![0.0; N * names.len()];
        self.system.equilibrium_guesses(&mut values);
        names
            .iter()
            .zip(values.chunks(N.max(1)))
            .map(|(name, q)| (*name, q.to_vec()))
            .collect()
    }
    fn set_event_terminal(&mut self, name: &str, terminal: bool) -> bool {
        match self.events.iter_mut().find(|e| e.name == name) {
            Some(e) => {
                e.terminal = terminal;
                true
            }
            None => false,
        }
    }
    fn constraint_equations(&self, t: f64, y: &[f64]) -> ConstraintValues {
        let (q, qdot) = split::<N>(y);
        let m = self.system.constraint_names().len();
        let h = self.system.holonomic_constraint_count();
        let mut phi = vec![0.0; h];
        let mut jacobian = vec![0.0; m * N];
        let mut velocity = vec![0.0; m];
        let mut gamma = vec![0.0; m];
        self.system.constraint_residuals(&q, t, &mut phi);
        self.system.constraint_jacobian(&q, t, &mut jacobian);
        self.system
            .constraint_velocity_residuals(&q, &qdot, t, &mut velocity);
        self.system.constraint_gamma(&q, &qdot, t, &mut gamma);
        ConstraintValues {
            phi: DVector::from_vec(phi),
            jacobian: DMatrix::from_row_slice(m, N, &jacobian),
            velocity: DVector::from_vec(velocity),
            gamma: DVector::from_vec(gamma),
        }
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

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

    use super::*;

    /// The closed forms for 1 × 1 and 2 × 2 against nalgebra's Cholesky solve, well and badly
    /// conditioned (κ ≈ 4e8): both are backward stable, so they agree to a few ulps of κ, and
    /// the residual is within a few ulps of κ |f|; `None` for indefinite, singular, negative
    /// and NaN matrices.
    #[test]
    fn solve_spd_closed_forms_match_cholesky_and_refuse_what_is_not_positive_definite() {
        for (m, f) in [
            (Matrix2::new(2.3, -0.7, -0.7, 0.9), Vector2::new(0.4, -1.1)),
            (
                Matrix2::new(1.0, 0.99999999, 0.99999999, 1.0),
                Vector2::new(1.0, 2.0),
            ),
        ] {
            let x = solve_spd(&m, &f).unwrap();
            let expected = nalgebra::Cholesky::new(m).unwrap().solve(&f);
            let condition = m.norm() * m.try_inverse().unwrap().norm();
            assert!(
                (x - expected).amax() <= 8.0 * f64::EPSILON * condition * expected.amax(),
                "{x} vs {expected}"
            );
            assert!(
                (m * x - f).amax() <= 16.0 * f64::EPSILON * f.amax() * condition,
                "residual"
            );
        }
        for bad in [
            Matrix2::new(1.0, 2.0, 2.0, 1.0),
            Matrix2::new(1.0, 1.0, 1.0, 1.0),
            Matrix2::new(-1.0, 0.0, 0.0, -1.0),
            Matrix2::new(f64::NAN, 0.0, 0.0, 1.0),
            Matrix2::new(1.0, 0.0, 0.0, f64::NAN),
        ] {
            assert_eq!(solve_spd(&bad, &Vector2::new(1.0, 1.0)), None, "{bad}");
        }
        let one = nalgebra::Matrix1::new(4.0);
        assert_eq!(
            solve_spd(&one, &nalgebra::Vector1::new(2.0)),
            Some(nalgebra::Vector1::new(0.5))
        );
        for bad in [0.0, -1.0, f64::NAN] {
            let m = nalgebra::Matrix1::new(bad);
            assert_eq!(solve_spd(&m, &nalgebra::Vector1::new(1.0)), None);
        }
    }

    /// `solve_spd` (the `L D Lᵀ` path) against nalgebra's Cholesky solve on a positive
    /// definite `M = BᵀB + I` (condition ~10): the two backward-stable solves agree to a few
    /// ulps of `|x|`, so 1e-13 relative; and `None` for an indefinite, a singular and a NaN
    /// matrix.
    #[test]
    fn solve_spd_matches_cholesky_and_refuses_what_is_not_positive_definite() {
        let b = Matrix3::new(1.0, 0.3, -0.7, 0.2, 1.5, 0.4, -0.6, 0.1, 0.9);
        let m = b.transpose() * b + Matrix3::identity();
        let f = Vector3::new(0.7, -1.3, 2.1);
        let x = solve_spd(&m, &f).unwrap();
        let expected = nalgebra::Cholesky::new(m).unwrap().solve(&f);
        assert!(
            (x - expected).amax() <= 1e-13 * expected.amax(),
            "{x} vs {expected}"
        );
        let indefinite = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert_eq!(solve_spd(&indefinite, &f), None);
        let singular = Matrix3::new(1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert_eq!(solve_spd(&singular, &f), None);
        let mut nan = m;
        nan[(1, 1)] = f64::NAN;
        assert_eq!(solve_spd(&nan, &f), None);
    }
}
