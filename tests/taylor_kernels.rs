//! Each Taylor-recurrence kernel of `eomgen::taylor` against independent high-precision series,
//! `tests/data/taylor_kernels.json`, written by `tools/taylor_kernel_reference.py` (see its
//! docstring to regenerate it).
//!
//! The kernels (`runtime/src/taylor/kernels.rs`, reached through [`eomgen::taylor::apply`]) are the
//! recurrences of Jorba & Zou, *A software package for the numerical integration of ODEs by
//! means of high-order Taylor methods*, Exp. Math. 14(1) (2005), §2, with the hidden partners
//! of heyoka's `doc/ad_notes.rst` (Biscani & Izzo 2021). The bundled models rarely reach most
//! of them, so each is checked here on its own: the reference script takes polynomial operands
//! (doubles) and computes the Taylor coefficients of the composed function `f(a(τ))` with
//! mpmath at 50 digits (`mpmath.taylor` of mpmath's own functions, cross-checked by Cauchy's
//! integral formula), sharing nothing with the recurrences.
//!
//! For each case this test fills a workspace with the operands' coefficients and every slot's
//! order 0 (the function values, in `f64`, as a model's order-0 evaluation does), runs the
//! kernel for `k = 1 … 16` in order, and compares every slot the kernel writes (hidden partners
//! included) with the reference within [`tolerance`]. The workspace is poisoned with NaN
//! wherever a kernel must not read: operand orders above `k` (they are written one order at a
//! time), output orders not yet computed, orders above 0 of constant slots, an unused slot and
//! the stride's spare entries; so reading ahead or out of place shows as a NaN coefficient.
//! Two more tests show that the comparison can fail: a perturbed reference coefficient and a
//! kernel of the wrong kind are both rejected.

use std::collections::{BTreeMap, BTreeSet};

use eomgen::taylor::{SeriesOp, Slot, apply, evaluate_order};
use serde::Deserialize;

/// The highest order the reference holds (and the kernels are run to).
const ORDER: usize = 16;

/// The workspace stride, longer than `ORDER + 1` so that a kernel confusing the stride with
/// the order reads a NaN spare entry; the stride of the unrolled kernels, so that
/// `evaluate_order` runs them.
const CAPACITY: usize = eomgen::taylor::UNROLLED_CAPACITY;

/// The reference file, as `tools/taylor_kernel_reference.py` writes it.
#[derive(Deserialize)]
struct Reference {
    /// The highest order of every series (16).
    order: usize,
    cases: Vec<Case>,
}

/// One case of the reference: one op on given operand series, and its outputs' series.
#[derive(Deserialize, Clone)]
struct Case {
    name: String,
    /// The kernel function of `runtime/src/taylor/kernels.rs` the op reaches (`tan_or_tanh`, …).
    kernel: String,
    /// The [`SeriesOp`] variant (`Acos` for `SeriesOp::Asin { acos: true, .. }`).
    op: String,
    /// The operands' coefficients, orders `0 … 16`, doubles written with 17 digits.
    operands: BTreeMap<String, Vec<String>>,
    /// Constants: `exponent` (`PowConstant`), `constant` (the numerator of `ConstantDiv`).
    #[serde(default)]
    constants: BTreeMap<String, String>,
    /// The expected coefficients of every slot the op writes, orders `0 … 16`, 25 digits.
    expected: BTreeMap<String, Vec<String>>,
}

/// Reads the reference file.
fn reference() -> Reference {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/taylor_kernels.json"
    );
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let reference: Reference = serde_json::from_str(&text).expect("taylor_kernels.json");
    assert_eq!(reference.order, ORDER, "the reference's order");
    reference
}

/// Parses decimal strings as doubles.
fn numbers(values: &[String]) -> Vec<f64> {
    values
        .iter()
        .map(|v| v.parse::<f64>().unwrap_or_else(|e| panic!("{v}: {e}")))
        .collect()
}

