//! The stage sums of the explicit Runge–Kutta steppers, `y + h Σⱼ wⱼ kⱼ`, with copies for
//! the small dimensions of most mechanisms whose accumulators stay in registers.

/// `out = Σⱼ wⱼ kⱼ` over the stages that have a weight (zero weights are skipped), where stage
/// 0 is `first` and stage `j ≥ 1` is row `j − 1` of `k` (rows of `dim`).
///
/// The increment is summed on its own before it is added to `y` (see [`combine`]), so that
/// small stage contributions are not rounded against `|y|` one at a time.
///
/// Summed component by component with each sum in a register: summing stage by stage into
/// `out` makes every addition wait for the previous stage's store to memory, which cost more
/// than the right-hand side itself on small systems (measured on the double pendulum).
pub(in crate::integrate) fn weighted_sum(
    out: &mut [f64],
    weights: &[f64],
    first: &[f64],
    k: &[f64],
    dim: usize,
) {
    // Small systems (most mechanisms) get a copy with the dimension fixed at compile time:
    // the accumulators live in registers (one vector register for dim 4) and the loops are
    // unrolled, which on the double pendulum halved the time spent outside the right-hand side.
    match dim {
        1 => weighted_sum_fixed::<1>(out, weights, first, k),
        2 => weighted_sum_fixed::<2>(out, weights, first, k),
        3 => weighted_sum_fixed::<3>(out, weights, first, k),
        4 => weighted_sum_fixed::<4>(out, weights, first, k),
        6 => weighted_sum_fixed::<6>(out, weights, first, k),
        8 => weighted_sum_fixed::<8>(out, weights, first, k),
        _ => weighted_sum_any(out, weights, first, k, dim),
    }
}

/// [`weighted_sum`] for `D` components (`out`, `first` of length `D`, `k` rows of `D`).
#[inline(always)]
fn weighted_sum_fixed<const D: usize>(out: &mut [f64], weights: &[f64], first: &[f64], k: &[f64]) {
    out[..D].copy_from_slice(&sum_fixed::<D>(weights, first, k));
}

/// `Σⱼ wⱼ kⱼ` for `D` components, accumulated in an array the compiler keeps in registers.
#[inline(always)]
pub(in crate::integrate) fn sum_fixed<const D: usize>(
    weights: &[f64],
    first: &[f64],
    k: &[f64],
) -> [f64; D] {
    let mut acc = [0.0f64; D];
    let Some((&w0, rest)) = weights.split_first() else {
        return acc;
    };
    // Sliced to `D` so that the indexing below needs no bounds checks.
    let first = &first[..D];
    if w0 != 0.0 {
        for i in 0..D {
            acc[i] = w0 * first[i];
        }
    }
    for (&w, kj) in rest.iter().zip(k.chunks_exact(D)) {
        if w != 0.0 {
            for i in 0..D {
                acc[i] += w * kj[i];
            }
        }
    }
    acc
}

/// [`weighted_sum`] for any dimension.
fn weighted_sum_any(out: &mut [f64], weights: &[f64], first: &[f64], k: &[f64], dim: usize) {
    let Some((&w0, rest)) = weights.split_first() else {
        out.fill(0.0);
        return;
    };
    // `out` has `dim` components, so the loop (and the chunking) runs only for `dim ≥ 1`.
    for (i, (o, &f)) in out.iter_mut().zip(first).enumerate() {
        let mut acc = if w0 == 0.0 { 0.0 } else { w0 * f };
        for (&w, kj) in rest.iter().zip(k.chunks_exact(dim)) {
            if w != 0.0 {
                acc += w * kj[i];
            }
        }
        *o = acc;
    }
}

/// `error / scale`, the weighted error of one component, by the multiplication
/// `error · inverse` with `inverse = 1/scale`.
///
/// The reciprocal depends only on the ends of the step, so it is formed while the last stage
/// is evaluated, and the error, which waits for that stage, then waits for a multiplication
/// instead of a division (on the path from the last stage to the next step's first). Where
/// the reciprocal overflows (a pure relative tolerance, `atol = 0`, on a component below
/// ~1e-308 in magnitude) the division is taken instead, so that the error stays finite there
/// (measured: ẏ = −y with rtol 1e-6, atol 0 fails with a step-size underflow near t = 697
/// without it). A zero error counts as zero even where the scale is zero (rtol only, y = 0);
/// a non-zero error there is infinitely large, and the step is rejected.
#[inline(always)]
pub(in crate::integrate) fn error_ratio(error: f64, scale: f64, inverse: f64) -> f64 {
    if error == 0.0 {
        0.0
    } else if inverse.is_finite() {
        error * inverse
    } else {
        error / scale
    }
}

