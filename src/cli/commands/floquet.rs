//! `eomgen study floquet MODEL`: Floquet multipliers of a time-periodic model about an
//! equilibrium, and its stability chart over two parameters (issue 7, item 7; lectures 19 and
//! 21, the Mathieu inverted pendulum).
//!
//! The numbers come from [`eomgen::analysis::vibration::floquet_at_equilibrium`] and, for
//! `--sweep a=LO..HI:N,w=LO..HI:N`, [`eomgen::analysis::vibration::floquet_cell`] on every point of the
//! grid, run here in parallel (rayon); the chart shows stable against unstable cells,
//! coloured by the spectral radius. What the model file's `floquet:` block gives at the
//! operating point ([`eomgen::FloquetReferences`]) is drawn and printed with it: for
//! `mathieu_pendulum`, Kapitza's boundary and the series edges of the Mathieu chart.

use std::f64::consts::TAU;

use clap::Args;
use eomgen::analysis::StudyRuns;
use eomgen::analysis::vibration::{
    self, FloquetCell, FloquetChart, FloquetPoint, FloquetStudyError, FloquetStudyOptions,
    PredictionSummary, SweepAxis,
};
use eomgen::{
    ChartAxis, FloquetAnalysis, FloquetError, FloquetOptions, FloquetReferences, FloquetStability,
    ModelInfo, ThresholdPrediction,
};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use rayon::prelude::*;

use crate::cli::error::CliError;
use crate::cli::files::Outputs;
use crate::cli::json::print_json_sorted;
use crate::cli::operating_point::OperatingPointArgs;
use crate::cli::plot::{Drawing, tick, write_chart};
use crate::cli::render::num;
use crate::cli::values::{evaluate, parameter_lookup, set_parameters, split_assignment};

/// Options of `eomgen study floquet`.
#[derive(Debug, Args)]
pub struct FloquetArgs {
    /// A model whose forcing has period 2π/w (`mathieu_pendulum`): a bundled name or the path
    /// of any model file.
    pub model: String,
    #[command(flatten)]
    pub point: OperatingPointArgs,
    /// The parameter that is the forcing frequency w (rad/s); the period is T = 2π/w.
    #[arg(long, default_value = FloquetStudyOptions::DEFAULT_PERIOD_PARAMETER)]
    pub period_parameter: String,
    /// Stability chart over two parameters, `X=LO..HI:N,Y=LO..HI:N` (N values each, ends
    /// included; `a=0..0.3:61,w=10..100:61`): the x axis first. N ≤ 10000 and at most 10⁶
    /// points in all.
    #[arg(long, value_name = "X=LO..HI:N,Y=LO..HI:N")]
    pub sweep: Option<String>,
    /// Tolerance on |μ| = 1: stable means every |μ| ≤ 1 + tol (marginal when within tol of 1),
    /// in [√tol, 0.1] (default: the larger of 1e-6 and √tol, the smallest the integration
    /// supports).
    #[arg(long)]
    pub stability_tolerance: Option<f64>,
    /// Relative and absolute tolerance of DOP853 on the state and the variational equations,
    /// in (0, 1e-4].
    #[arg(long, default_value_t = FloquetOptions::DEFAULT_TOL, value_parser = crate::cli::values::floquet_tolerance, allow_hyphen_values = true)]
    pub tol: f64,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Chart (.svg or .png): with --sweep the stability chart, else the multipliers in the
    /// complex plane with the unit circle.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
}

/// The text of a failed analysis (a point or a cell) of `model`: a failed equilibrium search
/// gets its hint.
fn analysis_text(model: &dyn ModelInfo, e: &FloquetStudyError) -> String {
    match e {
        FloquetStudyError::Equilibrium(m) => {
            format!(
                "{m}\nhelp: {}",
                crate::cli::operating_point::modal_hint(model, m)
            )
        }
        e => e.to_string(),
    }
}

impl FloquetArgs {
    /// The tolerance on |μ| = 1: as given, else the default 1e-6 raised to `√tol` when the
    /// integration is looser than 1e-12 (what `FloquetOptions::validate` accepts).
    fn stability_tolerance(&self) -> f64 {
        self.stability_tolerance.unwrap_or_else(|| {
            FloquetOptions::default()
                .stability_tolerance
                .max(self.tol.sqrt())
        })
    }
}

