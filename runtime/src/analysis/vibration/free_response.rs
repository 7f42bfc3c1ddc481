//! `eomgen study free-response` as one call (HW28, lectures 22–26): the free response of the
//! linearised, undamped equations `M δq̈ + K δq = 0` at an equilibrium computed four
//! independent ways, and their largest differences.
//!
//! Also what the modal studies share: the unconstrained operating point, the default
//! duration from the modes, the time grid and their errors.

use serde::Serialize;

use super::modes::{ModalAnalysis, ModalOptions, modal_analysis};
use super::operating_point::{
    OperatingPoint, OperatingPointError, OperatingPointOptions, PointSummary,
};
use crate::analysis::outcome::{RunTally, StudyRuns};
use crate::linear::modal::{Linearization, ModeKind, NormalModes};
use crate::linear::response::{
    FreeResponse, ResponseError, response_by_exponential, response_by_integration,
    response_by_m_inv_k_modes, response_by_normal_modes,
};
use crate::model_info::ModelInfo;

/// Why a free-response or modal-damping study failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ResponseStudyError {
    /// No operating point, or its linearisation or modes failed.
    #[error(transparent)]
    OperatingPoint(#[from] OperatingPointError),
    /// The model has holonomic constraints: its linearisation is in minimal coordinates
    /// (`δq = N z`), and these studies work in the model's own coordinates.
    #[error("`{model}` has constraints; this study takes unconstrained models")]
    Constrained {
        /// The model.
        model: String,
    },
    /// The integration tolerance is not positive and finite.
    #[error("the tolerance must be positive, got {tol}")]
    InvalidTolerance {
        /// Given.
        tol: f64,
    },
    /// The end time is not positive and finite.
    #[error("the end time must be positive and finite, got {t_end}")]
    InvalidEndTime {
        /// Given (s).
        t_end: f64,
    },
    /// Fewer than two output times.
    #[error("at least 2 samples are needed, got {samples}")]
    TooFewSamples {
        /// Given.
        samples: usize,
    },
    /// A Rayleigh mode index outside `1..=n`.
    #[error("mode {mode} does not exist; `{model}` has modes 1 to {count}")]
    NoSuchMode {
        /// The model.
        model: String,
        /// The 1-based mode asked for.
        mode: usize,
        /// The number of modes.
        count: usize,
    },
    /// A Rayleigh mode without an exact complex eigenvalue to fit.
    #[error("mode {mode} is not an underdamped oscillation (no complex eigenvalue to fit)")]
    NotUnderdamped {
        /// The 1-based mode.
        mode: usize,
    },
    /// The Rayleigh fit to two modes failed (equal frequencies, …).
    #[error("{source}")]
    RayleighFit {
        /// The two 1-based modes.
        modes: [usize; 2],
        /// Why.
        source: ResponseError,
    },
    /// A response computation failed.
    #[error(transparent)]
    Response(#[from] ResponseError),
}

/// Initial deviations from the operating point, `(δq₀, δq̇₀)`, each of length `n`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InitialDeviation {
    /// `δq₀` (m or rad).
    pub q: Vec<f64>,
    /// `δq̇₀` (m/s or rad/s).
    pub qdot: Vec<f64>,
}

/// The modal analysis of a model's own coordinates: [`modal_analysis`], refusing a
/// constrained model.
///
/// # Errors
/// [`ResponseStudyError::OperatingPoint`]; [`ResponseStudyError::Constrained`].
pub fn unconstrained_modal_analysis(
    model: &dyn ModelInfo,
    operating_point: &OperatingPointOptions,
) -> Result<ModalAnalysis, ResponseStudyError> {
    let options = ModalOptions {
        operating_point: operating_point.clone(),
    };
    let modal = modal_analysis(model, &options)?;
    if modal.linearization.num_minimal_coordinates() != model.num_dofs() {
        return Err(ResponseStudyError::Constrained {
            model: model.description().name.to_string(),
        });
    }
    Ok(modal)
}

/// `periods` periods of the slowest oscillatory mode, or the time the fastest unstable mode
/// grows by `e^growth` if that is shorter; 10 s if neither exists (s).
pub fn default_duration(modes: &NormalModes, periods: f64, growth: f64) -> f64 {
    let mut slowest = 0.0f64;
    let mut growth_time = f64::INFINITY;
    for (k, kind) in modes.kinds.iter().enumerate() {
        match kind {
            ModeKind::Oscillatory => {
                slowest =
                    slowest.max(periods * std::f64::consts::TAU / modes.natural_frequencies[k]);
            }
            ModeKind::Unstable { growth_rate } => {
                growth_time = growth_time.min(growth / growth_rate)
            }
            ModeKind::ZeroFrequency => {}
        }
    }
    let t = if slowest > 0.0 {
        slowest.min(growth_time)
    } else {
        growth_time
    };
    if t.is_finite() && t > 0.0 { t } else { 10.0 }
}

