//! Periodic orbits by shooting (HW5, HW39): Newton on the flow map `φ_T(y₀)` of an autonomous
//! model, with the monodromy matrix `Φ = ∂φ_T/∂y₀` from the variational equations
//! ([`monodromy_matrix`]), the period an unknown or fixed, and the Floquet multipliers of the
//! orbit found (`eomgen study periodic-orbit`).
//!
//! # The method
//! A periodic orbit of `ẏ = f(y)` through `y₀` with period `T` is a zero of the shooting
//! residual `r(y₀, T) = φ_T(y₀) − y₀` (`n = 2 num_dofs()` equations), whose Jacobian is
//! `[Φ − I | f(φ_T(y₀))]` (`n × (n + 1)`; with the period fixed, `Φ − I`). For an autonomous
//! system this Jacobian is singular at a solution, and more so for a conservative one:
//!
//! - **phase**: every point of the orbit is a solution, `(Φ − I) f(y₀) = 0`. One phase
//!   condition `f(yₖ)ᵀ (y₀ − yₖ) = 0` (Poincaré's, anchored at the current iterate `yₖ`:
//!   the correction is orthogonal to the flow) is added as a row (Seydel 2010, §7.3; Doedel
//!   2007, §2.2);
//! - **energy**: in a conservative model (`T + V` constant, no explicit `t`) periodic orbits come
//!   in one-parameter families along which the energy and the period vary together, so the
//!   period-free problem fixes the energy, `H(y₀) = E`, by a further row (the choice of
//!   Muñoz-Almaraz et al. 2003, who continue such families in `E` or `T`); with the period
//!   fixed the family is pinned by `T` and the energy is free;
//! - **symmetries**: each further continuous symmetry (a translation, a rotation) or hidden
//!   one (Kepler's Laplace–Runge–Lenz vector) moves the orbit along a family of equal energy
//!   and period, and leaves the Jacobian rank deficient at the solution.
//!
//! The augmented system (`n + 1` or `n + 2` rows) is solved by Gauss–Newton with the
//! minimum-norm step `Δ = −J⁺ r` from the singular value decomposition of `J` (Deuflhard
//! 2011, §4.3–4.4: the Moore–Penrose pseudo-inverse Gauss–Newton method converges locally
//! quadratically to a point of the solution manifold, which need not be isolated). Singular
//! values below `max(ε σ_max, κ ‖r‖)` are dropped: along a continuous symmetry `g`, the
//! residual is equivariant, `r(g y₀) = g r(y₀)`, so `J` maps the symmetry's generator to
//! `O(‖r‖)` and those directions carry noise, not information (`ε =`
//! [`RANK_TOLERANCE`], `κ =` [`SYMMETRY_FACTOR`]). The number of singular values dropped at
//! the solution is reported as [`PeriodicOrbit::symmetries`]. Each step is damped (halved up to
//! 12 times) until the residual norm decreases; if none does, the cut is lowered to `κ‖r‖/10`,
//! `κ‖r‖/100`, then `ε σ_max`, and the step tried again.
//!
//! The period's unknown is its relative change `ΔT/T` (the column `T f(φ_T(y₀))`), so that the
//! minimum-norm step weighs it like a change of state. Far from the orbit the integrations run
//! at `1e-4 ‖r‖²` (at most [`LOOSEST_TOL`]): Newton's next residual is about `‖r‖²`, and no
//! more accuracy is needed to reach it. An evaluation whose residual comes out below what its
//! tolerance resolves (tolerance above [`RESOLUTION_FACTOR`] `‖r‖`: a start already close to
//! the orbit, or a step better than quadratic) is integrated again more tightly before it is
//! used, so that no step is computed from, and no damped step compared with, a residual that
//! is integration error. Convergence is declared only on an evaluation at
//! [`PeriodicOrbitOptions::integration_tol`].
//!
//! The Floquet multipliers are the eigenvalues of `Φ(T)` at the solution
//! ([`floquet_multipliers`]). For a Hamiltonian system each first integral with its symmetry
//! gives a pair of multipliers 1 (a 2 × 2 Jordan block): time shift and energy, and one pair per
//! further independent symmetry with its conserved momentum; the figure eight of three bodies
//! has 8 (time/energy, two translations/linear momenta, rotation/angular momentum), an orbit
//! of a planar central force 4 (time/energy, rotation/angular momentum: every multiplier).
//!
//! # References
//! - R. Seydel, *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer 2010, §7.3
//!   (periodic solutions by shooting, phase conditions) and §7.4–7.5 (monodromy, multipliers).
//! - E. J. Doedel, "Lecture notes on numerical analysis of nonlinear equations", in
//!   *Numerical Continuation Methods for Dynamical Systems*, Springer 2007, §2
//!   (periodic solutions, phase condition).
//! - F. J. Muñoz-Almaraz, E. Freire, J. Galán, E. Doedel, A. Vanderbauwhede, "Continuation of
//!   periodic orbits in conservative and Hamiltonian systems", Physica D 181 (2003) 1–38.
//! - P. Deuflhard, *Newton Methods for Nonlinear Problems*, Springer 2011, §4.3–4.4
//!   (Gauss–Newton methods for underdetermined systems, Moore–Penrose pseudo-inverse).
//! - C. Simó, "New families of solutions in N-body problems", European Congress of
//!   Mathematics (Barcelona 2000), Progr. Math. 201, Birkhäuser 2001, 101–115 (the figure
//!   eight computed and continued numerically, `T = 6.32591398`).

