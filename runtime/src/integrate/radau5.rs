//! Radau IIA of order 5 (three stages), the L-stable implicit Runge–Kutta method of Hairer and
//! Wanner's RADAU5: simplified Newton iterations in the eigenbasis of the method's matrix
//! (one real and one complex linear system per iteration), an embedded error estimate,
//! Gustafsson's predictive step-size control and the collocation polynomial as dense output.
// The coefficients are transcribed with every digit their source prints, so that they can
// be checked against it; the compiler rounds them to f64.
#![allow(clippy::excessive_precision)]

use std::mem::swap;

use nalgebra::{Complex, DMatrix};

use crate::ode::OdeSystem;

use super::Integrator;
use super::controller::{NewtonWork, PredictiveController};
use super::dense_output::DenseOutput;
use super::driver::{self, Control, Problem};
use super::error::IntegrationFailure;
use super::linear::{LuFactors, SAME_STEP};
use super::options::{ErrorWeights, check_absolute_tolerance};
use super::solution::Solution;
use super::stepper::{CheckedRhs, StepFailure, Stepper};

/// Order of the error estimate (it behaves as `O(h⁴)`; RADAU5's exponent 1/4).
const ERROR_ORDER: u32 = 3;
/// Most Newton iterations per attempt (RADAU5's `NIT`, default of [`RadauIIA5`]).
const MAX_NEWTON_ITERATIONS: usize = 7;
/// The Jacobian is kept for the next step when the Newton contraction of the accepted step was
/// at most this (RADAU5's `THET`).
const JACOBIAN_REUSE_THETA: f64 = 0.001;
/// RADAU5's rounding unit `UROUND` (its default, `1e-16`; `f64::EPSILON / 2 ≈ 1.1e-16`), in
/// the Newton tolerance and as the floor of the contraction estimates, kept as `radau5.f`
/// has it so that runs repeat its steps.
const UROUND: f64 = 1e-16;

/// The method's constants, computed once per integration from their closed forms (nodes,
/// error-estimate weights, eigenvalues of `A⁻¹`), and the eigenvector matrix `T` of `A⁻¹` and
/// its inverse as Hairer's `radau5.f` prints them (20 digits).
#[derive(Debug, Clone)]
pub(crate) struct RadauConstants {
    /// Nodes `c₁ = (4 − √6)/10`, `c₂ = (4 + √6)/10` (`c₃ = 1`).
    pub(crate) c1: f64,
    pub(crate) c2: f64,
    /// Weights of the error estimate: `−(13 + 7√6)/3`, `(−13 + 7√6)/3`, `−1/3`.
    pub(crate) dd: [f64; 3],
    /// The real eigenvalue `γ` of `A⁻¹`.
    pub(crate) gamma: f64,
    /// The complex pair `α ± iβ` of eigenvalues of `A⁻¹`.
    pub(crate) alpha: f64,
    pub(crate) beta: f64,
    /// `T` with `T⁻¹ A⁻¹ T = [γ 0 0; 0 α −β; 0 β α]`.
    pub(crate) t: [[f64; 3]; 3],
    /// `T⁻¹`.
    pub(crate) t_inv: [[f64; 3]; 3],
}

impl RadauConstants {
    pub(crate) fn new() -> Self {
        let sq6 = 6.0_f64.sqrt();
        let cbrt81 = 81.0_f64.cbrt();
        let cbrt9 = 9.0_f64.cbrt();
        let u1 = (6.0 + cbrt81 - cbrt9) / 30.0;
        let alpha = (12.0 - cbrt81 + cbrt9) / 60.0;
        let beta = (cbrt81 + cbrt9) * 3.0_f64.sqrt() / 60.0;
        let norm = alpha * alpha + beta * beta;
        Self {
            c1: (4.0 - sq6) / 10.0,
            c2: (4.0 + sq6) / 10.0,
            dd: [
                -(13.0 + 7.0 * sq6) / 3.0,
                (-13.0 + 7.0 * sq6) / 3.0,
                -1.0 / 3.0,
            ],
            gamma: 1.0 / u1,
            alpha: alpha / norm,
            beta: beta / norm,
            t: [
                [
                    9.1232394870892942792e-02,
                    -0.14125529502095420843,
                    -3.0029194105147424492e-02,
                ],
                [
                    0.24171793270710701896,
                    0.20412935229379993199,
                    0.38294211275726193779,
                ],
                [0.96604818261509293619, 1.0, 0.0],
            ],
            t_inv: [
                [
                    4.3255798900631553510,
                    0.33919925181580986954,
                    0.54177053993587487119,
                ],
                [
                    -4.1787185915519047273,
                    -0.32768282076106238708,
                    0.47662355450055045196,
                ],
                [
                    -0.50287263494578687595,
                    2.5719269498556054292,
                    -0.59603920482822492497,
                ],
            ],
        }
    }
}

/// `out = Σⱼ m[row][j] · vⱼ[i]` for one component `i` of three stage vectors.
#[inline]
fn mix(m: &[[f64; 3]; 3], row: usize, v: [f64; 3]) -> f64 {
    m[row][0] * v[0] + m[row][1] * v[1] + m[row][2] * v[2]
}

