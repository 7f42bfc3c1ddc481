//! The recurrences of a model's Taylor series: [`TaylorProgram`].
//!
//! A model's equations `M(q, t) q̈ = F(q, q̇, t)` are a straight-line program over `q`, `q̇`,
//! `t` and the parameters (the CSE plan the model's code is printed from). Read with series
//! `x(t₀ + τ) = Σₖ x^[k] τᵏ` for every value of that program, each operation has a recurrence
//! that gives its coefficient of order `k` from those of its operands of orders `≤ k` and its
//! own of orders `< k` (automatic differentiation in Taylor mode: Jorba & Zou 2005, §2;
//! Biscani & Izzo 2021, heyoka's `doc/ad_notes.rst`). A [`TaylorProgram`] lists those
//! operations, one [`SeriesOp`] each, over numbered *slots* (one series per value):
//!
//! - order 0 is the model's own evaluation of `M` and `F`, every value kept (the generated
//!   `taylor_values` of a compiled model, the run-time model's tape);
//! - orders `k ≥ 1` are [`TaylorProgram::ops`] in order, for one `k` at a time; values that
//!   depend only on parameters and constants are *constant* (their series stops at order 0)
//!   and never appear as an op's output.
//!
//! The symbolic crate builds one program per model (`eomgen_symbolic::codegen::taylor`), the
//! `model!` macro prints it as a `static` (and its ops as inlined calls), the run-time compiler
//! keeps it as a value, and the runtime's series of motion (`eomgen_runtime::taylor`) drives
//! it: state series in, series of `M` and `F` out, `M^[0] a^[k] = F^[k] − Σⱼ M^[j] a^[k−j]`
//! for the accelerations.
//!
//! Series are stored by slot: order `k` of slot `s` at `s · capacity + k`, `capacity` the
//! highest order plus one.

use std::borrow::Cow;

use serde::Serialize;

use crate::List;

/// A slot: the index of one series (a value of the model's program, or an auxiliary series
/// an op keeps).
pub type Slot = u32;

