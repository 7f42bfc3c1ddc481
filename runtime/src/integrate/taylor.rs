//! The Taylor method: each step is the Taylor polynomial of the solution, its coefficients
//! from the model's generated recurrences ([`crate::taylor`]), its order and step size from
//! the tolerance (Jorba & Zou 2005, §3, as heyoka implements it).

use super::Integrator;
use super::dense_output::DenseOutput;
use super::driver::{self, Control, Problem};
use super::error::{IntegrationError, IntegrationFailure};
use super::options::{ErrorWeights, IntegratorOptions, Tolerance};
use super::solution::Solution;
use super::stepper::{CheckedRhs, StepFailure, Stepper, SystemShape, first_non_finite};
use crate::ode::OdeSystem;

/// `$sized` with `$d` a constant, for the state's usual sizes (2, 4, 6, 8 and 12 values:
/// code compiled for the size, a row's values in registers and no loop over them), else
/// `$other`: the one list of those sizes, for the state's polynomial and the rows' norms.
macro_rules! by_usual_size {
    ($dim:expr, $d:ident => $sized:expr, _ => $other:expr $(,)?) => {
        by_usual_size!(@sizes $dim, $d, $sized, $other; 2 4 6 8 12)
    };
    (@sizes $dim:expr, $d:ident, $sized:expr, $other:expr; $($size:literal)*) => {
        match $dim {
            $($size => {
                const $d: usize = $size;
                $sized
            })*
            _ => $other,
        }
    };
}

/// The Taylor method of adaptive order and step (Jorba & Zou 2005; Biscani & Izzo 2021):
/// every step evaluates the Taylor polynomial of the solution at the current state, its
/// coefficients computed to order `p` by the model's generated recurrences
/// ([`OdeSystem::taylor_coefficients`]), which is also the step's dense output.
///
/// # Order and step size
/// With `‖·‖` the max norm over the state `y` and `ε`, `N` chosen as in Jorba & Zou's
/// eq. (3-3) — `ε = atol`, `N = 1` if `rtol ‖y‖ ≤ atol` (absolute mode), else `ε = rtol`,
/// `N = ‖y‖` — the order is `p = ⌈−½ ln ε + 1⌉` (at least 2) and the step
///
/// ```text
/// h = min(ρ_{p−1}, ρ_p) · e^{−0.7/(p−1)} / e²,    ρ_k = (N / ‖y^[k]‖)^{1/k}
/// ```
///
/// (heyoka's `taylor_determine_h`: `ρ` estimates the radius of convergence, and the last
/// term is then about `N e^{−2p} ≤ N ε`), unless that radius is more than twice
/// `min(ρ_{p−3}, ρ_{p−2})`, which then replaces it: coefficients that vanish in a period of
/// four (a mechanism released at rest from a symmetric position) make the last two orders
/// 0, or rounding errors, and the radius infinite or huge; if all four vanish, the highest
/// order below them that does not decides. The step then stays on the principal branch of
/// every square root and non-integer power of the model ([`crate::taylor::branch_step`],
/// checked on the proposed steps only, not with [`IntegratorOptions::fixed_step`]). For `rtol = atol` the
/// tolerance is heyoka's `tol`. A tolerance given per component takes its smallest entry.
/// There is no error estimate and no rejected step; `dt_max` and the end of the interval cap
/// `h`, and with [`IntegratorOptions::fixed_step`] the steps are `dt` at the order of the
/// tolerance.
///
/// # Compensated summation
/// A step's end is `y + (δ + e)`, with `δ = h Σₖ₌₁ᵖ y^[k] hᵏ⁻¹` by Horner's rule and `e` the
/// rounding error of the last step's sum `y + (δ + e)`, kept exactly by Knuth's two-sum and
/// carried from step to step (compensated summation: Kahan 1965; Hairer, Lubich & Wanner,
/// *Geometric Numerical Integration*, 2nd ed., §VIII.5; heyoka's `high_accuracy` mode
/// compensates the sum of each step's polynomial but starts every step afresh). The
/// rounding of `y + δ` (`‖y‖ ε/2` a step, against the increment's own
/// `‖δ‖ ε`, far smaller when the step moves `y` little) then no longer accumulates: on the
/// figure eight over ten periods at `tol = 10⁻¹⁴` the error of the final state fell from
/// 3.1e-13 to 6.1e-14 and the energy drift from 3.3e-15 to 6.9e-16, for 0–6 % more time
/// (docs/performance.md). The first step (`e = 0`) is the plain sum to the bit (but for the
/// sign of a zero). The coefficients of each step are those at the rounded state `y`, and
/// the carry is added as if the flow moved it unchanged, so a step long against the scale
/// on which the forces vary gains nothing.
///
/// # Dense output and events
/// The step's polynomial, evaluated the same way with the carry of the step's start (`θ = 1`
/// gives the step's end to the bit): output times and events are located on it.
///
/// # Constraints
/// A model with constraints is integrated in its index-1 form `[M Jᵀ; J 0][q̈; λ] = [F; γ]`,
/// whose series the recurrences solve order by order with the multipliers
/// ([`crate::taylor::series_of_motion`]), the form every other method integrates. The
/// constraints then drift as they do under any method (by the truncation error of each step,
/// not corrected), unless [`crate::Stabilization::Projection`] projects each step's end onto
/// them (the next step's series then starts there). Baumgarte's terms and the penalty's
/// springs are not in the recurrences and are refused.
///
/// # Errors
/// As every [`Integrator`], and [`IntegrationError::NoTaylorRecurrences`] before any step for a
/// system without recurrences: equations given as a closure; a model whose equations use
/// `abs`, `sign`, `step` or a power with a variable exponent; constraints stabilised by
/// Baumgarte's terms or the penalty, or in a model compiled by `model!` (whose code has the
/// recurrences of `M q̈ = F` only; its file compiled at run time has them).
///
/// # Source
/// À. Jorba, M. Zou, *A software package for the numerical integration of ODEs by means of
/// high-order Taylor methods*, Exp. Math. 14(1) (2005) 99–117, §3; F. Biscani, D. Izzo,
/// *Revisiting high-order Taylor methods for astrodynamics and celestial mechanics*, MNRAS
/// 504(2) (2021) 2614–2628.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Taylor;

