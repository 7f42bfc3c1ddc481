//! `eomgen simulate MODEL`: integrate from the model's initial state and report.

use std::io::Write as _;

use clap::{Args, ValueEnum};
pub(crate) use eomgen::Method;
use eomgen::analysis::{
    AddedEvents, ConstraintDrift, EnergyDrift, FailureCause, Simulation, SimulationError,
    SimulationOptions, simulate_with_events,
};
use eomgen::expressions::{ExpressionEvents, set_initial_values};
use eomgen::{IntegrationError, ModelInfo, OutputTimes, Solution};
use serde_json::json;

use super::files::{self, Outputs};
use super::output::outln;
use super::render::num;
use super::values::{evaluate, set_parameters, usage};
use super::{CliError, find_model, plot};
use eomgen::Stabilization;

/// The `--method` help of each method (clap lists them under "Possible values"; the
/// methods themselves are [`Method`]).
fn method_help(method: Method) -> &'static str {
    match method {
        Method::Euler => "Explicit Euler, order 1, fixed step `--dt`",
        Method::Midpoint => "Explicit midpoint, order 2, fixed step `--dt`",
        Method::Rk4 => "Classical Runge–Kutta 4, fixed step `--dt`",
        Method::Bs32 => "Bogacki–Shampine 3(2) (ode23), adaptive, Hermite dense output",
        Method::Dp54 => "Dormand–Prince 5(4), adaptive, dense output (default)",
        Method::Dop853 => "DOP853, Hairer's Dormand–Prince 8(5,3), adaptive, order-7 dense output",
        Method::SymplecticEuler => {
            "Symplectic Euler, order 1, fixed step `--dt` (symplectic for constant M and velocity-independent forces)"
        }
        Method::StormerVerlet => {
            "Störmer–Verlet (leapfrog in q, q̇), order 2, fixed step `--dt` (symplectic for constant M and velocity-independent forces)"
        }
        Method::ImplicitMidpoint => {
            "Implicit midpoint, order 2, fixed step `--dt`, Newton with the generated Jacobians (symplectic for any M(q))"
        }
        Method::Radau5 => {
            "Radau IIA order 5 (RADAU5), adaptive, L-stable, Newton with the generated Jacobians"
        }
    }
}

/// clap's parser of a method name (`--method`, `--methods`): the names of [`Method::ALL`]
/// with their help, parsed by [`Method`]'s `FromStr`. Adaptive methods use
/// `--rtol`/`--atol` (and `--dt` as their first step); fixed-step methods use `--dt`
/// (default `t_end/1000`).
pub(crate) fn method_parser() -> impl clap::builder::TypedValueParser<Value = Method> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser as _};
    PossibleValuesParser::new(
        Method::ALL.map(|m| PossibleValue::new(m.name()).help(method_help(m))),
    )
    .try_map(|name| name.parse::<Method>())
}

/// Drift control of a constrained model (`--stabilization`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum StabilizationArg {
    /// None: the drift of Φ and Φ̇ is shown as it grows (HW10, HW12).
    None,
    /// Baumgarte's stabilisation with `--baumgarte ALPHA,BETA`.
    Baumgarte,
    /// Projection onto Φ = 0 and the velocity constraints after every accepted step.
    Projection,
}

/// Most output times `--t-out` may list.
const MAX_OUTPUT_TIMES: usize = 100_000;

/// Options of `eomgen simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any model file.
    pub model: String,
    /// Output times, comma separated (expressions allowed), e.g. `--t-out 1,2,2.5`; samples
    /// come from dense output at exactly these times (at most 100000). Default: every accepted
    /// step.
    #[arg(long, value_delimiter = ',')]
    pub t_out: Vec<String>,
    /// What to integrate and how.
    #[command(flatten)]
    pub run: IntegrationArgs,
    /// Print the result as JSON on stdout (byte-identical across runs: the wall time is left
    /// out unless `--timing` is given).
    #[arg(long)]
    pub json: bool,
    /// Add the wall time (`stats.wall_time_s`) to the JSON output.
    #[arg(long)]
    pub timing: bool,
    /// Write the samples as CSV (t, coordinates, rates, energy).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<String>,
    /// Plot the coordinates against time (.svg or .png); a constrained model also gets its
    /// constraint drift in `FILE-drift.svg`.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
    /// Plot the phase portrait, each rate against its coordinate (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot_phase: Option<String>,
    /// Plot the energy drift E(t) − E(0) against time (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot_energy: Option<String>,
}

