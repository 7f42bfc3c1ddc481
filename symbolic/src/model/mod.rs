//! Model files: YAML with source locations → typed [`ModelFile`] → checked.
//!
//! Pipeline: [`yaml`] (located YAML tree) → [`parser`] (expressions) → [`schema`] (typed
//! model, every unknown key / wrong type reported) → [`check`] (cross-references and
//! semantics, and [`unit_check`] — dimensional analysis with the algebra of [`units`] — when
//! the file declares `units: SI`). [`load`] runs all of it and reports every diagnostic of a
//! file at once.

pub mod ast;
pub mod check;
pub mod diagnostic;
pub mod file;
pub mod located;
pub mod parser;
pub mod schema;
pub mod templates;
pub mod unit_check;
pub mod units;
pub mod yaml;

pub use ast::{BinOp, Expr, ExprKind};
pub use diagnostic::{Diagnostic, Diagnostics};
pub use file::*;
pub use located::{Located, Location};
pub use yaml::decode;

/// Reads a model file: YAML → typed model → checks, reporting every problem at once.
///
/// `path` is used only in messages (as the user wrote it). The schema pass and the
/// cross-object checks both run even when the other finds problems; entries the schema pass
/// had to leave out are not reported again by the checks.
///
/// # Errors
/// All diagnostics of the file, sorted by location. A YAML syntax error stops early (there
/// is no tree to check).
pub fn load(path: &str, source: &str) -> Result<ModelFile, Vec<Diagnostic>> {
    let (root, mut diagnostics) = yaml::parse_partial(source);
    if let Some(root) = root {
        let built = schema::build_partial(path, source, &root);
        diagnostics.extend(built.diagnostics);
        if let Some(file) = built.file {
            if let Err(more) = check::check_partial(&file, &built.incomplete) {
                diagnostics.extend(more);
            }
            if diagnostics.is_empty() {
                return Ok(file);
            }
        }
    }
    diagnostics.sort_by_key(|d| d.location);
    Err(diagnostics)
}
