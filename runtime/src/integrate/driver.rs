//! The integration loop every method shares: input checks, the fixed and adaptive step
//! sequences, output sampling, statistics and the mapping of failures to errors.

use std::time::Instant;

use crate::ode::OdeSystem;

use super::controller::{StepOutcome, StepSizeController};
use super::error::{IntegrationError, IntegrationFailure};
use super::events::EventTracker;
use super::options::{
    ErrorWeights, IntegratorOptions, OutputTimes, check_initial_state, check_output_times,
    check_step_sizes, check_time_span, check_tolerances,
};
use super::solution::Solution;
use super::stepper::{CheckedRhs, StepFailure, Stepper, SystemShape};

/// Most samples reserved up front for [`OutputTimes::Steps`]; beyond this the solution grows
/// by amortised doubling.
const MAX_RESERVED_SAMPLES: usize = 1 << 16;

/// Samples reserved up front for adaptive [`OutputTimes::Steps`], whose count is unknown.
const ADAPTIVE_RESERVED_SAMPLES: usize = 256;

/// An integration problem, as [`Integrator::integrate`](super::Integrator::integrate)
/// receives it.
pub struct Problem<'a> {
    pub(crate) t0: f64,
    pub(crate) y0: &'a [f64],
    pub(crate) t_end: f64,
    pub(crate) output: &'a OutputTimes,
    pub(crate) options: &'a IntegratorOptions,
}

impl<'a> Problem<'a> {
    /// The problem of one [`Integrator::integrate`](super::Integrator::integrate) call.
    pub(crate) fn new(
        t0: f64,
        y0: &'a [f64],
        t_end: f64,
        output: &'a OutputTimes,
        options: &'a IntegratorOptions,
    ) -> Self {
        Self {
            t0,
            y0,
            t_end,
            output,
            options,
        }
    }
}

/// What each method supplies to [`Integrator::integrate`](super::Integrator::integrate),
/// which is written once: its stepper and step control, handed to [`run`].
///
/// Sealed: the trait is public in a private module, so that only this crate's methods
/// implement [`Integrator`](super::Integrator) (its driver and steppers are internal).
pub trait Method {
    /// Integrates `problem` with this method (a call of [`run`]).
    ///
    /// # Errors
    /// As [`Integrator::integrate`](super::Integrator::integrate).
    fn run(
        &mut self,
        problem: &Problem<'_>,
        system: &mut dyn OdeSystem,
    ) -> Result<Solution, IntegrationFailure>;
}

/// How the step sizes are chosen.
pub(crate) enum Control<'a> {
    /// Constant steps `dt`, the last one shortened to land on `t_end`; no error control.
    Fixed,
    /// Steps chosen by `controller` from the embedded error estimate of order
    /// `error_order`.
    Adaptive {
        controller: &'a mut dyn StepSizeController,
        error_order: u32,
    },
    /// Steps the stepper proposes from its current state ([`Stepper::proposed_step`]: the
    /// Taylor method), capped by `dt_max` and the end of the interval; none is rejected.
    Proposed,
}

impl<'a> Control<'a> {
    /// Constant steps if `options.fixed_step`, else the steps of `controller` from an error
    /// estimate of order `error_order`.
    pub(crate) fn from_options(
        options: &IntegratorOptions,
        controller: &'a mut dyn StepSizeController,
        error_order: u32,
    ) -> Self {
        if options.fixed_step {
            Control::Fixed
        } else {
            Control::Adaptive {
                controller,
                error_order,
            }
        }
    }
}

