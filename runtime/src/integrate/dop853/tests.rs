//! The unit tests of `dop853.rs`.

use super::*;
use crate::integrate::tableau::tests::{assert_tree_order, tree_residuals};
use crate::ode::OdeFn;

/// The extended tableau as full rows (16 × 16).
fn full_a() -> Vec<Vec<f64>> {
    (0..EXTENDED_STAGES)
        .map(|i| {
            let mut row = vec![0.0; EXTENDED_STAGES];
            row[..A[i].len()].copy_from_slice(A[i]);
            row
        })
        .collect()
}

/// Exactly the stages before row `UNWEIGHTED_ROWS` of `k` have no weight in `b`, in the
/// fifth-order and in the third-order estimate.
#[test]
fn unweighted_rows_are_the_stages_without_any_weight() {
    for j in 1..STAGES {
        let third = B_THIRD.iter().any(|&(s, _)| s == j);
        let without = B[j] == 0.0 && ERROR_FIFTH[j] == 0.0 && !third;
        assert_eq!(without, j - 1 < UNWEIGHTED_ROWS, "stage {j}");
    }
}

/// A NaN in stage 2 (`c₂ = 0.0789…`, no weight anywhere) is found by the check of the
/// unweighted rows, at its time, with compiled (4) and general (3) stages; `F` ignores
/// `y`, so nothing else could show it.
#[test]
fn a_non_finite_stage_without_weight_is_still_reported() {
    for dim in [3, 4] {
        let mut system = OdeFn::new(dim, |t: f64, _y: &[f64], dy: &mut [f64]| {
            let window = t > 0.0788 && t < 0.0790;
            dy.fill(if window { f64::NAN } else { 1.0 });
        });
        let mut rhs = CheckedRhs::new(&mut system);
        let mut stepper = Dop853Stepper::new(dim);
        stepper.reset(&mut rhs, 0.0, &vec![0.0; dim]).unwrap();
        let weights = ErrorWeights::uniform(dim, 1e-6, 1e-6);
        match stepper.attempt(&mut rhs, 1.0, &weights, true).unwrap_err() {
            StepFailure::Rhs {
                t,
                error: crate::ode::RhsError::NonFinite { index: 0 },
            } => assert!((t - C[2]).abs() < 1e-15, "t = {t}"),
            other => panic!("{other:?}"),
        }
        stepper.reset(&mut rhs, 2.0, &vec![0.0; dim]).unwrap();
        assert!(stepper.attempt(&mut rhs, 3.0, &weights, true).is_ok());
    }
}

/// Residual bound of the order conditions: the coefficients carry 30 digits but are
/// rounded to f64, and |bᵢ| ≤ 6 with |aᵢⱼ| ≤ 44, so a condition sums ~12 terms of size
/// up to ~10 rounded at 1e-16: 1e-13 leaves margin, while an order condition that fails
/// is off by at least ~1e-4 here.
const TOLERANCE: f64 = 1e-13;

#[test]
fn rows_sum_to_the_nodes() {
    for (i, row) in A.iter().enumerate() {
        assert_eq!(row.len(), i);
        let sum: f64 = row.iter().sum();
        assert!((sum - C[i]).abs() < 1e-14, "row {i}: {sum} vs {}", C[i]);
    }
}

/// Σ b = 1 … all 200 conditions of the trees up to order 8; the fifth-order embedded
/// weights b − ER satisfy the 17 conditions up to order 5, the third-order ones (BHH)
/// the 4 up to order 3, and neither has one order more.
#[test]
fn weights_have_orders_8_5_and_3() {
    let a = full_a();
    let pad = |w: &[f64]| {
        let mut padded = vec![0.0; EXTENDED_STAGES];
        padded[..w.len()].copy_from_slice(w);
        padded
    };
    assert_tree_order("dop853", &a, &pad(&B), 8, TOLERANCE, false);
    let fifth: Vec<f64> = B.iter().zip(&ERROR_FIFTH).map(|(b, e)| b - e).collect();
    assert_tree_order("dop853 fifth", &a, &pad(&fifth), 5, TOLERANCE, true);
    let mut third = vec![0.0; EXTENDED_STAGES];
    for &(j, w) in &B_THIRD {
        third[j] = w;
    }
    assert_tree_order("dop853 third", &a, &third, 3, TOLERANCE, true);
}

