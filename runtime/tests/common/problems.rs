//! The reference problems of the integrator tests and the one driver that runs every
//! integration method on every problem it suits.
//!
//! Each problem is `ẏ = F(t, y)` on `[t0, t_end]` with a closed-form solution and, where it
//! helps, its exact Jacobian (so that the implicit methods run both with it and with the
//! finite-difference fallback). The methods are those of the registry,
//! [`Method::ALL`]: a method added there runs here without further edits, and the
//! exhaustive matches below make its properties (partitioned or not) a decision.
//!
//! Included by the integration tests of `eomgen-runtime` (`mod common;`); each test file uses
//! some of it.
#![allow(dead_code)]

use eomgen_runtime::analysis::Method;
use eomgen_runtime::{Integrator, IntegratorOptions, OdeSystem, OutputTimes, RhsError, Solution};

/// A right-hand side, Jacobian (column-major) or closed-form solution, written into the slice.
pub type Function = fn(f64, &[f64], &mut [f64]);

/// `ẏ = F(t, y)` on `[t0, t_end]` with a closed-form solution `exact`.
#[derive(Clone, Copy)]
pub struct Problem {
    pub name: &'static str,
    /// `Some(n)` for a second-order system `y = [q; q̇]` with `n` coordinates, as the
    /// partitioned methods need.
    pub second_order: Option<usize>,
    pub dim: usize,
    pub t0: f64,
    pub t_end: f64,
    pub rhs: Function,
    /// The exact Jacobian `∂F/∂y`, if given (else the implicit methods difference `F`).
    pub jacobian: Option<Function>,
    pub exact: fn(f64, &mut [f64]),
}

/// A [`Problem`] as an [`OdeSystem`], with its exact Jacobian if it has one.
pub struct System(pub Problem);

impl OdeSystem for System {
    fn dim(&self) -> usize {
        self.0.dim
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        (self.0.rhs)(t, y, dy);
        Ok(())
    }

    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        match self.0.jacobian {
            Some(jacobian) => {
                jacobian(t, y, jac);
                Ok(true)
            }
            None => Ok(false),
        }
    }

    fn second_order_dim(&self) -> Option<usize> {
        self.0.second_order
    }
}

impl Problem {
    /// The initial state, `exact(t0)`.
    pub fn y0(&self) -> Vec<f64> {
        self.exact_at(self.t0)
    }

    pub fn exact_at(&self, t: f64) -> Vec<f64> {
        let mut y = vec![0.0; self.dim];
        (self.exact)(t, &mut y);
        y
    }

    /// The same problem on `[t0, t_end]`.
    pub fn until(self, t_end: f64) -> Self {
        Self { t_end, ..self }
    }

    /// Whether `method` applies to this problem (the partitioned methods need `y = [q; q̇]`).
    pub fn suits(&self, method: &dyn Integrator) -> bool {
        self.second_order.is_some() || !needs_second_order(method.name())
    }

    pub fn solve_with(
        &self,
        method: &mut dyn Integrator,
        output: &OutputTimes,
        options: &IntegratorOptions,
        t_end: f64,
    ) -> Solution {
        method
            .integrate(
                &mut System(*self),
                self.t0,
                &self.y0(),
                t_end,
                output,
                options,
            )
            .unwrap_or_else(|failure| panic!("{} on {}: {failure}", method.name(), self.name))
    }

    pub fn solve(
        &self,
        method: &mut dyn Integrator,
        output: &OutputTimes,
        options: &IntegratorOptions,
    ) -> Solution {
        self.solve_with(method, output, options, self.t_end)
    }

    /// Largest error over the samples, in the max norm.
    pub fn max_error(&self, solution: &Solution) -> f64 {
        self.largest(solution, |error, _| error)
    }

    /// Largest error over samples and components, relative to `max(1, |exact|)`.
    pub fn max_relative_error(&self, solution: &Solution) -> f64 {
        self.largest(solution, |error, exact| error / exact.abs().max(1.0))
    }

    fn largest(&self, solution: &Solution, measure: impl Fn(f64, f64) -> f64) -> f64 {
        solution
            .iter()
            .flat_map(|(t, y)| {
                y.iter()
                    .zip(self.exact_at(t))
                    .map(|(y, e)| measure((y - e).abs(), e))
                    .collect::<Vec<_>>()
            })
            .fold(0.0, f64::max)
    }