/// Runs `study floquet`.
pub fn run(args: &FloquetArgs) -> Result<(), CliError> {
    Outputs::new()
        .input(&args.model)
        .chart("--plot", args.plot.as_deref())
        .check()?;
    let mut model = args.point.model(&args.model)?;
    let source = crate::cli::model::open_model(&args.model)?;
    // A file that cannot be read here (a bundled model's file moved away from an installed
    // binary) declares no unit this check could read; the numerical check still runs.
    match eomgen::studies::check_period_parameter_unit(&source, &args.period_parameter) {
        Ok(()) | Err(eomgen::studies::PeriodUnitError::File(_)) => {}
        Err(e) => return Err(CliError::usage(e.to_string())),
    }
    let options = FloquetStudyOptions {
        operating_point: args.point.options(model.as_ref())?,
        period_parameter: args.period_parameter.clone(),
        floquet: FloquetOptions {
            rtol: args.tol,
            atol: args.tol,
            stability_tolerance: args.stability_tolerance(),
            ..FloquetOptions::default()
        },
    };
    let (label, guess) = args.point.guess(model.as_ref())?;
    let axes = args
        .sweep
        .as_deref()
        .map(|s| parse_sweep(s, model.as_ref()))
        .transpose()?;
    // With a sweep, the model must depend on t at swept values, not necessarily at its own.
    let point = match &axes {
        Some((x, y)) => {
            vibration::floquet_at_equilibrium_for_sweep(model.as_mut(), &options, [x, y])
        }
        None => vibration::floquet_at_equilibrium(model.as_mut(), &options),
    }
    .map_err(|e| study_error(model.as_ref(), &label, e))?;
    let sweep = match axes {
        Some((x, y)) => Some(run_sweep(args, &guess, x, y, &options)?),
        None => None,
    };
    let references = FloquetReferences::of(model.description(), &label)
        .map_err(|e| CliError::failure(e.to_string()))?;
    let thresholds = references
        .as_ref()
        .map(|r| r.thresholds(model.as_ref()))
        .unwrap_or_default();

    if let Some(path) = &args.plot {
        draw(
            path,
            args,
            model.as_ref(),
            &label,
            &point,
            sweep.as_ref(),
            references.as_ref(),
        )?;
    }

    let report = Report {
        args,
        model: model.as_ref(),
        label: &label,
        point: &point,
        thresholds: &thresholds,
        sweep: sweep.as_ref(),
    };
    let mut stdout = crate::cli::output::stdout();
    if args.json {
        let predictions = thresholds
            .iter()
            .map(|t| PredictionSummary {
                name: t.name.clone(),
                key: t.key.clone(),
                value: t.value,
                critical: t.critical,
                equilibrium: label.clone(),
                predicts_stable: t.predicts_stable,
            })
            .collect();
        let summary = point.summary(model.as_ref(), &options, predictions, sweep.as_ref());
        print_json_sorted(&summary)?;
    } else {
        print_report(&mut stdout, &report);
    }
    // A chart every cell of which failed measured nothing.
    match &sweep {
        Some(chart) => chart
            .check_measured()
            .map_err(|e| CliError::failure(e.to_string())),
        None => Ok(()),
    }
}

/// The CLI's error for a Floquet study that could not run: a usage error for an option, the
/// operating point's failure as the other studies say it, else the analysis' reason.
fn study_error(model: &dyn ModelInfo, label: &str, e: FloquetStudyError) -> CliError {
    match e {
        FloquetStudyError::UnknownPeriodParameter { ref name, .. } => CliError::usage(format!(
            "--period-parameter {name}: {e}; name the forcing frequency w (rad/s), T = 2π/w"
        )),
        FloquetStudyError::InvalidTolerance { .. } => CliError::usage(format!("--tol: {e}")),
        FloquetStudyError::Floquet(e @ FloquetError::InvalidStabilityTolerance { .. }) => {
            CliError::usage(format!("--stability-tolerance: {e}"))
        }
        FloquetStudyError::OperatingPoint(e) => {
            crate::cli::operating_point::point_failure(model, &e)
        }
        e => CliError::failure(format!(
            "`{}` at {label}: {}",
            model.description().name,
            analysis_text(model, &e)
        )),
    }
}

