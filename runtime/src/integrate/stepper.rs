//! The interface between the integration loop and a method: a [`Stepper`] takes one step at a
//! time and keeps a [`DenseOutput`] over the last accepted one.
//!
//! A new method (Euler, midpoint and Bogacki–Shampine are tableaus; DOP853, symplectic and
//! implicit methods are steppers of their own) implements [`Stepper`] and reuses the loop in
//! `driver`: validation, fixed and adaptive step sequences, output, statistics and errors.

use crate::ode::{OdeSystem, RhsError};

use super::dense_output::DenseOutput;
use super::error::IntegrationError;
use super::options::ErrorWeights;

/// Why a step attempt produced no usable candidate.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum StepFailure {
    /// The right-hand side failed, or was not finite, at time `t`.
    Rhs { t: f64, error: RhsError },
    /// The candidate state is not finite at time `t`.
    NonFiniteState { t: f64, index: usize },
}

impl StepFailure {
    /// Whether a smaller step may succeed: non-finite values often come from a step so large
    /// that a stage leaves the region where `F` is defined, whereas a singular mass matrix is
    /// a property of the model at that configuration.
    pub(crate) fn is_recoverable(&self) -> bool {
        match self {
            StepFailure::Rhs {
                error: RhsError::SingularMassMatrix | RhsError::SingularConstraintMatrix,
                ..
            } => false,
            StepFailure::Rhs {
                error: RhsError::NonFinite { .. },
                ..
            }
            | StepFailure::NonFiniteState { .. } => true,
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
                error: RhsError::NonFinite { index },
            } => IntegrationError::RhsNonFinite { t, index },
            StepFailure::NonFiniteState { t, index } => {
                IntegrationError::NonFiniteState { t, index }
            }
        }
    }
}

/// The right-hand side as a stepper sees it: every evaluation counted and its result checked
/// for finiteness, so that no method can forget either.
pub(crate) struct CheckedRhs<'a> {
    system: &'a mut dyn OdeSystem,
    evals: usize,
}

impl<'a> CheckedRhs<'a> {
    /// Wraps `system`, with no evaluations counted yet.
    pub(crate) fn new(system: &'a mut dyn OdeSystem) -> Self {
        Self { system, evals: 0 }
    }

    /// Number of evaluations so far.
    pub(crate) fn evals(&self) -> usize {
        self.evals
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
        match dy.iter().position(|v| !v.is_finite()) {
            Some(index) => Err(StepFailure::Rhs {
                t,
                error: RhsError::NonFinite { index },
            }),
            None => Ok(()),
        }
    }
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
    /// Returns the weighted RMS norm of the local error estimate (`≤ 1` meets the
    /// tolerances) when `weights` is given and the method has an error estimator, else
    /// `None`.
    ///
    /// # Errors
    /// A failed or non-finite right-hand side at a stage, or a non-finite candidate.
    fn attempt(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        t_new: f64,
        weights: Option<&ErrorWeights>,
    ) -> Result<Option<f64>, StepFailure>;

    /// Makes the last candidate the current state, with `F` there (reused from the last stage
    /// or evaluated), and the dense output over that step.
    ///
    /// # Errors
    /// The failure of evaluating `F` at the candidate; the state is then unchanged.
    fn accept(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure>;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ode::OdeFn;

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
