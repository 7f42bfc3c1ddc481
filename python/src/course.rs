//! The course's studies from Python (`eomgen study rayleigh`, `convolution`, `launch`,
//! `periodic-orbit`, `rolling-contact`, `expm` and `eomgen reduce`): each one library call
//! with its options from keyword arguments (the command line's defaults where one is not
//! given), its report as the command line's `--json` prints it, with numeric lists as numpy
//! arrays (`reduce`'s as plain lists).
//!
//! The command line parses expressions in some options (`--shape`, `--forcing`, `--period`,
//! `--shape-angle`); here those take numbers, or the same expression text, evaluated by the
//! library's [`eomgen::expressions`] against this model's parameter values.

use std::cell::RefCell;

use eomgen::ModelInfo;
use eomgen::analysis::StudyRuns;
use eomgen::analysis::launch::{LaunchError, LaunchOptions, launch_study};
use eomgen::analysis::rolling_contact::{RollingContactOptions, rolling_contact};
use eomgen::analysis::vibration::{
    self, ConvolutionOptions, ExpmOptions, Forcing, OperatingPointOptions, RayleighOptions,
};
use eomgen::analysis::{GaitOptions, PeriodicOrbitOptions, gait, periodic_orbit};
use eomgen::expressions::{TimeFunction, evaluate, parameter_lookup, split_list};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::{Lists, to_python};
use crate::errors::{analysis_error, model_error, parameter_error};
use crate::model::{CoreModel, equilibrium_start, finite};

/// Registers the course's studies.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(study_rayleigh, m)?)?;
    m.add_function(wrap_pyfunction!(study_convolution, m)?)?;
    m.add_function(wrap_pyfunction!(study_launch, m)?)?;
    m.add_function(wrap_pyfunction!(study_periodic_orbit, m)?)?;
    m.add_function(wrap_pyfunction!(study_rolling_contact, m)?)?;
    m.add_function(wrap_pyfunction!(study_expm, m)?)?;
    m.add_function(wrap_pyfunction!(reduce_model, m)?)?;
    Ok(())
}

/// The operating point at `at` (`None`, a name or coordinates), `t = 0`.
fn point(at: Option<&Bound<'_, PyAny>>) -> PyResult<OperatingPointOptions> {
    Ok(OperatingPointOptions {
        start: equilibrium_start(at, None)?,
        ..OperatingPointOptions::default()
    })
}

