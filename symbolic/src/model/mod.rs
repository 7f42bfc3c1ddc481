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
