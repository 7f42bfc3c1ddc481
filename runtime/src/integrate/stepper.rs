//! The interface between the integration loop and a method: a [`Stepper`] takes one step at a
//! time and keeps a [`DenseOutput`] over the last accepted one.
//!
//! A new method (Euler, midpoint and Bogacki–Shampine are tableaus; DOP853, symplectic and
//! implicit methods are steppers of their own) implements [`Stepper`] and reuses the loop in
//! `driver`: validation, fixed and adaptive step sequences, output, statistics and errors.

use nalgebra::DMatrix;

use crate::ode::{EventSpec, OdeSystem, RhsError};

use super::controller::NewtonWork;
use super::dense_output::{DenseOutput, hermite};
use super::error::IntegrationError;
use super::options::ErrorWeights;

/// Why a step attempt produced no usable candidate.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum StepFailure {
    /// The right-hand side (or its Jacobian) failed, or was not finite, at time `t`.
    Rhs { t: f64, error: RhsError },
    /// The candidate state is not finite at time `t`.
    NonFiniteState { t: f64, index: usize },
    /// The Newton iteration for the stages of the step from `t` diverged, converged too
    /// slowly, or used up its iterations; a step `retry_factor` times as large may converge.
    Newton {
        t: f64,
        iterations: usize,
        residual_norm: f64,
        retry_factor: f64,
    },
    /// The Newton iteration matrix of the step from `t` was exactly singular (an eigenvalue
    /// of the Jacobian coincides with one of the method's shifted eigenvalues); a different
    /// step size moves the shift.
    SingularIterationMatrix { t: f64 },
}

impl StepFailure {
    /// Whether a smaller step may succeed: non-finite values often come from a step so large
    /// that a stage leaves the region where `F` is defined, and Newton converges for small
    /// enough steps, whereas a singular mass matrix is a property of the model at that
    /// configuration.
    pub(crate) fn is_recoverable(&self) -> bool {
        match self {
            StepFailure::Rhs {
                error:
                    RhsError::SingularMassMatrix
                    | RhsError::SingularConstraintMatrix
                    | RhsError::ProjectionFailed { .. }
                    | RhsError::EventNotFinite { .. },
                ..
            } => false,
            StepFailure::Rhs {
                error: RhsError::NonFinite { .. } | RhsError::JacobianNonFinite { .. },
                ..
            }
            | StepFailure::NonFiniteState { .. }
            | StepFailure::Newton { .. }
            | StepFailure::SingularIterationMatrix { .. } => true,
        }
    }

    /// The factor by which the failed step should shrink, when the method knows better than
    /// the step-size controller (which otherwise sees an infinite error).
    pub(crate) fn retry_factor(&self) -> Option<f64> {
        match self {
            StepFailure::Newton { retry_factor, .. } => Some(*retry_factor),
            StepFailure::SingularIterationMatrix { .. } => Some(0.5),
            StepFailure::Rhs { .. } | StepFailure::NonFiniteState { .. } => None,
        }
    }

    /// The error an integration reports for this failure.
    pub(crate) fn into_error(self) -> IntegrationError {
        match self {
            StepFailure::Rhs {
                t,
                error: RhsError::SingularMassMatrix,
            } => IntegrationError::SingularMassMatrix { t },
            StepFailure::Rhs {
                t,
                error: RhsError::SingularConstraintMatrix,
            } => IntegrationError::SingularConstraintMatrix { t },
            StepFailure::Rhs {
                t,
                error: RhsError::ProjectionFailed { residual },
            } => IntegrationError::ProjectionFailed { t, residual },
            StepFailure::Rhs {
                t,
                error: RhsError::NonFinite { index },
            } => IntegrationError::RhsNonFinite { t, index },
            StepFailure::Rhs {
                t,
                error: RhsError::JacobianNonFinite { row },
            } => IntegrationError::JacobianNonFinite { t, row },
            StepFailure::Rhs {
                t,
                error: RhsError::EventNotFinite { index },
            } => IntegrationError::EventNotFinite { t, index },
            StepFailure::NonFiniteState { t, index } => {
                IntegrationError::NonFiniteState { t, index }
            }
            StepFailure::Newton {
                t,
                iterations,
                residual_norm,
                ..
            } => IntegrationError::NewtonDidNotConverge {
                t,
                iterations,
                residual_norm,
            },
            StepFailure::SingularIterationMatrix { t } => {
                IntegrationError::SingularIterationMatrix { t }
            }
        }
    }
}

