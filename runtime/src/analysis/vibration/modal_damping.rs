//! `eomgen study modal-damping` as one call (HW34, lectures 30–33): damping ratios and damped
//! frequencies of each mode three ways — exact (complex eigenvalues of `A`), the
//! modal-damping approximation (diagonal of `Ĉ = ΨᵀCΨ`) and Rayleigh damping `C = αM + βK`
//! fitted to two modes — and the free responses from each mode shape: exact (`e^{At}`, checked
//! by DOP853) against the two approximations.

use nalgebra::DMatrix;
use serde::Serialize;

use super::free_response::{
    InitialDeviation, ResponseStudyError, check_tolerance, default_duration,
    unconstrained_modal_analysis, uniform_times,
};
use super::modes::DampedEigenvalueSummary;
use super::operating_point::{OperatingPoint, OperatingPointOptions, PointSummary};
use crate::analysis::outcome::{RunTally, StudyRuns};
use crate::linear::modal::{Linearization, ModeKind, NormalModes};
use crate::linear::response::{
    DampedMode, FreeResponse, ModalDamping, RayleighDamping, exact_damped_modes, modal_damping,
    response_by_exponential, response_by_integration, response_with_modal_damping,
};
use crate::model_info::ModelInfo;

/// Options of [`modal_damping_study`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModalDampingOptions {
    /// The operating point (default: the file's first named equilibrium, else `q = 0`).
    pub operating_point: OperatingPointOptions,
    /// The two modes (1-based, ascending frequency) whose exact damping ratios the Rayleigh
    /// damping reproduces (default: the slowest and the fastest oscillatory modes, when both
    /// are underdamped; HW34).
    pub rayleigh_modes: Option<[usize; 2]>,
    /// One initial deviation instead of HW34's releases from each mode shape at rest
    /// (default: the releases).
    pub initial: Option<InitialDeviation>,
    /// End time (s) (default: ten periods of the slowest oscillatory mode, or the time an
    /// unstable mode grows by `e⁵` if that is shorter, else 10 s).
    pub t_end: Option<f64>,
    /// Number of output times, evenly spaced on `[0, t_end]` (default: 801; at least 2).
    pub samples: usize,
    /// Relative and absolute tolerance of the DOP853 check of the exact response (default:
    /// 1e-12; positive).
    pub tol: f64,
}

impl ModalDampingOptions {
    /// The default number of output times.
    pub const DEFAULT_SAMPLES: usize = 801;
    /// The default relative and absolute tolerance of the DOP853 check.
    pub const DEFAULT_TOL: f64 = 1e-12;
}

impl Default for ModalDampingOptions {
    fn default() -> Self {
        Self {
            operating_point: OperatingPointOptions::default(),
            rayleigh_modes: None,
            initial: None,
            t_end: None,
            samples: Self::DEFAULT_SAMPLES,
            tol: Self::DEFAULT_TOL,
        }
    }
}

/// The Rayleigh damping fitted to two modes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RayleighFit {
    /// The two 1-based modes whose exact `ζ` it reproduces.
    pub modes: [usize; 2],
    /// `α` (1/s) and `β` (s).
    #[serde(flatten)]
    pub damping: RayleighDamping,
}

/// A damping ratio and the damped frequency it gives.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModalRatio {
    /// `ζ`.
    pub damping_ratio: f64,
    /// `ω √(1 − ζ²)` (rad/s; `None` when `|ζ| ≥ 1`).
    pub damped_frequency: Option<f64>,
}

/// One mode's damping three ways.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModeDamping {
    /// The mode, 1-based.
    pub mode: usize,
    /// What it is.
    pub kind: ModeKind,
    /// Its undamped natural frequency (rad/s).
    pub natural_frequency: f64,
    /// The exact complex eigenvalue (`None` unless an underdamped oscillation).
    pub exact: Option<DampedMode>,
    /// The diagonal-`Ĉ` approximation (`None` unless oscillatory).
    pub diagonal: Option<ModalRatio>,
    /// The Rayleigh damping's (`None` without a fit or unless oscillatory).
    pub rayleigh: Option<ModalRatio>,
}

