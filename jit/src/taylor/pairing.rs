//! Two ops of the same kind run as the two lanes of one vector: the pairing of a program's
//! ops, and the order the units run in.
//!
//! # Why
//! The orders of a program such as the figure eight's are bound by throughput: its
//! convolutions add about a thousand products at order 12 (some 4,600 instructions). Its bodies' x and y components go
//! through the same operations, so the two lanes of one 2-wide vector can carry both, one
//! instruction doing the work of two. Each lane computes exactly its own op's kernel (the
//! same operations in the same order: Cranelift neither reassociates nor contracts), so the
//! bits are the scalar code's. LLVM's SLP vectoriser does this for straight-line code; the
//! figure eight's series written out (`tools/taylor_ssa_probe.py`) ran in 203 ns paired and
//! 494 ns unpaired under Cranelift (docs/performance.md, "The panel").
//!
//! # How the pairs are found
//! As an SLP vectoriser finds them (Larsen and Amarasinghe, "Exploiting superword level
//! parallelism with multimedia instruction sets", PLDI 2000), in three passes:
//! 1. **From the roots.** The forcing terms of adjacent coordinates `2i` and `2i + 1` (on a
//!    planar model, a body's `x` and `y`) are paired if their ops are of the same kind, then
//!    their operands position by position, down the two expressions while they stay alike.
//! 2. **Up from the pairs.** Two ops of the same kind whose operands are, position by
//!    position, the two lanes of a pair found, or one shared slot: a body's `x²` and `y²`.
//! 3. **The convolutions left**, each with the first of the next [`PARTNERS_TRIED`] of its
//!    kind in the program that it does not depend on (the figure eight's powers `r⁻³`):
//!    their operands are gathered into lanes at each order.
//!
//! Two ops pair only if neither depends on the other, through any chain of units: the units
//! must run in some order. Ops of other kinds (sine–cosine pairs, which already use both
//! lanes, and the ops with an auxiliary output) stay alone.
//!
//! # The lane slots
//! A paired op reads and writes *lane slots*: numbered after every slot of the workspace, each
//! names two slots `(s, t)` whose orders sit side by side in the scratch (order `i` of both in
//! one 16-byte unit), so each term of a convolution loads its operand in one instruction. A
//! lane slot is written by the paired op whose outputs it names (which also stores each lane
//! to its own slot, for the ops and the solve that read it alone), or gathered from its two
//! slots at each order before its first reader runs (at order 0 only if it is read at order
//! 0 only, as the constants of a scaling or a power are).

use super::*;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashSet};

/// Programs with more ops than this run unpaired: the search for pairs checks, for each
/// candidate, the chains of dependence through the whole program. Programs this large have
/// no orders compiled anyway (their code would not fit the instruction cache:
/// [`TaylorProgram::highest_unrolled_order`] is 0 past 2,100 ops).
const MAX_OPS: usize = 4000;

/// How many later ops of its kind pass 3 tries as a convolution's partner (each try walks
/// the chains of dependence): a bound on the search in a long chain of dependent products.
const PARTNERS_TRIED: usize = 8;

/// What a program's orders run, in order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Unit {
    /// One op of the program.
    Single(SeriesOp),
    /// Two ops as one, over lane slots (see the module documentation).
    Pair {
        /// The op over lane slots.
        op: SeriesOp,
        /// Its operands' lane slots that no paired op writes, read above order 0: gathered
        /// from their two slots at each order, before it runs.
        gathered: [Option<Slot>; 2],
    },
}

/// A lane slot (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct LaneSlot {
    /// Its lanes 0 and 1.
    pub(super) slots: (Slot, Slot),
    /// Whether a paired op writes it (else it is gathered from its two slots).
    pub(super) written: bool,
    /// Whether it is read as a constant (its order 0, at every order), so that its order 0 is
    /// kept in the scratch.
    pub(super) constant: bool,
    /// Whether an op reads its orders below the op's own (a convolution's terms), so that
    /// each order is kept in the scratch; else order `k` lives in registers only, in order
    /// `k`'s function.
    pub(super) history: bool,
}

/// Which orders of an operand an op's kernel reads at order `k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Read {
    /// Order `k` only.
    Current,
    /// Orders `0 … k` (a convolution's terms).
    History,
    /// Order 0 only (a constant).
    Constant,
}

