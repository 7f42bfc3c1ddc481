//! Mode-shape charts of `eomgen modes MODEL --plot PREFIX` (issue 7, item 8; lectures 22–29,
//! HW23–31): the mechanism drawn with its `draw:` lines at the equilibrium and displaced by
//! `± s ψₖ` along each mode shape.
//!
//! Each chart shows the equilibrium `q*` in grey and the configurations `q* + s ψₖ` and
//! `q* − s ψₖ` in colour, every point placed by the model's own (nonlinear) point positions.
//! The scale `s` makes the largest point displacement of the linearised shape a fifth of the
//! mechanism's size (the larger side of its bounding box at `q*`), so that shapes of every
//! mode read alike whatever their mass normalisation. Axes have equal scales, so angles and
//! lengths look as they are; 3-D models are drawn in an isometric view.

use eomgen::animation::drawing::{
    Frame, Layout, describe, displaced, drawing_size, each_mode, frame, is_three_d, mode_scale,
};
use eomgen::text::significant;
use eomgen::{ModelInfo, NormalModes};
use nalgebra::DMatrix;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::error::CliError;
use super::plot::{Drawing, tick, write_chart};

/// Chart size (px).
const SIZE: (u32, u32) = (900, 760);
/// Margin, x-label and y-label areas of the chart (px).
const MARGIN: u32 = 16;
const X_LABEL_AREA: u32 = 45;
const Y_LABEL_AREA: u32 = 70;

/// `PREFIX-mode<k>.svg`, or `.png` when the prefix ends in `.png` (`k` counts from 1).
pub fn chart_path(prefix: &str, mode: usize) -> String {
    super::plot::chart_path(prefix, &format!("mode{mode}"))
}

/// Checks that `model` has points to draw a mode shape on.
///
/// # Errors
/// A usage error naming the model when it has no `points:` (an energy-form model).
pub fn check_drawable(model: &dyn ModelInfo) -> Result<(), CliError> {
    if model.description().point_names().is_empty() {
        return Err(CliError::usage(format!(
            "`{}` has no points, so there is no mechanism to draw its mode shapes on; drop --plot, or give the model file `points:` and `draw: {{ lines: [[A, B]] }}`",
            model.description().name
        )));
    }
    Ok(())
}

/// One chart: its title, the three frames and the legend labels of the displaced ones.
struct ModeDrawing {
    title: String,
    equilibrium: Frame,
    displaced: Option<[(Frame, String); 2]>,
}

/// Writes one chart per mode, `PREFIX-mode<k>.svg` (or `.png`), and returns the paths.
///
/// `q` is the equilibrium the modes were computed at (length `n`), `modes` its normal modes
/// and `shapes` their shapes in the model's coordinates (`n × r`; `N Ψ` for a constrained
/// model, whose modes are computed in minimal coordinates); `c_left_out` whether the
/// linearisation has a velocity matrix `C` that the modes of `M` and `K` leave out (see
/// [`describe`]).
///
/// # Errors
/// A usage error when the model has no points ([`check_drawable`]); a failure when a file
/// cannot be written or a displaced configuration is not finite.
pub fn mode_charts(
    prefix: &str,
    model: &dyn ModelInfo,
    q: &[f64],
    modes: &NormalModes,
    shapes: &DMatrix<f64>,
    c_left_out: bool,
) -> Result<Vec<String>, CliError> {
    check_drawable(model)?;
    let layout = Layout::of(model, is_three_d(model, q, shapes));
    let rest = frame(model, &layout, q);
    let size = drawing_size(&rest, &layout.dots);
    let mut paths = Vec::with_capacity(modes.natural_frequencies.len());
    for (k, omega, kind, psi) in each_mode(modes, shapes) {
        let at = |s: f64| displaced(q, &psi, s);
        let mut title = format!(
            "{}, {}",
            model.description().name,
            describe(k + 1, omega, kind, c_left_out)
        );
        let displaced = if let Some(s) = mode_scale(model, &layout, q, &psi, size) {
            let plus = frame(model, &layout, &at(s));
            let minus = frame(model, &layout, &at(-s));
            let finite = |f: &Frame| f.iter().all(|(x, y)| x.is_finite() && y.is_finite());
            if !(finite(&plus) && finite(&minus)) {
                return Err(CliError::failure(format!(
                    "`{}`: mode {} displaced by ±{s:.3e} ψ leaves the model's domain (a point is not finite)",
                    model.description().name,
                    k + 1
                )));
            }
            Some([
                (plus, format!("q* + {} ψ{}", significant(s), k + 1)),
                (minus, format!("q* − {} ψ{}", significant(s), k + 1)),
            ])
        } else {
            title.push_str(" (moves no drawn point)");
            None
        };
        let path = chart_path(prefix, k + 1);
        let drawing = ModeDrawing {
            title,
            equilibrium: rest.clone(),
            displaced,
        };
        // The messages name the file (a write error names it itself).
        write_chart(
            &path,
            SIZE,
            &ModeChart {
                layout: &layout,
                drawing: &drawing,
            },
        )
        .map_err(CliError::failure)?;
        paths.push(path);
    }
    Ok(paths)
}

