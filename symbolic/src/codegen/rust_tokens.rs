//! Rust tokens for the generated code: source text tokenized, identifiers, `f64` and index
//! literals.

use proc_macro2::{Ident, Literal, TokenStream, TokenTree};

/// The tokens of Rust source: an expression of the printer, or a path from [`EmitOptions`](super::EmitOptions).
///
/// # Errors
/// Source that does not tokenize (a bug of the printer, or a bad `crate_path`), with the
/// source.
pub(super) fn tokens(source: &str) -> Result<TokenStream, String> {
    source
        .parse()
        .map_err(|e| format!("generated code does not tokenize ({e}): {source}"))
}

/// An identifier, raw for `r#name`.
///
/// # Errors
/// A name that is not one identifier (the loader refuses such names, so this is a bug).
pub(super) fn ident(name: &str) -> Result<Ident, String> {
    let mut trees = tokens(name)?.into_iter();
    match (trees.next(), trees.next()) {
        (Some(TokenTree::Ident(ident)), None) => Ok(ident),
        _ => Err(format!("`{name}` is not a Rust identifier")),
    }
}

/// An `f64` literal as the printer writes one (`9.81_f64`, `-1.0_f64`).
///
/// # Errors
/// A value that is not finite, which has no literal (the loader refuses such defaults, so
/// this is a bug).
pub(super) fn float(value: f64) -> Result<TokenStream, String> {
    if !value.is_finite() {
        return Err(format!("{value} has no Rust literal"));
    }
    tokens(&format!("{value:?}_f64"))
}

/// An index or size, unsuffixed (`3`).
pub(super) fn index(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}
