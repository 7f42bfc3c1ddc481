//! One stepper for every explicit Runge–Kutta [`Tableau`]: stages, embedded error estimate,
//! FSAL reuse, and dense output by the Hermite interpolant (with Shampine's correction for
//! DP5(4)) or by the pair's own interpolant with its extra stages (Verner's).

mod interpolant;
mod sums;

use std::mem::swap;

pub(super) use sums::{
    combine, combine_any, error_ratio, sum_fixed, weighted_sum, weighted_sum_any, write_update,
};

use super::dense_output::{DenseOutput, hermite};
use super::options::ErrorWeights;
use super::stepper::{AttemptTimes, CheckedRhs, StepEnds, StepFailure, Stepper, first_non_finite};
use super::tableau::{StageSums, Tableau};
use crate::ode::RhsError;
use interpolant::{InterpolantState, LastStep};

/// An explicit Runge–Kutta method given by its tableau, with all buffers allocated once.
///
/// Stage 0 of a step is `F(t, y)` at the current state, kept in `f` (for an FSAL tableau it
/// is the last stage of the previous step; otherwise it is evaluated when a step is accepted,
/// which is also what the dense output needs). Stages `1 … s−1` live in `k`. After an
/// accepted step, `y_prev`, `f_prev` and `k` describe that step for the dense output; a pair
/// with an interpolant appends its extra stages to `k` when the dense output is prepared
/// ([`Stepper::prepare_dense_output`]), only for a step that contains a requested output
/// time or an event, as OrdinaryDiffEq.jl's `lazy` option does.
///
/// With [`StageSums::Differences`] row `j − 1` of `k` holds the difference `kⱼ − k₀` of stage
/// `j ≥ 1`, and every sum is taken in the form `Σⱼ wⱼ kⱼ = (Σⱼ wⱼ) k₀ + Σⱼ≥₁ wⱼ (kⱼ − k₀)`:
/// the rows below (`a_rows`, `b_row`, `error_row`) then carry `Σⱼ wⱼ` (`cᵢ`, 1, 0) in place of
/// stage 0's weight.
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
    /// Stages `1 …` of all stages (an interpolant's extra ones included), row-major:
    /// `(all − 1) × dim`.
    k: Vec<f64>,
    /// Row `i` of `a` for every stage (an interpolant's extra ones included), as the sums
    /// take it.
    a_rows: Vec<Vec<f64>>,
    /// The weights `b`, as the sums take them.
    b_row: Vec<f64>,
    /// The error weights `b − b̂`, as the sums take them, if the tableau has them.
    error_row: Option<Vec<f64>>,
    /// Whether the sums are taken with differences ([`StageSums::Differences`]).
    differences: bool,
    /// The stages compiled for this tableau and dimension, if there is such a copy.
    kernel: Option<Kernel>,
    /// The rows of `k` whose stage has no weight in the candidate nor in the error estimate;
    /// an error-controlled attempt checks only these for finiteness on their own.
    unweighted_rows: Vec<usize>,
    /// The pair's own interpolant, if it has one (else the Hermite dense output).
    interpolant: Option<InterpolantState>,
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

