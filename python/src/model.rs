//! `eomgen._eomgen._Model`: a model opened once (bundled, or a file compiled at run time),
//! with parameter values of its own, and one method per library call. The Python class
//! `eomgen.Model` wraps it with docstrings and result objects; every number comes from here.

use std::sync::{Arc, Mutex, OnceLock};

use eomgen::analysis::vibration::{
    self, EquilibriumStart, ModalOptions, OperatingPointOptions, SteadyAnalysisError,
};
use eomgen::analysis::{AddedEvents, SimulationError, SimulationOptions, simulate_with_events};
use eomgen::expressions::ExpressionEvents;
use eomgen::{JitModel, Method, ModelInfo, ModelSource, OutputTimes, Stabilization};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::convert::{DeferredReport, Lists, matrix, to_python};
use crate::errors::{analysis_error, model_error, open_error, parameter_error};

/// A model as opened: the compiled code, how it was named, and the file's text (what a
/// pickle carries).
#[derive(Debug)]
pub struct Loaded {
    /// The compiled model.
    pub source: ModelSource,
    /// A bundled model's name or the path given.
    pub argument: String,
    /// The model file's text.
    pub text: String,
}

/// A model with parameter values of its own.
#[pyclass(module = "eomgen._eomgen", name = "_Model", frozen)]
pub struct CoreModel {
    pub(crate) loaded: Arc<Loaded>,
    /// `(name, value)` set over the file's defaults, in order.
    pub(crate) overrides: Vec<(String, f64)>,
    /// An instance with `overrides` applied, for the evaluations users call in their own
    /// loops (`rhs`, `mass_matrix`, `forcing`): built once, not per call.
    instance: Mutex<Box<dyn ModelInfo + Send>>,
}

/// Files compiled in this process, by `(path, text)`: unpickling the same model in every
/// task of a sweep compiles it once per worker process.
fn compiled_files() -> &'static Mutex<Vec<(String, String, JitModel)>> {
    static FILES: OnceLock<Mutex<Vec<(String, String, JitModel)>>> = OnceLock::new();
    FILES.get_or_init(|| Mutex::new(Vec::new()))
}

/// How many compiled files the cache keeps (the oldest is dropped past it).
const MAX_CACHED_FILES: usize = 64;

/// Opens `argument` as [`ModelSource::open`] does, or, when `text` is given (a pickle's),
/// compiles that text — a bundled model whose embedded text equals it is taken as is.
fn open(argument: &str, text: Option<&str>) -> Result<Loaded, eomgen::OpenError> {
    if let Some(text) = text {
        if let Some(entry) = eomgen::models::find(argument)
            && entry.source() == text
        {
            return Ok(Loaded {
                source: ModelSource::Bundled {
                    entry,
                    model: entry.model()?,
                },
                argument: argument.to_string(),
                text: text.to_string(),
            });
        }
        return Ok(Loaded {
            source: ModelSource::File {
                path: argument.to_string(),
                model: compile_text(argument, text)?,
            },
            argument: argument.to_string(),
            text: text.to_string(),
        });
    }
    match eomgen::resolve(argument)? {
        eomgen::Resolved::Bundled(entry) => Ok(Loaded {
            source: ModelSource::Bundled {
                entry,
                model: entry.model()?,
            },
            argument: argument.to_string(),
            text: entry.source().to_string(),
        }),
        eomgen::Resolved::File(path) => {
            // Read once: the text compiled is the text a pickle carries.
            let text = read_text(&path)?;
            Ok(Loaded {
                source: ModelSource::File {
                    path: path.clone(),
                    model: compile_text(&path, &text)?,
                },
                argument: path,
                text,
            })
        }
    }
}

/// A model file's text, through the loader's size limit; a file that is not UTF-8 is a
/// located diagnostic, as `JitModel::load` reports it.
fn read_text(path: &str) -> Result<String, eomgen::LoadError> {
    use eomgen_symbolic::model::{ReadError, read_model_file};
    read_model_file(std::path::Path::new(path)).map_err(|e| match e {
        ReadError::NotText { diagnostic, text } => eomgen::LoadError::Diagnostics {
            path: path.to_string(),
            text,
            diagnostics: vec![diagnostic],
        },
        source => eomgen::LoadError::Read {
            path: path.to_string(),
            source,
        },
    })
}

