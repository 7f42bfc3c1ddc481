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
//! `M_e (q̇_e⁺ − q̇_e⁻) = J_Sᵀ Λ` with `S` held after it (`J_S = [I, ∂r_S/∂q]`). The
//! coordinates are then relabelled for the new stance foot, `q⁺ = R(q)` as the file writes
//! it. Projected on the motions that keep `S` (which eliminates `Λ`) and written in the new
//! coordinates, the law is
//!
//! `M(q⁺) q̇⁺ = H(q) q̇⁻`, `H = Σ mᵢ Jᵢ(q⁺)ᵀ Jᵢ(q) + Iᵢ aᵢ(q⁺)ᵀ aᵢ(q)`:
//!
//! the momenta of every mass about the new foot are kept (`Jᵢ = ∂rᵢ/∂q` of a centre,
//! `aᵢ = ∂θᵢ/∂q` of a body's angle; `Jᵢ(q⁺)` is `∂(rᵢ − r_S)/∂q⁺` where `R` puts the mechanism
//! where it was). For the rimless wheel it is the angular momentum about the new foot,
//! `ω⁺ = cos 2α ω⁻`. The runtime applies it (`eomgen_runtime::hybrid::support`), checks the
//! landing impulse pushes (and stays in the friction cone, with `friction:`), the stance foot
//! leaves, and `R` puts the mechanism where it was, and takes the saltation matrix of the
//! gait's return map from the derivatives of `M(q⁺)` and `H`, which this module derives.
//!
//! Source: Grizzle, Abba & Plestan, IEEE TAC 46 (2001), §III (the impact model in extended
//! coordinates); Garcia, Chatterjee, Ruina & Coleman, J. Biomech. Eng. 120 (1998), eq. 4
//! (the simplest walker's heel strike); Coleman, Chatterjee & Ruina, Dynamics and Stability
//! of Systems 12 (1997) (the rimless wheel's).

use crate::expr::{ExprArena, ExprId, SymbolId};
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::Located;
use crate::model::schema::entries::get;
use crate::model::schema::walk::{Ctx, Fields, Keyed, Need};
use crate::model::schema::write::{NotRewritten, Writer, flow, list};
use crate::model::yaml::YamlNode;
use rustc_hash::FxHashMap;

use super::{Depends, Lower, Rules};

/// `support:` of a contact.
#[derive(Debug, Clone, PartialEq)]
pub struct Support {
    /// Where the value of `support:` is written.
    pub at: crate::model::located::Location,
    /// The landing foot (`foot:`); the contact's point when left out.
    pub foot: Option<Located<String>>,
    /// The ground's normal (`normal:`); the contact's `above:` normal when left out.
    pub normal: Option<Located<Vec<Expr>>>,
    /// The coordinates after the change, by name, as expressions of those before.
    pub relabel: Vec<(Located<String>, Expr)>,
    /// Where a strike lands (`when:`, a function of the configuration): only where it is
    /// positive; elsewhere the foot passes (the simplest walker's scuffing at mid-stance).
    /// `None`: everywhere.
    pub when: Option<Expr>,
}

/// The keys of `support:`.
const SUPPORT: Fields = Fields {
    kind: "the change of support",
    keys: &[
        ("foot", Need::Optional),
        ("normal", Need::Optional),
        ("relabel", Need::Required),
        ("when", Need::Optional),
    ],
    example: "{ foot: S, normal: [0, 1], relabel: { theta: -theta, phi: -phi } }",
};