impl Taylor {
    /// The method.
    pub fn new() -> Self {
        Self
    }

    /// The order `p = ⌈−½ ln ε + 1⌉` (at least 2) for a tolerance `ε` (heyoka's
    /// `taylor_order_from_tol`): 8 for 1e-6, 12 for 1e-9, 15 for 1e-12, 20 for 2.2e-16.
    ///
    /// A tolerance of 0 (or below the smallest positive `f64`) gives the highest order used,
    /// 400; the method itself never asks with 0 (a zero `rtol` or `atol` only fixes the mode).
    pub fn order_for_tolerance(tolerance: f64) -> usize {
        let p = (-0.5 * tolerance.ln() + 1.0).ceil();
        if p.is_nan() || p < 2.0 {
            2
        } else if p.is_finite() {
            (p as usize).min(MAX_ORDER)
        } else {
            MAX_ORDER
        }
    }
}

/// The highest order used: a tolerance below the smallest normal `f64` asks for no more.
const MAX_ORDER: usize = 400;

impl Integrator for Taylor {
    fn name(&self) -> &'static str {
        "taylor"
    }

    /// The order at the default tolerances' relative mode (`rtol = 10⁻⁶`): the method's order
    /// follows the tolerance ([`Taylor::order_for_tolerance`]).
    fn order(&self) -> u32 {
        Taylor::order_for_tolerance(IntegratorOptions::DEFAULT_RTOL) as u32
    }
}

impl driver::Method for Taylor {
    fn run(
        &mut self,
        problem: &Problem<'_>,
        system: &mut dyn OdeSystem,
    ) -> Result<Solution, IntegrationFailure> {
        let options = problem.options;
        let control = if options.fixed_step {
            Control::Fixed
        } else {
            Control::Proposed
        };
        let support = system.taylor_support();
        let (rtol, atol) = (smallest(&options.rtol), smallest(&options.atol));
        driver::run(problem, system, control, |shape| {
            support.map_err(|reason| IntegrationError::NoTaylorRecurrences {
                reason: reason.to_string(),
            })?;
            Ok(TaylorStepper::new(shape, rtol, atol))
        })
    }
}