/// A case laid out in a workspace, ready for its orders `k ≥ 1`.
struct Setup {
    op: SeriesOp,
    /// `s[slot · CAPACITY + i]`, order `i` of `slot`.
    s: Vec<f64>,
    /// The operands by slot, with their coefficients (written one order at a time).
    operands: Vec<(Slot, Vec<f64>)>,
    /// The slots the op writes, by name (`out`, `square`, `sin`, …).
    outputs: BTreeMap<String, Slot>,
}

/// Lays `case` out: slot 0 unused (NaN), then the operands, the constant exponent, the
/// outputs; order 0 of every slot filled (the outputs' with the function values in `f64`), all
/// else NaN.
fn setup(case: &Case) -> Setup {
    let mut names: Vec<String> = vec!["(unused)".into()];
    let mut slot = |name: &str| -> Slot {
        names.push(name.to_string());
        (names.len() - 1) as Slot
    };
    let operand = |name: &str| -> Vec<f64> {
        let values = case
            .operands
            .get(name)
            .unwrap_or_else(|| panic!("{}: no operand {name}", case.name));
        let values = numbers(values);
        assert_eq!(values.len(), ORDER + 1, "{}: operand {name}", case.name);
        values
    };
    let constant = |name: &str| -> f64 {
        let v = case
            .constants
            .get(name)
            .unwrap_or_else(|| panic!("{}: no constant {name}", case.name));
        v.parse().unwrap()
    };
    let mut operands: Vec<(Slot, Vec<f64>)> = Vec::new();
    // (slot, order-0 value) of the constant and output slots.
    let mut zero: Vec<(Slot, f64)> = Vec::new();
    let mut outputs = BTreeMap::new();
    let unary = |operands: &mut Vec<(Slot, Vec<f64>)>, slot: &mut dyn FnMut(&str) -> Slot| {
        let a = operand("a");
        let a0 = a[0];
        let s = slot("a");
        operands.push((s, a));
        (s, a0)
    };
    let op = match case.op.as_str() {
        "Mul" | "Div" => {
            let (a, b) = (operand("a"), operand("b"));
            let v = if case.op == "Mul" {
                a[0] * b[0]
            } else {
                a[0] / b[0]
            };
            let (sa, sb, out) = (slot("a"), slot("b"), slot("out"));
            operands.extend([(sa, a), (sb, b)]);
            zero.push((out, v));
            outputs.insert("out".into(), out);
            if case.op == "Mul" {
                SeriesOp::Mul { out, a: sa, b: sb }
            } else {
                SeriesOp::Div { out, a: sa, b: sb }
            }
        }
        "ConstantDiv" => {
            let b = operand("b");
            let (sb, out) = (slot("b"), slot("out"));
            zero.push((out, constant("constant") / b[0]));
            operands.push((sb, b));
            outputs.insert("out".into(), out);
            SeriesOp::ConstantDiv { out, b: sb }
        }
        "Exp" | "Ln" | "Sqrt" | "PowConstant" => {
            let (a, a0) = unary(&mut operands, &mut slot);
            let out = slot("out");
            let v = match case.op.as_str() {
                "Exp" => a0.exp(),
                "Ln" => a0.ln(),
                "Sqrt" => a0.sqrt(),
                _ => a0.powf(constant("exponent")),
            };
            zero.push((out, v));
            outputs.insert("out".into(), out);
            match case.op.as_str() {
                "Exp" => SeriesOp::Exp { out, a },
                "Ln" => SeriesOp::Ln { out, a },
                "Sqrt" => SeriesOp::Sqrt { out, a },
                _ => {
                    let exponent = slot("exponent");
                    zero.push((exponent, constant("exponent")));
                    SeriesOp::PowConstant { out, a, exponent }
                }
            }
        }
        "SinCos" | "SinhCosh" => {
            let (a, a0) = unary(&mut operands, &mut slot);
            let hyperbolic = case.op == "SinhCosh";
            let (first, second) = if hyperbolic {
                ("sinh", "cosh")
            } else {
                ("sin", "cos")
            };
            let (p, q) = (slot(first), slot(second));
            if hyperbolic {
                zero.extend([(p, a0.sinh()), (q, a0.cosh())]);
            } else {
                zero.extend([(p, a0.sin()), (q, a0.cos())]);
            }
            outputs.insert(first.into(), p);
            outputs.insert(second.into(), q);
            if hyperbolic {
                SeriesOp::SinhCosh {
                    sinh: p,
                    cosh: q,
                    a,
                }
            } else {
                SeriesOp::SinCos { sin: p, cos: q, a }
            }
        }
        "Tan" | "Tanh" => {
            let (a, a0) = unary(&mut operands, &mut slot);
            let (out, square) = (slot("out"), slot("square"));
            let v = if case.op == "Tan" {
                a0.tan()
            } else {
                a0.tanh()
            };
            zero.extend([(out, v), (square, v * v)]);
            outputs.insert("out".into(), out);
            outputs.insert("square".into(), square);
            if case.op == "Tan" {
                SeriesOp::Tan { out, a, square }
            } else {
                SeriesOp::Tanh { out, a, square }
            }
        }
        "Asin" | "Acos" => {
            let (a, a0) = unary(&mut operands, &mut slot);
            let (out, root) = (slot("out"), slot("root"));
            let acos = case.op == "Acos";
            zero.extend([
                (out, if acos { a0.acos() } else { a0.asin() }),
                (root, (1.0 - a0 * a0).sqrt()),
            ]);
            outputs.insert("out".into(), out);
            outputs.insert("root".into(), root);
            SeriesOp::Asin { out, a, root, acos }
        }
        "Atan" => {
            let (a, a0) = unary(&mut operands, &mut slot);
            let (out, square) = (slot("out"), slot("square"));
            zero.extend([(out, a0.atan()), (square, a0 * a0)]);
            outputs.insert("out".into(), out);
            outputs.insert("square".into(), square);
            SeriesOp::Atan { out, a, square }
        }
        "Atan2" => {
            let (y, x) = (operand("y"), operand("x"));
            let (sy, sx, out, norm) = (slot("y"), slot("x"), slot("out"), slot("norm"));
            zero.extend([(out, y[0].atan2(x[0])), (norm, x[0] * x[0] + y[0] * y[0])]);
            operands.extend([(sy, y), (sx, x)]);
            outputs.insert("out".into(), out);
            outputs.insert("norm".into(), norm);
            SeriesOp::Atan2 {
                out,
                y: sy,
                x: sx,
                norm,
            }
        }
        other => panic!("{}: unknown op {other}", case.name),
    };
    let mut s = vec![f64::NAN; names.len() * CAPACITY];
    for (slot, values) in &operands {
        s[*slot as usize * CAPACITY] = values[0];
    }
    for &(slot, v) in &zero {
        s[slot as usize * CAPACITY] = v;
    }
    let written: BTreeSet<&String> = outputs.keys().collect();
    let expected: BTreeSet<&String> = case.expected.keys().collect();
    assert_eq!(
        written, expected,
        "{}: the slots the op writes and the reference's",
        case.name
    );
    Setup {
        op,
        s,
        operands,
        outputs,
    }
}