/// One release and its responses.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Release {
    /// What it is: `mode k shape, x1 = 1` or `given initial values`.
    pub name: String,
    /// `δq₀` (m or rad).
    pub q0: Vec<f64>,
    /// `δq̇₀` (m/s or rad/s).
    pub qdot0: Vec<f64>,
    /// The exact damped response `e^{At} δy₀`.
    pub exact: FreeResponse,
    /// DOP853 on `δẏ = A δy`.
    pub integrated: FreeResponse,
    /// The modal-damping approximation (diagonal of `Ĉ`).
    pub diagonal: FreeResponse,
    /// The Rayleigh damping's response (with a fit).
    pub rayleigh: Option<FreeResponse>,
    /// The exact response's largest `|δq|` (m or rad).
    pub amplitude: f64,
    /// `max |δq_DOP853 − δq_exact|` over `amplitude` (absolute when it is 0).
    pub integration_vs_exact: f64,
    /// The same for the diagonal approximation.
    pub diagonal_vs_exact: f64,
    /// The same for the Rayleigh damping.
    pub rayleigh_vs_exact: Option<f64>,
}

/// What [`modal_damping_study`] computed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModalDampingStudy {
    /// The equilibrium.
    pub operating_point: OperatingPoint,
    /// `M`, `C`, `K` there (`n × n`).
    pub linearization: Linearization,
    /// The undamped normal modes.
    pub normal_modes: NormalModes,
    /// `Ĉ = ΨᵀCΨ`, the diagonal approximation and the coupling of `Ĉ`.
    pub modal_damping: ModalDamping,
    /// The Rayleigh fit (`None` with fewer than two underdamped oscillatory modes).
    pub rayleigh: Option<RayleighFit>,
    /// Each mode's damping three ways.
    pub modes: Vec<ModeDamping>,
    /// The end time (s).
    pub t_end: f64,
    /// The DOP853 tolerance.
    pub tol: f64,
    /// The releases.
    pub releases: Vec<Release>,
}

/// Each release is a run; a failed response fails the study as a whole
/// ([`ResponseStudyError::Response`]).
impl ModalDampingStudy {
    /// The study as `eomgen study modal-damping --json` prints it ([`ModalDampingSummary`]);
    /// `model` is the model studied (for its name).
    pub fn summary(&self, model: &dyn ModelInfo) -> ModalDampingSummary {
        let (lin, approx) = (&self.linearization, &self.modal_damping);
        ModalDampingSummary {
            model: model.description().name.to_string(),
            coordinates: self.operating_point.coordinates.clone(),
            operating_point: self.operating_point.summary_at(&lin.q),
            mass_matrix: lin.mass_matrix.clone(),
            stiffness_matrix: lin.stiffness_matrix.clone(),
            damping_matrix: lin.damping_matrix.clone(),
            modal_damping_matrix: approx.modal_damping_matrix.clone(),
            coupling: approx.coupling,
            rayleigh: self.rayleigh,
            modes: self
                .modes
                .iter()
                .map(|m| ModeDampingSummary {
                    mode: m.mode,
                    kind: m.kind.name(),
                    natural_frequency: m.natural_frequency,
                    exact: m.exact.as_ref().map(Into::into),
                    diagonal: m.diagonal,
                    rayleigh: m.rayleigh,
                })
                .collect(),
            t_end: self.t_end,
            samples: self.releases.first().map_or(0, |c| c.exact.times.len()),
            tol: self.tol,
            cases: self
                .releases
                .iter()
                .map(|c| ReleaseSummary {
                    name: c.name.clone(),
                    q0: c.q0.clone(),
                    qdot0: c.qdot0.clone(),
                    amplitude: c.amplitude,
                    integration_vs_exact: c.integration_vs_exact,
                    diagonal_vs_exact: c.diagonal_vs_exact,
                    rayleigh_vs_exact: c.rayleigh_vs_exact,
                })
                .collect(),
        }
    }
}

