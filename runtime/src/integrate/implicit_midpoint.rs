//! The implicit midpoint rule with fixed steps, solved by simplified Newton iterations with
//! the system's Jacobian.

use std::mem::swap;

use nalgebra::DMatrix;

use crate::ode::OdeSystem;

use super::Integrator;
use super::dense_output::DenseOutput;
use super::driver::{self, Control, Problem};
use super::error::IntegrationFailure;
use super::linear::{LuFactors, SAME_STEP};
use super::options::{ErrorWeights, check_absolute_tolerance};
use super::solution::Solution;
use super::stepper::{CheckedRhs, StepEnds, StepFailure, Stepper};

/// Newton stops when the residual of the stage equation, relative to
/// `max(|yᵢ|, |y_newᵢ|, atolᵢ)`, is below this (default of [`ImplicitMidpoint`]).
const NEWTON_TOLERANCE: f64 = 1e-12;
/// Most Newton iterations per attempt (default of [`ImplicitMidpoint`]).
const MAX_NEWTON_ITERATIONS: usize = 10;
/// Newton iterations beyond which the next step computes a fresh Jacobian.
const SLOW_NEWTON: usize = 3;
/// A residual this small relative to the state is rounding noise: the iteration has converged
/// as far as floating point allows, even if it no longer contracts.
const ROUNDOFF_FLOOR: f64 = 1e3 * f64::EPSILON;

/// The implicit-midpoint stepper: state, Jacobian and factorised iteration matrix, all
/// allocated once.
#[derive(Debug, Clone)]
pub(crate) struct MidpointStepper {
    dim: usize,
    newton_tolerance: f64,
    max_iterations: usize,
    /// Ends of the last accepted step and the candidate's time.
    ends: StepEnds,
    y_new: Vec<f64>,
    /// The increment `z = y_new − y`.
    z: Vec<f64>,
    /// Newton right-hand side, then update.
    delta: Vec<f64>,
    /// Stage `y + z/2`, also finite-difference scratch.
    stage: Vec<f64>,
    /// `F` at the stage, also finite-difference scratch.
    k: Vec<f64>,
    jac: DMatrix<f64>,
    lu: LuFactors<f64>,
    /// Whether `jac` was computed at the current `(t, y)`.
    jac_current: bool,
    /// Whether `jac` holds a Jacobian at all.
    jac_valid: bool,
    /// Whether the next attempt should compute a fresh Jacobian (slow convergence).
    jac_refresh: bool,
    /// Step size `h` of the factorised `I − (h/2) J`, NaN if none.
    lu_h: f64,
}

impl MidpointStepper {
    fn new(dim: usize, newton_tolerance: f64, max_iterations: usize) -> Self {
        Self {
            dim,
            newton_tolerance,
            max_iterations,
            ends: StepEnds::new(dim),
            y_new: vec![0.0; dim],
            z: vec![0.0; dim],
            delta: vec![0.0; dim],
            stage: vec![0.0; dim],
            k: vec![0.0; dim],
            jac: DMatrix::zeros(dim, dim),
            lu: LuFactors::new(dim),
            jac_current: false,
            jac_valid: false,
            jac_refresh: false,
            lu_h: f64::NAN,
        }
    }

    /// Computes `∂F/∂y` at the current state.
    fn update_jacobian(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        rhs.jacobian(
            self.ends.t,
            &self.ends.y,
            &self.ends.f,
            &mut self.jac,
            &mut self.stage,
            &mut self.k,
        )?;
        self.jac_current = true;
        self.jac_valid = true;
        self.jac_refresh = false;
        self.lu_h = f64::NAN;
        Ok(())
    }

    /// Factors `I − (h/2) J` unless it already is for this `h` (to within rounding: fixed
    /// steps `t0 + k dt` differ from `dt` in the last bits, and the iteration matrix of a
    /// simplified Newton method need not be exact).
    fn factor(&mut self, rhs: &mut CheckedRhs<'_>, h: f64) -> Result<(), StepFailure> {
        if (self.lu_h - h).abs() <= SAME_STEP * h.abs() {
            return Ok(());
        }
        let matrix = self.lu.matrix_mut();
        matrix.copy_from(&self.jac);
        *matrix *= -0.5 * h;
        for i in 0..self.dim {
            matrix[(i, i)] += 1.0;
        }
        rhs.count_lu();
        self.lu_h = f64::NAN;
        self.lu
            .factor()
            .map_err(|_| StepFailure::SingularIterationMatrix { t: self.ends.t })?;
        self.lu_h = h;
        Ok(())
    }

