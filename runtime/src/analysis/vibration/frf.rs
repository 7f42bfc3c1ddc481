//! `eomgen frf` as library calls (lecture 21, HW21, HW34, HW37): the frequency response
//! `H(ω) = (K − ω²M + iωC)⁻¹ B` from one input to coordinates over a sweep, its resonance
//! peaks, the response assembled mode by mode at chosen frequencies, and points of the curve
//! checked by simulating the full model to steady state.
//!
//! [`frequency_response_analysis`] computes everything but the simulations;
//! [`plan_simulation`] checks their options and picks the frequencies, and
//! [`simulate_point`] runs one (independent of the others, so a caller may run them in
//! parallel, each on its own instance of the model).
//!
//! long: over half of it is the `Serialize` summaries of the analysis (`*Summary`), which
//! mirror its types field by field; they could move beside the other summaries, a split left
//! to the issue on the code's shape.

use std::collections::BTreeMap;

use nalgebra::{Complex, DVector};
use serde::Serialize;

use super::operating_point::{
    OperatingPoint, OperatingPointError, OperatingPointOptions, PointSummary,
};
use crate::linear::eigenvalues::{LinearStability, linear_stability};
use crate::linear::frequency_response::{
    ForcedLinearization, FrequencySweep, FrfError, HarmonicForcing, ModalResponse, PeakAmplitude,
    SteadyStateOptions, frequency_response_to, frequency_sweep_with_rates,
    linearize_with_input_rates, linearize_with_inputs, log_frequencies, modal_frequency_response,
    output_index, settling_time, simulate_steady_state,
};
use crate::linear::modal::{NormalModes, normal_modes};
use crate::linear::response::{ModalDamping, modal_damping};
use crate::model_info::ModelInfo;

/// Why a frequency-response analysis failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FrfAnalysisError {
    /// Fewer than two sweep frequencies.
    #[error("the sweep needs at least 2 frequencies, got {points}")]
    TooFewPoints {
        /// Given.
        points: usize,
    },
    /// The input is neither a parameter nor a coordinate.
    #[error(
        "`{model}` has no parameter or coordinate `{input}` (parameters: {parameters}; coordinates: {coordinates})"
    )]
    UnknownInput {
        /// The model.
        model: String,
        /// The input asked for.
        input: String,
        /// Its parameters, comma separated.
        parameters: String,
        /// Its coordinates, comma separated.
        coordinates: String,
    },
    /// A simulation was asked for with a coordinate as the input (a unit generalized force
    /// has no load in the model to drive).
    #[error("simulation needs a load parameter as the input (`{input}` is a coordinate)")]
    SimulationNeedsParameter {
        /// The input.
        input: String,
    },
    /// The operating point's start is unknown.
    #[error(transparent)]
    OperatingPoint(#[from] OperatingPointError),
    /// The input is a parameter but not a load amplitude (nonlinear, absent at `t = 0`, or
    /// in the mass matrix).
    #[error(transparent)]
    Input(FrfError),
    /// An output that is not a coordinate.
    #[error("{source}")]
    Output {
        /// The output asked for.
        output: String,
        /// Why.
        source: FrfError,
    },
    /// No frequency range was given and no mode is oscillatory.
    #[error(
        "`{model}` has no oscillatory mode at `{operating_point}` to choose a frequency range from"
    )]
    NoFrequencyRange {
        /// The model.
        model: String,
        /// The operating point's name.
        operating_point: String,
    },
    /// The frequency range is not `0 < lo < hi < ∞`.
    #[error(transparent)]
    FrequencyRange(FrfError),
    /// No frequency parameter was named and the model has no `w`.
    #[error(
        "`{model}` has no parameter `w`; name the forcing frequency's parameter (parameters: {parameters})"
    )]
    NoFrequencyParameter {
        /// The model.
        model: String,
        /// Its parameters, comma separated.
        parameters: String,
    },
    /// The frequency parameter is not a parameter.
    #[error("`{model}` has no such parameter (parameters: {parameters})")]
    UnknownFrequencyParameter {
        /// The model.
        model: String,
        /// The name given.
        name: String,
        /// Its parameters, comma separated.
        parameters: String,
    },
    /// The frequency parameter is the input itself.
    #[error("the frequency parameter must differ from the input")]
    FrequencyParameterIsInput,
    /// The simulation's input amplitude is zero or not finite.
    #[error("the amplitude must be finite and nonzero, got {amplitude}")]
    InvalidAmplitude {
        /// Given.
        amplitude: f64,
    },
    /// The simulation's relative tolerance is not in `(0, 1)`.
    #[error("the relative tolerance must be in (0, 1), got {rtol}")]
    InvalidTolerance {
        /// Given.
        rtol: f64,
    },
    /// The free response does not decay: no steady state to simulate.
    #[error(transparent)]
    NoSteadyState(FrfError),
    /// A modal sum was asked for an input that enters through its rate (a base motion): the
    /// modal forces `ψₖᵀ(B₀ + iωB₁)` are complex, which the modal sum does not take.
    #[error(
        "the modal sum takes a load, and input `{input}` also enters through its rate (B₁ ≠ 0, a base motion through a dashpot)"
    )]
    ModalWithInputRate {
        /// The input.
        input: String,
    },
    /// The linearisation, a response or a simulation failed.
    #[error(transparent)]
    Frf(#[from] FrfError),
}

