//! The reduced model file's text: what the elimination changes ([`Edits`]) and its
//! expressions in the kept coordinates ([`Rewrite`]), written by the schema's writer, section
//! by section ([`write_file`]).

use super::*;
use crate::model::schema::write::{Edits, NotRewritten, Rewrite};
use crate::model::schema::write_file;

/// The reducer as the writer's [`Rewrite`]: each expression in the kept coordinates, and the
/// error of the one that stopped the writing.
struct Rewriter<'r, 'a> {
    reducer: &'r mut Reducer<'a>,
    /// The kept coordinates, onto which the generalized forces are moved.
    kept: &'r [String],
    /// The error behind the last [`NotRewritten`].
    error: Option<ReduceError>,
}

impl Rewriter<'_, '_> {
    /// `result`, its error kept and handed to the writer as a [`NotRewritten`].
    fn keep_error<T>(&mut self, result: Result<T, ReduceError>) -> Result<T, NotRewritten> {
        result.map_err(|error| {
            let message = error.to_string();
            self.error = Some(error);
            NotRewritten { message }
        })
    }
}

impl Rewrite for Rewriter<'_, '_> {
    fn expr(&mut self, e: &Expr, place: &str) -> Result<String, NotRewritten> {
        // Only the error of the expression that stops the writing is returned: one left out
        // with a note before it is forgotten.
        self.error = None;
        let result = self.reducer.rewrite(e, place);
        self.keep_error(result)
    }

    fn generalized_forces(&mut self) -> Result<Option<Vec<(String, String)>>, NotRewritten> {
        self.error = None;
        let result = self.reducer.generalized_forces(self.kept);
        self.keep_error(result).map(Some)
    }
}