/// The model of a file's text, compiled once per process for each `(path, text)`.
fn compile_text(path: &str, text: &str) -> Result<JitModel, eomgen::LoadError> {
    if let Ok(files) = compiled_files().lock()
        && let Some((_, _, model)) = files.iter().find(|(p, t, _)| p == path && t == text)
    {
        return Ok(model.clone());
    }
    let model = JitModel::from_source(path, text)?;
    if let Ok(mut files) = compiled_files().lock() {
        if files.len() >= MAX_CACHED_FILES {
            files.remove(0);
        }
        files.push((path.to_string(), text.to_string(), model.clone()));
    }
    Ok(model)
}

impl CoreModel {
    /// A new model of `loaded` with `overrides` applied (checked on an instance).
    fn new(loaded: Arc<Loaded>, overrides: Vec<(String, f64)>) -> PyResult<CoreModel> {
        let instance = instantiate(&loaded, &overrides)?;
        Ok(CoreModel {
            loaded,
            overrides,
            instance: Mutex::new(instance),
        })
    }

    /// A fresh instance with this model's parameters (for a call that may run on another
    /// thread).
    pub(crate) fn fresh(&self) -> PyResult<Box<dyn ModelInfo + Send>> {
        instantiate(&self.loaded, &self.overrides)
    }

    /// Runs `f` on the cached instance. An evaluation that panicked (a bug, reported as
    /// such by pyo3) left nothing half-done that the next one reads: every evaluation
    /// computes from the state it is given, so the lock is taken back.
    fn with_instance<T>(&self, f: impl FnOnce(&mut dyn ModelInfo) -> T) -> PyResult<T> {
        let mut guard = self
            .instance
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        Ok(f(guard.as_mut()))
    }
}

/// Most output times per run: `eomgen simulate --t-out`'s limit (docs/cli.md).
pub(crate) const MAX_OUTPUT_TIMES: usize = 100_000;

/// Output times as `t_out` gives them: a time, a sequence of times, or a 1-D array (s); read
/// here rather than converted in Python, where `[float(t) for t in np.atleast_1d(t_out)]`
/// cost a microsecond per call.
///
/// # Errors
/// `TypeError` for anything else (a 2-D array, a string, bytes).
pub(crate) fn output_times(t_out: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    if let Ok(array) = t_out.extract::<PyReadonlyArray1<'_, f64>>() {
        // Any strides (`times[::2]`).
        return Ok(array.as_array().to_vec());
    }
    if let Ok(time) = t_out.extract::<f64>() {
        return Ok(vec![time]);
    }
    // Bytes are sequences of integers to Python; as times they are a mistake.
    let bytes = t_out.is_instance_of::<pyo3::types::PyBytes>()
        || t_out.is_instance_of::<pyo3::types::PyByteArray>();
    let times = if bytes {
        Err(())
    } else {
        t_out.extract::<Vec<f64>>().map_err(|_| ())
    };
    times.map_err(|()| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "t_out must be a time or a 1-D sequence of times (s), got {}",
            t_out
                .get_type()
                .name()
                .map_or_else(|_| "an object".to_string(), |n| n.to_string())
        ))
    })
}

/// An instance of `loaded` with `overrides` set, in order.
pub(crate) fn instantiate(
    loaded: &Loaded,
    overrides: &[(String, f64)],
) -> PyResult<Box<dyn ModelInfo + Send>> {
    let mut model = loaded.source.instantiate_send();
    for (name, value) in overrides {
        set_parameter(model.as_mut(), name, *value)?;
    }
    check_bodies(model.as_ref(), overrides)?;
    Ok(model)
}

/// The bodies of `model` held, once `overrides` are set, to the rules the model file's
/// defaults are held to ([`eomgen::expressions::check_bodies`]): a `ParameterError` naming
/// the values otherwise.
pub(crate) fn check_bodies(model: &dyn ModelInfo, overrides: &[(String, f64)]) -> PyResult<()> {
    if overrides.is_empty() {
        return Ok(());
    }
    eomgen::expressions::check_bodies(model).map_err(|problem| {
        let values: Vec<String> = overrides.iter().map(|(n, v)| format!("{n}={v}")).collect();
        parameter_error(format!("{problem} with {}", values.join(", ")))
    })
}

