//! Physical units of model files: exponents of the SI base dimensions length (m), mass (kg)
//! and time (s), with exact rational exponents, a parser for unit text and a canonical
//! display.
//!
//! Unit text (the `unit:` of a parameter or coordinate, or the start of a parameter's
//! trailing comment):
//!
//! ```text
//! unit    := factor (('*' | '·' | ' ' | '/') factor)*     (left to right: N*s/m = (N*s)/m)
//! factor  := atom ('^' exponent | '²' | '³')?
//! atom    := name | '1' | '(' unit ')'
//! exponent:= '-'? digits | '(' '-'? digits ('/' digits)? ')'
//! name    := m | kg | s | N | J | W | Pa | Hz | rad
//! ```
//!
//! `rad` is dimensionless (an angle is a ratio of lengths), so `N*m/rad` is `N*m` and `rad/s`
//! is `1/s`. Prefixes (`mm`, `kN`) and non-coherent units (`deg`, `rpm`) are not units of a
//! model file: every value is in coherent SI units. The A, K, mol and cd dimensions do not
//! occur in the mechanics the files describe.
//!
//! Displayed forms prefer a named derived unit when it absorbs the seconds exactly: `N`,
//! `J`, `W`, `Pa`, `N/m` (= kg/s²); otherwise base units in the order kg, m, s: `kg*m^2`,
//! `kg*m/s`, `m/s^2`, `kg/s`, `1/s`; a pure number is `1`. Every displayed form parses back
//! to the same dimension.

use std::fmt;

use crate::expr::Constant;

/// An exact rational number `num/den` with `den > 0` and no common factor; arithmetic is
/// checked (`None` on `i64` overflow), so that no input can make it panic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Rational {
    num: i64,
    den: i64,
}

fn gcd(mut a: i128, mut b: i128) -> i128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a.abs()
}

impl Rational {
    /// Zero.
    pub const ZERO: Rational = Rational::integer(0);
    /// One.
    pub const ONE: Rational = Rational::integer(1);

    /// The integer `n`.
    pub const fn integer(n: i64) -> Self {
        Self { num: n, den: 1 }
    }

    /// `num/den` in lowest terms; `None` if `den` is 0 or the result does not fit.
    pub fn new(num: i64, den: i64) -> Option<Self> {
        Self::reduce(i128::from(num), i128::from(den))
    }

    /// `num/den` in lowest terms from wide intermediates (products of two `i64` fit in
    /// `i128`, so no operation below overflows before this check).
    fn reduce(num: i128, den: i128) -> Option<Self> {
        if den == 0 {
            return None;
        }
        let g = gcd(num, den);
        let (mut n, mut d) = (num / g, den / g);
        if d < 0 {
            (n, d) = (-n, -d);
        }
        Some(Self {
            num: i64::try_from(n).ok()?,
            den: i64::try_from(d).ok()?,
        })
    }

    /// The numerator (carries the sign).
    pub fn numer(self) -> i64 {
        self.num
    }

    /// The denominator (positive).
    pub fn denom(self) -> i64 {
        self.den
    }

    /// Whether the value is 0.
    pub fn is_zero(self) -> bool {
        self.num == 0
    }

    /// `self + o`, `None` on overflow.
    pub fn checked_add(self, o: Self) -> Option<Self> {
        let (a, b, c, d) = self.wide(o);
        Self::reduce(a * d + c * b, b * d)
    }

    /// `self - o`, `None` on overflow.
    pub fn checked_sub(self, o: Self) -> Option<Self> {
        let (a, b, c, d) = self.wide(o);
        Self::reduce(a * d - c * b, b * d)
    }

    /// `-self`, `None` on overflow.
    pub fn checked_neg(self) -> Option<Self> {
        Self::reduce(-i128::from(self.num), i128::from(self.den))
    }

    /// `self · o`, `None` on overflow.
    pub fn checked_mul(self, o: Self) -> Option<Self> {
        let (a, b, c, d) = self.wide(o);
        Self::reduce(a * c, b * d)
    }

