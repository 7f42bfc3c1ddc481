//! One stepper for every explicit Runge–Kutta [`Tableau`]: stages, embedded error estimate,
//! FSAL reuse and Hermite-based dense output.

use std::mem::swap;

use super::dense_output::{DenseOutput, hermite};
use super::options::ErrorWeights;
use super::stepper::{AttemptTimes, CheckedRhs, StepEnds, StepFailure, Stepper, first_non_finite};
use super::tableau::Tableau;
use crate::ode::RhsError;

/// An explicit Runge–Kutta method given by its tableau, with all buffers allocated once.
///
/// Stage 0 of a step is `F(t, y)` at the current state, kept in `f` (for an FSAL tableau it
/// is the last stage of the previous step; otherwise it is evaluated when a step is accepted,
/// which is also what the Hermite dense output needs). Stages `1 … s−1` live in `k`. After an
/// accepted step, `y_prev`, `f_prev` and `k` describe that step for the dense output.
#[derive(Debug, Clone)]
pub(crate) struct ExplicitRk {
    tableau: Tableau,
    dim: usize,
    /// Ends of the last accepted step and the candidate's time.
    ends: StepEnds,
    /// Candidate state at `t_new`.
    y_new: Vec<f64>,
    /// Stage input, then the error estimate.
    scratch: Vec<f64>,
    /// Stages `1 … s−1`, row-major: `(s − 1) × dim`.
    k: Vec<f64>,
    /// The stages compiled for this tableau and dimension, if there is such a copy.
    kernel: Option<Kernel>,
    /// The rows of `k` whose stage has no weight in the candidate nor in the error estimate;
    /// an error-controlled attempt checks only these for finiteness on their own.
    unweighted_rows: Vec<usize>,
}

/// The rows of `k` (stage `r + 1` in row `r`) whose stage has a zero weight in `b` and in the
/// error estimate: a NaN or infinite value there would show neither in the candidate nor in
/// the error norm. (Without an error estimate every stage is checked.) Checking these, the
/// candidate and the norm finds every non-finite stage
/// (then searched for, to report the first at its own time) at a fraction of the cost of
/// checking every stage (on the double pendulum, checking all stages took ~6 % of a DP5(4)
/// run with a cheap right-hand side).
fn unweighted_rows(tableau: &Tableau) -> Vec<usize> {
    let (b, e) = (tableau.b(), tableau.error_weights().unwrap_or(&[]));
    let zero = |w: &[f64], j: usize| w.get(j).is_none_or(|&x| x == 0.0);
    (1..tableau.num_stages())
        .filter(|&j| zero(b, j) && zero(e, j))
        .map(|j| j - 1)
        .collect()
}

