//! `eomgen study launch MODEL [--speeds V1,V2,…]` (lecture 2, HW2): for each launch speed,
//! the range against the launch angle, the best angle θ* by golden-section search on the
//! range, and the best path's apex and landing angle — what the path tends to as v0 → ∞ —
//! with charts of the best paths (`--plot`) and of the range curves (`--range-plot`).
//!
//! The numbers come from [`eomgen::analysis::launch::launch_study`]; this file parses, draws
//! and prints.

use std::io::Write as _;

use clap::Args;
use eomgen::analysis::StudyRuns;
use eomgen::analysis::launch::{LaunchError, LaunchOptions, LaunchStudy, Shot, launch_study};

use crate::cli::error::CliError;
use crate::cli::files::Outputs;
use crate::cli::json::print_json_sorted;
use crate::cli::model::find_smooth_model;
use crate::cli::plot::{Chart, Series, lines};
use crate::cli::values::{evaluate, parameter_lookup, set_parameters};

/// Options of `eomgen study launch`.
#[derive(Debug, Args)]
pub struct LaunchArgs {
    /// A bundled model's name or the path of any model file.
    pub model: String,
    /// Launch speeds (m/s), comma separated. Default: the model's value of the speed
    /// parameter.
    #[arg(
        long,
        value_name = "V1,V2,…",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub speeds: Vec<f64>,
    /// The launch-angle parameter (rad from the horizontal; set by the model's `initial:`).
    #[arg(long, default_value = "theta0")]
    pub angle_parameter: String,
    /// The launch-speed parameter (m/s).
    #[arg(long, default_value = "v0")]
    pub speed_parameter: String,
    /// The model event whose first zero is the landing (made terminal for the study).
    #[arg(long, default_value = "ground")]
    pub event: String,
    /// The horizontal coordinate: the range is its change from launch to landing.
    #[arg(long, default_value = "x")]
    pub range_coordinate: String,
    /// The vertical coordinate: the apex is where its rate falls through 0.
    #[arg(long, default_value = "y")]
    pub height_coordinate: String,
    /// Number of angles of the range curve, evenly spaced inside (0°, 90°) (3 to 10000).
    #[arg(long, default_value_t = LaunchOptions::DEFAULT_ANGLES, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(3..=10_000))]
    pub angles: usize,
    /// Width of the golden-section search's final bracket around θ* (rad).
    #[arg(long, default_value_t = LaunchOptions::DEFAULT_ANGLE_TOL, value_parser = crate::cli::values::relative_tolerance, allow_hyphen_values = true)]
    pub angle_tol: f64,
    /// Relative and absolute tolerance of the DOP853 integrations.
    #[arg(long, default_value_t = LaunchOptions::DEFAULT_RTOL, value_parser = crate::cli::values::relative_tolerance, allow_hyphen_values = true)]
    pub rtol: f64,
    /// The longest flight (s); a flight that has not landed by then fails the study.
    #[arg(long, default_value_t = LaunchOptions::DEFAULT_T_MAX, value_parser = crate::cli::values::study_end_time, allow_hyphen_values = true)]
    pub t_max: f64,
    /// A launch angle (rad; an expression such as `pi/3`) at which each speed's path is also
    /// reported and drawn: the shape at a fixed angle as v0 grows.
    #[arg(long, default_value = "pi/4", allow_hyphen_values = true)]
    pub shape_angle: String,
    /// Set a parameter, `NAME=VALUE`; repeatable (`--set c2=0` leaves linear drag only).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Chart of the paths at θ* and at the shape angle for each speed, both axes divided by
    /// the path's range (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
    /// Chart of the range, divided by the best range, against the angle at each speed.
    #[arg(long, value_name = "FILE")]
    pub range_plot: Option<String>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `study launch`.
pub fn run(args: &LaunchArgs) -> Result<(), CliError> {
    Outputs::new()
        .input(&args.model)
        .chart("--plot", args.plot.as_deref())
        .chart("--range-plot", args.range_plot.as_deref())
        .check()?;
    let mut model = find_smooth_model(&args.model, "`study launch`")?;
    set_parameters(model.as_mut(), &args.set)?;
    let options = LaunchOptions {
        speeds: args.speeds.clone(),
        angle_parameter: args.angle_parameter.clone(),
        speed_parameter: args.speed_parameter.clone(),
        event: args.event.clone(),
        range_coordinate: args.range_coordinate.clone(),
        height_coordinate: args.height_coordinate.clone(),
        angles: args.angles,
        angle_tol: args.angle_tol,
        rtol: args.rtol,
        t_max: args.t_max,
        shape_angle: Some(evaluate(
            &args.shape_angle,
            "--shape-angle",
            &parameter_lookup(model.as_ref()),
        )?),
        ..LaunchOptions::default()
    };
    let study = launch_study(model.as_mut(), &options).map_err(|e| match e {
        LaunchError::UnknownParameter { role: "angle", .. } => {
            CliError::usage(format!("--angle-parameter: {e}"))
        }
        LaunchError::UnknownParameter { .. } => CliError::usage(format!("--speed-parameter: {e}")),
        LaunchError::UnknownEvent { .. } => CliError::usage(format!("--event: {e}")),
        LaunchError::UnknownCoordinate { role: "range", .. } => {
            CliError::usage(format!("--range-coordinate: {e}"))
        }
        LaunchError::UnknownCoordinate { .. } => {
            CliError::usage(format!("--height-coordinate: {e}"))
        }
        LaunchError::InvalidSpeed { .. } => CliError::usage(format!("--speeds: {e}")),
        LaunchError::InvalidShapeAngle { .. } => CliError::usage(format!("--shape-angle: {e}")),
        e => CliError::failure(format!("`{}`: {e}", model.description().name)),
    })?;
    study
        .check_measured()
        .map_err(|e| CliError::failure(e.to_string()))?;
    if let Some(path) = &args.plot {
        paths_chart(path, &study).map_err(CliError::failure)?;
    }
    if let Some(path) = &args.range_plot {
        range_chart(path, &study).map_err(CliError::failure)?;
    }
    if args.json {
        return print_json_sorted(&study);
    }
    print_text(&study);
    Ok(())
}

/// The paths at θ* and at the shape angle, each scaled by its range: the shape, whatever the
/// size.
fn paths_chart(path: &str, study: &LaunchStudy) -> Result<(), String> {
    let scaled = |shot: &Shot| -> Vec<(f64, f64)> {
        shot.path
            .iter()
            .map(|[x, y]| (x / shot.range, y / shot.range))
            .collect()
    };
    let mut series = Vec::new();
    for s in &study.speeds {
        series.push(Series {
            name: format!(
                "v0 = {} m/s, θ* = {:.2}°",
                s.speed,
                s.best.angle.to_degrees()
            ),
            points: scaled(&s.best),
        });
        if let Some(shot) = &s.at_shape_angle {
            series.push(Series {
                name: format!("v0 = {} m/s, θ = {:.2}°", s.speed, shot.angle.to_degrees()),
                points: scaled(shot),
            });
        }
    }
    let title = format!("{}: paths scaled by their range (HW2)", study.model);
    lines(path, &Chart::linear(&title, "x / R", "y / R"), &series)
}

/// The range curves, each divided by its best range, against the angle in degrees.
fn range_chart(path: &str, study: &LaunchStudy) -> Result<(), String> {
    let series: Vec<Series> = study
        .speeds
        .iter()
        .map(|s| Series {
            name: format!("v0 = {} m/s", s.speed),
            points: s
                .curve
                .iter()
                .map(|p| (p.angle.to_degrees(), p.range / s.best.range))
                .collect(),
        })
        .collect();
    let title = format!("{}: range against launch angle (HW2)", study.model);
    lines(path, &Chart::linear(&title, "θ (deg)", "R / R*"), &series)
}

/// The table: one line per speed.
fn print_text(study: &LaunchStudy) {
    let mut out = crate::cli::output::stdout();
    let grid = study.speeds.first().map_or(0, |s| s.curve.len());
    let _ = writeln!(
        out,
        "model      {}: launch angle `{}`, speed `{}`, landing at `{}`; range = change of `{}`",
        study.model,
        study.angle_parameter,
        study.speed_parameter,
        study.event,
        study.range_coordinate
    );
    let _ = writeln!(
        out,
        "method     DOP853 (rtol = atol = {:e}); {grid} angles inside (0°, 90°), then golden-section search on R(θ) to a bracket of {:e} rad",
        study.rtol, study.angle_tol
    );
    let _ = writeln!(
        out,
        "{:>12} {:>15} {:>16} {:>13} {:>10} {:>13} {:>14}",
        "v0 (m/s)", "θ (deg)", "R (m)", "T (s)", "x_apex/R", "y_apex/R", "landing (deg)"
    );
    for s in &study.speeds {
        let shots =
            std::iter::once(("θ*", &s.best)).chain(s.at_shape_angle.iter().map(|a| ("", a)));
        for (mark, b) in shots {
            let (fraction, height) = match (b.apex_fraction, b.apex) {
                (Some(f), Some(a)) => (format!("{f:.6}"), format!("{:.6e}", a.y / b.range)),
                _ => ("-".to_string(), "-".to_string()),
            };
            let _ = writeln!(
                out,
                "{:>12} {:>2} {:>12.8} {:>16.10e} {:>13.6e} {:>10} {:>13} {:>14.6}",
                s.speed,
                mark,
                b.angle.to_degrees(),
                b.range,
                b.flight_time,
                fraction,
                height,
                b.landing_angle.to_degrees()
            );
        }
    }
    let _ = writeln!(
        out,
        "θ*: the best angle at that speed, found to the bracket above; the other row: the shape angle\nshape      a parabola has x_apex/R = 0.5 and lands at its launch angle; a straight rise and a vertical fall has x_apex/R → 1, y_apex/R → tan θ and lands at 90°"
    );
}
