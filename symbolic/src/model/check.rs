//! Cross-object rules of a model file, each stated above its check. Every violation is
//! collected; nothing stops at the first.

use super::ast::{Expr, FUNCTIONS};
use super::diagnostic::Diagnostic;
use super::file::{BodyKind, ModelFile};
use super::located::Location;
use super::parser::{closest, eval_expr, identifiers};

/// What a name in an expression may refer to, for one kind of expression.
#[derive(Clone, Copy)]
struct Allowed {
    coordinates: bool,
    rates: bool,
    time: bool,
}

const CONSTANT: Allowed = Allowed {
    coordinates: false,
    rates: false,
    time: false,
};
const POSITION: Allowed = Allowed {
    coordinates: true,
    rates: false,
    time: true,
};
const ANY: Allowed = Allowed {
    coordinates: true,
    rates: true,
    time: true,
};

/// Runs every rule on `file`.
///
/// # Errors
/// Every violation, in no particular order (the caller sorts by location).
pub fn check(file: &ModelFile) -> Result<(), Vec<Diagnostic>> {
    let mut errors = Vec::new();
    let params: Vec<&str> = file
        .parameters
        .iter()
        .map(|p| p.name.value.as_str())
        .collect();
    let coords: Vec<&str> = file
        .coordinates
        .iter()
        .map(|c| c.name.value.as_str())
        .collect();
    let rates: Vec<String> = coords.iter().map(|c| format!("{c}_dot")).collect();
    let points: Vec<&str> = file.points.iter().map(|p| p.name.value.as_str()).collect();

    // Rule: parameters, coordinates, points and bodies have distinct names, none of which is
    // `t`, `pi`, a function name, or ends in `_dot` / `_ddot` (those spell rates).
    let mut seen: Vec<(&str, Location, &str)> = Vec::new();
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
            errors.push(
                Diagnostic::new(name.location, format!("{kind} name `{n}` is reserved")).with_help(
                    "`t` is time, `pi` is π, and function names are taken; choose another name",
                ),
            );
        } else if n.ends_with("_dot") || n.ends_with("_ddot") {
            errors.push(Diagnostic::new(name.location, format!("{kind} name `{n}` ends in `_dot`/`_ddot`, which spell rates")).with_help("rates of coordinates are written `<coordinate>_dot` automatically; choose another name"));
        }
        if let Some((_, first, first_kind)) = seen.iter().find(|(s, _, _)| *s == n) {
            errors.push(
                Diagnostic::new(
                    name.location,
                    format!(
                        "`{n}` is already the name of a {first_kind} (line {})",
                        first.line
                    ),
                )
                .with_help("names of parameters, coordinates, points and bodies must all differ"),
            );
        } else {
            seen.push((n, name.location, kind));
        }
    }

    // Rule: the model has at least one coordinate, and inertia (`kinetic` or `bodies`).
    if file.coordinates.is_empty() {
        errors.push(
            Diagnostic::new(file.name.location, "the model has no coordinates")
                .with_help("list the generalized coordinates: `coordinates: [q]`"),
        );
    }
    if file.kinetic.is_none() && file.bodies.is_empty() {
        errors.push(
            Diagnostic::new(file.name.location, "the model has no kinetic energy")
                .with_help("give `kinetic:` (energy form) or `bodies:` (kinematic form)"),
        );
    }

    // Rule: every name in an expression is a parameter, `t`, `pi`, and where the expression
    // may depend on the motion, a coordinate or (for loads) a rate. Accelerations never.
    let names = |e: &Expr, allowed: Allowed, what: &str, errors: &mut Vec<Diagnostic>| {
        let mut ids = Vec::new();
        identifiers(e, &mut ids);
        for (n, loc) in ids {
            let is_param = params.contains(&n.as_str()) || n == "pi";
            let is_coord = coords.contains(&n.as_str());
            let is_rate = rates.contains(&n);
            let is_time = n == "t";
            let ok = is_param
                || (is_coord && allowed.coordinates)
                || (is_rate && allowed.rates)
                || (is_time && allowed.time);
            if ok {
                continue;
            }
            let d = if is_coord || is_time {
                Diagnostic::new(loc, format!("{what} cannot depend on `{n}`")).with_help(format!(
                    "{what} must be constant: use parameters and numbers"
                ))
            } else if is_rate {
                Diagnostic::new(loc, format!("{what} cannot depend on the rate `{n}`"))
                    .with_help(format!("{what} may use coordinates and `t`, not rates"))
            } else if n.ends_with("_ddot") {
                Diagnostic::new(
                    loc,
                    format!("accelerations such as `{n}` cannot appear in a model file"),
                )
                .with_help(
                    "the equations of motion are derived; give positions, energies and loads",
                )
            } else {
                let mut candidates: Vec<&str> = params.clone();
                if allowed.coordinates {
                    candidates.extend(&coords);
                }
                if allowed.rates {
                    candidates.extend(rates.iter().map(String::as_str));
                }
                let d = Diagnostic::new(loc, format!("unknown name `{n}` in {what}"));
                match closest(&n, &candidates) {
                    Some(c) => d.with_help(format!("did you mean `{c}`?")),
                    None => d.with_help(format!(
                        "names here are parameters ({}){}, `t` and `pi`",
                        params.join(", "),
                        if allowed.coordinates {
                            format!(", coordinates ({})", coords.join(", "))
                        } else {
                            String::new()
                        }
                    )),
                }
            };
            errors.push(d);
        }
    };
    if let Some(k) = &file.kinetic {
        names(k, ANY, "`kinetic`", &mut errors);
    }
    if let Some(v) = &file.potential {
        names(v, POSITION, "`potential`", &mut errors);
    }
    for (_, q) in &file.generalized_forces {
        names(q, ANY, "a generalized force", &mut errors);
    }
    for p in &file.points {
        for c in &p.position {
            names(
                c,
                POSITION,
                &format!("the position of point `{}`", p.name.value),
                &mut errors,
            );
        }
    }
    for b in &file.bodies {
        match &b.kind {
            BodyKind::Particle { mass, .. } => names(mass, CONSTANT, "a mass", &mut errors),
            BodyKind::Rigid {
                mass,
                inertia,
                angle,
                ..
            } => {
                names(mass, CONSTANT, "a mass", &mut errors);
                names(inertia, CONSTANT, "an inertia", &mut errors);
                names(angle, POSITION, "a body angle", &mut errors);
            }
        }
    }
    if let Some(g) = &file.gravity {
        for c in &g.value {
            names(c, CONSTANT, "`gravity`", &mut errors);
        }
    }
    for s in &file.springs {
        names(&s.stiffness, CONSTANT, "a stiffness", &mut errors);
        if let Some(l) = &s.rest_length {
            names(l, CONSTANT, "a rest length", &mut errors);
        }
    }
    for d in &file.dampers {
        names(
            &d.coefficient,
            CONSTANT,
            "a damping coefficient",
            &mut errors,
        );
    }
    for f in &file.forces {
        for c in &f.vector {
            names(c, ANY, "a force", &mut errors);
        }
    }
    for t in &file.torques {
        names(&t.value, ANY, "a torque", &mut errors);
    }
    for (_, e) in &file.initial {
        names(e, CONSTANT, "an initial value", &mut errors);
    }

    // Rule: all points have the same number of components (2 or 3), and so do gravity and
    // forces; planar rigid bodies only exist in 2-D models.
    let dim = file.dimension;
    for p in &file.points {
        if Some(p.position.len()) != dim {
            errors.push(
                Diagnostic::new(
                    p.location,
                    format!(
                        "point `{}` has {} components but the first point has {}",
                        p.name.value,
                        p.position.len(),
                        dim.unwrap_or(0)
                    ),
                )
                .with_help("a model is either planar ([x, y]) or spatial ([x, y, z])"),
            );
        }
    }
    let dim_or = |n: usize| dim.unwrap_or(n);
    if let Some(g) = &file.gravity {
        if dim.is_none() {
            errors.push(
                Diagnostic::new(g.location, "`gravity` needs points and bodies to act on")
                    .with_help("add `points:` and `bodies:`, or put gravity into `potential:`"),
            );
        } else if g.value.len() != dim_or(g.value.len()) {
            errors.push(Diagnostic::new(
                g.location,
                format!(
                    "`gravity` has {} components but the points have {}",
                    g.value.len(),
                    dim_or(0)
                ),
            ));
        }
    }
    for f in &file.forces {
        if f.vector.len() != dim_or(f.vector.len()) {
            errors.push(Diagnostic::new(
                f.location,
                format!(
                    "force `{}` has {} components but the points have {}",
                    f.name.value,
                    f.vector.len(),
                    dim_or(0)
                ),
            ));
        }
    }

    // Rule: every point named by a body, spring, damper, force or drawing exists; torques act
    // on planar rigid bodies; generalized forces are keyed by coordinates; initial values by
    // coordinates or rates.
    let point_ref = |name: &super::located::Located<String>, errors: &mut Vec<Diagnostic>| {
        if !points.contains(&name.value.as_str()) {
            let d = Diagnostic::new(name.location, format!("unknown point `{}`", name.value));
            errors.push(match closest(&name.value, &points) {
                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                None => d.with_help(if points.is_empty() {
                    "declare it under `points:`".to_string()
                } else {
                    format!("points are: {}", points.join(", "))
                }),
            });
        }
    };
    for b in &file.bodies {
        match &b.kind {
            BodyKind::Particle { at, .. } => point_ref(at, &mut errors),
            BodyKind::Rigid { com, .. } => {
                point_ref(com, &mut errors);
                if dim == Some(3) {
                    errors.push(Diagnostic::new(b.name.location, format!("body `{}` is a planar rigid body in a 3-D model", b.name.value)).with_help("rigid bodies (with `inertia` and `angle`) are planar: use 2-component points, or model the body as particles"));
                }
            }
        }
    }
    for s in &file.springs {
        for p in &s.between {
            point_ref(p, &mut errors);
        }
    }
    for d in &file.dampers {
        for p in &d.between {
            point_ref(p, &mut errors);
        }
    }
    for f in &file.forces {
        point_ref(&f.at, &mut errors);
    }
    for l in &file.draw.lines {
        for p in l {
            point_ref(p, &mut errors);
        }
    }
    for p in &file.draw.trace {
        point_ref(p, &mut errors);
    }
    for t in &file.torques {
        match file.bodies.iter().find(|b| b.name.value == t.body.value) {
            Some(b) if matches!(b.kind, BodyKind::Rigid { .. }) => {}
            Some(_) => errors.push(Diagnostic::new(t.body.location, format!("torque `{}` acts on `{}`, a particle", t.name.value, t.body.value)).with_help("torques act on planar rigid bodies (with `inertia` and `angle`); apply forces to particles")),
            None => errors.push(Diagnostic::new(t.body.location, format!("unknown body `{}`", t.body.value))),
        }
    }
    for (k, _) in &file.generalized_forces {
        if !coords.contains(&k.value.as_str()) {
            let d = Diagnostic::new(k.location, format!("`{}` is not a coordinate", k.value));
            errors.push(match closest(&k.value, &coords) {
                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                None => d.with_help(format!("coordinates are: {}", coords.join(", "))),
            });
        }
    }
    let mut initial_seen: Vec<&str> = Vec::new();
    for (k, _) in &file.initial {
        if !coords.contains(&k.value.as_str()) && !rates.contains(&k.value) {
            let mut cands: Vec<&str> = coords.clone();
            cands.extend(rates.iter().map(String::as_str));
            let d = Diagnostic::new(
                k.location,
                format!("`{}` is neither a coordinate nor a rate", k.value),
            );
            errors.push(match closest(&k.value, &cands) {
                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                None => d.with_help(format!(
                    "initial values are given for: {}",
                    cands.join(", ")
                )),
            });
        } else if initial_seen.contains(&k.value.as_str()) {
            errors.push(Diagnostic::new(
                k.location,
                format!("`{}` is given twice", k.value),
            ));
        }
        initial_seen.push(k.value.as_str());
    }

    // Rule: masses are positive and inertias non-negative at the default parameters.
    let value = |e: &Expr| {
        eval_expr(e, &|n| {
            file.parameters
                .iter()
                .find(|p| p.name.value == n)
                .map(|p| p.value)
        })
        .ok()
    };
    for b in &file.bodies {
        let (mass, inertia) = match &b.kind {
            BodyKind::Particle { mass, .. } => (mass, None),
            BodyKind::Rigid { mass, inertia, .. } => (mass, Some(inertia)),
        };
        if let Some(m) = value(mass) {
            if !(m > 0.0) {
                errors.push(
                    Diagnostic::new(
                        mass.location,
                        format!("body `{}` has non-positive mass `{m}` (kg)", b.name.value),
                    )
                    .with_help("masses must be positive"),
                );
            }
        }
        if let Some(i) = inertia.and_then(|i| value(i).map(|v| (i, v))) {
            if !(i.1 >= 0.0) {
                errors.push(
                    Diagnostic::new(
                        i.0.location,
                        format!(
                            "body `{}` has negative inertia `{}` (kg m^2)",
                            b.name.value, i.1
                        ),
                    )
                    .with_help("a centroidal moment of inertia is ≥ 0"),
                );
            }
        }
    }

    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors)
    }
}
