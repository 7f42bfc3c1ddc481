//! Equilibria: `F(q, 0, t) = 0` (with the constraints `Φ(q) = 0` and their multipliers) by
//! damped Newton with minimum-norm SVD steps, and how far it got when it found none (issue 7;
//! lecture 22).

use nalgebra::{DMatrix, DVector};

use super::modal::*;
pub use super::stops::NewtonStop;
use crate::model_info::ModelInfo;

/// An equilibrium `F(q*, 0, t) = 0` (with constraints: `F(q*, 0, t) = Jᵀλ*`, `Φ(q*, t) = 0`)
/// found by Newton's method.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Equilibrium {
    /// The coordinates `q*` (length `n`).
    pub q: Vec<f64>,
    /// `lagrange_multipliers` `λ*` of the holonomic constraints at `q*` (length `m`; empty
    /// for an unconstrained model): the constraint forces that hold the mechanism at rest, in
    /// the sign convention of [`ModelDescription::constraints`](crate::ModelDescription::constraints).
    pub lagrange_multipliers: Vec<f64>,
    /// Newton iterations used.
    pub iterations: usize,
    /// Largest `|Fᵢ − (Jᵀλ)ᵢ|` and `|Φⱼ|` left (units of the generalized forces and of the
    /// constraint expressions).
    pub residual: f64,
}