/// `out = y + h Σⱼ wⱼ kⱼ`.
pub(in crate::integrate) fn combine(
    out: &mut [f64],
    y: &[f64],
    h: f64,
    weights: &[f64],
    first: &[f64],
    k: &[f64],
) {
    match y.len() {
        2 => combine_fixed::<2>(out, y, h, weights, first, k),
        4 => combine_fixed::<4>(out, y, h, weights, first, k),
        6 => combine_fixed::<6>(out, y, h, weights, first, k),
        8 => combine_fixed::<8>(out, y, h, weights, first, k),
        _ => {
            weighted_sum(out, weights, first, k, y.len());
            for (o, &yi) in out.iter_mut().zip(y) {
                *o = yi + h * *o;
            }
        }
    }
}

/// [`combine`] for `D` components, the sum and the update in registers.
#[inline(always)]
fn combine_fixed<const D: usize>(
    out: &mut [f64],
    y: &[f64],
    h: f64,
    weights: &[f64],
    first: &[f64],
    k: &[f64],
) {
    let sum = sum_fixed::<D>(weights, first, k);
    write_update::<D>(out, y, h, &sum);
}

/// `out = y + h · sum` for `D` components, written two at a time.
///
/// What is written here is read back at once by the right-hand side, which
/// ([`FirstOrder::rhs`](crate::OdeSystem::rhs)) loads its state in 16-byte halves; a load is
/// served from the store buffer only if it lies within one earlier store, so eight-byte
/// stores of single components stall every stage until they reach the cache. Left to itself
/// the compiler wrote single components once the tableau was folded into the stage sums, and
/// DOP853 on the double pendulum ran 15–27 % slower for it.
#[inline(always)]
pub(in crate::integrate) fn write_update<const D: usize>(
    out: &mut [f64],
    y: &[f64],
    h: f64,
    sum: &[f64; D],
) {
    let (out, y) = (&mut out[..D], &y[..D]);
    for j in 0..D / 2 {
        let i = 2 * j;
        let pair = [y[i] + h * sum[i], y[i + 1] + h * sum[i + 1]];
        out[i..i + 2].copy_from_slice(&pair);
    }
    if D % 2 == 1 {
        out[D - 1] = y[D - 1] + h * sum[D - 1];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The copies of `weighted_sum` compiled for small dimensions add the same products in the
    /// same order as the general one: equal to the bit, for every dimension they cover, with
    /// zero weights skipped alike (so taking either path changes no result).
    #[test]
    fn the_fixed_dimension_sums_equal_the_general_one_to_the_bit() {
        let weights = [0.1, 0.0, -2.5, 1.0 / 3.0, 0.0, 7.25, 1e-3];
        for dim in 1..=9 {
            let first: Vec<f64> = (0..dim).map(|i| 0.3 + i as f64 / 7.0).collect();
            let k: Vec<f64> = (0..6 * dim)
                .map(|i| ((i * 37 % 11) as f64 - 5.0) / 3.0)
                .collect();
            let (mut fixed, mut general) = (vec![f64::NAN; dim], vec![f64::NAN; dim]);
            weighted_sum(&mut fixed, &weights, &first, &k, dim);
            weighted_sum_any(&mut general, &weights, &first, &k, dim);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&fixed), bits(&general), "dim {dim}");
        }
    }

    /// `combine`'s copies for 2, 4, 6 and 8 components equal `y + h Σ wⱼ kⱼ` formed by the
    /// general sum, to the bit; `write_update` also covers odd dimensions (its last component
    /// alone), which no stage uses today.
    #[test]
    fn the_fixed_dimension_updates_equal_the_general_one_to_the_bit() {
        let weights = [0.1, 0.0, -2.5, 1.0 / 3.0, 0.0, 7.25, 1e-3];
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for dim in [2, 4, 6, 8] {
            let y: Vec<f64> = (0..dim).map(|i| 1.0 - i as f64 / 9.0).collect();
            let first: Vec<f64> = (0..dim).map(|i| 0.3 + i as f64 / 7.0).collect();
            let k: Vec<f64> = (0..6 * dim)
                .map(|i| ((i * 37 % 11) as f64 - 5.0) / 3.0)
                .collect();
            let mut fixed = vec![f64::NAN; dim];
            combine(&mut fixed, &y, 0.125, &weights, &first, &k);
            let mut general = vec![f64::NAN; dim];
            weighted_sum_any(&mut general, &weights, &first, &k, dim);
            for (o, &yi) in general.iter_mut().zip(&y) {
                *o = yi + 0.125 * *o;
            }
            assert_eq!(bits(&fixed), bits(&general), "dim {dim}");
        }
        let (y, sum) = ([1.0, 2.0, 3.0], [0.5, -1.0, 4.0]);
        let mut out = [f64::NAN; 3];
        write_update::<3>(&mut out, &y, 0.25, &sum);
        assert_eq!(out, [1.125, 1.75, 4.0]);
        let mut one = [f64::NAN];
        write_update::<1>(&mut one, &[2.0], 0.5, &[3.0]);
        assert_eq!(one, [3.5]);
    }
}
