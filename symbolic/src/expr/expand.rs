//! Distributive expansion, used where exact cancellation matters (the Lagrange forcing) and
//! where products of sines and cosines must meet (momentum balance).
//!
//! `x·(a + b)` → `x·a + x·b` and `(a + b)^n` (n = 2, 3) multiplied out, recursively through
//! sums and products but not into function arguments, so that terms which cancel exactly
//! (∂T/∂q against the (∂²T/∂q̇∂q) q̇ term of Lagrange's equations) meet as like terms in one
//! canonical sum and vanish. Expansion can also swell an expression, so it is capped, and
//! [`ExprArena::expand_if_cheaper`] keeps whichever form costs fewer operations;
//! [`ExprArena::expand_time_varying`] leaves constant-in-time sums alone.
//!
//! Two caps guard against growth:
//! - a product of three or more sums stays a product past [`MAX_TERMS`] terms, unless the
//!   count is quadratic in its input (a square such as `v·v`, up to [`MAX_QUADRATIC_TERMS`]);
//! - a sum or product whose expansion would have more than [`DEEP_TERMS`] terms (4,096 in
//!   [`ExprArena::expand_bounded`], none in [`ExprArena::expand`]) from sums
//!   nested more than [`DEEP_NESTING`] levels deep in products stays as it is. The terms of
//!   such an expansion grow by a constant factor with each level (at most 2), although the
//!   expression (a DAG, each level sharing the one below) grows by a constant: the components
//!   of a point of a chain of 3-D bodies in relative rotations, each rotation
//!   `cos a vⱼ − sin a vₖ` with `vⱼ` and `vₖ` the previous rotation's sums, have terms
//!   exponential in the rotations multiplied out (up to `2` per rotation; 1.6 for rotations
//!   about x and y in turn). Kept nested, the chain's equations grow as a power of the joints
//!   (docs/performance.md, "Derivations of 3-D chains").
//!
//! Both caps are decided from the expression's estimated shape before anything is built
//! ([`ExprArena::expansion_shape`], memoised per node). The estimate counts a square's
//! terms as `t²` and like terms as distinct, so it can be above the real count; `expand`
//! decides [`MAX_TERMS`] again from the real one. `expand` of an expansion that kept parts
//! may multiply out more of them (it is not idempotent). [`ExprArena::expand`], for where
//! every term must be seen (the lowering's zero tests, the reduction's coefficients), has no
//! depth cap; the symbolic equality proof uses [`ExprArena::expand_bounded`], and a kept part
//! only makes it fail, never succeed wrongly.

use super::{ExprArena, ExprId, Node};

/// Most terms an expansion of a product of three or more sums may produce before the product
/// is left unexpanded (unless the count is within [`MAX_QUADRATIC_TERMS`] and the square of
/// the input's terms): the guard against exponential growth.
const MAX_TERMS: usize = 512;

/// Most terms an expansion may produce at all. A product of two sums (a square, as every
/// `v·v` of a kinetic energy) is expanded up to this many: its result grows only with the
/// square of its input, and a 40-link chain's `|v|²` alone has 1600 terms.
const MAX_QUADRATIC_TERMS: usize = 1 << 16;

/// Most terms an expansion may produce from sums nested more than [`DEEP_NESTING`] levels
/// deep in products. Chosen on the universal-joint chains of `eomgen new
/// universal-joint-chain` (N = 2…8, `check` time and operations after CSE of both
/// derivations, best at 16–64) while leaving every bundled model's equations as they were
/// except the Whipple bicycle's, whose equations became cheaper (Lagrange's 8,061 → 3,875
/// operations after CSE, momentum balance's 8,815 → 5,623).
const DEEP_TERMS: usize = 64;

/// [`DEEP_TERMS`] for the full expansion of the symbolic equality proof and of
/// [`ExprArena::expand_if_cheaper`] ([`ExprArena::expand_bounded`]): a bound on their work
/// (uncapped, `check` of 8 universal joints took 14 s, nearly all in them; every bundled
/// model's proof stays within it). [`ExprArena::expand`], which the zero tests of the
/// lowering and the reduction use, has no such bound.
const BOUNDED_DEEP_TERMS: usize = 4096;

/// How deeply sums may nest in products before [`DEEP_TERMS`] applies. A level is a product
/// of a sum with another sum or a time-varying factor (a rate, a sine), or with constants
/// when the sum's terms multiply more than two sines and cosines (or it holds a kept part,
/// which counts as a rotation's): each simple rotation `cos a vⱼ − sin a vₖ` of a sum is a
/// level, and so is a mass times a 3-D body's nested velocities. A planar chain's kinetic energy `Σ ½ m v·v` nests at most two levels (`v·v`,
/// and the rates times sums in `v` with relative angles) and is multiplied out whatever its
/// size, which its Lagrange derivation needs to cancel terms and sum the masses of a chain
/// (counting `½ m` as a level cost a 5-link chain in relative angles 1.9× the operations,
/// and 1 level the 40-link pendulum 11×).
const DEEP_NESTING: usize = 2;

