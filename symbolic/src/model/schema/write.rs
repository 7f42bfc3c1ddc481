//! A [`ModelFile`] written back as YAML text, section by section, by the same table that reads
//! a file (`SECTIONS` in `sections.rs`, whose `write_file` writes one): each row reads its key and writes it. Each section's
//! writer sits beside its reader, in the file of its group.
//!
//! The writer writes expressions through a [`Rewrite`], so that a transformer (`reduce`) can
//! write them in other coordinates, and takes what a transformer changes beyond expressions
//! as [`Edits`]; with none (`Edits::default()`) every section of the file is written. Every value is
//! written in the form the schema reads, and what the text cannot carry is said in notes.

use std::fmt::Write as _;

use super::*;

/// How the writer spells an expression of the file.
pub trait Rewrite {
    /// `e`, read at `place` (such as "spring `s1`"), as the text to write.
    ///
    /// # Errors
    /// [`NotRewritten`] if it cannot be written there; the implementor keeps its own error.
    fn expr(&mut self, e: &Expr, place: &str) -> Result<String, NotRewritten>;

    /// `generalized_forces:` as the transformer writes them, by coordinate; `None` (the
    /// default): the file's, each through [`Rewrite::expr`]. Called where the section is
    /// written.
    ///
    /// # Errors
    /// [`NotRewritten`] if they cannot be written.
    fn generalized_forces(&mut self) -> Result<Option<Vec<(String, String)>>, NotRewritten> {
        Ok(None)
    }
}

/// An expression that [`Rewrite::expr`] could not write: `message` says why, for a note
/// when the writer leaves its entry out; the implementor keeps its typed error for when the
/// writing stops.
#[derive(Debug, Clone, PartialEq)]
pub struct NotRewritten {
    /// Why, in words.
    pub message: String,
}

/// What a transformer changes of a file beyond its expressions. The default changes
/// nothing: the file is written as it is, with its constraints and twin.
#[derive(Debug, Clone, Default)]
pub struct Edits {
    /// Comment lines written before `name:` (each with its `#` and newline).
    pub header: String,
    /// The new `name:`.
    pub name: Option<String>,
    /// The new `description:`.
    pub description: Option<String>,
    /// The coordinates kept when the others are eliminated (with their constraints); `None`
    /// for the file as it is.
    pub kept: Option<Vec<String>>,
    /// The eliminations, as `(constraint, coordinate)`, for the note on `constraints:`.
    pub eliminated: Vec<(String, String)>,
    /// The initial values written, by name (`x`, `x_dot`); `None`: the file's.
    pub initial: Option<Vec<(String, Expr)>>,
    /// Equilibria left out, by name, with the note that says why.
    pub dropped_equilibria: Vec<(String, String)>,
    /// Where the new coordinates are singular, each with its note and, when runs end
    /// there, the terminal event `(name, when)` written for it.
    pub singular: Vec<(String, Option<(String, String)>)>,
}

/// The text being written, with its notes and what later sections need of earlier ones.
pub(crate) struct Writer<'a> {
    /// The YAML text so far.
    pub(crate) w: String,
    /// What was left out or changed, in words.
    pub(crate) notes: Vec<String>,
    rewrite: &'a mut dyn Rewrite,
    pub(crate) edits: &'a Edits,
    /// The equilibria written (`checks:` keeps the modal values at those only).
    pub(crate) kept_equilibria: Vec<String>,
    /// The events written (`checks: period` needs its event).
    pub(crate) kept_events: Vec<String>,
}

impl<'a> Writer<'a> {
    /// A writer of an empty text, with `rewrite` and `edits`.
    pub(crate) fn new(rewrite: &'a mut dyn Rewrite, edits: &'a Edits) -> Self {
        Self {
            w: String::new(),
            notes: Vec::new(),
            rewrite,
            edits,
            kept_equilibria: Vec::new(),
            kept_events: Vec::new(),
        }
    }

    /// `generalized_forces:` as the [`Rewrite`] writes them, if it does.
    pub(crate) fn rewritten_generalized_forces(
        &mut self,
    ) -> Result<Option<Vec<(String, String)>>, NotRewritten> {
        self.rewrite.generalized_forces()
    }

    /// `e` through the [`Rewrite`].
    pub(crate) fn expr(&mut self, e: &Expr, place: &str) -> Result<String, NotRewritten> {
        self.rewrite.expr(e, place)
    }

    /// Each of `parts` through the [`Rewrite`].
    pub(crate) fn exprs(
        &mut self,
        parts: &[Expr],
        place: &str,
    ) -> Result<Vec<String>, NotRewritten> {
        parts.iter().map(|e| self.expr(e, place)).collect()
    }

    /// Whether the file is written as it is (nothing eliminated).
    pub(crate) fn preserve(&self) -> bool {
        self.edits.kept.is_none()
    }

    /// Whether the coordinate `n` is written.
    pub(crate) fn is_kept(&self, n: &str) -> bool {
        self.edits
            .kept
            .as_ref()
            .is_none_or(|kept| kept.iter().any(|k| k == n))
    }

    /// Whether `n` is a written coordinate or its rate.
    pub(crate) fn is_kept_name(&self, n: &str) -> bool {
        self.is_kept(n) || n.strip_suffix("_dot").is_some_and(|c| self.is_kept(c))
    }

    /// Appends `line` and a newline.
    pub(crate) fn line(&mut self, line: impl std::fmt::Display) {
        let _ = writeln!(self.w, "{line}");
    }

    /// `key:` then the entries of `block` (each line already indented), if there are any.
    pub(crate) fn block(&mut self, key: &str, block: &str) {
        if !block.is_empty() {
            self.line(format_args!("{key}:"));
            self.w.push_str(block);
        }
    }
}

// How the writer spells a value in YAML.

/// A plain scalar where YAML reads it as the text, else in double quotes.
pub(crate) fn scalar(s: &str) -> String {
    let special = s.is_empty()
        || s.contains(": ")
        || s.contains(" #")
        || s.starts_with([
            '[', ']', '{', '}', ',', '#', '&', '*', '!', '|', '>', '\'', '"', '%', '@', '`',
        ])
        || s.starts_with("- ")
        || s.ends_with(':');
    if special { quoted(s) } else { s.to_string() }
}

/// A scalar inside a flow collection (`[…]`, `{…}`): quoted if it has a flow indicator.
pub(crate) fn flow(s: &str) -> String {
    if s.contains([',', '[', ']', '{', '}']) {
        quoted(s)
    } else {
        scalar(s)
    }
}

/// `s` in double quotes, with `\` and `"` escaped.
fn quoted(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// `[a, b, …]` of expressions.
pub(crate) fn list(parts: &[String]) -> String {
    let parts: Vec<String> = parts.iter().map(|p| flow(p)).collect();
    format!("[{}]", parts.join(", "))
}
