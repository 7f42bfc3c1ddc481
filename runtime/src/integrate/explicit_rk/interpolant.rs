//! The dense output of a pair with an interpolant of its own (Verner's): its extra stages,
//! evaluated only for a step that needs them, and its values at its nodes, interpolated
//! barycentrically.

use super::super::stepper::{CheckedRhs, StepEnds, StepFailure};
use super::super::tableau::{Interpolant, Tableau};
use super::sums::{combine, weighted_sum};

/// The interpolant of the last accepted step, once prepared.
#[derive(Debug, Clone)]
pub(super) struct InterpolantState {
    interpolant: &'static Interpolant,
    /// `bᵢ(θⱼ)` by node, with stage 0's weight replaced by `θⱼ` (the form with differences,
    /// see [`InterpolantState::prepare`]), `degree × all stages`.
    node_weights: Vec<f64>,
    /// Barycentric weights of the nodes `0, θ₁, …, θ_degree`.
    barycentric: Vec<f64>,
    /// `y(t_prev + θⱼh) − y_prev = h Σᵢ bᵢ(θⱼ) kᵢ` for `j = 1 … degree`, row-major
    /// `degree × dim`, once prepared.
    dense: Vec<f64>,
    ready: bool,
}

impl InterpolantState {
    /// The buffers and weights of `interpolant` for a system of dimension `dim`.
    pub(super) fn new(interpolant: &'static Interpolant, dim: usize) -> Self {
        let all = interpolant.num_all_stages();
        // Stage 0's weight is replaced by that of the differences (see
        // `InterpolantState::prepare`): Σᵢ bᵢ(θⱼ) = θⱼ.
        let mut node_weights = interpolant.node_weights.to_vec();
        for (row, &theta) in node_weights.chunks_exact_mut(all).zip(interpolant.nodes) {
            row[0] = theta;
        }
        // wₐ = 1 / Πᵦ≠ₐ (xₐ − xᵦ) over the nodes x = (0, θ₁, …), Berrut–Trefethen's first
        // form, rescaled by its largest entry.
        let points: Vec<f64> = std::iter::once(0.0)
            .chain(interpolant.nodes.iter().copied())
            .collect();
        let mut barycentric: Vec<f64> = points
            .iter()
            .enumerate()
            .map(|(a, &xa)| {
                let product: f64 = points
                    .iter()
                    .enumerate()
                    .filter(|&(b, _)| b != a)
                    .map(|(_, &xb)| xa - xb)
                    .product();
                1.0 / product
            })
            .collect();
        let largest = barycentric.iter().fold(0.0f64, |m, w| m.max(w.abs()));
        for w in &mut barycentric {
            *w /= largest;
        }
        Self {
            interpolant,
            node_weights,
            barycentric,
            dense: vec![0.0; interpolant.degree * dim],
            ready: false,
        }
    }

    /// `y(t_prev + θh) = y_prev + P(θ)`, with `P` the polynomial of the interpolant's degree
    /// through `P(0) = 0` and `P(θⱼ) = h Σᵢ bᵢ(θⱼ) kᵢ`, by the barycentric formula
    /// `P(θ) = Σⱼ (wⱼ/(θ − θⱼ)) Pⱼ / Σⱼ wⱼ/(θ − θⱼ)` (J.-P. Berrut, L. N. Trefethen,
    /// "Barycentric Lagrange interpolation", SIAM Rev. 46(3), 501–517, 2004,
    /// doi:10.1137/S0036144502417715: stable at the Chebyshev–Lobatto nodes, where the
    /// monomial coefficients `rᵢₘ`, up to 1.4e6, would cancel to weights below ~100); the
    /// step's ends exactly at `θ = 0` and `θ = 1`.
    pub(super) fn interpolate(&self, ends: &StepEnds, t: f64, out: &mut [f64]) {
        let h = ends.t - ends.t_prev;
        if h == 0.0 || t == ends.t {
            out.copy_from_slice(&ends.y);
            return;
        }
        if t == ends.t_prev {
            out.copy_from_slice(&ends.y_prev);
            return;
        }
        debug_assert!(self.ready, "prepare_dense_output before interpolate");
        let n = out.len();
        let theta = (t - ends.t_prev) / h;
        let nodes = self.interpolant.nodes;
        if let Some(j) = nodes.iter().position(|&x| x == theta) {
            let row = &self.dense[j * n..(j + 1) * n];
            for ((o, &y0), &d) in out.iter_mut().zip(&ends.y_prev).zip(row) {
                *o = y0 + d;
            }
            return;
        }
        // The node 0 contributes to the denominator only (P(0) = 0).
        let mut denominator = self.barycentric[0] / theta;
        out.fill(0.0);
        for (j, &x) in nodes.iter().enumerate() {
            let c = self.barycentric[j + 1] / (theta - x);
            denominator += c;
            for (o, &d) in out.iter_mut().zip(&self.dense[j * n..(j + 1) * n]) {
                *o += c * d;
            }
        }
        for (o, &y0) in out.iter_mut().zip(&ends.y_prev) {
            *o = y0 + *o / denominator;
        }
    }
}

