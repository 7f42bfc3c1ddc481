//! The Rust side of the work–precision comparison with peer codes: eomgen's integration
//! methods (by their [`Method`] names) and the peer crate `ode_solvers` (0.6.2) on the same
//! compiled model, one JSON line per run on stdout.
//! `tools/work_precision_peers.py` runs this program in alternating rounds with
//! `tools/heyoka_peer.py` and builds the tables and the chart.
//!
//! ```sh
//! cargo build --release -p eomgen-benches --features work-precision --example work_precision_peers
//! P=target/release/examples/work_precision_peers
//! $P initial --model double_pendulum            # y(0) as JSON (shortest round-trip digits)
//! $P rhs --model double_pendulum --state 0.1,0.2,0.3,0.4   # F(0, y) as JSON
//! $P run --model double_pendulum --t-end 10 --methods dp54,dop853,ode_solvers-dop853 \
//!     --tols 1e-2,1e-3,1e-4 --reps 5 [--reference reference.json] [--host-features off]
//! ```
//!
//! With `--from-file on`, eomgen's side and ode_solvers' run the model loaded from its file and
//! compiled at run time by Cranelift, the path of the command line and of Python, instead of
//! the copy `model!` compiled into this program.
//!
//! Models: `double_pendulum` (`models/double_pendulum.yaml`, HW19, 4 states) and
//! `figure_eight` (`models/figure_eight.yaml`, HW7, 12 states), with the files' default
//! parameters and initial states, as compiled into this program by `model!`; with
//! `--from-file on`, any bundled model or model file of 2, 4, 6, 10, 12 or 16 states (the
//! panel of `tools/peer_panel.py`, the cases of `tools/taylor_ops_bench.py`), `--name` labelling its lines, and `--set theta_dot=5.0,…`
//! changing its initial state by coordinate or rate name (for `initial`, `rhs` and `run`).
//!
//! Methods: every adaptive [`Method`] by its command-line name (`dp54`, `dop853`, and any
//! method added to [`Method::ALL`] later), run through [`Method::integrator`] with
//! `rtol = atol = tol`, at most 10⁶ steps, every accepted step recorded
//! ([`OutputTimes::Steps`]), the system passed as its concrete type ([`FirstOrder`] of the
//! `model!` struct, as `benches/peers.rs` does, or with `--from-file on` `DynFirstOrder` of
//! the file's `JitModel`, as the command line does); and `ode_solvers-dop853`, `ode_solvers-dopri5`:
//! ode_solvers' Dop853 and Dopri5 with `rtol = atol = tol` and their default controllers
//! (the settings of `benches/peers.rs`: safety 0.9, Dop853 `beta = 0`, step ratio in
//! `[0.333, 6]`, Dopri5 `beta = 0.04`, `[0.2, 10]`, `h_max = t_end`, automatic first step,
//! at most 10⁶ steps, `OutputType::Sparse`), calling the same right-hand side through a
//! `RefCell` (ode_solvers' `System::system` takes `&self`). Fixed-step
//! methods have no tolerance and are rejected.
//!
//! `run` prints, for each method and tolerance, one line
//! `{"side", "method", "model", "tol", "t_end", "time_s", "times_s", "rhs_evals", "steps",
//! "rejected", "final_state", "error", "energy_drift", "host_features"}`: `time_s` is the
//! median of `reps`
//! timed integrations (s, wall clock, `Instant`, the integrator built before the clock
//! starts), `error = max |yᵢ(t_end) − y_refᵢ|` over the state (the rule of
//! `benches/peers.rs`; `null` without `--reference`), `energy_drift = |E(t_end) − E(0)| /
//! |E(0)|` (total energy by [`ModelInfo::energy`]). A failed run prints
//! `{"side", "method", "model", "tol", "failed": message}`. The reference file is JSON
//! `{"<model>": {"t_end": 10.0, "state": ["<decimal>", …]}, …}` (as written by
//! `tools/heyoka_peer.py reference`); its decimals are read as the nearest `f64`.
//! `--host-features off` runs every Taylor step in the code compiled for any x86-64
//! ([`eomgen::taylor::set_host_features`]; the same bits, for comparing the cost);
//! `host_features` says which copy ran ([`eomgen::taylor::host_features`]).

