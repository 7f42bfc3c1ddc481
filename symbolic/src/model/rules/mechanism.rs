//! The mechanism of a model file: the rules across its constraints (names, count, guesses),
//! equations written by hand and balances; each element's own rules (constraints, rolling
//! contacts, masses and inertias) are in `model/elements/`, called from here in file order.

use super::*;
use crate::model::elements::{body, constraint, nonholonomic};

impl Checker<'_> {
    // Rule: constraints have distinct names; holonomic ones depend on q and t, non-holonomic
    // ones also on the rates; there are no more constraints than coordinates; `guess` marks
    // coordinates (not rates) of a model that has constraints.
    pub(super) fn constraints(&mut self) {
        let file = self.file;
        constraint::expression_rules(&file.constraints, self);
        nonholonomic::expression_rules(&file.nonholonomic, self);
        let names = file.constraint_names();
        let mut seen: Vec<(&str, Location)> = Vec::new();
        for k in &names {
            if let Some((_, first)) = seen.iter().find(|(n, _)| *n == k.value) {
                self.error(
                    Diagnostic::new(k.location, format!("duplicate constraint name `{}`: already used at {first}", k.value))
                        .with_help("constraints under `constraints` and `nonholonomic` share one namespace (a rolling contact `roll` names its rows `roll_x`, `roll_y`, …); rename one"),
                );
            } else {
                seen.push((&k.value, k.location));
            }
        }
        nonholonomic::rolling_rules(&file.rolling, self);
        constraint::point_rules(&file.point_constraints, self);
        let m = names.len();
        let n = file.coordinates.len();
        if m > n && !self.incomplete.has_section("coordinates") {
            let at = names.get(n).map_or(file.name.location, |k| k.location);
            self.error(
                Diagnostic::new(at, format!("{m} constraints on {n} coordinate(s): more constraints than coordinates"))
                    .with_help("each constraint removes one degree of freedom; remove redundant constraints or add coordinates"),
            );
        }
        for g in &file.initial_guesses {
            if !self.sets.coords.contains(g.value.as_str()) {
                self.error(
                    Diagnostic::new(
                        g.location,
                        format!(
                            "`{}` is not a coordinate: only coordinates take `{{ guess: … }}`",
                            g.value
                        ),
                    )
                    .with_help(
                        "the rates of guessed coordinates are solved from the velocity constraints",
                    ),
                );
            } else if m == 0 && !self.incomplete.has_section("constraints") {
                self.error(
                    Diagnostic::new(
                        g.location,
                        format!(
                            "`{}` is a guess, but the model has no constraints to solve it from",
                            g.value
                        ),
                    )
                    .with_help("give its value directly: `initial: { x: 0.5 }`"),
                );
            }
        }
    }

    // Rule (`speeds:`): one generalized speed per degree of freedom (per coordinate, less one
    // per constraint row), each read where the rates may be, defined by the rates (not other
    // speeds) and not named as an angular velocity, in a model of the kinematic form;
    // `initial:` gives the speeds or the rates, not both, and no guesses. The equations in
    // speeds are derived for systems without contacts (Kane and Levinson, ch. 6: contacts,
    // balances and hand-written equations in speeds are not supported).
    pub(super) fn speeds(&mut self) {
        let file = self.file;
        let Some(first) = file.speeds.first() else {
            return;
        };
        // Guesses are solved with their rates from the constraints' `Φ` and `J` in the
        // coordinates; in speeds `J` is over the speeds, and the auxiliary speeds start on the
        // constraints instead. (Without constraints the guess is refused above.)
        let rows = file.constraint_names();
        for g in file.initial_guesses.iter().filter(|_| !rows.is_empty()) {
            self.error(
                Diagnostic::new(g.location, format!("`{}` is a guess, but a model in generalized speeds does not solve its initial state from the constraints: its auxiliary speeds start at 0", g.value))
                    .with_help(format!("give the coordinates on the constraints: `initial: {{ {}: 0.5 }}`", g.value)),
            );
        }
        for s in &file.speeds {
            s.rules(self);
            // A constraint row is an auxiliary speed of its own name.
            if rows.iter().any(|r| r.value == s.name.value) {
                self.error(
                    Diagnostic::new(s.name.location, format!("speed name `{}` is taken: it names a constraint row, whose auxiliary speed it is", s.name.value))
                        .with_help("rename the speed or the constraint"),
                );
            }
            // A frame's angular velocity keeps its name; a definition reads the rates only.
            if file.angular_velocity_name(&s.name.value).is_some() {
                self.error(
                    Diagnostic::new(s.name.location, format!("speed name `{}` is taken: it names a component of a frame's angular velocity", s.name.value))
                        .with_help("rename the speed: `omega_<frame>_<axis>` always reads the frame's angular velocity"),
                );
            }
            let mut ids = Vec::new();
            identifiers(&s.value, &mut ids);
            // (A speed named as an angular velocity is reported above; the name reads the
            // angular velocity here.)
            if let Some((other, at)) = ids.iter().find(|(n, _)| {
                self.sets.speeds.contains(n.as_str()) && file.angular_velocity_name(n).is_none()
            }) {
                self.error(
                    Diagnostic::new(*at, format!("speed `{}` is defined through the speed `{other}`", s.name.value))
                        .with_help("define each speed by the rates (`theta1_dot + theta2_dot`), not by other speeds"),
                );
            }
        }
        // One speed per degree of freedom: per coordinate, less one per constraint row (those
        // rows become the auxiliary speeds held at 0).
        let (n, p) = (file.coordinates.len(), file.speeds.len());
        let rows = file.constraint_names().len();
        let plural = |k: usize| if k == 1 { "" } else { "s" };
        if n != p + rows && !self.incomplete.has_section("coordinates") {
            let message = if rows == 0 {
                format!(
                    "the model has {n} coordinate{} but {p} speed{}: `speeds` gives one per coordinate",
                    plural(n),
                    plural(p)
                )
            } else {
                format!(
                    "the model has {n} coordinate{} and {rows} constraint row{} but {p} speed{}: `speeds` gives one per degree of freedom, {}",
                    plural(n),
                    plural(rows),
                    plural(p),
                    n.saturating_sub(rows)
                )
            };
            self.error(
                Diagnostic::new(first.name.location, message)
                    .with_help("each speed is a combination of the rates, such as `w1: omega_B_x`; together with the constraints they must determine every rate"),
            );
        }
        if file.kinetic.is_some()
            || (file.bodies.is_empty() && !self.incomplete.has_section("bodies"))
        {
            self.error(
                Diagnostic::new(first.name.location, "generalized speeds need the kinematic form: bodies, and no written `kinetic:`")
                    .with_help("Kane's equations in the speeds are projected on the bodies' partial velocities, and they check Lagrange's; write the bodies, points and frames instead of `kinetic:`"),
            );
        }
        let unsupported = [
            (!file.contacts.is_empty(), "contacts"),
            (!file.balances.is_empty(), "balances"),
            (
                !file.checks.equations_of_motion.is_empty(),
                "equations of motion written by hand",
            ),
        ];
        for (_, what) in unsupported.iter().filter(|(has, _)| *has) {
            self.error(
                Diagnostic::new(
                    first.name.location,
                    format!("generalized speeds are not supported in a model with {what}"),
                )
                .with_help("write the model in the coordinates' rates (remove `speeds`)"),
            );
        }
        let rates: Vec<&Located<String>> = (file.initial.iter().map(|(k, _)| k))
            .filter(|k| self.sets.rates.contains(k.value.as_str()))
            .collect();
        let speeds = file
            .initial
            .iter()
            .find(|(k, _)| self.sets.speeds.contains(k.value.as_str()));
        if let (Some(rate), Some((speed, _))) = (rates.first(), speeds) {
            self.error(
                Diagnostic::new(rate.location, format!("`initial` gives the rate `{}` and the speed `{}`: give the speeds or the rates, not both", rate.value, speed.value))
                    .with_help("with `speeds`, the initial state is the coordinates and the speeds (the speeds not given start at 0)"),
            );
        }
        for q in &file.equilibria {
            if let Some((k, _)) = q
                .values
                .iter()
                .find(|(k, _)| self.sets.rates.contains(k.value.as_str()))
            {
                self.error(
                    Diagnostic::new(k.location, format!("equilibrium `{}` holds the rate `{}`, but the model's state holds speeds", q.name.value, k.value))
                        .with_help("an equilibrium of a model with `speeds` gives coordinates only"),
                );
            }
        }
    }

    // Rule: equations of motion written by hand (`checks: equations_of_motion`) are one per
    // coordinate and use parameters, coordinates, rates, accelerations and `t`.
    pub(super) fn hand_equations(&mut self) {
        let file = self.file;
        let equations = &file.checks.equations_of_motion;
        let Some(first) = equations.first() else {
            return;
        };
        let n = file.coordinates.len();
        if equations.len() != n && !self.incomplete.has_section("checks") {
            self.error(
                Diagnostic::new(
                    first.location,
                    format!(
                        "{} equation(s) of motion for {n} coordinate(s): give one per coordinate",
                        equations.len()
                    ),
                )
                .with_help("write each equation as `lhs = rhs` in the coordinates, rates (`x_dot`) and accelerations (`x_ddot`)"),
            );
        }
        for (i, e) in equations.iter().enumerate() {
            let what = format!("equation of motion {}", i + 1);
            self.resolve(&e.lhs, Depends::Acceleration, &what);
            if let Some(rhs) = &e.rhs {
                self.resolve(rhs, Depends::Acceleration, &what);
            }
        }
    }

    // Rule: user balances name existing bodies (each once per balance) and, for AMB, an
    // existing point; AMB needs a planar model; an LMB direction has as many components as
    // the points and depends only on parameters, coordinates and `t`; there are as many
    // balances as coordinates; and, since only gravity (at each centre of mass) and torques
    // (which name their body) can be assigned to the chosen bodies, a model with balances has
    // no point loads (forces, springs, dampers) and no energy-form pieces.
    pub(super) fn balances(&mut self) {
        let file = self.file;
        if file.balances.is_empty() {
            return;
        }
        self.balance_counts();
        self.balance_loads();
        for b in &file.balances {
            self.balance_bodies(&b.bodies);
            match &b.kind {
                BalanceKind::Amb {
                    about, axis, frame, ..
                } => self.amb_balance(b.location, about, axis.as_ref(), frame.as_ref()),
                BalanceKind::Lmb { along } => self.lmb_balance(b.location, along),
            }
        }
    }

    /// Checks that each set of balances has one balance per coordinate.
    fn balance_counts(&mut self) {
        let file = self.file;
        let n = file.coordinates.len();
        for set in file.balance_sets() {
            let count = file.balances.iter().filter(|b| b.set_name() == set).count();
            let first = file.balances.iter().find(|b| b.set_name() == set);
            if count != n
                && let Some(first) = first
            {
                let location = first.set.as_ref().map_or(first.location, |s| s.location);
                let which = match set {
                    Some(name) => format!("the set `{name}` has "),
                    None => String::new(),
                };
                self.error(
                    Diagnostic::new(
                        location,
                        format!("{which}{count} balance(s) for {n} coordinate(s): the balances must give one equation per coordinate"),
                    )
                    .with_help("choose as many balances as coordinates, each free of reaction forces (HW19: AMB/O of both bars and AMB/E of the forearm)"),
                );
            }
        }
    }

    /// Checks that a model with balances has no point loads (forces, springs, dampers,
    /// interactions) and no energy-form pieces.
    fn balance_loads(&mut self) {
        let file = self.file;
        let point_loads = file
            .forces
            .first()
            .map(|f| (f.name.location, "a force"))
            .or_else(|| file.springs.first().map(|s| (s.name.location, "a spring")))
            .or_else(|| file.dampers.first().map(|d| (d.name.location, "a damper")))
            .or_else(|| {
                file.interactions
                    .first()
                    .map(|i| (i.name.location, "an interaction"))
            });
        if let Some((location, what)) = point_loads {
            self.error(
                Diagnostic::new(location, format!("{what} in a model with `balances` is not supported yet"))
                    .with_help("a balance needs to know which body each load acts on; for now balances take gravity and torques only"),
            );
        }
        if file.kinetic.is_some() || file.potential.is_some() || !file.generalized_forces.is_empty()
        {
            self.error(
                Diagnostic::new(file.balances[0].location, "`balances` need the kinematic form, but the model gives `kinetic`, `potential` or `generalized_forces`")
                    .with_help("describe the mechanism with `points`, `bodies` and loads"),
            );
        }
    }

    /// Checks that the bodies of one balance exist and are each listed once.
    fn balance_bodies(&mut self, bodies: &[Located<String>]) {
        let mut seen: Vec<&str> = Vec::new();
        for body in bodies {
            if !self.bodies.contains(&body.value.as_str()) {
                let d = Diagnostic::new(
                    body.location,
                    format!("unknown body `{}` in a balance", body.value),
                );
                let d = match closest(&body.value, &self.bodies) {
                    Some(c) => d.with_help(format!("did you mean `{c}`?")),
                    None => d.with_help(format!("bodies are: {}", self.bodies.join(", "))),
                };
                self.error(d);
            } else if seen.contains(&body.value.as_str()) {
                self.error(Diagnostic::new(
                    body.location,
                    format!("body `{}` is listed twice in this balance", body.value),
                ));
            }
            seen.push(body.value.as_str());
        }
    }

    /// Checks an AMB balance (at `location`): its point exists, it has an `axis` of three
    /// components exactly in a 3-D model, the axis depends on the configuration only, and
    /// its frame `in` exists.
    fn amb_balance(
        &mut self,
        location: Location,
        about: &Located<String>,
        axis: Option<&Located<Vec<Expr>>>,
        frame: Option<&Located<String>>,
    ) {
        let file = self.file;
        if !self.points.contains(&about.value.as_str()) {
            let d = Diagnostic::new(about.location, format!("unknown point `{}`", about.value));
            let d = match closest(&about.value, &self.points) {
                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                None => d.with_help(format!("points are: {}", self.points.join(", "))),
            };
            self.error(d);
        }
        match (file.dimension, axis) {
            (Some(3), None) => self.error(
                Diagnostic::new(location, "an `amb` balance of a 3-D model needs the `axis` it takes moments about")
                    .with_help("write `{ amb: { about: O, bodies: [top], axis: [0, 0, 1], in: N } }`: the balance Σ M_O·e = (dH_O/dt)·e along that axis"),
            ),
            (Some(3), Some(axis)) if axis.value.len() != 3 => self.error(
                Diagnostic::new(axis.location, format!("`axis` has {} components; a 3-D axis has 3", axis.value.len()))
                    .with_help("write `axis: [0, 0, 1]`"),
            ),
            (Some(2), Some(axis)) => self.error(
                Diagnostic::new(axis.location, "an `amb` balance of a planar model takes moments about the normal to the plane: it has no `axis`")
                    .with_help("leave out `axis` (and `in`)"),
            ),
            _ => {}
        }
        if let Some(axis) = axis {
            for c in &axis.value {
                self.resolve(c, Depends::Position, "the axis of an `amb` balance");
            }
        }
        if let Some(frame) = frame {
            let frames: Vec<&str> = file
                .frames
                .iter()
                .map(|f| f.name.value.as_str())
                .chain([GROUND_FRAME])
                .collect();
            self.frame(frame, &frames);
        }
    }

    /// Checks an LMB balance (at `location`): its direction `along` has as many components as
    /// the points and uses only parameters, coordinates, `t` and `pi`.
    fn lmb_balance(&mut self, location: Location, along: &[Expr]) {
        let file = self.file;
        if let Some(dim) = file.dimension
            && along.len() != dim
        {
            self.error(Diagnostic::new(
                location,
                format!(
                    "`along` has {} components but the points have {dim}",
                    along.len()
                ),
            ));
        }
        for e in along {
            let mut ids = Vec::new();
            identifiers(e, &mut ids);
            for (name, location) in ids {
                let ok = self.sets.params.contains(name.as_str())
                    || self.sets.coords.contains(name.as_str())
                    || name == "t"
                    || name == "pi";
                if !ok {
                    self.error(
                        Diagnostic::new(location, format!("`along` cannot use `{name}`"))
                            .with_help("a direction may use parameters, coordinates and `t`"),
                    );
                }
            }
        }
    }

    // Rule: a body's mass is positive and its inertia a physical body's, when they are
    // constant expressions of the parameters (evaluated at the defaults).
    pub(super) fn masses(&mut self) {
        body::value_rules(&self.file.bodies, self);
    }
}
