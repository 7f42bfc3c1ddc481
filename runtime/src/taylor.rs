//! Taylor series of the motion: the recurrences of a model's [`TaylorProgram`] run order by
//! order, and `M q̈ = F` solved as a series (with `m` constraints, the index-1 system
//! `[M Jᵀ; J 0][q̈; λ] = [F; γ]`, its `n + m` unknowns in place of `q̈`'s `n`, the same way).
//!
//! long: the kernels of every op, their dispatch and the series of the motion share private
//! helpers that must inline into the fused orders (`known`, `at`, `put`, the convolutions) and
//! the two macros that keep their variants' bits equal (`with_host_features!`,
//! `unrolled_orders!`); splitting them into submodules belongs with the code's shape (the
//! element-per-module work), not with this file's features.
//!
//! With `x(t₀ + τ) = Σₖ x^[k] τᵏ` for every value of the model's program, the state
//! `y = [q; q̇]` has `q^[k+1] = q̇^[k] / (k + 1)` and `q̇^[k+1] = a^[k] / (k + 1)`, where the
//! accelerations `a = q̈` solve `M a = F` as series (the Cauchy product of `M(t) a(t) = F(t)`):
//!
//! ```text
//! M^[0] a^[k] = F^[k] − Σⱼ₌₁ᵏ M^[j] a^[k−j]
//! ```
//!
//! — one `L D Lᵀ` factorisation of `M^[0]` per step, one pair of triangular solves per order.
//! [`series_of_motion`] runs that loop over a model's generated functions (order 0: the
//! model's own evaluation, every value kept; order `k ≥ 1`: its [`SeriesOp`]s; and, for a
//! compiled model, the orders a step can run compiled for each order, fused with their
//! solves into one function), for compiled models and models compiled at run time alike.
//! Each recurrence is defined once, as the kernel of its op (`mul`, `sin_cos`, …): the `model!` macro's code calls the kernels op by
//! op with its slots as constants, the run-time model reaches them through [`apply`]
//! ([`evaluate_order`]), so both compute the same bits.
//!
//! # Source
//! Jorba & Zou, *A software package for the numerical integration of ODEs by means of
//! high-order Taylor methods*, Exp. Math. 14(1) (2005) 99–117, §2 (the recurrences);
//! Biscani & Izzo, MNRAS 504(2) (2021) 2614–2628 and heyoka's `doc/ad_notes.rst` (the
//! decomposition with hidden partners); the mass-matrix series is the quotient rule of §2
//! with a matrix denominator.

pub use eomgen_description::taylor::{
    DerivedLists, SeriesOp, Slot, TaylorProgram, TaylorUnsupported, UNROLLED_CAPACITY,
    UNROLLED_ORDERS,
};

use crate::ode::RhsError;
use wide::f64x2;

/// The series of one slot: its `capacity` coefficients.
#[inline(always)]
fn series(s: &[f64], capacity: usize, slot: Slot) -> &[f64] {
    let start = slot as usize * capacity;
    &s[start..start + capacity]
}

/// `$m!($($arg)*; 1 2 … 19)`: the orders compiled with `k` known ([`UNROLLED_ORDERS`]), one
/// list for every dispatch on the order.
macro_rules! unrolled_orders {
    ($m:ident $(, $arg:tt)*) => {{
        const _: () = assert!(UNROLLED_ORDERS == 19);
        $m!($($arg)*; 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19)
    }};
}

/// The order and the stride a kernel computes with: `(K, UNROLLED_CAPACITY)` when `K` is not
/// 0, else `(k, c)`.
///
/// [`evaluate_order`] (the run-time model's orders) and the `model!`
/// macro's `TaylorFunctions::orders` in optimised builds pick `K = k` for `k ≤` [`UNROLLED_ORDERS`]
/// when the workspace's stride is [`UNROLLED_CAPACITY`] (as [`series_of_motion`]'s is when
/// [`TaylorProgram::unrolled_code_fits`], or the model has fused orders): the sums then have
/// a known number of terms and unroll into straight-line code, and every coefficient is at
/// a known offset, so the compiler passes an op's result to the next in a register instead
/// of through memory. Both variants run the same operations in the same order, so they
/// compute the same bits.
#[inline(always)]
const fn known<const K: usize>(k: usize, c: usize) -> (usize, usize) {
    debug_assert!(K == 0 || (k == K && c == UNROLLED_CAPACITY));
    if K == 0 {
        (k, c)
    } else {
        (K, UNROLLED_CAPACITY)
    }
}

/// Order `i` of `slot`, in a workspace of stride `c`.
#[inline(always)]
fn at(s: &[f64], c: usize, slot: Slot, i: usize) -> f64 {
    s[slot as usize * c + i]
}

/// Writes `v` as order `k` of `slot`, in a workspace of stride `c`.
#[inline(always)]
fn put(s: &mut [f64], c: usize, slot: Slot, k: usize, v: f64) {
    s[slot as usize * c + k] = v;
}

/// `Σ_{j=from}^{to} a[j] b[k − j]` (`from ≤ to ≤ k`), in increasing `j`.
///
/// The recurrences spend most of a Taylor step here, in sums of a few to twenty terms.
/// Iterators over the two ranges (one reversed) leave the loop without bounds checks. One
/// running sum: four partial sums (to overlap the additions) were 2.4× slower with `k` a
/// variable, their set-up and remainder loops outweighing the gain on sums this short, and
/// no faster with `k` known (the double pendulum at orders 12 and 15, same run: the gain of
/// the unrolled code is in the known offsets, not in the sums' latency). The ranges are
/// half-open (`from..to + 1`): an inclusive range's indexing was not inlined into the
/// model's fused orders, a call per sum (3× slower).
#[inline(always)]
fn convolution(a: &[f64], b: &[f64], k: usize, from: usize, to: usize) -> f64 {
    let a = &a[from..to + 1];
    let b = &b[k - to..k - from + 1];
    let mut sum = 0.0;
    for (x, y) in a.iter().zip(b.iter().rev()) {
        sum += x * y;
    }
    sum
}

/// Order `k ≥ 1` of the Cauchy product `Σ_{j=0}^{k} a[j] b[k − j]`, summed with the two terms
/// that hold an order-`k` coefficient last: `(Σ_{j=1}^{k−1} a[j] b[k − j] + a[0] b[k]) +
/// a[k] b[0]`.
///
/// The older terms are ready before the operands' order `k` is computed: summing them first
/// lets the processor run those sums ahead (3–4 % faster on the double pendulum at order
/// 12 with one running sum, same run).
#[inline(always)]
fn cauchy(a: &[f64], b: &[f64], k: usize) -> f64 {
    let older = if k > 1 {
        convolution(a, b, k, 1, k - 1)
    } else {
        0.0
    };
    older + a[0] * b[k] + a[k] * b[0]
}

/// `Σ_{j=from}^{to} j a[j] b[k − j]`, in increasing `j` (each term `(j · a[j]) · b[k − j]`).
#[inline(always)]
fn weighted_convolution(a: &[f64], b: &[f64], k: usize, from: usize, to: usize) -> f64 {
    let a = &a[from..to + 1];
    let b = &b[k - to..k - from + 1];
    let mut sum = 0.0;
    let mut j = from as f64;
    for (x, y) in a.iter().zip(b.iter().rev()) {
        sum += j * x * y;
        j += 1.0;
    }
    sum
}

/// `[Σ_{j=1}^{k} j a[j] b[k − j], Σ_{j=1}^{k} j a[j] d[k − j]]`: the two
/// [`weighted_convolution`]s of a sine and cosine (or sinh and cosh) pair, over one operand,
/// as the two lanes of one 2-wide vector.
///
/// Each lane adds the same products in the same order as its own `weighted_convolution`
/// (`(j · a[j]) · b[k − j]`, increasing `j`), and a lane of a vector addition or
/// multiplication rounds as the scalar one does, so the bits are those of the two sums
/// apart (and of the run-time compiler's scalar code). One vector sum instead of two scalar
/// sums: the double pendulum (three sine–cosine pairs per order) in 0.98–0.99 of the time at
/// tolerances 1e-3 to 1e-12 in a quiet run, 0.94–1.01 at 1e-4 to 1e-9 in another (nine
/// alternating pairs each, the same steps and bits).
#[inline(always)]
fn weighted_convolution_pair(a: &[f64], b: &[f64], d: &[f64], k: usize) -> [f64; 2] {
    let a = &a[1..k + 1];
    let b = &b[..k];
    let d = &d[..k];
    let mut sum = f64x2::splat(0.0);
    let mut j = 1.0;
    for ((x, y), z) in a.iter().zip(b.iter().rev()).zip(d.iter().rev()) {
        sum += f64x2::splat(j * x) * f64x2::new([*y, *z]);
        j += 1.0;
    }
    sum.to_array()
}