/// The times of one step attempt of an explicit Runge–Kutta method: from `t` to `t_new`, of
/// size `h = t_new − t`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AttemptTimes {
    pub(crate) t: f64,
    pub(crate) h: f64,
    pub(crate) t_new: f64,
}

impl AttemptTimes {
    /// The attempt from `t` to `t_new`.
    pub(crate) fn new(t: f64, t_new: f64) -> Self {
        Self {
            t,
            h: t_new - t,
            t_new,
        }
    }

    /// The time of a stage at node `c`: `t + c h`, and exactly `t_new` for `c = 1` (so that
    /// the last stages of a step are evaluated at the time the step ends on, not one rounding
    /// away from it).
    #[inline(always)]
    pub(crate) fn at(self, c: f64) -> f64 {
        if c == 1.0 {
            self.t_new
        } else {
            self.t + c * self.h
        }
    }
}

pub(crate) use crate::ode::first_non_finite;

/// The system as a stepper sees it: every evaluation of `F` counted and checked for
/// finiteness, so that no method can forget either; Jacobians (exact, or differenced when the
/// system has none) and factorisations of iteration matrices counted as well.
pub(crate) struct CheckedRhs<'a> {
    system: &'a mut dyn OdeSystem,
    /// [`OdeSystem::corrects_state`], asked once.
    corrects_state: bool,
    evals: usize,
    jacobian_evals: usize,
    lu_decompositions: usize,
    event_evals: usize,
    taylor_series: usize,
}

impl<'a> CheckedRhs<'a> {
    /// Wraps `system`, with nothing counted yet.
    pub(crate) fn new(system: &'a mut dyn OdeSystem) -> Self {
        Self {
            corrects_state: system.corrects_state(),
            system,
            evals: 0,
            jacobian_evals: 0,
            lu_decompositions: 0,
            event_evals: 0,
            taylor_series: 0,
        }
    }

    /// Number of evaluations of `F` so far (including those of differenced Jacobians).
    pub(crate) fn evals(&self) -> usize {
        self.evals
    }

    /// Number of Jacobians so far.
    pub(crate) fn jacobian_evals(&self) -> usize {
        self.jacobian_evals
    }

    /// Number of factorisations counted with [`count_lu`](Self::count_lu) so far.
    pub(crate) fn lu_decompositions(&self) -> usize {
        self.lu_decompositions
    }

    /// Number of Taylor series computed so far ([`Self::taylor_coefficients`]).
    pub(crate) fn taylor_series(&self) -> usize {
        self.taylor_series
    }

    /// The Taylor coefficients of the solution through `(t, y)` up to `order`
    /// ([`OdeSystem::taylor_coefficients`]), counted.
    ///
    /// # Errors
    /// [`StepFailure::Rhs`] at `t` if the series cannot be computed or is not finite.
    pub(crate) fn taylor_coefficients(
        &mut self,
        t: f64,
        y: &[f64],
        order: usize,
        out: &mut [f64],
    ) -> Result<(), StepFailure> {
        self.taylor_series += 1;
        self.system
            .taylor_coefficients(t, y, order, out)
            .map_err(|error| StepFailure::Rhs { t, error })
    }

    /// The largest step `≤ h` on the branches of the last series' roots and powers
    /// ([`OdeSystem::taylor_branch_step`]).
    pub(crate) fn taylor_branch_step(&self, order: usize, h: f64) -> f64 {
        self.system.taylor_branch_step(order, h)
    }