/// The RADAU5 stepper, with all buffers allocated once.
#[derive(Debug, Clone)]
pub(crate) struct RadauStepper {
    n: usize,
    k: RadauConstants,
    max_iterations: usize,
    t: f64,
    t_prev: f64,
    t_new: f64,
    /// Size of the last accepted step (for the starting values and the dense output).
    h_prev: f64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    y_new: Vec<f64>,
    f: Vec<f64>,
    f_new: Vec<f64>,
    /// Stage increments `zₛ = Yₛ − y`.
    z: [Vec<f64>; 3],
    /// Transformed increments `w = T⁻¹ z`.
    w: [Vec<f64>; 3],
    /// `F` at the stages, then the transformed Newton right-hand sides and updates.
    fz: [Vec<f64>; 3],
    /// Stage input, finite-difference scratch, error estimate right-hand side.
    stage: Vec<f64>,
    /// The error estimate.
    err: Vec<f64>,
    /// Error and Newton scales `atolᵢ + rtolᵢ |yᵢ|` at the step's start.
    scale: Vec<f64>,
    /// Coefficients of the collocation polynomial of the last accepted step (`radau5.f`'s
    /// `CONT(N+1 …)`).
    cont: [Vec<f64>; 3],
    jac: DMatrix<f64>,
    /// `γ/h I − J`.
    real: LuFactors<f64>,
    /// `(α + iβ)/h I − J`.
    complex: LuFactors<Complex<f64>>,
    complex_rhs: Vec<Complex<f64>>,
    /// Whether `jac` was computed at the current `(t, y)`.
    jac_current: bool,
    /// Whether `jac` holds a Jacobian at all.
    jac_valid: bool,
    /// Whether an older Jacobian may serve the next attempt (fast convergence last time).
    reuse_jacobian: bool,
    /// Step size of the factorised matrices, NaN if none.
    lu_h: f64,
    /// Newton contraction of the last attempt.
    theta: f64,
    /// `θ/(1 − θ)` of the last attempt, the first iteration's convergence factor.
    faccon: f64,
    /// Newton iterations of the last attempt.
    iterations: usize,
    accepted_any: bool,
    attempted_since_accept: bool,
}

impl RadauStepper {
    pub(crate) fn new(n: usize, max_iterations: usize) -> Self {
        let v = || vec![0.0; n];
        Self {
            n,
            k: RadauConstants::new(),
            max_iterations,
            t: 0.0,
            t_prev: 0.0,
            t_new: 0.0,
            h_prev: 0.0,
            y: v(),
            y_prev: v(),
            y_new: v(),
            f: v(),
            f_new: v(),
            z: [v(), v(), v()],
            w: [v(), v(), v()],
            fz: [v(), v(), v()],
            stage: v(),
            err: v(),
            scale: v(),
            cont: [v(), v(), v()],
            jac: DMatrix::zeros(n, n),
            real: LuFactors::new(n),
            complex: LuFactors::new(n),
            complex_rhs: vec![Complex::new(0.0, 0.0); n],
            jac_current: false,
            jac_valid: false,
            reuse_jacobian: false,
            lu_h: f64::NAN,
            theta: JACOBIAN_REUSE_THETA,
            faccon: 1.0,
            iterations: 0,
            accepted_any: false,
            attempted_since_accept: false,
        }
    }

    fn update_jacobian(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        let [scratch, _, _] = &mut self.fz;
        rhs.jacobian(
            self.t,
            &self.y,
            &self.f,
            &mut self.jac,
            &mut self.stage,
            scratch,
        )?;
        self.jac_current = true;
        self.jac_valid = true;
        self.lu_h = f64::NAN;
        Ok(())
    }

    /// Factors `γ/h I − J` and `(α + iβ)/h I − J` unless they already are for this `h` (to
    /// within rounding: a step held by the controller lands on `t + h`, whose difference
    /// from `t` differs from `h` in the last bits).
    fn factor(&mut self, rhs: &mut CheckedRhs<'_>, h: f64) -> Result<(), StepFailure> {
        if (self.lu_h - h).abs() <= SAME_STEP * h.abs() {
            return Ok(());
        }
        self.lu_h = f64::NAN;
        let n = self.n;
        let (fac1, alphn, betan) = (self.k.gamma / h, self.k.alpha / h, self.k.beta / h);
        let real = self.real.matrix_mut();
        let complex = self.complex.matrix_mut();
        for j in 0..n {
            for i in 0..n {
                real[(i, j)] = -self.jac[(i, j)];
                complex[(i, j)] = Complex::new(-self.jac[(i, j)], 0.0);
            }
            real[(j, j)] += fac1;
            complex[(j, j)] += Complex::new(alphn, betan);
        }
        rhs.count_lu();
        let singular = StepFailure::SingularIterationMatrix { t: self.t };
        self.real.factor().map_err(|_| singular.clone())?;
        self.complex.factor().map_err(|_| singular)?;
        self.lu_h = h;
        Ok(())
    }

    /// Weighted RMS norm of `v` with the step's scales.
    fn norm(&self, v: &[f64]) -> f64 {
        if self.n == 0 {
            return 0.0;
        }
        let sum: f64 = v
            .iter()
            .zip(&self.scale)
            .map(|(v, s)| if *v == 0.0 { 0.0 } else { (v / s).powi(2) })
            .sum();
        (sum / self.n as f64).sqrt()
    }

