//! `eomgen study work-precision MODEL` (issue 6): error against work for every integration
//! method on a model; the study is [`eomgen::analysis::work_precision`](mod@eomgen::analysis::work_precision) (its module docs give
//! the error norm and the references), this module parses the options and renders the
//! tables, the JSON and the charts.

use std::io::Write;

use clap::Args;
use eomgen::ModelInfo;
use eomgen::analysis::StudyRuns;
use eomgen::analysis::work_precision::{
    AtTarget, DEFAULT_METHODS, MAX_REPEATS, Measured, MethodRuns, SMALLEST_TOLERANCE,
    WorkPrecision, WorkPrecisionError, WorkPrecisionOptions, decades, work_precision,
};

use crate::cli::error::CliError;
use crate::cli::integration::Method;
use crate::cli::model::find_smooth_model;
use crate::cli::plot;
use crate::cli::render::num;

/// A measure of work of a run: RHS evaluations or wall time.
type Work = fn(&Measured) -> f64;

/// A study that could not run, as the CLI reports it (naming the options to change).
fn study_error(args: &WorkPrecisionArgs, error: WorkPrecisionError) -> CliError {
    match error {
        WorkPrecisionError::InvalidEndTime { t_end } => CliError::usage(format!(
            "--t-end must be a positive number of seconds, got {:e}",
            num(t_end)
        )),
        WorkPrecisionError::NoSamples => CliError::usage("--samples must be at least 1"),
        WorkPrecisionError::InvalidTargetError { target_error } => CliError::usage(format!(
            "--target-error must be positive, got {:e}",
            num(target_error)
        )),
        WorkPrecisionError::InvalidReferenceTolerance { reference_tol } => {
            CliError::usage(format!(
                "--reference-tol must be in (0, 1e-6), far tighter than the tolerances studied, got {:e}",
                num(reference_tol)
            ))
        }
        WorkPrecisionError::InvalidBaseline { baseline_ms } => CliError::usage(format!(
            "--baseline-ms must be positive, got {:e}",
            num(baseline_ms)
        )),
        WorkPrecisionError::InvalidMinTime { .. } => CliError::usage(format!(
            "--min-time-ms must be in [0, 10000], got {:e}",
            num(args.min_time_ms)
        )),
        WorkPrecisionError::InitialState(e) => crate::cli::integration::simulation_error(e),
        e @ WorkPrecisionError::ReferenceFailed { .. } => CliError::failure(format!(
            "{e}; try a looser --reference-tol or a shorter --t-end"
        )),
        e @ WorkPrecisionError::ReferenceNotVerified { .. } => CliError::failure(format!(
            "{e}; try a shorter --t-end, a larger --target-error or another --reference-tol"
        )),
        e @ WorkPrecisionError::NoMotion { .. } => CliError::failure(e.to_string()),
        other => CliError::usage(other.to_string()),
    }
}

