//! Products in canonical form: nested products flattened, like factors gathered into powers and
//! numeric factors folded.

use super::*;

impl ExprArena {
    /// Canonical product of `factors`.
    pub fn product(&mut self, factors: &[ExprId]) -> ExprId {
        if self.over_limit() {
            return self.int(0);
        }
        // (base, exponent (`None` for 1), the factor itself)
        let mut powers: Vec<(ExprId, Option<ExprId>, ExprId)> =
            Vec::with_capacity(factors.len() + 2);
        let Some(mut coefficient) = self.gather_factors(factors, &mut powers) else {
            return self.int(0);
        };
        // Like factors: sorted by base (stably), then merged by adding their exponents.
        powers.sort_by_key(|(base, _, _)| *base);
        let mut results: Vec<ExprId> = Vec::with_capacity(powers.len());
        let mut needs_recanonicalisation = false;
        let mut start = 0;
        while start < powers.len() {
            let base = powers[start].0;
            let end = start
                + powers[start..]
                    .iter()
                    .take_while(|(b, _, _)| *b == base)
                    .count();
            if end == start + 1 {
                // A single canonical factor stays as it is.
                results.push(powers[start].2);
                start = end;
                continue;
            }
            let one = self.int(1);
            let exponents: Vec<ExprId> = powers[start..end]
                .iter()
                .map(|(_, e, _)| e.unwrap_or(one))
                .collect();
            start = end;
            let exponent = self.sum(&exponents);
            let p = self.pow(base, exponent);
            match self.node(p) {
                Node::Const(c) => {
                    let c = *c;
                    if c.is_zero() {
                        return self.int(0);
                    }
                    match coefficient.checked_mul(c) {
                        Ok(v) => coefficient = v,
                        Err(e) => {
                            self.fold_failed(e);
                            results.push(p);
                        }
                    }
                }
                Node::Mul(_) => {
                    needs_recanonicalisation = true;
                    results.push(p);
                }
                _ => results.push(p),
            }
        }
        if needs_recanonicalisation {
            let c = self.constant(coefficient);
            results.push(c);
            return self.product(&results);
        }
        results.sort();
        if !coefficient.is_one() {
            results.insert(0, self.constant(coefficient));
        }
        match results.len() {
            0 => self.constant(coefficient),
            1 => results[0],
            _ => self.add_ref(NodeRef::Mul(&results)),
        }
    }

    /// `terms` with nested sums flattened into their terms, in order.
    pub(super) fn flatten_sum(&self, terms: &[ExprId], out: &mut Vec<ExprId>) {
        for &t in terms {
            match self.node(t) {
                Node::Add(inner) => self.flatten_sum(inner, out),
                _ => out.push(t),
            }
        }
    }

    /// The factors of `Π factors` as `(base, exponent, factor)` in `powers` (nested products
    /// flattened), and the product of their numbers; `None` if that is zero.
    ///
    /// A product of numbers that cannot be folded (beyond `f64`, or lost to underflow) is
    /// recorded as a failed fold and not formed: the product is then gathered again by
    /// [`Self::gather_unflattened`], which keeps the numbers apart as written.
    fn gather_factors(
        &self,
        factors: &[ExprId],
        powers: &mut Vec<(ExprId, Option<ExprId>, ExprId)>,
    ) -> Option<Constant> {
        let mark = powers.len();
        match self.gather_flat(factors, powers) {
            Ok(coefficient) => coefficient,
            Err(error) => {
                self.fold_failed(error);
                powers.truncate(mark);
                self.gather_unflattened(factors, powers)
            }
        }
    }

    /// [`Self::gather_factors`] with every nested product flattened and every number folded
    /// into one, in order; the first fold that fails is the error.
    fn gather_flat(
        &self,
        factors: &[ExprId],
        powers: &mut Vec<(ExprId, Option<ExprId>, ExprId)>,
    ) -> Result<Option<Constant>, FoldError> {
        let mut coefficient = Constant::ONE;
        for &f in factors {
            match self.node(f) {
                Node::Mul(inner) => match self.gather_flat(inner, powers)? {
                    Some(c) => coefficient = coefficient.checked_mul(c)?,
                    None => return Ok(None),
                },
                Node::Const(c) if c.is_zero() => return Ok(None),
                Node::Const(c) => coefficient = coefficient.checked_mul(*c)?,
                Node::Pow([b, e]) => powers.push((*b, Some(*e), f)),
                _ => powers.push((f, None, f)),
            }
        }
        // A product of non-zero numbers that folds is not zero (an underflow is an error).
        Ok(Some(coefficient))
    }

    /// [`Self::gather_factors`] of a product whose numbers do not fold into one: the numbers
    /// among `factors` are folded first (one that would overflow or underflow stays a factor
    /// of its own), then a nested product is flattened only if its numbers fold into that
    /// coefficient, and is otherwise kept whole. So `16 · (1e-300 x¹⁵) · 1e-20`, the
    /// derivative of `(1e-20 x)¹⁶`, becomes `1.6e-19 · (1e-300 x¹⁵)`: it forms no number
    /// below the normal range, and evaluates at `x = 1e20` as it is written.
    pub(super) fn gather_unflattened(
        &self,
        factors: &[ExprId],
        powers: &mut Vec<(ExprId, Option<ExprId>, ExprId)>,
    ) -> Option<Constant> {
        let mut coefficient = Constant::ONE;
        for &f in factors {
            if let Node::Const(c) = self.node(f) {
                if c.is_zero() {
                    return None;
                }
                match coefficient.checked_mul(*c) {
                    Ok(v) => coefficient = v,
                    Err(e) => {
                        self.fold_failed(e);
                        powers.push((f, None, f));
                    }
                }
            }
        }
        for &f in factors {
            match self.node(f) {
                Node::Const(_) => {}
                Node::Mul(inner) => {
                    let mark = powers.len();
                    match self
                        .gather_flat(inner, powers)
                        .and_then(|c| c.map(|c| coefficient.checked_mul(c)).transpose())
                    {
                        Ok(Some(v)) => coefficient = v,
                        Ok(None) => return None,
                        Err(_) => {
                            powers.truncate(mark);
                            powers.push((f, None, f));
                        }
                    }
                }
                Node::Pow([b, e]) => powers.push((*b, Some(*e), f)),
                _ => powers.push((f, None, f)),
            }
        }
        Some(coefficient)
    }
}
