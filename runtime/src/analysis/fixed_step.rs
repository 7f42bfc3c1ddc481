//! Warnings for a fixed step that cannot give a meaningful result, found before the run:
//! a step longer than the whole span, and a step past the method's linear stability limit on
//! the model's linearisation at the initial state.
//!
//! The check linearises the first-order system at `(0, y₀)` (`A = ∂F/∂y` by central
//! differences), takes the eigenvalues `λ` of
//! `A` whose real part is not positive (modes that the exact solution does not amplify) and
//! evaluates the method's amplification per step `ρ(hλ)`: `|R(hλ)|` with the stability
//! function `R` of explicit Euler, explicit midpoint, RK4 and the implicit midpoint rule, and
//! the spectral radius of the step matrix of symplectic Euler and Störmer–Verlet on the
//! oscillator of frequency `|λ|`. Over the `N = ⌈t_end/h⌉` steps such a mode grows by `ρᴺ`
//! where it should not grow at all; beyond a factor of [`SPURIOUS_GROWTH_LIMIT`] the run is
//! warned about (an RK4 step of 100 s on the double pendulum took its energy from 5 J to
//! 3·10³³ J and reported success). The linearisation holds near the start only, so this is a
//! warning, not a refusal, and a run that stays in the stable region may still go unstable
//! later (the drift measures report that).
//!
//! References: E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed.,
//! Springer, 1996, §IV.2 (stability functions); E. Hairer, C. Lubich, G. Wanner, *Geometric
//! Numerical Integration*, 2nd ed., Springer, 2006, §I.5 (linear stability of Störmer–Verlet);
//! syllabus lecture 4 (integration methods, stability of Euler's method).

use nalgebra::{Complex, DMatrix};
use serde::Serialize;

use crate::analysis::methods::Method;
use crate::integrate::IntegratorOptions;
use crate::model_info::ModelInfo;

/// The growth of a mode that should not grow, over the whole run, beyond which a fixed step
/// is warned about (a factor of 10: an error that the exact solution does not have, larger
/// than the state itself).
pub const SPURIOUS_GROWTH_LIMIT: f64 = 10.0;

/// A fixed step that cannot give a meaningful result (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum SimulationWarning {
    /// The fixed step is longer than the span: the run is a single step of length `t_end`.
    StepLongerThanSpan {
        /// The step asked for (s).
        dt: f64,
        /// The end time (s).
        t_end: f64,
    },
    /// The fixed step is past the method's linear stability limit on a mode of the
    /// linearisation at the initial state.
    StepPastStabilityLimit {
        /// The method.
        method: Method,
        /// The step (s).
        dt: f64,
        /// The eigenvalue `λ` of `∂F/∂y` at `(0, y₀)` (1/s), as `[re, im]`.
        eigenvalue: [f64; 2],
        /// The method's amplification of that mode per step, `ρ(hλ) > 1`.
        amplification: f64,
        /// `ρᴺ` over the run's `N` steps (may be `inf`).
        growth: f64,
        /// The largest step (s) at which that growth stays within
        /// [`SPURIOUS_GROWTH_LIMIT`] (about: by bisection).
        suggested_dt: f64,
    },
    /// After the run: the energy of a conservative model drifted by more than
    /// [`ENERGY_DRIFT_LIMIT`] of its scale, so the numbers do not follow the motion (found
    /// from the conservation law, whatever the linearisation at the start said: a pendulum
    /// released from the horizontal has `A = 0` there).
    EnergyNotConserved {
        /// `max |E − E(0)| / max (T + |V|)` over the run.
        drift: f64,
        /// `E(0)` (J).
        initial_energy: f64,
        /// The energy at the last sample (J).
        final_energy: f64,
    },
}

/// The relative energy drift of a conservative model beyond which a run is warned about
/// ([`SimulationWarning::EnergyNotConserved`]): a tenth of the energy scale, far beyond the
/// drift of a run that follows the motion (the default Dormand–Prince runs of the bundled
/// conservative models drift by orders of magnitude less) and far below the drift of about 1
/// of a run that blew up.
pub const ENERGY_DRIFT_LIMIT: f64 = 0.1;

