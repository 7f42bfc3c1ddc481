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
pub(crate) struct Problem<'a> {
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
    let t = stepper.t();
    corrected.copy_from_slice(stepper.y());
    if rhs.after_step(t, corrected)? {
        stepper.reset(rhs, t, corrected)?;
        return Ok(true);
    }
    Ok(false)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::controller::{PiController, StepOutcome, StepSizeController};
    use crate::integrate::explicit_rk::ExplicitRk;
    use crate::integrate::tableau::Tableau;
    use crate::integrate::{DormandPrince54, DormandPrince853, Integrator, RungeKutta4};
    use crate::ode::{OdeFn, RhsError};

    /// DOPRI5's stepper over `[t0, t_end]` with the given controller, every step recorded.
    fn dopri5_run(
        system: &mut dyn OdeSystem,
        (t0, t_end): (f64, f64),
        options: &IntegratorOptions,
        controller: &mut dyn StepSizeController,
    ) -> Result<Solution, IntegrationFailure> {
        let y0 = vec![1.0; system.dim()];
        let problem = Problem {
            t0,
            y0: &y0,
            t_end,
            output: &OutputTimes::Steps,
            options,
        };
        let control = Control::Adaptive {
            controller,
            error_order: 4,
        };
        run(&problem, system, control, |shape| {
            Ok(ExplicitRk::new(Tableau::dopri5(), shape.dim))
        })
    }

    /// Breaks the controller's contract: accepts every step, then proposes 0.1.
    struct AcceptsEverything;

    impl StepSizeController for AcceptsEverything {
        fn reset(&mut self) {}
        fn decide(&mut self, _dt: f64, _error_norm: f64) -> StepOutcome {
            StepOutcome::Accepted { dt_next: 0.1 }
        }
    }

    /// An attempt with a NaN stage is rejected even by a controller that accepts every error
    /// (`∞` included), and retried at a fifth of its size: the steps of 0.1 run to 0.2, the
    /// attempt to 0.3 meets a one-off NaN at t = 0.28 (DOPRI5's third stage), the retry ends
    /// at 0.22, and the run goes on to t = 1 with a finite state, one rejection counted.
    #[test]
    fn a_controller_accepting_a_failed_attempt_is_overruled() {
        let mut fired = false;
        let mut system = OdeFn::new(1, move |t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = -y[0];
            if t > 0.25 && !fired {
                fired = true;
                dy[0] = f64::NAN;
            }
        });
        let options = IntegratorOptions::default().with_dt(0.1);
        let solution =
            dopri5_run(&mut system, (0.0, 1.0), &options, &mut AcceptsEverything).unwrap();
        assert_eq!(solution.stats.rejected, 1);
        let t2 = solution.t[2];
        let failed = (t2 + 0.1) - t2;
        assert_eq!(solution.t[3], t2 + 0.2 * failed, "{:?}", solution.t);
        assert_eq!(solution.t[4], solution.t[3] + 0.1, "{:?}", solution.t);
        assert_eq!(*solution.t.last().unwrap(), 1.0);
        assert!(solution.y.iter().all(|y| y.is_finite()));
    }

    /// A controller that decides as RADAU5's does and records how it was asked.
    #[derive(Default)]
    struct Recorder {
        inner: crate::integrate::PredictiveController,
        /// Errors handed over without Newton work.
        plain: Vec<f64>,
        /// Errors handed over with Newton work.
        with_newton: Vec<f64>,
    }

    impl StepSizeController for Recorder {
        fn reset(&mut self) {
            self.inner.reset();
        }
        fn decide(&mut self, dt: f64, error_norm: f64) -> StepOutcome {
            self.plain.push(error_norm);
            self.inner.decide(dt, error_norm)
        }
        fn decide_after_newton(
            &mut self,
            dt: f64,
            error_norm_squared: f64,
            newton: crate::integrate::NewtonWork,
        ) -> StepOutcome {
            self.with_newton.push(error_norm_squared.sqrt());
            self.inner
                .decide_after_newton(dt, error_norm_squared, newton)
        }
    }

    /// The controller hears the Newton work only of attempts whose iteration converged: an
    /// attempt whose iteration failed (some tens on van der Pol's equation with `ε = 10⁻⁶`
    /// at a loose tolerance) comes as an infinite error without it, since its work is not
    /// that of a step.
    #[test]
    fn newton_work_is_reported_only_for_converged_attempts() {
        let mut system = OdeFn::new(2, |_t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = y[1];
            dy[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / 1e-6;
        });
        let options = IntegratorOptions::default()
            .with_rtol(1e-3)
            .with_atol(1e-3)
            .with_dt(1e-6);
        let problem = Problem {
            t0: 0.0,
            y0: &[2.0, -0.66],
            t_end: 2.0,
            output: &OutputTimes::Steps,
            options: &options,
        };
        let mut recorder = Recorder::default();
        let control = Control::Adaptive {
            controller: &mut recorder,
            error_order: 3,
        };
        let solution = run(&problem, &mut system, control, |shape| {
            Ok(crate::integrate::radau5::RadauStepper::new(shape.dim, 7))
        })
        .unwrap();
        let attempts = solution.stats.steps + solution.stats.rejected;
        assert_eq!(recorder.plain.len() + recorder.with_newton.len(), attempts);
        assert!(recorder.with_newton.iter().all(|e| e.is_finite()));
        assert!(!recorder.plain.is_empty(), "no failed iteration");
        assert!(recorder.plain.iter().all(|e| e.is_infinite()));
    }

    /// A system that evaluates normally until `t > 0.25`, then reports a singular mass
    /// matrix, counting those reports.
    struct SingularAfter {
        reports: usize,
    }

    impl OdeSystem for SingularAfter {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
            if t > 0.25 {
                self.reports += 1;
                return Err(RhsError::SingularMassMatrix);
            }
            dy[0] = -y[0];
            Ok(())
        }
    }

    /// A failure that a smaller step cannot cure (a singular mass matrix) ends the run at
    /// the first evaluation that reports it, with no retry, and at that evaluation's time.
    #[test]
    fn a_failure_no_smaller_step_cures_ends_the_run_at_once() {
        let mut system = SingularAfter { reports: 0 };
        let options = IntegratorOptions::default();
        let failure = dopri5_run(
            &mut system,
            (0.0, 1.0),
            &options,
            &mut PiController::dopri5(),
        )
        .unwrap_err();
        assert_eq!(system.reports, 1);
        match failure.error {
            IntegrationError::SingularMassMatrix { t } => assert!(t > 0.25 && t < 1.0, "{t}"),
            other => panic!("{other:?}"),
        }
    }

    /// Adaptive and fixed steps over an interval that starts at a negative time (the span,
    /// not `t_end + t0`, bounds the steps): `ẏ = −y` from t = −1 to 1 ends at `e⁻²`.
    #[test]
    fn an_interval_may_start_before_zero() {
        let exact = (-2.0f64).exp();
        let options = IntegratorOptions::default()
            .with_rtol(1e-9)
            .with_atol(1e-12);
        let fixed = options.clone().with_fixed_step(true).with_dt(0.01);
        for (method, options, bound) in [
            (
                &mut DormandPrince54::new() as &mut dyn Integrator,
                &options,
                1e-8,
            ),
            (&mut RungeKutta4::new(), &fixed, 1e-9),
        ] {
            let mut system = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0]);
            let solution = method
                .integrate(&mut system, -1.0, &[1.0], 1.0, &OutputTimes::Steps, options)
                .unwrap();
            let last = solution.y[solution.y.len() - 1];
            assert!((last - exact).abs() < bound, "{}: {last}", method.name());
        }
    }

    /// A fixed step of 20 rounding units of `t_end` (above the smallest step, 16 units of
    /// `max(|t|, span)`) is taken: the run stops at its step budget, not for a step too small.
    #[test]
    fn a_fixed_step_just_above_the_smallest_is_taken() {
        let mut system = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0]);
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(40.0 * f64::EPSILON)
            .with_max_steps(5);
        let failure = RungeKutta4::new()
            .integrate(&mut system, 1.0, &[1.0], 2.0, &OutputTimes::Steps, &options)
            .unwrap_err();
        assert!(
            matches!(
                failure.error,
                IntegrationError::TooManySteps { max_steps: 5, .. }
            ),
            "{:?}",
            failure.error
        );
    }

    /// A fixed step that would end 3 rounding units (of `t_end` = 4) short of `t_end` ends
    /// at `t_end`: one step, no sliver step after it. The step is 2⁻²⁰ long, so the
    /// allowance is the 8 rounding units of `t_end`, not `10⁻⁹ dt` (one unit).
    #[test]
    fn a_step_a_few_rounding_units_short_of_the_end_ends_there() {
        let t_end = 4.0;
        let unit = 4.0 * f64::EPSILON;
        let t0 = t_end - (-20.0f64).exp2();
        // Exact (Sterbenz): both ends lie within a factor 2 of each other.
        let dt = (t_end - 3.0 * unit) - t0;
        let mut system = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0]);
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(dt);
        let solution = RungeKutta4::new()
            .integrate(
                &mut system,
                t0,
                &[1.0],
                t_end,
                &OutputTimes::Steps,
                &options,
            )
            .unwrap();
        assert_eq!(solution.t, [t0, t_end]);
    }

    /// A fixed step so much larger than the interval that `span / dt` underflows to 0 still
    /// takes the one step the interval needs.
    #[test]
    fn a_fixed_step_far_larger_than_the_interval_takes_one_step() {
        let mut system = OdeFn::new(1, |_t: f64, _y: &[f64], dy: &mut [f64]| dy[0] = 1.0);
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(1e300);
        let solution = RungeKutta4::new()
            .integrate(
                &mut system,
                0.0,
                &[0.0],
                1e-30,
                &OutputTimes::Steps,
                &options,
            )
            .unwrap();
        assert_eq!(solution.t, [0.0, 1e-30]);
        // y' = 1: one RK4 step is exact up to the rounding of its weights' sum.
        assert!((solution.y[1] / 1e-30 - 1.0).abs() < 1e-15);
    }

    /// [`initial_step`] for a DOPRI5 stepper (estimator order 4) started at `(t0, y0)`.
    fn first_step(
        f: impl FnMut(f64, &[f64], &mut [f64]),
        (t0, y0): (f64, &[f64]),
        (rtol, atol): (f64, f64),
        dt_max: f64,
    ) -> f64 {
        let mut system = OdeFn::new(y0.len(), f);
        let mut rhs = CheckedRhs::new(&mut system);
        let mut stepper = ExplicitRk::new(Tableau::dopri5(), y0.len());
        stepper.reset(&mut rhs, t0, y0).unwrap();
        let weights = ErrorWeights::uniform(y0.len(), rtol, atol);
        initial_step(&mut rhs, &stepper, &weights, 4, dt_max, 10.0)
    }

    /// Hairer's starting step, worked by hand on problems where every quantity has a closed
    /// form (scale `s = atol + rtol |y₀|`, estimator order q = 4, so `h₁ = (0.01/d)^(1/5)`).
    /// Each case takes another branch: both norms large; `‖y₀‖` small; `‖F‖` small; `‖F‖`
    /// infinite with a failing probe; `F = 0` (the 1e-6 floor of `h₁`); a time-dependent `F`
    /// (the probe's time); `dt_max`.
    #[test]
    fn the_initial_step_is_hairers_starting_step() {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        // ẏ = −2y², y₀ = 1: d₀ = 1/s, d₁ = 2/s, h₀ = 0.005, the probe y₁ = 0.99 gives
        // d₂ = ((2 − 2 · 0.99²)/s) / h₀ = 7.96/s, so h = min(100 h₀, (0.01 s/7.96)^(1/5)).
        let quadratic = |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -2.0 * y[0] * y[0];
        let s: f64 = 2e-6;
        let h = first_step(quadratic, (0.0, &[1.0]), (1e-6, 1e-6), 10.0);
        assert!(close(h, (0.01 * s / 7.96).powf(0.2)), "{h}");
        assert_eq!(
            first_step(quadratic, (0.0, &[1.0]), (1e-6, 1e-6), 0.01),
            0.01
        );
        // ẏ = −2y, y₀ = 1e-12 with atol = 1e-6: d₀ ≈ 1e-6 < 1e-5, so h₀ = 1e-6; d₂ ≈ 4e-6
        // gives h₁ ≈ 4.8, and h = 100 h₀.
        let decay = |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -2.0 * y[0];
        let h = first_step(decay, (0.0, &[1e-12]), (1e-6, 1e-6), 10.0);
        assert!(close(h, 1e-4), "{h}");
        // ẏ = 1, y₀ = 1e-12: d₀ ≈ 1e-6 < 1e-5 while d₁ = 1e6, so h₀ = 1e-6 (not
        // 0.01 d₀/d₁ = 1e-14); d₂ = 0 and h₁ = (1e-8)^(1/5), so h = 100 h₀.
        let constant = |_t: f64, _y: &[f64], dy: &mut [f64]| dy[0] = 1.0;
        let h = first_step(constant, (0.0, &[1e-12]), (1e-6, 1e-6), 10.0);
        assert!(close(h, 1e-4), "{h}");
        // ẏ = 1e-12 y: d₁ = 5e-7 < 1e-5, so h₀ = 1e-6 and h = 100 h₀ again.
        let slow = |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = 1e-12 * y[0];
        let h = first_step(slow, (0.0, &[1.0]), (1e-6, 1e-6), 10.0);
        assert!(close(h, 1e-4), "{h}");
        // A component at 0 with atol = 0 and F ≠ 0: zero scale, d₁ = ∞, so 0.01 d₀/d₁ = 0
        // is replaced by h₀ = 1e-6; a probe that fails (F is NaN after t₀) returns h₀.
        let stuck = |t: f64, _y: &[f64], dy: &mut [f64]| {
            dy[0] = 1.0;
            dy[1] = if t > 0.0 { f64::NAN } else { 1.0 };
        };
        assert_eq!(
            first_step(stuck, (0.0, &[1.0, 0.0]), (1e-6, 0.0), 10.0),
            1e-6
        );
        // ẏ = 0: d₁ = d₂ = 0, h₀ = 1e-6 and h₁ = max(1e-6, 1e-3 h₀) = 1e-6.
        let still = |_t: f64, _y: &[f64], dy: &mut [f64]| dy[0] = 0.0;
        assert_eq!(first_step(still, (0.0, &[1.0]), (1e-6, 1e-6), 10.0), 1e-6);
        // ẏ = t² from t₀ = 1, y₀ = 1: d₀ = d₁ = 1/s, h₀ = 0.01, and the probe at t = 1.01
        // gives d₂ = (1.01² − 1) / (s h₀) = 2.01/s.
        let clock = |t: f64, _y: &[f64], dy: &mut [f64]| dy[0] = t * t;
        let h = first_step(clock, (1.0, &[1.0]), (1e-6, 1e-6), 10.0);
        assert!(close(h, (0.01 * s / 2.01).powf(0.2)), "{h}");
    }

    #[test]
    fn min_step_scales_with_t_and_span() {
        assert_eq!(min_step(0.0, 1.0), 16.0 * f64::EPSILON);
        assert_eq!(min_step(-100.0, 1.0), 1600.0 * f64::EPSILON);
    }

    #[test]
    fn weighted_rms_ignores_zeros_with_zero_scale() {
        assert_eq!(weighted_rms(0, |_| (1.0, 1.0)), 0.0);
        let norm = weighted_rms(2, |i| ([0.0, 3.0][i], [0.0, 1.0][i]));
        assert!((norm - 4.5_f64.sqrt()).abs() < 1e-15);
        assert_eq!(weighted_rms(1, |_| (1.0, 0.0)), f64::INFINITY);
    }

    /// The restricted three-body problem (Arenstorf's orbit, Hairer–Nørsett–Wanner I,
    /// §II.0): `y = [y₁, y₂, ẏ₁, ẏ₂]`, the moon's mass ratio `μ = 0.012277471`. Only `+ − × /`
    /// and `√`, which IEEE 754 rounds exactly, so its bits are the same on every platform.
    fn arenstorf() -> OdeFn<impl FnMut(f64, &[f64], &mut [f64])> {
        OdeFn::new(4, |_t: f64, y: &[f64], dy: &mut [f64]| {
            let mu = 0.012277471;
            let mu1 = 1.0 - mu;
            let r1 = (y[0] + mu) * (y[0] + mu) + y[1] * y[1];
            let r2 = (y[0] - mu1) * (y[0] - mu1) + y[1] * y[1];
            let (d1, d2) = (r1 * r1.sqrt(), r2 * r2.sqrt());
            dy[0] = y[2];
            dy[1] = y[3];
            dy[2] = y[0] + 2.0 * y[3] - mu1 * (y[0] + mu) / d1 - mu * (y[0] - mu1) / d2;
            dy[3] = y[1] - 2.0 * y[2] - mu1 * y[1] / d1 - mu * y[1] / d2;
        })
    }

    /// Arenstorf's initial state and period (Hairer–Nørsett–Wanner I, §II.0, (0.2)), with
    /// every digit the book prints; the compiler rounds them to f64.
    #[allow(clippy::excessive_precision, reason = "the digits of the source")]
    const ARENSTORF_Y0: [f64; 4] = [0.994, 0.0, 0.0, -2.00158510637908252240537862224];
    #[allow(clippy::excessive_precision, reason = "the digits of the source")]
    const ARENSTORF_PERIOD: f64 = 17.0652165601579625588917206249;

    /// Lorenz's system (σ = 10, ρ = 28, β = 8/3): three components, so the stages take the
    /// general path rather than the copies compiled for 2, 4, 6 and 8 components.
    fn lorenz() -> OdeFn<impl FnMut(f64, &[f64], &mut [f64])> {
        OdeFn::new(3, |_t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = 10.0 * (y[1] - y[0]);
            dy[1] = y[0] * (28.0 - y[2]) - y[1];
            dy[2] = y[0] * y[1] - 8.0 / 3.0 * y[2];
        })
    }

    /// FNV-1a over the bits of every sample (times and states) of `solution`.
    fn sample_hash(solution: &Solution) -> u64 {
        let words = solution.t.iter().chain(&solution.y).map(|v| v.to_bits());
        words.fold(0xcbf2_9ce4_8422_2325, |hash, word| {
            word.to_le_bytes().iter().fold(hash, |h, &b| {
                (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
            })
        })
    }

    /// What pins a run: accepted and rejected steps, evaluations of `F`, the bits of the last
    /// sample's state and a hash of every sample.
    #[derive(Debug, PartialEq)]
    struct Pin {
        steps: usize,
        rejected: usize,
        rhs_evals: usize,
        last: Vec<u64>,
        hash: u64,
    }

    fn pin(solution: &Solution) -> Pin {
        let (_, last) = solution.last().unwrap();
        Pin {
            steps: solution.stats.steps,
            rejected: solution.stats.rejected,
            rhs_evals: solution.stats.rhs_evals,
            last: last.iter().map(|v| v.to_bits()).collect(),
            hash: sample_hash(solution),
        }
    }

    /// A regression pin for the bookkeeping around the steps of DP5(4) and DOP853 (error
    /// norm, copies on accept, dense output, output recording): the exact step sequences and
    /// final states of Arenstorf's orbit (4 components, the compiled stages) over one period
    /// and of Lorenz's system (3 components, the general stages) to t = 2, every step
    /// recorded and at requested times (dense output). The bits were recorded before that
    /// bookkeeping was reorganised for speed; any change of a floating-point operation in a
    /// step, its order included, changes them. (The problems use only `+ − × /` and `√`, but
    /// the step-size controller takes `ln` and `exp` from the platform's math library: the
    /// bits are those of glibc on x86-64 Linux, where CI runs.) Independently of the pin,
    /// the orbit closes (the state after one period equals the initial state to 1e-4, a loose
    /// bound: a run that lost the orbit, which passes close to the moon, misses it by order 1)
    /// and every run with requested times ends on the same state, to the bit, as the run
    /// that records every step.
    #[test]
    fn dormand_prince_runs_are_pinned_to_the_bit() {
        let options = IntegratorOptions::default().with_rtol(1e-9).with_atol(1e-9);
        let arenstorf_times: Vec<f64> = (1..=40)
            .map(|k| ARENSTORF_PERIOD * f64::from(k) / 40.0)
            .collect();
        let lorenz_times: Vec<f64> = (1..=40).map(|k| 2.0 * f64::from(k) / 40.0).collect();
        let mut actual = Vec::new();
        for method in [
            &mut DormandPrince54::new() as &mut dyn Integrator,
            &mut DormandPrince853::new(),
        ] {
            let mut system = arenstorf();
            let y0 = ARENSTORF_Y0;
            for output in [OutputTimes::Steps, OutputTimes::At(arenstorf_times.clone())] {
                let solution = method
                    .integrate(&mut system, 0.0, &y0, ARENSTORF_PERIOD, &output, &options)
                    .unwrap();
                let (t, y) = solution.last().unwrap();
                assert_eq!(t, ARENSTORF_PERIOD);
                for (a, b) in y.iter().zip(&y0) {
                    assert!((a - b).abs() < 1e-4, "{}: {y:?}", method.name());
                }
                actual.push(pin(&solution));
            }
            let mut system = lorenz();
            for output in [OutputTimes::Steps, OutputTimes::At(lorenz_times.clone())] {
                let solution = method
                    .integrate(&mut system, 0.0, &[1.0, 1.0, 1.0], 2.0, &output, &options)
                    .unwrap();
                actual.push(pin(&solution));
            }
        }
        for pair in actual.chunks(2) {
            assert_eq!(pair[0].last, pair[1].last, "Steps and At end alike");
        }
        let expected = vec![
            // DP5(4), Arenstorf, every step.
            Pin {
                steps: 530,
                rejected: 5,
                rhs_evals: 3212,
                last: vec![
                    0x3fefced8fdde5cf1,
                    0xbe7e40568bd2d000,
                    0xbef3678ca5546000,
                    0xc0000342cd11c8f4,
                ],
                hash: 0xd155cd3cd02586d0,
            },
            // DP5(4), Arenstorf, at 40 times.
            Pin {
                steps: 530,
                rejected: 5,
                rhs_evals: 3212,
                last: vec![
                    0x3fefced8fdde5cf1,
                    0xbe7e40568bd2d000,
                    0xbef3678ca5546000,
                    0xc0000342cd11c8f4,
                ],
                hash: 0xa0ae95a52819fd3c,
            },
            // DP5(4), Lorenz, every step.
            Pin {
                steps: 313,
                rejected: 0,
                rhs_evals: 1880,
                last: vec![0xc02058d4fc199472, 0xc0231fc19184eb36, 0x40389ee655013efd],
                hash: 0x4a5cf0ca3efeea1d,
            },
            // DP5(4), Lorenz, at 40 times.
            Pin {
                steps: 313,
                rejected: 0,
                rhs_evals: 1880,
                last: vec![0xc02058d4fc199472, 0xc0231fc19184eb36, 0x40389ee655013efd],
                hash: 0x5c372d12f87933ea,
            },
            // DOP853, Arenstorf, every step.
            Pin {
                steps: 136,
                rejected: 50,
                rhs_evals: 2184,
                last: vec![
                    0x3fefced91dab5e47,
                    0x3e68165b5e982000,
                    0x3ede8ac525d82000,
                    0xc000033df742a703,
                ],
                hash: 0xe67b4d8581dc05da,
            },
            // DOP853, Arenstorf, at 40 times.
            Pin {
                steps: 136,
                rejected: 50,
                rhs_evals: 2301,
                last: vec![
                    0x3fefced91dab5e47,
                    0x3e68165b5e982000,
                    0x3ede8ac525d82000,
                    0xc000033df742a703,
                ],
                hash: 0x9075b0ed3960a1f3,
            },
            // DOP853, Lorenz, every step.
            Pin {
                steps: 59,
                rejected: 10,
                rhs_evals: 820,
                last: vec![0xc02058d4fb88dc98, 0xc0231fc191782d47, 0x40389ee6543c5fc9],
                hash: 0x975a03c5a2041a6d,
            },
            // DOP853, Lorenz, at 40 times.
            Pin {
                steps: 59,
                rejected: 10,
                rhs_evals: 937,
                last: vec![0xc02058d4fb88dc98, 0xc0231fc191782d47, 0x40389ee6543c5fc9],
                hash: 0xae328b89715d00ca,
            },
        ];
        assert_eq!(actual, expected);
    }
}