/// Options of the steady-state simulations that check the curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrfSimulationOptions {
    /// How many frequencies, log-spaced over the sweep's range (0: none).
    pub count: usize,
    /// The parameter holding the forcing frequency, set to each `ω` (default: `w` if the
    /// model has it).
    pub frequency_parameter: Option<String>,
    /// The input's value in the runs, small so that the nonlinear model stays near its
    /// linearisation (default: 1e-3).
    pub amplitude: f64,
    /// Relative tolerance of DOP853, in `(0, 1)` (default: 1e-11); the absolute tolerance is
    /// `rtol` times the predicted response's scale `max|H| |amplitude| max(ω, 1)`.
    pub rtol: f64,
}

impl FrfSimulationOptions {
    /// The default input value of the runs (small, so that the model stays near its
    /// linearisation).
    pub const DEFAULT_AMPLITUDE: f64 = 1e-3;
    /// The default relative tolerance of the runs.
    pub const DEFAULT_RTOL: f64 = 1e-11;
}

impl Default for FrfSimulationOptions {
    fn default() -> Self {
        Self {
            count: 0,
            frequency_parameter: None,
            amplitude: Self::DEFAULT_AMPLITUDE,
            rtol: Self::DEFAULT_RTOL,
        }
    }
}

/// Options of [`frequency_response_analysis`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrfOptions {
    /// Where the equilibrium search starts (it runs with the input set to 0).
    pub operating_point: OperatingPointOptions,
    /// The input: a parameter that enters the forcing linearly (a load amplitude), or a
    /// coordinate's name (a unit generalized force on it).
    pub input: String,
    /// The output coordinates (default, empty: every coordinate).
    pub outputs: Vec<String>,
    /// The sweep's range `(lo, hi)` in rad/s (default: a decade below the lowest to a decade
    /// above the highest natural frequency).
    pub frequency_range: Option<(f64, f64)>,
    /// Frequencies of the sweep, log-spaced (default: 400; at least 2).
    pub points: usize,
    /// Frequencies (rad/s) at which the response is also evaluated.
    pub frequencies: Vec<f64>,
    /// Also assemble the response mode by mode at those frequencies (default: at the damped
    /// peaks when `frequencies` is empty).
    pub modal: bool,
    /// The steady-state simulations, checked (their frequency parameter, amplitude and
    /// tolerance) by [`plan_simulation`]; only whether they are asked for matters here.
    pub simulation: Option<FrfSimulationOptions>,
}

impl FrfOptions {
    /// The default number of log-spaced frequencies of the sweep.
    pub const DEFAULT_POINTS: usize = 400;
}

impl Default for FrfOptions {
    fn default() -> Self {
        Self {
            operating_point: OperatingPointOptions::default(),
            input: String::new(),
            outputs: Vec::new(),
            frequency_range: None,
            points: Self::DEFAULT_POINTS,
            frequencies: Vec::new(),
            modal: false,
            simulation: None,
        }
    }
}

/// An output coordinate.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct FrfOutput {
    /// Its name.
    pub name: String,
    /// Its index in `q`.
    pub index: usize,
}

/// The response at one evaluation frequency.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrfEvaluation {
    /// `ω` (rad/s).
    pub frequency: f64,
    /// `H(ω)` for the input, one entry per coordinate (length `n`); `None` at an undamped
    /// resonance (unbounded).
    #[serde(serialize_with = "option_complex_vector")]
    pub response: Option<DVector<Complex<f64>>>,
    /// The modal sum (with `modal`); `None` without it or where a mode is undamped at `ω`.
    pub modal: Option<ModalResponse>,
    /// `max_i |H_i − Σ_k (ψ_k η_k)_i| / max_i |H_i|` at `ω` (with a modal sum and a bounded
    /// direct solve).
    pub modal_difference: Option<f64>,
}

fn option_complex_vector<S: serde::Serializer>(
    v: &Option<DVector<Complex<f64>>>,
    s: S,
) -> Result<S::Ok, S::Error> {
    match v {
        Some(v) => crate::serde_matrix::complex_vector(v, s),
        None => s.serialize_none(),
    }
}

/// What [`frequency_response_analysis`] computed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrfAnalysis {
    /// The unforced equilibrium and its name.
    pub operating_point: OperatingPoint,
    /// The input.
    pub input: String,
    /// The outputs, in the order asked for.
    pub outputs: Vec<FrfOutput>,
    /// `M`, `C`, `K` at the equilibrium and the input column `B` (`n × 1`).
    pub forced: ForcedLinearization,
    /// The undamped modes.
    pub normal_modes: NormalModes,
    /// `ΨᵀCΨ` and the modal damping ratios.
    pub modal_damping: ModalDamping,
    /// The stability of the equilibrium from the whole linearisation, with the damping and
    /// gyroscopic parts of `C` ([`linear_stability`]); with a gyroscopic part the undamped
    /// modes are not the system's, and neither are the modal sums over them.
    pub stability: LinearStability,
    /// The sweep's range (rad/s).
    pub frequency_range: (f64, f64),
    /// The sweep's frequencies (rad/s, log-spaced).
    pub frequencies: Vec<f64>,
    /// One sweep per output.
    pub sweeps: Vec<FrequencySweep>,
    /// The response at the evaluation frequencies.
    pub evaluations: Vec<FrfEvaluation>,
}

