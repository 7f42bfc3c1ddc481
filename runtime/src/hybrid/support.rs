//! A change of support: the landing foot of a walker (or a rimless wheel's next spoke)
//! strikes, sticks and becomes the stance foot, the old stance foot leaves the ground, and
//! the coordinates are relabelled about the new one.
//!
//! The model is written in minimal coordinates about its stance foot at the origin
//! (`support:` on a contact: `eomgen_symbolic::model::elements::support`, which derives the
//! values used here). With the stance foot freed at `p₀`, the plastic impulse `Λ` at the
//! landing foot `S` gives `M_e (q̇_e⁺ − q̇_e⁻) = J_Sᵀ Λ` with `S` held after it. Eliminating
//! `p₀` (`ṗ₀⁺ = −F q̇⁺`, `F = ∂r_S/∂q`) leaves `P q̇⁺ = Q q̇⁻`:
//!
//! - `P = M − FᵀK − KᵀF + m FᵀF`, the mass matrix about the landing foot;
//! - `Q = M − FᵀK`, the angular momenta about it before the impact;
//! - `Λ = (K − m F) q̇⁺ − K q̇⁻` (`m` the total mass, `K q̇` the linear momentum);
//! - the old stance foot leaves at `ṗ₀⁺ = −F q̇⁺`.
//!
//! Then `q⁺ = R(q)` and `q̇⁺ = (∂R/∂q) v` with `v = P⁻¹ Q q̇⁻`.
//!
//! [`change_support`] applies it and checks what the model assumes: the landing foot pushes
//! (`Λ_N > 0`) and, with friction, sticks (`|Λ_T| ≤ μ Λ_N`); the old foot leaves
//! (`n̂ · ṗ₀⁺ ≥ 0`); and the relabelling puts the mechanism where it was (the centre of mass
//! and its kinetic energy). [`reset_jacobian`] gives `∂Δ/∂y` of the whole reset
//! `Δ(q, q̇) = (R(q), R_q P⁻¹ Q q̇)` from the derivatives of `P`, `Q` and `R`, exactly, for
//! the saltation matrix of a gait's return map.
//!
//! Source: Grizzle, Abba & Plestan, IEEE TAC 46 (2001) 51–64, §III; Westervelt et al.,
//! *Feedback Control of Dynamic Bipedal Robot Locomotion* (2007), §3.4.2; Garcia et al.,
//! J. Biomech. Eng. 120 (1998) 281–288, eq. 4.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::model_info::ModelInfo;

