//! Cross-object rules of a model file, each stated above its check. Every violation is
//! collected; nothing stops at the first.
//!
//! The rules run on what the schema pass built. Entries it left out (already reported) are
//! listed in [`Incomplete`] and treated as present, so that one mistake gives one message.

use rustc_hash::FxHashSet;

use super::ast::{Expr, FUNCTIONS};
use super::diagnostic::{Diagnostic, Diagnostics};
use super::file::{
    Axis, BalanceKind, BodyKind, GROUND_FRAME, InertiaTensor, ModelFile, Parameter, RollingContact,
    TorqueValue,
};
use super::located::{Located, Location};
use super::parser::{closest, eval_expr, identifiers};
use super::schema::{self, Incomplete, UNRAW_KEYWORDS};
use super::vectors;

/// Runs every rule on `file`.
///
/// # Errors
/// Every violation, sorted by location.
pub fn check(file: &ModelFile) -> Result<(), Vec<Diagnostic>> {
    check_partial(file, &Incomplete::default())
}

/// Runs every rule on a model that the schema pass built only in part, without reporting
/// what depends on the entries it left out (see [`Incomplete`]).
///
/// # Errors
/// Every violation, sorted by location.
pub fn check_partial(file: &ModelFile, incomplete: &Incomplete) -> Result<(), Vec<Diagnostic>> {
    let (mut list, units) = check_parts(file, incomplete);
    list.extend(units);
    if list.is_empty() {
        return Ok(());
    }
    list.sort_by_key(|d| d.location);
    Err(list)
}

/// [`check_partial`]'s diagnostics in two lists: the rules' and the units' (a unit mistake
/// at the place of a rule's mistake left out). A file whose only mistakes are units is sound
/// to derive ([`super::load`] then reports what the derivation finds too).
pub(crate) fn check_parts(
    file: &ModelFile,
    incomplete: &Incomplete,
) -> (Vec<Diagnostic>, Vec<Diagnostic>) {
    let mut checker = Checker::new(file, incomplete);
    checker.names();
    checker.presence();
    checker.expressions();
    checker.dimensions();
    checker.frames();
    checker.references();
    checker.masses();
    checker.balances();
    checker.hand_equations();
    checker.reference_checks();
    checker.floquet_references();
    checker.constraints();
    checker.interactions();
    checker.outputs();
    let units = super::unit_check::check(file);
    // A unit mistake at the place of another mistake is its consequence (`initial: { theta:
    // x }` is not constant, and so not in rad either): one message per mistake.
    let list = checker.diagnostics.finish().err().unwrap_or_default();
    let taken: Vec<Location> = list.iter().map(|d| d.location).collect();
    let units = units
        .into_iter()
        .filter(|d| !taken.contains(&d.location))
        .collect();
    (list, units)
}

/// The value of a constant expression at the parameters' defaults (`None` if it uses
/// anything but numbers, `pi`, functions and these parameters).
///
/// A NaN or infinite result is returned as such (`1/0` is `inf`).
pub fn evaluate(expr: &Expr, parameters: &[Parameter]) -> Option<f64> {
    eval_expr(expr, &|n| {
        parameters
            .iter()
            .find(|p| p.name.value == n)
            .map(|p| p.value)
    })
    .ok()
}

/// What an expression may depend on.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Depends {
    /// Parameters, numbers, `pi` and functions.
    Constant,
    /// Also coordinates and `t` (a configuration).
    Position,
    /// Also rates (`x_dot`).
    Motion,
    /// Also accelerations (`x_ddot`): only equations of motion written by hand.
    Acceleration,
    /// Also constraint forces (`lambda_<constraint>`): only event functions.
    Event,
}

struct Checker<'f> {
    file: &'f ModelFile,
    incomplete: &'f Incomplete,
    diagnostics: Diagnostics,
    params: Vec<&'f str>,
    coords: Vec<&'f str>,
    rates: Vec<String>,
    accelerations: Vec<String>,
    multipliers: Vec<String>,
    points: Vec<&'f str>,
    bodies: Vec<&'f str>,
    /// Whether `omega_<frame>_<axis>` may be read: in expressions the derivation lowers, not
    /// in the conserved quantities of `checks:`, which are evaluated from the state alone.
    angular_velocities: bool,
    /// Whether the vector functions (`dot(P - O, …)`) may be used: not in the positions of
    /// points and the rotations of frames, which define the points they would read.
    vectors: bool,
    /// Whether `r` and `r_dot` name an interaction's distance and its rate (in its
    /// magnitude).
    interaction: bool,
    /// The names above as sets, for lookups in time independent of their number (the lists
    /// keep the file's order for suggestions and help).
    sets: NameSets,
}

/// Parameter, coordinate, rate, acceleration and multiplier names, hashed.
#[derive(Default)]
struct NameSets {
    params: FxHashSet<String>,
    coords: FxHashSet<String>,
    rates: FxHashSet<String>,
    accelerations: FxHashSet<String>,
    multipliers: FxHashSet<String>,
}

impl<'f> Checker<'f> {
    fn new(file: &'f ModelFile, incomplete: &'f Incomplete) -> Self {
        let coords: Vec<&str> = file
            .coordinates
            .iter()
            .map(|c| c.name.value.as_str())
            .collect();
        let mut checker = Self {
            file,
            incomplete,
            diagnostics: Diagnostics::new(),
            params: file
                .parameters
                .iter()
                .map(|p| p.name.value.as_str())
                .collect(),
            rates: coords.iter().map(|c| format!("{c}_dot")).collect(),
            accelerations: coords.iter().map(|c| format!("{c}_ddot")).collect(),
            multipliers: file
                .constraint_names()
                .iter()
                .map(|k| format!("lambda_{}", k.value))
                .collect(),
            coords,
            points: file.points.iter().map(|p| p.name.value.as_str()).collect(),
            bodies: file.bodies.iter().map(|b| b.name.value.as_str()).collect(),
            angular_velocities: true,
            vectors: true,
            interaction: false,
            sets: NameSets::default(),
        };
        let owned = |v: &[&str]| v.iter().map(|s| s.to_string()).collect();
        let sets = NameSets {
            params: owned(&checker.params),
            coords: owned(&checker.coords),
            rates: checker.rates.iter().cloned().collect(),
            accelerations: checker.accelerations.iter().cloned().collect(),
            multipliers: checker.multipliers.iter().cloned().collect(),
        };
        checker.sets = sets;
        checker
    }

    fn error(&mut self, d: Diagnostic) {
        self.diagnostics.push(d);
    }

    /// Whether a whole section may be missing from the model because of a reported error.
    fn section_lost(&self, section: &str, built_empty: bool) -> bool {
        built_empty && self.incomplete.has_section(section)
    }

