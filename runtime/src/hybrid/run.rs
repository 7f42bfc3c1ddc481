//! A run through impacts: the smooth motion integrated until a contact strikes, the impact law
//! applied there ([`impact()`]), and the integration restarted from the state after it.
//!
//! Each contact's gap is an event function (falling, terminal) beside the model's own events.
//! When a contact strikes (`g = 0`, `ġ < 0`), its row `G` (and the slip's row `T` with
//! friction), the model's mass matrix and its constraint rows, which hold through the impact,
//! give the velocities after it; the configuration does not jump. The integrator then starts
//! afresh from that state, as a new initial value problem, so every method restarts cleanly.
//!
//! A contact that stays closed ends the run, with the time and the reason
//! ([`ContactStop`]): after a plastic impact (`ġ⁺ = 0`) or when the impacts accumulate (a
//! ball bouncing with `e < 1` strikes infinitely often before a finite time; Zeno). Holding a
//! closed contact as a constraint while its force pushes (a contact phase) comes later.
//!
//! Source: Pfeiffer & Glocker (1996), ch. 4 and 7 (the event-driven scheme); Leine &
//! Nijmeijer (2004), §2.4 (Zeno).

use serde::Serialize;

use super::impact::{ContactFriction, ImpactContact, ImpactError, ImpactMode, impact};
use crate::integrate::{Integrator, IntegratorOptions, OutputTimes, Solution};
use crate::model_info::ModelInfo;
use crate::ode::{EventDirection, EventSpec, WithEvents};
use crate::{IntegrationFailure, analysis::AddedEvents};

/// A contact's striking speed below this fraction of the largest that contact has struck
/// with in the run (or exactly 0 after an impact) closes it for good: the impacts accumulate.
/// At `e = 0.8` a ball reaches it after 62 bounces, `(1 − e)⁻¹ · 2 · 10⁻⁶ v₀/g` before the
/// accumulation time.
pub const ACCUMULATION_RATIO: f64 = 1e-6;

/// The most impacts one run takes before it stops ([`ContactStop::TooManyImpacts`]).
pub const MAX_IMPACTS: usize = 100_000;

/// One impact of a run: where, the velocities before and after, the impulses and the energy
/// lost.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Transition {
    /// Time of the impact (s).
    pub t: f64,
    /// The contact that struck ([`crate::ModelDescription::contacts`]).
    pub contact: String,
    /// How the impact ended: without friction, sticking, sliding, or reversing its slip.
    pub mode: ImpactMode,
    /// `q̇` before and after (`n` entries each).
    pub qdot: [Vec<f64>; 2],
    /// `ġ` before and after (m/s): `ġ⁺ = −e ġ⁻`.
    pub normal_velocity: [f64; 2],
    /// The normal impulse `Λ_N` (N·s; the generalized impulse is `Gᵀ Λ_N`).
    pub normal_impulse: f64,
    /// The tangential impulse `Λ_T` (N·s; 0 without friction).
    pub tangential_impulse: f64,
    /// The kinetic energy lost (J), `≥ 0`.
    pub energy_lost: f64,
    /// Index into the run's samples of the first sample after the impact (the sample before
    /// it has the same time and the state before).
    pub sample: usize,
}

/// Why a run through impacts stopped before its end time, other than a failed integration or
/// a terminal event.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum ContactStop {
    /// The contact stays closed: a plastic impact left it at `ġ = 0`, or the impacts
    /// accumulate (the striking speed fell below [`ACCUMULATION_RATIO`] of its largest).
    #[error(
        "contact `{contact}` stays closed from t = {t} ({}): holding a closed contact while its force pushes is not simulated yet, so the run stops here",
        if *accumulating { format!("impacts accumulate there: the striking speed fell to {speed:.3e} m/s") } else { "the impact left it at zero normal speed".to_string() }
    )]
    Closed {
        /// The contact.
        contact: String,
        /// Time (s).
        t: f64,
        /// The striking speed `|ġ⁻|` (m/s).
        speed: f64,
        /// Whether the impacts accumulate (else a plastic impact closed it).
        accumulating: bool,
    },
    /// The impact law has no answer at this state.
    #[error("the impact at contact `{contact}` at t = {t} has no answer: {error}")]
    Impact {
        /// The contact.
        contact: String,
        /// Time (s).
        t: f64,
        /// Why.
        error: ImpactError,
    },
    /// More than [`MAX_IMPACTS`] impacts.
    #[error("the run took {count} impacts and stops at t = {t}")]
    TooManyImpacts {
        /// Impacts taken.
        count: usize,
        /// Time (s).
        t: f64,
    },
}

