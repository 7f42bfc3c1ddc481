//! A change of support (`support:` on a contact): a walker's or a rimless wheel's foot that
//! lands, sticks and becomes the new stance foot, while the old one leaves the ground.
//!
//! ```yaml
//! contacts:
//!   heel:
//!     gap: phi - 2*theta
//!     restitution: 0
//!     support: { foot: S, normal: [0, 1], relabel: { theta: -theta, phi: -phi } }
//! ```
//!
//! The model is written in minimal coordinates `q` about its stance foot, which is at the
//! origin, as the walking literature writes it. When the contact strikes, the landing foot
//! `S` takes a plastic impulse and sticks, and the stance foot is released: in the extended
//! coordinates `(p₀, q)` of the mechanism with its stance foot free at `p₀`,
//! `M_e (q̇_e⁺ − q̇_e⁻) = J_Sᵀ Λ` with `J_S q̇_e⁺ = 0` (`J_S = [I, F]`, `F = ∂r_S/∂q`).
//! Written in the speeds `q̇` alone (`p₀` follows from the landing foot held:
//! `ṗ₀⁺ = −F q̇⁺`), the law is `P q̇⁺ = Q q̇⁻` with
//!
//! - `P = M − FᵀK − KᵀF + m FᵀF`, the mass matrix about the landing foot;
//! - `Q = M − FᵀK`, the angular momenta about it, kept;
//!
//! `m` the total mass and `K = ∂(Σ mᵢ rᵢ)/∂q` the Jacobian of the linear momentum. Then the
//! coordinates are relabelled for the new stance foot: `q⁺ = R(q)` as the file writes it,
//! `q̇⁺ = (∂R/∂q) v`. The runtime applies it (`eomgen_runtime::hybrid`), checks the landing
//! impulse pushes (and stays in the friction cone, with `friction:`), the stance foot
//! leaves, and `R` puts the mechanism where it was, and takes the saltation matrix of the
//! gait's return map from the derivatives of `P`, `Q` and `R`, which this module derives.
//!
//! Source: Grizzle, Abba & Plestan, IEEE TAC 46 (2001), §III (the impact model in extended
//! coordinates); Garcia, Chatterjee, Ruina & Coleman, J. Biomech. Eng. 120 (1998), eq. 4
//! (the simplest walker's heel strike); Coleman, Chatterjee & Ruina, Dynamics and Stability
//! of Systems 12 (1997) (the rimless wheel's).

use crate::expr::{ExprArena, ExprId};
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::Located;
use crate::model::schema::entries::get;
use crate::model::schema::walk::{Ctx, Fields, Keyed, Need};
use crate::model::schema::write::{NotRewritten, Writer, flow, list};
use crate::model::yaml::YamlNode;

use super::{Depends, Lower, Rules};

/// `support:` of a contact.
#[derive(Debug, Clone, PartialEq)]
pub struct Support {
    /// Where `support:` is written.
    pub at: crate::model::located::Location,
    /// The landing foot (`foot:`); the contact's point when left out.
    pub foot: Option<Located<String>>,
    /// The ground's normal (`normal:`); the contact's `above:` normal when left out.
    pub normal: Option<Located<Vec<Expr>>>,
    /// The coordinates after the change, by name, as expressions of those before.
    pub relabel: Vec<(Located<String>, Expr)>,
}

/// The keys of `support:`.
const SUPPORT: Fields = Fields {
    kind: "the change of support",
    keys: &[
        ("foot", Need::Optional),
        ("normal", Need::Optional),
        ("relabel", Need::Required),
    ],
    example: "{ foot: S, normal: [0, 1], relabel: { theta: -theta, phi: -phi } }",
};

