//! `eomgen study periodic-orbit MODEL` (HW5, HW39): a periodic orbit found by shooting —
//! Gauss–Newton with minimum-norm steps on the flow map and its monodromy matrix, with a phase
//! condition and, in a conservative model with the period free, the energy fixed — its period,
//! initial state, residual, Newton iterations and Floquet multipliers, and a chart of the
//! model's points over one period.
//!
//! The numbers come from [`eomgen::analysis::periodic_orbit()`]; this module parses the
//! guess, the period and the energy level, and renders the report.

use clap::Args;
use eomgen::ModelInfo;
use eomgen::analysis::{
    GaitError, GaitOptions, PeriodicOrbit, PeriodicOrbitError, PeriodicOrbitOptions, periodic_orbit,
};
use eomgen::expressions::{split_assignment, split_list};

use crate::cli::error::CliError;
use crate::cli::files::Outputs;
use crate::cli::json::print_json_sorted;
use crate::cli::plot::{Chart, Series, lines};
use crate::cli::render::num;
use crate::cli::values::{evaluate, parameter_lookup, set_parameters, usage};

/// Options of `eomgen study periodic-orbit`.
#[derive(Debug, Args)]
pub struct PeriodicOrbitArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any unconstrained model file.
    pub model: String,
    /// Set a parameter, `NAME=VALUE`; repeatable.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Newton's start: the model's initial state with these coordinates (`x1=-0.97`) or rates
    /// (`x1_dot=0.2`) changed, comma separated or repeated; values may use the parameters.
    #[arg(long, value_name = "NAME=VALUE,…")]
    pub guess: Vec<String>,
    /// The period (s), an expression of the parameters: the initial guess, or the period
    /// itself with --fix-period. Default: the model file's `checks:` (`period:`, else the
    /// time of `final_state:`).
    #[arg(long, allow_hyphen_values = true)]
    pub period: Option<String>,
    /// Keep the period fixed and solve for the initial state only (the energy is then free).
    #[arg(long)]
    pub fix_period: bool,
    /// The energy level T + V (J) of the orbit sought, with the period free in a
    /// conservative model (periodic orbits come in families along the energy): an expression
    /// of the parameters, or `start` for the energy of the guess. Default: the energy of the
    /// model's initial state (with --set, without --guess), so that --guess moves Newton's
    /// start, not the orbit sought.
    #[arg(long, value_name = "E|start", allow_hyphen_values = true)]
    pub energy: Option<String>,
    /// Newton's tolerance: ‖φ_T(y₀) − y₀‖ ≤ tol (1 + ‖y₀‖), in [1e-12, 1e-3] (for a gait,
    /// ‖P(y) − y‖∞ ≤ tol · max(1, ‖y‖∞), in [1e-14, 1e-3]).
    #[arg(long, default_value_t = 1e-10, allow_hyphen_values = true)]
    pub tol: f64,
    /// Most Newton iterations.
    #[arg(long, default_value_t = 30)]
    pub max_iterations: usize,
    /// Print JSON (the report, with the monodromy matrix and the sampled orbit).
    #[arg(long)]
    pub json: bool,
    /// Chart of the model's points over one period, y against x (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
    /// For a model with a change of support (`support:`): the landings in one period of the
    /// gait (1: a period-one gait; 2 after a period doubling).
    #[arg(long, default_value_t = 1)]
    pub steps: usize,
}

