//! Charts with plotters: SVG or PNG chosen by the file extension.

use eomgen::outputs::OutputSeries;
use eomgen::{ModelInfo, Solution};
use plotters::coord::Shift;
use plotters::prelude::*;

/// A chart that draws itself on any plotters backend: what [`write_chart`] writes as SVG or
/// PNG. Each kind of chart is a small value holding what it shows.
pub(super) trait Drawing {
    /// Draws the whole picture on `root`.
    ///
    /// # Errors
    /// A message saying what could not be drawn.
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static;
}

/// Draws `chart` at `size` pixels in memory, in the format `path`'s extension names
/// ([`ChartFormat`]), and writes the file with [`super::files::write`] (atomically for a
/// regular file, in place for a device or FIFO); a drawing error is prefixed with the path.
/// Drawing in memory keeps the file system out of plotters: one writer handles regular
/// files, links, devices and FIFOs, and names the file and the operating system's reason
/// when a write fails. The one place a chart file is written.
///
/// # Errors
/// The bundled font not loading, an extension other than `.svg`/`.png`, a drawing error or
/// a failed write.
pub(super) fn write_chart(
    path: &str,
    size: (u32, u32),
    chart: &impl Drawing,
) -> Result<(), String> {
    register_font()?;
    let drawn = |result: Result<(), String>| result.map_err(|e| format!("`{path}`: {e}"));
    match ChartFormat::of(path)? {
        ChartFormat::Svg => {
            let mut text = String::new();
            drawn(chart.draw(SVGBackend::with_string(&mut text, size).into_drawing_area()))?;
            save_svg(path, &text)
        }
        ChartFormat::Png => {
            let mut pixels = vec![0u8; size.0 as usize * size.1 as usize * 3];
            drawn(chart.draw(BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area()))?;
            save_png(path, &pixels, size)
        }
    }
}

/// The charts' font, zlib-compressed (assets/fonts/README.md): 104 KB of the program
/// instead of 185 KB, inflated once, at the first chart, in about a millisecond.
static FONT_ZLIB: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf.zlib");

/// The font inflated (`None` if the embedded data were corrupt, which the tests exclude).
fn font() -> Option<&'static [u8]> {
    static FONT: std::sync::OnceLock<Option<Vec<u8>>> = std::sync::OnceLock::new();
    FONT.get_or_init(|| miniz_oxide::inflate::decompress_to_vec_zlib(FONT_ZLIB).ok())
        .as_deref()
}

/// Registers the bundled DejaVu Sans as plotters' `sans-serif`.
pub(super) fn register_font() -> Result<(), String> {
    let font = font().ok_or_else(|| "the bundled font could not be inflated".to_string())?;
    plotters::style::register_font("sans-serif", FontStyle::Normal, font)
        .map_err(|_| "the bundled font could not be loaded".to_string())
}

/// One named line of a chart: `(x, y)` points in order.
pub struct Series {
    /// Legend label.
    pub name: String,
    /// The points.
    pub points: Vec<(f64, f64)>,
}

/// A line chart: title, axis labels (with units) and which axes are logarithmic.
pub struct Chart<'a> {
    /// Caption.
    pub title: &'a str,
    /// x-axis label, with its unit.
    pub x_desc: &'a str,
    /// y-axis label, with its unit.
    pub y_desc: &'a str,
    /// Logarithmic x axis (points with x ≤ 0 are dropped).
    pub log_x: bool,
    /// Logarithmic y axis (points with y ≤ 0 are dropped).
    pub log_y: bool,
}

impl<'a> Chart<'a> {
    /// A chart with linear axes.
    pub fn linear(title: &'a str, x_desc: &'a str, y_desc: &'a str) -> Self {
        Self {
            title,
            x_desc,
            y_desc,
            log_x: false,
            log_y: false,
        }
    }
}

