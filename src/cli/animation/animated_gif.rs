//! The animation as an animated GIF for slides: the same picture as the library's page
//! ([`eomgen::animation`]) drawn frame by frame with plotters, a fixed palette, and each
//! frame only the rectangle that changed.

use eomgen::animation::{Animation, Clip, Scene, grid_step};
use eomgen::text::significant;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::cli::error::CliError;
use crate::cli::plot;

/// The GIF: largest side of the drawing (px), band for the caption (px), frames per second
/// and frame count at most.
const GIF_SIDE: u32 = 440;
const GIF_CAPTION: u32 = 30;
const GIF_MAX_FPS: f64 = 25.0;
const GIF_MAX_FRAMES: usize = 600;
/// Colours of the links, joints and traces (those of the page's stylesheet) and of the grid.
const LINK: (u8, u8, u8) = (0x2b, 0x59, 0xc3);
const JOINT: (u8, u8, u8) = (0x1b, 0x1b, 0x1b);
const TRACE: (u8, u8, u8) = (0xe8, 0x87, 0x1e);
const GRID: (u8, u8, u8) = (0xe8, 0xe8, 0xe8);

/// Writes clip `clip` of `animation` as an animated GIF: the same picture as the page (equal
/// scales, the whole run's box), at most [`GIF_MAX_FPS`] frames per second of `t` and
/// [`GIF_MAX_FRAMES`] frames, played in real time, looping.
///
/// # Errors
/// A failure when drawing or writing the file fails.
///
/// # Panics
/// If `clip` is not an index of [`Animation::clips`].
pub(crate) fn write_gif(animation: &Animation, path: &str, clip: usize) -> Result<(), CliError> {
    let fail = |e: String| CliError::failure(format!("`{path}`: {e}"));
    plot::register_font().map_err(fail)?;
    let scene = animation.scene();
    let clip = &animation.clips()[clip];
    let view = Viewport::new(animation.bounding_box());
    let (width, height) = (view.width, view.height);
    let n = clip.times().len();
    let (step, delay) = frame_step_and_delay(clip);
    let palette = Palette::new();
    // Encoded in memory (at most GIF_MAX_FRAMES frames of a small picture) and written
    // atomically.
    let mut encoder = gif::Encoder::new(Vec::new(), width as u16, height as u16, &palette.rgb)
        .map_err(|e| fail(e.to_string()))?;
    encoder
        .set_repeat(gif::Repeat::Infinite)
        .map_err(|e| fail(e.to_string()))?;
    let mut buffer = vec![0u8; (width * height * 3) as usize];
    let mut previous: Vec<u8> = Vec::new();
    let mut k = 0;
    while k < n {
        draw_frame(&mut buffer, &view, scene, clip, k).map_err(fail)?;
        let indices = palette.map(&buffer);
        let mut frame = changed_rectangle(&previous, &indices, width as usize);
        frame.delay = delay;
        frame.dispose = gif::DisposalMethod::Keep;
        encoder
            .write_frame(&frame)
            .map_err(|e| fail(e.to_string()))?;
        previous = indices;
        k += step;
    }
    let bytes = encoder.into_inner().map_err(|e| fail(e.to_string()))?;
    Ok(crate::cli::files::write(path, &bytes)?)
}

/// The GIF's frame step (every `step`-th frame of `clip` is drawn) and the delay between
/// drawn frames (hundredths of a second, in [2, 6000]): a frame interval of at least
/// 1/[`GIF_MAX_FPS`] s of `t` and at most [`GIF_MAX_FRAMES`] frames, played in real time.
fn frame_step_and_delay(clip: &Clip) -> (usize, u16) {
    let t = clip.times();
    let n = t.len();
    let dt = if n > 1 {
        (t[n - 1] - t[0]) / (n - 1) as f64
    } else {
        1.0
    };
    let step = ((1.0 / (GIF_MAX_FPS * dt)).ceil() as usize)
        .max(n.div_ceil(GIF_MAX_FRAMES))
        .max(1);
    let delay = (100.0 * dt * step as f64 / clip.rate())
        .round()
        .clamp(2.0, 6000.0) as u16;
    (step, delay)
}

/// The GIF's picture of the run's box: equal scales, its larger side [`GIF_SIDE`] px (at
/// least 240 × 80 px), under a band of [`GIF_CAPTION`] px for the caption.
struct Viewport {
    /// The box `(x0, x1, y0, y1)` (m).
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    /// Metres per pixel.
    per_pixel: f64,
    /// Size of the image (px), the caption band included.
    width: u32,
    height: u32,
}

