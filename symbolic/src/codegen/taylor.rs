//! A model's Taylor recurrences ([`TaylorProgram`]) from the tape of `M` and `F` (with
//! constraints, of `[M Jᵀ; J 0]` and `[F; γ]`).
//!
//! The tape of [`ModelFunction::MassMatrixAndForcing`](super::plan::ModelFunction) — the plan
//! both backends compile — numbered ([`Tape::numbered`]: an operation the lowering repeats,
//! such as a pull written in the equations of both bodies it acts on, computed once; the
//! same bits) is read as a program over series: each instruction is a slot, and
//! [`taylor_program`] gives each instruction that depends on the state its recurrence
//! ([`SeriesOp`]). Order 0 is the tape itself, extended by the auxiliary values some
//! recurrences need (the cosine of a lone sine, `tan²`, `√(1 − a²)`, `x² + y²`, the sums of
//! angles whose sine and cosine the tape forms by the addition theorems): those are appended
//! as instructions, so the order-0 values of the tape's own instructions are the right-hand
//! side's to the bit, and both backends evaluate the extended tape as they evaluate any tape.
//! Constant instructions (parameters and numbers only) keep their order 0 alone. Above order
//! 0, a sine and cosine of a sum of angles come from one `sin_cos` of the sum, and an
//! instruction whose value no op, `M` or `F` reads there has no op (its orders `k ≥ 1` are
//! not computed).
//!
//! Source: the decomposition of Biscani & Izzo (2021), heyoka's `taylor_decompose`, with
//! hidden partners (`sin`↔`cos`, `tan`↔`tan²`); the recurrences of Jorba & Zou (2005, §2.1).

use std::borrow::Cow;

use eomgen_description::taylor::{DerivedLists, SeriesOp, Slot, TaylorProgram, TaylorUnsupported};

use crate::expr::Func;

use rustc_hash::{FxHashMap, FxHashSet};

use super::program::{FunctionTape, ModelProgram};
use super::tape::{Input, Instruction, Tape};

/// The Taylor recurrences of a model's `M q̈ = F` (with constraints, `[M Jᵀ; J 0][q̈; λ] =
/// [F; γ]`) and the order-0 tape they extend.
#[derive(Debug, Clone, PartialEq)]
pub struct TaylorPlan {
    /// The recurrences of orders `k ≥ 1` and the slots of the state, `M` and `F`.
    pub program: TaylorProgram,
    /// Order 0: the tape of `M` and `F` numbered ([`Tape::numbered`]: each operation on the
    /// same operands once, the same bits) with the auxiliary instructions appended; slot `s`
    /// is instruction `s`. Its outputs are those of the numbered tape of `M` and `F`.
    pub order_zero: Tape,
}

/// Builds the Taylor recurrences of the tape of `M` (column-major, `n × n`) and `F` (`n`), the
/// run-time compiler's [`ModelProgram::mass_matrix_and_forcing`](super::program::ModelProgram),
/// or, with `multipliers = m > 0` constraints, of `[M Jᵀ; J 0]` (column-major,
/// `(n + m) × (n + m)`) and `[F; γ]` ([`super::program::constrained_motion_tape`]).
///
/// # Errors
/// [`TaylorUnsupported::Functions`] naming each function without a recurrence (`abs`, `sign`,
/// `step`, `pow` with a variable exponent) that the equations apply to the state or time (of
/// parameters alone they are constants, computed once at order 0).
pub fn taylor_program(
    tape: &FunctionTape,
    n: usize,
    multipliers: usize,
) -> Result<TaylorPlan, TaylorUnsupported> {
    let k = n + multipliers;
    // Each value a series: a repeated operation would cost a convolution per order.
    let numbered = tape.tape.numbered();
    let mut builder = Builder::new(&numbered);
    builder.build();
    if !builder.unsupported.is_empty() {
        return Err(TaylorUnsupported::Functions {
            names: Cow::Owned(builder.unsupported.into_iter().map(Cow::Owned).collect()),
        });
    }
    let outputs = &numbered.outputs;
    let (mass, forcing) = outputs.split_at((k * k).min(outputs.len()));
    let Builder {
        order_zero,
        constant,
        mut ops,
        zeroed,
        coordinates,
        velocities,
        time,
        ..
    } = builder;
    // Constants read as whole series are zeroed above order 0 before anything reads them.
    let zero_ops: Vec<SeriesOp> = zeroed
        .into_iter()
        .map(|out| SeriesOp::Zero { out })
        .collect();
    ops.splice(0..0, zero_ops);
    let program = TaylorProgram {
        slots: order_zero.instructions.len(),
        coordinates: Cow::Owned(fit(coordinates, n)),
        velocities: Cow::Owned(fit(velocities, n)),
        time,
        mass_matrix: Cow::Owned(mass.to_vec()),
        forcing: Cow::Owned(forcing.to_vec()),
        constant: Cow::Owned(constant),
        ops: Cow::Owned(ops),
        derived: DerivedLists::default(),
    }
    .with_derived();
    Ok(TaylorPlan {
        program,
        order_zero,
    })
}

