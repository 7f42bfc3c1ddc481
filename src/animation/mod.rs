//! The animation page that `eomgen animate MODEL -o FILE.html`, `eomgen modes MODEL --animate
//! FILE.html` and the report write: the mechanism's `draw:` lines moving in one
//! self-contained HTML page (HW39's "simulate and animate"; lecture 17's line-drawing
//! animations; HW19's trace of the end of the forearm).
//!
//! The page needs no network: the frames (positions of the drawn points at uniform times,
//! sampled by the integrator's dense output, with `t` and the energy), a small stylesheet and
//! a small script are inline, and the drawing is inline SVG whose view box is the bounding
//! box of the whole run, so that both axes have one scale and nothing leaves the picture.
//! A 3-D model's page draws it in WebGL ([`pose`]): each 3-D body as a solid (the file's
//! `draw: shapes:`, or the box of its inertia) turned with its frame, with the frame's axes,
//! the `draw:` lines and traced paths in space, a grid in the ground plane, an orbit camera
//! and iso, top and side views (three.js, vendored and gzipped inside the page:
//! assets/three/README.md). Without WebGL the page keeps the isometric drawing of the
//! mode-shape charts ([`drawing::Layout::project`]), which the GIF also draws. Numbers are written with a fixed number of decimals
//! (positions to 10⁻¹¹ of the picture's size; times and energies to full precision), so the
//! file is byte-identical across runs.
//!
//! A simulation is animated in three steps: [`frame_times`] gives the output times of the
//! frames (checking the model's drawing and the options first), the caller simulates the
//! model sampled at them ([`analysis::simulate`](crate::analysis::simulate) with
//! [`OutputTimes::At`](crate::OutputTimes::At)), and [`simulation_animation`] draws the
//! samples. Normal modes are animated by [`modes_animation`]. [`Animation::to_html`] writes
//! the page; the command line also draws an [`Animation`] as an animated GIF (`eomgen
//! animate --gif`).
//!
//! # Examples
//! ```
//! use eomgen::OutputTimes;
//! use eomgen::analysis::{SimulationOptions, simulate};
//! use eomgen::animation::{AnimationOptions, frame_times, simulation_animation};
//!
//! let mut model = (eomgen::models::find("double_pendulum").unwrap().make)();
//! let options = AnimationOptions::default();
//! let times = frame_times(model.as_ref(), 2.0, &options)?;
//! let run = simulate(
//!     model.as_mut(),
//!     &SimulationOptions { t_end: 2.0, output: OutputTimes::At(times), ..Default::default() },
//! )
//! .expect("the double pendulum starts");
//! let animation = simulation_animation(model.as_ref(), &run, &options)?.expect("frames");
//! assert_eq!(animation.clips()[0].times().len(), 61); // 2 s at 30 frames per second
//! assert!(animation.to_html().starts_with("<!DOCTYPE html>"));
//! # Ok::<(), eomgen::animation::AnimationError>(())
//! ```

use eomgen_runtime::analysis::{Simulation, energy_drift_at};
use eomgen_runtime::{ModeKind, ModelInfo, NormalModes};
use nalgebra::DMatrix;

use crate::text::{num, short, step_control};
use drawing::{Frame, Layout};

pub mod drawing;
mod html;
pub mod pose;

/// Frames per second of simulated time by default ([`AnimationOptions::fps`]): `eomgen
/// animate` without `--fps`, and the report's animations.
pub const DEFAULT_FPS: f64 = 30.0;
/// Most frames an animation of a simulation may have (`⌊t_end · fps⌋ + 1`).
pub const MAX_FRAMES: usize = 100_000;
/// Frames per cycle of a mode-shape animation, and the real seconds one cycle takes at 1×.
const MODE_FRAMES: usize = 60;
const MODE_CYCLE_SECONDS: f64 = 2.0;
/// Samples of a traced path per frame (a power of 2, so that frame `k`'s time `k / fps`
/// is sample `4k`'s time `4k / (4 fps)` to the last bit).
const TRACE_SUBSTEPS: usize = 4;
/// Decimal digits kept of the picture's size in the positions: 10⁻¹¹ of it.
const POSITION_DIGITS: i32 = 11;

/// Options of a simulation's animation.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimationOptions {
    /// Frames per second of simulated time, finite and positive (default: [`DEFAULT_FPS`]):
    /// frames at `t = k / fps`, `k = 0 … ⌊t_end · fps⌋`, at most [`MAX_FRAMES`] of them.
    pub fps: f64,
    /// Names of the points whose paths are traced, instead of the model file's
    /// `draw: trace` (default: empty, the file's). Surrounding white space is ignored.
    pub trace: Vec<String>,
}

impl Default for AnimationOptions {
    fn default() -> Self {
        Self {
            fps: DEFAULT_FPS,
            trace: Vec::new(),
        }
    }
}

