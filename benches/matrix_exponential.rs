//! `e^{At}`: nalgebra's `Matrix::exp` (Al-Mohy and Higham's scaling and squaring with Padé
//! degrees 3–13, SIAM J. Matrix Anal. Appl. 31 (2009) 970–989) against a fixed-degree Padé 13
//! with scaling and squaring (Higham, SIAM J. Matrix Anal. Appl. 26 (2005) 1179–1193,
//! Algorithm 2.3; eomgen's own implementation until the comparison below), in one run:
//!
//! - accuracy, printed first: the relative error `‖X − e^{At}‖_F / ‖e^{At}‖_F` of each against
//!   closed forms (a rotation generator, a damped oscillator, a Jordan block and a nilpotent
//!   block, a stiff two-mass spring at a large `t`, a 12 × 12 `A = S D S⁻¹`);
//! - speed: criterion medians on a 4 × 4 and the 12 × 12 `A t`.
//!
//! `cargo bench --bench matrix_exponential` (figures in docs/performance.md).

use std::hint::black_box;

use criterion::Criterion;
use eomgen::nalgebra::DMatrix;
use rand::RngExt;

/// Padé 13 with scaling and squaring at a fixed degree (Higham 2005, Algorithm 2.3): `A` is
/// scaled by `2⁻ˢ` so that `‖A‖₁ 2⁻ˢ ≤ θ₁₃ = 5.37`, and the result squared `s` times. The
/// baseline of the comparison (eomgen's `matrix_exponential` before it called nalgebra).
fn pade13_fixed(a: &DMatrix<f64>) -> DMatrix<f64> {
    const B: [f64; 14] = [
        64_764_752_532_480_000.0,
        32_382_376_266_240_000.0,
        7_771_770_303_897_600.0,
        1_187_353_796_428_800.0,
        129_060_195_264_000.0,
        10_559_470_521_600.0,
        670_442_572_800.0,
        33_522_128_640.0,
        1_323_241_920.0,
        40_840_800.0,
        960_960.0,
        16_380.0,
        182.0,
        1.0,
    ];
    const THETA_13: f64 = 5.371_920_351_148_152;
    let n = a.nrows();
    let norm = a.column_iter().map(|c| c.lp_norm(1)).fold(0.0f64, f64::max);
    let s = if norm > THETA_13 {
        (norm / THETA_13).log2().ceil() as i32
    } else {
        0
    };
    let a = a * 2f64.powi(-s);
    let id = DMatrix::<f64>::identity(n, n);
    let a2 = &a * &a;
    let a4 = &a2 * &a2;
    let a6 = &a4 * &a2;
    let inner_u = &a6 * (&a6 * B[13] + &a4 * B[11] + &a2 * B[9]);
    let u = &a * (inner_u + &a6 * B[7] + &a4 * B[5] + &a2 * B[3] + &id * B[1]);
    let inner_v = &a6 * (&a6 * B[12] + &a4 * B[10] + &a2 * B[8]);
    let v = inner_v + &a6 * B[6] + &a4 * B[4] + &a2 * B[2] + &id * B[0];
    let mut r = (&v - &u)
        .lu()
        .solve(&(&v + &u))
        .unwrap_or_else(|| DMatrix::from_element(n, n, f64::NAN));
    for _ in 0..s {
        r = &r * &r;
    }
    r
}

