//! Forces between two points along their line (`interactions:`), lectures 3–7 (central
//! forces and many particles).
//!
//! ```yaml
//! interactions:
//!   gravity: { between: [P1, P2], magnitude: -G*m1*m2/r^2 }
//!   link: { between: [A, B], magnitude: -k*(r - l0) - c*r_dot }
//! ```
//!
//! Equal and opposite forces `f e` on `B` and `−f e` on `A`, `e = (B − A)/r`, `r = |B − A|`:
//! `f > 0` pushes the points apart. The magnitude reads `r` and its rate `r_dot`
//! (`ṙ = e·(v_B − v_A)`) besides the model's names. Lagrange's equations take a magnitude
//! that is a sum of powers of `r` as the potential `V(r) = −∫ f dr`, any other as the
//! generalized forces `Qᵢ = (f/r) d·∂d/∂qᵢ`; momentum balance takes the two forces.

use super::{
    Depends, Lower, Rules, Units, difference, dot, projections, read_between, write_between,
};
use crate::expr::{ExprArena, ExprId, Func, SymbolId, SymbolKind};
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::Located;
use crate::model::parser::identifiers;
use crate::model::schema::walk::{Ctx, Fields, Need};
use crate::model::schema::write::{NotRewritten, Writer};
use crate::model::units::Dimension;
use crate::model::yaml::YamlNode;
use rustc_hash::FxHashMap;

/// The key of the section.
pub(crate) const KEY: &str = "interactions";

/// A force between two points (`interactions:`): `{ between: [A, B], magnitude: f }`, equal
/// and opposite forces along the line of the points, `f e` on `B` and `−f e` on `A` with
/// `e = (B − A)/r` and `r = |B − A|`: `f > 0` pushes the points apart, `f < 0` pulls them
/// together (gravity is `-G*m1*m2/r^2`). The magnitude is any expression of `r`, its rate
/// `r_dot` (`ṙ = e·(v_B − v_A)`), the parameters, coordinates, rates and `t` (lectures 3–7:
/// central forces and many particles).
#[derive(Debug, Clone, PartialEq)]
pub struct Interaction {
    /// Name.
    pub name: Located<String>,
    /// The two points `[A, B]`.
    pub between: [Located<String>; 2],
    /// The magnitude `f` (N), positive apart.
    pub magnitude: Expr,
}

/// The names an interaction's magnitude reads for the distance of its points and its rate.
pub const INTERACTION_NAMES: [&str; 2] = ["r", "r_dot"];

/// The keys of an interaction.
const FIELDS: Fields = Fields {
    kind: "interaction",
    keys: &[("between", Need::Required), ("magnitude", Need::Required)],
    example: "{ between: [P1, P2], magnitude: -G*m1*m2/r^2 }",
};

/// `interactions:` — `name: { between, magnitude }`, in file order.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Vec<Interaction> {
    let what = |name: &str| format!("the magnitude of interaction `{name}`");
    read_between(cx, node, (KEY, &FIELDS, "gravity"), "magnitude", what)
        .into_iter()
        .map(|(name, between, magnitude)| Interaction {
            name,
            between,
            magnitude,
        })
        .collect()
}

/// `interactions:`, in the form [`read`] reads.
pub(crate) fn write(w: &mut Writer<'_>, interactions: &[Interaction]) -> Result<(), NotRewritten> {
    let entries = interactions
        .iter()
        .map(|i| (&i.name, &i.between, &i.magnitude));
    write_between(w, (KEY, "interaction", "magnitude"), entries)
}

/// An interaction as expressions of the model's arena.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct InteractionInfo {
    /// The points' indices `[A, B]` among the model's points.
    pub between: [usize; 2],
    /// The force on `B` (N).
    pub on_b: Vec<ExprId>,
    /// The force on `A` (N), `−` that on `B`.
    pub on_a: Vec<ExprId>,
    /// `r` and `f` as expressions of the state, for the check at the initial state.
    pub at_start: (ExprId, ExprId),
    /// Its potential `V(r)` if the magnitude is a sum of powers of `r`, else its generalized
    /// forces, per coordinate (`None` where 0).
    pub lagrange: InteractionTerms,
}

