//! The animation page that `eomgen animate MODEL -o FILE.html`, `eomgen modes MODEL --animate
//! FILE.html` and the report write: the mechanism's `draw:` lines moving in one
//! self-contained HTML page (HW39's "simulate and animate"; lecture 17's line-drawing
//! animations; HW19's trace of the end of the forearm).
//!
//! The page needs no network: the frames (positions of the drawn points at uniform times,
//! sampled by the integrator's dense output, with `t` and the energy), a small stylesheet and
//! a small script are inline, and the drawing is inline SVG whose view box is the bounding
//! box of the whole run, so that both axes have one scale and nothing leaves the picture.
//! 3-D models are drawn in the isometric view of the mode-shape charts
//! ([`mode_plot::Layout::project`]). Numbers are written with a fixed number of decimals
//! (positions to 10⁻¹¹ of the picture's size; times and energies to full precision), so the
//! file is byte-identical across runs. `--gif` writes the same animation as an animated GIF
//! for slides.

use std::fmt::Write as _;

use eomgen::analysis::energy_drift_at;
use eomgen::{ModeKind, ModelInfo, NormalModes, OutputTimes};
use nalgebra::DMatrix;
use plotters::prelude::*;

mod animated_gif;
mod html;

use super::error::CliError;
use super::integration::{IntegrationArgs, Run, failure_error, integrate};
use super::mode_plot::{self, Frame, Layout};
use super::plot;
use super::render::escape;

/// Frames per second of simulated time of `animate` without `--fps`, and of the report's
/// animations.
pub(super) const DEFAULT_FPS: f64 = 30.0;
/// Most frames an animation may have (`t_end · fps + 1`).
const MAX_FRAMES: usize = 100_000;
/// Frames per cycle of a mode-shape animation, and the real seconds one cycle takes at 1×.
const MODE_FRAMES: usize = 60;
const MODE_CYCLE_SECONDS: f64 = 2.0;
/// Samples of a traced path per frame (a power of 2, so that frame `k`'s time `k / fps`
/// is sample `4k`'s time `4k / (4 fps)` to the last bit).
const TRACE_SUBSTEPS: usize = 4;
/// Decimal digits kept of the picture's size in the positions: 10⁻¹¹ of it.
const POSITION_DIGITS: i32 = 11;
/// The GIF: largest side of the drawing (px), band for the caption (px), frames per second
/// and frame count at most.
const GIF_SIDE: u32 = 440;
const GIF_CAPTION: u32 = 30;
const GIF_MAX_FPS: f64 = 25.0;
const GIF_MAX_FRAMES: usize = 600;
/// Colours of the page's links, joints and traces (the GIF uses the same).
const LINK: (u8, u8, u8) = (0x2b, 0x59, 0xc3);
const JOINT: (u8, u8, u8) = (0x1b, 0x1b, 0x1b);
const TRACE: (u8, u8, u8) = (0xe8, 0x87, 0x1e);
const GRID: (u8, u8, u8) = (0xe8, 0xe8, 0xe8);

/// What every frame draws: the points used, the segments between them, the points marked
/// with a dot and the points whose paths are traced.
pub(crate) struct Scene {
    /// The model's name.
    pub model: String,
    /// Heading of the page: the model and its description.
    pub title: String,
    /// The drawn points' names, in the model's order (indices below count in this list).
    pub names: Vec<String>,
    /// The `draw:` lines.
    pub lines: Vec<[usize; 2]>,
    /// The points marked with a dot: the lines' ends and the traced points.
    pub dots: Vec<usize>,
    /// The traced points.
    pub traces: Vec<usize>,
    /// The bodies' centres of mass (points marked with a ring), with whether the body is
    /// rigid, and the body's name.
    pub centres: Vec<(usize, bool, String)>,
    /// Isometric view of a 3-D model.
    pub three_d: bool,
    /// Indices of the drawn points among the model's points.
    model_points: Vec<usize>,
}

