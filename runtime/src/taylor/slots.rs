//! Where a program's series live: slot `s`'s coefficients at `s · c` in one buffer of stride
//! `c` (the workspace's capacity). The helpers every kernel and every order's solve inline,
//! and the list of the orders compiled with `k` known.

use eomgen_description::taylor::{Slot, UNROLLED_CAPACITY};

/// The series of one slot: its `capacity` coefficients.
#[inline(always)]
pub(super) fn series(s: &[f64], capacity: usize, slot: Slot) -> &[f64] {
    let start = slot as usize * capacity;
    &s[start..start + capacity]
}

/// `$m!($($arg)*; 1 2 … 19)`: the orders compiled with `k` known
/// ([`UNROLLED_ORDERS`](super::UNROLLED_ORDERS)), one list for every dispatch on the order.
macro_rules! unrolled_orders {
    ($m:ident $(, $arg:tt)*) => {{
        const _: () = assert!($crate::taylor::UNROLLED_ORDERS == 19);
        $m!($($arg)*; 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19)
    }};
}

/// The order and the stride a kernel computes with: `(K, UNROLLED_CAPACITY)` when `K` is not
/// 0, else `(k, c)`.
///
/// [`evaluate_order`](super::evaluate_order) (the run-time model's orders) and the `model!`
/// macro's `TaylorFunctions::orders` in optimised builds pick `K = k` for
/// `k ≤` [`UNROLLED_ORDERS`](super::UNROLLED_ORDERS) when the workspace's stride is
/// [`UNROLLED_CAPACITY`] (as [`series_of_motion`](super::series_of_motion)'s is when
/// [`TaylorProgram::unrolled_code_fits`](super::TaylorProgram::unrolled_code_fits), or the
/// model has fused orders): the sums then have
/// a known number of terms and unroll into straight-line code, and every coefficient is at
/// a known offset, so the compiler passes an op's result to the next in a register instead
/// of through memory. Both variants run the same operations in the same order, so they
/// compute the same bits.
#[inline(always)]
pub(super) const fn known<const K: usize>(k: usize, c: usize) -> (usize, usize) {
    debug_assert!(K == 0 || (k == K && c == UNROLLED_CAPACITY));
    if K == 0 {
        (k, c)
    } else {
        (K, UNROLLED_CAPACITY)
    }
}

/// Order `i` of `slot`, in a workspace of stride `c`.
#[inline(always)]
pub(super) fn at(s: &[f64], c: usize, slot: Slot, i: usize) -> f64 {
    s[slot as usize * c + i]
}

/// Writes `v` as order `k` of `slot`, in a workspace of stride `c`.
#[inline(always)]
pub(super) fn put(s: &mut [f64], c: usize, slot: Slot, k: usize, v: f64) {
    s[slot as usize * c + k] = v;
}
