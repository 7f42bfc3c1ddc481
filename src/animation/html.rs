//! The animation as one self-contained HTML page: the frames as inline JSON, the drawing as
//! inline SVG, the stylesheet and the player inline.

use std::fmt::Write as _;

use super::{Animation, POSITION_DIGITS, grid_step};
use crate::text::{escape, fixed, short};

/// The stylesheet, the error hooks (first script: they record script errors and
/// `console.error` into `#errors`) and the player.
const STYLE: &str = include_str!("animate.css");
const HOOKS: &str = include_str!("animate_hooks.js");
const PLAYER: &str = include_str!("animate.js");
/// The 3-D view's script, and three.js for it, gzipped (assets/three/README.md).
const VIEW_3D: &str = include_str!("animate3d.js");
const THREE_GZ: &[u8] = include_bytes!("../../assets/three/three-subset.js.gz");

/// A JSON string literal safe inside `<script>` (no `</script>`).
fn json_string(s: &str) -> String {
    serde_json::Value::from(s)
        .to_string()
        .replace('<', "\\u003c")
}

impl Animation {
    /// The page: one self-contained HTML document (UTF-8) with the frames as inline JSON,
    /// the drawing as inline SVG in the box of [`Animation::bounding_box`], and the
    /// stylesheet and player inline; the same animation gives the same bytes.
    pub fn to_html(&self) -> String {
        let scene = &self.scene;
        let (x0, x1, y0, y1) = self.bounding_box();
        let span = (x1 - x0).max(y1 - y0);
        let magnitude = span.log10().floor() as i32;
        let decimals = (POSITION_DIGITS - magnitude).clamp(0, 17) as usize;
        let view_decimals = (5 - magnitude).clamp(0, 17) as usize;
        let p = |v: f64| fixed(v, decimals);
        let v = |v: f64| fixed(v, view_decimals);
        let mut data = self.data_json(&p);
        if scene.three_d() {
            // The 3-D view's data: each clip's points, paths and poses in space, the bodies
            // and the particles (after the planar data, which the fallback draws).
            data.pop();
            data.pop();
            data.push_str(&self.space_json(&p));
        }

        let step = grid_step(span);
        let svg = self.scene_svg((x0, x1, y0, y1), &p, &v);

        let choice = if self.clips.len() > 1 || self.clips[0].period.is_some() {
            let options: Vec<String> = self
                .clips
                .iter()
                .enumerate()
                .map(|(i, c)| format!("<option value=\"{i}\">{}</option>", escape(&c.label)))
                .collect();
            format!(
                "<select id=\"clip\" aria-label=\"mode\">{}</select>",
                options.join("")
            )
        } else {
            String::new()
        };
        let speeds = [0.25, 0.5, 1.0, 2.0, 4.0]
            .iter()
            .map(|s| {
                let selected = if *s == 1.0 { " selected" } else { "" };
                format!("<option value=\"{s}\"{selected}>{s}×</option>")
            })
            .collect::<Vec<_>>()
            .join("");
        let last_frame = self.clips[0].t.len() - 1;
        let view = if scene.three_d() {
            "3-D: drag to turn, scroll to zoom, right-drag to pan (isometric drawing without WebGL: across (x − y) cos 30°, up z + (x + y) sin 30°); "
        } else {
            ""
        };
        let (canvas, views, view_3d) = self.view_3d_parts();
        format!(
            r#"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<script>
{HOOKS}</script>
<style>
{STYLE}</style>
</head>
<body>
<h1>{title}</h1>
<p id="info">{info}</p>
{svg}
{canvas}
<div class="controls">
{choice}
{views}
<button id="play" type="button" title="play or pause (space)">Pause</button>
<label>speed <select id="speed">{speeds}</select></label>
<input id="scrub" type="range" min="0" max="{last_frame}" step="1" value="0" aria-label="frame">
</div>
<div id="marks" title="the contacts' transitions over the run"></div>
<div class="readout"><span id="time" data-t="0">t = 0 s</span><span id="energy"></span><span id="drift"></span><span id="event"></span><span id="frame" data-frame="0">frame 1 / {frames}</span><span class="hint">{view}<span id="grid-step">grid {grid} m</span> · space: play/pause · ←/→: step</span><span id="view-note"></span></div>
<pre id="errors"></pre>
<script>
const DATA = {data};
</script>
<script>
{PLAYER}</script>
{view_3d}</body>
</html>
"#,
            title = escape(&scene.title),
            info = escape(&self.clips[0].info),
            frames = last_frame + 1,
            grid = short(step),
        )
    }

