//! The Taylor method of a run-time model ([`TaylorFunctions`]): order 0 and the orders
//! compiled together once they pay ([`Code::taylor_orders`]), the runtime's kernels before.

use std::borrow::Cow;

use eomgen_runtime::taylor::{
    DerivedLists, MotionLayout, MotionSolve, TaylorFunctions, TaylorProgram, UNROLLED_CAPACITY,
};

use super::JitModel;
use crate::interpret;
use crate::taylor::{FACTOR_DENSE, FACTOR_DIAGONAL, FACTOR_SMALL, PairLanes};

/// The program of no model: what [`TaylorFunctions::program`] of a [`JitModel`] without
/// recurrences would read ([`Recurrences`], which [`DynMechanicalSystem::taylor`] never hands
/// out for such a model).
static EMPTY_PROGRAM: TaylorProgram = TaylorProgram {
    slots: 0,
    coordinates: Cow::Borrowed(&[]),
    velocities: Cow::Borrowed(&[]),
    time: None,
    mass_matrix: Cow::Borrowed(&[]),
    forcing: Cow::Borrowed(&[]),
    constant: Cow::Borrowed(&[]),
    ops: Cow::Borrowed(&[]),
    derived: DerivedLists {
        varying_mass_entries: Cow::Borrowed(&[]),
        inputs: Cow::Borrowed(&[]),
        convolutions: 0,
        branch_points: false,
    },
};

/// A [`JitModel`] that has recurrences, as its Taylor method ([`TaylorFunctions`]):
/// [`DynMechanicalSystem::taylor`] hands the model out as this type only then, so that no
/// caller runs the Taylor method of a model without recurrences.
#[repr(transparent)]
pub(super) struct Recurrences(JitModel);

impl Recurrences {
    /// `model` as its Taylor method (which reads [`EMPTY_PROGRAM`] without recurrences).
    pub(super) fn of(model: &JitModel) -> &Self {
        // SAFETY: `Recurrences` is `repr(transparent)` over `JitModel`: the same layout.
        unsafe { &*std::ptr::from_ref(model).cast::<Self>() }
    }
}