/// Which sums [`ExprArena::expand`] multiplies out, and within which bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum Expansion {
    /// Every sum, with no bound but [`MAX_TERMS`].
    Full,
    /// Every sum, within [`BOUNDED_DEEP_TERMS`].
    Bounded,
    /// Only sums that change in time, within [`DEEP_TERMS`]; a constant-in-time sum such as
    /// `R − r` stays a factor.
    TimeVarying,
}

impl Expansion {
    /// The most terms of an expansion of sums nested past [`DEEP_NESTING`].
    fn deep_terms(self) -> usize {
        match self {
            Self::Full => usize::MAX,
            Self::Bounded => BOUNDED_DEEP_TERMS,
            Self::TimeVarying => DEEP_TERMS,
        }
    }
}

/// What the expansion of an expression would produce, known before it is built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Shape {
    /// Terms of the expansion (an upper bound: like terms may merge), saturating.
    terms: usize,
    /// How many levels of sums nest in products on the way to its deepest term (see
    /// [`DEEP_NESTING`]).
    nesting: usize,
    /// Whether the expansion is not done (the expression is kept as it is), by the caps.
    kept: bool,
    /// Whether it changes in time (a constant-in-time factor, such as a mass, does not make a
    /// product a level of nesting).
    varying: bool,
    /// The most time-varying functions (sines, cosines, …) multiplied in one term.
    degree: usize,
}

impl Shape {
    /// A symbol or function: one term, no nesting.
    const ATOM: Self = Self {
        terms: 1,
        nesting: 0,
        kept: false,
        varying: true,
        degree: 0,
    };

    /// A factor constant in time (in [`Expansion::TimeVarying`], which leaves it alone).
    const CONSTANT: Self = Self {
        varying: false,
        ..Self::ATOM
    };

    /// The shape of a product of factors of these shapes, by [`ExprArena::multiply_out`]'s
    /// rule. A product left unexpanded by [`MAX_TERMS`] is one term at the nesting its
    /// expansion would have had.
    fn product(factors: &[Self]) -> Self {
        let (mut terms, mut inputs, mut nesting, mut sums) = (1usize, 0usize, 0, 0);
        let mut other_varying = false;
        let mut degree = 0usize;
        for f in factors {
            degree = degree.saturating_add(f.degree);
            nesting = nesting.max(f.nesting);
            if f.terms > 1 {
                sums += 1;
                terms = terms.saturating_mul(f.terms);
                inputs = inputs.saturating_add(f.terms);
            } else if f.varying {
                other_varying = true;
            }
        }
        let sum_degree = factors
            .iter()
            .filter(|f| f.terms > 1)
            .map(|f| f.degree)
            .max()
            .unwrap_or(0);
        // A sum times constants is a level only when the sum multiplies more than two
        // functions in a term (a rotation's, not a planar chain's `cos θᵢ cos θⱼ`).
        let level = sums > 1 || (sums == 1 && (other_varying || sum_degree > 2));
        let nesting = nesting + usize::from(level);
        let varying = factors.iter().any(|f| f.varying);
        let quadratic = terms <= MAX_QUADRATIC_TERMS && terms <= inputs.saturating_mul(inputs);
        if terms > MAX_TERMS && !quadratic {
            return Self {
                nesting,
                varying,
                degree,
                ..Self::ATOM
            };
        }
        Self {
            terms,
            nesting,
            kept: false,
            varying,
            degree,
        }
    }
}

impl ExprArena {
    /// `e` with products of sums and small powers of sums multiplied out (memoised), with no
    /// bound on how deeply sums nest (products stay capped at 512 terms, 65,536 for one that
    /// is quadratic in its input): for where every term must be seen, the tests that a
    /// difference is exactly zero, the coefficients and radicands of the reduction.
    pub fn expand(&mut self, e: ExprId) -> ExprId {
        self.expand_as(e, Expansion::Full)
    }

    /// [`Self::expand`] within a bound on its work: a sum or product whose expansion would
    /// have more than 4,096 terms from sums nested more than two levels deep is kept as it
    /// is. For the symbolic equality proof of `check`, which then fails (and the numeric
    /// comparison decides), and [`Self::expand_if_cheaper`].
    pub fn expand_bounded(&mut self, e: ExprId) -> ExprId {
        self.expand_as(e, Expansion::Bounded)
    }

