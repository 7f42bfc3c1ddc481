//! A model compiled at run time against the same file compiled by `eomgen::model!`, side by
//! side in one run (issue 18's figures).
//!
//! - `load_compile/*`: [`JitModel::load`] of a model file — read, check, derive (the cheaper
//!   formulation), plan and compile to native code — for the bundled double pendulum and
//!   the 10-, 20- and 40-link pendulums of `eomgen new n-link-pendulum N` (written to a
//!   temporary directory). The exact Jacobians are derived and compiled when first used, so
//!   this is what `eomgen simulate FILE` pays before its first step; `load_compile_eager/*`
//!   includes them (what `eomgen modes FILE` pays).
//! - `rhs/*`: one evaluation of the first-order right-hand side `ẏ = [q̇; M⁻¹F]` of the double
//!   pendulum at a generic state: compiled ([`FirstOrder`]) and run-time ([`DynFirstOrder`]
//!   over [`JitModel`], native code, and the interpreter).
//! - `dp54/*`, `dop853/*`: a whole Dormand–Prince 5(4) and DOP853 integration of the double
//!   pendulum to `t = 10 s` at `rtol = atol = 1e-10`, compiled and run-time.
//!
//! - After the criterion groups, the same three ratios as the fastest of alternated batches
//!   (compiled and run time in turn, 300 batches of 10⁵ right-hand sides, 40 integrations
//!   each): the figure least disturbed when the machine runs other work; and the
//!   right-hand side's ratio so for five models it was not tuned on (one and two degrees of
//!   freedom, the heavy top, a triple pendulum, two bodies in the plane).
//!
//! Before timing, the run-time right-hand side is checked equal to the compiled one to the bit.
//!
//! Run with `cargo bench --bench runtime_model`.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
eomgen::model!("../models/double_pendulum.yaml");

/// Models the right-hand side was not tuned on, one of each size the fused right-hand side
/// covers (`eomgen_jit`'s `first_order`), for the alternated ratios.
mod others {
    pub mod forced_oscillator {
        eomgen::model!("../models/forced_oscillator.yaml");
    }
    pub mod two_masses {
        eomgen::model!("../models/two_masses.yaml");
    }
    pub mod heavy_top {
        eomgen::model!("../models/heavy_top.yaml");
    }
    pub mod triple_pendulum {
        eomgen::model!("../models/triple_pendulum.yaml");
    }
    pub mod two_body {
        eomgen::model!("../models/two_body.yaml");
    }
}
use eomgen::{
    Backend, DormandPrince54, DormandPrince853, DynFirstOrder, FirstOrder, Integrator,
    IntegratorOptions, JitModel, LoadOptions, ModelInfo, OdeSystem, OutputTimes,
};

/// `[θ₁, θ₂, θ̇₁, θ̇₂]` (rad, rad/s), as in `benches/rhs.rs`.
const STATE: [f64; 4] = [0.4, 1.9, -0.8, 1.3];

fn double_pendulum_file() -> PathBuf {
    PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../models/double_pendulum.yaml"
    ))
}

/// Writes `eomgen new n-link-pendulum N` into `dir` and returns its path.
fn chain_file(dir: &std::path::Path, n: usize) -> PathBuf {
    let source = eomgen_symbolic::model::templates::n_link_pendulum(n);
    let path = dir.join(format!("pendulum_{n}.yaml"));
    std::fs::write(&path, source).expect("the temporary directory is writable");
    path
}

fn load_compile(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let files: Vec<(String, PathBuf)> =
        std::iter::once(("double_pendulum".to_string(), double_pendulum_file()))
            .chain([10, 20, 40].map(|n| (format!("{n}_link"), chain_file(dir.path(), n))))
            .collect();
    let mut group = c.benchmark_group("load_compile");
    group.sample_size(10);
    for (name, path) in &files {
        group.bench_function(name.as_str(), |b| {
            b.iter(|| JitModel::load(black_box(path)).expect("loads"))
        });
    }
    group.finish();
    let mut group = c.benchmark_group("load_compile_eager");
    group.sample_size(10);
    let eager = LoadOptions {
        eager_jacobians: true,
        ..LoadOptions::default()
    };
    for (name, path) in &files[..3] {
        group.bench_function(name.as_str(), |b| {
            b.iter(|| JitModel::load_with(black_box(path), eager).expect("loads"))
        });
    }
    group.finish();
    for (name, path) in &files {
        let model = JitModel::load_with(path, eager).expect("loads");
        println!("{name}: {} bytes of machine code", model.code_bytes());
    }
}

