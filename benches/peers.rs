//! eomgen's Dormand–Prince 5(4) and DOP853 against the peer crate `ode_solvers` (0.6.2), at
//! equal error, on the same generated double-pendulum right-hand side (issue 6, performance).
//!
//! The problem: `models/double_pendulum.yaml` with its default parameters (HW19: two uniform
//! bars, 1 kg, 1 m, g = 10 m/s²) from its initial state θ₁ = 0, θ₂ = π/2 at rest, integrated
//! to `t = 10 s`. Both sides evaluate `ẏ = [q̇; M⁻¹F]` through the same [`CountedRhs`]:
//! [`FirstOrder`]`<`[`DoublePendulum`]`>` called through [`OdeSystem::rhs`], behind a
//! `RefCell` (ode_solvers' `System::system` takes `&self`; the borrow flag costs both sides the
//! same ~1 ns) and a counter, so right-hand-side evaluations are counted identically.
//!
//! Settings, made the same on both sides (all of them ode_solvers' defaults except the output):
//! - tolerances `rtol = atol = tol` (scalars). Both weigh the local error the same way:
//!   `scᵢ = atol + rtol · max(|yᵢ|, |y_newᵢ|)`, the RMS norm over the components for DP5(4),
//!   and `dop853.f`'s combined fifth/third-order estimate for DOP853;
//! - step-size control: ode_solvers' defaults are Hairer's, as are ours ([`PiController`]):
//!   Dopri5 `alpha = 0.17`, `beta = 0.04`, safety 0.9, step ratio in `[0.2, 10]`; Dop853
//!   `alpha = 1/8`, `beta = 0`, safety 0.9, step ratio in `[0.333, 6]`; first step by Hairer's
//!   `hinit` on both sides (ode_solvers evaluates `F(t0)` once more than we do); `h_max =
//!   t_end − t0`; at most 10⁶ steps;
//! - output: every accepted step on both sides (ours [`OutputTimes::Steps`], ode_solvers
//!   `OutputType::Sparse`); the final state is the last step's, exactly at `t = 10`.
//!   ode_solvers' default `OutputType::Dense` would, for Dop853, compute the order-7 dense
//!   coefficients at *every* step (three more evaluations of `F` per step, 15 instead of 12,
//!   whether or not an output point falls in the step); Hairer's `dop853.f` and ours do that
//!   only when dense output is asked for. Its `solout` callback is left at its default (never
//!   stops). Its stiffness detection (every 1000 steps, a few dot products) is left on: we
//!   have none, and it never triggers here.
//!
//! The reference `y(10)` is our DOP853 at `rtol = atol = 1e-14`, checked against ode_solvers'
//! Dop853 and our Dormand–Prince 5(4) at the same tolerance (their differences are printed).
//! The error of a run is `max |yᵢ(10) − y_refᵢ(10)|` over `[θ₁, θ₂, θ̇₁, θ̇₂]` (rad, rad/s).
//!
//! Equal error: the two codes' errors differ at equal tolerance, so for each of our runs the
//! peer's work (right-hand-side evaluations, criterion median time) at the *same error* is
//! interpolated linearly in `log(work)` against `log(error)` between the peer's runs
//! (no extrapolation), and the ratio peer / eomgen is reported (> 1: eomgen cheaper).
//!
//! The MuJoCo anchor (issue 6): MuJoCo's RK4 at `dt = 1e-3` simulates this double pendulum for
//! 10 s in about 60 ms with a state error of ~5e-4; the goal is ≥ 200× less time at that
//! error. A tolerance sweep (`10^(−k/4)`) of our adaptive methods picks, for each, the loosest
//! tolerance from which on every tighter one gives an error ≤ 5e-4; the method with the
//! fewest evaluations there is timed (`anchor_*`), with our RK4 at `dt = 1e-3` for
//! comparison.
//!
//! Output: the table of errors and evaluations with the equal-error evaluation ratios is
//! printed to stderr before timing; after timing, the same table with the criterion medians and
//! the equal-error time ratios, then again with the medians of an interleaved timing (every
//! configuration run once per round, 300 rounds, so that a drift of the machine's speed cannot
//! fall between eomgen's runs and the peer's), and last a comparison of least-squares lines of
//! `ln work` against `ln error` over 49 tolerances 1e-6 … 1e-12 (evaluations, and interleaved
//! times; see `fitted_comparison`), is printed and written to
//! `<criterion dir>/peers-table.txt` (`target/criterion/` unless `CRITERION_HOME` or
//! `CARGO_TARGET_DIR` says otherwise).
//!
//! Run with `cargo bench --bench peers` (about 90 s on the 2-core development machine).