/// What an interaction gives Lagrange's equations.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum InteractionTerms {
    /// A term of `V` (J).
    Potential(ExprId),
    /// Per coordinate, a term of `Qᵢ` (N or N·m), `None` where it is 0.
    Forces(Vec<Option<ExprId>>),
}

impl Interaction {
    /// Its points exist and differ; `r` and `r_dot` in the magnitude name no other thing of
    /// the model; the magnitude depends on the motion, `t`, `r` and `r_dot` at most.
    pub(crate) fn rules(&self, cx: &mut dyn Rules) {
        let name = &self.name.value;
        self.between.iter().for_each(|p| cx.point(p));
        let [a, b] = &self.between;
        if a.value == b.value {
            cx.error(
                Diagnostic::new(
                    b.location,
                    format!("interaction `{name}` acts between `{}` and itself", a.value),
                )
                .with_help("an interaction acts along the line of two distinct points; name the other point"),
            );
        }
        let what = format!("the magnitude of interaction `{name}`");
        let mut ids = Vec::new();
        identifiers(&self.magnitude, &mut ids);
        for (n, at) in &ids {
            if let Some(kind) = cx.name_kind(n)
                && INTERACTION_NAMES.contains(&n.as_str())
            {
                cx.error(
                    Diagnostic::new(
                        *at,
                        format!("`{n}` in {what} is ambiguous: it names the distance of the points (or its rate), and {kind} of the model"),
                    )
                    .with_help("rename the model's `r`, or write the distance as `distance(A, B)` and its rate as `dot(A - B, vel(A) - vel(B))/distance(A, B)`"),
                );
            }
        }
        cx.expression_of_distance(&self.magnitude, Depends::Motion, &what);
    }

    /// The magnitude is in N (with `r` in m and `r_dot` in m/s).
    pub(crate) fn units(&self, cx: &mut dyn Units) {
        cx.distance(true);
        cx.fixed(
            &self.magnitude,
            Dimension::NEWTON,
            &format!("the magnitude of interaction `{}`", self.name.value),
            "a force",
            "N",
            "an interaction's magnitude is a force, with `r` in m and `r_dot` in m/s",
        );
        cx.distance(false);
    }
}

/// Every interaction of `interactions` as expressions, in order (those naming an unknown point
/// left out, the mistake reported): `r` and `r_dot` stand for two auxiliary symbols while the
/// magnitude is lowered, then for the distance of the points and its rate.
pub(crate) fn lower(cx: &mut dyn Lower, interactions: &[Interaction]) -> Vec<InteractionInfo> {
    let mut out = Vec::new();
    if interactions.is_empty() {
        return out;
    }
    // Names no model symbol can have (a space is not in a name), substituted away below.
    let arena = cx.arena();
    let r_symbol = arena.declare("interaction r", SymbolKind::Auxiliary);
    let rdot_symbol = arena.declare("interaction r_dot", SymbolKind::Auxiliary);
    for it in interactions {
        let (Some(a), Some(b)) = (
            cx.point_index(&it.between[0].value),
            cx.point_index(&it.between[1].value),
        ) else {
            cx.error(Diagnostic::new(
                it.name.location,
                format!("interaction `{}` names an unknown point", it.name.value),
            ));
            continue;
        };
        let (ra, rb) = (cx.point_at(a), cx.point_at(b));
        let d = difference(cx.arena(), &rb, &ra);
        let arena = cx.arena();
        let dd: Vec<ExprId> = d.iter().map(|c| arena.time_derivative(*c)).collect();
        let d2 = dot(arena, &d, &d);
        let r = arena.sqrt(d2);
        let d_dd = dot(arena, &d, &dd);
        let rdot = arena.divide(d_dd, r);
        let locals = [
            ("r", arena.symbol_expr(r_symbol)),
            ("r_dot", arena.symbol_expr(rdot_symbol)),
        ];
        let f_of_r = cx.expr_with(&it.magnitude, &locals);
        let arena = cx.arena();
        let mut values = FxHashMap::default();
        values.insert(r_symbol, r);
        values.insert(rdot_symbol, rdot);
        let f = arena.substitute(f_of_r, &values);
        // f e on B, −f e on A.
        let scale = arena.divide(f, r);
        let on_b: Vec<ExprId> = d.iter().map(|c| arena.times(scale, *c)).collect();
        let on_a: Vec<ExprId> = on_b.iter().map(|c| arena.neg(*c)).collect();
        let lagrange = match power_law_potential(arena, f_of_r, r_symbol, rdot_symbol) {
            Some(v_of_r) => InteractionTerms::Potential(arena.substitute(v_of_r, &values)),
            None => {
                let coordinates: Vec<_> = arena.coordinates().iter().map(|s| s[0]).collect();
                InteractionTerms::Forces(projections(arena, &coordinates, (&d, &d), Some(scale)))
            }
        };
        out.push(InteractionInfo {
            between: [a, b],
            on_b,
            on_a,
            at_start: (r, f),
            lagrange,
        });
    }
    out
}

