//! Unilateral contacts (`contacts:`): a gap `g(q, t) ≥ 0` that may close with an impact and
//! open again, with Newton's coefficient of restitution and optionally Coulomb's friction.
//!
//! ```yaml
//! contacts:
//!   floor: { gap: y, restitution: e }
//!   foot:  { point: F, above: { normal: [0, 1], through: [0, 0] }, restitution: 0, friction: mu }
//!   rim:   { point: B, inside: { centre: [0, 0], radius: R }, restitution: 1 }
//! ```
//!
//! The gap is written directly, or as a point of the model above a line (a plane in 3-D),
//! `g = n̂·(P − O)`, or inside or outside a circle (a sphere in 3-D), `g = R − |P − C|` or
//! `|P − C| − R`. While `g > 0` the contact is open; it closes with an impact when `g`
//! reaches 0 with `ġ < 0`. The impact law is `eomgen_runtime::hybrid::impact`'s (Newton's
//! restitution on the striking contact, Routh's process with friction).
//!
//! Source: Pfeiffer & Glocker, *Multibody Dynamics with Unilateral Contacts* (1996), ch. 4;
//! Brogliato, *Nonsmooth Mechanics* (3rd ed., 2016), §4.1 for the gap and its Jacobian.

use crate::expr::ExprId;
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::elements::support::{Support, SupportInfo};
use crate::model::elements::{Depends, Lower, Rules, Units};
use crate::model::located::Located;
use crate::model::schema::entries::get;
use crate::model::schema::walk::{Ctx, Fields, Keyed, Need};
use crate::model::schema::write::{NotRewritten, Writer, flow, list};
use crate::model::units::Dimension;
use crate::model::yaml::YamlNode;

mod gap;
use gap::read_gap;
pub use gap::{Disc, Gap};

/// The key of the section.
pub(crate) const KEY: &str = "contacts";

/// A unilateral contact: `name: { gap: g, restitution: e, friction: mu }`, or with
/// `point: P` and `above:`, `inside:` or `outside:` in place of `gap:`.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// Name.
    pub name: Located<String>,
    /// The gap `g(q, t)` (m), `≥ 0` while the contact is open.
    pub gap: Gap,
    /// Newton's coefficient of restitution `e ∈ [0, 1]` (1: elastic, 0: plastic), constant.
    pub restitution: Expr,
    /// Coulomb's friction coefficient `μ ≥ 0`, constant; `None`: frictionless.
    pub friction: Option<Expr>,
    /// The static coefficient `μ_s ≥ μ` (`static_friction:`): a sticking contact holds while
    /// `|λ_T| ≤ μ_s λ_N`, and slides with `μ`; `None`: `μ_s = μ`.
    pub static_friction: Option<Expr>,
    /// A change of support where it strikes (`support:`, [`super::support`]); `None`: an
    /// impact by Newton's law.
    pub support: Option<Support>,
}

/// The keys of a contact.
const CONTACT: Fields = Fields {
    kind: "contact",
    keys: &[
        ("gap", Need::Optional),
        ("point", Need::Optional),
        ("disc", Need::Optional),
        ("above", Need::Optional),
        ("inside", Need::Optional),
        ("outside", Need::Optional),
        ("restitution", Need::Required),
        ("friction", Need::Optional),
        ("static_friction", Need::Optional),
        ("support", Need::Optional),
    ],
    example: "{ gap: y, restitution: e, friction: mu }",
};

/// `contacts:`, in file order.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Vec<Contact> {
    let example = format!("contacts: {{ floor: {} }}", CONTACT.example);
    let spec = Keyed {
        what: "`contacts`",
        example: &example,
        names: Some("contact"),
        drop: false,
    };
    cx.keyed(node, spec, |cx, k, v| {
        let f = cx.fields(k, v, &CONTACT)?;
        let what = format!("contact `{}`", k.value);
        let gap = read_gap(cx, k, f, &what);
        let restitution =
            get(f, "restitution").and_then(|n| cx.expr(n, "a coefficient of restitution"));
        let friction = match get(f, "friction") {
            Some(n) => cx.expr(n, "a friction coefficient").map(Some),
            None => Some(None),
        };
        let static_friction = match get(f, "static_friction") {
            Some(n) => cx.expr(n, "a static friction coefficient").map(Some),
            None => Some(None),
        };
        let support = match get(f, "support") {
            Some(n) => super::support::read(cx, k, n).map(Some),
            None => Some(None),
        };
        Some(Contact {
            name: k.clone(),
            gap: gap?,
            restitution: restitution?,
            friction: friction?,
            static_friction: static_friction?,
            support: support?,
        })
    })
}

