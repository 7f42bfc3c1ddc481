//! Model files: YAML with source locations → typed [`ModelFile`] → checked.
//!
//! Pipeline: [`yaml`] (located YAML tree) → [`parser`] (expressions) → [`schema`] (typed
//! model, every unknown key / wrong type reported) → [`check`] (cross-references and
//! semantics). [`load`] runs all of it and reports every diagnostic of a file at once.

pub mod ast;
pub mod check;
pub mod diagnostic;
pub mod file;
pub mod located;
pub mod parser;
pub mod schema;
pub mod yaml;

pub use ast::{BinOp, Expr, ExprKind};
pub use diagnostic::{Diagnostic, Diagnostics};
pub use file::*;
pub use located::{Located, Location};

/// Reads a model file: YAML → typed model → checks, reporting every problem at once.
///
/// `path` is used only in messages (as the user wrote it).
///
/// # Errors
/// All diagnostics of the file sorted by location. A YAML syntax error stops early (there is
/// no tree to check); schema errors are reported before the cross-object checks run.
pub fn load(path: &str, source: &str) -> Result<ModelFile, Vec<Diagnostic>> {
    let sort = |mut d: Vec<Diagnostic>| {
        d.sort_by_key(|x| x.location);
        d
    };
    let root = yaml::parse(source).map_err(sort)?;
    let file = schema::build(path, source, &root).map_err(sort)?;
    check::check(&file).map_err(sort)?;
    Ok(file)
}
