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

/// [`weighted_sum`] for any dimension: blocks of [`BLOCK`] components, each summed as
/// [`sum_fixed`] sums a small system (its accumulators in registers), then the last
/// `dim mod BLOCK`. Each component's products are added in the same order as in
/// [`sum_fixed`], so the blocks change no bit. Summed component by component over the stages
/// instead (each weight tested for every component, one scalar accumulator), DOP853 on the
/// figure eight (12 states) and a 5-link chain (10) ran 1.24–1.32× the time of ode_solvers'
/// Dop853 on the same steps, against 0.96–0.98× on the double pendulum (4 states).
#[inline(always)]
pub(in crate::integrate) fn weighted_sum_any(
    out: &mut [f64],
    weights: &[f64],
    first: &[f64],
    k: &[f64],
    dim: usize,
) {
    blocks(Store(out), (weights, first, k), dim);
}

/// `out = y + h Σⱼ wⱼ kⱼ` for any dimension, in the blocks of [`weighted_sum_any`], each
/// block's sum added to `y` while in registers ([`write_update`]).
#[inline(always)]
pub(in crate::integrate) fn combine_any(
    out: &mut [f64],
    y: &[f64],
    h: f64,
    weights: &[f64],
    first: &[f64],
    k: &[f64],
    dim: usize,
) {
    blocks(Update { out, y, h }, (weights, first, k), dim);
}

/// Where a block's sum goes: [`Store`] or [`Update`]. A trait, monomorphised for each width,
/// rather than a closure per block, which the compiler did not inline: the coefficients of a
/// stage were then not constants (8 % of a DOP853 run of a 5-link chain in that closure).
trait BlockSink {
    /// Writes the sum of components `base … base + B − 1`.
    fn write<const B: usize>(&mut self, base: usize, sum: &[f64; B]);
}

/// The sums themselves into `out`.
struct Store<'a>(&'a mut [f64]);

impl BlockSink for Store<'_> {
    #[inline(always)]
    fn write<const B: usize>(&mut self, base: usize, sum: &[f64; B]) {
        self.0[base..base + B].copy_from_slice(sum);
    }
}

/// `out = y + h · sum`.
struct Update<'a> {
    out: &'a mut [f64],
    y: &'a [f64],
    h: f64,
}

impl BlockSink for Update<'_> {
    #[inline(always)]
    fn write<const B: usize>(&mut self, base: usize, sum: &[f64; B]) {
        write_update::<B>(&mut self.out[base..], &self.y[base..], self.h, sum);
    }
}

/// The sums `Σⱼ wⱼ kⱼ` of `dim` components in blocks of [`BLOCK`] and the rest, each into
/// `sink`.
#[inline(always)]
fn blocks(mut sink: impl BlockSink, (weights, first, k): (&[f64], &[f64], &[f64]), dim: usize) {
    let whole = dim - dim % BLOCK;
    for base in (0..whole).step_by(BLOCK) {
        sink.write(base, &sum_strided::<BLOCK>(weights, first, k, dim, base));
    }
    match dim - whole {
        0 => {}
        1 => sink.write(whole, &sum_strided::<1>(weights, first, k, dim, whole)),
        2 => sink.write(whole, &sum_strided::<2>(weights, first, k, dim, whole)),
        _ => sink.write(whole, &sum_strided::<3>(weights, first, k, dim, whole)),
    }
}

/// Components per block of the sums for any dimension: four, two vector registers of SSE2
/// (one of AVX) per accumulator set.
const BLOCK: usize = 4;

/// `Σⱼ wⱼ kⱼ` for components `base … base + B − 1` of `dim`: [`sum_fixed`] for rows of `k`
/// `dim` apart.
#[inline(always)]
fn sum_strided<const B: usize>(
    weights: &[f64],
    first: &[f64],
    k: &[f64],
    dim: usize,
    base: usize,
) -> [f64; B] {
    let mut acc = [0.0f64; B];
    let Some((&w0, rest)) = weights.split_first() else {
        return acc;
    };
    let first = &first[base..base + B];
    if w0 != 0.0 {
        for i in 0..B {
            acc[i] = w0 * first[i];
        }
    }
    for (j, &w) in rest.iter().enumerate() {
        if w != 0.0 {
            let start = j * dim + base;
            let kj = &k[start..start + B];
            for i in 0..B {
                acc[i] += w * kj[i];
            }
        }
    }
    acc
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
        dim => combine_any(out, y, h, weights, first, k, dim),
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

    /// `Σⱼ wⱼ kⱼ` component by component over the stages, one scalar accumulator, zero
    /// weights skipped: the order of additions every copy must keep.
    fn reference_sum(weights: &[f64], first: &[f64], k: &[f64], dim: usize) -> Vec<f64> {
        (0..dim)
            .map(|i| {
                let mut acc = if weights[0] == 0.0 {
                    0.0
                } else {
                    weights[0] * first[i]
                };
                for (j, &w) in weights[1..].iter().enumerate() {
                    if w != 0.0 {
                        acc += w * k[j * dim + i];
                    }
                }
                acc
            })
            .collect()
    }

    /// Stage values of `dim` components for the tests: `first`, and 6 rows of `k`.
    fn stages(dim: usize) -> (Vec<f64>, Vec<f64>) {
        let first = (0..dim).map(|i| 0.3 + i as f64 / 7.0).collect();
        let k = (0..6 * dim)
            .map(|i| ((i * 37 % 11) as f64 - 5.0) / 3.0)
            .collect();
        (first, k)
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// The copies of `weighted_sum` compiled for small dimensions and the blocked one for
    /// any dimension add the same products in the same order as the scalar reference: equal
    /// to the bit, for every dimension up to 17 (every block width and tail), with zero
    /// weights skipped alike (so taking either path changes no result).
    #[test]
    fn the_fixed_dimension_and_blocked_sums_equal_the_scalar_one_to_the_bit() {
        let weights = [0.1, 0.0, -2.5, 1.0 / 3.0, 0.0, 7.25, 1e-3];
        for dim in 1..=17 {
            let (first, k) = stages(dim);
            let reference = reference_sum(&weights, &first, &k, dim);
            let (mut fixed, mut blocked) = (vec![f64::NAN; dim], vec![f64::NAN; dim]);
            weighted_sum(&mut fixed, &weights, &first, &k, dim);
            weighted_sum_any(&mut blocked, &weights, &first, &k, dim);
            assert_eq!(bits(&fixed), bits(&reference), "dim {dim}");
            assert_eq!(bits(&blocked), bits(&reference), "dim {dim}");
        }
    }

    /// `combine` (its copies for 2, 4, 6 and 8 components and the blocked one) equals
    /// `y + h Σ wⱼ kⱼ` formed from the scalar reference, to the bit, for every dimension up to
    /// 17; `write_update` also covers odd widths (its last component alone).
    #[test]
    fn the_fixed_dimension_and_blocked_updates_equal_the_scalar_one_to_the_bit() {
        let weights = [0.1, 0.0, -2.5, 1.0 / 3.0, 0.0, 7.25, 1e-3];
        for dim in 1..=17 {
            let y: Vec<f64> = (0..dim).map(|i| 1.0 - i as f64 / 9.0).collect();
            let (first, k) = stages(dim);
            let mut combined = vec![f64::NAN; dim];
            combine(&mut combined, &y, 0.125, &weights, &first, &k);
            let reference: Vec<f64> = reference_sum(&weights, &first, &k, dim)
                .iter()
                .zip(&y)
                .map(|(s, yi)| yi + 0.125 * s)
                .collect();
            assert_eq!(bits(&combined), bits(&reference), "dim {dim}");
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