/// Plots the coordinates and rates `shown` against time into `path` (`.svg` or `.png`), one
/// panel each with its own scale (a spin of hundreds of radians beside a nutation of
/// hundredths), stacked over a shared time axis, with `note` (why the run is incomplete, if
/// it is) drawn in red above them. `shown` names components of the state `[q; q̇]` by their
/// index, or the model's output `k` (`outputs`, the run's, at every sample) as `2n + k`;
/// empty for every coordinate.
///
/// # Errors
/// An unknown extension, an empty solution, an output not among `outputs`, or a failure to
/// write the file.
pub fn time_histories(
    path: &str,
    model: &dyn ModelInfo,
    solution: &Solution,
    outputs: &[OutputSeries],
    shown: &[usize],
    note: Option<&str>,
) -> Result<(), String> {
    if solution.is_empty() {
        return Err("nothing to plot: the solution has no samples".to_string());
    }
    let d = model.description();
    let names = d.coordinate_names();
    let n = names.len();
    let indices: Vec<usize> = match shown.is_empty() {
        true => (0..n).collect(),
        false => shown.to_vec(),
    };
    let mut panels: Vec<Series> = Vec::with_capacity(indices.len());
    for &i in &indices {
        if i < 2 * n {
            let name = d.state_name(i);
            let points = solution.iter().map(|(t, y)| (t, y[i])).collect();
            panels.push(Series { name, points });
            continue;
        }
        // An output of the file, at every sample (evaluated with the run's report).
        let name = d.outputs.get(i - 2 * n).map_or("", |o| &*o.name);
        let Some(series) = outputs.iter().find(|o| o.name == name) else {
            return Err(format!(
                "the output `{name}` could not be evaluated along the run"
            ));
        };
        let points = (solution.t.iter().copied())
            .zip(series.values.iter().copied())
            .collect();
        panels.push(Series {
            name: name.to_string(),
            points,
        });
    }
    let title = format!("{}: against time", model.description().name);
    let height = (60 + 170 * panels.len()).max(600) as u32;
    write_chart(
        path,
        (960, height),
        &Panels {
            title: &title,
            panels: &panels,
            note,
        },
    )
}

/// The stacked panels of [`time_histories`]: one series each, over `t`.
struct Panels<'a> {
    title: &'a str,
    panels: &'a [Series],
    note: Option<&'a str>,
}

impl Drawing for Panels<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
        root.fill(&WHITE).map_err(err)?;
        // The note above everything, as on the other charts.
        let root = note_band(root, self.note)?;
        let titled = root.titled(self.title, ("sans-serif", 22)).map_err(err)?;
        for (area, series) in titled
            .split_evenly((self.panels.len(), 1))
            .iter()
            .zip(self.panels)
        {
            let chart = Chart::linear("", "t (s)", &series.name);
            draw_on(area, &chart, std::slice::from_ref(series), None)?;
        }
        root.present().map_err(err)?;
        Ok(())
    }
}

/// Draws one line per coordinate `i` of `model` into `path`: its name `name(coordinate)`,
/// its points `point(t, y, i, n)` at every sample `(t, y)` of `solution` (`n` coordinates),
/// with `note` drawn under the title ([`lines_noted`]).
///
/// # Errors
/// An empty solution, or the errors of [`lines`].
fn per_coordinate(
    path: &str,
    chart: &Chart<'_>,
    model: &dyn ModelInfo,
    solution: &Solution,
    name: impl Fn(&str) -> String,
    point: impl Fn(f64, &[f64], usize, usize) -> (f64, f64),
    note: Option<&str>,
) -> Result<(), String> {
    if solution.is_empty() {
        return Err("nothing to plot: the solution has no samples".to_string());
    }
    let n = model.num_dofs();
    let series: Vec<Series> = model
        .description()
        .coordinate_names()
        .iter()
        .enumerate()
        .map(|(i, coordinate)| Series {
            name: name(coordinate),
            points: solution.iter().map(|(t, y)| point(t, y, i, n)).collect(),
        })
        .collect();
    lines_noted(path, chart, &series, note)
}

