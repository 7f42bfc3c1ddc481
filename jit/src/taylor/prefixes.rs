//! The terms of each sum that read only the orders below `k`, added before the order's ops (see the
//! parent module's documentation): the partial sums that the kernels continue.

use super::*;

impl Emitter<'_> {
    /// Starts an order: nothing known, and the bases of [`Self::prefixes`]'
    /// loads: the series' and the scratch's addresses plus a constant, so that Cranelift,
    /// for which both loads are pure, does not merge a load of a partial sum's terms with the
    /// ops' load of the same coefficient (one value used in both places would keep a register
    /// from the top of the function to the op).
    pub(super) fn begin_order(&mut self, b: &mut FunctionBuilder) {
        self.known.clear();
        self.prefixes.clear();
        self.prefix_base = b.ins().iadd_imm_s(self.series, PREFIX_BIAS as i64);
        self.prefix_scratch = b.ins().iadd_imm_s(self.scratch, PREFIX_BIAS as i64);
    }

    /// Adds, before the order's ops, the terms of each of their sums that read only orders
    /// below `k` (the terms each kernel adds first), and keeps each partial sum in a stack
    /// slot where the op continues it: the same operations in the same order, but the long
    /// chains of additions start at the top of the function, where they overlap with each
    /// other instead of waiting behind the ops whose order `k` they do not need.
    pub(super) fn prefixes(&mut self, b: &mut FunctionBuilder, program: &TaylorProgram, k: usize) {
        let mut all: Vec<Sum> = Vec::new();
        for unit in self.layout.pairing.units.iter() {
            let (Unit::Single(op) | Unit::Pair { op, .. }) = unit;
            for sum in self.sums(op) {
                if !all.contains(&sum) {
                    all.push(sum);
                }
            }
        }
        // The solve's sums, which only the in-line solves continue (a constrained program
        // has none: the runtime's solve forms its own).
        if program.multipliers() == 0 {
            for e in 0..program.derived.varying_mass_entries.len() {
                all.push(Sum::Mass(e));
            }
        }
        for sums in all.chunks(INTERLEAVED_SUMS) {
            self.prefix_group(b, program, sums, k);
        }
    }

    /// The sums of `op`'s kernel that [`Self::prefixes`] starts.
    fn sums(&self, op: &SeriesOp) -> Vec<Sum> {
        let products = |x: Slot, y: Slot, weighted: bool| Sum::Products { x, y, weighted };
        match *op {
            SeriesOp::Mul { a, b: y, .. } if a == y => vec![Sum::Square { x: a }],
            SeriesOp::Mul { a, b: y, .. } => vec![products(a, y, false)],
            SeriesOp::Div { out, b: y, .. } | SeriesOp::ConstantDiv { out, b: y } => {
                vec![products(y, out, false)]
            }
            SeriesOp::Sqrt { out, .. } => vec![products(out, out, false)],
            SeriesOp::PowConstant { out, a, exponent } => {
                vec![Sum::Power { out, a, exponent }]
            }
            SeriesOp::Exp { out, a } => vec![products(a, out, true)],
            SeriesOp::Ln { out, a } => vec![products(out, a, true)],
            SeriesOp::SinCos { sin, .. } | SeriesOp::SinhCosh { sinh: sin, .. } => {
                vec![Sum::Pair(self.pair_of(sin))]
            }
            SeriesOp::Tan { out, a, square } | SeriesOp::Tanh { out, a, square } => {
                vec![products(a, square, true), products(out, out, false)]
            }
            SeriesOp::Asin { out, a, root, .. } => vec![
                products(a, a, false),
                products(root, root, false),
                products(out, root, true),
            ],
            SeriesOp::Atan { out, a, square } => {
                vec![products(a, a, false), products(out, square, true)]
            }
            SeriesOp::Atan2 { out, y, x, norm } => vec![
                products(x, x, false),
                products(y, y, false),
                products(y, x, true),
                products(x, y, true),
                products(out, norm, true),
            ],
            _ => vec![],
        }
    }

    /// Whether `sum` belongs to a paired op (its terms are vectors, written at width 2).
    fn paired_sum(&self, sum: &Sum) -> bool {
        let lane = |slot: &Slot| self.lane(*slot).is_some();
        match sum {
            Sum::Products { x, y, .. } => lane(x) || lane(y),
            Sum::Square { x } => lane(x),
            Sum::Power { out, .. } => lane(out),
            Sum::Pair(_) | Sum::Mass(_) => false,
        }
    }

    /// Order `i` of `slot` through the prefix bases (see [`Self::prefixes`]): a lane slot's
    /// vector, or a slot's value (in both lanes while a paired op's sum is written).
    fn older(&self, b: &mut FunctionBuilder, slot: Slot, i: usize) -> ir::Value {
        if self.lane(slot).is_some() {
            let offset = self.layout.lane_offset(slot, i) - PREFIX_BIAS;
            return b
                .ins()
                .load(types::F64X2, settled(), self.prefix_scratch, offset);
        }
        let offset = ((slot as usize * UNROLLED_CAPACITY + i) * 8) as i32 - PREFIX_BIAS;
        let v = b
            .ins()
            .load(types::F64, settled(), self.prefix_base, offset);
        if self.width == 2 {
            b.ins().splat(types::F64X2, v)
        } else {
            v
        }
    }

    /// Term `t` (in the order of addition) of `sum`'s terms of orders below `k`, read through
    /// the prefix base (see [`Self::prefixes`]).
    pub(super) fn prefix_term(
        &self,
        b: &mut FunctionBuilder,
        program: &TaylorProgram,
        sum: Sum,
        (k, t): (usize, usize),
    ) -> ir::Value {
        let flags = settled();
        let older = |b: &mut FunctionBuilder, slot: Slot, i: usize| self.older(b, slot, i);
        match sum {
            Sum::Products { x, y, weighted } => {
                let j = t + 1;
                let (u, v) = (older(b, x, j), older(b, y, k - j));
                self.product_term(b, (u, v), j, weighted)
            }
            Sum::Square { x } => {
                let j = t + 1;
                let (u, v) = (older(b, x, j), older(b, x, k - j));
                b.ins().fmul(u, v)
            }
            Sum::Pair(p) => {
                let j = t + 1;
                let w = b.ins().load(
                    types::F64X2,
                    flags,
                    self.prefix_scratch,
                    PairScratch::weighted(p, j) - PREFIX_BIAS,
                );
                let pair = b.ins().load(
                    types::F64X2,
                    flags,
                    self.prefix_scratch,
                    PairScratch::pair(p, k - j) - PREFIX_BIAS,
                );
                b.ins().fmul(w, pair)
            }
            Sum::Power { out, a, exponent } => {
                let j = k - 1 - t;
                let alpha = older(b, exponent, 0);
                let (xv, ov) = (older(b, a, k - j), older(b, out, j));
                self.power_term(b, (alpha, exponent, k, j), xv, ov)
            }
            Sum::Mass(e) => {
                let (_, l, slot) = program.derived.varying_mass_entries[e];
                let accelerations = program.acceleration_slot();
                let j = t;
                let m = older(b, slot, 1 + j);
                let a = older(b, accelerations + l, k - 1 - j);
                b.ins().fmul(m, a)
            }
        }
    }

    /// Writes the terms of orders below `k` of each of `sums` (`k − 1`, a square's
    /// `⌊(k − 1)/2⌋`) ([`INTERLEAVED_SUMS`] or
    /// fewer), term `t` of every sum before term `t + 1` of any, each partial sum into a stack
    /// slot of its own.
    pub(super) fn prefix_group(
        &mut self,
        b: &mut FunctionBuilder,
        program: &TaylorProgram,
        sums: &[Sum],
        k: usize,
    ) {
        let zero = b.ins().f64const(0.0);
        let wide = |s: &Sum| matches!(s, Sum::Pair(_)) || self.paired_sum(s);
        let mut totals: Vec<ir::Value> = sums
            .iter()
            .map(|s| {
                if wide(s) {
                    b.ins().splat(types::F64X2, zero)
                } else {
                    zero
                }
            })
            .collect();
        // A square's half sum has ⌊(k − 1)/2⌋ terms, every other sum k − 1.
        let terms = |sum: &Sum| match sum {
            Sum::Square { .. } => (k - 1) / 2,
            _ => k - 1,
        };
        for t in 0..k - 1 {
            for (i, &sum) in sums.iter().enumerate() {
                if t < terms(&sum) {
                    self.width = if self.paired_sum(&sum) { 2 } else { 1 };
                    let term = self.prefix_term(b, program, sum, (k, t));
                    self.width = 1;
                    totals[i] = b.ins().fadd(totals[i], term);
                }
            }
        }
        for (&sum, &value) in sums.iter().zip(&totals) {
            let size = if b.func.dfg.value_type(value) == types::F64X2 {
                16
            } else {
                8
            };
            let slot = b.create_sized_stack_slot(ir::StackSlotData::new(
                ir::StackSlotKind::ExplicitSlot,
                size,
                4,
            ));
            let pointer = b.func.dfg.value_type(self.series);
            b.ins().stack_store(pointer, value, slot, 0);
            self.prefixes.insert(sum, slot);
        }
    }

    /// The partial sum [`Self::prefixes`] kept for `sum`, if any.
    pub(super) fn started(
        &self,
        b: &mut FunctionBuilder,
        sum: Sum,
        ty: ir::Type,
    ) -> Option<ir::Value> {
        let slot = *self.prefixes.get(&sum)?;
        let pointer = b.func.dfg.value_type(self.series);
        Some(b.ins().stack_load(pointer, ty, slot, 0))
    }
}
