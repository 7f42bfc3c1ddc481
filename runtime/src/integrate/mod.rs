//! Numerical integration of first-order systems `ẏ = F(t, y)`: one [`Integrator`] trait and
//! every method behind it.
//!
//! | method | type | order | steps | dense output ([`OutputTimes::At`]) |
//! |---|---|---|---|---|
//! | explicit Euler | [`ExplicitEuler`] | 1 | fixed `dt` | cubic Hermite (order 3) |
//! | explicit midpoint | [`ExplicitMidpoint`] | 2 | fixed `dt` | cubic Hermite (order 3) |
//! | classical Runge–Kutta | [`RungeKutta4`] | 4 | fixed `dt` | cubic Hermite (order 3) |
//! | Bogacki–Shampine 3(2) | [`BogackiShampine32`] | 3 | adaptive ([`PiController`]) or fixed | cubic Hermite (order 3) |
//! | Dormand–Prince 5(4) | [`DormandPrince54`] | 5 | adaptive ([`PiController`]) or fixed | Shampine's quartic (order 4) |
//! | DOP853 | [`DormandPrince853`] | 8 | adaptive ([`PiController`]) or fixed | Hairer's septic (order 7) |
//! | Verner 6(5) | [`Verner65`] | 6 | adaptive ([`PiController`]) or fixed | Verner's (order 6, 3 extra stages) |
//! | Verner 7(6) | [`Verner76`] | 7 | adaptive ([`PiController`]) or fixed | Verner's (order 7, 5 extra stages) |
//! | Verner 8(7) | [`Verner87`] | 8 | adaptive ([`PiController`]) or fixed | Verner's (order 8, 7 extra stages) |
//! | Verner 9(8) | [`Verner98`] | 9 | adaptive ([`PiController`]) or fixed | Verner's (order 9, 9 extra stages) |
//! | Taylor | [`Taylor`] | `⌈−½ ln ε + 1⌉` from the tolerance | a priori from the series (Jorba & Zou), or fixed | the step's series (its order) |
//! | symplectic Euler | [`SymplecticEuler`] | 1 | fixed `dt`, `y = [q; q̇]` | cubic Hermite |
//! | Störmer–Verlet | [`StormerVerlet`] | 2 | fixed `dt`, `y = [q; q̇]` | cubic Hermite |
//! | implicit midpoint | [`ImplicitMidpoint`] | 2 | fixed `dt`, Newton with `∂F/∂y` | cubic Hermite (order 3) |
//! | Radau IIA | [`RadauIIA5`] | 5 | adaptive ([`PredictiveController`]) or fixed, Newton with `∂F/∂y` | collocation polynomial (order 3) |
//!
//! The symplectic methods are symplectic (bounded energy error, no drift) for a constant mass
//! matrix and velocity-independent forces; implicit midpoint is symplectic for any `M(q)` and
//! conserves quadratic invariants; Radau IIA is L-stable, for stiff problems. The implicit
//! methods use the exact Jacobian of [`OdeSystem::jacobian`] (generated for every model) and
//! difference `F` otherwise.
//!
//! An integration takes an [`OdeSystem`] (a hand-written [`OdeFn`](crate::OdeFn), or a model
//! through [`FirstOrder`](crate::FirstOrder)), an interval `[t0, t_end]`, an initial state,
//! the [`OutputTimes`] to record and [`IntegratorOptions`]. It returns a [`Solution`] with
//! [`Stats`], or an [`IntegrationFailure`]: an [`IntegrationError`] together with every sample
//! recorded before it. Bad input is an error, never a panic; a NaN is never returned.
//!
//! Inside, every method is a *stepper* (one step from the current state, an interpolant over
//! the last accepted step) driven by one shared loop that checks the input, chooses the step
//! sequence (fixed, or adaptive through a [`StepSizeController`]), samples the output and maps
//! failures to errors. Explicit Runge–Kutta methods are one stepper parameterised by a
//! [`Tableau`]; DOP853, the partitioned methods, implicit midpoint and Radau IIA are steppers of
//! their own. No heap allocation happens per step: buffers (Jacobians and LU factors
//! included) are allocated once per `integrate` call, and the solution grows by amortised
//! doubling.
//!
//! # Examples
//! ```
//! use eomgen_runtime::{
//!     DormandPrince54, Integrator, IntegratorOptions, OdeFn, OutputTimes, RungeKutta4,
//! };
//!
//! // ẏ = −y + sin t, y(0) = 1: y(t) = (sin t − cos t)/2 + 3/2 e^(−t).
//! let exact = |t: f64| (t.sin() - t.cos()) / 2.0 + 1.5 * (-t).exp();
//! let mut system = OdeFn::new(1, |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0] + t.sin());
//! let output = OutputTimes::At(vec![0.5, 1.0, 2.0]);
//! let options = IntegratorOptions::default().with_rtol(1e-8).with_atol(1e-8);
//! let mut methods: Vec<Box<dyn Integrator>> =
//!     vec![Box::new(RungeKutta4::new()), Box::new(DormandPrince54::new())];
//! for method in &mut methods {
//!     let solution = method.integrate(&mut system, 0.0, &[1.0], 2.0, &output, &options)?;
//!     for (t, y) in solution.iter() {
//!         assert!((y[0] - exact(t)).abs() < 1e-7, "{} at t = {t}", method.name());
//!     }
//! }
//! # Ok::<(), eomgen_runtime::IntegrationFailure>(())
//! ```

