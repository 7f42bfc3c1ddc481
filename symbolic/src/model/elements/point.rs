//! Points (`points:`), the kinematics the other elements read: a position in the ground
//! frame's components, another point plus vectors written in frames (3-D), or the contact
//! point of a knife-edge wheel on level ground (Meijaard et al. 2007, §3).
//!
//! ```yaml
//! points:
//!   P: [l*sin(theta), -l*cos(theta)]          # components, 2 or 3
//!   G: { from: O, B: [0, 0, -l/2] }           # O plus a vector in frame B
//!   C: { wheel: { centre: W, frame: H, axle: y, radius: r } }
//! ```
//!
//! The points are lowered right after the frames, in file order (a point may start from one
//! above it), and every element then reads them through `Lower::point`.

use super::{AXES, Axis, Depends, Lower, Rules, Units, dot};
use crate::expr::ExprId;
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::{Located, Location};
use crate::model::schema::entries::{Entries, get};
use crate::model::schema::walk::{Ctx, Fields, Keyed, Need};
use crate::model::schema::write::{NotRewritten, Writer, flow, list};
use crate::model::units::Dimension;
use crate::model::yaml::{YamlKind, YamlNode};

/// The key of the section.
pub(crate) const KEY: &str = "points";

/// A named point: a position expression in `q` and `t` with 2 or 3 components, or (in 3-D)
/// another point plus vectors written in frames.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Name.
    pub name: Located<String>,
    /// Components `[x, y]` or `[x, y, z]` (m) in the ground frame; empty for a point written
    /// as a point plus vectors (`{ from: O, B: [0, 0, l] }`).
    pub position: Vec<Expr>,
    /// The point plus vectors form: `{ from: O, B: [0, 0, l], N: [x, 0, 0] }`; `None` for a
    /// list of components.
    pub relative: Option<RelativePosition>,
    /// The contact point of a wheel: `{ wheel: { centre, frame, axle, radius } }`.
    pub wheel: Option<WheelContact>,
    /// Where the position list or map starts.
    pub location: Location,
}

impl Point {
    /// Number of components: 3 for a point written as a point plus vectors in frames.
    pub fn dimension(&self) -> usize {
        if self.relative.is_some() || self.wheel.is_some() {
            3
        } else {
            self.position.len()
        }
    }
}

/// A point written as another point plus vectors in frames:
/// `r_P = r_from + Σ_F [v_F]_F` (each vector's components along the axes of frame F).
#[derive(Debug, Clone, PartialEq)]
pub struct RelativePosition {
    /// The point it is measured from; `None`: the origin.
    pub from: Option<Located<String>>,
    /// Vectors by frame (`N` is the ground), each three components (m), in file order.
    pub vectors: Vec<(Located<String>, Vec<Expr>)>,
}

/// A wheel's contact point, `points: { C: { wheel: { centre: F, frame: H, axle: y, radius: r } } }`:
/// the point of the circle of radius `radius` about `centre`, in the plane normal to the axis
/// `axle` of `frame`, that is lowest (farthest along the ground frame's `−z`) — where a
/// knife-edge wheel touches a horizontal ground (Meijaard et al. 2007, §3).
#[derive(Debug, Clone, PartialEq)]
pub struct WheelContact {
    /// The wheel's centre (a point).
    pub centre: Located<String>,
    /// A frame in which the axle is fixed.
    pub frame: Located<String>,
    /// The axle's axis in that frame.
    pub axle: Located<Axis>,
    /// The radius (m), a constant expression.
    pub radius: Expr,
}
/// The keys of a wheel's contact point.
const WHEEL_FIELDS: Fields = Fields {
    kind: "wheel contact",
    keys: &[
        ("centre", Need::Required),
        ("frame", Need::Required),
        ("axle", Need::Required),
        ("radius", Need::Required),
    ],
    example: "{ centre: F, frame: H, axle: y, radius: r }",
};

