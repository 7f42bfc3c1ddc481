//! The mechanism: points, bodies, the loads between them (springs, dampers, forces, torques)
//! and the momentum balances chosen for its equations.

use super::walk::{Fields, Keyed, Need};
use super::*;

const BODY_KEYS: &[&str] = &["mass", "at", "inertia", "com", "angle"];
const PARTICLE_EXAMPLE: &str = "{ mass: m, at: P }";
const RIGID_EXAMPLE: &str = "{ mass: m, inertia: m*l^2/12, com: G, angle: theta }";

/// The keys of a spring.
const SPRING: Fields = Fields {
    kind: "spring",
    keys: &[
        ("between", Need::Required),
        ("stiffness", Need::Required),
        ("rest_length", Need::Optional),
    ],
    example: "{ between: [A, B], stiffness: k, rest_length: l0 }",
};

/// The keys of a damper.
const DAMPER: Fields = Fields {
    kind: "damper",
    keys: &[("between", Need::Required), ("coefficient", Need::Required)],
    example: "{ between: [A, B], coefficient: c }",
};

/// The keys of a force.
const FORCE: Fields = Fields {
    kind: "force",
    keys: &[("at", Need::Required), ("vector", Need::Required)],
    example: "{ at: P, vector: [F0*cos(w*t), 0] }",
};

/// The keys of a torque.
const TORQUE: Fields = Fields {
    kind: "torque",
    keys: &[("body", Need::Required), ("value", Need::Required)],
    example: "{ body: arm, value: tau0*sin(w*t) }",
};

/// The keys of an angular momentum balance.
const AMB: Fields = Fields {
    kind: "angular momentum balance",
    keys: &[
        ("about", Need::Required),
        ("bodies", Need::Required),
        ("form", Need::Optional),
    ],
    example: "{ about: O, bodies: [upper, fore] }",
};

/// The keys of a linear momentum balance.
const LMB: Fields = Fields {
    kind: "linear momentum balance",
    keys: &[("bodies", Need::Required), ("along", Need::Required)],
    example: "{ bodies: [slider], along: [cos(theta), sin(theta)] }",
};

