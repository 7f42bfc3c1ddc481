//! The syntax of `bodies:`: how a body is read from its entry and written back.

use super::{Body, BodyKind, InertiaTensor};
use crate::model::ast::Expr;
use crate::model::diagnostic::Diagnostic;
use crate::model::located::Located;
use crate::model::schema::entries::{Entries, get, get_key};
use crate::model::schema::walk::{Ctx, Keyed};
use crate::model::schema::write::{NotRewritten, Writer, flow, list};
use crate::model::yaml::{YamlKind, YamlNode};

const KEYS: &[&str] = &["mass", "at", "inertia", "com", "angle", "frame"];
const PARTICLE_EXAMPLE: &str = "{ mass: m, at: P }";
const RIGID_EXAMPLE: &str = "{ mass: m, inertia: m*l^2/12, com: G, angle: theta }";
const SPATIAL_EXAMPLE: &str = "{ mass: m, com: G, frame: B, inertia: [I1, I2, I3] }";

/// `bodies:` — `name: { mass, at }`, `name: { mass, inertia, com, angle }` or
/// `name: { mass, com, frame, inertia }`.
pub(crate) fn read(cx: &mut Ctx<'_>, node: &YamlNode) -> Vec<Body> {
    let spec = Keyed {
        what: "`bodies`",
        example: "bodies: { bob: { mass: m, at: P } }",
        names: Some("body"),
        drop: true,
    };
    cx.keyed(node, spec, read_body)
}

/// One body: a particle `{ mass, at }`, a planar rigid body `{ mass, inertia, com, angle }`,
/// or, with a `frame`, a 3-D one ([`read_spatial`]).
fn read_body(cx: &mut Ctx<'_>, k: &Located<String>, v: &YamlNode) -> Option<Body> {
    let what = format!("body `{}`", k.value);
    let f = cx.map(v, &what, &format!("{}: {PARTICLE_EXAMPLE}", k.value))?;
    cx.unknown_keys(f, &what, KEYS, KEYS);
    if get(f, "frame").is_some() {
        return read_spatial(cx, k, f);
    }
    if let Some(inertia) = get(f, "inertia")
        && !matches!(inertia.kind, YamlKind::Scalar { .. })
    {
        cx.error(
            Diagnostic::new(
                inertia.location,
                format!("{what} has an inertia tensor but no `frame`"),
            )
            .with_help(format!(
                "a planar rigid body has a scalar inertia about the axis normal to the plane (`{RIGID_EXAMPLE}`); a 3-D body has the frame its inertia is written in: `{SPATIAL_EXAMPLE}`"
            )),
        );
        return None;
    }
    let rigid_key = ["inertia", "com", "angle"]
        .into_iter()
        .find(|r| get(f, r).is_some());
    let Some(rigid_key) = rigid_key else {
        // A particle: `{ mass, at }`.
        let complete = cx.require(
            f,
            k.location,
            &what,
            &["mass", "at"],
            &format!("{}: {PARTICLE_EXAMPLE}", k.value),
        );
        let mass = get(f, "mass").and_then(|n| cx.expr(n, "a mass"));
        let at = get(f, "at").and_then(|n| cx.name(n, "`at`"));
        let (Some(mass), Some(at), true) = (mass, at, complete) else {
            return None;
        };
        return Some(Body {
            name: k.clone(),
            kind: BodyKind::Particle { mass, at },
        });
    };
    // A planar rigid body: `{ mass, inertia, com, angle }`.
    if let Some(at) = get_key(f, "at") {
        cx.error(
            Diagnostic::new(
                at.location,
                format!(
                    "{what} has `{rigid_key}`, so it is a planar rigid body, which has no `at`"
                ),
            )
            .with_help(format!(
                "a rigid body's position is its centre of mass `com`: `{RIGID_EXAMPLE}`; a particle is `{PARTICLE_EXAMPLE}`"
            )),
        );
    }
    let complete = cx.require(
        f,
        k.location,
        &format!("{what} (a planar rigid body, as it has `{rigid_key}`)"),
        &["mass", "inertia", "com", "angle"],
        &format!("{}: {RIGID_EXAMPLE}", k.value),
    );
    let mass = get(f, "mass").and_then(|n| cx.expr(n, "a mass"));
    let inertia = get(f, "inertia").and_then(|n| cx.expr(n, "an inertia"));
    let com = get(f, "com").and_then(|n| cx.name(n, "`com`"));
    let angle = get(f, "angle").and_then(|n| cx.expr(n, "a body angle"));
    let (Some(mass), Some(inertia), Some(com), Some(angle), true) = (
        mass,
        inertia,
        com,
        angle,
        complete && get(f, "at").is_none(),
    ) else {
        return None;
    };
    Some(Body {
        name: k.clone(),
        kind: BodyKind::Rigid {
            mass,
            inertia,
            com,
            angle,
        },
    })
}