/// Sets one parameter: a finite value of a parameter the model has.
pub(crate) fn set_parameter(model: &mut dyn ModelInfo, name: &str, value: f64) -> PyResult<()> {
    if !value.is_finite() {
        return Err(parameter_error(format!(
            "parameter `{name}` must be a finite number, got {value}"
        )));
    }
    // The error names the model and lists its parameters itself.
    model
        .set_parameter(name, value)
        .map_err(|e| parameter_error(e.to_string()))
}

/// The method named `name` ([`Method`]'s names: `dp54`, `dop853`, `radau5`, …).
pub(crate) fn method(name: &str) -> PyResult<Method> {
    name.parse::<Method>()
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))
}

/// The drift control named `name` with Baumgarte's gains.
pub(crate) fn stabilization(name: &str, baumgarte: (f64, f64)) -> PyResult<Stabilization> {
    match name {
        "none" => Ok(Stabilization::None),
        "baumgarte" => Ok(Stabilization::Baumgarte {
            alpha: baumgarte.0,
            beta: baumgarte.1,
        }),
        "projection" => Ok(Stabilization::Projection),
        other => Err(pyo3::exceptions::PyValueError::new_err(format!(
            "stabilization must be `none`, `baumgarte` or `projection`, got `{other}`"
        ))),
    }
}

/// The options of one simulation, as `simulate`'s keyword arguments give them.
pub(crate) struct RunOptions {
    pub options: SimulationOptions,
    pub stop_when: Vec<String>,
    pub event: Vec<String>,
}

/// A simulation's options as the Python layer hands them over, one dict for `simulate` and
/// `animate` alike (`eomgen._model._run_args`).
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct RunArgs {
    t_end: f64,
    method: String,
    rtol: f64,
    atol: f64,
    dt: Option<f64>,
    initial_state: Option<Vec<f64>>,
    stabilization: String,
    baumgarte: (f64, f64),
    stop_when: Vec<String>,
    events: Vec<String>,
}

impl RunArgs {
    /// The run's options, sampled at `output`.
    ///
    /// # Errors
    /// `ValueError` for an unknown method or drift control.
    pub(crate) fn options(self, output: OutputTimes) -> PyResult<RunOptions> {
        Ok(RunOptions {
            options: SimulationOptions {
                method: method(&self.method)?,
                t_end: self.t_end,
                rtol: self.rtol,
                atol: self.atol,
                dt: self.dt,
                output,
                stabilization: stabilization(&self.stabilization, self.baumgarte)?,
                initial_state: self.initial_state,
            },
            stop_when: self.stop_when,
            event: self.events,
        })
    }

    /// The end time (s).
    pub(crate) fn t_end(&self) -> f64 {
        self.t_end
    }
}

/// Why a simulation could not start, as the exception it becomes: options or event
/// expressions that are refused (`ValueError`), or a state the constraints cannot accept
/// (`AnalysisError`). Plain data, so that it crosses threads without the interpreter.
#[derive(Debug, Clone)]
pub(crate) enum RunError {
    /// A refused option or expression.
    Value(String),
    /// An initial state that cannot be made consistent with the constraints.
    Analysis(String),
}

impl RunError {
    /// The exception.
    pub(crate) fn into_py(self) -> PyErr {
        match self {
            RunError::Value(m) => pyo3::exceptions::PyValueError::new_err(m),
            RunError::Analysis(m) => analysis_error(m),
        }
    }

    /// The same error with `context` before its message.
    pub(crate) fn context(self, context: &str) -> RunError {
        match self {
            RunError::Value(m) => RunError::Value(format!("{context}: {m}")),
            RunError::Analysis(m) => RunError::Analysis(format!("{context}: {m}")),
        }
    }
}

/// One simulation on `model` (events added from expressions), off the interpreter.
pub(crate) fn run_simulation(
    model: &mut dyn ModelInfo,
    run: &RunOptions,
) -> Result<eomgen::analysis::Simulation, RunError> {
    let mut added = ExpressionEvents::parse(model, &run.stop_when, &run.event)
        .map_err(|e| RunError::Value(e.to_string()))?;
    let added: Option<&mut dyn AddedEvents> = if added.is_empty() {
        None
    } else {
        Some(&mut added)
    };
    simulate_with_events(model, &run.options, added).map_err(simulation_error)
}