/// Order `k ≥ 1` of the output(s) of one op, from the orders `≤ k` of its operands and `< k`
/// of its outputs, in `s` (slot `x`'s order `i` at `x · capacity + i`).
///
/// The recurrence of each op is written once, as the kernel function of its kind (`mul`,
/// `sin_cos`, …): the `model!` macro's generated code calls the kernels directly with its
/// slots as constants (inlined in optimised builds, calls in debug builds, which keeps the
/// generated code small to compile), and the run-time model reaches the same kernels through
/// this dispatch ([`evaluate_order`]), so both compute the same bits.
///
/// # Panics
/// If a slot is beyond `s` or `k ≥ capacity` (a program and workspace that do not belong
/// together).
#[inline]
pub fn apply<const K: usize>(op: SeriesOp, k: usize, capacity: usize, s: &mut [f64]) {
    let c = capacity;
    match op {
        SeriesOp::Neg { out, a } => neg::<K>(k, c, s, out, a),
        SeriesOp::Copy { out, a } => copy::<K>(k, c, s, out, a),
        SeriesOp::Add { out, a, b } => add::<K>(k, c, s, out, a, b),
        SeriesOp::Sub { out, a, b } => sub::<K>(k, c, s, out, a, b),
        SeriesOp::Mul { out, a, b } => mul::<K>(k, c, s, out, a, b),
        SeriesOp::Scale { out, a, constant } => scale::<K>(k, c, s, out, a, constant),
        SeriesOp::Div { out, a, b } => div::<K>(k, c, s, out, a, b),
        SeriesOp::DivByConstant { out, a, constant } => {
            div_by_constant::<K>(k, c, s, out, a, constant)
        }
        SeriesOp::ConstantDiv { out, b } => constant_div::<K>(k, c, s, out, b),
        SeriesOp::Sqrt { out, a } => sqrt::<K>(k, c, s, out, a),
        SeriesOp::PowConstant { out, a, exponent } => pow_constant::<K>(k, c, s, out, a, exponent),
        SeriesOp::Exp { out, a } => exp::<K>(k, c, s, out, a),
        SeriesOp::Ln { out, a } => ln::<K>(k, c, s, out, a),
        SeriesOp::SinCos { sin, cos, a } => sin_cos::<K>(k, c, s, sin, cos, a),
        SeriesOp::SinhCosh { sinh, cosh, a } => sinh_cosh::<K>(k, c, s, sinh, cosh, a),
        SeriesOp::Tan { out, a, square } => tan_or_tanh::<K>(k, c, s, out, a, square, 1.0),
        SeriesOp::Tanh { out, a, square } => tan_or_tanh::<K>(k, c, s, out, a, square, -1.0),
        SeriesOp::Asin { out, a, root, acos } => asin::<K>(k, c, s, out, a, root, acos),
        SeriesOp::Atan { out, a, square } => atan::<K>(k, c, s, out, a, square),
        SeriesOp::Atan2 { out, y, x, norm } => atan2::<K>(k, c, s, out, y, x, norm),
        SeriesOp::Zero { out } => zero::<K>(k, c, s, out),
    }
}

/// Order `k ≥ 1` of [`SeriesOp::Neg`].
#[inline(always)]
pub fn neg<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, a: Slot) {
    let (k, c) = known::<K>(k, c);
    let v = -at(s, c, a, k);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Copy`].
#[inline(always)]
pub fn copy<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, a: Slot) {
    let (k, c) = known::<K>(k, c);
    let v = at(s, c, a, k);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Add`].
#[inline(always)]
pub fn add<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, a: Slot, b: Slot) {
    let (k, c) = known::<K>(k, c);
    let v = at(s, c, a, k) + at(s, c, b, k);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Sub`].
#[inline(always)]
pub fn sub<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, a: Slot, b: Slot) {
    let (k, c) = known::<K>(k, c);
    let v = at(s, c, a, k) - at(s, c, b, k);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Mul`]: the Cauchy product, or for a series times itself
/// (`a == b`, a square: `x²` written as `x*x`, the `u² + v²` of a distance) the square's
/// recurrence (`square`), with half the products.
#[inline(always)]
pub fn mul<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, a: Slot, b: Slot) {
    let (k, c) = known::<K>(k, c);
    let v = if a == b {
        square(series(s, c, a), k)
    } else {
        cauchy(series(s, c, a), series(s, c, b), k)
    };
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of `a²`: `Σ_{j=0}^{k} a[j] a[k − j]` with each pair of equal products
/// formed once, `(2 h + [k even] a[k/2]²) + 2 (a[0] a[k])` with `h = Σ_{j=1}^{⌊(k−1)/2⌋}
/// a[j] a[k − j]` in increasing `j`; the term that holds order `k` last, as in [`cauchy`].
/// (Jorba & Zou 2005, §2.1; heyoka's `square`.) Half the products of the Cauchy product
/// (a sixth of the figure eight's products at order 12 are squares' halves).
#[inline(always)]
fn square(a: &[f64], k: usize) -> f64 {
    let half = convolution(a, a, k, 1, (k - 1) / 2);
    let mut sum = half + half;
    if k.is_multiple_of(2) {
        sum += a[k / 2] * a[k / 2];
    }
    sum + 2.0 * (a[0] * a[k])
}

/// Order `k ≥ 1` of [`SeriesOp::Scale`].
#[inline(always)]
pub fn scale<const K: usize>(
    k: usize,
    c: usize,
    s: &mut [f64],
    out: Slot,
    a: Slot,
    constant: Slot,
) {
    let (k, c) = known::<K>(k, c);
    let v = at(s, c, a, k) * at(s, c, constant, 0);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Div`].
#[inline(always)]
pub fn div<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, a: Slot, b: Slot) {
    let (k, c) = known::<K>(k, c);
    let sum = convolution(series(s, c, b), series(s, c, out), k, 1, k);
    let v = (at(s, c, a, k) - sum) / at(s, c, b, 0);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::DivByConstant`].
#[inline(always)]
pub fn div_by_constant<const K: usize>(
    k: usize,
    c: usize,
    s: &mut [f64],
    out: Slot,
    a: Slot,
    constant: Slot,
) {
    let (k, c) = known::<K>(k, c);
    let v = at(s, c, a, k) / at(s, c, constant, 0);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::ConstantDiv`].
#[inline(always)]
pub fn constant_div<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, b: Slot) {
    let (k, c) = known::<K>(k, c);
    let sum = convolution(series(s, c, b), series(s, c, out), k, 1, k);
    let v = -sum / at(s, c, b, 0);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Sqrt`].
#[inline(always)]
pub fn sqrt<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, a: Slot) {
    let (k, c) = known::<K>(k, c);
    let o = series(s, c, out);
    let sum = if k > 1 {
        convolution(o, o, k, 1, k - 1)
    } else {
        0.0
    };
    let v = (at(s, c, a, k) - sum) / (2.0 * o[0]);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::PowConstant`].
#[inline(always)]
pub fn pow_constant<const K: usize>(
    k: usize,
    c: usize,
    s: &mut [f64],
    out: Slot,
    a: Slot,
    exponent: Slot,
) {
    let (k, c) = known::<K>(k, c);
    let kf = k as f64;
    let alpha = at(s, c, exponent, 0);
    let (x, o) = (series(s, c, a), series(s, c, out));
    // Decreasing j: the term with x[k], this order's, comes last (see `cauchy`).
    let mut sum = 0.0;
    for j in (0..k).rev() {
        sum += (kf * alpha - j as f64 * (alpha + 1.0)) * x[k - j] * o[j];
    }
    let v = sum / (kf * x[0]);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Exp`].
#[inline(always)]
pub fn exp<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, a: Slot) {
    let (k, c) = known::<K>(k, c);
    let kf = k as f64;
    let v = weighted_convolution(series(s, c, a), series(s, c, out), k, 1, k) * (1.0 / kf);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Ln`].
#[inline(always)]
pub fn ln<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, a: Slot) {
    let (k, c) = known::<K>(k, c);
    let kf = k as f64;
    let (x, o) = (series(s, c, a), series(s, c, out));
    let sum = if k > 1 {
        weighted_convolution(o, x, k, 1, k - 1)
    } else {
        0.0
    };
    let v = (kf * x[k] - sum) / (kf * x[0]);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::SinCos`].
#[inline(always)]
pub fn sin_cos<const K: usize>(k: usize, c: usize, s: &mut [f64], sin: Slot, cos: Slot, a: Slot) {
    let (k, c) = known::<K>(k, c);
    let kf = k as f64;
    let x = series(s, c, a);
    let [ws, wc] = weighted_convolution_pair(x, series(s, c, cos), series(s, c, sin), k);
    let vs = ws * (1.0 / kf);
    let vc = -wc * (1.0 / kf);
    put(s, c, sin, k, vs);
    put(s, c, cos, k, vc);
}

/// Order `k ≥ 1` of [`SeriesOp::SinhCosh`].
#[inline(always)]
pub fn sinh_cosh<const K: usize>(
    k: usize,
    c: usize,
    s: &mut [f64],
    sinh: Slot,
    cosh: Slot,
    a: Slot,
) {
    let (k, c) = known::<K>(k, c);
    let kf = k as f64;
    let x = series(s, c, a);
    let [ws, wc] = weighted_convolution_pair(x, series(s, c, cosh), series(s, c, sinh), k);
    let vs = ws * (1.0 / kf);
    let vc = wc * (1.0 / kf);
    put(s, c, sinh, k, vs);
    put(s, c, cosh, k, vc);
}