use std::cell::RefCell;
use std::hint::black_box;
use std::process::ExitCode;
use std::str::FromStr;
use std::time::Instant;

mod models {
    eomgen::model!("../models/double_pendulum.yaml");
    eomgen::model!("../models/figure_eight.yaml");
}
use eomgen::{FirstOrder, IntegratorOptions, Method, ModelInfo, OdeSystem, OutputTimes};
use models::{DoublePendulum, FigureEight};
use ode_solvers::{Dop853, Dopri5};

#[macro_use]
#[path = "peer_stepper.rs"]
mod peer_stepper;
use serde_json::{Value, json};

/// Largest number of steps of any run.
const MAX_STEPS: usize = 1_000_000;

/// A method of the comparison: one of eomgen's, or one of ode_solvers'.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Runner {
    /// An adaptive eomgen method.
    Eomgen(Method),
    /// ode_solvers' Dop853 (Hairer's DOP853).
    PeerDop853,
    /// ode_solvers' Dopri5 (Dormand–Prince 5(4)).
    PeerDopri5,
}

impl Runner {
    /// The name in the output: eomgen's [`Method::name`], or `ode_solvers-dop853`,
    /// `ode_solvers-dopri5`.
    fn name(self) -> String {
        match self {
            Runner::Eomgen(m) => m.name().to_string(),
            Runner::PeerDop853 => "ode_solvers-dop853".to_string(),
            Runner::PeerDopri5 => "ode_solvers-dopri5".to_string(),
        }
    }

    /// The code that runs it: `eomgen` or `ode_solvers`.
    fn side(self) -> &'static str {
        match self {
            Runner::Eomgen(_) => "eomgen",
            Runner::PeerDop853 | Runner::PeerDopri5 => "ode_solvers",
        }
    }
}

impl FromStr for Runner {
    type Err = String;

    /// `ode_solvers-dop853`, `ode_solvers-dopri5`, or an adaptive [`Method`]'s name.
    fn from_str(name: &str) -> Result<Self, String> {
        match name {
            "ode_solvers-dop853" => Ok(Runner::PeerDop853),
            "ode_solvers-dopri5" => Ok(Runner::PeerDopri5),
            _ => {
                let method: Method = name.parse().map_err(|e| format!("{e}"))?;
                if method.is_adaptive() {
                    Ok(Runner::Eomgen(method))
                } else {
                    Err(format!(
                        "`{name}` is a fixed-step method (no tolerance to sweep)"
                    ))
                }
            }
        }
    }
}

/// What one run measured.
struct Measurement {
    final_state: Vec<f64>,
    rhs_evals: usize,
    steps: usize,
    rejected: usize,
    times_s: Vec<f64>,
}

/// `y(t_end)` of ode_solvers' `$solver` (`Dop853` or `Dopri5`) on `$system` (a
/// `&RefCell` of the first-order system) from `$y0` (a `&[f64]` of length `$dim`) at `rtol = atol =
/// $tol`, with the controller's `beta` and step-ratio bounds; `(state, evaluations, accepted,
/// rejected)` or the solver's error message.
macro_rules! peer_run {
    ($solver:ident, $dim:literal, $system:expr, $y0:expr, $t_end:expr, $tol:expr,
     $beta:expr, $fac_min:expr, $fac_max:expr) => {{
        /// The shared first-order system as an ode_solvers `System`.
        struct Peer<'a, S>(&'a RefCell<S>);
        impl<S: OdeSystem> ode_solvers::System<f64, ode_solvers::SVector<f64, $dim>> for Peer<'_, S> {
            /// # Panics
            /// If the right-hand side fails (ode_solvers has no error channel); neither
            /// model's does at the states of these orbits.
            fn system(
                &self,
                t: f64,
                y: &ode_solvers::SVector<f64, $dim>,
                dy: &mut ode_solvers::SVector<f64, $dim>,
            ) {
                self.0
                    .borrow_mut()
                    .rhs(t, y.as_slice(), dy.as_mut_slice())
                    .expect("the model's right-hand side");
            }
        }
        let mut stepper = peer_stepper!(
            $solver,
            Peer($system),
            ode_solvers::SVector::<f64, $dim>::from_column_slice($y0),
            $t_end,
            $tol,
            $beta,
            $fac_min,
            $fac_max,
            MAX_STEPS as u32
        );
        match stepper.integrate() {
            Ok(stats) => match (stepper.x_out().last(), stepper.y_out().last()) {
                (Some(&t), Some(y)) if t == $t_end => Ok((
                    y.as_slice().to_vec(),
                    stats.num_eval as usize,
                    stats.accepted_steps as usize,
                    stats.rejected_steps as usize,
                )),
                _ => Err(format!("ode_solvers stopped before t = {}", $t_end)),
            },
            Err(e) => Err(format!("ode_solvers: {e:?}")),
        }
    }};
}