/// A run-time model's Taylor recurrences: [`taylor_program`] of
/// [`ModelProgram::taylor_tape`], with the constraints' multipliers when it has any.
///
/// # Errors
/// As [`taylor_program`].
pub fn model_taylor_plan(program: &ModelProgram) -> Result<TaylorPlan, TaylorUnsupported> {
    if program.description.has_speeds() {
        return Err(TaylorUnsupported::Speeds);
    }
    taylor_program(
        &program.taylor_tape(),
        program.num_dofs(),
        program.description.constraints.len(),
    )
}

/// `slots` padded or cut to `n` entries.
fn fit(mut slots: Vec<Option<Slot>>, n: usize) -> Vec<Option<Slot>> {
    slots.resize(n, None);
    slots
}

struct Builder<'a> {
    tape: &'a Tape,
    order_zero: Tape,
    constant: Vec<bool>,
    ops: Vec<SeriesOp>,
    zeroed: Vec<Slot>,
    coordinates: Vec<Option<Slot>>,
    velocities: Vec<Option<Slot>>,
    time: Option<Slot>,
    unsupported: Vec<String>,
}

impl<'a> Builder<'a> {
    fn new(tape: &'a Tape) -> Self {
        Self {
            tape,
            order_zero: tape.clone(),
            constant: Vec::with_capacity(tape.instructions.len()),
            ops: Vec::new(),
            zeroed: Vec::new(),
            coordinates: Vec::new(),
            velocities: Vec::new(),
            time: None,
            unsupported: Vec::new(),
        }
    }

    fn is_constant(&self, v: Slot) -> bool {
        self.constant[v as usize]
    }

    /// Appends an auxiliary instruction to the order-0 tape; its slot.
    fn aux(&mut self, instruction: Instruction, constant: bool) -> Slot {
        let slot = self.order_zero.instructions.len() as Slot;
        self.order_zero.instructions.push(instruction);
        self.constant.push(constant);
        slot
    }

    /// Records instruction `k` as the slot of input `i` of `list` (refusing an input read
    /// twice).
    fn input(&mut self, k: usize, list: fn(&mut Self) -> &mut Vec<Option<Slot>>, i: usize) {
        let slots = list(self);
        if slots.len() <= i {
            slots.resize(i + 1, None);
        }
        match slots[i] {
            // The tapes bind each symbol once; an input read twice would need its order 0
            // copied too, so it is refused rather than half supported.
            Some(_) => self.refuse("an input read twice"),
            None => slots[i] = Some(k as Slot),
        }
    }

    fn refuse(&mut self, name: &str) {
        if !self.unsupported.iter().any(|n| n == name) {
            self.unsupported.push(name.to_string());
        }
    }

    /// A constant read as a whole series: zeroed above order 0.
    fn as_series(&mut self, v: Slot) -> Slot {
        if self.is_constant(v) && !self.zeroed.contains(&v) {
            self.zeroed.push(v);
        }
        v
    }

