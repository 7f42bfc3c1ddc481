//! `eomgen study rayleigh` as one call (lectures 35–37): the Rayleigh quotient
//! `R(v) = vᵀKv / vᵀMv` of a trial shape `v` at an equilibrium, against the exact lowest
//! natural frequency of the modal analysis, and its stationarity.
//!
//! With the mass-normalised modes `ψ_k` (`K ψ_k = ω_k² M ψ_k`, `ΨᵀMΨ = I`) and the modal
//! coordinates `η = ΨᵀM v`,
//!
//! ```text
//! R(v) = Σ ω_k² η_k² / Σ η_k²  ≥  ω₁²,
//! R(ψ₁ + ε w) − ω₁² = ε² (R(w) − ω₁²) / (1 + ε²)   for w ⊥_M ψ₁, ‖w‖_M = 1,
//! ```
//!
//! so `√R` bounds `ω₁` from above, exactly when `v ∝ ψ₁`, and its error is second order in
//! the shape's error `ε` (the quotient is stationary at each mode). Zero-frequency (rigid-body)
//! modes are projected out of `v` first — with them `R ≥ 0` says nothing — and the bound is
//! then on the lowest non-zero frequency.

use serde::Serialize;

use super::modes::{ModalAnalysis, ModalOptions, modal_analysis};
use super::operating_point::{
    OperatingPoint, OperatingPointError, OperatingPointOptions, PointSummary,
};
use crate::linear::modal::{Linearization, ModeKind, NormalModes};
use crate::model_info::ModelInfo;
use nalgebra::{DMatrix, DVector};

/// Why a Rayleigh quotient study failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RayleighError {
    /// No operating point, or its linearisation or modes failed.
    #[error(transparent)]
    OperatingPoint(#[from] OperatingPointError),
    /// The model has holonomic constraints (its linearisation is in minimal coordinates).
    #[error(
        "`{model}` has constraints; the Rayleigh quotient here takes a shape in the coordinates of an unconstrained model"
    )]
    Constrained {
        /// The model.
        model: String,
    },
    /// The shape does not have one entry per coordinate.
    #[error("the shape has {found} entries, `{model}` has {expected} coordinates ({coordinates})")]
    DimensionMismatch {
        /// The model.
        model: String,
        /// Its number of coordinates.
        expected: usize,
        /// Given.
        found: usize,
        /// The coordinates' names, comma separated.
        coordinates: String,
    },
    /// An entry of the shape is NaN or infinite.
    #[error("entry {index} of the shape is {value}, not a finite number")]
    NonFinite {
        /// 1-based index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// `vᵀMv = 0`: the zero shape (`M` is positive definite), whose quotient is `0/0`.
    #[error("the shape is zero (vᵀMv = 0), so its Rayleigh quotient 0/0 is undefined")]
    ZeroShape,
    /// The shape lies in the zero-frequency modes: nothing is left once they are projected
    /// out.
    #[error(
        "the shape is a zero-frequency (rigid-body) motion: with the {count} zero-frequency mode(s) projected out, {remaining:.1e} of its mass norm is left, so it bounds no vibration frequency"
    )]
    OnlyZeroModes {
        /// The number of zero-frequency modes.
        count: usize,
        /// `‖v − P v‖_M / ‖v‖_M` after the projection.
        remaining: f64,
    },
    /// Every mode has zero frequency: there is no lowest natural frequency to bound.
    #[error(
        "every mode of `{model}` here has zero frequency; there is no natural frequency to bound"
    )]
    NoOscillatoryMode {
        /// The model.
        model: String,
    },
    /// `K` is not symmetric (a follower load): Rayleigh's quotient bounds and is stationary at
    /// the frequencies of a symmetric `K` only, and those of `M⁻¹K` are not its extrema.
    #[error(
        "the stiffness matrix is not symmetric here (max |K − Kᵀ| / max |K| = {asymmetry:.2e}: a non-conservative load such as a follower force), and Rayleigh's quotient vᵀKv/vᵀMv bounds the natural frequencies of a symmetric K only; `modes` gives this system's eigenvalues"
    )]
    NonSymmetricStiffness {
        /// `‖K − Kᵀ‖_max / ‖K‖_max`.
        asymmetry: f64,
    },
    /// The equilibrium is unstable (`ω² < 0` for some mode): `R` still bounds the lowest
    /// `ω²` from above, but `√R` is no frequency to compare.
    #[error(
        "the equilibrium is unstable: mode {mode} has ω² = {eigenvalue:e} 1/s² < 0, so there is no lowest natural frequency for √R to bound (choose a stable equilibrium)"
    )]
    Unstable {
        /// The 1-based mode.
        mode: usize,
        /// Its `ω²` (1/s²).
        eigenvalue: f64,
    },
}