/// A program's units and lane slots.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Pairing {
    /// The ops, each alone or in a pair, in an order in which each reads only what those
    /// before it wrote.
    pub(super) units: Vec<Unit>,
    /// Lane slot `base + v` at index `v`.
    pub(super) lanes: Vec<LaneSlot>,
    /// The first lane slot's number: past every slot of the workspace.
    pub(super) base: Slot,
}

/// What two ops must share to be paired, and what is paired of them.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Shape {
    /// The op with its slots zeroed: the kind and any flag.
    kind: SeriesOp,
    /// Which operands are the same slot (`a == b` makes a product a square).
    same: bool,
    out: Slot,
    /// Whether its kernel reads its own output's orders below `k`.
    recursive: bool,
    /// The operands and which of their orders the kernel reads.
    operands: [(Slot, Read); 2],
    count: usize,
}

/// `op`'s shape, if it may be paired: the ops whose kernel is one output computed from at
/// most two operands.
fn shape(op: &SeriesOp) -> Option<Shape> {
    use Read::{Constant, Current, History};
    let one = |out: Slot, a: (Slot, Read)| (out, [a, a], 1);
    let (out, operands, count) = match *op {
        SeriesOp::Neg { out, a } | SeriesOp::Copy { out, a } | SeriesOp::Sqrt { out, a } => {
            one(out, (a, Current))
        }
        SeriesOp::Exp { out, a }
        | SeriesOp::Ln { out, a }
        | SeriesOp::ConstantDiv { out, b: a } => one(out, (a, History)),
        SeriesOp::Add { out, a, b } | SeriesOp::Sub { out, a, b } => {
            (out, [(a, Current), (b, Current)], 2)
        }
        SeriesOp::Mul { out, a, b } => (out, [(a, History), (b, History)], 2),
        SeriesOp::Div { out, a, b } => (out, [(a, Current), (b, History)], 2),
        SeriesOp::Scale { out, a, constant } | SeriesOp::DivByConstant { out, a, constant } => {
            (out, [(a, Current), (constant, Constant)], 2)
        }
        SeriesOp::PowConstant { out, a, exponent } => {
            (out, [(a, History), (exponent, Constant)], 2)
        }
        _ => return None,
    };
    // Every convolution of these kinds but the product's runs over its own output too.
    let recursive = op.convolutions() > 0 && !matches!(op, SeriesOp::Mul { .. });
    let slots: Vec<Slot> = operands[..count].iter().map(|&(s, _)| s).collect();
    Some(Shape {
        kind: with_slots(*op, 0, &[0, 0]),
        same: count == 2 && slots[0] == slots[1],
        out,
        recursive,
        operands,
        count,
    })
}

/// `op` (of a kind [`shape`] accepts) with output `out` and the operands `operands`, in the
/// order [`shape`] lists them.
fn with_slots(op: SeriesOp, out: Slot, operands: &[Slot]) -> SeriesOp {
    let (a, b) = (operands[0], operands.get(1).copied().unwrap_or(operands[0]));
    match op {
        SeriesOp::Neg { .. } => SeriesOp::Neg { out, a },
        SeriesOp::Copy { .. } => SeriesOp::Copy { out, a },
        SeriesOp::Sqrt { .. } => SeriesOp::Sqrt { out, a },
        SeriesOp::Exp { .. } => SeriesOp::Exp { out, a },
        SeriesOp::Ln { .. } => SeriesOp::Ln { out, a },
        SeriesOp::ConstantDiv { .. } => SeriesOp::ConstantDiv { out, b: a },
        SeriesOp::Add { .. } => SeriesOp::Add { out, a, b },
        SeriesOp::Sub { .. } => SeriesOp::Sub { out, a, b },
        SeriesOp::Mul { .. } => SeriesOp::Mul { out, a, b },
        SeriesOp::Div { .. } => SeriesOp::Div { out, a, b },
        SeriesOp::Scale { .. } => SeriesOp::Scale {
            out,
            a,
            constant: b,
        },
        SeriesOp::DivByConstant { .. } => SeriesOp::DivByConstant {
            out,
            a,
            constant: b,
        },
        SeriesOp::PowConstant { .. } => SeriesOp::PowConstant {
            out,
            a,
            exponent: b,
        },
        other => other,
    }
}

