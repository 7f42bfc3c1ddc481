//! Reading a contact's gap: written (`gap:`), or a point (or a disc) and the surface it
//! stays on (`above:`, `inside:`, `outside:`).

use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::Located;
use crate::model::schema::entries::get;
use crate::model::schema::walk::{Ctx, Fields, Need};
use crate::model::yaml::YamlNode;

/// How a contact's gap is written.
#[derive(Debug, Clone, PartialEq)]
pub enum Gap {
    /// `gap: g`, any expression of the coordinates and `t`.
    Written(Expr),
    /// `point: P, above: { normal: n, through: O }`: `g = n̂·(P − O)`, `n̂ = n/|n|`; `O` is
    /// the origin when left out. With `disc: { centre: P, radius: R, angle: θ }` instead of
    /// `point:`, a disc about `P` on the line: `g = n̂·(P − O) − R`.
    Above {
        /// The point (a disc's centre).
        point: Located<String>,
        /// The normal `n`, pointing to the open side (2 or 3 components).
        normal: Located<Vec<Expr>>,
        /// A point `O` of the line or plane.
        through: Option<Located<Vec<Expr>>>,
        /// The disc about `point`, if the contact is a disc's.
        disc: Option<Disc>,
    },
    /// `point: P, inside: { centre: C, radius: R }` (`g = R − |P − C|`) or `outside:`
    /// (`g = |P − C| − R`).
    Circle {
        /// The point.
        point: Located<String>,
        /// Whether the point stays inside the circle (or sphere).
        inside: bool,
        /// The centre `C`.
        centre: Located<Vec<Expr>>,
        /// The radius `R` (m).
        radius: Expr,
    },
}

/// A disc touching a line (`disc: { centre: P, radius: R, angle: θ }`), in the plane: a
/// wheel or a cylinder rolling, sliding or flying (HW36, lecture 17). Its gap is the centre's
/// distance from the line less `R`, and it slips as its own material point in contact moves,
/// `v_t = t̂ · Ṗ − R θ̇` (`t̂` the normal turned a quarter-turn counter-clockwise, `θ` the
/// disc's rotation counter-clockwise): rolling is sticking.
#[derive(Debug, Clone, PartialEq)]
pub struct Disc {
    /// The radius `R` (m), constant.
    pub radius: Expr,
    /// The disc's rotation `θ(q)` (rad, counter-clockwise), as its body's `angle:`.
    pub angle: Expr,
}

/// The keys of `above:`.
const ABOVE: Fields = Fields {
    kind: "the line or plane",
    keys: &[("normal", Need::Required), ("through", Need::Optional)],
    example: "{ normal: [0, 1], through: [0, 0] }",
};

/// The keys of `disc:`.
const DISC: Fields = Fields {
    kind: "the disc",
    keys: &[
        ("centre", Need::Required),
        ("radius", Need::Required),
        ("angle", Need::Required),
    ],
    example: "{ centre: C, radius: R, angle: theta }",
};

/// The keys of `inside:` and `outside:`.
const CIRCLE: Fields = Fields {
    kind: "the circle or sphere",
    keys: &[("centre", Need::Required), ("radius", Need::Required)],
    example: "{ centre: [0, 0], radius: R }",
};

/// The surfaces a point may be kept to, as keys.
const SURFACES: [&str; 3] = ["above", "inside", "outside"];

/// The gap of the contact `k` whose keys are `f`: `gap:`, or `point:` with one surface.
pub(super) fn read_gap(
    cx: &mut Ctx<'_>,
    k: &Located<String>,
    f: &crate::model::schema::entries::Entries,
    what: &str,
) -> Option<Gap> {
    let surfaces: Vec<&(Located<String>, YamlNode)> = f
        .iter()
        .filter(|(key, _)| SURFACES.contains(&key.value.as_str()))
        .collect();
    let written = f.iter().find(|(key, _)| key.value == "gap");
    let points: Vec<&(Located<String>, YamlNode)> = f
        .iter()
        .filter(|(key, _)| key.value == "point" || key.value == "disc")
        .collect();
    let shape_help = "write the gap itself (`gap: y`), or a point and where it stays: `point: P, above: { normal: [0, 1] }`, `inside:` or `outside: { centre: [0, 0], radius: R }`, or a disc on a line: `disc: { centre: C, radius: R, angle: theta }, above: { normal: [0, 1] }`";
    if let [_, (second, _), ..] = points.as_slice() {
        cx.error(
            Diagnostic::new(
                second.location,
                format!("{what} has both `point` and `disc`"),
            )
            .with_help(shape_help),
        );
        return None;
    }
    let point = points.first().copied();
    match (written, point, surfaces.as_slice()) {
        (Some((_, g)), None, []) => cx.expr(g, "a gap").map(Gap::Written),
        (None, Some((key, p)), [(surface, value)]) if key.value == "disc" => {
            read_disc_gap(cx, what, (key, p), (surface, value))
        }
        (None, Some((_, p)), [(surface, value)]) => {
            let point = cx.name(p, "the point of a contact");
            let gap = match surface.value.as_str() {
                "above" => read_above(cx, surface, value, point.clone()),
                side => read_circle(cx, surface, value, point.clone(), side == "inside"),
            };
            point.and(gap)
        }
        (Some((g, _)), _, _) if point.is_some() || !surfaces.is_empty() => {
            cx.error(
                Diagnostic::new(g.location, format!("{what} has both `gap` and a point"))
                    .with_help(shape_help),
            );
            None
        }
        (None, Some((p, _)), []) => {
            cx.error(
                Diagnostic::new(
                    p.location,
                    format!("{what} names a point but not where it stays"),
                )
                .with_help(shape_help),
            );
            None
        }
        (None, None, [(s, _), ..]) | (None, Some(_), [_, (s, _), ..]) => {
            let message = if point.is_none() {
                format!("{what} has `{}` but no `point`", s.value)
            } else {
                format!("{what} has more than one of `above`, `inside` and `outside`")
            };
            cx.error(Diagnostic::new(s.location, message).with_help(shape_help));
            None
        }
        _ => {
            cx.error(
                Diagnostic::new(k.location, format!("{what} has no gap")).with_help(shape_help),
            );
            None
        }
    }
}