/// An expression of `model`'s parameters (and of what `extra` names) as a number, or a
/// `ValueError` that names the argument.
fn expression(
    model: &dyn ModelInfo,
    text: &str,
    what: &str,
    extra: &dyn Fn(&str) -> Option<f64>,
) -> PyResult<f64> {
    let parameters = parameter_lookup(model);
    let lookup = |name: &str| extra(name).or_else(|| parameters(name));
    evaluate(text, what, &lookup).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// A number, or an expression of `model`'s parameters as text.
fn number_or_expression(
    model: &dyn ModelInfo,
    value: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<f64> {
    if let Ok(text) = value.extract::<String>() {
        return expression(model, &text, what, &|_| None);
    }
    value.extract::<f64>()
}

/// The trial shape of `study rayleigh`: one number per coordinate, or the command line's
/// text (entries comma separated, or one expression of the 1-based index `i` and `n`).
fn rayleigh_shape(model: &dyn ModelInfo, shape: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let Ok(text) = shape.extract::<String>() else {
        return shape.extract::<Vec<f64>>();
    };
    let items = split_list(&text);
    if items.len() > 1 {
        return items
            .iter()
            .enumerate()
            .map(|(k, item)| expression(model, item, &format!("shape entry {}", k + 1), &|_| None))
            .collect();
    }
    let Some(text) = items.first() else {
        return Err(PyValueError::new_err(
            "shape is empty: give one value per coordinate, or an expression of i and n",
        ));
    };
    let n = model.num_dofs();
    (1..=n)
        .map(|i| {
            let index = move |name: &str| match name {
                "i" => Some(i as f64),
                "n" => Some(n as f64),
                _ => None,
            };
            expression(model, text, &format!("shape at i = {i}"), &index)
        })
        .collect()
}

/// The Rayleigh quotient of a trial shape at an equilibrium against the lowest natural
/// frequency, with its stationarity (`eomgen study rayleigh`).
#[pyfunction]
#[pyo3(signature = (model, shape, at = None, perturbations = None))]
fn study_rayleigh<'py>(
    py: Python<'py>,
    model: &CoreModel,
    shape: &Bound<'py, PyAny>,
    at: Option<&Bound<'py, PyAny>>,
    perturbations: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut instance = model.fresh()?;
    let mut options = RayleighOptions::new(rayleigh_shape(instance.as_ref(), shape)?);
    options.operating_point = point(at)?;
    if let Some(p) = perturbations {
        options.perturbations = p;
    }
    let name = instance.description().name.to_string();
    let model_ref = &mut instance;
    let study = py
        .detach(move || vibration::rayleigh_study(model_ref.as_ref(), &options))
        .map_err(|e| analysis_error(format!("`{name}`: {e}")))?;
    to_python(py, &study.summary(instance.as_ref()), Lists::Arrays)
}

/// The response to an impulse, a step or a function of time through one input by Duhamel's
/// integral, against DOP853 and the closed form (`eomgen study convolution`). `forcing` is
/// `"impulse"`, `"step"`, an expression of `t` and the parameters, or a Python callable of
/// `t` (called with the interpreter held).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (model, input, forcing, at = None, t_end = None, intervals = None, rtol = None, label = None))]
fn study_convolution<'py>(
    py: Python<'py>,
    model: &CoreModel,
    input: String,
    forcing: &Bound<'py, PyAny>,
    at: Option<&Bound<'py, PyAny>>,
    t_end: Option<f64>,
    intervals: Option<usize>,
    rtol: Option<f64>,
    label: Option<String>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut instance = model.fresh()?;
    let operating_point = point(at)?;
    let intervals = intervals.unwrap_or(ConvolutionOptions::DEFAULT_INTERVALS);
    let rtol = rtol.unwrap_or(ConvolutionOptions::DEFAULT_RTOL);
    let base = ConvolutionBase {
        operating_point,
        input,
        t_end,
        intervals,
        rtol,
    };
    let name = instance.description().name.to_string();
    let failure = |e: vibration::ConvolutionError| analysis_error(format!("`{name}`: {e}"));
    if let Ok(text) = forcing.extract::<String>() {
        let time_function = TimeFunction::parse(&text, "forcing", instance.as_ref())
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let model_ref = &mut instance;
        let study = py
            .detach(move || {
                time_function.with_forcing(|forcing| {
                    vibration::convolution_response(
                        model_ref.as_mut(),
                        &with_forcing(&base, forcing),
                    )
                })
            })
            .map_err(failure)?;
        return to_python(py, &study, Lists::Arrays);
    }
    if !forcing.is_callable() {
        return Err(PyValueError::new_err(
            "forcing must be `impulse`, `step`, an expression of t, or a callable f(t)",
        ));
    }
    // A Python function: called with the interpreter held; its first exception is raised
    // instead of the library's error about the value it did not give.
    let raised: RefCell<Option<PyErr>> = RefCell::new(None);
    let function = |t: f64| -> f64 {
        if raised.borrow().is_some() {
            return f64::NAN;
        }
        match forcing.call1((t,)).and_then(|v| v.extract::<f64>()) {
            Ok(v) => v,
            Err(e) => {
                *raised.borrow_mut() = Some(e);
                f64::NAN
            }
        }
    };
    let label = match label {
        Some(l) => l,
        None => forcing
            .getattr("__name__")
            .and_then(|n| n.extract::<String>())
            .unwrap_or_else(|_| "f(t)".to_string()),
    };
    let result = vibration::convolution_response(
        instance.as_mut(),
        &with_forcing(
            &base,
            Forcing::Function {
                label: &label,
                f: &function,
            },
        ),
    );
    if let Some(e) = raised.into_inner() {
        return Err(e);
    }
    to_python(py, &result.map_err(failure)?, Lists::Arrays)
}

/// The options of `study_convolution` but the forcing (which borrows what it calls).
struct ConvolutionBase {
    operating_point: OperatingPointOptions,
    input: String,
    t_end: Option<f64>,
    intervals: usize,
    rtol: f64,
}

/// `base` with `forcing`.
fn with_forcing<'a>(base: &ConvolutionBase, forcing: Forcing<'a>) -> ConvolutionOptions<'a> {
    ConvolutionOptions {
        operating_point: base.operating_point.clone(),
        input: base.input.clone(),
        forcing,
        t_end: base.t_end,
        intervals: base.intervals,
        rtol: base.rtol,
    }
}

