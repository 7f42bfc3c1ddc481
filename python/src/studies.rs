//! The library's studies from Python: each one library call with its options from keyword
//! arguments (the library's defaults where one is not given), its report as the command
//! line's `--json` prints it, with numeric lists as numpy arrays.

use eomgen::analysis::vibration::{
    self, FloquetStudyOptions, FreeResponseOptions, FrfOptions, InitialDeviation,
    ModalDampingOptions, OperatingPointOptions, ParameterSweepOptions, SweepAxis,
};
use eomgen::analysis::{WorkPrecisionOptions, work_precision};
use pyo3::prelude::*;

use crate::convert::{Lists, to_python};
use crate::errors::analysis_error;
use crate::model::{CoreModel, equilibrium_start, method};

/// The operating point at `at` (`None`, a name or coordinates), `t = 0`.
fn point(at: Option<&Bound<'_, PyAny>>) -> PyResult<OperatingPointOptions> {
    Ok(OperatingPointOptions {
        start: equilibrium_start(at, None)?,
        t: 0.0,
    })
}

/// Registers the studies.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(study_work_precision, m)?)?;
    m.add_function(wrap_pyfunction!(study_parameter_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(study_frf, m)?)?;
    m.add_function(wrap_pyfunction!(study_floquet, m)?)?;
    m.add_function(wrap_pyfunction!(study_free_response, m)?)?;
    m.add_function(wrap_pyfunction!(study_modal_damping, m)?)?;
    m.add_function(wrap_pyfunction!(study_constraint_methods, m)?)?;
    Ok(())
}

/// Error against work of integration methods on `model` (`eomgen study work-precision`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (model, methods = None, tolerances = None, steps = None, t_end = None, samples = None, target_error = None, reference_tol = None, repeats = None, min_time_s = None))]
fn study_work_precision<'py>(
    py: Python<'py>,
    model: &CoreModel,
    methods: Option<Vec<String>>,
    tolerances: Option<Vec<f64>>,
    steps: Option<Vec<usize>>,
    t_end: Option<f64>,
    samples: Option<usize>,
    target_error: Option<f64>,
    reference_tol: Option<f64>,
    repeats: Option<usize>,
    min_time_s: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let defaults = WorkPrecisionOptions::default();
    let methods = match methods {
        Some(names) => names
            .iter()
            .map(|m| method(m))
            .collect::<PyResult<Vec<_>>>()?,
        None => defaults.methods.clone(),
    };
    let mut tolerances = tolerances.unwrap_or(defaults.tolerances.clone());
    tolerances.sort_by(|a, b| b.total_cmp(a));
    tolerances.dedup();
    let steps = steps.map(|mut s| {
        s.sort_unstable();
        s.dedup();
        s
    });
    let options = WorkPrecisionOptions {
        methods,
        tolerances,
        steps,
        t_end: t_end.unwrap_or(defaults.t_end),
        samples: samples.unwrap_or(defaults.samples),
        target_error: target_error.unwrap_or(defaults.target_error),
        baseline_ms: None,
        reference_tol: reference_tol.unwrap_or(defaults.reference_tol),
        repeats: repeats.unwrap_or(defaults.repeats),
        min_time_s: min_time_s.unwrap_or(defaults.min_time_s),
    };
    let mut instance = model.fresh()?;
    let report = py
        .detach(|| work_precision(instance.as_mut(), &options, &mut |_, _| {}))
        .map_err(analysis_error)?;
    to_python(
        py,
        &report.summary(instance.as_ref(), &options),
        Lists::Arrays,
    )
}

/// Eigenvalues of an operating point against one parameter, with the stability changes
/// (`eomgen study parameter-sweep`); for a model with a change of support, its gait of
/// `steps` landings followed over the parameter.
#[pyfunction]
#[pyo3(signature = (model, parameter, values, at = None, refine = true, steps = 1))]
fn study_parameter_sweep<'py>(
    py: Python<'py>,
    model: &CoreModel,
    parameter: String,
    values: Vec<f64>,
    at: Option<&Bound<'py, PyAny>>,
    refine: bool,
    steps: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let ascending = values
        .windows(2)
        .all(|w| w[0].partial_cmp(&w[1]) == Some(std::cmp::Ordering::Less));
    if values.is_empty() || !ascending || values.iter().any(|v| !v.is_finite()) {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "values must be a non-empty, strictly ascending sequence of finite numbers",
        ));
    }
    if values.len() > 10_000 {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "values has {} entries, at most 10000 are allowed (as `study parameter-sweep --values`)",
            values.len()
        )));
    }
    let axis = SweepAxis {
        name: parameter,
        values,
    };
    let mut instance = model.fresh()?;
    if !instance.description().supports.is_empty() {
        // A gait followed over the parameter from the model's initial state.
        if at.is_some() {
            return Err(pyo3::exceptions::PyValueError::new_err(
                "at does not apply to a gait: the sweep follows it from the model's initial state",
            ));
        }
        let options = eomgen::analysis::GaitOptions {
            steps,
            ..Default::default()
        };
        let sweep = py
            .detach(|| eomgen::analysis::gait_sweep(instance.as_mut(), &axis, &options, |_, _| {}))
            .map_err(|e| match e {
                e @ eomgen::analysis::GaitError::UnknownParameter { .. } => {
                    crate::errors::parameter_error(e)
                }
                e => analysis_error(e),
            })?;
        return to_python(py, &sweep, Lists::Arrays);
    }
    let options = ParameterSweepOptions {
        axis,
        operating_point: point(at)?,
        refine,
    };
    let sweep = py
        .detach(|| vibration::parameter_sweep(instance.as_mut(), &options, |_, _| {}))
        .map_err(|e| match e {
            e @ vibration::ParameterSweepError::UnknownParameter { .. } => {
                crate::errors::parameter_error(e)
            }
            e => analysis_error(e),
        })?;
    to_python(py, &sweep, Lists::Arrays)
}

