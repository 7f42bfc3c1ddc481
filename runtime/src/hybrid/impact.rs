//! The impact law at one striking unilateral contact: Newton's restitution on its normal,
//! Coulomb friction on its tangent (sticking, or sliding on the cone's edge), and the
//! constraints that hold through the impact.
//!
//! With `n` generalized speeds, mass matrix `M(q)`, the contact's normal row `G_N = ∂g/∂q`,
//! its tangent row `G_T` (the tangential velocity `v_T = G_T q̇`) and the rows `A` of the
//! constraints that hold (holonomic and non-holonomic constraints, contacts already closed),
//! the velocities jump at fixed `q` by
//!
//! ```text
//! M (q̇⁺ − q̇⁻) = G_Nᵀ Λ_N + G_Tᵀ Λ_T + Aᵀ Λ_A
//! G_N q̇⁺ = −e G_N q̇⁻          (Newton's restitution, 0 ≤ e ≤ 1)
//! A q̇⁺ = A q̇⁻                  (the constraints hold)
//! sticking: G_T q̇⁺ = 0, |Λ_T| ≤ μ Λ_N;  else sliding: Λ_T = ±μ Λ_N
//! ```
//!
//! solved as one linear system (the impact's KKT matrix) by [`lu_solve`]. For one contact
//! without friction or held constraints this is `Λ_N = −(1 + e) G_N q̇⁻ / (G_N M⁻¹ G_Nᵀ)`, and
//! the kinetic energy lost `½ (1 − e²) (G_N q̇⁻)² / (G_N M⁻¹ G_Nᵀ) ≥ 0`.
//!
//! A sliding impact keeps the direction of the sticking impulse that the cone could not
//! supply (against the slip before the impact where the contact cannot stick at all). Newton's kinematic restitution with friction can be inconsistent (Stronge 2000,
//! §4): the slip can stop or reverse during the impact, the normal impulse can turn negative,
//! or the energy can grow. Each is returned as an error, never as a result.
//!
//! # References
//! - E. T. Whittaker, *Analytical Dynamics*, 4th ed., 1937, §94 (impulsive motion in
//!   generalized coordinates).
//! - F. Pfeiffer, C. Glocker, *Multibody Dynamics with Unilateral Contacts*, Wiley, 1996, §7.
//! - W. J. Stronge, *Impact Mechanics*, Cambridge University Press, 2000, §§3–5.

use serde::Serialize;

use crate::constrained::lu_solve;

/// Relative size below which a kinetic energy gained, an opposite normal impulse or a
/// reversed slip counts as rounding: about 100 rounding units of the quantities it compares
/// (the KKT solve loses a few digits to its condition number).
const ROUNDING: f64 = 1e-12;

/// The striking contact of an impact.
#[derive(Debug, Clone, Copy)]
pub struct ImpactContact<'a> {
    /// `G_N = ∂g/∂q`, the gradient of the gap (`n` entries): `G_N q̇` is the normal velocity
    /// (m/s for a gap in m), negative when the contact closes.
    pub normal: &'a [f64],
    /// Newton's coefficient of restitution `e ∈ [0, 1]`: `G_N q̇⁺ = −e G_N q̇⁻` (0: plastic).
    pub restitution: f64,
    /// Coulomb friction on one tangent direction, or `None` for a frictionless contact.
    pub friction: Option<ContactFriction<'a>>,
}

/// Coulomb friction at a contact, along one tangent direction (a planar contact).
#[derive(Debug, Clone, Copy)]
pub struct ContactFriction<'a> {
    /// `G_T` (`n` entries): `G_T q̇` is the tangential velocity of the contact point.
    pub tangent: &'a [f64],
    /// The friction coefficient `μ ≥ 0`.
    pub coefficient: f64,
}

/// How the contact behaved in the impact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ImpactMode {
    /// No friction at the contact.
    Frictionless,
    /// The tangential velocity ends at 0, with `|Λ_T| ≤ μ Λ_N`.
    Sticking,
    /// The contact slides through the impact, `|Λ_T| = μ Λ_N`.
    Sliding,
}

