//! Constrained equations of motion: the index-1 DAE `[M Jᵀ; J 0][q̈; λ] = [F; γ]`, drift
//! control, projection onto the constraint manifold and consistent initial states
//! (lectures 8–11 of the syllabus; HW10, HW12–HW14).
//!
//! Everything here works on buffers allocated once, in [`ConstraintWorkspace::new`], so an
//! evaluation of the right-hand side allocates nothing.

use nalgebra::SVector;

use crate::dynamic::{DynMechanicalSystem, StaticSystem};
use crate::linalg::solve_spd_in_place;
use crate::ode::RhsError;
use crate::system::MechanicalSystem;

/// How constraint drift is controlled during an integration (selectable per run).
///
/// The index-1 form `J q̈ = γ` only keeps `Φ̈ = 0`, so round-off and truncation errors make
/// `Φ` and `Φ̇` drift (HW10, HW12).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Stabilization {
    /// No control: the drift is shown as it is.
    #[default]
    None,
    /// Baumgarte's stabilisation (Baumgarte 1972, *Comput. Methods Appl. Mech. Eng.* 1):
    /// `Φ̈ + 2α Φ̇ + β² Φ = 0` replaces `Φ̈ = 0`, so the acceleration-level row becomes
    /// `J q̈ = γ − 2α Φ̇ − β² Φ` (non-holonomic rows: `γ − 2α (A q̇ + b)`). `α`, `β` in 1/s,
    /// finite and ≥ 0 ([`Stabilization::validate`]): the drift then decays as the motion of
    /// a damped oscillator of natural frequency `β` and damping ratio `α/β`.
    Baumgarte {
        /// Damping of the drift (1/s), finite and ≥ 0.
        alpha: f64,
        /// Stiffness of the drift (1/s), finite and ≥ 0.
        beta: f64,
    },
    /// Projection after every accepted step (Hairer, Lubich & Wanner, *Geometric Numerical
    /// Integration*, §IV.4; Eich 1993): `q` onto `Φ(q, t) = 0` by Gauss–Newton with the
    /// minimum-norm correction `Δq = −Jᵀ(J Jᵀ)⁻¹ Φ`, then `q̇` onto the velocity constraints
    /// by the minimum-norm correction of `J q̇ + Φ_t` (and `A q̇ + b`). The integrators call it
    /// through [`crate::OdeSystem::after_step`], which projects the step's samples too; a
    /// projected step restarts the method there (one more evaluation of `F`).
    Projection,
    /// Not a stabilisation of the DAE but method I of lectures 8–11 in its place: each
    /// holonomic constraint becomes a stiff spring and damper on `Φ`, `λ = k Φ + c Φ̇`
    /// (non-holonomic rows: `λ = c (A q̇ + b)`), and `M q̈ = F − Jᵀ λ` is an ODE again. The
    /// constraint holds only to `O(F/k)`, and the stiffness makes explicit methods take
    /// steps of order `√(m/k)` (HW9's large `k`, HW10's comparison).
    Penalty {
        /// Spring stiffness `k` on `Φ` (N/m for a length constraint).
        stiffness: f64,
        /// Damping `c` on `Φ̇` (N·s/m for a length constraint).
        damping: f64,
    },
}

/// Why a [`Stabilization`] cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StabilizationError {
    /// Baumgarte's `α` or `β` is negative or not finite. With `Φ̈ + 2α Φ̇ + β² Φ = 0` a
    /// negative `α` makes the drift grow as `e^{−αt}` (a residual of 8.4e34 over a short
    /// run), and a non-finite gain makes `γ̃` NaN; `β` enters squared, and is taken ≥ 0 as
    /// Baumgarte writes it.
    #[error(
        "Baumgarte's gains must be in [0, 1e6] (1/s; Φ̈ + 2α Φ̇ + β² Φ = 0, where a negative α makes the drift grow and β² overflows past 1e154), got α = {alpha}, β = {beta}"
    )]
    InvalidBaumgarteGains {
        /// The damping gain `α` given (1/s).
        alpha: f64,
        /// The stiffness gain `β` given (1/s).
        beta: f64,
    },
    /// The penalty's stiffness is not finite and positive, or its damping not finite and
    /// ≥ 0 (a negative spring pushes the constraint apart).
    #[error(
        "the constraint springs need a finite positive stiffness and a finite damping ≥ 0, got k = {stiffness}, c = {damping}"
    )]
    InvalidPenalty {
        /// The stiffness `k` given.
        stiffness: f64,
        /// The damping `c` given.
        damping: f64,
    },
}

