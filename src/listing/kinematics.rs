//! Kinematics on demand (`eomgen kinematics`, the Python package's `Model.kinematics`): the
//! angular velocity and acceleration of a model's frames, the position, velocity and
//! acceleration of its points and their partial velocities, printed as text and LaTeX from
//! [`eomgen_symbolic::mechanics::SymbolicModel::frame_kinematics`] and
//! [`eomgen_symbolic::mechanics::SymbolicModel::point_kinematics`].

use std::fmt::Write as _;

use eomgen_symbolic::expr::ExprId;
use eomgen_symbolic::expr::print::{Printer, Syntax};
use eomgen_symbolic::mechanics::SymbolicModel;
use serde::Serialize;

use super::error::ListingError;

/// What [`kinematics`] lists.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct KinematicsOptions {
    /// The frames, by name (empty: every frame of the file's `frames:`).
    pub frames: Vec<String>,
    /// The points, by name (empty: every point of the file's `points:`).
    pub points: Vec<String>,
    /// Whether to list the partial velocities `∂v/∂q̇ᵢ` and `∂ω/∂q̇ᵢ` too.
    pub partial: bool,
    /// The reactions to list: the force and moment on a set of bodies at a point besides
    /// gravity and their own torques (a joint the model leaves implicit).
    pub reactions: Vec<ReactionRequest>,
}

/// A reaction [`kinematics`] lists: on the bodies `bodies`, the moment about the point `at`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ReactionRequest {
    /// The bodies, by name.
    pub bodies: Vec<String>,
    /// The point, by name.
    pub at: String,
}

/// One reaction as [`kinematics`] lists it
/// ([`eomgen_symbolic::mechanics::Reaction`]): expressions of `q`, `q̇` and `q̈`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReactionListing {
    /// The bodies it acts on.
    pub bodies: Vec<String>,
    /// The point the moment is about.
    pub at: String,
    /// `R = Σ m a_G − Σ m g` in `N`'s components (N).
    pub force: Vec<String>,
    /// `M_P` in `N`'s components (N·m; its `z` component alone in a planar model).
    pub moment: Vec<String>,
}

/// One frame's angular motion in the ground frame `N`, each vector as its three components.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameListing {
    /// The frame's name.
    pub name: String,
    /// `^N ω^F` in the frame's own components (rad/s).
    pub angular_velocity: Vec<String>,
    /// `^N ω^F` in `N`'s components (rad/s).
    pub angular_velocity_ground: Vec<String>,
    /// `^N α^F` in the frame's own components (rad/s²).
    pub angular_acceleration: Vec<String>,
    /// `∂ω/∂q̇ᵢ` in the frame's components, per coordinate `qᵢ` (in coordinate order); empty
    /// unless asked for, and then left out of the JSON.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub partial_angular_velocities: Vec<Vec<String>>,
}

/// One point's motion in the ground frame `N`, in `N`'s components (two for a planar model).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointListing {
    /// The point's name.
    pub name: String,
    /// `r_P` (m).
    pub position: Vec<String>,
    /// `^N v_P` (m/s).
    pub velocity: Vec<String>,
    /// `^N a_P` (m/s²).
    pub acceleration: Vec<String>,
    /// `∂v_P/∂q̇ᵢ` per coordinate `qᵢ` (in coordinate order); empty unless asked for, and
    /// then left out of the JSON.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub partial_velocities: Vec<Vec<String>>,
}

/// The frames and points listed in one syntax.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct KinematicsListing {
    /// The frames asked for, in the file's order.
    pub frames: Vec<FrameListing>,
    /// The points asked for, in the file's order.
    pub points: Vec<PointListing>,
    /// The reactions asked for, in the order asked; left out of the JSON when none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub reactions: Vec<ReactionListing>,
}

