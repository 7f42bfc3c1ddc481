//! `eomgen study work-precision MODEL` (issue 6): error against work for every integration
//! method on a model.
//!
//! Every method runs at a sequence of tolerances (adaptive methods, `rtol = atol = tol`) or
//! step sizes `h = T/N` (fixed-step methods). Each run's state at `S` equally spaced output
//! times (dense output, [`OutputTimes::At`]) is compared with a reference solution computed
//! by DOP853 at a far tighter tolerance and accepted only if a second, different method
//! (Dormand–Prince 5(4)) at the same tolerance agrees with it far below the target error.
//!
//! The error of a run is
//!
//! ```text
//! error = max over k = 1…S, i = 1…2n of |yᵢ(t_k) − y_refᵢ(t_k)|,   t_k = k T / S,
//! ```
//!
//! the largest absolute deviation over the output times and over *all* state components,
//! the coordinates `q` and the rates `q̇` alike (each in its own unit: m or rad, m/s or
//! rad/s). Work is the RHS evaluations and steps of [`Stats`](eomgen::Stats), and the
//! median wall time of repeated identical runs (one short run is too noisy to time). The
//! work needed to reach a target error is interpolated log–log between the two settings
//! whose errors bracket it.
//!
//! References: E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations
//! I*, 2nd ed., Springer, 1993, §II.10 (work–precision diagrams of the kind drawn here);
//! the MuJoCo anchor of issue 6 (RK4 at `dt = 1e-3`: about 60 ms for 10 s of the double
//! pendulum at a state error of about 5e-4).

use std::io::Write;

use clap::Args;
use eomgen::{IntegrationFailure, Integrator, IntegratorOptions, ModelInfo, OutputTimes, Solution};
use serde_json::json;

use super::simulate::{Method, consistent_initial_state};
use eomgen::analysis::energy_drift;
use super::{CliError, find_model, plot};

/// The methods compared when `--methods` is not given: every adaptive method, and the
/// fixed-step RK4 and Störmer–Verlet.
const DEFAULT_METHODS: [Method; 6] = [
    Method::Bs32,
    Method::Dp54,
    Method::Dop853,
    Method::Radau5,
    Method::Rk4,
    Method::StormerVerlet,
];

/// Most step attempts of one adaptive run; far more than any default setting needs, small
/// enough that a method that cannot cope fails in seconds rather than minutes.
const MAX_STEPS: usize = 5_000_000;

/// Most timed repetitions of one setting, whatever `--min-time-ms` asks.
const MAX_REPEATS: usize = 1000;

/// Options of `eomgen study work-precision MODEL`.
#[derive(Debug, Args)]
pub struct WorkPrecisionArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any model file.
    pub model: String,
    /// Methods to compare, comma separated (default: bs32, dp54, dop853, radau5, rk4,
    /// stormer-verlet).
    #[arg(long, value_parser = super::simulate::method_parser(), value_delimiter = ',', default_values_t = DEFAULT_METHODS)]
    pub methods: Vec<Method>,
    /// Tolerances of the adaptive methods (`rtol = atol = tol`): `A..B`, every decade from A
    /// to B (e.g. `1e-3..1e-12`), or a comma-separated list; each in (0, 1).
    #[arg(long, default_value = "1e-3..1e-12", allow_hyphen_values = true)]
    pub tols: String,
    /// Step counts N of the fixed-step methods (step `h = t_end / N`): `A..B`, doubling from
    /// A up to B (e.g. `64..65536`), or a comma-separated list of positive integers. Default
    /// by the method's order p, to span a comparable range of errors: `64..65536` for p ≥ 3,
    /// `256..4194304` for p = 2, `1024..4194304` for p = 1.
    #[arg(long)]
    pub steps: Option<String>,
    /// End time T (s).
    #[arg(long, default_value_t = 10.0)]
    pub t_end: f64,
    /// Number S of equally spaced output times `k T / S`, k = 1…S, at which errors are taken.
    #[arg(long, default_value_t = 100)]
    pub samples: usize,
    /// Error at which the work of every method is interpolated (same norm as the table).
    #[arg(long, default_value_t = 5e-4)]
    pub target_error: f64,
    /// A wall time (ms) to compare the time at the target error with (issue 6's anchor:
    /// `--baseline-ms 60`, MuJoCo's RK4 on the double pendulum over 10 s).
    #[arg(long, value_name = "MS")]
    pub baseline_ms: Option<f64>,
    /// Tolerance of the reference solution (DOP853, and Dormand–Prince 5(4) as its check).
    #[arg(long, default_value_t = 1e-14)]
    pub reference_tol: f64,
    /// Fewest timed runs per setting; the reported time is their median.
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,
    /// Runs of one setting are repeated until their total wall time reaches this (ms), at
    /// most 1000 times.
    #[arg(long, default_value_t = 20.0)]
    pub min_time_ms: f64,
    /// Print JSON instead of the tables.
    #[arg(long)]
    pub json: bool,
    /// Write the charts `PREFIX-evals.svg/.png` (error against RHS evaluations) and
    /// `PREFIX-time.svg/.png` (error against wall time), log–log, one line per method.
    #[arg(long, value_name = "PREFIX")]
    pub plot: Option<String>,
}

