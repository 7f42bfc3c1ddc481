//! The explicit (forward) Euler method with fixed steps.

use crate::ode::OdeSystem;

use super::Integrator;
use super::driver::{self, Control, Problem};
use super::error::IntegrationFailure;
use super::explicit_rk::ExplicitRk;
use super::solution::Solution;
use super::tableau::Tableau;

/// The explicit Euler method `y₁ = y + h F(t, y)`, order 1, with constant steps
/// ([`Tableau::euler`]).
///
/// Steps are `dt` (default `(t_end − t0)/1000`, at most `dt_max`), the last one shortened to
/// land exactly on `t_end`; `rtol`, `atol` and `fixed_step` are not used. One evaluation of
/// `F` per step, plus one at `t0`. It is the baseline of the course's studies: on an undamped
/// oscillator its energy grows by the factor `1 + (ω dt)²` every step.
///
/// Dense output is the cubic Hermite interpolant of the step's end values and derivatives
/// (more accurate than the steps themselves).
///
/// # Examples
/// ```
/// use eomgen_runtime::{ExplicitEuler, Integrator, IntegratorOptions, OdeFn, OutputTimes};
///
/// // ẋ = x, x(0) = 1: 100 Euler steps give (1 + 1/100)¹⁰⁰ at t = 1.
/// let mut growth = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = y[0]);
/// let options = IntegratorOptions::default().with_dt(0.01);
/// let solution =
///     ExplicitEuler::new().integrate(&mut growth, 0.0, &[1.0], 1.0, &OutputTimes::Steps, &options)?;
/// let (_, y) = solution.last().unwrap();
/// assert!((y[0] - 1.01_f64.powi(100)).abs() < 1e-12);
/// assert_eq!(solution.stats.rhs_evals, 100 + 1);
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
///
/// # References
/// E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed.,
/// Springer, 1993, §I.7, doi:10.1007/978-3-540-78862-1.
#[derive(Debug, Clone, Default)]
pub struct ExplicitEuler {
    _private: (),
}

fixed_step_integrator!(ExplicitEuler, name: "euler", order: 1, tableau: Tableau::euler());