impl Scene {
    /// The scene of `model`'s `draw:` block, with `trace` (point names) instead of its
    /// `draw: trace` when not empty.
    ///
    /// # Errors
    /// A usage error when the model has no points, no `draw:` lines and nothing to trace,
    /// or a traced name is not one of its points.
    fn of(model: &dyn ModelInfo, trace: &[String]) -> Result<Self, CliError> {
        let all = model.description().point_names();
        if all.is_empty() {
            return Err(CliError::usage(format!(
                "`{}` has no points, so there is no mechanism to animate; give its model file `points:` and `draw: {{ lines: [[A, B]], trace: [B] }}`",
                model.description().name
            )));
        }
        let index = |n: &str| all.iter().position(|p| *p == n);
        let traced: Vec<usize> = if trace.is_empty() {
            model
                .description()
                .trace_point_names()
                .iter()
                .filter_map(|p| index(p))
                .collect()
        } else {
            let mut out = Vec::with_capacity(trace.len());
            for name in trace {
                let i = index(name.trim()).ok_or_else(|| {
                    CliError::usage(format!(
                        "--trace {name}: `{}` has no point `{}` (points: {})",
                        model.description().name,
                        name.trim(),
                        all.join(", ")
                    ))
                })?;
                if !out.contains(&i) {
                    out.push(i);
                }
            }
            out
        };
        let lines: Vec<[usize; 2]> = model
            .description()
            .draw_line_names()
            .iter()
            .filter_map(|[a, b]| Some([index(a)?, index(b)?]))
            .collect();
        if lines.is_empty() && traced.is_empty() {
            return Err(CliError::usage(format!(
                "`{}` has no `draw:` block, so there is nothing to animate; add `draw: {{ lines: [[{a}, {b}]], trace: [{b}] }}` to its model file, with lines between its points ({}), or pass --trace POINT",
                model.description().name,
                all.join(", "),
                a = all[0],
                b = all[all.len() - 1],
            )));
        }
        let centres: Vec<(usize, bool, String)> = model
            .description()
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
            model: model.description().name.to_string(),
            title: format!(
                "{} — {}",
                model.description().name,
                model.description().summary
            ),
            names: used.iter().map(|&i| all[i].to_string()).collect(),
            lines: lines.iter().map(|[a, b]| [local(*a), local(*b)]).collect(),
            dots,
            traces: traced.iter().map(|&i| local(i)).collect(),
            centres: centres
                .iter()
                .map(|(i, rigid, body)| (local(*i), *rigid, body.clone()))
                .collect(),
            three_d: false,
            model_points: used,
        })
    }

    /// The projection of the drawn points' positions (`[x, y, z]` of every model point).
    fn project(&self, positions: &[[f64; 3]]) -> Frame {
        let layout = Layout {
            lines: Vec::new(),
            dots: Vec::new(),
            three_d: self.three_d,
        };
        self.model_points
            .iter()
            .map(|&i| layout.project(positions[i]))
            .collect()
    }
}

/// Energy per frame: `E = T + V` (J) and its drift `(E − E₀) / max(T + |V|)` (the scale
/// of `eomgen simulate`'s drift, so a zero `E₀` still gives a relative figure).
pub(crate) struct Energy {
    /// `E` per frame (J).
    pub energy: Vec<f64>,
    /// `(E − E₀) / max(T + |V|)` per frame, the maximum over the initial state and the frames.
    pub drift: Vec<f64>,
}

/// One animation the page can play: frame times, positions and what to say about it.
pub(crate) struct Clip {
    /// Its name in the clip selector.
    pub label: String,
    /// The line under the heading (method, frames, energy; or the mode's frequency).
    pub info: String,
    /// Frame times (s), increasing.
    pub t: Vec<f64>,
    /// Per frame, the projected position of every drawn point (m), in [`Scene::names`] order.
    pub frames: Vec<Frame>,
    /// Per traced point ([`Scene::traces`]), its path sampled [`Clip::sub`] times per frame
    /// (`(frames − 1) · sub + 1` positions, m).
    pub trail: Vec<Vec<(f64, f64)>>,
    /// Samples of [`Clip::trail`] per frame.
    pub sub: usize,
    /// Energy per frame, for a simulation.
    pub energy: Option<Energy>,
    /// Seconds of `t` per real second at 1× (1 for a simulation).
    pub rate: f64,
    /// The period of a mode's cycle (s; the clip loops over one cycle).
    pub period: Option<f64>,
}

