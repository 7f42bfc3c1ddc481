//! Text that the animation page, the report's rows and the command line write alike: numbers
//! as the command line prints them, HTML escaping and a simulation's step control in words.
//!
//! Only presentation lives here (no numerics). Every function is deterministic: the same
//! value gives the same text on every platform, so pages and reports are byte-identical
//! across runs.

use eomgen_runtime::IntegratorOptions;
use eomgen_runtime::analysis::SimulationOptions;

/// Escapes text for HTML content and attribute values (`&`, `<`, `>`, `"` and `'`).
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// The exponents printed in fixed notation by [`number`]: `10⁻³ ≤ |v| < 10⁵`, the range of
/// the report's tables and the mode charts' legends.
const FIXED_EXPONENTS: std::ops::RangeInclusive<i32> = -3..=4;

/// `v` for text output, with the significant digits of `{:.precision$e}` (or the shortest
/// that round-trip, without a precision): in fixed notation when `10⁻³ ≤ |v| < 10⁵`
/// (`1.333333`, `0.001250`, `12500.00`), in exponent notation outside it (`1.25e-7`,
/// `3.5e8`), so never with an exponent `e0`. Infinities and NaN print as Rust prints them.
pub fn number(v: f64, precision: Option<usize>) -> String {
    let exponent_form = match precision {
        Some(p) => format!("{v:.p$e}"),
        None => format!("{v:e}"),
    };
    let Some((mantissa, exponent)) = exponent_form.split_once('e') else {
        return exponent_form;
    };
    let Ok(exponent) = exponent.parse::<i32>() else {
        return exponent_form;
    };
    if !FIXED_EXPONENTS.contains(&exponent) {
        return exponent_form;
    }
    let (sign, mantissa) = match mantissa.strip_prefix('-') {
        Some(m) => ("-", m),
        None => ("", mantissa),
    };
    let digits: String = mantissa.chars().filter(|c| *c != '.').collect();
    if exponent >= 0 {
        let integer = exponent as usize + 1;
        if digits.len() <= integer {
            format!("{sign}{digits}{}", "0".repeat(integer - digits.len()))
        } else {
            format!("{sign}{}.{}", &digits[..integer], &digits[integer..])
        }
    } else {
        let zeros = "0".repeat((-exponent - 1) as usize);
        format!("{sign}0.{zeros}{digits}")
    }
}

/// A number formatted by [`number`] through `{:e}`, `{:.6e}`, `{:>12.4e}`, `{:+.2e}`: the
/// precision is [`number`]'s, width, alignment and sign are honoured as for any number.
#[derive(Debug, Clone, Copy)]
pub struct Number(f64);

/// `v` to print with `{:e}` and its variants as [`number`] prints it.
pub fn num(v: impl std::borrow::Borrow<f64>) -> Number {
    Number(*v.borrow())
}

impl std::fmt::LowerExp for Number {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let text = number(self.0, f.precision());
        match text.strip_prefix('-') {
            Some(magnitude) => f.pad_integral(false, "", magnitude),
            None => f.pad_integral(true, "", &text),
        }
    }
}

