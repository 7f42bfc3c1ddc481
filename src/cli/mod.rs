//! Command-line interface (clap): the top level of the command line and the dispatch to the
//! commands.
//!
//! Two layers: each command (and each study) is a file of [`commands`], which parses its own
//! options, calls the library and renders the result; the pieces several commands share sit
//! beside this file (the error and exit status, opening a model, the integration and
//! operating-point options, files, charts, the animation's GIF, progress bars). A
//! command imports shared pieces, never another command.

mod animation;
mod arguments;
mod commands;
mod error;
mod files;
mod integration;
mod json;
mod mode_plot;
mod model;
mod operating_point;
pub(crate) mod output;
mod plot;
mod render;
mod report_html;
mod response_study;
mod values;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use commands::{
    animate, check, constraint_methods, equations, euler_roundoff, floquet, free_response, frf,
    list, modal_damping, modes, parameter_sweep, report, simulate, stability, work_precision,
};

/// eomgen: equations of motion derived at compile time from model files, simulated.
#[derive(Debug, Parser)]
#[command(name = "eomgen", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// List the bundled models: name, degrees of freedom, description.
    List {
        /// Print a JSON list of {"name", "dof", "description"}.
        #[arg(long)]
        json: bool,
    },
    /// Integrate a model's equations of motion from its initial state.
    Simulate(commands::simulate::SimulateArgs),
    /// Simulate a model and write its `draw:` lines moving as one self-contained HTML page
    /// (play/pause, speed, time scrubber, t and energy), optionally also a GIF.
    Animate(commands::animate::AnimateArgs),
    /// Derive a model (bundled, or any YAML file) by Lagrange and by momentum balance at run
    /// time and cross-check them and the power balance; exit 1 if a check fails.
    Check(commands::check::CheckArgs),
    /// Print a model's equations of motion M q'' = F (+ J^T lambda and J q'' = gamma with
    /// constraints) as text, LaTeX or JSON, derived at run time.
    Equations(commands::equations::EquationsArgs),
    /// Print a model's kinematics: the angular velocity and acceleration of its frames, the
    /// position, velocity and acceleration of its points, and their partial velocities, as
    /// text, LaTeX or JSON.
    Kinematics(commands::equations::KinematicsArgs),
    /// Equilibrium, exact linearisation (M, C, K), natural frequencies, mode shapes and
    /// damping ratios at an operating point (`--at hanging`).
    Modes(commands::modes::ModesArgs),
    /// Frequency response from a load parameter to coordinates: Bode chart, resonance peaks,
    /// modal contributions (`--modal`), points checked by simulation (`--simulate K`).
    Frf(commands::frf::FrfArgs),
    /// Print a generated model file: `n-link-pendulum N`, `n-mass-chain N` or
    /// `universal-joint-chain N`.
    New(commands::equations::NewArgs),
    /// Eliminate a model's holonomic constraints (method II.2): solve them for the
    /// coordinates not kept (`--keep x`) and write the model file in minimal coordinates.
    Reduce(commands::reduce::ReduceArgs),
    /// Run every model's checks (derivations, conservation, the reference values of its
    /// `checks:`) and write DIR/index.html (equations, figures, pass/fail tables) and
    /// DIR/report.json; exit 1 if a check fails.
    Report(commands::report::ReportArgs),
    /// Numerical experiments: `work-precision`, `stability`, `euler-roundoff`,
    /// `constraint-methods`, `launch`, `free-response`, `modal-damping`, `floquet`,
    /// `convolution`, `parameter-sweep`, `periodic-orbit`, `expm`, `rayleigh`,
    /// `rolling-contact`.
    #[command(subcommand)]
    Study(Study),
}

