//! Floquet analysis of a periodic linearisation: the monodromy matrix, Floquet multipliers
//! and exponents, and the stability they imply (issue 7, item 7; lectures 19 and 21, the
//! Mathieu inverted pendulum).
//!
//! For `ẏ = F(t, y)` with `F` of period `T` in `t`, and a solution `y*(t)` of the same period
//! (an equilibrium that stays one for all `t`, or a periodic orbit), small deviations
//! `δy = Φ(t) δy(t₀)` obey the variational equations
//!
//! ```text
//! Φ̇ = (∂F/∂y)(t, y*(t)) Φ,   Φ(t₀) = I
//! ```
//!
//! integrated here together with `y*` (the state `[y; vec Φ]`, `n + n²` components) by
//! DOP853 at tight tolerance, with the exact Jacobian of [`OdeSystem::jacobian`] (generated for
//! every unconstrained model). The monodromy matrix `Φ(t₀ + T)` maps a deviation over one
//! period; its eigenvalues `μ` are the Floquet multipliers. A deviation along an eigenvector
//! is multiplied by `μ` each period, so the periodic solution is linearly stable when every
//! `|μ| ≤ 1` and unstable when some `|μ| > 1`. The Floquet exponents `ln(μ)/T` are growth rates
//! (real part, 1/s) and frequencies (imaginary part, rad/s, defined modulo `2π/T`).
//!
//! For a constant `∂F/∂y = A`, `Φ(T) = e^{AT}` ([`crate::matrix_exponential`]); by Liouville's
//! formula `det Φ(T) = exp ∫ tr(∂F/∂y) dt`, which is 1 for an undamped mechanical system
//! (the multipliers of a Hamiltonian system come in pairs `μ`, `1/μ`).
//!
//! # References
//! - G. Floquet, "Sur les équations différentielles linéaires à coefficients périodiques",
//!   Ann. Sci. ÉNS 12 (1883) 47–88.
//! - A. H. Nayfeh and D. T. Mook, *Nonlinear Oscillations*, Wiley 1979, §5.2 (Floquet
//!   theory) and §5.4 (the Mathieu equation).
//! - P. L. Kapitza, "Dynamic stability of a pendulum when its point of suspension vibrates",
//!   Soviet Phys. JETP 21 (1951) 588–592; L. D. Landau and E. M. Lifshitz, *Mechanics*, §30.

use nalgebra::{Complex, DMatrix};

use crate::integrate::{
    DormandPrince853, IntegrationError, IntegrationFailure, Integrator, IntegratorOptions,
    OutputTimes, Stats,
};
use crate::model_info::ModelInfo;
use crate::ode::{OdeSystem, RhsError};