/// Options of [`rayleigh_study`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RayleighOptions {
    /// The operating point (default: the file's first named equilibrium, else `q = 0`).
    pub operating_point: OperatingPointOptions,
    /// The trial shape `v` (length `n`, one entry per coordinate; m or rad, any scale).
    pub shape: Vec<f64>,
    /// The sizes `ε` of the perturbations `ψ₁ + ε w` that show the stationarity (default:
    /// [`Self::DEFAULT_PERTURBATIONS`]; non-positive or non-finite ones are skipped).
    pub perturbations: Vec<f64>,
}

impl RayleighOptions {
    /// The default `ε`: 1e-1 down to 1e-3, where `R − ω₁² ∝ ε²` is well above rounding.
    pub const DEFAULT_PERTURBATIONS: [f64; 5] = [1e-1, 3e-2, 1e-2, 3e-3, 1e-3];

    /// The options for `shape` at the default operating point and perturbations.
    pub fn new(shape: Vec<f64>) -> Self {
        Self {
            operating_point: OperatingPointOptions::default(),
            shape,
            perturbations: Self::DEFAULT_PERTURBATIONS.to_vec(),
        }
    }
}

/// Which direction `w` the stationarity test perturbs `ψ₁` in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PerturbationDirection {
    /// The trial shape's own error: its part `M`-orthogonal to the lowest mode's eigenspace.
    ShapeError,
    /// The next higher mode (the trial shape is the lowest mode itself).
    NextMode,
}

/// `R(ψ₁ + ε w)` for one `ε`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PerturbedQuotient {
    /// `ε` (the shape's error in the mass norm, `‖v − ψ₁‖_M`).
    pub epsilon: f64,
    /// `R(ψ₁ + ε w)` (1/s²).
    pub rayleigh_quotient: f64,
    /// `R − ω₁²` (1/s²; ≥ 0 up to rounding).
    pub excess: f64,
    /// `ε² (R(w) − ω₁²) / (1 + ε²)`, the closed form of `excess` (1/s²).
    pub predicted_excess: f64,
    /// `(√R − ω₁)/ω₁`.
    pub relative_error: f64,
}

/// The stationarity of `R` at the lowest mode: `R(ψ₁ + ε w)` for several `ε` and the order
/// fitted to `R − ω₁² ∝ εᵖ` (2 in theory).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stationarity {
    /// Where `w` came from.
    pub direction: PerturbationDirection,
    /// `R(w)` (1/s²), `w ⊥_M ψ₁`, `‖w‖_M = 1`.
    pub direction_quotient: f64,
    /// One entry per `ε`, largest first as given.
    pub samples: Vec<PerturbedQuotient>,
    /// The least-squares slope of `ln(R − ω₁²)` against `ln ε` over the samples whose
    /// excess is above rounding; `None` with fewer than two.
    pub fitted_order: Option<f64>,
}

