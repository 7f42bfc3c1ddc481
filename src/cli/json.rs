//! `--json` output: every command prints its report through [`print_json`].
//!
//! Its own file (not in `output.rs`) because it returns the command error type, which itself
//! writes through `output.rs`.

use std::io::Write as _;

use super::error::CliError;
use super::output::stdout;

/// Prints `value` as pretty JSON on stdout: the one form of every command's `--json`.
///
/// # Errors
/// A value that cannot be encoded (a map with keys that are not strings).
pub(super) fn print_json(value: &impl serde::Serialize) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(value).map_err(|e| CliError::failure(e.to_string()))?;
    let _ = writeln!(stdout(), "{text}");
    Ok(())
}

/// Prints `value` as pretty JSON on stdout with the keys of every object sorted
/// alphabetically ([`sorted`]).
///
/// # Errors
/// As [`print_json`].
pub(super) fn print_json_sorted(value: &impl serde::Serialize) -> Result<(), CliError> {
    print_json(&sorted(value)?)
}

/// `value` as a JSON value with the keys of every object sorted alphabetically: the key order
/// of every command's `--json` since the commands first printed JSON, which the library types
/// (declared in reading order) do not follow.
///
/// # Errors
/// As [`print_json`].
pub(super) fn sorted(value: &impl serde::Serialize) -> Result<serde_json::Value, CliError> {
    // `serde_json::Value`'s objects are ordered maps (no `preserve_order` feature): going
    // through one sorts the keys at every level.
    serde_json::to_value(value).map_err(|e| CliError::failure(e.to_string()))
}
