//! Equilibria, exact linearisation into `M δq̈ + C δq̇ + K δq = 0`, and undamped normal modes
//! (issue 7; lectures 22–26).
//!
//! long: the linearisation (with constraints), its checks, and the normal modes by both routes
//! (symmetric, and `M⁻¹K` for a non-symmetric `K`) share the error type and the mass
//! matrix's checks; the modes could be a room of their own, a split left to the issue on the
//! code's shape.
//!
//! The linearisation uses the generated Jacobians, so it is exact (no finite differences,
//! except for an entry of `∂F/∂q` or `∂F/∂q̇` that is not finite where `F` is, a removable
//! singularity such as quadratic drag's `d|v|/dv` at rest, which is differenced as the
//! implicit integrators difference it; [`Linearization::differenced_entries`] counts them):
//! with `M(q, t) q̈ = F(q, q̇, t)` and an operating point `(q*, q̇*, t)` where `q̈* = M⁻¹F`,
//!
//! ```text
//! M = M(q*),  K = ∂(M a)/∂q |a = q̈*  − ∂F/∂q,  C = −∂F/∂q̇
//! ```
//!
//! (at an equilibrium `q̇* = 0`, `q̈* = 0` and `K = −∂F/∂q`). The state matrix is
//! `A = [0 I; −M⁻¹K −M⁻¹C]`.
//!
//! Normal modes solve `K ψ = ω² M ψ` by Cholesky reduction `M = L Lᵀ`,
//! `K̃ = L⁻¹ K L⁻ᵀ` (symmetric), `K̃ v = ω² v`, `ψ = L⁻ᵀ v`, so that `ΨᵀMΨ = I` (lecture 24's
//! `M^{-1/2} K M^{-1/2}` route with the Cholesky factor in place of the symmetric root: the same
//! eigenvalues, and mass-normalised shapes either way). `K` from a Lagrangian system is
//! symmetric at an equilibrium; an asymmetry (a follower load, or an operating point that is
//! not an equilibrium) is reported, and the modes are those of `M⁻¹K` (lecture 22), not of
//! `K`'s symmetric part, unless `M⁻¹K` has complex eigenvalues (flutter: [`normal_modes`]).
//!
//! With holonomic constraints the linearisation is projected onto the null space of the
//! constraint Jacobian (minimal coordinates; see [`Linearization`]); non-holonomic constraints
//! are refused ([`ModalError::NonHolonomic`]).

use nalgebra::{DMatrix, DVector};

use crate::model_info::ModelInfo;

/// ` of the linearisation at q = […]`, or nothing for a matrix given as such (no `q`).
fn operating_point(q: &[f64]) -> String {
    if q.is_empty() {
        String::new()
    } else {
        format!(" of the linearisation at q = {q:?}")
    }
}

