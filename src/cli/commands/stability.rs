//! `eomgen study stability` (issue 6; syllabus lecture 4, HW9): where each integration method
//! fails, measured by running it, against the theory of its stability function.
//!
//! a. Stability limits on `ẍ = −ω²x` (`hω`) and `ẋ = −λx` (`hλ`), measured by bisection on
//!    constant-step runs, against the intervals of `R(z) = 1 + z bᵀ(I − zA)⁻¹𝟙`; per-step
//!    amplification where the interval is empty (explicit Euler and midpoint) and for the
//!    A-stable implicit methods at large `hω`.
//! b. Energy of explicit Euler, RK4 and Störmer–Verlet over many periods of the oscillator.
//! c. The stiff two-mass spring (HW9's `two_masses` with large `k/m`): steps of explicit and
//!    implicit methods at one tolerance, against a tight DOP853 reference.
//! d. A step-size underflow (`ẏ = y²` blows up at `t = 1`), reported as the integration
//!    reports it.

use std::io::Write as _;

use clap::Args;
use eomgen::analysis::stability::{
    AMPLIFICATION_STEPS, BISECTION_TOLERANCE, EnergyRow, ExplicitMethod, GROWTH_THRESHOLD, Limits,
    STIFF_OUTPUT_TIMES, STIFF_REFERENCE_TOL, StabilityError, StabilityOptions, StabilityStudy,
    StiffMode, StiffRow, StiffSpring, UnderflowRun, stability_study,
};
use eomgen::integrate::stability_function::GrowthTest;
use nalgebra::Complex;

use crate::cli::error::CliError;
use crate::cli::files::Outputs;
use crate::cli::json::print_json_sorted;
use crate::cli::model::find_model;
use crate::cli::plot::{self, log_y_chart};
use crate::cli::render::num;

/// The bundled model of part c: HW9's two-mass spring.
const STIFF_MODEL: &str = "two_masses";

/// Options of `eomgen study stability`.
#[derive(Debug, Args)]
pub struct StabilityArgs {
    /// Constant steps of each run of the stability-limit bisection (part a).
    #[arg(long, default_value_t = StabilityOptions::DEFAULT_STEPS)]
    pub steps: usize,
    /// Periods of the oscillator in the energy study (part b).
    #[arg(long, default_value_t = StabilityOptions::DEFAULT_PERIODS)]
    pub periods: usize,
    /// Stiffness ratios k/m (1/s²) of the stiff two-mass spring (part c), comma separated.
    #[arg(long, value_delimiter = ',', value_parser = crate::cli::values::stiffness, allow_hyphen_values = true, default_values_t = StabilityOptions::DEFAULT_STIFFNESS)]
    pub stiffness: Vec<f64>,
    /// End time of the stiff runs (s).
    #[arg(long, default_value_t = StabilityOptions::DEFAULT_T_END)]
    pub t_end: f64,
    /// Relative and absolute tolerance of the stiff runs and of the underflow run.
    #[arg(long, default_value_t = StabilityOptions::DEFAULT_TOL, value_parser = crate::cli::values::relative_tolerance, allow_hyphen_values = true)]
    pub tol: f64,
    /// Print JSON instead of the tables.
    #[arg(long)]
    pub json: bool,
    /// Charts PREFIX-limits, PREFIX-energy and PREFIX-stiff (.svg, or .png if PREFIX ends in
    /// .png).
    #[arg(long, value_name = "PREFIX")]
    pub plot: Option<String>,
}

/// A study that could not run, as the CLI reports it (naming the options to change).
fn study_error(error: StabilityError) -> CliError {
    match error {
        StabilityError::InvalidSteps { .. } => CliError::usage("--steps must be in [100, 10⁶]"),
        StabilityError::InvalidPeriods { .. } => CliError::usage("--periods must be in [1, 10⁵]"),
        StabilityError::InvalidStiffness => {
            CliError::usage("--stiffness takes ratios k/m in (0, 1e10], comma separated")
        }
        StabilityError::InvalidEndTime { .. } => {
            CliError::usage("--t-end must be in [1e-6, 100] s")
        }
        StabilityError::InvalidTolerance { .. } => CliError::usage("--tol must be in [1e-13, 1)"),
        other => CliError::failure(other.to_string()),
    }
}