/// Options of `eomgen study work-precision MODEL`.
#[derive(Debug, Args)]
pub struct WorkPrecisionArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any model file.
    pub model: String,
    /// Methods to compare, comma separated (default: bs32, dp54, dop853, vern6, vern7, vern8,
    /// vern9, taylor, radau5, rk4, stormer-verlet).
    #[arg(long, value_parser = crate::cli::integration::method_parser(), value_delimiter = ',', default_values_t = DEFAULT_METHODS)]
    pub methods: Vec<Method>,
    /// Tolerances of the adaptive methods (`rtol = atol = tol`): `A..B`, every decade from A
    /// to B (e.g. `1e-3..1e-12`), or a comma-separated list; each in (0, 1).
    #[arg(long, default_value_t = default_tols(), allow_hyphen_values = true)]
    pub tols: String,
    /// Step counts N of the fixed-step methods (step `h = t_end / N`): `A..B`, doubling from
    /// A up to B (e.g. `64..65536`), or a comma-separated list of positive integers. Default
    /// by the method's order p, to span a comparable range of errors: `64..65536` for p ≥ 3,
    /// `256..4194304` for p = 2, `1024..4194304` for p = 1.
    #[arg(long)]
    pub steps: Option<String>,
    /// End time T (s), in [1e-6, 1e6].
    #[arg(long, default_value_t = WorkPrecisionOptions::DEFAULT_T_END, value_parser = crate::cli::values::study_end_time, allow_hyphen_values = true)]
    pub t_end: f64,
    /// Number S of equally spaced output times `k T / S`, k = 1…S, at which errors are taken
    /// (1 to 100000).
    #[arg(long, default_value_t = WorkPrecisionOptions::DEFAULT_SAMPLES, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=100_000))]
    pub samples: usize,
    /// Error at which the work of every method is interpolated (same norm as the table).
    #[arg(long, default_value_t = WorkPrecisionOptions::DEFAULT_TARGET_ERROR)]
    pub target_error: f64,
    /// A wall time (ms) to compare the time at the target error with (issue 6's anchor:
    /// `--baseline-ms 60`, MuJoCo's RK4 on the double pendulum over 10 s).
    #[arg(long, value_name = "MS")]
    pub baseline_ms: Option<f64>,
    /// Tolerance of the reference solution (DOP853, and Dormand–Prince 5(4) as its check).
    #[arg(long, default_value_t = WorkPrecisionOptions::DEFAULT_REFERENCE_TOL)]
    pub reference_tol: f64,
    /// Fewest timed runs per setting; the reported time is their median (1 to 1000).
    #[arg(long, default_value_t = WorkPrecisionOptions::DEFAULT_REPEATS, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=1000))]
    pub repeats: usize,
    /// Runs of one setting are repeated until their total wall time reaches this (ms, 0 to
    /// 10000), at most 1000 times.
    #[arg(long, default_value_t = WorkPrecisionOptions::DEFAULT_MIN_TIME_S * 1e3, value_parser = crate::cli::values::min_time_ms, allow_hyphen_values = true)]
    pub min_time_ms: f64,
    /// Print JSON instead of the tables.
    #[arg(long)]
    pub json: bool,
    /// Write the charts `PREFIX-evals.svg/.png` (error against RHS evaluations) and
    /// `PREFIX-time.svg/.png` (error against wall time), log–log, one line per method.
    #[arg(long, value_name = "PREFIX")]
    pub plot: Option<String>,
}

/// `--tols`' default, the library's range written as `A..B`.
fn default_tols() -> String {
    let (a, b) = WorkPrecisionOptions::DEFAULT_TOLERANCE_RANGE;
    format!("{a:e}..{b:e}")
}

/// Parses `--tols`: `A..B` (every decade from A towards B, either direction) or a comma list.
/// Returned loosest first, without repeats.
///
/// # Errors
/// A usage error naming the bad entry; every tolerance must be finite and in (0, 1).
fn parse_tols(text: &str) -> Result<Vec<f64>, CliError> {
    let bad = |what: &str| {
        CliError::usage(format!(
            "--tols `{text}`: {what}; write a range of decades like `1e-3..1e-12` or a list like `1e-4,1e-6,1e-8`"
        ))
    };
    let number = |s: &str| -> Result<f64, CliError> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| bad(&format!("`{}` is not a number", s.trim())))?;
        if v.is_finite() && (SMALLEST_TOLERANCE..1.0).contains(&v) {
            Ok(v)
        } else {
            Err(bad(&format!(
                "{v:e} is not a tolerance in [{SMALLEST_TOLERANCE:e}, 1) (f64 cannot deliver less)"
            )))
        }
    };
    let mut tols = if let Some((a, b)) = text.split_once("..") {
        let (a, b) = (number(a)?, number(b)?);
        decades(a, b)
            .ok_or_else(|| bad("the two ends of a range must be a whole number of decades apart"))?
    } else {
        text.split(',').map(number).collect::<Result<Vec<_>, _>>()?
    };
    tols.sort_by(|a, b| b.total_cmp(a));
    tols.dedup();
    Ok(tols)
}

