//! Partial and total time derivatives, memoised per `(expression, variable)`.

use super::{Constant, ExprArena, ExprId, Func, Node, SymbolId, SymbolKind};

impl ExprArena {
    /// `∂expr/∂var`, canonical and memoised: each `(expr, var)` pair is differentiated once,
    /// so shared subexpressions are differentiated once.
    pub fn diff(&mut self, expr: ExprId, var: SymbolId) -> ExprId {
        if !self.may_depend_on(expr, var) {
            return self.int(0);
        }
        if let Some(&d) = self.diff_memo.get(&(expr, var)) {
            return d;
        }
        let d = self.diff_uncached(expr, var);
        self.diff_memo.insert((expr, var), d);
        d
    }

    fn diff_uncached(&mut self, expr: ExprId, var: SymbolId) -> ExprId {
        match self.node(expr).clone() {
            Node::Const(_) | Node::Pi => self.int(0),
            Node::Symbol(s) => self.int(i64::from(s == var)),
            Node::Add(terms) => {
                // Only the terms that may contain `var` (one bit test each): a collected
                // kinetic energy has `O(n²)` terms, of which `O(n)` contain a given rate.
                let mut d: Vec<ExprId> = Vec::new();
                for &t in terms.iter() {
                    if self.may_depend_on(t, var) {
                        let dt = self.diff(t, var);
                        if !self.is_zero(dt) {
                            d.push(dt);
                        }
                    }
                }
                self.sum(&d)
            }
            Node::Mul(factors) => {
                // Product rule: Σᵢ f'ᵢ Πⱼ≠ᵢ fⱼ, skipping factors that do not depend on var.
                let derivatives: Vec<ExprId> = factors.iter().map(|&f| self.diff(f, var)).collect();
                let mut terms = Vec::new();
                for (i, &d) in derivatives.iter().enumerate() {
                    if self.is_zero(d) {
                        continue;
                    }
                    let mut parts: Vec<ExprId> = Vec::with_capacity(factors.len());
                    parts.push(d);
                    parts.extend(
                        factors
                            .iter()
                            .enumerate()
                            .filter(|(j, _)| *j != i)
                            .map(|(_, f)| *f),
                    );
                    terms.push(self.product(&parts));
                }
                self.sum(&terms)
            }
            Node::Pow([b, e]) => {
                let db = self.diff(b, var);
                let de = self.diff(e, var);
                let mut terms = Vec::new();
                if !self.is_zero(db) {
                    // e · b^(e−1) · b'
                    let minus_one = self.int(-1);
                    let e1 = self.plus(e, minus_one);
                    let p = self.pow(b, e1);
                    terms.push(self.product(&[e, p, db]));
                }
                if !self.is_zero(de) {
                    // b^e · ln(b) · e'
                    let ln = self.func(Func::Ln, b);
                    terms.push(self.product(&[expr, ln, de]));
                }
                self.sum(&terms)
            }
            Node::Func(f, u) => {
                let du = self.diff(u, var);
                if self.is_zero(du) {
                    return self.int(0);
                }
                let outer = self.func_derivative(f, u);
                self.times(outer, du)
            }
            Node::Atan2([y, x]) => {
                // d atan2(y, x) = (x dy − y dx) / (x² + y²)
                let dy = self.diff(y, var);
                let dx = self.diff(x, var);
                let a = self.times(x, dy);
                let b = self.times(y, dx);
                let num = self.minus(a, b);
                let two = self.int(2);
                let x2 = self.pow(x, two);
                let y2 = self.pow(y, two);
                let den = self.plus(x2, y2);
                self.divide(num, den)
            }
        }
    }

    /// `f'(u)` for the elementary functions.
    fn func_derivative(&mut self, f: Func, u: ExprId) -> ExprId {
        let one = self.int(1);
        let two = self.int(2);
        let half = self.constant(Constant::Rational { num: -1, den: 2 });
        match f {
            Func::Sin => self.cos(u),
            Func::Cos => {
                let s = self.sin(u);
                self.neg(s)
            }
            Func::Tan => {
                let c = self.cos(u);
                let m2 = self.int(-2);
                self.pow(c, m2)
            }
            Func::Asin | Func::Acos => {
                let u2 = self.pow(u, two);
                let r = self.minus(one, u2);
                let d = self.pow(r, half);
                if f == Func::Asin { d } else { self.neg(d) }
            }
            Func::Atan => {
                let u2 = self.pow(u, two);
                let r = self.plus(one, u2);
                let m1 = self.int(-1);
                self.pow(r, m1)
            }
            Func::Sinh => self.func(Func::Cosh, u),
            Func::Cosh => self.func(Func::Sinh, u),
            Func::Tanh => {
                let c = self.func(Func::Cosh, u);
                let m2 = self.int(-2);
                self.pow(c, m2)
            }
            Func::Exp => self.func(Func::Exp, u),
            Func::Ln => {
                let m1 = self.int(-1);
                self.pow(u, m1)
            }
            Func::Abs => self.func(Func::Sign, u),
            // Piecewise constant: zero derivative away from the jump.
            Func::Sign | Func::Step => self.int(0),
        }
    }

    /// Total time derivative `d/dt expr = ∂/∂t + Σᵢ (∂/∂qᵢ q̇ᵢ + ∂/∂q̇ᵢ q̈ᵢ)` along the motion
    /// (with generalized speeds, `∂/∂t + Σᵢ ∂/∂qᵢ q̇ᵢ(q, u, t) + Σᵣ ∂/∂uᵣ u̇ᵣ`).
    ///
    /// Parameters and auxiliary symbols are constant in time. Differentiating an expression
    /// that already contains accelerations `q̈` is not supported (their derivative, the jerk,
    /// has no symbol) and yields a derivative that ignores them.
    pub fn time_derivative(&mut self, expr: ExprId) -> ExprId {
        if let Some(&d) = self.dt_memo.get(&expr) {
            return d;
        }
        let mut terms = Vec::new();
        if let Some(t) = self.time {
            let dt = self.diff(expr, t);
            terms.push(dt);
        }
        let coordinates = self.coordinates.clone();
        for (i, [q, qd, qdd]) in coordinates.into_iter().enumerate() {
            let dq = self.diff(expr, q);
            if !self.is_zero(dq) {
                let rate = self.coordinate_rate(i);
                terms.push(self.times(dq, rate));
            }
            let dqd = self.diff(expr, qd);
            if !self.is_zero(dqd) {
                let acc = self.symbol_expr(qdd);
                terms.push(self.times(dqd, acc));
            }
        }
        let d = self.sum(&terms);
        self.dt_memo.insert(expr, d);
        d
    }

    /// Whether `s` is a symbol that changes in time (coordinate, rate, acceleration, `t`).
    pub fn is_time_varying(&self, s: SymbolId) -> bool {
        !matches!(
            self.symbol_info(s).kind,
            SymbolKind::Parameter | SymbolKind::Auxiliary
        )
    }
}