    fn build(&mut self) {
        let count = self.tape.instructions.len();
        // The flags of the tape's own instructions come first: auxiliary slots are appended
        // after them, so `constant[k]` is instruction `k`'s.
        for k in 0..count {
            let constant = match self.tape.instructions[k] {
                Instruction::Input(input) => match input {
                    Input::Parameter(_) => true,
                    Input::Coordinate(i) => {
                        self.input(k, |b| &mut b.coordinates, i as usize);
                        false
                    }
                    Input::Velocity(i) => {
                        self.input(k, |b| &mut b.velocities, i as usize);
                        false
                    }
                    Input::Time => {
                        match self.time {
                            Some(_) => self.refuse("an input read twice"),
                            None => self.time = Some(k as Slot),
                        }
                        false
                    }
                    Input::Acceleration(_) | Input::Multiplier(_) => {
                        self.refuse("an acceleration or multiplier input");
                        false
                    }
                },
                Instruction::Const(_) => true,
                instruction => operands(instruction)
                    .iter()
                    .all(|&v| self.constant[v as usize]),
            };
            self.constant.push(constant);
        }
        let pairs = self.angle_sum_pairs();
        let mut emitted = FxHashMap::default();
        let mut angles = FxHashMap::default();
        for k in 0..count {
            if self.constant[k] {
                continue;
            }
            let out = k as Slot;
            if let Some((sin, cos, angle)) = pairs.get(&out) {
                // The pair's op goes where the first of the two is, before any reader.
                if emitted.insert((*sin, *cos), ()).is_none() {
                    let a = self.angle_slot(angle, &mut angles);
                    self.ops.push(SeriesOp::SinCos {
                        sin: *sin,
                        cos: *cos,
                        a,
                    });
                }
                continue;
            }
            let instruction = self.tape.instructions[k];
            if let Some(op) = self.op(out, instruction) {
                self.ops.push(op);
            }
        }
        self.ops = live_ops(std::mem::take(&mut self.ops), self.tape);
    }

    /// The sines and cosines of sums of angles that the tape forms by the addition theorems
    /// ([`crate::expr::trig::expand_angle_sums`]: `sin a cos b − cos a sin b` and
    /// `cos a cos b + sin a sin b` from the angles' own sines and cosines), found in pairs of
    /// a sine and a cosine of the same sum: each slot of a pair mapped to `(sin, cos,
    /// angle)`, the angle as its terms `(negated, slot)` in the sine's sign.
    ///
    /// Such a pair costs four products of series and two sums per order as the tape forms
    /// it, one `sin_cos` recurrence (two sums of products) and the angle's difference as a
    /// series: the pair's order-0 values stay the tape's (no `sin_cos` call is added), its
    /// higher orders come from the recurrence of `sin_cos` of the angle, and the products
    /// no other op reads are dropped ([`live_ops`]). Sums of sums (chains of three or more
    /// angles) are found level by level.
    fn angle_sum_pairs(&self) -> FxHashMap<Slot, (Slot, Slot, Angle)> {
        // The pairs by their angle's key, and each paired slot as a sine or cosine (what the
        // next level reads): both only grow, a round at a time, until a round adds none.
        let mut pairs: FxHashMap<Angle, (Slot, Slot, Angle)> = FxHashMap::default();
        let mut found: FxHashMap<Slot, (bool, Angle)> = FxHashMap::default();
        loop {
            let mut sines: FxHashMap<Angle, (Slot, Angle)> = FxHashMap::default();
            let mut cosines: FxHashMap<Angle, Slot> = FxHashMap::default();
            for k in 0..self.tape.instructions.len() {
                let slot = k as Slot;
                if self.constant[k] || found.contains_key(&slot) {
                    continue;
                }
                let Some((cos, angle)) = self.angle_sum(slot, &found) else {
                    continue;
                };
                let key = canonical(&angle);
                if pairs.contains_key(&key) {
                    continue;
                }
                if cos {
                    cosines.entry(key).or_insert(slot);
                } else if angle.iter().any(|&(negated, _)| !negated) {
                    sines.entry(key).or_insert((slot, angle));
                }
            }
            let before = pairs.len();
            for (key, (sin, angle)) in sines {
                if let Some(&cos) = cosines.get(&key) {
                    found.insert(sin, (false, angle.clone()));
                    found.insert(cos, (true, angle.clone()));
                    pairs.insert(key, (sin, cos, angle));
                }
            }
            if pairs.len() == before {
                break;
            }
        }
        let mut by_slot = FxHashMap::default();
        for (sin, cos, angle) in pairs.into_values() {
            by_slot.insert(sin, (sin, cos, angle.clone()));
            by_slot.insert(cos, (sin, cos, angle));
        }
        by_slot
    }