/// The studies.
#[derive(Debug, Subcommand)]
pub enum Study {
    /// Constraint handled by stiff springs, as a DAE (with and without Baumgarte) and in
    /// minimal coordinates: accuracy of the point positions, constraint drift, RHS
    /// evaluations and time, as a table, JSON and a chart.
    ConstraintMethods(constraint_methods::ConstraintMethodsArgs),
    /// Error against work for every integration method on a model: error of the state at
    /// the output times against a verified reference, RHS evaluations, wall time and energy
    /// drift, per tolerance (or step size); a table, JSON and log–log charts.
    WorkPrecision(work_precision::WorkPrecisionArgs),
    /// Where each method fails: stability limits on the oscillator against theory, energy
    /// growth over 10⁴ periods, a stiff two-mass spring, step-size underflow.
    Stability(stability::StabilityArgs),
    /// HW1: explicit Euler on ẋ = x with h = 10⁻ⁿ, truncation against roundoff error and
    /// the optimal n.
    EulerRoundoff(euler_roundoff::EulerRoundoffArgs),
    /// HW2: the range against the launch angle at each launch speed, the best angle θ* by
    /// golden-section search, and the shape of the paths (apex, landing angle) at θ* and at a
    /// fixed angle as v0 grows.
    Launch(commands::launch::LaunchArgs),
    /// HW28: the free response of the linearised, undamped equations four ways (integration,
    /// e^{At}, modes of M⁻¹K, mass-normalised modes), their differences and a chart.
    FreeResponse(free_response::FreeResponseArgs),
    /// HW34: damping ratios exact (eigenvalues of A) vs the diagonal of Ĉ = ΨᵀCΨ vs Rayleigh
    /// damping fitted to two modes, and the free responses from each mode shape.
    ModalDamping(modal_damping::ModalDampingArgs),
    /// Lecture 21: the response of the linearised model to an impulse, a step or any f(t)
    /// through one input, by Duhamel's integral over the impulse response, against DOP853
    /// and the closed form.
    Convolution(commands::convolution::ConvolutionArgs),
    /// Floquet multipliers of a time-periodic model about an equilibrium (the Mathieu
    /// inverted pendulum), and its stability chart over two parameters (`--sweep`).
    Floquet(floquet::FloquetArgs),
    /// The eigenvalues of an operating point (an equilibrium or a steady motion) against
    /// one parameter, the values where its stability changes (refined by bisection), and
    /// the root-locus chart.
    ParameterSweep(parameter_sweep::ParameterSweepArgs),
    /// HW5, HW39: a periodic orbit by shooting (Newton on the flow map with the monodromy
    /// matrix, period free or fixed): period, initial state, residual, iterations, Floquet
    /// multipliers, and a chart of the orbit.
    PeriodicOrbit(commands::periodic_orbit::PeriodicOrbitArgs),
    /// HW32: ż = A z for a random real n × n A three ways (e^{At}, complex eigenvector
    /// superposition, DOP853), the eigenvalues, the eigenvector matrix's condition number
    /// and the largest differences.
    Expm(commands::expm::ExpmArgs),
    /// Lectures 35–37: the Rayleigh quotient of a trial shape against the lowest natural
    /// frequency, the bound R ≥ ω₁² and its stationarity (error second order in the shape's).
    Rayleigh(commands::rayleigh::RayleighArgs),
    /// HW36: the friction coefficient μ(t) = |F_t|/N a rolling body needs up to its lift-off,
    /// from the constraint forces and by Newton–Euler, and (`--after-lift-off`) the free
    /// flight to the landing, joined and checked against its closed forms.
    RollingContact(commands::rolling_contact::RollingContactArgs),
}

/// Runs the CLI on the process arguments. Exit status: 0 success, 1 a failed computation or
/// a failed write (standard output or a file), 2 a usage error, 141 standard output closed by
/// its reader ([`output`]).
pub fn run() -> ExitCode {
    let command = arguments::allow_negative_numbers(<Cli as clap::CommandFactory>::command());
    let args = arguments::join_hyphen_values(&command, std::env::args_os().collect());
    let parsed = command
        .try_get_matches_from(args)
        .and_then(|matches| <Cli as clap::FromArgMatches>::from_arg_matches(&matches));
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) => return error::parse_failure(&e),
    };
    let result = match cli.command {
        Command::List { json } => list::run(json),
        Command::Simulate(args) => simulate::run(&args),
        Command::Animate(args) => animate::run(&args),
        Command::Check(args) => check::run(&args),
        Command::Equations(args) => equations::run(&args),
        Command::Kinematics(args) => equations::run_kinematics(&args),
        Command::New(args) => equations::new(&args),
        Command::Modes(args) => modes::run(&args),
        Command::Frf(args) => frf::run(&args),
        Command::Report(args) => report::run(&args),
        Command::Reduce(args) => commands::reduce::run(&args),
        Command::Study(study) => match study {
            Study::ConstraintMethods(args) => constraint_methods::run(&args),
            Study::WorkPrecision(args) => work_precision::run(&args),
            Study::Stability(args) => stability::run(&args),
            Study::EulerRoundoff(args) => euler_roundoff::run(&args),
            Study::Launch(args) => commands::launch::run(&args),
            Study::FreeResponse(args) => free_response::run(&args),
            Study::ModalDamping(args) => modal_damping::run(&args),
            Study::Floquet(args) => floquet::run(&args),
            Study::Convolution(args) => commands::convolution::run(&args),
            Study::ParameterSweep(args) => parameter_sweep::run(&args),
            Study::PeriodicOrbit(args) => commands::periodic_orbit::run(&args),
            Study::Expm(args) => commands::expm::run(&args),
            Study::Rayleigh(args) => commands::rayleigh::run(&args),
            Study::RollingContact(args) => commands::rolling_contact::run(&args),
        },
    };
    error::exit(result)
}