/// Runs `study periodic-orbit`.
pub fn run(args: &PeriodicOrbitArgs) -> Result<(), CliError> {
    Outputs::new()
        .input(&args.model)
        .chart("--plot", args.plot.as_deref())
        .check()?;
    let mut model = crate::cli::model::find_model(&args.model)?;
    if !model.description().supports.is_empty() {
        return run_gait(args, model);
    }
    crate::cli::model::smooth_only(model.as_ref(), "`study periodic-orbit`")?;
    set_parameters(model.as_mut(), &args.set)?;
    let initial = model.initial_state();
    let start = guess(model.as_ref(), &args.guess)?;
    let lookup = parameter_lookup(model.as_ref());
    let (period, period_source) = match &args.period {
        Some(text) => (evaluate(text, "--period", &lookup)?, "--period"),
        None => (model_period(model.as_ref())?, "the model file's checks"),
    };
    let energy = match args.energy.as_deref() {
        Some("start") => model.energy(0.0, &start),
        Some(text) => evaluate(text, "--energy", &lookup)?,
        None => model.energy(0.0, &initial),
    };
    drop(lookup);
    let options = PeriodicOrbitOptions {
        start: Some(start),
        fix_period: args.fix_period,
        energy: Some(energy),
        tol: args.tol,
        max_iterations: args.max_iterations,
        ..PeriodicOrbitOptions::new(period)
    };
    let orbit = periodic_orbit(model.as_mut(), &options).map_err(|e| match e {
        PeriodicOrbitError::InvalidPeriod { .. } => CliError::usage(format!("--period: {e}")),
        PeriodicOrbitError::InvalidTolerance { .. } => CliError::usage(format!("--tol: {e}")),
        PeriodicOrbitError::InvalidEnergy { .. } => CliError::usage(format!(
            "{e}: T + V is not finite here (a potential undefined at this state or these parameters); fix the period instead (--fix-period --period T)"
        )),
        PeriodicOrbitError::Constrained { .. } => CliError::usage(e.to_string()),
        PeriodicOrbitError::TimeDependent { .. } => CliError::usage(format!(
            "{e} (--fix-period --period T, T the forcing's period)"
        )),
        e => CliError::failure(format!("`{}`: {e}", model.description().name)),
    })?;
    if let Some(path) = &args.plot {
        plot(path, model.as_ref(), &orbit).map_err(CliError::failure)?;
    }
    if args.json {
        print_json_sorted(&orbit)
    } else {
        let mut stdout = crate::cli::output::stdout();
        print_text(
            &mut stdout,
            &orbit,
            period,
            period_source,
            args.energy.as_deref(),
        );
        Ok(())
    }
}

/// `study periodic-orbit` on a model with a change of support: its gait
/// ([`eomgen::analysis::gait()`]) from the model's initial state with `--guess` applied.
fn run_gait(args: &PeriodicOrbitArgs, mut model: Box<dyn ModelInfo>) -> Result<(), CliError> {
    set_parameters(model.as_mut(), &args.set)?;
    for (given, flag) in [
        (args.period.is_some(), "--period"),
        (args.fix_period, "--fix-period"),
        (args.energy.is_some(), "--energy"),
        (args.plot.is_some(), "--plot"),
    ] {
        if given {
            return Err(CliError::usage(format!(
                "{flag} does not apply to a gait: its period is the time of its steps, found with it (`{}` changes its support)",
                model.description().name
            )));
        }
    }
    let options = GaitOptions {
        start: Some(guess(model.as_ref(), &args.guess)?),
        steps: args.steps,
        tol: args.tol,
        max_iterations: args.max_iterations,
        ..GaitOptions::default()
    };
    let gait = eomgen::analysis::gait(model.as_mut(), &options).map_err(|e| match e {
        GaitError::InvalidOptions { .. } => CliError::usage(e.to_string()),
        e => CliError::failure(format!("`{}`: {e}", model.description().name)),
    })?;
    if args.json {
        return print_json_sorted(&gait);
    }
    use std::io::Write as _;
    let mut out = crate::cli::output::stdout();
    let _ = writeln!(
        out,
        "model        {} ({} dof), a gait of {} step{} per period",
        gait.model,
        gait.state_names.len() / 2,
        gait.step_times.len(),
        if gait.step_times.len() == 1 { "" } else { "s" }
    );
    let _ = writeln!(
        out,
        "method       Newton on the return map P(y) − y = 0 (y just after a landing), its Jacobian from the variational equations and a saltation matrix at each landing; DOP853 on y and Φ"
    );
    for (k, r) in gait.residuals.iter().enumerate() {
        let label = if k == 0 { "newton" } else { "" };
        let _ = writeln!(out, "{label:<12} {k:<3} ‖P(y) − y‖ = {:.3e}", num(r));
    }
    let steps: Vec<String> = (gait.step_times.iter())
        .map(|t| format!("{t:.12}"))
        .collect();
    let _ = writeln!(
        out,
        "period       T = {:.12} s (steps {})",
        gait.period,
        steps.join(", ")
    );
    for (i, (name, value)) in gait.state_names.iter().zip(&gait.state).enumerate() {
        let label = if i == 0 { "state y*" } else { "" };
        let _ = writeln!(out, "{label:<12} {name:<10} = {:+.12e}", num(value));
    }
    let lost: Vec<String> = (gait.energy_lost.iter())
        .map(|e| format!("{:.9e}", num(e)))
        .collect();
    let _ = writeln!(
        out,
        "landings     kinetic energy lost {} J",
        lost.join(", ")
    );
    complex_rows(&mut out, "eigenvalues", 'λ', &gait.eigenvalues);
    let _ = writeln!(
        out,
        "             (of ∂P/∂y; one is 0, the flow's direction)"
    );
    complex_rows(&mut out, "multipliers", 'μ', &gait.floquet_multipliers);
    let _ = writeln!(
        out,
        "             (Floquet multipliers, of the monodromy matrix through the landings: the same and 1 for the flow)"
    );
    let _ = writeln!(
        out,
        "stability    {} (max |λ| = {:.9})",
        gait.stability.as_str(),
        gait.spectral_radius
    );
    let _ = writeln!(
        out,
        "work         {} steps, {} right-hand sides (with Φ), {:.3} s",
        gait.stats.steps, gait.stats.rhs_evals, gait.stats.wall_time_s
    );
    Ok(())
}

