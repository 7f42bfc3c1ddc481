//! Located YAML tree → typed [`ModelFile`], reporting every unknown key, wrong type and
//! malformed expression at once.

use super::ast::Expr;
use super::diagnostic::Diagnostic;
use super::file::*;
use super::located::{Located, Location};
use super::parser::{closest, eval_expr, parse_expr};
use super::yaml::{YamlKind, YamlNode, trailing_comment};

type Entries = [(Located<String>, YamlNode)];

/// Top-level keys of a model file.
pub const TOP_LEVEL_KEYS: &[&str] = &[
    "name",
    "description",
    "parameters",
    "coordinates",
    "kinetic",
    "potential",
    "generalized_forces",
    "points",
    "bodies",
    "gravity",
    "springs",
    "dampers",
    "forces",
    "torques",
    "initial",
    "draw",
];

/// Keys of the model format that this version does not implement yet.
pub const LATER_KEYS: &[&str] = &[
    "constraints",
    "nonholonomic",
    "balances",
    "events",
    "equilibria",
    "outputs",
    "checks",
];

struct Ctx<'s> {
    source: &'s str,
    errors: Vec<Diagnostic>,
}

impl Ctx<'_> {
    fn error(&mut self, d: Diagnostic) {
        self.errors.push(d);
    }

    /// Checks that `entries` use only `allowed` keys and have every `required` one.
    fn keys(
        &mut self,
        entries: &Entries,
        at: Location,
        what: &str,
        allowed: &[&str],
        required: &[&str],
    ) {
        for (k, _) in entries {
            if !allowed.contains(&k.value.as_str()) {
                let mut d =
                    Diagnostic::new(k.location, format!("unknown key `{}` in {what}", k.value));
                d = match closest(&k.value, allowed) {
                    Some(c) => d.with_help(format!(
                        "did you mean `{c}`? {what} takes: {}",
                        allowed.join(", ")
                    )),
                    None => d.with_help(format!("{what} takes: {}", allowed.join(", "))),
                };
                self.error(d);
            }
        }
        for r in required {
            if !entries.iter().any(|(k, _)| k.value == *r) {
                self.error(
                    Diagnostic::new(at, format!("{what} has no `{r}`")).with_help(format!(
                        "add `{r}: …`; {what} takes: {}",
                        allowed.join(", ")
                    )),
                );
            }
        }
    }

    fn map<'n>(&mut self, node: &'n YamlNode, what: &str, example: &str) -> Option<&'n Entries> {
        match &node.kind {
            YamlKind::Map(e) => Some(e),
            YamlKind::Null => Some(&[]),
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be a map, found {}", other.describe()),
                    )
                    .with_help(format!("write it like `{example}`")),
                );
                None
            }
        }
    }

    fn seq<'n>(&mut self, node: &'n YamlNode, what: &str, example: &str) -> Option<&'n [YamlNode]> {
        match &node.kind {
            YamlKind::Seq(items) => Some(items),
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be a list, found {}", other.describe()),
                    )
                    .with_help(format!("write it like `{example}`")),
                );
                None
            }
        }
    }

    fn text(&mut self, node: &YamlNode, what: &str) -> Option<Located<String>> {
        match &node.kind {
            YamlKind::Scalar { text, .. } => Some(Located::new(text.clone(), node.location)),
            other => {
                self.error(Diagnostic::new(
                    node.location,
                    format!("{what} must be a single value, found {}", other.describe()),
                ));
                None
            }
        }
    }

    fn name(&mut self, node: &YamlNode, what: &str) -> Option<Located<String>> {
        let t = self.text(node, what)?;
        if !is_identifier(&t.value) {
            self.error(
                Diagnostic::new(t.location, format!("{what} `{}` is not a name", t.value))
                    .with_help("names start with a letter and contain letters, digits and `_`"),
            );
            return None;
        }
        Some(t)
    }

    fn expr(&mut self, node: &YamlNode, what: &str) -> Option<Expr> {
        match &node.kind {
            YamlKind::Scalar { text, .. } => match parse_expr(text, node.location) {
                Ok(e) => Some(e),
                Err(d) => {
                    self.error(d);
                    None
                }
            },
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be an expression, found {}", other.describe()),
                    )
                    .with_help("write a number or an expression such as `m*g*l`"),
                );
                None
            }
        }
    }

    fn vector(&mut self, node: &YamlNode, what: &str) -> Option<Vec<Expr>> {
        let items = self.seq(node, what, "[x, y] or [x, y, z]")?;
        if !(2..=3).contains(&items.len()) {
            self.error(
                Diagnostic::new(
                    node.location,
                    format!(
                        "{what} has {} components; expected 2 (planar) or 3 (spatial)",
                        items.len()
                    ),
                )
                .with_help("write it like `[l*cos(q), l*sin(q)]`"),
            );
            return None;
        }
        let out: Vec<Option<Expr>> = items.iter().map(|i| self.expr(i, what)).collect();
        out.into_iter().collect()
    }

    fn point_pair(&mut self, node: &YamlNode, what: &str) -> Option<[Located<String>; 2]> {
        let items = self.seq(node, what, "[A, B]")?;
        if items.len() != 2 {
            self.error(
                Diagnostic::new(
                    node.location,
                    format!("{what} must name two points, found {}", items.len()),
                )
                .with_help("write it like `[A, B]`"),
            );
            return None;
        }
        let a = self.name(&items[0], "a point")?;
        let b = self.name(&items[1], "a point")?;
        Some([a, b])
    }
}

