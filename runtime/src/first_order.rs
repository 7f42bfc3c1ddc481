//! The first-order forms `y = [q; q̇]`, `ẏ = [q̇; q̈]` that integrators take: [`FirstOrder`] of a
//! [`MechanicalSystem<N>`] compiled by `eomgen::model!` (stack vectors and matrices, size
//! known at compile time) and [`DynFirstOrder`] of a [`DynMechanicalSystem`] compiled at run
//! time, with the same solves in the same operation order.

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

use crate::constrained::{ConstraintWorkspace, ProjectionError, Stabilization, StaticSystem};
use crate::dynamic::DynMechanicalSystem;
use crate::linalg::{solve_spd, solve_spd_in_place};
use crate::model_info::{ConstraintValues, ModelInfo};
use crate::ode::{EventSpec, OdeSystem, RhsError};
use crate::system::{BodyCentre, MechanicalSystem, UnknownParameter};

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

/// The first-order form `y = [q; q̇]`, `ẏ = [q̇; q̈]` of a [`DynMechanicalSystem`]: what
/// [`FirstOrder`](crate::FirstOrder) is for a [`MechanicalSystem<N>`](crate::MechanicalSystem),
/// with the same solves in the same operation order, so that the same equations give the
/// same bits either way.
///
/// `M q̈ = F` is solved by [`solve_spd_in_place`] (closed forms for one and two degrees of
/// freedom, else `L D Lᵀ`); with constraints, `q̈` and `λ` come from `[M Jᵀ; J 0][q̈; λ] = [F; γ]`
/// ([`ConstraintWorkspace`]), with the drift control [`DynFirstOrder::stabilization`]. Every
/// buffer is allocated in [`DynFirstOrder::new`]: an evaluation of the right-hand side
/// allocates nothing.
#[derive(Debug, Clone)]
pub struct DynFirstOrder<S> {
    /// The wrapped system.
    pub system: S,
    /// Drift control of a constrained system (ignored without constraints).
    pub stabilization: Stabilization,
    /// Buffers and the last multipliers `λ` of a constrained system.
    pub constraints: ConstraintWorkspace,
    /// The model's events, whose `terminal` flags may be changed
    /// ([`ModelInfo::set_event_terminal`]).
    pub events: Vec<EventSpec>,
    n: usize,
    mass: Vec<f64>,
    forcing: Vec<f64>,
    spd: Vec<f64>,
    zeros: Vec<f64>,
}

impl<S: DynMechanicalSystem> DynFirstOrder<S> {
    /// Wraps `system`.
    pub fn new(system: S) -> Self {
        let n = system.num_dofs();
        let m = system.constraint_names().len();
        let holonomic = system.holonomic_constraint_count();
        let events = system.event_specs();
        Self {
            system,
            stabilization: Stabilization::None,
            constraints: ConstraintWorkspace::new(n, m, holonomic),
            events,
            n,
            mass: vec![0.0; n * n],
            forcing: vec![0.0; n],
            spd: vec![0.0; n * n + 2 * n],
            zeros: vec![0.0; n],
        }
    }

    /// Generalized accelerations `q̈` at `(q, q̇, t)` into `qddot` (length `n`): `M⁻¹F`, or the
    /// constrained solve.
    ///
    /// # Errors
    /// [`RhsError::SingularMassMatrix`] if `M` is not positive definite,
    /// [`RhsError::SingularConstraintMatrix`] for a singular KKT matrix, and
    /// [`RhsError::NonFinite`] if `q̈` has a NaN or infinite component (index counted in
    /// `y`, so `n + i`).
    pub fn generalized_accelerations(
        &mut self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        qddot: &mut [f64],
    ) -> Result<(), RhsError> {
        let n = self.n;
        if self.constraints.is_empty() {
            self.system
                .mass_matrix_and_forcing(q, qdot, t, &mut self.mass, &mut self.forcing);
            solve_spd_in_place(n, &self.mass, &mut self.forcing, &mut self.spd)
                .ok_or(RhsError::SingularMassMatrix)?;
            qddot[..n].copy_from_slice(&self.forcing);
        } else {
            self.constraints.accelerations_into(
                &self.system,
                q,
                qdot,
                t,
                self.stabilization,
                qddot,
            )?;
        }
        match qddot[..n].iter().position(|v| !v.is_finite()) {
            Some(i) => Err(RhsError::NonFinite { index: n + i }),
            None => Ok(()),
        }
    }

