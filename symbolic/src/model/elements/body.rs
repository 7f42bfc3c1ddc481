//! Bodies (`bodies:`): particles (lectures 5–7), planar rigid bodies (lectures 11–16) and
//! rigid bodies in 3-D (Kane & Levinson, *Dynamics: Theory and Applications*, 1985, ch. 3 on
//! mass distribution and ch. 5 on energy functions).
//!
//! ```yaml
//! bodies:
//!   bob: { mass: m, at: P }                                      # a particle
//!   rod: { mass: m, inertia: m*l^2/12, com: G, angle: theta }     # planar
//!   top: { mass: m, com: G, frame: B, inertia: [I1, I1, I3] }     # 3-D, in frame B's axes
//! ```
//!
//! A body gives the kinetic energy `T = ½ m v_G·v_G` plus `½ I_G θ̇²` (planar) or
//! `½ ω·I_G ω` (3-D), gravity's potential `−m g·r_G`, and momentum balance its mass and
//! inertia at its centre of mass.

pub mod inertia;
mod syntax;

pub(crate) use syntax::{read, write};

use super::{BodyShape, Depends, Lower, Rules, Units, dot};
use crate::expr::ExprId;
use crate::mechanics::frames::tensor_times;
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::{Located, Location};
use crate::model::units::Dimension;
use inertia::InertiaProblem;

/// The key of the section.
pub(crate) const KEY: &str = "bodies";

/// A 3-D inertia tensor about a body's centre of mass in the body's frame (kg·m²): the
/// moments `xx, yy, zz` and the tensor's off-diagonal entries `xy, yz, xz` (which are the
/// negatives of the products of inertia `∫xy dm`); absent entries are 0.
#[derive(Debug, Clone, PartialEq)]
pub struct InertiaTensor {
    /// `[xx, yy, zz, xy, yz, xz]`; `None` for an entry not written (0).
    pub entries: [Option<Expr>; 6],
    /// Where the inertia is written.
    pub location: Location,
}

impl InertiaTensor {
    /// The names of the entries, in [`InertiaTensor::entries`]'s order.
    pub const KEYS: [&'static str; 6] = ["xx", "yy", "zz", "xy", "yz", "xz"];
}

/// What kind of body.
#[derive(Debug, Clone, PartialEq)]
pub enum BodyKind {
    /// A point mass at `at`: `{ mass: m, at: P }`.
    Particle {
        /// Mass (kg).
        mass: Expr,
        /// The point where the mass sits.
        at: Located<String>,
    },
    /// A planar rigid body: `{ mass: m, inertia: I_G, com: G, angle: theta }`.
    Rigid {
        /// Mass (kg).
        mass: Expr,
        /// Centroidal moment of inertia about the axis normal to the plane (kg·m²).
        inertia: Expr,
        /// Centre-of-mass point.
        com: Located<String>,
        /// Orientation angle (rad), counter-clockwise; an expression in `q` and `t`.
        angle: Expr,
    },
    /// A rigid body in 3-D: `{ mass: m, com: G, frame: B, inertia: [I1, I2, I3] }`.
    Spatial {
        /// Mass (kg).
        mass: Expr,
        /// Centre-of-mass point.
        com: Located<String>,
        /// The frame fixed in the body.
        frame: Located<String>,
        /// Inertia tensor about the centre of mass, in the body frame's axes (boxed: six
        /// expressions would make every body as large).
        inertia: Box<InertiaTensor>,
    },
}

impl BodyKind {
    /// The body's mass.
    pub fn mass(&self) -> &Expr {
        match self {
            BodyKind::Particle { mass, .. }
            | BodyKind::Rigid { mass, .. }
            | BodyKind::Spatial { mass, .. } => mass,
        }
    }

    /// The point of its mass: `at` of a particle, `com` of a rigid body.
    pub fn com(&self) -> &Located<String> {
        match self {
            BodyKind::Particle { at, .. } => at,
            BodyKind::Rigid { com, .. } | BodyKind::Spatial { com, .. } => com,
        }
    }