/// How one run is set up: a tolerance for an adaptive method, a step count for a fixed-step
/// one.
#[derive(Debug, Clone, Copy)]
enum Setting {
    /// `rtol = atol = tol`.
    Tolerance(f64),
    /// `steps` constant steps `h = T / steps`.
    Steps { steps: usize, dt: f64 },
}

impl Setting {
    fn options(self) -> IntegratorOptions {
        let options = IntegratorOptions::default();
        match self {
            Setting::Tolerance(tol) => options
                .with_rtol(tol)
                .with_atol(tol)
                .with_max_steps(MAX_STEPS),
            // Room for the requested steps and a rounding-shortened last one.
            Setting::Steps { steps, dt } => options.with_dt(dt).with_max_steps(steps + 2),
        }
    }

    fn label(self) -> String {
        match self {
            Setting::Tolerance(tol) => format!("tol {tol:.0e}"),
            Setting::Steps { dt, .. } => format!("h {dt:.3e}"),
        }
    }
}

/// What one successful setting measured.
struct Measured {
    /// The study's error norm against the reference (see the module docs).
    error: f64,
    rhs_evals: usize,
    steps: usize,
    rejected: usize,
    /// Jacobians `∂F/∂y` and LU factorisations of the implicit methods (0 for explicit ones).
    jacobian_evals: usize,
    lu_decompositions: usize,
    /// Median over `repeats` identical runs (s).
    wall_time_s: f64,
    repeats: usize,
    /// `max |E − E(0)| / max(T + |V|)` over the output times, as `simulate` reports it.
    energy_drift: Option<f64>,
}

/// A measure of work of a run: RHS evaluations, steps or wall time.
type Work = fn(&Measured) -> f64;

/// One setting of one method.
struct Run {
    setting: Setting,
    outcome: Result<Measured, Failure>,
}

/// A run that stopped: where and why.
struct Failure {
    t: Option<f64>,
    message: String,
}

/// Every setting of one method, and its work at the target error.
struct MethodRuns {
    method: Method,
    runs: Vec<Run>,
    at_target: AtTarget,
}

/// The work interpolated at the target error, or why there is none.
enum AtTarget {
    /// Two consecutive settings bracket the target: RHS evaluations, steps and time (s).
    Reached {
        rhs_evals: f64,
        steps: f64,
        wall_time_s: f64,
    },
    /// Already below the target at the loosest setting: at most this work.
    BelowAtLoosest { rhs_evals: usize, wall_time_s: f64 },
    /// No pair of consecutive settings brackets the target.
    NotReached,
}

