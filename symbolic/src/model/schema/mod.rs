//! Located YAML tree → typed [`ModelFile`], reporting every unknown key, wrong type and
//! malformed expression at once.
//!
//! The pass never stops at the first problem: an entry that cannot be built is reported and
//! left out, and what was left out is recorded in [`Incomplete`] so that the cross-object
//! checks ([`super::rules`]) do not report its consequences a second time.
//!
//! One scaffold (`walk`) reads every keyed part of a file: `sections` holds the table of
//! top-level keys and the sections about the model as a whole, and each group of sections
//! has its file — points and balances (`mechanics`), initial state, events and equilibria
//! (`states`), `checks:` (`checks`) and `floquet:` (`floquet`); the model elements (frames,
//! bodies, energies, constraints, loads, contacts) read and write themselves in
//! `model/elements/`. How a single value is read (a name, an expression, a vector) is in `values`;
//! lookups in a map's entries in `entries`.
//!
//! The same table writes a [`ModelFile`] back as text ([`write_file`]): each section's
//! writer sits beside its reader, and `reduce` writes its results through it.

mod checks;
pub(crate) mod entries;
mod floquet;
mod mechanics;
mod sections;
mod states;
mod values;
pub(crate) mod walk;
pub mod write;

pub use sections::write_file;
pub(crate) use walk::Ctx;
pub use walk::Incomplete;

use std::collections::HashMap;

use super::ast::{BinOp, Expr, ExprKind};
use super::checks::*;
use super::diagnostic::{Diagnostic, Diagnostics};
use super::file::*;
use super::located::{Located, Location};
use super::parser::{closest, eval_expr, identifiers, parse_expr_mapped};
use super::yaml::{YamlKind, YamlNode, char_locations_in_lines, trailing_comment_of_line};
use entries::{Entries, get, misspelt};

/// Expressions by name, in file order.
type KeyedExprs = Vec<(Located<String>, Expr)>;

/// The most generalized coordinates a model may have (a located error at the `coordinates`
/// list beyond it). The mass matrix is derived, simplified and evaluated as a dense `n × n`
/// matrix, so that memory and time grow as `n²` and faster: measured in a release build, a
/// chain of N masses (`eomgen new n-mass-chain`, written by a script beyond 1000) took, in
/// CPU time and peak memory, for `eomgen check` 4.4 s and 97 MiB at N = 1000, 22 s and
/// 345 MiB at 2000; for `simulate --t-end 0.01` 1.9 s and 122 MiB at 1000, 8.2 s and
/// 423 MiB at 2000 (docs/performance.md has the rest). The limit is the largest of these
/// sizes that loads, checks and takes a first step within about 10 s and 2 GB, and the
/// template's largest; a 10,000-mass chain (1.4 MB, within
/// [`MAX_FILE_BYTES`](super::MAX_FILE_BYTES)) needed 5.8 GB.
pub const MAX_COORDINATES: usize = 1_000;

/// Top-level keys of a model file.
pub const TOP_LEVEL_KEYS: &[&str] = &[
    "name",
    "description",
    "units",
    "parameters",
    "coordinates",
    "speeds",
    "kinetic",
    "potential",
    "generalized_forces",
    "frames",
    "points",
    "bodies",
    "gravity",
    "springs",
    "dampers",
    "forces",
    "torques",
    "interactions",
    "outputs",
    "initial",
    "draw",
    "balances",
    "checks",
    "constraints",
    "nonholonomic",
    "contacts",
    "events",
    "equilibria",
    "floquet",
    "minimal_twin",
];

/// Keys of `checks:`.
pub const CHECK_KEYS: &[&str] = &[
    "equations_of_motion",
    "natural_frequencies",
    "damping_ratios",
    "period",
    "final_state",
    "conserved",
    "energy_drift",
    "constraint_drift",
];