/// Order `k ≥ 1` of `tan a` (`sign = 1`) or `tanh a` (`sign = −1`), with `square` its square: [`SeriesOp::Tan`], [`SeriesOp::Tanh`].
#[inline(always)]
pub fn tan_or_tanh<const K: usize>(
    k: usize,
    c: usize,
    s: &mut [f64],
    out: Slot,
    a: Slot,
    square: Slot,
    sign: f64,
) {
    let (k, c) = known::<K>(k, c);
    let kf = k as f64;
    let x = series(s, c, a);
    let v = x[k] + sign * (weighted_convolution(x, series(s, c, square), k, 1, k) * (1.0 / kf));
    put(s, c, out, k, v);
    let o = series(s, c, out);
    let q = cauchy(o, o, k);
    put(s, c, square, k, q);
}

/// Order `k ≥ 1` of [`SeriesOp::Asin`].
#[inline(always)]
pub fn asin<const K: usize>(
    k: usize,
    c: usize,
    s: &mut [f64],
    out: Slot,
    a: Slot,
    root: Slot,
    acos: bool,
) {
    let (k, c) = known::<K>(k, c);
    let kf = k as f64;
    let x = series(s, c, a);
    let a2 = cauchy(x, x, k);
    let r = series(s, c, root);
    let sum = if k > 1 {
        convolution(r, r, k, 1, k - 1)
    } else {
        0.0
    };
    let rk = (-a2 - sum) / (2.0 * r[0]);
    let sign = if acos { -1.0 } else { 1.0 };
    let sum = if k > 1 {
        weighted_convolution(series(s, c, out), r, k, 1, k - 1)
    } else {
        0.0
    };
    let v = (sign * kf * x[k] - sum) / (kf * r[0]);
    put(s, c, root, k, rk);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Atan`].
#[inline(always)]
pub fn atan<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, a: Slot, square: Slot) {
    let (k, c) = known::<K>(k, c);
    let kf = k as f64;
    let x = series(s, c, a);
    let q = cauchy(x, x, k);
    put(s, c, square, k, q);
    let (x, sq) = (series(s, c, a), series(s, c, square));
    let sum = if k > 1 {
        weighted_convolution(series(s, c, out), sq, k, 1, k - 1)
    } else {
        0.0
    };
    let v = (kf * x[k] - sum) / (kf * (1.0 + sq[0]));
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Atan2`].
#[inline(always)]
pub fn atan2<const K: usize>(
    k: usize,
    c: usize,
    s: &mut [f64],
    out: Slot,
    y: Slot,
    x: Slot,
    norm: Slot,
) {
    let (k, c) = known::<K>(k, c);
    let kf = k as f64;
    let (ys, xs) = (series(s, c, y), series(s, c, x));
    let nk = cauchy(xs, xs, k) + cauchy(ys, ys, k);
    let cross = weighted_convolution(ys, xs, k, 1, k) - weighted_convolution(xs, ys, k, 1, k);
    put(s, c, norm, k, nk);
    let ns = series(s, c, norm);
    let sum = if k > 1 {
        weighted_convolution(series(s, c, out), ns, k, 1, k - 1)
    } else {
        0.0
    };
    let v = (cross - sum) / (kf * ns[0]);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Zero`].
#[inline(always)]
pub fn zero<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot) {
    let (k, c) = known::<K>(k, c);
    put(s, c, out, k, 0.0);
}

/// Whether the Taylor method's steps run in their copy compiled for AVX2 and FMA: on an
/// x86-64 processor that has both (detected once), unless [`set_host_features`] turned it off;
/// never elsewhere.
///
/// The copy covers each compiled model's fused orders (the `model!` macro's `TaylorFunctions::orders`,
/// in optimised builds), the rest of [`series_of_motion`], and the Taylor method's Horner's
/// rule and step rule: the same Rust code compiled a second time with those instruction sets
/// enabled — three-operand VEX encodings, fewer register copies — in a binary that still runs
/// on any x86-64. Rust neither contracts a product and a sum into a fused multiply–add nor
/// reassociates, so both copies compute the same bits (`tests/taylor_coefficients.rs`
/// compares them). Orders above the fused ones (`TaylorFunctions::order`, the run-time model's
/// `evaluate_order`) run the baseline code; a model compiled at run time gets the host's
/// instructions from Cranelift anyway. On the double pendulum (AMD EPYC, Zen 3) a run took
/// 0.73–0.94 of the time at tolerances 1e-4 to 1e-12; on a processor with AVX-512 the whole
/// crate compiled for it had left the Taylor method's times unchanged (docs/performance.md).
#[inline]
pub fn host_features() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        match HOST_FEATURES.load(std::sync::atomic::Ordering::Relaxed) {
            ENABLED => true,
            DISABLED => false,
            _ => detect_host_features(),
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// [`host_features`]' first call: detects AVX2 and FMA and records the answer.
#[cfg(target_arch = "x86_64")]
#[cold]
#[inline(never)]
fn detect_host_features() -> bool {
    use std::sync::atomic::Ordering;
    let found = std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma");
    let state = if found { ENABLED } else { DISABLED };
    // A concurrent `set_host_features(false)` wins over the detection.
    let _ = HOST_FEATURES.compare_exchange(UNKNOWN, state, Ordering::Relaxed, Ordering::Relaxed);
    HOST_FEATURES.load(Ordering::Relaxed) == ENABLED
}

/// Turns the copy of [`host_features`] off (`false`: every Taylor step runs the baseline
/// code from then on, in the whole process) or back to what the processor has (`true`): for
/// comparing the two copies' bits and cost. The results are the same either way.
pub fn set_host_features(enabled: bool) {
    #[cfg(target_arch = "x86_64")]
    {
        let state = if enabled { UNKNOWN } else { DISABLED };
        HOST_FEATURES.store(state, std::sync::atomic::Ordering::Relaxed);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = enabled;
}

/// [`host_features`]' answer: [`UNKNOWN`] until the first call.
#[cfg(target_arch = "x86_64")]
static HOST_FEATURES: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(UNKNOWN);
#[cfg(target_arch = "x86_64")]
const UNKNOWN: u8 = 0;
#[cfg(target_arch = "x86_64")]
const ENABLED: u8 = 1;
#[cfg(target_arch = "x86_64")]
const DISABLED: u8 = 2;

/// Order `k ≥ 1` of every series of `ops`, in order ([`apply`] for each): the run-time
/// model's orders, compiled for `K = k` when `k ≤` [`UNROLLED_ORDERS`] and `capacity` is
/// [`UNROLLED_CAPACITY`], else for any order.
pub fn evaluate_order(ops: &[SeriesOp], k: usize, capacity: usize, s: &mut [f64]) {
    /// The ops for one `K`, out of line (one variant per order).
    #[inline(never)]
    fn run<const K: usize>(ops: &[SeriesOp], k: usize, capacity: usize, s: &mut [f64]) {
        for &op in ops {
            apply::<K>(op, k, capacity, s);
        }
    }
    if capacity != UNROLLED_CAPACITY {
        return run::<0>(ops, k, capacity, s);
    }
    macro_rules! orders {
        (; $($order:literal)*) => {
            match k {
                $($order => run::<$order>(ops, k, capacity, s),)*
                _ => run::<0>(ops, k, capacity, s),
            }
        };
    }
    unrolled_orders!(orders)
}

/// The buffers of [`series_of_motion`], allocated on first use and grown when a higher order
/// is asked for (never per step).
#[derive(Debug, Clone, Default)]
pub struct TaylorWorkspace {
    capacity: usize,
    /// The program's slots, then one per acceleration `q̈ᵢ` and one per multiplier `λⱼ`
    /// ([`TaylorProgram::acceleration_slot`]).
    series: Vec<f64>,
    lower: Vec<f64>,
    pivots: Vec<f64>,
    inverse_pivots: Vec<f64>,
    /// `(row, column, L[row][column])` for each entry of `L` below the diagonal that is not
    /// zero, row by row.
    nonzeros: Vec<(u32, u32, f64)>,
    rhs: Vec<f64>,
    /// `1 / (k + 1)` for `k = 0 … capacity − 1`.
    reciprocals: Vec<f64>,
    /// A run-time backend's scratch ([`MotionSolve::lanes`]), kept between steps.
    lanes: Vec<Lanes>,
    /// The slots of a constant `M` (no entry reads the state or the time) whose factors
    /// `lower`, `pivots`, `inverse_pivots` and `nonzeros` hold, entry by entry as the
    /// program's `mass_matrix` lists them; empty when they hold another's. A step whose `M`
    /// has these slots, with the values in `factored_values`, reuses the factors instead of
    /// factoring again (11 % of a figure-eight step at order 5 went into factoring its
    /// constant diagonal `M`).
    factored_mass: Vec<Slot>,
    /// The distinct slots of `factored_mass` with their values' bits when factored: the
    /// figure eight's 36 entries are two slots (`m` and 0), so the test of each step reads
    /// two values rather than 36 (4 % of its step's instructions: 363 of 8,851 at 10⁻⁹).
    factored_values: Vec<(Slot, u64)>,
    /// The coordinates `n` of the program the factors are for: of `[M Jᵀ; J 0]` the first `n`
    /// pivots are positive, the rest negative, so the same bits factor otherwise for another
    /// `n`.
    coordinates: usize,
    /// Whether the program of the last series has ops whose branch [`branch_step`] checks.
    branch_points: bool,
}

/// Two values side by side, aligned for one 16-byte load: the unit of the scratch a run-time
/// backend's compiled orders keep between orders ([`MotionSolve::lanes`]).
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(16))]
pub struct Lanes(pub [f64; 2]);

impl TaylorWorkspace {
    /// Empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether the program of the last [`series_of_motion`] into this workspace has square
    /// roots or real powers whose branch [`branch_step`] checks (`false` before any series):
    /// without, `branch_step` returns the step it is given, and a step need not ask.
    pub fn has_branch_points(&self) -> bool {
        self.branch_points
    }

    /// Buffers for `order`: grown when a higher order or another program asks for more,
    /// never shrunk (the stride `capacity` is the kernels' argument, so a longer one serves a
    /// lower order), so a method switching order between steps does not reallocate. The
    /// stride is [`UNROLLED_CAPACITY`], the one the kernels compiled for each order run with,
    /// when [`TaylorProgram::unrolled_code_fits`] or the model has `fused` orders (and
    /// `order` is within the stride), else any other (so that they do not).
    /// `unknowns` is the series solve's: `n`, or `n + m` with `m` constraints.
    fn fit(&mut self, program: &TaylorProgram, unknowns: usize, order: usize, fused: usize) {
        let n = unknowns;
        // With fused orders (a compiled model's), those run compiled for each order and the
        // rest as loops at the same stride, whatever the order (to its limit): the fused
        // code alone is what must fit the instruction cache.
        let unrolled =
            (fused > 0 && order <= UNROLLED_ORDERS + 1) || program.unrolled_code_fits(order);
        let capacity = if unrolled {
            UNROLLED_CAPACITY
        } else if self.capacity != UNROLLED_CAPACITY && self.capacity > order {
            self.capacity
        } else {
            // Any stride but the unrolled code's.
            (order + 1).max(UNROLLED_CAPACITY + 1)
        };
        let size = (program.slots + n) * capacity;
        if self.capacity != capacity || self.series.len() != size {
            // The contents need not survive (each step writes before it reads): a stride
            // switching between steps reuses the allocations.
            self.capacity = capacity;
            self.series.clear();
            self.series.resize(size, 0.0);
            self.reciprocals.clear();
            self.reciprocals
                .extend((0..capacity).map(|k| 1.0 / (k + 1) as f64));
        }
        if self.lower.len() != n * n || self.coordinates != program.coordinates.len() {
            self.factored_mass.clear();
            self.factored_values.clear();
        }
        self.coordinates = program.coordinates.len();
        self.branch_points = !program.derived.branch_points.is_empty();
        self.lower.resize(n * n, 0.0);
        self.pivots.resize(n, 0.0);
        self.inverse_pivots.resize(n, 0.0);
        self.rhs.resize(n, 0.0);
    }
}

/// A model's Taylor method: its recurrences ([`TaylorProgram`]) and the code that runs them,
/// which [`series_of_motion`] drives. A model hands it out through one accessor,
/// [`MechanicalSystem::taylor`](crate::MechanicalSystem::taylor) (or
/// [`DynMechanicalSystem::taylor`](crate::DynMechanicalSystem::taylor)), the way it hands
/// out its description. The `model!` macro implements it for the struct it generates
/// (order 0 as straight-line code, every op's kernel inlined with its slots as constants, and
/// in optimised builds the fused orders); a model compiled at run time implements it with
/// its tape interpreted or compiled, and its orders on the kernels or compiled by Cranelift.
/// Every implementation computes the same bits.
///
/// Source: Jorba & Zou (2005, §2) for the recurrences; the layout of the series is
/// [`series_of_motion`]'s.
pub trait TaylorFunctions {
    /// The program: its ops, slots and the slots of the state, `M` and `F`.
    fn program(&self) -> &TaylorProgram;

    /// Order 0 of every slot of [`Self::program`] into `series` (slot `s` at
    /// `s · capacity`): the model's own evaluation of `M` and `F`, reading `q`, `q̇` and `t`
    /// from their slots, every intermediate value kept.
    fn order_zero(&self, capacity: usize, series: &mut [f64]);

    /// Order `k ≥ 1` of every slot the program's ops write (the slots that an op, `M` or `F`
    /// reads; others keep what the workspace held), from the orders below `k`. The default
    /// runs the program's ops on the kernels ([`evaluate_order`]).
    fn order(&self, k: usize, capacity: usize, series: &mut [f64]) {
        evaluate_order(&self.program().ops, k, capacity, series);
    }

    /// [`motion_order`] for `k = 0`, then orders `k = 1, 2, …` of the ops' slots, each
    /// followed by its [`motion_order`], stopping before `order`; returns the first order it
    /// did not compute, from which [`series_of_motion`] goes on one order at a time. The
    /// `model!` macro's code (when `solve` has the unrolled stride,
    /// [`MotionSolve::unrolled`]; optimised builds compile each order
    /// `k ≤ TaylorProgram::highest_unrolled_order` for that `k`) passes the values of an
    /// order's ops and solve in registers and lists its slots as constants; a run-time model's
    /// orders compiled by Cranelift do the same. The same bits as one order at a time. The
    /// default computes none and returns 0.
    fn orders(
        &self,
        solve: &mut MotionSolve<'_>,
        order: usize,
        series: &mut [f64],
        out: &mut [f64],
    ) -> usize {
        let _ = (solve, order, series, out);
        0
    }

    /// The highest order `k` that [`Self::orders`] computes when `solve` has the unrolled
    /// stride (0, the default, when it computes none). A step to a higher order then runs
    /// those orders fused and the rest one at a time at the same stride.
    fn fused_orders(&self) -> usize {
        0
    }
}

with_host_features! {
    /// The Taylor coefficients of the motion through `(t, y)`, `y = [q; q̇]` (`2n` entries), up
    /// to `order`: `out[k · 2n + i] = yᵢ^[k]` for `k = 0 … order` (so `out[..2n] = y`).
    ///
    /// With `m` constraints the program's matrix and right-hand side are `[M Jᵀ; J 0]` and
    /// `[F; γ]` ([`TaylorProgram`]), and each order solves for `[q̈; λ]`.
    ///
    /// # Errors
    /// [`RhsError::SingularMassMatrix`] if `M(q, t)` is not positive definite;
    /// [`RhsError::SingularConstraintMatrix`] if, with constraints, `J` has dependent rows
    /// (`−J M⁻¹ Jᵀ` is not negative definite);
    /// [`RhsError::NonFinite`] with the component of the first coefficient that is not finite.
    ///
    /// # Panics
    /// If `y` has fewer than `2n` entries or `out` fewer than `(order + 1) · 2n`.
    pub fn series_of_motion(
        model: &(impl TaylorFunctions + ?Sized),
        workspace: &mut TaylorWorkspace,
        t: f64,
        y: &[f64],
        order: usize,
        out: &mut [f64],
    ) -> Result<(), RhsError> {
        series_in(model, workspace, t, y, order, out)
    }
}

/// [`series_of_motion`]'s body, inlined into its two copies.
#[inline(always)]
fn series_in(
    model: &(impl TaylorFunctions + ?Sized),
    workspace: &mut TaylorWorkspace,
    t: f64,
    y: &[f64],
    order: usize,
    out: &mut [f64],
) -> Result<(), RhsError> {
    let program = model.program();
    let n = program.coordinates.len();
    let dim = 2 * n;
    // The unknowns of each order: `q̈`, then the multipliers `λ` of a constrained model.
    let unknowns = program.forcing.len();
    workspace.fit(program, unknowns, order, model.fused_orders());
    let c = workspace.capacity;
    let TaylorWorkspace {
        series: s,
        lower,
        pivots,
        inverse_pivots,
        nonzeros,
        rhs,
        reciprocals,
        lanes,
        factored_mass,
        factored_values,
        ..
    } = workspace;
    debug_assert!(
        program.derived == program.derive(),
        "TaylorProgram::derived is not with_derived()'s"
    );
    let inputs = &program.derived.inputs;
    let out = &mut out[..(order + 1) * dim];
    out[..dim].copy_from_slice(&y[..dim]);
    if order == 0 {
        return match out.iter().position(|v| !v.is_finite()) {
            Some(at) => Err(RhsError::NonFinite { index: at }),
            None => Ok(()),
        };
    }
    // Order 0: the state, t, the model's own evaluation and M⁰'s factors.
    for &(slot, index) in inputs.iter() {
        s[slot as usize * c] = y[index as usize];
    }
    if let Some(slot) = program.time {
        s[slot as usize * c] = t;
    }
    model.order_zero(c, s);
    let mass = |e: usize| s[program.mass_matrix[e] as usize * c];
    let factors = Factors {
        unknowns,
        positive: n,
        lower,
        pivots,
        inverse_pivots,
        nonzeros,
    };
    if program.derived.varying_mass_entries.is_empty() {
        // A constant M: factored again only when its entries changed (new parameters).
        let slots = &program.mass_matrix[..unknowns * unknowns];
        let same = factored_mass[..] == *slots
            && factored_values
                .iter()
                .all(|&(slot, bits)| s[slot as usize * c].to_bits() == bits);
        if !same {
            factored_mass.clear();
            factored_values.clear();
            factor_mass(mass, factors)?;
            factored_mass.extend_from_slice(slots);
            let mut distinct = slots.to_vec();
            distinct.sort_unstable();
            distinct.dedup();
            factored_values.extend(
                distinct
                    .into_iter()
                    .map(|slot| (slot, s[slot as usize * c].to_bits())),
            );
        }
    } else {
        // The factors become another M's.
        factored_mass.clear();
        factored_values.clear();
        factor_mass(mass, factors)?;
    }
    let layout = MotionLayout {
        forcing: &program.forcing,
        coupled: &program.derived.varying_mass_entries,
        inputs,
        time: program.time,
        accelerations: program.acceleration_slot(),
    };
    let mut solve = MotionSolve {
        n: unknowns,
        coordinates: n,
        c,
        // A factor with a zero below its diagonal is solved over the list of its non-zero
        // entries (faster for a sparse one: the figure eight's diagonal M; and the dense
        // loops never meet a zero, whose `b − 0·x` would not be `b` to the bit for `b = −0`
        // or `x` infinite). With constraints, always the sparse solve: the dense solve's unknowns are `q̈`
        // alone.
        dense: unknowns == n && 2 * nonzeros.len() >= n * n.saturating_sub(1),
        nonzeros,
        lower,
        inverse_pivots,
        reciprocals,
        rhs,
        lanes,
    };
    // The model's fused orders (compiled models with the unrolled stride), then the rest one
    // order at a time: order k of the ops (none at 0), of q̈, and order k + 1 of the state.
    let from = model.orders(&mut solve, order, s, out);
    for k in from..order {
        if k > 0 {
            model.order(k, c, s);
        }
        accelerations(&layout, &mut solve, k, s, out);
    }
    all_finite(out, dim)
}

/// `Ok` when every coefficient in `out` is finite, else the component (of `dim`) of the first
/// that is not. In line: part of the hot step, in its copy for the host's instruction set.
#[inline(always)]
fn all_finite(out: &[f64], dim: usize) -> Result<(), RhsError> {
    // Whether any exponent field is all ones (infinite or NaN), as one OR over the bits
    // (vectorised; a branch per value took 3 % of a double-pendulum step), then where.
    const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
    let any = out.iter().fold(0u64, |m, v| {
        m | u64::from(v.to_bits() & EXPONENT == EXPONENT)
    });
    match (any != 0)
        .then(|| out.iter().position(|v| !v.is_finite()))
        .flatten()
    {
        Some(at) => Err(RhsError::NonFinite { index: at % dim }),
        None => Ok(()),
    }
}

/// Where [`motion_order`] finds the series of `F`, of the entries of `M` that vary and of
/// the accelerations, and where it writes the state's next order: the same lists for a
/// program whether the run-time [`series_of_motion`] builds them from the program or the
/// `model!` macro prints them as constants (so that the compiler folds the loops over them
/// into straight-line code).
#[derive(Debug, Clone, Copy)]
pub struct MotionLayout<'a> {
    /// `F`'s slots ([`TaylorProgram::forcing`]), one per coordinate, then `γ`'s, one per
    /// constraint.
    pub forcing: &'a [Slot],
    /// [`DerivedLists::varying_mass_entries`].
    pub coupled: &'a [(u32, u32, Slot)],
    /// [`DerivedLists::inputs`].
    pub inputs: &'a [(Slot, u32)],
    /// [`TaylorProgram::time`].
    pub time: Option<Slot>,
    /// [`TaylorProgram::acceleration_slot`].
    pub accelerations: Slot,
}

/// `M⁰`'s factor and the stride of one [`series_of_motion`], for [`motion_order`], and the
/// workspace's scratch for a run-time backend's compiled orders ([`Self::lanes`]).
#[derive(Debug)]
pub struct MotionSolve<'a> {
    /// The unknowns of each order: `n` accelerations, then `m` multipliers.
    n: usize,
    /// `n`.
    coordinates: usize,
    c: usize,
    /// `L` has no zero below its diagonal.
    dense: bool,
    nonzeros: &'a [(u32, u32, f64)],
    /// `L`, row-major `n × n`.
    lower: &'a [f64],
    inverse_pivots: &'a [f64],
    reciprocals: &'a [f64],
    rhs: &'a mut [f64],
    lanes: &'a mut Vec<Lanes>,
}

impl MotionSolve<'_> {
    /// At least `units` of the workspace's scratch for a run-time backend, kept between
    /// steps (grown when a backend asks for more, never shrunk): what the orders of one step
    /// wrote is there for the orders above, in that step.
    #[inline]
    pub fn lanes(&mut self, units: usize) -> &mut [Lanes] {
        if self.lanes.len() < units {
            self.lanes.resize(units, Lanes::default());
        }
        &mut self.lanes[..]
    }

    /// Whether the workspace has the stride of the code compiled for each order
    /// ([`UNROLLED_CAPACITY`]), the one [`motion_order`] with `K ≠ 0` needs.
    #[inline]
    pub fn unrolled(&self) -> bool {
        self.c == UNROLLED_CAPACITY
    }

    /// `(L, D⁻¹)` (`L` row-major `n × n`, unit diagonal implied) when [`motion_order`] solves
    /// with them as a dense factor in registers — `n ≤ 6` and no zero below `L`'s diagonal —
    /// for a run-time backend that does the same: `L z = b` row by row, `z ← D⁻¹ z`, then
    /// `Lᵀ x = z` from the last row up; `None` when it solves over `L`'s non-zero entries.
    #[inline]
    pub fn dense_factor(&self) -> Option<(&[f64], &[f64])> {
        (self.n <= FIXED_DEGREES && self.dense).then(|| {
            (
                &self.lower[..self.n * self.n],
                &self.inverse_pivots[..self.n],
            )
        })
    }

    /// `(L, D⁻¹)` as [`Self::dense_factor`] gives them, for any `L` with `n ≤ 6` — with zeros
    /// below its diagonal too, whose updates a run-time backend that solves with it must skip
    /// (as [`motion_order`]'s solve over `L`'s non-zero entries does: `b − 0·x` is not `b` for
    /// `b = −0` or `x` infinite); `None` for larger `n`.
    #[inline]
    pub fn small_factor(&self) -> Option<(&[f64], &[f64])> {
        (self.n <= FIXED_DEGREES && self.n == self.coordinates).then(|| {
            (
                &self.lower[..self.n * self.n],
                &self.inverse_pivots[..self.n],
            )
        })
    }

    /// `D⁻¹` when `L` is the identity (no non-zero entry below its diagonal: a diagonal `M`),
    /// whose solve is then `x = D⁻¹ b` alone, for a run-time backend that does the same;
    /// `None` otherwise.
    #[inline]
    pub fn diagonal_factor(&self) -> Option<&[f64]> {
        (self.nonzeros.is_empty() && self.n == self.coordinates)
            .then(|| &self.inverse_pivots[..self.n])
    }
}

/// The largest `n` whose solves [`motion_order`] compiles for a known `n` (dense `L` in
/// registers).
const FIXED_DEGREES: usize = 6;

/// Order `k` of the accelerations `a` (into their slots) and order `k + 1` of the state
/// (into `out` and the input slots), once every slot holds its orders `≤ k`: `M⁰ a^[k] =
/// F^[k] − Σⱼ₌₁ᵏ M^[j] a^[k−j]` solved with the step's factor, `q^[k+1] = q̇^[k] / (k + 1)`,
/// `q̇^[k+1] = a^[k] / (k + 1)`, and `t`'s order `k + 1`.
///
/// `N` is `n` (the dense solve, `L` in registers, for `n ≤ 6`; larger `n` take the other),
/// or 0 for the solve over `L`'s non-zero entries, which the function takes anyway when `L`
/// has a zero below its diagonal; `K` is `k` for the code compiled for that order (the workspace
/// then has [`MotionSolve::unrolled`]'s stride), or 0. Every variant computes the same
/// bits. The orders follow each other through this function (order `k + 1` of every op
/// waits for `a^[k]`): the `model!` macro's code inlines it after each order's ops, with its
/// `layout` a constant.
///
/// # Panics
/// If `out` has fewer than `(k + 2) · 2n` entries, or `layout` and `s` are not those of the
/// [`series_of_motion`] `solve` comes from.
#[inline(always)]
pub fn motion_order<const N: usize, const K: usize>(
    layout: &MotionLayout<'_>,
    solve: &mut MotionSolve<'_>,
    k: usize,
    s: &mut [f64],
    out: &mut [f64],
) {
    if N != 0 && N <= FIXED_DEGREES && solve.dense {
        dense_order::<N, K>(layout, solve, k, s, out);
    } else {
        sparse_order::<K>(layout, solve, k, s, out);
    }
}

/// Order `k` of `M a = F` as [`motion_order`] computes it, for a run-time `n` and `k` (the
/// variant compiled for them): what a run-time backend's own fused orders call between its
/// orders (the JIT's Cranelift code), the same bits as a compiled model's.
///
/// # Panics
/// If `s` or `out` is too short for the layout and `k` (a program and workspace that do not
/// belong together).
pub fn motion_order_at(
    layout: &MotionLayout<'_>,
    solve: &mut MotionSolve<'_>,
    k: usize,
    s: &mut [f64],
    out: &mut [f64],
) {
    accelerations(layout, solve, k, s, out);
}

/// [`motion_order`] for the run-time `n` and `k`: the variant compiled for them.
#[inline]
fn accelerations(
    layout: &MotionLayout<'_>,
    solve: &mut MotionSolve<'_>,
    k: usize,
    s: &mut [f64],
    out: &mut [f64],
) {
    /// One variant, out of line (the dispatch would otherwise inline 7 × 20 of them).
    #[inline(never)]
    fn variant<const N: usize, const K: usize>(
        layout: &MotionLayout<'_>,
        solve: &mut MotionSolve<'_>,
        k: usize,
        s: &mut [f64],
        out: &mut [f64],
    ) {
        motion_order::<N, K>(layout, solve, k, s, out);
    }
    let unrolled = solve.unrolled();
    macro_rules! orders {
        ($n:literal; $($order:literal)*) => {
            match k {
                $($order if unrolled => variant::<$n, $order>(layout, solve, k, s, out),)*
                _ => variant::<$n, 0>(layout, solve, k, s, out),
            }
        };
    }
    const _: () = assert!(FIXED_DEGREES == 6);
    if !solve.dense {
        return unrolled_orders!(orders, 0);
    }
    match solve.n {
        1 => unrolled_orders!(orders, 1),
        2 => unrolled_orders!(orders, 2),
        3 => unrolled_orders!(orders, 3),
        4 => unrolled_orders!(orders, 4),
        5 => unrolled_orders!(orders, 5),
        6 => unrolled_orders!(orders, 6),
        _ => unrolled_orders!(orders, 0),
    }
}

/// [`motion_order`] with `L` dense, `n = N`.
#[inline(always)]
fn dense_order<const N: usize, const K: usize>(
    layout: &MotionLayout<'_>,
    solve: &MotionSolve<'_>,
    k: usize,
    s: &mut [f64],
    out: &mut [f64],
) {
    let (k, c) = known::<K>(k, solve.c);
    let mut b = [0.0; N];
    for (r, &slot) in b.iter_mut().zip(layout.forcing) {
        *r = at(s, c, slot, k);
    }
    coupled_sums::<K>(k, c, s, layout, &mut b);
    // L z = b, z ← D⁻¹ z, Lᵀ x = z, with L full (no zero below its diagonal).
    let lower = &solve.lower[..N * N];
    for i in 0..N {
        for j in 0..i {
            b[i] -= lower[i * N + j] * b[j];
        }
    }
    for (x, d) in b.iter_mut().zip(solve.inverse_pivots) {
        *x *= d;
    }
    for i in (0..N).rev() {
        for j in 0..i {
            b[j] -= lower[i * N + j] * b[i];
        }
    }
    next_order(layout, solve.reciprocals, k, c, s, &b, N, out);
}

/// [`motion_order`] over `L`'s non-zero entries, any `n`.
#[inline(always)]
fn sparse_order<const K: usize>(
    layout: &MotionLayout<'_>,
    solve: &mut MotionSolve<'_>,
    k: usize,
    s: &mut [f64],
    out: &mut [f64],
) {
    let (k, c) = known::<K>(k, solve.c);
    let b = &mut *solve.rhs;
    for (r, &slot) in b.iter_mut().zip(layout.forcing) {
        *r = at(s, c, slot, k);
    }
    coupled_sums::<K>(k, c, s, layout, b);
    self::solve(solve.nonzeros, solve.inverse_pivots, b);
    next_order(
        layout,
        solve.reciprocals,
        k,
        c,
        s,
        b,
        solve.coordinates,
        out,
    );
}

/// Stores `a^[k] = b` (`[q̈^[k]; λ^[k]]` with constraints) and the state's order `k + 1` (see
/// [`motion_order`]); `n` is the number of coordinates (`b`'s first `n` entries are `q̈^[k]`).
#[inline(always)]
#[allow(clippy::too_many_arguments)] // the solve's pieces, inlined into each variant
fn next_order(
    layout: &MotionLayout<'_>,
    reciprocals: &[f64],
    k: usize,
    c: usize,
    s: &mut [f64],
    b: &[f64],
    n: usize,
    out: &mut [f64],
) {
    let dim = 2 * n;
    let inverse = reciprocals[k];
    let (now, next) = out[k * dim..(k + 2) * dim].split_at_mut(dim);
    let (q_next, v_next) = next.split_at_mut(n);
    for i in 0..n {
        put(s, c, layout.accelerations + i as Slot, k, b[i]);
        q_next[i] = now[n + i] * inverse;
        v_next[i] = b[i] * inverse;
    }
    for (i, &multiplier) in b.iter().enumerate().skip(n) {
        put(s, c, layout.accelerations + i as Slot, k, multiplier);
    }
    if k + 1 < c {
        for &(slot, index) in layout.inputs {
            put(s, c, slot, k + 1, next[index as usize]);
        }
        if let Some(slot) = layout.time {
            put(s, c, slot, k + 1, if k == 0 { 1.0 } else { 0.0 });
        }
    }
}

/// `b[i] −= Σⱼ₌₁ᵏ M_il^[j] a_l^[k−j]` for each entry `(i, l, slot)` of `M` that varies (`k`
/// known when `K ≠ 0`; nothing at `k = 0`).
#[inline(always)]
fn coupled_sums<const K: usize>(
    k: usize,
    c: usize,
    s: &[f64],
    layout: &MotionLayout<'_>,
    b: &mut [f64],
) {
    let (k, c) = known::<K>(k, c);
    if k == 0 {
        return;
    }
    for &(i, l, slot) in layout.coupled {
        let m = &s[slot as usize * c + 1..][..k];
        let a = &series(s, c, layout.accelerations + l)[..k];
        // The sum apart from `b` (`F^[k]`, the order's last value), in increasing `j`:
        // formed while the order's ops run, then one subtraction (subtracting term by term
        // from `b` made the whole sum wait for `F^[k]`: 3–4 % of a double-pendulum run at
        // 10⁻⁹ and 10⁻¹²; the term of `a^[k−1]`, the newest, last instead of first: no
        // change).
        let mut sum = 0.0;
        for (x, y) in m.iter().zip(a.iter().rev()) {
            sum += x * y;
        }
        b[i as usize] -= sum;
    }
}

/// Where [`factor_mass`] writes the factor of an `unknowns × unknowns` matrix whose first
/// `positive` pivots are positive and the rest negative (see [`factor`]).
struct Factors<'a> {
    unknowns: usize,
    positive: usize,
    lower: &'a mut [f64],
    pivots: &'a mut [f64],
    inverse_pivots: &'a mut [f64],
    nonzeros: &'a mut Vec<(u32, u32, f64)>,
}

