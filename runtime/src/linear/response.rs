//! Free response of the linearised equations computed several independent ways (HW28,
//! lectures 22–26, 32), and damping models compared with the exact damped response (HW34,
//! lectures 30–33).
//!
//! long: the free response by integration, exponential, eigenvectors and modes, and the
//! damping models compared against it, share the eigenvector clusters and the modal
//! coordinates; the damping models (Rayleigh, modal) could move to a room of their own, a split
//! left to the issue on the code's shape.
//!
//! For a [`Linearization`] `M δq̈ + C δq̇ + K δq = 0` and initial values `(δq₀, δq̇₀)`:
//!
//! - [`response_by_integration`]: numerical integration of `δẏ = A δy`, `y = [δq; δq̇]`, with
//!   DOP853 through the [`LinearOde`] system (approximate, to the tolerance given);
//! - [`response_by_exponential`]: `δy(t) = e^{At} δy₀` with [`matrix_exponential`] (exact up to
//!   rounding: the Padé approximant's backward error is below the unit roundoff);
//! - [`response_by_m_inv_k_modes`] (lecture 22, HW28 `solvemode`): superposition of the modes
//!   `u_k` of the non-symmetric `M⁻¹K`, whose eigenvectors are not orthogonal: the initial
//!   values are expanded by solving `P a = δq₀`, `P b = δq̇₀` with the eigenvector matrix `P`;
//! - [`response_by_normal_modes`] (lecture 24, HW28 `solvenorm`): superposition of the
//!   mass-normalised modes `Ψ` of [`normal_modes`] (the `M^{-1/2} K M^{-1/2}` route), modal
//!   coordinates `η = ΨᵀM δq`.
//!
//! The modal routes are closed forms per mode and treat each [`ModeKind`] exactly:
//! `ω² > 0` as `a cos ωt + b sin ωt / ω`, `ω² = 0` (a zero-frequency mode, lecture 24 item 4) as
//! `a + b t`, `ω² = −σ² < 0` (indefinite `K`) as `a cosh σt + b sinh σt / σ`. They solve the
//! undamped equations and refuse a non-zero `C` ([`ResponseError::Damped`]).
//!
//! Damping (HW34): [`RayleighDamping`] `C = αM + βK` fitted to the damping ratios of two modes;
//! [`modal_damping`], the modal damping matrix `Ĉ = ΨᵀCΨ` whose diagonal gives the
//! modal-damping approximation ([`response_with_modal_damping`], one damped oscillator per
//! mode); [`exact_damped_modes`], each mode's complex eigenvalue of `A`. For a general state
//! matrix (HW32) [`state_response_by_eigenvectors`] superposes the complex eigenvector
//! solutions `e^{λt} v`.

use nalgebra::{Complex, DMatrix, DVector};

use crate::integrate::{
    DormandPrince853, IntegrationError, Integrator, IntegratorOptions, OutputTimes,
};
use crate::linear::modal::{
    Linearization, ModalError, ModeKind, NormalModes, matrix_exponential, normal_modes,
};
use crate::ode::{OdeSystem, RhsError};

/// Why a free response or a damping model could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ResponseError {
    /// The linearisation itself failed (a singular mass matrix, …).
    #[error(transparent)]
    Modal(#[from] ModalError),
    /// An initial vector has the wrong length.
    #[error("the initial {what} has {found} entries, the system {expected}")]
    DimensionMismatch {
        /// `"displacements"`, `"velocities"` or `"state"`.
        what: &'static str,
        /// The size the system needs.
        expected: usize,
        /// Given.
        found: usize,
    },
    /// A state matrix is not square.
    #[error("the state matrix is {rows} × {columns}, not square")]
    NotSquare {
        /// Rows.
        rows: usize,
        /// Columns.
        columns: usize,
    },
    /// An initial value or matrix entry is NaN or infinite.
    #[error("the {what} is not finite")]
    NonFinite {
        /// What is not finite.
        what: &'static str,
    },
    /// The output times are not finite, non-negative and non-decreasing.
    #[error(
        "output time {time} (index {index}) is not finite, negative or smaller than the one before; times must be finite, ≥ 0 and non-decreasing"
    )]
    InvalidTimes {
        /// Index of the first bad time.
        index: usize,
        /// Its value (s).
        time: f64,
    },
    /// A modal route of the undamped equations was given a non-zero damping matrix.
    #[error(
        "the modal superpositions solve M δq̈ + K δq = 0, but the damping matrix is not zero (max |C| = {max_damping:e}); use the state-matrix routes or the modal-damping approximation"
    )]
    Damped {
        /// `max |Cᵢⱼ|`.
        max_damping: f64,
    },
    /// `M⁻¹K` has a complex eigenvalue (a non-symmetric `K`: a follower load or an operating
    /// point that is not an equilibrium), so its modes are not real oscillations.
    #[error(
        "M⁻¹K has the complex eigenvalue {re:e} ± {im:e} i (K is not symmetric); its modes do not superpose as real oscillations"
    )]
    ComplexEigenvalue {
        /// Real part (1/s²).
        re: f64,
        /// Imaginary part (1/s²).
        im: f64,
    },
    /// The eigenvectors do not span the space (a defective matrix, such as the Jordan block
    /// of a zero-frequency mode in the state matrix), so superposition cannot match every
    /// initial condition.
    #[error(
        "the eigenvectors of {matrix} do not span the space (singular value ratio {ratio:e}): the matrix is defective or nearly so, and superposition of its modes cannot fit every initial condition accurately"
    )]
    Defective {
        /// `"M⁻¹K"` or `"A"`.
        matrix: &'static str,
        /// The singular-value ratio that failed: `σ_min/σ_max` of the eigenvector matrix, or
        /// `σ/σ_max` of `B − λI` for a supposed eigenvector.
        ratio: f64,
    },
    /// The numerical integration failed.
    #[error("the integration of the linear equations failed: {0}")]
    Integration(IntegrationError),
    /// A Rayleigh fit needs two oscillatory modes with different natural frequencies and
    /// finite damping ratios.
    #[error(
        "a Rayleigh fit needs two different positive natural frequencies and finite damping ratios; got ω = {omega1}, {omega2} rad/s and ζ = {zeta1}, {zeta2}"
    )]
    RayleighFit {
        /// First frequency (rad/s).
        omega1: f64,
        /// Second frequency (rad/s).
        omega2: f64,
        /// First damping ratio.
        zeta1: f64,
        /// Second damping ratio.
        zeta2: f64,
    },
    /// The modal damping coefficients do not match the number of modes.
    #[error("{found} modal damping coefficients for {expected} modes")]
    ModalDampingLength {
        /// Modes.
        expected: usize,
        /// Given.
        found: usize,
    },
}