    /// The value of `slot` as `±sin` or `±cos` of an angle: `(negated, cos, angle)`, from
    /// the tape's sines and cosines, their negations and the sums already `found`.
    fn trig(
        &self,
        slot: Slot,
        found: &FxHashMap<Slot, (bool, Angle)>,
    ) -> Option<(bool, bool, Angle)> {
        if self.constant[slot as usize] {
            return None;
        }
        let single = |a: Slot| vec![(false, a)];
        match self.tape.instructions[slot as usize] {
            Instruction::SinCos(a) | Instruction::Call(Func::Sin, a) => {
                Some((false, false, single(a)))
            }
            Instruction::Call(Func::Cos, a) => Some((false, true, single(a))),
            Instruction::CosOfSinCos(s) => match self.tape.instructions[s as usize] {
                Instruction::SinCos(a) => Some((false, true, single(a))),
                _ => None,
            },
            Instruction::Neg(x) => self.trig(x, found).map(|(n, c, a)| (!n, c, a)),
            _ => found
                .get(&slot)
                .map(|(cos, angle)| (false, *cos, angle.clone())),
        }
    }

    /// `slot` as `±` a product of two sines or cosines: `(negated, first, second)`, each
    /// factor `(cos, angle)`.
    fn trig_product(
        &self,
        slot: Slot,
        found: &FxHashMap<Slot, (bool, Angle)>,
    ) -> Option<(bool, Factor, Factor)> {
        match self.tape.instructions[slot as usize] {
            Instruction::Mul(x, y) => {
                let (nx, cx, ax) = self.trig(x, found)?;
                let (ny, cy, ay) = self.trig(y, found)?;
                Some((nx != ny, (cx, ax), (cy, ay)))
            }
            Instruction::Neg(x) => self.trig_product(x, found).map(|(n, f, g)| (!n, f, g)),
            _ => None,
        }
    }

    /// `slot` as the sine (`false`) or cosine (`true`) of a sum of angles by the addition
    /// theorems, with the sum's terms.
    fn angle_sum(
        &self,
        slot: Slot,
        found: &FxHashMap<Slot, (bool, Angle)>,
    ) -> Option<(bool, Angle)> {
        let (p, q, q_negated) = match self.tape.instructions[slot as usize] {
            Instruction::Add(p, q) => (p, q, false),
            Instruction::Sub(p, q) => (p, q, true),
            _ => return None,
        };
        let (np, p1, p2) = self.trig_product(p, found)?;
        let (nq, q1, q2) = self.trig_product(q, found)?;
        let nq = nq != q_negated;
        // The product `f(α) g(β)` with `f` of `first` and `g` of `second`, in either order.
        let split = |f: bool, g: bool, x: &Factor, y: &Factor| {
            if x.0 == f && y.0 == g {
                Some((x.1.clone(), y.1.clone()))
            } else if y.0 == f && x.0 == g {
                Some((y.1.clone(), x.1.clone()))
            } else {
                None
            }
        };
        let same = |x: &(Angle, Angle), y: &(Angle, Angle)| x.0 == y.0 && x.1 == y.1;
        // ±sin α cos β ± cos α sin β.
        if let (Some(sc), Some(cs)) = (split(false, true, &p1, &p2), split(true, false, &q1, &q2))
            && same(&sc, &cs)
        {
            let (alpha, beta) = sc;
            return match (np, nq) {
                (false, false) => Some((false, sum(&alpha, &beta, false))),
                (false, true) => Some((false, sum(&alpha, &beta, true))),
                (true, false) => Some((false, sum(&beta, &alpha, true))),
                (true, true) => None,
            };
        }
        // cos α cos β ± sin α sin β (either product first).
        for ((nc, c1, c2), (ns, s1, s2)) in [
            ((np, &p1, &p2), (nq, &q1, &q2)),
            ((nq, &q1, &q2), (np, &p1, &p2)),
        ] {
            if let (Some(cc), Some(ss)) = (split(true, true, c1, c2), split(false, false, s1, s2))
                && (same(&cc, &ss) || (cc.0 == ss.1 && cc.1 == ss.0))
            {
                let (alpha, beta) = cc;
                return match (nc, ns) {
                    (false, true) => Some((true, sum(&alpha, &beta, false))),
                    (false, false) => Some((true, sum(&alpha, &beta, true))),
                    _ => None,
                };
            }
        }
        None
    }

