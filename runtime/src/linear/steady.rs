//! Steady motions and their linearisation, with or without constraints (holonomic and
//! non-holonomic): a spinning body, a precessing top, a sleigh, disc or bicycle moving
//! straight at constant speed, or a coin or bicycle in a steady turn
//! ([`crate::linear::turning`]). The search for one ([`find_steady_motion_with`]) is a room
//! of its own, `steady/search.rs`.
//!
//! A *steady motion* holds every rate `q̇*` constant (`q̈ = 0`) while the coordinates that
//! nothing depends on — *ignorable* (cyclic) coordinates: heading, wheel angles, contact
//! position, spin angle — drift at their rates and the others stay put. It is an operating
//! point of the equations of motion, not an equilibrium. [`find_steady_motion`] finds the
//! coordinates of one from a guess with the rates held (Gauss–Newton); an equilibrium is the
//! case `q̇* = 0`.
//!
//! [`linearize_steady_motion`] linearises the first-order equations `ẏ = f(y)`, `y = (q, q̇)`
//! about it and restricts them to the motions the constraints allow, in the manner of the
//! partition of Peterson, Gede & Hubbard ("Symbolic linearization of equations of motion of
//! constrained multibody systems", *Multibody System Dynamics* 33:143–161, 2015,
//! doi:10.1007/s11044-014-9436-5), done numerically:
//!
//! 1. `A = ∂f/∂y` (`2n × 2n`): exact from the generated Jacobians for an unconstrained model,
//!    else by central differences with one Richardson extrapolation (error `O(h⁴)`, about
//!    `1e-11` relative).
//! 2. The tangent space of the constraints at the point: `Φ_q δq = 0` for the holonomic
//!    constraints and `V_q δq + J δq̇ = 0` for every velocity-level constraint `V = J q̇ + b`
//!    (the holonomic ones differentiated, and the non-holonomic ones). Dependent coordinates
//!    are chosen among the non-ignorable ones by pivoting on `Φ_q`, dependent rates by
//!    pivoting on `J` (the rates of the dependent coordinates first, then those of the
//!    ignorable ones: a contact point's rates and the heading rate are outputs of the motion).
//!    The independent coordinates and rates parametrise the tangent space: `δy = N z`,
//!    `δq_d = C₀ δq_i` and `δq̇_d = C₁ δq + C₂ δq̇_i` as in the paper — the `C₁ δq` term, which
//!    makes the dependent rates answer a change of configuration at a speed `q̇* ≠ 0`, is the
//!    one a hand linearisation most often drops.
//! 3. The space is invariant under the linearised flow (the equations keep the constraints'
//!    second derivatives at zero), so `A N = N A_z` with `A_z = S A N`, `S` picking the
//!    independent entries of `δy`: `A_z` is the state matrix of the constrained motion, and
//!    has its eigenvalues.
//! 4. Ignorable coordinates are left out: their columns must vanish in every other row (a
//!    located error names the row otherwise), so that they only integrate the rest, and each
//!    carries an exact zero eigenvalue. Then every remaining row that is zero — a rate that
//!    stays constant to first order, as the bicycle's forward speed — is left out with its
//!    column: another exact zero eigenvalue. What remains is the reduced state matrix whose
//!    eigenvalues decide the stability; what was left out is reported.

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

use super::eigenvalues::{Stability, ZERO_EIGENVALUE, ZERO_REAL_PART, verdict};
mod search;

pub use search::{find_steady_motion, find_steady_motion_with};

use super::turning::TurningFrame;
use crate::model_info::ModelInfo;
use crate::ode::RhsError;

