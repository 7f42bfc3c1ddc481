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

use std::f64::consts::PI;
use std::io::Write as _;

use clap::Args;
use eomgen::integrate::stability::{
    GrowthTest, StabilityPolynomial, TestEquation, amplification, explicit_tableau_methods,
    implicit_midpoint_stability, measured_limit, partitioned_oscillator_growth_limit,
    partitioned_oscillator_spectral_radius, radau_iia5_stability,
};
use eomgen::{
    BogackiShampine32, DormandPrince54, DormandPrince853, ExplicitEuler, ImplicitMidpoint,
    IntegrationFailure, Integrator, IntegratorOptions, OdeFn, OutputTimes, RadauIIA5, RungeKutta4,
    Solution, StormerVerlet, SymplecticEuler, Tableau,
};
use nalgebra::Complex;
use serde::Serialize;
use serde_json::json;

use super::{CliError, find_model, plot};

/// Options of `eomgen study stability`.
#[derive(Debug, Args)]
pub struct StabilityArgs {
    /// Constant steps of each run of the stability-limit bisection (part a).
    #[arg(long, default_value_t = 10_000)]
    pub steps: usize,
    /// Periods of the oscillator in the energy study (part b).
    #[arg(long, default_value_t = 10_000)]
    pub periods: usize,
    /// Stiffness ratios k/m (1/s²) of the stiff two-mass spring (part c), comma separated.
    #[arg(long, value_delimiter = ',', default_values_t = [1e2, 1e4, 1e6, 1e8])]
    pub stiffness: Vec<f64>,
    /// End time of the stiff runs (s).
    #[arg(long, default_value_t = 1.0)]
    pub t_end: f64,
    /// Relative and absolute tolerance of the stiff runs and of the underflow run.
    #[arg(long, default_value_t = 1e-6)]
    pub tol: f64,
    /// Print JSON instead of the tables.
    #[arg(long)]
    pub json: bool,
    /// Charts PREFIX-limits, PREFIX-energy and PREFIX-stiff (.svg, or .png if PREFIX ends in
    /// .png).
    #[arg(long, value_name = "PREFIX")]
    pub plot: Option<String>,
}

/// Growth of `‖y‖` that counts as unstable in the bisection: far above the bounded transient
/// of a stable non-normal step (symplectic Euler: `1/√(1 − hω/2)`, 100 at 10⁻⁴ below its
/// limit).
const GROWTH_THRESHOLD: f64 = 1e4;
/// Relative width of the final bisection bracket.
const BISECTION_TOLERANCE: f64 = 1e-6;
/// `hω` at which the per-step amplification of the methods with an empty imaginary interval
/// is measured.
const EMPTY_INTERVAL_STEPS: [f64; 4] = [0.1, 0.5, 1.0, 2.0];
/// Multiples of the imaginary limit at which a method too weakly unstable beyond it for the
/// bisection's `N` (Dormand–Prince 5(4)) is shown by its amplification.
const WEAK_INSTABILITY_FACTORS: [f64; 4] = [1.01, 1.2, 1.5, 2.0];
/// `hω` at which the A-stable methods are run.
const A_STABLE_STEPS: [f64; 3] = [10.0, 100.0, 1000.0];
/// Steps of each amplification run (`N` in `(‖y_N‖/‖y₀‖)^(1/N)`): few enough that Radau
/// IIA's amplitude (`≈ (3/hω)ᴺ`) stays above the `atol` of 1e-14 of its Newton iterations.
const AMPLIFICATION_STEPS: usize = 3;
/// Steps of the long run that shows the A-stable methods stable.
const LONG_RUN_STEPS: usize = 1000;
/// Steps per period in the energy study.
const STEPS_PER_PERIOD: usize = 32;
/// Number of output times of the stiff runs (uniform in `(0, t_end]`).
const STIFF_OUTPUT_TIMES: usize = 100;
/// Tolerance of the DOP853 reference of the stiff runs.
const STIFF_REFERENCE_TOL: f64 = 1e-12;