/// Parses `--steps`: `A..B` (A, 2A, 4A, … up to B) or a comma list of step counts. Returned
/// in increasing order (largest step first), without repeats.
///
/// # Errors
/// A usage error naming the bad entry; every count must be a positive integer, at most 10⁸.
fn parse_steps(text: &str) -> Result<Vec<usize>, CliError> {
    let bad = |what: &str| {
        CliError::usage(format!(
            "--steps `{text}`: {what}; write a doubling range of step counts like `64..65536` or a list like `100,1000,10000`"
        ))
    };
    let number = |s: &str| -> Result<usize, CliError> {
        match s.trim().parse::<usize>() {
            Ok(n) if (1..=100_000_000).contains(&n) => Ok(n),
            _ => Err(bad(&format!(
                "`{}` is not a step count from 1 to 10⁸",
                s.trim()
            ))),
        }
    };
    let mut steps = if let Some((a, b)) = text.split_once("..") {
        let (a, b) = (number(a)?, number(b)?);
        let (lo, hi) = (a.min(b), a.max(b));
        std::iter::successors(Some(lo), |n| Some(n * 2).filter(|m| *m <= hi)).collect()
    } else {
        text.split(',').map(number).collect::<Result<Vec<_>, _>>()?
    };
    steps.sort_unstable();
    steps.dedup();
    Ok(steps)
}

/// Runs `eomgen study work-precision MODEL`.
///
/// # Errors
/// Usage errors (exit 2) for a bad `--tols`, `--steps`, `--t-end`, `--samples`,
/// `--target-error`, `--reference-tol`, `--baseline-ms` or `--min-time-ms`; failures (exit 1)
/// when the reference cannot be computed or its check does not agree with it far below the
/// target error (`agreement > target_error / 100`), or a chart cannot be written. A method
/// that fails at a setting is reported in its row, never an error of the study.
pub fn run(args: &WorkPrecisionArgs) -> Result<(), CliError> {
    let mut options = WorkPrecisionOptions {
        methods: args.methods.clone(),
        tolerances: Vec::new(),
        steps: None,
        t_end: args.t_end,
        samples: args.samples,
        target_error: args.target_error,
        baseline_ms: args.baseline_ms,
        reference_tol: args.reference_tol,
        repeats: args.repeats,
        min_time_s: args.min_time_ms * 1e-3,
    };
    options.validate().map_err(|e| study_error(args, e))?;
    if let Some(prefix) = &args.plot {
        ["evals", "time"]
            .iter()
            .flat_map(|tag| ["svg", "png"].map(|ext| chart_path(prefix, tag, ext)))
            .fold(
                crate::cli::files::Outputs::new().input(&args.model),
                |outputs, path| outputs.chart("--plot", Some(&path)),
            )
            .check()?;
    }
    options.tolerances = parse_tols(&args.tols)?;
    options.steps = args.steps.as_deref().map(parse_steps).transpose()?;
    let mut model = find_smooth_model(&args.model, "`study work-precision`")?;
    // The runs take seconds to minutes: a bar on a terminal, nothing otherwise.
    let bar = crate::cli::render::progress_bar(
        0,
        "{msg} [{bar:30}] {pos}/{len} runs ({elapsed}, eta {eta})",
        "work-precision",
        args.json,
    );
    let report = work_precision(model.as_mut(), &options, &mut |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    let report = report.map_err(|e| study_error(args, e))?;
    let study = Study {
        args,
        model: model.as_ref(),
        report,
    };
    let num_unresolved = study.report.num_unresolved();
    let agreement = study.report.agreement;
    if num_unresolved > 0 {
        crate::cli::output::errln!(
            "warning: {num_unresolved} run(s) have an error below 10 × the reference's agreement ({agreement:.2e}): the reference does not resolve them, their errors are upper bounds at best (marked `!` in the table, `\"resolved\": false` in JSON)",
            agreement = num(agreement)
        );
    }
    if let Some(prefix) = &args.plot {
        write_charts(
            prefix,
            &study.model.description().name,
            &study.report.results,
        )?;
    }
    if args.json {
        crate::cli::json::print_json_sorted(&study.report.summary(study.model, &options))?;
    } else {
        // A failed write (a pipe into `head` closed) is kept by `output` and sets the status.
        let _ = study.write_text(&mut crate::cli::output::stdout());
    }
    study.report.check_measured().map_err(|e| {
        CliError::failure(format!(
            "{e}; try tolerances between 1e-3 and 1e-13{}",
            if args.steps.is_some() {
                " or more steps"
            } else {
                ""
            }
        ))
    })
}

/// Everything the study measured, for the table and the JSON.
struct Study<'a> {
    args: &'a WorkPrecisionArgs,
    model: &'a dyn ModelInfo,
    report: WorkPrecision,
}