/// One run of `runner` on `system` from `y0` to `t_end` at `rtol = atol = tol`:
/// `(final state, evaluations, accepted steps, rejected steps)`.
macro_rules! run_once {
    ($dim:literal, $runner:expr, $system:expr, $y0:expr, $t_end:expr, $tol:expr) => {{
        let (runner, system, y0, t_end, tol): (Runner, &RefCell<_>, &[f64], f64, f64) =
            ($runner, $system, $y0, $t_end, $tol);
        match runner {
            Runner::Eomgen(method) => {
                let options = IntegratorOptions::default()
                    .with_rtol(tol)
                    .with_atol(tol)
                    .with_max_steps(MAX_STEPS);
                let mut integrator = method.integrator();
                let mut system = system.borrow_mut();
                integrator
                    .integrate(&mut *system, 0.0, y0, t_end, &OutputTimes::Steps, &options)
                    .map_err(|e| format!("{e}"))
                    .and_then(|solution| match solution.last() {
                        Some((t, y)) if t == t_end => Ok((
                            y.to_vec(),
                            solution.stats.rhs_evals,
                            solution.stats.steps,
                            solution.stats.rejected,
                        )),
                        _ => Err(format!("stopped before t = {t_end}")),
                    })
            }
            Runner::PeerDop853 => peer_run!(Dop853, $dim, system, y0, t_end, tol, 0.0, 0.333, 6.0),
            Runner::PeerDopri5 => peer_run!(Dopri5, $dim, system, y0, t_end, tol, 0.04, 0.2, 10.0),
        }
    }};
}

/// Runs `runner` `reps` times (the first run also gives the state and counts) and times each
/// run.
macro_rules! measure {
    ($dim:literal, $runner:expr, $system:expr, $y0:expr, $t_end:expr, $tol:expr, $reps:expr) => {{
        let (final_state, rhs_evals, steps, rejected) =
            run_once!($dim, $runner, $system, $y0, $t_end, $tol)?;
        let mut times_s = Vec::with_capacity($reps);
        for _ in 0..$reps {
            let start = Instant::now();
            let outcome = run_once!($dim, $runner, $system, black_box($y0), $t_end, $tol);
            times_s.push(start.elapsed().as_secs_f64());
            black_box(outcome)?;
        }
        Ok::<Measurement, String>(Measurement {
            final_state,
            rhs_evals,
            steps,
            rejected,
            times_s,
        })
    }};
}

/// The median of `values` (the upper one of an even count).
fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.get(sorted.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The command line's options after the subcommand, as `(name, value)` pairs.
fn options(args: &[String]) -> Result<Vec<(String, String)>, String> {
    args.chunks(2)
        .map(|pair| match pair {
            [name, value] if name.starts_with("--") => Ok((name[2..].to_string(), value.clone())),
            _ => Err(format!("expected `--name value` pairs, got {pair:?}")),
        })
        .collect()
}

/// The value of option `name`, if given.
fn option<'a>(options: &'a [(String, String)], name: &str) -> Option<&'a str> {
    options
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, v)| v.as_str())
}

/// A comma-separated list of numbers.
fn numbers(list: &str) -> Result<Vec<f64>, String> {
    list.split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| format!("`{x}`: {e}")))
        .collect()
}

