//! A change of support: the landing foot of a walker (or a rimless wheel's next spoke)
//! strikes, sticks and becomes the stance foot, the old stance foot leaves the ground, and
//! the coordinates are relabelled about the new one.
//!
//! The model is written in minimal coordinates about its stance foot at the origin
//! (`support:` on a contact: `eomgen_symbolic::model::elements::support`, which derives the
//! values used here). The plastic impulse `Λ` at the landing foot `S`, with `S` held after
//! it and the old stance foot free, keeps the momenta of every mass about `S`; in the new
//! coordinates `q⁺ = R(q)`:
//!
//! - `M(q⁺) q̇⁺ = H(q) q̇⁻`, `H = Σ mᵢ Jᵢ(q⁺)ᵀ Jᵢ(q) + Iᵢ aᵢ(q⁺)ᵀ aᵢ(q)`;
//! - `Λ = K(q⁺) q̇⁺ − K(q) q̇⁻`, the change of the linear momentum (`K = ∂(Σ mᵢ rᵢ)/∂q`);
//! - the old stance foot leaves at `−F v`, `F = ∂r_S/∂q` and `v = (∂R/∂q)⁻¹ q̇⁺` the speeds
//!   after in the old coordinates.
//!
//! [`change_support`] applies it and checks what the model assumes: the landing foot pushes
//! (`Λ_N > 0`) and, with friction, sticks (`|Λ_T| ≤ μ Λ_N`); the old foot leaves
//! (`n̂ · ṗ₀⁺ ≥ 0`); the relabelling puts the mechanism where it was (its centre of mass);
//! and the bodies carry the model's whole mass matrix. [`reset_jacobian`] gives `∂Δ/∂y` of
//! the whole reset `Δ(q, q̇) = (R(q), M(R(q))⁻¹ H(q) q̇)` from the derivatives of `M(q⁺)` and
//! `H`, exactly, for the saltation matrix of a gait's return map.
//!
//! Source: Grizzle, Abba & Plestan, IEEE TAC 46 (2001) 51–64, §III; Westervelt et al.,
//! *Feedback Control of Dynamic Bipedal Robot Locomotion* (2007), §3.4.2; Garcia et al.,
//! J. Biomech. Eng. 120 (1998) 281–288, eq. 4.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::model_info::ModelInfo;

/// How far the relabelling may move the mechanism's centre of mass, relative to its size
/// (the centre of mass's and the landing foot's distances from the stance foot), or change
/// its mass matrix, relative to the largest entry, before the change of support is refused:
/// rounding, not a wrong `relabel:`.
pub const RELABEL_TOLERANCE: f64 = 1e-8;

/// A landing foot within this fraction of the mechanism's size of the stance foot does not
/// land ([`SupportValues::lands`]): the swing foot passing over the stance foot.
pub const COINCIDENT: f64 = 1e-6;

/// The old stance foot leaves the ground when its speed into it is below this fraction of
/// the speeds at play (the landing foot's before the impact, the stance foot's after): a
/// speed of 0 rounds either way.
pub const RELEASE_TOLERANCE: f64 = 1e-9;

/// One change of support's values at a configuration (see the module documentation and
/// `eomgen_symbolic::model::elements::support::block`).
#[derive(Debug, Clone, PartialEq)]
pub struct SupportValues {
    /// The total mass `m` (kg).
    pub mass: f64,
    /// The ground's unit normal `n̂`.
    pub normal: [f64; 2],
    /// The first moment of mass `Σ mᵢ rᵢ` (kg·m), the stance foot at the origin.
    pub moment: [f64; 2],
    /// The same at `q⁺ = R(q)`.
    pub moment_after: [f64; 2],
    /// The landing foot `r_S` (m).
    pub foot: [f64; 2],
    /// `K = ∂(Σ mᵢ rᵢ)/∂q` (2 × n).
    pub momentum_jacobian: DMatrix<f64>,
    /// The same at `q⁺`.
    pub momentum_jacobian_after: DMatrix<f64>,
    /// `F = ∂r_S/∂q` (2 × n).
    pub foot_jacobian: DMatrix<f64>,
    /// `M(q⁺)` (n × n).
    pub mass_matrix_after: DMatrix<f64>,
    /// `H` (n × n).
    pub h: DMatrix<f64>,
    /// `∂H/∂q_k`, one per coordinate.
    pub dh: Vec<DMatrix<f64>>,
    /// `∂M(R(q))/∂q_k`.
    pub dm: Vec<DMatrix<f64>>,
    /// `R(q)` (n).
    pub relabel: DVector<f64>,
    /// `∂R/∂q` (n × n).
    pub relabel_jacobian: DMatrix<f64>,
    /// Positive where a strike lands (the file's `when:`, else 1); elsewhere the foot
    /// passes through the ground (the simplest walker's scuffing).
    pub when: f64,
}

