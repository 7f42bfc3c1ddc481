//! The stability of a steady motion (`eomgen modes --at NAME` where `NAME` holds rates, and
//! every operating point of a model with non-holonomic constraints): the steady motion
//! found with its rates held, the linearisation restricted to the constraints and reduced by
//! the ignorable coordinates ([`crate::linear::steady`]), its eigenvalues and the verdict.

use std::collections::BTreeMap;

use nalgebra::Complex;
use serde::Serialize;

use super::modes::DampedEigenvalueSummary;
use super::operating_point::{
    EquilibriumStart, OperatingPointError, OperatingPointOptions, steady_motion_spec,
};
use crate::linear::eigenvalues::Stability;
use crate::linear::steady::{
    SteadyLinearization, SteadyMotion, SteadyMotionError, find_steady_motion_with,
    linearize_steady_motion_with, steady_stability,
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
    let spec = steady_motion_spec(model, start);
    non_holonomic
        || spec.rates.iter().any(|r| *r != 0.0)
        || spec.turning.is_some()
        || !spec.solved_rates.is_empty()
        || !spec.held_coordinates.is_empty()
}

/// The frame of a steady turn as a report gives it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SteadyTurn {
    /// The turning angle (a heading).
    pub angle: String,
    /// The two coordinates whose rates are constant in the turning frame.
    pub plane: [String; 2],
    /// The turn's rate `Ω` (rad/s), the angle's rate: positive turns the first plane
    /// coordinate toward the second.
    pub rate: f64,
    /// The radius (in the plane coordinates' unit) of the circle the plane's point runs on,
    /// `|v|/|Ω|`; `None` (left out of the JSON) when `Ω = 0`, a straight line.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
}

/// A steady motion, its reduced linearisation and stability.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SteadyMotionAnalysis {
    /// The operating point's name (or the guess's label).
    pub name: String,
    /// The model's coordinates.
    pub coordinates: Vec<String>,
    /// Coordinates held at their value (`{ held: … }`) rather than found.
    pub held_coordinates: Vec<String>,
    /// Rates found (`{ guess: … }`) rather than held.
    pub found_rates: Vec<String>,
    /// A steady turn's frame, in which the plane's rates are held and the linearisation is
    /// taken; `None` for a steady motion whose rates are constant in the ground.
    pub turning: Option<SteadyTurn>,
    /// What the search found, by name: the coordinates neither ignorable nor held, and the
    /// rates found.
    pub found: BTreeMap<String, f64>,
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
    /// [`SteadyMotionAnalysis::held_coordinates`]; left out when empty.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub held_coordinates: Vec<String>,
    /// [`SteadyMotionAnalysis::found_rates`]; left out when empty.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub found_rates: Vec<String>,
    /// [`SteadyMotionAnalysis::turning`]; left out when `None`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub turning: Option<SteadyTurn>,
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
                held_coordinates: self.held_coordinates.clone(),
                found_rates: self.found_rates.clone(),
                turning: self.turning.clone(),
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
    steady_motion_analysis_from(model, options, None)
}

/// [`steady_motion_analysis`] with the search started from the state `from` (`(q, q̇)`,
/// length `2n`) where given: the coordinates it finds and the rates it finds start there,
/// while what the entry holds is held at the entry's values. A parameter sweep follows a
/// family of steady motions (a bicycle's turns as its lean grows) by starting each value
/// from the motion found at the one before.
///
/// # Errors
/// As [`steady_motion_analysis`].
pub fn steady_motion_analysis_from(
    model: &mut dyn ModelInfo,
    options: &OperatingPointOptions,
    from: Option<&[f64]>,
) -> Result<SteadyMotionAnalysis, SteadyAnalysisError> {
    let (name, mut guess) = options.start.resolve(model)?;
    let mut spec = steady_motion_spec(model, &options.start);
    let n = guess.len();
    if let Some(y) = from.filter(|y| y.len() == 2 * n) {
        for i in (0..n).filter(|i| !spec.held_coordinates.contains(i)) {
            guess[i] = y[i];
        }
        for &i in &spec.solved_rates {
            if let Some(rate) = spec.rates.get_mut(i) {
                *rate = y[n + i];
            }
        }
    }
    if let Some(i) = spec.rates.iter().position(|r| !r.is_finite()) {
        return Err(OperatingPointError::GuessNotFinite {
            model: model.description().name.to_string(),
            name,
            coordinate: model.description().state_name(model.num_dofs() + i),
            value: spec.rates[i],
        }
        .into());
    }
    let steady_motion = find_steady_motion_with(model, options.t, &guess, &spec)?;
    let linearization =
        linearize_steady_motion_with(model, options.t, &steady_motion.state(), &spec)?;
    let (eigenvalues, stability, rounded_real_part) = steady_stability(&linearization)?;
    let coordinates: Vec<String> = (model.description().coordinates.iter())
        .map(|c| c.to_string())
        .collect();
    let turning = spec.turning.map(|frame| {
        let [a, b] = frame.plane;
        let rate = steady_motion.qdot[frame.angle];
        let speed = steady_motion.qdot[a].hypot(steady_motion.qdot[b]);
        SteadyTurn {
            angle: coordinates[frame.angle].clone(),
            plane: [coordinates[a].clone(), coordinates[b].clone()],
            rate,
            radius: (rate != 0.0).then(|| speed / rate.abs()),
        }
    });
    let found = (spec.unknowns(n).into_iter())
        .map(|j| match j < n {
            true => (coordinates[j].clone(), steady_motion.q[j]),
            false => (
                format!("{}_dot", coordinates[j - n]),
                steady_motion.qdot[j - n],
            ),
        })
        .collect();
    Ok(SteadyMotionAnalysis {
        name,
        found,
        held_coordinates: (spec.held_coordinates.iter())
            .map(|&i| coordinates[i].clone())
            .collect(),
        found_rates: (spec.solved_rates.iter())
            .map(|&i| format!("{}_dot", coordinates[i]))
            .collect(),
        turning,
        coordinates,
        steady_motion,
        linearization,
        eigenvalues,
        stability,
        rounded_real_part,
    })
}