/// [`factor`] of `M` (entry `e` column-major is `mass(e)`; `[M Jᵀ; J 0]` with constraints,
/// [`RhsError::SingularConstraintMatrix`] when a pivot of its constraints' block fails), then the list of the factor's
/// entries below the diagonal that are not zero, which the solves of every order visit (a
/// model's `M` is often sparse: bodies that do not share a coordinate).
#[inline(always)]
fn factor_mass(mass: impl Fn(usize) -> f64, factors: Factors<'_>) -> Result<(), RhsError> {
    let Factors {
        unknowns: n,
        positive,
        lower,
        pivots,
        inverse_pivots,
        nonzeros,
    } = factors;
    factor(
        n,
        positive,
        |i, j| mass(i + j * n),
        lower,
        pivots,
        inverse_pivots,
    )
    .map_err(|pivot| {
        if pivot < positive {
            RhsError::SingularMassMatrix
        } else {
            RhsError::SingularConstraintMatrix
        }
    })?;
    nonzeros.clear();
    for i in 0..n {
        for (j, &l) in lower[i * n..i * n + i].iter().enumerate() {
            if l != 0.0 {
                nonzeros.push((i as u32, j as u32, l));
            }
        }
    }
    Ok(())
}

/// `L D Lᵀ` of the symmetric `n × n` matrix `m(i, j)` (lower triangle read) into `lower`
/// (row-major, unit diagonal implied), `pivots` (`D`) and `inverse_pivots` (`D⁻¹`, so that
/// each order's solve multiplies where it would divide), with the first `positive` pivots
/// positive and the rest negative; else `Err` with the first pivot that is not.
///
/// With `positive = n` that is `M` positive definite. With `positive = n` coordinates and
/// `m` constraints, `[M Jᵀ; J 0]` factors so exactly when `M` is positive definite and `J`
/// has full row rank: the last `m` pivots are those of the Schur complement `−J M⁻¹ Jᵀ`,
/// negative definite (the range-space method; Nocedal & Wright, *Numerical Optimization*,
/// 2nd ed., §16.2, and §16.1 on the inertia of such a matrix), so no pivoting is needed and
/// the factor's solves are `M`'s and those of the complement.
#[inline]
fn factor(
    n: usize,
    positive: usize,
    m: impl Fn(usize, usize) -> f64,
    lower: &mut [f64],
    pivots: &mut [f64],
    inverse_pivots: &mut [f64],
) -> Result<(), usize> {
    if n == 2 && positive == 2 {
        // The second pivot as `det M / M₁₁`, so that its reciprocal `M₁₁ / det M` does not
        // wait for the first (the two divisions run side by side; one after the other they
        // lay on the path from a step's order 0 to its order 1). Only where `det M` and that
        // reciprocal are normal numbers: `M₁₁ M₂₂` overflows or underflows for entries
        // beyond about 1e±154, where the loop below, which never forms it, still factors.
        let (m11, m21, m22) = (m(0, 0), m(1, 0), m(1, 1));
        let det = m11 * m22 - m21 * m21;
        let inverse_det = 1.0 / det;
        let second = m11 * inverse_det;
        if m11 > 0.0 && m11.is_finite() && det.is_normal() && det > 0.0 && second.is_normal() {
            let inverse = 1.0 / m11;
            pivots[0] = m11;
            inverse_pivots[0] = inverse;
            lower[2] = m21 * inverse;
            pivots[1] = det * inverse;
            inverse_pivots[1] = second;
            return Ok(());
        }
    }
    for j in 0..n {
        let mut d = m(j, j);
        for k in 0..j {
            d -= lower[j * n + k] * lower[j * n + k] * pivots[k];
        }
        // Not of its sign (positive, then negative), or NaN.
        let signed = if j < positive { d } else { -d };
        if signed.is_nan() || signed <= 0.0 {
            return Err(j);
        }
        let inverse = 1.0 / d;
        pivots[j] = d;
        inverse_pivots[j] = inverse;
        for i in j + 1..n {
            let mut v = m(i, j);
            for k in 0..j {
                v -= lower[i * n + k] * lower[j * n + k] * pivots[k];
            }
            lower[i * n + j] = v * inverse;
        }
    }
    Ok(())
}