/// `contacts:`, in the form [`read`] reads.
pub(crate) fn write(w: &mut Writer<'_>, contacts: &[Contact]) -> Result<(), NotRewritten> {
    if contacts.is_empty() {
        return Ok(());
    }
    w.line("contacts:");
    for c in contacts {
        let place = format!("contact `{}`", c.name.value);
        let vector = |w: &mut Writer<'_>, v: &[Expr]| w.exprs(v, &place).map(|v| list(&v));
        let gap = match &c.gap {
            Gap::Written(g) => format!("gap: {}", flow(&w.expr(g, &place)?)),
            Gap::Above {
                point,
                normal,
                through,
                disc,
            } => {
                let mut surface = format!("normal: {}", vector(w, &normal.value)?);
                if let Some(o) = through {
                    surface.push_str(&format!(", through: {}", vector(w, &o.value)?));
                }
                let what = match disc {
                    Some(d) => format!(
                        "disc: {{ centre: {}, radius: {}, angle: {} }}",
                        point.value,
                        flow(&w.expr(&d.radius, &place)?),
                        flow(&w.expr(&d.angle, &place)?)
                    ),
                    None => format!("point: {}", point.value),
                };
                format!("{what}, above: {{ {surface} }}")
            }
            Gap::Circle {
                point,
                inside,
                centre,
                radius,
            } => format!(
                "point: {}, {}: {{ centre: {}, radius: {} }}",
                point.value,
                if *inside { "inside" } else { "outside" },
                vector(w, &centre.value)?,
                flow(&w.expr(radius, &place)?)
            ),
        };
        let mut text = format!(
            "  {}: {{ {gap}, restitution: {}",
            c.name.value,
            flow(&w.expr(&c.restitution, &place)?)
        );
        if let Some(mu) = &c.friction {
            text.push_str(&format!(", friction: {}", flow(&w.expr(mu, &place)?)));
        }
        if let Some(mu) = &c.static_friction {
            text.push_str(&format!(
                ", static_friction: {}",
                flow(&w.expr(mu, &place)?)
            ));
        }
        if let Some(s) = &c.support {
            text.push_str(&format!(
                ", support: {}",
                super::support::write(w, s, &place)?
            ));
        }
        w.line(format_args!("{text} }}"));
    }
    Ok(())
}

impl Contact {
    /// The rules of a contact: its point exists; the gap depends on the configuration and
    /// `t` only; `0 ≤ e ≤ 1` and `μ ≥ 0`, constant; vectors of the model's dimension; a
    /// normal that is not zero and a radius that is positive (at the parameters' defaults).
    pub(crate) fn rules(&self, cx: &mut dyn Rules) {
        let name = &self.name.value;
        let what = |part: &str| format!("the {part} of contact `{name}`");
        match &self.gap {
            Gap::Written(g) => cx.expression(g, Depends::Position, &what("gap")),
            Gap::Above {
                point,
                normal,
                through,
                disc,
            } => {
                cx.point(point);
                if let Some(d) = disc {
                    self.disc_rules(cx, d);
                }
                self.vector_rules(cx, normal, &what("normal"));
                if let Some(o) = through {
                    self.vector_rules(cx, o, &what("point `through`"));
                }
                let values: Option<Vec<f64>> = normal.value.iter().map(|c| cx.value(c)).collect();
                if let Some(values) = values
                    && values.iter().all(|c| *c == 0.0)
                {
                    cx.error(
                        Diagnostic::new(normal.location, format!("{} is zero", what("normal")))
                            .with_help("the normal points from the line or plane to the side where the point may go, as `[0, 1]` above a floor"),
                    );
                }
            }
            Gap::Circle {
                point,
                centre,
                radius,
                ..
            } => {
                cx.point(point);
                self.vector_rules(cx, centre, &what("centre"));
                cx.expression(radius, Depends::Position, &what("radius"));
                positive_radius(cx, radius, &what("radius"));
            }
        }
        self.fixed_surface(cx);
        self.coefficient_rules(cx, &self.restitution, "coefficient of restitution");
        if let Some(mu) = &self.friction {
            self.coefficient_rules(cx, mu, "friction coefficient");
            let what = format!("contact `{name}` has friction");
            if matches!(self.gap, Gap::Written(_)) {
                cx.error(
                    Diagnostic::new(mu.location, format!("{what}, but a written gap has no direction of slip"))
                        .with_help("write the contact as a point and its surface (`point: P, above: { normal: [0, 1] }`), whose slip is along the surface, or leave `friction` out"),
                );
            } else if cx.dimension().unwrap_or(2) != 2 {
                cx.error(
                    Diagnostic::new(mu.location, format!("{what}, but friction is taken in the plane only: a contact in 3-D slips in two directions, which the impact law does not take yet"))
                        .with_help("leave `friction` out of a contact between 3-D points"),
                );
            }
        }
        self.static_friction_rules(cx);
        if let Some(s) = &self.support {
            let shape = match &self.gap {
                Gap::Written(_) => (false, false),
                Gap::Above { disc, .. } => (disc.is_none(), disc.is_none()),
                Gap::Circle { .. } => (true, false),
            };
            let restitution = cx.value(&self.restitution);
            s.rules(cx, name, shape, restitution);
        }
    }

