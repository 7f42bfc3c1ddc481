//! The states of a model named in its file: the initial state, events (functions of the
//! state that cross zero) and equilibria.

use super::walk::{Fields, Keyed, Need};
use super::write::{NotRewritten, Writer, flow, scalar};
use super::*;

/// The keys of an output written as a map.
const OUTPUT: Fields = Fields {
    kind: "output",
    keys: &[
        ("value", Need::Required),
        ("conserved", Need::Optional),
        ("tolerance", Need::Optional),
    ],
    example: "{ value: m*cross(P - O, vel(P)), conserved: true, tolerance: 1e-9 }",
};

/// The keys of an event written as a map.
const EVENT: Fields = Fields {
    kind: "event",
    keys: &[
        ("when", Need::Required),
        ("direction", Need::Optional),
        ("terminal", Need::Optional),
    ],
    example: "{ when: theta_dot, direction: falling, terminal: false }",
};

impl Ctx<'_> {
    /// `initial:` — values, or `{ guess: value }` for coordinates solved from the constraints.
    pub(super) fn initial(&mut self, node: &YamlNode) -> (KeyedExprs, Vec<Located<String>>) {
        let spec = Keyed {
            what: "`initial`",
            example: "initial: { theta: pi/2, theta_dot: 0 }",
            names: None,
            drop: false,
        };
        let entries = self.keyed(node, spec, |cx, k, v| {
            let what = format!("an initial value (`{}`)", k.value);
            if let YamlKind::Map(inner) = &v.kind {
                if inner.len() == 1 && inner[0].0.value == "guess" {
                    let e = cx.expr(&inner[0].1, &what)?;
                    Some((k.clone(), e, true))
                } else {
                    cx.error(
                        Diagnostic::new(v.location, format!("{what} is an expression or `{{ guess: value }}`"))
                            .with_help("`{ guess: 0.5 }` marks a starting guess that the runtime corrects to satisfy the constraints"),
                    );
                    None
                }
            } else {
                let e = cx.expr(v, &what)?;
                Some((k.clone(), e, false))
            }
        });
        let guesses = entries
            .iter()
            .filter(|(_, _, guess)| *guess)
            .map(|(k, _, _)| k.clone())
            .collect();
        let values = entries.into_iter().map(|(k, e, _)| (k, e)).collect();
        (values, guesses)
    }

    /// `outputs:` — `name: expr` or `name: { value: expr, conserved: true|false,
    /// tolerance: number }`.
    pub(super) fn outputs(&mut self, node: &YamlNode) -> Vec<OutputDef> {
        let spec = Keyed {
            what: "`outputs`",
            example: "outputs: { L: m*cross(P - O, vel(P)) }",
            names: Some("output"),
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let what = format!("output `{}`", k.value);
            if !matches!(v.kind, YamlKind::Map(_)) {
                let value = cx.expr(v, &what)?;
                return Some(OutputDef {
                    name: k.clone(),
                    value,
                    conserved: false,
                    tolerance: DEFAULT_CHECK_TOLERANCE,
                });
            }
            let f = cx.fields(k, v, &OUTPUT)?;
            let value = get(f, "value").and_then(|n| cx.expr(n, &what));
            let conserved = match get(f, "conserved") {
                None => Some(false),
                Some(n) => cx.choice(
                    n,
                    &format!("`conserved` of output `{}`", k.value),
                    &[("true", true), ("false", false)],
                ),
            };
            let tolerance = cx.number_or(f, "tolerance", &what, DEFAULT_CHECK_TOLERANCE);
            Some(OutputDef {
                name: k.clone(),
                value: value?,
                conserved: conserved?,
                tolerance: tolerance?,
            })
        })
    }

    /// `events:` — `name: g` or `name: { when: g, direction: rising|falling|both,
    /// terminal: true|false }`, where `g` is an expression (the event is `g = 0`) or an
    /// equation `lhs = rhs`.
    pub(super) fn events(&mut self, node: &YamlNode) -> Vec<EventDef> {
        let example = format!("events: {{ peak: {} }}", EVENT.example);
        let spec = Keyed {
            what: "`events`",
            example: &example,
            names: Some("event"),
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let what = format!("the function of event `{}`", k.value);
            if !matches!(v.kind, YamlKind::Map(_)) {
                let when = cx.event_function(v, &what)?;
                return Some(EventDef {
                    name: k.clone(),
                    when,
                    direction: Crossing::Both,
                    terminal: false,
                });
            }
            let f = cx.fields(k, v, &EVENT)?;
            let when = get(f, "when").and_then(|n| cx.event_function(n, &what));
            let direction = match get(f, "direction") {
                None => Some(Crossing::Both),
                Some(n) => cx.choice(
                    n,
                    &format!("the direction of event `{}`", k.value),
                    &[
                        ("rising", Crossing::Rising),
                        ("falling", Crossing::Falling),
                        ("both", Crossing::Both),
                    ],
                ),
            };
            let terminal = match get(f, "terminal") {
                None => Some(false),
                Some(n) => cx.choice(
                    n,
                    &format!("`terminal` of event `{}`", k.value),
                    &[("true", true), ("false", false)],
                ),
            };
            Some(EventDef {
                name: k.clone(),
                when: when?,
                direction: direction?,
                terminal: terminal?,
            })
        })
    }

    /// The function of an event: an expression `g` (the event is `g = 0`), or an equation
    /// `lhs = rhs`, which means `lhs − rhs = 0` (as `--stop-when "y = 0"` on the command line).
    pub(super) fn event_function(&mut self, node: &YamlNode, what: &str) -> Option<Expr> {
        let (lhs, rhs) = self.sides(
            node,
            what,
            "write the event as one expression that crosses zero, such as `y` or `x = l`",
        )?;
        Some(match rhs {
            None => lhs,
            // The `=` is not kept: the difference is located at its right side.
            Some(rhs) => Expr {
                location: lhs.location,
                kind: ExprKind::Binary {
                    op: BinOp::Sub,
                    op_location: rhs.location,
                    lhs: Box::new(lhs),
                    rhs: Box::new(rhs),
                },
            },
        })
    }

    /// `equilibria:` — `name: { coordinate: value, … }`; a steady motion also gives rates
    /// (`phi_dot: Omega`) and the coordinates it leaves out (`ignorable: [phi]`). A coordinate
    /// written `{ held: value }` is held, a rate written `{ guess: value }` is found, and
    /// `turning: { angle: yaw, plane: [x, y] }` makes the entry a steady turn.
    pub(super) fn equilibria(&mut self, node: &YamlNode) -> Vec<EquilibriumDef> {
        let spec = Keyed {
            what: "`equilibria`",
            example: "equilibria: { hanging: { theta: 0 }, upright: { theta: pi } }",
            names: Some("equilibrium"),
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let what = format!("equilibrium `{}`", k.value);
            let entries = cx.map(v, &what, &format!("{}: {{ theta: pi }}", k.value))?;
            let mut ignorable = Vec::new();
            let mut values = Vec::new();
            let (mut held, mut solved) = (Vec::new(), Vec::new());
            let mut turning = None;
            for (c, e) in entries {
                if c.value == "ignorable" {
                    if let Some(items) = cx.seq(e, "`ignorable`", "ignorable: [phi]") {
                        ignorable.extend(items.iter().filter_map(|i| cx.name(i, "a coordinate")));
                    }
                    continue;
                }
                if c.value == "turning" {
                    turning = cx.turning(c, e, &what);
                    continue;
                }
                let value_what = format!("the value of `{}` in {what}", c.value);
                let (node, mark) = match marked_value(e) {
                    Some((mark, inner)) => (inner, Some(mark)),
                    None if matches!(e.kind, YamlKind::Map(_)) => {
                        cx.error(
                            Diagnostic::new(e.location, format!("{value_what} is an expression, `{{ held: value }}` or `{{ guess: value }}`"))
                                .with_help("`lean: { held: 0.1 }` holds a coordinate that the search would find; `front_wheel_dot: { guess: 17 }` finds a rate that it would hold"),
                        );
                        continue;
                    }
                    None => (e, None),
                };
                let Some(expr) = cx.expr(node, &value_what) else { continue };
                match mark {
                    Some("held") => held.push(c.clone()),
                    Some(_) => solved.push(c.clone()),
                    None => {}
                }
                values.push((c.clone(), expr));
            }
            Some(EquilibriumDef {
                name: k.clone(),
                values,
                ignorable,
                held,
                solved,
                turning,
            })
        })
    }

    /// `turning: { angle: yaw, plane: [x, y] }` of the equilibrium `what`, at the key `key`.
    fn turning(
        &mut self,
        key: &Located<String>,
        node: &YamlNode,
        what: &str,
    ) -> Option<TurningDef> {
        let example = "turning: { angle: yaw, plane: [x, y] }";
        let entries = self.map(node, &format!("`turning` of {what}"), example)?;
        let (mut angle, mut plane) = (None, None);
        for (k, v) in entries {
            match k.value.as_str() {
                "angle" => angle = self.name(v, "a coordinate"),
                "plane" => {
                    let items = self.seq(v, "`plane`", "plane: [x, y]")?;
                    let names: Vec<_> = items
                        .iter()
                        .filter_map(|i| self.name(i, "a coordinate"))
                        .collect();
                    if names.len() != 2 {
                        self.error(
                            Diagnostic::new(v.location, format!("`plane` of `turning` names {} coordinates, not two", names.len()))
                                .with_help("name the two Cartesian coordinates whose rates turn with the frame: `plane: [x, y]`"),
                        );
                        return None;
                    }
                    plane = Some(names);
                }
                other => {
                    self.error(
                        Diagnostic::new(
                            k.location,
                            format!("unknown key `{other}` in `turning` of {what}"),
                        )
                        .with_help(format!("`turning` takes `angle` and `plane`: `{example}`")),
                    );
                    return None;
                }
            }
        }
        match (angle, plane) {
            (Some(angle), Some(plane)) => Some(TurningDef {
                angle,
                plane,
                at: key.location,
            }),
            _ => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("`turning` of {what} needs `angle` and `plane`"),
                    )
                    .with_help(format!("write it like `{example}`")),
                );
                None
            }
        }
    }
}