/// A [`ModalDampingStudy`] as `eomgen study modal-damping --json` prints it
/// ([`ModalDampingStudy::summary`]): the matrices as lists of rows, each mode's damping three
/// ways and each release's differences (the responses themselves left out).
///
/// # Shapes
/// `n` coordinates: the matrices `n × n`, each case's `q0` and `qdot0` `n` entries.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModalDampingSummary {
    /// The model's name.
    pub model: String,
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// The operating point at the linearisation's `q`.
    pub operating_point: PointSummary,
    /// `M`, as rows.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub mass_matrix: DMatrix<f64>,
    /// `K`, as rows.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub stiffness_matrix: DMatrix<f64>,
    /// `C`, as rows.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub damping_matrix: DMatrix<f64>,
    /// `Ĉ = ΨᵀCΨ`, as rows.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub modal_damping_matrix: DMatrix<f64>,
    /// The off-diagonal share of `Ĉ` ([`ModalDamping::coupling`]).
    pub coupling: f64,
    /// The Rayleigh fit, null without one.
    pub rayleigh: Option<RayleighFit>,
    /// Each mode's damping.
    pub modes: Vec<ModeDampingSummary>,
    /// The end time (s).
    pub t_end: f64,
    /// The number of sample times.
    pub samples: usize,
    /// The integration's tolerance.
    pub tol: f64,
    /// The releases.
    pub cases: Vec<ReleaseSummary>,
}

/// One mode of a [`ModalDampingSummary`] ([`ModeDamping`] with its kind by name and the
/// exact eigenvalue flat).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModeDampingSummary {
    /// The mode's number (from 1).
    pub mode: usize,
    /// [`ModeKind::name`].
    pub kind: &'static str,
    /// `ω` (rad/s).
    pub natural_frequency: f64,
    /// The exact damped eigenvalue, null when none.
    pub exact: Option<DampedEigenvalueSummary>,
    /// The modal-damping approximation's ratio.
    pub diagonal: Option<ModalRatio>,
    /// The Rayleigh damping's ratio.
    pub rayleigh: Option<ModalRatio>,
}

/// One release of a [`ModalDampingSummary`]: [`Release`] without its responses.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReleaseSummary {
    /// [`Release::name`].
    pub name: String,
    /// `δq₀` (m or rad).
    pub q0: Vec<f64>,
    /// `δq̇₀` (m/s or rad/s).
    pub qdot0: Vec<f64>,
    /// [`Release::amplitude`] (m or rad).
    pub amplitude: f64,
    /// [`Release::integration_vs_exact`].
    pub integration_vs_exact: f64,
    /// [`Release::diagonal_vs_exact`].
    pub diagonal_vs_exact: f64,
    /// [`Release::rayleigh_vs_exact`].
    pub rayleigh_vs_exact: Option<f64>,
}

impl StudyRuns for ModalDampingStudy {
    fn study(&self) -> &'static str {
        "modal-damping"
    }

    fn tally(&self) -> RunTally {
        RunTally {
            measured: self.releases.len(),
            ..RunTally::default()
        }
    }
}

/// `ω √(1 − ζ²)` (`None` when `|ζ| ≥ 1`).
fn damped_frequency(omega: f64, zeta: f64) -> Option<f64> {
    (zeta.abs() < 1.0).then(|| omega * (1.0 - zeta * zeta).sqrt())
}

