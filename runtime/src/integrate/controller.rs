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
/// The integrator calls [`reset`](Self::reset) before an integration and, after every
/// attempted step, [`decide_after_newton`](Self::decide_after_newton) for a step of an
/// implicit method whose Newton iteration converged, else
/// [`decide_squared`](Self::decide_squared) (whose default calls [`decide`](Self::decide)).
pub trait StepSizeController {
    /// Forgets the history of earlier steps.
    fn reset(&mut self);

    /// Decides on a step of size `dt` whose weighted RMS error norm is `error_norm`.
    ///
    /// `error_norm ≤ 1` means the local error meets the tolerances. A controller must reject
    /// every step with `error_norm > 1`, including `∞` (used for a step whose right-hand side
    /// was not finite) and NaN.
    fn decide(&mut self, dt: f64, error_norm: f64) -> StepOutcome;

    /// [`decide`](Self::decide) given the *square* of the error norm, `error_norm²` (what
    /// the integrators hand over: for an RMS norm the mean of the squared weighted errors,
    /// whose square root is then left to the controller). The integrators call this one, or
    /// [`decide_after_newton`](Self::decide_after_newton) (whose default calls this one).
    ///
    /// The default takes the square root and calls [`decide`](Self::decide). A controller
    /// that works with `ln(error_norm)` takes `ln(error_norm²)/2` instead: the step size is
    /// waited for by the next step's first stage, and the square root was on that path
    /// (issue 6: ~2 % of a DP5(4) run on the double pendulum).
    fn decide_squared(&mut self, dt: f64, error_norm_squared: f64) -> StepOutcome {
        self.decide(dt, error_norm_squared.sqrt())
    }

    /// [`decide_squared`](Self::decide_squared) for a step of an implicit method whose
    /// Newton iteration converged after `newton`'s work; the integrators call this one for
    /// such methods. An attempt whose iteration failed comes through
    /// [`decide_squared`](Self::decide_squared) as an infinite error.
    ///
    /// The default ignores `newton`. [`PredictiveController`] uses it as RADAU5 does: it
    /// lowers its safety factor after many iterations and holds the step size only when the
    /// factorised matrices can be kept.
    fn decide_after_newton(
        &mut self,
        dt: f64,
        error_norm_squared: f64,
        newton: NewtonWork,
    ) -> StepOutcome {
        let _ = newton;
        self.decide_squared(dt, error_norm_squared)
    }
}

/// What the Newton iteration of an implicit method did on an attempted step, for
/// [`StepSizeController::decide_after_newton`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[non_exhaustive]
pub struct NewtonWork {
    /// Newton iterations of the attempt (`≥ 1`).
    pub iterations: usize,
    /// The method's limit on them (RADAU5's `NIT`; [`RadauIIA5`](super::RadauIIA5): 7 by
    /// default).
    pub max_iterations: usize,
    /// Whether a next step of the same size would reuse the factorised iteration matrices:
    /// the iteration contracted fast enough (RADAU5: `θ ≤ 0.001`) for the method to keep its
    /// Jacobian.
    pub matrices_reusable: bool,
}

