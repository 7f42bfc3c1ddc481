//! The simplest walker's gait (issue: impacts and gaits, item 7), loaded from its file and
//! compiled at run time as `eomgen` serves it:
//!
//! - one return map `P(y)` with its Jacobian (variational equations, a scuff passed and a
//!   saltation matrix at the heel strike), from the gait at γ = 0.009;
//! - the gait found from a rough guess (1 % off in θ, 10 % in φ̇);
//! - the gait followed over 100 slopes from 0.001 to 0.0149.
//!
//! What one run of each does is printed first, then criterion's medians.
//! `cargo bench --bench gait` (figures in docs/performance.md, beside SciPy's
//! `solve_ivp` with events on the limit's equations: tools/simplest_walker_reference.py
//! --bench).

use std::hint::black_box;

use criterion::Criterion;
use eomgen::analysis::vibration::SweepAxis;
use eomgen::analysis::{GaitOptions, gait, gait_sweep, return_map};
use eomgen::{DynFirstOrder, JitModel};

fn walker() -> DynFirstOrder<JitModel> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../models/simplest_walker.yaml"
    );
    DynFirstOrder::new(JitModel::load(path).expect("the bundled walker loads"))
}

fn main() {
    let mut model = walker();
    let on_gait = vec![
        0.2003109003941,
        0.4006218007882,
        -0.1998324730785,
        -0.01582299993073,
    ];
    let rough = vec![0.198, 0.4006, -0.1998, -0.0142];
    let options = GaitOptions::default();
    let rough_options = GaitOptions {
        start: Some(rough.clone()),
        ..GaitOptions::default()
    };
    let axis = SweepAxis::linear("gamma", 0.001, 0.0149, 100).expect("a valid axis");
    let mut stats = Default::default();
    let map = return_map(&mut model, &on_gait, &options, &mut stats).expect("a step");
    println!(
        "one return map: T = {:.10}, {} steps, {} right-hand sides of [y; Φ]",
        map.step_times[0], stats.steps, stats.rhs_evals
    );
    let found = gait(&mut model, &rough_options).expect("the gait");
    println!(
        "the gait from a rough guess: {} Newton iterations, |λ| = {:.9}, {} steps",
        found.iterations, found.spectral_radius, found.stats.steps
    );
    let sweep = gait_sweep(&mut model, &axis, &options, |_, _| {}).expect("a sweep");
    let failed = sweep.points.iter().filter(|p| p.error.is_some()).count();
    println!("100 slopes: {failed} without a gait");
    let mut c = Criterion::default().sample_size(20).configure_from_args();
    c.bench_function("gait_return_map_with_jacobian", |b| {
        b.iter(|| {
            let mut stats = Default::default();
            return_map(&mut model, black_box(&on_gait), &options, &mut stats)
        })
    });
    c.bench_function("gait_from_a_rough_guess", |b| {
        b.iter(|| gait(&mut model, black_box(&rough_options)))
    });
    let mut c = Criterion::default().sample_size(10).configure_from_args();
    c.bench_function("gait_sweep_100_slopes", |b| {
        b.iter(|| gait_sweep(&mut model, black_box(&axis), &options, |_, _| {}))
    });
    c.final_summary();
}