use std::cell::{Cell, RefCell};
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant, SystemTime};

use criterion::{BenchmarkId, Criterion};
eomgen::model!("../models/double_pendulum.yaml");
use eomgen::{
    BogackiShampine32, DormandPrince54, DormandPrince853, FirstOrder, Integrator,
    IntegratorOptions, ModelInfo, OdeSystem, OutputTimes, RhsError, RungeKutta4,
};
use ode_solvers::{Dop853, Dopri5};

#[macro_use]
#[path = "peer_stepper.rs"]
mod peer_stepper;

/// The state `[θ₁, θ₂, θ̇₁, θ̇₂]` as ode_solvers holds it (its own nalgebra 0.34 vector).
type PeerState = ode_solvers::SVector<f64, 4>;

/// End of every integration (s).
const T_END: f64 = 10.0;

/// The tolerances `rtol = atol` of the comparison.
const TOLERANCES: [f64; 9] = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12];

/// Tolerance of the reference solution.
const REFERENCE_TOLERANCE: f64 = 1e-14;

/// MuJoCo's anchor (issue 6): RK4 at `dt = 1e-3`, 10 s of the double pendulum in ~60 ms with a
/// final-state error of ~5e-4.
const ANCHOR_ERROR: f64 = 5e-4;
/// MuJoCo's time for the anchor (s).
const ANCHOR_TIME: f64 = 60e-3;

/// Criterion group of the pair timings.
const GROUP: &str = "peers_double_pendulum_10s";
/// Criterion group of the MuJoCo-anchor timings.
const ANCHOR_GROUP: &str = "anchor_double_pendulum_10s";

/// The generated double pendulum's right-hand side, shared by both codes, with a count of its
/// evaluations.
struct CountedRhs {
    system: RefCell<FirstOrder<DoublePendulum, 2>>,
    evals: Cell<usize>,
}

impl CountedRhs {
    /// The model with its default parameters.
    fn new() -> Self {
        Self {
            system: RefCell::new(FirstOrder::new(DoublePendulum::default())),
            evals: Cell::new(0),
        }
    }

    /// `dy = F(t, y)` by [`OdeSystem::rhs`], counted.
    fn eval(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        self.evals.set(self.evals.get() + 1);
        self.system.borrow_mut().rhs(t, y, dy)
    }

    /// The evaluations since the last call, and the counter reset.
    fn take_evals(&self) -> usize {
        self.evals.replace(0)
    }
}

/// [`CountedRhs`] as an eomgen [`OdeSystem`].
struct Eomgen<'a>(&'a CountedRhs);

impl OdeSystem for Eomgen<'_> {
    fn dim(&self) -> usize {
        4
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        self.0.eval(t, y, dy)
    }
}

/// [`CountedRhs`] as an ode_solvers `System`.
struct Peer<'a>(&'a CountedRhs);

impl ode_solvers::System<f64, PeerState> for Peer<'_> {
    /// # Panics
    /// If the right-hand side fails, which it cannot for the double pendulum (its mass matrix
    /// is positive definite at every configuration); ode_solvers has no error channel.
    fn system(&self, t: f64, y: &PeerState, dy: &mut PeerState) {
        self.0
            .eval(t, y.as_slice(), dy.as_mut_slice())
            .expect("the double pendulum's right-hand side");
    }
}