    /// `self / o`, `None` if `o` is 0 or on overflow.
    pub fn checked_div(self, o: Self) -> Option<Self> {
        let (a, b, c, d) = self.wide(o);
        Self::reduce(a * d, b * c)
    }

    /// Both as `i128` numerators and denominators; `|a·d ± c·b| ≤ 2·2^126 < 2^127` since
    /// denominators are positive and at most `i64::MAX`.
    fn wide(self, o: Self) -> (i128, i128, i128, i128) {
        (
            i128::from(self.num),
            i128::from(self.den),
            i128::from(o.num),
            i128::from(o.den),
        )
    }

    /// The exact value of a decimal literal as the expression parser accepts it (`2`, `0.5`,
    /// `1e-3`, `1.5E2`); `None` for anything else or when it does not fit.
    pub fn from_decimal(text: &str) -> Option<Self> {
        match Constant::parse_decimal(text)? {
            Constant::Rational { num, den } => Self::new(num, den),
            Constant::Float(_) => None,
        }
    }
}

impl fmt::Display for Rational {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.den == 1 {
            write!(f, "{}", self.num)
        } else {
            write!(f, "{}/{}", self.num, self.den)
        }
    }
}

/// A physical dimension: the exponents of length (m), mass (kg) and time (s).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Dimension {
    /// Exponent of the metre.
    pub length: Rational,
    /// Exponent of the kilogram.
    pub mass: Rational,
    /// Exponent of the second.
    pub time: Rational,
}

impl Dimension {
    /// A pure number (also an angle in rad).
    pub const ONE: Dimension = Dimension::integers(0, 0, 0);
    /// Length, m.
    pub const METRE: Dimension = Dimension::integers(1, 0, 0);
    /// Mass, kg.
    pub const KILOGRAM: Dimension = Dimension::integers(0, 1, 0);
    /// Time, s.
    pub const SECOND: Dimension = Dimension::integers(0, 0, 1);
    /// Force, N = kg·m/s².
    pub const NEWTON: Dimension = Dimension::integers(1, 1, -2);
    /// Energy, work and torque, J = N·m = kg·m²/s².
    pub const JOULE: Dimension = Dimension::integers(2, 1, -2);
    /// Power, W = J/s.
    pub const WATT: Dimension = Dimension::integers(2, 1, -3);
    /// Pressure, Pa = N/m².
    pub const PASCAL: Dimension = Dimension::integers(-1, 1, -2);
    /// Translational stiffness, N/m = kg/s².
    pub const STIFFNESS: Dimension = Dimension::integers(0, 1, -2);
    /// Translational damping coefficient, N·s/m = kg/s.
    pub const DAMPING: Dimension = Dimension::integers(0, 1, -1);
    /// Moment of inertia, kg·m².
    pub const INERTIA: Dimension = Dimension::integers(2, 1, 0);
    /// Acceleration, m/s².
    pub const ACCELERATION: Dimension = Dimension::integers(1, 0, -2);
    /// Frequency (and angular velocity), 1/s.
    pub const FREQUENCY: Dimension = Dimension::integers(0, 0, -1);

    /// m^length · kg^mass · s^time with integer exponents.
    pub const fn integers(length: i64, mass: i64, time: i64) -> Self {
        Self {
            length: Rational::integer(length),
            mass: Rational::integer(mass),
            time: Rational::integer(time),
        }
    }

    fn zip(self, o: Self, f: impl Fn(Rational, Rational) -> Option<Rational>) -> Option<Self> {
        Some(Self {
            length: f(self.length, o.length)?,
            mass: f(self.mass, o.mass)?,
            time: f(self.time, o.time)?,
        })
    }

    /// The dimension of a product; `None` on exponent overflow.
    pub fn checked_mul(self, o: Self) -> Option<Self> {
        self.zip(o, Rational::checked_add)
    }