/// A stability interval, measured and in theory (part a).
#[derive(Debug, Serialize)]
struct LimitRow {
    method: &'static str,
    /// `"imaginary"` (`hω` on `ẍ = −ω²x`) or `"real"` (`hλ` on `ẋ = −λx`).
    axis: &'static str,
    theory: f64,
    measured: Option<f64>,
    relative_difference: Option<f64>,
    /// The limit a run of `steps_used` steps can see: the first `h` where the per-step growth
    /// exceeds the smallest detected one (theory, for this `N`).
    theory_at_detection: f64,
    relative_difference_at_detection: Option<f64>,
    /// Per-step growth `|R| − 1` one percent above the theoretical limit.
    growth_one_percent_above: f64,
    /// Steps needed to see that growth exceed the threshold.
    steps_needed_one_percent_above: usize,
    steps_used: usize,
}

/// A measured per-step amplification against `|R(ihω)|` (part a).
#[derive(Debug, Serialize)]
struct AmplificationRow {
    method: &'static str,
    h_omega: f64,
    steps: usize,
    measured: f64,
    theory: f64,
    relative_difference: f64,
    /// `‖y‖` after 1000 steps, from 1 (A-stable methods only).
    norm_after_long_run: Option<f64>,
}

/// Where an integration stopped early: the error as reported, its time, and the time of the
/// last sample recorded before it.
#[derive(Debug, Serialize)]
struct Failure {
    error: String,
    t: Option<f64>,
    last_sample_t: Option<f64>,
}

impl Failure {
    fn of(failure: &IntegrationFailure) -> Self {
        Self {
            error: failure.error.to_string(),
            t: failure.error.t(),
            last_sample_t: failure.partial.last().map(|(t, _)| t),
        }
    }
}

/// The energy of one run over many periods (part b).
#[derive(Debug, Serialize)]
struct EnergyRow {
    method: &'static str,
    h: f64,
    steps_per_period: usize,
    /// Periods reached (fewer than asked if the run failed).
    periods_reached: f64,
    /// `E/E₀` at the last sample (`None` if it overflows a double).
    final_energy_ratio: Option<f64>,
    /// `log₁₀(E/E₀)` at the last sample.
    log10_final_energy_ratio: f64,
    /// `log₁₀(E/E₀)` the stability function predicts there: `2n log₁₀|R(ih)|` after `n`
    /// steps (Runge–Kutta methods).
    theory_log10_final_energy_ratio: Option<f64>,
    /// Largest `|E/E₀ − 1|` over the samples (`None` if it overflows).
    max_energy_error: Option<f64>,
    /// The modified-energy bound on it (Störmer–Verlet: `(h²/4)/(1 − h²/4)`).
    theory_max_energy_error: Option<f64>,
    failure: Option<Failure>,
    #[serde(skip)]
    history: Vec<(f64, f64)>,
}

/// One method on the stiff spring at one `k/m` (part c).
#[derive(Debug, Serialize)]
struct StiffRow {
    k_over_m: f64,
    /// `"equilibrium"` (spring pre-stretched by the step force's static share: the stiff
    /// mode is not excited) or `"rest"` (the model's initial state, spring at rest length).
    start: &'static str,
    method: &'static str,
    steps: usize,
    rejected: usize,
    rhs_evals: usize,
    jacobian_evals: usize,
    lu_decompositions: usize,
    /// Largest position error (m) at the output times against the reference.
    position_error: Option<f64>,
    /// Largest velocity error (m/s) at the output times against the reference.
    velocity_error: Option<f64>,
    failure: Option<Failure>,
}

/// The stiff mode at one `k/m` (part c).
#[derive(Debug, Serialize)]
struct StiffMode {
    k_over_m: f64,
    start: &'static str,
    /// Its angular frequency `ω = √(k (m₁ + m₂)/(m₁ m₂))` (rad/s).
    omega: f64,
    /// Largest amplitude of a mass's oscillation about the slow motion (m): from rest with
    /// the spring at rest length, the static stretch `F₀ m₁/(k (m₁ + m₂))` times
    /// `max(m₁, m₂)/(m₁ + m₂)`; 0 from the equilibrium start.
    position_amplitude: f64,
    /// Its velocity amplitude `ω ·` that (m/s).
    velocity_amplitude: f64,
    reference_steps: usize,
}

