//! A run through impacts: the smooth motion integrated until a contact strikes, the impact law
//! applied there ([`impact()`]), and the integration restarted from the state after it.
//!
//! Each contact's gap is an event function (falling, terminal) beside the model's own events.
//! When a contact strikes (`g = 0`, `ġ < 0`), its row `G` (and the slip's row `T` with
//! friction), the model's mass matrix and its constraint rows, which hold through the impact,
//! give the velocities after it; the configuration does not jump. The integrator then starts
//! afresh from that state, as a new initial value problem, so every method restarts cleanly.
//!
//! A contact closes when an impact leaves it at zero normal speed (a plastic
//! impact), or when its impacts accumulate (a ball bouncing with `e < 1` strikes infinitely
//! often before a finite time, Zeno): below [`ACCUMULATION_RATIO`] of its largest striking
//! speed the last impact is taken as plastic. The contact is then held as a constraint
//! (a contact phase) while its normal force pushes, and opens again where the force falls
//! through 0. With friction a closed contact sticks (its slip held at 0 while the tangential
//! force stays in the cone `|λ_T| ≤ μ λ_N`) or slides (the force `(G − μ s T)ᵀ λ_N`, `s` the
//! slip's sign), switching by events: stick to slip where the force leaves the cone, slip
//! to stick (or to a slip the other way) where the slip stops (Leine & Nijmeijer 2004,
//! §5.1: the switch model of Coulomb's law, without smoothing).
//!
//! Source: Pfeiffer & Glocker (1996), ch. 4 and 7 (the event-driven scheme); Leine &
//! Nijmeijer (2004), §2.4 (Zeno).

use super::impact::{
    ContactFriction, ImpactContact, ImpactError, ImpactMode, ImpactReport, impact,
};
use super::phase::{ContactPhase, Hold, closing_hold, contact_events, touching};
use super::record::{ContactStop, HybridRecord, Transition, TransitionKind};
use super::support::{SupportError, SupportValues, change_support};
use crate::IntegrationFailure;
use crate::integrate::{Integrator, IntegratorOptions, OutputTimes, Solution, Tolerance};
use crate::model_info::{AddedEvents, ContactValues, ModelInfo};
use crate::ode::{EventDirection, EventSpec, WithEvents};

/// A contact's striking speed below this fraction of the largest that contact has struck
/// with since it last opened from a contact phase (or since the start; or exactly 0 after an
/// impact) closes it for good: the impacts accumulate. A contact that rests and is lifted
/// off again starts a new sequence of strikes, measured afresh.
/// At `e = 0.8` a ball reaches it after 62 bounces, `(1 − e)⁻¹ · 2 · 10⁻⁶ v₀/g` before the
/// accumulation time.
pub const ACCUMULATION_RATIO: f64 = 1e-6;

/// The response of a sliding contact's normal acceleration to its own normal force, relative
/// to the frictionless one, `G W (G − μ s T)ᵀ / G W Gᵀ`, below which the run stops
/// ([`ContactStop::SlidingPainleve`]): where it reaches 0 the normal force needed is
/// unbounded. Its event is located to the tolerance; this is the margin for deciding that
/// it, not the normal force or the slip, reached 0.
pub const PAINLEVE_RESPONSE: f64 = 1e-6;

