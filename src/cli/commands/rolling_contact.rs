//! `eomgen study rolling-contact MODEL [--after-lift-off]` (HW36): the friction coefficient
//! a body rolling on the ground needs, `μ(t) = |F_t|/N`, from its constraint forces up to the
//! lift-off, checked against Newton–Euler; with `--after-lift-off`, the free flight that
//! follows (a second model, default `MODEL_flight`) to the next touch-down, joined to the
//! rolling phase and checked against its closed forms; a chart with `--plot`.
//!
//! The numbers come from [`eomgen::analysis::rolling_contact::rolling_contact`]; this file
//! parses, draws and prints.

use std::io::Write as _;

use clap::Args;
use eomgen::ModelInfo;
use eomgen::analysis::StudyRuns;
use eomgen::analysis::rolling_contact::{
    FlightPhase, RollingContact, RollingContactError, RollingContactOptions, RollingPhase,
    rolling_contact,
};

use crate::cli::error::CliError;
use crate::cli::files::Outputs;
use crate::cli::json::print_json_sorted;
use crate::cli::model::find_model;
use crate::cli::plot::Series;
use crate::cli::response_study::{Panel, panels};
use crate::cli::values::{set_parameters, split_assignment};

/// Options of `eomgen study rolling-contact`.
#[derive(Debug, Args)]
pub struct RollingContactArgs {
    /// The rolling model: a bundled model's name or the path of any model file
    /// (`eccentric_cylinder`).
    pub model: String,
    /// Also integrate the free flight after the lift-off, from the rolling state there, to
    /// the landing.
    #[arg(long)]
    pub after_lift_off: bool,
    /// The flight model (the same body and coordinates, no constraints). Default: the
    /// rolling model's name with `_flight` (`eccentric_cylinder_flight`).
    #[arg(long, value_name = "MODEL", requires = "after_lift_off")]
    pub flight: Option<String>,
    /// Friction coefficients whose first exceedance by μ(t) is located, comma separated.
    #[arg(long, value_name = "MU1,MU2,…", value_delimiter = ',', default_values_t = RollingContactOptions::default().thresholds)]
    pub mu: Vec<f64>,
    /// The coordinate along the ground.
    #[arg(long, default_value = "x")]
    pub ground: String,
    /// The coordinate along the ground's normal.
    #[arg(long, default_value = "y")]
    pub normal: String,
    /// The body's rotation angle (its rate is constant in flight).
    #[arg(long, default_value = "theta")]
    pub angle: String,
    /// The rolling model's event where the normal force reaches zero.
    #[arg(long, default_value = "lift_off")]
    pub lift_off: String,
    /// The flight model's event where the body touches the ground again.
    #[arg(long, default_value = "landing")]
    pub landing: String,
    /// Uniform samples of each phase (5 to 1000000).
    #[arg(long, default_value_t = RollingContactOptions::DEFAULT_SAMPLES, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(5..=1_000_000))]
    pub samples: usize,
    /// The longest phase (s).
    #[arg(long, default_value_t = RollingContactOptions::DEFAULT_T_END, value_parser = crate::cli::values::study_end_time, allow_hyphen_values = true)]
    pub t_end: f64,
    /// Relative and absolute tolerance of the DOP853 integrations.
    #[arg(long, default_value_t = RollingContactOptions::DEFAULT_RTOL, value_parser = crate::cli::values::relative_tolerance, allow_hyphen_values = true)]
    pub rtol: f64,
    /// Set a parameter of both models, `NAME=VALUE` (the flight model takes those it has);
    /// repeatable.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Chart: μ(t), the contact forces both ways and, after the lift-off, the height and
    /// the energy over both phases (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `study rolling-contact`; exits 1 when a check fails.
pub fn run(args: &RollingContactArgs) -> Result<(), CliError> {
    let mut rolling = crate::cli::model::find_smooth_model(&args.model, "`study rolling-contact`")?;
    set_parameters(rolling.as_mut(), &args.set)?;
    let mut flight = match args.after_lift_off {
        true => {
            let name = args
                .flight
                .clone()
                .unwrap_or_else(|| format!("{}_flight", rolling.description().name));
            let mut flight = find_model(&name)?;
            let own: Vec<String> = flight
                .description()
                .parameters
                .iter()
                .map(|p| p.name.to_string())
                .collect();
            let mut sets = Vec::new();
            for set in &args.set {
                let (name, _) = split_assignment(set, "set")?;
                if own.iter().any(|p| p == name) {
                    sets.push(set.clone());
                }
            }
            set_parameters(flight.as_mut(), &sets)?;
            Some(flight)
        }
        false => None,
    };
    // After both models are open, so that the flight model is among the inputs no output
    // may replace (`files::read_input`).
    Outputs::new()
        .input(&args.model)
        .chart("--plot", args.plot.as_deref())
        .check()?;
    let options = RollingContactOptions {
        ground: args.ground.clone(),
        normal: args.normal.clone(),
        angle: args.angle.clone(),
        lift_off: args.lift_off.clone(),
        landing: args.landing.clone(),
        thresholds: args.mu.clone(),
        samples: args.samples,
        t_end: args.t_end,
        rtol: args.rtol,
        ..RollingContactOptions::default()
    };
    let study = rolling_contact(
        rolling.as_mut(),
        flight.as_mut().map(|f| f.as_mut() as &mut dyn ModelInfo),
        &options,
    )
    .map_err(|e| match e {
        RollingContactError::UnknownCoordinate { role, .. } => {
            CliError::usage(format!("--{role}: {e}"))
        }
        RollingContactError::UnknownEvent { .. } => CliError::usage(e.to_string()),
        RollingContactError::InvalidOption { .. } => CliError::usage(e.to_string()),
        e => CliError::failure(e.to_string()),
    })?;
    study
        .check_measured()
        .map_err(|e| CliError::failure(e.to_string()))?;
    if let Some(path) = &args.plot {
        chart(path, &study).map_err(CliError::failure)?;
    }
    if args.json {
        print_json_sorted(&study)?;
    } else {
        print_text(&study);
    }
    let failed = study.failed_checks();
    if failed.is_empty() {
        Ok(())
    } else {
        Err(CliError::failure(format!(
            "check failed: {}",
            failed.join("; ")
        )))
    }
}

/// The stacked chart: μ(t) (clipped above, since it diverges at the lift-off) with the
/// thresholds, `N` and `F_t` both ways, and, when the body flies after the lift-off, the
/// normal coordinate of the centre and of G and the energy change over both phases.
fn chart(path: &str, study: &RollingContact) -> Result<(), String> {
    let r = &study.rolling;
    let largest_threshold = study
        .rolling
        .exceedances
        .iter()
        .fold(0.0_f64, |m, e| m.max(e.mu));
    let clip = (2.0 * r.max_peak.map_or(0.0, |p| p.mu))
        .max(1.5 * largest_threshold)
        .max(0.5);
    let t_end = study
        .flight
        .as_ref()
        .and_then(|f| f.samples.last().map(|s| s.t))
        .unwrap_or(r.lift_off_time);
    let mut mu_series = vec![Series {
        name: "μ = |F_t|/N needed".to_string(),
        points: r
            .samples
            .iter()
            .filter_map(|s| s.mu.filter(|mu| *mu <= clip).map(|mu| (s.t, mu)))
            .collect(),
    }];
    for e in &r.exceedances {
        mu_series.push(Series {
            name: match e.t {
                Some(t) => format!("μ = {}: slips at t = {t:.4} s", e.mu),
                None => format!("μ = {}: never reached", e.mu),
            },
            points: vec![(0.0, e.mu), (r.lift_off_time, e.mu)],
        });
    }
    let forces =
        |name: &str,
         f: &dyn Fn(&eomgen::analysis::rolling_contact::ContactSample) -> Option<f64>| {
            Series {
                name: name.to_string(),
                points: r
                    .samples
                    .iter()
                    .filter_map(|s| f(s).map(|v| (s.t, v)))
                    .collect(),
            }
        };
    let mut list = vec![
        Panel {
            caption: Some(format!(
                "friction needed, up to the lift-off at t = {:.5} s (→ ∞ there; clipped at {clip:.2})",
                r.lift_off_time
            )),
            y_desc: "μ (1)".to_string(),
            series: mu_series,
        },
        Panel {
            caption: Some(
                "contact forces: multipliers (−Jᵀλ) and Newton–Euler (m a_G − m g)".to_string(),
            ),
            y_desc: "force (N)".to_string(),
            series: vec![
                forces("N from λ", &|s| Some(s.normal_force)),
                forces("F_t from λ", &|s| Some(s.friction_force)),
                forces("N Newton–Euler", &|s| s.normal_force_newton_euler),
                forces("F_t Newton–Euler", &|s| s.friction_force_newton_euler),
            ],
        },
    ];
    if let Some(f) = study.flight.as_ref().filter(|f| f.flies) {
        list.extend(flight_panels(r, f, t_end)?);
    }
    let title = format!("{}: rolling contact (HW36)", r.model);
    panels(path, &title, &list)
}

/// The panels of a flight: the normal coordinate of the centre and of `G` (integrated and on
/// the closed-form parabola), and the energy over both phases.
///
/// # Errors
/// A model whose coordinates do not include the contact's normal one.
fn flight_panels(r: &RollingPhase, f: &FlightPhase, t_end: f64) -> Result<Vec<Panel>, String> {
    let mut panels = Vec::new();
    let normal = r
        .coordinates
        .iter()
        .position(|c| *c == r.normal)
        .ok_or_else(|| format!("no coordinate `{}`", r.normal))?;
    let mut centre: Vec<(f64, f64)> = r.samples.iter().map(|s| (s.t, s.q[normal])).collect();
    centre.extend(f.samples.iter().map(|s| (s.t, s.q[normal])));
    let e0 = r.samples[0].energy;
    let mut energy: Vec<(f64, f64)> = r.samples.iter().map(|s| (s.t, s.energy - e0)).collect();
    energy.extend(f.samples.iter().map(|s| (s.t, s.energy - e0)));
    panels.push(Panel {
        caption: Some(match f.landing_time {
            Some(t) => format!(
                "rolling, then flight from t = {:.5} s to the landing at t = {t:.5} s",
                r.lift_off_time
            ),
            None => format!(
                "rolling, then flight from t = {:.5} s (no landing by {t_end:.3} s)",
                r.lift_off_time
            ),
        }),
        y_desc: format!("{} (m)", r.coordinates[normal]),
        series: vec![
            Series {
                name: format!("centre {}", r.coordinates[normal]),
                points: centre,
            },
            Series {
                name: "G on the closed-form parabola (flight)".to_string(),
                points: f.samples.iter().map(|s| (s.t, s.parabola[1])).collect(),
            },
            Series {
                name: "G integrated (flight)".to_string(),
                points: f
                    .samples
                    .iter()
                    .map(|s| (s.t, s.centre_of_mass[1]))
                    .collect(),
            },
        ],
    });
    panels.push(Panel {
        caption: Some("energy over both phases (no impulse at the lift-off)".to_string()),
        y_desc: "E − E(0) (J)".to_string(),
        series: vec![Series {
            name: "T + V − E(0)".to_string(),
            points: energy,
        }],
    });
    Ok(panels)
}

/// The table.
fn print_text(study: &RollingContact) {
    let mut out = crate::cli::output::stdout();
    let r = &study.rolling;
    let ne = &r.newton_euler;
    let _ = writeln!(
        out,
        "model      {}: DOP853, {} samples up to the lift-off; contact force = −Jᵀλ along `{}` (F_t) and `{}` (N)",
        r.model,
        r.samples.len(),
        r.ground,
        r.normal,
    );
    let _ = writeln!(
        out,
        "lift-off   t = {:.12} s: N = {:.3e} N, F_t = {:.9} N, dN/dt = {:.6} N/s",
        r.lift_off_time,
        r.normal_force_at_lift_off,
        r.friction_force_at_lift_off,
        r.normal_force_rate_at_lift_off
    );
    if r.mu_diverges {
        let _ = writeln!(
            out,
            "           μ(t) → ∞ at the lift-off (N → 0 while F_t ≠ 0): μ ≈ {:.6} s / (t_lift − t); no finite μ rolls all the way",
            (r.friction_force_at_lift_off / r.normal_force_rate_at_lift_off).abs()
        );
    }
    for p in &r.peaks {
        let _ = writeln!(out, "μ peak     t = {:.6} s: μ = {:.6}", p.t, p.mu);
    }
    if let Some(p) = &r.max_peak {
        let rise = r.final_rise_from.map_or(String::new(), |t| {
            format!("; μ rises without bound from t = {t:.6} s")
        });
        let _ = writeln!(
            out,
            "max μ      {:.6} at t = {:.6} s before the final rise{rise}",
            p.mu, p.t
        );
    }
    for e in &r.exceedances {
        let _ = match e.t {
            Some(t) => writeln!(
                out,
                "μ = {:<6} reached at t = {t:.9} s ({:.6} s before the lift-off): a body with that μ slips there",
                e.mu,
                r.lift_off_time - t
            ),
            None => writeln!(out, "μ = {:<6} never reached before the lift-off", e.mu),
        };
    }
    let _ = writeln!(
        out,
        "newton–euler m = {:.6} kg, g = ({:.6}, {:.6}) m/s²: max |ΔN| = {:.3e} N, max |ΔF_t| = {:.3e} N, {:.2e} of max N = {:.6} N (tolerance {:.0e}): {}",
        ne.mass,
        ne.gravity[0],
        ne.gravity[1],
        ne.max_normal_difference,
        ne.max_friction_difference,
        ne.relative,
        ne.max_normal_force,
        ne.tolerance,
        if ne.passed { "ok" } else { "FAILED" }
    );
    let _ = writeln!(
        out,
        "energy     rolling drift max|E − E(0)|/max(T + |V|) = {:.3e}",
        r.energy_drift
    );
    let Some(f) = &study.flight else {
        return;
    };
    print_flight(&mut out, r, f);
}

/// The flight after the lift-off: the release, the flight or why there is none, and the
/// checks of the flight phase.
fn print_flight(out: &mut impl std::io::Write, r: &RollingPhase, f: &FlightPhase) {
    let _ = writeln!(
        out,
        "release    {}: from the lift-off state, free of the ground: d²{}/dt² = {:.9} m/s² (0 while rolling)",
        f.model, r.normal, f.release_normal_acceleration
    );
    match (f.flies, f.landing_time, f.flight_time) {
        (false, _, _) if f.release_normal_acceleration < 0.0 => {
            let _ = writeln!(
                out,
                "flight     none: released, the body presses on the ground at once — the friction force F_t = {:.6} N, which no μ supplies at N = 0, vanishes with N; it would keep contact and slide",
                r.friction_force_at_lift_off
            );
        }
        (false, _, _) => {
            let _ = writeln!(out, "flight     none: the body never rose off the ground");
        }
        (true, Some(t), Some(air)) => {
            let _ = writeln!(
                out,
                "flight     lift-off at t = {:.9} s, landing at t = {t:.9} s ({air:.9} s in the air), highest {:.6e} m above the lift-off, landing {}-velocity {:.6} m/s",
                r.lift_off_time,
                f.max_height,
                r.normal,
                f.landing_normal_velocity.unwrap_or(f64::NAN)
            );
            let _ = writeln!(
                out,
                "           stopped at the landing: the impact is beyond the model"
            );
        }
        (true, _, _) => {
            let _ = writeln!(
                out,
                "flight     no landing within the longest phase; highest {:.6e} m",
                f.max_height
            );
        }
    }
    for c in &f.checks {
        let _ = writeln!(
            out,
            "check      {:<34} {:.3e} (tolerance {:.0e}): {}",
            c.name,
            c.value,
            c.tolerance,
            if c.passed { "ok" } else { "FAILED" }
        );
    }
}
