//! The description of a derived model ([`describe`]) and its printing as Rust
//! ([`description_tokens`]): the one place where a model's data — everything that is not a
//! function of the state — is gathered, for the macro (which prints it as a `static`) and for
//! the run-time compiler (which keeps the value) alike.

use std::borrow::Cow;

use proc_macro2::TokenStream;
use quote::quote;

use eomgen_description::checks::{Checks, DriftCheck, ModalCheck, RunSettings};
use eomgen_description::floquet::FloquetReference;
use eomgen_description::{
    BodyCentre, EventDirection, EventSpec, FrameSpec, List, ModelDescription, Parameter,
    RotationSpec, Shape, Text,
};

use crate::mechanics::{EquationsOfMotion, SymbolicModel};
use crate::model::Crossing;

/// Everything about `model` that is not a function of the state, with `eom`'s equations as
/// text and LaTeX ([`super::equations_text`], [`super::equations_latex`]), as MathML
/// ([`super::equations_mathml`]) if `mathml`, and the file's `checks:` and `floquet:`
/// references.
///
/// Names of points that a drawing or a body refers to are looked up in `model.points`; an
/// index out of range (which the model file's checks exclude) drops the entry rather than
/// panicking.
pub fn describe(model: &SymbolicModel, eom: &EquationsOfMotion, mathml: bool) -> ModelDescription {
    let text = |s: &str| -> Text { Cow::Owned(s.to_string()) };
    let point_name = |i: usize| model.points.get(i).map(|(p, _)| text(p));
    let c = &model.constraints;
    let printer = crate::expr::print::Printer::new(&model.arena, crate::expr::print::Syntax::Text);
    let expression = |e: crate::expr::ExprId| -> Text { Cow::Owned(printer.print(e)) };
    ModelDescription {
        name: text(&model.name),
        summary: text(&model.description),
        coordinates: model.coordinate_names.iter().map(|c| text(c)).collect(),
        speeds: (model.speeds.iter())
            .flat_map(|s| s.names.iter().map(|u| text(u)))
            .collect(),
        speeds_depend_on_time: model.speeds_depend_on_time(),
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
                    rigid: b.rotation.is_some() || b.spatial.is_some(),
                    mass: expression(b.mass),
                    inertia: match (&b.rotation, &b.spatial) {
                        (_, Some(spatial)) => spatial.inertia.map(expression).to_vec().into(),
                        (Some((inertia, _)), None) => vec![expression(*inertia)].into(),
                        (None, None) => Cow::Borrowed(&[]),
                    },
                    frame: (b.spatial.as_ref())
                        .and_then(|s| model.frames.names().get(s.frame))
                        .map_or(Cow::Borrowed(""), |f| text(f)),
                    shape: (model.shapes.iter())
                        .find(|(body, _)| *body == b.name)
                        .map(|(_, shape)| shape.clone()),
                })
            })
            .collect(),
        constraints: c.names.iter().map(|n| text(n)).collect(),
        holonomic_constraints: c.holonomic,
        initial_guesses: Cow::Owned(model.initial_guesses.clone()),
        equilibria: model.equilibria.iter().map(|e| text(&e.name)).collect(),
        equilibrium_rates: model.has_steady_motions(),
        ignorable_coordinates: model
            .equilibria
            .iter()
            .enumerate()
            .flat_map(|(k, e)| e.ignorable.iter().map(move |&c| [k, c]))
            .collect(),
        held_coordinates: (model.equilibria.iter().enumerate())
            .flat_map(|(k, e)| e.held.iter().map(move |&c| [k, c]))
            .collect(),
        solved_rates: (model.equilibria.iter().enumerate())
            .flat_map(|(k, e)| e.solved.iter().map(move |&c| [k, c]))
            .collect(),
        turning_frames: (model.equilibria.iter().enumerate())
            .filter_map(|(k, e)| e.turning.map(|[a, x, y]| [k, a, x, y]))
            .collect(),
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
        contacts: model.contacts.iter().map(|c| text(&c.name)).collect(),
        supports: (model.contacts.iter())
            .filter(|c| c.support.is_some())
            .map(|c| text(&c.name))
            .collect(),
        events_need_accelerations: model.events_need_accelerations(),
        conservative: model.conservative,
        derivation: text(crate::mechanics::preferred_formulation(model).name()),
        equations_text: Cow::Owned(super::listing::equations_text(model, eom)),
        equations_latex: Cow::Owned(super::listing::equations_latex(model, eom)),
        equations_mathml: mathml.then(|| {
            super::listing::equations_mathml(model, eom)
                .into_iter()
                .map(Cow::Owned)
                .collect()
        }),
        checks: model.checks.clone(),
        floquet: Cow::Owned(model.floquet.clone()),
        outputs: Cow::Owned(model.outputs.clone()),
        frames: drawn_frames(model, &printer),
    }
}