/// The smallest positive entry of a tolerance, or 0 if it has none (0 for every component:
/// that tolerance plays no part).
fn smallest(tolerance: &Tolerance) -> f64 {
    let values: &[f64] = match tolerance {
        Tolerance::Scalar(x) => std::slice::from_ref(x),
        Tolerance::PerComponent(v) => v,
    };
    let positive = values
        .iter()
        .copied()
        .filter(|&x| x > 0.0)
        .fold(f64::INFINITY, f64::min);
    if positive.is_finite() { positive } else { 0.0 }
}

/// The Taylor method's state: the coefficients at the current point (which give the next
/// step) and at the start of the last accepted step (its dense output).
pub(crate) struct TaylorStepper {
    dim: usize,
    rtol: f64,
    atol: f64,
    /// The order used at the current point.
    order: usize,
    t: f64,
    t_prev: f64,
    t_new: f64,
    y: Vec<f64>,
    y_new: Vec<f64>,
    /// The rounding error of the sum that gave `y` (compensated summation: `y + carry` is the
    /// step's end more closely than `y`), for the next step's sum.
    carry: Vec<f64>,
    /// The same for `y_new`.
    carry_new: Vec<f64>,
    /// The same at the start of the last accepted step (its dense output).
    previous_carry: Vec<f64>,
    /// `(order + 1) · dim` coefficients at `(t, y)`, order-major.
    coefficients: Vec<f64>,
    /// The same at the start of the last accepted step.
    previous: Vec<f64>,
    previous_order: usize,
    /// Scratch for the coefficients at a candidate.
    scratch: Vec<f64>,
    /// The step the coefficients at `(t, y)` propose.
    proposed: f64,
    /// `e^{−0.7/(p−1)} / e²` of the step rule, for `p = factor_order` (0: not yet computed).
    factor: f64,
    factor_order: usize,
    /// `(1/(p−1), 1/p)` for `p = factor_order`.
    reciprocals: (f64, f64),
    /// [`Taylor::order_for_tolerance`] of `rtol` and of `atol` (a logarithm each, once per
    /// run rather than per step).
    relative_order: usize,
    absolute_order: usize,
}

impl TaylorStepper {
    fn new(shape: SystemShape, rtol: f64, atol: f64) -> Self {
        let dim = shape.dim;
        // The highest order either mode can ask for (the driver refuses tolerances that are
        // both 0 for a component).
        let order = |tol: f64| {
            if tol > 0.0 {
                Taylor::order_for_tolerance(tol)
            } else {
                2
            }
        };
        let (relative_order, absolute_order) = (order(rtol), order(atol));
        let max_order = relative_order.max(absolute_order);
        let size = (max_order + 1) * dim;
        Self {
            dim,
            rtol,
            atol,
            order: max_order,
            t: 0.0,
            t_prev: 0.0,
            t_new: 0.0,
            y: vec![0.0; dim],
            y_new: vec![0.0; dim],
            carry: vec![0.0; dim],
            carry_new: vec![0.0; dim],
            previous_carry: vec![0.0; dim],
            coefficients: vec![0.0; size],
            previous: vec![0.0; size],
            previous_order: 0,
            scratch: vec![0.0; size],
            proposed: f64::INFINITY,
            factor: 0.0,
            factor_order: 0,
            reciprocals: (0.0, 0.0),
            relative_order,
            absolute_order,
        }
    }

    /// The mode of Jorba & Zou's eq. (3-3) at a state of max norm `norm`: `(ε, N)`.
    ///
    /// With `atol = 0` the mode is always relative (`N = ‖y‖`, or 1 at `y = 0`), with
    /// `rtol = 0` always absolute.
    fn mode(&self, norm: f64) -> (f64, f64) {
        if self.relative(norm) {
            (self.rtol, if norm > 0.0 { norm } else { 1.0 })
        } else {
            (self.atol, 1.0)
        }
    }

    /// Whether the mode at a state of max norm `norm` is relative.
    fn relative(&self, norm: f64) -> bool {
        if self.atol == 0.0 {
            true
        } else if self.rtol == 0.0 {
            false
        } else {
            self.rtol * norm > self.atol
        }
    }

    /// Computes the coefficients at `(t, y)` into `scratch`; the order used and `‖y‖`.
    fn series(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        t: f64,
        y: &[f64],
    ) -> Result<(usize, f64), StepFailure> {
        let norm = row_norm(y, 0, self.dim);
        let order = if self.relative(norm) {
            self.relative_order
        } else {
            self.absolute_order
        };
        let size = (order + 1) * self.dim;
        rhs.taylor_coefficients(t, y, order, &mut self.scratch[..size])?;
        Ok((order, norm))
    }

