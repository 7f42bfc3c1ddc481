//! `eomgen study convolution MODEL --input NAME --forcing EXPR` (lecture 21): the response of
//! the model linearised at an equilibrium to an impulse, a step or any `f(t)` through one
//! input, by Duhamel's integral over the impulse response, against DOP853 on the same linear
//! equations and, for one degree of freedom, the closed form.
//!
//! The numbers come from [`eomgen::analysis::vibration::convolution_response`]; this module
//! parses the forcing (the model format's expressions of `t` and the parameters) and renders
//! text, JSON and a chart.

use clap::Args;
use eomgen::analysis::vibration::{self, ConvolutionError, ConvolutionOptions, ConvolutionStudy};
use eomgen::expressions::TimeFunction;
use eomgen::{FrfError, ModelInfo};

use crate::cli::error::CliError;
use crate::cli::files::Outputs;
use crate::cli::json::print_json_sorted;
use crate::cli::operating_point::OperatingPointArgs;
use crate::cli::plot::{Chart, Series, lines};
use crate::cli::render::num;

/// Options of `eomgen study convolution`.
#[derive(Debug, Args)]
pub struct ConvolutionArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any model file.
    pub model: String,
    /// The input, as for `frf`: a parameter that enters the forcing linearly (a load
    /// amplitude, `A` in `A*cos(w*t)`, whose time function `--forcing` replaces), or a
    /// coordinate's name (a unit generalized force on it). The equilibrium is found with the
    /// input set to 0.
    #[arg(long)]
    pub input: String,
    /// The forcing f(t): `impulse` (the unit impulse δ(t): the response is h), `step` (the
    /// unit step H(t)), or an expression of `t` (s) and the parameters in the model format's
    /// syntax (`sin(2*t)`, `step(t - 1)`, `exp(-t)`).
    #[arg(long, value_name = "EXPR")]
    pub forcing: String,
    #[command(flatten)]
    pub point: OperatingPointArgs,
    /// End time (s). Default: ten periods of the lowest natural frequency; in [1e-6, 1e6].
    #[arg(long, value_parser = crate::cli::values::study_end_time, allow_hyphen_values = true)]
    pub t_end: Option<f64>,
    /// Intervals of the time grid (4 to 100000); the quadrature's error falls as its fourth
    /// power, its cost grows as its square.
    #[arg(long, default_value_t = ConvolutionOptions::DEFAULT_INTERVALS, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(4..=100_000))]
    pub intervals: usize,
    /// Relative tolerance of the DOP853 check.
    #[arg(long, default_value_t = ConvolutionOptions::DEFAULT_RTOL, value_parser = crate::cli::values::relative_tolerance, allow_hyphen_values = true)]
    pub rtol: f64,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Chart of each coordinate against time: Duhamel, DOP853 and the closed form (.svg or
    /// .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
}

/// The error of a failed study of `model`, in the words of the options.
fn failure(model: &dyn ModelInfo, e: ConvolutionError) -> CliError {
    let name = &model.description().name;
    match e {
        ConvolutionError::NoInput
        | ConvolutionError::UnknownInput { .. }
        | ConvolutionError::Input(_)
        | ConvolutionError::InputEntersThroughRate { .. } => {
            CliError::usage(format!("--input: {e}"))
        }
        ConvolutionError::OperatingPoint(e) => {
            crate::cli::operating_point::point_failure(model, &e)
        }
        ConvolutionError::Linearization(FrfError::Modal(m)) => {
            crate::cli::operating_point::modal_failure(model, &m)
        }
        ConvolutionError::NoDuration { .. } => CliError::usage(format!("{e}: --t-end")),
        ConvolutionError::NonFiniteForcing { .. } => CliError::usage(format!("--forcing: {e}")),
        e => CliError::failure(format!("`{name}`: {e}")),
    }
}

/// Runs `study convolution`.
pub fn run(args: &ConvolutionArgs) -> Result<(), CliError> {
    Outputs::new()
        .input(&args.model)
        .chart("--plot", args.plot.as_deref())
        .check()?;
    let mut model = args.point.model(&args.model)?;
    let time_function = TimeFunction::parse(&args.forcing, "--forcing", model.as_ref())
        .map_err(|e| CliError::usage(e.to_string()))?;
    let operating_point = args.point.options(model.as_ref())?;
    let study = time_function
        .with_forcing(|forcing| {
            let options = ConvolutionOptions {
                operating_point,
                input: args.input.clone(),
                forcing,
                t_end: args.t_end,
                intervals: args.intervals,
                rtol: args.rtol,
            };
            vibration::convolution_response(model.as_mut(), &options)
        })
        .map_err(|e| failure(model.as_ref(), e))?;
    if let Some(path) = &args.plot {
        chart(path, model.as_ref(), &study).map_err(CliError::failure)?;
    }
    if args.json {
        return print_json_sorted(&study);
    }
    print_text(&mut crate::cli::output::stdout(), model.as_ref(), &study);
    Ok(())
}