    /// The dimension of a quotient; `None` on exponent overflow.
    pub fn checked_div(self, o: Self) -> Option<Self> {
        self.zip(o, Rational::checked_sub)
    }

    /// The dimension of `self^p`; `None` on exponent overflow.
    pub fn pow(self, p: Rational) -> Option<Self> {
        self.zip(Self::ONE, |a, _| a.checked_mul(p))
    }

    /// Whether this is a pure number.
    pub fn is_one(self) -> bool {
        self == Self::ONE
    }

    fn exponents(self) -> [Rational; 3] {
        [self.mass, self.length, self.time]
    }
}

/// Unit symbols of model files and their dimensions.
pub const UNIT_NAMES: &[(&str, Dimension)] = &[
    ("m", Dimension::METRE),
    ("kg", Dimension::KILOGRAM),
    ("s", Dimension::SECOND),
    ("N", Dimension::NEWTON),
    ("J", Dimension::JOULE),
    ("W", Dimension::WATT),
    ("Pa", Dimension::PASCAL),
    ("Hz", Dimension::FREQUENCY),
    ("rad", Dimension::ONE),
];

/// Named units tried by the display, in order of preference.
const DISPLAY_NAMES: &[(&str, Dimension)] = &[
    ("N", Dimension::NEWTON),
    ("J", Dimension::JOULE),
    ("W", Dimension::WATT),
    ("Pa", Dimension::PASCAL),
];

/// `name`, `name^2`, `name^(1/2)`.
fn power_text(name: &str, p: Rational) -> String {
    if p == Rational::ONE {
        name.to_string()
    } else if p.denom() == 1 {
        format!("{name}^{p}")
    } else {
        format!("{name}^({p})")
    }
}

/// `a*b` over `c*d` as `a*b/(c*d)`, `1/c`, `a*b`.
fn fraction_text(up: &[String], down: &[String]) -> String {
    let top = if up.is_empty() {
        "1".to_string()
    } else {
        up.join("*")
    };
    match down.len() {
        0 => top,
        1 => format!("{top}/{}", down[0]),
        _ => format!("{top}/({})", down.join("*")),
    }
}

/// Splits `(name, exponent)` factors into numerator and denominator texts.
fn factors_text(factors: &[(&str, Rational)]) -> Option<String> {
    let mut up = Vec::new();
    let mut down = Vec::new();
    for &(name, p) in factors {
        if p.is_zero() {
            continue;
        }
        if p.numer() > 0 {
            up.push(power_text(name, p));
        } else {
            down.push(power_text(name, p.checked_neg()?));
        }
    }
    Some(fraction_text(&up, &down))
}

impl fmt::Display for Dimension {
    /// The canonical form described in the module documentation.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let base = ["kg", "m", "s"];
        // A named unit raised to the mass exponent, when the rest has no seconds.
        let mut best: Option<((usize, u64), String)> = None;
        if !self.mass.is_zero() {
            for (name, unit) in DISPLAY_NAMES {
                let Some(rest) = unit.pow(self.mass).and_then(|u| self.checked_div(u)) else {
                    continue;
                };
                if !rest.time.is_zero() {
                    continue;
                }
                // Fewest remaining factors, then the smallest remaining power; ties keep the
                // earlier name (N/m rather than Pa*m).
                let score = (
                    usize::from(!rest.length.is_zero()),
                    rest.length.numer().unsigned_abs(),
                );
                if best.as_ref().is_none_or(|(s, _)| score < *s)
                    && let Some(text) = factors_text(&[(name, self.mass), ("m", rest.length)])
                {
                    best = Some((score, text));
                }
            }
        }
        let text = match best {
            Some((_, text)) => Some(text),
            None => {
                let factors: Vec<(&str, Rational)> =
                    base.iter().copied().zip(self.exponents()).collect();
                factors_text(&factors)
            }
        };
        f.write_str(text.as_deref().unwrap_or("?"))
    }
}

