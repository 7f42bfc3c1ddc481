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
//! The impact is followed in impulse space (Routh's method): with `W` the inverse mass seen
//! through the held constraints (`M w = D + Aᵀ λ`, `A w = 0`, one KKT solve by [`lu_solve`]
//! per row), the velocities are linear in the impulses, and the normal impulse `p` grows from
//! 0 while the contact slides against its slip (`dΛ_T = ∓μ dp`), sticks once the slip stops
//! (if the cone holds the tangential impulse that sticking needs, else the slip reverses),
//! until Newton's law `G_N q̇ = −e G_N q̇⁻` is met. For one contact without friction or held
//! constraints this is `Λ_N = −(1 + e) G_N q̇⁻ / (G_N M⁻¹ G_Nᵀ)`, and the kinetic energy lost
//! `½ (1 − e²) (G_N q̇⁻)² / (G_N M⁻¹ G_Nᵀ) ≥ 0`.
//!
//! Newton's kinematic restitution with friction can still be inconsistent (Stronge 2000, §4):
//! the normal velocity may not grow with the normal impulse (a Painlevé-type case), or the
//! impact may add kinetic energy. Each is returned as an error, never as a result. One case
//! has an answer: where the slip stops and sticking fixes the normal velocity as well (the
//! normal row depends on the tangent row through the held constraints), with the cone wide
//! enough to hold, friction locks the contact and the impact ends there ([`ImpactMode::Jammed`]:
//! the velocities after it are those at the end of the compression, the restitution lost).
//! Where the slip stops with the contact still closing (the held rows move), no impulse opens
//! it, and the impact is refused ([`ImpactError::Pulling`] in the sticking phase).
//!
//! Whether a rate is 0 (the held rows fix a velocity, sticking fixes the normal one) is
//! decided against an estimate of the KKT solves' error, not the rounding of the products
//! alone, and an impact whose impulses are so large that the solves' error decides the speeds
//! after it is refused ([`ImpactError::IllConditioned`]): near a locked contact the impulses
//! grow without bound, and a result there would be rounding.
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

/// How many times its estimated error (the correction of one step of iterative refinement,
/// [`response`]) a rate must exceed to count as non-zero: the estimate gives the error's
/// order, not a bound.
const SOLVE_MARGIN: f64 = 10.0;

/// The relative error of the speeds after an impact, estimated from the responses' errors
/// and the impulses (`Λ_N |δw_N| + |Λ_T| |δw_T|` against the largest speed), above which the
/// impact is refused ([`ImpactError::IllConditioned`]): near a locked contact the impulses grow
/// without bound while their product with the responses stays of the order of the speeds, and
/// the responses' rounding then decides the result.
const ACCURACY: f64 = 1e-6;

/// The largest normal velocity, relative to the one before the impact, that a contact locked
/// by friction ([`ImpactMode::Jammed`]) may keep: in exact arithmetic it is the velocity of
/// the held rows along the normal, zero on a consistent state, so what is left is their drift
/// (the integration's tolerance, 1e-8 of the approach on a rod held to `atol` 1e-10). Above
/// it the locked contact would still be closing, and the impact is refused.
const LOCKED: f64 = 1e-6;

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
    /// The friction coefficient `μ ≥ 0`, with which the contact slides.
    pub coefficient: f64,
    /// The static coefficient `μ_s ≥ μ`: once its slip stops, the contact sticks if the
    /// tangential impulse sticking needs is within `μ_s` times the normal one.
    pub static_coefficient: f64,
    /// `v_s`, the speed of the surface's material along the tangent (a belt's; 0 for a
    /// fixed surface): the contact slips at `v_t = G_T q̇ − v_s` (m/s).
    pub surface_velocity: f64,
}

impl ContactFriction<'_> {
    /// The slip `v_t = G_T q̇ − v_s` at speeds `qdot`.
    fn slip(&self, qdot: &[f64]) -> f64 {
        dot(self.tangent, qdot) - self.surface_velocity
    }
}