/// Why an equilibrium, a linearisation or a modal analysis failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModalError {
    /// Newton's method on `F(q, 0, t) = 0` did not converge.
    #[error(
        "no equilibrium found: Newton stopped after {iterations} iterations ({reason}) with |F| = {residual:e} (from the guess {guess:?})"
    )]
    EquilibriumNotFound {
        /// Iterations made.
        iterations: usize,
        /// Why it stopped.
        reason: NewtonStop,
        /// Largest `|Fᵢ|` left (units of the generalized forces).
        residual: f64,
        /// The starting guess.
        guess: Vec<f64>,
    },
    /// Newton's residual fell below its tolerance only because the iterates ran away: the
    /// forces fade with distance (an inverse-square attraction), and the next Newton step
    /// from the last iterate is not small against it, so no root is near.
    #[error(
        "no equilibrium found: from the guess {guess:?} Newton walked away to q = {q:?}, where |F| = {residual:.3e} is small only because the forces fade with distance (the next Newton step would move q by {step:.3e} more)"
    )]
    EquilibriumAtInfinity {
        /// The starting guess.
        guess: Vec<f64>,
        /// The last iterate (length `n`).
        q: Vec<f64>,
        /// Largest `|Fᵢ|` there (units of the generalized forces).
        residual: f64,
        /// Largest entry of the Newton step from there (units of `q`; and of `λ` with
        /// constraints).
        step: f64,
    },
    /// The eigenvalue solver (nalgebra's QR iteration, bounded by
    /// [`crate::linalg::eigenvalues`]) did not converge on a matrix of the linearisation.
    #[error(
        "the eigenvalue solver did not converge on a {size} × {size} matrix{}",
        operating_point(q)
    )]
    EigenvaluesDidNotConverge {
        /// The matrix's order.
        size: usize,
        /// The operating point.
        q: Vec<f64>,
    },
    /// The mass matrix at the operating point is not positive definite.
    #[error("the mass matrix is not positive definite at q = {q:?}")]
    SingularMassMatrix {
        /// The operating point.
        q: Vec<f64>,
    },
    /// The mass matrix at the operating point is too ill-conditioned for `f64` work: some
    /// coordinates have no inertia there, or move the mechanism the same way (Euler angles
    /// at `θ = 0`, where the precession and spin angles turn the body about the same axis).
    #[error(
        "the mass matrix is too ill-conditioned at q = {q:?} in the coordinates {}: the smallest eigenvalue of its unit-diagonal form is {smallest_eigenvalue:.1e} (about the ratio of its smallest to largest; below {MASS_MATRIX_SINGULARITY:e} the modes would lose all but a few digits): these coordinates have nearly no inertia or move the mechanism nearly the same way here",
        coordinates.join(", ")
    )]
    DegenerateCoordinates {
        /// The coordinates (minimal coordinates with constraints) of the near-null
        /// direction: those whose entry in it is at least a tenth of the largest.
        coordinates: Vec<String>,
        /// The operating point.
        q: Vec<f64>,
        /// The smallest eigenvalue of `D^{-1/2} M D^{-1/2}`, `D = diag M` (dimensionless; 1
        /// for a diagonal `M`, 0 for a singular one, negative for an indefinite one).
        smallest_eigenvalue: f64,
    },
    /// The equations linearised about the operating point change with time: the mass,
    /// damping or stiffness coefficients, or a constraint, depend on `t` (parametric
    /// excitation, a rheonomic constraint, a moving frame written with `t`). Modes of the
    /// equations frozen at one `t` describe no motion; a periodic dependence is analysed by
    /// its Floquet multipliers instead.
    #[error(
        "the linearised equations depend on t: {part} at the operating point changes by {relative_change:.1e} (relative) between t = {t0} s and t = {t} s, so no modes are computed from the equations frozen at t = {t0} s (a parametrically excited system or a moving constraint); for a periodic dependence its stability is given by Floquet multipliers"
    )]
    TimeDependent {
        /// What depends on `t`.
        part: TimeDependentPart,
        /// The time of the operating point (s).
        t0: f64,
        /// The sampled time where the change was largest (s).
        t: f64,
        /// The largest change relative to the part's largest entry over the samples.
        relative_change: f64,
    },
    /// A load that depends on `t` (it enters neither `M`, `C` nor `K`), under whose value at
    /// `t₀` the equations at rest have no equilibrium: the equilibrium search failed, and its
    /// failure comes from the load's value at that one instant, so the time dependence is
    /// what stands between the model and its modes (a pendulum driven by `A cos wt` with
    /// `A` above `m g l`).
    #[error(
        "the load on `{}` depends on t (F(q, 0, t) − F(q, 0, t₀) reaches {:.3e} at t = {} s, t₀ = {} s), and under its value at t₀ the equations at rest have no equilibrium ({equilibrium}): modes need an equilibrium of equations that do not change with t",
        forcing.coordinate, forcing.largest_change, forcing.t, forcing.t0
    )]
    TimeDependentLoad {
        /// The load and how much it changes.
        forcing: TimeDependentForcing,
        /// Why the equilibrium search under its value at `t₀` failed
        /// ([`ModalError::EquilibriumNotFound`] or [`ModalError::EquilibriumAtInfinity`]).
        equilibrium: Box<ModalError>,
    },
    /// A value is not finite at the operating point.
    #[error("the linearisation is not finite at q = {q:?}")]
    NonFinite {
        /// The operating point.
        q: Vec<f64>,
    },
    /// `K` is not symmetric and `M⁻¹K` has complex eigenvalues (flutter): there are no real
    /// normal modes to superpose ([`NormalModes::symmetric_part_only`]).
    #[error(
        "K is not symmetric (‖K − Kᵀ‖/‖K‖ = {asymmetry:.2e}) and M⁻¹K has complex eigenvalues (flutter): there are no real normal modes to superpose"
    )]
    NoRealModes {
        /// `‖K − Kᵀ‖_max / ‖K‖_max`.
        asymmetry: f64,
    },
    /// The equations are not finite at the operating point at the time asked for, and are
    /// at a later time: a load outside its domain at that instant (`ln(w t)` at `t = 0`).
    #[error(
        "the equations are not finite at t = {t} s at q = {q:?}, though they are at t = {finite_at} s: a load is outside its domain at that instant (ln(w*t), 1/t at t = 0)"
    )]
    NotFiniteAtTime {
        /// The operating point.
        q: Vec<f64>,
        /// The time (s).
        t: f64,
        /// A later time where they are finite (s).
        finite_at: f64,
    },
    /// The model has non-holonomic constraints, which restrict the velocities but not the
    /// configuration: its equilibria are not isolated and the linearisation in `q` is not a
    /// second-order system `M δq̈ + C δq̇ + K δq = 0`.
    #[error(
        "`{model}` has the non-holonomic constraint `{constraint}`; equilibria and modes are computed for holonomic constraints only"
    )]
    NonHolonomic {
        /// The model.
        model: String,
        /// The first non-holonomic constraint.
        constraint: String,
    },
    /// The operating point violates the holonomic constraints.
    #[error("the operating point violates the constraint `{constraint}` (|Φ| = {residual:e})")]
    OffConstraints {
        /// The constraint with the largest residual.
        constraint: String,
        /// Its `|Φ|`.
        residual: f64,
    },
    /// A constrained model linearised at a moving operating point.
    #[error(
        "constrained models are linearised at rest only (q̇ = 0); the operating point has |q̇| = {speed:e}"
    )]
    ConstrainedMotion {
        /// The largest `|q̇ᵢ|` given.
        speed: f64,
    },
    /// A model in generalized speeds linearised where it moves (its `q̇ = W (u − Z) ≠ 0`).
    #[error(
        "a model in generalized speeds is linearised at rest only (q' = W (u - Z) = 0); the operating point has |q'| = {speed:e}"
    )]
    SpeedsInMotion {
        /// The largest `|q̇ᵢ|` from the kinematic equations.
        speed: f64,
    },
    /// A model whose generalized speeds depend on `t` (`u = Y(q, t) q̇ + Z(q, t)` with `t` in
    /// `Y` or `Z`): its rest moves with `t` in the speeds.
    #[error(
        "the generalized speeds depend on t (u = Y(q, t) q' + Z(q, t)), so rest (q' = 0) moves with t in the speeds: equilibria and linearisations are found in the coordinates' rates"
    )]
    SpeedsDependOnTime,
    /// A model in generalized speeds beside constraints (their rows its auxiliary speeds):
    /// rest and the linearisation in speeds are derived for unconstrained models.
    #[error(
        "the model is in generalized speeds beside the constraint `{constraint}`: equilibria and linearisations in speeds are derived without constraints"
    )]
    SpeedsBesideConstraints {
        /// The model.
        model: String,
        /// Its first constraint.
        constraint: String,
    },
    /// The kinematic equations of a model in generalized speeds are singular there: `W` is
    /// not invertible or not finite (Euler angles at gimbal lock).
    #[error(
        "the kinematic equations q' = W (u - Z) are singular at q = {q:?} (W is not invertible there, as Euler angles are at gimbal lock)"
    )]
    SingularKinematics {
        /// The coordinates.
        q: Vec<f64>,
    },
    /// The constraints fix every coordinate: no motion is left to have modes.
    #[error(
        "the {constraints} constraint(s) fix all {coordinates} coordinate(s) at the operating point: no degree of freedom is left, so there are no modes"
    )]
    NoDegreesOfFreedom {
        /// `n`.
        coordinates: usize,
        /// The holonomic constraints `m` (independent ones at least `n`).
        constraints: usize,
    },
    /// The operating point has the wrong number of coordinates.
    #[error("the operating point has {found} coordinates, the model {expected}")]
    DimensionMismatch {
        /// The model's degrees of freedom.
        expected: usize,
        /// Given.
        found: usize,
    },
}

impl From<super::speeds::KinematicsError> for ModalError {
    fn from(e: super::speeds::KinematicsError) -> Self {
        use super::speeds::KinematicsFailure as F;
        match e.kind {
            F::Singular => ModalError::SingularKinematics { q: e.q },
            F::TimeDependent => ModalError::SpeedsDependOnTime,
            F::Moving(speed) => ModalError::SpeedsInMotion { speed },
            F::SingularMassMatrix => ModalError::SingularMassMatrix { q: e.q },
            F::NonFinite => ModalError::NonFinite { q: e.q },
        }
    }
}

pub use super::stops::{NewtonStop, TimeDependentForcing, TimeDependentPart};
pub use super::time_dependence::time_dependence;

/// Below this smallest eigenvalue of the unit-diagonal mass matrix `D^{-1/2} M D^{-1/2}` (its
/// largest is between 1 and `n`, so this is the inverse of its condition number to within
/// `n`) the mass matrix is refused as ill-conditioned for `f64` work
/// ([`ModalError::DegenerateCoordinates`]): solving with it loses `log₁₀(1/λ_min)` digits, so
/// the modes would be wrong by about `1e-16/λ_min ≈ 1e-3` here. Above it they are merely less
/// accurate (`cart_pendulum` with m1 = 1e-9 kg, `λ_min ≈ 5e-10`: modes right to 4e-8).
/// Scaling by the diagonal makes the test independent of units and of the sizes of the
/// bodies (a 1000 kg cart and a 1 g bob give a ratio near 1 if their coordinates are
/// independent).
pub const MASS_MATRIX_SINGULARITY: f64 = 1e-13;

pub use super::equilibrium::{Equilibrium, find_equilibrium};