    /// `μ_s`: a constant no smaller than `μ`, with `friction:` given.
    fn static_friction_rules(&self, cx: &mut dyn Rules) {
        let Some(mu_s) = &self.static_friction else {
            return;
        };
        let name = &self.name.value;
        self.coefficient_rules(cx, mu_s, "static friction coefficient");
        let Some(mu) = &self.friction else {
            cx.error(
                Diagnostic::new(mu_s.location, format!("contact `{name}` has `static_friction` but no `friction`"))
                    .with_help("give the kinetic coefficient too: `friction: mu, static_friction: mu_s`, with `mu_s` at least `mu`"),
            );
            return;
        };
        if let (Some(s), Some(k)) = (cx.value(mu_s), cx.value(mu))
            && s < k
        {
            cx.error(
                Diagnostic::new(mu_s.location, format!("the static friction coefficient of contact `{name}` is {s}, below its friction coefficient {k}"))
                    .with_help("a contact that sticks holds at least the force it slides with: `static_friction` is at least `friction`"),
            );
        }
    }

    /// A disc's radius is a positive constant, its angle a function of the configuration,
    /// and it rolls in the plane.
    fn disc_rules(&self, cx: &mut dyn Rules, disc: &Disc) {
        let what = |part: &str| format!("the {part} of contact `{}`'s disc", self.name.value);
        cx.expression(&disc.radius, Depends::Constant, &what("radius"));
        positive_radius(cx, &disc.radius, &what("radius"));
        cx.expression(&disc.angle, Depends::Position, &what("angle"));
        if cx.dimension().unwrap_or(2) != 2 {
            cx.error(
                Diagnostic::new(disc.angle.location, format!("contact `{}` is a disc, but a disc rolls in the plane only", self.name.value))
                    .with_help("a body rolling in 3-D touches the plane at a point that moves over its surface: write it as a rolling constraint (`constraints:`), or the contact as a point above the plane"),
            );
        }
    }

    /// The gap may not depend on `t`: Newton's law on a surface moving across itself needs
    /// the surface's own speed in the impact law (`ġ⁺ = −e ġ⁻` with `ġ = G q̇ + ∂g/∂t`),
    /// which is not there yet. A line may move along itself (a belt: `through` with `t`,
    /// whose gap the lowering checks does not change): its material's speed enters the slip.
    fn fixed_surface(&self, cx: &mut dyn Rules) {
        let parts: Vec<&Expr> = match &self.gap {
            Gap::Written(g) => vec![g],
            Gap::Above { normal, disc, .. } => normal
                .value
                .iter()
                .chain(disc.iter().flat_map(|d| [&d.radius, &d.angle]))
                .collect(),
            Gap::Circle { centre, radius, .. } => {
                centre.value.iter().chain(std::iter::once(radius)).collect()
            }
        };
        for e in parts {
            let mut names = Vec::new();
            crate::model::parser::identifiers(e, &mut names);
            if let Some((_, at)) = names.iter().find(|(name, _)| name == "t") {
                cx.error(
                    Diagnostic::new(*at, format!("contact `{}` moves with `t`, but impacts on a moving surface are not simulated yet", self.name.value))
                        .with_help("write a surface fixed in the ground frame, or one moving along itself as a belt does (`above: { normal: [0, 1], through: [v*t, 0] }`); a surface moving across itself (a shaken table) needs its own speed in the impact law"),
                );
                return;
            }
        }
    }

