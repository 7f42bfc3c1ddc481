//! The mechanism's points (with wheel contact points) and the momentum balances chosen for its
//! equations (the model elements, frames, bodies, constraints and loads among them: their
//! modules in `model/elements/`).

use super::walk::{Fields, Keyed, Need};
use super::write::{NotRewritten, Writer, flow, list};
use super::*;

/// The names of the other derivations that `eomgen check` lists beside a named set of
/// balances, which a set may not take.
const RESERVED_SET_NAMES: [&str; 5] = ["lagrange", "momentum", "by_hand", "energy", "power"];

/// The keys of a wheel's contact point.
const WHEEL: Fields = Fields {
    kind: "wheel contact",
    keys: &[
        ("centre", Need::Required),
        ("frame", Need::Required),
        ("axle", Need::Required),
        ("radius", Need::Required),
    ],
    example: "{ centre: F, frame: H, axle: y, radius: r }",
};

/// The keys of an angular momentum balance.
const AMB: Fields = Fields {
    kind: "angular momentum balance",
    keys: &[
        ("about", Need::Required),
        ("bodies", Need::Required),
        ("form", Need::Optional),
        ("axis", Need::Optional),
        ("in", Need::Optional),
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
            if let YamlKind::Map(entries) = &v.kind {
                if let [(key, wheel)] = entries.as_slice()
                    && key.value == "wheel"
                {
                    let what = Located::new(format!("{}'s wheel", k.value), key.location);
                    let wheel = cx.wheel_contact(&what, wheel)?;
                    return Some(Point {
                        name: k.clone(),
                        position: Vec::new(),
                        relative: None,
                        wheel: Some(wheel),
                        location: v.location,
                    });
                }
                let relative = cx.relative_position(k, entries, v.location)?;
                return Some(Point {
                    name: k.clone(),
                    position: Vec::new(),
                    relative: Some(relative),
                    wheel: None,
                    location: v.location,
                });
            }
            let position = cx.vector(
                v,
                &format!("point `{}`", k.value),
                "P: [l*cos(q), l*sin(q)]",
            )?;
            Some(Point {
                name: k.clone(),
                position,
                relative: None,
                wheel: None,
                location: v.location,
            })
        })
    }

    /// A point written as a point plus vectors in frames: `{ from: O, B: [0, 0, l] }`.
    fn relative_position(
        &mut self,
        k: &Located<String>,
        entries: &Entries,
        at: Location,
    ) -> Option<RelativePosition> {
        let what = format!("point `{}`", k.value);
        let example = format!("{}: {{ from: O, B: [0, 0, l] }}", k.value);
        let mut from = None;
        let mut vectors = Vec::new();
        let mut complete = true;
        for (key, value) in entries {
            if key.value == "from" {
                match self.name(value, "`from`") {
                    Some(p) => from = Some(p),
                    None => complete = false,
                }
                continue;
            }
            if !self.key_name(key, "a frame") {
                complete = false;
                continue;
            }
            let in_frame = format!("the vector of {what} in frame `{}`", key.value);
            match self.vector(value, &in_frame, "B: [0, 0, l]") {
                Some(v) if v.len() == 3 => vectors.push((key.clone(), v)),
                Some(v) => {
                    self.error(
                        Diagnostic::new(
                            value.location,
                            format!("{in_frame} has {} components; a vector in a frame has 3", v.len()),
                        )
                        .with_help("write its components along the frame's x, y and z axes, as in `B: [0, 0, l]`"),
                    );
                    complete = false;
                }
                None => complete = false,
            }
        }
        if from.is_none() && vectors.is_empty() && complete {
            self.error(
                Diagnostic::new(
                    at,
                    format!("{what} is a map with neither `from` nor a vector"),
                )
                .with_help(format!(
                    "a point is a list `[x, y, z]` or a point plus vectors in frames: `{example}`"
                )),
            );
            return None;
        }
        complete.then_some(RelativePosition { from, vectors })
    }

    /// A wheel's contact point: `{ centre, frame, axle, radius }`.
    pub(super) fn wheel_contact(
        &mut self,
        k: &Located<String>,
        v: &YamlNode,
    ) -> Option<WheelContact> {
        let f = self.fields(k, v, &WHEEL)?;
        let centre = get(f, "centre").and_then(|n| self.name(n, "`centre`"));
        let frame = get(f, "frame").and_then(|n| self.name(n, "`frame`"));
        let axle = get(f, "axle").and_then(|n| self.axes(n, true).and_then(|mut a| a.pop()));
        let radius = get(f, "radius").and_then(|n| self.expr(n, "a wheel radius"));
        Some(WheelContact {
            centre: centre?,
            frame: frame?,
            axle: axle?,
            radius: radius?,
        })
    }

    /// `balances:` — a list of `amb: { about, bodies, form }` (angular momentum balance) and
    /// `lmb: { bodies, along }` (linear momentum balance), one set; or a map of named sets,
    /// `{ NAME: [ … ], … }`, each such a list (several derivations of the same equations).
    pub(super) fn balances(&mut self, node: &YamlNode) -> Vec<Balance> {
        let YamlKind::Map(sets) = &node.kind else {
            return self.balance_list(node, None);
        };
        let mut out = Vec::new();
        for (name, value) in sets {
            // A set's name labels its derivation beside the others in `eomgen check`.
            if RESERVED_SET_NAMES.contains(&name.value.as_str()) {
                self.error(
                    Diagnostic::new(
                        name.location,
                        format!(
                            "`{}` names another derivation of the equations of motion; a set of balances needs its own name",
                            name.value
                        ),
                    )
                    .with_help(format!(
                        "`{}` are the other derivations' names; call the set after its form, such as `r_x_ma` or `about_E`",
                        RESERVED_SET_NAMES.join("`, `")
                    )),
                );
            }
            // `NAME: [...]`, or `NAME: { expect: disagree, balances: [...] }`.
            let (list, expect_disagreement) = match &value.kind {
                YamlKind::Map(entries) => {
                    let expect = entries.iter().find(|(k, _)| k.value == "expect");
                    let list = entries.iter().find(|(k, _)| k.value == "balances");
                    let unknown = entries
                        .iter()
                        .find(|(k, _)| !matches!(k.value.as_str(), "expect" | "balances"));
                    let disagree = expect.is_some_and(|(_, v)| {
                        matches!(&v.kind, YamlKind::Scalar { text, .. } if text == "disagree")
                    });
                    if let Some((k, _)) = unknown {
                        self.error(
                            Diagnostic::new(k.location, format!("unknown key `{}` in the set of balances `{}`", k.value, name.value))
                                .with_help("a set is a list of balances, or `{ expect: disagree, balances: [...] }` for a set kept to show a wrong form"),
                        );
                    }
                    if let Some((_, v)) = expect.filter(|_| !disagree) {
                        self.error(
                            Diagnostic::new(
                                v.location,
                                "`expect` of a set of balances is `disagree`",
                            )
                            .with_help(
                                "leave `expect` out for a set that must agree with Lagrange",
                            ),
                        );
                    }
                    let Some((_, list)) = list else {
                        self.error(
                            Diagnostic::new(name.location, format!("the set of balances `{}` has no `balances:` list", name.value))
                                .with_help("write `{ expect: disagree, balances: [ { amb: { about: E, bodies: [fore], form: h_dot } } ] }`"),
                        );
                        continue;
                    };
                    (list, disagree)
                }
                _ => (value, false),
            };
            let mut set = self.balance_list(list, Some(name.clone()));
            if matches!(&list.kind, YamlKind::Seq(items) if items.is_empty()) {
                self.error(
                    Diagnostic::new(
                        name.location,
                        format!("the set of balances `{}` is empty", name.value),
                    )
                    .with_help("a set gives one balance per coordinate; remove the set or list its balances"),
                );
            }
            for b in &mut set {
                b.expect_disagreement = expect_disagreement;
            }
            out.extend(set);
        }
        out
    }

    /// One set of balances, a list, as [`Self::balances`] reads it.
    fn balance_list(&mut self, node: &YamlNode, set: Option<Located<String>>) -> Vec<Balance> {
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
                        YamlKind::Scalar { text, .. } if text == "h_rel_dot" => {
                            Some(AmbForm::HRelDot)
                        }
                        _ => {
                            self.error(
                                Diagnostic::new(n.location, "`form` of an angular momentum balance is `r_x_ma`, `h_dot` or `h_rel_dot`")
                                    .with_help("`r_x_ma` (the default): Σ M_A = Σ r_G/A × m a_G + I θ̈, valid about any point; `h_dot`: Σ M_A = dH_A/dt with absolute velocities, valid when v_A × v_G = 0; `h_rel_dot`: Σ M_A = dH_A/rel/dt with velocities relative to A, valid when r_G/A × a_A = 0"),
                            );
                            None
                        }
                    },
                };
                get(f, "about")
                    .and_then(|n| self.name(n, "`about`"))
                    .zip(form)
                    .zip(match get(f, "axis") {
                        Some(n) => self
                            .vector(n, "`axis`", "axis: [0, 0, 1]")
                            .map(|v| Some(Located::new(v, n.location))),
                        None => Some(None),
                    })
                    .zip(match get(f, "in") {
                        Some(n) => self.name(n, "`in`").map(Some),
                        None => Some(None),
                    })
                    .map(|(((about, form), axis), frame)| BalanceKind::Amb {
                        about,
                        form,
                        axis,
                        frame,
                    })
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
                    set: set.clone(),
                    expect_disagreement: false,
                    location: item.location,
                });
            }
        }
        out
    }
}