/// Parses `--tols`: `A..B` (every decade from A towards B, either direction) or a comma list.
/// Returned loosest first, without repeats.
///
/// # Errors
/// A usage error naming the bad entry; every tolerance must be finite and in (0, 1).
fn parse_tols(text: &str) -> Result<Vec<f64>, CliError> {
    let bad = |what: &str| {
        CliError::usage(format!(
            "--tols `{text}`: {what}; write a range of decades like `1e-3..1e-12` or a list like `1e-4,1e-6,1e-8`"
        ))
    };
    let number = |s: &str| -> Result<f64, CliError> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| bad(&format!("`{}` is not a number", s.trim())))?;
        if v.is_finite() && v > 0.0 && v < 1.0 {
            Ok(v)
        } else {
            Err(bad(&format!("{v} is not a tolerance in (0, 1)")))
        }
    };
    let mut tols = if let Some((a, b)) = text.split_once("..") {
        let (a, b) = (number(a)?, number(b)?);
        let (hi, lo) = (a.max(b), a.min(b));
        // Decades from the loosest end down to the tightest, the products computed from the
        // exponent so that `1e-3..1e-12` gives exactly 1e-3, 1e-4, …, 1e-12.
        let decades = (hi / lo).log10().round() as i32;
        if ((hi / lo).log10() - f64::from(decades)).abs() > 1e-9 {
            return Err(bad(
                "the two ends of a range must be a whole number of decades apart",
            ));
        }
        (0..=decades)
            .map(|k| {
                let exponent = hi.log10() - f64::from(k);
                if (exponent - exponent.round()).abs() < 1e-9 {
                    10f64.powi(exponent.round() as i32)
                } else {
                    hi / 10f64.powi(k)
                }
            })
            .collect()
    } else {
        text.split(',').map(number).collect::<Result<Vec<_>, _>>()?
    };
    tols.sort_by(|a, b| b.total_cmp(a));
    tols.dedup();
    Ok(tols)
}

/// Parses `--steps`: `A..B` (A, 2A, 4A, … up to B) or a comma list of step counts. Returned
/// in increasing order (largest step first), without repeats.
///
/// # Errors
/// A usage error naming the bad entry; every count must be a positive integer, at most 10⁸.
fn parse_steps(text: &str) -> Result<Vec<usize>, CliError> {
    let bad = |what: &str| {
        CliError::usage(format!(
            "--steps `{text}`: {what}; write a doubling range of step counts like `64..65536` or a list like `100,1000,10000`"
        ))
    };
    let number = |s: &str| -> Result<usize, CliError> {
        match s.trim().parse::<usize>() {
            Ok(n) if (1..=100_000_000).contains(&n) => Ok(n),
            _ => Err(bad(&format!(
                "`{}` is not a step count from 1 to 10⁸",
                s.trim()
            ))),
        }
    };
    let mut steps = if let Some((a, b)) = text.split_once("..") {
        let (a, b) = (number(a)?, number(b)?);
        let (lo, hi) = (a.min(b), a.max(b));
        std::iter::successors(Some(lo), |n| Some(n * 2).filter(|m| *m <= hi)).collect()
    } else {
        text.split(',').map(number).collect::<Result<Vec<_>, _>>()?
    };
    steps.sort_unstable();
    steps.dedup();
    Ok(steps)
}

/// The default step counts of a fixed-step method of order `order`: doublings over ranges
/// chosen so that first- and second-order methods reach errors comparable to the
/// higher-order ones (their errors fall by only 2× or 4× per doubling).
fn default_steps(order: u32) -> Vec<usize> {
    let (lo, hi) = match order {
        0 | 1 => (10, 22),
        2 => (8, 22),
        _ => (6, 16),
    };
    (lo..=hi).map(|k| 1usize << k).collect()
}

/// The study's error norm: the largest `|yᵢ − y_refᵢ|` over every sample and component.
fn state_error(solution: &Solution, reference: &Solution) -> f64 {
    solution
        .y
        .iter()
        .zip(&reference.y)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// Timing rule of the study: at least `repeats` runs, and more until they total
/// `min_time_s`, at most [`MAX_REPEATS`].
#[derive(Debug, Clone, Copy)]
struct Timing {
    repeats: usize,
    min_time_s: f64,
}

/// The median of `values` (not empty).
fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let mid = values.len() / 2;
    if values.len() % 2 == 1 {
        values[mid]
    } else {
        0.5 * (values[mid - 1] + values[mid])
    }
}

/// Problem shared by every run: the model, its initial state, the interval and the output
/// times.
struct Problem {
    model: Box<dyn ModelInfo>,
    y0: Vec<f64>,
    t_end: f64,
    times: OutputTimes,
}

impl Problem {
    /// Integrates the model once from `y0` over `[0, t_end]`, sampled at the output times.
    fn solve(
        &mut self,
        integrator: &mut dyn Integrator,
        options: &IntegratorOptions,
    ) -> Result<Solution, Failure> {
        integrator
            .integrate(
                self.model.as_ode_mut(),
                0.0,
                &self.y0,
                self.t_end,
                &self.times,
                options,
            )
            .map_err(|IntegrationFailure { error, .. }| Failure {
                t: error.t(),
                message: error.to_string(),
            })
    }

