//! Drift measures of a computed motion: the energy `E = T + V` against its initial value, and
//! the residuals of the holonomic and velocity constraints, sample by sample.
//!
//! For a conservative model `E` is a constant of the motion, so its change measures the
//! integrator's error; for a constrained model integrated as a DAE (index-1 form, `Φ̈ = 0`
//! imposed), `Φ` and `Φ̇` drift away from zero unless the integration is stabilised
//! (Baumgarte) or projected.
//!
//! References: J. Baumgarte, "Stabilization of constraints and integrals of motion in
//! dynamical systems", *Computer Methods in Applied Mechanics and Engineering* 1 (1972) 1–16,
//! doi:10.1016/0045-7825(72)90018-7; E. Hairer, C. Lubich, G. Wanner, *Geometric Numerical
//! Integration*, 2nd ed., Springer, 2006, §IV.4 (projection methods) and §I.1 (energy).

use serde::Serialize;

use crate::integrate::Solution;
use crate::model_info::ModelInfo;

/// The energy at every sample and its relative drift (see [`energy_drift`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EnergyDrift {
    /// `E(0) = T + V` at the initial state (J).
    pub initial_energy: f64,
    /// `E = T + V` at every sample of the solution (J), in order.
    pub energy: Vec<f64>,
    /// The energy scale `max (T + |V|)` over the initial state and the samples (J).
    pub scale: f64,
    /// `max |E − E(0)| / scale` over the samples (the absolute deviation when the scale is
    /// 0); `None` for a solution without samples.
    pub drift: Option<f64>,
}

impl EnergyDrift {
    /// Measures [`Self::drift`] on `E` plus the energy lost at impacts (a run through
    /// impacts, [`crate::hybrid::run`]): `losses` are `(first sample after the impact, J
    /// lost)` in sample order, so that only the smooth phases' drift is measured. `energy`
    /// keeps the energy itself.
    pub fn add_losses(&mut self, losses: impl Iterator<Item = (usize, f64)>) {
        let mut losses = losses.peekable();
        let mut lost = 0.0;
        let mut deviation: f64 = 0.0;
        for (k, e) in self.energy.iter().enumerate() {
            while let Some(&(_, l)) = losses.peek().filter(|(sample, _)| *sample <= k) {
                lost += l;
                losses.next();
            }
            deviation = deviation.max((e + lost - self.initial_energy).abs());
        }
        if self.drift.is_some() {
            self.drift = Some(if self.scale > 0.0 {
                deviation / self.scale
            } else {
                deviation
            });
        }
    }

    /// `(E − E(0)) / scale` at every sample (the absolute deviation when the scale is 0),
    /// signed.
    pub fn relative(&self) -> Vec<f64> {
        self.energy
            .iter()
            .map(|e| {
                if self.scale > 0.0 {
                    (e - self.initial_energy) / self.scale
                } else {
                    e - self.initial_energy
                }
            })
            .collect()
    }
}

/// The energy drift of `solution` from the initial state `y0`:
///
/// ```text
/// drift = max_k |E(t_k) − E(0)| / max(T + |V|),   E = T + V,
/// ```
///
/// with the scale taken over the initial state and the samples, so that a motion of zero
/// total energy (a pendulum released from the horizontal) still gives a meaningful relative
/// figure. `eomgen simulate` prints it as `max|E - E(0)| / max(T + |V|)`.
///
/// # Shapes
/// `y0` has `2n` entries (`[q; q̇]`, `n = model.num_dofs()`), as has every sample.
///
/// # Examples
/// ```
/// use eomgen::analysis::energy_drift;
/// use eomgen::{DormandPrince54, Integrator, IntegratorOptions, OutputTimes};
///
/// let mut model = (eomgen::models::find("simple_pendulum").unwrap().make)();
/// let y0 = model.initial_state();
/// let options = IntegratorOptions::default().with_rtol(1e-10).with_atol(1e-12);
/// let solution = DormandPrince54::new()
///     .integrate(model.as_ode_mut(), 0.0, &y0, 10.0, &OutputTimes::Steps, &options)?;
/// let drift = energy_drift(model.as_ref(), &y0, &solution);
/// assert_eq!(drift.energy.len(), solution.len());
/// assert!(drift.drift.unwrap() < 1e-8);
/// # Ok::<(), eomgen::IntegrationFailure>(())
/// ```
pub fn energy_drift(model: &dyn ModelInfo, y0: &[f64], solution: &Solution) -> EnergyDrift {
    energy_drift_at(model, y0, solution.iter())
}