/// Solves `L D Lᵀ x = b` in place, with `L`'s entries below the diagonal that are not zero
/// listed row by row as `(row, column, value)` and `inverse_pivots` = `D⁻¹`.
#[inline(always)]
fn solve(nonzeros: &[(u32, u32, f64)], inverse_pivots: &[f64], b: &mut [f64]) {
    // L z = b, row by row: each row's earlier entries are final when it is reached.
    for &(i, j, l) in nonzeros {
        b[i as usize] -= l * b[j as usize];
    }
    for (x, d) in b.iter_mut().zip(inverse_pivots) {
        *x *= d;
    }
    // Lᵀ x = z, from the last row of L up: x[row] is final before its column is updated.
    for &(i, j, l) in nonzeros.iter().rev() {
        b[j as usize] -= l * b[i as usize];
    }
}

/// `x.fract() == 0.0` (false for infinities and NaN), without the call `trunc` is in the
/// runtime's baseline build (8 % of the branch check's instructions on the figure eight):
/// every finite `f64` of magnitude `2⁵²` or more is an integer, and below that the conversion
/// to `i64` is exact for the integers and truncates the rest.
fn is_integer(x: f64) -> bool {
    const EXACT: f64 = 4_503_599_627_370_496.0; // 2⁵²
    let a = x.abs();
    (EXACT..f64::INFINITY).contains(&a) || (x as i64) as f64 == x
}