    /// Error of the last sample (at `t_end` for `Steps`), in the max norm.
    pub fn final_error(&self, solution: &Solution) -> f64 {
        let (t, y) = solution.last().expect("a solution has samples");
        y.iter()
            .zip(self.exact_at(t))
            .map(|(y, e)| (y - e).abs())
            .fold(0.0, f64::max)
    }

    /// `count` times strictly inside `(t0, t_end)` at irrational fractions of the interval,
    /// so that none falls on a step.
    pub fn interior_times(&self, count: usize) -> Vec<f64> {
        let span = self.t_end - self.t0;
        (0..count)
            .map(|k| self.t0 + span * ((k as f64 + 2.0_f64.sqrt() / 3.0) / count as f64))
            .collect()
    }

    /// `count` output times spread over `[t0, t_end]`, including both ends, the others at
    /// irrational fractions of the interval so that none falls on a step.
    pub fn scattered_times(&self, count: usize) -> Vec<f64> {
        let span = self.t_end - self.t0;
        let mut times: Vec<f64> = (1..count - 1)
            .map(|k| self.t0 + span * ((k as f64 + 2.0_f64.sqrt() / 3.0) / count as f64))
            .collect();
        times.insert(0, self.t0);
        times.push(self.t_end);
        times
    }
}

/// Harmonic oscillator `ẍ = −4x`: `x = cos 2t`, `ẋ = −2 sin 2t`, on `[0, 10]`.
pub fn oscillator() -> Problem {
    Problem {
        name: "harmonic oscillator",
        second_order: Some(1),
        dim: 2,
        t0: 0.0,
        t_end: 10.0,
        rhs: |_t, y, dy| {
            dy[0] = y[1];
            dy[1] = -4.0 * y[0];
        },
        jacobian: Some(|_t, _y, jac| jac.copy_from_slice(&[0.0, -4.0, 1.0, 0.0])),
        exact: |t, y| {
            y[0] = (2.0 * t).cos();
            y[1] = -2.0 * (2.0 * t).sin();
        },
    }
}

/// Forced oscillator `ẍ = −x + sin 2t`, `x(0) = 1`, `ẋ(0) = 0`:
/// `x = cos t + (2/3) sin t − (1/3) sin 2t`, on `[0, 6]`. Second order and non-autonomous
/// (checks the stage times of the partitioned methods); no exact Jacobian.
pub fn forced_oscillator() -> Problem {
    Problem {
        name: "forced oscillator",
        second_order: Some(1),
        dim: 2,
        t0: 0.0,
        t_end: 6.0,
        rhs: |t, y, dy| {
            dy[0] = y[1];
            dy[1] = -y[0] + (2.0 * t).sin();
        },
        jacobian: None,
        exact: |t, y| {
            y[0] = t.cos() + 2.0 / 3.0 * t.sin() - (2.0 * t).sin() / 3.0;
            y[1] = -t.sin() + 2.0 / 3.0 * t.cos() - 2.0 / 3.0 * (2.0 * t).cos();
        },
    }
}

/// `ζ` of the damped oscillator.
pub const ZETA: f64 = 0.1;

/// Damped oscillator `ẍ = −x − 2ζẋ` (a velocity-dependent force), `x(0) = 1`, `ẋ(0) = 0`:
/// `x = e^(−ζt) (cos ωt + (ζ/ω) sin ωt)` with `ω = √(1 − ζ²)`, on `[0, 6]`.
pub fn damped_oscillator() -> Problem {
    Problem {
        name: "damped oscillator",
        second_order: Some(1),
        dim: 2,
        t0: 0.0,
        t_end: 6.0,
        rhs: |_t, y, dy| {
            dy[0] = y[1];
            dy[1] = -y[0] - 2.0 * ZETA * y[1];
        },
        jacobian: Some(|_t, _y, jac| jac.copy_from_slice(&[0.0, -1.0, 1.0, -2.0 * ZETA])),
        exact: |t, y| {
            let w = (1.0 - ZETA * ZETA).sqrt();
            let decay = (-ZETA * t).exp();
            y[0] = decay * ((w * t).cos() + ZETA / w * (w * t).sin());
            y[1] = -decay * (1.0 + ZETA * ZETA / (w * w)) * w * (w * t).sin();
        },
    }
}