/// The integration options that `simulate` and `animate` share: end time, method,
/// tolerances, parameters, initial state, drift control and events.
#[derive(Debug, Args)]
pub struct IntegrationArgs {
    /// End time (s).
    #[arg(long, default_value_t = 10.0)]
    pub t_end: f64,
    /// Integration method.
    #[arg(long, value_parser = method_parser(), default_value_t = Method::Dp54)]
    pub method: Method,
    /// Relative tolerance (adaptive methods: bs32, dp54, dop853, radau5).
    #[arg(long, default_value_t = 1e-8, value_parser = super::values::relative_tolerance, allow_hyphen_values = true)]
    pub rtol: f64,
    /// Absolute tolerance (adaptive methods; implicit-midpoint's scale for components near 0).
    #[arg(long, default_value_t = 1e-10, value_parser = super::values::absolute_tolerance, allow_hyphen_values = true)]
    pub atol: f64,
    /// Step size: the fixed step of euler, midpoint, rk4, symplectic-euler, stormer-verlet and
    /// implicit-midpoint (default t_end/1000); the initial step of the adaptive methods
    /// (default automatic).
    #[arg(long)]
    pub dt: Option<f64>,
    /// Set a parameter, `NAME=VALUE` (value may be an expression of numbers, pi and the other
    /// parameters); repeatable.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Set initial coordinates or rates, `NAME=VALUE` or a comma list (e.g.
    /// `theta1=pi/2,theta1_dot=0`); repeatable.
    #[arg(long = "init", value_name = "NAME=VALUE,…")]
    pub init: Vec<String>,
    /// Drift control of a constrained model: `none` (show the drift), `baumgarte`
    /// (Φ̈ + 2α Φ̇ + β² Φ = 0, see --baumgarte) or `projection` (onto Φ = 0 and the velocity
    /// constraints after every step). Ignored without constraints.
    #[arg(long, value_enum, default_value_t = StabilizationArg::None)]
    pub stabilization: StabilizationArg,
    /// Baumgarte's α and β (1/s, in [0, 1e6]), `ALPHA,BETA`.
    #[arg(long, value_name = "ALPHA,BETA", value_delimiter = ',', value_parser = super::values::baumgarte_gain, allow_hyphen_values = true, default_values_t = [10.0, 10.0])]
    pub baumgarte: Vec<f64>,
    /// Stop at the first zero of a function: a model event's name (`--stop-when lift_off`)
    /// or `EXPR` / `LHS = RHS`, optionally followed by `, rising`, `, falling` or `, both`
    /// (e.g. `--stop-when "theta_dot = 0, falling"`); names: parameters, coordinates, `t`,
    /// rates `x_dot`, accelerations `x_ddot`, constraint forces `lambda_<constraint>`;
    /// repeatable (the first to occur stops).
    #[arg(long = "stop-when", value_name = "EVENT")]
    pub stop_when: Vec<String>,
    /// Locate the zeros of a function without stopping (same syntax as --stop-when);
    /// repeatable. The model file's own `events:` are always located.
    #[arg(long = "event", value_name = "EVENT")]
    pub event: Vec<String>,
}

impl IntegrationArgs {
    /// The command line's defaults, as `eomgen simulate MODEL` without options.
    ///
    /// # Errors
    /// None in practice: parsing an empty command line only fails if a default is invalid.
    pub(crate) fn defaults() -> Result<Self, CliError> {
        #[derive(clap::Parser)]
        struct Defaults {
            #[command(flatten)]
            args: IntegrationArgs,
        }
        <Defaults as clap::Parser>::try_parse_from(["eomgen"])
            .map(|d| d.args)
            .map_err(|e| CliError::failure(format!("default integration options: {e}")))
    }

    /// How the method controls its step: `rtol 1e-8, atol 1e-10` for an adaptive method,
    /// `fixed step dt = 1e-2 s` otherwise (`--dt`, default `t_end/1000`).
    pub(crate) fn step_control(&self) -> String {
        if self.method.is_adaptive() {
            format!("rtol {:e}, atol {:e}", num(self.rtol), num(self.atol))
        } else {
            let dt = self.dt.unwrap_or(self.t_end / 1000.0);
            format!("fixed step dt = {dt:e} s", dt = num(dt))
        }
    }
}

/// One integration of a model from its initial state, as `simulate` and `animate` run it.
pub(crate) struct Run {
    /// The model, with `--set` and the drift control applied.
    pub model: Box<dyn ModelInfo>,
    /// The consistent initial state `[q; q̇]`.
    pub y0: Vec<f64>,
    /// The samples: all of them, or those computed before a failure.
    pub solution: Solution,
    /// Why the integration stopped early, if it did.
    pub failure: Option<IntegrationError>,
    /// What the model shows where it stopped, if anything.
    pub cause: Option<FailureCause>,
    /// The integrator's name (`dp54`).
    pub method_name: &'static str,
}

