//! `eomgen study floquet` as library calls (issue 7, item 7; lectures 19 and 21): the Floquet
//! multipliers of a time-periodic model about an equilibrium that holds for every `t` of the
//! period, and one cell of a stability chart over two parameters.
//!
//! The period is `T = 2π/w` with `w` the value of the period parameter, which is checked
//! numerically to be the forcing frequency: `M` and `F` depend on `t` and are `T`-periodic at a
//! few states and times, both at `w` and at a value 1/64 above it (so a parameter that merely
//! equals the frequency, or a model with no time dependence, is refused); the operating point
//! is found by Newton at `t = 0` and checked to stay an equilibrium over the period
//! ([`check_periodic_equilibrium`], 65 times); the monodromy matrix comes from the variational
//! equations with the generated Jacobians ([`floquet_analysis`]). A chart repeats
//! [`floquet_cell`] over a grid of [`SweepAxis`] values; each cell is independent, so a
//! caller may run them in parallel, each on its own instance of the model.

use std::f64::consts::TAU;

use std::collections::BTreeMap;

use nalgebra::{Complex, DMatrix};
use serde::Serialize;

use super::operating_point::{OperatingPointError, OperatingPointOptions, PointSummary};
use crate::analysis::outcome::{RunTally, StudyRuns};
use crate::linear::modal::{ModalError, find_equilibrium};
use crate::linear::monodromy::{
    FloquetAnalysis, FloquetError, FloquetOptions, FloquetStability, check_periodic_equilibrium,
    floquet_analysis,
};
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
    /// DOP853's tolerances are not finite and positive. (A tolerance on `|μ| = 1` out of its
    /// range is [`FloquetError::InvalidStabilityTolerance`], in [`FloquetStudyError::Floquet`].)
    #[error(
        "the integration's tolerances must be finite and positive, got rtol = {rtol}, atol = {atol}"
    )]
    InvalidTolerance {
        /// DOP853's relative tolerance.
        rtol: f64,
        /// DOP853's absolute tolerance.
        atol: f64,
    },
    /// A swept axis is malformed.
    #[error("need 1 ≤ N ≤ 10000 values and finite LO < HI, got {lo}..{hi}:{count}")]
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
    /// The model's equations do not depend on `t`: there is no period to analyse (the
    /// multipliers would be `e^{λT}` of the modes for any `T`).
    #[error(
        "`{model}` does not depend on t, so it has no forcing period; its stability is that of its modes (eomgen modes)"
    )]
    TimeIndependent {
        /// The model.
        model: String,
    },
    /// The model is not `T`-periodic with `T = 2π/w` for the named parameter `w` (at its
    /// value, or at a value 1/64 above it: a parameter that only happens to equal the
    /// frequency is not the frequency).
    #[error(
        "`{model}` is not periodic with T = 2π/{parameter} = {period} s at {parameter} = {frequency}: M or F differs by {difference:.3e} between t = {t} s and t + T; the period parameter must be the forcing frequency (rad/s)"
    )]
    NotPeriodic {
        /// The model.
        model: String,
        /// The period parameter.
        parameter: String,
        /// The value tried (rad/s).
        frequency: f64,
        /// `T = 2π/frequency` (s).
        period: f64,
        /// The time of the largest difference (s).
        t: f64,
        /// The largest difference of `M` or `F`, relative to their size.
        difference: f64,
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

impl FloquetStudyOptions {
    /// The default parameter that holds the forcing frequency.
    pub const DEFAULT_PERIOD_PARAMETER: &'static str = "w";
}

impl Default for FloquetStudyOptions {
    fn default() -> Self {
        Self {
            operating_point: OperatingPointOptions::default(),
            period_parameter: Self::DEFAULT_PERIOD_PARAMETER.to_string(),
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
    /// Whether the equations depend on `t` at these parameters. Only the point that heads a
    /// chart ([`floquet_at_equilibrium_for_sweep`]) and a chart's cells may be independent
    /// of `t`; their multipliers are then those of the modes over `2π/w`.
    pub time_dependent: bool,
    /// The monodromy matrix, multipliers, exponents, spectral radius and stability.
    pub floquet: FloquetAnalysis,
}

/// Checks the period parameter and the tolerances of `options` against `model`.
fn check_options(
    model: &dyn ModelInfo,
    options: &FloquetStudyOptions,
) -> Result<(), FloquetStudyError> {
    let name = &options.period_parameter;
    if !model
        .description()
        .parameter_names()
        .contains(&name.as_str())
    {
        return Err(FloquetStudyError::UnknownPeriodParameter {
            model: model.description().name.to_string(),
            name: name.clone(),
            parameters: model.description().parameter_names().join(", "),
        });
    }
    let FloquetOptions { rtol, atol, .. } = options.floquet;
    if !(rtol.is_finite() && rtol > 0.0 && atol.is_finite() && atol > 0.0) {
        return Err(FloquetStudyError::InvalidTolerance { rtol, atol });
    }
    options.floquet.validate()?;
    Ok(())
}

/// The Floquet analysis of `model` about its equilibrium: Newton at `t = 0` from
/// `options.operating_point`, the check that it stays an equilibrium over the period, and the
/// monodromy matrix and multipliers there.
///
/// # Errors
/// [`FloquetStudyError::UnknownPeriodParameter`], [`FloquetStudyError::InvalidTolerance`],
/// [`FloquetStudyError::OperatingPoint`], [`FloquetStudyError::InvalidFrequency`],
/// [`FloquetStudyError::TimeIndependent`] and [`FloquetStudyError::NotPeriodic`] (the model
/// is checked numerically to be `2π/w`-periodic in `t` for the period parameter `w`, see the
/// module docs), [`FloquetStudyError::Equilibrium`], [`FloquetStudyError::Floquet`].
///
/// # Examples
/// A model whose equations do not depend on `t` has no forcing period, whatever parameter is
/// named; the Mathieu pendulum's upright equilibrium is analysed (its shaking makes it
/// stable at the file's values).
/// ```
/// use eomgen_runtime::analysis::vibration::{FloquetStudyError, FloquetStudyOptions, floquet_at_equilibrium};
/// let mut pendulum = (eomgen::models::find("double_pendulum").unwrap().make)();
/// let options = FloquetStudyOptions { period_parameter: "g".into(), ..Default::default() };
/// let refused = floquet_at_equilibrium(pendulum.as_mut(), &options);
/// assert!(matches!(refused, Err(FloquetStudyError::TimeIndependent { .. })));
///
/// let mut model = (eomgen::models::find("mathieu_pendulum").unwrap().make)();
/// let point = floquet_at_equilibrium(model.as_mut(), &FloquetStudyOptions::default())?;
/// assert!(point.floquet.spectral_radius <= 1.0 + 1e-6);
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
    let (name, guess) = options.operating_point.start.resolve_equilibrium(model)?;
    analyse(model, name, &guess, options, TimeDependence::Required)
}

/// Whether [`check_period_parameter`] refuses a model whose equations do not depend on `t`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TimeDependence {
    /// The analysis at the user's parameters: a model without time dependence is refused.
    Required,
    /// A cell of a chart: a parameter set without forcing (the Mathieu pendulum's `a = 0`
    /// column) is the chart's limit, analysed as it is.
    Allowed,
}

/// Equilibrium at `t = 0` from `guess`, the check that it stays one over the period, and the
/// Floquet analysis there.
fn analyse(
    model: &mut dyn ModelInfo,
    name: String,
    guess: &[f64],
    options: &FloquetStudyOptions,
    time_dependence: TimeDependence,
) -> Result<FloquetPoint, FloquetStudyError> {
    let parameter = &options.period_parameter;
    let index = model
        .description()
        .parameter_names()
        .iter()
        .position(|p| p == parameter)
        .ok_or_else(|| FloquetStudyError::UnknownPeriodParameter {
            model: model.description().name.to_string(),
            name: parameter.clone(),
            parameters: model.description().parameter_names().join(", "),
        })?;
    let frequency = model.parameter_values()[index];
    if !(frequency.is_finite() && frequency > 0.0) {
        return Err(FloquetStudyError::InvalidFrequency {
            parameter: parameter.clone(),
            frequency,
        });
    }
    let period = TAU / frequency;
    let time_dependent = check_period_parameter(model, index, guess, time_dependence)?;
    let equilibrium =
        find_equilibrium(model, guess, 0.0).map_err(FloquetStudyError::Equilibrium)?;
    let residual = check_periodic_equilibrium(model, &equilibrium.q, 0.0, period)?;
    let y0 = crate::linear::speeds::rest_state(model, &equilibrium.q, 0.0)
        .map_err(|e| FloquetStudyError::Equilibrium(e.into()))?;
    let floquet = floquet_analysis(model.as_ode_mut(), &y0, 0.0, period, &options.floquet)?;
    Ok(FloquetPoint {
        name,
        q: equilibrium.q,
        frequency,
        residual,
        time_dependent,
        floquet,
    })
}

/// Largest relative difference of `M` and `F` at the states `ys` between the times `t` and
/// `t + shift`, with the time of the largest: the largest absolute difference of any entry
/// over the largest magnitude of any entry of `M` and `F` over all the states and times (a
/// purely relative measure, so that a model in small units is judged as one in large units).
fn largest_change(model: &dyn ModelInfo, ys: &[Vec<f64>], times: &[f64], shift: f64) -> (f64, f64) {
    let (mut worst, mut at, mut scale) = (0.0f64, times[0], 0.0f64);
    for y in ys {
        for &t in times {
            let (m0, f0) = model.mass_matrix_and_forcing(t, y);
            let (m1, f1) = model.mass_matrix_and_forcing(t + shift, y);
            scale = scale
                .max(m0.amax())
                .max(f0.amax())
                .max(m1.amax())
                .max(f1.amax());
            let d = (m1 - m0).amax().max((f1 - f0).amax());
            let d = if d.is_nan() { f64::INFINITY } else { d };
            if d > worst {
                (worst, at) = (d, t);
            }
        }
    }
    (worst / scale.max(f64::MIN_POSITIVE), at)
}

/// The relative change of `M` or `F` the period checks accept as none: far above the
/// round-off of evaluating at `t + T` (~1e-15 relative for the bundled models' `cos(w t)`)
/// and far below the change a wrong period makes (of the order of the forcing amplitude).
const PERIOD_TOLERANCE: f64 = 1e-9;

/// Three states near `q` (the equilibrium guess, and it moved by up to 0.1 with rates up to
/// 0.2) at which the period checks evaluate `M` and `F`.
fn probe_states(model: &dyn ModelInfo, q: &[f64]) -> Vec<Vec<f64>> {
    let n = model.num_dofs();
    [(0.0, 0.0), (0.1, 0.2), (-0.07, -0.13)]
        .iter()
        .map(|&(dq, dv)| {
            let mut y: Vec<f64> = q
                .iter()
                .copied()
                .chain(std::iter::repeat_n(0.0, n))
                .collect();
            for i in 0..n {
                let sign = if i % 2 == 0 { 1.0 } else { -0.6 };
                y[i] += dq * sign;
                y[n + i] = dv * sign;
            }
            y
        })
        .collect()
}

/// Whether `M` or `F` changes with `t` at the states `ys`, for the forcing frequency
/// `frequency`: across two shifts that are irrational-looking fractions of the period `2π/w`
/// (a quarter and a third would be whole periods of a forcing at 12 times the named
/// "frequency"), from seven times in a period.
fn depends_on_time(model: &dyn ModelInfo, ys: &[Vec<f64>], frequency: f64) -> bool {
    let period = TAU / frequency;
    let times: Vec<f64> = (0..7)
        .map(|k| 0.137 * period + f64::from(k) * period / 7.0)
        .collect();
    let varies = largest_change(model, ys, &times, 0.271_828 * period)
        .0
        .max(largest_change(model, ys, &times, 0.414_214 * period).0);
    varies > PERIOD_TOLERANCE
}

/// Checks numerically that the parameter at `index` is the forcing frequency `w` of
/// `model`: its equations `M(q, t)`, `F(q, q̇, t)` depend on `t` (where `time_dependence`
/// requires it), and are `2π/w`-periodic at three states near `q` ([`probe_states`]) and
/// seven times in the period, both at `w` and at `w (1 + 1/64)` (then restored), to a
/// relative difference of [`PERIOD_TOLERANCE`]. Returns whether they depend on `t`.
fn check_period_parameter(
    model: &mut dyn ModelInfo,
    index: usize,
    q: &[f64],
    time_dependence: TimeDependence,
) -> Result<bool, FloquetStudyError> {
    let ys = probe_states(model, q);
    let name = model.description().parameters[index].name.to_string();
    let frequency = model.parameter_values()[index];
    let time_dependent = depends_on_time(model, &ys, frequency);
    if !time_dependent && time_dependence == TimeDependence::Required {
        return Err(FloquetStudyError::TimeIndependent {
            model: model.description().name.to_string(),
        });
    }
    let perturbed = frequency * (1.0 + 1.0 / 64.0);
    for w in [frequency, perturbed] {
        model.set_parameter(&name, w)?;
        let period = TAU / w;
        let times: Vec<f64> = (0..7)
            .map(|k| 0.137 * period + f64::from(k) * period / 7.0)
            .collect();
        let (difference, t) = largest_change(model, &ys, &times, period);
        if difference > PERIOD_TOLERANCE {
            model.set_parameter(&name, frequency)?;
            return Err(FloquetStudyError::NotPeriodic {
                model: model.description().name.to_string(),
                parameter: name,
                frequency: w,
                period,
                t,
                difference,
            });
        }
    }
    model.set_parameter(&name, frequency)?;
    Ok(time_dependent)
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
    /// [`FloquetStudyError::InvalidAxis`] unless `1 ≤ count ≤ 10000`, `lo` and `hi` are
    /// finite and, for `count > 1`, `lo < hi`.
    pub fn linear(name: &str, lo: f64, hi: f64, count: usize) -> Result<Self, FloquetStudyError> {
        if !(1..=10_000).contains(&count)
            || !lo.is_finite()
            || !hi.is_finite()
            || (count > 1 && hi <= lo)
        {
            return Err(FloquetStudyError::InvalidAxis { lo, hi, count });
        }
        let values = if count == 1 {
            vec![lo]
        } else {
            (0..count)
                .map(|k| {
                    let v = lo + (hi - lo) * k as f64 / (count - 1) as f64;
                    // Near the largest numbers `hi − lo` or its product overflows (`0..1e308`
                    // gave inf and NaN values): the weighted mean cannot.
                    if v.is_finite() {
                        v
                    } else {
                        let f = k as f64 / (count - 1) as f64;
                        lo * (1.0 - f) + hi * f
                    }
                })
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
/// [`floquet_at_equilibrium`] except [`FloquetStudyError::TimeIndependent`]: a cell whose
/// parameters switch the forcing off (the Mathieu pendulum's `a = 0`) is analysed, its
/// multipliers those of the modes over the period `2π/w`.
pub fn floquet_cell(
    model: &mut dyn ModelInfo,
    guess: &[f64],
    values: &[(&str, f64)],
    options: &FloquetStudyOptions,
) -> Result<FloquetCell, FloquetStudyError> {
    for (name, value) in values {
        model.set_parameter(name, *value)?;
    }
    let point = analyse(
        model,
        String::new(),
        guess,
        options,
        TimeDependence::Allowed,
    )?;
    Ok(FloquetCell {
        spectral_radius: point.floquet.spectral_radius,
        stability: point.floquet.stability,
    })
}

/// The Floquet analysis at the model's own parameters that heads a stability chart over
/// `axes`: as [`floquet_at_equilibrium`], except that the model need not depend on `t` at
/// its own parameters when it does at swept values (the Mathieu pendulum at `a = 0`, swept
/// over `a = 0..0.6`). The time dependence is checked at the corners and the centre of the
/// grid and the middles of its sides (3 × 3 points, the other parameters as set); the point
/// itself is then analysed as a cell is, and says whether it depends on `t`
/// ([`FloquetPoint::time_dependent`]). `model` keeps its own parameter values.
///
/// # Errors
/// Those of [`floquet_at_equilibrium`], [`FloquetStudyError::TimeIndependent`] only when the
/// model depends on `t` at none of the 3 × 3 points, and [`FloquetStudyError::Parameter`]
/// for an axis that is not a parameter of the model.
///
/// # Examples
/// The Mathieu pendulum without shaking (`a = 0`) has no period, but a chart over `a` has:
/// ```
/// use eomgen_runtime::analysis::vibration::{
///     FloquetStudyError, FloquetStudyOptions, SweepAxis, floquet_at_equilibrium,
///     floquet_at_equilibrium_for_sweep,
/// };
/// let mut model = (eomgen::models::find("mathieu_pendulum").unwrap().make)();
/// model.set_parameter("a", 0.0)?;
/// let options = FloquetStudyOptions::default();
/// assert!(matches!(
///     floquet_at_equilibrium(model.as_mut(), &options),
///     Err(FloquetStudyError::TimeIndependent { .. })
/// ));
/// let a = SweepAxis::linear("a", 0.0, 0.3, 31)?;
/// let w = SweepAxis::linear("w", 10.0, 100.0, 31)?;
/// let point = floquet_at_equilibrium_for_sweep(model.as_mut(), &options, [&a, &w])?;
/// assert!(!point.time_dependent);
/// let flat = SweepAxis::linear("a", 0.0, 0.0, 1)?;
/// assert!(matches!(
///     floquet_at_equilibrium_for_sweep(model.as_mut(), &options, [&flat, &w]),
///     Err(FloquetStudyError::TimeIndependent { .. })
/// ));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn floquet_at_equilibrium_for_sweep(
    model: &mut dyn ModelInfo,
    options: &FloquetStudyOptions,
    axes: [&SweepAxis; 2],
) -> Result<FloquetPoint, FloquetStudyError> {
    check_options(model, options)?;
    let (name, guess) = options.operating_point.start.resolve_equilibrium(model)?;
    let ys = probe_states(model, &guess);
    let names: Vec<String> = model
        .description()
        .parameter_names()
        .iter()
        .map(|n| n.to_string())
        .collect();
    let index = |p: &str| names.iter().position(|n| n == p);
    let period_index = index(&options.period_parameter);
    let own: Vec<(String, f64)> = axes
        .iter()
        .map(|a| {
            let i = index(&a.name).ok_or_else(|| UnknownParameter {
                model: model.description().name.to_string(),
                name: a.name.clone(),
                known: names.join(", "),
            })?;
            Ok((a.name.clone(), model.parameter_values()[i]))
        })
        .collect::<Result<_, FloquetStudyError>>()?;
    let three = |a: &SweepAxis| -> Vec<f64> {
        let v = &a.values;
        vec![v[0], v[v.len() / 2], v[v.len() - 1]]
    };
    let mut found = false;
    'grid: for x in three(axes[0]) {
        for y in three(axes[1]) {
            model.set_parameter(&axes[0].name, x)?;
            model.set_parameter(&axes[1].name, y)?;
            let frequency = period_index.map_or(f64::NAN, |i| model.parameter_values()[i]);
            if frequency.is_finite() && frequency > 0.0 && depends_on_time(model, &ys, frequency) {
                found = true;
                break 'grid;
            }
        }
    }
    for (name, value) in &own {
        model.set_parameter(name, *value)?;
    }
    let time_dependence = if found {
        TimeDependence::Allowed
    } else {
        TimeDependence::Required
    };
    analyse(model, name, &guess, options, time_dependence)
}

/// A stability chart: the Floquet analysis ([`floquet_cell`]) at every point of a grid over
/// two parameters, or why it failed there.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FloquetChart {
    /// The x axis.
    pub x: SweepAxis,
    /// The y axis.
    pub y: SweepAxis,
    /// `cells[i][j]` at `(x.values[i], y.values[j])`: the cell, or the failure's text.
    pub cells: Vec<Vec<Result<FloquetCell, String>>>,
}

/// Every cell is a run; a failed one is counted with its parameters and reason.
impl StudyRuns for FloquetChart {
    fn study(&self) -> &'static str {
        "floquet --sweep"
    }

    fn tally(&self) -> RunTally {
        let mut tally = RunTally::default();
        for (i, column) in self.cells.iter().enumerate() {
            for (j, cell) in column.iter().enumerate() {
                tally.add(cell.as_ref().err().map(|e| {
                    format!(
                        "{} = {}, {} = {}: {e}",
                        self.x.name, self.x.values[i], self.y.name, self.y.values[j]
                    )
                }));
            }
        }
        tally
    }
}