/// Finds an equilibrium of `model` near `guess` by Newton's method with the generated
/// Jacobians (issue 7, item 1; lecture 25).
///
/// Unconstrained, the unknowns are `q` and the residual is `F(q, 0, t)` with Jacobian `∂F/∂q`
/// (in generalized speeds `F(q, Z(q, t), t)`, at rest, with `∂F/∂q + ∂F/∂u ∂Z/∂q`).
/// With holonomic constraints `Φ(q, t) = 0` (lectures 8–11), the unknowns are `(q, λ)` and the
/// residual is `[F(q, 0, t) − J(q)ᵀλ; Φ(q, t)]` with Jacobian
/// `[∂F/∂q − Σᵢ λᵢ ∇²Φᵢ, −Jᵀ; J, 0]`; `λ` starts from the least-squares solution of
/// `Jᵀλ = F` at the guess, and the constraint Hessians `∇²Φᵢ` are exact (see
/// [`constraint_hessians`]).
///
/// Each step solves the linear system in the least-squares, minimum-norm sense (SVD with
/// singular values below `1e-12 σ_max` dropped), so neutral directions (a free cart's
/// position, a rigid-body rotation) stay at their guess; steps are halved while the residual
/// does not decrease (at most 30 halvings). Converged when the largest residual is at most
/// `1e-12 r₀`, with `r₀` the larger of the largest residual at the guess and the size of its
/// terms there, `max_i Σ_j |J_ij x_j|` (the model's force scale, whatever its units), or when every step component is below `1e-14 |xᵢ|` (or no step decreases the
/// residual) with the residual down to `1e-8 r₀`, or when no step decreases the residual and
/// it is at rounding row by row — the Newton step would cancel it (`|F + J δ| ≤ 1e-6 |F|`)
/// and each `|F_i| ≤ 1e-12 Σ_j |J_ij|` (an exact guess, where the residual and the coordinates
/// are both near 0 and the loads that cancel there show in neither); a degenerate root (`F = −k x³`), where
/// Newton converges only linearly, is followed while the steps shrink (up to 100 iterations).
/// A small residual is refused as [`ModalError::EquilibriumAtInfinity`] when `max |qᵢ|` grew
/// to more than 10 times the guess's and the next Newton step is above `1e-3 max |qᵢ|`:
/// forces that fade with distance (a central `−μm/r²`) fall below any residual tolerance as
/// the iterates run off to infinity, each step a fixed fraction of the distance.
///
/// # Errors
/// [`ModalError::EquilibriumNotFound`] after 100 iterations, when no halving decreases the
/// residual, or when the Jacobian is zero (the forces do not depend on `q`: no equilibrium
/// unless they vanish) or not finite; [`ModalError::EquilibriumAtInfinity`] when the residual
/// is small only because the iterates ran away; [`ModalError::NonHolonomic`] for a model with non-holonomic constraints;
/// [`ModalError::DimensionMismatch`].
pub fn find_equilibrium(
    model: &dyn ModelInfo,
    guess: &[f64],
    t: f64,
) -> Result<Equilibrium, ModalError> {
    let n = model.num_dofs();
    check_point(model, guess)?;
    let m = model.description().holonomic_constraints;
    // At rest: `q̇ = 0`, which in generalized speeds is `u = Z(q, t)` (NaN where the
    // kinematic equations are singular, a residual no step accepts).
    let speeds = model.description().has_speeds();
    let rest = |q: &[f64]| super::speeds::rest(model, q, t);
    if speeds {
        // Speeds that depend on t, or kinematic equations singular at the guess, are said so
        // rather than left to Newton's failure.
        rest(guess)?;
    }
    let state = |q: &[f64]| -> Vec<f64> {
        super::speeds::rest_state(model, q, t)
            .unwrap_or_else(|_| q.iter().copied().chain(vec![f64::NAN; n]).collect())
    };
    // x = [q; λ]; the residual [F − Jᵀλ; Φ].
    let residual_of = |x: &[f64]| -> DVector<f64> {
        let y = state(&x[..n]);
        let (_, f) = model.mass_matrix_and_forcing(t, &y);
        if m == 0 {
            return f;
        }
        let c = model.constraint_equations(t, &y);
        let j = c.jacobian.rows(0, m);
        let lambda = DVector::from_column_slice(&x[n..]);
        let mut r = DVector::zeros(n + m);
        r.rows_mut(0, n).copy_from(&(f - j.transpose() * lambda));
        r.rows_mut(n, m).copy_from(&c.phi);
        r
    };
    let jacobian_of = |x: &[f64]| -> DMatrix<f64> {
        let y = state(&x[..n]);
        let (jq, jqd, _) = forcing_jacobians(model, t, &y);
        if speeds {
            // d F(q, Z(q))/dq = ∂F/∂q + ∂F/∂u ∂Z/∂q (unconstrained: the rules refuse speeds
            // beside constraints).
            return match rest(&x[..n]) {
                Ok(r) => jq + jqd * r.p,
                Err(_) => DMatrix::from_element(n, n, f64::NAN),
            };
        }
        if m == 0 {
            return jq;
        }
        let c = model.constraint_equations(t, &y);
        let mut a = DMatrix::zeros(n + m, n + m);
        let mut top = jq;
        for (lambda, h) in x[n..].iter().zip(constraint_hessians(model, &x[..n], t)) {
            top -= h * *lambda;
        }
        a.view_mut((0, 0), (n, n)).copy_from(&top);
        let j = c.jacobian.rows(0, m).into_owned();
        a.view_mut((0, n), (n, m)).copy_from(&(-j.transpose()));
        a.view_mut((n, 0), (m, n)).copy_from(&j);
        a
    };
    let mut x0 = guess.to_vec();
    if m > 0 {
        // λ from the least-squares solution of Jᵀλ = F at the guess.
        let y = state(guess);
        let (_, f) = model.mass_matrix_and_forcing(t, &y);
        let j = model
            .constraint_equations(t, &y)
            .jacobian
            .rows(0, m)
            .into_owned();
        let svd = j.transpose().svd(true, true);
        let eps = 1e-12 * svd.singular_values.max();
        let lambda = svd.solve(&f, eps).unwrap_or_else(|_| DVector::zeros(m));
        x0.extend(lambda.iter());
    }
    let (x, iterations, residual) =
        newton(&x0, &residual_of, &jacobian_of).map_err(|(iterations, residual, reason)| {
            ModalError::EquilibriumNotFound {
                iterations,
                reason,
                residual,
                guess: guess.to_vec(),
            }
        })?;
    // A small residual is a root only if the root is near: where the forces fade with
    // distance (`−μm/r²`), |F| falls below any tolerance as Newton walks off to infinity, each
    // step a fixed fraction of the distance, |q| growing by orders of magnitude. At a simple
    // root the next step is of the order of the rounding of q; at a degenerate one (`F = −k x³`)
    // a fixed fraction of the distance to the root, but q does not grow. Sizes are of q alone
    // (λ is a force).
    let step = newton_step(&jacobian_of(&x), &residual_of(&x))
        .rows(0, n)
        .amax();
    let size = x[..n].iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let start = guess.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if step.is_nan() || (step > RECEDING_STEP * size && size > RECEDING_GROWTH * start) {
        return Err(ModalError::EquilibriumAtInfinity {
            guess: guess.to_vec(),
            q: x[..n].to_vec(),
            residual,
            step,
        });
    }
    Ok(Equilibrium {
        q: x[..n].to_vec(),
        lagrange_multipliers: x[n..].to_vec(),
        iterations,
        residual,
    })
}