/// `y(T_END)` by ode_solvers' `$solver` at `rtol = atol = $tol` from `$y0`, at most 10⁶
/// steps (the stepper's settings: `peer_stepper!`).
///
/// # Panics
/// If the integration fails or does not end at `T_END`.
macro_rules! peer_final_state {
    ($solver:ident, $rhs:expr, $y0:expr, $tol:expr, $beta:expr, $fac_min:expr, $fac_max:expr) => {{
        let mut stepper = peer_stepper!(
            $solver,
            Peer($rhs),
            PeerState::from_column_slice($y0),
            T_END,
            $tol,
            $beta,
            $fac_min,
            $fac_max,
            1_000_000
        );
        stepper.integrate().expect("ode_solvers integrates");
        assert_eq!(stepper.x_out().last(), Some(&T_END));
        let y = stepper.y_out().last().expect("a final sample");
        [y[0], y[1], y[2], y[3]]
    }};
}

/// A method and its setting: a tolerance for the adaptive ones, a step for RK4.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Run {
    /// eomgen's Dormand–Prince 5(4) at `rtol = atol = tol`.
    EomgenDp54(f64),
    /// ode_solvers' Dopri5 at `rtol = atol = tol`.
    PeerDopri5(f64),
    /// eomgen's DOP853 at `rtol = atol = tol`.
    EomgenDop853(f64),
    /// ode_solvers' Dop853 at `rtol = atol = tol`.
    PeerDop853(f64),
    /// eomgen's Bogacki–Shampine 3(2) at `rtol = atol = tol`.
    EomgenBs32(f64),
    /// eomgen's classical RK4 with the fixed step `dt`.
    EomgenRk4(f64),
}

impl Run {
    /// Criterion function name.
    fn name(self) -> &'static str {
        match self {
            Run::EomgenDp54(_) => "eomgen_dp54",
            Run::PeerDopri5(_) => "ode_solvers_dopri5",
            Run::EomgenDop853(_) => "eomgen_dop853",
            Run::PeerDop853(_) => "ode_solvers_dop853",
            Run::EomgenBs32(_) => "eomgen_bs32",
            Run::EomgenRk4(_) => "eomgen_rk4",
        }
    }

    /// The tolerance or step.
    fn setting(self) -> f64 {
        match self {
            Run::EomgenDp54(x)
            | Run::PeerDopri5(x)
            | Run::EomgenDop853(x)
            | Run::PeerDop853(x)
            | Run::EomgenBs32(x)
            | Run::EomgenRk4(x) => x,
        }
    }

    /// Integrates from `y0` at `t = 0` to [`T_END`] and returns `y(T_END)`.
    ///
    /// # Panics
    /// If an integration fails or does not end at `T_END` (neither happens for these
    /// settings).
    fn final_state(self, rhs: &CountedRhs, y0: &[f64; 4]) -> [f64; 4] {
        let adaptive = |tol: f64| {
            IntegratorOptions::default()
                .with_rtol(tol)
                .with_atol(tol)
                .with_max_steps(1_000_000)
        };
        let eomgen = |method: &mut dyn Integrator, options: IntegratorOptions| {
            let solution = method
                .integrate(
                    &mut Eomgen(rhs),
                    0.0,
                    y0,
                    T_END,
                    &OutputTimes::Steps,
                    &options,
                )
                .expect("eomgen integrates the double pendulum");
            let (t, y) = solution.last().expect("a final sample");
            assert_eq!(t, T_END);
            [y[0], y[1], y[2], y[3]]
        };
        match self {
            Run::EomgenDp54(tol) => eomgen(&mut DormandPrince54::new(), adaptive(tol)),
            Run::EomgenDop853(tol) => eomgen(&mut DormandPrince853::new(), adaptive(tol)),
            Run::EomgenBs32(tol) => eomgen(&mut BogackiShampine32::new(), adaptive(tol)),
            Run::EomgenRk4(dt) => eomgen(
                &mut RungeKutta4::new(),
                IntegratorOptions::default().with_dt(dt),
            ),
            // Dopri5's defaults: beta = 0.04, step ratio in [0.2, 10].
            Run::PeerDopri5(tol) => peer_final_state!(Dopri5, rhs, y0, tol, 0.04, 0.2, 10.0),
            // Dop853's defaults: beta = 0, step ratio in [0.333, 6].
            Run::PeerDop853(tol) => peer_final_state!(Dop853, rhs, y0, tol, 0.0, 0.333, 6.0),
        }
    }
}