/// The most impacts one run takes before it stops ([`ContactStop::TooManyImpacts`]).
pub const MAX_IMPACTS: usize = 100_000;

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
    added: Option<&mut dyn AddedEvents>,
    (t0, y0): (f64, &[f64]),
    t_end: f64,
    output: &OutputTimes,
    options: &IntegratorOptions,
) -> (Result<Solution, IntegrationFailure>, HybridRecord) {
    let contacts: Vec<String> = (model.description().contacts.iter())
        .map(|c| c.to_string())
        .collect();
    let atol = match &options.atol {
        Tolerance::Scalar(a) => *a,
        Tolerance::PerComponent(a) => a.iter().copied().fold(f64::INFINITY, f64::min),
    };
    let mut run = Run {
        closed: vec![false; contacts.len()],
        holds: vec![Hold::Normal; contacts.len()],
        fastest: vec![0.0; contacts.len()],
        contacts,
        starting: Vec::new(),
        record: HybridRecord::default(),
        whole: None,
        t: t0,
        y: y0.to_vec(),
        added,
        atol,
    };
    (run.closed, run.holds) = touching(model, (t0, y0), atol);
    // A change of support is never held closed: it lands at its event, or passes.
    let supports = &model.description().supports;
    for (c, name) in run.contacts.iter().enumerate() {
        if supports.iter().any(|s| **s == **name) {
            run.closed[c] = false;
        }
    }
    if let Err(stop) = run.settle(model, 0) {
        run.record.stop = Some(stop);
    }
    while run.record.stop.is_none() {
        if run.closed.contains(&true) && integrator.name() == "taylor" {
            run.record.stop = Some(ContactStop::MethodInContact {
                method: integrator.name(),
                t: run.t,
            });
            break;
        }
        let phase = run.phase(integrator, model, (t_end, output), options);
        let (phase, strike) = match phase {
            Ok(phase) => phase,
            Err(IntegrationFailure { error, partial }) => {
                let partial = append(run.whole, *partial);
                let failure = IntegrationFailure {
                    error,
                    partial: Box::new(partial),
                };
                return (Err(failure), run.record);
            }
        };
        let solution = append(run.whole.take(), phase);
        let sample = solution.len();
        run.whole = Some(solution);
        let Some((c, at, state)) = strike else {
            break;
        };
        if run.record.transitions.len() >= MAX_IMPACTS {
            run.record.stop = Some(ContactStop::TooManyImpacts {
                count: run.record.transitions.len(),
                t: at,
            });
            break;
        }
        let result = run
            .transition(model, c, (at, state), sample)
            .and_then(|()| run.settle(model, sample));
        if let Err(stop) = result {
            run.record.stop = Some(stop);
            break;
        }
        // A transition at the end time ends the run there, with the state after it.
        if run.t >= t_end {
            if let (Some(w), OutputTimes::Steps) = (run.whole.as_mut(), output) {
                w.push(run.t, &run.y);
            }
            break;
        }
    }
    let mut solution = run.whole.unwrap_or_else(|| Solution::new(y0.len()));
    if solution.is_empty() {
        solution.push(run.t, &run.y);
    }
    (Ok(solution), run.record)
}

/// The transition that ended a phase: the contact, the time and the state there.
type Strike = (usize, f64, Vec<f64>);

/// The state of a run through impacts between its phases.
struct Run<'a> {
    /// The contacts' names.
    contacts: Vec<String>,
    /// Which contacts are closed (held in the phase).
    closed: Vec<bool>,
    /// How each closed contact is held (frictionless, sticking or sliding).
    holds: Vec<Hold>,
    /// Each contact's largest striking speed so far (m/s).
    fastest: Vec<f64>,
    /// The open contacts whose event functions start the phase at a zero, with their gaps
    /// there (see [`contact_events`]).
    starting: Vec<(usize, f64)>,
    /// The transitions so far.
    record: HybridRecord,
    /// The samples of the phases so far.
    whole: Option<Solution>,
    /// Where the next phase starts.
    t: f64,
    y: Vec<f64>,
    /// The events added to the model's own.
    added: Option<&'a mut dyn AddedEvents>,
    /// The smallest absolute tolerance of the run: a gap within it of 0 touches.
    atol: f64,
}