/// Why a Floquet analysis failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FloquetError {
    /// The period is zero, negative or not finite.
    #[error("the period {period} is not a finite positive number of seconds")]
    InvalidPeriod {
        /// The period given (s).
        period: f64,
    },
    /// The starting state does not have the system's dimension.
    #[error("the state has {found} components but the system has dimension {expected}")]
    DimensionMismatch {
        /// The system's dimension.
        expected: usize,
        /// Given.
        found: usize,
    },
    /// The system has no exact Jacobian `∂F/∂y` ([`OdeSystem::jacobian`] returned
    /// `Ok(false)`: a hand-written system, or a model with constraints).
    #[error(
        "the system has no exact Jacobian ∂F/∂y (a constrained model, or a system without one), which the variational equations need"
    )]
    JacobianUnavailable,
    /// The integration of the state and the variational equations failed at `t` (`None` for
    /// input the integrator rejected before its first step).
    #[error("integrating the variational equations failed{}: {source}", at_time(*.t))]
    IntegrationFailed {
        /// Where it stopped (s).
        t: Option<f64>,
        /// The integrator's error.
        source: IntegrationError,
    },
    /// The monodromy matrix has a NaN or infinite entry (the deviations overflowed).
    #[error("the monodromy matrix is not finite (entry ({row}, {column}))")]
    NonFinite {
        /// Row of the first non-finite entry.
        row: usize,
        /// Its column.
        column: usize,
    },
    /// The tolerance on `|μ| = 1` is outside
    /// `[FloquetOptions::smallest_stability_tolerance(), LARGEST_STABILITY_TOLERANCE]`.
    #[error(
        "the stability tolerance must be in [{smallest:.3e}, {largest}], got {stability_tolerance:e}: below √tol = {smallest:.3e} the integration error (at tol = {tol:e}) decides between stable, marginal and unstable (an undamped system's multipliers lie on the unit circle only to that error), and above {largest} a growth of more than 10 % per period would be called marginal"
    )]
    InvalidStabilityTolerance {
        /// The tolerance given.
        stability_tolerance: f64,
        /// The larger of the integration's `rtol` and `atol`.
        tol: f64,
        /// The smallest tolerance allowed, `√tol`.
        smallest: f64,
        /// The largest allowed, [`LARGEST_STABILITY_TOLERANCE`].
        largest: f64,
    },
    /// The eigenvalues of the monodromy matrix did not converge (Schur iteration limit).
    #[error("the eigenvalues of the monodromy matrix did not converge")]
    EigenvaluesDidNotConverge,
    /// The operating point `q*` (at rest) is not an equilibrium for every `t` of a period:
    /// `F(q*, 0, t) ≠ 0` at this `t`, so it is no fixed point of the time-periodic system.
    #[error(
        "q = {q:?} at rest is not an equilibrium for all t: max |F(q, 0, t)| = {residual:e} at t = {t} (allowed {allowed:e})"
    )]
    NotAnEquilibrium {
        /// The operating point.
        q: Vec<f64>,
        /// A time where it fails (s).
        t: f64,
        /// `max |Fᵢ(q*, 0, t)|` there (units of the generalized forces).
        residual: f64,
        /// The threshold.
        allowed: f64,
    },
}

fn at_time(t: Option<f64>) -> String {
    t.map_or(String::new(), |t| format!(" at t = {t}"))
}

impl From<IntegrationFailure> for FloquetError {
    fn from(failure: IntegrationFailure) -> Self {
        FloquetError::IntegrationFailed {
            t: failure.error.t(),
            source: failure.error,
        }
    }
}

/// The stability of a periodic solution from its spectral radius `ρ = max |μ|`, with a
/// tolerance `tol` ([`FloquetOptions::stability_tolerance`]) for the integration error.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FloquetStability {
    /// `ρ < 1 − tol`: every deviation decays (a damped system).
    AsymptoticallyStable,
    /// `|ρ − 1| ≤ tol`: the largest multipliers lie on the unit circle to within the
    /// tolerance. An undamped (Hamiltonian) system is stable only in this way, since its
    /// multipliers come in pairs `μ, 1/μ`; counted as stable by [`Self::is_stable`].
    /// (Exactly on a stability boundary a double multiplier ±1 with one eigenvector gives
    /// deviations growing linearly in `t`; such points are of measure zero in a chart.)
    Marginal,
    /// `ρ > 1 + tol`: some deviation grows by `ρ` per period.
    Unstable,
}

impl FloquetStability {
    /// Classifies a spectral radius `rho` with tolerance `tol`.
    pub fn of(rho: f64, tol: f64) -> Self {
        if rho > 1.0 + tol || rho.is_nan() {
            FloquetStability::Unstable
        } else if rho < 1.0 - tol {
            FloquetStability::AsymptoticallyStable
        } else {
            FloquetStability::Marginal
        }
    }

    /// Whether every `|μ| ≤ 1 + tol` (asymptotically stable or marginal).
    pub fn is_stable(self) -> bool {
        self != FloquetStability::Unstable
    }

    /// `"asymptotically_stable"`, `"marginal"` or `"unstable"` (as in JSON).
    pub fn as_str(self) -> &'static str {
        match self {
            FloquetStability::AsymptoticallyStable => "asymptotically_stable",
            FloquetStability::Marginal => "marginal",
            FloquetStability::Unstable => "unstable",
        }
    }
}