/// Runs `eomgen study stability`.
pub fn run(args: &StabilityArgs) -> Result<(), CliError> {
    let options = StabilityOptions {
        steps: args.steps,
        periods: args.periods,
        stiffness: args.stiffness.clone(),
        t_end: args.t_end,
        tol: args.tol,
        // HW9's two-mass spring file and its names.
        stiff_spring: StiffSpring {
            mass_1: "m1".to_string(),
            mass_2: "m2".to_string(),
            stiffness: "k".to_string(),
            force: "F0".to_string(),
            stretched: "x2".to_string(),
        },
    };
    options.validate().map_err(study_error)?;
    if let Some(prefix) = &args.plot
        && prefix.is_empty()
    {
        return Err(CliError::usage("--plot needs a file prefix"));
    }
    let charts = args
        .plot
        .as_deref()
        .map(|prefix| CHARTS.map(|name| plot::chart_path(prefix, name)));
    charts
        .iter()
        .flatten()
        .fold(Outputs::new(), |outputs, path| {
            outputs.chart("--plot", Some(path))
        })
        .check()?;
    let mut two_masses = find_model(STIFF_MODEL)?;
    let mut study = stability_study(two_masses.as_mut(), &options).map_err(study_error)?;
    if let Some([limits_path, energy_path, stiff_path]) = &charts {
        plot_limits(limits_path, &mut study.limits.explicit)?;
        plot_energy(energy_path, &study.energy)?;
        plot_stiff(stiff_path, &study.stiff)?;
    }
    let StabilityStudy {
        test,
        limits,
        energy,
        stiff_modes: modes,
        stiff,
        underflow,
    } = &study;
    if args.json {
        print_json_sorted(&study.summary(two_masses.as_ref(), &options))?;
    } else {
        let mut text = String::new();
        write_limits(&mut text, test, limits);
        write_energy(&mut text, args.periods, energy);
        write_stiff(&mut text, args, modes, stiff);
        write_underflow(&mut text, underflow);
        let _ = write!(crate::cli::output::stdout(), "{text}");
    }
    // The limits of part a are always measured (a failure there is the study's error), so
    // the rule of a study that measured nothing has nothing to refuse here.
    Ok(())
}

/// The charts of `--plot PREFIX`: `PREFIX-limits`, `PREFIX-energy`, `PREFIX-stiff`
/// ([`plot::chart_path`]).
const CHARTS: [&str; 3] = ["limits", "energy", "stiff"];

fn optional(value: Option<f64>) -> String {
    value.map_or_else(|| "-".to_string(), |v| format!("{v:.4e}", v = num(v)))
}

fn write_limits(out: &mut String, test: &GrowthTest, limits: &Limits) {
    use std::fmt::Write as _;
    let _ = writeln!(
        out,
        "a. Stability limits: largest stable hω on x'' = −ω²x (imaginary axis) and hλ on x' = −λx (real axis)"
    );
    let _ = writeln!(
        out,
        "   theory: first crossing of |R| = 1 of R(z) = 1 + z bᵀ(I − zA)⁻¹𝟙 (explicit tableaus), of the trace 2 − (hω)² (partitioned);"
    );
    let _ = writeln!(
        out,
        "   measured: bisection (to {BISECTION_TOLERANCE:e} relative) on runs of N = {} constant steps, unstable when ‖y‖ grows beyond {GROWTH_THRESHOLD:e}.",
        test.steps,
        BISECTION_TOLERANCE = num(BISECTION_TOLERANCE),
        GROWTH_THRESHOLD = num(GROWTH_THRESHOLD)
    );
    let _ = writeln!(
        out,
        "   N detects a per-step growth δ ≥ {:.2e}; one percent above a limit the growth is δ₁ and needs N₁ = ln {GROWTH_THRESHOLD:e}/ln(1 + δ₁) steps.",
        num(test.smallest_detected_growth()),
        GROWTH_THRESHOLD = num(GROWTH_THRESHOLD)
    );
    let _ = writeln!(
        out,
        "   {:<18} {:<9} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9} {:>8}",
        "method", "axis", "theory", "measured", "rel. diff", "theory(N)", "rel. diff", "δ₁", "N₁"
    );
    let difference =
        |d: Option<f64>| d.map_or("-".to_string(), |d| format!("{d:+.2e}", d = num(d)));
    for r in &limits.rows {
        let _ = writeln!(
            out,
            "   {:<18} {:<9} {:>10.6} {:>10} {:>10} {:>10.6} {:>10} {:>9.2e} {:>8}{}",
            r.method,
            r.axis,
            r.theory,
            r.measured.map_or("-".to_string(), |m| format!("{m:.6}")),
            difference(r.relative_difference),
            r.theory_at_detection,
            difference(r.relative_difference_at_detection),
            num(r.growth_one_percent_above),
            r.steps_needed_one_percent_above,
            if r.steps_needed_one_percent_above > r.steps_used {
                "  N₁ > N: 1% not resolvable"
            } else {
                ""
            }
        );
    }
    let _ = writeln!(
        out,
        "   theory(N): first h where the per-step growth exceeds the detected {:.2e}, the limit N steps can see.",
        num(test.smallest_detected_growth())
    );
    let _ = writeln!(
        out,
        "   Per-step amplification (‖y_N‖/‖y₀‖)^(1/N), N = {AMPLIFICATION_STEPS}, on x'' = −ω²x: empty imaginary interval (euler, midpoint: |R(iy)| > 1 for all y > 0),\n   weak instability beyond the limit (N₁ > N), A-stable implicit methods"
    );
    let _ = writeln!(
        out,
        "   {:<18} {:>8} {:>14} {:>14} {:>11} {:>16}",
        "method", "hω", "measured", "|R(ihω)|", "rel. diff", "‖y‖ after 1000"
    );
    for r in &limits.amplification {
        let _ = writeln!(
            out,
            "   {:<18} {:>8.4} {:>14.10} {:>14.10} {:>+11.2e} {:>16}",
            r.method,
            r.h_omega,
            r.measured,
            r.theory,
            num(r.relative_difference),
            optional(r.norm_after_long_run)
        );
    }
    for m in &limits.explicit {
        let check = m.implementation_difference.map_or_else(
            || "read off one step of the implementation (tableau private)".to_string(),
            |d| {
                format!(
                    "tableau vs one step of the implementation: {d:.1e}",
                    d = num(d)
                )
            },
        );
        let _ = writeln!(
            out,
            "   {:<8} R of degree {:>2}, = eᶻ + O(z^{}); {check}",
            m.name,
            m.polynomial.degree(),
            m.polynomial.order() + 1
        );
    }
    let _ = writeln!(out);
}