/// A simulation's error as the Python layer raises it: an initial state the constraints
/// cannot accept as `AnalysisError` with what to do, anything else as `ValueError`.
pub(crate) fn simulation_error(e: SimulationError) -> RunError {
    match e {
        e @ SimulationError::InconsistentInitialState { has_guesses, .. } => {
            RunError::Analysis(format!("{e}; {}", not_started_hint(has_guesses)))
        }
        e => RunError::Value(e.to_string()),
    }
}

/// What to do about an initial state the constraints cannot accept, for a model that marks
/// coordinates of its initial state as guesses or not.
pub(crate) fn not_started_hint(has_guesses: bool) -> &'static str {
    if has_guesses {
        "start Newton from other guesses (initial=…)"
    } else {
        "give the dependent coordinates consistent values (initial=…), or mark them `{ guess: … }` in the model file's `initial:`"
    }
}

/// A simulation's results for the Python layer: `{"summary", "error", "t", "y", "energy",
/// "lagrange_multipliers", "constraint_drift"}`; `summary` is a [`DeferredReport`] (called,
/// `simulate --json`'s report without its samples), `error` the report's `error` (a failed
/// run only).
pub(crate) fn simulation_dict<'py>(
    py: Python<'py>,
    model: &dyn ModelInfo,
    mut simulation: eomgen::analysis::Simulation,
) -> PyResult<Bound<'py, PyDict>> {
    let dim = 2 * model.num_dofs();
    let out = PyDict::new(py);
    // The summary becomes dicts when the Python layer first reads it; the failure, which
    // every call reads, at once.
    let summary = simulation.summary_without_samples(model);
    if let Some(error) = &summary.error {
        out.set_item("error", to_python(py, error, Lists::Plain)?)?;
    }
    out.set_item("summary", DeferredReport::new(summary))?;
    // What the model shows where a failed run stopped (a singular mass matrix, a forcing
    // out of its domain), for the exception's message.
    if let Some(cause) = &simulation.cause {
        out.set_item("cause", cause.to_string())?;
    }
    // The samples' buffers become the arrays' (no copy).
    let samples = simulation.solution.len();
    let t = std::mem::take(&mut simulation.solution.t);
    let y = std::mem::take(&mut simulation.solution.y);
    out.set_item("t", PyArray1::from_vec(py, t))?;
    out.set_item("y", matrix(py, y, samples, dim)?)?;
    let energy = std::mem::take(&mut simulation.energy.energy);
    out.set_item("energy", PyArray1::from_vec(py, energy))?;
    let constraints = &simulation.constraints;
    if !constraints.is_empty() {
        let m = constraints.constraint_names.len();
        let mut forces = Vec::with_capacity(samples * m);
        let mut solved = Vec::with_capacity(samples);
        for row in &constraints.lagrange_multipliers {
            match row {
                Some(values) => forces.extend_from_slice(values),
                None => forces.extend(std::iter::repeat_n(f64::NAN, m)),
            }
            solved.push(row.is_some());
        }
        out.set_item("lagrange_multipliers", matrix(py, forces, samples, m)?)?;
        out.set_item("multipliers_solved", PyArray1::from_vec(py, solved))?;
        let drift: Vec<f64> = constraints
            .drift
            .iter()
            .flat_map(|&(p, v)| [p, v])
            .collect();
        out.set_item("constraint_drift", matrix(py, drift, samples, 2)?)?;
    }
    Ok(out)
}

/// The start of an equilibrium search: `None` (the file's first equilibrium), a name, or
/// coordinates with a label.
pub(crate) fn equilibrium_start(
    at: Option<&Bound<'_, PyAny>>,
    label: Option<String>,
) -> PyResult<EquilibriumStart> {
    let Some(at) = at else {
        return Ok(EquilibriumStart::FirstNamed);
    };
    if let Ok(name) = at.extract::<String>() {
        return Ok(EquilibriumStart::Named(name));
    }
    let q: Vec<f64> = at.extract()?;
    finite("at", &q)?;
    let label = label.unwrap_or_else(|| {
        format!(
            "q = [{}]",
            q.iter().map(f64::to_string).collect::<Vec<_>>().join(", ")
        )
    });
    Ok(EquilibriumStart::Guess { label, q })
}

/// `values` (argument `name`) when every entry is finite, else a `ValueError` naming it.
pub(crate) fn finite<'a>(name: &str, values: &'a [f64]) -> PyResult<&'a [f64]> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(values),
        Some(i) => Err(pyo3::exceptions::PyValueError::new_err(format!(
            "{name}[{i}] is {}: the model is evaluated at finite values only",
            values[i]
        ))),
    }
}

