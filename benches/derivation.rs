//! Cost of the compile-time half of `eomgen::model!`: model file → equations of motion →
//! tokens, and how it grows with the size of the mechanism.
//!
//! Every `derive_*` bench runs the pipeline the macro runs before code generation, from the
//! YAML text:
//!
//! ```text
//! model::load (YAML → typed, checked ModelFile)
//!   → SymbolicModel::from_file (points, T, V, Q in the arena)
//!   → preferred_equations (momentum balance for a kinematic model, else Lagrange: one
//!     derivation)
//!   → Jacobians::of (∂F/∂q, ∂F/∂q̇, ∂(M a)/∂q)
//!   → cse::plan over [M; F] (the plan of the hot `mass_matrix_and_forcing`)
//! ```
//!
//! - `derive_double_pendulum` is the bundled `models/double_pendulum.yaml`, what a user
//!   compiles;
//! - `derive_n_link_pendulum_{2,5,10,20,40}` run the same pipeline on generated chains of `n`
//!   uniform bars ([`n_link_pendulum`], after sympy's `n_link_pendulum_on_cart`), to show how
//!   derivation time and expression size scale with `n` (the mass matrix is dense, so `F`
//!   has `O(n²)` velocity-product terms and `M` `O(n²)` entries);
//! - `emit_n_link_pendulum_10` times code generation alone ([`codegen::emit`]: CSE plans
//!   and printing of every generated function) on an already derived 10-link chain;
//! - the `formulations` group (issue 4's scaling table) times each formulation on its own,
//!   Lagrange and momentum balance for `n` = 2, 5, 10, 20, 30, 40, 80:
//!   `{method}_n_link_pendulum_{n}`
//!   derives `M` and `F`, `{method}_and_jacobians_n_link_pendulum_{n}` also `Jacobians::of`
//!   (what the macro derives from the equations it keeps); loading and lowering are setup.
//!
//! Before timing, each size is derived once and reported on stderr: operations of `M` and `F`
//! evaluated as trees and after CSE (the same figures as [`codegen::EmitStats`]), and the
//! wall time of each stage of that one run. The derived `M` and `F` of every chain, by every
//! formulation, are also checked against the closed form (see [`check_against_closed_form`]),
//! so a wrong generator cannot produce plausible timings.
//!
//! - the `universal_joint_chain` group times `check` (both derivations and their comparison)
//!   of the chain of 3-D bodies in relative rotations of `eomgen new universal-joint-chain N`
//!   for N = 2, 4, 6, 8 joints (issue 52).
//!
//! Run with `cargo bench --bench derivation`; the side-by-side SymPy
//! figures come from `tools/sympy_n_link.py`, the compile time of the generated code from
//! `tools/compile_time.sh`.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use eomgen_symbolic::codegen::{self, EmitOptions};
use eomgen_symbolic::expr::ExprId;
use eomgen_symbolic::expr::cse::{self, CsePlan};
use eomgen_symbolic::expr::eval::Evaluator;
use eomgen_symbolic::mechanics::{
    EquationsOfMotion, Formulation, Jacobians, Lagrange, MomentumBalance, SymbolicModel,
    cross_check, preferred_equations,
};
use eomgen_symbolic::model;

/// The bundled double pendulum (two uniform bars, HW19).
const DOUBLE_PENDULUM: &str = include_str!("../models/double_pendulum.yaml");

/// Chain sizes of the `derive_n_link_pendulum_{n}` benches.
const SIZES: [usize; 5] = [2, 5, 10, 20, 40];

/// Model file of an `n`-link planar pendulum of uniform bars, in the convention of
/// `models/double_pendulum.yaml`.
///
/// Bar `i` (1-based) has mass `m{i}` = 1 kg, length `l{i}` = 1 m and centroidal inertia
/// `m{i} l{i}²/12`; `theta{i}` is its absolute angle from +x (counter-clockwise). Bar 1 is
/// hinged at the fixed point `O`; bar `i` ends at the joint `P{i}`, where bar `i + 1` is
/// hinged, and has its centre of mass `G{i}` at its middle. Gravity `g` = 10 m/s² along −y.
/// Positions are written out in full (`P{i}` = `Σₖ≤ᵢ lₖ (cos θₖ, sin θₖ)`), as a student
/// would write them, so the derivation does the differentiation work of a real model.
///
/// # Panics
/// If `n` is 0.
fn n_link_pendulum(n: usize) -> String {
    eomgen_symbolic::model::templates::n_link_pendulum(n)
}

