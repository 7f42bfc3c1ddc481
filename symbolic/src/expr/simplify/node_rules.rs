//! The printing rules of [`ExprArena::readable`] that rewrite one node where that prints it
//! shorter: double angles, fractions over a common divisor, numbers and signs moved into or
//! out of a sum (SymPy's `trigsimp` and `together` do the same on whole expressions).

use super::super::{Constant, ExprArena, ExprId, Func, Node};
use super::{Factors, Monomial, exponent_of, gcd, lcm};

impl ExprArena {
    /// The sum of `terms` with every pair `c X cos²u` and `∓c X sin²u` (the same rest `X`,
    /// up to negated sums, `I₁ − I₃` against `I₃ − I₁`) written `c X cos 2u`, and the pairs
    /// with `±c` written `c X`: `(I₁ − I₃) cos²ψ + (I₃ − I₁) sin²ψ = (I₁ − I₃) cos 2ψ`.
    pub(super) fn double_angles(&mut self, terms: &[ExprId]) -> ExprId {
        const MOST_TERMS: usize = 16;
        if terms.len() < 2 || terms.len() > MOST_TERMS {
            return self.sum(terms);
        }
        // Per term: its coefficient, the rest's factors (sorted) and `(u, sine)` of its
        // `sin²u` or `cos²u` factor.
        let split: Vec<Option<(Constant, Factors, ExprId, bool)>> = (terms.iter())
            .map(|&t| {
                let (c, factors) = self.monomial(t)?;
                let (k, u, sine) = factors.iter().enumerate().find_map(|(k, &(b, e))| {
                    match (self.node(b), e) {
                        (Node::Func(Func::Sin, u), 2) => Some((k, *u, true)),
                        (Node::Func(Func::Cos, u), 2) => Some((k, *u, false)),
                        _ => None,
                    }
                })?;
                let mut rest = factors;
                rest.remove(k);
                rest.sort_unstable();
                Some((c, rest, u, sine))
            })
            .collect();
        let mut used = vec![false; terms.len()];
        let mut out = Vec::with_capacity(terms.len());
        for i in 0..terms.len() {
            let Some((ci, fi, u, false)) = split[i].clone().filter(|_| !used[i]) else {
                continue;
            };
            let partner = (0..terms.len()).find_map(|j| {
                let (cj, fj, v, true) = split[j].clone().filter(|_| !used[j])? else {
                    return None;
                };
                if v != u {
                    return None;
                }
                let (mut fj, flipped) = self.aligned_factors(&fi, &fj);
                fj.sort_unstable();
                let cj = if flipped { cj.negated() } else { cj };
                (fj == fi && (cj == ci || cj == ci.negated())).then_some((j, cj == ci))
            });
            let Some((j, same)) = partner else { continue };
            used[i] = true;
            used[j] = true;
            let mut factors = vec![self.constant(ci)];
            for &(b, e) in &fi {
                let e = self.int(e);
                factors.push(self.pow(b, e));
            }
            if !same {
                let two = self.int(2);
                let doubled = self.times(two, u);
                factors.push(self.cos(doubled));
            }
            out.push(self.product(&factors));
        }
        out.extend((0..terms.len()).filter(|&i| !used[i]).map(|i| terms[i]));
        self.sum(&out)
    }

    /// The sum of `terms` with those divided by powers of one sum `D` written over the highest
    /// power, `N/Dᴷ`, the numerator multiplied out: like terms of `N` then cancel,
    /// `−1/D + r² cos²θ/D²` with `D = l² − r² sin²θ` → `(r² − l²)/D²`. The sum `D` chosen is
    /// the one that divides the most terms.
    pub(super) fn over_common_divisor(&mut self, terms: &[ExprId]) -> ExprId {
        self.over_divisor(terms, false)
    }

    /// [`Self::over_common_divisor`] with every term put over `Dᴷ` (SymPy's `together`):
    /// `1 + y²/(l² − y²)` → `l²/(l² − y²)`.
    pub(super) fn together(&mut self, terms: &[ExprId]) -> ExprId {
        self.over_divisor(terms, true)
    }