    /// The data of the player, a JS object literal: the scene (names, lines, dots, traces,
    /// centres) and every clip's times and frames; positions through `p`.
    fn data_json(&self, p: &dyn Fn(f64) -> String) -> String {
        let scene = &self.scene;
        let mut data = String::new();
        let names: Vec<String> = scene.names.iter().map(|n| json_string(n)).collect();
        let pairs = |list: &[usize]| {
            list.iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(",")
        };
        let _ = write!(
            data,
            "{{\"title\":{},\"names\":[{}],\"lines\":[{}],\"dots\":[{}],\"traces\":[{}],\"centres\":[{}],\"clips\":[",
            json_string(&scene.title),
            names.join(","),
            scene
                .lines
                .iter()
                .map(|[a, b]| format!("[{a},{b}]"))
                .collect::<Vec<_>>()
                .join(","),
            pairs(&scene.dots),
            pairs(&scene.traces),
            pairs(&scene.centres.iter().map(|c| c.0).collect::<Vec<_>>()),
        );
        for (c, clip) in self.clips.iter().enumerate() {
            if c > 0 {
                data.push(',');
            }
            let _ = write!(
                data,
                "\n{{\"label\":{},\"info\":{},\"rate\":{:e},\"period\":{},\"t\":[{}],\n\"xy\":[",
                json_string(&clip.label),
                json_string(&clip.info),
                clip.rate,
                clip.period.map_or("null".to_string(), |p| format!("{p:e}")),
                clip.t
                    .iter()
                    .map(|t| format!("{t:e}"))
                    .collect::<Vec<_>>()
                    .join(","),
            );
            for (k, f) in clip.frames.iter().enumerate() {
                if k > 0 {
                    data.push_str(",\n");
                }
                data.push('[');
                for (i, (x, y)) in f.iter().enumerate() {
                    if i > 0 {
                        data.push(',');
                    }
                    let _ = write!(data, "{},{}", p(*x), p(*y));
                }
                data.push(']');
            }
            data.push_str("],\n\"trail\":[");
            for (i, path) in clip.trail.iter().enumerate() {
                if i > 0 {
                    data.push_str(",\n");
                }
                let xy: Vec<String> = path
                    .iter()
                    .map(|(x, y)| format!("{},{}", p(*x), p(*y)))
                    .collect();
                let _ = write!(data, "[{}]", xy.join(","));
            }
            let _ = write!(data, "],\"sub\":{}", clip.sub);
            if let Some(e) = &clip.energy {
                let _ = write!(
                    data,
                    ",\n\"e\":[{}],\n\"de\":[{}]",
                    e.energy
                        .iter()
                        .map(|v| format!("{v:e}"))
                        .collect::<Vec<_>>()
                        .join(","),
                    e.drift
                        .iter()
                        .map(|v| format!("{v:.2e}"))
                        .collect::<Vec<_>>()
                        .join(",")
                );
            }
            if !clip.transitions.is_empty() {
                // The contacts' transitions, `[t, text, first frame after it]` (names are
                // identifiers, the text is escaped as JSON all the same).
                let list: Vec<String> = (clip.transitions.iter())
                    .map(|(t, text, frame)| {
                        let text = serde_json::Value::String(text.clone()).to_string();
                        format!("[{},{text},{frame}]", p(*t))
                    })
                    .collect();
                let _ = write!(data, ",\n\"ev\":[{}]", list.join(","));
            }
            data.push('}');
        }
        data.push_str("]}");
        data
    }