impl AnimationOptions {
    /// The number of frames of a run to `t_end` (s): `⌊t_end · fps⌋ + 1`, frames at
    /// `t = k / fps` (a `t_end` a rounding below a frame time keeps that frame; a `t_end`
    /// that is not positive gives 1, and is the simulation's error).
    ///
    /// # Errors
    /// [`AnimationError::InvalidFps`] when `fps` is not finite and positive,
    /// [`AnimationError::TooManyFrames`] when there would be more than [`MAX_FRAMES`].
    pub fn frame_count(&self, t_end: f64) -> Result<usize, AnimationError> {
        let fps = self.fps;
        if !(fps.is_finite() && fps > 0.0) {
            return Err(AnimationError::InvalidFps { fps });
        }
        let frames = (t_end * fps * (1.0 + 1e-12)).floor().max(0.0);
        if frames >= MAX_FRAMES as f64 {
            return Err(AnimationError::TooManyFrames { t_end, fps });
        }
        Ok(frames as usize + 1)
    }
}

/// Why a model or a run cannot be animated.
///
/// The messages are those `eomgen animate` and `eomgen modes --animate` print (the options
/// named as the command line spells them).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AnimationError {
    /// The model has no points (an energy-form model): there is no mechanism to draw.
    #[error(
        "`{model}` has no points, so there is no mechanism to animate; give its model file `points:` and `draw: {{ lines: [[A, B]], trace: [B] }}`"
    )]
    NoPoints {
        /// The model's name.
        model: String,
    },
    /// The model file draws no line and traces no point, and none was asked to be traced.
    #[error(
        "`{model}` has no `draw:` block, so there is nothing to animate; add `draw: {{ lines: [[{first}, {last}]], trace: [{last}] }}` to its model file, with lines between its points ({points}), or pass --trace POINT",
        first = points[0],
        last = points[points.len() - 1],
        points = points.join(", ")
    )]
    NothingToDraw {
        /// The model's name.
        model: String,
        /// The names of its points (not empty).
        points: Vec<String>,
    },
    /// A point to trace ([`AnimationOptions::trace`]) is not one of the model's points.
    #[error(
        "--trace {name}: `{model}` has no point `{}` (points: {})",
        .name.trim(),
        .points.join(", ")
    )]
    UnknownTracePoint {
        /// The name as it was given.
        name: String,
        /// The model's name.
        model: String,
        /// The names of its points.
        points: Vec<String>,
    },
    /// [`AnimationOptions::fps`] is not a finite positive number.
    #[error(
        "--fps must be a positive number of frames per second, got {:e}",
        num(fps)
    )]
    InvalidFps {
        /// The frames per second given.
        fps: f64,
    },
    /// The run would have more than [`MAX_FRAMES`] frames.
    #[error(
        "--t-end {:e} at --fps {:e} gives more than {MAX_FRAMES} frames; lower --fps",
        num(t_end),
        num(fps)
    )]
    TooManyFrames {
        /// The end time (s).
        t_end: f64,
        /// The frames per second.
        fps: f64,
    },
    /// A drawn point is NaN or infinite: the model leaves its domain there.
    #[error(
        "`{model}`: a drawn point is not finite at frame {frame}; the model leaves its domain there"
    )]
    PointNotFinite {
        /// The model's name.
        model: String,
        /// The frame (from 0) of the clip where it happened.
        frame: usize,
    },
    /// An expression of the model's description that the 3-D view evaluates (a frame's
    /// rotation, a shape's size, a body's inertia) does not parse or evaluate.
    #[error("`{model}`: {what}")]
    Description {
        /// The model's name.
        model: String,
        /// What is wrong.
        what: String,
    },
    /// The normal modes to animate are none.
    #[error("`{model}` has no modes to animate")]
    NoModes {
        /// The model's name.
        model: String,
    },
}

/// What every frame draws: the points used, the segments between them, the points marked
/// with a dot and the points whose paths are traced. Indices count in the list of drawn
/// points, which is the order of every [`Frame`] of the animation.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The model's name.
    model: String,
    /// Heading of the page: the model and its description.
    title: String,
    /// The drawn points' names, in the model's order (indices below count in this list).
    names: Vec<String>,
    /// The `draw:` lines.
    lines: Vec<[usize; 2]>,
    /// The points marked with a dot: the lines' ends and the traced points.
    dots: Vec<usize>,
    /// The traced points.
    traces: Vec<usize>,
    /// The bodies' centres of mass (points marked with a ring), with whether the body is
    /// rigid, and the body's name.
    centres: Vec<(usize, bool, String)>,
    /// The 3-D bodies, their solids and orientations: a 3-D model's scene (drawn in the 3-D
    /// view, projected isometrically for the GIF and the fallback), `None` for a planar one.
    poses: Option<pose::Poses>,
    /// Indices of the drawn points among the model's points.
    model_points: Vec<usize>,
}

