//! Exact-when-possible numeric constants: reduced rationals `p/q` (i64), else `f64`.
//!
//! Rationals keep the derivation exact (`1/2 + 1/2 = 1`, `(1/3)·3 = 1`), which makes
//! canonical forms and symbolic equality reliable. Overflow falls back to `f64`. The `f64`
//! is stored as its bit pattern (with `-0.0` normalised to `0.0`) so that constants are
//! `Eq + Hash` and can be hash-consed; NaN is never stored.

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

    /// `self + other`, exact for rationals (falls back to `f64` on overflow).
    pub fn checked_add(self, other: Self) -> Option<Self> {
        if let (Constant::Rational { num: a, den: b }, Constant::Rational { num: c, den: d }) =
            (self, other)
        {
            let exact = (|| {
                let g = gcd(b, d);
                let num = a.checked_mul(d / g)?.checked_add(c.checked_mul(b / g)?)?;
                Constant::rational(num, b.checked_mul(d / g)?)
            })();
            if exact.is_some() {
                return exact;
            }
        }
        Constant::float(self.to_f64() + other.to_f64())
    }

    /// `self · other`, exact for rationals (falls back to `f64` on overflow).
    pub fn checked_mul(self, other: Self) -> Option<Self> {
        if let (Constant::Rational { num: a, den: b }, Constant::Rational { num: c, den: d }) =
            (self, other)
        {
            let exact = (|| {
                let g1 = gcd(a, d).max(1);
                let g2 = gcd(c, b).max(1);
                Constant::rational((a / g1).checked_mul(c / g2)?, (b / g2).checked_mul(d / g1)?)
            })();
            if exact.is_some() {
                return exact;
            }
        }
        Constant::float(self.to_f64() * other.to_f64())
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
    /// is finite and real; `None` when it is not (`0^-1`, `(-2)^(1/2)`) or would not be exact
    /// enough to be worth folding (irrational results of rationals are kept symbolic).
    pub fn pow(self, other: Self) -> Option<Self> {
        let base = self.to_f64();
        if let Some(n) = other.as_integer() {
            if let Constant::Rational { num, den } = self {
                if n.unsigned_abs() <= 64 {
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
                        return exact;
                    }
                }
                if base == 0.0 && n < 0 {
                    return None;
                }
            }
            return Constant::float(base.powi(n.clamp(i32::MIN as i64, i32::MAX as i64) as i32));
        }
        // Non-integer exponent: fold only floats, where exactness is already gone.
        match self {
            Constant::Float(_) if base > 0.0 => Constant::float(base.powf(other.to_f64())),
            _ => None,
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
        assert_eq!(third.checked_mul(Constant::int(3)), Some(Constant::ONE));
        let half = Constant::rational(1, 2).unwrap();
        assert_eq!(half.checked_add(half), Some(Constant::ONE));
        assert_eq!(half.pow(Constant::int(-2)), Some(Constant::int(4)));
        assert_eq!(Constant::ZERO.pow(Constant::int(-1)), None);
    }

    #[test]
    fn overflow_falls_back_to_float() {
        let big = Constant::int(i64::MAX / 2);
        let r = big.checked_mul(Constant::int(4)).unwrap();
        assert!(matches!(r, Constant::Float(_)));
        assert_eq!(r.to_f64(), (i64::MAX / 2) as f64 * 4.0);
    }
}
