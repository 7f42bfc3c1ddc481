//! The geometry of a model's drawing, shared by the animation page and the command line's
//! mode-shape charts: the points placed by the model's own (nonlinear) point positions,
//! projected onto the picture plane (3-D models in an isometric view), configurations
//! displaced along a mode shape, and the scale that makes every mode's drawing read alike.

use eomgen_runtime::{ModeKind, ModelInfo, NormalModes};
use nalgebra::DMatrix;

use crate::text::significant;

/// Largest point displacement of a drawn mode, as a fraction of the mechanism's size
/// ([`mode_scale`]).
pub const AMPLITUDE_FRACTION: f64 = 0.2;

/// The drawing of one configuration: the picture-plane coordinates `(x, y)` of every point
/// drawn (m), in the order of the points they are projected from.
pub type Frame = Vec<(f64, f64)>;

/// What a mode-shape chart draws: the point pairs of the lines, the points marked with a dot
/// and the view.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Point indices (among the model's points) of the `draw:` lines.
    pub lines: Vec<[usize; 2]>,
    /// Indices (among the model's points) of the points marked with a dot, increasing.
    pub dots: Vec<usize>,
    /// Whether the view is isometric (a 3-D model; see [`Layout::project`]).
    pub three_d: bool,
}

impl Layout {
    /// The model's `draw:` lines and trace points as indices; the points marked are the
    /// lines' ends and the traced points, or every point when the file draws nothing.
    /// `three_d`: whether any point leaves the plane z = 0 ([`is_three_d`]).
    pub fn of(model: &dyn ModelInfo, three_d: bool) -> Self {
        let names = model.description().point_names();
        let index = |n: &str| names.iter().position(|p| *p == n);
        let lines: Vec<[usize; 2]> = model
            .description()
            .draw_line_names()
            .iter()
            .filter_map(|[a, b]| Some([index(a)?, index(b)?]))
            .collect();
        let mut dots: Vec<usize> = lines.iter().flatten().copied().collect();
        dots.extend(
            model
                .description()
                .trace_point_names()
                .iter()
                .filter_map(|p| index(p)),
        );
        if dots.is_empty() {
            dots = (0..names.len()).collect();
        }
        dots.sort_unstable();
        dots.dedup();
        Self {
            lines,
            dots,
            three_d,
        }
    }

    /// The picture coordinates of a point `p = [x, y, z]` (m): `(x, y)`, or for a 3-D model
    /// the isometric view `((x − y) cos 30°, z + (x + y) sin 30°)`.
    pub fn project(&self, p: [f64; 3]) -> (f64, f64) {
        if self.three_d {
            let c = 30f64.to_radians();
            ((p[0] - p[1]) * c.cos(), p[2] + (p[0] + p[1]) * c.sin())
        } else {
            (p[0], p[1])
        }
    }
}

/// Positions `[x, y, z]` (m) of every point of `model` at the coordinates `q` (length `n`;
/// the rates, which do not move a point, are taken as zero, and `t` as 0).
pub fn positions(model: &dyn ModelInfo, q: &[f64]) -> Vec<[f64; 3]> {
    let y: Vec<f64> = q
        .iter()
        .copied()
        .chain(std::iter::repeat_n(0.0, q.len()))
        .collect();
    model.point_positions(0.0, &y)
}

/// The configuration `q + s ψ` (`q` and `ψ` of length `n`).
pub fn displaced(q: &[f64], psi: &[f64], s: f64) -> Vec<f64> {
    q.iter().zip(psi).map(|(a, p)| a + s * p).collect()
}

/// Every mode of `modes` as `(k, ω, kind, ψ)`: its index from 0, natural frequency (rad/s),
/// kind and shape (column `k` of `shapes`, `n × r` in the model's coordinates).
///
/// # Panics
/// If `shapes` has fewer columns than `modes` has frequencies.
pub fn each_mode<'a>(
    modes: &'a NormalModes,
    shapes: &'a DMatrix<f64>,
) -> impl Iterator<Item = (usize, f64, ModeKind, Vec<f64>)> + 'a {
    modes
        .natural_frequencies
        .iter()
        .zip(&modes.kinds)
        .enumerate()
        .map(|(k, (&omega, &kind))| (k, omega, kind, shapes.column(k).iter().copied().collect()))
}