/// What a run through impacts adds to a run: its transitions and why it stopped early.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct HybridRecord {
    /// The impacts, in time order.
    pub transitions: Vec<Transition>,
    /// Why the run stopped before its end time at a contact, if it did.
    pub stop: Option<ContactStop>,
}

/// Integrates `model` from `y0` at `t0` to `t_end` through the impacts of its contacts (see
/// the module documentation), with the `added` events beside the model's own, sampled at
/// `output` (a requested time equal to an impact's is sampled before it).
///
/// # Shapes
/// `y0`: `2n`. The solution's samples include, at each impact, the state before and after at
/// the same time.
///
/// # Errors
/// [`IntegrationFailure`] as [`Integrator::integrate`], its partial solution holding the
/// samples of every phase before the failure; the record then holds the impacts before it
/// (the second element of the pair is returned in both cases).
pub fn integrate_through_impacts(
    integrator: &mut dyn Integrator,
    model: &mut dyn ModelInfo,
    mut added: Option<&mut dyn AddedEvents>,
    (t0, y0): (f64, &[f64]),
    t_end: f64,
    output: &OutputTimes,
    options: &IntegratorOptions,
) -> (Result<Solution, IntegrationFailure>, HybridRecord) {
    let n = model.num_dofs();
    let contacts: Vec<String> = (model.description().contacts.iter())
        .map(|c| c.to_string())
        .collect();
    let own = model.description().events.len();
    let added_specs = added.as_mut().map_or_else(Vec::new, |a| a.specs());
    let first_contact = own + added_specs.len();
    let mut specs = added_specs.clone();
    specs.extend(
        contacts
            .iter()
            .map(|c| EventSpec::new(c.clone(), EventDirection::Falling, true)),
    );
    let mut record = HybridRecord::default();
    let mut fastest = vec![0.0_f64; contacts.len()];
    let mut whole: Option<Solution> = None;
    let (mut t, mut y) = (t0, y0.to_vec());
    // The contact struck at the phase's start, with its gap there: `(contact, gap)`.
    let mut struck: Option<(usize, f64)> = None;
    let mut values = vec![0.0; 2 * contacts.len()];
    loop {
        let t0_phase = t;
        let phase = {
            let added = &mut added;
            let count = added_specs.len();
            let mut system = WithEvents::new(
                model,
                specs.clone(),
                |m: &mut (dyn ModelInfo + '_), t: f64, y: &[f64], g: &mut [f64]| {
                    let (outer, gaps) = g.split_at_mut(count);
                    if let Some(added) = added.as_deref_mut() {
                        added.values(m, t, y, outer)?;
                    }
                    contact_gaps(
                        m,
                        (t, y),
                        struck.map(|(c, g)| (c, t0_phase, g)),
                        &mut values,
                        gaps,
                    );
                    Ok(())
                },
            );
            let output = match output {
                OutputTimes::Steps => OutputTimes::Steps,
                OutputTimes::At(times) if whole.is_some() => {
                    OutputTimes::At(times.iter().copied().filter(|&s| s > t).collect())
                }
                OutputTimes::At(times) => OutputTimes::At(times.clone()),
            };
            integrator.integrate(&mut system, t, &y, t_end, &output, options)
        };
        let phase = match phase {
            Ok(phase) => phase,
            Err(IntegrationFailure { error, partial }) => {
                let partial = append(whole, *partial);
                return (
                    Err(IntegrationFailure {
                        error,
                        partial: Box::new(partial),
                    }),
                    record,
                );
            }
        };
        let (phase, strike) = take_strike(phase, first_contact);
        let solution = append(whole, phase);
        let Some((c, at, state)) = strike else {
            return (Ok(solution), record);
        };
        let sample = solution.len();
        whole = Some(solution);
        if record.transitions.len() >= MAX_IMPACTS {
            record.stop = Some(ContactStop::TooManyImpacts {
                count: record.transitions.len(),
                t: at,
            });
            break;
        }
        match strike_contact(model, &contacts, c, at, &state, &mut fastest[c]) {
            Ok(mut transition) => {
                transition.sample = sample;
                struck = Some((c, model.contact_values(at, &state).gaps[c]));
                y = state;
                y[n..2 * n].copy_from_slice(&transition.qdot[1]);
                t = at;
                let closed = transition.normal_velocity[1] <= 0.0;
                let speed = -transition.normal_velocity[0];
                record.transitions.push(transition);
                if closed {
                    if let Some(w) = whole.as_mut() {
                        w.push(t, &y);
                    }
                    record.stop = Some(ContactStop::Closed {
                        contact: contacts[c].clone(),
                        t: at,
                        speed,
                        accumulating: false,
                    });
                    break;
                }
            }
            Err(stop) => {
                record.stop = Some(stop);
                break;
            }
        }
    }
    (Ok(whole.unwrap_or_else(|| Solution::new(2 * n))), record)
}