impl Scene {
    /// The scene of `model`'s `draw:` block, with `trace` (point names) instead of its
    /// `draw: trace` when not empty.
    ///
    /// # Errors
    /// [`AnimationError::NoPoints`], [`AnimationError::UnknownTracePoint`] and
    /// [`AnimationError::NothingToDraw`] (no `draw:` lines and nothing to trace).
    fn of(model: &dyn ModelInfo, trace: &[String]) -> Result<Self, AnimationError> {
        let description = model.description();
        let all = description.point_names();
        let model_name = || description.name.to_string();
        if all.is_empty() {
            return Err(AnimationError::NoPoints {
                model: model_name(),
            });
        }
        let point_names = || all.iter().map(|p| p.to_string()).collect::<Vec<_>>();
        let index = |n: &str| all.iter().position(|p| *p == n);
        let traced: Vec<usize> = if trace.is_empty() {
            description
                .trace_point_names()
                .iter()
                .filter_map(|p| index(p))
                .collect()
        } else {
            let mut out = Vec::with_capacity(trace.len());
            for name in trace {
                let i = index(name.trim()).ok_or_else(|| AnimationError::UnknownTracePoint {
                    name: name.clone(),
                    model: model_name(),
                    points: point_names(),
                })?;
                if !out.contains(&i) {
                    out.push(i);
                }
            }
            out
        };
        let lines: Vec<[usize; 2]> = description
            .draw_line_names()
            .iter()
            .filter_map(|[a, b]| Some([index(a)?, index(b)?]))
            .collect();
        if lines.is_empty() && traced.is_empty() {
            return Err(AnimationError::NothingToDraw {
                model: model_name(),
                points: point_names(),
            });
        }
        let centres: Vec<(usize, bool, String)> = description
            .body_centres
            .iter()
            .filter_map(|c| Some((index(&c.point)?, c.rigid, c.body.to_string())))
            .collect();
        let mut used: Vec<usize> = lines.iter().flatten().copied().collect();
        used.extend(&traced);
        used.extend(centres.iter().map(|c| c.0));
        used.sort_unstable();
        used.dedup();
        let local = |i: usize| used.iter().position(|&u| u == i).unwrap_or(0);
        // Joints: the lines' ends and the traced points (a body's centre alone gets a ring).
        let mut dots: Vec<usize> = lines
            .iter()
            .flatten()
            .chain(&traced)
            .map(|&i| local(i))
            .collect();
        dots.sort_unstable();
        dots.dedup();
        Ok(Self {
            model: model_name(),
            title: format!("{} — {}", description.name, description.summary),
            names: used.iter().map(|&i| all[i].to_string()).collect(),
            lines: lines.iter().map(|[a, b]| [local(*a), local(*b)]).collect(),
            dots,
            traces: traced.iter().map(|&i| local(i)).collect(),
            centres: centres
                .iter()
                .map(|(i, rigid, body)| (local(*i), *rigid, body.clone()))
                .collect(),
            poses: None,
            model_points: used,
        })
    }

    /// Samples of a traced path per frame: [`TRACE_SUBSTEPS`] when a point is traced, else 1.
    fn substeps(&self) -> usize {
        if self.traces.is_empty() {
            1
        } else {
            TRACE_SUBSTEPS
        }
    }

    /// The projection of the drawn points' positions (`[x, y, z]` of every model point).
    fn project(&self, positions: &[[f64; 3]]) -> Frame {
        let layout = Layout {
            lines: Vec::new(),
            dots: Vec::new(),
            three_d: self.three_d(),
        };
        self.model_points
            .iter()
            .map(|&i| layout.project(positions[i]))
            .collect()
    }

    /// Makes the scene a 3-D one: isometric projections, and the 3-D view's points and bodies.
    ///
    /// # Errors
    /// As [`pose::Poses::of`].
    fn make_three_d(&mut self, model: &dyn ModelInfo) -> Result<(), AnimationError> {
        self.poses = Some(pose::Poses::of(model)?);
        Ok(())
    }

    /// The 3-D view's data of one configuration: the drawn points' positions (from the model's
    /// `positions`) and the bodies' poses at `(t, q)`; `None` for a planar scene.
    ///
    /// # Errors
    /// As [`pose::Poses::at`].
    fn space_frame(
        &self,
        model: &dyn ModelInfo,
        t: f64,
        q: &[f64],
        positions: &[[f64; 3]],
    ) -> Result<Option<SpaceFrame>, AnimationError> {
        let Some(poses) = &self.poses else {
            return Ok(None);
        };
        let points = self.model_points.iter().map(|&i| positions[i]).collect();
        Ok(Some((points, poses.at(model, t, q, positions)?)))
    }

