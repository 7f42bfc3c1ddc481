//! Where a reduction is singular: the kept coordinates no longer determine an eliminated one (at
//! the start, at an equilibrium, or moving with the motion), or a state is off the branch taken.

use super::*;

impl Reducer<'_> {
    /// Where the reduced model's start is singular: a vanishing slope or discriminant.
    pub(super) fn singular_start(&self, initial: &[(String, Expr)]) -> Option<String> {
        let located: Vec<(crate::model::Located<String>, Expr)> = initial
            .iter()
            .map(|(n, e)| {
                (
                    crate::model::Located::new(n.clone(), Location::default()),
                    e.clone(),
                )
            })
            .collect();
        self.singular_at(&located)
    }

    /// Where the solutions are singular at `values` (the slope or discriminant that vanishes
    /// there), if they are.
    pub(super) fn singular_at(
        &self,
        values: &[(crate::model::Located<String>, Expr)],
    ) -> Option<String> {
        let bindings = self.bindings(values);
        self.singular_where
            .iter()
            .find_map(|(coordinate, e, discriminant)| {
                let v = self.arena.eval(*e, &bindings);
                // The size of the parameters the expression names (a length `l` for
                // `l² − x²`); a huge force elsewhere in the file does not make `1` small.
                let scale: f64 = self
                    .file
                    .parameters
                    .iter()
                    .filter(|p| {
                        self.arena
                            .symbol_id(&p.name.value)
                            .is_some_and(|s| self.arena.depends_on(*e, s))
                    })
                    .map(|p| p.value.abs())
                    .fold(1.0, f64::max);
                if *discriminant && v < 0.0 {
                    return Some(format!(
                        "{} = {v} < 0: no real `{coordinate}` satisfies the constraint",
                        self.print(*e)
                    ));
                }
                (v.is_nan() || v.abs() <= 1e-12 * scale * scale)
                    .then(|| format!("{} = {v} where `{coordinate}` is solved", self.print(*e)))
            })
    }

    /// The singularities of the eliminations that move with the state or the time (not a
    /// constant of the parameters): `(coordinate, expression, the event that ends runs
    /// there)`. A linear solution's slope changes sign there, and the event is the slope
    /// itself (explicit methods step over such a pole). A quadratic's discriminant reaches 0
    /// where the motion leaves the chosen branch (a pendulum kept in `x` that swings past the
    /// horizontal) and may only touch it, which no event function of the file's units can
    /// catch short of it: it is noted, and a run that reaches it fails there (the reduced
    /// mass matrix is not finite).
    pub(super) fn moving_singularities(&self) -> Vec<(String, String, Option<String>)> {
        self.singular_where
            .iter()
            .filter(|(_, e, _)| {
                self.arena.symbols().iter().enumerate().any(|(i, s)| {
                    matches!(
                        s.kind,
                        SymbolKind::Coordinate(_) | SymbolKind::Velocity(_) | SymbolKind::Time
                    ) && self.arena.depends_on(*e, SymbolId(i as u32))
                })
            })
            .map(|(c, e, discriminant)| {
                let text = self.print(*e);
                let event = (!*discriminant).then(|| text.clone());
                (c.clone(), text, event)
            })
            .collect()
    }

    /// Why an equilibrium's listed values of eliminated coordinates are off their chosen
    /// solution, if they are.
    pub(super) fn off_branch(
        &self,
        values: &[(crate::model::Located<String>, Expr)],
    ) -> Option<String> {
        let bindings = self.bindings(values);
        for (name, _) in values {
            let Some(s) = self.arena.symbol_id(&name.value) else {
                continue;
            };
            let Some(&root) = self.values.get(&s) else {
                continue;
            };
            if name.value.ends_with("_dot") {
                continue;
            }
            let (listed, solved) = (bindings[s.index()], self.arena.eval(root, &bindings));
            let off = (listed - solved).abs();
            if off.is_nan() || off > BRANCH_TOL * listed.abs().max(1.0) {
                return Some(format!(
                    "{} = {listed} there, the solution gives {solved}",
                    name.value
                ));
            }
        }
        None
    }
}