/// Integrates `problem` with the stepper `make_stepper(shape)` under `control`.
///
/// `make_stepper` runs after the input checks and allocates every buffer of the integration;
/// it may refuse a system whose structure the method cannot use
/// ([`IntegrationError::NotSecondOrder`]).
///
/// # Errors
/// Every [`IntegrationError`]; the failure keeps the samples recorded before it and the
/// statistics, including the wall time.
pub(crate) fn run<S: Stepper>(
    problem: &Problem<'_>,
    system: &mut dyn OdeSystem,
    control: Control<'_>,
    make_stepper: impl FnOnce(SystemShape) -> Result<S, IntegrationError>,
) -> Result<Solution, IntegrationFailure> {
    let start = Instant::now();
    let shape = SystemShape {
        dim: system.dim(),
        second_order_dim: system.second_order_dim(),
    };
    let mut solution = Solution::new(shape.dim);
    let mut rhs = CheckedRhs::new(system);
    let result = integrate_into(
        problem,
        &mut rhs,
        control,
        shape,
        make_stepper,
        &mut solution,
    );
    solution.stats.rhs_evals = rhs.evals();
    solution.stats.jacobian_evals = rhs.jacobian_evals();
    solution.stats.lu_decompositions = rhs.lu_decompositions();
    solution.stats.event_evals = rhs.event_evals();
    solution.stats.taylor_series = rhs.taylor_series();
    solution.stats.wall_time_s = start.elapsed().as_secs_f64();
    match result {
        Ok(()) => Ok(solution),
        Err(error) => Err(IntegrationFailure {
            error,
            partial: Box::new(solution),
        }),
    }
}

/// The smallest usable step at time `t`: below `16 ε |t|` the step no longer changes `t` by
/// more than a few bits, and `16 ε (t_end − t0)` is a floor near `t = 0` (a step of
/// `10⁻¹⁵` of the interval only happens at a singularity).
fn min_step(t: f64, span: f64) -> f64 {
    16.0 * f64::EPSILON * t.abs().max(span)
}

fn integrate_into<S: Stepper>(
    problem: &Problem<'_>,
    rhs: &mut CheckedRhs<'_>,
    control: Control<'_>,
    shape: SystemShape,
    make_stepper: impl FnOnce(SystemShape) -> Result<S, IntegrationError>,
    solution: &mut Solution,
) -> Result<(), IntegrationError> {
    let dim = solution.dim;
    check_time_span(problem.t0, problem.t_end)?;
    check_initial_state(dim, problem.t0, problem.y0)?;
    let weights = check_tolerances(problem.options, dim)?;
    check_step_sizes(problem.options)?;
    check_output_times(problem.output, problem.t0, problem.t_end)?;

    let mut stepper = make_stepper(shape)?;
    stepper
        .reset(rhs, problem.t0, problem.y0)
        .map_err(StepFailure::into_error)?;
    let mut recorder = Recorder::new(problem.output);
    let mut events = EventTracker::new(rhs, dim);
    if let Some(events) = events.as_mut() {
        events
            .start(rhs, problem.t0, problem.y0)
            .map_err(StepFailure::into_error)?;
    }
    let mut finish = Finish {
        recorder: &mut recorder,
        events: events.as_mut(),
    };
    match control {
        Control::Fixed => {
            let dt = fixed_step(problem);
            if let OutputTimes::Steps = problem.output {
                let steps = ((problem.t_end - problem.t0) / dt).ceil();
                // Float-to-int `as` saturates (and maps NaN to 0); the reservation is a hint.
                solution.reserve((steps as usize).min(MAX_RESERVED_SAMPLES) + 1);
            }
            finish.recorder.start(solution, problem.t0, problem.y0);
            fixed_steps(
                problem,
                dt,
                &weights,
                rhs,
                &mut stepper,
                &mut finish,
                solution,
            )
        }
        Control::Adaptive {
            controller,
            error_order,
        } => {
            if let OutputTimes::Steps = problem.output {
                solution.reserve(ADAPTIVE_RESERVED_SAMPLES);
            }
            finish.recorder.start(solution, problem.t0, problem.y0);
            let adaptive = Adaptive {
                weights: &weights,
                controller,
                error_order,
            };
            adaptive_steps(problem, adaptive, rhs, &mut stepper, &mut finish, solution)
        }
        Control::Proposed => {
            if let OutputTimes::Steps = problem.output {
                solution.reserve(ADAPTIVE_RESERVED_SAMPLES);
            }
            finish.recorder.start(solution, problem.t0, problem.y0);
            proposed_steps(problem, &weights, rhs, &mut stepper, &mut finish, solution)
        }
    }
}