/// `support:` of the contact `key` (`node` its value).
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
    let when = match get(f, "when") {
        Some(n) => cx.expr(n, "where the foot lands").map(Some),
        None => Some(None),
    };
    Some(Support {
        at: node.location,
        foot: foot?,
        normal: normal?,
        relabel: relabel?,
        when: when?,
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
    if let Some(when) = &s.when {
        parts.push(format!("when: {}", flow(&w.expr(when, place)?)));
    }
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
        if cx.dimension().unwrap_or(2) != 2 {
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
        if let Some(when) = &self.when {
            cx.expression(
                when,
                Depends::Position,
                &format!("where contact `{contact}` lands"),
            );
        }
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
        let when = match &self.when {
            Some(w) => cx.expr(w),
            None => cx.arena().int(1),
        };
        Some(SupportInfo {
            foot,
            normal,
            relabel,
            when,
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
    /// Positive where a strike lands (1 when the file gives no `when:`).
    pub when: ExprId,
    /// What the runtime evaluates (its number: [`block_len`]); empty until the
    /// model's masses are lowered.
    pub block: Vec<ExprId>,
}

/// The number of values in one change of support's block (the values the model's
/// `support_changes` writes, in the order of `block`), for `n` coordinates.
pub fn block_len(n: usize) -> usize {
    10 + 7 * n + 3 * n * n + 2 * n * n * n
}

/// A mass of the mechanism as [`block`] reads it: its mass, its centre's position, and for a
/// planar rigid body its centroidal inertia and angle.
pub(crate) type Mass = (ExprId, Vec<ExprId>, Option<(ExprId, ExprId)>);

/// The values the runtime needs at a change of support of the mechanism made of `masses`, in
/// this order (`n` coordinates; matrices row-major; `∂X/∂q` as `n` matrices, one per `q_k`;
/// `q⁺ = R(q) = A q + c`), or `None` where `R` is not affine or `A` is singular:
///
/// | values | count |
/// |---|---|
/// | `m`, the total mass (kg) | 1 |
/// | `n̂` | 2 |
/// | `Σ mᵢ rᵢ` at `q` and at `q⁺` (kg·m) | 2 + 2 |
/// | `r_S` (m) | 2 |
/// | `K = ∂(Σ mᵢ rᵢ)/∂q` | 2n |
/// | `K⁺ = Σ mᵢ Gᵢ`, the momentum about `S` in the new speeds | 2n |
/// | `F = ∂r_S/∂q` | 2n |
/// | `M⁺ = Σ wᵢ Gᵢᵀ Gᵢ`, the mass matrix after the change | n² |
/// | `H = Σ wᵢ Gᵢᵀ Jᵢ` | n² |
/// | `∂H/∂q_k`, `∂M⁺/∂q_k` | n³ each |
/// | `R(q)` | n |
/// | `A = ∂R/∂q` | n² |
/// | `when`, positive where a strike lands | 1 |
///
/// Each mass gives rows: its centre's two, `Jᵢ = ∂rᵢ/∂q` with `Gᵢ = ∂(rᵢ − r_S)/∂q⁺`
/// (weight `mᵢ`), and a rigid body's angle, `Jᵢ = ∂θᵢ/∂q`, `Gᵢ = ∂θᵢ/∂q⁺` (weight `Iᵢ`),
/// each `Gᵢ` differentiated in the new coordinates (`q = A⁻¹ (q⁺ − c)`) and evaluated at
/// `q⁺ = R(q)`.
/// The law after a plastic landing that keeps the new foot and frees the old is
/// `M⁺ q̇⁺ = H q̇⁻`: the momenta of every mass about the new foot, in the new coordinates.
/// Written there, each relative position `rᵢ − r_S` is differentiated in the new coordinates
/// before anything is summed, so a foot of small mass `β` keeps a row of order `β` of its own
/// (the limit of massless legs), where the same law in the old coordinates would take it from
/// a difference of order 1 and lose `ε/β` of it.
pub(crate) fn block(
    arena: &mut ExprArena,
    s: &SupportInfo,
    masses: &[Mass],
) -> Option<Vec<ExprId>> {
    let q: Vec<_> = arena.coordinates().iter().map(|s| s[0]).collect();
    let n = q.len();
    let a = jacobian(arena, &q, &s.relabel);
    if derivatives(arena, &q, &a)
        .iter()
        .any(|&e| !arena.is_zero(e))
    {
        return None;
    }
    let inverse = inverse(arena, &a, n)?;
    let mass_terms: Vec<ExprId> = masses.iter().map(|(m, ..)| *m).collect();
    let m = arena.sum(&mass_terms);
    let moment: Vec<ExprId> = (0..2)
        .map(|c| {
            let terms: Vec<ExprId> = (masses.iter())
                .map(|(mi, r, _)| arena.times(*mi, r[c]))
                .collect();
            arena.sum(&terms)
        })
        .collect();
    let relabelled: FxHashMap<_, _> = q.iter().copied().zip(s.relabel.iter().copied()).collect();
    let moment_after: Vec<ExprId> = (moment.iter())
        .map(|&e| arena.substitute(e, &relabelled))
        .collect();
    let k = jacobian(arena, &q, &moment);
    let f = jacobian(arena, &q, &s.foot);
    let back = old_in_new(arena, s, &q, &inverse);
    let new = NewCoordinates {
        q: &q,
        back: &back,
        relabelled: &relabelled,
    };
    let (rows, k_after) = impact_rows(arena, s, masses, &new);
    let (mass_after, h) = impact_matrices(arena, &rows, n);
    let dh = derivatives(arena, &q, &h);
    let dm = derivatives(arena, &q, &mass_after);
    let mut out = vec![m];
    for part in [
        &s.normal[..],
        &moment,
        &moment_after,
        &s.foot,
        &k,
        &k_after,
        &f,
        &mass_after,
        &h,
        &dh,
        &dm,
        &s.relabel,
        &a,
    ] {
        out.extend_from_slice(part);
    }
    out.push(s.when);
    debug_assert_eq!(out.len(), block_len(n));
    Some(out)
}

/// `∂vᵢ/∂qⱼ`, row-major (`i` the row).
fn jacobian(arena: &mut ExprArena, q: &[SymbolId], v: &[ExprId]) -> Vec<ExprId> {
    (v.iter())
        .flat_map(|&e| q.iter().map(move |&qj| (e, qj)))
        .collect::<Vec<_>>()
        .into_iter()
        .map(|(e, qj)| arena.diff(e, qj))
        .collect()
}

/// `∂x/∂q_k` for each `k` in turn, each a copy of `x`'s layout.
fn derivatives(arena: &mut ExprArena, q: &[SymbolId], x: &[ExprId]) -> Vec<ExprId> {
    (q.iter())
        .flat_map(|&qk| x.iter().map(move |&e| (e, qk)))
        .collect::<Vec<_>>()
        .into_iter()
        .map(|(e, qk)| arena.diff(e, qk))
        .collect()
}

/// The old coordinates written in the new ones, `q = A⁻¹ (q⁺ − c)` with `c = R(0)`, as a
/// substitution of each `qᵢ` (`inverse` is `A⁻¹`, row-major).
fn old_in_new(
    arena: &mut ExprArena,
    s: &SupportInfo,
    q: &[SymbolId],
    inverse: &[ExprId],
) -> FxHashMap<SymbolId, ExprId> {
    let n = q.len();
    let zero: FxHashMap<_, _> = q.iter().map(|&qi| (qi, arena.int(0))).collect();
    let offset: Vec<ExprId> = (s.relabel.iter())
        .map(|&r| arena.substitute(r, &zero))
        .collect();
    (0..n)
        .map(|i| {
            let terms: Vec<ExprId> = (0..n)
                .map(|j| {
                    let qj = arena.symbol_expr(q[j]);
                    let shifted = arena.minus(qj, offset[j]);
                    arena.times(inverse[i * n + j], shifted)
                })
                .collect();
            (q[i], arena.sum(&terms))
        })
        .collect()
}

/// The new coordinates of a change of support, for [`NewCoordinates::jacobian`].
struct NewCoordinates<'a> {
    /// The old coordinates.
    q: &'a [SymbolId],
    /// Each old coordinate written in the new ones ([`old_in_new`]).
    back: &'a FxHashMap<SymbolId, ExprId>,
    /// Each old coordinate's relabelled value `R(q)`.
    relabelled: &'a FxHashMap<SymbolId, ExprId>,
}

impl NewCoordinates<'_> {
    /// `G = ∂x/∂q⁺` at `q⁺ = R(q)` of a quantity `x(q)`: `x` written in the new coordinates,
    /// differentiated there, then evaluated at `R(q)`. A part of the mechanism that the new
    /// coordinates do not move (a walker's hip under the new swing leg's angle) then has its
    /// entry exactly 0, not a difference that rounds to 0.
    fn jacobian(&self, arena: &mut ExprArena, x: ExprId) -> Vec<ExprId> {
        let written = arena.substitute(x, self.back);
        let g = jacobian(arena, self.q, &[written]);
        g.iter()
            .map(|&e| arena.substitute(e, self.relabelled))
            .collect()
    }
}

/// A row of the impact law: a mass (or a planar body's inertia), the Jacobian of its
/// coordinate (a position component or the angle) in the old coordinates, and `G` of its
/// position relative to the new foot (or of its angle) in the new ones.
type ImpactRow = (ExprId, Vec<ExprId>, Vec<ExprId>);

/// The impact law's rows, mass by mass, and `K⁺ = Σ mᵢ Gᵢ` (two rows of `n`, row-major).
fn impact_rows(
    arena: &mut ExprArena,
    s: &SupportInfo,
    masses: &[Mass],
    new: &NewCoordinates<'_>,
) -> (Vec<ImpactRow>, Vec<ExprId>) {
    let n = new.q.len();
    let mut rows: Vec<ImpactRow> = Vec::new();
    let mut k_after = vec![Vec::new(); 2];
    for (mi, r, rotation) in masses {
        for c in 0..2 {
            let relative = arena.minus(r[c], s.foot[c]);
            let g = new.jacobian(arena, relative);
            k_after[c].push((*mi, g.clone()));
            rows.push((*mi, jacobian(arena, new.q, &[r[c]]), g));
        }
        if let Some((inertia, angle)) = rotation {
            let j = jacobian(arena, new.q, &[*angle]);
            let g = new.jacobian(arena, *angle);
            rows.push((*inertia, j, g));
        }
    }
    let k_after: Vec<ExprId> = (k_after.iter())
        .flat_map(|parts| {
            (0..n)
                .map(|j| parts.iter().map(|(mi, g)| (*mi, g[j])).collect::<Vec<_>>())
                .collect::<Vec<_>>()
        })
        .map(|terms| {
            let products: Vec<ExprId> = terms.iter().map(|(mi, g)| arena.times(*mi, *g)).collect();
            arena.sum(&products)
        })
        .collect();
    (rows, k_after)
}

/// `M⁺ = Σ w GᵀG` and `H = Σ w GᵀJ` over the rows, each `n × n` row-major.
fn impact_matrices(
    arena: &mut ExprArena,
    rows: &[ImpactRow],
    n: usize,
) -> (Vec<ExprId>, Vec<ExprId>) {
    let (mut mass_after, mut h) = (Vec::with_capacity(n * n), Vec::with_capacity(n * n));
    for i in 0..n {
        for j in 0..n {
            let (mut mm, mut hh) = (Vec::new(), Vec::new());
            for (w, jr, g) in rows {
                let gg = arena.times(g[i], g[j]);
                mm.push(arena.times(*w, gg));
                let gj = arena.times(g[i], jr[j]);
                hh.push(arena.times(*w, gj));
            }
            mass_after.push(arena.sum(&mm));
            h.push(arena.sum(&hh));
        }
    }
    (mass_after, h)
}

/// The inverse of the `n × n` matrix `a` (row-major) of constant expressions, by Gauss–Jordan
/// elimination on the expressions (each pivot the first entry of its column that is not
/// identically 0); `None` if it is singular.
fn inverse(arena: &mut ExprArena, a: &[ExprId], n: usize) -> Option<Vec<ExprId>> {
    let mut m: Vec<Vec<ExprId>> = (0..n)
        .map(|i| {
            let mut row = a[i * n..(i + 1) * n].to_vec();
            row.extend((0..n).map(|j| arena.int(i64::from(i == j))));
            row
        })
        .collect();
    for c in 0..n {
        let p = (c..n).find(|&r| !arena.is_zero(m[r][c]))?;
        m.swap(c, p);
        let pivot = m[c][c];
        let row: Vec<ExprId> = m[c].iter().map(|&e| arena.divide(e, pivot)).collect();
        for r in (0..n).filter(|&r| r != c) {
            let factor = m[r][c];
            if arena.is_zero(factor) {
                continue;
            }
            for (e, &p) in m[r].iter_mut().zip(&row) {
                let t = arena.times(factor, p);
                *e = arena.minus(*e, t);
            }
        }
        m[c] = row;
    }
    Some(m.into_iter().flat_map(|row| row[n..].to_vec()).collect())
}