    /// `e` with products of time-varying sums multiplied out, constant-in-time sums kept as
    /// factors (memoised): enough to bring products of sines and cosines together (and the
    /// angle-difference and Pythagorean identities to apply) without multiplying out
    /// parameter expressions like `(R − r)²`, which are computed once anyway.
    pub fn expand_time_varying(&mut self, e: ExprId) -> ExprId {
        self.expand_as(e, Expansion::TimeVarying)
    }

    fn expand_as(&mut self, e: ExprId, mode: Expansion) -> ExprId {
        if mode == Expansion::TimeVarying && !self.contains_time_varying(e) {
            return e;
        }
        let memo = match mode {
            Expansion::Full => &self.expand_memo,
            Expansion::Bounded => &self.expand_bounded_memo,
            Expansion::TimeVarying => &self.expand_time_varying_memo,
        };
        if let Some(&x) = memo.get(&e) {
            return x;
        }
        // The full expansion keeps nothing by depth: no shape to estimate.
        let kept = mode != Expansion::Full && self.expansion_shape(e, mode).kept;
        let result = match self.node(e) {
            _ if kept => e,
            Node::Add(terms) => {
                let terms = terms.to_vec();
                let t: Vec<ExprId> = terms.iter().map(|&t| self.expand_as(t, mode)).collect();
                self.sum(&t)
            }
            Node::Mul(factors) => {
                let factors = factors.to_vec();
                let expanded: Vec<ExprId> =
                    factors.iter().map(|&f| self.expand_as(f, mode)).collect();
                self.multiply_out(&expanded, mode)
            }
            &Node::Pow([b, n]) => match self.as_constant(n).and_then(|c| c.as_integer()) {
                Some(k @ 2..=3) => {
                    let base = self.expand_as(b, mode);
                    if self.is_distributed(base, mode) {
                        self.multiply_out(&vec![base; k as usize], mode)
                    } else {
                        self.pow(base, n)
                    }
                }
                _ => e,
            },
            _ => e,
        };
        match mode {
            Expansion::Full => self.expand_memo.insert(e, result),
            Expansion::Bounded => self.expand_bounded_memo.insert(e, result),
            Expansion::TimeVarying => self.expand_time_varying_memo.insert(e, result),
        };
        result
    }

    /// The [`Shape`] of `e`'s expansion in `mode`, from the shapes of its operands (memoised;
    /// linear in the size of the DAG). An expansion past the mode's term bound
    /// ([`DEEP_TERMS`], [`BOUNDED_DEEP_TERMS`]) and [`DEEP_NESTING`] is kept, and then counts
    /// as its own terms (a sum's) or one.
    fn expansion_shape(&mut self, e: ExprId, mode: Expansion) -> Shape {
        if mode == Expansion::TimeVarying && !self.contains_time_varying(e) {
            return Shape::CONSTANT;
        }
        if let Some(&shape) = self.expansion_shapes.get(&(e, mode)) {
            return shape;
        }
        let shape = match self.node(e) {
            Node::Add(terms) => {
                let terms = terms.to_vec();
                terms.iter().fold(
                    Shape {
                        terms: 0,
                        ..Shape::CONSTANT
                    },
                    |sum, &t| {
                        let s = self.expansion_shape(t, mode);
                        Shape {
                            terms: sum.terms.saturating_add(s.terms),
                            nesting: sum.nesting.max(s.nesting),
                            kept: false,
                            varying: sum.varying || s.varying,
                            degree: sum.degree.max(s.degree),
                        }
                    },
                )
            }
            Node::Mul(factors) => {
                let factors = factors.to_vec();
                let shapes: Vec<Shape> = factors
                    .iter()
                    .map(|&f| self.expansion_shape(f, mode))
                    .collect();
                Shape::product(&shapes)
            }
            &Node::Pow([b, n]) => match self.as_constant(n).and_then(|c| c.as_integer()) {
                Some(k @ 2..=3) => {
                    let base = self.expansion_shape(b, mode);
                    Shape::product(&vec![base; k as usize])
                }
                _ => self.atom_shape(e),
            },
            _ => self.atom_shape(e),
        };
        let shape = if shape.terms > mode.deep_terms() && shape.nesting > DEEP_NESTING {
            let terms = match self.node(e) {
                Node::Add(t) => t.len(),
                _ => 1,
            };
            // What contains it counts its nesting afresh from here, and takes it for a
            // rotation's sum (more than two sines and cosines a term), never a planar one.
            Shape {
                terms,
                nesting: 0,
                kept: true,
                varying: shape.varying,
                degree: DEEP_NESTING + 1,
            }
        } else {
            shape
        };
        self.expansion_shapes.insert((e, mode), shape);
        shape
    }