/// The writers of the mechanism's points, loads and constraints.
impl Writer<'_> {
    /// `points:`.
    pub(super) fn write_points(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        if file.points.is_empty() {
            return Ok(());
        }
        self.line("points:");
        for p in &file.points {
            let text = self.point_text(p)?;
            self.line(format_args!("  {}: {text}", p.name.value));
        }
        Ok(())
    }

    /// A point's value: its components, the point plus vectors in frames, or a wheel contact.
    fn point_text(&mut self, p: &Point) -> Result<String, NotRewritten> {
        let place = format!("point `{}`", p.name.value);
        if let Some(wheel) = &p.wheel {
            return Ok(format!("{{ wheel: {} }}", self.wheel_text(wheel, &place)?));
        }
        if let Some(RelativePosition { from, vectors }) = &p.relative {
            let mut parts = Vec::new();
            if let Some(from) = from {
                parts.push(format!("from: {}", from.value));
            }
            for (frame, vector) in vectors {
                let components = self.exprs(vector, &place)?;
                parts.push(format!("{}: {}", frame.value, list(&components)));
            }
            return Ok(format!("{{ {} }}", parts.join(", ")));
        }
        let parts = self.exprs(&p.position, &place)?;
        Ok(list(&parts))
    }

    /// `balances:` is not written: the model is derived by Lagrange's equations, noted.
    pub(super) fn write_balances(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        if !file.balances.is_empty() {
            self.notes.push(
                "`balances:` left out: the reduced model is derived by Lagrange's equations"
                    .to_string(),
            );
        }
        Ok(())
    }
}

/// The text of a wheel, in a point's entry and in `draw: wheels:`.
impl Writer<'_> {
    /// `{ centre: G, frame: R, axle: y, radius: r }`.
    pub(super) fn wheel_text(
        &mut self,
        wheel: &WheelContact,
        place: &str,
    ) -> Result<String, NotRewritten> {
        let radius = self.expr(&wheel.radius, place)?;
        Ok(format!(
            "{{ centre: {}, frame: {}, axle: {}, radius: {} }}",
            wheel.centre.value,
            wheel.frame.value,
            wheel.axle.value.letter(),
            flow(&radius)
        ))
    }
}