/// What the schema pass built from a file, and what it had to leave out.
#[derive(Debug, Clone, PartialEq)]
pub struct Built {
    /// The typed model without the entries that had errors; `None` when the file is not a
    /// map of `key: value` at all.
    pub file: Option<ModelFile>,
    /// What was left out of `file` because of a reported error.
    pub incomplete: Incomplete,
    /// Every problem found, sorted by location.
    pub diagnostics: Vec<Diagnostic>,
}

/// Builds the typed model from the YAML tree of `path`.
///
/// # Errors
/// Every schema diagnostic of the file, sorted by location.
pub fn build(path: &str, source: &str, root: &YamlNode) -> Result<ModelFile, Vec<Diagnostic>> {
    let built = build_partial(path, source, root);
    match built.file {
        Some(file) if built.diagnostics.is_empty() => Ok(file),
        _ => Err(built.diagnostics),
    }
}

/// Builds as much of the typed model as the YAML tree allows, with every diagnostic and a
/// record of what was left out (see [`Built`]).
pub fn build_partial(path: &str, source: &str, root: &YamlNode) -> Built {
    let mut cx = Ctx::new(source);
    let file = cx.model(path, root);
    let diagnostics = cx.diagnostics.finish().err().unwrap_or_default();
    Built {
        file,
        incomplete: cx.incomplete,
        diagnostics,
    }
}

/// Where the text `comment` of the trailing comment of `line`, whose text is `text`, starts
/// (it ends the line).
fn comment_location(text: &str, line: u32, comment: &str) -> Location {
    let text = text.trim_end();
    let byte = text.len().saturating_sub(comment.len());
    let column = text.get(..byte).map_or(0, |p| p.chars().count());
    Location {
        line,
        column: column as u32 + 1,
    }
}

/// Whether `s` is a model-file name: a letter, then letters, digits and `_`.
pub fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    c.next().is_some_and(|f| f.is_ascii_alphabetic())
        && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

/// Rust's keywords, strict and reserved, of every edition up to 2024 (`gen`): generated code
/// spells a parameter or coordinate named so as a raw identifier (`r#type`).
pub const RUST_KEYWORDS: &[&str] = &[
    "as", "async", "await", "break", "const", "continue", "crate", "dyn", "else", "enum", "extern",
    "false", "fn", "for", "gen", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut",
    "pub", "ref", "return", "self", "Self", "static", "struct", "super", "trait", "true", "type",
    "unsafe", "use", "where", "while", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try",
];

/// The keywords that are not raw identifiers either (`r#self` is not Rust): no parameter or
/// coordinate can be named so, and no model whose struct ([`struct_name`]) would be `Self`.
pub const UNRAW_KEYWORDS: &[&str] = &["self", "Self", "super", "crate"];

/// The generated struct's name, the UpperCamelCase of the model's: `double_pendulum` →
/// `DoublePendulum`.
pub fn struct_name(model_name: &str) -> String {
    model_name
        .split('_')
        .filter(|p| !p.is_empty())
        .map(|p| {
            let mut c = p.chars();
            match c.next() {
                Some(f) => f.to_ascii_uppercase().to_string() + c.as_str(),
                None => String::new(),
            }
        })
        .collect()
}

/// Whether `s` is a snake_case identifier: a lowercase letter, then lowercase letters,
/// digits and `_`.
pub fn is_snake_case(s: &str) -> bool {
    let mut c = s.chars();
    c.next().is_some_and(|f| f.is_ascii_lowercase())
        && c.all(|x| x.is_ascii_lowercase() || x.is_ascii_digit() || x == '_')
}