    with_host_features! {
        /// Makes the coefficients in `scratch` (of `order`, at a state of max norm `norm`)
        /// the current ones and proposes the next step from them.
        fn commit(stepper: &mut TaylorStepper, series: (usize, f64)) {
            stepper.commit_in(series.0, series.1);
        }
    }

    /// [`Self::commit`]'s body, inlined into its two copies.
    #[inline(always)]
    fn commit_in(&mut self, order: usize, norm: f64) {
        std::mem::swap(&mut self.coefficients, &mut self.scratch);
        self.order = order;
        let dim = self.dim;
        let c = &self.coefficients;
        // Row 0 is the state the series was computed at (`norm` is its max norm).
        let (_, n) = self.mode(norm);
        // N = 1 in the absolute mode.
        let ln_n = if n == 1.0 { 0.0 } else { n.ln() };
        // ln ρ_k: the radius of the last two orders as one exponential of the smaller
        // logarithm (three `ln` and one `exp` in place of two `powf` and an `exp`; in `perf`,
        // 5 % of a double-pendulum step at 1e-9 in `pow` before, 4 % in `log` and `exp`).
        // `ln ρ_k` as `(ln N − ln ‖x^[k]‖) · reciprocal`, `reciprocal = 1/k`.
        let ln_rho = |k: usize, reciprocal: f64| (ln_n - row_norm(c, k, dim).ln()) * reciprocal;
        let rho = |k: usize| ln_rho(k, 1.0 / k as f64).exp();
        let p = order;
        if self.factor_order != p {
            self.factor_order = p;
            self.factor = (-0.7 / (p - 1) as f64).exp() / std::f64::consts::E.powi(2);
            self.reciprocals = (1.0 / (p - 1) as f64, 1.0 / p as f64);
        }
        // Jorba & Zou (and heyoka) estimate the radius of convergence from the last two
        // orders, so that a series with only odd or only even terms is not taken for one
        // that ends. A mechanism released from rest in a symmetric position can have its
        // coefficients vanish in a period of four (the pendulum from horizontal at rest:
        // q^[2], q^[6], q^[10], … and q̇^[1], q̇^[5], …), and then the last two orders are 0
        // (or rounding errors) at p = 8, 12, 16, …: the radius comes out infinite (or
        // huge), one step to the end with a wrong polynomial. So when the last two orders
        // give more than twice the radius of the two before (ρ_k of a smooth solution grows
        // far more slowly: 1.26× from order 6 to 8 for `cos t`), those two decide; if all
        // four vanish, the highest order below them that does not.
        let first = p.saturating_sub(3).max(1);
        // The last two radii with their `1/k` computed once per order (a division each lay on
        // the path from one step's coefficients to the next step's state).
        let (r1, r0) = self.reciprocals;
        let mut radius = ln_rho(p - 1, r1).min(ln_rho(p, r0)).exp();
        // ρ_k < r/2 exactly when ‖x^[k]‖ (r/2)ᵏ > N: the earlier orders cost no logarithm
        // unless they decide, and (r/2)ᵏ is one power and then products.
        // (A loop rather than `any`, whose closure and running power were compiled out of
        // line as `try_fold`: about 110 instructions a step on the Kepler orbit in callgrind.)
        let half = 0.5 * radius;
        let mut power = half.powi(first as i32);
        let mut anomalous = false;
        for k in first..p - 1 {
            let row = row_norm(c, k, dim);
            if row > 0.0 && row * power > n {
                anomalous = true;
                break;
            }
            power *= half;
        }
        if anomalous {
            radius = (first..p - 1).map(rho).fold(f64::INFINITY, f64::min);
        }
        if radius == f64::INFINITY {
            radius = (1..first)
                .rev()
                .map(rho)
                .find(|r| r.is_finite())
                .unwrap_or(f64::INFINITY);
        }
        self.proposed = radius * self.factor;
    }

