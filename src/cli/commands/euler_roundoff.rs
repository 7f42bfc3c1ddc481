//! `eomgen study euler-roundoff` (HW1; syllabus lecture 4): the study is
//! [`eomgen::analysis::euler_roundoff`] (its module docs give the split of the error into
//! truncation and roundoff); this module renders its table, JSON and chart.

use std::f64::consts::E;
use std::io::Write as _;

use clap::Args;
use eomgen::analysis::StudyRuns;
use eomgen::analysis::roundoff::{
    EulerRoundoff, RoundoffError, RoundoffOptions, RoundoffRow, euler_roundoff,
};

use crate::cli::error::CliError;
use crate::cli::files::Outputs;
use crate::cli::json::print_json_sorted;
use crate::cli::plot;
use crate::cli::plot::log_y_chart;
use crate::cli::render::num;

/// Options of `eomgen study euler-roundoff`.
#[derive(Debug, Args)]
pub struct EulerRoundoffArgs {
    /// Largest n: steps h = 10⁻ⁿ for n = 0 … N, so 10ᴺ steps per method at the end
    /// (at most 8; 7 takes about 3 s, 8 about 30 s in a release build).
    #[arg(long, default_value_t = RoundoffOptions::DEFAULT_MAX_N)]
    pub max_n: u32,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Chart of |x(1) − e| against n with the reference lines (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
}

/// Runs `eomgen study euler-roundoff`.
pub fn run(args: &EulerRoundoffArgs) -> Result<(), CliError> {
    Outputs::new()
        .chart("--plot", args.plot.as_deref())
        .check()?;
    let study = euler_roundoff(&RoundoffOptions { max_n: args.max_n }).map_err(|e| match e {
        RoundoffError::MaxNTooLarge { largest, .. } => CliError::usage(format!(
            "--max-n must be at most {largest} (10ⁿ steps per method)"
        )),
        other => CliError::failure(other.to_string()),
    })?;
    study
        .check_measured()
        .map_err(|e| CliError::failure(e.to_string()))?;
    let EulerRoundoff {
        rows,
        summary: summaries,
        notes,
    } = &study;

    if let Some(path) = &args.plot {
        plot_errors(path, rows)?;
    }
    let mut stdout = crate::cli::output::stdout();
    if args.json {
        print_json_sorted(&study.summary())?;
    } else {
        let _ = writeln!(
            stdout,
            "x' = x, x(0) = 1 on [0, 1], h = 10⁻ⁿ: error x(1) − e = truncation (exact-arithmetic Φ(h)ᴺ − e) + roundoff (x(1) − Φ(h)ᴺ); ε = {:e}",
            num(f64::EPSILON)
        );
        let _ = writeln!(
            stdout,
            "{:>3} {:>11} | {:>10} {:>10} {:>10} {:>10} | {:>10} {:>10} | {:>10} {:>10} | {:>10} {:>10} | {:>10} {:>10}",
            "n",
            "steps",
            "euler err",
            "truncation",
            "e h/2",
            "roundoff",
            "midpt err",
            "roundoff",
            "rk4 err",
            "roundoff",
            "ε√N",
            "εN",
            "f32 euler",
            "ε₃₂√N"
        );
        for r in rows {
            let [euler, midpoint, rk4] = [&r.runs[0], &r.runs[1], &r.runs[2]];
            let _ = writeln!(
                stdout,
                "{:>3} {:>11} | {:>10.2e} {:>10.2e} {:>10.2e} {:>10.2e} | {:>10.2e} {:>10.2e} | {:>10.2e} {:>10.2e} | {:>10.2e} {:>10.2e} | {:>10.2e} {:>10.2e}",
                r.n,
                r.steps,
                num(euler.error),
                num(euler.truncation),
                num(-E * r.h / 2.0),
                num(euler.roundoff),
                num(midpoint.error),
                num(midpoint.roundoff),
                num(rk4.error),
                num(rk4.roundoff),
                num(r.epsilon_sqrt_steps),
                num(r.epsilon_steps),
                num(r.single_precision_euler.error),
                num(r.single_precision_euler.epsilon_sqrt_steps)
            );
        }
        for s in summaries {
            let _ = writeln!(
                stdout,
                "{:<9} optimal n = {} (|error| {:.2e}); roundoff grows as N^{}",
                s.method,
                s.optimal_n,
                num(s.smallest_error),
                s.roundoff_exponent
                    .map_or("? (too few n above the floor)".to_string(), |a| format!(
                        "{a:.2}"
                    ))
            );
        }
        for note in notes {
            let _ = writeln!(stdout, "note: {note}");
        }
    }
    Ok(())
}

fn plot_errors(path: &str, rows: &[RoundoffRow]) -> Result<(), CliError> {
    let mut series: Vec<plot::Series> = (0..3)
        .map(|i| plot::Series {
            name: format!("{} |x(1) − e|", rows[0].runs[i].method),
            points: rows
                .iter()
                .map(|r| (f64::from(r.n), r.runs[i].error.abs()))
                .collect(),
        })
        .collect();
    let line = |name: &str, f: &dyn Fn(&RoundoffRow) -> f64| plot::Series {
        name: name.to_string(),
        points: rows.iter().map(|r| (f64::from(r.n), f(r))).collect(),
    };
    series.push(line("e h/2", &|r| E * r.h / 2.0));
    series.push(line("e h²/6", &|r| E * r.h * r.h / 6.0));
    series.push(line("ε √N", &|r| r.epsilon_sqrt_steps));
    series.push(line("ε N", &|r| r.epsilon_steps));
    series.push(line("euler in f32 (loop) |x(1) − e|", &|r| {
        r.single_precision_euler.error.abs()
    }));
    series.push(line("ε₃₂ √N", &|r| {
        r.single_precision_euler.epsilon_sqrt_steps
    }));
    log_y_chart(
        path,
        [
            "x' = x on [0, 1], h = 10⁻ⁿ: truncation falls, roundoff rises",
            "n (h = 10⁻ⁿ, N = 10ⁿ steps)",
            "|x(1) − e|",
        ],
        false,
        &series,
    )
}