/// What one run of the pipeline produces.
struct Derived {
    model: SymbolicModel,
    eom: EquationsOfMotion,
    /// The formulation `preferred_equations` chose.
    method: &'static str,
    plan: CsePlan,
}

/// Wall time of each stage of one run.
#[derive(Debug, Default)]
struct StageTimes {
    load: Duration,
    lower: Duration,
    equations: Duration,
    jacobians: Duration,
    cse: Duration,
}

impl StageTimes {
    fn total(&self) -> Duration {
        self.load + self.lower + self.equations + self.jacobians + self.cse
    }
}

/// `[M (row-major, n²); F (n)]`: the roots of the generated `mass_matrix_and_forcing`, exactly
/// as `codegen::emit` gathers them (the symmetric entries of `M` are one node each).
fn mass_and_forcing_roots(eom: &EquationsOfMotion) -> Vec<ExprId> {
    eom.mass_matrix
        .iter()
        .chain(&eom.forcing)
        .copied()
        .collect()
}

/// Runs load → lower → preferred equations → Jacobians → CSE plan of `[M; F]`, timing each
/// stage.
///
/// # Panics
/// If the model file is rejected (the generator and the bundled model are valid).
fn derive_timed(path: &str, source: &str) -> (Derived, StageTimes) {
    let mut times = StageTimes::default();
    let start = Instant::now();
    let file = model::load(path, source).unwrap_or_else(|d| panic!("{path}: {d:?}"));
    times.load = start.elapsed();

    let start = Instant::now();
    let mut model = SymbolicModel::from_file(&file).unwrap_or_else(|d| panic!("{path}: {d:?}"));
    times.lower = start.elapsed();

    let start = Instant::now();
    let (eom, method) = preferred_equations(&mut model);
    times.equations = start.elapsed();

    let start = Instant::now();
    black_box(Jacobians::of(&mut model, &eom));
    times.jacobians = start.elapsed();

    let start = Instant::now();
    let roots = mass_and_forcing_roots(&eom);
    let plan = cse::plan(&model.arena, &roots, "t");
    times.cse = start.elapsed();

    let derived = Derived {
        model,
        eom,
        method,
        plan,
    };
    (derived, times)
}

/// The timed pipeline: [`derive_timed`] without the clock reads.
fn derive(path: &str, source: &str) -> Derived {
    let file = model::load(path, source).unwrap_or_else(|d| panic!("{path}: {d:?}"));
    let mut model = SymbolicModel::from_file(&file).unwrap_or_else(|d| panic!("{path}: {d:?}"));
    let (eom, method) = preferred_equations(&mut model);
    Jacobians::of(&mut model, &eom);
    let roots = mass_and_forcing_roots(&eom);
    let plan = cse::plan(&model.arena, &roots, "t");
    Derived {
        model,
        eom,
        method,
        plan,
    }
}

/// Derives `source` once and prints its operation counts and stage times to stderr.
fn report(label: &str, path: &str, source: &str) -> Derived {
    let (derived, times) = derive_timed(path, source);
    let roots = mass_and_forcing_roots(&derived.eom);
    let before = derived.model.arena.tree_operation_count(&roots);
    let after = derived.plan.operation_count();
    eprintln!(
        "{label}: M and F by {}: {before} ops as trees, {after} after CSE ({} temporaries, \
         {} arena nodes); one derivation {:.3?} (load {:.3?}, lower {:.3?}, equations {:.3?}, \
         Jacobians {:.3?}, CSE {:.3?})",
        derived.method,
        derived.plan.temporaries.len(),
        derived.model.arena.len(),
        times.total(),
        times.load,
        times.lower,
        times.equations,
        times.jacobians,
        times.cse,
    );
    derived
}