/// The largest Newton step from a converged iterate, relative to `max |qᵢ|`, that
/// [`find_equilibrium`] accepts when the iterates grew by [`RECEDING_GROWTH`]: beyond both
/// the residual is small only because the iterates ran away
/// ([`ModalError::EquilibriumAtInfinity`]). Walking off to infinity the step is a fixed
/// fraction of the distance (`r/2` under an inverse-square force, `1/r ≈ 0.04` for an
/// exponentially fading one); at a simple root it is rounding (`≲ 1e-12` relative).
const RECEDING_STEP: f64 = 1e-3;

/// How much `max |qᵢ|` must have grown over the guess's for a converged iterate with a large
/// step to count as walking away: a degenerate root (`F = −k x³`, steps a third of the
/// distance) is approached with `q` shrinking or staying of the guess's size.
const RECEDING_GROWTH: f64 = 10.0;

/// Newton has converged when the largest residual is below this fraction of the largest at
/// the guess: relative to the model's own force scale, so that a milligram pendulum
/// (forces of 1e-12 N·m) converges as well as a heavy one.
const RESIDUAL_REDUCTION: f64 = 1e-12;

/// `Σ_j |J_ij| w_j` for each row `i` of `J` (0 where not finite): with `w = |x|`, the size
/// of the terms of `F` near `x` (a stiffness times a coordinate, in the units of that row of
/// `F`); with `w = 1`, the force a row's stiffness gives at one unit (m or rad) of each
/// coordinate.
fn row_sums(jac: &DMatrix<f64>, weight: impl Fn(usize) -> f64) -> Vec<f64> {
    (0..jac.nrows())
        .map(|i| {
            let t: f64 = (0..jac.ncols())
                .map(|j| (jac[(i, j)] * weight(j)).abs())
                .sum();
            if t.is_finite() { t } else { 0.0 }
        })
        .collect()
}

/// The minimum-norm Newton step `−J⁺F` (singular values below `1e-12 σ_max` dropped); zero
/// when `J` is zero, not finite or the solve fails.
fn newton_step(jac: &DMatrix<f64>, f: &DVector<f64>) -> DVector<f64> {
    if !jac.iter().all(|v| v.is_finite()) {
        return DVector::zeros(f.len());
    }
    let svd = jac.clone().svd(true, true);
    let largest = svd.singular_values.max();
    if largest == 0.0 {
        return DVector::zeros(f.len());
    }
    svd.solve(&(-f), 1e-12 * largest)
        .unwrap_or_else(|_| DVector::zeros(f.len()))
}