    with_host_features! {
        /// The polynomial of `coefficients` (of `order`, order-major rows, row 0 the state `y`)
        /// at `τ`: `y + (τ P(τ) + carry)` with `P(τ) = Σₖ₌₁ᵖ y^[k] τᵏ⁻¹` by Horner's rule, into
        /// `out`; with `carry_out`, the rounding error of that last sum by Knuth's two-sum (see
        /// [`Taylor`]'s compensated summation).
        ///
        /// (The even and odd orders as two chains in `τ²` were 1 % faster on the double pendulum
        /// at 10⁻⁹ — the chain is not what a step waits for — and round differently: kept as
        /// it is.)
        ///
        /// The state's usual sizes are compiled for their size (the rows then load as whole
        /// registers with no loop over the components: the generic loop was 6 % of a
        /// double-pendulum step at 10⁻⁶); the products and sums are the same, in the same order.
        fn horner(
            coefficients: &[f64],
            order: usize,
            dim: usize,
            tau: f64,
            carry: &[f64],
            out: &mut [f64],
            carry_out: Option<&mut [f64]>,
        ) {
            TaylorStepper::horner_in(coefficients, order, dim, tau, carry, out, carry_out);
        }
    }

    /// [`Self::horner`]'s body, inlined into its two copies.
    #[inline(always)]
    fn horner_in(
        coefficients: &[f64],
        order: usize,
        dim: usize,
        tau: f64,
        carry: &[f64],
        out: &mut [f64],
        carry_out: Option<&mut [f64]>,
    ) {
        by_usual_size! { dim,
            D => horner_of_size::<D>(coefficients, order, tau, carry, out, carry_out),
            _ => {
                if order == 0 {
                    out.fill(0.0);
                } else {
                    out.copy_from_slice(&coefficients[order * dim..(order + 1) * dim]);
                }
                for k in (1..order).rev() {
                    let row = &coefficients[k * dim..(k + 1) * dim];
                    for (o, &c) in out.iter_mut().zip(row) {
                        *o = *o * tau + c;
                    }
                }
                let y = &coefficients[..dim];
                match carry_out {
                    Some(carry_out) => {
                        for i in 0..dim {
                            (out[i], carry_out[i]) = sum_with_carry(y[i], out[i], tau, carry[i]);
                        }
                    }
                    None => {
                        for i in 0..dim {
                            out[i] = y[i] + (out[i] * tau + carry[i]);
                        }
                    }
                }
            }
        }
    }
}

/// `(s, e)`: `s = y + (p τ + carry)` and its rounding error `e = y + u − s` exactly (Knuth's
/// two-sum, six additions, with no condition on the operands' sizes), `u = p τ + carry`.
#[inline(always)]
fn sum_with_carry(y: f64, p: f64, tau: f64, carry: f64) -> (f64, f64) {
    let u = p * tau + carry;
    let s = y + u;
    let u_part = s - y;
    let y_part = s - u_part;
    (s, (y - y_part) + (u - u_part))
}

/// [`TaylorStepper::horner`] for a state of `D` components.
#[inline(always)]
fn horner_of_size<const D: usize>(
    coefficients: &[f64],
    order: usize,
    tau: f64,
    carry: &[f64],
    out: &mut [f64],
    carry_out: Option<&mut [f64]>,
) {
    let rows = coefficients[..(order + 1) * D].as_chunks::<D>().0;
    let mut sum = if order == 0 { [0.0; D] } else { rows[order] };
    for row in rows[1..order.max(1)].iter().rev() {
        for (s, &c) in sum.iter_mut().zip(row) {
            *s = *s * tau + c;
        }
    }
    let (y, carry, out) = (&rows[0], &carry[..D], &mut out[..D]);
    match carry_out {
        Some(carry_out) => {
            let carry_out = &mut carry_out[..D];
            for i in 0..D {
                (out[i], carry_out[i]) = sum_with_carry(y[i], sum[i], tau, carry[i]);
            }
        }
        None => {
            for i in 0..D {
                out[i] = y[i] + (sum[i] * tau + carry[i]);
            }
        }
    }
}

/// The max norm of row `k` of the order-major rows of `dim` values in `c`, the state's usual
/// sizes compiled for their size (the row's values in registers, no loop), as [`max_norm`]
/// (the same maximum: the same comparisons in the same order).
#[inline(always)]
fn row_norm(c: &[f64], k: usize, dim: usize) -> f64 {
    #[inline(always)]
    fn of_size<const D: usize>(c: &[f64], k: usize) -> f64 {
        max_norm(&c[k * D..(k + 1) * D])
    }
    by_usual_size! { dim,
        D => of_size::<D>(c, k),
        _ => max_norm(&c[k * dim..(k + 1) * dim]),
    }
}