/// Steps of the sizes the stepper proposes ([`Stepper::proposed_step`]), at most `dt_max`; a
/// step within 1 % of the end is stretched onto it, as in adaptive stepping. A failure ends
/// the run: with the step chosen a priori there is no error to shrink it by.
fn proposed_steps<S: Stepper>(
    problem: &Problem<'_>,
    weights: &ErrorWeights,
    rhs: &mut CheckedRhs<'_>,
    stepper: &mut S,
    finish: &mut Finish<'_, '_>,
    solution: &mut Solution,
) -> Result<(), IntegrationError> {
    let (t0, t_end) = (problem.t0, problem.t_end);
    let mut corrected = vec![0.0; stepper.y().len()];
    let span = t_end - t0;
    let dt_max = problem
        .options
        .dt_max
        .map_or(span, |dt_max| dt_max.min(span));
    while stepper.t() < t_end {
        let t = stepper.t();
        if solution.stats.steps >= problem.options.max_steps {
            return Err(IntegrationError::TooManySteps {
                t,
                max_steps: problem.options.max_steps,
            });
        }
        // A NaN proposal (a non-finite series), or none, is too small as well (checked before
        // `min`, which would return `dt_max` for NaN).
        let proposed = stepper.proposed_step().unwrap_or(f64::NAN);
        if proposed.is_nan() || proposed < min_step(t, span) {
            return Err(IntegrationError::StepSizeTooSmall { t, dt: proposed });
        }
        let dt = proposed.min(dt_max);
        let t_new = if t + 1.01 * dt >= t_end && t_end - t <= dt_max {
            t_end
        } else {
            t + dt
        };
        stepper
            .attempt(rhs, t_new, weights, false)
            .map_err(StepFailure::into_error)?;
        stepper.accept(rhs).map_err(StepFailure::into_error)?;
        solution.stats.steps += 1;
        if finish
            .step(rhs, stepper, &mut corrected, solution)
            .map_err(StepFailure::into_error)?
        {
            return Ok(());
        }
    }
    Ok(())
}

/// The fixed step: `dt` (default `(t_end − t0)/1000`), at most `dt_max`.
fn fixed_step(problem: &Problem<'_>) -> f64 {
    let span = problem.t_end - problem.t0;
    let dt = problem
        .options
        .dt
        .unwrap_or(span / f64::from(IntegratorOptions::DEFAULT_FIXED_STEPS));
    problem.options.dt_max.map_or(dt, |dt_max| dt.min(dt_max))
}

/// Constant steps of `dt`, step `k` ending at `t0 + k dt` (computed afresh, so the grid does
/// not drift by accumulated rounding) and the last ending exactly at `t_end`.
fn fixed_steps<S: Stepper>(
    problem: &Problem<'_>,
    dt: f64,
    weights: &ErrorWeights,
    rhs: &mut CheckedRhs<'_>,
    stepper: &mut S,
    finish: &mut Finish<'_, '_>,
    solution: &mut Solution,
) -> Result<(), IntegrationError> {
    let (t0, t_end) = (problem.t0, problem.t_end);
    let mut corrected = vec![0.0; stepper.y().len()];
    let largest_t = t0.abs().max(t_end.abs());
    if dt.is_nan() || dt < min_step(largest_t, t_end - t0) {
        return Err(IntegrationError::StepSizeTooSmall { t: t0, dt });
    }
    // A grid point this close to t_end is taken as t_end, rather than leaving a sliver step
    // made of rounding error (t0 + N dt misses t_end by a few ulps for most dt).
    let snap = (1e-9 * dt).max(8.0 * f64::EPSILON * largest_t);
    let mut k: u64 = 0;
    while stepper.t() < t_end {
        if solution.stats.steps >= problem.options.max_steps {
            return Err(IntegrationError::TooManySteps {
                t: stepper.t(),
                max_steps: problem.options.max_steps,
            });
        }
        k += 1;
        let mut t_new = t0 + k as f64 * dt;
        if t_new >= t_end - snap {
            t_new = t_end;
        }
        stepper
            .attempt(rhs, t_new, weights, false)
            .map_err(StepFailure::into_error)?;
        stepper.accept(rhs).map_err(StepFailure::into_error)?;
        solution.stats.steps += 1;
        if finish
            .step(rhs, stepper, &mut corrected, solution)
            .map_err(StepFailure::into_error)?
        {
            return Ok(());
        }
    }
    Ok(())
}

