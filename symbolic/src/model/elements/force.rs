//! Forces applied at points (`forces:`), lectures 3–7 and 20–21.
//!
//! ```yaml
//! forces:
//!   push: { at: P, vector: [F0*cos(w*t), 0] }
//!   thrust: { at: Q, vector: [0, 0, T], in: B }   # components in frame B (3-D)
//! ```
//!
//! A force `F` at the point `P` does the virtual work `F·δr_P`, so Lagrange's equations take
//! it as the generalized forces `Qᵢ = F·∂r_P/∂qᵢ` (the partial velocities `∂v_P/∂q̇ᵢ`), and
//! momentum balance as the force itself at its point. A force written in a frame (`in: B`)
//! is carried into the ground frame's components first. Components may depend on the
//! configuration, the rates and `t`.

use super::{AXES, Depends, Lower, Rules, Units, in_frame, projections, read_in};
use crate::expr::ExprId;
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::{Located, Location};
use crate::model::schema::entries::get;
use crate::model::schema::walk::{Ctx, Fields, Keyed, Need};
use crate::model::schema::write::{NotRewritten, Writer, list};
use crate::model::units::Dimension;
use crate::model::yaml::YamlNode;

/// The key of the section.
pub(crate) const KEY: &str = "forces";

/// A force applied at a point: `{ at: P, vector: [Fx, Fy] }`, components any expression of
/// `q`, `q̇` and `t`.
#[derive(Debug, Clone, PartialEq)]
pub struct Force {
    /// Name.
    pub name: Located<String>,
    /// Point of application.
    pub at: Located<String>,
    /// Components (N), as many as the model's dimension.
    pub vector: Vec<Expr>,
    /// The frame the components are written in (`in: B`); `None`: the ground frame.
    pub frame: Option<Located<String>>,
    /// Where the vector list starts.
    pub location: Location,
}

/// The keys of a force.
const FIELDS: Fields = Fields {
    kind: "force",
    keys: &[
        ("at", Need::Required),
        ("vector", Need::Required),
        ("in", Need::Optional),
    ],
    example: "{ at: P, vector: [F0*cos(w*t), 0] }",
};

/// `forces:` — `name: { at, vector, in }`, in file order.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Vec<Force> {
    let example = format!("forces: {{ push: {} }}", FIELDS.example);
    let spec = Keyed {
        what: "`forces`",
        example: &example,
        names: None,
        drop: false,
    };
    cx.keyed(node, spec, |cx, k, v| {
        let f = cx.fields(k, v, &FIELDS)?;
        let at = get(f, "at").and_then(|n| cx.name(n, "`at`"));
        let vector = get(f, "vector").and_then(|n| {
            cx.vector(
                n,
                &format!("the vector of force `{}`", k.value),
                "vector: [Fx, Fy]",
            )
            .map(|x| (x, n.location))
        });
        let frame = read_in(cx, f);
        let (vector, location) = vector?;
        Some(Force {
            name: k.clone(),
            at: at?,
            vector,
            frame: frame?,
            location,
        })
    })
}

/// `forces:`, in the form [`read`] reads (3-D ones and those written in frames included).
pub(crate) fn write(w: &mut Writer<'_>, forces: &[Force]) -> Result<(), NotRewritten> {
    if forces.is_empty() {
        return Ok(());
    }
    w.line("forces:");
    for f in forces {
        let place = format!("force `{}`", f.name.value);
        let parts = w.exprs(&f.vector, &place)?;
        w.line(format_args!(
            "  {}: {{ at: {}, vector: {}{} }}",
            f.name.value,
            f.at.value,
            list(&parts),
            in_frame(f.frame.as_ref())
        ));
    }
    Ok(())
}

/// A force as expressions of the model's arena.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ForceInfo {
    /// The point's index among the model's points.
    pub point: usize,
    /// The components in the ground frame (N), 2 or 3.
    pub vector: Vec<ExprId>,
    /// Per coordinate, its generalized force `Qᵢ = F·∂r_P/∂qᵢ` (N or N·m), `None` where it is
    /// 0.
    pub generalized_forces: Vec<Option<ExprId>>,
}

impl Force {
    /// As many components as the points have (`dim`, checked where the model has points),
    /// three when written in a frame.
    pub(crate) fn dimension_rules(&self, cx: &mut dyn Rules, dim: usize) {
        if self.vector.len() != dim {
            cx.error(Diagnostic::new(
                self.location,
                format!(
                    "force `{}` has {} components but the points have {dim}",
                    self.name.value,
                    self.vector.len()
                ),
            ));
        }
        if let Some(frame) = &self.frame
            && self.vector.len() != 3
        {
            cx.error(
                Diagnostic::new(
                    frame.location,
                    format!(
                        "force `{}` is written in frame `{}`, which needs 3 components",
                        self.name.value, frame.value
                    ),
                )
                .with_help("frames are 3-D: write `vector: [Fx, Fy, Fz]`, or leave out `in` for components in the plane"),
            );
        }
    }

    /// Its components depend on the motion and `t` at most, its frame and point exist.
    pub(crate) fn rules(&self, cx: &mut dyn Rules) {
        for c in &self.vector {
            cx.expression(c, Depends::Motion, &format!("force `{}`", self.name.value));
        }
        if let Some(frame) = &self.frame {
            cx.frame(frame);
        }
        cx.point(&self.at);
    }

    /// The components are in N.
    pub(crate) fn units(&self, cx: &mut dyn Units) {
        for (axis, c) in AXES.iter().zip(&self.vector) {
            cx.fixed(
                c,
                Dimension::NEWTON,
                &format!("the {axis} component of force `{}`", self.name.value),
                "a force",
                "N",
                "a force is mass × acceleration, kg*m/s^2 = N",
            );
        }
    }

    /// The force in the ground frame's components, with its generalized forces; `None` (with
    /// the mistake reported) if its point is unknown.
    pub(crate) fn lower(&self, cx: &mut dyn Lower) -> Option<ForceInfo> {
        let Some(point) = cx.point_index(&self.at.value) else {
            cx.error(Diagnostic::new(
                self.at.location,
                format!("unknown point `{}`", self.at.value),
            ));
            return None;
        };
        let mut vector: Vec<ExprId> = self.vector.iter().map(|c| cx.expr(c)).collect();
        if let Some(frame) = &self.frame
            && let &[x, y, z] = &vector[..]
            && let Some(from) = cx.frame_index(&frame.value)
        {
            vector = cx.express([x, y, z], from, 0).to_vec();
        }
        let r = cx.point_at(point);
        let arena = cx.arena();
        let coordinates: Vec<_> = arena.coordinates().iter().map(|s| s[0]).collect();
        let generalized_forces = projections(arena, &coordinates, (&vector, &r), None);
        Some(ForceInfo {
            point,
            vector,
            generalized_forces,
        })
    }
}