/// What [`InterpolantState::prepare`] reads of the stepper's last step, and the buffers it
/// fills: its ends, its stages (to which the extra ones are appended), a scratch of `dim`
/// values, and the rows of `a` of all stages as the sums take them.
pub(super) struct LastStep<'a> {
    pub(super) tableau: &'a Tableau,
    pub(super) ends: &'a StepEnds,
    pub(super) k: &'a mut [f64],
    pub(super) scratch: &'a mut [f64],
    pub(super) a_rows: &'a [Vec<f64>],
}

impl InterpolantState {
    /// Marks the interpolant as not prepared (after a new attempt, step or start).
    pub(super) fn invalidate(&mut self) {
        self.ready = false;
    }

    /// The interpolant's extra stages of the last step (`F` at the step's end is already
    /// known), then its values at its nodes `h Σᵢ bᵢ(θⱼ) kᵢ`. Nothing when it is prepared.
    ///
    /// The extra stages are kept as differences `kᵢ − k₀` like the step's (the pairs with an
    /// interpolant sum with differences).
    pub(super) fn prepare(
        &mut self,
        step: LastStep<'_>,
        rhs: &mut CheckedRhs<'_>,
    ) -> Result<(), StepFailure> {
        let LastStep {
            tableau,
            ends,
            k,
            scratch,
            a_rows,
        } = step;
        if self.ready || ends.t == ends.t_prev {
            return Ok(());
        }
        let n = scratch.len();
        if n == 0 {
            self.ready = true;
            return Ok(());
        }
        let interpolant = self.interpolant;
        let all = interpolant.num_all_stages();
        let h = ends.t - ends.t_prev;
        let end = tableau.end_stage();
        if !tableau.is_fsal() {
            let row = &mut k[(end - 1) * n..end * n];
            for ((k, &f1), &f0) in row.iter_mut().zip(&ends.f).zip(&ends.f_prev) {
                *k = f1 - f0;
            }
        }
        for (i, (a_row, &c)) in a_rows.iter().zip(interpolant.c).enumerate().skip(end + 1) {
            let (earlier, rest) = k.split_at_mut((i - 1) * n);
            combine(scratch, &ends.y_prev, h, a_row, &ends.f_prev, earlier);
            let t = ends.t_prev + c * h;
            let row = &mut rest[..n];
            rhs.eval(t, scratch, row)?;
            for (k, &f0) in row.iter_mut().zip(&ends.f_prev) {
                *k -= f0;
            }
        }
        // The values at the nodes as h (θⱼ k₀ + Σᵢ≥₁ bᵢ(θⱼ) (kᵢ − k₀)), equal to
        // h Σᵢ bᵢ(θⱼ) kᵢ since Σᵢ bᵢ(θ) = θ.
        for (j, weights) in self.node_weights.chunks_exact(all).enumerate() {
            let row = &mut self.dense[j * n..(j + 1) * n];
            weighted_sum(row, weights, &ends.f_prev, k, n);
            for v in row.iter_mut() {
                *v *= h;
            }
        }
        self.ready = true;
        Ok(())
    }
}
