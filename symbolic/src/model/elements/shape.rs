//! The shapes the 3-D view draws the bodies as (`draw: shapes:`): a box, a cylinder, a disc or
//! a sphere, centred at the body's centre of mass and fixed in its frame. A 3-D body without
//! one is drawn as the uniform box of its mass and inertia (`eomgen::animation`).
//!
//! ```yaml
//! draw:
//!   shapes:
//!     frame: { box: [0.4, 0.05, 0.3] }         # sides along the frame's x, y, z (m)
//!     rotor: { cylinder: [r, h], axis: z }     # radius and length along the axis (m)
//!     wheel: { disc: r, axis: y }              # a thin disc normal to the axis
//!     ball: { sphere: r }
//! ```

use super::{Axis, BodyLookup, BodyShape, Depends, Rules, Units};
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::Located;
use crate::model::schema::entries::get;
use crate::model::schema::walk::{Ctx, Keyed};
use crate::model::schema::write::{NotRewritten, Writer, flow, list};
use crate::model::units::Dimension;
use crate::model::yaml::YamlNode;
use eomgen_description::Shape;

/// An example of the section, in messages.
const EXAMPLE: &str = "shapes: { wheel: { disc: r, axis: y }, frame: { box: [a, b, c] } }";

/// The kinds of shape, as the file writes them.
const KINDS: [&str; 4] = ["box", "cylinder", "disc", "sphere"];

/// A shape's size, by kind.
#[derive(Debug, Clone, PartialEq)]
pub enum ShapeSize {
    /// A box's sides along the frame's x, y and z (m).
    Box([Expr; 3]),
    /// A cylinder's radius and length (m).
    Cylinder(Expr, Expr),
    /// A thin disc's radius (m).
    Disc(Expr),
    /// A sphere's radius (m).
    Sphere(Expr),
}

/// One entry of `draw: shapes:`.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnShape {
    /// The body (a 3-D rigid body of the model).
    pub body: Located<String>,
    /// Its kind and size.
    pub size: ShapeSize,
    /// The axis of a cylinder or a disc (`z` when not given); `None` for a box or a sphere.
    pub axis: Option<Located<Axis>>,
}

impl DrawnShape {
    /// The expressions of its size, with what each is.
    fn sizes(&self) -> Vec<(&'static str, &Expr)> {
        match &self.size {
            ShapeSize::Box(sides) => (["x side", "y side", "z side"].into_iter())
                .zip(sides)
                .collect(),
            ShapeSize::Cylinder(r, l) => vec![("radius", r), ("length", l)],
            ShapeSize::Disc(r) | ShapeSize::Sphere(r) => vec![("radius", r)],
        }
    }

    /// The shape as the model's description keeps it ([`eomgen_description::Shape`]).
    pub fn describe(&self) -> Shape {
        let text = |e: &Expr| e.to_string().into();
        let axis = self.axis.as_ref().map_or(2, |a| a.value.index());
        match &self.size {
            ShapeSize::Box(sides) => Shape::Box {
                sides: sides.each_ref().map(text),
            },
            ShapeSize::Cylinder(r, l) => Shape::Cylinder {
                radius: text(r),
                length: text(l),
                axis,
            },
            ShapeSize::Disc(r) => Shape::Disc {
                radius: text(r),
                axis,
            },
            ShapeSize::Sphere(r) => Shape::Sphere { radius: text(r) },
        }
    }
}

/// `draw: shapes:` — `body: { box: [a, b, c] }`, `{ cylinder: [r, l], axis: z }`,
/// `{ disc: r, axis: z }` or `{ sphere: r }`, in file order.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Vec<DrawnShape> {
    let spec = Keyed {
        what: "`shapes`",
        example: EXAMPLE,
        names: Some("body"),
        drop: false,
    };
    cx.keyed(node, spec, read_shape)
}

/// One shape: exactly one of the kinds, and an axis for a cylinder or a disc.
fn read_shape(cx: &mut Ctx<'_>, k: &Located<String>, v: &YamlNode) -> Option<DrawnShape> {
    let what = format!("the shape of `{}`", k.value);
    let example = format!("{}: {{ disc: r, axis: y }}", k.value);
    let f = cx.map(v, &what, &example)?;
    let mut allowed = KINDS.to_vec();
    allowed.push("axis");
    cx.unknown_keys(f, &what, &allowed, &allowed);
    let kinds: Vec<&str> = KINDS.into_iter().filter(|n| get(f, n).is_some()).collect();
    let [kind] = kinds[..] else {
        cx.error(
            Diagnostic::new(
                k.location,
                format!(
                    "{what} needs exactly one of box, cylinder, disc or sphere, found {}",
                    kinds.len()
                ),
            )
            .with_help(format!("write it like `{example}`")),
        );
        return None;
    };
    let node = get(f, kind)?;
    let size = match kind {
        "box" => ShapeSize::Box(fixed_list(cx, node, &what, "box: [a, b, c]")?),
        "cylinder" => {
            let [r, l] = fixed_list(cx, node, &what, "cylinder: [r, length], axis: z")?;
            ShapeSize::Cylinder(r, l)
        }
        "disc" => ShapeSize::Disc(cx.expr(node, &format!("the radius of {what}"))?),
        _ => ShapeSize::Sphere(cx.expr(node, &format!("the radius of {what}"))?),
    };
    let axis = match get(f, "axis") {
        Some(n) if matches!(size, ShapeSize::Cylinder(..) | ShapeSize::Disc(_)) => {
            let options = [("x", Axis::X), ("y", Axis::Y), ("z", Axis::Z)];
            let axis = cx.choice(n, &format!("the axis of {what}"), &options)?;
            Some(Located::new(axis, n.location))
        }
        Some(n) => {
            cx.error(
                Diagnostic::new(n.location, format!("{what}: a {kind} has no axis"))
                    .with_help("only a cylinder or a disc takes `axis: x`, `y` or `z`"),
            );
            return None;
        }
        None => None,
    };
    Some(DrawnShape {
        body: k.clone(),
        size,
        axis,
    })
}