/// A free response sampled at given times.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FreeResponse {
    /// The sample times (s), as asked for.
    pub times: Vec<f64>,
    /// `δq` at each time: `displacements[i][j]` is coordinate `j` at `times[i]` (m or rad).
    pub displacements: Vec<Vec<f64>>,
    /// `δq̇` at each time, laid out like `displacements` (m/s or rad/s).
    pub velocities: Vec<Vec<f64>>,
}

impl FreeResponse {
    /// `max |δqᵢⱼ − δq'ᵢⱼ|` over all samples and coordinates; `None` if the two responses do
    /// not have the same times and sizes.
    pub fn max_displacement_difference(&self, other: &FreeResponse) -> Option<f64> {
        self.same_grid(other)?;
        Some(max_difference(&self.displacements, &other.displacements))
    }

    /// `max |δq̇ᵢⱼ − δq̇'ᵢⱼ|` over all samples and coordinates; `None` if the two responses do
    /// not have the same times and sizes.
    pub fn max_velocity_difference(&self, other: &FreeResponse) -> Option<f64> {
        self.same_grid(other)?;
        Some(max_difference(&self.velocities, &other.velocities))
    }

    /// `max |δqᵢⱼ|` over all samples and coordinates (the scale for relative differences).
    pub fn max_displacement(&self) -> f64 {
        self.displacements
            .iter()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs()))
    }

    /// `max |δq̇ᵢⱼ|` over all samples and coordinates.
    pub fn max_velocity(&self) -> f64 {
        self.velocities
            .iter()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs()))
    }

    /// Coordinate `j` against time, `(t, δq_j)` (empty if `j` is out of range).
    pub fn coordinate_history(&self, j: usize) -> Vec<(f64, f64)> {
        self.times
            .iter()
            .zip(&self.displacements)
            .filter_map(|(t, q)| q.get(j).map(|v| (*t, *v)))
            .collect()
    }

    fn same_grid(&self, other: &FreeResponse) -> Option<()> {
        let shape = |r: &FreeResponse| -> Vec<usize> {
            r.displacements
                .iter()
                .chain(&r.velocities)
                .map(Vec::len)
                .collect()
        };
        (self.times == other.times && shape(self) == shape(other)).then_some(())
    }

    fn from_states(times: &[f64], states: Vec<Vec<f64>>, n: usize) -> Self {
        let (displacements, velocities) = states
            .into_iter()
            .map(|y| (y[..n].to_vec(), y[n..].to_vec()))
            .unzip();
        Self {
            times: times.to_vec(),
            displacements,
            velocities,
        }
    }
}

fn max_difference(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// The linear system `ẏ = A y` with a constant state matrix `A` (`dim × dim`), with its exact
/// Jacobian `A`: what the integrators see of a linearisation (lecture 30) or of HW32's random
/// `A`.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearOde {
    state_matrix: DMatrix<f64>,
}

impl LinearOde {
    /// Wraps a square state matrix.
    ///
    /// # Errors
    /// [`ResponseError::NotSquare`]; [`ResponseError::NonFinite`] for a NaN or infinite entry.
    pub fn new(state_matrix: DMatrix<f64>) -> Result<Self, ResponseError> {
        if state_matrix.nrows() != state_matrix.ncols() {
            return Err(ResponseError::NotSquare {
                rows: state_matrix.nrows(),
                columns: state_matrix.ncols(),
            });
        }
        if !state_matrix.iter().all(|v| v.is_finite()) {
            return Err(ResponseError::NonFinite {
                what: "state matrix",
            });
        }
        Ok(Self { state_matrix })
    }

    /// The state matrix `A`.
    pub fn state_matrix(&self) -> &DMatrix<f64> {
        &self.state_matrix
    }
}

impl OdeSystem for LinearOde {
    fn dim(&self) -> usize {
        self.state_matrix.nrows()
    }

    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let a = &self.state_matrix;
        for (i, d) in dy.iter_mut().enumerate() {
            *d = a.row(i).iter().zip(y).map(|(aij, yj)| aij * yj).sum();
        }
        Ok(())
    }

    fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        jac.copy_from_slice(self.state_matrix.as_slice());
        Ok(true)
    }
}

fn check_times(times: &[f64]) -> Result<(), ResponseError> {
    let mut previous = 0.0;
    for (index, &time) in times.iter().enumerate() {
        if !(time.is_finite() && time >= previous) {
            return Err(ResponseError::InvalidTimes { index, time });
        }
        previous = time;
    }
    Ok(())
}

fn check_vector(v: &[f64], n: usize, what: &'static str) -> Result<(), ResponseError> {
    if v.len() != n {
        return Err(ResponseError::DimensionMismatch {
            what,
            expected: n,
            found: v.len(),
        });
    }
    if !v.iter().all(|x| x.is_finite()) {
        return Err(ResponseError::NonFinite { what });
    }
    Ok(())
}

fn initial_state(
    lin: &Linearization,
    q0: &[f64],
    qdot0: &[f64],
) -> Result<Vec<f64>, ResponseError> {
    let n = lin.num_minimal_coordinates();
    check_vector(q0, n, "displacements")?;
    check_vector(qdot0, n, "velocities")?;
    Ok(q0.iter().chain(qdot0).copied().collect())
}

/// `y(t)` of `ẏ = A y`, `y(0) = y0`, at each of `times`, by DOP853 at `rtol = atol =
/// tolerance` through [`LinearOde`] (HW32 (e), "ODE45"; approximate: the global error is a
/// small multiple of `tolerance` times the growth of the solution).
///
/// # Shapes
/// `a` is `m × m`, `y0` has `m` entries; the result has one `m`-vector per time.
///
/// # Errors
/// [`ResponseError::NotSquare`], [`ResponseError::DimensionMismatch`],
/// [`ResponseError::NonFinite`], [`ResponseError::InvalidTimes`] (times must be finite, ≥ 0,
/// non-decreasing), [`ResponseError::Integration`] (a tolerance that is not positive, too
/// many steps).
pub fn state_response_by_integration(
    a: &DMatrix<f64>,
    y0: &[f64],
    times: &[f64],
    tolerance: f64,
) -> Result<Vec<Vec<f64>>, ResponseError> {
    let mut system = LinearOde::new(a.clone())?;
    check_vector(y0, a.nrows(), "state")?;
    check_times(times)?;
    let t_end = times.last().copied().unwrap_or(0.0);
    if t_end == 0.0 {
        return Ok(vec![y0.to_vec(); times.len()]);
    }
    let options = IntegratorOptions::default()
        .with_rtol(tolerance)
        .with_atol(tolerance);
    let solution = DormandPrince853::new()
        .integrate(
            &mut system,
            0.0,
            y0,
            t_end,
            &OutputTimes::At(times.to_vec()),
            &options,
        )
        .map_err(|f| ResponseError::Integration(f.error))?;
    Ok(solution.iter().map(|(_, y)| y.to_vec()).collect())
}