impl Run<'_> {
    /// The next phase, from `(t, y)` to `t_end` or the first transition at a contact: its
    /// samples (without the contacts' events), and the contact, time and state of the
    /// transition if one ended it.
    fn phase(
        &mut self,
        integrator: &mut dyn Integrator,
        model: &mut dyn ModelInfo,
        (t_end, output): (f64, &OutputTimes),
        options: &IntegratorOptions,
    ) -> Result<(Solution, Option<Strike>), IntegrationFailure> {
        let added_specs = self.added.as_ref().map_or_else(Vec::new, |a| a.specs());
        let count = added_specs.len();
        let first_contact = model.as_ode().event_specs().len() + count;
        let mut specs = added_specs;
        specs.extend(
            (self.contacts.iter())
                .map(|c| EventSpec::new(c.clone(), EventDirection::Falling, true)),
        );
        let closed: Vec<usize> = (0..self.closed.len()).filter(|&c| self.closed[c]).collect();
        let holds: Vec<Hold> = closed.iter().map(|&c| self.holds[c]).collect();
        // The sticking cones' coefficients, `μ_s`, for the sticking contacts' events.
        let friction = model.contact_values(self.t, &self.y).static_friction;
        let (start, added) = (self.t, &mut self.added);
        let starting: Vec<(usize, f64, f64)> = (self.starting.iter())
            .map(|&(c, g)| (c, start, g))
            .collect();
        let mut phase = ContactPhase::new(model, closed, holds);
        let mut values = vec![0.0; 5 * self.contacts.len()];
        let mut system = WithEvents::new(
            &mut phase,
            specs,
            |p: &mut ContactPhase<'_>, t: f64, y: &[f64], g: &mut [f64]| {
                let (outer, contacts) = g.split_at_mut(count);
                if let Some(added) = added.as_deref_mut() {
                    added.values(p.model, t, y, outer)?;
                }
                contact_events(p, (t, y), (&starting, &friction), &mut values, contacts)
            },
        );
        let output = match output {
            OutputTimes::At(times) if self.whole.is_some() => {
                OutputTimes::At(times.iter().copied().filter(|&s| s > start).collect())
            }
            other => other.clone(),
        };
        let phase = integrator.integrate(&mut system, start, &self.y, t_end, &output, options)?;
        Ok(take_strike(phase, first_contact))
    }

    /// The transition at contact `c` at `(t, y)`: a lift-off if it is closed, else an
    /// impact, which may close it; the next phase starts after it. `sample` is the index
    /// the next phase's first sample will have.
    fn transition(
        &mut self,
        model: &mut dyn ModelInfo,
        c: usize,
        (t, y): (f64, Vec<f64>),
        sample: usize,
    ) -> Result<(), ContactStop> {
        let n = model.num_dofs();
        let supports = &model.description().supports;
        if let Some(which) = supports.iter().position(|s| **s == *self.contacts[c]) {
            return self.change_support(model, (c, which), (t, y), sample);
        }
        let mut released = Vec::new();
        let mut y = y;
        if !self.closed[c] {
            held_velocities(model, t, &mut y);
        }
        let transition = if self.closed[c] {
            let kind = self.switch(model, c, (t, &y))?;
            if kind == TransitionKind::LiftOff {
                self.closed[c] = false;
                self.holds[c] = Hold::Normal;
                self.fastest[c] = 0.0;
            }
            Transition::switch(t, self.contacts[c].clone(), kind, &y[n..2 * n], sample)
        } else {
            let before = self.closed.clone();
            let mut transition = strike_contact(
                model,
                &self.contacts,
                (c, &mut self.closed, &mut self.holds),
                (t, &y),
                (&mut self.fastest[c], self.atol),
            )?;
            transition.sample = sample;
            // The closed contacts the impact released (held, they would have pulled), listed
            // after it.
            for k in (0..before.len()).filter(|&k| before[k] && !self.closed[k]) {
                self.fastest[k] = 0.0;
                released.push(Transition::switch(
                    t,
                    self.contacts[k].clone(),
                    TransitionKind::LiftOff,
                    &transition.qdot[1],
                    sample,
                ));
            }
            if transition.kind == TransitionKind::Closes {
                self.closed[c] = true;
                self.holds[c] = closing_hold(model, c, (t, &transition.qdot[1]), self.atol, &y);
            }
            transition
        };
        self.y = y;
        self.y[n..2 * n].copy_from_slice(&transition.qdot[1]);
        self.t = t;
        self.record.transitions.push(transition);
        self.record.transitions.extend(released);
        Ok(())
    }

    /// The change of support `which` at contact `c` at `(t, y)` ([`change_support`]); the
    /// next phase starts after it, in the relabelled coordinates.
    fn change_support(
        &mut self,
        model: &mut dyn ModelInfo,
        (c, which): (usize, usize),
        (t, y): (f64, Vec<f64>),
        sample: usize,
    ) -> Result<(), ContactStop> {
        let n = model.num_dofs();
        let stop = |error| ContactStop::Support {
            contact: self.contacts[c].clone(),
            t,
            error,
        };
        if let Some(k) = self.closed.iter().position(|&closed| closed) {
            return Err(stop(SupportError::Closed {
                contact: self.contacts[k].clone(),
            }));
        }
        // Where the file's `when:` is not positive, or the foot passes over the stance foot,
        // it does not land (scuffing): the phase goes on from here, the contact open at a
        // zero.
        let s = SupportValues::of(model, which, t, &y[..n]);
        if !s.lands() {
            self.y = y;
            self.t = t;
            return Ok(());
        }
        let values = model.contact_values(t, &y);
        let law = (values.restitution[c], values.static_friction[c]);
        let change = change_support(model, &s, (t, &y), law).map_err(stop)?;
        let after: Vec<f64> = change.q.iter().chain(&change.qdot).copied().collect();
        let potential = |y: &[f64]| model.energy(t, y) - model.kinetic_energy(t, y);
        self.record.transitions.push(Transition {
            t,
            contact: self.contacts[c].clone(),
            kind: TransitionKind::SupportChange,
            // The landing foot sticks, whether or not the file bounds its friction.
            mode: ImpactMode::Sticking,
            qdot: [y[n..2 * n].to_vec(), change.qdot.clone()],
            normal_velocity: [values.rates[c], 0.0],
            normal_impulse: change.normal_impulse,
            tangential_impulse: change.tangential_impulse,
            energy_lost: change.energy_lost,
            datum_shift: potential(&after) - potential(&y),
            foot: Some(change.foot),
            sample,
        });
        self.y = after;
        self.t = t;
        Ok(())
    }

    /// The switch at the closed contact `c`, at the zero of its event function: a lift-off
    /// where `λ_N` reached 0 first; for a sticking contact whose force left the cone, a slip
    /// (it slides against the force it needed, `s = −sign λ_T`); for a sliding contact whose
    /// slip stopped, a stick where the cone holds the force sticking needs, else a slip the
    /// other way. Updates [`Self::holds`].
    fn switch(
        &mut self,
        model: &mut dyn ModelInfo,
        c: usize,
        (t, y): (f64, &[f64]),
    ) -> Result<TransitionKind, ContactStop> {
        let closed: Vec<usize> = (0..self.closed.len()).filter(|&k| self.closed[k]).collect();
        let at = closed.iter().position(|&k| k == c).unwrap_or_default();
        if matches!(self.holds[c], Hold::Slide(_)) {
            let holds: Vec<Hold> = closed.iter().map(|&k| self.holds[k]).collect();
            let response =
                ContactPhase::new(model, closed.clone(), holds).sliding_response(c, t, y);
            if response.is_some_and(|b| b <= PAINLEVE_RESPONSE) {
                return Err(ContactStop::SlidingPainleve {
                    contact: self.contacts[c].clone(),
                    t,
                });
            }
        }
        let values = model.contact_values(t, y);
        let n = model.num_dofs();
        // The sticking cone's coefficient, `μ_s`.
        let mu = values.static_friction[c];
        let slip = values.slip(c, &y[n..2 * n]);
        let mut holds: Vec<Hold> = closed.iter().map(|&k| self.holds[k]).collect();
        // A phase that cannot be solved here (its forces not finite) decides nothing: the
        // run stops, rather than read a failed solve as a lift-off or a stick.
        let unsolved = || ContactStop::Unsolved {
            contact: self.contacts[c].clone(),
            t,
        };
        let forces = |model: &mut dyn ModelInfo, holds: &[Hold]| {
            ContactPhase::new(model, closed.clone(), holds.to_vec())
                .solve(t, y)
                .map(|(_, forces)| forces[at])
                .map_err(|_| unsolved())
        };
        let (normal, tangential) = forces(model, &holds)?;
        // Its normal force reached 0 first (or pulls): it lifts off, whatever its friction.
        let lifts = normal <= 0.0
            || (self.holds[c] == Hold::Stick && normal <= mu * normal - tangential.abs());
        let next = match self.holds[c] {
            _ if lifts => None,
            Hold::Normal => None,
            Hold::Stick if mu * normal - tangential.abs() < normal => {
                Some(Hold::Slide(-tangential.signum()))
            }
            Hold::Stick => None,
            Hold::Slide(s) if normal <= s * slip => None,
            Hold::Slide(_) => {
                holds[at] = Hold::Stick;
                let (normal, tangential) = forces(model, &holds)?;
                Some(if mu * normal - tangential.abs() >= 0.0 {
                    Hold::Stick
                } else {
                    Hold::Slide(-tangential.signum())
                })
            }
        };
        Ok(match next {
            None => TransitionKind::LiftOff,
            Some(hold) => {
                self.holds[c] = hold;
                if hold == Hold::Stick {
                    TransitionKind::Stick
                } else {
                    TransitionKind::Slip
                }
            }
        })
    }

    /// The closed contacts' holds decided afresh where a phase starts, at `(t, y)`: a
    /// contact whose normal force pulls is released; a contact with friction sticks where its
    /// slip is within `atol` of 0, else slides with its slip's sign (so a slide never starts
    /// against its slip); a sticking contact whose force is outside its cone slides against
    /// the force it needed, `s = −sign λ_T` (its event function would start below 0 and never
    /// be seen to cross). Each change is recorded at `sample`.
    fn redecide(&mut self, model: &mut dyn ModelInfo, sample: usize) {
        let n = model.num_dofs();
        let values = model.contact_values(self.t, &self.y);
        // A slide just decided by a switch here (its slip still 0) is decided again the same
        // way, and not recorded twice.
        let before = self.holds.clone();
        // A contact that starts to slip here has no slip yet: it keeps the slide its switch
        // chose (at the cone's edge, deciding it again would be rounding's choice).
        let slipping_here: Vec<String> = (self.record.transitions.iter().rev())
            .take_while(|tr| tr.t == self.t)
            .filter(|tr| tr.kind == TransitionKind::Slip)
            .map(|tr| tr.contact.clone())
            .collect();
        for c in (0..self.closed.len()).filter(|&c| self.closed[c]) {
            if slipping_here.contains(&self.contacts[c]) && matches!(self.holds[c], Hold::Slide(_))
            {
                continue;
            }
            if values.friction[c] > 0.0 {
                let slip = values.slip(c, &self.y[n..2 * n]);
                self.holds[c] = if slip.abs() <= self.atol {
                    Hold::Stick
                } else {
                    Hold::Slide(slip.signum())
                };
            }
        }
        for _ in 0..=2 * self.closed.len() {
            let closed: Vec<usize> = (0..self.closed.len()).filter(|&k| self.closed[k]).collect();
            if closed.is_empty() {
                return;
            }
            let holds: Vec<Hold> = closed.iter().map(|&k| self.holds[k]).collect();
            let Ok((_, forces)) =
                ContactPhase::new(model, closed.clone(), holds).solve(self.t, &self.y)
            else {
                return;
            };
            let pulling = (closed.iter().zip(&forces)).find(|(_, f)| f.0 < 0.0);
            let outside = (closed.iter().zip(&forces)).find(|&(&c, f)| {
                self.holds[c] == Hold::Stick && values.static_friction[c] * f.0 - f.1.abs() < 0.0
            });
            let (c, kind) = match (pulling, outside) {
                (Some((&c, _)), _) => {
                    self.closed[c] = false;
                    self.holds[c] = Hold::Normal;
                    self.fastest[c] = 0.0;
                    (c, TransitionKind::LiftOff)
                }
                (None, Some((&c, f))) => {
                    self.holds[c] = Hold::Slide(-f.1.signum());
                    if before[c] == self.holds[c] {
                        continue;
                    }
                    (c, TransitionKind::Slip)
                }
                (None, None) => return,
            };
            self.record.transitions.push(Transition::switch(
                self.t,
                self.contacts[c].clone(),
                kind,
                &self.y[n..2 * n],
                sample,
            ));
        }
    }

    /// The open contacts that touch at `(t, y)` with no normal speed (`|g|`, `|ġ| ≤ atol`) and
    /// whose gap the free motion would close (`g̈ < 0` with them open): each closes where its
    /// normal force then pushes (recorded at `sample`); where it would pull too, the contact
    /// can be neither open nor closed (Painlevé's paradox with friction), and the run stops.
    /// A change of support (`lands`) never closes.
    ///
    /// # Errors
    /// [`ContactStop::NoConsistentMode`] for such a contact.
    fn close_touching(
        &mut self,
        model: &mut dyn ModelInfo,
        sample: usize,
        released: Option<usize>,
        lands: &[bool],
    ) -> Result<(), ContactStop> {
        let n = model.num_dofs();
        for (c, &lands) in lands.iter().enumerate() {
            let values = model.contact_values(self.t, &self.y);
            let touches = values.gaps[c].abs() <= self.atol && values.rates[c].abs() <= self.atol;
            if self.closed[c] || Some(c) == released || lands || !touches {
                continue;
            }
            let mut closed: Vec<usize> =
                (0..self.closed.len()).filter(|&k| self.closed[k]).collect();
            let holds: Vec<Hold> = closed.iter().map(|&k| self.holds[k]).collect();
            let Ok((free, _)) =
                ContactPhase::new(model, closed.clone(), holds.clone()).solve(self.t, &self.y)
            else {
                continue;
            };
            let closing: f64 = (0..n)
                .map(|j| values.normal[c * n + j] * free[j])
                .sum::<f64>()
                - values.gamma[c];
            if closing >= 0.0 {
                continue;
            }
            let hold = closing_hold(model, c, (self.t, &self.y[n..2 * n]), self.atol, &self.y);
            let at = closed.partition_point(|&k| k < c);
            closed.insert(at, c);
            let mut holds = holds;
            holds.insert(at, hold);
            let pushes = ContactPhase::new(model, closed, holds)
                .solve(self.t, &self.y)
                .is_ok_and(|(_, forces)| forces[at].0 > 0.0);
            if !pushes {
                return Err(ContactStop::NoConsistentMode {
                    contact: self.contacts[c].clone(),
                    t: self.t,
                });
            }
            self.closed[c] = true;
            self.holds[c] = hold;
            self.record.transitions.push(Transition::switch(
                self.t,
                self.contacts[c].clone(),
                TransitionKind::Closes,
                &self.y[n..2 * n],
                sample,
            ));
        }
        Ok(())
    }

    /// Resolves, one after another, every open contact that touches at `(t, y)` (`g ≤
    /// atol`) and moves into its surface (`ġ < −atol`; slower, it is touching, and closes or
    /// not by its force below, so that a contact left at `ġ = 0` by a plastic impact is not
    /// struck again by the rounding of `ġ`): a corner struck by a ball, or a run
    /// started on a surface it moves into. Then notes the open contacts that start the next
    /// phase at a zero. (Simultaneous impacts are taken in the order of the contacts, each
    /// with the closed ones held: a documented rule, not Moreau's or an LCP's.)
    ///
    /// # Errors
    /// As [`Self::transition`].
    fn settle(&mut self, model: &mut dyn ModelInfo, sample: usize) -> Result<(), ContactStop> {
        // The contact just released leaves at zero normal speed (to rounding): it is not
        // struck again at once.
        let released = match self.record.transitions.last() {
            Some(tr) if tr.kind == TransitionKind::LiftOff && tr.t == self.t => {
                self.contacts.iter().position(|c| *c == tr.contact)
            }
            _ => None,
        };
        // A change of support lands at its event only (a foot that passes is left open).
        let supports = &model.description().supports;
        let lands: Vec<bool> = (self.contacts.iter())
            .map(|c| supports.iter().any(|s| **s == **c))
            .collect();
        for _ in 0..=2 * self.contacts.len() {
            let values = model.contact_values(self.t, &self.y);
            let striking = (0..self.contacts.len()).find(|&k| {
                !self.closed[k]
                    && !lands[k]
                    && Some(k) != released
                    && values.gaps[k] <= self.atol
                    && values.rates[k] < -self.atol
            });
            let Some(k) = striking else {
                break;
            };
            self.transition(model, k, (self.t, self.y.clone()), sample)?;
        }
        self.close_touching(model, sample, released, &lands)?;
        self.redecide(model, sample);
        // A slide that starts where its normal force is already unbounded (its event would
        // start below 0 and never be seen to cross) stops the run here.
        let closed: Vec<usize> = (0..self.closed.len()).filter(|&k| self.closed[k]).collect();
        let holds: Vec<Hold> = closed.iter().map(|&k| self.holds[k]).collect();
        let phase = ContactPhase::new(model, closed.clone(), holds);
        for &c in &closed {
            if (phase.sliding_response(c, self.t, &self.y)).is_some_and(|b| b <= PAINLEVE_RESPONSE)
            {
                return Err(ContactStop::SlidingPainleve {
                    contact: self.contacts[c].clone(),
                    t: self.t,
                });
            }
        }
        let values = model.contact_values(self.t, &self.y);
        self.starting = (0..self.contacts.len())
            .filter(|&k| !self.closed[k] && values.gaps[k].abs() <= self.atol)
            .map(|k| (k, values.gaps[k]))
            .collect();
        Ok(())
    }
}