    /// The Jacobians `(∂q̈/∂q, ∂q̈/∂q̇)` (each `n × n`) of `q̈ = M⁻¹F` at `(q, q̇, t)`, as
    /// [`FirstOrder::acceleration_jacobians`](crate::FirstOrder::acceleration_jacobians)
    /// computes them: `M⁻¹ (∂F/∂q − ∂(M a)/∂q |_(a = q̈))` and `M⁻¹ ∂F/∂q̇`, with one Cholesky
    /// factorisation.
    ///
    /// # Errors
    /// [`RhsError::SingularMassMatrix`] if `M` is not positive definite; [`RhsError::NonFinite`]
    /// if `q̈` or an entry of the Jacobians is not finite (index `n + i` for row `i`).
    pub fn acceleration_jacobians(
        &mut self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
    ) -> Result<(DMatrix<f64>, DMatrix<f64>), RhsError> {
        let n = self.n;
        self.system
            .mass_matrix_and_forcing(q, qdot, t, &mut self.mass, &mut self.forcing);
        let mass = DMatrix::from_column_slice(n, n, &self.mass);
        let chol = nalgebra::Cholesky::new(mass).ok_or(RhsError::SingularMassMatrix)?;
        let qdd = chol.solve(&DVector::from_column_slice(&self.forcing));
        let mut d_forcing_q = DMatrix::zeros(n, n);
        self.system
            .forcing_jacobian_q(q, qdot, t, d_forcing_q.as_mut_slice());
        let mut product = DMatrix::zeros(n, n);
        self.system
            .mass_matrix_product_jacobian(q, t, qdd.as_slice(), product.as_mut_slice());
        let d_qdd_q = chol.solve(&(d_forcing_q - product));
        let mut d_forcing_qdot = DMatrix::zeros(n, n);
        self.system
            .forcing_jacobian_qdot(q, qdot, t, d_forcing_qdot.as_mut_slice());
        let d_qdd_qdot = chol.solve(&d_forcing_qdot);
        if let Some(i) = qdd.iter().position(|v| !v.is_finite()) {
            return Err(RhsError::NonFinite { index: n + i });
        }
        for matrix in [&d_qdd_q, &d_qdd_qdot] {
            let bad = matrix
                .row_iter()
                .position(|row| row.iter().any(|v| !v.is_finite()));
            if let Some(i) = bad {
                return Err(RhsError::NonFinite { index: n + i });
            }
        }
        Ok((d_qdd_q, d_qdd_qdot))
    }
}

impl<S: DynMechanicalSystem> DynFirstOrder<S> {
    /// The right-hand side of an unconstrained system of `N = n` degrees of freedom, as
    /// `FirstOrder::rhs` computes it.
    fn unconstrained_rhs<const N: usize>(
        &mut self,
        t: f64,
        y: &[f64],
        dy: &mut [f64],
    ) -> Result<(), RhsError> {
        let mut mass = SMatrix::<f64, N, N>::zeros();
        let mut forcing = SVector::<f64, N>::zeros();
        self.system.mass_matrix_and_forcing(
            &y[..N],
            &y[N..2 * N],
            t,
            mass.as_mut_slice(),
            forcing.as_mut_slice(),
        );
        let qdd = solve_spd(&mass, &forcing).ok_or(RhsError::SingularMassMatrix)?;
        if let Some(i) = qdd.iter().position(|v| !v.is_finite()) {
            return Err(RhsError::NonFinite { index: N + i });
        }
        dy[..N].copy_from_slice(&y[N..2 * N]);
        dy[N..2 * N].copy_from_slice(qdd.as_slice());
        Ok(())
    }
}