    /// [`Self::over_common_divisor`] (`all` false) and [`Self::together`] (`all` true).
    fn over_divisor(&mut self, terms: &[ExprId], all: bool) -> ExprId {
        const MOST_TERMS: usize = 40;
        if !(2..=MOST_TERMS).contains(&terms.len()) {
            return self.sum(terms);
        }
        let terms: Vec<ExprId> = terms.iter().map(|&t| self.primitive_divisors(t)).collect();
        let split: Vec<Option<Monomial>> = terms.iter().map(|&t| self.monomial(t)).collect();
        // The sums dividing terms, with how many terms each divides and its highest power.
        let mut divisors: Vec<(ExprId, usize, i64)> = Vec::new();
        for (_, factors) in split.iter().flatten() {
            for &(b, e) in factors {
                if e < 0 && matches!(self.node(b), Node::Add(_)) {
                    let Some(power) = e.checked_neg() else {
                        return self.sum(&terms);
                    };
                    match divisors.iter_mut().find(|(d, ..)| *d == b) {
                        Some((_, count, k)) => (*count, *k) = (*count + 1, (*k).max(power)),
                        None => divisors.push((b, 1, power)),
                    }
                }
            }
        }
        let Some(&(d, _, k)) = (divisors.iter()).max_by_key(|(_, count, _)| *count) else {
            return self.sum(&terms);
        };
        let power = self.int(k);
        let dk = self.pow(d, power);
        let (mut over, mut rest) = (Vec::new(), Vec::new());
        for (i, &t) in terms.iter().enumerate() {
            match &split[i] {
                Some((_, f)) if all || exponent_of(f, d) < 0 => over.push(self.times(dk, t)),
                _ if all => over.push(self.times(dk, t)),
                _ => rest.push(t),
            }
        }
        let numerator = self.sum(&over);
        let numerator = self.expand_bounded(numerator);
        let minus = self.int(-k);
        let inverse = self.pow(d, minus);
        rest.push(self.times(numerator, inverse));
        self.sum(&rest)
    }

    /// `D = Π bᵏ` over the factors `b` that divide some of `terms` (monomials), `k` the
    /// highest power among them: `D` times each term has no divisor left (1 where no term has
    /// one); `None` where a term is no monomial or a power is past `i64`.
    fn divisors_of(&mut self, terms: &[ExprId]) -> Option<ExprId> {
        let mut divisors: Factors = Vec::new();
        for &t in terms {
            let (_, factors) = self.monomial(t)?;
            for (b, e) in factors.into_iter().filter(|(_, e)| *e < 0) {
                let power = e.checked_neg()?;
                match divisors.iter_mut().find(|(d, _)| *d == b) {
                    Some((_, k)) => *k = (*k).max(power),
                    None => divisors.push((b, power)),
                }
            }
        }
        let divisors: Vec<ExprId> = (divisors.into_iter())
            .map(|(b, k)| {
                let k = self.int(k);
                self.pow(b, k)
            })
            .collect();
        Some(self.product(&divisors))
    }

    /// `t` with each sum `B` it is divided by written `f P`, `P` the primitive part: the
    /// fractions of its terms cleared, their integer coefficients without a common divisor,
    /// and its sign fixed by its first term's, so that `4 l² − 4 r² sin²θ`,
    /// `1 − r² sin²θ/l²` and `r² sin²θ − l²` all divide by the one `P = l² − r² sin²θ` (up to
    /// the order of the canonical sum); `t` itself where it is not a monomial.
    fn primitive_divisors(&mut self, t: ExprId) -> ExprId {
        let Some((c, factors)) = self.monomial(t) else {
            return t;
        };
        let mut out = vec![self.constant(c)];
        for (b, e) in factors {
            let (f, p) = match e < 0 {
                true => self.primitive(b).unwrap_or((self.int(1), b)),
                false => (self.int(1), b),
            };
            let e = self.int(e);
            out.push(self.pow(f, e));
            out.push(self.pow(p, e));
        }
        self.product(&out)
    }