/// Finds the unforced equilibrium, linearises with the input's column of `B`, sweeps `H(ω)`
/// from the input to each output, finds the resonance peaks and evaluates the response (and,
/// with `modal`, its modal sum) at the evaluation frequencies.
///
/// A parameter input whose load reverses over half a period of the frequency parameter (the
/// simulation's `frequency_parameter`, else `w` when the model has it) may also enter through
/// its rate, as a base motion `Y cos(w t)` does through a dashpot: its rate column `B₁` is
/// read a quarter period after `t = 0`
/// ([`linearize_with_input_rates`])
/// and the input column at `ω` is `B₀ + iωB₁`, so `H` is the transmissibility
/// `(k + iωc)/(k − mω² + iωc)` of `models/base_excited_oscillator.yaml` (lecture 38).
///
/// # Errors
/// [`FrfAnalysisError::ModalWithInputRate`] (`modal` with `B₁ ≠ 0`),
/// [`FrfAnalysisError::TooFewPoints`], [`FrfAnalysisError::UnknownInput`],
/// [`FrfAnalysisError::SimulationNeedsParameter`], [`FrfAnalysisError::OperatingPoint`],
/// [`FrfAnalysisError::Input`] (not a load amplitude), [`FrfAnalysisError::Output`],
/// [`FrfAnalysisError::NoFrequencyRange`], [`FrfAnalysisError::FrequencyRange`],
/// [`FrfAnalysisError::Frf`] (a failed linearisation or response).
///
/// # Examples
/// The forced oscillator (`m = k = c = 1`): `|H(ω)| = 1/√((k − mω²)² + (cω)²)`.
/// ```
/// use eomgen_runtime::analysis::vibration::{FrfOptions, frequency_response_analysis};
/// let mut model = (eomgen::models::find("forced_oscillator").unwrap().make)();
/// let options = FrfOptions {
///     input: "A".to_string(),
///     frequencies: vec![2.0],
///     ..FrfOptions::default()
/// };
/// let frf = frequency_response_analysis(model.as_mut(), &options)?;
/// let h = frf.evaluations[0].response.as_ref().unwrap()[0];
/// assert!((h.norm() - 1.0 / ((1.0f64 - 4.0).powi(2) + 4.0).sqrt()).abs() < 1e-14);
/// # Ok::<(), eomgen_runtime::analysis::vibration::FrfAnalysisError>(())
/// ```
///
/// # References
/// Lecture 21 and HW21 (one degree of freedom), HW37 (modal forcing), HW34 (modal damping).
pub fn frequency_response_analysis(
    model: &mut dyn ModelInfo,
    options: &FrfOptions,
) -> Result<FrfAnalysis, FrfAnalysisError> {
    let parameter_input = check_frf_input(model, options)?;
    let input = options.input.as_str();
    let (label, guess) = options.operating_point.start.resolve_equilibrium(model)?;
    let forced = forced_linearization(model, options, &guess, parameter_input)?;
    if options.modal && forced.has_input_rates() {
        return Err(FrfAnalysisError::ModalWithInputRate {
            input: input.to_string(),
        });
    }
    let coordinates: Vec<String> = model
        .description()
        .coordinate_names()
        .iter()
        .map(|c| c.to_string())
        .collect();
    let outputs = frf_outputs(model, &options.outputs, &coordinates)?;
    let lin = &forced.linearization;
    let modes = normal_modes(lin).map_err(FrfError::from)?;
    let damping = modal_damping(lin, &modes);
    let stability = linear_stability(lin).map_err(FrfError::from)?;
    // Without an undamped oscillation (a gyroscopic system whose K is not positive), the
    // oscillations of the whole linearisation set the range.
    let mut oscillations: Vec<f64> = stability
        .eigenvalues
        .iter()
        .filter(|s| s.im > 0.0)
        .map(|s| s.im)
        .collect();
    oscillations.sort_by(f64::total_cmp);
    let (lo, hi) = match options.frequency_range {
        Some(range) => range,
        None => default_range(&modes.natural_frequencies)
            .or_else(|| default_range(&oscillations))
            .ok_or_else(|| FrfAnalysisError::NoFrequencyRange {
                model: model.description().name.to_string(),
                operating_point: label.clone(),
            })?,
    };
    let frequencies =
        log_frequencies(lo, hi, options.points).map_err(FrfAnalysisError::FrequencyRange)?;
    // The one input's column, `n × 1`.
    let b_matrix = &forced.input_matrix;
    let mut sweeps = Vec::with_capacity(outputs.len());
    for o in &outputs {
        sweeps.push(frequency_sweep_with_rates(
            lin,
            b_matrix,
            &forced.input_rate_matrix,
            0,
            o.index,
            &frequencies,
        )?);
    }
    let evaluation_frequencies = evaluation_frequencies(options, &sweeps);
    let mut evaluations = Vec::with_capacity(evaluation_frequencies.len());
    let requested: Vec<usize> = outputs.iter().map(|o| o.index).collect();
    let b = options.modal.then(|| b_matrix.column(0).into_owned());
    for w in evaluation_frequencies {
        evaluations.push(evaluate_at(&forced, b.as_ref(), &modes, w, &requested)?);
    }
    let operating_point = OperatingPoint {
        name: label,
        coordinates,
        guess,
        t: 0.0,
        equilibrium: forced.equilibrium.clone(),
    };
    Ok(FrfAnalysis {
        operating_point,
        input: input.to_string(),
        outputs,
        normal_modes: modes,
        modal_damping: damping,
        stability,
        frequency_range: (lo, hi),
        frequencies,
        sweeps,
        evaluations,
        forced,
    })
}

