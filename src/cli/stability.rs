//! `eomgen study stability` (issue 6). Placeholder for wiring; replaced by the implementation.

use clap::Args;

use super::CliError;

/// Options of `eomgen study stability`.
#[derive(Debug, Args)]
pub struct StabilityArgs {}

/// Runs `eomgen study stability`.
pub fn run(_args: &StabilityArgs) -> Result<(), CliError> {
    Err(CliError::failure("not implemented yet"))
}