    /// The slot of an angle's sum as a series, appended once per angle: its first term that
    /// is not negated, then the others added or subtracted.
    fn angle_slot(&mut self, angle: &Angle, memo: &mut FxHashMap<Angle, Slot>) -> Slot {
        if let Some(&slot) = memo.get(angle) {
            return slot;
        }
        // The first term that is not negated starts the sum (the pairs found have one); with
        // none, the first term's negation.
        let first = angle.iter().position(|&(negated, _)| !negated);
        let mut slot = match first {
            Some(i) => angle[i].1,
            None => {
                let x = angle[0].1;
                let out = self.aux(Instruction::Neg(x), false);
                self.ops.push(SeriesOp::Neg { out, a: x });
                out
            }
        };
        let start = first.unwrap_or(0);
        for (i, &(negated, x)) in angle.iter().enumerate() {
            if i == start {
                continue;
            }
            let out = if negated {
                self.aux(Instruction::Sub(slot, x), false)
            } else {
                self.aux(Instruction::Add(slot, x), false)
            };
            self.ops.push(if negated {
                SeriesOp::Sub { out, a: slot, b: x }
            } else {
                SeriesOp::Add { out, a: slot, b: x }
            });
            slot = out;
        }
        memo.insert(angle.clone(), slot);
        slot
    }

    /// `z` when slot `v` is the tape's `−z` of a series `z`.
    fn negation_of(&self, v: Slot) -> Option<Slot> {
        match self.tape.instructions.get(v as usize) {
            Some(&Instruction::Neg(z)) if !self.is_constant(z) => Some(z),
            _ => None,
        }
    }