/// One panel per coordinate would crowd a multi-dof chart: every coordinate's Duhamel and
/// DOP853 lines (and the closed form) share one chart.
fn chart(path: &str, model: &dyn ModelInfo, study: &ConvolutionStudy) -> Result<(), String> {
    let names = model.description().coordinate_names();
    let mut series = Vec::new();
    let history = |values: &[Vec<f64>], i: usize| -> Vec<(f64, f64)> {
        study
            .times
            .iter()
            .zip(values)
            .map(|(t, x)| (*t, x[i]))
            .collect()
    };
    for (i, name) in names.iter().enumerate() {
        series.push(Series {
            name: format!("δ{name}, Duhamel"),
            points: history(&study.convolution, i),
        });
        series.push(Series {
            name: format!("δ{name}, DOP853"),
            points: history(&study.direct, i),
        });
    }
    if let Some(c) = &study.closed_form {
        series.push(Series {
            name: "closed form".to_string(),
            points: study.times.iter().copied().zip(c.values.clone()).collect(),
        });
    }
    let title = format!(
        "{}: response to {} through {} (lecture 21)",
        model.description().name,
        study.forcing,
        study.input
    );
    lines(
        path,
        &Chart::linear(&title, "t (s)", "δq (m or rad)"),
        &series,
    )
}

/// The text of `study convolution`: the set-up, the modes, the quadrature, a table of eleven
/// times and the largest differences.
fn print_text(out: &mut impl std::io::Write, model: &dyn ModelInfo, study: &ConvolutionStudy) {
    let names = model.description().coordinate_names();
    let n = names.len();
    let t_end = study.times.last().copied().unwrap_or(0.0);
    let _ = writeln!(
        out,
        "model      {} ({n} dof) at {}: M δq̈ + C δq̇ + K δq = b f(t), input {}, f = {}",
        model.description().name,
        study.operating_point.name,
        study.input,
        study.forcing
    );
    let b: Vec<String> = study
        .forced
        .input_matrix
        .column(0)
        .iter()
        .map(|v| format!("{v:.6e}", v = num(v)))
        .collect();
    let _ = writeln!(
        out,
        "b          [{}] (generalized force per unit {})",
        b.join(", "),
        study.input
    );
    for (k, w) in study.natural_frequencies.iter().enumerate() {
        let zeta =
            study.damping_ratios[k].map_or("-".to_string(), |z| format!("{z:.6e}", z = num(z)));
        let _ = writeln!(
            out,
            "mode {:<5} ω = {:.10e} rad/s, ζ = {zeta}",
            k + 1,
            num(w)
        );
    }
    let q = &study.quadrature;
    let _ = writeln!(
        out,
        "grid       0 ≤ t ≤ {t_end:.6} s, {} intervals, Δ = {:.6e} s",
        study.times.len() - 1,
        num(q.step)
    );
    let _ = writeln!(
        out,
        "quadrature {}, order {}; Richardson error estimate {:.2e}{}",
        q.rule,
        q.order,
        num(q.error_estimate),
        q.observed_order.map_or(String::new(), |p| format!(
            " (order seen on Δ, 2Δ, 4Δ: {p:.2})"
        ))
    );
    print_table(out, &names, study);
    let scale = study.max_response;
    let relative = |d: f64| if scale > 0.0 { d / scale } else { d };
    let _ = writeln!(
        out,
        "largest |δq| = {:.6e}; max |Duhamel − DOP853| = {:.2e} ({:.1e} relative; DOP853 rtol {:.0e}, {} steps)",
        num(scale),
        num(study.max_difference),
        num(relative(study.max_difference)),
        num(study.direct_rtol),
        study.direct_steps
    );
    if let Some(c) = &study.closed_form {
        let _ = writeln!(
            out,
            "closed form {} (ω = {:.10e} rad/s, ζ = {:.6e}): max |Duhamel − closed form| = {:.2e} ({:.1e} relative)",
            c.formula,
            num(c.natural_frequency),
            num(c.damping_ratio),
            num(c.max_difference),
            num(relative(c.max_difference))
        );
    }
}

/// Eleven times of the response, evenly spread: each coordinate by Duhamel's integral and by
/// DOP853, and the closed form where there is one.
fn print_table(out: &mut impl std::io::Write, names: &[&str], study: &ConvolutionStudy) {
    let n = names.len();
    let mut header = format!("{:>12}", "t (s)");
    for name in names {
        header.push_str(&format!(
            "  {:>16}  {:>16}",
            format!("δ{name} Duhamel"),
            format!("δ{name} DOP853")
        ));
    }
    if study.closed_form.is_some() {
        header.push_str(&format!("  {:>16}", "closed form"));
    }
    let _ = writeln!(out, "{header}");
    let last = study.times.len() - 1;
    let mut rows: Vec<usize> = (0..=10).map(|r| r * last / 10).collect();
    rows.dedup();
    for j in rows {
        let mut line = format!("{:>12.6}", study.times[j]);
        for i in 0..n {
            line.push_str(&format!(
                "  {:>16.9e}  {:>16.9e}",
                num(study.convolution[j][i]),
                num(study.direct[j][i])
            ));
        }
        if let Some(c) = &study.closed_form {
            line.push_str(&format!("  {:>16.9e}", num(c.values[j])));
        }
        let _ = writeln!(out, "{line}");
    }
}