/// The model's initial state with `--guess` applied; an unknown name is a usage error that
/// lists the coordinates and rates.
fn guess(model: &dyn ModelInfo, items: &[String]) -> Result<Vec<f64>, CliError> {
    let mut y = model.initial_state();
    let n = model.num_dofs();
    let coordinates = model.description().coordinate_names();
    let lookup = parameter_lookup(model);
    for item in items.iter().flat_map(|s| split_list(s)) {
        let (name, text) = split_assignment(item, "--guess").map_err(usage)?;
        let d = model.description();
        let index = d.state_index(name).ok_or_else(|| {
            CliError::usage(format!(
                "--guess {name}: `{}` has no coordinate or rate `{name}`; its coordinates are {} and {} {}",
                d.name,
                coordinates.join(", "),
                if d.has_speeds() { "its speeds" } else { "their rates" },
                (n..2 * n).map(|i| d.state_name(i)).collect::<Vec<_>>().join(", ")
            ))
        })?;
        y[index] = evaluate(text, &format!("--guess {name}"), &lookup)?;
    }
    Ok(y)
}

/// The period guess from the model file's `checks:`: `period:`'s value, else the time of
/// `final_state:`.
fn model_period(model: &dyn ModelInfo) -> Result<f64, CliError> {
    let checks = &model.description().checks;
    let lookup = parameter_lookup(model);
    if let Some(check) = &checks.period {
        return evaluate(&check.value, "the file's `checks: period:`", &lookup);
    }
    if let Some(check) = &checks.final_state {
        return evaluate(&check.t, "the file's `checks: final_state: t:`", &lookup);
    }
    Err(CliError::usage(format!(
        "`{}` gives no period in its `checks:` (`period:` or `final_state:`): give a guess with --period T",
        model.description().name
    )))
}

/// The text report.
fn print_text(
    stdout: &mut impl std::io::Write,
    orbit: &PeriodicOrbit,
    period_guess: f64,
    period_source: &str,
    energy: Option<&str>,
) {
    let dofs = orbit.state_names.len() / 2;
    let what = if orbit.fix_period {
        format!(
            "period fixed at {:e} s ({period_source})",
            num(orbit.period)
        )
    } else {
        format!(
            "period free, guess {:e} s ({period_source})",
            num(period_guess)
        )
    };
    let _ = writeln!(stdout, "model        {} ({dofs} dof), {what}", orbit.model);
    let rows = match orbit.energy_level {
        Some(level) => format!(
            "φ_T(y₀) − y₀ = 0, a phase condition and H(y₀) = E = {:.12e} J ({})",
            num(level),
            match energy {
                Some("start") => "the energy of the guess",
                Some(_) => "--energy",
                None => "the energy of the model's initial state",
            }
        ),
        None if orbit.fix_period => "φ_T(y₀) − y₀ = 0 and a phase condition".to_string(),
        None => "φ_T(y₀) − y₀ = 0 and a phase condition (not conservative: an isolated cycle)"
            .to_string(),
    };
    let _ = writeln!(
        stdout,
        "method       shooting, Gauss–Newton with minimum-norm (SVD) steps on {rows}; DOP853 on y and Φ"
    );
    let _ = writeln!(
        stdout,
        "newton       k   ‖φ_T(y₀) − y₀‖     H(y₀) − E (J)     T (s)               rank  damping"
    );
    for (k, step) in orbit.history.iter().enumerate() {
        let energy = step
            .energy_residual
            .map_or("—".to_string(), |r| format!("{:+.3e}", num(r)));
        let rank = step.rank.map_or("—".to_string(), |r| r.to_string());
        let damping = step.damping.map_or("—".to_string(), |d| format!("{d}"));
        let _ = writeln!(
            stdout,
            "             {k:<3} {:<18.3e} {energy:<17} {:<19.12} {rank:<5} {damping}",
            num(step.residual),
            step.period
        );
    }
    let _ = writeln!(stdout, "period       T = {:.12} s", orbit.period);
    for (i, (name, value)) in orbit
        .state_names
        .iter()
        .zip(&orbit.initial_state)
        .enumerate()
    {
        let label = if i == 0 { "initial y₀" } else { "" };
        let _ = writeln!(stdout, "{label:<12} {name:<10} = {:+.12e}", num(value));
    }
    let _ = writeln!(
        stdout,
        "residual     ‖φ_T(y₀) − y₀‖ = {:.3e} (max {:.3e}) after {} Newton iterations",
        num(orbit.residual),
        num(orbit.residual_max),
        orbit.iterations
    );
    print_stability(stdout, orbit);
}

