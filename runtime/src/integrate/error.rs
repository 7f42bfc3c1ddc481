//! Why an integration stopped: [`IntegrationError`], and [`IntegrationFailure`], which keeps
//! the samples computed before it.

use super::solution::Solution;

/// Why an integration did not reach `t_end`.
///
/// The first group of variants rejects the input before any step is taken; the second
/// reports a failure during the integration, at time `t` (see [`IntegrationError::t`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IntegrationError {
    /// The time span is empty, reversed or not finite: integration needs finite `t0 < t_end`.
    #[error("the time span [{t0}, {t_end}] is empty, reversed or not finite (need t0 < t_end)")]
    InvalidTimeSpan {
        /// Initial time.
        t0: f64,
        /// Final time.
        t_end: f64,
    },
    /// The initial state does not have the system's dimension.
    #[error("the initial state has {found} components but the system has dimension {expected}")]
    DimensionMismatch {
        /// The system's dimension, [`OdeSystem::dim`](crate::OdeSystem::dim).
        expected: usize,
        /// The length of the initial state.
        found: usize,
    },
    /// A per-component tolerance does not have one value per state component.
    #[error("`{option}` has {found} components but the state has {expected}")]
    ToleranceLengthMismatch {
        /// Which option: `"rtol"` or `"atol"`.
        option: &'static str,
        /// The system's dimension.
        expected: usize,
        /// The number of values given.
        found: usize,
    },
    /// A tolerance is negative or not finite, or a relative tolerance is 1 or more.
    #[error(
        "`{option}` is {value} for component {index}; tolerances must be finite and >= 0, and rtol < 1"
    )]
    InvalidTolerance {
        /// Which option: `"rtol"` or `"atol"`.
        option: &'static str,
        /// The component (0 for a scalar tolerance).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// `rtol` and `atol` are both zero for a component, so its error scale can be zero.
    #[error("`rtol` and `atol` are both zero for component {index}")]
    ZeroTolerance {
        /// The component.
        index: usize,
    },
    /// A method that solves its stages by Newton's iteration was given `atol = 0` for a
    /// component: it measures each correction in the weights `atol + rtol |y|` of the step's
    /// start, which are 0 for a component at 0 (a body at rest), so no iteration could
    /// converge. Hairer and Wanner's radau5.f refuses `ATOL ≤ 0` for the same reason.
    #[error(
        "{method} needs an absolute tolerance above 0 (`atol` is 0 for component {index}): its Newton iteration measures corrections relative to atol + rtol·|y|, which is 0 for a component at 0"
    )]
    AbsoluteToleranceRequired {
        /// The method's name.
        method: &'static str,
        /// The first component whose `atol` is 0.
        index: usize,
    },
    /// `dt` or `dt_max` is zero, negative or not finite.
    #[error("`{option}` is {value}; step sizes must be finite and positive")]
    InvalidStepSize {
        /// Which option: `"dt"` or `"dt_max"`.
        option: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A requested output time is earlier than the one before it.
    #[error(
        "output time {index} ({t}) is earlier than the one before it ({previous}); output times must be sorted"
    )]
    OutputTimesNotSorted {
        /// Position of the offending time in the list.
        index: usize,
        /// The offending time.
        t: f64,
        /// The time before it.
        previous: f64,
    },
    /// A requested output time lies outside `[t0, t_end]` (or is NaN).
    #[error("output time {index} ({t}) lies outside [{t0}, {t_end}]")]
    OutputTimeOutOfRange {
        /// Position of the offending time in the list.
        index: usize,
        /// The offending time.
        t: f64,
        /// Initial time.
        t0: f64,
        /// Final time.
        t_end: f64,
    },
    /// The method needs a second-order system `y = [q; q̇]`
    /// ([`OdeSystem::second_order_dim`](crate::OdeSystem::second_order_dim)), and this one
    /// does not declare that structure (or declares one that does not match its dimension).
    #[error(
        "`{method}` needs a second-order system y = [q; q̇] (OdeSystem::second_order_dim), and this one is not (a model in generalized speeds has y = [q; u]: take an explicit or implicit Runge–Kutta method)"
    )]
    NotSecondOrder {
        /// The method's [`name`](super::Integrator::name).
        method: &'static str,
    },
    /// The Taylor method needs the system's Taylor recurrences
    /// ([`OdeSystem::taylor_support`](crate::OdeSystem::taylor_support)), and this one has
    /// none: equations given as a closure, equations that use a function without a
    /// recurrence, constraints stabilised by Baumgarte's terms or the penalty, a constrained
    /// model compiled by `model!`, closed contacts (the reason says which).
    #[error("the Taylor method cannot integrate this system: {reason}")]
    NoTaylorRecurrences {
        /// Why, naming what is missing.
        reason: String,
    },
    /// The step size fell below `16 ε · max(|t|, t_end − t0)`: the solution changes faster
    /// than the method can follow (a singularity, or stiffness for an explicit method).
    #[error("the step size {dt:e} fell below the smallest usable step at t = {}", time(.t))]
    StepSizeTooSmall {
        /// Time reached.
        t: f64,
        /// The step size that was too small.
        dt: f64,
    },
    /// `max_steps` step attempts did not reach `t_end`.
    #[error("{max_steps} step attempts did not reach t_end (stopped at t = {})", time(.t))]
    TooManySteps {
        /// Time reached.
        t: f64,
        /// The limit, [`IntegratorOptions::max_steps`](super::IntegratorOptions::max_steps).
        max_steps: usize,
    },
    /// A component of the state is NaN or infinite, at `t0` (the initial state) or after a
    /// step (overflow).
    #[error("component {index} of the state is not finite at t = {}", time(.t))]
    NonFiniteState {
        /// Time of the non-finite state.
        t: f64,
        /// Index of the first non-finite component.
        index: usize,
    },
    /// The right-hand side is NaN or infinite, as reported by the system
    /// ([`RhsError::NonFinite`](crate::RhsError::NonFinite)) or found by the integrator.
    #[error("component {index} of the right-hand side is not finite at t = {}", time(.t))]
    RhsNonFinite {
        /// Time at which the right-hand side was evaluated (a stage time of the failed step).
        t: f64,
        /// Index of the first non-finite component.
        index: usize,
    },
    /// The Jacobian `∂F/∂y` an implicit method needs is NaN or infinite in row `row`, even
    /// by differences of `F` ([`RhsError::JacobianNonFinite`](crate::RhsError::JacobianNonFinite)).
    #[error("row {row} of the Jacobian of the right-hand side is not finite at t = {}", time(.t))]
    JacobianNonFinite {
        /// Time at which the Jacobian was evaluated (the start of the failed step).
        t: f64,
        /// The first row whose derivative is not finite.
        row: usize,
    },
    /// The mass matrix is not positive definite
    /// ([`RhsError::SingularMassMatrix`](crate::RhsError::SingularMassMatrix)).
    #[error("the mass matrix is not positive definite at t = {}", time(.t))]
    SingularMassMatrix {
        /// Time at which the right-hand side was evaluated (a stage time of the failed step).
        t: f64,
    },
    /// The constrained system `[M Jᵀ; J 0]` is singular
    /// ([`RhsError::SingularConstraintMatrix`](crate::RhsError::SingularConstraintMatrix)).
    #[error(
        "the constrained system [M Jᵀ; J 0] is singular at t = {} (redundant constraints or a singular configuration)",
        time(.t)
    )]
    SingularConstraintMatrix {
        /// Time at which the right-hand side was evaluated (a stage time of the failed step).
        t: f64,
    },
    /// Projection onto the constraints after the step ending at `t` failed
    /// ([`RhsError::ProjectionFailed`](crate::RhsError::ProjectionFailed)).
    #[error("projection onto the constraints failed at t = {}: residual {residual:e} left", time(.t))]
    ProjectionFailed {
        /// End of the step whose state could not be projected.
        t: f64,
        /// The largest constraint residual left.
        residual: f64,
    },
    /// An event function ([`OdeSystem::event_values`](crate::OdeSystem::event_values)) is NaN
    /// at `t`, so its sign, and whether it crossed zero, is unknown
    /// ([`RhsError::EventNotFinite`](crate::RhsError::EventNotFinite)).
    #[error("event function {index} is NaN at t = {}", time(.t))]
    EventNotFinite {
        /// Time at which the event functions were evaluated.
        t: f64,
        /// Index of the event function.
        index: usize,
    },
    /// The Newton iteration of an implicit method did not converge for the step from `t`:
    /// with a fixed step at once; with adaptive steps after the step was shrunk until it
    /// was too small.
    #[error(
        "the Newton iteration did not converge for the step from t = {} ({iterations} iterations, residual norm {residual_norm:e})",
        time(.t)
    )]
    NewtonDidNotConverge {
        /// Start of the step whose stage equations could not be solved.
        t: f64,
        /// Newton iterations of the last attempt.
        iterations: usize,
        /// How far from converged the last iterate was: for
        /// [`RadauIIA5`](crate::RadauIIA5) the weighted RMS norm of the last Newton update
        /// (scales `atolᵢ + rtolᵢ |yᵢ|`), for [`ImplicitMidpoint`](crate::ImplicitMidpoint) the
        /// relative max norm of the residual of the stage equation; `∞` or NaN if it
        /// diverged.
        residual_norm: f64,
    },
    /// The Newton iteration matrix (`I − (h/2) J` for implicit midpoint, `γ/h I − J` and its
    /// complex twin for Radau IIA) was exactly singular at the step from `t`, and a smaller
    /// step did not help.
    #[error("the Newton iteration matrix is singular at t = {}", time(.t))]
    SingularIterationMatrix {
        /// Start of the step.
        t: f64,
    },
}

