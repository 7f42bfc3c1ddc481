//! A uniform gravitational field (`gravity:`), lectures 3 and 9.
//!
//! ```yaml
//! gravity: [0, -g]        # planar; [0, 0, -g] in 3-D
//! ```
//!
//! The acceleration of free fall, constant components in the ground frame. It acts on every
//! body at its centre of mass: Lagrange's equations take `V = −Σ m g·r_G` and momentum
//! balance the forces `m g`, both from the bodies' lowering with the vector this module
//! lowers.

use super::{AXES, Depends, Lower, Rules, Units};
use crate::expr::ExprId;
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::Located;
use crate::model::schema::walk::Ctx;
use crate::model::schema::write::{NotRewritten, Writer, list};
use crate::model::units::Dimension;
use crate::model::yaml::YamlNode;

/// The key of the section.
pub(crate) const KEY: &str = "gravity";

/// `gravity: [gx, gy]` (or three components), located at the list.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Option<Located<Vec<Expr>>> {
    cx.vector(node, "`gravity`", "gravity: [0, -g]")
        .map(|g| Located::new(g, node.location))
}

/// `gravity:`, in the form [`read`] reads.
pub(crate) fn write(
    w: &mut Writer<'_>,
    gravity: Option<&Located<Vec<Expr>>>,
) -> Result<(), NotRewritten> {
    if let Some(g) = gravity {
        let parts = w.exprs(&g.value, "`gravity:`")?;
        w.line(format_args!("gravity: {}", list(&parts)));
    }
    Ok(())
}

/// Its components are constants.
pub(crate) fn rules(g: &Located<Vec<Expr>>, cx: &mut dyn Rules) {
    for c in &g.value {
        cx.expression(c, Depends::Constant, "`gravity`");
    }
}

/// As many components as the points have (`dim`); with no points (unless their section was
/// lost to an error already reported), nothing to act on.
pub(crate) fn dimension_rules(g: &Located<Vec<Expr>>, cx: &mut dyn Rules, dim: Option<usize>) {
    match dim {
        None if !cx.section_incomplete("points") => cx.error(
            Diagnostic::new(
                g.location,
                "`gravity` acts on bodies, but the model has no points",
            )
            .with_help(
                "add `points:` and `bodies:`, or write the gravitational energy into `potential:`",
            ),
        ),
        Some(dim) if g.value.len() != dim => {
            let example = if dim == 2 { "[0, -g]" } else { "[0, 0, -g]" };
            cx.error(
                Diagnostic::new(
                    g.location,
                    format!(
                        "`gravity` has {} components but the points have {dim}",
                        g.value.len()
                    ),
                )
                .with_help(format!("write it like `{example}`")),
            );
        }
        _ => {}
    }
}

/// Its components are in m/s².
pub(crate) fn units(g: &Located<Vec<Expr>>, cx: &mut dyn Units) {
    for (axis, c) in AXES.iter().zip(&g.value) {
        cx.fixed(
            c,
            Dimension::ACCELERATION,
            &format!("the {axis} component of `gravity`"),
            "an acceleration",
            "m/s^2",
            "gravity is the acceleration of free fall, as in `[0, -g]` with `g: 9.81  # m/s^2`",
        );
    }
}

/// The vector as expressions (m/s²), ground-frame components.
pub(crate) fn lower(g: &Located<Vec<Expr>>, cx: &mut dyn Lower) -> Vec<ExprId> {
    g.value.iter().map(|c| cx.expr(c)).collect()
}
