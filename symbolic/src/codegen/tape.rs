//! A CSE plan as a straight-line program of `f64` operations: what a run-time backend (a JIT
//! compiler, an interpreter) evaluates in place of the Rust source [`super::emit`] prints.
//!
//! The lowering follows the Rust printer ([`crate::expr::print`] with [`Syntax::Rust`])
//! operation by operation — the same terms in the same order, the same grouping, `powi` as
//! the same sequence of squarings and products LLVM emits, `sqrt` for `^(1/2)` — so that a
//! backend which computes each instruction with the same IEEE operation or library function
//! as the compiled Rust gets the same bits. Negation is exact and commutes with rounding
//! (`(−a)·b = −(a·b)`, `−a + b` is `b − a` with the sign of zero preserved as Rust has it),
//! so where the printer puts a minus sign on a factor the tape negates the product; nothing
//! else is reordered.
//!
//! [`Syntax::Rust`]: crate::expr::print::Syntax::Rust

use rustc_hash::FxHashMap;

use crate::expr::cse::{CsePlan, Temporary};
use crate::expr::{Constant, ExprArena, ExprId, Func, Node, SymbolId, SymbolKind};

/// A value of a [`Tape`]: the index of the instruction that computes it.
pub type Value = u32;

/// Where a tape reads an input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Input {
    /// Parameter `i` (file order).
    Parameter(u32),
    /// Generalized coordinate `qᵢ`.
    Coordinate(u32),
    /// Generalized velocity `q̇ᵢ`.
    Velocity(u32),
    /// Component `i` of the acceleration-like vector: `a` of `∂(M a)/∂q`, or `q̈` in event
    /// functions.
    Acceleration(u32),
    /// Lagrange multiplier `λᵢ` (event functions only; NaN where the caller has none).
    Multiplier(u32),
    /// Time `t`.
    Time,
}

/// One operation; each defines the [`Value`] of its index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Instruction {
    /// Reads an input.
    Input(Input),
    /// A constant.
    Const(f64),
    /// `−x`.
    Neg(Value),
    /// `x + y`.
    Add(Value, Value),
    /// `x − y`.
    Sub(Value, Value),
    /// `x · y`.
    Mul(Value, Value),
    /// `x / y`.
    Div(Value, Value),
    /// `√x` (IEEE, correctly rounded).
    Sqrt(Value),
    /// `|x|`.
    Abs(Value),
    /// A function of one argument other than `abs` (which is [`Instruction::Abs`]), called
    /// as the generated Rust calls it: `sin` and `cos` from the `libm` crate, `sign` and `step`
    /// as `eomgen::__private` defines them, the others as the `f64` methods of their names.
    Call(Func, Value),
    /// `xʸ` (`eomgen_runtime::functions::powf`: `f64::powf`, but for a half-integer `y`
    /// from ±3/2 to ±17/2, taken through `√x`).
    Powf(Value, Value),
    /// `atan2(y, x)` (`f64::atan2`), arguments in that order.
    Atan2(Value, Value),
    /// `sin x` of `libm::sincos(x)`; the instruction right after it is its
    /// [`Instruction::CosOfSinCos`].
    SinCos(Value),
    /// `cos x` of the `libm::sincos` call of the instruction it names.
    CosOfSinCos(Value),
}

impl Instruction {
    /// The same instruction with each operand `v` replaced by `f(v)`.
    pub fn map_operands(self, mut f: impl FnMut(Value) -> Value) -> Instruction {
        use Instruction as I;
        match self {
            I::Input(_) | I::Const(_) => self,
            I::Neg(x) => I::Neg(f(x)),
            I::Sqrt(x) => I::Sqrt(f(x)),
            I::Abs(x) => I::Abs(f(x)),
            I::Call(g, x) => I::Call(g, f(x)),
            I::SinCos(x) => I::SinCos(f(x)),
            I::CosOfSinCos(x) => I::CosOfSinCos(f(x)),
            I::Add(x, y) => I::Add(f(x), f(y)),
            I::Sub(x, y) => I::Sub(f(x), f(y)),
            I::Mul(x, y) => I::Mul(f(x), f(y)),
            I::Div(x, y) => I::Div(f(x), f(y)),
            I::Powf(x, y) => I::Powf(f(x), f(y)),
            I::Atan2(x, y) => I::Atan2(f(x), f(y)),
        }
    }
}

/// A straight-line program: instructions in evaluation order, then the outputs.
///
/// Every operand precedes its user; a [`Instruction::SinCos`] is always followed by its
/// [`Instruction::CosOfSinCos`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Tape {
    /// The instructions.
    pub instructions: Vec<Instruction>,
    /// The values returned, in the order of the plan's roots.
    pub outputs: Vec<Value>,
}