/// The model's Taylor method: order 0 compiled with the orders (at their stride) or interpreted, orders on
/// the runtime's kernels (the trait's default `order`, the definitions the compiled model's
/// code inlines) until they are compiled ([`Code::taylor_orders`]); the same bits.
impl TaylorFunctions for Recurrences {
    fn program(&self) -> &TaylorProgram {
        match &self.0.code.taylor {
            Ok(plan) => &plan.program,
            // Not handed out without a plan.
            Err(_) => &EMPTY_PROGRAM,
        }
    }
    fn order_zero(&self, capacity: usize, series: &mut [f64]) {
        if let Ok(plan) = &self.0.code.taylor {
            // Compiled with the orders (at their stride), else interpreted: the same bits.
            if let Some(Some(orders)) = self.0.code.taylor_orders.get()
                && capacity == UNROLLED_CAPACITY
                && series.len() >= plan.order_zero.instructions.len() * UNROLLED_CAPACITY
            {
                // SAFETY: `series` holds every instruction's slot at the stride of 25
                // (checked above) and the caller has written the inputs' order 0;
                // `parameters` holds the model's parameters, the count the code was
                // compiled for.
                unsafe { (orders.order_zero)(series.as_mut_ptr(), self.0.parameters.as_ptr()) };
                return;
            }
            interpret::order_zero_in_place(&plan.order_zero, &self.0.parameters, capacity, series);
        }
    }
    fn orders(
        &self,
        solve: &mut MotionSolve<'_>,
        order: usize,
        series: &mut [f64],
        out: &mut [f64],
    ) -> usize {
        let (Ok(plan), Some(orders)) = (&self.0.code.taylor, self.0.code.taylor_orders()) else {
            return 0;
        };
        let program = &plan.program;
        let n = program.coordinates.len();
        // The code's offsets assume the stride of 25 and every slot present, and the orders
        // it computes (below `order`, to `highest`) write `out` to the next one.
        let computed = order.min(orders.highest + 1);
        if !solve.unrolled()
            || series.len() < (program.slots + n) * UNROLLED_CAPACITY
            || out.len() < (computed + 1) * 2 * n
        {
            return 0;
        }
        // With a diagonal factor, or any of `n ≤ 6`, the code solves in line (the same
        // operations as `motion_order`'s), else it calls `solve_order`.
        let (lower, inverse_pivots, mode) = match (solve.small_factor(), solve.diagonal_factor()) {
            (_, Some(inverse)) if inverse.len() == n => {
                (std::ptr::null(), inverse.as_ptr(), FACTOR_DIAGONAL)
            }
            (Some((lower, inverse)), _) if lower.len() == n * n && inverse.len() == n => {
                let mode = if solve.dense_factor().is_some() {
                    FACTOR_DENSE
                } else {
                    FACTOR_SMALL
                };
                (lower.as_ptr(), inverse.as_ptr(), mode)
            }
            _ => (std::ptr::null(), std::ptr::null(), 0),
        };
        let mut context = OrderContext {
            layout: MotionLayout {
                forcing: &program.forcing,
                coupled: &program.derived.varying_mass_entries,
                inputs: &program.derived.inputs,
                time: program.time,
                accelerations: program.acceleration_slot(),
            },
            solve,
            series: series.as_mut_ptr(),
            series_len: series.len(),
            out: out.as_mut_ptr(),
            out_len: out.len(),
        };
        thread_local! {
            /// The compiled orders' scratch ([`crate::taylor::PairScratch`]), kept between
            /// calls on this thread.
            static SCRATCH: std::cell::RefCell<Vec<PairLanes>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let ran = SCRATCH.try_with(|scratch| {
            let Ok(mut scratch) = scratch.try_borrow_mut() else {
                return false;
            };
            if scratch.len() < orders.scratch_units {
                scratch.resize(orders.scratch_units, PairLanes::default());
            }
            let scratch = scratch.as_mut_ptr();
            for function in &orders.orders[..computed] {
                // SAFETY: `series` holds every slot at the stride of 25 with the orders below
                // `k` computed (by the calls before this one), and `out` every order the code
                // writes (checked above); `lower` and `inverse_pivots`, when not null, hold
                // `n × n` and `n` values that nothing writes during the call; `solve_order` is
                // called with the context built for it; `scratch` holds the units the orders
                // use, with the orders below `k` written by the calls before; `series`, `out`
                // and `scratch` are not used otherwise until the call returns.
                let status = unsafe {
                    function(
                        context.series,
                        (&raw mut context).cast::<u8>(),
                        solve_order,
                        context.out,
                        lower,
                        inverse_pivots,
                        mode,
                        scratch,
                    )
                };
                if status != 0 {
                    return false;
                }
            }
            true
        });
        if ran != Ok(true) {
            return 0;
        }
        computed
    }
    fn fused_orders(&self) -> usize {
        // None before they are compiled: until then the workspace's stride follows the
        // kernels' rule (`TaylorProgram::unrolled_code_fits`), as for a model without them.
        self.0
            .code
            .taylor_orders
            .get()
            .and_then(Option::as_ref)
            .map_or(0, |orders| orders.highest)
    }
}

/// What the compiled Taylor orders pass to [`solve_order`] between orders.
struct OrderContext<'a, 'b> {
    layout: MotionLayout<'a>,
    solve: &'a mut MotionSolve<'b>,
    series: *mut f64,
    series_len: usize,
    out: *mut f64,
    out_len: usize,
}

/// Order `k` of `M a = F` for the compiled Taylor orders
/// ([`eomgen_runtime::taylor::motion_order_at`]); non-zero if it panicked (the orders then
/// stop and report none computed, and the step computes them again by the runtime's
/// kernels: a panic must not unwind through the compiled code).
extern "C" fn solve_order(context: *mut u8, k: usize) -> u8 {
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        // SAFETY: `context` is the `OrderContext` of the `orders` call in progress,
        // whose `series` and `out` are exclusively lent to this call chain.
        let context = unsafe { &mut *context.cast::<OrderContext<'_, '_>>() };
        let series = unsafe { std::slice::from_raw_parts_mut(context.series, context.series_len) };
        let out = unsafe { std::slice::from_raw_parts_mut(context.out, context.out_len) };
        eomgen_runtime::taylor::motion_order_at(&context.layout, context.solve, k, series, out);
    }));
    u8::from(result.is_err())
}
