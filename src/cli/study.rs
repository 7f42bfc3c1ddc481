//! `eomgen study …`: numerical experiments that compare methods on a model.
//!
//! `constraint-methods` (issue 5, item 6; lectures 8–11, HW10's "which one is faster? more
//! accurate?"): the constraint of a model handled as a stiff spring (method I, several `k`),
//! as a DAE without and with Baumgarte stabilisation (II.1), and in minimal coordinates (II.3)
//! where the model has a minimal-coordinate twin, side by side.

use std::io::Write as _;

use clap::{Args, Subcommand};
use eomgen::{
    DormandPrince54, IntegrationFailure, Integrator, IntegratorOptions, ModelInfo, OutputTimes,
    Solution, Stabilization,
};
use serde_json::json;

use super::{CliError, find_model, plot};

/// The studies.
#[derive(Debug, Subcommand)]
pub enum Study {
    /// Constraint handled by stiff springs, as a DAE (with and without Baumgarte) and in
    /// minimal coordinates: accuracy of the point positions, constraint drift, RHS
    /// evaluations and time, as a table, JSON and a chart.
    ConstraintMethods(ConstraintMethodsArgs),
    /// Error against work for every integration method on a model: error of the state at
    /// the output times against a verified reference, RHS evaluations, wall time and energy
    /// drift, per tolerance (or step size); a table, JSON and log–log charts.
    WorkPrecision(super::work_precision::WorkPrecisionArgs),
    /// Where each method fails: stability limits on the oscillator against theory, energy
    /// growth over 10⁴ periods, a stiff two-mass spring, step-size underflow.
    Stability(super::stability::StabilityArgs),
    /// HW1: explicit Euler on ẋ = x with h = 10⁻ⁿ, truncation against roundoff error and
    /// the optimal n.
    EulerRoundoff(super::roundoff::EulerRoundoffArgs),
    /// HW28: the free response of the linearised, undamped equations four ways (integration,
    /// e^{At}, modes of M⁻¹K, mass-normalised modes), their differences and a chart.
    FreeResponse(super::free_response::FreeResponseArgs),
    /// HW34: damping ratios exact (eigenvalues of A) vs the diagonal of Ĉ = ΨᵀCΨ vs Rayleigh
    /// damping fitted to two modes, and the free responses from each mode shape.
    ModalDamping(super::modal_damping::ModalDampingArgs),
    /// Floquet multipliers of a time-periodic model about an equilibrium (the Mathieu
    /// inverted pendulum), and its stability chart over two parameters (`--sweep`).
    Floquet(super::floquet::FloquetArgs),
}

/// Options of `eomgen study constraint-methods`.
#[derive(Debug, Args)]
pub struct ConstraintMethodsArgs {
    /// A model with holonomic constraints (`simple_pendulum_cartesian`, `two_masses_rod`, …):
    /// a bundled name or the path of any model file.
    pub model: String,
    /// End time (s).
    #[arg(long, default_value_t = 10.0)]
    pub t_end: f64,
    /// Relative and absolute tolerance of every run (Dormand–Prince 5(4)).
    #[arg(long, default_value_t = 1e-8)]
    pub tol: f64,
    /// Spring stiffnesses of method I, comma separated.
    #[arg(long, value_delimiter = ',', default_values_t = [1e2, 1e4, 1e6])]
    pub stiffness: Vec<f64>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Chart of the position error against time, one line per method (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
}

/// Runs a study.
pub fn run(study: &Study) -> Result<(), CliError> {
    match study {
        Study::ConstraintMethods(args) => constraint_methods(args),
        Study::WorkPrecision(args) => super::work_precision::run(args),
        Study::Stability(args) => super::stability::run(args),
        Study::EulerRoundoff(args) => super::roundoff::run(args),
        Study::FreeResponse(args) => super::free_response::run(args),
        Study::ModalDamping(args) => super::modal_damping::run(args),
        Study::Floquet(args) => super::floquet::run(args),
    }
}

/// The bundled model with the same mechanism in minimal coordinates, and how to map its
/// state to this model's points (by point name).
fn minimal_twin(model: &str) -> Option<&'static str> {
    match model {
        "simple_pendulum_cartesian" => Some("simple_pendulum"),
        _ => None,
    }
}