/// Positions of every point of `model` at `q` ([`positions`]), projected by `layout`.
pub fn frame(model: &dyn ModelInfo, layout: &Layout, q: &[f64]) -> Frame {
    positions(model, q)
        .into_iter()
        .map(|p| layout.project(p))
        .collect()
}

/// The largest distance (m) between the points `which` of two frames.
fn largest_distance(a: &Frame, b: &Frame, which: &[usize]) -> f64 {
    which
        .iter()
        .map(|&i| (a[i].0 - b[i].0).hypot(a[i].1 - b[i].1))
        .fold(0.0, f64::max)
}

/// What a drawing says about mode `k` (counted from 1) of natural frequency `omega` (rad/s)
/// and `kind`: a mode-shape chart's title, an animated mode's info line. The shapes are the
/// modes of `M` and `K`; where the linearisation also has a velocity matrix `C`
/// (`c_left_out`: damping or gyroscopic terms, which can stabilise what `K` alone would not,
/// or the reverse), the text says that they are the undamped modes and what `K` alone
/// predicts, not the verdict of the whole linearisation (which `eomgen modes` prints).
pub fn describe(k: usize, omega: f64, kind: ModeKind, c_left_out: bool) -> String {
    let hz = omega / std::f64::consts::TAU;
    let mode = if c_left_out {
        format!("undamped mode {k} (M, K without C)")
    } else {
        format!("mode {k}")
    };
    match kind {
        ModeKind::Oscillatory => format!(
            "{mode}: ω = {} rad/s ({} Hz), oscillatory",
            significant(omega),
            significant(hz)
        ),
        ModeKind::ZeroFrequency => {
            format!("{mode}: ω = 0 rad/s, zero-frequency (rigid-body or mechanism)")
        }
        ModeKind::Unstable { growth_rate } if c_left_out => format!(
            "{mode}: negative stiffness, σ = {} 1/s without C",
            significant(growth_rate)
        ),
        ModeKind::Unstable { growth_rate } => format!(
            "{mode}: unstable, grows as e^(σt), σ = {} 1/s",
            significant(growth_rate)
        ),
    }
}

/// Whether a 3-D view is needed: a point off the plane z = 0 at `q` (length `n`) or along
/// some column of `shapes` (`n × r`).
pub fn is_three_d(model: &dyn ModelInfo, q: &[f64], shapes: &DMatrix<f64>) -> bool {
    std::iter::once(q.to_vec())
        .chain((0..shapes.ncols()).map(|k| {
            let psi: Vec<f64> = shapes.column(k).iter().copied().collect();
            displaced(q, &psi, 1e-3)
        }))
        .any(|qk| positions(model, &qk).iter().any(|p| p[2] != 0.0))
}

/// The mechanism's size (m): the larger side of the bounding box of the points `which` of
/// `frame`, or 1 when it is empty or degenerate.
pub fn drawing_size(frame: &Frame, which: &[usize]) -> f64 {
    let (mut lo, mut hi) = (
        (f64::INFINITY, f64::INFINITY),
        (f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    for &i in which {
        lo = (lo.0.min(frame[i].0), lo.1.min(frame[i].1));
        hi = (hi.0.max(frame[i].0), hi.1.max(frame[i].1));
    }
    let size = (hi.0 - lo.0).max(hi.1 - lo.1);
    if size.is_finite() && size > 0.0 {
        size
    } else {
        1.0
    }
}

/// The scale `s` of a drawn mode `q* + s ψ` (`q` the equilibrium `q*` and `psi` the shape `ψ`,
/// both of length `n`): the largest linearised displacement of the points `layout.dots` is
/// [`AMPLITUDE_FRACTION`] of `size` (m, [`drawing_size`]); `None` when the mode moves no
/// drawn point.
pub fn mode_scale(
    model: &dyn ModelInfo,
    layout: &Layout,
    q: &[f64],
    psi: &[f64],
    size: f64,
) -> Option<f64> {
    let at = |s: f64| displaced(q, psi, s);
    // The linearised displacement of the points per unit of s, by a central difference with
    // a step small against q.
    let q_scale = 1.0 + q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let psi_max = psi.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let h = 1e-6 * q_scale / psi_max.max(f64::MIN_POSITIVE);
    let rate = largest_distance(
        &frame(model, layout, &at(h)),
        &frame(model, layout, &at(-h)),
        &layout.dots,
    ) / (2.0 * h);
    (rate.is_finite() && rate > 0.0).then(|| AMPLITUDE_FRACTION * size / rate)
}