/// The max norm `maxᵢ |vᵢ|` (NaN entries skipped, as `f64::max` does: a comparison and a
/// select, one `maxsd` each, where `f64::max`'s rule for NaN took four instructions per entry).
fn max_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m: f64, x| {
        let a = x.abs();
        if a > m { a } else { m }
    })
}

impl DenseOutput for TaylorStepper {
    fn interval(&self) -> (f64, f64) {
        (self.t_prev, self.t)
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        if self.t == self.t_prev {
            out.copy_from_slice(&self.y);
            return;
        }
        let tau = t - self.t_prev;
        Self::horner(
            &self.previous,
            self.previous_order,
            self.dim,
            tau,
            &self.previous_carry,
            out,
            None,
        );
    }
}

impl Stepper for TaylorStepper {
    fn t(&self) -> f64 {
        self.t
    }

    fn y(&self) -> &[f64] {
        &self.y
    }

    fn derivative(&self) -> &[f64] {
        &self.coefficients[self.dim..2 * self.dim]
    }

    fn reset(&mut self, rhs: &mut CheckedRhs<'_>, t0: f64, y0: &[f64]) -> Result<(), StepFailure> {
        self.t = t0;
        self.t_prev = t0;
        self.t_new = t0;
        self.y.copy_from_slice(y0);
        self.carry.fill(0.0);
        let series = self.series(rhs, t0, y0)?;
        Self::commit(self, series);
        self.proposed = rhs.taylor_branch_step(series.0, self.proposed);
        Ok(())
    }

    fn attempt(
        &mut self,
        _rhs: &mut CheckedRhs<'_>,
        t_new: f64,
        _weights: &ErrorWeights,
        _estimate_error: bool,
    ) -> Result<Option<f64>, StepFailure> {
        self.t_new = t_new;
        let tau = t_new - self.t;
        Self::horner(
            &self.coefficients,
            self.order,
            self.dim,
            tau,
            &self.carry,
            &mut self.y_new,
            Some(&mut self.carry_new),
        );
        match first_non_finite(&self.y_new) {
            Some(index) => Err(StepFailure::NonFiniteState { t: t_new, index }),
            None => Ok(None),
        }
    }

    fn proposed_step(&self) -> Option<f64> {
        Some(self.proposed)
    }

    fn accept(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        let (t_new, y_new) = (self.t_new, std::mem::take(&mut self.y_new));
        let series = self.series(rhs, t_new, &y_new);
        self.y_new = y_new;
        let series = series?;
        // The coefficients at the step's start become its dense output.
        std::mem::swap(&mut self.previous, &mut self.coefficients);
        self.previous_order = self.order;
        Self::commit(self, series);
        self.proposed = rhs.taylor_branch_step(series.0, self.proposed);
        self.t_prev = self.t;
        self.t = t_new;
        std::mem::swap(&mut self.y, &mut self.y_new);
        // The step's start carry goes with its coefficients to the dense output.
        std::mem::swap(&mut self.previous_carry, &mut self.carry);
        std::mem::swap(&mut self.carry, &mut self.carry_new);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::{max_norm, row_norm};

    /// `row_norm`'s copies for the usual sizes give `max_norm`'s result to the bit, for every
    /// row of a matrix of each size, with a NaN (skipped), an infinity and a negative zero
    /// among the values.
    #[test]
    fn row_norms_are_the_max_norm_of_the_row() {
        for dim in 1..=13 {
            let rows = 4;
            let mut c: Vec<f64> = (0..rows * dim)
                .map(|i| ((i * 7919) % 113) as f64 * if i % 3 == 0 { -0.37 } else { 1.9 })
                .collect();
            c[dim] = f64::NAN;
            c[2 * dim] = -0.0;
            c[3 * dim + dim / 2] = f64::NEG_INFINITY;
            for k in 0..rows {
                let row = &c[k * dim..(k + 1) * dim];
                assert_eq!(
                    row_norm(&c, k, dim).to_bits(),
                    max_norm(row).to_bits(),
                    "dim {dim}, row {k}"
                );
            }
        }
    }
}
