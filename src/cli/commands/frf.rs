//! `eomgen frf MODEL --input NAME`: the frequency response `H(ω) = (K − ω²M + iωC)⁻¹ B` from
//! a load parameter to coordinates, its resonance peaks, a Bode chart, the response assembled
//! mode by mode (`--modal`), and points of the curve checked by simulating the full model
//! (`--simulate K`) (lecture 21, HW21, HW34, HW37). The numbers come from
//! [`eomgen::analysis::vibration::frequency_response_analysis`] and its simulated points; this module
//! runs those in parallel and renders text, JSON and the chart.

use clap::Args;
use eomgen::analysis::vibration::{
    self, FrfAnalysis, FrfAnalysisError, FrfOptions, FrfOutput, FrfSimulationOptions,
    FrfSimulationPlan, SimulatedPoint, max_simulation_error,
};
use eomgen::{
    FrequencySweep, FrfError, ModalResponse, ModelInfo, NormalModes, PeakAmplitude, phase_degrees,
};
use nalgebra::Complex;
use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;

use crate::cli::error::CliError;
use crate::cli::files::Outputs;
use crate::cli::json::print_json_sorted;
use crate::cli::operating_point::OperatingPointArgs;
use crate::cli::plot;
use crate::cli::render::num;
use crate::cli::values::{evaluate, parameter_lookup};

/// Options of `eomgen frf`.
#[derive(Debug, Args)]
pub struct FrfArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any model file.
    pub model: String,
    /// The input: a parameter that enters the forcing linearly (a load amplitude, `A` in
    /// `A*cos(w*t)`; its time function is taken at t = 0, so for `A*cos(w*t)` the response is
    /// the steady state under `A cos(ω t)`), or a coordinate's name: a unit generalized force
    /// on that coordinate (no `--simulate` then: the model has no load to drive). The
    /// equilibrium (`--at`) is found with the input set to 0. An input whose load reverses
    /// over half a period of `w` (or `--frequency-parameter`) and is read a quarter period
    /// later too also enters through its rate: a base motion `Y*cos(w*t)` through a spring and
    /// a dashpot gives the input column `k + iωc` and the transmissibility.
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
    /// Frequencies of the sweep, spaced evenly in log ω (1 to 100000).
    #[arg(long, default_value_t = FrfOptions::DEFAULT_POINTS, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=100_000))]
    pub points: usize,
    /// Also evaluate the response at this frequency (rad/s, an expression such as
    /// `sqrt(2*k/m)` or `w`); repeatable. With `--modal`, the modal breakdown is given here.
    #[arg(long = "frequency", value_name = "W")]
    pub frequencies: Vec<String>,
    /// The response assembled mode by mode, `Σ ψ_k ψ_kᵀ b / (ω_k² − ω² + 2iζ_k ω_k ω)`, with
    /// each mode's contribution, at the `--frequency` values (default: the damped peaks); for
    /// the modes of a non-symmetric K (a follower load) `ψ_kᵀ b` is row k of `Ψ⁻¹M⁻¹b`.
    #[arg(long)]
    pub modal: bool,
    /// Check K frequencies of the curve (log-spaced over the range) by simulating the full
    /// model to steady state, in parallel (1 to 1000).
    #[arg(long, value_name = "K", value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=1000))]
    pub simulate: Option<usize>,
    /// The parameter holding the forcing frequency, set to each ω by `--simulate` and used to
    /// read an input's rate column (default: `w` if the model has it).
    #[arg(long, value_name = "NAME")]
    pub frequency_parameter: Option<String>,
    /// The input's value in the `--simulate` runs (small, so that the nonlinear model stays
    /// near its linearisation).
    #[arg(long, default_value_t = FrfSimulationOptions::DEFAULT_AMPLITUDE)]
    pub amplitude: f64,
    /// Relative tolerance of the `--simulate` runs (DOP853).
    #[arg(long, default_value_t = FrfSimulationOptions::DEFAULT_RTOL, value_parser = crate::cli::values::relative_tolerance, allow_hyphen_values = true)]
    pub rtol: f64,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Bode chart (log ω; log |H| and phase in degrees, two panels), `.svg` or `.png`.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
}

