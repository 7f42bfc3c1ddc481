//! The names of a model file: each defined once, none reserved, and every section that must be
//! there.

use super::*;

impl Checker<'_> {
    // Rule: parameters, coordinates, speeds, points and bodies have distinct names, none of which is
    // `t`, `pi` or a function name, or ends in `_dot` / `_ddot` (those spell rates and
    // accelerations of coordinates). Parameters and coordinates are Rust names in generated
    // code (fields and locals, a keyword as `r#type`), so none is one of the keywords that
    // cannot be raw (`self`, `Self`, `super`, `crate`); nor is the model's struct `Self`.
    // (Points and bodies are only strings there: any name will do.)
    pub(super) fn names(&mut self) {
        let file = self.file;
        let model = &file.name;
        if schema::struct_name(&model.value) == "Self" {
            self.error(
                Diagnostic::new(
                    model.location,
                    format!(
                        "model name `{}` is reserved: its struct would be `Self`, a Rust keyword",
                        model.value
                    ),
                )
                .with_help("choose another name, such as `self_model`"),
            );
        }
        // First place and kind of each name (a map: a file of many names stays linear).
        let mut seen: std::collections::HashMap<&str, (Location, &str)> =
            std::collections::HashMap::new();
        let named = file
            .parameters
            .iter()
            .map(|p| (&p.name, "parameter"))
            .chain(file.coordinates.iter().map(|c| (&c.name, "coordinate")))
            .chain(file.speeds.iter().map(|s| (&s.name, "speed")))
            .chain(file.points.iter().map(|p| (&p.name, "point")))
            .chain(file.bodies.iter().map(|b| (&b.name, "body")));
        for (name, kind) in named {
            let n = name.value.as_str();
            if n == "t" || n == "pi" || FUNCTIONS.iter().any(|(f, _)| *f == n) {
                let why = match n {
                    "t" => "`t` is time".to_string(),
                    "pi" => "`pi` is π".to_string(),
                    _ => format!("`{n}` is a function"),
                };
                self.error(
                    Diagnostic::new(
                        name.location,
                        format!("{kind} name `{n}` is reserved: {why}"),
                    )
                    .with_help("choose another name"),
                );
            } else if matches!(kind, "parameter" | "coordinate" | "speed")
                && UNRAW_KEYWORDS.contains(&n)
            {
                self.error(
                    Diagnostic::new(
                        name.location,
                        format!(
                            "{kind} name `{n}` is reserved: `{n}` is a Rust keyword, which generated code cannot use as a name (not even as `r#{n}`)"
                        ),
                    )
                    .with_help(format!(
                        "choose another name, such as `{}_`; other keywords (`type`, `box`) are fine",
                        n.to_lowercase()
                    )),
                );
            } else if n.ends_with("_dot") || n.ends_with("_ddot") {
                self.error(
                    Diagnostic::new(
                        name.location,
                        format!("{kind} name `{n}` ends in `_dot` or `_ddot`, which spell rates"),
                    )
                    .with_help(
                        "the rate of coordinate `x` is written `x_dot` without being declared; choose another name",
                    ),
                );
            }
            if let Some((first, first_kind)) = seen.get(n) {
                self.error(
                    Diagnostic::new(
                        name.location,
                        format!("duplicate name `{n}`: already a {first_kind} at {first}"),
                    )
                    .with_help("parameters, coordinates, speeds, points and bodies share one namespace; rename one"),
                );
            } else {
                seen.insert(n, (name.location, kind));
            }
        }
    }

    // Rule: the model has at least one coordinate, and inertia: `kinetic` or at least one
    // body.
    pub(super) fn presence(&mut self) {
        let file = self.file;
        if file.coordinates.is_empty() && !self.incomplete.has_section("coordinates") {
            self.error(
                Diagnostic::new(file.name.location, "the model has no coordinates")
                    .with_help("list the generalized coordinates: `coordinates: [q]`"),
            );
        }
        if file.kinetic.is_none()
            && file.bodies.is_empty()
            && !self.incomplete.has_section("kinetic")
            && !self.incomplete.has_section("bodies")
        {
            self.error(
                Diagnostic::new(
                    file.name.location,
                    "no kinetic energy: give `kinetic:` or `bodies:`",
                )
                .with_help("energy form: `kinetic: m*x_dot^2/2`; kinematic form: `bodies: { bob: { mass: m, at: P } }`"),
            );
        }
    }

    pub(super) fn parameter_name(&mut self, name: &Located<String>, what: &str) {
        let n = name.value.as_str();
        if self.sets.params.contains(n) || self.incomplete.has_name(n) {
            return;
        }
        let d = Diagnostic::new(name.location, format!("{what}: `{n}` is not a parameter"));
        let d = match closest(n, &self.params) {
            Some(c) => d.with_help(format!("did you mean `{c}`?")),
            None => d.with_help(format!("parameters are: {}", self.params.join(", "))),
        };
        self.error(d);
    }
}