/// Removes the charts `PREFIX-mode<k>` (`k` from `written + 1` on, while such a file is
/// there) that an earlier run wrote for modes this run does not have (a model with more
/// modes), so that the charts beside the prefix come from one run: each is removed only if
/// eomgen wrote it (its Software mark and a mode chart's title, as
/// [`files::remove_stale`](super::files::remove_stale) recognises companion files); a file of
/// that name that eomgen did not write is kept, with a warning.
///
/// # Errors
/// A chart of ours that cannot be removed.
pub fn remove_stale_charts(prefix: &str, written: usize) -> Result<(), CliError> {
    for k in written + 1.. {
        let path = chart_path(prefix, k);
        if std::fs::symlink_metadata(&path).is_err() {
            return Ok(());
        }
        super::files::remove_stale_or_warn(&path, |bytes| {
            super::plot::is_own_chart(bytes, MODE_TITLE)
        })?;
    }
    Ok(())
}

/// Every mode chart's title has this after the model's name ([`describe`]).
const MODE_TITLE: &str = ", mode ";

/// A tick label; a tick within rounding of 0 (`1e-16` from the range arithmetic) reads `0`.
fn label(v: f64, span: f64) -> String {
    if v.abs() <= 1e-9 * span.abs() {
        "0".to_string()
    } else {
        tick(v, false)
    }
}

/// `[lo, hi]` of x and y widened so that one metre is as long on both axes for a plotting
/// area of `pixels`, with a 10 % border.
fn equal_ranges(frames: &[&Frame], dots: &[usize], pixels: (f64, f64)) -> ((f64, f64), (f64, f64)) {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for f in frames {
        for &i in dots {
            x0 = x0.min(f[i].0);
            x1 = x1.max(f[i].0);
            y0 = y0.min(f[i].1);
            y1 = y1.max(f[i].1);
        }
    }
    let span = (x1 - x0).max(y1 - y0);
    let span = if span > 0.0 { span } else { 1.0 };
    let pad = 0.1 * span;
    let (w, h) = (x1 - x0 + 2.0 * pad, y1 - y0 + 2.0 * pad);
    // Metres per pixel: the larger of the two, then each range grown about its centre.
    let per_pixel = (w / pixels.0).max(h / pixels.1);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (hw, hh) = (0.5 * per_pixel * pixels.0, 0.5 * per_pixel * pixels.1);
    ((cx - hw, cx + hw), (cy - hh, cy + hh))
}

/// One mode chart of [`mode_charts`], drawn.
struct ModeChart<'a> {
    layout: &'a Layout,
    drawing: &'a ModeDrawing,
}