/// How far the relabelling may move the mechanism, relative to the landing foot's distance
/// from the stance foot (and its kinetic energy, relative to itself), before the change of
/// support is refused: rounding, not a wrong `relabel:`.
pub const RELABEL_TOLERANCE: f64 = 1e-8;

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
    /// The landing foot `r_S` (m).
    pub foot: [f64; 2],
    /// `K = ∂(Σ mᵢ rᵢ)/∂q` (2 × n).
    pub momentum_jacobian: DMatrix<f64>,
    /// `F = ∂r_S/∂q` (2 × n).
    pub foot_jacobian: DMatrix<f64>,
    /// `P` (n × n).
    pub p: DMatrix<f64>,
    /// `Q` (n × n).
    pub q: DMatrix<f64>,
    /// `∂P/∂q_k`, one per coordinate.
    pub dp: Vec<DMatrix<f64>>,
    /// `∂Q/∂q_k`.
    pub dq: Vec<DMatrix<f64>>,
    /// `R(q)` (n).
    pub relabel: DVector<f64>,
    /// `∂R/∂q` (n × n).
    pub relabel_jacobian: DMatrix<f64>,
    /// `∂(∂R/∂q)/∂q_k`.
    pub relabel_second: Vec<DMatrix<f64>>,
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
        let mass = take(1)[0];
        let normal = pair(take(2));
        let moment = pair(take(2));
        let foot = pair(take(2));
        let momentum_jacobian = DMatrix::from_row_slice(2, n, take(2 * n));
        let foot_jacobian = DMatrix::from_row_slice(2, n, take(2 * n));
        let p = DMatrix::from_row_slice(n, n, take(n * n));
        let qm = DMatrix::from_row_slice(n, n, take(n * n));
        let matrices = |values: &[f64]| -> Vec<DMatrix<f64>> {
            values
                .chunks(n * n)
                .map(|m| DMatrix::from_row_slice(n, n, m))
                .collect()
        };
        let dp = matrices(take(n * n * n));
        let dq = matrices(take(n * n * n));
        let relabel = DVector::from_row_slice(take(n));
        let relabel_jacobian = DMatrix::from_row_slice(n, n, take(n * n));
        let relabel_second = matrices(take(n * n * n));
        Self {
            mass,
            normal,
            moment,
            foot,
            momentum_jacobian,
            foot_jacobian,
            p,
            q: qm,
            dp,
            dq,
            relabel,
            relabel_jacobian,
            relabel_second,
        }
    }

    /// `t̂`, the normal turned a quarter-turn counter-clockwise.
    fn tangent(&self) -> [f64; 2] {
        [-self.normal[1], self.normal[0]]
    }

    /// `a · r` for a 2-vector `a` and a row pair `rows` (2 × n) times `v`: `a · (rows v)`.
    fn along(a: [f64; 2], rows: &DMatrix<f64>, v: &DVector<f64>) -> f64 {
        let r = rows * v;
        a[0] * r[0] + a[1] * r[1]
    }
}

/// The number of values of one change of support for `n` coordinates (as the symbolic
/// side's `block_len`).
pub fn block_len(n: usize) -> usize {
    7 + 5 * n + 3 * n * n + 3 * n * n * n
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
}

/// Why a change of support has no answer that the model's assumptions allow.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum SupportError {
    /// `P` is singular (a mechanism with no mass about the landing foot).
    #[error("the mass matrix about the landing foot is singular")]
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
        "`relabel` does not put the mechanism where it was: {what} differs by {difference:.3e} (relative); each coordinate after the change must describe the same configuration about the landing foot"
    )]
    Relabel {
        /// What moved: "the centre of mass" or "the kinetic energy".
        what: &'static str,
        /// By how much, relative.
        difference: f64,
    },
}

/// Applies change of support `which` at `(t, y)` (`y = [q; q̇]` just before the strike), with
/// the landing foot's friction coefficient `friction` (0: its sticking is not checked).
///
/// # Errors
/// [`SupportError`] where the model's assumptions fail (see the module documentation).
pub fn change_support(
    model: &dyn ModelInfo,
    which: usize,
    t: f64,
    y: &[f64],
    friction: f64,
) -> Result<SupportChange, SupportError> {
    let n = model.num_dofs();
    let s = SupportValues::of(model, which, t, &y[..n]);
    let before = DVector::from_row_slice(&y[n..2 * n]);
    let v = (s.p.clone().lu())
        .solve(&(&s.q * &before))
        .filter(|v| v.iter().all(|x| x.is_finite()))
        .ok_or(SupportError::Singular)?;
    // `Λ = (K − m F) v − K q̇⁻`, along `n̂` and `t̂`.
    let landing = &s.momentum_jacobian - &s.foot_jacobian * s.mass;
    let impulse = &landing * &v - &s.momentum_jacobian * &before;
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
    let release_velocity = -SupportValues::along(normal, &s.foot_jacobian, &v);
    if release_velocity < 0.0 {
        return Err(SupportError::StanceStays { release_velocity });
    }
    let after_energy = 0.5 * v.dot(&(&s.p * &v));
    let q_after: Vec<f64> = s.relabel.iter().copied().collect();
    let qdot_after: Vec<f64> = (&s.relabel_jacobian * &v).iter().copied().collect();
    check_relabel(model, which, t, &s, (&q_after, &qdot_after), after_energy)?;
    let before_energy = model.kinetic_energy(t, y);
    Ok(SupportChange {
        q: q_after,
        qdot: qdot_after,
        normal_impulse,
        tangential_impulse,
        release_velocity,
        energy_lost: before_energy - after_energy,
    })
}