impl Study<'_> {
    /// Whether a run's error is within 10× of the reference's agreement.
    fn unresolved(&self, m: &Measured) -> bool {
        self.report.unresolved(m)
    }

    /// The header, the table of runs and the table of work at the target error.
    fn write_text(&self, out: &mut impl Write) -> std::io::Result<()> {
        let args = self.args;
        writeln!(
            out,
            "model      {} ({} dof) over 0 ≤ t ≤ {} s",
            self.model.description().name,
            self.model.num_dofs(),
            args.t_end
        )?;
        writeln!(
            out,
            "error      max over the {s} output times k·T/{s} and over all {} components of y = [q; q̇] of |y − y_ref|",
            self.report.dim,
            s = args.samples
        )?;
        writeln!(
            out,
            "reference  DOP853 at rtol = atol = {:e} ({} steps); Dormand–Prince 5(4) at the same tolerance agrees to {:.2e}",
            num(args.reference_tol),
            self.report.reference_steps,
            num(self.report.agreement)
        )?;
        writeln!(
            out,
            "time       median wall time of ≥ {} identical runs totalling ≥ {} ms (at most {MAX_REPEATS} runs)",
            self.report.min_repeats, args.min_time_ms
        )?;
        let drift_note = if self.model.description().conservative {
            ""
        } else {
            " (not conserved: the model has non-conservative loads or explicit time dependence)"
        };
        writeln!(
            out,
            "drift      energy drift max|E − E(0)| / max(T + |V|) over the output times{drift_note}\n"
        )?;
        writeln!(
            out,
            "{:<22} {:>13} {:>10} {:>11} {:>9} {:>11} {:>12}",
            "method", "tol or h", "error", "RHS evals", "steps", "time (ms)", "energy drift"
        )?;
        for r in &self.report.results {
            let name = r.method.display_name();
            for run in &r.runs {
                let setting = run.setting.label();
                match &run.outcome {
                    Ok(m) => writeln!(
                        out,
                        "{name:<22} {setting:>13} {:>9.2e}{} {:>11} {:>9} {:>11.3} {:>12}",
                        num(m.error),
                        if self.unresolved(m) { "!" } else { " " },
                        m.rhs_evals,
                        m.steps,
                        m.wall_time_s * 1e3,
                        m.energy_drift
                            .map_or("-".to_string(), |d| format!("{d:.2e}", d = num(d)))
                    )?,
                    Err(f) => writeln!(out, "{name:<22} {setting:>13}   failed: {}", f.message)?,
                }
            }
        }
        writeln!(
            out,
            "\nwork to reach an error of {:e} (log–log interpolation between the bracketing settings)",
            num(args.target_error)
        )?;
        let baseline_header = args.baseline_ms.map_or(String::new(), |b| {
            format!(" {:>16}", format!("{b} ms / time"))
        });
        writeln!(
            out,
            "{:<22} {:>11} {:>9} {:>11}{baseline_header}",
            "method", "RHS evals", "steps", "time (ms)"
        )?;
        for r in &self.report.results {
            let name = r.method.display_name();
            match r.at_target {
                AtTarget::Reached {
                    rhs_evals,
                    steps,
                    wall_time_s,
                } => {
                    let ratio = args.baseline_ms.map_or(String::new(), |b| {
                        format!(" {:>16.1}", b * 1e-3 / wall_time_s)
                    });
                    let evals = rhs_evals.map_or("-".to_string(), |e| format!("{e:.0}"));
                    writeln!(
                        out,
                        "{name:<22} {evals:>11} {steps:>9.0} {:>11.3}{ratio}",
                        wall_time_s * 1e3
                    )?;
                }
                _ => writeln!(out, "{name:<22} {}", r.at_target.note())?,
            }
        }
        Ok(())
    }
}