/// `max |aᵢ − bᵢ|`.
fn max_difference(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// A run's outcome: final-state error, evaluations, and the criterion median (s) once known.
#[derive(Debug, Clone, Copy)]
struct Outcome {
    run: Run,
    error: f64,
    rhs_evals: usize,
    median: Option<f64>,
}

/// Runs `run` once and measures its error against `reference`.
fn outcome(run: Run, y0: &[f64; 4], reference: &[f64; 4]) -> Outcome {
    let rhs = CountedRhs::new();
    let y = run.final_state(&rhs, y0);
    Outcome {
        run,
        error: max_difference(&y, reference),
        rhs_evals: rhs.take_evals(),
        median: None,
    }
}

/// The work `work(error)` of the `points` `(error, work)` at `error`, linear in
/// `log work` against `log error` between the two nearest errors on either side, or `None`
/// outside their range (no extrapolation).
fn work_at_error(points: &[(f64, f64)], error: f64) -> Option<f64> {
    let mut sorted: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(e, w)| *e > 0.0 && *w > 0.0)
        .collect();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let x = error.ln();
    sorted.windows(2).find_map(|pair| {
        let ((e0, w0), (e1, w1)) = (pair[0], pair[1]);
        let (x0, x1) = (e0.ln(), e1.ln());
        if !(x0 <= x && x <= x1) {
            return None;
        }
        let s = if x1 > x0 { (x - x0) / (x1 - x0) } else { 0.0 };
        Some((w0.ln() + s * (w1.ln() - w0.ln())).exp())
    })
}

/// Where criterion writes its results, resolved as criterion 0.8 does: `$CRITERION_HOME`,
/// else `$CARGO_TARGET_DIR/criterion`, else the workspace's `target/criterion`.
fn criterion_dir() -> PathBuf {
    if let Some(home) = std::env::var_os("CRITERION_HOME") {
        return PathBuf::from(home);
    }
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../target")))
        .join("criterion")
}

