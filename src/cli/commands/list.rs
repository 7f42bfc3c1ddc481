//! `eomgen list`: the bundled models, their degrees of freedom and descriptions.

use crate::cli::error::CliError;
use crate::cli::json::print_json_sorted;
use crate::cli::output::outln;

/// Runs `list`: a table, or with `json` a JSON list of `{"name", "dof", "description"}`.
pub fn run(json: bool) -> Result<(), CliError> {
    let models: Vec<_> = eomgen::models::ALL.iter().map(|e| (e.make)()).collect();
    if json {
        let items: Vec<eomgen::ModelSummary> = models
            .iter()
            .map(|m| eomgen::ModelSummary::of(m.as_ref()))
            .collect();
        print_json_sorted(&items)?;
    } else {
        let width = models
            .iter()
            .map(|m| m.description().name.len())
            .max()
            .unwrap_or(4);
        outln!("{:width$}  dof  description", "name");
        for m in &models {
            outln!(
                "{:width$}  {:>3}  {}",
                m.description().name,
                m.num_dofs(),
                m.description().summary
            );
        }
    }
    Ok(())
}
