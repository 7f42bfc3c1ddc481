//! Reference frames (`frames:`): a frame is its parent turned by successive simple rotations
//! (Kane & Levinson, *Dynamics: Theory and Applications*, 1985, §1.7–1.9; rotations and
//! rotating coordinate systems are lectures 11 and 20 of the course).
//!
//! ```yaml
//! frames:
//!   A: { parent: N, axis: z, angle: psi }                     # one simple rotation
//!   B: { parent: A, axes: xz, angles: [theta, phi] }          # successive ones, body-fixed
//!   C: { parent: N, axes: zyx, angles: [a, b, c], about: parent }
//! ```
//!
//! The frames form a tree rooted at the ground frame `N`. The kinematics engine
//! (`mechanics::frames`) composes their rotation matrices and angular velocities; this module
//! gives it each frame's rotations as expressions, and names the components of a frame's
//! angular velocity that expressions may read, `omega_<frame>_<axis>`.

use super::{Axis, Depends, GROUND_FRAME, Lower, Rules, Units};
use crate::expr::ExprId;
use crate::mechanics::frames::RotationAxis;
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::Located;
use crate::model::schema::entries::get;
use crate::model::schema::walk::{Ctx, Fields, Keyed, Need};
use crate::model::schema::write::{NotRewritten, Writer, flow, list};
use crate::model::units::Dimension;
use crate::model::yaml::{YamlKind, YamlNode};

/// The key of the section.
pub(crate) const KEY: &str = "frames";

/// One simple rotation: the new frame is the previous one turned by `angle` (rad, right-hand
/// rule) about `axis`, an axis fixed in both.
#[derive(Debug, Clone, PartialEq)]
pub struct SimpleRotation {
    /// The axis (for a rotation about `direction`, where it is written).
    pub axis: Located<Axis>,
    /// The angle (rad), an expression of the parameters, coordinates and `t`.
    pub angle: Expr,
    /// An oblique axis, `axis: [a, b, c]`: the components, in the frame before the rotation
    /// (and after: the axis is fixed in both), of a constant vector the rotation turns about
    /// (normalised where lowered; any length but zero). `None` for `x`, `y` or `z`.
    pub direction: Option<[Expr; 3]>,
    /// Euler parameters, `quaternion: [e0, e1, e2, e3]`: the vector part `[e1, e2, e3]`, the
    /// scalar part `e0` being [`Self::angle`]; the rotation is then the one they give (in
    /// `axis` only its location is meant). `None` for a simple rotation.
    pub quaternion: Option<[Expr; 3]>,
}

/// A reference frame: its parent turned by successive simple rotations (Kane & Levinson,
/// *Dynamics: Theory and Applications*, 1985, §1.7–1.9).
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Name.
    pub name: Located<String>,
    /// The parent frame ([`GROUND_FRAME`] or a frame defined earlier in the file).
    pub parent: Located<String>,
    /// The rotations in the order they are applied, each about an axis of the frame the
    /// previous ones produced (body-fixed; `about: parent` is stored here already reversed,
    /// which gives the same orientation).
    pub rotations: Vec<SimpleRotation>,
}

/// An example of a frame, in messages.
pub(crate) const EXAMPLE: &str = "{ parent: N, axes: zxz, angles: [psi, theta, phi] }";

/// The keys of a frame.
const FIELDS: Fields = Fields {
    kind: "frame",
    keys: &[
        ("parent", Need::Optional),
        ("axis", Need::Optional),
        ("angle", Need::Optional),
        ("axes", Need::Optional),
        ("angles", Need::Optional),
        ("about", Need::Optional),
        ("quaternion", Need::Optional),
    ],
    example: EXAMPLE,
};

/// `frames:` — `name: { parent, axis, angle }` or `name: { parent, axes, angles, about }`, in
/// file order.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Vec<Frame> {
    let example = format!("frames: {{ B: {EXAMPLE} }}");
    let spec = Keyed {
        what: "`frames`",
        example: &example,
        names: Some("frame"),
        drop: true,
    };
    cx.keyed(node, spec, read_frame)
}