/// The error of a failed analysis of `model`, in the words of the options.
fn failure(model: &dyn ModelInfo, e: FrfAnalysisError) -> CliError {
    let name = &model.description().name;
    match e {
        FrfAnalysisError::TooFewPoints { .. } => CliError::usage("--points must be at least 2"),
        FrfAnalysisError::UnknownInput { ref input, .. } => {
            CliError::usage(format!("--input {input}: {e}"))
        }
        FrfAnalysisError::SimulationNeedsParameter { input } => CliError::usage(format!(
            "--simulate needs a load parameter as --input (`{input}` is a coordinate: a unit generalized force has no load in the model to drive)"
        )),
        FrfAnalysisError::OperatingPoint(e) => {
            crate::cli::operating_point::point_failure(model, &e)
        }
        FrfAnalysisError::Input(ref source) => {
            let input = match source {
                FrfError::NonlinearInput { input, .. }
                | FrfError::InputNotInForcing { input }
                | FrfError::InputChangesMassMatrix { input }
                | FrfError::InputRateNotConstant { input, .. } => input.as_str(),
                _ => "",
            };
            CliError::usage(format!("--input {input}: {e}"))
        }
        FrfAnalysisError::ModalWithInputRate { ref input } => {
            CliError::usage(format!("--modal with --input {input}: {e}"))
        }
        FrfAnalysisError::Output { output, source } => {
            CliError::usage(format!("--output {output}: {source}"))
        }
        FrfAnalysisError::NoFrequencyRange {
            model,
            operating_point,
        } => CliError::usage(format!(
            "`{model}` has no oscillatory mode at `{operating_point}` to choose a frequency range from; give --freqs LO..HI"
        )),
        FrfAnalysisError::FrequencyRange(e) => CliError::usage(format!("--freqs: {e}")),
        FrfAnalysisError::NoFrequencyParameter { parameters, .. } => CliError::usage(format!(
            "--simulate: `{name}` has no parameter `w`; name the forcing frequency's parameter with --frequency-parameter (parameters: {parameters})"
        )),
        FrfAnalysisError::UnknownFrequencyParameter {
            name: parameter,
            parameters,
            ..
        } => CliError::usage(format!(
            "--frequency-parameter {parameter}: `{name}` has no such parameter (parameters: {parameters})"
        )),
        FrfAnalysisError::FrequencyParameterIsInput => {
            CliError::usage("--frequency-parameter must differ from --input")
        }
        FrfAnalysisError::InvalidAmplitude { .. } => {
            CliError::usage("--amplitude must be finite and nonzero")
        }
        FrfAnalysisError::InvalidTolerance { .. } => CliError::usage("--rtol must be in (0, 1)"),
        FrfAnalysisError::NoSteadyState(e) => {
            CliError::usage(format!("--simulate: `{name}`: {e}; add damping with --set"))
        }
        FrfAnalysisError::Frf(FrfError::Modal(m)) => {
            crate::cli::operating_point::modal_failure(model, &m)
        }
        FrfAnalysisError::Frf(e @ FrfError::ResponseOutOfRange { .. }) => CliError::usage(format!(
            "--frequency/--freqs: {e}; choose frequencies where the response is representable"
        )),
        e => CliError::failure(format!("`{name}`: {e}")),
    }
}

/// `w` (rad/s), the value of `option` typed as `text`, if it is in
/// [`crate::cli::values::FREQUENCY`] (or 0, the static response, when `zero` is allowed).
///
/// # Errors
/// A usage error that quotes `text` and gives the range.
fn frequency(option: &str, text: &str, w: f64, zero: bool) -> Result<f64, CliError> {
    if crate::cli::values::FREQUENCY.contains(&w) || (zero && w == 0.0) {
        Ok(w)
    } else {
        Err(CliError::usage(format!(
            "{option} `{text}`: a frequency must be in [1e-12, 1e12] rad/s{}",
            if zero { " or 0" } else { "" }
        )))
    }
}

