//! Part b: the energy of explicit Euler, RK4 and Störmer–Verlet over many periods of the
//! oscillator.

use std::f64::consts::PI;

use nalgebra::Complex;
use serde::Serialize;

use crate::integrate::stability_function::StabilityPolynomial;
use crate::integrate::{
    ExplicitEuler, Integrator, IntegratorOptions, OutputTimes, RungeKutta4, Solution,
    StormerVerlet, Tableau,
};
use crate::ode::OdeFn;

use super::options::Failure;

/// Steps per period in the energy study.
pub const STEPS_PER_PERIOD: usize = 32;

/// The energy of one run over many periods (part b).
#[derive(Debug, Serialize)]
pub struct EnergyRow {
    /// The integrator's name.
    pub method: &'static str,
    /// The constant step (s; the oscillator's period is 2π).
    pub h: f64,
    /// Steps per period `2π/h`.
    pub steps_per_period: usize,
    /// Periods reached (fewer than asked if the run failed).
    pub periods_reached: f64,
    /// `E/E₀` at the last sample (`None` if it overflows a double).
    pub final_energy_ratio: Option<f64>,
    /// `log₁₀(E/E₀)` at the last sample.
    pub log10_final_energy_ratio: f64,
    /// `log₁₀(E/E₀)` the stability function predicts there: `2n log₁₀|R(ih)|` after `n`
    /// steps (Runge–Kutta methods).
    pub theory_log10_final_energy_ratio: Option<f64>,
    /// Largest `|E/E₀ − 1|` over the samples (`None` if it overflows).
    pub max_energy_error: Option<f64>,
    /// The modified-energy bound on it (Störmer–Verlet: `(h²/4)/(1 − h²/4)`).
    pub theory_max_energy_error: Option<f64>,
    /// Why the run stopped early, if it did.
    pub failure: Option<Failure>,
    /// `(t/T, E/E₀)` for the chart (not serialised).
    #[serde(skip)]
    pub history: Vec<(f64, f64)>,
}

/// `E/E₀ = x² + ẋ²` of the oscillator `ẍ = −x` started at `(1, 0)`.
fn energy_ratio(y: &[f64]) -> f64 {
    y[0] * y[0] + y[1] * y[1]
}

pub(super) fn energy_runs(periods: usize) -> Vec<EnergyRow> {
    let period = 2.0 * PI;
    let t_end = periods as f64 * period;
    // Explicit Euler a hundred times finer too, since with h = T/32 it overflows.
    let fine = 100 * STEPS_PER_PERIOD;
    let runs: [(Box<dyn Integrator>, usize); 4] = [
        (Box::new(ExplicitEuler::new()), STEPS_PER_PERIOD),
        (Box::new(ExplicitEuler::new()), fine),
        (Box::new(RungeKutta4::new()), STEPS_PER_PERIOD),
        (Box::new(StormerVerlet::new()), STEPS_PER_PERIOD),
    ];
    let rk4 = StabilityPolynomial::of_tableau(&Tableau::rk4());
    let euler = StabilityPolynomial::of_tableau(&Tableau::euler());
    runs.into_iter()
        .map(|(mut method, steps_per_period)| {
            let h_run = period / steps_per_period as f64;
            let options = IntegratorOptions::default()
                .with_dt(h_run)
                .with_max_steps(periods * steps_per_period + 10);
            // Every step of the coarse runs (the energy of Störmer–Verlet oscillates within a
            // period); once per period for the fine run (3.2 · 10⁷ steps).
            let output = if steps_per_period == STEPS_PER_PERIOD {
                OutputTimes::Steps
            } else {
                OutputTimes::At((0..=periods).map(|k| k as f64 * period).collect())
            };
            let mut oscillator = OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
                dy[0] = y[1];
                dy[1] = -y[0];
            });
            let (solution, failure) =
                match method.integrate(&mut oscillator, 0.0, &[1.0, 0.0], t_end, &output, &options)
                {
                    Ok(s) => (s, None),
                    Err(f) => {
                        let failure = Failure::of(&f);
                        (*f.partial, Some(failure))
                    }
                };
            energy_row(method.name(), h_run, &solution, failure, &rk4, &euler)
        })
        .collect()
}

fn energy_row(
    method: &'static str,
    h: f64,
    solution: &Solution,
    failure: Option<Failure>,
    rk4: &StabilityPolynomial,
    euler: &StabilityPolynomial,
) -> EnergyRow {
    let period = 2.0 * PI;
    let steps_per_period = (period / h).round() as usize;
    let (t_last, y_last) = solution.last().unwrap_or((0.0, &[1.0, 0.0][..]));
    let steps_done = (t_last / h).round();
    let log_amplitude = |r: &StabilityPolynomial| r.eval(Complex::new(0.0, h)).norm().log10();
    let theory_log10_final_energy_ratio = match method {
        "euler" => Some(2.0 * steps_done * log_amplitude(euler)),
        "rk4" => Some(2.0 * steps_done * log_amplitude(rk4)),
        _ => None,
    };
    let theory_max_energy_error =
        (method == "stormer-verlet").then(|| (h * h / 4.0) / (1.0 - h * h / 4.0));
    let max_energy_error = solution
        .iter()
        .map(|(_, y)| (energy_ratio(y) - 1.0).abs())
        .fold(0.0, f64::max);
    let stride = if solution.len() > 1 && solution.t[1] < 0.99 * period {
        steps_per_period
    } else {
        1
    };
    // E/E₀ above 1e200 is left out of the chart (its axis padding would overflow).
    let history = solution
        .iter()
        .step_by(stride)
        .map(|(t, y)| (t / period, energy_ratio(y)))
        .filter(|(_, e)| *e <= 1e200)
        .collect();
    let final_energy_ratio = energy_ratio(y_last);
    EnergyRow {
        method,
        h,
        steps_per_period,
        periods_reached: t_last / period,
        final_energy_ratio: final_energy_ratio.is_finite().then_some(final_energy_ratio),
        log10_final_energy_ratio: 2.0 * y_last[0].hypot(y_last[1]).log10(),
        theory_log10_final_energy_ratio,
        max_energy_error: max_energy_error.is_finite().then_some(max_energy_error),
        theory_max_energy_error,
        failure,
        history,
    }
}