/// The weights `bᵢ(θ)` of `y₀ + h Σ bᵢ(θ) kᵢ` that the dense output computes (expanding
/// `CONTD8` over the sixteen stages; stage 12 is `F` at the step's end).
fn dense_weights(theta: f64) -> Vec<f64> {
    let t1 = 1.0 - theta;
    // y − y₀ = θΔ + θ(1−θ)(h f₀ − Δ) + θ²(1−θ)(2Δ − h(f₁ + f₀)) + Σᵣ pᵣ(θ) h dᵣ·k
    let delta = theta - theta * t1 + 2.0 * theta * theta * t1;
    let p = [
        theta * theta * t1 * t1,
        theta.powi(3) * t1 * t1,
        theta.powi(3) * t1.powi(3),
        theta.powi(4) * t1.powi(3),
    ];
    (0..EXTENDED_STAGES)
        .map(|i| {
            let mut w = if i < STAGES { delta * B[i] } else { 0.0 };
            if i == 0 {
                w += theta * t1 - theta * theta * t1;
            }
            if i == STAGES {
                w -= theta * theta * t1;
            }
            w + (0..4).map(|r| p[r] * DENSE[r][i]).sum::<f64>()
        })
        .collect()
}

/// The continuous extension has order 7: `Σ bᵢ(θ) Φᵢ(τ) = θ^|τ|/γ(τ)` for the 115 trees
/// up to order 7 at every θ (this checks `d` and the three extra stages together).
#[test]
fn dense_output_has_order_7() {
    let a = full_a();
    for k in 1..10 {
        let theta = f64::from(k) / 10.0;
        let weights = dense_weights(theta);
        for (o, residual) in tree_residuals(&a, &weights, 7, theta) {
            assert!(
                residual.abs() < TOLERANCE,
                "θ = {theta}, order {o}: {residual:e}"
            );
        }
    }
}

/// A nonlinear, non-autonomous test system of `dim` components (every component is
/// coupled to the next, so no error sum vanishes by symmetry).
fn coupled(dim: usize) -> OdeFn<impl FnMut(f64, &[f64], &mut [f64])> {
    OdeFn::new(dim, |t: f64, y: &[f64], dy: &mut [f64]| {
        for i in 0..y.len() {
            dy[i] = (1.3 * y[(i + 1) % y.len()]).sin() - 0.2 * y[i] + (t * (1.0 + i as f64)).cos();
        }
    })
}

/// The stages compiled for 2, 4, 6 and 8 components equal the general ones (any dimension,
/// in blocks of four) to the bit: every stage, the increment, the candidate and the
/// fifth-order error sum (which both leave in `scratch`).
#[test]
fn the_compiled_stages_equal_the_general_ones_to_the_bit() {
    fn check<const D: usize>() {
        let mut system = coupled(D);
        let mut rhs = CheckedRhs::new(&mut system);
        let y0: Vec<f64> = (0..D).map(|i| 0.3 + 0.1 * i as f64).collect();
        let times = AttemptTimes::new(0.2, 0.45);
        let mut compiled = Dop853Stepper::new(D);
        let mut general = Dop853Stepper::new(D);
        compiled.reset(&mut rhs, 0.2, &y0).unwrap();
        general.reset(&mut rhs, 0.2, &y0).unwrap();
        compiled.stages_fixed::<D>(&mut rhs, times).unwrap();
        general.stages_fixed::<0>(&mut rhs, times).unwrap();
        let rows = (STAGES - 1) * D;
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for (name, a, b) in [
            ("stages", &compiled.k[..rows], &general.k[..rows]),
            ("increment", &compiled.increment[..], &general.increment[..]),
            ("candidate", &compiled.y_new[..], &general.y_new[..]),
            ("error sum", &compiled.scratch[..D], &general.scratch[..D]),
        ] {
            assert_eq!(bits(a), bits(b), "{name}, dim {D}");
        }
    }
    check::<2>();
    check::<4>();
    check::<6>();
    check::<8>();
}

