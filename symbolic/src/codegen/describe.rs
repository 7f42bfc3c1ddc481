//! The description of a derived model ([`describe`]) and its printing as Rust
//! ([`description_tokens`]): the one place where a model's data — everything that is not a
//! function of the state — is gathered, for the macro (which prints it as a `static`) and for
//! the run-time compiler (which keeps the value) alike.

use std::borrow::Cow;

use proc_macro2::TokenStream;
use quote::quote;

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
///
/// # Errors
/// A parameter default that is not finite, which has no literal (the loader refuses such
/// values, so this is a bug).
pub fn description_tokens(
    description: &ModelDescription,
    krate: &TokenStream,
) -> Result<TokenStream, String> {
    let borrowed = |items: Vec<TokenStream>| quote!(::std::borrow::Cow::Borrowed(&[#(#items),*]));
    let text = |s: &str| quote!(::std::borrow::Cow::Borrowed(#s));
    let texts = |items: &[Text]| borrowed(items.iter().map(|s| text(s)).collect());
    let d = description;
    let name = text(&d.name);
    let summary = text(&d.summary);
    let coordinates = texts(&d.coordinates);
    let parameters = d
        .parameters
        .iter()
        .map(|p| {
            let name = text(&p.name);
            let default = super::float(p.default)?;
            Ok(quote!(#krate::Parameter { name: #name, default: #default }))
        })
        .collect::<Result<_, String>>()?;
    let parameters = borrowed(parameters);
    let points = texts(&d.points);
    let draw_lines = borrowed(
        d.draw_lines
            .iter()
            .map(|[a, b]| {
                let (a, b) = (text(a), text(b));
                quote!([#a, #b])
            })
            .collect(),
    );
    let trace_points = texts(&d.trace_points);
    let body_centres = borrowed(
        d.body_centres
            .iter()
            .map(|c| {
                let (body, point, rigid) = (text(&c.body), text(&c.point), c.rigid);
                quote!(#krate::BodyCentre { body: #body, point: #point, rigid: #rigid })
            })
            .collect(),
    );
    let constraints = texts(&d.constraints);
    let holonomic = super::index(d.holonomic_constraints);
    let guesses: Vec<TokenStream> = d
        .initial_guesses
        .iter()
        .map(|i| super::tokens(&format!("{i}_usize")))
        .collect::<Result<_, String>>()?;
    let initial_guesses = borrowed(guesses);
    let equilibria = texts(&d.equilibria);
    let events = borrowed(
        d.events
            .iter()
            .map(|e| {
                let direction = match e.direction {
                    EventDirection::Rising => quote!(Rising),
                    EventDirection::Falling => quote!(Falling),
                    EventDirection::Both => quote!(Both),
                };
                let (name, terminal) = (text(&e.name), e.terminal);
                quote!(#krate::EventSpec {
                    name: #name,
                    direction: #krate::EventDirection::#direction,
                    terminal: #terminal,
                })
            })
            .collect(),
    );
    let (needs, conservative) = (d.events_need_accelerations, d.conservative);
    let equations_text = text(&d.equations_text);
    let equations_latex = text(&d.equations_latex);
    Ok(quote! {
        #krate::ModelDescription {
            name: #name,
            summary: #summary,
            coordinates: #coordinates,
            parameters: #parameters,
            points: #points,
            draw_lines: #draw_lines,
            trace_points: #trace_points,
            body_centres: #body_centres,
            constraints: #constraints,
            holonomic_constraints: #holonomic,
            initial_guesses: #initial_guesses,
            equilibria: #equilibria,
            events: #events,
            events_need_accelerations: #needs,
            conservative: #conservative,
            equations_text: #equations_text,
            equations_latex: #equations_latex,
        }
    })
}
