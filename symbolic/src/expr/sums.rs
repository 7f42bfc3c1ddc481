//! Sums in canonical form: like terms collected with exact rational coefficients, `sin² + cos² = 1`
//! and the angle-difference identities applied as a sum is built.

use super::*;

impl ExprArena {
    /// Splits a term into `(coefficient, rest)` with `term = coefficient · rest`; `rest` is
    /// `None` for a pure constant.
    pub(super) fn split_coefficient(&mut self, term: ExprId) -> (Constant, Option<ExprId>) {
        let (c, rest) = match self.node(term) {
            Node::Const(c) => return (*c, None),
            Node::Mul(factors) => match self.as_constant(factors[0]) {
                Some(c) if factors.len() == 2 => return (c, Some(factors[1])),
                Some(c) => match self.lookup(NodeRef::Mul(&factors[1..])) {
                    Some(rest) => return (c, Some(rest)),
                    None => (c, Node::Mul(factors[1..].into())),
                },
                None => return (Constant::ONE, Some(term)),
            },
            _ => return (Constant::ONE, Some(term)),
        };
        (c, Some(self.add(rest)))
    }

    /// `c · rest` for a non-constant `rest` without a numeric factor (as
    /// [`Self::split_coefficient`] returns it): the canonical product, built directly.
    pub(super) fn with_coefficient(&mut self, c: Constant, rest: ExprId) -> ExprId {
        if c.is_one() {
            return rest;
        }
        let coefficient = self.constant(c);
        let factors: Vec<ExprId> = match self.node(rest) {
            // A product with a number of its own is one whose numbers did not fold into one
            // ([`Self::gather_unflattened`]): it is multiplied by the rules.
            Node::Mul(f) if f.iter().any(|&x| self.as_constant(x).is_some()) => {
                return self.product(&[coefficient, rest]);
            }
            Node::Mul(f) => std::iter::once(coefficient)
                .chain(f.iter().copied())
                .collect(),
            _ => vec![coefficient, rest],
        };
        self.add_ref(NodeRef::Mul(&factors))
    }

    /// Canonical sum of `terms`.
    pub fn sum(&mut self, terms: &[ExprId]) -> ExprId {
        // The canonical sum does not depend on the order of the terms (they are sorted and
        // merged), so `a + b` and `b + a` share one memo entry.
        if let &[a, b] = terms {
            let key = (a.min(b), a.max(b));
            if let Some(&s) = self.pair_sum_memo.get(&key) {
                return s;
            }
            let s = self.sum_uncached(terms);
            self.pair_sum_memo.insert(key, s);
            return s;
        }
        self.sum_uncached(terms)
    }

    /// [`Self::sum`] without the memo.
    fn sum_uncached(&mut self, terms: &[ExprId]) -> ExprId {
        if self.over_limit() {
            return self.int(0);
        }
        let mut constant = Constant::ZERO;
        let mut flat: Vec<ExprId> = Vec::with_capacity(terms.len());
        self.flatten_sum(terms, &mut flat);
        // (rest, coefficient, the term itself while it is the only one with this rest)
        let mut merged: Vec<(ExprId, Constant, Option<ExprId>)> = Vec::with_capacity(flat.len());
        let mut float_fallback: Vec<ExprId> = Vec::new();
        for term in flat {
            match self.split_coefficient(term) {
                (c, None) => match constant.checked_add(c) {
                    Ok(s) => constant = s,
                    Err(e) => {
                        self.fold_failed(e);
                        float_fallback.push(term);
                    }
                },
                (c, Some(rest)) => merged.push((rest, c, Some(term))),
            }
        }
        // Like terms: sorted by rest (stably, so in input order within a rest), then merged.
        merged.sort_by_key(|(rest, _, _)| *rest);
        let mut kept = 0;
        for k in 0..merged.len() {
            let (rest, c, original) = merged[k];
            if kept > 0 && merged[kept - 1].0 == rest {
                let (_, total, o) = &mut merged[kept - 1];
                match total.checked_add(c) {
                    Ok(s) => {
                        *total = s;
                        *o = None;
                    }
                    Err(e) => {
                        self.fold_failed(e);
                        float_fallback.extend(original);
                    }
                }
            } else {
                merged[kept] = (rest, c, original);
                kept += 1;
            }
        }
        merged.truncate(kept);
        let sines = merged
            .iter()
            .any(|(rest, _, _)| self.has_sine_square(*rest));
        let products = merged
            .iter()
            .filter(|(rest, _, _)| self.has_two_trig_factors(*rest))
            .nth(1)
            .is_some();
        if sines || products {
            let mut collected: indexmap::IndexMap<ExprId, Constant> =
                merged.iter().map(|(rest, c, _)| (*rest, *c)).collect();
            if sines {
                self.collect_pythagorean(&mut collected, &mut constant);
            }
            if products {
                self.collect_angle_differences(&mut collected);
            }
            let mut entries: Vec<(ExprId, Constant)> = collected.into_iter().collect();
            entries.sort_by_key(|(rest, _)| *rest);
            // A term that the identities left alone keeps its node.
            let original = |rest: ExprId, c: Constant| {
                merged
                    .binary_search_by_key(&rest, |(r, _, _)| *r)
                    .ok()
                    .and_then(|k| (merged[k].1 == c).then_some(merged[k].2).flatten())
            };
            merged = entries
                .into_iter()
                .map(|(rest, c)| (rest, c, original(rest, c)))
                .collect();
        }
        let mut operands: Vec<ExprId> = Vec::with_capacity(merged.len() + 1);
        for (rest, c, original) in merged {
            if c.is_zero() {
                continue;
            }
            operands.push(match original {
                Some(term) => term,
                None => self.with_coefficient(c, rest),
            });
        }
        operands.extend(float_fallback);
        operands.sort();
        if !constant.is_zero() {
            operands.insert(0, self.constant(constant));
        }
        match operands.len() {
            0 => self.int(0),
            1 => operands[0],
            _ => self.add_ref(NodeRef::Add(&operands)),
        }
    }

