//! The kernels of `eomgen_runtime::taylor` as Cranelift code, one op's order `k` at a time, and the
//! order's solve of `M a = F`: the same operations in the same order as the runtime's, so the same
//! bits.

use super::*;

impl Emitter<'_> {
    /// The index among the pair ops, in the program's order, of the sine–cosine or
    /// sinh–cosh op writing `sin` (see [`PairScratch`]).
    pub(super) fn pair_of(&self, sin: Slot) -> usize {
        self.layout.pair_ops[&sin]
    }

    /// The type of the values written: `f64`, or two in a vector while a paired op is
    /// written.
    pub(super) fn ty(&self) -> ir::Type {
        if self.width == 2 {
            types::F64X2
        } else {
            types::F64
        }
    }

    /// The lane slot `slot` (see [`pairing`]), if it is one.
    pub(super) fn lane(&self, slot: Slot) -> Option<LaneSlot> {
        self.layout.pairing.lane(slot).copied()
    }

    /// Order `k` of paired op `op` (over lane slots): the lane slots `gathered` first (those
    /// of its operands that no paired op writes, [`Unit::Pair`]), if this order has not yet,
    /// then its kernel over vectors.
    pub(super) fn paired(
        &mut self,
        b: &mut FunctionBuilder,
        op: SeriesOp,
        gathered: [Option<Slot>; 2],
        k: usize,
    ) {
        for slot in gathered.into_iter().flatten() {
            if !self.known.contains_key(&(slot, k)) {
                self.gather(b, slot, k);
            }
        }
        self.width = 2;
        self.op(b, op, k);
        self.width = 1;
    }

    /// Order `i` of lane slot `slot` from its two slots, into the scratch if it is read there
    /// ([`LaneSlot::history`], or order 0 of one read as a constant).
    pub(super) fn gather(&mut self, b: &mut FunctionBuilder, slot: Slot, i: usize) {
        let Some(lane) = self.lane(slot) else { return };
        let width = std::mem::replace(&mut self.width, 1);
        let (x, y) = (self.at(b, lane.slots.0, i), self.at(b, lane.slots.1, i));
        self.width = width;
        let v = b.ins().splat(types::F64X2, x);
        let v = if lane.slots.0 == lane.slots.1 {
            v
        } else {
            b.ins().insertlane(v, y, 1)
        };
        if lane.history || (i == 0 && lane.constant) {
            let offset = self.layout.lane_offset(slot, i);
            b.ins()
                .store(MemFlagsData::trusted(), v, self.scratch, offset);
        }
        self.known.insert((slot, i), v);
    }

    /// `motion_order`'s solve of order `k` with `factor` (`dense_order`, or `sparse_order`,
    /// then `next_order`), the same operations in the same order: `b = F^[k]`, minus each
    /// varying entry's sum `Σⱼ₌₁ᵏ M_il^[j] a_l^[k−j]` (increasing `j`, from `0.0`), `L z = b`,
    /// `z ← D⁻¹ z`, `Lᵀ x = z` (each update by a zero entry of `L` skipped for
    /// [`Factor::Small`], as `sparse_order` visits only the non-zero ones; a diagonal factor:
    /// `x = D⁻¹ b` alone, as `sparse_order` over no non-zero entries); then `a^[k] = x` into the series, `q^[k+1] = q̇^[k]/(k+1)` and
    /// `q̇^[k+1] = x/(k+1)` into `out` (`2n` per order) and the inputs' and time's order
    /// `k + 1` into the series.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn dense_solve(
        &mut self,
        b: &mut FunctionBuilder,
        program: &TaylorProgram,
        (n, k): (usize, usize),
        out: ir::Value,
        factor: Factor,
        (lower, inverse_pivots): (ir::Value, ir::Value),
    ) {
        let flags = MemFlagsData::trusted();
        let accelerations = program.acceleration_slot();
        let mut x: Vec<ir::Value> = program
            .forcing
            .iter()
            .map(|&slot| self.at(b, slot, k))
            .collect();
        if k > 0 {
            for (e, &(i, l, slot)) in program.derived.varying_mass_entries.iter().enumerate() {
                let (mut sum, from) = match self.started(b, Sum::Mass(e), types::F64) {
                    Some(sum) => (sum, k - 1),
                    None => (self.constant(b, 0.0), 0),
                };
                for j in from..k {
                    let m = self.at(b, slot, 1 + j);
                    let a = self.at(b, accelerations + l, k - 1 - j);
                    let term = b.ins().fmul(m, a);
                    sum = b.ins().fadd(sum, term);
                }
                x[i as usize] = b.ins().fsub(x[i as usize], sum);
            }
        }
        let entry = |b: &mut FunctionBuilder, lower: ir::Value, i: usize, j: usize| {
            b.ins()
                .load(types::F64, flags, lower, ((i * n + j) * 8) as i32)
        };
        // `x − l·y`, or `x` where a factor with zeros has `l = 0` (the runtime's solve over
        // the non-zero entries skips them; `x − 0·y` is not `x` for `x = −0` or `y` infinite).
        let update = |b: &mut FunctionBuilder, x: ir::Value, l: ir::Value, y: ir::Value| {
            let t = b.ins().fmul(l, y);
            let updated = b.ins().fsub(x, t);
            if factor == Factor::Small {
                let zero = b.ins().f64const(0.0);
                let skip = b.ins().fcmp(FloatCC::Equal, l, zero);
                b.ins().select(skip, x, updated)
            } else {
                updated
            }
        };
        if factor != Factor::Diagonal {
            for i in 0..n {
                for j in 0..i {
                    let l = entry(b, lower, i, j);
                    x[i] = update(b, x[i], l, x[j]);
                }
            }
        }
        for (i, xi) in x.iter_mut().enumerate() {
            let d = b
                .ins()
                .load(types::F64, flags, inverse_pivots, (i * 8) as i32);
            *xi = b.ins().fmul(*xi, d);
        }
        if factor != Factor::Diagonal {
            for i in (0..n).rev() {
                for j in 0..i {
                    let l = entry(b, lower, i, j);
                    x[j] = update(b, x[j], l, x[i]);
                }
            }
        }
        let inverse = self.constant(b, 1.0 / (k + 1) as f64);
        let dim = 2 * n;
        let mut next = Vec::with_capacity(dim);
        for i in 0..n {
            let now = b
                .ins()
                .load(types::F64, settled(), out, ((k * dim + n + i) * 8) as i32);
            next.push(b.ins().fmul(now, inverse));
        }
        for (i, &xi) in x.iter().enumerate() {
            self.put(b, accelerations + i as Slot, k, xi);
            next.push(b.ins().fmul(xi, inverse));
        }
        for (i, &v) in next.iter().enumerate() {
            b.ins()
                .store(flags, v, out, (((k + 1) * dim + i) * 8) as i32);
        }
        if k + 1 < UNROLLED_CAPACITY {
            for &(slot, index) in program.derived.inputs.iter() {
                self.put(b, slot, k + 1, next[index as usize]);
            }
            if let Some(slot) = program.time {
                let v = self.constant(b, if k == 0 { 1.0 } else { 0.0 });
                self.put(b, slot, k + 1, v);
            }
        }
    }

    /// Order `i` of `slot`: of a lane slot, both lanes in a vector; of any other slot, its
    /// value (in both lanes of a vector while a paired op is written).
    pub(super) fn at(&mut self, b: &mut FunctionBuilder, slot: Slot, i: usize) -> ir::Value {
        if let Some(&v) = self.known.get(&(slot, i)) {
            return if self.width == 2 && self.lane(slot).is_none() {
                b.ins().splat(types::F64X2, v)
            } else {
                v
            };
        }
        let v = if self.lane(slot).is_some() {
            let offset = self.layout.lane_offset(slot, i);
            b.ins().load(types::F64X2, settled(), self.scratch, offset)
        } else {
            let offset = ((slot as usize * UNROLLED_CAPACITY + i) * 8) as i32;
            b.ins().load(types::F64, settled(), self.series, offset)
        };
        self.known.insert((slot, i), v);
        if self.width == 2 && self.lane(slot).is_none() {
            return b.ins().splat(types::F64X2, v);
        }
        v
    }

    /// Writes `v` as order `k` of `slot`: of a lane slot, into the scratch and each lane into
    /// its own slot.
    pub(super) fn put(&mut self, b: &mut FunctionBuilder, slot: Slot, k: usize, v: ir::Value) {
        if let Some(lane) = self.lane(slot) {
            if lane.history {
                let offset = self.layout.lane_offset(slot, k);
                b.ins()
                    .store(MemFlagsData::trusted(), v, self.scratch, offset);
            }
            self.known.insert((slot, k), v);
            let (x, y) = (b.ins().extractlane(v, 0), b.ins().extractlane(v, 1));
            self.put(b, lane.slots.0, k, x);
            self.put(b, lane.slots.1, k, y);
            return;
        }
        let offset = ((slot as usize * UNROLLED_CAPACITY + k) * 8) as i32;
        b.ins()
            .store(MemFlagsData::trusted(), v, self.series, offset);
        self.known.insert((slot, k), v);
    }

    /// `x`, in both lanes of a vector while a paired op is written.
    pub(super) fn constant(&self, b: &mut FunctionBuilder, x: f64) -> ir::Value {
        let v = b.ins().f64const(x);
        if self.width == 2 {
            b.ins().splat(types::F64X2, v)
        } else {
            v
        }
    }

    /// The kernels' `convolution` (`Σ_{j ∈ range} a[j] b[k − j]`) or, if `weighted`, their
    /// `weighted_convolution` (each term `(j a[j]) b[k − j]`), summed from `0.0` in increasing
    /// `j`.
    pub(super) fn sum_of_products(
        &mut self,
        b: &mut FunctionBuilder,
        (x, y, k): (Slot, Slot, usize),
        range: std::ops::RangeInclusive<usize>,
        weighted: bool,
    ) -> ir::Value {
        let started = if *range.start() == 1 {
            self.started(b, Sum::Products { x, y, weighted }, self.ty())
        } else {
            None
        };
        let (mut sum, from) = match started {
            Some(sum) => (sum, k),
            None => (self.constant(b, 0.0), *range.start()),
        };
        for j in from.max(*range.start())..=*range.end() {
            let (u, v) = (self.at(b, x, j), self.at(b, y, k - j));
            let term = self.product_term(b, (u, v), j, weighted);
            sum = b.ins().fadd(sum, term);
        }
        sum
    }

    /// A term of [`Self::sum_of_products`]: `u v`, or `(u j) v` if `weighted`.
    pub(super) fn product_term(
        &self,
        b: &mut FunctionBuilder,
        (u, v): (ir::Value, ir::Value),
        j: usize,
        weighted: bool,
    ) -> ir::Value {
        let u = if weighted {
            let weight = self.constant(b, j as f64);
            b.ins().fmul(u, weight)
        } else {
            u
        };
        b.ins().fmul(u, v)
    }

    /// The kernels' `weighted_convolution_pair` of pair `p` (a sine–cosine or sinh–cosh op
    /// over `x`): `Σ_{j=1}^{k} (j x[j]) y[k − j]` and the same with `z`, as the two lanes of
    /// one 2-wide vector sum. Each lane adds the same products in the same order as its
    /// scalar sum, so the bits are the kernels'. The lanes' operands come from the scratch
    /// ([`PairScratch`]): `(j x[j], j x[j])` and `(y[i], z[i])` as one 16-byte load each;
    /// `(k x[k], k x[k])` is stored there for the orders above.
    pub(super) fn weighted_pair(
        &mut self,
        b: &mut FunctionBuilder,
        p: usize,
        x: Slot,
        k: usize,
    ) -> (ir::Value, ir::Value) {
        let xk = self.at(b, x, k);
        let kc = self.constant(b, k as f64);
        let weighted = b.ins().fmul(xk, kc);
        let newest = b.ins().splat(types::F64X2, weighted);
        b.ins().store(
            MemFlagsData::trusted(),
            newest,
            self.scratch,
            PairScratch::weighted(p, k),
        );
        let (mut sum, from) = match self.started(b, Sum::Pair(p), types::F64X2) {
            Some(sum) => (sum, k),
            None => {
                let zero = self.constant(b, 0.0);
                (b.ins().splat(types::F64X2, zero), 1)
            }
        };
        for j in from..=k {
            let w = if j == k {
                newest
            } else {
                b.ins().load(
                    types::F64X2,
                    settled(),
                    self.scratch,
                    PairScratch::weighted(p, j),
                )
            };
            let pair = b.ins().load(
                types::F64X2,
                settled(),
                self.scratch,
                PairScratch::pair(p, k - j),
            );
            let term = b.ins().fmul(w, pair);
            sum = b.ins().fadd(sum, term);
        }
        (b.ins().extractlane(sum, 0), b.ins().extractlane(sum, 1))
    }

    /// Stores `(y[k], z[k])` as pair `p`'s order `k` in the scratch ([`PairScratch`]).
    pub(super) fn store_pair(
        &mut self,
        b: &mut FunctionBuilder,
        p: usize,
        k: usize,
        (y, z): (ir::Value, ir::Value),
    ) {
        // One 16-byte store, as the orders above load it: two 8-byte stores read back by one
        // 16-byte load cannot be forwarded from the store buffer, and the load waits for
        // both stores to reach the cache.
        let lanes = b.ins().splat(types::F64X2, y);
        let lanes = b.ins().insertlane(lanes, z, 1);
        b.ins().store(
            MemFlagsData::trusted(),
            lanes,
            self.scratch,
            PairScratch::pair(p, k),
        );
    }

    /// `cauchy`: `(Σ_{j=1}^{k−1} a[j] b[k − j] + a[0] b[k]) + a[k] b[0]`.
    pub(super) fn cauchy(
        &mut self,
        b: &mut FunctionBuilder,
        x: Slot,
        y: Slot,
        k: usize,
    ) -> ir::Value {
        let older = if k > 1 {
            self.sum_of_products(b, (x, y, k), 1..=k - 1, false)
        } else {
            self.constant(b, 0.0)
        };
        let (x0, yk, xk, y0) = (
            self.at(b, x, 0),
            self.at(b, y, k),
            self.at(b, x, k),
            self.at(b, y, 0),
        );
        let first = b.ins().fmul(x0, yk);
        let sum = b.ins().fadd(older, first);
        let last = b.ins().fmul(xk, y0);
        b.ins().fadd(sum, last)
    }

    /// The kernels' `square`: `(2 h + [k even] x[k/2]²) + (2 x[0]) x[k]`, `h` the sum of
    /// `x[j] x[k − j]` for `j = 1 … ⌊(k − 1)/2⌋` (started by [`Self::prefixes`]).
    pub(super) fn square(&mut self, b: &mut FunctionBuilder, x: Slot, k: usize) -> ir::Value {
        let half = match self.started(b, Sum::Square { x }, self.ty()) {
            Some(sum) => sum,
            None => {
                let mut sum = self.constant(b, 0.0);
                for j in 1..=(k - 1) / 2 {
                    let (u, v) = (self.at(b, x, j), self.at(b, x, k - j));
                    let term = b.ins().fmul(u, v);
                    sum = b.ins().fadd(sum, term);
                }
                sum
            }
        };
        let mut sum = b.ins().fadd(half, half);
        if k.is_multiple_of(2) {
            let middle = self.at(b, x, k / 2);
            let term = b.ins().fmul(middle, middle);
            sum = b.ins().fadd(sum, term);
        }
        let (x0, xk) = (self.at(b, x, 0), self.at(b, x, k));
        let two = self.constant(b, 2.0);
        let twice = b.ins().fmul(two, x0);
        let last = b.ins().fmul(twice, xk);
        b.ins().fadd(sum, last)
    }

    /// `v · (1/k)`.
    pub(super) fn over_k(&self, b: &mut FunctionBuilder, v: ir::Value, k: usize) -> ir::Value {
        let r = self.constant(b, 1.0 / k as f64);
        b.ins().fmul(v, r)
    }

    /// The kernels' `over`: `n · (1/d)`, the reciprocal of a divisor formed from order-0
    /// coefficients, so that only the multiplication waits for order `k`'s numerator.
    pub(super) fn over(&self, b: &mut FunctionBuilder, n: ir::Value, d: ir::Value) -> ir::Value {
        let one = self.constant(b, 1.0);
        let r = b.ins().fdiv(one, d);
        b.ins().fmul(n, r)
    }

    /// Order `k ≥ 1` of `op`: the kernel of `eomgen_runtime::taylor` of its kind.
    // Long: one arm per op kind, each that op's kernel beside the others (as
    // runtime/src/taylor/kernels.rs's kernels); split, the arms would only move into as many one-use
    // functions.
    pub(super) fn op(&mut self, b: &mut FunctionBuilder, op: SeriesOp, k: usize) {
        let kf = k as f64;
        match op {
            SeriesOp::Neg { out, a } => {
                let x = self.at(b, a, k);
                let v = b.ins().fneg(x);
                self.put(b, out, k, v);
            }
            SeriesOp::Copy { out, a } => {
                let v = self.at(b, a, k);
                self.put(b, out, k, v);
            }
            SeriesOp::Add { out, a, b: y } => {
                let (u, w) = (self.at(b, a, k), self.at(b, y, k));
                let v = b.ins().fadd(u, w);
                self.put(b, out, k, v);
            }
            SeriesOp::Sub { out, a, b: y } => {
                let (u, w) = (self.at(b, a, k), self.at(b, y, k));
                let v = b.ins().fsub(u, w);
                self.put(b, out, k, v);
            }
            SeriesOp::Mul { out, a, b: y } => {
                let v = if a == y {
                    self.square(b, a, k)
                } else {
                    self.cauchy(b, a, y, k)
                };
                self.put(b, out, k, v);
            }
            SeriesOp::Scale { out, a, constant } => {
                let (u, c) = (self.at(b, a, k), self.at(b, constant, 0));
                let v = b.ins().fmul(u, c);
                self.put(b, out, k, v);
            }
            SeriesOp::Div { out, a, b: y } => {
                let sum = self.sum_of_products(b, (y, out, k), 1..=k, false);
                let (ak, y0) = (self.at(b, a, k), self.at(b, y, 0));
                let d = b.ins().fsub(ak, sum);
                let v = self.over(b, d, y0);
                self.put(b, out, k, v);
            }
            SeriesOp::DivByConstant { out, a, constant } => {
                let (u, c) = (self.at(b, a, k), self.at(b, constant, 0));
                let v = b.ins().fdiv(u, c);
                self.put(b, out, k, v);
            }
            SeriesOp::ConstantDiv { out, b: y } => {
                let sum = self.sum_of_products(b, (y, out, k), 1..=k, false);
                let y0 = self.at(b, y, 0);
                let minus = b.ins().fneg(sum);
                let v = self.over(b, minus, y0);
                self.put(b, out, k, v);
            }
            SeriesOp::Sqrt { out, a } => {
                let sum = if k > 1 {
                    self.sum_of_products(b, (out, out, k), 1..=k - 1, false)
                } else {
                    self.constant(b, 0.0)
                };
                let (ak, o0) = (self.at(b, a, k), self.at(b, out, 0));
                let d = b.ins().fsub(ak, sum);
                let two = self.constant(b, 2.0);
                let twice = b.ins().fmul(o0, two);
                let v = self.over(b, d, twice);
                self.put(b, out, k, v);
            }
            SeriesOp::PowConstant { out, a, exponent } => {
                let alpha = self.at(b, exponent, 0);
                let kc = self.constant(b, kf);
                let power = Sum::Power { out, a, exponent };
                let (mut sum, from) = match self.started(b, power, self.ty()) {
                    Some(sum) => (sum, 0),
                    None => (self.constant(b, 0.0), k - 1),
                };
                for j in (0..=from).rev() {
                    let (xv, ov) = (self.at(b, a, k - j), self.at(b, out, j));
                    let term = self.power_term(b, (alpha, exponent, k, j), xv, ov);
                    sum = b.ins().fadd(sum, term);
                }
                let x0 = self.at(b, a, 0);
                let d = b.ins().fmul(x0, kc);
                let v = self.over(b, sum, d);
                self.put(b, out, k, v);
            }
            SeriesOp::Exp { out, a } => {
                let w = self.sum_of_products(b, (a, out, k), 1..=k, true);
                let v = self.over_k(b, w, k);
                self.put(b, out, k, v);
            }
            SeriesOp::Ln { out, a } => {
                let sum = if k > 1 {
                    self.sum_of_products(b, (out, a, k), 1..=k - 1, true)
                } else {
                    self.constant(b, 0.0)
                };
                let kc = self.constant(b, kf);
                let (xk, x0) = (self.at(b, a, k), self.at(b, a, 0));
                let kx = b.ins().fmul(xk, kc);
                let n = b.ins().fsub(kx, sum);
                let d = b.ins().fmul(x0, kc);
                let v = self.over(b, n, d);
                self.put(b, out, k, v);
            }
            SeriesOp::SinCos { sin, cos, a } => {
                let p = self.pair_of(sin);
                let (ws, wc) = self.weighted_pair(b, p, a, k);
                let vs = self.over_k(b, ws, k);
                // `(−wc)·(1/k)` as `wc·(−1/k)`: the same bits for every `wc` but NaN (negation
                // is exact and rounding symmetric; a NaN keeps its sign, and any NaN fails the
                // step), one multiplication instead of a sign mask and a multiplication.
                let minus_r = self.constant(b, -(1.0 / k as f64));
                let vc = b.ins().fmul(wc, minus_r);
                self.put(b, sin, k, vs);
                self.put(b, cos, k, vc);
                self.store_pair(b, p, k, (vc, vs));
            }
            SeriesOp::SinhCosh { sinh, cosh, a } => {
                let p = self.pair_of(sinh);
                let (ws, wc) = self.weighted_pair(b, p, a, k);
                let vs = self.over_k(b, ws, k);
                let vc = self.over_k(b, wc, k);
                self.put(b, sinh, k, vs);
                self.put(b, cosh, k, vc);
                self.store_pair(b, p, k, (vc, vs));
            }
            SeriesOp::Tan { out, a, square } => self.tan_or_tanh(b, k, out, a, square, 1.0),
            SeriesOp::Tanh { out, a, square } => self.tan_or_tanh(b, k, out, a, square, -1.0),
            SeriesOp::Asin { out, a, root, acos } => {
                let a2 = self.cauchy(b, a, a, k);
                let sum = if k > 1 {
                    self.sum_of_products(b, (root, root, k), 1..=k - 1, false)
                } else {
                    self.constant(b, 0.0)
                };
                let r0 = self.at(b, root, 0);
                let minus = b.ins().fneg(a2);
                let n = b.ins().fsub(minus, sum);
                let two = self.constant(b, 2.0);
                let twice = b.ins().fmul(r0, two);
                let rk = self.over(b, n, twice);
                let sign = if acos { -1.0 } else { 1.0 };
                let sum = if k > 1 {
                    self.sum_of_products(b, (out, root, k), 1..=k - 1, true)
                } else {
                    self.constant(b, 0.0)
                };
                let sk = self.constant(b, sign * kf);
                let xk = self.at(b, a, k);
                let sx = b.ins().fmul(xk, sk);
                let n = b.ins().fsub(sx, sum);
                let kc = self.constant(b, kf);
                let d = b.ins().fmul(r0, kc);
                let v = self.over(b, n, d);
                self.put(b, root, k, rk);
                self.put(b, out, k, v);
            }
            SeriesOp::Atan { out, a, square } => {
                let q = self.cauchy(b, a, a, k);
                self.put(b, square, k, q);
                let sum = if k > 1 {
                    self.sum_of_products(b, (out, square, k), 1..=k - 1, true)
                } else {
                    self.constant(b, 0.0)
                };
                let kc = self.constant(b, kf);
                let xk = self.at(b, a, k);
                let kx = b.ins().fmul(xk, kc);
                let n = b.ins().fsub(kx, sum);
                let one = self.constant(b, 1.0);
                let sq0 = self.at(b, square, 0);
                let s = b.ins().fadd(one, sq0);
                let d = b.ins().fmul(s, kc);
                let v = self.over(b, n, d);
                self.put(b, out, k, v);
            }
            SeriesOp::Atan2 { out, y, x, norm } => {
                let xx = self.cauchy(b, x, x, k);
                let yy = self.cauchy(b, y, y, k);
                let nk = b.ins().fadd(xx, yy);
                let wy = self.sum_of_products(b, (y, x, k), 1..=k, true);
                let wx = self.sum_of_products(b, (x, y, k), 1..=k, true);
                let cross = b.ins().fsub(wy, wx);
                self.put(b, norm, k, nk);
                let sum = if k > 1 {
                    self.sum_of_products(b, (out, norm, k), 1..=k - 1, true)
                } else {
                    self.constant(b, 0.0)
                };
                let n = b.ins().fsub(cross, sum);
                let kc = self.constant(b, kf);
                let n0 = self.at(b, norm, 0);
                let d = b.ins().fmul(n0, kc);
                let v = self.over(b, n, d);
                self.put(b, out, k, v);
            }
            SeriesOp::Zero { out } => {
                let v = self.constant(b, 0.0);
                self.put(b, out, k, v);
            }
        }
    }

    /// `tan_or_tanh`.
    pub(super) fn tan_or_tanh(
        &mut self,
        b: &mut FunctionBuilder,
        k: usize,
        out: Slot,
        a: Slot,
        square: Slot,
        sign: f64,
    ) {
        let w = self.sum_of_products(b, (a, square, k), 1..=k, true);
        let scaled = self.over_k(b, w, k);
        let s = self.constant(b, sign);
        let signed = b.ins().fmul(scaled, s);
        let xk = self.at(b, a, k);
        let v = b.ins().fadd(xk, signed);
        self.put(b, out, k, v);
        let q = self.cauchy(b, out, out, k);
        self.put(b, square, k, q);
    }

    /// A term `(kα − j(α + 1)) x[k − j] y[j]` of the power with constant exponent `α`, as
    /// the kernel `pow_constant` computes it (for `j = 0`, `x[k] (kα y[0])`).
    pub(super) fn power_term(
        &self,
        b: &mut FunctionBuilder,
        (alpha, exponent, k, j): (ir::Value, Slot, usize, usize),
        xv: ir::Value,
        ov: ir::Value,
    ) -> ir::Value {
        if j == 0 {
            // The term with order k: `x[k] (kα o[0])`, as the kernel forms it.
            let weight = match self.layout.constants.get(&exponent) {
                Some(&alpha) => self.constant(b, k as f64 * alpha),
                None => {
                    let kc = self.constant(b, k as f64);
                    b.ins().fmul(kc, alpha)
                }
            };
            let t = b.ins().fmul(weight, ov);
            return b.ins().fmul(xv, t);
        }
        if let Some(&alpha) = self.layout.constants.get(&exponent) {
            // The same operations in Rust, so the same bits.
            let weight = alpha * k as f64 - (alpha + 1.0) * j as f64;
            let weight = self.constant(b, weight);
            let t = b.ins().fmul(weight, xv);
            return b.ins().fmul(t, ov);
        }
        let kc = self.constant(b, k as f64);
        let one = self.constant(b, 1.0);
        let ka = b.ins().fmul(alpha, kc);
        let jc = self.constant(b, j as f64);
        let a1 = b.ins().fadd(alpha, one);
        let ja = b.ins().fmul(a1, jc);
        let weight = b.ins().fsub(ka, ja);
        let t = b.ins().fmul(weight, xv);
        b.ins().fmul(t, ov)
    }
}