/// One frame: its parent (the ground `N` if not given) turned by one simple rotation
/// (`axis`, `angle`) or by several (`axes: zxz`, `angles: [...]`), each about an axis of the
/// newest frame (`about: body`, the default) or of the parent (`about: parent`).
fn read_frame(cx: &mut Ctx<'_>, k: &Located<String>, v: &YamlNode) -> Option<Frame> {
    let f = cx.fields(k, v, &FIELDS)?;
    let what = format!("frame `{}`", k.value);
    let example = format!("{}: {EXAMPLE}", k.value);
    let parent = match get(f, "parent") {
        Some(n) => cx.name(n, "`parent`")?,
        None => Located::new(GROUND_FRAME.to_string(), k.location),
    };
    let single = get(f, "axis").is_some() || get(f, "angle").is_some();
    let several = get(f, "axes").is_some() || get(f, "angles").is_some();
    if let Some(node) = get(f, "quaternion") {
        if single || several || get(f, "about").is_some() {
            cx.error(
                Diagnostic::new(k.location, format!("{what} has both `quaternion` and rotation angles"))
                    .with_help(format!("a frame is turned either by Euler parameters, `{}: {{ parent: N, quaternion: [e0, e1, e2, e3] }}`, or by simple rotations", k.value)),
            );
            return None;
        }
        return Some(Frame {
            name: k.clone(),
            parent,
            rotations: vec![quaternion(cx, node)?],
        });
    }
    if single == several {
        let message = if single {
            format!("{what} has both `axis`/`angle` and `axes`/`angles`")
        } else {
            format!("{what} has no rotation")
        };
        cx.error(Diagnostic::new(k.location, message).with_help(format!(
            "one simple rotation is `{}: {{ parent: N, axis: z, angle: psi }}`; successive ones `{example}`",
            k.value
        )));
        return None;
    }
    let (axes_key, angles_key) = if single {
        ("axis", "angle")
    } else {
        ("axes", "angles")
    };
    if !cx.require(f, k.location, &what, &[axes_key, angles_key], &example) {
        return None;
    }
    // `axis: [a, b, c]`: one rotation about an oblique axis, its components constants.
    let oblique = match (&get(f, axes_key)?.kind, single) {
        (YamlKind::Seq(items), true) => Some(oblique_axis(cx, get(f, axes_key)?, items)?),
        _ => None,
    };
    let axes = match oblique {
        Some(_) => vec![Located::new(Axis::Z, get(f, axes_key)?.location)],
        None => cx.axes(get(f, axes_key)?, single)?,
    };
    let angles: Vec<Expr> = if single {
        vec![cx.expr(get(f, "angle")?, "a rotation angle")?]
    } else {
        let node = get(f, "angles")?;
        let items = cx.seq(node, "`angles`", "angles: [psi, theta, phi]")?;
        if items.len() != axes.len() {
            cx.error(
                Diagnostic::new(
                    node.location,
                    format!("{what} has {} axes but {} angles", axes.len(), items.len()),
                )
                .with_help("give one angle per axis, in the same order"),
            );
            return None;
        }
        let angles: Vec<Option<Expr>> = items
            .iter()
            .map(|i| cx.expr(i, "a rotation angle"))
            .collect();
        angles.into_iter().collect::<Option<_>>()?
    };
    let about_parent = match get(f, "about") {
        None => false,
        Some(n) => cx.choice(n, "`about`", &[("body", false), ("parent", true)])?,
    };
    let mut rotations: Vec<SimpleRotation> = axes
        .into_iter()
        .zip(angles)
        .map(|(axis, angle)| SimpleRotation {
            axis,
            angle,
            direction: oblique.clone(),
            quaternion: None,
        })
        .collect();
    // Rotations about the parent's fixed axes in the order a, b, c give the orientation of
    // rotations about the newest frame's axes in the order c, b, a.
    if about_parent {
        rotations.reverse();
    }
    Some(Frame {
        name: k.clone(),
        parent,
        rotations,
    })
}