/// Settings of [`floquet_analysis`].
///
/// # Solver limits
/// The integration gives up after `max_steps` step attempts over the one period, or when
/// DOP853's step falls below its floor ([`FloquetError::IntegrationFailed`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FloquetOptions {
    /// Relative tolerance of DOP853 on `[y; vec Φ]` (default: 1e-12).
    pub rtol: f64,
    /// Absolute tolerance of DOP853 on `[y; vec Φ]` (default: 1e-12; `Φ` starts at `I`).
    pub atol: f64,
    /// Most step attempts over one period (default: 1 000 000).
    pub max_steps: usize,
    /// Tolerance `tol` on `|μ| = 1` in [`FloquetStability::of`], in
    /// `[√max(rtol, atol), 0.1]` ([`FloquetOptions::validate`]) (default: 1e-6; the
    /// multipliers of a matrix integrated to 1e-12 are accurate to about 1e-10 away from a
    /// stability boundary, and to about `√1e-12 = 1e-6` at a double multiplier on it).
    pub stability_tolerance: f64,
}

/// The largest tolerance on `|μ| = 1`: a spectral radius of 1.1, a growth of 10 % per
/// period, is instability, not a margin of the computation.
pub const LARGEST_STABILITY_TOLERANCE: f64 = 0.1;

impl FloquetOptions {
    /// The smallest tolerance on `|μ| = 1` the integration supports: `√max(rtol, atol)`.
    ///
    /// The multipliers of an undamped (Hamiltonian) system lie on the unit circle, as pairs
    /// `μ, 1/μ`, only up to the integration's error. Away from a stability boundary that
    /// error in `|μ|` is about the tolerance; at a boundary the two multipliers of a pair
    /// meet in a double multiplier, whose computed value moves by the square root of the
    /// perturbation of the matrix (a 2 × 2 Jordan block perturbed by `δ` has eigenvalues
    /// `±√δ` apart). A tolerance below `√tol` would let the integration error decide whether
    /// a conservative system is called asymptotically stable, marginal or unstable.
    pub fn smallest_stability_tolerance(&self) -> f64 {
        self.rtol.max(self.atol).sqrt()
    }

    /// Checks that the tolerance on `|μ| = 1` is in
    /// `[self.smallest_stability_tolerance(), LARGEST_STABILITY_TOLERANCE]`.
    ///
    /// # Errors
    /// [`FloquetError::InvalidStabilityTolerance`].
    ///
    /// # Examples
    /// ```
    /// use eomgen_runtime::FloquetOptions;
    /// assert!(FloquetOptions::default().validate().is_ok()); // 1e-6 = √1e-12
    /// for bad in [0.0, 1e-9, 1e9, f64::NAN] {
    ///     let options = FloquetOptions { stability_tolerance: bad, ..FloquetOptions::default() };
    ///     assert!(options.validate().is_err(), "{bad}");
    /// }
    /// ```
    pub fn validate(&self) -> Result<(), FloquetError> {
        let smallest = self.smallest_stability_tolerance();
        let tol = self.stability_tolerance;
        if (smallest..=LARGEST_STABILITY_TOLERANCE).contains(&tol) {
            Ok(())
        } else {
            Err(FloquetError::InvalidStabilityTolerance {
                stability_tolerance: tol,
                tol: self.rtol.max(self.atol),
                smallest,
                largest: LARGEST_STABILITY_TOLERANCE,
            })
        }
    }
}

impl FloquetOptions {
    /// The default relative and absolute tolerance of DOP853 on the state and the variational
    /// equations.
    pub const DEFAULT_TOL: f64 = 1e-12;
}

impl Default for FloquetOptions {
    fn default() -> Self {
        Self {
            rtol: Self::DEFAULT_TOL,
            atol: Self::DEFAULT_TOL,
            max_steps: crate::IntegratorOptions::DEFAULT_MAX_STEPS,
            stability_tolerance: 1e-6,
        }
    }
}