impl Viewport {
    /// The viewport of the box `(x0, x1, y0, y1)` (m).
    fn new((x0, x1, y0, y1): (f64, f64, f64, f64)) -> Self {
        let per_pixel = (x1 - x0).max(y1 - y0) / f64::from(GIF_SIDE);
        let width = ((x1 - x0) / per_pixel).round().max(240.0) as u32;
        let height = ((y1 - y0) / per_pixel).round().max(80.0) as u32 + GIF_CAPTION;
        Self {
            x0,
            x1,
            y0,
            y1,
            per_pixel,
            width,
            height,
        }
    }

    /// The pixel of the point `(x, y)` (m): x to the right from the box's left side, y down
    /// from its top, below the caption band.
    fn pixel(&self, (x, y): (f64, f64)) -> (i32, i32) {
        (
            ((x - self.x0) / self.per_pixel).round() as i32,
            (GIF_CAPTION as f64 + (self.y1 - y) / self.per_pixel).round() as i32,
        )
    }
}

/// Draws frame `k` of `clip` into `buffer` (RGB, the size of `view`): the grid, the traces
/// up to the frame, the links, joints and centres of mass, and the caption (the model and
/// `t`, with the energy of a simulation or the clip's name).
///
/// # Errors
/// A failure of plotters, as `drawing failed: …`.
fn draw_frame(
    buffer: &mut [u8],
    view: &Viewport,
    scene: &Scene,
    clip: &Clip,
    k: usize,
) -> Result<(), String> {
    let root = BitMapBackend::with_buffer(buffer, (view.width, view.height)).into_drawing_area();
    let err = |e: DrawingAreaErrorKind<_>| format!("drawing failed: {e}");
    root.fill(&WHITE).map_err(err)?;
    draw_grid(&root, view)?;
    let frame = &clip.frames()[k];
    for trail in clip.trails() {
        let path: Vec<(i32, i32)> = trail[..=k * clip.trail_substeps()]
            .iter()
            .map(|p| view.pixel(*p))
            .collect();
        root.draw(&PathElement::new(path, rgb(TRACE).stroke_width(2)))
            .map_err(err)?;
    }
    for [a, b] in scene.lines() {
        root.draw(&PathElement::new(
            vec![view.pixel(frame[*a]), view.pixel(frame[*b])],
            rgb(LINK).stroke_width(5),
        ))
        .map_err(err)?;
    }
    for &d in scene.dots() {
        root.draw(&Circle::new(view.pixel(frame[d]), 5, rgb(JOINT).filled()))
            .map_err(err)?;
    }
    for c in scene.centre_points() {
        root.draw(&Circle::new(
            view.pixel(frame[c]),
            8,
            rgb(JOINT).stroke_width(2),
        ))
        .map_err(err)?;
    }
    let t = clip.times();
    let caption = match clip.energy() {
        Some(energy) => format!(
            "{}   t = {:.2} s   E = {} J",
            scene.model(),
            t[k],
            significant(energy[k])
        ),
        None => format!("{}, {}   t = {:.3} s", scene.model(), clip.label(), t[k]),
    };
    root.draw(&Text::new(caption, (10, 7), ("sans-serif", 16).into_font()))
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// The grid of the GIF's background: vertical and horizontal lines across `view`'s box at
/// the multiples of [`grid_step`] of its larger side.
///
/// # Errors
/// A failure of plotters, as `drawing failed: …`.
fn draw_grid(root: &DrawingArea<BitMapBackend<'_>, Shift>, view: &Viewport) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<_>| format!("drawing failed: {e}");
    let (x0, x1, y0, y1) = (view.x0, view.x1, view.y0, view.y1);
    let step_m = grid_step((x1 - x0).max(y1 - y0));
    for i in (x0 / step_m).ceil() as i64..=(x1 / step_m).floor() as i64 {
        let x = i as f64 * step_m;
        root.draw(&PathElement::new(
            vec![view.pixel((x, y0)), view.pixel((x, y1))],
            rgb(GRID),
        ))
        .map_err(err)?;
    }
    for i in (y0 / step_m).ceil() as i64..=(y1 / step_m).floor() as i64 {
        let y = i as f64 * step_m;
        root.draw(&PathElement::new(
            vec![view.pixel((x0, y)), view.pixel((x1, y))],
            rgb(GRID),
        ))
        .map_err(err)?;
    }
    Ok(())
}

/// The plotters colour of an `(r, g, b)` triple such as [`LINK`].
fn rgb((r, g, b): (u8, u8, u8)) -> RGBColor {
    RGBColor(r, g, b)
}

/// A GIF frame of the pixels of `current` (palette indices, rows of `width`) inside the
/// smallest rectangle holding every pixel that differs from `previous` (the whole image when
/// `previous` is empty; one pixel when nothing changed), to be drawn over the previous frame.
fn changed_rectangle(previous: &[u8], current: &[u8], width: usize) -> gif::Frame<'static> {
    let height = current.len() / width;
    let (mut x0, mut x1, mut y0, mut y1) = (width, 0, height, 0);
    if previous.len() == current.len() {
        for (i, (a, b)) in previous.iter().zip(current).enumerate() {
            if a != b {
                let (x, y) = (i % width, i / width);
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
        if x0 > x1 {
            (x0, x1, y0, y1) = (0, 0, 0, 0);
        }
    } else {
        (x0, x1, y0, y1) = (0, width - 1, 0, height - 1);
    }
    let pixels: Vec<u8> = (y0..=y1)
        .flat_map(|y| current[y * width + x0..=y * width + x1].iter().copied())
        .collect();
    let mut frame =
        gif::Frame::from_indexed_pixels((x1 - x0 + 1) as u16, (y1 - y0 + 1) as u16, pixels, None);
    frame.left = x0 as u16;
    frame.top = y0 as u16;
    frame
}

/// The GIF's global palette: white, a grey ramp (text, joints, grid) and ramps from white
/// to each drawing colour (anti-aliased edges), with a lookup table from 5-bit RGB to the
/// nearest entry — fixed, so the file is deterministic and no quantiser is needed.
struct Palette {
    rgb: Vec<u8>,
    table: Vec<u8>,
}

impl Palette {
    fn new() -> Self {
        let mut colours: Vec<(u8, u8, u8)> = Vec::new();
        for i in 0..32u32 {
            let g = (255 * i / 31) as u8;
            colours.push((g, g, g));
        }
        for c in [LINK, TRACE] {
            for i in 1..=16u32 {
                let mix = |from: u8, to: u8| {
                    (f64::from(from) + (f64::from(to) - f64::from(from)) * f64::from(i) / 16.0)
                        .round() as u8
                };
                colours.push((mix(255, c.0), mix(255, c.1), mix(255, c.2)));
            }
        }
        let rgb: Vec<u8> = colours.iter().flat_map(|c| [c.0, c.1, c.2]).collect();
        let mut table = vec![0u8; 1 << 15];
        for (key, entry) in table.iter_mut().enumerate() {
            let channel = |shift: usize| (((key >> shift) & 31) * 255 / 31) as i32;
            let (r, g, b) = (channel(10), channel(5), channel(0));
            let nearest = colours
                .iter()
                .enumerate()
                .min_by_key(|(_, c)| {
                    let d = |a: u8, b: i32| (i32::from(a) - b).pow(2);
                    d(c.0, r) + d(c.1, g) + d(c.2, b)
                })
                .map_or(0, |(i, _)| i);
            *entry = nearest as u8;
        }
        Self { rgb, table }
    }

    /// Palette indices of an RGB buffer.
    fn map(&self, buffer: &[u8]) -> Vec<u8> {
        buffer
            .chunks_exact(3)
            .map(|p| {
                let key = (usize::from(p[0] >> 3) << 10)
                    | (usize::from(p[1] >> 3) << 5)
                    | usize::from(p[2] >> 3);
                self.table[key]
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The palette maps its own colours to themselves (drawn pixels keep their colour).
    #[test]
    fn palette_keeps_the_drawing_colours() {
        let palette = Palette::new();
        for c in [LINK, TRACE, (255, 255, 255), (0, 0, 0)] {
            let i = usize::from(palette.map(&[c.0, c.1, c.2])[0]);
            let entry = &palette.rgb[3 * i..3 * i + 3];
            // 5-bit keys: within 8 per channel of the colour.
            for (a, b) in entry.iter().zip([c.0, c.1, c.2]) {
                assert!(
                    (i32::from(*a) - i32::from(b)).abs() <= 8,
                    "{c:?} → {entry:?}"
                );
            }
        }
    }
}