    /// Whether the scene is a 3-D model's.
    fn three_d(&self) -> bool {
        self.poses.is_some()
    }

    /// The 3-D bodies drawn, with their solids (empty for a planar scene).
    pub fn bodies(&self) -> &[pose::DrawnBody] {
        self.poses.as_ref().map_or(&[], |p| &p.bodies)
    }

    /// The model's name.
    pub fn model(&self) -> &str {
        &self.model
    }

    /// The `draw:` lines, as pairs of indices of drawn points (into every [`Frame`]).
    pub fn lines(&self) -> &[[usize; 2]] {
        &self.lines
    }

    /// The drawn points marked with a dot (the lines' ends and the traced points), as
    /// indices into every [`Frame`], increasing.
    pub fn dots(&self) -> &[usize] {
        &self.dots
    }

    /// The bodies' centres of mass, marked with a ring, as indices into every [`Frame`].
    pub fn centre_points(&self) -> impl Iterator<Item = usize> + '_ {
        self.centres.iter().map(|c| c.0)
    }
}

/// Energy per frame: `E = T + V` (J) and its drift `(E − E₀) / max(T + |V|)` (the scale
/// of `eomgen simulate`'s drift, so a zero `E₀` still gives a relative figure).
#[derive(Debug, Clone, PartialEq)]
struct Energy {
    /// `E` per frame (J).
    energy: Vec<f64>,
    /// `(E − E₀) / max(T + |V|)` per frame, the maximum over the initial state and the frames.
    drift: Vec<f64>,
}

/// One animation the page can play: frame times, positions and what to say about it.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    /// Its name in the clip selector.
    label: String,
    /// The line under the heading (method, frames, energy; or the mode's frequency).
    info: String,
    /// Frame times (s), increasing.
    t: Vec<f64>,
    /// Per frame, the projected position of every drawn point (m), in [`Scene::names`] order.
    frames: Vec<Frame>,
    /// Per traced point ([`Scene::traces`]), its path sampled [`Clip::sub`] times per frame
    /// (`(frames − 1) · sub + 1` positions, m).
    trail: Vec<Vec<(f64, f64)>>,
    /// Samples of [`Clip::trail`] per frame.
    sub: usize,
    /// Energy per frame, for a simulation.
    energy: Option<Energy>,
    /// Seconds of `t` per real second at 1× (1 for a simulation).
    rate: f64,
    /// The period of a mode's cycle (s; the clip loops over one cycle).
    period: Option<f64>,
    /// A simulation's transitions at its contacts (impacts, lift-offs, stick and slip), in
    /// time order: `(t, what happened, the first frame after it)`.
    transitions: Vec<(f64, String, usize)>,
    /// The 3-D view's data (a 3-D scene only).
    space: Option<Space>,
}

/// One frame of the 3-D view: the drawn points' `[x, y, z]` (m) and the bodies' poses
/// `[x, y, z, qx, qy, qz, qw]`.
type SpaceFrame = (Vec<[f64; 3]>, Vec<[f64; 7]>);

/// The 3-D view's data of a clip: positions in the ground's axes (m), not projected.
#[derive(Debug, Clone, PartialEq, Default)]
struct Space {
    /// Per frame, every drawn point's `[x, y, z]`, in [`Scene::names`] order.
    points: Vec<Vec<[f64; 3]>>,
    /// Per traced point, its path, sampled as [`Clip::trail`].
    trail: Vec<Vec<[f64; 3]>>,
    /// Per frame, each body's centre and orientation, `[x, y, z, qx, qy, qz, qw]`, in
    /// [`Scene::bodies`] order.
    poses: Vec<Vec<[f64; 7]>>,
}

impl Space {
    /// Adds one frame's points and poses (`None` for a planar scene: nothing to add).
    fn push(&mut self, frame: Option<SpaceFrame>) {
        if let Some((points, poses)) = frame {
            self.points.push(points);
            self.poses.push(poses);
        }
    }

    /// The first frame with a pose that is not finite, if any (the points and paths are
    /// checked in their projections first).
    fn first_not_finite(&self) -> Option<usize> {
        (self.poses.iter()).position(|f| !f.iter().flatten().all(|v| v.is_finite()))
    }
}

impl Clip {
    /// Its name in the page's clip selector (`simulation`, `mode 1: ω = 3.5 rad/s`).
    pub fn label(&self) -> &str {
        &self.label
    }

    /// The frame times (s), increasing (from 0; a mode's clip covers one cycle).
    pub fn times(&self) -> &[f64] {
        &self.t
    }

    /// Per frame, the picture coordinates `(x, y)` (m) of every drawn point, indexed as
    /// [`Scene::lines`], [`Scene::dots`] and [`Scene::centre_points`] are.
    pub fn frames(&self) -> &[Frame] {
        &self.frames
    }