impl<S: DynMechanicalSystem> OdeSystem for DynFirstOrder<S> {
    fn dim(&self) -> usize {
        2 * self.n
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        if self.constraints.is_empty() {
            // The sizes of most mechanisms, with the matrices on the stack and the solve of
            // `FirstOrder` (the same operations as `solve_spd_in_place`): on the double
            // pendulum this path is ~6 ns shorter than the general one (`benches/runtime_model.rs`).
            match self.n {
                1 => return self.unconstrained_rhs::<1>(t, y, dy),
                2 => return self.unconstrained_rhs::<2>(t, y, dy),
                3 => return self.unconstrained_rhs::<3>(t, y, dy),
                4 => return self.unconstrained_rhs::<4>(t, y, dy),
                _ => {}
            }
        }
        let n = self.n;
        let (q, qdot) = (&y[..n], &y[n..2 * n]);
        let (velocity, acceleration) = dy.split_at_mut(n);
        self.generalized_accelerations(q, qdot, t, acceleration)?;
        velocity.copy_from_slice(qdot);
        Ok(())
    }

    fn after_step(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RhsError> {
        if self.constraints.is_empty() || self.stabilization != Stabilization::Projection {
            return Ok(false);
        }
        let n = self.n;
        let (q, qdot) = y.split_at_mut(n);
        self.constraints
            .project(&self.system, q, &mut qdot[..n], t, &[], 1e-12)
            .map_err(|e| RhsError::ProjectionFailed {
                residual: e.residual,
            })?;
        Ok(true)
    }

    /// The exact Jacobian of `ẏ = [q̇; q̈]`, as
    /// [`FirstOrder`](crate::FirstOrder)'s; `Ok(false)` for a constrained system.
    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        if !self.constraints.is_empty() {
            return Ok(false);
        }
        let n = self.n;
        let (d_q, d_qdot) = self.acceleration_jacobians(&y[..n], &y[n..2 * n], t)?;
        let dim = 2 * n;
        jac[..dim * dim].fill(0.0);
        for j in 0..n {
            // Column n + j of the upper block row: ∂q̇ᵢ/∂q̇ⱼ = δᵢⱼ.
            jac[j + (n + j) * dim] = 1.0;
            for i in 0..n {
                jac[n + i + j * dim] = d_q[(i, j)];
                jac[n + i + (n + j) * dim] = d_qdot[(i, j)];
            }
        }
        Ok(true)
    }

    fn second_order_dim(&self) -> Option<usize> {
        Some(self.n)
    }

    fn event_specs(&self) -> &[EventSpec] {
        &self.events
    }

    fn event_values(&mut self, t: f64, y: &[f64], g: &mut [f64]) -> Result<(), RhsError> {
        if self.events.is_empty() {
            return Ok(());
        }
        let n = self.n;
        let (q, qdot) = (&y[..n], &y[n..2 * n]);
        if !self.system.events_need_accelerations() {
            self.system.event_values(q, qdot, t, &self.zeros, &[], g);
            return Ok(());
        }
        let mut qddot = std::mem::take(&mut self.zeros);
        let result = self.generalized_accelerations(q, qdot, t, &mut qddot);
        if result.is_ok() {
            let lambda: &[f64] = if self.constraints.is_empty() {
                &[]
            } else {
                &self.constraints.multipliers
            };
            self.system.event_values(q, qdot, t, &qddot, lambda, g);
        }
        qddot.fill(0.0);
        self.zeros = qddot;
        result
    }
}