    /// `(f, P)` with `b = f P` for a sum `b`, `P` its primitive part
    /// ([`Self::primitive_divisors`]) and `f` a number times powers of the divisors
    /// cleared; `None` where `b` is no sum of monomials with rational coefficients.
    fn primitive(&mut self, b: ExprId) -> Option<(ExprId, ExprId)> {
        let Node::Add(terms) = self.node(b) else {
            return None;
        };
        let terms = terms.to_vec();
        let d = self.divisors_of(&terms)?;
        let cleared: Vec<ExprId> = terms.iter().map(|&t| self.times(d, t)).collect();
        // The content: the gcd of the numerators over the lcm of the denominators, with the
        // sign of the first term.
        let (mut num, mut den) = (0i64, 1i64);
        for &t in &cleared {
            let Constant::Rational { num: n, den: m } = self.split_coefficient(t).0 else {
                return None;
            };
            num = gcd(num, n.checked_abs()?);
            den = lcm(den, m)?;
        }
        if self.split_coefficient(cleared[0]).0.is_negative() {
            num = -num;
        }
        let content = self.constant(Constant::rational(num, den)?);
        let inverse = self.constant(Constant::rational(den, num)?);
        let primitive: Vec<ExprId> = cleared.iter().map(|&t| self.times(inverse, t)).collect();
        // A product past `i64` folds to a float: not exact, so no primitive part.
        for &t in &primitive {
            if matches!(self.split_coefficient(t).0, Constant::Float(_)) {
                return None;
            }
        }
        let primitive = self.sum(&primitive);
        let minus_one = self.int(-1);
        let d_inverse = self.pow(d, minus_one);
        Some((self.times(content, d_inverse), primitive))
    }

    /// `x` with a product `c sin u cos u` written `(c/2) sin 2u`; `None` where `x` has no
    /// such pair.
    pub(super) fn double_angle_product(&mut self, x: ExprId) -> Option<ExprId> {
        if !matches!(self.node(x), Node::Mul(_)) {
            return None;
        }
        let (c, factors) = self.monomial(x)?;
        let Constant::Rational { num, den } = c else {
            return None;
        };
        let sines: Vec<(usize, ExprId)> = (factors.iter().enumerate())
            .filter_map(|(k, &(b, e))| match self.node(b) {
                Node::Func(Func::Sin, u) if e == 1 => Some((k, *u)),
                _ => None,
            })
            .collect();
        let (s, u, k) = sines.into_iter().find_map(|(s, u)| {
            let cosine = self.cos(u);
            let k = factors.iter().position(|&(b, e)| b == cosine && e == 1)?;
            Some((s, u, k))
        })?;
        let mut out = vec![self.constant(Constant::rational(num, den.checked_mul(2)?)?)];
        for (i, &(b, e)) in factors.iter().enumerate() {
            if i != s && i != k {
                let e = self.int(e);
                out.push(self.pow(b, e));
            }
        }
        let two = self.int(2);
        let doubled = self.times(two, u);
        out.push(self.sin(doubled));
        Some(self.product(&out))
    }

