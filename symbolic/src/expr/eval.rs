//! Numerical evaluation of expressions in `f64`.

use super::{ExprArena, ExprId, Func, Node};
use rustc_hash::FxHashMap;

/// Values of symbols, indexed by [`super::SymbolId`]; symbols beyond the slice are 0.
pub type Bindings<'a> = &'a [f64];

/// Evaluates a fixed set of root expressions at many bindings.
///
/// Built once (the reachable sub-DAG in topological order, compiled to instructions that
/// address their operands by slot), then each [`Evaluator::eval`] is one pass over that
/// list with no hashing. Used by `eomgen check`, tests and runtime `--init` values.
#[derive(Debug, Clone)]
pub struct Evaluator {
    /// One instruction per reachable node, children first; instruction `k` writes slot `k`.
    program: Vec<Instruction>,
    /// The operand slots of the sums and products, each a range of this list.
    operands: Vec<u32>,
    roots: Vec<usize>,
    values: Vec<f64>,
}

/// One node of an [`Evaluator`]'s program, its operands given as slots.
#[derive(Debug, Clone, Copy)]
enum Instruction {
    Value(f64),
    Symbol(usize),
    /// Sum of the slots `operands[start..end]`.
    Add(u32, u32),
    /// Product of the slots `operands[start..end]`.
    Mul(u32, u32),
    Pow(u32, u32),
    Func(Func, u32),
    Atan2(u32, u32),
}

impl Evaluator {
    /// Prepares evaluation of `roots`.
    pub fn new(arena: &ExprArena, roots: &[ExprId]) -> Self {
        let reachable = arena.reachable(roots);
        let slot: FxHashMap<ExprId, u32> = reachable
            .iter()
            .enumerate()
            .map(|(i, e)| (*e, i as u32))
            .collect();
        let mut operands: Vec<u32> = Vec::new();
        let mut range = |children: &[ExprId]| {
            let start = operands.len() as u32;
            operands.extend(children.iter().map(|c| slot[c]));
            (start, operands.len() as u32)
        };
        let program = reachable
            .iter()
            .map(|&e| match arena.node(e) {
                Node::Const(c) => Instruction::Value(c.to_f64()),
                Node::Pi => Instruction::Value(std::f64::consts::PI),
                Node::Symbol(s) => Instruction::Symbol(s.index()),
                Node::Add(terms) => {
                    let (start, end) = range(terms);
                    Instruction::Add(start, end)
                }
                Node::Mul(factors) => {
                    let (start, end) = range(factors);
                    Instruction::Mul(start, end)
                }
                Node::Pow([b, x]) => Instruction::Pow(slot[b], slot[x]),
                Node::Func(f, u) => Instruction::Func(*f, slot[u]),
                Node::Atan2([y, x]) => Instruction::Atan2(slot[y], slot[x]),
            })
            .collect();
        let roots = roots.iter().map(|r| slot[r] as usize).collect();
        Self {
            values: vec![0.0; reachable.len()],
            program,
            operands,
            roots,
        }
    }

    /// Values of the roots at `bindings` (written into `out`, one per root).
    pub fn eval_into(&mut self, bindings: Bindings<'_>, out: &mut [f64]) {
        let values = &mut self.values;
        for (i, instruction) in self.program.iter().enumerate() {
            let slots = |start: u32, end: u32| &self.operands[start as usize..end as usize];
            let v = match *instruction {
                Instruction::Value(v) => v,
                Instruction::Symbol(s) => bindings.get(s).copied().unwrap_or(0.0),
                Instruction::Add(start, end) => {
                    slots(start, end).iter().map(|&k| values[k as usize]).sum()
                }
                Instruction::Mul(start, end) => slots(start, end)
                    .iter()
                    .map(|&k| values[k as usize])
                    .product(),
                Instruction::Pow(b, e) => pow(values[b as usize], values[e as usize]),
                Instruction::Func(f, u) => f.apply(values[u as usize]),
                Instruction::Atan2(y, x) => values[y as usize].atan2(values[x as usize]),
            };
            values[i] = v;
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
/// `sqrt`, as the generated code does; any other exponent through `f64::powf`, where the
/// generated code takes the half-integers `±3/2 … ±17/2` through a square root
/// (`eomgen_runtime::functions::powf`, within a few ulp of `pow`): this evaluation serves the
/// derivation's numeric checks, which compare within tolerances.
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