/// `(A t, e^{At})` of each accuracy case, with its name.
fn cases() -> Vec<(&'static str, DMatrix<f64>, DMatrix<f64>)> {
    let mut out = Vec::new();
    // Rotation generator [[0, w], [-w, 0]] t: e^{At} = [[cos wt, sin wt], [-sin wt, cos wt]].
    for (w, t) in [(1.0f64, 1.0f64), (2.0, 50.0)] {
        let a = DMatrix::from_row_slice(2, 2, &[0.0, w * t, -w * t, 0.0]);
        let (s, c) = (w * t).sin_cos();
        let name = if t == 1.0 {
            "rotation, wt = 1"
        } else {
            "rotation, wt = 100"
        };
        out.push((name, a, DMatrix::from_row_slice(2, 2, &[c, s, -s, c])));
    }
    // Damped oscillator x'' + 2ζω x' + ω² x = 0, A = [[0, 1], [-ω², -2ζω]]:
    // e^{At} = e^{-ζωt} [cos(ω_d t) I + sin(ω_d t)/ω_d (A + ζω I)], ω_d = ω √(1 − ζ²).
    {
        let (omega, zeta, t) = (2.0 * std::f64::consts::PI, 0.05, 10.0);
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -omega * omega, -2.0 * zeta * omega]);
        let wd = omega * (1.0 - zeta * zeta).sqrt();
        let shifted = &a + DMatrix::identity(2, 2) * (zeta * omega);
        let exact = (DMatrix::identity(2, 2) * (wd * t).cos() + shifted * ((wd * t).sin() / wd))
            * (-zeta * omega * t).exp();
        out.push(("damped oscillator, ζ = 0.05, t = 10", a * t, exact));
    }
    // Jordan block λ I + N (4 × 4, N the upper shift): e^{Jt} = e^{λt} Σ_k (t^k/k!) N^k; and
    // the nilpotent N t alone (the series ends: a polynomial, exact in floating point).
    for (lambda, t, name) in [
        (-1.0f64, 5.0f64, "Jordan block 4 × 4, λ = −1, t = 5"),
        (0.0, 10.0, "nilpotent 4 × 4, t = 10"),
    ] {
        let a = DMatrix::from_fn(4, 4, |i, j| {
            if i == j {
                lambda * t
            } else if j == i + 1 {
                t
            } else {
                0.0
            }
        });
        let exact = DMatrix::from_fn(4, 4, |i, j| {
            if j < i {
                0.0
            } else {
                let k = (j - i) as i32;
                (lambda * t).exp() * t.powi(k) / (1..=k).product::<i32>() as f64
            }
        });
        out.push((name, a, exact));
    }
    // Stiff two-mass spring (M = I, a soft spring k to the wall on each, a stiff K between):
    // K = [[k + K, −K], [−K, k + K]] has the exact eigenvectors (1, ±1)/√2 and ω₁² = k,
    // ω₂² = k + 2K, so e^{At} = [[P C Pᵀ, P Ω⁻¹S Pᵀ], [−P ΩS Pᵀ, P C Pᵀ]] with C = cos Ωt,
    // S = sin Ωt. At ω₂ t ≈ 1.4e5 the reference itself carries ω₂ t ε ≈ 3e-11 (the rounding of
    // ω₂ t), and e^{At}'s condition is ~‖At‖.
    {
        let (k, big_k, t): (f64, f64, f64) = (1.0, 1e6, 100.0);
        let stiffness = DMatrix::from_row_slice(2, 2, &[k + big_k, -big_k, -big_k, k + big_k]);
        let mut a = DMatrix::zeros(4, 4);
        a.view_mut((0, 2), (2, 2)).fill_with_identity();
        a.view_mut((2, 0), (2, 2)).copy_from(&(-stiffness));
        let r = std::f64::consts::FRAC_1_SQRT_2;
        let p = DMatrix::from_row_slice(2, 2, &[r, r, r, -r]);
        let omegas = [k.sqrt(), (k + 2.0 * big_k).sqrt()];
        let diag = |f: &dyn Fn(f64) -> f64| {
            &p * DMatrix::from_diagonal(&nalgebra_vector(omegas.map(f))) * p.transpose()
        };
        let c = diag(&|w| (w * t).cos());
        let s_over = diag(&|w| (w * t).sin() / w);
        let s_times = diag(&|w| -(w * t).sin() * w);
        let mut exact = DMatrix::zeros(4, 4);
        exact.view_mut((0, 0), (2, 2)).copy_from(&c);
        exact.view_mut((0, 2), (2, 2)).copy_from(&s_over);
        exact.view_mut((2, 0), (2, 2)).copy_from(&s_times);
        exact.view_mut((2, 2), (2, 2)).copy_from(&c);
        out.push(("stiff two-mass spring, K/k = 1e6, t = 100", a * t, exact));
    }
    let (a, exact) = modal_test(12);
    out.push(("12 × 12 A = S D S⁻¹, t = 1.7", a, exact));
    out
}

