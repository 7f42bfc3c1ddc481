//! Generalized speeds (`speeds:`), Kane's way (T. R. Kane, D. A. Levinson, *Dynamics: Theory
//! and Applications*, McGraw-Hill, 1985, §2.12 and ch. 6).
//!
//! ```yaml
//! speeds:                # one per coordinate, each linear in the rates
//!   w1: omega_B_x        # rad/s, the body's angular velocity in its own axes
//!   w2: omega_B_y
//!   w3: omega_B_z
//! ```
//!
//! Each speed is `uᵣ = Σⱼ Yᵣⱼ(q, t) q̇ⱼ + Zᵣ(q, t)`. The state is then `(q, u)`: the kinematic
//! equations `q̇ = W (u − Z)`, `W = Y⁻¹`, give the rates, and the equations of motion are
//! Kane's `M(q, t) u̇ = F(q, u, t)`, projected on the partial velocities `∂v/∂uᵣ` and partial
//! angular velocities `∂ω/∂uᵣ`. With the body-fixed components of `ω` as speeds, a free
//! rigid body's equations are Euler's.

use super::{Depends, Rules};
use crate::model::ast::Expr;
use crate::model::located::Located;
use crate::model::schema::walk::{Ctx, Keyed};
use crate::model::schema::write::{NotRewritten, Writer, scalar};
use crate::model::yaml::YamlNode;

/// The key of the section.
pub(crate) const KEY: &str = "speeds";

/// A generalized speed: `w1: omega_B_x` (its definition, linear in the rates).
#[derive(Debug, Clone, PartialEq)]
pub struct Speed {
    /// Its name: the state's entry, the symbol in the equations (`w1`; its rate `w1_dot`).
    pub name: Located<String>,
    /// `uᵣ` in the coordinates, the rates and `t`, linear in the rates.
    pub value: Expr,
}

/// `speeds:` — `name: expr`, in file order.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Vec<Speed> {
    let spec = Keyed {
        what: "`speeds`",
        example: "speeds: { w1: omega_B_x, w2: omega_B_y, w3: omega_B_z }",
        names: Some("speed"),
        drop: false,
    };
    cx.keyed(node, spec, |cx, k, v| {
        let value = cx.expr(v, &format!("speed `{}`", k.value))?;
        Some(Speed {
            name: k.clone(),
            value,
        })
    })
}

/// `speeds:`, in the form [`read`] reads.
pub(crate) fn write(w: &mut Writer<'_>, speeds: &[Speed]) -> Result<(), NotRewritten> {
    if speeds.is_empty() {
        return Ok(());
    }
    w.line("speeds:");
    for s in speeds {
        let value = w.expr(&s.value, &format!("speed `{}`", s.name.value))?;
        w.line(format_args!("  {}: {}", s.name.value, scalar(&value)));
    }
    Ok(())
}

impl Speed {
    /// Its definition may use parameters, coordinates, rates, `t` and angular velocities
    /// (whether it is linear in the rates is checked where it is lowered).
    pub(crate) fn rules(&self, cx: &mut dyn Rules) {
        cx.expression(
            &self.value,
            Depends::Motion,
            &format!("speed `{}`", self.name.value),
        );
    }
}
