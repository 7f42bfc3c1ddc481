//! `eomgen study expm` as one call (HW32, lectures 30–33): the solution of `ż = A z` for a
//! real `n × n` state matrix `A` (by default a reproducible random one) computed three
//! independent ways, and their largest differences.
//!
//! - `e^{At} z₀` with [`matrix_exponential`](crate::linear::modal::matrix_exponential)
//!   ([`state_response_by_exponential`]; exact up to rounding);
//! - the superposition of the complex eigenvector solutions `z(t) = Σ_k c_k v_k e^{λ_k t}`,
//!   `V c = z₀` ([`state_response_by_eigenvectors`]; the imaginary parts cancel, the real part
//!   is kept). Its error is about `κ(V) ε` times the solution's size, with `κ(V)` the
//!   condition number of the eigenvector matrix: a defective `A` (a Jordan block) has no
//!   eigenvector basis, and a nearly defective one an ill-conditioned basis, so the study
//!   reports `κ(V)` and, past `10⁶`, the route's refusal instead of a number;
//! - DOP853 on `ż = A z` at a tight tolerance ([`state_response_by_integration`]).

use nalgebra::{Complex, DMatrix};
use serde::Serialize;

use crate::analysis::outcome::{RunTally, StudyRuns};
use crate::linear::response::{
    ResponseError, state_response_by_eigenvectors, state_response_by_exponential,
    state_response_by_integration,
};

/// Why `eomgen study expm` could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ExpmStudyError {
    /// The size of the random matrix is 0 or above [`ExpmOptions::LARGEST_SIZE`].
    #[error("the size n must be between 1 and {largest}, got {n}")]
    InvalidSize {
        /// Given.
        n: usize,
        /// The largest accepted.
        largest: usize,
    },
    /// The end time is not positive and finite.
    #[error("the end time must be positive and finite, got {t_end}")]
    InvalidEndTime {
        /// Given (s).
        t_end: f64,
    },
    /// Fewer than two sample times.
    #[error("at least 2 samples are needed, got {samples}")]
    TooFewSamples {
        /// Given.
        samples: usize,
    },
    /// The integration tolerance is not in `(0, 1)`.
    #[error("the tolerance must be in (0, 1), got {tol}")]
    InvalidTolerance {
        /// Given.
        tol: f64,
    },
    /// The initial state does not have one entry per row of `A`.
    #[error("the initial state has {found} entries, the matrix {expected} rows")]
    DimensionMismatch {
        /// Rows of `A`.
        expected: usize,
        /// Given.
        found: usize,
    },
    /// A given matrix whose rows are not all as long as there are rows.
    #[error("the matrix has {rows} rows, but row {row} has {columns} entries; A must be square")]
    MatrixNotSquare {
        /// Rows given.
        rows: usize,
        /// The 1-based row that differs.
        row: usize,
        /// Its entries.
        columns: usize,
    },
    /// The solution's largest entry is zero (a zero initial state): differences relative to
    /// it mean nothing.
    #[error("the solution is identically zero (a zero initial state)")]
    ZeroSolution,
    /// The matrix exponential or the integration failed (a non-square or non-finite matrix,
    /// an overflowing solution, a failed integration).
    #[error(transparent)]
    Response(#[from] ResponseError),
}

/// Options of [`expm_study`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExpmOptions {
    /// Size `n` of the random `A` (default: 10; 1 to [`Self::LARGEST_SIZE`]).
    pub n: usize,
    /// Seed of the random `A` and `z₀` ([`random_problem`]; default: 32).
    pub seed: u64,
    /// End time (s) (default: 5; positive and finite).
    pub t_end: f64,
    /// Number of sample times, evenly spaced on `[0, t_end]` (default: 21; at least 2).
    pub samples: usize,
    /// Relative and absolute tolerance of DOP853 (default: 1e-13; in `(0, 1)`).
    pub tol: f64,
    /// A given `A`, as a list of rows, instead of the random one (default: none); `n` is then
    /// its number of rows, and `z₀` is still the seed's.
    pub matrix: Option<Vec<Vec<f64>>>,
}