/// The slots `op` reads and writes.
fn reads_writes(op: &SeriesOp) -> (Vec<Slot>, Vec<Slot>) {
    match *op {
        SeriesOp::Neg { out, a }
        | SeriesOp::Copy { out, a }
        | SeriesOp::Sqrt { out, a }
        | SeriesOp::Exp { out, a }
        | SeriesOp::Ln { out, a }
        | SeriesOp::ConstantDiv { out, b: a } => (vec![a], vec![out]),
        SeriesOp::Add { out, a, b }
        | SeriesOp::Sub { out, a, b }
        | SeriesOp::Mul { out, a, b }
        | SeriesOp::Div { out, a, b }
        | SeriesOp::Scale {
            out,
            a,
            constant: b,
        }
        | SeriesOp::DivByConstant {
            out,
            a,
            constant: b,
        }
        | SeriesOp::PowConstant {
            out,
            a,
            exponent: b,
        } => (vec![a, b], vec![out]),
        SeriesOp::SinCos { sin, cos, a } => (vec![a], vec![sin, cos]),
        SeriesOp::SinhCosh { sinh, cosh, a } => (vec![a], vec![sinh, cosh]),
        SeriesOp::Tan { out, a, square }
        | SeriesOp::Tanh { out, a, square }
        | SeriesOp::Atan { out, a, square } => (vec![a], vec![out, square]),
        SeriesOp::Asin { out, a, root, .. } => (vec![a], vec![out, root]),
        SeriesOp::Atan2 { out, y, x, norm } => (vec![y, x], vec![out, norm]),
        SeriesOp::Zero { out } => (vec![], vec![out]),
    }
}

/// The search's state: which op is paired with which.
struct Search<'a> {
    ops: &'a [SeriesOp],
    shapes: Vec<Option<Shape>>,
    /// The ops each op reads from.
    deps: Vec<Vec<usize>>,
    /// The op that writes each slot.
    writer: HashMap<Slot, usize>,
    /// The ops that read each slot.
    readers: HashMap<Slot, Vec<usize>>,
    partner: Vec<Option<usize>>,
    /// Whether each paired op runs in lane 0.
    first: Vec<bool>,
    /// `(s, t)` of each pair's outputs, lane 0 first.
    written: HashSet<(Slot, Slot)>,
    /// For each slot written in lane 0, the slots written beside it in lane 1.
    beside: HashMap<Slot, Vec<Slot>>,
}

impl<'a> Search<'a> {
    fn new(ops: &'a [SeriesOp]) -> Self {
        let mut writer = HashMap::new();
        for (i, op) in ops.iter().enumerate() {
            for slot in reads_writes(op).1 {
                writer.insert(slot, i);
            }
        }
        let mut readers: HashMap<Slot, Vec<usize>> = HashMap::new();
        let deps = ops
            .iter()
            .enumerate()
            .map(|(i, op)| {
                let mut d: Vec<usize> = Vec::new();
                for slot in reads_writes(op).0 {
                    let list = readers.entry(slot).or_default();
                    if list.last() != Some(&i) {
                        list.push(i);
                    }
                    if let Some(&w) = writer.get(&slot)
                        && !d.contains(&w)
                    {
                        d.push(w);
                    }
                }
                d
            })
            .collect();
        Search {
            ops,
            shapes: ops.iter().map(shape).collect(),
            deps,
            writer,
            readers,
            partner: vec![None; ops.len()],
            first: vec![false; ops.len()],
            written: HashSet::new(),
            beside: HashMap::new(),
        }
    }

    /// Whether op `to` depends on op `from` through any chain of units (each pair one unit).
    fn reaches(&self, from: usize, to: usize) -> bool {
        let mut seen = vec![false; self.ops.len()];
        let mut stack = vec![to];
        while let Some(o) = stack.pop() {
            let unit = [Some(o), self.partner[o]];
            for member in unit.into_iter().flatten() {
                for &d in &self.deps[member] {
                    if d == from {
                        return true;
                    }
                    if !seen[d] {
                        seen[d] = true;
                        stack.push(d);
                    }
                }
            }
        }
        false
    }