    /// Each way of reading `term` as `f(u)² · X` for `f` = `func` (sine or cosine): `u` and
    /// where the square stands, `None` when it is the whole term, else its index among the
    /// factors of the product `term`.
    fn trig_squares(&self, term: ExprId, func: Func) -> Vec<(Option<usize>, ExprId)> {
        let square = |f: ExprId| match self.node(f) {
            Node::Pow([b, e]) if self.as_constant(*e) == Some(Constant::int(2)) => {
                match self.node(*b) {
                    Node::Func(g, u) if *g == func => Some(*u),
                    _ => None,
                }
            }
            _ => None,
        };
        if let Some(u) = square(term) {
            return vec![(None, u)];
        }
        let Node::Mul(factors) = self.node(term) else {
            return Vec::new();
        };
        factors
            .iter()
            .enumerate()
            .filter_map(|(i, &f)| square(f).map(|u| (Some(i), u)))
            .collect()
    }

    /// Each way of reading `rest` as `sin²u · X` (a power, or a product with one or more such
    /// factors): `u` and the other factors `X` (sorted ids), one per `sin²` factor. A term
    /// with two (`sin²θ cos²φ` beside `sin²θ sin²φ`, the heavy top's `M`) pairs with its
    /// partner through either.
    fn sine_square_factors(&self, rest: ExprId) -> Vec<(ExprId, Vec<ExprId>)> {
        self.trig_squares(rest, Func::Sin)
            .into_iter()
            .map(|(at, u)| {
                let others = match (at, self.node(rest)) {
                    (Some(i), Node::Mul(factors)) => factors
                        .iter()
                        .enumerate()
                        .filter(|(j, _)| *j != i)
                        .map(|(_, x)| *x)
                        .collect(),
                    _ => Vec::new(),
                };
                (u, others)
            })
            .collect()
    }

    /// Pythagorean identity on collected sum terms: `c·X·sin²u + c·X·cos²u = c·X`.
    ///
    /// The partner term `X·cos²u` is looked up in the hash-cons table without creating nodes;
    /// it can only be among the terms if it already exists. Terms whose coefficients differ are
    /// left alone (that would need a choice of which square to keep).
    fn collect_pythagorean(
        &mut self,
        collected: &mut indexmap::IndexMap<ExprId, Constant>,
        constant: &mut Constant,
    ) {
        // One pass over the terms with a sin² factor; a term this creates is examined in turn.
        let mut pending: Vec<ExprId> = collected
            .keys()
            .copied()
            .filter(|&rest| self.has_sine_square(rest))
            .collect();
        pending.reverse();
        while let Some(rest) = pending.pop() {
            let Some(&c) = collected.get(&rest) else {
                continue;
            };
            if c.is_zero() {
                continue;
            }
            let Some((others, partner)) =
                self.sine_square_factors(rest)
                    .into_iter()
                    .find_map(|(u, others)| {
                        let partner = self.cosine_square_partner(u, &others)?;
                        (collected.get(&partner) == Some(&c)).then_some((others, partner))
                    })
            else {
                continue;
            };
            // The sum first: a coefficient that would overflow leaves both terms as they are.
            let x = match others.len() {
                0 => None,
                1 => Some(others[0]),
                _ => Some(self.add(Node::Mul(others.into()))),
            };
            let before = x.map_or(*constant, |x| {
                collected.get(&x).copied().unwrap_or(Constant::ZERO)
            });
            let sum = match before.checked_add(c) {
                Ok(sum) => sum,
                Err(e) => {
                    self.fold_failed(e);
                    continue;
                }
            };
            // Zeroed, not removed: removing from the middle of an `IndexMap` moves every later
            // entry, quadratic in the number of terms; zero terms are dropped at the end.
            zero_term(collected, rest);
            zero_term(collected, partner);
            let Some(x) = x else {
                *constant = sum;
                continue;
            };
            collected.insert(x, sum);
            // `x` may now pair: through a sin² factor of its own, or as the cos² partner of a
            // term examined before it existed (`X·sin²v` beside the new `X·cos²v`).
            if self.has_sine_square(x) {
                pending.push(x);
            }
            pending.extend(
                self.sine_square_partners(x)
                    .into_iter()
                    .filter(|t| collected.get(t).is_some_and(|c| !c.is_zero())),
            );
        }
    }

