//! `eomgen modes` as one call: the equilibrium, the exact linearisation
//! `M δq̈ + C δq̇ + K δq = 0` there, the undamped normal modes and the damped eigenvalues
//! (issue 7; lectures 22–26, 30).

use std::collections::BTreeMap;

use nalgebra::{Complex, DMatrix};
use serde::Serialize;

use super::operating_point::{
    OperatingPoint, OperatingPointError, OperatingPointOptions, PointSummary, operating_point,
};
use crate::linear::eigenvalues::{LinearStability, damped_modes_of, linear_stability};
use crate::linear::modal::{
    Linearization, ModalError, ModeKind, NormalModes, TimeDependentForcing, eigenvalues_of_m_inv_k,
    linearize, normal_modes, time_dependence,
};
use crate::model_info::ModelInfo;

/// Options of [`modal_analysis`].
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct ModalOptions {
    /// The operating point (default: the file's first named equilibrium, else `q = 0`, at
    /// `t = 0`).
    pub operating_point: OperatingPointOptions,
}

/// One eigenvalue `s` of the state matrix `A = [0 I; −M⁻¹K −M⁻¹C]` with `Im s ≥ 0`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DampedEigenvalue {
    /// The eigenvalue `s` (1/s), serialised as `{"re", "im"}`.
    #[serde(serialize_with = "crate::serde_matrix::complex")]
    pub eigenvalue: Complex<f64>,
    /// `ζ = −Re s/|s|` (0 for `s = 0`).
    pub damping_ratio: f64,
    /// `ω_d = |Im s|` (rad/s; 0 for a real eigenvalue).
    pub damped_frequency: f64,
}

/// The modal analysis of a model at an operating point: what `eomgen modes` prints.
///
/// `n` is the number of coordinates, `r` the number of minimal coordinates (`r = n` without
/// constraints; see [`Linearization`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModalAnalysis {
    /// The equilibrium.
    pub operating_point: OperatingPoint,
    /// `M`, `C`, `K` (`r × r`) at the equilibrium, with the constraint basis `N` (`n × r`).
    pub linearization: Linearization,
    /// The undamped modes: `natural_frequencies` (rad/s, ascending), kinds, mode shapes in
    /// the minimal coordinates (mass-normalised, `ΨᵀMΨ = I`).
    pub normal_modes: NormalModes,
    /// The mass-normalised `mode_shapes` in the model's coordinates, `δq = N ψ`:
    /// `mode_shapes[k]` (length `n`) is mode `k`'s.
    pub mode_shapes: Vec<Vec<f64>>,
    /// The names of the `r` minimal coordinates (all `n` coordinates without constraints).
    pub minimal_coordinates: Vec<String>,
    /// The eigenvalues `s` of `A` with `Im s ≥ 0`, sorted by `|s|` (a complex pair once, each
    /// real eigenvalue once).
    pub damped_modes: Vec<DampedEigenvalue>,
    /// `damping_ratios`: `ζ` of each entry of `damped_modes`; `r` zeros when `C = 0`.
    pub damping_ratios: Vec<f64>,
    /// The eigenvalues `ω²` of the non-symmetric `M⁻¹K` (1/s², lecture 22's route), ascending.
    pub m_inv_k_eigenvalues: Vec<f64>,
    /// The largest difference between them and `normal_modes.eigenvalues` (lecture 24's
    /// symmetric route), relative to the largest `|ω²|`.
    pub m_inv_k_relative_difference: f64,
    /// A load that depends on `t` and enters neither `M`, `C` nor `K` (`F₀ cos ωt` on a
    /// linear oscillator): the operating point is the equilibrium under the load's value at
    /// the operating point's `t` (deflected by it where that value is not 0: a pendulum under
    /// `A cos wt` at `t = 0` leans by `≈ A/(m g l)`), and its variation is set aside; the
    /// modes are those of the equations linearised there. `None` when the equations at the
    /// operating point do not depend on `t`.
    pub time_dependent_forcing: Option<TimeDependentForcing>,
    /// The stability of the operating point from the eigenvalues of the whole state matrix
    /// (damping and gyroscopic terms included; issue 30), with `C` split into its damping and
    /// gyroscopic parts and the gyroscopic frequencies. The `kinds` of
    /// [`Self::normal_modes`] come from `K` alone (undamped, non-gyroscopic): a spinning
    /// system whose `K` has negative eigenvalues can be stable.
    pub stability: LinearStability,
}