/// Runs the op of `setup` for `k = 1 … ORDER`, writing each operand's order `k` just before
/// (its higher orders stay NaN), and returns every output's coefficients `0 … ORDER`.
///
/// # Panics
/// If the op changed an operand or wrote beyond order `ORDER` of an output (its spare entries
/// must stay NaN).
fn run(setup: &mut Setup) -> BTreeMap<String, Vec<f64>> {
    // The kernels compiled for any order (`K = 0`) and for each order (`evaluate_order`'s
    // unrolled variants, here for k ≤ 16) must give the same bits.
    let mut unrolled = setup.s.clone();
    let s = &mut setup.s;
    for k in 1..=ORDER {
        for (slot, values) in &setup.operands {
            s[*slot as usize * CAPACITY + k] = values[k];
            unrolled[*slot as usize * CAPACITY + k] = values[k];
        }
        apply::<0>(setup.op, k, CAPACITY, s);
        evaluate_order(&[setup.op], k, CAPACITY, &mut unrolled);
    }
    assert!(
        s.iter()
            .zip(&unrolled)
            .all(|(a, b)| a.to_bits() == b.to_bits()),
        "{:?}: the unrolled kernels differ from the general ones",
        setup.op
    );
    for (slot, values) in &setup.operands {
        let start = *slot as usize * CAPACITY;
        assert!(
            s[start..start + ORDER + 1]
                .iter()
                .zip(values)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "an operand was modified"
        );
    }
    setup
        .outputs
        .iter()
        .map(|(name, &slot)| {
            let start = slot as usize * CAPACITY;
            assert!(
                s[start + ORDER + 1..start + CAPACITY]
                    .iter()
                    .all(|v| v.is_nan()),
                "{name}: written beyond order {ORDER}"
            );
            (name.clone(), s[start..start + ORDER + 1].to_vec())
        })
        .collect()
}