    /// A vector of a contact's surface: the model's dimension, configuration and `t` only.
    fn vector_rules(&self, cx: &mut dyn Rules, v: &Located<Vec<Expr>>, what: &str) {
        for c in &v.value {
            cx.expression(c, Depends::Position, what);
        }
        let dimension = cx.dimension().unwrap_or(2);
        if v.value.len() != dimension {
            cx.error(
                Diagnostic::new(
                    v.location,
                    format!(
                        "{what} has {} components, but the model's points have {dimension}",
                        v.value.len()
                    ),
                )
                .with_help(format!(
                    "write it with {dimension} components, as the points' positions are"
                )),
            );
        }
    }

    /// `e` (the restitution) or `μ`: constant, and in its range at the defaults.
    fn coefficient_rules(&self, cx: &mut dyn Rules, e: &Expr, kind: &str) {
        let what = format!("the {kind} of contact `{}`", self.name.value);
        cx.expression(e, Depends::Constant, &what);
        let Some(value) = cx.value(e) else {
            return;
        };
        let restitution = kind.contains("restitution");
        let inside = if restitution {
            (0.0..=1.0).contains(&value)
        } else {
            value >= 0.0 && value.is_finite()
        };
        if !inside {
            let (range, help) = if restitution {
                (
                    "between 0 and 1",
                    "Newton's coefficient is the ratio of the gap's rates after and before an impact: 1 for an elastic impact, 0 for a plastic one",
                )
            } else {
                (
                    "0 or more",
                    "Coulomb's friction coefficient is the ratio of the largest tangential force to the normal force; leave `friction` out for a frictionless contact",
                )
            };
            cx.error(
                Diagnostic::new(
                    e.location,
                    format!("{what} is {value}, but it must be {range}"),
                )
                .with_help(help),
            );
        }
    }

    /// The equations of dimension: the gap, the surface's points and the radius are
    /// lengths; `e` and `μ` are numbers.
    pub(crate) fn units(&self, cx: &mut dyn Units) {
        let name = &self.name.value;
        let length = |cx: &mut dyn Units, e: &Expr, part: &str| {
            cx.fixed(
                e,
                Dimension::METRE,
                &format!("the {part} of contact `{name}`"),
                "a length",
                "m",
                "a gap is the distance the contact may still close, in m",
            );
        };
        match &self.gap {
            Gap::Written(g) => length(cx, g, "gap"),
            Gap::Above { through, disc, .. } => {
                for c in through.iter().flat_map(|o| &o.value) {
                    length(cx, c, "point `through`");
                }
                if let Some(d) = disc {
                    length(cx, &d.radius, "disc's radius");
                    cx.fixed(
                        &d.angle,
                        Dimension::ONE,
                        &format!("the disc's angle of contact `{name}`"),
                        "an angle",
                        "rad",
                        "a disc's angle is its rotation, in rad, as its body's `angle:`",
                    );
                }
            }
            Gap::Circle { centre, radius, .. } => {
                for c in &centre.value {
                    length(cx, c, "centre");
                }
                length(cx, radius, "radius");
            }
        }
        for (e, kind) in [
            (Some(&self.restitution), "coefficient of restitution"),
            (self.friction.as_ref(), "friction coefficient"),
            (self.static_friction.as_ref(), "static friction coefficient"),
        ] {
            if let Some(e) = e {
                cx.fixed(
                    e,
                    Dimension::ONE,
                    &format!("the {kind} of contact `{name}`"),
                    "a number",
                    "1",
                    "a coefficient of restitution or friction is a ratio and has no unit",
                );
            }
        }
    }