/// The writers of `outputs:`, `initial:`, `equilibria:` and `events:`.
impl Writer<'_> {
    /// `outputs:`, each left out (and noted) where it cannot be rewritten.
    pub(super) fn write_outputs(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        let mut block = String::new();
        for o in &file.outputs {
            let place = format!("output `{}`", o.name.value);
            match self.expr(&o.value, &place) {
                Ok(v) if o.conserved => block.push_str(&format!(
                    "  {}: {{ value: {}, conserved: true, tolerance: {:e} }}\n",
                    o.name.value,
                    flow(&v),
                    o.tolerance
                )),
                Ok(v) => block.push_str(&format!("  {}: {}\n", o.name.value, scalar(&v))),
                Err(e) => self
                    .notes
                    .push(format!("output `{}` left out: {}", o.name.value, e.message)),
            }
        }
        self.block("outputs", &block);
        Ok(())
    }

    /// `initial:`: the values and rates given (guesses marked as such in a file written as it
    /// is), noting the rates of eliminated coordinates left out.
    pub(super) fn write_initial(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        let initial: Vec<(String, Expr)> = match &self.edits.initial {
            Some(initial) => initial.clone(),
            None => file
                .initial
                .iter()
                .map(|(n, e)| (n.value.clone(), e.clone()))
                .collect(),
        };
        let preserve = self.preserve();
        if !initial.is_empty() {
            let parts: Vec<String> = initial
                .iter()
                .map(|(n, e)| {
                    if preserve && file.initial_guesses.iter().any(|g| g.value == *n) {
                        format!("{n}: {{ guess: {} }}", flow(&e.to_string()))
                    } else {
                        format!("{n}: {}", flow(&e.to_string()))
                    }
                })
                .collect();
            self.line(format_args!("initial: {{ {} }}", parts.join(", ")));
        }
        let dropped_rates: Vec<&str> = file
            .initial
            .iter()
            .map(|(n, _)| n.value.as_str())
            .filter(|n| !self.is_kept_name(n) && n.ends_with("_dot"))
            .collect();
        if !dropped_rates.is_empty() {
            self.notes.push(format!(
                "the initial rates of eliminated coordinates ({}) are left out: the kept rates \
                 alone set the motion",
                dropped_rates.join(", ")
            ));
        }
        if !preserve && file.initial_guesses.iter().any(|g| self.is_kept(&g.value)) {
            self.notes.push(
                "a kept coordinate's initial value was a guess; the reduced file starts at \
                 the guess"
                    .to_string(),
            );
        }
        Ok(())
    }

    /// `equilibria:`, less those the transformer leaves out (noted), each with the values of
    /// the kept coordinates and its ignorable ones.
    pub(super) fn write_equilibria(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        let mut block = String::new();
        for eq in &file.equilibria {
            let dropped = self
                .edits
                .dropped_equilibria
                .iter()
                .find(|(name, _)| *name == eq.name.value);
            if let Some((_, note)) = dropped {
                self.notes.push(note.clone());
                continue;
            }
            let mut parts: Vec<String> = eq
                .values
                .iter()
                .filter(|(n, _)| self.is_kept_name(&n.value))
                .map(|(n, e)| {
                    let value = flow(&e.to_string());
                    if eq.held.iter().any(|h| h.value == n.value) {
                        format!("{}: {{ held: {value} }}", n.value)
                    } else if eq.solved.iter().any(|h| h.value == n.value) {
                        format!("{}: {{ guess: {value} }}", n.value)
                    } else {
                        format!("{}: {value}", n.value)
                    }
                })
                .collect();
            let ignorable: Vec<&str> = eq
                .ignorable
                .iter()
                .map(|n| n.value.as_str())
                .filter(|n| self.is_kept(n))
                .collect();
            if !ignorable.is_empty() {
                parts.push(format!("ignorable: [{}]", ignorable.join(", ")));
            }
            if let Some(t) = &eq.turning {
                let names: Vec<&str> = std::iter::once(&t.angle)
                    .chain(&t.plane)
                    .map(|n| n.value.as_str())
                    .collect();
                if names.iter().all(|n| self.is_kept(n)) {
                    parts.push(format!(
                        "turning: {{ angle: {}, plane: [{}] }}",
                        names[0],
                        names[1..].join(", ")
                    ));
                } else {
                    self.notes.push(format!(
                        "the steady turn `{}` lost its turning frame: a coordinate of it was removed",
                        eq.name.value
                    ));
                }
            }
            block.push_str(&format!(
                "  {}: {{ {} }}\n",
                eq.name.value,
                parts.join(", ")
            ));
            self.kept_equilibria.push(eq.name.value.clone());
        }
        self.block("equilibria", &block);
        Ok(())
    }

    /// `events:`: those that end runs where the transformer's coordinates are singular
    /// (each noted), then the file's, each left out (and noted) where it cannot be
    /// rewritten.
    pub(super) fn write_events(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        let mut block = String::new();
        for (note, event) in &self.edits.singular {
            self.notes.push(note.clone());
            if let Some((name, when)) = event
                && !file.events.iter().any(|ev| ev.name.value == *name)
            {
                block.push_str(&format!(
                    "  {name}: {{ when: {}, direction: both, terminal: true }}\n",
                    flow(when)
                ));
            }
        }
        for ev in &file.events {
            let place = format!("event `{}`", ev.name.value);
            match self.expr(&ev.when, &place) {
                Ok(g) => {
                    let direction = match ev.direction {
                        Crossing::Rising => "rising",
                        Crossing::Falling => "falling",
                        Crossing::Both => "both",
                    };
                    block.push_str(&format!(
                        "  {}: {{ when: {}, direction: {direction}, terminal: {} }}\n",
                        ev.name.value,
                        flow(&g),
                        ev.terminal
                    ));
                    self.kept_events.push(ev.name.value.clone());
                }
                Err(e) => self
                    .notes
                    .push(format!("event `{}` left out: {}", ev.name.value, e.message)),
            }
        }
        self.block("events", &block);
        Ok(())
    }
}

/// The mark and value of `{ held: value }` or `{ guess: value }`; `None` for anything else.
fn marked_value(node: &YamlNode) -> Option<(&'static str, &YamlNode)> {
    let YamlKind::Map(inner) = &node.kind else {
        return None;
    };
    match inner.as_slice() {
        [(k, v)] if k.value == "held" => Some(("held", v)),
        [(k, v)] if k.value == "guess" => Some(("guess", v)),
        _ => None,
    }
}