    /// Runs `method` at `setting`: the error against `reference` and the work of its first
    /// run, the median time of `timing`'s repetitions.
    fn run(
        &mut self,
        method: Method,
        setting: Setting,
        timing: Timing,
        reference: &Solution,
    ) -> Run {
        let options = setting.options();
        let mut integrator = method.integrator();
        let first = self.solve(integrator.as_mut(), &options);
        let outcome = first.map(|solution| {
            let mut times = vec![solution.stats.wall_time_s];
            while times.len() < timing.repeats.max(1)
                || (times.iter().sum::<f64>() < timing.min_time_s && times.len() < MAX_REPEATS)
            {
                // The runs are identical (deterministic steps); only the clock differs.
                match self.solve(integrator.as_mut(), &options) {
                    Ok(again) => times.push(again.stats.wall_time_s),
                    Err(_) => break,
                }
            }
            let report = energy_drift(self.model.as_ref(), &self.y0, &solution);
            Measured {
                error: state_error(&solution, reference),
                rhs_evals: solution.stats.rhs_evals,
                steps: solution.stats.steps,
                rejected: solution.stats.rejected,
                jacobian_evals: solution.stats.jacobian_evals,
                lu_decompositions: solution.stats.lu_decompositions,
                repeats: times.len(),
                wall_time_s: median(&mut times),
                energy_drift: report.drift.filter(|d| d.is_finite()),
            }
        });
        Run { setting, outcome }
    }
}

/// Interpolates `log work` linearly in `log error` between the first two consecutive
/// points (loosest first) whose errors bracket `target`.
fn interpolate(points: &[(f64, f64)], target: f64) -> Option<f64> {
    points.windows(2).find_map(|pair| {
        let [(e0, w0), (e1, w1)] = [pair[0], pair[1]];
        if !(e0 > 0.0 && e1 > 0.0 && w0 > 0.0 && w1 > 0.0) {
            return None;
        }
        let (lo, hi) = (e0.min(e1), e0.max(e1));
        if !(lo <= target && target <= hi) {
            return None;
        }
        if hi == lo {
            return Some(w0.min(w1));
        }
        let s = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
        Some((w0.ln() + s * (w1.ln() - w0.ln())).exp())
    })
}

/// The work of `runs` (loosest first) at `target`; a failed run breaks the bracketing.
fn at_target(runs: &[Run], target: f64) -> AtTarget {
    let measured: Vec<Option<&Measured>> = runs.iter().map(|r| r.outcome.as_ref().ok()).collect();
    if let Some(Some(first)) = measured.first()
        && first.error < target
    {
        return AtTarget::BelowAtLoosest {
            rhs_evals: first.rhs_evals,
            wall_time_s: first.wall_time_s,
        };
    }
    let series = |work: Work| -> Vec<(f64, f64)> {
        measured
            .iter()
            .map(|m| m.map_or((f64::NAN, f64::NAN), |m| (m.error, work(m))))
            .collect()
    };
    let evals = interpolate(&series(|m| m.rhs_evals as f64), target);
    let steps = interpolate(&series(|m| m.steps as f64), target);
    let time = interpolate(&series(|m| m.wall_time_s), target);
    match (evals, steps, time) {
        (Some(rhs_evals), Some(steps), Some(wall_time_s)) => AtTarget::Reached {
            rhs_evals,
            steps,
            wall_time_s,
        },
        _ => AtTarget::NotReached,
    }
}

/// A finite number as JSON, anything else as `null`.
fn finite(x: f64) -> serde_json::Value {
    if x.is_finite() { json!(x) } else { json!(null) }
}

