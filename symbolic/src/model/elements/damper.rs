//! Linear viscous dampers between two points (`dampers:`), lectures 20–21.
//!
//! ```yaml
//! dampers:
//!   d1: { between: [A, B], coefficient: c }
//! ```
//!
//! With `d = r_A − r_B`, the damper pushes along the line of its points against the rate of
//! stretch, `F_A = −c (ḋ·d) d/(d·d)` and `F_B = −F_A`. Lagrange's equations take it as the
//! generalized forces `Qᵢ = F_A·∂d/∂qᵢ`, momentum balance as the two forces: both from
//! `force_scale`.

use super::{Lower, Rules, Units, between, dot, projections, read_between, write_between};
use crate::expr::{ExprArena, ExprId};
use crate::model::ast::Expr;
use crate::model::elements::Depends;
use crate::model::located::Located;
use crate::model::schema::walk::{Ctx, Fields, Need};
use crate::model::schema::write::{NotRewritten, Writer};
use crate::model::units::Dimension;
use crate::model::yaml::YamlNode;

/// The key of the section.
pub(crate) const KEY: &str = "dampers";

/// A linear viscous damper between two points, acting along the line of the points:
/// `{ between: [A, B], coefficient: c }`.
#[derive(Debug, Clone, PartialEq)]
pub struct Damper {
    /// Name.
    pub name: Located<String>,
    /// The two end points.
    pub between: [Located<String>; 2],
    /// Damping coefficient `c` (N·s/m).
    pub coefficient: Expr,
}

/// The keys of a damper.
const FIELDS: Fields = Fields {
    kind: "damper",
    keys: &[("between", Need::Required), ("coefficient", Need::Required)],
    example: "{ between: [A, B], coefficient: c }",
};

/// `dampers:` — `name: { between, coefficient }`, in file order.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Vec<Damper> {
    let what = |_: &str| "a damping coefficient".to_string();
    read_between(cx, node, (KEY, &FIELDS, "d"), "coefficient", what)
        .into_iter()
        .map(|(name, between, coefficient)| Damper {
            name,
            between,
            coefficient,
        })
        .collect()
}

/// `dampers:`, in the form [`read`] reads.
pub(crate) fn write(w: &mut Writer<'_>, dampers: &[Damper]) -> Result<(), NotRewritten> {
    let entries = dampers
        .iter()
        .map(|d| (&d.name, &d.between, &d.coefficient));
    write_between(w, (KEY, "damper", "coefficient"), entries)
}

/// A damper as expressions of the model's arena.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct DamperInfo {
    /// The end points' indices among the model's points.
    pub between: [usize; 2],
    /// `c` (N·s/m).
    pub coefficient: ExprId,
    /// Per coordinate, its generalized force `Qᵢ = F_A·∂d/∂qᵢ` (N or N·m), `None` where it
    /// is 0.
    pub generalized_forces: Vec<Option<ExprId>>,
}

impl Damper {
    /// Its points exist; the coefficient depends on the configuration and `t` at most.
    pub(crate) fn rules(&self, cx: &mut dyn Rules) {
        self.between.iter().for_each(|p| cx.point(p));
        cx.expression(
            &self.coefficient,
            Depends::Position,
            &format!("the coefficient of damper `{}`", self.name.value),
        );
    }

    /// The coefficient is in N·s/m.
    pub(crate) fn units(&self, cx: &mut dyn Units) {
        cx.fixed(
            &self.coefficient,
            Dimension::DAMPING,
            &format!("the coefficient of damper `{}`", self.name.value),
            "a damping coefficient",
            "N*s/m",
            "a damper pushes with coefficient × rate of stretch, N*s/m × m/s = N",
        );
    }

    /// The damper as expressions, with its generalized forces; `None` (with the mistake
    /// reported) if it names an unknown point.
    pub(crate) fn lower(&self, cx: &mut dyn Lower) -> Option<DamperInfo> {
        let ([a, b], d) = between(cx, &self.between, &self.name, "damper")?;
        let arena = cx.arena();
        let rate_of: Vec<ExprId> = d.iter().map(|c| arena.time_derivative(*c)).collect();
        let c = cx.expr(&self.coefficient);
        let arena = cx.arena();
        let scale = force_scale(arena, (&d, &rate_of), c);
        let coordinates: Vec<_> = arena.coordinates().iter().map(|s| s[0]).collect();
        let generalized_forces = projections(arena, &coordinates, (&d, &d), Some(scale));
        Some(DamperInfo {
            between: [a, b],
            coefficient: c,
            generalized_forces,
        })
    }
}

/// The damper's push on its end `A` per unit of `d = r_A − r_B`, from `d` and its rate `ḋ`:
/// `F_A = s d` with `s = −c (ḋ·d)/(d·d)` (`F_B = −F_A`).
pub(crate) fn force_scale(
    arena: &mut ExprArena,
    (d, rate_of): (&[ExprId], &[ExprId]),
    coefficient: ExprId,
) -> ExprId {
    let d2 = dot(arena, d, d);
    let rate = dot(arena, d, rate_of);
    let c_rate = arena.times(coefficient, rate);
    let scale = arena.divide(c_rate, d2);
    arena.neg(scale)
}