    /// The recurrence of the non-constant instruction `out`.
    // Long: one arm per instruction, each the recurrence it becomes; the match is the table from
    // instructions to series ops.
    fn op(&mut self, out: Slot, instruction: Instruction) -> Option<SeriesOp> {
        let c = |b: &Self, v: Slot| b.is_constant(v);
        // A negation read by a sum is folded into it: `a + (−z)` is `a − z`, `(−z) + b` is
        // `b − z`, `a − (−z)` is `a + z` and `−(−z)` is `z`, each to the bit for every value
        // but a NaN's sign (IEEE 754 defines `x − y` as `x + (−y)`, and addition commutes; a
        // NaN stays a NaN, and a series that is not finite stops the step), one op per order fewer (the
        // figure eight's differences of positions are written `x₂ + (−x₁)`); the
        // negation's own op goes if nothing else reads it ([`live_ops`]).
        Some(match instruction {
            Instruction::Input(_) | Instruction::Const(_) => return None,
            Instruction::Neg(a) => match self.negation_of(a) {
                Some(z) => SeriesOp::Copy { out, a: z },
                None => SeriesOp::Neg { out, a },
            },
            Instruction::Add(a, b) => match (c(self, a), c(self, b)) {
                (false, false) => match (self.negation_of(a), self.negation_of(b)) {
                    (_, Some(z)) => SeriesOp::Sub { out, a, b: z },
                    (Some(z), None) => SeriesOp::Sub { out, a: b, b: z },
                    (None, None) => SeriesOp::Add { out, a, b },
                },
                (false, true) => SeriesOp::Copy { out, a },
                _ => SeriesOp::Copy { out, a: b },
            },
            Instruction::Sub(a, b) => match (c(self, a), c(self, b)) {
                (false, false) => match self.negation_of(b) {
                    Some(z) => SeriesOp::Add { out, a, b: z },
                    None => SeriesOp::Sub { out, a, b },
                },
                (false, true) => SeriesOp::Copy { out, a },
                _ => SeriesOp::Neg { out, a: b },
            },
            Instruction::Mul(a, b) => match (c(self, a), c(self, b)) {
                (false, false) => SeriesOp::Mul { out, a, b },
                (false, true) => SeriesOp::Scale {
                    out,
                    a,
                    constant: b,
                },
                _ => SeriesOp::Scale {
                    out,
                    a: b,
                    constant: a,
                },
            },
            Instruction::Div(a, b) => match (c(self, a), c(self, b)) {
                (false, false) => SeriesOp::Div { out, a, b },
                (false, true) => SeriesOp::DivByConstant {
                    out,
                    a,
                    constant: b,
                },
                _ => SeriesOp::ConstantDiv { out, b },
            },
            Instruction::Sqrt(a) => SeriesOp::Sqrt { out, a },
            Instruction::Abs(_) => {
                self.refuse("abs");
                return None;
            }
            Instruction::Powf(a, b) => {
                if c(self, b) {
                    SeriesOp::PowConstant {
                        out,
                        a,
                        exponent: b,
                    }
                } else {
                    self.refuse("pow (a variable exponent)");
                    return None;
                }
            }
            Instruction::Atan2(y, x) => {
                let (y, x) = (self.as_series(y), self.as_series(x));
                let xx = self.aux(Instruction::Mul(x, x), false);
                let yy = self.aux(Instruction::Mul(y, y), false);
                let norm = self.aux(Instruction::Add(xx, yy), false);
                SeriesOp::Atan2 { out, y, x, norm }
            }
            Instruction::SinCos(a) => SeriesOp::SinCos {
                sin: out,
                cos: out + 1,
                a,
            },
            Instruction::CosOfSinCos(_) => return None,
            Instruction::Call(f, a) => match f {
                Func::Sin => {
                    let cos = self.aux(Instruction::Call(Func::Cos, a), false);
                    SeriesOp::SinCos { sin: out, cos, a }
                }
                Func::Cos => {
                    let sin = self.aux(Instruction::Call(Func::Sin, a), false);
                    SeriesOp::SinCos { sin, cos: out, a }
                }
                Func::Sinh => {
                    let cosh = self.aux(Instruction::Call(Func::Cosh, a), false);
                    SeriesOp::SinhCosh { sinh: out, cosh, a }
                }
                Func::Cosh => {
                    let sinh = self.aux(Instruction::Call(Func::Sinh, a), false);
                    SeriesOp::SinhCosh { sinh, cosh: out, a }
                }
                Func::Tan => {
                    let square = self.aux(Instruction::Mul(out, out), false);
                    SeriesOp::Tan { out, a, square }
                }
                Func::Tanh => {
                    let square = self.aux(Instruction::Mul(out, out), false);
                    SeriesOp::Tanh { out, a, square }
                }
                Func::Asin | Func::Acos => {
                    let square = self.aux(Instruction::Mul(a, a), false);
                    let one = self.aux(Instruction::Const(1.0), true);
                    let difference = self.aux(Instruction::Sub(one, square), false);
                    let root = self.aux(Instruction::Sqrt(difference), false);
                    SeriesOp::Asin {
                        out,
                        a,
                        root,
                        acos: f == Func::Acos,
                    }
                }
                Func::Atan => {
                    let square = self.aux(Instruction::Mul(a, a), false);
                    SeriesOp::Atan { out, a, square }
                }
                Func::Exp => SeriesOp::Exp { out, a },
                Func::Ln => SeriesOp::Ln { out, a },
                Func::Abs | Func::Sign | Func::Step => {
                    self.refuse(f.name());
                    return None;
                }
            },
        })
    }
}

/// A sum of angles `Σ ±xᵢ`: its terms `(negated, slot)`, sorted.
type Angle = Vec<(bool, Slot)>;

/// A sine (`false`) or cosine (`true`) of an angle.
type Factor = (bool, Angle);

