//! `eomgen study periodic-orbit`'s shooting on the figure eight (HW39; Simó's `T = 6.32591398`):
//! Gauss–Newton with the monodromy matrix from a start moved by up to 1e-3 in every
//! component, at the energy of the model's initial state, to ‖φ_T(y₀) − y₀‖ ≤ 1e-10 (1 + ‖y₀‖).
//! What one run does (iterations, integration steps, right-hand sides, the period found) is
//! printed first; then the criterion median of the whole call, which includes the final
//! sampling of the orbit (400 points) and the multipliers.
//!
//! `cargo bench --bench periodic_orbit` (figures in docs/performance.md).

use std::hint::black_box;

use criterion::Criterion;
use eomgen::ModelInfo;
use eomgen::analysis::{PeriodicOrbitOptions, periodic_orbit};

/// The figure eight compiled by `model!` (the figures of docs/performance.md were measured so).
mod compiled {
    eomgen::model!("../models/figure_eight.yaml");
}

/// The figure eight and the options of the run: the model's initial state moved by
/// `1e-3 sin(0.7 i)` in component `i`, period guess 6.3.
fn setup() -> (Box<dyn ModelInfo>, PeriodicOrbitOptions) {
    let model: Box<dyn ModelInfo> =
        Box::new(eomgen::FirstOrder::new(compiled::FigureEight::default()));
    let initial = model.initial_state();
    let energy = model.energy(0.0, &initial);
    let start = initial
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-3 * (0.7 * i as f64).sin())
        .collect();
    let options = PeriodicOrbitOptions {
        start: Some(start),
        energy: Some(energy),
        ..PeriodicOrbitOptions::new(6.3)
    };
    (model, options)
}

fn main() {
    let (mut model, options) = setup();
    match periodic_orbit(model.as_mut(), &options) {
        Ok(orbit) => println!(
            "figure eight: T = {:.10} (Simó 6.32591398), {} Newton iterations, residual {:.1e}, {} steps, {} right-hand sides of [y; Φ] and y",
            orbit.period,
            orbit.iterations,
            orbit.residual,
            orbit.stats.steps,
            orbit.stats.rhs_evals
        ),
        Err(e) => {
            eprintln!("the figure eight was not found: {e}");
            std::process::exit(1);
        }
    }
    let mut c = Criterion::default().sample_size(20).configure_from_args();
    c.bench_function("periodic_orbit_figure_eight", |b| {
        b.iter(|| periodic_orbit(model.as_mut(), black_box(&options)))
    });
    c.final_summary();
}
