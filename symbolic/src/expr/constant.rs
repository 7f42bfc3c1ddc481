//! Exact-when-possible numeric constants: reduced rationals `p/q` (i64), else `f64`.
//!
//! Rationals keep the derivation exact (`1/2 + 1/2 = 1`, `(1/3)·3 = 1`), which makes
//! canonical forms and symbolic equality reliable. Overflow falls back to `f64`. The `f64`
//! is stored as its bit pattern (with `-0.0` normalised to `0.0`) so that constants are
//! `Eq + Hash` and can be hash-consed; NaN is never stored.
//!
//! Every `f64` computed from constants passes [`fold`], the one rule for what a folded
//! number may be: finite, and not lost to underflow (see [`FoldError`]).

/// Why an operation on numbers has no value that a constant may hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum FoldError {
    /// The result is beyond ±1.8e308 (`f64::MAX`): `1e308*10`, `10^400`.
    #[error("the result is beyond ±1.8e308, the largest a double holds")]
    Overflow,
    /// The result of non-zero numbers is below 2.2e-308 (`f64::MIN_POSITIVE`), the smallest
    /// normal double: it came out 0 (`1e-300*1e-300`) or subnormal, with fewer than the 53
    /// significant bits of every other number, so that a term would vanish or lose its
    /// precision without a word.
    #[error(
        "the result is below 2.2e-308, the smallest normal double, and would be rounded to 0 or lose its precision"
    )]
    Underflow,
    /// The result is not a real number (NaN): `0/0`, `ln(-1)`.
    #[error("the result is not a real number")]
    Undefined,
}

/// The one rule for a number computed from constants: `value` is kept if it is finite and,
/// unless it is an exact 0 (`exact_zero`: `1 - 1`, `ln(1)`), normal.
///
/// Sums pass `exact_zero = true` when their value is 0 (a sum that cancels is exact in
/// binary floating point); products, powers and functions of non-zero numbers pass `false`,
/// since their exact value is not 0.
///
/// # Errors
/// [`FoldError::Undefined`] for NaN, [`FoldError::Overflow`] for ±∞,
/// [`FoldError::Underflow`] for a subnormal value, or 0 that is not exact.
pub fn fold(value: f64, exact_zero: bool) -> Result<f64, FoldError> {
    if value.is_nan() {
        Err(FoldError::Undefined)
    } else if value.is_infinite() {
        Err(FoldError::Overflow)
    } else if value == 0.0 && !exact_zero || value != 0.0 && !value.is_normal() {
        Err(FoldError::Underflow)
    } else {
        Ok(value)
    }
}

/// A constant in an expression.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Constant {
    /// `num / den` in lowest terms with `den > 0`.
    Rational {
        /// Numerator.
        num: i64,
        /// Denominator, positive.
        den: i64,
    },
    /// A finite `f64` stored as its bits.
    Float(u64),
}

