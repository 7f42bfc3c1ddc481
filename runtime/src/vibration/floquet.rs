//! `eomgen study floquet` as library calls (issue 7, item 7; lectures 19 and 21): the Floquet
//! multipliers of a time-periodic model about an equilibrium that holds for every `t` of the
//! period, and one cell of a stability chart over two parameters.
//!
//! The period is `T = 2π/w` with `w` the value of the period parameter; the operating point
//! is found by Newton at `t = 0` and checked to stay an equilibrium over the period
//! ([`check_periodic_equilibrium`], 65 times); the monodromy matrix comes from the variational
//! equations with the generated Jacobians ([`floquet_analysis`]). A chart repeats
//! [`floquet_cell`] over a grid of [`SweepAxis`] values; each cell is independent, so a
//! caller may run them in parallel, each on its own instance of the model.

use std::f64::consts::TAU;

use serde::Serialize;

use super::operating_point::{OperatingPointError, OperatingPointOptions};
use crate::floquet::{
    FloquetAnalysis, FloquetError, FloquetOptions, FloquetStability, check_periodic_equilibrium,
    floquet_analysis,
};
use crate::modal::{ModalError, find_equilibrium};
use crate::model_info::ModelInfo;
use crate::system::UnknownParameter;

/// Why a Floquet analysis (or one cell of a chart) failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FloquetStudyError {
    /// The period parameter is not a parameter of the model.
    #[error("`{model}` has no parameter `{name}` (it has: {parameters})")]
    UnknownPeriodParameter {
        /// The model.
        model: String,
        /// The name given.
        name: String,
        /// Its parameters, comma separated.
        parameters: String,
    },
    /// A tolerance is out of range.
    #[error(
        "the tolerance must be positive ({rtol}) and the stability tolerance finite and ≥ 0 ({stability_tolerance})"
    )]
    InvalidTolerance {
        /// DOP853's tolerance.
        rtol: f64,
        /// The tolerance on `|μ| = 1`.
        stability_tolerance: f64,
    },
    /// A swept axis is malformed.
    #[error("need 1 ≤ N ≤ 10000 values and LO < HI, got {lo}..{hi}:{count}")]
    InvalidAxis {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
        /// Number of values.
        count: usize,
    },
    /// The operating point's start is unknown.
    #[error(transparent)]
    OperatingPoint(#[from] OperatingPointError),
    /// A swept parameter is not a parameter of the model.
    #[error(transparent)]
    Parameter(#[from] UnknownParameter),
    /// The forcing frequency is not positive.
    #[error(
        "the forcing frequency {parameter} = {frequency} must be positive (T = 2π/{parameter})"
    )]
    InvalidFrequency {
        /// The period parameter.
        parameter: String,
        /// Its value (rad/s).
        frequency: f64,
    },
    /// Newton found no equilibrium at `t = 0`.
    #[error(transparent)]
    Equilibrium(ModalError),
    /// The equilibrium does not hold over the period, or the monodromy failed.
    #[error(transparent)]
    Floquet(#[from] FloquetError),
}

/// Options of [`floquet_at_equilibrium`] and [`floquet_cell`].
#[derive(Debug, Clone, PartialEq)]
pub struct FloquetStudyOptions {
    /// Where Newton starts (default: the file's first named equilibrium, else `q = 0`).
    pub operating_point: OperatingPointOptions,
    /// The parameter that is the forcing frequency `w` (rad/s), `T = 2π/w` (default: `w`).
    pub period_parameter: String,
    /// DOP853's tolerances and the tolerance on `|μ| = 1` (defaults: 1e-12, 1e-12, 1e-6).
    pub floquet: FloquetOptions,
}

impl Default for FloquetStudyOptions {
    fn default() -> Self {
        Self {
            operating_point: OperatingPointOptions::default(),
            period_parameter: "w".to_string(),
            floquet: FloquetOptions::default(),
        }
    }
}

/// The Floquet analysis at one parameter set.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FloquetPoint {
    /// The equilibrium's name (from the start).
    pub name: String,
    /// The equilibrium `q*` (length `n`).
    pub q: Vec<f64>,
    /// The forcing frequency `w` (rad/s).
    pub frequency: f64,
    /// `max |F(q*, 0, t)|` over the period (units of the generalized forces).
    pub residual: f64,
    /// The monodromy matrix, multipliers, exponents, spectral radius and stability.
    pub floquet: FloquetAnalysis,
}

/// Checks the period parameter and the tolerances of `options` against `model`.
fn check_options(
    model: &dyn ModelInfo,
    options: &FloquetStudyOptions,
) -> Result<(), FloquetStudyError> {
    let name = &options.period_parameter;
    if !model.parameter_names().contains(&name.as_str()) {
        return Err(FloquetStudyError::UnknownPeriodParameter {
            model: model.name().to_string(),
            name: name.clone(),
            parameters: model.parameter_names().join(", "),
        });
    }
    let FloquetOptions {
        rtol,
        atol,
        stability_tolerance,
        ..
    } = options.floquet;
    let valid_tol = rtol.is_finite() && rtol > 0.0 && atol.is_finite() && atol > 0.0;
    if !(valid_tol && stability_tolerance.is_finite() && stability_tolerance >= 0.0) {
        return Err(FloquetStudyError::InvalidTolerance {
            rtol,
            stability_tolerance,
        });
    }
    Ok(())
}