/// The largest Baumgarte gain `α` or `β` (1/s): a drift time constant of a microsecond, far
/// below any step a run takes; beyond ~1e154, `β² Φ` overflows.
pub const MAX_BAUMGARTE_GAIN: f64 = 1e6;

impl Stabilization {
    /// The default Baumgarte gains `[α, β]` (1/s) of `--baumgarte` and of the constraint
    /// methods study: a drift decaying like a critically damped oscillator of 10 rad/s,
    /// fast against the motions of the bundled mechanisms (periods of about a second).
    pub const DEFAULT_BAUMGARTE_GAINS: [f64; 2] = [10.0, 10.0];

    /// The drift control's name without its gains, as `--stabilization` spells it: `"none"`,
    /// `"baumgarte"`, `"projection"` or `"penalty"`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Baumgarte { .. } => "baumgarte",
            Self::Projection => "projection",
            Self::Penalty { .. } => "penalty",
        }
    }

    /// Baumgarte's stabilisation with [`Self::DEFAULT_BAUMGARTE_GAINS`].
    pub const fn default_baumgarte() -> Self {
        let [alpha, beta] = Self::DEFAULT_BAUMGARTE_GAINS;
        Stabilization::Baumgarte { alpha, beta }
    }

    /// Checks the gains: Baumgarte's `α`, `β` in `[0, MAX_BAUMGARTE_GAIN]` (1/s); the
    /// penalty's stiffness finite and positive, its damping finite and ≥ 0.
    ///
    /// # Errors
    /// [`StabilizationError::InvalidBaumgarteGains`], [`StabilizationError::InvalidPenalty`].
    ///
    /// # Examples
    /// ```
    /// use eomgen_runtime::Stabilization;
    /// assert!(Stabilization::Baumgarte { alpha: 10.0, beta: 10.0 }.validate().is_ok());
    /// assert!(Stabilization::Baumgarte { alpha: 0.0, beta: 0.0 }.validate().is_ok());
    /// assert!(Stabilization::Baumgarte { alpha: -10.0, beta: 10.0 }.validate().is_err());
    /// assert!(Stabilization::Baumgarte { alpha: f64::NAN, beta: 1.0 }.validate().is_err());
    /// assert!(Stabilization::Baumgarte { alpha: 10.0, beta: 1e200 }.validate().is_err());
    /// ```
    pub fn validate(self) -> Result<(), StabilizationError> {
        let gain = |x: f64| x.is_finite() && x >= 0.0;
        let baumgarte = |x: f64| (0.0..=MAX_BAUMGARTE_GAIN).contains(&x);
        match self {
            Stabilization::Baumgarte { alpha, beta } if !(baumgarte(alpha) && baumgarte(beta)) => {
                Err(StabilizationError::InvalidBaumgarteGains { alpha, beta })
            }
            Stabilization::Penalty { stiffness, damping }
                if !(gain(stiffness) && stiffness > 0.0 && gain(damping)) =>
            {
                Err(StabilizationError::InvalidPenalty { stiffness, damping })
            }
            _ => Ok(()),
        }
    }
}

/// Scratch space of the constrained solve, sized for `n` coordinates and `m` constraints.
#[derive(Debug, Clone)]
pub struct ConstraintWorkspace {
    n: usize,
    m: usize,
    holonomic: usize,
    kkt: Vec<f64>,
    rhs: Vec<f64>,
    pivots: Vec<usize>,
    jacobian: Vec<f64>,
    gamma: Vec<f64>,
    velocity: Vec<f64>,
    phi: Vec<f64>,
    small: Vec<f64>,
    small_rhs: Vec<f64>,
    small_pivots: Vec<usize>,
    mass: Vec<f64>,
    forcing: Vec<f64>,
    spd: Vec<f64>,
    /// The envelope indices of `solve_spd_in_place` (`2n`).
    envelope: Vec<usize>,
    /// `λ` of the last solve (length `m`).
    pub multipliers: Vec<f64>,
}