/// Runs `eomgen study work-precision MODEL`.
///
/// # Errors
/// Usage errors (exit 2) for a bad `--tols`, `--steps`, `--t-end`, `--samples`,
/// `--target-error`, `--reference-tol`, `--baseline-ms` or `--min-time-ms`; failures (exit 1)
/// when the reference cannot be computed or its check does not agree with it far below the
/// target error (`agreement > target_error / 100`), or a chart cannot be written. A method
/// that fails at a setting is reported in its row, never an error of the study.
pub fn run(args: &WorkPrecisionArgs) -> Result<(), CliError> {
    let positive = |x: f64| x.is_finite() && x > 0.0;
    if !positive(args.t_end) {
        return Err(CliError::usage(format!(
            "--t-end must be a positive number of seconds, got {}",
            args.t_end
        )));
    }
    if args.samples == 0 {
        return Err(CliError::usage("--samples must be at least 1"));
    }
    if !positive(args.target_error) {
        return Err(CliError::usage(format!(
            "--target-error must be positive, got {}",
            args.target_error
        )));
    }
    if !(positive(args.reference_tol) && args.reference_tol < 1e-6) {
        return Err(CliError::usage(format!(
            "--reference-tol must be in (0, 1e-6), far tighter than the tolerances studied, got {}",
            args.reference_tol
        )));
    }
    if let Some(b) = args.baseline_ms
        && !positive(b)
    {
        return Err(CliError::usage(format!(
            "--baseline-ms must be positive, got {b}"
        )));
    }
    if !(args.min_time_ms.is_finite() && args.min_time_ms >= 0.0) {
        return Err(CliError::usage(format!(
            "--min-time-ms must be ≥ 0, got {}",
            args.min_time_ms
        )));
    }
    let tols = parse_tols(&args.tols)?;
    let step_counts = args.steps.as_deref().map(parse_steps).transpose()?;
    let mut methods: Vec<Method> = Vec::with_capacity(args.methods.len());
    for &m in &args.methods {
        if !methods.contains(&m) {
            methods.push(m);
        }
    }

    let mut model = find_model(&args.model)?;
    let mut y0 = model.initial_state();
    consistent_initial_state(model.as_mut(), &mut y0)?;
    let times = OutputTimes::At(
        (1..=args.samples)
            .map(|k| args.t_end * k as f64 / args.samples as f64)
            .collect(),
    );

    // The reference, DOP853 at `reference_tol`, accepted only if Dormand–Prince 5(4) at the
    // same tolerance (another tableau, error estimator and dense output) agrees with it far
    // below the target error.
    let reference_options = IntegratorOptions::default()
        .with_rtol(args.reference_tol)
        .with_atol(args.reference_tol)
        .with_max_steps(MAX_STEPS);
    let mut problem = Problem {
        model,
        y0,
        t_end: args.t_end,
        times,
    };
    let mut solve = |method: Method, role: &str| {
        problem
            .solve(method.integrator().as_mut(), &reference_options)
            .map_err(|f| {
                CliError::failure(format!(
                    "{role} ({} at rtol = atol = {:e}) failed: {}; try a looser --reference-tol or a shorter --t-end",
                    method.display_name(),
                    args.reference_tol,
                    f.message
                ))
            })
    };
    let reference = solve(Method::Dop853, "the reference solution")?;
    let check = solve(Method::Dp54, "the check of the reference")?;
    let agreement = state_error(&check, &reference);
    if agreement.is_nan() || agreement > args.target_error / 100.0 {
        return Err(CliError::failure(format!(
            "the reference is not verified: DOP853 and Dormand–Prince 5(4) at rtol = atol = {:e} differ by {agreement:.3e}, not far below the target error {:e} (need ≤ 1/100 of it); try a shorter --t-end, a larger --target-error or another --reference-tol",
            args.reference_tol, args.target_error
        )));
    }
    let reference_steps = reference.stats.steps;

    let timing = Timing {
        repeats: args.repeats.max(1),
        min_time_s: args.min_time_ms * 1e-3,
    };
    let results: Vec<MethodRuns> = methods
        .iter()
        .map(|&method| {
            let settings: Vec<Setting> = if method.is_adaptive() {
                tols.iter().map(|&tol| Setting::Tolerance(tol)).collect()
            } else {
                step_counts
                    .clone()
                    .unwrap_or_else(|| default_steps(method.integrator().order()))
                    .into_iter()
                    .map(|steps| Setting::Steps {
                        steps,
                        dt: args.t_end / steps as f64,
                    })
                    .collect()
            };
            let runs: Vec<Run> = settings
                .into_iter()
                .map(|s| problem.run(method, s, timing, &reference))
                .collect();
            let at_target = at_target(&runs, args.target_error);
            MethodRuns {
                method,
                runs,
                at_target,
            }
        })
        .collect();

    let study = Study {
        args,
        model: problem.model.as_ref(),
        dim: problem.y0.len(),
        agreement,
        reference_steps,
        timing,
        results,
    };
    let num_unresolved = study
        .results
        .iter()
        .flat_map(|r| &r.runs)
        .filter(|r| r.outcome.as_ref().is_ok_and(|m| study.unresolved(m)))
        .count();
    if num_unresolved > 0 {
        eprintln!(
            "warning: {num_unresolved} run(s) have an error below 10 × the reference's agreement ({agreement:.2e}): the reference does not resolve them, their errors are upper bounds at best (marked `!` in the table, `\"resolved\": false` in JSON)"
        );
    }
    if let Some(prefix) = &args.plot {
        write_charts(prefix, study.model.name(), &study.results)?;
    }
    let mut stdout = std::io::stdout().lock();
    // A closed stdout (a pipe into `head`) is not an error of the study.
    let _ = if args.json {
        serde_json::to_string_pretty(&study.to_json())
            .map_err(|e| CliError::failure(e.to_string()))
            .map(|text| writeln!(stdout, "{text}"))?
    } else {
        study.write_text(&mut stdout)
    };
    Ok(())
}