/// Damping ratios exact, by the diagonal of `Ĉ` and by a Rayleigh fit, and the free responses
/// from each mode shape (or one given deviation), exact against both approximations (HW34).
///
/// # Errors
/// [`ResponseStudyError::OperatingPoint`], [`ResponseStudyError::Constrained`],
/// [`ResponseStudyError::NoSuchMode`], [`ResponseStudyError::NotUnderdamped`] and
/// [`ResponseStudyError::RayleighFit`] for the Rayleigh modes,
/// [`ResponseStudyError::InvalidTolerance`], [`ResponseStudyError::InvalidEndTime`],
/// [`ResponseStudyError::TooFewSamples`], [`ResponseStudyError::Response`].
///
/// # Examples
/// ```
/// use eomgen_runtime::analysis::vibration::{ModalDampingOptions, modal_damping_study};
/// let model = (eomgen::models::find("three_masses_damped").unwrap().make)();
/// let study = modal_damping_study(model.as_ref(), &ModalDampingOptions::default())?;
/// // Rayleigh damping fitted to modes 1 and 3 reproduces their exact ζ.
/// let fit = study.rayleigh.unwrap();
/// assert_eq!(fit.modes, [1, 3]);
/// for k in [0, 2] {
///     let mode = &study.modes[k];
///     let exact = mode.exact.unwrap().damping_ratio;
///     assert!((mode.rayleigh.unwrap().damping_ratio - exact).abs() < 1e-14);
/// }
/// # Ok::<(), eomgen_runtime::analysis::vibration::ResponseStudyError>(())
/// ```
///
/// # References
/// HW34; lectures 30–33; D. J. Inman, *Engineering Vibration*, 4th ed., §4.5 (Rayleigh
/// damping).
pub fn modal_damping_study(
    model: &dyn ModelInfo,
    options: &ModalDampingOptions,
) -> Result<ModalDampingStudy, ResponseStudyError> {
    let modal = unconstrained_modal_analysis(model, &options.operating_point)?;
    let (lin, modes) = (&modal.linearization, &modal.normal_modes);
    modes.require_real().map_err(crate::ResponseError::from)?;
    let n = model.num_dofs();
    let approx = modal_damping(lin, modes);
    let exact = exact_damped_modes(lin, modes)?;
    let rayleigh = rayleigh_fit(model, options.rayleigh_modes, modes, &exact)?;
    let per_mode = mode_dampings(n, modes, &approx, &exact, &rayleigh);

    // The releases: HW34's mode shapes (first coordinate 1, or the largest entry if the
    // first is zero), or one given deviation.
    check_tolerance(options.tol)?;
    let t_end = options
        .t_end
        .unwrap_or_else(|| default_duration(modes, 10.0, 5.0));
    let times = uniform_times(t_end, options.samples)?;
    let names = model.description().coordinate_names();
    let starts = release_starts(n, modes, &names, options.initial.as_ref());
    let diagonal_damping = approx.diagonal();
    let setting = ReleaseSetting {
        lin,
        modes,
        diagonal_damping: &diagonal_damping,
        rayleigh: rayleigh.as_ref(),
        times: &times,
        tol: options.tol,
    };
    let mut releases = Vec::new();
    for (name, q0, v0) in starts {
        releases.push(setting.release(name, q0, v0)?);
    }
    Ok(ModalDampingStudy {
        operating_point: modal.operating_point,
        linearization: modal.linearization,
        normal_modes: modal.normal_modes,
        modal_damping: approx,
        rayleigh,
        modes: per_mode,
        t_end,
        tol: options.tol,
        releases,
    })
}

/// The damping ratios of each of the `n` modes ([`ModalDampingStudy::modes`]): exact, by the
/// diagonal of `Ĉ` (`approx`) and by the Rayleigh fit for the oscillatory modes.
fn mode_dampings(
    n: usize,
    modes: &NormalModes,
    approx: &ModalDamping,
    exact: &[Option<DampedMode>],
    rayleigh: &Option<RayleighFit>,
) -> Vec<ModeDamping> {
    (0..n)
        .map(|k| {
            let w = modes.natural_frequencies[k];
            ModeDamping {
                mode: k + 1,
                kind: modes.kinds[k],
                natural_frequency: w,
                exact: exact[k],
                diagonal: approx.damping_ratios[k].map(|z| ModalRatio {
                    damping_ratio: z,
                    damped_frequency: approx.damped_frequencies[k],
                }),
                rayleigh: match (rayleigh, modes.kinds[k]) {
                    (Some(fit), ModeKind::Oscillatory) => {
                        let z = fit.damping.damping_ratio(w);
                        Some(ModalRatio {
                            damping_ratio: z,
                            damped_frequency: damped_frequency(w, z),
                        })
                    }
                    _ => None,
                },
            }
        })
        .collect()
}

/// The name, `δq₀` and `δq̇₀` of each release: from each of the `n` mode shapes at rest
/// (scaled so that its first coordinate, or its largest entry if the first is zero, is 1),
/// or the one `initial` deviation.
fn release_starts(
    n: usize,
    modes: &NormalModes,
    names: &[&str],
    initial: Option<&InitialDeviation>,
) -> Vec<(String, Vec<f64>, Vec<f64>)> {
    let mut starts: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
    match initial {
        None => {
            for k in 0..n {
                let shape = modes.mode_shapes.column(k);
                let largest = shape.amax();
                let j = if shape[0].abs() > 1e-8 * largest {
                    0
                } else {
                    shape.iamax()
                };
                let q0: Vec<f64> = shape.iter().map(|v| v / shape[j]).collect();
                starts.push((
                    format!("mode {} shape, {} = 1", k + 1, names[j]),
                    q0,
                    vec![0.0; n],
                ));
            }
        }
        Some(initial) => starts.push((
            "given initial values".to_string(),
            initial.q.clone(),
            initial.qdot.clone(),
        )),
    }
    starts
}