/// Runs `simulate`.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    // Every file this run may write or remove, checked before any work: `--csv FILE` owns
    // `FILE-events.csv` and `--plot FILE` owns `FILE-drift.EXT` (written when the run has
    // events or constraints, else removed when an earlier run left one). An output written
    // in place (`/dev/stdout`, a FIFO) has no directory beside it, so no companion.
    let companion = |path: &Option<String>, tag: &str| {
        path.as_deref()
            .filter(|path| !files::writes_in_place(path))
            .map(|path| sibling(path, tag))
    };
    let events_csv = companion(&args.csv, "events");
    let drift_chart = companion(&args.plot, "drift");
    Outputs::new()
        .input(&args.model)
        .file("--csv", args.csv.as_deref())
        .file("--csv (its events file)", events_csv.as_deref())
        .chart("--plot", args.plot.as_deref())
        .chart(
            "--plot (its constraint drift chart)",
            drift_chart.as_deref(),
        )
        .chart("--plot-phase", args.plot_phase.as_deref())
        .chart("--plot-energy", args.plot_energy.as_deref())
        .check()?;
    if args.t_out.len() > MAX_OUTPUT_TIMES {
        return Err(CliError::usage(format!(
            "--t-out lists {} times; at most {MAX_OUTPUT_TIMES} are allowed",
            args.t_out.len()
        )));
    }
    let mut times = Vec::with_capacity(args.t_out.len());
    for t in &args.t_out {
        times.push(evaluate(t, "--t-out", &|_| None)?);
    }
    let output = if times.is_empty() {
        OutputTimes::Steps
    } else {
        OutputTimes::At(times)
    };
    let (model, simulation) = simulation(&args.model, &args.run, output)?;
    let Simulation {
        solution,
        energy: report,
        constraints,
        failure,
        cause,
        warnings,
        integrator: method_name,
        ..
    } = simulation;
    for warning in &warnings {
        super::output::errln!("warning: {warning}");
    }
    let n = model.num_dofs();
    let coordinates: Vec<String> = model
        .description()
        .coordinate_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    // The files of a failed integration say so: `# incomplete: <reason> at t = <t>` above a
    // CSV's header, the same note on the charts (and `"error"` in the JSON below).
    let incomplete = failure.as_ref().map(|e| match e.t() {
        // The reasons with a time say "at t = …" themselves.
        Some(t) if !e.to_string().contains("t = ") => format!("incomplete: {e} at t = {t}"),
        _ => format!("incomplete: {e}"),
    });
    if let Some(path) = &args.csv {
        write_csv(
            path,
            model.as_ref(),
            &solution,
            &report,
            &constraints,
            incomplete.as_deref(),
        )?;
    }
    // A companion this run has nothing for is removed when an earlier run of eomgen wrote
    // it; a file of that name that eomgen did not write is kept, with a warning.
    if let Some(events) = &events_csv {
        if solution.events.is_empty() {
            files::remove_stale_or_warn(events, is_events_csv)?;
        } else {
            write_events_csv(events, model.as_ref(), &solution)?;
        }
    }
    if let Some(path) = &args.plot {
        plot::time_histories(path, model.as_ref(), &solution, incomplete.as_deref())
            .map_err(CliError::failure)?;
    }
    if let Some(drift_path) = &drift_chart {
        if constraints.is_empty() {
            files::remove_stale_or_warn(drift_path, plot::is_own_drift_chart)?;
        } else {
            plot::constraint_drift(
                drift_path,
                &model.description().name,
                &solution.t,
                &constraints.drift,
                incomplete.as_deref(),
            )
            .map_err(CliError::failure)?;
        }
    }
    if let Some(path) = &args.plot_phase {
        plot::phase_portrait(path, model.as_ref(), &solution, incomplete.as_deref())
            .map_err(CliError::failure)?;
    }
    if let Some(path) = &args.plot_energy {
        plot::energy_drift(
            path,
            &model.description().name,
            &solution.t,
            &report.energy,
            report.initial_energy,
            incomplete.as_deref(),
        )
        .map_err(CliError::failure)?;
    }
    if args.json {
        let samples: Vec<serde_json::Value> = solution
            .iter()
            .zip(&report.energy)
            .enumerate()
            .map(|(k, ((t, y), e))| {
                let mut sample = json!({"t": t, "q": &y[..n], "qdot": &y[n..], "energy": e});
                if !constraints.is_empty() {
                    sample["constraint_forces"] = json!(constraints.lagrange_multipliers[k]);
                    sample["constraint_drift"] =
                        json!({"position": constraints.drift[k].0, "velocity": constraints.drift[k].1});
                }
                sample
            })
            .collect();
        let mut out = json!({
            "model": model.description().name,
            "coordinates": coordinates,
            "parameters": model.description().parameter_names().iter().zip(model.parameter_values()).map(|(k, v)| (k.to_string(), json!(v))).collect::<serde_json::Map<_, _>>(),
            "method": method_name,
            "rtol": args.run.rtol,
            "atol": args.run.atol,
            "samples": samples,
            "initial_energy": report.initial_energy,
            "energy_drift": report.drift,
            "conservative": model.description().conservative,
            "stats": {
                "steps": solution.stats.steps,
                "rejected": solution.stats.rejected,
                "rhs_evals": solution.stats.rhs_evals,
                "jacobian_evals": solution.stats.jacobian_evals,
                "lu_decompositions": solution.stats.lu_decompositions,
                "event_evals": solution.stats.event_evals,
            },
        });
        if args.timing {
            out["stats"]["wall_time_s"] = json!(solution.stats.wall_time_s);
        }
        if !constraints.is_empty() {
            out["constraints"] = json!(constraints.constraint_names);
            out["stabilization"] = json!(format!("{:?}", args.run.stabilization).to_lowercase());
            out["max_constraint_drift"] = json!({
                "position": constraints.max_drift().0,
                "velocity": constraints.max_drift().1,
            });
        }
        if !solution.events.is_empty()
            || !args.run.stop_when.is_empty()
            || !args.run.event.is_empty()
        {
            out["events"] = json!(
                solution
                    .events
                    .iter()
                    .map(|e| json!({
                        "name": e.name,
                        "t": e.t,
                        "direction": e.direction.name(),
                        "terminal": e.terminal,
                        "q": &e.y[..n],
                        "qdot": &e.y[n..],
                    }))
                    .collect::<Vec<_>>()
            );
            out["terminated_by_event"] = json!(
                solution
                    .terminated_by_event
                    .map(|k| solution.events[k].name.clone())
            );
        }
        if let Some(e) = &failure {
            out["error"] = json!({"t": e.t(), "message": e.to_string()});
        }
        if !warnings.is_empty() {
            out["warnings"] = json!(
                warnings
                    .iter()
                    .map(|w| {
                        let mut warning = json!(w);
                        warning["message"] = json!(w.to_string());
                        warning
                    })
                    .collect::<Vec<_>>()
            );
        }
        let text =
            serde_json::to_string_pretty(&out).map_err(|e| CliError::failure(e.to_string()))?;
        let mut stdout = super::output::stdout();
        let _ = writeln!(stdout, "{text}");
    } else {
        print_summary(model.as_ref(), method_name, &args.run, &solution, &report);
        print_constraint_summary(&constraints, args.run.stabilization);
        print_events(model.as_ref(), &solution);
    }
    match failure {
        None => Ok(()),
        Some(e) => Err(failure_error(
            &model.description().name,
            &e,
            cause.as_ref(),
            &args.run,
            &format!(
                "the {} samples computed before it were kept",
                solution.len()
            ),
        )),
    }
}