/// Why a steady motion or its linearisation could not be found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SteadyMotionError {
    /// Gauss–Newton did not bring the accelerations and constraint residuals to zero with
    /// the rates held.
    #[error(
        "no steady motion found with the rates held: after {iterations} Gauss–Newton iterations the largest residual is {residual:e} ({worst})"
    )]
    NotSteady {
        /// Iterations made.
        iterations: usize,
        /// Largest residual left (an acceleration, or a constraint residual).
        residual: f64,
        /// What it is: `theta_ddot`, or a constraint's name.
        worst: String,
    },
    /// The holonomic constraints do not determine dependent coordinates at the point (`Φ_q`
    /// has rank below `m_h`).
    #[error(
        "the holonomic constraints are singular at the operating point: their Jacobian Φ_q has rank {found}, below their number {needed}"
    )]
    SingularConstraints {
        /// Holonomic constraints.
        needed: usize,
        /// Independent columns found.
        found: usize,
    },
    /// The velocity constraints do not determine dependent rates at the point.
    #[error(
        "the velocity constraints are singular at the operating point: {found} of {needed} dependent rates found"
    )]
    SingularVelocityConstraints {
        /// Velocity-level constraints.
        needed: usize,
        /// Independent columns found.
        found: usize,
    },
    /// A coordinate declared ignorable moves something else at the point.
    #[error(
        "`{coordinate}` is declared ignorable, but the linearised `{state}` depends on it (entry {value:e} of the state matrix)"
    )]
    NotIgnorable {
        /// The coordinate.
        coordinate: String,
        /// The state whose rate depends on it.
        state: String,
        /// The entry.
        value: f64,
    },
    /// A rate is held for a coordinate not declared ignorable: the coordinate moves, and
    /// unless nothing depends on it the state is an instant of a motion, not a steady one
    /// (a pendulum at the bottom of its swing).
    #[error(
        "the rate `{coordinate}_dot` = {rate} is held, but `{coordinate}` is not declared ignorable: a steady motion moves only cyclic coordinates; list `{coordinate}` in the entry's `ignorable:` if nothing depends on it, else this state is an instant of a motion, not a steady one"
    )]
    HeldRateNotIgnorable {
        /// The coordinate.
        coordinate: String,
        /// Its held rate.
        rate: f64,
    },
    /// A coordinate that moves in the steady motion (declared ignorable, with a held rate)
    /// is not cyclic: the equations change as it moves, so the motion is not steady and its
    /// linearisation at one instant says nothing of its stability.
    #[error(
        "`{coordinate}` moves in the steady motion (`{coordinate}_dot` = {rate}) and is declared ignorable, but {part} depends on it (relative change {change:.1e} when it moves by {shift} from the steady motion or a state near it): a steady motion moves only cyclic coordinates"
    )]
    NotCyclic {
        /// The coordinate.
        coordinate: String,
        /// Its held rate.
        rate: f64,
        /// What depends on it: the mass matrix, the forces, a constraint.
        part: String,
        /// The largest relative change found.
        change: f64,
        /// The shift of the coordinate where it was found.
        shift: f64,
    },
    /// The model is in generalized speeds: steady motions hold rates of the coordinates,
    /// which its state does not have.
    #[error(
        "steady motions hold coordinates' rates, and a model in generalized speeds has its speeds in the state instead: find its steady motions in the coordinates' rates (remove `speeds`)"
    )]
    InSpeeds,
    /// A steady turn's equations are not symmetric under turning: the accelerations at the
    /// state turned about the plane's normal are not the turned accelerations, so the turn
    /// changes the equations and is no steady motion.
    #[error(
        "the steady turn turns `{plane_a}` and `{plane_b}` with `{angle}`, but the equations are not symmetric under turning: at the state turned by {shift} rad the accelerations differ from the turned ones by {change:.1e} (relative to the largest); a steady turn needs forces that turn with the motion, with nothing fixed to the ground's directions, and `plane` in the order that a positive `{angle}` turns `{plane_a}` toward `{plane_b}`"
    )]
    NotSymmetric {
        /// The turning angle.
        angle: String,
        /// The first plane coordinate.
        plane_a: String,
        /// The second plane coordinate.
        plane_b: String,
        /// The relative difference found.
        change: f64,
        /// The angle turned by where it was found (rad).
        shift: f64,
    },
    /// The search came to a point where the equations cannot be evaluated, and no step
    /// around it reduces the residual: the steady motion the guess leads to lies at (or
    /// beyond) a singularity, most often of the coordinates (Euler angles at `θ = 0`).
    #[error(
        "no steady motion found with the rates held: the search was stopped near {at}, where the equations cannot be evaluated ({source}); the motion it was heading for may lie at a singularity of the coordinates, so start from a guess nearer the one wanted"
    )]
    Unevaluable {
        /// The free coordinates of the last point refused, `name = value, …`.
        at: String,
        /// Why the equations failed there.
        source: RhsError,
    },
    /// What the steady motion holds names a coordinate the model does not have (an index
    /// past its `n` coordinates, from a spec built by hand).
    #[error("the steady motion's spec names coordinate {index}, but the model has {n}")]
    SpecOutOfRange {
        /// The index given.
        index: usize,
        /// The model's number of coordinates.
        n: usize,
    },
    /// The right-hand side failed at (or near) the point.
    #[error("the equations cannot be evaluated at the operating point: {0}")]
    Rhs(#[from] RhsError),
    /// A derivative came out not finite.
    #[error("the linearisation is not finite at the operating point")]
    NonFinite,
    /// The eigenvalue solver (bounded: [`crate::linalg::eigenvalues`]) did not converge on
    /// the reduced state matrix.
    #[error("the eigenvalue solver did not converge on the {size} × {size} reduced state matrix")]
    EigenvaluesDidNotConverge {
        /// The matrix's order.
        size: usize,
    },
}

