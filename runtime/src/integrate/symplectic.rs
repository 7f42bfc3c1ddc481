//! Partitioned methods for second-order systems `q̇ = v`, `v̇ = q̈(t, q, v)`: symplectic Euler
//! and Störmer–Verlet (leapfrog in `q`, `q̇`), with fixed steps.
//!
//! Both treat `q` and `v = q̇` differently, so they need the split `y = [q; q̇]`
//! ([`OdeSystem::second_order_dim`](crate::OdeSystem::second_order_dim)). They are symplectic
//! in the variables `(q, q̇)` when those are canonical up to a constant factor: a constant mass
//! matrix and forces that do not depend on the velocities. Then the energy error stays bounded
//! over exponentially long times instead of drifting (Hairer, Lubich, Wanner, *Geometric
//! Numerical Integration*, §IX.8). With a configuration-dependent `M(q)` the canonical momentum
//! is `p = M(q) q̇`, not `q̇`, and with damping or gyroscopic forces the flow is not
//! Hamiltonian: the methods still converge at their order, but are not symplectic.

use std::mem::swap;

use crate::ode::OdeSystem;

use super::Integrator;
use super::dense_output::DenseOutput;
use super::driver::{self, Control, Problem};
use super::error::{IntegrationError, IntegrationFailure};
use super::options::ErrorWeights;
use super::solution::Solution;
use super::stepper::{CheckedRhs, StepEnds, StepFailure, Stepper, SystemShape};

/// Which partitioned scheme a [`Partitioned`] stepper takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scheme {
    /// Kick then drift: `v₁ = v + h a(t, q, v)`, `q₁ = q + h v₁`.
    SymplecticEuler,
    /// Half kick, drift, half kick (velocity Verlet).
    StormerVerlet,
}

/// A partitioned stepper for `y = [q; v]` with `n` coordinates, all buffers allocated once.
///
/// `f = [v; a]` holds the acceleration used for the next kick: for symplectic Euler exactly
/// `F(t, y)`; for Störmer–Verlet the acceleration evaluated at the end of the last step (see
/// [`StormerVerlet`] for the velocity it uses).
#[derive(Debug, Clone)]
pub(crate) struct Partitioned {
    scheme: Scheme,
    n: usize,
    /// Ends of the last accepted step and the candidate's time.
    ends: StepEnds,
    y_new: Vec<f64>,
    f_new: Vec<f64>,
    /// Stage input `[q₁; ṽ]` (Störmer–Verlet).
    stage: Vec<f64>,
}

impl Partitioned {
    /// A stepper for `shape`, or [`IntegrationError::NotSecondOrder`] for `method` if the
    /// system has no split `y = [q; q̇]` of its dimension.
    pub(crate) fn new(
        scheme: Scheme,
        shape: SystemShape,
        method: &'static str,
    ) -> Result<Self, IntegrationError> {
        let n = match shape.second_order_dim {
            Some(n) if 2 * n == shape.dim => n,
            _ => return Err(IntegrationError::NotSecondOrder { method }),
        };
        let dim = shape.dim;
        Ok(Self {
            scheme,
            n,
            ends: StepEnds::new(dim),
            y_new: vec![0.0; dim],
            f_new: vec![0.0; dim],
            stage: vec![0.0; dim],
        })
    }
}

impl DenseOutput for Partitioned {
    fn interval(&self) -> (f64, f64) {
        self.ends.interval()
    }

    /// The cubic Hermite interpolant of the step's ends `(y, [v; a])`, accurate to `O(h³)`
    /// (`O(h⁴)` where the accelerations are exact), at least the order of the methods.
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        self.ends.hermite(t, out);
    }
}

impl Stepper for Partitioned {
    stepper_state_from_ends!();

    fn reset(&mut self, rhs: &mut CheckedRhs<'_>, t0: f64, y0: &[f64]) -> Result<(), StepFailure> {
        self.ends.reset(rhs, t0, y0)?;
        Ok(())
    }

    fn attempt(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        t_new: f64,
        _weights: &ErrorWeights,
        _estimate_error: bool,
    ) -> Result<Option<f64>, StepFailure> {
        let n = self.n;
        let h = t_new - self.ends.t;
        self.ends.t_new = t_new;
        let (q, v) = self.ends.y.split_at(n);
        let a = &self.ends.f[n..];
        let (q_new, v_new) = self.y_new.split_at_mut(n);
        match self.scheme {
            Scheme::SymplecticEuler => {
                for i in 0..n {
                    v_new[i] = v[i] + h * a[i];
                    q_new[i] = q[i] + h * v_new[i];
                }
            }
            Scheme::StormerVerlet => {
                // v½ = v + h/2 a;  q₁ = q + h v½;  a₁ = a(t₁, q₁, ṽ) with ṽ = v½ + h/2 a
                // (= v + h a, within O(h²) of v₁);  v₁ = v½ + h/2 a₁.
                let (stage_q, stage_v) = self.stage.split_at_mut(n);
                for i in 0..n {
                    let v_half = v[i] + 0.5 * h * a[i];
                    v_new[i] = v_half;
                    q_new[i] = q[i] + h * v_half;
                    stage_q[i] = q_new[i];
                    stage_v[i] = v_half + 0.5 * h * a[i];
                }
                rhs.eval(t_new, &self.stage, &mut self.f_new)?;
                let (f_q, f_v) = self.f_new.split_at_mut(n);
                for (v, a) in v_new.iter_mut().zip(f_v.iter()) {
                    *v += 0.5 * h * a;
                }
                f_q.copy_from_slice(v_new);
            }
        }
        if let Some(index) = self.y_new.iter().position(|v| !v.is_finite()) {
            return Err(StepFailure::NonFiniteState { t: t_new, index });
        }
        Ok(None)
    }