impl IntegrationArgs {
    /// The library's options of these arguments, sampled at `output`, from the initial state
    /// `y0`.
    ///
    /// # Errors
    /// A usage error when `--baumgarte` does not give exactly two gains.
    fn simulation_options(
        &self,
        output: OutputTimes,
        y0: Vec<f64>,
    ) -> Result<SimulationOptions, CliError> {
        let &[alpha, beta] = self.baumgarte.as_slice() else {
            return Err(CliError::usage(format!(
                "--baumgarte takes two gains ALPHA,BETA (1/s), got {}",
                self.baumgarte.len()
            )));
        };
        Ok(SimulationOptions {
            method: self.method,
            t_end: self.t_end,
            rtol: self.rtol,
            atol: self.atol,
            dt: self.dt,
            output,
            stabilization: match self.stabilization {
                StabilizationArg::None => Stabilization::None,
                StabilizationArg::Baumgarte => Stabilization::Baumgarte { alpha, beta },
                StabilizationArg::Projection => Stabilization::Projection,
            },
            initial_state: Some(y0),
        })
    }
}

/// Simulates `model_name` (a bundled model or a model file) with `args`: `--set` and
/// `--init` applied, the events of `--stop-when` and `--event` added, then one call of
/// [`simulate_with_events`].
///
/// # Errors
/// A usage error for an unknown model, parameter, coordinate or event, or a `--t-end` that
/// is not a positive number; a failure when no consistent initial state exists. A failed
/// integration is not an error here: it is [`Simulation::failure`], with the samples
/// computed before it.
fn simulation(
    model_name: &str,
    args: &IntegrationArgs,
    output: OutputTimes,
) -> Result<(Box<dyn ModelInfo>, Simulation), CliError> {
    let mut model = find_model(model_name)?;
    set_parameters(model.as_mut(), &args.set)?;
    let mut y0 = model.initial_state();
    set_initial_values(model.as_ref(), &mut y0, &args.init).map_err(usage)?;
    let mut added =
        ExpressionEvents::parse(model.as_mut(), &args.stop_when, &args.event).map_err(usage)?;
    let options = args.simulation_options(output, y0)?;
    let added: Option<&mut dyn AddedEvents> = if added.is_empty() {
        None
    } else {
        Some(&mut added)
    };
    let simulation =
        simulate_with_events(model.as_mut(), &options, added).map_err(simulation_error)?;
    // A failure without a time is an invalid input (output times out of order, a step of 0)
    // that stopped the run before its first step: a usage error, with no file written, in
    // `simulate`, `animate` and `report` alike.
    if let Some(e) = &simulation.failure
        && e.t().is_none()
    {
        return Err(CliError::usage(e.to_string()).before_output());
    }
    Ok((model, simulation))
}

