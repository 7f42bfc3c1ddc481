//! Step-size control: from the error estimate of a step to the size of the next one.

use serde::Serialize;

/// What a [`StepSizeController`] decided about an attempted step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum StepOutcome {
    /// Keep the step; try `dt_next` next.
    Accepted {
        /// Proposed size of the next step (units of `t`).
        dt_next: f64,
    },
    /// Discard the step; retry from the same state with `dt_retry`.
    Rejected {
        /// Proposed size of the retried step (units of `t`), smaller than the rejected one.
        dt_retry: f64,
    },
}

/// A rule that accepts or rejects a step from its error estimate and proposes the next step
/// size.
///
/// The integrator calls [`reset`](Self::reset) before an integration and
/// [`decide`](Self::decide) after every attempted step.
pub trait StepSizeController {
    /// Forgets the history of earlier steps.
    fn reset(&mut self);

    /// Decides on a step of size `dt` whose weighted RMS error norm is `error_norm`.
    ///
    /// `error_norm ≤ 1` means the local error meets the tolerances. A controller must reject
    /// every step with `error_norm > 1`, including `∞` (used for a step whose right-hand side
    /// was not finite) and NaN.
    fn decide(&mut self, dt: f64, error_norm: f64) -> StepOutcome;
}

/// Smallest error remembered for the next step, so that a step with zero error does not
/// freeze the PI term (Hairer's DOPRI5 uses the same bound).
const ERROR_FLOOR: f64 = 1e-4;

/// The proportional–integral step-size controller of Gustafsson, with the defaults of Hairer's
/// DOPRI5.
///
/// After a step of size `h` with error norm `errₙ ≤ 1` (accepted), the next step is
///
/// ```text
/// h_next = h · clamp(safety · errₙ^(−alpha) · errₙ₋₁^beta, min_factor, max_factor)
/// ```
///
/// where `errₙ₋₁` is the error of the previous accepted step (at least 1e-4; 1e-4 before the
/// first step). A rejected step (`errₙ > 1`) is retried with
/// `h · max(safety · errₙ^(−alpha), min_factor)`, and the step accepted right after a
/// rejection is not allowed to grow the step. With `beta = 0` this is the classical
/// (integral-only) controller with exponent `alpha = 1/(q+1)` for an error estimator of order
/// `q`.
///
/// # References
/// - K. Gustafsson, "Control theoretic techniques for stepsize selection in explicit
///   Runge–Kutta methods", ACM Trans. Math. Softw. 17(4), 533–554, 1991,
///   doi:10.1145/210232.210242.
/// - E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer,
///   1996, §IV.2, doi:10.1007/978-3-642-05221-7; and the code `dopri5.f` (defaults
///   `beta = 0.04`, `alpha = 0.2 − 0.75 beta`, `safety = 0.9`, factors in `[0.2, 10]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PiController {
    /// Exponent of the current error, `> 0` (DOPRI5: `0.2 − 0.75 · 0.04 = 0.17`).
    pub alpha: f64,
    /// Exponent of the previous error, `≥ 0` (DOPRI5: 0.04).
    pub beta: f64,
    /// Safety factor, in `(0, 1)` (default: 0.9).
    pub safety: f64,
    /// Smallest ratio of new to old step, in `(0, 1)` (default: 0.2).
    pub min_factor: f64,
    /// Largest ratio of new to old step, `> 1` (default: 10).
    pub max_factor: f64,
    /// Error norm of the previous accepted step, at least [`ERROR_FLOOR`].
    #[serde(skip)]
    error_previous: f64,
    /// Whether the last attempted step was rejected.
    #[serde(skip)]
    rejected_last: bool,
}

impl PiController {
    /// A controller with exponents `alpha` (current error) and `beta` (previous error), and
    /// safety 0.9 and step ratios in `[0.2, 10]`.
    pub fn new(alpha: f64, beta: f64) -> Self {
        Self {
            alpha,
            beta,
            safety: 0.9,
            min_factor: 0.2,
            max_factor: 10.0,
            error_previous: ERROR_FLOOR,
            rejected_last: false,
        }
    }