/// `samples` evenly spaced times on `[0, t_end]` (s).
///
/// # Errors
/// [`ResponseStudyError::InvalidEndTime`], [`ResponseStudyError::TooFewSamples`].
pub fn uniform_times(t_end: f64, samples: usize) -> Result<Vec<f64>, ResponseStudyError> {
    if !(t_end.is_finite() && t_end > 0.0) {
        return Err(ResponseStudyError::InvalidEndTime { t_end });
    }
    if samples < 2 {
        return Err(ResponseStudyError::TooFewSamples { samples });
    }
    Ok((0..samples)
        .map(|i| t_end * i as f64 / (samples - 1) as f64)
        .collect())
}

/// `tol` if it is positive and finite.
pub(crate) fn check_tolerance(tol: f64) -> Result<(), ResponseStudyError> {
    if tol.is_finite() && tol > 0.0 {
        Ok(())
    } else {
        Err(ResponseStudyError::InvalidTolerance { tol })
    }
}

/// The four ways of [`free_response`], in the order they are reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FreeResponseMethod {
    /// DOP853 on `δẏ = A δy` ([`response_by_integration`]).
    Integration,
    /// `e^{At} δy₀` ([`response_by_exponential`]).
    Exponential,
    /// Superposed modes of `M⁻¹K` ([`response_by_m_inv_k_modes`]).
    MInvKModes,
    /// Superposed mass-normalised modes ([`response_by_normal_modes`]).
    NormalModes,
}

impl FreeResponseMethod {
    /// Every method, in the order reported.
    pub const ALL: [Self; 4] = [
        Self::Integration,
        Self::Exponential,
        Self::MInvKModes,
        Self::NormalModes,
    ];

    /// Its name in reports (`integration`, `exponential`, `m_inv_k_modes`, `normal_modes`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Integration => "integration",
            Self::Exponential => "exponential",
            Self::MInvKModes => "m_inv_k_modes",
            Self::NormalModes => "normal_modes",
        }
    }

    /// One line on what it computes.
    pub fn description(self) -> &'static str {
        match self {
            Self::Integration => "DOP853 on δẏ = A δy (numerical, to the tolerance)",
            Self::Exponential => "e^{At} δy₀, Padé 13 (exact to rounding)",
            Self::MInvKModes => "superposed modes of M⁻¹K, P a = δq₀ solved (lecture 22)",
            Self::NormalModes => "superposed mass-normalised modes, η₀ = ΨᵀM δq₀ (lecture 24)",
        }
    }
}

/// Options of [`free_response`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FreeResponseOptions {
    /// The operating point (default: the file's first named equilibrium, else `q = 0`).
    pub operating_point: OperatingPointOptions,
    /// The initial deviation (default: `δq₀ = 0.1` (m or rad) in every coordinate, at rest).
    pub initial: Option<InitialDeviation>,
    /// End time (s) (default: four periods of the slowest oscillatory mode, or the time an
    /// unstable mode grows by `e⁵` if that is shorter, else 10 s).
    pub t_end: Option<f64>,
    /// Number of output times, evenly spaced on `[0, t_end]` (default: 401; at least 2).
    pub samples: usize,
    /// Relative and absolute tolerance of DOP853 (default: 1e-13; positive).
    pub tol: f64,
}

impl FreeResponseOptions {
    /// The default number of output times.
    pub const DEFAULT_SAMPLES: usize = 401;
    /// The default relative and absolute tolerance of the DOP853 integration.
    pub const DEFAULT_TOL: f64 = 1e-13;
}

impl Default for FreeResponseOptions {
    fn default() -> Self {
        Self {
            operating_point: OperatingPointOptions::default(),
            initial: None,
            t_end: None,
            samples: Self::DEFAULT_SAMPLES,
            tol: Self::DEFAULT_TOL,
        }
    }
}

/// The largest differences between two of the responses.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ResponseDifference {
    /// The first method.
    pub a: FreeResponseMethod,
    /// The second method.
    pub b: FreeResponseMethod,
    /// `max |δq_a − δq_b|` over all samples and coordinates (m or rad; ∞ if the grids differ).
    pub displacement: f64,
    /// `max |δq̇_a − δq̇_b|` (m/s or rad/s).
    pub velocity: f64,
    /// `displacement` over the exponential response's largest `|δq|` (absolute if that is 0).
    pub displacement_relative: f64,
    /// `velocity` over the exponential response's largest `|δq̇|` (absolute if that is 0).
    pub velocity_relative: f64,
}