/// The gap of a disc `disc: { … }` (the key and its value) rolling on the line of its
/// surface `above: { … }`; `None` (with the mistake reported) for a circle.
fn read_disc_gap(
    cx: &mut Ctx<'_>,
    what: &str,
    (key, p): (&Located<String>, &YamlNode),
    (surface, value): (&Located<String>, &YamlNode),
) -> Option<Gap> {
    if surface.value != "above" {
        cx.error(
            Diagnostic::new(
                surface.location,
                format!(
                    "{what} is a disc `{}` a circle, but a disc rolls on a line only",
                    surface.value
                ),
            )
            .with_help("write the line it rolls on: `above: { normal: [0, 1] }`"),
        );
        return None;
    }
    let (centre, disc) = read_disc(cx, key, p)?;
    match read_above(cx, surface, value, Some(centre))? {
        Gap::Above {
            point,
            normal,
            through,
            ..
        } => Some(Gap::Above {
            point,
            normal,
            through,
            disc: Some(disc),
        }),
        other => Some(other),
    }
}

/// A located list of 2 or 3 expressions.
fn located_vector(
    cx: &mut Ctx<'_>,
    node: &YamlNode,
    what: &str,
    example: &str,
) -> Option<Located<Vec<Expr>>> {
    cx.vector(node, what, example)
        .map(|v| Located::new(v, node.location))
}

/// `above: { normal, through }` of `point`.
fn read_above(
    cx: &mut Ctx<'_>,
    key: &Located<String>,
    node: &YamlNode,
    point: Option<Located<String>>,
) -> Option<Gap> {
    let f = cx.fields(key, node, &ABOVE)?;
    let normal = get(f, "normal").and_then(|n| located_vector(cx, n, "a normal", "[0, 1]"));
    let through = match get(f, "through") {
        Some(n) => located_vector(cx, n, "a point of the line or plane", "[0, 0]").map(Some),
        None => Some(None),
    };
    Some(Gap::Above {
        point: point?,
        normal: normal?,
        through: through?,
        disc: None,
    })
}

/// `disc: { centre, radius, angle }`: the centre's point and the disc.
fn read_disc(
    cx: &mut Ctx<'_>,
    key: &Located<String>,
    node: &YamlNode,
) -> Option<(Located<String>, Disc)> {
    let f = cx.fields(key, node, &DISC)?;
    let centre = get(f, "centre").and_then(|n| cx.name(n, "the centre of a disc"));
    let radius = get(f, "radius").and_then(|n| cx.expr(n, "a radius"));
    let angle = get(f, "angle").and_then(|n| cx.expr(n, "an angle"));
    Some((
        centre?,
        Disc {
            radius: radius?,
            angle: angle?,
        },
    ))
}

/// `inside:` or `outside: { centre, radius }` of `point`.
fn read_circle(
    cx: &mut Ctx<'_>,
    key: &Located<String>,
    node: &YamlNode,
    point: Option<Located<String>>,
    inside: bool,
) -> Option<Gap> {
    let f = cx.fields(key, node, &CIRCLE)?;
    let centre = get(f, "centre").and_then(|n| located_vector(cx, n, "a centre", "[0, 0]"));
    let radius = get(f, "radius").and_then(|n| cx.expr(n, "a radius"));
    Some(Gap::Circle {
        point: point?,
        inside,
        centre: centre?,
        radius: radius?,
    })
}
