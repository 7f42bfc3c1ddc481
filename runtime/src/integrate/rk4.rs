//! The classical fourth-order Runge–Kutta method with fixed steps.

use crate::ode::OdeSystem;

use super::Integrator;
use super::driver::{self, Control, Problem};
use super::error::IntegrationFailure;
use super::explicit_rk::ExplicitRk;
use super::solution::Solution;
use super::tableau::Tableau;

/// The classical Runge–Kutta method of order 4, with constant steps ([`Tableau::rk4`]).
///
/// Steps are `dt` (default `(t_end − t0)/1000`, at most `dt_max`), the last one shortened to
/// land exactly on `t_end`; `rtol`, `atol` and `fixed_step` are not used. Each step costs four
/// evaluations of `F`, plus one at `t0`: `F` at the end of a step is the first stage of the
/// next.
///
/// Dense output is the cubic Hermite interpolant of the step's end values and derivatives: a
/// continuous extension of order 3 (local interpolation error `O(dt⁴)`), so interpolated
/// values converge as `O(dt⁴)`, like the steps themselves.
///
/// # Examples
/// ```
/// use eomgen_runtime::{Integrator, IntegratorOptions, OdeFn, OutputTimes, RungeKutta4};
///
/// // ẋ = x, x(0) = 1 on [0, 1]: x(1) = e.
/// let mut growth = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = y[0]);
/// let options = IntegratorOptions::default().with_dt(0.01);
/// let solution =
///     RungeKutta4::new().integrate(&mut growth, 0.0, &[1.0], 1.0, &OutputTimes::Steps, &options)?;
/// assert_eq!(solution.stats.steps, 100);
/// assert_eq!(solution.stats.rhs_evals, 4 * 100 + 1);
/// assert!((solution.state(100)[0] - std::f64::consts::E).abs() < 1e-9);
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
///
/// # References
/// W. Kutta, "Beitrag zur näherungsweisen Integration totaler Differentialgleichungen",
/// Zeitschrift für Mathematik und Physik 46, 435–453, 1901.
#[derive(Debug, Clone, Default)]
pub struct RungeKutta4 {
    _private: (),
}

fixed_step_integrator!(RungeKutta4, name: "rk4", order: 4, tableau: Tableau::rk4());
