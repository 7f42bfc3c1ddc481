//! Events: zeros of functions `g(t, y)` located during an integration on each method's dense
//! output, with a direction and an optional stop ([`EventSpec`], [`Event`]).
//!
//! After every accepted step from `t₀` to `t₁` the driver evaluates `g(t₁, y₁)` and compares
//! it with `g(t₀, y₀)`. A component that changes sign in the requested direction has a zero
//! in `(t₀, t₁]`; it is located by Brent's bracketing method on `gᵢ(t, y(t))` with `y(t)` the
//! method's dense output over the step, to a bracket of a few ulps of `t`: to machine
//! precision in `t` for the interpolant, so the event time is as accurate as the dense output
//! (order 4 for Dormand–Prince 5(4), 7 for DOP853, the collocation polynomial for Radau IIA,
//! cubic Hermite otherwise). Several zeros in one step are reported in time order; a terminal
//! one ends the integration there and later ones in that step are dropped.
//!
//! As in MATLAB's `odeset('Events', …)` (lecture 17, HW21), only sign changes between step
//! ends are seen: a function that has two zeros inside one step (touching zero and coming
//! back) is missed; a step no longer than the events' time scale (`dt_max`) prevents it.
//! A zero exactly at a step's end counts for that step and not again for the next, and a zero
//! at `t0` is not an event (the integration starts there).
//!
//! # References
//! R. P. Brent, *Algorithms for Minimization without Derivatives*, Prentice-Hall, 1973, ch. 4
//! (the `zero` procedure); L. F. Shampine, M. W. Reichelt, "The MATLAB ODE suite", SIAM J.
//! Sci. Comput. 18 (1997) 1–22, §6 (event location on the interpolant).

use super::solution::Solution;
use super::stepper::{CheckedRhs, StepFailure, Stepper};
use crate::ode::{Event, EventDirection, EventSpec};

/// The event functions' values at the last step end, and the scratch of root finding.
pub(crate) struct EventTracker {
    specs: Vec<EventSpec>,
    g_prev: Vec<f64>,
    g_new: Vec<f64>,
    g_trial: Vec<f64>,
    y_trial: Vec<f64>,
    /// `(t, index, direction)` of the zeros found in the current step.
    found: Vec<(f64, usize, EventDirection)>,
}

impl EventTracker {
    /// A tracker for the system's events, or `None` when it has none.
    pub(crate) fn new(rhs: &CheckedRhs<'_>, dim: usize) -> Option<Self> {
        let specs = rhs.event_specs().to_vec();
        if specs.is_empty() {
            return None;
        }
        let m = specs.len();
        Some(Self {
            specs,
            g_prev: vec![0.0; m],
            g_new: vec![0.0; m],
            g_trial: vec![0.0; m],
            y_trial: vec![0.0; dim],
            found: Vec::with_capacity(m),
        })
    }

    /// Evaluates the event functions at the start `(t, y)` (or at a restart after a
    /// projection).
    ///
    /// # Errors
    /// The failure of the evaluation.
    pub(crate) fn start(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        t: f64,
        y: &[f64],
    ) -> Result<(), StepFailure> {
        rhs.event_values(t, y, &mut self.g_prev)
    }