/// One row per complex value, `label` on the first: `μ1 = re im i   |μ| = …`.
fn complex_rows(
    out: &mut impl std::io::Write,
    label: &str,
    symbol: char,
    values: &[eomgen::nalgebra::Complex<f64>],
) {
    for (k, v) in values.iter().enumerate() {
        let label = if k == 0 { label } else { "" };
        let _ = writeln!(
            out,
            "{label:<12} {symbol}{:<3} = {:+.9} {:+.9}i   |{symbol}| = {:.9}",
            k + 1,
            v.re,
            v.im,
            v.norm()
        );
    }
}

/// The orbit's energy, its Floquet multipliers with the trivial ones and the symmetries they
/// count, the stability verdict and the work.
fn print_stability(stdout: &mut impl std::io::Write, orbit: &PeriodicOrbit) {
    let _ = writeln!(stdout, "energy       T + V = {:.12e} J", num(orbit.energy));
    complex_rows(stdout, "multipliers", 'μ', &orbit.multipliers);
    let _ = writeln!(
        stdout,
        "trivial μ    {} of {} within {:e} of 1, their mean off by {:.1e} (a Hamiltonian system: a pair for the time shift and the energy, one per further symmetry with its conserved momentum)",
        orbit.unit_multipliers,
        orbit.multipliers.len(),
        orbit.unit_multiplier_tolerance,
        num(orbit.unit_mean_error)
    );
    let _ = writeln!(
        stdout,
        "symmetries   {}: directions of the Jacobian dropped at the solution (orbits of the same {} through nearby states: translations, rotations, …)",
        orbit.symmetries,
        if orbit.fix_period {
            "period"
        } else if orbit.energy_level.is_some() {
            "energy and period"
        } else {
            "period"
        }
    );
    let radius = if orbit.unit_multipliers == orbit.multipliers.len() {
        "every multiplier is trivial".to_string()
    } else {
        format!(
            "nontrivial multipliers: max |μ| = {:.9}",
            orbit.nontrivial_spectral_radius
        )
    };
    let _ = writeln!(
        stdout,
        "stability    {} ({radius})",
        orbit.stability.as_str()
    );
    let _ = writeln!(
        stdout,
        "work         {} steps, {} right-hand sides (with Φ), {:.3} s",
        orbit.stats.steps, orbit.stats.rhs_evals, orbit.stats.wall_time_s
    );
}

/// The chart: each of the model's points over one period, y against x.
fn plot(path: &str, model: &dyn ModelInfo, orbit: &PeriodicOrbit) -> Result<(), String> {
    let names = model.description().points.clone();
    let series: Vec<Series> = names
        .iter()
        .enumerate()
        .filter(|(i, _)| {
            // A fixed point (the centre of force) draws no line.
            let first = orbit.orbit.points.first().map(|p| p[*i]);
            orbit.orbit.points.iter().any(|p| Some(p[*i]) != first)
        })
        .map(|(i, name)| Series {
            name: name.to_string(),
            points: orbit
                .orbit
                .points
                .iter()
                .map(|p| (p[i][0], p[i][1]))
                .collect(),
        })
        .collect();
    let title = format!("{}: periodic orbit, T = {:.9} s", orbit.model, orbit.period);
    lines(path, &Chart::linear(&title, "x (m)", "y (m)"), &series)
}