/// Checks the derived `M` and `F` of an `n`-link chain of unit bars against the closed form
/// at an arbitrary state, to relative 1e-12.
///
/// For uniform bars with absolute angles, with `μᵢ = Σₖ>ᵢ mₖ` (mass hanging below joint `i`)
/// and here `mᵢ = lᵢ = 1`:
///
/// ```text
/// Mᵢᵢ = mᵢ lᵢ²/3 + μᵢ lᵢ²
/// Mᵢⱼ = aᵢⱼ cos(θᵢ − θⱼ),  aᵢⱼ = lᵢ lⱼ (mₖ/2 + μₖ), k = max(i, j)
/// Fᵢ  = −Σⱼ≠ᵢ aᵢⱼ sin(θᵢ − θⱼ) θ̇ⱼ² − g lᵢ (mᵢ/2 + μᵢ) cos θᵢ
/// ```
///
/// # Panics
/// If an entry differs.
fn check_against_closed_form(model: &SymbolicModel, eom: &EquationsOfMotion, n: usize) {
    let g = 10.0;
    let theta: Vec<f64> = (0..n).map(|i| 0.3 + 0.71 * i as f64).collect();
    let omega: Vec<f64> = (0..n).map(|i| -1.1 + 0.53 * i as f64).collect();
    let mut bindings = vec![0.0; model.arena.symbols().len()];
    for p in &model.parameters {
        bindings[p.symbol.index()] = p.default;
    }
    for i in 0..n {
        let [q, qdot, _] = model.coordinate_symbols(i);
        bindings[q.index()] = theta[i];
        bindings[qdot.index()] = omega[i];
    }
    let roots = mass_and_forcing_roots(eom);
    let values = Evaluator::new(&model.arena, &roots).eval(&bindings);

    // 0-based: μᵢ = n − 1 − i unit bars below joint i.
    let below = |i: usize| (n - 1 - i) as f64;
    let coupling = |i: usize, j: usize| 0.5 + below(i.max(j));
    let close = |a: f64, b: f64, what: &str| {
        assert!(
            (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0),
            "{n}-link pendulum: {what}: derived {a}, closed form {b}"
        );
    };
    for i in 0..n {
        for j in 0..n {
            let expected = if i == j {
                1.0 / 3.0 + below(i)
            } else {
                coupling(i, j) * (theta[i] - theta[j]).cos()
            };
            close(values[i * n + j], expected, &format!("M[{i}][{j}]"));
        }
        let velocity_terms: f64 = (0..n)
            .filter(|&j| j != i)
            .map(|j| coupling(i, j) * (theta[i] - theta[j]).sin() * omega[j] * omega[j])
            .sum();
        let expected = -velocity_terms - g * (0.5 + below(i)) * theta[i].cos();
        close(values[n * n + i], expected, &format!("F[{i}]"));
    }
}

fn derivation(c: &mut Criterion) {
    let mut group = c.benchmark_group("derivation");
    let path = "models/double_pendulum.yaml";
    report("double_pendulum", path, DOUBLE_PENDULUM);
    group.bench_function("derive_double_pendulum", |b| {
        b.iter(|| derive(black_box(path), black_box(DOUBLE_PENDULUM)))
    });

    for n in SIZES {
        let source = n_link_pendulum(n);
        let path = format!("n_link_pendulum_{n}.yaml");
        let derived = report(&format!("n_link_pendulum_{n}"), &path, &source);
        check_against_closed_form(&derived.model, &derived.eom, n);
        drop(derived);
        if n >= 10 {
            // Each run takes long enough that criterion's minimum of 10 samples is plenty.
            group.sample_size(10);
        }
        // The model file is generated in the setup; the pipeline from its text is timed.
        // The derived model is returned, so its (large) arena is freed outside the timing.
        group.bench_function(format!("derive_n_link_pendulum_{n}"), |b| {
            b.iter_batched(
                || n_link_pendulum(n),
                |source| derive(black_box(&path), black_box(&source)),
                BatchSize::LargeInput,
            )
        });
    }
    group.finish();

    // Code generation alone (printing the plans as Rust tokens), on a chain derived and
    // planned once: `emit` only reads the model and the plans, so no per-iteration setup is
    // needed.
    let n = 10;
    let Derived { model, eom, .. } =
        derive(&format!("n_link_pendulum_{n}.yaml"), &n_link_pendulum(n));
    let plans = codegen::plan::EmitPlans::of(&model, &eom);
    let options = EmitOptions::default();
    let (tokens, stats) =
        codegen::emit(&model, &eom, &plans, &options).expect("the 10-link chain emits");
    eprintln!(
        "emit n_link_pendulum_{n}: {} bytes of tokens; mass_matrix_and_forcing {} ops as \
         trees, {} after CSE",
        tokens.to_string().len(),
        stats.ops_before_cse,
        stats.ops_after_cse
    );
    let mut group = c.benchmark_group("codegen");
    group.sample_size(10);
    group.bench_function(format!("emit_n_link_pendulum_{n}"), |b| {
        b.iter(|| codegen::emit(black_box(&model), &eom, &plans, &options))
    });
    group.finish();
}

/// Chain sizes of the `formulations` group.
const SCALING_SIZES: [usize; 7] = [2, 5, 10, 20, 30, 40, 80];