impl NewtonWork {
    /// The work of an attempt that converged after `iterations` of at most `max_iterations`
    /// Newton iterations, `matrices_reusable` if a next step of the same size would keep the
    /// factorised iteration matrices.
    pub fn new(iterations: usize, max_iterations: usize, matrices_reusable: bool) -> Self {
        Self {
            iterations,
            max_iterations,
            matrices_reusable,
        }
    }
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
    /// `ln` of the error norm of the previous accepted step (at least [`ERROR_FLOOR`]).
    #[serde(skip)]
    ln_error_previous: f64,
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
            ln_error_previous: ERROR_FLOOR.ln(),
            rejected_last: false,
        }
    }

    /// Hairer's DOPRI5 settings, for a method whose error estimator has order 4:
    /// `beta = 0.04`, `alpha = 1/5 − 0.75 beta`, safety 0.9, step ratios in `[0.2, 10]`.
    pub fn dopri5() -> Self {
        Self::for_error_order(4)
    }

    /// DOPRI5's rule for an error estimator of order `q` (the local error estimate behaves as
    /// `O(h^(q+1))`): `beta = 0.04`, `alpha = 1/(q+1) − 0.75 beta`, safety 0.9, step ratios in
    /// `[0.2, 10]`. [`Self::dopri5`] is `q = 4`; Bogacki–Shampine 3(2) uses `q = 2`.
    pub fn for_error_order(error_order: u32) -> Self {
        let beta = 0.04;
        Self::new(1.0 / f64::from(error_order + 1) - 0.75 * beta, beta)
    }

    /// Hairer's DOP853 settings: the integral controller `alpha = 1/8`, `beta = 0` (DOP853's
    /// error estimate behaves as `O(h⁸)`), safety 0.9, step ratios in `[1/3, 6]`
    /// (`dop853.f`: `FAC1 = 0.333`, `FAC2 = 6`).
    pub fn dop853() -> Self {
        Self::new(1.0 / 8.0, 0.0).with_factor_bounds(0.333, 6.0)
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

impl PiController {
    /// [`StepSizeController::decide`] from `value = error_normᵖ` with `p = 1/power` (1 for
    /// the norm, 2 for its square): `error_norm > 1` exactly when `value > 1`, and
    /// `ln error_norm = power · ln value`, which is what the error floor (1e-4 on the norm)
    /// and the step-size formula use.
    fn decide_power(&mut self, dt: f64, value: f64, power: f64) -> StepOutcome {
        if value.is_nan() || value > 1.0 {
            self.rejected_last = true;
            // `f64::max` returns `min_factor` when the first operand is NaN; `∞^(−alpha) = 0`.
            let factor = (self.safety * value.powf(-self.alpha * power)).max(self.min_factor);
            return StepOutcome::Rejected {
                dt_retry: dt * factor,
            };
        }
        // errₙ^(−alpha) errₙ₋₁^beta as one exponential of logarithms, with ln errₙ₋₁ kept
        // from the previous step: one `ln` and one `exp` per step instead of two `powf`.
        // errₙ = 0 gives ln = −∞ and ∞ here, which the clamp turns into `max_factor`.
        let ln_error = power * value.ln();
        let mut factor = (self.safety
            * (self.beta * self.ln_error_previous - self.alpha * ln_error).exp())
        .max(self.min_factor)
        .min(self.max_factor);
        if self.rejected_last {
            factor = factor.min(1.0);
        }
        self.ln_error_previous = ln_error.max(ERROR_FLOOR.ln());
        self.rejected_last = false;
        StepOutcome::Accepted {
            dt_next: dt * factor,
        }
    }
}

impl StepSizeController for PiController {
    fn reset(&mut self) {
        self.ln_error_previous = ERROR_FLOOR.ln();
        self.rejected_last = false;
    }

    fn decide(&mut self, dt: f64, error_norm: f64) -> StepOutcome {
        self.decide_power(dt, error_norm, 1.0)
    }

    fn decide_squared(&mut self, dt: f64, error_norm_squared: f64) -> StepOutcome {
        self.decide_power(dt, error_norm_squared, 0.5)
    }
}

/// Gustafsson's predictive step-size controller, as Hairer and Wanner's RADAU5 uses it.
///
/// With `errₙ` the error norm of the current step `hₙ` (exponent `1/(q+1)` for an error
/// estimator of order `q`; RADAU5: `q = 3`, exponent 1/4), the classical proposal is
/// `h · safety · errₙ^(−exponent)`. After an accepted step that follows an earlier accepted
/// one (`hₙ₋₁`, `errₙ₋₁`), the predictive proposal
///
/// ```text
/// h_pred = hₙ · safety · (hₙ/hₙ₋₁) · errₙ^(−exponent) · (errₙ₋₁/errₙ)^exponent
/// ```
///
/// is taken when it is smaller. Every proposal is clamped to `[min_factor, max_factor]` times
/// `h`. A rejected step is retried with the classical proposal, or with `h/10` if no step has
/// been accepted yet; the step accepted right after a rejection does not grow. An accepted
/// proposal within `[1, hold_max]` times `h` keeps `h` unchanged, so that an implicit method
/// can keep its factorised iteration matrix (RADAU5's `QUOT1 = 1`, `QUOT2 = 1.2`).
///
/// Through [`decide_after_newton`](StepSizeController::decide_after_newton) it also does
/// what RADAU5 does with the Newton work of the step: after `k` of at most `k_max` iterations
/// the classical proposal uses the safety factor
/// `min(safety, safety (1 + 2 k_max)/(k + 2 k_max))`, and a step is held only when the method
/// keeps its factorised matrices. The arithmetic is RADAU5's (quotients `h/h_new`), so that
/// [`RadauIIA5`](super::RadauIIA5) repeats `radau5.f`'s steps.
///
/// # References
/// - K. Gustafsson, "Control-theoretic techniques for stepsize selection in implicit
///   Runge–Kutta methods", ACM Trans. Math. Softw. 20(4), 496–517, 1994,
///   doi:10.1145/198429.198437.
/// - E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer,
///   1996, §IV.8, eq. (8.25), doi:10.1007/978-3-642-05221-7; and the code `radau5.f`
///   (`SAFE = 0.9`, `FACL = 5`, `FACR = 1/8`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PredictiveController {
    /// Exponent of the error, `> 0` (RADAU5: 1/4).
    pub exponent: f64,
    /// Safety factor, in `(0, 1)` (default: 0.9).
    pub safety: f64,
    /// Smallest ratio of new to old step, in `(0, 1)` (default: 0.2).
    pub min_factor: f64,
    /// Largest ratio of new to old step, `> 1` (default: 8).
    pub max_factor: f64,
    /// Largest ratio of new to old step that keeps the old step, `≥ 1` (default: 1.2).
    pub hold_max: f64,
    /// Step and error norm (at least 1e-2) of the last accepted step, if any.
    #[serde(skip)]
    last_accepted: Option<(f64, f64)>,
    /// Whether the last attempted step was rejected.
    #[serde(skip)]
    rejected_last: bool,
}

