//! The top-level keys of a model file, one table ([`SECTIONS`]) that says how each is read
//! into the [`ModelFile`], and the sections about the model as a whole: its name, parameters,
//! coordinates, expressions by name and drawing.

use super::walk::{Fields, Keyed, Need};
use super::write::{Edits, NotRewritten, Rewrite, Writer, scalar};
use super::*;
use crate::model::elements::{
    body, constraint, contact, damper, energy, force, frame, gravity, interaction, nonholonomic,
    point, shape, speed, spring, torque,
};

/// How one top-level key of a model file is read, and written.
struct Section {
    /// The key.
    key: &'static str,
    /// Reads its value into the model.
    read: fn(&mut Ctx<'_>, &YamlNode, &mut ModelFile),
    /// Reports the key missing from the file's map (`top`, which starts at the location
    /// given); `None` when the key may be left out.
    missing: Option<fn(&mut Ctx<'_>, &Entries, Location)>,
    /// Writes the section of a model (nothing when it has none), or notes why it is left
    /// out.
    write: WriteSection,
}

/// Writes one section of a model file ([`Section::write`]).
type WriteSection = fn(&mut Writer<'_>, &ModelFile) -> Result<(), NotRewritten>;

/// Every top-level key, in the order the sections are read and written (a section may use
/// one read before it: `minimal_twin` the name; `checks:` is written after the equilibria and
/// events it names). The order the keys are listed to the user in is [`TOP_LEVEL_KEYS`]'s.
const SECTIONS: &[Section] = &[
    Section {
        key: "name",
        read: |cx, n, file| {
            if let Some(name) = cx.model_name(n) {
                file.name = name;
            }
        },
        missing: Some(|cx, top, at| {
            if !misspelt(top, "name") {
                cx.error(
                    Diagnostic::new(at, "the model file has no `name`").with_help(
                        "add `name: my_model` (snake_case; the generated struct is `MyModel`)",
                    ),
                );
            }
        }),
        write: |w, file| w.write_name(file),
    },
    Section {
        key: "description",
        read: |cx, n, file| file.description = cx.description(n),
        missing: None,
        write: |w, file| w.write_description(file),
    },
    Section {
        key: "units",
        read: |cx, n, file| {
            file.units = cx
                .choice(n, "`units`", &[("SI", UnitSystem::Si)])
                .map(|u| Located::new(u, n.location));
        },
        missing: None,
        write: |w, file| w.write_units(file),
    },
    Section {
        key: "minimal_twin",
        read: |cx, n, file| {
            file.minimal_twin = cx
                .name(n, "`minimal_twin`")
                .and_then(|twin| cx.minimal_twin(twin, &file.name));
        },
        missing: None,
        write: |w, file| w.write_minimal_twin(file),
    },
    Section {
        key: "parameters",
        read: |cx, n, file| file.parameters = cx.parameters(n),
        missing: None,
        write: |w, file| w.write_parameters(file),
    },
    Section {
        key: "coordinates",
        read: |cx, n, file| file.coordinates = cx.coordinates(n),
        missing: Some(|cx, top, at| {
            if misspelt(top, "coordinates") {
                cx.incomplete.sections.push("coordinates".to_string());
            } else {
                cx.error(
                    Diagnostic::new(at, "the model file has no `coordinates`")
                        .with_help("list the generalized coordinates: `coordinates: [theta]`"),
                );
            }
        }),
        write: |w, file| w.write_coordinates(file),
    },
    Section {
        key: speed::KEY,
        read: |cx, n, file| file.speeds = speed::read(cx, n),
        missing: None,
        write: |w, file| speed::write(w, &file.speeds),
    },
    Section {
        key: energy::KINETIC,
        read: |cx, n, file| file.kinetic = energy::read_energy(cx, n, energy::KINETIC),
        missing: None,
        write: |w, file| energy::write_energy(w, energy::KINETIC, file.kinetic.as_ref()),
    },
    Section {
        key: energy::POTENTIAL,
        read: |cx, n, file| file.potential = energy::read_energy(cx, n, energy::POTENTIAL),
        missing: None,
        write: |w, file| energy::write_energy(w, energy::POTENTIAL, file.potential.as_ref()),
    },
    Section {
        key: energy::GENERALIZED_FORCES,
        read: |cx, n, file| file.generalized_forces = energy::read_generalized_forces(cx, n),
        missing: None,
        write: |w, file| energy::write_generalized_forces(w, &file.generalized_forces),
    },
    Section {
        key: frame::KEY,
        read: |cx, n, file| file.frames = frame::read(cx, n),
        missing: None,
        write: |w, file| frame::write(w, &file.frames),
    },
    Section {
        key: point::KEY,
        read: |cx, n, file| file.points = point::read(cx, n),
        missing: None,
        write: |w, file| point::write(w, &file.points),
    },
    Section {
        key: body::KEY,
        read: |cx, n, file| file.bodies = body::read(cx, n),
        missing: None,
        write: |w, file| body::write(w, &file.bodies),
    },
    Section {
        key: gravity::KEY,
        read: |cx, n, file| file.gravity = gravity::read(cx, n),
        missing: None,
        write: |w, file| gravity::write(w, file.gravity.as_ref()),
    },
    Section {
        key: spring::KEY,
        read: |cx, n, file| file.springs = spring::read(cx, n),
        missing: None,
        write: |w, file| spring::write(w, &file.springs),
    },
    Section {
        key: damper::KEY,
        read: |cx, n, file| file.dampers = damper::read(cx, n),
        missing: None,
        write: |w, file| damper::write(w, &file.dampers),
    },
    Section {
        key: force::KEY,
        read: |cx, n, file| file.forces = force::read(cx, n),
        missing: None,
        write: |w, file| force::write(w, &file.forces),
    },
    Section {
        key: torque::KEY,
        read: |cx, n, file| file.torques = torque::read(cx, n),
        missing: None,
        write: |w, file| torque::write(w, &file.torques),
    },
    Section {
        key: interaction::KEY,
        read: |cx, n, file| file.interactions = interaction::read(cx, n),
        missing: None,
        write: |w, file| interaction::write(w, &file.interactions),
    },
    Section {
        key: "outputs",
        read: |cx, n, file| file.outputs = cx.outputs(n),
        missing: None,
        write: |w, file| w.write_outputs(file),
    },
    Section {
        key: "balances",
        read: |cx, n, file| file.balances = cx.balances(n),
        missing: None,
        write: |w, file| w.write_balances(file),
    },
    Section {
        key: constraint::KEY,
        read: |cx, n, file| (file.constraints, file.point_constraints) = constraint::read(cx, n),
        missing: None,
        write: |w, file| {
            // The constraints the frames in Euler parameters generate are written with them.
            let written: Vec<_> = (file.constraints.iter())
                .filter(|(k, _)| {
                    !file.frames.iter().any(|f| {
                        frame::unit_norm(f)
                            .is_some_and(|(g, _)| g.value == k.value && g.location == k.location)
                    })
                })
                .cloned()
                .collect();
            constraint::write(w, &written, &file.point_constraints)
        },
    },
    Section {
        key: nonholonomic::KEY,
        read: |cx, n, file| (file.nonholonomic, file.rolling) = nonholonomic::read(cx, n),
        missing: None,
        write: |w, file| nonholonomic::write(w, &file.nonholonomic, &file.rolling),
    },
    Section {
        key: contact::KEY,
        read: |cx, n, file| file.contacts = contact::read(cx, n),
        missing: None,
        write: |w, file| contact::write(w, &file.contacts),
    },
    Section {
        key: "initial",
        read: |cx, n, file| (file.initial, file.initial_guesses) = cx.initial(n),
        missing: None,
        write: |w, file| w.write_initial(file),
    },
    Section {
        key: "draw",
        read: |cx, n, file| file.draw = cx.draw(n),
        missing: None,
        write: |w, file| w.write_draw(file),
    },
    Section {
        key: "equilibria",
        read: |cx, n, file| file.equilibria = cx.equilibria(n),
        missing: None,
        write: |w, file| w.write_equilibria(file),
    },
    Section {
        key: "events",
        read: |cx, n, file| file.events = cx.events(n),
        missing: None,
        write: |w, file| w.write_events(file),
    },
    Section {
        key: "floquet",
        read: |cx, n, file| file.floquet = cx.floquet(n),
        missing: None,
        write: |w, file| w.write_floquet(file),
    },
    Section {
        key: "checks",
        read: |cx, n, file| file.checks = cx.checks(n),
        missing: None,
        write: |w, file| w.write_checks(file),
    },
];

/// The YAML text of `file`, every section of the table that reads a file in its order, with
/// its expressions through `rewrite` and `edits` applied; and the notes on what was left out
/// or changed.
///
/// # Errors
/// The [`NotRewritten`] of an expression that a section cannot leave out.
pub fn write_file(
    file: &ModelFile,
    rewrite: &mut dyn Rewrite,
    edits: &Edits,
) -> Result<(String, Vec<String>), NotRewritten> {
    let mut writer = Writer::new(rewrite, edits);
    for section in SECTIONS {
        (section.write)(&mut writer, file)?;
    }
    Ok((writer.w, writer.notes))
}

/// The keys of a parameter written as a map.
const PARAMETER: Fields = Fields {
    kind: "parameter",
    keys: &[("value", Need::Required), ("unit", Need::Optional)],
    example: "{ value: 1.0, unit: kg }",
};

impl Ctx<'_> {
    /// The model of the file whose tree is `root`: reports keys planned for later and unknown
    /// keys, then reads every section of [`SECTIONS`] in turn, with what a section left out
    /// recorded under its key.
    pub(super) fn model(&mut self, path: &str, root: &YamlNode) -> Option<ModelFile> {
        let YamlKind::Map(top) = &root.kind else {
            self.error(
                Diagnostic::new(
                    root.location,
                    format!(
                        "a model file must be a map of `key: value`, found {}",
                        root.kind.describe()
                    ),
                )
                .with_help("start with `name: my_model` and `coordinates: [q]`"),
            );
            return None;
        };

        self.unknown_keys(top, "a model file", TOP_LEVEL_KEYS, TOP_LEVEL_KEYS);

        let mut file = ModelFile {
            path: path.to_string(),
            // A model without a valid name is named "" at the top of the file.
            name: Located::new(String::new(), root.location),
            description: String::new(),
            minimal_twin: None,
            units: None,
            parameters: Vec::new(),
            coordinates: Vec::new(),
            kinetic: None,
            potential: None,
            generalized_forces: Vec::new(),
            frames: Vec::new(),
            rolling: Vec::new(),
            point_constraints: Vec::new(),
            points: Vec::new(),
            bodies: Vec::new(),
            gravity: None,
            springs: Vec::new(),
            dampers: Vec::new(),
            forces: Vec::new(),
            torques: Vec::new(),
            interactions: Vec::new(),
            outputs: Vec::new(),
            speeds: Vec::new(),
            initial: Vec::new(),
            draw: Draw::default(),
            dimension: None,
            balances: Vec::new(),
            checks: Checks::default(),
            constraints: Vec::new(),
            nonholonomic: Vec::new(),
            contacts: Vec::new(),
            initial_guesses: Vec::new(),
            events: Vec::new(),
            equilibria: Vec::new(),
            floquet: Vec::new(),
        };
        for section in SECTIONS {
            self.section = section.key;
            match get(top, section.key) {
                Some(node) => (section.read)(self, node, &mut file),
                None => {
                    if let Some(missing) = section.missing {
                        missing(self, top, root.location);
                    }
                }
            }
        }
        self.section = "";
        file.dimension = file.points.first().map(Point::dimension);
        // A frame in Euler parameters keeps them of unit norm by a constraint of its own
        // (where they are coordinates: a rotation given in `t` alone needs none), unless the
        // file names one so.
        let coordinates: Vec<&str> = (file.coordinates.iter())
            .map(|c| c.name.value.as_str())
            .collect();
        let generated: Vec<_> = (file.frames.iter())
            .filter(|f| frame::moves_with_coordinates(f, &coordinates))
            .filter_map(frame::unit_norm)
            .filter(|(name, _)| !file.constraints.iter().any(|(k, _)| k.value == name.value))
            .collect();
        file.constraints.extend(generated);
        Some(file)
    }

    /// `name:` — the model's snake_case name.
    fn model_name(&mut self, node: &YamlNode) -> Option<Located<String>> {
        let n = self.name(node, "`name`")?;
        if is_snake_case(&n.value) {
            return Some(n);
        }
        let d = Diagnostic::new(
            n.location,
            format!("`name` must be snake_case, found `{}`", n.value),
        )
        .with_help(format!(
            "write `name: {}`; the generated struct takes its UpperCamelCase form",
            to_snake_case(&n.value)
        ));
        self.error(d);
        None
    }

    /// `description:` — a text, empty when left empty.
    fn description(&mut self, node: &YamlNode) -> String {
        if node.kind == YamlKind::Null {
            return String::new();
        }
        // A folded (`>`) description ends with a line break; keep the text only.
        self.text(
            node,
            "`description`",
            "description: A pendulum of length l.",
        )
        .map(|d| d.value.trim().to_string())
        .unwrap_or_default()
    }

    /// `minimal_twin:` — the snake_case name of another model, the same mechanism in minimal
    /// coordinates. Rule: it is a snake_case name (a bundled model's) and not the model's own.
    pub(super) fn minimal_twin(
        &mut self,
        twin: Located<String>,
        name: &Located<String>,
    ) -> Option<Located<String>> {
        if !is_snake_case(&twin.value) {
            let d = Diagnostic::new(
                twin.location,
                format!(
                    "`minimal_twin` must be the snake_case name of a bundled model, found `{}`",
                    twin.value
                ),
            )
            .with_help("write `minimal_twin: simple_pendulum` (see `eomgen list`)");
            self.error(d);
            return None;
        }
        if twin.value == name.value {
            let d = Diagnostic::new(
                twin.location,
                format!("`minimal_twin` names the model itself, `{}`", twin.value),
            )
            .with_help("name the model with the same mechanism in minimal coordinates, or leave the key out");
            self.error(d);
            return None;
        }
        Some(twin)
    }

    /// `parameters:` — `name: default` or `name: { value, unit }`.
    pub(super) fn parameters(&mut self, node: &YamlNode) -> Vec<Parameter> {
        // How many entries are written on each line (an entry counts once for each line its
        // key and value are on): counted once, so that the whole section is linear in its
        // number of parameters.
        let mut per_line: HashMap<u32, usize> = HashMap::new();
        if let YamlKind::Map(entries) = &node.kind {
            for (k, v) in entries {
                *per_line.entry(k.location.line).or_default() += 1;
                if v.location.line != k.location.line {
                    *per_line.entry(v.location.line).or_default() += 1;
                }
            }
        }
        let spec = Keyed {
            what: "`parameters`",
            example: "parameters: { m: 1.0, g: 9.81 }",
            names: Some("parameter"),
            drop: true,
        };
        self.keyed(node, spec, |cx, k, v| cx.parameter(k, v, &per_line))
    }

    /// One parameter, `name: default  # unit` or `name: { value, unit }`; `per_line` counts
    /// the entries written on each line (see [`Ctx::parameters`]).
    pub(super) fn parameter(
        &mut self,
        k: &Located<String>,
        v: &YamlNode,
        per_line: &HashMap<u32, usize>,
    ) -> Option<Parameter> {
        // The map form `{ value: 1.0, unit: N/m }`.
        let mut unit_key = None;
        let v = if let YamlKind::Map(_) = &v.kind {
            let f = self.fields(k, v, &PARAMETER)?;
            if let Some(u) = get(f, "unit") {
                let what = format!("the unit of parameter `{}`", k.value);
                unit_key = Some(self.text(u, &what, "unit: N/m")?);
            }
            get(f, "value")?
        } else {
            v
        };
        if v.kind == YamlKind::Null {
            self.error(
                Diagnostic::new(
                    k.location,
                    format!("parameter `{}` has no default value", k.value),
                )
                .with_help(format!("give one, as in `{}: 1.0  # kg`", k.value)),
            );
            return None;
        }
        let default = self.expr(v, &format!("the default of parameter `{}`", k.value))?;
        // Rule: parameter defaults are constant (numbers, `pi`, functions); they may not
        // refer to other parameters, coordinates or `t`.
        let mut names = Vec::new();
        identifiers(&default, &mut names);
        if let Some((n, at)) = names.into_iter().find(|(n, _)| n != "pi") {
            self.error(
                Diagnostic::new(
                    at,
                    format!(
                        "parameter defaults must be constant, but the default of `{}` uses `{n}`",
                        k.value
                    ),
                )
                .with_help("use numbers, `pi` and functions of them, as in `9.81`, `pi/4` or `sqrt(2)`; a default cannot refer to another parameter or a coordinate"),
            );
            return None;
        }
        let value = match eval_expr(&default, &|_| None) {
            Ok(value) => value,
            Err(d) => {
                self.error(d);
                return None;
            }
        };
        if !value.is_finite() {
            self.error(
                Diagnostic::new(
                    v.location,
                    format!(
                        "parameter `{}` has the non-finite default `{value}`",
                        k.value
                    ),
                )
                .with_help("a default must evaluate to a finite number"),
            );
            return None;
        }
        // The unit is the comment at the end of the value's line, if no other parameter
        // shares that line (`parameters: { m: 1, g: 9.81 }  # SI` names no unit).
        let line = v.location.line;
        let shared = per_line.get(&line).copied().unwrap_or(0) > 1;
        let unit = if unit_key.is_some() || shared {
            unit_key
        } else {
            let text = self.line(line);
            trailing_comment_of_line(text).map(|c| {
                let at = comment_location(text, line, &c);
                Located::new(c, at)
            })
        };
        Some(Parameter {
            name: k.clone(),
            default,
            value,
            unit,
        })
    }

    /// `coordinates:` — a list of names, each possibly `{ name, unit }`, whose trailing
    /// comments describe them.
    pub(super) fn coordinates(&mut self, node: &YamlNode) -> Vec<Coordinate> {
        let items = match &node.kind {
            YamlKind::Seq(items) => items,
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("`coordinates` must be a list of names, found {}", other.describe()),
                    )
                    .with_help("write `coordinates: [theta1, theta2]`, or one `- theta1  # comment` per line"),
                );
                return Vec::new();
            }
        };
        // How many coordinates start on each line, counted once (not per coordinate, which
        // was quadratic in a long one-line list).
        let mut per_line: HashMap<u32, usize> = HashMap::new();
        for item in items {
            *per_line.entry(item.location.line).or_default() += 1;
        }
        let mut out = Vec::new();
        for item in items {
            // The map form `{ name: x, unit: m }`.
            let mut unit = None;
            let named = if let YamlKind::Map(f) = &item.kind {
                const EXAMPLE: &str = "{ name: x, unit: m }";
                self.unknown_keys(f, "a coordinate", &["name", "unit"], &["name", "unit"]);
                if !self.require(f, item.location, "a coordinate", &["name"], EXAMPLE) {
                    continue;
                }
                if let Some(u) = get(f, "unit") {
                    unit = self.text(u, "the unit of a coordinate", "unit: m");
                }
                match get(f, "name") {
                    Some(n) => n,
                    None => continue,
                }
            } else {
                item
            };
            let Some(n) = self.name(named, "a coordinate") else {
                if let YamlKind::Scalar { text, .. } = &named.kind {
                    self.drop_name(text);
                }
                continue;
            };
            // A trailing comment describes the coordinate only if it is alone on its line.
            let alone = per_line[&item.location.line] == 1;
            let comment = if alone {
                trailing_comment_of_line(self.line(n.location.line))
            } else {
                None
            };
            out.push(Coordinate {
                name: n,
                comment,
                unit,
            });
        }
        // Rule: at most `MAX_COORDINATES` coordinates. The list is kept, so that the rest of
        // the file is checked against it (in time linear in its length) and this is the one
        // error of an otherwise sound file.
        if out.len() > MAX_COORDINATES {
            self.error(
                Diagnostic::new(
                    node.location,
                    format!(
                        "the model has {} generalized coordinates, more than the {MAX_COORDINATES} a model may have: its mass matrix is derived and evaluated as a dense {}×{} matrix",
                        out.len(),
                        out.len(),
                        out.len()
                    ),
                )
                .with_help(format!(
                    "use at most {MAX_COORDINATES} coordinates (a chain of {MAX_COORDINATES} masses loads, checks and takes its first step in seconds)"
                )),
            );
        }
        out
    }

    /// A map of names to expressions (`generalized_forces`, `constraints`, `nonholonomic`):
    /// `what` names it and `example` writes it in messages, `item` names one value.
    pub(crate) fn keyed_exprs(
        &mut self,
        node: &YamlNode,
        what: &str,
        example: &str,
        item: &str,
    ) -> Vec<(Located<String>, Expr)> {
        let spec = Keyed {
            what,
            example,
            names: None,
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let e = cx.expr(v, &format!("{item} (`{}`)", k.value))?;
            Some((k.clone(), e))
        })
    }

    /// `draw:` — `{ lines: [[A, B], …], trace: [P, …] }`.
    pub(super) fn draw(&mut self, node: &YamlNode) -> Draw {
        let mut draw = Draw::default();
        let Some(f) = self.map(node, "`draw`", "draw: { lines: [[O, P]], trace: [P] }") else {
            return draw;
        };
        const KEYS: [&str; 4] = ["lines", "trace", "wheels", "shapes"];
        self.unknown_keys(f, "`draw`", &KEYS, &KEYS);
        if let Some(lines) =
            get(f, "lines").and_then(|n| self.seq(n, "`lines`", "lines: [[O, E], [E, H]]"))
        {
            for l in lines {
                if let Some(pair) = self.point_pair(l, "a line") {
                    draw.lines.push(pair);
                }
            }
        }
        if let Some(trace) = get(f, "trace").and_then(|n| self.seq(n, "`trace`", "trace: [H]")) {
            for p in trace {
                if let Some(n) = self.name(p, "a traced point") {
                    draw.trace.push(n);
                }
            }
        }
        if let Some(wheels) = get(f, "wheels").and_then(|n| {
            self.seq(
                n,
                "`wheels`",
                "wheels: [{ centre: RH, frame: WR, axle: y, radius: rR }]",
            )
        }) {
            for w in wheels {
                let k = Located::new("wheel".to_string(), w.location);
                if let Some(wheel) = point::read_wheel(self, &k, w) {
                    draw.wheels.push(wheel);
                }
            }
        }
        if let Some(shapes) = get(f, "shapes") {
            draw.shapes = shape::read(self, shapes);
        }
        draw
    }
}