/// What a steady motion holds and what its search finds (an entry of the file's
/// `equilibria:` that holds rates).
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct SteadyMotionSpec {
    /// The rates `q̇*` held (length `n`); those of [`Self::solved_rates`] are the search's
    /// starting guesses instead.
    pub rates: Vec<f64>,
    /// The coordinates nothing depends on (indices): they may move, and the linearisation
    /// leaves them out.
    pub ignorable: Vec<usize>,
    /// Coordinates held at their guess (indices) where the search would find them (a
    /// bicycle's lean, whose turn's speed is then found).
    pub held_coordinates: Vec<usize>,
    /// Coordinates whose rates the search finds (indices) where it would hold them (rates
    /// fixed by rolling constraints, such as a front wheel's in a turn).
    pub solved_rates: Vec<usize>,
    /// The frame of a steady turn: the rates of two coordinates constant in it, not in the
    /// ground.
    pub turning: Option<TurningFrame>,
}

impl SteadyMotionSpec {
    /// Checks that every index of the spec is one of `n` coordinates.
    ///
    /// # Errors
    /// [`SteadyMotionError::SpecOutOfRange`] for the first that is not.
    pub fn check(&self, n: usize) -> Result<(), SteadyMotionError> {
        let turning = (self.turning.iter()).flat_map(|f| [f.angle, f.plane[0], f.plane[1]]);
        let all = (self.ignorable.iter().chain(&self.held_coordinates))
            .chain(&self.solved_rates)
            .copied()
            .chain(turning);
        match all.into_iter().find(|&i| i >= n) {
            Some(index) => Err(SteadyMotionError::SpecOutOfRange { index, n }),
            None => Ok(()),
        }
    }

    /// The spec that holds `rates` (length `n`), with the coordinates `ignorable`: every other
    /// coordinate found, every rate held, no turn.
    pub fn holding(rates: &[f64], ignorable: &[usize]) -> Self {
        Self {
            rates: rates.to_vec(),
            ignorable: ignorable.to_vec(),
            ..Self::default()
        }
    }

    /// The entries of `y = (q, q̇)` (length `2n`) the search finds: the coordinates neither
    /// ignorable nor held, then the solved rates (`n + i`).
    pub fn unknowns(&self, n: usize) -> Vec<usize> {
        (0..n)
            .filter(|i| !self.ignorable.contains(i) && !self.held_coordinates.contains(i))
            .chain(self.solved_rates.iter().map(|i| n + i))
            .collect()
    }
}

/// A steady motion: coordinates `q*` and rates `q̇*` at which `q̈ = 0` (in a steady turn,
/// the plane's `q̈` is the turn's `Ω S q̇`) and the constraints hold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SteadyMotion {
    /// `q*` (length `n`).
    pub q: Vec<f64>,
    /// `q̇*` (length `n`): as held, and as found for the rates the search finds.
    pub qdot: Vec<f64>,
    /// Gauss–Newton iterations.
    pub iterations: usize,
    /// The largest `|q̈ᵢ|`, `|Φᵢ|` or velocity residual left.
    pub residual: f64,
}

impl SteadyMotion {
    /// `y* = (q*, q̇*)` (length `2n`).
    pub fn state(&self) -> Vec<f64> {
        self.q.iter().chain(&self.qdot).copied().collect()
    }
}

/// The linearisation of a model about a steady motion, restricted to the motions its
/// constraints allow and reduced by its ignorable coordinates and constant rates.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SteadyLinearization {
    /// The reduced state's entries by name: coordinates (`theta`) and rates (`theta_dot`),
    /// `k` of them.
    pub states: Vec<String>,
    /// The reduced state matrix `A` (`k × k`, 1/s), rows in JSON: `δż = A δz`.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub state_matrix: DMatrix<f64>,
    /// Coordinates solved from the holonomic constraints (left out of the state).
    pub dependent_coordinates: Vec<String>,
    /// Rates solved from the velocity constraints (left out of the state).
    pub dependent_rates: Vec<String>,
    /// Ignorable coordinates left out (each an exact zero eigenvalue).
    pub ignorable_coordinates: Vec<String>,
    /// Rates left out because they stay constant to first order (a zero row of the state
    /// matrix; each an exact zero eigenvalue).
    pub constant_rates: Vec<String>,
    /// Whether `∂f/∂y` came from the exact generated Jacobians (else central differences
    /// with Richardson extrapolation).
    pub exact_jacobian: bool,
}