impl FloquetPoint {
    /// The analysis as `eomgen study floquet --json` prints it ([`FloquetSummary`]): `model`
    /// is the model analysed (for its names), `options` those of the analysis, `predictions`
    /// what the model file's references predict at this point, `sweep` the stability chart
    /// when one was computed.
    pub fn summary(
        &self,
        model: &dyn ModelInfo,
        options: &FloquetStudyOptions,
        predictions: Vec<PredictionSummary>,
        sweep: Option<&FloquetChart>,
    ) -> FloquetSummary {
        let f = &self.floquet;
        let coordinates: Vec<String> = model
            .description()
            .coordinate_names()
            .iter()
            .map(|c| c.to_string())
            .collect();
        FloquetSummary {
            model: model.description().name.to_string(),
            operating_point: PointSummary {
                max_forcing_residual: Some(self.residual),
                ..PointSummary::new(&self.name, &coordinates, &self.q)
            },
            coordinates,
            period_parameter: options.period_parameter.clone(),
            frequency: self.frequency,
            period: f.period,
            monodromy_matrix: f.monodromy_matrix.clone(),
            multipliers: f
                .multipliers
                .iter()
                .map(|c| MultiplierSummary {
                    re: c.re,
                    im: c.im,
                    modulus: c.norm(),
                })
                .collect(),
            exponents: f.exponents.clone(),
            spectral_radius: f.spectral_radius,
            determinant: f.determinant,
            stability: f.stability.as_str(),
            stable: f.stability.is_stable(),
            stability_tolerance: options.floquet.stability_tolerance,
            closure_error: f.closure_error,
            integration: FloquetIntegrationSummary {
                method: "dop853",
                tol: options.floquet.rtol,
                steps: f.stats.steps,
                rhs_evals: f.stats.rhs_evals,
            },
            predictions: predictions
                .into_iter()
                .map(|p| (p.name.clone(), p))
                .collect(),
            time_dependent: self.time_dependent,
            sweep: sweep.map(FloquetChart::summary),
        }
    }
}