/// How the contact behaved in the impact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ImpactMode {
    /// No friction at the contact.
    Frictionless,
    /// The tangential velocity ends at 0 (from the start, or once the slip stopped), with the
    /// tangential impulse inside the cone all along.
    Sticking,
    /// The contact slides one way through the impact, `|Λ_T| = μ Λ_N`.
    Sliding,
    /// The slip stops during the impact and, the cone being too narrow to hold it, starts
    /// again the other way.
    Reversing,
    /// The slip stops during the compression where sticking also fixes the normal velocity
    /// (the contact's normal row depends on its tangent row through the constraints that
    /// hold: a bob on a rod, one freedom), and the cone holds it: friction locks the contact
    /// (the impulse that sticks it lies along the rod, at `θ` from the normal, inside the
    /// cone for `μ ≥ tan θ`), no pushing impulse can open it, and the impact ends there,
    /// closed and sticking. The restitution Newton's law asks for is lost: `G_N q̇⁺ = 0`, not
    /// `−e G_N q̇⁻`. (With `e = 0` the compression's end is the impact's end anyway, and the
    /// impact is listed by how it slid or stuck on the way.)
    Jammed,
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
    /// The slips `G_T q̇⁻ − v_s` and `G_T q̇⁺ − v_s` before and after (0 without friction).
    pub tangential_velocity: [f64; 2],
    /// `½ q̇ᵀ M q̇` before and after (J).
    pub kinetic_energy: [f64; 2],
    /// The kinetic energy lost, `T⁻ − T⁺ ≥ 0` (J).
    pub energy_lost: f64,
}

/// Why an impact could not be computed.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
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
    /// No pushing normal impulse meets Newton's law: the normal velocity does not grow
    /// with the normal impulse in the contact's mode (with friction, a Painlevé-type
    /// inconsistency).
    #[error(
        "no pushing normal impulse meets Newton's law in the {mode:?} phase (normal velocity {normal_velocity} m/s, growing at {rate} per unit impulse)"
    )]
    Pulling {
        /// `G_N q̇` where it stops growing.
        normal_velocity: f64,
        /// `d(G_N q̇)/dΛ_N` in that phase (≤ 0).
        rate: f64,
        /// The phase.
        mode: ImpactMode,
    },
    /// The impulses are so large against the accuracy of the impact's equations that
    /// rounding decides the speeds after it: near a contact that friction locks while it is
    /// still closing, or equations near singular.
    #[error(
        "the impact's equations are too ill-conditioned for its impulses: the speeds after it are uncertain by {uncertainty} against speeds of {speed}"
    )]
    IllConditioned {
        /// The estimated error of the largest speed after the impact.
        uncertainty: f64,
        /// The largest speed before or after it.
        speed: f64,
    },
    /// The impact would add kinetic energy beyond the work of the moving surfaces and
    /// constraints (kinematic restitution with friction can).
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
/// # Errors
/// [`ImpactError`]: wrong lengths, NaN or infinite inputs, `e ∉ [0, 1]`, `μ < 0`, a contact
/// that is not closing, singular equations, and the inconsistencies of kinematic restitution
/// with friction (no pushing normal impulse, a gain of energy), and equations too
/// ill-conditioned for the impulses they need (their error would decide the speeds after).
pub fn impact(
    mass_matrix: &[f64],
    qdot: &[f64],
    contact: &ImpactContact<'_>,
    holding: &[f64],
) -> Result<ImpactReport, ImpactError> {
    check_inputs(mass_matrix, qdot, contact, holding)?;
    let normal_before = dot(contact.normal, qdot);
    if normal_before >= 0.0 {
        return Err(ImpactError::NotApproaching {
            normal_velocity: normal_before,
        });
    }
    let n = qdot.len();
    let held: Vec<&[f64]> = holding.chunks_exact(n).collect();
    let normal = response(mass_matrix, &held, contact.normal)?;
    let tangent = match &contact.friction {
        Some(f) => Some((f, response(mass_matrix, &held, f.tangent)?)),
        None => None,
    };
    let target = -contact.restitution * normal_before;
    let process = match &tangent {
        None => {
            let rate = Rate::of(contact.normal, &normal);
            if !rate.is_positive() {
                // The held rows fix the normal velocity.
                return Err(ImpactError::Singular);
            }
            let normal_impulse =
                phase_to_target(normal_before, rate, target, ImpactMode::Frictionless)?;
            Process {
                mode: ImpactMode::Frictionless,
                normal_impulse,
                tangential_impulse: 0.0,
            }
        }
        Some((f, t)) => {
            let rates = Rates {
                nn: Rate::of(contact.normal, &normal),
                nt: Rate::of(contact.normal, t),
                tt: Rate::of(f.tangent, t),
            };
            routh(
                (normal_before, f.slip(qdot), target),
                (f.coefficient, f.static_coefficient.max(f.coefficient)),
                rates,
            )?
        }
    };
    let (p, q) = (process.normal_impulse, process.tangential_impulse);
    let tangent = tangent.as_ref().map(|(_, t)| (q, t));
    let (after, held_impulses) = apply_impulses(qdot, (p, &normal), tangent);
    check_accuracy(qdot, &after, (p, &normal), tangent)?;
    let kinetic_energy = [
        kinetic_energy(mass_matrix, qdot),
        kinetic_energy(mass_matrix, &after),
    ];
    // The work the moving parts do: a belt's (`Λ_T v_s`) and the held rows' that move
    // (`Λ_A · A q̇`, which the impact keeps); the rest of `T⁺ − T⁻` is the impact's own, never
    // a gain (`½ Λ·(v⁻ + v⁺)` on the contact's own slip and normal speed).
    let supplied = match &contact.friction {
        Some(f) => q * f.surface_velocity,
        None => 0.0,
    } + (held.iter().zip(&held_impulses))
        .map(|(row, impulse)| impulse * dot(row, qdot))
        .sum::<f64>();
    if kinetic_energy[1] - supplied > kinetic_energy[0] * (1.0 + ROUNDING) {
        return Err(ImpactError::EnergyGain {
            before: kinetic_energy[0],
            after: kinetic_energy[1],
        });
    }
    let tangential_velocity = match &contact.friction {
        Some(f) => [f.slip(qdot), f.slip(&after)],
        None => [0.0, 0.0],
    };
    Ok(ImpactReport {
        normal_velocity: [normal_before, dot(contact.normal, &after)],
        qdot: after,
        mode: process.mode,
        normal_impulse: p,
        tangential_impulse: q,
        holding_impulses: held_impulses,
        tangential_velocity,
        energy_lost: kinetic_energy[0] - kinetic_energy[1],
        kinetic_energy,
    })
}

