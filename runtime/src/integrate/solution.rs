//! What an integration returns: the samples ([`Solution`]) and the work done ([`Stats`]).

use serde::Serialize;

use crate::ode::Event;

/// The work an integration did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Stats {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected step attempts (error too large, or a non-finite right-hand side).
    pub rejected: usize,
    /// Evaluations of the right-hand side `F(t, y)`, including those of the initial-step
    /// selection and of rejected steps.
    pub rhs_evals: usize,
    /// Jacobians `∂F/∂y` computed by implicit methods, exact or by finite differences (whose
    /// evaluations of `F` are also counted in `rhs_evals`).
    pub jacobian_evals: usize,
    /// LU factorisations of Newton iteration matrices by implicit methods (Radau IIA's real
    /// and complex matrices together count once).
    pub lu_decompositions: usize,
    /// Evaluations of the event functions `g(t, y)` (one per accepted step and one per
    /// root-finding iteration; none without events).
    pub event_evals: usize,
    /// Taylor series of the solution computed by the Taylor method (one per step, each
    /// to the step's order); 0 for the other methods.
    pub taylor_series: usize,
    /// Wall-clock time of the whole `integrate` call (s).
    pub wall_time_s: f64,
}

/// Samples `(tₖ, y(tₖ))` of an integration, with its [`Stats`].
///
/// # Shapes
/// `t` has `len()` entries; `y` is row-major with one row of `dim` entries per sample, so
/// `y.len() == len() · dim` and sample `k` is `y[k·dim .. (k+1)·dim]` ([`Solution::state`]).
///
/// # Examples
/// ```
/// use eomgen_runtime::{Integrator, IntegratorOptions, OdeFn, OutputTimes, RungeKutta4};
///
/// // ẋ = −x, x(0) = 1.
/// let mut decay = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0]);
/// let solution = RungeKutta4::new().integrate(
///     &mut decay,
///     0.0,
///     &[1.0],
///     1.0,
///     &OutputTimes::At(vec![0.0, 0.5, 1.0]),
///     &IntegratorOptions::default(),
/// )?;
/// assert_eq!(solution.len(), 3);
/// assert!((solution.state(1)[0] - (-0.5_f64).exp()).abs() < 1e-12);
/// assert_eq!(solution.last(), Some((1.0, solution.state(2))));
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Solution {
    /// Sample times, non-decreasing (units of `t`).
    pub t: Vec<f64>,
    /// Sampled states, row-major: `len() × dim`.
    pub y: Vec<f64>,
    /// Dimension of the state, [`OdeSystem::dim`](crate::OdeSystem::dim).
    pub dim: usize,
    /// The work done.
    pub stats: Stats,
    /// The zeros of the system's event functions, in time order
    /// ([`OdeSystem::event_specs`](crate::OdeSystem::event_specs)); empty without events.
    pub events: Vec<Event>,
    /// Index into `events` of the terminal event that ended the integration before `t_end`,
    /// if one did; the last sample is then at that event's time (with
    /// [`OutputTimes::Steps`](super::OutputTimes::Steps)), and requested times after it are
    /// not sampled.
    pub terminated_by_event: Option<usize>,
}

impl Stats {
    /// Adds the work of `other` (a later phase of the same run) to this one.
    pub(crate) fn accumulate(&mut self, other: &Stats) {
        self.steps += other.steps;
        self.rejected += other.rejected;
        self.rhs_evals += other.rhs_evals;
        self.jacobian_evals += other.jacobian_evals;
        self.lu_decompositions += other.lu_decompositions;
        self.event_evals += other.event_evals;
        self.taylor_series += other.taylor_series;
        self.wall_time_s += other.wall_time_s;
    }
}

impl Solution {
    /// An empty solution of dimension `dim`.
    pub(crate) fn new(dim: usize) -> Self {
        Self {
            t: Vec::new(),
            y: Vec::new(),
            dim,
            stats: Stats::default(),
            events: Vec::new(),
            terminated_by_event: None,
        }
    }

    /// Reserves room for `samples` more samples.
    pub(crate) fn reserve(&mut self, samples: usize) {
        self.t.reserve(samples);
        self.y.reserve(samples.saturating_mul(self.dim));
    }

    /// Appends the sample `(t, y)`.
    pub(crate) fn push(&mut self, t: f64, y: &[f64]) {
        debug_assert_eq!(y.len(), self.dim);
        self.t.push(t);
        self.y.extend_from_slice(y);
    }

    /// Appends a sample at `t` whose state `fill` writes in place.
    pub(crate) fn push_with(&mut self, t: f64, fill: impl FnOnce(&mut [f64])) {
        let start = self.y.len();
        self.y.resize(start + self.dim, 0.0);
        fill(&mut self.y[start..]);
        self.t.push(t);
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The state at sample `index`, `dim` entries.
    ///
    /// # Panics
    /// If `index >= len()`; [`Solution::try_state`] returns `None` instead.
    pub fn state(&self, index: usize) -> &[f64] {
        &self.y[index * self.dim..(index + 1) * self.dim]
    }

    /// The state at sample `index`, or `None` if there is no such sample.
    pub fn try_state(&self, index: usize) -> Option<&[f64]> {
        let start = index.checked_mul(self.dim)?;
        let end = start.checked_add(self.dim)?;
        if index < self.len() {
            self.y.get(start..end)
        } else {
            None
        }
    }

    /// The last sample `(t, y)`, or `None` if there are no samples.
    pub fn last(&self) -> Option<(f64, &[f64])> {
        let index = self.len().checked_sub(1)?;
        Some((self.t[index], self.try_state(index)?))
    }

    /// The samples `(t, y)` in order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = (f64, &[f64])> + '_ {
        (0..self.len()).map(|index| (self.t[index], self.state(index)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_rows() {
        let mut solution = Solution::new(2);
        assert!(solution.is_empty());
        assert_eq!(solution.last(), None);
        solution.push(0.0, &[1.0, 2.0]);
        solution.push_with(0.5, |row| row.copy_from_slice(&[3.0, 4.0]));
        assert_eq!(solution.len(), 2);
        assert_eq!(solution.state(1), &[3.0, 4.0]);
        assert_eq!(solution.try_state(2), None);
        assert_eq!(solution.last(), Some((0.5, &[3.0, 4.0][..])));
        let times: Vec<f64> = solution.iter().map(|(t, _)| t).collect();
        assert_eq!(times, vec![0.0, 0.5]);
    }

    #[test]
    fn zero_dimensional_solutions_work() {
        let mut solution = Solution::new(0);
        solution.push(0.0, &[]);
        solution.push(1.0, &[]);
        assert_eq!(solution.len(), 2);
        assert_eq!(solution.state(1), &[] as &[f64]);
        assert_eq!(solution.iter().count(), 2);
        // The empty row past the end is not a sample.
        assert_eq!(solution.try_state(1), Some(&[] as &[f64]));
        assert_eq!(solution.try_state(2), None);
    }
}