    /// The shape of a node the expansion does not enter (a symbol, constant or function).
    fn atom_shape(&self, e: ExprId) -> Shape {
        if !self.contains_time_varying(e) {
            Shape::CONSTANT
        } else if matches!(self.node(e), Node::Func(..) | Node::Atan2(..)) {
            Shape {
                degree: 1,
                ..Shape::ATOM
            }
        } else {
            Shape::ATOM
        }
    }

    /// Whether [`Self::expand_time_varying`] multiplies `e` out (it is not kept by the
    /// caps) with its sums nested at most two levels deep in products (counted from the
    /// parts the caps keep, which are factors to it): false for the components of a point or
    /// a partial velocity of a chain of 3-D bodies in relative rotations past its second
    /// rotation, whose products are then best left as products
    /// (momentum balance: 570,514 operations after CSE for 8 universal joints with its dot
    /// products multiplied out, 68,408 with them left as products).
    pub fn expands_shallowly(&mut self, e: ExprId) -> bool {
        let shape = self.expansion_shape(e, Expansion::TimeVarying);
        !shape.kept && shape.nesting <= DEEP_NESTING
    }

    /// Whether `e` is a sum that `mode` multiplies out.
    fn is_distributed(&self, e: ExprId, mode: Expansion) -> bool {
        matches!(self.node(e), Node::Add(_))
            && (mode != Expansion::TimeVarying || self.contains_time_varying(e))
    }

    /// Π factors with every sum factor (that `mode` multiplies out) distributed, unless that
    /// makes more than [`MAX_TERMS`] terms.
    fn multiply_out(&mut self, factors: &[ExprId], mode: Expansion) -> ExprId {
        // The factors that are not distributed are common to every term of the result.
        let mut common: Vec<ExprId> = Vec::with_capacity(factors.len());
        let mut sums: Vec<Vec<ExprId>> = Vec::new();
        let mut count = 1usize;
        let mut inputs = 0usize;
        for &f in factors {
            match self.node(f) {
                Node::Add(t) if self.is_distributed(f, mode) => {
                    count = count.saturating_mul(t.len());
                    inputs += t.len();
                    sums.push(t.to_vec());
                }
                _ => common.push(f),
            }
        }
        let quadratic = count <= MAX_QUADRATIC_TERMS && count <= inputs.saturating_mul(inputs);
        if count > MAX_TERMS && !quadratic {
            return self.product(factors);
        }
        if sums.is_empty() {
            return self.product(&common);
        }
        if let [a, b] = &sums[..]
            && a == b
        {
            return self.square_out(common, a);
        }
        // One term per choice of a term from each sum (an odometer over the sums).
        let width = common.len();
        let mut choice = vec![0usize; sums.len()];
        let mut monomials: Vec<ExprId> = Vec::with_capacity(count);
        let mut parts = common;
        loop {
            parts.truncate(width);
            parts.extend(sums.iter().zip(&choice).map(|(terms, &k)| terms[k]));
            monomials.push(self.product(&parts));
            let mut digit = 0;
            loop {
                if digit == sums.len() {
                    return self.sum(&monomials);
                }
                choice[digit] += 1;
                if choice[digit] < sums[digit].len() {
                    break;
                }
                choice[digit] = 0;
                digit += 1;
            }
        }
    }

    /// `Π common · (Σ terms)²` multiplied out as `Σₖ tₖ² + Σₖ<ₗ 2 tₖ tₗ`: half the products of
    /// the general odometer, which would build `tₖ tₗ` and `tₗ tₖ` and merge them.
    fn square_out(&mut self, mut common: Vec<ExprId>, terms: &[ExprId]) -> ExprId {
        let two = self.int(2);
        let width = common.len();
        let mut monomials = Vec::with_capacity(terms.len() * (terms.len() + 1) / 2);
        for (k, &a) in terms.iter().enumerate() {
            for (l, &b) in terms.iter().enumerate().skip(k) {
                common.truncate(width);
                common.extend([a, b]);
                if l > k {
                    common.push(two);
                }
                monomials.push(self.product(&common));
            }
        }
        self.sum(&monomials)
    }

    /// The expansion of `e` if it evaluates with fewer operations (as a tree), else `e`.
    pub fn expand_if_cheaper(&mut self, e: ExprId) -> ExprId {
        let x = self.expand_bounded(e);
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

    /// [`Self::substitute`] with `memo` as its table of what each node became: nodes put there
    /// beforehand are replaced by their entry (a subexpression rewritten another way), and
    /// the table kept across calls shares the work of many roots.
    pub fn substitute_memo(
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
