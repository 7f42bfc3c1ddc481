//! The Bogacki–Shampine 3(2) pair with PI step-size control and Hermite dense output.

use crate::ode::OdeSystem;

use super::Integrator;
use super::controller::PiController;
use super::driver::{self, Control, Problem};
use super::error::IntegrationFailure;
use super::explicit_rk::ExplicitRk;
use super::solution::Solution;
use super::tableau::Tableau;

/// Order of the embedded (error-estimating) solution of Bogacki–Shampine 3(2).
const ERROR_ORDER: u32 = 2;

/// The Bogacki–Shampine 3(2) method (MATLAB's `ode23`, [`Tableau::bs32`]): third order,
/// adaptive steps from the embedded second-order estimate, cubic Hermite dense output.
///
/// The third-order solution is propagated. A step is accepted when the weighted RMS norm of
/// `err = h Σ (bᵢ − b̂ᵢ) kᵢ` (scales `atolᵢ + rtolᵢ · max(|yᵢ|, |y_newᵢ|)`) is at most 1; the
/// [`PiController`] ([`PiController::for_error_order`]`(2)` unless replaced with
/// [`with_controller`](Self::with_controller)) proposes the next step. Three evaluations of
/// `F` per attempted step (FSAL), plus one at `t0` and one for the automatic first step.
///
/// Dense output ([`OutputTimes::At`](super::OutputTimes::At)) is the cubic Hermite interpolant of
/// the step's end values and derivatives, which are stages of the step: a continuous extension of
/// order 3 at no extra cost (Bogacki and Shampine's own choice). With
/// [`IntegratorOptions::fixed_step`](super::IntegratorOptions::fixed_step) the method takes
/// constant steps `dt`.
///
/// # Examples
/// ```
/// use eomgen_runtime::{BogackiShampine32, Integrator, IntegratorOptions, OdeFn, OutputTimes};
///
/// // ẏ = −y + sin t, y(0) = 1: y(t) = (sin t − cos t)/2 + 3/2 e^(−t).
/// let mut system = OdeFn::new(1, |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0] + t.sin());
/// let options = IntegratorOptions::default().with_rtol(1e-8).with_atol(1e-8);
/// let solution = BogackiShampine32::new().integrate(
///     &mut system,
///     0.0,
///     &[1.0],
///     3.0,
///     &OutputTimes::At(vec![1.5, 3.0]),
///     &options,
/// )?;
/// for (t, y) in solution.iter() {
///     let exact = (t.sin() - t.cos()) / 2.0 + 1.5 * (-t).exp();
///     assert!((y[0] - exact).abs() < 1e-7);
/// }
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
///
/// # References
/// P. Bogacki, L. F. Shampine, "A 3(2) pair of Runge–Kutta formulas", Appl. Math. Lett.
/// 2(4), 321–325, 1989, doi:10.1016/0893-9659(89)90079-7.
#[derive(Debug, Clone)]
pub struct BogackiShampine32 {
    controller: PiController,
}

pi_controlled_integrator!(
    BogackiShampine32,
    name: "bs32",
    order: 3,
    error_order: ERROR_ORDER,
    controller: PiController::for_error_order(ERROR_ORDER),
    new_doc: "The method with [`PiController::for_error_order`]`(2)`.",
    stepper: |dim| ExplicitRk::new(Tableau::bs32(), dim),
);
