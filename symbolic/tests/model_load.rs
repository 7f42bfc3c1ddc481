//! The model loader on valid files: contents, locations, units and comments; and never a
//! panic on any input.

use eomgen_symbolic::model::{BodyKind, Expr, ExprKind, Gap, Location, ModelFile, load};
use proptest::prelude::*;

const DOUBLE_PENDULUM: &str = include_str!("fixtures/double_pendulum.yaml");
const DAMPED_OSCILLATOR: &str = include_str!("fixtures/damped_oscillator.yaml");
const EVERY_SECTION: &str = include_str!("fixtures/every_section.yaml");

fn at(line: u32, column: u32) -> Location {
    Location { line, column }
}

fn loads(path: &str, source: &str) -> ModelFile {
    match load(path, source) {
        Ok(file) => file,
        Err(errors) => panic!(
            "{path} does not load:\n{}",
            errors
                .iter()
                .map(|d| d.render(path, source))
                .collect::<Vec<_>>()
                .join("\n")
        ),
    }
}

fn ident(e: &Expr) -> &str {
    match &e.kind {
        ExprKind::Ident(n) => n,
        other => panic!("expected a name, found {other:?}"),
    }
}

#[test]
fn the_double_pendulum_of_the_design_loads_with_contents_and_locations() {
    let file = loads("double_pendulum.yaml", DOUBLE_PENDULUM);
    assert_eq!(file.path, "double_pendulum.yaml");
    assert_eq!(file.name.value, "double_pendulum");
    assert_eq!(file.name.location, at(2, 7));
    assert_eq!(
        file.description,
        "Two uniform bars hinged at O and E (homework 19)."
    );

    let params: Vec<(&str, f64)> = file
        .parameters
        .iter()
        .map(|p| (p.name.value.as_str(), p.value))
        .collect();
    assert_eq!(
        params,
        [
            ("m1", 1.0),
            ("m2", 1.0),
            ("l1", 1.0),
            ("l2", 1.0),
            ("g", 10.0)
        ]
    );
    assert_eq!(file.parameters[0].name.location, at(4, 15));
    assert_eq!(file.parameters[0].default.location, at(4, 19));
    // Five parameters share the line: the comment is no one's unit.
    assert!(file.parameters.iter().all(|p| p.unit.is_none()));

    let coords: Vec<(&str, Location)> = file
        .coordinates
        .iter()
        .map(|c| (c.name.value.as_str(), c.name.location))
        .collect();
    assert_eq!(coords, [("theta1", at(5, 15)), ("theta2", at(5, 23))]);
    assert!(file.coordinates.iter().all(|c| c.comment.is_none()));

    let points: Vec<&str> = file.points.iter().map(|p| p.name.value.as_str()).collect();
    assert_eq!(points, ["O", "E", "G1", "G2", "H"]);
    assert_eq!(file.dimension, Some(2));
    let e = &file.points[1];
    assert_eq!(e.name.location, at(8, 3));
    assert_eq!(e.location, at(8, 7));
    assert_eq!(e.position[0].location, at(8, 8));
    assert_eq!(e.position[1].location, at(8, 24));

    assert_eq!(file.bodies.len(), 2);
    let BodyKind::Rigid {
        mass,
        inertia,
        com,
        angle,
    } = &file.bodies[0].kind
    else {
        panic!("`upper` is a rigid body")
    };
    assert_eq!(file.bodies[0].name.value, "upper");
    assert_eq!((ident(mass), mass.location), ("m1", at(13, 18)));
    assert_eq!(inertia.location, at(13, 31));
    assert_eq!((com.value.as_str(), com.location), ("G1", at(13, 48)));
    assert_eq!((ident(angle), angle.location), ("theta1", at(13, 59)));

    let gravity = file.gravity.as_ref().expect("gravity");
    assert_eq!(gravity.location, at(15, 10));
    assert_eq!(gravity.value[1].location, at(15, 14));
    assert!(matches!(gravity.value[1].kind, ExprKind::Neg(_)));

    let initial: Vec<&str> = file.initial.iter().map(|(k, _)| k.value.as_str()).collect();
    assert_eq!(initial, ["theta1", "theta2"]);
    assert_eq!(file.initial[1].1.location, at(16, 31));

    let lines: Vec<[&str; 2]> = file
        .draw
        .lines
        .iter()
        .map(|[a, b]| [a.value.as_str(), b.value.as_str()])
        .collect();
    assert_eq!(lines, [["O", "E"], ["E", "H"]]);
    assert!(file.draw.trace.is_empty());
    assert!(file.kinetic.is_none() && file.potential.is_none());
}