    /// Per traced point, its path (m) sampled [`Clip::trail_substeps`] times per frame:
    /// `(frames − 1) · substeps + 1` positions, the path up to frame `k` being the first
    /// `k · substeps + 1`.
    pub fn trails(&self) -> &[Vec<(f64, f64)>] {
        &self.trail
    }

    /// Samples of each of [`Clip::trails`] per frame (1, or 4 for a simulation that traces
    /// a point).
    pub fn trail_substeps(&self) -> usize {
        self.sub
    }

    /// Seconds of [`Clip::times`] per real second when played at 1× (1 for a simulation).
    pub fn rate(&self) -> f64 {
        self.rate
    }

    /// The energy `E = T + V` (J) at every frame of a simulation; `None` for a mode.
    pub fn energy(&self) -> Option<&[f64]> {
        self.energy.as_ref().map(|e| e.energy.as_slice())
    }

    /// A simulation's transitions at its contacts, in time order: `(t, text, frame)` with
    /// `t` in s, the text as the page shows it ("impact at `floor`, 0.2472 J lost") and the
    /// first frame that shows the state after it (a frame at the transition's own time shows
    /// the state before it); empty for a model without contacts and for a mode.
    pub fn transitions(&self) -> &[(f64, String, usize)] {
        &self.transitions
    }
}

/// A scene and its clips: one page (and, in the command line, one GIF).
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    /// What is drawn.
    scene: Scene,
    /// The clips (one for a simulation, one per mode); at least one, each with a frame.
    clips: Vec<Clip>,
}

impl Animation {
    /// What every frame draws.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The clips: one for a simulation, one per mode; never empty, each with a frame.
    pub fn clips(&self) -> &[Clip] {
        &self.clips
    }

    /// The picture's box `(x0, x1, y0, y1)` (m): every drawn point of every frame and trail
    /// of every clip, with a border of 6 % of the larger side (of 1 m when all points
    /// coincide).
    pub fn bounding_box(&self) -> (f64, f64, f64, f64) {
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for (x, y) in self
            .clips
            .iter()
            .flat_map(|c| c.frames.iter().chain(&c.trail).flatten())
        {
            x0 = x0.min(*x);
            x1 = x1.max(*x);
            y0 = y0.min(*y);
            y1 = y1.max(*y);
        }
        let span = (x1 - x0).max(y1 - y0);
        let span = if span > 0.0 { span } else { 1.0 };
        let pad = 0.06 * span;
        (x0 - pad, x1 + pad, y0 - pad, y1 + pad)
    }
}

/// The output times (s) of the samples a simulation of `model` to `t_end` (s) needs for its
/// animation with `options`: the frames at `t = k / fps`, and when a point is traced, three
/// more samples of its path between frames (times `j / (4 fps)`), the last clamped onto
/// `t_end`. Pass them as [`OutputTimes::At`](crate::OutputTimes::At) to the simulation,
/// then its result to [`simulation_animation`]. The model's drawing is checked here, before
/// anything is integrated.
///
/// # Errors
/// [`AnimationError::InvalidFps`] and [`AnimationError::TooManyFrames`]
/// ([`AnimationOptions::frame_count`]); [`AnimationError::NoPoints`],
/// [`AnimationError::UnknownTracePoint`] and [`AnimationError::NothingToDraw`] for a model
/// that cannot be drawn.
pub fn frame_times(
    model: &dyn ModelInfo,
    t_end: f64,
    options: &AnimationOptions,
) -> Result<Vec<f64>, AnimationError> {
    let frames = options.frame_count(t_end)? - 1;
    let sub = Scene::of(model, &options.trace)?.substeps();
    let rate = options.fps * sub as f64;
    // The fudge of `frame_count` lets `t_end` a rounding below a frame time keep that frame,
    // which is then clamped onto `t_end` (output times may not pass it).
    Ok((0..=frames * sub)
        .map(|j| (j as f64 / rate).min(t_end))
        .collect())
}