/// A model's kinematics, as `eomgen kinematics --json` prints it: `{"model", "coordinates",
/// "frames", "points", "latex": {"frames", "points"}}`, the expressions in the model file's
/// syntax (they parse back with the model parser, and with SymPy once `^` is `**`), rates
/// named `x_dot` and accelerations `x_ddot`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Kinematics {
    /// The model's name.
    pub model: String,
    /// The coordinates `qᵢ`, the order of the partial velocities.
    pub coordinates: Vec<String>,
    /// With generalized speeds (`speeds:`), the speeds `uᵢ` the partial velocities are taken
    /// with respect to (in place of the rates); left out of the JSON otherwise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub speeds: Vec<String>,
    /// The frames and points in the model file's syntax.
    #[serde(flatten)]
    pub listing: KinematicsListing,
    /// The same in LaTeX.
    pub latex: KinematicsListing,
    /// The listing as `eomgen kinematics` prints it (not serialised).
    #[serde(skip)]
    pub text: String,
    /// The listing as `eomgen kinematics --latex` prints it (not serialised).
    #[serde(skip)]
    pub latex_document: String,
}

/// Loads the model file `text` (`path` names it in diagnostics) and lists the kinematics
/// `options` asks for: each frame's `^N ω^F` (in its own and in `N`'s components) and
/// `^N α^F`, each point's position, velocity and acceleration in `N`, and with
/// `options.partial` the partial velocities with the coordinate rates as generalized
/// speeds (with `speeds:`, with respect to the file's speeds).
///
/// # Errors
/// [`ListingError::Diagnostics`] for a file with mistakes; [`ListingError::UnknownName`] for
/// a frame or point the file does not have; [`ListingError::Reaction`] for a reaction that
/// cannot be computed.
///
/// # Examples
/// ```
/// use eomgen::listing::{KinematicsOptions, kinematics};
/// let Some(top) = eomgen::models::find("heavy_top") else { return Ok(()) };
/// let text = top.source();
/// let options = KinematicsOptions { frames: vec!["B".into()], ..Default::default() };
/// let k = kinematics("heavy_top.yaml", text, &options)?;
/// assert_eq!(k.listing.frames[0].angular_velocity.len(), 3);
/// # Ok::<(), eomgen::listing::ListingError>(())
/// ```
///
/// # References
/// Kane & Levinson, *Dynamics: Theory and Applications* (1985), §§2.1–2.7, 2.14; lecture 18.
pub fn kinematics(
    path: &str,
    text: &str,
    options: &KinematicsOptions,
) -> Result<Kinematics, ListingError> {
    let file = eomgen_symbolic::model::load(path, text).map_err(ListingError::Diagnostics)?;
    let mut model = SymbolicModel::from_file(&file).map_err(ListingError::Diagnostics)?;
    let file_frames: Vec<String> = file.frames.iter().map(|f| f.name.value.clone()).collect();
    let file_points: Vec<String> = file.points.iter().map(|p| p.name.value.clone()).collect();
    let frames = chosen("frame", &options.frames, &file_frames)?;
    let points = chosen("point", &options.points, &file_points)?;
    let mut frame_exprs = Vec::new();
    for name in &frames {
        let Some(index) = model.frame_names().iter().position(|f| f == name) else {
            continue;
        };
        frame_exprs.push(model.frame_kinematics(index));
    }
    let mut point_exprs = Vec::new();
    for name in &points {
        let Some(index) = model.points.iter().position(|(p, _)| p == name) else {
            continue;
        };
        point_exprs.push(model.point_kinematics(index));
    }
    let reactions = (options.reactions.iter())
        .map(|r| model.reaction(&r.bodies, &r.at))
        .collect::<Result<Vec<_>, _>>()
        .map_err(ListingError::Reaction)?;
    let start = model.arena.len();
    for f in &mut frame_exprs {
        let parts = [
            &mut f.angular_velocity,
            &mut f.angular_velocity_ground,
            &mut f.angular_acceleration,
        ];
        for v in parts
            .into_iter()
            .chain(f.partial_angular_velocities.iter_mut())
        {
            *v = v.map(|x| model.arena.readable_within(x, start));
        }
    }
    for k in &mut point_exprs {
        let parts = [&mut k.position, &mut k.velocity, &mut k.acceleration];
        for v in parts.into_iter().chain(k.partial_velocities.iter_mut()) {
            for x in v.iter_mut() {
                *x = model.arena.readable_within(*x, start);
            }
        }
    }
    let mut reactions = reactions;
    for r in &mut reactions {
        for x in r.force.iter_mut().chain(r.moment.iter_mut()) {
            *x = model.arena.readable_within(*x, start);
        }
    }
    let list = |syntax: Syntax| {
        let p = Printer::for_display(&model.arena, syntax);
        let show = |v: &[ExprId]| v.iter().map(|&e| p.print(e)).collect::<Vec<_>>();
        KinematicsListing {
            frames: (frame_exprs.iter())
                .map(|f| FrameListing {
                    name: f.name.clone(),
                    angular_velocity: show(&f.angular_velocity),
                    angular_velocity_ground: show(&f.angular_velocity_ground),
                    angular_acceleration: show(&f.angular_acceleration),
                    partial_angular_velocities: match options.partial {
                        true => f
                            .partial_angular_velocities
                            .iter()
                            .map(|w| show(w))
                            .collect(),
                        false => Vec::new(),
                    },
                })
                .collect(),
            points: (point_exprs.iter())
                .map(|k| PointListing {
                    name: k.name.clone(),
                    position: show(&k.position),
                    velocity: show(&k.velocity),
                    acceleration: show(&k.acceleration),
                    partial_velocities: match options.partial {
                        true => k.partial_velocities.iter().map(|v| show(v)).collect(),
                        false => Vec::new(),
                    },
                })
                .collect(),
            reactions: (reactions.iter())
                .map(|r| ReactionListing {
                    bodies: r.bodies.clone(),
                    at: r.at.clone(),
                    force: show(&r.force),
                    moment: show(&r.moment),
                })
                .collect(),
        }
    };
    let listing = list(Syntax::Text);
    let latex = list(Syntax::Latex);
    let coordinates = model.coordinate_names.clone();
    // What the partial velocities are taken with respect to: the rates `q_dot`, or with
    // generalized speeds (`speeds:`) the speeds.
    let speeds: Option<Vec<String>> = model.speeds.as_ref().map(|s| s.names.clone());
    Ok(Kinematics {
        text: render_text(&model.name, &coordinates, speeds.as_deref(), &listing),
        latex_document: render_latex(&coordinates, speeds.as_deref(), &latex),
        model: model.name.clone(),
        coordinates,
        speeds: speeds.unwrap_or_default(),
        listing,
        latex,
    })
}