    /// The shapes of unpaired ops `a` and `b` if they are alike and may run as one unit.
    fn fits(&self, a: usize, b: usize) -> Option<(Shape, Shape)> {
        if a == b || self.partner[a].is_some() || self.partner[b].is_some() {
            return None;
        }
        let (x, y) = (self.shapes[a]?, self.shapes[b]?);
        if x.kind != y.kind || x.same != y.same {
            return None;
        }
        // Two ops of the same operands compute the same values (but two quotients `c / b` of
        // constants `c` that the op does not name): nothing to gain.
        let same_values = !matches!(x.kind, SeriesOp::ConstantDiv { .. });
        if same_values && (0..x.count).all(|i| x.operands[i].0 == y.operands[i].0) {
            return None;
        }
        (!self.reaches(a, b) && !self.reaches(b, a)).then_some((x, y))
    }

    /// Pairs `a` (lane 0, of shape `x`) with `b` (lane 1, `y`).
    fn pair(&mut self, (a, x): (usize, Shape), (b, y): (usize, Shape)) {
        self.partner[a] = Some(b);
        self.partner[b] = Some(a);
        self.first[a] = true;
        self.written.insert((x.out, y.out));
        self.beside.entry(x.out).or_default().push(y.out);
    }

    /// Pass 1: pairs down from the slots `s` (lane 0) and `t` (lane 1).
    fn down(&mut self, s: Slot, t: Slot) {
        let mut stack = vec![(s, t)];
        while let Some((s, t)) = stack.pop() {
            let (Some(&a), Some(&b)) = (self.writer.get(&s), self.writer.get(&t)) else {
                continue;
            };
            let Some((x, y)) = self.fits(a, b) else {
                continue;
            };
            self.pair((a, x), (b, y));
            for i in 0..x.count {
                let ((u, read), (v, _)) = (x.operands[i], y.operands[i]);
                if read != Read::Constant && u != v {
                    stack.push((u, v));
                }
            }
        }
    }

    /// Pass 2: pairs whose every operand is a pair's lanes or one slot; whether one was found.
    fn up(&mut self) -> bool {
        let mut found = false;
        for a in 0..self.ops.len() {
            let Some(x) = self.shapes[a] else { continue };
            if self.partner[a].is_some() {
                continue;
            }
            // A partner reads, at the same position, lane 1 of a pair whose lane 0 `a` reads.
            let mut candidates: Vec<usize> = Vec::new();
            for i in 0..x.count {
                for t in self.beside.get(&x.operands[i].0).into_iter().flatten() {
                    if let Some(list) = self.readers.get(t) {
                        candidates.extend(list.iter().copied());
                    }
                }
            }
            candidates.sort_unstable();
            candidates.dedup();
            for b in candidates {
                let Some(y) = self.shapes[b] else { continue };
                let alike = (0..x.count).all(|i| {
                    let (u, v) = (x.operands[i].0, y.operands[i].0);
                    u == v || self.written.contains(&(u, v))
                });
                if !alike {
                    continue;
                }
                if let Some((x, y)) = self.fits(a, b) {
                    self.pair((a, x), (b, y));
                    found = true;
                    break;
                }
            }
        }
        found
    }

    /// Pass 3: each convolution left with the next of its kind.
    fn convolutions(&mut self) {
        for a in 0..self.ops.len() {
            let Some(x) = self.shapes[a] else { continue };
            if self.partner[a].is_some() || x.kind.convolutions() == 0 {
                continue;
            }
            let kind = x.kind;
            let partner = (a + 1..self.ops.len())
                .filter(|&b| {
                    self.partner[b].is_none() && self.shapes[b].is_some_and(|y| y.kind == kind)
                })
                .take(PARTNERS_TRIED)
                .find_map(|b| self.fits(a, b).map(|shapes| (b, shapes)));
            if let Some((b, (x, y))) = partner {
                self.pair((a, x), (b, y));
            }
        }
    }
}

impl Pairing {
    /// The program's ops, each alone, in its own order.
    pub(super) fn none(program: &TaylorProgram) -> Self {
        Pairing {
            units: program.ops.iter().map(|&op| Unit::Single(op)).collect(),
            lanes: Vec::new(),
            base: 0,
        }
    }

