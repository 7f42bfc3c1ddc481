//! `eomgen frf MODEL --input NAME`: the frequency response `H(ω) = (K − ω²M + iωC)⁻¹ B` from
//! a load parameter to coordinates, its resonance peaks, a Bode chart, the response assembled
//! mode by mode (`--modal`), and points of the curve checked by simulating the full model
//! (`--simulate K`) (lecture 21, HW21, HW34, HW37).

use std::io::{IsTerminal as _, Write as _};

use clap::Args;
use eomgen::{
    FrequencySweep, FrfError, HarmonicForcing, ModalResponse, ModelInfo, PeakAmplitude,
    SteadyStateOptions, frequency_response, frequency_sweep, linearize_with_inputs,
    log_frequencies, modal_damping, modal_frequency_response, normal_modes, phase_degrees,
    settling_time, simulate_steady_state,
};
use nalgebra::Complex;
use plotters::prelude::*;
use rayon::prelude::*;
use serde_json::{Value, json};

use super::modes::{OperatingPointArgs, point_json};
use super::values::{evaluate, parameter_lookup};
use super::{CliError, plot};

/// Options of `eomgen frf`.
#[derive(Debug, Args)]
pub struct FrfArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any model file.
    pub model: String,
    /// The input: a parameter that enters the forcing linearly (a load amplitude, `A` in
    /// `A*cos(w*t)`; its time function is taken at t = 0, so for `A*cos(w*t)` the response is
    /// the steady state under `A cos(ω t)`), or a coordinate's name: a unit generalized force
    /// on that coordinate (no `--simulate` then: the model has no load to drive). The
    /// equilibrium (`--at`) is found with the input set to 0.
    #[arg(long)]
    pub input: String,
    /// An output coordinate; repeatable (default: every coordinate).
    #[arg(long = "output", value_name = "NAME")]
    pub outputs: Vec<String>,
    #[command(flatten)]
    pub point: OperatingPointArgs,
    /// Frequency range `LO..HI` (rad/s, expressions of the parameters allowed; default: a
    /// decade below the lowest to a decade above the highest natural frequency).
    #[arg(long, value_name = "LO..HI")]
    pub freqs: Option<String>,
    /// Frequencies of the sweep, spaced evenly in log ω.
    #[arg(long, default_value_t = 400)]
    pub points: usize,
    /// Also evaluate the response at this frequency (rad/s, an expression such as
    /// `sqrt(2*k/m)` or `w`); repeatable. With `--modal`, the modal breakdown is given here.
    #[arg(long = "frequency", value_name = "W")]
    pub frequencies: Vec<String>,
    /// The response assembled mode by mode, `Σ ψ_k ψ_kᵀ b / (ω_k² − ω² + 2iζ_k ω_k ω)`, with
    /// each mode's contribution, at the `--frequency` values (default: the damped peaks).
    #[arg(long)]
    pub modal: bool,
    /// Check K frequencies of the curve (log-spaced over the range) by simulating the full
    /// model to steady state, in parallel.
    #[arg(long, value_name = "K")]
    pub simulate: Option<usize>,
    /// The parameter holding the forcing frequency, set to each ω by `--simulate` (default:
    /// `w` if the model has it).
    #[arg(long, value_name = "NAME")]
    pub frequency_parameter: Option<String>,
    /// The input's value in the `--simulate` runs (small, so that the nonlinear model stays
    /// near its linearisation).
    #[arg(long, default_value_t = 1e-3)]
    pub amplitude: f64,
    /// Relative tolerance of the `--simulate` runs (DOP853).
    #[arg(long, default_value_t = 1e-11)]
    pub rtol: f64,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Bode chart (log ω; log |H| and phase in degrees, two panels), `.svg` or `.png`.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
}

/// One simulated point.
struct Simulated {
    frequency: f64,
    settling_time: f64,
    /// Per output: (simulated X / amplitude, predicted H).
    values: Vec<(Complex<f64>, Complex<f64>)>,
    steps: usize,
    rhs_evals: usize,
}

fn fail(model: &str) -> impl Fn(FrfError) -> CliError + '_ {
    move |e| CliError::failure(format!("`{model}`: {e}"))
}