/// Stages `1 … s−1` of an attempt, compiled for one tableau and one dimension: see
/// [`dopri5_stages`]. A kernel also leaves the error estimate's sum `Σ eᵢ kᵢ` in `scratch`
/// (the attempt then does not form it again).
///
/// The times come as `(t, t_new)` in registers rather than as an [`AttemptTimes`] in memory
/// (measured: DP5(4) on the double pendulum ~5 % faster this way).
type Kernel = fn(&mut ExplicitRk, &mut CheckedRhs<'_>, f64, f64) -> Result<(), StepFailure>;

impl ExplicitRk {
    /// A stepper for `tableau` on a system of dimension `dim`.
    pub(crate) fn new(tableau: Tableau, dim: usize) -> Self {
        let stages = tableau.num_stages();
        Self {
            tableau,
            dim,
            ends: StepEnds::new(dim),
            y_new: vec![0.0; dim],
            scratch: vec![0.0; dim],
            k: vec![0.0; stages.saturating_sub(1) * dim],
            kernel: kernel(&tableau, dim),
            unweighted_rows: unweighted_rows(&tableau),
        }
    }

    /// Stage `I` (`1 ≤ I < s`) of the tableau `make()` for `D` components: its input
    /// `y + h Σⱼ aᵢⱼ kⱼ` (into `y_new` for the last stage of an FSAL tableau, else `scratch`),
    /// then `F` there into row `I − 1` of `k`, unchecked (see [`CheckedRhs::eval_stage`]).
    #[inline(always)]
    fn stage_fixed<const I: usize, const D: usize>(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        make: fn() -> Tableau,
        times: AttemptTimes,
    ) -> Result<(), StepFailure> {
        // Built here from `make` (a function item), so that once the stage is inlined its
        // coefficients are constants to the compiler.
        let tableau = make();
        let (earlier, rest) = self.k.split_at_mut((I - 1) * D);
        let sum = sum_fixed::<D>(tableau.a(I), &self.ends.f, earlier);
        let input = if tableau.is_fsal() && I + 1 == tableau.num_stages() {
            &mut self.y_new
        } else {
            &mut self.scratch
        };
        write_update::<D>(input, &self.ends.y, times.h, &sum);
        let c = tableau.c();
        match rhs.eval_stage(times.at(c[I]), &input[..D], &mut rest[..D]) {
            Ok(()) => Ok(()),
            Err(failure) => {
                let time = |r: usize| times.at(c[r + 1]);
                Err(CheckedRhs::stage_failure(earlier, D, time, failure))
            }
        }
    }
}

/// The copy of the stages compiled for `tableau` and `dim`: Dormand–Prince 5(4) on systems
/// of 2, 4, 6 or 8 components (mechanisms of one to four degrees of freedom); `None`
/// otherwise (the stages then run through [`combine`] with the dimension a run-time value).
fn kernel(tableau: &Tableau, dim: usize) -> Option<Kernel> {
    if tableau.name() != Tableau::dopri5().name() {
        return None;
    }
    match dim {
        2 => Some(dopri5_stages::<2>),
        4 => Some(dopri5_stages::<4>),
        6 => Some(dopri5_stages::<6>),
        8 => Some(dopri5_stages::<8>),
        _ => None,
    }
}

/// Stages 1 … 6 of Dormand–Prince 5(4) for `D` components, unrolled: with the stage index,
/// the dimension and the tableau (`static`s) known to the compiler, each stage input is a
/// fixed sequence of multiply–adds with the non-zero coefficients as constants, in registers,
/// instead of a loop over the row that tests every coefficient (on the double pendulum, DOP853
/// done this way executes ~85 fewer instructions per evaluation of `F`, callgrind).
fn dopri5_stages<const D: usize>(
    rk: &mut ExplicitRk,
    rhs: &mut CheckedRhs<'_>,
    t: f64,
    t_new: f64,
) -> Result<(), StepFailure> {
    let times = AttemptTimes::new(t, t_new);
    let make = Tableau::dopri5;
    rk.stage_fixed::<1, D>(rhs, make, times)?;
    rk.stage_fixed::<2, D>(rhs, make, times)?;
    rk.stage_fixed::<3, D>(rhs, make, times)?;
    rk.stage_fixed::<4, D>(rhs, make, times)?;
    rk.stage_fixed::<5, D>(rhs, make, times)?;
    rk.stage_fixed::<6, D>(rhs, make, times)?;
    // The error estimate's sum `Σ eᵢ kᵢ`, with the weights folded in as constants too.
    if let Some(e) = make().error_weights() {
        let sum = sum_fixed::<D>(e, &rk.ends.f, &rk.k);
        rk.scratch[..D].copy_from_slice(&sum);
    }
    Ok(())
}

/// `out = Σⱼ wⱼ kⱼ` over the stages that have a weight (zero weights are skipped), where stage
/// 0 is `first` and stage `j ≥ 1` is row `j − 1` of `k` (rows of `dim`).
///
/// The increment is summed on its own before it is added to `y` (see [`combine`]), so that
/// small stage contributions are not rounded against `|y|` one at a time.
///
/// Summed component by component with each sum in a register: summing stage by stage into
/// `out` makes every addition wait for the previous stage's store to memory, which cost more
/// than the right-hand side itself on small systems (measured on the double pendulum).
pub(super) fn weighted_sum(out: &mut [f64], weights: &[f64], first: &[f64], k: &[f64], dim: usize) {
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
pub(super) fn sum_fixed<const D: usize>(weights: &[f64], first: &[f64], k: &[f64]) -> [f64; D] {
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
pub(super) fn error_ratio(error: f64, scale: f64, inverse: f64) -> f64 {
    if error == 0.0 {
        0.0
    } else if inverse.is_finite() {
        error * inverse
    } else {
        error / scale
    }
}

/// `out = y + h Σⱼ wⱼ kⱼ`.
pub(super) fn combine(
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
pub(super) fn write_update<const D: usize>(out: &mut [f64], y: &[f64], h: f64, sum: &[f64; D]) {
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

impl DenseOutput for ExplicitRk {
    fn interval(&self) -> (f64, f64) {
        self.ends.interval()
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let h = self.ends.t - self.ends.t_prev;
        if h == 0.0 {
            out.copy_from_slice(&self.ends.y);
            return;
        }
        let theta = (t - self.ends.t_prev) / h;
        // `out` first holds Σ dᵢ kᵢ over the stages of the accepted step (stage 0 is
        // f_prev), the quartic correction D = h Σ dᵢ kᵢ divided by h; zero without one.
        match self.tableau.dense_correction() {
            Some(d) => weighted_sum(out, d, &self.ends.f_prev, &self.k, self.dim),
            None => out.fill(0.0),
        }
        let ends = self.ends.y_prev.iter().zip(&self.ends.y);
        let slopes = self.ends.f_prev.iter().zip(&self.ends.f);
        for (o, ((&y0, &y1), (&f0, &f1))) in out.iter_mut().zip(ends.zip(slopes)) {
            *o = hermite(theta, y0, y1, h * f0, h * f1, h * *o);
        }
    }
}

impl Stepper for ExplicitRk {
    fn t(&self) -> f64 {
        self.ends.t
    }

    fn y(&self) -> &[f64] {
        &self.ends.y
    }

    fn derivative(&self) -> &[f64] {
        &self.ends.f
    }

    fn reset(&mut self, rhs: &mut CheckedRhs<'_>, t0: f64, y0: &[f64]) -> Result<(), StepFailure> {
        self.ends.reset(rhs, t0, y0)?;
        Ok(())
    }

    fn attempt(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        t_new: f64,
        weights: &ErrorWeights,
        estimate_error: bool,
    ) -> Result<Option<f64>, StepFailure> {
        let tableau = self.tableau;
        let n = self.dim;
        let s = tableau.num_stages();
        let times = AttemptTimes::new(self.ends.t, t_new);
        let h = times.h;
        self.ends.t_new = t_new;
        let c = tableau.c();
        // Row r of k is stage r + 1.
        let stage_time = |r: usize| times.at(c[r + 1]);
        let compiled = self.kernel.is_some();
        if let Some(kernel) = self.kernel {
            kernel(self, rhs, times.t, times.t_new)?;
        } else {
            for (i, &ci) in c.iter().enumerate().skip(1) {
                let (earlier, rest) = self.k.split_at_mut((i - 1) * n);
                // The last stage of an FSAL tableau is evaluated at the candidate itself.
                let input = if tableau.is_fsal() && i == s - 1 {
                    &mut self.y_new
                } else {
                    &mut self.scratch
                };
                combine(input, &self.ends.y, h, tableau.a(i), &self.ends.f, earlier);
                if let Err(failure) = rhs.eval_stage(times.at(ci), input, &mut rest[..n]) {
                    return Err(CheckedRhs::stage_failure(earlier, n, stage_time, failure));
                }
            }
        }
        let error_weights = if estimate_error {
            tableau.error_weights()
        } else {
            None
        };
        if error_weights.is_some() {
            // A non-finite stage with a weight in the candidate or in the error estimate makes
            // that one non-finite, which is checked below; only the others are checked here.
            for &row in &self.unweighted_rows {
                if let Some(index) = first_non_finite(&self.k[row * n..(row + 1) * n]) {
                    return Err(StepFailure::Rhs {
                        t: stage_time(row),
                        error: RhsError::NonFinite { index },
                    });
                }
            }
        } else {
            CheckedRhs::check_stages(&self.k, n, stage_time)?;
        }
        if !tableau.is_fsal() {
            combine(
                &mut self.y_new,
                &self.ends.y,
                h,
                tableau.b(),
                &self.ends.f,
                &self.k,
            );
        }
        if let Some(index) = first_non_finite(&self.y_new) {
            // A non-finite stage that made it so is reported at its own time.
            CheckedRhs::check_stages(&self.k, n, stage_time)?;
            return Err(StepFailure::NonFiniteState { t: t_new, index });
        }
        let Some(e) = error_weights else {
            return Ok(None);
        };
        if n == 0 {
            return Ok(Some(0.0));
        }
        // Hairer's norm: RMS over i of errᵢ / (atolᵢ + rtolᵢ · max(|yᵢ|, |y_newᵢ|)).
        if !compiled {
            weighted_sum(&mut self.scratch, e, &self.ends.f, &self.k, n);
        }
        let mut sum = 0.0;
        for i in 0..n {
            let scale = weights.scale(i, self.ends.y[i].abs().max(self.y_new[i].abs()));
            let ratio = error_ratio(h * self.scratch[i], scale, 1.0 / scale);
            sum += ratio * ratio;
        }
        // The square of the norm (the controller takes its logarithm).
        let squared = sum * (1.0 / n as f64);
        if !squared.is_finite() {
            // A non-finite stage in the estimate (reported at its time); else a non-zero
            // error where the scale is zero, which is an infinite error.
            CheckedRhs::check_stages(&self.k, n, stage_time)?;
        }
        Ok(Some(squared))
    }

    fn accept(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        let n = self.dim;
        let s = self.tableau.num_stages();
        // F at the candidate goes into f_prev first, whose old content is no longer needed,
        // so that a failure leaves the current state untouched.
        if self.tableau.is_fsal() {
            self.ends
                .f_prev
                .copy_from_slice(&self.k[(s - 2) * n..(s - 1) * n]);
        } else {
            rhs.eval(self.ends.t_new, &self.y_new, &mut self.ends.f_prev)?;
        }
        swap(&mut self.ends.f, &mut self.ends.f_prev);
        swap(&mut self.ends.y_prev, &mut self.ends.y);
        swap(&mut self.ends.y, &mut self.y_new);
        self.ends.t_prev = self.ends.t;
        self.ends.t = self.ends.t_new;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ode::OdeFn;

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

    /// The DP5(4) stages compiled for 2, 4, 6 and 8 components give the same steps as the
    /// general stages, to the bit, over several error-controlled attempts of a nonlinear
    /// system.
    #[test]
    fn the_compiled_stages_equal_the_general_ones_to_the_bit() {
        for dim in [2, 4, 6, 8] {
            let mut system = OdeFn::new(dim, |t: f64, y: &[f64], dy: &mut [f64]| {
                for i in 0..y.len() {
                    dy[i] = (y[(i + 1) % y.len()] * 1.3).sin() - 0.2 * y[i] + t.cos();
                }
            });
            let mut rhs = CheckedRhs::new(&mut system);
            let weights = ErrorWeights::uniform(dim, 1e-6, 1e-6);
            let y0: Vec<f64> = (0..dim).map(|i| 0.1 * i as f64).collect();
            let mut compiled = ExplicitRk::new(Tableau::dopri5(), dim);
            assert!(compiled.kernel.is_some());
            let mut general = ExplicitRk::new(Tableau::dopri5(), dim);
            general.kernel = None;
            for stepper in [&mut compiled, &mut general] {
                stepper.reset(&mut rhs, 0.0, &y0).unwrap();
                let mut t = 0.0;
                for _ in 0..5 {
                    t += 0.05;
                    stepper.attempt(&mut rhs, t, &weights, true).unwrap();
                    stepper.accept(&mut rhs).unwrap();
                }
            }
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(compiled.y()), bits(general.y()), "dim {dim}");
        }
    }

    /// One RK4 step of ẏ = y from y = 1 is the degree-4 Taylor polynomial of eʰ.
    #[test]
    fn rk4_step_is_the_taylor_polynomial() {
        let mut system = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = y[0]);
        let mut rhs = CheckedRhs::new(&mut system);
        let mut stepper = ExplicitRk::new(Tableau::rk4(), 1);
        stepper.reset(&mut rhs, 0.0, &[1.0]).unwrap();
        let h: f64 = 0.1;
        let weights = ErrorWeights::uniform(1, 1e-6, 1e-9);
        assert_eq!(stepper.attempt(&mut rhs, h, &weights, true).unwrap(), None);
        stepper.accept(&mut rhs).unwrap();
        let taylor = 1.0 + h + h * h / 2.0 + h.powi(3) / 6.0 + h.powi(4) / 24.0;
        assert!((stepper.y()[0] - taylor).abs() < 1e-16);
        // F at t0, stages 2–4, then F at the new state (the next step's first stage):
        // four evaluations per step.
        assert_eq!(rhs.evals(), 1 + 3 + 1);
        assert_eq!(stepper.derivative()[0], stepper.y()[0]);
        assert_eq!(stepper.interval(), (0.0, h));
    }

    /// DOPRI5 reuses its last stage: six evaluations per step.
    #[test]
    fn dopri5_step_is_fsal() {
        let mut system = OdeFn::new(1, |t: f64, _y: &[f64], dy: &mut [f64]| dy[0] = t.cos());
        let mut rhs = CheckedRhs::new(&mut system);
        let mut stepper = ExplicitRk::new(Tableau::dopri5(), 1);
        stepper.reset(&mut rhs, 0.0, &[0.0]).unwrap();
        let weights = ErrorWeights::uniform(1, 1e-6, 1e-9);
        let error = stepper.attempt(&mut rhs, 0.1, &weights, true).unwrap();
        assert!(error.unwrap() > 0.0);
        stepper.accept(&mut rhs).unwrap();
        assert_eq!(rhs.evals(), 1 + 6);
        assert!((stepper.y()[0] - 0.1_f64.sin()).abs() < 1e-10);
        assert_eq!(stepper.derivative()[0], 0.1_f64.cos());
        // Dense output at the ends reproduces the step exactly.
        let mut out = [0.0];
        stepper.interpolate(0.0, &mut out);
        assert_eq!(out[0], 0.0);
        stepper.interpolate(0.1, &mut out);
        assert_eq!(out[0], stepper.y()[0]);
        stepper.interpolate(0.05, &mut out);
        assert!((out[0] - 0.05_f64.sin()).abs() < 1e-9);
    }

    /// One error-controlled DP5(4) attempt from `t = 0` to `0.1` in `dim` components, where
    /// `F` (which ignores `y`) is NaN for `t` within 1e-3 of `t_nan` and 1 elsewhere: the
    /// failure must be a non-finite stage at `t_nan`. Then, away from the window, the same
    /// step succeeds.
    fn expect_nan_stage_at(dim: usize, t_nan: f64) {
        let mut system = OdeFn::new(dim, move |t: f64, _y: &[f64], dy: &mut [f64]| {
            let nan_window = (t - t_nan).abs() < 1e-3;
            dy.fill(if nan_window { f64::NAN } else { 1.0 });
        });
        let mut rhs = CheckedRhs::new(&mut system);
        let mut stepper = ExplicitRk::new(Tableau::dopri5(), dim);
        stepper.reset(&mut rhs, 0.0, &vec![0.0; dim]).unwrap();
        let weights = ErrorWeights::uniform(dim, 1e-6, 1e-6);
        match stepper.attempt(&mut rhs, 0.1, &weights, true).unwrap_err() {
            StepFailure::Rhs {
                t,
                error: RhsError::NonFinite { index: 0 },
            } => assert!((t - t_nan).abs() < 1e-15, "t = {t}"),
            other => panic!("{other:?}"),
        }
        stepper.reset(&mut rhs, 0.5, &vec![0.0; dim]).unwrap();
        assert!(stepper.attempt(&mut rhs, 0.6, &weights, true).is_ok());
    }

    /// A stage with no weight in the candidate nor in the error estimate (DP5(4)'s second, at
    /// `c = 1/5`) is checked on its own: `F` ignores `y`, so its NaN reaches neither the later
    /// stages, nor the candidate, nor the error norm, and only that check can find it. Without
    /// the check the attempt would succeed, the NaN never reported. Dimension 2 takes the
    /// compiled stages, 3 the general ones.
    #[test]
    fn a_non_finite_stage_without_weight_is_still_reported() {
        assert_eq!(unweighted_rows(&Tableau::dopri5()), vec![0]);
        for dim in [2, 3] {
            expect_nan_stage_at(dim, 0.2 * 0.1);
        }
    }

    /// A NaN stage with a weight in the candidate (DP5(4)'s third, `c = 3/10`) makes the
    /// candidate NaN; all stages are then searched, and the NaN stage is reported at its own
    /// time rather than as a non-finite state at the end of the step.
    #[test]
    fn a_non_finite_weighted_stage_is_reported_at_its_time() {
        for dim in [2, 3] {
            expect_nan_stage_at(dim, 0.3 * 0.1);
        }
    }

    #[test]
    fn a_rejected_attempt_leaves_the_state() {
        let mut system = OdeFn::new(1, |t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = if t > 0.5 { f64::NAN } else { -y[0] };
        });
        let mut rhs = CheckedRhs::new(&mut system);
        let mut stepper = ExplicitRk::new(Tableau::dopri5(), 1);
        stepper.reset(&mut rhs, 0.0, &[1.0]).unwrap();
        let weights = ErrorWeights::uniform(1, 1e-6, 1e-9);
        let failure = stepper.attempt(&mut rhs, 1.0, &weights, false).unwrap_err();
        assert!(matches!(failure, StepFailure::Rhs { t, .. } if t > 0.5));
        assert_eq!(stepper.t(), 0.0);
        assert_eq!(stepper.y(), &[1.0]);
        assert!(stepper.attempt(&mut rhs, 0.25, &weights, false).is_ok());
        stepper.accept(&mut rhs).unwrap();
        assert_eq!(stepper.t(), 0.25);
    }
}