    /// Starting values of the stage increments: zero before the first accepted step, else the
    /// collocation polynomial of the last accepted step, extrapolated (`radau5.f`).
    fn starting_values(&mut self, h: f64) {
        let n = self.n;
        if !self.accepted_any {
            for s in 0..3 {
                self.z[s].fill(0.0);
                self.w[s].fill(0.0);
            }
            return;
        }
        let (c1m1, c2m1) = (self.k.c1 - 1.0, self.k.c2 - 1.0);
        let ratio = h / self.h_prev;
        let nodes = [self.k.c1 * ratio, self.k.c2 * ratio, ratio];
        for i in 0..n {
            let (a1, a2, a3) = (self.cont[0][i], self.cont[1][i], self.cont[2][i]);
            let mut zi = [0.0; 3];
            for (s, &c) in nodes.iter().enumerate() {
                zi[s] = c * (a1 + (c - c2m1) * (a2 + (c - c1m1) * a3));
                self.z[s][i] = zi[s];
            }
            for s in 0..3 {
                self.w[s][i] = mix(&self.k.t_inv, s, zi);
            }
        }
    }

    /// The simplified Newton iteration for the stage increments (Hairer–Wanner II, §IV.8):
    /// returns the number of iterations, or the failure with RADAU5's step reduction.
    ///
    /// With `predict` (adaptive steps) an iteration that will not converge within the allowed
    /// iterations at its observed rate is abandoned early for a smaller step, as in RADAU5;
    /// with fixed steps, where the step cannot shrink, it runs on until it converges,
    /// diverges or uses up its iterations.
    // Long: pinned bit for bit against radau5.f; a split risks its order of operations.
    fn newton(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        h: f64,
        newton_tolerance: f64,
        predict: bool,
    ) -> Result<usize, StepFailure> {
        let n = self.n;
        let t = self.t;
        let nit = self.max_iterations;
        let (fac1, alphn, betan) = (self.k.gamma / h, self.k.alpha / h, self.k.beta / h);
        let nodes = [self.k.c1, self.k.c2, 1.0];
        self.faccon = self.faccon.max(UROUND).powf(0.8);
        self.theta = JACOBIAN_REUSE_THETA;
        let (mut dyno, mut dyno_old, mut thq_old) = (0.0, 0.0, 0.0);
        let mut iterations = 0;
        loop {
            if iterations >= nit {
                return Err(StepFailure::Newton {
                    t,
                    iterations,
                    residual_norm: dyno,
                    retry_factor: 0.5,
                });
            }
            for (s, &c) in nodes.iter().enumerate() {
                for i in 0..n {
                    self.stage[i] = self.y[i] + self.z[s][i];
                }
                let t_stage = if s == 2 { self.t_new } else { t + c * h };
                rhs.eval(t_stage, &self.stage, &mut self.fz[s])?;
            }
            // Right-hand sides in the eigenbasis: T⁻¹F − Λ w / h, with Λ = diag(γ, [α −β; β α]).
            for i in 0..n {
                let g = [self.fz[0][i], self.fz[1][i], self.fz[2][i]];
                let (w1, w2, w3) = (self.w[0][i], self.w[1][i], self.w[2][i]);
                self.fz[0][i] = mix(&self.k.t_inv, 0, g) - fac1 * w1;
                let r2 = mix(&self.k.t_inv, 1, g) - alphn * w2 + betan * w3;
                let r3 = mix(&self.k.t_inv, 2, g) - alphn * w3 - betan * w2;
                self.complex_rhs[i] = Complex::new(r2, r3);
            }
            self.real.solve_in_place(&mut self.fz[0]);
            self.complex.solve_in_place(&mut self.complex_rhs);
            for i in 0..n {
                self.fz[1][i] = self.complex_rhs[i].re;
                self.fz[2][i] = self.complex_rhs[i].im;
            }
            iterations += 1;
            let mut sum = 0.0;
            for i in 0..n {
                for s in 0..3 {
                    let d = self.fz[s][i];
                    if d != 0.0 {
                        sum += (d / self.scale[i]).powi(2);
                    }
                }
            }
            dyno = if n == 0 {
                0.0
            } else {
                (sum / (3 * n) as f64).sqrt()
            };
            if !dyno.is_finite() {
                return Err(StepFailure::Newton {
                    t,
                    iterations,
                    residual_norm: dyno,
                    retry_factor: 0.5,
                });
            }
            if iterations > 1 && iterations < nit {
                let thq = dyno / dyno_old;
                self.theta = if iterations == 2 {
                    thq
                } else {
                    (thq * thq_old).sqrt()
                };
                thq_old = thq;
                if self.theta < 0.99 {
                    self.faccon = self.theta / (1.0 - self.theta);
                    // Predicted error after the remaining iterations; if it will not meet
                    // the tolerance, retry at once with the step that would let it.
                    let remaining = (nit - 1 - iterations) as i32;
                    let predicted =
                        self.faccon * dyno * self.theta.powi(remaining) / newton_tolerance;
                    if predict && predicted >= 1.0 {
                        let q = predicted.clamp(1e-4, 20.0);
                        let factor = 0.8 * q.powf(-1.0 / (4.0 + f64::from(remaining)));
                        return Err(StepFailure::Newton {
                            t,
                            iterations,
                            residual_norm: dyno,
                            retry_factor: factor,
                        });
                    }
                } else {
                    return Err(StepFailure::Newton {
                        t,
                        iterations,
                        residual_norm: dyno,
                        retry_factor: 0.5,
                    });
                }
            }
            dyno_old = dyno.max(UROUND);
            for i in 0..n {
                let mut wi = [0.0; 3];
                for (s, w) in wi.iter_mut().enumerate() {
                    self.w[s][i] += self.fz[s][i];
                    *w = self.w[s][i];
                }
                for s in 0..3 {
                    self.z[s][i] = mix(&self.k.t, s, wi);
                }
            }
            if self.faccon * dyno <= newton_tolerance {
                return Ok(iterations);
            }
        }
    }