/// The result of a Floquet analysis over one period (serialised with the matrix as a list of
/// rows and complex numbers as `{"re", "im"}`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FloquetAnalysis {
    /// The period `T` (s).
    pub period: f64,
    /// The start `t₀` of the period (s).
    pub t0: f64,
    /// The monodromy matrix `Φ(t₀ + T)`, `n × n` with `n = dim()` (`2 num_dofs()` for a model,
    /// `y = [q; q̇]`); column `j` is the deviation after one period that starts as `eⱼ`.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub monodromy_matrix: DMatrix<f64>,
    /// The Floquet multipliers `μ` (eigenvalues of the monodromy matrix), `n` of them, sorted
    /// by modulus, largest first (ties: larger imaginary part first). Dimensionless.
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub multipliers: Vec<Complex<f64>>,
    /// The Floquet exponents `ln(μ)/T` (principal logarithm), in the order of
    /// `multipliers`: real part the growth rate (1/s), imaginary part a frequency (rad/s)
    /// determined modulo `2π/T`. A zero multiplier gives a real part of `−∞`.
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub exponents: Vec<Complex<f64>>,
    /// The spectral radius `ρ = max |μ|`.
    pub spectral_radius: f64,
    /// `det Φ(t₀ + T)`, the product of the multipliers (Liouville:
    /// `exp ∫ tr(∂F/∂y) dt`, 1 without damping).
    pub determinant: f64,
    /// The stability that `ρ` implies.
    pub stability: FloquetStability,
    /// `max |y(t₀ + T) − y(t₀)|`: how far the solution `y*` is from closing after one period
    /// (0 for an equilibrium; large if `y(t₀)` was no periodic solution, and then the
    /// multipliers describe nothing periodic). Units of `y`.
    pub closure_error: f64,
    /// The work of the integration.
    pub stats: Stats,
}

/// `ẏ = F(t, y)` with its variational equations `Φ̇ = (∂F/∂y) Φ`: the state `[y; vec Φ]`
/// (`Φ` column-major). Also the flow of a gait's smooth phases
/// ([`crate::analysis::gait`]).
pub(crate) struct Variational<'a, S: OdeSystem + ?Sized = dyn OdeSystem> {
    /// The system.
    pub(crate) system: &'a mut S,
    n: usize,
    jac: Vec<f64>,
    /// Whether the system had no exact Jacobian where it was asked for.
    pub(crate) jacobian_missing: bool,
}

impl<'a, S: OdeSystem + ?Sized> Variational<'a, S> {
    /// The variational flow of `system` (`n = system.dim()`).
    pub(crate) fn new(system: &'a mut S) -> Self {
        let n = system.dim();
        Self {
            system,
            n,
            jac: vec![0.0; n * n],
            jacobian_missing: false,
        }
    }

    /// `[y₀; vec I]`, the start of the flow from `y0`.
    pub(crate) fn start(&self, y0: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut start = vec![0.0; n + n * n];
        start[..n].copy_from_slice(y0);
        for i in 0..n {
            start[n + i + i * n] = 1.0;
        }
        start
    }
}

impl<S: OdeSystem + ?Sized> OdeSystem for Variational<'_, S> {
    fn dim(&self) -> usize {
        self.n + self.n * self.n
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let n = self.n;
        let (state, phi) = y.split_at(n);
        let (d_state, d_phi) = dy.split_at_mut(n);
        self.system.rhs(t, state, d_state)?;
        if !self.system.jacobian(t, state, &mut self.jac)? {
            self.jacobian_missing = true;
            return Err(RhsError::NonFinite { index: n });
        }
        // (J Φ)ᵢⱼ = Σₖ Jᵢₖ Φₖⱼ with both column-major: column j of the product is J times
        // column j of Φ.
        for j in 0..n {
            let column = &phi[j * n..(j + 1) * n];
            let out = &mut d_phi[j * n..(j + 1) * n];
            out.fill(0.0);
            for (k, &phi_kj) in column.iter().enumerate() {
                if phi_kj != 0.0 {
                    let jac_column = &self.jac[k * n..(k + 1) * n];
                    for (o, &j_ik) in out.iter_mut().zip(jac_column) {
                        *o += j_ik * phi_kj;
                    }
                }
            }
        }
        if let Some(i) = dy.iter().position(|v| !v.is_finite()) {
            return Err(RhsError::NonFinite { index: i });
        }
        Ok(())
    }
}