/// `y(t) = e^{At} y0` at each of `times`, one [`matrix_exponential`] per time (lecture 31;
/// exact up to rounding).
///
/// # Shapes
/// `a` is `m × m`, `y0` has `m` entries; the result has one `m`-vector per time.
///
/// # Errors
/// [`ResponseError::NotSquare`], [`ResponseError::DimensionMismatch`],
/// [`ResponseError::NonFinite`] (also if the solution overflows), [`ResponseError::InvalidTimes`].
pub fn state_response_by_exponential(
    a: &DMatrix<f64>,
    y0: &[f64],
    times: &[f64],
) -> Result<Vec<Vec<f64>>, ResponseError> {
    LinearOde::new(a.clone())?;
    check_vector(y0, a.nrows(), "state")?;
    check_times(times)?;
    let y0 = DVector::from_column_slice(y0);
    let mut out = Vec::with_capacity(times.len());
    for &t in times {
        let y = matrix_exponential(&(a * t)) * &y0;
        if !y.iter().all(|v| v.is_finite()) {
            return Err(ResponseError::NonFinite {
                what: "matrix exponential",
            });
        }
        out.push(y.as_slice().to_vec());
    }
    Ok(out)
}

/// Groups sorted eigenvalues into clusters of (numerically) repeated values: members within
/// `tol` of the cluster's first member.
fn clusters<T: Copy>(
    values: &[T],
    distance: impl Fn(T, T) -> f64,
    tol: impl Fn(T, T) -> f64,
) -> Vec<Vec<usize>> {
    let mut assigned = vec![false; values.len()];
    let mut out = Vec::new();
    for i in 0..values.len() {
        if assigned[i] {
            continue;
        }
        let mut members = vec![i];
        assigned[i] = true;
        for j in i + 1..values.len() {
            if !assigned[j] && distance(values[i], values[j]) <= tol(values[i], values[j]) {
                assigned[j] = true;
                members.push(j);
            }
        }
        out.push(members);
    }
    out
}

/// Eigenvector matrices with `σ_min/σ_max` below this are refused as defective: superposition
/// through them would lose more than six digits (error ≈ ε/ratio).
const MIN_SINGULAR_RATIO: f64 = 1e-6;

/// A singular value of `B − λI` at most this fraction of `max |Bᵢⱼ|` is rounding: the entries
/// of `B` and the computed `λ` carry errors of a few `ε max |Bᵢⱼ|`. Also the absolute part of
/// the tolerance within which eigenvalues are one repeated value ([`repeated`]).
const ROUNDING_SINGULAR_VALUE: f64 = 1e-12;

/// The tolerance within which the eigenvalues of sizes `x` and `y` are one repeated value,
/// for a matrix whose largest eigenvalue is `scale`: `1e-8` relative to their own size, and
/// at least rounding of the whole matrix (`1e-12 scale`). Relative to their own size, not to
/// `scale`: beside a stiff mode (ω² = 1e9) the soft ω² = 1 and 1.5 are distinct, not one
/// value 1.25.
fn repeated(x: f64, y: f64, scale: f64) -> f64 {
    1e-8 * x.max(y) + ROUNDING_SINGULAR_VALUE * scale
}

/// `max_i Σ_j |Bᵢⱼ| |vⱼ|`: the size of the entries of `B` that act on `v`, the scale of the
/// block a candidate eigenvector lives in.
fn local_scale<T: nalgebra::ComplexField<RealField = f64>>(
    b: &DMatrix<T>,
    v: impl Fn(usize) -> f64,
) -> f64 {
    (0..b.nrows())
        .map(|i| {
            (0..b.ncols())
                .map(|j| b[(i, j)].clone().abs() * v(j))
                .sum::<f64>()
        })
        .fold(0.0f64, f64::max)
}

/// The rows of `Vᵀ` (right singular vectors of `B − λI`) for the `count` smallest singular
/// values, where `count` is the multiplicity of the eigenvalue `λ`. Each is an eigenvector only
/// if its singular value is negligible: `≤ 1e-6 max(|λ|, sₖ)`, with `sₖ` the size of the
/// entries of `B` acting on the vector (`local(k)`, [`local_scale`]), or rounding
/// (`≤ 1e-12 max |Bᵢⱼ|`, given as `matrix_scale`); otherwise the eigenvalue's eigenspace is
/// smaller than its multiplicity (a Jordan block): [`ResponseError::Defective`].
///
/// The first bound is the eigenvalue's own scale, not `σ_max(B − λI)`: beside a stiff mode
/// (entries 1e8) a Jordan block of a soft one (entries 1) leaves a singular value of 1, far
/// below `1e-6 σ_max` yet of the size of the block. The second is for `B = λI` (an isotropic
/// oscillator, `M = 2I`, `K = 50I`): `B − λI` is then rounding in every direction.
fn null_vectors(
    singular_values: &DVector<f64>,
    count: usize,
    (lambda, local): (f64, &dyn Fn(usize) -> f64),
    matrix_scale: f64,
    matrix: &'static str,
) -> Result<Vec<usize>, ResponseError> {
    let max = singular_values.max();
    let mut order: Vec<usize> = (0..singular_values.len()).collect();
    order.sort_by(|&i, &j| singular_values[i].total_cmp(&singular_values[j]));
    order.truncate(count);
    let negligible =
        |k: usize| (1e-6 * lambda.max(local(k))).max(ROUNDING_SINGULAR_VALUE * matrix_scale);
    if let Some(&k) = order.iter().find(|&&k| singular_values[k] > negligible(k)) {
        return Err(ResponseError::Defective {
            matrix,
            ratio: singular_values[k] / max,
        });
    }
    Ok(order)
}

/// `σ_min/σ_max` of an eigenvector matrix (real or complex), refused below
/// [`MIN_SINGULAR_RATIO`] as [`ResponseError::Defective`].
fn spanning_ratio(
    singular_values: &DVector<f64>,
    matrix: &'static str,
) -> Result<f64, ResponseError> {
    let max = singular_values.max();
    let ratio = if max > 0.0 {
        singular_values.min() / max
    } else {
        0.0
    };
    if ratio < MIN_SINGULAR_RATIO {
        return Err(ResponseError::Defective { matrix, ratio });
    }
    Ok(ratio)
}

