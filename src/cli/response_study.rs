//! What the free-vibration studies (`free-response`, `modal-damping`) share: `--init`
//! parsing, their errors in the options' words, the JSON of a mode kind and the chart of
//! stacked panels against time.

use eomgen::ModelInfo;
use eomgen::analysis::vibration::{InitialDeviation, ResponseStudyError};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::error::CliError;
use super::operating_point::{modal_failure, point_failure};
use super::plot::{self, Series};
use eomgen::expressions::set_linearized_values;

/// Parses `--init NAME=VALUE,…` (repeatable, as `simulate --init`) into `(δq₀, δq̇₀)`,
/// starting from zeros (`None` without `--init`: the study's default).
pub(super) fn parse_init(
    model: &dyn ModelInfo,
    init: &[String],
) -> Result<Option<InitialDeviation>, CliError> {
    if init.is_empty() {
        return Ok(None);
    }
    // The deviation from rest, as `--init` sets a state: [δq₀; δq̇₀] from zeros.
    let n = model.num_dofs();
    let mut y = vec![0.0; 2 * n];
    set_linearized_values(model, &mut y, init).map_err(super::values::usage)?;
    let v0 = y.split_off(n);
    let q0 = y;
    Ok(Some(InitialDeviation { q: q0, qdot: v0 }))
}

/// The error of a failed free-response or modal-damping study of `model`, in the words of
/// the options (`--tol`, `--t-end`, `--rayleigh-modes`); failed searches get their hint.
pub(super) fn study_failure(model: &dyn ModelInfo, e: &ResponseStudyError) -> CliError {
    match e {
        ResponseStudyError::OperatingPoint(e) => point_failure(model, e),
        ResponseStudyError::Constrained { model: name } => CliError::usage(format!(
            "`{name}` has constraints; this study takes unconstrained models (`eomgen modes {name}` gives its modes in minimal coordinates)"
        )),
        ResponseStudyError::InvalidTolerance { .. } => CliError::usage("--tol must be positive"),
        ResponseStudyError::InvalidEndTime { t_end } => CliError::usage(format!(
            "--t-end must be positive and finite, got {:e}",
            super::render::num(t_end)
        )),
        ResponseStudyError::TooFewSamples { .. } => CliError::usage("--samples must be at least 2"),
        ResponseStudyError::NoSuchMode { .. } | ResponseStudyError::NotUnderdamped { .. } => {
            CliError::usage(format!("--rayleigh-modes: {e}"))
        }
        ResponseStudyError::RayleighFit {
            modes: [a, b],
            source,
        } => CliError::usage(format!("--rayleigh-modes {a},{b}: {source}")),
        ResponseStudyError::Response(e) => response_failure(model, e),
        e => CliError::failure(format!("`{}`: {e}", model.description().name)),
    }
}

/// One panel of a stacked chart: an optional caption, the y-axis label (with units) and the
/// lines against time.
pub(super) struct Panel {
    /// Shown above the panel.
    pub caption: Option<String>,
    /// The y-axis label, with its unit.
    pub y_desc: String,
    /// The lines, drawn in this order.
    pub series: Vec<Series>,
}

/// A chart of stacked panels sharing the time axis, each with its own y label and lines
/// (drawn thick to thin, so that coinciding lines all stay visible), into `path` (`.svg` or
/// `.png`).
///
/// # Errors
/// An unknown extension, a panel with no finite point, or a failure to write the file.
pub(super) fn panels(path: &str, title: &str, panels: &[Panel]) -> Result<(), String> {
    let size = (960, 60 + 260 * panels.len().max(1) as u32);
    plot::write_chart(path, size, &PanelChart { title, panels })
}

/// The panels of [`panels`], drawn.
struct PanelChart<'a> {
    title: &'a str,
    panels: &'a [Panel],
}

impl plot::Drawing for PanelChart<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        draw_panels(root, self.title, self.panels)
    }
}

fn draw_panels<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    panels: &[Panel],
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(err)?;
    let areas = root.split_evenly((panels.len().max(1), 1));
    for (panel, area) in panels.iter().zip(&areas) {
        let (y_desc, series) = (&panel.y_desc, &panel.series);
        let finite = || {
            series
                .iter()
                .flat_map(|s| s.points.iter())
                .filter(|(x, y)| x.is_finite() && y.is_finite())
        };
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for (x, y) in finite() {
            x0 = x0.min(*x);
            x1 = x1.max(*x);
            y0 = y0.min(*y);
            y1 = y1.max(*y);
        }
        if !(x0.is_finite() && y0.is_finite()) {
            return Err(format!("nothing to plot for `{y_desc}`: no finite point"));
        }
        let (x0, x1) = plot::range(x0, x1, false);
        let (y0, y1) = plot::range(y0, y1, false);
        let mut builder = ChartBuilder::on(area);
        builder
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(90);
        if let Some(caption) = &panel.caption {
            builder.caption(caption, ("sans-serif", 16));
        }
        let mut ctx = builder.build_cartesian_2d(x0..x1, y0..y1).map_err(err)?;
        // Ticks within rounding of zero print as 0, not as 1e-17.
        let snap = |v: f64, span: f64| if v.abs() < 1e-9 * span { 0.0 } else { v };
        let (x_span, y_span) = (x1 - x0, y1 - y0);
        ctx.configure_mesh()
            .x_desc("t (s)")
            .y_desc(y_desc.as_str())
            .x_label_formatter(&|v| plot::tick(snap(*v, x_span), false))
            .y_label_formatter(&|v| plot::tick(snap(*v, y_span), false))
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(err)?;
        let count = series.len();
        for (i, s) in series.iter().enumerate() {
            let color = Palette99::pick(i).to_rgba();
            let width = 1 + 2 * (count - 1 - i) as u32;
            let points = s
                .points
                .iter()
                .copied()
                .filter(|(x, y)| x.is_finite() && y.is_finite());
            ctx.draw_series(LineSeries::new(points, color.stroke_width(width)))
                .map_err(err)?
                .label(s.name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(width))
                });
        }
        ctx.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .draw()
            .map_err(err)?;
    }
    root.present().map_err(err)?;
    Ok(())
}

/// The error of a failed response computation of `model`; a modal failure gets its hint
/// ([`modal_failure`]).
pub(super) fn response_failure(model: &dyn ModelInfo, e: &eomgen::ResponseError) -> CliError {
    match e {
        eomgen::ResponseError::Modal(m) => modal_failure(model, m),
        e => CliError::failure(format!("`{}`: {e}", model.description().name)),
    }
}