    /// Simplified Newton for `z = h F(t + h/2, y + z/2)` from `z = h F(t, y)`; returns the
    /// number of evaluations of `F`, or `Err((iterations, last residual norm))` if it does
    /// not converge.
    ///
    /// Convergence is judged on the residual `r = h F(t + h/2, y + z/2) − z` itself rather
    /// than on the size of the updates: a badly wrong Jacobian makes the updates small without
    /// making `z` right, and the residual shows it.
    fn newton(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        h: f64,
        weights: &ErrorWeights,
    ) -> Result<Result<usize, (usize, f64)>, StepFailure> {
        let n = self.dim;
        let t_mid = self.ends.t + 0.5 * h;
        for (z, &f) in self.z.iter_mut().zip(&self.ends.f) {
            *z = h * f;
        }
        let mut previous = f64::NAN;
        let mut stalls = 0;
        for iteration in 1..=self.max_iterations {
            for i in 0..n {
                self.stage[i] = self.ends.y[i] + 0.5 * self.z[i];
            }
            rhs.eval(t_mid, &self.stage, &mut self.k)?;
            let mut residual: f64 = 0.0;
            for i in 0..n {
                self.delta[i] = h * self.k[i] - self.z[i];
                if self.delta[i] != 0.0 {
                    let scale = self.ends.y[i]
                        .abs()
                        .max((self.ends.y[i] + self.z[i]).abs())
                        .max(weights.atol[i]);
                    residual = residual.max(self.delta[i].abs() / scale);
                }
            }
            if !residual.is_finite() {
                return Ok(Err((iteration, residual)));
            }
            if residual <= self.newton_tolerance {
                return Ok(Ok(iteration));
            }
            if iteration > 1 && residual >= 0.99 * previous {
                // No contraction: rounding noise if tiny, else divergence. The max norm can
                // stall once by coincidence (the largest relative residual moving to another
                // component of the same size, as on the double pendulum's first step), so only
                // a second stall in a row counts as a failure.
                if residual <= ROUNDOFF_FLOOR {
                    return Ok(Ok(iteration));
                }
                stalls += 1;
                if stalls >= 2 {
                    return Ok(Err((iteration, residual)));
                }
            } else {
                stalls = 0;
            }
            // (I − (h/2) J) Δ = r,  z ← z + Δ.
            self.lu.solve_in_place(&mut self.delta);
            for (z, d) in self.z.iter_mut().zip(&self.delta) {
                *z += d;
            }
            previous = residual;
        }
        Ok(Err((self.max_iterations, previous)))
    }
}

impl DenseOutput for MidpointStepper {
    fn interval(&self) -> (f64, f64) {
        self.ends.interval()
    }

    /// The cubic Hermite interpolant of the step's ends and derivatives (order 3, above the
    /// method's 2).
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        self.ends.hermite(t, out);
    }
}

impl Stepper for MidpointStepper {
    stepper_state_from_ends!();

    fn reset(&mut self, rhs: &mut CheckedRhs<'_>, t0: f64, y0: &[f64]) -> Result<(), StepFailure> {
        self.ends.reset(rhs, t0, y0)?;
        self.jac_valid = false;
        self.jac_current = false;
        self.lu_h = f64::NAN;
        Ok(())
    }

    fn attempt(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        t_new: f64,
        weights: &ErrorWeights,
        _estimate_error: bool,
    ) -> Result<Option<f64>, StepFailure> {
        let h = t_new - self.ends.t;
        self.ends.t_new = t_new;
        loop {
            if !self.jac_valid || (self.jac_refresh && !self.jac_current) {
                self.update_jacobian(rhs)?;
            }
            let outcome = match self.factor(rhs, h) {
                Ok(()) => self.newton(rhs, h, weights)?,
                Err(failure) if self.jac_current => return Err(failure),
                Err(_) => Err((0, f64::NAN)),
            };
            match outcome {
                Ok(iterations) => {
                    self.jac_refresh = iterations > SLOW_NEWTON;
                    break;
                }
                // A Jacobian from an earlier step may be too far off: retry once with a
                // fresh one before giving up.
                Err(_) if !self.jac_current => self.jac_refresh = true,
                Err((iterations, residual_norm)) => {
                    return Err(StepFailure::Newton {
                        t: self.ends.t,
                        iterations,
                        residual_norm,
                        retry_factor: 0.5,
                    });
                }
            }
        }
        for i in 0..self.dim {
            self.y_new[i] = self.ends.y[i] + self.z[i];
        }
        if let Some(index) = self.y_new.iter().position(|v| !v.is_finite()) {
            return Err(StepFailure::NonFiniteState { t: t_new, index });
        }
        Ok(None)
    }