/// Checks [`frequency_response_analysis`]'s options against `model` before any work: at least
/// two points, an input that is a parameter or a coordinate, and a simulation only for a
/// parameter input. Returns whether the input is a parameter.
///
/// # Errors
/// [`FrfAnalysisError::TooFewPoints`], [`FrfAnalysisError::UnknownInput`] and
/// [`FrfAnalysisError::SimulationNeedsParameter`].
fn check_frf_input(model: &dyn ModelInfo, options: &FrfOptions) -> Result<bool, FrfAnalysisError> {
    if options.points < 2 {
        return Err(FrfAnalysisError::TooFewPoints {
            points: options.points,
        });
    }
    let input = options.input.as_str();
    let parameter_input = model.description().parameter_names().contains(&input);
    if !parameter_input && !model.description().coordinate_names().contains(&input) {
        return Err(FrfAnalysisError::UnknownInput {
            model: model.description().name.to_string(),
            input: input.to_string(),
            parameters: model.description().parameter_names().join(", "),
            coordinates: model.description().coordinate_names().join(", "),
        });
    }
    if !parameter_input && options.simulation.is_some() {
        return Err(FrfAnalysisError::SimulationNeedsParameter {
            input: input.to_string(),
        });
    }
    Ok(parameter_input)
}

/// The linearisation of `model` about the equilibrium near `guess` (length `n`) with the
/// input matrix of `options.input` (`n × 1`), and its rate column when a frequency parameter
/// (the simulation's, else `w`) times a parameter input.
///
/// # Errors
/// [`FrfAnalysisError::Input`] when the input is not a load amplitude,
/// [`FrfAnalysisError::Frf`] when the linearisation fails.
fn forced_linearization(
    model: &mut dyn ModelInfo,
    options: &FrfOptions,
    guess: &[f64],
    parameter_input: bool,
) -> Result<ForcedLinearization, FrfAnalysisError> {
    let input = options.input.as_str();
    // The parameter that times the load (the simulation's, else `w`) also says where to read
    // an input's rate column (a base motion through a dashpot).
    let parameters = model.description().parameter_names();
    let frequency_parameter = options
        .simulation
        .as_ref()
        .and_then(|s| s.frequency_parameter.clone())
        .or_else(|| Some("w".to_string()))
        .filter(|p| parameter_input && p != input && parameters.contains(&p.as_str()));
    match &frequency_parameter {
        Some(p) => linearize_with_input_rates(model, guess, &[input], p),
        None => linearize_with_inputs(model, guess, &[input]),
    }
    .map_err(|e| match e {
        FrfError::NonlinearInput { .. }
        | FrfError::InputNotInForcing { .. }
        | FrfError::InputChangesMassMatrix { .. }
        | FrfError::InputRateNotConstant { .. } => FrfAnalysisError::Input(e),
        e => FrfAnalysisError::Frf(e),
    })
}

/// The frequencies (rad/s) at which [`frequency_response_analysis`] evaluates the response:
/// `options.frequencies`, or when those are empty and `options.modal` is set, every finite
/// peak of the `sweeps` (peaks within `1e-6` relative of one taken counted once), ascending.
fn evaluation_frequencies(options: &FrfOptions, sweeps: &[FrequencySweep]) -> Vec<f64> {
    let mut evaluation_frequencies = options.frequencies.clone();
    if options.modal && evaluation_frequencies.is_empty() {
        for peak in sweeps.iter().flat_map(|s| &s.peaks) {
            if matches!(peak.amplitude, PeakAmplitude::Finite(_))
                && !evaluation_frequencies
                    .iter()
                    .any(|w: &f64| (w - peak.frequency).abs() <= 1e-6 * peak.frequency)
            {
                evaluation_frequencies.push(peak.frequency);
            }
        }
        evaluation_frequencies.sort_by(f64::total_cmp);
    }
    evaluation_frequencies
}

