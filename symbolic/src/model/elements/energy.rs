//! The energy form (`kinetic:`, `potential:`, `generalized_forces:`), lectures 9–10: the
//! kinetic energy `T(q, q̇, t)`, the potential energy `V(q, t)` and the generalized forces
//! `Qᵢ(q, q̇, t)` written as expressions, for Lagrange's equations
//! `d/dt ∂T/∂q̇ᵢ − ∂T/∂qᵢ + ∂V/∂qᵢ = Qᵢ`.
//!
//! ```yaml
//! kinetic: m*x_dot^2/2
//! potential: k*x^2/2
//! generalized_forces: { x: -c*x_dot }
//! ```
//!
//! They add to what the kinematic form (points and bodies) gives. Momentum balance, which
//! derives its equations from the kinematics, takes the written potential and forces as they
//! are (`SymbolicModel::written_potential`, `written_forces`).

use super::{Depends, Lower, Rules, Units};
use crate::expr::ExprId;
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::Located;
use crate::model::schema::walk::Ctx;
use crate::model::schema::write::{NotRewritten, Writer, scalar};
use crate::model::units::Dimension;
use crate::model::yaml::YamlNode;

/// The key of the kinetic energy.
pub(crate) const KINETIC: &str = "kinetic";
/// The key of the potential energy.
pub(crate) const POTENTIAL: &str = "potential";
/// The key of the generalized forces.
pub(crate) const GENERALIZED_FORCES: &str = "generalized_forces";

/// The generalized forces as written: by coordinate name, in file order.
pub type GeneralizedForces = Vec<(Located<String>, Expr)>;

/// The three sections as a model file holds them: `T`, `V` and the `Qᵢ`
/// (`ModelFile::written_energies`).
pub type Written<'f> = (
    Option<&'f Expr>,
    Option<&'f Expr>,
    &'f [(Located<String>, Expr)],
);

/// `kinetic: T` or `potential: V`, an expression (`key` one of [`KINETIC`], [`POTENTIAL`]).
pub(crate) fn read_energy(cx: &mut Ctx<'_>, node: &YamlNode, key: &str) -> Option<Expr> {
    cx.expr(node, &format!("`{key}`"))
}

/// `generalized_forces: { q: Q, … }`.
pub(crate) fn read_generalized_forces(cx: &mut Ctx<'_>, node: &YamlNode) -> GeneralizedForces {
    cx.keyed_exprs(
        node,
        "`generalized_forces`",
        "generalized_forces: { x: -c*x_dot }",
        "a generalized force",
    )
}

/// `kinetic:` or `potential:` (`key`), in the form [`read_energy`] reads.
pub(crate) fn write_energy(
    w: &mut Writer<'_>,
    key: &str,
    energy: Option<&Expr>,
) -> Result<(), NotRewritten> {
    if let Some(e) = energy {
        let e = w.expr(e, &format!("`{key}:`"))?;
        w.line(format_args!("{key}: {}", scalar(&e)));
    }
    Ok(())
}

/// `generalized_forces:`, as a transformer gives them, else each rewritten.
pub(crate) fn write_generalized_forces(
    w: &mut Writer<'_>,
    written: &[(Located<String>, Expr)],
) -> Result<(), NotRewritten> {
    if written.is_empty() {
        return Ok(());
    }
    let forces = match w.rewritten_generalized_forces()? {
        Some(forces) => forces,
        None => {
            let mut forces = Vec::new();
            for (name, e) in written {
                let place = format!("generalized force `{}`", name.value);
                forces.push((name.value.clone(), w.expr(e, &place)?));
            }
            forces
        }
    };
    if !forces.is_empty() {
        w.line("generalized_forces:");
        for (k, q) in forces {
            w.line(format_args!("  {k}: {}", scalar(&q)));
        }
    }
    Ok(())
}

/// `T` and each `Q` may depend on the motion, `V` on the configuration only.
pub(crate) fn rules((kinetic, potential, forces): Written<'_>, cx: &mut dyn Rules) {
    if let Some(k) = kinetic {
        cx.expression(k, Depends::Motion, "`kinetic`");
    }
    if let Some(v) = potential {
        cx.expression(v, Depends::Position, "`potential`");
    }
    for (k, q) in forces {
        cx.expression(
            q,
            Depends::Motion,
            &format!("the generalized force `{}`", k.value),
        );
    }
}

/// `T` and `V` are energies (J); each `Qᵢ` is J per unit of its coordinate.
pub(crate) fn units((kinetic, potential, forces): Written<'_>, cx: &mut dyn Units) {
    if let Some(k) = kinetic {
        cx.fixed(
            k,
            Dimension::JOULE,
            "`kinetic`",
            "an energy",
            "J",
            "kinetic energy is mass × speed² / 2, kg*(m/s)^2 = J: check the powers of the rates and the units of the parameters",
        );
    }
    if let Some(v) = potential {
        cx.fixed(
            v,
            Dimension::JOULE,
            "`potential`",
            "an energy",
            "J",
            "potential energy is force × length, N*m = J, as in `m*g*h` or `k*x^2/2`",
        );
    }
    for (k, q) in forces {
        cx.generalized_force(k, q);
    }
}

/// The written energies lowered: their terms of `T`, `V` and the `Qᵢ`.
pub(crate) struct WrittenEnergies {
    /// `T` (J), if written.
    pub(crate) kinetic: Option<ExprId>,
    /// `V` (J), if written.
    pub(crate) potential: Option<ExprId>,
    /// Each generalized force with its coordinate's index, in file order.
    pub(crate) forces: Vec<(usize, ExprId)>,
}

/// `T`, `V` and the `Qᵢ`, lowered in that order; a force keyed by a name that is not a
/// coordinate is reported (the rules reject it first) and left out.
pub(crate) fn lower(
    (kinetic, potential, forces): Written<'_>,
    coordinate_names: &[String],
    cx: &mut dyn Lower,
) -> WrittenEnergies {
    let kinetic = kinetic.map(|k| cx.expr(k));
    let potential = potential.map(|v| cx.expr(v));
    let mut lowered = Vec::new();
    for (name, q) in forces {
        let e = cx.expr(q);
        match coordinate_names.iter().position(|c| *c == name.value) {
            Some(i) => lowered.push((i, e)),
            None => cx.error(Diagnostic::new(
                name.location,
                format!("`{}` is not a coordinate", name.value),
            )),
        }
    }
    WrittenEnergies {
        kinetic,
        potential,
        forces: lowered,
    }
}