    /// The gap `g(q, t)` and what the slip and a change of support read of its form; `None`
    /// (with the mistake reported) if it names an unknown point.
    fn lower_gap(&self, cx: &mut dyn Lower) -> Option<LoweredGap> {
        // A disc's radius and angle: its own point in contact moves by `−R θ̇` along `t̂`.
        let mut rolling = None;
        // The speed of the surface's material along `t̂` (a belt's), 0 for a fixed one.
        let mut surface = None;
        let mut foot = (None, None);
        let (gap, across) = match &self.gap {
            Gap::Written(g) => (cx.expr(g), None),
            Gap::Above {
                point,
                normal,
                through,
                disc,
            } => {
                let p = position(cx, point)?;
                let n: Vec<ExprId> = normal.value.iter().map(|c| cx.expr(c)).collect();
                let d = match through {
                    Some(o) => difference(cx, &p, &o.value),
                    None => p.clone(),
                };
                let nd = super::dot(cx.arena(), &n, &d);
                let nn = super::dot(cx.arena(), &n, &n);
                let length = super::exact_sqrt(cx.arena(), nn);
                let mut gap = cx.arena().divide(nd, length);
                if let Some(o) = through {
                    surface = self.moving_line(cx, o, (&n, length), gap);
                }
                if let Some(disc) = disc {
                    let (radius, angle) = (cx.expr(&disc.radius), cx.expr(&disc.angle));
                    gap = cx.arena().minus(gap, radius);
                    rolling = Some((radius, angle));
                }
                foot = (Some(p.clone()), Some(n.clone()));
                (gap, Some((p, n)))
            }
            Gap::Circle {
                point,
                inside,
                centre,
                radius,
            } => {
                let p = position(cx, point)?;
                foot.0 = Some(p.clone());
                let d = difference(cx, &p, &centre.value);
                let dd = super::dot(cx.arena(), &d, &d);
                let r = cx.expr(radius);
                let arena = cx.arena();
                let distance = arena.sqrt(dd);
                let gap = if *inside {
                    arena.minus(r, distance)
                } else {
                    arena.minus(distance, r)
                };
                (gap, Some((p, d)))
            }
        };
        Some(LoweredGap {
            gap,
            across,
            rolling,
            surface,
            foot,
        })
    }

    /// The contact as expressions: its gap `g(q, t)`; `None` (with the mistake reported)
    /// if it names an unknown point.
    pub(crate) fn lower(&self, cx: &mut dyn Lower) -> Option<ContactInfo> {
        let LoweredGap {
            gap,
            across,
            rolling,
            surface,
            foot,
        } = self.lower_gap(cx)?;
        if self.friction.is_some() {
            self.surface_fixed_in_the_coordinates(cx);
        }
        let restitution = cx.expr(&self.restitution);
        let friction = match &self.friction {
            Some(mu) => cx.expr(mu),
            None => cx.arena().int(0),
        };
        let static_friction = match &self.static_friction {
            Some(mu) => cx.expr(mu),
            None => friction,
        };
        let arena = cx.arena();
        let coordinates: Vec<_> = arena.coordinates().iter().map(|s| s[0]).collect();
        let jacobian = coordinates.iter().map(|&q| arena.diff(gap, q)).collect();
        let rate = arena.time_derivative(gap);
        // `g̈ = G q̈ − γ`: `γ = −g̈` at `q̈ = 0`, as a holonomic constraint's.
        let second = arena.time_derivative(rate);
        let gamma = minus_at_rest(arena, second);
        let tangent = match (&self.friction, across) {
            (Some(_), Some((p, u))) if p.len() == 2 && u.len() == 2 => {
                let mut row = slip_row(cx, &p, &u, &coordinates);
                if let Some((radius, angle)) = rolling {
                    let arena = cx.arena();
                    for (t, &q) in row.iter_mut().zip(&coordinates) {
                        let turning = arena.diff(angle, q);
                        let turning = arena.times(radius, turning);
                        *t = arena.minus(*t, turning);
                    }
                }
                row
            }
            _ => {
                let zero = cx.arena().int(0);
                vec![zero; coordinates.len()]
            }
        };
        // `γ_T` of `T q̈ = γ_T` while it sticks (`v̇_t = 0`, `v_t = T q̇ − v_s`): `−v̇_t` at
        // `q̈ = 0`.
        let arena = cx.arena();
        let surface_velocity = match (&self.friction, surface) {
            (Some(_), Some(v)) => v,
            _ => arena.int(0),
        };
        let rates: Vec<ExprId> = (arena.coordinates().to_vec().iter())
            .map(|s| arena.symbol_expr(s[1]))
            .collect();
        let mut slip_terms: Vec<ExprId> = (tangent.iter().zip(&rates))
            .map(|(&t, &v)| arena.times(t, v))
            .collect();
        slip_terms.push(arena.neg(surface_velocity));
        let slip = arena.sum(&slip_terms);
        let slip_rate = arena.time_derivative(slip);
        let tangent_gamma = minus_at_rest(arena, slip_rate);
        let support = match &self.support {
            Some(s) => {
                let coordinates = cx.coordinate_names();
                Some(s.lower(cx, &coordinates, foot)?)
            }
            None => None,
        };
        Some(ContactInfo {
            name: self.name.value.clone(),
            gap,
            jacobian,
            tangent,
            rate,
            gamma,
            tangent_gamma,
            surface_velocity,
            restitution,
            friction,
            static_friction,
            support,
        })
    }