/// Lagrange against momentum balance on the same lowered chain, N = 2 … 80 (issue 4's scaling
/// table): the derivation of `M` and `F` alone, and followed by [`Jacobians::of`]; loading and
/// lowering are setup. Before the timed runs, one run per size and method reports operation
/// counts and its wall times on stderr and checks `M` and `F` against the closed form.
fn formulations(c: &mut Criterion) {
    let mut group = c.benchmark_group("formulations");
    group.sample_size(10);
    for n in SCALING_SIZES {
        let source = n_link_pendulum(n);
        let file = model::load("chain.yaml", &source).expect("the generated chain loads");
        let methods: [(&str, &dyn Formulation); 2] =
            [("lagrange", &Lagrange), ("momentum", &MomentumBalance)];
        for (name, method) in methods {
            let mut lowered = SymbolicModel::from_file(&file).expect("lowers");
            let start = Instant::now();
            let eom = method.derive(&mut lowered);
            let equations = start.elapsed();
            let start = Instant::now();
            let jacobians = Jacobians::of(&mut lowered, &eom);
            let derivatives = start.elapsed();
            check_against_closed_form(&lowered, &eom, n);
            let roots = mass_and_forcing_roots(&eom);
            let jacobian_roots: Vec<ExprId> = jacobians
                .forcing_q
                .iter()
                .chain(&jacobians.forcing_qdot)
                .copied()
                .collect();
            eprintln!(
                "{name} n_link_pendulum_{n}: M and F {} ops as trees, {} after CSE; \
                 ∂F/∂q and ∂F/∂q̇ {} ops after CSE; one run: M and F {equations:.3?}, \
                 Jacobians {derivatives:.3?}, together {:.3?}",
                lowered.arena.tree_operation_count(&roots),
                cse::plan(&lowered.arena, &roots, "t").operation_count(),
                cse::plan(&lowered.arena, &jacobian_roots, "t").operation_count(),
                equations + derivatives,
            );
            drop(lowered);
            // The derived model is returned, so its arena is freed outside the timing.
            group.bench_function(format!("{name}_n_link_pendulum_{n}"), |b| {
                b.iter_batched(
                    || SymbolicModel::from_file(&file).expect("lowers"),
                    |mut m| {
                        let eom = method.derive(&mut m);
                        (m, eom)
                    },
                    BatchSize::LargeInput,
                )
            });
            group.bench_function(format!("{name}_and_jacobians_n_link_pendulum_{n}"), |b| {
                b.iter_batched(
                    || SymbolicModel::from_file(&file).expect("lowers"),
                    |mut m| {
                        let eom = method.derive(&mut m);
                        let jacobians = Jacobians::of(&mut m, &eom);
                        (m, eom, jacobians)
                    },
                    BatchSize::LargeInput,
                )
            });
        }
    }
    group.finish();
}

/// Joint counts of the `universal_joint_chain` group.
const JOINTS: [usize; 4] = [2, 4, 6, 8];

/// `eomgen check` of the chain of `eomgen new universal-joint-chain N` (issue 52), the
/// library call the command makes ([`cross_check::check_model`], 200 states): both
/// derivations of a chain of 3-D bodies in relative rotations, their comparison and the power
/// balance, from the loaded file. Before the timed runs, one run per size reports each
/// derivation's operations after CSE and checks that the two derivations agree (to 1e-12).
/// The growth from 2 to 8 joints is the figure of docs/performance.md ("Derivations of 3-D
/// chains"); it was exponential (×15 per joint) before the expansion's caps.
fn universal_joint_chain(c: &mut Criterion) {
    let mut group = c.benchmark_group("universal_joint_chain");
    group.sample_size(10);
    for n in JOINTS {
        let source = eomgen_symbolic::model::templates::universal_joint_chain(n);
        let file = model::load("chain.yaml", &source).expect("the generated chain loads");
        let report = cross_check::check_model(&file, 200, 7).expect("derives");
        let comparison = &report.comparisons[0];
        assert!(comparison.max_rel_residual < 1e-12, "{report:?}");
        let ops: Vec<String> = report
            .derivations
            .iter()
            .map(|d| format!("{} {} ops after CSE", d.name, d.ops_after_cse))
            .collect();
        eprintln!("universal_joint_chain_{n}: {}", ops.join(", "));
        group.bench_function(format!("check_{n}"), |b| {
            b.iter(|| cross_check::check_model(black_box(&file), 200, 7).expect("derives"))
        });
    }
    group.finish();
}

criterion_group!(benches, derivation, formulations, universal_joint_chain);
criterion_main!(benches);