fn runtime(backend: Option<Backend>) -> DynFirstOrder<JitModel> {
    let options = LoadOptions {
        backend,
        ..LoadOptions::default()
    };
    DynFirstOrder::new(JitModel::load_with(double_pendulum_file(), options).expect("loads"))
}

fn rhs(c: &mut Criterion) {
    let mut compiled = FirstOrder::new(DoublePendulum::default());
    let mut native = runtime(None);
    let mut interpreted = runtime(Some(Backend::Interpreter));
    let (mut a, mut b) = ([0.0; 4], [0.0; 4]);
    compiled.rhs(0.0, &STATE, &mut a).expect("evaluates");
    native.rhs(0.0, &STATE, &mut b).expect("evaluates");
    assert_eq!(
        a.map(f64::to_bits),
        b.map(f64::to_bits),
        "run-time rhs differs"
    );
    let mut group = c.benchmark_group("rhs");
    let mut dy = [0.0; 4];
    group.bench_function("compiled", |bench| {
        bench.iter(|| compiled.rhs(0.0, black_box(&STATE), &mut dy))
    });
    group.bench_function("runtime_native", |bench| {
        bench.iter(|| native.rhs(0.0, black_box(&STATE), &mut dy))
    });
    group.bench_function("runtime_interpreter", |bench| {
        bench.iter(|| interpreted.rhs(0.0, black_box(&STATE), &mut dy))
    });
    group.finish();
    // The equations alone, without the solve: the generated code against the native code.
    let mut group = c.benchmark_group("mass_matrix_and_forcing");
    let pendulum = DoublePendulum::default();
    let q = nalgebra::Vector2::new(STATE[0], STATE[1]);
    let qdot = nalgebra::Vector2::new(STATE[2], STATE[3]);
    group.bench_function("compiled", |bench| {
        bench.iter(|| {
            eomgen::MechanicalSystem::mass_matrix_and_forcing(
                &pendulum,
                black_box(&q),
                black_box(&qdot),
                0.0,
            )
        })
    });
    let (mut mass, mut forcing) = ([0.0; 4], [0.0; 2]);
    group.bench_function("runtime_native", |bench| {
        bench.iter(|| {
            eomgen::DynMechanicalSystem::mass_matrix_and_forcing(
                &native.system,
                black_box(&STATE[..2]),
                black_box(&STATE[2..]),
                0.0,
                &mut mass,
                &mut forcing,
            );
            forcing[1]
        })
    });
    group.finish();
}

fn integrate(integrator: &mut dyn Integrator, system: &mut dyn OdeSystem, y0: &[f64]) -> usize {
    let options = IntegratorOptions::default()
        .with_rtol(1e-10)
        .with_atol(1e-10);
    integrator
        .integrate(system, 0.0, y0, 10.0, &OutputTimes::Steps, &options)
        .expect("integrates")
        .len()
}

fn runs(c: &mut Criterion) {
    let mut compiled = FirstOrder::new(DoublePendulum::default());
    let mut native = runtime(None);
    let y0 = ModelInfo::initial_state(&compiled);
    assert_eq!(y0, native.initial_state());
    let mut methods: [(&str, Box<dyn Integrator>); 2] = [
        ("dp54", Box::new(DormandPrince54::new())),
        ("dop853", Box::new(DormandPrince853::new())),
    ];
    for (name, method) in &mut methods {
        let mut group = c.benchmark_group(*name);
        group.bench_function("compiled", |b| {
            b.iter(|| integrate(method.as_mut(), &mut compiled, black_box(&y0)))
        });
        group.bench_function("runtime_native", |b| {
            b.iter(|| integrate(method.as_mut(), &mut native, black_box(&y0)))
        });
        group.finish();
    }
}