/// The Floquet analysis of `system` over one period `[t0, t0 + period]` about the solution
/// that starts at `y0`: monodromy matrix, multipliers, exponents, spectral radius and
/// stability.
///
/// `y0` should lie on a solution of period `period` (an equilibrium for all `t`, see
/// [`check_periodic_equilibrium`], or a periodic orbit); [`FloquetAnalysis::closure_error`]
/// reports how well it does. The variational equations use the exact Jacobian; the state and
/// `Φ` are integrated together by [`DormandPrince853`] at [`FloquetOptions::rtol`] and
/// [`FloquetOptions::atol`].
///
/// # Shapes
/// `y0` has `n = system.dim()` entries; the monodromy matrix is `n × n`, with `n` multipliers
/// and exponents.
///
/// # Errors
/// [`FloquetError::InvalidStabilityTolerance`] ([`FloquetOptions::validate`]),
/// [`FloquetError::InvalidPeriod`], [`FloquetError::DimensionMismatch`],
/// [`FloquetError::JacobianUnavailable`], [`FloquetError::IntegrationFailed`] (with the time
/// it stopped), [`FloquetError::NonFinite`], [`FloquetError::EigenvaluesDidNotConverge`].
///
/// # Examples
/// ```
/// use eomgen_runtime::{floquet_analysis, FloquetOptions, FloquetStability, OdeSystem, RhsError};
///
/// // The undamped oscillator ẍ = −x over T = 1: Φ(T) is a rotation by 1 rad, so μ = e^{±i}.
/// struct Oscillator;
/// impl OdeSystem for Oscillator {
///     fn dim(&self) -> usize { 2 }
///     fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
///         dy[0] = y[1];
///         dy[1] = -y[0];
///         Ok(())
///     }
///     fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
///         jac.copy_from_slice(&[0.0, -1.0, 1.0, 0.0]); // column-major [0 1; −1 0]
///         Ok(true)
///     }
/// }
/// let floquet = floquet_analysis(&mut Oscillator, &[0.0, 0.0], 0.0, 1.0, &FloquetOptions::default())?;
/// assert!((floquet.multipliers[0].arg().abs() - 1.0).abs() < 1e-10);
/// assert!((floquet.spectral_radius - 1.0).abs() < 1e-10);
/// assert_eq!(floquet.stability, FloquetStability::Marginal);
/// # Ok::<(), eomgen_runtime::FloquetError>(())
/// ```
pub fn floquet_analysis(
    system: &mut dyn OdeSystem,
    y0: &[f64],
    t0: f64,
    period: f64,
    options: &FloquetOptions,
) -> Result<FloquetAnalysis, FloquetError> {
    options.validate()?;
    let (monodromy_matrix, y_end, stats) = monodromy_matrix(system, y0, t0, period, options)?;
    let closure_error = y_end
        .iter()
        .zip(y0)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f64, f64::max);
    let mut analysis = floquet_multipliers(monodromy_matrix, period, options.stability_tolerance)?;
    analysis.t0 = t0;
    analysis.closure_error = closure_error;
    analysis.stats = stats;
    Ok(analysis)
}

/// The monodromy matrix `Φ(t0 + period)` (`n × n`) of `system` about the solution from `y0`,
/// with that solution's end state `y(t0 + period)` (length `n`) and the integration's
/// statistics; see [`floquet_analysis`].
///
/// # Errors
/// As [`floquet_analysis`], except the eigenvalue error.
pub fn monodromy_matrix(
    system: &mut dyn OdeSystem,
    y0: &[f64],
    t0: f64,
    period: f64,
    options: &FloquetOptions,
) -> Result<(DMatrix<f64>, Vec<f64>, Stats), FloquetError> {
    if !(period.is_finite() && period > 0.0) {
        return Err(FloquetError::InvalidPeriod { period });
    }
    let n = system.dim();
    if y0.len() != n {
        return Err(FloquetError::DimensionMismatch {
            expected: n,
            found: y0.len(),
        });
    }
    let mut jac = vec![0.0; n * n];
    if y0.iter().all(|v| v.is_finite()) && !system.jacobian(t0, y0, &mut jac).unwrap_or(true) {
        return Err(FloquetError::JacobianUnavailable);
    }
    let mut start = vec![0.0; n + n * n];
    start[..n].copy_from_slice(y0);
    for i in 0..n {
        start[n + i + i * n] = 1.0;
    }
    let mut variational = Variational {
        system,
        n,
        jac,
        jacobian_missing: false,
    };
    let integrator_options = IntegratorOptions::default()
        .with_rtol(options.rtol)
        .with_atol(options.atol)
        .with_max_steps(options.max_steps);
    let t_end = t0 + period;
    let result = DormandPrince853::new().integrate(
        &mut variational,
        t0,
        &start,
        t_end,
        &OutputTimes::At(vec![t_end]),
        &integrator_options,
    );
    if variational.jacobian_missing {
        return Err(FloquetError::JacobianUnavailable);
    }
    let solution = result?;
    // A successful integration samples every requested time, so `t_end` is there; were it
    // missing, the integration did not reach it.
    let Some((_, end)) = solution.last() else {
        return Err(FloquetError::IntegrationFailed {
            t: Some(t0),
            source: IntegrationError::TooManySteps {
                t: t0,
                max_steps: options.max_steps,
            },
        });
    };
    let phi = DMatrix::from_column_slice(n, n, &end[n..]);
    if let Some(k) = phi.iter().position(|v| !v.is_finite()) {
        return Err(FloquetError::NonFinite {
            row: k % n,
            column: k / n,
        });
    }
    Ok((phi, end[..n].to_vec(), solution.stats))
}