/// One step of DOP853 and its squared error estimate, computed the plain way from the
/// tableau, following dop853.f: stages `kᵢ = F(t + cᵢh, y + h Σⱼ aᵢⱼ kⱼ)`, candidate
/// `y + h Σ bᵢ kᵢ`, `e₅ = Σ ERᵢ kᵢ`, `e₃ = Σ bᵢ kᵢ − Σ BHHⱼ kⱼ`, scales
/// `sk = atol + rtol · max(|y|, |y₁|)`, `E₅² = Σ (e₅/sk)²`, `E₃² = Σ (e₃/sk)²` and
/// `err = |h| E₅² / √(n (E₅² + 0.01 E₃²))`.
fn plain_step<F: FnMut(f64, &[f64], &mut [f64])>(
    f: &mut F,
    t: f64,
    y: &[f64],
    h: f64,
    tol: f64,
) -> (Vec<f64>, f64) {
    let n = y.len();
    let mut k = vec![vec![0.0; n]; STAGES];
    for i in 0..STAGES {
        let input: Vec<f64> = (0..n)
            .map(|c| y[c] + h * (0..i).map(|j| A[i][j] * k[j][c]).sum::<f64>())
            .collect();
        f(t + C[i] * h, &input, &mut k[i]);
    }
    let weighted =
        |w: &dyn Fn(usize) -> f64, c: usize| (0..STAGES).map(|i| w(i) * k[i][c]).sum::<f64>();
    let y1: Vec<f64> = (0..n).map(|c| y[c] + h * weighted(&|i| B[i], c)).collect();
    let third = |i: usize| {
        B_THIRD
            .iter()
            .filter(|&&(j, _)| j == i)
            .map(|&(_, w)| w)
            .sum::<f64>()
    };
    let (mut e5, mut e3) = (0.0, 0.0);
    for c in 0..n {
        let sk = tol + tol * y[c].abs().max(y1[c].abs());
        e5 += (weighted(&|i| ERROR_FIFTH[i], c) / sk).powi(2);
        e3 += ((weighted(&|i| B[i], c) - weighted(&third, c)) / sk).powi(2);
    }
    (y1, h.abs() * e5 / (n as f64 * (e5 + 0.01 * e3)).sqrt())
}

/// `attempt`'s candidate and error estimate agree with [`plain_step`], by the compiled
/// (2) and the general (3) stages, and the estimate has order 8: halving `h` divides it
/// by about 2⁸.
///
/// Bounds: the candidate to 1e-15 (components of size ~0.5, the same sums in another
/// order: a few rounding units). The estimate to 1e-4 relative: `e₅` and `e₃` are sums of
/// stages of size ~1 whose weights cancel to `O(h⁵)` and `O(h³)`, so their rounding is a
/// growing part of them as `h` shrinks (observed 1e-7 to 8e-6 here); every change to the
/// formula moves it by a factor. The observed order `log₂` of successive ratios within
/// 0.5 of 8 (observed 7.69–8.06 from h = 0.1 to 0.025, the next terms of the expansion
/// still showing), while dropping `h` or `E₃` from the formula, or its division, moves
/// it to 7, 6 or 11.
#[test]
fn the_error_estimate_is_dop853s_and_of_order_8() {
    // 2: the compiled stages; 3 and 10: the blocked ones (a block of 3; two of 4 and one of 2).
    for dim in [2, 3, 10] {
        let y0: Vec<f64> = (0..dim).map(|i| 0.3 + 0.1 * i as f64).collect();
        let tol = 1e-6;
        let weights = ErrorWeights::uniform(dim, tol, tol);
        let mut estimates = Vec::new();
        for h in [0.1, 0.05, 0.025] {
            let mut system = coupled(dim);
            let mut rhs = CheckedRhs::new(&mut system);
            let mut stepper = Dop853Stepper::new(dim);
            stepper.reset(&mut rhs, 0.5, &y0).unwrap();
            let squared = stepper
                .attempt(&mut rhs, 0.5 + h, &weights, true)
                .unwrap()
                .unwrap();
            let mut plain = coupled(dim);
            let (y1, err) = plain_step(
                &mut |t, y, dy| plain.rhs(t, y, dy).unwrap(),
                0.5,
                &y0,
                h,
                tol,
            );
            let relative = |a: f64, b: f64| (a - b).abs() / b.abs();
            assert!(
                relative(squared.sqrt(), err) < 1e-4,
                "dim {dim}, h {h}: {} vs {err}",
                squared.sqrt()
            );
            for (a, b) in stepper.y_new.iter().zip(&y1) {
                assert!((a - b).abs() < 1e-15, "dim {dim}, h {h}: {a} vs {b}");
            }
            estimates.push(err);
        }
        for pair in estimates.windows(2) {
            let order = (pair[0] / pair[1]).log2();
            assert!(
                (order - 8.0).abs() < 0.5,
                "dim {dim}: observed order {order} in {estimates:?}"
            );
        }
    }
}