/// The speeds after the impulses `p` along the normal and `q` along the tangent (with their
/// responses), `q̇⁻ + w_N p + w_T q`, and the impulses of the held rows, `Λ_A`.
fn apply_impulses(
    qdot: &[f64],
    (p, normal): (f64, &Response),
    tangent: Option<(f64, &Response)>,
) -> (Vec<f64>, Vec<f64>) {
    let mut after = qdot.to_vec();
    let mut held_impulses: Vec<f64> = normal.held.iter().map(|l| l * p).collect();
    for (v, w) in after.iter_mut().zip(&normal.velocity) {
        *v += w * p;
    }
    if let Some((q, t)) = tangent {
        for (v, w) in after.iter_mut().zip(&t.velocity) {
            *v += w * q;
        }
        for (h, l) in held_impulses.iter_mut().zip(&t.held) {
            *h += l * q;
        }
    }
    (after, held_impulses)
}

/// Whether the speeds after an impact, `after`, are known to [`ACCURACY`] of the speeds: the
/// error the responses' solves leave in them, `Λ_N |δw_N| + |Λ_T| |δw_T|`, against the largest
/// speed before or after.
///
/// # Errors
/// [`ImpactError::IllConditioned`] where they are not.
fn check_accuracy(
    qdot: &[f64],
    after: &[f64],
    (p, normal): (f64, &Response),
    tangent: Option<(f64, &Response)>,
) -> Result<(), ImpactError> {
    let uncertainty = (0..qdot.len())
        .map(|i| p.abs() * normal.error[i] + tangent.map_or(0.0, |(q, t)| q.abs() * t.error[i]))
        .fold(0.0, f64::max);
    let speed = qdot
        .iter()
        .chain(after)
        .fold(0.0, |m: f64, v| m.max(v.abs()));
    if uncertainty <= ACCURACY * speed {
        Ok(())
    } else {
        Err(ImpactError::IllConditioned { uncertainty, speed })
    }
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

/// The response to a unit generalized impulse along a row `D`: the change of speeds
/// `w = W Dᵀ`, an estimate of each speed's error `|δw|`, and the impulses of the held rows.
struct Response {
    velocity: Vec<f64>,
    error: Vec<f64>,
    held: Vec<f64>,
}

/// [`Response`] to `direction`: `M w − Aᵀ λ = Dᵀ`, `A w = 0`.
///
/// The error estimate is the correction of one step of iterative refinement: the residual
/// `r = K x − b` of the solution, in `f64`, solved by the same matrix, `|K⁻¹ r|`. It is of the
/// order of the forward error (about `κ(K) ε |x|`; Higham, *Accuracy and Stability of
/// Numerical Algorithms*, 2nd ed., 2002, §12.1), which the rounding of the products alone
/// (`ε Σ |Gᵢ wᵢ|`) understates by the condition number: on a contact with one free direction
/// left by three held rows (`κ ≈ 3·10⁴`), sticking's normal rate, 0 in exact arithmetic, came
/// out above the rounding of its products and was taken for a positive one.
fn response(
    mass_matrix: &[f64],
    held: &[&[f64]],
    direction: &[f64],
) -> Result<Response, ImpactError> {
    let n = direction.len();
    let k = n + held.len();
    let mut matrix = vec![0.0; k * k];
    let mut rhs = vec![0.0; k];
    for r in 0..n {
        for c in 0..n {
            matrix[r * k + c] = mass_matrix[r + c * n];
        }
        rhs[r] = direction[r];
    }
    for (j, row) in held.iter().enumerate() {
        for (i, &a) in row.iter().enumerate() {
            matrix[i * k + n + j] = -a;
            matrix[(n + j) * k + i] = a;
        }
    }
    let (original, b) = (matrix.clone(), rhs.clone());
    let mut pivots = vec![0; k];
    lu_solve(&mut matrix, &mut rhs, &mut pivots, k).ok_or(ImpactError::Singular)?;
    if rhs.iter().any(|v| !v.is_finite()) {
        return Err(ImpactError::Singular);
    }
    // The refinement's correction, solved by a fresh copy (`lu_solve` keeps no factors; `k`
    // is a handful of rows, and an impact is an event, not a step).
    let mut error: Vec<f64> = (0..k)
        .map(|r| dot(&original[r * k..(r + 1) * k], &rhs) - b[r])
        .collect();
    let mut matrix = original;
    lu_solve(&mut matrix, &mut error, &mut pivots, k).ok_or(ImpactError::Singular)?;
    error.truncate(n);
    error.iter_mut().for_each(|e| *e = e.abs());
    if error.iter().any(|v| !v.is_finite()) {
        return Err(ImpactError::Singular);
    }
    let held = rhs.split_off(n);
    Ok(Response {
        velocity: rhs,
        error,
        held,
    })
}

/// A velocity's change per unit impulse, `G W Dᵀ`, with the size of the products it sums
/// (`Σ |Gᵢ wᵢ|`) and the error the response's solve leaves in it (`Σ |Gᵢ| |δwᵢ|`), against
/// which a rate that rounding left near 0 is told from a true one.
#[derive(Debug, Clone, Copy)]
struct Rate {
    value: f64,
    size: f64,
    error: f64,
}

impl Rate {
    /// `row · w`.
    fn of(row: &[f64], w: &Response) -> Self {
        Self {
            value: dot(row, &w.velocity),
            size: row
                .iter()
                .zip(&w.velocity)
                .map(|(a, b)| (a * b).abs())
                .sum(),
            error: row.iter().zip(&w.error).map(|(a, e)| a.abs() * e).sum(),
        }
    }

    /// What rounding may leave of a rate that is 0: [`ROUNDING`] of its products, and
    /// [`SOLVE_MARGIN`] times the solve's estimated error.
    fn uncertainty(self) -> f64 {
        ROUNDING * self.size + SOLVE_MARGIN * self.error
    }

    /// Whether it is positive beyond rounding (false for NaN).
    fn is_positive(self) -> bool {
        self.value > self.uncertainty()
    }

    /// Whether it is 0 to rounding.
    fn is_zero(self) -> bool {
        self.value.abs() <= self.uncertainty()
    }

    /// `self + k · other`, `k` exact.
    fn plus(self, k: f64, other: Rate) -> Self {
        Self {
            value: self.value + k * other.value,
            size: self.size + k.abs() * other.size,
            error: self.error + k.abs() * other.error,
        }
    }
}

/// How the normal and tangential velocities change per unit impulse: `G_N W G_Nᵀ`,
/// `G_N W G_Tᵀ` (= `G_T W G_Nᵀ`) and `G_T W G_Tᵀ`.
#[derive(Debug, Clone, Copy)]
struct Rates {
    nn: Rate,
    nt: Rate,
    tt: Rate,
}

/// The impulses of the whole impact and how it ended.
struct Process {
    mode: ImpactMode,
    normal_impulse: f64,
    tangential_impulse: f64,
}

/// The normal impulse that takes the normal velocity from `from` to `target` at `rate` per
/// unit impulse.
///
/// # Errors
/// [`ImpactError::Pulling`] where the rate is not positive beyond rounding.
fn phase_to_target(
    from: f64,
    rate: Rate,
    target: f64,
    mode: ImpactMode,
) -> Result<f64, ImpactError> {
    if !rate.is_positive() {
        return Err(ImpactError::Pulling {
            normal_velocity: from,
            rate: rate.value,
            mode,
        });
    }
    Ok((target - from) / rate.value)
}

/// Routh's process in impulse space for a contact with friction `mu` (`μ`, and `μ_s ≥ μ` for
/// sticking): from the normal and tangential velocities `v_n < 0` and `v_t`, the normal
/// impulse `p` grows until the normal velocity reaches `target` (Newton's law). While the
/// contact slips (`v_t ≠ 0`), friction opposes it, `dΛ_T = −sign(v_t) μ dp`; when the slip
/// stops it sticks, if `|G_T W G_Nᵀ| ≤ μ_s G_T W G_Tᵀ` (the tangential impulse sticking needs
/// lies in the static cone), else it slips again the other way.
///
/// # Errors
/// [`ImpactError::Pulling`] where the normal velocity does not grow in the phase that must
/// reach the target; [`ImpactError::Singular`] where sticking needs `G_T W G_Tᵀ = 0`.
fn routh(
    (v_n, v_t, target): (f64, f64, f64),
    (mu, mu_static): (f64, f64),
    a: Rates,
) -> Result<Process, ImpactError> {
    let (mut p, mut q, mut normal) = (0.0, 0.0, v_n);
    if v_t != 0.0 {
        let s = -v_t.signum() * mu;
        let (normal_rate, tangent_rate) = (a.nn.plus(s, a.nt), a.nt.plus(s, a.tt));
        // The impulse at which the slip stops, if it does.
        let stops = if tangent_rate.value * v_t < 0.0 {
            -v_t / tangent_rate.value
        } else {
            f64::INFINITY
        };
        let to_target = phase_to_target(v_n, normal_rate, target, ImpactMode::Sliding);
        match to_target {
            Ok(done) if done <= stops => {
                return Ok(Process {
                    mode: ImpactMode::Sliding,
                    normal_impulse: done,
                    tangential_impulse: s * done,
                });
            }
            Err(error) if stops.is_infinite() => return Err(error),
            _ => {}
        }
        p = stops;
        q = s * stops;
        normal = v_n + normal_rate.value * stops;
        if normal >= target {
            // The slip stops where the target is met (rounding).
            return Ok(Process {
                mode: ImpactMode::Sticking,
                normal_impulse: p,
                tangential_impulse: q,
            });
        }
    }
    if !a.tt.is_positive() {
        return Err(ImpactError::Singular);
    }
    // The tangential impulse per unit normal impulse that keeps the slip at 0.
    let ratio = -a.nt.value / a.tt.value;
    let (mode, slope) = if ratio.abs() <= mu_static {
        (ImpactMode::Sticking, ratio)
    } else {
        // Slipping in the direction the normal impulse drives it, friction against it.
        (ImpactMode::Reversing, -a.nt.value.signum() * mu)
    };
    let mode = if mode == ImpactMode::Reversing && v_t == 0.0 {
        ImpactMode::Sliding
    } else {
        mode
    };
    let mut rate = a.nn.plus(slope, a.nt);
    if mode == ImpactMode::Sticking {
        // The ratio's own error: `nn − nt²/tt` moves by `δnn + 2 |ratio| δnt + ratio² δtt` in
        // all, of which `plus` counted `δnn + |ratio| δnt`.
        rate.error += ratio.abs() * a.nt.error + ratio * ratio * a.tt.error;
    }
    if mode == ImpactMode::Sticking && rate.is_zero() && normal.abs() <= LOCKED * v_n.abs() {
        // Sticking fixes the normal velocity, at the end of the compression (to the held
        // rows' drift): friction locks the contact, and no impulse opens it.
        return Ok(Process {
            mode: ImpactMode::Jammed,
            normal_impulse: p,
            tangential_impulse: q,
        });
    }
    let more = phase_to_target(normal, rate, target, mode)?;
    Ok(Process {
        mode,
        normal_impulse: p + more,
        tangential_impulse: q + slope * more,
    })
}