/// The Hessians `∇²Φᵢ(q, t)` (`n × n` each, one per holonomic constraint), exact.
///
/// They are read off the generated `γ` of `J q̈ = γ`, whose dependence on `q̇` is
/// `γᵢ(q̇) = −q̇ᵀ ∇²Φᵢ q̇ + (linear in q̇) + const` (the linear and constant parts come from
/// an explicit time dependence), by polarisation:
/// `(∇²Φᵢ)ⱼₖ = −[γᵢ(eⱼ + eₖ) − γᵢ(eⱼ) − γᵢ(eₖ) + γᵢ(0)] / 2` — exact up to rounding because
/// `γ` is exactly quadratic in `q̇`.
pub fn constraint_hessians(model: &dyn ModelInfo, q: &[f64], t: f64) -> Vec<DMatrix<f64>> {
    let n = model.num_dofs();
    let m = model.description().holonomic_constraints;
    let gamma = |v: &[(usize, f64)]| -> DVector<f64> {
        let mut y: Vec<f64> = q
            .iter()
            .copied()
            .chain(std::iter::repeat_n(0.0, n))
            .collect();
        for &(j, a) in v {
            y[n + j] += a;
        }
        model
            .constraint_equations(t, &y)
            .gamma
            .rows(0, m)
            .into_owned()
    };
    let g0 = gamma(&[]);
    let single: Vec<DVector<f64>> = (0..n).map(|j| gamma(&[(j, 1.0)])).collect();
    let mut out = vec![DMatrix::zeros(n, n); m];
    for j in 0..n {
        for k in j..n {
            let both = gamma(&[(j, 1.0), (k, 1.0)]);
            for (i, h) in out.iter_mut().enumerate() {
                let v = -(both[i] - single[j][i] - single[k][i] + g0[i]) / 2.0;
                h[(j, k)] = v;
                h[(k, j)] = v;
            }
        }
    }
    out
}

/// Refuses a mass matrix (`r × r`, in the coordinates `names`) that is singular to working
/// precision at `q`: a non-positive diagonal entry, or a smallest eigenvalue of the
/// unit-diagonal form below [`MASS_MATRIX_SINGULARITY`] ([`ModalError::DegenerateCoordinates`],
/// naming the coordinates of the near-null direction; a negative diagonal entry is
/// [`ModalError::SingularMassMatrix`]). A non-finite `M` passes here and is refused by the
/// caller's finiteness check.
fn check_mass_matrix(mass: &DMatrix<f64>, names: &[&str], q: &[f64]) -> Result<(), ModalError> {
    let r = mass.nrows();
    if r == 0 || !mass.iter().all(|v| v.is_finite()) {
        return Ok(());
    }
    let degenerate = |coordinates: Vec<String>, smallest_eigenvalue: f64| {
        Err(ModalError::DegenerateCoordinates {
            coordinates,
            q: q.to_vec(),
            smallest_eigenvalue,
        })
    };
    let diagonal: Vec<f64> = mass.diagonal().iter().copied().collect();
    if diagonal.iter().any(|d| *d < 0.0) {
        return Err(ModalError::SingularMassMatrix { q: q.to_vec() });
    }
    if let Some(i) = diagonal.iter().position(|d| *d == 0.0) {
        return degenerate(vec![names[i].to_string()], 0.0);
    }
    let root: Vec<f64> = diagonal.iter().map(|d| d.sqrt()).collect();
    let scaled = DMatrix::from_fn(r, r, |i, j| {
        0.5 * (mass[(i, j)] + mass[(j, i)]) / (root[i] * root[j])
    });
    let eigen = crate::linalg::symmetric_eigen(scaled).ok_or_else(|| {
        ModalError::EigenvaluesDidNotConverge {
            size: r,
            q: q.to_vec(),
        }
    })?;
    let k = eigen.eigenvalues.imin();
    let smallest = eigen.eigenvalues[k];
    if smallest >= MASS_MATRIX_SINGULARITY {
        return Ok(());
    }
    let v = eigen.eigenvectors.column(k);
    let largest = v.amax();
    let coordinates = (0..r)
        .filter(|&i| v[i].abs() >= 0.1 * largest)
        .map(|i| names[i].to_string())
        .collect();
    degenerate(coordinates, smallest)
}

pub(super) fn check_point(model: &dyn ModelInfo, q: &[f64]) -> Result<(), ModalError> {
    let names = model.description().constraint_names();
    let h = model.description().holonomic_constraints;
    if model.description().has_speeds() && !names.is_empty() {
        return Err(ModalError::SpeedsBesideConstraints {
            model: model.description().name.to_string(),
            constraint: names[0].to_string(),
        });
    }
    if names.len() > h {
        return Err(ModalError::NonHolonomic {
            model: model.description().name.to_string(),
            constraint: names[h].to_string(),
        });
    }
    if q.len() != model.num_dofs() {
        return Err(ModalError::DimensionMismatch {
            expected: model.num_dofs(),
            found: q.len(),
        });
    }
    Ok(())
}

/// `∂F/∂q` and `∂F/∂q̇` at `(t, y)` (`n × n` each, `y = [q; q̇]`), with the number of their
/// entries that were replaced by differences: the generated, exact ones, except that an entry
/// that is not finite where `F` is finite is replaced by its forward difference of `F`
/// ([`forward_differences`](crate::linalg::forward_differences), the integrators' fallback):
/// a derivative can have a removable singularity that `F` has not (quadratic drag `c |v| v`
/// at rest, `c vₓ²/|v|` = 0/0 where the derivative is 0; its difference is `c δ ≈ 5e-11 c`).
/// The exact entries that are finite are kept. Where `F` itself or a difference is not finite
/// the entry stays as it is, for the caller's finiteness check.
pub(super) fn forcing_jacobians(
    model: &dyn ModelInfo,
    t: f64,
    y: &[f64],
) -> (DMatrix<f64>, DMatrix<f64>, usize) {
    let (mut jq, mut jqd) = model.forcing_jacobians(t, y);
    let finite = |a: &DMatrix<f64>| a.iter().all(|v| v.is_finite());
    if finite(&jq) && finite(&jqd) {
        return (jq, jqd, 0);
    }
    let (_, f0) = model.mass_matrix_and_forcing(t, y);
    let n = f0.len();
    if !f0.iter().all(|v| v.is_finite()) || y.len() != 2 * n {
        return (jq, jqd, 0);
    }
    // ∂F/∂[q; q̇], n × 2n: ∂F/∂q in the first n columns, ∂F/∂q̇ in the last n.
    let mut both = DMatrix::zeros(n, 2 * n);
    let (mut work_y, mut work_f) = (vec![0.0; 2 * n], vec![0.0; n]);
    let _ = crate::linalg::forward_differences(
        y,
        f0.as_slice(),
        both.as_mut_slice(),
        &mut work_y,
        &mut work_f,
        |y, f| {
            f.copy_from_slice(model.mass_matrix_and_forcing(t, y).1.as_slice());
            Ok::<(), std::convert::Infallible>(())
        },
    );
    let mut replaced = 0;
    for (offset, exact) in [(0, &mut jq), (n, &mut jqd)] {
        for j in 0..n {
            for i in 0..n {
                let difference = both[(i, offset + j)];
                if !exact[(i, j)].is_finite() && difference.is_finite() {
                    exact[(i, j)] = difference;
                    replaced += 1;
                }
            }
        }
    }
    (jq, jqd, replaced)
}

