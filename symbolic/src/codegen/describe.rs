//! The description of a derived model ([`describe`]) and its printing as Rust
//! ([`description_source`]): the one place where a model's data — everything that is not a
//! function of the state — is gathered, for the macro (which prints it as a `static`) and for
//! the run-time compiler (which keeps the value) alike.

use std::borrow::Cow;
use std::fmt::Write as _;

use eomgen_description::{
    BodyCentre, EventDirection, EventSpec, ModelDescription, Parameter, Text,
};

use crate::mechanics::{EquationsOfMotion, SymbolicModel};
use crate::model::Crossing;

/// Everything about `model` that is not a function of the state, with `eom`'s equations as
/// text and LaTeX ([`super::equations_text`], [`super::equations_latex`]).
///
/// Names of points that a drawing or a body refers to are looked up in `model.points`; an
/// index out of range (which the model file's checks exclude) drops the entry rather than
/// panicking.
pub fn describe(model: &SymbolicModel, eom: &EquationsOfMotion) -> ModelDescription {
    let text = |s: &str| -> Text { Cow::Owned(s.to_string()) };
    let point_name = |i: usize| model.points.get(i).map(|(p, _)| text(p));
    let c = &model.constraints;
    ModelDescription {
        name: text(&model.name),
        summary: text(&model.description),
        coordinates: model.coordinate_names.iter().map(|c| text(c)).collect(),
        parameters: model
            .parameters
            .iter()
            .map(|p| Parameter {
                name: text(&p.name),
                default: p.default,
            })
            .collect(),
        points: model.points.iter().map(|(p, _)| text(p)).collect(),
        draw_lines: model
            .draw_lines
            .iter()
            .filter_map(|[a, b]| Some([point_name(*a)?, point_name(*b)?]))
            .collect(),
        trace_points: model
            .trace_points
            .iter()
            .filter_map(|p| point_name(*p))
            .collect(),
        body_centres: model
            .bodies
            .iter()
            .filter_map(|b| {
                Some(BodyCentre {
                    body: text(&b.name),
                    point: point_name(b.com)?,
                    rigid: b.rotation.is_some(),
                })
            })
            .collect(),
        constraints: c.names.iter().map(|n| text(n)).collect(),
        holonomic_constraints: c.holonomic,
        initial_guesses: Cow::Owned(model.initial_guesses.clone()),
        equilibria: model.equilibria.iter().map(|(n, _)| text(n)).collect(),
        events: model
            .events
            .iter()
            .map(|e| EventSpec {
                name: text(&e.name),
                direction: match e.direction {
                    Crossing::Rising => EventDirection::Rising,
                    Crossing::Falling => EventDirection::Falling,
                    Crossing::Both => EventDirection::Both,
                },
                terminal: e.terminal,
            })
            .collect(),
        events_need_accelerations: model.events_need_accelerations(),
        conservative: model.conservative,
        equations_text: Cow::Owned(super::equations_text(model, eom)),
        equations_latex: Cow::Owned(super::equations_latex(model, eom)),
    }
}

/// A Rust expression that builds `description` in a `static` (every string and list
/// borrowed from the binary), naming the types under `krate` (`::eomgen`).
pub fn description_source(description: &ModelDescription, krate: &str) -> String {
    let text = |s: &str| format!("::std::borrow::Cow::Borrowed({s:?})");
    let list =
        |items: Vec<String>| format!("::std::borrow::Cow::Borrowed(&[{}])", items.join(", "));
    let texts = |items: &[Text]| list(items.iter().map(|s| text(s)).collect());
    let d = description;
    let mut src = format!("{krate}::ModelDescription {{ ");
    let _ = write!(src, "name: {}, ", text(&d.name));
    let _ = write!(src, "summary: {}, ", text(&d.summary));
    let _ = write!(src, "coordinates: {}, ", texts(&d.coordinates));
    let parameters = d
        .parameters
        .iter()
        .map(|p| {
            format!(
                "{krate}::Parameter {{ name: {}, default: {:?}_f64 }}",
                text(&p.name),
                p.default
            )
        })
        .collect();
    let _ = write!(src, "parameters: {}, ", list(parameters));
    let _ = write!(src, "points: {}, ", texts(&d.points));
    let lines = d
        .draw_lines
        .iter()
        .map(|[a, b]| format!("[{}, {}]", text(a), text(b)))
        .collect();
    let _ = write!(src, "draw_lines: {}, ", list(lines));
    let _ = write!(src, "trace_points: {}, ", texts(&d.trace_points));
    let centres = d
        .body_centres
        .iter()
        .map(|b| {
            format!(
                "{krate}::BodyCentre {{ body: {}, point: {}, rigid: {} }}",
                text(&b.body),
                text(&b.point),
                b.rigid
            )
        })
        .collect();
    let _ = write!(src, "body_centres: {}, ", list(centres));
    let _ = write!(src, "constraints: {}, ", texts(&d.constraints));
    let _ = write!(src, "holonomic_constraints: {}, ", d.holonomic_constraints);
    let guesses = d
        .initial_guesses
        .iter()
        .map(|i| format!("{i}_usize"))
        .collect();
    let _ = write!(src, "initial_guesses: {}, ", list(guesses));
    let _ = write!(src, "equilibria: {}, ", texts(&d.equilibria));
    let events = d
        .events
        .iter()
        .map(|e| {
            let direction = match e.direction {
                EventDirection::Rising => "Rising",
                EventDirection::Falling => "Falling",
                EventDirection::Both => "Both",
            };
            format!(
                "{krate}::EventSpec {{ name: {}, direction: {krate}::EventDirection::{direction}, terminal: {} }}",
                text(&e.name),
                e.terminal
            )
        })
        .collect();
    let _ = write!(src, "events: {}, ", list(events));
    let _ = write!(
        src,
        "events_need_accelerations: {}, ",
        d.events_need_accelerations
    );
    let _ = write!(src, "conservative: {}, ", d.conservative);
    let _ = write!(src, "equations_text: {}, ", text(&d.equations_text));
    let _ = write!(src, "equations_latex: {} }}", text(&d.equations_latex));
    src
}