    // Rule: parameters, coordinates, points and bodies have distinct names, none of which is
    // `t`, `pi` or a function name, or ends in `_dot` / `_ddot` (those spell rates and
    // accelerations of coordinates). Parameters and coordinates are Rust names in generated
    // code (fields and locals, a keyword as `r#type`), so none is one of the keywords that
    // cannot be raw (`self`, `Self`, `super`, `crate`); nor is the model's struct `Self`.
    // (Points and bodies are only strings there: any name will do.)
    fn names(&mut self) {
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
            } else if matches!(kind, "parameter" | "coordinate") && UNRAW_KEYWORDS.contains(&n) {
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
                    .with_help("parameters, coordinates, points and bodies share one namespace; rename one"),
                );
            } else {
                seen.insert(n, (name.location, kind));
            }
        }
    }

    // Rule: the model has at least one coordinate, and inertia: `kinetic` or at least one
    // body.
    fn presence(&mut self) {
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

    // Rule: every name in an expression is a parameter or `pi`, and where the expression may
    // depend on the configuration, a coordinate or `t`, and where it may depend on the
    // motion, a rate `<coordinate>_dot`:
    // - constant: masses, inertias, `gravity`, initial values;
    // - configuration (no rates): point positions, `potential`, body angles, stiffnesses,
    //   rest lengths, damping coefficients;
    // - motion: `kinetic`, generalized forces, forces, torques.
    // Accelerations (`_ddot`) appear nowhere: the equations of motion are derived.
    fn expressions(&mut self) {
        let file = self.file;
        if let Some(k) = &file.kinetic {
            self.resolve(k, Depends::Motion, "`kinetic`");
        }
        if let Some(v) = &file.potential {
            self.resolve(v, Depends::Position, "`potential`");
        }
        for (k, q) in &file.generalized_forces {
            self.resolve(
                q,
                Depends::Motion,
                &format!("the generalized force `{}`", k.value),
            );
        }
        self.vectors = false;
        for p in &file.points {
            let relative = p.relative.iter().flat_map(|r| &r.vectors);
            for c in p.position.iter().chain(relative.flat_map(|(_, v)| v)) {
                self.resolve(
                    c,
                    Depends::Position,
                    &format!("the position of point `{}`", p.name.value),
                );
            }
        }
        for f in &file.frames {
            for r in &f.rotations {
                self.resolve(
                    &r.angle,
                    Depends::Position,
                    &format!("the rotation of frame `{}`", f.name.value),
                );
            }
        }
        self.vectors = true;
        for b in &file.bodies {
            let name = &b.name.value;
            match &b.kind {
                BodyKind::Particle { mass, .. } => {
                    self.resolve(
                        mass,
                        Depends::Constant,
                        &format!("the mass of body `{name}`"),
                    );
                }
                BodyKind::Rigid {
                    mass,
                    inertia,
                    angle,
                    ..
                } => {
                    self.resolve(
                        mass,
                        Depends::Constant,
                        &format!("the mass of body `{name}`"),
                    );
                    self.resolve(
                        inertia,
                        Depends::Constant,
                        &format!("the inertia of body `{name}`"),
                    );
                    self.resolve(
                        angle,
                        Depends::Position,
                        &format!("the angle of body `{name}`"),
                    );
                }
                BodyKind::Spatial { mass, inertia, .. } => {
                    self.resolve(
                        mass,
                        Depends::Constant,
                        &format!("the mass of body `{name}`"),
                    );
                    for e in inertia.entries.iter().flatten() {
                        self.resolve(
                            e,
                            Depends::Constant,
                            &format!("the inertia of body `{name}`"),
                        );
                    }
                }
            }
        }
        if let Some(g) = &file.gravity {
            for c in &g.value {
                self.resolve(c, Depends::Constant, "`gravity`");
            }
        }
        for s in &file.springs {
            let name = &s.name.value;
            self.resolve(
                &s.stiffness,
                Depends::Position,
                &format!("the stiffness of spring `{name}`"),
            );
            if let Some(l) = &s.rest_length {
                self.resolve(
                    l,
                    Depends::Position,
                    &format!("the rest length of spring `{name}`"),
                );
            }
        }
        for d in &file.dampers {
            self.resolve(
                &d.coefficient,
                Depends::Position,
                &format!("the coefficient of damper `{}`", d.name.value),
            );
        }
        for f in &file.forces {
            for c in &f.vector {
                self.resolve(c, Depends::Motion, &format!("force `{}`", f.name.value));
            }
        }
        for t in &file.torques {
            for e in t.value.expressions() {
                self.resolve(e, Depends::Motion, &format!("torque `{}`", t.name.value));
            }
        }
        for (k, e) in &file.initial {
            self.resolve(
                e,
                Depends::Constant,
                &format!("the initial value of `{}`", k.value),
            );
        }
        for e in &file.events {
            self.resolve(
                &e.when,
                Depends::Event,
                &format!("the function of event `{}`", e.name.value),
            );
        }
        for q in &file.equilibria {
            for (c, e) in &q.values {
                self.resolve(
                    e,
                    Depends::Constant,
                    &format!("`{}` of equilibrium `{}`", c.value, q.name.value),
                );
            }
        }
    }

    /// Reports every name in `e` that `depends` does not allow; `what` names the expression.
    fn resolve(&mut self, e: &Expr, depends: Depends, what: &str) {
        let mut ids = Vec::new();
        identifiers(e, &mut ids);
        if vectors::uses_vectors(e) {
            let Some(points) = self.vector_points(e, depends, what) else {
                return;
            };
            ids.retain(|id| !points.contains(id));
        }
        for (n, at) in ids {
            let n = n.as_str();
            if self.interaction && n == "r" {
                continue;
            }
            if self.interaction && n == "r_dot" {
                if depends < Depends::Motion {
                    self.error(
                        Diagnostic::new(at, format!("{what} cannot depend on the rate `r_dot`"))
                            .with_help("it may use parameters, coordinates, `t` and `r`"),
                    );
                }
                continue;
            }
            let is_param = n == "pi" || self.sets.params.contains(n);
            let is_coord = self.sets.coords.contains(n);
            let is_rate = self.sets.rates.contains(n);
            let is_acceleration =
                depends >= Depends::Acceleration && self.sets.accelerations.contains(n);
            let is_multiplier = depends >= Depends::Event && self.sets.multipliers.contains(n);
            let is_angular_velocity =
                self.angular_velocities && self.file.angular_velocity_name(n).is_some();
            let needs = if is_param {
                Depends::Constant
            } else if is_coord || n == "t" {
                Depends::Position
            } else if is_rate || is_angular_velocity {
                Depends::Motion
            } else if is_acceleration {
                Depends::Acceleration
            } else if is_multiplier {
                Depends::Event
            } else {
                self.unknown(n, at, depends, what);
                continue;
            };
            if needs <= depends {
                continue;
            }
            let d = match (depends, needs) {
                (Depends::Constant, _) => {
                    let kind = match needs {
                        Depends::Motion => "the rate ",
                        _ if n == "t" => "the time ",
                        _ => "the coordinate ",
                    };
                    Diagnostic::new(
                        at,
                        format!("{what} must be constant, but it uses {kind}`{n}`"),
                    )
                    .with_help("use parameters, numbers, `pi` and functions of them")
                }
                _ => Diagnostic::new(at, format!("{what} cannot depend on the rate `{n}`"))
                    .with_help("it may use parameters, coordinates and `t`, not rates"),
            };
            self.error(d);
        }
    }

    /// The points `e` reads as vectors through the vector functions, with their locations;
    /// `None` after reporting why it cannot: vectors where they are not allowed (the
    /// definitions of points and frames, constants), shapes that do not fit
    /// ([`vectors::check_shapes`]), `vel` where the rates are not allowed.
    fn vector_points(
        &mut self,
        e: &Expr,
        depends: Depends,
        what: &str,
    ) -> Option<Vec<(String, Location)>> {
        if !self.vectors || depends < Depends::Position {
            let why = if self.vectors {
                "which must be constant"
            } else {
                "which defines the points and frames they read"
            };
            self.error(
                Diagnostic::new(
                    e.location,
                    format!("{what} uses the vector functions of points (`dot`, `cross`, `norm`, `distance`, `vel`), {why}"),
                )
                .with_help("write the expression with parameters, numbers and functions of them"),
            );
            return None;
        }
        let dimension = self.file.dimension.unwrap_or(2);
        let used = match vectors::check_shapes(e, &self.points, dimension, what) {
            Ok(used) => used,
            Err(errors) => {
                errors.into_iter().for_each(|d| self.error(d));
                return None;
            }
        };
        if depends < Depends::Motion && vectors::uses_velocities(e) {
            self.error(
                Diagnostic::new(
                    e.location,
                    format!("{what} cannot depend on the rates, but it uses `vel`"),
                )
                .with_help("it may use the positions of points, not their velocities"),
            );
            return None;
        }
        Some(used)
    }

    fn unknown(&mut self, n: &str, at: Location, depends: Depends, what: &str) {
        if self.incomplete.has_name(n)
            || n.strip_suffix("_dot")
                .is_some_and(|q| self.incomplete.has_name(q))
        {
            return;
        }
        if n.ends_with("_ddot") && depends < Depends::Acceleration {
            self.error(
                Diagnostic::new(
                    at,
                    format!("accelerations such as `{n}` cannot appear in a model file"),
                )
                .with_help(
                    "the equations of motion are derived: give positions or energies, and loads",
                ),
            );
            return;
        }
        // The rate (or acceleration) of something that is not a coordinate: a parameter, `t`,
        // a point or a body.
        let stem = n
            .strip_suffix("_ddot")
            .or_else(|| n.strip_suffix("_dot"))
            .filter(|s| !self.sets.coords.contains(*s));
        if let Some(stem) = stem {
            let kind = if self.sets.params.contains(stem) {
                Some("a parameter, which is constant")
            } else if stem == "t" {
                Some("the time")
            } else if self.points.contains(&stem) {
                Some("a point")
            } else if self.bodies.contains(&stem) {
                Some("a body")
            } else {
                None
            };
            if let Some(kind) = kind {
                let coordinates = self.coords.join(", ");
                self.error(
                    Diagnostic::new(
                        at,
                        format!("`{n}` in {what} is a rate of `{stem}`, {kind}, not a coordinate"),
                    )
                    .with_help(format!(
                        "only coordinates have rates (`<coordinate>_dot`; the coordinates are {coordinates}); a quantity that changes in time is a coordinate or a function of `t`"
                    )),
                );
                return;
            }
        }
        if self.points.contains(&n) || self.bodies.contains(&n) {
            let kind = if self.points.contains(&n) {
                "point"
            } else {
                "body"
            };
            self.error(
                Diagnostic::new(at, format!("`{n}` is a {kind}; {what} cannot use it as a value"))
                    .with_help("expressions use parameters, coordinates, rates, `t` and `pi`; write the components out"),
            );
            return;
        }
        if self.section_lost("parameters", self.file.parameters.is_empty())
            || self.section_lost("coordinates", self.file.coordinates.is_empty())
        {
            return;
        }
        let mut candidates: Vec<&str> = self.params.clone();
        if depends >= Depends::Position {
            candidates.extend(&self.coords);
            candidates.push("t");
        }
        if depends >= Depends::Motion {
            candidates.extend(self.rates.iter().map(String::as_str));
        }
        if depends >= Depends::Acceleration {
            candidates.extend(self.accelerations.iter().map(String::as_str));
        }
        if depends >= Depends::Event {
            candidates.extend(self.multipliers.iter().map(String::as_str));
        }
        candidates.push("pi");
        let d = Diagnostic::new(at, format!("unknown name `{n}` in {what}"));
        let d = match closest(n, &candidates) {
            Some(c) => d.with_help(format!("did you mean `{c}`?")),
            None => d.with_help(format!(
                "names here are: {}; declare parameters under `parameters:`",
                candidates.join(", ")
            )),
        };
        self.error(d);
    }

    // Rule: all points have the same number of components (2 or 3), and `gravity` and every
    // force have as many; planar rigid bodies exist only in 2-D models; `gravity` needs
    // points to act on.
    fn dimensions(&mut self) {
        let file = self.file;
        let Some(first) = file.points.first() else {
            if let Some(g) = &file.gravity
                && !self.incomplete.has_section("points")
            {
                self.error(
                    Diagnostic::new(g.location, "`gravity` acts on bodies, but the model has no points")
                        .with_help("add `points:` and `bodies:`, or write the gravitational energy into `potential:`"),
                );
            }
            return;
        };
        let dim = first.dimension();
        for p in &file.points[1..] {
            if p.dimension() != dim {
                self.error(
                    Diagnostic::new(
                        p.location,
                        format!(
                            "point `{}` has {} components but point `{}` has {dim}",
                            p.name.value,
                            p.dimension(),
                            first.name.value
                        ),
                    )
                    .with_help("a model is either planar (`[x, y]`) or spatial (`[x, y, z]`)"),
                );
            }
        }
        if let Some(g) = &file.gravity
            && g.value.len() != dim
        {
            let example = if dim == 2 { "[0, -g]" } else { "[0, 0, -g]" };
            self.error(
                Diagnostic::new(
                    g.location,
                    format!(
                        "`gravity` has {} components but the points have {dim}",
                        g.value.len()
                    ),
                )
                .with_help(format!("write it like `{example}`")),
            );
        }
        for f in &file.forces {
            if f.vector.len() != dim {
                self.error(Diagnostic::new(
                    f.location,
                    format!(
                        "force `{}` has {} components but the points have {dim}",
                        f.name.value,
                        f.vector.len()
                    ),
                ));
            }
        }
        for b in &file.bodies {
            match (&b.kind, dim) {
                (BodyKind::Rigid { .. }, 3) => self.error(
                    Diagnostic::new(
                        b.name.location,
                        format!("body `{}` is a planar rigid body, but the points are 3-D", b.name.value),
                    )
                    .with_help("a planar body (`inertia` a number, `angle`) turns in the plane of 2-component points; in 3-D a rigid body has a frame and an inertia tensor: `{ mass: m, com: G, frame: B, inertia: [I1, I2, I3] }`"),
                ),
                (BodyKind::Spatial { frame, .. }, 2) => self.error(
                    Diagnostic::new(
                        frame.location,
                        format!("body `{}` is a 3-D rigid body, but the points are planar", b.name.value),
                    )
                    .with_help("a 3-D body's centre of mass is a 3-D point (`[x, y, z]` or `{ from: O, B: [0, 0, l] }`); a planar body is `{ mass: m, inertia: I, com: G, angle: theta }`"),
                ),
                _ => {}
            }
        }
        for f in &file.forces {
            if let Some(frame) = &f.frame
                && f.vector.len() != 3
            {
                self.error(
                    Diagnostic::new(frame.location, format!("force `{}` is written in frame `{}`, which needs 3 components", f.name.value, frame.value))
                        .with_help("frames are 3-D: write `vector: [Fx, Fy, Fz]`, or leave out `in` for components in the plane"),
                );
            }
        }
        for t in &file.torques {
            if let TorqueValue::Spatial {
                vector, location, ..
            } = &t.value
                && vector.len() != 3
            {
                self.error(
                    Diagnostic::new(*location, format!("the vector of torque `{}` has {} components; a torque on a 3-D body has 3", t.name.value, vector.len()))
                        .with_help("write `vector: [Tx, Ty, Tz]`; a torque on a planar body is `value: tau`"),
                );
            }
        }
        if dim == 2
            && let Some(f) = file.frames.first()
        {
            self.error(
                Diagnostic::new(f.name.location, format!("frame `{}` is 3-D, but the points are planar", f.name.value))
                    .with_help("frames orient 3-D bodies and place 3-D points; a planar model gives its bodies an `angle`"),
            );
        }
    }

    // Rule: frames have distinct names other than the ground `N` and `from`; each frame's
    // parent is `N` or a frame defined before it (so that frames form a tree); a point
    // written from another point names one defined before it, and its vectors known frames.
    fn frames(&mut self) {
        let file = self.file;
        let mut defined: Vec<&str> = vec![GROUND_FRAME];
        for f in &file.frames {
            let n = f.name.value.as_str();
            if n == GROUND_FRAME || n == "from" {
                let why = if n == "from" {
                    "`from` is the key of a point's start"
                } else {
                    "`N` is the ground frame"
                };
                self.error(
                    Diagnostic::new(
                        f.name.location,
                        format!("frame name `{n}` is reserved: {why}"),
                    )
                    .with_help("choose another name"),
                );
                continue;
            }
            let p = f.parent.value.as_str();
            if !defined.contains(&p) {
                let later = file.frames.iter().any(|g| g.name.value == p);
                let d = if later {
                    Diagnostic::new(f.parent.location, format!("frame `{n}` is turned from `{p}`, which is not defined before it"))
                        .with_help("define a frame's parent above it (frames form a tree rooted at the ground frame `N`)")
                } else {
                    self.unknown_frame_message(&f.parent, &defined)
                };
                self.error(d);
            }
            if defined.contains(&n) {
                self.error(
                    Diagnostic::new(f.name.location, format!("duplicate frame name `{n}`"))
                        .with_help("rename one"),
                );
            }
            defined.push(n);
        }
        let frames: Vec<&str> = file
            .frames
            .iter()
            .map(|f| f.name.value.as_str())
            .chain([GROUND_FRAME])
            .collect();
        for (i, p) in file.points.iter().enumerate() {
            if let Some(wheel) = &p.wheel {
                let earlier = file.points[..i]
                    .iter()
                    .any(|q| q.name.value == wheel.centre.value);
                if !earlier
                    && file.points[i..]
                        .iter()
                        .any(|q| q.name.value == wheel.centre.value)
                {
                    self.error(
                        Diagnostic::new(wheel.centre.location, format!("the wheel of point `{}` is centred at `{}`, which is not defined before it", p.name.value, wheel.centre.value))
                            .with_help("define the wheel's centre above its contact point"),
                    );
                } else {
                    self.point(&wheel.centre);
                }
                self.frame(&wheel.frame, &frames);
                self.resolve(
                    &wheel.radius,
                    Depends::Constant,
                    &format!("the wheel radius of point `{}`", p.name.value),
                );
                continue;
            }
            let Some(relative) = &p.relative else {
                continue;
            };
            if let Some(from) = &relative.from {
                let earlier = file.points[..i].iter().any(|q| q.name.value == from.value);
                let later = file.points[i..].iter().any(|q| q.name.value == from.value);
                if later && !earlier {
                    self.error(
                        Diagnostic::new(
                            from.location,
                            format!(
                                "point `{}` is measured from `{}`, which is not defined before it",
                                p.name.value, from.value
                            ),
                        )
                        .with_help("define the point it starts from above it"),
                    );
                } else {
                    self.point(from);
                }
            }
            for (frame, _) in &relative.vectors {
                self.frame(frame, &frames);
            }
        }
        for b in &file.bodies {
            if let BodyKind::Spatial { frame, .. } = &b.kind {
                self.frame(frame, &frames);
            }
        }
        for f in &file.forces {
            if let Some(frame) = &f.frame {
                self.frame(frame, &frames);
            }
        }
        for w in &file.draw.wheels {
            self.point(&w.centre);
            self.frame(&w.frame, &frames);
            self.resolve(&w.radius, Depends::Constant, "the radius of a drawn wheel");
        }
        for t in &file.torques {
            if let TorqueValue::Spatial {
                frame: Some(frame), ..
            } = &t.value
            {
                self.frame(frame, &frames);
            }
        }
    }

    /// Reports `name` if it is not one of `frames`.
    fn frame(&mut self, name: &Located<String>, frames: &[&str]) {
        if frames.contains(&name.value.as_str()) || self.incomplete.has_name(&name.value) {
            return;
        }
        let d = self.unknown_frame_message(name, frames);
        self.error(d);
    }

    /// "unknown frame", with the closest of `frames`.
    fn unknown_frame_message(&self, name: &Located<String>, frames: &[&str]) -> Diagnostic {
        let d = Diagnostic::new(name.location, format!("unknown frame `{}`", name.value));
        match closest(&name.value, frames) {
            Some(c) => d.with_help(format!("did you mean `{c}`?")),
            None => d.with_help(format!(
                "frames are: {} (the ground); declare one under `frames:`",
                frames.join(", ")
            )),
        }
    }

    /// Reports `name` if it is not a point.
    fn point(&mut self, name: &Located<String>) {
        let n = name.value.as_str();
        if self.points.contains(&n)
            || self.incomplete.has_name(n)
            || self.section_lost("points", self.points.is_empty())
        {
            return;
        }
        let d = Diagnostic::new(name.location, format!("unknown point `{n}`"));
        let d = match closest(n, &self.points) {
            Some(c) => d.with_help(format!("did you mean `{c}`?")),
            None if self.points.is_empty() => d.with_help("declare it under `points:`"),
            None => d.with_help(format!("points are: {}", self.points.join(", "))),
        };
        self.error(d);
    }

    // Rule: every point named by a body, spring, damper, force or drawing exists; torques
    // act on planar rigid bodies; generalized forces are keyed by coordinates; initial
    // values by coordinates or rates.
    fn references(&mut self) {
        let file = self.file;
        for b in &file.bodies {
            self.point(b.kind.com());
        }
        for s in &file.springs {
            s.between.iter().for_each(|p| self.point(p));
        }
        for d in &file.dampers {
            d.between.iter().for_each(|p| self.point(p));
        }
        for f in &file.forces {
            self.point(&f.at);
        }
        for l in &file.draw.lines {
            l.iter().for_each(|p| self.point(p));
        }
        for p in &file.draw.trace {
            self.point(p);
        }
        for t in &file.torques {
            let name = &t.body.value;
            match file.bodies.iter().find(|b| b.name.value == *name) {
                Some(b) => match (&b.kind, &t.value) {
                    (BodyKind::Rigid { .. }, TorqueValue::Planar(_))
                    | (BodyKind::Spatial { .. }, TorqueValue::Spatial { .. }) => {}
                    (BodyKind::Rigid { .. }, TorqueValue::Spatial { location, .. }) => self.error(
                        Diagnostic::new(*location, format!("torque `{}` is a 3-D vector, but `{name}` is a planar rigid body", t.name.value))
                            .with_help("a torque on a planar body is `value: tau` (counter-clockwise, about the axis normal to the plane)"),
                    ),
                    (BodyKind::Spatial { .. }, TorqueValue::Planar(e)) => self.error(
                        Diagnostic::new(e.location, format!("torque `{}` is a number, but `{name}` is a 3-D rigid body", t.name.value))
                            .with_help("a torque on a 3-D body is a vector: `{ body: B, vector: [0, 0, T], in: B }`"),
                    ),
                    (BodyKind::Particle { .. }, _) => self.error(
                        Diagnostic::new(
                            t.body.location,
                            format!("torque `{}` acts on `{name}`, which is a particle", t.name.value),
                        )
                        .with_help("torques act on rigid bodies (planar with `inertia` and `angle`, 3-D with `frame`); apply a force to a particle"),
                    ),
                },
                None if self.incomplete.has_name(name)
                    || self.section_lost("bodies", file.bodies.is_empty()) => {}
                None => {
                    let d = Diagnostic::new(t.body.location, format!("unknown body `{name}`"));
                    let d = match closest(name, &self.bodies) {
                        Some(c) => d.with_help(format!("did you mean `{c}`?")),
                        None => d.with_help("declare it under `bodies:` as a planar rigid body"),
                    };
                    self.error(d);
                }
            }
        }
        let coordinates_lost = self.section_lost("coordinates", self.coords.is_empty());
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
        }
        for (k, _) in &file.initial {
            let n = k.value.as_str();
            let base = n.strip_suffix("_dot").unwrap_or(n);
            if self.sets.coords.contains(n)
                || self.sets.rates.contains(n)
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

    // Rule: constraints have distinct names; holonomic ones depend on q and t, non-holonomic
    // ones also on the rates; there are no more constraints than coordinates; `guess` marks
    // coordinates (not rates) of a model that has constraints.
    fn constraints(&mut self) {
        let file = self.file;
        for (k, e) in &file.constraints {
            self.resolve(e, Depends::Position, &format!("constraint `{}`", k.value));
        }
        for (k, e) in &file.nonholonomic {
            self.resolve(e, Depends::Motion, &format!("constraint `{}`", k.value));
        }
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
        for r in &file.rolling {
            self.rolling_contact(r);
        }
        for c in &file.point_constraints {
            self.point(&c.point);
            if file.dimension == Some(2) {
                if let Some(frame) = &c.frame {
                    self.error(
                        Diagnostic::new(
                            frame.location,
                            format!(
                                "constraint `{}` is in a planar model, which has no frames",
                                c.name.value
                            ),
                        )
                        .with_help("leave out `in`: the axes are the plane's x and y"),
                    );
                }
                if c.along.value == Axis::Z {
                    self.error(
                        Diagnostic::new(
                            c.along.location,
                            format!(
                                "constraint `{}` is planar, so it has no `z` axis",
                                c.name.value
                            ),
                        )
                        .with_help("in a planar model `along` is `x` or `y`"),
                    );
                }
            } else if let Some(frame) = &c.frame {
                let frames: Vec<&str> = file
                    .frames
                    .iter()
                    .map(|f| f.name.value.as_str())
                    .chain([GROUND_FRAME])
                    .collect();
                self.frame(frame, &frames);
            }
        }
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

    // Rule: equations of motion written by hand (`checks: equations_of_motion`) are one per
    // coordinate and use parameters, coordinates, rates, accelerations and `t`.
    fn hand_equations(&mut self) {
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

    // Rule (`floquet:`): each entry names an equilibrium; `axis_units`, `along` and `gives`
    // name parameters (`along` ≠ `gives`); every expression is a constant of the parameters;
    // colour components are whole numbers from 0 to 255.
    fn floquet_references(&mut self) {
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

    /// Reports `name` unless it is a parameter; `what` says where it was written.
    // Rule: an interaction acts between two distinct points of the model; its magnitude is
    // a function of the motion, where `r` and `r_dot` are the distance and its rate, which
    // are then no other name of the model.
    fn interactions(&mut self) {
        let file = self.file;
        for i in &file.interactions {
            let name = &i.name.value;
            i.between.iter().for_each(|p| self.point(p));
            let [a, b] = &i.between;
            if a.value == b.value {
                self.error(
                    Diagnostic::new(
                        b.location,
                        format!("interaction `{name}` acts between `{}` and itself", a.value),
                    )
                    .with_help("an interaction acts along the line of two distinct points; name the other point"),
                );
            }
            let what = format!("the magnitude of interaction `{name}`");
            let mut ids = Vec::new();
            identifiers(&i.magnitude, &mut ids);
            for (n, at) in &ids {
                let taken = if self.sets.params.contains(n.as_str()) {
                    Some("a parameter")
                } else if self.sets.coords.contains(n.as_str()) {
                    Some("a coordinate")
                } else if n == "r_dot" && self.sets.rates.contains(n.as_str()) {
                    Some("the rate of coordinate `r`")
                } else if self.points.contains(&n.as_str()) {
                    Some("a point")
                } else {
                    None
                };
                if let Some(kind) = taken
                    && super::file::INTERACTION_NAMES.contains(&n.as_str())
                {
                    self.error(
                        Diagnostic::new(
                            *at,
                            format!("`{n}` in {what} is ambiguous: it names the distance of the points (or its rate), and {kind} of the model"),
                        )
                        .with_help("rename the model's `r`, or write the distance as `distance(A, B)` and its rate as `dot(A - B, vel(A) - vel(B))/distance(A, B)`"),
                    );
                }
            }
            self.interaction = true;
            self.resolve(&i.magnitude, Depends::Motion, &what);
            self.interaction = false;
        }
    }

    // Rule: outputs are functions of the motion, named apart from the columns beside them
    // in a simulation's output (`t`, the coordinates and rates, `energy`).
    fn outputs(&mut self) {
        let file = self.file;
        for o in &file.outputs {
            let n = o.name.value.as_str();
            if n == "t"
                || n == "energy"
                || self.sets.coords.contains(n)
                || self.sets.rates.contains(n)
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
        }
    }

    fn parameter_name(&mut self, name: &Located<String>, what: &str) {
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

    // Rule: the reference values of `checks:` are expressions of the parameters (a conserved
    // quantity may also use coordinates, rates and `t`); `at:` names an entry of
    // `equilibria:`, `event:` an entry of `events:`, and `final_state` gives coordinates and
    // rates; `natural_frequencies` lists one value per mode (coordinates minus holonomic
    // constraints, when there are no non-holonomic ones).
    fn reference_checks(&mut self) {
        let file = self.file;
        let checks = &file.checks;
        for (key, modal) in [
            ("natural_frequencies", &checks.natural_frequencies),
            ("damping_ratios", &checks.damping_ratios),
        ] {
            let Some(modal) = modal else { continue };
            for (i, v) in modal.values.iter().enumerate() {
                self.resolve(v, Depends::Constant, &format!("value {} of `{key}`", i + 1));
            }
            if let Some(at) = &modal.at {
                let names: Vec<&str> = file
                    .equilibria
                    .iter()
                    .map(|e| e.name.value.as_str())
                    .collect();
                if !names.contains(&at.value.as_str()) && !self.incomplete.has_section("equilibria")
                {
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
        if let Some(period) = &checks.period {
            self.resolve(&period.value, Depends::Constant, "the `value` of `period`");
            let names: Vec<&str> = file.events.iter().map(|e| e.name.value.as_str()).collect();
            if !names.contains(&period.event.value.as_str())
                && !self.incomplete.has_section("events")
            {
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
        if let Some(state) = &checks.final_state {
            self.resolve(&state.t, Depends::Constant, "the time `t` of `final_state`");
            for (k, v) in &state.values {
                self.resolve(
                    v,
                    Depends::Constant,
                    &format!("the value of `{}` in `final_state`", k.value),
                );
                let n = k.value.as_str();
                if self.sets.coords.contains(n)
                    || self.sets.rates.contains(n)
                    || self.incomplete.has_section("coordinates")
                {
                    continue;
                }
                let mut candidates: Vec<&str> = self.coords.clone();
                candidates.extend(self.rates.iter().map(String::as_str));
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
        self.angular_velocities = false;
        for c in &checks.conserved {
            self.resolve(
                &c.value,
                Depends::Motion,
                &format!("conserved quantity `{}`", c.name.value),
            );
        }
        self.angular_velocities = true;
    }

    // Rule: user balances name existing bodies (each once per balance) and, for AMB, an
    // existing point; AMB needs a planar model; an LMB direction has as many components as
    // the points and depends only on parameters, coordinates and `t`; there are as many
    // balances as coordinates; and, since only gravity (at each centre of mass) and torques
    // (which name their body) can be assigned to the chosen bodies, a model with balances has
    // no point loads (forces, springs, dampers) and no energy-form pieces.
    fn balances(&mut self) {
        let file = self.file;
        if file.balances.is_empty() {
            return;
        }
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
        for b in &file.balances {
            let mut seen: Vec<&str> = Vec::new();
            for body in &b.bodies {
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
            match &b.kind {
                BalanceKind::Amb {
                    about, axis, frame, ..
                } => {
                    if !self.points.contains(&about.value.as_str()) {
                        let d = Diagnostic::new(
                            about.location,
                            format!("unknown point `{}`", about.value),
                        );
                        let d = match closest(&about.value, &self.points) {
                            Some(c) => d.with_help(format!("did you mean `{c}`?")),
                            None => d.with_help(format!("points are: {}", self.points.join(", "))),
                        };
                        self.error(d);
                    }
                    match (file.dimension, axis) {
                        (Some(3), None) => self.error(
                            Diagnostic::new(b.location, "an `amb` balance of a 3-D model needs the `axis` it takes moments about")
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
                BalanceKind::Lmb { along } => {
                    if let Some(dim) = file.dimension
                        && along.len() != dim
                    {
                        self.error(Diagnostic::new(
                            b.location,
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
                                    Diagnostic::new(
                                        location,
                                        format!("`along` cannot use `{name}`"),
                                    )
                                    .with_help(
                                        "a direction may use parameters, coordinates and `t`",
                                    ),
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    // Rule: a body's mass is positive and its inertia non-negative, when they are constant
    // expressions of the parameters (evaluated at the defaults).
    fn masses(&mut self) {
        let file = self.file;
        for b in &file.bodies {
            let (mass, inertia) = match &b.kind {
                BodyKind::Particle { mass, .. } => (mass, None),
                BodyKind::Rigid { mass, inertia, .. } => (mass, Some(inertia)),
                BodyKind::Spatial { mass, inertia, .. } => {
                    self.inertia_tensor(&b.name.value, inertia);
                    (mass, None)
                }
            };
            if let Some(problem) =
                evaluate(mass, &file.parameters).and_then(|m| mass_problem(&b.name.value, m))
            {
                self.error(
                    Diagnostic::new(mass.location, problem)
                        .with_help("a mass must be positive (at the parameters' defaults)"),
                );
            }
            if let Some(inertia) = inertia
                && let Some(problem) = evaluate(inertia, &file.parameters)
                    .and_then(|i| planar_inertia_problem(&b.name.value, i))
            {
                self.error(Diagnostic::new(inertia.location, problem).with_help(
                    "a centroidal moment of inertia is ≥ 0 (at the parameters' defaults)",
                ));
            }
        }
    }
}

impl Checker<'_> {
    /// Reports a rolling contact whose body is not a rigid body, whose point is unknown, or
    /// whose frame is unknown or given in a planar model, and an axis `z` in a planar one.
    fn rolling_contact(&mut self, r: &RollingContact) {
        let file = self.file;
        self.point(&r.point);
        match file.bodies.iter().find(|b| b.name.value == r.body.value) {
            Some(b) if matches!(b.kind, BodyKind::Particle { .. }) => self.error(
                Diagnostic::new(r.body.location, format!("rolling contact `{}` names `{}`, which is a particle", r.name.value, r.body.value))
                    .with_help("a body rolls about its centre of mass: name a rigid body (planar with `angle`, 3-D with `frame`)"),
            ),
            Some(_) => {}
            None if self.incomplete.has_name(&r.body.value)
                || self.section_lost("bodies", file.bodies.is_empty()) => {}
            None => {
                let d = Diagnostic::new(r.body.location, format!("unknown body `{}`", r.body.value));
                let d = match closest(&r.body.value, &self.bodies) {
                    Some(c) => d.with_help(format!("did you mean `{c}`?")),
                    None => d.with_help("declare it under `bodies:` as a rigid body"),
                };
                self.error(d);
            }
        }
        let planar = file.dimension == Some(2);
        if let Some(frame) = &r.frame {
            if planar {
                self.error(
                    Diagnostic::new(
                        frame.location,
                        format!(
                            "rolling contact `{}` is in a planar model, which has no frames",
                            r.name.value
                        ),
                    )
                    .with_help("leave out `in`: the axes are the plane's x and y"),
                );
            } else {
                let frames: Vec<&str> = file
                    .frames
                    .iter()
                    .map(|f| f.name.value.as_str())
                    .chain([GROUND_FRAME])
                    .collect();
                self.frame(frame, &frames);
            }
        }
        if planar {
            for a in &r.along {
                if a.value == Axis::Z {
                    self.error(
                        Diagnostic::new(
                            a.location,
                            format!(
                                "rolling contact `{}` is planar, so it has no `z` axis",
                                r.name.value
                            ),
                        )
                        .with_help("in a planar model `along` lists `x` and `y`"),
                    );
                }
            }
        }
    }

    /// Reports a 3-D inertia tensor that is not positive definite at the parameters'
    /// defaults (Sylvester's criterion on its leading minors), or whose principal moments
    /// break the triangle inequality `I₃ ≤ I₁ + I₂`, which every mass distribution satisfies.
    /// (Symmetric it is by construction: each off-diagonal entry is written once.)
    fn inertia_tensor(&mut self, body: &str, inertia: &InertiaTensor) {
        let parameters = &self.file.parameters;
        let mut e = [0.0; 6];
        for ((slot, entry), name) in e
            .iter_mut()
            .zip(&inertia.entries)
            .zip(["xx", "yy", "zz", "xy", "yz", "xz"])
        {
            if let Some(x) = entry {
                match evaluate(x, parameters) {
                    Some(v) if v.is_finite() => *slot = v,
                    Some(v) => {
                        self.error(
                            Diagnostic::new(
                                inertia.location,
                                format!(
                                    "the inertia of body `{body}` is not finite: its entry {name} is {v} at the parameters' defaults"
                                ),
                            )
                            .with_help("each entry of an inertia tensor is a finite number of kg·m² (check the parameters it is written with: a 0/0, a root of a negative number)"),
                        );
                        return;
                    }
                    None => return,
                }
            }
        }
        if let Some(problem) = inertia_problem(body, e) {
            let at = "at the parameters' defaults";
            let diagnostic = match problem {
                InertiaProblem::NotPositiveDefinite(message) => Diagnostic::new(
                    inertia.location,
                    format!("{message} {at}"),
                )
                .with_help("a rigid body's inertia tensor about its centre of mass is positive definite (its three principal moments are positive); a moment ≤ 0, or an off-diagonal entry as large as the moments it joins, is not"),
                InertiaProblem::NotARigidBody(message) => Diagnostic::new(
                    inertia.location,
                    format!("{message} {at}"),
                )
                .with_help("no mass distribution has one principal moment larger than the sum of the other two (in principal axes, I₃ = ∫(x² + y²) dm ≤ ∫(y² + z²) dm + ∫(x² + z²) dm = I₁ + I₂; equal for a flat body); check the moments and their axes"),
            };
            self.error(diagnostic);
        }
    }
}

/// What is wrong with the mass `m` (kg) of body `body`: `None` for a positive mass.
pub fn mass_problem(body: &str, m: f64) -> Option<String> {
    (m.is_nan() || m <= 0.0).then(|| format!("body `{body}` has non-positive mass `{m:?}` (kg)"))
}

/// What is wrong with the centroidal moment of inertia `i` (kg·m²) of the planar body
/// `body`: `None` for `i ≥ 0`.
pub fn planar_inertia_problem(body: &str, i: f64) -> Option<String> {
    (i.is_nan() || i < 0.0).then(|| format!("body `{body}` has negative inertia `{i:?}` (kg·m²)"))
}

/// Why a 3-D inertia tensor is not a rigid body's ([`inertia_problem`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum InertiaProblem {
    /// Not positive definite (or not finite): the message.
    NotPositiveDefinite(String),
    /// Positive definite, but its principal moments break `I₃ ≤ I₁ + I₂`: the message.
    NotARigidBody(String),
}

/// What is wrong with the inertia tensor `[xx, yy, zz, xy, yz, xz]` (kg·m², about the centre
/// of mass) of body `body`, by the rules every rigid body meets: finite entries, positive
/// definite (Sylvester's criterion on the leading minors of the tensor scaled by its largest
/// entry, each above `64ε`, so that neither 1e300 nor 1e-300 kg·m² overflows and a needle
/// whose axial moment is 1e-12 of the others passes, while a rotated zero moment does not),
/// and principal moments within the triangle inequality `I₃ ≤ I₁ + I₂` to 0.1 % of `I₃`.
/// `None` for a rigid body's tensor. The messages end where a caller says at which
/// parameter values.
pub fn inertia_problem(body: &str, e: [f64; 6]) -> Option<InertiaProblem> {
    if let Some((name, v)) = ["xx", "yy", "zz", "xy", "yz", "xz"]
        .iter()
        .zip(e)
        .find(|(_, v)| !v.is_finite())
    {
        return Some(InertiaProblem::NotPositiveDefinite(format!(
            "the inertia of body `{body}` is not finite: its entry {name} is {v}"
        )));
    }
    // Scaled by the largest entry, so that neither 1e300 nor 1e-300 kg·m² overflows or
    // underflows in the minors and moments below.
    let scale = e.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let [xx, yy, zz, xy, yz, xz] = e.map(|v| if scale > 0.0 { v / scale } else { v });
    let minors = [
        xx,
        xx * yy - xy * xy,
        xx * (yy * zz - yz * yz) - xy * (xy * zz - yz * xz) + xz * (xy * yz - yy * xz),
    ];
    // Each scaled minor carries a rounding error of a few ε: above 64ε it is positive, so a
    // needle whose smallest moment is 1e-12 of the others is definite, and the rounding of a
    // singular tensor (a rotated zero moment) is not taken for definiteness.
    // A diagonal tensor has no rounding to tell apart: positive moments are definite
    // (`diag(1e-14, 1, 1)`, a needle).
    let diagonal = xy == 0.0 && yz == 0.0 && xz == 0.0;
    let definite = scale > 0.0
        && if diagonal {
            xx > 0.0 && yy > 0.0 && zz > 0.0
        } else {
            minors.iter().all(|m| *m > 64.0 * f64::EPSILON)
        };
    if !definite {
        let [exx, eyy, ezz, exy, eyz, exz] = e.map(short);
        return Some(InertiaProblem::NotPositiveDefinite(format!(
            "the inertia of body `{body}` is not positive definite: [[{exx}, {exy}, {exz}], [{exy}, {eyy}, {eyz}], [{exz}, {eyz}, {ezz}]] kg·m²"
        )));
    }
    // The triangle inequality of the principal moments: `I₃ = ∫(x² + y²) dm ≤ ∫(y² + z²) dm
    // + ∫(x² + z²) dm = I₁ + I₂` in principal axes (equal for a flat body). Refused beyond
    // 0.1 % of `I₃`: a flat body's moments typed to four digits may miss the equality by a
    // few parts in 10⁴, and the moments computed here carry `√ε` where two coincide.
    let [a, b, c] = principal_moments([xx, yy, zz, xy, yz, xz]).map(|v| v * scale);
    let excess = c - (a + b);
    (excess > 1e-3 * c).then(|| {
        InertiaProblem::NotARigidBody(format!(
            "the inertia of body `{body}` is not a rigid body's: its principal moments {}, {} and {} kg·m² break the triangle inequality I₃ ≤ I₁ + I₂ by {} kg·m²",
            short(a),
            short(b),
            short(c),
            short(excess)
        ))
    })
}

/// A number in a diagnostic: 6 decimals between 1e-3 and 1e6 (trailing zeros dropped, as `1`,
/// `-0.5`, `0.001235`), 6 significant digits outside (`1.20000e-7`).
pub(crate) fn short(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e6) {
        format!("{v:.5e}")
    } else {
        let s = format!("{v:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// The eigenvalues of the symmetric 3 × 3 tensor `[xx, yy, zz, xy, yz, xz]`, ascending, by
/// the trigonometric solution of its characteristic cubic (Smith, *Eigenvalues of a symmetric
/// 3 × 3 matrix*, Commun. ACM 4(4), 1961): to rounding of the largest where they are apart,
/// to about `√ε` of it where two (nearly) coincide (the `acos` near ±1).
fn principal_moments([xx, yy, zz, xy, yz, xz]: [f64; 6]) -> [f64; 3] {
    let off = xy * xy + yz * yz + xz * xz;
    let mut e = if off == 0.0 {
        [xx, yy, zz]
    } else {
        let q = (xx + yy + zz) / 3.0;
        let p = ((xx - q).powi(2) + (yy - q).powi(2) + (zz - q).powi(2) + 2.0 * off) / 6.0;
        let p = p.sqrt();
        // B = (A − qI)/p; det B / 2 = cos 3φ.
        let (bxx, byy, bzz) = ((xx - q) / p, (yy - q) / p, (zz - q) / p);
        let (bxy, byz, bxz) = (xy / p, yz / p, xz / p);
        let det = bxx * (byy * bzz - byz * byz) - bxy * (bxy * bzz - byz * bxz)
            + bxz * (bxy * byz - byy * bxz);
        let phi = (det / 2.0).clamp(-1.0, 1.0).acos() / 3.0;
        let largest = q + 2.0 * p * phi.cos();
        let smallest = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
        [smallest, 3.0 * q - largest - smallest, largest]
    };
    e.sort_by(f64::total_cmp);
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The principal moments against diagonal tensors and a rotated one: `diag(1, 2, 3)`
    /// rotated by 30° about `z` (`xx = 1.25`, `yy = 1.75`, `xy = 0.25·√3 · (−1)`) keeps its
    /// eigenvalues 1, 2, 3 to 1e-14.
    #[test]
    fn principal_moments_are_the_eigenvalues() {
        assert_eq!(
            principal_moments([3.0, 1.0, 2.0, 0.0, 0.0, 0.0]),
            [1.0, 2.0, 3.0]
        );
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let (xx, yy, xy) = (
            c * c + 2.0 * s * s,
            s * s + 2.0 * c * c,
            (1.0 - 2.0) * c * s,
        );
        let e = principal_moments([xx, yy, 3.0, xy, 0.0, 0.0]);
        for (got, want) in e.iter().zip([1.0, 2.0, 3.0]) {
            assert!((got - want).abs() < 1e-14, "{e:?}");
        }
    }

    use crate::model::{schema, yaml};

    #[test]
    fn numbers_in_diagnostics_print_short() {
        for (v, s) in [
            (0.0, "0"),
            (1.0, "1"),
            (-0.5, "-0.5"),
            (0.001, "0.001"),
            (0.000_999_9, "9.99900e-4"),
            (1.2e-7, "1.20000e-7"),
            (999_999.0, "999999"),
            (1e6, "1.00000e6"),
            (-2.5e6, "-2.50000e6"),
            (1.0 / 3.0, "0.333333"),
        ] {
            assert_eq!(short(v), s, "{v}");
        }
    }

    fn errors(src: &str) -> Vec<String> {
        let root = yaml::parse(src).unwrap();
        let file = schema::build("t.yaml", src, &root).unwrap();
        match check(&file) {
            Ok(()) => Vec::new(),
            Err(d) => d
                .iter()
                .map(|d| format!("{}: {}", d.location, d.message))
                .collect(),
        }
    }

    const HEAD: &str = "name: a\nparameters: { m: 1, l: 2 }\ncoordinates: [q]\n";

    #[test]
    fn a_valid_model_passes() {
        let src = format!(
            "{HEAD}points: {{ O: [0, 0], P: [l*sin(q), -l*cos(q)] }}\nbodies: {{ bob: {{ mass: m, at: P }} }}\ngravity: [0, -9.81]\ninitial: {{ q: pi/4, q_dot: 0 }}\n"
        );
        assert_eq!(errors(&src), Vec::<String>::new());
    }

    #[test]
    fn dependencies_are_enforced() {
        let src = format!(
            "{HEAD}kinetic: m*q_dot^2/2 + q_ddot\npotential: q_dot\ninitial: {{ q: l*q }}\n"
        );
        assert_eq!(
            errors(&src),
            [
                "4:24: accelerations such as `q_ddot` cannot appear in a model file",
                "5:12: `potential` cannot depend on the rate `q_dot`",
                "6:17: the initial value of `q` must be constant, but it uses the coordinate `q`",
            ]
        );
    }

    #[test]
    fn reserved_and_duplicate_names() {
        let src = "name: a\nparameters: { t: 1, q: 2, sin: 3, x_dot: 4 }\ncoordinates: [q]\nkinetic: q_dot^2\n";
        assert_eq!(
            errors(src),
            [
                "2:15: parameter name `t` is reserved: `t` is time",
                "2:27: parameter name `sin` is reserved: `sin` is a function",
                "2:35: parameter name `x_dot` ends in `_dot` or `_ddot`, which spell rates",
                "3:15: duplicate name `q`: already a parameter at 2:21",
            ]
        );
    }

    /// Issue 28: the keywords that are not raw identifiers cannot name a parameter, a
    /// coordinate or (as `Self`) the model; any other keyword can, and any name a point.
    #[test]
    fn keywords_that_generated_code_cannot_spell_are_reserved() {
        let src = "name: self\nparameters: { super: 1, type: 2 }\ncoordinates: [crate, Self]\npoints: { self: [crate, Self] }\nkinetic: crate_dot^2 + Self_dot^2\n";
        assert_eq!(
            errors(src),
            [
                "1:7: model name `self` is reserved: its struct would be `Self`, a Rust keyword",
                "2:15: parameter name `super` is reserved: `super` is a Rust keyword, which generated code cannot use as a name (not even as `r#super`)",
                "3:15: coordinate name `crate` is reserved: `crate` is a Rust keyword, which generated code cannot use as a name (not even as `r#crate`)",
                "3:22: coordinate name `Self` is reserved: `Self` is a Rust keyword, which generated code cannot use as a name (not even as `r#Self`)",
            ]
        );
    }

    #[test]
    fn the_evaluator_uses_parameter_defaults() {
        let src = "name: a\nparameters: { m: 2, l: 3 }\ncoordinates: [q]\nkinetic: q_dot^2\n";
        let root = yaml::parse(src).unwrap();
        let file = schema::build("t.yaml", src, &root).unwrap();
        let e =
            crate::model::parser::parse_expr("m*l^2/12 + cos(pi)", Location::default()).unwrap();
        assert_eq!(evaluate(&e, &file.parameters), Some(2.0 * 9.0 / 12.0 - 1.0));
        let e = crate::model::parser::parse_expr("m*q", Location::default()).unwrap();
        assert_eq!(evaluate(&e, &file.parameters), None);
    }

    #[test]
    fn masses_and_inertias() {
        let src = format!(
            "{HEAD}points: {{ P: [q, 0] }}\nbodies:\n  a: {{ mass: m - 1, at: P }}\n  b: {{ mass: m, inertia: -l, com: P, angle: q }}\n"
        );
        assert_eq!(
            errors(&src),
            [
                "6:14: body `a` has non-positive mass `0.0` (kg)",
                "7:26: body `b` has negative inertia `-2.0` (kg·m²)",
            ]
        );
    }

    /// A 3-D inertia whose largest principal moment exceeds the sum of the others (beyond 0.1 %) is refused,
    /// also when products of inertia hide it (`diag(1, 1, 3)` rotated by 30° about `x`); a
    /// flat body's (`I₃ = I₁ + I₂`, here `diag(1, 2, 3)` rotated) and an ordinary one pass.
    #[test]
    fn an_inertia_breaking_the_triangle_inequality_is_refused() {
        let body = |inertia: &str| {
            format!(
                "name: t\nparameters: {{ m: 1.0 }}\ncoordinates: [psi]\nframes:\n  B: {{ parent: N, axis: z, angle: psi }}\npoints:\n  G: [0, 0, 0]\nbodies:\n  disc: {{ mass: m, com: G, frame: B, inertia: {inertia} }}\n"
            )
        };
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        // diag(1, 1, 3) rotated about x: yy = c²·1 + s²·3, zz = s²·1 + c²·3, yz = (3 − 1)cs.
        let hidden = format!(
            "{{ xx: 1, yy: {}, zz: {}, yz: {} }}",
            c * c + 3.0 * s * s,
            s * s + 3.0 * c * c,
            2.0 * c * s
        );
        for inertia in ["{ xx: 1, yy: 1, zz: 3 }", hidden.as_str()] {
            let found = errors(&body(inertia));
            assert!(
                found.len() == 1 && found[0].contains("triangle inequality I₃ ≤ I₁ + I₂"),
                "{inertia}: {found:?}"
            );
        }
        let flat = format!(
            "{{ xx: 1, yy: {}, zz: {}, yz: {} }}",
            2.0 * c * c + 3.0 * s * s,
            2.0 * s * s + 3.0 * c * c,
            c * s
        );
        for inertia in [
            "{ xx: 1, yy: 2, zz: 3 }",
            "{ xx: 2, yy: 2, zz: 3 }",
            flat.as_str(),
        ] {
            assert_eq!(errors(&body(inertia)), Vec::<String>::new(), "{inertia}");
        }
    }

    /// Definiteness judged on the tensor scaled by its largest entry: `diag(1e300, 1e300,
    /// 1e300)`, `diag(1e-300, …)` and needles whose axial moment is 1e-12 of the others (along
    /// `x`, and rotated by 30° about `z`) are positive definite (before, each was refused: the
    /// minors overflowed, underflowed or sat at a threshold of 1e-12 of the largest entry). A
    /// rotated zero moment, `diag(0, 1, 1)` turned by 30°, is refused with its entries in six
    /// digits; a NaN entry is named as not finite (before, skipped here and reported later as a
    /// singular mass matrix).
    #[test]
    fn inertias_are_judged_at_their_own_scale() {
        let body = |inertia: &str| {
            format!(
                "name: t\nparameters: {{ m: 1.0, z: 0.0 }}\ncoordinates: [psi]\nframes:\n  B: {{ parent: N, axis: z, angle: psi }}\npoints:\n  G: [0, 0, 0]\nbodies:\n  disc: {{ mass: m, com: G, frame: B, inertia: {inertia} }}\n"
            )
        };
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        // diag(a, 1, 1) rotated about z: xx = c²a + s², yy = s²a + c², xy = (a − 1)cs.
        let rotated = |a: f64| {
            format!(
                "{{ xx: {:e}, yy: {:e}, zz: 1, xy: {:e} }}",
                c * c * a + s * s,
                s * s * a + c * c,
                (a - 1.0) * c * s
            )
        };
        for inertia in [
            "[1e300, 1e300, 1e300]".to_string(),
            "[1e-300, 1e-300, 1e-300]".to_string(),
            "[1e-12, 1, 1]".to_string(),
            "[1e-14, 1, 1]".to_string(),
            rotated(1e-12),
        ] {
            assert_eq!(errors(&body(&inertia)), Vec::<String>::new(), "{inertia}");
        }
        let found = errors(&body(&rotated(0.0)));
        assert!(
            found.len() == 1
                && found[0].contains("is not positive definite: [[0.25, -0.433013, 0]"),
            "{found:?}"
        );
        let found = errors(&body("[z/z, 1, 1]"));
        assert!(
            found.len() == 1 && found[0].contains("is not finite: its entry xx is NaN"),
            "{found:?}"
        );
    }
}