    /// The terms `X·sin²v` that exist for each way of reading `term` as `X·cos²v` (looked up,
    /// never made): those the Pythagorean identity pairs `term` with.
    fn sine_square_partners(&self, term: ExprId) -> Vec<ExprId> {
        let Some(two) = self.lookup(NodeRef::Const(Constant::int(2))) else {
            return Vec::new();
        };
        let sin_square = |v: ExprId| {
            let sin = self.lookup(NodeRef::Func(Func::Sin, v))?;
            self.lookup(NodeRef::Pow([sin, two]))
        };
        self.trig_squares(term, Func::Cos)
            .into_iter()
            .filter_map(|(at, v)| {
                let sin2 = sin_square(v)?;
                let (Some(i), Node::Mul(factors)) = (at, self.node(term)) else {
                    return Some(sin2);
                };
                let mut swapped: Vec<ExprId> = factors.to_vec();
                swapped[i] = sin2;
                swapped.sort();
                self.lookup(NodeRef::Mul(&swapped))
            })
            .collect()
    }

    /// The term `X·cos²u` if its node exists (looked up in the hash-cons table, never made):
    /// the partner of `X·sin²u` in the Pythagorean identity.
    fn cosine_square_partner(&self, u: ExprId, others: &[ExprId]) -> Option<ExprId> {
        let cos = self.lookup(NodeRef::Func(Func::Cos, u))?;
        let two = self.lookup(NodeRef::Const(Constant::int(2)))?;
        let cos2 = self.lookup(NodeRef::Pow([cos, two]))?;
        if others.is_empty() {
            return Some(cos2);
        }
        let mut factors = others.to_vec();
        factors.push(cos2);
        factors.sort();
        self.lookup(NodeRef::Mul(&factors))
    }

    /// Whether `rest` is `sin²u` or a product with such a factor (a cheap pre-filter of
    /// [`Self::sine_square_factors`]).
    fn has_sine_square(&self, rest: ExprId) -> bool {
        let is_sin2 = |f: &ExprId| match self.node(*f) {
            Node::Pow([b, _]) => matches!(self.node(*b), Node::Func(Func::Sin, _)),
            _ => false,
        };
        match self.node(rest) {
            Node::Mul(factors) => factors.iter().any(is_sin2),
            _ => is_sin2(&rest),
        }
    }

    /// Whether the term `rest` has sine or cosine factors of two different arguments (a
    /// cheap pre-filter of [`Self::collect_angle_differences`]).
    fn has_two_trig_factors(&self, rest: ExprId) -> bool {
        let Node::Mul(factors) = self.node(rest) else {
            return false;
        };
        let mut first: Option<ExprId> = None;
        for f in factors.iter() {
            if let Node::Func(Func::Sin | Func::Cos, u) = self.node(*f) {
                match first {
                    Some(v) if v != *u => return true,
                    _ => first = Some(*u),
                }
            }
        }
        false
    }

