//! The Taylor coefficients of every bundled model's motion (`OdeSystem::taylor_coefficients`)
//! against an independent high-precision reference, `tests/data/taylor_coefficients.json`,
//! written by `tools/taylor_reference.py` (see its docstring to regenerate it).
//!
//! The reference shares no code with eomgen: the script reads each model's `M` and `F` as text
//! (`eomgen equations FILE --json`), evaluates them with SymPy and mpmath on truncated power
//! series at 50 digits (functions by composition with their Taylor expansions, not by the
//! recurrences the models generate), solves `M a = F` (with constraints, `[M Jᵀ; J 0][a; λ] =
//! [F; γ]`) order by order, and cross-checks every
//! model against mpmath's own ODE Taylor method (finite differences of tiny Euler steps); the
//! two routes agree to 1e-34 relative. Each model is checked at its own state: `t = 0.3`, the
//! file's initial state plus a seeded perturbation, order 12.
//!
//! Three properties, for every bundled model:
//! - the coefficients of the model compiled at run time from its file, and of the same model
//!   compiled by `model!` (the thirteen of `compiled_models`) or else interpreted, agree with
//!   the reference within [`tolerance`];
//! - the two are bit-identical (they run the same recurrences, `eomgen_runtime::taylor::apply`,
//!   on the same values in the same order);
//! - a model without coefficients says why: the functions of its equations without a
//!   recurrence (`abs`, `sign`, `step`), which its file uses; compiled by `model!`, its
//!   constraints (with their number).
//!
//! The reference leaves out the Whipple bicycle, whose listing is too long to print:
//! `tests/taylor.rs` checks its series against its right-hand side and DOP853.

use std::collections::BTreeSet;

use eomgen::taylor::TaylorUnsupported;
use eomgen::{DynFirstOrder, JitModel, LoadOptions, ModelInfo};
use serde::Deserialize;

/// The reference file, as `tools/taylor_reference.py` writes it.
#[derive(Deserialize)]
struct Reference {
    models: Vec<Entry>,
}

/// One model of the reference: its coefficients at `(t, y)`, or why it has none.
#[derive(Deserialize)]
struct Entry {
    name: String,
    /// `models/<file>.yaml`, as `ModelEntry::file`.
    file: String,
    /// Why there are no coefficients (constraints, functions without a recurrence).
    #[serde(default)]
    skip: Option<String>,
    /// The number of constraints.
    #[serde(default)]
    constraints: usize,
    /// The functions without a recurrence the equations use, for a skipped model.
    #[serde(default)]
    functions: Vec<String>,
    /// `2n`.
    #[serde(default)]
    dim: usize,
    #[serde(default)]
    t: String,
    /// `y = [q; q̇]`, doubles written with 25 digits.
    #[serde(default)]
    y: Vec<String>,
    #[serde(default)]
    order: usize,
    /// `coefficients[k · dim + i] = yᵢ⁽ᵏ⁾(t)/k!`, 30 digits.
    #[serde(default)]
    coefficients: Vec<String>,
}

fn reference() -> Reference {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/taylor_coefficients.json"
    );
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn number(text: &str) -> f64 {
    text.parse()
        .unwrap_or_else(|e| panic!("`{text}` is not a number: {e}"))
}

/// The file of a bundled model in this source tree.
fn bundled_file(entry: &eomgen::models::ModelEntry) -> String {
    format!("{}/{}", env!("CARGO_MANIFEST_DIR"), entry.file)
}

/// A bundled model with its reference entry.
struct Case {
    entry: Entry,
    /// Compiled by `eomgen::model!` for the models of `compiled_models`, else the file on
    /// the run-time compiler's interpreter backend (`make_or_interpreted`).
    compiled: Box<dyn ModelInfo + Send>,
    /// Its file, compiled at run time.
    runtime: Box<dyn ModelInfo>,
}