    /// Number of evaluations of the event functions so far.
    pub(crate) fn event_evals(&self) -> usize {
        self.event_evals
    }

    /// The system's event functions ([`OdeSystem::event_specs`]).
    pub(crate) fn event_specs(&self) -> &[EventSpec] {
        self.system.event_specs()
    }

    /// Evaluates the event functions `g(t, y)` into `g`.
    ///
    /// # Errors
    /// [`StepFailure::Rhs`] at `t` if the system fails or a value is NaN (an infinite value
    /// still has a sign and is allowed).
    pub(crate) fn event_values(
        &mut self,
        t: f64,
        y: &[f64],
        g: &mut [f64],
    ) -> Result<(), StepFailure> {
        self.event_evals += 1;
        self.system
            .event_values(t, y, g)
            .map_err(|error| StepFailure::Rhs { t, error })?;
        match g.iter().position(|v| v.is_nan()) {
            Some(index) => Err(StepFailure::Rhs {
                t,
                error: RhsError::EventNotFinite { index },
            }),
            None => Ok(()),
        }
    }

    /// Counts one factorisation of an iteration matrix (for an implicit Runge–Kutta method,
    /// the real and the complex one together count once, as in Hairer's RADAU5).
    pub(crate) fn count_lu(&mut self) {
        self.lu_decompositions += 1;
    }

    /// Whether the system's correction after a step can change a state
    /// ([`OdeSystem::corrects_state`]): if not, the driver neither copies the state nor calls
    /// [`Self::after_step`].
    pub(crate) fn corrects_state(&self) -> bool {
        self.corrects_state
    }

    /// The system's correction after an accepted step ([`OdeSystem::after_step`]), applied
    /// to `y` (a copy of the stepper's state).
    ///
    /// # Errors
    /// [`StepFailure::Rhs`] at `t` if the correction fails.
    pub(crate) fn after_step(&mut self, t: f64, y: &mut [f64]) -> Result<bool, StepFailure> {
        self.system
            .after_step(t, y)
            .map_err(|error| StepFailure::Rhs { t, error })
    }

    /// Evaluates `dy = F(t, y)`.
    ///
    /// # Errors
    /// [`StepFailure::Rhs`] at `t` if the system reports an error or `dy` has a NaN or
    /// infinite component.
    pub(crate) fn eval(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), StepFailure> {
        self.evals += 1;
        self.system
            .rhs(t, y, dy)
            .map_err(|error| StepFailure::Rhs { t, error })?;
        match first_non_finite(dy) {
            Some(index) => Err(StepFailure::Rhs {
                t,
                error: RhsError::NonFinite { index },
            }),
            None => Ok(()),
        }
    }

    /// Evaluates stage `dy = F(t, y)` of an explicit Runge–Kutta step, counted but *not*
    /// checked for finiteness: the stepper checks its stages once per attempt with
    /// [`check_stages`](Self::check_stages) (when it estimates the error, only the stages
    /// without weight in the candidate and the estimate, and all of them once the candidate
    /// or the error norm is not finite), and hands a failure of a later stage to
    /// [`stage_failure`](Self::stage_failure), so that a stage that was not finite is still
    /// reported at its own time and component.
    ///
    /// A search for non-finite entries after every evaluation branches on data that is ready
    /// only when `F` is; on the double pendulum, checking once per attempt instead made DOP853
    /// and DP5(4) runs ~2 % faster (interleaved best-of-300 timings against ode_solvers on the
    /// same right-hand side, issue 6).
    ///
    /// # Errors
    /// [`StepFailure::Rhs`] at `t` if the system reports an error.
    #[inline]
    pub(crate) fn eval_stage(
        &mut self,
        t: f64,
        y: &[f64],
        dy: &mut [f64],
    ) -> Result<(), StepFailure> {
        self.evals += 1;
        self.system
            .rhs(t, y, dy)
            .map_err(|error| StepFailure::Rhs { t, error })
    }