use nalgebra::{Complex, DMatrix, DVector, Dyn, SVD};
use serde::Serialize;

use crate::integrate::{DormandPrince853, Integrator, IntegratorOptions, OutputTimes, Stats};
use crate::linear::monodromy::{
    FloquetError, FloquetOptions, FloquetStability, floquet_multipliers, monodromy_matrix,
};
use crate::model_info::ModelInfo;
use crate::ode::{OdeSystem, RhsError};

mod newton;

/// Relative floor `ε` of the singular values kept in a Gauss–Newton step: `σ ≤ ε σ_max` is
/// rank deficiency (the monodromy matrix is integrated to about 1e-12).
pub const RANK_TOLERANCE: f64 = 1e-9;

/// The loosest integration tolerance of an evaluation far from the orbit.
pub const LOOSEST_TOL: f64 = 1e-8;

/// An evaluation's residual is used (for a step, or compared with another's) only when its
/// integration tolerance is at most this times its merit, or is the tolerance asked for;
/// otherwise it is integrated again more tightly. DOP853's error at the end of a period is a
/// few to ten times its tolerance (measured: 4 on the figure eight at 1e-8, whose residual
/// from the model's 8-decimal data is 7.5e-8 but reads 3.7e-8 at 1e-8; 10 on a rosette of
/// period 39.6 s), so the residual is then known to about 1 % of itself. The schedule
/// `1e-4 ‖r‖²` meets this whenever Newton's next residual is at least `0.1 ‖r‖²`; it misses
/// it from a start already close to the orbit, or after a step better than quadratic.
pub const RESOLUTION_FACTOR: f64 = 1e-3;

/// Most halvings of a step before a lower cut is tried.
const MAX_HALVINGS: usize = 12;

/// Factor `κ` of the residual below which a singular value is dropped, `σ ≤ κ ‖r‖`: along a
/// continuous symmetry `J` maps the generator to `O(‖r‖)` (measured: 0.5–1.5 ‖r‖ on the
/// figure eight and a rosette); a genuine direction so weak is left for a later iteration, when
/// the residual is smaller.
pub const SYMMETRY_FACTOR: f64 = 3.0;