/// Whether `s` is a model-file name: a letter, then letters, digits and `_`.
pub fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    c.next().is_some_and(|f| f.is_ascii_alphabetic())
        && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

fn get<'n>(entries: &'n Entries, key: &str) -> Option<&'n YamlNode> {
    entries.iter().find(|(k, _)| k.value == key).map(|(_, v)| v)
}

/// Builds the typed model from the YAML tree of `path`.
///
/// # Errors
/// Every schema diagnostic of the file.
pub fn build(path: &str, source: &str, root: &YamlNode) -> Result<ModelFile, Vec<Diagnostic>> {
    let mut cx = Ctx {
        source,
        errors: Vec::new(),
    };
    let Some(top) = cx.map(root, "a model file", "name: my_model") else {
        return Err(cx.errors);
    };
    for (k, _) in top {
        if LATER_KEYS.contains(&k.value.as_str()) {
            cx.error(
                Diagnostic::new(
                    k.location,
                    format!(
                        "`{}:` is not supported yet by this version of eomgen",
                        k.value
                    ),
                )
                .with_help("remove it for now; it is planned"),
            );
        }
    }
    let allowed: Vec<&str> = TOP_LEVEL_KEYS.iter().chain(LATER_KEYS).copied().collect();
    cx.keys(
        top,
        root.location,
        "a model file",
        &allowed,
        &["name", "coordinates"],
    );

    let name = get(top, "name")
        .and_then(|n| cx.name(n, "`name`"))
        .unwrap_or_else(|| Located::new(String::new(), root.location));
    let description = get(top, "description")
        .and_then(|n| cx.text(n, "`description`"))
        .map(|d| d.value)
        .unwrap_or_default();

    let mut parameters = Vec::new();
    if let Some(node) = get(top, "parameters") {
        if let Some(entries) = cx.map(node, "`parameters`", "parameters: { m: 1.0, g: 9.81 }") {
            for (k, v) in entries {
                if !is_identifier(&k.value) {
                    cx.error(Diagnostic::new(
                        k.location,
                        format!("parameter `{}` is not a name", k.value),
                    ));
                    continue;
                }
                let Some(default) = cx.expr(v, "a parameter default") else {
                    continue;
                };
                match eval_expr(&default, &|_| None) {
                    Ok(value) if value.is_finite() => parameters.push(Parameter {
                        name: k.clone(),
                        default,
                        value,
                        unit: trailing_comment(cx.source, v.location.line)
                            .filter(|_| v.location.line == k.location.line),
                    }),
                    Ok(value) => cx.error(Diagnostic::new(
                        v.location,
                        format!(
                            "parameter `{}` has the non-finite default `{value}`",
                            k.value
                        ),
                    )),
                    Err(d) => cx.error(
                        Diagnostic::new(
                            d.location,
                            format!("parameter defaults must be constant: {}", d.message),
                        )
                        .with_help("use numbers, `pi` and functions, e.g. `pi/4` or `9.81`"),
                    ),
                }
            }
        }
    }

    let mut coordinates = Vec::new();
    if let Some(node) = get(top, "coordinates") {
        if let Some(items) = cx.seq(node, "`coordinates`", "coordinates: [theta1, theta2]") {
            for item in items {
                if let Some(n) = cx.name(item, "a coordinate") {
                    // A trailing comment describes the coordinate only if it is alone on its line.
                    let alone = items
                        .iter()
                        .filter(|o| o.location.line == item.location.line)
                        .count()
                        == 1;
                    let comment = if alone {
                        trailing_comment(cx.source, n.location.line)
                    } else {
                        None
                    };
                    coordinates.push(Coordinate { name: n, comment });
                }
            }
        }
    }

    let kinetic = get(top, "kinetic").and_then(|n| cx.expr(n, "`kinetic`"));
    let potential = get(top, "potential").and_then(|n| cx.expr(n, "`potential`"));
    let mut generalized_forces = Vec::new();
    if let Some(node) = get(top, "generalized_forces") {
        if let Some(entries) = cx.map(
            node,
            "`generalized_forces`",
            "generalized_forces: { x: -c*x_dot }",
        ) {
            for (k, v) in entries {
                if let Some(e) = cx.expr(v, "a generalized force") {
                    generalized_forces.push((k.clone(), e));
                }
            }
        }
    }

    let mut points = Vec::new();
    if let Some(node) = get(top, "points") {
        if let Some(entries) = cx.map(node, "`points`", "points: { P: [l*cos(q), l*sin(q)] }") {
            for (k, v) in entries {
                if let Some(position) = cx.vector(v, &format!("point `{}`", k.value)) {
                    points.push(Point {
                        name: k.clone(),
                        position,
                        location: v.location,
                    });
                }
            }
        }
    }

    let mut bodies = Vec::new();
    if let Some(node) = get(top, "bodies") {
        if let Some(entries) = cx.map(node, "`bodies`", "bodies: { bob: { mass: m, at: P } }") {
            for (k, v) in entries {
                let what = format!("body `{}`", k.value);
                let Some(f) = cx.map(
                    v,
                    &what,
                    "{ mass: m, at: P } or { mass: m, inertia: m*l^2/12, com: G, angle: theta }",
                ) else {
                    continue;
                };
                let rigid = get(f, "inertia").is_some()
                    || get(f, "com").is_some()
                    || get(f, "angle").is_some();
                if rigid {
                    cx.keys(
                        f,
                        v.location,
                        &format!("{what} (a planar rigid body)"),
                        &["mass", "inertia", "com", "angle"],
                        &["mass", "inertia", "com", "angle"],
                    );
                    let mass = get(f, "mass").and_then(|n| cx.expr(n, "`mass`"));
                    let inertia = get(f, "inertia").and_then(|n| cx.expr(n, "`inertia`"));
                    let com = get(f, "com").and_then(|n| cx.name(n, "`com`"));
                    let angle = get(f, "angle").and_then(|n| cx.expr(n, "`angle`"));
                    if let (Some(mass), Some(inertia), Some(com), Some(angle)) =
                        (mass, inertia, com, angle)
                    {
                        bodies.push(Body {
                            name: k.clone(),
                            kind: BodyKind::Rigid {
                                mass,
                                inertia,
                                com,
                                angle,
                            },
                        });
                    }
                } else {
                    cx.keys(
                        f,
                        v.location,
                        &format!("{what} (a particle)"),
                        &["mass", "at", "inertia", "com", "angle"],
                        &["mass", "at"],
                    );
                    let mass = get(f, "mass").and_then(|n| cx.expr(n, "`mass`"));
                    let at = get(f, "at").and_then(|n| cx.name(n, "`at`"));
                    if let (Some(mass), Some(at)) = (mass, at) {
                        bodies.push(Body {
                            name: k.clone(),
                            kind: BodyKind::Particle { mass, at },
                        });
                    }
                }
            }
        }
    }

    let gravity = get(top, "gravity").and_then(|n| {
        cx.vector(n, "`gravity`")
            .map(|g| Located::new(g, n.location))
    });

    let mut springs = Vec::new();
    let mut dampers = Vec::new();
    let mut forces = Vec::new();
    let mut torques = Vec::new();
    if let Some(node) = get(top, "springs") {
        if let Some(entries) = cx.map(
            node,
            "`springs`",
            "springs: { s: { between: [A, B], stiffness: k, rest_length: l0 } }",
        ) {
            for (k, v) in entries {
                let what = format!("spring `{}`", k.value);
                let Some(f) = cx.map(
                    v,
                    &what,
                    "{ between: [A, B], stiffness: k, rest_length: l0 }",
                ) else {
                    continue;
                };
                cx.keys(
                    f,
                    v.location,
                    &what,
                    &["between", "stiffness", "rest_length"],
                    &["between", "stiffness"],
                );
                let between = get(f, "between").and_then(|n| cx.point_pair(n, "`between`"));
                let stiffness = get(f, "stiffness").and_then(|n| cx.expr(n, "`stiffness`"));
                let rest_length = get(f, "rest_length").and_then(|n| cx.expr(n, "`rest_length`"));
                if let (Some(between), Some(stiffness)) = (between, stiffness) {
                    springs.push(Spring {
                        name: k.clone(),
                        between,
                        stiffness,
                        rest_length,
                    });
                }
            }
        }
    }
    if let Some(node) = get(top, "dampers") {
        if let Some(entries) = cx.map(
            node,
            "`dampers`",
            "dampers: { d: { between: [A, B], coefficient: c } }",
        ) {
            for (k, v) in entries {
                let what = format!("damper `{}`", k.value);
                let Some(f) = cx.map(v, &what, "{ between: [A, B], coefficient: c }") else {
                    continue;
                };
                cx.keys(
                    f,
                    v.location,
                    &what,
                    &["between", "coefficient"],
                    &["between", "coefficient"],
                );
                let between = get(f, "between").and_then(|n| cx.point_pair(n, "`between`"));
                let coefficient = get(f, "coefficient").and_then(|n| cx.expr(n, "`coefficient`"));
                if let (Some(between), Some(coefficient)) = (between, coefficient) {
                    dampers.push(Damper {
                        name: k.clone(),
                        between,
                        coefficient,
                    });
                }
            }
        }
    }
    if let Some(node) = get(top, "forces") {
        if let Some(entries) = cx.map(
            node,
            "`forces`",
            "forces: { push: { at: P, vector: [F0*step(t), 0] } }",
        ) {
            for (k, v) in entries {
                let what = format!("force `{}`", k.value);
                let Some(f) = cx.map(v, &what, "{ at: P, vector: [Fx, Fy] }") else {
                    continue;
                };
                cx.keys(f, v.location, &what, &["at", "vector"], &["at", "vector"]);
                let at = get(f, "at").and_then(|n| cx.name(n, "`at`"));
                let vector = get(f, "vector")
                    .and_then(|n| cx.vector(n, "`vector`").map(|x| (x, n.location)));
                if let (Some(at), Some((vector, location))) = (at, vector) {
                    forces.push(Force {
                        name: k.clone(),
                        at,
                        vector,
                        location,
                    });
                }
            }
        }
    }
    if let Some(node) = get(top, "torques") {
        if let Some(entries) = cx.map(
            node,
            "`torques`",
            "torques: { motor: { body: arm, value: tau0 } }",
        ) {
            for (k, v) in entries {
                let what = format!("torque `{}`", k.value);
                let Some(f) = cx.map(v, &what, "{ body: B, value: tau }") else {
                    continue;
                };
                cx.keys(f, v.location, &what, &["body", "value"], &["body", "value"]);
                let body = get(f, "body").and_then(|n| cx.name(n, "`body`"));
                let value = get(f, "value").and_then(|n| cx.expr(n, "`value`"));
                if let (Some(body), Some(value)) = (body, value) {
                    torques.push(Torque {
                        name: k.clone(),
                        body,
                        value,
                    });
                }
            }
        }
    }

    let mut initial = Vec::new();
    if let Some(node) = get(top, "initial") {
        if let Some(entries) = cx.map(node, "`initial`", "initial: { theta: pi/2, theta_dot: 0 }") {
            for (k, v) in entries {
                if let Some(e) = cx.expr(v, "an initial value") {
                    initial.push((k.clone(), e));
                }
            }
        }
    }

    let mut draw = Draw::default();
    if let Some(node) = get(top, "draw") {
        if let Some(f) = cx.map(node, "`draw`", "draw: { lines: [[O, P]], trace: [P] }") {
            cx.keys(f, node.location, "`draw`", &["lines", "trace"], &[]);
            if let Some(lines) =
                get(f, "lines").and_then(|n| cx.seq(n, "`lines`", "lines: [[O, E], [E, H]]"))
            {
                for l in lines {
                    if let Some(pair) = cx.point_pair(l, "a line") {
                        draw.lines.push(pair);
                    }
                }
            }
            if let Some(trace) = get(f, "trace").and_then(|n| cx.seq(n, "`trace`", "trace: [H]")) {
                for p in trace {
                    if let Some(n) = cx.name(p, "a traced point") {
                        draw.trace.push(n);
                    }
                }
            }
        }
    }

    let dimension = points.first().map(|p| p.position.len());
    if cx.errors.is_empty() {
        Ok(ModelFile {
            path: path.to_string(),
            name,
            description,
            parameters,
            coordinates,
            kinetic,
            potential,
            generalized_forces,
            points,
            bodies,
            gravity,
            springs,
            dampers,
            forces,
            torques,
            initial,
            draw,
            dimension,
        })
    } else {
        Err(cx.errors)
    }
}