/// One operation of the orders `k ≥ 1`: it writes order `k` of its output slot(s) from the
/// orders `≤ k` of its operands and the orders `< k` of its outputs.
///
/// Operands named `constant` are constant slots (only order 0 is read). The recurrences are
/// those of Jorba & Zou (2005, §2.1) and heyoka's `doc/ad_notes.rst`; `x^[k]` is the
/// coefficient of order `k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum SeriesOp {
    /// `out^[k] = −a^[k]`.
    Neg {
        /// Output.
        out: Slot,
        /// Operand.
        a: Slot,
    },
    /// `out^[k] = a^[k]` (a series plus or minus a constant).
    Copy {
        /// Output.
        out: Slot,
        /// Operand.
        a: Slot,
    },
    /// `out^[k] = a^[k] + b^[k]`.
    Add {
        /// Output.
        out: Slot,
        /// First operand.
        a: Slot,
        /// Second operand.
        b: Slot,
    },
    /// `out^[k] = a^[k] − b^[k]`.
    Sub {
        /// Output.
        out: Slot,
        /// First operand.
        a: Slot,
        /// Second operand.
        b: Slot,
    },
    /// `out^[k] = Σⱼ₌₀ᵏ a^[j] b^[k−j]` (Cauchy product).
    Mul {
        /// Output.
        out: Slot,
        /// First operand.
        a: Slot,
        /// Second operand.
        b: Slot,
    },
    /// `out^[k] = a^[k] · constant^[0]`.
    Scale {
        /// Output.
        out: Slot,
        /// Series operand.
        a: Slot,
        /// Constant operand.
        constant: Slot,
    },
    /// `out = a / b`: `out^[k] = (a^[k] − Σⱼ₌₁ᵏ b^[j] out^[k−j]) / b^[0]`.
    Div {
        /// Output.
        out: Slot,
        /// Numerator.
        a: Slot,
        /// Denominator.
        b: Slot,
    },
    /// `out = a / constant`: `out^[k] = a^[k] / constant^[0]`.
    DivByConstant {
        /// Output.
        out: Slot,
        /// Numerator.
        a: Slot,
        /// Constant denominator.
        constant: Slot,
    },
    /// `out = constant / b`: `out^[k] = −(Σⱼ₌₁ᵏ b^[j] out^[k−j]) / b^[0]`.
    ConstantDiv {
        /// Output.
        out: Slot,
        /// Denominator.
        b: Slot,
    },
    /// `out = √a`: `out^[k] = (a^[k] − Σⱼ₌₁ᵏ⁻¹ out^[j] out^[k−j]) / (2 out^[0])`.
    Sqrt {
        /// Output.
        out: Slot,
        /// Operand.
        a: Slot,
    },
    /// `out = a^α` for a constant `α = exponent^[0]`:
    /// `out^[k] = Σⱼ₌₀ᵏ⁻¹ (k α − j (α + 1)) a^[k−j] out^[j] / (k a^[0])`.
    PowConstant {
        /// Output.
        out: Slot,
        /// Base.
        a: Slot,
        /// Constant exponent.
        exponent: Slot,
    },
    /// `out = eᵃ`: `out^[k] = (Σⱼ₌₁ᵏ j a^[j] out^[k−j]) / k`.
    Exp {
        /// Output.
        out: Slot,
        /// Operand.
        a: Slot,
    },
    /// `out = ln a`: `out^[k] = (k a^[k] − Σⱼ₌₁ᵏ⁻¹ j a^[k−j] out^[j]) / (k a^[0])`.
    Ln {
        /// Output.
        out: Slot,
        /// Operand.
        a: Slot,
    },
    /// `sin a` and `cos a` together: `sin^[k] = (Σⱼ₌₁ᵏ j a^[j] cos^[k−j]) / k`,
    /// `cos^[k] = −(Σⱼ₌₁ᵏ j a^[j] sin^[k−j]) / k`.
    SinCos {
        /// `sin a`.
        sin: Slot,
        /// `cos a`.
        cos: Slot,
        /// Operand.
        a: Slot,
    },
    /// `sinh a` and `cosh a` together: as [`SeriesOp::SinCos`] with `+` in both.
    SinhCosh {
        /// `sinh a`.
        sinh: Slot,
        /// `cosh a`.
        cosh: Slot,
        /// Operand.
        a: Slot,
    },
    /// `out = tan a`, `square = out²`: `out^[k] = a^[k] + (Σⱼ₌₁ᵏ j a^[j] square^[k−j]) / k`,
    /// then `square^[k]` by the Cauchy product.
    Tan {
        /// Output.
        out: Slot,
        /// Operand.
        a: Slot,
        /// Auxiliary `tan² a`.
        square: Slot,
    },
    /// `out = tanh a`, `square = out²`: `out^[k] = a^[k] − (Σⱼ₌₁ᵏ j a^[j] square^[k−j]) / k`,
    /// then `square^[k]`.
    Tanh {
        /// Output.
        out: Slot,
        /// Operand.
        a: Slot,
        /// Auxiliary `tanh² a`.
        square: Slot,
    },
    /// `out = asin a` (`sign = 1`) or `acos a` (`sign = −1`), `root = √(1 − a²)`:
    /// `root^[k]` from `root² = 1 − a²`, then
    /// `out^[k] = (sign k a^[k] − Σⱼ₌₁ᵏ⁻¹ j out^[j] root^[k−j]) / (k root^[0])`.
    Asin {
        /// Output.
        out: Slot,
        /// Operand.
        a: Slot,
        /// Auxiliary `√(1 − a²)`.
        root: Slot,
        /// Whether this is `acos` (`out' = −a'/root`).
        acos: bool,
    },
    /// `out = atan a`, `square = a²`: `square^[k]` first, then
    /// `out^[k] = (k a^[k] − Σⱼ₌₁ᵏ⁻¹ j out^[j] square^[k−j]) / (k (1 + square^[0]))`.
    Atan {
        /// Output.
        out: Slot,
        /// Operand.
        a: Slot,
        /// Auxiliary `a²`.
        square: Slot,
    },
    /// `out = atan2(y, x)`, `norm = x² + y²`: `norm^[k]` first, then
    /// `out^[k] = (Σⱼ₌₁ᵏ j (x^[k−j] y^[j] − y^[k−j] x^[j]) − Σⱼ₌₁ᵏ⁻¹ j out^[j] norm^[k−j]) / (k norm^[0])`.
    Atan2 {
        /// Output.
        out: Slot,
        /// `y`.
        y: Slot,
        /// `x`.
        x: Slot,
        /// Auxiliary `x² + y²`.
        norm: Slot,
    },
    /// `out^[k] = 0`: a constant slot read as a whole series by an op without a constant form
    /// ([`SeriesOp::Atan2`]), zeroed above order 0 before its readers.
    Zero {
        /// Output.
        out: Slot,
    },
}