/// `y(t) = Re Σ_k c_k e^{λ_k t} v_k` with the complex eigenpairs `(λ_k, v_k)` of `A` and `V c =
/// y0` (HW32, lectures 32–33: superposition of the complex eigenvector solutions).
///
/// The eigenvalues come from the real Schur form; each eigenvector (a basis of each eigenspace
/// for eigenvalues repeated within `1e-8` of their size plus `1e-12 max |λ|`) is the right singular vector of `A − λI`
/// for its smallest singular value(s), computed in complex arithmetic.
///
/// # Shapes
/// `a` is `m × m`, `y0` has `m` entries; the result has one `m`-vector per time.
///
/// # Errors
/// [`ResponseError::Defective`] if an eigenvalue has fewer eigenvectors than its multiplicity
/// (a Jordan block, as a zero-frequency mode gives) or the eigenvector matrix has
/// `σ_min/σ_max < 1e-6`; and as
/// [`state_response_by_exponential`].
pub fn state_response_by_eigenvectors(
    a: &DMatrix<f64>,
    y0: &[f64],
    times: &[f64],
) -> Result<Vec<Vec<f64>>, ResponseError> {
    LinearOde::new(a.clone())?;
    let m = a.nrows();
    check_vector(y0, m, "state")?;
    check_times(times)?;
    let mut lambdas =
        crate::linalg::eigenvalues(a).ok_or_else(|| ModalError::EigenvaluesDidNotConverge {
            size: m,
            q: Vec::new(),
        })?;
    lambdas.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    let scale = lambdas.iter().fold(0.0f64, |s, l| s.max(l.norm()));
    let ac: DMatrix<Complex<f64>> = a.map(|v| Complex::new(v, 0.0));
    let mut vectors: DMatrix<Complex<f64>> = DMatrix::zeros(m, m);
    let mut values = Vec::with_capacity(m);
    for cluster in clusters(
        &lambdas,
        |x, y| (x - y).norm(),
        |x, y| repeated(x.norm(), y.norm(), scale),
    ) {
        let mean = cluster.iter().map(|&i| lambdas[i]).sum::<Complex<f64>>()
            / Complex::new(cluster.len() as f64, 0.0);
        let shifted = &ac - DMatrix::<Complex<f64>>::identity(m, m) * mean;
        let svd = shifted.svd(false, true);
        let Some(v_t) = svd.v_t else {
            return Err(ResponseError::Defective {
                matrix: "A",
                ratio: 0.0,
            });
        };
        let local = |k: usize| local_scale(a, |j| v_t[(k, j)].norm());
        for k in null_vectors(
            &svd.singular_values,
            cluster.len(),
            (mean.norm(), &local),
            a.amax(),
            "A",
        )? {
            let col = values.len();
            for i in 0..m {
                vectors[(i, col)] = v_t[(k, i)].conj();
            }
            values.push(mean);
        }
    }
    let ratio = spanning_ratio(&vectors.clone().svd(false, false).singular_values, "A")?;
    let y0c = DVector::from_iterator(m, y0.iter().map(|v| Complex::new(*v, 0.0)));
    let coefficients = vectors
        .clone()
        .lu()
        .solve(&y0c)
        .ok_or(ResponseError::Defective { matrix: "A", ratio })?;
    let mut out = Vec::with_capacity(times.len());
    for &t in times {
        let mut y = vec![0.0; m];
        for (k, (lambda, c)) in values.iter().zip(coefficients.iter()).enumerate() {
            let w = c * (lambda * t).exp();
            for (i, yi) in y.iter_mut().enumerate() {
                *yi += (w * vectors[(i, k)]).re;
            }
        }
        if !y.iter().all(|v| v.is_finite()) {
            return Err(ResponseError::NonFinite {
                what: "eigenvector superposition",
            });
        }
        out.push(y);
    }
    Ok(out)
}

/// The free response of `M δq̈ + C δq̇ + K δq = 0` by numerical integration of `δẏ = A δy`
/// with DOP853 at `rtol = atol = tolerance` (HW28 `solvenum`, HW34 (a); approximate).
///
/// # Shapes
/// `q0`, `qdot0` have `n` entries (m or rad, m/s or rad/s).
///
/// # Errors
/// [`ResponseError::Modal`] (singular `M`) and as [`state_response_by_integration`].
pub fn response_by_integration(
    lin: &Linearization,
    q0: &[f64],
    qdot0: &[f64],
    times: &[f64],
    tolerance: f64,
) -> Result<FreeResponse, ResponseError> {
    let y0 = initial_state(lin, q0, qdot0)?;
    let a = lin.state_matrix()?;
    let states = state_response_by_integration(&a, &y0, times, tolerance)?;
    Ok(FreeResponse::from_states(
        times,
        states,
        lin.num_minimal_coordinates(),
    ))
}

/// The free response of `M δq̈ + C δq̇ + K δq = 0` as `δy(t) = e^{At} δy₀` (lecture 31, HW34
/// (b); exact up to rounding).
///
/// # Errors
/// [`ResponseError::Modal`] (singular `M`) and as [`state_response_by_exponential`].
pub fn response_by_exponential(
    lin: &Linearization,
    q0: &[f64],
    qdot0: &[f64],
    times: &[f64],
) -> Result<FreeResponse, ResponseError> {
    let y0 = initial_state(lin, q0, qdot0)?;
    let a = lin.state_matrix()?;
    let states = state_response_by_exponential(&a, &y0, times)?;
    Ok(FreeResponse::from_states(
        times,
        states,
        lin.num_minimal_coordinates(),
    ))
}

/// The modes of the non-symmetric `M⁻¹K` (lecture 22's route).
#[derive(Debug, Clone, PartialEq)]
pub struct MInvKModes {
    /// Eigenvalues `ω²` (1/s²), ascending; those with `|ω²| ≤ 1e-9 max |ω²|` are set to 0
    /// (the threshold of [`normal_modes`]).
    pub eigenvalues: Vec<f64>,
    /// What each mode is.
    pub kinds: Vec<ModeKind>,
    /// The eigenvectors `u_k` as the columns of `P` (`n × n`), each of unit length with its
    /// largest-magnitude entry positive. Not orthogonal in general, nor mass-normalised.
    pub eigenvectors: DMatrix<f64>,
}