/// The impact of contact `c` at `(t, y)`, the closed contacts (`closed`) and the model's
/// constraints held through it: the velocities after it, and whether the contact stays
/// closed ([`TransitionKind::Closes`]: after a plastic impact or one that friction locked
/// ([`ImpactMode::Jammed`]), or below
/// [`ACCUMULATION_RATIO`] of its largest striking speed, where the impact is taken as
/// plastic; and its normal force then pushes). A closed contact whose impulse would pull is
/// released (and the impact solved again without it). `fastest` is the contact's largest
/// striking speed so far (updated); a strike at `graze` (m/s) or slower has no impulse.
fn strike_contact(
    model: &mut dyn ModelInfo,
    contacts: &[String],
    (c, closed, holds): (usize, &mut [bool], &mut [Hold]),
    (t, y): (f64, &[f64]),
    (fastest, graze): (&mut f64, f64),
) -> Result<Transition, ContactStop> {
    let n = model.num_dofs();
    let contact = &contacts[c];
    let values = model.contact_values(t, y);
    let speed = -values.rates[c];
    *fastest = fastest.max(speed);
    let accumulating = speed.is_nan() || speed <= ACCUMULATION_RATIO * *fastest;
    let restitution = if accumulating {
        0.0
    } else {
        values.restitution[c]
    };
    let qdot = &y[n..2 * n];
    let mut transition = Transition {
        t,
        contact: contact.clone(),
        kind: TransitionKind::Closes,
        mode: ImpactMode::Frictionless,
        qdot: [qdot.to_vec(), qdot.to_vec()],
        normal_velocity: [-speed, -speed],
        normal_impulse: 0.0,
        tangential_impulse: 0.0,
        energy_lost: 0.0,
        datum_shift: 0.0,
        foot: None,
        sample: 0,
    };
    // A graze (`|ġ⁻| ≤ atol`, in m/s) closes without an impulse where its force pushes.
    if speed > graze {
        let r = impact_holding(
            model,
            (c, closed, holds),
            (t, y),
            (restitution, graze),
            &values,
        )
        .map_err(|error| ContactStop::Impact {
            contact: contact.clone(),
            t,
            error,
        })?;
        transition.mode = r.mode;
        transition.qdot[1] = r.qdot;
        transition.normal_velocity = r.normal_velocity;
        transition.normal_impulse = r.normal_impulse;
        transition.tangential_impulse = r.tangential_impulse;
        transition.energy_lost = r.energy_lost;
    }
    // After a plastic impact, or one that friction locked, the normal speed is 0 to
    // rounding, of either sign: the contact closes where its force pushes, else it leaves
    // (`g̈ > 0`) from the impact.
    if restitution > 0.0 && transition.mode != ImpactMode::Jammed {
        transition.kind = TransitionKind::Impact;
        return Ok(transition);
    }
    let mut state = y.to_vec();
    state[n..2 * n].copy_from_slice(&transition.qdot[1]);
    let mut with = closed.to_vec();
    with[c] = true;
    let held: Vec<usize> = (0..with.len()).filter(|&k| with[k]).collect();
    let closing = closing_hold(model, c, (t, &state[n..2 * n]), graze, y);
    let wanted: Vec<Hold> = (held.iter())
        .map(|&k| if k == c { closing } else { holds[k] })
        .collect();
    let at = held.iter().position(|&k| k == c).unwrap_or_default();
    let pushes = ContactPhase::new(model, held, wanted)
        .solve(t, &state)
        .map(|(_, forces)| forces[at].0 > 0.0)
        .unwrap_or(false);
    if !pushes {
        transition.kind = TransitionKind::Impact;
    }
    Ok(transition)
}