/// The linearised equations `M δq̈ + C δq̇ + K δq = 0` at an operating point.
///
/// Without constraints the unknowns are `δq` itself. With holonomic constraints they are `r`
/// minimal coordinates `z` (lecture 25 with lectures 8–11): `δq = N z`, where the columns of
/// the `n × r` [`Self::coordinate_basis`] `N` span the null space of the constraint Jacobian
/// `J(q*)` and `z` are the increments of the [`Self::independent_coordinates`] (coordinate
/// partitioning: `N` restricted to those rows is the identity). Then `M`, `C`, `K` are
/// `r × r`: `Nᵀ M N`, `Nᵀ C N` and `Nᵀ (∂(M q̈*)/∂q − ∂F/∂q + Σᵢ λᵢ ∇²Φᵢ) N` — the last term
/// is the stiffness of the constraint forces (a rod's tension makes the Cartesian pendulum
/// swing).
///
/// Serialised with each matrix as a list of rows.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Linearization {
    /// The operating point's coordinates `q*` (length `n`).
    pub q: Vec<f64>,
    /// Its rates `q̇*` (length `n`; zero at an equilibrium).
    pub qdot: Vec<f64>,
    /// Its time (s).
    pub t: f64,
    /// `mass_matrix` `M(q*)` (`r × r`, `r = n` without constraints), symmetric positive
    /// definite.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub mass_matrix: DMatrix<f64>,
    /// `stiffness_matrix` `K`, `r × r`, as derived (not symmetrised).
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub stiffness_matrix: DMatrix<f64>,
    /// `damping_matrix` `C = −∂F/∂q̇` (`r × r`; velocity-dependent gyroscopic terms make it
    /// non-symmetric).
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub damping_matrix: DMatrix<f64>,
    /// `N` (`n × r`): `δq = N z`; the identity without constraints.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub coordinate_basis: DMatrix<f64>,
    /// Indices (into `q`, ascending) of the `r` coordinates whose increments are `z`.
    pub independent_coordinates: Vec<usize>,
    /// `lagrange_multipliers` `λ*` at the operating point (length `m`; empty without
    /// constraints).
    pub lagrange_multipliers: Vec<f64>,
    /// How many entries of the generated `∂F/∂q` and `∂F/∂q̇` (`n × n` each) were not finite
    /// at the operating point while `F` was, and were replaced by forward differences of `F`
    /// (a removable singularity: quadratic drag `c |v| v` at rest, whose exact derivative is
    /// 0/0 there and whose difference is `c δ`, about `5e-11 c`); 0 when `K` and `C` are
    /// exact.
    pub differenced_entries: usize,
}

impl Linearization {
    /// A linearisation given by its matrices (`n × n` each), at rest at `q = 0`, `t = 0`,
    /// without constraints: for systems assembled by hand (lectures 27–29's stiffness
    /// assembly, HW32's matrices).
    pub fn from_matrices(
        mass_matrix: DMatrix<f64>,
        stiffness_matrix: DMatrix<f64>,
        damping_matrix: DMatrix<f64>,
    ) -> Self {
        let n = mass_matrix.nrows();
        Self {
            q: vec![0.0; n],
            qdot: vec![0.0; n],
            t: 0.0,
            mass_matrix,
            stiffness_matrix,
            damping_matrix,
            coordinate_basis: DMatrix::identity(n, n),
            independent_coordinates: (0..n).collect(),
            lagrange_multipliers: Vec::new(),
            differenced_entries: 0,
        }
    }

    /// `‖K − Kᵀ‖_max / ‖K‖_max` (0 for a symmetric `K`; 0 when `K = 0`).
    pub fn stiffness_asymmetry(&self) -> f64 {
        asymmetry(&self.stiffness_matrix)
    }

    /// The Cholesky factorisation of `M`.
    ///
    /// # Errors
    /// [`ModalError::SingularMassMatrix`] if `M` is not positive definite.
    pub fn mass_cholesky(&self) -> Result<nalgebra::Cholesky<f64, nalgebra::Dyn>, ModalError> {
        self.mass_matrix
            .clone()
            .cholesky()
            .ok_or_else(|| ModalError::SingularMassMatrix { q: self.q.clone() })
    }

    /// The state matrix `A = [0 I; −M⁻¹K −M⁻¹C]` (`2n × 2n`) of `δẏ = A δy`, `y = [q; q̇]`.
    ///
    /// # Errors
    /// [`ModalError::SingularMassMatrix`] if `M` is not positive definite.
    pub fn state_matrix(&self) -> Result<DMatrix<f64>, ModalError> {
        let n = self.mass_matrix.nrows();
        let chol = self.mass_cholesky()?;
        let mk = chol.solve(&self.stiffness_matrix);
        let mc = chol.solve(&self.damping_matrix);
        let mut a = DMatrix::zeros(2 * n, 2 * n);
        for i in 0..n {
            a[(i, n + i)] = 1.0;
            for j in 0..n {
                a[(n + i, j)] = -mk[(i, j)];
                a[(n + i, n + j)] = -mc[(i, j)];
            }
        }
        Ok(a)
    }

    /// Number of minimal coordinates `r` (the size of `M`, `C`, `K`).
    pub fn num_minimal_coordinates(&self) -> usize {
        self.mass_matrix.nrows()
    }

    /// Vectors in the minimal coordinates (`r × k`, e.g. mode shapes) expressed in the model's
    /// coordinates: `N Z` (`n × k`).
    pub fn to_coordinates(&self, z: &DMatrix<f64>) -> DMatrix<f64> {
        &self.coordinate_basis * z
    }
}

fn asymmetry(k: &DMatrix<f64>) -> f64 {
    let scale = k.amax();
    if scale == 0.0 {
        return 0.0;
    }
    (k - k.transpose()).amax() / scale
}