/// The eigenvalues and eigenvectors of `M⁻¹K` (lecture 22, `[P, D] = eig(M⁻¹K)`).
///
/// The eigenvalues come from the real Schur form; each eigenvector (a basis of the eigenspace
/// for eigenvalues repeated within `1e-8` of their size plus `1e-12 max |ω²|`) is the right singular vector of
/// `M⁻¹K − ω² I` for its smallest singular value(s). `K` is used as derived (not symmetrised).
///
/// # Errors
/// [`ResponseError::Modal`] (singular `M`); [`ResponseError::ComplexEigenvalue`] if an
/// eigenvalue has `|Im| > 1e-8 max |ω²|` (non-symmetric `K`); [`ResponseError::Defective`] if
/// an eigenvalue has fewer eigenvectors than its multiplicity or the eigenvector matrix has
/// `σ_min/σ_max < 1e-6`.
pub fn modes_of_m_inv_k(lin: &Linearization) -> Result<MInvKModes, ResponseError> {
    let n = lin.num_minimal_coordinates();
    let chol = lin.mass_cholesky()?;
    let b = chol.solve(&lin.stiffness_matrix);
    if !b.iter().all(|v| v.is_finite()) {
        return Err(ModalError::NonFinite { q: lin.q.clone() }.into());
    }
    let complex =
        crate::linalg::eigenvalues(&b).ok_or_else(|| ModalError::EigenvaluesDidNotConverge {
            size: n,
            q: lin.q.clone(),
        })?;
    let scale = complex.iter().fold(0.0f64, |s, l| s.max(l.norm()));
    if let Some(c) = complex.iter().find(|c| c.im.abs() > 1e-8 * scale) {
        return Err(ResponseError::ComplexEigenvalue {
            re: c.re,
            im: c.im.abs(),
        });
    }
    let mut lambdas: Vec<f64> = complex.iter().map(|c| c.re).collect();
    lambdas.sort_by(f64::total_cmp);
    let mut eigenvalues = Vec::with_capacity(n);
    let mut kinds = Vec::with_capacity(n);
    let mut vectors = DMatrix::zeros(n, n);
    for cluster in clusters(
        &lambdas,
        |x, y| (x - y).abs(),
        |x, y| repeated(x.abs(), y.abs(), scale),
    ) {
        let mean = cluster.iter().map(|&i| lambdas[i]).sum::<f64>() / cluster.len() as f64;
        let svd = (&b - DMatrix::<f64>::identity(n, n) * mean).svd(false, true);
        let Some(v_t) = svd.v_t else {
            return Err(ResponseError::Defective {
                matrix: "M⁻¹K",
                ratio: 0.0,
            });
        };
        let (value, kind) = if mean.abs() <= 1e-9 * scale || scale == 0.0 {
            (0.0, ModeKind::ZeroFrequency)
        } else if mean < 0.0 {
            (
                mean,
                ModeKind::Unstable {
                    growth_rate: (-mean).sqrt(),
                },
            )
        } else {
            (mean, ModeKind::Oscillatory)
        };
        let local = |k: usize| local_scale(&b, |j| v_t[(k, j)].abs());
        for k in null_vectors(
            &svd.singular_values,
            cluster.len(),
            (mean.abs(), &local),
            b.amax(),
            "M⁻¹K",
        )? {
            let col = eigenvalues.len();
            let mut u: DVector<f64> = v_t.row(k).transpose();
            let imax = u.iamax();
            if u[imax] < 0.0 {
                u = -u;
            }
            vectors.set_column(col, &(u.normalize()));
            eigenvalues.push(value);
            kinds.push(kind);
        }
    }
    spanning_ratio(&vectors.clone().svd(false, false).singular_values, "M⁻¹K")?;
    Ok(MInvKModes {
        eigenvalues,
        kinds,
        eigenvectors: vectors,
    })
}

/// One undamped modal coordinate from `r(0) = r0`, `ṙ(0) = v0`, by its kind: returns
/// `(r(t), ṙ(t))` for `r̈ + ω² r = 0` (`eigenvalue = ω²`).
fn undamped_modal_coordinate(
    kind: ModeKind,
    eigenvalue: f64,
    r0: f64,
    v0: f64,
    t: f64,
) -> (f64, f64) {
    match kind {
        ModeKind::Oscillatory => {
            let w = eigenvalue.sqrt();
            let (s, c) = (w * t).sin_cos();
            (r0 * c + v0 * s / w, -r0 * w * s + v0 * c)
        }
        ModeKind::ZeroFrequency => (r0 + v0 * t, v0),
        ModeKind::Unstable { growth_rate } => {
            let (s, c) = ((growth_rate * t).sinh(), (growth_rate * t).cosh());
            (r0 * c + v0 * s / growth_rate, r0 * growth_rate * s + v0 * c)
        }
    }
}

/// One damped modal coordinate `r̈ + d ṙ + k r = 0` from `r(0) = r0`, `ṙ(0) = v0`: returns
/// `(r(t), ṙ(t))` in closed form for every sign of `κ = k − d²/4` (under-, critically and
/// over-damped, and `k ≤ 0`).
///
/// With `h = d/2`, `C(t) = cos √κ t, 1, cosh √−κ t` and `S(t) = sin √κ t/√κ, t, sinh √−κ t/√−κ`
/// for `κ > 0, = 0, < 0`: `r = e^{−ht} [r0 (C + h S) + v0 S]`, `ṙ = e^{−ht} [−k r0 S + v0 (C − h S)]`.
fn damped_modal_coordinate(k: f64, d: f64, r0: f64, v0: f64, t: f64) -> (f64, f64) {
    let h = 0.5 * d;
    let kappa = k - h * h;
    // e^{−ht} C and e^{−ht} S, written so that e^{−ht} cosh(μt) cannot overflow.
    let (ec, es) = if kappa > 0.0 {
        let w = kappa.sqrt();
        let e = (-h * t).exp();
        let (s, c) = (w * t).sin_cos();
        (e * c, e * s / w)
    } else if kappa < 0.0 {
        let mu = (-kappa).sqrt();
        let grow = ((mu - h) * t).exp();
        let decay = (-(mu + h) * t).exp();
        (0.5 * (grow + decay), 0.5 * (grow - decay) / mu)
    } else {
        let e = (-h * t).exp();
        (e, e * t)
    };
    (
        r0 * (ec + h * es) + v0 * es,
        -k * r0 * es + v0 * (ec - h * es),
    )
}

fn require_undamped(lin: &Linearization) -> Result<(), ResponseError> {
    let max_damping = lin.damping_matrix.amax();
    if max_damping != 0.0 {
        return Err(ResponseError::Damped { max_damping });
    }
    Ok(())
}

/// The free response of `M δq̈ + K δq = 0` by superposition of the modes of `M⁻¹K` (lecture
/// 22, HW28 `solvemode`): `δq(t) = Σ_k u_k (a_k c_k(t) + b_k s_k(t))` with `P a = δq₀`,
/// `P b = δq̇₀` solved by LU (the eigenvectors are not orthogonal), and per [`ModeKind`]
/// `(c, s) = (cos ωt, sin ωt/ω)`, `(1, t)`, `(cosh σt, sinh σt/σ)`.
///
/// # Errors
/// [`ResponseError::Damped`] if `C ≠ 0`; as [`modes_of_m_inv_k`]; [`ResponseError::DimensionMismatch`],
/// [`ResponseError::NonFinite`], [`ResponseError::InvalidTimes`].
pub fn response_by_m_inv_k_modes(
    lin: &Linearization,
    q0: &[f64],
    qdot0: &[f64],
    times: &[f64],
) -> Result<FreeResponse, ResponseError> {
    initial_state(lin, q0, qdot0)?;
    check_times(times)?;
    require_undamped(lin)?;
    let modes = modes_of_m_inv_k(lin)?;
    let lu = modes.eigenvectors.clone().lu();
    let solve = |v: &[f64]| {
        lu.solve(&DVector::from_column_slice(v))
            .ok_or(ResponseError::Defective {
                matrix: "M⁻¹K",
                ratio: 0.0,
            })
    };
    let a = solve(q0)?;
    let b = solve(qdot0)?;
    superpose(&modes.eigenvectors, times, |k, t| {
        undamped_modal_coordinate(modes.kinds[k], modes.eigenvalues[k], a[k], b[k], t)
    })
}