impl ConstraintWorkspace {
    /// Buffers for `n` coordinates, `m` constraints of which the first `holonomic` are
    /// holonomic.
    pub fn new(n: usize, m: usize, holonomic: usize) -> Self {
        let k = n + m;
        Self {
            n,
            m,
            holonomic,
            kkt: vec![0.0; k * k],
            rhs: vec![0.0; k],
            pivots: vec![0; k],
            jacobian: vec![0.0; m * n],
            gamma: vec![0.0; m],
            velocity: vec![0.0; m],
            phi: vec![0.0; holonomic],
            small: vec![0.0; m * m],
            small_rhs: vec![0.0; m],
            small_pivots: vec![0; m],
            mass: vec![0.0; n * n],
            forcing: vec![0.0; n],
            spd: vec![0.0; n * n + 2 * n],
            envelope: vec![0; 2 * n],
            multipliers: vec![0.0; m],
        }
    }

    /// Number of constraints `m`.
    pub fn len(&self) -> usize {
        self.m
    }

    /// Whether there are no constraints.
    pub fn is_empty(&self) -> bool {
        self.m == 0
    }

    /// Solves `[M Jᵀ; J 0][q̈; λ] = [F; γ̃]` at `(q, q̇, t)`, with `γ̃` stabilised as
    /// `stabilization` says (or, for [`Stabilization::Penalty`], `M q̈ = F − Jᵀ λ` with the
    /// penalty forces); `λ` is left in [`Self::multipliers`]. A [`MechanicalSystem<N>`]'s
    /// static-size twin of [`Self::accelerations_into`].
    ///
    /// # Errors
    /// As [`Self::accelerations_into`].
    pub fn accelerations<S: MechanicalSystem<N>, const N: usize>(
        &mut self,
        system: &S,
        q: &SVector<f64, N>,
        qdot: &SVector<f64, N>,
        t: f64,
        stabilization: Stabilization,
    ) -> Result<SVector<f64, N>, RhsError> {
        let mut qddot = SVector::<f64, N>::zeros();
        self.accelerations_into(
            StaticSystem::from_ref(system),
            q.as_slice(),
            qdot.as_slice(),
            t,
            stabilization,
            qddot.as_mut_slice(),
        )?;
        Ok(qddot)
    }

    /// Solves `[M Jᵀ; J 0][q̈; λ] = [F; γ̃]` at `(q, q̇, t)` into `qddot` (length `n`), with
    /// `γ̃` stabilised as `stabilization` says (or, for [`Stabilization::Penalty`],
    /// `M q̈ = F − Jᵀ λ` with the penalty forces, by [`solve_spd_in_place`]); `λ` is left in
    /// [`Self::multipliers`]. No heap allocation.
    ///
    /// # Errors
    /// [`RhsError::SingularConstraintMatrix`] when the KKT matrix is singular (redundant
    /// constraints, a singular configuration, or `M` singular on the null space of `J`);
    /// [`RhsError::SingularMassMatrix`] when a penalty solve meets an `M` that is not
    /// positive definite.
    pub fn accelerations_into<C: DynMechanicalSystem + ?Sized>(
        &mut self,
        system: &C,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        stabilization: Stabilization,
        qddot: &mut [f64],
    ) -> Result<(), RhsError> {
        let (n, m) = (self.n, self.m);
        let k = n + m;
        system.mass_matrix_and_forcing(q, qdot, t, &mut self.mass, &mut self.forcing);
        system.constraint_jacobian(q, t, &mut self.jacobian);
        if let Stabilization::Penalty { stiffness, damping } = stabilization {
            system.constraint_velocity_residuals(q, qdot, t, &mut self.velocity);
            system.constraint_residuals(q, t, &mut self.phi);
            for i in 0..m {
                let position = if i < self.holonomic { self.phi[i] } else { 0.0 };
                let lambda = stiffness * position + damping * self.velocity[i];
                self.multipliers[i] = lambda;
                for c in 0..n {
                    self.forcing[c] -= self.jacobian[i * n + c] * lambda;
                }
            }
            solve_spd_in_place(
                n,
                &self.mass,
                &mut self.forcing,
                &mut self.spd,
                &mut self.envelope,
            )
            .ok_or(RhsError::SingularMassMatrix)?;
            qddot[..n].copy_from_slice(&self.forcing);
            return Ok(());
        }
        system.constraint_gamma(q, qdot, t, &mut self.gamma);
        if let Stabilization::Baumgarte { alpha, beta } = stabilization {
            system.constraint_velocity_residuals(q, qdot, t, &mut self.velocity);
            system.constraint_residuals(q, t, &mut self.phi);
            for i in 0..m {
                let position = if i < self.holonomic { self.phi[i] } else { 0.0 };
                self.gamma[i] -= 2.0 * alpha * self.velocity[i] + beta * beta * position;
            }
        }
        for r in 0..k {
            for c in 0..k {
                self.kkt[r * k + c] = match (r < n, c < n) {
                    (true, true) => self.mass[r + c * n],
                    (true, false) => self.jacobian[(c - n) * n + r],
                    (false, true) => self.jacobian[(r - n) * n + c],
                    (false, false) => 0.0,
                };
            }
            self.rhs[r] = if r < n {
                self.forcing[r]
            } else {
                self.gamma[r - n]
            };
        }
        lu_solve(&mut self.kkt, &mut self.rhs, &mut self.pivots, k)
            .ok_or(RhsError::SingularConstraintMatrix)?;
        self.multipliers.copy_from_slice(&self.rhs[n..k]);
        qddot[..n].copy_from_slice(&self.rhs[..n]);
        Ok(())
    }