/// A [`FloquetPoint`] as `eomgen study floquet --json` prints it ([`FloquetPoint::summary`]),
/// with each prediction of the model file's references under its own name and the stability
/// chart under `sweep` (left out without one).
///
/// # Shapes
/// `n` coordinates: `monodromy_matrix` `2n × 2n` as rows, `multipliers` and `exponents` `2n`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FloquetSummary {
    /// The model's name.
    pub model: String,
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// The equilibrium, with `max_forcing_residual` (`max |F(q*, 0, t)|` over the period).
    pub operating_point: PointSummary,
    /// The parameter that is the forcing frequency.
    pub period_parameter: String,
    /// The forcing frequency `w` (rad/s).
    pub frequency: f64,
    /// `T = 2π/w` (s).
    pub period: f64,
    /// `Φ(T)`, as rows.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub monodromy_matrix: DMatrix<f64>,
    /// The multipliers `μ` with their moduli.
    pub multipliers: Vec<MultiplierSummary>,
    /// The exponents `ln(μ)/T` (1/s), each `{"re", "im"}`.
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub exponents: Vec<Complex<f64>>,
    /// `ρ = max |μ|`.
    pub spectral_radius: f64,
    /// `det Φ(T)`.
    pub determinant: f64,
    /// [`FloquetStability::as_str`].
    pub stability: &'static str,
    /// [`FloquetStability::is_stable`].
    pub stable: bool,
    /// The tolerance on `|μ| = 1`.
    pub stability_tolerance: f64,
    /// [`FloquetAnalysis::closure_error`].
    pub closure_error: f64,
    /// How the period was integrated.
    pub integration: FloquetIntegrationSummary,
    /// The predictions by name (each a key of the summary).
    #[serde(flatten)]
    pub predictions: BTreeMap<String, PredictionSummary>,
    /// [`FloquetPoint::time_dependent`].
    pub time_dependent: bool,
    /// The stability chart (left out without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sweep: Option<FloquetChartSummary>,
}

