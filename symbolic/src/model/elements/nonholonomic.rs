//! Non-holonomic constraints (`nonholonomic:`), lectures 15–16 (the Chaplygin sleigh):
//! `A(q, t) q̇ + b(q, t) = 0`, written as an expression or as a body rolling without slip.
//!
//! ```yaml
//! nonholonomic:
//!   no_side_slip: -sin(theta)*x_dot + cos(theta)*y_dot
//!   roll: { body: wheel, point: C, along: [x, y], in: N }   # rows roll_x, roll_y
//! ```
//!
//! Each row joins the holonomic constraints' differentiated rows in the constraint Jacobian
//! `J` and `γ`; the mechanics checks that a written row is linear in the rates. The
//! expressions come first, then each rolling contact's rows, in file order. Their units are
//! checked with the holonomic constraints' by the unit check (unit_check/sections.rs), which
//! gives each multiplier its unit from its row's.

use super::{
    Axis, BodyLookup, BodyShape, Depends, Expressions, Lower, Rules, axes_rules, difference, dot,
    expression_rows, in_frame, read_expressions_or, read_in,
};
use crate::expr::ExprId;
use crate::mechanics::frames::cross;
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::Located;
use crate::model::schema::entries::get;
use crate::model::schema::walk::{Ctx, Fields, Need};
use crate::model::schema::write::{NotRewritten, Writer, flow};
use crate::model::yaml::YamlNode;

/// The key of the section.
pub(crate) const KEY: &str = "nonholonomic";

/// Rolling without slip, `nonholonomic: { roll: { body: wheel, point: C, along: [x, y], in: N } }`:
/// the velocity of the material point of `body` that is at `point`,
/// `v_G + ω × (r_C − r_G)`, has no component along the axes `along` of frame `in` (the
/// ground frame if not given). One constraint per axis, named `roll_x`, `roll_y`, … after the
/// entry and the axis, after the constraints written as expressions.
#[derive(Debug, Clone, PartialEq)]
pub struct RollingContact {
    /// The entry's name (the constraints are `<name>_<axis>`).
    pub name: Located<String>,
    /// The rigid body that rolls (planar or 3-D).
    pub body: Located<String>,
    /// The point of contact (a point of `points:`).
    pub point: Located<String>,
    /// The axes along which the contact point's velocity vanishes.
    pub along: Vec<Located<Axis>>,
    /// The frame of the axes; `None`: the ground frame.
    pub frame: Option<Located<String>>,
}

impl RollingContact {
    /// The names of its constraints, `<name>_<axis>`, located at the entry.
    pub fn constraint_names(&self) -> Vec<Located<String>> {
        self.along
            .iter()
            .map(|a| {
                Located::new(
                    format!("{}_{}", self.name.value, a.value.letter()),
                    self.name.location,
                )
            })
            .collect()
    }
}

/// The keys of a rolling contact.
const ROLLING_FIELDS: Fields = Fields {
    kind: "rolling contact",
    keys: &[
        ("body", Need::Required),
        ("point", Need::Required),
        ("along", Need::Required),
        ("in", Need::Optional),
    ],
    example: "{ body: wheel, point: C, along: [x, y], in: N }",
};

/// `nonholonomic:` — `name: A(q, t) q̇ + b(q, t)` (an expression), or a rolling contact
/// `name: { body, point, along, in }`.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> (Expressions, Vec<RollingContact>) {
    let what = (
        "`nonholonomic`",
        "nonholonomic: { no_side_slip: -sin(theta)*x_dot + cos(theta)*y_dot }",
        "a non-holonomic constraint",
    );
    read_expressions_or(cx, node, what, read_rolling)
}

/// A rolling contact: `{ body, point, along: [x, y], in: N }`.
fn read_rolling(cx: &mut Ctx<'_>, k: &Located<String>, v: &YamlNode) -> Option<RollingContact> {
    let f = cx.fields(k, v, &ROLLING_FIELDS)?;
    let body = get(f, "body").and_then(|n| cx.name(n, "`body`"));
    let point = get(f, "point").and_then(|n| cx.name(n, "`point`"));
    let frame = read_in(cx, f)?;
    let along = get(f, "along").and_then(|n| {
        let items = cx.seq(n, "`along`", "along: [x, y]")?;
        let axes: Option<Vec<Located<Axis>>> = items
            .iter()
            .map(|i| cx.axes(i, true).and_then(|mut a| a.pop()))
            .collect();
        match axes {
            Some(a) if !a.is_empty() => Some(a),
            Some(_) => {
                cx.error(
                    Diagnostic::new(n.location, "`along` names no axis")
                        .with_help("list the axes along which the contact point does not slip, as in `along: [x, y]`"),
                );
                None
            }
            None => None,
        }
    });
    Some(RollingContact {
        name: k.clone(),
        body: body?,
        point: point?,
        along: along?,
        frame,
    })
}

/// `nonholonomic:` of a file written as it is: the constraints written as expressions,
/// then the rolling contacts.
pub(crate) fn write(
    w: &mut Writer<'_>,
    expressions: &[(Located<String>, Expr)],
    rolling: &[RollingContact],
) -> Result<(), NotRewritten> {
    if !w.preserve() || (expressions.is_empty() && rolling.is_empty()) {
        return Ok(());
    }
    w.line("nonholonomic:");
    for (name, e) in expressions {
        let place = format!("non-holonomic constraint `{}`", name.value);
        let text = w.expr(e, &place)?;
        w.line(format_args!("  {}: {}", name.value, flow(&text)));
    }
    for RollingContact {
        name,
        body,
        point,
        along,
        frame,
    } in rolling
    {
        let axes: Vec<Axis> = along.iter().map(|a| a.value).collect();
        w.line(format_args!(
            "  {}: {{ body: {}, point: {}, along: {}{} }}",
            name.value,
            body.value,
            point.value,
            axes_list(&axes),
            in_frame(frame.as_ref())
        ));
    }
    Ok(())
}