/// What [`free_response`] computed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FreeResponseStudy {
    /// The equilibrium.
    pub operating_point: OperatingPoint,
    /// `M`, `C`, `K` there (`n × n`; `C` as derived, left out of the responses).
    pub linearization: Linearization,
    /// The undamped normal modes.
    pub normal_modes: NormalModes,
    /// `max |C|`, the damping left out (0 for an undamped model).
    pub ignored_damping: f64,
    /// The initial deviation.
    pub initial: InitialDeviation,
    /// The end time (s).
    pub t_end: f64,
    /// The DOP853 tolerance.
    pub tol: f64,
    /// The four responses, in the order of [`FreeResponseMethod::ALL`].
    pub responses: Vec<(FreeResponseMethod, FreeResponse)>,
    /// The exponential response's largest `|δq|` (m or rad).
    pub max_displacement: f64,
    /// Its largest `|δq̇|` (m/s or rad/s).
    pub max_velocity: f64,
    /// Every pair of methods, in the order `(1, 2), (1, 3), …, (3, 4)`.
    pub differences: Vec<ResponseDifference>,
}

/// Each of the four responses is a run; a failed one fails the study as a whole
/// ([`ResponseStudyError::Response`]).
impl FreeResponseStudy {
    /// The study as `eomgen study free-response --json` prints it ([`FreeResponseSummary`]);
    /// `model` is the model studied (for its name).
    pub fn summary(&self, model: &dyn ModelInfo) -> FreeResponseSummary {
        let modes = &self.normal_modes;
        FreeResponseSummary {
            model: model.description().name.to_string(),
            coordinates: self.operating_point.coordinates.clone(),
            operating_point: self.operating_point.summary_at(&self.linearization.q),
            ignored_damping: self.ignored_damping,
            modes: modes
                .kinds
                .iter()
                .zip(&modes.eigenvalues)
                .zip(&modes.natural_frequencies)
                .map(|((kind, &eigenvalue), &natural_frequency)| ModeSummary {
                    kind: kind.name(),
                    eigenvalue,
                    natural_frequency,
                    growth_rate: kind.growth_rate(),
                })
                .collect(),
            initial: self.initial.clone(),
            t_end: self.t_end,
            samples: self.responses.first().map_or(0, |(_, r)| r.times.len()),
            tol: self.tol,
            methods: FreeResponseMethod::ALL
                .iter()
                .map(|m| MethodSummary {
                    name: m.name(),
                    description: m.description(),
                })
                .collect(),
            max_displacement: self.max_displacement,
            max_velocity: self.max_velocity,
            max_differences: self.differences.clone(),
            final_states: self
                .responses
                .iter()
                .map(|(method, r)| FinalState {
                    method: method.name(),
                    q: r.displacements.last().cloned(),
                    qdot: r.velocities.last().cloned(),
                })
                .collect(),
        }
    }
}

/// A [`FreeResponseStudy`] as `eomgen study free-response --json` prints it
/// ([`FreeResponseStudy::summary`]): the set-up, the modes, the methods, their largest
/// differences and each method's final state (the responses themselves left out).
///
/// # Shapes
/// `n` coordinates: `coordinates`, `modes`, the `initial` and `final` states `n` each.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FreeResponseSummary {
    /// The model's name.
    pub model: String,
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// The operating point at the linearisation's `q`.
    pub operating_point: PointSummary,
    /// [`FreeResponseStudy::ignored_damping`].
    pub ignored_damping: f64,
    /// The undamped modes.
    pub modes: Vec<ModeSummary>,
    /// The initial deviation `{"q", "qdot"}` from the equilibrium.
    pub initial: InitialDeviation,
    /// The end time (s).
    pub t_end: f64,
    /// The number of sample times.
    pub samples: usize,
    /// The integration's tolerance.
    pub tol: f64,
    /// The four methods, in the order reported.
    pub methods: Vec<MethodSummary>,
    /// [`FreeResponseStudy::max_displacement`] (m or rad).
    pub max_displacement: f64,
    /// [`FreeResponseStudy::max_velocity`] (m/s or rad/s).
    pub max_velocity: f64,
    /// The largest differences between the methods.
    pub max_differences: Vec<ResponseDifference>,
    /// Each method's state at `t_end`.
    #[serde(rename = "final")]
    pub final_states: Vec<FinalState>,
}

/// One mode in a study's summary: `{"kind", "eigenvalue", "natural_frequency",
/// "growth_rate"}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModeSummary {
    /// [`ModeKind::name`].
    pub kind: &'static str,
    /// `ω²` (1/s²).
    pub eigenvalue: f64,
    /// `ω` (rad/s).
    pub natural_frequency: f64,
    /// `σ` (1/s) of an unstable mode, null for the others.
    pub growth_rate: Option<f64>,
}