    /// The kind as the rules of loads on bodies see it.
    pub(crate) fn shape(&self) -> BodyShape {
        match self {
            BodyKind::Particle { .. } => BodyShape::Particle,
            BodyKind::Rigid { .. } => BodyShape::Planar,
            BodyKind::Spatial { .. } => BodyShape::Spatial,
        }
    }
}

/// A body of the kinematic form.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Name.
    pub name: Located<String>,
    /// A particle, a planar rigid body or a 3-D one.
    pub kind: BodyKind,
}

/// The frame of each 3-D body is a frame of the model.
pub(crate) fn frame_rules(bodies: &[Body], cx: &mut dyn Rules) {
    for b in bodies {
        if let BodyKind::Spatial { frame, .. } = &b.kind {
            cx.frame(frame);
        }
    }
}

/// Masses and inertias are constants; a planar body's angle is a function of the
/// configuration (no rates).
pub(crate) fn expression_rules(bodies: &[Body], cx: &mut dyn Rules) {
    for b in bodies {
        let name = &b.name.value;
        cx.expression(
            b.kind.mass(),
            Depends::Constant,
            &format!("the mass of body `{name}`"),
        );
        match &b.kind {
            BodyKind::Particle { .. } => {}
            BodyKind::Rigid { inertia, angle, .. } => {
                cx.expression(
                    inertia,
                    Depends::Constant,
                    &format!("the inertia of body `{name}`"),
                );
                cx.expression(
                    angle,
                    Depends::Position,
                    &format!("the angle of body `{name}`"),
                );
            }
            BodyKind::Spatial { inertia, .. } => {
                for e in inertia.entries.iter().flatten() {
                    cx.expression(
                        e,
                        Depends::Constant,
                        &format!("the inertia of body `{name}`"),
                    );
                }
            }
        }
    }
}

/// A body's mass is positive and its inertia that of a physical body ([`inertia`]), where
/// they are constant expressions of the parameters (evaluated at the defaults).
pub(crate) fn value_rules(bodies: &[Body], cx: &mut dyn Rules) {
    for b in bodies {
        let (mass, inertia) = match &b.kind {
            BodyKind::Particle { mass, .. } => (mass, None),
            BodyKind::Rigid { mass, inertia, .. } => (mass, Some(inertia)),
            BodyKind::Spatial { mass, inertia, .. } => {
                tensor_rules(&b.name.value, inertia, cx);
                (mass, None)
            }
        };
        if let Some(problem) = cx
            .value(mass)
            .and_then(|m| inertia::mass_problem(&b.name.value, m))
        {
            cx.error(
                Diagnostic::new(mass.location, problem)
                    .with_help("a mass must be positive (at the parameters' defaults)"),
            );
        }
        if let Some(inertia) = inertia
            && let Some(problem) = cx
                .value(inertia)
                .and_then(|i| inertia::planar_inertia_problem(&b.name.value, i))
        {
            cx.error(
                Diagnostic::new(inertia.location, problem).with_help(
                    "a centroidal moment of inertia is ≥ 0 (at the parameters' defaults)",
                ),
            );
        }
    }
}