/// Linearises `model` at `(q, q̇, t)` exactly, from the generated `M`, `∂F/∂q`, `∂F/∂q̇`,
/// `∂(M a)/∂q` and, with holonomic constraints, `J` and the constraint Hessians (issue 7,
/// item 2; lecture 25).
///
/// Unconstrained: `M = M(q*)`, `K = ∂(M q̈*)/∂q − ∂F/∂q`, `C = −∂F/∂q̇` with
/// `q̈* = M⁻¹F`. A model in generalized speeds (`qdot` then holds the speeds `u`) is
/// linearised at rest, in its coordinates, from Kane's equations and the kinematic
/// equations (`linear/speeds.rs`); an all-zero `qdot` is read as rest there. With holonomic constraints (at rest only): `q̈*` and `λ*` from
/// `[M Jᵀ; J 0][q̈; λ] = [F; γ]`, the minimal coordinates by coordinate partitioning of `J`
/// (Gaussian elimination with complete pivoting picks the `rank J` best-conditioned dependent
/// coordinates), and the projected matrices described at [`Linearization`].
///
/// # Errors
/// [`ModalError::NonHolonomic`], [`ModalError::DimensionMismatch`],
/// [`ModalError::ConstrainedMotion`] (constrained and `q̇ ≠ 0`),
/// [`ModalError::SpeedsInMotion`] and [`ModalError::SingularKinematics`] (generalized speeds
/// off rest, or where the kinematic equations are singular),
/// [`ModalError::OffConstraints`] (`|Φ| > 1e-8`), [`ModalError::SingularMassMatrix`],
/// [`ModalError::DegenerateCoordinates`] (a mass matrix singular to working precision: the
/// smallest eigenvalue of `D^{-1/2} M D^{-1/2}`, `D = diag M`, below
/// [`MASS_MATRIX_SINGULARITY`], in the minimal coordinates with constraints),
/// [`ModalError::NonFinite`] (an entry of `∂F/∂q` or `∂F/∂q̇` that is not finite is first
/// replaced by its forward difference of `F`, as the implicit integrators do, and counted in
/// [`Linearization::differenced_entries`]; the error is for what stays not finite).
pub fn linearize(
    model: &dyn ModelInfo,
    q: &[f64],
    qdot: &[f64],
    t: f64,
) -> Result<Linearization, ModalError> {
    check_point(model, q)?;
    if qdot.len() != q.len() {
        return Err(ModalError::DimensionMismatch {
            expected: q.len(),
            found: qdot.len(),
        });
    }
    if model.description().has_speeds() {
        let rest = super::speeds::linearize_at_rest(model, q, qdot, t)?;
        let n = q.len();
        return Ok(Linearization {
            q: q.to_vec(),
            qdot: vec![0.0; n],
            t,
            mass_matrix: rest.mass,
            stiffness_matrix: rest.stiffness,
            damping_matrix: rest.damping,
            coordinate_basis: DMatrix::identity(n, n),
            independent_coordinates: (0..n).collect(),
            lagrange_multipliers: Vec::new(),
            differenced_entries: 0,
        });
    }
    let n = q.len();
    let m = model.description().holonomic_constraints;
    let y: Vec<f64> = q.iter().chain(qdot).copied().collect();
    let (mass, f) = model.mass_matrix_and_forcing(t, &y);
    let (jq, jqd, differenced_entries) = forcing_jacobians(model, t, &y);
    let finite = |a: &DMatrix<f64>| a.iter().all(|v| v.is_finite());
    let names = model.description().coordinate_names();
    if m == 0 {
        check_mass_matrix(&mass, &names, q)?;
        let chol = mass
            .clone()
            .cholesky()
            .ok_or_else(|| ModalError::SingularMassMatrix { q: q.to_vec() })?;
        let qdd = chol.solve(&f);
        let ma = model.mass_matrix_product_jacobian(t, &y, qdd.as_slice());
        let stiffness_matrix = ma - jq;
        let damping_matrix = -jqd;
        if !(finite(&mass) && finite(&stiffness_matrix) && finite(&damping_matrix)) {
            return Err(ModalError::NonFinite { q: q.to_vec() });
        }
        return Ok(Linearization {
            q: q.to_vec(),
            qdot: qdot.to_vec(),
            t,
            mass_matrix: mass,
            stiffness_matrix,
            damping_matrix,
            coordinate_basis: DMatrix::identity(n, n),
            independent_coordinates: (0..n).collect(),
            lagrange_multipliers: Vec::new(),
            differenced_entries,
        });
    }
    let speed = qdot.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if speed != 0.0 {
        return Err(ModalError::ConstrainedMotion { speed });
    }
    let c = model.constraint_equations(t, &y);
    check_on_constraints(model, &c.phi)?;
    let j = c.jacobian.rows(0, m).into_owned();
    if !(finite(&mass) && finite(&j) && finite(&jq) && finite(&jqd)) {
        return Err(ModalError::NonFinite { q: q.to_vec() });
    }
    let (qdd, lambda) = constrained_accelerations(&mass, &j, &f, &c.gamma, q)?;
    let mut k_full = model.mass_matrix_product_jacobian(t, &y, qdd.as_slice()) - jq;
    for (l, h) in lambda.iter().zip(constraint_hessians(model, q, t)) {
        k_full += h * *l;
    }
    let (basis, independent) = null_space_by_partitioning(&j);
    if basis.ncols() == 0 {
        return Err(ModalError::NoDegreesOfFreedom {
            coordinates: n,
            constraints: m,
        });
    }
    let nt = basis.transpose();
    let mass_matrix = &nt * &mass * &basis;
    let minimal: Vec<&str> = independent.iter().map(|&i| names[i]).collect();
    check_mass_matrix(&mass_matrix, &minimal, q)?;
    let stiffness_matrix = &nt * &k_full * &basis;
    let damping_matrix = &nt * (-jqd) * &basis;
    if !(finite(&mass_matrix) && finite(&stiffness_matrix) && finite(&damping_matrix)) {
        return Err(ModalError::NonFinite { q: q.to_vec() });
    }
    Ok(Linearization {
        q: q.to_vec(),
        qdot: qdot.to_vec(),
        t,
        mass_matrix,
        stiffness_matrix,
        damping_matrix,
        coordinate_basis: basis,
        independent_coordinates: independent,
        lagrange_multipliers: lambda,
        differenced_entries,
    })
}

/// Checks that the state is on the holonomic constraints: every residual `|Φᵢ|` at most
/// `1e-8` (a NaN counts as infinite).
///
/// # Errors
/// [`ModalError::OffConstraints`] naming the constraint with the largest residual.
fn check_on_constraints(model: &dyn ModelInfo, phi: &DVector<f64>) -> Result<(), ModalError> {
    let (worst, residual) = phi
        .iter()
        .map(|v| if v.is_nan() { f64::INFINITY } else { v.abs() })
        .enumerate()
        .fold((0, 0.0f64), |b, x| if x.1 > b.1 { x } else { b });
    if residual > 1e-8 {
        return Err(ModalError::OffConstraints {
            constraint: model.description().constraints[worst].to_string(),
            residual,
        });
    }
    Ok(())
}

/// `q̈` (length `n`) and `λ` (length `m`) from `[M Jᵀ; J 0][q̈; λ] = [F; γ]` (`M` `n × n`,
/// `J` `m × n`, `F` length `n`, the first `m` entries of `gamma`), solved by SVD in the
/// minimum-norm sense, singular values below `1e-12` of the largest dropped; `q` (length `n`)
/// only names the point in the error.
///
/// # Errors
/// [`ModalError::SingularMassMatrix`] when the solve fails.
fn constrained_accelerations(
    mass: &DMatrix<f64>,
    j: &DMatrix<f64>,
    f: &DVector<f64>,
    gamma: &DVector<f64>,
    q: &[f64],
) -> Result<(DVector<f64>, Vec<f64>), ModalError> {
    let (n, m) = (q.len(), j.nrows());
    // [M Jᵀ; J 0][q̈; λ] = [F; γ] in the minimum-norm sense (redundant constraints leave λ
    // undetermined; the minimum-norm λ is then used).
    let mut kkt = DMatrix::zeros(n + m, n + m);
    kkt.view_mut((0, 0), (n, n)).copy_from(mass);
    kkt.view_mut((0, n), (n, m)).copy_from(&j.transpose());
    kkt.view_mut((n, 0), (m, n)).copy_from(j);
    let mut rhs = DVector::zeros(n + m);
    rhs.rows_mut(0, n).copy_from(f);
    rhs.rows_mut(n, m).copy_from(&gamma.rows(0, m));
    let svd = kkt.svd(true, true);
    let eps = 1e-12 * svd.singular_values.max();
    let solution = svd
        .solve(&rhs, eps)
        .map_err(|_| ModalError::SingularMassMatrix { q: q.to_vec() })?;
    let qdd = solution.rows(0, n).into_owned();
    let lambda: Vec<f64> = solution.rows(n, m).iter().copied().collect();
    Ok((qdd, lambda))
}

