//! Animations: the self-contained HTML page `eomgen animate` and `eomgen modes --animate`
//! write, built by the library (`eomgen::animation`) from the same simulation or modal
//! analysis.

use eomgen::OutputTimes;
use eomgen::analysis::vibration::{self, ModalOptions, OperatingPointOptions};
use eomgen::animation::{
    AnimationError, AnimationOptions, frame_times, modes_animation, simulation_animation,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::analysis_error;
use crate::model::{CoreModel, RunArgs, RunError, equilibrium_start, run_simulation};

/// An animation that cannot be made, in the Python API's words (the library's messages name
/// the command line's options).
fn animation_error(error: AnimationError) -> PyErr {
    use pyo3::exceptions::PyValueError;
    match error {
        AnimationError::InvalidFps { fps } => PyValueError::new_err(format!(
            "fps must be a positive number of frames per second, got {fps}"
        )),
        AnimationError::TooManyFrames { t_end, fps } => PyValueError::new_err(format!(
            "t_end = {t_end} s at fps = {fps} gives more than {} frames; lower fps",
            eomgen::animation::MAX_FRAMES
        )),
        AnimationError::UnknownTracePoint {
            name,
            model,
            points,
        } => PyValueError::new_err(format!(
            "trace: `{model}` has no point `{}` (points: {})",
            name.trim(),
            points.join(", ")
        )),
        AnimationError::NothingToDraw { model, points } => analysis_error(format!(
            "`{model}` has no `draw:` block, so there is nothing to animate; add `draw: {{ lines: [[A, B]] }}` with lines between its points ({}) to its model file, or name points to trace (trace=[...])",
            points.join(", ")
        )),
        other => analysis_error(other),
    }
}

/// Animates one simulation: the page and, when the integration stopped early, the
/// simulation's report (`{"summary", "t", …}` as `simulate` returns it) for the exception.
#[pyfunction]
#[pyo3(signature = (model, args, fps, trace))]
pub fn animate_simulation<'py>(
    py: Python<'py>,
    model: &CoreModel,
    args: RunArgs,
    fps: Option<f64>,
    trace: Vec<String>,
) -> PyResult<(Option<String>, Bound<'py, PyDict>)> {
    let options = AnimationOptions {
        fps: fps.unwrap_or(eomgen::animation::DEFAULT_FPS),
        trace,
    };
    let mut instance = model.fresh()?;
    options.frame_count(args.t_end()).map_err(animation_error)?;
    let times = frame_times(instance.as_ref(), args.t_end(), &options).map_err(animation_error)?;
    let run = args.options(OutputTimes::At(times))?;
    let model_ref = &mut instance;
    let (simulation, page) = py
        .detach(move || {
            let simulation = run_simulation(model_ref.as_mut(), &run)?;
            let page = simulation_animation(model_ref.as_ref(), &simulation, &options)
                .map(|animation| animation.map(|a| a.to_html()));
            Ok::<_, RunError>((simulation, page))
        })
        .map_err(RunError::into_py)?;
    let page = page.map_err(animation_error)?;
    let report = crate::model::simulation_dict(py, instance.as_ref(), simulation)?;
    Ok((page, report))
}

/// Animates the normal modes at an equilibrium: one clip per mode, `q* + s ψₖ sin(ωₖ t)`.
#[pyfunction]
#[pyo3(signature = (model, at = None, label = None, t = 0.0))]
pub fn animate_modes(
    py: Python<'_>,
    model: &CoreModel,
    at: Option<&Bound<'_, PyAny>>,
    label: Option<String>,
    t: f64,
) -> PyResult<String> {
    let options = OperatingPointOptions {
        start: equilibrium_start(at, label)?,
        t,
    };
    let mut instance = model.fresh()?;
    if vibration::is_steady_motion(instance.as_ref(), &options.start) {
        return Err(analysis_error(format!(
            "`{}` at this operating point is a steady motion (or has non-holonomic constraints): its modes are eigenvectors of the reduced state matrix, which are not drawn; `modes()` gives its eigenvalues",
            instance.description().name
        )));
    }
    let model_ref = &mut instance;
    let page = py.detach(move || {
        let model = model_ref.as_ref();
        let modal = vibration::modal_analysis(
            model,
            &ModalOptions {
                operating_point: options,
            },
        )
        .map_err(|e| analysis_error(format!("`{}`: {e}", model.description().name)))?;
        let animation = modes_animation(
            model,
            &modal.operating_point.equilibrium.q,
            &modal.normal_modes,
            &modal.mode_shape_matrix(),
            !modal.is_undamped(),
        )
        .map_err(animation_error)?;
        Ok::<_, PyErr>(animation.to_html())
    })?;
    Ok(page)
}