    /// Looks for zeros over the step the stepper has just accepted; records them in
    /// `solution.events` (in time order, up to and including the first terminal one) and
    /// returns the time of the terminal one, if any.
    ///
    /// # Errors
    /// The failure of an evaluation of the event functions or of the dense output.
    pub(crate) fn check_step<S: Stepper>(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        stepper: &mut S,
        solution: &mut Solution,
    ) -> Result<Option<f64>, StepFailure> {
        let (t0, t1) = stepper.interval();
        rhs.event_values(t1, stepper.y(), &mut self.g_new)?;
        self.found.clear();
        let mut prepared = false;
        for i in 0..self.specs.len() {
            let (before, after) = (self.g_prev[i], self.g_new[i]);
            if !self.specs[i].direction.crosses(before, after) {
                continue;
            }
            let direction = if before < 0.0 {
                EventDirection::Rising
            } else {
                EventDirection::Falling
            };
            if !prepared {
                stepper.prepare_dense_output(rhs)?;
                prepared = true;
            }
            let t = if after == 0.0 {
                t1
            } else {
                self.locate(rhs, stepper, i, (t0, before), (t1, after))?
            };
            self.found.push((t, i, direction));
        }
        std::mem::swap(&mut self.g_prev, &mut self.g_new);
        if self.found.is_empty() {
            return Ok(None);
        }
        self.found
            .sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut terminal_at = None;
        for k in 0..self.found.len() {
            let (t, index, direction) = self.found[k];
            if terminal_at.is_some_and(|t_stop| t > t_stop) {
                break;
            }
            let mut y = vec![0.0; stepper.y().len()];
            if t == t1 {
                y.copy_from_slice(stepper.y());
            } else {
                stepper.interpolate(t, &mut y);
            }
            rhs.after_step(t, &mut y)?;
            let spec = &self.specs[index];
            if spec.terminal && terminal_at.is_none() {
                terminal_at = Some(t);
                solution.terminated_by_event = Some(solution.events.len());
            }
            solution.events.push(Event {
                index,
                name: spec.name.to_string(),
                t,
                y,
                direction,
                terminal: spec.terminal,
            });
        }
        Ok(terminal_at)
    }

    /// Brent's method on `gᵢ(t, y(t))` over `[a, b]` with `gᵢ(a) = ga`, `gᵢ(b) = gb` of
    /// opposite signs: bisection safeguarding secant and inverse quadratic interpolation,
    /// until the bracket is a few ulps of `t` wide. Returns the end of the final bracket on
    /// the side after the crossing (so the state there has crossed).
    fn locate<S: Stepper>(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        stepper: &S,
        i: usize,
        (a, ga): (f64, f64),
        (b, gb): (f64, f64),
    ) -> Result<f64, StepFailure> {
        // Brent's zero(a, b, t): b is the best estimate, a the previous one, c brackets with b.
        let (mut a, mut fa, mut b, mut fb) = (a, ga, b, gb);
        let (mut c, mut fc) = (a, fa);
        let mut d = b - a;
        let mut e = d;
        for _ in 0..200 {
            if (fb > 0.0) == (fc > 0.0) && fb != 0.0 && fc != 0.0 {
                c = a;
                fc = fa;
                d = b - a;
                e = d;
            }
            if fc.abs() < fb.abs() {
                a = b;
                b = c;
                c = a;
                fa = fb;
                fb = fc;
                fc = fa;
            }
            let tol = 2.0 * f64::EPSILON * b.abs() + f64::MIN_POSITIVE;
            let m = 0.5 * (c - b);
            if m.abs() <= tol || fb == 0.0 {
                break;
            }
            if e.abs() < tol || fa.abs() <= fb.abs() {
                d = m;
                e = m;
            } else {
                let s = fb / fa;
                let (mut p, mut q);
                if a == c {
                    p = 2.0 * m * s;
                    q = 1.0 - s;
                } else {
                    let qa = fa / fc;
                    let r = fb / fc;
                    p = s * (2.0 * m * qa * (qa - r) - (b - a) * (r - 1.0));
                    q = (qa - 1.0) * (r - 1.0) * (s - 1.0);
                }
                if p > 0.0 {
                    q = -q;
                } else {
                    p = -p;
                }
                if 2.0 * p < 3.0 * m * q - (tol * q).abs() && p < (0.5 * e * q).abs() {
                    e = d;
                    d = p / q;
                } else {
                    d = m;
                    e = m;
                }
            }
            a = b;
            fa = fb;
            b += if d.abs() > tol { d } else { tol.copysign(m) };
            stepper.interpolate(b, &mut self.y_trial);
            rhs.event_values(b, &self.y_trial, &mut self.g_trial)?;
            fb = self.g_trial[i];
        }
        // Report the end of the bracket [b, c] at which g has crossed (later in time).
        let (t0, t1) = stepper.interval();
        let t = if fb == 0.0 { b } else { b.max(c) };
        Ok(t.clamp(t0, t1))
    }
}
