//! What a run through impacts records: its transitions (impacts, switches, changes of
//! support) and why it stopped early.

use serde::Serialize;

use super::impact::{ImpactError, ImpactMode};
use super::support::SupportError;

/// What happened at a contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TransitionKind {
    /// An impact after which the contact opens again.
    Impact,
    /// An impact after which the contact stays closed (plastic, or where impacts
    /// accumulate): a contact phase begins.
    Closes,
    /// The closed contact's normal force fell through 0: it opens, with no jump.
    LiftOff,
    /// The closed contact's slip stopped and the friction cone holds it: it sticks.
    Stick,
    /// The closed contact starts to slide: its sticking force left the friction cone, or its
    /// slip stopped where the cone cannot hold it (it slides the other way).
    Slip,
    /// A walker's foot landed and became the stance foot, the old one left the ground, and
    /// the coordinates were relabelled about the new one ([`super::support`]): the speeds
    /// before and after are in the old and the new coordinates.
    SupportChange,
}

/// One transition of a run at a contact: where, what, the velocities before and after, the
/// impulses and the energy lost (0 and the same velocities at a lift-off).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Transition {
    /// Time (s).
    pub t: f64,
    /// The contact ([`crate::ModelDescription::contacts`]).
    pub contact: String,
    /// What happened.
    pub kind: TransitionKind,
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
    /// How far the potential energy's datum moved (J): `V(q⁺) − V(q⁻)` at a change of
    /// support, whose coordinates are taken about the new stance foot; 0 at every other
    /// transition.
    pub datum_shift: f64,
    /// At a change of support, where the new stance foot is in the old one's coordinates
    /// (m): the origin of the coordinates moves there (a drawing of the walk adds it up).
    /// `None` at every other transition.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub foot: Option<[f64; 2]>,
    /// Index into the run's samples of the first sample after the transition. With every
    /// step sampled ([`OutputTimes::Steps`](crate::integrate::OutputTimes::Steps)) it is at the transition's time, and so is the
    /// sample before it, with the state before; with requested times
    /// ([`OutputTimes::At`](crate::integrate::OutputTimes::At)) it is the first requested time after the transition.
    pub sample: usize,
}

impl Transition {
    /// A switch with no jump at contact `contact` (a lift-off, a stick, a slip, a closing
    /// without impulse): the same speeds `qdot` before and after, no impulse, nothing lost.
    pub(super) fn switch(
        t: f64,
        contact: String,
        kind: TransitionKind,
        qdot: &[f64],
        sample: usize,
    ) -> Self {
        Self {
            t,
            contact,
            kind,
            mode: ImpactMode::Frictionless,
            qdot: [qdot.to_vec(), qdot.to_vec()],
            normal_velocity: [0.0; 2],
            normal_impulse: 0.0,
            tangential_impulse: 0.0,
            energy_lost: 0.0,
            datum_shift: 0.0,
            foot: None,
            sample,
        }
    }

    /// The drop of the model's `T + V` across the transition (J): the energy lost, less the
    /// datum's shift at a change of support. A run's energy plus these drops is conserved
    /// where nothing else does work.
    pub fn energy_drop(&self) -> f64 {
        self.energy_lost - self.datum_shift
    }
}

/// Why a run through impacts stopped before its end time, other than a failed integration or
/// a terminal event.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum ContactStop {
    /// A contact that touches, with its gap closing in the free motion, would have to pull
    /// to stay closed: no mode is consistent (Painlevé's paradox with friction).
    #[error(
        "contact `{contact}` at t = {t} can be neither open (the motion would move into it) nor closed (its force would pull): no consistent contact mode (Painlevé's paradox with friction), so the run stops here"
    )]
    NoConsistentMode {
        /// The contact.
        contact: String,
        /// Time (s).
        t: f64,
    },
    /// A sliding contact's normal force would grow without bound: its normal acceleration no
    /// longer answers its own normal force with friction against the slip
    /// ([`PAINLEVE_RESPONSE`](super::run::PAINLEVE_RESPONSE); Painlevé's paradox while sliding, where the motion goes on
    /// only through an impulse, an impact without collision, which is not there).
    #[error(
        "contact `{contact}` at t = {t} would slide where sliding has no bounded normal force (Painlevé's paradox: with friction against the slip, the normal acceleration no longer answers the normal force); the motion goes on only through an impulsive force, which is not simulated, so the run stops here"
    )]
    SlidingPainleve {
        /// The contact.
        contact: String,
        /// Time (s).
        t: f64,
    },
    /// The equations of the contact phase that a switch at this contact must decide from
    /// have no finite solution (held rows that contradict each other, or a mass matrix
    /// singular on the motions they allow).
    #[error(
        "the contact phase at contact `{contact}` at t = {t} has no finite solution (the rows held contradict each other, or the mass matrix is singular on the motions they allow), so the run stops here"
    )]
    Unsolved {
        /// The contact.
        contact: String,
        /// Time (s).
        t: f64,
    },
    /// A contact is closed and the method integrates only free phases (the Taylor method,
    /// whose recurrences have no contact rows).
    #[error(
        "a contact is closed at t = {t}, and the {method} method integrates free motions only: choose another method (dop853, for one) for a run with contact phases"
    )]
    MethodInContact {
        /// The method.
        method: &'static str,
        /// Time (s).
        t: f64,
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
    /// A change of support has no answer that the model's assumptions allow, or another
    /// contact is closed when it strikes.
    #[error("the change of support at contact `{contact}` at t = {t} has no answer: {error}")]
    Support {
        /// The contact.
        contact: String,
        /// Time (s).
        t: f64,
        /// Why.
        error: SupportError,
    },
    /// More than [`MAX_IMPACTS`](super::run::MAX_IMPACTS) impacts.
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