/// The outputs of a frequency response: every coordinate when `requested` is empty, else each
/// requested coordinate or rate by name.
fn frf_outputs(
    model: &dyn ModelInfo,
    requested: &[String],
    coordinates: &[String],
) -> Result<Vec<FrfOutput>, FrfAnalysisError> {
    if requested.is_empty() {
        return Ok(coordinates
            .iter()
            .enumerate()
            .map(|(index, name)| FrfOutput {
                name: name.clone(),
                index,
            })
            .collect());
    }
    requested
        .iter()
        .map(|o| {
            let index = output_index(model, o).map_err(|source| FrfAnalysisError::Output {
                output: o.clone(),
                source,
            })?;
            Ok(FrfOutput {
                name: o.clone(),
                index,
            })
        })
        .collect()
}

/// The default sweep: a decade below the lowest positive natural frequency to a decade above
/// the highest (rad/s); `None` without a positive one.
fn default_range(natural_frequencies: &[f64]) -> Option<(f64, f64)> {
    let mut positive = natural_frequencies.iter().copied().filter(|w| *w > 0.0);
    let first = positive.next()?;
    let last = positive.next_back().unwrap_or(first);
    Some((first / 10.0, last * 10.0))
}

/// `H(ω)` of the one input (`B₀ + iωB₁` of `forced`) at `w` for the `requested` outputs,
/// its modal sum when `b` is given, and their largest difference relative to the largest `|H|`; a singular `ω` (undamped
/// resonance) gives `None` for the response it makes singular.
fn evaluate_at(
    forced: &ForcedLinearization,
    b: Option<&DVector<f64>>,
    modes: &NormalModes,
    w: f64,
    requested: &[usize],
) -> Result<FrfEvaluation, FrfError> {
    let lin = &forced.linearization;
    let response = match frequency_response_to(lin, &forced.input_at(w), w, requested) {
        Ok(h) => Some(h.column(0).into_owned()),
        Err(FrfError::Singular { .. }) => None,
        Err(e) => return Err(e),
    };
    let modal = match b.map(|b| modal_frequency_response(lin, modes, b, w)) {
        Some(Ok(r)) => Some(r),
        None | Some(Err(FrfError::Singular { .. })) => None,
        Some(Err(e)) => return Err(e),
    };
    let modal_difference = match (&response, &modal) {
        (Some(d), Some(r)) => {
            let largest = d.iter().map(|z| z.norm()).fold(0.0f64, f64::max);
            let difference = d
                .iter()
                .zip(r.response.iter())
                .map(|(a, b)| (a - b).norm())
                .fold(0.0f64, f64::max);
            Some(difference / largest.max(f64::MIN_POSITIVE))
        }
        _ => None,
    };
    Ok(FrfEvaluation {
        frequency: w,
        response,
        modal,
        modal_difference,
    })
}

/// The checked plan of the steady-state simulations.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrfSimulationPlan {
    /// The parameter set to each `ω`.
    pub frequency_parameter: String,
    /// The time to wait before measuring (s): the slowest free decay shrinks by `1e-10`.
    pub settling_time: f64,
    /// The frequencies (rad/s), log-spaced over the sweep's range.
    pub frequencies: Vec<f64>,
    /// The options, as given.
    pub options: FrfSimulationOptions,
}

/// Checks the simulation options against `model` and `analysis` and picks the frequencies
/// and the settling time.
///
/// # Errors
/// [`FrfAnalysisError::NoFrequencyParameter`], [`FrfAnalysisError::UnknownFrequencyParameter`],
/// [`FrfAnalysisError::FrequencyParameterIsInput`], [`FrfAnalysisError::InvalidAmplitude`],
/// [`FrfAnalysisError::InvalidTolerance`], [`FrfAnalysisError::NoSteadyState`] (a mode
/// without damping), [`FrfAnalysisError::FrequencyRange`], [`FrfAnalysisError::Frf`].
pub fn plan_simulation(
    model: &dyn ModelInfo,
    analysis: &FrfAnalysis,
    options: &FrfSimulationOptions,
) -> Result<FrfSimulationPlan, FrfAnalysisError> {
    let parameters = model.description().parameter_names();
    let frequency_parameter = match &options.frequency_parameter {
        Some(p) => p.clone(),
        None if parameters.contains(&"w") => "w".to_string(),
        None => {
            return Err(FrfAnalysisError::NoFrequencyParameter {
                model: model.description().name.to_string(),
                parameters: parameters.join(", "),
            });
        }
    };
    if !parameters.contains(&frequency_parameter.as_str()) {
        return Err(FrfAnalysisError::UnknownFrequencyParameter {
            model: model.description().name.to_string(),
            name: frequency_parameter,
            parameters: parameters.join(", "),
        });
    }
    if frequency_parameter == analysis.input {
        return Err(FrfAnalysisError::FrequencyParameterIsInput);
    }
    if !(options.amplitude.is_finite() && options.amplitude != 0.0) {
        return Err(FrfAnalysisError::InvalidAmplitude {
            amplitude: options.amplitude,
        });
    }
    if !(options.rtol > 0.0 && options.rtol < 1.0) {
        return Err(FrfAnalysisError::InvalidTolerance { rtol: options.rtol });
    }
    // Wait until the slowest free decay has shrunk by 1e-10 relative to the response.
    let settle = settling_time(&analysis.forced.linearization, 1e-10).map_err(|e| match e {
        FrfError::NoSteadyState { .. } => FrfAnalysisError::NoSteadyState(e),
        e => FrfAnalysisError::Frf(e),
    })?;
    let (lo, hi) = analysis.frequency_range;
    let frequencies =
        log_frequencies(lo, hi, options.count).map_err(FrfAnalysisError::FrequencyRange)?;
    Ok(FrfSimulationPlan {
        frequency_parameter,
        settling_time: settle,
        frequencies,
        options: options.clone(),
    })
}