    /// Checks stages evaluated by [`eval_stage`](Self::eval_stage): `stages` holds rows of
    /// `dim` values, row `r` evaluated at time `stage_time(r)`.
    ///
    /// # Errors
    /// [`StepFailure::Rhs`] with [`RhsError::NonFinite`] for the first row with a NaN or
    /// infinite entry, at that row's time (index: the component).
    pub(crate) fn check_stages(
        stages: &[f64],
        dim: usize,
        stage_time: impl Fn(usize) -> f64,
    ) -> Result<(), StepFailure> {
        match first_non_finite(stages) {
            None => Ok(()),
            Some(at) => Err(StepFailure::Rhs {
                t: stage_time(at / dim),
                error: RhsError::NonFinite { index: at % dim },
            }),
        }
    }

    /// The failure to report when evaluating a stage failed with `failure` after the stages
    /// in `earlier` (as for [`check_stages`](Self::check_stages)): a non-finite earlier stage
    /// comes first, since the later stage was evaluated at an input made from it (a singular
    /// mass matrix at a NaN configuration is then a symptom, and the step can be retried
    /// smaller).
    pub(crate) fn stage_failure(
        earlier: &[f64],
        dim: usize,
        stage_time: impl Fn(usize) -> f64,
        failure: StepFailure,
    ) -> StepFailure {
        Self::check_stages(earlier, dim, stage_time)
            .err()
            .unwrap_or(failure)
    }

    /// The Jacobian `∂F/∂y` at `(t, y)` into `jac` (`dim × dim`): the system's own, or forward
    /// differences of `F` from `f = F(t, y)` ([`forward_differences`](crate::linalg::forward_differences):
    /// RADAU5's increments, `dim` evaluations of `F`, counted as such).
    ///
    /// `work_y` and `work_f` are `dim`-entry scratch buffers.
    ///
    /// The system's exact Jacobian is replaced by those differences where it is not finite
    /// and `F` is: a derivative can have a removable singularity that `F` has not (quadratic
    /// drag `|v| v`, with `|v| = √(vₓ² + v_y²)`, has `vₓ²/|v|`, 0/0 at rest, where the
    /// derivative is 0), and the Jacobian only steers Newton's iteration.
    ///
    /// # Errors
    /// [`StepFailure::Rhs`] at `t` if the system fails, or with
    /// [`RhsError::JacobianNonFinite`] if an entry of the differences is not finite (the
    /// row).
    pub(crate) fn jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        f: &[f64],
        jac: &mut DMatrix<f64>,
        work_y: &mut [f64],
        work_f: &mut [f64],
    ) -> Result<(), StepFailure> {
        self.jacobian_evals += 1;
        let n = y.len();
        let exact = match self.system.jacobian(t, y, jac.as_mut_slice()) {
            Ok(exact) => exact,
            Err(RhsError::JacobianNonFinite { .. }) => false,
            Err(error) => return Err(StepFailure::Rhs { t, error }),
        };
        if !exact {
            crate::linalg::forward_differences(
                y,
                f,
                jac.as_mut_slice(),
                work_y,
                work_f,
                |y, f| self.eval(t, y, f),
            )?;
        }
        let bad = (0..n).find(|&i| (0..n).any(|j| !jac[(i, j)].is_finite()));
        match bad {
            Some(row) => Err(StepFailure::Rhs {
                t,
                error: RhsError::JacobianNonFinite { row },
            }),
            None => Ok(()),
        }
    }
}

/// What the stepper is given about the system before the first step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SystemShape {
    /// [`OdeSystem::dim`].
    pub(crate) dim: usize,
    /// [`OdeSystem::second_order_dim`].
    pub(crate) second_order_dim: Option<usize>,
}

/// One method's state between steps: the current `(t, y)`, `F(t, y)`, work buffers allocated
/// once, and a [`DenseOutput`] over the last accepted step.
///
/// A step is attempted ([`attempt`](Self::attempt)), then either accepted
/// ([`accept`](Self::accept)) or dropped, in which case the next attempt starts again from
/// the same state.
pub(crate) trait Stepper: DenseOutput {
    /// Current time.
    fn t(&self) -> f64;