impl Tape {
    /// Arithmetic operations and calls (inputs and constants not counted).
    pub fn operation_count(&self) -> usize {
        self.instructions
            .iter()
            .filter(|i| !matches!(i, Instruction::Input(_) | Instruction::Const(_)))
            .count()
    }

    /// Checks the tape's shape: every operand precedes its user, every
    /// [`Instruction::SinCos`] is followed by its [`Instruction::CosOfSinCos`] (and only there),
    /// and every output names an instruction. A backend checks this before it compiles a tape
    /// it did not build itself.
    ///
    /// # Errors
    /// The first violation, as a sentence naming the instruction.
    pub fn validate(&self) -> Result<(), String> {
        let count = self.instructions.len();
        for (k, instruction) in self.instructions.iter().enumerate() {
            let operands: &[Value] = match instruction {
                Instruction::Input(_) | Instruction::Const(_) => &[],
                Instruction::Neg(x)
                | Instruction::Sqrt(x)
                | Instruction::Abs(x)
                | Instruction::Call(_, x)
                | Instruction::SinCos(x) => std::slice::from_ref(x),
                Instruction::CosOfSinCos(x) => {
                    if *x as usize + 1 != k
                        || !matches!(self.instructions[*x as usize], Instruction::SinCos(_))
                    {
                        return Err(format!(
                            "instruction {k} takes the cosine of instruction {x}, which is not the `sin_cos` just before it"
                        ));
                    }
                    &[]
                }
                Instruction::Add(x, y)
                | Instruction::Sub(x, y)
                | Instruction::Mul(x, y)
                | Instruction::Div(x, y)
                | Instruction::Powf(x, y)
                | Instruction::Atan2(x, y) => {
                    if *x as usize >= k || *y as usize >= k {
                        return Err(format!(
                            "instruction {k} uses a value ({x} or {y}) that is not computed before it"
                        ));
                    }
                    &[]
                }
            };
            if let Some(x) = operands.iter().find(|x| **x as usize >= k) {
                return Err(format!(
                    "instruction {k} uses value {x}, which is not computed before it"
                ));
            }
            if matches!(instruction, Instruction::SinCos(_))
                && !matches!(self.instructions.get(k + 1), Some(Instruction::CosOfSinCos(s)) if *s as usize == k)
            {
                return Err(format!(
                    "the `sin_cos` of instruction {k} is not followed by its cosine"
                ));
            }
        }
        match self.outputs.iter().find(|x| **x as usize >= count) {
            Some(x) => Err(format!(
                "output names value {x}, but the tape has {count} instructions"
            )),
            None => Ok(()),
        }
    }

    /// The same tape with every operation on the same operands computed once (value
    /// numbering: `x + y` and `y + x`, `x · y` and `y · x` are the same operation; inputs and
    /// constants are kept as they are), the operands and outputs renumbered to match.
    ///
    /// The lowering writes each product and sum of the printed code out in full, so the
    /// chains the expression DAG does not share are repeated: the same `G·Δ·m²` prefix in
    /// `−G·Δ·m²·r⁻³` and `G·Δ·m²·r⁻³` (each pair's pull in the equations of both its bodies).
    /// An operation on the same operands computes the same bits (IEEE addition and
    /// multiplication are commutative), so every value of the numbered tape is the value of
    /// the instructions it replaces, to the bit. Used for the Taylor recurrences
    /// ([`super::taylor::taylor_program`]), where each value is a series and each repeat
    /// costs a convolution per order: the figure eight's `M` and `F` go from 67 to 46
    /// operations and its Taylor method from 77 to 56 series. The right-hand sides stay as
    /// lowered: the run-time compiler took longer over the Whipple bicycle's numbered tape
    /// (5,168 operations for 8,586, but its shared values live longer: 58 ms against 45 ms).
    ///
    /// A [`Instruction::SinCos`] repeated is followed by its repeated
    /// [`Instruction::CosOfSinCos`], so both go and the pair stays adjacent.
    pub fn numbered(&self) -> Tape {
        let mut numbered = Tape::default();
        let mut new_value = Vec::with_capacity(self.instructions.len());
        let mut operations: FxHashMap<Operation, Value> = FxHashMap::default();
        for instruction in &self.instructions {
            let renumbered = instruction.map_operands(|v| new_value[v as usize]);
            let key = Operation::of(renumbered);
            let value = match key.and_then(|k| operations.get(&k).copied()) {
                Some(v) => v,
                None => {
                    numbered.instructions.push(renumbered);
                    let v = (numbered.instructions.len() - 1) as Value;
                    if let Some(k) = key {
                        operations.insert(k, v);
                    }
                    v
                }
            };
            new_value.push(value);
        }
        numbered.outputs = self
            .outputs
            .iter()
            .map(|&v| new_value[v as usize])
            .collect();
        numbered
    }