/// What adaptive stepping needs besides the problem.
struct Adaptive<'a, 'c> {
    weights: &'a ErrorWeights,
    controller: &'c mut dyn StepSizeController,
    error_order: u32,
}

/// Error-controlled steps: each attempt is accepted or rejected by the controller.
///
/// A step stretched by up to 1 % (but never beyond `dt_max`) lands on `t_end` rather than
/// leaving a tiny last step (as Hairer's codes do). An attempt whose right-hand side or
/// candidate is not finite, or whose Newton iteration fails, counts as an infinite error, so
/// the step shrinks (by the factor the method proposes for a Newton failure, else by the
/// controller's); if that persists until the step is too small, that failure is reported
/// rather than [`IntegrationError::StepSizeTooSmall`].
fn adaptive_steps<S: Stepper>(
    problem: &Problem<'_>,
    adaptive: Adaptive<'_, '_>,
    rhs: &mut CheckedRhs<'_>,
    stepper: &mut S,
    finish: &mut Finish<'_, '_>,
    solution: &mut Solution,
) -> Result<(), IntegrationError> {
    let Adaptive {
        weights,
        controller,
        error_order,
    } = adaptive;
    let (t0, t_end) = (problem.t0, problem.t_end);
    let mut corrected = vec![0.0; stepper.y().len()];
    let span = t_end - t0;
    let max_steps = problem.options.max_steps;
    let dt_max = problem
        .options
        .dt_max
        .map_or(span, |dt_max| dt_max.min(span));
    let mut dt = match problem.options.dt {
        Some(dt) => dt.min(dt_max),
        None => initial_step(rhs, stepper, weights, error_order, dt_max, span),
    };
    controller.reset();
    let mut last_failure: Option<StepFailure> = None;
    let mut attempts: usize = 0;
    while stepper.t() < t_end {
        let t = stepper.t();
        if attempts >= max_steps {
            return Err(IntegrationError::TooManySteps { t, max_steps });
        }
        // A NaN step (from a controller with NaN parameters) is too small as well.
        if dt.is_nan() || dt < min_step(t, span) {
            return Err(match last_failure {
                Some(failure) => failure.into_error(),
                None => IntegrationError::StepSizeTooSmall { t, dt },
            });
        }
        let t_new = if t + 1.01 * dt >= t_end && t_end - t <= dt_max {
            t_end
        } else {
            t + dt
        };
        attempts += 1;
        let (error_squared, usable) = match stepper.attempt(rhs, t_new, weights, true) {
            Ok(error_squared) => {
                last_failure = None;
                debug_assert!(
                    error_squared.is_some(),
                    "adaptive stepping needs an estimator"
                );
                (error_squared.unwrap_or(0.0), true)
            }
            Err(failure) if failure.is_recoverable() => {
                last_failure = Some(failure);
                (f64::INFINITY, false)
            }
            Err(failure) => return Err(failure.into_error()),
        };
        let outcome = match stepper.newton_work() {
            Some(work) if usable => controller.decide_after_newton(t_new - t, error_squared, work),
            _ => controller.decide_squared(t_new - t, error_squared),
        };
        match outcome {
            // `usable` guards against a controller that would accept an infinite error.
            StepOutcome::Accepted { dt_next } if usable => {
                stepper.accept(rhs).map_err(StepFailure::into_error)?;
                solution.stats.steps += 1;
                if finish
                    .step(rhs, stepper, &mut corrected, solution)
                    .map_err(StepFailure::into_error)?
                {
                    return Ok(());
                }
                dt = dt_next.min(dt_max);
            }
            StepOutcome::Accepted { .. } => {
                solution.stats.rejected += 1;
                dt = 0.2 * (t_new - t);
            }
            StepOutcome::Rejected { dt_retry } => {
                solution.stats.rejected += 1;
                dt = dt_retry;
            }
        }
        if let Some(factor) = last_failure.as_ref().and_then(StepFailure::retry_factor) {
            dt = factor * (t_new - t);
        }
    }
    Ok(())
}