impl ExpmOptions {
    /// The default size of `A`.
    pub const DEFAULT_N: usize = 10;
    /// The default seed (HW32).
    pub const DEFAULT_SEED: u64 = 32;
    /// The default end time (s): with the default scaling of `A` (spectral radius about 1),
    /// `e^{At}` grows or decays by at most about `e^5 ≈ 150` over it.
    pub const DEFAULT_T_END: f64 = 5.0;
    /// The default number of sample times.
    pub const DEFAULT_SAMPLES: usize = 21;
    /// The default DOP853 tolerance.
    pub const DEFAULT_TOL: f64 = 1e-13;
    /// The largest `n` accepted. The eigenvector route takes a complex SVD of `n × n` per
    /// eigenvalue, twice (the eigenvectors and their condition number), `O(n⁴)`: measured in
    /// a release build on the 2-core machine, 0.85 processor-seconds at `n = 100`, 4.0 at
    /// 150, 12 at 200 and 206 at 400 (the maximum until 2026-11-26).
    pub const LARGEST_SIZE: usize = 150;
    /// A bound on the routes' relative difference at or above this tests nothing (a relative
    /// difference of two bounded solutions is at most about 2): such a pair is reported
    /// unchecked, not passed ([`RouteDifference::checked`]).
    pub const LARGEST_BOUND: f64 = 1e-2;
}

impl Default for ExpmOptions {
    fn default() -> Self {
        Self {
            n: Self::DEFAULT_N,
            seed: Self::DEFAULT_SEED,
            t_end: Self::DEFAULT_T_END,
            samples: Self::DEFAULT_SAMPLES,
            tol: Self::DEFAULT_TOL,
            matrix: None,
        }
    }
}

/// SplitMix64 (G. L. Steele, D. Lea, C. H. Flood, "Fast splittable pseudorandom number
/// generators", OOPSLA 2014, doi:10.1145/2660193.2660195): a 64-bit state advanced by a
/// constant and mixed by two xor-shift-multiplies.
///
/// Why not `rand`: the runtime crate does not depend on it (it is a dependency of the
/// symbolic crate and of the tests only), and a study needs only a portable, reproducible
/// stream for a seed; these few lines are fully specified by the paper, identical on every
/// platform and release, and add no dependency.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform on `(0, 1]`: the top 53 bits, plus one ulp so that `ln u` is finite.
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A standard normal deviate by the Box–Muller transform (one of the pair).
    fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// A random problem `ż = A z`, `z(0) = z₀` ([`random_problem`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RandomProblem {
    /// `A` (`n × n`, 1/s), serialised as a list of rows.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub state_matrix: DMatrix<f64>,
    /// `z₀` (length `n`), of unit Euclidean norm.
    pub initial_state: Vec<f64>,
}

/// The random problem of `seed`: `Aᵢⱼ ~ N(0, 1)/√n` row by row, then `z₀` with `N(0, 1)`
/// entries scaled to unit norm, from one SplitMix64 stream (Box–Muller normals).
///
/// The scaling `1/√n` keeps the spectrum of `A` in about the unit disc for every `n` (the
/// circular law: the eigenvalues of an `n × n` matrix of independent `N(0, 1/n)` entries fill
/// the unit disc as `n → ∞`), so `e^{At}` neither explodes nor vanishes over a few seconds.
///
/// # Examples
/// ```
/// use eomgen_runtime::analysis::vibration::random_problem;
/// let p = random_problem(10, 32);
/// assert_eq!(p, random_problem(10, 32)); // reproducible
/// let norm: f64 = p.initial_state.iter().map(|v| v * v).sum::<f64>().sqrt();
/// assert!((norm - 1.0).abs() < 1e-15);
/// ```
pub fn random_problem(n: usize, seed: u64) -> RandomProblem {
    let mut rng = SplitMix64(seed);
    let scale = 1.0 / (n.max(1) as f64).sqrt();
    let state_matrix = DMatrix::from_row_iterator(n, n, (0..n * n).map(|_| rng.normal() * scale));
    let mut initial_state: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
    let norm = initial_state.iter().map(|v| v * v).sum::<f64>().sqrt();
    if norm > 0.0 {
        initial_state.iter_mut().for_each(|v| *v /= norm);
    }
    RandomProblem {
        state_matrix,
        initial_state,
    }
}