/// The tolerance of order `k`, relative to the scale `max_{i ≤ k} |expected_i|`:
/// `1e-13 (1 + k)`.
///
/// Why: each order is a sum of at most `k + 1` products of earlier coefficients (weighted by
/// `j / k ≤ 1`) divided by an order-0 value, so its rounding error is at most about
/// `(k + 1) u Σ|terms|` (`u = 2⁻⁵³ ≈ 1.1e-16`), and it inherits the errors of the earlier
/// orders, themselves of that size, plus the one-ulp errors of the order-0 function values
/// computed in `f64`. With operands of moderate size whose coefficients decay (so `Σ|terms|`
/// is a small multiple of the scale), that is `(1 + k)` times a few hundred `u` at most;
/// `1e-13 ≈ 900 u` leaves room for that constant without hiding a wrong recurrence, whose
/// errors are of the size of the coefficients themselves (a wrong sign, index or weight moves
/// order 1 or 2 by ~1e-1 of the scale). The reference itself (50 digits, rounded to 25, read
/// as doubles) contributes at most `u` relative.
fn tolerance(k: usize) -> f64 {
    1e-13 * (1 + k) as f64
}

/// The outcome of comparing one series: the largest `error / tolerance` over the orders and
/// where it occurs, and the orders beyond tolerance.
#[derive(Debug)]
struct Comparison {
    /// `max_k |computed_k − expected_k| / (scale_k · tolerance(k))`.
    worst: f64,
    /// The order of `worst`.
    at: usize,
    /// `(k, computed, expected, relative error)` of each order beyond tolerance (or NaN).
    failures: Vec<(usize, f64, f64, f64)>,
}

/// Compares computed with expected coefficients: order `k` passes when
/// `|computed_k − expected_k| ≤ tolerance(k) · max_{i ≤ k} |expected_i|` (and fails if NaN).
fn compare(computed: &[f64], expected: &[f64]) -> Comparison {
    assert_eq!(computed.len(), expected.len());
    let mut scale = 0.0_f64;
    let mut comparison = Comparison {
        worst: 0.0,
        at: 0,
        failures: Vec::new(),
    };
    for (k, (&c, &e)) in computed.iter().zip(expected).enumerate() {
        scale = scale.max(e.abs());
        let relative = (c - e).abs() / scale;
        // A NaN (a kernel that read a poisoned entry) counts as infinitely wrong.
        let ratio = match relative / tolerance(k) {
            r if r.is_nan() => f64::INFINITY,
            r => r,
        };
        if ratio > 1.0 {
            comparison.failures.push((k, c, e, relative));
        }
        if ratio > comparison.worst {
            comparison.worst = ratio;
            comparison.at = k;
        }
    }
    comparison
}

/// The ops the reference must cover, as the `op` names of its cases (`Acos` is
/// `Asin { acos: true }`): the kernels the bundled models rarely exercise, so that dropping a
/// case from the data fails the test.
const COVERED: [&str; 15] = [
    "Mul",
    "Div",
    "ConstantDiv",
    "Exp",
    "Ln",
    "Sqrt",
    "PowConstant",
    "SinCos",
    "SinhCosh",
    "Tan",
    "Tanh",
    "Asin",
    "Acos",
    "Atan",
    "Atan2",
];

