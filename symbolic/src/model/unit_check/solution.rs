//! Solving the equations of dimension for the units left unknown, and naming the units the file
//! leaves undeclared.

use super::*;

impl Checker<'_> {
    /// Solves the unknowns one at a time. Every equation with exactly one unknown left,
    /// `known · x^c = 1`, proposes `x = known^(-1/c)`; the proposal that satisfies the most
    /// equations wins (ties: key requirements first, then file order), so that one wrong
    /// formula does not outvote the others.
    ///
    /// An equation with the one unknown `i` left holds for `x` exactly when it proposes `x`
    /// itself (dimensions have no roots of unity), and an equation with none left holds for
    /// every proposal alike; so the votes for `(i, x)` are counted as the equations proposing
    /// it, with each equation reduced once a round (counting by re-checking every equation
    /// for every proposal took 7.5 s for a 40-link pendulum with no coordinate units).
    pub(super) fn solve(&mut self) {
        loop {
            let proposals: Vec<(usize, Dimension, &Equation)> = self
                .equations
                .iter()
                .filter_map(|eq| {
                    let (known, left) = self.reduce(&eq.dim)?;
                    let [(i, c)] = left[..] else { return None };
                    let x = Rational::integer(-1)
                        .checked_div(c)
                        .and_then(|p| known.pow(p))?;
                    Some((i, x, eq))
                })
                .collect();
            let mut votes: HashMap<(usize, Dimension), usize> = HashMap::new();
            for &(i, x, _) in &proposals {
                *votes.entry((i, x)).or_default() += 1;
            }
            let mut best: Option<(usize, u8, usize, Dimension, &Equation)> = None;
            for &(i, x, eq) in &proposals {
                let count = votes[&(i, x)];
                let better = best
                    .as_ref()
                    .is_none_or(|(v, p, ..)| count > *v || (count == *v && eq.priority < *p));
                if better {
                    best = Some((count, eq.priority, i, x, eq));
                }
            }
            let Some((_, _, i, unit, eq)) = best else {
                return;
            };
            let solved = Solved {
                unit,
                origin: eq.origin.clone(),
                at: eq.at,
                spelling: eq.spelling.clone(),
            };
            if let Some(s) = self.solution.get_mut(i) {
                *s = Some(solved);
            }
        }
    }

    /// An equation with the solved unknowns substituted: its known part and the unknowns
    /// left (`None` on exponent overflow).
    fn reduce(&self, eq: &Dim) -> Option<(Dimension, Vec<(usize, Rational)>)> {
        let mut known = eq.known;
        let mut left = Vec::new();
        for &(i, c) in &eq.unknowns {
            match self.solution.get(i).and_then(Option::as_ref) {
                Some(x) => known = known.checked_mul(x.unit.pow(c)?)?,
                None => left.push((i, c)),
            }
        }
        Some((known, left))
    }

    /// Parameters without a unit, and coordinates whose unit could not be inferred.
    pub(super) fn undeclared(&mut self) {
        let file = self.file;
        for (k, &(is_coordinate, i)) in self.unknowns.iter().enumerate() {
            let implied = self.solution.get(k).cloned().flatten();
            if is_coordinate {
                if implied.is_some() {
                    continue;
                }
                let Some(c) = file.coordinates.get(i) else {
                    continue;
                };
                let n = &c.name.value;
                self.diagnostics.push(
                    Diagnostic::new(
                        c.name.location,
                        format!("the unit of coordinate `{n}` is neither declared nor implied by its use"),
                    )
                    .with_help(format!(
                        "declare it at the start of its comment, `- {n}  # m`, or as `- {{ name: {n}, unit: m }}`"
                    )),
                );
                continue;
            }
            let Some(p) = file.parameters.get(i) else {
                continue;
            };
            let n = &p.name.value;
            let value = write_expr(&p.default, 0);
            let shared = file
                .parameters
                .iter()
                .any(|o| o.name.location.line == p.name.location.line && o.name.value != *n);
            let line = if shared { " on a line of its own" } else { "" };
            let help = match implied {
                Some(u) => format!(
                    "write `{n}: {value}  # {u}`{line} (the unit its use implies), or `{n}: {{ value: {value}, unit: {u} }}`",
                    u = u.text()
                ),
                None => format!(
                    "write its unit in a trailing comment, `{n}: {value}  # N/m`{line}, or `{n}: {{ value: {value}, unit: N/m }}` (`1` for a pure number)"
                ),
            };
            self.diagnostics.push(
                Diagnostic::new(p.name.location, format!("parameter `{n}` has no unit"))
                    .with_help(help),
            );
        }
    }
}