impl<S: DynMechanicalSystem> ModelInfo for DynFirstOrder<S> {
    fn name(&self) -> &str {
        self.system.name()
    }
    fn description(&self) -> &str {
        self.system.description()
    }
    fn num_dofs(&self) -> usize {
        self.n
    }
    fn coordinate_names(&self) -> Vec<&str> {
        self.system.coordinate_names()
    }
    fn parameter_names(&self) -> Vec<&str> {
        self.system.parameter_names()
    }
    fn parameter_values(&self) -> Vec<f64> {
        self.system.parameter_values()
    }
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter> {
        self.system.set_parameter(name, value)
    }
    fn initial_state(&self) -> Vec<f64> {
        let n = self.n;
        let mut y = vec![0.0; 2 * n];
        let (q, qdot) = y.split_at_mut(n);
        self.system.initial_state(q, qdot);
        y
    }
    fn kinetic_energy(&self, t: f64, y: &[f64]) -> f64 {
        self.system
            .kinetic_energy(&y[..self.n], &y[self.n..2 * self.n], t)
    }
    fn potential_energy(&self, t: f64, y: &[f64]) -> f64 {
        self.system.potential_energy(&y[..self.n], t)
    }
    fn is_conservative(&self) -> bool {
        self.system.is_conservative()
    }
    fn point_names(&self) -> Vec<&str> {
        self.system.point_names()
    }
    fn point_positions(&self, t: f64, y: &[f64]) -> Vec<[f64; 3]> {
        let mut out = vec![[0.0; 3]; self.system.point_names().len()];
        self.system.point_positions(&y[..self.n], t, &mut out);
        out
    }
    fn draw_lines(&self) -> Vec<[&str; 2]> {
        self.system.draw_lines()
    }
    fn trace_points(&self) -> Vec<&str> {
        self.system.trace_points()
    }
    fn body_centres(&self) -> Vec<BodyCentre<'_>> {
        self.system.body_centres()
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
        let n = self.n;
        let (mut mass, mut forcing) = (DMatrix::zeros(n, n), DVector::zeros(n));
        self.system.mass_matrix_and_forcing(
            &y[..n],
            &y[n..2 * n],
            t,
            mass.as_mut_slice(),
            forcing.as_mut_slice(),
        );
        (mass, forcing)
    }
    fn forcing_jacobians(&self, t: f64, y: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
        let n = self.n;
        let (mut jq, mut jqd) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
        self.system
            .forcing_jacobian_q(&y[..n], &y[n..2 * n], t, jq.as_mut_slice());
        self.system
            .forcing_jacobian_qdot(&y[..n], &y[n..2 * n], t, jqd.as_mut_slice());
        (jq, jqd)
    }
    fn mass_matrix_product_jacobian(&self, t: f64, y: &[f64], a: &[f64]) -> DMatrix<f64> {
        let n = self.n;
        let mut out = DMatrix::zeros(n, n);
        self.system
            .mass_matrix_product_jacobian(&y[..n], t, &a[..n], out.as_mut_slice());
        out
    }
    fn constraint_names(&self) -> Vec<&str> {
        self.system.constraint_names()
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
        let n = self.n;
        let mut qddot = vec![0.0; n];
        self.constraints.accelerations_into(
            &self.system,
            &y[..n],
            &y[n..2 * n],
            t,
            self.stabilization,
            &mut qddot,
        )?;
        Ok(self.constraints.multipliers.clone())
    }
    fn constraint_drift(&mut self, t: f64, y: &[f64]) -> (f64, f64) {
        let n = self.n;
        self.constraints
            .drift(&self.system, &y[..n], &y[n..2 * n], t)
    }
    fn project(&mut self, t: f64, y: &mut [f64], free: &[usize]) -> Result<usize, ProjectionError> {
        // On a copy, so that a projection that fails leaves `y` as it was.
        let n = self.n;
        let mut projected = y[..2 * n].to_vec();
        let (q, qdot) = projected.split_at_mut(n);
        let iterations = self
            .constraints
            .project(&self.system, q, qdot, t, free, 1e-12)?;
        y[..2 * n].copy_from_slice(&projected);
        Ok(iterations)
    }
    fn initial_guesses(&self) -> &[usize] {
        self.system.initial_guesses()
    }
    fn equilibrium_guesses(&self) -> Vec<(&str, Vec<f64>)> {
        let n = self.n;
        let names = self.system.equilibrium_names();
        let mut values = vec![0.0; n * names.len()];
        self.system.equilibrium_guesses(&mut values);
        names
            .into_iter()
            .zip(values.chunks(n.max(1)))
            .map(|(name, q)| (name, q.to_vec()))
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
        let n = self.n;
        let (q, qdot) = (&y[..n], &y[n..2 * n]);
        let m = self.system.constraint_names().len();
        let h = self.system.holonomic_constraint_count();
        let mut phi = vec![0.0; h];
        let mut jacobian = vec![0.0; m * n];
        let mut velocity = vec![0.0; m];
        let mut gamma = vec![0.0; m];
        if m > 0 {
            self.system.constraint_residuals(q, t, &mut phi);
            self.system.constraint_jacobian(q, t, &mut jacobian);
            self.system
                .constraint_velocity_residuals(q, qdot, t, &mut velocity);
            self.system.constraint_gamma(q, qdot, t, &mut gamma);
        }
        ConstraintValues {
            phi: DVector::from_vec(phi),
            jacobian: DMatrix::from_row_slice(m, n, &jacobian),
            velocity: DVector::from_vec(velocity),
            gamma: DVector::from_vec(gamma),
        }
    }
}