/// Every kernel's outputs (and hidden partners) agree with the mpmath reference within
/// [`tolerance`] at orders `0 … 16`, for every case of `tests/data/taylor_kernels.json`; prints
/// each kernel's largest error relative to its tolerance (`--nocapture`). Recurrences: Jorba &
/// Zou (2005) §2, heyoka's `doc/ad_notes.rst`.
#[test]
fn kernels_match_mpmath_reference() {
    let reference = reference();
    let ops: BTreeSet<&str> = reference.cases.iter().map(|c| c.op.as_str()).collect();
    for op in COVERED {
        assert!(ops.contains(op), "no case for {op}");
    }
    let mut failures = Vec::new();
    // kernel -> (worst ratio, where)
    let mut by_kernel: BTreeMap<String, (f64, String)> = BTreeMap::new();
    for case in &reference.cases {
        let mut setup = setup(case);
        let computed = run(&mut setup);
        for (name, values) in &computed {
            let expected = numbers(&case.expected[name]);
            let comparison = compare(values, &expected);
            println!(
                "{:<32} {:<7} worst error/tolerance {:.3e} at order {}",
                case.name, name, comparison.worst, comparison.at
            );
            let entry = by_kernel
                .entry(case.kernel.clone())
                .or_insert((0.0, String::new()));
            if comparison.worst >= entry.0 {
                *entry = (
                    comparison.worst,
                    format!("{}.{name}, order {}", case.name, comparison.at),
                );
            }
            for (k, c, e, relative) in comparison.failures {
                failures.push(format!(
                    "{}.{name} order {k}: computed {c:e}, expected {e:e}, error {relative:.3e} of \
                     the scale > tolerance {:.1e}",
                    case.name,
                    tolerance(k)
                ));
            }
        }
    }
    println!("largest error / tolerance per kernel:");
    for (kernel, (worst, at)) in &by_kernel {
        println!("  {kernel:<13} {worst:.3e} ({at})");
    }
    assert!(
        failures.is_empty(),
        "{} coefficient(s) beyond tolerance:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The comparison can fail: for every case and output, the reference with its largest
/// coefficient of order `k ≥ 1` moved by `1e-10` relative is rejected (the tolerance is at
/// most `1.7e-12` of the scale), while the unperturbed reference passes.
#[test]
fn perturbed_reference_is_rejected() {
    for case in &reference().cases {
        let computed = run(&mut setup(case));
        for (name, values) in &computed {
            let expected = numbers(&case.expected[name]);
            assert!(
                compare(values, &expected).failures.is_empty(),
                "{}.{name}",
                case.name
            );
            let k = (1..=ORDER)
                .max_by(|&i, &j| expected[i].abs().total_cmp(&expected[j].abs()))
                .unwrap();
            let mut wrong = expected.clone();
            wrong[k] *= 1.0 + 1e-10;
            let comparison = compare(values, &wrong);
            assert!(
                comparison.failures.iter().any(|f| f.0 == k),
                "{}.{name}: a 1e-10 change of order {k} passed ({comparison:?})",
                case.name
            );
        }
    }
}

/// A kernel of the wrong kind fails the comparison: `tan` run as `tanh`, `sin_cos` as
/// `sinh_cosh` and `asin` as `acos` (each a sign in the recurrences of Jorba & Zou §2) are
/// rejected, so a sign error in a kernel would be caught.
#[test]
fn wrong_kernel_is_rejected() {
    let reference = reference();
    let mut checked = 0;
    for case in &reference.cases {
        let mut setup = setup(case);
        setup.op = match setup.op {
            SeriesOp::Tan { out, a, square } => SeriesOp::Tanh { out, a, square },
            SeriesOp::SinCos { sin, cos, a } => SeriesOp::SinhCosh {
                sinh: sin,
                cosh: cos,
                a,
            },
            SeriesOp::Asin {
                out,
                a,
                root,
                acos: false,
            } => SeriesOp::Asin {
                out,
                a,
                root,
                acos: true,
            },
            _ => continue,
        };
        let computed = run(&mut setup);
        let rejected = computed.iter().any(|(name, values)| {
            !compare(values, &numbers(&case.expected[name]))
                .failures
                .is_empty()
        });
        assert!(rejected, "{}: the wrong kernel passed", case.name);
        checked += 1;
    }
    assert!(checked >= 3, "only {checked} cases had a counterpart");
}