/// `points:` — `name: [x, y]` or `name: [x, y, z]`.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Vec<Point> {
    let spec = Keyed {
        what: "`points`",
        example: "points: { O: [0, 0], P: [l*cos(q), l*sin(q)] }",
        names: Some("point"),
        drop: true,
    };
    cx.keyed(node, spec, |cx, k, v| {
        if let YamlKind::Map(entries) = &v.kind {
            if let [(key, wheel)] = entries.as_slice()
                && key.value == "wheel"
            {
                let what = Located::new(format!("{}'s wheel", k.value), key.location);
                let wheel = read_wheel(cx, &what, wheel)?;
                return Some(Point {
                    name: k.clone(),
                    position: Vec::new(),
                    relative: None,
                    wheel: Some(wheel),
                    location: v.location,
                });
            }
            let relative = read_relative(cx, k, entries, v.location)?;
            return Some(Point {
                name: k.clone(),
                position: Vec::new(),
                relative: Some(relative),
                wheel: None,
                location: v.location,
            });
        }
        let position = cx.vector(
            v,
            &format!("point `{}`", k.value),
            "P: [l*cos(q), l*sin(q)]",
        )?;
        Some(Point {
            name: k.clone(),
            position,
            relative: None,
            wheel: None,
            location: v.location,
        })
    })
}

/// A point written as a point plus vectors in frames: `{ from: O, B: [0, 0, l] }`.
fn read_relative(
    cx: &mut Ctx<'_>,
    k: &Located<String>,
    entries: &Entries,
    at: Location,
) -> Option<RelativePosition> {
    let what = format!("point `{}`", k.value);
    let example = format!("{}: {{ from: O, B: [0, 0, l] }}", k.value);
    let mut from = None;
    let mut vectors = Vec::new();
    let mut complete = true;
    for (key, value) in entries {
        if key.value == "from" {
            match cx.name(value, "`from`") {
                Some(p) => from = Some(p),
                None => complete = false,
            }
            continue;
        }
        if !cx.key_name(key, "a frame") {
            complete = false;
            continue;
        }
        let in_frame = format!("the vector of {what} in frame `{}`", key.value);
        match cx.vector(value, &in_frame, "B: [0, 0, l]") {
            Some(v) if v.len() == 3 => vectors.push((key.clone(), v)),
            Some(v) => {
                cx.error(
                    Diagnostic::new(
                        value.location,
                        format!("{in_frame} has {} components; a vector in a frame has 3", v.len()),
                    )
                    .with_help("write its components along the frame's x, y and z axes, as in `B: [0, 0, l]`"),
                );
                complete = false;
            }
            None => complete = false,
        }
    }
    if from.is_none() && vectors.is_empty() && complete {
        cx.error(
            Diagnostic::new(
                at,
                format!("{what} is a map with neither `from` nor a vector"),
            )
            .with_help(format!(
                "a point is a list `[x, y, z]` or a point plus vectors in frames: `{example}`"
            )),
        );
        return None;
    }
    complete.then_some(RelativePosition { from, vectors })
}

/// A wheel's contact point: `{ centre, frame, axle, radius }`.
pub(crate) fn read_wheel(
    cx: &mut Ctx<'_>,
    k: &Located<String>,
    v: &YamlNode,
) -> Option<WheelContact> {
    let f = cx.fields(k, v, &WHEEL_FIELDS)?;
    let centre = get(f, "centre").and_then(|n| cx.name(n, "`centre`"));
    let frame = get(f, "frame").and_then(|n| cx.name(n, "`frame`"));
    let axle = get(f, "axle").and_then(|n| cx.axes(n, true).and_then(|mut a| a.pop()));
    let radius = get(f, "radius").and_then(|n| cx.expr(n, "a wheel radius"));
    Some(WheelContact {
        centre: centre?,
        frame: frame?,
        axle: axle?,
        radius: radius?,
    })
}

/// `points:`.
pub(crate) fn write(w: &mut Writer<'_>, points: &[Point]) -> Result<(), NotRewritten> {
    if points.is_empty() {
        return Ok(());
    }
    w.line("points:");
    for p in points {
        let text = point_text(w, p)?;
        w.line(format_args!("  {}: {text}", p.name.value));
    }
    Ok(())
}

/// A point's value: its components, the point plus vectors in frames, or a wheel contact.
fn point_text(w: &mut Writer<'_>, p: &Point) -> Result<String, NotRewritten> {
    let place = format!("point `{}`", p.name.value);
    if let Some(wheel) = &p.wheel {
        return Ok(format!("{{ wheel: {} }}", wheel_text(w, wheel, &place)?));
    }
    if let Some(RelativePosition { from, vectors }) = &p.relative {
        let mut parts = Vec::new();
        if let Some(from) = from {
            parts.push(format!("from: {}", from.value));
        }
        for (frame, vector) in vectors {
            let components = w.exprs(vector, &place)?;
            parts.push(format!("{}: {}", frame.value, list(&components)));
        }
        return Ok(format!("{{ {} }}", parts.join(", ")));
    }
    let parts = w.exprs(&p.position, &place)?;
    Ok(list(&parts))
}