/// A 3-D body's inertia tensor is finite, positive definite and within the triangle
/// inequality of its principal moments, at the parameters' defaults
/// ([`inertia::inertia_problem`]).
fn tensor_rules(body: &str, inertia: &InertiaTensor, cx: &mut dyn Rules) {
    let mut e = [0.0; 6];
    for ((slot, entry), name) in e.iter_mut().zip(&inertia.entries).zip(InertiaTensor::KEYS) {
        if let Some(x) = entry {
            match cx.value(x) {
                Some(v) if v.is_finite() => *slot = v,
                Some(v) => {
                    cx.error(
                        Diagnostic::new(
                            inertia.location,
                            format!(
                                "the inertia of body `{body}` is not finite: its entry {name} is {v} at the parameters' defaults"
                            ),
                        )
                        .with_help("each entry of an inertia tensor is a finite number of kg·m² (check the parameters it is written with: a 0/0, a root of a negative number)"),
                    );
                    return;
                }
                None => return,
            }
        }
    }
    if let Some(problem) = inertia::inertia_problem(body, e) {
        let at = "at the parameters' defaults";
        let diagnostic = match problem {
            InertiaProblem::NotPositiveDefinite(message) => Diagnostic::new(
                inertia.location,
                format!("{message} {at}"),
            )
            .with_help("a rigid body's inertia tensor about its centre of mass is positive definite (its three principal moments are positive); a moment ≤ 0, or an off-diagonal entry as large as the moments it joins, is not"),
            InertiaProblem::NotARigidBody(message) => Diagnostic::new(
                inertia.location,
                format!("{message} {at}"),
            )
            .with_help("no mass distribution has one principal moment larger than the sum of the other two (in principal axes, I₃ = ∫(x² + y²) dm ≤ ∫(y² + z²) dm + ∫(x² + z²) dm = I₁ + I₂; equal for a flat body); check the moments and their axes"),
        };
        cx.error(diagnostic);
    }
}

/// Masses in kg, inertias in kg·m², a planar body's angle a pure number (rad).
pub(crate) fn units(bodies: &[Body], cx: &mut dyn Units) {
    for b in bodies {
        let name = &b.name.value;
        let (mass, inertia_angle) = match &b.kind {
            BodyKind::Particle { mass, .. } => (mass, None),
            BodyKind::Spatial { mass, inertia, .. } => {
                for (key, e) in InertiaTensor::KEYS.iter().zip(&inertia.entries) {
                    if let Some(e) = e {
                        cx.fixed(
                            e,
                            Dimension::INERTIA,
                            &format!("the `{key}` inertia of body `{name}`"),
                            "a moment of inertia",
                            "kg*m^2",
                            "an entry of an inertia tensor is mass × length², as in `m*r^2/2` for a disc about its axis",
                        );
                    }
                }
                (mass, None)
            }
            BodyKind::Rigid {
                mass,
                inertia,
                angle,
                ..
            } => (mass, Some((inertia, angle))),
        };
        cx.fixed(
            mass,
            Dimension::KILOGRAM,
            &format!("the mass of body `{name}`"),
            "a mass",
            "kg",
            "a body's mass is in kg",
        );
        if let Some((inertia, angle)) = inertia_angle {
            cx.fixed(
                inertia,
                Dimension::INERTIA,
                &format!("the inertia of body `{name}`"),
                "a moment of inertia",
                "kg*m^2",
                "a moment of inertia is mass × length², as in `m*l^2/12` for a uniform bar about its centre",
            );
            cx.fixed(
                angle,
                Dimension::ONE,
                &format!("the angle of body `{name}`"),
                "an angle",
                "rad (a pure number)",
                "a body's angle is an angle coordinate, or a function of the coordinates that gives a pure number",
            );
        }
    }
}

/// A body of the kinematic form, as expressions.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyInfo {
    /// Name.
    pub name: String,
    /// Mass (kg).
    pub mass: ExprId,
    /// Index into `SymbolicModel::points` of the centre of mass (or the particle).
    pub com: usize,
    /// `(centroidal inertia, angle)` of a planar rigid body; `None` for a particle.
    pub rotation: Option<(ExprId, ExprId)>,
    /// The orientation and inertia of a 3-D rigid body; `None` for a particle or a planar
    /// body.
    pub spatial: Option<SpatialBody>,
}

/// A 3-D rigid body's frame, angular velocity and inertia, all in the body frame's axes.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialBody {
    /// Index of its frame in `SymbolicModel::frames`.
    pub frame: usize,
    /// `^N ω^B` (rad/s) in the body frame's components, linear in the rates.
    pub angular_velocity: [ExprId; 3],
    /// The inertia tensor about the centre of mass (kg·m²): `[xx, yy, zz, xy, yz, xz]`.
    pub inertia: [ExprId; 6],
}