/// Runs `frf`.
pub fn run(args: &FrfArgs) -> Result<(), CliError> {
    Outputs::new()
        .input(&args.model)
        .chart("--plot", args.plot.as_deref())
        .check()?;
    let mut model = args.point.model(&args.model)?;
    let (frequency_range, frequencies) = frequencies(args, model.as_ref())?;
    let simulation = simulation_options(args, model.as_ref())?;
    let options = FrfOptions {
        operating_point: args.point.options(model.as_ref())?,
        input: args.input.clone(),
        outputs: args.outputs.clone(),
        frequency_range,
        points: args.points,
        frequencies,
        modal: args.modal,
        simulation: simulation.clone(),
    };
    let frf = vibration::frequency_response_analysis(model.as_mut(), &options)
        .map_err(|e| failure(model.as_ref(), e))?;
    let simulated = match simulation {
        Some(sim) if sim.count > 0 => {
            let plan = vibration::plan_simulation(model.as_ref(), &frf, &sim)
                .map_err(|e| failure(model.as_ref(), e))?;
            Some((simulate_points(args, model.as_ref(), &frf, &plan)?, plan))
        }
        _ => None,
    };
    let simulated = simulated
        .as_ref()
        .map(|(points, plan)| (points.as_slice(), plan));
    if let Some(path) = &args.plot {
        bode_chart(
            path,
            &format!(
                "{}: frequency response from {}",
                model.description().name,
                args.input
            ),
            &frf.outputs,
            &frf.sweeps,
            simulated.map(|(s, _)| s),
        )
        .map_err(CliError::failure)?;
    }
    if args.json {
        print_json_sorted(&frf.summary(model.as_ref(), simulated))?;
        return Ok(());
    }
    print_report(
        &mut crate::cli::output::stdout(),
        args,
        model.as_ref(),
        &frf,
        simulated,
    );
    Ok(())
}

/// The range of `--freqs` and the list of `--frequency` (rad/s).
type Frequencies = (Option<(f64, f64)>, Vec<f64>);

/// `--freqs LO..HI` and the `--frequency` list (rad/s), evaluated with the model's parameters.
///
/// # Errors
/// A usage error for a range or frequency that does not parse or lies outside [1e-12, 1e12].
fn frequencies(args: &FrfArgs, model: &dyn ModelInfo) -> Result<Frequencies, CliError> {
    let lookup = parameter_lookup(model);
    let frequency_range = match &args.freqs {
        Some(text) => {
            let (a, b) = text.split_once("..").ok_or_else(|| {
                CliError::usage(format!(
                    "--freqs takes LO..HI in rad/s, got `{text}` (for example `--freqs 0.1..10`)"
                ))
            })?;
            let lo = evaluate(a.trim(), "--freqs LO", &lookup)?;
            let hi = evaluate(b.trim(), "--freqs HI", &lookup)?;
            Some((
                frequency("--freqs LO", a.trim(), lo, false)?,
                frequency("--freqs HI", b.trim(), hi, false)?,
            ))
        }
        None => None,
    };
    let mut frequencies = Vec::new();
    for text in &args.frequencies {
        let w = evaluate(text, &format!("--frequency {text}"), &lookup)?;
        frequencies.push(frequency("--frequency", text, w, true)?);
    }
    Ok((frequency_range, frequencies))
}

/// The simulated points `--simulate` asks for, or, with `--frequency-parameter` alone, none
/// but where a parameter input's rate is read (checked here, not ignored).
///
/// # Errors
/// A usage error for an unknown `--frequency-parameter` or one equal to `--input`.
fn simulation_options(
    args: &FrfArgs,
    model: &dyn ModelInfo,
) -> Result<Option<FrfSimulationOptions>, CliError> {
    let simulation = args.simulate.map(|count| FrfSimulationOptions {
        count,
        frequency_parameter: args.frequency_parameter.clone(),
        amplitude: args.amplitude,
        rtol: args.rtol,
    });
    // `--frequency-parameter` also says where to read a parameter input's rate column: without
    // `--simulate` it is checked here and passed on with no runs, not ignored.
    let simulation = match (simulation, &args.frequency_parameter) {
        (None, Some(p)) => {
            let parameters = model.description().parameter_names();
            if !parameters.contains(&p.as_str()) {
                return Err(CliError::usage(format!(
                    "--frequency-parameter {p}: `{}` has no such parameter (parameters: {})",
                    model.description().name,
                    parameters.join(", ")
                )));
            }
            if *p == args.input {
                return Err(CliError::usage(
                    "--frequency-parameter must differ from --input",
                ));
            }
            parameters
                .contains(&args.input.as_str())
                .then(|| FrfSimulationOptions {
                    count: 0,
                    frequency_parameter: Some(p.clone()),
                    ..FrfSimulationOptions::default()
                })
        }
        (simulation, _) => simulation,
    };
    Ok(simulation)
}