/// A model's Taylor recurrences, with where the state goes in and `M` and `F` come out.
///
/// # Shapes
/// `n` degrees of freedom and `m` constraints; `coordinates`, `velocities`: `n` slots each
/// (or `None` for an input the equations do not read); `mass_matrix`: `(n + m) × (n + m)`
/// slots, **column-major**; `forcing`: `n + m` slots. A slot marked constant
/// ([`Self::constant`]) holds only order 0.
///
/// With constraints (`m > 0`) the matrix is the index-1 system's `[M Jᵀ; J 0]` and the
/// right-hand side `[F; γ]` (Haug, *Computer-Aided Kinematics and Dynamics of Mechanical
/// Systems*, §6.3), solved as a series for `[q̈; λ]` in the same way as
/// `M q̈ = F` ([`Self::multipliers`] gives `m`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TaylorProgram {
    /// Number of slots: the series a workspace holds.
    pub slots: usize,
    /// Where `qᵢ` is read (its series is written there before each order).
    pub coordinates: List<Option<Slot>>,
    /// Where `q̇ᵢ` is read.
    pub velocities: List<Option<Slot>>,
    /// Where `t` is read (`t^[0] = t₀`, `t^[1] = 1`, the rest 0).
    pub time: Option<Slot>,
    /// `M` entry by entry, column-major (`[M Jᵀ; J 0]` with constraints).
    pub mass_matrix: List<Slot>,
    /// `F` (`[F; γ]` with constraints).
    pub forcing: List<Slot>,
    /// Whether each slot is constant (its orders above 0 are never written nor read).
    pub constant: List<bool>,
    /// The operations of orders `k ≥ 1`, in order.
    pub ops: List<SeriesOp>,
    /// Derived from the fields above once, for the per-step work: must be what
    /// [`TaylorProgram::with_derived`] fills in (a program written by hand ends with
    /// `.with_derived()`; the runtime checks it in debug builds). Left at its default, the
    /// series would read no state, and the branch check would look at no root or power.
    pub derived: DerivedLists,
}

/// What a [`TaylorProgram`]'s steps read of it besides its ops, derived from its other
/// fields once ([`TaylorProgram::with_derived`]) rather than at every step (a tenth of a
/// double-pendulum step's instructions went into rebuilding these).
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct DerivedLists {
    /// `(row, column, slot)` of each entry of `M` that is not constant, row by row: the
    /// terms of `Σⱼ₌₁ᵏ M^[j] a^[k−j]` in the solve of each order (a constant entry has no
    /// `M^[j]` for `j ≥ 1`).
    pub varying_mass_entries: List<(u32, u32, Slot)>,
    /// `(slot, state index)` of each input the equations read: `qᵢ` (index `i`) then `q̇ᵢ`
    /// (index `n + i`) for each coordinate in turn.
    pub inputs: List<(Slot, u32)>,
    /// The convolutions per order of the ops: one for a product, quotient or power, two for
    /// a sine–cosine pair, …, five for `atan2` ([`TaylorProgram::unrolled_code_size`]'s `w`).
    pub convolutions: usize,
    /// The index in the ops of each op with a branch point (a square root, `asin`/`acos`'s
    /// root, a power), increasing: what the runtime's `branch_step` looks at each step, in
    /// that order (its bound on the step narrows from one to the next). A walk over every op
    /// instead was a third of the check's cost on the figure eight (40 ops, 3 powers).
    pub branch_points: List<u32>,
}

/// The orders `k = 1 …` this many that the Taylor kernels are compiled for with `k` known
/// (`eomgen_runtime::taylor::evaluate_order`, the `model!` code's `TaylorFunctions::orders`); higher orders run the same kernels with `k` a
/// variable. A step to order `p` computes the orders `k = 1 … p − 1` of the program, so
/// this serves steps to order 20, what tolerances down to 3·10⁻¹⁷ ask for (20 at the unit
/// roundoff 2.2·10⁻¹⁶): tighter tolerances than a double can hold run the variable-`k`
/// kernels. With orders to 23 (tolerances to 10⁻²⁰) the program was 15.07 MB against
/// 15.0 MB, the motion solve's unrolled variants alone 590 KB (2026-11-28).
pub const UNROLLED_ORDERS: usize = 19;

