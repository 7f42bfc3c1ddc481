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