/// Why no periodic orbit was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PeriodicOrbitError {
    /// The model has constraints: the variational equations need the exact Jacobian of an
    /// unconstrained model.
    #[error(
        "`{model}` has constraints ({constraints}); periodic orbits are computed for unconstrained models only (the variational equations need the exact Jacobian ∂f/∂y)"
    )]
    Constrained {
        /// The model.
        model: String,
        /// Its constraints, comma separated.
        constraints: String,
    },
    /// The period guess is not a finite positive number.
    #[error("the period must be a finite positive number of seconds, got {period}")]
    InvalidPeriod {
        /// Given (s).
        period: f64,
    },
    /// A tolerance is outside its range.
    #[error("{what} must be in [{smallest:e}, {largest:e}], got {value:e}")]
    InvalidTolerance {
        /// Which tolerance.
        what: &'static str,
        /// Given.
        value: f64,
        /// Smallest allowed.
        smallest: f64,
        /// Largest allowed.
        largest: f64,
    },
    /// The energy level, or the energy `T + V` at the start, is not finite (with the period
    /// free in a conservative model, where the energy is fixed).
    #[error("the energy must be finite to be fixed, got {energy}")]
    InvalidEnergy {
        /// Given (J).
        energy: f64,
    },
    /// The start has the wrong length or a non-finite entry.
    #[error("the start must have {expected} finite entries [q; q̇], got {found:?}")]
    InvalidStart {
        /// `2 num_dofs()`.
        expected: usize,
        /// Given.
        found: Vec<f64>,
    },
    /// The model depends on `t` and the period was left free: a forced system's periodic
    /// responses have the forcing's period.
    #[error(
        "`{model}` depends explicitly on t, so its periodic responses have the forcing's period: fix the period to it"
    )]
    TimeDependent {
        /// The model.
        model: String,
    },
    /// Newton did not converge.
    #[error(
        "no periodic orbit: after {iterations} Newton iterations the residual ‖φ_T(y₀) − y₀‖ is {residual:.3e} (allowed {allowed:.3e}) at T = {period}{}",
        if *.stalled { "; no damped step reduced it" } else { "" }
    )]
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// The last residual norm (units of `y`).
        residual: f64,
        /// What convergence needs.
        allowed: f64,
        /// The last period (s).
        period: f64,
        /// Whether Newton stopped because no damped step reduced the residual.
        stalled: bool,
    },
    /// The iterates collapsed to an equilibrium: `T → 0`, or `y` hardly moves over a period.
    #[error(
        "the orbit collapsed to an equilibrium after {iterations} Newton iterations: T = {period:.6e} s and the state moves {travel:.3e} over a period (|f(y₀)| T); start on a motion, not at rest"
    )]
    Collapsed {
        /// Iterations done.
        iterations: usize,
        /// The period there (s).
        period: f64,
        /// `‖f(y₀)‖ T`: how far the state moves over a period (units of `y`).
        travel: f64,
    },
    /// Newton closed the state to its tolerance, but no Floquet multiplier is 1, which every
    /// periodic orbit of an autonomous model has (the flow's own direction, `Φ f(y₀) =
    /// f(y₀)`): near a stable equilibrium of a damped model every small state closes to the
    /// tolerance, and that is not an orbit.
    #[error(
        "no periodic orbit: Newton closed the state to {residual:.3e} with T = {period:.6e} s, but no Floquet multiplier is within {tolerance:e} of 1 (the largest |μ| is {spectral_radius:.6}), as every periodic orbit of an autonomous model has one along the flow; the state moves {travel:.3e} over that time, so it is near an equilibrium that motions decay to or leave, not on an orbit"
    )]
    NoUnitMultiplier {
        /// The period there (s).
        period: f64,
        /// The residual Newton reached.
        residual: f64,
        /// `‖f(y₀)‖ T` (units of `y`).
        travel: f64,
        /// The tolerance of a multiplier 1.
        tolerance: f64,
        /// `max |μ|`.
        spectral_radius: f64,
    },
    /// The integration of the state and variational equations, or the multipliers, failed.
    #[error(transparent)]
    Floquet(#[from] FloquetError),
    /// The right-hand side failed at the start.
    #[error("the right-hand side failed at the start: {0}")]
    Rhs(RhsError),
}

/// Settings of [`periodic_orbit`].
#[derive(Debug, Clone, PartialEq)]
pub struct PeriodicOrbitOptions {
    /// Newton's start `y₀ = [q; q̇]` (length `2 num_dofs()`); `None`: the model's initial
    /// state.
    pub start: Option<Vec<f64>>,
    /// The period (s): the initial guess, or the period itself with `fix_period`.
    pub period: f64,
    /// Keep the period fixed (unknowns `y₀` only) instead of solving for it.
    pub fix_period: bool,
    /// The energy level `E` (J) of the orbit sought with the period free in a conservative
    /// model; `None`: the energy of the start. Ignored otherwise.
    pub energy: Option<f64>,
    /// Convergence: `‖φ_T(y₀) − y₀‖₂ ≤ tol (1 + ‖y₀‖₂)` and, with an energy row,
    /// `|H(y₀) − E| ≤ tol (1 + |E|)`; in `[1e-13, 1e-3]` and not below the integration's
    /// tolerance (default 1e-10).
    pub tol: f64,
    /// Relative and absolute tolerance of DOP853 on the state and the variational equations,
    /// in `[1e-14, 1e-6]` (default 1e-12).
    pub integration_tol: f64,
    /// Most Newton iterations (default 30).
    pub max_iterations: usize,
    /// Number of samples of the orbit over one period, ends included (default 400, at least 2).
    pub samples: usize,
    /// A multiplier `μ` counts as 1 (a trivial multiplier) when `|μ − 1| ≤` this, in
    /// `[1e-8, 0.1]` (default 1e-3: the multipliers 1 come in Jordan blocks, whose computed
    /// eigenvalues split by the square root of the error of `Φ` times the block's shear — up
    /// to 2e-4 on a rosette of period 37.6 s integrated at 1e-12 — symmetrically about 1, so
    /// that their mean stays 1 to about that error).
    pub unit_multiplier_tolerance: f64,
}

impl PeriodicOrbitOptions {
    /// Defaults around a period guess `period` (s).
    pub fn new(period: f64) -> Self {
        Self {
            start: None,
            period,
            fix_period: false,
            energy: None,
            tol: 1e-10,
            integration_tol: FloquetOptions::DEFAULT_TOL,
            max_iterations: 30,
            samples: 400,
            unit_multiplier_tolerance: 1e-3,
        }
    }
}

/// One Newton iteration of [`periodic_orbit`], at its start.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NewtonStep {
    /// `‖φ_T(y₀) − y₀‖₂` at the iterate (units of `y`).
    pub residual: f64,
    /// `H(y₀) − E` at the iterate (J; `None` without an energy row).
    pub energy_residual: Option<f64>,
    /// The period of the iterate (s).
    pub period: f64,
    /// The rank of the Jacobian used for the step (`None` for the last iterate, which took
    /// no step).
    pub rank: Option<usize>,
    /// The damping factor of the step taken (1 = a full Newton step).
    pub damping: Option<f64>,
}