/// The frames of the 3-D bodies and their ancestors, parents first (the ground left out),
/// their rotations' axes and angles printed in the file's syntax
/// ([`ModelDescription::frames`]).
fn drawn_frames(
    model: &SymbolicModel,
    printer: &crate::expr::print::Printer<'_>,
) -> List<FrameSpec> {
    use crate::mechanics::frames::RotationAxis;
    let frames = &model.frames;
    let mut used = vec![false; frames.names().len()];
    for b in &model.bodies {
        let mut f = match &b.spatial {
            Some(s) => s.frame,
            None => continue,
        };
        while f != 0 && !used[f] {
            used[f] = true;
            f = frames.parent(f);
        }
    }
    let print = |e: crate::expr::ExprId| -> Text { Cow::Owned(printer.print(e)) };
    let unit = |i: usize| -> [Text; 3] {
        [0, 1, 2].map(|k| Cow::Borrowed(if k == i { "1" } else { "0" }))
    };
    (1..frames.names().len())
        .filter(|&f| used[f])
        .map(|f| FrameSpec {
            name: Cow::Owned(frames.names()[f].clone()),
            parent: Cow::Owned(frames.names()[frames.parent(f)].clone()),
            rotations: (frames.rotations(f).iter())
                .map(|&(axis, angle)| {
                    let (axis, quaternion) = match axis {
                        RotationAxis::Principal(i) => (unit(i), false),
                        RotationAxis::Unit(k) => (k.map(print), false),
                        RotationAxis::Quaternion(e) => (e.map(print), true),
                    };
                    RotationSpec {
                        axis,
                        angle: print(angle),
                        quaternion,
                    }
                })
                .collect(),
        })
        .collect()
}

