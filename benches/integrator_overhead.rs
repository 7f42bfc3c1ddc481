//! The cost an explicit Runge–Kutta run adds to each evaluation of the right-hand side: the
//! time of a whole Dormand–Prince 5(4) or DOP853 integration divided by its number of
//! right-hand-side evaluations, against the right-hand side alone, in the same run.
//!
//! The system is the bundled double pendulum (`models/double_pendulum.yaml`, default
//! parameters) through [`FirstOrder`], from the model's initial state (θ₁ = 0, θ₂ = π/2, at
//! rest) to `t = 10 s`, at `rtol = atol = 1e-6, 1e-8, 1e-10`, every step recorded
//! ([`OutputTimes::Steps`]), and for DOP853 also at 100 requested times (dense output, whose
//! three extra evaluations per step with an output time are counted as evaluations too).
//!
//! Groups (every figure in ns per evaluation of `F`):
//! - `integrator_overhead/rhs_bare`: one evaluation of `F` at a fixed state, called directly
//!   (the figure of `benches/rhs.rs`). Successive calls do not depend on each other, so the
//!   processor overlaps them: this is the right-hand side's *throughput*.
//! - `integrator_overhead/rhs_dyn`: the same through `&mut dyn OdeSystem`, as the integrators
//!   call it.
//! - `integrator_overhead/rhs_chain`: a chain of 1000 explicit Euler steps
//!   `y ← y + 10⁻⁴ F(y)` through `&mut dyn OdeSystem`, per evaluation: each evaluation waits
//!   for the last one, as the stages of a Runge–Kutta step do. This is the right-hand side's
//!   *latency* plus one multiply–add per component, the least any explicit method can cost.
//! - `integrator_overhead/dp54_<tol>`, `dop853_<tol>`, `dop853_dense_<tol>`: a whole
//!   integration, its time divided by the evaluations it made (`Stats::rhs_evals`, the same
//!   in every run), reported by `iter_custom` so that criterion's figure is already per
//!   evaluation.
//!
//! The step and evaluation counts of each run are printed once before timing.
//!
//! Run with `cargo bench --bench integrator_overhead` (about a minute on the 2-core
//! development machine; `-- --warm-up-time 1 --measurement-time 3` for the figures of
//! `docs/performance.md`).

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
eomgen::model!("../models/double_pendulum.yaml");
use eomgen::{
    DormandPrince54, DormandPrince853, FirstOrder, Integrator, IntegratorOptions, ModelInfo,
    OdeSystem, OutputTimes,
};

/// End of every integration (s).
const T_END: f64 = 10.0;

/// The tolerances `rtol = atol` of the runs.
const TOLERANCES: [(f64, &str); 3] = [(1e-6, "1e-6"), (1e-8, "1e-8"), (1e-10, "1e-10")];

/// A generic state `[θ₁, θ₂, θ̇₁, θ̇₂]` (rad, rad/s) for the right-hand side alone: no angle
/// or rate zero, no special trigonometric value.
const STATE: [f64; 4] = [0.4, 1.9, -0.8, 1.3];

/// Evaluations in one dependent chain of `rhs_chain`.
const CHAIN: usize = 1000;

fn new_system() -> FirstOrder<DoublePendulum, 2> {
    FirstOrder::new(DoublePendulum::default())
}

/// One integration of the double pendulum by `method` to [`T_END`]; returns its evaluation
/// count.
///
/// # Panics
/// If the integration fails (it cannot for the double pendulum, whose mass matrix is
/// positive definite everywhere).
fn run(method: &mut dyn Integrator, tol: f64, output: &OutputTimes, y0: &[f64]) -> usize {
    let options = IntegratorOptions::default().with_rtol(tol).with_atol(tol);
    let mut system = new_system();
    let solution = method
        .integrate(&mut system, 0.0, black_box(y0), T_END, output, &options)
        .expect("the double pendulum integrates to 10 s");
    black_box(&solution);
    solution.stats.rhs_evals
}

fn rhs(c: &mut Criterion) {
    let mut group = c.benchmark_group("integrator_overhead");
    group.bench_function("rhs_bare", |b| {
        let mut system = black_box(new_system());
        let mut dy = [0.0; 4];
        b.iter(|| {
            system.rhs(0.0, black_box(&STATE), &mut dy).unwrap();
            black_box(&dy);
        })
    });
    group.bench_function("rhs_dyn", |b| {
        let mut concrete = new_system();
        let system: &mut dyn OdeSystem = black_box(&mut concrete);
        let mut dy = [0.0; 4];
        b.iter(|| {
            system.rhs(0.0, black_box(&STATE), &mut dy).unwrap();
            black_box(&dy);
        })
    });
    group.bench_function("rhs_chain", |b| {
        let mut concrete = new_system();
        let system: &mut dyn OdeSystem = black_box(&mut concrete);
        b.iter_custom(|iters| {
            let start = Instant::now();
            for _ in 0..iters {
                let (mut y, mut dy) = (black_box(STATE), [0.0; 4]);
                for _ in 0..CHAIN {
                    system.rhs(0.0, &y, &mut dy).unwrap();
                    for (yi, di) in y.iter_mut().zip(&dy) {
                        *yi += 1e-4 * di;
                    }
                }
                black_box(&y);
            }
            start.elapsed().div_f64(CHAIN as f64)
        })
    });

    let y0 = ModelInfo::initial_state(&new_system());
    let dense = OutputTimes::At((1..=100).map(|k| f64::from(k) * T_END / 100.0).collect());
    type Make = fn() -> Box<dyn Integrator>;
    let runs: [(&str, Make, &OutputTimes); 3] = [
        (
            "dp54",
            || Box::new(DormandPrince54::new()),
            &OutputTimes::Steps,
        ),
        (
            "dop853",
            || Box::new(DormandPrince853::new()),
            &OutputTimes::Steps,
        ),
        ("dop853_dense", || Box::new(DormandPrince853::new()), &dense),
    ];
    for (name, make, output) in runs {
        for (tol, tol_name) in TOLERANCES {
            let evals = run(make().as_mut(), tol, output, &y0);
            let options = IntegratorOptions::default().with_rtol(tol).with_atol(tol);
            let stats = make()
                .integrate(&mut new_system(), 0.0, &y0, T_END, output, &options)
                .expect("the double pendulum integrates to 10 s")
                .stats;
            eprintln!(
                "{name}_{tol_name}: {} steps, {} rejected, {evals} evaluations of F",
                stats.steps, stats.rejected
            );
            group.bench_function(format!("{name}_{tol_name}"), |b| {
                b.iter_custom(|iters| {
                    let mut method = make();
                    let mut total = Duration::ZERO;
                    for _ in 0..iters {
                        let start = Instant::now();
                        run(method.as_mut(), tol, output, &y0);
                        total += start.elapsed();
                    }
                    total.div_f64(evals as f64)
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, rhs);
criterion_main!(benches);