/// The largest step `τ ≤ h` over which the series of the last [`series_of_motion`] into
/// `workspace` (of `program`, to `order`) stay on the principal branch of every square root
/// (`Sqrt`, and the `√(1 − a²)` of `Asin`) and of every power with a non-integer exponent.
///
/// A root of a near-perfect square hides its branch point from the series: `√(u² + δ²)`
/// with `δ` tiny has coefficients that read as those of `u`, so the radius of convergence
/// estimated from the last orders is `u`'s, and a step through `u = 0` continues the series
/// as `u` — negative — where the root is `|u|`. This is the speed `√(ẋ² + ẏ²)` of a
/// quadratic drag at the top of a vertical throw (the drag would push along the motion on
/// the way down), `(ẋ² + ẏ²)^{3/2}` likewise, and `acos(cos q)` at `q = 0`.
///
/// For each such op, `f = g^α`, whose argument can come near 0 in the step
/// (`Σₖ₌₁ |gᵏ| hᵏ ≥ g⁰/2`; for `Asin`'s root, whose argument has no series of its own, when
/// `Σₖ₌₁ |fᵏ| hᵏ ≥ f⁰`), the step is sampled at
/// 16 points: at the first where `f` or `g` has left its sign at `τ = 0`, or `f` is no longer
/// `g^α` to 10⁻³ of `max(|f|, |f⁰|)` (near a hidden branch point the higher orders of `f`
/// are rounding errors divided by powers of `f⁰`), or either is not finite, the point is
/// located by bisection (to `h / 2³⁴`) and the step is half of it. Halving toward that
/// point each step, the method either reaches where the branch point shows in the
/// coefficients (`δ` not tiny: small steps pass it) or its step falls below the smallest
/// usable one — the motion is not analytic there, and the run ends with
/// [`StepSizeTooSmall`](crate::IntegrationError::StepSizeTooSmall) at that time. Between
/// samples nothing is checked.
///
/// The result is unspecified (it may panic) unless `workspace` holds the series of
/// `program` to `order` from the last [`series_of_motion`].
pub fn branch_step(
    program: &TaylorProgram,
    workspace: &TaylorWorkspace,
    order: usize,
    h: f64,
) -> f64 {
    // Through a constant series the step is infinite: nothing to bound; nor without a root
    // or power.
    if !h.is_finite() || order == 0 || program.derived.branch_points.is_empty() {
        return h;
    }
    let c = workspace.capacity;
    // Orders 0 … order − 1 of the program's slots are computed.
    let degree = order - 1;
    let s = &workspace.series;
    let mut limit = h;
    for &index in program.derived.branch_points.iter() {
        // An index past the ops (a `derived` not made from this program) names no op.
        let Some(&op) = program.ops.get(index as usize) else {
            continue;
        };
        let (out, argument, alpha) = match op {
            SeriesOp::Sqrt { out, a } => (out, Argument::Slot(a), 0.5),
            SeriesOp::Asin { a, root, .. } => (root, Argument::OneMinusSquare(a), 0.5),
            SeriesOp::PowConstant { out, a, exponent } => {
                let alpha = s[exponent as usize * c];
                if is_integer(alpha) {
                    continue;
                }
                (out, Argument::Slot(a), alpha)
            }
            _ => continue,
        };
        // A root or a real power of a positive argument is positive; anything else (a
        // model's NaN, an exact 0) is not this check's to judge.
        // Order 0 read as it is: the series at τ = 0 by Horner's rule would be the same value
        // for the finite series a step has here (`series_of_motion` refuses any other), after
        // a chain of `order` dependent multiply–adds (two of three such chains per power
        // per step, on the figure eight's r⁻³).
        let f = &s[out as usize * c..][..=degree];
        let start = f[0];
        if !(start > 0.0 && start < f64::INFINITY) {
            continue;
        }
        // Where the argument's series cannot fall below half its start in the step
        // (Σₖ₌₁ |gᵏ| τᵏ < g⁰/2), the branch point g = 0 is away from the step and f = g^α is
        // its series (the usual case, decided by one sum); for `Asin`'s root, whose argument
        // 1 − a² has no series of its own, where f cannot change sign (Σₖ₌₁ |fᵏ| τᵏ < f⁰).
        let moved = |series: &[f64]| {
            series[1..]
                .iter()
                .rev()
                .fold(0.0, |v, &x| v * limit + x.abs())
                * limit
        };
        let far = match argument {
            Argument::Slot(a) => {
                let g = &s[a as usize * c..][..=degree];
                moved(g) < 0.5 * g[0]
            }
            Argument::OneMinusSquare(_) => moved(f) < start,
        };
        if !far && let Some(off) = first_off_branch(s, c, degree, (out, argument, alpha), limit) {
            limit = 0.5 * off;
        }
    }
    limit
}