/// The Floquet analysis of `model` about its equilibrium: Newton at `t = 0` from
/// `options.operating_point`, the check that it stays an equilibrium over the period, and the
/// monodromy matrix and multipliers there.
///
/// # Errors
/// [`FloquetStudyError::UnknownPeriodParameter`], [`FloquetStudyError::InvalidTolerance`],
/// [`FloquetStudyError::OperatingPoint`], [`FloquetStudyError::InvalidFrequency`],
/// [`FloquetStudyError::Equilibrium`], [`FloquetStudyError::Floquet`].
///
/// # Examples
/// The Mathieu pendulum upright without shaking (`a = 0`) is unstable with multipliers
/// `e^{±√(g/l) T}`, `T = 2π/w`.
/// ```
/// use eomgen_runtime::vibration::{FloquetStudyOptions, floquet_at_equilibrium};
/// let mut model = (eomgen::models::find("mathieu_pendulum").unwrap().make)();
/// model.set_parameter("a", 0.0)?;
/// let point = floquet_at_equilibrium(model.as_mut(), &FloquetStudyOptions::default())?;
/// let period = 2.0 * std::f64::consts::PI / 60.0;
/// let expected = (10f64.sqrt() * period).exp();
/// assert!((point.floquet.spectral_radius - expected).abs() < 1e-8 * expected);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # References
/// Lectures 19 and 21 (the Mathieu inverted pendulum); G. Floquet, Ann. Sci. ÉNS 12 (1883)
/// 47–88.
pub fn floquet_at_equilibrium(
    model: &mut dyn ModelInfo,
    options: &FloquetStudyOptions,
) -> Result<FloquetPoint, FloquetStudyError> {
    check_options(model, options)?;
    let (name, guess) = options.operating_point.start.resolve(model)?;
    analyse(model, name, &guess, options)
}

/// Equilibrium at `t = 0` from `guess`, the check that it stays one over the period, and the
/// Floquet analysis there.
fn analyse(
    model: &mut dyn ModelInfo,
    name: String,
    guess: &[f64],
    options: &FloquetStudyOptions,
) -> Result<FloquetPoint, FloquetStudyError> {
    let parameter = &options.period_parameter;
    let index = model
        .parameter_names()
        .iter()
        .position(|p| p == parameter)
        .ok_or_else(|| FloquetStudyError::UnknownPeriodParameter {
            model: model.name().to_string(),
            name: parameter.clone(),
            parameters: model.parameter_names().join(", "),
        })?;
    let frequency = model.parameter_values()[index];
    if !(frequency.is_finite() && frequency > 0.0) {
        return Err(FloquetStudyError::InvalidFrequency {
            parameter: parameter.clone(),
            frequency,
        });
    }
    let period = TAU / frequency;
    let equilibrium =
        find_equilibrium(model, guess, 0.0).map_err(FloquetStudyError::Equilibrium)?;
    let residual = check_periodic_equilibrium(model, &equilibrium.q, 0.0, period)?;
    let n = model.num_dofs();
    let y0: Vec<f64> = equilibrium
        .q
        .iter()
        .copied()
        .chain(std::iter::repeat_n(0.0, n))
        .collect();
    let floquet = floquet_analysis(model.as_ode_mut(), &y0, 0.0, period, &options.floquet)?;
    Ok(FloquetPoint {
        name,
        q: equilibrium.q,
        frequency,
        residual,
        floquet,
    })
}

/// One swept parameter of a stability chart.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepAxis {
    /// The parameter.
    pub name: String,
    /// Its values, ascending.
    pub values: Vec<f64>,
}

impl SweepAxis {
    /// `count` values evenly spaced from `lo` to `hi`, ends included (`lo` alone when
    /// `count = 1`).
    ///
    /// # Errors
    /// [`FloquetStudyError::InvalidAxis`] unless `1 ≤ count ≤ 10000` and, for `count > 1`,
    /// `lo < hi`.
    pub fn linear(name: &str, lo: f64, hi: f64, count: usize) -> Result<Self, FloquetStudyError> {
        if !(1..=10_000).contains(&count) || (count > 1 && hi <= lo) {
            return Err(FloquetStudyError::InvalidAxis { lo, hi, count });
        }
        let values = if count == 1 {
            vec![lo]
        } else {
            (0..count)
                .map(|k| lo + (hi - lo) * k as f64 / (count - 1) as f64)
                .collect()
        };
        Ok(Self {
            name: name.to_string(),
            values,
        })
    }
}

/// One cell of a stability chart: the spectral radius and the stability.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FloquetCell {
    /// `ρ = max |μ|`.
    pub spectral_radius: f64,
    /// Stable, marginal or unstable.
    pub stability: FloquetStability,
}

/// The Floquet analysis of `model` with the parameters `values` (`(name, value)` pairs) set,
/// from the equilibrium guess `guess` (resolved once for the chart with
/// [`EquilibriumStart::resolve`](super::EquilibriumStart::resolve)): one cell of a stability
/// chart. `model` keeps the values set.
///
/// # Errors
/// [`FloquetStudyError::Parameter`] for an unknown name, and those of
/// [`floquet_at_equilibrium`].
pub fn floquet_cell(
    model: &mut dyn ModelInfo,
    guess: &[f64],
    values: &[(&str, f64)],
    options: &FloquetStudyOptions,
) -> Result<FloquetCell, FloquetStudyError> {
    for (name, value) in values {
        model.set_parameter(name, *value)?;
    }
    let point = analyse(model, String::new(), guess, options)?;
    Ok(FloquetCell {
        spectral_radius: point.floquet.spectral_radius,
        stability: point.floquet.stability,
    })
}
