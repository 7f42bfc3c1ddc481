//! The compiled code of a run-time model is freed with the model, and a large model's memory
//! stays bounded (issue 18).

use eomgen_jit::{JitModel, LoadOptions};
use eomgen_runtime::{DynFirstOrder, DynMechanicalSystem, ModelInfo};

/// Resident memory of this process (bytes), from `/proc/self/status`.
#[cfg(target_os = "linux")]
fn resident_bytes() -> usize {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc is mounted");
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<usize>().ok())
        .map(|kb| kb * 1024)
        .expect("VmRSS")
}

/// A chain of 100 masses and 101 springs (`eomgen new n-mass-chain 100`) is loaded, derived,
/// compiled with its Jacobians and evaluated 25 times over, each model dropped before the
/// next is loaded. If the machine code (a model's `code_bytes`, ~86 kB here, in pages mapped
/// for it) or the derivation leaked, 20 further loads would add at least 20 times that; the
/// test allows the growth of 4 models' code (the allocator keeps some freed memory), and
/// checks that the model still evaluates correctly (the spring forces of a displaced middle
/// mass). Made to leak the code (`mem::forget` of the module), the test sees 5 MB of growth.
#[cfg(target_os = "linux")]
#[test]
fn a_hundred_mass_chain_loads_again_and_again_in_bounded_memory() {
    let source = eomgen_symbolic::model::templates::n_mass_chain(100);
    let options = LoadOptions {
        eager_jacobians: true,
        ..LoadOptions::default()
    };
    let load = || {
        let model = JitModel::from_source_with("n_mass_chain_100.yaml", &source, options)
            .unwrap_or_else(|e| panic!("{e}"));
        let n = model.num_dofs();
        assert_eq!(n, 100);
        // Mass 50 displaced by 1 cm: springs on both sides pull it back with 2 k x = 0.02 N
        // (k = 1 N/m) and push its neighbours with k x.
        let mut q = vec![0.0; n];
        q[50] = 0.01;
        let (mut mass, mut forcing) = (vec![0.0; n * n], vec![0.0; n]);
        model.mass_matrix_and_forcing(&q, &vec![0.0; n], 0.0, &mut mass, &mut forcing);
        assert!((forcing[50] + 0.02).abs() < 1e-12, "{}", forcing[50]);
        assert!((forcing[49] - 0.01).abs() < 1e-12 && (forcing[51] - 0.01).abs() < 1e-12);
        let system = DynFirstOrder::new(model);
        let (jq, _) = system.forcing_jacobians(0.0, &vec![0.0; 2 * n]);
        assert!((jq[(50, 50)] + 2.0).abs() < 1e-12, "∂F/∂q diagonal is −2k");
        system.system.code_bytes()
    };
    for _ in 0..5 {
        load();
    }
    let before = resident_bytes();
    let mut code = 0;
    for _ in 0..20 {
        code = load();
    }
    let growth = resident_bytes().saturating_sub(before);
    assert!(code > 50_000, "{code} bytes of code");
    assert!(
        growth < 4 * code,
        "memory grew by {growth} bytes over 20 loads of a model with {code} bytes of code"
    );
}

/// A 100-link pendulum (`eomgen new n-link-pendulum 100`: 100 coordinates, 10 000 entries of
/// `M`) is derived, compiled and integrated for a few steps three times, each model dropped
/// before the next: the resident memory after the third equals that after the second to
/// within twice the model's machine code (nothing accumulates), and stays under 1 GiB
/// (~220 MB measured for the whole `eomgen simulate` process). Seconds in a release build,
/// so it is left out of the default run:
/// `cargo test --release -p eomgen-jit --test memory -- --ignored --nocapture`.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a 100-link chain takes seconds to derive and compile; run with --ignored"]
fn a_hundred_link_pendulum_loads_in_bounded_memory() {
    use eomgen_runtime::{DormandPrince54, Integrator, IntegratorOptions, OutputTimes};
    let source = eomgen_symbolic::model::templates::n_link_pendulum(100);
    let mut resident = Vec::new();
    let mut code = 0;
    for _ in 0..3 {
        let started = std::time::Instant::now();
        let model = JitModel::from_source("p100.yaml", &source).unwrap_or_else(|e| panic!("{e}"));
        let loaded = started.elapsed();
        code = model.code_bytes();
        let mut system = DynFirstOrder::new(model);
        let y0 = system.initial_state();
        let solution = DormandPrince54::new()
            .integrate(
                &mut system,
                0.0,
                &y0,
                1e-3,
                &OutputTimes::At(vec![1e-3]),
                &IntegratorOptions::default(),
            )
            .unwrap_or_else(|e| panic!("{e}"));
        let (_, y) = solution.iter().last().expect("a sample");
        let drift = (system.energy(1e-3, y) - system.energy(0.0, &y0)).abs();
        assert!(
            drift < 1e-6 * system.energy(0.0, &y0).abs().max(1.0),
            "{drift}"
        );
        drop(system);
        resident.push(resident_bytes());
        println!(
            "loaded in {loaded:?}, {code} bytes of code, resident {} MB",
            resident_bytes() / 1_000_000
        );
    }
    assert!(resident[2] < 1 << 30, "{resident:?}");
    assert!(
        resident[2].saturating_sub(resident[1]) < 2 * code,
        "{resident:?} with {code} bytes of code"
    );
}