/// The argument of a root or power: a slot, or `1 − a²` of `Asin`'s slot `a`.
#[derive(Clone, Copy)]
enum Argument {
    Slot(Slot),
    OneMinusSquare(Slot),
}

/// [`branch_step`]'s samples of `f = g^α` (`out`, its `argument` and `α`) over `[0, limit]`
/// in `series` (stride `c`, orders to `degree`): the first point where `f` or `g` has left
/// its sign, or `f` is no longer `g^α` to 10⁻³, or either is not finite (bisected to `limit /
/// 2³⁴`); `None` where every sample is on the branch, or where the argument at `τ = 0` is not
/// positive (NaN included). A function of its own, out of line, so that the loop over the
/// points, which the usual step leaves without a sample, keeps its registers.
#[cold]
#[inline(never)]
fn first_off_branch(
    series: &[f64],
    c: usize,
    degree: usize,
    (out, argument, alpha): (Slot, Argument, f64),
    limit: f64,
) -> Option<f64> {
    let value = |slot: Slot, tau: f64| {
        series[slot as usize * c..][..=degree]
            .iter()
            .rev()
            .fold(0.0, |v, &x| v * tau + x)
    };
    let argument_at = |tau: f64| match argument {
        Argument::Slot(a) => value(a, tau),
        Argument::OneMinusSquare(a) => {
            let x = value(a, tau);
            1.0 - x * x
        }
    };
    // Also skips a NaN argument.
    if argument_at(0.0).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let start = series[out as usize * c];
    // Written so that a NaN is off the branch.
    let off = |tau: f64| {
        let (f, g) = (value(out, tau), argument_at(tau));
        let on = f > 0.0 && g > 0.0 && (f - g.powf(alpha)).abs() <= 1e-3 * f.max(start);
        !on
    };
    const SAMPLES: usize = 16;
    let j = (1..=SAMPLES).find(|&j| off(limit * j as f64 / SAMPLES as f64))?;
    let (mut below, mut above) = (
        limit * (j - 1) as f64 / SAMPLES as f64,
        limit * j as f64 / SAMPLES as f64,
    );
    for _ in 0..30 {
        let middle = 0.5 * (below + above);
        if off(middle) {
            above = middle;
        } else {
            below = middle;
        }
    }
    Some(above)
}