/// One method's run.
struct Row {
    method: String,
    /// Largest distance (m) of any point from its reference position at the output times.
    position_error: f64,
    /// Largest `|Φ|` at the output times (`None` in minimal coordinates: no constraint).
    drift: Option<f64>,
    rhs_evals: usize,
    steps: usize,
    wall_time_s: f64,
    error_history: Vec<(f64, f64)>,
    failure: Option<String>,
}

fn integrate(
    model: &mut dyn ModelInfo,
    t_end: f64,
    times: &[f64],
    tol: f64,
) -> (Solution, Option<String>) {
    let options = IntegratorOptions::default()
        .with_rtol(tol)
        .with_atol(tol)
        .with_max_steps(2_000_000);
    let y0 = model.initial_state();
    match DormandPrince54::new().integrate(
        model.as_ode_mut(),
        0.0,
        &y0,
        t_end,
        &OutputTimes::At(times.to_vec()),
        &options,
    ) {
        Ok(s) => (s, None),
        Err(IntegrationFailure { error, partial }) => (*partial, Some(error.to_string())),
    }
}

/// Positions of the points named in `names`, in that order, at every sample.
fn positions(model: &dyn ModelInfo, solution: &Solution, names: &[&str]) -> Vec<Vec<[f64; 3]>> {
    let own = model.point_names();
    solution
        .iter()
        .map(|(t, y)| {
            let all = model.point_positions(t, y);
            names
                .iter()
                .map(|n| {
                    own.iter()
                        .position(|p| p == n)
                        .map_or([f64::NAN; 3], |i| all[i])
                })
                .collect()
        })
        .collect()
}

fn row(
    method: String,
    model: &mut dyn ModelInfo,
    solution: &Solution,
    failure: Option<String>,
    reference: &[Vec<[f64; 3]>],
    names: &[&str],
    constrained: bool,
) -> Row {
    let here = positions(model, solution, names);
    let mut error_history = Vec::new();
    let mut position_error: f64 = 0.0;
    for ((t, p), r) in solution.t.iter().zip(&here).zip(reference) {
        let e = p
            .iter()
            .zip(r)
            .map(|(a, b)| {
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
            })
            .fold(0.0f64, f64::max);
        position_error = position_error.max(e);
        error_history.push((*t, e));
    }
    let drift = constrained.then(|| {
        solution
            .iter()
            .map(|(t, y)| model.constraint_drift(t, y).0)
            .fold(0.0f64, f64::max)
    });
    Row {
        method,
        position_error,
        drift,
        rhs_evals: solution.stats.rhs_evals,
        steps: solution.stats.steps,
        wall_time_s: solution.stats.wall_time_s,
        error_history,
        failure,
    }
}