impl SupportValues {
    /// The values of support change `which` (an index into
    /// [`ModelDescription::supports`](crate::ModelDescription::supports)) at `(t, q)`.
    pub fn of(model: &dyn ModelInfo, which: usize, t: f64, q: &[f64]) -> Self {
        let n = q.len();
        let len = block_len(n);
        let count = model.description().supports.len();
        let mut out = vec![0.0; len * count];
        model.support_changes(t, q, &mut out);
        let block = &out[which * len..(which + 1) * len];
        let mut at = 0;
        let mut take = |k: usize| {
            at += k;
            &block[at - k..at]
        };
        let pair = |v: &[f64]| [v[0], v[1]];
        let matrices = |values: &[f64]| -> Vec<DMatrix<f64>> {
            (values.chunks(n * n))
                .map(|m| DMatrix::from_row_slice(n, n, m))
                .collect()
        };
        Self {
            mass: take(1)[0],
            normal: pair(take(2)),
            moment: pair(take(2)),
            moment_after: pair(take(2)),
            foot: pair(take(2)),
            momentum_jacobian: DMatrix::from_row_slice(2, n, take(2 * n)),
            momentum_jacobian_after: DMatrix::from_row_slice(2, n, take(2 * n)),
            foot_jacobian: DMatrix::from_row_slice(2, n, take(2 * n)),
            mass_matrix_after: DMatrix::from_row_slice(n, n, take(n * n)),
            h: DMatrix::from_row_slice(n, n, take(n * n)),
            dh: matrices(take(n * n * n)),
            dm: matrices(take(n * n * n)),
            relabel: DVector::from_row_slice(take(n)),
            relabel_jacobian: DMatrix::from_row_slice(n, n, take(n * n)),
            when: take(1)[0],
        }
    }

    /// Whether a strike here lands: the file's `when` is positive, and the landing foot is
    /// away from the stance foot (more than [`COINCIDENT`] of the mechanism's size: a swing
    /// foot passing over the stance foot, the legs crossing, is no step).
    pub fn lands(&self) -> bool {
        self.when > 0.0 && self.foot[0].hypot(self.foot[1]) > COINCIDENT * self.size()
    }

    /// The mechanism's size (m): its centre of mass's and the landing foot's distances from
    /// the stance foot.
    fn size(&self) -> f64 {
        (self.moment[0].hypot(self.moment[1]) / self.mass + self.foot[0].hypot(self.foot[1]))
            .max(f64::MIN_POSITIVE)
    }

    /// `t̂`, the normal turned a quarter-turn counter-clockwise.
    fn tangent(&self) -> [f64; 2] {
        [-self.normal[1], self.normal[0]]
    }
}

/// The number of values of one change of support for `n` coordinates (as the symbolic
/// side's `block_len`).
pub fn block_len(n: usize) -> usize {
    10 + 7 * n + 3 * n * n + 2 * n * n * n
}

/// A change of support applied: the state after it and what it took.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SupportChange {
    /// `q` after, relabelled (`R(q)`).
    pub q: Vec<f64>,
    /// `q̇` after, relabelled.
    pub qdot: Vec<f64>,
    /// The landing foot's impulse along the ground's normal, `Λ_N` (N·s, `> 0`).
    pub normal_impulse: f64,
    /// Its impulse along the ground, `Λ_T` (N·s).
    pub tangential_impulse: f64,
    /// The old stance foot's speed away from the ground after it (m/s, `≥ 0`).
    pub release_velocity: f64,
    /// The kinetic energy lost (J).
    pub energy_lost: f64,
    /// Where the new stance foot is in the old one's coordinates, `r_S` (m): the origin of
    /// the new coordinates.
    pub foot: [f64; 2],
}