/// The names asked for (`asked`), checked against the file's (`known`), or all of them.
fn chosen(
    kind: &'static str,
    asked: &[String],
    known: &[String],
) -> Result<Vec<String>, ListingError> {
    if asked.is_empty() {
        return Ok(known.to_vec());
    }
    match asked.iter().find(|a| !known.contains(a)) {
        Some(name) => Err(ListingError::UnknownName {
            kind,
            name: name.clone(),
            known: match known.is_empty() {
                true => vec![format!("none: the file has no `{kind}s:`")],
                false => known.to_vec(),
            },
        }),
        None => Ok(known
            .iter()
            .filter(|k| asked.contains(k))
            .cloned()
            .collect()),
    }
}

/// `[a, b, c]`.
fn vector(v: &[String]) -> String {
    format!("[{}]", v.join(", "))
}

/// The listing as `eomgen kinematics` prints it.
fn render_text(
    model: &str,
    coordinates: &[String],
    speeds: Option<&[String]>,
    k: &KinematicsListing,
) -> String {
    let rates: Vec<String> = match speeds {
        Some(speeds) => speeds.to_vec(),
        None => coordinates.iter().map(|q| format!("{q}_dot")).collect(),
    };
    let mut out = String::new();
    let _ = writeln!(out, "kinematics of `{model}` in the ground frame N");
    for f in &k.frames {
        let _ = writeln!(
            out,
            "\nframe {} (angular velocity in rad/s, acceleration in rad/s^2)",
            f.name
        );
        let _ = writeln!(
            out,
            "  omega ({} components) = {}",
            f.name,
            vector(&f.angular_velocity)
        );
        let _ = writeln!(
            out,
            "  omega (N components) = {}",
            vector(&f.angular_velocity_ground)
        );
        let _ = writeln!(
            out,
            "  alpha ({} components) = {}",
            f.name,
            vector(&f.angular_acceleration)
        );
        for (u, w) in rates.iter().zip(&f.partial_angular_velocities) {
            let _ = writeln!(out, "  d omega/d {u} = {}", vector(w));
        }
    }
    for r in &k.reactions {
        let _ = writeln!(
            out,
            "\nreaction on {} at {} (besides gravity and their torques; N components, N and N*m)",
            r.bodies.join(" + "),
            r.at
        );
        let _ = writeln!(out, "  R = {}", vector(&r.force));
        let _ = writeln!(out, "  M_{} = {}", r.at, vector(&r.moment));
    }
    for p in &k.points {
        let _ = writeln!(out, "\npoint {} (N components: m, m/s, m/s^2)", p.name);
        let _ = writeln!(out, "  r = {}", vector(&p.position));
        let _ = writeln!(out, "  v = {}", vector(&p.velocity));
        let _ = writeln!(out, "  a = {}", vector(&p.acceleration));
        for (u, v) in rates.iter().zip(&p.partial_velocities) {
            let _ = writeln!(out, "  d v/d {u} = {}", vector(v));
        }
    }
    out
}