/// `V(r) = −∫ f dr` of a magnitude `f` that is a sum of terms `c rᵏ`, `k` a number and `c`
/// free of `r`, `ṙ`, the coordinates and the rates: `−c r^(k+1)/(k+1)`, or `−c ln r` for
/// `k = −1`. `None` for any other magnitude (it is not, or not visibly, the derivative of a
/// potential of `r`).
fn power_law_potential(
    arena: &mut ExprArena,
    f: ExprId,
    r_symbol: SymbolId,
    rdot_symbol: SymbolId,
) -> Option<ExprId> {
    use crate::expr::Node;
    if arena.depends_on(f, rdot_symbol) {
        return None;
    }
    let motion: Vec<SymbolId> = (arena.coordinates().iter())
        .flat_map(|c| [c[0], c[1]])
        .collect();
    let f = arena.expand(f);
    let terms: Vec<ExprId> = match arena.node(f) {
        Node::Add(ts) => ts.to_vec(),
        _ => vec![f],
    };
    let mut potential = Vec::new();
    for term in terms {
        let factors: Vec<ExprId> = match arena.node(term) {
            Node::Mul(fs) => fs.to_vec(),
            _ => vec![term],
        };
        let mut power = vec![arena.int(0)];
        let mut coefficient = Vec::new();
        for factor in factors {
            if !arena.depends_on(factor, r_symbol) {
                if motion.iter().any(|s| arena.depends_on(factor, *s)) {
                    return None;
                }
                coefficient.push(factor);
                continue;
            }
            match arena.node(factor).clone() {
                Node::Symbol(s) if s == r_symbol => power.push(arena.int(1)),
                Node::Pow([base, exponent])
                    if matches!(arena.node(base), Node::Symbol(s) if *s == r_symbol)
                        && arena.as_constant(exponent).is_some() =>
                {
                    power.push(exponent);
                }
                _ => return None,
            }
        }
        let c = arena.product(&coefficient);
        let k = arena.sum(&power);
        let one = arena.int(1);
        let k1 = arena.plus(k, one);
        let r = arena.symbol_expr(r_symbol);
        let integral = if arena.is_zero(k1) {
            let ln = arena.func(Func::Ln, r);
            arena.times(c, ln)
        } else {
            let rk1 = arena.pow(r, k1);
            let crk1 = arena.times(c, rk1);
            arena.divide(crk1, k1)
        };
        potential.push(arena.neg(integral));
    }
    Some(arena.sum(&potential))
}