/// The range against the launch angle at each speed, the best angle by golden-section search
/// and the best path (`eomgen study launch`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (model, speeds = Vec::new(), angle_parameter = None, speed_parameter = None, event = None, range_coordinate = None, height_coordinate = None, angles = None, angle_tol = None, rtol = None, t_max = None, path_samples = None, shape_angle = None))]
fn study_launch<'py>(
    py: Python<'py>,
    model: &CoreModel,
    speeds: Vec<f64>,
    angle_parameter: Option<String>,
    speed_parameter: Option<String>,
    event: Option<String>,
    range_coordinate: Option<String>,
    height_coordinate: Option<String>,
    angles: Option<usize>,
    angle_tol: Option<f64>,
    rtol: Option<f64>,
    t_max: Option<f64>,
    path_samples: Option<usize>,
    shape_angle: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut instance = model.fresh()?;
    let d = LaunchOptions::default();
    let shape_angle = match shape_angle {
        None => None,
        Some(a) => Some(number_or_expression(instance.as_ref(), a, "shape_angle")?),
    };
    let options = LaunchOptions {
        speeds,
        angle_parameter: angle_parameter.unwrap_or(d.angle_parameter),
        speed_parameter: speed_parameter.unwrap_or(d.speed_parameter),
        event: event.unwrap_or(d.event),
        range_coordinate: range_coordinate.unwrap_or(d.range_coordinate),
        height_coordinate: height_coordinate.unwrap_or(d.height_coordinate),
        angles: angles.unwrap_or(d.angles),
        angle_tol: angle_tol.unwrap_or(d.angle_tol),
        rtol: rtol.unwrap_or(d.rtol),
        t_max: t_max.unwrap_or(d.t_max),
        path_samples: path_samples.unwrap_or(d.path_samples),
        shape_angle,
    };
    let name = instance.description().name.to_string();
    let model_ref = &mut instance;
    let study = py
        .detach(move || launch_study(model_ref.as_mut(), &options))
        .map_err(|e| match e {
            e @ LaunchError::UnknownParameter { .. } => parameter_error(e),
            e => analysis_error(format!("`{name}`: {e}")),
        })?;
    study.check_measured().map_err(analysis_error)?;
    to_python(py, &study, Lists::Arrays)
}

/// The period from the model file's `checks:` (`period:`, else the time of `final_state:`),
/// as `study periodic-orbit` takes it without `--period`.
fn model_period(model: &dyn ModelInfo) -> PyResult<f64> {
    let checks = &model.description().checks;
    if let Some(check) = &checks.period {
        return expression(model, &check.value, "the file's `checks: period:`", &|_| {
            None
        });
    }
    if let Some(check) = &checks.final_state {
        return expression(
            model,
            &check.t,
            "the file's `checks: final_state: t:`",
            &|_| None,
        );
    }
    Err(PyValueError::new_err(format!(
        "`{}` gives no period in its `checks:` (`period:` or `final_state:`): give a guess with period=T",
        model.description().name
    )))
}