/// The chart of `--plot`: the stability chart of a sweep, else the multipliers on the unit
/// circle.
///
/// # Errors
/// A chart that cannot be written.
fn draw(
    path: &str,
    args: &FloquetArgs,
    model: &dyn ModelInfo,
    label: &str,
    point: &FloquetPoint,
    sweep: Option<&FloquetChart>,
    references: Option<&FloquetReferences>,
) -> Result<(), CliError> {
    match sweep {
        Some(FloquetChart { x, y, cells: grid }) => {
            let title = format!(
                "{} at {label}: Floquet stability over {} and {}",
                model.description().name,
                x.name,
                y.name
            );
            let labels = [
                axis_label(&x.name, &args.period_parameter, references),
                axis_label(&y.name, &args.period_parameter, references),
            ];
            let curves = references.map(|r| (r, model));
            stability_chart(path, &title, [x, y], &labels, grid, curves)
        }
        _ => {
            let title = format!(
                "{} at {label}: Floquet multipliers",
                model.description().name
            );
            multiplier_chart(path, &title, &point.floquet)
        }
    }
    .map_err(CliError::failure)?;
    Ok(())
}

/// What `study floquet` prints.
struct Report<'a> {
    args: &'a FloquetArgs,
    model: &'a dyn ModelInfo,
    label: &'a str,
    point: &'a FloquetPoint,
    thresholds: &'a [ThresholdPrediction],
    sweep: Option<&'a FloquetChart>,
}

/// The text of `report`.
fn print_report(stdout: &mut impl std::io::Write, report: &Report<'_>) {
    let Report {
        args,
        model,
        label,
        point,
        thresholds,
        sweep,
    } = *report;
    let names = model.description().coordinate_names();
    let f = &point.floquet;
    let q: Vec<String> = names
        .iter()
        .zip(&point.q)
        .map(|(c, v)| format!("{c} = {v:.12e}", v = num(v)))
        .collect();
    let _ = writeln!(
        stdout,
        "model        {} ({} dof)",
        model.description().name,
        names.len()
    );
    let _ = writeln!(
        stdout,
        "equilibrium  {label}: {} (for all t: max |F(q, 0, t)| = {:.1e})",
        q.join(", "),
        num(point.residual)
    );
    let _ = writeln!(
        stdout,
        "period       T = 2π/{} = {:.12e} s ({} = {} rad/s); DOP853 at tol {:e}: {} steps, {} RHS evaluations",
        args.period_parameter,
        num(f.period),
        args.period_parameter,
        point.frequency,
        num(args.tol),
        f.stats.steps,
        f.stats.rhs_evals
    );
    let _ = writeln!(
        stdout,
        "{:>3}  {:>22}  {:>22}  {:>16}  {:>16}  {:>16}",
        "k", "Re μ", "Im μ", "|μ|", "Re ln(μ)/T (1/s)", "Im ln(μ)/T"
    );
    for (k, (m, e)) in f.multipliers.iter().zip(&f.exponents).enumerate() {
        let _ = writeln!(
            stdout,
            "{:>3}  {:>22.14e}  {:>22.14e}  {:>16.10e}  {:>16.8e}  {:>16.8e}",
            k + 1,
            num(m.re),
            num(m.im),
            num(m.norm()),
            num(e.re),
            num(e.im)
        );
    }
    let _ = writeln!(
        stdout,
        "result       spectral radius ρ = {:.12e}, det Φ(T) = {:.12e}: {} (tolerance {:e} on |μ| = 1)",
        num(f.spectral_radius),
        num(f.determinant),
        f.stability.as_str().replace('_', " "),
        num(args.stability_tolerance())
    );
    for t in thresholds {
        let _ = writeln!(
            stdout,
            "{:<12} {} = {:.6e} against {} = {:.6e}: {} predicts {label} {} ({})",
            t.name,
            t.label,
            num(t.value),
            t.critical_label,
            num(t.critical),
            t.by,
            if t.predicts_stable {
                "stable"
            } else {
                "unstable"
            },
            t.note
        );
    }
    if !point.time_dependent {
        let _ = writeln!(
            stdout,
            "note         at these parameters the equations do not depend on t: the multipliers are those of the modes over T = 2π/{}; the chart's swept values do depend on t",
            args.period_parameter
        );
    }
    if let Some(chart) = sweep {
        print_map(stdout, &chart.x, &chart.y, &chart.cells);
    }
}