    fn accept(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        if self.scheme == Scheme::SymplecticEuler {
            rhs.eval(self.ends.t_new, &self.y_new, &mut self.f_new)?;
        }
        swap(&mut self.ends.f_prev, &mut self.ends.f);
        swap(&mut self.ends.f, &mut self.f_new);
        swap(&mut self.ends.y_prev, &mut self.ends.y);
        swap(&mut self.ends.y, &mut self.y_new);
        self.ends.t_prev = self.ends.t;
        self.ends.t = self.ends.t_new;
        Ok(())
    }
}

/// Runs a partitioned scheme over `problem`.
fn integrate_partitioned(
    scheme: Scheme,
    method: &'static str,
    system: &mut dyn OdeSystem,
    problem: &Problem<'_>,
) -> Result<Solution, IntegrationFailure> {
    driver::run(problem, system, Control::Fixed, |shape| {
        Partitioned::new(scheme, shape, method)
    })
}

/// Symplectic Euler for second-order systems: `v₁ = v + h q̈(t, q, v)`, `q₁ = q + h v₁`
/// ("kick, then drift"), order 1, constant steps.
///
/// Needs `y = [q; q̇]` ([`OdeSystem::second_order_dim`](crate::OdeSystem::second_order_dim);
/// models through [`FirstOrder`](crate::FirstOrder) have it, hand-written systems use
/// [`OdeFn::second_order`](crate::OdeFn::second_order)); otherwise
/// [`IntegrationError::NotSecondOrder`] before any step. One evaluation of `F` per step (at the
/// new state, serving the next kick), plus one at `t0`.
///
/// Symplectic, hence with bounded energy error over long times, only for a constant mass
/// matrix and velocity-independent forces: with a configuration-dependent `M(q)` the
/// canonical momentum is `M(q) q̇`, not `q̇`, and damping or gyroscopic forces are not
/// Hamiltonian; the method then still converges at order 1. Steps are `dt`
/// (default `(t_end − t0)/1000`); `rtol`, `atol` and `fixed_step` are not used. Dense output is
/// the cubic Hermite interpolant of the step's ends.
///
/// # Examples
/// ```
/// use eomgen_runtime::{Integrator, IntegratorOptions, OdeFn, OutputTimes, SymplecticEuler};
///
/// // ẍ = −x over 100 periods: the energy error stays of order dt, without drift.
/// let mut oscillator = OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
///     dy[0] = y[1];
///     dy[1] = -y[0];
/// });
/// let t_end = 200.0 * std::f64::consts::PI;
/// let options = IntegratorOptions::default().with_dt(0.01);
/// let solution = SymplecticEuler::new()
///     .integrate(&mut oscillator, 0.0, &[1.0, 0.0], t_end, &OutputTimes::Steps, &options)?;
/// for (_, y) in solution.iter() {
///     assert!(((y[0] * y[0] + y[1] * y[1]) / 2.0 - 0.5).abs() < 0.01);
/// }
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
///
/// # References
/// E. Hairer, C. Lubich, G. Wanner, *Geometric Numerical Integration*, 2nd ed., Springer, 2006,
/// §I.1.2 and Theorem VI.3.3, doi:10.1007/3-540-30666-8.
#[derive(Debug, Clone, Default)]
pub struct SymplecticEuler {
    _private: (),
}

impl SymplecticEuler {
    /// The method.
    pub fn new() -> Self {
        Self::default()
    }
}

impl Integrator for SymplecticEuler {
    fn name(&self) -> &'static str {
        "symplectic-euler"
    }

    fn order(&self) -> u32 {
        1
    }
}

impl driver::Method for SymplecticEuler {
    fn run(
        &mut self,
        problem: &Problem<'_>,
        system: &mut dyn OdeSystem,
    ) -> Result<Solution, IntegrationFailure> {
        integrate_partitioned(Scheme::SymplecticEuler, self.name(), system, problem)
    }
}