/// `Σ_k shape_k r_k(t)` and its rate at each time, with `(r_k, ṙ_k) = coordinate(k, t)`.
fn superpose(
    shapes: &DMatrix<f64>,
    times: &[f64],
    coordinate: impl Fn(usize, f64) -> (f64, f64),
) -> Result<FreeResponse, ResponseError> {
    let n = shapes.nrows();
    let mut displacements = Vec::with_capacity(times.len());
    let mut velocities = Vec::with_capacity(times.len());
    for &t in times {
        let mut q = vec![0.0; n];
        let mut qdot = vec![0.0; n];
        for k in 0..shapes.ncols() {
            let (r, rdot) = coordinate(k, t);
            for i in 0..n {
                q[i] += shapes[(i, k)] * r;
                qdot[i] += shapes[(i, k)] * rdot;
            }
        }
        if !q.iter().chain(&qdot).all(|v| v.is_finite()) {
            return Err(ResponseError::NonFinite {
                what: "modal superposition",
            });
        }
        displacements.push(q);
        velocities.push(qdot);
    }
    Ok(FreeResponse {
        times: times.to_vec(),
        displacements,
        velocities,
    })
}

/// The free response of `M δq̈ + K δq = 0` by superposition of the mass-normalised modes of
/// [`normal_modes`] (lecture 24, the `M^{-1/2} K M^{-1/2}` route; HW28 `solvenorm`): modal
/// coordinates `η₀ = ΨᵀM δq₀`, `η̇₀ = ΨᵀM δq̇₀` (no solve: `ΨᵀMΨ = I`), each evolved in closed
/// form by its [`ModeKind`], `δq(t) = Ψ η(t)`. `K` is symmetrised as in [`normal_modes`].
///
/// # Errors
/// [`ResponseError::Damped`] if `C ≠ 0`; [`ResponseError::Modal`];
/// [`ResponseError::DimensionMismatch`], [`ResponseError::NonFinite`],
/// [`ResponseError::InvalidTimes`].
pub fn response_by_normal_modes(
    lin: &Linearization,
    q0: &[f64],
    qdot0: &[f64],
    times: &[f64],
) -> Result<FreeResponse, ResponseError> {
    initial_state(lin, q0, qdot0)?;
    check_times(times)?;
    require_undamped(lin)?;
    let modes = normal_modes(lin)?;
    modes.require_real()?;
    let (eta0, etadot0) = modal_initial_values(lin, &modes, q0, qdot0);
    superpose(&modes.mode_shapes, times, |k, t| {
        undamped_modal_coordinate(modes.kinds[k], modes.eigenvalues[k], eta0[k], etadot0[k], t)
    })
}

fn modal_initial_values(
    lin: &Linearization,
    modes: &NormalModes,
    q0: &[f64],
    qdot0: &[f64],
) -> (DVector<f64>, DVector<f64>) {
    let project = modal_projector(lin, modes) * &lin.mass_matrix;
    (
        &project * DVector::from_column_slice(q0),
        &project * DVector::from_column_slice(qdot0),
    )
}

/// The matrix `L` with `L M Ψ = I` that takes a force to modal forces (`L b`) and, times `M`,
/// a displacement to modal coordinates: `Ψᵀ` for mass-normalised modes of a symmetric `K`;
/// `Ψ⁻¹ M⁻¹` for the modes of a non-symmetric `K` (follower loads), which are not
/// `M`-orthogonal (the left eigenvectors of the pencil `(K, M)`, biorthonormal to `Ψ`).
/// `Ψᵀ` where `Ψ` or `M` cannot be inverted.
pub(crate) fn modal_projector(lin: &Linearization, modes: &NormalModes) -> DMatrix<f64> {
    let psi = &modes.mode_shapes;
    if !modes.m_orthogonal()
        && let (Some(psi_inv), Some(chol)) = (
            psi.clone().try_inverse(),
            lin.mass_matrix.clone().cholesky(),
        )
    {
        return chol.solve(&psi_inv.transpose()).transpose();
    }
    psi.transpose()
}

/// The free response with the modal-damping approximation (HW34 (c)): each modal coordinate
/// obeys its own `η̈_k + d_k η̇_k + ω_k² η_k = 0`, `d_k = modal_damping[k]` (1/s; the diagonal
/// of `Ĉ = ΨᵀCΨ` from [`modal_damping`], or `α + β ω_k²` for [`RayleighDamping`], for which
/// it is exact), in closed form for every `ω_k²` and `d_k`; `η₀ = ΨᵀM δq₀`, `δq = Ψ η`.
/// The linearisation's own `C` is not used.
///
/// # Shapes
/// `modal_damping` has one entry per mode of `modes`, in its order.
///
/// # Errors
/// [`ResponseError::ModalDampingLength`], [`ResponseError::DimensionMismatch`],
/// [`ResponseError::NonFinite`] (also for a non-finite `d_k`), [`ResponseError::InvalidTimes`].
pub fn response_with_modal_damping(
    lin: &Linearization,
    modes: &NormalModes,
    modal_damping: &[f64],
    q0: &[f64],
    qdot0: &[f64],
    times: &[f64],
) -> Result<FreeResponse, ResponseError> {
    initial_state(lin, q0, qdot0)?;
    check_times(times)?;
    let n = modes.eigenvalues.len();
    if modal_damping.len() != n {
        return Err(ResponseError::ModalDampingLength {
            expected: n,
            found: modal_damping.len(),
        });
    }
    if !modal_damping.iter().all(|d| d.is_finite()) {
        return Err(ResponseError::NonFinite {
            what: "modal damping",
        });
    }
    let (eta0, etadot0) = modal_initial_values(lin, modes, q0, qdot0);
    superpose(&modes.mode_shapes, times, |k, t| {
        damped_modal_coordinate(
            modes.eigenvalues[k],
            modal_damping[k],
            eta0[k],
            etadot0[k],
            t,
        )
    })
}

/// Rayleigh (proportional) damping `C = αM + βK` (HW34 (c) i; Inman §4.5): in modal
/// coordinates `Ĉ = α I + β Λ` is diagonal and `ζ_k = α/(2ω_k) + β ω_k/2`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RayleighDamping {
    /// The mass-proportional coefficient `α` (1/s).
    pub alpha: f64,
    /// The stiffness-proportional coefficient `β` (s).
    pub beta: f64,
}

