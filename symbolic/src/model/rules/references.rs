//! What a model file compares with: `checks:`, `floquet:` and `outputs:`, and the names they refer
//! to.

use super::*;
use crate::model::EquilibriumDef;
use crate::model::checks::{FinalStateCheck, ModalCheck, PeriodCheck};

impl Checker<'_> {
    // Rule: every point named by a body or a drawing exists (springs, dampers, forces and
    // torques: their own rules, in elements/); generalized forces are keyed by coordinates;
    // initial values by coordinates or rates.
    pub(super) fn references(&mut self) {
        let file = self.file;
        for b in &file.bodies {
            self.point(b.kind.com());
        }
        for l in &file.draw.lines {
            l.iter().for_each(|p| self.point(p));
        }
        for p in &file.draw.trace {
            self.point(p);
        }
        let coordinates_lost = self.section_lost("coordinates", self.coords.is_empty());
        self.generalized_force_keys(coordinates_lost);
        self.equilibrium_keys(coordinates_lost);
        self.initial_keys(coordinates_lost);
    }

    /// Checks that `generalized_forces` is keyed by coordinates (unless the coordinates were
    /// lost to an earlier error).
    fn generalized_force_keys(&mut self, coordinates_lost: bool) {
        let file = self.file;
        for (k, _) in &file.generalized_forces {
            let n = k.value.as_str();
            if self.sets.coords.contains(n) || self.incomplete.has_name(n) || coordinates_lost {
                continue;
            }
            let d = Diagnostic::new(
                k.location,
                format!("`{n}` in `generalized_forces` is not a coordinate"),
            );
            let d = match closest(n, &self.coords) {
                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                None => d.with_help(format!("coordinates are: {}", self.coords.join(", "))),
            };
            self.error(d);
        }
    }

    /// Checks that each equilibrium gives values of coordinates or rates and that its
    /// `ignorable` names coordinates.
    fn equilibrium_keys(&mut self, coordinates_lost: bool) {
        let file = self.file;
        for q in &file.equilibria {
            for (k, _) in &q.values {
                let n = k.value.as_str();
                let base = n.strip_suffix("_dot").unwrap_or(n);
                if self.sets.coords.contains(n)
                    || self.sets.rates.contains(n)
                    || self.incomplete.has_name(base)
                    || coordinates_lost
                {
                    continue;
                }
                let d = Diagnostic::new(
                    k.location,
                    format!(
                        "`{n}` in equilibrium `{}` is neither a coordinate nor a rate",
                        q.name.value
                    ),
                );
                let mut candidates: Vec<&str> = self.coords.clone();
                candidates.extend(self.rates.iter().map(String::as_str));
                let d = match closest(n, &candidates) {
                    Some(c) => d.with_help(format!(
                        "did you mean `{c}`? an equilibrium gives coordinates (a steady motion also the rates it holds, and `ignorable`)"
                    )),
                    None => d.with_help(format!("coordinates are: {}", self.coords.join(", "))),
                };
                self.error(d);
            }
            for k in &q.ignorable {
                let n = k.value.as_str();
                if self.sets.coords.contains(n) || self.incomplete.has_name(n) || coordinates_lost {
                    continue;
                }
                let d = Diagnostic::new(
                    k.location,
                    format!(
                        "`{n}` in `ignorable` of `{}` is not a coordinate",
                        q.name.value
                    ),
                );
                let d = match closest(n, &self.coords) {
                    Some(c) => d.with_help(format!("did you mean `{c}`?")),
                    None => d.with_help(format!("coordinates are: {}", self.coords.join(", "))),
                };
                self.error(d);
            }
            if !coordinates_lost {
                self.steady_marks(q);
            }
        }
    }

    /// Checks an equilibrium's marks: `{ held: … }` only on coordinates, `{ guess: … }` only
    /// on rates, and a `turning:` frame of three distinct coordinates, each `ignorable`.
    fn steady_marks(&mut self, q: &EquilibriumDef) {
        let name = &q.name.value;
        let moves = q.turning.is_some() || q.values.iter().any(|(k, _)| k.value.ends_with("_dot"));
        for k in &q.held {
            if self.sets.coords.contains(k.value.as_str()) && !moves {
                self.error(
                    Diagnostic::new(k.location, format!("`{}` is held, but equilibrium `{name}` gives no rate: an equilibrium's coordinates are all found", k.value))
                        .with_help("`{ held: value }` picks one steady motion of a family (give the rates it holds, or `turning:`); for an equilibrium write the coordinate's guess"),
                );
                continue;
            }
            if !self.sets.coords.contains(k.value.as_str()) {
                self.error(
                    Diagnostic::new(k.location, format!("`{}` in equilibrium `{name}` is held, but only a coordinate can be: a rate is held unless marked", k.value))
                        .with_help(format!("write `{}: value` to hold a rate, or `{{ guess: value }}` for the search to find it", k.value)),
                );
            }
        }
        for k in &q.solved {
            if !self.sets.rates.contains(k.value.as_str()) {
                self.error(
                    Diagnostic::new(k.location, format!("`{}` in equilibrium `{name}` is marked a guess, but only a rate can be: a coordinate is a guess unless held", k.value))
                        .with_help(format!("write `{}: value` for a coordinate the search finds, or `{{ held: value }}` to hold it", k.value)),
                );
                continue;
            }
            let base = k.value.strip_suffix("_dot").unwrap_or(&k.value);
            if !q.ignorable.iter().any(|i| i.value == base) {
                self.error(
                    Diagnostic::new(k.location, format!("`{}` in equilibrium `{name}` is to be found, but `{base}` is not in its `ignorable`: a steady motion moves only ignorable coordinates, and holds the other rates at 0", k.value))
                        .with_help(format!("add `{base}` to `ignorable` if nothing depends on it, or leave `{}` out (held at 0)", k.value)),
                );
            }
        }
        let Some(turning) = &q.turning else { return };
        let names: Vec<&Located<String>> = std::iter::once(&turning.angle)
            .chain(&turning.plane)
            .collect();
        for (i, k) in names.iter().enumerate() {
            let n = k.value.as_str();
            if !self.sets.coords.contains(n) {
                let d = Diagnostic::new(
                    k.location,
                    format!("`{n}` in `turning` of `{name}` is not a coordinate"),
                );
                let d = match closest(n, &self.coords) {
                    Some(c) => d.with_help(format!("did you mean `{c}`?")),
                    None => d.with_help(format!("coordinates are: {}", self.coords.join(", "))),
                };
                self.error(d);
            } else if names[..i].iter().any(|o| o.value == n) {
                self.error(
                    Diagnostic::new(k.location, format!("`{n}` appears twice in `turning` of `{name}`"))
                        .with_help("the turning angle and the two plane coordinates are three different coordinates: `turning: { angle: yaw, plane: [x, y] }`"),
                );
            } else if !q.ignorable.iter().any(|o| o.value == n) {
                self.error(
                    Diagnostic::new(k.location, format!("`{n}` turns in the steady turn `{name}` but is not in its `ignorable`"))
                        .with_help(format!("a steady turn moves its turning angle and plane coordinates, which nothing may depend on: add `{n}` to `ignorable`")),
                );
            }
        }
    }

    /// Checks that `initial` gives values of coordinates or rates.
    fn initial_keys(&mut self, coordinates_lost: bool) {
        let file = self.file;
        for (k, _) in &file.initial {
            let n = k.value.as_str();
            let base = n.strip_suffix("_dot").unwrap_or(n);
            if self.sets.coords.contains(n)
                || self.sets.rates.contains(n)
                || self.sets.speeds.contains(n)
                || self.incomplete.has_name(base)
                || coordinates_lost
            {
                continue;
            }
            let mut candidates: Vec<&str> = self.coords.clone();
            candidates.extend(self.rates.iter().map(String::as_str));
            let d = Diagnostic::new(
                k.location,
                format!("`{n}` in `initial` is neither a coordinate nor a rate"),
            );
            let d = match closest(n, &candidates) {
                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                None => d.with_help(format!(
                    "initial values are given for: {}",
                    candidates.join(", ")
                )),
            };
            self.error(d);
        }
    }

    // Rule (`floquet:`): each entry names an equilibrium; `axis_units`, `along` and `gives`
    // name parameters (`along` ≠ `gives`); every expression is a constant of the parameters;
    // colour components are whole numbers from 0 to 255.
    pub(super) fn floquet_references(&mut self) {
        let file = self.file;
        let equilibria: Vec<&str> = file
            .equilibria
            .iter()
            .map(|e| e.name.value.as_str())
            .collect();
        for entry in &file.floquet {
            let at = &entry.at;
            if !equilibria.contains(&at.value.as_str())
                && !self.incomplete.has_section("equilibria")
            {
                let d = Diagnostic::new(
                    at.location,
                    format!(
                        "`floquet:` names `{}`, which is not an equilibrium of the model",
                        at.value
                    ),
                );
                let d = match closest(&at.value, &equilibria) {
                    Some(c) => d.with_help(format!("did you mean `{c}`?")),
                    None => d.with_help(
                        "a `floquet:` entry is keyed by a name of `equilibria:`, as in `equilibria: { upright: { theta: 0 } }`",
                    ),
                };
                self.error(d);
            }
            let what = format!("`floquet:` at `{}`", at.value);
            for (p, _) in &entry.axis_units {
                self.parameter_name(p, &format!("`axis_units` of {what}"));
            }
            for t in &entry.thresholds {
                let of = format!("threshold `{}` of {what}", t.name.value);
                self.resolve(&t.value, Depends::Constant, &format!("the value of {of}"));
                self.resolve(
                    &t.critical,
                    Depends::Constant,
                    &format!("the critical value of {of}"),
                );
            }
            for c in &entry.curves {
                let of = format!("curve `{}` of {what}", c.name.value);
                self.parameter_name(&c.along, &format!("`along` of {of}"));
                self.parameter_name(&c.gives, &format!("`gives` of {of}"));
                if c.along.value == c.gives.value {
                    self.error(
                        Diagnostic::new(
                            c.gives.location,
                            format!("{of} gives `{}` along itself", c.gives.value),
                        )
                        .with_help("`along` and `gives` name the chart's two parameters: `along: a, gives: w`"),
                    );
                }
                self.resolve(&c.value, Depends::Constant, &format!("the value of {of}"));
                if let Some(domain) = &c.domain {
                    self.resolve(domain, Depends::Constant, &format!("`where` of {of}"));
                }
                for e in &c.color {
                    self.resolve(e, Depends::Constant, &format!("the colour of {of}"));
                    let value = evaluate(e, &file.parameters);
                    if value.is_some_and(|v| !(0.0..=255.0).contains(&v) || v.fract() != 0.0) {
                        self.error(
                            Diagnostic::new(
                                e.location,
                                format!("the colour of {of} has a component outside 0 to 255"),
                            )
                            .with_help("write red, green and blue as whole numbers from 0 to 255: `color: [0, 150, 60]`"),
                        );
                    }
                }
            }
        }
    }

    // Rule: the reference values of `checks:` are expressions of the parameters (a conserved
    // quantity may also use coordinates, rates and `t`); `at:` names an entry of
    // `equilibria:`, `event:` an entry of `events:`, and `final_state` gives coordinates and
    // rates; `natural_frequencies` lists one value per mode (coordinates minus holonomic
    // constraints, when there are no non-holonomic ones).
    pub(super) fn reference_checks(&mut self) {
        let file = self.file;
        let checks = &file.checks;
        for (key, modal) in [
            ("natural_frequencies", &checks.natural_frequencies),
            ("damping_ratios", &checks.damping_ratios),
        ] {
            let Some(modal) = modal else { continue };
            self.modal_check(key, modal);
        }
        if let Some(period) = &checks.period {
            self.period_check(period);
        }
        if let Some(state) = &checks.final_state {
            self.final_state_check(state);
        }
        self.angular_velocities = false;
        for c in &checks.conserved {
            let what = format!("conserved quantity `{}`", c.name.value);
            self.resolve(&c.value, Depends::Motion, &what);
            self.no_rates_beside_speeds(&c.value, &what);
        }
        self.angular_velocities = true;
    }

    /// The `modal` check under `key` (`natural_frequencies` or `damping_ratios`): its values
    /// are constants, its `at:` an entry of `equilibria:`, and natural frequencies one per mode.
    fn modal_check(&mut self, key: &str, modal: &ModalCheck) {
        let file = self.file;
        for (i, v) in modal.values.iter().enumerate() {
            self.resolve(v, Depends::Constant, &format!("value {} of `{key}`", i + 1));
        }
        if let Some(at) = &modal.at {
            let names: Vec<&str> = file
                .equilibria
                .iter()
                .map(|e| e.name.value.as_str())
                .collect();
            if !names.contains(&at.value.as_str()) && !self.incomplete.has_section("equilibria") {
                let d = Diagnostic::new(
                    at.location,
                    format!(
                        "`at: {}` of `{key}` is not an equilibrium of the model",
                        at.value
                    ),
                );
                let d = match closest(&at.value, &names) {
                    Some(c) => d.with_help(format!("did you mean `{c}`?")),
                    None if names.is_empty() => d.with_help(
                        "name the operating point in `equilibria:`, as in `equilibria: { hanging: { theta: 0 } }`",
                    ),
                    None => d.with_help(format!("equilibria are: {}", names.join(", "))),
                };
                self.error(d);
            }
        }
        let modes = file
            .coordinates
            .len()
            .saturating_sub(file.holonomic_names().len());
        if key == "natural_frequencies"
            && file.nonholonomic.is_empty()
            && file.rolling.is_empty()
            && modal.values.len() != modes
            && !self.incomplete.has_section("coordinates")
            && !self.incomplete.has_section("constraints")
        {
            self.error(
                Diagnostic::new(
                    modal.location,
                    format!(
                        "`natural_frequencies` lists {} value(s), but the model has {modes} mode(s)",
                        modal.values.len()
                    ),
                )
                .with_help("give every natural frequency in rad/s, ascending, zero-frequency modes as 0"),
            );
        }
    }

    /// The `period` check: its value is a constant and its `event:` an entry of `events:`.
    fn period_check(&mut self, period: &PeriodCheck) {
        let file = self.file;
        self.resolve(&period.value, Depends::Constant, "the `value` of `period`");
        let names: Vec<&str> = file.events.iter().map(|e| e.name.value.as_str()).collect();
        if !names.contains(&period.event.value.as_str()) && !self.incomplete.has_section("events") {
            let d = Diagnostic::new(
                period.event.location,
                format!(
                    "`event: {}` of `period` is not an event of the model",
                    period.event.value
                ),
            );
            let d = match closest(&period.event.value, &names) {
                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                None if names.is_empty() => d.with_help(
                    "define it in `events:`, as in `events: { peak: { when: x_dot, direction: falling } }`",
                ),
                None => d.with_help(format!("events are: {}", names.join(", "))),
            };
            self.error(d);
        }
    }

    /// The `final_state` check: its time and values are constants, keyed by coordinates and
    /// rates.
    fn final_state_check(&mut self, state: &FinalStateCheck) {
        self.resolve(&state.t, Depends::Constant, "the time `t` of `final_state`");
        for (k, v) in &state.values {
            self.resolve(
                v,
                Depends::Constant,
                &format!("the value of `{}` in `final_state`", k.value),
            );
            let n = k.value.as_str();
            let speeds = !self.file.speeds.is_empty();
            if self.sets.coords.contains(n)
                || (self.sets.rates.contains(n) && !speeds)
                || self.sets.speeds.contains(n)
                || self.incomplete.has_section("coordinates")
            {
                continue;
            }
            if speeds && self.sets.rates.contains(n) {
                self.error(
                    Diagnostic::new(k.location, format!("`{n}` in `final_state` is a rate, but a model in generalized speeds has the speeds in its state"))
                        .with_help("give the final values of the coordinates and the speeds"),
                );
                continue;
            }
            let mut candidates: Vec<&str> = self.coords.clone();
            match speeds {
                true => candidates.extend(self.file.speeds.iter().map(|s| s.name.value.as_str())),
                false => candidates.extend(self.rates.iter().map(String::as_str)),
            }
            let d = Diagnostic::new(
                k.location,
                format!("`{n}` in `final_state` is neither a coordinate nor a rate"),
            );
            let d = match closest(n, &candidates) {
                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                None => d.with_help(format!(
                    "coordinates and rates are: {}",
                    candidates.join(", ")
                )),
            };
            self.error(d);
        }
    }

    // Rule: outputs are functions of the motion, named apart from the columns beside them
    // in a simulation's output (`t`, the coordinates and rates, `energy`).
    pub(super) fn outputs(&mut self) {
        let file = self.file;
        // Beside speeds, each constraint row is a speed (an auxiliary one).
        let auxiliary: Vec<String> = match file.speeds.is_empty() {
            true => Vec::new(),
            false => file
                .constraint_names()
                .into_iter()
                .map(|k| k.value)
                .collect(),
        };
        for o in &file.outputs {
            let n = o.name.value.as_str();
            if n == "t"
                || n == "energy"
                || self.sets.coords.contains(n)
                || self.sets.rates.contains(n)
                || self.sets.speeds.contains(n)
                || auxiliary.iter().any(|a| a == n)
            {
                self.error(
                    Diagnostic::new(
                        o.name.location,
                        format!("output name `{n}` is taken: a simulation's output already has a column `{n}`"),
                    )
                    .with_help("choose another name, such as `L` or `angular_momentum`"),
                );
            }
            self.resolve(&o.value, Depends::Motion, &format!("output `{n}`"));
            self.no_rates_beside_speeds(&o.value, &format!("output `{n}`"));
        }
    }

    /// With generalized speeds, an expression evaluated on the simulated state (an output, a
    /// conserved quantity) reads the speeds, which the state holds, not the rates: a rate, a
    /// frame's angular velocity or a point's velocity it names is an error at its place.
    fn no_rates_beside_speeds(&mut self, e: &Expr, what: &str) {
        if self.file.speeds.is_empty() {
            return;
        }
        let mut ids = Vec::new();
        identifiers(e, &mut ids);
        // A rate by name, a frame's angular velocity (`omega_B_z`) or a point's velocity
        // (`vel(P)`): each is a function of the rates once lowered.
        let rate = ids.iter().find(|(n, _)| {
            self.sets.rates.contains(n.as_str()) || self.file.angular_velocity_name(n).is_some()
        });
        let read = match rate {
            Some((name, at)) => Some((format!("`{name}`"), *at)),
            None => crate::model::vectors::uses_velocities(e)
                .then(|| ("a point's velocity `vel(…)`".to_string(), e.location)),
        };
        if let Some((read, at)) = read {
            let speeds: Vec<&str> = (self.file.speeds.iter())
                .map(|s| s.name.value.as_str())
                .collect();
            self.error(
                Diagnostic::new(at, format!("{what} reads {read}, a function of the rates, but a model in generalized speeds has the speeds in its state"))
                    .with_help(format!("write it with the speeds ({}), the coordinates and the parameters", speeds.join(", "))),
            );
        }
    }
}