/// Draws `series` as lines into `path` (`.svg` or `.png`), 960 × 600 px.
///
/// # Errors
/// An unknown extension, no finite point, or a failure to write the file.
pub fn lines(path: &str, chart: &Chart<'_>, series: &[Series]) -> Result<(), String> {
    lines_noted(path, chart, series, None)
}

/// [`lines`] with `note` (the reason a run is incomplete, say) drawn in red under the title.
/// The file is written by [`super::files::write`]: atomically for a regular file, in place
/// for a device or FIFO.
///
/// # Errors
/// As [`lines`].
pub fn lines_noted(
    path: &str,
    chart: &Chart<'_>,
    series: &[Series],
    note: Option<&str>,
) -> Result<(), String> {
    write_chart(
        path,
        (960, 600),
        &LineChart {
            chart,
            series,
            note,
        },
    )
}

/// The lines of [`lines_noted`], drawn.
struct LineChart<'a> {
    chart: &'a Chart<'a>,
    series: &'a [Series],
    note: Option<&'a str>,
}

impl Drawing for LineChart<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        draw(root, self.chart, self.series, self.note)
    }
}

/// Draws `series` into `path` with a logarithmic y axis; `labels` are the title and the x and
/// y axis descriptions.
pub(super) fn log_y_chart(
    path: &str,
    labels: [&str; 3],
    log_x: bool,
    series: &[Series],
) -> Result<(), super::error::CliError> {
    let [title, x_desc, y_desc] = labels;
    let chart = Chart {
        title,
        x_desc,
        y_desc,
        log_x,
        log_y: true,
    };
    lines(path, &chart, series).map_err(super::error::CliError::failure)
}

/// The chart `PREFIX-tag.svg` of an option that names a prefix for several charts, or
/// `.png` when the prefix ends in `.png` (a `.svg` ending is dropped): `out/dp` and
/// `out/dp.svg` give `out/dp-tag.svg`, `out/dp.png` gives `out/dp-tag.png`.
pub(super) fn chart_path(prefix: &str, tag: &str) -> String {
    if let Some(stem) = prefix.strip_suffix(".png") {
        format!("{stem}-{tag}.png")
    } else {
        let stem = prefix.strip_suffix(".svg").unwrap_or(prefix);
        format!("{stem}-{tag}.svg")
    }
}

/// The format of a chart file, named by its extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum ChartFormat {
    /// `.svg`.
    Svg,
    /// `.png`.
    Png,
}

impl ChartFormat {
    /// The format `path`'s extension names.
    ///
    /// # Errors
    /// A message naming `path` when it ends in neither `.svg` nor `.png` (the commands find
    /// this before any work, [`super::files::Outputs::check`]).
    pub(super) fn of(path: &str) -> Result<Self, String> {
        if path.ends_with(".svg") {
            Ok(Self::Svg)
        } else if path.ends_with(".png") {
            Ok(Self::Png)
        } else {
            Err(format!("`{path}`: a chart file must end in .svg or .png"))
        }
    }
}

/// Writes a drawn chart's bytes to `path` ([`super::files::write`]).
///
/// # Errors
/// The write error, naming the file and the operating system's reason.
pub(super) fn save(path: &str, bytes: &[u8]) -> Result<(), String> {
    super::files::write(path, bytes).map_err(|e| e.to_string())
}

/// The comment that marks an SVG as written by eomgen, right after its opening `<svg …>`
/// tag: how a later run recognises a stale chart of its own ([`is_own_drift_chart`]).
const SVG_SOFTWARE: &str = "<!-- Software: eomgen -->";

/// Writes a drawn SVG to `path` ([`save`]) with the [`SVG_SOFTWARE`] comment after its
/// opening tag.
///
/// # Errors
/// The write error, naming the file and the operating system's reason.
pub(super) fn save_svg(path: &str, svg: &str) -> Result<(), String> {
    let marked = match svg.split_once('\n') {
        Some((open, rest)) => format!("{open}\n{SVG_SOFTWARE}\n{rest}"),
        None => svg.to_string(),
    };
    save(path, marked.as_bytes())
}