/// A Rust expression that builds `description` in a `static` (every string and list
/// borrowed from the binary), naming the types under `krate` (`::eomgen`).
///
/// # Errors
/// A parameter default that is not finite, which has no literal (the loader refuses such
/// values, so this is a bug).
// Long: one `quote!` of the whole `ModelDescription` literal, field by field in its order; split,
// the fields would be far from the struct they fill.
pub fn description_tokens(
    description: &ModelDescription,
    krate: &TokenStream,
) -> Result<TokenStream, String> {
    let texts = |items: &[Text]| borrowed(items.iter().map(|s| text(s)).collect());
    let d = description;
    let name = text(&d.name);
    let summary = text(&d.summary);
    let coordinates = texts(&d.coordinates);
    let speeds = texts(&d.speeds);
    let speeds_depend_on_time = d.speeds_depend_on_time;
    let parameters = d
        .parameters
        .iter()
        .map(|p| {
            let name = text(&p.name);
            let default = super::rust_tokens::float(p.default)?;
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
                let mass = text(&c.mass);
                let inertia = texts(&c.inertia);
                let frame = text(&c.frame);
                let shape = optional(c.shape.as_ref().map(|s| shape_tokens(s, krate)));
                quote!(#krate::BodyCentre {
                    body: #body,
                    point: #point,
                    rigid: #rigid,
                    mass: #mass,
                    inertia: #inertia,
                    frame: #frame,
                    shape: #shape,
                })
            })
            .collect(),
    );
    let constraints = texts(&d.constraints);
    let holonomic = super::rust_tokens::index(d.holonomic_constraints);
    let guesses: Vec<TokenStream> = d
        .initial_guesses
        .iter()
        .map(|i| super::rust_tokens::tokens(&format!("{i}_usize")))
        .collect::<Result<_, String>>()?;
    let initial_guesses = borrowed(guesses);
    let equilibria = texts(&d.equilibria);
    let equilibrium_rates = d.equilibrium_rates;
    let ignorable: Vec<TokenStream> = d
        .ignorable_coordinates
        .iter()
        .map(|[k, c]| super::rust_tokens::tokens(&format!("[{k}_usize, {c}_usize]")))
        .collect::<Result<_, String>>()?;
    let ignorable_coordinates = borrowed(ignorable);
    let index_rows = |rows: Vec<String>| -> Result<TokenStream, String> {
        let rows: Vec<TokenStream> = (rows.iter())
            .map(|r| super::rust_tokens::tokens(r))
            .collect::<Result<_, String>>()?;
        Ok(borrowed(rows))
    };
    let pair = |[k, c]: &[usize; 2]| format!("[{k}_usize, {c}_usize]");
    let held_coordinates = index_rows(d.held_coordinates.iter().map(pair).collect())?;
    let solved_rates = index_rows(d.solved_rates.iter().map(pair).collect())?;
    let turning_frames = index_rows(
        (d.turning_frames.iter())
            .map(|[k, a, x, y]| format!("[{k}_usize, {a}_usize, {x}_usize, {y}_usize]"))
            .collect(),
    )?;
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
    let contacts = texts(&d.contacts);
    let supports = texts(&d.supports);
    let (needs, conservative) = (d.events_need_accelerations, d.conservative);
    let derivation = text(&d.derivation);
    let equations_text = text(&d.equations_text);
    let equations_latex = text(&d.equations_latex);
    let equations_mathml = optional(d.equations_mathml.as_deref().map(texts));
    let checks = checks_tokens(&d.checks, krate)?;
    let floquet = borrowed(
        d.floquet
            .iter()
            .map(|r| floquet_tokens(r, krate))
            .collect::<Result<_, String>>()?,
    );
    let outputs = borrowed(
        d.outputs
            .iter()
            .map(|o| output_tokens(o, krate))
            .collect::<Result<_, String>>()?,
    );
    let frames = borrowed(d.frames.iter().map(|f| frame_tokens(f, krate)).collect());
    Ok(quote! {
        #krate::ModelDescription {
            name: #name,
            summary: #summary,
            coordinates: #coordinates,
            speeds: #speeds,
            speeds_depend_on_time: #speeds_depend_on_time,
            parameters: #parameters,
            points: #points,
            draw_lines: #draw_lines,
            trace_points: #trace_points,
            body_centres: #body_centres,
            constraints: #constraints,
            holonomic_constraints: #holonomic,
            initial_guesses: #initial_guesses,
            equilibria: #equilibria,
            equilibrium_rates: #equilibrium_rates,
            ignorable_coordinates: #ignorable_coordinates,
            held_coordinates: #held_coordinates,
            solved_rates: #solved_rates,
            turning_frames: #turning_frames,
            events: #events,
            contacts: #contacts,
            supports: #supports,
            events_need_accelerations: #needs,
            conservative: #conservative,
            derivation: #derivation,
            equations_text: #equations_text,
            equations_latex: #equations_latex,
            equations_mathml: #equations_mathml,
            checks: #checks,
            floquet: #floquet,
            outputs: #outputs,
            frames: #frames,
        }
    })
}