/// Damped Newton with minimum-norm SVD steps (see [`find_equilibrium`]): returns the root,
/// the iterations and the largest residual, or `(iterations, residual, why)` on failure.
#[allow(clippy::type_complexity)]
fn newton(
    x0: &[f64],
    residual_of: &impl Fn(&[f64]) -> DVector<f64>,
    jacobian_of: &impl Fn(&[f64]) -> DMatrix<f64>,
) -> Result<(Vec<f64>, usize, f64), (usize, f64, NewtonStop)> {
    let norm = |f: &DVector<f64>| {
        let r = f.amax();
        if r.is_nan() { f64::INFINITY } else { r }
    };
    let mut x = x0.to_vec();
    let mut f = residual_of(&x);
    let mut r = norm(&f);
    // The size of the terms of F near x, `max_i Σ_j |J_ij x_j|` (a stiffness times a
    // coordinate: units of F), which sets its rounding where F itself is near 0.
    let terms = |jac: &DMatrix<f64>, x: &[f64]| -> f64 {
        row_sums(jac, |j| x[j]).into_iter().fold(0.0f64, f64::max)
    };
    // The force scale of the model at the guess, in its own units; a guess that is an exact
    // root is returned.
    let mut scale = if r.is_finite() { r } else { 0.0 };
    let converged = |r: f64, scale: f64| r <= RESIDUAL_REDUCTION * scale;
    // Converged as far as rounding allows: the residual is down by this much, yet no step
    // reduces it further.
    let stalled = |r: f64, scale: f64| r <= 1e-8 * scale;
    for iteration in 0..100 {
        if r == 0.0 || converged(r, scale) {
            return Ok((x, iteration, r));
        }
        let jac = jacobian_of(&x);
        if !jac.iter().all(|v| v.is_finite()) {
            return Err((iteration, r, NewtonStop::NonFiniteJacobian));
        }
        if jac.amax() == 0.0 {
            return Err((iteration, r, NewtonStop::ZeroJacobian));
        }
        if iteration == 0 {
            scale = scale.max(terms(&jac, &x));
            if converged(r, scale) {
                return Ok((x, 0, r));
            }
        }
        let floor = scale.max(terms(&jac, &x));
        let step = newton_step(&jac, &f);
        let mut lambda = 1.0;
        let mut accepted = false;
        for _ in 0..30 {
            let trial: Vec<f64> = x
                .iter()
                .zip(step.iter())
                .map(|(a, d)| a + lambda * d)
                .collect();
            let f_trial = residual_of(&trial);
            let r_trial = norm(&f_trial);
            if r_trial < r || converged(r_trial, scale) {
                // A step at the rounding of x: nothing more to gain.
                let small = step
                    .iter()
                    .zip(&x)
                    .all(|(d, a)| (lambda * d).abs() <= 1e-14 * a.abs());
                x = trial;
                f = f_trial;
                r = r_trial;
                accepted = true;
                if small && stalled(r, floor) {
                    return Ok((x, iteration + 1, r));
                }
                break;
            }
            lambda *= 0.5;
        }
        if !accepted {
            // No decrease along the Newton direction: converged as far as rounding allows,
            // or stuck. At an exact guess the residual and the coordinates are both near 0,
            // and the loads that cancel there (a weight on its springs) show in neither: then
            // the guess is a root if the linear model says the step would cancel F (F lies
            // in J's range, so only rounding stopped the decrease) and each row's residual
            // is at rounding of that row's stiffness times one unit of each coordinate (a
            // row J does not reach, a constant push on a free cart, is never so).
            let predicted = &f + &jac * &step;
            let at_rounding = predicted.amax() <= 1e-6 * r
                && row_sums(&jac, |_| 1.0)
                    .iter()
                    .zip(f.iter())
                    .all(|(unit, fi)| converged(fi.abs(), *unit));
            if stalled(r, floor) || at_rounding {
                return Ok((x, iteration + 1, r));
            }
            return Err((iteration + 1, r, NewtonStop::NoDecrease));
        }
    }
    if converged(r, scale) {
        return Ok((x, 100, r));
    }
    Err((100, r, NewtonStop::IterationLimit))
}
