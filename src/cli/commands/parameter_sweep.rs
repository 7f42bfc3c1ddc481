//! `eomgen study parameter-sweep MODEL --parameter v --values 0..10:201 [--at NAME]`: the
//! eigenvalues of an operating point against one parameter (the root locus of a steady
//! motion against speed), the values where the stability changes refined by bisection, and
//! a chart of their real and imaginary parts.
//!
//! The numbers come from [`eomgen::analysis::vibration::parameter_sweep`]; this file parses,
//! draws and prints.

use std::io::Write as _;

use clap::Args;
use eomgen::analysis::vibration::{
    self, Crossing, Direction, ParameterSweep, ParameterSweepError, ParameterSweepOptions,
    SweepAxis,
};
use eomgen::{ModelInfo, Stability};

use crate::cli::error::CliError;
use crate::cli::files::Outputs;
use crate::cli::json::print_json_sorted;
use crate::cli::operating_point::OperatingPointArgs;
use crate::cli::plot::{Chart, Series, lines};
use crate::cli::values::{evaluate, parameter_lookup};

/// Options of `eomgen study parameter-sweep`.
#[derive(Debug, Args)]
pub struct ParameterSweepArgs {
    /// A bundled model's name or the path of any model file.
    pub model: String,
    #[command(flatten)]
    pub point: OperatingPointArgs,
    /// The parameter to sweep.
    #[arg(long)]
    pub parameter: String,
    /// Its values, `LO..HI:N` (N values, ends included; `0..10:201`). 1 ≤ N ≤ 10000.
    #[arg(long, value_name = "LO..HI:N")]
    pub values: String,
    /// Chart of the real and imaginary parts of the eigenvalues against the parameter
    /// (`.svg` or `.png`).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `study parameter-sweep`.
pub fn run(args: &ParameterSweepArgs) -> Result<(), CliError> {
    Outputs::new()
        .input(&args.model)
        .chart("--plot", args.plot.as_deref())
        .check()?;
    let mut model = args.point.model(&args.model)?;
    let axis = parse_values(&args.parameter, &args.values, model.as_ref())?;
    let options = ParameterSweepOptions {
        axis,
        operating_point: args.point.options(model.as_ref())?,
        refine: true,
    };
    let bar = crate::cli::render::progress_bar(
        options.axis.values.len(),
        "{msg} [{bar:40}] {pos}/{len} values",
        "parameter sweep",
        args.json,
    );
    let sweep = vibration::parameter_sweep(model.as_mut(), &options, |done, _| {
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    let sweep = sweep.map_err(|e| match e {
        ParameterSweepError::UnknownParameter { .. } => {
            CliError::usage(format!("--parameter: {e}"))
        }
        // The error and hint of `modes`, which refuses the same equations.
        ParameterSweepError::TimeDependent { source, .. } => {
            crate::cli::operating_point::modal_failure(model.as_ref(), &source)
        }
        e => CliError::failure(format!("`{}`: {e}", model.description().name)),
    })?;
    if let Some(path) = &args.plot {
        root_locus(path, &sweep).map_err(CliError::failure)?;
    }
    if args.json {
        return print_json_sorted(&SweepJson {
            sweep: &sweep,
            chart: &args.plot,
        });
    }
    print_text(&sweep, args.plot.as_deref());
    Ok(())
}

/// What `study parameter-sweep --json` prints: the library's sweep and the chart written.
#[derive(serde::Serialize)]
struct SweepJson<'a> {
    #[serde(flatten)]
    sweep: &'a ParameterSweep,
    /// The chart written (`--plot`).
    chart: &'a Option<String>,
}

/// `LO..HI:N` of the parameter `name` (bounds may be expressions of the parameters).
fn parse_values(name: &str, spec: &str, model: &dyn ModelInfo) -> Result<SweepAxis, CliError> {
    let bad = || {
        CliError::usage(format!(
            "--values: `{spec}` is not LO..HI:N (for example `0..10:201`)"
        ))
    };
    let lookup = parameter_lookup(model);
    let (range, count) = spec.rsplit_once(':').ok_or_else(bad)?;
    let (lo, hi) = range.split_once("..").ok_or_else(bad)?;
    let lo = evaluate(lo.trim(), "--values", &lookup)?;
    let hi = evaluate(hi.trim(), "--values", &lookup)?;
    let count: usize = count.trim().parse().map_err(|_| bad())?;
    SweepAxis::linear(name, lo, hi, count).map_err(|_| {
        CliError::usage(format!(
            "--values: need 1 ≤ N ≤ 10000 values and finite LO < HI, got `{spec}`"
        ))
    })
}

/// The table: one line per value (verdict, then the eigenvalues with `Im s ≥ 0`), then the
/// stability changes.
fn print_text(sweep: &ParameterSweep, chart: Option<&str>) {
    let mut out = crate::cli::output::stdout();
    let _ = writeln!(
        out,
        "{} at {}: eigenvalues s (1/s) against {}",
        sweep.model, sweep.operating_point, sweep.parameter
    );
    for p in &sweep.points {
        let verdict = match p.stability {
            Some(Stability::Stable { .. }) => "stable",
            Some(Stability::MarginallyStable) => "marginal",
            Some(Stability::Unstable { .. }) => "unstable",
            None => "failed",
        };
        let values: Vec<String> = p
            .eigenvalues
            .iter()
            .filter(|s| s.im >= 0.0)
            .map(|s| {
                if s.im == 0.0 {
                    decimals(s.re, 8)
                } else {
                    format!("{}±{}i", decimals(s.re, 8), decimals(s.im, 8))
                }
            })
            .collect();
        let tail = match &p.error {
            Some(e) => e.clone(),
            None => values.join("  "),
        };
        let _ = writeln!(out, "{:>14}  {verdict:<9} {tail}", decimals(p.value, 8));
    }
    if sweep.stability_changes.is_empty() {
        let _ = writeln!(out, "stability changes: none in this range");
    }
    for c in &sweep.stability_changes {
        let kind = match c.eigenvalue {
            Crossing::Real => "a real eigenvalue crosses 0".to_string(),
            Crossing::Pole => "a real eigenvalue passes through infinity (a pole: a stiffness or an inertia of the linearisation is singular there)".to_string(),
            Crossing::Complex => format!("a complex pair crosses at ±{:.10}i", c.frequency),
        };
        let direction = match c.direction {
            Direction::Stabilising => "stabilising",
            Direction::Destabilising => "destabilising",
        };
        let _ = writeln!(
            out,
            "stability change  {} = {}: {kind}, {direction} as {} grows",
            sweep.parameter,
            decimals(c.value, 14),
            sweep.parameter
        );
    }
    if let Some(path) = chart {
        let _ = writeln!(out, "chart      {path}");
    }
}

/// `v` with `digits` decimals, or in exponent form with as many significant digits where
/// that would print more than a few digits before the point (1e200 is not 200 digits).
fn decimals(v: f64, digits: usize) -> String {
    if v.is_finite() && v.abs() >= 1e6 {
        format!("{v:.digits$e}")
    } else {
        format!("{v:.digits$}")
    }
}

/// The root locus against the parameter: every tracked eigenvalue's real part (solid) and
/// imaginary part (its own series), against the parameter.
fn root_locus(path: &str, sweep: &ParameterSweep) -> Result<(), String> {
    let tracked = sweep.tracked();
    let mut series = Vec::new();
    for (k, slot) in tracked.iter().enumerate() {
        series.push(Series {
            name: format!("Re s{}", k + 1),
            points: slot.iter().map(|(v, s)| (*v, s.re)).collect(),
        });
    }
    for (k, slot) in tracked.iter().enumerate() {
        if slot.iter().any(|(_, s)| s.im > 0.0) {
            series.push(Series {
                name: format!("Im s{}", k + 1),
                points: slot.iter().map(|(v, s)| (*v, s.im)).collect(),
            });
        }
    }
    let title = format!(
        "{} at {}: eigenvalues against {}",
        sweep.model, sweep.operating_point, sweep.parameter
    );
    let x = sweep.parameter.clone();
    lines(
        path,
        &Chart::linear(&title, &x, "Re s (1/s), Im s (rad/s)"),
        &series,
    )
}