/// The chart `PREFIX-{tag}.{ext}` of `--plot PREFIX`.
fn chart_path(prefix: &str, tag: &str, ext: &str) -> String {
    format!("{prefix}-{tag}.{ext}")
}

/// Writes `PREFIX-evals.{svg,png}` and `PREFIX-time.{svg,png}`: the error of every
/// successful run against its RHS evaluations and its median wall time, log–log.
fn write_charts(prefix: &str, model: &str, results: &[MethodRuns]) -> Result<(), CliError> {
    let series = |work: Work| -> Vec<plot::Series> {
        results
            .iter()
            .map(|r| plot::Series {
                name: r.method.display_name().to_string(),
                points: r
                    .runs
                    .iter()
                    .filter_map(|run| run.outcome.as_ref().ok())
                    .map(|m| (work(m), m.error))
                    .collect(),
            })
            .collect()
    };
    let charts: [(&str, &str, Work); 2] = [
        ("evals", "RHS evaluations", |m| m.rhs_evals as f64),
        ("time", "median wall time (ms)", |m| m.wall_time_s * 1e3),
    ];
    for (tag, x_desc, work) in charts {
        let data = series(work);
        let title = format!("{model}: work–precision ({x_desc})");
        for ext in ["svg", "png"] {
            let path = chart_path(prefix, tag, ext);
            plot::lines(
                &path,
                &plot::Chart {
                    title: &title,
                    x_desc,
                    y_desc: "max |y − y_ref| over the output times",
                    log_x: true,
                    log_y: true,
                },
                &data,
            )
            .map_err(CliError::failure)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decade_ranges_are_exact_and_loosest_first() {
        assert_eq!(parse_tols("1e-3..1e-6").unwrap(), [1e-3, 1e-4, 1e-5, 1e-6]);
        assert_eq!(parse_tols("1e-6..1e-3").unwrap(), [1e-3, 1e-4, 1e-5, 1e-6]);
        assert_eq!(parse_tols("1e-8,1e-4,1e-4").unwrap(), [1e-4, 1e-8]);
        assert_eq!(parse_tols("2e-3..2e-5").unwrap().len(), 3);
        for bad in [
            "",
            "abc",
            "1e-3..",
            "0",
            "1..1e-3",
            "1e-3..3e-5",
            "nan",
            "-1e-3",
        ] {
            let e = parse_tols(bad).unwrap_err();
            assert_eq!(e.code, 2, "{bad}");
            assert!(e.message.contains("--tols"), "{}", e.message);
        }
    }

    #[test]
    fn step_ranges_double() {
        assert_eq!(parse_steps("16..128").unwrap(), [16, 32, 64, 128]);
        assert_eq!(parse_steps("16..100").unwrap(), [16, 32, 64]);
        assert_eq!(parse_steps("1000,10,100").unwrap(), [10, 100, 1000]);
        for bad in ["0..8", "x", "1.5", "-4", ""] {
            assert_eq!(parse_steps(bad).unwrap_err().code, 2, "{bad}");
        }
    }
}