/// The velocities after an impact, its impulses and the energy it took.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImpactReport {
    /// `q̇⁺`, the generalized speeds after the impact (`n` entries).
    pub qdot: Vec<f64>,
    /// How the contact behaved.
    pub mode: ImpactMode,
    /// `Λ_N ≥ 0`, the normal impulse (N·s for a gap in m).
    pub normal_impulse: f64,
    /// `Λ_T`, the tangential impulse (0 without friction).
    pub tangential_impulse: f64,
    /// `Λ_A`, the impulses of the constraints that hold (one per row).
    pub holding_impulses: Vec<f64>,
    /// `G_N q̇⁻` and `G_N q̇⁺`, the normal velocity before and after.
    pub normal_velocity: [f64; 2],
    /// `G_T q̇⁻` and `G_T q̇⁺`, the tangential velocity before and after (0 without friction).
    pub tangential_velocity: [f64; 2],
    /// `½ q̇ᵀ M q̇` before and after (J).
    pub kinetic_energy: [f64; 2],
    /// The kinetic energy lost, `T⁻ − T⁺ ≥ 0` (J).
    pub energy_lost: f64,
}

/// Why an impact could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImpactError {
    /// A slice has the wrong length.
    #[error("{what} has {found} entries, expected {expected}")]
    Dimensions {
        /// Which input.
        what: &'static str,
        /// Its length.
        found: usize,
        /// The length it must have.
        expected: usize,
    },
    /// An input is NaN or infinite.
    #[error("{what} is not finite")]
    NonFinite {
        /// Which input.
        what: &'static str,
    },
    /// The restitution is outside `[0, 1]`.
    #[error("the coefficient of restitution must lie in [0, 1], found {value}")]
    Restitution {
        /// The value given.
        value: f64,
    },
    /// The friction coefficient is negative.
    #[error("the friction coefficient must be at least 0, found {value}")]
    Friction {
        /// The value given.
        value: f64,
    },
    /// The contact does not close: `G_N q̇⁻ ≥ 0`.
    #[error(
        "the contact is not closing: its normal velocity is {normal_velocity} (an impact needs < 0)"
    )]
    NotApproaching {
        /// `G_N q̇⁻`.
        normal_velocity: f64,
    },
    /// The impact's KKT matrix is singular: the contact's rows depend on the constraints
    /// that hold, or `M` is singular on the motions they allow.
    #[error(
        "the impact equations are singular: the contact's normal or tangent depends on the constraints that hold, or the mass matrix is singular"
    )]
    Singular,
    /// The normal impulse would pull (`Λ_N < 0`): no consistent impact with this contact
    /// mode (with friction, a Painlevé-type inconsistency).
    #[error("the normal impulse would pull ({normal_impulse}) in the {mode:?} impact")]
    Pulling {
        /// `Λ_N`.
        normal_impulse: f64,
        /// The mode tried.
        mode: ImpactMode,
    },
    /// The slip would stop or reverse during a sliding impact, where kinematic restitution
    /// with friction has no consistent solution of one sliding direction.
    #[error(
        "the slip reverses during the impact (tangential velocity {before} → {after} against the friction impulse {impulse})"
    )]
    SlipReversal {
        /// `G_T q̇⁻`.
        before: f64,
        /// `G_T q̇⁺`.
        after: f64,
        /// `Λ_T`.
        impulse: f64,
    },
    /// The impact would add kinetic energy (kinematic restitution with friction can).
    #[error("the impact would gain kinetic energy: {before} J → {after} J")]
    EnergyGain {
        /// `T⁻` (J).
        before: f64,
        /// `T⁺` (J).
        after: f64,
    },
}

