//! Linear springs between two points (`springs:`), lecture 8 and HW23.
//!
//! ```yaml
//! springs:
//!   s1: { between: [A, B], stiffness: k, rest_length: l0 }
//! ```
//!
//! With `d = r_A − r_B`, the spring stores `V = ½ k (|d| − ℓ₀)²` (`½ k |d|²` without a rest
//! length), which Lagrange's equations take from the potential; momentum balance takes its
//! two forces instead, `F_A = k (ℓ₀/|d| − 1) d` (`−k d`) and `F_B = −F_A`. Both come from
//! this module. They are the same spring where `k` and `ℓ₀` are constant; a stiffness that
//! depends on the configuration makes `V`'s gradient differ from that force law, and
//! `eomgen check` reports the two derivations apart.

use super::{Lower, Rules, Units, between, dot};
use crate::expr::{Constant, ExprArena, ExprId};
use crate::model::ast::Expr;
use crate::model::elements::Depends;
use crate::model::located::Located;
use crate::model::schema::entries::get;
use crate::model::schema::walk::{Ctx, Fields, Keyed, Need};
use crate::model::schema::write::{NotRewritten, Writer, flow};
use crate::model::units::Dimension;
use crate::model::yaml::YamlNode;

/// The key of the section.
pub(crate) const KEY: &str = "springs";

/// A linear spring between two points: `{ between: [A, B], stiffness: k, rest_length: l0 }`.
#[derive(Debug, Clone, PartialEq)]
pub struct Spring {
    /// Name.
    pub name: Located<String>,
    /// The two end points.
    pub between: [Located<String>; 2],
    /// Stiffness `k` (N/m).
    pub stiffness: Expr,
    /// Rest length `ℓ₀` (m); `None` means zero rest length.
    pub rest_length: Option<Expr>,
}

/// The keys of a spring.
const FIELDS: Fields = Fields {
    kind: "spring",
    keys: &[
        ("between", Need::Required),
        ("stiffness", Need::Required),
        ("rest_length", Need::Optional),
    ],
    example: "{ between: [A, B], stiffness: k, rest_length: l0 }",
};

/// `springs:` — `name: { between, stiffness, rest_length }`, in file order.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Vec<Spring> {
    let example = format!("springs: {{ s: {} }}", FIELDS.example);
    let spec = Keyed {
        what: "`springs`",
        example: &example,
        names: None,
        drop: false,
    };
    cx.keyed(node, spec, |cx, k, v| {
        let f = cx.fields(k, v, &FIELDS)?;
        let between = get(f, "between").and_then(|n| cx.point_pair(n, "`between`"));
        let stiffness = get(f, "stiffness").and_then(|n| cx.expr(n, "a stiffness"));
        let rest_length = match get(f, "rest_length") {
            Some(n) => cx.expr(n, "a rest length").map(Some),
            None => Some(None),
        };
        Some(Spring {
            name: k.clone(),
            between: between?,
            stiffness: stiffness?,
            rest_length: rest_length?,
        })
    })
}

/// `springs:`, in the form [`read`] reads.
pub(crate) fn write(w: &mut Writer<'_>, springs: &[Spring]) -> Result<(), NotRewritten> {
    if springs.is_empty() {
        return Ok(());
    }
    w.line("springs:");
    for s in springs {
        let place = format!("spring `{}`", s.name.value);
        let k = w.expr(&s.stiffness, &place)?;
        let mut text = format!(
            "  {}: {{ between: [{}, {}], stiffness: {}",
            s.name.value,
            s.between[0].value,
            s.between[1].value,
            flow(&k)
        );
        if let Some(l0) = &s.rest_length {
            let l0 = w.expr(l0, &place)?;
            text.push_str(&format!(", rest_length: {}", flow(&l0)));
        }
        w.line(format_args!("{text} }}"));
    }
    Ok(())
}

/// A spring as expressions of the model's arena.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SpringInfo {
    /// The end points' indices among the model's points.
    pub between: [usize; 2],
    /// `k` (N/m).
    pub stiffness: ExprId,
    /// `ℓ₀` (m); `None` for zero.
    pub rest_length: Option<ExprId>,
    /// Its potential `½ k (|d| − ℓ₀)²` (J).
    pub potential: ExprId,
}

impl Spring {
    /// Its points exist; the stiffness and rest length depend on the configuration and `t`
    /// at most.
    pub(crate) fn rules(&self, cx: &mut dyn Rules) {
        self.between.iter().for_each(|p| cx.point(p));
        let name = &self.name.value;
        cx.expression(
            &self.stiffness,
            Depends::Position,
            &format!("the stiffness of spring `{name}`"),
        );
        if let Some(l) = &self.rest_length {
            cx.expression(
                l,
                Depends::Position,
                &format!("the rest length of spring `{name}`"),
            );
        }
    }

    /// The stiffness is in N/m, the rest length in m.
    pub(crate) fn units(&self, cx: &mut dyn Units) {
        let name = &self.name.value;
        cx.fixed(
            &self.stiffness,
            Dimension::STIFFNESS,
            &format!("the stiffness of spring `{name}`"),
            "a spring stiffness",
            "N/m",
            "a spring pulls with stiffness × stretch, N/m × m = N",
        );
        if let Some(l) = &self.rest_length {
            cx.fixed(
                l,
                Dimension::METRE,
                &format!("the rest length of spring `{name}`"),
                "a length",
                "m",
                "a rest length is the distance between the spring's points when it is relaxed",
            );
        }
    }

    /// The spring as expressions, with its potential; `None` (with the mistake reported) if
    /// it names an unknown point.
    pub(crate) fn lower(&self, cx: &mut dyn Lower) -> Option<SpringInfo> {
        let ([a, b], d) = between(cx, &self.between, &self.name, "spring")?;
        let d2 = dot(cx.arena(), &d, &d);
        let k = cx.expr(&self.stiffness);
        let rest = self.rest_length.as_ref().map(|l| cx.expr(l));
        let arena = cx.arena();
        let stretch2 = match rest {
            None => d2,
            Some(l0) => {
                let len = arena.sqrt(d2);
                let st = arena.minus(len, l0);
                let two = arena.int(2);
                arena.pow(st, two)
            }
        };
        let half = arena.constant(Constant::Rational { num: 1, den: 2 });
        Some(SpringInfo {
            between: [a, b],
            stiffness: k,
            rest_length: rest,
            potential: arena.product(&[half, k, stretch2]),
        })
    }
}

/// The spring's pull on its end `A` per unit of `d = r_A − r_B`: `F_A = s d` with
/// `s = k (ℓ₀/|d| − 1)`, or `−k` without a rest length (`F_B = −F_A`).
pub(crate) fn force_scale(
    arena: &mut ExprArena,
    d: &[ExprId],
    stiffness: ExprId,
    rest_length: Option<ExprId>,
) -> ExprId {
    match rest_length {
        None => arena.neg(stiffness),
        Some(l0) => {
            let d2 = dot(arena, d, d);
            let len = arena.sqrt(d2);
            let ratio = arena.divide(l0, len);
            let one = arena.int(1);
            let s = arena.minus(ratio, one);
            arena.times(stiffness, s)
        }
    }
}