    /// Lowers `plan` (made by [`crate::expr::cse::plan`] over `arena`) to a tape that
    /// computes what the Rust code [`super::emit`] prints for the same plan computes, in the
    /// same order. `parameters` are the parameters' symbols in file order: parameter symbol
    /// `parameters[i]` is read as [`Input::Parameter`]`(i)`.
    pub fn from_plan(arena: &ExprArena, plan: &CsePlan, parameters: &[SymbolId]) -> Tape {
        let mut lowering = Lowering {
            arena,
            tape: Tape::default(),
            temporaries: FxHashMap::default(),
            symbols: FxHashMap::default(),
            constants: FxHashMap::default(),
        };
        // Inputs first, in symbol order (as the Rust bodies bind them).
        let mut used: Vec<SymbolId> = arena
            .reachable(&plan.roots)
            .iter()
            .filter_map(|e| match arena.node(*e) {
                Node::Symbol(s) => Some(*s),
                _ => None,
            })
            .collect();
        used.sort();
        for s in used {
            let value = match arena.symbol_info(s).kind {
                SymbolKind::Parameter => match parameters.iter().position(|p| *p == s) {
                    Some(i) => lowering.push(Instruction::Input(Input::Parameter(i as u32))),
                    // Not a parameter of the model: the lowering declares none such.
                    None => lowering.constant(f64::NAN),
                },
                SymbolKind::Coordinate(i) => {
                    lowering.push(Instruction::Input(Input::Coordinate(i)))
                }
                SymbolKind::Velocity(i) => lowering.push(Instruction::Input(Input::Velocity(i))),
                SymbolKind::Acceleration(i) => {
                    lowering.push(Instruction::Input(Input::Acceleration(i)))
                }
                SymbolKind::Multiplier(i) => {
                    lowering.push(Instruction::Input(Input::Multiplier(i)))
                }
                SymbolKind::Time => lowering.push(Instruction::Input(Input::Time)),
                // The generated Rust binds auxiliary symbols to 0.
                SymbolKind::Auxiliary => lowering.constant(0.0),
                // Replaced in every expression of a model with speeds; a NaN if one were left.
                SymbolKind::Retired => lowering.constant(f64::NAN),
            };
            lowering.symbols.insert(s, value);
        }
        for temp in &plan.temporaries {
            match *temp {
                Temporary::Single(e) => {
                    let v = lowering.definition(e);
                    lowering.temporaries.insert(e, v);
                }
                Temporary::SinCos { arg, sin, cos } => {
                    let a = lowering.operand(arg);
                    let s = lowering.push(Instruction::SinCos(a));
                    let c = lowering.push(Instruction::CosOfSinCos(s));
                    lowering.temporaries.insert(sin, s);
                    lowering.temporaries.insert(cos, c);
                }
            }
        }
        let outputs = plan.roots.iter().map(|r| lowering.operand(*r)).collect();
        let mut tape = lowering.tape;
        tape.outputs = outputs;
        tape
    }
}

struct Lowering<'a> {
    arena: &'a ExprArena,
    tape: Tape,
    temporaries: FxHashMap<ExprId, Value>,
    symbols: FxHashMap<SymbolId, Value>,
    constants: FxHashMap<u64, Value>,
}

/// An operation's kind and operands, the key under which [`Tape::numbered`] numbers values:
/// commutative operations with their operands in increasing order.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Operation {
    Unary(u8, Option<Func>, Value),
    Binary(u8, Value, Value),
}

impl Operation {
    /// The key of `instruction`; `None` for inputs and constants (numbered elsewhere).
    fn of(instruction: Instruction) -> Option<Self> {
        use Instruction as I;
        let unary = |tag, x| Some(Self::Unary(tag, None, x));
        let binary = |tag, x, y| Some(Self::Binary(tag, x, y));
        let commutative = |tag, x: Value, y: Value| Some(Self::Binary(tag, x.min(y), x.max(y)));
        match instruction {
            I::Input(_) | I::Const(_) => None,
            I::Neg(x) => unary(0, x),
            I::Sqrt(x) => unary(1, x),
            I::Abs(x) => unary(2, x),
            I::SinCos(x) => unary(3, x),
            I::CosOfSinCos(x) => unary(4, x),
            I::Call(f, x) => Some(Self::Unary(5, Some(f), x)),
            I::Add(x, y) => commutative(0, x, y),
            I::Mul(x, y) => commutative(1, x, y),
            I::Sub(x, y) => binary(2, x, y),
            I::Div(x, y) => binary(3, x, y),
            I::Powf(x, y) => binary(4, x, y),
            I::Atan2(x, y) => binary(5, x, y),
        }
    }
}