    /// The embedded error estimate of RADAU5 (Hairer–Wanner II, §IV.8, (8.19)–(8.20)):
    /// `err = (γ/h I − J)⁻¹ (F(t, y) + Σ dₛ zₛ / h)`, refined by one more evaluation of `F` on
    /// the first step and after a rejection when it exceeds 1, to filter out stiff
    /// components that the plain estimate overstates.
    fn error_estimate(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        h: f64,
        refine: bool,
    ) -> Result<f64, StepFailure> {
        let n = self.n;
        let [hee1, hee2, hee3] = self.k.dd.map(|d| d / h);
        for i in 0..n {
            self.stage[i] = hee1 * self.z[0][i] + hee2 * self.z[1][i] + hee3 * self.z[2][i];
            self.err[i] = self.stage[i] + self.f[i];
        }
        self.real.solve_in_place(&mut self.err);
        let mut error = self.norm(&self.err).max(1e-10);
        if error >= 1.0 && refine {
            // F(t, y + err) replaces F(t, y); `fz[0]` is free after the Newton iteration.
            for i in 0..n {
                self.err[i] += self.y[i];
            }
            rhs.eval(self.t, &self.err, &mut self.fz[0])?;
            for i in 0..n {
                self.err[i] = self.fz[0][i] + self.stage[i];
            }
            self.real.solve_in_place(&mut self.err);
            error = self.norm(&self.err).max(1e-10);
        }
        Ok(error)
    }
}

impl DenseOutput for RadauStepper {
    fn interval(&self) -> (f64, f64) {
        (self.t_prev, self.t)
    }

    /// The collocation polynomial of the last step (`radau5.f`'s `CONTR5`): with
    /// `s = (t − t₁)/h ∈ [−1, 0]`,
    /// `u(s) = y₁ + s (d₁ + (s − c₂ + 1)(d₂ + (s − c₁ + 1) d₃))`; degree 3, it interpolates
    /// `y₀`, the three stages and `y₁`.
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let h = self.t - self.t_prev;
        if h == 0.0 {
            out.copy_from_slice(&self.y);
            return;
        }
        let s = (t - self.t) / h;
        let (c1m1, c2m1) = (self.k.c1 - 1.0, self.k.c2 - 1.0);
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.y[i]
                + s * (self.cont[0][i]
                    + (s - c2m1) * (self.cont[1][i] + (s - c1m1) * self.cont[2][i]));
        }
    }
}

impl Stepper for RadauStepper {
    fn t(&self) -> f64 {
        self.t
    }

    fn y(&self) -> &[f64] {
        &self.y
    }

    fn derivative(&self) -> &[f64] {
        &self.f
    }

    fn reset(&mut self, rhs: &mut CheckedRhs<'_>, t0: f64, y0: &[f64]) -> Result<(), StepFailure> {
        self.t = t0;
        self.t_prev = t0;
        self.t_new = t0;
        self.h_prev = 0.0;
        self.y.copy_from_slice(y0);
        self.y_prev.copy_from_slice(y0);
        rhs.eval(t0, y0, &mut self.f)?;
        self.jac_current = false;
        self.jac_valid = false;
        self.reuse_jacobian = false;
        self.lu_h = f64::NAN;
        self.theta = JACOBIAN_REUSE_THETA;
        self.faccon = 1.0;
        self.iterations = 0;
        self.accepted_any = false;
        self.attempted_since_accept = false;
        Ok(())
    }

    fn attempt(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        t_new: f64,
        weights: &ErrorWeights,
        estimate_error: bool,
    ) -> Result<Option<f64>, StepFailure> {
        let n = self.n;
        let h = t_new - self.t;
        self.t_new = t_new;
        let rejected = self.attempted_since_accept;
        self.attempted_since_accept = true;
        for i in 0..n {
            self.scale[i] = weights.scale(i, self.y[i].abs());
        }
        // RADAU5's Newton tolerance max(10 u / rtol, min(0.03, √rtol)) with its rounding unit
        // u = UROUND, with the smallest relative tolerance (at least 1000 ε, so that a pure
        // atol still iterates).
        let rtol = weights
            .rtol
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
            .max(1e3 * f64::EPSILON);
        let rtol = if rtol.is_finite() { rtol } else { 1e-6 };
        let newton_tolerance = (10.0 * UROUND / rtol).max(0.03_f64.min(rtol.sqrt()));

        // After a rejection or a failure, a Jacobian from an earlier step is recomputed.
        if rejected {
            self.reuse_jacobian = false;
        }
        if !self.jac_valid || (!self.jac_current && !self.reuse_jacobian) {
            self.update_jacobian(rhs)?;
        }
        self.factor(rhs, h)?;
        self.starting_values(h);
        self.iterations = self.newton(rhs, h, newton_tolerance, estimate_error)?;
        for i in 0..n {
            self.y_new[i] = self.y[i] + self.z[2][i];
        }
        if let Some(index) = self.y_new.iter().position(|v| !v.is_finite()) {
            return Err(StepFailure::NonFiniteState { t: t_new, index });
        }
        if !estimate_error {
            return Ok(None);
        }
        let refine = !self.accepted_any || rejected;
        // Squared, as the driver expects (`√(e²) = e` exactly for the controller).
        self.error_estimate(rhs, h, refine)
            .map(|error| Some(error * error))
    }