/// A Floquet multiplier `μ` as `{"re", "im", "modulus"}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MultiplierSummary {
    /// `Re μ`.
    pub re: f64,
    /// `Im μ`.
    pub im: f64,
    /// `|μ|`.
    pub modulus: f64,
}

/// How a [`FloquetSummary`]'s period was integrated.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FloquetIntegrationSummary {
    /// The integrator (`"dop853"`).
    pub method: &'static str,
    /// Its relative and absolute tolerance.
    pub tol: f64,
    /// Accepted steps.
    pub steps: usize,
    /// Right-hand-side evaluations.
    pub rhs_evals: usize,
}

/// A stability prediction at the analysed point, serialised as an object with three keys
/// named after it: `{KEY: value, "critical_KEY": critical, "predicts_stable_EQUILIBRIUM":
/// predicts_stable}`.
#[derive(Debug, Clone, PartialEq)]
pub struct PredictionSummary {
    /// Its name (`kapitza`): its key in the [`FloquetSummary`].
    pub name: String,
    /// The value's key (`a_w`).
    pub key: String,
    /// The value.
    pub value: f64,
    /// The critical value.
    pub critical: f64,
    /// The equilibrium's name (`upright`).
    pub equilibrium: String,
    /// Whether the prediction says stable (`value > critical`).
    pub predicts_stable: bool,
}