#[macro_use]
mod wrappers;

mod bs32;
mod controller;
mod dense_output;
mod dop853;
mod dopri5;
mod driver;
mod error;
mod euler;
mod events;
mod explicit_rk;
mod implicit_midpoint;
mod linear;
mod midpoint;
mod options;
mod radau5;
mod rk4;
mod solution;
pub mod stability_function;
mod stepper;
mod symplectic;
mod tableau;
mod taylor;
mod verner;

pub use bs32::BogackiShampine32;
pub use controller::{
    NewtonWork, PiController, PredictiveController, StepOutcome, StepSizeController,
};
pub use dop853::DormandPrince853;
pub use dopri5::DormandPrince54;
pub use error::{IntegrationError, IntegrationFailure};
pub use euler::ExplicitEuler;
pub use implicit_midpoint::ImplicitMidpoint;
pub use midpoint::ExplicitMidpoint;
pub use options::{IntegratorOptions, OutputTimes, Tolerance};
pub use radau5::RadauIIA5;
pub use rk4::RungeKutta4;
pub use solution::{Solution, Stats};
pub use symplectic::{StormerVerlet, SymplecticEuler};
pub use tableau::Tableau;
pub use taylor::Taylor;
pub use verner::{Verner65, Verner76, Verner87, Verner98};

// The event types belong to the ODE interface (`OdeSystem::event_specs`); the root finding is
// `events`.
pub use crate::ode::{Event, EventDirection, EventSpec};

use crate::ode::OdeSystem;
use driver::Problem;

/// A method that integrates `ẏ = F(t, y)` forward in time.
///
/// Object safe: the CLI holds methods as `Box<dyn Integrator>`.
///
/// Sealed: this crate's methods are its implementations. Each supplies its stepper and step
/// control; the one driver loop behind [`Integrator::integrate`] does the rest.
pub trait Integrator: driver::Method {
    /// Short name of the method (`"euler"`, `"midpoint"`, `"rk4"`, `"bs32"`, `"dp54"`,
    /// `"dop853"`, `"vern6"`, `"vern7"`, `"vern8"`, `"vern9"`, `"symplectic-euler"`, `"stormer-verlet"`, `"implicit-midpoint"`,
    /// `"radau5"`).
    fn name(&self) -> &'static str;

    /// Order of convergence `p` of the method: the global error at a fixed final time
    /// behaves as `O(dtᵖ)`.
    fn order(&self) -> u32;

    /// Integrates `system` from `(t0, y0)` to `t_end`, recording the samples `output` asks
    /// for.
    ///
    /// Only forward integration is supported: `t_end > t0`. The last step ends exactly at
    /// `t_end`, so with [`OutputTimes::Steps`] the last sample is `(t_end, y(t_end))`.
    ///
    /// # Shapes
    /// `y0` has `n = system.dim()` entries; the solution's `y` has `n` entries per sample.
    ///
    /// # Errors
    /// An [`IntegrationFailure`] whose `partial` solution holds the samples recorded before
    /// the failure, with one of these errors:
    /// - invalid input, before any step: [`IntegrationError::InvalidTimeSpan`] (`t_end ≤ t0`
    ///   or not finite), [`IntegrationError::DimensionMismatch`] (`y0`),
    ///   [`IntegrationError::NonFiniteState`] (`y0` not finite),
    ///   [`IntegrationError::ToleranceLengthMismatch`], [`IntegrationError::InvalidTolerance`],
    ///   [`IntegrationError::ZeroTolerance`], [`IntegrationError::InvalidStepSize`],
    ///   [`IntegrationError::OutputTimesNotSorted`],
    ///   [`IntegrationError::OutputTimeOutOfRange`], and for the partitioned methods
    ///   [`IntegrationError::NotSecondOrder`];
    /// - during the integration: [`IntegrationError::StepSizeTooSmall`],
    ///   [`IntegrationError::TooManySteps`], [`IntegrationError::NonFiniteState`],
    ///   [`IntegrationError::RhsNonFinite`], [`IntegrationError::SingularMassMatrix`],
    ///   [`IntegrationError::SingularConstraintMatrix`], and for the implicit methods
    ///   [`IntegrationError::NewtonDidNotConverge`] and
    ///   [`IntegrationError::SingularIterationMatrix`].
    fn integrate(
        &mut self,
        system: &mut dyn OdeSystem,
        t0: f64,
        y0: &[f64],
        t_end: f64,
        output: &OutputTimes,
        options: &IntegratorOptions,
    ) -> Result<Solution, IntegrationFailure> {
        self.run(&Problem::new(t0, y0, t_end, output, options), system)
    }
}