/// Exponential growth `ẋ = x` on `[0, 1]`: `x(1) = e`. No exact Jacobian.
pub fn growth() -> Problem {
    Problem {
        name: "exponential growth",
        second_order: None,
        dim: 1,
        t0: 0.0,
        t_end: 1.0,
        rhs: |_t, y, dy| dy[0] = y[0],
        jacobian: None,
        exact: |t, y| y[0] = t.exp(),
    }
}

/// Forced decay `ẏ = −y + sin t`, `y(0) = 1`: `y = (sin t − cos t)/2 + 3/2 e^(−t)`, on
/// `[0, 5]`. Non-autonomous, so it checks the stage times.
pub fn forced_decay() -> Problem {
    Problem {
        name: "forced decay",
        second_order: None,
        dim: 1,
        t0: 0.0,
        t_end: 5.0,
        rhs: |t, y, dy| dy[0] = -y[0] + t.sin(),
        jacobian: Some(|_t, _y, jac| jac[0] = -1.0),
        exact: |t, y| y[0] = (t.sin() - t.cos()) / 2.0 + 1.5 * (-t).exp(),
    }
}

/// Logistic growth `ẏ = y(1 − y)`, `y(1) = 0.1`, from `t0 = 1` (a non-zero start):
/// `y = 1/(1 + 9 e^(−(t − 1)))`, on `[1, 11]`. Nonlinear, so the Newton iterations do real
/// work; no exact Jacobian (finite differences).
pub fn logistic() -> Problem {
    Problem {
        name: "logistic",
        second_order: None,
        dim: 1,
        t0: 1.0,
        t_end: 11.0,
        rhs: |_t, y, dy| dy[0] = y[0] * (1.0 - y[0]),
        jacobian: None,
        exact: |t, y| y[0] = 1.0 / (1.0 + 9.0 * (-(t - 1.0)).exp()),
    }
}

/// Every reference problem.
pub fn problems() -> Vec<Problem> {
    vec![
        oscillator(),
        forced_oscillator(),
        damped_oscillator(),
        growth(),
        forced_decay(),
        logistic(),
    ]
}

/// The registered method named `name`.
pub fn method(name: &str) -> Method {
    name.parse()
        .unwrap_or_else(|e| panic!("{name} is not in the registry: {e}"))
}

/// Every registered method ([`Method::ALL`]), each a new integrator in its default
/// configuration.
///
/// The Taylor method is left out: it needs a model's generated recurrences, which equations
/// written as closures do not have (it is tested on models in the root package's
/// `tests/taylor.rs`).
pub fn integrators() -> Vec<Box<dyn Integrator>> {
    Method::ALL
        .iter()
        .filter(|&&m| m != Method::Taylor)
        .map(|m| m.integrator())
        .collect()
}

/// Whether the method named `name` takes constant steps `dt` (by default
/// `(t_end − t0)/1000`).
pub fn is_fixed_step(name: &str) -> bool {
    !method(name).is_adaptive()
}

/// Whether the method named `name` needs a second-order system `y = [q; q̇]` (the
/// partitioned methods).
pub fn needs_second_order(name: &str) -> bool {
    match method(name) {
        Method::SymplecticEuler | Method::StormerVerlet => true,
        Method::Euler
        | Method::Midpoint
        | Method::Rk4
        | Method::Bs32
        | Method::Dp54
        | Method::Dop853
        | Method::Vern6
        | Method::Vern7
        | Method::Vern8
        | Method::Vern9
        | Method::Taylor
        | Method::ImplicitMidpoint
        | Method::Radau5 => false,
    }
}

/// The driver: runs `check(method, problem)` for every registered method on every problem of
/// `problems` it suits, and checks that each method ran on at least one of them.
pub fn every_method_on_every_problem(
    problems: &[Problem],
    mut check: impl FnMut(&mut dyn Integrator, &Problem),
) {
    for mut method in integrators() {
        let suitable: Vec<&Problem> = problems
            .iter()
            .filter(|p| p.suits(method.as_ref()))
            .collect();
        assert!(
            !suitable.is_empty(),
            "{} suits none of the problems",
            method.name()
        );
        for problem in suitable {
            check(method.as_mut(), problem);
        }
    }
}