/// Encodes `pixels` (RGB, 8 bits a channel, rows of `size.0`) as PNG, as plotters' own
/// bitmap files are encoded, with the text chunk `Software: eomgen` ([`PNG_SOFTWARE`]), and
/// writes it to `path` ([`save`]).
///
/// # Errors
/// A failed encoding, or the write error.
pub(super) fn save_png(
    path: &str,
    pixels: &[u8],
    (width, height): (u32, u32),
) -> Result<(), String> {
    let bytes = encode_png(pixels, (width, height))
        .map_err(|e| format!("`{path}`: cannot encode the PNG: {e}"))?;
    save(path, &bytes)
}

/// `pixels` (RGB, 8 bits per channel, by rows) as a PNG that carries the [`PNG_SOFTWARE`]
/// text chunk right after its header, written by the `png` crate.
fn encode_png(pixels: &[u8], (width, height): (u32, u32)) -> Result<Vec<u8>, png::EncodingError> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let (keyword, text) = PNG_SOFTWARE_TEXT;
    encoder.add_text_chunk(keyword.to_string(), text.to_string())?;
    let mut writer = encoder.write_header()?;
    writer.write_image_data(pixels)?;
    writer.finish()?;
    Ok(bytes)
}

/// The `tEXt` chunk that marks a PNG as written by eomgen (keyword `Software`, PNG
/// specification §11.3.4.2): how a later run recognises a stale chart of its own
/// ([`is_own_png`]) before removing it.
const PNG_SOFTWARE: &[u8] = b"Software\0eomgen";

/// [`PNG_SOFTWARE`]'s keyword and text.
const PNG_SOFTWARE_TEXT: (&str, &str) = ("Software", "eomgen");

/// The 8-byte PNG signature and the 25-byte `IHDR` chunk that every PNG starts with: the
/// `tEXt` chunk goes right after them.
const PNG_HEADER_LEN: usize = 8 + 25;

/// Whether `bytes` is a PNG that eomgen wrote: its first chunk after the header is the
/// [`PNG_SOFTWARE`] text chunk.
pub(super) fn is_own_png(bytes: &[u8]) -> bool {
    let start = PNG_HEADER_LEN + 8;
    bytes.starts_with(b"\x89PNG\r\n\x1a\n")
        && bytes.get(PNG_HEADER_LEN + 4..start) == Some(b"tEXt".as_slice())
        && bytes.get(start..start + PNG_SOFTWARE.len()) == Some(PNG_SOFTWARE)
}

/// Every constraint drift chart's title ([`constraint_drift`]) ends with this.
const DRIFT_TITLE: &str = ": constraint drift";

/// Whether `bytes` is a constraint drift chart that eomgen wrote: an SVG with eomgen's
/// comment ([`SVG_SOFTWARE`]) and the drift chart's title, or a PNG with eomgen's text chunk
/// ([`is_own_png`]).
pub(super) fn is_own_drift_chart(bytes: &[u8]) -> bool {
    is_own_chart(bytes, DRIFT_TITLE)
}

/// Whether `bytes` is a chart that eomgen wrote: a PNG with eomgen's `Software` text chunk, or
/// an SVG with the [`SVG_SOFTWARE`] comment whose text contains `title` (part of the chart's
/// title, which tells one kind of chart from another).
pub(super) fn is_own_chart(bytes: &[u8], title: &str) -> bool {
    let contains = |needle: &str| bytes.windows(needle.len()).any(|w| w == needle.as_bytes());
    is_own_png(bytes) || (bytes.starts_with(b"<svg") && contains(SVG_SOFTWARE) && contains(title))
}

/// The points of `s` that can be drawn on the chart's axes.
fn usable<'s>(chart: &Chart<'_>, s: &'s Series) -> impl Iterator<Item = (f64, f64)> + 's {
    let (log_x, log_y) = (chart.log_x, chart.log_y);
    s.points.iter().copied().filter(move |(x, y)| {
        x.is_finite() && y.is_finite() && (!log_x || *x > 0.0) && (!log_y || *y > 0.0)
    })
}

