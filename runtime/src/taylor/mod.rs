//! Taylor series of the motion: the recurrences of a model's [`TaylorProgram`] run order by
//! order, and `M q̈ = F` solved as a series (with `m` constraints, the index-1 system
//! `[M Jᵀ; J 0][q̈; λ] = [F; γ]`, its `n + m` unknowns in place of `q̈`'s `n`, the same way).
//!
//! Rooms: where a slot's orders live, the helpers every kernel inlines (`known`, `at`, `put`,
//! `series`) and the list of the orders compiled with `k` known (`unrolled_orders!`) in
//! `slots`; the kernel of each op and their dispatch in `kernels`; the series solve of
//! `M q̈ = F` order by order in `motion`; the branch check of a step in `branch`; and here the
//! workspace, the [`TaylorFunctions`] a model hands out and [`series_of_motion`], which runs
//! them.
//!
//! With `x(t₀ + τ) = Σₖ x^[k] τᵏ` for every value of the model's program, the state
//! `y = [q; q̇]` has `q^[k+1] = q̇^[k] / (k + 1)` and `q̇^[k+1] = a^[k] / (k + 1)`, where the
//! accelerations `a = q̈` solve `M a = F` as series (the Cauchy product of `M(t) a(t) = F(t)`):
//!
//! ```text
//! M^[0] a^[k] = F^[k] − Σⱼ₌₁ᵏ M^[j] a^[k−j]
//! ```
//!
//! — one `L D Lᵀ` factorisation of `M^[0]` per step, one pair of triangular solves per order.
//! [`series_of_motion`] runs that loop over a model's generated functions (order 0: the
//! model's own evaluation, every value kept; order `k ≥ 1`: its [`SeriesOp`]s; and, for a
//! compiled model, the orders a step can run compiled for each order, fused with their
//! solves into one function), for compiled models and models compiled at run time alike.
//! Each recurrence is defined once, as the kernel of its op (`mul`, `sin_cos`, …): the `model!` macro's code calls the kernels op by
//! op with its slots as constants, the run-time model reaches them through [`apply`]
//! ([`evaluate_order`]), so both compute the same bits.
//!
//! # Source
//! Jorba & Zou, *A software package for the numerical integration of ODEs by means of
//! high-order Taylor methods*, Exp. Math. 14(1) (2005) 99–117, §2 (the recurrences);
//! Biscani & Izzo, MNRAS 504(2) (2021) 2614–2628 and heyoka's `doc/ad_notes.rst` (the
//! decomposition with hidden partners); the mass-matrix series is the quotient rule of §2
//! with a matrix denominator.

pub use eomgen_description::taylor::{
    DerivedLists, SeriesOp, Slot, TaylorProgram, TaylorUnsupported, UNROLLED_CAPACITY,
    UNROLLED_ORDERS,
};

use crate::ode::RhsError;

#[macro_use]
mod slots;
mod branch;
mod kernels;
mod motion;

pub use kernels::{
    add, apply, asin, atan, atan2, constant_div, copy, div, div_by_constant, evaluate_order, exp,
    ln, mul, neg, pow_constant, scale, sin_cos, sinh_cosh, sqrt, sub, tan_or_tanh, zero,
};
pub use motion::{FactorForm, Lanes, MotionLayout, MotionSolve, motion_order, motion_order_at};
use motion::{Factors, accelerations, factor_mass};