/// The speeds of `y` projected onto the model's own velocity constraints (`J q̇ + Φ_t = 0`
/// and `A q̇ + b = 0`) as an impulse would move them, `q̇ ← q̇ − M⁻¹Jᵀ (J M⁻¹Jᵀ)⁻¹ (J q̇ + Φ_t)`:
/// the state an impact starts from is the dense output's, off the constraints by the
/// integration's drift, and the rows held through the impact keep what they had (a
/// pendulum bob's rod its drift, which would decide whether friction locks it). Left as it
/// is where the projection is singular.
fn held_velocities(model: &mut dyn ModelInfo, t: f64, y: &mut [f64]) {
    let n = model.num_dofs();
    let constraints = model.constraint_equations(t, y);
    if constraints.jacobian.nrows() == 0 {
        return;
    }
    let (mass, _) = model.mass_matrix_and_forcing(t, y);
    let Some(lu) = Some(mass.lu()).filter(|lu| lu.is_invertible()) else {
        return;
    };
    let Some(w) = lu.solve(&constraints.jacobian.transpose()) else {
        return;
    };
    let schur = &constraints.jacobian * &w;
    let Some(impulses) = schur.lu().solve(&constraints.velocity) else {
        return;
    };
    let correction = w * impulses;
    if correction.iter().all(|v| v.is_finite()) {
        for (v, d) in y[n..2 * n].iter_mut().zip(correction.iter()) {
            *v -= d;
        }
    }
}