/// `quaternion: [e0, e1, e2, e3]`: the frame's orientation in Euler parameters (expressions of
/// the coordinates, normally four coordinates), as one rotation.
fn quaternion(cx: &mut Ctx<'_>, node: &YamlNode) -> Option<SimpleRotation> {
    let example = "quaternion: [e0, e1, e2, e3]";
    let items = cx.seq(node, "`quaternion`", example)?;
    if items.len() != 4 {
        cx.error(
            Diagnostic::new(node.location, format!("`quaternion` has 4 Euler parameters, found {}", items.len()))
                .with_help("write the scalar part first: `quaternion: [e0, e1, e2, e3]`, e0 = cos(θ/2) and (e1, e2, e3) = sin(θ/2) times the rotation's axis"),
        );
        return None;
    }
    let parts: Vec<Option<Expr>> = (items.iter())
        .map(|i| cx.expr(i, "an Euler parameter"))
        .collect();
    let mut parts: Vec<Expr> = parts.into_iter().collect::<Option<_>>()?;
    let vector: [Expr; 3] = parts.split_off(1).try_into().ok()?;
    let scalar = parts.pop()?;
    Some(SimpleRotation {
        axis: Located::new(Axis::Z, node.location),
        angle: scalar,
        direction: None,
        quaternion: Some(vector),
    })
}

/// Whether a frame in Euler parameters has a coordinate among their expressions (names in
/// `coordinates`): then its unit norm is a constraint on the coordinates.
pub(crate) fn moves_with_coordinates(frame: &Frame, coordinates: &[&str]) -> bool {
    let mut names = Vec::new();
    for r in &frame.rotations {
        if let Some(vector) = &r.quaternion {
            for e in std::iter::once(&r.angle).chain(vector) {
                crate::model::parser::identifiers(e, &mut names);
            }
        }
    }
    names.iter().any(|(n, _)| coordinates.contains(&n.as_str()))
}

/// The generated constraint that keeps a frame's Euler parameters of unit norm,
/// `e0² + e1² + e2² + e3² − 1 = 0`, named `<frame>_unit` and located at the frame's name; `None`
/// for a frame of simple rotations.
pub(crate) fn unit_norm(frame: &Frame) -> Option<(Located<String>, Expr)> {
    let [rotation] = frame.rotations.as_slice() else {
        return None;
    };
    let vector = rotation.quaternion.as_ref()?;
    let at = frame.name.location;
    let binary = |op, lhs: Expr, rhs: Expr| Expr {
        kind: crate::model::ast::ExprKind::Binary {
            op,
            lhs: Box::new(lhs),
            rhs: Box::new(rhs),
            op_location: at,
        },
        location: at,
    };
    let number = |value: f64| Expr {
        kind: crate::model::ast::ExprKind::Number {
            value,
            text: format!("{value}"),
        },
        location: at,
    };
    use crate::model::ast::BinOp;
    let square = |e: &Expr| binary(BinOp::Pow, e.clone(), number(2.0));
    let sum = std::iter::once(&rotation.angle)
        .chain(vector.iter())
        .map(square)
        .reduce(|a, b| binary(BinOp::Add, a, b))?;
    Some((
        Located::new(format!("{}_unit", frame.name.value), at),
        binary(BinOp::Sub, sum, number(1.0)),
    ))
}

/// The components `[a, b, c]` of an oblique axis (`axis: [0, 0.6, 0.8]`): three expressions of
/// the parameters.
fn oblique_axis(cx: &mut Ctx<'_>, node: &YamlNode, items: &[YamlNode]) -> Option<[Expr; 3]> {
    if items.len() != 3 {
        cx.error(
            Diagnostic::new(
                node.location,
                format!(
                    "an oblique `axis` has 3 components (in the parent frame), found {}",
                    items.len()
                ),
            )
            .with_help("write `axis: [0, 0.6, 0.8]`, or `axis: z` for a frame's own axis"),
        );
        return None;
    }
    let parts: Vec<Option<Expr>> = items
        .iter()
        .map(|i| cx.expr(i, "a component of a rotation axis"))
        .collect();
    let parts: Vec<Expr> = parts.into_iter().collect::<Option<_>>()?;
    parts.try_into().ok()
}