impl Ctx<'_> {
    /// `points:` — `name: [x, y]` or `name: [x, y, z]`.
    pub(super) fn points(&mut self, node: &YamlNode) -> Vec<Point> {
        let spec = Keyed {
            what: "`points`",
            example: "points: { O: [0, 0], P: [l*cos(q), l*sin(q)] }",
            names: Some("point"),
            drop: true,
        };
        self.keyed(node, spec, |cx, k, v| {
            let position = cx.vector(
                v,
                &format!("point `{}`", k.value),
                "P: [l*cos(q), l*sin(q)]",
            )?;
            Some(Point {
                name: k.clone(),
                position,
                location: v.location,
            })
        })
    }

    /// `bodies:` — `name: { mass, at }` or `name: { mass, inertia, com, angle }`.
    pub(super) fn bodies(&mut self, node: &YamlNode) -> Vec<Body> {
        let spec = Keyed {
            what: "`bodies`",
            example: "bodies: { bob: { mass: m, at: P } }",
            names: Some("body"),
            drop: true,
        };
        self.keyed(node, spec, Self::body)
    }

    /// One body: a particle `{ mass, at }`, or a planar rigid body
    /// `{ mass, inertia, com, angle }`.
    pub(super) fn body(&mut self, k: &Located<String>, v: &YamlNode) -> Option<Body> {
        let what = format!("body `{}`", k.value);
        let f = self.map(v, &what, &format!("{}: {PARTICLE_EXAMPLE}", k.value))?;
        self.unknown_keys(f, &what, BODY_KEYS, BODY_KEYS);
        let rigid_key = ["inertia", "com", "angle"]
            .into_iter()
            .find(|r| get(f, r).is_some());
        let Some(rigid_key) = rigid_key else {
            // A particle: `{ mass, at }`.
            let complete = self.require(
                f,
                k.location,
                &what,
                &["mass", "at"],
                &format!("{}: {PARTICLE_EXAMPLE}", k.value),
            );
            let mass = get(f, "mass").and_then(|n| self.expr(n, "a mass"));
            let at = get(f, "at").and_then(|n| self.name(n, "`at`"));
            let (Some(mass), Some(at), true) = (mass, at, complete) else {
                return None;
            };
            return Some(Body {
                name: k.clone(),
                kind: BodyKind::Particle { mass, at },
            });
        };
        // A planar rigid body: `{ mass, inertia, com, angle }`.
        if let Some(at) = get_key(f, "at") {
            self.error(
                Diagnostic::new(
                    at.location,
                    format!(
                        "{what} has `{rigid_key}`, so it is a planar rigid body, which has no `at`"
                    ),
                )
                .with_help(format!(
                    "a rigid body's position is its centre of mass `com`: `{RIGID_EXAMPLE}`; a particle is `{PARTICLE_EXAMPLE}`"
                )),
            );
        }
        let complete = self.require(
            f,
            k.location,
            &format!("{what} (a planar rigid body, as it has `{rigid_key}`)"),
            &["mass", "inertia", "com", "angle"],
            &format!("{}: {RIGID_EXAMPLE}", k.value),
        );
        let mass = get(f, "mass").and_then(|n| self.expr(n, "a mass"));
        let inertia = get(f, "inertia").and_then(|n| self.expr(n, "an inertia"));
        let com = get(f, "com").and_then(|n| self.name(n, "`com`"));
        let angle = get(f, "angle").and_then(|n| self.expr(n, "a body angle"));
        let (Some(mass), Some(inertia), Some(com), Some(angle), true) = (
            mass,
            inertia,
            com,
            angle,
            complete && get(f, "at").is_none(),
        ) else {
            return None;
        };
        Some(Body {
            name: k.clone(),
            kind: BodyKind::Rigid {
                mass,
                inertia,
                com,
                angle,
            },
        })
    }

    /// `springs:` — `name: { between, stiffness, rest_length }`.
    pub(super) fn springs(&mut self, node: &YamlNode) -> Vec<Spring> {
        let example = format!("springs: {{ s: {} }}", SPRING.example);
        let spec = Keyed {
            what: "`springs`",
            example: &example,
            names: None,
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let f = cx.fields(k, v, &SPRING)?;
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

    /// `dampers:` — `name: { between, coefficient }`.
    pub(super) fn dampers(&mut self, node: &YamlNode) -> Vec<Damper> {
        let example = format!("dampers: {{ d: {} }}", DAMPER.example);
        let spec = Keyed {
            what: "`dampers`",
            example: &example,
            names: None,
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let f = cx.fields(k, v, &DAMPER)?;
            let between = get(f, "between").and_then(|n| cx.point_pair(n, "`between`"));
            let coefficient =
                get(f, "coefficient").and_then(|n| cx.expr(n, "a damping coefficient"));
            Some(Damper {
                name: k.clone(),
                between: between?,
                coefficient: coefficient?,
            })
        })
    }

    /// `forces:` — `name: { at, vector }`.
    pub(super) fn forces(&mut self, node: &YamlNode) -> Vec<Force> {
        let example = format!("forces: {{ push: {} }}", FORCE.example);
        let spec = Keyed {
            what: "`forces`",
            example: &example,
            names: None,
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let f = cx.fields(k, v, &FORCE)?;
            let at = get(f, "at").and_then(|n| cx.name(n, "`at`"));
            let vector = get(f, "vector").and_then(|n| {
                cx.vector(
                    n,
                    &format!("the vector of force `{}`", k.value),
                    "vector: [Fx, Fy]",
                )
                .map(|x| (x, n.location))
            });
            let (vector, location) = vector?;
            Some(Force {
                name: k.clone(),
                at: at?,
                vector,
                location,
            })
        })
    }

    /// `torques:` — `name: { body, value }`.
    pub(super) fn torques(&mut self, node: &YamlNode) -> Vec<Torque> {
        let example = format!("torques: {{ motor: {} }}", TORQUE.example);
        let spec = Keyed {
            what: "`torques`",
            example: &example,
            names: None,
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let f = cx.fields(k, v, &TORQUE)?;
            let body = get(f, "body").and_then(|n| cx.name(n, "`body`"));
            let value = get(f, "value").and_then(|n| cx.expr(n, "a torque"));
            Some(Torque {
                name: k.clone(),
                body: body?,
                value: value?,
            })
        })
    }

    /// `balances:` — a list of `amb: { about, bodies, form }` (angular momentum balance) and
    /// `lmb: { bodies, along }` (linear momentum balance).
    pub(super) fn balances(&mut self, node: &YamlNode) -> Vec<Balance> {
        const EXAMPLE: &str = "balances:\n  - { amb: { about: O, bodies: [upper, fore] } }\n  - { lmb: { bodies: [slider], along: [cos(theta), sin(theta)] } }";
        let Some(items) = self.seq(node, "`balances`", EXAMPLE) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for item in items {
            let Some(entries) = self.map(
                item,
                "a balance",
                "{ amb: { about: O, bodies: [upper, fore] } }",
            ) else {
                continue;
            };
            if entries.len() != 1 || !matches!(entries[0].0.value.as_str(), "amb" | "lmb") {
                self.error(
                    Diagnostic::new(item.location, "a balance is one of `amb: {…}` (angular momentum balance) or `lmb: {…}` (linear momentum balance)")
                        .with_help("write `{ amb: { about: O, bodies: [upper, fore] } }` or `{ lmb: { bodies: [slider], along: [1, 0] } }`"),
                );
                continue;
            }
            let (key, value) = &entries[0];
            let amb = key.value == "amb";
            let Some(f) = self.fields(key, value, if amb { &AMB } else { &LMB }) else {
                continue;
            };
            let mut bodies = Vec::new();
            if let Some(list) =
                get(f, "bodies").and_then(|n| self.seq(n, "`bodies`", "bodies: [upper, fore]"))
            {
                for b in list {
                    if let Some(name) = self.name(b, "a body") {
                        bodies.push(name);
                    }
                }
            }
            let kind = if amb {
                let form = match get(f, "form") {
                    None => Some(AmbForm::RCrossMa),
                    Some(n) => match &n.kind {
                        YamlKind::Scalar { text, .. } if text == "r_x_ma" => {
                            Some(AmbForm::RCrossMa)
                        }
                        YamlKind::Scalar { text, .. } if text == "h_dot" => Some(AmbForm::HDot),
                        _ => {
                            self.error(
                                Diagnostic::new(n.location, "`form` of an angular momentum balance is `r_x_ma` or `h_dot`")
                                    .with_help("`r_x_ma` (the default): Σ M_A = Σ r_G/A × m a_G + I θ̈, valid about any point; `h_dot`: Σ M_A = dH_A/dt, valid about a fixed point or the centre of mass"),
                            );
                            None
                        }
                    },
                };
                get(f, "about")
                    .and_then(|n| self.name(n, "`about`"))
                    .zip(form)
                    .map(|(about, form)| BalanceKind::Amb { about, form })
            } else {
                get(f, "along")
                    .and_then(|n| self.vector(n, "`along`", "along: [cos(theta), sin(theta)]"))
                    .map(|along| BalanceKind::Lmb { along })
            };
            if let Some(kind) = kind
                && !bodies.is_empty()
            {
                out.push(Balance {
                    kind,
                    bodies,
                    location: item.location,
                });
            }
        }
        out
    }
}
