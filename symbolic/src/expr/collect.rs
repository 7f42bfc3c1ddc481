//! Collection of a multiplied-out sum by its time-varying factors, with common factors pulled
//! out: the compact form of the equations of motion of chains.
//!
//! Multiplied out, an entry of `M` or `F` of an `n`-link chain is a sum over the bodies below
//! a joint of monomials such as `m₅ l₂ l₃ cos(θ₂ − θ₃)`, one per body, all with the same
//! time-varying part. Grouping the terms by that part and factoring the constant-in-time
//! coefficient turns
//!
//! ```text
//! ½ m₃ l₂ l₃ cos(θ₂ − θ₃) + m₄ l₂ l₃ cos(θ₂ − θ₃) + m₅ l₂ l₃ cos(θ₂ − θ₃)
//!   → l₂ l₃ (½ m₃ + m₄ + m₅) cos(θ₂ − θ₃)
//! ```
//!
//! and the same sum of masses `½ m₃ + m₄ + m₅` appears in every entry that couples bar 3 to
//! the bars above it (in `M` and in the velocity and gravity terms of `F`), so common-
//! subexpression elimination computes it once. This is the hand derivation's "mass below the
//! joint" (Kane and Levinson's generalized inertia forces of a chain), found from the
//! expressions rather than from the structure of the model.
//!
//! # References
//! T. R. Kane, D. A. Levinson, *Dynamics: Theory and Applications*, McGraw-Hill, 1985, §6.1
//! (generalized inertia forces); SymPy's `collect` and `factor_terms` do the same two steps
//! on arbitrary expressions.

use rustc_hash::FxHashMap;

use super::{Constant, ExprArena, ExprId, Node, NodeRef};

impl ExprArena {
    /// `e` (a multiplied-out sum) with its terms grouped by their time-varying factors, the
    /// factors common to the constant-in-time coefficients of each group pulled out of their
    /// sum, and then the factors common to every group pulled out of the whole sum. A sign is
    /// pulled out too when most terms (or, on a tie, the first in canonical order) are
    /// negative, so that a sum of masses and its negation share one node.
    ///
    /// A factor is time-varying if it contains a coordinate, a rate, an acceleration or
    /// `t`. The result has the same value; it is not canonical (two equal sums collect to the
    /// same node only if their multiplied-out forms are one node).
    pub fn collect_time_varying(&mut self, e: ExprId) -> ExprId {
        let Node::Add(terms) = self.node(e) else {
            // One term: only its number may move into a sum of masses.
            let (coefficient, varying) = self.split_time_varying(e);
            let absorbed = self.absorb_number(coefficient);
            return if absorbed == coefficient {
                e
            } else {
                self.times(absorbed, varying)
            };
        };
        let terms = terms.to_vec();
        let mut groups: Vec<(ExprId, Vec<ExprId>)> = Vec::new();
        let mut index: FxHashMap<ExprId, usize> = FxHashMap::default();
        for t in terms {
            let (coefficient, varying) = self.split_time_varying(t);
            let k = *index.entry(varying).or_insert_with(|| {
                groups.push((varying, Vec::new()));
                groups.len() - 1
            });
            groups[k].1.push(coefficient);
        }
        if groups.len() == 1 && groups[0].1.len() == 1 {
            let coefficient = groups[0].1[0];
            let absorbed = self.absorb_number(coefficient);
            return if absorbed == coefficient {
                e
            } else {
                self.times(absorbed, groups[0].0)
            };
        }
        groups.sort_by_key(|(varying, _)| *varying);
        let collected: Vec<ExprId> = groups
            .into_iter()
            .map(|(varying, coefficients)| {
                let c = self.factor_terms(&coefficients);
                let c = self.absorb_number(c);
                self.times(c, varying)
            })
            .collect();
        self.factor_terms(&collected)
    }