    fn newton_work(&self) -> Option<NewtonWork> {
        Some(NewtonWork::new(
            self.iterations,
            self.max_iterations,
            self.theta <= JACOBIAN_REUSE_THETA,
        ))
    }

    fn accept(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        rhs.eval(self.t_new, &self.y_new, &mut self.f_new)?;
        let (c1, c2) = (self.k.c1, self.k.c2);
        let (c1m1, c2m1, c1mc2) = (c1 - 1.0, c2 - 1.0, c1 - c2);
        for i in 0..self.n {
            let (z1, z2, z3) = (self.z[0][i], self.z[1][i], self.z[2][i]);
            let d1 = (z2 - z3) / c2m1;
            let ak = (z1 - z2) / c1mc2;
            let acont3 = (ak - z1 / c1) / c2;
            let d2 = (ak - d1) / c1m1;
            self.cont[0][i] = d1;
            self.cont[1][i] = d2;
            self.cont[2][i] = d2 - acont3;
        }
        swap(&mut self.f, &mut self.f_new);
        swap(&mut self.y_prev, &mut self.y);
        swap(&mut self.y, &mut self.y_new);
        self.h_prev = self.t_new - self.t;
        self.t_prev = self.t;
        self.t = self.t_new;
        self.jac_current = false;
        self.reuse_jacobian = self.theta <= JACOBIAN_REUSE_THETA;
        self.accepted_any = true;
        self.attempted_since_accept = false;
        Ok(())
    }
}

