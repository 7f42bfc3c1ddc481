//! The first-order forms `y = [q; q̇]`, `ẏ = [q̇; q̈]` that integrators take: [`FirstOrder`] of a
//! [`MechanicalSystem<N>`] compiled by `eomgen::model!` (stack vectors and matrices, size
//! known at compile time) and [`DynFirstOrder`] of a [`DynMechanicalSystem`] compiled at run
//! time, with the same solves in the same operation order.

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

use crate::constrained::{ConstraintWorkspace, Stabilization};
use crate::dynamic::{DynMechanicalSystem, StaticSystem};
use crate::linalg::{solve_spd, solve_spd_in_place};
use crate::model_info::{FirstOrderForm, FirstOrderParts};
use crate::ode::{EventSpec, OdeSystem, RhsError};
use crate::system::MechanicalSystem;
use crate::taylor::{TaylorFunctions, TaylorUnsupported, TaylorWorkspace};

/// The first-order form `y = [q; q̇]`, `ẏ = [q̇; M⁻¹F]` of a [`MechanicalSystem`].
///
/// `M q̈ = F` is solved at every evaluation by [`solve_spd`] (in closed form for one or two
/// degrees of freedom, else an `L D Lᵀ` factorisation); a mass matrix that is not
/// positive definite is [`RhsError::SingularMassMatrix`], a non-finite `q̈` is
/// [`RhsError::NonFinite`]. No heap allocation.
///
/// With constraints ([`ModelDescription::constraints`](crate::ModelDescription::constraints) not empty), `q̈` and the
/// multipliers `λ` come from the index-1 system `[M Jᵀ; J 0][q̈; λ] = [F; γ]` instead, solved by
/// LU with partial pivoting on buffers allocated in [`FirstOrder::new`]; the drift control is
/// [`FirstOrder::stabilization`].
///
/// Its [`OdeSystem`] (right-hand side, Jacobian, events) is its own, on stack vectors and
/// matrices of size `N`; its size-erased [`ModelInfo`](crate::ModelInfo) is the one written
/// once for both first-order forms, reaching the system through an internal adapter to
/// [`DynMechanicalSystem`].
#[derive(Debug, Clone)]
pub struct FirstOrder<S, const N: usize> {
    /// The wrapped system.
    pub system: S,
    /// Drift control of a constrained system (ignored without constraints).
    pub stabilization: Stabilization,
    /// Buffers and the last multipliers `λ` of a constrained system.
    pub constraints: ConstraintWorkspace,
    /// The model's events ([`ModelDescription::events`](crate::ModelDescription::events)), whose `terminal` flags may be
    /// changed ([`ModelInfo::set_event_terminal`](crate::ModelInfo::set_event_terminal)).
    pub events: Vec<EventSpec>,
    /// Buffers of the Taylor series ([`crate::taylor`]), allocated on first use.
    taylor: TaylorWorkspace,
    /// Whether the state is in generalized speeds (`y = [q; u]`, `q̇` from
    /// [`MechanicalSystem::coordinate_rates`]).
    speeds: bool,
}

impl<S: MechanicalSystem<N>, const N: usize> FirstOrder<S, N> {
    /// Wraps `system`.
    pub fn new(system: S) -> Self {
        let description = system.description();
        // The description names the `N` coordinates the compiled functions take (a
        // hand-written model built from `ModelDescription::EMPTY` must list them too).
        debug_assert_eq!(description.num_dofs(), N, "the description's coordinates");
        let m = description.constraints.len();
        let holonomic = description.holonomic_constraints;
        let events = description.events.to_vec();
        let speeds = description.has_speeds();
        Self {
            system,
            stabilization: Stabilization::None,
            constraints: ConstraintWorkspace::new(N, m, holonomic),
            events,
            taylor: TaylorWorkspace::new(),
            speeds,
        }
    }