fn nalgebra_vector<const N: usize>(v: [f64; N]) -> eomgen::nalgebra::DVector<f64> {
    eomgen::nalgebra::DVector::from_row_slice(&v)
}

/// `(A t, e^{At})` with `A = S D S⁻¹` (a random well-conditioned `S`, `D` of 2 × 2 blocks
/// `[σ ω; −ω σ]`), as the modal tests build it: `e^{At} = S e^{Dt} S⁻¹`.
fn modal_test(n: usize) -> (DMatrix<f64>, DMatrix<f64>) {
    let mut rng: rand::rngs::Xoshiro256PlusPlus =
        rand::SeedableRng::seed_from_u64(0x2545_f491_4f6c_dd1d);
    let mut uniform = move || rng.random_range(-1.0..1.0);
    let s = DMatrix::from_fn(n, n, |i, j| uniform() + if i == j { 3.0 } else { 0.0 });
    let s_inv = s.clone().try_inverse().expect("S is diagonally dominant");
    let t = 1.7;
    let mut d = DMatrix::zeros(n, n);
    let mut exp_dt = DMatrix::zeros(n, n);
    for b in 0..n / 2 {
        let (sigma, omega) = (-0.3 * b as f64 + 0.2 * uniform(), 1.0 + 2.0 * b as f64);
        let k = 2 * b;
        d[(k, k)] = sigma;
        d[(k + 1, k + 1)] = sigma;
        d[(k, k + 1)] = omega;
        d[(k + 1, k)] = -omega;
        let e = (sigma * t).exp();
        let (sn, cs) = (omega * t).sin_cos();
        exp_dt[(k, k)] = e * cs;
        exp_dt[(k + 1, k + 1)] = e * cs;
        exp_dt[(k, k + 1)] = e * sn;
        exp_dt[(k + 1, k)] = -e * sn;
    }
    (&s * &d * &s_inv * t, &s * &exp_dt * &s_inv)
}

fn accuracy() {
    println!(
        "relative error ‖X − e^(At)‖_F / ‖e^(At)‖_F (ε = {:.2e})",
        f64::EPSILON
    );
    println!(
        "{:<44} {:>10} {:>12} {:>12}",
        "case", "‖At‖₁", "Padé 13", "nalgebra"
    );
    for (name, a, exact) in cases() {
        let norm = a.column_iter().map(|c| c.lp_norm(1)).fold(0.0f64, f64::max);
        let err = |x: DMatrix<f64>| (x - &exact).norm() / exact.norm();
        println!(
            "{name:<44} {norm:>10.3e} {:>12.2e} {:>12.2e}",
            err(pade13_fixed(&a)),
            err(a.exp())
        );
    }
}

fn speed(c: &mut Criterion) {
    // 4 × 4: the damped two-mass chain's A (k = 100, c = 0.5) times t = 1.
    let four = DMatrix::from_row_slice(
        4,
        4,
        &[
            0.0, 0.0, 1.0, 0.0, //
            0.0, 0.0, 0.0, 1.0, //
            -200.0, 100.0, -1.0, 0.5, //
            100.0, -100.0, 0.5, -0.5,
        ],
    );
    let (twelve, _) = modal_test(12);
    for (label, a) in [("4x4", four), ("12x12", twelve)] {
        let mut group = c.benchmark_group(format!("expm_{label}"));
        group.bench_function("pade13_fixed", |b| b.iter(|| pade13_fixed(black_box(&a))));
        group.bench_function("nalgebra_exp", |b| b.iter(|| black_box(&a).exp()));
        group.finish();
    }
}

fn main() {
    accuracy();
    let mut c = Criterion::default().configure_from_args();
    speed(&mut c);
    c.final_summary();
}