/// The orbit sampled over one period, for a chart.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrbitSamples {
    /// Times from 0 to `T` (s).
    pub t: Vec<f64>,
    /// The state `[q; q̇]` at each time.
    pub y: Vec<Vec<f64>>,
    /// The model's points `[x, y, z]` (m) at each time, in the description's order.
    pub points: Vec<Vec<[f64; 3]>>,
}

/// A periodic orbit found by [`periodic_orbit`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PeriodicOrbit {
    /// The model.
    pub model: String,
    /// The period `T` (s).
    pub period: f64,
    /// Whether the period was fixed.
    pub fix_period: bool,
    /// The names of the state's entries: the coordinates, then their rates (`x_dot`).
    pub state_names: Vec<String>,
    /// The initial state `y₀ = [q; q̇]` on the orbit.
    pub initial_state: Vec<f64>,
    /// `‖φ_T(y₀) − y₀‖₂` (units of `y`).
    pub residual: f64,
    /// `max |φ_T(y₀) − y₀|` (units of `y`).
    pub residual_max: f64,
    /// `T + V` at `y₀` (J).
    pub energy: f64,
    /// The energy level imposed (J; `None` when the energy was free).
    pub energy_level: Option<f64>,
    /// Whether the model is conservative (`T + V` a constant of the motion).
    pub conservative: bool,
    /// Newton iterations taken (steps; 0 if the start was already periodic).
    pub iterations: usize,
    /// Every iterate, the last one the solution.
    pub history: Vec<NewtonStep>,
    /// The number of singular values of the augmented Jacobian dropped at the solution: the
    /// dimension of the family of orbits of the same period (and energy) through `y₀` — its
    /// continuous symmetries beyond the time shift.
    pub symmetries: usize,
    /// The Floquet multipliers (eigenvalues of the monodromy matrix `Φ(T)`), largest modulus
    /// first.
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub multipliers: Vec<Complex<f64>>,
    /// How many multipliers are 1 to within
    /// [`PeriodicOrbitOptions::unit_multiplier_tolerance`].
    pub unit_multipliers: usize,
    /// The tolerance used for that count.
    pub unit_multiplier_tolerance: f64,
    /// `|mean − 1|` of the multipliers counted as 1: the mean of a cluster of eigenvalues is
    /// well conditioned where each one is not (0 if there are none).
    pub unit_mean_error: f64,
    /// `max |μ|`.
    pub spectral_radius: f64,
    /// `max |μ|` over the nontrivial multipliers (those not counted as 1); 1 if every
    /// multiplier is 1.
    pub nontrivial_spectral_radius: f64,
    /// The linear stability that the nontrivial multipliers imply (tolerance
    /// `√integration_tol`): the trivial ones stand for deviations along the family and the
    /// symmetries, which grow at most linearly in time.
    pub stability: FloquetStability,
    /// The monodromy matrix `Φ(T)` at the solution (`n × n`).
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub monodromy_matrix: DMatrix<f64>,
    /// The orbit over one period.
    pub orbit: OrbitSamples,
    /// The work of every integration together (`wall_time_s` summed).
    pub stats: Stats,
}

/// The rows and unknowns of the shooting problem.
struct Shooting {
    n: usize,
    free_period: bool,
    phase: bool,
    energy: Option<f64>,
}

/// One evaluation: residual and monodromy at `(y, T)`.
struct Evaluation {
    y: Vec<f64>,
    period: f64,
    monodromy: DMatrix<f64>,
    end: Vec<f64>,
    residual: Vec<f64>,
    residual_norm: f64,
    energy_residual: Option<f64>,
    /// The merit `‖[r; (H − E)/s_E]‖₂` that damping decreases.
    merit: f64,
    /// The integration tolerance of this evaluation.
    tol: f64,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The model's right-hand side alone (its events left out), for sampling the orbit.
struct Flow<'a>(&'a mut dyn OdeSystem);

impl OdeSystem for Flow<'_> {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        self.0.rhs(t, y, dy)
    }
}