impl RayleighDamping {
    /// Fits `α`, `β` so that modes with natural frequencies `ω₁`, `ω₂` (rad/s) get damping
    /// ratios `ζ₁`, `ζ₂` exactly: from `2 ζ_k ω_k = α + β ω_k²`,
    /// `β = 2 (ζ₂ω₂ − ζ₁ω₁)/(ω₂² − ω₁²)`, `α = 2 ζ₁ω₁ − β ω₁²`.
    ///
    /// # Errors
    /// [`ResponseError::RayleighFit`] unless both `ω` are finite and positive, differ by more
    /// than `1e-9` of the larger, and both `ζ` are finite.
    pub fn fit(
        natural_frequencies: [f64; 2],
        damping_ratios: [f64; 2],
    ) -> Result<Self, ResponseError> {
        let [w1, w2] = natural_frequencies;
        let [z1, z2] = damping_ratios;
        let good = |w: f64| w.is_finite() && w > 0.0;
        if !(good(w1) && good(w2) && z1.is_finite() && z2.is_finite())
            || (w2 - w1).abs() <= 1e-9 * w1.max(w2)
        {
            return Err(ResponseError::RayleighFit {
                omega1: w1,
                omega2: w2,
                zeta1: z1,
                zeta2: z2,
            });
        }
        let beta = 2.0 * (z2 * w2 - z1 * w1) / ((w2 - w1) * (w2 + w1));
        let alpha = 2.0 * z1 * w1 - beta * w1 * w1;
        Ok(Self { alpha, beta })
    }

    /// `ζ = α/(2ω) + βω/2` for a mode of natural frequency `ω` (rad/s, positive).
    pub fn damping_ratio(&self, natural_frequency: f64) -> f64 {
        self.alpha / (2.0 * natural_frequency) + self.beta * natural_frequency / 2.0
    }

    /// The modal damping coefficients `d_k = α + β ω_k²` (1/s) of `modes`, for
    /// [`response_with_modal_damping`] (valid for every kind of mode, `ω_k² ≤ 0` too).
    pub fn modal_damping(&self, modes: &NormalModes) -> Vec<f64> {
        modes
            .eigenvalues
            .iter()
            .map(|w2| self.alpha + self.beta * w2)
            .collect()
    }

    /// The `damping_matrix` `αM + βK` (`n × n`, N·s/m or its rotational analogue), with the
    /// symmetric part of `K` (as [`normal_modes`] uses).
    pub fn damping_matrix(&self, lin: &Linearization) -> DMatrix<f64> {
        let k_sym = (&lin.stiffness_matrix + lin.stiffness_matrix.transpose()) * 0.5;
        &lin.mass_matrix * self.alpha + k_sym * self.beta
    }
}

/// The damping matrix in modal coordinates and the modal-damping approximation (HW34 (c) ii).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ModalDamping {
    /// `Ĉ = ΨᵀCΨ` (`n × n`, 1/s; the same as `Pᵀ M^{-1/2} C M^{-1/2} P` with orthonormal `P`),
    /// serialised as a list of rows.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub modal_damping_matrix: DMatrix<f64>,
    /// The approximation's `damping_ratios` `ζ_k = Ĉ_kk/(2ω_k)` of the oscillatory modes
    /// (`None` for zero-frequency and unstable modes, where `ζ` is not defined).
    pub damping_ratios: Vec<Option<f64>>,
    /// Its damped frequencies `ω_k √(1 − ζ_k²)` (rad/s; `None` where `ζ` is `None` or `≥ 1`).
    pub damped_frequencies: Vec<Option<f64>>,
    /// How far `Ĉ` is from diagonal: `max_{i≠j} |Ĉᵢⱼ| / max_k |Ĉ_kk|` (0 for a diagonal
    /// `Ĉ`, as proportional damping gives; 0 when `C = 0`).
    pub coupling: f64,
}

impl ModalDamping {
    /// The diagonal `Ĉ_kk` (1/s), the `modal_damping` of [`response_with_modal_damping`].
    pub fn diagonal(&self) -> Vec<f64> {
        self.modal_damping_matrix
            .diagonal()
            .iter()
            .copied()
            .collect()
    }
}

/// `Ĉ = ΨᵀCΨ` of the linearisation's damping matrix on the modes `modes`, and the damping
/// ratios of keeping only its diagonal (HW34 (c) ii); `Ĉ = Ψ⁻¹M⁻¹CΨ` for the modes of a
/// non-symmetric `K`, which are not `M`-orthogonal.
pub fn modal_damping(lin: &Linearization, modes: &NormalModes) -> ModalDamping {
    let psi = &modes.mode_shapes;
    let c_hat = modal_projector(lin, modes) * &lin.damping_matrix * psi;
    let n = c_hat.nrows();
    let diagonal_max = (0..n).fold(0.0f64, |m, k| m.max(c_hat[(k, k)].abs()));
    let mut off_max = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            if i != j {
                off_max = off_max.max(c_hat[(i, j)].abs());
            }
        }
    }
    let coupling = if off_max == 0.0 {
        0.0
    } else {
        off_max / diagonal_max
    };
    let mut damping_ratios = Vec::with_capacity(n);
    let mut damped_frequencies = Vec::with_capacity(n);
    for k in 0..n {
        let w = modes.natural_frequencies[k];
        if modes.kinds[k] == ModeKind::Oscillatory && w > 0.0 {
            // `+ 0.0`: an undamped mode's `Ĉ_kk` can be −0 (a sum of −0 products), and its
            // ratio is 0, not −0.
            let zeta = c_hat[(k, k)] / (2.0 * w) + 0.0;
            damping_ratios.push(Some(zeta));
            damped_frequencies.push((zeta.abs() < 1.0).then(|| w * (1.0 - zeta * zeta).sqrt()));
        } else {
            damping_ratios.push(None);
            damped_frequencies.push(None);
        }
    }
    ModalDamping {
        modal_damping_matrix: c_hat,
        damping_ratios,
        damped_frequencies,
        coupling,
    }
}

/// A mode's exact complex eigenvalue `s` of the state matrix (one of the pair `s`, `s̄`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DampedMode {
    /// The eigenvalue `s` with `Im s > 0` (1/s), serialised as `{"re", "im"}`.
    #[serde(serialize_with = "crate::serde_matrix::complex")]
    pub eigenvalue: Complex<f64>,
    /// `ζ = −Re s/|s|`.
    pub damping_ratio: f64,
    /// `ω_d = Im s` (rad/s).
    pub damped_frequency: f64,
}