/// `frames:`, each as its successive rotations about the newest frame's axes (a frame written
/// `about: parent` was read into that order, which gives the same orientation).
pub(crate) fn write(w: &mut Writer<'_>, frames: &[Frame]) -> Result<(), NotRewritten> {
    if frames.is_empty() {
        return Ok(());
    }
    w.line("frames:");
    for frame in frames {
        let text = frame_text(w, frame)?;
        w.line(format_args!("  {}: {text}", frame.name.value));
    }
    Ok(())
}

/// `{ parent: P, axis: z, angle: … }`, or `axes:` and `angles:` for several rotations.
fn frame_text(w: &mut Writer<'_>, frame: &Frame) -> Result<String, NotRewritten> {
    let place = format!("frame `{}`", frame.name.value);
    if let [
        SimpleRotation {
            angle,
            quaternion: Some(vector),
            ..
        },
    ] = frame.rotations.as_slice()
    {
        let parts = std::iter::once(angle)
            .chain(vector.iter())
            .map(|p| w.expr(p, &place))
            .collect::<Result<Vec<_>, _>>()?;
        return Ok(format!(
            "{{ parent: {}, quaternion: {} }}",
            frame.parent.value,
            list(&parts)
        ));
    }
    let angles = frame
        .rotations
        .iter()
        .map(|r| w.expr(&r.angle, &place))
        .collect::<Result<Vec<_>, _>>()?;
    let axes: String = match frame.rotations.as_slice() {
        [
            SimpleRotation {
                direction: Some(parts),
                ..
            },
        ] => {
            let parts = parts
                .iter()
                .map(|p| w.expr(p, &place))
                .collect::<Result<Vec<_>, _>>()?;
            list(&parts)
        }
        rotations => rotations.iter().map(|r| r.axis.value.letter()).collect(),
    };
    Ok(match angles.as_slice() {
        [angle] => format!(
            "{{ parent: {}, axis: {axes}, angle: {} }}",
            frame.parent.value,
            flow(angle)
        ),
        _ => format!(
            "{{ parent: {}, axes: {axes}, angles: {} }}",
            frame.parent.value,
            list(&angles)
        ),
    })
}

/// The frames' names are distinct and neither the ground's `N` nor `from` (a point's key),
/// and each frame's parent is `N` or a frame defined before it, so that the frames form a
/// tree rooted at the ground.
pub(crate) fn rules(frames: &[Frame], cx: &mut dyn Rules) {
    let mut defined: Vec<&str> = vec![GROUND_FRAME];
    for f in frames {
        let n = f.name.value.as_str();
        if n == GROUND_FRAME || n == "from" {
            let why = if n == "from" {
                "`from` is the key of a point's start"
            } else {
                "`N` is the ground frame"
            };
            cx.error(
                Diagnostic::new(
                    f.name.location,
                    format!("frame name `{n}` is reserved: {why}"),
                )
                .with_help("choose another name"),
            );
            continue;
        }
        let p = f.parent.value.as_str();
        if !defined.contains(&p) {
            let later = frames.iter().any(|g| g.name.value == p);
            let d = if later {
                Diagnostic::new(
                    f.parent.location,
                    format!("frame `{n}` is turned from `{p}`, which is not defined before it"),
                )
                .with_help(
                    "define a frame's parent above it (frames form a tree rooted at the ground frame `N`)",
                )
            } else {
                // Listed as everywhere else: the file's frames, then the ground.
                let mut known = defined[1..].to_vec();
                known.push(GROUND_FRAME);
                cx.unknown_frame(&f.parent, &known)
            };
            cx.error(d);
        }
        if defined.contains(&n) {
            cx.error(
                Diagnostic::new(f.name.location, format!("duplicate frame name `{n}`"))
                    .with_help("rename one"),
            );
        }
        defined.push(n);
    }
}

/// Every rotation angle with its frame's name, in file order.
fn angles(frames: &[Frame]) -> impl Iterator<Item = (&str, &Expr)> {
    frames
        .iter()
        .flat_map(|f| (f.rotations.iter()).map(move |r| (f.name.value.as_str(), &r.angle)))
}