impl PredictiveController {
    /// RADAU5's settings: exponent 1/4, safety 0.9, step ratios in `[0.2, 8]`, steps held for
    /// proposals within `[1, 1.2]`.
    pub fn radau5() -> Self {
        Self {
            exponent: 0.25,
            safety: 0.9,
            min_factor: 0.2,
            max_factor: 8.0,
            hold_max: 1.2,
            last_accepted: None,
            rejected_last: false,
        }
    }
}

impl Default for PredictiveController {
    fn default() -> Self {
        Self::radau5()
    }
}

impl PredictiveController {
    /// The decision, with RADAU5's arithmetic: in quotients `h/h_new`, clamped to
    /// `[1/max_factor, 1/min_factor]` (`FACR`, `FACL`), so that a run repeats `radau5.f`'s
    /// steps to the bit where the estimates agree.
    fn decide_with(&mut self, dt: f64, error_norm: f64, newton: Option<NewtonWork>) -> StepOutcome {
        let (quot_min, quot_max) = (1.0 / self.max_factor, 1.0 / self.min_factor);
        // A NaN quotient (NaN error) becomes `quot_max`: `f64::min` returns the other operand.
        let clamp = |quot: f64| quot.min(quot_max).max(quot_min);
        // RADAU5's `FAC = min(SAFE, CFAC/(NEWT + 2 NIT))` with `CFAC = SAFE (1 + 2 NIT)`:
        // the step grows less after a Newton iteration that needed many iterations.
        let safety = newton.map_or(self.safety, |work| {
            let limit = 2.0 * work.max_iterations as f64;
            let damped = self.safety * (1.0 + limit) / (work.iterations as f64 + limit);
            self.safety.min(damped)
        });
        // RADAU5 accepts only `err < 1` (DOPRI5, and the PI controller, also accept 1).
        if error_norm.is_nan() || error_norm >= 1.0 {
            self.rejected_last = true;
            let dt_retry = if self.last_accepted.is_none() {
                dt * 0.1
            } else {
                // `∞^exponent = ∞`: the largest quotient, `1/min_factor`.
                dt / clamp(error_norm.powf(self.exponent) / safety)
            };
            return StepOutcome::Rejected { dt_retry };
        }
        let error = error_norm.max(1e-10);
        let mut quot = clamp(error.powf(self.exponent) / safety);
        if let Some((dt_previous, error_previous)) = self.last_accepted {
            // Gustafsson's `FACGUS = (h_prev/h) (err²/err_prev)^exponent / SAFE`, with the
            // undamped safety factor as in RADAU5.
            let predictive = (dt_previous / dt)
                * (error * error / error_previous).powf(self.exponent)
                / self.safety;
            quot = quot.max(clamp(predictive));
        }
        let mut dt_next = dt / quot;
        if self.rejected_last {
            dt_next = dt_next.min(dt);
        }
        // Holding the step pays only if the method can keep its factorised matrices.
        let hold = newton.is_none_or(|work| work.matrices_reusable);
        if hold && (1.0..=self.hold_max).contains(&(dt_next / dt)) {
            dt_next = dt;
        }
        self.last_accepted = Some((dt, error.max(1e-2)));
        self.rejected_last = false;
        StepOutcome::Accepted { dt_next }
    }
}