/// The stride (coefficients per slot) of a workspace whose steps run the code compiled for
/// each order: orders `0 … UNROLLED_ORDERS + 1`.
pub const UNROLLED_CAPACITY: usize = UNROLLED_ORDERS + 2;

/// The largest [`TaylorProgram::unrolled_code_size`] of a step that runs the code compiled
/// for each order (see [`TaylorProgram::unrolled_code_fits`]).
pub const UNROLLED_CODE_BUDGET: usize = 2100;

impl TaylorProgram {
    /// The size of the code compiled for each order that a step to `order` runs, in
    /// convolution terms and ops: `Σₖ₌₁^{order−1} (w k + ops)` with `w` the convolutions per
    /// order of the program's ops (one for a product, quotient or power, two for a
    /// sine–cosine pair, …, five for `atan2`).
    pub fn unrolled_code_size(&self, order: usize) -> usize {
        let w = self.derived.convolutions;
        let p = order.max(1);
        w * p * (p - 1) / 2 + self.ops.len() * (p - 1)
    }

    /// Whether a step to `order` runs the kernels compiled for each order: `order ≤`
    /// [`UNROLLED_ORDERS`]` + 1` and [`Self::unrolled_code_size`] `≤`
    /// [`UNROLLED_CODE_BUDGET`].
    ///
    /// Each order is its own code, so a step runs all of it once: past what the processor's
    /// instruction cache holds, the unrolled code is slower than the loops. Measured on one
    /// machine (2 cores, 32 KiB instruction cache; time of a run against the loops', same
    /// runs, when the programs were larger than today's): the double pendulum (24 ops,
    /// w = 12; 19 and 10 now) at orders 8, 12, 15 (sizes 504, 1056, 1596) in 0.74, 0.71, 0.75,
    /// at 18 and 20 (2244, 2736) 1.09 and 1.2× the loops' time; the figure eight (58 ops,
    /// w = 21; 40 and 15 now, its pulls formed once) at orders 8 and 12 (994, 2024) in 0.73
    /// and 0.77, at 15 and 18 (3017, 4199) 1.1×.
    pub fn unrolled_code_fits(&self, order: usize) -> bool {
        order <= UNROLLED_ORDERS + 1 && self.unrolled_code_size(order) <= UNROLLED_CODE_BUDGET
    }

    /// The program with [`Self::derived`] computed from its other fields ([`Self::derive`]).
    pub fn with_derived(mut self) -> Self {
        self.derived = self.derive();
        self
    }

    /// [`Self::derived`] as its other fields give it.
    pub fn derive(&self) -> DerivedLists {
        let k = self.forcing.len();
        let n = self.coordinates.len();
        let mut varying = Vec::new();
        for i in 0..k {
            for l in 0..k {
                let slot = self.mass_matrix[i + l * k];
                if !self.constant[slot as usize] {
                    varying.push((i as u32, l as u32, slot));
                }
            }
        }
        let mut inputs = Vec::new();
        for i in 0..n {
            if let Some(slot) = self.coordinates[i] {
                inputs.push((slot, i as u32));
            }
            if let Some(slot) = self.velocities[i] {
                inputs.push((slot, (n + i) as u32));
            }
        }
        let convolutions = self.ops.iter().map(convolutions).sum();
        let branch_points = (0..self.ops.len() as u32)
            .filter(|&i| {
                matches!(
                    self.ops[i as usize],
                    SeriesOp::Sqrt { .. } | SeriesOp::Asin { .. } | SeriesOp::PowConstant { .. }
                )
            })
            .collect();
        DerivedLists {
            varying_mass_entries: List::Owned(varying),
            inputs: List::Owned(inputs),
            convolutions,
            branch_points: List::Owned(branch_points),
        }
    }

    /// The slot of the series of the first acceleration `q̈₀` in a workspace of
    /// `slots + n + m` series: `q̈ᵢ`'s is this plus `i`, after the program's own slots, and
    /// the multiplier `λⱼ`'s this plus `n + j`.
    pub fn acceleration_slot(&self) -> Slot {
        self.slots as Slot
    }

    /// `m`, the constraints whose multipliers the series solves for with the accelerations
    /// (0 for `M q̈ = F`).
    pub fn multipliers(&self) -> usize {
        self.forcing.len().saturating_sub(self.coordinates.len())
    }

    /// The highest order `k` whose code compiled for `k` a step of this program can run: the
    /// order below the highest that [`Self::unrolled_code_fits`] (0 if none).
    pub fn highest_unrolled_order(&self) -> usize {
        (2..=UNROLLED_ORDERS + 1)
            .take_while(|&p| self.unrolled_code_fits(p))
            .last()
            .map_or(0, |p| p - 1)
    }
}

