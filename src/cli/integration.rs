//! The integration options and run that `simulate`, `animate`, `report` and the
//! work-precision study share: `--method` (with each method's help), `--rtol`/`--atol`,
//! `--set`/`--init`, drift control and events, one call of the library's simulation, and the
//! errors of a run that could not start or stopped early, with what to try.

use clap::{Args, ValueEnum};
pub(crate) use eomgen::Method;
use eomgen::Stabilization;
use eomgen::analysis::{
    AddedEvents, FailureCause, Simulation, SimulationError, SimulationOptions, check_initial_state,
    simulate_with_events,
};
use eomgen::expressions::{ExpressionEvents, set_initial_values};
use eomgen::{IntegrationError, ModelInfo, OutputTimes};

use super::error::CliError;
use super::model::find_model;
use super::render::num;
use super::values::{set_parameters, usage};

/// The names of the methods that are (`adaptive`) or are not adaptive, from the method table,
/// for the help of `--rtol` and `--dt`: `"bs32, dp54, …"`, the last joined by `joiner`.
fn method_names(adaptive: bool, joiner: &str) -> String {
    let names: Vec<&str> = Method::ALL
        .into_iter()
        // The Taylor method's tolerance chooses its order, as told in its own help.
        .filter(|m| m.is_adaptive() == adaptive && *m != Method::Taylor)
        .map(Method::name)
        .collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{}{joiner}{last}", rest.join(", ")),
        _ => names.join(", "),
    }
}

/// `--rtol`'s help.
fn rtol_help() -> String {
    format!(
        "Relative tolerance (adaptive methods: {})",
        method_names(true, ", ")
    )
}

/// `--dt`'s help.
fn dt_help() -> String {
    format!(
        "Step size: the fixed step of {} (default t_end/1000); the initial step of the adaptive methods (default automatic)",
        method_names(false, " and ")
    )
}

/// clap's parser of a method name (`--method`, `--methods`): the names of [`Method::ALL`]
/// with their help, parsed by [`Method`]'s `FromStr`. Adaptive methods use
/// `--rtol`/`--atol` (and `--dt` as their first step); fixed-step methods use `--dt`
/// (default `t_end/1000`).
pub(super) fn method_parser() -> impl clap::builder::TypedValueParser<Value = Method> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser as _};
    PossibleValuesParser::new(Method::ALL.map(|m| PossibleValue::new(m.name()).help(m.summary())))
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

