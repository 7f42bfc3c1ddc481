//! Torques on rigid bodies (`torques:`), lectures 9–12 (planar) and 22–24 (3-D).
//!
//! ```yaml
//! torques:
//!   motor: { body: arm, value: tau0*sin(w*t) }          # planar body, counter-clockwise
//!   spin: { body: rotor, vector: [0, 0, T], in: B }      # 3-D body, components in frame B
//! ```
//!
//! A torque `τ` on a planar body of angle `θ` does the virtual work `τ δθ`, so Lagrange's
//! equations take it as `Qᵢ = τ ∂θ/∂qᵢ`; on a 3-D body, `τ·δφ` with `δφ = ω(δq)`, so
//! `Qᵢ = τ·∂ω/∂q̇ᵢ`, both vectors in the body frame's components (the vector is carried from
//! its frame `in:` there first). Momentum balance takes the torque itself on its body.

use super::{
    AXES, BodyLookup, BodyShape, Depends, Lower, Rules, Units, in_frame, projections, read_in,
};
use crate::expr::ExprId;
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::{Located, Location};
use crate::model::schema::entries::{get, get_key};
use crate::model::schema::walk::{Ctx, Fields, Keyed, Need};
use crate::model::schema::write::{NotRewritten, Writer, flow, list};
use crate::model::units::Dimension;
use crate::model::yaml::YamlNode;

/// The key of the section.
pub(crate) const KEY: &str = "torques";

/// A torque on a rigid body: `{ body: B, value: tau }` (N·m, counter-clockwise) on a planar
/// body, `{ body: B, vector: [Tx, Ty, Tz], in: F }` on a 3-D one.
#[derive(Debug, Clone, PartialEq)]
pub struct Torque {
    /// Name.
    pub name: Located<String>,
    /// The body it acts on.
    pub body: Located<String>,
    /// Torque (N·m).
    pub value: TorqueValue,
}

/// The value of a [`Torque`].
#[derive(Debug, Clone, PartialEq)]
pub enum TorqueValue {
    /// `value: tau` — about the axis normal to the plane, counter-clockwise (planar models).
    Planar(Expr),
    /// `vector: [Tx, Ty, Tz]` in the frame `in:` (the ground frame if `None`).
    Spatial {
        /// Components (N·m).
        vector: Vec<Expr>,
        /// The frame of the components.
        frame: Option<Located<String>>,
        /// Where the vector list starts.
        location: Location,
    },
}

impl TorqueValue {
    /// Every expression of the value.
    pub fn expressions(&self) -> Vec<&Expr> {
        match self {
            TorqueValue::Planar(e) => vec![e],
            TorqueValue::Spatial { vector, .. } => vector.iter().collect(),
        }
    }
}

/// The keys of a torque (`value` on a planar body, `vector` and `in` on a 3-D one).
const FIELDS: Fields = Fields {
    kind: "torque",
    keys: &[
        ("body", Need::Required),
        ("value", Need::Optional),
        ("vector", Need::Optional),
        ("in", Need::Optional),
    ],
    example: "{ body: arm, value: tau0*sin(w*t) }",
};

/// `torques:` — `name: { body, value }` or `name: { body, vector, in }`, in file order.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Vec<Torque> {
    let example = format!("torques: {{ motor: {} }}", FIELDS.example);
    let spec = Keyed {
        what: "`torques`",
        example: &example,
        names: None,
        drop: false,
    };
    cx.keyed(node, spec, |cx, k, v| {
        let f = cx.fields(k, v, &FIELDS)?;
        let body = get(f, "body").and_then(|n| cx.name(n, "`body`"));
        let what = format!("torque `{}`", k.value);
        let value = match (get(f, "value"), get(f, "vector")) {
            (Some(n), None) => {
                if let Some(i) = get_key(f, "in") {
                    cx.error(
                        Diagnostic::new(i.location, format!("{what} has a `value`, which is about the axis normal to the plane, so it has no frame `in`"))
                            .with_help("a torque on a 3-D body is `{ body: B, vector: [Tx, Ty, Tz], in: B }`"),
                    );
                    return None;
                }
                cx.expr(n, "a torque").map(TorqueValue::Planar)
            }
            (None, Some(n)) => {
                let frame = read_in(cx, f)?;
                let vector = cx.vector(n, &format!("the vector of {what}"), "vector: [0, 0, T]")?;
                Some(TorqueValue::Spatial {
                    vector,
                    frame,
                    location: n.location,
                })
            }
            (Some(_), Some(_)) | (None, None) => {
                cx.error(
                    Diagnostic::new(k.location, format!("{what} needs one of `value` (planar bodies) and `vector` (3-D bodies)"))
                        .with_help("on a planar body `{ body: arm, value: tau }` (counter-clockwise); on a 3-D body `{ body: B, vector: [Tx, Ty, Tz], in: B }`"),
                );
                None
            }
        };
        Some(Torque {
            name: k.clone(),
            body: body?,
            value: value?,
        })
    })
}