/// The text of `frf` (and of the simulated points).
fn print_report(
    out: &mut impl std::io::Write,
    args: &FrfArgs,
    model: &dyn ModelInfo,
    frf: &FrfAnalysis,
    simulated: Option<(&[SimulatedPoint], &FrfSimulationPlan)>,
) {
    let name = &model.description().name;
    let (lo, hi) = frf.frequency_range;
    let FrfAnalysis {
        operating_point: point,
        outputs,
        forced,
        sweeps,
        ..
    } = frf;
    let label = &point.name;
    let b: Vec<f64> = forced.input_matrix.column(0).iter().copied().collect();
    let n = model.num_dofs();
    let _ = writeln!(out, "model      {name} ({n} dof), input {}", args.input);
    let point: Vec<String> = model
        .description()
        .coordinate_names()
        .iter()
        .zip(&forced.equilibrium.q)
        .map(|(c, v)| format!("{c} = {v:.6e}", v = num(v)))
        .collect();
    let _ = writeln!(out, "equilibrium {label} (input = 0): {}", point.join(", "));
    let column: Vec<String> = b.iter().map(|v| format!("{v:.6e}", v = num(v))).collect();
    let _ = writeln!(
        out,
        "B          [{}] (generalized force per unit {} at t = 0)",
        column.join(", "),
        args.input
    );
    if forced.has_input_rates() {
        let rates: Vec<String> = forced
            .input_rate_matrix
            .column(0)
            .iter()
            .map(|v| format!("{v:.6e}", v = num(v)))
            .collect();
        let _ = writeln!(
            out,
            "B₁         [{}] (generalized force per unit rate of {}: the input column at ω is B + iω B₁)",
            rates.join(", "),
            args.input
        );
    }
    write_modes(out, frf);
    let _ = writeln!(
        out,
        "sweep      {} frequencies from {lo:.6e} to {hi:.6e} rad/s",
        frf.frequencies.len(),
        lo = num(lo),
        hi = num(hi)
    );
    write_peaks(out, outputs, sweeps);
    write_evaluations(out, args, frf);
    if let Some((points, plan)) = simulated {
        write_simulated(out, args, outputs, points, plan);
    }
    if let Some(path) = &args.plot {
        let _ = writeln!(out, "chart      {path}");
    }
}

/// The modes the response is made of: the undamped ones of `K` with their modal damping, or,
/// with a gyroscopic `C`, the eigenvalues of the whole linearisation; and the coupling the
/// modal sum drops.
fn write_modes(out: &mut impl std::io::Write, frf: &FrfAnalysis) {
    let FrfAnalysis {
        normal_modes: modes,
        modal_damping: damping,
        ..
    } = frf;
    let gyroscopic = frf.stability.gyroscopic_frequencies.is_some();
    if gyroscopic {
        // The undamped modes of K are not the system's: the whole linearisation's are.
        let _ = writeln!(out, "{:>4}  {:>16}  {:>12}", "mode", "|s| (rad/s)", "ζ");
        let upper = frf.stability.eigenvalues.iter().filter(|s| s.im > 0.0);
        for (k, s) in upper.enumerate() {
            let zeta = -s.re / s.norm() + 0.0;
            let _ = writeln!(
                out,
                "{:>4}  {:>16.10e}  {:>12.6e}",
                k + 1,
                num(s.norm()),
                num(zeta)
            );
        }
        let _ = writeln!(
            out,
            "note       C has a gyroscopic part G = (C − Cᵀ)/2 (max |G| = {:.6e}): the modes above are the eigenvalues s of the whole linearisation ({}), and modal sums over the undamped modes of K do not apply",
            num(frf.stability.gyroscopic_part.amax()),
            frf.stability.stability.name()
        );
    } else {
        let _ = writeln!(out, "{:>4}  {:>16}  {:>12}", "mode", "ω (rad/s)", "ζ");
        for (k, w) in modes.natural_frequencies.iter().enumerate() {
            let zeta = damping.damping_ratios[k]
                .map_or("-".to_string(), |z| format!("{z:.6e}", z = num(z)));
            let _ = writeln!(out, "{:>4}  {:>16.10e}  {:>12}", k + 1, num(w), zeta);
        }
    }
    if !gyroscopic && damping.coupling > 1e-12 {
        let _ = writeln!(
            out,
            "note       {}CΨ is not diagonal (off-diagonal {:.2e} of the diagonal): the modal sum drops the coupling",
            modes.projector_label(),
            num(damping.coupling)
        );
    }
}