/// A simulation that could not start, as the CLI reports it.
pub(crate) fn simulation_error(error: SimulationError) -> CliError {
    match error {
        SimulationError::InvalidEndTime { t_end } => CliError::usage(format!(
            "--t-end must be a positive number of seconds, got {:e}",
            num(t_end)
        )),
        SimulationError::InconsistentInitialState {
            model,
            constraint,
            residual,
            iterations,
            has_guesses,
        } => CliError::failure(inconsistent_message(
            &model,
            &constraint,
            residual,
            iterations,
            has_guesses,
        )),
        SimulationError::InvalidStabilization(e) => CliError::usage(format!("--baumgarte: {e}")),
        other => CliError::usage(other.to_string()),
    }
}

/// What to say when no consistent initial state was found.
fn inconsistent_message(
    model: &str,
    constraint: &str,
    residual: f64,
    iterations: usize,
    has_guesses: bool,
) -> String {
    if has_guesses {
        format!(
            "no consistent initial state for `{model}`: constraint `{constraint}` keeps a residual of {residual:.3e} after {iterations} Newton iteration(s) from the guesses; try other guesses",
            residual = num(residual)
        )
    } else {
        format!(
            "the initial state of `{model}` violates its constraints: `{constraint}` has a residual of {residual:.3e}; mark the dependent coordinates as `{{ guess: … }}` in `initial:` or fix the values",
            residual = num(residual)
        )
    }
}

/// Integrates `model_name` with `args` as `simulate` does (see [`simulation`]), sampled at
/// `output`: the shared start of `simulate`, `animate` and `report`.
///
/// # Errors
/// As [`simulation`]; report a failed integration with [`failure_error`].
pub(crate) fn integrate(
    model_name: &str,
    args: &IntegrationArgs,
    output: OutputTimes,
) -> Result<Run, CliError> {
    let (model, simulation) = simulation(model_name, args, output)?;
    Ok(Run {
        model,
        y0: simulation.initial_state,
        solution: simulation.solution,
        failure: simulation.failure,
        cause: simulation.cause,
        method_name: simulation.integrator,
    })
}

/// The error of a failed integration of `model`: where and why it stopped, what became of
/// the samples (`kept`), and what to try.
pub(crate) fn failure_error(
    model: &str,
    error: &IntegrationError,
    cause: Option<&FailureCause>,
    args: &IntegrationArgs,
    kept: &str,
) -> CliError {
    CliError::failure(format!(
        "integration of `{model}` stopped: {error}; {kept}\nhelp: {}",
        failure_hint(error, cause, args)
    ))
}

/// An end time from which on `f64` resolves `t` only to steps of `16 ε t_end ≈ 3.6e-9 s` or
/// coarser: a step-size underflow there comes from the end time, not from the model.
const COARSE_TIME_END: f64 = 1e6;

/// A relative tolerance this loose or looser no longer keeps the step inside the region
/// where the error estimate is asymptotically right; an underflow there is the tolerance's.
const LOOSE_RTOL: f64 = 1e-2;