/// `torques:`, in the form [`read`] reads (planar and 3-D).
pub(crate) fn write(w: &mut Writer<'_>, torques: &[Torque]) -> Result<(), NotRewritten> {
    if torques.is_empty() {
        return Ok(());
    }
    w.line("torques:");
    for t in torques {
        let place = format!("torque `{}`", t.name.value);
        let value = match &t.value {
            TorqueValue::Planar(e) => format!("value: {}", flow(&w.expr(e, &place)?)),
            TorqueValue::Spatial { vector, frame, .. } => {
                let parts = w.exprs(vector, &place)?;
                format!("vector: {}{}", list(&parts), in_frame(frame.as_ref()))
            }
        };
        w.line(format_args!(
            "  {}: {{ body: {}, {value} }}",
            t.name.value, t.body.value
        ));
    }
    Ok(())
}

/// A torque as expressions of the model's arena.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum TorqueInfo {
    /// On a planar body.
    Planar {
        /// The body's index among the model's bodies.
        body: usize,
        /// Its angle `θ` (rad).
        angle: ExprId,
        /// `τ` (N·m), counter-clockwise.
        value: ExprId,
        /// Per coordinate, `Qᵢ = τ ∂θ/∂qᵢ`, `None` where it is 0.
        generalized_forces: Vec<Option<ExprId>>,
    },
    /// On a 3-D body.
    Spatial {
        /// The body's index among the model's bodies.
        body: usize,
        /// `τ` in the body frame's components (N·m).
        vector: [ExprId; 3],
        /// Per coordinate, `Qᵢ = τ·∂ω/∂q̇ᵢ`, `None` where it is 0.
        generalized_forces: Vec<Option<ExprId>>,
    },
}

impl TorqueInfo {
    /// Its generalized forces, per coordinate.
    pub(crate) fn generalized_forces(&self) -> &[Option<ExprId>] {
        match self {
            TorqueInfo::Planar {
                generalized_forces, ..
            }
            | TorqueInfo::Spatial {
                generalized_forces, ..
            } => generalized_forces,
        }
    }
}

impl Torque {
    /// A 3-D torque has three components (checked where the model has points).
    pub(crate) fn dimension_rules(&self, cx: &mut dyn Rules) {
        if let TorqueValue::Spatial {
            vector, location, ..
        } = &self.value
            && vector.len() != 3
        {
            cx.error(
                Diagnostic::new(
                    *location,
                    format!(
                        "the vector of torque `{}` has {} components; a torque on a 3-D body has 3",
                        self.name.value,
                        vector.len()
                    ),
                )
                .with_help(
                    "write `vector: [Tx, Ty, Tz]`; a torque on a planar body is `value: tau`",
                ),
            );
        }
    }

    /// Its value depends on the motion and `t` at most, its frame exists, and its body is a
    /// rigid body of the value's kind (planar for `value`, 3-D for `vector`).
    pub(crate) fn rules(&self, cx: &mut dyn Rules) {
        let what = format!("torque `{}`", self.name.value);
        for e in self.value.expressions() {
            cx.expression(e, Depends::Motion, &what);
        }
        if let TorqueValue::Spatial {
            frame: Some(frame), ..
        } = &self.value
        {
            cx.frame(frame);
        }
        self.body_rules(cx);
    }