impl IntegrationError {
    /// The time at which the integration stopped, or `None` for invalid input.
    pub fn t(&self) -> Option<f64> {
        match *self {
            IntegrationError::StepSizeTooSmall { t, .. }
            | IntegrationError::TooManySteps { t, .. }
            | IntegrationError::NonFiniteState { t, .. }
            | IntegrationError::RhsNonFinite { t, .. }
            | IntegrationError::JacobianNonFinite { t, .. }
            | IntegrationError::SingularMassMatrix { t }
            | IntegrationError::SingularConstraintMatrix { t }
            | IntegrationError::ProjectionFailed { t, .. }
            | IntegrationError::EventNotFinite { t, .. }
            | IntegrationError::NewtonDidNotConverge { t, .. }
            | IntegrationError::SingularIterationMatrix { t } => Some(t),
            IntegrationError::InvalidTimeSpan { .. }
            | IntegrationError::DimensionMismatch { .. }
            | IntegrationError::ToleranceLengthMismatch { .. }
            | IntegrationError::InvalidTolerance { .. }
            | IntegrationError::ZeroTolerance { .. }
            | IntegrationError::AbsoluteToleranceRequired { .. }
            | IntegrationError::InvalidStepSize { .. }
            | IntegrationError::OutputTimesNotSorted { .. }
            | IntegrationError::OutputTimeOutOfRange { .. }
            | IntegrationError::NotSecondOrder { .. }
            | IntegrationError::NoTaylorRecurrences { .. } => None,
        }
    }
}