/// A scene and its clips: one page, one GIF.
pub(crate) struct Animation {
    /// What is drawn.
    pub scene: Scene,
    /// The clips (one for a simulation, one per mode); at least one, each with a frame.
    pub clips: Vec<Clip>,
}

/// The animation of a simulation of `model_name` with `args`, frames at `t = k / fps`.
///
/// Returns the animation (`None` when not even the first frame was computed) and, when the
/// integration failed, its error (as `simulate` reports it, saying that the frames before
/// it are in the animation).
///
/// # Errors
/// Usage errors of `simulate`, an `fps` that is not positive or gives more than
/// [`MAX_FRAMES`] frames, a model without `draw:`; a failure when a position is not finite.
pub(crate) fn simulation(
    model_name: &str,
    args: &IntegrationArgs,
    fps: f64,
    trace: &[String],
) -> Result<(Option<Animation>, Option<CliError>), CliError> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(CliError::usage(format!(
            "--fps must be a positive number of frames per second, got {:e}",
            super::render::num(fps)
        )));
    }
    // (A `--t-end` that is not positive is `integrate`'s usage error.)
    let frames = (args.t_end * fps * (1.0 + 1e-12)).floor().max(0.0);
    if frames >= MAX_FRAMES as f64 {
        return Err(CliError::usage(format!(
            "--t-end {:e} at --fps {:e} gives more than {MAX_FRAMES} frames; lower --fps",
            super::render::num(args.t_end),
            super::render::num(fps)
        )));
    }
    // Check the model's drawing before integrating.
    let scene = Scene::of(super::model::find_model(model_name)?.as_ref(), trace)?;
    let sub = if scene.traces.is_empty() {
        1
    } else {
        TRACE_SUBSTEPS
    };
    let rate = fps * sub as f64;
    // The fudge above lets `t_end` a rounding below a frame time keep that frame, which is
    // then clamped onto `t_end` (output times may not pass it).
    let times: Vec<f64> = (0..=frames as usize * sub)
        .map(|j| (j as f64 / rate).min(args.t_end))
        .collect();
    let Run {
        model,
        y0,
        solution,
        failure,
        cause,
        method_name,
    } = integrate(model_name, args, OutputTimes::At(times))?;
    let model = model.as_ref();
    // Whole frames only: the samples up to the last one at a frame time.
    let samples = match solution.len() {
        0 => 0,
        m => (m - 1) / sub * sub + 1,
    };
    let failure = failure.map(|e| {
        let kept = match samples {
            0 => "no frame was computed, so no animation was written".to_string(),
            m => format!(
                "the {} frames computed before it (t = 0 … {} s) are in the animation",
                (m - 1) / sub + 1,
                short(solution.t[m - 1])
            ),
        };
        failure_error(&model.description().name, &e, cause.as_ref(), args, &kept)
    });
    if samples == 0 {
        return Ok((None, failure));
    }
    let mut scene = scene;
    scene.three_d = solution
        .iter()
        .any(|(t, y)| model.point_positions(t, y).iter().any(|p| p[2] != 0.0));
    let mut t = Vec::with_capacity(samples / sub + 1);
    let mut frames = Vec::with_capacity(samples / sub + 1);
    let mut frame_states = Vec::with_capacity(samples / sub + 1);
    let mut trail = vec![Vec::with_capacity(samples); scene.traces.len()];
    for (j, (tk, y)) in solution.iter().take(samples).enumerate() {
        let frame = scene.project(&model.point_positions(tk, y));
        for (path, &p) in trail.iter_mut().zip(&scene.traces) {
            path.push(frame[p]);
        }
        if j % sub != 0 {
            continue;
        }
        t.push(tk);
        frames.push(frame);
        frame_states.push((tk, y));
    }
    // The energy and its drift over the frames.
    let energy_drift = energy_drift_at(model, &y0, frame_states.into_iter());
    let drift = energy_drift.relative();
    let max_drift = energy_drift.drift.unwrap_or(0.0);
    let (e0, energy) = (energy_drift.initial_energy, energy_drift.energy);
    let method = format!("{method_name} ({})", args.step_control());
    let conserved = if model.description().conservative {
        ""
    } else {
        " (not conserved: non-conservative loads or explicit time dependence)"
    };
    // "Over the frames": the drift sampled at the frame times, which can be smaller than
    // `eomgen simulate`'s, taken over every step.
    // A minus sign, not a hyphen, in the exponent: no line break inside the number.
    let max_drift = format!("{max_drift:.2e}").replace('-', "−");
    let info = format!(
        "{method}; {} frames at {} fps of simulated time, t = 0 … {} s; E(0) = {} J, max |E − E₀| / max(T + |V|) over the frames = {max_drift}{conserved}{}",
        t.len(),
        short(fps),
        short(t[t.len() - 1]),
        short(e0),
        if scene.three_d {
            "; isometric view"
        } else {
            ""
        }
    );
    check_finite(&model.description().name, &frames)?;
    check_finite(&model.description().name, &trail)?;
    let clip = Clip {
        label: "simulation".to_string(),
        info,
        t,
        frames,
        trail,
        sub,
        energy: Some(Energy { energy, drift }),
        rate: 1.0,
        period: None,
    };
    Ok((
        Some(Animation {
            scene,
            clips: vec![clip],
        }),
        failure,
    ))
}