/// The fastest of many alternated batches: `time(false)` (compiled) and `time(true)` (run
/// time) in turn, so that a machine busy with other work slows both alike, and the minimum is
/// the figure least disturbed by it.
fn fastest_alternated(batches: usize, mut time: impl FnMut(bool) -> f64) -> (f64, f64) {
    (0..batches).fold((f64::MAX, f64::MAX), |(c, r), _| {
        (c.min(time(false)), r.min(time(true)))
    })
}

/// Seconds per call of `f`, over `calls` calls.
fn per_call(calls: usize, mut f: impl FnMut()) -> f64 {
    let start = std::time::Instant::now();
    for _ in 0..calls {
        f();
    }
    start.elapsed().as_secs_f64() / calls as f64
}

/// The run-time / compiled ratios again, as the fastest of alternated batches (printed, not
/// a criterion group): a check of the criterion medians on a machine shared with other work.
fn alternated(_: &mut Criterion) {
    let mut compiled = FirstOrder::new(DoublePendulum::default());
    let mut native = runtime(None);
    let mut dy = [0.0; 4];
    let (c, r) = fastest_alternated(300, |run_time| {
        per_call(100_000, || {
            let _ = if run_time {
                native.rhs(0.0, black_box(&STATE), black_box(&mut dy))
            } else {
                compiled.rhs(0.0, black_box(&STATE), black_box(&mut dy))
            };
        })
    });
    println!(
        "alternated rhs: compiled {:.2} ns, run time {:.2} ns, ratio {:.3}",
        c * 1e9,
        r * 1e9,
        r / c
    );
    let others: [(&str, Box<dyn ModelInfo>); 5] = [
        (
            "forced_oscillator",
            Box::new(FirstOrder::new(
                others::forced_oscillator::ForcedOscillator::default(),
            )),
        ),
        (
            "two_masses",
            Box::new(FirstOrder::new(others::two_masses::TwoMasses::default())),
        ),
        (
            "heavy_top",
            Box::new(FirstOrder::new(others::heavy_top::HeavyTop::default())),
        ),
        (
            "triple_pendulum",
            Box::new(FirstOrder::new(
                others::triple_pendulum::TriplePendulum::default(),
            )),
        ),
        (
            "two_body",
            Box::new(FirstOrder::new(others::two_body::TwoBody::default())),
        ),
    ];
    for (name, mut other) in others {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../models/{name}.yaml"));
        let mut run_time = DynFirstOrder::new(JitModel::load(&path).expect("loads"));
        // A state off the initial one, where no rate is zero.
        let y: Vec<f64> = ModelInfo::initial_state(other.as_ref())
            .iter()
            .enumerate()
            .map(|(i, v)| v + 0.1 + 0.05 * i as f64)
            .collect();
        let mut dy = vec![0.0; y.len()];
        let (c, r) = fastest_alternated(100, |runtime| {
            per_call(100_000, || {
                let _ = if runtime {
                    run_time.rhs(0.3, black_box(&y), black_box(&mut dy))
                } else {
                    other
                        .as_ode_mut()
                        .rhs(0.3, black_box(&y), black_box(&mut dy))
                };
            })
        });
        println!(
            "alternated rhs of {name}: compiled {:.2} ns, run time {:.2} ns, ratio {:.3}",
            c * 1e9,
            r * 1e9,
            r / c
        );
    }
    let y0 = ModelInfo::initial_state(&compiled);
    let mut methods: [(&str, Box<dyn Integrator>); 2] = [
        ("dp54", Box::new(DormandPrince54::new())),
        ("dop853", Box::new(DormandPrince853::new())),
    ];
    for (name, method) in &mut methods {
        let (c, r) = fastest_alternated(40, |run_time| {
            per_call(1, || {
                let system: &mut dyn OdeSystem = if run_time { &mut native } else { &mut compiled };
                black_box(integrate(method.as_mut(), system, &y0));
            })
        });
        println!(
            "alternated {name}: compiled {:.1} µs, run time {:.1} µs, ratio {:.3}",
            c * 1e6,
            r * 1e6,
            r / c
        );
    }
}

criterion_group!(benches, rhs, runs, alternated, load_compile);
criterion_main!(benches);
