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