    /// A contact with friction slips against its surface as the ground frame sees it (or as a
    /// belt's `t` moves it): a surface carried by the coordinates (a floor on a cart) would
    /// need the slip relative to it, which is not there yet, and is reported.
    fn surface_fixed_in_the_coordinates(&self, cx: &mut dyn Lower) {
        let parts: Vec<&Located<Vec<Expr>>> = match &self.gap {
            Gap::Written(_) => Vec::new(),
            Gap::Above {
                normal, through, ..
            } => std::iter::once(normal).chain(through).collect(),
            Gap::Circle { centre, .. } => vec![centre],
        };
        for part in parts {
            let lowered: Vec<ExprId> = part.value.iter().map(|c| cx.expr(c)).collect();
            let arena = cx.arena();
            let coordinates: Vec<_> = arena.coordinates().iter().map(|s| s[0]).collect();
            let moves =
                (lowered.iter()).any(|&e| coordinates.iter().any(|&q| arena.depends_on(e, q)));
            if moves {
                cx.error(
                    Diagnostic::new(part.location, format!("contact `{}` has friction on a surface that moves with the coordinates, but its slip is taken against a surface fixed in the ground frame", self.name.value))
                        .with_help("write the surface fixed (or moving along itself with `t`, as a belt), or leave `friction` out; a floor carried by a body needs the slip relative to it, which is not there yet"),
                );
                return;
            }
        }
    }

    /// The speed `v_s = t̂ · Ȯ` along the line of its point `O` (`through`), `t̂` the normal
    /// turned a quarter-turn counter-clockwise: a belt's. The gap `gap` may not change with
    /// `t` (the line moving across itself), else the mistake is reported at `through`. `None`
    /// where `O` is fixed or the model is 3-D.
    fn moving_line(
        &self,
        cx: &mut dyn Lower,
        through: &Located<Vec<Expr>>,
        (n, length): (&[ExprId], ExprId),
        gap: ExprId,
    ) -> Option<ExprId> {
        let o: Vec<ExprId> = through.value.iter().map(|c| cx.expr(c)).collect();
        let arena = cx.arena();
        let t = arena.time_id();
        if !o.iter().any(|&c| arena.depends_on(c, t)) {
            return None;
        }
        let across = arena.diff(gap, t);
        if !arena.is_zero(across) || o.len() != 2 {
            cx.error(
                Diagnostic::new(through.location, format!("contact `{}`'s surface moves with `t` other than along itself in the plane, but impacts on a moving surface are not simulated yet", self.name.value))
                    .with_help("a line may move along itself, as a belt does (`through: [v*t, 0]` on `normal: [0, 1]`), in the plane; a surface moving across itself (a shaken table) needs its own speed in the impact law"),
            );
            return None;
        }
        let speed: Vec<ExprId> = o.iter().map(|&c| arena.diff(c, t)).collect();
        let minus_ny = arena.neg(n[1]);
        let along = super::dot(arena, &[minus_ny, n[0]], &speed);
        Some(arena.divide(along, length))
    }
}

/// A radius positive at the parameters' defaults, else the mistake reported.
fn positive_radius(cx: &mut dyn Rules, radius: &Expr, what: &str) {
    if let Some(r) = cx.value(radius)
        && r.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
    {
        cx.error(
            Diagnostic::new(radius.location, format!("{what} is {r}"))
                .with_help("a radius is positive"),
        );
    }
}

/// `−e` at `q̈ = 0`: the `γ` of an acceleration condition `e = A q̈ − γ = 0`.
fn minus_at_rest(arena: &mut crate::expr::ExprArena, e: ExprId) -> ExprId {
    let at_rest: rustc_hash::FxHashMap<_, _> = (arena.coordinates().to_vec().iter())
        .map(|s| (s[2], arena.int(0)))
        .collect();
    let rest = arena.substitute(e, &at_rest);
    arena.neg(rest)
}