/// The animation of a finished (or failed) `simulation` of `model`, whose samples are at
/// [`frame_times`]`(model, t_end, options)` (every sample is drawn; with a traced point every
/// fourth is a frame): one clip, titled `simulation`, with the energy and its drift at every
/// frame and an info line naming the method and its step control
/// ([`text::step_control`](crate::text::step_control) of the simulation's options).
///
/// A failed run is drawn up to its last whole frame. Returns `None` when not even the first
/// frame was computed.
///
/// # Errors
/// As [`frame_times`] for a model that cannot be drawn; [`AnimationError::PointNotFinite`]
/// when a drawn point is not finite.
pub fn simulation_animation(
    model: &dyn ModelInfo,
    simulation: &Simulation,
    options: &AnimationOptions,
) -> Result<Option<Animation>, AnimationError> {
    let mut scene = Scene::of(model, &options.trace)?;
    let sub = scene.substeps();
    let solution = &simulation.solution;
    // Whole frames only: the samples up to the last one at a frame time.
    let samples = match solution.len() {
        0 => return Ok(None),
        m => (m - 1) / sub * sub + 1,
    };
    if solution
        .iter()
        .any(|(t, y)| model.point_positions(t, y).iter().any(|p| p[2] != 0.0))
    {
        scene.make_three_d(model)?;
    }
    let n = model.description().num_dofs();
    // The 3-D view's frames: `(t, y, positions)`, posed once every point is known finite.
    let mut in_space = Vec::new();
    let mut space_trail = vec![
        Vec::new();
        if scene.three_d() {
            scene.traces.len()
        } else {
            0
        }
    ];
    let mut t = Vec::with_capacity(samples / sub + 1);
    let mut frames = Vec::with_capacity(samples / sub + 1);
    let mut frame_states = Vec::with_capacity(samples / sub + 1);
    let mut trail = vec![Vec::with_capacity(samples); scene.traces.len()];
    // Each frame's sample, for the energy lost at impacts before it.
    let mut frame_samples = Vec::with_capacity(samples / sub + 1);
    // A walker's coordinates are about its stance foot: each change of support moves their
    // origin to the landing foot, and the drawing follows it (`offset` from sample `next.0`).
    let mut landings = (simulation.transitions.iter())
        .filter_map(|tr| Some((tr.sample, tr.foot?)))
        .peekable();
    let mut offset = [0.0; 2];
    for (j, (tk, y)) in solution.iter().take(samples).enumerate() {
        while let Some((_, foot)) = landings.next_if(|(s, _)| *s <= j) {
            offset = [offset[0] + foot[0], offset[1] + foot[1]];
        }
        let mut positions = model.point_positions(tk, y);
        for p in &mut positions {
            p[0] += offset[0];
            p[1] += offset[1];
        }
        let frame = scene.project(&positions);
        for (path, &p) in trail.iter_mut().zip(&scene.traces) {
            path.push(frame[p]);
        }
        for (path, &p) in space_trail.iter_mut().zip(&scene.traces) {
            path.push(positions[scene.model_points[p]]);
        }
        if j % sub != 0 {
            continue;
        }
        if scene.three_d() {
            in_space.push((tk, y, positions));
        }
        t.push(tk);
        frames.push(frame);
        frame_states.push((tk, y));
        frame_samples.push(j);
    }
    let (energy, e0, max_drift) = frame_energies(model, simulation, frame_states, &frame_samples);
    let info = simulation_info(
        model,
        simulation,
        options,
        (&t, e0, max_drift),
        scene.three_d(),
    );
    check_finite(&scene.model, &frames)?;
    check_finite(&scene.model, &trail)?;
    let mut space = Space {
        trail: space_trail,
        ..Space::default()
    };
    for (tk, y, positions) in &in_space {
        space.push(scene.space_frame(model, *tk, &y[..n], positions)?);
    }
    let space = scene.three_d().then_some(space);
    check_space(&scene.model, space.as_ref())?;
    let clip = Clip {
        label: "simulation".to_string(),
        info,
        t,
        frames,
        trail,
        sub,
        energy: Some(energy),
        rate: 1.0,
        period: None,
        transitions: (simulation.transitions.iter())
            .map(|tr| {
                let (t, text) = describe_transition(tr);
                (t, text, frame_samples.partition_point(|&j| j < tr.sample))
            })
            .collect(),
        space,
    };
    Ok(Some(Animation {
        scene,
        clips: vec![clip],
    }))
}

/// The energy `E` and its drift at the frames `(t, y)` of `simulation` (their samples
/// `frame_samples`), of `E` plus the energy lost at impacts before each (as `eomgen simulate`
/// measures it: the integration's error, not the impacts'); with `E(0)` and the largest
/// drift.
fn frame_energies(
    model: &dyn ModelInfo,
    simulation: &Simulation,
    frame_states: Vec<(f64, &[f64])>,
    frame_samples: &[usize],
) -> (Energy, f64, f64) {
    let mut energy_drift =
        energy_drift_at(model, &simulation.initial_state, frame_states.into_iter());
    let lost = lost_by_frame(simulation, frame_samples);
    let mut drift = energy_drift.relative();
    if energy_drift.scale > 0.0 {
        for (d, l) in drift.iter_mut().zip(&lost) {
            *d += l / energy_drift.scale;
        }
    }
    let losses = (simulation.transitions.iter()).map(|tr| (tr.sample, tr.energy_drop()));
    let losses: Vec<(usize, f64)> = losses
        .map(|(s, l)| (frame_samples.partition_point(|&j| j < s), l))
        .collect();
    energy_drift.add_losses(losses.into_iter());
    let max_drift = energy_drift.drift.unwrap_or(0.0);
    let energy = Energy {
        energy: energy_drift.energy,
        drift,
    };
    (energy, energy_drift.initial_energy, max_drift)
}