/// The three routes of [`expm_study`], in the order reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ExpmRoute {
    /// `e^{At} z₀` ([`state_response_by_exponential`]).
    Exponential,
    /// `Σ c_k v_k e^{λ_k t}` ([`state_response_by_eigenvectors`]).
    Eigenvectors,
    /// DOP853 on `ż = A z` ([`state_response_by_integration`]).
    Integration,
}

impl ExpmRoute {
    /// Every route, in the order reported.
    pub const ALL: [Self; 3] = [Self::Exponential, Self::Eigenvectors, Self::Integration];

    /// Its name in reports (`exponential`, `eigenvectors`, `integration`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Exponential => "exponential",
            Self::Eigenvectors => "eigenvectors",
            Self::Integration => "integration",
        }
    }

    /// One line on what it computes.
    pub fn description(self) -> &'static str {
        match self {
            Self::Exponential => "e^{At} z₀, scaling and squaring with Padé (exact to rounding)",
            Self::Eigenvectors => {
                "Σ c_k v_k e^{λ_k t}, V c = z₀, complex eigenpairs (error ≈ κ(V) ε)"
            }
            Self::Integration => "DOP853 on ż = A z (numerical, to the tolerance)",
        }
    }
}

/// The eigenvector route's outcome: the sampled solution, or why it was refused.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum EigenvectorOutcome {
    /// The superposition, one `n`-vector per sample time.
    Computed {
        /// `z(tᵢ)`.
        states: Vec<Vec<f64>>,
    },
    /// `A` is defective or nearly so: its eigenvectors do not span the space to six digits,
    /// and a superposition would be inaccurate (or impossible), so no number is given.
    Refused {
        /// Why ([`ResponseError::Defective`]'s message).
        reason: String,
    },
}

/// The largest difference between two routes over every sample time and entry.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RouteDifference {
    /// The first route.
    pub a: ExpmRoute,
    /// The second route.
    pub b: ExpmRoute,
    /// `max |z_a − z_b|`.
    pub absolute: f64,
    /// `absolute` over the exponential's largest `|zᵢ|` over the samples.
    pub relative: f64,
    /// The largest `relative` expected ([`expected_difference`]).
    pub tolerance: f64,
    /// Whether `tolerance` tests anything: below [`ExpmOptions::LARGEST_BOUND`]. A pair whose
    /// bound is not (an `A` so far from normal that its transient growth dwarfs the
    /// solution) is not passed.
    pub checked: bool,
    /// `relative ≤ tolerance`, with a bound that tests something (`checked`).
    pub passed: bool,
}

/// The relative difference expected at most between routes `a` and `b`, with DOP853 at
/// `tol`, the eigenvector matrix's condition number `condition` and `horizon = ρ(A) t_max G`:
/// the number of time scales of `A` the samples span, `ρ(A) t_max` (each bound grows with it
/// from 1: both the rounding of `e^{At}` and an integration's global error accumulate along
/// `t`), times the transient amplification `G = max(1, max_k ‖e^{A t_k}‖_F |z₀| / scale)`, the
/// growth of a disturbance that the solution itself does not show (a non-normal `A`). Until
/// 2026-11-26 the horizon was `‖A‖_F t_max`, which a large coupling of a non-normal `A`
/// inflates: for `[[1, 1e10], [0, 1]]` (eigenvalues 1, time scale 1) the bound was 50, which
/// no relative difference can exceed; it is 5.6e-9 now, against a measured 7e-14.
///
/// - exponential against eigenvectors: `max(1e-11, 100 κ(V) ε) · max(1, horizon)` — Padé is
///   accurate to a few `ε` of the solution's scale times `‖A t‖`, the superposition to
///   `κ(V) ε` times it;
/// - either against the integration: `max(1e-9, 1e4 tol) · max(1, horizon)` — DOP853's
///   global error is a modest multiple of its local tolerance per unit of `‖A‖ t`
///   (measured: at most 2.1e-13 of the solution's scale at `tol = 1e-13` on the default
///   10 × 10 matrices of seeds 1–12 over 5 s, where `horizon` ≈ 16).
pub fn expected_difference(
    a: ExpmRoute,
    b: ExpmRoute,
    tol: f64,
    condition: Option<f64>,
    horizon: f64,
) -> f64 {
    let integration = a == ExpmRoute::Integration || b == ExpmRoute::Integration;
    let base = if integration {
        (1e4 * tol).max(1e-9)
    } else {
        (100.0 * condition.unwrap_or(f64::INFINITY) * f64::EPSILON).max(1e-11)
    };
    base * horizon.max(1.0)
}