/// A snake_case spelling of `s` for suggestions (`DoublePendulum` → `double_pendulum`).
fn to_snake_case(s: &str) -> String {
    let mut out = String::new();
    let mut previous_lower = false;
    for c in s.chars() {
        if c.is_ascii_uppercase() {
            if previous_lower {
                out.push('_');
            }
            out.push(c.to_ascii_lowercase());
            previous_lower = false;
        } else if c.is_ascii_alphanumeric() {
            out.push(c);
            previous_lower = true;
        } else {
            out.push('_');
            previous_lower = false;
        }
    }
    let mut collapsed = String::new();
    for c in out.chars() {
        if !(c == '_' && collapsed.ends_with('_')) {
            collapsed.push(c);
        }
    }
    let trimmed = collapsed.trim_matches('_');
    if trimmed.starts_with(|c: char| c.is_ascii_lowercase()) {
        trimmed.to_string()
    } else {
        format!("model_{trimmed}").trim_end_matches('_').to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::yaml;

    fn built(src: &str) -> Built {
        let root = yaml::parse(src).unwrap();
        build_partial("t.yaml", src, &root)
    }

    fn messages(src: &str) -> Vec<String> {
        built(src)
            .diagnostics
            .iter()
            .map(|d| format!("{}: {}", d.location, d.message))
            .collect()
    }

    #[test]
    fn snake_case_names() {
        assert!(is_snake_case("double_pendulum2"));
        assert!(!is_snake_case("DoublePendulum"));
        assert_eq!(to_snake_case("DoublePendulum"), "double_pendulum");
        assert_eq!(to_snake_case("my-model"), "my_model");
        assert_eq!(to_snake_case("2d"), "model_2d");
        let m = messages("name: DoublePendulum\ncoordinates: [q]\n");
        assert_eq!(
            m,
            ["1:7: `name` must be snake_case, found `DoublePendulum`"]
        );
    }

    #[test]
    fn parameter_units_and_constant_defaults() {
        let src = "name: a\ncoordinates: [q]\nparameters:\n  m: 2.0  # kg\n  l: pi/4\n  k: 2*m\n";
        let b = built(src);
        let file = b.file.unwrap();
        assert_eq!(file.parameters.len(), 2);
        let unit = file.parameters[0].unit.as_ref().unwrap();
        assert_eq!(unit.value, "kg");
        assert_eq!(
            unit.location,
            Location {
                line: 4,
                column: 13
            }
        );
        assert_eq!(file.parameters[1].unit, None);
        assert!((file.parameters[1].value - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
        assert_eq!(b.diagnostics.len(), 1);
        assert_eq!(b.diagnostics[0].location, Location { line: 6, column: 8 });
        assert!(
            b.diagnostics[0]
                .message
                .contains("parameter defaults must be constant")
        );
        assert_eq!(b.incomplete.names, ["k"]);
        // Several parameters on one line: no unit.
        let src = "name: a\ncoordinates: [q]\nparameters: { m: 1, g: 9.81 }  # SI\n";
        let file = built(src).file.unwrap();
        assert!(file.parameters.iter().all(|p| p.unit.is_none()));
    }

    #[test]
    fn coordinate_comments() {
        let src = "name: a\ncoordinates:\n  - x   # m, cart\n  - y\n";
        let file = built(src).file.unwrap();
        assert_eq!(file.coordinates[0].comment.as_deref(), Some("m, cart"));
        assert_eq!(file.coordinates[1].comment, None);
        let src = "name: a\ncoordinates: [x, y]  # both\n";
        let file = built(src).file.unwrap();
        assert!(file.coordinates.iter().all(|c| c.comment.is_none()));
    }

    #[test]
    fn later_keys_and_unknown_keys() {
        // `outputs:`, once a key for later, is read now.
        let m = messages("name: a\ncoordinates: [q]\noutputs: { p: q_dot }\nkinetc: q_dot^2\n");
        assert_eq!(m, ["4:1: unknown key `kinetc` in a model file"]);
        let b = built("name: a\ncoordinates: [q]\nkinetc: q_dot^2\n");
        assert!(
            b.diagnostics[0]
                .help
                .as_deref()
                .unwrap()
                .starts_with("did you mean `kinetic`?")
        );
    }

    #[test]
    fn reference_checks_with_their_defaults() {
        let src = "name: a\nparameters: { k: 1.0 }\ncoordinates: [q]\nkinetic: q_dot^2/2\npotential: k*q^2/2\nchecks:\n  natural_frequencies: { at: rest, values: [sqrt(k)] }\n  damping_ratios: { values: [0], tolerance: 1e-6 }\n  period: { event: peak, value: 2*pi, method: rk4, rtol: 1e-9, t_end: 20 }\n  final_state: { t: pi, values: { q: -1, q_dot: 0 } }\n  conserved: { p: q_dot, e: { value: q_dot^2 + k*q^2, tolerance: 1e-8 } }\n  energy_drift: {}\n  constraint_drift: { max: 1e-6 }\n";
        let built = built(src);
        assert!(built.diagnostics.is_empty(), "{:?}", built.diagnostics);
        let c = built.file.unwrap().checks;
        let w = c.natural_frequencies.unwrap();
        assert_eq!(w.at.unwrap().value, "rest");
        assert_eq!((w.values.len(), w.tolerance), (1, DEFAULT_CHECK_TOLERANCE));
        let z = c.damping_ratios.unwrap();
        assert!(z.at.is_none());
        assert_eq!(z.tolerance, 1e-6);
        let p = c.period.unwrap();
        assert_eq!(p.event.value, "peak");
        assert_eq!(p.run.method.unwrap().value, "rk4");
        assert_eq!((p.run.rtol, p.run.t_end), (Some(1e-9), Some(20.0)));
        let f = c.final_state.unwrap();
        let names: Vec<&str> = f.values.iter().map(|(k, _)| k.value.as_str()).collect();
        assert_eq!(names, ["q", "q_dot"]);
        assert_eq!(f.run, RunSettings::default());
        let tolerances: Vec<(&str, f64)> = c
            .conserved
            .iter()
            .map(|q| (q.name.value.as_str(), q.tolerance))
            .collect();
        assert_eq!(tolerances, [("p", DEFAULT_CHECK_TOLERANCE), ("e", 1e-8)]);
        assert_eq!(c.energy_drift.unwrap().max, DEFAULT_ENERGY_DRIFT);
        assert_eq!(c.constraint_drift.unwrap().max, 1e-6);
    }

    #[test]
    fn events_short_and_full_forms() {
        let src = "name: a\ncoordinates: [q]\nkinetic: q_dot^2/2\nevents:\n  cross: q\n  peak: { when: q_dot, direction: falling, terminal: true }\n";
        let file = built(src).file.unwrap();
        assert_eq!(file.events.len(), 2);
        assert_eq!(file.events[0].name.value, "cross");
        assert_eq!(
            (file.events[0].direction, file.events[0].terminal),
            (Crossing::Both, false)
        );
        assert_eq!(
            (file.events[1].direction, file.events[1].terminal),
            (Crossing::Falling, true)
        );
        let m = messages(
            "name: a\ncoordinates: [q]\nkinetic: q_dot^2/2\nevents:\n  peak: { when: q_dot, terminal: yes, directon: up }\n  bare: { direction: rising }\n",
        );
        assert_eq!(
            m,
            [
                "5:34: `terminal` of event `peak` must be one of true, false, found `yes`",
                "5:39: unknown key `directon` in event `peak`",
                "6:3: event `bare` has no `when`"
            ]
        );
    }

    /// `when: lhs = rhs` means `lhs − rhs = 0`, as `--stop-when "lhs = rhs"` does; a second
    /// `=` is an error at its column.
    #[test]
    fn an_event_may_be_written_as_an_equation() {
        let src = "name: a\ncoordinates: [y]\nkinetic: y_dot^2/2\nevents:\n  ground: { when: y = 0.5, terminal: true }\n  level: y_dot = -1\n";
        let file = built(src).file.unwrap();
        let at = |y: f64, y_dot: f64| {
            move |name: &str| match name {
                "y" => Some(y),
                "y_dot" => Some(y_dot),
                _ => None,
            }
        };
        let ground = &file.events[0].when;
        assert_eq!(eval_expr(ground, &at(2.0, 0.0)).unwrap(), 1.5);
        assert_eq!(eval_expr(ground, &at(0.5, 0.0)).unwrap(), 0.0);
        assert_eq!(eval_expr(&file.events[1].when, &at(0.0, 3.0)).unwrap(), 4.0);
        assert_eq!(
            ground.location,
            Location {
                line: 5,
                column: 19
            }
        );
        let m =
            messages("name: a\ncoordinates: [y]\nkinetic: y_dot^2/2\nevents:\n  e: y = 1 = 2\n");
        assert_eq!(
            m,
            ["5:12: the function of event `e` has one `=`, this is a second"]
        );
    }

    #[test]
    fn expressions_across_lines_keep_exact_locations() {
        let src = "name: a\ncoordinates: [q]\nkinetic: q_dot^2/2\n  + 3*\n";
        let m = messages(src);
        assert_eq!(
            m,
            ["4:7: expected an operand after `*`, found the end of the expression"]
        );
        let src = "name: a\ncoordinates: [q]\npotential: >\n  q^2/2\n  + )\n";
        let m = messages(src);
        assert_eq!(m, ["5:5: expected an operand after `+`, found `)`"]);
        let src = "name: a\ncoordinates: [q]\npotential: \"q^2 + $\"\n";
        assert_eq!(
            messages(src),
            ["3:19: unexpected character `$` in an expression"]
        );
    }

    #[test]
    fn a_comma_inside_a_flow_list_is_explained() {
        let src = "name: a\ncoordinates: [q]\npoints: { P: [atan2(q, 1), 0] }\n";
        let b = built(src);
        assert_eq!(b.diagnostics.len(), 1);
        assert!(
            b.diagnostics[0]
                .message
                .contains("`atan2(q` is cut at a `,`")
        );
        let src = "name: a\ncoordinates: [q]\npoints: { P: [\"atan2(q, 1)\", 0] }\n";
        assert!(built(src).diagnostics.is_empty());
    }

    #[test]
    fn a_comma_inside_a_flow_map_is_explained() {
        let src = "name: a\ncoordinates: [q]\npoints: { P: [q, 0] }\nbodies: { b: { mass: 1, inertia: 1, com: P, angle: atan2(q, 1) } }\n";
        let b = built(src);
        let d = b
            .diagnostics
            .iter()
            .find(|d| d.message.contains("unclosed"))
            .unwrap();
        assert!(
            d.help
                .as_deref()
                .unwrap()
                .contains("YAML splits values at every `,`")
        );
        // An unclosed parenthesis that YAML did not cut gets no such advice.
        let src = "name: a\ncoordinates: [q]\npotential: (q + 1\n";
        let b = built(src);
        assert_eq!(b.diagnostics.len(), 1);
        assert_eq!(
            b.diagnostics[0].help.as_deref(),
            Some("add the missing `)`")
        );
        let src = "name: a\ncoordinates: [q]\npoints: { P: [l*(q + 1, 0] }\n";
        let b = built(src);
        assert_eq!(b.diagnostics.len(), 1);
        assert!(b.diagnostics[0].message.contains("unclosed"));
    }

    #[test]
    fn bodies_particles_and_rigid() {
        let src = "name: a\ncoordinates: [q]\nbodies:\n  b: { inertia: 1, com: G, angle: q }\n  c: { mass: 1, at: P, angle: q }\n  d: { mas: 1, at: P }\n";
        let m = messages(src);
        assert_eq!(
            m,
            [
                "4:3: body `b` (a planar rigid body, as it has `inertia`) has no `mass`",
                "5:3: body `c` (a planar rigid body, as it has `angle`) has no `inertia`",
                "5:3: body `c` (a planar rigid body, as it has `angle`) has no `com`",
                "5:17: body `c` has `angle`, so it is a planar rigid body, which has no `at`",
                "6:8: unknown key `mas` in body `d`",
            ]
        );
        assert_eq!(built(src).incomplete.names, ["b", "c", "d"]);
    }
}