/// The rotation angles are functions of the configuration (no rates); an oblique axis's
/// components are constants.
pub(crate) fn angle_rules(frames: &[Frame], cx: &mut dyn Rules) {
    for (frame, angle) in angles(frames) {
        let what = format!("the rotation of frame `{frame}`");
        cx.expression(angle, Depends::Position, &what);
    }
    for f in frames {
        for part in (f.rotations.iter())
            .filter_map(|r| r.quaternion.as_ref())
            .flatten()
        {
            let what = format!("the Euler parameters of frame `{}`", f.name.value);
            cx.expression(part, Depends::Position, &what);
        }
        for part in f
            .rotations
            .iter()
            .filter_map(|r| r.direction.as_ref())
            .flatten()
        {
            let what = format!("the rotation axis of frame `{}`", f.name.value);
            cx.expression(part, Depends::Constant, &what);
        }
    }
}

/// The rotation angles are pure numbers (rad).
pub(crate) fn units(frames: &[Frame], cx: &mut dyn Units) {
    for f in frames {
        for part in (f.rotations.iter())
            .filter_map(|r| r.quaternion.as_ref())
            .flatten()
        {
            cx.fixed(
                part,
                Dimension::ONE,
                &format!("an Euler parameter of frame `{}`", f.name.value),
                "an Euler parameter",
                "a pure number",
                "Euler parameters are pure numbers, e0 = cos(θ/2) and (e1, e2, e3) = sin(θ/2) times a unit axis",
            );
        }
    }
    for (frame, angle) in angles(frames) {
        cx.fixed(
            angle,
            Dimension::ONE,
            &format!("the rotation angle of frame `{frame}`"),
            "an angle",
            "rad (a pure number)",
            "a rotation angle is an angle coordinate, or a function of the coordinates that gives a pure number",
        );
    }
}

/// The frame's rotations as the kinematics engine takes them: per rotation, the axis (its
/// index 0, 1, 2 for x, y, z, or an oblique axis's unit vector, its components divided by
/// their norm) and the angle lowered (rad).
pub(crate) fn lower(f: &Frame, cx: &mut dyn Lower) -> Vec<(RotationAxis, ExprId)> {
    f.rotations
        .iter()
        .map(|r| {
            if let Some(vector) = &r.quaternion {
                let v = vector.clone().map(|p| cx.expr(&p));
                return (RotationAxis::Quaternion(v), cx.expr(&r.angle));
            }
            let axis = match &r.direction {
                None => RotationAxis::Principal(r.axis.value.index()),
                Some(parts) => {
                    let v = parts.clone().map(|p| cx.expr(&p));
                    let arena = cx.arena();
                    let squares: Vec<ExprId> = v.iter().map(|&c| arena.times(c, c)).collect();
                    let sum = arena.sum(&squares);
                    if arena.is_zero(sum) {
                        cx.error(
                            Diagnostic::new(
                                r.axis.location,
                                format!(
                                    "the rotation axis of frame `{}` is the zero vector",
                                    f.name.value
                                ),
                            )
                            .with_help("give the axis a direction, as in `axis: [0, 0.6, 0.8]`"),
                        );
                    }
                    let arena = cx.arena();
                    let norm = arena.sqrt(sum);
                    RotationAxis::Unit(v.map(|c| arena.divide(c, norm)))
                }
            };
            (axis, cx.expr(&r.angle))
        })
        .collect()
}

/// `omega_<frame>_<axis>`: the name by which expressions read the component of `frame`'s
/// angular velocity in the ground frame along the axis `axis` (`x`, `y` or `z`), rad/s.
pub(crate) fn angular_velocity_name(frame: &str, axis: &str) -> String {
    format!("omega_{frame}_{axis}")
}

/// The frame of `frames` and the axis that `name` reads if it is an
/// [`angular_velocity_name`].
pub(crate) fn angular_velocity_of<'f>(
    frames: &'f [Frame],
    name: &str,
) -> Option<(&'f Frame, Axis)> {
    let rest = name.strip_prefix("omega_")?;
    let (frame, axis) = rest.rsplit_once('_')?;
    let axis = match axis {
        "x" => Axis::X,
        "y" => Axis::Y,
        "z" => Axis::Z,
        _ => return None,
    };
    let frame = frames.iter().find(|f| f.name.value == frame)?;
    Some((frame, axis))
}