/// The Störmer–Verlet method (velocity Verlet, leapfrog in `q` and `q̇`), order 2, constant
/// steps:
///
/// ```text
/// v½ = v + (h/2) a,   q₁ = q + h v½,   a₁ = q̈(t + h, q₁, ṽ),   v₁ = v½ + (h/2) a₁,
/// ```
///
/// where `a` is the acceleration of the previous step's end and `ṽ = v½ + (h/2) a`.
///
/// For forces that do not depend on `q̇` the velocity `ṽ` is irrelevant and this is exactly the
/// classical leapfrog: one evaluation of `F` per step, symmetric, and symplectic for a constant
/// mass matrix (bounded energy error, no drift). For velocity-dependent forces (dampers,
/// Coriolis terms of a configuration-dependent `M(q)`) the exact scheme would be implicit in
/// `v₁`; evaluating the force at the explicit prediction `ṽ`, which is within `O(h²)` of `v₁`,
/// keeps second order at the same cost, but the method is then neither symmetric nor
/// symplectic. In short: symplectic only for a constant mass matrix and velocity-independent
/// forces (with a configuration-dependent `M(q)` the canonical momentum is `M(q) q̇`, not
/// `q̇`).
///
/// Needs `y = [q; q̇]` ([`OdeSystem::second_order_dim`](crate::OdeSystem::second_order_dim)),
/// otherwise [`IntegrationError::NotSecondOrder`]. Steps are `dt` (default
/// `(t_end − t0)/1000`); `rtol`, `atol` and `fixed_step` are not used. Dense output is the
/// cubic Hermite interpolant of the step's ends.
///
/// # Examples
/// ```
/// use eomgen_runtime::{Integrator, IntegratorOptions, OdeFn, OutputTimes, StormerVerlet};
///
/// // ẍ = −x over 1000 periods with 20 steps per period: energy error ~ (ω h)²/8, no drift.
/// let mut oscillator = OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
///     dy[0] = y[1];
///     dy[1] = -y[0];
/// });
/// let period = 2.0 * std::f64::consts::PI;
/// let options = IntegratorOptions::default().with_dt(period / 20.0);
/// let solution = StormerVerlet::new().integrate(
///     &mut oscillator, 0.0, &[1.0, 0.0], 1000.0 * period, &OutputTimes::Steps, &options,
/// )?;
/// assert_eq!(solution.stats.rhs_evals, 20_000 + 1);
/// for (_, y) in solution.iter() {
///     assert!(((y[0] * y[0] + y[1] * y[1]) / 2.0 - 0.5).abs() < 0.02);
/// }
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
///
/// # References
/// - L. Verlet, "Computer 'experiments' on classical fluids. I.", Phys. Rev. 159, 98–103,
///   1967, doi:10.1103/PhysRev.159.98.
/// - E. Hairer, C. Lubich, G. Wanner, "Geometric numerical integration illustrated by the
///   Störmer–Verlet method", Acta Numerica 12, 399–450, 2003,
///   doi:10.1017/S0962492902000144.
#[derive(Debug, Clone, Default)]
pub struct StormerVerlet {
    _private: (),
}

impl StormerVerlet {
    /// The method.
    pub fn new() -> Self {
        Self::default()
    }
}

impl Integrator for StormerVerlet {
    fn name(&self) -> &'static str {
        "stormer-verlet"
    }

    fn order(&self) -> u32 {
        2
    }
}

impl driver::Method for StormerVerlet {
    fn run(
        &mut self,
        problem: &Problem<'_>,
        system: &mut dyn OdeSystem,
    ) -> Result<Solution, IntegrationFailure> {
        integrate_partitioned(Scheme::StormerVerlet, self.name(), system, problem)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ode::OdeFn;

    /// One Verlet step of ẍ = −x from (1, 0) is the textbook leapfrog.
    #[test]
    fn verlet_step_is_the_leapfrog() {
        let mut system = OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = y[1];
            dy[1] = -y[0];
        });
        let mut rhs = CheckedRhs::new(&mut system);
        let shape = SystemShape {
            dim: 2,
            second_order_dim: Some(1),
        };
        let mut stepper = Partitioned::new(Scheme::StormerVerlet, shape, "stormer-verlet").unwrap();
        stepper.reset(&mut rhs, 0.0, &[1.0, 0.0]).unwrap();
        let h = 0.1;
        let weights = ErrorWeights::uniform(2, 1e-6, 1e-9);
        stepper.attempt(&mut rhs, h, &weights, false).unwrap();
        stepper.accept(&mut rhs).unwrap();
        let v_half = -0.5 * h;
        let q1 = 1.0 + h * v_half;
        let v1 = v_half - 0.5 * h * q1;
        assert!((stepper.y()[0] - q1).abs() < 1e-16);
        assert!((stepper.y()[1] - v1).abs() < 1e-16);
        assert_eq!(stepper.derivative(), &[v1, -q1]);
        assert_eq!(rhs.evals(), 2);
    }

    #[test]
    fn first_order_systems_are_refused() {
        let shape = SystemShape {
            dim: 3,
            second_order_dim: None,
        };
        let error =
            Partitioned::new(Scheme::SymplecticEuler, shape, "symplectic-euler").unwrap_err();
        assert_eq!(
            error,
            IntegrationError::NotSecondOrder {
                method: "symplectic-euler"
            }
        );
        let mismatched = SystemShape {
            dim: 3,
            second_order_dim: Some(1),
        };
        assert!(Partitioned::new(Scheme::StormerVerlet, mismatched, "stormer-verlet").is_err());
    }
}
