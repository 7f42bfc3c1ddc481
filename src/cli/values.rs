//! `NAME=VALUE` arguments whose values are expressions (`theta1=pi/2`, `k=4*10^2`): the
//! library's [`eomgen::expressions`] with its errors as usage errors.

use super::CliError;
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

/// Parses `text` as a number and accepts it if `valid`, else says what `expected` is.
fn number(text: &str, valid: impl Fn(f64) -> bool, expected: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number"))?;
    if valid(value) {
        Ok(value)
    } else {
        Err(format!("{expected}; got {value}"))
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

/// Parses the relative tolerance of `simulate --rtol`: a number in `[0, 1)` (0 leaves the
/// absolute tolerance alone in control, which then must be positive: the integrator says so).
pub fn simulation_relative_tolerance(text: &str) -> Result<f64, String> {
    number(
        text,
        |v| v.is_finite() && (0.0..1.0).contains(&v),
        "a relative tolerance must be a number in [0, 1), such as 1e-8",
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
        |v| v.is_finite() && v >= 0.0,
        "a Baumgarte gain must be a finite number >= 0 (1/s), such as 10",
    )
}

/// Parses a positive finite number (a stiffness): refused values are usage errors.
pub fn positive(text: &str) -> Result<f64, String> {
    number(
        text,
        |v| v.is_finite() && v > 0.0,
        "must be a positive number",
    )
}