    fn accept(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        rhs.eval(self.ends.t_new, &self.y_new, &mut self.ends.f_prev)?;
        swap(&mut self.ends.f, &mut self.ends.f_prev);
        swap(&mut self.ends.y_prev, &mut self.ends.y);
        swap(&mut self.ends.y, &mut self.y_new);
        self.ends.t_prev = self.ends.t;
        self.ends.t = self.ends.t_new;
        self.jac_current = false;
        Ok(())
    }
}

/// The implicit midpoint rule `y₁ = y + h F(t + h/2, (y + y₁)/2)`, order 2, constant steps.
///
/// It is symplectic for every Hamiltonian system, whatever the form of the mass matrix, and
/// conserves every quadratic invariant exactly (the energy of a linear oscillator, angular
/// momentum); it is A-stable and symmetric, and its numerical dissipation is zero. For a
/// mechanical model in the form `y = [q; q̇]` the symplectic structure is that of
/// `(q, p = M(q) q̇)`, to which the map in `(q, q̇)` is conjugate.
///
/// Each step solves for the increment `z = y₁ − y` by simplified Newton iterations
///
/// ```text
/// (I − (h/2) J) Δ = h F(t + h/2, y + z/2) − z,   z ← z + Δ,
/// ```
///
/// from `z = h F(t, y)`, with `J = ∂F/∂y` from [`OdeSystem::jacobian`] (the generated exact
/// Jacobians for models through [`FirstOrder`](crate::FirstOrder); finite differences of `F`
/// otherwise). `J` and the LU factors of `I − (h/2) J` are kept from step to step while
/// Newton converges in at most three iterations; the iteration matrix is refactored only when
/// `J` or `h` changes. The iteration stops when the residual `h F(t + h/2, y + z/2) − z` is
/// at most the Newton tolerance (default 1e-12) in the max norm relative to
/// `max(|yᵢ|, |y₁ᵢ|, atolᵢ)`, so the geometric properties hold to about that level. It fails
/// when the residual stops contracting (by less than 1 %, twice in a row) above rounding level, or after the
/// allowed iterations (default 10). `atol` is the only tolerance used (as the scale of
/// components near zero); `rtol` and `fixed_step` are not.
///
/// Steps are `dt` (default `(t_end − t0)/1000`), the last one shortened to land on `t_end`.
/// Per step: one evaluation of `F` per Newton iteration (the last one confirms the residual),
/// one at the new state (for the next predictor and the dense output, the cubic Hermite
/// interpolant of the step's ends).
///
/// # Errors
/// Besides the errors of every method: [`IntegrationError::NewtonDidNotConverge`] at the start
/// of a step whose iteration diverged or did not converge in the allowed iterations, even
/// with a fresh Jacobian; and
/// [`IntegrationError::SingularIterationMatrix`] if `I − (h/2) J` is singular. With fixed
/// steps there is no retry with a smaller step: reduce `dt`.
///
/// [`IntegrationError::NewtonDidNotConverge`]: super::IntegrationError::NewtonDidNotConverge
/// [`IntegrationError::SingularIterationMatrix`]: super::IntegrationError::SingularIterationMatrix
///
/// # Examples
/// ```
/// use eomgen_runtime::{ImplicitMidpoint, Integrator, IntegratorOptions, OdeFn, OutputTimes};
///
/// // The pendulum q̈ = −sin q: the energy error stays bounded over many periods.
/// let mut pendulum = OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
///     dy[0] = y[1];
///     dy[1] = -y[0].sin();
/// });
/// let energy = |y: &[f64]| y[1] * y[1] / 2.0 - y[0].cos();
/// let options = IntegratorOptions::default().with_dt(0.1);
/// let solution = ImplicitMidpoint::new()
///     .integrate(&mut pendulum, 0.0, &[1.0, 0.0], 100.0, &OutputTimes::Steps, &options)?;
/// let e0 = energy(&[1.0, 0.0]);
/// assert!(solution.iter().all(|(_, y)| (energy(y) - e0).abs() < 1e-3));
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
///
/// # References
/// - E. Hairer, C. Lubich, G. Wanner, *Geometric Numerical Integration*, 2nd ed., Springer,
///   2006, §I.1.2, §IV.2 (quadratic invariants), §VI.3 (symplecticity) and §VIII.6 (the
///   iteration), doi:10.1007/3-540-30666-8.
/// - E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer,
///   1996, §IV.8 (simplified Newton iterations), doi:10.1007/978-3-642-05221-7.
#[derive(Debug, Clone)]
pub struct ImplicitMidpoint {
    newton_tolerance: f64,
    max_newton_iterations: usize,
}