/// A periodic orbit by shooting with its period, residual, Newton iterations and Floquet
/// multipliers (`eomgen study periodic-orbit`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (model, start = None, period = None, fix_period = false, energy = None, tol = None, max_iterations = None, integration_tol = None, samples = None, unit_multiplier_tolerance = None, steps = 1))]
fn study_periodic_orbit<'py>(
    py: Python<'py>,
    model: &CoreModel,
    start: Option<Vec<f64>>,
    period: Option<&Bound<'py, PyAny>>,
    fix_period: bool,
    energy: Option<&Bound<'py, PyAny>>,
    tol: Option<f64>,
    max_iterations: Option<usize>,
    integration_tol: Option<f64>,
    samples: Option<usize>,
    unit_multiplier_tolerance: Option<f64>,
    steps: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let mut instance = model.fresh()?;
    let initial = instance.initial_state();
    if !instance.description().supports.is_empty() {
        // A gait: the fixed point of the return map through `steps` landings.
        if period.is_some() || fix_period || energy.is_some() {
            return Err(PyValueError::new_err(
                "period, fix_period and energy do not apply to a gait: its period is the time of its steps",
            ));
        }
        if integration_tol.is_some() || samples.is_some() || unit_multiplier_tolerance.is_some() {
            return Err(PyValueError::new_err(
                "integration_tol, samples and unit_multiplier_tolerance do not apply to a gait (its integration is DOP853 at 1e-12, and it has no trivial multipliers to count)",
            ));
        }
        let defaults = GaitOptions::default();
        let options = GaitOptions {
            start: Some(match start {
                Some(y) if y.len() == initial.len() => finite("start", &y)?.to_vec(),
                Some(y) => {
                    return Err(PyValueError::new_err(format!(
                        "the start must have {} entries ([q; q̇]), got {}",
                        initial.len(),
                        y.len()
                    )));
                }
                None => initial,
            }),
            steps,
            tol: tol.unwrap_or(defaults.tol),
            max_iterations: max_iterations.unwrap_or(defaults.max_iterations),
            ..defaults
        };
        let name = instance.description().name.to_string();
        let model_ref = &mut instance;
        let found = py
            .detach(move || gait(model_ref.as_mut(), &options))
            .map_err(|e| analysis_error(format!("`{name}`: {e}")))?;
        return to_python(py, &found, Lists::Arrays);
    }
    let start = match start {
        Some(y) if y.len() != initial.len() => {
            return Err(PyValueError::new_err(format!(
                "the start must have {} entries ([q; q̇]), got {}",
                initial.len(),
                y.len()
            )));
        }
        Some(y) => finite("start", &y)?.to_vec(),
        None => initial.clone(),
    };
    let period = match period {
        Some(p) => number_or_expression(instance.as_ref(), p, "period")?,
        None => model_period(instance.as_ref())?,
    };
    let energy = match energy {
        None => instance.energy(0.0, &initial),
        Some(e) if e.extract::<String>().is_ok_and(|s| s.trim() == "start") => {
            instance.energy(0.0, &start)
        }
        Some(e) => number_or_expression(instance.as_ref(), e, "energy")?,
    };
    let defaults = PeriodicOrbitOptions::new(period);
    let options = PeriodicOrbitOptions {
        start: Some(start),
        fix_period,
        energy: Some(energy),
        tol: tol.unwrap_or(defaults.tol),
        max_iterations: max_iterations.unwrap_or(defaults.max_iterations),
        integration_tol: integration_tol.unwrap_or(defaults.integration_tol),
        samples: samples.unwrap_or(defaults.samples),
        unit_multiplier_tolerance: unit_multiplier_tolerance
            .unwrap_or(defaults.unit_multiplier_tolerance),
        ..defaults
    };
    let name = instance.description().name.to_string();
    let model_ref = &mut instance;
    let orbit = py
        .detach(move || periodic_orbit(model_ref.as_mut(), &options))
        .map_err(|e| analysis_error(format!("`{name}`: {e}")))?;
    to_python(py, &orbit, Lists::Arrays)
}

/// The friction a rolling body needs up to the lift-off, and the flight after it
/// (`eomgen study rolling-contact`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (model, flight = None, mu = None, ground = None, normal = None, angle = None, lift_off = None, landing = None, samples = None, t_end = None, rtol = None))]
fn study_rolling_contact<'py>(
    py: Python<'py>,
    model: &CoreModel,
    flight: Option<&CoreModel>,
    mu: Option<Vec<f64>>,
    ground: Option<String>,
    normal: Option<String>,
    angle: Option<String>,
    lift_off: Option<String>,
    landing: Option<String>,
    samples: Option<usize>,
    t_end: Option<f64>,
    rtol: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let d = RollingContactOptions::default();
    let options = RollingContactOptions {
        ground: ground.unwrap_or(d.ground),
        normal: normal.unwrap_or(d.normal),
        angle: angle.unwrap_or(d.angle),
        lift_off: lift_off.unwrap_or(d.lift_off),
        landing: landing.unwrap_or(d.landing),
        thresholds: mu.unwrap_or(d.thresholds),
        samples: samples.unwrap_or(d.samples),
        t_end: t_end.unwrap_or(d.t_end),
        rtol: rtol.unwrap_or(d.rtol),
        ..d
    };
    let mut rolling = model.fresh()?;
    let mut flight = flight.map(CoreModel::fresh).transpose()?;
    let (rolling_ref, flight_ref) = (&mut rolling, &mut flight);
    let study = py
        .detach(move || {
            rolling_contact(
                rolling_ref.as_mut(),
                flight_ref
                    .as_mut()
                    .map(|f| f.as_mut() as &mut dyn ModelInfo),
                &options,
            )
        })
        .map_err(analysis_error)?;
    study.check_measured().map_err(analysis_error)?;
    to_python(py, &study, Lists::Arrays)
}

