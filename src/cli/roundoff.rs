//! `eomgen study euler-roundoff` (issue 6). Placeholder for wiring; replaced by the implementation.

use clap::Args;

use super::CliError;

/// Options of `eomgen study euler-roundoff`.
#[derive(Debug, Args)]
pub struct EulerRoundoffArgs {}

/// Runs `eomgen study euler-roundoff`.
pub fn run(_args: &EulerRoundoffArgs) -> Result<(), CliError> {
    Err(CliError::failure("not implemented yet"))
}