    /// Angle-difference identities on collected sum terms:
    /// `c·X·cos u·cos v + c·X·sin u·sin v = c·X·cos(u − v)` and
    /// `c·X·sin u·cos v − c·X·cos u·sin v = c·X·sin(u − v)`, with `u` the argument of smaller
    /// id so that each difference has one canonical node. Partners are found by hash-cons
    /// lookups only.
    fn collect_angle_differences(&mut self, collected: &mut indexmap::IndexMap<ExprId, Constant>) {
        // One pass over the terms with two trigonometric factors; a term this creates is
        // examined in turn (cos(u − v)·cos w + sin(u − v)·sin w folds again).
        let mut pending: Vec<ExprId> = collected
            .keys()
            .copied()
            .filter(|&rest| self.has_two_trig_factors(rest))
            .collect();
        if pending.len() < 2 {
            return;
        }
        pending.reverse();
        while let Some(rest) = pending.pop() {
            let Some(&c) = collected.get(&rest) else {
                continue;
            };
            let Some(AngleMatch {
                rest,
                partner,
                others,
                c,
                result,
                u,
                v,
            }) = self.angle_partner(rest, c, collected)
            else {
                continue;
            };
            zero_term(collected, rest);
            zero_term(collected, partner);
            // Canonical difference: smaller id first; sin(v − u) = −sin(u − v).
            let (a, b, flip) = if u < v { (u, v, false) } else { (v, u, true) };
            let diff = self.minus(a, b);
            let f = self.func(result, diff);
            let mut coefficient = c;
            if flip && result == Func::Sin {
                coefficient = c.negated();
            }
            let mut parts = others;
            parts.push(f);
            let term = self.product(&parts);
            let (k, rest_term) = self.split_coefficient(term);
            let total = coefficient.checked_mul(k).unwrap_or(coefficient);
            match rest_term {
                Some(r) => {
                    let entry = collected.entry(r).or_insert(Constant::ZERO);
                    *entry = entry.checked_add(total).unwrap_or(*entry);
                    if self.has_two_trig_factors(r) {
                        pending.push(r);
                    }
                }
                None => {
                    // A constant term cannot arise (f is not constant), but keep it safe.
                    collected.insert(term, Constant::ONE);
                }
            }
        }
    }

    /// The term of `collected` that combines with `c·rest` by an angle-difference identity
    /// (see [`Self::collect_angle_differences`]), found by hash-cons lookups only.
    fn angle_partner(
        &self,
        rest: ExprId,
        c: Constant,
        collected: &indexmap::IndexMap<ExprId, Constant>,
    ) -> Option<AngleMatch> {
        if c.is_zero() {
            return None;
        }
        let Node::Mul(factors) = self.node(rest) else {
            return None;
        };
        let trig: Vec<(usize, Func, ExprId)> = factors
            .iter()
            .enumerate()
            .filter_map(|(i, &f)| match self.node(f) {
                Node::Func(func @ (Func::Sin | Func::Cos), u) => Some((i, *func, *u)),
                _ => None,
            })
            .collect();
        for &(i, fi, u) in &trig {
            for &(j, fj, v) in &trig {
                if i == j || u == v {
                    continue;
                }
                // cos u cos v (u < v) pairs with sin u sin v; sin u cos v with cos u sin v.
                let (partner_i, partner_j, sign, result) = match (fi, fj) {
                    (Func::Cos, Func::Cos) if u < v => {
                        (Func::Sin, Func::Sin, Constant::ONE, Func::Cos)
                    }
                    (Func::Sin, Func::Cos) => {
                        (Func::Cos, Func::Sin, Constant::MINUS_ONE, Func::Sin)
                    }
                    _ => continue,
                };
                let (Some(pi), Some(pj)) = (
                    self.lookup(NodeRef::Func(partner_i, u)),
                    self.lookup(NodeRef::Func(partner_j, v)),
                ) else {
                    continue;
                };
                let mut others: Vec<ExprId> = factors
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| *k != i && *k != j)
                    .map(|(_, f)| *f)
                    .collect();
                let mut partner_factors = others.clone();
                partner_factors.push(pi);
                partner_factors.push(pj);
                partner_factors.sort();
                let Some(partner) = self.lookup(NodeRef::Mul(&partner_factors)) else {
                    continue;
                };
                let Ok(expected) = c.checked_mul(sign) else {
                    continue;
                };
                if collected.get(&partner) == Some(&expected) {
                    others.sort();
                    return Some(AngleMatch {
                        rest,
                        partner,
                        others,
                        c,
                        result,
                        u,
                        v,
                    });
                }
            }
        }
        None
    }
}

/// Sets the coefficient of `rest` among collected sum terms to zero (the term is dropped when
/// the sum is built; a zero coefficient never matches a partner's).
fn zero_term(collected: &mut indexmap::IndexMap<ExprId, Constant>, rest: ExprId) {
    if let Some(c) = collected.get_mut(&rest) {
        *c = Constant::ZERO;
    }
}

/// Two sum terms `c·X·f(u)·g(v)` and their partner that combine into `c·X·result(u − v)`.
struct AngleMatch {
    rest: ExprId,
    partner: ExprId,
    others: Vec<ExprId>,
    c: Constant,
    result: Func,
    u: ExprId,
    v: ExprId,
}