/// `{ centre: G, frame: R, axle: y, radius: r }`.
pub(crate) fn wheel_text(
    w: &mut Writer<'_>,
    wheel: &WheelContact,
    place: &str,
) -> Result<String, NotRewritten> {
    let radius = w.expr(&wheel.radius, place)?;
    Ok(format!(
        "{{ centre: {}, frame: {}, axle: {}, radius: {} }}",
        wheel.centre.value,
        wheel.frame.value,
        wheel.axle.value.letter(),
        flow(&radius)
    ))
}

/// Each wheel's centre and each point a point is measured from is defined before it; the
/// frames of wheels and of vectors are the model's; a wheel's radius is constant.
pub(crate) fn origin_rules(points: &[Point], cx: &mut dyn Rules) {
    for (i, p) in points.iter().enumerate() {
        if let Some(wheel) = &p.wheel {
            let earlier = points[..i]
                .iter()
                .any(|q| q.name.value == wheel.centre.value);
            if !earlier
                && points[i..]
                    .iter()
                    .any(|q| q.name.value == wheel.centre.value)
            {
                cx.error(
                    Diagnostic::new(wheel.centre.location, format!("the wheel of point `{}` is centred at `{}`, which is not defined before it", p.name.value, wheel.centre.value))
                        .with_help("define the wheel's centre above its contact point"),
                );
            } else {
                cx.point(&wheel.centre);
            }
            cx.frame(&wheel.frame);
            cx.expression(
                &wheel.radius,
                Depends::Constant,
                &format!("the wheel radius of point `{}`", p.name.value),
            );
            continue;
        }
        let Some(relative) = &p.relative else {
            continue;
        };
        if let Some(from) = &relative.from {
            let earlier = points[..i].iter().any(|q| q.name.value == from.value);
            let later = points[i..].iter().any(|q| q.name.value == from.value);
            if later && !earlier {
                cx.error(
                    Diagnostic::new(
                        from.location,
                        format!(
                            "point `{}` is measured from `{}`, which is not defined before it",
                            p.name.value, from.value
                        ),
                    )
                    .with_help("define the point it starts from above it"),
                );
            } else {
                cx.point(from);
            }
        }
        for (frame, _) in &relative.vectors {
            cx.frame(frame);
        }
    }
}

/// The components (and the vectors' components) are functions of the configuration.
pub(crate) fn expression_rules(points: &[Point], cx: &mut dyn Rules) {
    for p in points {
        let relative = p.relative.iter().flat_map(|r| &r.vectors);
        for c in p.position.iter().chain(relative.flat_map(|(_, v)| v)) {
            cx.expression(
                c,
                Depends::Position,
                &format!("the position of point `{}`", p.name.value),
            );
        }
    }
}

/// Every point has as many components as the first (2 or 3): that number, or `None` when
/// there are no points.
pub(crate) fn dimension_rules(points: &[Point], cx: &mut dyn Rules) -> Option<usize> {
    let first = points.first()?;
    let dim = first.dimension();
    for p in &points[1..] {
        if p.dimension() != dim {
            cx.error(
                Diagnostic::new(
                    p.location,
                    format!(
                        "point `{}` has {} components but point `{}` has {dim}",
                        p.name.value,
                        p.dimension(),
                        first.name.value
                    ),
                )
                .with_help("a model is either planar (`[x, y]`) or spatial (`[x, y, z]`)"),
            );
        }
    }
    Some(dim)
}

/// Positions in m, and wheel radii.
pub(crate) fn units(points: &[Point], cx: &mut dyn Units) {
    for p in points {
        let relative = p.relative.iter().flat_map(|r| &r.vectors);
        let in_frames = relative.flat_map(|(_, v)| AXES.iter().zip(v));
        for (axis, c) in AXES.iter().zip(&p.position).chain(in_frames) {
            cx.fixed(
                c,
                Dimension::METRE,
                &format!("the {axis} component of point `{}`", p.name.value),
                "a position",
                "m",
                "positions are lengths: check the units of the parameters in it",
            );
        }
    }
    for p in points {
        if let Some(wheel) = &p.wheel {
            cx.fixed(
                &wheel.radius,
                Dimension::METRE,
                &format!("the wheel radius of point `{}`", p.name.value),
                "a length",
                "m",
                "a wheel's radius is a length",
            );
        }
    }
}