/// The reference state of `model` in the JSON file at `path`, as `(t_end, state)`.
fn reference(path: &str, model: &str) -> Result<(f64, Vec<f64>), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let json: Value = serde_json::from_str(&text).map_err(|e| format!("{path}: {e}"))?;
    let entry = &json[model];
    let t_end = entry["t_end"]
        .as_f64()
        .ok_or_else(|| format!("{path}: no `{model}.t_end`"))?;
    let state = entry["state"]
        .as_array()
        .ok_or_else(|| format!("{path}: no `{model}.state`"))?
        .iter()
        .map(|v| match v {
            Value::String(s) => s.parse::<f64>().map_err(|e| format!("{path}: `{s}`: {e}")),
            _ => v
                .as_f64()
                .ok_or_else(|| format!("{path}: {v} is not a number")),
        })
        .collect::<Result<Vec<f64>, String>>()?;
    Ok((t_end, state))
}

/// Changes `y0 = [q; q̇]` by `name=value` pairs (comma-separated), each a coordinate's name
/// or a rate's (`theta_dot`).
fn set_initial(coordinates: &[&str], y0: &mut [f64], changes: &str) -> Result<(), String> {
    let n = coordinates.len();
    for change in changes.split(',') {
        let (name, value) = change
            .split_once('=')
            .ok_or_else(|| format!("--set: `{change}` is not name=value"))?;
        let value: f64 = value.parse().map_err(|e| format!("--set {name}: {e}"))?;
        let (base, offset) = name.strip_suffix("_dot").map_or((name, 0), |b| (b, n));
        let i = coordinates.iter().position(|c| *c == base).ok_or_else(|| {
            format!(
                "--set: no coordinate `{base}` (valid: {})",
                coordinates.join(", ")
            )
        })?;
        y0[offset + i] = value;
    }
    Ok(())
}

/// The subcommands for one model type: `initial`, `rhs`, `run`.
macro_rules! command {
    ($dim:literal, $system:expr, $name:expr, $command:expr, $opts:expr) => {{
        let (name, command, opts): (&str, &str, &[(String, String)]) = ($name, $command, $opts);
        let system = RefCell::new($system);
        let mut y0 = ModelInfo::initial_state(&*system.borrow());
        if let Some(changes) = option(opts, "set") {
            let borrowed = system.borrow();
            let names = ModelInfo::description(&*borrowed).coordinate_names();
            set_initial(&names, &mut y0, changes)?;
        }
        match command {
            "initial" => {
                println!("{}", json!({"model": name, "initial_state": y0}));
                Ok(())
            }
            "rhs" => {
                let state = numbers(option(opts, "state").ok_or("`rhs` needs --state")?)?;
                if state.len() != $dim {
                    return Err(format!("--state needs {} numbers", $dim));
                }
                let mut dy = vec![0.0; $dim];
                system
                    .borrow_mut()
                    .rhs(0.0, &state, &mut dy)
                    .map_err(|e| format!("{e}"))?;
                println!("{}", json!({"model": name, "state": state, "rhs": dy}));
                Ok(())
            }
            "run" => {
                let t_end: f64 = option(opts, "t-end")
                    .ok_or("`run` needs --t-end")?
                    .parse()
                    .map_err(|e| format!("--t-end: {e}"))?;
                let runners = option(opts, "methods")
                    .ok_or("`run` needs --methods")?
                    .split(',')
                    .map(Runner::from_str)
                    .collect::<Result<Vec<_>, _>>()?;
                let tols = numbers(option(opts, "tols").ok_or("`run` needs --tols")?)?;
                let reps: usize = option(opts, "reps")
                    .unwrap_or("5")
                    .parse()
                    .map_err(|e| format!("--reps: {e}"))?;
                let reference = option(opts, "reference")
                    .map(|path| reference(path, name))
                    .transpose()?;
                match option(opts, "host-features") {
                    None | Some("on") => {}
                    Some("off") => eomgen::taylor::set_host_features(false),
                    Some(other) => return Err(format!("--host-features: `{other}`, not on or off")),
                }
                if let Some((t_ref, state)) = &reference {
                    if *t_ref != t_end || state.len() != $dim {
                        return Err(format!(
                            "the reference is at t = {t_ref} with {} states, not t = {t_end} \
                             with {}",
                            state.len(),
                            $dim
                        ));
                    }
                }
                let e0 = system.borrow().energy(0.0, &y0);
                for &tol in &tols {
                    for &runner in &runners {
                        let measured = (|| measure!($dim, runner, &system, &y0, t_end, tol, reps))();
                        let line = match measured {
                            Ok(m) => {
                                let error = reference.as_ref().map(|(_, r)| {
                                    m.final_state
                                        .iter()
                                        .zip(r)
                                        .map(|(a, b)| (a - b).abs())
                                        .fold(0.0, f64::max)
                                });
                                let e1 = system.borrow().energy(t_end, &m.final_state);
                                json!({
                                    "side": runner.side(),
                                    "method": runner.name(),
                                    "model": name,
                                    "tol": tol,
                                    "t_end": t_end,
                                    "time_s": median(&m.times_s),
                                    "times_s": m.times_s,
                                    "rhs_evals": m.rhs_evals,
                                    "steps": m.steps,
                                    "rejected": m.rejected,
                                    "final_state": m.final_state,
                                    "error": error,
                                    "energy_drift": ((e1 - e0) / e0).abs(),
                                    "host_features": eomgen::taylor::host_features(),
                                })
                            }
                            Err(message) => json!({
                                "side": runner.side(),
                                "method": runner.name(),
                                "model": name,
                                "tol": tol,
                                "failed": message,
                            }),
                        };
                        println!("{line}");
                    }
                }
                Ok(())
            }
            _ => Err(format!(
                "unknown command `{command}` (valid: initial, rhs, run)"
            )),
        }
    }};
}