/// The impact law at contact `c` with the model's constraints and the closed contacts held
/// (their normal rows, and the slips' rows of those that stick), choosing which closed
/// contacts hold by an active set: a held contact whose normal impulse pulls (`Λ < 0`) is
/// released, a released one that would move into its surface (`ġ⁺ < −graze`) is held again,
/// and where holding them all leaves the impact no answer (a rimless wheel's old foot held,
/// sticking, fixes the wheel) they all start released. `closed` and `sticking` end as the
/// contacts that held.
fn impact_holding(
    model: &mut dyn ModelInfo,
    (c, closed, holds): (usize, &mut [bool], &mut [Hold]),
    (t, y): (f64, &[f64]),
    (restitution, graze): (f64, f64),
    values: &ContactValues,
) -> Result<ImpactReport, ImpactError> {
    let n = model.num_dofs();
    let (mass, _) = model.mass_matrix_and_forcing(t, y);
    let own = model.constraint_equations(t, y).jacobian;
    let own_rows: Vec<f64> = (0..own.nrows())
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| own[(i, j)])
        .collect();
    let friction = (values.friction[c] > 0.0).then_some(ContactFriction {
        tangent: &values.tangent[c * n..(c + 1) * n],
        coefficient: values.friction[c],
        static_coefficient: values.static_friction[c],
        surface_velocity: values.surface_velocity[c],
    });
    let law = ImpactContact {
        normal: &values.normal[c * n..(c + 1) * n],
        restitution,
        friction,
    };
    let was_closed = closed.to_vec();
    let mut hold = closed.to_vec();
    // After all were released, a contact held again holds its normal row alone (where it
    // sticks or slides is decided afresh after the impact).
    let mut demoted = false;
    let mut last_error = None;
    for _ in 0..=2 * (closed.len() + 1) {
        let mut rows = own_rows.clone();
        // For each held contact, the index of its normal row among the held rows.
        let mut normal_rows = Vec::new();
        for k in (0..hold.len()).filter(|&k| hold[k]) {
            normal_rows.push((k, rows.len() / n));
            rows.extend_from_slice(&values.normal[k * n..(k + 1) * n]);
            if holds[k] == Hold::Stick && !demoted {
                rows.extend_from_slice(&values.tangent[k * n..(k + 1) * n]);
            }
        }
        let r = match impact(mass.as_slice(), &y[n..2 * n], &law, &rows) {
            Ok(r) => r,
            // Singular, or so near it that rounding decides the result: as singular.
            Err(error @ (ImpactError::Singular | ImpactError::IllConditioned { .. }))
                if hold.contains(&true) =>
            {
                last_error = Some(error);
                hold.fill(false);
                demoted = true;
                continue;
            }
            Err(e) => return Err(e),
        };
        if let Some(&(k, _)) = normal_rows
            .iter()
            .find(|&&(_, row)| r.holding_impulses[row] < 0.0)
        {
            hold[k] = false;
            continue;
        }
        let entering = (0..hold.len()).find(|&k| {
            was_closed[k] && !hold[k] && {
                let rate: f64 = (0..n).map(|j| values.normal[k * n + j] * r.qdot[j]).sum();
                rate < -graze
            }
        });
        if let Some(k) = entering {
            hold[k] = true;
            continue;
        }
        closed.copy_from_slice(&hold);
        for (h, &held) in holds.iter_mut().zip(&hold) {
            if !held || demoted {
                *h = Hold::Normal;
            }
        }
        return Ok(r);
    }
    // Holding and releasing the closed contacts both fail (one pulls when held and moves in
    // when released): the impact needs a complementarity solve, not there yet.
    Err(last_error.unwrap_or(ImpactError::Singular))
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