/// The resonance peaks of every output's sweep.
fn write_peaks(out: &mut impl std::io::Write, outputs: &[FrfOutput], sweeps: &[FrequencySweep]) {
    for (o, s) in outputs.iter().zip(sweeps) {
        let o = &o.name;
        if s.peaks.is_empty() {
            let _ = writeln!(out, "peaks {o:<4} none in the range");
        }
        for p in &s.peaks {
            match p.amplitude {
                PeakAmplitude::Finite(a) => {
                    let _ = writeln!(
                        out,
                        "peak  {o:<4} ω = {:.10e} rad/s  |H| = {a:.10e}  phase {:.4}°",
                        num(p.frequency),
                        p.phase_deg.unwrap_or(f64::NAN),
                        a = num(a)
                    );
                }
                PeakAmplitude::Unbounded => {
                    let _ = writeln!(
                        out,
                        "peak  {o:<4} ω = {:.10e} rad/s  |H| unbounded (undamped resonance)",
                        num(p.frequency)
                    );
                }
            }
        }
    }
}

/// `H(ω)` at every `--frequency`, with the modal contributions of `--modal`.
fn write_evaluations(out: &mut impl std::io::Write, args: &FrfArgs, frf: &FrfAnalysis) {
    let FrfAnalysis {
        outputs,
        normal_modes: modes,
        modal_damping: damping,
        evaluations,
        ..
    } = frf;
    for e in evaluations {
        let w = e.frequency;
        match &e.response {
            Some(d) => {
                let cells: Vec<String> = outputs
                    .iter()
                    .map(|o| format!("{}: {}", o.name, polar(d[o.index])))
                    .collect();
                let _ = writeln!(out, "H(ω = {w:.10e})  {}", cells.join(", "), w = num(w));
            }
            None => {
                let _ = writeln!(
                    out,
                    "H(ω = {w:.10e})  unbounded (K − ω²M + iωC is singular: undamped resonance)",
                    w = num(w)
                );
            }
        }
        if let Some(r) = &e.modal {
            write_modal(out, outputs, modes, &damping.damping_ratios, r);
            // As the JSON has it: a non-finite difference is no number.
            if let Some(diff) = e.modal_difference.filter(|d| d.is_finite()) {
                let _ = writeln!(
                    out,
                    "           modal sum vs direct solve: max difference {diff:.2e} of max |H|",
                    diff = num(diff)
                );
            }
        } else if args.modal {
            let _ = writeln!(
                out,
                "           modal sum: unbounded (a mode is undamped at this frequency)"
            );
        }
    }
}

/// The points of `--simulate` against `H`.
fn write_simulated(
    out: &mut impl std::io::Write,
    args: &FrfArgs,
    outputs: &[FrfOutput],
    points: &[SimulatedPoint],
    plan: &FrfSimulationPlan,
) {
    let _ = writeln!(
        out,
        "simulate   {} = {:e}, {} = ω, DOP853 rtol {:e}, from rest at the equilibrium to steady state",
        args.input,
        num(args.amplitude),
        plan.frequency_parameter,
        num(args.rtol)
    );
    let _ = writeln!(
        out,
        "{:>16}  {:>5}  {:>10}  {:>36}  {:>36}  {:>9}",
        "ω (rad/s)", "out", "t_settle", "simulated X/amplitude", "H(ω)", "rel. err"
    );
    for p in points {
        for (o, v) in outputs.iter().zip(&p.values) {
            let _ = writeln!(
                out,
                "{:>16.10e}  {:>5}  {:>10.1}  {:>36}  {:>36}  {:>9.2e}",
                num(p.frequency),
                o.name,
                p.settling_time,
                polar(v.simulated),
                polar(v.predicted),
                num(v.relative_error())
            );
        }
    }
    let _ = writeln!(
        out,
        "check      max relative error of the simulated steady state against H: {:.2e}",
        num(max_simulation_error(points))
    );
}