impl Serialize for PredictionSummary {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap as _;
        let mut map = s.serialize_map(Some(3))?;
        map.serialize_entry(&self.key, &self.value)?;
        map.serialize_entry(&format!("critical_{}", self.key), &self.critical)?;
        map.serialize_entry(
            &format!("predicts_stable_{}", self.equilibrium),
            &self.predicts_stable,
        )?;
        map.end()
    }
}

impl FloquetChart {
    /// The chart as `eomgen study floquet --sweep … --json` prints it ([`FloquetChartSummary`]).
    pub fn summary(&self) -> FloquetChartSummary {
        let (x, y) = (&self.x, &self.y);
        let mut failures = Vec::new();
        for (i, column) in self.cells.iter().enumerate() {
            for (j, cell) in column.iter().enumerate() {
                if let Err(e) = cell {
                    failures.push(FailedCell {
                        x: (x.name.clone(), x.values[i]),
                        y: (y.name.clone(), y.values[j]),
                        error: e.clone(),
                    });
                }
            }
        }
        let grid = |f: &dyn Fn(&FloquetCell) -> f64| -> Vec<Vec<Option<f64>>> {
            self.cells
                .iter()
                .map(|column| column.iter().map(|c| c.as_ref().ok().map(f)).collect())
                .collect()
        };
        FloquetChartSummary {
            x: x.clone(),
            y: y.clone(),
            layout: "spectral_radius[i][j] and stability[i][j] at (x[i], y[j]); null where the analysis failed",
            spectral_radius: grid(&|c| c.spectral_radius),
            stability: self
                .cells
                .iter()
                .map(|column| {
                    column
                        .iter()
                        .map(|c| c.as_ref().ok().map(|c| c.stability.as_str()))
                        .collect()
                })
                .collect(),
            stable_points: self
                .cells
                .iter()
                .flatten()
                .filter(|c| matches!(c, Ok(c) if c.stability.is_stable()))
                .count(),
            failures,
        }
    }
}