/// The impact at `contact` of a system with mass matrix `mass_matrix` (`n × n`,
/// column-major), speeds `qdot` (`q̇⁻`, `n` entries) and the constraints that hold through
/// it, `holding` (`r × n`, row-major, the rows `A` of their velocity form: holonomic and
/// non-holonomic constraints and contacts already closed). See the module's equations.
///
/// With friction the sticking impact is tried first; where its tangential impulse leaves the
/// cone `|Λ_T| ≤ μ Λ_N`, the sliding impact on the cone's edge in the same direction.
///
/// # Errors
/// [`ImpactError`]: wrong lengths, NaN or infinite inputs, `e ∉ [0, 1]`, `μ < 0`, a contact
/// that is not closing, singular equations, and the inconsistencies of kinematic restitution
/// with friction (a pulling normal impulse, a reversing slip, a gain of energy).
pub fn impact(
    mass_matrix: &[f64],
    qdot: &[f64],
    contact: &ImpactContact<'_>,
    holding: &[f64],
) -> Result<ImpactReport, ImpactError> {
    let n = qdot.len();
    check_inputs(mass_matrix, qdot, contact, holding)?;
    let normal_before = dot(contact.normal, qdot);
    if normal_before >= 0.0 {
        return Err(ImpactError::NotApproaching {
            normal_velocity: normal_before,
        });
    }
    let holding: Vec<&[f64]> = if n == 0 {
        Vec::new()
    } else {
        holding.chunks_exact(n).collect()
    };
    let kkt = Kkt {
        mass_matrix,
        qdot,
        normal: contact.normal,
        normal_target: -contact.restitution * normal_before,
        holding: &holding,
    };
    let Outcome {
        mode,
        qdot: after,
        normal_impulse,
        tangential_impulse,
        held,
    } = match contact.friction {
        None => {
            let (after, impulses) = kkt.solve(None)?;
            Outcome {
                mode: ImpactMode::Frictionless,
                qdot: after,
                normal_impulse: impulses[0],
                tangential_impulse: 0.0,
                held: impulses[1..].to_vec(),
            }
        }
        Some(friction) => kkt.frictional(&friction)?,
    };
    if normal_impulse < 0.0 {
        return Err(ImpactError::Pulling {
            normal_impulse,
            mode,
        });
    }
    let tangential_velocity = match contact.friction {
        Some(f) => [dot(f.tangent, qdot), dot(f.tangent, &after)],
        None => [0.0, 0.0],
    };
    // Sliding, the friction impulse opposes the slip: a final tangential velocity along it
    // means the slip stopped or reversed within the impact.
    let [v_before, v_after] = tangential_velocity;
    let slip_scale = v_before.abs() + normal_before.abs();
    if mode == ImpactMode::Sliding
        && v_after * tangential_impulse > ROUNDING * slip_scale * tangential_impulse.abs()
    {
        return Err(ImpactError::SlipReversal {
            before: v_before,
            after: v_after,
            impulse: tangential_impulse,
        });
    }
    let kinetic_energy = [
        kinetic_energy(mass_matrix, qdot),
        kinetic_energy(mass_matrix, &after),
    ];
    if kinetic_energy[1] > kinetic_energy[0] * (1.0 + ROUNDING) {
        return Err(ImpactError::EnergyGain {
            before: kinetic_energy[0],
            after: kinetic_energy[1],
        });
    }
    Ok(ImpactReport {
        normal_velocity: [normal_before, dot(contact.normal, &after)],
        qdot: after,
        mode,
        normal_impulse,
        tangential_impulse,
        holding_impulses: held,
        tangential_velocity,
        energy_lost: kinetic_energy[0] - kinetic_energy[1],
        kinetic_energy,
    })
}

/// The lengths and values of [`impact`]'s inputs.
fn check_inputs(
    mass_matrix: &[f64],
    qdot: &[f64],
    contact: &ImpactContact<'_>,
    holding: &[f64],
) -> Result<(), ImpactError> {
    let n = qdot.len();
    let length = |what, found: usize, expected| {
        if found == expected {
            Ok(())
        } else {
            Err(ImpactError::Dimensions {
                what,
                found,
                expected,
            })
        }
    };
    length("the mass matrix", mass_matrix.len(), n * n)?;
    length("the contact's normal", contact.normal.len(), n)?;
    if let Some(f) = &contact.friction {
        length("the contact's tangent", f.tangent.len(), n)?;
    }
    let rows = holding.len().checked_div(n).unwrap_or(0);
    length("the rows that hold", holding.len(), rows * n)?;
    let finite = |what, values: &[f64]| {
        if values.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(ImpactError::NonFinite { what })
        }
    };
    finite("the mass matrix", mass_matrix)?;
    finite("the speeds", qdot)?;
    finite("the contact's normal", contact.normal)?;
    finite("the rows that hold", holding)?;
    let e = contact.restitution;
    if !(0.0..=1.0).contains(&e) {
        return Err(ImpactError::Restitution { value: e });
    }
    if let Some(f) = &contact.friction {
        finite("the contact's tangent", f.tangent)?;
        if !(f.coefficient >= 0.0 && f.coefficient.is_finite()) {
            return Err(ImpactError::Friction {
                value: f.coefficient,
            });
        }
    }
    Ok(())
}

/// `a · b`.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `½ vᵀ M v` for `M` column-major.
fn kinetic_energy(mass_matrix: &[f64], v: &[f64]) -> f64 {
    let n = v.len();
    let quadratic: f64 = v
        .iter()
        .enumerate()
        .map(|(c, vc)| vc * dot(&mass_matrix[c * n..(c + 1) * n], v))
        .sum();
    0.5 * quadratic
}