/// A tick label: `1e-5` on a log axis (plotters' default prints `9999999e-5`), else a
/// short decimal.
pub(super) fn tick(v: f64, log: bool) -> String {
    if log {
        let e = v.log10().round();
        if (v.log10() - e).abs() < 1e-6 {
            return format!("1e{e}");
        }
        return format!("{v:.1e}");
    }
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.1e}")
    } else {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".to_string()
        } else {
            s.to_string()
        }
    }
}

/// The offset a linear axis `[y0, y1]` labels its ticks from, where its span is below 1e-4
/// of its values (a nutation of 1e-7 rad about 0.5236 rad, whose ticks four decimals would
/// print alike): the middle of the axis to the digits the span leaves, shown in the axis's
/// description (`theta − 0.52359878`) while the ticks read the differences (`+1.0e-7`).
pub(super) fn tick_offset(y0: f64, y1: f64, log: bool) -> Option<f64> {
    let (span, middle) = (y1 - y0, 0.5 * (y0 + y1));
    if log || span.is_nan() || span <= 0.0 || !middle.is_finite() || span >= 1e-4 * middle.abs() {
        return None;
    }
    let decimals = (-(span / 10.0).log10()).ceil().clamp(0.0, 15.0) as i32;
    let scale = 10f64.powi(decimals);
    Some((middle * scale).round() / scale)
}

/// `[lo, hi]` padded by 5 % (or a factor for log axes), with a unit range for a constant.
pub(super) fn range(lo: f64, hi: f64, log: bool) -> (f64, f64) {
    if log {
        // Padding by a factor must not overflow to ∞ (plotters never returns on an infinite
        // log range) or underflow to 0.
        let (lo_pad, hi_pad) = if hi > lo { (1.5, 1.5) } else { (10.0, 10.0) };
        let hi = if hi > lo { hi } else { lo };
        (
            (lo / lo_pad).max(f64::MIN_POSITIVE),
            (hi * hi_pad).min(f64::MAX),
        )
    } else if hi > lo {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    } else {
        (lo - 1.0, hi + 1.0)
    }
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    chart: &Chart<'_>,
    series: &[Series],
    note: Option<&str>,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    root.fill(&WHITE).map_err(err)?;
    draw_on(&root, chart, series, note)?;
    root.present().map_err(err)?;
    Ok(())
}

/// `note` (why a run is incomplete), in red in a band of its own at the top of `root`, so
/// that no line can hide it; the rest of `root` below it (all of it without a note).
fn note_band<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    note: Option<&str>,
) -> Result<DrawingArea<DB, Shift>, String>
where
    DB::ErrorType: 'static,
{
    let Some(note) = note else {
        return Ok(root);
    };
    root.draw(&Text::new(
        note.to_string(),
        (12, 6),
        ("sans-serif", 16).into_font().color(&RED),
    ))
    .map_err(|e| format!("plotting failed: {e}"))?;
    Ok(root.margin(24, 0, 0, 0))
}