#[test]
fn an_energy_form_file_loads_with_units_and_comments() {
    let file = loads("damped_oscillator.yaml", DAMPED_OSCILLATOR);
    assert_eq!(file.name.value, "damped_oscillator");
    assert_eq!(
        file.description,
        "A cart of mass m on a spring k and a dashpot c, driven by F0 cos(w t)."
    );
    let units: Vec<(&str, Option<&str>)> = file
        .parameters
        .iter()
        .map(|p| {
            (
                p.name.value.as_str(),
                p.unit.as_ref().map(|u| u.value.as_str()),
            )
        })
        .collect();
    assert_eq!(
        units,
        [
            ("m", Some("kg")),
            ("k", Some("N/m")),
            ("c", Some("N s/m")),
            ("F0", Some("N")),
            ("w", Some("rad/s")),
            ("x0", Some("m")),
            ("phase", Some("rad"))
        ]
    );
    assert_eq!(file.parameters[5].value, 1e-2);
    assert!(matches!(
        &file.parameters[5].default.kind,
        ExprKind::Number { text, .. } if text == "1e-2"
    ));
    assert!((file.parameters[6].value - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
    assert_eq!(file.coordinates.len(), 1);
    assert_eq!(
        file.coordinates[0].comment.as_deref(),
        Some("m, extension of the spring")
    );
    assert_eq!(file.kinetic.as_ref().map(|k| k.location), Some(at(17, 10)));
    assert_eq!(
        file.potential.as_ref().map(|v| v.location),
        Some(at(18, 12))
    );
    assert_eq!(file.generalized_forces.len(), 1);
    assert_eq!(file.generalized_forces[0].0.value, "x");
    assert_eq!(file.generalized_forces[0].1.location, at(20, 6));
    assert_eq!(file.initial.len(), 2);
    assert!(file.points.is_empty() && file.bodies.is_empty());
    assert_eq!(file.dimension, None);
}

#[test]
fn every_supported_section_loads() {
    let file = loads("every_section.yaml", EVERY_SECTION);
    assert_eq!(file.bodies.len(), 2);
    assert!(matches!(file.bodies[1].kind, BodyKind::Particle { .. }));
    assert_eq!(file.springs.len(), 2);
    assert!(file.springs[0].rest_length.is_some());
    assert!(file.springs[1].rest_length.is_none());
    assert_eq!(file.dampers.len(), 1);
    assert_eq!(file.forces.len(), 1);
    assert_eq!(file.forces[0].vector.len(), 2);
    assert_eq!(file.torques.len(), 1);
    assert_eq!(file.torques[0].body.value, "crank");
    assert_eq!(file.draw.trace.len(), 1);
    let contacts: Vec<&str> = file
        .contacts
        .iter()
        .map(|c| c.name.value.as_str())
        .collect();
    assert_eq!(contacts, ["stop", "tip", "guard"]);
    assert!(matches!(file.contacts[0].gap, Gap::Written(_)));
    assert!(
        matches!(&file.contacts[1].gap, Gap::Above { point, through: Some(_), .. } if point.value == "A")
    );
    assert!(matches!(
        &file.contacts[2].gap,
        Gap::Circle { point, inside: true, .. } if point.value == "B"
    ));
    assert_eq!(file.contacts[1].restitution.location, at(37, 78));
    assert!(file.contacts[0].friction.is_none() && file.contacts[1].friction.is_some());
    assert_eq!(file.initial.len(), 3);
    assert!(file.potential.is_some());
    assert_eq!(
        file.description,
        "Crank OA driven by a motor; a bead B on a spring to A; a drag force on B."
    );
}

#[test]
fn windows_line_endings_give_the_same_model() {
    let crlf = DAMPED_OSCILLATOR.replace('\n', "\r\n");
    let unix = loads("damped_oscillator.yaml", DAMPED_OSCILLATOR);
    let windows = loads("damped_oscillator.yaml", &crlf);
    assert_eq!(unix, windows);
}

#[test]
fn expressions_may_span_lines_and_keep_exact_locations() {
    let src = "name: a\nparameters: { m: 1, k: 2 }\ncoordinates: [x]\nkinetic: >\n  m*x_dot^2/2\n  + 0*x\npotential: k*x^2/2\n  + k*x^4/24\n";
    let file = loads("a.yaml", src);
    assert_eq!(file.kinetic.as_ref().map(|e| e.location), Some(at(5, 3)));
    let errors = load("a.yaml", &src.replace("k*x^4/24", "k*y^4/24")).unwrap_err();
    assert_eq!(errors.len(), 1);
    assert_eq!(errors[0].location, at(8, 7));
    assert!(
        errors[0]
            .message
            .contains("unknown name `y` in `potential`")
    );
}

/// The project's own models load (they are embedded in the CLI; a failure here is either a
/// loader bug or a model that uses a feature this version does not have).
#[test]
fn the_project_models_load() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    let mut failures = Vec::new();
    for entry in entries.flatten() {
        let path = entry.path();
        if path.extension().is_none_or(|x| x != "yaml") {
            continue;
        }
        let Ok(source) = std::fs::read_to_string(&path) else {
            continue;
        };
        let name = path.display().to_string();
        if let Err(errors) = load(&name, &source) {
            for d in errors {
                failures.push(d.render(&name, &source));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, .. ProptestConfig::default() })]

    /// Arbitrary text never panics the loader.
    #[test]
    fn arbitrary_text_never_panics(src in "\\PC{0,300}") {
        let _ = load("fuzz.yaml", &src);
    }

    /// YAML-ish text never panics the loader, and every diagnostic points into the file.
    #[test]
    fn yaml_like_text_never_panics(src in "([a-z_]{1,6}: ?|  |- |\\[|\\]|\\{|\\}|, |\\(|\\)|[0-9.e]{1,4}|[-+*/^]|#[ a-z]*|'|\"|&a |\\*a|!!str |\n|\t|sin\\(|θ){0,60}") {
        if let Err(errors) = load("fuzz.yaml", &src) {
            let lines = src.split('\n').count() as u32;
            for d in &errors {
                prop_assert!(d.location.line >= 1 && d.location.line <= lines + 1, "{d:?}");
                prop_assert!(d.location.column >= 1, "{d:?}");
                let _ = d.render("fuzz.yaml", &src);
            }
        }
    }

    /// Random edits of valid files never panic the loader.
    #[test]
    fn edited_models_never_panic(
        which in 0usize..3,
        edits in prop::collection::vec(
            (0usize..4000, prop::sample::select(vec![
                "", "[", "]", "{", "}", ":", "-", "*", "^", "(", ")", ",", "x", "theta1", "0",
                "#", "\n", " ", "  ", "'", "\"", "&a ", "*a", "/0", "_dot", "_ddot", "-1",
            ])),
            1..6,
        ),
    ) {
        let mut src = [DOUBLE_PENDULUM, DAMPED_OSCILLATOR, EVERY_SECTION][which].to_string();
        for (pos, text) in edits {
            let mut p = pos % (src.len() + 1);
            while !src.is_char_boundary(p) {
                p -= 1;
            }
            src.insert_str(p, text);
        }
        let _ = load("fuzz.yaml", &src);
    }
}