/// Finds a periodic orbit of the autonomous `model` by shooting from
/// [`PeriodicOrbitOptions::start`] with the period guess [`PeriodicOrbitOptions::period`]:
/// Gauss–Newton with minimum-norm steps on `φ_T(y₀) − y₀ = 0` with a phase condition and, for
/// a conservative model with the period free, the energy `H(y₀) = E` (see the module
/// documentation for the method and its sources). Returns the period, the initial state, the
/// residual, the iterations, the Floquet multipliers and the orbit sampled over one period.
///
/// # Shapes
/// `start` and [`PeriodicOrbit::initial_state`] have `n = 2 num_dofs()` entries; the monodromy
/// matrix is `n × n` with `n` multipliers.
///
/// # Errors
/// [`PeriodicOrbitError::Constrained`], [`PeriodicOrbitError::InvalidPeriod`],
/// [`PeriodicOrbitError::InvalidTolerance`], [`PeriodicOrbitError::InvalidEnergy`],
/// [`PeriodicOrbitError::InvalidStart`], [`PeriodicOrbitError::TimeDependent`] (period free on
/// a model depending on `t`), [`PeriodicOrbitError::NotConverged`] (with the residual and
/// iterations), [`PeriodicOrbitError::Collapsed`] (`T → 0` or `y` constant),
/// [`PeriodicOrbitError::Floquet`] (an integration failed, or the eigenvalues).
///
/// # Examples
/// `tests/periodic_orbit.rs`: the figure eight, a Kepler circle and a closed rosette of a
/// non-Kepler central force.
pub fn periodic_orbit(
    model: &mut dyn ModelInfo,
    options: &PeriodicOrbitOptions,
) -> Result<PeriodicOrbit, PeriodicOrbitError> {
    let Setup {
        name,
        start,
        time_dependent,
        conservative,
        energy_level,
        shooting,
    } = set_up(model, options)?;
    let final_tol = options.integration_tol;
    let newton = Newton {
        shooting: &shooting,
        options,
        final_tol,
    };
    let mut stats = Stats::default();
    let Solution {
        current,
        iterations,
        rank: rank_used,
        history,
    } = newton.solve(model, start, &mut stats)?;
    let symmetries = (shooting.n + usize::from(shooting.free_period)) - rank_used;
    let multipliers = classify_multipliers(model, &current, options, time_dependent)?;
    let orbit = sample_orbit(model, &current, options, &mut stats)?;
    let d = model.description();
    let state_names = (0..2 * d.num_dofs()).map(|i| d.state_name(i)).collect();
    let residual_max = current.residual.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    Ok(PeriodicOrbit {
        model: name,
        period: current.period,
        fix_period: options.fix_period,
        state_names,
        energy: model.energy(0.0, &current.y),
        initial_state: current.y,
        residual: current.residual_norm,
        residual_max,
        energy_level,
        conservative,
        iterations,
        history,
        symmetries,
        multipliers: multipliers.multipliers,
        unit_multipliers: multipliers.unit_multipliers,
        unit_multiplier_tolerance: options.unit_multiplier_tolerance,
        unit_mean_error: multipliers.unit_mean_error,
        spectral_radius: multipliers.spectral_radius,
        nontrivial_spectral_radius: multipliers.nontrivial_spectral_radius,
        stability: multipliers.stability,
        monodromy_matrix: current.monodromy,
        orbit,
        stats,
    })
}

/// What [`periodic_orbit`] settles before its first integration.
struct Setup {
    /// The model's name.
    name: String,
    /// Newton's start `y₀ = [q; q̇]` (`n = 2 num_dofs()` finite entries).
    start: Vec<f64>,
    /// Whether `f(t, y)` changes with `t` at the start.
    time_dependent: bool,
    /// Whether `T + V` is a constant of the motion (a conservative model, no explicit `t`).
    conservative: bool,
    /// The energy level `E` (J) of the energy row (`None` without one).
    energy_level: Option<f64>,
    /// The rows and unknowns of the shooting problem.
    shooting: Shooting,
}

/// Checks the model and the options and settles the shooting problem of [`periodic_orbit`]:
/// the start `y₀` (the options' or the model's initial state, `n = 2 num_dofs()` entries),
/// whether `f` depends on `t` (then the period must be fixed and there is no phase row),
/// whether the model is conservative and, with the period free in a conservative model, the
/// energy level `E` (J) of the energy row (the options', or `T + V` at the start). Every
/// refusal before the first integration comes from here, in the order the checks are made:
/// [`PeriodicOrbitError::Constrained`], then [`validate`]'s, then
/// [`PeriodicOrbitError::InvalidStart`], [`PeriodicOrbitError::Rhs`],
/// [`PeriodicOrbitError::TimeDependent`] and [`PeriodicOrbitError::InvalidEnergy`].
fn set_up(
    model: &mut dyn ModelInfo,
    options: &PeriodicOrbitOptions,
) -> Result<Setup, PeriodicOrbitError> {
    let name = model.description().name.to_string();
    if !model.description().constraints.is_empty() {
        return Err(PeriodicOrbitError::Constrained {
            model: name,
            constraints: model.description().constraints.join(", "),
        });
    }
    validate(options)?;
    let n = 2 * model.num_dofs();
    let start = options
        .start
        .clone()
        .unwrap_or_else(|| model.initial_state());
    if start.len() != n || start.iter().any(|v| !v.is_finite()) {
        return Err(PeriodicOrbitError::InvalidStart {
            expected: n,
            found: start,
        });
    }
    let time_dependent = depends_on_time(model, &start, options.period)?;
    if time_dependent && !options.fix_period {
        return Err(PeriodicOrbitError::TimeDependent { model: name });
    }
    let conservative = model.description().conservative && !time_dependent;
    let energy_level = (conservative && !options.fix_period)
        .then(|| options.energy.unwrap_or_else(|| model.energy(0.0, &start)));
    if let Some(level) = energy_level {
        let at_start = model.energy(0.0, &start);
        for energy in [level, at_start] {
            if !energy.is_finite() {
                return Err(PeriodicOrbitError::InvalidEnergy { energy });
            }
        }
    }
    let shooting = Shooting {
        n,
        free_period: !options.fix_period,
        phase: !time_dependent,
        energy: energy_level,
    };
    Ok(Setup {
        name,
        start,
        time_dependent,
        conservative,
        energy_level,
        shooting,
    })
}