/// What [`rayleigh_study`] computed.
///
/// # Shapes
/// `n` coordinates: `shape`, `projected_shape`, `lowest_mode_shape`, `modal_participation`
/// have `n` entries.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RayleighStudy {
    /// The equilibrium.
    pub operating_point: OperatingPoint,
    /// `M`, `C`, `K` there (`n × n`).
    pub linearization: Linearization,
    /// The undamped normal modes (ascending).
    pub normal_modes: NormalModes,
    /// The trial shape `v` as given.
    pub shape: Vec<f64>,
    /// `v` with its zero-frequency modes projected out, `v − Σ_z ψ_z ψ_zᵀ M v` (`v` itself
    /// without zero-frequency modes).
    pub projected_shape: Vec<f64>,
    /// How many zero-frequency modes were projected out.
    pub zero_modes_removed: usize,
    /// `‖Σ_z ψ_z ψ_zᵀ M v‖_M / ‖v‖_M`: the part of the shape that was rigid-body motion.
    pub zero_mode_fraction: f64,
    /// `vᵀKv` of the projected shape (`K` symmetrised as the modes take it).
    pub stiffness_form: f64,
    /// `vᵀMv` of the projected shape.
    pub mass_form: f64,
    /// `R = vᵀKv / vᵀMv` (1/s²).
    pub rayleigh_quotient: f64,
    /// `√R` (rad/s), the estimate of the lowest natural frequency.
    pub frequency_estimate: f64,
    /// The 1-based index of the lowest oscillatory mode (after the zero-frequency ones).
    pub lowest_mode: usize,
    /// Its exact natural frequency `ω₁` (rad/s) from the modal analysis.
    pub natural_frequency: f64,
    /// Its mass-normalised shape `ψ₁`.
    pub lowest_mode_shape: Vec<f64>,
    /// `(√R − ω₁)/ω₁`: ≥ 0 by the bound.
    pub relative_error: f64,
    /// `R − ω₁²` (1/s²).
    pub excess: f64,
    /// `R ≥ ω₁²` to rounding (`R − ω₁² ≥ −1e-12 max ω²`).
    pub bound_holds: bool,
    /// `tan θ = ‖v − (ψ₁ᵀMv) ψ₁‖_M / |ψ₁ᵀMv|`, the shape's error relative to its `ψ₁` part
    /// (`None` when `v ⊥_M ψ₁`); for a repeated `ω₁`, relative to its part in the whole
    /// eigenspace of `ω₁` (`v − P₁v` against `P₁v`, `P₁` the `M`-orthogonal projection), so
    /// that `R − ω₁² = tan²θ (R(w) − ω₁²)/(1 + tan²θ)` holds either way.
    pub shape_error: Option<f64>,
    /// `η_k² / Σ η²` of each mode, `η = ΨᵀM v`: how the quotient averages the `ω_k²`.
    pub modal_participation: Vec<f64>,
    /// The stationarity test (`None` for one oscillatory mode: no other direction).
    pub stationarity: Option<Stationarity>,
}

impl RayleighStudy {
    /// The study as `eomgen study rayleigh --json` prints it ([`RayleighSummary`]).
    pub fn summary(&self, model: &dyn ModelInfo) -> RayleighSummary {
        RayleighSummary {
            model: model.description().name.to_string(),
            coordinates: self.operating_point.coordinates.clone(),
            operating_point: self.operating_point.summary_at(&self.linearization.q),
            natural_frequencies: self.normal_modes.natural_frequencies.clone(),
            shape: self.shape.clone(),
            projected_shape: self.projected_shape.clone(),
            zero_modes_removed: self.zero_modes_removed,
            zero_mode_fraction: self.zero_mode_fraction,
            rayleigh_quotient: self.rayleigh_quotient,
            frequency_estimate: self.frequency_estimate,
            lowest_mode: self.lowest_mode,
            natural_frequency: self.natural_frequency,
            lowest_mode_shape: self.lowest_mode_shape.clone(),
            relative_error: self.relative_error,
            excess: self.excess,
            bound_holds: self.bound_holds,
            shape_error: self.shape_error,
            modal_participation: self.modal_participation.clone(),
            stationarity: self.stationarity.clone(),
        }
    }
}