/// A 3-D rigid body: `{ mass, com, frame, inertia }`.
fn read_spatial(cx: &mut Ctx<'_>, k: &Located<String>, f: &Entries) -> Option<Body> {
    let what = format!("body `{}`", k.value);
    let example = format!("{}: {SPATIAL_EXAMPLE}", k.value);
    for (key, planar) in [("angle", true), ("at", false)] {
        if let Some(at) = get_key(f, key) {
            let help = if planar {
                format!(
                    "the orientation of a 3-D body is its `frame`, whose rotations give its angular velocity; `angle` is for planar bodies: `{example}`"
                )
            } else {
                format!("a rigid body's position is its centre of mass `com`: `{example}`")
            };
            cx.error(
                Diagnostic::new(
                    at.location,
                    format!(
                        "{what} has a `frame`, so it is a 3-D rigid body, which has no `{key}`"
                    ),
                )
                .with_help(help),
            );
        }
    }
    let complete = cx.require(
        f,
        k.location,
        &format!("{what} (a 3-D rigid body, as it has `frame`)"),
        &["mass", "com", "frame", "inertia"],
        &example,
    );
    let mass = get(f, "mass").and_then(|n| cx.expr(n, "a mass"));
    let com = get(f, "com").and_then(|n| cx.name(n, "`com`"));
    let frame = get(f, "frame").and_then(|n| cx.name(n, "`frame`"));
    let inertia = get(f, "inertia").and_then(|n| read_inertia(cx, n));
    let (Some(mass), Some(com), Some(frame), Some(inertia), true) = (
        mass,
        com,
        frame,
        inertia,
        complete && get(f, "angle").is_none() && get(f, "at").is_none(),
    ) else {
        return None;
    };
    Some(Body {
        name: k.clone(),
        kind: BodyKind::Spatial {
            mass,
            com,
            frame,
            inertia: Box::new(inertia),
        },
    })
}

/// A 3-D inertia tensor: `[Ixx, Iyy, Izz]` (principal axes along the frame's) or
/// `{ xx, yy, zz, xy, yz, xz }` (the off-diagonal tensor entries optional, 0 if left out).
fn read_inertia(cx: &mut Ctx<'_>, node: &YamlNode) -> Option<InertiaTensor> {
    const HELP: &str = "the inertia of a 3-D body about its centre of mass, in its frame's axes, is `[Ixx, Iyy, Izz]` (principal axes) or `{ xx: Ixx, yy: Iyy, zz: Izz, xz: Ixz }` (off-diagonal tensor entries, −∫xz dm, 0 if left out)";
    let mut entries: [Option<Expr>; 6] = Default::default();
    match &node.kind {
        YamlKind::Seq(items) if items.len() == 3 => {
            for (slot, item) in entries.iter_mut().zip(items) {
                *slot = Some(cx.expr(item, "a moment of inertia")?);
            }
        }
        YamlKind::Map(map) => {
            cx.unknown_keys(
                map,
                "a 3-D inertia",
                &InertiaTensor::KEYS,
                &InertiaTensor::KEYS,
            );
            if !cx.require(
                map,
                node.location,
                "a 3-D inertia",
                &InertiaTensor::KEYS[..3],
                "inertia: { xx: Ixx, yy: Iyy, zz: Izz, xz: Ixz }",
            ) {
                return None;
            }
            for (slot, key) in entries.iter_mut().zip(InertiaTensor::KEYS) {
                if let Some(n) = get(map, key) {
                    *slot = Some(cx.expr(n, "an entry of an inertia tensor")?);
                }
            }
        }
        other => {
            cx.error(
                Diagnostic::new(
                    node.location,
                    format!(
                        "a 3-D body's inertia must be a list of three moments or a map of tensor entries, found {}",
                        other.describe()
                    ),
                )
                .with_help(HELP),
            );
            return None;
        }
    }
    Some(InertiaTensor {
        entries,
        location: node.location,
    })
}

/// `bodies:`: particles, planar rigid bodies and 3-D bodies.
pub(crate) fn write(w: &mut Writer<'_>, bodies: &[Body]) -> Result<(), NotRewritten> {
    if bodies.is_empty() {
        return Ok(());
    }
    w.line("bodies:");
    for b in bodies {
        let place = format!("body `{}`", b.name.value);
        let text = match &b.kind {
            BodyKind::Particle { mass, at } => {
                let m = w.expr(mass, &place)?;
                format!("{{ mass: {}, at: {} }}", flow(&m), at.value)
            }
            BodyKind::Rigid {
                mass,
                inertia,
                com,
                angle,
            } => {
                let m = w.expr(mass, &place)?;
                let i = w.expr(inertia, &place)?;
                let a = w.expr(angle, &place)?;
                format!(
                    "{{ mass: {}, inertia: {}, com: {}, angle: {} }}",
                    flow(&m),
                    flow(&i),
                    com.value,
                    flow(&a)
                )
            }
            BodyKind::Spatial {
                mass,
                com,
                frame,
                inertia,
            } => spatial_text(w, &place, (mass, &com.value, &frame.value, inertia))?,
        };
        w.line(format_args!("  {}: {text}", b.name.value));
    }
    Ok(())
}

/// A 3-D body: `{ mass: m, com: G, frame: B, inertia: … }`, the inertia as three moments
/// when its products are not written, else as the map of the entries written.
fn spatial_text(
    w: &mut Writer<'_>,
    place: &str,
    (mass, com, frame, inertia): (&Expr, &str, &str, &InertiaTensor),
) -> Result<String, NotRewritten> {
    let mass = w.expr(mass, place)?;
    let mut entries = Vec::new();
    for (key, entry) in InertiaTensor::KEYS.iter().zip(&inertia.entries) {
        if let Some(e) = entry {
            entries.push((*key, w.expr(e, place)?));
        }
    }
    let principal = inertia.entries[3..].iter().all(Option::is_none)
        && inertia.entries[..3].iter().all(Option::is_some);
    let inertia = if principal {
        let moments: Vec<String> = entries.into_iter().map(|(_, e)| e).collect();
        list(&moments)
    } else {
        let parts: Vec<String> = entries
            .into_iter()
            .map(|(k, e)| format!("{k}: {}", flow(&e)))
            .collect();
        format!("{{ {} }}", parts.join(", "))
    };
    Ok(format!(
        "{{ mass: {}, com: {com}, frame: {frame}, inertia: {inertia} }}",
        flow(&mass)
    ))
}