/// Runs `frf`.
pub fn run(args: &FrfArgs) -> Result<(), CliError> {
    let mut model = args.point.model(&args.model)?;
    if args.points < 2 {
        return Err(CliError::usage("--points must be at least 2"));
    }
    let parameter_input = model.parameter_names().contains(&args.input.as_str());
    if !parameter_input && !model.coordinate_names().contains(&args.input.as_str()) {
        return Err(CliError::usage(format!(
            "--input {}: `{}` has no parameter or coordinate `{}` (parameters: {}; coordinates: {})",
            args.input,
            model.name(),
            args.input,
            model.parameter_names().join(", "),
            model.coordinate_names().join(", ")
        )));
    }
    if !parameter_input && args.simulate.is_some() {
        return Err(CliError::usage(format!(
            "--simulate needs a load parameter as --input (`{}` is a coordinate: a unit generalized force has no load in the model to drive)",
            args.input
        )));
    }
    let name = model.name().to_string();
    let name = name.as_str();
    let (label, guess) = args.point.guess(model.as_ref())?;
    let forced = linearize_with_inputs(model.as_mut(), &guess, &[args.input.as_str()]).map_err(
        |e| match e {
            FrfError::NonlinearInput { .. }
            | FrfError::InputNotInForcing { .. }
            | FrfError::InputChangesMassMatrix { .. } => {
                CliError::usage(format!("--input {}: {e}", args.input))
            }
            FrfError::Modal(m) => super::modes::modal_failure(model.as_ref(), &m),
            e => fail(name)(e),
        },
    )?;
    let lin = &forced.linearization;
    let b = forced.input_matrix.column(0).into_owned();
    let coordinates: Vec<String> = model
        .coordinate_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let outputs: Vec<(String, usize)> = if args.outputs.is_empty() {
        coordinates
            .iter()
            .enumerate()
            .map(|(i, c)| (c.to_string(), i))
            .collect()
    } else {
        let mut list = Vec::new();
        for o in &args.outputs {
            let i = eomgen::frf::output_index(model.as_ref(), o)
                .map_err(|e| CliError::usage(format!("--output {o}: {e}")))?;
            list.push((o.clone(), i));
        }
        list
    };
    let modes = normal_modes(lin).map_err(|e| super::modes::modal_failure(model.as_ref(), &e))?;
    let damping = modal_damping(lin, &modes);
    let lookup = parameter_lookup(model.as_ref());
    let (lo, hi) = match &args.freqs {
        Some(text) => {
            let (a, b) = text.split_once("..").ok_or_else(|| {
                CliError::usage(format!(
                    "--freqs takes LO..HI in rad/s, got `{text}` (for example `--freqs 0.1..10`)"
                ))
            })?;
            (
                evaluate(a.trim(), "--freqs LO", &lookup)?,
                evaluate(b.trim(), "--freqs HI", &lookup)?,
            )
        }
        None => {
            let positive: Vec<f64> = modes
                .natural_frequencies
                .iter()
                .copied()
                .filter(|w| *w > 0.0)
                .collect();
            match (positive.first(), positive.last()) {
                (Some(a), Some(b)) => (a / 10.0, b * 10.0),
                _ => {
                    return Err(CliError::usage(format!(
                        "`{name}` has no oscillatory mode at `{label}` to choose a frequency range from; give --freqs LO..HI"
                    )));
                }
            }
        }
    };
    let frequencies = log_frequencies(lo, hi, args.points)
        .map_err(|e| CliError::usage(format!("--freqs: {e}")))?;
    let mut sweeps: Vec<FrequencySweep> = Vec::with_capacity(outputs.len());
    // The one input's column, `n × 1`.
    let b_matrix = &forced.input_matrix;
    for (_, i) in &outputs {
        sweeps.push(frequency_sweep(lin, b_matrix, 0, *i, &frequencies).map_err(fail(name))?);
    }
    let mut evaluation_frequencies = Vec::new();
    for text in &args.frequencies {
        let w = evaluate(text, &format!("--frequency {text}"), &lookup)?;
        if w < 0.0 {
            return Err(CliError::usage(format!(
                "--frequency {text}: {w} rad/s is negative"
            )));
        }
        evaluation_frequencies.push(w);
    }
    drop(lookup);
    if args.modal && evaluation_frequencies.is_empty() {
        for peak in sweeps.iter().flat_map(|s| &s.peaks) {
            if matches!(peak.amplitude, PeakAmplitude::Finite(_))
                && !evaluation_frequencies
                    .iter()
                    .any(|w: &f64| (w - peak.frequency).abs() <= 1e-6 * peak.frequency)
            {
                evaluation_frequencies.push(peak.frequency);
            }
        }
        evaluation_frequencies.sort_by(f64::total_cmp);
    }
    // The response (direct and, with --modal, mode by mode) at the evaluation frequencies.
    let mut evaluations = Vec::new();
    for &w in &evaluation_frequencies {
        let direct = match frequency_response(lin, b_matrix, w) {
            Ok(h) => Some(h.column(0).into_owned()),
            Err(FrfError::Singular { .. }) => None,
            Err(e) => return Err(fail(name)(e)),
        };
        let modal = if args.modal {
            match modal_frequency_response(lin, &modes, &b, w) {
                Ok(r) => Some(r),
                Err(FrfError::Singular { .. }) => None,
                Err(e) => return Err(fail(name)(e)),
            }
        } else {
            None
        };
        evaluations.push((w, direct, modal));
    }
    let simulated = match args.simulate {
        Some(k) if k > 0 => Some(simulate_points(
            args,
            model.as_mut(),
            &forced,
            &outputs,
            lo,
            hi,
            k,
        )?),
        _ => None,
    };
    if let Some(path) = &args.plot {
        bode_chart(
            path,
            &format!("{name}: frequency response from {}", args.input),
            &outputs,
            &sweeps,
            simulated.as_ref().map(|(s, _)| s.as_slice()),
        )
        .map_err(CliError::failure)?;
    }
    let n = model.num_dofs();
    let amp_phase = |z: Complex<f64>| json!({"re": z.re, "im": z.im, "amplitude": z.norm(), "phase_deg": phase_degrees(z)});
    let modal_json = |r: &ModalResponse| {
        let direct = frequency_response(lin, b_matrix, r.frequency).ok();
        let difference = direct.map(|d| {
            (0..n)
                .map(|i| (d[(i, 0)] - r.response[i]).norm())
                .fold(0.0f64, f64::max)
                / (0..n)
                    .map(|i| d[(i, 0)].norm())
                    .fold(0.0f64, f64::max)
                    .max(f64::MIN_POSITIVE)
        });
        json!({
            "modes": (0..modes.natural_frequencies.len()).map(|k| json!({
                "mode": k + 1,
                "natural_frequency": modes.natural_frequencies[k],
                "damping_ratio": damping.damping_ratios[k],
                "modal_force": r.modal_forces[k],
                "modal_coordinate": amp_phase(r.modal_coordinates[k]),
                "contributions": outputs.iter().map(|(o, i)| (o.clone(), amp_phase(r.contributions[(*i, k)]))).collect::<serde_json::Map<_, _>>(),
            })).collect::<Vec<_>>(),
            "sum": outputs.iter().map(|(o, i)| (o.clone(), amp_phase(r.response[*i]))).collect::<serde_json::Map<_, _>>(),
            "max_relative_difference_from_direct": difference,
        })
    };
    if args.json {
        let peak_json = |p: &eomgen::ResonancePeak| match p.amplitude {
            PeakAmplitude::Finite(a) => {
                json!({"frequency": p.frequency, "amplitude": a, "unbounded": false, "phase_deg": p.phase_deg})
            }
            PeakAmplitude::Unbounded => {
                json!({"frequency": p.frequency, "amplitude": Value::Null, "unbounded": true, "phase_deg": Value::Null})
            }
        };
        let out = json!({
            "model": name,
            "input": args.input,
            "outputs": outputs.iter().map(|(o, _)| o.clone()).collect::<Vec<_>>(),
            "operating_point": point_json(&label, &model.coordinate_names(), &forced.equilibrium.q),
            "input_matrix": b.iter().copied().collect::<Vec<f64>>(),
            "natural_frequencies": modes.natural_frequencies,
            "damping_ratios": damping.damping_ratios,
            "modal_damping_coupling": damping.coupling,
            "frequencies": frequencies,
            "responses": outputs.iter().zip(&sweeps).map(|((o, _), s)| json!({
                "output": o,
                "amplitude": s.amplitudes(),
                "phase_deg": s.phases_deg,
                "peaks": s.peaks.iter().map(peak_json).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "evaluations": evaluations.iter().map(|(w, direct, modal)| json!({
                "frequency": w,
                "response": direct.as_ref().map(|d| outputs.iter().map(|(o, i)| (o.clone(), amp_phase(d[*i]))).collect::<serde_json::Map<_, _>>()),
                "unbounded": direct.is_none(),
                "modal": modal.as_ref().map(modal_json),
            })).collect::<Vec<_>>(),
            "simulation": simulated.as_ref().map(|(points, frequency_parameter)| json!({
                "amplitude": args.amplitude,
                "frequency_parameter": frequency_parameter,
                "rtol": args.rtol,
                "points": points.iter().map(|p| json!({
                    "frequency": p.frequency,
                    "settling_time": p.settling_time,
                    "steps": p.steps,
                    "rhs_evals": p.rhs_evals,
                    "outputs": outputs.iter().zip(&p.values).map(|((o, _), (sim, pred))| (o.clone(), json!({
                        "simulated": amp_phase(*sim),
                        "predicted": amp_phase(*pred),
                        "relative_error": relative_error(*sim, *pred),
                    }))).collect::<serde_json::Map<_, _>>(),
                })).collect::<Vec<_>>(),
                "max_relative_error": max_error(points),
            })),
        });
        let text =
            serde_json::to_string_pretty(&out).map_err(|e| CliError::failure(e.to_string()))?;
        let _ = writeln!(std::io::stdout().lock(), "{text}");
        return Ok(());
    }
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "model      {name} ({n} dof), input {}", args.input);
    let point: Vec<String> = coordinates
        .iter()
        .zip(&forced.equilibrium.q)
        .map(|(c, v)| format!("{c} = {v:.6e}"))
        .collect();
    let _ = writeln!(out, "equilibrium {label} (input = 0): {}", point.join(", "));
    let column: Vec<String> = b.iter().map(|v| format!("{v:.6e}")).collect();
    let _ = writeln!(
        out,
        "B          [{}] (generalized force per unit {} at t = 0)",
        column.join(", "),
        args.input
    );
    let _ = writeln!(out, "{:>4}  {:>16}  {:>12}", "mode", "ω (rad/s)", "ζ");
    for (k, w) in modes.natural_frequencies.iter().enumerate() {
        let zeta = damping.damping_ratios[k].map_or("-".to_string(), |z| format!("{z:.6e}"));
        let _ = writeln!(out, "{:>4}  {:>16.10e}  {:>12}", k + 1, w, zeta);
    }
    if damping.coupling > 1e-12 {
        let _ = writeln!(
            out,
            "note       ΨᵀCΨ is not diagonal (off-diagonal {:.2e} of the diagonal): the modal sum drops the coupling",
            damping.coupling
        );
    }
    let _ = writeln!(
        out,
        "sweep      {} frequencies from {lo:.6e} to {hi:.6e} rad/s",
        frequencies.len()
    );
    for ((o, _), s) in outputs.iter().zip(&sweeps) {
        if s.peaks.is_empty() {
            let _ = writeln!(out, "peaks {o:<4} none in the range");
        }
        for p in &s.peaks {
            match p.amplitude {
                PeakAmplitude::Finite(a) => {
                    let _ = writeln!(
                        out,
                        "peak  {o:<4} ω = {:.10e} rad/s  |H| = {a:.10e}  phase {:.4}°",
                        p.frequency,
                        p.phase_deg.unwrap_or(f64::NAN)
                    );
                }
                PeakAmplitude::Unbounded => {
                    let _ = writeln!(
                        out,
                        "peak  {o:<4} ω = {:.10e} rad/s  |H| unbounded (undamped resonance)",
                        p.frequency
                    );
                }
            }
        }
    }
    for (w, direct, modal) in &evaluations {
        match direct {
            Some(d) => {
                let cells: Vec<String> = outputs
                    .iter()
                    .map(|(o, i)| format!("{o}: {}", polar(d[*i])))
                    .collect();
                let _ = writeln!(out, "H(ω = {w:.10e})  {}", cells.join(", "));
            }
            None => {
                let _ = writeln!(
                    out,
                    "H(ω = {w:.10e})  unbounded (K − ω²M + iωC is singular: undamped resonance)"
                );
            }
        }
        if let Some(r) = modal {
            write_modal(
                &mut out,
                &outputs,
                &modes.natural_frequencies,
                &damping.damping_ratios,
                r,
            );
            if let Some(diff) = modal_json(r)["max_relative_difference_from_direct"].as_f64() {
                let _ = writeln!(
                    out,
                    "           modal sum vs direct solve: max difference {diff:.2e} of max |H|"
                );
            }
        } else if args.modal {
            let _ = writeln!(
                out,
                "           modal sum: unbounded (a mode is undamped at this frequency)"
            );
        }
    }
    if let Some((points, frequency_parameter)) = &simulated {
        let _ = writeln!(
            out,
            "simulate   {} = {:e}, {frequency_parameter} = ω, DOP853 rtol {:e}, from rest at the equilibrium to steady state",
            args.input, args.amplitude, args.rtol
        );
        let _ = writeln!(
            out,
            "{:>16}  {:>5}  {:>10}  {:>36}  {:>36}  {:>9}",
            "ω (rad/s)", "out", "t_settle", "simulated X/amplitude", "H(ω)", "rel. err"
        );
        for p in points {
            for ((o, _), (sim, pred)) in outputs.iter().zip(&p.values) {
                let _ = writeln!(
                    out,
                    "{:>16.10e}  {o:>5}  {:>10.1}  {:>36}  {:>36}  {:>9.2e}",
                    p.frequency,
                    p.settling_time,
                    polar(*sim),
                    polar(*pred),
                    relative_error(*sim, *pred)
                );
            }
        }
        let _ = writeln!(
            out,
            "check      max relative error of the simulated steady state against H: {:.2e}",
            max_error(points)
        );
    }
    if let Some(path) = &args.plot {
        let _ = writeln!(out, "chart      {path}");
    }
    Ok(())
}

fn polar(z: Complex<f64>) -> String {
    format!("{:.9e} ∠ {:>9.4}°", z.norm(), phase_degrees(z))
}

/// `|sim − pred| / |pred|`, or `|sim − pred|` for a zero prediction.
fn relative_error(sim: Complex<f64>, pred: Complex<f64>) -> f64 {
    let d = (sim - pred).norm();
    if pred.norm() > 0.0 {
        d / pred.norm()
    } else {
        d
    }
}

/// The largest relative error over the points, each output's error taken against the largest
/// predicted amplitude at that frequency (an output near an antiresonance, or one the mode
/// shape leaves still, would make a relative error meaningless).
fn max_error(points: &[Simulated]) -> f64 {
    points
        .iter()
        .map(|p| {
            let scale = p
                .values
                .iter()
                .map(|(_, h)| h.norm())
                .fold(0.0f64, f64::max);
            p.values
                .iter()
                .map(|(s, h)| (s - h).norm() / scale.max(f64::MIN_POSITIVE))
                .fold(0.0f64, f64::max)
        })
        .fold(0.0f64, f64::max)
}

fn write_modal(
    out: &mut impl std::io::Write,
    outputs: &[(String, usize)],
    natural_frequencies: &[f64],
    damping_ratios: &[Option<f64>],
    r: &ModalResponse,
) {
    let header: Vec<String> = outputs
        .iter()
        .map(|(o, _)| format!("{:>34}", format!("contribution to {o}")))
        .collect();
    let _ = writeln!(
        out,
        "           {:>4}  {:>12}  {:>10}  {:>12}  {:>34}  {}",
        "mode",
        "ω_k",
        "ζ_k",
        "ψ_kᵀb",
        "η_k per unit input",
        header.join("  ")
    );
    for k in 0..r.modal_forces.len() {
        let cells: Vec<String> = outputs
            .iter()
            .map(|(_, i)| format!("{:>34}", polar(r.contributions[(*i, k)])))
            .collect();
        let _ = writeln!(
            out,
            "           {:>4}  {:>12.6e}  {:>10}  {:>12.5e}  {:>34}  {}",
            k + 1,
            natural_frequencies[k],
            damping_ratios[k].map_or("-".to_string(), |z| format!("{z:.4e}")),
            r.modal_forces[k],
            polar(r.modal_coordinates[k]),
            cells.join("  ")
        );
    }
    let sum: Vec<String> = outputs
        .iter()
        .map(|(_, i)| format!("{:>34}", polar(r.response[*i])))
        .collect();
    let _ = writeln!(
        out,
        "           {:>4}  {:>12}  {:>10}  {:>12}  {:>34}  {}",
        "sum",
        "",
        "",
        "",
        "",
        sum.join("  ")
    );
}

/// Simulates `k` log-spaced frequencies of `[lo, hi]` to steady state in parallel and returns
/// the points with the frequency parameter's name.
fn simulate_points(
    args: &FrfArgs,
    model: &mut dyn ModelInfo,
    forced: &eomgen::ForcedLinearization,
    outputs: &[(String, usize)],
    lo: f64,
    hi: f64,
    k: usize,
) -> Result<(Vec<Simulated>, String), CliError> {
    let name = model.name();
    let frequency_parameter = match &args.frequency_parameter {
        Some(p) => p.clone(),
        None if model.parameter_names().contains(&"w") => "w".to_string(),
        None => {
            return Err(CliError::usage(format!(
                "--simulate: `{name}` has no parameter `w`; name the forcing frequency's parameter with --frequency-parameter (parameters: {})",
                model.parameter_names().join(", ")
            )));
        }
    };
    if !model
        .parameter_names()
        .contains(&frequency_parameter.as_str())
    {
        return Err(CliError::usage(format!(
            "--frequency-parameter {frequency_parameter}: `{name}` has no such parameter (parameters: {})",
            model.parameter_names().join(", ")
        )));
    }
    if frequency_parameter == args.input {
        return Err(CliError::usage(
            "--frequency-parameter must differ from --input",
        ));
    }
    if !(args.amplitude.is_finite() && args.amplitude != 0.0) {
        return Err(CliError::usage("--amplitude must be finite and nonzero"));
    }
    if !(args.rtol > 0.0 && args.rtol < 1.0) {
        return Err(CliError::usage("--rtol must be in (0, 1)"));
    }
    let lin = &forced.linearization;
    // Wait until the slowest free decay has shrunk by 1e-10 relative to the response.
    let settle = settling_time(lin, 1e-10).map_err(|e| match e {
        FrfError::NoSteadyState { .. } => {
            CliError::usage(format!("--simulate: `{name}`: {e}; add damping with --set"))
        }
        e => fail(name)(e),
    })?;
    let frequencies = log_frequencies(lo, hi, k).map_err(|e| CliError::usage(e.to_string()))?;
    let b = &forced.input_matrix;
    let progress = if args.json || !std::io::stderr().is_terminal() {
        indicatif::ProgressBar::hidden()
    } else {
        let bar = indicatif::ProgressBar::new(k as u64);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg} [{bar:30}] {pos}/{len} ({elapsed}, eta {eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar.set_message("steady-state simulations");
        bar
    };
    let q_star = forced.equilibrium.q.clone();
    let results: Vec<Result<Simulated, CliError>> = frequencies
        .par_iter()
        .map(|&w| {
            let result = (|| {
                let mut model = args.point.model(&args.model)?;
                let h = frequency_response(lin, b, w).map_err(fail(name))?;
                let scale = h.iter().map(|z| z.norm()).fold(0.0f64, f64::max)
                    * args.amplitude.abs()
                    * w.max(1.0);
                let options = SteadyStateOptions {
                    rtol: args.rtol,
                    atol: args.rtol * scale.max(f64::MIN_POSITIVE),
                    ..SteadyStateOptions::default()
                };
                let forcing = HarmonicForcing {
                    input: &args.input,
                    amplitude: args.amplitude,
                    frequency_parameter: &frequency_parameter,
                    frequency: w,
                };
                let steady =
                    simulate_steady_state(model.as_mut(), &q_star, &forcing, settle, &options)
                        .map_err(fail(name))?;
                let values = outputs
                    .iter()
                    .map(|(_, i)| (steady.complex_amplitudes[*i] / args.amplitude, h[(*i, 0)]))
                    .collect();
                Ok(Simulated {
                    frequency: w,
                    settling_time: settle,
                    values,
                    steps: steady.steps,
                    rhs_evals: steady.rhs_evals,
                })
            })();
            progress.inc(1);
            result
        })
        .collect();
    progress.finish_and_clear();
    let points = results.into_iter().collect::<Result<Vec<_>, _>>()?;
    Ok((points, frequency_parameter))
}

/// The Bode chart: |H| (log) over log ω above, the phase in degrees below; simulated points
/// as circles.
fn bode_chart(
    path: &str,
    title: &str,
    outputs: &[(String, usize)],
    sweeps: &[FrequencySweep],
    simulated: Option<&[Simulated]>,
) -> Result<(), String> {
    plot::register_font()?;
    let size = (960, 720);
    if path.ends_with(".svg") {
        let root = SVGBackend::new(path, size).into_drawing_area();
        draw_bode(root, title, outputs, sweeps, simulated)
    } else if path.ends_with(".png") {
        let root = BitMapBackend::new(path, size).into_drawing_area();
        draw_bode(root, title, outputs, sweeps, simulated)
    } else {
        Err(format!("`{path}`: a chart file must end in .svg or .png"))
    }
}

/// Contiguous runs of finite points (a `None` breaks the line).
fn segments(points: impl Iterator<Item = (f64, Option<f64>)>, log_y: bool) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![Vec::new()];
    for (x, y) in points {
        match y.filter(|y| y.is_finite() && (!log_y || *y > 0.0)) {
            Some(y) => out
                .last_mut()
                .map_or((), |s: &mut Vec<(f64, f64)>| s.push((x, y))),
            None => {
                if out.last().is_some_and(|s| !s.is_empty()) {
                    out.push(Vec::new());
                }
            }
        }
    }
    out.retain(|s| !s.is_empty());
    out
}

fn draw_bode<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    outputs: &[(String, usize)],
    sweeps: &[FrequencySweep],
    simulated: Option<&[Simulated]>,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(err)?;
    let (upper, lower) = root.split_vertically(400);
    let amplitude: Vec<Vec<Vec<(f64, f64)>>> = sweeps
        .iter()
        .map(|s| segments(s.frequencies.iter().copied().zip(s.amplitudes()), true))
        .collect();
    let phase: Vec<Vec<Vec<(f64, f64)>>> = sweeps
        .iter()
        .map(|s| {
            segments(
                s.frequencies
                    .iter()
                    .copied()
                    .zip(s.phases_deg.iter().copied()),
                false,
            )
        })
        .collect();
    let bounds = |sets: &[Vec<Vec<(f64, f64)>>], extra: &[(f64, f64)]| {
        let mut b = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for &(x, y) in sets.iter().flatten().flatten().chain(extra) {
            b = (b.0.min(x), b.1.max(x), b.2.min(y), b.3.max(y));
        }
        b
    };
    let sim_amp: Vec<(f64, f64)> = simulated
        .unwrap_or(&[])
        .iter()
        .flat_map(|p| p.values.iter().map(move |(s, _)| (p.frequency, s.norm())))
        .filter(|(_, a)| *a > 0.0)
        .collect();
    let (x_lo, x_hi, a_lo, a_hi) = bounds(&amplitude, &sim_amp);
    if !(x_lo.is_finite() && a_lo.is_finite()) {
        return Err("nothing to plot: no finite |H|".to_string());
    }
    let (x0, x1) = plot::range(x_lo, x_hi, true);
    let (a0, a1) = plot::range(a_lo, a_hi, true);
    let color = |i: usize| Palette99::pick(i).to_rgba();
    {
        let mut chart = ChartBuilder::on(&upper)
            .margin(12)
            .x_label_area_size(30)
            .y_label_area_size(90)
            .build_cartesian_2d((x0..x1).log_scale(), (a0..a1).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .y_desc("|H| (output per unit input)")
            .x_label_formatter(&|v| plot::tick(*v, true))
            .y_label_formatter(&|v| plot::tick(*v, true))
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(err)?;
        for (i, segs) in amplitude.iter().enumerate() {
            let c = color(i);
            for (j, seg) in segs.iter().enumerate() {
                let series = chart
                    .draw_series(LineSeries::new(seg.iter().copied(), c.stroke_width(2)))
                    .map_err(err)?;
                if j == 0 {
                    series.label(outputs[i].0.clone()).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                    });
                }
            }
        }
        // Undamped resonances: |H| → ∞, marked by a thin vertical line.
        for (i, s) in sweeps.iter().enumerate() {
            let c = color(i).mix(0.5);
            for p in &s.peaks {
                if p.amplitude == PeakAmplitude::Unbounded {
                    chart
                        .draw_series(LineSeries::new(
                            [(p.frequency, a0), (p.frequency, a1)],
                            c.stroke_width(1),
                        ))
                        .map_err(err)?;
                }
            }
        }
        if let Some(points) = simulated {
            let mut first = true;
            for (i, _) in outputs.iter().enumerate() {
                let c = color(i);
                let dots: Vec<(f64, f64)> = points
                    .iter()
                    .map(|p| (p.frequency, p.values[i].0.norm()))
                    .filter(|(_, a)| *a > 0.0)
                    .collect();
                let series = chart
                    .draw_series(
                        dots.into_iter()
                            .map(|p| Circle::new(p, 5, c.stroke_width(2))),
                    )
                    .map_err(err)?;
                if first {
                    first = false;
                    series
                        .label("simulated steady state")
                        .legend(move |(x, y)| Circle::new((x + 10, y), 5, BLACK.stroke_width(2)));
                }
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(err)?;
    }
    let (_, _, p_lo, p_hi) = bounds(&phase, &[]);
    let (p0, p1) = if p_lo.is_finite() {
        plot::range(p_lo, p_hi, false)
    } else {
        (-190.0, 10.0)
    };
    let mut chart = ChartBuilder::on(&lower)
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(90)
        .build_cartesian_2d((x0..x1).log_scale(), p0..p1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("ω (rad/s)")
        .y_desc("phase (degrees)")
        .x_label_formatter(&|v| plot::tick(*v, true))
        .y_label_formatter(&|v| plot::tick(*v, false))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    for (i, segs) in phase.iter().enumerate() {
        let c = color(i);
        for seg in segs {
            chart
                .draw_series(LineSeries::new(seg.iter().copied(), c.stroke_width(2)))
                .map_err(err)?;
        }
    }
    if let Some(points) = simulated {
        for (i, _) in outputs.iter().enumerate() {
            let c = color(i);
            // The simulated phase in (−180, 180], shifted by whole turns to the curve's branch.
            let dots: Vec<(f64, f64)> = points
                .iter()
                .filter_map(|p| {
                    let (s, h) = p.values[i];
                    if s.norm() == 0.0 {
                        return None;
                    }
                    let curve = sweeps[i]
                        .frequencies
                        .iter()
                        .zip(&sweeps[i].phases_deg)
                        .filter_map(|(w, ph)| ph.map(|ph| ((w / p.frequency).ln().abs(), ph)))
                        .min_by(|a, b| a.0.total_cmp(&b.0))
                        .map_or(phase_degrees(h), |(_, ph)| ph);
                    let mut ph = phase_degrees(s);
                    ph += 360.0 * ((curve - ph) / 360.0).round();
                    Some((p.frequency, ph))
                })
                .collect();
            chart
                .draw_series(
                    dots.into_iter()
                        .map(|p| Circle::new(p, 5, c.stroke_width(2))),
                )
                .map_err(err)?;
        }
    }
    root.present().map_err(err)?;
    Ok(())
}