/// One output at one simulated frequency.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SimulatedValue {
    /// The simulated complex amplitude over the input's amplitude (`{"re", "im"}`).
    #[serde(serialize_with = "crate::serde_matrix::complex")]
    pub simulated: Complex<f64>,
    /// The predicted `H(ω)` (`{"re", "im"}`).
    #[serde(serialize_with = "crate::serde_matrix::complex")]
    pub predicted: Complex<f64>,
}

impl SimulatedValue {
    /// `|simulated − predicted| / |predicted|`, or `|simulated − predicted|` for a zero
    /// prediction.
    pub fn relative_error(&self) -> f64 {
        let d = (self.simulated - self.predicted).norm();
        let p = self.predicted.norm();
        if p > 0.0 { d / p } else { d }
    }
}

/// One simulated frequency.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimulatedPoint {
    /// `ω` (rad/s).
    pub frequency: f64,
    /// The settling time used (s).
    pub settling_time: f64,
    /// One value per output, in the analysis's order.
    pub values: Vec<SimulatedValue>,
    /// DOP853 steps.
    pub steps: usize,
    /// Right-hand-side evaluations.
    pub rhs_evals: usize,
}

/// Simulates `model` (the analysed one, or a fresh instance with the same parameters) forced
/// at `frequency` from rest at the equilibrium to steady state and measures each output's
/// complex amplitude at the forcing frequency ([`simulate_steady_state`]), beside the
/// predicted `H(ω)`.
///
/// # Errors
/// [`FrfError`] from `H(ω)` or the simulation.
pub fn simulate_point(
    model: &mut dyn ModelInfo,
    analysis: &FrfAnalysis,
    plan: &FrfSimulationPlan,
    frequency: f64,
) -> Result<SimulatedPoint, FrfError> {
    let w = frequency;
    let amplitude = plan.options.amplitude;
    let h = frequency_response_to(
        &analysis.forced.linearization,
        &analysis.forced.input_at(w),
        w,
        &[],
    )?;
    let scale = h.iter().map(|z| z.norm()).fold(0.0f64, f64::max) * amplitude.abs() * w.max(1.0);
    let options = SteadyStateOptions {
        rtol: plan.options.rtol,
        atol: plan.options.rtol * scale.max(f64::MIN_POSITIVE),
        ..SteadyStateOptions::default()
    };
    let forcing = HarmonicForcing {
        input: &analysis.input,
        amplitude,
        frequency_parameter: &plan.frequency_parameter,
        frequency: w,
    };
    let steady = simulate_steady_state(
        model,
        &analysis.forced.equilibrium.q,
        &forcing,
        plan.settling_time,
        &options,
    )?;
    let values = analysis
        .outputs
        .iter()
        .map(|o| SimulatedValue {
            simulated: steady.complex_amplitudes[o.index] / amplitude,
            predicted: h[(o.index, 0)],
        })
        .collect();
    Ok(SimulatedPoint {
        frequency: w,
        settling_time: plan.settling_time,
        values,
        steps: steady.steps,
        rhs_evals: steady.rhs_evals,
    })
}

/// The largest error of the simulated points: at each frequency, `|simulated − predicted|`
/// against the largest predicted amplitude at that frequency (an output near an
/// antiresonance, or one the mode shape leaves still, would make a relative error
/// meaningless).
pub fn max_simulation_error(points: &[SimulatedPoint]) -> f64 {
    points
        .iter()
        .map(|p| {
            let scale = p
                .values
                .iter()
                .map(|v| v.predicted.norm())
                .fold(0.0f64, f64::max);
            p.values
                .iter()
                .map(|v| (v.simulated - v.predicted).norm() / scale.max(f64::MIN_POSITIVE))
                .fold(0.0f64, f64::max)
        })
        .fold(0.0f64, f64::max)
}

