//! Distributive expansion, used where exact cancellation matters (the Lagrange forcing).
//!
//! `x·(a + b)` → `x·a + x·b` and `(a + b)^n` (n = 2, 3) multiplied out, recursively through
//! sums and products but not into function arguments, so that terms which cancel exactly
//! (∂T/∂q against the (∂²T/∂q̇∂q) q̇ term of Lagrange's equations) meet as like terms in one
//! canonical sum and vanish. Expansion can also swell an expression, so it is capped, and
//! [`ExprArena::expand_if_cheaper`] keeps whichever form costs fewer operations.

use super::{ExprArena, ExprId, Node};

/// Most terms an expansion may produce before the product is left unexpanded.
const MAX_TERMS: usize = 512;

impl ExprArena {
    /// The terms of `e` as a sum (itself if it is not a sum).
    fn terms_of(&self, e: ExprId) -> Vec<ExprId> {
        match self.node(e) {
            Node::Add(t) => t.to_vec(),
            _ => vec![e],
        }
    }

    /// `e` with products of sums and small powers of sums multiplied out (memoised).
    pub fn expand(&mut self, e: ExprId) -> ExprId {
        if let Some(&x) = self.expand_memo.get(&e) {
            return x;
        }
        let result = match self.node(e).clone() {
            Node::Add(terms) => {
                let t: Vec<ExprId> = terms.iter().map(|&t| self.expand(t)).collect();
                self.sum(&t)
            }
            Node::Mul(factors) => {
                let expanded: Vec<ExprId> = factors.iter().map(|&f| self.expand(f)).collect();
                self.multiply_out(&expanded)
            }
            Node::Pow([b, n]) => match self.as_constant(n).and_then(|c| c.as_integer()) {
                Some(k @ 2..=3) => {
                    let base = self.expand(b);
                    if matches!(self.node(base), Node::Add(_)) {
                        self.multiply_out(&vec![base; k as usize])
                    } else {
                        self.pow(base, n)
                    }
                }
                _ => e,
            },
            _ => e,
        };
        self.expand_memo.insert(e, result);
        result
    }

    /// Π factors with every sum factor distributed, unless that makes more than
    /// [`MAX_TERMS`] terms.
    fn multiply_out(&mut self, factors: &[ExprId]) -> ExprId {
        let mut count = 1usize;
        for &f in factors {
            count = count.saturating_mul(self.terms_of(f).len());
        }
        if count > MAX_TERMS {
            return self.product(factors);
        }
        let mut partial: Vec<Vec<ExprId>> = vec![Vec::new()];
        for &f in factors {
            let terms = self.terms_of(f);
            let mut next = Vec::with_capacity(partial.len() * terms.len());
            for p in &partial {
                for &t in &terms {
                    let mut q = p.clone();
                    q.push(t);
                    next.push(q);
                }
            }
            partial = next;
        }
        let monomials: Vec<ExprId> = partial.iter().map(|p| self.product(p)).collect();
        self.sum(&monomials)
    }

    /// The expansion of `e` if it evaluates with fewer operations (as a tree), else `e`.
    pub fn expand_if_cheaper(&mut self, e: ExprId) -> ExprId {
        let x = self.expand(e);
        if self.tree_operation_count(&[x]) < self.tree_operation_count(&[e]) {
            x
        } else {
            e
        }
    }
}

impl ExprArena {
    /// `e` with every symbol in `values` replaced by its expression, rebuilt canonically.
    pub fn substitute(
        &mut self,
        e: ExprId,
        values: &rustc_hash::FxHashMap<super::SymbolId, ExprId>,
    ) -> ExprId {
        let mut memo: rustc_hash::FxHashMap<ExprId, ExprId> = Default::default();
        self.substitute_memo(e, values, &mut memo)
    }

    fn substitute_memo(
        &mut self,
        e: ExprId,
        values: &rustc_hash::FxHashMap<super::SymbolId, ExprId>,
        memo: &mut rustc_hash::FxHashMap<ExprId, ExprId>,
    ) -> ExprId {
        if let Some(&x) = memo.get(&e) {
            return x;
        }
        let result = match self.node(e).clone() {
            Node::Const(_) | Node::Pi => e,
            Node::Symbol(s) => values.get(&s).copied().unwrap_or(e),
            Node::Add(t) => {
                let t: Vec<ExprId> = t
                    .iter()
                    .map(|&x| self.substitute_memo(x, values, memo))
                    .collect();
                self.sum(&t)
            }
            Node::Mul(f) => {
                let f: Vec<ExprId> = f
                    .iter()
                    .map(|&x| self.substitute_memo(x, values, memo))
                    .collect();
                self.product(&f)
            }
            Node::Pow([b, x]) => {
                let b = self.substitute_memo(b, values, memo);
                let x = self.substitute_memo(x, values, memo);
                self.pow(b, x)
            }
            Node::Func(f, u) => {
                let u = self.substitute_memo(u, values, memo);
                self.func(f, u)
            }
            Node::Atan2([y, x]) => {
                let y = self.substitute_memo(y, values, memo);
                let x = self.substitute_memo(x, values, memo);
                self.atan2(y, x)
            }
        };
        memo.insert(e, result);
        result
    }
}