/// Criterion's median (s) of the benchmark `run` in `group`, if it was measured by this process
/// (the estimates file is newer than `since`).
fn criterion_median(group: &str, run: Run, since: SystemTime) -> Option<f64> {
    let path = criterion_dir()
        .join(group)
        .join(run.name())
        .join(format!("{:e}", run.setting()))
        .join("new")
        .join("estimates.json");
    let modified = std::fs::metadata(&path).ok()?.modified().ok()?;
    if modified < since {
        return None;
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()?;
    json["median"]["point_estimate"]
        .as_f64()
        .map(|ns| ns * 1e-9)
}

/// `value` with three significant digits, or `—`.
fn show(value: Option<f64>) -> String {
    value.map_or_else(|| "—".to_string(), |v| format!("{v:.3}"))
}

/// A duration in µs, or `—`.
fn show_time(seconds: Option<f64>) -> String {
    seconds.map_or_else(|| "—".to_string(), |s| format!("{:.1} µs", s * 1e6))
}

/// The comparison table of one pair (eomgen, peer) over [`TOLERANCES`], with the equal-error
/// ratios peer / eomgen of evaluations and (once measured) time.
fn pair_table(title: &str, ours: &[Outcome], theirs: &[Outcome]) -> String {
    let evals = |o: &[Outcome]| -> Vec<(f64, f64)> {
        o.iter().map(|o| (o.error, o.rhs_evals as f64)).collect()
    };
    let times = |o: &[Outcome]| -> Vec<(f64, f64)> {
        o.iter()
            .filter_map(|o| o.median.map(|m| (o.error, m)))
            .collect()
    };
    let (their_evals, their_times) = (evals(theirs), times(theirs));
    let mut out = String::new();
    let _ = writeln!(out, "{title}");
    let _ = writeln!(
        out,
        "| tol | eomgen error | eomgen RHS | eomgen time | peer error | peer RHS | peer time | \
         RHS ratio at eomgen's error | time ratio at eomgen's error |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|");
    for (a, b) in ours.iter().zip(theirs) {
        let evals_ratio = work_at_error(&their_evals, a.error).map(|w| w / a.rhs_evals as f64);
        let time_ratio = a
            .median
            .and_then(|m| work_at_error(&their_times, a.error).map(|w| w / m));
        let _ = writeln!(
            out,
            "| {:.0e} | {:.2e} | {} | {} | {:.2e} | {} | {} | {} | {} |",
            a.run.setting(),
            a.error,
            a.rhs_evals,
            show_time(a.median),
            b.error,
            b.rhs_evals,
            show_time(b.median),
            show(evals_ratio),
            show(time_ratio),
        );
    }
    out
}

/// Exponents `k` of the fine tolerance grid `10^(−k/8)` (1e-6 … 1e-12) of the fitted
/// comparison of evaluations.
const FIT_GRID: std::ops::RangeInclusive<i32> = 48..=96;

/// Errors at which the fitted evaluations are compared.
const FIT_ERRORS: [f64; 3] = [1e-3, 1e-5, 1e-7];

/// Rounds of the interleaved timing on the fine grid.
const FIT_ROUNDS: usize = 60;

/// Least-squares line `ln work = a + b ln error` through `(error, work)` points.
struct LogLogFit {
    a: f64,
    b: f64,
    n: f64,
    mean_x: f64,
    sxx: f64,
    /// Residual variance `Σ r² / (n − 2)`.
    variance: f64,
}

impl LogLogFit {
    fn new(points: &[(f64, f64)]) -> Self {
        let n = points.len() as f64;
        let (xs, ys): (Vec<f64>, Vec<f64>) = points.iter().map(|(e, w)| (e.ln(), w.ln())).unzip();
        let (mean_x, mean_y) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
        let sxy: f64 = xs
            .iter()
            .zip(&ys)
            .map(|(x, y)| (x - mean_x) * (y - mean_y))
            .sum();
        let sxx: f64 = xs.iter().map(|x| (x - mean_x).powi(2)).sum();
        let b = sxy / sxx;
        let a = mean_y - b * mean_x;
        let residuals: f64 = xs
            .iter()
            .zip(&ys)
            .map(|(x, y)| (y - a - b * x).powi(2))
            .sum();
        Self {
            a,
            b,
            n,
            mean_x,
            sxx,
            variance: residuals / (n - 2.0),
        }
    }

    /// `ln work` on the line at `error`, and its standard error.
    fn at(&self, error: f64) -> (f64, f64) {
        let x = error.ln();
        let se = (self.variance * (1.0 / self.n + (x - self.mean_x).powi(2) / self.sxx)).sqrt();
        (self.a + self.b * x, se)
    }
}

/// Work at equal error from fitted lines: on this chaotic problem the final-state error of a
/// run scatters by tens of per cent around its trend (two correct codes at the same tolerance
/// differ that much), so a ratio interpolated between single runs scatters as well. Both codes
/// run on the fine grid [`FIT_GRID`] (evaluations counted, times by [`interleaved_medians`]
/// in [`FIT_ROUNDS`] rounds); `ln(work)` is fitted against `ln(error)` by least squares for
/// each, and the fits are compared at [`FIT_ERRORS`] as peer / eomgen with a factor of two
/// standard errors (the ratio's 95 % band).
fn fitted_comparison(
    title: &str,
    ours: fn(f64) -> Run,
    theirs: fn(f64) -> Run,
    rhs: &CountedRhs,
    y0: &[f64; 4],
    reference: &[f64; 4],
) -> String {
    let tolerances: Vec<f64> = FIT_GRID.map(|k| 10f64.powf(-f64::from(k) / 8.0)).collect();
    let runs: Vec<Run> = tolerances
        .iter()
        .flat_map(|&tol| [ours(tol), theirs(tol)])
        .collect();
    let outcomes: Vec<Outcome> = runs.iter().map(|&r| outcome(r, y0, reference)).collect();
    let medians = interleaved_medians(&runs, rhs, y0, FIT_ROUNDS);
    let fit = |side: usize, work: &dyn Fn(usize) -> f64| {
        let points: Vec<(f64, f64)> = (side..runs.len())
            .step_by(2)
            .map(|i| (outcomes[i].error, work(i)))
            .filter(|&(e, w)| e > 0.0 && w > 0.0)
            .collect();
        LogLogFit::new(&points)
    };
    let mut out = format!(
        "{title}, fitted over {} tolerances 1e-6 … 1e-12 (ln work = a + b ln error; peer / \
         eomgen at equal error, × or ÷ the 95 % band):\n",
        tolerances.len()
    );
    let evals = |i: usize| outcomes[i].rhs_evals as f64;
    let times = |i: usize| medians[i];
    for (what, work) in [
        ("RHS", &evals as &dyn Fn(usize) -> f64),
        ("time", &times as &dyn Fn(usize) -> f64),
    ] {
        let (eomgen, peer) = (fit(0, work), fit(1, work));
        let _ = write!(
            out,
            "  {what}: slope b eomgen {:.4}, peer {:.4};",
            eomgen.b, peer.b
        );
        for error in FIT_ERRORS {
            let ((w0, s0), (w1, s1)) = (eomgen.at(error), peer.at(error));
            let band = (2.0 * (s0 * s0 + s1 * s1).sqrt()).exp();
            let _ = write!(out, " at {error:e}: {:.3} (×÷{band:.3});", (w1 - w0).exp());
        }
        out.push('\n');
    }
    out
}

/// Rounds of the interleaved timing.
const ROUNDS: usize = 300;

/// The median time (s) of each of `runs`, measured in `rounds` rounds that each run every
/// configuration once, in the listed order on even rounds and reversed on odd ones.
///
/// Criterion times one configuration after another, so a drift of the machine's speed (a
/// few per cent over a minute on the 2-core VM) lands between eomgen's runs and the peer's
/// and shows in their ratio. Interleaved, a drift slows every configuration alike; the
/// medians' ratios are then steady to ~1 % between invocations.
fn interleaved_medians(runs: &[Run], rhs: &CountedRhs, y0: &[f64; 4], rounds: usize) -> Vec<f64> {
    let mut times = vec![Vec::with_capacity(rounds); runs.len()];
    for round in 0..rounds {
        let order: Vec<usize> = if round % 2 == 0 {
            (0..runs.len()).collect()
        } else {
            (0..runs.len()).rev().collect()
        };
        for i in order {
            let start = Instant::now();
            black_box(runs[i].final_state(rhs, black_box(y0)));
            times[i].push(start.elapsed().as_secs_f64());
        }
    }
    times
        .into_iter()
        .map(|mut t| {
            t.sort_by(f64::total_cmp);
            t[t.len() / 2]
        })
        .collect()
}

/// The whole report: both pairs and the anchor.
fn report(
    reference_note: &str,
    pairs: &[(&str, Vec<Outcome>, Vec<Outcome>)],
    anchor: &[Outcome],
) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Double pendulum (HW19 defaults) 0 → 10 s, final-state error max|y − y_ref| \
         (rad, rad/s); ratios are ode_solvers / eomgen at eomgen's error (> 1: eomgen cheaper)"
    );
    let _ = writeln!(out, "{reference_note}\n");
    for (title, ours, theirs) in pairs {
        out.push_str(&pair_table(title, ours, theirs));
        out.push('\n');
    }
    let _ = writeln!(
        out,
        "MuJoCo anchor: RK4 dt = 1e-3, error ~{ANCHOR_ERROR:e}, ~{} ms; goal ≥ 200× less time",
        ANCHOR_TIME * 1e3
    );
    let _ = writeln!(
        out,
        "| run | setting | error | RHS | time | MuJoCo time / time |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|");
    for o in anchor {
        let _ = writeln!(
            out,
            "| {} | {:.2e} | {:.2e} | {} | {} | {} |",
            o.run.name(),
            o.run.setting(),
            o.error,
            o.rhs_evals,
            show_time(o.median),
            show(o.median.map(|m| ANCHOR_TIME / m)),
        );
    }
    out
}