/// [`draw`] on a part of a picture, which the caller fills and presents (a panel of
/// [`time_histories`]); a chart with an empty title has no caption.
fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    chart: &Chart<'_>,
    series: &[Series],
    note: Option<&str>,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plotting failed: {e}");
    let root = note_band(root.clone(), note)?;
    let (mut x_lo, mut x_hi, mut y_lo, mut y_hi) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for s in series {
        for (x, y) in usable(chart, s) {
            x_lo = x_lo.min(x);
            x_hi = x_hi.max(x);
            y_lo = y_lo.min(y);
            y_hi = y_hi.max(y);
        }
    }
    if !(x_lo.is_finite() && y_lo.is_finite()) {
        return Err(format!(
            "nothing to plot in `{}`: no finite point",
            chart.title
        ));
    }
    let (x0, x1) = if chart.log_x || x_hi > x_lo {
        range(x_lo, x_hi, chart.log_x)
    } else {
        (x_lo, x_lo + 1.0)
    };
    let (y0, y1) = range(y_lo, y_hi, chart.log_y);
    let y_offset = tick_offset(y0, y1, chart.log_y);
    let y_desc = match y_offset {
        Some(offset) => format!("{} − {offset}", chart.y_desc),
        None => chart.y_desc.to_string(),
    };
    let mut builder = ChartBuilder::on(&root);
    if !chart.title.is_empty() {
        builder.caption(chart.title, ("sans-serif", 22));
    }
    builder
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(90);
    macro_rules! finish {
        ($ctx:expr) => {{
            let mut ctx = $ctx.map_err(err)?;
            let (log_x, log_y) = (chart.log_x, chart.log_y);
            ctx.configure_mesh()
                .x_desc(chart.x_desc)
                .y_desc(y_desc.as_str())
                .x_label_formatter(&|v| tick(*v, log_x))
                .y_label_formatter(&|v| match y_offset {
                    Some(offset) => format!("{:+.2e}", *v - offset),
                    None => tick(*v, log_y),
                })
                .label_style(("sans-serif", 14))
                .draw()
                .map_err(err)?;
            for (i, s) in series.iter().enumerate() {
                let color = Palette99::pick(i).to_rgba();
                ctx.draw_series(LineSeries::new(usable(chart, s), color.stroke_width(2)))
                    .map_err(err)?
                    .label(s.name.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
            }
            ctx.configure_series_labels()
                .position(legend_position(chart, series, (x0, x1), (y0, y1)))
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .label_font(("sans-serif", 14))
                .draw()
                .map_err(err)?;
        }};
    }
    match (chart.log_x, chart.log_y) {
        (false, false) => finish!(builder.build_cartesian_2d(x0..x1, y0..y1)),
        (true, false) => finish!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)),
        (false, true) => finish!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())),
        (true, true) => {
            finish!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale()))
        }
    }
    Ok(())
}