/// A basis `N` (`n × r`) of the null space of `J` (`m × n`) by coordinate partitioning:
/// Gaussian elimination with complete pivoting picks `rank J` dependent coordinates (pivots
/// below `1e-10` of the first are rank deficiency); the other `r` are independent and `N` is
/// the identity on them and `−J_d⁻¹ J_i` on the dependent ones. Returns `N` and the
/// independent indices (ascending).
fn null_space_by_partitioning(j: &DMatrix<f64>) -> (DMatrix<f64>, Vec<usize>) {
    let (m, n) = j.shape();
    let mut a = j.clone();
    let mut rows: Vec<usize> = (0..m).collect();
    let mut cols: Vec<usize> = (0..n).collect();
    let mut first = 0.0f64;
    let mut rank = 0;
    for k in 0..m.min(n) {
        // Largest remaining entry (first in row-major order on ties).
        let (mut bi, mut bj, mut best) = (k, k, 0.0f64);
        for i in k..m {
            for jj in k..n {
                let v = a[(rows[i], cols[jj])].abs();
                if v > best {
                    (bi, bj, best) = (i, jj, v);
                }
            }
        }
        if k == 0 {
            first = best;
        }
        if best == 0.0 || best <= 1e-10 * first {
            break;
        }
        rows.swap(k, bi);
        cols.swap(k, bj);
        let (pr, pc) = (rows[k], cols[k]);
        for &r in &rows[k + 1..] {
            let factor = a[(r, pc)] / a[(pr, pc)];
            if factor != 0.0 {
                for &cc in &cols {
                    let v = a[(pr, cc)];
                    a[(r, cc)] -= factor * v;
                }
            }
        }
        rank += 1;
    }
    let mut dependent: Vec<usize> = cols[..rank].to_vec();
    let mut independent: Vec<usize> = cols[rank..].to_vec();
    dependent.sort_unstable();
    independent.sort_unstable();
    let pivot_rows: Vec<usize> = rows[..rank].to_vec();
    // J_d (rank × rank) on the pivot rows and dependent columns, J_i the rest of those rows.
    let jd = DMatrix::from_fn(rank, rank, |r, c| j[(pivot_rows[r], dependent[c])]);
    let ji = DMatrix::from_fn(rank, independent.len(), |r, c| {
        j[(pivot_rows[r], independent[c])]
    });
    let solved = jd
        .lu()
        .solve(&ji)
        .unwrap_or_else(|| DMatrix::from_element(rank, independent.len(), f64::NAN));
    let mut basis = DMatrix::zeros(n, independent.len());
    for (c, &i) in independent.iter().enumerate() {
        basis[(i, c)] = 1.0;
        for (r, &d) in dependent.iter().enumerate() {
            basis[(d, c)] = -solved[(r, c)];
        }
    }
    (basis, independent)
}

/// What a mode is; serialised as `{"kind": "oscillatory"}`, `{"kind": "zero_frequency"}` or
/// `{"kind": "unstable", "growth_rate": σ}`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ModeKind {
    /// `ω² > 0`: an oscillation at `ω` rad/s.
    Oscillatory,
    /// `ω² ≈ 0`: below `1e-9` of the stiffness acting on the mode's own coordinates (or at
    /// rounding, `1e-13 max |ω²|`), a zero-frequency (rigid-body) mode (lecture 24).
    ZeroFrequency,
    /// `ω² < 0`: an unstable direction growing like `e^{σ t}`, `σ = √(−ω²)` (1/s).
    Unstable {
        /// The growth rate `σ` (1/s).
        growth_rate: f64,
    },
}

impl ModeKind {
    /// Its name in reports: `"oscillatory"`, `"zero_frequency"` or `"unstable"`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Oscillatory => "oscillatory",
            Self::ZeroFrequency => "zero_frequency",
            Self::Unstable { .. } => "unstable",
        }
    }

    /// The growth rate `σ` (1/s) of an unstable mode, `None` for the others.
    pub fn growth_rate(&self) -> Option<f64> {
        match self {
            Self::Unstable { growth_rate } => Some(*growth_rate),
            _ => None,
        }
    }
}

/// The undamped normal modes `K ψ = ω² M ψ` at an operating point (serialised with the mode
/// shapes as a list of rows).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NormalModes {
    /// The eigenvalues `ω²` (1/s²), ascending; zero-frequency ones are set to 0.
    pub eigenvalues: Vec<f64>,
    /// `natural_frequencies` ω (rad/s), ascending with `eigenvalues`: `√ω²`, 0 for
    /// zero-frequency and unstable modes (see `kinds`).
    pub natural_frequencies: Vec<f64>,
    /// What each mode is.
    pub kinds: Vec<ModeKind>,
    /// `mode_shapes`, `r × r` in the linearisation's coordinates ([`Linearization::to_coordinates`] gives
    /// them in `q`), column `k` the shape of mode `k`, mass-normalised:
    /// `ΨᵀMΨ = I` (for a non-symmetric `K`, each column `ψᵀMψ = 1`, the columns not
    /// `M`-orthogonal); sign fixed so that the largest-magnitude entry is positive.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub mode_shapes: DMatrix<f64>,
    /// `‖K − Kᵀ‖_max / ‖K‖_max` before symmetrisation.
    pub stiffness_asymmetry: f64,
    /// Whether the modes are those of the symmetric part of `K` only, not the system's: `K`
    /// is not symmetric (follower loads) and `M⁻¹K` has complex eigenvalues (flutter), so the
    /// system has no real normal modes. Its kinds are then no verdict; the stability of the
    /// state matrix is.
    pub symmetric_part_only: bool,
}