/// Why a unit text does not parse.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnitError {
    /// Character offset of the problem in the text.
    pub offset: usize,
    /// Lowercase message naming the offending piece.
    pub message: String,
    /// What would be right.
    pub help: String,
}

impl UnitError {
    /// The message naming whose unit it is: "unknown unit `mm` in the unit of parameter `k`",
    /// "unclosed `(` in the unit of coordinate `x`" (said once, where the message already
    /// speaks of "the unit").
    pub fn message_for(&self, whose: &str) -> String {
        match self.message.split_once(" in the unit") {
            Some((before, after)) => format!("{before} in the unit of {whose}{after}"),
            None => format!("{} in the unit of {whose}", self.message),
        }
    }
}

/// Help shared by unit errors: what a unit may be made of.
pub const UNIT_HELP: &str = "a unit is a product or quotient of m, kg, s, N, J, W, Pa, Hz, rad and 1, as in `N/m`, `N*s/m` or `kg*m^2`";

/// Parses unit text (grammar in the module documentation).
///
/// # Errors
/// The first problem, with its character offset: an unknown name (with a "did you mean"), a
/// missing factor or exponent, an unbalanced parenthesis, an exponent that does not fit.
pub fn parse_unit(text: &str) -> Result<Dimension, UnitError> {
    let chars: Vec<char> = text.chars().collect();
    let mut p = UnitParser {
        chars: &chars,
        pos: 0,
        depth: 0,
    };
    p.skip_space();
    if p.pos == chars.len() {
        return Err(p.error("empty unit".to_string(), UNIT_HELP.to_string()));
    }
    let d = p.product()?;
    p.skip_space();
    match p.peek() {
        None => Ok(d),
        Some(')') => Err(p.error(
            "unexpected `)` in the unit: it closes no `(`".to_string(),
            "remove it, or add the `(` it should close".to_string(),
        )),
        Some(c) => Err(p.error(
            format!("unexpected `{c}` in the unit"),
            UNIT_HELP.to_string(),
        )),
    }
}

/// `Nm` → `N*m`, `kgm` → `kg*m`: a short word made of two or more unit names written
/// together.
fn split_names(word: &str) -> Option<String> {
    fn split(word: &str, out: &mut Vec<&'static str>) -> bool {
        if word.is_empty() {
            return true;
        }
        for (n, _) in UNIT_NAMES {
            if let Some(rest) = word.strip_prefix(n) {
                out.push(n);
                if split(rest, out) {
                    return true;
                }
                out.pop();
            }
        }
        false
    }
    let mut parts = Vec::new();
    (word.len() <= 12 && split(word, &mut parts) && parts.len() > 1).then(|| parts.join("*"))
}

/// Nesting limit of parentheses in a unit (no real unit comes near it).
const MAX_UNIT_DEPTH: usize = 16;

struct UnitParser<'c> {
    chars: &'c [char],
    pos: usize,
    depth: usize,
}