/// `support:` of the contact `key`.
pub(crate) fn read(cx: &mut Ctx<'_>, key: &Located<String>, node: &YamlNode) -> Option<Support> {
    let f = cx.fields(key, node, &SUPPORT)?;
    let foot = match get(f, "foot") {
        Some(n) => cx.name(n, "the landing foot").map(Some),
        None => Some(None),
    };
    let normal = match get(f, "normal") {
        Some(n) => (cx.vector(n, "a normal", "[0, 1]")).map(|v| Some(Located::new(v, n.location))),
        None => Some(None),
    };
    let relabel = get(f, "relabel").map(|n| {
        let spec = Keyed {
            what: "`relabel`",
            example: "relabel: { theta: -theta, phi: -phi }",
            names: Some("coordinate"),
            drop: false,
        };
        cx.keyed(n, spec, |cx, k, v| {
            Some((k.clone(), cx.expr(v, "a coordinate after the change")?))
        })
    });
    Some(Support {
        at: key.location,
        foot: foot?,
        normal: normal?,
        relabel: relabel?,
    })
}

/// `support: { … }`, the text after `support: ` in the form [`read`] reads.
pub(crate) fn write(w: &mut Writer<'_>, s: &Support, place: &str) -> Result<String, NotRewritten> {
    let mut parts = Vec::new();
    if let Some(foot) = &s.foot {
        parts.push(format!("foot: {}", foot.value));
    }
    if let Some(n) = &s.normal {
        parts.push(format!("normal: {}", list(&w.exprs(&n.value, place)?)));
    }
    let mut relabel = Vec::new();
    for (name, e) in &s.relabel {
        relabel.push(format!("{}: {}", name.value, flow(&w.expr(e, place)?)));
    }
    parts.push(format!("relabel: {{ {} }}", relabel.join(", ")));
    Ok(format!("{{ {} }}", parts.join(", ")))
}

impl Support {
    /// The rules of a change of support on contact `contact`, written as `point` (its point,
    /// if it has one) and `plastic` (whether `restitution` is 0 at the defaults): in the
    /// plane; the landing foot sticks (plastic); a foot and a normal, given or the contact's;
    /// every coordinate relabelled once, by an expression of the configuration.
    pub(crate) fn rules(
        &self,
        cx: &mut dyn Rules,
        contact: &str,
        (point, above): (bool, bool),
        restitution: Option<f64>,
    ) {
        let what = format!("contact `{contact}` changes the support");
        if cx.dimension() != 2 {
            cx.error(
                Diagnostic::new(
                    self.at,
                    format!("{what}, but a change of support is taken in the plane only"),
                )
                .with_help("write the walker in the plane (2-D points)"),
            );
        }
        if let Some(e) = restitution
            && e != 0.0
        {
            cx.error(
                Diagnostic::new(self.at, format!("{what}, but its restitution is {e}: the landing foot sticks, so the impact is plastic"))
                    .with_help("write `restitution: 0`"),
            );
        }
        match &self.foot {
            Some(foot) => cx.point(foot),
            None if !point => cx.error(
                Diagnostic::new(self.at, format!("{what}, but names no foot: its gap is written, not a point's"))
                    .with_help("name the point that lands: `support: { foot: S, normal: [0, 1], relabel: { … } }`"),
            ),
            None => {}
        }
        match &self.normal {
            Some(n) => {
                for c in &n.value {
                    cx.expression(c, Depends::Constant, &format!("the ground's normal of contact `{contact}`"));
                }
                if n.value.len() != 2 {
                    cx.error(Diagnostic::new(n.location, format!("the ground's normal of contact `{contact}` has {} components, but a change of support is in the plane", n.value.len())).with_help("write two components: `normal: [0, 1]`"));
                }
            }
            None if !above => cx.error(
                Diagnostic::new(self.at, format!("{what}, but gives no ground normal: its contact is not above a line"))
                    .with_help("give the ground's normal: `support: { foot: S, normal: [0, 1], relabel: { … } }`"),
            ),
            None => {}
        }
        self.relabel_rules(cx, &what);
    }