/// The normal modes of a linearisation, by Cholesky reduction to a symmetric eigenproblem.
/// Where `K` is not symmetric beyond rounding (a follower load), its symmetric part would
/// give other frequencies, and can be indefinite while the system is stable (Ziegler's
/// pendulum between P = 2 and its flutter load): the modes are then those of `M⁻¹K`
/// (lecture 22), `K ψ = ω² M ψ` with real `ω²`, each `ψ` normalised to `ψᵀMψ = 1` (they are
/// not `M`-orthogonal); if `M⁻¹K` has complex eigenvalues (flutter), the symmetric part's
/// modes are returned with [`NormalModes::symmetric_part_only`].
///
/// # Errors
/// [`ModalError::SingularMassMatrix`] if `M` is not positive definite;
/// [`ModalError::NonFinite`] if the eigensolver fails.
pub fn normal_modes(lin: &Linearization) -> Result<NormalModes, ModalError> {
    let asymmetric = lin.stiffness_asymmetry() > STIFFNESS_ASYMMETRY;
    if asymmetric && let Some(modes) = non_symmetric_modes(lin)? {
        return Ok(modes);
    }
    let n = lin.mass_matrix.nrows();
    let k_sym = (&lin.stiffness_matrix + lin.stiffness_matrix.transpose()) * 0.5;
    let chol = lin.mass_cholesky()?;
    let l = chol.l();
    // K̃ = L⁻¹ K L⁻ᵀ: solve L X = K, then L Y = Xᵀ (Y = L⁻¹ (L⁻¹ K)ᵀ = L⁻¹ K L⁻ᵀ for symmetric K).
    let x = l
        .solve_lower_triangular(&k_sym)
        .ok_or_else(|| ModalError::SingularMassMatrix { q: lin.q.clone() })?;
    let y = l
        .solve_lower_triangular(&x.transpose())
        .ok_or_else(|| ModalError::SingularMassMatrix { q: lin.q.clone() })?;
    let y = (&y + y.transpose()) * 0.5;
    if !y.iter().all(|v| v.is_finite()) {
        return Err(ModalError::NonFinite { q: lin.q.clone() });
    }
    let eigen = crate::linalg::symmetric_eigen(y.clone()).ok_or_else(|| {
        ModalError::EigenvaluesDidNotConverge {
            size: n,
            q: lin.q.clone(),
        }
    })?;
    let reduced = y;
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
    let largest = eigen.eigenvalues.amax();
    let lt = l.transpose();
    let mut shapes = DMatrix::zeros(n, n);
    let mut eigenvalues = Vec::with_capacity(n);
    let mut natural_frequencies = Vec::with_capacity(n);
    let mut kinds = Vec::with_capacity(n);
    for (col, &k) in order.iter().enumerate() {
        let mut w2 = eigen.eigenvalues[k];
        let kind = if is_zero_frequency(w2, &reduced, eigen.eigenvectors.column(k), largest) {
            w2 = 0.0;
            ModeKind::ZeroFrequency
        } else if w2 < 0.0 {
            ModeKind::Unstable {
                growth_rate: (-w2).sqrt(),
            }
        } else {
            ModeKind::Oscillatory
        };
        eigenvalues.push(w2);
        natural_frequencies.push(w2.max(0.0).sqrt());
        kinds.push(kind);
        let v = eigen.eigenvectors.column(k).into_owned();
        let mut psi = lt
            .solve_upper_triangular(&v)
            .ok_or_else(|| ModalError::SingularMassMatrix { q: lin.q.clone() })?;
        let (imax, _) =
            psi.iter().enumerate().fold(
                (0, 0.0f64),
                |b, (i, v)| if v.abs() > b.1 { (i, v.abs()) } else { b },
            );
        if psi[imax] < 0.0 {
            psi = -psi;
        }
        shapes.set_column(col, &psi);
    }
    Ok(NormalModes {
        eigenvalues,
        natural_frequencies,
        kinds,
        mode_shapes: shapes,
        stiffness_asymmetry: lin.stiffness_asymmetry(),
        symmetric_part_only: asymmetric,
    })
}

impl NormalModes {
    /// For an analysis that superposes the modes (free response, modal damping, the FRF's
    /// modal sum): the system's own modes, not only its symmetric part's.
    ///
    /// # Errors
    /// [`ModalError::NoRealModes`] when [`Self::symmetric_part_only`].
    pub fn require_real(&self) -> Result<(), ModalError> {
        if self.symmetric_part_only {
            return Err(ModalError::NoRealModes {
                asymmetry: self.stiffness_asymmetry,
            });
        }
        Ok(())
    }

    /// Whether the mode shapes are `M`-orthonormal (`ΨᵀMΨ = I`): those of a symmetric `K`.
    /// The modes of a non-symmetric `K` (follower loads; lecture 22) are not, and a force is
    /// taken to modal forces by `Ψ⁻¹M⁻¹` (the left eigenvectors) instead of `Ψᵀ`.
    pub fn m_orthogonal(&self) -> bool {
        self.stiffness_asymmetry <= STIFFNESS_ASYMMETRY
    }

    /// The matrix that takes a force to modal forces, as text for reports: `Ψᵀ`, or `Ψ⁻¹M⁻¹`
    /// where the modes are not [`Self::m_orthogonal`]. The modal damping matrix is this
    /// times `CΨ`.
    pub fn projector_label(&self) -> &'static str {
        if self.m_orthogonal() {
            "Ψᵀ"
        } else {
            "Ψ⁻¹M⁻¹"
        }
    }
}

/// `K` is symmetric to rounding below this asymmetry ([`Linearization::stiffness_asymmetry`]).
const STIFFNESS_ASYMMETRY: f64 = 1e-12;

/// The modes of a non-symmetric `K` from `M⁻¹K` ([`normal_modes`]); `None` when an eigenvalue
/// is complex beyond rounding (`|Im λ| > 1e-12 max |λ|`: flutter).
fn non_symmetric_modes(lin: &Linearization) -> Result<Option<NormalModes>, ModalError> {
    let n = lin.mass_matrix.nrows();
    let chol = lin.mass_cholesky()?;
    let a = chol.solve(&lin.stiffness_matrix);
    let values = crate::linalg::eigenvalues(&a).ok_or(ModalError::EigenvaluesDidNotConverge {
        size: n,
        q: lin.q.clone(),
    })?;
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.norm()));
    if values.iter().any(|v| v.im.abs() > 1e-12 * largest) {
        return Ok(None);
    }
    let mut w2s: Vec<f64> = values.iter().map(|v| v.re).collect();
    w2s.sort_by(f64::total_cmp);
    let mut shapes = DMatrix::zeros(n, n);
    let (mut eigenvalues, mut natural_frequencies, mut kinds) =
        (Vec::new(), Vec::new(), Vec::new());
    // Each cluster of equal ω² (within 1e-8 of their size) has as many independent null
    // vectors of K − ω² M as members, the smallest singular values' right vectors; fewer (a
    // defective ω², at a divergence–flutter boundary) means no basis of modes.
    let mut start = 0;
    let mut cluster: Vec<nalgebra::DVector<f64>> = Vec::new();
    for (col, &w2) in w2s.iter().enumerate() {
        if col == start {
            // Equal to 1e-8 of their own size (a stiff mode beside soft ones must not merge
            // the soft ones), or both at rounding of the largest.
            let end = (col..n)
                .take_while(|&j| {
                    (w2s[j] - w2).abs() <= 1e-8 * w2.abs().max(EIGENVALUE_ROUNDING * largest)
                })
                .last()
                .map_or(col + 1, |j| j + 1);
            let mean = w2s[col..end].iter().sum::<f64>() / (end - col) as f64;
            let svd = (&lin.stiffness_matrix - &lin.mass_matrix * mean).svd(false, true);
            let v_t = svd.v_t.ok_or(ModalError::NonFinite { q: lin.q.clone() })?;
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&a, &b| svd.singular_values[a].total_cmp(&svd.singular_values[b]));
            let top = svd.singular_values.max();
            if svd.singular_values[order[end - col - 1]] > 1e-6 * top {
                return Ok(None);
            }
            cluster = order[..end - col]
                .iter()
                .map(|&i| v_t.row(i).transpose())
                .collect();
            start = end;
        }
        let mut psi = cluster.remove(0);
        let norm = (psi.transpose() * &lin.mass_matrix * &psi)[(0, 0)].sqrt();
        psi /= norm;
        if psi[psi.iamax()] < 0.0 {
            psi = -psi;
        }
        if !psi.iter().all(|v| v.is_finite()) {
            return Err(ModalError::NonFinite { q: lin.q.clone() });
        }
        shapes.set_column(col, &psi);
        let (w2, kind) = if w2.abs() <= EIGENVALUE_ROUNDING * largest {
            (0.0, ModeKind::ZeroFrequency)
        } else if w2 < 0.0 {
            let growth_rate = (-w2).sqrt();
            (w2, ModeKind::Unstable { growth_rate })
        } else {
            (w2, ModeKind::Oscillatory)
        };
        eigenvalues.push(w2);
        natural_frequencies.push(w2.max(0.0).sqrt());
        kinds.push(kind);
    }
    Ok(Some(NormalModes {
        eigenvalues,
        natural_frequencies,
        kinds,
        mode_shapes: shapes,
        stiffness_asymmetry: lin.stiffness_asymmetry(),
        symmetric_part_only: false,
    }))
}

