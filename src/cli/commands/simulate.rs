//! `eomgen simulate MODEL`: integrate from the model's initial state and report.

use clap::Args;
use eomgen::analysis::{ConstraintDrift, EnergyDrift, Simulation};
use eomgen::hybrid::TransitionKind;
use eomgen::outputs::{OutputSeries, evaluate_outputs};
use eomgen::{ModelInfo, OutputTimes, Solution};

use crate::cli::error::CliError;
use crate::cli::files::{self, Outputs};
use crate::cli::integration::{IntegrationArgs, StabilizationArg, failure_error, simulation};
use crate::cli::output::{self, outln};
use crate::cli::plot;
use crate::cli::render::num;
use crate::cli::values::evaluate;

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
    /// Write the samples as CSV (t, coordinates, rates, energy, then the constraint forces
    /// and drift of a constrained model, then the model's `outputs:`).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<String>,
    /// Plot the coordinates against time (.svg or .png), one panel each with its own scale;
    /// a constrained model also gets its constraint drift in `FILE-drift.svg`.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
    /// What --plot draws, one panel each: coordinates and rates (`theta,phi_dot`), in this
    /// order (default: every coordinate).
    #[arg(long, value_name = "NAMES", requires = "plot")]
    pub plot_coordinates: Option<String>,
    /// Plot the phase portrait, each rate against its coordinate (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot_phase: Option<String>,
    /// Plot the energy drift E(t) − E(0) against time (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot_energy: Option<String>,
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
    let (model, simulation) = simulation(&args.model, &args.run, output_times(&args.t_out)?)?;
    let Simulation {
        solution,
        failure,
        cause,
        warnings,
        ..
    } = &simulation;
    for warning in warnings {
        output::errln!("warning: {warning}");
    }
    // The files of a failed integration say so: `# incomplete: <reason> at t = <t>` above a
    // CSV's header, the same note on the charts (and `"error"` in the JSON below).
    let incomplete = failure.as_ref().map(|e| match e.t() {
        // The reasons with a time say "at t = …" themselves.
        Some(t) if !e.to_string().contains("t = ") => format!("incomplete: {e} at t = {t}"),
        _ => format!("incomplete: {e}"),
    });
    // A run that stopped at a contact is incomplete too (its stop says where and why).
    let incomplete = incomplete
        .or_else(|| (simulation.contact_stop.as_ref()).map(|stop| format!("incomplete: {stop}")));
    // The file's `outputs:` at every sample; one that cannot be evaluated (not a number
    // where the run went) fails the command after everything else is written.
    let (outputs, outputs_error) =
        match evaluate_outputs(model.as_ref(), &simulation.initial_state, solution) {
            Ok(outputs) => (outputs, None),
            Err(e) => (Vec::new(), Some(e)),
        };
    let companions = (events_csv.as_deref(), drift_chart.as_deref());
    write_files(
        args,
        model.as_ref(),
        &simulation,
        &outputs,
        incomplete.as_deref(),
        companions,
    )?;
    print_report(args, model.as_ref(), &simulation, &outputs)?;
    if let Some(e) = &outputs_error {
        output::errln!("error: {e}");
    }
    match failure {
        None if outputs_error.is_some() => Err(CliError::failure(format!(
            "the outputs of `{}` could not be evaluated along the run",
            model.description().name
        ))),
        None => match &simulation.contact_stop {
            Some(stop) => Err(CliError::failure(format!(
                "the run of `{}` stopped before its end time: {stop}; {} computed before it {} kept",
                model.description().name,
                samples(solution.len()),
                if solution.len() == 1 { "was" } else { "were" }
            ))),
            None => Ok(()),
        },
        Some(e) => Err(failure_error(
            &model.description().name,
            e,
            cause.as_ref(),
            &args.run,
            &format!(
                "{} computed before it {} kept",
                samples(solution.len()),
                if solution.len() == 1 { "was" } else { "were" }
            ),
        )),
    }
}

/// `the N samples` (`the sample` for one), for the messages of a run that stopped early.
fn samples(n: usize) -> String {
    if n == 1 {
        "the sample".to_string()
    } else {
        format!("the {n} samples")
    }
}

/// The samples `--t-out` asks for: every accepted step without it.
///
/// # Errors
/// A usage error for more than [`MAX_OUTPUT_TIMES`] times or a time that does not evaluate.
fn output_times(t_out: &[String]) -> Result<OutputTimes, CliError> {
    if t_out.len() > MAX_OUTPUT_TIMES {
        return Err(CliError::usage(format!(
            "--t-out lists {} times; at most {MAX_OUTPUT_TIMES} are allowed",
            t_out.len()
        )));
    }
    let mut times = Vec::with_capacity(t_out.len());
    for t in t_out {
        times.push(evaluate(t, "--t-out", &|_| None)?);
    }
    Ok(if times.is_empty() {
        OutputTimes::Steps
    } else {
        OutputTimes::At(times)
    })
}