/// The points' positions in the ground frame's components, by name, in file order: a list of
/// components as written, a point plus vectors in frames carried into the ground frame's
/// components ([`Lower::express`]), or a wheel's contact point ([`wheel_contact`]). A name
/// or frame that is not known is reported (the rules reject it first) and taken as the origin
/// or left out.
pub(crate) fn lower(points: &[Point], cx: &mut dyn Lower) -> Vec<(String, Vec<ExprId>)> {
    let mut lowered: Vec<(String, Vec<ExprId>)> = Vec::new();
    let index =
        |lowered: &[(String, Vec<ExprId>)], name: &str| lowered.iter().position(|(n, _)| n == name);
    for p in points {
        if let Some(wheel) = &p.wheel {
            let centre = index(&lowered, &wheel.centre.value).map(|i| lowered[i].1.clone());
            let r = wheel_contact(wheel, centre.as_deref(), cx);
            lowered.push((p.name.value.clone(), r));
            continue;
        }
        let Some(relative) = &p.relative else {
            let r = p.position.iter().map(|c| cx.expr(c)).collect();
            lowered.push((p.name.value.clone(), r));
            continue;
        };
        let zero = cx.arena().int(0);
        let mut r: Vec<ExprId> = match &relative.from {
            Some(from) => match index(&lowered, &from.value) {
                Some(i) => lowered[i].1.clone(),
                None => {
                    cx.error(Diagnostic::new(
                        from.location,
                        format!("unknown point `{}`", from.value),
                    ));
                    vec![zero; 3]
                }
            },
            None => vec![zero; 3],
        };
        for (frame, v) in &relative.vectors {
            let Some(f) = cx.frame_index(&frame.value) else {
                cx.error(Diagnostic::new(
                    frame.location,
                    format!("unknown frame `{}`", frame.value),
                ));
                continue;
            };
            let v = [&v[0], &v[1], &v[2]].map(|c| cx.expr(c));
            let v = cx.express(v, f, 0);
            let arena = cx.arena();
            for (x, c) in r.iter_mut().zip(v) {
                *x = arena.plus(*x, c);
            }
        }
        lowered.push((p.name.value.clone(), r));
    }
    lowered
}

/// A wheel's contact point (its centre at `centre`, ground components): the centre less the
/// radius along the unit vector of the wheel's plane (normal to the axle `a`) nearest the
/// ground frame's `z`, `r_C = r_centre − r (n − (n·a) a)/|n − (n·a) a|`, `n = N.z`, computed
/// in the wheel frame's components (where `a` is a unit axis and the projection drops one
/// component) and carried into the ground frame's. The origin (reported) if the centre or
/// the frame is unknown, or if the axle is the ground's z in every configuration.
fn wheel_contact(
    wheel: &WheelContact,
    centre: Option<&[ExprId]>,
    cx: &mut dyn Lower,
) -> Vec<ExprId> {
    let (Some(centre), Some(frame)) = (centre, cx.frame_index(&wheel.frame.value)) else {
        cx.error(Diagnostic::new(
            wheel.centre.location,
            "a wheel contact names an unknown point or frame",
        ));
        return vec![cx.arena().int(0); 3];
    };
    let arena = cx.arena();
    let (zero, one) = (arena.int(0), arena.int(1));
    let mut n = cx.express([zero, zero, one], 0, frame);
    n[wheel.axle.value.index()] = zero;
    let arena = cx.arena();
    let n2 = dot(arena, &n, &n);
    // The wheel's plane has no direction nearest the ground's z when its axle is that z in
    // every configuration (a disc lying flat): `r/|n|` times components that are all 0 would
    // put the contact point at the centre, silently.
    if arena.is_zero(n2) {
        cx.error(
            Diagnostic::new(
                wheel.axle.location,
                format!(
                    "the wheel centred at `{}` has its axle `{}` of frame `{}` along the ground's z in every configuration: a wheel lying flat has no lowest point of its rim",
                    wheel.centre.value,
                    wheel.axle.value.letter(),
                    wheel.frame.value
                ),
            )
            .with_help("a wheel contact needs an axle that is not vertical (the axle `y` of a frame that leans and steers); for a disc sliding flat, write its contact point directly"),
        );
        return vec![zero; 3];
    }
    let length = arena.sqrt(n2);
    let radius = cx.expr(&wheel.radius);
    let arena = cx.arena();
    let scale = arena.divide(radius, length);
    let down = n.map(|c| {
        let t = arena.times(scale, c);
        arena.neg(t)
    });
    let down = cx.express(down, frame, 0);
    let arena = cx.arena();
    centre
        .iter()
        .zip(down)
        .map(|(c, d)| arena.plus(*c, d))
        .collect()
}