    /// Current state, `dim` entries.
    fn y(&self) -> &[f64];

    /// `F(t, y)` at the current state, `dim` entries.
    fn derivative(&self) -> &[f64];

    /// Starts at `(t0, y0)`, evaluating `F(t0, y0)`.
    ///
    /// # Errors
    /// The failure of that evaluation.
    fn reset(&mut self, rhs: &mut CheckedRhs<'_>, t0: f64, y0: &[f64]) -> Result<(), StepFailure>;

    /// Computes a candidate step from the current state to `t_new > t`.
    ///
    /// Returns the *square* of the weighted RMS norm of the local error estimate (`≤ 1` meets
    /// the tolerances; squared because the controller needs only its logarithm, see
    /// [`StepSizeController::decide_squared`](super::StepSizeController::decide_squared)) when
    /// `estimate_error` is set and the method has an error estimator, else `None`. `weights` are the tolerances, which implicit methods also use to stop their
    /// Newton iterations.
    ///
    /// # Errors
    /// A failed or non-finite right-hand side at a stage, a non-finite candidate, or a Newton
    /// iteration that did not converge.
    fn attempt(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        t_new: f64,
        weights: &ErrorWeights,
        estimate_error: bool,
    ) -> Result<Option<f64>, StepFailure>;

    /// The Newton work of the last successful attempt, for methods that iterate (the
    /// controller adapts the step size to it); `None` (the default) for the others.
    fn newton_work(&self) -> Option<NewtonWork> {
        None
    }

    /// The step the method proposes from its current state, for methods that choose their
    /// steps a priori (the Taylor method, [`Control::Proposed`](super::driver::Control));
    /// `None` (the default) for the others.
    fn proposed_step(&self) -> Option<f64> {
        None
    }

    /// Makes the last candidate the current state, with `F` there (reused from the last stage
    /// or evaluated), and the dense output over that step.
    ///
    /// # Errors
    /// The failure of evaluating `F` at the candidate; the state is then unchanged.
    fn accept(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure>;

    /// Completes the dense output over the last accepted step, for methods whose
    /// interpolant needs more evaluations of `F` than the step (DOP853's three extra stages).
    /// Called only for steps that contain a requested output time; the default does nothing.
    ///
    /// # Errors
    /// The failure of one of those evaluations.
    fn prepare_dense_output(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        let _ = rhs;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::dop853::Dop853Stepper;
    use crate::integrate::explicit_rk::ExplicitRk;
    use crate::integrate::tableau::Tableau;
    use crate::ode::OdeFn;

    /// `ẏ = 1` in `.0` components, except that `F` is NaN for `t` in `(0.065, 0.066)`, and
    /// that it refuses a NaN state as a model with a singular mass matrix there would.
    struct NanWindow(usize);

    impl OdeSystem for NanWindow {
        fn dim(&self) -> usize {
            self.0
        }

        fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
            if y.iter().any(|v| v.is_nan()) {
                return Err(RhsError::SingularMassMatrix);
            }
            let value = if t > 0.065 && t < 0.066 {
                f64::NAN
            } else {
                1.0
            };
            dy.fill(value);
            Ok(())
        }
    }

    /// Stages are checked once per attempt, yet a non-finite stage is reported at its own
    /// time, as recoverable, and ahead of the failure it causes in a later stage (here the
    /// stage at `c = 0.651…` of DOP853 and the one at `c = 4/5` of DP5(4); the stages after
    /// them see NaN inputs). Dimension 2 takes the stages compiled for a fixed dimension, 3
    /// the general ones.
    #[test]
    fn a_non_finite_stage_is_reported_at_its_time_before_what_it_causes() {
        let expect_nan_stage_at = |failure: StepFailure, t_nan: f64| {
            assert!(failure.is_recoverable(), "{failure:?}");
            match failure {
                StepFailure::Rhs {
                    t,
                    error: RhsError::NonFinite { index: 0 },
                } => assert!((t - t_nan).abs() < 1e-15, "t = {t}"),
                other => panic!("{other:?}"),
            }
        };
        for dim in [2, 3] {
            let weights = ErrorWeights::uniform(dim, 1e-6, 1e-6);
            let y0 = vec![0.0; dim];
            // DOP853 from t = 0 with h = 0.1: stage 8 (c₈ = 0.6512820512820513) lands in the
            // window; the following stages see NaN inputs.
            let mut system = NanWindow(dim);
            let mut rhs = CheckedRhs::new(&mut system);
            let mut stepper = Dop853Stepper::new(dim);
            stepper.reset(&mut rhs, 0.0, &y0).unwrap();
            let failure = stepper.attempt(&mut rhs, 0.1, &weights, true).unwrap_err();
            expect_nan_stage_at(failure, 0.06512820512820513);
            // DP5(4) from t = 0 with h = 0.0819: stage c = 4/5 is at 0.06552; its successor
            // (c = 8/9) sees NaN and refuses it, but the NaN stage is what is reported.
            let mut system = NanWindow(dim);
            let mut rhs = CheckedRhs::new(&mut system);
            let mut stepper = ExplicitRk::new(Tableau::dopri5(), dim);
            stepper.reset(&mut rhs, 0.0, &y0).unwrap();
            let failure = stepper
                .attempt(&mut rhs, 0.0819, &weights, true)
                .unwrap_err();
            expect_nan_stage_at(failure, 0.8 * 0.0819);
        }
    }

    /// The stages compiled for a fixed dimension (DOP853 for 2, 4, 6, 8 components, DP5(4)
    /// likewise) compute the same step as the general ones: a four-component system, and the
    /// same system with a fifth, constant component (which takes the general path), give the
    /// same candidate state to a few ulps over one step.
    #[test]
    fn fixed_dimension_stages_match_the_general_ones() {
        let field = |_t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = y[2];
            dy[1] = y[3];
            dy[2] = -y[0].sin() + 0.3 * y[1];
            dy[3] = -y[1] - 0.1 * y[3] * y[0];
            if y.len() > 4 {
                dy[4] = 0.0;
            }
        };
        let y0 = [0.7, -0.2, 0.4, 1.1, 0.0];
        let h = 0.3;
        let steppers: [fn(usize) -> Box<dyn Stepper>; 2] = [
            |dim| Box::new(Dop853Stepper::new(dim)),
            |dim| Box::new(ExplicitRk::new(Tableau::dopri5(), dim)),
        ];
        for make in steppers {
            let mut candidates = Vec::new();
            for dim in [4, 5] {
                let mut system = OdeFn::new(dim, field);
                let mut rhs = CheckedRhs::new(&mut system);
                let mut stepper = make(dim);
                stepper.reset(&mut rhs, 0.0, &y0[..dim]).unwrap();
                let weights = ErrorWeights::uniform(dim, 1e-6, 1e-6);
                stepper.attempt(&mut rhs, h, &weights, true).unwrap();
                stepper.accept(&mut rhs).unwrap();
                candidates.push(stepper.y()[..4].to_vec());
            }
            for (a, b) in candidates[0].iter().zip(&candidates[1]) {
                assert!(
                    (a - b).abs() <= 4.0 * f64::EPSILON * a.abs().max(1.0),
                    "{a} vs {b}"
                );
            }
            assert_ne!(candidates[0], y0[..4].to_vec(), "the step moved");
        }
    }

    /// Without an exact Jacobian, `jacobian` differences `F` (one evaluation per column,
    /// counted) to about √ε relative accuracy; a non-finite entry is reported by its row.
    #[test]
    fn jacobian_falls_back_to_finite_differences() {
        let mut system = OdeFn::new(2, |_t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = y[0] * y[1];
            dy[1] = y[0].sin() + 3.0 * y[1];
        });
        let mut rhs = CheckedRhs::new(&mut system);
        let y = [0.7, -1.3];
        let mut f = [0.0; 2];
        rhs.eval(0.0, &y, &mut f).unwrap();
        let mut jac = DMatrix::zeros(2, 2);
        let (mut work_y, mut work_f) = ([0.0; 2], [0.0; 2]);
        rhs.jacobian(0.0, &y, &f, &mut jac, &mut work_y, &mut work_f)
            .unwrap();
        let exact = DMatrix::from_row_slice(2, 2, &[y[1], y[0], y[0].cos(), 3.0]);
        assert!((jac - exact).amax() < 1e-7);
        assert_eq!(rhs.evals(), 1 + 2);
        assert_eq!(rhs.jacobian_evals(), 1);

        let mut blows_up = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = if y[0] > 1.0 { f64::INFINITY } else { y[0] };
        });
        let mut rhs = CheckedRhs::new(&mut blows_up);
        let mut jac = DMatrix::zeros(1, 1);
        let failure = rhs
            .jacobian(0.0, &[1.0], &[1.0], &mut jac, &mut [0.0], &mut [0.0])
            .unwrap_err();
        assert!(matches!(
            failure,
            StepFailure::Rhs {
                error: RhsError::NonFinite { index: 0 },
                ..
            }
        ));
    }

    /// The difference step scales with `|y|` (`√(ε max(|y|, 1e-5))`): at `y = 10⁶` the
    /// derivative of `y³`, 3e12, comes out to 1e-5 relative (the rounding of `F ≈ 1e18`
    /// divided by a step of 1.5e-5), where a step not scaled up with `y` would drown it.
    #[test]
    fn the_difference_step_scales_with_the_state() {
        let mut cube = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = y[0].powi(3));
        let mut rhs = CheckedRhs::new(&mut cube);
        let y = [1e6];
        let f = [1e18];
        let mut jac = DMatrix::zeros(1, 1);
        rhs.jacobian(0.0, &y, &f, &mut jac, &mut [0.0], &mut [0.0])
            .unwrap();
        assert!((jac[(0, 0)] / 3e12 - 1.0).abs() < 1e-5, "{}", jac[(0, 0)]);
    }

    /// The cubic Hermite interpolant over a step that does not start at 0 reproduces a
    /// quadratic: implicit midpoint on `ẏ = 2t` (exact at the steps, the midpoint rule being
    /// exact for a linear integrand) from t = 1 with steps of 0.5, sampled between steps.
    #[test]
    fn hermite_output_reproduces_a_quadratic_on_later_steps() {
        use crate::integrate::{ImplicitMidpoint, Integrator, IntegratorOptions, OutputTimes};
        let mut system = OdeFn::new(1, |t: f64, _y: &[f64], dy: &mut [f64]| dy[0] = 2.0 * t);
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(0.5);
        let times = vec![1.25, 1.8, 2.6, 2.9];
        let solution = ImplicitMidpoint::new()
            .integrate(
                &mut system,
                1.0,
                &[1.0],
                3.0,
                &OutputTimes::At(times.clone()),
                &options,
            )
            .unwrap();
        for (t, y) in times.iter().zip(&solution.y) {
            assert!((y - t * t).abs() < 1e-13, "t = {t}: {y}");
        }
    }

    #[test]
    fn newton_failures_are_recoverable_with_their_factor() {
        let newton = StepFailure::Newton {
            t: 1.0,
            iterations: 7,
            residual_norm: 3.0,
            retry_factor: 0.3,
        };
        assert!(newton.is_recoverable());
        assert_eq!(newton.retry_factor(), Some(0.3));
        assert_eq!(
            newton.into_error(),
            IntegrationError::NewtonDidNotConverge {
                t: 1.0,
                iterations: 7,
                residual_norm: 3.0
            }
        );
        let singular = StepFailure::SingularIterationMatrix { t: 2.0 };
        assert!(singular.is_recoverable());
        assert_eq!(singular.retry_factor(), Some(0.5));
        assert_eq!(
            singular.into_error(),
            IntegrationError::SingularIterationMatrix { t: 2.0 }
        );
    }

    #[test]
    fn checked_rhs_counts_and_checks() {
        let mut system = OdeFn::new(2, |t: f64, _y: &[f64], dy: &mut [f64]| {
            dy[0] = 1.0;
            dy[1] = if t > 1.0 { f64::NAN } else { 0.0 };
        });
        let mut rhs = CheckedRhs::new(&mut system);
        let mut dy = [0.0; 2];
        assert!(rhs.eval(0.0, &[0.0, 0.0], &mut dy).is_ok());
        let failure = rhs.eval(2.0, &[0.0, 0.0], &mut dy).unwrap_err();
        assert_eq!(rhs.evals(), 2);
        assert!(failure.is_recoverable());
        assert_eq!(
            failure.into_error(),
            IntegrationError::RhsNonFinite { t: 2.0, index: 1 }
        );
        let singular = StepFailure::Rhs {
            t: 0.5,
            error: RhsError::SingularMassMatrix,
        };
        assert!(!singular.is_recoverable());
        assert_eq!(
            singular.into_error(),
            IntegrationError::SingularMassMatrix { t: 0.5 }
        );
    }
}