/// One grid cell's outcome: the cell or the failure.
type Cell = Result<FloquetCell, String>;

/// One swept parameter.
type Axis = SweepAxis;

/// The analyses on the grid `x × y`, in parallel; `cells[i][j]` at `(x[i], y[j])`.
fn run_sweep(
    args: &FloquetArgs,
    guess: &[f64],
    x: Axis,
    y: Axis,
    options: &FloquetStudyOptions,
) -> Result<FloquetChart, CliError> {
    let source = crate::cli::model::open_model(&args.model)?;
    let total = x.values.len() * y.values.len();
    let bar = crate::cli::render::progress_bar(
        total,
        "{msg} [{bar:40}] {pos}/{len} analyses, {elapsed} (eta {eta})",
        "floquet",
        false,
    );
    let flat: Vec<Cell> = (0..total)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k / y.values.len(), k % y.values.len());
            let mut model = source.instantiate();
            let cell = (|| {
                set_parameters(model.as_mut(), &args.point.set).map_err(|e| e.message)?;
                let values = [
                    (x.name.as_str(), x.values[i]),
                    (y.name.as_str(), y.values[j]),
                ];
                vibration::floquet_cell(model.as_mut(), guess, &values, options)
                    .map_err(|e| analysis_text(model.as_ref(), &e))
            })();
            bar.inc(1);
            cell
        })
        .collect();
    bar.finish_and_clear();
    let cells = flat.chunks(y.values.len()).map(<[Cell]>::to_vec).collect();
    Ok(FloquetChart { x, y, cells })
}

/// The widest sweep whose map is printed as text, one character per point.
const MAP_COLUMNS: usize = 120;

/// The sweep as characters, y descending: `·` stable, `#` unstable, `?` failed.
fn print_map(out: &mut impl std::io::Write, x: &Axis, y: &Axis, grid: &[Vec<Cell>]) {
    let stable = grid
        .iter()
        .flatten()
        .filter(|c| matches!(c, Ok(c) if c.stability.is_stable()))
        .count();
    let failed = grid.iter().flatten().filter(|c| c.is_err()).count();
    let (columns, rows) = (x.values.len(), y.values.len());
    if columns > MAP_COLUMNS {
        // Too wide for a terminal: the counts only (the chart of `--plot` has the map).
        let _ = writeln!(
            out,
            "sweep        {columns} × {rows} points: {stable} stable, {failed} failed (the map is printed for at most {MAP_COLUMNS} points across)"
        );
        return;
    }
    let _ = writeln!(
        out,
        "sweep        {columns} × {rows} points: {stable} stable, {failed} failed ('·' stable, '#' unstable, '?' failed; {} across, {} up)",
        x.name, y.name
    );
    for j in (0..y.values.len()).rev() {
        let row: String = grid
            .iter()
            .map(|col| match &col[j] {
                Ok(c) if c.stability.is_stable() => '·',
                Ok(_) => '#',
                Err(_) => '?',
            })
            .collect();
        let _ = writeln!(out, "{:>12.4e} {row}", num(y.values[j]));
    }
    let _ = writeln!(
        out,
        "{:>12} {} = {:.4e} … {:.4e}",
        "",
        x.name,
        num(x.values.first().copied().unwrap_or(f64::NAN)),
        num(x.values.last().copied().unwrap_or(f64::NAN))
    );
}

/// `X=LO..HI:N,Y=LO..HI:N`.
/// Most points of a `--sweep` grid (each is one Floquet analysis over a period).
const MAX_SWEEP_POINTS: usize = 1_000_000;