    /// Largest `|Φᵢ|` and largest velocity residual `|Φ̇ᵢ|` (or `|A q̇ + b|`) at a state.
    pub fn drift<C: DynMechanicalSystem + ?Sized>(
        &mut self,
        system: &C,
        q: &[f64],
        qdot: &[f64],
        t: f64,
    ) -> (f64, f64) {
        system.constraint_residuals(q, t, &mut self.phi);
        system.constraint_velocity_residuals(q, qdot, t, &mut self.velocity);
        let max = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        (max(&self.phi), max(&self.velocity))
    }

    /// Projects `(q, q̇)` onto the constraint manifold at time `t`: Gauss–Newton on
    /// `Φ(q, t) = 0` over the coordinates `free` (all when `free` is empty) with the
    /// minimum-norm step, then the minimum-norm correction of the velocity residuals over the
    /// same coordinates. Returns the number of Newton iterations.
    ///
    /// # Errors
    /// [`ProjectionError`] naming the constraint with the largest residual when Newton does
    /// not reach `tolerance` in 50 iterations or `J Jᵀ` is singular.
    ///
    /// No heap allocation (it runs after every step under [`Stabilization::Projection`]).
    /// `q` and `q̇` are changed in place, also by a projection that then fails: project a
    /// copy where the state must survive a failure (the integrators hand it a scratch copy).
    pub fn project<C: DynMechanicalSystem + ?Sized>(
        &mut self,
        system: &C,
        q: &mut [f64],
        qdot: &mut [f64],
        t: f64,
        free: &[usize],
        tolerance: f64,
    ) -> Result<usize, ProjectionError> {
        let count = if free.is_empty() { self.n } else { free.len() };
        let column = |j: usize| if free.is_empty() { j } else { free[j] };
        let h = self.holonomic;
        let mut iterations = 0;
        if h > 0 {
            loop {
                system.constraint_residuals(q, t, &mut self.phi);
                let (worst, residual) = largest(&self.phi);
                if residual <= tolerance {
                    break;
                }
                let failure = ProjectionError {
                    constraint: worst,
                    residual,
                    iterations,
                };
                if iterations == 50 || !residual.is_finite() {
                    return Err(failure);
                }
                system.constraint_jacobian(q, t, &mut self.jacobian);
                self.minimum_norm(h, free, false).ok_or(failure)?;
                for j in 0..count {
                    let c = column(j);
                    q[c] -= self.step_component(h, c);
                }
                iterations += 1;
            }
        }
        if self.m > 0 {
            system.constraint_jacobian(q, t, &mut self.jacobian);
            system.constraint_velocity_residuals(q, qdot, t, &mut self.velocity);
            let (worst, residual) = largest(&self.velocity);
            self.minimum_norm(self.m, free, true)
                .ok_or(ProjectionError {
                    constraint: worst,
                    residual,
                    iterations,
                })?;
            for j in 0..count {
                let c = column(j);
                qdot[c] -= self.step_component(self.m, c);
            }
        }
        Ok(iterations)
    }