/// A [`RayleighStudy`] as `eomgen study rayleigh --json` prints it
/// ([`RayleighStudy::summary`]): the matrices left out.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RayleighSummary {
    /// The model's name.
    pub model: String,
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// The operating point.
    pub operating_point: PointSummary,
    /// Every natural frequency (rad/s, ascending; 0 for zero-frequency modes).
    pub natural_frequencies: Vec<f64>,
    /// [`RayleighStudy::shape`].
    pub shape: Vec<f64>,
    /// [`RayleighStudy::projected_shape`].
    pub projected_shape: Vec<f64>,
    /// [`RayleighStudy::zero_modes_removed`].
    pub zero_modes_removed: usize,
    /// [`RayleighStudy::zero_mode_fraction`].
    pub zero_mode_fraction: f64,
    /// `R` (1/s²).
    pub rayleigh_quotient: f64,
    /// `√R` (rad/s).
    pub frequency_estimate: f64,
    /// [`RayleighStudy::lowest_mode`].
    pub lowest_mode: usize,
    /// `ω₁` (rad/s).
    pub natural_frequency: f64,
    /// `ψ₁`.
    pub lowest_mode_shape: Vec<f64>,
    /// `(√R − ω₁)/ω₁`.
    pub relative_error: f64,
    /// `R − ω₁²` (1/s²).
    pub excess: f64,
    /// `R ≥ ω₁²`.
    pub bound_holds: bool,
    /// [`RayleighStudy::shape_error`].
    pub shape_error: Option<f64>,
    /// [`RayleighStudy::modal_participation`].
    pub modal_participation: Vec<f64>,
    /// [`RayleighStudy::stationarity`].
    pub stationarity: Option<Stationarity>,
}

/// Two eigenvalues `ω²` within this fraction of the larger are one repeated frequency (the
/// stationarity test perturbs out of the whole eigenspace of `ω₁`).
const SAME_FREQUENCY: f64 = 1e-9;

/// The Rayleigh quotient `R(v) = vᵀKv / vᵀMv` of the trial shape `v` at an equilibrium,
/// `√R` against the exact lowest natural frequency `ω₁` of [`modal_analysis`], the bound
/// `R ≥ ω₁²`, the shape's modal participation, and the stationarity of `R`: `R(ψ₁ + ε w)`
/// for [`RayleighOptions::perturbations`] with the fitted order of `R − ω₁² ∝ εᵖ`
/// (lectures 35–37).
///
/// Zero-frequency modes (a free structure's rigid-body motions) are projected out of `v`
/// (`M`-orthogonally, with the mass-normalised shapes) before the quotient is taken, and `ω₁`
/// is then the lowest non-zero frequency. `K` is symmetrised as [`normal_modes`] takes it
/// where it is symmetric to rounding; a `K` that is not (a follower load) is refused.
///
/// [`normal_modes`]: crate::linear::modal::normal_modes
///
/// # Errors
/// [`RayleighError::OperatingPoint`], [`RayleighError::Constrained`],
/// [`RayleighError::DimensionMismatch`], [`RayleighError::NonFinite`],
/// [`RayleighError::ZeroShape`], [`RayleighError::OnlyZeroModes`],
/// [`RayleighError::NoOscillatoryMode`], [`RayleighError::Unstable`],
/// [`RayleighError::NonSymmetricStiffness`].
///
/// # Examples
/// Three equal masses (`three_masses`, `m = k = 1`): the uniform shape `(1, 1, 1)` gives
/// `R = 2/3` against `ω₁² = 2 − √2 = 0.586`.
/// ```
/// use eomgen_runtime::analysis::vibration::{RayleighOptions, rayleigh_study};
/// let model = (eomgen::models::find("three_masses").unwrap().make)();
/// let study = rayleigh_study(model.as_ref(), &RayleighOptions::new(vec![1.0, 1.0, 1.0]))?;
/// assert!((study.rayleigh_quotient - 2.0 / 3.0).abs() < 1e-13);
/// assert!((study.natural_frequency - (2.0 - 2f64.sqrt()).sqrt()).abs() < 1e-13);
/// assert!(study.bound_holds);
/// let order = study.stationarity.unwrap().fitted_order.unwrap();
/// assert!((order - 2.0).abs() < 0.01);
/// # Ok::<(), eomgen_runtime::analysis::vibration::RayleighError>(())
/// ```
///
/// # References
/// Lectures 35–37; Lord Rayleigh, *The Theory of Sound*, vol. 1, §88–89 (1877);
/// L. Meirovitch, *Fundamentals of Vibrations*, §7.9 (2001).
pub fn rayleigh_study(
    model: &dyn ModelInfo,
    options: &RayleighOptions,
) -> Result<RayleighStudy, RayleighError> {
    let modal = modal_analysis(
        model,
        &ModalOptions {
            operating_point: options.operating_point.clone(),
        },
    )?;
    check_inputs(model, options, &modal)?;
    let modes = &modal.normal_modes;
    let m = &modal.linearization.mass_matrix;
    let stiffness = &modal.linearization.stiffness_matrix;
    let k_sym = (stiffness + stiffness.transpose()) * 0.5;
    let psi = &modes.mode_shapes;
    let quotient = |v: &DVector<f64>| v.dot(&(&k_sym * v)) / mass_form(m, v);
    let Projection {
        scale,
        projected,
        zero_modes,
        zero_mode_fraction,
        lowest,
    } = project_shape(model, &options.shape, m, modes)?;
    let mass = mass_form(m, &projected);
    let stiffness_form = projected.dot(&(&k_sym * &projected));
    let rayleigh_quotient = stiffness_form / mass;
    let omega1 = modes.natural_frequencies[lowest];
    let w1 = modes.eigenvalues[lowest];
    let frequency_estimate = rayleigh_quotient.max(0.0).sqrt();
    let largest = modes.eigenvalues.iter().fold(0.0f64, |a, w| a.max(w.abs()));
    let excess = rayleigh_quotient - w1;
    let eta: DVector<f64> = psi.transpose() * (m * &projected);
    let eta_norm = eta.norm_squared();
    let modal_participation = eta.iter().map(|e| e * e / eta_norm).collect();
    let psi1 = psi.column(lowest).into_owned();
    let (remainder, shape_error) = lowest_eigenspace_error(m, modes, lowest, &projected);
    let stationarity = stationarity(
        (m, modes),
        (lowest, &remainder, projected.norm()),
        &options.perturbations,
        &quotient,
    );
    Ok(RayleighStudy {
        shape: options.shape.clone(),
        projected_shape: projected.iter().map(|x| x * scale).collect(),
        zero_modes_removed: zero_modes,
        zero_mode_fraction,
        stiffness_form: stiffness_form * scale * scale,
        mass_form: mass * scale * scale,
        rayleigh_quotient,
        frequency_estimate,
        lowest_mode: lowest + 1,
        natural_frequency: omega1,
        lowest_mode_shape: psi1.iter().copied().collect(),
        relative_error: (frequency_estimate - omega1) / omega1,
        excess,
        bound_holds: excess >= -1e-12 * largest,
        shape_error,
        modal_participation,
        stationarity,
        operating_point: modal.operating_point,
        linearization: modal.linearization,
        normal_modes: modal.normal_modes,
    })
}