/// The runs of part d.
#[derive(Debug, Serialize)]
struct UnderflowRun {
    problem: &'static str,
    method: &'static str,
    t_end: f64,
    tol: f64,
    failure: Option<Failure>,
}

fn usage_checks(args: &StabilityArgs) -> Result<(), CliError> {
    if !(100..=10_000_000).contains(&args.steps) {
        return Err(CliError::usage("--steps must be in [100, 10⁷]"));
    }
    if !(1..=1_000_000).contains(&args.periods) {
        return Err(CliError::usage("--periods must be in [1, 10⁶]"));
    }
    if args.stiffness.is_empty()
        || args
            .stiffness
            .iter()
            .any(|k| !(k.is_finite() && *k > 0.0 && *k <= 1e10))
    {
        return Err(CliError::usage(
            "--stiffness takes ratios k/m in (0, 1e10], comma separated",
        ));
    }
    if !(args.t_end.is_finite() && args.t_end > 0.0 && args.t_end <= 100.0) {
        return Err(CliError::usage("--t-end must be in (0, 100] s"));
    }
    if !(args.tol.is_finite() && args.tol >= 1e-13 && args.tol < 1.0) {
        return Err(CliError::usage("--tol must be in [1e-13, 1)"));
    }
    if let Some(prefix) = &args.plot
        && prefix.is_empty()
    {
        return Err(CliError::usage("--plot needs a file prefix"));
    }
    Ok(())
}

/// Runs `eomgen study stability`.
pub fn run(args: &StabilityArgs) -> Result<(), CliError> {
    usage_checks(args)?;
    let test = GrowthTest {
        steps: args.steps,
        threshold: GROWTH_THRESHOLD,
    };
    let mut limits = stability_limits(&test)?;
    let energy = energy_runs(args.periods);
    let (modes, stiff) = stiff_runs(args)?;
    let underflow = underflow_run(args.tol);

    if let Some(prefix) = &args.plot {
        plot_limits(&chart_path(prefix, "limits"), &mut limits.explicit)?;
        plot_energy(&chart_path(prefix, "energy"), &energy)?;
        plot_stiff(&chart_path(prefix, "stiff"), &stiff)?;
    }
    if args.json {
        let out = json!({
            "limits": {
                "growth_threshold": GROWTH_THRESHOLD,
                "steps": args.steps,
                "smallest_detected_growth": test.smallest_detected_growth(),
                "bisection_tolerance": BISECTION_TOLERANCE,
                "rows": limits.rows,
                "amplification": limits.amplification,
                "polynomials": limits.explicit.iter().map(|m| json!({
                    "method": m.name,
                    "coefficients": m.polynomial.coefficients(),
                    "order": m.polynomial.order(),
                    "implementation_difference": m.implementation_difference,
                })).collect::<Vec<_>>(),
            },
            "energy": {"periods": args.periods, "runs": energy},
            "stiff": {
                "model": "two_masses",
                "t_end": args.t_end,
                "tol": args.tol,
                "reference": {"method": "dop853", "tol": STIFF_REFERENCE_TOL},
                "modes": modes,
                "runs": stiff,
            },
            "underflow": underflow,
        });
        print_json(&out)?;
    } else {
        let mut text = String::new();
        write_limits(&mut text, &test, &limits);
        write_energy(&mut text, args.periods, &energy);
        write_stiff(&mut text, args, &modes, &stiff);
        write_underflow(&mut text, &underflow);
        let _ = write!(std::io::stdout().lock(), "{text}");
    }
    Ok(())
}