impl std::fmt::Display for SimulationWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::StepLongerThanSpan { dt, t_end } => write!(
                f,
                "the step {dt} s is longer than the whole run (t_end = {t_end} s): the run is one step"
            ),
            Self::StepPastStabilityLimit {
                method,
                dt,
                eigenvalue,
                amplification,
                growth,
                suggested_dt,
            } => write!(
                f,
                "the step {dt} s is past the stability limit of {} on the linearisation at t = 0: its mode λ = {:.4e}{:+.4e}i is amplified {amplification:.3e}× per step ({growth:.3e}× over the run) where the motion does not grow; a step of at most ~{suggested_dt:.3e} s, or an adaptive method, follows it",
                method.display_name(),
                eigenvalue[0],
                eigenvalue[1],
            ),
            Self::EnergyNotConserved {
                drift,
                initial_energy,
                final_energy,
            } => write!(
                f,
                "the energy of this conservative model drifted by {drift:.3} of its scale (from {initial_energy:.6e} J to {final_energy:.6e} J): the run does not follow the motion; use a smaller step or tolerance"
            ),
        }
    }
}

/// `ln ρᴺ` over `t_end` with the step `h` on the mode `λ` (0 where `ρ ≤ 1`).
fn log_growth(method: Method, lambda: Complex<f64>, h: f64, t_end: f64) -> f64 {
    let rho = method.amplification(lambda * h).unwrap_or(1.0);
    if rho > 1.0 {
        (t_end / h).ceil() * rho.ln()
    } else {
        0.0
    }
}

/// `∂F/∂y` at `(t, y)` by central differences of `F` (`2 dim` evaluations). Not the
/// system's exact Jacobian: a model compiled at run time derives and compiles its Jacobians
/// only when first asked, which an explicit method never does, and a warning must not cost
/// more than the run (a 60-link chain's Jacobians doubled a short run's time).
fn state_jacobian(model: &mut dyn ModelInfo, t: f64, y: &[f64]) -> Option<DMatrix<f64>> {
    let dim = y.len();
    let ode = model.as_ode_mut();
    let mut jac = vec![0.0; dim * dim];
    let (mut plus, mut minus) = (vec![0.0; dim], vec![0.0; dim]);
    let mut shifted = y.to_vec();
    for j in 0..dim {
        let delta = f64::EPSILON.cbrt() * y[j].abs().max(1.0);
        shifted[j] = y[j] + delta;
        ode.rhs(t, &shifted, &mut plus).ok()?;
        shifted[j] = y[j] - delta;
        ode.rhs(t, &shifted, &mut minus).ok()?;
        shifted[j] = y[j];
        for i in 0..dim {
            jac[i + j * dim] = (plus[i] - minus[i]) / (2.0 * delta);
        }
    }
    Some(DMatrix::from_vec(dim, dim, jac))
}