/// The largest `|λ|` of `eigenvalues` (0 for none).
fn study_spectral_radius(eigenvalues: &[Complex<f64>]) -> f64 {
    eigenvalues.iter().map(|l| l.norm()).fold(0.0, f64::max)
}

/// What [`expm_study`] computed.
///
/// # Shapes
/// `n` = rows of `A`; `times` has `s` entries; each state list `s` vectors of `n`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExpmStudy {
    /// `A` (`n × n`), as a list of rows.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub state_matrix: DMatrix<f64>,
    /// `z₀` (length `n`).
    pub initial_state: Vec<f64>,
    /// The eigenvalues `λ` of `A` (1/s), sorted by real part, then imaginary part, each
    /// `{"re", "im"}`.
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub eigenvalues: Vec<Complex<f64>>,
    /// `κ₂(V) = σ_max/σ_min` of the eigenvector matrix with unit columns
    /// ([`eigenvector_condition`]); `None` when `A` has no basis of eigenvectors (defective).
    pub eigenvector_condition: Option<f64>,
    /// The sample times (s).
    pub times: Vec<f64>,
    /// The DOP853 tolerance.
    pub tol: f64,
    /// `e^{At} z₀` at each time.
    pub exponential: Vec<Vec<f64>>,
    /// The eigenvector superposition, or why it was refused.
    pub eigenvectors: EigenvectorOutcome,
    /// DOP853 at each time.
    pub integration: Vec<Vec<f64>>,
    /// The exponential's largest `|zᵢ(t)|` over the samples: the solution's scale.
    pub scale: f64,
    /// `|z(t_end)| / |z₀|` (Euclidean norms) by the exponential: the growth or decay.
    pub final_growth: f64,
    /// Every pair of computed routes, in the order `(exponential, eigenvectors)`,
    /// `(exponential, integration)`, `(eigenvectors, integration)`.
    pub differences: Vec<RouteDifference>,
}

impl ExpmStudy {
    /// Whether every difference is within its expected bound.
    pub fn passed(&self) -> bool {
        self.differences.iter().all(|d| d.passed)
    }

    /// The states of `route`, `None` when it was refused.
    pub fn states(&self, route: ExpmRoute) -> Option<&[Vec<f64>]> {
        match route {
            ExpmRoute::Exponential => Some(&self.exponential),
            ExpmRoute::Integration => Some(&self.integration),
            ExpmRoute::Eigenvectors => match &self.eigenvectors {
                EigenvectorOutcome::Computed { states } => Some(states),
                EigenvectorOutcome::Refused { .. } => None,
            },
        }
    }
}

/// Each computed route is a run; a refused eigenvector route is reported, not a failure.
impl StudyRuns for ExpmStudy {
    fn study(&self) -> &'static str {
        "expm"
    }

    fn tally(&self) -> RunTally {
        let mut tally = RunTally::default();
        for route in ExpmRoute::ALL {
            match (&route, &self.eigenvectors) {
                (ExpmRoute::Eigenvectors, EigenvectorOutcome::Refused { reason }) => {
                    tally.failed(reason)
                }
                _ => tally.measured(),
            }
        }
        tally
    }
}

/// Eigenvalues within this distance (relative to their size, plus `1e-12` of the largest)
/// are one repeated value, as [`state_response_by_eigenvectors`] groups them.
const REPEATED: f64 = 1e-8;