/// The writers of the sections about the model as a whole ([`SECTIONS`]).
impl Writer<'_> {
    /// A transformer's header, then `name:`.
    fn write_name(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        self.w.push_str(&self.edits.header);
        let name = self.edits.name.as_deref().unwrap_or(&file.name.value);
        self.line(format_args!("name: {name}"));
        Ok(())
    }

    /// `description:`.
    fn write_description(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        let description = self
            .edits
            .description
            .as_deref()
            .unwrap_or(&file.description);
        self.line(format_args!("description: {}", scalar(description)));
        Ok(())
    }

    /// `units: SI`, if given.
    fn write_units(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        if file.units.is_some() {
            self.line("units: SI");
        }
        Ok(())
    }

    /// `minimal_twin:` of a file written as it is (a reduced model is minimal itself).
    fn write_minimal_twin(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        match &file.minimal_twin {
            Some(twin) if self.preserve() => {
                self.line(format_args!("minimal_twin: {}", twin.value))
            }
            Some(_) => self
                .notes
                .push("`minimal_twin:` left out (the reduced model is minimal)".to_string()),
            None => {}
        }
        Ok(())
    }

    /// `parameters:`, each default with its unit as a comment.
    fn write_parameters(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        if file.parameters.is_empty() {
            return Ok(());
        }
        self.line("parameters:");
        for p in &file.parameters {
            let value = format!("  {}: {}", p.name.value, scalar(&p.default.to_string()));
            match &p.unit {
                Some(u) => self.line(format_args!("{value}  # {}", u.value)),
                None => self.line(value),
            }
        }
        Ok(())
    }

    /// `coordinates:`, those kept, each with its unit or comment.
    fn write_coordinates(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        self.line("coordinates:");
        for c in &file.coordinates {
            if !self.is_kept(&c.name.value) {
                continue;
            }
            match (&c.unit, &c.comment) {
                (Some(u), _) => self.line(format_args!(
                    "  - {{ name: {}, unit: {} }}",
                    c.name.value, u.value
                )),
                (None, Some(comment)) => {
                    self.line(format_args!("  - {}  # {}", c.name.value, comment.trim()));
                }
                (None, None) => self.line(format_args!("  - {}", c.name.value)),
            }
        }
        Ok(())
    }

    /// `draw:`: its lines, traces and wheels.
    fn write_draw(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        let mut wheels = Vec::new();
        for wheel in &file.draw.wheels {
            wheels.push(point::wheel_text(self, wheel, "`draw: wheels:`")?);
        }
        let lines: Vec<String> = file
            .draw
            .lines
            .iter()
            .map(|[a, b]| format!("[{}, {}]", a.value, b.value))
            .collect();
        let trace: Vec<&str> = file.draw.trace.iter().map(|p| p.value.as_str()).collect();
        let mut parts = Vec::new();
        if !lines.is_empty() {
            parts.push(format!("lines: [{}]", lines.join(", ")));
        }
        if !trace.is_empty() {
            parts.push(format!("trace: [{}]", trace.join(", ")));
        }
        if !wheels.is_empty() {
            parts.push(format!("wheels: [{}]", wheels.join(", ")));
        }
        parts.extend(shape::write(self, &file.draw.shapes)?);
        if !parts.is_empty() {
            self.line(format_args!("draw: {{ {} }}", parts.join(", ")));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every top-level key has exactly one reader, and every reader a listed key.
    #[test]
    fn every_top_level_key_has_one_section() {
        let mut read: Vec<&str> = SECTIONS.iter().map(|s| s.key).collect();
        let mut listed = TOP_LEVEL_KEYS.to_vec();
        read.sort_unstable();
        listed.sort_unstable();
        assert_eq!(read, listed);
    }
}