/// The integration options that `simulate` and `animate` share: end time, method,
/// tolerances, parameters, initial state, drift control and events.
#[derive(Debug, Args)]
pub struct IntegrationArgs {
    /// End time (s).
    #[arg(long, default_value_t = SimulationOptions::DEFAULT_T_END)]
    pub t_end: f64,
    /// Integration method.
    #[arg(long, value_parser = method_parser(), default_value_t = SimulationOptions::DEFAULT_METHOD)]
    pub method: Method,
    /// Relative tolerance; its help, which names the adaptive methods, is `rtol_help`'s.
    #[arg(long, help = rtol_help(), default_value_t = SimulationOptions::DEFAULT_RTOL, value_parser = super::values::relative_tolerance, allow_hyphen_values = true)]
    pub rtol: f64,
    /// Absolute tolerance (adaptive methods; implicit-midpoint's scale for components near 0).
    #[arg(long, default_value_t = SimulationOptions::DEFAULT_ATOL, value_parser = super::values::absolute_tolerance, allow_hyphen_values = true)]
    pub atol: f64,
    /// Step size; its help, which names the fixed-step methods, is `dt_help`'s.
    #[arg(long, help = dt_help())]
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
    #[arg(long, value_name = "ALPHA,BETA", value_delimiter = ',', value_parser = super::values::baumgarte_gain, allow_hyphen_values = true, default_values_t = eomgen::Stabilization::DEFAULT_BAUMGARTE_GAINS)]
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
    /// `fixed step dt = 1e-2 s` otherwise (`--dt`, default `t_end/1000`), as
    /// [`eomgen::text::step_control`] says it.
    pub(crate) fn step_control(&self) -> String {
        eomgen::text::step_control(&SimulationOptions {
            method: self.method,
            t_end: self.t_end,
            rtol: self.rtol,
            atol: self.atol,
            dt: self.dt,
            ..SimulationOptions::default()
        })
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
pub(super) fn simulation(
    model_name: &str,
    args: &IntegrationArgs,
    output: OutputTimes,
) -> Result<(Box<dyn ModelInfo>, Simulation), CliError> {
    let mut model = find_model(model_name)?;
    set_parameters(model.as_mut(), &args.set)?;
    let mut y0 = model.initial_state();
    check_initial_state(model.description(), &y0, false).map_err(simulation_error)?;
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
pub(super) fn simulation_error(error: SimulationError) -> CliError {
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
        e @ SimulationError::InitialStateNotFinite { given: false, .. } => {
            CliError::failure(e.to_string())
        }
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
            "the initial state of `{model}` violates its constraints: `{constraint}` has a residual of {residual:.3e}; fix the values, or in the rates mark the dependent coordinates as `{{ guess: … }}` in `initial:` (in generalized speeds, give the speeds, and coordinates on the holonomic constraints: the auxiliary speeds then start at 0)",
            residual = num(residual)
        )
    }
}

/// The error of a failed integration of `model`: where and why it stopped, what became of
/// the samples (`kept`), and what to try.
pub(super) fn failure_error(
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
    // Settings that make the run impossible come first: whatever the model shows where a
    // run with them stopped is their consequence (an end time of 1e300 s made a first step
    // of 3.6e285 s, and then an infinite state, read as a division by zero).
    if let Some(hint) = settings_hint(error, args) {
        return hint;
    }
    // What the model shows where the run stopped comes before any guess about the method.
    if let Some(cause) = cause {
        return cause_hint(cause);
    }
    error_hint(error, args)
}

/// The hint when the settings make the run impossible: an end time too large for `f64` to
/// resolve the steps near it, or tolerances that a step collapsing at the start points to
/// (`--rtol` below what `f64` delivers, `--atol 0`); `None` when the settings explain
/// nothing.
fn settings_hint(error: &IntegrationError, args: &IntegrationArgs) -> Option<String> {
    let adaptive = args.method.is_adaptive();
    // Beyond 2.8e14 s, t is resolved to a second or worse near the end: a failure within the
    // first such step is the end time's (the first step is at least that long).
    let resolution = 16.0 * f64::EPSILON * args.t_end;
    if resolution >= 1.0
        && error
            .t()
            .is_some_and(|t| t == 0.0 || t.abs() >= 1e-3 * resolution)
    {
        return Some(coarse_end_hint(args.t_end));
    }
    // The tolerances explain a step that collapsed at the start, not a run that met something
    // in the model on its way (a blow-up at t = 2.38 stops the same at --rtol 1e-16 and 1e-10).
    let collapsed = matches!(
        error,
        IntegrationError::StepSizeTooSmall { .. } | IntegrationError::TooManySteps { .. }
    ) && error.t() == Some(0.0);
    if collapsed && adaptive && args.rtol < eomgen::analysis::work_precision::SMALLEST_TOLERANCE {
        return Some(format!(
            "--rtol {:e} is below what f64 delivers (its rounding, 1.1e-16 per operation, accumulates over a step to more than that): use --rtol 1e-15 or larger",
            args.rtol
        ));
    }
    if collapsed && adaptive && args.atol == 0.0 {
        return Some(format!(
            "--atol 0 leaves --rtol {:e} alone in control, and a component that starts at 0 (a rate at rest) then asks for its error relative to 0: give --atol above 0 (such as 1e-12)",
            args.rtol
        ));
    }
    None
}

/// The hint that an end time `t_end` (s) is too large: `f64` resolves `t` near it only to
/// `16 ε t_end`.
fn coarse_end_hint(t_end: f64) -> String {
    format!(
        "the end time {:e} s is so large that f64 resolves t only to about {:.1e} s near it, coarser than the steps the motion needs; shorten --t-end (or rescale time in the model)",
        t_end,
        16.0 * f64::EPSILON * t_end
    )
}

/// The hint of what the model shows where the run stopped: the cause, then what to do.
fn cause_hint(cause: &FailureCause) -> String {
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
    format!("{cause}; {what_to_do}")
}

/// The hint by the integration error alone, with the method (explicit or implicit, adaptive
/// or fixed-step) and the settings, when neither the settings ([`settings_hint`]) nor the
/// model ([`cause_hint`]) explain the failure.
fn error_hint(error: &IntegrationError, args: &IntegrationArgs) -> String {
    let method = args.method;
    let explicit = !method.is_implicit();
    let adaptive = method.is_adaptive();
    let hint = match error {
        IntegrationError::StepSizeTooSmall { .. } if args.t_end >= COARSE_TIME_END => {
            return coarse_end_hint(args.t_end);
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
            "the Jacobian of the right-hand side is not finite there, even by differences, though the right-hand side is: a term of the model grows without bound in its derivative; smooth the model there, or use an explicit method (--method dp54)"
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