    /// Generalized accelerations `q̈ = M⁻¹F` at `(q, q̇, t)`.
    ///
    /// # Errors
    /// [`RhsError::SingularMassMatrix`] if `M` is not positive definite, [`RhsError::NonFinite`]
    /// if `q̈` has a NaN or infinite component (index counted in `y`, so `N + i`).
    // Always inlined: it is the whole of `rhs` for an unconstrained model, and LLVM's
    // heuristics otherwise flip with unrelated changes to the generated code around it (left
    // out of line, the double pendulum's `rhs` took 14 % longer, 27 → 31 ns; criterion `rhs`).
    #[inline(always)]
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
                return Err(RhsError::JacobianNonFinite { row: N + i });
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
        if self.speeds {
            let rates = self.system.coordinate_rates(&q, &qdot, t);
            dy[..N].copy_from_slice(rates.as_slice());
            if let Some(i) = rates.iter().position(|v| !v.is_finite()) {
                return Err(RhsError::NonFinite { index: i });
            }
        } else {
            dy[..N].copy_from_slice(qdot.as_slice());
        }
        dy[N..2 * N].copy_from_slice(qdd.as_slice());
        Ok(())
    }

    /// Only a constrained model projected after each step ([`Stabilization::Projection`]).
    fn corrects_state(&self) -> bool {
        !self.constraints.is_empty() && self.stabilization == Stabilization::Projection
    }

    fn after_step(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RhsError> {
        if !self.corrects_state() {
            return Ok(false);
        }
        let (q, qdot) = y.split_at_mut(N);
        self.constraints
            .project(
                StaticSystem::from_ref(&self.system),
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
    /// In generalized speeds the upper block row is
    /// [`MechanicalSystem::coordinate_rates_jacobian`], `[∂q̇/∂q  W]`.
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
        if self.speeds {
            let (rates_q, rates_u) = self.system.coordinate_rates_jacobian(&q, &qdot, t);
            coordinate_rate_rows(N, rates_q.as_slice(), rates_u.as_slice(), jac)?;
        }
        Ok(true)
    }

    fn second_order_dim(&self) -> Option<usize> {
        (!self.speeds).then_some(N)
    }

    fn event_specs(&self) -> &[EventSpec] {
        &self.events
    }

    fn taylor_support(&self) -> Result<(), crate::taylor::TaylorUnsupported> {
        taylor_support(StaticSystem::from_ref(&self.system), self.stabilization).map(|_| ())
    }

    fn taylor_coefficients(
        &mut self,
        t: f64,
        y: &[f64],
        order: usize,
        out: &mut [f64],
    ) -> Result<(), RhsError> {
        let system = StaticSystem::from_ref(&self.system);
        let stabilization = self.stabilization;
        taylor_coefficients(system, stabilization, &mut self.taylor, t, y, order, out)
    }

    fn taylor_branch_step(&self, order: usize, h: f64) -> f64 {
        let system = StaticSystem::from_ref(&self.system);
        taylor_branch_step(system, self.stabilization, &self.taylor, order, h)
    }

    fn event_values(&mut self, t: f64, y: &[f64], g: &mut [f64]) -> Result<(), RhsError> {
        if self.events.is_empty() {
            return Ok(());
        }
        let (q, qdot) = split::<N>(y);
        if !self.system.description().events_need_accelerations {
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

impl<S: MechanicalSystem<N>, const N: usize> FirstOrderForm for FirstOrder<S, N> {
    type System = StaticSystem<S, N>;
    fn dyn_system(&self) -> &StaticSystem<S, N> {
        StaticSystem::from_ref(&self.system)
    }
    fn parts_mut(&mut self) -> FirstOrderParts<'_, StaticSystem<S, N>> {
        FirstOrderParts {
            system: StaticSystem::from_mut(&mut self.system),
            stabilization: &mut self.stabilization,
            constraints: &mut self.constraints,
            events: &mut self.events,
        }
    }
}

/// The first-order form `y = [q; q̇]`, `ẏ = [q̇; q̈]` of a [`DynMechanicalSystem`]: what
/// [`FirstOrder`] is for a [`MechanicalSystem<N>`],
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
    /// ([`ModelInfo::set_event_terminal`](crate::ModelInfo::set_event_terminal)).
    pub events: Vec<EventSpec>,
    n: usize,
    taylor: TaylorWorkspace,
    mass: Vec<f64>,
    forcing: Vec<f64>,
    spd: Vec<f64>,
    /// The envelope indices of `solve_spd_in_place` (`2n`).
    envelope: Vec<usize>,
    zeros: Vec<f64>,
    /// Whether the state is in generalized speeds (`y = [q; u]`).
    speeds: bool,
}

impl<S: DynMechanicalSystem> DynFirstOrder<S> {
    /// Wraps `system`.
    pub fn new(system: S) -> Self {
        let n = system.num_dofs();
        let description = system.description();
        let m = description.constraints.len();
        let holonomic = description.holonomic_constraints;
        let events = description.events.to_vec();
        let speeds = description.has_speeds();
        Self {
            system,
            stabilization: Stabilization::None,
            constraints: ConstraintWorkspace::new(n, m, holonomic),
            events,
            n,
            mass: vec![0.0; n * n],
            forcing: vec![0.0; n],
            spd: vec![0.0; n * n + 2 * n],
            envelope: vec![0; 2 * n],
            zeros: vec![0.0; n],
            taylor: TaylorWorkspace::new(),
            speeds,
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
            solve_spd_in_place(
                n,
                &self.mass,
                &mut self.forcing,
                &mut self.spd,
                &mut self.envelope,
            )
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
                return Err(RhsError::JacobianNonFinite { row: n + i });
            }
        }
        Ok((d_qdd_q, d_qdd_qdot))
    }
}

impl<S: DynMechanicalSystem> DynFirstOrder<S> {
    /// Every right-hand side but a sound fused one: in speeds, constrained, of a system
    /// without the fused form, or where the fused form's verdict failed (computed again by
    /// `M` and `F`, then the solve, to the same bits, for the error it reports).
    #[inline(never)]
    fn rhs_unfused(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        if self.speeds {
            return self.rhs_in_speeds(t, y, dy);
        }
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

    /// The right-hand side of an unconstrained system of `N = n` degrees of freedom, as
    /// `FirstOrder::rhs` computes it: `M` and `F`, then the solve.
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

impl<S: DynMechanicalSystem> DynFirstOrder<S> {
    /// The right-hand side `ẏ = [q̇; u̇]` of a model in generalized speeds: `q̇` from the
    /// kinematic equations ([`DynMechanicalSystem::coordinate_rates`]), `u̇` from `M u̇ = F`,
    /// or beside non-holonomic constraints (their rows the auxiliary speeds, `J = [0 I]`) from
    /// the constraints' index-1 system, as in the rates.
    fn rhs_in_speeds(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let n = self.n;
        let (q, u) = (&y[..n], &y[n..2 * n]);
        let (rates, acceleration) = dy.split_at_mut(n);
        self.generalized_accelerations(q, u, t, acceleration)?;
        self.system.coordinate_rates(q, u, t, rates);
        match rates.iter().position(|v| !v.is_finite()) {
            Some(i) => Err(RhsError::NonFinite { index: i }),
            None => Ok(()),
        }
    }
}

/// Writes the upper block row `[∂q̇/∂q  ∂q̇/∂u]` of a first-order Jacobian (`jac`, `2n × 2n`
/// column-major) from the kinematic equations' Jacobians (`n × n` column-major each).
///
/// # Errors
/// [`RhsError::JacobianNonFinite`] naming the first row with an entry that is not finite
/// (at a singularity of the speeds' kinematic equations, such as gimbal lock).
fn coordinate_rate_rows(
    n: usize,
    rates_q: &[f64],
    rates_u: &[f64],
    jac: &mut [f64],
) -> Result<(), RhsError> {
    let dim = 2 * n;
    for j in 0..n {
        for i in 0..n {
            jac[i + j * dim] = rates_q[i + j * n];
            jac[i + (n + j) * dim] = rates_u[i + j * n];
        }
    }
    let bad = (0..n).find(|&i| {
        (0..n).any(|j| !(rates_q[i + j * n].is_finite() && rates_u[i + j * n].is_finite()))
    });
    match bad {
        Some(row) => Err(RhsError::JacobianNonFinite { row }),
        None => Ok(()),
    }
}

impl<S: DynMechanicalSystem> OdeSystem for DynFirstOrder<S> {
    fn dim(&self) -> usize {
        2 * self.n
    }

    /// The fused form where the system has it ([`DynMechanicalSystem::first_order_rhs`]) and
    /// its verdict is sound; otherwise every other form, out of line, so that the fused call's
    /// frame is small (with every form in one function it saved six registers and reserved
    /// 200 bytes of stack a call).
    #[inline]
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        if !self.speeds
            && self.constraints.is_empty()
            && self.system.first_order_rhs(t, y, dy) == Some(true)
        {
            return Ok(());
        }
        self.rhs_unfused(t, y, dy)
    }

    /// Only a constrained model projected after each step ([`Stabilization::Projection`]).
    fn corrects_state(&self) -> bool {
        !self.constraints.is_empty() && self.stabilization == Stabilization::Projection
    }

    fn after_step(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RhsError> {
        if !self.corrects_state() {
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
    /// [`FirstOrder`]'s; `Ok(false)` for a constrained system.
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
        if self.speeds {
            let (mut rates_q, mut rates_u) = (vec![0.0; n * n], vec![0.0; n * n]);
            self.system.coordinate_rates_jacobian(
                &y[..n],
                &y[n..2 * n],
                t,
                &mut rates_q,
                &mut rates_u,
            );
            coordinate_rate_rows(n, &rates_q, &rates_u, jac)?;
        }
        Ok(true)
    }

    fn second_order_dim(&self) -> Option<usize> {
        (!self.speeds).then_some(self.n)
    }

    fn event_specs(&self) -> &[EventSpec] {
        &self.events
    }

    fn taylor_support(&self) -> Result<(), crate::taylor::TaylorUnsupported> {
        taylor_support(&self.system, self.stabilization).map(|_| ())
    }

    fn taylor_coefficients(
        &mut self,
        t: f64,
        y: &[f64],
        order: usize,
        out: &mut [f64],
    ) -> Result<(), RhsError> {
        let stabilization = self.stabilization;
        taylor_coefficients(
            &self.system,
            stabilization,
            &mut self.taylor,
            t,
            y,
            order,
            out,
        )
    }

    fn taylor_branch_step(&self, order: usize, h: f64) -> f64 {
        taylor_branch_step(&self.system, self.stabilization, &self.taylor, order, h)
    }

    fn event_values(&mut self, t: f64, y: &[f64], g: &mut [f64]) -> Result<(), RhsError> {
        if self.events.is_empty() {
            return Ok(());
        }
        let n = self.n;
        let (q, qdot) = (&y[..n], &y[n..2 * n]);
        if !self.system.description().events_need_accelerations {
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

impl<S: DynMechanicalSystem> FirstOrderForm for DynFirstOrder<S> {
    type System = S;
    fn dyn_system(&self) -> &S {
        &self.system
    }
    fn parts_mut(&mut self) -> FirstOrderParts<'_, S> {
        FirstOrderParts {
            system: &mut self.system,
            stabilization: &mut self.stabilization,
            constraints: &mut self.constraints,
            events: &mut self.events,
        }
    }
}

/// [`OdeSystem::taylor_support`](crate::OdeSystem::taylor_support) of a first-order form:
/// the system's Taylor method. With constraints its series are those of the index-1 system
/// `[M Jᵀ; J 0][q̈; λ] = [F; γ]`: the drift is left as it is ([`Stabilization::None`]) or
/// projected away after each step ([`Stabilization::Projection`]); Baumgarte's terms and the
/// penalty's springs are refused, not in the recurrences.
fn taylor_support<S: DynMechanicalSystem + ?Sized>(
    system: &S,
    stabilization: Stabilization,
) -> Result<&dyn TaylorFunctions, TaylorUnsupported> {
    // The stabilization first: the model's description (a dynamic call) is read only when
    // the stabilization has terms the recurrences lack (this runs once or twice a step: for
    // the series, and for the branch check of a model that has branch points).
    if !matches!(
        stabilization,
        Stabilization::None | Stabilization::Projection
    ) && !system.description().constraints.is_empty()
    {
        return Err(TaylorUnsupported::Stabilization {
            name: std::borrow::Cow::Borrowed(stabilization.name()),
        });
    }
    system.taylor()
}

/// [`OdeSystem::taylor_coefficients`](crate::OdeSystem::taylor_coefficients) of a first-order
/// form.
fn taylor_coefficients<S: DynMechanicalSystem + ?Sized>(
    system: &S,
    stabilization: Stabilization,
    workspace: &mut TaylorWorkspace,
    t: f64,
    y: &[f64],
    order: usize,
    out: &mut [f64],
) -> Result<(), RhsError> {
    let taylor =
        taylor_support(system, stabilization).map_err(|_| RhsError::NonFinite { index: 0 })?;
    crate::taylor::series_of_motion(taylor, workspace, t, y, order, out)
}

/// [`OdeSystem::taylor_branch_step`](crate::OdeSystem::taylor_branch_step) of a first-order
/// form.
fn taylor_branch_step<S: DynMechanicalSystem + ?Sized>(
    system: &S,
    stabilization: Stabilization,
    workspace: &TaylorWorkspace,
    order: usize,
    h: f64,
) -> f64 {
    // Most models have no op whose branch is checked (a root, a power with a constant
    // exponent, `asin`, `acos`): nothing to look up.
    if !workspace.has_branch_points() {
        return h;
    }
    match taylor_support(system, stabilization) {
        Ok(taylor) => crate::taylor::branch_step(taylor.program(), workspace, order, h),
        Err(_) => h,
    }
}