impl UnitParser<'_> {
    fn peek(&self) -> Option<char> {
        self.chars.get(self.pos).copied()
    }

    fn error(&self, message: String, help: String) -> UnitError {
        UnitError {
            offset: self.pos,
            message,
            help,
        }
    }

    fn skip_space(&mut self) {
        while self.peek().is_some_and(|c| c == ' ' || c == '\t') {
            self.pos += 1;
        }
    }

    fn overflow(&self) -> UnitError {
        self.error(
            "the unit's exponents are too large".to_string(),
            UNIT_HELP.to_string(),
        )
    }

    fn product(&mut self) -> Result<Dimension, UnitError> {
        let mut d = self.factor()?;
        loop {
            let before = self.pos;
            self.skip_space();
            let spaced = self.pos > before;
            match self.peek() {
                Some('*' | '·' | '⋅') => {
                    self.pos += 1;
                    self.skip_space();
                    let f = self.factor()?;
                    d = d.checked_mul(f).ok_or_else(|| self.overflow())?;
                }
                Some('/') => {
                    self.pos += 1;
                    self.skip_space();
                    let f = self.factor()?;
                    d = d.checked_div(f).ok_or_else(|| self.overflow())?;
                }
                Some(c) if spaced && (c.is_alphanumeric() || c == '(') => {
                    let f = self.factor()?;
                    d = d.checked_mul(f).ok_or_else(|| self.overflow())?;
                }
                _ => return Ok(d),
            }
        }
    }

    fn factor(&mut self) -> Result<Dimension, UnitError> {
        let start = self.pos;
        let d = match self.peek() {
            Some('(') => {
                if self.depth >= MAX_UNIT_DEPTH {
                    return Err(self.error(
                        "the unit nests parentheses too deeply".to_string(),
                        UNIT_HELP.to_string(),
                    ));
                }
                self.pos += 1;
                self.depth += 1;
                self.skip_space();
                let d = self.product()?;
                self.depth -= 1;
                self.skip_space();
                if self.peek() != Some(')') {
                    return Err(self.error(
                        "unclosed `(` in the unit".to_string(),
                        "add the `)` that closes it".to_string(),
                    ));
                }
                self.pos += 1;
                d
            }
            Some(c) if c.is_ascii_digit() => {
                while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                    self.pos += 1;
                }
                let digits: String = self.chars[start..self.pos].iter().collect();
                if digits != "1" {
                    self.pos = start;
                    return Err(self.error(
                        format!("the number `{digits}` is not a unit"),
                        "units have no factors but `1` (a pure number); write the value in SI units without a factor".to_string(),
                    ));
                }
                Dimension::ONE
            }
            Some(c) if c.is_alphabetic() => {
                while self.peek().is_some_and(char::is_alphabetic) {
                    self.pos += 1;
                }
                let name: String = self.chars[start..self.pos].iter().collect();
                match UNIT_NAMES.iter().find(|(n, _)| *n == name) {
                    Some((_, d)) => *d,
                    None => {
                        self.pos = start;
                        return Err(self.unknown(&name));
                    }
                }
            }
            Some(c) => {
                return Err(self.error(
                    format!("expected a unit, found `{c}`"),
                    UNIT_HELP.to_string(),
                ));
            }
            None => {
                return Err(self.error(
                    "the unit ends where a unit name was expected".to_string(),
                    UNIT_HELP.to_string(),
                ));
            }
        };
        let p = match self.peek() {
            Some('^') => {
                self.pos += 1;
                self.exponent()?
            }
            Some('²') => {
                self.pos += 1;
                Rational::integer(2)
            }
            Some('³') => {
                self.pos += 1;
                Rational::integer(3)
            }
            _ => return Ok(d),
        };
        d.pow(p).ok_or_else(|| self.overflow())
    }

    fn unknown(&self, name: &str) -> UnitError {
        let names: Vec<&str> = UNIT_NAMES.iter().map(|(n, _)| *n).collect();
        let advice = match name {
            "deg" | "degree" | "degrees" | "rpm" => {
                "angles are in rad and angular velocities in rad/s (coherent SI units)".to_string()
            }
            "g" | "mm" | "cm" | "km" | "kN" | "ms" | "min" | "h" => {
                "values are in coherent SI units without prefixes: m, kg, s".to_string()
            }
            _ => match split_names(name)
                .or_else(|| super::parser::closest(name, &names).map(str::to_string))
            {
                Some(c) => format!("did you mean `{c}`? {UNIT_HELP}"),
                None => UNIT_HELP.to_string(),
            },
        };
        self.error(format!("unknown unit `{name}`"), advice)
    }

    /// `2`, `-2`, `(1/2)`, `(-3/2)`.
    fn exponent(&mut self) -> Result<Rational, UnitError> {
        let parenthesised = self.peek() == Some('(');
        if parenthesised {
            self.pos += 1;
        }
        let negative = self.peek() == Some('-');
        if negative {
            self.pos += 1;
        }
        let mut value = self.integer()?;
        if parenthesised {
            if self.peek() == Some('/') {
                self.pos += 1;
                let den = self.integer()?;
                value = value.checked_div(den).ok_or_else(|| {
                    self.error(
                        "the exponent divides by zero".to_string(),
                        "write a fraction such as `^(1/2)`".to_string(),
                    )
                })?;
            }
            if self.peek() != Some(')') {
                return Err(self.error(
                    "unclosed `(` in the exponent".to_string(),
                    "write a fractional exponent as `^(1/2)`".to_string(),
                ));
            }
            self.pos += 1;
        }
        if negative {
            value = value.checked_neg().ok_or_else(|| self.overflow())?;
        }
        Ok(value)
    }

    fn integer(&mut self) -> Result<Rational, UnitError> {
        let start = self.pos;
        while self.peek().is_some_and(|c| c.is_ascii_digit()) {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.error(
                "expected an integer exponent".to_string(),
                "write a power as `m^2`, `s^-1` or `m^(1/2)`".to_string(),
            ));
        }
        let digits: String = self.chars[start..self.pos].iter().collect();
        digits
            .parse::<i64>()
            .map(Rational::integer)
            .map_err(|_| self.overflow())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(n: i64, d: i64) -> Rational {
        Rational::new(n, d).unwrap()
    }

    fn unit(text: &str) -> Dimension {
        parse_unit(text).unwrap_or_else(|e| panic!("{text}: {e:?}"))
    }

    #[test]
    fn rationals_are_exact_and_checked() {
        assert_eq!(r(2, -4), r(-1, 2));
        assert_eq!(r(1, 2).checked_add(r(1, 3)), Some(r(5, 6)));
        assert_eq!(r(1, 2).checked_mul(r(2, 3)), Some(r(1, 3)));
        assert_eq!(r(1, 2).checked_div(Rational::ZERO), None);
        assert_eq!(Rational::new(1, 0), None);
        assert_eq!(Rational::integer(i64::MAX).checked_add(Rational::ONE), None);
        assert_eq!(Rational::new(i64::MIN, -1), None);
        assert_eq!(Rational::from_decimal("0.5"), Some(r(1, 2)));
        assert_eq!(Rational::from_decimal("1e-3"), Some(r(1, 1000)));
        assert_eq!(
            Rational::from_decimal("1.5E2"),
            Some(Rational::integer(150))
        );
        assert_eq!(Rational::from_decimal("007"), Some(Rational::integer(7)));
        assert_eq!(Rational::from_decimal("1e400"), None);
        assert_eq!(Rational::from_decimal("0x10"), None);
        assert_eq!(Rational::from_decimal("."), None);
        assert_eq!(r(-3, 2).to_string(), "-3/2");
    }

    #[test]
    fn named_units_are_their_definitions_in_base_units() {
        // Each named unit against its definition written in base units (SI brochure,
        // table 4), so a wrong entry of the table fails here.
        assert_eq!(unit("N"), unit("kg*m/s^2"));
        assert_eq!(unit("J"), unit("N*m"));
        assert_eq!(unit("W"), unit("J/s"));
        assert_eq!(unit("Pa"), unit("N/m^2"));
        assert_eq!(unit("Hz"), unit("1/s"));
        assert_eq!(unit("rad"), unit("1"));
        assert_eq!(unit("N*m/rad"), unit("J"));
        assert_eq!(unit("rad/s"), Dimension::FREQUENCY);
    }

    #[test]
    fn products_quotients_and_powers() {
        assert_eq!(unit("N/m"), Dimension::integers(0, 1, -2));
        assert_eq!(unit("N*s/m"), Dimension::integers(0, 1, -1));
        assert_eq!(unit("N s/m"), unit("N*s/m"));
        assert_eq!(unit("kg m^2"), Dimension::integers(2, 1, 0));
        assert_eq!(unit("kg·m²"), Dimension::integers(2, 1, 0));
        assert_eq!(unit("m/s^2"), Dimension::integers(1, 0, -2));
        assert_eq!(unit("s^-1"), Dimension::integers(0, 0, -1));
        assert_eq!(unit("kg/(m*s)"), Dimension::integers(-1, 1, -1));
        // Left to right: a/b*c = (a/b)*c.
        assert_eq!(unit("m/s*kg"), Dimension::integers(1, 1, -1));
        let root = unit("m^(1/2)");
        assert_eq!(root.length, r(1, 2));
        assert_eq!(unit("(m^(-3/2))^2"), Dimension::integers(-3, 0, 0));
        assert_eq!(
            unit("m")
                .checked_mul(unit("m"))
                .unwrap()
                .checked_div(unit("s^2")),
            Some(unit("m^2/s^2"))
        );
        assert_eq!(
            unit("N/m").pow(r(1, 2)).unwrap().pow(Rational::integer(2)),
            Some(unit("N/m"))
        );
        assert_ne!(unit("N"), unit("N/m"));
    }

    #[test]
    fn bad_units_say_where_and_why() {
        let e = parse_unit("N/mm").unwrap_err();
        assert_eq!((e.offset, e.message.as_str()), (2, "unknown unit `mm`"));
        let e = parse_unit("Nm").unwrap_err();
        assert!(e.help.starts_with("did you mean `N*m`?"), "{}", e.help);
        let e = parse_unit("Nms").unwrap_err();
        assert!(e.help.starts_with("did you mean `N*m*s`?"), "{}", e.help);
        let e = parse_unit("kgg").unwrap_err();
        assert!(e.help.starts_with("did you mean `kg`?"), "{}", e.help);
        assert_eq!(parse_unit("deg").unwrap_err().message, "unknown unit `deg`");
        assert_eq!(parse_unit("").unwrap_err().message, "empty unit");
        assert_eq!(parse_unit("kg*").unwrap_err().offset, 3);
        assert_eq!(
            parse_unit("(m").unwrap_err().message,
            "unclosed `(` in the unit"
        );
        assert_eq!(parse_unit("m)").unwrap_err().offset, 1);
        assert_eq!(
            parse_unit("2*m").unwrap_err().message,
            "the number `2` is not a unit"
        );
        assert_eq!(
            parse_unit("m^").unwrap_err().message,
            "expected an integer exponent"
        );
        assert!(parse_unit("m^99999999999999999999").is_err());
        assert!(parse_unit("m^(1/0)").is_err());
        assert!(parse_unit(&"(".repeat(100)).is_err());
        assert!(parse_unit("(m^4000000000)^4000000000^4000000000").is_err());
    }

    #[test]
    fn display_prefers_named_units_when_exact() {
        let cases = [
            ("N", "N"),
            ("J", "J"),
            ("N*m", "J"),
            ("W", "W"),
            ("Pa", "Pa"),
            ("N/m", "N/m"),
            ("N/m^2", "Pa"),
            ("N^2", "N^2"),
            ("1/N", "1/N"),
            ("J*m", "J*m"),
            ("kg*m^2", "kg*m^2"),
            ("N*s/m", "kg/s"),
            ("kg*m/s", "kg*m/s"),
            ("kg*m^2/s", "kg*m^2/s"),
            ("m/s^2", "m/s^2"),
            ("rad/s", "1/s"),
            ("kg", "kg"),
            ("m", "m"),
            ("1", "1"),
            ("rad", "1"),
            ("kg/(m*s)", "kg/(m*s)"),
            ("m^(1/2)", "m^(1/2)"),
            ("s^-2", "1/s^2"),
        ];
        for (text, shown) in cases {
            let d = unit(text);
            assert_eq!(d.to_string(), shown, "{text}");
            // Every displayed form parses back to the same dimension.
            assert_eq!(unit(shown), d, "{shown}");
        }
    }
}