fn polar(z: Complex<f64>) -> String {
    format!("{:.9e} ∠ {:>9.4}°", num(z.norm()), phase_degrees(z))
}

fn write_modal(
    out: &mut impl std::io::Write,
    outputs: &[FrfOutput],
    modes: &NormalModes,
    damping_ratios: &[Option<f64>],
    r: &ModalResponse,
) {
    let natural_frequencies = &modes.natural_frequencies;
    // Row k of the projector times b.
    let modal_force = if modes.m_orthogonal() {
        "ψ_kᵀb".to_string()
    } else {
        format!("({}b)_k", modes.projector_label())
    };
    let header: Vec<String> = outputs
        .iter()
        .map(|o| format!("{:>34}", format!("contribution to {}", o.name)))
        .collect();
    let _ = writeln!(
        out,
        "           {:>4}  {:>12}  {:>10}  {:>12}  {:>34}  {}",
        "mode",
        "ω_k",
        "ζ_k",
        modal_force,
        "η_k per unit input",
        header.join("  ")
    );
    for k in 0..r.modal_forces.len() {
        let cells: Vec<String> = outputs
            .iter()
            .map(|o| format!("{:>34}", polar(r.contributions[(o.index, k)])))
            .collect();
        let _ = writeln!(
            out,
            "           {:>4}  {:>12.6e}  {:>10}  {:>12.5e}  {:>34}  {}",
            k + 1,
            num(natural_frequencies[k]),
            damping_ratios[k].map_or("-".to_string(), |z| format!("{z:.4e}", z = num(z))),
            num(r.modal_forces[k]),
            polar(r.modal_coordinates[k]),
            cells.join("  ")
        );
    }
    let sum: Vec<String> = outputs
        .iter()
        .map(|o| format!("{:>34}", polar(r.response[o.index])))
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

/// Runs the planned steady-state simulations in parallel (rayon), each on its own instance of
/// the model with `--set` applied ([`vibration::simulate_point`]), with a progress bar on a
/// terminal.
fn simulate_points(
    args: &FrfArgs,
    model: &dyn ModelInfo,
    frf: &FrfAnalysis,
    plan: &FrfSimulationPlan,
) -> Result<Vec<SimulatedPoint>, CliError> {
    let name = &model.description().name;
    let k = plan.frequencies.len();
    let progress = crate::cli::render::progress_bar(
        k,
        "{msg} [{bar:30}] {pos}/{len} ({elapsed}, eta {eta})",
        "steady-state simulations",
        args.json,
    );
    let results: Vec<Result<SimulatedPoint, CliError>> = plan
        .frequencies
        .par_iter()
        .map(|&w| {
            let result = args.point.model(&args.model).and_then(|mut model| {
                vibration::simulate_point(model.as_mut(), frf, plan, w)
                    .map_err(|e| CliError::failure(format!("`{name}`: {e}")))
            });
            progress.inc(1);
            result
        })
        .collect();
    progress.finish_and_clear();
    results.into_iter().collect()
}

/// The Bode chart: |H| (log) over log ω above, the phase in degrees below; simulated points
/// as circles.
fn bode_chart(
    path: &str,
    title: &str,
    outputs: &[FrfOutput],
    sweeps: &[FrequencySweep],
    simulated: Option<&[SimulatedPoint]>,
) -> Result<(), String> {
    let chart = BodeChart {
        title,
        outputs,
        sweeps,
        simulated,
    };
    plot::write_chart(path, (960, 720), &chart)
}

/// The Bode chart of [`bode_chart`], drawn.
struct BodeChart<'a> {
    title: &'a str,
    outputs: &'a [FrfOutput],
    sweeps: &'a [FrequencySweep],
    simulated: Option<&'a [SimulatedPoint]>,
}

impl plot::Drawing for BodeChart<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        draw_bode(root, self.title, self.outputs, self.sweeps, self.simulated)
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