impl SeriesOp {
    /// The convolutions its kernel sums per order (see [`DerivedLists::convolutions`]): 0
    /// for an op of order `k` alone (a sum, a scaling), 1 for a product, quotient, root,
    /// power, exponential or logarithm, up to 5 for `atan2`.
    pub fn convolutions(&self) -> usize {
        convolutions(self)
    }
}

/// The convolutions per order of one op (see [`DerivedLists::convolutions`]).
fn convolutions(op: &SeriesOp) -> usize {
    match op {
        SeriesOp::Mul { .. }
        | SeriesOp::Div { .. }
        | SeriesOp::ConstantDiv { .. }
        | SeriesOp::Sqrt { .. }
        | SeriesOp::PowConstant { .. }
        | SeriesOp::Exp { .. }
        | SeriesOp::Ln { .. } => 1,
        SeriesOp::SinCos { .. }
        | SeriesOp::SinhCosh { .. }
        | SeriesOp::Tan { .. }
        | SeriesOp::Tanh { .. }
        | SeriesOp::Atan { .. } => 2,
        SeriesOp::Asin { .. } => 3,
        SeriesOp::Atan2 { .. } => 5,
        SeriesOp::Neg { .. }
        | SeriesOp::Copy { .. }
        | SeriesOp::Add { .. }
        | SeriesOp::Sub { .. }
        | SeriesOp::Scale { .. }
        | SeriesOp::DivByConstant { .. }
        | SeriesOp::Zero { .. } => 0,
    }
}

/// Why a model has no Taylor recurrences.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub enum TaylorUnsupported {
    /// The model has constraints, and its code has no recurrences for them (a model
    /// compiled by `model!`; the run-time compiler's have them).
    Constraints {
        /// How many.
        count: usize,
    },
    /// A function of the equations has no recurrence (`abs`, `sign`, `step`: piecewise, their
    /// series would not see the switch), or a power has a non-constant exponent.
    Functions {
        /// The functions, by name, each once, in order of appearance.
        names: List<Cow<'static, str>>,
    },
    /// The model was written by hand, without a program.
    NotGenerated,
    /// Contacts are closed: the Taylor method integrates a hybrid model's free phases only.
    Contacts {
        /// How many.
        count: usize,
    },
    /// The constraints are stabilised in a way the recurrences do not follow: Baumgarte's
    /// terms and the penalty's springs are not in the series of `[M Jᵀ; J 0][q̈; λ] = [F; γ]`
    /// (no stabilisation, or projection after each step, are).
    Stabilization {
        /// The stabilisation's name.
        name: Cow<'static, str>,
    },
    /// The state is in generalized speeds, `(q, u)`: the recurrences take the coordinates'
    /// rates as the state's second half, and have no series of the kinematic equations
    /// `q̇ = W(q, t) (u − Z(q, t))`.
    Speeds,
}

impl std::fmt::Display for TaylorUnsupported {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TaylorUnsupported::Constraints { count } => write!(
                f,
                "the model has {count} constraint(s), and the code `model!` compiled has no Taylor \
                 recurrences for them (load its file at run time, whose code has them)"
            ),
            TaylorUnsupported::Functions { names } => {
                let list: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
                write!(
                    f,
                    "the equations use {} which has no Taylor recurrence (a piecewise function \
                     or a power with a variable exponent)",
                    list.join(", ")
                )
            }
            TaylorUnsupported::NotGenerated => {
                write!(f, "the model has no generated Taylor recurrences")
            }
            TaylorUnsupported::Contacts { count } => write!(
                f,
                "{count} contact(s) are closed, and its series cover the free phases only"
            ),
            TaylorUnsupported::Stabilization { name } => write!(
                f,
                "its constraints can be left as they are or projected after each step \
                 (stabilisation `none` or `projection`), not stabilised by `{name}`, whose \
                 terms the recurrences do not have"
            ),
            TaylorUnsupported::Speeds => write!(
                f,
                "the state is in generalized speeds, and the recurrences have no series of \
                 the kinematic equations q' = W(q, t) (u - Z(q, t)) (take an explicit method)"
            ),
        }
    }
}

impl std::error::Error for TaylorUnsupported {}

#[cfg(test)]
mod tests {
    use super::*;