    /// Its body is a rigid body of the value's kind.
    fn body_rules(&self, cx: &mut dyn Rules) {
        let name = &self.body.value;
        let shape = match cx.body(name) {
            BodyLookup::Found(shape) => shape,
            BodyLookup::Excused => return,
            BodyLookup::Unknown(closest) => {
                let d = Diagnostic::new(self.body.location, format!("unknown body `{name}`"));
                cx.error(match closest {
                    Some(c) => d.with_help(format!("did you mean `{c}`?")),
                    None => d.with_help("declare it under `bodies:` as a planar rigid body"),
                });
                return;
            }
        };
        let d = match (shape, &self.value) {
            (BodyShape::Planar, TorqueValue::Planar(_))
            | (BodyShape::Spatial, TorqueValue::Spatial { .. }) => return,
            (BodyShape::Planar, TorqueValue::Spatial { location, .. }) => Diagnostic::new(*location, format!("torque `{}` is a 3-D vector, but `{name}` is a planar rigid body", self.name.value))
                .with_help("a torque on a planar body is `value: tau` (counter-clockwise, about the axis normal to the plane)"),
            (BodyShape::Spatial, TorqueValue::Planar(e)) => Diagnostic::new(e.location, format!("torque `{}` is a number, but `{name}` is a 3-D rigid body", self.name.value))
                .with_help("a torque on a 3-D body is a vector: `{ body: B, vector: [0, 0, T], in: B }`"),
            (BodyShape::Particle, _) => Diagnostic::new(
                self.body.location,
                format!("torque `{}` acts on `{name}`, which is a particle", self.name.value),
            )
            .with_help("torques act on rigid bodies (planar with `inertia` and `angle`, 3-D with `frame`); apply a force to a particle"),
        };
        cx.error(d);
    }

    /// Its components are in N·m.
    pub(crate) fn units(&self, cx: &mut dyn Units) {
        for (i, e) in self.value.expressions().into_iter().enumerate() {
            let what = match &self.value {
                TorqueValue::Planar(_) => format!("torque `{}`", self.name.value),
                TorqueValue::Spatial { .. } => {
                    format!("the {} component of torque `{}`", AXES[i], self.name.value)
                }
            };
            cx.fixed(
                e,
                Dimension::JOULE,
                &what,
                "a torque",
                "N*m",
                "a torque is force × lever arm, N*m",
            );
        }
    }

    /// The torque as expressions, with its generalized forces; `None` (with the mistake
    /// reported) if its body is not a rigid body of the value's kind.
    pub(crate) fn lower(&self, cx: &mut dyn Lower) -> Option<TorqueInfo> {
        match &self.value {
            TorqueValue::Planar(value) => self.lower_planar(cx, value),
            TorqueValue::Spatial { vector, frame, .. } => {
                self.lower_spatial(cx, vector, frame.as_ref())
            }
        }
    }

    /// On a planar body: `Qᵢ = τ ∂θ/∂qᵢ`.
    fn lower_planar(&self, cx: &mut dyn Lower, value: &Expr) -> Option<TorqueInfo> {
        let Some(angle) = cx.planar_angle(&self.body.value) else {
            cx.error(Diagnostic::new(
                self.body.location,
                format!("`{}` is not a planar rigid body", self.body.value),
            ));
            return None;
        };
        let tau = cx.expr(value);
        let body = cx.body_index(&self.body.value).unwrap_or(0);
        let arena = cx.arena();
        let coordinates: Vec<_> = arena.coordinates().iter().map(|s| s[0]).collect();
        let generalized_forces = coordinates
            .iter()
            .map(|&q| {
                let partial = arena.diff(angle, q);
                (!arena.is_zero(partial)).then(|| arena.times(tau, partial))
            })
            .collect();
        Some(TorqueInfo::Planar {
            body,
            angle,
            value: tau,
            generalized_forces,
        })
    }

    /// On a 3-D body: `τ` in the body frame's components, `Qᵢ = τ·∂ω/∂q̇ᵢ`.
    fn lower_spatial(
        &self,
        cx: &mut dyn Lower,
        vector: &[Expr],
        frame: Option<&Located<String>>,
    ) -> Option<TorqueInfo> {
        let Some((body, body_frame, omega)) = cx.rigid_body_3d(&self.body.value) else {
            cx.error(Diagnostic::new(
                self.body.location,
                format!("`{}` is not a 3-D rigid body", self.body.value),
            ));
            return None;
        };
        let from = frame.and_then(|f| cx.frame_index(&f.value)).unwrap_or(0);
        let [x, y, z] = vector else { return None };
        let v = [x, y, z].map(|c| cx.expr(c));
        let v = cx.express(v, from, body_frame);
        let arena = cx.arena();
        let rates: Vec<_> = arena.coordinates().iter().map(|s| s[1]).collect();
        let generalized_forces = projections(arena, &rates, (&v, &omega), None);
        Some(TorqueInfo::Spatial {
            body,
            vector: v,
            generalized_forces,
        })
    }
}