/// Linearises `model` about the steady motion `y* = (q*, q̇*)` (length `2n`) at time `t`,
/// leaving out the coordinates `ignorable` (indices); see the module documentation for the
/// method.
///
/// # Errors
/// [`SteadyMotionError::SingularConstraints`] or
/// [`SteadyMotionError::SingularVelocityConstraints`] when the constraints do not determine
/// dependent coordinates or rates there; [`SteadyMotionError::NotIgnorable`] when an
/// ignorable coordinate feeds back; [`SteadyMotionError::Rhs`] and
/// [`SteadyMotionError::NonFinite`] when the equations fail there.
pub fn linearize_steady_motion(
    model: &mut dyn ModelInfo,
    t: f64,
    y: &[f64],
    ignorable: &[usize],
) -> Result<SteadyLinearization, SteadyMotionError> {
    linearize_steady_motion_with(model, t, y, &SteadyMotionSpec::holding(&[], ignorable))
}

/// Linearises `model` about the steady motion `y* = (q*, q̇*)` (length `2n`) of `spec` at
/// time `t`, leaving out its ignorable coordinates; for a steady turn, in the turning frame
/// ([`crate::linear::turning`]). See the module documentation for the method.
///
/// # Errors
/// As [`linearize_steady_motion`]; [`SteadyMotionError::InSpeeds`] for a model in generalized
/// speeds.
pub fn linearize_steady_motion_with(
    model: &mut dyn ModelInfo,
    t: f64,
    y: &[f64],
    spec: &SteadyMotionSpec,
) -> Result<SteadyLinearization, SteadyMotionError> {
    if model.description().has_speeds() {
        return Err(SteadyMotionError::InSpeeds);
    }
    let ignorable = spec.ignorable.as_slice();
    spec.check(y.len() / 2)?;
    let d = model.description().clone();
    let n = d.coordinates.len();
    let (m, m_h) = (d.constraints.len(), d.holonomic_constraints);
    let (a, exact_jacobian) = state_jacobian(model, t, y)?;
    let jacobians = ConstraintJacobians::at(model, t, y, n, m, m_h)?;
    let split = Partition::choose(&jacobians, ignorable, n, m_h, m)?;
    // The basis N of the tangent space, one column per independent coordinate and rate.
    let basis = split.tangent_basis(&jacobians, n, m_h, m)?;
    let Partition {
        dependent_q,
        dependent_u,
        independent_q,
        independent_u,
    } = split;
    let k = independent_q.len() + independent_u.len();
    let rows: Vec<usize> = independent_q
        .iter()
        .copied()
        .chain(independent_u.iter().map(|j| n + j))
        .collect();
    let mut reduced = match &spec.turning {
        None => {
            let a_basis = &a * &basis;
            DMatrix::from_fn(k, k, |r, c| a_basis[(rows[r], c)])
        }
        Some(frame) => turning_reduced(frame, &a, &basis, y, &rows)?,
    };
    if reduced.iter().any(|v| !v.is_finite()) {
        return Err(SteadyMotionError::NonFinite);
    }
    let mut names: Vec<String> = independent_q
        .iter()
        .map(|&i| d.coordinates[i].to_string())
        .chain(
            independent_u
                .iter()
                .map(|&j| format!("{}_dot", d.coordinates[j])),
        )
        .collect();
    // Entries below this fraction of the largest are zero: rounding of exact Jacobians, or
    // the differences' (central differences of a function even in the varied entry cancel
    // to rounding, so a structurally zero entry comes out near `1e-13` of the largest). Kept
    // small, so that a rate that changes slowly (a sleigh at a speed of 1e-9 m/s) is not
    // taken for a constant one.
    let zero = if exact_jacobian { 1e-13 } else { 1e-10 } * reduced.amax().max(f64::MIN_POSITIVE);
    let ignorable_coordinates =
        remove_ignorable_states(&mut reduced, &mut names, &independent_q, ignorable, zero)?;
    let constant_rates = remove_constant_rates(&mut reduced, &mut names, zero);
    Ok(SteadyLinearization {
        states: names,
        state_matrix: reduced,
        dependent_coordinates: dependent_q
            .iter()
            .map(|&i| d.coordinates[i].to_string())
            .collect(),
        dependent_rates: dependent_u
            .iter()
            .map(|&i| format!("{}_dot", d.coordinates[i]))
            .collect(),
        ignorable_coordinates,
        constant_rates,
        exact_jacobian,
    })
}