/// `PREFIX-name.svg`, or `.png` when the prefix ends in `.png` (a `.svg` ending is dropped).
fn chart_path(prefix: &str, name: &str) -> String {
    if let Some(stem) = prefix.strip_suffix(".png") {
        format!("{stem}-{name}.png")
    } else {
        let stem = prefix.strip_suffix(".svg").unwrap_or(prefix);
        format!("{stem}-{name}.svg")
    }
}

/// Draws `series` into `path` with a logarithmic y axis; `labels` are the title and the x and
/// y axis descriptions.
pub(super) fn log_y_chart(
    path: &str,
    labels: [&str; 3],
    log_x: bool,
    series: &[plot::Series],
) -> Result<(), CliError> {
    let [title, x_desc, y_desc] = labels;
    let chart = plot::Chart {
        title,
        x_desc,
        y_desc,
        log_x,
        log_y: true,
    };
    plot::lines(path, &chart, series).map_err(CliError::failure)
}

/// Prints `value` as pretty JSON on stdout.
pub(super) fn print_json(value: &serde_json::Value) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(value).map_err(|e| CliError::failure(e.to_string()))?;
    let _ = writeln!(std::io::stdout().lock(), "{text}");
    Ok(())
}

/// A stability function `R(z)`.
type StabilityFunction = fn(Complex<f64>) -> Complex<f64>;

/// An explicit method with its stability polynomial.
struct ExplicitMethod {
    name: &'static str,
    method: Box<dyn Integrator>,
    polynomial: StabilityPolynomial,
    /// Largest difference between the coefficients from the tableau and those read off one
    /// step of the implementation (`None` for DOP853, whose polynomial is the latter).
    implementation_difference: Option<f64>,
}

/// The explicit methods, their polynomials from their tableaus (DOP853's from one step of it,
/// its tableau being private), each checked against one step of its implementation.
fn explicit_methods() -> Result<Vec<ExplicitMethod>, CliError> {
    let failed =
        |e: IntegrationFailure| CliError::failure(format!("a polynomial step failed: {e}"));
    let mut methods = Vec::new();
    for (tableau, mut method) in explicit_tableau_methods() {
        let polynomial = StabilityPolynomial::of_tableau(&tableau);
        let stepped = StabilityPolynomial::of_method(method.as_mut(), tableau.num_stages())
            .map_err(failed)?;
        let difference = polynomial
            .coefficients()
            .iter()
            .zip(stepped.coefficients())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        methods.push(ExplicitMethod {
            name: method.name(),
            method,
            polynomial,
            implementation_difference: Some(difference),
        });
    }
    let mut dop853: Box<dyn Integrator> = Box::new(DormandPrince853::new());
    let polynomial = StabilityPolynomial::of_method(dop853.as_mut(), 12).map_err(failed)?;
    methods.push(ExplicitMethod {
        name: dop853.name(),
        method: dop853,
        polynomial,
        implementation_difference: None,
    });
    Ok(methods)
}

/// Everything part a measures.
struct Limits {
    explicit: Vec<ExplicitMethod>,
    rows: Vec<LimitRow>,
    amplification: Vec<AmplificationRow>,
}

/// The theoretical limits of one method on one axis: strict (`|R| ≤ 1`), at the test's
/// detection threshold, and the per-step growth one percent above the strict limit.
struct Theory {
    limit: f64,
    at_detection: f64,
    growth_one_percent_above: f64,
}

fn limit_row(
    method: &mut dyn Integrator,
    axis: &'static str,
    theory: Theory,
    test: &GrowthTest,
) -> Result<LimitRow, CliError> {
    let Theory {
        limit: theory,
        at_detection,
        growth_one_percent_above: growth,
    } = theory;
    let equation = if axis == "real" {
        TestEquation::Decay
    } else {
        TestEquation::Oscillator
    };
    let measured = measured_limit(method, equation, test, BISECTION_TOLERANCE).map_err(|e| {
        CliError::failure(format!(
            "{} failed on the test equation: {e}",
            method.name()
        ))
    })?;
    Ok(LimitRow {
        method: method.name(),
        axis,
        theory,
        measured,
        relative_difference: measured.map(|m| (m - theory) / theory),
        theory_at_detection: at_detection,
        relative_difference_at_detection: measured.map(|m| (m - at_detection) / at_detection),
        growth_one_percent_above: growth,
        steps_needed_one_percent_above: test.steps_to_detect(growth),
        steps_used: test.steps,
    })
}