    /// `Σ terms` with the factors common to every term pulled out, `g · Σ (terms / g)`, and
    /// a sign pulled out when most terms (or, on a tie, the first in canonical order) are
    /// negative, so that a sum and its negation share one inner node.
    ///
    /// Common factors are bases with positive integer exponents (`l₂`, `l₂²`); a number is
    /// pulled out only when every term has it, up to sign (`½ m₁ + ½ m₂ → ½ (m₁ + m₂)`, one
    /// multiplication instead of two; `½ m₁ + m₂` keeps its coefficients).
    fn factor_terms(&mut self, terms: &[ExprId]) -> ExprId {
        if terms.len() < 2 {
            return self.sum(terms);
        }
        let split: Vec<(Constant, Vec<(ExprId, i64)>)> =
            terms.iter().map(|&t| self.power_factors(t)).collect();
        // Common bases with the smallest exponent among the terms (every term has them).
        let mut common: Vec<(ExprId, i64)> =
            split[0].1.iter().filter(|(_, k)| *k > 0).copied().collect();
        for (_, factors) in &split[1..] {
            common.retain_mut(|(base, k)| match factors.iter().find(|(b, _)| b == base) {
                Some((_, other)) if *other > 0 => {
                    *k = (*k).min(*other);
                    true
                }
                _ => false,
            });
            if common.is_empty() {
                break;
            }
        }
        let negative = split.iter().filter(|(c, _)| c.is_negative()).count();
        let positive = split.len() - negative;
        let flip = negative > positive || (negative == positive && self.leads_negative(terms));
        let magnitude = if split[0].0.is_negative() {
            split[0].0.negated()
        } else {
            split[0].0
        };
        let shared_magnitude = !magnitude.is_one()
            && split
                .iter()
                .all(|(c, _)| *c == magnitude || c.negated() == magnitude);
        if common.is_empty() && !flip && !shared_magnitude {
            return self.sum(terms);
        }
        let unit = |negative: bool| {
            if negative {
                Constant::MINUS_ONE
            } else {
                Constant::ONE
            }
        };
        let sign = unit(flip);
        // The number pulled out, and each term's coefficient divided by it (exactly, as the
        // magnitudes are equal).
        let scale = if shared_magnitude {
            if flip { magnitude.negated() } else { magnitude }
        } else {
            sign
        };
        let reduced: Vec<ExprId> = split
            .into_iter()
            .map(|(c, factors)| {
                let mut parts = Vec::with_capacity(factors.len() + 1);
                let coefficient = if shared_magnitude {
                    unit(c.is_negative() != flip)
                } else {
                    c.checked_mul(sign).unwrap_or(c)
                };
                parts.push(self.constant(coefficient));
                for (base, k) in factors {
                    let left = k - common
                        .iter()
                        .find(|(b, _)| *b == base)
                        .map_or(0, |(_, m)| *m);
                    if left != 0 {
                        let exponent = self.int(left);
                        parts.push(self.pow(base, exponent));
                    }
                }
                self.product(&parts)
            })
            .collect();
        let mut parts: Vec<ExprId> = Vec::with_capacity(common.len() + 2);
        parts.push(self.constant(scale));
        for (base, k) in common {
            let exponent = self.int(k);
            parts.push(self.pow(base, exponent));
        }
        parts.push(self.sum(&reduced));
        self.product(&parts)
    }