    /// A 3-D scene's canvas, its view buttons and its scripts (three.js in base64, then the
    /// view); nothing for a planar scene.
    fn view_3d_parts(&self) -> (&'static str, &'static str, String) {
        if !self.scene.three_d() {
            return ("", "", String::new());
        }
        use base64::Engine as _;
        let three = base64::engine::general_purpose::STANDARD.encode(THREE_GZ);
        (
            "<canvas id=\"view3d\" hidden></canvas>",
            "<span id=\"views\" hidden>view <button type=\"button\" data-view=\"iso\">iso</button><button type=\"button\" data-view=\"top\">top</button><button type=\"button\" data-view=\"side\">side</button> <label title=\"keep the mechanism in the middle of the view\"><input id=\"follow\" type=\"checkbox\"> follow</label></span>",
            format!(
                "<script id=\"three-gz\" type=\"application/octet-stream\">{three}</script>\n<script>\n{VIEW_3D}</script>\n"
            ),
        )
    }

    /// The end of the player's data for a 3-D scene, in place of the closing `]}` of
    /// [`Self::data_json`]: per clip (`space`, in the clips' order) its 3-D points (`xyz`),
    /// paths (`trail3`) and poses
    /// (`pose`, per body `[x, y, z, qx, qy, qz, qw]`), then the bodies (their solids in m,
    /// the solid's quaternion in the body frame, the largest dimension) and the centres
    /// marked with a dot (`particles`, indices of drawn points).
    fn space_json(&self, p: &dyn Fn(f64) -> String) -> String {
        let unit = |v: f64| fixed(v, 12);
        let flat = |list: &[[f64; 3]]| {
            (list.iter().flatten())
                .map(|v| p(*v))
                .collect::<Vec<_>>()
                .join(",")
        };
        let mut out = "],\"space\":[".to_string();
        for (c, clip) in self.clips.iter().enumerate() {
            if c > 0 {
                out.push_str(",\n");
            }
            // Every clip of a 3-D scene has its space; `null` keeps the lists aligned.
            let Some(space) = &clip.space else {
                out.push_str("null");
                continue;
            };
            let frames: Vec<String> = (space.points.iter())
                .map(|f| format!("[{}]", flat(f)))
                .collect();
            let trails: Vec<String> = (space.trail.iter())
                .map(|t| format!("[{}]", flat(t)))
                .collect();
            let poses: Vec<String> = (space.poses.iter())
                .map(|f| {
                    let numbers: Vec<String> = (f.iter())
                        .flat_map(|b| {
                            let (position, turn) = b.split_at(3);
                            position
                                .iter()
                                .map(|v| p(*v))
                                .chain(turn.iter().map(|v| unit(*v)))
                        })
                        .collect();
                    format!("[{}]", numbers.join(","))
                })
                .collect();
            let _ = write!(
                out,
                "{{\"xyz\":[{}],\n\"trail3\":[{}],\n\"pose\":[{}]}}",
                frames.join(",\n"),
                trails.join(",\n"),
                poses.join(",\n")
            );
        }
        let bodies: Vec<String> = (self.scene.bodies().iter())
            .map(|b| {
                let solid = match b.solid {
                    super::pose::Solid::Box([a, b, c]) => {
                        format!("[\"box\",{},{},{}]", p(a), p(b), p(c))
                    }
                    super::pose::Solid::Cylinder { radius, length } => {
                        format!("[\"cylinder\",{},{}]", p(radius), p(length))
                    }
                    super::pose::Solid::Sphere(r) => format!("[\"sphere\",{}]", p(r)),
                };
                let local: Vec<String> = b.local_quaternion().iter().map(|v| unit(*v)).collect();
                format!(
                    "{{\"name\":{},\"solid\":{solid},\"local\":[{}],\"extent\":{},\"inertia\":{}}}",
                    json_string(&b.name),
                    local.join(","),
                    p(b.extent()),
                    b.from_inertia
                )
            })
            .collect();
        // The centres the 3-D view marks with a dot: those of the bodies it draws no solid
        // for (particles, planar bodies).
        let drawn: Vec<&str> = self
            .scene
            .bodies()
            .iter()
            .map(|b| b.name.as_str())
            .collect();
        let particles: Vec<String> = (self.scene.centres.iter())
            .filter(|(_, _, body)| !drawn.contains(&body.as_str()))
            .map(|(i, _, _)| i.to_string())
            .collect();
        let _ = write!(
            out,
            "],\"bodies\":[{}],\"particles\":[{}]}}",
            bodies.join(","),
            particles.join(",")
        );
        out
    }