/// A body lowered: what the derivations read of it, and its terms of `T` and `V`.
pub(crate) struct LoweredBody {
    /// What momentum balance, the constraints and the contacts read of it.
    pub(crate) info: BodyInfo,
    /// Its terms of the kinetic energy (J): `½ m v_G·v_G`, then `½ I_G θ̇²` (planar) or
    /// `½ ω·I_G ω` (3-D).
    pub(crate) kinetic: Vec<ExprId>,
    /// Its potential in the gravitational field, `−m g·r_G` (J), when there is one.
    pub(crate) potential: Option<ExprId>,
}

impl Body {
    /// Its mass, centre, rotation and energies, with `gravity` (m/s², ground components) if
    /// the model has it and `half` the constant ½; `None` (reported) if its point is unknown.
    /// The expressions are built in this order, which fixes their identifiers and so the
    /// generated code.
    pub(crate) fn lower(
        &self,
        gravity: Option<&[ExprId]>,
        half: ExprId,
        cx: &mut dyn Lower,
    ) -> Option<LoweredBody> {
        let (mass, at, rigid) = match &self.kind {
            BodyKind::Particle { mass, at } => (mass, at, None),
            BodyKind::Rigid {
                mass,
                inertia,
                com,
                angle,
            } => (mass, com, Some((inertia, angle))),
            BodyKind::Spatial { mass, com, .. } => (mass, com, None),
        };
        let m = cx.expr(mass);
        let Some(com) = cx.point_index(&at.value) else {
            cx.error(Diagnostic::new(
                at.location,
                format!("unknown point `{}`", at.value),
            ));
            return None;
        };
        let r = cx.point_at(com);
        let arena = cx.arena();
        let v: Vec<ExprId> = r.iter().map(|c| arena.time_derivative(*c)).collect();
        let v2 = dot(arena, &v, &v);
        let mut kinetic = vec![arena.product(&[half, m, v2])];
        let potential = gravity.map(|g| {
            let gr = dot(arena, g, &r);
            let mgr = arena.times(m, gr);
            arena.neg(mgr)
        });
        let mut rotation = None;
        if let Some((inertia, angle)) = rigid {
            let i = cx.expr(inertia);
            let th = cx.expr(angle);
            rotation = Some((i, th));
            let arena = cx.arena();
            let w = arena.time_derivative(th);
            let two = arena.int(2);
            let w2 = arena.pow(w, two);
            kinetic.push(arena.product(&[half, i, w2]));
        }
        let spatial = match &self.kind {
            BodyKind::Spatial { frame, inertia, .. } => {
                lower_spatial(frame, inertia, half, cx, &mut kinetic)
            }
            _ => None,
        };
        Some(LoweredBody {
            info: BodyInfo {
                name: self.name.value.clone(),
                mass: m,
                com,
                rotation,
                spatial,
            },
            kinetic,
            potential,
        })
    }
}

/// A 3-D body's angular velocity (from its frame's rotations) and inertia tensor, with its
/// rotational kinetic energy `½ ω·I_G ω` (body components) added to `kinetic`; `None`
/// (reported) if its frame is unknown.
fn lower_spatial(
    frame: &Located<String>,
    inertia: &InertiaTensor,
    half: ExprId,
    cx: &mut dyn Lower,
    kinetic: &mut Vec<ExprId>,
) -> Option<SpatialBody> {
    let Some(f) = cx.frame_index(&frame.value) else {
        cx.error(Diagnostic::new(
            frame.location,
            format!("unknown frame `{}`", frame.value),
        ));
        return None;
    };
    let zero = cx.arena().int(0);
    let inertia = inertia
        .entries
        .clone()
        .map(|e| e.map_or(zero, |e| cx.expr(&e)));
    let w = cx.angular_velocity(f);
    let arena = cx.arena();
    let iw = tensor_times(arena, &inertia, &w);
    let wiw = dot(arena, &w, &iw);
    kinetic.push(arena.times(half, wiw));
    Some(SpatialBody {
        frame: f,
        angular_velocity: w,
        inertia,
    })
}
