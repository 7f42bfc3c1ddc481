//! `eomgen study free-response MODEL` (HW28, lectures 22–26): the free response of the
//! linearised, undamped equations `M δq̈ + K δq = 0` at an equilibrium computed four ways —
//! DOP853 on the linear equations, `e^{At}`, superposed modes of `M⁻¹K` and superposed
//! mass-normalised modes — their largest differences, and a chart of every coordinate.
//!
//! The numbers come from [`eomgen::analysis::vibration::free_response()`]; this module renders them. Also
//! the pieces `study modal-damping` shares: `--init` parsing, the errors in the options' words
//! and the stacked charts.

use clap::Args;
use eomgen::analysis::StudyRuns;
use eomgen::analysis::vibration::{
    self, FreeResponseMethod, FreeResponseOptions, FreeResponseStudy,
};
use eomgen::{ModeKind, ModelInfo};

use crate::cli::error::CliError;
use crate::cli::files::Outputs;
use crate::cli::json::print_json_sorted;
use crate::cli::operating_point::OperatingPointArgs;
use crate::cli::plot::Series;
use crate::cli::render::num;
use crate::cli::response_study::{Panel, panels, parse_init, study_failure};

/// Options of `eomgen study free-response`.
#[derive(Debug, Args)]
pub struct FreeResponseArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any model file.
    pub model: String,
    #[command(flatten)]
    pub point: OperatingPointArgs,
    /// Initial deviation from the operating point: `NAME=VALUE` for a coordinate (`x=0.1`) or a
    /// rate (`x_dot=0.2`), comma separated or repeated; the others 0. Default: 0.1 (m or rad)
    /// for every coordinate, at rest.
    #[arg(long, value_name = "NAME=VALUE,…")]
    pub init: Vec<String>,
    /// End time (s). Default: four periods of the slowest oscillatory mode, or the time an
    /// unstable mode grows by e⁵ if that is shorter, else 10 s; in [1e-6, 1e6].
    #[arg(long, value_parser = crate::cli::values::study_end_time, allow_hyphen_values = true)]
    pub t_end: Option<f64>,
    /// Number of output times, evenly spaced from 0 to the end time (2 to 1000000).
    #[arg(long, default_value_t = FreeResponseOptions::DEFAULT_SAMPLES, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(2..=1_000_000))]
    pub samples: usize,
    /// Relative and absolute tolerance of the DOP853 integration.
    #[arg(long, default_value_t = FreeResponseOptions::DEFAULT_TOL, value_parser = crate::cli::values::relative_tolerance, allow_hyphen_values = true)]
    pub tol: f64,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Chart of each coordinate against time, the four responses overlaid (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
}

/// Runs `study free-response`.
pub fn run(args: &FreeResponseArgs) -> Result<(), CliError> {
    Outputs::new()
        .input(&args.model)
        .chart("--plot", args.plot.as_deref())
        .check()?;
    let model = args.point.model(&args.model)?;
    let options = FreeResponseOptions {
        operating_point: args.point.options(model.as_ref())?,
        initial: parse_init(model.as_ref(), &args.init)?,
        t_end: args.t_end,
        samples: args.samples,
        tol: args.tol,
    };
    let study = vibration::free_response(model.as_ref(), &options)
        .map_err(|e| study_failure(model.as_ref(), &e))?;
    study
        .check_measured()
        .map_err(|e| CliError::failure(e.to_string()))?;
    let (label, responses) = (&study.operating_point.name, &study.responses);
    let n = model.num_dofs();
    let names = model.description().coordinate_names();
    if let Some(path) = &args.plot {
        let panel_list: Vec<Panel> = (0..n)
            .map(|j| {
                let series = responses
                    .iter()
                    .map(|(method, r)| Series {
                        name: method.name().to_string(),
                        points: r.coordinate_history(j),
                    })
                    .collect();
                Panel {
                    caption: None,
                    y_desc: format!("δ{} (m or rad)", names[j]),
                    series,
                }
            })
            .collect();
        let title = format!(
            "{} at {label}: free response four ways (HW28)",
            model.description().name
        );
        panels(path, &title, &panel_list).map_err(CliError::failure)?;
    }
    let mut stdout = crate::cli::output::stdout();
    if args.json {
        print_json_sorted(&study.summary(model.as_ref()))
    } else {
        print_text(&mut stdout, model.as_ref(), &study);
        Ok(())
    }
}

/// The text of `study free-response`: the set-up, the modes, the methods and their largest
/// differences.
fn print_text(stdout: &mut impl std::io::Write, model: &dyn ModelInfo, study: &FreeResponseStudy) {
    let FreeResponseStudy {
        operating_point: point,
        normal_modes: modes,
        ignored_damping,
        initial,
        t_end,
        responses,
        max_displacement: q_scale,
        max_velocity: v_scale,
        differences,
        ..
    } = study;
    let (label, (q0, v0)) = (&point.name, (&initial.q, &initial.qdot));
    let n = model.num_dofs();
    let names = model.description().coordinate_names();
    let samples = responses[0].1.times.len();
    let _ = writeln!(
        stdout,
        "model      {} ({} dof) at {label}: M δq̈ + K δq = 0, 0 ≤ t ≤ {t_end:.6} s, {} samples",
        model.description().name,
        n,
        samples
    );
    if *ignored_damping > 0.0 {
        let _ = writeln!(
            stdout,
            "note       the damping matrix (max |C| = {ignored_damping:.3e}) is left out here; see `eomgen study modal-damping`",
            ignored_damping = num(ignored_damping)
        );
    }
    let fmt = |v: &[f64]| -> String {
        names
            .iter()
            .zip(v)
            .map(|(c, x)| format!("{c} = {x:.6e}", x = num(x)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let _ = writeln!(stdout, "initial    δq: {}", fmt(q0));
    let _ = writeln!(stdout, "           δq̇: {}", fmt(v0));
    for k in 0..n {
        let what = match modes.kinds[k] {
            ModeKind::Oscillatory => format!(
                "ω = {:.10e} rad/s: a cos ωt + b sin ωt/ω",
                num(modes.natural_frequencies[k])
            ),
            ModeKind::ZeroFrequency => "zero-frequency: a + b t".to_string(),
            ModeKind::Unstable { growth_rate } => {
                format!(
                    "unstable, σ = {growth_rate:.10e} 1/s: a cosh σt + b sinh σt/σ",
                    growth_rate = num(growth_rate)
                )
            }
        };
        let _ = writeln!(stdout, "mode {:<5} {what}", k + 1);
    }
    for (i, method) in FreeResponseMethod::ALL.iter().enumerate() {
        let _ = writeln!(
            stdout,
            "method {}    {}: {}",
            i + 1,
            method.name(),
            method.description()
        );
    }
    let _ = writeln!(
        stdout,
        "largest |δq| = {q_scale:.6e}, |δq̇| = {v_scale:.6e}; max differences (absolute, relative):",
        q_scale = num(q_scale),
        v_scale = num(v_scale)
    );
    for d in differences {
        let _ = writeln!(
            stdout,
            "  {:<14} vs {:<14} δq {:>9.2e} ({:>8.1e})   δq̇ {:>9.2e} ({:>8.1e})",
            d.a.name(),
            d.b.name(),
            num(d.displacement),
            num(d.displacement_relative),
            num(d.velocity),
            num(d.velocity_relative)
        );
    }
}