    /// Every coordinate once in `relabel`, each by an expression of the configuration.
    fn relabel_rules(&self, cx: &mut dyn Rules, what: &str) {
        let coordinates = cx.coordinates();
        for (i, (name, e)) in self.relabel.iter().enumerate() {
            if !coordinates.contains(&name.value) {
                cx.error(
                    Diagnostic::new(
                        name.location,
                        format!("`{}` in `relabel` is not a coordinate", name.value),
                    )
                    .with_help(format!(
                        "`relabel` gives every coordinate after the change: {}",
                        coordinates.join(", ")
                    )),
                );
            } else if self.relabel[..i].iter().any(|(n, _)| n.value == name.value) {
                cx.error(Diagnostic::new(
                    name.location,
                    format!("coordinate `{}` is relabelled twice", name.value),
                ));
            }
            cx.expression(
                e,
                Depends::Position,
                &format!("coordinate `{}` after the change", name.value),
            );
        }
        let missing: Vec<&String> = (coordinates.iter())
            .filter(|c| !self.relabel.iter().any(|(n, _)| &n.value == *c))
            .collect();
        if !missing.is_empty() {
            let list: Vec<String> = missing.iter().map(|c| format!("`{c}`")).collect();
            cx.error(
                Diagnostic::new(self.at, format!("{what}, but `relabel` does not give {} after it", list.join(", ")))
                    .with_help("give every coordinate after the change as an expression of those before (`theta: -theta`; `x: x` for one that does not change)"),
            );
        }
    }

    /// The change as expressions: the landing foot's position (`foot`, the contact's point
    /// when the file names none), the ground's unit normal (`normal`, likewise) and the
    /// coordinates after it, in coordinate order; `None` with the mistake reported.
    pub(crate) fn lower(
        &self,
        cx: &mut dyn Lower,
        coordinates: &[String],
        (point, normal): (Option<Vec<ExprId>>, Option<Vec<ExprId>>),
    ) -> Option<SupportInfo> {
        let foot = match &self.foot {
            Some(f) => {
                let p = cx.point(&f.value);
                if p.is_none() {
                    cx.error(Diagnostic::new(
                        f.location,
                        format!("the landing foot `{}` is not a point of the model", f.value),
                    ));
                }
                p?
            }
            None => point?,
        };
        let normal = match &self.normal {
            Some(n) => n.value.iter().map(|c| cx.expr(c)).collect(),
            None => normal?,
        };
        let arena = cx.arena();
        let nn = super::dot(arena, &normal, &normal);
        let length = arena.sqrt(nn);
        let normal = normal.iter().map(|&c| arena.divide(c, length)).collect();
        let mut relabel = Vec::with_capacity(coordinates.len());
        for c in coordinates {
            let (_, e) = self.relabel.iter().find(|(n, _)| &n.value == c)?;
            relabel.push(cx.expr(e));
        }
        Some(SupportInfo {
            foot,
            normal,
            relabel,
            block: Vec::new(),
        })
    }
}

/// A change of support as expressions of the model's arena.
#[derive(Debug, Clone, PartialEq)]
pub struct SupportInfo {
    /// The landing foot's position `r_S(q)` (m, 2 components, the stance foot at the origin).
    pub foot: Vec<ExprId>,
    /// The ground's unit normal `n̂` (2 components).
    pub normal: Vec<ExprId>,
    /// The coordinates after the change, `R(q)`, one per coordinate.
    pub relabel: Vec<ExprId>,
    /// What the runtime evaluates ([`block`]); empty until the model's masses are lowered.
    pub block: Vec<ExprId>,
}

/// The number of values in one change of support's [`block`], for `n` coordinates.
pub fn block_len(n: usize) -> usize {
    7 + 5 * n + 3 * n * n + 3 * n * n * n
}