    /// `x = c S R` for a number `c ≠ 1` and a sum `S` (the only one among the factors) with
    /// `c` multiplied into `S`: `−(a − b)` → `b − a`, `(a + 3b)/2` → `a/2 + 3b/2`; `None`
    /// where `x` is not such a product.
    pub(super) fn number_multiplied_in(&mut self, x: ExprId) -> Option<ExprId> {
        let Node::Mul(factors) = self.node(x) else {
            return None;
        };
        let factors = factors.to_vec();
        let (c, _) = self.split_coefficient(x);
        let sums: Vec<usize> = (factors.iter().enumerate())
            .filter(|&(_, &f)| matches!(self.node(f), Node::Add(_)))
            .map(|(i, _)| i)
            .collect();
        let (&[k], false) = (sums.as_slice(), c.is_one()) else {
            return None;
        };
        let Node::Add(terms) = self.node(factors[k]) else {
            return None;
        };
        let terms = terms.to_vec();
        let c = self.constant(c);
        let scaled: Vec<ExprId> = terms.into_iter().map(|t| self.times(c, t)).collect();
        let mut out = vec![self.sum(&scaled)];
        out.extend(
            (factors.iter().enumerate())
                .filter(|&(i, &f)| i != k && self.as_constant(f).is_none())
                .map(|(_, &f)| f),
        );
        Some(self.product(&out))
    }

    /// `x = c Sⁿ R` with a sum `S` (to an integer power) whose terms are all negative written
    /// `(−1)ⁿ c (−S)ⁿ R`: `m (−a − b)` → `−m (a + b)`, `(−a − b)²` → `(a + b)²`; `None` where
    /// `x` has no such factor.
    pub(super) fn sign_taken_out(&mut self, x: ExprId) -> Option<ExprId> {
        let factors = match self.node(x) {
            Node::Mul(factors) => factors.to_vec(),
            Node::Pow(_) => vec![x],
            _ => return None,
        };
        let (mut flipped, mut changed) = (false, false);
        let mut out = Vec::with_capacity(factors.len() + 1);
        for f in factors {
            let (base, exponent) = match self.node(f) {
                Node::Pow([b, e]) => (*b, self.as_constant(*e).and_then(Constant::as_integer)),
                _ => (f, Some(1)),
            };
            let negative = match (self.node(base), exponent) {
                (Node::Add(terms), Some(_)) => {
                    let terms = terms.to_vec();
                    terms
                        .iter()
                        .all(|&t| self.split_coefficient(t).0.is_negative())
                }
                _ => false,
            };
            if !negative {
                out.push(f);
                continue;
            }
            let exponent = exponent.unwrap_or(1);
            flipped ^= exponent % 2 != 0;
            let negated = self.neg_terms(base);
            let e = self.int(exponent);
            out.push(self.pow(negated, e));
            changed = true;
        }
        if !changed {
            return None;
        }
        if flipped {
            out.push(self.int(-1));
        }
        Some(self.product(&out))
    }

    /// The sum `s` negated term by term (a sum, where `neg` would give the product `−1 · s`).
    pub(super) fn neg_terms(&mut self, s: ExprId) -> ExprId {
        let Node::Add(terms) = self.node(s) else {
            return self.neg(s);
        };
        let terms = terms.to_vec();
        let negated: Vec<ExprId> = terms.iter().map(|&t| self.neg(t)).collect();
        self.sum(&negated)
    }

    /// `x = S⁻ⁿ` for a sum `S` some of whose terms are divided by factors `D` written
    /// `Dⁿ (D S)⁻ⁿ`, the fractions of `D S` cleared: `1/(1 − r² sin²θ/l²)` →
    /// `l²/(l² − r² sin²θ)`; `None` where `x` is not such a power.
    pub(super) fn denominator_cleared(&mut self, x: ExprId) -> Option<ExprId> {
        let Node::Pow([sum, exponent]) = *self.node(x) else {
            return None;
        };
        let n = self
            .as_constant(exponent)?
            .as_integer()
            .filter(|n| *n < 0)?;
        let Node::Add(terms) = self.node(sum) else {
            return None;
        };
        let terms = terms.to_vec();
        let d = self.divisors_of(&terms)?;
        let one = self.int(1);
        if d == one {
            return None;
        }
        let cleared: Vec<ExprId> = terms.iter().map(|&t| self.times(d, t)).collect();
        let cleared = self.sum(&cleared);
        let power = self.pow(cleared, exponent);
        let minus_n = self.int(n.checked_neg()?);
        let outside = self.pow(d, minus_n);
        Some(self.times(outside, power))
    }
}