impl Drawing for ModeChart<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        draw(root, self.layout, self.drawing)
    }
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    layout: &Layout,
    drawing: &ModeDrawing,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    root.fill(&WHITE).map_err(err)?;
    let area = root
        .titled(&drawing.title, ("sans-serif", 20))
        .map_err(err)?;
    let (w, h) = area.dim_in_pixel();
    let pixels = (
        f64::from(w.saturating_sub(2 * MARGIN + Y_LABEL_AREA).max(1)),
        f64::from(h.saturating_sub(2 * MARGIN + X_LABEL_AREA).max(1)),
    );
    let mut frames = vec![&drawing.equilibrium];
    if let Some([plus, minus]) = &drawing.displaced {
        frames.push(&plus.0);
        frames.push(&minus.0);
    }
    let ((x0, x1), (y0, y1)) = equal_ranges(&frames, &layout.dots, pixels);
    let mut ctx = ChartBuilder::on(&area)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    let (x_desc, y_desc) = if layout.three_d {
        (
            "isometric view: (x − y) cos 30° (m)",
            "z + (x + y) sin 30° (m)",
        )
    } else {
        ("x (m)", "y (m)")
    };
    ctx.configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|v| label(*v, x1 - x0))
        .y_label_formatter(&|v| label(*v, y1 - y0))
        .label_style(("sans-serif", 14))
        .light_line_style(WHITE)
        .draw()
        .map_err(err)?;
    let grey = RGBColor(150, 150, 150);
    let mut styled: Vec<(&Frame, RGBAColor, String)> = vec![(
        &drawing.equilibrium,
        grey.to_rgba(),
        "equilibrium q*".to_string(),
    )];
    if let Some([plus, minus]) = &drawing.displaced {
        styled.push((&plus.0, RGBColor(214, 39, 40).to_rgba(), plus.1.clone()));
        styled.push((&minus.0, RGBColor(31, 119, 180).to_rgba(), minus.1.clone()));
    }
    for (f, color, label) in &styled {
        let color = *color;
        let style = color.stroke_width(3);
        let mut first = true;
        for [a, b] in &layout.lines {
            let series = ctx
                .draw_series(LineSeries::new([f[*a], f[*b]], style))
                .map_err(err)?;
            if first {
                series.label(label.clone()).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(3))
                });
                first = false;
            }
        }
        let dots = ctx
            .draw_series(
                layout
                    .dots
                    .iter()
                    .map(|&i| Circle::new(f[i], 5, color.filled())),
            )
            .map_err(err)?;
        if layout.lines.is_empty() {
            dots.label(label.clone())
                .legend(move |(x, y)| Circle::new((x + 10, y), 5, color.filled()));
        }
    }
    ctx.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    mod fixture {
        eomgen::model!("../../symbolic/tests/fixtures/damped_oscillator.yaml");
    }

    /// An energy-form model has no points: a usage error (exit 2) that says why, no file.
    #[test]
    fn a_model_without_points_gets_a_clear_message() {
        let model = eomgen::FirstOrder::new(fixture::DampedOscillator::default());
        let e = check_drawable(&model).expect_err("no points");
        assert_eq!(e.code, 2);
        assert!(e.message.contains("has no points"), "{}", e.message);
    }

    #[test]
    fn chart_paths_follow_the_prefix() {
        assert_eq!(chart_path("out/dp", 2), "out/dp-mode2.svg");
        assert_eq!(chart_path("out/dp.svg", 1), "out/dp-mode1.svg");
        assert_eq!(chart_path("out/dp.png", 3), "out/dp-mode3.png");
    }

    /// Equal scales: metres per pixel are the same on both axes, and every point is inside.
    #[test]
    fn ranges_have_equal_scales() {
        let f: Frame = vec![(0.0, 0.0), (3.0, 1.0), (1.0, -0.5)];
        let ((x0, x1), (y0, y1)) = equal_ranges(&[&f], &[0, 1, 2], (800.0, 600.0));
        assert!((((x1 - x0) / 800.0) - ((y1 - y0) / 600.0)).abs() < 1e-15);
        assert!(x0 < 0.0 && x1 > 3.0 && y0 < -0.5 && y1 > 1.0);
    }
}