/// A list of exactly `K` expressions (`example` says which), reported otherwise.
fn fixed_list<const K: usize>(
    cx: &mut Ctx<'_>,
    node: &YamlNode,
    what: &str,
    example: &str,
) -> Option<[Expr; K]> {
    let items = cx.expr_list(node, what, example)?;
    let found = items.len();
    <[Expr; K]>::try_from(items).ok().or_else(|| {
        cx.error(
            Diagnostic::new(
                node.location,
                format!("{what} needs {K} values, found {found}"),
            )
            .with_help(format!("write it like `{example}`")),
        );
        None
    })
}

/// Each shape names a 3-D rigid body, once, and its sizes are positive constants.
pub(crate) fn rules(shapes: &[DrawnShape], cx: &mut dyn Rules) {
    for (i, s) in shapes.iter().enumerate() {
        let name = &s.body.value;
        match cx.body(name) {
            BodyLookup::Found(BodyShape::Spatial) | BodyLookup::Excused => {}
            BodyLookup::Found(_) => cx.error(
                Diagnostic::new(s.body.location, format!("`{name}` in `draw: shapes:` is not a 3-D rigid body"))
                    .with_help("shapes are drawn for bodies with a `frame:` and an inertia tensor; the 3-D view marks a particle's or a planar body's centre with a dot"),
            ),
            BodyLookup::Unknown(closest) => {
                let d = Diagnostic::new(s.body.location, format!("`draw: shapes:` names an unknown body `{name}`"));
                cx.error(match closest {
                    Some(c) => d.with_help(format!("did you mean `{c}`?")),
                    None => d.with_help("a shape is keyed by the name of a body under `bodies:`"),
                });
            }
        }
        if shapes[..i].iter().any(|o| o.body.value == *name) {
            cx.error(
                Diagnostic::new(
                    s.body.location,
                    format!("`{name}` has two shapes in `draw: shapes:`"),
                )
                .with_help("give each body one shape"),
            );
        }
        for (what, e) in s.sizes() {
            let what = format!("the {what} of the shape of `{name}`");
            cx.expression(e, Depends::Constant, &what);
            if let Some(v) = cx.value(e)
                && !(v.is_finite() && v > 0.0)
            {
                cx.error(
                    Diagnostic::new(
                        e.location,
                        format!("{what} is {v}, not a positive length (m)"),
                    )
                    .with_help("sizes of drawn shapes are positive lengths"),
                );
            }
        }
    }
}

/// Under `units: SI`, every size of a shape is a length (m).
pub(crate) fn units(shapes: &[DrawnShape], cx: &mut dyn Units) {
    for s in shapes {
        for (what, e) in s.sizes() {
            cx.fixed(
                e,
                Dimension::METRE,
                &format!("the {what} of the shape of `{}`", s.body.value),
                "a length",
                "m",
                "a drawn shape's sizes are lengths",
            );
        }
    }
}

/// `shapes: { body: { … }, … }`, as `draw:` writes it; `None` when there is none.
pub(crate) fn write(
    w: &mut Writer<'_>,
    shapes: &[DrawnShape],
) -> Result<Option<String>, NotRewritten> {
    if shapes.is_empty() {
        return Ok(None);
    }
    let mut parts = Vec::with_capacity(shapes.len());
    for s in shapes {
        let place = format!("the shape of `{}`", s.body.value);
        let size = match &s.size {
            ShapeSize::Box(sides) => format!("box: {}", list(&w.exprs(sides, &place)?)),
            ShapeSize::Cylinder(r, l) => {
                format!(
                    "cylinder: {}",
                    list(&w.exprs(&[r.clone(), l.clone()], &place)?)
                )
            }
            ShapeSize::Disc(r) => format!("disc: {}", flow(&w.expr(r, &place)?)),
            ShapeSize::Sphere(r) => format!("sphere: {}", flow(&w.expr(r, &place)?)),
        };
        let axis = s
            .axis
            .as_ref()
            .map_or(String::new(), |a| format!(", axis: {}", a.value.letter()));
        parts.push(format!("{}: {{ {size}{axis} }}", s.body.value));
    }
    Ok(Some(format!("shapes: {{ {} }}", parts.join(", "))))
}