/// Everything the study measured, for the table and the JSON.
struct Study<'a> {
    args: &'a WorkPrecisionArgs,
    model: &'a dyn ModelInfo,
    /// State dimension `2n`.
    dim: usize,
    /// The study's error norm between the reference and its check.
    agreement: f64,
    reference_steps: usize,
    timing: Timing,
    results: Vec<MethodRuns>,
}

impl Study<'_> {
    /// Whether a run's error is within 10× of the reference's agreement, so that it measures
    /// the reference as much as the method.
    fn unresolved(&self, m: &Measured) -> bool {
        m.error < 10.0 * self.agreement
    }

    /// The JSON document of `--json` (schema in docs/cli.md).
    fn to_json(&self) -> serde_json::Value {
        let args = self.args;
        let methods: Vec<serde_json::Value> = self
            .results
            .iter()
            .map(|r| {
                let runs: Vec<serde_json::Value> =
                    r.runs.iter().map(|run| self.run_json(run)).collect();
                json!({
                    "method": r.method.name(),
                    "name": r.method.display_name(),
                    "order": r.method.integrator().order(),
                    "adaptive": r.method.is_adaptive(),
                    "runs": runs,
                    "at_target": self.target_json(&r.at_target),
                })
            })
            .collect();
        json!({
            "model": self.model.name(),
            "t_end": args.t_end,
            "samples": args.samples,
            "error_norm": format!("max over the {s} output times k·T/{s} (k = 1…{s}) and over all {} components of y = [q; q̇] of |y − y_ref|", self.dim, s = args.samples),
            "conservative": self.model.is_conservative(),
            "target_error": args.target_error,
            "baseline_ms": args.baseline_ms,
            "timing": {
                "statistic": "median",
                "min_repeats": self.timing.repeats,
                "min_total_s": self.timing.min_time_s,
                "max_repeats": MAX_REPEATS,
            },
            "reference": {
                "method": "dop853",
                "rtol": args.reference_tol,
                "atol": args.reference_tol,
                "steps": self.reference_steps,
                "check_method": "dp54",
                "agreement": self.agreement,
            },
            "methods": methods,
        })
    }

    /// One run: every key always present, `null` where a failed run has no value.
    fn run_json(&self, run: &Run) -> serde_json::Value {
        let (tol, num_steps, dt) = match run.setting {
            Setting::Tolerance(tol) => (Some(tol), None, None),
            Setting::Steps { steps, dt } => (None, Some(steps), Some(dt)),
        };
        let m = run.outcome.as_ref().ok();
        let failure = run
            .outcome
            .as_ref()
            .err()
            .map(|f| json!({"t": f.t.filter(|t| t.is_finite()), "message": f.message}));
        json!({
            "tol": tol,
            "num_steps": num_steps,
            "dt": dt,
            "error": m.map(|m| finite(m.error)),
            "resolved": m.map(|m| !self.unresolved(m)),
            "rhs_evals": m.map(|m| m.rhs_evals),
            "steps": m.map(|m| m.steps),
            "rejected": m.map(|m| m.rejected),
            "jacobian_evals": m.map(|m| m.jacobian_evals),
            "lu_decompositions": m.map(|m| m.lu_decompositions),
            "wall_time_s": m.map(|m| finite(m.wall_time_s)),
            "repeats": m.map(|m| m.repeats),
            "energy_drift": m.and_then(|m| m.energy_drift),
            "failure": failure,
        })
    }

    /// The work at the target error: interpolated values, or `null`s and a note.
    fn target_json(&self, target: &AtTarget) -> serde_json::Value {
        let (reached, evals, steps, time, note) = match *target {
            AtTarget::Reached {
                rhs_evals,
                steps,
                wall_time_s,
            } => (true, Some(rhs_evals), Some(steps), Some(wall_time_s), None),
            AtTarget::BelowAtLoosest { .. } | AtTarget::NotReached => (
                !matches!(target, AtTarget::NotReached),
                None,
                None,
                None,
                Some(target.note()),
            ),
        };
        json!({
            "reached": reached,
            "rhs_evals": evals.map(finite),
            "steps": steps.map(finite),
            "wall_time_s": time.map(finite),
            "baseline_ratio": time.zip(self.args.baseline_ms).map(|(t, b)| finite(b * 1e-3 / t)),
            "note": note,
        })
    }

    /// The header, the table of runs and the table of work at the target error.
    fn write_text(&self, out: &mut impl Write) -> std::io::Result<()> {
        let args = self.args;
        writeln!(
            out,
            "model      {} ({} dof) over 0 ≤ t ≤ {} s",
            self.model.name(),
            self.model.num_dofs(),
            args.t_end
        )?;
        writeln!(
            out,
            "error      max over the {s} output times k·T/{s} and over all {} components of y = [q; q̇] of |y − y_ref|",
            self.dim,
            s = args.samples
        )?;
        writeln!(
            out,
            "reference  DOP853 at rtol = atol = {:e} ({} steps); Dormand–Prince 5(4) at the same tolerance agrees to {:.2e}",
            args.reference_tol, self.reference_steps, self.agreement
        )?;
        writeln!(
            out,
            "time       median wall time of ≥ {} identical runs totalling ≥ {} ms (at most {MAX_REPEATS} runs)",
            self.timing.repeats, args.min_time_ms
        )?;
        let drift_note = if self.model.is_conservative() {
            ""
        } else {
            " (not conserved: the model has non-conservative loads or explicit time dependence)"
        };
        writeln!(
            out,
            "drift      energy drift max|E − E(0)| / max(T + |V|) over the output times{drift_note}\n"
        )?;
        writeln!(
            out,
            "{:<22} {:>13} {:>10} {:>11} {:>9} {:>11} {:>12}",
            "method", "tol or h", "error", "RHS evals", "steps", "time (ms)", "energy drift"
        )?;
        for r in &self.results {
            let name = r.method.display_name();
            for run in &r.runs {
                let setting = run.setting.label();
                match &run.outcome {
                    Ok(m) => writeln!(
                        out,
                        "{name:<22} {setting:>13} {:>9.2e}{} {:>11} {:>9} {:>11.3} {:>12}",
                        m.error,
                        if self.unresolved(m) { "!" } else { " " },
                        m.rhs_evals,
                        m.steps,
                        m.wall_time_s * 1e3,
                        m.energy_drift
                            .map_or("-".to_string(), |d| format!("{d:.2e}"))
                    )?,
                    Err(f) => writeln!(out, "{name:<22} {setting:>13}   failed: {}", f.message)?,
                }
            }
        }
        writeln!(
            out,
            "\nwork to reach an error of {:e} (log–log interpolation between the bracketing settings)",
            args.target_error
        )?;
        let baseline_header = args.baseline_ms.map_or(String::new(), |b| {
            format!(" {:>16}", format!("{b} ms / time"))
        });
        writeln!(
            out,
            "{:<22} {:>11} {:>9} {:>11}{baseline_header}",
            "method", "RHS evals", "steps", "time (ms)"
        )?;
        for r in &self.results {
            let name = r.method.display_name();
            match r.at_target {
                AtTarget::Reached {
                    rhs_evals,
                    steps,
                    wall_time_s,
                } => {
                    let ratio = args.baseline_ms.map_or(String::new(), |b| {
                        format!(" {:>16.1}", b * 1e-3 / wall_time_s)
                    });
                    writeln!(
                        out,
                        "{name:<22} {rhs_evals:>11.0} {steps:>9.0} {:>11.3}{ratio}",
                        wall_time_s * 1e3
                    )?;
                }
                _ => writeln!(out, "{name:<22} {}", r.at_target.note())?,
            }
        }
        Ok(())
    }
}