/// `vᵀMv`, the squared mass norm of `v` (`n` entries; `M` is `n × n`).
fn mass_form(m: &DMatrix<f64>, v: &DVector<f64>) -> f64 {
    v.dot(&(m * v))
}

/// Refuses what [`rayleigh_study`] cannot take at the equilibrium `modal` found: a model with
/// constraints ([`RayleighError::Constrained`]), a shape without one finite entry per
/// coordinate ([`RayleighError::DimensionMismatch`], [`RayleighError::NonFinite`]), a `K`
/// that is not symmetric ([`RayleighError::NonSymmetricStiffness`]) and an unstable
/// equilibrium ([`RayleighError::Unstable`]), in that order.
fn check_inputs(
    model: &dyn ModelInfo,
    options: &RayleighOptions,
    modal: &ModalAnalysis,
) -> Result<(), RayleighError> {
    let name = || model.description().name.to_string();
    let n = model.num_dofs();
    if modal.linearization.num_minimal_coordinates() != n {
        return Err(RayleighError::Constrained { model: name() });
    }
    if options.shape.len() != n {
        return Err(RayleighError::DimensionMismatch {
            model: name(),
            expected: n,
            found: options.shape.len(),
            coordinates: model.description().coordinate_names().join(", "),
        });
    }
    if let Some((i, &value)) = options
        .shape
        .iter()
        .enumerate()
        .find(|(_, v)| !v.is_finite())
    {
        return Err(RayleighError::NonFinite {
            index: i + 1,
            value,
        });
    }
    let modes = &modal.normal_modes;
    if !modes.m_orthogonal() {
        return Err(RayleighError::NonSymmetricStiffness {
            asymmetry: modes.stiffness_asymmetry,
        });
    }
    if let Some((k, _)) = modes
        .kinds
        .iter()
        .enumerate()
        .find(|(_, kind)| matches!(kind, ModeKind::Unstable { .. }))
    {
        return Err(RayleighError::Unstable {
            mode: k + 1,
            eigenvalue: modes.eigenvalues[k],
        });
    }
    Ok(())
}