/// `t` when it is finite, else a `ValueError`.
fn finite_time(t: f64) -> PyResult<f64> {
    if t.is_finite() {
        Ok(t)
    } else {
        Err(pyo3::exceptions::PyValueError::new_err(format!(
            "t is {t}: the model is evaluated at finite times only"
        )))
    }
}

/// An operating point that could not be found or analysed as `AnalysisError`.
fn point_error(model: &dyn ModelInfo, e: impl std::fmt::Display) -> PyErr {
    analysis_error(format!("`{}`: {e}", model.description().name))
}

#[pymethods]
impl CoreModel {
    /// Opens a bundled model by name or a model file by path (compiled at run time).
    #[staticmethod]
    fn load(py: Python<'_>, name_or_path: &str) -> PyResult<CoreModel> {
        let argument = name_or_path.to_string();
        let loaded = py
            .detach(move || open(&argument, None))
            .map_err(|e| open_error(py, e))?;
        CoreModel::new(Arc::new(loaded), Vec::new())
    }

    /// A model from a file's text (`path` names it in diagnostics), as a pickle restores it.
    #[staticmethod]
    #[pyo3(signature = (argument, text, overrides = Vec::new()))]
    fn restore(
        py: Python<'_>,
        argument: &str,
        text: &str,
        overrides: Vec<(String, f64)>,
    ) -> PyResult<CoreModel> {
        let (a, t) = (argument.to_string(), text.to_string());
        let loaded = py
            .detach(move || open(&a, Some(&t)))
            .map_err(|e| open_error(py, e))?;
        CoreModel::new(Arc::new(loaded), overrides)
    }