fn amplification_row(
    method: &mut dyn Integrator,
    h_omega: f64,
    theory: f64,
    long_run: bool,
) -> Result<AmplificationRow, CliError> {
    let name = method.name();
    let failed =
        |e: IntegrationFailure| CliError::failure(format!("{name} at hω = {h_omega}: {e}"));
    let measured = amplification(
        method,
        TestEquation::Oscillator,
        h_omega,
        AMPLIFICATION_STEPS,
    )
    .map_err(failed)?;
    let norm_after_long_run = if long_run {
        Some(
            TestEquation::Oscillator
                .final_norm(method, h_omega, LONG_RUN_STEPS)
                .map_err(failed)?,
        )
    } else {
        None
    };
    Ok(AmplificationRow {
        norm_after_long_run,
        method: name,
        h_omega,
        steps: AMPLIFICATION_STEPS,
        measured,
        theory,
        relative_difference: (measured - theory) / theory,
    })
}

fn stability_limits(test: &GrowthTest) -> Result<Limits, CliError> {
    let mut explicit = explicit_methods()?;
    let mut rows = Vec::new();
    let mut amplification = Vec::new();
    let detected = test.smallest_detected_growth();
    for m in &mut explicit {
        let r = &m.polynomial;
        let imaginary = r.imaginary_axis_limit();
        if imaginary == 0.0 {
            for h in EMPTY_INTERVAL_STEPS {
                let theory = r.eval(Complex::new(0.0, h)).norm();
                amplification.push(amplification_row(m.method.as_mut(), h, theory, false)?);
            }
        } else {
            let growth = r.eval(Complex::new(0.0, 1.01 * imaginary)).norm() - 1.0;
            let theory = Theory {
                limit: imaginary,
                at_detection: r.imaginary_axis_growth_limit(detected),
                growth_one_percent_above: growth,
            };
            rows.push(limit_row(m.method.as_mut(), "imaginary", theory, test)?);
            if test.steps_to_detect(growth) > test.steps {
                // Too weakly unstable just beyond the limit for N steps to see: show the
                // growth there directly.
                for factor in WEAK_INSTABILITY_FACTORS {
                    let h = factor * imaginary;
                    let theory = r.eval(Complex::new(0.0, h)).norm();
                    amplification.push(amplification_row(m.method.as_mut(), h, theory, false)?);
                }
            }
        }
        let real = r.real_axis_limit();
        let theory = Theory {
            limit: real,
            at_detection: r.real_axis_growth_limit(detected),
            growth_one_percent_above: r.eval_real(-1.01 * real).abs() - 1.0,
        };
        rows.push(limit_row(m.method.as_mut(), "real", theory, test)?);
    }
    let partitioned: [Box<dyn Integrator>; 2] = [
        Box::new(SymplecticEuler::new()),
        Box::new(StormerVerlet::new()),
    ];
    for mut method in partitioned {
        let theory = Theory {
            limit: 2.0,
            at_detection: partitioned_oscillator_growth_limit(detected),
            growth_one_percent_above: partitioned_oscillator_spectral_radius(2.02) - 1.0,
        };
        rows.push(limit_row(method.as_mut(), "imaginary", theory, test)?);
    }
    let implicit: [(Box<dyn Integrator>, StabilityFunction); 2] = [
        // Its default Newton tolerance (1e-12 relative) is below the rounding of h·F at
        // h = 1000 (about 1000 ε), where Newton would report non-convergence.
        (
            Box::new(ImplicitMidpoint::new().with_newton_tolerance(1e-10)),
            implicit_midpoint_stability,
        ),
        (Box::new(RadauIIA5::new()), radau_iia5_stability),
    ];
    for (mut method, stability) in implicit {
        for h in A_STABLE_STEPS {
            let theory = stability(Complex::new(0.0, h)).norm();
            amplification.push(amplification_row(method.as_mut(), h, theory, true)?);
        }
    }
    Ok(Limits {
        explicit,
        rows,
        amplification,
    })
}