/// What every release's responses share: the linearisation and its modes, the diagonal
/// modal damping, the Rayleigh fit if any, the output times and the DOP853 tolerance.
struct ReleaseSetting<'a> {
    lin: &'a Linearization,
    modes: &'a NormalModes,
    diagonal_damping: &'a [f64],
    rayleigh: Option<&'a RayleighFit>,
    times: &'a [f64],
    tol: f64,
}

impl ReleaseSetting<'_> {
    /// The release `name` from `q0`, `v0`: its exact, integrated, diagonal and Rayleigh
    /// responses and their differences from the exact one.
    ///
    /// # Errors
    /// [`ResponseStudyError::Response`] when a response cannot be computed.
    fn release(
        &self,
        name: String,
        q0: Vec<f64>,
        v0: Vec<f64>,
    ) -> Result<Release, ResponseStudyError> {
        let (lin, modes, times) = (self.lin, self.modes, self.times);
        let exact_response = response_by_exponential(lin, &q0, &v0, times)?;
        let integrated = response_by_integration(lin, &q0, &v0, times, self.tol)?;
        let diagonal =
            response_with_modal_damping(lin, modes, self.diagonal_damping, &q0, &v0, times)?;
        let rayleigh_response = match self.rayleigh {
            Some(fit) => Some(response_with_modal_damping(
                lin,
                modes,
                &fit.damping.modal_damping(modes),
                &q0,
                &v0,
                times,
            )?),
            None => None,
        };
        // Differences from the exact response, relative to its largest |δq|.
        let amplitude = exact_response.max_displacement();
        let versus = |other: &FreeResponse| -> f64 {
            let d = exact_response
                .max_displacement_difference(other)
                .unwrap_or(f64::INFINITY);
            if amplitude > 0.0 { d / amplitude } else { d }
        };
        Ok(Release {
            integration_vs_exact: versus(&integrated),
            diagonal_vs_exact: versus(&diagonal),
            rayleigh_vs_exact: rayleigh_response.as_ref().map(versus),
            name,
            q0,
            qdot0: v0,
            amplitude,
            exact: exact_response,
            integrated,
            diagonal,
            rayleigh: rayleigh_response,
        })
    }
}

/// The Rayleigh fit `C = αM + βK` to the exact damping ratios of two modes (numbered from 1):
/// those `requested`, which must exist and be underdamped, or by default the slowest and the
/// fastest oscillatory modes when both are underdamped; `None` without such a pair.
fn rayleigh_fit(
    model: &dyn ModelInfo,
    requested: Option<[usize; 2]>,
    modes: &NormalModes,
    exact: &[Option<DampedMode>],
) -> Result<Option<RayleighFit>, ResponseStudyError> {
    let n = modes.natural_frequencies.len();
    let oscillatory: Vec<usize> = (0..n)
        .filter(|&k| modes.kinds[k] == ModeKind::Oscillatory)
        .collect();
    // The Rayleigh fit: explicit modes must be usable; by default the slowest and fastest
    // oscillatory modes, if there are two with exact damping ratios.
    let chosen: Option<[usize; 2]> = match requested {
        Some(pair) => {
            for k in pair {
                if k == 0 || k > n {
                    return Err(ResponseStudyError::NoSuchMode {
                        model: model.description().name.to_string(),
                        mode: k,
                        count: n,
                    });
                }
                if exact[k - 1].is_none() {
                    return Err(ResponseStudyError::NotUnderdamped { mode: k });
                }
            }
            Some(pair)
        }
        None => match (oscillatory.first(), oscillatory.last()) {
            (Some(&a), Some(&b)) if a != b && exact[a].is_some() && exact[b].is_some() => {
                Some([a + 1, b + 1])
            }
            _ => None,
        },
    };
    Ok(match chosen {
        Some([a, b]) => {
            let zeta = |k: usize| exact[k - 1].map_or(f64::NAN, |d| d.damping_ratio);
            let damping = RayleighDamping::fit(
                [
                    modes.natural_frequencies[a - 1],
                    modes.natural_frequencies[b - 1],
                ],
                [zeta(a), zeta(b)],
            )
            .map_err(|source| ResponseStudyError::RayleighFit {
                modes: [a, b],
                source,
            })?;
            Some(RayleighFit {
                modes: [a, b],
                damping,
            })
        }
        None => None,
    })
}