/// The info line of a simulation's clip: the method and its step control, the frames, `E(0)`
/// and the largest drift over the frames (`(t, e0, max_drift)`), what the drift is of, and
/// the view.
fn simulation_info(
    model: &dyn ModelInfo,
    simulation: &Simulation,
    options: &AnimationOptions,
    (t, e0, max_drift): (&[f64], f64, f64),
    three_d: bool,
) -> String {
    let method = format!(
        "{} ({})",
        simulation.integrator,
        step_control(&simulation.options)
    );
    let conserved = if !simulation.transitions.is_empty() {
        " (of E plus the energy lost at impacts; friction's work while sliding is not added)"
    } else if model.description().conservative {
        ""
    } else {
        " (not conserved: non-conservative loads or explicit time dependence)"
    };
    // "Over the frames": the drift sampled at the frame times, which can be smaller than
    // `eomgen simulate`'s, taken over every step.
    // A minus sign, not a hyphen, in the exponent: no line break inside the number.
    let max_drift = format!("{max_drift:.2e}").replace('-', "−");
    format!(
        "{method}; {} frames at {} fps of simulated time, t = 0 … {} s; E(0) = {} J, max |E − E₀| / max(T + |V|) over the frames = {max_drift}{conserved}{}",
        t.len(),
        short(options.fps),
        short(t[t.len() - 1]),
        short(e0),
        if three_d { "; 3-D view" } else { "" }
    )
}

/// The energy lost at impacts before each frame (J), the frame at sample `frame_samples[k]`
/// (a transition's `sample` is the first sample after it).
fn lost_by_frame(simulation: &Simulation, frame_samples: &[usize]) -> Vec<f64> {
    let mut lost = 0.0;
    let mut transitions = simulation.transitions.iter().peekable();
    (frame_samples.iter())
        .map(|&j| {
            while let Some(tr) = transitions.next_if(|tr| tr.sample <= j) {
                lost += tr.energy_drop();
            }
            lost
        })
        .collect()
}

/// A transition as the page lists it: "impact at `floor`, 0.2472 J lost", "`floor` lifts
/// off", "`floor` sticks", "`floor` slips".
fn describe_transition(tr: &eomgen_runtime::hybrid::Transition) -> (f64, String) {
    use eomgen_runtime::hybrid::TransitionKind;
    let c = &tr.contact;
    let text = match tr.kind {
        TransitionKind::Impact | TransitionKind::Closes => {
            let closes = if tr.kind == TransitionKind::Closes {
                ", stays closed"
            } else {
                ""
            };
            format!("impact at `{c}`{closes}, {} J lost", short(tr.energy_lost))
        }
        TransitionKind::LiftOff => format!("`{c}` lifts off"),
        TransitionKind::Stick => format!("`{c}` sticks"),
        TransitionKind::Slip => format!("`{c}` slips"),
        TransitionKind::SupportChange => {
            format!("`{c}` lands: a step, {} J lost", short(tr.energy_lost))
        }
    };
    (tr.t, text)
}

/// [`AnimationError::PointNotFinite`] at the first frame where a pose of the 3-D view is not
/// finite.
fn check_space(model: &str, space: Option<&Space>) -> Result<(), AnimationError> {
    match space.and_then(Space::first_not_finite) {
        Some(frame) => Err(AnimationError::PointNotFinite {
            model: model.to_string(),
            frame,
        }),
        None => Ok(()),
    }
}

/// [`AnimationError::PointNotFinite`] at the first frame of `frames` with a coordinate that
/// is not finite.
fn check_finite(model: &str, frames: &[Frame]) -> Result<(), AnimationError> {
    match frames
        .iter()
        .position(|f| f.iter().any(|(x, y)| !(x.is_finite() && y.is_finite())))
    {
        Some(frame) => Err(AnimationError::PointNotFinite {
            model: model.to_string(),
            frame,
        }),
        None => Ok(()),
    }
}