fn write_energy(out: &mut String, periods: usize, rows: &[EnergyRow]) {
    use std::fmt::Write as _;
    let _ = writeln!(
        out,
        "b. Energy of x'' = −x from (1, 0) over {periods} periods (T = 2π)"
    );
    let _ = writeln!(
        out,
        "   {:<16} {:>8} {:>9} {:>13} {:>16} {:>16} {:>13} {:>11}",
        "method",
        "h",
        "periods",
        "final E/E₀",
        "log₁₀ final E/E₀",
        "theory (|R|²ⁿ)",
        "max |E/E₀−1|",
        "bound"
    );
    for r in rows {
        let _ = writeln!(
            out,
            "   {:<16} {:>8} {:>9.1} {:>13} {:>16.6} {:>16} {:>13} {:>11}",
            r.method,
            format!("T/{}", r.steps_per_period),
            r.periods_reached,
            r.final_energy_ratio
                .map_or("overflow".to_string(), |e| format!("{e:.6e}", e = num(e))),
            r.log10_final_energy_ratio,
            r.theory_log10_final_energy_ratio
                .map_or("-".to_string(), |e| format!("{e:.6}")),
            r.max_energy_error
                .map_or("overflow".to_string(), |e| format!("{e:.4e}", e = num(e))),
            optional(r.theory_max_energy_error)
        );
        if let Some(f) = &r.failure {
            let _ = writeln!(
                out,
                "   {:<16} failed: {} (last sample at t = {})",
                "",
                f.error,
                f.last_sample_t.map_or("-".to_string(), |t| t.to_string())
            );
        }
    }
    let _ = writeln!(
        out,
        "   theory: E/E₀ = |R(ih)|^(2n) after n steps (explicit Euler 1 + h² per step, RK4 below 1); Störmer–Verlet conserves (1 − h²/4)x² + ẋ²."
    );
    let _ = writeln!(out);
}