/// An eigenvalue `ω²` below this fraction of its own scale ([`is_zero_frequency`]) is a
/// zero-frequency (rigid-body) mode: far above the rounding of a rigid-body mode (`ε` times
/// the stiffness acting on it, ~1e-16) and far below any real stiffness of its coordinates.
const ZERO_FREQUENCY: f64 = 1e-9;

/// Below this fraction of the largest `|ω²|` an eigenvalue is rounding whatever its own scale:
/// the symmetric eigensolver's error is `ε ‖K̃‖` in absolute terms (a few hundred `ε` here),
/// so a rigid-body mode of a soft part beside a stiff part has a computed `ω²` of that size.
const EIGENVALUE_ROUNDING: f64 = 1e-13;

/// Whether the eigenvalue `w2` of the reduced stiffness `reduced`, `K̃ = L⁻¹ K L⁻ᵀ`, with the
/// unit eigenvector `v`, is a zero frequency: `|ω²|` at most
/// [`ZERO_FREQUENCY`] of its own scale `max_i Σ_j |K̃ᵢⱼ| |vⱼ|` — the stiffness that acts on
/// the mode's own coordinates — or at most [`EIGENVALUE_ROUNDING`] of `largest`, the largest
/// `|ω²|` (all zero when `largest` is 0).
///
/// Its own scale, not the largest `|ω²|`: beside a stiff mode (`ω² = 1e8`) a soft but real one
/// (`ω² = 1e-3`, a slack spring) is an oscillation, while the rigid-body mode of a free–free
/// chain has `ω²` at rounding of the springs it stretches (none: `K̃ v ≈ 0` while `|K̃| |v|` is
/// of the springs' size). The free-response study's test for a defective matrix judges each
/// eigenvalue on its own scale in the same way.
fn is_zero_frequency(
    w2: f64,
    reduced: &DMatrix<f64>,
    v: nalgebra::DVectorView<'_, f64>,
    largest: f64,
) -> bool {
    if largest == 0.0 || w2.abs() <= EIGENVALUE_ROUNDING * largest {
        return true;
    }
    let own = (0..reduced.nrows())
        .map(|i| {
            (0..reduced.ncols())
                .map(|j| reduced[(i, j)].abs() * v[j].abs())
                .sum::<f64>()
        })
        .fold(0.0f64, f64::max);
    w2.abs() <= ZERO_FREQUENCY * own
}

/// The eigenvalues `ω²` of the non-symmetric `M⁻¹K` (lecture 22's route), real parts sorted
/// ascending, for comparison with [`normal_modes`] (lecture 24's symmetric route).
///
/// # Errors
/// [`ModalError::SingularMassMatrix`].
pub fn eigenvalues_of_m_inv_k(lin: &Linearization) -> Result<Vec<f64>, ModalError> {
    let chol = lin.mass_cholesky()?;
    let mk = chol.solve(&lin.stiffness_matrix);
    let mut values: Vec<f64> = crate::linalg::eigenvalues(&mk)
        .ok_or_else(|| ModalError::EigenvaluesDidNotConverge {
            size: mk.nrows(),
            q: lin.q.clone(),
        })?
        .iter()
        .map(|c| c.re)
        .collect();
    values.sort_by(f64::total_cmp);
    Ok(values)
}

/// The matrix exponential `e^A`, for the free response `y(t) = e^{At} y(0)` of the linearised
/// system (lectures 30–32, HW32) and the monodromy of a constant-coefficient system.
///
/// nalgebra's `Matrix::exp`: scaling and squaring with the Padé approximant of degree 3, 5,
/// 7, 9 or 13, the cheapest whose backward error is below the unit roundoff for this `A`
/// (Higham 2005's method, Algorithm 2.3, with the degree and scaling chosen from the norms of
/// powers of `A` as in Al-Mohy and Higham 2009, Algorithm 6.1, which avoids overscaling).
/// Against closed forms it was as accurate as a fixed degree-13 Padé on every case measured
/// and 400 times more accurate on a stiff two-mass spring (relative error 1.2e-11 against
/// 5.0e-9 at `‖At‖₁ = 2e8`), at 1.2–1.9 times its time (docs/performance.md, "Matrix
/// exponential").
///
/// # Shapes
/// `a` is square, `n × n`; so is the result. A non-finite entry gives an all-NaN result.
/// Beyond `‖A‖₁ = 10¹¹`, `e^A = (e^{A/2^k})^{2^k}` with the smallest `k` that brings the norm
/// below it: nalgebra's own choice of scaling uses `‖|A|²⁷‖₁ ≤ ‖A‖₁²⁷`, which overflows above
/// ~2.6·10¹¹, and an infinite value made its squaring loop run (practically) forever for a
/// matrix whose `|A|` grows where `A` does not (a nilpotent `A` with cancelling entries). Such
/// a defective matrix of norm ~10¹² is beyond scaling and squaring in `f64` (a perturbation ε
/// of `e^{A/2^k}` splits its double eigenvalue by √ε, which `2^k` squarings blow up): the
/// result is finite but not accurate.
///
/// # References
/// N. J. Higham, "The scaling and squaring method for the matrix exponential revisited",
/// SIAM J. Matrix Anal. Appl. 26 (2005) 1179–1193; A. H. Al-Mohy, N. J. Higham, "A new
/// scaling and squaring algorithm for the matrix exponential", SIAM J. Matrix Anal. Appl. 31
/// (2009) 970–989.
pub fn matrix_exponential(a: &DMatrix<f64>) -> DMatrix<f64> {
    /// Largest `‖A‖₁` handed to nalgebra: `‖A‖₁²⁷` stays finite below ~2.6·10¹¹.
    const LARGEST_NORM: f64 = 1e11;
    let n = a.nrows();
    if n == 0 {
        return DMatrix::identity(0, 0);
    }
    if a.iter().any(|v| !v.is_finite()) {
        return DMatrix::from_element(n, n, f64::NAN);
    }
    let norm = a.column_iter().map(|c| c.lp_norm(1)).fold(0.0, f64::max);
    let k = if norm > LARGEST_NORM {
        (norm / LARGEST_NORM).log2().ceil() as i32
    } else {
        0
    };
    let mut r = (a * 2f64.powi(-k)).exp();
    for _ in 0..k {
        r = &r * &r;
    }
    r
}
