//! Holonomic constraints (`constraints:`), lectures 8–10: `Φ(q, t) = 0`, written as an
//! expression or as a point kept on a plane.
//!
//! ```yaml
//! constraints:
//!   rod: sqrt(x^2 + y^2) - l                  # Φ(q, t), a length
//!   on_ground: { point: C, along: z, in: N }  # C's position along N's z axis is 0
//! ```
//!
//! Each gives one row of `Φ`; the mechanics differentiates them into the constraint Jacobian
//! `J = ∂Φ/∂q` and `γ`, solves for the multipliers `λ` (named `lambda_<constraint>`) and
//! checks that the rows are independent. The expressions come first, then the constraints on
//! points, both in file order. Their units are checked with the other constraints' by the unit
//! check (unit_check/sections.rs), which gives each multiplier its unit from its row's.

use super::{
    Axis, Depends, Expressions, Lower, Rules, axes_rules, dot, expression_rows, in_frame,
    read_expressions_or, read_in,
};
use crate::expr::ExprId;
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::Located;
use crate::model::schema::entries::get;
use crate::model::schema::walk::{Ctx, Fields, Need};
use crate::model::schema::write::{NotRewritten, Writer, scalar};
use crate::model::yaml::YamlNode;

/// The key of the section.
pub(crate) const KEY: &str = "constraints";

/// A holonomic constraint on a point, `constraints: { on_ground: { point: C, along: z, in: N } }`:
/// the point's position along the axis `along` of frame `in` (the ground frame if not given)
/// is 0 — a contact point kept on the ground plane.
#[derive(Debug, Clone, PartialEq)]
pub struct PointConstraint {
    /// The constraint's name.
    pub name: Located<String>,
    /// The point.
    pub point: Located<String>,
    /// The axis.
    pub along: Located<Axis>,
    /// The frame of the axis; `None`: the ground frame.
    pub frame: Option<Located<String>>,
}

/// The keys of a constraint on a point.
const POINT_FIELDS: Fields = Fields {
    kind: "constraint on a point",
    keys: &[
        ("point", Need::Required),
        ("along", Need::Required),
        ("in", Need::Optional),
    ],
    example: "{ point: C, along: z, in: N }",
};

/// `constraints:` — `name: Φ(q, t)` (an expression), or a point kept on a plane
/// `name: { point, along, in }`.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> (Expressions, Vec<PointConstraint>) {
    let what = (
        "`constraints`",
        "constraints: { rod: sqrt(x^2 + y^2) - l }",
        "a holonomic constraint",
    );
    read_expressions_or(cx, node, what, read_point)
}

/// A constraint on a point: `{ point: C, along: z, in: N }`.
fn read_point(cx: &mut Ctx<'_>, k: &Located<String>, v: &YamlNode) -> Option<PointConstraint> {
    let f = cx.fields(k, v, &POINT_FIELDS)?;
    let point = get(f, "point").and_then(|n| cx.name(n, "`point`"));
    let along = get(f, "along").and_then(|n| cx.axes(n, true).and_then(|mut a| a.pop()));
    let frame = read_in(cx, f)?;
    Some(PointConstraint {
        name: k.clone(),
        point: point?,
        along: along?,
        frame,
    })
}

/// `constraints:` (expressions, then constraints on points) of a file written as it is; the
/// eliminations noted otherwise.
pub(crate) fn write(
    w: &mut Writer<'_>,
    expressions: &[(Located<String>, Expr)],
    on_points: &[PointConstraint],
) -> Result<(), NotRewritten> {
    if !w.preserve() {
        let eliminated: Vec<String> = w
            .edits
            .eliminated
            .iter()
            .map(|(constraint, coordinate)| format!("`{constraint}` gives {coordinate}"))
            .collect();
        w.notes.push(format!(
            "`constraints:` eliminated: {}",
            eliminated.join(", ")
        ));
        return Ok(());
    }
    if expressions.is_empty() && on_points.is_empty() {
        return Ok(());
    }
    w.line("constraints:");
    for (name, e) in expressions {
        w.line(format_args!("  {}: {}", name.value, scalar(&e.to_string())));
    }
    for c in on_points {
        w.line(format_args!(
            "  {}: {{ point: {}, along: {}{} }}",
            c.name.value,
            c.point.value,
            c.along.value.letter(),
            in_frame(c.frame.as_ref())
        ));
    }
    Ok(())
}

/// The expressions depend on the configuration and `t` only.
pub(crate) fn expression_rules(expressions: &[(Located<String>, Expr)], cx: &mut dyn Rules) {
    super::expression_rules(expressions, Depends::Position, cx);
}

/// A constraint on a point names a point of the model; in a planar model it has no frame and
/// no `z` axis, in 3-D its frame is one of the model's.
pub(crate) fn point_rules(on_points: &[PointConstraint], cx: &mut dyn Rules) {
    for c in on_points {
        cx.point(&c.point);
        axes_rules(
            &format!("constraint `{}`", c.name.value),
            (c.frame.as_ref(), std::slice::from_ref(&c.along)),
            "in a planar model `along` is `x` or `y`",
            cx,
        );
    }
}

/// The rows `Φ` of the holonomic constraints, by name: the expressions, then each
/// constraint on a point as its position along the axis (the axis carried into the ground
/// frame's components in 3-D), in file order. A point or frame that is not known is reported
/// (the rules reject it first) and its row left out.
pub(crate) fn rows(
    expressions: &[(Located<String>, Expr)],
    on_points: &[PointConstraint],
    cx: &mut dyn Lower,
) -> Vec<(String, ExprId)> {
    let mut rows = expression_rows(expressions, cx);
    for c in on_points {
        let (Some(p), Some(frame)) = (
            cx.point_index(&c.point.value),
            match &c.frame {
                Some(f) => cx.frame_index(&f.value),
                None => Some(0),
            },
        ) else {
            cx.error(Diagnostic::new(
                c.name.location,
                format!(
                    "constraint `{}` names an unknown point or frame",
                    c.name.value
                ),
            ));
            continue;
        };
        let r = cx.point_at(p);
        let arena = cx.arena();
        let (zero, one) = (arena.int(0), arena.int(1));
        let mut e = vec![zero; r.len()];
        if let Some(slot) = e.get_mut(c.along.value.index()) {
            *slot = one;
        }
        if r.len() == 3 {
            e = cx.express([e[0], e[1], e[2]], frame, 0).to_vec();
        }
        let phi = dot(cx.arena(), &r, &e);
        rows.push((c.name.value.clone(), phi));
    }
    rows
}