/// Whether the Taylor method's steps run in their copy compiled for AVX2 and FMA: on an
/// x86-64 processor that has both (detected once), unless [`set_host_features`] turned it off;
/// never elsewhere.
///
/// The copy covers each compiled model's fused orders (the `model!` macro's `TaylorFunctions::orders`,
/// in optimised builds), the rest of [`series_of_motion`], and the Taylor method's Horner's
/// rule and step rule: the same Rust code compiled a second time with those instruction sets
/// enabled — three-operand VEX encodings, fewer register copies — in a binary that still runs
/// on any x86-64. Rust neither contracts a product and a sum into a fused multiply–add nor
/// reassociates, so both copies compute the same bits (`tests/taylor_coefficients.rs`
/// compares them). Orders above the fused ones (`TaylorFunctions::order`, the run-time model's
/// `evaluate_order`) run the baseline code; a model compiled at run time gets the host's
/// instructions from Cranelift anyway. On the double pendulum (AMD EPYC, Zen 3) a run took
/// 0.73–0.94 of the time at tolerances 1e-4 to 1e-12; on a processor with AVX-512 the whole
/// crate compiled for it had left the Taylor method's times unchanged (docs/performance.md).
#[inline]
pub fn host_features() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        match HOST_FEATURES.load(std::sync::atomic::Ordering::Relaxed) {
            ENABLED => true,
            DISABLED => false,
            _ => detect_host_features(),
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// [`host_features`]' first call: detects AVX2 and FMA and records the answer.
#[cfg(target_arch = "x86_64")]
#[cold]
#[inline(never)]
fn detect_host_features() -> bool {
    use std::sync::atomic::Ordering;
    let found = std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma");
    let state = if found { ENABLED } else { DISABLED };
    // A concurrent `set_host_features(false)` wins over the detection.
    let _ = HOST_FEATURES.compare_exchange(UNKNOWN, state, Ordering::Relaxed, Ordering::Relaxed);
    HOST_FEATURES.load(Ordering::Relaxed) == ENABLED
}

/// Turns the copy of [`host_features`] off (`false`: every Taylor step runs the baseline
/// code from then on, in the whole process) or back to what the processor has (`true`): for
/// comparing the two copies' bits and cost. The results are the same either way.
pub fn set_host_features(enabled: bool) {
    #[cfg(target_arch = "x86_64")]
    {
        let state = if enabled { UNKNOWN } else { DISABLED };
        HOST_FEATURES.store(state, std::sync::atomic::Ordering::Relaxed);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = enabled;
}

/// [`host_features`]' answer: [`UNKNOWN`] until the first call.
#[cfg(target_arch = "x86_64")]
static HOST_FEATURES: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(UNKNOWN);
#[cfg(target_arch = "x86_64")]
const UNKNOWN: u8 = 0;
#[cfg(target_arch = "x86_64")]
const ENABLED: u8 = 1;
#[cfg(target_arch = "x86_64")]
const DISABLED: u8 = 2;

/// The buffers of [`series_of_motion`], allocated on first use and grown when a higher order
/// is asked for (never per step).
#[derive(Debug, Clone, Default)]
pub struct TaylorWorkspace {
    capacity: usize,
    /// The program's slots, then one per acceleration `q̈ᵢ` and one per multiplier `λⱼ`
    /// ([`TaylorProgram::acceleration_slot`]).
    series: Vec<f64>,
    lower: Vec<f64>,
    pivots: Vec<f64>,
    inverse_pivots: Vec<f64>,
    /// `(row, column, L[row][column])` for each entry of `L` below the diagonal that is not
    /// zero, row by row.
    nonzeros: Vec<(u32, u32, f64)>,
    rhs: Vec<f64>,
    /// `1 / (k + 1)` for `k = 0 … capacity − 1`.
    reciprocals: Vec<f64>,
    /// A run-time backend's scratch ([`MotionSolve::lanes`]), kept between steps.
    lanes: Vec<Lanes>,
    /// The slots of a constant `M` (no entry reads the state or the time) whose factors
    /// `lower`, `pivots`, `inverse_pivots` and `nonzeros` hold, entry by entry as the
    /// program's `mass_matrix` lists them; empty when they hold another's. A step whose `M`
    /// has these slots, with the values in `factored_values`, reuses the factors instead of
    /// factoring again (11 % of a figure-eight step at order 5 went into factoring its
    /// constant diagonal `M`).
    factored_mass: Vec<Slot>,
    /// The distinct slots of `factored_mass` with their values' bits when factored: the
    /// figure eight's 36 entries are two slots (`m` and 0), so the test of each step reads
    /// two values rather than 36 (4 % of its step's instructions: 363 of 8,851 at 10⁻⁹).
    factored_values: Vec<(Slot, u64)>,
    /// The coordinates `n` of the program the factors are for: of `[M Jᵀ; J 0]` the first `n`
    /// pivots are positive, the rest negative, so the same bits factor otherwise for another
    /// `n`.
    coordinates: usize,
    /// Whether the program of the last series has ops whose branch [`branch_step`] checks.
    branch_points: bool,
}

impl TaylorWorkspace {
    /// Empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether the program of the last [`series_of_motion`] into this workspace has ops whose
    /// branch [`branch_step`] checks (square roots, powers with a constant exponent, `asin`
    /// and `acos`; `false` before any series): without, `branch_step` returns the step it is
    /// given, and a step need not ask.
    pub(crate) fn has_branch_points(&self) -> bool {
        self.branch_points
    }

    /// Buffers for `order`: grown when a higher order or another program asks for more,
    /// never shrunk (the stride `capacity` is the kernels' argument, so a longer one serves a
    /// lower order), so a method switching order between steps does not reallocate. The
    /// stride is [`UNROLLED_CAPACITY`], the one the kernels compiled for each order run with,
    /// when [`TaylorProgram::unrolled_code_fits`] or the model has `fused` orders (and
    /// `order` is within the stride), else any other (so that they do not).
    /// `unknowns` is the series solve's: `n`, or `n + m` with `m` constraints.
    ///
    /// In line, the usual step (nothing to resize) in a few comparisons; the rest out of line
    /// (68 instructions a step for the double pendulum as one function).
    #[inline(always)]
    fn fit(&mut self, program: &TaylorProgram, unknowns: usize, order: usize, fused: usize) {
        let n = unknowns;
        // With fused orders (a compiled model's), those run compiled for each order and the
        // rest as loops at the same stride, whatever the order (to its limit): the fused
        // code alone is what must fit the instruction cache.
        let unrolled =
            (fused > 0 && order <= UNROLLED_ORDERS + 1) || program.unrolled_code_fits(order);
        let capacity = if unrolled {
            UNROLLED_CAPACITY
        } else if self.capacity != UNROLLED_CAPACITY && self.capacity > order {
            self.capacity
        } else {
            // Any stride but the unrolled code's.
            (order + 1).max(UNROLLED_CAPACITY + 1)
        };
        let size = (program.slots + n) * capacity;
        self.branch_points = !program.derived.branch_points.is_empty();
        // `pivots`, `inverse_pivots` and `rhs` are resized with `lower`, to `n`.
        if self.capacity == capacity
            && self.series.len() == size
            && self.lower.len() == n * n
            && self.rhs.len() == n
            && self.coordinates == program.coordinates.len()
        {
            return;
        }
        self.refit(program, n, capacity, size);
    }

    /// [`Self::fit`]'s resizing, for a new program, size or stride.
    #[cold]
    #[inline(never)]
    fn refit(&mut self, program: &TaylorProgram, n: usize, capacity: usize, size: usize) {
        if self.capacity != capacity || self.series.len() != size {
            // The contents need not survive (each step writes before it reads): a stride
            // switching between steps reuses the allocations.
            self.capacity = capacity;
            self.series.clear();
            self.series.resize(size, 0.0);
            self.reciprocals.clear();
            self.reciprocals
                .extend((0..capacity).map(|k| 1.0 / (k + 1) as f64));
        }
        if self.lower.len() != n * n || self.coordinates != program.coordinates.len() {
            self.factored_mass.clear();
            self.factored_values.clear();
        }
        self.coordinates = program.coordinates.len();
        self.lower.resize(n * n, 0.0);
        self.pivots.resize(n, 0.0);
        self.inverse_pivots.resize(n, 0.0);
        self.rhs.resize(n, 0.0);
    }
}

/// A model's Taylor method: its recurrences ([`TaylorProgram`]) and the code that runs them,
/// which [`series_of_motion`] drives. A model hands it out through one accessor,
/// [`MechanicalSystem::taylor`](crate::MechanicalSystem::taylor) (or
/// [`DynMechanicalSystem::taylor`](crate::DynMechanicalSystem::taylor)), the way it hands
/// out its description. The `model!` macro implements it for the struct it generates
/// (order 0 as straight-line code, every op's kernel inlined with its slots as constants, and
/// in optimised builds the fused orders); a model compiled at run time implements it with
/// its tape interpreted or compiled, and its orders on the kernels or compiled by Cranelift.
/// Every implementation computes the same bits.
///
/// Source: Jorba & Zou (2005, §2) for the recurrences; the layout of the series is
/// [`series_of_motion`]'s.
pub trait TaylorFunctions {
    /// The program: its ops, slots and the slots of the state, `M` and `F`.
    fn program(&self) -> &TaylorProgram;

    /// Order 0 of every slot of [`Self::program`] into `series` (slot `s` at
    /// `s · capacity`): the model's own evaluation of `M` and `F`, reading `q`, `q̇` and `t`
    /// from their slots, every intermediate value kept.
    fn order_zero(&self, capacity: usize, series: &mut [f64]);

    /// Order `k ≥ 1` of every slot the program's ops write (the slots that an op, `M` or `F`
    /// reads; others keep what the workspace held), from the orders below `k`. The default
    /// runs the program's ops on the kernels ([`evaluate_order`]).
    fn order(&self, k: usize, capacity: usize, series: &mut [f64]) {
        evaluate_order(&self.program().ops, k, capacity, series);
    }

    /// [`motion_order`] for `k = 0`, then orders `k = 1, 2, …` of the ops' slots, each
    /// followed by its [`motion_order`], stopping before `order`; returns the first order it
    /// did not compute, from which [`series_of_motion`] goes on one order at a time. The
    /// `model!` macro's code (when `solve` has the unrolled stride,
    /// [`MotionSolve::unrolled`]; optimised builds compile each order
    /// `k ≤ TaylorProgram::highest_unrolled_order` for that `k`) passes the values of an
    /// order's ops and solve in registers and lists its slots as constants; a run-time model's
    /// orders compiled by Cranelift do the same. The same bits as one order at a time. The
    /// default computes none and returns 0.
    fn orders(
        &self,
        solve: &mut MotionSolve<'_>,
        order: usize,
        series: &mut [f64],
        out: &mut [f64],
    ) -> usize {
        let _ = (solve, order, series, out);
        0
    }

    /// The highest order `k` that [`Self::orders`] computes when `solve` has the unrolled
    /// stride (0, the default, when it computes none). A step to a higher order then runs
    /// those orders fused and the rest one at a time at the same stride.
    fn fused_orders(&self) -> usize {
        0
    }
}

with_host_features! {
    /// The Taylor coefficients of the motion through `(t, y)`, `y = [q; q̇]` (`2n` entries), up
    /// to `order`: `out[k · 2n + i] = yᵢ^[k]` for `k = 0 … order` (so `out[..2n] = y`).
    ///
    /// With `m` constraints the program's matrix and right-hand side are `[M Jᵀ; J 0]` and
    /// `[F; γ]` ([`TaylorProgram`]), and each order solves for `[q̈; λ]`.
    ///
    /// # Errors
    /// [`RhsError::SingularMassMatrix`] if `M(q, t)` is not positive definite;
    /// [`RhsError::SingularConstraintMatrix`] if, with constraints, `J` has dependent rows
    /// (`−J M⁻¹ Jᵀ` is not negative definite);
    /// [`RhsError::NonFinite`] with the component of the first coefficient that is not finite.
    ///
    /// # Panics
    /// If `y` has fewer than `2n` entries or `out` fewer than `(order + 1) · 2n`.
    pub fn series_of_motion(
        model: &(impl TaylorFunctions + ?Sized),
        workspace: &mut TaylorWorkspace,
        t: f64,
        y: &[f64],
        order: usize,
        out: &mut [f64],
    ) -> Result<(), RhsError> {
        series_in(model, workspace, t, y, order, out)
    }
}

/// [`series_of_motion`]'s body, inlined into its two copies.
#[inline(always)]
fn series_in(
    model: &(impl TaylorFunctions + ?Sized),
    workspace: &mut TaylorWorkspace,
    t: f64,
    y: &[f64],
    order: usize,
    out: &mut [f64],
) -> Result<(), RhsError> {
    let program = model.program();
    let n = program.coordinates.len();
    let dim = 2 * n;
    // The unknowns of each order: `q̈`, then the multipliers `λ` of a constrained model.
    let unknowns = program.forcing.len();
    workspace.fit(program, unknowns, order, model.fused_orders());
    let c = workspace.capacity;
    let TaylorWorkspace {
        series: s,
        lower,
        pivots,
        inverse_pivots,
        nonzeros,
        rhs,
        reciprocals,
        lanes,
        factored_mass,
        factored_values,
        ..
    } = workspace;
    debug_assert!(
        program.derived == program.derive(),
        "TaylorProgram::derived is not with_derived()'s"
    );
    let inputs = &program.derived.inputs;
    let out = &mut out[..(order + 1) * dim];
    out[..dim].copy_from_slice(&y[..dim]);
    if order == 0 {
        return match out.iter().position(|v| !v.is_finite()) {
            Some(at) => Err(RhsError::NonFinite { index: at }),
            None => Ok(()),
        };
    }
    // Order 0: the state, t, the model's own evaluation and M⁰'s factors.
    for &(slot, index) in inputs.iter() {
        s[slot as usize * c] = y[index as usize];
    }
    if let Some(slot) = program.time {
        s[slot as usize * c] = t;
    }
    model.order_zero(c, s);
    let mass = |e: usize| s[program.mass_matrix[e] as usize * c];
    let factors = Factors {
        unknowns,
        positive: n,
        lower,
        pivots,
        inverse_pivots,
        nonzeros,
    };
    if program.derived.varying_mass_entries.is_empty() {
        // A constant M: factored again only when its entries changed (new parameters).
        let slots = &program.mass_matrix[..unknowns * unknowns];
        let same = factored_mass[..] == *slots
            && factored_values
                .iter()
                .all(|&(slot, bits)| s[slot as usize * c].to_bits() == bits);
        if !same {
            factored_mass.clear();
            factored_values.clear();
            factor_mass(mass, factors)?;
            factored_mass.extend_from_slice(slots);
            let mut distinct = slots.to_vec();
            distinct.sort_unstable();
            distinct.dedup();
            factored_values.extend(
                distinct
                    .into_iter()
                    .map(|slot| (slot, s[slot as usize * c].to_bits())),
            );
        }
    } else {
        // The factors become another M's.
        factored_mass.clear();
        factored_values.clear();
        factor_mass(mass, factors)?;
    }
    let layout = MotionLayout {
        forcing: &program.forcing,
        coupled: &program.derived.varying_mass_entries,
        inputs,
        time: program.time,
        accelerations: program.acceleration_slot(),
    };
    let mut solve = MotionSolve {
        n: unknowns,
        coordinates: n,
        c,
        // A factor with a zero below its diagonal is solved over the list of its non-zero
        // entries (faster for a sparse one: the figure eight's diagonal M; and the dense
        // loops never meet a zero, whose `b − 0·x` would not be `b` to the bit for `b = −0`
        // or `x` infinite). With constraints, always the sparse solve: the dense solve's unknowns are `q̈`
        // alone.
        dense: unknowns == n && 2 * nonzeros.len() >= n * n.saturating_sub(1),
        nonzeros,
        lower,
        inverse_pivots,
        reciprocals,
        rhs,
        lanes,
    };
    // The model's fused orders (compiled models with the unrolled stride), then the rest one
    // order at a time: order k of the ops (none at 0), of q̈, and order k + 1 of the state.
    let from = model.orders(&mut solve, order, s, out);
    for k in from..order {
        if k > 0 {
            model.order(k, c, s);
        }
        accelerations(&layout, &mut solve, k, s, out);
    }
    all_finite(out, dim)
}

/// `Ok` when every coefficient in `out` is finite, else the component (of `dim`) of the first
/// that is not ([`first_non_finite`](crate::ode::first_non_finite), in line: part of the hot
/// step, in its copy for the host's instruction set).
#[inline(always)]
fn all_finite(out: &[f64], dim: usize) -> Result<(), RhsError> {
    match crate::ode::first_non_finite(out) {
        Some(at) => Err(RhsError::NonFinite { index: at % dim }),
        None => Ok(()),
    }
}

/// The largest step `τ ≤ h` over which the series of the last [`series_of_motion`] into
/// `workspace` (of `program`, to `order`) stay on the principal branch of every square root
/// (`Sqrt`, and the `√(1 − a²)` of `Asin`) and of every power with a non-integer exponent.
///
/// A root of a near-perfect square hides its branch point from the series: `√(u² + δ²)`
/// with `δ` tiny has coefficients that read as those of `u`, so the radius of convergence
/// estimated from the last orders is `u`'s, and a step through `u = 0` continues the series
/// as `u` — negative — where the root is `|u|`. This is the speed `√(ẋ² + ẏ²)` of a
/// quadratic drag at the top of a vertical throw (the drag would push along the motion on
/// the way down), `(ẋ² + ẏ²)^{3/2}` likewise, and `acos(cos q)` at `q = 0`.
///
/// For each such op, `f = g^α`, whose argument can come near 0 in the step
/// (`Σₖ₌₁ |gᵏ| hᵏ ≥ g⁰/2`; for `Asin`'s root, whose argument has no series of its own, when
/// `Σₖ₌₁ |fᵏ| hᵏ ≥ f⁰`), the step is sampled at
/// 16 points: at the first where `f` or `g` has left its sign at `τ = 0`, or `f` is no longer
/// `g^α` to 10⁻³ of `max(|f|, |f⁰|)` (near a hidden branch point the higher orders of `f`
/// are rounding errors divided by powers of `f⁰`), or either is not finite, the point is
/// located by bisection (to `h / 2³⁴`) and the step is half of it. Halving toward that
/// point each step, the method either reaches where the branch point shows in the
/// coefficients (`δ` not tiny: small steps pass it) or its step falls below the smallest
/// usable one — the motion is not analytic there, and the run ends with
/// [`StepSizeTooSmall`](crate::IntegrationError::StepSizeTooSmall) at that time. Between
/// samples nothing is checked.
///
/// The result is unspecified (it may panic) unless `workspace` holds the series of
/// `program` to `order` from the last [`series_of_motion`].
pub fn branch_step(
    program: &TaylorProgram,
    workspace: &TaylorWorkspace,
    order: usize,
    h: f64,
) -> f64 {
    branch::largest_step(program, &workspace.series, workspace.capacity, order, h)
}