fn check_finite(model: &str, frames: &[Frame]) -> Result<(), CliError> {
    if let Some(k) = frames
        .iter()
        .position(|f| f.iter().any(|(x, y)| !(x.is_finite() && y.is_finite())))
    {
        return Err(CliError::failure(format!(
            "`{model}`: a drawn point is not finite at frame {k}; the model leaves its domain there"
        )));
    }
    Ok(())
}

/// The animation of the normal modes at the equilibrium `q` (length `n`): one clip per
/// mode, `q* + s ψₖ sin(ωₖ t)` over one period with [`MODE_FRAMES`] frames, played at one
/// cycle per [`MODE_CYCLE_SECONDS`] at 1×, `s` as in the mode-shape charts (the largest
/// point displacement a fifth of the mechanism's size). Zero-frequency and unstable modes
/// swing their shape over a nominal 2 s cycle. `shapes`: `n × r` in the model's coordinates;
/// `c_left_out` as for [`mode_plot::mode_charts`].
///
/// # Errors
/// A usage error for a model that cannot be drawn ([`Scene::of`]); a failure when a
/// displaced configuration is not finite.
pub(crate) fn modes(
    model: &dyn ModelInfo,
    q: &[f64],
    modes: &NormalModes,
    shapes: &DMatrix<f64>,
    c_left_out: bool,
) -> Result<Animation, CliError> {
    let mut scene = Scene::of(model, &[])?;
    scene.three_d = mode_plot::is_three_d(model, q, shapes);
    // The mode scale measures the displacement of the drawn points.
    let layout = Layout {
        lines: Vec::new(),
        dots: scene.model_points.clone(),
        three_d: scene.three_d,
    };
    let positions = |qk: &[f64]| mode_plot::positions(model, qk);
    let rest = scene.project(&positions(q));
    let size = mode_plot::drawing_size(&rest, &(0..rest.len()).collect::<Vec<_>>());
    let mut clips = Vec::with_capacity(shapes.ncols());
    for (k, omega, kind, psi) in mode_plot::each_mode(modes, shapes) {
        let oscillatory = matches!(kind, ModeKind::Oscillatory) && omega > 0.0;
        let period = if oscillatory {
            std::f64::consts::TAU / omega
        } else {
            MODE_CYCLE_SECONDS
        };
        let s = mode_plot::mode_scale(model, &layout, q, &psi, size);
        let t: Vec<f64> = (0..=MODE_FRAMES)
            .map(|j| period * j as f64 / MODE_FRAMES as f64)
            .collect();
        let frames: Vec<Frame> = t
            .iter()
            .enumerate()
            .map(|(j, _)| {
                let phase = std::f64::consts::TAU * j as f64 / MODE_FRAMES as f64;
                let amplitude = s.unwrap_or(0.0) * phase.sin();
                scene.project(&positions(&mode_plot::displaced(q, &psi, amplitude)))
            })
            .collect();
        check_finite(&model.description().name, &frames)?;
        let described = mode_plot::describe(k + 1, omega, kind, c_left_out);
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
        });
    }
    if clips.is_empty() {
        return Err(CliError::failure(format!(
            "`{}` has no modes to animate",
            model.description().name
        )));
    }
    Ok(Animation { scene, clips })
}

