//! The recurrence of each op of a [`TaylorProgram`](super::TaylorProgram) (its kernel: order `k` of
//! the op's value from the orders below `k` of its operands) and [`evaluate_order`], which runs a
//! program's ops one order at a time. The `model!` macro's code calls the kernels op by op with its
//! slots as constants; a run-time model reaches them through [`apply`].
//!
//! Source: Jorba & Zou (2005), §2; Biscani & Izzo (2021) and heyoka's `doc/ad_notes.rst`.

use super::slots::{at, known, put, series};
use eomgen_description::taylor::{SeriesOp, Slot, UNROLLED_CAPACITY};
use wide::f64x2;

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
/// formed once, `(2 h + [k even] a[k/2]²) + (2 a[0]) a[k]` with `h = Σ_{j=1}^{⌊(k−1)/2⌋}
/// a[j] a[k − j]` in increasing `j`; the term that holds order `k` last, as in [`cauchy`],
/// with `2 a[0]` formed before `a[k]` is known (one multiplication after it instead of two;
/// the same value as `2 (a[0] a[k])` unless that product is subnormal or `2 a[0]` overflows).
/// (Jorba & Zou 2005, §2.1; heyoka's `square`.) Half the products of the Cauchy product
/// (a sixth of the figure eight's products at order 12 are squares' halves).
#[inline(always)]
fn square(a: &[f64], k: usize) -> f64 {
    let half = convolution(a, a, k, 1, (k - 1) / 2);
    let mut sum = half + half;
    if k.is_multiple_of(2) {
        sum += a[k / 2] * a[k / 2];
    }
    sum + (2.0 * a[0]) * a[k]
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

/// `n · (1/d)`: the quotient of a recurrence whose divisor `d` is formed from order-0
/// coefficients (`b⁰`, `k a⁰`, `2 f⁰`, …), as a product with its reciprocal.
///
/// Order `k`'s numerator waits for the operands' order `k`, its divisor does not, so the
/// division runs beside the numerator's sum and only a multiplication stays on the path from
/// one order to the next (about 4 cycles instead of 13–14 on x86-64). On the Kepler orbit and
/// the central force, whose `r⁻³` is a power on that path, whole runs took 0.90–0.92 of the
/// time at tolerances 1e-6 to 1e-12, with the square's and the power's last terms below
/// (docs/performance.md, "What heyoka executes a step"). Two roundings instead of one: the
/// quotient is within 1.5 ulp rather than 0.5, far inside the truncation error of the series,
/// while `1/d` is a normal number (`|d|` between about 2⁻¹⁰²⁴ and 2¹⁰²²; beyond, `1/d` is
/// infinite or subnormal, and a zero numerator over a tiny divisor gives NaN, which fails the
/// step, where the division gave 0).
/// The run-time compiler's kernels (`eomgen_jit`) form it the same way, so both give these
/// bits.
#[inline(always)]
fn over(n: f64, d: f64) -> f64 {
    n * (1.0 / d)
}

/// Order `k ≥ 1` of [`SeriesOp::Div`].
#[inline(always)]
pub fn div<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot, a: Slot, b: Slot) {
    let (k, c) = known::<K>(k, c);
    let sum = convolution(series(s, c, b), series(s, c, out), k, 1, k);
    let v = over(at(s, c, a, k) - sum, at(s, c, b, 0));
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
    let v = over(-sum, at(s, c, b, 0));
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
    let v = over(at(s, c, a, k) - sum, 2.0 * o[0]);
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
    // Decreasing j: the term with x[k], this order's, comes last (see `cauchy`), and as
    // `x[k] (kα o[0])`, whose weight and `o[0]` are multiplied before `x[k]` is known.
    let mut sum = 0.0;
    for j in (1..k).rev() {
        sum += (kf * alpha - j as f64 * (alpha + 1.0)) * x[k - j] * o[j];
    }
    sum += x[k] * ((kf * alpha) * o[0]);
    let v = over(sum, kf * x[0]);
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
    let v = over(kf * x[k] - sum, kf * x[0]);
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
    let rk = over(-a2 - sum, 2.0 * r[0]);
    let sign = if acos { -1.0 } else { 1.0 };
    let sum = if k > 1 {
        weighted_convolution(series(s, c, out), r, k, 1, k - 1)
    } else {
        0.0
    };
    let v = over(sign * kf * x[k] - sum, kf * r[0]);
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
    let v = over(kf * x[k] - sum, kf * (1.0 + sq[0]));
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
    let v = over(cross - sum, kf * ns[0]);
    put(s, c, out, k, v);
}

/// Order `k ≥ 1` of [`SeriesOp::Zero`].
#[inline(always)]
pub fn zero<const K: usize>(k: usize, c: usize, s: &mut [f64], out: Slot) {
    let (k, c) = known::<K>(k, c);
    put(s, c, out, k, 0.0);
}

/// Order `k ≥ 1` of every series of `ops`, in order ([`apply`] for each): the run-time
/// model's orders, compiled for `K = k` when `k ≤` [`UNROLLED_ORDERS`](super::UNROLLED_ORDERS)
/// and `capacity` is [`UNROLLED_CAPACITY`], else for any order.
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