fn write_stiff(out: &mut String, args: &StabilityArgs, modes: &[StiffMode], rows: &[StiffRow]) {
    use std::fmt::Write as _;
    let _ = writeln!(
        out,
        "c. Stiff two-mass spring ({STIFF_MODEL}, k = (k/m)·m₁), 0 ≤ t ≤ {} s, rtol = atol = {:e}; errors at {STIFF_OUTPUT_TIMES} times against DOP853 at {STIFF_REFERENCE_TOL:e}",
        args.t_end,
        num(args.tol),
        STIFF_REFERENCE_TOL = num(STIFF_REFERENCE_TOL)
    );
    let _ = writeln!(
        out,
        "   From rest (the model's start) the step force excites the stiff mode: each mass oscillates about the slow motion with the amplitudes below,"
    );
    let _ = writeln!(
        out,
        "   to be compared with the tolerance; from the equilibrium start (spring pre-stretched by F₀m₁/(k(m₁+m₂))) the mode is not excited."
    );
    let _ = writeln!(
        out,
        "   {:>8} {:<12} {:>12} {:>14} {:>14} {:>11}",
        "k/m", "start", "ω (rad/s)", "x ampl. (m)", "ẋ ampl. (m/s)", "ref. steps"
    );
    for m in modes {
        let _ = writeln!(
            out,
            "   {:>8.0e} {:<12} {:>12.1} {:>14.2e} {:>14.2e} {:>11}",
            num(m.k_over_m),
            m.start,
            m.omega,
            num(m.position_amplitude),
            num(m.velocity_amplitude),
            m.reference_steps
        );
    }
    let _ = writeln!(
        out,
        "   {:>8} {:<12} {:<8} {:>9} {:>8} {:>10} {:>6} {:>6} {:>12} {:>12}",
        "k/m",
        "start",
        "method",
        "steps",
        "rejected",
        "RHS evals",
        "jac",
        "LU",
        "x error (m)",
        "ẋ error"
    );
    for r in rows {
        let _ = writeln!(
            out,
            "   {:>8.0e} {:<12} {:<8} {:>9} {:>8} {:>10} {:>6} {:>6} {:>12} {:>12}{}",
            num(r.k_over_m),
            r.start,
            r.method,
            r.steps,
            r.rejected,
            r.rhs_evals,
            r.jacobian_evals,
            r.lu_decompositions,
            optional(r.position_error),
            optional(r.velocity_error),
            r.failure
                .as_ref()
                .map_or(String::new(), |f| format!("  failed: {}", f.error))
        );
    }
    let _ = writeln!(out);
}

fn write_underflow(out: &mut String, run: &UnderflowRun) {
    use std::fmt::Write as _;
    let _ = writeln!(
        out,
        "d. Step-size underflow: {}, {} at rtol = atol = {:e}",
        run.problem,
        run.method,
        num(run.tol)
    );
    match &run.failure {
        Some(f) => {
            let _ = writeln!(out, "   error: {}", f.error);
            let time = |t: Option<f64>| t.map_or("-".to_string(), |t| t.to_string());
            let _ = writeln!(
                out,
                "   t = {}, last sample of the partial solution at t = {}",
                time(f.t),
                time(f.last_sample_t)
            );
        }
        None => {
            let _ = writeln!(out, "   the integration did not fail (unexpected)");
        }
    }
}

fn plot_limits(path: &str, methods: &mut [ExplicitMethod]) -> Result<(), CliError> {
    let grid: Vec<f64> = (1..=200).map(|i| 4.0 * i as f64 / 200.0).collect();
    let mut series = Vec::new();
    for m in methods.iter() {
        series.push(plot::Series {
            name: format!("{} |R(iy)|", m.name),
            points: grid
                .iter()
                .map(|&y| (y, m.polynomial.eval(Complex::new(0.0, y)).norm()))
                .collect(),
        });
    }
    for m in methods.iter_mut() {
        let steps: Vec<f64> = (1..=16).map(|i| 0.25 * f64::from(i)).collect();
        let points = m.measured_amplifications(&steps);
        series.push(plot::Series {
            name: format!("{} measured", m.name),
            points,
        });
    }
    log_y_chart(
        path,
        [
            "per-step amplification on x'' = −ω²x: |R(ihω)| and measured (stable where ≤ 1)",
            "hω",
            "amplification per step",
        ],
        false,
        &series,
    )
}

fn plot_energy(path: &str, rows: &[EnergyRow]) -> Result<(), CliError> {
    let series: Vec<plot::Series> = rows
        .iter()
        .map(|r| plot::Series {
            name: format!("{} h = T/{}", r.method, r.steps_per_period),
            points: r.history.clone(),
        })
        .collect();
    log_y_chart(
        path,
        [
            "energy of x'' = −x: explicit Euler grows, RK4 decays, Störmer–Verlet bounded (E/E₀ ≤ 1e200 drawn)",
            "t/T (periods)",
            "E/E₀",
        ],
        false,
        &series,
    )
}

fn plot_stiff(path: &str, rows: &[StiffRow]) -> Result<(), CliError> {
    let mut names: Vec<(&str, &str)> = Vec::new();
    for r in rows {
        if !names.contains(&(r.method, r.start)) {
            names.push((r.method, r.start));
        }
    }
    let series: Vec<plot::Series> = names
        .iter()
        .map(|&(name, start)| plot::Series {
            name: format!("{name} from {start}"),
            points: rows
                .iter()
                .filter(|r| r.method == name && r.start == start)
                .map(|r| (r.k_over_m, r.steps as f64))
                .collect(),
        })
        .collect();
    log_y_chart(
        path,
        [
            "stiff two-mass spring: accepted steps against k/m",
            "k/m (1/s²)",
            "steps",
        ],
        true,
        &series,
    )
}