/// Why a change of support has no answer that the model's assumptions allow.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum SupportError {
    /// The mass matrix after the change (or `∂R/∂q`) is singular.
    #[error(
        "the mass matrix after the change of support, or the relabelling's Jacobian, is singular"
    )]
    Singular,
    /// The landing foot would pull on the ground.
    #[error("the landing foot would pull on the ground (normal impulse {normal_impulse:.6e} N·s)")]
    Pulls {
        /// `Λ_N` (N·s).
        normal_impulse: f64,
    },
    /// The landing foot's impulse is outside the friction cone: it would slip.
    #[error(
        "the landing foot would slip: its impulse needs a friction coefficient of {needed:.6}, above the contact's {friction}"
    )]
    Slips {
        /// `|Λ_T| / Λ_N`.
        needed: f64,
        /// `μ`.
        friction: f64,
    },
    /// The old stance foot would be pushed into the ground: both feet stay (double support),
    /// which the model does not have.
    #[error(
        "the stance foot would not leave the ground (its speed after the impact is {release_velocity:.6e} m/s into it): both feet would stay, a double support the model does not have"
    )]
    StanceStays {
        /// `n̂ · ṗ₀⁺` (m/s).
        release_velocity: f64,
    },
    /// The contact's coefficient of restitution (at the parameters' values) is not 0.
    #[error(
        "its coefficient of restitution is {restitution}, but the landing foot sticks: a change of support is plastic"
    )]
    NotPlastic {
        /// `e`.
        restitution: f64,
    },
    /// Another contact is closed where the foot lands (a change of support is taken from a
    /// free swing only).
    #[error(
        "contact `{contact}` is closed, and a change of support is taken from a free swing only"
    )]
    Closed {
        /// The closed contact.
        contact: String,
    },
    /// The relabelling does not put the mechanism where it was.
    #[error(
        "`relabel` does not put the mechanism where it was: {what} differs by {difference:.3e} (relative); each coordinate after the change must describe the same configuration about the landing foot, and the bodies must carry the whole kinetic energy"
    )]
    Relabel {
        /// What differs: "the centre of mass" or "the mass matrix of the bodies".
        what: &'static str,
        /// By how much, relative.
        difference: f64,
    },
}

/// Applies the change of support whose values at `q` are `s` ([`SupportValues::of`]) at
/// `(t, y)` (`y = [q; q̇]` just before the strike), with
/// the contact's coefficient of restitution `restitution` (which must be 0: the foot sticks)
/// and its sticking cone's `friction` (`μ_s`; 0: the foot's sticking is not checked).
///
/// # Errors
/// [`SupportError`] where the model's assumptions fail (see the module documentation).
pub fn change_support(
    model: &dyn ModelInfo,
    s: &SupportValues,
    (t, y): (f64, &[f64]),
    (restitution, friction): (f64, f64),
) -> Result<SupportChange, SupportError> {
    let n = model.num_dofs();
    if restitution != 0.0 {
        return Err(SupportError::NotPlastic { restitution });
    }
    check_relabel(model, t, s)?;
    let before = DVector::from_row_slice(&y[n..2 * n]);
    let finite = |v: &DVector<f64>| v.iter().all(|x| x.is_finite());
    let after = (s.mass_matrix_after.clone().lu())
        .solve(&(&s.h * &before))
        .filter(finite)
        .ok_or(SupportError::Singular)?;
    // `Λ = K(q⁺) q̇⁺ − K(q) q̇⁻`, along `n̂` and `t̂`.
    let impulse = &s.momentum_jacobian_after * &after - &s.momentum_jacobian * &before;
    let (normal, tangent) = (s.normal, s.tangent());
    let normal_impulse = normal[0] * impulse[0] + normal[1] * impulse[1];
    let tangential_impulse = tangent[0] * impulse[0] + tangent[1] * impulse[1];
    if normal_impulse <= 0.0 {
        return Err(SupportError::Pulls { normal_impulse });
    }
    let needed = tangential_impulse.abs() / normal_impulse;
    if friction > 0.0 && needed > friction {
        return Err(SupportError::Slips { needed, friction });
    }
    // The old stance foot's velocity after, `−F v`, `v` the speeds in the old coordinates.
    let old = (s.relabel_jacobian.clone().lu())
        .solve(&after)
        .filter(finite)
        .ok_or(SupportError::Singular)?;
    let release = &s.foot_jacobian * &old;
    let release_velocity = -(normal[0] * release[0] + normal[1] * release[1]);
    let landing = &s.foot_jacobian * &before;
    let speeds = release.norm().max(landing.norm());
    if release_velocity < -RELEASE_TOLERANCE * speeds {
        return Err(SupportError::StanceStays { release_velocity });
    }
    let q_after: Vec<f64> = s.relabel.iter().copied().collect();
    let qdot_after: Vec<f64> = after.iter().copied().collect();
    let state: Vec<f64> = q_after.iter().chain(&qdot_after).copied().collect();
    Ok(SupportChange {
        energy_lost: model.kinetic_energy(t, y) - model.kinetic_energy(t, &state),
        q: q_after,
        qdot: qdot_after,
        normal_impulse,
        tangential_impulse,
        release_velocity,
        foot: s.foot,
    })
}

