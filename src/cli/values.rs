//! `NAME=VALUE` arguments whose values are expressions (`theta1=pi/2`, `k=4*10^2`): the
//! library's [`eomgen::expressions`] with its errors as usage errors.

use super::error::CliError;
use eomgen::ModelInfo;
pub use eomgen::expressions::parameter_lookup;
use eomgen::expressions::{self, ExpressionError};

/// An expression error as the CLI reports it: a usage error (exit 2) with its message.
pub fn usage(e: ExpressionError) -> CliError {
    CliError::usage(e.to_string())
}

/// Evaluates `text` as an expression in which names are looked up with `lookup`
/// ([`expressions::evaluate`]).
pub fn evaluate(
    text: &str,
    what: &str,
    lookup: &dyn Fn(&str) -> Option<f64>,
) -> Result<f64, CliError> {
    expressions::evaluate(text, what, lookup).map_err(usage)
}

/// Splits `NAME=VALUE` ([`expressions::split_assignment`]).
pub fn split_assignment<'a>(arg: &'a str, option: &str) -> Result<(&'a str, &'a str), CliError> {
    expressions::split_assignment(arg, option).map_err(usage)
}

/// Applies `--set NAME=VALUE` arguments in order ([`expressions::set_parameters`]).
///
/// # Errors
/// A usage error for a malformed argument, a bad expression or an unknown parameter.
pub fn set_parameters(model: &mut dyn ModelInfo, sets: &[String]) -> Result<(), CliError> {
    expressions::set_parameters(model, sets).map_err(usage)
}

/// Parses `text` as a number and accepts it if `valid`, else says what `expected` is (clap
/// quotes the value as it was typed before it: `1e308`, not its 309 digits).
fn number(text: &str, valid: impl Fn(f64) -> bool, expected: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number"))?;
    if valid(value) {
        Ok(value)
    } else {
        Err(expected.to_string())
    }
}

/// Parses a relative tolerance (`--rtol`, `--tol`): a number in `(0, 1)`. A tolerance of 1
/// or more asks for no correct digit; a negative one is written `--rtol -1` and reaches this
/// parser (the arguments allow values that start with `-`) to get this message rather than
/// clap's "unexpected argument". Refused values are usage errors (exit 2) in every command.
pub fn relative_tolerance(text: &str) -> Result<f64, String> {
    number(
        text,
        |v| v.is_finite() && v > 0.0 && v < 1.0,
        "a relative tolerance must be a number in (0, 1), such as 1e-8",
    )
}

/// Parses an absolute tolerance (`--atol`): a finite number `≥ 0` (0 leaves the relative
/// tolerance alone in control).
pub fn absolute_tolerance(text: &str) -> Result<f64, String> {
    number(
        text,
        |v| v.is_finite() && v >= 0.0,
        "an absolute tolerance must be a finite number >= 0, such as 1e-10",
    )
}

/// Parses a gain of Baumgarte's stabilisation (`--baumgarte ALPHA,BETA`, 1/s): a finite
/// number `≥ 0` (a negative α makes the constraint drift grow instead of decay).
pub fn baumgarte_gain(text: &str) -> Result<f64, String> {
    number(
        text,
        |v| (0.0..=eomgen::MAX_BAUMGARTE_GAIN).contains(&v),
        "a Baumgarte gain must be a number in [0, 1e6] (1/s), such as 10",
    )
}

/// Parses the integration tolerance of `study floquet` (`--tol`): in (0, 1e-4], since the
/// stability tolerance on |μ| = 1 must be at least √tol and at most 0.1 (below 1e-4 that
/// leaves a range of at least 1e-2 to 0.1).
pub fn floquet_tolerance(text: &str) -> Result<f64, String> {
    number(
        text,
        |v| v > 0.0 && v <= 1e-4,
        "the tolerance of study floquet must be in (0, 1e-4]: the verdict's tolerance on |μ| = 1 is at least √tol and at most 0.1",
    )
}

/// The stiffnesses `--stiffness` takes (N/m, or k/m in 1/s² for `study stability`): below
/// 1e-6 a spring no longer holds anything on the studies' scales (masses and lengths of
/// order 1), and above 1e10 its period (~6e-5 s for 1 kg) asks an explicit method for more
/// steps than the step limit allows over the default runs. Subnormal values and 0 are in
/// neither range of meaning.
pub const STIFFNESS: std::ops::RangeInclusive<f64> = 1e-6..=1e10;

/// Parses a stiffness ([`STIFFNESS`]): refused values are usage errors that give the range.
pub fn stiffness(text: &str) -> Result<f64, String> {
    number(
        text,
        |v| STIFFNESS.contains(&v),
        "a stiffness must be a positive number in [1e-6, 1e10]",
    )
}

/// The end times the studies take (`--t-end` of `work-precision`, `constraint-methods`,
/// `free-response`, `modal-damping`), in s: below 1e-6 s no step of the default runs is
/// resolved, and from 1e6 s on `f64` resolves t only to ~4e-9 s, coarser than the steps the
/// bundled models need (as `simulate`'s hint for a step-size underflow says).
pub const STUDY_END_TIME: std::ops::RangeInclusive<f64> = 1e-6..=1e6;

/// Parses a study's end time ([`STUDY_END_TIME`]): refused values are usage errors.
pub fn study_end_time(text: &str) -> Result<f64, String> {
    number(
        text,
        |v| STUDY_END_TIME.contains(&v),
        "an end time must be a number of seconds in [1e-6, 1e6]",
    )
}

/// The longest `study work-precision --min-time-ms`: 10 s of timed runs per setting (each
/// setting repeats at most 1000 times anyway).
pub const MAX_MIN_TIME_MS: f64 = 1e4;

/// Parses `--min-time-ms`: a number of milliseconds in `[0, 1e4]`.
pub fn min_time_ms(text: &str) -> Result<f64, String> {
    number(
        text,
        |v| (0.0..=MAX_MIN_TIME_MS).contains(&v),
        "--min-time-ms must be a number of milliseconds in [0, 10000]",
    )
}

/// The frequencies `frf` takes (`--freqs LO..HI`, `--frequency`), in rad/s: outside
/// `[1e-12, 1e12]` ω² under- or overflows against the bundled models' stiffnesses and
/// masses, and |H(ω)| is then not the response of the model.
pub const FREQUENCY: std::ops::RangeInclusive<f64> = 1e-12..=1e12;