/// Radau IIA of order 5 (three stages; Hairer and Wanner's RADAU5): L-stable, stiffly
/// accurate, for stiff problems, with adaptive steps and dense output.
///
/// The method is the collocation method at the Radau points `c = ((4 − √6)/10, (4 + √6)/10, 1)`:
///
/// ```text
///  (4−√6)/10 | (88−7√6)/360      (296−169√6)/1800  (−2+3√6)/225
///  (4+√6)/10 | (296+169√6)/1800  (88+7√6)/360      (−2−3√6)/225
///  1         | (16−√6)/36        (16+√6)/36        1/9
/// -----------+------------------------------------------------
///            | (16−√6)/36        (16+√6)/36        1/9
/// ```
///
/// Each step solves the stage equations `Z = h (A ⊗ I) F(Z)` by simplified Newton iterations
/// with `J = ∂F/∂y` from [`OdeSystem::jacobian`] (the generated exact Jacobians for models
/// through [`FirstOrder`](crate::FirstOrder); finite differences of `F` otherwise). Following
/// RADAU5, the iteration is transformed with the eigenvectors `T` of `A⁻¹`
/// (`T⁻¹A⁻¹T = diag(γ, [α −β; β α])`), so that each iteration solves one real `n × n` system
/// `(γ/h I − J)` and one complex one `((α + iβ)/h I − J)` (LU with partial pivoting, computed
/// only when `J` or `h` changes). The iteration starts from the extrapolated collocation
/// polynomial of the previous step and stops when the estimated remaining error
/// `θ/(1 − θ) ‖Δw‖` is below `max(10 u/rtol, min(0.03, √rtol))` (`u = 10⁻¹⁶`, weighted RMS
/// norm with scales `atolᵢ + rtolᵢ |yᵢ|`). It fails when it diverges (`θ ≥ 0.99`), uses up its
/// iterations (default 7), or is predicted too slow; the step is then retried smaller (halved,
/// or by RADAU5's predicted factor). The Jacobian is kept for the next step when the iteration
/// contracted by `θ ≤ 0.001`; after a rejected or failed attempt a Jacobian from an earlier
/// step is recomputed.
///
/// The error estimate is RADAU5's embedded third-order one, `(γ/h I − J)⁻¹(F(t, y) + Σ dₛ zₛ/h)`,
/// refined by one evaluation of `F` on the first step and after a rejection; steps are accepted
/// when its weighted RMS norm (scales `atolᵢ + rtolᵢ |yᵢ|` at the step's start) is below 1, and the
/// [`PredictiveController`] proposes the next one from the error and the Newton work
/// ([`NewtonWork`]). Unlike `radau5.f`, the tolerances are used as given (RADAU5 replaces `rtol` by
/// `rtol' = 0.1 rtol^(2/3)` and `atol` by `rtol' atol/rtol` internally), so that `rtol` means the
/// same for every method: the local error per step. Given those internal tolerances, an exact
/// Jacobian and the same starting step
/// ([`IntegratorOptions::with_dt`](super::IntegratorOptions::with_dt)), the method takes
/// `radau5.f`'s steps: the same accepted and rejected attempts, evaluations of `F` (one more, at
/// the final state), Jacobians and factorisations (tested on van der Pol's and Robertson's
/// problems, `runtime/tests/radau5_reference.rs`). Two things can still part them: a maximum step
/// (`dt_max` caps the proposal after the test for holding the step, radau5.f's `HMAX` before it),
/// and the end of the interval, where the driver stretches a step by up to 1 % onto `t_end` (as
/// DOPRI5 does) while radau5.f takes a step only as far as `t_end` reaches. Dense output
/// ([`OutputTimes::At`](super::OutputTimes::At)) is the collocation polynomial of each step (degree
/// 3, continuous extension of order 3). With
/// [`IntegratorOptions::fixed_step`](super::IntegratorOptions::fixed_step) the method takes
/// constant steps `dt` without error control; Newton then iterates until it converges, diverges or
/// uses up its iterations, and a failure is an error at once.
///
/// # Errors
/// Besides those of every method: [`IntegrationError::NewtonDidNotConverge`] when Newton still
/// fails as the step shrinks below the smallest usable step (or at once with fixed steps), and
/// [`IntegrationError::SingularIterationMatrix`] likewise for a singular iteration matrix.
///
/// [`IntegrationError::NewtonDidNotConverge`]: super::IntegrationError::NewtonDidNotConverge
/// [`IntegrationError::SingularIterationMatrix`]: super::IntegrationError::SingularIterationMatrix
///
/// # Examples
/// ```
/// use eomgen_runtime::{Integrator, IntegratorOptions, OdeFn, OutputTimes, RadauIIA5};
///
/// // A stiff linear problem: ẏ = −1000 (y − cos t), y(0) = 0, follows cos t after a layer.
/// let mut stiff = OdeFn::new(1, |t: f64, y: &[f64], dy: &mut [f64]| {
///     dy[0] = -1000.0 * (y[0] - t.cos());
/// });
/// let options = IntegratorOptions::default().with_rtol(1e-6).with_atol(1e-8);
/// let solution =
///     RadauIIA5::new().integrate(&mut stiff, 0.0, &[0.0], 10.0, &OutputTimes::Steps, &options)?;
/// let (_, y) = solution.last().unwrap();
/// // y ≈ cos t + sin t / 1000 away from the layer.
/// assert!((y[0] - (10.0_f64.cos() + 10.0_f64.sin() / 1000.0)).abs() < 1e-5);
/// assert!(solution.stats.steps < 200);
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
///
/// # References
/// - E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer,
///   1996, §IV.5 (Radau IIA), §IV.8 (implementation: transformation, starting values, error
///   estimate, step-size control), doi:10.1007/978-3-642-05221-7; and the code `radau5.f`,
///   whose constants `T` and `T⁻¹` are used here.
/// - B. L. Ehle, *On Padé approximations to the exponential function and A-stable methods for
///   the numerical solution of initial value problems*, Research Report CSRR 2010, University
///   of Waterloo, 1969.
/// - K. Gustafsson, "Control-theoretic techniques for stepsize selection in implicit
///   Runge–Kutta methods", ACM Trans. Math. Softw. 20(4), 496–517, 1994,
///   doi:10.1145/198429.198437.
#[derive(Debug, Clone)]
pub struct RadauIIA5 {
    controller: PredictiveController,
    max_newton_iterations: usize,
}

impl Default for RadauIIA5 {
    fn default() -> Self {
        Self {
            controller: PredictiveController::radau5(),
            max_newton_iterations: MAX_NEWTON_ITERATIONS,
        }
    }
}

impl RadauIIA5 {
    /// The method with [`PredictiveController::radau5`] and at most 7 Newton iterations per
    /// step.
    pub fn new() -> Self {
        Self::default()
    }

    /// Uses `controller` for the step sizes.
    pub fn with_controller(mut self, controller: PredictiveController) -> Self {
        self.controller = controller;
        self
    }

    /// Sets the most Newton iterations per attempt, `≥ 2` (default: 7, RADAU5's `NIT`).
    pub fn with_max_newton_iterations(mut self, max_newton_iterations: usize) -> Self {
        self.max_newton_iterations = max_newton_iterations;
        self
    }

    /// The step-size controller.
    pub fn controller(&self) -> &PredictiveController {
        &self.controller
    }
}

impl Integrator for RadauIIA5 {
    fn name(&self) -> &'static str {
        "radau5"
    }

    fn order(&self) -> u32 {
        5
    }
}