/// The reduced state matrix of a steady turn (`k × k`): `P A_z N_z (P N_z)⁻¹`, with `A_z`
/// and `N_z = T⁻¹ N` the state matrix `a` and the tangent basis `basis` (`2n × k`) taken
/// to the turning frame at `y` ([`TurningFrame::state_matrix`]) and `P` picking the state
/// entries `rows`: the linearised flow in the independent entries `P δz` of the turning
/// frame's state (`δz = N_z w` with `w` the independent entries of `δy`, so
/// `P δz = (P N_z) w`). `P N_z = I` unless the plane's rates are independent states.
fn turning_reduced(
    frame: &TurningFrame,
    a: &DMatrix<f64>,
    basis: &DMatrix<f64>,
    y: &[f64],
    rows: &[usize],
) -> Result<DMatrix<f64>, SteadyMotionError> {
    let k = rows.len();
    let (a_z, t_inverse) = frame.state_matrix(a, y);
    let basis_z = t_inverse * basis;
    let a_basis = a_z * &basis_z;
    let picked = DMatrix::from_fn(k, k, |r, c| basis_z[(rows[r], c)]);
    let moved = DMatrix::from_fn(k, k, |r, c| a_basis[(rows[r], c)]);
    // moved · picked⁻¹, as (picked⁻ᵀ movedᵀ)ᵀ.
    let solved = (picked.transpose().lu())
        .solve(&moved.transpose())
        .ok_or(SteadyMotionError::NonFinite)?;
    Ok(solved.transpose())
}

/// The constraint Jacobians of [`linearize_steady_motion`] at the operating point:
/// `Φ_q` (`m_h × n`, the first `m_h` rows of `J`), `J` (`m × n`) and `V_q` (`m × n`).
struct ConstraintJacobians {
    /// `Φ_q` (`m_h × n`).
    phi_q: DMatrix<f64>,
    /// `J` (`m × n`), the velocity constraints' Jacobian with respect to `q̇`.
    j_all: DMatrix<f64>,
    /// `V_q` (`m × n`), by Richardson-extrapolated differences of the velocity residuals.
    v_q: DMatrix<f64>,
}

impl ConstraintJacobians {
    /// `Φ_q`, `J` and `V_q` of `model` at `(t, y)` (`y` of length `2n`; `m` constraints,
    /// `m_h` of them holonomic); empty (`0 × n`) when there are no constraints.
    fn at(
        model: &mut dyn ModelInfo,
        t: f64,
        y: &[f64],
        n: usize,
        m: usize,
        m_h: usize,
    ) -> Result<Self, SteadyMotionError> {
        // Constraint Jacobians at the point: Φ_q (the first m_h rows of J), J, and V_q by
        // differences of the velocity residuals.
        let (j_all, v_q) = if m > 0 {
            let c = model.constraint_equations(t, y);
            let v_q = richardson(n, m, y, |yy| {
                Ok(model
                    .constraint_equations(t, yy)
                    .velocity
                    .as_slice()
                    .to_vec())
            })?;
            (c.jacobian, v_q)
        } else {
            (DMatrix::zeros(0, n), DMatrix::zeros(0, n))
        };
        let phi_q = j_all.rows(0, m_h).into_owned();
        Ok(Self { phi_q, j_all, v_q })
    }
}

/// The partition of [`linearize_steady_motion`]: coordinate and rate indices (into `0..n`)
/// that the constraints make dependent, and the independent ones left.
struct Partition {
    /// Coordinates solved from the holonomic constraints (`m_h` of them).
    dependent_q: Vec<usize>,
    /// Rates solved from the velocity constraints (`m` of them).
    dependent_u: Vec<usize>,
    /// The other coordinates, ascending.
    independent_q: Vec<usize>,
    /// The other rates, ascending.
    independent_u: Vec<usize>,
}

impl Partition {
    /// Chooses the dependent coordinates and rates by pivoting on `Φ_q` and `J`.
    ///
    /// # Errors
    /// [`SteadyMotionError::SingularConstraints`] or
    /// [`SteadyMotionError::SingularVelocityConstraints`] when too few independent columns
    /// are found.
    fn choose(
        jacobians: &ConstraintJacobians,
        ignorable: &[usize],
        n: usize,
        m_h: usize,
        m: usize,
    ) -> Result<Self, SteadyMotionError> {
        // Dependent coordinates among the non-ignorable ones first, then the ignorable ones (a
        // belt `phi1 = phi2` between two pulleys that both turn freely names only ignorable
        // coordinates; one of them is then dependent, and leaves the ignorable states), dependent
        // rates preferring the dependent coordinates' rates and then the ignorable ones'.
        let coordinate_order: Vec<usize> = (0..n)
            .filter(|i| !ignorable.contains(i))
            .chain(ignorable.iter().copied())
            .collect();
        let dependent_q = pivot_columns(&jacobians.phi_q, &coordinate_order, m_h);
        if dependent_q.len() < m_h {
            return Err(SteadyMotionError::SingularConstraints {
                needed: m_h,
                found: dependent_q.len(),
            });
        }
        let mut rate_order: Vec<usize> = dependent_q.clone();
        for i in ignorable.iter().copied().chain(0..n) {
            if !rate_order.contains(&i) {
                rate_order.push(i);
            }
        }
        let dependent_u = pivot_columns(&jacobians.j_all, &rate_order, m);
        if dependent_u.len() < m {
            return Err(SteadyMotionError::SingularVelocityConstraints {
                needed: m,
                found: dependent_u.len(),
            });
        }
        let independent_q: Vec<usize> = (0..n).filter(|i| !dependent_q.contains(i)).collect();
        let independent_u: Vec<usize> = (0..n).filter(|i| !dependent_u.contains(i)).collect();
        Ok(Self {
            dependent_q,
            dependent_u,
            independent_q,
            independent_u,
        })
    }