/// The most panels of a `--plot` chart: the first coordinates by default (a warning says
/// so), the most `--plot-coordinates` may name. Twelve panels of 170 px make a chart of
/// about 2,100 px.
const MAX_PANELS: usize = 12;

/// The components of the state `[q; q̇]` and the model's `outputs:` that `--plot-coordinates`
/// names (`theta`, `phi_dot`, `L_z`), by index (`2n + k` for the output `k`); empty without
/// it (every coordinate, or the first [`MAX_PANELS`]).
///
/// # Errors
/// A usage error naming a name that is neither a coordinate, a rate nor an output.
fn shown_components(model: &dyn ModelInfo, names: Option<&str>) -> Result<Vec<usize>, CliError> {
    let description = model.description();
    let coordinates = description.coordinate_names();
    let n = coordinates.len();
    let Some(names) = names else {
        if n > MAX_PANELS {
            output::errln!(
                "warning: --plot draws the first {MAX_PANELS} of the {n} coordinates, one panel each; --plot-coordinates names the ones to draw"
            );
            return Ok((0..MAX_PANELS).collect());
        }
        return Ok(Vec::new());
    };
    let count = names.split(',').count();
    if count > MAX_PANELS {
        return Err(CliError::usage(format!(
            "--plot-coordinates names {count} coordinates, rates and outputs; a chart has at most {MAX_PANELS} panels (draw the others in a second chart)"
        )));
    }
    let outputs: Vec<&str> = (model.description().outputs.iter())
        .map(|o| &*o.name)
        .collect();
    let speeds = match description.has_speeds() {
        true => format!("; speeds: {}", description.speeds.join(", ")),
        false => String::new(),
    };
    let known = match outputs.is_empty() {
        true => format!("coordinates: {}{speeds}", coordinates.join(", ")),
        false => format!(
            "coordinates: {}{speeds}; outputs: {}",
            coordinates.join(", "),
            outputs.join(", ")
        ),
    };
    names
        .split(',')
        .map(str::trim)
        .map(|name| {
            let rate = name.strip_suffix("_dot").filter(|_| !description.has_speeds());
            (coordinates.iter().position(|c| *c == name))
                .or_else(|| rate.and_then(|r| coordinates.iter().position(|c| *c == r)).map(|i| n + i))
                .or_else(|| description.speeds.iter().position(|u| *u == name).map(|i| n + i))
                .or_else(|| outputs.iter().position(|o| *o == name).map(|k| 2 * n + k))
                .ok_or_else(|| {
                    CliError::usage(format!(
                        "--plot-coordinates: `{name}` is neither a coordinate, a rate nor an output of `{}` ({known})",
                        model.description().name,
                    ))
                })
        })
        .collect()
}

/// Writes the files the options ask for (`--csv` and its events file, the charts and the
/// drift chart beside `--plot`), each noting `incomplete` when the run stopped early; a
/// companion this run has nothing for is removed when an earlier run of eomgen wrote it.
///
/// # Errors
/// A file that cannot be written or removed.
fn write_files(
    args: &SimulateArgs,
    model: &dyn ModelInfo,
    simulation: &Simulation,
    outputs: &[OutputSeries],
    incomplete: Option<&str>,
    (events_csv, drift_chart): (Option<&str>, Option<&str>),
) -> Result<(), CliError> {
    let Simulation {
        solution,
        energy: report,
        constraints,
        ..
    } = simulation;
    let shown = shown_components(model, args.plot_coordinates.as_deref())?;
    if let Some(path) = &args.csv {
        write_csv(
            path,
            model,
            solution,
            report,
            constraints,
            outputs,
            incomplete,
        )?;
    }
    // A companion this run has nothing for is removed when an earlier run of eomgen wrote
    // it; a file of that name that eomgen did not write is kept, with a warning.
    if let Some(events) = events_csv {
        if solution.events.is_empty() {
            // The header this model writes, which names the speeds in generalized speeds.
            let own = events_header(model);
            let ours = |bytes: &[u8]| is_events_csv(bytes) || bytes.starts_with(own.as_bytes());
            files::remove_stale_or_warn(events, ours)?;
        } else {
            write_events_csv(events, model, solution)?;
        }
    }
    if let Some(path) = &args.plot {
        plot::time_histories(path, model, solution, outputs, &shown, incomplete)
            .map_err(CliError::failure)?;
    }
    if let Some(drift_path) = drift_chart {
        if constraints.is_empty() {
            files::remove_stale_or_warn(drift_path, plot::is_own_drift_chart)?;
        } else {
            plot::constraint_drift(
                drift_path,
                &model.description().name,
                &solution.t,
                &constraints.drift,
                incomplete,
            )
            .map_err(CliError::failure)?;
        }
    }
    if let Some(path) = &args.plot_phase {
        plot::phase_portrait(path, model, solution, incomplete).map_err(CliError::failure)?;
    }
    if let Some(path) = &args.plot_energy {
        plot::energy_drift(
            path,
            &model.description().name,
            &solution.t,
            &report.energy,
            report.initial_energy,
            incomplete,
        )
        .map_err(CliError::failure)?;
    }
    Ok(())
}

