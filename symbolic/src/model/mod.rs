//! Model files: YAML with source locations → typed [`ModelFile`] → checked.
//!
//! Pipeline: [`read`] (the file's text, bounded in size) → [`yaml`] (located YAML tree) → [`parser`] (expressions) → [`schema`] (typed
//! model, every unknown key / wrong type reported) → [`rules`] (cross-references and
//! semantics, and [`unit_check`] — dimensional analysis with the algebra of [`units`] — when
//! the file declares `units: SI`). [`load`] runs all of it and reports every diagnostic of a
//! file at once.

pub mod ast;
pub mod checks;
pub mod diagnostic;
pub mod elements;
pub mod file;
pub mod located;
pub mod parser;
pub mod read;
pub mod reduce;
pub mod rules;
pub mod schema;
pub mod templates;
pub mod unit_check;
pub mod units;
pub mod vectors;
pub mod yaml;

pub use ast::{BinOp, Expr, ExprKind};
pub use checks::*;
pub use diagnostic::{Diagnostic, Diagnostics};
pub use file::*;
pub use located::{Located, Location};
pub use read::{MAX_FILE_BYTES, ReadError, read_model_file};
pub use yaml::decode;

/// Reads a model file: YAML → typed model → checks, reporting every problem at once.
///
/// `path` is used only in messages (as the user wrote it). The schema pass and the
/// cross-object checks both run even when the other finds problems; entries the schema pass
/// had to leave out are not reported again by the checks. A file whose only mistakes are
/// units is also lowered ([`crate::mechanics::SymbolicModel::from_file`]), so that what the
/// derivation finds (a redundant constraint, a constant that overflows) comes with them.
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
            let (rules, units) = rules::check_parts(&file, &built.incomplete);
            let sound = diagnostics.is_empty() && rules.is_empty();
            diagnostics.extend(rules);
            diagnostics.extend(units);
            if diagnostics.is_empty() {
                return Ok(file);
            }
            // Only units are wrong: the file is sound to derive, and a mistake the derivation
            // finds is reported now rather than after the units are fixed.
            if sound && let Err(more) = crate::mechanics::SymbolicModel::from_file(&file) {
                for d in more {
                    if !diagnostics.contains(&d) {
                        diagnostics.push(d);
                    }
                }
            }
        }
    }
    diagnostics.sort_by_key(|d| d.location);
    Err(diagnostics)
}