/// The frequency response to a harmonic input about an equilibrium (`eomgen frf`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (model, input, outputs = Vec::new(), frequency_range = None, points = None, frequencies = Vec::new(), modal = false, at = None))]
fn study_frf<'py>(
    py: Python<'py>,
    model: &CoreModel,
    input: String,
    outputs: Vec<String>,
    frequency_range: Option<(f64, f64)>,
    points: Option<usize>,
    frequencies: Vec<f64>,
    modal: bool,
    at: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let options = FrfOptions {
        operating_point: point(at)?,
        input,
        outputs,
        frequency_range,
        points: points.unwrap_or(FrfOptions::DEFAULT_POINTS),
        frequencies,
        modal,
        simulation: None,
    };
    let mut instance = model.fresh()?;
    let analysis = py
        .detach(|| vibration::frequency_response_analysis(instance.as_mut(), &options))
        .map_err(analysis_error)?;
    to_python(
        py,
        &analysis.summary(instance.as_ref(), None),
        Lists::Arrays,
    )
}

/// The Floquet multipliers of a periodically forced model about its equilibrium
/// (`eomgen study floquet`, without the stability chart).
#[pyfunction]
#[pyo3(signature = (model, period_parameter = None, at = None, rtol = None, atol = None, stability_tolerance = None))]
fn study_floquet<'py>(
    py: Python<'py>,
    model: &CoreModel,
    period_parameter: Option<String>,
    at: Option<&Bound<'py, PyAny>>,
    rtol: Option<f64>,
    atol: Option<f64>,
    stability_tolerance: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let defaults = FloquetStudyOptions::default();
    let options = FloquetStudyOptions {
        operating_point: point(at)?,
        period_parameter: period_parameter.unwrap_or(defaults.period_parameter),
        floquet: eomgen::FloquetOptions {
            rtol: rtol.unwrap_or(defaults.floquet.rtol),
            atol: atol.unwrap_or(defaults.floquet.atol),
            stability_tolerance: stability_tolerance
                .unwrap_or(defaults.floquet.stability_tolerance),
            ..defaults.floquet
        },
    };
    let mut instance = model.fresh()?;
    let (label, _) = options
        .operating_point
        .start
        .resolve(instance.as_ref())
        .map_err(analysis_error)?;
    let point = py
        .detach(|| vibration::floquet_at_equilibrium(instance.as_mut(), &options))
        .map_err(analysis_error)?;
    // What the model file's `floquet:` references predict here (the Kapitza threshold of
    // the Mathieu pendulum), as the command line reports them.
    let references =
        eomgen::FloquetReferences::of(instance.description(), &label).map_err(analysis_error)?;
    let predictions = references
        .map(|r| r.thresholds(instance.as_ref()))
        .unwrap_or_default()
        .into_iter()
        .map(|t| vibration::PredictionSummary {
            name: t.name,
            key: t.key,
            value: t.value,
            critical: t.critical,
            equilibrium: label.clone(),
            predicts_stable: t.predicts_stable,
        })
        .collect();
    let summary = point.summary(instance.as_ref(), &options, predictions, None);
    to_python(py, &summary, Lists::Arrays)
}

/// An initial deviation `(δq₀, δq̇₀)` from keyword arguments: both or neither.
fn deviation(q: Option<Vec<f64>>, qdot: Option<Vec<f64>>, n: usize) -> Option<InitialDeviation> {
    match (q, qdot) {
        (None, None) => None,
        (q, qdot) => Some(InitialDeviation {
            q: q.unwrap_or_else(|| vec![0.0; n]),
            qdot: qdot.unwrap_or_else(|| vec![0.0; n]),
        }),
    }
}