/// `weights` as the sums take them: as written, or with stage 0's weight replaced by
/// `total = Σⱼ wⱼ` in the form with differences.
fn sum_row(weights: &[f64], total: f64, differences: bool) -> Vec<f64> {
    let mut row = weights.to_vec();
    if differences && let Some(first) = row.first_mut() {
        *first = total;
    }
    row
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
        let differences = tableau.sums() == StageSums::Differences;
        let (c, a): (&[f64], Vec<&[f64]>) = match tableau.interpolant() {
            Some(interpolant) => (interpolant.c, interpolant.a.to_vec()),
            None => (
                tableau.c(),
                (0..tableau.num_stages()).map(|i| tableau.a(i)).collect(),
            ),
        };
        let a_rows = a
            .iter()
            .zip(c)
            .map(|(row, &ci)| sum_row(row, ci, differences))
            .collect();
        Self {
            tableau,
            dim,
            ends: StepEnds::new(dim),
            y_new: vec![0.0; dim],
            scratch: vec![0.0; dim],
            k: vec![0.0; c.len().saturating_sub(1) * dim],
            a_rows,
            b_row: sum_row(tableau.b(), 1.0, differences),
            error_row: tableau
                .error_weights()
                .map(|e| sum_row(e, 0.0, differences)),
            differences,
            kernel: kernel(&tableau, dim),
            unweighted_rows: unweighted_rows(&tableau),
            interpolant: tableau
                .interpolant()
                .map(|interpolant| InterpolantState::new(interpolant, dim)),
        }
    }

    /// Stage `I` (`1 ≤ I < s`) of the tableau `make()` for `D` components: its input
    /// `y + h Σⱼ aᵢⱼ kⱼ` (into `y_new` for the last stage of an FSAL tableau, else `scratch`),
    /// then `F` there into row `I − 1` of `k`, unchecked (see [`CheckedRhs::eval_stage`]).
    /// For a tableau whose sums are plain.
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

    /// Marks the interpolant of the last step, if there is one, as not prepared (after a new
    /// attempt, step or start).
    fn invalidate_dense_output(&mut self) {
        if let Some(state) = &mut self.interpolant {
            state.invalidate();
        }
    }

    /// Stages `1 … s−1` of an attempt through the general sums: each stage's input, then `F`
    /// there into its row of `k` (less `k₀` in the form with differences).
    fn stages(&mut self, rhs: &mut CheckedRhs<'_>, times: AttemptTimes) -> Result<(), StepFailure> {
        let n = self.dim;
        let s = self.tableau.num_stages();
        let c = self.tableau.c();
        // Row r of k is stage r + 1.
        let stage_time = |r: usize| times.at(c[r + 1]);
        for (i, &ci) in c.iter().enumerate().skip(1) {
            let (earlier, rest) = self.k.split_at_mut((i - 1) * n);
            // The last stage of an FSAL tableau is evaluated at the candidate itself.
            let input = if self.tableau.is_fsal() && i == s - 1 {
                &mut self.y_new
            } else {
                &mut self.scratch
            };
            // The copies of `combine` for 2, 4, 6 and 8 components keep the sums in registers.
            combine(
                input,
                &self.ends.y,
                times.h,
                &self.a_rows[i],
                &self.ends.f,
                earlier,
            );
            let row = &mut rest[..n];
            if let Err(failure) = rhs.eval_stage(times.at(ci), input, row) {
                return Err(CheckedRhs::stage_failure(earlier, n, stage_time, failure));
            }
            if self.differences {
                // A non-finite stage stays non-finite as a difference (k₀ is finite).
                for (k, &f0) in row.iter_mut().zip(&self.ends.f) {
                    *k -= f0;
                }
            }
        }
        Ok(())
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

impl DenseOutput for ExplicitRk {
    fn interval(&self) -> (f64, f64) {
        self.ends.interval()
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        if let Some(interpolant) = &self.interpolant {
            interpolant.interpolate(&self.ends, t, out);
            return;
        }
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
    stepper_state_from_ends!();

    fn reset(&mut self, rhs: &mut CheckedRhs<'_>, t0: f64, y0: &[f64]) -> Result<(), StepFailure> {
        self.ends.reset(rhs, t0, y0)?;
        self.invalidate_dense_output();
        Ok(())
    }

    fn attempt(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        t_new: f64,
        weights: &ErrorWeights,
        estimate_error: bool,
    ) -> Result<Option<f64>, StepFailure> {
        let n = self.dim;
        let s = self.tableau.num_stages();
        let times = AttemptTimes::new(self.ends.t, t_new);
        let h = times.h;
        self.ends.t_new = t_new;
        self.invalidate_dense_output();
        let c = self.tableau.c();
        // Row r of k is stage r + 1.
        let stage_time = |r: usize| times.at(c[r + 1]);
        let compiled = self.kernel.is_some();
        if let Some(kernel) = self.kernel {
            kernel(self, rhs, times.t, times.t_new)?;
        } else {
            self.stages(rhs, times)?;
        }
        let stages = &self.k[..s.saturating_sub(1) * n];
        let error_row = self.error_row.as_deref().filter(|_| estimate_error);
        if error_row.is_some() {
            // A non-finite stage with a weight in the candidate or in the error estimate makes
            // that one non-finite, which is checked below; only the others are checked here.
            for &row in &self.unweighted_rows {
                if let Some(index) = first_non_finite(&stages[row * n..(row + 1) * n]) {
                    return Err(StepFailure::Rhs {
                        t: stage_time(row),
                        error: RhsError::NonFinite { index },
                    });
                }
            }
        } else {
            CheckedRhs::check_stages(stages, n, stage_time)?;
        }
        if !self.tableau.is_fsal() {
            combine(
                &mut self.y_new,
                &self.ends.y,
                h,
                &self.b_row,
                &self.ends.f,
                stages,
            );
        }
        if let Some(index) = first_non_finite(&self.y_new) {
            // A non-finite stage that made it so is reported at its own time.
            CheckedRhs::check_stages(stages, n, stage_time)?;
            return Err(StepFailure::NonFiniteState { t: t_new, index });
        }
        let Some(e) = error_row else {
            return Ok(None);
        };
        if n == 0 {
            return Ok(Some(0.0));
        }
        // Hairer's norm (and OrdinaryDiffEq.jl's): RMS over i of errᵢ / (atolᵢ + rtolᵢ ·
        // max(|yᵢ|, |y_newᵢ|)), errᵢ = h Σ (bⱼ − b̂ⱼ) kⱼ.
        if !compiled {
            weighted_sum(&mut self.scratch, e, &self.ends.f, stages, n);
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
            CheckedRhs::check_stages(stages, n, stage_time)?;
        }
        Ok(Some(squared))
    }

    fn accept(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        let n = self.dim;
        let s = self.tableau.num_stages();
        // F at the candidate goes into f_prev first, whose old content is no longer needed,
        // so that a failure leaves the current state untouched.
        if self.tableau.is_fsal() {
            let last = &self.k[(s - 2) * n..(s - 1) * n];
            if self.differences {
                // The last stage, F at the candidate, from its difference.
                for ((f_new, &d), &f0) in self.ends.f_prev.iter_mut().zip(last).zip(&self.ends.f) {
                    *f_new = d + f0;
                }
            } else {
                self.ends.f_prev.copy_from_slice(last);
            }
        } else {
            rhs.eval(self.ends.t_new, &self.y_new, &mut self.ends.f_prev)?;
        }
        swap(&mut self.ends.f, &mut self.ends.f_prev);
        swap(&mut self.ends.y_prev, &mut self.ends.y);
        swap(&mut self.ends.y, &mut self.y_new);
        self.ends.t_prev = self.ends.t;
        self.ends.t = self.ends.t_new;
        self.invalidate_dense_output();
        Ok(())
    }

    /// The interpolant's extra stages of the last step, for a pair that has one (two, three
    /// … nine evaluations of `F` for Verner 6(5) … 9(8); `F` at the step's end is already
    /// known), then its values at its nodes. Nothing for the Hermite dense output.
    fn prepare_dense_output(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        let Some(state) = &mut self.interpolant else {
            return Ok(());
        };
        let step = LastStep {
            tableau: &self.tableau,
            ends: &self.ends,
            k: &mut self.k,
            scratch: &mut self.scratch,
            a_rows: &self.a_rows,
        };
        state.prepare(step, rhs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ode::OdeFn;

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
        // Verner 6(5)'s stages at c = 0.06 and 0.0960…: the form with differences keeps the
        // tableau's zero weights.
        assert_eq!(unweighted_rows(&Tableau::vern6()), vec![0, 1]);
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