/// For each adaptive method, the loosest tolerance `10^(−k/4)` from which on every tighter one
/// (down to 1e-10) gives an error ≤ [`ANCHOR_ERROR`]; of these, the run with the fewest
/// evaluations first, then the others.
fn anchor_runs(y0: &[f64; 4], reference: &[f64; 4]) -> Vec<Outcome> {
    let tolerances: Vec<f64> = (12..=40).map(|k| 10f64.powf(-f64::from(k) / 4.0)).collect();
    let methods: [fn(f64) -> Run; 3] = [Run::EomgenBs32, Run::EomgenDp54, Run::EomgenDop853];
    let mut chosen: Vec<Outcome> = methods
        .iter()
        .filter_map(|method| {
            let sweep: Vec<Outcome> = tolerances
                .iter()
                .map(|&tol| outcome(method(tol), y0, reference))
                .collect();
            let first_good =
                (0..sweep.len()).find(|&i| sweep[i..].iter().all(|o| o.error <= ANCHOR_ERROR))?;
            Some(sweep[first_good])
        })
        .collect();
    chosen.sort_by_key(|o| o.rhs_evals);
    chosen
}

/// A comparison of one eomgen method with its peer: the title, our runs and the peer's, one
/// per tolerance of [`TOLERANCES`].
type Pair = (&'static str, Vec<Outcome>, Vec<Outcome>);

/// The reference `y(10)` (our DOP853 at [`REFERENCE_TOLERANCE`]) and the report's line about
/// it: its differences from ode_solvers' Dop853 and our DP5(4) at the same tolerance.
fn reference_solution(model: &CountedRhs, y0: &[f64; 4]) -> ([f64; 4], String) {
    let reference = Run::EomgenDop853(REFERENCE_TOLERANCE).final_state(model, y0);
    let peer_reference = Run::PeerDop853(REFERENCE_TOLERANCE).final_state(model, y0);
    let dp54_reference = Run::EomgenDp54(REFERENCE_TOLERANCE).final_state(model, y0);
    let reference_note = format!(
        "reference: eomgen DOP853 at {REFERENCE_TOLERANCE:e} = {reference:?}; differs from \
         ode_solvers Dop853 at {REFERENCE_TOLERANCE:e} by {:.1e}, from eomgen DP5(4) at \
         {REFERENCE_TOLERANCE:e} by {:.1e}",
        max_difference(&reference, &peer_reference),
        max_difference(&reference, &dp54_reference),
    );
    (reference, reference_note)
}

/// Both pairs' tolerance sweeps: Dormand–Prince 5(4) against Dopri5, DOP853 against Dop853.
fn sweep_pairs(y0: &[f64; 4], reference: &[f64; 4]) -> Vec<Pair> {
    let sweep = |method: fn(f64) -> Run| -> Vec<Outcome> {
        TOLERANCES
            .iter()
            .map(|&tol| outcome(method(tol), y0, reference))
            .collect()
    };
    vec![
        (
            "Dormand–Prince 5(4): eomgen dp54 vs ode_solvers Dopri5",
            sweep(Run::EomgenDp54),
            sweep(Run::PeerDopri5),
        ),
        (
            "DOP853: eomgen dop853 vs ode_solvers Dop853",
            sweep(Run::EomgenDop853),
            sweep(Run::PeerDop853),
        ),
    ]
}

/// Times every run of `pairs` (group [`GROUP`]) and of `anchor` (group [`ANCHOR_GROUP`])
/// with criterion.
fn bench_runs(
    criterion: &mut Criterion,
    pairs: &[Pair],
    anchor: &[Outcome],
    rhs: &CountedRhs,
    y0: &[f64; 4],
) {
    let paired: Vec<Run> = pairs
        .iter()
        .flat_map(|(_, ours, theirs)| ours.iter().chain(theirs))
        .map(|o| o.run)
        .collect();
    let anchored: Vec<Run> = anchor.iter().map(|o| o.run).collect();
    for (name, runs) in [(GROUP, paired), (ANCHOR_GROUP, anchored)] {
        let mut group = criterion.benchmark_group(name);
        for run in runs {
            group.bench_with_input(
                BenchmarkId::new(run.name(), format!("{:e}", run.setting())),
                &run,
                |b, run| b.iter(|| black_box(run.final_state(rhs, black_box(y0)))),
            );
        }
        group.finish();
    }
}

/// Sets the median time of every outcome of `pairs`, then of `anchor`, to
/// `median(group, run)`, the group being the run's criterion group ([`GROUP`],
/// [`ANCHOR_GROUP`]).
fn set_medians(
    pairs: &mut [Pair],
    anchor: &mut [Outcome],
    median: impl Fn(&str, Run) -> Option<f64>,
) {
    for (_, ours, theirs) in pairs {
        for outcome in ours.iter_mut().chain(theirs.iter_mut()) {
            outcome.median = median(GROUP, outcome.run);
        }
    }
    for outcome in anchor {
        outcome.median = median(ANCHOR_GROUP, outcome.run);
    }
}

/// The runs of the interleaved timing: each pair's runs, ours and the peer's alternating by
/// tolerance, then the anchor's.
fn interleaved_runs(pairs: &[Pair], anchor: &[Outcome]) -> Vec<Run> {
    let mut runs: Vec<Run> = pairs
        .iter()
        .flat_map(|(_, ours, theirs)| ours.iter().zip(theirs).flat_map(|(a, b)| [a.run, b.run]))
        .collect();
    runs.extend(anchor.iter().map(|o| o.run));
    runs
}

/// Writes `table` to `<criterion dir>/peers-table.txt`, saying on stderr where (or why not).
fn write_table(table: &str) {
    let path = criterion_dir().join("peers-table.txt");
    match std::fs::create_dir_all(criterion_dir()).and_then(|()| std::fs::write(&path, table)) {
        Ok(()) => eprintln!("written to {}", path.display()),
        Err(e) => eprintln!("cannot write {}: {e}", path.display()),
    }
}

fn main() {
    let mut criterion = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(1))
        .configure_from_args();
    let started = SystemTime::now();

    let model = CountedRhs::new();
    let initial = ModelInfo::initial_state(&*model.system.borrow());
    let y0: [f64; 4] = [initial[0], initial[1], initial[2], initial[3]];
    let (reference, reference_note) = reference_solution(&model, &y0);

    let mut pairs = sweep_pairs(&y0, &reference);
    let mut anchor = anchor_runs(&y0, &reference);
    anchor.push(outcome(Run::EomgenRk4(1e-3), &y0, &reference));
    eprintln!("{}", report(&reference_note, &pairs, &anchor));

    let rhs = CountedRhs::new();
    bench_runs(&mut criterion, &pairs, &anchor, &rhs, &y0);
    set_medians(&mut pairs, &mut anchor, |group, run| {
        criterion_median(group, run, started)
    });
    let mut table = report(&reference_note, &pairs, &anchor);

    // The same comparisons timed interleaved (see `interleaved_medians`).
    let runs = interleaved_runs(&pairs, &anchor);
    let medians = interleaved_medians(&runs, &rhs, &y0, ROUNDS);
    let median_of = |run: Run| runs.iter().position(|&r| r == run).map(|i| medians[i]);
    set_medians(&mut pairs, &mut anchor, |_, run| median_of(run));
    let _ = writeln!(
        table,
        "\nInterleaved: medians of {ROUNDS} rounds, each running every configuration once \
         (eomgen and peer alternating)\n"
    );
    table.push_str(&report(&reference_note, &pairs, &anchor));
    table.push('\n');
    table.push_str(&fitted_comparison(
        "Dormand–Prince 5(4)",
        Run::EomgenDp54,
        Run::PeerDopri5,
        &rhs,
        &y0,
        &reference,
    ));
    table.push_str(&fitted_comparison(
        "DOP853",
        Run::EomgenDop853,
        Run::PeerDop853,
        &rhs,
        &y0,
        &reference,
    ));
    eprintln!("{table}");
    write_table(&table);
    criterion.final_summary();
}