/// A right singular vector of `A − λI` whose singular value is above this fraction of
/// `max(|λ|, max |Aᵢⱼ|)` is not an eigenvector (rounding leaves a few `ε` of it).
const NOT_NULL: f64 = 1e-6;

/// `κ₂(V) = σ_max(V)/σ_min(V)` of the eigenvector matrix of `A` with unit columns, given its
/// eigenvalues; `None` when `A` is defective (an eigenvalue repeated `m` times, within
/// `1e-8` of its size, with fewer than `m` eigenvectors).
///
/// The eigenvectors of each eigenvalue (or group of repeated ones) are the right singular
/// vectors of `A − λI` for its smallest singular values, as
/// [`state_response_by_eigenvectors`] computes them; a singular value above `1e-6 max(|λ|,
/// max |Aᵢⱼ|)` means the vector is not an eigenvector, and `A` is defective. Distinct but close
/// eigenvalues of a nearly defective `A` give nearly parallel eigenvectors and a large `κ`.
///
/// # Shapes
/// `a` is `n × n`, `eigenvalues` has `n` entries.
///
/// # References
/// G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed., §7.2.2 (the sensitivity of
/// eigenvector expansions, `κ₂(V)`); HW32.
pub fn eigenvector_condition(a: &DMatrix<f64>, eigenvalues: &[Complex<f64>]) -> Option<f64> {
    let n = a.nrows();
    if n == 0 || eigenvalues.len() != n {
        return None;
    }
    let largest = eigenvalues.iter().fold(0.0f64, |m, l| m.max(l.norm()));
    let entries = a.amax();
    let ac: DMatrix<Complex<f64>> = a.map(|v| Complex::new(v, 0.0));
    let mut assigned = vec![false; n];
    let mut vectors: DMatrix<Complex<f64>> = DMatrix::zeros(n, n);
    let mut col = 0;
    for i in 0..n {
        if assigned[i] {
            continue;
        }
        let mut cluster = vec![i];
        assigned[i] = true;
        for j in i + 1..n {
            let close =
                REPEATED * eigenvalues[i].norm().max(eigenvalues[j].norm()) + 1e-12 * largest;
            if !assigned[j] && (eigenvalues[i] - eigenvalues[j]).norm() <= close {
                assigned[j] = true;
                cluster.push(j);
            }
        }
        let mean = cluster
            .iter()
            .map(|&k| eigenvalues[k])
            .sum::<Complex<f64>>()
            / Complex::new(cluster.len() as f64, 0.0);
        let svd = (&ac - DMatrix::<Complex<f64>>::identity(n, n) * mean).svd(false, true);
        let v_t = svd.v_t?;
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&x, &y| svd.singular_values[x].total_cmp(&svd.singular_values[y]));
        for &k in order.iter().take(cluster.len()) {
            if svd.singular_values[k] > NOT_NULL * mean.norm().max(entries) {
                return None;
            }
            for r in 0..n {
                vectors[(r, col)] = v_t[(k, r)].conj();
            }
            col += 1;
        }
    }
    let sv = vectors.svd(false, false).singular_values;
    let (max, min) = (sv.max(), sv.min());
    (min > 0.0).then(|| max / min)
}