/// What to try after a failed integration (issue 8, item 3), by the reason, the method and
/// the settings: a step-size underflow is blamed on the end time or the tolerance where
/// those explain it, before stiffness or a singularity.
fn failure_hint(
    error: &IntegrationError,
    cause: Option<&FailureCause>,
    args: &IntegrationArgs,
) -> String {
    let method = args.method;
    let explicit = !method.is_implicit();
    let adaptive = method.is_adaptive();
    // What the model shows where the run stopped comes before any guess about the method.
    if let Some(cause) = cause {
        let what_to_do = match cause {
            FailureCause::MassMatrixDegenerateEverywhere { .. } => {
                "check the parameters (--set) and that every coordinate moves some mass"
            }
            FailureCause::NegativeParameters { .. } => "masses and inertias must be positive",
            FailureCause::SingularCoordinates { .. } | FailureCause::InertiaVanishes { .. } => {
                "choose coordinates that stay regular there, or add the motion as a constraint"
            }
            _ => "check the model's expressions and the initial state near that t",
        };
        return format!("{cause}; {what_to_do}");
    }
    let hint = match error {
        IntegrationError::StepSizeTooSmall { .. } if args.t_end >= COARSE_TIME_END => {
            return format!(
                "the end time {:e} s is so large that f64 resolves t only to about {:.1e} s near it, coarser than the steps the motion needs; shorten --t-end (or rescale time in the model)",
                args.t_end,
                16.0 * f64::EPSILON * args.t_end
            );
        }
        IntegrationError::StepSizeTooSmall { .. } if adaptive && args.rtol >= LOOSE_RTOL => {
            return format!(
                "--rtol {} is too loose for the error estimate to steer the step (it grows until the solution is lost, then collapses); use --rtol 1e-3 or tighter",
                args.rtol
            );
        }
        IntegrationError::StepSizeTooSmall { .. } | IntegrationError::TooManySteps { .. }
            if explicit && adaptive =>
        {
            "the model may be stiff (a fast mode forces tiny steps on an explicit method); try --method radau5"
        }
        IntegrationError::StepSizeTooSmall { .. } => {
            "the solution may have a singularity there (it blows up or loses smoothness); check the model and the initial state near that t"
        }
        IntegrationError::TooManySteps { .. } if !adaptive => {
            "a fixed-step run takes t_end/dt steps, more than allowed here: use a larger --dt or shorten --t-end"
        }
        IntegrationError::TooManySteps { .. } if explicit => {
            "the run needs more steps than allowed: loosen --rtol/--atol, shorten --t-end, or use --method radau5 if the model is stiff"
        }
        IntegrationError::TooManySteps { .. } => {
            "the run needs more steps than allowed: loosen --rtol/--atol or shorten --t-end"
        }
        IntegrationError::JacobianNonFinite { .. } => {
            "the Jacobian of the right-hand side is not finite there, even by differences, though the right-hand side is: a term of the model grows without bound in its derivative; smooth the model there, or use an explicit method (--method dopri5)"
        }
        IntegrationError::NonFiniteState { .. } | IntegrationError::RhsNonFinite { .. }
            if !adaptive =>
        {
            "the state blew up: the fixed step may be beyond the method's stability limit (`eomgen study stability`); try a smaller --dt or an adaptive method"
        }
        IntegrationError::NonFiniteState { .. } | IntegrationError::RhsNonFinite { .. } => {
            "a right-hand side or state became infinite or NaN: the model may divide by zero or leave the domain of a function (sqrt, log, asin) there"
        }
        IntegrationError::SingularMassMatrix { .. } => {
            "the coordinates are singular at that configuration (M loses rank); choose coordinates that stay regular, or add the motion as a constraint"
        }
        IntegrationError::SingularConstraintMatrix { .. }
        | IntegrationError::ProjectionFailed { .. } => {
            "the constraints are redundant or the mechanism reaches a singular configuration there; try --stabilization projection or check the constraints"
        }
        IntegrationError::NewtonDidNotConverge { .. }
        | IntegrationError::SingularIterationMatrix { .. } => {
            "the implicit step did not converge: try a smaller --dt (or tighter --rtol with radau5)"
        }
        IntegrationError::EventNotFinite { .. } => {
            "an event function is NaN there: check its expression (division by zero, sqrt of a negative)"
        }
        _ => "check the options against `eomgen simulate --help`",
    };
    hint.to_string()
}