/// Parses the command line and runs the subcommand.
fn main_inner() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (command, rest) = args
        .split_first()
        .ok_or("usage: work_precision_peers initial|rhs|run --model NAME [options]")?;
    let opts = options(rest)?;
    let model = option(&opts, "model").ok_or("--model is required")?;
    match option(&opts, "from-file") {
        None | Some("off") => {}
        Some("on") => {
            let name = option(&opts, "name").unwrap_or(model);
            return from_file(model, name, command, &opts);
        }
        Some(other) => return Err(format!("--from-file: `{other}`, not on or off")),
    }
    match model {
        "double_pendulum" => command!(
            4,
            FirstOrder::new(DoublePendulum::default()),
            model,
            command,
            &opts
        ),
        "figure_eight" => command!(
            12,
            FirstOrder::new(FigureEight::default()),
            model,
            command,
            &opts
        ),
        _ => Err(format!(
            "unknown model `{model}` (valid: double_pendulum, figure_eight)"
        )),
    }
}

/// The subcommand on the model loaded from its file and compiled at run time (`--from-file
/// on`): the path of the command line and of Python, with its Taylor orders compiled from the
/// first series (`LoadOptions::eager_taylor`), as after the first steps of any run. `model` is a bundled model's name or a model file's path
/// (`.yaml`); `name` labels the output lines and picks the reference (`--name`, default the
/// model). The states of the panel of `tools/peer_panel.py` have 4, 6, 10, 12 and 16
/// components, those of `tools/taylor_ops_bench.py` 2 (ode_solvers' state is a fixed-size
/// vector, one copy of its code per size).
fn from_file(
    model: &str,
    name: &str,
    command: &str,
    opts: &[(String, String)],
) -> Result<(), String> {
    let path = if model.ends_with(".yaml") {
        model.to_string()
    } else {
        format!("{}/../models/{model}.yaml", env!("CARGO_MANIFEST_DIR"))
    };
    let options = eomgen::LoadOptions {
        eager_taylor: true,
        ..eomgen::LoadOptions::default()
    };
    let system = eomgen::JitModel::load_with(&path, options)
        .map(eomgen::DynFirstOrder::new)
        .map_err(|e| format!("{path}: {e}"))?;
    match 2 * ModelInfo::num_dofs(&system) {
        2 => command!(2, system, name, command, opts),
        4 => command!(4, system, name, command, opts),
        6 => command!(6, system, name, command, opts),
        10 => command!(10, system, name, command, opts),
        12 => command!(12, system, name, command, opts),
        16 => command!(16, system, name, command, opts),
        dim => Err(format!(
            "{path}: {dim} states; this program runs models of 2, 4, 6, 10, 12 or 16"
        )),
    }
}

fn main() -> ExitCode {
    match main_inner() {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