/// The Bode chart under its title: |H| (log) over log ω in the upper panel
/// ([`draw_amplitude`]), the phase in degrees in the lower one ([`draw_phase`]).
fn draw_bode<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    outputs: &[FrfOutput],
    sweeps: &[FrequencySweep],
    simulated: Option<&[SimulatedPoint]>,
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
    let sim_amp = simulated_amplitudes(simulated);
    let (x_lo, x_hi, a_lo, a_hi) = bounds(&amplitude, &sim_amp);
    if !(x_lo.is_finite() && a_lo.is_finite()) {
        return Err("nothing to plot: no finite |H|".to_string());
    }
    let (x0, x1) = plot::range(x_lo, x_hi, true);
    let (a0, a1) = plot::range(a_lo, a_hi, true);
    draw_amplitude(
        &upper,
        (x0, x1),
        (a0, a1),
        &amplitude,
        outputs,
        sweeps,
        simulated,
    )?;
    let (_, _, p_lo, p_hi) = bounds(&phase, &[]);
    draw_phase(
        &lower,
        (x0, x1),
        (p_lo, p_hi),
        &phase,
        outputs,
        sweeps,
        simulated,
    )?;
    root.present().map_err(err)?;
    Ok(())
}

/// The bounding box `(x_min, x_max, y_min, y_max)` of the points of `sets` (curves in
/// segments) and `extra`; infinite (min +∞, max −∞) when there are none.
fn bounds(sets: &[Vec<Vec<(f64, f64)>>], extra: &[(f64, f64)]) -> (f64, f64, f64, f64) {
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
}

/// The simulated steady-state amplitudes `(ω, |output|)` of every output at every simulated
/// frequency, those above 0 only (they go on a log scale).
fn simulated_amplitudes(simulated: Option<&[SimulatedPoint]>) -> Vec<(f64, f64)> {
    simulated
        .unwrap_or(&[])
        .iter()
        .flat_map(|p| {
            p.values
                .iter()
                .map(move |v| (p.frequency, v.simulated.norm()))
        })
        .filter(|(_, a)| *a > 0.0)
        .collect()
}

/// A chart with log scales on both axes (the Bode chart's |H| over ω).
type LogLogChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// The Bode chart's upper panel: |H| over log ω, both on log scales (`amplitude` in segments,
/// each undamped resonance a thin vertical line, the simulated points as circles), with the
/// legend.
fn draw_amplitude<DB: DrawingBackend>(
    upper: &DrawingArea<DB, plotters::coord::Shift>,
    (x0, x1): (f64, f64),
    (a0, a1): (f64, f64),
    amplitude: &[Vec<Vec<(f64, f64)>>],
    outputs: &[FrfOutput],
    sweeps: &[FrequencySweep],
    simulated: Option<&[SimulatedPoint]>,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    let color = |i: usize| Palette99::pick(i).to_rgba();
    let mut chart = ChartBuilder::on(upper)
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
                series.label(outputs[i].name.clone()).legend(move |(x, y)| {
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
        draw_simulated_amplitudes(&mut chart, outputs, points)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// The simulated steady-state amplitudes of the Bode chart's upper panel: a circle per
/// output and simulated frequency (above 0), in the output's colour, with one legend entry.
fn draw_simulated_amplitudes<DB: DrawingBackend>(
    chart: &mut LogLogChart<'_, DB>,
    outputs: &[FrfOutput],
    points: &[SimulatedPoint],
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    let color = |i: usize| Palette99::pick(i).to_rgba();
    let mut first = true;
    for (i, _) in outputs.iter().enumerate() {
        let c = color(i);
        let dots: Vec<(f64, f64)> = points
            .iter()
            .map(|p| (p.frequency, p.values[i].simulated.norm()))
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
    Ok(())
}

/// The Bode chart's lower panel: the phase in degrees over log ω (`phase` in segments, the
/// simulated points as circles on the curve's branch).
fn draw_phase<DB: DrawingBackend>(
    lower: &DrawingArea<DB, plotters::coord::Shift>,
    (x0, x1): (f64, f64),
    (p_lo, p_hi): (f64, f64),
    phase: &[Vec<Vec<(f64, f64)>>],
    outputs: &[FrfOutput],
    sweeps: &[FrequencySweep],
    simulated: Option<&[SimulatedPoint]>,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    let color = |i: usize| Palette99::pick(i).to_rgba();
    let (p0, p1) = if p_lo.is_finite() {
        plot::range(p_lo, p_hi, false)
    } else {
        (-190.0, 10.0)
    };
    let mut chart = ChartBuilder::on(lower)
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
                    let (s, h) = (p.values[i].simulated, p.values[i].predicted);
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
    Ok(())
}