impl driver::Method for RadauIIA5 {
    fn run(
        &mut self,
        problem: &Problem<'_>,
        system: &mut dyn OdeSystem,
    ) -> Result<Solution, IntegrationFailure> {
        let options = problem.options;
        let control = Control::from_options(options, &mut self.controller, ERROR_ORDER);
        let iterations = self.max_newton_iterations.max(2);
        driver::run(problem, system, control, |shape| {
            check_absolute_tolerance(options, shape.dim, "Radau IIA (radau5)")?;
            Ok(RadauStepper::new(shape.dim, iterations))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::tableau::tests::assert_tree_order;
    use crate::ode::OdeFn;
    use crate::ode::tests::Linear;
    use nalgebra::{Matrix3, Vector3};

    /// The Butcher matrix of Radau IIA order 5, from its closed form.
    fn radau_a() -> Matrix3<f64> {
        let s = 6.0_f64.sqrt();
        Matrix3::new(
            (88.0 - 7.0 * s) / 360.0,
            (296.0 - 169.0 * s) / 1800.0,
            (-2.0 + 3.0 * s) / 225.0,
            (296.0 + 169.0 * s) / 1800.0,
            (88.0 + 7.0 * s) / 360.0,
            (-2.0 - 3.0 * s) / 225.0,
            (16.0 - s) / 36.0,
            (16.0 + s) / 36.0,
            1.0 / 9.0,
        )
    }

    /// RADAU5's error estimate on `ẏ = λy` from its definition (Hairer–Wanner II, IV.8
    /// (8.19)–(8.20)), with the stage increments solved directly from
    /// `(I − hλA) Z = hλ A𝟙 y₀`: `e₀ = (γ/h − λ)⁻¹ (λ y₀ + Σ dₛ Zₛ / h)` and, refined,
    /// `e₁ = (γ/h − λ)⁻¹ (λ (y₀ + e₀) + Σ dₛ Zₛ / h)`, each over the scale
    /// `atol + rtol |y₀|` (and at least 1e-10). The estimate is refined only when it is at
    /// least 1 on the first step or after a rejection.
    #[test]
    fn the_error_estimate_is_radau5s() {
        let (lambda, y0) = (-50.0, 1.0);
        let k = RadauConstants::new();
        let estimates = |h: f64, y: f64, tol: f64| -> (f64, f64) {
            let a = radau_a();
            let z = (Matrix3::identity() - a * (h * lambda))
                .lu()
                .solve(&(a * Vector3::repeat(h * lambda * y)))
                .unwrap();
            let dz = (k.dd[0] * z[0] + k.dd[1] * z[1] + k.dd[2] * z[2]) / h;
            let inverse = 1.0 / (k.gamma / h - lambda);
            let e0 = inverse * (lambda * y + dz);
            let e1 = inverse * (lambda * (y + e0) + dz);
            let scale = tol + tol * y.abs();
            ((e0 / scale).abs().max(1e-10), (e1 / scale).abs().max(1e-10))
        };
        // The same quantities, computed another way: 1e-9 relative leaves room for the
        // rounding of the Newton iteration and of the two solves (observed 1e-13).
        let close = |squared: f64, e: f64| (squared.sqrt() - e).abs() <= 1e-9 * e;
        let mut system = Linear(lambda);
        let mut rhs = CheckedRhs::new(&mut system);
        let tight = ErrorWeights::uniform(1, 1e-8, 1e-8);
        let mut stepper = RadauStepper::new(1, MAX_NEWTON_ITERATIONS);
        stepper.reset(&mut rhs, 0.0, &[y0]).unwrap();
        // The first step: e₀ ≥ 1 is refined.
        let (e0, e1) = estimates(0.1, y0, 1e-8);
        assert!(e0 >= 1.0 && (e1 - e0).abs() > 1e-3 * e0, "{e0} {e1}");
        let squared = stepper
            .attempt(&mut rhs, 0.1, &tight, true)
            .unwrap()
            .unwrap();
        assert!(close(squared, e1));
        // Rejected and retried before any acceptance: refined again.
        let (_, e1) = estimates(0.05, y0, 1e-8);
        let squared = stepper
            .attempt(&mut rhs, 0.05, &tight, true)
            .unwrap()
            .unwrap();
        assert!(close(squared, e1));
        // After an accepted step, e₀ ≥ 1 is kept.
        stepper.accept(&mut rhs).unwrap();
        let y1 = stepper.y()[0];
        let (e0, _) = estimates(0.1, y1, 1e-8);
        assert!(e0 >= 1.0);
        let squared = stepper
            .attempt(&mut rhs, 0.15, &tight, true)
            .unwrap()
            .unwrap();
        assert!(close(squared, e0));
        // That attempt rejected and retried, after an accepted step: refined.
        let (e0, e1) = estimates(0.08, y1, 1e-8);
        assert!(e0 >= 1.0);
        let squared = stepper
            .attempt(&mut rhs, 0.05 + 0.08, &tight, true)
            .unwrap()
            .unwrap();
        assert!(close(squared, e1));
        // The first step with e₀ < 1: kept.
        let loose = ErrorWeights::uniform(1, 1e-3, 1e-3);
        let (e0, _) = estimates(0.01, y0, 1e-3);
        assert!(e0 < 1.0 && e0 > 1e-10, "{e0}");
        stepper.reset(&mut rhs, 0.0, &[y0]).unwrap();
        let squared = stepper
            .attempt(&mut rhs, 0.01, &loose, true)
            .unwrap()
            .unwrap();
        assert!(close(squared, e0));
    }

    /// One factorisation per step size, at small steps too: fixed steps of 1e-6 over
    /// [0, 1.5e-6] are one of 1e-6 and one of 5e-7, two factorisations (the test of "the same
    /// step" is relative to `h`).
    #[test]
    fn a_new_small_step_is_factored_anew() {
        use crate::integrate::{Integrator, IntegratorOptions, OutputTimes};
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(1e-6);
        let solution = RadauIIA5::new()
            .integrate(
                &mut Linear(-50.0),
                0.0,
                &[1.0],
                1.5e-6,
                &OutputTimes::Steps,
                &options,
            )
            .unwrap();
        assert_eq!(solution.stats.steps, 2);
        assert_eq!(solution.stats.lu_decompositions, 2);
    }

    /// The Newton iteration limit given is kept: with fixed steps (which cannot shrink) two
    /// iterations (the least allowed) cannot solve the nonlinear stage equations of
    /// `ẏ = −y²` with h = 0.5, while the default limit does.
    #[test]
    fn the_newton_limit_is_kept() {
        use crate::integrate::{IntegrationError, Integrator, IntegratorOptions, OutputTimes};
        let mut system = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0] * y[0]);
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(0.5);
        let mut run = |method: RadauIIA5| {
            method
                .clone()
                .integrate(&mut system, 0.0, &[1.0], 1.0, &OutputTimes::Steps, &options)
        };
        let failure = run(RadauIIA5::new().with_max_newton_iterations(2)).unwrap_err();
        assert!(
            matches!(
                failure.error,
                IntegrationError::NewtonDidNotConverge { iterations: 2, .. }
            ),
            "{:?}",
            failure.error
        );
        assert!(run(RadauIIA5::new()).is_ok());
    }

    /// Row sums are the nodes, `Σ b = 1`, the simplifying assumption C(3)
    /// `Σⱼ aᵢⱼ cⱼ^(k−1) = cᵢᵏ/k` (stage order 3), and the order conditions of every tree up to
    /// order 5 (not 6).
    #[test]
    fn radau_iia_has_order_5_and_stage_order_3() {
        let k = RadauConstants::new();
        let a = radau_a();
        let c = [k.c1, k.c2, 1.0];
        for i in 0..3 {
            for power in 1..=3 {
                let sum: f64 = (0..3).map(|j| a[(i, j)] * c[j].powi(power - 1)).sum();
                let expected = c[i].powi(power) / f64::from(power);
                assert!((sum - expected).abs() < 1e-15, "C({power}) row {i}");
            }
        }
        let rows: Vec<Vec<f64>> = (0..3)
            .map(|i| (0..3).map(|j| a[(i, j)]).collect())
            .collect();
        let b = rows[2].clone();
        assert_tree_order("radau5", &rows, &b, 5, 1e-14, true);
    }

    /// `T⁻¹` is the inverse of `T`, and `T⁻¹ A⁻¹ T = diag(γ, [α −β; β α])`: the constants of
    /// the transformed Newton iteration are consistent with the method.
    #[test]
    fn transformation_diagonalises_a_inverse() {
        let k = RadauConstants::new();
        let t = Matrix3::from_fn(|i, j| k.t[i][j]);
        let t_inv = Matrix3::from_fn(|i, j| k.t_inv[i][j]);
        assert!((t_inv * t - Matrix3::identity()).amax() < 1e-15);
        let lambda = t_inv * radau_a().try_inverse().unwrap() * t;
        let expected = Matrix3::new(
            k.gamma, 0.0, 0.0, //
            0.0, k.alpha, -k.beta, //
            0.0, k.beta, k.alpha,
        );
        assert!((lambda - expected).amax() < 1e-13, "{lambda}");
    }

    /// The collocation polynomial passes through the start of the step, and the stepper
    /// solves ẏ = λy with the (2,3) Padé approximant of e^(hλ) (the stability function of
    /// Radau IIA order 5).
    #[test]
    fn linear_step_is_the_pade_approximant() {
        let lambda = -2.0;
        let mut system = OdeFn::new(1, move |_t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = lambda * y[0];
        });
        let mut rhs = CheckedRhs::new(&mut system);
        let mut stepper = RadauStepper::new(1, MAX_NEWTON_ITERATIONS);
        stepper.reset(&mut rhs, 0.0, &[1.0]).unwrap();
        let weights = ErrorWeights::uniform(1, 1e-10, 1e-10);
        let h: f64 = 0.2;
        stepper.attempt(&mut rhs, h, &weights, true).unwrap();
        stepper.accept(&mut rhs).unwrap();
        let z = h * lambda;
        let pade = (1.0 + 2.0 * z / 5.0 + z * z / 20.0)
            / (1.0 - 3.0 * z / 5.0 + 3.0 * z * z / 20.0 - z.powi(3) / 60.0);
        assert!(
            (stepper.y()[0] - pade).abs() < 1e-10,
            "{} vs {pade}",
            stepper.y()[0]
        );
        let mut out = [0.0];
        stepper.interpolate(0.0, &mut out);
        assert!((out[0] - 1.0).abs() < 1e-10, "{}", out[0]);
        stepper.interpolate(h, &mut out);
        assert_eq!(out[0], stepper.y()[0]);
        // The cubic collocation polynomial is accurate to O((hλ)⁴) inside the step:
        // (0.4)⁴ times a constant ~1e-3, observed 1.2e-5.
        stepper.interpolate(h / 2.0, &mut out);
        assert!((out[0] - (lambda * h / 2.0).exp()).abs() < 1e-4);
    }
}