/// One of [`ModelDescription::frames`] as a Rust expression for a `static`.
fn frame_tokens(f: &FrameSpec, krate: &TokenStream) -> TokenStream {
    let (name, parent) = (text(&f.name), text(&f.parent));
    let rotations = borrowed(
        (f.rotations.iter())
            .map(|r| {
                let axis = r.axis.iter().map(|a| text(a));
                let (angle, quaternion) = (text(&r.angle), r.quaternion);
                quote!(#krate::RotationSpec { axis: [#(#axis),*], angle: #angle, quaternion: #quaternion })
            })
            .collect(),
    );
    quote!(#krate::FrameSpec { name: #name, parent: #parent, rotations: #rotations })
}

/// A body's [`Shape`] as a Rust expression for a `static`.
fn shape_tokens(s: &Shape, krate: &TokenStream) -> TokenStream {
    match s {
        Shape::Box { sides } => {
            let sides = sides.iter().map(|a| text(a));
            quote!(#krate::Shape::Box { sides: [#(#sides),*] })
        }
        Shape::Cylinder {
            radius,
            length,
            axis,
        } => {
            let (radius, length) = (text(radius), text(length));
            quote!(#krate::Shape::Cylinder { radius: #radius, length: #length, axis: #axis })
        }
        Shape::Disc { radius, axis } => {
            let radius = text(radius);
            quote!(#krate::Shape::Disc { radius: #radius, axis: #axis })
        }
        Shape::Sphere { radius } => {
            let radius = text(radius);
            quote!(#krate::Shape::Sphere { radius: #radius })
        }
    }
}

/// A string in a `static`.
fn text(s: &str) -> TokenStream {
    quote!(::std::borrow::Cow::Borrowed(#s))
}

/// A list in a `static`.
fn borrowed(items: Vec<TokenStream>) -> TokenStream {
    quote!(::std::borrow::Cow::Borrowed(&[#(#items),*]))
}

/// `Some(tokens)` or `None`.
fn optional(value: Option<TokenStream>) -> TokenStream {
    match value {
        Some(v) => quote!(::core::option::Option::Some(#v)),
        None => quote!(::core::option::Option::None),
    }
}

/// A float literal, or the error of a non-finite one.
fn float(v: f64) -> Result<TokenStream, String> {
    super::rust_tokens::float(v)
}

/// An optional float literal.
fn optional_float(v: Option<f64>) -> Result<TokenStream, String> {
    Ok(optional(v.map(float).transpose()?))
}

/// The file's `checks:` as a Rust expression for a `static`.
fn checks_tokens(c: &Checks, krate: &TokenStream) -> Result<TokenStream, String> {
    let m = quote!(#krate::description::checks);
    let run = |r: &RunSettings| -> Result<TokenStream, String> {
        let method = optional(r.method.as_deref().map(text));
        let (rtol, t_end) = (optional_float(r.rtol)?, optional_float(r.t_end)?);
        Ok(quote!(#m::RunSettings { method: #method, rtol: #rtol, t_end: #t_end }))
    };
    let modal = |c: &Option<ModalCheck>| -> Result<TokenStream, String> {
        c.as_ref()
            .map(|c| {
                let at = optional(c.at.as_deref().map(text));
                let values = borrowed(c.values.iter().map(|v| text(v)).collect());
                let tolerance = float(c.tolerance)?;
                Ok(quote!(#m::ModalCheck { at: #at, values: #values, tolerance: #tolerance }))
            })
            .transpose()
            .map(optional)
    };
    let drift = |c: &Option<DriftCheck>| -> Result<TokenStream, String> {
        c.as_ref()
            .map(|c| {
                let (max, run) = (float(c.max)?, run(&c.run)?);
                Ok(quote!(#m::DriftCheck { max: #max, run: #run }))
            })
            .transpose()
            .map(optional)
    };
    let period = c
        .period
        .as_ref()
        .map(|c| -> Result<TokenStream, String> {
            let (event, value) = (text(&c.event), text(&c.value));
            let (tolerance, run) = (float(c.tolerance)?, run(&c.run)?);
            Ok(quote!(#m::PeriodCheck {
                event: #event, value: #value, tolerance: #tolerance, run: #run,
            }))
        })
        .transpose()?;
    let final_state = c
        .final_state
        .as_ref()
        .map(|c| -> Result<TokenStream, String> {
            let t = text(&c.t);
            let values = borrowed(
                c.values
                    .iter()
                    .map(|(k, v)| {
                        let (k, v) = (text(k), text(v));
                        quote!((#k, #v))
                    })
                    .collect(),
            );
            let (tolerance, run) = (float(c.tolerance)?, run(&c.run)?);
            Ok(quote!(#m::FinalStateCheck {
                t: #t, values: #values, tolerance: #tolerance, run: #run,
            }))
        })
        .transpose()?;
    let conserved = borrowed(
        c.conserved
            .iter()
            .map(|c| {
                let (name, value, tolerance) = (text(&c.name), text(&c.value), float(c.tolerance)?);
                Ok(quote!(#m::ConservedCheck { name: #name, value: #value, tolerance: #tolerance }))
            })
            .collect::<Result<_, String>>()?,
    );
    let (natural_frequencies, damping_ratios) =
        (modal(&c.natural_frequencies)?, modal(&c.damping_ratios)?);
    let (period, final_state) = (optional(period), optional(final_state));
    let (energy_drift, constraint_drift) = (drift(&c.energy_drift)?, drift(&c.constraint_drift)?);
    Ok(quote!(#m::Checks {
        natural_frequencies: #natural_frequencies,
        damping_ratios: #damping_ratios,
        period: #period,
        final_state: #final_state,
        conserved: #conserved,
        energy_drift: #energy_drift,
        constraint_drift: #constraint_drift,
    }))
}

/// One `outputs:` entry as a Rust expression for a `static`.
fn output_tokens(
    o: &eomgen_description::outputs::OutputSpec,
    krate: &TokenStream,
) -> Result<TokenStream, String> {
    let (name, value, conserved) = (text(&o.name), text(&o.value), o.conserved);
    let tolerance = float(o.tolerance)?;
    Ok(quote!(#krate::description::outputs::OutputSpec {
        name: #name,
        value: #value,
        conserved: #conserved,
        tolerance: #tolerance,
    }))
}

/// One `floquet:` entry as a Rust expression for a `static`.
fn floquet_tokens(r: &FloquetReference, krate: &TokenStream) -> Result<TokenStream, String> {
    let m = quote!(#krate::description::floquet);
    let at = text(&r.at);
    let axis_units = borrowed(
        r.axis_units
            .iter()
            .map(|(p, u)| {
                let (p, u) = (text(p), text(u));
                quote!((#p, #u))
            })
            .collect(),
    );
    let thresholds = borrowed(
        r.thresholds
            .iter()
            .map(|t| {
                let [name, key, label, value, critical, critical_label, by, note] = [
                    &t.name,
                    &t.key,
                    &t.label,
                    &t.value,
                    &t.critical,
                    &t.critical_label,
                    &t.by,
                    &t.note,
                ]
                .map(|s| text(s));
                quote!(#m::FloquetThreshold {
                    name: #name, key: #key, label: #label, value: #value, critical: #critical,
                    critical_label: #critical_label, by: #by, note: #note,
                })
            })
            .collect(),
    );
    let curves = borrowed(
        r.curves
            .iter()
            .map(|c| {
                let [name, label, along, gives, value] =
                    [&c.name, &c.label, &c.along, &c.gives, &c.value].map(|s| text(s));
                let color = borrowed(c.color.iter().map(|s| text(s)).collect());
                let domain = optional(c.domain.as_deref().map(text));
                quote!(#m::ReferenceCurve {
                    name: #name, label: #label, color: #color, along: #along, gives: #gives,
                    value: #value, domain: #domain,
                })
            })
            .collect(),
    );
    Ok(quote!(#m::FloquetReference {
        at: #at, axis_units: #axis_units, thresholds: #thresholds, curves: #curves,
    }))
}