/// [`energy_drift`] over the states `samples` (`(t, y)` pairs, `y = [q; q̇]` of `2n`
/// entries), for samples that are not a whole [`Solution`] (an animation's frames).
///
/// # Examples
/// ```
/// use eomgen::analysis::energy_drift_at;
///
/// let model = (eomgen::models::find("simple_pendulum").unwrap().make)();
/// let y0 = model.initial_state();
/// let drift = energy_drift_at(model.as_ref(), &y0, [(0.0, y0.as_slice())].into_iter());
/// assert_eq!(drift.drift, Some(0.0));
/// assert_eq!(drift.relative(), [0.0]);
/// ```
pub fn energy_drift_at<'a>(
    model: &dyn ModelInfo,
    y0: &[f64],
    samples: impl Iterator<Item = (f64, &'a [f64])>,
) -> EnergyDrift {
    let mut energy = Vec::with_capacity(samples.size_hint().0);
    let initial_energy = model.energy(0.0, y0);
    let mut scale: f64 = model.kinetic_energy(0.0, y0) + model.potential_energy(0.0, y0).abs();
    for (t, y) in samples {
        let (tk, v) = (model.kinetic_energy(t, y), model.potential_energy(t, y));
        energy.push(tk + v);
        scale = scale.max(tk + v.abs());
    }
    let drift = (!energy.is_empty()).then(|| {
        let deviation = energy
            .iter()
            .map(|e| (e - initial_energy).abs())
            .fold(0.0, f64::max);
        if scale > 0.0 {
            deviation / scale
        } else {
            deviation
        }
    });
    EnergyDrift {
        initial_energy,
        energy,
        scale,
        drift,
    }
}

/// The constraint forces and the constraint drift at every sample (see
/// [`constraint_drift`]); empty for a model without constraints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConstraintDrift {
    /// The constraints' names (`m` of them), in the model's order.
    pub constraint_names: Vec<String>,
    /// The Lagrange multipliers `λ` (constraint forces, `m` per sample); `None` at a sample
    /// where the constrained system is singular.
    pub lagrange_multipliers: Vec<Option<Vec<f64>>>,
    /// `(max |Φᵢ|, max |Φ̇ᵢ|)` at every sample: the largest position-level residual and the
    /// largest velocity-level residual (units of the constraints: m or rad, per second).
    pub drift: Vec<(f64, f64)>,
}

impl ConstraintDrift {
    /// `(max |Φ|, max |Φ̇|)` over all samples; `(0, 0)` without samples or constraints.
    pub fn max_drift(&self) -> (f64, f64) {
        self.drift
            .iter()
            .fold((0.0f64, 0.0f64), |(a, b), (p, v)| (a.max(*p), b.max(*v)))
    }

    /// Whether the model has no constraints (then every vector is empty).
    pub fn is_empty(&self) -> bool {
        self.constraint_names.is_empty()
    }
}

/// The constraint forces `λ` and the residuals `(max |Φ|, max |Φ̇|)` at every sample of
/// `solution`, by [`ModelInfo::constraint_forces`] and [`ModelInfo::constraint_drift`].
///
/// # Shapes
/// One entry per sample; `λ` has `m = model.description().constraints.len()` entries.
///
/// # Examples
/// The cartesian pendulum (`x² + y² = l²`) integrated without stabilisation drifts off
/// its circle slowly; its rod tension is the one multiplier:
/// ```
/// use eomgen::analysis::constraint_drift;
/// use eomgen::{DormandPrince54, Integrator, IntegratorOptions, OutputTimes};
///
/// let mut model = (eomgen::models::find("simple_pendulum_cartesian").unwrap().make)();
/// let y0 = model.initial_state();
/// let options = IntegratorOptions::default().with_rtol(1e-8).with_atol(1e-10);
/// let solution = DormandPrince54::new()
///     .integrate(model.as_ode_mut(), 0.0, &y0, 2.0, &OutputTimes::Steps, &options)?;
/// let drift = constraint_drift(model.as_mut(), &solution);
/// assert_eq!(drift.constraint_names.len(), 1);
/// assert_eq!(drift.drift.len(), solution.len());
/// let (position, velocity) = drift.max_drift();
/// assert!(position > 0.0 && position < 1e-5 && velocity < 1e-5);
/// # Ok::<(), eomgen::IntegrationFailure>(())
/// ```
pub fn constraint_drift(model: &mut dyn ModelInfo, solution: &Solution) -> ConstraintDrift {
    let constraint_names: Vec<String> = model
        .description()
        .constraint_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let mut lagrange_multipliers = Vec::new();
    let mut drift = Vec::new();
    if !constraint_names.is_empty() {
        for (t, y) in solution.iter() {
            lagrange_multipliers.push(model.constraint_forces(t, y).ok());
            drift.push(model.constraint_drift(t, y));
        }
    }
    ConstraintDrift {
        constraint_names,
        lagrange_multipliers,
        drift,
    }
}