/// The trial shape scaled and with its zero-frequency modes projected out.
struct Projection {
    /// `max |vᵢ|`, the shape's scale (m or rad): the projected shape is `v / scale` with its
    /// zero-frequency modes removed.
    scale: f64,
    /// The projected shape, in units of `scale` (`n` entries).
    projected: DVector<f64>,
    /// How many zero-frequency modes were projected out.
    zero_modes: usize,
    /// `‖Σ_z ψ_z ψ_zᵀ M v‖_M / ‖v‖_M`.
    zero_mode_fraction: f64,
    /// The 0-based index of the lowest oscillatory mode.
    lowest: usize,
}

/// `v = shape / max |shapeᵢ|` (`n` entries) with its part along the zero-frequency modes
/// removed `M`-orthogonally (`M` `n × n`, `modes` mass-normalised), the fraction removed and
/// the lowest oscillatory mode. Scaling first keeps a shape of 1e300 or 1e-300 from
/// overflowing or underflowing the forms.
///
/// # Errors
/// [`RayleighError::ZeroShape`] (`vᵀMv` zero or NaN), [`RayleighError::NoOscillatoryMode`]
/// (of the `model`), [`RayleighError::OnlyZeroModes`] (nothing left after the projection).
fn project_shape(
    model: &dyn ModelInfo,
    shape: &[f64],
    m: &DMatrix<f64>,
    modes: &NormalModes,
) -> Result<Projection, RayleighError> {
    let n = model.num_dofs();
    let psi = &modes.mode_shapes;
    // The quotient does not depend on the shape's scale: it is taken of `v / max|vᵢ|`, so a
    // shape of 1e300 or 1e-300 neither overflows nor underflows the forms (the forms and the
    // projected shape are scaled back for the report).
    let scale = shape.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    if scale == 0.0 {
        return Err(RayleighError::ZeroShape);
    }
    let v = DVector::from_column_slice(shape) / scale;
    let full = mass_form(m, &v);
    if full.is_nan() || full <= 0.0 {
        return Err(RayleighError::ZeroShape);
    }
    // M-orthogonal projection out of the zero-frequency modes: with ΨᵀMΨ = I the component
    // along ψ_z is ψ_z (ψ_zᵀ M v).
    let mv = m * &v;
    let zero: Vec<usize> = (0..n)
        .filter(|&k| modes.kinds[k] == ModeKind::ZeroFrequency)
        .collect();
    let mut projected = v.clone();
    for &z in &zero {
        projected -= psi.column(z) * psi.column(z).dot(&mv);
    }
    let remaining = (mass_form(m, &projected).max(0.0) / full).sqrt();
    let Some(lowest) = (0..n).find(|&k| modes.kinds[k] == ModeKind::Oscillatory) else {
        return Err(RayleighError::NoOscillatoryMode {
            model: model.description().name.to_string(),
        });
    };
    // Below this the remainder is the rounding of the projection (a few ε of the shape).
    if remaining <= 1e-10 {
        return Err(RayleighError::OnlyZeroModes {
            count: zero.len(),
            remaining,
        });
    }
    let zero_mode_fraction = if zero.is_empty() {
        0.0
    } else {
        (mass_form(m, &(&v - &projected)).max(0.0) / full).sqrt()
    };
    Ok(Projection {
        scale,
        projected,
        zero_modes: zero.len(),
        zero_mode_fraction,
        lowest,
    })
}

