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
use eomgen::analysis::{GaitBifurcation, GaitError, GaitOptions};
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
    /// For a model with a change of support (`support:`): the landings in one period of the
    /// gait followed (1: a period-one gait; 2 after a period doubling).
    #[arg(long, default_value_t = 1)]
    pub steps: usize,
}

/// Runs `study parameter-sweep`.
pub fn run(args: &ParameterSweepArgs) -> Result<(), CliError> {
    Outputs::new()
        .input(&args.model)
        .chart("--plot", args.plot.as_deref())
        .check()?;
    let found = crate::cli::model::find_model(&args.model)?;
    if !found.description().supports.is_empty() {
        return gait_sweep(args, found);
    }
    drop(found);
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

/// `study parameter-sweep` on a model with a change of support: its gait followed over the
/// parameter from the model's initial state ([`eomgen::analysis::gait_sweep()`]).
fn gait_sweep(args: &ParameterSweepArgs, mut model: Box<dyn ModelInfo>) -> Result<(), CliError> {
    if args.point.at.is_some() || args.plot.is_some() {
        return Err(CliError::usage(format!(
            "--at and --plot do not apply to a gait (`{}` changes its support): the sweep follows the gait from the model's initial state",
            model.description().name
        )));
    }
    crate::cli::values::set_parameters(model.as_mut(), &args.point.set)?;
    let axis = parse_values(&args.parameter, &args.values, model.as_ref())?;
    let options = GaitOptions {
        steps: args.steps,
        ..GaitOptions::default()
    };
    let bar = crate::cli::render::progress_bar(
        axis.values.len(),
        "{msg} [{bar:40}] {pos}/{len} values",
        "gait sweep",
        args.json,
    );
    let sweep = eomgen::analysis::gait_sweep(model.as_mut(), &axis, &options, |done, _| {
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    let sweep = sweep.map_err(|e| match e {
        GaitError::UnknownParameter { .. } => CliError::usage(format!("--parameter: {e}")),
        GaitError::InvalidOptions { .. } => CliError::usage(e.to_string()),
        e => CliError::failure(format!("`{}`: {e}", model.description().name)),
    })?;
    if args.json {
        return print_json_sorted(&sweep);
    }
    let mut out = crate::cli::output::stdout();
    let _ = writeln!(
        out,
        "{}: its gait of {} step{} per period against {}, the eigenvalues λ of the return map (|λ| < 1: stable)",
        sweep.model,
        sweep.steps,
        if sweep.steps == 1 { "" } else { "s" },
        sweep.parameter
    );
    for p in &sweep.points {
        let verdict = p.stability.map_or("failed", |s| s.as_str());
        let tail = match (&p.error, p.period) {
            (Some(e), _) => e.clone(),
            (None, period) => {
                let values: Vec<String> = (p.eigenvalues.iter())
                    .filter(|l| l.im >= 0.0 && l.norm() > 1e-9)
                    .map(|l| {
                        if l.im == 0.0 {
                            decimals(l.re, 8)
                        } else {
                            format!("{}±{}i", decimals(l.re, 8), decimals(l.im, 8))
                        }
                    })
                    .collect();
                format!(
                    "T = {:.9}  {}",
                    period.unwrap_or(f64::NAN),
                    values.join("  ")
                )
            }
        };
        let _ = writeln!(out, "{:>14}  {verdict:<22} {tail}", decimals(p.value, 8));
    }
    if sweep.stability_changes.is_empty() {
        let _ = writeln!(out, "stability changes: none in this range");
    }
    for c in &sweep.stability_changes {
        let kind = match c.kind {
            GaitBifurcation::PeriodDoubling => "a period doubling (an eigenvalue through −1)",
            GaitBifurcation::Fold => "a fold (an eigenvalue through +1)",
            GaitBifurcation::NeimarkSacker => {
                "a Neimark–Sacker bifurcation (a complex pair leaves the unit circle)"
            }
        };
        let direction = if c.stable_below {
            "stable below"
        } else {
            "stable above"
        };
        let _ = writeln!(
            out,
            "stability change  {} = {} (in [{}, {}]): {kind}, {direction}; λ = {:.6}{:+.6}i",
            sweep.parameter,
            decimals(c.value, 10),
            decimals(c.bracket[0], 10),
            decimals(c.bracket[1], 10),
            c.eigenvalue[0],
            c.eigenvalue[1]
        );
    }
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