/// Prints the run's report: its JSON with `--json` (the wall time only with `--timing`), else
/// the text summary, the constraints' drift and the events.
///
/// # Errors
/// Standard output that cannot be written.
fn print_report(
    args: &SimulateArgs,
    model: &dyn ModelInfo,
    simulation: &Simulation,
    outputs: &[OutputSeries],
) -> Result<(), CliError> {
    let Simulation {
        solution,
        energy: report,
        constraints,
        integrator: method_name,
        ..
    } = simulation;
    if args.json {
        // The wall time is the one figure that differs between two identical runs: only
        // printed when asked for (`--timing`), so that the JSON is byte-identical otherwise.
        let mut json = crate::cli::json::sorted(&simulation.summary(model))?;
        if !args.timing
            && let Some(stats) = json["stats"].as_object_mut()
        {
            stats.remove("wall_time_s");
        }
        if !outputs.is_empty()
            && let Some(object) = json.as_object_mut()
        {
            object.insert("outputs".to_string(), crate::cli::json::sorted(&outputs)?);
            json = crate::cli::json::sorted(&json)?;
        }
        crate::cli::json::print_json(&json)?;
    } else {
        print_summary(model, method_name, &args.run, solution, report, outputs);
        print_constraint_summary(constraints, args.run.stabilization);
        print_events(model, solution);
        print_impacts(simulation);
    }
    Ok(())
}

/// The impacts at the model's contacts (time, contact, how it ended, `ġ` before and after,
/// the impulses and the energy lost), and why the run stopped at a contact.
fn print_impacts(simulation: &Simulation) {
    let transitions = &simulation.transitions;
    if !transitions.is_empty() {
        let lost: f64 = transitions.iter().map(|tr| tr.energy_lost).sum();
        outln!(
            "contacts   {} transitions (energy lost {:.6e} J):",
            transitions.len(),
            num(lost)
        );
        for tr in transitions {
            let tangential = if tr.tangential_impulse == 0.0 {
                String::new()
            } else {
                format!(", tangential {:.6e} N*s", num(tr.tangential_impulse))
            };
            let switch = match tr.kind {
                TransitionKind::LiftOff => Some("lifts off (opens with no jump)"),
                TransitionKind::Stick => Some("sticks (its slip stops inside the friction cone)"),
                TransitionKind::Slip => Some("slips (the friction cone cannot hold it)"),
                TransitionKind::Impact | TransitionKind::Closes | TransitionKind::SupportChange => {
                    None
                }
            };
            if let Some(switch) = switch {
                outln!(
                    "           {:<16} t = {:.15e}   {switch}",
                    tr.contact,
                    num(tr.t)
                );
                continue;
            }
            let closes = match tr.kind {
                TransitionKind::Closes => ", stays closed",
                TransitionKind::SupportChange => ", lands: the new stance foot",
                _ => "",
            };
            outln!(
                "           {:<16} t = {:.15e}   {:?}{closes}, g_dot {:.9e} -> {:.9e} m/s, normal impulse {:.6e} N*s{tangential}, lost {:.6e} J",
                tr.contact,
                num(tr.t),
                tr.mode,
                num(tr.normal_velocity[0]),
                num(tr.normal_velocity[1]),
                num(tr.normal_impulse),
                num(tr.energy_lost)
            );
        }
    }
    if let Some(stop) = &simulation.contact_stop {
        outln!("stopped    {stop}");
    }
}

fn print_summary(
    model: &dyn ModelInfo,
    method: &str,
    args: &IntegrationArgs,
    solution: &Solution,
    report: &EnergyDrift,
    outputs: &[OutputSeries],
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
                model.description().state_name(n + i),
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
            } else if !model.description().contacts.is_empty() {
                " (of E plus the energy lost at impacts; friction's work while sliding is not added)"
            } else {
                " (not conserved: the model has non-conservative loads or explicit time dependence)"
            };
            outln!(
                "drift      max|E - E(0)| / max(T + |V|) = {d:.3e}{note}",
                d = num(d)
            );
        }
    }
    print_conserved_outputs(outputs, args.rtol);
    let s = &solution.stats;
    let implicit = if s.jacobian_evals > 0 {
        format!(
            ", {} Jacobians, {} LU factorisations",
            s.jacobian_evals, s.lu_decompositions
        )
    } else {
        String::new()
    };
    // The Taylor method evaluates series of the motion, not the right-hand side.
    let evaluations = match (s.taylor_series, s.rhs_evals) {
        (0, evals) => format!("{evals} RHS evaluations"),
        (series, 0) => format!("{series} Taylor series"),
        (series, evals) => format!("{series} Taylor series, {evals} RHS evaluations"),
    };
    outln!(
        "work       {} steps ({} rejected), {evaluations}{implicit}, {:.3} ms",
        s.steps,
        s.rejected,
        s.wall_time_s * 1e3
    );
}