/// The projected shape's error from the lowest mode: its remainder `v − P₁v` (`n` entries,
/// `P₁` the `M`-orthogonal projection onto the eigenspace of `ω₁`, the mode `lowest` and any
/// of the same frequency) and `tan θ = ‖v − P₁v‖_M / ‖P₁v‖_M` (`None` when `P₁v = 0`).
fn lowest_eigenspace_error(
    m: &DMatrix<f64>,
    modes: &NormalModes,
    lowest: usize,
    projected: &DVector<f64>,
) -> (DVector<f64>, Option<f64>) {
    let n = projected.len();
    let psi = &modes.mode_shapes;
    let w1 = modes.eigenvalues[lowest];
    // The shape's part in the eigenspace of ω₁ (`ψ₁ (ψ₁ᵀMv)` when ω₁ is simple): with a
    // repeated ω₁ (a ring's pair of modes) any vector of that space is a lowest mode, and the
    // error is measured from the space, not from the one `ψ₁` the solver returned.
    let mp = m * projected;
    let mut lowest_part = DVector::zeros(n);
    for k in 0..n {
        if modes.kinds[k] == ModeKind::Oscillatory
            && (modes.eigenvalues[k] - w1).abs() <= SAME_FREQUENCY * w1.abs()
        {
            lowest_part += psi.column(k) * psi.column(k).dot(&mp);
        }
    }
    let remainder = projected - &lowest_part;
    let remainder_norm = mass_form(m, &remainder).max(0.0).sqrt();
    let part_norm = mass_form(m, &lowest_part).max(0.0).sqrt();
    let shape_error = (part_norm > 0.0).then(|| remainder_norm / part_norm);
    (remainder, shape_error)
}

/// The stationarity test of [`rayleigh_study`]: `w` is the shape's remainder (its part
/// `M`-orthogonal to `ψ₁`) with the rest of `ω₁`'s eigenspace removed, or, if nothing is left
/// (`v` is a lowest mode), the next higher mode; `None` without one.
fn stationarity(
    (m, modes): (&DMatrix<f64>, &NormalModes),
    (lowest, remainder, shape_size): (usize, &DVector<f64>, f64),
    perturbations: &[f64],
    quotient: &dyn Fn(&DVector<f64>) -> f64,
) -> Option<Stationarity> {
    let n = m.nrows();
    let psi = &modes.mode_shapes;
    let w1 = modes.eigenvalues[lowest];
    let same: Vec<usize> = (0..n)
        .filter(|&k| {
            modes.kinds[k] == ModeKind::ZeroFrequency
                || (modes.eigenvalues[k] - w1).abs() <= SAME_FREQUENCY * w1.abs()
        })
        .collect();
    let mut w = remainder.clone();
    let mw = m * &w;
    for &k in &same {
        w -= psi.column(k) * psi.column(k).dot(&mw);
    }
    let mut norm = w.dot(&(m * &w)).max(0.0).sqrt();
    let mut direction = PerturbationDirection::ShapeError;
    // A remainder at the rounding of the shape (ε of its size) is no direction.
    if norm <= 1e-8 * shape_size * m.amax().sqrt() {
        let next = (0..n).find(|k| !same.contains(k))?;
        w = psi.column(next).into_owned();
        norm = 1.0;
        direction = PerturbationDirection::NextMode;
    }
    w /= norm;
    let psi1 = psi.column(lowest).into_owned();
    let direction_quotient = quotient(&w);
    let omega1 = w1.sqrt();
    let samples: Vec<PerturbedQuotient> = perturbations
        .iter()
        .copied()
        .filter(|e| e.is_finite() && *e > 0.0)
        .map(|epsilon| {
            let r = quotient(&(&psi1 + &w * epsilon));
            PerturbedQuotient {
                epsilon,
                rayleigh_quotient: r,
                excess: r - w1,
                predicted_excess: epsilon * epsilon * (direction_quotient - w1)
                    / (1.0 + epsilon * epsilon),
                relative_error: (r.max(0.0).sqrt() - omega1) / omega1,
            }
        })
        .collect();
    // The excess is resolved only well above the rounding of R (a few ε of the largest ω²
    // acting on the vectors).
    let largest = modes.eigenvalues.iter().fold(0.0f64, |a, w| a.max(w.abs()));
    let points: Vec<(f64, f64)> = samples
        .iter()
        .filter(|s| s.excess > 1e3 * f64::EPSILON * largest)
        .map(|s| (s.epsilon.ln(), s.excess.ln()))
        .collect();
    let count = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / count, b + y / count));
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    let fitted_order = (points.len() >= 2 && sxx > 0.0).then(|| sxy / sxx);
    Some(Stationarity {
        direction,
        direction_quotient,
        samples,
        fitted_order,
    })
}