/// `v` with `decimals` decimals, trailing zeros dropped, `-0` as `0` (`fixed(10.0, 6)` is
/// `10`, `fixed(0.25, 6)` is `0.25`), as the report's rows write times and the animation page
/// its positions.
pub fn fixed(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// Six significant digits: fixed notation when `10⁻³ ≤ |v| < 10⁵` (`6.39800`, `0.500000`),
/// exponent notation with five decimals otherwise and for 0 (`1.25000e-7`, `0.00000e0`).
pub fn significant(v: f64) -> String {
    if v == 0.0 || !(1e-3..1e5).contains(&v.abs()) {
        format!("{v:.5e}")
    } else {
        let digits = (5 - v.abs().log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    }
}

/// Six significant digits ([`significant`]) without trailing zeros (`30`, `0.5`, `6.398`).
pub fn short(v: f64) -> String {
    let s = significant(v);
    if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// How a simulation with `options` controls its step, in words: `rtol 1e-8, atol 1e-10` for
/// an adaptive method, `fixed step dt = 0.01 s` otherwise (`options.dt`, by default
/// `t_end / `[`IntegratorOptions::DEFAULT_FIXED_STEPS`]); numbers as [`number`] prints them.
/// What `eomgen simulate` prints after the method's name, and the animation page's info
/// line.
pub fn step_control(options: &SimulationOptions) -> String {
    if options.method.is_adaptive() {
        format!("rtol {:e}, atol {:e}", num(options.rtol), num(options.atol))
    } else {
        let dt = options
            .dt
            .unwrap_or(options.t_end / f64::from(IntegratorOptions::DEFAULT_FIXED_STEPS));
        format!("fixed step dt = {dt:e} s", dt = num(dt))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use eomgen_runtime::analysis::Method;

    /// Fixed notation in [1e-3, 1e5) with the significant digits of the exponent form, the
    /// exponent form outside, never `e0`; width, alignment and sign as for a number.
    #[test]
    fn numbers_print_without_e0() {
        assert_eq!(number(4.0 / 3.0, Some(6)), "1.333333");
        assert_eq!(number(0.5, Some(6)), "0.5000000");
        assert_eq!(number(15.0, Some(6)), "15.00000");
        assert_eq!(number(12345.678, Some(2)), "12300");
        assert_eq!(number(0.00125, Some(2)), "0.00125");
        assert_eq!(number(-0.000125, Some(2)), "-1.25e-4");
        assert_eq!(number(123456.0, Some(2)), "1.23e5");
        assert_eq!(number(0.0, Some(3)), "0.000");
        assert_eq!(number(1.0, None), "1");
        assert_eq!(number(100.0, None), "100");
        assert_eq!(number(1e-8, None), "1e-8");
        assert_eq!(number(f64::INFINITY, Some(3)), "inf");
        assert_eq!(number(f64::NAN, None), "NaN");
        // 9.9999 rounds up to the next decade: the exponent form decides the digits.
        assert_eq!(number(9.99999, Some(2)), "10.0");
        assert_eq!(format!("[{:>10.3e}]", num(-2.5)), "[    -2.500]");
        assert_eq!(format!("[{:<9.1e}]", num(2.5e-7)), "[2.5e-7   ]");
        assert_eq!(format!("{:+.2e}", num(0.25)), "+0.250");
        let two = [2.0];
        assert_eq!(format!("{:e}", num(two.first().unwrap())), "2");
        for v in [1.0, 3.7, -8.25, 0.0, 42.0, 0.001, 9999.0] {
            for p in 0..8 {
                let s = number(v, Some(p));
                assert!(!s.contains('e'), "{v} {p}: {s}");
                assert_eq!(
                    s.parse::<f64>().unwrap(),
                    format!("{v:.p$e}").parse::<f64>().unwrap()
                );
            }
        }
    }

    #[test]
    fn numbers_are_trimmed() {
        assert_eq!(fixed(-0.0000000000001, 11), "0");
        assert_eq!(fixed(1.5, 11), "1.5");
        assert_eq!(fixed(-2.0, 3), "-2");
        assert_eq!(fixed(12.0, 0), "12");
        assert_eq!(short(30.0), "30");
        assert_eq!(short(0.5), "0.5");
        assert_eq!(short(6.398), "6.398");
        assert_eq!(short(1.25e-7), "1.25000e-7");
        assert_eq!(
            escape("<a href=\"x\">&'"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;"
        );
    }

    /// The tolerances of an adaptive method, the fixed step of the others (by default
    /// `t_end / 1000`).
    #[test]
    fn step_control_names_the_tolerances_or_the_step() {
        assert_eq!(
            step_control(&SimulationOptions::default()),
            "rtol 1e-8, atol 1e-10"
        );
        let rk4 = SimulationOptions {
            method: Method::Rk4,
            ..SimulationOptions::default()
        };
        assert_eq!(step_control(&rk4), "fixed step dt = 0.01 s");
        let rk4 = SimulationOptions {
            dt: Some(0.5),
            ..rk4
        };
        assert_eq!(step_control(&rk4), "fixed step dt = 0.5 s");
    }
}
