//! The functions of model files whose every evaluation must agree to the bit: the non-smooth
//! `sign` and `step`, and the power `powf`. The code `eomgen::model!` generates calls them
//! (through `eomgen::__private`), and the code compiled at run time calls them or computes
//! their operations in line, so that both evaluate the very same function.

/// Sign of `x`: −1, 0 or 1 (unlike `f64::signum`, 0 at 0; 0 for NaN).
#[inline]
pub fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Heaviside step: 1 for `x ≥ 0`, else 0 (also for NaN).
#[inline]
pub fn step(x: f64) -> f64 {
    if x >= 0.0 { 1.0 } else { 0.0 }
}

/// The largest `m` for which [`powf`] takes `x^{±(m + ½)}` as `xᵐ √x` (exponents ±3/2 to
/// ±17/2).
pub const HALF_POWER_MAX: u32 = 8;

/// `m` when `y = ±(m + ½)` with `1 ≤ m ≤` [`HALF_POWER_MAX`], with `y`'s sign: the exponents
/// [`powf`] takes through a square root.
#[inline]
pub fn half_power(y: f64) -> Option<(u32, bool)> {
    // Exact: a product by 2 (and no overflow within the range tested).
    let twice = 2.0 * y.abs();
    // False for NaN.
    if !(3.0..=(2 * HALF_POWER_MAX + 1) as f64).contains(&twice) {
        return None;
    }
    let n = twice as u32;
    (f64::from(n) == twice && n % 2 == 1).then_some(((n - 1) / 2, y < 0.0))
}

/// `xᵐ` for `m ≥ 1` by repeated squaring from the lowest bit, the first set bit taken as it is
/// (`1 · x = x`): the products of the tape's `powi` and of LLVM's expansion of `f64::powi`,
/// in the same order; 1 for `m = 0`.
#[inline]
pub fn powi_by_squaring(x: f64, m: u32) -> f64 {
    squaring(x, m, |a, b| a * b).unwrap_or(1.0)
}

/// [`powi_by_squaring`]'s products, each made by `mul` (`None` for `m = 0`): what the code
/// compiled at run time emits the same products with, in the same order.
#[inline]
pub fn squaring<T: Copy>(x: T, m: u32, mut mul: impl FnMut(T, T) -> T) -> Option<T> {
    let (mut bits, mut square, mut result) = (m, x, None);
    while bits != 0 {
        if bits & 1 == 1 {
            result = Some(match result {
                None => square,
                Some(r) => mul(r, square),
            });
        }
        bits >>= 1;
        if bits != 0 {
            square = mul(square, square);
        }
    }
    result
}

/// `xʸ` as every backend evaluates a model's power with an exponent other than ½, −½ or an
/// integer (those are `sqrt`, `1/sqrt` and `powi`): for `y = ±(m + ½)` with `1 ≤ m ≤`
/// [`HALF_POWER_MAX`] (the gravitational `r⁻³ = (r²)^{−3/2}`), `p = |xᵐ √x|` with `xᵐ` by
/// [`powi_by_squaring`], and `p` or `1/p`; for any other `y`, `f64::powf`.
///
/// The square root and a few products cost a tenth of `pow` (a call, and in code compiled
/// at run time the registers saved around it): on the figure eight, whose three `r⁻³` are
/// such powers, a Taylor step took 4.9 % fewer instructions (docs/performance.md, "Fewer
/// instructions per step"). The code
/// `model!` generates calls this function, and the code compiled at run time computes the
/// same operations in line, so both give the same bits.
///
/// # Accuracy
/// Within `m + 2` units in the last place of `xʸ` (each product and the root round once; the
/// reciprocal once more), against `pow`'s one: for `m = 1`, `x √x` within 1 ulp and
/// `1/(x √x)` within 1.5. The same values as `pow` at `±0` (through the absolute value),
/// `+∞` and NaN; NaN for a negative `x`, as `pow`, and for `x = −∞` (where `pow` gives `+∞`
/// or `+0`). For a negative `y` near the limits of `f64`, where `p = x^{m+½}` itself is out
/// of the normal range: `+0` where `p` overflows and `pow` gives a subnormal, and a few ulp
/// more where `p` is subnormal (results above a quarter of the largest `f64`).
///
/// Source: the square-root expansion of `pow(x, n + 0.5)` in LLVM's library-call
/// simplifier (`x · x ⋯ √x`), which applies it under relaxed floating-point rules only.
#[inline]
pub fn powf(x: f64, y: f64) -> f64 {
    match half_power(y) {
        Some((m, negative)) => {
            let p = (powi_by_squaring(x, m) * x.sqrt()).abs();
            if negative { 1.0 / p } else { p }
        }
        None => x.powf(y),
    }
}

#[cfg(test)]
mod tests {
    use super::{HALF_POWER_MAX, half_power, powf};

    /// The half-integer exponents and no others.
    #[test]
    fn half_powers_are_the_half_integers_from_three_halves() {
        for m in 1..=HALF_POWER_MAX {
            let y = f64::from(m) + 0.5;
            assert_eq!(half_power(y), Some((m, false)));
            assert_eq!(half_power(-y), Some((m, true)));
        }
        for y in [
            0.0,
            0.5,
            -0.5,
            1.0,
            2.0,
            -3.0,
            1.25,
            1.5000000000000002,
            9.5,
            -9.5,
            1e300,
            f64::INFINITY,
            f64::NAN,
        ] {
            assert_eq!(half_power(y), None, "{y}");
        }
    }

    /// Within `m + 2` ulp of `pow` on x from 1e-3 to 1e3 (2,000 values a power), and `pow`'s
    /// values at the special points but −∞.
    #[test]
    fn half_powers_are_within_a_few_ulp_of_pow() {
        let ulps = |a: f64, b: f64| (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs();
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for m in 1..=HALF_POWER_MAX {
            for sign in [1.0, -1.0] {
                let y = sign * (f64::from(m) + 0.5);
                let mut worst = 0;
                for _ in 0..2000 {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    let u = (state >> 11) as f64 / (1u64 << 53) as f64;
                    let x = 10f64.powf(6.0 * u - 3.0);
                    worst = worst.max(ulps(powf(x, y), x.powf(y)));
                }
                assert!(worst <= u64::from(m) + 2, "y = {y}: {worst} ulp");
            }
            for y in [f64::from(m) + 0.5, -(f64::from(m) + 0.5)] {
                for x in [0.0, -0.0, f64::INFINITY, f64::NAN, -1.0, 1.0, 4.0] {
                    let (ours, theirs) = (powf(x, y), x.powf(y));
                    assert!(
                        ours.to_bits() == theirs.to_bits() || (ours.is_nan() && theirs.is_nan()),
                        "{x}^{y}: {ours} against {theirs}"
                    );
                }
                assert!(powf(f64::NEG_INFINITY, y).is_nan());
            }
        }
        // Any other exponent is `pow`'s.
        assert_eq!(
            powf(2.0, 1.0 / 3.0).to_bits(),
            2f64.powf(1.0 / 3.0).to_bits()
        );
    }
}
