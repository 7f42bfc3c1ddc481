//! Charts with plotters: SVG or PNG chosen by the file extension.

use eomgen::{ModelInfo, Solution};
use plotters::prelude::*;

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

fn register_font() -> Result<(), String> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| "the bundled font could not be loaded".to_string())
}

/// Plots every coordinate against time, one line each, into `path` (`.svg` or `.png`).
///
/// # Errors
/// An unknown extension, an empty solution, or a failure to write the file.
pub fn time_histories(
    path: &str,
    model: &dyn ModelInfo,
    solution: &Solution,
) -> Result<(), String> {
    if solution.is_empty() {
        return Err("nothing to plot: the solution has no samples".to_string());
    }
    register_font()?;
    let size = (960, 600);
    if path.ends_with(".svg") {
        let root = SVGBackend::new(path, size).into_drawing_area();
        draw(root, model, solution)
    } else if path.ends_with(".png") {
        let root = BitMapBackend::new(path, size).into_drawing_area();
        draw(root, model, solution)
    } else {
        Err(format!(
            "--plot `{path}`: the file must end in .svg or .png"
        ))
    }
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    model: &dyn ModelInfo,
    solution: &Solution,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    root.fill(&WHITE).map_err(err)?;
    let n = model.num_dofs();
    let t0 = solution.t.first().copied().unwrap_or(0.0);
    let t1 = solution.t.last().copied().unwrap_or(1.0).max(t0 + 1e-12);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (_, y) in solution.iter() {
        for v in &y[..n] {
            if v.is_finite() {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
    }
    // No finite sample, or a constant signal: give the axis a unit range.
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        lo -= 1.0;
        hi += 1.0;
    }
    let pad = 0.05 * (hi - lo);
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{}: coordinates against time", model.name()),
            ("sans-serif", 22),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(t0..t1, (lo - pad)..(hi + pad))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("t (s)")
        .y_desc("q (m or rad)")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    for (i, name) in model.coordinate_names().iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(
                solution.iter().map(|(t, y)| (t, y[i])),
                color.stroke_width(2),
            ))
            .map_err(err)?
            .label(*name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}