/// A column vector in LaTeX.
fn latex_vector(v: &[String]) -> String {
    format!("\\begin{{bmatrix}} {} \\end{{bmatrix}}", v.join(" \\\\ "))
}

/// The listing as `eomgen kinematics --latex` prints it: an amsmath document body, one
/// `lhs &= [v] \\` row per vector.
fn render_latex(
    coordinates: &[String],
    speeds: Option<&[String]>,
    k: &KinematicsListing,
) -> String {
    let symbol = eomgen_symbolic::expr::print::latex_symbol;
    let mut rows: Vec<(String, &[String])> = Vec::new();
    // With respect to `q̇ᵢ`, or with generalized speeds to `uᵢ`.
    let rates: Vec<String> = match speeds {
        Some(speeds) => speeds.iter().map(|u| symbol(u)).collect(),
        None => (coordinates.iter())
            .map(|q| format!("\\dot{{{}}}", symbol(q)))
            .collect(),
    };
    let partial = |of: &str, u: &str| format!("\\frac{{\\partial\\, {of}}}{{\\partial {u}}}");
    for f in &k.frames {
        let frame = symbol(&f.name);
        let omega = format!("{{}}^{{N}}\\boldsymbol{{\\omega}}^{{{frame}}}");
        rows.push((
            format!("{omega} \\quad (\\text{{in }} {frame})"),
            &f.angular_velocity,
        ));
        rows.push((
            format!("{omega} \\quad (\\text{{in }} N)"),
            &f.angular_velocity_ground,
        ));
        let alpha =
            format!("{{}}^{{N}}\\boldsymbol{{\\alpha}}^{{{frame}}} \\quad (\\text{{in }} {frame})");
        rows.push((alpha, &f.angular_acceleration));
        for (u, w) in rates.iter().zip(&f.partial_angular_velocities) {
            rows.push((partial(&omega, u), w));
        }
    }
    for p in &k.points {
        let point = symbol(&p.name);
        let velocity = format!("{{}}^{{N}}\\mathbf{{v}}_{{{point}}}");
        rows.push((format!("\\mathbf{{r}}_{{{point}}}"), &p.position));
        rows.push((velocity.clone(), &p.velocity));
        rows.push((
            format!("{{}}^{{N}}\\mathbf{{a}}_{{{point}}}"),
            &p.acceleration,
        ));
        for (u, v) in rates.iter().zip(&p.partial_velocities) {
            rows.push((partial(&velocity, u), v));
        }
    }
    for r in &k.reactions {
        let at = symbol(&r.at);
        let on: Vec<String> = r.bodies.iter().map(|b| format!("\\text{{{b}}}")).collect();
        let on = on.join("+");
        rows.push((format!("\\mathbf{{R}}_{{{at}}}^{{{on}}}"), &r.force));
        rows.push((format!("\\mathbf{{M}}_{{{at}}}^{{{on}}}"), &r.moment));
    }
    let mut out = String::from("\\begin{align*}\n");
    for (lhs, v) in rows {
        let _ = writeln!(out, "{lhs} &= {} \\\\", latex_vector(v));
    }
    out.push_str("\\end{align*}\n");
    out
}