/// A method of [`free_response`] by name, with what it computes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MethodSummary {
    /// [`FreeResponseMethod::name`].
    pub name: &'static str,
    /// [`FreeResponseMethod::description`].
    pub description: &'static str,
}

/// A method's last sample in a [`FreeResponseSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FinalState {
    /// [`FreeResponseMethod::name`].
    pub method: &'static str,
    /// `δq` at the last sample (m or rad; null without samples).
    pub q: Option<Vec<f64>>,
    /// `δq̇` at the last sample (m/s or rad/s; null without samples).
    pub qdot: Option<Vec<f64>>,
}

impl StudyRuns for FreeResponseStudy {
    fn study(&self) -> &'static str {
        "free-response"
    }

    fn tally(&self) -> RunTally {
        RunTally {
            measured: self.responses.len(),
            ..RunTally::default()
        }
    }
}

/// The free response of the undamped linearisation `M δq̈ + K δq = 0` at an operating point,
/// computed four ways ([`FreeResponseMethod`]), and the largest differences between them: the
/// modal routes are exact closed forms, so the differences measure rounding and the
/// integration's error (HW28).
///
/// # Errors
/// [`ResponseStudyError::OperatingPoint`], [`ResponseStudyError::Constrained`],
/// [`ResponseStudyError::InvalidTolerance`], [`ResponseStudyError::InvalidEndTime`],
/// [`ResponseStudyError::TooFewSamples`], [`ResponseStudyError::Response`] (an initial vector
/// of the wrong length, a failed integration).
///
/// # Examples
/// ```
/// use eomgen_runtime::analysis::vibration::{FreeResponseOptions, free_response};
/// let model = (eomgen::models::find("three_masses").unwrap().make)();
/// let study = free_response(model.as_ref(), &FreeResponseOptions::default())?;
/// // Exact closed forms agree with e^{At} to rounding, DOP853 to its tolerance.
/// for d in &study.differences {
///     assert!(d.displacement_relative < 1e-9, "{d:?}");
/// }
/// # Ok::<(), eomgen_runtime::analysis::vibration::ResponseStudyError>(())
/// ```
///
/// # References
/// HW28; lectures 22 (modes of `M⁻¹K`), 24 (mass-normalised modes), 32 (`e^{At}`).
pub fn free_response(
    model: &dyn ModelInfo,
    options: &FreeResponseOptions,
) -> Result<FreeResponseStudy, ResponseStudyError> {
    let modal = unconstrained_modal_analysis(model, &options.operating_point)?;
    let n = model.num_dofs();
    let mut undamped = modal.linearization.clone();
    let ignored_damping = undamped.damping_matrix.amax();
    undamped.damping_matrix.fill(0.0);
    let initial = options.initial.clone().unwrap_or(InitialDeviation {
        q: vec![0.1; n],
        qdot: vec![0.0; n],
    });
    check_tolerance(options.tol)?;
    let t_end = options
        .t_end
        .unwrap_or_else(|| default_duration(&modal.normal_modes, 4.0, 5.0));
    let times = uniform_times(t_end, options.samples)?;
    let (q0, v0) = (&initial.q, &initial.qdot);
    let responses = vec![
        (
            FreeResponseMethod::Integration,
            response_by_integration(&undamped, q0, v0, &times, options.tol)?,
        ),
        (
            FreeResponseMethod::Exponential,
            response_by_exponential(&undamped, q0, v0, &times)?,
        ),
        (
            FreeResponseMethod::MInvKModes,
            response_by_m_inv_k_modes(&undamped, q0, v0, &times)?,
        ),
        (
            FreeResponseMethod::NormalModes,
            response_by_normal_modes(&undamped, q0, v0, &times)?,
        ),
    ];
    let max_displacement = responses[1].1.max_displacement();
    let max_velocity = responses[1].1.max_velocity();
    let relative = |d: f64, s: f64| if s > 0.0 { d / s } else { d };
    let mut differences = Vec::new();
    for i in 0..4 {
        for j in i + 1..4 {
            let (a, b) = (&responses[i], &responses[j]);
            let displacement =
                a.1.max_displacement_difference(&b.1)
                    .unwrap_or(f64::INFINITY);
            let velocity = a.1.max_velocity_difference(&b.1).unwrap_or(f64::INFINITY);
            differences.push(ResponseDifference {
                a: a.0,
                b: b.0,
                displacement,
                velocity,
                displacement_relative: relative(displacement, max_displacement),
                velocity_relative: relative(velocity, max_velocity),
            });
        }
    }
    Ok(FreeResponseStudy {
        operating_point: modal.operating_point,
        linearization: modal.linearization,
        normal_modes: modal.normal_modes,
        ignored_damping,
        initial,
        t_end,
        tol: options.tol,
        responses,
        max_displacement,
        max_velocity,
        differences,
    })
}