/// The values the runtime needs at a change of support, of the mechanism whose masses are
/// `masses` (mass, position) and whose kinetic energy is `kinetic`, in this order (`n`
/// coordinates; matrices row-major; `∂X/∂q` as `n` matrices, one per `q_k`):
///
/// | values | count |
/// |---|---|
/// | `m`, the total mass (kg) | 1 |
/// | `n̂` | 2 |
/// | `Σ mᵢ rᵢ` (kg·m) | 2 |
/// | `r_S` (m) | 2 |
/// | `K = ∂(Σ mᵢ rᵢ)/∂q` | 2n |
/// | `F = ∂r_S/∂q` | 2n |
/// | `P = M − FᵀK − KᵀF + m FᵀF` | n² |
/// | `Q = M − FᵀK` | n² |
/// | `∂P/∂q_k`, `∂Q/∂q_k` | n³ each |
/// | `R(q)` | n |
/// | `∂R/∂q` | n² |
/// | `∂²R/∂q_k∂q` | n³ |
pub(crate) fn block(
    arena: &mut ExprArena,
    s: &SupportInfo,
    masses: &[(ExprId, Vec<ExprId>)],
    kinetic: ExprId,
) -> Vec<ExprId> {
    let symbols = arena.coordinates().to_vec();
    let q: Vec<_> = symbols.iter().map(|s| s[0]).collect();
    let n = q.len();
    let mass_terms: Vec<ExprId> = masses.iter().map(|(m, _)| *m).collect();
    let m = arena.sum(&mass_terms);
    let moment: Vec<ExprId> = (0..2)
        .map(|a| {
            let terms: Vec<ExprId> = (masses.iter())
                .map(|(mi, r)| arena.times(*mi, r[a]))
                .collect();
            arena.sum(&terms)
        })
        .collect();
    let jacobian = |arena: &mut ExprArena, v: &[ExprId]| -> Vec<ExprId> {
        (v.iter())
            .flat_map(|&e| q.iter().map(|&qj| (e, qj)).collect::<Vec<_>>())
            .map(|(e, qj)| arena.diff(e, qj))
            .collect()
    };
    let k = jacobian(arena, &moment);
    let f = jacobian(arena, &s.foot);
    let mut mass = Vec::with_capacity(n * n);
    for si in &symbols {
        let ti = arena.diff(kinetic, si[1]);
        for sj in &symbols {
            mass.push(arena.diff(ti, sj[1]));
        }
    }
    // `(Aᵀ B)_ij = Σ_a A_ai B_aj` over the two components.
    let ta_b = |arena: &mut ExprArena, a: &[ExprId], b: &[ExprId], i: usize, j: usize| {
        let terms = [arena.times(a[i], b[j]), arena.times(a[n + i], b[n + j])];
        arena.sum(&terms)
    };
    let (mut p, mut qm) = (Vec::with_capacity(n * n), Vec::with_capacity(n * n));
    for i in 0..n {
        for j in 0..n {
            let fk = ta_b(arena, &f, &k, i, j);
            let kf = ta_b(arena, &k, &f, i, j);
            let ff = ta_b(arena, &f, &f, i, j);
            let mff = arena.times(m, ff);
            let minus_fk = arena.neg(fk);
            let minus_kf = arena.neg(kf);
            p.push(arena.sum(&[mass[i * n + j], minus_fk, minus_kf, mff]));
            qm.push(arena.sum(&[mass[i * n + j], minus_fk]));
        }
    }
    let derivatives = |arena: &mut ExprArena, x: &[ExprId]| -> Vec<ExprId> {
        (q.iter())
            .flat_map(|&qk| x.iter().map(move |&e| (e, qk)).collect::<Vec<_>>())
            .map(|(e, qk)| arena.diff(e, qk))
            .collect()
    };
    let dp = derivatives(arena, &p);
    let dq = derivatives(arena, &qm);
    let rq = jacobian(arena, &s.relabel);
    let drq = derivatives(arena, &rq);
    let mut out = vec![m];
    for part in [
        &s.normal[..],
        &moment,
        &s.foot,
        &k,
        &f,
        &p,
        &qm,
        &dp,
        &dq,
        &s.relabel,
        &rq,
        &drq,
    ] {
        out.extend_from_slice(part);
    }
    debug_assert_eq!(out.len(), block_len(n));
    out
}
