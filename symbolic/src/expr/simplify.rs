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
        let flat = self.flattened(e, &mut FxHashMap::default());
        let expanded = self.expand_bounded(flat);
        let collected = self.collect_time_varying(expanded);
        let mut candidates = vec![flat, expanded, collected];
        for x in [flat, collected] {
            let over = self.over_common_denominator(x, &mut FxHashMap::default());
            candidates.push(over);
        }
        for x in [expanded, collected] {
            let one = self.cosines_squared_out(x, &mut FxHashMap::default());
            let over = self.over_common_denominator(one, &mut FxHashMap::default());
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

    /// `e` with every number times a sum, `c (a + b)`, multiplied into the sum it stands in
    /// (`x − (y + 2l/3)` → `x − y − 2l/3`), through the whole expression (memoised in `memo`).
    fn flattened(&mut self, e: ExprId, memo: &mut FxHashMap<ExprId, ExprId>) -> ExprId {
        if let Some(&done) = memo.get(&e) {
            return done;
        }
        let node = self.node(e).clone();
        let children: Vec<ExprId> = (node.children().iter())
            .map(|&c| self.flattened(c, memo))
            .collect();
        let out = match node {
            Node::Add(_) => {
                let mut terms = Vec::with_capacity(children.len());
                for t in children {
                    let (c, rest) = self.split_coefficient(t);
                    match rest.map(|r| self.node(r).clone()) {
                        Some(Node::Add(inner)) => {
                            let k = self.constant(c);
                            for &x in inner.iter() {
                                terms.push(self.times(k, x));
                            }
                        }
                        _ => terms.push(t),
                    }
                }
                self.sum(&terms)
            }
            Node::Mul(_) => self.product(&children),
            Node::Pow(_) => self.pow(children[0], children[1]),
            Node::Func(f, _) => self.func(f, children[0]),
            Node::Atan2(_) => self.add(Node::Atan2([children[0], children[1]])),
            _ => e,
        };
        memo.insert(e, out);
        out
    }

    /// `e` with every sum whose terms' coefficients are fractions with a common denominator
    /// `d > 1` written `(Σ d cᵢ tᵢ)/d` (`(5 sin θ₁ + 3 sin θ₂)/2`), through the whole
    /// expression (memoised in `memo`).
    fn over_common_denominator(
        &mut self,
        e: ExprId,
        memo: &mut FxHashMap<ExprId, ExprId>,
    ) -> ExprId {
        if let Some(&done) = memo.get(&e) {
            return done;
        }
        let node = self.node(e).clone();
        let children: Vec<ExprId> = (node.children().iter())
            .map(|&c| self.over_common_denominator(c, memo))
            .collect();
        let out = match node {
            Node::Add(_) => {
                let split: Vec<(Constant, Option<ExprId>)> = children
                    .iter()
                    .map(|&t| self.split_coefficient(t))
                    .collect();
                let denominator = split.iter().try_fold(1i64, |d, (c, _)| match c {
                    Constant::Rational { den, .. } => Some(lcm(d, *den)?),
                    Constant::Float(_) => None,
                });
                match denominator {
                    Some(d) if d > 1 => {
                        let scaled: Option<Vec<ExprId>> = (split.iter())
                            .map(|&(c, rest)| {
                                let Constant::Rational { num, den } = c else {
                                    return None;
                                };
                                let k = Constant::int(num.checked_mul(d / den)?);
                                Some(match rest {
                                    Some(r) => self.with_coefficient(k, r),
                                    None => self.constant(k),
                                })
                            })
                            .collect();
                        match scaled {
                            Some(terms) => {
                                let sum = self.sum(&terms);
                                let inverse = Constant::rational(1, d).map(|c| self.constant(c));
                                match inverse {
                                    Some(k) => self.add(Node::Mul([k, sum].into())),
                                    None => self.sum(&children),
                                }
                            }
                            None => self.sum(&children),
                        }
                    }
                    _ => self.sum(&children),
                }
            }
            Node::Mul(_) => self.product(&children),
            Node::Pow(_) => self.pow(children[0], children[1]),
            Node::Func(f, _) => self.func(f, children[0]),
            Node::Atan2(_) => self.add(Node::Atan2([children[0], children[1]])),
            _ => e,
        };
        memo.insert(e, out);
        out
    }
}

impl ExprArena {
    /// `e` with every pair of terms `a X sin²u + b X cos²u` of a sum (numbers `a ≠ b`, the
    /// same rest `X`) written `b X + (a − b) X sin²u` (`sin² + cos² = 1` with unlike
    /// coefficients: `m r² (6 sin² λ + cos² λ)/4 = m r² (1 + 5 sin² λ)/4`), through the whole
    /// expression (memoised in `memo`). The canonical sum already does `a = b`.
    fn cosines_squared_out(&mut self, e: ExprId, memo: &mut FxHashMap<ExprId, ExprId>) -> ExprId {
        if let Some(&done) = memo.get(&e) {
            return done;
        }
        let node = self.node(e).clone();
        let children: Vec<ExprId> = (node.children().iter())
            .map(|&c| self.cosines_squared_out(c, memo))
            .collect();
        let out = match node {
            Node::Add(_) => self.pair_squares(&children),
            Node::Mul(_) => self.product(&children),
            Node::Pow(_) => self.pow(children[0], children[1]),
            Node::Func(f, _) => self.func(f, children[0]),
            Node::Atan2(_) => self.add(Node::Atan2([children[0], children[1]])),
            _ => e,
        };
        memo.insert(e, out);
        out
    }

    /// The sum of `terms` with the pairs of [`Self::cosines_squared_out`] rewritten.
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
