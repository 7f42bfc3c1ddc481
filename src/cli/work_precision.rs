//! `eomgen study work-precision MODEL` (issue 6). Placeholder for wiring; replaced by the implementation.

use clap::Args;

use super::CliError;

/// Options of `eomgen study work-precision MODEL`.
#[derive(Debug, Args)]
pub struct WorkPrecisionArgs {}

/// Runs `eomgen study work-precision MODEL`.
pub fn run(_args: &WorkPrecisionArgs) -> Result<(), CliError> {
    Err(CliError::failure("not implemented yet"))
}
