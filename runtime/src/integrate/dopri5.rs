//! The Dormand–Prince 5(4) pair with PI step-size control and dense output.

use crate::ode::OdeSystem;

use super::Integrator;
use super::controller::PiController;
use super::driver::{self, Control, Problem};
use super::error::IntegrationFailure;
use super::explicit_rk::ExplicitRk;
use super::solution::Solution;
use super::tableau::Tableau;

/// Order of the embedded (error-estimating) solution of Dormand–Prince 5(4).
const ERROR_ORDER: u32 = 4;

/// The Dormand–Prince 5(4) method ("DOPRI5", [`Tableau::dopri5`]): fifth order, adaptive
/// steps from the embedded fourth-order estimate, fourth-order dense output.
///
/// The fifth-order solution is propagated (local extrapolation). A step is accepted when the
/// weighted RMS norm of the error estimate `err = h Σ (bᵢ − b̂ᵢ) kᵢ`,
///
/// ```text
/// ‖err‖ = √( (1/n) Σᵢ ( errᵢ / (atolᵢ + rtolᵢ · max(|yᵢ|, |y_newᵢ|)) )² ),
/// ```
///
/// is at most 1; the [`PiController`] (Hairer's DOPRI5 defaults unless replaced with
/// [`with_controller`](Self::with_controller)) then proposes the next step. The first step is
/// `dt` if given, else chosen automatically (Hairer–Nørsett–Wanner I, §II.4; one extra
/// evaluation of `F`). Each attempted step, accepted or rejected, costs six evaluations of `F`
/// (FSAL: the seventh stage is the next step's first), plus one at `t0`.
///
/// With [`IntegratorOptions::fixed_step`](super::IntegratorOptions::fixed_step) the method takes
/// constant steps `dt` (default `(t_end − t0)/1000`) without error control, like
/// [`RungeKutta4`](super::RungeKutta4); convergence-order studies use this.
///
/// # Examples
/// ```
/// use eomgen_runtime::{DormandPrince54, Integrator, IntegratorOptions, OdeFn, OutputTimes};
///
/// // The harmonic oscillator ẍ = −x, x(0) = 1, ẋ(0) = 0: x(t) = cos t.
/// let mut oscillator = OdeFn::new(2, |_t: f64, y: &[f64], dy: &mut [f64]| {
///     dy[0] = y[1];
///     dy[1] = -y[0];
/// });
/// let options = IntegratorOptions::default().with_rtol(1e-9).with_atol(1e-12);
/// let times = vec![0.0, 1.0, 2.0, 3.0];
/// let solution = DormandPrince54::new().integrate(
///     &mut oscillator,
///     0.0,
///     &[1.0, 0.0],
///     3.0,
///     &OutputTimes::At(times.clone()),
///     &options,
/// )?;
/// for (t, y) in solution.iter() {
///     assert!((y[0] - t.cos()).abs() < 1e-7);
/// }
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
///
/// # References
/// - J. R. Dormand, P. J. Prince, "A family of embedded Runge–Kutta formulae",
///   J. Comput. Appl. Math. 6(1), 19–26, 1980, doi:10.1016/0771-050X(80)90013-3.
/// - L. F. Shampine, "Some practical Runge–Kutta formulas", Math. Comp. 46(173), 135–150,
///   1986, doi:10.1090/S0025-5718-1986-0815836-3.
/// - E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed.,
///   Springer, 1993, §II.4–II.6, doi:10.1007/978-3-540-78862-1.
#[derive(Debug, Clone)]
pub struct DormandPrince54 {
    controller: PiController,
}

pi_controlled_integrator!(
    DormandPrince54,
    name: "dp54",
    order: 5,
    error_order: ERROR_ORDER,
    controller: PiController::dopri5(),
    new_doc: "The method with [`PiController::dopri5`].",
    stepper: |dim| ExplicitRk::new(Tableau::dopri5(), dim),
);