    /// The basis `N` of the constraints' tangent space (`2n × k`, `k` the independent
    /// coordinates and rates): `δy = N z`, one column per independent coordinate, then one per
    /// independent rate.
    fn tangent_basis(
        &self,
        jacobians: &ConstraintJacobians,
        n: usize,
        m_h: usize,
        m: usize,
    ) -> Result<DMatrix<f64>, SteadyMotionError> {
        let ConstraintJacobians { phi_q, j_all, v_q } = jacobians;
        let (dependent_q, dependent_u) = (&self.dependent_q, &self.dependent_u);
        let (independent_q, independent_u) = (&self.independent_q, &self.independent_u);
        let phi_d = select_columns(phi_q, dependent_q);
        let j_d = select_columns(j_all, dependent_u);
        let phi_lu = phi_d.lu();
        let j_lu = j_d.lu();
        let k = independent_q.len() + independent_u.len();
        let mut basis = DMatrix::zeros(2 * n, k);
        for (col, &i) in independent_q.iter().enumerate() {
            let mut dq = DVector::zeros(n);
            dq[i] = 1.0;
            if m_h > 0 {
                let dd = phi_lu
                    .solve(&phi_q.column(i).into_owned())
                    .ok_or(SteadyMotionError::NonFinite)?;
                for (r, &c) in dependent_q.iter().enumerate() {
                    dq[c] = -dd[r];
                }
            }
            if m > 0 {
                let rhs = v_q * &dq;
                let du = j_lu.solve(&rhs).ok_or(SteadyMotionError::NonFinite)?;
                for (r, &c) in dependent_u.iter().enumerate() {
                    basis[(n + c, col)] = -du[r];
                }
            }
            basis.view_mut((0, col), (n, 1)).copy_from(&dq);
        }
        for (offset, &j) in independent_u.iter().enumerate() {
            let col = independent_q.len() + offset;
            basis[(n + j, col)] = 1.0;
            if m > 0 {
                let du = j_lu
                    .solve(&j_all.column(j).into_owned())
                    .ok_or(SteadyMotionError::NonFinite)?;
                for (r, &c) in dependent_u.iter().enumerate() {
                    basis[(n + c, col)] = -du[r];
                }
            }
        }
        Ok(basis)
    }
}

/// Leaves the ignorable coordinates among the states `names` of the reduced state matrix
/// `reduced` (`k × k`) out, rows and columns, and returns their names; entries at most
/// `zero` count as zero.
///
/// # Errors
/// [`SteadyMotionError::NotIgnorable`] when an ignorable coordinate's column does not vanish
/// outside the ignorable coordinates' rows.
fn remove_ignorable_states(
    reduced: &mut DMatrix<f64>,
    names: &mut Vec<String>,
    independent_q: &[usize],
    ignorable: &[usize],
    zero: f64,
) -> Result<Vec<String>, SteadyMotionError> {
    let k = names.len();
    // Ignorable coordinates: their columns must vanish outside their own rows.
    let ignorable_states: Vec<usize> = (0..independent_q.len())
        .filter(|&s| ignorable.contains(&independent_q[s]))
        .collect();
    for &s in &ignorable_states {
        for r in 0..k {
            if !ignorable_states.contains(&r) && reduced[(r, s)].abs() > zero {
                return Err(SteadyMotionError::NotIgnorable {
                    coordinate: names[s].clone(),
                    state: names[r].clone(),
                    value: reduced[(r, s)],
                });
            }
        }
    }
    let ignorable_coordinates: Vec<String> =
        ignorable_states.iter().map(|&s| names[s].clone()).collect();
    remove_states(reduced, names, &ignorable_states);
    Ok(ignorable_coordinates)
}