/// Checks that `R` puts the mechanism where it was about the new stance foot: its first
/// moment of mass `Σ mᵢ rᵢ` becomes `Σ mᵢ rᵢ − m r_S` (the landing foot of the new labels
/// need not be the old stance foot: a rimless wheel's next spoke is another), and the mass
/// matrix the bodies give about the new foot is the model's at `R(q)`, entry by entry
/// relative to `√(M_ii M_jj)`, so that a body of small mass is checked too.
fn check_relabel(model: &dyn ModelInfo, t: f64, s: &SupportValues) -> Result<(), SupportError> {
    let q: Vec<f64> = s.relabel.iter().copied().collect();
    let length = s.size();
    let moment = [0, 1].map(|a| s.moment_after[a] - (s.moment[a] - s.mass * s.foot[a]));
    let difference = moment[0].hypot(moment[1]) / (s.mass * length);
    if difference.is_nan() || difference > RELABEL_TOLERANCE {
        return Err(SupportError::Relabel {
            what: "the centre of mass",
            difference,
        });
    }
    let state: Vec<f64> = q.iter().copied().chain(vec![0.0; q.len()]).collect();
    let (mass_matrix, _) = model.mass_matrix_and_forcing(t, &state);
    let n = q.len();
    let difference = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| {
            let scale = (mass_matrix[(i, i)] * mass_matrix[(j, j)]).abs().sqrt();
            (mass_matrix[(i, j)] - s.mass_matrix_after[(i, j)]).abs() / scale.max(f64::MIN_POSITIVE)
        })
        .fold(0.0f64, |m, d| if d.is_nan() { f64::NAN } else { m.max(d) });
    if difference.is_nan() || difference > RELABEL_TOLERANCE {
        return Err(SupportError::Relabel {
            what: "the mass matrix of the bodies",
            difference,
        });
    }
    Ok(())
}

/// `∂Δ/∂y` (2n × 2n) of the reset `Δ(q, q̇) = (R(q), M(R(q))⁻¹ H(q) q̇)` of the change of
/// support whose values at `q` are `s`, at `y = [q; q̇]` (the state before it), exactly, from
/// the derived derivatives of
/// `M(R(q))` and `H`:
///
/// - `∂q⁺/∂q = ∂R/∂q`, `∂q⁺/∂q̇ = 0`;
/// - `∂q̇⁺/∂q_k = M⁺⁻¹ (∂H/∂q_k q̇ − ∂M⁺/∂q_k q̇⁺)`;
/// - `∂q̇⁺/∂q̇ = M⁺⁻¹ H`.
///
/// `None` where `M(q⁺)` is singular.
pub fn reset_jacobian(s: &SupportValues, y: &[f64]) -> Option<DMatrix<f64>> {
    let n = y.len() / 2;
    let qdot = DVector::from_row_slice(&y[n..2 * n]);
    let lu = s.mass_matrix_after.clone().lu();
    let after = lu.solve(&(&s.h * &qdot))?;
    let mut d = DMatrix::zeros(2 * n, 2 * n);
    d.view_mut((0, 0), (n, n)).copy_from(&s.relabel_jacobian);
    for k in 0..n {
        let rhs = &s.dh[k] * &qdot - &s.dm[k] * &after;
        d.view_mut((n, k), (n, 1)).copy_from(&lu.solve(&rhs)?);
    }
    d.view_mut((n, n), (n, n)).copy_from(&lu.solve(&s.h)?);
    d.iter().all(|x| x.is_finite()).then_some(d)
}