/// `E/E₀ = x² + ẋ²` of the oscillator `ẍ = −x` started at `(1, 0)`.
fn energy_ratio(y: &[f64]) -> f64 {
    y[0] * y[0] + y[1] * y[1]
}

fn energy_runs(periods: usize) -> Vec<EnergyRow> {
    let period = 2.0 * PI;
    let t_end = periods as f64 * period;
    // Explicit Euler a hundred times finer too, since with h = T/32 it overflows.
    let fine = 100 * STEPS_PER_PERIOD;
    let runs: [(Box<dyn Integrator>, usize); 4] = [
        (Box::new(ExplicitEuler::new()), STEPS_PER_PERIOD),
        (Box::new(ExplicitEuler::new()), fine),
        (Box::new(RungeKutta4::new()), STEPS_PER_PERIOD),
        (Box::new(StormerVerlet::new()), STEPS_PER_PERIOD),
    ];
    let rk4 = StabilityPolynomial::of_tableau(&Tableau::rk4());
    let euler = StabilityPolynomial::of_tableau(&Tableau::euler());
    runs.into_iter()
        .map(|(mut method, steps_per_period)| {
            let h_run = period / steps_per_period as f64;
            let options = IntegratorOptions::default()
                .with_dt(h_run)
                .with_max_steps(periods * steps_per_period + 10);
            // Every step of the coarse runs (the energy of Störmer–Verlet oscillates within a
            // period); once per period for the fine run (3.2 · 10⁷ steps).
            let output = if steps_per_period == STEPS_PER_PERIOD {
                OutputTimes::Steps
            } else {
                OutputTimes::At((0..=periods).map(|k| k as f64 * period).collect())
            };
            let mut oscillator = OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
                dy[0] = y[1];
                dy[1] = -y[0];
            });
            let (solution, failure) =
                match method.integrate(&mut oscillator, 0.0, &[1.0, 0.0], t_end, &output, &options)
                {
                    Ok(s) => (s, None),
                    Err(f) => {
                        let failure = Failure::of(&f);
                        (*f.partial, Some(failure))
                    }
                };
            energy_row(method.name(), h_run, &solution, failure, &rk4, &euler)
        })
        .collect()
}

fn energy_row(
    method: &'static str,
    h: f64,
    solution: &Solution,
    failure: Option<Failure>,
    rk4: &StabilityPolynomial,
    euler: &StabilityPolynomial,
) -> EnergyRow {
    let period = 2.0 * PI;
    let steps_per_period = (period / h).round() as usize;
    let (t_last, y_last) = solution.last().unwrap_or((0.0, &[1.0, 0.0][..]));
    let steps_done = (t_last / h).round();
    let log_amplitude = |r: &StabilityPolynomial| r.eval(Complex::new(0.0, h)).norm().log10();
    let theory_log10_final_energy_ratio = match method {
        "euler" => Some(2.0 * steps_done * log_amplitude(euler)),
        "rk4" => Some(2.0 * steps_done * log_amplitude(rk4)),
        _ => None,
    };
    let theory_max_energy_error =
        (method == "stormer-verlet").then(|| (h * h / 4.0) / (1.0 - h * h / 4.0));
    let max_energy_error = solution
        .iter()
        .map(|(_, y)| (energy_ratio(y) - 1.0).abs())
        .fold(0.0, f64::max);
    let stride = if solution.len() > 1 && solution.t[1] < 0.99 * period {
        steps_per_period
    } else {
        1
    };
    // E/E₀ above 1e200 is left out of the chart (its axis padding would overflow).
    let history = solution
        .iter()
        .step_by(stride)
        .map(|(t, y)| (t / period, energy_ratio(y)))
        .filter(|(_, e)| *e <= 1e200)
        .collect();
    let final_energy_ratio = energy_ratio(y_last);
    EnergyRow {
        method,
        h,
        steps_per_period,
        periods_reached: t_last / period,
        final_energy_ratio: final_energy_ratio.is_finite().then_some(final_energy_ratio),
        log10_final_energy_ratio: 2.0 * y_last[0].hypot(y_last[1]).log10(),
        theory_log10_final_energy_ratio,
        max_energy_error: max_energy_error.is_finite().then_some(max_energy_error),
        theory_max_energy_error,
        failure,
        history,
    }
}