impl FrfAnalysis {
    /// The analysis as `eomgen frf --json` prints it ([`FrfSummary`]); `model` is the model
    /// analysed (for its name), `simulated` the points of [`simulate_point`] with their plan
    /// when the prediction was checked by simulation.
    pub fn summary(
        &self,
        model: &dyn ModelInfo,
        simulated: Option<(&[SimulatedPoint], &FrfSimulationPlan)>,
    ) -> FrfSummary {
        let outputs = &self.outputs;
        let by_output = |values: &dyn Fn(usize) -> Complex<f64>| -> BTreeMap<String, Phasor> {
            outputs
                .iter()
                .map(|o| (o.name.clone(), values(o.index).into()))
                .collect()
        };
        let (modes, damping) = (&self.normal_modes, &self.modal_damping);
        let modal = |r: &ModalResponse, difference: Option<f64>| ModalSumSummary {
            modes: (0..modes.natural_frequencies.len())
                .map(|k| ModalTermSummary {
                    mode: k + 1,
                    natural_frequency: modes.natural_frequencies[k],
                    damping_ratio: damping.damping_ratios[k],
                    modal_force: r.modal_forces[k],
                    modal_coordinate: r.modal_coordinates[k].into(),
                    contributions: by_output(&|i| r.contributions[(i, k)]),
                })
                .collect(),
            sum: by_output(&|i| r.response[i]),
            max_relative_difference_from_direct: difference,
        };
        FrfSummary {
            model: model.description().name.to_string(),
            input: self.input.clone(),
            outputs: outputs.iter().map(|o| o.name.clone()).collect(),
            operating_point: self.operating_point.summary_at(&self.forced.equilibrium.q),
            input_matrix: self.forced.input_matrix.column(0).iter().copied().collect(),
            input_rate_matrix: self
                .forced
                .input_rate_matrix
                .column(0)
                .iter()
                .copied()
                .collect(),
            natural_frequencies: modes.natural_frequencies.clone(),
            damping_ratios: damping.damping_ratios.clone(),
            modal_damping_coupling: damping.coupling,
            stability: self.stability.clone(),
            frequencies: self.frequencies.clone(),
            responses: outputs
                .iter()
                .zip(&self.sweeps)
                .map(|(o, s)| FrfSweepSummary {
                    output: o.name.clone(),
                    amplitude: s.amplitudes(),
                    phase_deg: s.phases_deg.clone(),
                    peaks: s.peaks.iter().map(PeakSummary::from).collect(),
                })
                .collect(),
            evaluations: self
                .evaluations
                .iter()
                .map(|e| FrfEvaluationSummary {
                    frequency: e.frequency,
                    response: e.response.as_ref().map(|d| by_output(&|i| d[i])),
                    unbounded: e.response.is_none(),
                    modal: e.modal.as_ref().map(|r| modal(r, e.modal_difference)),
                })
                .collect(),
            simulation: simulated.map(|(points, plan)| FrfSimulationSummary {
                amplitude: plan.options.amplitude,
                frequency_parameter: plan.frequency_parameter.clone(),
                rtol: plan.options.rtol,
                points: points
                    .iter()
                    .map(|p| SimulatedPointSummary {
                        frequency: p.frequency,
                        settling_time: p.settling_time,
                        steps: p.steps,
                        rhs_evals: p.rhs_evals,
                        outputs: outputs
                            .iter()
                            .zip(&p.values)
                            .map(|(o, v)| {
                                (
                                    o.name.clone(),
                                    SimulatedValueSummary {
                                        simulated: v.simulated.into(),
                                        predicted: v.predicted.into(),
                                        relative_error: v.relative_error(),
                                    },
                                )
                            })
                            .collect(),
                    })
                    .collect(),
                max_relative_error: max_simulation_error(points),
            }),
        }
    }
}

/// An [`FrfAnalysis`] as `eomgen frf --json` prints it ([`FrfAnalysis::summary`]): every
/// complex response as a [`Phasor`], the values of each output by its name.
///
/// # Shapes
/// `n` coordinates, `k` modes, `o` outputs, `f` frequencies: `input_matrix` `n` entries,
/// `natural_frequencies` and `damping_ratios` `k`, `frequencies` `f`, `responses` `o` sweeps
/// of `f` values each.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrfSummary {
    /// The model's name.
    pub model: String,
    /// The input parameter's name.
    pub input: String,
    /// The outputs' names.
    pub outputs: Vec<String>,
    /// The equilibrium at input 0.
    pub operating_point: PointSummary,
    /// The input column `b` (generalized force per unit input at `t = 0`).
    pub input_matrix: Vec<f64>,
    /// The input's rate column `B₁` (generalized force per unit rate of the input; zero for a
    /// load): the input column at `ω` is `b + iω B₁`.
    pub input_rate_matrix: Vec<f64>,
    /// `ωₖ` (rad/s).
    pub natural_frequencies: Vec<f64>,
    /// The modal damping ratios ([`ModalDamping::damping_ratios`]).
    pub damping_ratios: Vec<Option<f64>>,
    /// [`ModalDamping::coupling`].
    pub modal_damping_coupling: f64,
    /// The sweep's frequencies (rad/s).
    pub frequencies: Vec<f64>,
    /// One sweep per output.
    pub responses: Vec<FrfSweepSummary>,
    /// The responses at the frequencies asked for one by one.
    pub evaluations: Vec<FrfEvaluationSummary>,
    /// The check by simulation (null without one).
    pub simulation: Option<FrfSimulationSummary>,
    /// [`FrfAnalysis::stability`].
    pub stability: LinearStability,
}

