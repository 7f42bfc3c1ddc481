//! Numerical evaluation of expressions in `f64`.

use super::{ExprArena, ExprId, Node};
use rustc_hash::FxHashMap;

/// Values of symbols, indexed by [`super::SymbolId`]; symbols beyond the slice are 0.
pub type Bindings<'a> = &'a [f64];

/// Evaluates a fixed set of root expressions at many bindings.
///
/// Built once (the reachable sub-DAG in topological order), then each [`Evaluator::eval`]
/// is one pass over that list. Used by `eomgen check`, tests and runtime `--init` values.
#[derive(Debug, Clone)]
pub struct Evaluator {
    order: Vec<(ExprId, Node)>,
    slot: FxHashMap<ExprId, usize>,
    roots: Vec<usize>,
    values: Vec<f64>,
}

impl Evaluator {
    /// Prepares evaluation of `roots`.
    pub fn new(arena: &ExprArena, roots: &[ExprId]) -> Self {
        let reachable = arena.reachable(roots);
        let slot: FxHashMap<ExprId, usize> =
            reachable.iter().enumerate().map(|(i, e)| (*e, i)).collect();
        let order = reachable
            .iter()
            .map(|&e| (e, arena.node(e).clone()))
            .collect();
        let roots = roots.iter().map(|r| slot[r]).collect();
        Self {
            values: vec![0.0; reachable.len()],
            order,
            slot,
            roots,
        }
    }

    /// Values of the roots at `bindings` (written into `out`, one per root).
    pub fn eval_into(&mut self, bindings: Bindings<'_>, out: &mut [f64]) {
        for i in 0..self.order.len() {
            let v = {
                let (_, node) = &self.order[i];
                let value = |e: &ExprId| self.values[self.slot[e]];
                match node {
                    Node::Const(c) => c.to_f64(),
                    Node::Pi => std::f64::consts::PI,
                    Node::Symbol(s) => bindings.get(s.index()).copied().unwrap_or(0.0),
                    Node::Add(terms) => terms.iter().map(value).sum(),
                    Node::Mul(factors) => factors.iter().map(value).product(),
                    Node::Pow([b, e]) => pow(value(b), value(e)),
                    Node::Func(f, u) => f.apply(value(u)),
                    Node::Atan2([y, x]) => value(y).atan2(value(x)),
                }
            };
            self.values[i] = v;
        }
        for (o, &r) in out.iter_mut().zip(&self.roots) {
            *o = self.values[r];
        }
    }

    /// Values of the roots at `bindings`.
    pub fn eval(&mut self, bindings: Bindings<'_>) -> Vec<f64> {
        let mut out = vec![0.0; self.roots.len()];
        self.eval_into(bindings, &mut out);
        out
    }
}

/// `b^e` with integer exponents through `powi` (exact sign for negative bases), `1/2` through
/// `sqrt`, as the generated code does.
pub fn pow(b: f64, e: f64) -> f64 {
    if e.fract() == 0.0 && e.abs() <= i32::MAX as f64 {
        b.powi(e as i32)
    } else if e == 0.5 {
        b.sqrt()
    } else if e == -0.5 {
        1.0 / b.sqrt()
    } else {
        b.powf(e)
    }
}

impl ExprArena {
    /// Value of `expr` at `bindings` (symbol values indexed by [`super::SymbolId`]).
    pub fn eval(&self, expr: ExprId, bindings: Bindings<'_>) -> f64 {
        Evaluator::new(self, &[expr]).eval(bindings)[0]
    }
}