fn print_summary(
    model: &dyn ModelInfo,
    method: &str,
    args: &IntegrationArgs,
    solution: &Solution,
    report: &EnergyDrift,
) {
    outln!(
        "model      {} ({} dof): {}",
        model.description().name,
        model.num_dofs(),
        model.description().summary
    );
    outln!("method     {method} ({})", args.step_control());
    if let Some((t, y)) = solution.last() {
        let n = model.num_dofs();
        let names = model.description().coordinate_names();
        outln!("final      t = {t}");
        for (i, name) in names.iter().enumerate() {
            outln!(
                "           {name:>12} = {:>22.15e}   {:>16} = {:>22.15e}",
                num(y[i]),
                format!("{name}_dot"),
                num(y[n + i])
            );
        }
    }
    if let (e0, Some(e1)) = (report.initial_energy, report.energy.last()) {
        outln!(
            "energy     E(0) = {e0:.12e} J, E(end) = {e1:.12e} J",
            e0 = num(e0),
            e1 = num(e1)
        );
        if let Some(d) = report.drift {
            let note = if model.description().conservative {
                ""
            } else {
                " (not conserved: the model has non-conservative loads or explicit time dependence)"
            };
            outln!(
                "drift      max|E - E(0)| / max(T + |V|) = {d:.3e}{note}",
                d = num(d)
            );
        }
    }
    let s = &solution.stats;
    let implicit = if s.jacobian_evals > 0 {
        format!(
            ", {} Jacobians, {} LU factorisations",
            s.jacobian_evals, s.lu_decompositions
        )
    } else {
        String::new()
    };
    outln!(
        "work       {} steps ({} rejected), {} RHS evaluations{implicit}, {:.3} ms",
        s.steps,
        s.rejected,
        s.rhs_evals,
        s.wall_time_s * 1e3
    );
}

fn write_csv(
    path: &str,
    model: &dyn ModelInfo,
    solution: &Solution,
    report: &EnergyDrift,
    constraints: &ConstraintDrift,
    incomplete: Option<&str>,
) -> Result<(), CliError> {
    let mut out = incomplete.map_or_else(String::new, |note| format!("# {note}\n"));
    out.push('t');
    for c in model.description().coordinate_names() {
        out.push(',');
        out.push_str(c);
    }
    for c in model.description().coordinate_names() {
        out.push_str(&format!(",{c}_dot"));
    }
    out.push_str(",energy");
    for c in &constraints.constraint_names {
        out.push_str(&format!(",lambda_{c}"));
    }
    if !constraints.is_empty() {
        out.push_str(",drift_position,drift_velocity");
    }
    out.push('\n');
    for (k, ((t, y), e)) in solution.iter().zip(&report.energy).enumerate() {
        out.push_str(&format!("{t:e}"));
        for v in y {
            out.push_str(&format!(",{v:e}"));
        }
        out.push_str(&format!(",{e:e}"));
        if !constraints.is_empty() {
            // A state where λ cannot be solved (singular KKT matrix) leaves empty cells.
            match &constraints.lagrange_multipliers[k] {
                Some(forces) => forces.iter().for_each(|l| out.push_str(&format!(",{l:e}"))),
                None => out.push_str(&",".repeat(constraints.constraint_names.len())),
            }
            let (p, v) = constraints.drift[k];
            out.push_str(&format!(",{p:e},{v:e}"));
        }
        out.push('\n');
    }
    Ok(super::files::write(path, out.as_bytes())?)
}

/// The located events: name, direction, time and state, and the intervals between
/// successive zeros of the same function (HW21: the period from successive peaks).
fn print_events(model: &dyn ModelInfo, solution: &Solution) {
    if solution.events.is_empty() {
        return;
    }
    let n = model.num_dofs();
    let names = model.description().coordinate_names();
    outln!("events     {} located:", solution.events.len());
    for e in &solution.events {
        let state: Vec<String> = names
            .iter()
            .enumerate()
            .map(|(i, c)| {
                format!(
                    "{c} = {:.9e}, {c}_dot = {:.9e}",
                    num(e.y[i]),
                    num(e.y[n + i])
                )
            })
            .collect();
        outln!(
            "           {:<16} {:<8} t = {:.15e}   {}",
            e.name,
            e.direction.name(),
            num(e.t),
            state.join(", ")
        );
    }
    let mut seen: Vec<&str> = Vec::new();
    for e in &solution.events {
        if seen.contains(&e.name.as_str()) {
            continue;
        }
        seen.push(&e.name);
        let times: Vec<f64> = solution
            .events
            .iter()
            .filter(|x| x.name == e.name)
            .map(|x| x.t)
            .collect();
        if times.len() >= 2 {
            let intervals: Vec<String> = times
                .windows(2)
                .map(|w| format!("{:.12e}", num(w[1] - w[0])))
                .collect();
            outln!(
                "intervals  between successive `{}`: {} s",
                e.name,
                intervals.join(", ")
            );
        }
    }
    if let Some(k) = solution.terminated_by_event {
        let e = &solution.events[k];
        outln!("stopped    at t = {:.15e} by event `{}`", num(e.t), e.name);
    }
}

/// The first columns of an events CSV's header ([`write_events_csv`]).
const EVENTS_HEADER: &str = "event,direction,terminal,t";