fn parse_sweep(spec: &str, model: &dyn ModelInfo) -> Result<(Axis, Axis), CliError> {
    let lookup = parameter_lookup(model);
    let mut axes = Vec::new();
    for part in spec.split(',') {
        let (name, rest) = split_assignment(part, "--sweep")?;
        if !model.description().parameter_names().contains(&name) {
            return Err(CliError::usage(format!(
                "--sweep: `{}` has no parameter `{name}` (it has: {})",
                model.description().name,
                model.description().parameter_names().join(", ")
            )));
        }
        let bad = || {
            CliError::usage(format!(
                "--sweep: `{part}` is not NAME=LO..HI:N (for example `a=0..0.3:31`)"
            ))
        };
        let (range, count) = rest.rsplit_once(':').ok_or_else(bad)?;
        let (lo, hi) = range.split_once("..").ok_or_else(bad)?;
        let lo = evaluate(lo.trim(), &format!("--sweep {name}"), &lookup)?;
        let hi = evaluate(hi.trim(), &format!("--sweep {name}"), &lookup)?;
        let count: usize = count.trim().parse().map_err(|_| bad())?;
        let axis = SweepAxis::linear(name, lo, hi, count).map_err(|_| {
            CliError::usage(format!(
                "--sweep {name}: need 1 ≤ N ≤ 10000 values and LO < HI, got `{rest}`"
            ))
        })?;
        axes.push(axis);
    }
    match <[Axis; 2]>::try_from(axes) {
        Ok([x, y]) if x.values.len() * y.values.len() > MAX_SWEEP_POINTS => {
            Err(CliError::usage(format!(
                "--sweep: {} × {} points; the grid may have at most {MAX_SWEEP_POINTS}",
                x.values.len(),
                y.values.len()
            )))
        }
        Ok([x, y]) if x.name != y.name => Ok((x, y)),
        _ => Err(CliError::usage(
            "--sweep takes two different parameters, `X=LO..HI:N,Y=LO..HI:N` (for example `a=0..0.3:31,w=10..100:31`)",
        )),
    }
}

/// The stability chart: one rectangle per grid point, stable cells blue (lighter for
/// marginal), unstable ones yellow to red with `log₁₀ ρ`, failed ones grey; Kapitza's
/// boundary and the `a₀`, `b₁` series curves where they apply.
fn stability_chart(
    path: &str,
    title: &str,
    axes: [&Axis; 2],
    labels: &[String; 2],
    grid: &[Vec<Cell>],
    references: Option<(&FloquetReferences, &dyn ModelInfo)>,
) -> Result<(), String> {
    let chart = StabilityChart {
        title,
        axes,
        labels,
        grid,
        references,
    };
    write_chart(path, (960, 720), &chart)
}

/// The stability chart of [`stability_chart`], drawn.
struct StabilityChart<'a> {
    title: &'a str,
    axes: [&'a Axis; 2],
    labels: &'a [String; 2],
    grid: &'a [Vec<Cell>],
    references: Option<(&'a FloquetReferences, &'a dyn ModelInfo)>,
}

impl Drawing for StabilityChart<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        draw_stability(
            root,
            self.title,
            self.axes,
            self.labels,
            self.grid,
            self.references,
        )
    }
}

/// An axis label with the unit where it is known: the period parameter is a frequency in
/// rad/s; the model file's `floquet:` references give others (`axis_units`).
fn axis_label(
    name: &str,
    period_parameter: &str,
    references: Option<&FloquetReferences>,
) -> String {
    if name == period_parameter {
        format!("{name} (rad/s)")
    } else if let Some(unit) = references.and_then(|r| r.axis_unit(name)) {
        format!("{name} ({unit})")
    } else {
        name.to_string()
    }
}

/// Cell edges: midpoints between neighbouring values, half a spacing beyond the ends.
fn edges(values: &[f64]) -> Vec<f64> {
    if values.len() == 1 {
        let v = values[0];
        let h = if v == 0.0 { 0.5 } else { 0.1 * v.abs() };
        return vec![v - h, v + h];
    }
    let mut e = Vec::with_capacity(values.len() + 1);
    e.push(values[0] - 0.5 * (values[1] - values[0]));
    for w in values.windows(2) {
        e.push(0.5 * (w[0] + w[1]));
    }
    let n = values.len();
    e.push(values[n - 1] + 0.5 * (values[n - 1] - values[n - 2]));
    e
}