/// Weighted RMS norm `√(Σᵢ (vᵢ / scaleᵢ)² / n)`; a zero entry counts as zero even where its
/// scale is zero.
fn weighted_rms(n: usize, mut ratio: impl FnMut(usize) -> (f64, f64)) -> f64 {
    if n == 0 {
        return 0.0;
    }
    let sum: f64 = (0..n)
        .map(|i| {
            let (value, scale) = ratio(i);
            if value == 0.0 {
                0.0
            } else {
                (value / scale).powi(2)
            }
        })
        .sum();
    (sum / n as f64).sqrt()
}

/// A first step for an adaptive method, from `F` at the start and one explicit Euler probe
/// (one evaluation of `F`), following Hairer, Nørsett and Wanner.
///
/// With `‖·‖` the weighted RMS norm with scales `atolᵢ + rtolᵢ |y₀ᵢ|`:
///
/// ```text
/// d₀ = ‖y₀‖, d₁ = ‖F(t₀, y₀)‖
/// h₀ = 0.01 d₀/d₁                      (1e-6 if d₀ or d₁ < 1e-5)
/// y₁ = y₀ + h₀ F(t₀, y₀),  d₂ = ‖F(t₀ + h₀, y₁) − F(t₀, y₀)‖ / h₀
/// h₁ = (0.01 / max(d₁, d₂))^(1/(q+1))  (max(1e-6, 1e-3 h₀) if max(d₁, d₂) ≤ 1e-15)
/// h  = min(100 h₀, h₁, dt_max)
/// ```
///
/// with `q` the order of the error estimator. If the probe fails, `h₀` is used.
///
/// # References
/// E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed.,
/// Springer, 1993, §II.4 ("Starting step size"), doi:10.1007/978-3-540-78862-1.
fn initial_step<S: Stepper>(
    rhs: &mut CheckedRhs<'_>,
    stepper: &S,
    weights: &ErrorWeights,
    error_order: u32,
    dt_max: f64,
    span: f64,
) -> f64 {
    let (t0, y0, f0) = (stepper.t(), stepper.y(), stepper.derivative());
    let n = y0.len();
    let scale = |i: usize| weights.scale(i, y0[i].abs());
    let d0 = weighted_rms(n, |i| (y0[i], scale(i)));
    let d1 = weighted_rms(n, |i| (f0[i], scale(i)));
    let mut h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    if !(h0.is_finite() && h0 > 0.0) {
        h0 = 1e-6;
    }
    let dt_min = min_step(t0, span);
    let wanted = h0.min(dt_max);
    h0 = wanted.max(dt_min);
    // Two buffers once per integration, not per step.
    let y1: Vec<f64> = y0.iter().zip(f0).map(|(y, f)| y + h0 * f).collect();
    let mut f1 = vec![0.0; n];
    if rhs.eval(t0 + h0, &y1, &mut f1).is_err() {
        return h0;
    }
    let d2 = weighted_rms(n, |i| (f1[i] - f0[i], scale(i))) / h0;
    let d_max = d1.max(d2);
    let h1 = if d_max <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d_max).powf(1.0 / f64::from(error_order + 1))
    };
    // `f64::min`/`max` ignore a NaN operand, so the result is a number.
    let h = (100.0 * h0).min(h1).min(dt_max);
    // A sound estimate (the start's derivative of finite norm) below the smallest usable
    // step: the motion needs steps finer than f64 resolves t near the end time (an end time
    // of 1e300 s, where that step is 3.6e285 s, and the probe's change of the derivative
    // overflows). Returned, the step loop refuses it at t0; raised, it would be taken and
    // overflow the state. A start whose own norm overflows (a push of 1e300 N against an
    // absolute tolerance) is no evidence, and the step is raised as before.
    if d1.is_finite() && h < dt_min {
        return if h > 0.0 { h } else { wanted };
    }
    h.max(dt_min)
}

