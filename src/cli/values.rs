//! `NAME=VALUE` arguments whose values are expressions (`theta1=pi/2`, `k=4*10^2`).

use super::CliError;
use eomgen::ModelInfo;
use eomgen_symbolic::model::Location;
use eomgen_symbolic::model::parser::{eval_expr, parse_expr};

/// Evaluates `text` as an expression in which names are looked up with `lookup`.
pub fn evaluate(
    text: &str,
    what: &str,
    lookup: &dyn Fn(&str) -> Option<f64>,
) -> Result<f64, CliError> {
    let start = Location { line: 1, column: 1 };
    let expr = parse_expr(text, start).map_err(|d| {
        CliError::usage(format!(
            "{what}: `{text}` is not an expression (column {}): {}",
            d.location.column, d.message
        ))
    })?;
    let v = eval_expr(&expr, lookup)
        .map_err(|d| CliError::usage(format!("{what}: {} in `{text}`", d.message)))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(CliError::usage(format!(
            "{what}: `{text}` evaluates to {v}, not a finite number"
        )))
    }
}

/// Splits `NAME=VALUE`.
pub fn split_assignment<'a>(arg: &'a str, option: &str) -> Result<(&'a str, &'a str), CliError> {
    arg.split_once('=')
        .map(|(n, v)| (n.trim(), v.trim()))
        .filter(|(n, v)| !n.is_empty() && !v.is_empty())
        .ok_or_else(|| {
            CliError::usage(format!(
                "{option} takes NAME=VALUE, got `{arg}` (for example `{option} theta1=pi/2`)"
            ))
        })
}

/// Looks up `model`'s current parameter values by name (for expressions in options).
pub fn parameter_lookup(model: &dyn ModelInfo) -> impl Fn(&str) -> Option<f64> + '_ {
    let names = model.parameter_names();
    let values = model.parameter_values();
    move |n: &str| names.iter().position(|p| *p == n).map(|i| values[i])
}

/// Applies `--set NAME=VALUE` arguments in order (a value may use the parameters set before).
///
/// # Errors
/// A usage error for a malformed argument, a bad expression or an unknown parameter.
pub fn set_parameters(model: &mut dyn ModelInfo, sets: &[String]) -> Result<(), CliError> {
    for s in sets {
        let (name, text) = split_assignment(s, "--set")?;
        let value = evaluate(text, &format!("--set {name}"), &parameter_lookup(model))?;
        model
            .set_parameter(name, value)
            .map_err(|e| CliError::usage(e.to_string()))?;
    }
    Ok(())
}