/// The stability chart over the two axes of the sweep: each cell coloured by its stability
/// ([`draw_cells`]), the references of the model file's `floquet:` block as curves
/// ([`draw_reference_curves`]), and the legend.
fn draw_stability<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    [x, y]: [&Axis; 2],
    labels: &[String; 2],
    grid: &[Vec<Cell>],
    references: Option<(&FloquetReferences, &dyn ModelInfo)>,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    root.fill(&WHITE).map_err(err)?;
    let (xe, ye) = (edges(&x.values), edges(&y.values));
    let (x0, x1) = (xe[0], xe[xe.len() - 1]);
    let (y0, y1) = (ye[0], ye[ye.len() - 1]);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(labels[0].as_str())
        .y_desc(labels[1].as_str())
        .x_label_formatter(&|v| tick(*v, false))
        .y_label_formatter(&|v| tick(*v, false))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    draw_cells(&mut chart, grid, [&xe, &ye])?;
    if let Some((references, model)) = references {
        let axes = [
            ChartAxis {
                name: &x.name,
                lo: x0,
                hi: x1,
            },
            ChartAxis {
                name: &y.name,
                lo: y0,
                hi: y1,
            },
        ];
        draw_reference_curves(&mut chart, references, model, axes)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperMiddle)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// A chart with linear scales on both axes (the stability chart over the two parameters).
type LinearChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The cells of the stability chart between `cell_edges` (x, y), one series (and legend
/// entry) per kind: asymptotically stable, marginal, unstable (yellow to dark red by
/// log₁₀ ρ, up to the largest on the chart) and failed.
fn draw_cells<DB: DrawingBackend>(
    chart: &mut LinearChart<'_, DB>,
    grid: &[Vec<Cell>],
    cell_edges: [&[f64]; 2],
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let log_max = grid
        .iter()
        .flatten()
        .filter_map(|c| c.as_ref().ok())
        .map(|c| c.spectral_radius.log10())
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max)
        .max(1e-3);
    let stable_color = RGBColor(70, 110, 200);
    let marginal_color = RGBColor(150, 190, 240);
    let unstable = |rho: f64| {
        // Yellow (ρ just above 1) to dark red (the largest ρ on the chart), by log₁₀ ρ.
        let s = (rho.log10() / log_max).clamp(0.0, 1.0);
        RGBColor(
            (250.0 - 90.0 * s) as u8,
            (220.0 * (1.0 - s)) as u8,
            (60.0 * (1.0 - s)) as u8,
        )
    };
    draw_cell_series(
        chart,
        grid,
        cell_edges,
        &|c| {
            matches!(c, Ok(c) if c.stability == FloquetStability::AsymptoticallyStable)
                .then_some(stable_color)
        },
        "asymptotically stable (ρ < 1)",
        stable_color,
    )?;
    draw_cell_series(
        chart,
        grid,
        cell_edges,
        &|c| {
            matches!(c, Ok(c) if c.stability == FloquetStability::Marginal)
                .then_some(marginal_color)
        },
        "marginal (|μ| = 1 within tol): stable",
        marginal_color,
    )?;
    draw_cell_series(
        chart,
        grid,
        cell_edges,
        &|c| match c {
            Ok(c) if c.stability == FloquetStability::Unstable => Some(unstable(c.spectral_radius)),
            _ => None,
        },
        &format!("unstable, yellow→red with log₁₀ ρ up to {log_max:.2}"),
        unstable(10f64.powf(0.5 * log_max)),
    )?;
    draw_cell_series(
        chart,
        grid,
        cell_edges,
        &|c| c.is_err().then_some(RGBColor(160, 160, 160)),
        "analysis failed",
        RGBColor(160, 160, 160),
    )
}