/// The dense-output sum, formed four components at a time in registers, equals the same
/// sum formed stage by stage into memory from zero, as `dop853.f` forms it, to the bit,
/// for whole blocks of four and a remainder: the additions of each component are the
/// same and in the same order (components of zeros only, whose sign depends on the first
/// addition, included).
#[test]
fn the_dense_output_sum_adds_in_stage_order() {
    for n in [3, 4, 9] {
        dense_sum_in_stage_order(n);
    }
}

/// [`the_dense_output_sum_adds_in_stage_order`] for `n` components.
fn dense_sum_in_stage_order(n: usize) {
    let stages: Vec<Vec<f64>> = (0..EXTENDED_STAGES)
        .map(|j| {
            (0..n)
                .map(|i| match i % 4 {
                    2 => -0.0,
                    _ => ((j * 7 + i * 3) % 11) as f64 / 3.0 - 1.5,
                })
                .collect()
        })
        .collect();
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    for weights in [&DENSE[0][..], &DENSE[3][..], A[13], A[15]] {
        let mut out = vec![f64::NAN; n];
        weighted_sum(&mut out, weights, |j| &stages[j]);
        let mut reference = vec![0.0; n];
        for (j, &w) in weights.iter().enumerate() {
            if w != 0.0 {
                for (r, &x) in reference.iter_mut().zip(&stages[j]) {
                    *r += w * x;
                }
            }
        }
        assert_eq!(bits(&out), bits(&reference), "n = {n}");
    }
}

#[test]
fn dense_output_interpolates_a_step() {
    let mut system = OdeFn::new(1, |t: f64, _y: &[f64], dy: &mut [f64]| dy[0] = t.cos());
    let mut rhs = CheckedRhs::new(&mut system);
    let mut stepper = Dop853Stepper::new(1);
    stepper.reset(&mut rhs, 0.0, &[0.0]).unwrap();
    let weights = ErrorWeights::uniform(1, 1e-9, 1e-9);
    let error = stepper.attempt(&mut rhs, 0.25, &weights, true).unwrap();
    assert!(error.unwrap() < 1.0);
    stepper.accept(&mut rhs).unwrap();
    // 11 stages plus F at the new state, plus F(t0).
    assert_eq!(rhs.evals(), 1 + 12);
    stepper.prepare_dense_output(&mut rhs).unwrap();
    stepper.prepare_dense_output(&mut rhs).unwrap();
    assert_eq!(rhs.evals(), 1 + 12 + 3, "prepared once");
    let mut out = [0.0];
    for k in 0..=10 {
        let t = 0.025 * f64::from(k);
        stepper.interpolate(t, &mut out);
        // One step of h = 0.25: the interpolant's error is O(h⁸) (order 7), observed
        // 1e-11 for h = 0.5 and so ~4e-14 here.
        assert!((out[0] - t.sin()).abs() < 1e-12, "t = {t}: {}", out[0]);
    }
    stepper.interpolate(0.25, &mut out);
    assert_eq!(out[0], stepper.y()[0]);
}