/// The two ends of the last accepted step `[t_prev, t]` (states and derivatives) and the time
/// `t_new` of the candidate being attempted: the state every one-step method keeps, with its
/// start, and the cubic Hermite interpolant that most of them use as dense output.
#[derive(Debug, Clone)]
pub(crate) struct StepEnds {
    /// Current time (end of the last accepted step).
    pub(crate) t: f64,
    /// Start of the last accepted step.
    pub(crate) t_prev: f64,
    /// End of the candidate step.
    pub(crate) t_new: f64,
    /// Current state.
    pub(crate) y: Vec<f64>,
    /// State at `t_prev`.
    pub(crate) y_prev: Vec<f64>,
    /// `F(t, y)`.
    pub(crate) f: Vec<f64>,
    /// `F(t_prev, y_prev)`.
    pub(crate) f_prev: Vec<f64>,
}

impl StepEnds {
    /// Buffers for a system of dimension `dim`.
    pub(crate) fn new(dim: usize) -> Self {
        Self {
            t: 0.0,
            t_prev: 0.0,
            t_new: 0.0,
            y: vec![0.0; dim],
            y_prev: vec![0.0; dim],
            f: vec![0.0; dim],
            f_prev: vec![0.0; dim],
        }
    }

    /// Starts at `(t0, y0)`: both ends there, `F(t0, y0)` evaluated.
    ///
    /// # Errors
    /// The failure of that evaluation.
    pub(crate) fn reset(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        t0: f64,
        y0: &[f64],
    ) -> Result<(), StepFailure> {
        self.t = t0;
        self.t_prev = t0;
        self.t_new = t0;
        self.y.copy_from_slice(y0);
        self.y_prev.copy_from_slice(y0);
        rhs.eval(t0, y0, &mut self.f)?;
        self.f_prev.copy_from_slice(&self.f);
        Ok(())
    }

    /// The last accepted step `(t_prev, t)`.
    pub(crate) fn interval(&self) -> (f64, f64) {
        (self.t_prev, self.t)
    }

    /// The cubic Hermite interpolant of the step's ends and derivatives at `t` (order 3).
    pub(crate) fn hermite(&self, t: f64, out: &mut [f64]) {
        let h = self.t - self.t_prev;
        if h == 0.0 {
            out.copy_from_slice(&self.y);
            return;
        }
        let theta = (t - self.t_prev) / h;
        for (i, o) in out.iter_mut().enumerate() {
            *o = hermite(
                theta,
                self.y_prev[i],
                self.y[i],
                h * self.f_prev[i],
                h * self.f[i],
                0.0,
            );
        }
    }
}
