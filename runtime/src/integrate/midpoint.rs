//! The explicit midpoint rule with fixed steps.

use crate::ode::OdeSystem;

use super::Integrator;
use super::driver::{self, Control, Problem};
use super::error::IntegrationFailure;
use super::explicit_rk::ExplicitRk;
use super::solution::Solution;
use super::tableau::Tableau;

/// The explicit midpoint rule `y₁ = y + h F(t + h/2, y + (h/2) F(t, y))`, order 2, with
/// constant steps ([`Tableau::midpoint`]).
///
/// Steps are `dt` (default `(t_end − t0)/1000`, at most `dt_max`), the last one shortened to
/// land exactly on `t_end`; `rtol`, `atol` and `fixed_step` are not used. Two evaluations of
/// `F` per step, plus one at `t0`. Dense output is the cubic Hermite interpolant of the
/// step's end values and derivatives.
///
/// # Examples
/// ```
/// use eomgen_runtime::{ExplicitMidpoint, Integrator, IntegratorOptions, OdeFn, OutputTimes};
///
/// // ẋ = x, x(0) = 1: one step of h is the Taylor polynomial 1 + h + h²/2.
/// let mut growth = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = y[0]);
/// let options = IntegratorOptions::default().with_dt(0.1);
/// let solution = ExplicitMidpoint::new()
///     .integrate(&mut growth, 0.0, &[1.0], 0.1, &OutputTimes::Steps, &options)?;
/// assert!((solution.state(1)[0] - 1.105).abs() < 1e-15);
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
///
/// # References
/// C. Runge, "Über die numerische Auflösung von Differentialgleichungen", Math. Ann. 46,
/// 167–178, 1895, doi:10.1007/BF01446807; E. Hairer, S. P. Nørsett, G. Wanner, *Solving
/// Ordinary Differential Equations I*, 2nd ed., Springer, 1993, §II.1,
/// doi:10.1007/978-3-540-78862-1.
#[derive(Debug, Clone, Default)]
pub struct ExplicitMidpoint {
    _private: (),
}

fixed_step_integrator!(ExplicitMidpoint, name: "midpoint", order: 2, tableau: Tableau::midpoint());