/// Six significant digits without trailing zeros (`30`, `0.5`, `6.398`).
fn short(v: f64) -> String {
    let s = mode_plot::significant(v);
    if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// `v` with `decimals` decimals, trailing zeros dropped, `-0` as `0`.
pub(super) use eomgen::checks::fixed;

/// A round grid spacing: 1, 2 or 5 × 10ᵏ, near `span / 10`.
fn grid_step(span: f64) -> f64 {
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

/// The picture's box `[x0, x1] × [y0, y1]` (m): every drawn point of every frame of every
/// clip, with a border of 6 % of the larger side.
fn bounding_box(clips: &[Clip]) -> (f64, f64, f64, f64) {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (x, y) in clips
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

#[cfg(test)]
mod tests {
    use super::*;

    mod undrawn {
        eomgen::model!("../../../tests/fixtures/undrawn_pendulum.yaml");
    }
    mod energy_form {
        eomgen::model!("../../../symbolic/tests/fixtures/damped_oscillator.yaml");
    }

    /// A model with points but no `draw:` block: a usage error (exit 2) that says what to
    /// add, naming the model's points.
    #[test]
    fn a_model_without_draw_gets_an_error_naming_what_to_add() {
        let model = eomgen::FirstOrder::new(undrawn::UndrawnPendulum::default());
        let e = Scene::of(&model, &[]).err().expect("no draw: block");
        assert_eq!(e.code, 2);
        assert!(e.message.contains("has no `draw:` block"), "{}", e.message);
        assert!(
            e.message.contains("draw: { lines: [[O, P]]"),
            "{}",
            e.message
        );
        // Tracing a point is enough to animate it; a misspelt point is an error.
        let scene = Scene::of(&model, &["P".to_string()]).expect("traced point");
        assert_eq!(scene.names, ["P"]);
        let e = Scene::of(&model, &["Q".to_string()])
            .err()
            .expect("no such point");
        assert!(
            e.message.contains("has no point `Q` (points: O, P)"),
            "{}",
            e.message
        );
    }

    /// An energy-form model has no points at all.
    #[test]
    fn a_model_without_points_gets_an_error() {
        let model = eomgen::FirstOrder::new(energy_form::DampedOscillator::default());
        let e = Scene::of(&model, &[]).err().expect("no points");
        assert!(e.message.contains("has no points"), "{}", e.message);
    }

    #[test]
    fn numbers_are_trimmed_and_grid_steps_are_round() {
        assert_eq!(fixed(-0.0000000000001, 11), "0");
        assert_eq!(fixed(1.5, 11), "1.5");
        assert_eq!(fixed(-2.0, 3), "-2");
        assert_eq!(fixed(12.0, 0), "12");
        assert_eq!(grid_step(6.0), 0.5);
        assert_eq!(grid_step(1.2), 0.1);
        assert_eq!(grid_step(30.0), 2.0);
    }
}