/// The free response about an equilibrium four ways: superposed modes, `e^{At}`, the
/// linearised and the nonlinear equations integrated (`eomgen study free-response`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (model, at = None, dq0 = None, dqdot0 = None, t_end = None, samples = None, tol = None))]
fn study_free_response<'py>(
    py: Python<'py>,
    model: &CoreModel,
    at: Option<&Bound<'py, PyAny>>,
    dq0: Option<Vec<f64>>,
    dqdot0: Option<Vec<f64>>,
    t_end: Option<f64>,
    samples: Option<usize>,
    tol: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut instance = model.fresh()?;
    let options = FreeResponseOptions {
        operating_point: point(at)?,
        initial: deviation(dq0, dqdot0, instance.num_dofs()),
        t_end,
        samples: samples.unwrap_or(FreeResponseOptions::DEFAULT_SAMPLES),
        tol: tol.unwrap_or(FreeResponseOptions::DEFAULT_TOL),
    };
    let model_ref = &mut instance;
    let study = py
        .detach(move || vibration::free_response(model_ref.as_ref(), &options))
        .map_err(analysis_error)?;
    to_python(py, &study.summary(instance.as_ref()), Lists::Arrays)
}

/// Modal damping against the exact damped response, with a Rayleigh fit to two modes
/// (`eomgen study modal-damping`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (model, at = None, rayleigh_modes = None, dq0 = None, dqdot0 = None, t_end = None, samples = None, tol = None))]
fn study_modal_damping<'py>(
    py: Python<'py>,
    model: &CoreModel,
    at: Option<&Bound<'py, PyAny>>,
    rayleigh_modes: Option<[usize; 2]>,
    dq0: Option<Vec<f64>>,
    dqdot0: Option<Vec<f64>>,
    t_end: Option<f64>,
    samples: Option<usize>,
    tol: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut instance = model.fresh()?;
    let options = ModalDampingOptions {
        operating_point: point(at)?,
        rayleigh_modes,
        initial: deviation(dq0, dqdot0, instance.num_dofs()),
        t_end,
        samples: samples.unwrap_or(ModalDampingOptions::DEFAULT_SAMPLES),
        tol: tol.unwrap_or(ModalDampingOptions::DEFAULT_TOL),
    };
    let model_ref = &mut instance;
    let study = py
        .detach(move || vibration::modal_damping_study(model_ref.as_ref(), &options))
        .map_err(analysis_error)?;
    to_python(py, &study.summary(instance.as_ref()), Lists::Arrays)
}

/// Constraint methods compared on a model with holonomic constraints (`eomgen study
/// constraint-methods`): a stiff spring (method I), the KKT system with and without drift
/// control, the constraints eliminated symbolically (method II.2, where they can be) and the
/// file's minimal-coordinate twin, against a reference.
#[pyfunction]
#[pyo3(signature = (model, t_end = None, tol = None, stiffness = None))]
fn study_constraint_methods<'py>(
    py: Python<'py>,
    model: &CoreModel,
    t_end: Option<f64>,
    tol: Option<f64>,
    stiffness: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyAny>> {
    use eomgen::analysis::{ConstraintMethodsOptions, constraint_methods_with_reduced};
    let defaults = ConstraintMethodsOptions::default();
    let options = ConstraintMethodsOptions {
        t_end: t_end.unwrap_or(defaults.t_end),
        tol: tol.unwrap_or(defaults.tol),
        stiffness: stiffness.unwrap_or(defaults.stiffness),
    };
    let loaded = model.loaded.clone();
    let overrides = model.overrides.clone();
    // This model's parameter values go to the twin too, where it has the parameter, so that
    // both describe the same mechanism.
    let with_values = move |mut m: Box<dyn eomgen::ModelInfo>| {
        for (name, value) in &overrides {
            let _ = m.set_parameter(name, *value);
        }
        m
    };
    let study = py.detach(move || {
        let twin = eomgen::studies::minimal_twin(&loaded.source).map_err(|e| e.to_string())?;
        // Method II.2 where the constraints can be eliminated symbolically (as the command
        // line: a model whose constraints cannot be has no such row).
        let reduced = eomgen::reduction::reduced_twin(&loaded.source).ok();
        let label = reduced.as_ref().map(eomgen::reduction::ReducedTwin::label);
        let mut make = || with_values(loaded.source.instantiate());
        let reduced_model = reduced
            .as_ref()
            .zip(label.as_deref())
            .map(|(r, label)| (label, with_values(r.instantiate())));
        let twin_model = twin
            .as_ref()
            .map(|(name, twin)| (name.as_str(), with_values(twin.instantiate())));
        constraint_methods_with_reduced(&mut make, reduced_model, twin_model, &options)
            .map(|study| (study, options))
            .map_err(|e| e.to_string())
    });
    let (study, options) = study.map_err(analysis_error)?;
    to_python(py, &study.summary(&options), Lists::Arrays)
}