impl Lowering<'_> {
    fn push(&mut self, instruction: Instruction) -> Value {
        self.tape.instructions.push(instruction);
        (self.tape.instructions.len() - 1) as Value
    }

    fn constant(&mut self, x: f64) -> Value {
        if let Some(&v) = self.constants.get(&x.to_bits()) {
            return v;
        }
        let v = self.push(Instruction::Const(x));
        self.constants.insert(x.to_bits(), v);
        v
    }

    /// A constant as the printer writes it: `|c|` as an `f64` literal, negated if `c < 0`.
    fn printed_constant(&mut self, c: Constant) -> Value {
        let magnitude = c.to_f64().abs();
        self.constant(if c.is_negative() {
            -magnitude
        } else {
            magnitude
        })
    }

    /// `e` where it is used: its temporary if it has one, else its definition.
    fn operand(&mut self, e: ExprId) -> Value {
        match self.temporaries.get(&e) {
            Some(&v) => v,
            None => self.definition(e),
        }
    }

    /// The node of `e` itself, its children as operands (the printer's `node`).
    fn definition(&mut self, e: ExprId) -> Value {
        match self.arena.node(e) {
            Node::Const(c) => self.printed_constant(*c),
            Node::Pi => self.constant(std::f64::consts::PI),
            Node::Symbol(s) => match self.symbols.get(s) {
                Some(&v) => v,
                // Every reachable symbol was bound before the temporaries.
                None => self.constant(f64::NAN),
            },
            Node::Add(terms) => self.sum(terms),
            Node::Mul(factors) => {
                let (coefficient, rest) = self.split(factors);
                let magnitude = self.product(coefficient.abs_constant(), rest);
                if coefficient.is_negative() {
                    self.push(Instruction::Neg(magnitude))
                } else {
                    magnitude
                }
            }
            Node::Pow([b, x]) => {
                let exponent = match self.arena.as_constant(*x) {
                    Some(c) => Exponent::Constant(c),
                    None => Exponent::Expr(*x),
                };
                self.power(*b, exponent)
            }
            Node::Func(f, u) => {
                let a = self.operand(*u);
                match f {
                    Func::Abs => self.push(Instruction::Abs(a)),
                    f => self.push(Instruction::Call(*f, a)),
                }
            }
            Node::Atan2([y, x]) => {
                let y = self.operand(*y);
                let x = self.operand(*x);
                self.push(Instruction::Atan2(y, x))
            }
        }
    }

    /// The printer's `split`: a leading constant factor that is not a temporary.
    fn split<'b>(&self, factors: &'b [ExprId]) -> (Constant, &'b [ExprId]) {
        match self.arena.as_constant(factors[0]) {
            Some(c) if !self.temporaries.contains_key(&factors[0]) => (c, &factors[1..]),
            _ => (Constant::ONE, factors),
        }
    }

    /// The printer's `sum`: non-constant terms in order, then the constants, added and
    /// subtracted left to right.
    fn sum(&mut self, terms: &[ExprId]) -> Value {
        let ordered: Vec<ExprId> = terms
            .iter()
            .copied()
            .filter(|t| self.arena.as_constant(*t).is_none())
            .chain(
                terms
                    .iter()
                    .copied()
                    .filter(|t| self.arena.as_constant(*t).is_some()),
            )
            .collect();
        let mut acc: Option<Value> = None;
        for t in ordered {
            let (negative, magnitude) = self.signed_term(t);
            acc = Some(match (acc, negative) {
                (None, false) => magnitude,
                (None, true) => self.push(Instruction::Neg(magnitude)),
                (Some(a), false) => self.push(Instruction::Add(a, magnitude)),
                (Some(a), true) => self.push(Instruction::Sub(a, magnitude)),
            });
        }
        acc.unwrap_or_else(|| self.constant(0.0))
    }

    /// The printer's `signed_term`: (is negative, magnitude).
    fn signed_term(&mut self, t: ExprId) -> (bool, Value) {
        if let Some(&v) = self.temporaries.get(&t) {
            return (false, v);
        }
        match self.arena.node(t) {
            Node::Const(c) => {
                let c = *c;
                (c.is_negative(), self.printed_constant(c.abs_constant()))
            }
            Node::Mul(factors) => {
                let (c, rest) = self.split(factors);
                (c.is_negative(), self.product(c.abs_constant(), rest))
            }
            _ => (false, self.operand(t)),
        }
    }

    /// The printer's `product` for `coefficient ≥ 0`: `c · n₁ · n₂ ⋯ / (d₁ · d₂ ⋯)`, each
    /// chain multiplied left to right, factors with a negative constant exponent in the
    /// denominator.
    fn product(&mut self, coefficient: Constant, factors: &[ExprId]) -> Value {
        let mut numerator: Vec<Value> = Vec::new();
        let mut denominator: Vec<Value> = Vec::new();
        if !coefficient.is_one() {
            let c = self.printed_constant(coefficient);
            numerator.push(c);
        }
        for &f in factors {
            if !self.temporaries.contains_key(&f)
                && let Node::Pow([b, x]) = self.arena.node(f)
                && let Some(c) = self.arena.as_constant(*x)
                && c.is_negative()
            {
                let (b, power) = (*b, c.negated());
                let d = if power.is_one() {
                    self.operand(b)
                } else {
                    self.power(b, Exponent::Constant(power))
                };
                denominator.push(d);
                continue;
            }
            let v = self.operand(f);
            numerator.push(v);
        }
        let num = self.chain(&numerator);
        if denominator.is_empty() {
            return num.unwrap_or_else(|| self.constant(1.0));
        }
        let num = num.unwrap_or_else(|| self.constant(1.0));
        let den = self
            .chain(&denominator)
            .unwrap_or_else(|| self.constant(1.0));
        self.push(Instruction::Div(num, den))
    }

    /// `v₁ · v₂ · ⋯` left to right; `None` for no factors.
    fn chain(&mut self, values: &[Value]) -> Option<Value> {
        let (&first, rest) = values.split_first()?;
        Some(
            rest.iter()
                .fold(first, |acc, &v| self.push(Instruction::Mul(acc, v))),
        )
    }

    /// The printer's `power` in Rust: `sqrt`, `1/sqrt`, `powi` for integer exponents, else
    /// `powf`.
    fn power(&mut self, base: ExprId, exponent: Exponent) -> Value {
        let b = self.operand(base);
        let constant = match exponent {
            Exponent::Constant(c) => Some(c),
            Exponent::Expr(x) => self.arena.as_constant(x),
        };
        let half = Constant::Rational { num: 1, den: 2 };
        let minus_half = Constant::Rational { num: -1, den: 2 };
        match constant {
            Some(c) if c == half => self.push(Instruction::Sqrt(b)),
            Some(c) if c == minus_half => {
                let root = self.push(Instruction::Sqrt(b));
                let one = self.constant(1.0);
                self.push(Instruction::Div(one, root))
            }
            Some(c)
                if c.as_integer()
                    .is_some_and(|n| n.unsigned_abs() <= i32::MAX as u64) =>
            {
                self.powi(b, c.as_integer().unwrap_or(1) as i32)
            }
            _ => {
                let x = match exponent {
                    Exponent::Constant(c) => self.printed_constant(c),
                    Exponent::Expr(x) => self.operand(x),
                };
                self.push(Instruction::Powf(b, x))
            }
        }
    }

    /// `x.powi(n)` as LLVM expands it (and as `compiler-builtins`' `__powidf2` computes it):
    /// repeated squaring from the lowest bit, the first set bit taken as it is (`1 · x = x`),
    /// and `1/r` for a negative `n`; `x⁰ = 1`.
    fn powi(&mut self, x: Value, n: i32) -> Value {
        let mut bits = n.unsigned_abs();
        let mut result: Option<Value> = None;
        let mut square = x;
        while bits != 0 {
            if bits & 1 == 1 {
                result = Some(match result {
                    None => square,
                    Some(r) => self.push(Instruction::Mul(r, square)),
                });
            }
            bits >>= 1;
            if bits != 0 {
                square = self.push(Instruction::Mul(square, square));
            }
        }
        let result = match result {
            Some(r) => r,
            None => return self.constant(1.0),
        };
        if n < 0 {
            let one = self.constant(1.0);
            self.push(Instruction::Div(one, result))
        } else {
            result
        }
    }
}

#[derive(Clone, Copy)]
enum Exponent {
    Constant(Constant),
    Expr(ExprId),
}