/// `z(t)` of `ż = A z`, `z(0) = z₀` at `times`, three ways ([`ExpmRoute`]), with the
/// eigenvalues of `A`, the condition number of its eigenvectors and the largest pairwise
/// differences relative to the solution's scale, each against its expected bound
/// ([`expected_difference`]) (HW32).
///
/// # Shapes
/// `a` is `n × n`, `z0` has `n` entries; `times` finite, non-negative, non-decreasing.
///
/// # Errors
/// [`ExpmStudyError::DimensionMismatch`], [`ExpmStudyError::InvalidTolerance`],
/// [`ExpmStudyError::TooFewSamples`], [`ExpmStudyError::ZeroSolution`],
/// [`ExpmStudyError::Response`] (a non-square or non-finite `A`, bad times, an overflowing
/// exponential, a failed integration). A defective `A` is not an error: the eigenvector route
/// is [`EigenvectorOutcome::Refused`].
///
/// # Examples
/// A rotation `ż = [[0, 1], [−1, 0]] z`: `z(t) = (cos t, −sin t)` from `(1, 0)`.
/// ```
/// use eomgen::nalgebra::DMatrix;
/// use eomgen_runtime::analysis::vibration::expm_study_of;
/// let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, 0.0]);
/// let study = expm_study_of(&a, &[1.0, 0.0], &[0.0, 1.0, 2.0], 1e-13)?;
/// assert!(study.passed());
/// assert!((study.exponential[2][1] + 2f64.sin()).abs() < 1e-15);
/// # Ok::<(), eomgen_runtime::analysis::vibration::ExpmStudyError>(())
/// ```
///
/// # References
/// HW32; lectures 30–33 (`e^{At}`, complex eigenvector solutions); C. Moler, C. Van Loan,
/// "Nineteen dubious ways to compute the exponential of a matrix, twenty-five years later",
/// SIAM Review 45 (2003) 3–49 (methods 1, 5 and 14 here).
pub fn expm_study_of(
    a: &DMatrix<f64>,
    z0: &[f64],
    times: &[f64],
    tol: f64,
) -> Result<ExpmStudy, ExpmStudyError> {
    if !(tol > 0.0 && tol < 1.0) {
        return Err(ExpmStudyError::InvalidTolerance { tol });
    }
    if times.len() < 2 {
        return Err(ExpmStudyError::TooFewSamples {
            samples: times.len(),
        });
    }
    if z0.len() != a.nrows() {
        return Err(ExpmStudyError::DimensionMismatch {
            expected: a.nrows(),
            found: z0.len(),
        });
    }
    let exponential = state_response_by_exponential(a, z0, times)?;
    let scale = exponential
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if scale == 0.0 {
        return Err(ExpmStudyError::ZeroSolution);
    }
    let integration = state_response_by_integration(a, z0, times, tol)?;
    let mut eigenvalues = crate::linalg::eigenvalues(a).ok_or_else(|| {
        ResponseError::from(
            crate::linear::modal::ModalError::EigenvaluesDidNotConverge {
                size: a.nrows(),
                q: Vec::new(),
            },
        )
    })?;
    eigenvalues.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    let eigenvector_condition = eigenvector_condition(a, &eigenvalues);
    let eigenvectors = eigenvector_outcome(a, z0, times, eigenvector_condition)?;
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let final_growth = exponential.last().map_or(1.0, |z| norm(z)) / norm(z0);
    let t_max = times.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let spectral_radius = study_spectral_radius(&eigenvalues);
    let amplification = times
        .iter()
        .map(|&t| crate::linear::modal::matrix_exponential(&(a * t)).norm() * norm(z0) / scale)
        .fold(1.0f64, f64::max);
    let horizon = spectral_radius * t_max * amplification;
    let mut study = ExpmStudy {
        state_matrix: a.clone(),
        initial_state: z0.to_vec(),
        eigenvalues,
        eigenvector_condition,
        times: times.to_vec(),
        tol,
        exponential,
        eigenvectors,
        integration,
        scale,
        final_growth,
        differences: Vec::new(),
    };
    study.push_differences(horizon);
    Ok(study)
}

/// The eigenvector route of [`expm_study_of`]: its states, or why it is refused (a defective
/// or ill-conditioned `A`, `eigenvector_condition` being `κ(V)`).
///
/// # Errors
/// [`ExpmStudyError::Response`] for a failure other than [`ResponseError::Defective`].
fn eigenvector_outcome(
    a: &DMatrix<f64>,
    z0: &[f64],
    times: &[f64],
    eigenvector_condition: Option<f64>,
) -> Result<EigenvectorOutcome, ExpmStudyError> {
    let outcome = match state_response_by_eigenvectors(a, z0, times) {
        Ok(states) => EigenvectorOutcome::Computed { states },
        Err(e @ ResponseError::Defective { .. }) => EigenvectorOutcome::Refused {
            reason: match eigenvector_condition {
                None => format!(
                    "A is defective (an eigenvalue repeated m times has fewer than m eigenvectors, a Jordan block), so no sum of e^{{λt}} v can give its t e^{{λt}} terms; {e}"
                ),
                Some(k) => format!(
                    "κ(V) = {k:.1e}: the eigenvectors are nearly parallel and the superposition would lose about {:.0} digits; {e}",
                    k.log10()
                ),
            },
        },
        Err(e) => return Err(e.into()),
    };
    Ok(outcome)
}