impl ModalAnalysis {
    /// `true` when the damping matrix is zero (the text leaves `C` out then).
    pub fn is_undamped(&self) -> bool {
        self.linearization.damping_matrix.amax() == 0.0
    }

    /// The mode shapes in the model's coordinates as one `n × r` matrix `N Ψ`, column `k`
    /// mode `k`'s.
    pub fn mode_shape_matrix(&self) -> DMatrix<f64> {
        self.linearization
            .to_coordinates(&self.normal_modes.mode_shapes)
    }

    /// The analysis as `eomgen modes --json` prints it ([`ModesSummary`]); `model` is the
    /// model analysed (for its name and its constraints' names).
    pub fn summary(&self, model: &dyn ModelInfo) -> ModesSummary {
        let (lin, modes) = (&self.linearization, &self.normal_modes);
        ModesSummary {
            model: model.description().name.to_string(),
            coordinates: self.operating_point.coordinates.clone(),
            operating_point: self.operating_point.summary(),
            natural_frequencies: modes.natural_frequencies.clone(),
            frequencies_hz: modes
                .natural_frequencies
                .iter()
                .map(|w| w / std::f64::consts::TAU)
                .collect(),
            eigenvalues: modes.eigenvalues.clone(),
            kinds: modes.kinds.clone(),
            damping_ratios: self.damping_ratios.clone(),
            damped_modes: self.damped_modes.iter().map(Into::into).collect(),
            mode_shapes: self.mode_shapes.clone(),
            minimal_coordinates: self.minimal_coordinates.clone(),
            lagrange_multipliers: model
                .description()
                .constraint_names()
                .iter()
                .zip(&lin.lagrange_multipliers)
                .map(|(c, &v)| (c.to_string(), v))
                .collect(),
            mass_matrix: lin.mass_matrix.clone(),
            stiffness_matrix: lin.stiffness_matrix.clone(),
            damping_matrix: lin.damping_matrix.clone(),
            differenced_jacobian_entries: lin.differenced_entries,
            stiffness_asymmetry: modes.stiffness_asymmetry,
            m_inv_k_eigenvalues: self.m_inv_k_eigenvalues.clone(),
            m_inv_k_relative_difference: self.m_inv_k_relative_difference,
            time_dependent_forcing: self.time_dependent_forcing.clone(),
            stability: self.stability.clone(),
        }
    }
}

/// A [`ModalAnalysis`] as `eomgen modes --json` prints it ([`ModalAnalysis::summary`]): the
/// names, the operating point with Newton's figures, the modes with their frequencies in Hz,
/// the matrices as lists of rows and the checks.
///
/// # Shapes
/// `n` coordinates, `r` minimal coordinates, `m` constraints: `coordinates` `n`,
/// `natural_frequencies`, `frequencies_hz`, `eigenvalues` and `kinds` `r`, `mode_shapes`
/// `r` rows of `n`, the matrices `r × r`, `lagrange_multipliers` `m` entries.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModesSummary {
    /// The model's name.
    pub model: String,
    /// The model's coordinates' names.
    pub coordinates: Vec<String>,
    /// The equilibrium, with Newton's iterations and residual.
    pub operating_point: PointSummary,
    /// `ωₖ` (rad/s), ascending.
    pub natural_frequencies: Vec<f64>,
    /// `ωₖ / 2π` (Hz).
    pub frequencies_hz: Vec<f64>,
    /// `ωₖ²` (1/s²; negative for an unstable mode).
    pub eigenvalues: Vec<f64>,
    /// What each mode is (serialised as `{"kind", …}`).
    pub kinds: Vec<ModeKind>,
    /// `ζ` of each damped mode ([`ModalAnalysis::damping_ratios`]).
    pub damping_ratios: Vec<f64>,
    /// The eigenvalues of the state matrix with `Im s ≥ 0`, each flat.
    pub damped_modes: Vec<DampedEigenvalueSummary>,
    /// The mass-normalised mode shapes in the model's coordinates ([`ModalAnalysis::mode_shapes`]).
    pub mode_shapes: Vec<Vec<f64>>,
    /// The minimal coordinates' names.
    pub minimal_coordinates: Vec<String>,
    /// `λ*` by constraint name (the constraint forces at rest; empty without constraints).
    pub lagrange_multipliers: BTreeMap<String, f64>,
    /// `M` (`r × r`), as rows.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub mass_matrix: DMatrix<f64>,
    /// `K` (`r × r`), as rows.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub stiffness_matrix: DMatrix<f64>,
    /// `C` (`r × r`), as rows.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub damping_matrix: DMatrix<f64>,
    /// Jacobian entries taken by finite differences ([`Linearization::differenced_entries`]).
    pub differenced_jacobian_entries: usize,
    /// [`NormalModes::stiffness_asymmetry`].
    pub stiffness_asymmetry: f64,
    /// [`ModalAnalysis::m_inv_k_eigenvalues`] (1/s²).
    pub m_inv_k_eigenvalues: Vec<f64>,
    /// [`ModalAnalysis::m_inv_k_relative_difference`].
    pub m_inv_k_relative_difference: f64,
    /// [`ModalAnalysis::time_dependent_forcing`] (null when none).
    pub time_dependent_forcing: Option<TimeDependentForcing>,
    /// [`ModalAnalysis::stability`]: the verdict from the whole linearisation, its
    /// eigenvalues, the symmetric and skew parts of `C`, the gyroscopic frequencies.
    pub stability: LinearStability,
}

