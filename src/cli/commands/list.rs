//! `eomgen list`: the bundled models, their degrees of freedom and descriptions.

use crate::cli::error::CliError;
use crate::cli::json::print_json;
use crate::cli::output::outln;

/// Runs `list`: a table, or with `json` a JSON list of `{"name", "dof", "description"}`.
pub fn run(json: bool) -> Result<(), CliError> {
    let models: Vec<_> = eomgen::models::ALL.iter().map(|e| (e.make)()).collect();
    if json {
        let items: Vec<serde_json::Value> = models
            .iter()
            .map(|m| serde_json::json!({"name": m.description().name, "dof": m.num_dofs(), "description": m.description().summary}))
            .collect();
        print_json(&items)?;
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