/// Multipliers, exponents, spectral radius, determinant and stability of a given monodromy
/// matrix over `period` (s), with tolerance `tol` on `|μ| = 1`
/// ([`FloquetOptions::stability_tolerance`]); `t0`, `closure_error` and `stats` are left
/// zero.
///
/// # Shapes
/// `monodromy` is square, `n × n`.
///
/// # Errors
/// [`FloquetError::InvalidPeriod`], [`FloquetError::DimensionMismatch`] (not square),
/// [`FloquetError::NonFinite`], [`FloquetError::EigenvaluesDidNotConverge`].
pub fn floquet_multipliers(
    monodromy: DMatrix<f64>,
    period: f64,
    tol: f64,
) -> Result<FloquetAnalysis, FloquetError> {
    if !(period.is_finite() && period > 0.0) {
        return Err(FloquetError::InvalidPeriod { period });
    }
    let n = monodromy.nrows();
    if monodromy.ncols() != n {
        return Err(FloquetError::DimensionMismatch {
            expected: n,
            found: monodromy.ncols(),
        });
    }
    if let Some(k) = monodromy.iter().position(|v| !v.is_finite()) {
        return Err(FloquetError::NonFinite {
            row: k % n,
            column: k / n,
        });
    }
    let mut multipliers: Vec<Complex<f64>> = if n == 0 {
        Vec::new()
    } else {
        nalgebra::Schur::try_new(monodromy.clone(), f64::EPSILON, 100 * n.max(10))
            .ok_or(FloquetError::EigenvaluesDidNotConverge)?
            .complex_eigenvalues()
            .iter()
            .copied()
            .collect()
    };
    if multipliers
        .iter()
        .any(|m| !(m.re.is_finite() && m.im.is_finite()))
    {
        return Err(FloquetError::EigenvaluesDidNotConverge);
    }
    multipliers.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
    let exponents = multipliers.iter().map(|m| m.ln() / period).collect();
    let spectral_radius = multipliers.first().map_or(0.0, |m| m.norm());
    let determinant = monodromy.determinant();
    Ok(FloquetAnalysis {
        period,
        t0: 0.0,
        monodromy_matrix: monodromy,
        multipliers,
        exponents,
        spectral_radius,
        determinant,
        stability: FloquetStability::of(spectral_radius, tol),
        closure_error: 0.0,
        stats: Stats::default(),
    })
}