/// A damped eigenvalue flat, as reports print it: `{"re", "im", "damping_ratio",
/// "damped_frequency"}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DampedEigenvalueSummary {
    /// `Re s` (1/s).
    pub re: f64,
    /// `Im s` (rad/s).
    pub im: f64,
    /// `ζ = −Re s/|s|`.
    pub damping_ratio: f64,
    /// `ω_d` (rad/s).
    pub damped_frequency: f64,
}

impl From<&DampedEigenvalue> for DampedEigenvalueSummary {
    fn from(d: &DampedEigenvalue) -> Self {
        Self {
            re: d.eigenvalue.re,
            im: d.eigenvalue.im,
            damping_ratio: d.damping_ratio,
            damped_frequency: d.damped_frequency,
        }
    }
}

impl From<&crate::linear::response::DampedMode> for DampedEigenvalueSummary {
    fn from(d: &crate::linear::response::DampedMode) -> Self {
        Self {
            re: d.eigenvalue.re,
            im: d.eigenvalue.im,
            damping_ratio: d.damping_ratio,
            damped_frequency: d.damped_frequency,
        }
    }
}

/// Finds the operating point, linearises there exactly (`q̇ = 0`) and computes the normal
/// modes, the damped eigenvalues and lecture 22's `M⁻¹K` check: `eomgen modes` and the start
/// of the modal studies.
///
/// Explicit time dependence is checked at the equilibrium ([`time_dependence`]): a load that
/// changes with `t` but enters neither `M`, `C` nor `K` is set aside (reported in
/// [`ModalAnalysis::time_dependent_forcing`]): the operating point is the equilibrium under
/// the load's value at the operating point's `t` (deflected by it where that value is not
/// 0), and the modes are those of the equations linearised there, the load's variation left
/// out. Coefficients or constraints that change with `t` are refused, since modes of
/// equations frozen at one instant describe no motion; where the equilibrium search fails,
/// they are looked for at the guess, so that the error names them, and so is a load that
/// changes with `t` ([`ModalError::TimeDependentLoad`]: the equilibrium failed under the
/// load's value at one instant).
///
/// # Errors
/// [`OperatingPointError::UnknownEquilibrium`]; [`OperatingPointError::Modal`] when the
/// equilibrium search, the linearisation (constraints violated, singular or non-finite
/// matrices, [`ModalError::DegenerateCoordinates`])
/// or the eigenproblems fail, or with
/// [`ModalError::TimeDependent`] for time-dependent
/// coefficients or constraints, and [`ModalError::TimeDependentLoad`] for a load that changes
/// with `t` when no equilibrium is found under its value at `t₀`.
///
/// # Examples
/// Three equal masses between four equal springs (`three_masses`, HW28): `ω² = (2 − √2) k/m`,
/// `2k/m`, `(2 + √2) k/m`.
/// ```
/// use eomgen_runtime::analysis::vibration::{ModalOptions, modal_analysis};
/// let model = (eomgen::models::find("three_masses").unwrap().make)();
/// let modal = modal_analysis(model.as_ref(), &ModalOptions::default())?;
/// let (k, m) = (1.0, 1.0);
/// let expected = [(2.0 - 2f64.sqrt()) * k / m, 2.0 * k / m, (2.0 + 2f64.sqrt()) * k / m];
/// for (w, w2) in modal.normal_modes.natural_frequencies.iter().zip(expected) {
///     assert!((w - w2.sqrt()).abs() < 1e-12);
/// }
/// assert!(modal.is_undamped());
/// # Ok::<(), eomgen_runtime::analysis::vibration::OperatingPointError>(())
/// ```
///
/// # References
/// Lectures 22 (`M⁻¹K`), 24 (mass-normalised modes by the symmetric route), 25
/// (linearisation about an equilibrium), 30 (damping ratios from the eigenvalues of `A`).
pub fn modal_analysis(
    model: &dyn ModelInfo,
    options: &ModalOptions,
) -> Result<ModalAnalysis, OperatingPointError> {
    let point = match operating_point(model, &options.operating_point) {
        Ok(point) => point,
        Err(OperatingPointError::Modal(
            error @ (ModalError::EquilibriumNotFound { .. }
            | ModalError::EquilibriumAtInfinity { .. }
            | ModalError::NonFinite { .. }),
        )) => {
            // Coefficients that change with t are the reason to give, not Newton's failure
            // on the equations frozen at t₀: checked at the guess.
            // A load that changes with t is the reason too: the equilibrium failed under its
            // value at t₀, one instant of it. Equations not finite at the guess at t₀ alone
            // (`ln(w t)` at 0) are the instant's, not the configuration's.
            let (_, guess) = options.operating_point.start.resolve(model)?;
            if let Some(forcing) = time_dependence(model, &guess, options.operating_point.t)? {
                return Err(ModalError::TimeDependentLoad {
                    forcing,
                    equilibrium: Box::new(error),
                }
                .into());
            }
            return Err(error.into());
        }
        Err(error) => return Err(error),
    };
    let time_dependent_forcing = time_dependence(model, point.q(), point.t)?;
    let n = model.num_dofs();
    let linearization = linearize(model, point.q(), &vec![0.0; n], point.t)?;
    let stability = linear_stability(&linearization)?;
    let modes = normal_modes(&linearization)?;
    let m_inv_k_eigenvalues = eigenvalues_of_m_inv_k(&linearization)?;
    // The eigenvalues the verdict came from, not computed a second time.
    let damped_modes: Vec<DampedEigenvalue> = damped_modes_of(&stability.eigenvalues)
        .into_iter()
        .map(|(s, zeta, wd)| DampedEigenvalue {
            eigenvalue: s,
            damping_ratio: zeta,
            damped_frequency: wd,
        })
        .collect();
    let r = linearization.num_minimal_coordinates();
    let damping_ratios = if linearization.damping_matrix.amax() == 0.0 {
        vec![0.0; r]
    } else {
        damped_modes.iter().map(|d| d.damping_ratio).collect()
    };
    let scale = modes.eigenvalues.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let m_inv_k_relative_difference = modes
        .eigenvalues
        .iter()
        .zip(&m_inv_k_eigenvalues)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f64, f64::max)
        / scale.max(f64::MIN_POSITIVE);
    let shapes = linearization.to_coordinates(&modes.mode_shapes);
    // Column by column, as `mode_shape_matrix` gives them.
    let mode_shapes = (0..r)
        .map(|k| shapes.column(k).iter().copied().collect())
        .collect();
    let names = model.description().coordinate_names();
    let minimal_coordinates = linearization
        .independent_coordinates
        .iter()
        .map(|&i| names[i].to_string())
        .collect();
    Ok(ModalAnalysis {
        operating_point: point,
        linearization,
        normal_modes: modes,
        mode_shapes,
        minimal_coordinates,
        damped_modes,
        damping_ratios,
        m_inv_k_eigenvalues,
        m_inv_k_relative_difference,
        time_dependent_forcing,
        stability,
    })
}