/// Whether `bytes` is an events CSV that eomgen wrote, for any model: its first line is the
/// exact header [`write_events_csv`] writes, [`EVENTS_HEADER`] then the coordinates `c₁…cₙ`
/// and their rates `c₁_dot…cₙ_dot`.
fn is_events_csv(bytes: &[u8]) -> bool {
    let Some(line) = bytes.split(|&b| b == b'\n').next() else {
        return false;
    };
    let Some(columns) = std::str::from_utf8(line)
        .ok()
        .and_then(|line| line.strip_prefix(EVENTS_HEADER)?.strip_prefix(','))
    else {
        return false;
    };
    let columns: Vec<&str> = columns.split(',').collect();
    let (coordinates, rates) = columns.split_at(columns.len() / 2);
    columns.len().is_multiple_of(2)
        && coordinates
            .iter()
            .zip(rates)
            .all(|(c, r)| !c.is_empty() && r.strip_suffix("_dot") == Some(c))
}

/// The located events as CSV: name, direction, t, coordinates, rates.
fn write_events_csv(
    path: &str,
    model: &dyn ModelInfo,
    solution: &Solution,
) -> Result<(), CliError> {
    let mut out = String::from(EVENTS_HEADER);
    for c in model.description().coordinate_names() {
        out.push_str(&format!(",{c}"));
    }
    for c in model.description().coordinate_names() {
        out.push_str(&format!(",{c}_dot"));
    }
    out.push('\n');
    for e in &solution.events {
        out.push_str(&format!(
            "{},{},{},{:e}",
            e.name,
            e.direction.name(),
            e.terminal,
            num(e.t)
        ));
        for v in &e.y {
            out.push_str(&format!(",{v:e}"));
        }
        out.push('\n');
    }
    Ok(super::files::write(path, out.as_bytes())?)
}

/// `dir/name.svg` → `dir/name-{tag}.svg`, `dir.d/name` → `dir.d/name-{tag}` (only the
/// file name's extension counts; a leading dot starts no extension).
fn sibling(path: &str, tag: &str) -> String {
    let name = path.rfind('/').map_or(0, |i| i + 1);
    match path[name..].rfind('.') {
        Some(dot) if dot > 0 => {
            let (stem, ext) = path.split_at(name + dot);
            format!("{stem}-{tag}{ext}")
        }
        _ => format!("{path}-{tag}"),
    }
}

/// The constraint forces at the end and the largest drift, under `stabilization`.
fn print_constraint_summary(constraints: &ConstraintDrift, stabilization: StabilizationArg) {
    if constraints.is_empty() {
        return;
    }
    if let Some(Some(last)) = constraints.lagrange_multipliers.last() {
        let forces: Vec<String> = constraints
            .constraint_names
            .iter()
            .zip(last)
            .map(|(n, l)| format!("{n} = {l:.9e}", l = num(l)))
            .collect();
        outln!("lambda     at the end: {}", forces.join(", "));
    }
    let (p, v) = constraints.max_drift();
    outln!(
        "drift      constraints ({}): max |Φ| = {p:.3e}, max |Φ̇| = {v:.3e}",
        format!("{stabilization:?}").to_lowercase(),
        p = num(p),
        v = num(v)
    );
}

#[cfg(test)]
mod tests {
    use super::{is_events_csv, sibling};

    /// Only the file name's extension counts (a dot in a directory name used to put the tag
    /// inside the directory's name), and a leading dot starts no extension.
    #[test]
    fn siblings_keep_the_extension_of_the_file_name() {
        assert_eq!(sibling("out/run.csv", "events"), "out/run-events.csv");
        assert_eq!(sibling("out.d/run", "events"), "out.d/run-events");
        assert_eq!(sibling("run", "drift"), "run-drift");
        assert_eq!(sibling("dir/.hidden", "drift"), "dir/.hidden-drift");
        assert_eq!(sibling("a.b/c.tar.svg", "drift"), "a.b/c.tar-drift.svg");
    }

    /// An events CSV is recognised by the exact header eomgen writes, for any model; a file
    /// whose first line differs in any way is not ours.
    #[test]
    fn an_events_csv_is_recognised_by_its_header() {
        for ours in [
            "event,direction,terminal,t,q,q_dot\n",
            "event,direction,terminal,t,x,theta,x_dot,theta_dot\nhit,rising,true,1e0,0,0,0,0\n",
        ] {
            assert!(is_events_csv(ours.as_bytes()), "{ours}");
        }
        for theirs in [
            "mine\n",
            "",
            "event,direction,terminal,t\n",
            "event,direction,terminal,t,q\n",
            "event,direction,terminal,t,q,p_dot\n",
            "event,direction,terminal,time,q,q_dot\n",
            "event,direction,terminal,t,q,q_dot,extra\n",
            "# event,direction,terminal,t,q,q_dot\n",
        ] {
            assert!(!is_events_csv(theirs.as_bytes()), "{theirs}");
        }
    }
}