/// The stiff two-mass spring at every `k/m`: the mode's figures and every method's run.
fn stiff_runs(args: &StabilityArgs) -> Result<(Vec<StiffMode>, Vec<StiffRow>), CliError> {
    let times: Vec<f64> = (1..=STIFF_OUTPUT_TIMES)
        .map(|i| args.t_end * i as f64 / STIFF_OUTPUT_TIMES as f64)
        .collect();
    let output = OutputTimes::At(times);
    let mut modes = Vec::new();
    let mut rows = Vec::new();
    for &ratio in &args.stiffness {
        let mut model = find_model("two_masses")?;
        let parameter = |name: &str| {
            model
                .parameter_names()
                .iter()
                .position(|p| *p == name)
                .map(|i| model.parameter_values()[i])
                .ok_or_else(|| CliError::failure(format!("two_masses has no parameter `{name}`")))
        };
        let (m1, m2, force) = (parameter("m1")?, parameter("m2")?, parameter("F0")?);
        model
            .set_parameter("k", ratio * m1)
            .map_err(|e| CliError::failure(e.to_string()))?;
        let k = ratio * m1;
        let omega = (k * (m1 + m2) / (m1 * m2)).sqrt();
        let static_stretch = force * m1 / (k * (m1 + m2));
        let x2 = model
            .coordinate_names()
            .iter()
            .position(|c| *c == "x2")
            .ok_or_else(|| CliError::failure("two_masses has no coordinate `x2`"))?;
        for start in ["equilibrium", "rest"] {
            let mut y0 = model.initial_state();
            let position_amplitude = if start == "equilibrium" {
                y0[x2] += static_stretch;
                0.0
            } else {
                static_stretch * m1.max(m2) / (m1 + m2)
            };
            let run = |method: &mut dyn Integrator,
                       model: &mut dyn eomgen::ModelInfo,
                       tol: f64|
             -> Result<Solution, IntegrationFailure> {
                let options = IntegratorOptions::default()
                    .with_rtol(tol)
                    .with_atol(tol)
                    .with_max_steps(20_000_000);
                method.integrate(model.as_ode_mut(), 0.0, &y0, args.t_end, &output, &options)
            };
            let reference = run(
                &mut DormandPrince853::new(),
                model.as_mut(),
                STIFF_REFERENCE_TOL,
            )
            .map_err(|e| {
                CliError::failure(format!(
                    "the DOP853 reference at k/m = {ratio:e} from {start} failed: {e}"
                ))
            })?;
            modes.push(StiffMode {
                k_over_m: ratio,
                start,
                omega,
                position_amplitude,
                velocity_amplitude: omega * position_amplitude,
                reference_steps: reference.stats.steps,
            });
            let methods: [Box<dyn Integrator>; 4] = [
                Box::new(BogackiShampine32::new()),
                Box::new(DormandPrince54::new()),
                Box::new(DormandPrince853::new()),
                Box::new(RadauIIA5::new()),
            ];
            for mut method in methods {
                let (solution, failure) = match run(method.as_mut(), model.as_mut(), args.tol) {
                    Ok(s) => (s, None),
                    Err(f) => {
                        let failure = Failure::of(&f);
                        (*f.partial, Some(failure))
                    }
                };
                let error = |offset: usize| {
                    failure.is_none().then(|| {
                        solution
                            .iter()
                            .zip(reference.iter())
                            .flat_map(|((_, y), (_, r))| {
                                (offset..offset + 2).map(move |i| (y[i] - r[i]).abs())
                            })
                            .fold(0.0, f64::max)
                    })
                };
                rows.push(StiffRow {
                    k_over_m: ratio,
                    start,
                    method: method.name(),
                    steps: solution.stats.steps,
                    rejected: solution.stats.rejected,
                    rhs_evals: solution.stats.rhs_evals,
                    jacobian_evals: solution.stats.jacobian_evals,
                    lu_decompositions: solution.stats.lu_decompositions,
                    position_error: error(0),
                    velocity_error: error(2),
                    failure,
                });
            }
        }
    }
    Ok((modes, rows))
}