fn gcd(mut a: i64, mut b: i64) -> i64 {
    a = a.abs();
    b = b.abs();
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

impl Constant {
    /// Zero.
    pub const ZERO: Constant = Constant::Rational { num: 0, den: 1 };
    /// One.
    pub const ONE: Constant = Constant::Rational { num: 1, den: 1 };
    /// Minus one.
    pub const MINUS_ONE: Constant = Constant::Rational { num: -1, den: 1 };

    /// The integer `n`.
    pub fn int(n: i64) -> Self {
        Constant::Rational { num: n, den: 1 }
    }

    /// `num/den` reduced; `None` if `den == 0` or reduction overflows.
    pub fn rational(num: i64, den: i64) -> Option<Self> {
        if den == 0 {
            return None;
        }
        let g = gcd(num, den);
        let (mut n, mut d) = (num / g, den / g);
        if d < 0 {
            n = n.checked_neg()?;
            d = d.checked_neg()?;
        }
        Some(Constant::Rational { num: n, den: d })
    }

    /// A float constant, or `None` if `x` is not finite. Integral floats that fit in
    /// 2⁵³ become rationals.
    pub fn float(x: f64) -> Option<Self> {
        if !x.is_finite() {
            return None;
        }
        if x.fract() == 0.0 && x.abs() < 9.0e15 {
            return Some(Constant::int(x as i64));
        }
        Some(Constant::Float(if x == 0.0 { 0.0f64 } else { x }.to_bits()))
    }

    /// Parses a decimal literal (`0.5`, `12`, `1e-3`, `2.5E+2`) exactly as a rational when it
    /// fits, else as `f64`. `None` for text that is not a number.
    pub fn parse_decimal(text: &str) -> Option<Self> {
        let value: f64 = text.parse().ok()?;
        let lower = text.to_ascii_lowercase();
        let (mantissa, exponent) = match lower.split_once('e') {
            Some((m, e)) => (m, e.parse::<i32>().ok()?),
            None => (lower.as_str(), 0),
        };
        let (int_part, frac_part) = mantissa.split_once('.').unwrap_or((mantissa, ""));
        let digits = format!("{int_part}{frac_part}");
        let scale = exponent - frac_part.len() as i32;
        let exact = (|| {
            let mut num: i64 = digits.parse().ok()?;
            let mut den: i64 = 1;
            if scale >= 0 {
                num = num.checked_mul(10i64.checked_pow(scale as u32)?)?;
            } else {
                den = 10i64.checked_pow((-scale) as u32)?;
            }
            Constant::rational(num, den)
        })();
        exact.or_else(|| Constant::float(value))
    }

    /// The value as `f64`.
    pub fn to_f64(self) -> f64 {
        match self {
            Constant::Rational { num, den } => num as f64 / den as f64,
            Constant::Float(bits) => f64::from_bits(bits),
        }
    }

    /// Whether this is exactly zero.
    pub fn is_zero(self) -> bool {
        match self {
            Constant::Rational { num, .. } => num == 0,
            Constant::Float(_) => self.to_f64() == 0.0,
        }
    }

    /// Whether this is exactly one.
    pub fn is_one(self) -> bool {
        match self {
            Constant::Rational { num, den } => num == den,
            Constant::Float(_) => self.to_f64() == 1.0,
        }
    }

    /// Whether this is negative.
    pub fn is_negative(self) -> bool {
        match self {
            Constant::Rational { num, .. } => num < 0,
            Constant::Float(_) => self.to_f64() < 0.0,
        }
    }

    /// The integer value, if this is an integral rational.
    pub fn as_integer(self) -> Option<i64> {
        match self {
            Constant::Rational { num, den: 1 } => Some(num),
            _ => None,
        }
    }

    /// [`fold`] of `value` as a constant.
    ///
    /// # Errors
    /// As [`fold`].
    pub fn folded(value: f64, exact_zero: bool) -> Result<Self, FoldError> {
        // `fold` lets through only finite values, which `float` keeps.
        fold(value, exact_zero).map(|v| Constant::float(v).unwrap_or(Constant::ZERO))
    }

    /// `self + other`, exact for rationals (falls back to `f64` on overflow).
    ///
    /// # Errors
    /// As [`fold`]: a sum of floats beyond `f64` or below its normal range.
    pub fn checked_add(self, other: Self) -> Result<Self, FoldError> {
        if let (Constant::Rational { num: a, den: b }, Constant::Rational { num: c, den: d }) =
            (self, other)
        {
            let exact = (|| {
                let g = gcd(b, d);
                let num = a.checked_mul(d / g)?.checked_add(c.checked_mul(b / g)?)?;
                Constant::rational(num, b.checked_mul(d / g)?)
            })();
            if let Some(exact) = exact {
                return Ok(exact);
            }
        }
        let (a, b) = (self.to_f64(), other.to_f64());
        Constant::folded(a + b, a == -b)
    }

    /// `self · other`, exact for rationals (falls back to `f64` on overflow).
    ///
    /// # Errors
    /// As [`fold`]: a product beyond `f64`, or of non-zero numbers below its normal range
    /// (`1e-300 · 1e-300`).
    pub fn checked_mul(self, other: Self) -> Result<Self, FoldError> {
        if let (Constant::Rational { num: a, den: b }, Constant::Rational { num: c, den: d }) =
            (self, other)
        {
            let exact = (|| {
                let g1 = gcd(a, d).max(1);
                let g2 = gcd(c, b).max(1);
                Constant::rational((a / g1).checked_mul(c / g2)?, (b / g2).checked_mul(d / g1)?)
            })();
            if let Some(exact) = exact {
                return Ok(exact);
            }
        }
        let (a, b) = (self.to_f64(), other.to_f64());
        Constant::folded(a * b, a == 0.0 || b == 0.0)
    }

    /// `-self`.
    pub fn negated(self) -> Self {
        match self {
            Constant::Rational { num, den } => match num.checked_neg() {
                Some(n) => Constant::Rational { num: n, den },
                None => Constant::Float((-(num as f64) / den as f64).to_bits()),
            },
            Constant::Float(bits) => Constant::float(-f64::from_bits(bits)).unwrap_or(self),
        }
    }

    /// `self ^ other`: exact for a rational to an integer power, else `f64` when the result
    /// is finite, real and normal; `Ok(None)` when it would not be exact enough to be worth
    /// folding (irrational results of rationals are kept symbolic).
    ///
    /// # Errors
    /// [`FoldError::Undefined`] for `0^-1` and `(-2)^(1/2)`; else as [`fold`]: `10^400`
    /// overflows, `10^-400` underflows.
    pub fn pow(self, other: Self) -> Result<Option<Self>, FoldError> {
        let base = self.to_f64();
        if let Some(n) = other.as_integer() {
            if let Constant::Rational { num, den } = self
                && n.unsigned_abs() <= 64
            {
                let e = n.unsigned_abs() as u32;
                let exact = (|| {
                    let p = num.checked_pow(e)?;
                    let q = den.checked_pow(e)?;
                    if n >= 0 {
                        Constant::rational(p, q)
                    } else {
                        Constant::rational(q, p)
                    }
                })();
                if exact.is_some() {
                    return Ok(exact);
                }
            }
            if base == 0.0 && n < 0 {
                return Err(FoldError::Undefined);
            }
            let value = base.powi(n.clamp(i32::MIN as i64, i32::MAX as i64) as i32);
            return Constant::folded(value, base == 0.0).map(Some);
        }
        // Non-integer exponent: fold only floats, where exactness is already gone.
        match self {
            Constant::Float(_) if base > 0.0 => {
                Constant::folded(base.powf(other.to_f64()), false).map(Some)
            }
            _ if base < 0.0 => Err(FoldError::Undefined),
            _ => Ok(None),
        }
    }
}

impl std::fmt::Display for Constant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Constant::Rational { num, den: 1 } => write!(f, "{num}"),
            Constant::Rational { num, den } => write!(f, "{num}/{den}"),
            Constant::Float(bits) => write!(f, "{:?}", f64::from_bits(bits)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimals_are_exact_rationals() {
        assert_eq!(Constant::parse_decimal("0.5"), Constant::rational(1, 2));
        assert_eq!(Constant::parse_decimal("1e-3"), Constant::rational(1, 1000));
        assert_eq!(Constant::parse_decimal("2.5E+2"), Some(Constant::int(250)));
        assert_eq!(Constant::parse_decimal("10"), Some(Constant::int(10)));
    }

    #[test]
    fn rational_arithmetic_is_exact() {
        let third = Constant::rational(1, 3).unwrap();
        assert_eq!(third.checked_mul(Constant::int(3)), Ok(Constant::ONE));
        let half = Constant::rational(1, 2).unwrap();
        assert_eq!(half.checked_add(half), Ok(Constant::ONE));
        assert_eq!(half.pow(Constant::int(-2)), Ok(Some(Constant::int(4))));
        assert_eq!(
            Constant::ZERO.pow(Constant::int(-1)),
            Err(FoldError::Undefined)
        );
    }

    /// Issue 28: `1e-300 · 1e-300` was folded to 0, and a term of the potential vanished.
    #[test]
    fn underflow_of_non_zero_numbers_is_refused() {
        let tiny = Constant::parse_decimal("1e-300").unwrap();
        assert_eq!(tiny.checked_mul(tiny), Err(FoldError::Underflow));
        // Subnormal: 1e-300 · 1e-10 = 1e-310 has only ~44 significant bits.
        let small = Constant::parse_decimal("1e-10").unwrap();
        assert_eq!(tiny.checked_mul(small), Err(FoldError::Underflow));
        assert_eq!(
            Constant::int(10).pow(Constant::int(-400)),
            Err(FoldError::Underflow)
        );
        assert_eq!(
            Constant::int(10).pow(Constant::int(400)),
            Err(FoldError::Overflow)
        );
        // Exact zeros and normal results are kept.
        assert_eq!(tiny.checked_add(tiny.negated()), Ok(Constant::ZERO));
        assert_eq!(tiny.checked_mul(Constant::ZERO), Ok(Constant::ZERO));
        assert_eq!(
            Constant::ZERO.pow(Constant::int(3)),
            Ok(Some(Constant::ZERO))
        );
        let near = Constant::parse_decimal("1e-150").unwrap();
        assert!(
            near.checked_mul(near)
                .is_ok_and(|c| c.to_f64() == 1e-150 * 1e-150)
        );
        assert_eq!(fold(f64::MIN_POSITIVE, false), Ok(f64::MIN_POSITIVE));
        assert_eq!(
            fold(f64::MIN_POSITIVE / 2.0, true),
            Err(FoldError::Underflow)
        );
        assert_eq!(fold(f64::NAN, true), Err(FoldError::Undefined));
    }

    #[test]
    fn overflow_falls_back_to_float() {
        let big = Constant::int(i64::MAX / 2);
        let r = big.checked_mul(Constant::int(4)).unwrap();
        assert_eq!(
            Constant::Float(1e300f64.to_bits()).checked_mul(Constant::Float(1e300f64.to_bits())),
            Err(FoldError::Overflow)
        );
        assert!(matches!(r, Constant::Float(_)));
        assert_eq!(r.to_f64(), (i64::MAX / 2) as f64 * 4.0);
    }
}