/// The animation of the normal modes at the equilibrium `q` (length `n`), what `eomgen modes
/// --animate` writes: one clip per mode, `q* + s ψₖ sin(ωₖ t)` over one period with 60
/// frames, played at one cycle per 2 s at 1×, `s` as in the mode-shape charts
/// ([`drawing::mode_scale`]: the largest point displacement a fifth of the mechanism's size).
/// Zero-frequency and unstable modes swing their shape over a nominal 2 s cycle.
///
/// # Arguments
/// * `modes` — the normal modes at `q`, `r` of them.
/// * `shapes` — their shapes, `n × r` in the model's coordinates (`N Ψ` for a constrained
///   model, whose modes are computed in minimal coordinates).
/// * `c_left_out` — whether the linearisation has a velocity matrix `C` that the modes of
///   `M` and `K` leave out (the info lines then say so: [`drawing::describe`]).
///
/// # Errors
/// [`AnimationError::NoPoints`] and [`AnimationError::NothingToDraw`] for a model that
/// cannot be drawn; [`AnimationError::PointNotFinite`] when a displaced configuration is not
/// finite; [`AnimationError::NoModes`] when `modes` is empty.
///
/// # Panics
/// If `shapes` has fewer than `r` columns or fewer than `n` rows.
pub fn modes_animation(
    model: &dyn ModelInfo,
    q: &[f64],
    modes: &NormalModes,
    shapes: &DMatrix<f64>,
    c_left_out: bool,
) -> Result<Animation, AnimationError> {
    let mut scene = Scene::of(model, &[])?;
    if drawing::is_three_d(model, q, shapes) {
        scene.make_three_d(model)?;
    }
    // The mode scale measures the displacement of the drawn points.
    let layout = Layout {
        lines: Vec::new(),
        dots: scene.model_points.clone(),
        three_d: scene.three_d(),
    };
    let positions = |qk: &[f64]| drawing::positions(model, qk);
    let rest = scene.project(&positions(q));
    let size = drawing::drawing_size(&rest, &(0..rest.len()).collect::<Vec<_>>());
    let mut clips = Vec::with_capacity(shapes.ncols());
    for (k, omega, kind, psi) in drawing::each_mode(modes, shapes) {
        let oscillatory = matches!(kind, ModeKind::Oscillatory) && omega > 0.0;
        let period = if oscillatory {
            std::f64::consts::TAU / omega
        } else {
            MODE_CYCLE_SECONDS
        };
        let s = drawing::mode_scale(model, &layout, q, &psi, size);
        let t: Vec<f64> = (0..=MODE_FRAMES)
            .map(|j| period * j as f64 / MODE_FRAMES as f64)
            .collect();
        let mut frames: Vec<Frame> = Vec::with_capacity(t.len());
        let mut configurations = Vec::with_capacity(t.len());
        for j in 0..t.len() {
            let phase = std::f64::consts::TAU * j as f64 / MODE_FRAMES as f64;
            let qk = drawing::displaced(q, &psi, s.unwrap_or(0.0) * phase.sin());
            let at = positions(&qk);
            frames.push(scene.project(&at));
            configurations.push((qk, at));
        }
        check_finite(&scene.model, &frames)?;
        let mut space = Space::default();
        for (qk, at) in &configurations {
            space.push(scene.space_frame(model, 0.0, qk, at)?);
        }
        space.trail = (scene.traces.iter())
            .map(|&p| space.points.iter().map(|f| f[p]).collect())
            .collect();
        let space = scene.three_d().then_some(space);
        check_space(&scene.model, space.as_ref())?;
        let described = drawing::describe(k + 1, omega, kind, c_left_out);
        let motion = match s {
            Some(s) => format!("q* + {} ψ{} sin(ω t)", short(s), k + 1),
            None => "it moves no drawn point".to_string(),
        };
        let pace = if oscillatory {
            format!(
                "period {} s, shown at one cycle per {MODE_CYCLE_SECONDS} s at 1×",
                short(period)
            )
        } else {
            format!("shape only, one swing per {MODE_CYCLE_SECONDS} s at 1×")
        };
        let trail = scene
            .traces
            .iter()
            .map(|&p| frames.iter().map(|f| f[p]).collect())
            .collect();
        let label = match kind {
            ModeKind::Oscillatory => format!("mode {}: ω = {} rad/s", k + 1, short(omega)),
            ModeKind::ZeroFrequency => format!("mode {}: zero-frequency", k + 1),
            ModeKind::Unstable { .. } => format!("mode {}: unstable", k + 1),
        };
        clips.push(Clip {
            label,
            info: format!("{described}; {motion}; {pace}"),
            t,
            frames,
            trail,
            sub: 1,
            energy: None,
            rate: period / MODE_CYCLE_SECONDS,
            period: Some(period),
            transitions: Vec::new(),
            space,
        });
    }
    if clips.is_empty() {
        return Err(AnimationError::NoModes { model: scene.model });
    }
    Ok(Animation { scene, clips })
}

/// A round grid spacing (m): 1, 2 or 5 × 10ᵏ, near `span / 10` (`span` in m, positive) —
/// the page's grid, and the GIF's.
pub fn grid_step(span: f64) -> f64 {
    let raw = span / 10.0;
    let power = 10f64.powf(raw.log10().floor());
    let m = raw / power;
    power
        * if m < 1.5 {
            1.0
        } else if m < 3.5 {
            2.0
        } else if m < 7.5 {
            5.0
        } else {
            10.0
        }
}

#[cfg(test)]
mod tests;
