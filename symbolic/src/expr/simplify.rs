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
//! simplified forms prints shorter. On those forms, rules rewrite node by node where that
//! prints shorter: `a sin²u + b cos²u` with unlike numbers,
//! double angles (`(I₁ − I₃)(cos²ψ − sin²ψ) = (I₁ − I₃) cos 2ψ`), terms paired by a shared
//! factor, fractions over a common divisor with their numerator multiplied out (so that
//! `−1/D + r² cos²θ/D²` with `D = l² − r² sin²θ` becomes `(r² − l²)/D²`), a denominator's
//! fractions cleared, and numbers and signs moved into or out of a sum. Each step is an
//! identity, so the value is unchanged; `tests` evaluate both forms at random states.
//!
//! # References
//! SymPy's `expand`, `trigsimp` and `collect` (Meurer et al., *PeerJ Comput. Sci.* 3:e103,
//! 2017) do the same steps on arbitrary expressions.

use rustc_hash::FxHashMap;

mod node_rules;

use super::print::{DISPLAY_LIMIT, PrintMemo, Printer, Syntax};
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
        let mut candidates = vec![];
        for x in [flat, collected] {
            candidates.push(self.sums_rewritten(x, Self::over_common_denominator));
        }
        let mut lengths = Lengths::default();
        let square = self.sums_rewritten(expanded, Self::perfect_squares);
        if square != expanded {
            candidates.push(self.rules_composed(square, &mut lengths));
        }
        // Every node rule where it pays, composed node by node: on the written form, the
        // collected form, the expanded form over common divisors (`together`), and that
        // collected. (Of the forms tried on every bundled model and fixture, these are the
        // ones some entry needs to print shortest.)
        let together = self.sums_rewritten(expanded, Self::over_common_divisor);
        let together_collected = self.collect_time_varying(together);
        for x in [flat, collected, together, together_collected] {
            candidates.push(self.rules_composed(x, &mut lengths));
        }
        // The first of the shortest, `e` itself before the candidates.
        std::iter::once(e)
            .chain(candidates)
            .map(|x| (lengths.printed(self, x), x))
            .min_by_key(|&(length, _)| length)
            .map_or(e, |(_, x)| x)
    }

    /// `e` rebuilt bottom up (memoised) with each sum of (rebuilt) terms made by `rule`, and
    /// every other node by the canonical constructors: the walk the printing forms share.
    fn sums_rewritten(&mut self, e: ExprId, rule: fn(&mut Self, &[ExprId]) -> ExprId) -> ExprId {
        let mut memo: FxHashMap<ExprId, ExprId> = FxHashMap::default();
        for x in self.reachable(&[e]) {
            let out = match self.node(x) {
                Node::Add(terms) => {
                    let terms: Vec<ExprId> = terms.iter().map(|c| memo[c]).collect();
                    rule(self, &terms)
                }
                _ => self.rebuilt(x, &memo),
            };
            memo.insert(x, out);
        }
        memo.get(&e).copied().unwrap_or(e)
    }

    /// The node `x` built anew by the canonical constructors from its children as `memo`
    /// maps them.
    fn rebuilt(&mut self, x: ExprId, memo: &FxHashMap<ExprId, ExprId>) -> ExprId {
        let node = self.node(x).clone();
        let children: Vec<ExprId> = node.children().iter().map(|c| memo[c]).collect();
        match node {
            Node::Add(_) => self.sum(&children),
            Node::Mul(_) => self.product(&children),
            Node::Pow(_) => self.pow(children[0], children[1]),
            Node::Func(f, _) => self.func(f, children[0]),
            Node::Atan2(_) => self.atan2(children[0], children[1]),
            Node::Const(_) | Node::Pi | Node::Symbol(_) => x,
        }
    }

    /// `e` with the printing rules applied node by node where each shortens the node, in
    /// order, bottom up and again on the result until it no longer shortens (at most three
    /// passes, so that a sum a rule builds, `C (R₁ + R₂)`, is itself ruled):
    /// - sums: [`Self::pair_squares`], [`Self::double_angles`], [`Self::factored_pairs`],
    ///   [`Self::over_common_denominator`], [`Self::over_common_divisor`], [`Self::together`];
    /// - products: [`Self::double_angle_product`], [`Self::number_multiplied_in`],
    ///   [`Self::sign_taken_out`] (taken at equal length too: its sign then merges with the
    ///   sum around it);
    /// - powers: [`Self::denominator_cleared`].
    ///
    /// `lengths` keeps the lengths met, for the next call on the same expression.
    fn rules_composed(&mut self, e: ExprId, lengths: &mut Lengths) -> ExprId {
        let mut x = e;
        for _ in 0..3 {
            let next = self.rules_pass(x, lengths);
            if self.cached_length(lengths, next) >= self.cached_length(lengths, x) {
                break;
            }
            x = next;
        }
        x
    }

    /// The length of `x` as a factor of a product ([`Lengths`]), kept in `lengths`.
    fn cached_length(&self, lengths: &mut Lengths, x: ExprId) -> usize {
        if let Some(&l) = lengths.factor.get(&x) {
            return l;
        }
        let parentheses = match self.node(x) {
            Node::Add(_) => 2,
            _ => 0,
        };
        let l = lengths.printed(self, x).saturating_add(parentheses);
        lengths.factor.insert(x, l);
        l
    }

    /// One bottom-up pass of [`Self::rules_composed`] (memoised), with the
    /// lengths met kept in `lengths`.
    fn rules_pass(&mut self, e: ExprId, lengths: &mut Lengths) -> ExprId {
        type SumRule = fn(&mut ExprArena, &[ExprId]) -> ExprId;
        type NodeRule = fn(&mut ExprArena, ExprId) -> Option<ExprId>;
        enum Rule {
            Sum(SumRule),
            Node(NodeRule),
            /// A node rule taken at equal length too.
            NodeOnTie(NodeRule),
        }
        let rules = [
            Rule::Sum(Self::pair_squares),
            Rule::Sum(Self::double_angles),
            Rule::Sum(Self::factored_pairs),
            Rule::Sum(Self::over_common_denominator),
            Rule::Sum(Self::over_common_divisor),
            Rule::Sum(Self::together),
            Rule::Node(Self::double_angle_product),
            Rule::Node(Self::number_multiplied_in),
            Rule::NodeOnTie(Self::sign_taken_out),
            Rule::Node(Self::denominator_cleared),
        ];
        let mut memo: FxHashMap<ExprId, ExprId> = FxHashMap::default();
        for x in self.reachable(&[e]) {
            let mut best = self.rebuilt(x, &memo);
            let mut length = self.cached_length(lengths, best);
            for rule in &rules {
                let candidate = match (rule, self.node(best)) {
                    (Rule::Sum(r), Node::Add(terms)) => {
                        let terms = terms.to_vec();
                        Some(r(self, &terms))
                    }
                    (Rule::Sum(_), _) => None,
                    (Rule::Node(r) | Rule::NodeOnTie(r), _) => r(self, best),
                };
                if let Some(c) = candidate.filter(|&c| c != best) {
                    let l = self.cached_length(lengths, c);
                    if l < length || (l == length && matches!(rule, Rule::NodeOnTie(_))) {
                        (best, length) = (c, l);
                    }
                }
            }
            memo.insert(x, best);
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

impl ExprArena {
    /// The sum of `terms` with every three `k A²`, `k β² B²` and `±2 k β A B` (monomials:
    /// numbers times integer powers) written `k (A ± β B)²`: a kinetic energy
    /// `m (ẋ² + 2 v ẋ cos ωt + v² cos² ωt)/2` as `m (ẋ + v cos ωt)²/2`. A third term is found
    /// by `(±2 k β A B)² = 4 (k A²)(k β² B²)`, its sign by comparing it with `2 k β A B`;
    /// sums of more than `MOST_SQUARED_TERMS` terms are left as they are.
    fn perfect_squares(&mut self, terms: &[ExprId]) -> ExprId {
        const MOST_SQUARED_TERMS: usize = 12;
        if terms.len() < 3 || terms.len() > MOST_SQUARED_TERMS {
            return self.sum(terms);
        }
        let mut used = vec![false; terms.len()];
        let mut out = Vec::with_capacity(terms.len());
        for i in 0..terms.len() {
            for j in i + 1..terms.len() {
                if used[i] || used[j] {
                    continue;
                }
                let Some((k, a, b)) = self.square_roots(terms[i], terms[j]) else {
                    continue;
                };
                let two = self.int(2);
                let cross = self.product(&[two, k, a, b]);
                let minus = self.neg(cross);
                let Some((l, sign)) = (0..terms.len())
                    .filter(|&l| l != i && l != j && !used[l])
                    .find_map(|l| match terms[l] {
                        t if t == cross => Some((l, false)),
                        t if t == minus => Some((l, true)),
                        _ => None,
                    })
                else {
                    continue;
                };
                used[i] = true;
                used[j] = true;
                used[l] = true;
                let b = if sign { self.neg(b) } else { b };
                let base = self.plus(a, b);
                let square = self.pow(base, two);
                out.push(self.times(k, square));
            }
        }
        out.extend((0..terms.len()).filter(|&i| !used[i]).map(|i| terms[i]));
        self.sum(&out)
    }

    /// `(k, A, β B)` with `p = k A²` and `q = k β² B²`: `k` the coefficient of `p` times the
    /// lower power of each factor the two share, `β` the rational square root of their
    /// coefficients' ratio; `None` where there is none (a float coefficient, a power that is
    /// not an integer, exponents of unlike parity, a ratio that is no square).
    fn square_roots(&mut self, p: ExprId, q: ExprId) -> Option<(ExprId, ExprId, ExprId)> {
        let (cp, fp) = self.monomial(p)?;
        let (cq, fq) = self.monomial(q)?;
        let (Constant::Rational { num: np, den: dp }, Constant::Rational { num: nq, den: dq }) =
            (cp, cq)
        else {
            return None;
        };
        // β² = cq/cp = (nq dp)/(dq np), a square of a rational.
        let num = nq.checked_mul(dp)?;
        let den = dq.checked_mul(np)?;
        let ratio = Constant::rational(num, den)?;
        let Constant::Rational { num, den } = ratio else {
            return None;
        };
        let beta = Constant::rational(integer_sqrt(num)?, integer_sqrt(den)?)?;
        let mut bases: Vec<ExprId> = fp.iter().chain(&fq).map(|(b, _)| *b).collect();
        bases.sort_unstable();
        bases.dedup();
        let exponent = |list: &[(ExprId, i64)], b: ExprId| {
            list.iter().find(|(x, _)| *x == b).map_or(0, |(_, e)| *e)
        };
        let (mut k, mut a, mut bb) = (
            vec![self.constant(cp)],
            Vec::new(),
            vec![self.constant(beta)],
        );
        for b in bases {
            let (ep, eq) = (exponent(&fp, b), exponent(&fq, b));
            if ep.checked_sub(eq)? % 2 != 0 {
                return None;
            }
            let low = ep.min(eq);
            let (half_p, half_q) = (ep.checked_sub(low)? / 2, eq.checked_sub(low)? / 2);
            for (list, e) in [(&mut k, low), (&mut a, half_p), (&mut bb, half_q)] {
                if e != 0 {
                    let e = self.int(e);
                    list.push(self.pow(b, e));
                }
            }
        }
        if a.is_empty() && bb.len() == 1 {
            return None;
        }
        Some((self.product(&k), self.product(&a), self.product(&bb)))
    }

    /// `t` as a number times integer powers of factors, `(c, [(factor, exponent)])`; `None`
    /// where a power is not an integer.
    fn monomial(&mut self, t: ExprId) -> Option<Monomial> {
        let (c, rest) = self.split_coefficient(t);
        let Some(rest) = rest else {
            return Some((c, Vec::new()));
        };
        let factors: Vec<ExprId> = match self.node(rest) {
            Node::Mul(f) => f.to_vec(),
            _ => vec![rest],
        };
        factors
            .into_iter()
            .map(|f| match self.node(f) {
                Node::Pow([b, e]) => {
                    let (b, e) = (*b, *e);
                    Some((b, self.as_constant(e)?.as_integer()?))
                }
                _ => Some((f, 1)),
            })
            .collect::<Option<Vec<_>>>()
            .map(|f| (c, f))
    }
}

impl ExprArena {
    /// The sum of `terms` with terms of the same rates paired greedily by their largest
    /// common factor (at least two factors, counted with their powers; a sum factor and its
    /// negation count as the same, `I₃ − I₁` and `I₁ − I₃`) and each pair written
    /// `C (R₁ + R₂)`:
    /// `a cos²ψ (I₃ − I₁) + a sin²ψ (I₁ − I₃)` → `a (I₃ − I₁) (cos²ψ − sin²ψ)`. Sums of more
    /// than `MOST_PAIRED_TERMS` terms are left as they are.
    fn factored_pairs(&mut self, terms: &[ExprId]) -> ExprId {
        const MOST_PAIRED_TERMS: usize = 16;
        if terms.len() < 2 || terms.len() > MOST_PAIRED_TERMS {
            return self.sum(terms);
        }
        let split: Vec<Option<Monomial>> = terms.iter().map(|&t| self.monomial(t)).collect();
        let mut used = vec![false; terms.len()];
        let mut out = Vec::with_capacity(terms.len());
        for i in 0..terms.len() {
            let Some((ci, fi)) = split[i].clone().filter(|_| !used[i]) else {
                continue;
            };
            // The partner sharing the most factors: `(j, shared units, its factors with any
            // negated sum turned back, and whether that flipped its sign)`.
            let mut best: Option<(usize, i64, Factors, bool)> = None;
            let rates = self.rates_of(&fi);
            for j in i + 1..terms.len() {
                let Some((_, fj)) = split[j].as_ref().filter(|_| !used[j]) else {
                    continue;
                };
                // Only terms of the same rates: a kinetic energy stays a sum over products
                // of rates (`θ̇₁ θ̇₂ cos(θ₁ − θ₂)` apart from `θ̇₂²`), as a textbook writes it.
                if rates != self.rates_of(fj) {
                    continue;
                }
                let (fj, flipped) = self.aligned_factors(&fi, fj);
                let shared: i64 = (fi.iter())
                    .map(|(b, e)| common_power(*e, exponent_of(&fj, *b)))
                    .fold(0, i64::saturating_add);
                if shared >= 2 && best.as_ref().is_none_or(|(_, s, ..)| shared > *s) {
                    best = Some((j, shared, fj, flipped));
                }
            }
            let Some((j, _, fj, flipped)) = best else {
                continue;
            };
            let Some((cj, _)) = split[j] else { continue };
            used[i] = true;
            used[j] = true;
            let cj = if flipped { cj.negated() } else { cj };
            let mut bases: Vec<ExprId> = fi.iter().chain(&fj).map(|(b, _)| *b).collect();
            bases.sort_unstable();
            bases.dedup();
            let (mut common, mut ri, mut rj) =
                (Vec::new(), vec![self.constant(ci)], vec![self.constant(cj)]);
            for b in bases {
                let (ei, ej) = (exponent_of(&fi, b), exponent_of(&fj, b));
                let c = common_power(ei, ej);
                for (list, e) in [(&mut common, c), (&mut ri, ei - c), (&mut rj, ej - c)] {
                    if e != 0 {
                        let e = self.int(e);
                        list.push(self.pow(b, e));
                    }
                }
            }
            let (common, ri, rj) = (self.product(&common), self.product(&ri), self.product(&rj));
            let inner = self.plus(ri, rj);
            out.push(self.times(common, inner));
        }
        out.extend((0..terms.len()).filter(|&i| !used[i]).map(|i| terms[i]));
        self.sum(&out)
    }

    /// The rates among `factors` and their powers, in order.
    fn rates_of(&self, factors: &[(ExprId, i64)]) -> Factors {
        let mut rates: Factors = (factors.iter())
            .filter(|(b, _)| match self.node(*b) {
                Node::Symbol(s) => {
                    matches!(self.symbol_info(*s).kind, super::SymbolKind::Velocity(_))
                }
                _ => false,
            })
            .copied()
            .collect();
        rates.sort_unstable();
        rates
    }

    /// `other`'s factors with each sum that is the negation of one of `factors`' sums replaced
    /// by that sum, and whether that flipped the sign (an odd number of odd powers).
    fn aligned_factors(
        &mut self,
        factors: &[(ExprId, i64)],
        other: &[(ExprId, i64)],
    ) -> (Factors, bool) {
        let mut flipped = false;
        let mut aligned: Factors = Vec::with_capacity(other.len());
        for &(b, e) in other {
            let mut base = b;
            if let Node::Add(_) = self.node(b)
                && exponent_of(factors, b) == 0
            {
                // The sum negated term by term: the canonical node of `I₃ − I₁` (`neg`
                // would give `−1 · (I₁ − I₃)`, a product).
                let negated = self.neg_terms(b);
                if exponent_of(factors, negated) != 0 {
                    flipped ^= e % 2 != 0;
                    base = negated;
                }
            }
            // A base met twice (a sum and its negation both in `other`) has its powers added.
            match aligned.iter_mut().find(|(x, _)| *x == base) {
                Some((_, power)) => *power = power.saturating_add(e),
                None => aligned.push((base, e)),
            }
        }
        aligned.retain(|(_, e)| *e != 0);
        (aligned, flipped)
    }
}

/// The power of a base two monomials share: the lower of two positive exponents, else 0.
fn common_power(a: i64, b: i64) -> i64 {
    if a > 0 && b > 0 { a.min(b) } else { 0 }
}

/// The exponent of `base` among `factors` (0 if absent).
fn exponent_of(factors: &[(ExprId, i64)], base: ExprId) -> i64 {
    factors
        .iter()
        .find(|(b, _)| *b == base)
        .map_or(0, |(_, e)| *e)
}

/// Factors and their integer powers, `[(factor, exponent)]`.
type Factors = Vec<(ExprId, i64)>;

/// A number times integer powers of factors ([`ExprArena::monomial`]).
type Monomial = (Constant, Factors);

/// The square root of a non-negative integer that is a perfect square.
fn integer_sqrt(n: i64) -> Option<i64> {
    if n < 0 {
        return None;
    }
    let r = (n as f64).sqrt().round() as i64;
    (r.checked_mul(r) == Some(n)).then_some(r)
}

/// The printed lengths the readable forms compare: as the listings print an expression,
/// spaces aside (they only set the operators apart). The printed text of the subexpressions
/// the candidates share is kept between them.
#[derive(Default)]
struct Lengths {
    /// Lengths of expressions as factors of a product: a sum counts its parentheses, so that
    /// `(1 + 5 sin²λ)/8` and `1/8 + 5 sin²λ/8`, of one length alone, are told apart.
    factor: FxHashMap<ExprId, usize>,
    memo: PrintMemo,
}

impl Lengths {
    /// The length of `x` as the listings print it, spaces aside; `usize::MAX` for an
    /// expression the listings print as a note that it is too large
    /// ([`Printer::for_display`]), so that no such form is ever the shortest.
    fn printed(&self, arena: &ExprArena, x: ExprId) -> usize {
        if arena.tree_operation_count(&[x]) > DISPLAY_LIMIT {
            return usize::MAX;
        }
        let text = Printer::for_display(arena, Syntax::Text)
            .with_memo(&self.memo)
            .print(x);
        text.chars().filter(|c| !c.is_whitespace()).count()
    }
}

/// The least common multiple of two positive integers; `None` past `i64`.
fn lcm(a: i64, b: i64) -> Option<i64> {
    (a / gcd(a, b)).checked_mul(b)
}

/// The greatest common divisor of two non-negative integers (`gcd(0, b) = b`).
fn gcd(a: i64, b: i64) -> i64 {
    let (mut x, mut y) = (a, b);
    while y != 0 {
        (x, y) = (y, x % y);
    }
    x
}