/// `ẏ = y²`, `y(0) = 1` (`y = 1/(1 − t)`, infinite at `t = 1`) asked for on `[0, 2]` with
/// Dormand–Prince 5(4): the step size must shrink to nothing at the singularity.
fn underflow_run(tol: f64) -> UnderflowRun {
    let mut blow_up = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = y[0] * y[0]);
    let options = IntegratorOptions::default().with_rtol(tol).with_atol(tol);
    let mut method = DormandPrince54::new();
    let result = method.integrate(
        &mut blow_up,
        0.0,
        &[1.0],
        2.0,
        &OutputTimes::Steps,
        &options,
    );
    UnderflowRun {
        problem: "y' = y², y(0) = 1 on [0, 2] (y = 1/(1 − t) blows up at t = 1)",
        method: method.name(),
        t_end: 2.0,
        tol,
        failure: result.err().as_ref().map(Failure::of),
    }
}

fn optional(value: Option<f64>) -> String {
    value.map_or_else(|| "-".to_string(), |v| format!("{v:.4e}"))
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
        test.steps
    );
    let _ = writeln!(
        out,
        "   N detects a per-step growth δ ≥ {:.2e}; one percent above a limit the growth is δ₁ and needs N₁ = ln {GROWTH_THRESHOLD:e}/ln(1 + δ₁) steps.",
        test.smallest_detected_growth()
    );
    let _ = writeln!(
        out,
        "   {:<18} {:<9} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9} {:>8}",
        "method", "axis", "theory", "measured", "rel. diff", "theory(N)", "rel. diff", "δ₁", "N₁"
    );
    let difference = |d: Option<f64>| d.map_or("-".to_string(), |d| format!("{d:+.2e}"));
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
            r.growth_one_percent_above,
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
        test.smallest_detected_growth()
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
            r.relative_difference,
            optional(r.norm_after_long_run)
        );
    }
    for m in &limits.explicit {
        let check = m.implementation_difference.map_or_else(
            || "read off one step of the implementation (tableau private)".to_string(),
            |d| format!("tableau vs one step of the implementation: {d:.1e}"),
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
                .map_or("overflow".to_string(), |e| format!("{e:.6e}")),
            r.log10_final_energy_ratio,
            r.theory_log10_final_energy_ratio
                .map_or("-".to_string(), |e| format!("{e:.6}")),
            r.max_energy_error
                .map_or("overflow".to_string(), |e| format!("{e:.4e}")),
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
        "c. Stiff two-mass spring (two_masses, k = (k/m)·m₁), 0 ≤ t ≤ {} s, rtol = atol = {:e}; errors at {STIFF_OUTPUT_TIMES} times against DOP853 at {STIFF_REFERENCE_TOL:e}",
        args.t_end, args.tol
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
            m.k_over_m,
            m.start,
            m.omega,
            m.position_amplitude,
            m.velocity_amplitude,
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
            r.k_over_m,
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
        run.problem, run.method, run.tol
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
        let points = (1..=16)
            .filter_map(|i| {
                let h = 0.25 * i as f64;
                amplification(m.method.as_mut(), TestEquation::Oscillator, h, 10)
                    .ok()
                    .map(|a| (h, a))
            })
            .collect();
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