#[cfg(test)]
mod tests {
    use super::{factor, is_integer};

    /// `is_integer` is `fract() == 0` on the integers, the halves around them, the limits of
    /// the exact conversion and the values that are not finite.
    #[test]
    fn is_integer_is_fract_equal_to_zero() {
        let exact = 4_503_599_627_370_496.0_f64;
        let mut cases = vec![
            0.0,
            -0.0,
            1.5,
            -1.5,
            0.5,
            1e-300,
            exact,
            exact - 0.5,
            exact + 1.0,
            9.3e18,
            1e300,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
        ];
        cases.extend((-40..=40).map(|i| i as f64 * 0.25));
        for x in cases {
            for x in [
                x,
                -x,
                f64::from_bits(x.to_bits() + 1),
                f64::from_bits(x.to_bits().wrapping_sub(1)),
            ] {
                assert_eq!(is_integer(x), x.fract() == 0.0, "{x:e}");
            }
        }
    }

    /// `L D Lᵀ` reproduces the matrix (to rounding: a few ulps of its largest entry), for two
    /// coordinates (the closed form) and three (the loops), and a matrix that is not positive
    /// definite, or NaN, has no factor.
    #[test]
    fn factor_reproduces_the_matrix_and_refuses_what_is_not_positive_definite() {
        let cases: [&[f64]; 3] = [
            &[4.0, 1.5, 1.5, 2.0],
            &[1e-3, 2e-4, 2e-4, 5e2],
            &[4.0, 1.0, 0.5, 1.0, 3.0, -0.7, 0.5, -0.7, 2.0],
        ];
        for m in cases {
            let n = (m.len() as f64).sqrt() as usize;
            let (mut lower, mut d, mut inverse) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
            factor(n, n, |i, j| m[i + j * n], &mut lower, &mut d, &mut inverse).expect("a factor");
            let l = |i: usize, j: usize| match i.cmp(&j) {
                std::cmp::Ordering::Equal => 1.0,
                std::cmp::Ordering::Greater => lower[i * n + j],
                std::cmp::Ordering::Less => 0.0,
            };
            let largest = m.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            for i in 0..n {
                assert!(
                    (d[i] * inverse[i] - 1.0).abs() < 4.0 * f64::EPSILON,
                    "{m:?}"
                );
                for j in 0..n {
                    let v: f64 = (0..n).map(|k| l(i, k) * d[k] * l(j, k)).sum();
                    assert!(
                        (v - m[i + j * n]).abs() <= 8.0 * f64::EPSILON * largest,
                        "{m:?}: ({i}, {j}) {v}"
                    );
                }
            }
        }
        // The index-1 matrix `[M Jᵀ; J 0]` of two coordinates and one constraint: positive
        // pivots for `M`, a negative one for `−J M⁻¹ Jᵀ`, and `L D Lᵀ` reproduces it. (Entry
        // `(r, c)`, each row and column from 2 on a constraint `j`.)
        let index_one = |m: [f64; 4], j: [f64; 2]| {
            move |r: usize, c: usize| match (r < 2, c < 2) {
                (true, true) => m[r + 2 * c],
                (true, false) => j[r],
                (false, true) => j[c],
                (false, false) => 0.0,
            }
        };
        let (m, j) = ([4.0, 1.0, 1.0, 3.0], [0.6, 0.8]);
        let kkt = index_one(m, j);
        let (mut lower, mut d, mut inverse) = (vec![0.0; 9], vec![0.0; 3], vec![0.0; 3]);
        factor(3, 2, kkt, &mut lower, &mut d, &mut inverse).expect("a factor");
        assert!(d[0] > 0.0 && d[1] > 0.0 && d[2] < 0.0, "{d:?}");
        // −J M⁻¹ Jᵀ with M⁻¹ = [3 −1; −1 4] / 11.
        let schur = -(3.0 * 0.36 - 2.0 * 0.48 + 4.0 * 0.64) / 11.0;
        assert!(
            (d[2] - schur).abs() <= 4.0 * f64::EPSILON * schur.abs(),
            "{d:?}"
        );
        for r in 0..3 {
            for c in 0..3 {
                let l = |i: usize, k: usize| match i.cmp(&k) {
                    std::cmp::Ordering::Equal => 1.0,
                    std::cmp::Ordering::Greater => lower[i * 3 + k],
                    std::cmp::Ordering::Less => 0.0,
                };
                let v: f64 = (0..3).map(|k| l(r, k) * d[k] * l(c, k)).sum();
                assert!(
                    (v - kkt(r, c)).abs() <= 8.0 * f64::EPSILON * 4.0,
                    "({r}, {c}) {v}"
                );
            }
        }
        // The same constraint twice (dependent rows, a 4 × 4 matrix): the second constraint's
        // pivot is 0, the constraints' block fails (index ≥ n); an `M` that is not positive
        // definite fails within the coordinates' block (index < n).
        let (mut lower, mut d, mut inverse) = (vec![0.0; 16], vec![0.0; 4], vec![0.0; 4]);
        let dependent = factor(4, 2, index_one(m, j), &mut lower, &mut d, &mut inverse);
        assert_eq!(dependent, Err(3));
        let indefinite = index_one([1.0, 2.0, 2.0, 1.0], j);
        let (mut lower, mut d, mut inverse) = (vec![0.0; 9], vec![0.0; 3], vec![0.0; 3]);
        assert_eq!(
            factor(3, 2, indefinite, &mut lower, &mut d, &mut inverse),
            Err(1)
        );
        // Beyond the closed form's range (`M₁₁ M₂₂` overflows or underflows): the loop's
        // factor, exact for these diagonal and scaled matrices.
        for scale in [1e160, 1e200, 1e-160, 1e-170] {
            let m = [scale, 0.5 * scale, 0.5 * scale, scale];
            let (mut lower, mut d, mut inverse) = ([0.0; 4], [0.0; 2], [0.0; 2]);
            factor(2, 2, |i, j| m[i + j * 2], &mut lower, &mut d, &mut inverse).expect("a factor");
            assert_eq!((d[0], lower[2]), (scale, 0.5), "{scale:e}");
            assert!(
                (d[1] / (0.75 * scale) - 1.0).abs() < 4.0 * f64::EPSILON,
                "{scale:e}: {d:?}"
            );
            assert!(
                (inverse[1] * d[1] - 1.0).abs() < 4.0 * f64::EPSILON,
                "{scale:e}"
            );
        }
        let refused: [&[f64]; 4] = [
            &[1.0, 2.0, 2.0, 1.0],
            &[-1.0, 0.0, 0.0, 1.0],
            &[1.0, f64::NAN, f64::NAN, 1.0],
            &[1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        ];
        for m in refused {
            let n = (m.len() as f64).sqrt() as usize;
            let (mut lower, mut d, mut inverse) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
            assert!(
                factor(n, n, |i, j| m[i + j * n], &mut lower, &mut d, &mut inverse).is_err(),
                "{m:?}"
            );
        }
    }
}