    /// `(argument, text, overrides)`: what a pickle carries.
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        PyTuple::new(
            py,
            [
                self.loaded.argument.clone().into_pyobject(py)?.into_any(),
                self.loaded.text.clone().into_pyobject(py)?.into_any(),
                self.overrides.clone().into_pyobject(py)?.into_any(),
            ],
        )
    }

    /// A copy with `values` (name → value) set over this model's parameters.
    fn with_parameters(&self, values: Vec<(String, f64)>) -> PyResult<CoreModel> {
        let mut overrides = self.overrides.clone();
        for (name, value) in values {
            overrides.retain(|(n, _)| *n != name);
            overrides.push((name, value));
        }
        CoreModel::new(self.loaded.clone(), overrides)
    }

    /// The model's name.
    #[getter]
    fn name(&self) -> PyResult<String> {
        self.with_instance(|m| m.description().name.to_string())
    }

    /// A bundled model's name, or the path given.
    #[getter]
    fn argument(&self) -> String {
        self.loaded.argument.clone()
    }

    /// The file as messages name it (`models/<file>` for a bundled model).
    #[getter]
    fn path(&self) -> String {
        self.loaded.source.path().to_string()
    }

    /// The model file's text.
    #[getter]
    fn text(&self) -> String {
        self.loaded.text.clone()
    }

    /// Whether the model was read from a file (not bundled).
    #[getter]
    fn is_file(&self) -> bool {
        self.loaded.source.is_file()
    }

    /// The model's description (`ModelDescription`) as a dict: names, defaults, points,
    /// constraints, equilibria, events, drawing, equations as text.
    fn description<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let d = self.with_instance(|m| serde_json::to_value(m.description()))?;
        let d = d.map_err(|e| analysis_error(format!("the description: {e}")))?;
        crate::convert::value_to_python(py, &d, Lists::Plain)
    }

    /// The generalized coordinates' names.
    #[getter]
    fn coordinates(&self) -> PyResult<Vec<String>> {
        self.with_instance(|m| {
            m.description()
                .coordinate_names()
                .iter()
                .map(|s| s.to_string())
                .collect()
        })
    }

    /// The generalized speeds' names (`speeds:`), empty for a model in the coordinates' rates.
    #[getter]
    fn speeds(&self) -> PyResult<Vec<String>> {
        self.with_instance(|m| {
            m.description()
                .speeds
                .iter()
                .map(|s| s.to_string())
                .collect()
        })
    }

    /// The names of the state's `2n` entries: the coordinates, then their rates (`x_dot`) or
    /// the generalized speeds.
    #[getter]
    fn state_names(&self) -> PyResult<Vec<String>> {
        self.with_instance(|m| {
            let d = m.description();
            (0..2 * d.num_dofs()).map(|i| d.state_name(i)).collect()
        })
    }

    /// `(name, value)` of every parameter, in the file's order, with this model's values.
    #[getter]
    fn parameters(&self) -> PyResult<Vec<(String, f64)>> {
        self.with_instance(|m| {
            m.description()
                .parameter_names()
                .iter()
                .map(|s| s.to_string())
                .zip(m.parameter_values())
                .collect()
        })
    }

    /// The parameters set over the file's defaults, in order.
    #[getter]
    fn overrides(&self) -> Vec<(String, f64)> {
        self.overrides.clone()
    }

    /// The number of degrees of freedom `n`.
    #[getter]
    fn num_dofs(&self) -> PyResult<usize> {
        self.with_instance(|m| m.num_dofs())
    }

    /// The file's initial state `[q; q̇]` (`2n`), before it is made consistent with the
    /// constraints.
    fn initial_state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let y = self.with_instance(|m| m.initial_state())?;
        Ok(PyArray1::from_vec(py, y))
    }

    /// One simulation; see `eomgen.Model.simulate`.
    #[pyo3(signature = (args, t_out))]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        args: RunArgs,
        t_out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let t_out = t_out.map(output_times).transpose()?;
        if let Some(times) = &t_out
            && times.len() > MAX_OUTPUT_TIMES
        {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "t_out has {} times, at most {} are allowed (as `eomgen simulate --t-out`)",
                times.len(),
                MAX_OUTPUT_TIMES
            )));
        }
        let run = args.options(t_out.map_or(OutputTimes::Steps, OutputTimes::At))?;
        let mut model = self.fresh()?;
        let started = std::time::Instant::now();
        let simulation = py
            .detach(|| run_simulation(model.as_mut(), &run))
            .map_err(RunError::into_py)?;
        let library_time = started.elapsed().as_secs_f64();
        let out = simulation_dict(py, model.as_ref(), simulation)?;
        // The library call's own wall time, for the measurement of what the binding adds.
        out.set_item("library_time_s", library_time)?;
        Ok(out)
    }

    /// The modal analysis at an operating point (an equilibrium, or a steady motion); see
    /// `eomgen.Model.modes`. Returns `(kind, summary)`: `"equilibrium"` with what
    /// `eomgen modes --json` prints, or `"steady"` with the steady-motion summary.
    #[pyo3(signature = (at = None, label = None, t = 0.0))]
    fn modes<'py>(
        &self,
        py: Python<'py>,
        at: Option<&Bound<'py, PyAny>>,
        label: Option<String>,
        t: f64,
    ) -> PyResult<(String, Bound<'py, PyAny>)> {
        let options = OperatingPointOptions {
            start: equilibrium_start(at, label)?,
            t,
        };
        let mut model = self.fresh()?;
        if vibration::is_steady_motion(model.as_ref(), &options.start) {
            let analysis = py
                .detach(|| vibration::steady_motion_analysis(model.as_mut(), &options))
                .map_err(|e| match e {
                    SteadyAnalysisError::OperatingPoint(e) => point_error(model.as_ref(), e),
                    e => point_error(model.as_ref(), e),
                })?;
            let summary = analysis.summary(model.as_ref());
            return Ok(("steady".into(), to_python(py, &summary, Lists::Plain)?));
        }
        let modal_options = ModalOptions {
            operating_point: options,
        };
        let instance = &mut model;
        let modal = py
            .detach(move || vibration::modal_analysis(instance.as_ref(), &modal_options))
            .map_err(|e| point_error(model.as_ref(), e))?;
        let summary = modal.summary(model.as_ref());
        Ok(("equilibrium".into(), to_python(py, &summary, Lists::Plain)?))
    }

    /// The state-space model `δẏ = A δy + B u`, `z = C δy + D u` from `inputs` to `outputs`
    /// about the equilibrium whose Newton search starts at `at` (found with the inputs at
    /// 0): `eomgen modes --input … --output … --json`'s `state_space` ([`eomgen::state_space`]).
    fn state_space<'py>(
        &self,
        py: Python<'py>,
        at: Option<&Bound<'py, PyAny>>,
        label: Option<String>,
        inputs: Vec<String>,
        outputs: Vec<String>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let start = equilibrium_start(at, label)?;
        let mut model = self.fresh()?;
        let state_space = py.detach(|| {
            let (_, guess) = start
                .resolve_equilibrium(model.as_ref())
                .map_err(|e| e.to_string())?;
            let inputs: Vec<&str> = inputs.iter().map(String::as_str).collect();
            let outputs: Vec<&str> = outputs.iter().map(String::as_str).collect();
            eomgen::state_space(model.as_mut(), &guess, &inputs, &outputs)
                .map_err(|e| e.to_string())
        });
        let state_space = state_space.map_err(|e| point_error(model.as_ref(), e))?;
        to_python(py, &state_space, Lists::Plain)
    }

    /// The cross-check of the derivations at `states` random states: what
    /// `eomgen check --json` prints (with `timing`, the derivation times too).
    #[pyo3(signature = (states = eomgen_symbolic::mechanics::cross_check::DEFAULT_CHECK_STATES, timing = false))]
    fn check<'py>(
        &self,
        py: Python<'py>,
        states: usize,
        timing: bool,
    ) -> PyResult<(bool, Bound<'py, PyAny>)> {
        use eomgen_symbolic::mechanics::cross_check::{CHECK_SEED, CHECK_TOLERANCE, check_model};
        if !(1..=100_000).contains(&states) {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "states must be between 1 and 100000, got {states}"
            )));
        }
        let path = self.loaded.source.path().to_string();
        let text = self.loaded.text.clone();
        let report = py.detach(|| {
            let file = eomgen_symbolic::model::load(&path, &text)?;
            check_model(&file, states, CHECK_SEED)
        });
        let report = report.map_err(|d| model_error(py, &path, &text, &d))?;
        let summary = report.summary(CHECK_TOLERANCE, timing);
        Ok((
            report.passed(CHECK_TOLERANCE),
            to_python(py, &summary, Lists::Plain)?,
        ))
    }

    /// The equations of motion by `method` (`lagrange` or `momentum`): `(listing, text,
    /// latex)`, the listing `{"model", "method", "equations", "latex"}` as
    /// `eomgen equations --json` prints it, and the whole listing as text and as LaTeX.
    #[pyo3(signature = (method = "lagrange"))]
    fn equations<'py>(
        &self,
        py: Python<'py>,
        method: &str,
    ) -> PyResult<(Bound<'py, PyAny>, String, String)> {
        use eomgen::listing::{Derivation, ListingError, equations};
        let path = self.loaded.source.path().to_string();
        let text = self.loaded.text.clone();
        let derivation = match method {
            "lagrange" => Derivation::Lagrange,
            "momentum" => Derivation::Momentum,
            other => {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "method must be `lagrange` or `momentum`, got `{other}`"
                )));
            }
        };
        let listing = py.detach(|| equations(&path, &text, derivation));
        let listing = listing.map_err(|e| match e {
            ListingError::Diagnostics(d) => model_error(py, &path, &text, &d),
            e => pyo3::exceptions::PyValueError::new_err(e.to_string()),
        })?;
        Ok((
            to_python(py, &listing, Lists::Plain)?,
            listing.text,
            listing.latex_document,
        ))
    }

    /// The kinematics of `frames` and `points` (every one of the file's when empty), with
    /// the partial velocities when `partial` and the `reactions` (bodies, point): `(listing,
    /// text, latex)`, the listing
    /// `{"model", "coordinates", "frames", "points", "latex"}` as `eomgen kinematics --json`
    /// prints it ([`eomgen::listing::kinematics`]).
    #[pyo3(signature = (frames, points, partial, reactions))]
    fn kinematics<'py>(
        &self,
        py: Python<'py>,
        frames: Vec<String>,
        points: Vec<String>,
        partial: bool,
        reactions: Vec<(Vec<String>, String)>,
    ) -> PyResult<(Bound<'py, PyAny>, String, String)> {
        use eomgen::listing::{KinematicsOptions, ListingError, ReactionRequest, kinematics};
        let path = self.loaded.source.path().to_string();
        let text = self.loaded.text.clone();
        let options = KinematicsOptions {
            frames,
            points,
            partial,
            reactions: (reactions.into_iter())
                .map(|(bodies, at)| ReactionRequest { bodies, at })
                .collect(),
        };
        let listing = py.detach(|| kinematics(&path, &text, &options));
        let listing = listing.map_err(|e| match e {
            ListingError::Diagnostics(d) => model_error(py, &path, &text, &d),
            e => pyo3::exceptions::PyValueError::new_err(e.to_string()),
        })?;
        Ok((
            to_python(py, &listing, Lists::Plain)?,
            listing.text,
            listing.latex_document,
        ))
    }

    /// The equations as source code in `language` (`c`, `matlab` or `python`), as
    /// `eomgen equations --c` (`--matlab`, `--python`) prints them, with the parameters this
    /// model has set as the exported defaults ([`eomgen::listing::export_with_parameters`]).
    fn export(&self, py: Python<'_>, language: &str) -> PyResult<String> {
        use eomgen::listing::{Language, ListingError, export_with_parameters};
        let Some(language) = Language::ALL.into_iter().find(|l| l.name() == language) else {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "language must be `c`, `matlab` or `python`, got `{language}`"
            )));
        };
        let path = self.loaded.source.path().to_string();
        let text = self.loaded.text.clone();
        let overrides = self.overrides.clone();
        let code = py.detach(|| export_with_parameters(&path, &text, language, &overrides));
        code.map_err(|e| match e {
            ListingError::Diagnostics(d) => model_error(py, &path, &text, &d),
            e => pyo3::exceptions::PyValueError::new_err(e.to_string()),
        })
    }

    /// The right-hand side `ẏ = f(t, y)` of the first-order form, `y = [q; q̇]` (`2n`).
    fn rhs<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        y: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let y = finite("y", y.as_slice()?)?;
        let t = finite_time(t)?;
        let dy = self.with_instance(|m| {
            let dim = 2 * m.num_dofs();
            if y.len() != dim {
                return Err(format!("y has {} entries, the state has {dim}", y.len()));
            }
            let mut dy = vec![0.0; dim];
            m.as_ode_mut()
                .rhs(t, y, &mut dy)
                .map(|()| dy)
                .map_err(|e| e.to_string())
        })?;
        let dy = dy.map_err(pyo3::exceptions::PyValueError::new_err)?;
        Ok(PyArray1::from_vec(py, dy))
    }

    /// `M(q, t)` (`n × n`) and `F(q, q̇, t)` (`n`) of `M q̈ = F`.
    fn mass_matrix_and_forcing<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray1<'py, f64>,
        qdot: PyReadonlyArray1<'py, f64>,
        t: f64,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyArray1<f64>>)> {
        let (q, qdot) = (
            finite("q", q.as_slice()?)?,
            finite("qdot", qdot.as_slice()?)?,
        );
        let t = finite_time(t)?;
        let result = self.with_instance(|m| {
            let n = m.num_dofs();
            if q.len() != n || qdot.len() != n {
                return Err(format!(
                    "q and qdot must have {n} entries each, got {} and {}",
                    q.len(),
                    qdot.len()
                ));
            }
            let y: Vec<f64> = q.iter().chain(qdot).copied().collect();
            let (mass, forcing) = m.mass_matrix_and_forcing(t, &y);
            // nalgebra stores columns; the array is row-major.
            Ok((
                mass.transpose().as_slice().to_vec(),
                forcing.as_slice().to_vec(),
                n,
            ))
        })?;
        let (mass, forcing, n) = result.map_err(pyo3::exceptions::PyValueError::new_err)?;
        Ok((matrix(py, mass, n, n)?, PyArray1::from_vec(py, forcing)))
    }

    /// The kinetic and potential energies `(T, V)` (J) at `(t, y)`.
    fn energies(&self, t: f64, y: PyReadonlyArray1<'_, f64>) -> PyResult<(f64, f64)> {
        let y = finite("y", y.as_slice()?)?;
        let t = finite_time(t)?;
        let result = self.with_instance(|m| {
            if y.len() != 2 * m.num_dofs() {
                return Err(format!(
                    "y has {} entries, the state has {}",
                    y.len(),
                    2 * m.num_dofs()
                ));
            }
            Ok((m.kinetic_energy(t, y), m.potential_energy(t, y)))
        })?;
        result.map_err(pyo3::exceptions::PyValueError::new_err)
    }

    fn __repr__(&self) -> PyResult<String> {
        let name = self.name()?;
        Ok(format!(
            "<eomgen model `{name}` from {}>",
            self.loaded.source.path()
        ))
    }
}
