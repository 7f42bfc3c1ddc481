//! Times each stage of loading a model file at run time, for profiling large models.
//!
//! ```sh
//! cargo run --release -p eomgen-jit --example stages -- FILE.yaml [EVALUATIONS]
//! ```
//!
//! Prints the wall time of: reading and checking the file, lowering it, deriving the
//! equations the generated code uses, the mass-matrix diagnostics, planning the functions
//! (CSE and tapes), compiling them to native code, and `EVALUATIONS` (default 100)
//! right-hand sides `ẏ = [q̇; M⁻¹F]` at the initial state.

use std::time::Instant;

use eomgen_runtime::{DynFirstOrder, ModelInfo, OdeSystem};

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: stages FILE.yaml [EVALUATIONS]");
        std::process::exit(2);
    };
    let evaluations: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(100);
    let stage = |name: &str, start: Instant| {
        eprintln!(
            "{name:<28} {:>10.1} ms",
            start.elapsed().as_secs_f64() * 1e3
        );
        Instant::now()
    };
    let start = Instant::now();
    let source = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let file = eomgen_symbolic::model::load(&path, &source)
        .unwrap_or_else(|d| panic!("{} diagnostics", d.len()));
    let t = stage("read and check", start);
    let mut model = eomgen_symbolic::mechanics::SymbolicModel::from_file(&file)
        .unwrap_or_else(|d| panic!("{} diagnostics", d.len()));
    let t = stage("lower", t);
    let (eom, formulation) = eomgen_symbolic::mechanics::preferred_equations(&mut model);
    let t = stage(&format!("derive ({formulation})"), t);
    let problems = eomgen_symbolic::mechanics::mass_matrix_diagnostics(&model, &eom, &file);
    assert!(problems.is_empty());
    let t = stage("mass-matrix diagnostics", t);
    // The same again in one call, which keeps the derivation for the Jacobians: the
    // difference is the planning.
    let (program, derivation) = eomgen_symbolic::codegen::program::ModelProgram::from_file(&file)
        .unwrap_or_else(|_| panic!("cannot plan"));
    let t = stage("lower, derive, diagnose, plan", t);
    let jit = eomgen_jit::JitModel::from_program(program, derivation, Default::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let t = stage("compile", t);
    let mut system = DynFirstOrder::new(jit);
    let y0 = system.initial_state().to_vec();
    let mut dy = vec![0.0; y0.len()];
    for _ in 0..evaluations {
        system
            .rhs(0.0, &y0, &mut dy)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    stage(&format!("{evaluations} right-hand sides"), t);
}