impl Default for ImplicitMidpoint {
    fn default() -> Self {
        Self {
            newton_tolerance: NEWTON_TOLERANCE,
            max_newton_iterations: MAX_NEWTON_ITERATIONS,
        }
    }
}

impl ImplicitMidpoint {
    /// The method with Newton tolerance 1e-12 and at most 10 iterations per step.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the Newton tolerance on the relative residual (see the type's docs), `> 0`
    /// (default: 1e-12).
    pub fn with_newton_tolerance(mut self, newton_tolerance: f64) -> Self {
        self.newton_tolerance = newton_tolerance;
        self
    }

    /// Sets the most Newton iterations per step, `≥ 1` (default: 10).
    pub fn with_max_newton_iterations(mut self, max_newton_iterations: usize) -> Self {
        self.max_newton_iterations = max_newton_iterations;
        self
    }
}

impl Integrator for ImplicitMidpoint {
    fn name(&self) -> &'static str {
        "implicit-midpoint"
    }

    fn order(&self) -> u32 {
        2
    }
}

impl driver::Method for ImplicitMidpoint {
    fn run(
        &mut self,
        problem: &Problem<'_>,
        system: &mut dyn OdeSystem,
    ) -> Result<Solution, IntegrationFailure> {
        let options = problem.options;
        let (tolerance, iterations) = (self.newton_tolerance, self.max_newton_iterations.max(1));
        driver::run(problem, system, Control::Fixed, |shape| {
            check_absolute_tolerance(options, shape.dim, "implicit midpoint")?;
            Ok(MidpointStepper::new(shape.dim, tolerance, iterations))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{IntegrationError, Integrator, IntegratorOptions, OutputTimes};
    use crate::ode::OdeFn;
    use crate::ode::tests::Linear;

    /// On ẏ = λy one step is the (1,1) Padé approximant (1 + hλ/2)/(1 − hλ/2) of e^(hλ); the
    /// differenced Jacobian is exact to about 1e-8 here, so Newton converges in a few
    /// iterations and keeps the factorisation for the next step.
    #[test]
    fn linear_step_is_the_pade_approximant() {
        let lambda = -3.0;
        let mut system = OdeFn::new(1, move |_t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = lambda * y[0];
        });
        let mut rhs = CheckedRhs::new(&mut system);
        let mut stepper = MidpointStepper::new(1, NEWTON_TOLERANCE, MAX_NEWTON_ITERATIONS);
        stepper.reset(&mut rhs, 0.0, &[1.0]).unwrap();
        let weights = ErrorWeights::uniform(1, 1e-6, 1e-9);
        let h = 0.1;
        stepper.attempt(&mut rhs, h, &weights, false).unwrap();
        stepper.accept(&mut rhs).unwrap();
        let pade = (1.0 + h * lambda / 2.0) / (1.0 - h * lambda / 2.0);
        assert!((stepper.y()[0] - pade).abs() < 1e-14);
        stepper.attempt(&mut rhs, 2.0 * h, &weights, false).unwrap();
        assert_eq!(rhs.jacobian_evals(), 1);
        assert_eq!(rhs.lu_decompositions(), 1);
    }

    /// On a linear system with its exact Jacobian one Newton correction solves the step
    /// exactly, so each step costs three evaluations of `F` (the correction's, the check's and
    /// `F` at the new state, which the dense output and the next guess use; plus `F(t₀)`),
    /// and the iteration matrix `I − (h/2) J` is factored once per step size: steps of 0.1
    /// over [0, 1.05] are ten of 0.1 and a last of 0.05, two factorisations. The derivative
    /// kept at the step's end is `F` there.
    #[test]
    fn a_linear_step_takes_one_correction_and_one_factorisation_per_step_size() {
        let lambda = -3.0;
        let mut system = Linear(lambda);
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(0.1);
        let solution = ImplicitMidpoint::new()
            .integrate(
                &mut system,
                0.0,
                &[1.0],
                1.05,
                &OutputTimes::Steps,
                &options,
            )
            .unwrap();
        assert_eq!(solution.stats.steps, 11);
        assert_eq!(solution.stats.rhs_evals, 1 + 3 * 11);
        assert_eq!(solution.stats.jacobian_evals, 1);
        assert_eq!(solution.stats.lu_decompositions, 2);
        // The same at steps of 1e-6 (ten of them and a last of 5e-7): the test of "the same
        // step" is relative to `h`, so a halved small step is still a new factorisation.
        let small = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(1e-6);
        let solution = ImplicitMidpoint::new()
            .integrate(
                &mut system,
                0.0,
                &[1.0],
                1.05e-5,
                &OutputTimes::Steps,
                &small,
            )
            .unwrap();
        assert_eq!(solution.stats.steps, 11);
        assert_eq!(solution.stats.lu_decompositions, 2);

        let mut rhs = CheckedRhs::new(&mut system);
        let mut stepper = MidpointStepper::new(1, NEWTON_TOLERANCE, MAX_NEWTON_ITERATIONS);
        stepper.reset(&mut rhs, 0.0, &[1.0]).unwrap();
        let weights = ErrorWeights::uniform(1, 1e-6, 1e-9);
        stepper.attempt(&mut rhs, 0.1, &weights, false).unwrap();
        stepper.accept(&mut rhs).unwrap();
        assert_eq!(stepper.derivative(), [lambda * stepper.y()[0]]);
        assert_eq!(rhs.jacobian_evals(), 1);
    }

    /// Implicit midpoint with the default Newton options, fixed steps of `dt` from `y0` at
    /// `t = 0` to `t_end`.
    fn fixed_steps(
        system: &mut dyn OdeSystem,
        y0: f64,
        dt: f64,
        t_end: f64,
    ) -> Result<Solution, IntegrationError> {
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(dt);
        ImplicitMidpoint::new()
            .integrate(system, 0.0, &[y0], t_end, &OutputTimes::Steps, &options)
            .map_err(|failure| failure.error)
    }

    /// `ẏ = a(t) y` with `a = before` for `t < at` and `after` from `at` on, with its exact
    /// Jacobian.
    struct Switched {
        at: f64,
        before: f64,
        after: f64,
    }

    impl Switched {
        fn a(&self, t: f64) -> f64 {
            if t < self.at { self.before } else { self.after }
        }
    }

    impl OdeSystem for Switched {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), crate::ode::RhsError> {
            dy[0] = self.a(t) * y[0];
            Ok(())
        }
        fn jacobian(
            &mut self,
            t: f64,
            _y: &[f64],
            jac: &mut [f64],
        ) -> Result<bool, crate::ode::RhsError> {
            jac[0] = self.a(t);
            Ok(true)
        }
    }

    /// A Jacobian kept from an earlier step that fails the iteration is replaced before the
    /// step is given up: `ẏ = a(t) y` with `a` switching from 0 to −100 at t = 0.2, steps of
    /// 0.25. The second step starts with the first step's `J = 0`, with which the simplified
    /// Newton iteration multiplies its error by `h a / 2 = 12.5`; the fresh `J = −100` solves
    /// the linear stage equation, and the step ends at the rule's value.
    #[test]
    fn a_stale_jacobian_that_fails_is_replaced() {
        let mut switched = Switched {
            at: 0.2,
            before: 0.0,
            after: -100.0,
        };
        let solution = fixed_steps(&mut switched, 1.0, 0.25, 0.5).unwrap();
        let rule = (1.0 - 0.25 * 100.0 / 2.0) / (1.0 + 0.25 * 100.0 / 2.0);
        assert!((solution.y[2] - rule).abs() < 1e-12, "{}", solution.y[2]);
        assert_eq!(solution.stats.jacobian_evals, 2);
    }

    /// The Newton options are the ones given: one iteration cannot solve a nonlinear stage
    /// equation (`ẏ = −y²`), and a loose tolerance stops the iteration sooner than the
    /// default one.
    #[test]
    fn newton_options_are_kept() {
        let mut system = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0] * y[0]);
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(0.1);
        let mut run = |method: ImplicitMidpoint| {
            method
                .clone()
                .integrate(&mut system, 0.0, &[1.0], 1.0, &OutputTimes::Steps, &options)
        };
        let failure = run(ImplicitMidpoint::new().with_max_newton_iterations(1)).unwrap_err();
        assert!(
            matches!(
                failure.error,
                IntegrationError::NewtonDidNotConverge { iterations: 1, .. }
            ),
            "{:?}",
            failure.error
        );
        let tight = run(ImplicitMidpoint::new()).unwrap().stats.rhs_evals;
        let loose = run(ImplicitMidpoint::new().with_newton_tolerance(1e-3))
            .unwrap()
            .stats
            .rhs_evals;
        assert!(loose < tight, "{loose} vs {tight}");
    }

    /// `I − (h/2) J` singular with a Jacobian evaluated at the step's start (`ẏ = 4y`,
    /// `h = 0.5`) is reported as such, at the step's start: a fresh Jacobian cannot help.
    #[test]
    fn a_singular_iteration_matrix_with_a_current_jacobian_is_reported() {
        let mut system = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = 4.0 * y[0]);
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(0.5);
        let failure = ImplicitMidpoint::new()
            .integrate(&mut system, 0.0, &[1.0], 1.0, &OutputTimes::Steps, &options)
            .unwrap_err();
        assert!(
            matches!(failure.error, IntegrationError::SingularIterationMatrix { t } if t == 0.0),
            "{:?}",
            failure.error
        );
    }

    /// `ẏ = λy` whose `jacobian` returns `μ` instead of `λ`. The simplified Newton iteration
    /// is then a linear fixed-point iteration: each correction `Δ = r/(1 − hμ/2)` multiplies
    /// the residual `r = hλ(y + z/2) − z` by exactly `ρ = h(λ − μ)/(2 − hμ)`, so the number of
    /// iterations a step takes can be worked out by hand.
    struct WrongJacobian {
        lambda: f64,
        mu: f64,
    }

    impl WrongJacobian {
        /// The system whose iteration contracts by `rho` at step `h`:
        /// `μ = (hλ − 2ρ)/(h(1 − ρ))`.
        fn contracting(lambda: f64, h: f64, rho: f64) -> Self {
            let mu = (h * lambda - 2.0 * rho) / (h * (1.0 - rho));
            Self { lambda, mu }
        }

        /// `steps` fixed steps of `h` from `y0` with the default Newton options.
        fn run(&mut self, y0: f64, h: f64, steps: usize) -> Result<Solution, IntegrationError> {
            fixed_steps(self, y0, h, steps as f64 * h)
        }
    }

    impl OdeSystem for WrongJacobian {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), crate::ode::RhsError> {
            dy[0] = self.lambda * y[0];
            Ok(())
        }
        fn jacobian(
            &mut self,
            _t: f64,
            _y: &[f64],
            jac: &mut [f64],
        ) -> Result<bool, crate::ode::RhsError> {
            jac[0] = self.mu;
            Ok(true)
        }
    }

    /// The iteration starts from `z = h F(t, y)` and stops at the first iterate whose residual
    /// relative to the state is within the tolerance, whatever the state's scale.
    ///
    /// `ẏ = −y`, `h = 0.01`, contraction `ρ = 3·10⁻⁵`: from `z = h F` the first residual is
    /// `h²λ² |y|/2`, relative `5·10⁻⁵` (`|y₁| < |y|`), then `1.5·10⁻⁹` and
    /// `4.5·10⁻¹⁴ ≤ 10⁻¹²`: three evaluations of `F` per step, plus one at its end. Three
    /// iterations are not slow, so the one Jacobian serves all ten steps. The same from
    /// `y₀ = 10⁻³`, 1 and 10³: the residual is relative. (From `z = 0` the residuals would be
    /// `h|λ| = 10⁻²`, `3·10⁻⁷` and `9·10⁻¹²`, and the step would need four iterations.)
    #[test]
    fn newton_stops_at_the_first_iterate_within_the_tolerance_at_every_scale() {
        let (h, steps) = (0.01, 10);
        for y0 in [1e-3, 1.0, 1e3] {
            let solution = WrongJacobian::contracting(-1.0, h, 3e-5)
                .run(y0, h, steps)
                .unwrap();
            assert_eq!(solution.stats.steps, steps, "y0 = {y0}");
            assert_eq!(solution.stats.rhs_evals, 1 + steps * (3 + 1), "y0 = {y0}");
            assert_eq!(solution.stats.jacobian_evals, 1, "y0 = {y0}");
            let rule = ((1.0 - h / 2.0) / (1.0 + h / 2.0)).powi(steps as i32);
            let (_, y) = solution.last().unwrap();
            // Each step's residual is within the Newton tolerance 1e-12 (relative), so ten
            // steps stay within 1e-11 of the rule.
            assert!((y[0] / y0 - rule).abs() < 1e-11, "y0 = {y0}: {}", y[0] / y0);
        }
    }

    /// A step that needs more than three iterations fetches a fresh Jacobian for the next one:
    /// with `ρ = 10⁻³` the residuals are `5·10⁻⁵ ρ^(k−1)`, within `10⁻¹²` at `k = 4`, so each of
    /// the five steps takes four iterations and each after the first a new Jacobian (here the
    /// same wrong one).
    #[test]
    fn a_slow_iteration_fetches_a_fresh_jacobian_for_the_next_step() {
        let (h, steps) = (0.01, 5);
        let solution = WrongJacobian::contracting(-1.0, h, 1e-3)
            .run(1.0, h, steps)
            .unwrap();
        assert_eq!(solution.stats.rhs_evals, 1 + steps * (4 + 1));
        assert_eq!(solution.stats.jacobian_evals, steps);
    }

    /// The residual is measured against `max(|y|, |y + z|)`, the larger of the state and the
    /// current iterate of the new state: `ẏ = y`, `h = 1` (`y₁ = 3y`, `z → 2y`), `y₀ = 1`,
    /// contraction `ρ = 2.2·10⁻⁶`. The residuals are `0.5 ρ^(k−1)` against a scale of 3 (from
    /// the second iterate on): at `k = 3`, `0.5 ρ²/3 = 8.1·10⁻¹³ ≤ 10⁻¹²`, so the step takes
    /// three iterations. Against `|y|` alone, or `|y − z|`, or `|y z|` (scales 1, 1 and 2) it
    /// would take four.
    #[test]
    fn the_residual_is_relative_to_the_larger_of_the_state_and_its_new_value() {
        let solution = WrongJacobian::contracting(1.0, 1.0, 2.2e-6)
            .run(1.0, 1.0, 1)
            .unwrap();
        assert_eq!(solution.stats.rhs_evals, 1 + 3 + 1);
        let (_, y) = solution.last().unwrap();
        assert!((y[0] - 3.0).abs() < 1e-11, "{}", y[0]);
    }

    /// An iteration that stops contracting fails at its second stall in a row: with
    /// `ρ = 0.995` each residual is at least 0.99 times the one before, so iterations 2 and 3
    /// stall and the step fails after three iterations (with fixed steps, at once).
    #[test]
    fn an_iteration_that_stalls_twice_fails() {
        let h = 0.01;
        let error = WrongJacobian::contracting(-1.0, h, 0.995)
            .run(1.0, h, 1)
            .unwrap_err();
        assert!(
            matches!(
                error,
                IntegrationError::NewtonDidNotConverge {
                    t: 0.0,
                    iterations: 3,
                    ..
                }
            ),
            "{error:?}"
        );
    }

    /// A Jacobian kept from an earlier step whose iteration matrix is singular at a new step
    /// size is replaced rather than reported: `ẏ = a(t) y` with `a = 4` before `t = 2` and 1
    /// after, steps of 1 to `t = 2.5`. The last step, of 0.5, would factor `1 − 0.25 · 4 = 0`
    /// with the kept `J = 4`; the fresh `J = 1` gives 0.75, and the run ends at the rule's
    /// value `(−3)² · 5/3 = 15`.
    #[test]
    fn a_stale_jacobian_singular_at_a_new_step_size_is_replaced() {
        let mut switched = Switched {
            at: 2.0,
            before: 4.0,
            after: 1.0,
        };
        let solution = fixed_steps(&mut switched, 1.0, 1.0, 2.5).unwrap();
        let (t, y) = solution.last().unwrap();
        assert_eq!(t, 2.5);
        assert!((y[0] - 15.0).abs() < 1e-12, "{}", y[0]);
        assert_eq!(solution.stats.jacobian_evals, 2);
    }
}
