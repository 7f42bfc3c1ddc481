//! `eomgen study constraint-methods MODEL` (issue 5, item 6; lectures 8–11, HW10): the study is
//! [`eomgen::analysis::constraint_methods_with_reduced()`]; the reduced model of method II.2 is
//! [`eomgen::reduction::reduced_twin()`] (the constraints eliminated symbolically, compiled at
//! run time) and the minimal twin is the one the model file names (`minimal_twin:`). This
//! module renders the table, the JSON and the chart.

use std::io::Write as _;

use clap::Args;
use eomgen::analysis::{
    ConstraintMethodRow, ConstraintMethods, ConstraintMethodsError, ConstraintMethodsOptions,
    StudyRuns,
};
use eomgen::reduction::ReducedTwin;
use eomgen::studies::minimal_twin;

use crate::cli::error::CliError;
use crate::cli::json::print_json_sorted;
use crate::cli::plot;
use crate::cli::render::num;

/// Options of `eomgen study constraint-methods`.
#[derive(Debug, Args)]
pub struct ConstraintMethodsArgs {
    /// A model with holonomic constraints (`simple_pendulum_cartesian`, `two_masses_rod`, …):
    /// a bundled name or the path of any model file.
    pub model: String,
    /// End time (s), in [1e-6, 1e6].
    #[arg(long, default_value_t = ConstraintMethodsOptions::DEFAULT_T_END, value_parser = crate::cli::values::study_end_time, allow_hyphen_values = true)]
    pub t_end: f64,
    /// Relative and absolute tolerance of every run (Dormand–Prince 5(4)).
    #[arg(long, default_value_t = ConstraintMethodsOptions::DEFAULT_TOL, value_parser = crate::cli::values::relative_tolerance, allow_hyphen_values = true)]
    pub tol: f64,
    /// Spring stiffnesses of method I, comma separated.
    #[arg(long, value_delimiter = ',', value_parser = crate::cli::values::stiffness, allow_hyphen_values = true, default_values_t = ConstraintMethodsOptions::DEFAULT_STIFFNESS)]
    pub stiffness: Vec<f64>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Chart of the position error against time, one line per method (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
}

/// Runs `study constraint-methods`: [`eomgen::analysis::constraint_methods()`] on the model
/// and the minimal twin its file names, rendered as a table, JSON and a chart.
pub fn run(args: &ConstraintMethodsArgs) -> Result<(), CliError> {
    // The twin is read too: its file, named in the model's, is an input no output may
    // overwrite, so it is found before the outputs are checked.
    let source = crate::cli::model::open_model(&args.model)?;
    crate::cli::model::smooth_only(source.instantiate().as_ref(), "`study constraint-methods`")?;
    let twin = minimal_twin(&source).map_err(|e| CliError::failure(e.to_string()))?;
    let twin_file = match &twin {
        Some((_, eomgen::ModelSource::File { path, .. })) => Some(path.as_str()),
        _ => None,
    };
    twin_file
        .into_iter()
        .fold(
            crate::cli::files::Outputs::new().input(&args.model),
            |outputs, path| outputs.input(path),
        )
        .chart("--plot", args.plot.as_deref())
        .check()?;
    let options = ConstraintMethodsOptions {
        t_end: args.t_end,
        tol: args.tol,
        stiffness: args.stiffness.clone(),
    };
    // Method II.2 where the constraints can be eliminated; a model whose constraints cannot
    // (trigonometric in every coordinate) has no such row, and the reason is said.
    let reduced = match eomgen::reduction::reduced_twin(&source) {
        Ok(r) => Some(r),
        Err(e) => {
            if !args.json {
                crate::cli::output::errln!("note: no II.2 row: {e}");
            }
            None
        }
    };
    let label = reduced.as_ref().map(eomgen::reduction::ReducedTwin::label);
    let study = eomgen::analysis::constraint_methods_with_reduced(
        &mut || source.instantiate(),
        reduced
            .as_ref()
            .zip(label.as_deref())
            .map(|(r, label)| (label, r.instantiate())),
        twin.as_ref()
            .map(|(name, twin)| (name.as_str(), twin.instantiate())),
        &options,
    )
    .map_err(study_error)?;
    if let Some(path) = &args.plot {
        draw_chart(path, &study.model, &study.rows)?;
    }
    if args.json {
        print_json_sorted(&study.summary(&options))?;
    } else {
        print_text(args, &study, reduced.as_ref());
    }
    study
        .check_measured()
        .map_err(|e| CliError::failure(e.to_string()))
}

/// The CLI's error for a study that could not run: a usage error for what the options or the
/// model got wrong, a failure otherwise.
fn study_error(e: ConstraintMethodsError) -> CliError {
    match e {
        ConstraintMethodsError::NoHolonomicConstraints { model } => CliError::usage(format!(
            "`{model}` has no holonomic constraints to compare methods on; try simple_pendulum_cartesian or two_masses_rod"
        )),
        ConstraintMethodsError::InvalidOptions { .. } => {
            CliError::usage("--t-end and --tol must be positive")
        }
        ConstraintMethodsError::InvalidStiffness { stiffness } => CliError::usage(format!(
            "--stiffness: every stiffness must be a positive number, got {:e}",
            num(stiffness)
        )),
        other => CliError::failure(other.to_string()),
    }
}

/// The chart of `--plot`: each method's largest point position error against time.
///
/// # Errors
/// A chart that cannot be written.
fn draw_chart(path: &str, model: &str, rows: &[ConstraintMethodRow]) -> Result<(), CliError> {
    let series: Vec<plot::Series> = rows
        .iter()
        .map(|r| plot::Series {
            name: r.method.clone(),
            points: r.error_history.clone(),
        })
        .collect();
    let title = format!("{model}: constraint methods, position error");
    plot::lines(
        path,
        &plot::Chart {
            title: &title,
            x_desc: "t (s)",
            y_desc: "largest point position error (m)",
            log_x: false,
            log_y: true,
        },
        &series,
    )
    .map_err(CliError::failure)?;
    Ok(())
}

/// The study as a table on standard output, with the II.2 row's eliminations.
fn print_text(
    args: &ConstraintMethodsArgs,
    study: &ConstraintMethods,
    reduced: Option<&ReducedTwin>,
) {
    let ConstraintMethods {
        model,
        reference_tol,
        agreement,
        rows,
    } = study;
    let (reference_tol, agreement) = (*reference_tol, *agreement);
    let mut stdout = crate::cli::output::stdout();
    let _ = writeln!(
        stdout,
        "model      {} over 0 ≤ t ≤ {} s, Dormand–Prince 5(4) at rtol = atol = {:e}",
        model,
        args.t_end,
        num(args.tol)
    );
    let _ = writeln!(
        stdout,
        "reference  DAE with Baumgarte at tol {reference_tol:e}; the unstabilised DAE at that tolerance agrees to {agreement:.2e} m",
        reference_tol = num(reference_tol),
        agreement = num(agreement)
    );
    if let Some(r) = reduced {
        for e in &r.reduced.eliminations {
            let _ = writeln!(
                stdout,
                "II.2       {} = {} (from `{}`), {}_dot = {}",
                e.coordinate, e.solution, e.constraint, e.coordinate, e.rate
            );
        }
    }
    let _ = writeln!(
        stdout,
        "{:<44} {:>12} {:>12} {:>10} {:>8} {:>10}",
        "method", "pos. err (m)", "max |Φ|", "RHS evals", "steps", "time (ms)"
    );
    for r in rows {
        // A failed run measured nothing: `failed` in its error and drift columns, never
        // the 0.00 of an empty run.
        let (error, drift) = if r.failure.is_some() {
            ("failed".to_string(), "failed".to_string())
        } else {
            (
                format!("{:.2e}", num(r.position_error)),
                r.drift
                    .map_or("-".to_string(), |d| format!("{d:.2e}", d = num(d))),
            )
        };
        let _ = writeln!(
            stdout,
            "{:<44} {:>12} {:>12} {:>10} {:>8} {:>10.3}{}",
            r.method,
            error,
            drift,
            r.rhs_evals,
            r.steps,
            r.wall_time_s * 1e3,
            r.failure
                .as_ref()
                .map_or(String::new(), |f| format!("  failed: {f}"))
        );
    }
}