    /// The picture: the grid over the box `(x0, x1, y0, y1)` and the mechanism at the first
    /// frame, positions through `p`, view-box sizes through `v`.
    fn scene_svg(
        &self,
        (x0, x1, y0, y1): (f64, f64, f64, f64),
        p: &dyn Fn(f64) -> String,
        v: &dyn Fn(f64) -> String,
    ) -> String {
        let scene = &self.scene;
        let span = (x1 - x0).max(y1 - y0);
        // The picture: y up (a flipped group), the view box of the whole run.
        let mut svg = String::new();
        let _ = write!(
            svg,
            "<svg id=\"scene\" viewBox=\"{} {} {} {}\" role=\"img\" aria-label=\"{}\">\n<g transform=\"scale(1,-1)\">\n<g class=\"grid\">",
            v(x0),
            v(-y1),
            v(x1 - x0),
            v(y1 - y0),
            escape(&scene.title)
        );
        // The grid covers twice the box about its centre, so it fills a view box widened to
        // the page's shape.
        let step = grid_step(span);
        let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        let (gx0, gx1, gy0, gy1) = (cx - span, cx + span, cy - span, cy + span);
        let first = |lo: f64| (lo / step).ceil() as i64;
        let last = |hi: f64| (hi / step).floor() as i64;
        for i in first(gx0)..=last(gx1) {
            let x = i as f64 * step;
            let class = if i == 0 { " class=\"axis\"" } else { "" };
            let _ = write!(
                svg,
                "<line{class} x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>",
                v(x),
                v(gy0),
                v(x),
                v(gy1)
            );
        }
        for i in first(gy0)..=last(gy1) {
            let y = i as f64 * step;
            let class = if i == 0 { " class=\"axis\"" } else { "" };
            let _ = write!(
                svg,
                "<line{class} x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>",
                v(gx0),
                v(y),
                v(gx1),
                v(y)
            );
        }
        svg.push_str("</g>\n");
        let f0 = &self.clips[0].frames[0];
        for i in 0..scene.traces.len() {
            let _ = write!(svg, "<polyline id=\"tr{i}\" class=\"trace\" points=\"\"/>");
        }
        for (i, [a, b]) in scene.lines.iter().enumerate() {
            let _ = write!(
                svg,
                "<line id=\"l{i}\" class=\"link\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>",
                p(f0[*a].0),
                p(f0[*a].1),
                p(f0[*b].0),
                p(f0[*b].1)
            );
        }
        let radius = v(0.012 * span);
        for (i, d) in scene.dots.iter().enumerate() {
            let _ = write!(
                svg,
                "<circle id=\"d{i}\" class=\"joint\" cx=\"{}\" cy=\"{}\" r=\"{radius}\"><title>{}</title></circle>",
                p(f0[*d].0),
                p(f0[*d].1),
                escape(&scene.names[*d])
            );
        }
        for (i, (c, rigid, body)) in scene.centres.iter().enumerate() {
            let kind = if *rigid { "rigid body" } else { "particle" };
            let _ = write!(
                svg,
                "<circle id=\"c{i}\" class=\"centre\" cx=\"{}\" cy=\"{}\" r=\"{}\"><title>{} ({kind}), centre of mass {}</title></circle>",
                p(f0[*c].0),
                p(f0[*c].1),
                v(0.022 * span),
                escape(body),
                escape(&scene.names[*c])
            );
        }
        svg.push_str("\n</g>\n</svg>");
        svg
    }
}