impl ExpmStudy {
    /// Pushes the difference of every pair of routes with states to
    /// [`ExpmStudy::differences`], relative to [`ExpmStudy::scale`] and checked against its
    /// expected bound at `horizon` (`ρ(A) t_max` times the largest amplification).
    fn push_differences(&mut self, horizon: f64) {
        let (scale, tol, eigenvector_condition) =
            (self.scale, self.tol, self.eigenvector_condition);
        for (i, &ra) in ExpmRoute::ALL.iter().enumerate() {
            for &rb in &ExpmRoute::ALL[i + 1..] {
                let (Some(za), Some(zb)) = (self.states(ra), self.states(rb)) else {
                    continue;
                };
                let absolute = za
                    .iter()
                    .flatten()
                    .zip(zb.iter().flatten())
                    .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
                let relative = absolute / scale;
                let tolerance = expected_difference(ra, rb, tol, eigenvector_condition, horizon);
                let checked = tolerance < ExpmOptions::LARGEST_BOUND;
                self.differences.push(RouteDifference {
                    a: ra,
                    b: rb,
                    absolute,
                    relative,
                    tolerance,
                    checked,
                    passed: checked && relative <= tolerance,
                });
            }
        }
    }
}

/// [`expm_study_of`] on the random problem of [`ExpmOptions`] ([`random_problem`]; or the
/// given matrix with the seed's `z₀`), sampled at `samples` evenly spaced times on
/// `[0, t_end]` (HW32: "generate a random 10 × 10 A").
///
/// # Errors
/// [`ExpmStudyError::InvalidSize`], [`ExpmStudyError::MatrixNotSquare`],
/// [`ExpmStudyError::InvalidEndTime`] and as [`expm_study_of`].
///
/// # Examples
/// ```
/// use eomgen_runtime::analysis::vibration::{ExpmOptions, expm_study};
/// let study = expm_study(&ExpmOptions::default())?;
/// assert!(study.passed(), "{:?}", study.differences);
/// assert_eq!(study.eigenvalues.len(), 10);
/// # Ok::<(), eomgen_runtime::analysis::vibration::ExpmStudyError>(())
/// ```
pub fn expm_study(options: &ExpmOptions) -> Result<ExpmStudy, ExpmStudyError> {
    let n = options.matrix.as_ref().map_or(options.n, Vec::len);
    if n == 0 || n > ExpmOptions::LARGEST_SIZE {
        return Err(ExpmStudyError::InvalidSize {
            n,
            largest: ExpmOptions::LARGEST_SIZE,
        });
    }
    let mut problem = random_problem(n, options.seed);
    if let Some(rows) = &options.matrix {
        if let Some((i, row)) = rows.iter().enumerate().find(|(_, r)| r.len() != n) {
            return Err(ExpmStudyError::MatrixNotSquare {
                rows: n,
                row: i + 1,
                columns: row.len(),
            });
        }
        problem.state_matrix = DMatrix::from_row_iterator(n, n, rows.iter().flatten().copied());
    }
    if !(options.t_end.is_finite() && options.t_end > 0.0) {
        return Err(ExpmStudyError::InvalidEndTime {
            t_end: options.t_end,
        });
    }
    if options.samples < 2 {
        return Err(ExpmStudyError::TooFewSamples {
            samples: options.samples,
        });
    }
    let times: Vec<f64> = (0..options.samples)
        .map(|i| options.t_end * i as f64 / (options.samples - 1) as f64)
        .collect();
    expm_study_of(
        &problem.state_matrix,
        &problem.initial_state,
        &times,
        options.tol,
    )
}