/// The contacts' event functions at `(t, y)` into `gaps` (one per contact): each gap, but for
/// the contact `c` struck at the phase's start `(t*, g*)`, `(g − g*)/(t − t*)` (its rate `ġ`
/// at `t*`). That contact leaves with `ġ⁺ > 0` from a gap of 0 (to rounding, of either
/// sign), so its gap would start at a zero that the sign test between two steps cannot see
/// past: a short flight that rises and lands within one step would be missed. The quotient
/// starts at `ġ⁺ > 0` and turns negative where the gap returns to `g*` (within rounding of
/// 0). `values` is scratch of `2 m_c` entries.
fn contact_gaps(
    model: &mut dyn ModelInfo,
    (t, y): (f64, &[f64]),
    struck: Option<(usize, f64, f64)>,
    values: &mut [f64],
    gaps: &mut [f64],
) {
    model.contact_gaps(t, y, values);
    let m = gaps.len();
    gaps.copy_from_slice(&values[..m]);
    if let Some((c, start, gap)) = struck {
        gaps[c] = if t > start {
            (values[c] - gap) / (t - start)
        } else {
            values[m + c]
        };
    }
}

/// The impact of contact `c` at `(t, y)`: the velocities after it, or why the run stops
/// there. `fastest` is the largest striking speed of the contact so far (updated).
fn strike_contact(
    model: &mut dyn ModelInfo,
    contacts: &[String],
    c: usize,
    t: f64,
    y: &[f64],
    fastest: &mut f64,
) -> Result<Transition, ContactStop> {
    let n = model.num_dofs();
    let contact = &contacts[c];
    let values = model.contact_values(t, y);
    let speed = -values.rates[c];
    *fastest = fastest.max(speed);
    if speed.is_nan() || speed <= ACCUMULATION_RATIO * *fastest {
        return Err(ContactStop::Closed {
            contact: contact.clone(),
            t,
            speed,
            accumulating: true,
        });
    }
    let (mass, _) = model.mass_matrix_and_forcing(t, y);
    let held = model.constraint_equations(t, y).jacobian;
    let held: Vec<f64> = (0..held.nrows())
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| held[(i, j)])
        .collect();
    let normal = &values.normal[c * n..(c + 1) * n];
    let tangent = &values.tangent[c * n..(c + 1) * n];
    let friction = (values.friction[c] > 0.0).then_some(ContactFriction {
        tangent,
        coefficient: values.friction[c],
    });
    let law = ImpactContact {
        normal,
        restitution: values.restitution[c],
        friction,
    };
    let qdot = &y[n..2 * n];
    let r = impact(mass.as_slice(), qdot, &law, &held).map_err(|error| ContactStop::Impact {
        contact: contact.clone(),
        t,
        error,
    })?;
    Ok(Transition {
        t,
        contact: contact.clone(),
        mode: r.mode,
        qdot: [qdot.to_vec(), r.qdot],
        normal_velocity: r.normal_velocity,
        normal_impulse: r.normal_impulse,
        tangential_impulse: r.tangential_impulse,
        energy_lost: r.energy_lost,
        sample: 0,
    })
}

/// `phase` without its contacts' events (an impact is a [`Transition`], not an event), and
/// the strike that ended it, if one did: `(contact, t, y)`.
fn take_strike(
    mut phase: Solution,
    first_contact: usize,
) -> (Solution, Option<(usize, f64, Vec<f64>)>) {
    let terminal = phase.terminated_by_event.take();
    let mut strike = None;
    let mut kept = Vec::with_capacity(phase.events.len());
    for (k, e) in std::mem::take(&mut phase.events).into_iter().enumerate() {
        if e.index >= first_contact {
            if terminal == Some(k) {
                strike = Some((e.index - first_contact, e.t, e.y));
            }
            continue;
        }
        if terminal == Some(k) {
            phase.terminated_by_event = Some(kept.len());
        }
        kept.push(e);
    }
    phase.events = kept;
    (phase, strike)
}

/// `head` (if any) followed by `tail`: samples, events (the tail's terminal event re-indexed)
/// and work.
fn append(head: Option<Solution>, tail: Solution) -> Solution {
    let Some(mut head) = head else {
        return tail;
    };
    let offset = head.events.len();
    head.t.extend_from_slice(&tail.t);
    head.y.extend_from_slice(&tail.y);
    head.events.extend(tail.events);
    head.terminated_by_event = tail.terminated_by_event.map(|k| k + offset);
    head.stats.accumulate(&tail.stats);
    head
}