/// The drift of each output the file declares conserved, as the energy's: its start and
/// `max |Q − Q(0)| / max(1, |Q(0)|)`. The file's bound holds for `eomgen report`'s run
/// (DOP853 at 1e-12); a run at a looser `rtol` drifts in proportion, so a drift is called
/// "not conserved" (with a warning) only beyond both the bound and 1000 × `rtol`, and
/// noted as above the bound otherwise.
fn print_conserved_outputs(outputs: &[OutputSeries], rtol: f64) {
    for o in outputs.iter().filter(|o| o.conserved) {
        let (q0, Some(d), Some(bound)) = (o.initial, o.drift, o.tolerance) else {
            continue;
        };
        let note = if d > bound.max(1e3 * rtol) {
            output::errln!(
                "warning: output `{}` is declared conserved, but it drifted by {:.3e}, beyond its bound {bound:e} and 1000 × rtol",
                o.name,
                num(d)
            );
            format!(" (exceeds the bound {bound:e} and 1000 × rtol: not conserved along this run)")
        } else if o.drifted() {
            format!(
                " (above the file's bound {bound:e}, which `eomgen report` checks at rtol 1e-12)"
            )
        } else {
            String::new()
        };
        outln!(
            "conserved  {name}: Q(0) = {q0:.12e}, max|Q - Q(0)| / max(1, |Q(0)|) = {d:.3e}{note}",
            name = o.name,
            q0 = num(q0),
            d = num(d)
        );
    }
}

fn write_csv(
    path: &str,
    model: &dyn ModelInfo,
    solution: &Solution,
    report: &EnergyDrift,
    constraints: &ConstraintDrift,
    outputs: &[OutputSeries],
    incomplete: Option<&str>,
) -> Result<(), CliError> {
    let mut out = incomplete.map_or_else(String::new, |note| format!("# {note}\n"));
    out.push('t');
    for c in model.description().coordinate_names() {
        out.push(',');
        out.push_str(c);
    }
    let d = model.description();
    for i in d.num_dofs()..2 * d.num_dofs() {
        out.push(',');
        out.push_str(&d.state_name(i));
    }
    out.push_str(",energy");
    for c in &constraints.constraint_names {
        out.push_str(&format!(",lambda_{c}"));
    }
    if !constraints.is_empty() {
        out.push_str(",drift_position,drift_velocity");
    }
    for o in outputs {
        out.push(',');
        out.push_str(&o.name);
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
        for o in outputs {
            out.push_str(&format!(",{:e}", o.values[k]));
        }
        out.push('\n');
    }
    Ok(files::write(path, out.as_bytes())?)
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
                    "{c} = {:.9e}, {} = {:.9e}",
                    num(e.y[i]),
                    model.description().state_name(n + i),
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

/// Whether `bytes` is an events CSV that eomgen wrote, for any model in the coordinates'
/// rates: its first line is the exact header [`write_events_csv`] writes, [`EVENTS_HEADER`]
/// then the coordinates `c₁…cₙ` and their rates `c₁_dot…cₙ_dot`. (A model in generalized
/// speeds recognises its own header, [`events_header`].)
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

/// The first line of `model`'s events CSV: [`EVENTS_HEADER`], the coordinates, then the
/// state's second half (the rates, or the speeds), and the line's end.
fn events_header(model: &dyn ModelInfo) -> String {
    let d = model.description();
    let mut out = String::from(EVENTS_HEADER);
    for i in 0..2 * d.num_dofs() {
        out.push(',');
        out.push_str(&d.state_name(i));
    }
    out.push('\n');
    out
}

/// The located events as CSV: name, direction, t, coordinates, rates.
fn write_events_csv(
    path: &str,
    model: &dyn ModelInfo,
    solution: &Solution,
) -> Result<(), CliError> {
    let mut out = events_header(model);
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
    Ok(files::write(path, out.as_bytes())?)
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
            "event,direction,terminal,t,phi,theta,w1,w2\n",
            "# event,direction,terminal,t,q,q_dot\n",
        ] {
            assert!(!is_events_csv(theirs.as_bytes()), "{theirs}");
        }
    }
}