/// Checks that `R` puts the mechanism where it was about the new stance foot: its first
/// moment of mass `Σ mᵢ rᵢ` becomes `Σ mᵢ rᵢ − m r_S`, and its kinetic energy is the same
/// in the new coordinates. (The landing foot of the new labels need not be the old stance
/// foot: a rimless wheel's next spoke is another.)
fn check_relabel(
    model: &dyn ModelInfo,
    which: usize,
    t: f64,
    s: &SupportValues,
    (q, qdot): (&[f64], &[f64]),
    energy: f64,
) -> Result<(), SupportError> {
    let after = SupportValues::of(model, which, t, q);
    let length = s.foot[0].hypot(s.foot[1]).max(f64::MIN_POSITIVE);
    let moment = [0, 1].map(|a| after.moment[a] - (s.moment[a] - s.mass * s.foot[a]));
    let difference = moment[0].hypot(moment[1]) / (s.mass * length);
    if difference.is_nan() || difference > RELABEL_TOLERANCE {
        return Err(SupportError::Relabel {
            what: "the centre of mass",
            difference,
        });
    }
    let state: Vec<f64> = q.iter().chain(qdot).copied().collect();
    let kinetic = model.kinetic_energy(t, &state);
    let difference = (kinetic - energy).abs() / energy.abs().max(f64::MIN_POSITIVE);
    if (difference.is_nan() || difference > RELABEL_TOLERANCE)
        && (kinetic - energy).abs() > f64::EPSILON
    {
        return Err(SupportError::Relabel {
            what: "the kinetic energy",
            difference,
        });
    }
    Ok(())
}

/// `∂Δ/∂y` (2n × 2n) of the reset `Δ(q, q̇) = (R(q), R_q(q) P(q)⁻¹ Q(q) q̇)` of change of
/// support `which` at `(t, y)` (the state before it), exactly, from the derived derivatives
/// of `P`, `Q` and `R`:
///
/// - `∂q⁺/∂q = R_q`, `∂q⁺/∂q̇ = 0`;
/// - `∂q̇⁺/∂q_k = (∂R_q/∂q_k) v + R_q P⁻¹ (∂Q/∂q_k q̇ − ∂P/∂q_k v)`, `v = P⁻¹ Q q̇`;
/// - `∂q̇⁺/∂q̇ = R_q P⁻¹ Q`.
///
/// `None` where `P` is singular.
pub fn reset_jacobian(
    model: &dyn ModelInfo,
    which: usize,
    t: f64,
    y: &[f64],
) -> Option<DMatrix<f64>> {
    let n = model.num_dofs();
    let s = SupportValues::of(model, which, t, &y[..n]);
    let qdot = DVector::from_row_slice(&y[n..2 * n]);
    let lu = s.p.clone().lu();
    let v = lu.solve(&(&s.q * &qdot))?;
    let mut d = DMatrix::zeros(2 * n, 2 * n);
    d.view_mut((0, 0), (n, n)).copy_from(&s.relabel_jacobian);
    for k in 0..n {
        let rhs = &s.dq[k] * &qdot - &s.dp[k] * &v;
        let dv = lu.solve(&rhs)?;
        let column = &s.relabel_second[k] * &v + &s.relabel_jacobian * dv;
        d.view_mut((n, k), (n, 1)).copy_from(&column);
    }
    let pq = lu.solve(&s.q)?;
    d.view_mut((n, n), (n, n))
        .copy_from(&(&s.relabel_jacobian * pq));
    d.iter().all(|x| x.is_finite()).then_some(d)
}
