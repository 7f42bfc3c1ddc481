//! Forms of an expression for reading: the equations and kinematics a person compares with a
//! textbook, as `eomgen equations` and `eomgen kinematics` print them.
//!
//! The derivations keep expressions in the shape that shares most (a point's coordinates
//! nested rotation by rotation, a constraint's Jacobian as the derivative of its residual),
//! which prints as `r sin(lean) cos(yaw) − (y − (y − r sin(lean) cos(yaw)))`: exact, but not
//! what a textbook writes. [`ExprArena::readable`] multiplies such an expression out (where
//! that stays within the bounds of [`ExprArena::expand_bounded`]), so that like terms meet
//! and cancel and `sin² u + cos² u` becomes 1 as the canonical sum is built, then groups the
//! terms by their time-varying factors with the common factors pulled out
//! ([`ExprArena::collect_time_varying`]), and keeps whichever of the written and the
//! simplified forms prints shorter. The value is unchanged (the same rules the equality proof
//! of `eomgen check` uses); `tests` evaluate both at random states.
//!
//! # References
//! SymPy's `expand`, `trigsimp` and `collect` (Meurer et al., *PeerJ Comput. Sci.* 3:e103,
//! 2017) do the same steps on arbitrary expressions.

use rustc_hash::FxHashMap;

use super::print::{Printer, Syntax};
use super::{Constant, ExprArena, ExprId, Node};

/// Most operations (written out as a tree) of an expression that [`ExprArena::readable`]
/// multiplies out: past this the expansion's cost is not worth a form that would print
/// longer than the limit of a listing anyway.
const MOST_OPERATIONS: u64 = 4_000;

/// Most nodes the readable forms of one listing may add to the arena
/// ([`ExprArena::readable_within`]): past it, the rest is printed as derived. Chosen so that
/// the listing of a model whose entries are many and deep (a chain of six universal joints,
/// three nested frames in Euler parameters) stays within a second or so.
const READABLE_BUDGET: usize = 200_000;

impl ExprArena {
    /// [`Self::readable`] while the arena has grown by less than `READABLE_BUDGET` (200,000) nodes
    /// since it had `start` (its [`ExprArena::len`] when the listing began); `e` itself past
    /// that.
    pub fn readable_within(&mut self, e: ExprId, start: usize) -> ExprId {
        if self.len() > start + READABLE_BUDGET {
            return e;
        }
        self.readable(e)
    }

    /// The shorter to print of `e` and its multiplied-out, collected form (see the module
    /// documentation); `e` itself when it is larger than `MOST_OPERATIONS` (4,000 operations
    /// written out as a tree).
    pub fn readable(&mut self, e: ExprId) -> ExprId {
        if self.tree_operation_count(&[e]) > MOST_OPERATIONS {
            return e;
        }
        let flat = self.sums_rewritten(e, Self::flattened_sum);
        let expanded = self.expand_bounded(flat);
        let collected = self.collect_time_varying(expanded);
        let mut candidates = vec![flat, expanded, collected];
        for x in [flat, collected] {
            let over = self.sums_rewritten(x, Self::over_common_denominator);
            candidates.push(over);
        }
        for x in [expanded, collected] {
            let one = self.sums_rewritten(x, Self::pair_squares);
            let over = self.sums_rewritten(one, Self::over_common_denominator);
            candidates.extend([one, over]);
        }
        let length =
            |arena: &ExprArena, x: ExprId| Printer::for_display(arena, Syntax::Text).print(x).len();
        candidates.into_iter().fold(e, |best, x| {
            if length(self, x) < length(self, best) {
                x
            } else {
                best
            }
        })
    }

    /// `e` rebuilt bottom up (memoised) with each sum of (rebuilt) terms made by `rule`, and
    /// every other node by the canonical constructors: the walk the printing forms share.
    fn sums_rewritten(&mut self, e: ExprId, rule: fn(&mut Self, &[ExprId]) -> ExprId) -> ExprId {
        let mut memo: FxHashMap<ExprId, ExprId> = FxHashMap::default();
        for x in self.reachable(&[e]) {
            let node = self.node(x).clone();
            let children: Vec<ExprId> = node.children().iter().map(|c| memo[c]).collect();
            let out = match node {
                Node::Add(_) => rule(self, &children),
                Node::Mul(_) => self.product(&children),
                Node::Pow(_) => self.pow(children[0], children[1]),
                Node::Func(f, _) => self.func(f, children[0]),
                Node::Atan2(_) => self.atan2(children[0], children[1]),
                Node::Const(_) | Node::Pi | Node::Symbol(_) => x,
            };
            memo.insert(x, out);
        }
        memo.get(&e).copied().unwrap_or(e)
    }

    /// The sum of `terms` with every number times a sum, `c (a + b)`, multiplied into it
    /// (`x − (y + 2l/3)` → `x − y − 2l/3`).
    fn flattened_sum(&mut self, terms: &[ExprId]) -> ExprId {
        let mut out = Vec::with_capacity(terms.len());
        for &t in terms {
            let (c, rest) = self.split_coefficient(t);
            match rest.map(|r| self.node(r).clone()) {
                Some(Node::Add(inner)) => {
                    let k = self.constant(c);
                    for &x in inner.iter() {
                        out.push(self.times(k, x));
                    }
                }
                _ => out.push(t),
            }
        }
        self.sum(&out)
    }