    /// The pairs of `program`'s ops (see the module documentation), its lane slots numbered
    /// from `base` (past every slot of the workspace).
    pub(super) fn new(program: &TaylorProgram, base: Slot) -> Self {
        let ops: &[SeriesOp] = &program.ops;
        if ops.len() > MAX_OPS {
            return Self::none(program);
        }
        let mut search = Search::new(ops);
        let n = program.coordinates.len();
        for i in (0..n.saturating_sub(1)).step_by(2) {
            search.down(program.forcing[i], program.forcing[i + 1]);
        }
        while search.up() {}
        search.convolutions();
        Self::schedule(program, &search, base).unwrap_or_else(|| Self::none(program))
    }

    /// The units in an order in which each reads only what those before it wrote (among the
    /// units ready, the one holding the earliest op first), and the lane slots; `None` if the
    /// pairs leave no such order (the search rules that out).
    fn schedule(program: &TaylorProgram, search: &Search, base: Slot) -> Option<Self> {
        let ops: &[SeriesOp] = &program.ops;
        // Each op's unit: its own index, or the lower of its pair's.
        let unit_of: Vec<usize> = (0..ops.len())
            .map(|i| search.partner[i].map_or(i, |p| p.min(i)))
            .collect();
        let mut waiting = vec![0usize; ops.len()];
        let mut dependents: Vec<Vec<usize>> = vec![Vec::new(); ops.len()];
        for (i, deps) in search.deps.iter().enumerate() {
            for &d in deps {
                let (u, from) = (unit_of[i], unit_of[d]);
                if u != from && !dependents[from].contains(&u) {
                    dependents[from].push(u);
                    waiting[u] += 1;
                }
            }
        }
        let mut ready: BinaryHeap<Reverse<usize>> = (0..ops.len())
            .filter(|&i| unit_of[i] == i && waiting[i] == 0)
            .map(Reverse)
            .collect();
        let mut order = Vec::new();
        while let Some(Reverse(u)) = ready.pop() {
            order.push(u);
            for &d in &dependents[u] {
                waiting[d] -= 1;
                if waiting[d] == 0 {
                    ready.push(Reverse(d));
                }
            }
        }
        if order.len() != unit_of.iter().enumerate().filter(|(i, u)| i == *u).count() {
            return None;
        }
        let mut pairing = Pairing {
            units: Vec::with_capacity(order.len()),
            lanes: Vec::new(),
            base,
        };
        let mut numbers: HashMap<(Slot, Slot), Slot> = HashMap::new();
        for u in order {
            let Some(p) = search.partner[u] else {
                pairing.units.push(Unit::Single(ops[u]));
                continue;
            };
            // Lane 0 is the op the search put first.
            let (a, b) = if search.first[u] { (u, p) } else { (p, u) };
            let (x, y) = (search.shapes[a]?, search.shapes[b]?);
            let mut lane = |slots: (Slot, Slot), written: bool, read: Read| {
                let number = *numbers.entry(slots).or_insert_with(|| {
                    pairing.lanes.push(LaneSlot {
                        slots,
                        written: false,
                        constant: false,
                        history: false,
                    });
                    base + (pairing.lanes.len() - 1) as Slot
                });
                let entry = &mut pairing.lanes[(number - base) as usize];
                entry.written |= written;
                entry.constant |= read == Read::Constant;
                entry.history |= read == Read::History;
                (number, entry.written)
            };
            // A slot both ops read is read as it is, into both lanes.
            let mut gathered = [None; 2];
            let operands: Vec<Slot> = (0..x.count)
                .map(|i| {
                    let ((s, read), (t, _)) = (x.operands[i], y.operands[i]);
                    if s == t {
                        return s;
                    }
                    let (number, written) = lane((s, t), false, read);
                    // Its writer, if any, runs before: what it wrote is known here.
                    if read != Read::Constant && !written {
                        gathered[i] = Some(number);
                    }
                    number
                })
                .collect();
            let (out, _) = lane(
                (x.out, y.out),
                true,
                if x.recursive {
                    Read::History
                } else {
                    Read::Current
                },
            );
            pairing.units.push(Unit::Pair {
                op: with_slots(ops[a], out, &operands),
                gathered,
            });
        }
        Some(pairing)
    }