/// `[x, y]` of axes.
fn axes_list(axes: &[Axis]) -> String {
    let letters: Vec<String> = axes.iter().map(|a| a.letter().to_string()).collect();
    format!("[{}]", letters.join(", "))
}

/// The expressions may depend on the motion (they are linear in the rates, which the
/// mechanics checks once they are lowered).
pub(crate) fn expression_rules(expressions: &[(Located<String>, Expr)], cx: &mut dyn Rules) {
    super::expression_rules(expressions, Depends::Motion, cx);
}

/// A rolling contact names a rigid body and a point of the model; in a planar model it has
/// no frame and no `z` axis, in 3-D its frame is one of the model's.
pub(crate) fn rolling_rules(rolling: &[RollingContact], cx: &mut dyn Rules) {
    for r in rolling {
        cx.point(&r.point);
        match cx.body(&r.body.value) {
            BodyLookup::Found(BodyShape::Particle) => cx.error(
                Diagnostic::new(r.body.location, format!("rolling contact `{}` names `{}`, which is a particle", r.name.value, r.body.value))
                    .with_help("a body rolls about its centre of mass: name a rigid body (planar with `angle`, 3-D with `frame`)"),
            ),
            BodyLookup::Found(_) | BodyLookup::Excused => {}
            BodyLookup::Unknown(closest) => {
                let d = Diagnostic::new(r.body.location, format!("unknown body `{}`", r.body.value));
                cx.error(match closest {
                    Some(c) => d.with_help(format!("did you mean `{c}`?")),
                    None => d.with_help("declare it under `bodies:` as a rigid body"),
                });
            }
        }
        axes_rules(
            &format!("rolling contact `{}`", r.name.value),
            (r.frame.as_ref(), &r.along),
            "in a planar model `along` lists `x` and `y`",
            cx,
        );
    }
}

/// The rows of the non-holonomic constraints, by name: the expressions, then each rolling
/// contact's rows ([`rolling_rows`]), in file order.
pub(crate) fn rows(
    expressions: &[(Located<String>, Expr)],
    rolling: &[RollingContact],
    cx: &mut dyn Lower,
) -> Vec<(String, ExprId)> {
    let mut rows = expression_rows(expressions, cx);
    for r in rolling {
        rows.extend(rolling_rows(r, cx));
    }
    rows
}

/// The constraints of a rolling contact, `(v_G + ω × (r_C − r_G))·e_k = 0` for each axis
/// `e_k` of its frame, by name; none (reported) when its body, point or frame is unknown or
/// the body is not a rigid body of the model's dimension.
fn rolling_rows(r: &RollingContact, cx: &mut dyn Lower) -> Vec<(String, ExprId)> {
    let body = &r.body.value;
    let centre = cx.body_centre(body);
    let contact = cx.point_index(&r.point.value);
    let frame = match &r.frame {
        Some(f) => cx.frame_index(&f.value),
        None => Some(0),
    };
    let (Some(centre), Some(contact), Some(frame)) = (centre, contact, frame) else {
        cx.error(Diagnostic::new(
            r.name.location,
            format!(
                "rolling contact `{}` names an unknown body, point or frame",
                r.name.value
            ),
        ));
        return Vec::new();
    };
    let (centre, contact) = (cx.point_at(centre), cx.point_at(contact));
    let arena = cx.arena();
    let offset = difference(arena, &contact, &centre);
    let velocity: Vec<ExprId> = centre.iter().map(|c| arena.time_derivative(*c)).collect();
    // ω × r: in 3-D with ω carried into the ground frame; in the plane ω = θ̇ about z.
    let spin: Vec<ExprId> = match (cx.rigid_body_3d(body), cx.planar_angle(body), offset.len()) {
        (Some((_, body_frame, w)), _, 3) => {
            let w = cx.express(w, body_frame, 0);
            let r3 = [offset[0], offset[1], offset[2]];
            cross(cx.arena(), &w, &r3).to_vec()
        }
        (None, Some(angle), 2) => {
            let arena = cx.arena();
            let w = arena.time_derivative(angle);
            let a = arena.times(w, offset[1]);
            let b = arena.times(w, offset[0]);
            vec![arena.neg(a), b]
        }
        _ => {
            cx.error(Diagnostic::new(
                r.body.location,
                format!(
                    "rolling contact `{}`: `{}` is not a rigid body of the model's dimension",
                    r.name.value, r.body.value
                ),
            ));
            return Vec::new();
        }
    };
    let arena = cx.arena();
    let slip: Vec<ExprId> = velocity
        .iter()
        .zip(&spin)
        .map(|(v, s)| arena.plus(*v, *s))
        .collect();
    let (zero, one) = (arena.int(0), arena.int(1));
    r.along
        .iter()
        .zip(r.constraint_names())
        .map(|(axis, name)| {
            let mut e = vec![zero; slip.len()];
            e[axis.value.index()] = one;
            if slip.len() == 3 {
                e = cx.express([e[0], e[1], e[2]], frame, 0).to_vec();
            }
            (name.value, dot(cx.arena(), &slip, &e))
        })
        .collect()
}