/// Each undamped mode's exact complex eigenvalue of `A = [0 I; −M⁻¹K −M⁻¹C]` (lecture 30):
/// the oscillatory modes, in ascending `ω_k`, each take the unused eigenvalue with `Im s > 0`
/// whose `|s|` is nearest `ω_k` (for light damping `|s| = ω_k + O(ζ²)`).
///
/// # Shapes
/// One entry per mode of `modes`; `None` for zero-frequency and unstable modes and for an
/// oscillatory mode left without a complex eigenvalue (overdamped).
///
/// # Errors
/// [`ResponseError::Modal`] (singular `M`).
pub fn exact_damped_modes(
    lin: &Linearization,
    modes: &NormalModes,
) -> Result<Vec<Option<DampedMode>>, ResponseError> {
    // The refined eigenvalues of the whole linearisation, as `modes` reports them.
    let complex: Vec<Complex<f64>> = crate::linear::eigenvalues::state_eigenvalues(lin)?
        .into_iter()
        .filter(|s| s.im > 0.0)
        .collect();
    let mut used = vec![false; complex.len()];
    let mut out = Vec::with_capacity(modes.kinds.len());
    for (k, kind) in modes.kinds.iter().enumerate() {
        if *kind != ModeKind::Oscillatory {
            out.push(None);
            continue;
        }
        let w = modes.natural_frequencies[k];
        let best = (0..complex.len()).filter(|&i| !used[i]).min_by(|&i, &j| {
            (complex[i].norm() - w)
                .abs()
                .total_cmp(&(complex[j].norm() - w).abs())
        });
        out.push(best.map(|i| {
            used[i] = true;
            let s = complex[i];
            DampedMode {
                eigenvalue: s,
                damping_ratio: if s.re == 0.0 { 0.0 } else { -s.re / s.norm() },
                damped_frequency: s.im,
            }
        }));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form of one damped coordinate satisfies r̈ + d ṙ + k r = 0 (checked by
    /// central differences of ṙ, to 1e-6 for a step of 1e-4: truncation O(h²)) and its
    /// initial values, in every regime.
    #[test]
    fn damped_coordinate_solves_its_equation() {
        for (k, d) in [
            (4.0, 0.3),
            (4.0, 4.0),
            (4.0, 10.0),
            (0.0, 0.5),
            (-2.0, 0.5),
            (1.0, 0.0),
        ] {
            let (r0, v0) = (0.7, -0.4);
            let (r, v) = damped_modal_coordinate(k, d, r0, v0, 0.0);
            assert!((r - r0).abs() < 1e-15 && (v - v0).abs() < 1e-15, "{k} {d}");
            for t in [0.3, 1.1, 2.5] {
                let h = 1e-4;
                let (r, v) = damped_modal_coordinate(k, d, r0, v0, t);
                let (rp, vp) = damped_modal_coordinate(k, d, r0, v0, t + h);
                let (rm, vm) = damped_modal_coordinate(k, d, r0, v0, t - h);
                assert!(((rp - rm) / (2.0 * h) - v).abs() < 1e-6, "ṙ: {k} {d} {t}");
                let a = (vp - vm) / (2.0 * h);
                assert!((a + d * v + k * r).abs() < 1e-6, "{k} {d} {t}");
            }
        }
    }

    /// The undamped forms agree with the damped one at d = 0 (exactly the same formulas, so
    /// to rounding).
    #[test]
    fn undamped_kinds_match_the_general_form() {
        for (kind, w2) in [
            (ModeKind::Oscillatory, 2.5),
            (ModeKind::ZeroFrequency, 0.0),
            (
                ModeKind::Unstable {
                    growth_rate: 3f64.sqrt(),
                },
                -3.0,
            ),
        ] {
            for t in [0.0, 0.4, 2.0] {
                let (r1, v1) = undamped_modal_coordinate(kind, w2, 0.3, 1.2, t);
                let (r2, v2) = damped_modal_coordinate(w2, 0.0, 0.3, 1.2, t);
                assert!((r1 - r2).abs() < 1e-13 * (1.0 + r1.abs()));
                assert!((v1 - v2).abs() < 1e-13 * (1.0 + v1.abs()));
            }
        }
    }

    #[test]
    fn bad_input_is_a_typed_error() {
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, 0.0]);
        assert!(matches!(
            state_response_by_exponential(&a, &[1.0], &[0.0]),
            Err(ResponseError::DimensionMismatch { .. })
        ));
        assert!(matches!(
            state_response_by_exponential(&a, &[1.0, 0.0], &[1.0, 0.5]),
            Err(ResponseError::InvalidTimes { index: 1, .. })
        ));
        assert!(matches!(
            state_response_by_integration(&a, &[1.0, f64::NAN], &[1.0], 1e-10),
            Err(ResponseError::NonFinite { .. })
        ));
        // A Jordan block has one eigenvector: superposition cannot work.
        let jordan = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        assert!(matches!(
            state_response_by_eigenvectors(&jordan, &[1.0, 1.0], &[1.0]),
            Err(ResponseError::Defective { .. })
        ));
        assert!(RayleighDamping::fit([1.0, 1.0], [0.1, 0.1]).is_err());
        assert!(RayleighDamping::fit([0.0, 1.0], [0.1, 0.1]).is_err());
    }

    /// Issue 28 review: a free soft coordinate (a Jordan block at 0: `x = x₀ + v₀ t`) beside a
    /// stiff oscillator (ω² = 1e8). Against `1e-6 σ_max(A) = 100` the block's singular value 1
    /// looked negligible and the eigenvalue was given a full eigenvector set; against its own
    /// scale it is a Jordan block. The isotropic oscillator stays non-defective (the facade's
    /// `tests/response.rs`, which runs its model file through the CLI too).
    #[test]
    fn issue_28_defective_soft_mode_beside_a_stiff_one() {
        let mut a = DMatrix::zeros(4, 4);
        a[(0, 2)] = 1.0; // ẋ = v (soft, free)
        a[(1, 3)] = 1.0; // ẏ = w
        a[(3, 1)] = -1e8; // ẇ = −1e8 y (stiff)
        let err = state_response_by_eigenvectors(&a, &[0.0, 0.0, 1.0, 0.0], &[1.0]);
        assert!(
            matches!(err, Err(ResponseError::Defective { .. })),
            "{err:?}"
        );
    }

    /// Issue 28 review: beside a stiff mode (ω² = 1e9) the soft ω² = 2 and 5 were within
    /// `1e-8 max |ω²| = 10` of each other, merged into one repeated value and both reported as
    /// 3.5. Now the tolerance is relative to their own size: 2 and 5 exactly (1e-12), with
    /// eigenvectors e₁ and e₂.
    #[test]
    fn issue_28_soft_eigenvalues_beside_a_stiff_one_are_distinct() {
        let lin = Linearization::from_matrices(
            DMatrix::identity(3, 3),
            DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![2.0, 5.0, 1e9])),
            DMatrix::zeros(3, 3),
        );
        let modes = modes_of_m_inv_k(&lin).unwrap();
        for (got, want) in modes.eigenvalues.iter().zip([2.0, 5.0, 1e9]) {
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "{:?}",
                modes.eigenvalues
            );
        }
        assert!((modes.eigenvectors[(0, 0)].abs() - 1.0).abs() < 1e-12);
        assert!((modes.eigenvectors[(1, 1)].abs() - 1.0).abs() < 1e-12);
    }
}
