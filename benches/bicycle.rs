//! The Whipple bicycle benchmark (`models/whipple_bicycle.yaml`, issue 30 item 6): what its
//! derivation, compilation and stability sweep cost.
//!
//! - `derive/*`: the symbolic work of the `model!` macro and of the run-time loader — read
//!   and check the file, lower it, derive `M q̈ = F` by the preferred formulation (momentum
//!   balance), and with `jacobians` also `∂F/∂q`, `∂F/∂q̇` and `∂(M a)/∂q`; `emit` adds the
//!   macro's code planning and printing (the tokens rustc then compiles).
//! - `load_compile_eager`: [`JitModel::load_with`] with the Jacobians — the whole run-time
//!   path from the file to native code.
//! - `steady_motion`: one `eomgen modes whipple_bicycle --at upright` analysis (the steady
//!   motion, the reduced linearisation by differences, its eigenvalues).
//! - `sweep_201`: `eomgen study parameter-sweep whipple_bicycle --at upright --parameter v
//!   --values 0..10:201`: 201 analyses and the bisections of the weave and capsize speeds.
//! - `integrate/*`: 0–5 s from the file's state at `rtol = atol = 1e-8` with the Taylor method
//!   (the index-1 system's series, `[M Jᵀ; J 0][q̈; λ] = [F; γ]`), Verner 9(8) and DOP853:
//!   the model and methods docs/performance.md's "The Taylor method with constraints"
//!   charts (there over 10 s and nine tolerances). At the same
//!   tolerance (not the same error), 2026-11-27: Taylor 8.7 ms, Verner 9(8) 1.84 ms, DOP853
//!   0.75 ms.
//!
//! Run with `cargo bench --bench bicycle`.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use eomgen::analysis::vibration::{
    self, EquilibriumStart, OperatingPointOptions, ParameterSweepOptions, SweepAxis,
};
use eomgen::{JitModel, LoadOptions};
use eomgen_symbolic::codegen::{self, EmitOptions};
use eomgen_symbolic::mechanics::{Jacobians, SymbolicModel, preferred_equations};

fn bicycle_file() -> PathBuf {
    PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../models/whipple_bicycle.yaml"
    ))
}

fn upright() -> OperatingPointOptions {
    OperatingPointOptions {
        start: EquilibriumStart::Named("upright".to_string()),
        ..OperatingPointOptions::default()
    }
}

fn derive(c: &mut Criterion) {
    let path = bicycle_file();
    let source = std::fs::read_to_string(&path).expect("the model file reads");
    let name = path.to_string_lossy().to_string();
    let mut group = c.benchmark_group("derive");
    group.sample_size(10);
    group.bench_function("equations", |b| {
        b.iter(|| {
            let file = eomgen_symbolic::model::load(&name, black_box(&source)).expect("loads");
            let mut model = SymbolicModel::from_file(&file).expect("lowers");
            preferred_equations(&mut model)
        })
    });
    group.bench_function("jacobians", |b| {
        b.iter(|| {
            let file = eomgen_symbolic::model::load(&name, black_box(&source)).expect("loads");
            let mut model = SymbolicModel::from_file(&file).expect("lowers");
            let (eom, _) = preferred_equations(&mut model);
            Jacobians::of(&mut model, &eom)
        })
    });
    group.bench_function("emit", |b| {
        b.iter(|| {
            let file = eomgen_symbolic::model::load(&name, black_box(&source)).expect("loads");
            let mut model = SymbolicModel::from_file(&file).expect("lowers");
            let (eom, _) = preferred_equations(&mut model);
            let plans = codegen::plan::EmitPlans::of(&model, &eom);
            codegen::emit(&model, &eom, &plans, &EmitOptions::default()).expect("emits")
        })
    });
    group.finish();
    let mut group = c.benchmark_group("load_compile_eager");
    group.sample_size(10);
    let eager = LoadOptions {
        eager_jacobians: true,
        ..LoadOptions::default()
    };
    group.bench_function("whipple_bicycle", |b| {
        b.iter(|| JitModel::load_with(black_box(&path), eager).expect("loads"))
    });
    group.finish();
}

/// The bicycle compiled by `model!` (the figures of docs/performance.md were measured so).
mod compiled {
    eomgen::model!("../models/whipple_bicycle.yaml");
}

fn stability(c: &mut Criterion) {
    let mut model: Box<dyn eomgen::ModelInfo> =
        Box::new(eomgen::FirstOrder::new(compiled::WhippleBicycle::default()));
    let mut group = c.benchmark_group("bicycle");
    group.sample_size(10);
    group.bench_function("steady_motion", |b| {
        b.iter(|| vibration::steady_motion_analysis(model.as_mut(), &upright()).expect("steady"))
    });
    let options = ParameterSweepOptions {
        axis: SweepAxis::linear("v", 0.0, 10.0, 201).expect("an axis"),
        operating_point: upright(),
        refine: true,
    };
    group.bench_function("sweep_201", |b| {
        b.iter(|| {
            let sweep =
                vibration::parameter_sweep(model.as_mut(), &options, |_, _| {}).expect("sweeps");
            assert_eq!(sweep.stability_changes.len(), 2);
            sweep
        })
    });
    group.finish();
    let n = model.num_dofs();
    println!("whipple_bicycle: {n} coordinates");
}

fn integrate(c: &mut Criterion) {
    use eomgen::analysis::{SimulationOptions, simulate};
    use eomgen::{DynFirstOrder, Method};
    let model = JitModel::load(bicycle_file()).expect("the bicycle loads");
    let mut system = DynFirstOrder::new(model);
    let mut group = c.benchmark_group("integrate");
    group.sample_size(10);
    for (name, method) in [
        ("taylor", Method::Taylor),
        ("vern9", Method::Vern9),
        ("dop853", Method::Dop853),
    ] {
        let options = SimulationOptions {
            method,
            t_end: 5.0,
            rtol: 1e-8,
            atol: 1e-8,
            ..SimulationOptions::default()
        };
        group.bench_function(name, |b| {
            b.iter(|| {
                let run = simulate(&mut system, black_box(&options)).expect("starts");
                assert!(run.failure.is_none(), "{name}: {:?}", run.failure);
                run
            })
        });
    }
    group.finish();
}

criterion_group!(benches, derive, stability, integrate);
criterion_main!(benches);