/// The fixed data of the Gauss–Newton iteration of [`periodic_orbit`] (the iteration itself,
/// [`Newton::solve`], is in the child module `newton`).
struct Newton<'a> {
    /// The rows and unknowns.
    shooting: &'a Shooting,
    /// The options (period guess, tolerances, most iterations).
    options: &'a PeriodicOrbitOptions,
    /// The integration tolerance asked for ([`PeriodicOrbitOptions::integration_tol`]): the
    /// only one at which convergence is declared.
    final_tol: f64,
}

/// Where the Newton iteration of [`periodic_orbit`] ended.
struct Solution {
    /// The converged evaluation, at the integration tolerance asked for.
    current: Evaluation,
    /// Newton steps taken.
    iterations: usize,
    /// The rank of the augmented Jacobian at the solution (for the symmetry count).
    rank: usize,
    /// Every iterate, the last one the solution.
    history: Vec<NewtonStep>,
}

/// The Floquet multipliers at the solution and what [`PeriodicOrbit`] reports of them.
struct Multipliers {
    /// The eigenvalues of `Φ(T)`, largest modulus first.
    multipliers: Vec<Complex<f64>>,
    /// `max |μ|`.
    spectral_radius: f64,
    /// How many are 1 to within the options' tolerance.
    unit_multipliers: usize,
    /// `|mean − 1|` of those (0 if none).
    unit_mean_error: f64,
    /// `max |μ|` over the others (1 if none).
    nontrivial_spectral_radius: f64,
    /// The stability the others imply.
    stability: FloquetStability,
}

/// The Floquet multipliers of the converged evaluation `current` (eigenvalues of its `n × n`
/// monodromy matrix, tolerance `√integration_tol`), split into the trivial ones (within
/// [`PeriodicOrbitOptions::unit_multiplier_tolerance`] of 1) and the others, whose spectral
/// radius sets the stability.
///
/// # Errors
/// [`PeriodicOrbitError::Floquet`] (the eigenvalues), [`PeriodicOrbitError::Rhs`], and
/// [`PeriodicOrbitError::NoUnitMultiplier`] when an autonomous model's "orbit" keeps neither
/// a multiplier 1 nor the flow's direction (`Φ f(y₀) = f(y₀)`): the state only closed to the
/// tolerance near an equilibrium.
fn classify_multipliers(
    model: &mut dyn ModelInfo,
    current: &Evaluation,
    options: &PeriodicOrbitOptions,
    time_dependent: bool,
) -> Result<Multipliers, PeriodicOrbitError> {
    let final_tol = options.integration_tol;
    let analysis =
        floquet_multipliers(current.monodromy.clone(), current.period, final_tol.sqrt())?;
    let one = Complex::new(1.0, 0.0);
    let (trivial, nontrivial): (Vec<Complex<f64>>, Vec<Complex<f64>>) = analysis
        .multipliers
        .iter()
        .partition(|m| (*m - one).norm() <= options.unit_multiplier_tolerance);
    let unit_multipliers = trivial.len();
    // An autonomous model's orbit has the multiplier 1 of the flow's direction: `Φ f(y₀) =
    // f(y₀)`. Without it the state closed only to the tolerance: three damped masses shrank
    // to ‖y₀‖ = 8e-10 (multipliers 0.946 and below, `Φ f` 5 % short of `f`) and were reported
    // an asymptotically stable orbit. The flow's direction is tested itself, not only the
    // multipliers: near a separatrix the pair at 1 is a Jordan block with a large shear,
    // which rounding splits farther than the tolerance, while `Φ f = f` still holds.
    let f0 = rhs(model, &current.y)?;
    let flow = nalgebra::DVector::from_column_slice(&f0);
    let flow_kept = (&current.monodromy * &flow - &flow).norm()
        <= options.unit_multiplier_tolerance * flow.norm();
    if !time_dependent && unit_multipliers == 0 && !flow_kept {
        return Err(PeriodicOrbitError::NoUnitMultiplier {
            period: current.period,
            residual: current.residual_norm,
            travel: norm(&f0) * current.period,
            tolerance: options.unit_multiplier_tolerance,
            spectral_radius: analysis.spectral_radius,
        });
    }
    let unit_mean_error = if trivial.is_empty() {
        0.0
    } else {
        (trivial.iter().sum::<Complex<f64>>() / trivial.len() as f64 - one).norm()
    };
    let nontrivial_spectral_radius = if nontrivial.is_empty() {
        1.0
    } else {
        nontrivial.iter().map(|m| m.norm()).fold(0.0, f64::max)
    };
    let stability = FloquetStability::of(nontrivial_spectral_radius, final_tol.sqrt());
    Ok(Multipliers {
        multipliers: analysis.multipliers,
        spectral_radius: analysis.spectral_radius,
        unit_multipliers,
        unit_mean_error,
        nontrivial_spectral_radius,
        stability,
    })
}

