//! Large generated models load, check and simulate (issue 28, item 5): the mass-matrix solve
//! within the envelope of `M`, the runs of zero outputs written by one call, and the
//! cross-checks of `eomgen check` on chains of many bodies.

use eomgen_jit::JitModel;
use eomgen_runtime::{
    DormandPrince54, DynFirstOrder, DynMechanicalSystem, Integrator, IntegratorOptions, ModelInfo,
    OdeSystem, OutputTimes,
};
use eomgen_symbolic::mechanics::cross_check::check_model;
use eomgen_symbolic::model::templates::{MAX_SIZES, TEMPLATES, generate};

/// The relative tolerance of `eomgen check`.
const CHECK_TOLERANCE: f64 = 1e-8;

/// Loads the template `name` of size `n` at run time, checks it as `eomgen check` does
/// (`states` random states) and integrates it over `t_end` with DP5(4): every comparison
/// of derivations passes, and `T + V` is conserved to 1e-6 relative (both templates are
/// conservative; at rtol = atol = 1e-6 over a short run the drift is far below that).
/// Returns the model's `M`, `F` at its initial state.
fn load_check_and_simulate(
    name: &str,
    n: usize,
    states: usize,
    t_end: f64,
) -> (Vec<f64>, Vec<f64>) {
    let source = generate(name, n).unwrap_or_else(|e| panic!("{e}"));
    let file = eomgen_symbolic::model::load("t.yaml", &source)
        .unwrap_or_else(|d| panic!("{name} {n}: {} diagnostics", d.len()));
    let report = check_model(&file, states, 0x5EED).unwrap_or_else(|_| panic!("lowers"));
    assert!(!report.comparisons.is_empty(), "{name} {n}");
    assert!(report.passed(CHECK_TOLERANCE), "{name} {n}: {report:?}");
    let model = JitModel::from_source("t.yaml", &source).unwrap_or_else(|e| panic!("{e}"));
    let mut system = DynFirstOrder::new(model);
    let y0 = system.initial_state();
    let (q, qdot) = y0.split_at(n);
    let (mut mass, mut forcing) = (vec![f64::NAN; n * n], vec![f64::NAN; n]);
    system
        .system
        .mass_matrix_and_forcing(q, qdot, 0.0, &mut mass, &mut forcing);
    let solution = DormandPrince54::new()
        .integrate(
            &mut system,
            0.0,
            &y0,
            t_end,
            &OutputTimes::At(vec![t_end]),
            &IntegratorOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{name} {n}: {e}"));
    let (_, y) = solution.iter().last().expect("a sample");
    let e0 = system.energy(0.0, &y0);
    let drift = (system.energy(t_end, y) - e0).abs();
    assert!(
        drift < 1e-6 * e0.abs().max(1.0),
        "{name} {n}: drift {drift}"
    );
    (mass, forcing)
}

/// A 60-mass chain (its `M` diagonal: runs of 60 zeros between the diagonal entries, each
/// written by one call, and the solve within the envelope) and a 12-link pendulum (a dense
/// `M`, the envelope the whole matrix) check and simulate; the chain's `M` is exactly
/// `m I` (every entry written over the NaN the buffer held), its `F` at the start (mass 1
/// displaced by 1 m) is exactly `k (x₂ − 2x₁) = −2 N` and `k x₁ = 1 N` on its neighbour,
/// and its right-hand side is `q̈ = F/m` to the bit.
#[test]
fn a_chain_of_masses_and_a_pendulum_of_bars_load_check_and_simulate() {
    let n = 60;
    let (mass, forcing) = load_check_and_simulate("n-mass-chain", n, 20, 1.0);
    for i in 0..n {
        for j in 0..n {
            let expected = if i == j { 1.0 } else { 0.0 };
            assert_eq!(
                mass[i + j * n].to_bits(),
                f64::to_bits(expected),
                "M({i}, {j})"
            );
        }
    }
    assert_eq!(forcing[0], -2.0);
    assert_eq!(forcing[1], 1.0);
    assert!(forcing[2..].iter().all(|&f| f == 0.0));
    let source = generate("n-mass-chain", n).unwrap();
    let mut system = DynFirstOrder::new(JitModel::from_source("c.yaml", &source).unwrap());
    let y0 = system.initial_state();
    let mut dy = vec![f64::NAN; 2 * n];
    system.rhs(0.0, &y0, &mut dy).unwrap();
    assert_eq!(&dy[n..n + 2], &[-2.0, 1.0]);
    load_check_and_simulate("n-link-pendulum", 12, 20, 0.1);
}

/// The largest size of each template ([`MAX_SIZES`]: 100 links, 1000 masses) loads, passes
/// `eomgen check`'s cross-checks at its 200 default states and simulates a short run. Seconds
/// each in a release build (docs/performance.md has the figures), minutes in a debug one, so
/// it is left out of the default run:
/// `cargo test --release -p eomgen-jit --test scale -- --ignored --nocapture`.
#[test]
#[ignore = "seconds in release, minutes in debug; run with --release --ignored"]
fn the_largest_templates_load_check_and_simulate() {
    for (name, &n) in TEMPLATES.iter().zip(&MAX_SIZES) {
        let started = std::time::Instant::now();
        load_check_and_simulate(name, n, 200, 0.01);
        println!("{name} {n}: {:?}", started.elapsed());
    }
}
