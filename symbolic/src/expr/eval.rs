//! Numerical evaluation of expressions in `f64`.

use super::{ExprArena, ExprId, Node};
use rustc_hash::FxHashMap;

/// Values of symbols, indexed by [`super::SymbolId`]; symbols beyond the slice are 0.
pub type Bindings<'a> = &'a [f64];

/// Evaluates a fixed set of root expressions at many bindings.
///
/// Built once (the reachable sub-DAG in topological order, each node's children as indices
/// into that order), then each [`Evaluator::eval`] is one pass over that list. Used by
/// `eomgen check`, tests and runtime `--init` values.
#[derive(Debug, Clone)]
pub struct Evaluator {
    order: Vec<Step>,
    roots: Vec<usize>,
    values: Vec<f64>,
}

/// One node with its children as slots of [`Evaluator::order`] (no hashing while evaluating:
/// `eomgen check` of an 80-link chain evaluates a DAG of over a million nodes 200 times).
#[derive(Debug, Clone)]
enum Step {
    Const(f64),
    Symbol(usize),
    Add(Box<[usize]>),
    Mul(Box<[usize]>),
    Pow(usize, usize),
    Func(super::Func, usize),
    Atan2(usize, usize),
}

impl Evaluator {
    /// Prepares evaluation of `roots`.
    pub fn new(arena: &ExprArena, roots: &[ExprId]) -> Self {
        let reachable = arena.reachable(roots);
        let slot: FxHashMap<ExprId, usize> =
            reachable.iter().enumerate().map(|(i, e)| (*e, i)).collect();
        let slots =
            |children: &[ExprId]| -> Box<[usize]> { children.iter().map(|c| slot[c]).collect() };
        let order = reachable
            .iter()
            .map(|&e| match arena.node(e) {
                Node::Const(c) => Step::Const(c.to_f64()),
                Node::Pi => Step::Const(std::f64::consts::PI),
                Node::Symbol(s) => Step::Symbol(s.index()),
                Node::Add(terms) => Step::Add(slots(terms)),
                Node::Mul(factors) => Step::Mul(slots(factors)),
                Node::Pow([b, x]) => Step::Pow(slot[b], slot[x]),
                Node::Func(f, u) => Step::Func(*f, slot[u]),
                Node::Atan2([y, x]) => Step::Atan2(slot[y], slot[x]),
            })
            .collect();
        let roots = roots.iter().map(|r| slot[r]).collect();
        Self {
            values: vec![0.0; reachable.len()],
            order,
            roots,
        }
    }

    /// Values of the roots at `bindings` (written into `out`, one per root).
    pub fn eval_into(&mut self, bindings: Bindings<'_>, out: &mut [f64]) {
        for i in 0..self.order.len() {
            let values = &self.values;
            let value = |k: &usize| values[*k];
            let v = match &self.order[i] {
                Step::Const(c) => *c,
                Step::Symbol(s) => bindings.get(*s).copied().unwrap_or(0.0),
                Step::Add(terms) => terms.iter().map(value).sum(),
                Step::Mul(factors) => factors.iter().map(value).product(),
                Step::Pow(b, e) => pow(values[*b], values[*e]),
                Step::Func(f, u) => f.apply(values[*u]),
                Step::Atan2(y, x) => values[*y].atan2(values[*x]),
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