fn validate(options: &PeriodicOrbitOptions) -> Result<(), PeriodicOrbitError> {
    if !(options.period.is_finite() && options.period > 0.0) {
        return Err(PeriodicOrbitError::InvalidPeriod {
            period: options.period,
        });
    }
    let range = |what, value: f64, smallest: f64, largest: f64| {
        if (smallest..=largest).contains(&value) {
            Ok(())
        } else {
            Err(PeriodicOrbitError::InvalidTolerance {
                what,
                value,
                smallest,
                largest,
            })
        }
    };
    range(
        "the integration tolerance",
        options.integration_tol,
        1e-14,
        1e-6,
    )?;
    range(
        "the Newton tolerance",
        options.tol,
        options.integration_tol.max(1e-13),
        1e-3,
    )?;
    range(
        "the tolerance on a unit multiplier",
        options.unit_multiplier_tolerance,
        1e-8,
        0.1,
    )?;
    Ok(())
}

fn rhs(model: &mut dyn ModelInfo, y: &[f64]) -> Result<Vec<f64>, PeriodicOrbitError> {
    let mut f = vec![0.0; y.len()];
    model
        .as_ode_mut()
        .rhs(0.0, y, &mut f)
        .map_err(PeriodicOrbitError::Rhs)?;
    Ok(f)
}

/// Whether `f(t, y)` at the start changes with `t` (at `t` = 0, 0.37 T and 0.71 T), relative to
/// its size.
fn depends_on_time(
    model: &mut dyn ModelInfo,
    y: &[f64],
    period: f64,
) -> Result<bool, PeriodicOrbitError> {
    let n = y.len();
    let mut f0 = vec![0.0; n];
    let mut f1 = vec![0.0; n];
    model
        .as_ode_mut()
        .rhs(0.0, y, &mut f0)
        .map_err(PeriodicOrbitError::Rhs)?;
    let scale = 1.0 + norm(&f0);
    for t in [0.37 * period, 0.71 * period, 1.3] {
        model
            .as_ode_mut()
            .rhs(t, y, &mut f1)
            .map_err(PeriodicOrbitError::Rhs)?;
        let change = norm(&f0.iter().zip(&f1).map(|(a, b)| a - b).collect::<Vec<f64>>());
        if change > 1e-12 * scale {
            return Ok(true);
        }
    }
    Ok(false)
}

/// The scale of the energy row: `1 + |E|`.
fn energy_scale(level: f64) -> f64 {
    1.0 + level.abs()
}

/// [`evaluate`] at `tol`, then again at tighter tolerances (half [`RESOLUTION_FACTOR`] times
/// the merit found, at least `final_tol`) until the tolerance is at most
/// [`RESOLUTION_FACTOR`] times the merit, or `final_tol`: a residual below the integration's
/// error is that error, and neither a Newton step nor a comparison of merits may rest on it.
fn evaluate_resolved(
    model: &mut dyn ModelInfo,
    shooting: &Shooting,
    y: Vec<f64>,
    period: f64,
    tol: f64,
    final_tol: f64,
    stats: &mut Stats,
) -> Result<Evaluation, PeriodicOrbitError> {
    let mut at = evaluate(model, shooting, y, period, tol, stats)?;
    while at.tol > final_tol && at.tol > RESOLUTION_FACTOR * at.merit {
        // At most half the last tolerance (the condition failed), so the loop ends.
        let tighter = final_tol.max(0.5 * RESOLUTION_FACTOR * at.merit);
        let Evaluation { y, period, .. } = at;
        at = evaluate(model, shooting, y, period, tighter, stats)?;
    }
    Ok(at)
}