/// A complex response per unit input as `{"re", "im", "amplitude", "phase_deg"}`
/// (`amplitude = |z|`, `phase_deg = arg z` in degrees by [`phase_degrees`](crate::linear::frequency_response::phase_degrees)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Phasor {
    /// `Re z`.
    pub re: f64,
    /// `Im z`.
    pub im: f64,
    /// `|z|`.
    pub amplitude: f64,
    /// `arg z` (degrees, in `[−180, 180)`).
    pub phase_deg: f64,
}

impl From<Complex<f64>> for Phasor {
    fn from(z: Complex<f64>) -> Self {
        Self {
            re: z.re,
            im: z.im,
            amplitude: z.norm(),
            phase_deg: crate::linear::frequency_response::phase_degrees(z),
        }
    }
}

/// One output's sweep in an [`FrfSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrfSweepSummary {
    /// The output's name.
    pub output: String,
    /// `|H|` at every frequency (null where unbounded).
    pub amplitude: Vec<Option<f64>>,
    /// `arg H` (degrees) at every frequency (null where unbounded).
    pub phase_deg: Vec<Option<f64>>,
    /// The resonance peaks.
    pub peaks: Vec<PeakSummary>,
}

/// A resonance peak in an [`FrfSummary`]: `amplitude` and `phase_deg` null and `unbounded`
/// true for an undamped resonance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PeakSummary {
    /// Where `|H|` is largest (rad/s).
    pub frequency: f64,
    /// `|H|` there (null when unbounded).
    pub amplitude: Option<f64>,
    /// Whether `|H| → ∞` there.
    pub unbounded: bool,
    /// `arg H` there (degrees; null when unbounded).
    pub phase_deg: Option<f64>,
}

impl From<&crate::linear::frequency_response::ResonancePeak> for PeakSummary {
    fn from(p: &crate::linear::frequency_response::ResonancePeak) -> Self {
        match p.amplitude {
            PeakAmplitude::Finite(a) => Self {
                frequency: p.frequency,
                amplitude: Some(a),
                unbounded: false,
                phase_deg: p.phase_deg,
            },
            PeakAmplitude::Unbounded => Self {
                frequency: p.frequency,
                amplitude: None,
                unbounded: true,
                phase_deg: None,
            },
        }
    }
}

/// The response at one frequency asked for, in an [`FrfSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrfEvaluationSummary {
    /// The frequency (rad/s).
    pub frequency: f64,
    /// Each output's response (null when unbounded).
    pub response: Option<BTreeMap<String, Phasor>>,
    /// Whether the response is unbounded (an undamped resonance).
    pub unbounded: bool,
    /// The modal sum (null unless asked for).
    pub modal: Option<ModalSumSummary>,
}

/// The modal sum at one frequency: each mode's terms, their sum per output and how far it
/// is from the direct solve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModalSumSummary {
    /// One entry per mode.
    pub modes: Vec<ModalTermSummary>,
    /// `Σ_k ψ_k η_k` per output.
    pub sum: BTreeMap<String, Phasor>,
    /// [`FrfEvaluation::modal_difference`].
    pub max_relative_difference_from_direct: Option<f64>,
}

/// One mode's term of a [`ModalSumSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModalTermSummary {
    /// The mode's number (from 1).
    pub mode: usize,
    /// `ωₖ` (rad/s).
    pub natural_frequency: f64,
    /// Its damping ratio (null when not defined).
    pub damping_ratio: Option<f64>,
    /// `ψ_kᵀ b` per unit input.
    pub modal_force: f64,
    /// `η_k` per unit input.
    pub modal_coordinate: Phasor,
    /// `ψ_k η_k` per output.
    pub contributions: BTreeMap<String, Phasor>,
}

/// The check by simulation in an [`FrfSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrfSimulationSummary {
    /// The forcing amplitude simulated (units of the input).
    pub amplitude: f64,
    /// The parameter set to each frequency.
    pub frequency_parameter: String,
    /// The integration's relative tolerance.
    pub rtol: f64,
    /// The simulated frequencies.
    pub points: Vec<SimulatedPointSummary>,
    /// [`max_simulation_error`].
    pub max_relative_error: f64,
}

/// One simulated frequency in an [`FrfSimulationSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimulatedPointSummary {
    /// The frequency (rad/s).
    pub frequency: f64,
    /// The time simulated before the measured period (s).
    pub settling_time: f64,
    /// Accepted steps.
    pub steps: usize,
    /// Right-hand-side evaluations.
    pub rhs_evals: usize,
    /// Each output's simulated and predicted response.
    pub outputs: BTreeMap<String, SimulatedValueSummary>,
}

/// One output at one simulated frequency.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SimulatedValueSummary {
    /// The response measured from the simulation, per unit input.
    pub simulated: Phasor,
    /// The linear prediction, per unit input.
    pub predicted: Phasor,
    /// [`SimulatedValue::relative_error`].
    pub relative_error: f64,
}