/// Leaves out of `reduced` (square, its states `names`) every rate whose row is zero
/// (entries at most `zero`), one at a time with its column, and returns their names.
fn remove_constant_rates(
    reduced: &mut DMatrix<f64>,
    names: &mut Vec<String>,
    zero: f64,
) -> Vec<String> {
    // Rates that stay constant: zero rows, left out with their columns, one at a time.
    let mut constant_rates = Vec::new();
    while let Some(r) = (0..names.len())
        .find(|&r| names[r].ends_with("_dot") && reduced.row(r).iter().all(|v| v.abs() <= zero))
    {
        constant_rates.push(names[r].clone());
        remove_states(reduced, names, &[r]);
    }
    constant_rates
}

/// `∂f/∂y` of the first-order equations at `y` (`2n × 2n`) and whether it is exact.
fn state_jacobian(
    model: &mut dyn ModelInfo,
    t: f64,
    y: &[f64],
) -> Result<(DMatrix<f64>, bool), SteadyMotionError> {
    let dim = y.len();
    let mut jac = vec![0.0; dim * dim];
    if model.as_ode_mut().jacobian(t, y, &mut jac)? {
        let a = DMatrix::from_column_slice(dim, dim, &jac);
        if a.iter().all(|v| v.is_finite()) {
            return Ok((a, true));
        }
        return Err(SteadyMotionError::NonFinite);
    }
    let system = model.as_ode_mut();
    let a = richardson(dim, dim, y, |yy| {
        let mut dy = vec![0.0; dim];
        system.rhs(t, yy, &mut dy)?;
        Ok(dy)
    })?;
    Ok((a, false))
}

/// `∂g/∂y` (`rows × cols`, `cols` the leading entries of `y` that are varied) of `g` by
/// central differences with one Richardson extrapolation: `(4 D(h/2) − D(h))/3`, with
/// `h = 1e-3 max(1, |yⱼ|)` (error `O(h⁴)` against rounding `ε/h`: about `1e-11` relative).
fn richardson(
    cols: usize,
    rows: usize,
    y: &[f64],
    mut g: impl FnMut(&[f64]) -> Result<Vec<f64>, RhsError>,
) -> Result<DMatrix<f64>, SteadyMotionError> {
    let mut out = DMatrix::zeros(rows, cols);
    for j in 0..cols {
        let h = 1e-3 * y[j].abs().max(1.0);
        let mut central = |h: f64| -> Result<Vec<f64>, RhsError> {
            let (mut up, mut down) = (y.to_vec(), y.to_vec());
            up[j] += h;
            down[j] -= h;
            let (gu, gd) = (g(&up)?, g(&down)?);
            Ok(gu
                .iter()
                .zip(&gd)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect())
        };
        let (coarse, fine) = (central(h)?, central(h / 2.0)?);
        for i in 0..rows {
            out[(i, j)] = (4.0 * fine[i] - coarse[i]) / 3.0;
        }
    }
    if out.iter().all(|v| v.is_finite()) {
        Ok(out)
    } else {
        Err(SteadyMotionError::NonFinite)
    }
}

/// Up to `count` columns of `a`, taken greedily: at each step the first column in the order
/// `order` whose part orthogonal to the columns taken is at least half the largest such
/// part among those left (and above `1e-9` of the largest column). The order is kept where
/// the columns are of like size, and a column that adds to the rank only weakly (a bicycle's
/// lean in the front contact's constraint, near upright) is passed over for a better one
/// (its pitch): a partial pivoting, so that the dependent entries are well conditioned.
fn pivot_columns(a: &DMatrix<f64>, order: &[usize], count: usize) -> Vec<usize> {
    let size = order
        .iter()
        .map(|&j| a.column(j).norm())
        .fold(0.0, f64::max);
    let mut taken: Vec<usize> = Vec::new();
    let mut basis: Vec<DVector<f64>> = Vec::new();
    while taken.len() < count {
        let orthogonal: Vec<(usize, DVector<f64>)> = (order.iter())
            .filter(|j| !taken.contains(j))
            .map(|&j| {
                let mut v = a.column(j).into_owned();
                for b in &basis {
                    let p = b.dot(&v);
                    v -= b * p;
                }
                (j, v)
            })
            .collect();
        let best = orthogonal.iter().map(|(_, v)| v.norm()).fold(0.0, f64::max);
        if !(best > 1e-9 * size && best > 0.0) {
            break;
        }
        let Some((j, v)) = orthogonal.into_iter().find(|(_, v)| v.norm() >= 0.5 * best) else {
            break;
        };
        let norm = v.norm();
        basis.push(v / norm);
        taken.push(j);
    }
    taken
}

/// The columns `cols` of `a`, in that order.
fn select_columns(a: &DMatrix<f64>, cols: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(a.nrows(), cols.len(), |r, c| a[(r, cols[c])])
}