/// A [`FloquetChart`] as `eomgen study floquet --sweep … --json` prints it.
///
/// # Shapes
/// `spectral_radius` and `stability` are `len(x.values) × len(y.values)`, `[i][j]` at
/// `(x.values[i], y.values[j])`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FloquetChartSummary {
    /// The x axis.
    pub x: SweepAxis,
    /// The y axis.
    pub y: SweepAxis,
    /// The grids' layout, in words.
    pub layout: &'static str,
    /// `ρ` at every cell (null where the analysis failed).
    pub spectral_radius: Vec<Vec<Option<f64>>>,
    /// [`FloquetStability::as_str`] at every cell (null where the analysis failed).
    pub stability: Vec<Vec<Option<&'static str>>>,
    /// The number of stable cells.
    pub stable_points: usize,
    /// The failed cells.
    pub failures: Vec<FailedCell>,
}

/// A failed cell of a [`FloquetChartSummary`], serialised as `{X: x, Y: y, "error":
/// message}` with the axes' parameter names as keys.
#[derive(Debug, Clone, PartialEq)]
pub struct FailedCell {
    /// The x parameter's name and value.
    pub x: (String, f64),
    /// The y parameter's name and value.
    pub y: (String, f64),
    /// Why the analysis failed there.
    pub error: String,
}

impl Serialize for FailedCell {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap as _;
        let mut map = s.serialize_map(Some(3))?;
        map.serialize_entry(&self.x.0, &self.x.1)?;
        map.serialize_entry(&self.y.0, &self.y.1)?;
        map.serialize_entry("error", &self.error)?;
        map.end()
    }
}