/// The tangent row of a frictional impact.
enum Tangent<'a> {
    /// `G_T q̇⁺ = 0`, with its own impulse.
    Sticking(&'a [f64]),
    /// No tangent row; the normal impulse acts along `G_N + slope · G_T` (`slope = ±μ`).
    Sliding(&'a [f64], f64),
}

/// What an impact's equations gave: the mode, `q̇⁺` and the impulses.
struct Outcome {
    mode: ImpactMode,
    qdot: Vec<f64>,
    normal_impulse: f64,
    tangential_impulse: f64,
    /// `Λ_A`.
    held: Vec<f64>,
}

/// The impact's equations without their tangent row.
struct Kkt<'a> {
    mass_matrix: &'a [f64],
    qdot: &'a [f64],
    normal: &'a [f64],
    /// `−e G_N q̇⁻`.
    normal_target: f64,
    holding: &'a [&'a [f64]],
}

impl Kkt<'_> {
    /// The impact with `friction`: sticking if its tangential impulse lies in the cone, else
    /// sliding on the cone's edge in the direction of the sticking impulse that it could not
    /// supply; where the contact cannot stick (its tangent velocity is set by the other rows,
    /// so that the sticking equations are singular), against the slip before the impact.
    fn frictional(&self, friction: &ContactFriction<'_>) -> Result<Outcome, ImpactError> {
        let sticking = self.solve(Some(Tangent::Sticking(friction.tangent))).ok();
        if let Some((after, impulses)) = &sticking
            && impulses[1].abs() <= friction.coefficient * impulses[0]
        {
            return Ok(Outcome {
                mode: ImpactMode::Sticking,
                qdot: after.clone(),
                normal_impulse: impulses[0],
                tangential_impulse: impulses[1],
                held: impulses[2..].to_vec(),
            });
        }
        let direction = match &sticking {
            Some((_, impulses)) => impulses[1],
            None => -dot(friction.tangent, self.qdot),
        };
        if direction == 0.0 {
            return Err(ImpactError::Singular);
        }
        let slope = direction.signum() * friction.coefficient;
        let (after, impulses) = self.solve(Some(Tangent::Sliding(friction.tangent, slope)))?;
        Ok(Outcome {
            mode: ImpactMode::Sliding,
            qdot: after,
            normal_impulse: impulses[0],
            tangential_impulse: slope * impulses[0],
            held: impulses[1..].to_vec(),
        })
    }

    /// `q̇⁺` and the impulses: `Λ_N`, then `Λ_T` if sticking, then `Λ_A`; from
    /// `M q̇⁺ − Σ Dⱼᵀ Λⱼ = M q̇⁻`, `Wⱼ q̇⁺ = wⱼ`, with `Dⱼ` the direction of impulse `j` and
    /// `Wⱼ` its velocity row (equal but for the sliding normal).
    fn solve(&self, tangent: Option<Tangent<'_>>) -> Result<(Vec<f64>, Vec<f64>), ImpactError> {
        let n = self.qdot.len();
        let mut normal_direction = self.normal.to_vec();
        if let Some(Tangent::Sliding(t, slope)) = &tangent {
            for (d, ti) in normal_direction.iter_mut().zip(t.iter()) {
                *d += slope * ti;
            }
        }
        // (direction, velocity row, target).
        let mut rows: Vec<(&[f64], &[f64], f64)> =
            vec![(&normal_direction, self.normal, self.normal_target)];
        if let Some(Tangent::Sticking(t)) = tangent {
            rows.push((t, t, 0.0));
        }
        for row in self.holding {
            rows.push((row, row, dot(row, self.qdot)));
        }
        let k = n + rows.len();
        let mut matrix = vec![0.0; k * k];
        let mut rhs = vec![0.0; k];
        for r in 0..n {
            for c in 0..n {
                matrix[r * k + c] = self.mass_matrix[r + c * n];
            }
            rhs[r] = (0..n)
                .map(|c| self.mass_matrix[r + c * n] * self.qdot[c])
                .sum();
        }
        for (j, (direction, velocity, target)) in rows.iter().enumerate() {
            for i in 0..n {
                matrix[i * k + n + j] = -direction[i];
                matrix[(n + j) * k + i] = velocity[i];
            }
            rhs[n + j] = *target;
        }
        let mut pivots = vec![0; k];
        lu_solve(&mut matrix, &mut rhs, &mut pivots, k).ok_or(ImpactError::Singular)?;
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(ImpactError::Singular);
        }
        let impulses = rhs.split_off(n);
        Ok((rhs, impulses))
    }
}