/// Removes the states `which` (rows and columns, and names).
fn remove_states(a: &mut DMatrix<f64>, names: &mut Vec<String>, which: &[usize]) {
    let keep: Vec<usize> = (0..names.len()).filter(|i| !which.contains(i)).collect();
    *a = DMatrix::from_fn(keep.len(), keep.len(), |r, c| a[(keep[r], keep[c])]);
    *names = keep.iter().map(|&i| names[i].clone()).collect();
}

/// The eigenvalues of a general real state matrix `a` (`k × k`), by balancing
/// (Parlett–Reinsch) and the Schur form, sorted by ascending `|s|` then `Im s`; eigenvalues
/// below [`ZERO_EIGENVALUE`] of the largest are set to 0 and real parts below
/// [`ZERO_REAL_PART`] of `|s|` to 0 (`tolerance` widens both, for a matrix taken by
/// differences). `None` as [`raw_eigenvalues`].
pub fn general_eigenvalues(a: &DMatrix<f64>, tolerance: f64) -> Option<Vec<Complex<f64>>> {
    Some(rounded_general_eigenvalues(a, tolerance)?.0)
}

/// [`general_eigenvalues`] and the largest `|Re s|` it set to 0 (0 when none): the bound of
/// a marginal verdict decided within rounding.
fn rounded_general_eigenvalues(
    a: &DMatrix<f64>,
    tolerance: f64,
) -> Option<(Vec<Complex<f64>>, f64)> {
    let mut values = raw_eigenvalues(a)?;
    let largest = values.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let mut rounded = 0.0f64;
    for v in &mut values {
        if v.norm() <= ZERO_EIGENVALUE.max(tolerance) * largest {
            rounded = rounded.max(v.re.abs());
            *v = Complex::new(0.0, 0.0);
        } else if v.re.abs() <= ZERO_REAL_PART.max(tolerance) * v.norm() {
            rounded = rounded.max(v.re.abs());
            v.re = 0.0;
        }
        if v.im.abs() <= ZERO_EIGENVALUE.max(tolerance) * largest {
            v.im = 0.0;
        }
    }
    values.sort_by(|a, b| a.norm().total_cmp(&b.norm()).then(a.im.total_cmp(&b.im)));
    Some((values, rounded))
}

/// The eigenvalues of a general real matrix `a` as the balanced Schur form gives them, in its
/// order, with nothing set to zero: for locating where a real part changes sign.
///
/// `None` when `a` is not finite or the Schur iteration does not converge
/// ([`crate::linalg::eigenvalues`]).
pub fn raw_eigenvalues(a: &DMatrix<f64>) -> Option<Vec<Complex<f64>>> {
    if a.is_empty() {
        return Some(Vec::new());
    }
    if a.iter().any(|v| !v.is_finite()) {
        return None;
    }
    // Scaled by a power of two (exactly) so that the largest entry is about 1: nalgebra's
    // balancing squares column norms, and past 1.3e154 they are infinite and its loop never
    // ends (a sweep of g from 1e200 hung there).
    let largest = a.amax();
    let scale = if largest > 0.0 {
        // Clamped: below 2^-1000 (subnormal) the inverse power would overflow.
        2f64.powi(-(largest.log2().round().clamp(-1000.0, 1000.0) as i32))
    } else {
        1.0
    };
    let mut balanced = a * scale;
    nalgebra::linalg::balancing::balance_parlett_reinsch(&mut balanced);
    let values = crate::linalg::eigenvalues(&balanced)?;
    Some(values.into_iter().map(|v| v / scale).collect())
}

/// The eigenvalues of a steady linearisation, its stability verdict and the largest `|Re s|`
/// (1/s) set to 0 as rounding or as the differences' error (0 when none: a marginal verdict
/// with a positive value is decided within that bound).
///
/// # Errors
/// [`SteadyMotionError::EigenvaluesDidNotConverge`] (a state matrix that is not finite, or a
/// Schur iteration past its bound).
pub fn steady_stability(
    lin: &SteadyLinearization,
) -> Result<(Vec<Complex<f64>>, Stability, f64), SteadyMotionError> {
    let tolerance = if lin.exact_jacobian { 0.0 } else { 1e-8 };
    if lin.state_matrix.iter().any(|v| !v.is_finite()) {
        return Err(SteadyMotionError::NonFinite);
    }
    let (eigenvalues, rounded) = rounded_general_eigenvalues(&lin.state_matrix, tolerance).ok_or(
        SteadyMotionError::EigenvaluesDidNotConverge {
            size: lin.state_matrix.nrows(),
        },
    )?;
    let stability = verdict(&eigenvalues);
    Ok((eigenvalues, stability, rounded))
}