    /// A constant-in-time coefficient `c · X · (Σ cₖ yₖ)` with a number `c ≠ ±1` and one sum
    /// among its factors, as `X · (Σ c cₖ yₖ)` when that leaves no more non-unit numbers in
    /// the sum than it had (one multiplication fewer): the mass matrix of a chain, derived
    /// from a collected `T`, has `2 l₁² (m₁/6 + m₂/2)`, which is `l₁² (m₁/3 + m₂)`, the form
    /// that momentum balance and the rest of the chain's entries share. A sign alone stays
    /// outside, so that a sum and its negation share one node (see [`Self::factor_terms`]).
    fn absorb_number(&mut self, coefficient: ExprId) -> ExprId {
        let Node::Mul(factors) = self.node(coefficient) else {
            return coefficient;
        };
        let Some(c) = self.as_constant(factors[0]) else {
            return coefficient;
        };
        if c.is_one() || c.negated().is_one() {
            return coefficient;
        }
        let mut sums = factors[1..]
            .iter()
            .enumerate()
            .filter(|(_, f)| matches!(self.node(**f), Node::Add(_)));
        let (Some((k, &sum)), None) = (sums.next(), sums.next()) else {
            return coefficient;
        };
        let others: Vec<ExprId> = factors[1..]
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != k)
            .map(|(_, f)| *f)
            .collect();
        let Node::Add(terms) = self.node(sum) else {
            return coefficient;
        };
        let terms = terms.to_vec();
        let is_unit = |x: Constant| x.is_one() || x.negated().is_one();
        let mut before = 0;
        let mut after = 0;
        let mut scaled = Vec::with_capacity(terms.len());
        for t in terms {
            let (ct, rest) = self.split_coefficient(t);
            let Ok(product) = ct.checked_mul(c) else {
                return coefficient;
            };
            before += usize::from(!is_unit(ct));
            after += usize::from(!is_unit(product));
            scaled.push(match rest {
                Some(r) => self.with_coefficient(product, r),
                None => self.constant(product),
            });
        }
        if after > before {
            return coefficient;
        }
        let mut parts = others;
        parts.push(self.sum(&scaled));
        self.product(&parts)
    }

    /// Whether the first of `terms` in canonical (id) order has a negative coefficient.
    fn leads_negative(&self, terms: &[ExprId]) -> bool {
        let first = terms.iter().min().copied();
        first.is_some_and(|t| match self.node(t) {
            Node::Const(c) => c.is_negative(),
            Node::Mul(f) => self.as_constant(f[0]).is_some_and(Constant::is_negative),
            _ => false,
        })
    }

    /// A term as `coefficient · Π baseᵏ`, with integer `k` (a factor with another exponent is
    /// its own base, with `k = 1`).
    fn power_factors(&self, term: ExprId) -> (Constant, Vec<(ExprId, i64)>) {
        let factors: &[ExprId] = match self.node(term) {
            Node::Mul(f) => f,
            _ => std::slice::from_ref(&term),
        };
        let mut coefficient = Constant::ONE;
        let mut out = Vec::with_capacity(factors.len());
        for &f in factors {
            match self.node(f) {
                Node::Const(c) => coefficient = *c,
                Node::Pow([b, x]) => match self.as_constant(*x).and_then(Constant::as_integer) {
                    Some(k) => out.push((*b, k)),
                    None => out.push((f, 1)),
                },
                _ => out.push((f, 1)),
            }
        }
        (coefficient, out)
    }

    /// A term as `(constant-in-time part, time-varying part)`, their product being the
    /// term; either part may be the number 1.
    fn split_time_varying(&mut self, term: ExprId) -> (ExprId, ExprId) {
        let factors: &[ExprId] = match self.node(term) {
            Node::Mul(f) => f,
            _ => std::slice::from_ref(&term),
        };
        let (varying, constant): (Vec<ExprId>, Vec<ExprId>) = factors
            .iter()
            .partition(|&&f| self.contains_time_varying(f));
        // Parts of a canonical product (sorted, distinct bases, coefficient first) are
        // canonical products themselves.
        (
            self.product_of_part(&constant),
            self.product_of_part(&varying),
        )
    }

    /// The product of some of the factors of a canonical product, in their order.
    fn product_of_part(&mut self, factors: &[ExprId]) -> ExprId {
        match factors {
            [] => self.int(1),
            [f] => *f,
            _ => self.add_ref(NodeRef::Mul(factors)),
        }
    }
}