/// What happens after every accepted step: events are looked for, the samples recorded and
/// the state corrected ([`OdeSystem::after_step`]).
struct Finish<'r, 'e> {
    recorder: &'r mut Recorder<'r>,
    events: Option<&'e mut EventTracker>,
}

impl Finish<'_, '_> {
    /// Handles the step the stepper has just accepted; returns whether a terminal event ended
    /// the integration (its samples then end at the event).
    fn step<S: Stepper>(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        stepper: &mut S,
        corrected: &mut [f64],
        solution: &mut Solution,
    ) -> Result<bool, StepFailure> {
        let stop_at = match self.events.as_deref_mut() {
            Some(events) => events.check_step(rhs, stepper, solution)?,
            None => None,
        };
        let first_sample = solution.t.len();
        match stop_at {
            Some(t_event) => {
                self.recorder
                    .record_until(solution, stepper, rhs, t_event)?;
                project_samples(rhs, corrected, solution, first_sample)?;
                Ok(true)
            }
            None => {
                self.recorder.record_step(solution, stepper, rhs)?;
                // When the step's one sample is its end (every step recorded), the correction
                // of the state serves the sample too: one call of `after_step`, not two.
                let end_only =
                    solution.t.len() == first_sample + 1 && solution.t[first_sample] == stepper.t();
                if !end_only {
                    project_samples(rhs, corrected, solution, first_sample)?;
                }
                if correct_state(rhs, stepper, corrected)? {
                    if end_only {
                        let dim = corrected.len();
                        let row = first_sample * dim..(first_sample + 1) * dim;
                        solution.y[row].copy_from_slice(corrected);
                    }
                    if let Some(events) = self.events.as_deref_mut() {
                        events.start(rhs, stepper.t(), stepper.y())?;
                    }
                }
                Ok(false)
            }
        }
    }
}

/// Records the samples [`OutputTimes`] asks for, as the steps go by.
struct Recorder<'a> {
    /// The requested times, or `None` to record every step.
    times: Option<&'a [f64]>,
    /// The first requested time not yet recorded.
    next: usize,
}

impl<'a> Recorder<'a> {
    fn new(output: &'a OutputTimes) -> Self {
        let times = match output {
            OutputTimes::Steps => None,
            OutputTimes::At(times) => Some(times.as_slice()),
        };
        Self { times, next: 0 }
    }

    /// Records the initial state: as the first step sample, or for requested times at `t0`.
    fn start(&mut self, solution: &mut Solution, t0: f64, y0: &[f64]) {
        match self.times {
            None => solution.push(t0, y0),
            Some(times) => {
                solution.reserve(times.len());
                while self.next < times.len() && times[self.next] <= t0 {
                    solution.push(times[self.next], y0);
                    self.next += 1;
                }
            }
        }
    }