    /// The lane slot `slot`, if it is one.
    pub(super) fn lane(&self, slot: Slot) -> Option<&LaneSlot> {
        slot.checked_sub(self.base)
            .and_then(|v| self.lanes.get(v as usize))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use eomgen_runtime::taylor::DerivedLists;
    use std::borrow::Cow;

    /// A program over `slots` slots with coordinates `x = 0`, `y = 1` and the forcing
    /// `forcing`, running `ops`.
    fn program(slots: usize, ops: Vec<SeriesOp>, forcing: [Slot; 2]) -> TaylorProgram {
        TaylorProgram {
            slots,
            coordinates: Cow::Owned(vec![Some(0), Some(1)]),
            velocities: Cow::Owned(vec![None, None]),
            time: None,
            mass_matrix: Cow::Owned(vec![2, 2, 2, 2]),
            forcing: Cow::Owned(forcing.to_vec()),
            constant: Cow::Owned((0..slots).map(|s| s == 2 || s == 6 || s == 10).collect()),
            ops: Cow::Owned(ops),
            derived: DerivedLists::default(),
        }
        .with_derived()
    }

    /// A Kepler orbit's pull `−μ (x, y) (x² + y²)^−3/2`: slots 0, 1 the position, 2 a zero,
    /// 6 the exponent, 10 `−μ`.
    fn kepler() -> TaylorProgram {
        let ops = vec![
            SeriesOp::Mul { out: 3, a: 0, b: 0 },
            SeriesOp::Mul { out: 4, a: 1, b: 1 },
            SeriesOp::Add { out: 5, a: 3, b: 4 },
            SeriesOp::PowConstant {
                out: 7,
                a: 5,
                exponent: 6,
            },
            SeriesOp::Mul { out: 8, a: 0, b: 7 },
            SeriesOp::Mul { out: 9, a: 1, b: 7 },
            SeriesOp::Scale {
                out: 11,
                a: 8,
                constant: 10,
            },
            SeriesOp::Scale {
                out: 12,
                a: 9,
                constant: 10,
            },
        ];
        program(13, ops, [11, 12])
    }

    /// Whether each unit reads only what the units before it wrote (or the inputs and the
    /// constants), and every op of `program` runs once.
    fn runs_in_order(program: &TaylorProgram, pairing: &Pairing) -> bool {
        let mut written: HashSet<Slot> = [0, 1, 2, 6, 10].into_iter().collect();
        let mut ran = 0;
        for unit in &pairing.units {
            let (op, lanes) = match *unit {
                Unit::Single(op) => (op, 1),
                Unit::Pair { op, .. } => (op, 2),
            };
            let (reads, writes) = reads_writes(&op);
            let real = |slot: Slot| -> Vec<Slot> {
                match pairing.lane(slot) {
                    Some(lane) => vec![lane.slots.0, lane.slots.1],
                    None => vec![slot],
                }
            };
            if !reads
                .into_iter()
                .flat_map(real)
                .all(|s| written.contains(&s))
            {
                return false;
            }
            written.extend(writes.into_iter().flat_map(real));
            ran += lanes;
        }
        ran == program.ops.len()
    }

    #[test]
    fn the_pull_of_a_kepler_orbit_runs_in_two_lanes_but_its_radius() {
        let p = kepler();
        let pairing = Pairing::new(&p, 20);
        assert!(runs_in_order(&p, &pairing));
        let paired: Vec<SeriesOp> = pairing
            .units
            .iter()
            .filter_map(|u| match u {
                Unit::Pair { op, .. } => Some(*op),
                Unit::Single(_) => None,
            })
            .collect();
        // The scalings and the products by the power from the forcing down (pass 1), the
        // squares as the next products of their kind (pass 3); the sum x² + y² and the power
        // stay alone.
        assert_eq!(paired.len(), 3, "{:?}", pairing.units);
        let lane = |slot: Slot| pairing.lane(slot).unwrap().slots;
        let scalings: Vec<_> = paired
            .iter()
            .filter_map(|op| match *op {
                SeriesOp::Scale { out, a, constant } => Some((lane(out), lane(a), constant)),
                _ => None,
            })
            .collect();
        assert_eq!(scalings, [((11, 12), (8, 9), 10)]);
        // The products by the power read it as it is, in both lanes.
        assert!(
            paired.contains(&SeriesOp::Mul {
                out: pairing
                    .units
                    .iter()
                    .find_map(|u| match *u {
                        Unit::Pair {
                            op: SeriesOp::Mul { out, b: 7, .. },
                            ..
                        } => Some(out),
                        _ => None,
                    })
                    .unwrap(),
                a: 20
                    + pairing
                        .lanes
                        .iter()
                        .position(|l| l.slots == (0, 1))
                        .unwrap() as Slot,
                b: 7,
            })
        );
        // The position is gathered (no op writes it), and read at every order below.
        let position = pairing.lanes.iter().find(|l| l.slots == (0, 1)).unwrap();
        assert!(!position.written && position.history);
        // ... by each paired op that reads it, before it runs.
        let number = 20
            + pairing
                .lanes
                .iter()
                .position(|l| l.slots == (0, 1))
                .unwrap() as Slot;
        let gathering = pairing
            .units
            .iter()
            .filter(
                |u| matches!(u, Unit::Pair { gathered, .. } if gathered.contains(&Some(number))),
            )
            .count();
        assert_eq!(gathering, 2, "{:?}", pairing.units);
    }

    #[test]
    fn ops_that_depend_on_each_other_stay_alone() {
        // y' = x·x, then x·y': the second product reads the first.
        let ops = vec![
            SeriesOp::Mul { out: 3, a: 0, b: 0 },
            SeriesOp::Mul { out: 4, a: 0, b: 3 },
        ];
        let p = program(13, ops, [3, 4]);
        let pairing = Pairing::new(&p, 20);
        assert!(runs_in_order(&p, &pairing));
        assert!(pairing.lanes.is_empty(), "{:?}", pairing.units);
        // Nor through a pair: with c and d paired (the forcing), a and b paired would wait
        // on c (b reads it), and c on a (its partner d reads it).
        let ops = vec![
            SeriesOp::Mul { out: 3, a: 0, b: 0 }, // a
            SeriesOp::Neg { out: 4, a: 1 },       // c
            SeriesOp::Neg { out: 5, a: 3 },       // d
            SeriesOp::Mul { out: 7, a: 4, b: 4 }, // b
        ];
        let p = program(13, ops, [4, 5]);
        let pairing = Pairing::new(&p, 20);
        assert!(runs_in_order(&p, &pairing));
        assert_eq!(
            pairing
                .units
                .iter()
                .filter(|u| matches!(u, Unit::Pair { .. }))
                .count(),
            1,
            "{:?}",
            pairing.units
        );
        assert!(matches!(
            pairing.units[0],
            Unit::Single(SeriesOp::Mul { out: 3, .. })
        ));
    }

    /// Two powers of other bases and exponents: the bases' and outputs' orders are kept
    /// (their kernels read the orders below), the exponents' order 0 alone.
    #[test]
    fn lane_slots_keep_the_orders_their_readers_read() {
        let ops = vec![
            SeriesOp::PowConstant {
                out: 3,
                a: 0,
                exponent: 6,
            },
            SeriesOp::PowConstant {
                out: 4,
                a: 1,
                exponent: 10,
            },
            SeriesOp::Add { out: 5, a: 3, b: 4 },
        ];
        let p = program(13, ops, [5, 5]);
        let pairing = Pairing::new(&p, 20);
        assert!(runs_in_order(&p, &pairing));
        let lane = |slots: (Slot, Slot)| *pairing.lanes.iter().find(|l| l.slots == slots).unwrap();
        let (bases, exponents, powers) = (lane((0, 1)), lane((6, 10)), lane((3, 4)));
        assert!(!bases.written && bases.history && !bases.constant);
        assert!(!exponents.written && !exponents.history && exponents.constant);
        assert!(powers.written && powers.history && !powers.constant);
        assert_eq!(pairing.lanes.len(), 3);
    }

    #[test]
    fn shapes_rebuild_the_op_they_were_read_from() {
        let ops = [
            SeriesOp::Mul { out: 5, a: 1, b: 2 },
            SeriesOp::Scale {
                out: 5,
                a: 1,
                constant: 2,
            },
            SeriesOp::PowConstant {
                out: 5,
                a: 1,
                exponent: 2,
            },
            SeriesOp::ConstantDiv { out: 5, b: 1 },
            SeriesOp::Neg { out: 5, a: 1 },
        ];
        for op in ops {
            let s = shape(&op).unwrap();
            let operands: Vec<Slot> = s.operands[..s.count].iter().map(|o| o.0).collect();
            assert_eq!(with_slots(op, s.out, &operands), op);
        }
    }
}