/// The slip's row `T = t̂ · ∂P/∂q` of the point `p` in the plane, `t̂ = (−u_y, u_x)/|u|` (the
/// direction `u` across the surface turned a quarter-turn), one entry per coordinate.
fn slip_row(
    cx: &mut dyn Lower,
    p: &[ExprId],
    u: &[ExprId],
    coordinates: &[crate::expr::SymbolId],
) -> Vec<ExprId> {
    let uu = super::dot(cx.arena(), u, u);
    let length = super::exact_sqrt(cx.arena(), uu);
    let arena = cx.arena();
    let minus_uy = arena.neg(u[1]);
    let t = [arena.divide(minus_uy, length), arena.divide(u[0], length)];
    coordinates
        .iter()
        .map(|&q| {
            let parts: Vec<ExprId> = (0..2)
                .map(|k| {
                    let dp = arena.diff(p[k], q);
                    arena.times(t[k], dp)
                })
                .collect();
            arena.sum(&parts)
        })
        .collect()
}

/// The position of `point`, or `None` with the mistake reported.
fn position(cx: &mut dyn Lower, point: &Located<String>) -> Option<Vec<ExprId>> {
    let p = cx.point(&point.value);
    if p.is_none() {
        cx.error(Diagnostic::new(
            point.location,
            format!(
                "contact point `{}` is not a point of the model",
                point.value
            ),
        ));
    }
    p
}

/// `p − o`, `o` as written.
fn difference(cx: &mut dyn Lower, p: &[ExprId], o: &[Expr]) -> Vec<ExprId> {
    p.iter()
        .zip(o)
        .map(|(&p, o)| {
            let o = cx.expr(o);
            cx.arena().minus(p, o)
        })
        .collect()
}

/// A contact as expressions of the model's arena.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactInfo {
    /// Name.
    pub name: String,
    /// The gap `g(q, t)` (m).
    pub gap: ExprId,
    /// Its Jacobian `G = ∂g/∂q` (one entry per coordinate).
    pub jacobian: Vec<ExprId>,
    /// The row `T` of its slip `v_t = T q̇` along the surface (in the plane: `t̂ · ∂P/∂q`,
    /// `t̂` the normal turned a quarter-turn counter-clockwise); zeros for a frictionless
    /// contact.
    pub tangent: Vec<ExprId>,
    /// Its rate `ġ = G q̇ + ∂g/∂t` (m/s).
    pub rate: ExprId,
    /// `γ` of `G q̈ = γ` while it is closed (`g̈ = 0`): `−g̈` at `q̈ = 0` (m/s²).
    pub gamma: ExprId,
    /// `γ_T` of `T q̈ = γ_T` while it sticks (the slip `v_t = T q̇ − v_s` held at 0): `−v̇_t`
    /// at `q̈ = 0` (m/s²; 0 for a frictionless contact).
    pub tangent_gamma: ExprId,
    /// `v_s`, the speed of the surface's material along `t̂` (a belt's, m/s): the contact
    /// slips at `v_t = T q̇ − v_s`. 0 for a fixed surface and a frictionless contact.
    pub surface_velocity: ExprId,
    /// Newton's coefficient of restitution `e`.
    pub restitution: ExprId,
    /// Coulomb's friction coefficient `μ` (0 for a frictionless contact).
    pub friction: ExprId,
    /// The static coefficient `μ_s ≥ μ` of the sticking cone (`μ` unless given).
    pub static_friction: ExprId,
    /// The change of support where it strikes, if it is one.
    pub support: Option<SupportInfo>,
}

/// A contact's gap as expressions, with what the rest of its lowering reads of its form.
struct LoweredGap {
    /// `g(q, t)`.
    gap: ExprId,
    /// For a point, the point and the direction `u` across the surface (the normal, or the
    /// point from the centre), whose perpendicular is the slip's.
    across: Option<(Vec<ExprId>, Vec<ExprId>)>,
    /// A disc's radius and angle.
    rolling: Option<(ExprId, ExprId)>,
    /// The speed of a moving line's material along `t̂` (a belt's).
    surface: Option<ExprId>,
    /// The point and the normal, for a change of support.
    foot: (Option<Vec<ExprId>>, Option<Vec<ExprId>>),
}