impl Reducer<'_> {
    /// The reduced file's YAML text, with `notes` on what was left out or changed.
    pub(super) fn write(
        &mut self,
        name: &str,
        kept: &[String],
        eliminations: &[Elimination],
        initial: &[(String, Expr)],
        notes: &mut Vec<String>,
    ) -> Result<String, ReduceError> {
        let file = self.file;
        // A file written as it is ([`write_model`]) keeps its constraints and twin.
        let preserve = eliminations.is_empty();
        let mut header = String::new();
        if !preserve {
            self.write_header(&mut header, kept, eliminations);
        }
        let edits = Edits {
            header,
            name: Some(name.to_string()),
            description: (!preserve).then(|| {
                format!(
                    "{} Reduced to {} (constraints eliminated).",
                    file.description.trim_end(),
                    kept.join(", ")
                )
            }),
            kept: (!preserve).then(|| kept.to_vec()),
            eliminated: eliminations
                .iter()
                .map(|e| (e.constraint.clone(), e.coordinate.clone()))
                .collect(),
            initial: Some(initial.to_vec()),
            dropped_equilibria: self.dropped_equilibria(),
            singular: self.singular_events(),
        };
        let mut rewriter = Rewriter {
            reducer: self,
            kept,
            error: None,
        };
        match write_file(file, &mut rewriter, &edits) {
            Ok((text, written)) => {
                notes.extend(written);
                Ok(text)
            }
            Err(stopped) => Err(rewriter.error.take().unwrap_or(ReduceError::Invalid {
                messages: vec![stopped.message],
            })),
        }
    }

    /// The equilibria the reduced file leaves out, each with its note: those off the chosen
    /// branches and those where the kept coordinates are singular.
    fn dropped_equilibria(&self) -> Vec<(String, String)> {
        let mut dropped = Vec::new();
        for eq in &self.file.equilibria {
            let name = &eq.name.value;
            if let Some(off) = self.off_branch(&eq.values) {
                dropped.push((
                    name.clone(),
                    format!(
                        "equilibrium `{name}` left out: it is not on the chosen branch ({off})"
                    ),
                ));
            } else if let Some(singular) = self.singular_at(&eq.values) {
                dropped.push((
                    name.clone(),
                    format!(
                        "equilibrium `{name}` left out: the reduced coordinates are singular there ({singular})"
                    ),
                ));
            }
        }
        dropped
    }

    /// Where the reduced model is singular, each with its note and the terminal event
    /// `(name, when)` that ends runs there, if it is one of the state.
    fn singular_events(&self) -> Vec<(String, Option<(String, String)>)> {
        self.moving_singularities()
            .into_iter()
            .map(|(coordinate, e, event)| {
                let name = format!("{coordinate}_singular");
                let note = format!(
                    "the reduced model is singular where {e} = 0 (`{coordinate}` is solved by dividing by it, or by a square root of it): the kept coordinates do not determine `{coordinate}` there, and the motion past it is not unique{}",
                    if event.is_some() {
                        format!("; the event `{name}` ends runs there")
                    } else {
                        "; a run that reaches it fails there".to_string()
                    }
                );
                (note, event.map(|when| (name, when)))
            })
            .collect()
    }

    /// The header of a reduced file: each elimination, its branch and where the kept
    /// coordinates no longer determine an eliminated one.
    fn write_header(&self, w: &mut String, kept: &[String], eliminations: &[Elimination]) {
        use std::fmt::Write as _;
        let file = self.file;
        let _ = writeln!(
            w,
            "# `{}` reduced to the coordinates {} by eliminating the holonomic constraints",
            file.name.value,
            kept.join(", ")
        );
        let _ = writeln!(
            w,
            "# (method II.2, lectures 8-10, HW13; written by `eomgen reduce`):"
        );
        for e in eliminations {
            let how = match &e.branch {
                None => String::new(),
                Some((b, BranchReason::Option)) => format!(", branch {} as asked", b.sign()),
                Some((b, BranchReason::InitialState)) => {
                    format!(", branch {} of the initial state", b.sign())
                }
                Some((b, BranchReason::Equilibrium(q))) => {
                    format!(", branch {} of the equilibrium `{q}`", b.sign())
                }
            };
            let _ = writeln!(
                w,
                "#   {} = {}  (from `{}`{how})",
                e.coordinate, e.solution, e.constraint
            );
            let _ = writeln!(w, "#   {}_dot = {}", e.coordinate, e.rate);
        }
        for (coordinate, e, event) in self.moving_singularities() {
            let _ = writeln!(
                w,
                "#   singular where {e} = 0: the kept coordinates do not determine {coordinate} there{}",
                if event.is_some() {
                    format!(" (event `{coordinate}_singular` ends runs)")
                } else {
                    String::new()
                }
            );
        }
    }

    /// The energy form's generalized forces moved onto the kept coordinates by virtual work:
    /// `Q_k + Σ_d Q_d ∂d/∂k`.
    fn generalized_forces(
        &mut self,
        kept: &[String],
    ) -> Result<Vec<(String, String)>, ReduceError> {
        let mut by_coordinate: Vec<(usize, ExprId)> = Vec::new();
        for (name, e) in &self.file.generalized_forces {
            let place = format!("generalized force `{}`", name.value);
            let q = self.lower_in(e, &place)?;
            if let Some(i) = self
                .file
                .coordinates
                .iter()
                .position(|c| c.name.value == name.value)
            {
                by_coordinate.push((i, q));
            }
        }
        let mut out = Vec::new();
        for (k, c) in self.file.coordinates.iter().enumerate() {
            if !kept.contains(&c.name.value) {
                continue;
            }
            let xk = self.coordinates[k][0];
            let mut terms = Vec::new();
            for &(i, q) in &by_coordinate {
                if i == k {
                    terms.push(q);
                } else if let Some(&root) = self.values.get(&self.coordinates[i][0]) {
                    let partial = self.arena.diff(root, xk);
                    terms.push(self.arena.times(q, partial));
                }
            }
            if terms.is_empty() {
                continue;
            }
            let sum = self.arena.sum(&terms);
            let sum = self.arena.substitute(sum, &self.values);
            let sum = self.arena.expand_if_cheaper(sum);
            if !self.arena.is_zero(sum) {
                out.push((c.name.value.clone(), self.print(sum)));
            }
        }
        Ok(out)
    }
}