impl StepSizeController for PredictiveController {
    fn reset(&mut self) {
        self.last_accepted = None;
        self.rejected_last = false;
    }

    fn decide(&mut self, dt: f64, error_norm: f64) -> StepOutcome {
        self.decide_with(dt, error_norm, None)
    }

    fn decide_after_newton(
        &mut self,
        dt: f64,
        error_norm_squared: f64,
        newton: NewtonWork,
    ) -> StepOutcome {
        self.decide_with(dt, error_norm_squared.sqrt(), Some(newton))
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

    #[test]
    fn exponents_follow_the_error_order() {
        assert_eq!(PiController::for_error_order(4), PiController::dopri5());
        let bs32 = PiController::for_error_order(2);
        assert!((bs32.alpha - (1.0 / 3.0 - 0.03)).abs() < 1e-15);
        let dop853 = PiController::dop853();
        assert_eq!((dop853.alpha, dop853.beta), (0.125, 0.0));
        assert_eq!((dop853.min_factor, dop853.max_factor), (0.333, 6.0));
    }

    /// When the error grows, Gustafsson's predictive factor
    /// `0.9 (h/h_prev) (err_prev/err)^(1/4) err^(−1/4)` is below the classical one and is
    /// taken: after a step of 2 with error 0.01, a step of 1 with error 0.5 proposes
    /// 0.9 · 0.5 · 0.02^(1/4) · 0.5^(−1/4) = 0.2012 (the classical factor is 1.07).
    #[test]
    fn the_predictive_factor_is_taken_when_the_error_grows() {
        let mut controller = PredictiveController::radau5();
        accepted(controller.decide(2.0, 0.01));
        let next = accepted(controller.decide(1.0, 0.5));
        let predictive = 0.9 * 0.5 * (0.01_f64 / 0.5).powf(0.25) * 0.5_f64.powf(-0.25);
        assert!(predictive < 0.9 * 0.5_f64.powf(-0.25));
        assert!((next - predictive).abs() < 1e-15, "{next} vs {predictive}");
    }

    /// An error norm of exactly 1: the PI controller accepts it (as DOPRI5 does, `err ≤ 1`),
    /// the predictive one rejects it (as RADAU5 does, accepting only `err < 1`).
    #[test]
    fn an_error_of_exactly_one_is_accepted_by_pi_and_rejected_by_radau5() {
        let mut pi = PiController::dopri5();
        assert!(matches!(pi.decide(1.0, 1.0), StepOutcome::Accepted { .. }));
        let mut predictive = PredictiveController::radau5();
        assert!(matches!(
            predictive.decide(1.0, 1.0),
            StepOutcome::Rejected { .. }
        ));
    }

    /// Each adaptive method keeps the controller it is given.
    #[test]
    fn the_methods_keep_the_controller_they_are_given() {
        use crate::integrate::{BogackiShampine32, DormandPrince54, DormandPrince853, RadauIIA5};
        let pi = PiController::dopri5()
            .with_safety(0.8)
            .with_factor_bounds(0.3, 4.0);
        assert_eq!(*DormandPrince54::new().with_controller(pi).controller(), pi);
        assert_eq!(
            *BogackiShampine32::new().with_controller(pi).controller(),
            pi
        );
        assert_eq!(
            *DormandPrince853::new().with_controller(pi).controller(),
            pi
        );
        let predictive = PredictiveController {
            safety: 0.8,
            ..PredictiveController::radau5()
        };
        assert_eq!(
            *RadauIIA5::new().with_controller(predictive).controller(),
            predictive
        );
    }

    /// The predictive controller follows RADAU5: h/10 after a first rejected step, the
    /// classical proposal before any history, the smaller predictive one after, and holds the
    /// step for proposals in [1, 1.2].
    #[test]
    fn predictive_controller_follows_radau5() {
        let mut controller = PredictiveController::radau5();
        assert_eq!(rejected(controller.decide(1.0, 2.0)), 0.1);
        // No growth right after the rejection.
        assert_eq!(accepted(controller.decide(0.1, 1e-6)), 0.1);
        // With history: error shrinking by 16 → predictive factor
        // 0.9 · (h/h_prev) · (err_prev/err)^(1/4) · err^(−1/4), here larger than the
        // classical one, which is taken.
        let mut controller = PredictiveController::radau5();
        let first = accepted(controller.decide(1.0, 0.1));
        assert!((first - 0.9 * 0.1_f64.powf(-0.25)).abs() < 1e-15);
        let second = accepted(controller.decide(1.0, 0.1 / 16.0));
        let classical = 0.9 * (0.1_f64 / 16.0).powf(-0.25);
        let predictive = 0.9 * 16.0_f64.powf(0.25) * (0.1_f64 / 16.0).powf(-0.25);
        assert!((second - classical.min(predictive)).abs() < 1e-14);
        // A proposal within [1, 1.2] keeps the step.
        let mut controller = PredictiveController::radau5();
        assert_eq!(
            accepted(controller.decide(2.0, 0.9 / 1.1_f64.powi(4) * 0.9_f64.powi(3))),
            2.0
        );
        // Bounds.
        let mut controller = PredictiveController::radau5();
        assert_eq!(accepted(controller.decide(1.0, 0.0)), 8.0);
        controller.decide(1.0, 0.5);
        assert_eq!(rejected(controller.decide(1.0, f64::INFINITY)), 0.2);
        assert_eq!(rejected(controller.decide(1.0, f64::NAN)), 0.2);
        controller.reset();
        assert_eq!(rejected(controller.decide(1.0, 3.0)), 0.1);
    }

    /// With the Newton work of the step, the predictive controller lowers its safety factor
    /// as RADAU5 does, to `min(0.9, 0.9 (1 + 2·7)/(k + 2·7))` after `k` of at most 7
    /// iterations (0.9 for `k = 1`, 0.675 for `k = 6`), and holds the step only when the
    /// method can keep its matrices; without it, it decides as before. Other controllers
    /// ignore the Newton work.
    #[test]
    fn the_newton_work_lowers_the_safety_factor_and_gates_the_hold() {
        let work = |iterations, matrices_reusable| NewtonWork {
            iterations,
            max_iterations: 7,
            matrices_reusable,
        };
        let error: f64 = 0.01;
        for (iterations, safety) in [(1, 0.9), (2, 0.9 * 15.0 / 16.0), (6, 0.9 * 15.0 / 20.0)] {
            let mut controller = PredictiveController::radau5();
            let next = accepted(controller.decide_after_newton(
                1.0,
                error * error,
                work(iterations, false),
            ));
            let expected = safety / error.powf(0.25);
            assert!(
                (next - expected).abs() < 1e-15,
                "{iterations}: {next} vs {expected}"
            );
        }
        // A proposal of 1.1 h: held only if the matrices can be kept.
        let error = (0.9_f64 / 1.1).powi(4);
        let mut controller = PredictiveController::radau5();
        assert_eq!(
            accepted(controller.decide_after_newton(2.0, error * error, work(1, true))),
            2.0
        );
        let mut controller = PredictiveController::radau5();
        let next = accepted(controller.decide_after_newton(2.0, error * error, work(1, false)));
        assert!((next - 2.2).abs() < 1e-14, "{next}");
        let mut controller = PredictiveController::radau5();
        assert_eq!(accepted(controller.decide(2.0, error)), 2.0);
        // A rejection (error 4) after six iterations: the retry uses the lowered factor too.
        let mut controller = PredictiveController::radau5();
        accepted(controller.decide(1.0, 0.5));
        let retry = rejected(controller.decide_after_newton(1.0, 16.0, work(6, false)));
        assert!((retry - 0.675 / 2.0_f64.sqrt()).abs() < 1e-15, "{retry}");
        let mut pi = PiController::dopri5();
        let mut same = PiController::dopri5();
        assert_eq!(
            pi.decide_after_newton(1.0, 0.25, work(6, false)),
            same.decide_squared(1.0, 0.25)
        );
    }

    /// The integrators hand the controllers the square of the error norm. Fed the squares of
    /// the same errors, both controllers decide as they do on the norms: the PI controller
    /// (which takes `ln(err²)/2` instead of `ln err`) to a few ulps over a sequence that
    /// crosses the error floor 1e-4 (with an error between it and its square root, 3e-3,
    /// followed by one that remembers it), the rejection bound 1 and the zero, infinite and
    /// NaN errors; RADAU5's controller (the default, `√(err²) = err` exactly) bit for bit.
    #[test]
    fn squared_error_norms_give_the_same_decisions() {
        let errors = [
            0.5,
            0.9,
            1e-4,
            0.99e-4,
            0.0,
            2.0,
            0.3,
            1.0,
            1.0001,
            1e-9,
            7.0,
            f64::INFINITY,
            0.2,
            f64::NAN,
            0.8,
            1e-5,
            0.6,
            3e-3,
            0.5,
        ];
        let close = |a: StepOutcome, b: StepOutcome| match (a, b) {
            (StepOutcome::Accepted { dt_next: x }, StepOutcome::Accepted { dt_next: y })
            | (StepOutcome::Rejected { dt_retry: x }, StepOutcome::Rejected { dt_retry: y }) => {
                (x - y).abs() <= 8.0 * f64::EPSILON * x.abs()
            }
            _ => false,
        };
        let mut controllers: [Box<dyn Fn() -> Box<dyn StepSizeController>>; 3] = [
            Box::new(|| Box::new(PiController::dopri5())),
            Box::new(|| Box::new(PiController::dop853())),
            Box::new(|| Box::new(PredictiveController::radau5())),
        ];
        for (c, make) in controllers.iter_mut().enumerate() {
            let (mut on_norms, mut on_squares) = (make(), make());
            let mut dt = 0.1;
            for &error in &errors {
                let a = on_norms.decide(dt, error);
                let b = on_squares.decide_squared(dt, error * error);
                if c == 2 {
                    assert_eq!(a, b, "RADAU5 at error {error}");
                } else {
                    assert!(close(a, b), "{c}: at error {error}: {a:?} vs {b:?}");
                }
                dt = match a {
                    StepOutcome::Accepted { dt_next } => dt_next,
                    StepOutcome::Rejected { dt_retry } => dt_retry,
                };
            }
        }
    }
}
