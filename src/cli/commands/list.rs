//! `eomgen list`: the bundled models, their degrees of freedom and descriptions.

use crate::cli::error::CliError;
use crate::cli::json::print_json_sorted;
use crate::cli::output::outln;

/// Runs `list`: a table, or with `json` a JSON list of `{"name", "dof", "description"}`. The
/// files are read, not compiled ([`eomgen::models::ModelEntry::summary`]).
pub fn run(json: bool) -> Result<(), CliError> {
    let models = eomgen::models::ALL
        .iter()
        .map(|e| e.summary())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| CliError::failure(e.to_string()))?;
    if json {
        print_json_sorted(&models)?;
    } else {
        let width = models.iter().map(|m| m.name.len()).max().unwrap_or(4);
        outln!("{:width$}  dof  description", "name");
        for m in &models {
            outln!("{:width$}  {:>3}  {}", m.name, m.dof, m.description);
        }
    }
    Ok(())
}