/// A failed integration: what went wrong, and every sample recorded before it.
///
/// Displays as its [`error`](Self::error). `partial` holds the samples the requested
/// [`OutputTimes`](super::OutputTimes) had produced up to the failure, all at times before the
/// failure's `t` (at `t` itself for [`IntegrationError::TooManySteps`]; empty when the input
/// was rejected), and the statistics of the work done.
///
/// The solution is boxed so that `Result<Solution, IntegrationFailure>` stays small on the
/// success path (clippy's `result_large_err`); it reads like a `Solution` through `Deref`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{error}")]
pub struct IntegrationFailure {
    /// Why the integration stopped.
    pub error: IntegrationError,
    /// The samples recorded before the failure, with the statistics of the attempt.
    pub partial: Box<Solution>,
}

/// A time in an error message: as Rust prints it (shortest round trip), or in exponent form
/// from 1e6 s on (an end time of 1e300 s printed a time of 300 digits).
fn time(t: &f64) -> String {
    if t.is_finite() && t.abs() >= 1e6 {
        format!("{t:e}")
    } else {
        format!("{t}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_time() {
        let error = IntegrationError::StepSizeTooSmall { t: 1.0, dt: 1e-16 };
        assert_eq!(
            error.to_string(),
            "the step size 1e-16 fell below the smallest usable step at t = 1"
        );
        assert_eq!(error.t(), Some(1.0));
        let invalid = IntegrationError::InvalidTimeSpan {
            t0: 1.0,
            t_end: 0.0,
        };
        assert_eq!(invalid.t(), None);
    }

    #[test]
    fn failure_displays_as_its_error() {
        let failure = IntegrationFailure {
            error: IntegrationError::SingularMassMatrix { t: 0.5 },
            partial: Box::new(Solution::new(2)),
        };
        assert_eq!(
            failure.to_string(),
            "the mass matrix is not positive definite at t = 0.5"
        );
    }
}