    /// Hairer's DOPRI5 settings, for a method whose error estimator has order 4:
    /// `beta = 0.04`, `alpha = 1/5 − 0.75 beta`, safety 0.9, step ratios in `[0.2, 10]`.
    pub fn dopri5() -> Self {
        let beta = 0.04;
        Self::new(0.2 - 0.75 * beta, beta)
    }

    /// Sets the safety factor.
    pub fn with_safety(mut self, safety: f64) -> Self {
        self.safety = safety;
        self
    }

    /// Sets the smallest and largest ratio of new to old step.
    pub fn with_factor_bounds(mut self, min_factor: f64, max_factor: f64) -> Self {
        self.min_factor = min_factor;
        self.max_factor = max_factor;
        self
    }
}

impl StepSizeController for PiController {
    fn reset(&mut self) {
        self.error_previous = ERROR_FLOOR;
        self.rejected_last = false;
    }

    fn decide(&mut self, dt: f64, error_norm: f64) -> StepOutcome {
        if error_norm.is_nan() || error_norm > 1.0 {
            self.rejected_last = true;
            // `f64::max` returns `min_factor` when the first operand is NaN; `∞^(−alpha) = 0`.
            let factor = (self.safety * error_norm.powf(-self.alpha)).max(self.min_factor);
            return StepOutcome::Rejected {
                dt_retry: dt * factor,
            };
        }
        // errₙ = 0 gives ∞ here, which the clamp turns into `max_factor`.
        let mut factor =
            (self.safety * error_norm.powf(-self.alpha) * self.error_previous.powf(self.beta))
                .max(self.min_factor)
                .min(self.max_factor);
        if self.rejected_last {
            factor = factor.min(1.0);
        }
        self.error_previous = error_norm.max(ERROR_FLOOR);
        self.rejected_last = false;
        StepOutcome::Accepted {
            dt_next: dt * factor,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn accepted(outcome: StepOutcome) -> f64 {
        match outcome {
            StepOutcome::Accepted { dt_next } => dt_next,
            StepOutcome::Rejected { .. } => panic!("expected acceptance, got {outcome:?}"),
        }
    }

    fn rejected(outcome: StepOutcome) -> f64 {
        match outcome {
            StepOutcome::Rejected { dt_retry } => dt_retry,
            StepOutcome::Accepted { .. } => panic!("expected rejection, got {outcome:?}"),
        }
    }

    #[test]
    fn dopri5_exponents() {
        let controller = PiController::dopri5();
        assert!((controller.alpha - 0.17).abs() < 1e-15);
        assert_eq!(controller.beta, 0.04);
    }

    #[test]
    fn first_step_follows_the_formula() {
        let mut controller = PiController::dopri5();
        let error: f64 = 0.5;
        let expected = 0.9 * error.powf(-0.17) * 1e-4_f64.powf(0.04);
        let dt_next = accepted(controller.decide(1.0, error));
        assert!(
            (dt_next - expected).abs() < 1e-15,
            "{dt_next} vs {expected}"
        );
    }

    #[test]
    fn growth_and_shrinkage_are_bounded() {
        let mut controller = PiController::dopri5();
        assert_eq!(accepted(controller.decide(1.0, 0.0)), 10.0);
        assert_eq!(rejected(controller.decide(1.0, 1e10)), 0.2);
        assert_eq!(rejected(controller.decide(1.0, f64::INFINITY)), 0.2);
        assert_eq!(rejected(controller.decide(1.0, f64::NAN)), 0.2);
    }

    #[test]
    fn no_growth_right_after_a_rejection() {
        let mut controller = PiController::dopri5();
        let dt_retry = rejected(controller.decide(1.0, 2.0));
        assert!(dt_retry < 1.0);
        // A tiny error would allow growth ×10, but the previous attempt was rejected.
        assert_eq!(accepted(controller.decide(dt_retry, 1e-12)), dt_retry);
        // The step after that may grow again.
        assert!(accepted(controller.decide(dt_retry, 1e-12)) > dt_retry);
    }

    #[test]
    fn reset_forgets_history() {
        let mut controller = PiController::dopri5();
        let mut copy = controller;
        let fresh = accepted(copy.decide(1.0, 0.5));
        controller.decide(1.0, 0.9);
        controller.decide(1.0, 3.0);
        controller.reset();
        assert_eq!(accepted(controller.decide(1.0, 0.5)), fresh);
    }
}