/// Where the legend hides the fewest points of the curves: plotters' default, the middle of
/// the right side, unless another corner or side is emptier (a phase portrait's closed
/// curves pass through the middle right). The legend's box is estimated from its labels
/// (14 px text, 20 px per line) on the plotting area of a 960 × 600 px chart, and the curves
/// are sampled along each segment so that a line crossing the box counts too.
fn legend_position(
    chart: &Chart<'_>,
    series: &[Series],
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> SeriesLabelPosition {
    // The plotting area (px) and the legend's box as fractions of it.
    let (width, height) = (840.0, 490.0);
    let longest = series
        .iter()
        .map(|s| s.name.chars().count())
        .max()
        .unwrap_or(0);
    let box_w = ((longest as f64 * 8.0 + 50.0) / width).min(1.0);
    let box_h = ((series.len() as f64 * 20.0 + 20.0) / height).min(1.0);
    let fraction = |v: f64, lo: f64, hi: f64, log: bool| {
        if log {
            (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
        } else {
            (v - lo) / (hi - lo)
        }
    };
    let mut points: Vec<(f64, f64)> = Vec::new();
    for s in series {
        let drawn: Vec<(f64, f64)> = usable(chart, s)
            .map(|(x, y)| {
                (
                    fraction(x, x0, x1, chart.log_x),
                    fraction(y, y0, y1, chart.log_y),
                )
            })
            .collect();
        for pair in drawn.windows(2) {
            let ((ax, ay), (bx, by)) = (pair[0], pair[1]);
            points.extend((0..8).map(|k| {
                let f = f64::from(k) / 8.0;
                (ax + f * (bx - ax), ay + f * (by - ay))
            }));
        }
        points.extend(drawn.last());
    }
    // Candidates in order of preference (ties keep the earlier), with the box's lower-left
    // corner in fractions of the plotting area (y up).
    let candidates = [
        (
            SeriesLabelPosition::MiddleRight,
            (1.0 - box_w, 0.5 - box_h / 2.0),
        ),
        (SeriesLabelPosition::UpperRight, (1.0 - box_w, 1.0 - box_h)),
        (SeriesLabelPosition::UpperLeft, (0.0, 1.0 - box_h)),
        (SeriesLabelPosition::LowerRight, (1.0 - box_w, 0.0)),
        (SeriesLabelPosition::LowerLeft, (0.0, 0.0)),
        (
            SeriesLabelPosition::UpperMiddle,
            (0.5 - box_w / 2.0, 1.0 - box_h),
        ),
        (SeriesLabelPosition::LowerMiddle, (0.5 - box_w / 2.0, 0.0)),
        (SeriesLabelPosition::MiddleLeft, (0.0, 0.5 - box_h / 2.0)),
    ];
    let hidden = |(left, bottom): (f64, f64)| {
        points
            .iter()
            .filter(|(x, y)| {
                (left..=left + box_w).contains(x) && (bottom..=bottom + box_h).contains(y)
            })
            .count()
    };
    let mut best = (SeriesLabelPosition::MiddleRight, usize::MAX);
    for (position, corner) in candidates {
        let count = hidden(corner);
        if count < best.1 {
            best = (position, count);
        }
    }
    best.0
}

/// Plots the phase portrait of every coordinate, `q̇ᵢ` against `qᵢ`, one line each, into
/// `path` (`.svg` or `.png`) — lecture 17's picture of a trajectory in the state plane; `note`
/// as in [`time_histories`].
///
/// # Errors
/// An unknown extension, an empty solution, or a failure to write the file.
pub fn phase_portrait(
    path: &str,
    model: &dyn ModelInfo,
    solution: &Solution,
    note: Option<&str>,
) -> Result<(), String> {
    let d = model.description();
    let title = format!("{}: phase portrait", d.name);
    // In generalized speeds the state's second half is `u`, drawn against the coordinate
    // under its own name (`w1 vs theta`).
    let axis = if d.has_speeds() {
        "u"
    } else {
        "q̇ (m/s or rad/s)"
    };
    let n = d.num_dofs();
    per_coordinate(
        path,
        &Chart::linear(&title, "q (m or rad)", axis),
        model,
        solution,
        |name| {
            let i = d.coordinate_index(name).unwrap_or(0);
            format!("{} vs {name}", d.state_name(n + i))
        },
        |_, y, i, n| (y[i], y[n + i]),
        note,
    )
}

/// Plots the energy drift `E(t) − E(0)` (J) against time into `path` (`.svg` or `.png`):
/// `energy[k] = T + V` at `t[k]` and `initial = E(0)`, the energy of the initial state (which
/// need not be a sample: with requested output times the first may come later), as
/// [`eomgen::analysis::energy_drift`] computes them. Constant for a conservative
/// model up to the integration error; for others it is the work of the non-conservative loads.
/// `note` as in [`time_histories`].
///
/// # Errors
/// An unknown extension, no samples, or a failure to write the file.
pub fn energy_drift(
    path: &str,
    name: &str,
    t: &[f64],
    energy: &[f64],
    initial: f64,
    note: Option<&str>,
) -> Result<(), String> {
    if t.is_empty() {
        return Err("nothing to plot: the solution has no samples".to_string());
    }
    let series = [Series {
        name: "E − E(0)".to_string(),
        points: t
            .iter()
            .zip(energy)
            .map(|(&t, e)| (t, e - initial))
            .collect(),
    }];
    let title = format!("{name}: energy drift");
    lines_noted(
        path,
        &Chart::linear(&title, "t (s)", "E − E(0) (J)"),
        &series,
        note,
    )
}

/// Plots the constraint drift of a constrained model against time into `path` (`.svg` or
/// `.png`), on a logarithmic axis: `max |Φᵢ|` and the largest velocity-level residual at each
/// time (`drift[k] = (position, velocity)` at `t[k]`, as [`ModelInfo::constraint_drift`]
/// gives them; exact zeros are left out of the log axis); `note` as in [`time_histories`].
///
/// # Errors
/// Unequal lengths, an unknown extension, no positive value, or a failure to write the file.
pub fn constraint_drift(
    path: &str,
    model: &str,
    t: &[f64],
    drift: &[(f64, f64)],
    note: Option<&str>,
) -> Result<(), String> {
    if t.len() != drift.len() {
        return Err(format!(
            "constraint drift: {} times but {} residuals",
            t.len(),
            drift.len()
        ));
    }
    let series = [
        Series {
            name: "max |Φ|".to_string(),
            points: t.iter().zip(drift).map(|(t, d)| (*t, d.0)).collect(),
        },
        Series {
            name: "max |Φ̇|".to_string(),
            points: t.iter().zip(drift).map(|(t, d)| (*t, d.1)).collect(),
        },
    ];
    let title = format!("{model}{DRIFT_TITLE}");
    lines_noted(
        path,
        &Chart {
            title: &title,
            x_desc: "t (s)",
            y_desc: "residual (units of Φ, Φ̇)",
            log_x: false,
            log_y: true,
        },
        &series,
        note,
    )
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_narrow_axis_labels_its_ticks_from_an_offset() {
        use super::tick_offset;
        // A nutation of 2e-7 rad about 0.7236 rad: an offset to 8 decimals.
        let offset = tick_offset(0.7235986, 0.7235988, false).unwrap();
        assert!((offset - 0.7235987).abs() < 1e-12, "{offset}");
        // An axis wide beside its values, a log axis or a constant has none.
        assert_eq!(tick_offset(0.2, 0.4, false), None);
        assert_eq!(tick_offset(1e-9, 1e-8, true), None);
        assert_eq!(tick_offset(0.5, 0.5, false), None);
        // Around zero there is nothing to take off.
        assert_eq!(tick_offset(-1e-9, 1e-9, false), None);
    }

    use super::*;

    /// A PNG written here carries the software chunk where [`is_own_png`] looks for it and
    /// decodes to the pixels given; a PNG without it is not ours.
    #[test]
    fn a_png_carries_the_software_chunk() {
        let pixels: Vec<u8> = (0..12).collect();
        let marked = encode_png(&pixels, (2, 2)).unwrap();
        assert!(is_own_png(&marked));
        let decoder = png::Decoder::new(std::io::Cursor::new(&marked));
        let mut reader = decoder.read_info().unwrap();
        let mut decoded = vec![0; reader.output_buffer_size()];
        reader.next_frame(&mut decoded).unwrap();
        assert_eq!(decoded, pixels);
        let text = &reader.info().uncompressed_latin1_text;
        assert_eq!(
            (text[0].keyword.as_str(), text[0].text.as_str()),
            PNG_SOFTWARE_TEXT
        );
        let mut plain = marked.clone();
        plain[PNG_HEADER_LEN + 4..PNG_HEADER_LEN + 8].copy_from_slice(b"zTXt");
        assert!(!is_own_png(&plain));
    }

    /// A phase portrait's closed curve through the middle of the right side moves the legend
    /// to an empty corner; a curve that leaves the middle right empty keeps plotters' default.
    #[test]
    fn the_legend_goes_where_it_hides_nothing() {
        let chart = Chart::linear("t", "x", "y");
        let ellipse = |phase: f64| Series {
            name: "q_dot vs q".to_string(),
            points: (0..=200)
                .map(|k| {
                    let a = phase + std::f64::consts::TAU * f64::from(k) / 200.0;
                    (a.cos(), 0.5 * a.sin())
                })
                .collect(),
        };
        let series = [ellipse(0.0)];
        let (x, y) = ((-1.1, 1.1), (-0.55, 0.55));
        let position = legend_position(&chart, &series, x, y);
        assert!(
            !matches!(position, SeriesLabelPosition::MiddleRight),
            "the ellipse crosses the middle right"
        );
        let rising = [Series {
            name: "x".to_string(),
            points: vec![(0.0, 0.0), (0.5, 1.0)],
        }];
        let position = legend_position(&chart, &rising, (0.0, 1.0), (0.0, 1.0));
        assert!(matches!(position, SeriesLabelPosition::MiddleRight));
    }
}