    /// Records after an accepted step: its end, or the requested times it covers, by dense
    /// output (a time equal to the step's end gets the step's state exactly). The dense output
    /// is completed ([`Stepper::prepare_dense_output`]) only for a step that needs it.
    ///
    /// # Errors
    /// The failure of an evaluation that completes the dense output.
    fn record_step<S: Stepper>(
        &mut self,
        solution: &mut Solution,
        stepper: &mut S,
        rhs: &mut CheckedRhs<'_>,
    ) -> Result<(), StepFailure> {
        let t = stepper.t();
        match self.times {
            None => solution.push(t, stepper.y()),
            Some(times) => {
                let mut prepared = false;
                while self.next < times.len() && times[self.next] <= t {
                    let t_out = times[self.next];
                    debug_assert!(t_out >= stepper.interval().0);
                    if t_out == t {
                        solution.push(t, stepper.y());
                    } else {
                        if !prepared {
                            stepper.prepare_dense_output(rhs)?;
                            prepared = true;
                        }
                        solution.push_with(t_out, |out| stepper.interpolate(t_out, out));
                    }
                    self.next += 1;
                }
            }
        }
        Ok(())
    }

    /// Records after the step in which a terminal event at `t_event` ended the integration:
    /// the requested times up to `t_event` by dense output, or (recording every step) the
    /// event's state as the last sample.
    ///
    /// # Errors
    /// The failure of an evaluation that completes the dense output.
    fn record_until<S: Stepper>(
        &mut self,
        solution: &mut Solution,
        stepper: &mut S,
        rhs: &mut CheckedRhs<'_>,
        t_event: f64,
    ) -> Result<(), StepFailure> {
        let (t_step, t_end) = (stepper.t(), t_event);
        let sample = |t: f64, out: &mut [f64], stepper: &S| {
            if t == t_step {
                out.copy_from_slice(stepper.y());
            } else {
                stepper.interpolate(t, out);
            }
        };
        stepper.prepare_dense_output(rhs)?;
        match self.times {
            None => solution.push_with(t_end, |out| sample(t_end, out, stepper)),
            Some(times) => {
                while self.next < times.len() && times[self.next] <= t_end {
                    let t_out = times[self.next];
                    solution.push_with(t_out, |out| sample(t_out, out, stepper));
                    self.next += 1;
                }
            }
        }
        Ok(())
    }
}

/// Gives the samples recorded during a step (from `first_sample` on, interpolated before any
/// correction of the state) the system's correction after a step ([`OdeSystem::after_step`]:
/// projection onto a constrained system's manifold), so the output satisfies what the state
/// does. `corrected` is a `dim`-entry scratch buffer.
fn project_samples(
    rhs: &mut CheckedRhs<'_>,
    corrected: &mut [f64],
    solution: &mut Solution,
    first_sample: usize,
) -> Result<(), StepFailure> {
    if !rhs.corrects_state() {
        return Ok(());
    }
    let dim = corrected.len();
    for i in first_sample..solution.t.len() {
        let row = &mut solution.y[i * dim..(i + 1) * dim];
        corrected.copy_from_slice(row);
        if rhs.after_step(solution.t[i], corrected)? {
            row.copy_from_slice(corrected);
        }
    }
    Ok(())
}

/// Lets the system correct the state after an accepted step ([`OdeSystem::after_step`]) and,
/// if it did, restarts the stepper there; returns whether it did.
fn correct_state<S: Stepper>(
    rhs: &mut CheckedRhs<'_>,
    stepper: &mut S,
    corrected: &mut [f64],
) -> Result<bool, StepFailure> {
    if !rhs.corrects_state() {
        return Ok(false);
    }
    let t = stepper.t();
    corrected.copy_from_slice(stepper.y());
    if rhs.after_step(t, corrected)? {
        stepper.reset(rhs, t, corrected)?;
        return Ok(true);
    }
    Ok(false)
}

#[cfg(test)]
mod tests;