/// `α + β`, or `α − β` if `minus`, sorted.
fn sum(alpha: &Angle, beta: &Angle, minus: bool) -> Angle {
    let mut terms: Angle = alpha
        .iter()
        .copied()
        .chain(beta.iter().map(|&(negated, x)| (negated != minus, x)))
        .collect();
    terms.sort_unstable_by_key(|&(negated, x)| (x, negated));
    terms
}

/// The key an angle and its negation share (a cosine is even, and a sine is matched with
/// the cosine of its own angle or of the negation).
fn canonical(angle: &Angle) -> Angle {
    let mut negation: Angle = angle.iter().map(|&(negated, x)| (!negated, x)).collect();
    negation.sort_unstable_by_key(|&(negated, x)| (x, negated));
    let mut own = angle.clone();
    own.sort_unstable_by_key(|&(negated, x)| (x, negated));
    own.min(negation)
}

/// `ops` without those whose results no op reads at orders `k ≥ 1` and that are not `M`'s
/// or `F`'s (the products of the addition theorems replaced by a `sin_cos`), in order. Only
/// ops whose slots are all outputs or inputs are dropped (one or two outputs, each written
/// by that op alone); the others are kept, every slot of theirs read.
fn live_ops(ops: Vec<SeriesOp>, tape: &Tape) -> Vec<SeriesOp> {
    let mut read: FxHashSet<Slot> = tape.outputs.iter().copied().collect();
    let mut keep = vec![true; ops.len()];
    for (i, op) in ops.iter().enumerate().rev() {
        let (outputs, inputs): (Vec<Slot>, Vec<Slot>) = match *op {
            SeriesOp::Neg { out, a }
            | SeriesOp::Copy { out, a }
            | SeriesOp::Sqrt { out, a }
            | SeriesOp::Exp { out, a }
            | SeriesOp::Ln { out, a }
            | SeriesOp::Scale { out, a, .. }
            | SeriesOp::DivByConstant { out, a, .. }
            | SeriesOp::PowConstant { out, a, .. } => (vec![out], vec![a]),
            SeriesOp::Add { out, a, b }
            | SeriesOp::Sub { out, a, b }
            | SeriesOp::Mul { out, a, b }
            | SeriesOp::Div { out, a, b } => (vec![out], vec![a, b]),
            SeriesOp::ConstantDiv { out, b } => (vec![out], vec![b]),
            SeriesOp::SinCos { sin, cos, a } => (vec![sin, cos], vec![a]),
            SeriesOp::SinhCosh { sinh, cosh, a } => (vec![sinh, cosh], vec![a]),
            // Kept, every slot read.
            SeriesOp::Tan { out, a, square } | SeriesOp::Tanh { out, a, square } => {
                (vec![], vec![out, a, square])
            }
            SeriesOp::Asin { out, a, root, .. } => (vec![], vec![out, a, root]),
            SeriesOp::Atan { out, a, square } => (vec![], vec![out, a, square]),
            SeriesOp::Atan2 { out, y, x, norm } => (vec![], vec![out, y, x, norm]),
            SeriesOp::Zero { out } => (vec![], vec![out]),
        };
        if !outputs.is_empty() && !outputs.iter().any(|s| read.contains(s)) {
            keep[i] = false;
            continue;
        }
        read.extend(inputs);
    }
    ops.into_iter()
        .zip(keep)
        .filter_map(|(op, keep)| keep.then_some(op))
        .collect()
}

/// The operands of an instruction.
fn operands(instruction: Instruction) -> Vec<Slot> {
    match instruction {
        Instruction::Input(_) | Instruction::Const(_) => vec![],
        Instruction::Neg(x)
        | Instruction::Sqrt(x)
        | Instruction::Abs(x)
        | Instruction::Call(_, x)
        | Instruction::SinCos(x)
        | Instruction::CosOfSinCos(x) => vec![x],
        Instruction::Add(x, y)
        | Instruction::Sub(x, y)
        | Instruction::Mul(x, y)
        | Instruction::Div(x, y)
        | Instruction::Powf(x, y)
        | Instruction::Atan2(x, y) => vec![x, y],
    }
}