    /// The sum of `terms`, written `(Σ d cᵢ tᵢ)/d` where their coefficients are fractions
    /// with a common denominator `d > 1` (`(5 sin θ₁ + 3 sin θ₂)/2`).
    fn over_common_denominator(&mut self, terms: &[ExprId]) -> ExprId {
        self.scaled_by_denominator(terms)
            .unwrap_or_else(|| self.sum(terms))
    }

    /// `(Σ d cᵢ tᵢ)/d` of [`Self::over_common_denominator`]; `None` where the terms have no
    /// common denominator above 1 (a float coefficient, or one past `i64`).
    fn scaled_by_denominator(&mut self, terms: &[ExprId]) -> Option<ExprId> {
        let split: Vec<(Constant, Option<ExprId>)> =
            terms.iter().map(|&t| self.split_coefficient(t)).collect();
        let d = split.iter().try_fold(1i64, |d, (c, _)| match c {
            Constant::Rational { den, .. } => lcm(d, *den),
            Constant::Float(_) => None,
        })?;
        if d <= 1 {
            return None;
        }
        let mut scaled = Vec::with_capacity(split.len());
        for (c, rest) in split {
            let Constant::Rational { num, den } = c else {
                return None;
            };
            let k = Constant::int(num.checked_mul(d / den)?);
            scaled.push(match rest {
                Some(r) => self.with_coefficient(k, r),
                None => self.constant(k),
            });
        }
        let sum = self.sum(&scaled);
        let inverse = self.constant(Constant::rational(1, d)?);
        // Interned as it stands: the number `1/d` times the sum, printed `(…)/d`.
        Some(self.add(Node::Mul([inverse, sum].into())))
    }
}

impl ExprArena {
    /// The sum of `terms` with every pair `a X sin²u + b X cos²u` (numbers `a ≠ b`, the same
    /// rest `X`) written `b X + (a − b) X sin²u` (`sin² + cos² = 1` with unlike coefficients:
    /// `m r² (6 sin² λ + cos² λ)/4 = m r² (1 + 5 sin² λ)/4`); the canonical sum already does
    /// `a = b`.
    fn pair_squares(&mut self, terms: &[ExprId]) -> ExprId {
        // Per term: its coefficient, and for a factor `sin(u)²` or `cos(u)²` the rest of it,
        // `u` and which.
        let two = self.int(2);
        let squares: Vec<Option<(Constant, ExprId, ExprId, bool)>> = (terms.iter())
            .map(|&t| {
                let (c, rest) = self.split_coefficient(t);
                let rest = rest?;
                let factors: Vec<ExprId> = match self.node(rest) {
                    Node::Mul(f) => f.to_vec(),
                    _ => vec![rest],
                };
                let (k, u, sine) = factors.iter().enumerate().find_map(|(k, &f)| {
                    let Node::Pow([base, exponent]) = self.node(f) else {
                        return None;
                    };
                    if *exponent != two {
                        return None;
                    }
                    match self.node(*base) {
                        Node::Func(super::Func::Sin, u) => Some((k, *u, true)),
                        Node::Func(super::Func::Cos, u) => Some((k, *u, false)),
                        _ => None,
                    }
                })?;
                let others: Vec<ExprId> = (factors.iter().enumerate())
                    .filter(|&(j, _)| j != k)
                    .map(|(_, &f)| f)
                    .collect();
                let x = self.product(&others);
                Some((c, x, u, sine))
            })
            .collect();
        let mut out: Vec<ExprId> = Vec::with_capacity(terms.len());
        let mut used = vec![false; terms.len()];
        for i in 0..terms.len() {
            if used[i] {
                continue;
            }
            let Some((a, x, u, true)) = squares[i] else {
                continue;
            };
            let partner = (0..terms.len()).find(|&j| {
                !used[j] && matches!(squares[j], Some((_, y, v, false)) if y == x && v == u)
            });
            if let Some(j) = partner
                && let Some((b, ..)) = squares[j]
                && let Ok(difference) = a.checked_add(b.negated())
            {
                used[i] = true;
                used[j] = true;
                let sin = self.sin(u);
                let sin2 = self.pow(sin, two);
                let rest = self.times(x, sin2);
                let (b, difference) = (self.constant(b), self.constant(difference));
                let first = self.times(b, x);
                let second = self.times(difference, rest);
                out.extend([first, second]);
            }
        }
        out.extend((0..terms.len()).filter(|&i| !used[i]).map(|i| terms[i]));
        self.sum(&out)
    }
}

/// The least common multiple of two positive integers; `None` past `i64`.
fn lcm(a: i64, b: i64) -> Option<i64> {
    let (mut x, mut y) = (a, b);
    while y != 0 {
        (x, y) = (y, x % y);
    }
    (a / x).checked_mul(b)
}