fn constraint_methods(args: &ConstraintMethodsArgs) -> Result<(), CliError> {
    let mut model = find_model(&args.model)?;
    if model.holonomic_constraint_count() == 0 {
        return Err(CliError::usage(format!(
            "`{}` has no holonomic constraints to compare methods on; try simple_pendulum_cartesian or two_masses_rod",
            model.name()
        )));
    }
    let positive = |x: f64| x.is_finite() && x > 0.0;
    if !positive(args.t_end) || !positive(args.tol) {
        return Err(CliError::usage("--t-end and --tol must be positive"));
    }
    let times: Vec<f64> = (1..=200)
        .map(|i| args.t_end * f64::from(i) / 200.0)
        .collect();
    let owned: Vec<String> = model.point_names().iter().map(|s| s.to_string()).collect();
    let names: Vec<&str> = owned.iter().map(String::as_str).collect();

    // Reference: the DAE with Baumgarte at rtol = atol = 1e-13, checked against the
    // unstabilised DAE at the same tolerance (their agreement is printed).
    let reference_tol = 1e-13;
    model.set_stabilization(Stabilization::Baumgarte {
        alpha: 10.0,
        beta: 10.0,
    });
    let (reference_solution, failure) =
        integrate(model.as_mut(), args.t_end, &times, reference_tol);
    if let Some(f) = failure {
        return Err(CliError::failure(format!(
            "the reference solution failed: {f}"
        )));
    }
    let reference = positions(model.as_ref(), &reference_solution, &names);
    model.set_stabilization(Stabilization::None);
    let (check, _) = integrate(model.as_mut(), args.t_end, &times, reference_tol);
    let agreement = row(
        String::new(),
        model.as_mut(),
        &check,
        None,
        &reference,
        &names,
        true,
    )
    .position_error;

    let mut rows = Vec::new();
    for &k in &args.stiffness {
        let mut m = find_model(&args.model)?;
        m.set_stabilization(Stabilization::Penalty {
            stiffness: k,
            damping: 0.0,
        });
        let (s, f) = integrate(m.as_mut(), args.t_end, &times, args.tol);
        rows.push(row(
            format!("I: stiff spring k = {k:e}"),
            m.as_mut(),
            &s,
            f,
            &reference,
            &names,
            true,
        ));
    }
    for (label, stab) in [
        ("II.1: DAE, no stabilisation", Stabilization::None),
        (
            "II.1: DAE, Baumgarte α = β = 10/s",
            Stabilization::Baumgarte {
                alpha: 10.0,
                beta: 10.0,
            },
        ),
    ] {
        let mut m = find_model(&args.model)?;
        m.set_stabilization(stab);
        let (s, f) = integrate(m.as_mut(), args.t_end, &times, args.tol);
        rows.push(row(
            label.to_string(),
            m.as_mut(),
            &s,
            f,
            &reference,
            &names,
            true,
        ));
    }
    if let Some(twin) = minimal_twin(model.name()) {
        let mut m = find_model(twin)?;
        let (s, f) = integrate(m.as_mut(), args.t_end, &times, args.tol);
        rows.push(row(
            format!("II.3: minimal coordinates ({twin})"),
            m.as_mut(),
            &s,
            f,
            &reference,
            &names,
            false,
        ));
    }

    if let Some(path) = &args.plot {
        let series: Vec<plot::Series> = rows
            .iter()
            .map(|r| plot::Series {
                name: r.method.clone(),
                points: r.error_history.clone(),
            })
            .collect();
        let title = format!("{}: constraint methods, position error", model.name());
        plot::lines(
            path,
            &plot::Chart {
                title: &title,
                x_desc: "t (s)",
                y_desc: "largest point position error (m)",
                log_x: false,
                log_y: true,
            },
            &series,
        )
        .map_err(CliError::failure)?;
    }
    let mut stdout = std::io::stdout().lock();
    if args.json {
        let out = json!({
            "model": model.name(),
            "t_end": args.t_end,
            "tol": args.tol,
            "reference": {"method": "dopri5, DAE with Baumgarte α = β = 10/s", "tol": reference_tol, "agreement_with_unstabilised_dae_m": agreement},
            "methods": rows.iter().map(|r| json!({
                "method": r.method,
                "position_error_m": r.position_error,
                "max_constraint_drift": r.drift,
                "rhs_evals": r.rhs_evals,
                "steps": r.steps,
                "wall_time_s": r.wall_time_s,
                "error": r.failure,
            })).collect::<Vec<_>>(),
        });
        let text =
            serde_json::to_string_pretty(&out).map_err(|e| CliError::failure(e.to_string()))?;
        let _ = writeln!(stdout, "{text}");
    } else {
        let _ = writeln!(
            stdout,
            "model      {} over 0 ≤ t ≤ {} s, Dormand–Prince 5(4) at rtol = atol = {:e}",
            model.name(),
            args.t_end,
            args.tol
        );
        let _ = writeln!(
            stdout,
            "reference  DAE with Baumgarte at tol {reference_tol:e}; the unstabilised DAE at that tolerance agrees to {agreement:.2e} m"
        );
        let _ = writeln!(
            stdout,
            "{:<44} {:>12} {:>12} {:>10} {:>8} {:>10}",
            "method", "pos. err (m)", "max |Φ|", "RHS evals", "steps", "time (ms)"
        );
        for r in &rows {
            let drift = r.drift.map_or("-".to_string(), |d| format!("{d:.2e}"));
            let _ = writeln!(
                stdout,
                "{:<44} {:>12.2e} {:>12} {:>10} {:>8} {:>10.3}{}",
                r.method,
                r.position_error,
                drift,
                r.rhs_evals,
                r.steps,
                r.wall_time_s * 1e3,
                r.failure
                    .as_ref()
                    .map_or(String::new(), |f| format!("  failed: {f}"))
            );
        }
    }
    Ok(())
}