impl AtTarget {
    /// Why there is no interpolated work (empty when there is).
    fn note(&self) -> String {
        match *self {
            AtTarget::Reached { .. } => String::new(),
            AtTarget::BelowAtLoosest {
                rhs_evals,
                wall_time_s,
            } => format!(
                "below the target already at the loosest setting (≤ {rhs_evals} RHS evals, ≤ {:.3} ms): add looser settings",
                wall_time_s * 1e3
            ),
            AtTarget::NotReached => {
                "not bracketed by two consecutive settings: add tighter settings or smaller steps"
                    .to_string()
            }
        }
    }
}

/// Writes `PREFIX-evals.{svg,png}` and `PREFIX-time.{svg,png}`: the error of every
/// successful run against its RHS evaluations and its median wall time, log–log.
fn write_charts(prefix: &str, model: &str, results: &[MethodRuns]) -> Result<(), CliError> {
    let series = |work: Work| -> Vec<plot::Series> {
        results
            .iter()
            .map(|r| plot::Series {
                name: r.method.display_name().to_string(),
                points: r
                    .runs
                    .iter()
                    .filter_map(|run| run.outcome.as_ref().ok())
                    .map(|m| (work(m), m.error))
                    .collect(),
            })
            .collect()
    };
    let charts: [(&str, &str, Work); 2] = [
        ("evals", "RHS evaluations", |m| m.rhs_evals as f64),
        ("time", "median wall time (ms)", |m| m.wall_time_s * 1e3),
    ];
    for (tag, x_desc, work) in charts {
        let data = series(work);
        let title = format!("{model}: work–precision ({x_desc})");
        for ext in ["svg", "png"] {
            let path = format!("{prefix}-{tag}.{ext}");
            plot::lines(
                &path,
                &plot::Chart {
                    title: &title,
                    x_desc,
                    y_desc: "max |y − y_ref| over the output times",
                    log_x: true,
                    log_y: true,
                },
                &data,
            )
            .map_err(CliError::failure)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decade_ranges_are_exact_and_loosest_first() {
        assert_eq!(parse_tols("1e-3..1e-6").unwrap(), [1e-3, 1e-4, 1e-5, 1e-6]);
        assert_eq!(parse_tols("1e-6..1e-3").unwrap(), [1e-3, 1e-4, 1e-5, 1e-6]);
        assert_eq!(parse_tols("1e-8,1e-4,1e-4").unwrap(), [1e-4, 1e-8]);
        assert_eq!(parse_tols("2e-3..2e-5").unwrap().len(), 3);
        for bad in [
            "",
            "abc",
            "1e-3..",
            "0",
            "1..1e-3",
            "1e-3..3e-5",
            "nan",
            "-1e-3",
        ] {
            let e = parse_tols(bad).unwrap_err();
            assert_eq!(e.code, 2, "{bad}");
            assert!(e.message.contains("--tols"), "{}", e.message);
        }
    }

    #[test]
    fn step_ranges_double() {
        assert_eq!(parse_steps("16..128").unwrap(), [16, 32, 64, 128]);
        assert_eq!(parse_steps("16..100").unwrap(), [16, 32, 64]);
        assert_eq!(parse_steps("1000,10,100").unwrap(), [10, 100, 1000]);
        for bad in ["0..8", "x", "1.5", "-4", ""] {
            assert_eq!(parse_steps(bad).unwrap_err().code, 2, "{bad}");
        }
    }

    #[test]
    fn interpolation_is_log_log_between_the_bracketing_pair() {
        // error = work⁻², so at error 1e-4 the work is 100.
        let points = [(1.0, 1.0), (1e-2, 10.0), (1e-6, 1000.0)];
        let w = interpolate(&points, 1e-4).unwrap();
        assert!((w - 100.0).abs() < 1e-9, "{w}");
        assert_eq!(interpolate(&points, 1e-8), None);
        // A failed run (NaN) breaks the bracket rather than being interpolated across.
        let gap = [(1.0, 1.0), (f64::NAN, f64::NAN), (1e-6, 1000.0)];
        assert_eq!(interpolate(&gap, 1e-4), None);
    }

    #[test]
    fn median_of_even_and_odd() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