/// Checks that `q` at rest is an equilibrium of `model` for every `t` of one period
/// `[t0, t0 + period]`, so that `y* = [q; 0]` is a (constant) periodic solution of the
/// time-periodic system; returns the largest `|Fᵢ(q, 0, t)|` found.
///
/// `F` is evaluated at `t0` and at 64 times `t0 + (k + 0.382) T/64` (`k = 0 … 63`; the
/// offset keeps the samples off the zeros of a forcing `cos(w t)` or `sin(w t)`). `q` fails
/// when `max |F| > 1e-8 (1 + s)`, where `s` is the largest `|∂Fᵢ/∂qⱼ|` over the samples: the
/// force that a displacement of 1e-8 (m or rad) would cause.
///
/// # Errors
/// [`FloquetError::NotAnEquilibrium`] at the worst sample; [`FloquetError::InvalidPeriod`];
/// [`FloquetError::DimensionMismatch`] if `q` does not have `num_dofs()` entries.
pub fn check_periodic_equilibrium(
    model: &dyn ModelInfo,
    q: &[f64],
    t0: f64,
    period: f64,
) -> Result<f64, FloquetError> {
    if !(period.is_finite() && period > 0.0) {
        return Err(FloquetError::InvalidPeriod { period });
    }
    let n = model.num_dofs();
    if q.len() != n {
        return Err(FloquetError::DimensionMismatch {
            expected: n,
            found: q.len(),
        });
    }
    // At rest (in generalized speeds `u = Z(q, t₀)`; NaN, which no equilibrium passes, where
    // their kinematic equations are singular).
    let y = super::speeds::rest_state(model, q, t0)
        .unwrap_or_else(|_| q.iter().copied().chain(vec![f64::NAN; n]).collect());
    let times =
        std::iter::once(t0).chain((0..64).map(|k| t0 + (f64::from(k) + 0.382) * period / 64.0));
    let (mut worst_t, mut worst, mut scale) = (t0, 0.0f64, 0.0f64);
    for t in times {
        let (_, f) = model.mass_matrix_and_forcing(t, &y);
        let (jq, _) = model.forcing_jacobians(t, &y);
        let r = f.iter().fold(0.0f64, |m, v| {
            if v.is_nan() {
                f64::INFINITY
            } else {
                m.max(v.abs())
            }
        });
        scale = scale.max(jq.iter().fold(0.0f64, |m, v| m.max(v.abs())));
        if r > worst || r.is_infinite() {
            worst = r;
            worst_t = t;
        }
    }
    let allowed = 1e-8 * (1.0 + if scale.is_finite() { scale } else { 0.0 });
    if worst > allowed || !worst.is_finite() {
        return Err(FloquetError::NotAnEquilibrium {
            q: q.to_vec(),
            t: worst_t,
            residual: worst,
            allowed,
        });
    }
    Ok(worst)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 × 2 monodromy matrix with known eigenvalues 2 and 1/2: sorted largest first,
    /// exponents ±ln 2 / T, determinant 1, unstable.
    #[test]
    fn multipliers_of_a_known_matrix() {
        let m = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 0.0, 0.5]);
        let f = floquet_multipliers(m, 2.0, 1e-6).unwrap();
        assert!((f.multipliers[0].re - 2.0).abs() < 1e-14);
        assert!((f.multipliers[1].re - 0.5).abs() < 1e-14);
        assert!((f.exponents[0].re - 2f64.ln() / 2.0).abs() < 1e-14);
        assert!((f.determinant - 1.0).abs() < 1e-14);
        assert_eq!(f.stability, FloquetStability::Unstable);
    }

    #[test]
    fn classification_and_bad_input() {
        assert_eq!(
            FloquetStability::of(0.5, 1e-6),
            FloquetStability::AsymptoticallyStable
        );
        assert_eq!(
            FloquetStability::of(1.0 + 1e-9, 1e-6),
            FloquetStability::Marginal
        );
        assert_eq!(
            FloquetStability::of(f64::NAN, 1e-6),
            FloquetStability::Unstable
        );
        assert!(matches!(
            floquet_multipliers(DMatrix::identity(2, 2), 0.0, 1e-6),
            Err(FloquetError::InvalidPeriod { .. })
        ));
        let mut nan = DMatrix::identity(2, 2);
        nan[(1, 0)] = f64::NAN;
        assert_eq!(
            floquet_multipliers(nan, 1.0, 1e-6),
            Err(FloquetError::NonFinite { row: 1, column: 0 })
        );
    }

    /// A system without a Jacobian is refused with a typed error, not differenced.
    #[test]
    fn no_jacobian_is_an_error() {
        let mut decay = crate::OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0]);
        assert_eq!(
            floquet_analysis(&mut decay, &[0.0], 0.0, 1.0, &FloquetOptions::default()),
            Err(FloquetError::JacobianUnavailable)
        );
    }
}