    /// A program of `products` products, `pairs` sine–cosine pairs and `others` additions
    /// (nothing but the ops is read).
    fn program(products: usize, pairs: usize, others: usize) -> TaylorProgram {
        let mut ops = Vec::new();
        ops.extend((0..products).map(|_| SeriesOp::Mul { out: 0, a: 0, b: 0 }));
        ops.extend((0..pairs).map(|_| SeriesOp::SinCos {
            sin: 0,
            cos: 0,
            a: 0,
        }));
        ops.extend((0..others).map(|_| SeriesOp::Add { out: 0, a: 0, b: 0 }));
        TaylorProgram {
            slots: 1,
            coordinates: List::Owned(vec![]),
            velocities: List::Owned(vec![]),
            time: None,
            mass_matrix: List::Owned(vec![]),
            forcing: List::Owned(vec![]),
            constant: List::Owned(vec![false]),
            ops: List::Owned(ops),
            derived: DerivedLists::default(),
        }
        .with_derived()
    }

    /// The double pendulum's program (8 products, 2 sine–cosine pairs, 14 other ops: w = 12,
    /// 24 ops): the sizes quoted in `unrolled_code_fits`' measurements, summed term by term.
    #[test]
    fn unrolled_code_size_counts_the_terms_of_each_order() {
        let p = program(8, 2, 14);
        for order in [1, 2, 8, 12, 15, 17, 18] {
            let by_order: usize = (1..order).map(|k| 12 * k + 24).sum();
            assert_eq!(p.unrolled_code_size(order), by_order, "order {order}");
        }
        assert_eq!(p.unrolled_code_size(12), 1056);
        assert!(p.unrolled_code_fits(17) && !p.unrolled_code_fits(18));
        assert_eq!(p.highest_unrolled_order(), 16);
        // A program too large for any unrolled order, and an empty one.
        assert_eq!(program(2000, 0, 0).highest_unrolled_order(), 0);
        assert_eq!(program(0, 0, 0).highest_unrolled_order(), UNROLLED_ORDERS);
    }

    /// The derived lists of a two-coordinate program whose `M₁₁` and `M₂₂` are constant
    /// and whose `q₁` the equations do not read: the varying entries row by row, the inputs
    /// that exist in state order, and the weights of its ops.
    #[test]
    fn derived_lists_follow_the_program() {
        let program = TaylorProgram {
            slots: 7,
            coordinates: List::Owned(vec![None, Some(1)]),
            velocities: List::Owned(vec![Some(2), Some(3)]),
            time: None,
            // Column-major: M₁₁ = slot 4, M₂₁ = M₁₂ = slot 5, M₂₂ = slot 6.
            mass_matrix: List::Owned(vec![4, 5, 5, 6]),
            forcing: List::Owned(vec![0, 0]),
            constant: List::Owned(vec![false, false, false, false, true, false, true]),
            ops: List::Owned(vec![
                SeriesOp::SinCos {
                    sin: 0,
                    cos: 5,
                    a: 1,
                },
                SeriesOp::Mul { out: 0, a: 2, b: 3 },
            ]),
            derived: DerivedLists::default(),
        }
        .with_derived();
        assert_eq!(
            program.derived,
            DerivedLists {
                varying_mass_entries: List::Owned(vec![(0, 1, 5), (1, 0, 5)]),
                inputs: List::Owned(vec![(2, 2), (1, 1), (3, 3)]),
                convolutions: 3,
                branch_points: List::Owned(vec![]),
            }
        );
        let rooted = TaylorProgram {
            ops: List::Owned(vec![SeriesOp::Sqrt { out: 0, a: 1 }]),
            ..program
        }
        .with_derived();
        assert_eq!(rooted.derived.branch_points, List::Owned(vec![0]));
        // Among other ops, each root and power by its index, in order.
        let mixed = TaylorProgram {
            ops: List::Owned(vec![
                SeriesOp::Mul { out: 0, a: 2, b: 3 },
                SeriesOp::Sqrt { out: 0, a: 1 },
                SeriesOp::Add { out: 0, a: 2, b: 3 },
                SeriesOp::PowConstant {
                    out: 0,
                    a: 1,
                    exponent: 2,
                },
            ]),
            ..rooted.clone()
        }
        .with_derived();
        assert_eq!(mixed.derived.branch_points, List::Owned(vec![1, 3]));
        assert_eq!(rooted.derived.convolutions, 1);
    }
}
