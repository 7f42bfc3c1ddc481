//! The bundled models that declare `units: SI` pass the dimensional checks, and their units
//! are binding: changing any one declared unit (of a parameter or a coordinate) makes the
//! file fail, so the checks see every declaration and the passing files are not passing
//! because nothing is checked.

use std::path::PathBuf;

use eomgen_symbolic::model::{ModelFile, load};

/// Models whose units must be declared: they document the unit syntax.
const REQUIRED: &[&str] = &[
    "simple_pendulum",
    "double_pendulum",
    "three_masses",
    "forced_oscillator",
    "cart_pendulum",
    "two_masses",
    "turntable_slot_spring",
];

fn models() -> Vec<(String, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../models");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("models/ exists")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let source = std::fs::read_to_string(&p).expect("readable model");
            (p.display().to_string(), source)
        })
        .collect()
}

fn with_units() -> Vec<(String, String, ModelFile)> {
    models()
        .into_iter()
        .filter_map(|(path, source)| {
            let file = load(&path, &source).unwrap_or_else(|d| panic!("{path}: {d:?}"));
            file.units.is_some().then_some((path, source, file))
        })
        .collect()
}

#[test]
fn every_model_that_declares_units_passes_the_checks() {
    let checked = with_units();
    for name in REQUIRED {
        assert!(
            checked.iter().any(|(_, _, f)| f.name.value == *name),
            "`{name}` does not declare `units: SI`"
        );
    }
}

/// Replaces the unit text at (line, column) — up to the first `,` of the comment — by
/// `(unit)*m`, a different but well-formed unit.
fn change_unit(source: &str, line: u32, column: u32) -> String {
    let mut lines: Vec<String> = source.lines().map(str::to_string).collect();
    let text = &mut lines[line as usize - 1];
    let start: usize = text
        .char_indices()
        .nth(column as usize - 1)
        .map(|(i, _)| i)
        .expect("the unit is on its line");
    let rest = &text[start..];
    let unit = rest.split(',').next().unwrap_or_default().trim_end();
    let changed = format!("{}({unit})*m{}", &text[..start], &rest[unit.len()..]);
    *text = changed;
    lines.join("\n") + "\n"
}

#[test]
fn every_declared_unit_is_binding() {
    let mut unnoticed = Vec::new();
    let mut tried = 0;
    for (path, source, file) in with_units() {
        let mut places = Vec::new();
        for p in &file.parameters {
            let unit = p
                .unit
                .as_ref()
                .expect("a units file gives every parameter a unit");
            places.push((format!("parameter `{}`", p.name.value), unit.location));
        }
        for c in &file.coordinates {
            // A coordinate's unit is the start of its comment in these files.
            let line = source
                .lines()
                .nth(c.name.location.line as usize - 1)
                .unwrap();
            if let Some(hash) = line.find("# ") {
                let column = line[..hash + 2].chars().count() as u32 + 1;
                let location = eomgen_symbolic::model::Location {
                    line: c.name.location.line,
                    column,
                };
                places.push((format!("coordinate `{}`", c.name.value), location));
            }
        }
        for (what, at) in places {
            tried += 1;
            let changed = change_unit(&source, at.line, at.column);
            if load(&path, &changed).is_ok() {
                unnoticed.push(format!("{path}: {what}"));
            }
        }
    }
    assert!(tried > 100, "only {tried} units tried");
    assert!(
        unnoticed.is_empty(),
        "changing these units went unnoticed:\n{}",
        unnoticed.join("\n")
    );
}

/// Issue 28: one wrong unit gave one error per use of its parameter (six), the first at a
/// use, none at the declaration. A declared unit that the uses of its name contradict is
/// reported once, at the declaration, with the unit the uses need; a mistake elsewhere is
/// still reported on its own.
#[test]
fn issue_28_one_wrong_unit_is_one_error_at_its_declaration() {
    let src = "\
name: falling
units: SI
parameters:
  m: 1.0     # kg
  g: 9.81    # m/s
  h: 2.0     # m
coordinates:
  - y        # m
points: { P: [0, y] }
bodies: { ball: { mass: m, at: P } }
gravity: [0, -g]
initial: { y: h }
events:
  floor: y
checks:
  equations_of_motion:
    - m*y_ddot = -m*g
  conserved: { energy: m*y_dot^2/2 + m*g*y }
";
    let errors = load("falling.yaml", src).expect_err("refused");
    let shown: Vec<String> = errors
        .iter()
        .map(|d| format!("{}: {}", d.location, d.message))
        .collect();
    assert_eq!(errors.len(), 1, "{shown:#?}");
    assert_eq!(errors[0].location.to_string(), "5:16", "{shown:#?}");
    assert!(
        errors[0]
            .message
            .starts_with("parameter `g` is declared in m/s, but its uses need m/s^2"),
        "{shown:#?}"
    );
    assert!(
        errors[0]
            .help
            .as_deref()
            .is_some_and(|h| h.contains("declare `g` in m/s^2")),
        "{:?}",
        errors[0].help
    );

    // With a second, unrelated mistake (a mass in N), both are reported, each once.
    let two = src.replace("m: 1.0     # kg", "m: 1.0     # N");
    let errors = load("falling.yaml", &two).expect_err("refused");
    let shown: Vec<String> = errors
        .iter()
        .map(|d| format!("{}: {}", d.location, d.message))
        .collect();
    assert!(
        shown
            .iter()
            .any(|s| s.starts_with("5:16: parameter `g` is declared in m/s")),
        "{shown:#?}"
    );
    assert!(shown.len() <= 3, "{shown:#?}");
}