/// `ż = A z` three ways — `e^{At} z₀`, the complex eigenvector solutions, DOP853 — for a
/// random or a given `A` (`eomgen study expm`); with `z0` or `times`, the study of that
/// problem ([`vibration::expm_study_of`]).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (n = None, seed = None, t = None, samples = None, tol = None, matrix = None, z0 = None, times = None))]
fn study_expm<'py>(
    py: Python<'py>,
    n: Option<usize>,
    seed: Option<u64>,
    t: Option<f64>,
    samples: Option<usize>,
    tol: Option<f64>,
    matrix: Option<Vec<Vec<f64>>>,
    z0: Option<Vec<f64>>,
    times: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyAny>> {
    let options = ExpmOptions {
        n: n.unwrap_or(ExpmOptions::DEFAULT_N),
        seed: seed.unwrap_or(ExpmOptions::DEFAULT_SEED),
        t_end: t.unwrap_or(ExpmOptions::DEFAULT_T_END),
        samples: samples.unwrap_or(ExpmOptions::DEFAULT_SAMPLES),
        tol: tol.unwrap_or(ExpmOptions::DEFAULT_TOL),
        matrix,
    };
    let study = if z0.is_none() && times.is_none() {
        py.detach(|| vibration::expm_study(&options))
    } else {
        let size = options.matrix.as_ref().map_or(options.n, Vec::len);
        if size == 0 || size > ExpmOptions::LARGEST_SIZE {
            return Err(PyValueError::new_err(format!(
                "the size of A must be 1 to {}, got {size}",
                ExpmOptions::LARGEST_SIZE
            )));
        }
        let problem = vibration::random_problem(size, options.seed);
        let a = match &options.matrix {
            Some(rows) => {
                if let Some((i, row)) = rows.iter().enumerate().find(|(_, r)| r.len() != size) {
                    return Err(PyValueError::new_err(format!(
                        "A must be square: row {} has {} entries, not {size}",
                        i + 1,
                        row.len()
                    )));
                }
                eomgen::nalgebra::DMatrix::from_row_iterator(
                    size,
                    size,
                    rows.iter().flatten().copied(),
                )
            }
            None => problem.state_matrix,
        };
        let z0 = z0.unwrap_or(problem.initial_state);
        let times = times.unwrap_or_else(|| {
            let k = options.samples.max(2);
            (0..k)
                .map(|i| options.t_end * i as f64 / (k - 1) as f64)
                .collect()
        });
        py.detach(|| vibration::expm_study_of(&a, &z0, &times, options.tol))
    }
    .map_err(|e| analysis_error(format!("study expm: {e}")))?;
    study.check_measured().map_err(analysis_error)?;
    to_python(py, &study, Lists::Arrays)
}

/// A model file with its holonomic constraints eliminated symbolically (`eomgen reduce
/// --json`): the reduced file's text, the coordinates kept, each elimination and the notes.
#[pyfunction]
#[pyo3(signature = (path, text, keep, branches = Vec::new(), initial = Vec::new(), name = None))]
fn reduce_model<'py>(
    py: Python<'py>,
    path: String,
    text: String,
    keep: Vec<String>,
    branches: Vec<(String, String)>,
    initial: Vec<(String, String)>,
    name: Option<String>,
) -> PyResult<Bound<'py, PyAny>> {
    use eomgen_symbolic::model::reduce::{Branch, ReduceError, ReduceOptions, reduce};
    let mut options = ReduceOptions {
        name,
        initial,
        ..ReduceOptions::default()
    };
    for (coordinate, sign) in branches {
        let sign: Branch = sign
            .parse()
            .map_err(|e| PyValueError::new_err(format!("branch of `{coordinate}`: {e}")))?;
        options.branches.push((coordinate, sign));
    }
    let file = eomgen_symbolic::model::load(&path, &text)
        .map_err(|d| model_error(py, &path, &text, &d))?;
    let keep: Vec<&str> = keep.iter().map(String::as_str).collect();
    let reduced = py
        .detach(|| reduce(&file, &keep, &options))
        .map_err(|e| match e {
            ReduceError::UnknownCoordinate { .. }
            | ReduceError::WrongCount { .. }
            | ReduceError::UnusedBranch { .. }
            | ReduceError::BadInitial { .. } => PyValueError::new_err(e.to_string()),
            e => analysis_error(format!("{path}: {e}")),
        })?;
    to_python(py, &reduced, Lists::Plain)
}
