//! The expressions of a model file: every name they use defined where it may be used, the vector
//! functions of points, and the dimensions of vectors.

use super::*;
use crate::model::elements::{body, energy, frame, gravity, point};

impl Checker<'_> {
    // Rule: every name in an expression is a parameter or `pi`, and where the expression may
    // depend on the configuration, a coordinate or `t`, and where it may depend on the
    // motion, a rate `<coordinate>_dot`:
    // - constant: masses, inertias, `gravity`, initial values;
    // - configuration (no rates): point positions, `potential`, body angles, stiffnesses,
    //   rest lengths, damping coefficients;
    // - motion: `kinetic`, generalized forces (forces and torques: their own rules, in
    //   elements/).
    // Accelerations (`_ddot`) appear nowhere: the equations of motion are derived.
    // Long: one list, one call per place in the file where an expression stands, in the file's
    // order, as unit_check's `walk`; split by section it would only be a longer list.
    pub(super) fn expressions(&mut self) {
        let file = self.file;
        energy::rules(file.written_energies(), self);
        self.vectors = false;
        point::expression_rules(&file.points, self);
        frame::angle_rules(&file.frames, self);
        self.vectors = true;
        body::expression_rules(&file.bodies, self);
        if let Some(g) = &file.gravity {
            gravity::rules(g, self);
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
    pub(super) fn resolve(&mut self, e: &Expr, depends: Depends, what: &str) {
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
            let is_rate = self.sets.rates.contains(n) || self.sets.speeds.contains(n);
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

    pub(super) fn unknown(&mut self, n: &str, at: Location, depends: Depends, what: &str) {
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
    pub(super) fn dimensions(&mut self) {
        let file = self.file;
        let Some(dim) = point::dimension_rules(&file.points, self) else {
            if let Some(g) = &file.gravity {
                gravity::dimension_rules(g, self, None);
            }
            return;
        };
        self.vector_lengths(dim);
        self.spatial_pieces(dim);
    }

    /// Checks that `gravity` and every force have `dim` components, as the points do (and a
    /// force written in a frame 3: `Force::dimension_rules`).
    fn vector_lengths(&mut self, dim: usize) {
        let file = self.file;
        if let Some(g) = &file.gravity {
            gravity::dimension_rules(g, self, Some(dim));
        }
        for f in &file.forces {
            f.dimension_rules(self, dim);
        }
    }

    /// Checks that the 3-D pieces (3-D bodies, 3-D torques, frames)
    /// fit the points' dimension `dim`, and that planar rigid bodies are in a 2-D model.
    fn spatial_pieces(&mut self, dim: usize) {
        let file = self.file;
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
        for t in &file.torques {
            t.dimension_rules(self);
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
}