    /// Solves `(J Jᵀ) z = r` over the first `rows` rows of the Jacobian buffer and the columns
    /// `free` (all when empty), with `r` the position residuals `Φ` or (`velocity`) the
    /// velocity residuals; `z` is left in `small_rhs`, and the minimum-norm correction is
    /// `Jᵀ z` ([`Self::step_component`]). No allocation.
    fn minimum_norm(&mut self, rows: usize, free: &[usize], velocity: bool) -> Option<()> {
        let n = self.n;
        let count = if free.is_empty() { n } else { free.len() };
        let column = |j: usize| if free.is_empty() { j } else { free[j] };
        for a in 0..rows {
            for b in 0..rows {
                self.small[a * rows + b] = (0..count)
                    .map(|j| self.jacobian[a * n + column(j)] * self.jacobian[b * n + column(j)])
                    .sum();
            }
            self.small_rhs[a] = if velocity {
                self.velocity[a]
            } else {
                self.phi[a]
            };
        }
        lu_solve(
            &mut self.small[..rows * rows],
            &mut self.small_rhs[..rows],
            &mut self.small_pivots[..rows],
            rows,
        )
    }

    /// Component `c` of `Jᵀ z` after [`Self::minimum_norm`] over `rows` rows.
    fn step_component(&self, rows: usize, c: usize) -> f64 {
        (0..rows)
            .map(|a| self.jacobian[a * self.n + c] * self.small_rhs[a])
            .sum()
    }
}

/// Projection onto the constraints failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "could not satisfy constraint {constraint} (index into the model's constraints): residual {residual:e} after {iterations} Newton iteration(s)"
)]
pub struct ProjectionError {
    /// Index of the constraint with the largest residual, into
    /// [`crate::ModelDescription::constraints`].
    pub constraint: usize,
    /// Its residual.
    pub residual: f64,
    /// Newton iterations done.
    pub iterations: usize,
}

/// Index and absolute value of the largest-magnitude entry (NaN counts as largest).
fn largest(v: &[f64]) -> (usize, f64) {
    v.iter()
        .enumerate()
        .map(|(i, x)| (i, if x.is_nan() { f64::INFINITY } else { x.abs() }))
        .fold((0, 0.0), |best, c| if c.1 > best.1 { c } else { best })
}

/// Solves `a x = b` in place (`a` is `k × k` row-major, overwritten by its LU factors; `b`
/// becomes `x`) by Gaussian elimination with partial pivoting. `None` if a pivot is zero or
/// not finite, or is below `1e-13` of the largest entry of its column (numerically singular).
pub fn lu_solve(a: &mut [f64], b: &mut [f64], pivots: &mut [usize], k: usize) -> Option<()> {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for c in 0..k {
        let mut p = c;
        for r in c + 1..k {
            if a[r * k + c].abs() > a[p * k + c].abs() {
                p = r;
            }
        }
        let pivot = a[p * k + c];
        if !pivot.is_finite() || pivot.abs() <= 1e-13 * scale {
            return None;
        }
        pivots[c] = p;
        if p != c {
            for j in 0..k {
                a.swap(c * k + j, p * k + j);
            }
            b.swap(c, p);
        }
        for r in c + 1..k {
            let f = a[r * k + c] / pivot;
            if f != 0.0 {
                for j in c..k {
                    a[r * k + j] -= f * a[c * k + j];
                }
                b[r] -= f * b[c];
            }
        }
    }
    for r in (0..k).rev() {
        let s: f64 = (r + 1..k).map(|j| a[r * k + j] * b[j]).sum();
        b[r] = (b[r] - s) / a[r * k + r];
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lu_solves_a_system_that_needs_pivoting() {
        // [0 1; 1 1] x = [1; 3] → x = [2, 1].
        let mut a = vec![0.0, 1.0, 1.0, 1.0];
        let mut b = vec![1.0, 3.0];
        let mut p = vec![0; 2];
        lu_solve(&mut a, &mut b, &mut p, 2).unwrap();
        assert!((b[0] - 2.0).abs() < 1e-15 && (b[1] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn lu_rejects_a_singular_matrix() {
        let mut a = vec![1.0, 2.0, 2.0, 4.0];
        let mut b = vec![1.0, 2.0];
        let mut p = vec![0; 2];
        assert!(lu_solve(&mut a, &mut b, &mut p, 2).is_none());
    }
}