/// The warnings for a run of `model` by the fixed-step `method` with the step `dt` from `y0`
/// at `t = 0` to `t_end` (see the module docs); none for an adaptive method, or where the
/// Jacobian cannot be evaluated or is not finite at `y0`. The step is `dt`, or
/// `t_end / 1000` when `None`, as [`crate::analysis::simulate`] runs it.
///
/// Of the modes past the limit, the warning names the one that grows most over the run.
///
/// # Examples
/// RK4 with a step of 100 s on a pendulum of period 2 s swinging about its hanging
/// equilibrium (`q = −π/2`, `λ = ±i√(g/l)`):
/// ```
/// use eomgen::analysis::{Method, SimulationWarning, fixed_step_warnings};
/// let mut model = (eomgen::models::find("simple_pendulum").unwrap().make)();
/// let y0 = [-1.4, 0.0];
/// let warnings = fixed_step_warnings(model.as_mut(), Method::Rk4, &y0, Some(100.0), 1000.0);
/// assert!(matches!(warnings[0], SimulationWarning::StepPastStabilityLimit { .. }));
/// assert!(fixed_step_warnings(model.as_mut(), Method::Rk4, &y0, Some(0.01), 10.0).is_empty());
/// ```
pub fn fixed_step_warnings(
    model: &mut dyn ModelInfo,
    method: Method,
    y0: &[f64],
    dt: Option<f64>,
    t_end: f64,
) -> Vec<SimulationWarning> {
    let mut warnings = Vec::new();
    if method.is_adaptive() || !(t_end.is_finite() && t_end > 0.0) {
        return warnings;
    }
    let h = dt.unwrap_or(t_end / f64::from(IntegratorOptions::DEFAULT_FIXED_STEPS));
    if !(h.is_finite() && h > 0.0) {
        return warnings;
    }
    if h > t_end {
        warnings.push(SimulationWarning::StepLongerThanSpan { dt: h, t_end });
    }
    let h = h.min(t_end);
    let Some(a) = state_jacobian(model, 0.0, y0) else {
        return warnings;
    };
    if a.iter().any(|v| !v.is_finite()) {
        return warnings;
    }
    let limit = SPURIOUS_GROWTH_LIMIT.ln();
    let Some(eigenvalues) = crate::linalg::eigenvalues(&a) else {
        return warnings;
    };
    let worst = eigenvalues
        .iter()
        .filter(|l| l.re <= 1e-8 * l.norm())
        .map(|&l| (l, log_growth(method, l, h, t_end)))
        .filter(|&(_, g)| g > limit)
        .max_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((lambda, log_growth_h)) = worst {
        // The largest step in (0, h] whose growth over the run is within the limit.
        let (mut lo, mut hi) = (0.0, h);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if log_growth(method, lambda, mid, t_end) > limit {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        warnings.push(SimulationWarning::StepPastStabilityLimit {
            method,
            dt: h,
            eigenvalue: [lambda.re, lambda.im],
            amplification: method.amplification(lambda * h).unwrap_or(1.0),
            growth: log_growth_h.exp(),
            suggested_dt: lo,
        });
    }
    warnings
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Explicit Euler on `λ = iω` amplifies by `√(1 + (hω)²)` per step, so its growth over
    /// `t_end` stays within 10 up to `h ≈ 2 ln 10 / (ω² t_end)` for small `hω`; RK4 is
    /// stable on the imaginary axis up to `hω = 2√2`, and the symplectic methods up to 2.
    #[test]
    fn amplification_matches_the_stability_functions() {
        let i = |y: f64| Complex::new(0.0, y);
        let euler = Method::Euler.amplification(i(0.5)).unwrap();
        assert!((euler - 1.25f64.sqrt()).abs() < 1e-15);
        assert!(
            Method::Rk4
                .amplification(i(2.0 * 2f64.sqrt() - 1e-6))
                .unwrap()
                <= 1.0
        );
        assert!(
            Method::Rk4
                .amplification(i(2.0 * 2f64.sqrt() + 1e-3))
                .unwrap()
                > 1.0
        );
        assert_eq!(Method::StormerVerlet.amplification(i(1.99)).unwrap(), 1.0);
        assert!(Method::StormerVerlet.amplification(i(2.01)).unwrap() > 1.0);
        assert!((Method::ImplicitMidpoint.amplification(i(100.0)).unwrap() - 1.0).abs() < 1e-12);
        assert!(Method::Dp54.amplification(i(100.0)).is_none());
        // Euler's growth over t_end = 10 at ω = 1 is ⌈10/h⌉ ln √(1 + h²): 1.86 at h = 0.4
        // (25 steps), 2.61 at h = 0.6 (17 steps), on either side of ln 10 = 2.30.
        let growth = |h: f64| log_growth(Method::Euler, i(1.0), h, 10.0);
        assert!((growth(0.4) - 25.0 * 1.16f64.sqrt().ln()).abs() < 1e-12);
        assert!(growth(0.4) < SPURIOUS_GROWTH_LIMIT.ln());
        assert!(growth(0.6) > SPURIOUS_GROWTH_LIMIT.ln());
    }
}
