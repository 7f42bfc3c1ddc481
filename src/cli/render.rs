//! Rendering shared by the commands: what more than one command prints or writes the same way.
//!
//! Only presentation lives here (no numerics): the commands call the library for results and
//! render them with these.

/// Escapes text for HTML content and attribute values.
pub(super) fn escape(s: &str) -> String {
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

/// A progress bar on standard error, `len` steps drawn with the indicatif `template`
/// (`{msg}` is `message`), or a hidden one when `quiet` (a `--json` run) or when standard
/// error is not a terminal: scripts, pipes and tests see nothing.
pub(super) fn progress_bar(
    len: usize,
    template: &str,
    message: &'static str,
    quiet: bool,
) -> indicatif::ProgressBar {
    use std::io::IsTerminal as _;
    if quiet || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(template)
            .map(|style| style.progress_chars("=> "))
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message(message);
    bar
}

/// The exponents printed in fixed notation by [`number`]: `10⁻³ ≤ |v| < 10⁵`, the range of
/// the report's tables and the mode charts' legends.
const FIXED_EXPONENTS: std::ops::RangeInclusive<i32> = -3..=4;

/// `v` for text output, with the significant digits of `{:.precision$e}` (or the shortest
/// that round-trip, without a precision): in fixed notation when `10⁻³ ≤ |v| < 10⁵`
/// (`1.333333`, `0.001250`, `12500.00`), in exponent notation outside it (`1.25e-7`,
/// `3.5e8`), so never with an exponent `e0`. Infinities and NaN print as Rust prints them.
pub(super) fn number(v: f64, precision: Option<usize>) -> String {
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
pub(super) struct Number(f64);

/// `v` to print with `{:e}` and its variants as [`number`] prints it.
pub(super) fn num(v: impl std::borrow::Borrow<f64>) -> Number {
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

#[cfg(test)]
mod tests {
    use super::{num, number};

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
}
