//! The animation page of `eomgen animate MODEL -o FILE.html`, `eomgen modes MODEL --animate
//! FILE.html` and the report, with the command line's arguments: the page is the library's
//! ([`eomgen::animation`]); here are the integration with `simulate`'s options, the mapping
//! of its errors to exit statuses and `--gif`, the same animation as an animated GIF for
//! slides.

use eomgen::animation::{
    Animation, AnimationError, AnimationOptions, frame_times, modes_animation, simulation_animation,
};
use eomgen::text::short;
use eomgen::{ModelInfo, NormalModes, OutputTimes};
use nalgebra::DMatrix;

mod animated_gif;

pub(super) use animated_gif::write_gif;
pub(super) use eomgen::animation::DEFAULT_FPS;

use super::error::CliError;
use super::integration::{self, IntegrationArgs, failure_error};

/// The error of the command line for `error`: a usage error (exit 2) for a model that cannot
/// be drawn or options that cannot be met, a failure (exit 1) otherwise.
fn cli_error(error: AnimationError) -> CliError {
    match error {
        AnimationError::NoPoints { .. }
        | AnimationError::NothingToDraw { .. }
        | AnimationError::UnknownTracePoint { .. }
        | AnimationError::InvalidFps { .. }
        | AnimationError::TooManyFrames { .. } => CliError::usage(error.to_string()),
        _ => CliError::failure(error.to_string()),
    }
}

/// The animation of a simulation of `model_name` with `args`, frames at `t = k / fps`,
/// `trace` the points to trace instead of the file's.
///
/// Returns the animation (`None` when not even the first frame was computed) and, when the
/// integration failed, its error (as `simulate` reports it, saying that the frames before
/// it are in the animation).
///
/// # Errors
/// Usage errors of `simulate`, an `fps` that is not positive or gives more than
/// [`eomgen::animation::MAX_FRAMES`] frames, a model without `draw:`; a failure when a
/// position is not finite.
pub(crate) fn simulation(
    model_name: &str,
    args: &IntegrationArgs,
    fps: f64,
    trace: &[String],
) -> Result<(Option<Animation>, Option<CliError>), CliError> {
    let options = AnimationOptions {
        fps,
        trace: trace.to_vec(),
    };
    // The options before the model, the model's drawing before integrating.
    options.frame_count(args.t_end).map_err(cli_error)?;
    let times = frame_times(
        super::model::find_model(model_name)?.as_ref(),
        args.t_end,
        &options,
    )
    .map_err(cli_error)?;
    let (model, run) = integration::simulation(model_name, args, OutputTimes::At(times))?;
    let animation = simulation_animation(model.as_ref(), &run, &options).map_err(cli_error)?;
    let failure = run.failure.as_ref().map(|e| {
        let kept = match &animation {
            None => "no frame was computed, so no animation was written".to_string(),
            Some(animation) => {
                let t = animation.clips()[0].times();
                format!(
                    "the {} frames computed before it (t = 0 … {} s) are in the animation",
                    t.len(),
                    short(t[t.len() - 1])
                )
            }
        };
        failure_error(
            &model.description().name,
            e,
            run.cause.as_ref(),
            args,
            &kept,
        )
    });
    Ok((animation, failure))
}

/// The animation of the normal modes at the equilibrium `q` ([`modes_animation`]).
///
/// # Errors
/// A usage error for a model that cannot be drawn; a failure when a displaced configuration
/// is not finite or there is no mode.
pub(crate) fn modes(
    model: &dyn ModelInfo,
    q: &[f64],
    modes: &NormalModes,
    shapes: &DMatrix<f64>,
    c_left_out: bool,
) -> Result<Animation, CliError> {
    modes_animation(model, q, modes, shapes, c_left_out).map_err(cli_error)
}