/// One series of the stability chart: a filled rectangle between the cell edges
/// `[xe, ye]` for each cell that `pick` gives a colour, labelled `label` in the legend with
/// a swatch of `legend`; nothing (and no legend entry) when no cell is picked.
fn draw_cell_series<DB: DrawingBackend>(
    chart: &mut LinearChart<'_, DB>,
    grid: &[Vec<Cell>],
    [xe, ye]: [&[f64]; 2],
    pick: &dyn Fn(&Cell) -> Option<RGBColor>,
    label: &str,
    legend: RGBColor,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    let rects: Vec<_> = grid
        .iter()
        .enumerate()
        .flat_map(|(i, col)| {
            col.iter()
                .enumerate()
                .filter_map(move |(j, c)| pick(c).map(|color| (i, j, color)))
        })
        .map(|(i, j, color)| {
            Rectangle::new([(xe[i], ye[j]), (xe[i + 1], ye[j + 1])], color.filled())
        })
        .collect();
    if rects.is_empty() {
        return Ok(());
    }
    chart
        .draw_series(rects)
        .map_err(err)?
        .label(label)
        .legend(move |(px, py)| Rectangle::new([(px, py - 6), (px + 16, py + 6)], legend.filled()));
    Ok(())
}

/// The curves of the model file's `floquet:` references over the chart's axes (Kapitza's
/// boundary, the Mathieu chart's edges), each in its colour with a legend entry; curves of
/// fewer than two points are left out.
fn draw_reference_curves<DB: DrawingBackend>(
    chart: &mut LinearChart<'_, DB>,
    references: &FloquetReferences,
    model: &dyn ModelInfo,
    [x, y]: [ChartAxis<'_>; 2],
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    for curve in references.curves(model, x, y) {
        if curve.points.len() < 2 {
            continue;
        }
        let [r, g, b] = curve.color;
        let color = RGBColor(r, g, b);
        chart
            .draw_series(LineSeries::new(curve.points, color.stroke_width(3)))
            .map_err(err)?
            .label(curve.label)
            .legend(move |(px, py)| {
                PathElement::new(vec![(px, py), (px + 16, py)], color.stroke_width(3))
            });
    }
    Ok(())
}

/// The multipliers in the complex plane, with the unit circle.
fn multiplier_chart(path: &str, title: &str, floquet: &FloquetAnalysis) -> Result<(), String> {
    write_chart(path, (720, 720), &MultiplierChart { title, floquet })
}

/// The multipliers of [`multiplier_chart`], drawn.
struct MultiplierChart<'a> {
    title: &'a str,
    floquet: &'a FloquetAnalysis,
}

impl Drawing for MultiplierChart<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        draw_multipliers(root, self.title, self.floquet)
    }
}

fn draw_multipliers<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    floquet: &FloquetAnalysis,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    root.fill(&WHITE).map_err(err)?;
    let r = floquet
        .multipliers
        .iter()
        .map(|m| m.norm())
        .filter(|v| v.is_finite())
        .fold(1.0f64, f64::max)
        * 1.15;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(-r..r, -r..r)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("Re μ")
        .y_desc("Im μ")
        .x_label_formatter(&|v| tick(*v, false))
        .y_label_formatter(&|v| tick(*v, false))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    let circle: Vec<(f64, f64)> = (0..=360)
        .map(|k| {
            let phi = TAU * f64::from(k) / 360.0;
            (phi.cos(), phi.sin())
        })
        .collect();
    chart
        .draw_series(LineSeries::new(circle, BLACK.stroke_width(2)))
        .map_err(err)?
        .label("|μ| = 1")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK.stroke_width(2)));
    let color = RGBColor(200, 30, 30);
    chart
        .draw_series(
            floquet
                .multipliers
                .iter()
                .filter(|m| m.re.is_finite() && m.im.is_finite())
                .map(|m| Circle::new((m.re, m.im), 6, color.filled())),
        )
        .map_err(err)?
        .label(format!(
            "multipliers μ (ρ = {:.6}, {})",
            floquet.spectral_radius,
            floquet.stability.as_str().replace('_', " ")
        ))
        .legend(move |(x, y)| Circle::new((x + 8, y), 5, color.filled()));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}
