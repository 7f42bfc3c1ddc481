//! `eomgen study expm` (HW32) on the default 10 × 10 random `A` (seed 32, 21 samples on
//! [0, 5] s, DOP853 at 1e-13): the whole study, and each of its three routes alone, as
//! criterion medians. The goal is the whole study under 10 ms.
//!
//! `cargo bench --bench expm_study` (figures in docs/performance.md, "Studies of the
//! linearisation").

use std::hint::black_box;

use criterion::Criterion;
use eomgen::analysis::vibration::{ExpmOptions, expm_study, random_problem};
use eomgen::{
    state_response_by_eigenvectors, state_response_by_exponential, state_response_by_integration,
};

fn main() {
    let mut c = Criterion::default().configure_from_args();
    let options = ExpmOptions::default();
    let problem = random_problem(options.n, options.seed);
    let (a, z0) = (&problem.state_matrix, &problem.initial_state);
    let times: Vec<f64> = (0..options.samples)
        .map(|i| options.t_end * i as f64 / (options.samples - 1) as f64)
        .collect();
    let mut group = c.benchmark_group("study_expm_10x10");
    group.bench_function("whole_study", |b| {
        b.iter(|| expm_study(black_box(&options)).expect("the default study runs"))
    });
    group.bench_function("exponential", |b| {
        b.iter(|| state_response_by_exponential(black_box(a), z0, &times))
    });
    group.bench_function("eigenvectors", |b| {
        b.iter(|| state_response_by_eigenvectors(black_box(a), z0, &times))
    });
    group.bench_function("integration", |b| {
        b.iter(|| state_response_by_integration(black_box(a), z0, &times, options.tol))
    });
    group.finish();
    c.final_summary();
}