/// Every bundled model with its reference entry (every model has one, and every entry is a
/// bundled model).
fn models() -> Vec<Case> {
    let reference = reference();
    assert_eq!(
        reference.models.len(),
        eomgen::models::ALL.len(),
        "the reference has an entry per bundled model (regenerate it after adding one)"
    );
    let mut entries: Vec<Option<Entry>> = reference.models.into_iter().map(Some).collect();
    eomgen::models::ALL
        .iter()
        .map(|bundled| {
            let entry = entries
                .iter_mut()
                .find(|e| e.as_ref().is_some_and(|e| e.file == bundled.file))
                .and_then(Option::take)
                .unwrap_or_else(|| panic!("{}: no reference entry", bundled.file));
            assert_eq!(entry.name, bundled.name, "{}", bundled.file);
            let path = bundled_file(bundled);
            let runtime = JitModel::load(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
            Case {
                entry,
                compiled: crate::compiled_models::make_or_interpreted(bundled),
                runtime: Box::new(DynFirstOrder::new(runtime)),
            }
        })
        .collect()
}

/// The coefficients of `model` at the entry's `(t, y)` and order.
fn coefficients(entry: &Entry, model: &mut dyn ModelInfo) -> Vec<f64> {
    coefficients_to(entry, model, entry.order, 0.0)
}

/// The coefficients of `model` to `order` at the entry's `(t, y)` moved by `shift`: `t +
/// shift`, `yᵢ + 10⁻³ shift (i + 1)`.
fn coefficients_to(entry: &Entry, model: &mut dyn ModelInfo, order: usize, shift: f64) -> Vec<f64> {
    let t = number(&entry.t) + shift;
    let y: Vec<f64> = entry
        .y
        .iter()
        .enumerate()
        .map(|(i, v)| number(v) + 1e-3 * shift * (i + 1) as f64)
        .collect();
    assert_eq!(y.len(), entry.dim, "{}: y", entry.name);
    assert_eq!(model.num_dofs() * 2, entry.dim, "{}: dim", entry.name);
    let mut out = vec![f64::NAN; (order + 1) * entry.dim];
    model
        .as_ode_mut()
        .taylor_coefficients(t, &y, order, &mut out)
        .unwrap_or_else(|e| panic!("{}: {e}", entry.name));
    out
}

/// The allowed error of an order-`k` coefficient, relative to `1 + |c|` with `|c|` the
/// largest reference coefficient of that order (the order's scale: a component that is small
/// by cancellation carries the rounding error of the order's large terms):
/// `1e-14 · (1 + k) · 3^(k/2)`.
///
/// Order `k` is a sum of `O(k)` products of lower orders, each carrying their own error; for
/// most models the measured error stays below 1.2e-14 up to order 12, but `heavy_top` (spin
/// 100 rad/s, the large `φ̇` and `ψ̇` series cancel in the conserved spin) grows about ×3 per
/// two orders: 1.6e-14 at order 5, 3.7e-13 at 8, 1.4e-11 at 12. The same series arithmetic
/// run in 53-bit mpmath by `tools/taylor_reference.py` shows the same growth there
/// (6.7e-11 at order 12), so it is the state's conditioning, not the recurrences. The bound
/// (3.5e-14 at order 1, 7.3e-12 at 8, 9.5e-11 at 12) keeps a margin of ~7 over that worst
/// case and is still far below an error of the recurrences (a wrong term is wrong at order
/// one).
fn tolerance(k: usize) -> f64 {
    1e-14 * (1 + k) as f64 * 3f64.powf(k as f64 / 2.0)
}

#[test]
fn coefficients_agree_with_the_high_precision_reference() {
    let mut worst = Vec::<(f64, String)>::new();
    let mut checked = 0;
    for Case {
        entry,
        mut compiled,
        mut runtime,
    } in models()
    {
        if entry.skip.is_some() {
            continue;
        }
        let reference: Vec<f64> = entry.coefficients.iter().map(|c| number(c)).collect();
        assert_eq!(reference.len(), (entry.order + 1) * entry.dim);
        for (how, model) in [
            ("compiled", compiled.as_mut() as &mut dyn ModelInfo),
            ("run time", runtime.as_mut()),
        ] {
            if how == "compiled"
                && entry.constraints > 0
                && model.as_ode().taylor_support().is_err()
            {
                // `model!`'s code has no recurrences for constraints (checked below).
                continue;
            }
            let got = coefficients(&entry, model);
            for k in 0..=entry.order {
                let row = k * entry.dim..(k + 1) * entry.dim;
                let scale = 1.0
                    + reference[row.clone()]
                        .iter()
                        .fold(0.0, |m, c| c.abs().max(m));
                for i in 0..entry.dim {
                    let (c, r) = (got[row.start + i], reference[row.start + i]);
                    let error = (c - r).abs() / scale;
                    assert!(
                        error <= tolerance(k),
                        "{} ({how}): order {k}, component {i}: {c:e}, reference {r:e}: \
                         error {error:.2e} · (1 + {:.3e}) > tolerance {:.2e}",
                        entry.name,
                        scale - 1.0,
                        tolerance(k)
                    );
                    if worst.len() <= k {
                        worst.resize(k + 1, (0.0, String::new()));
                    }
                    if error >= worst[k].0 {
                        worst[k] = (error, format!("{} [{i}]", entry.name));
                    }
                }
            }
        }
        checked += 1;
    }
    for (k, (error, at)) in worst.iter().enumerate() {
        println!(
            "order {k:2}: worst error {error:.2e} (tolerance {:.2e}) at {at}",
            tolerance(k)
        );
    }
    assert!(checked >= 30, "only {checked} models have coefficients");
}

#[test]
fn compiled_and_run_time_coefficients_are_bit_identical() {
    for Case {
        entry,
        mut compiled,
        mut runtime,
    } in models()
    {
        if entry.skip.is_some() || compiled.as_ode().taylor_support().is_err() {
            continue;
        }
        // The reference's order, then orders that cross the code compiled for each order
        // (the compiled model's fused orders end at its `highest_unrolled_order`, at most
        // 23) and the switches of the workspace's stride, through one workspace each, at a
        // state that moves from call to call (what an earlier call left in the workspace
        // must not show).
        let orders = [
            entry.order,
            1,
            2,
            3,
            5,
            8,
            13,
            17,
            18,
            21,
            24,
            25,
            30,
            12,
            0,
            7,
            23,
        ];
        // The run-time model's orders by the runtime's kernels (`runtime`: fewer series than
        // it computes before compiling them) and compiled to native code from the first
        // series (`native`).
        let path = bundled_file(
            eomgen::models::ALL
                .iter()
                .find(|m| m.file == entry.file)
                .expect("a bundled model"),
        );
        let options = LoadOptions {
            eager_taylor: true,
            ..LoadOptions::default()
        };
        let native = JitModel::load_with(&path, options).unwrap_or_else(|e| panic!("{path}: {e}"));
        let mut native: Box<dyn ModelInfo> = Box::new(DynFirstOrder::new(native));
        for (shift, order) in orders.into_iter().enumerate() {
            let shift = shift as f64;
            let a = coefficients_to(&entry, compiled.as_mut(), order, shift);
            for (how, model) in [("run time", &mut runtime), ("native orders", &mut native)] {
                let b = coefficients_to(&entry, model.as_mut(), order, shift);
                for (j, (x, y)) in a.iter().zip(&b).enumerate() {
                    assert_eq!(
                        x.to_bits(),
                        y.to_bits(),
                        "{} to order {order}: order {}, component {}: compiled {x:e}, {how} {y:e}",
                        entry.name,
                        j / entry.dim,
                        j % entry.dim
                    );
                }
            }
        }
    }
}

#[test]
fn models_without_coefficients_say_why() {
    for Case {
        entry,
        compiled,
        runtime,
    } in models()
    {
        let source = eomgen::models::ALL
            .iter()
            .find(|m| m.file == entry.file)
            .map(|m| m.source())
            .unwrap_or_default();
        for (how, support) in [
            ("compiled", compiled.taylor_support()),
            ("run time", runtime.taylor_support()),
        ] {
            let name = &entry.name;
            match (&entry.skip, support) {
                (None, Ok(())) => {}
                // Only `model!`'s code lacks the recurrences of constraints.
                (_, Err(TaylorUnsupported::Constraints { count })) => {
                    assert_eq!(how, "compiled", "{name}");
                    assert_eq!(count, entry.constraints, "{name} ({how}): constraints");
                    assert!(count > 0, "{name} ({how})");
                }
                (None, Err(e)) => panic!("{name} ({how}): the reference has coefficients: {e}"),
                // The reference cannot read equations too long to print.
                (Some(reason), Ok(())) if reason.contains("too long to print") => {}
                (Some(reason), Ok(())) => {
                    panic!("{name} ({how}): has recurrences, the reference skips it: {reason}")
                }
                (Some(_), Err(TaylorUnsupported::Functions { names })) => {
                    let got: BTreeSet<&str> = names.iter().map(|n| n.as_ref()).collect();
                    let want: BTreeSet<&str> = entry.functions.iter().map(String::as_str).collect();
                    assert_eq!(got, want, "{name} ({how}): functions");
                    for function in &want {
                        assert!(
                            ["abs", "sign", "step"].contains(function)
                                && source.contains(&format!("{function}(")),
                            "{name} ({how}): `{function}` is not a function of its file"
                        );
                    }
                }
                (Some(reason), Err(e)) => {
                    panic!("{name} ({how}): {e}; the reference skips it: {reason}")
                }
            }
        }
    }
}

/// The sines and cosines of angle differences that the equations form by the addition
/// theorems (`sin θ₁ cos θ₂ − cos θ₁ sin θ₂`, …) run at orders ≥ 1 as one `sin_cos` of the
/// difference: no product of two sines or cosines is left in the chains' programs, each pair
/// of angles has a `sin_cos` of its difference, and (above) the coefficients still agree with
/// the reference computed from the equations as they stand.
#[test]
fn angle_differences_run_as_one_sin_cos() {
    use eomgen::DynMechanicalSystem;
    use eomgen::taylor::SeriesOp;
    for (file, pairs) in [("double_pendulum", 1), ("triple_pendulum", 3)] {
        let path = format!("{}/models/{file}.yaml", env!("CARGO_MANIFEST_DIR"));
        let model = JitModel::load(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        let program = model.taylor().expect("recurrences").program();
        let trig: BTreeSet<u32> = program
            .ops
            .iter()
            .filter_map(|op| match *op {
                SeriesOp::SinCos { sin, cos, .. } => Some([sin, cos]),
                _ => None,
            })
            .flatten()
            .collect();
        let products = program
            .ops
            .iter()
            .filter(|op| matches!(**op, SeriesOp::Mul { a, b, .. } if trig.contains(&a) && trig.contains(&b)))
            .count();
        assert_eq!(products, 0, "{file}: products of sines and cosines left");
        let differences = program
            .ops
            .iter()
            .filter(|op| match **op {
                SeriesOp::SinCos { a, .. } => program.ops.iter().any(|other| {
                    matches!(*other, SeriesOp::Sub { out, a: x, b: y }
                        if out == a && program.coordinates.contains(&Some(x))
                            && program.coordinates.contains(&Some(y)))
                }),
                _ => false,
            })
            .count();
        assert_eq!(
            differences, pairs,
            "{file}: sin_cos of coordinate differences"
        );
    }
}

/// The run-time model's Taylor orders and their order 0, compiled to native code, against
/// the runtime's kernels and tape interpreter (the interpreter backend), to the bit, on
/// fixtures that use every op kind (`exp`, `ln`, `sinh`/`cosh`, `tan`, `tanh`, `asin`,
/// `acos`, `atan`, `atan2`, powers, roots, quotients: the bundled models use only some), a
/// mass matrix that varies (dense, diagonal, and with zeros below its factor's diagonal, which
/// the compiled orders solve in line, the zeros skipped; and the last with seven coordinates,
/// more than they solve in line, solved by their call per order), and functions without a
/// recurrence applied to parameters alone (constants of order 0); and the orders really are
/// compiled (`TaylorFunctions::fused_orders` after the first series: a failure of Cranelift would
/// leave them to the kernels and this comparison would prove nothing). Then again with every
/// parameter changed on both models after the code was compiled: the compiled code reads
/// the parameters at each call (a value baked in at compilation would show here), and the
/// coefficients must change.
#[test]
fn compiled_orders_of_every_op_kind_are_the_kernels_bits() {
    use eomgen::{Backend, DynMechanicalSystem, OdeSystem};
    for file in [
        "taylor_ops_dense",
        "taylor_ops_diagonal",
        "taylor_ops_sparse",
        "taylor_ops_large_sparse",
        "taylor_order_zero_constants",
    ] {
        let path = format!("{}/tests/fixtures/{file}.yaml", env!("CARGO_MANIFEST_DIR"));
        let load =
            |options| JitModel::load_with(&path, options).unwrap_or_else(|e| panic!("{path}: {e}"));
        let native = load(LoadOptions {
            eager_taylor: true,
            ..LoadOptions::default()
        });
        let highest = native
            .taylor()
            .expect("recurrences")
            .program()
            .highest_unrolled_order();
        assert!(highest > 0, "{file}: no order fits the cache");
        let mut kernels = DynFirstOrder::new(load(LoadOptions {
            backend: Some(Backend::Interpreter),
            ..LoadOptions::default()
        }));
        let handle = native.clone();
        let mut native = DynFirstOrder::new(native);
        let y0 = ModelInfo::initial_state(&native);
        let mut before = Vec::new();
        for pass in 0..2 {
            if pass == 1 {
                let names: Vec<String> = native
                    .description()
                    .parameter_names()
                    .into_iter()
                    .map(str::to_owned)
                    .collect();
                assert!(!names.is_empty(), "{file}: no parameters");
                for (name, value) in names.iter().zip(native.parameter_values()) {
                    native.set_parameter(name, 1.25 * value).unwrap();
                    kernels.set_parameter(name, 1.25 * value).unwrap();
                }
            }
            let mut coefficients = Vec::new();
            for (shift, order) in [12, 1, 2, 5, 8, 13, 17, 23, 24, 25, 30, 0, 7]
                .into_iter()
                .enumerate()
            {
                let t = 0.1 * shift as f64;
                // The file's initial state, moved from call to call.
                let y: Vec<f64> = y0
                    .iter()
                    .enumerate()
                    .map(|(i, v)| v + 1e-2 * (shift * (i + 1)) as f64)
                    .collect();
                let dim = y.len();
                let mut a = vec![f64::NAN; (order + 1) * dim];
                let mut b = a.clone();
                native
                    .taylor_coefficients(t, &y, order, &mut a)
                    .unwrap_or_else(|e| panic!("{file}: {e}"));
                kernels
                    .taylor_coefficients(t, &y, order, &mut b)
                    .unwrap_or_else(|e| panic!("{file}: {e}"));
                for (j, (x, z)) in a.iter().zip(&b).enumerate() {
                    assert_eq!(
                        x.to_bits(),
                        z.to_bits(),
                        "{file} to order {order}: order {}, component {}: compiled {x:e}, kernels {z:e}",
                        j / dim,
                        j % dim
                    );
                }
                assert_eq!(
                    handle.taylor().map_or(0, |t| t.fused_orders()),
                    highest.min(24),
                    "{file}: the orders are not compiled"
                );
                coefficients.push(a);
            }
            if pass == 1 {
                assert_ne!(
                    coefficients, before,
                    "{file}: the parameters changed nothing"
                );
            }
            before = coefficients;
        }
    }
}

/// Every bundled model's compiled orders, and the panel's model files' (loaded with
/// `eager_taylor`: compiled by Cranelift from the first series, independent ops of one kind
/// paired in the two lanes of a vector), compute the runtime's kernels' bits (the interpreter
/// backend's series) at orders across the compiled ones, from three states. The figure eight
/// pairs 36 of its 40 ops, the Kepler orbit 8 of 10 (`jit/src/taylor/pairing.rs`).
#[test]
fn every_models_compiled_orders_are_the_kernels_bits() {
    use eomgen::{Backend, DynMechanicalSystem, OdeSystem};
    let root = env!("CARGO_MANIFEST_DIR");
    let mut files: Vec<String> = eomgen::models::ALL
        .iter()
        .map(|m| format!("{root}/{}", m.file))
        .collect();
    files.push(format!("{root}/tools/panel/kepler_e09.yaml"));
    files.push(format!("{root}/tools/panel/five_link_chain.yaml"));
    let mut compiled = 0;
    for path in &files {
        let load =
            |options| JitModel::load_with(path, options).unwrap_or_else(|e| panic!("{path}: {e}"));
        let native = load(LoadOptions {
            eager_taylor: true,
            ..LoadOptions::default()
        });
        let Ok(taylor) = native.taylor() else {
            continue;
        };
        let highest = taylor.program().highest_unrolled_order();
        if highest == 0 || taylor.program().multipliers() > 0 && path.contains("bicycle") {
            continue;
        }
        compiled += 1;
        let mut native = DynFirstOrder::new(native);
        let mut kernels = DynFirstOrder::new(load(LoadOptions {
            backend: Some(Backend::Interpreter),
            ..LoadOptions::default()
        }));
        let y0 = ModelInfo::initial_state(&native);
        for (shift, order) in [highest + 1, 3, highest.min(12)].into_iter().enumerate() {
            let y: Vec<f64> = y0
                .iter()
                .enumerate()
                .map(|(i, v)| v + 1e-2 * ((shift + 1) * (i + 1)) as f64)
                .collect();
            let dim = y.len();
            let (mut a, mut b) = (
                vec![f64::NAN; (order + 1) * dim],
                vec![f64::NAN; (order + 1) * dim],
            );
            let (x, z) = (
                native.taylor_coefficients(0.1, &y, order, &mut a),
                kernels.taylor_coefficients(0.1, &y, order, &mut b),
            );
            assert_eq!(
                x.is_ok(),
                z.is_ok(),
                "{path} to order {order}: {x:?} against {z:?}"
            );
            for (j, (x, z)) in a.iter().zip(&b).enumerate() {
                assert_eq!(
                    x.to_bits(),
                    z.to_bits(),
                    "{path} to order {order}: order {}, component {}: compiled {x:e}, kernels {z:e}",
                    j / dim,
                    j % dim
                );
            }
        }
    }
    assert!(
        compiled >= 30,
        "only {compiled} models have compiled orders"
    );
}

/// The Taylor method's copy of its code for AVX2 and FMA (`eomgen::taylor::host_features`:
/// the runtime's series of the motion, Horner's rule and step rule and, in an optimised
/// build, each model's fused orders) computes the bits of the code for any x86-64: the
/// coefficients of every bundled model, compiled by `model!` (or interpreted) and loaded from
/// its file, at orders across
/// the fused ones, and whole Taylor runs of the double pendulum and the figure eight, with
/// the copy turned off and on. A debug build has no fused orders to compare; `cargo test
/// --release --test suite taylor_coefficients::` compares them too. On a processor without AVX2 and
/// FMA (or not x86-64) both runs take the same code and the test only checks that turning
/// the copy off changes nothing.
#[test]
fn the_code_for_the_hosts_instruction_sets_computes_the_same_bits() {
    use eomgen::analysis::{SimulationOptions, simulate};
    use eomgen::taylor::{host_features, set_host_features};
    // The switch itself: off when turned off, and what the processor has when turned on.
    set_host_features(false);
    assert!(!host_features());
    set_host_features(true);
    #[cfg(target_arch = "x86_64")]
    let expected = std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma");
    #[cfg(not(target_arch = "x86_64"))]
    let expected = false;
    assert_eq!(host_features(), expected);
    let bits = |v: &[f64]| -> Vec<u64> { v.iter().map(|x| x.to_bits()).collect() };
    let mut compared = 0;
    for Case {
        entry,
        mut compiled,
        mut runtime,
    } in models()
    {
        if entry.skip.is_some() {
            continue;
        }
        for order in [entry.order, 3, 8, 17, 24] {
            let models: [(&str, &mut dyn ModelInfo); 2] =
                [("compiled", compiled.as_mut()), ("file", runtime.as_mut())];
            for (how, model) in models {
                if model.as_ode().taylor_support().is_err() {
                    // `model!`'s code of a constrained model (no recurrences).
                    continue;
                }
                set_host_features(false);
                let baseline = coefficients_to(&entry, model, order, 0.5);
                set_host_features(true);
                let host = coefficients_to(&entry, model, order, 0.5);
                assert!(
                    bits(&baseline) == bits(&host),
                    "{} ({how}) to order {order}: the two copies' coefficients differ",
                    entry.name
                );
                compared += 1;
            }
        }
    }
    assert!(compared >= 35 * 10, "{compared} comparisons");
    let runs: Vec<_> = eomgen::models::ALL
        .iter()
        .filter(|m| ["double_pendulum", "figure_eight"].contains(&m.name))
        .collect();
    assert_eq!(
        runs.len(),
        2,
        "the two models of the whole runs are bundled"
    );
    for entry in runs {
        let run = |tol: f64| {
            let mut model = crate::compiled_models::make(entry.name).expect("compiled by model!");
            let options = SimulationOptions {
                method: eomgen::Method::Taylor,
                t_end: 5.0,
                rtol: tol,
                atol: tol,
                ..SimulationOptions::default()
            };
            let s = simulate(model.as_mut(), &options).expect("the simulation starts");
            assert!(s.failure.is_none(), "{}: {:?}", entry.name, s.failure);
            (s.solution.t, s.solution.y)
        };
        for tol in [1e-4, 1e-9, 1e-14] {
            set_host_features(false);
            let (t0, y0) = run(tol);
            set_host_features(true);
            let (t1, y1) = run(tol);
            assert!(
                bits(&t0) == bits(&t1) && bits(&y0) == bits(&y1),
                "{} at tol {tol}: the two copies' runs differ",
                entry.name
            );
        }
    }
}

/// A run-time model's Taylor orders are compiled once `COMPILE_TAYLOR_AFTER` series have
/// been computed by the kernels, not before; and every series before and after computes the
/// same bits.
#[test]
fn the_orders_are_compiled_after_the_kernels_series_with_the_same_bits() {
    use eomgen::{COMPILE_TAYLOR_AFTER, DynMechanicalSystem, OdeSystem};
    let path = format!("{}/models/double_pendulum.yaml", env!("CARGO_MANIFEST_DIR"));
    let model = JitModel::load(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let handle = model.clone();
    let fused = || handle.taylor().map_or(0, |t| t.fused_orders());
    let mut model = DynFirstOrder::new(model);
    let y = ModelInfo::initial_state(&model);
    let order = 12;
    let mut series = || {
        let mut out = vec![f64::NAN; (order + 1) * y.len()];
        model
            .taylor_coefficients(0.3, &y, order, &mut out)
            .expect("coefficients");
        out.iter().map(|v| v.to_bits()).collect::<Vec<u64>>()
    };
    let first = series();
    for _ in 1..COMPILE_TAYLOR_AFTER {
        assert_eq!(series(), first, "a series by the kernels");
    }
    assert_eq!(fused(), 0, "compiled before the series asked for it");
    assert_eq!(series(), first, "the series that compiles the orders");
    assert!(
        fused() > 0,
        "not compiled after {COMPILE_TAYLOR_AFTER} series"
    );
    assert_eq!(series(), first, "a series by the compiled orders");
}

/// A constant mass matrix is factored once and its factors reused while its entries keep
/// their bits: after a parameter changes `M` (the figure eight's `M = m I`), the series of the
/// same instance equal a fresh instance's to the bit, and differ from those before the change
/// (so stale factors would fail this).
#[test]
fn a_constant_mass_matrix_is_factored_again_when_a_parameter_changes_it() {
    use eomgen::OdeSystem;
    let path = format!("{}/models/figure_eight.yaml", env!("CARGO_MANIFEST_DIR"));
    let load =
        || DynFirstOrder::new(JitModel::load(&path).unwrap_or_else(|e| panic!("{path}: {e}")));
    let order = 10;
    let series = |model: &mut DynFirstOrder<JitModel>, y: &[f64]| {
        let mut out = vec![f64::NAN; (order + 1) * y.len()];
        model
            .taylor_coefficients(0.0, y, order, &mut out)
            .expect("the series");
        out
    };
    let mut model = load();
    let y = ModelInfo::initial_state(&model);
    let before = series(&mut model, &y);
    assert_eq!(series(&mut model, &y), before, "the reused factors");
    model.set_parameter("m", 2.0).expect("m");
    let after = series(&mut model, &y);
    let mut fresh = load();
    fresh.set_parameter("m", 2.0).expect("m");
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&after), bits(&series(&mut fresh, &y)));
    assert_ne!(bits(&after), bits(&before));
}

/// One workspace serving a model with a constant `M`, then one whose `M` varies (the same
/// number of coordinates), then the first again: the first's series equal those of a fresh
/// workspace to the bit (the second's factors are not taken for the first's).
#[test]
fn a_workspace_shared_by_two_models_never_reuses_the_others_factors() {
    use eomgen::DynMechanicalSystem;
    use eomgen::taylor::{TaylorWorkspace, series_of_motion};
    let kepler = JitModel::from_source(
        "kepler.yaml",
        "name: kepler\nparameters: { mu: 1.0 }\ncoordinates: [x, y]\n\
         kinetic: (x_dot^2 + y_dot^2)/2\npotential: -mu/sqrt(x^2 + y^2)\n\
         initial: { x: 0.1, y_dot: 4.0 }\n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let path = format!("{}/models/double_pendulum.yaml", env!("CARGO_MANIFEST_DIR"));
    let pendulum = JitModel::load(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let order = 8;
    let run = |model: &JitModel, workspace: &mut TaylorWorkspace, y: &[f64]| {
        let mut out = vec![f64::NAN; (order + 1) * 4];
        let taylor = model.taylor().expect("recurrences");
        series_of_motion(taylor, workspace, 0.0, y, order, &mut out).expect("the series");
        out.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    };
    let (yk, yp) = ([0.1, 0.0, 0.0, 4.0], [0.3, 1.2, -0.5, 0.7]);
    let mut shared = TaylorWorkspace::new();
    let first = run(&kepler, &mut shared, &yk);
    run(&pendulum, &mut shared, &yp);
    assert_eq!(run(&kepler, &mut shared, &yk), first);
    assert_eq!(run(&kepler, &mut TaylorWorkspace::new(), &yk), first);
}
