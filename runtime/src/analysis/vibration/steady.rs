//! The stability of a steady motion (`eomgen modes --at NAME` where `NAME` holds rates, and
//! every operating point of a model with non-holonomic constraints): the steady motion
//! found with its rates held, the linearisation restricted to the constraints and reduced by
//! the ignorable coordinates ([`crate::linear::steady`]), its eigenvalues and the verdict.

use std::collections::BTreeMap;

use nalgebra::Complex;
use serde::Serialize;

use super::modes::DampedEigenvalueSummary;
use super::operating_point::{
    EquilibriumStart, OperatingPointError, OperatingPointOptions, held_rates,
};
use crate::linear::eigenvalues::Stability;
use crate::linear::steady::{
    SteadyLinearization, SteadyMotion, SteadyMotionError, find_steady_motion,
    linearize_steady_motion, steady_stability,
};
use crate::model_info::ModelInfo;

/// Why a steady-motion analysis failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SteadyAnalysisError {
    /// The operating point's name or guess is wrong.
    #[error(transparent)]
    OperatingPoint(#[from] OperatingPointError),
    /// The steady motion or its linearisation failed.
    #[error(transparent)]
    Steady(#[from] SteadyMotionError),
}

/// Whether the operating point `start` of `model` is analysed as a steady motion: it holds
/// a rate that is not 0, or the model has non-holonomic constraints (whose linearisation
/// the modal analysis of `M`, `C`, `K` cannot take).
pub fn is_steady_motion(model: &dyn ModelInfo, start: &EquilibriumStart) -> bool {
    let d = model.description();
    let non_holonomic = d.constraints.len() > d.holonomic_constraints;
    non_holonomic || held_rates(model, start).0.iter().any(|r| *r != 0.0)
}

/// A steady motion, its reduced linearisation and stability.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SteadyMotionAnalysis {
    /// The operating point's name (or the guess's label).
    pub name: String,
    /// The model's coordinates.
    pub coordinates: Vec<String>,
    /// The steady motion found.
    pub steady_motion: SteadyMotion,
    /// The reduced linearisation there.
    pub linearization: SteadyLinearization,
    /// The eigenvalues of its state matrix (1/s), by ascending `|s|` then `Im s`.
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub eigenvalues: Vec<Complex<f64>>,
    /// The verdict from them.
    pub stability: Stability,
    /// The largest `|Re s|` (1/s) set to 0 as rounding or as the differences' error, 0 when
    /// none: a marginal verdict with a positive value is decided within that bound.
    pub rounded_real_part: f64,
}

/// [`SteadyMotionAnalysis`] as `eomgen modes --json` prints it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SteadyMotionSummary {
    /// The model's name.
    pub model: String,
    /// The operating point: name, `q*` and `q̇*` by name, Gauss–Newton's iterations and
    /// residual.
    pub operating_point: SteadyPointSummary,
    /// The reduced state's entries, the state matrix and what was left out.
    #[serde(flatten)]
    pub linearization: SteadyLinearization,
    /// The eigenvalues with `Im s ≥ 0` (`re`, `im`, `damping_ratio`, `damped_frequency`).
    pub damped_modes: Vec<DampedEigenvalueSummary>,
    /// The verdict (`"verdict"` and its rate).
    pub stability: Stability,
    /// [`SteadyMotionAnalysis::rounded_real_part`].
    pub rounded_real_part: f64,
}

/// A steady motion in a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SteadyPointSummary {
    /// Its name.
    pub name: String,
    /// `q*` by coordinate.
    pub q: BTreeMap<String, f64>,
    /// `q̇*` by rate name (`phi_dot`).
    pub qdot: BTreeMap<String, f64>,
    /// Gauss–Newton iterations.
    pub iterations: usize,
    /// Largest residual left.
    pub residual: f64,
}

impl SteadyMotionAnalysis {
    /// The analysis as `eomgen modes --json` prints it.
    pub fn summary(&self, model: &dyn ModelInfo) -> SteadyMotionSummary {
        let names = &self.coordinates;
        SteadyMotionSummary {
            model: model.description().name.to_string(),
            operating_point: SteadyPointSummary {
                name: self.name.clone(),
                q: names
                    .iter()
                    .cloned()
                    .zip(self.steady_motion.q.iter().copied())
                    .collect(),
                qdot: names
                    .iter()
                    .map(|c| format!("{c}_dot"))
                    .zip(self.steady_motion.qdot.iter().copied())
                    .collect(),
                iterations: self.steady_motion.iterations,
                residual: self.steady_motion.residual,
            },
            linearization: self.linearization.clone(),
            damped_modes: damped_summaries(&self.eigenvalues),
            stability: self.stability,
            rounded_real_part: self.rounded_real_part,
        }
    }
}

/// Each eigenvalue with `Im s ≥ 0`, with `ζ = −Re s/|s|` and `ω_d = Im s`.
pub fn damped_summaries(eigenvalues: &[Complex<f64>]) -> Vec<DampedEigenvalueSummary> {
    eigenvalues
        .iter()
        .filter(|s| s.im >= 0.0)
        .map(|s| DampedEigenvalueSummary {
            re: s.re,
            im: s.im,
            // An exact 0 real part is ζ = 0, not −0.
            damping_ratio: if s.norm() > 0.0 && s.re != 0.0 {
                -s.re / s.norm()
            } else {
                0.0
            },
            damped_frequency: s.im,
        })
        .collect()
}

/// Finds the steady motion of `options.start` (its coordinates by Gauss–Newton from the
/// entry's guess, its rates held at the entry's values), linearises about it and decides
/// its stability from the eigenvalues of the reduced state matrix.
///
/// # Errors
/// [`SteadyAnalysisError::OperatingPoint`] for an unknown name or a bad guess;
/// [`SteadyAnalysisError::Steady`] when no steady motion is found or the linearisation
/// fails (see [`SteadyMotionError`]).
///
/// # References
/// D. L. Peterson, G. Gede, M. Hubbard, *Multibody System Dynamics* 33:143–161 (2015), for
/// the constrained linearisation; J. P. Meijaard et al., *Proc. R. Soc. A* 463:1955–1982
/// (2007), §5, for the reduction of a bicycle's steady motion to lean and steer.
pub fn steady_motion_analysis(
    model: &mut dyn ModelInfo,
    options: &OperatingPointOptions,
) -> Result<SteadyMotionAnalysis, SteadyAnalysisError> {
    let (name, guess) = options.start.resolve(model)?;
    let (rates, ignorable) = held_rates(model, &options.start);
    if let Some(i) = rates.iter().position(|r| !r.is_finite()) {
        return Err(OperatingPointError::GuessNotFinite {
            model: model.description().name.to_string(),
            name,
            coordinate: model.description().state_name(model.num_dofs() + i),
            value: rates[i],
        }
        .into());
    }
    let steady_motion = find_steady_motion(model, options.t, &guess, &rates, &ignorable)?;
    let linearization =
        linearize_steady_motion(model, options.t, &steady_motion.state(), &ignorable)?;
    let (eigenvalues, stability, rounded_real_part) = steady_stability(&linearization)?;
    Ok(SteadyMotionAnalysis {
        name,
        coordinates: model
            .description()
            .coordinates
            .iter()
            .map(|c| c.to_string())
            .collect(),
        steady_motion,
        linearization,
        eigenvalues,
        stability,
        rounded_real_part,
    })
}