fn evaluate(
    model: &mut dyn ModelInfo,
    shooting: &Shooting,
    y: Vec<f64>,
    period: f64,
    tol: f64,
    stats: &mut Stats,
) -> Result<Evaluation, PeriodicOrbitError> {
    let options = FloquetOptions {
        rtol: tol,
        atol: tol,
        ..FloquetOptions::default()
    };
    if !(period.is_finite() && period > 0.0) || y.iter().any(|v| !v.is_finite()) {
        return Err(FloquetError::NonFinite { row: 0, column: 0 }.into());
    }
    let (monodromy, end, run) = monodromy_matrix(model.as_ode_mut(), &y, 0.0, period, &options)?;
    stats.accumulate(&run);
    let residual: Vec<f64> = end.iter().zip(&y).map(|(a, b)| a - b).collect();
    let residual_norm = norm(&residual);
    let energy_residual = shooting.energy.map(|e| model.energy(0.0, &y) - e);
    let merit = energy_residual
        .zip(shooting.energy)
        .map_or(residual_norm, |(r, e)| {
            residual_norm.hypot(r / energy_scale(e))
        });
    Ok(Evaluation {
        y,
        period,
        monodromy,
        end,
        residual,
        residual_norm,
        energy_residual,
        merit,
        tol,
    })
}

/// The augmented Jacobian: `[Φ − I | T f(φ_T)]` (the period's unknown is its relative change
/// `ΔT/T`, so that the minimum-norm step weighs it like a state's), the phase row `[f(y)ᵀ/‖f‖ | 0]` and the energy
/// row `[∇H(y)ᵀ/(1 + |E|) | 0]` (by central differences of `H`).
fn jacobian(
    model: &mut dyn ModelInfo,
    shooting: &Shooting,
    at: &Evaluation,
    f0: &[f64],
) -> Result<DMatrix<f64>, PeriodicOrbitError> {
    let n = shooting.n;
    let columns = n + usize::from(shooting.free_period);
    let rows = n + usize::from(shooting.phase) + usize::from(shooting.energy.is_some());
    let mut j = DMatrix::zeros(rows, columns);
    j.view_mut((0, 0), (n, n)).copy_from(&at.monodromy);
    for i in 0..n {
        j[(i, i)] -= 1.0;
    }
    if shooting.free_period {
        let f_end = rhs(model, &at.end)?;
        for i in 0..n {
            j[(i, n)] = f_end[i] * at.period;
        }
    }
    let mut row = n;
    if shooting.phase {
        let f_norm = norm(f0).max(f64::MIN_POSITIVE);
        for i in 0..n {
            j[(row, i)] = f0[i] / f_norm;
        }
        row += 1;
    }
    if let Some(level) = shooting.energy {
        let mut y = at.y.clone();
        for i in 0..n {
            let h = 1e-6 * (1.0 + y[i].abs());
            let keep = y[i];
            y[i] = keep + h;
            let plus = model.energy(0.0, &y);
            y[i] = keep - h;
            let minus = model.energy(0.0, &y);
            y[i] = keep;
            j[(row, i)] = (plus - minus) / (2.0 * h) / energy_scale(level);
        }
    }
    Ok(j)
}

/// `b` of `J Δ = −b`: the residual, 0 for the phase row (anchored at the iterate), and the
/// scaled energy residual.
fn right_hand_side(shooting: &Shooting, at: &Evaluation) -> DVector<f64> {
    let mut b: Vec<f64> = at.residual.clone();
    if shooting.phase {
        b.push(0.0);
    }
    if let (Some(level), Some(r)) = (shooting.energy, at.energy_residual) {
        b.push(r / energy_scale(level));
    }
    DVector::from_vec(b)
}

fn sample_orbit(
    model: &mut dyn ModelInfo,
    at: &Evaluation,
    options: &PeriodicOrbitOptions,
    stats: &mut Stats,
) -> Result<OrbitSamples, PeriodicOrbitError> {
    let samples = options.samples.max(2);
    // `T (k / (N − 1))`, not `T k / (N − 1)`: the fraction is exactly 1 at the end, so the
    // last time is `T` itself and not one rounding past it (outside the integration).
    let times: Vec<f64> = (0..samples)
        .map(|k| at.period * (k as f64 / (samples - 1) as f64))
        .collect();
    let integrator_options = IntegratorOptions::default()
        .with_rtol(options.integration_tol)
        .with_atol(options.integration_tol);
    let solution = DormandPrince853::new()
        .integrate(
            &mut Flow(model.as_ode_mut()),
            0.0,
            &at.y,
            at.period,
            &OutputTimes::At(times),
            &integrator_options,
        )
        .map_err(FloquetError::from)?;
    stats.accumulate(&solution.stats);
    let mut orbit = OrbitSamples {
        t: Vec::with_capacity(samples),
        y: Vec::with_capacity(samples),
        points: Vec::with_capacity(samples),
    };
    for (t, y) in solution.iter() {
        orbit.t.push(t);
        orbit.y.push(y.to_vec());
        orbit.points.push(model.point_positions(t, y));
    }
    Ok(orbit)
}
