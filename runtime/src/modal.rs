//! Equilibria, exact linearisation into `M δq̈ + C δq̇ + K δq = 0`, and undamped normal modes
//! (issue 7; lectures 22–26).
//!
//! The linearisation uses the generated Jacobians, so it is exact (no finite differences):
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
//! not an equilibrium) is reported, then `K` is symmetrised (lecture 24, item 1).
//!
//! Constrained models are not linearised here yet (projection onto the null space of `J` is
//! the plan); [`ModalError::Constrained`] says so.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use crate::system::ModelInfo;

/// Why an equilibrium, a linearisation or a modal analysis failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModalError {
    /// Newton's method on `F(q, 0, t) = 0` did not converge.
    #[error(
        "no equilibrium found: Newton stopped after {iterations} iterations with |F| = {residual:e} (from the guess {guess:?})"
    )]
    EquilibriumNotFound {
        /// Iterations made.
        iterations: usize,
        /// Largest `|Fᵢ|` left (units of the generalized forces).
        residual: f64,
        /// The starting guess.
        guess: Vec<f64>,
    },
    /// The mass matrix at the operating point is not positive definite.
    #[error("the mass matrix is not positive definite at q = {q:?}")]
    SingularMassMatrix {
        /// The operating point.
        q: Vec<f64>,
    },
    /// A value is not finite at the operating point.
    #[error("the linearisation is not finite at q = {q:?}")]
    NonFinite {
        /// The operating point.
        q: Vec<f64>,
    },
    /// The model has constraints; linearising them is not supported yet.
    #[error(
        "`{model}` has constraints; linearisation of constrained models (onto the null space of J) is not supported yet"
    )]
    Constrained {
        /// The model.
        model: String,
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

/// An equilibrium `F(q*, 0, t) = 0` found by Newton's method.
#[derive(Debug, Clone, PartialEq)]
pub struct Equilibrium {
    /// The coordinates `q*` (length `n`).
    pub q: Vec<f64>,
    /// Newton iterations used.
    pub iterations: usize,
    /// Largest `|Fᵢ(q*, 0, t)|` (units of the generalized forces).
    pub residual: f64,
}

/// Finds an equilibrium `F(q, 0, t) = 0` of `model` near `guess` by Newton's method with the
/// generated `∂F/∂q`.
///
/// Each step solves `(∂F/∂q) Δq = −F` in the least-squares, minimum-norm sense (SVD with
/// singular values below `1e-12 σ_max` dropped), so neutral directions (a free cart's
/// position, a rigid-body rotation) stay at their guess; steps are halved while `|F|` does
/// not decrease (at most 30 halvings). Converged when `max |Fᵢ| ≤ 1e-12 (1 + F_scale)`, with
/// `F_scale` the largest `|Fᵢ|` at the guess, or when the step is below `1e-14 (1 + |q|)`
/// with `|F|` small (`≤ 1e-8 (1 + F_scale)`).
///
/// # Errors
/// [`ModalError::EquilibriumNotFound`] after 100 iterations or when no halving decreases `|F|`;
/// [`ModalError::Constrained`] for a constrained model; [`ModalError::DimensionMismatch`].
pub fn find_equilibrium(
    model: &dyn ModelInfo,
    guess: &[f64],
    t: f64,
) -> Result<Equilibrium, ModalError> {
    let n = model.num_dofs();
    check_point(model, guess)?;
    let state = |q: &[f64]| -> Vec<f64> {
        q.iter()
            .copied()
            .chain(std::iter::repeat_n(0.0, n))
            .collect()
    };
    let residual_of = |q: &[f64]| -> (DVector<f64>, f64) {
        let (_, f) = model.mass_matrix_and_forcing(t, &state(q));
        let r = f.amax();
        (f, if r.is_nan() { f64::INFINITY } else { r })
    };
    let mut q = guess.to_vec();
    let (mut f, mut r) = residual_of(&q);
    let scale = if r.is_finite() { r } else { 0.0 };
    for iteration in 0..100 {
        if r <= 1e-12 * (1.0 + scale) {
            return Ok(Equilibrium {
                q,
                iterations: iteration,
                residual: r,
            });
        }
        let (jq, _) = model.forcing_jacobians(t, &state(&q));
        let svd = jq.svd(true, true);
        let eps = 1e-12 * svd.singular_values.max();
        let Ok(step) = svd.solve(&(-&f), eps) else {
            break;
        };
        let mut lambda = 1.0;
        let mut accepted = false;
        for _ in 0..30 {
            let trial: Vec<f64> = q
                .iter()
                .zip(step.iter())
                .map(|(a, d)| a + lambda * d)
                .collect();
            let (f_trial, r_trial) = residual_of(&trial);
            if r_trial < r || r_trial <= 1e-12 * (1.0 + scale) {
                let small = lambda * step.amax()
                    <= 1e-14 * (1.0 + q.iter().fold(0.0f64, |m, v| m.max(v.abs())));
                q = trial;
                f = f_trial;
                r = r_trial;
                accepted = true;
                if small && r <= 1e-8 * (1.0 + scale) {
                    return Ok(Equilibrium {
                        q,
                        iterations: iteration + 1,
                        residual: r,
                    });
                }
                break;
            }
            lambda *= 0.5;
        }
        if !accepted {
            // No decrease along the Newton direction: converged as far as rounding allows,
            // or stuck.
            if r <= 1e-8 * (1.0 + scale) {
                return Ok(Equilibrium {
                    q,
                    iterations: iteration + 1,
                    residual: r,
                });
            }
            return Err(ModalError::EquilibriumNotFound {
                iterations: iteration + 1,
                residual: r,
                guess: guess.to_vec(),
            });
        }
    }
    if r <= 1e-12 * (1.0 + scale) {
        return Ok(Equilibrium {
            q,
            iterations: 100,
            residual: r,
        });
    }
    Err(ModalError::EquilibriumNotFound {
        iterations: 100,
        residual: r,
        guess: guess.to_vec(),
    })
}

fn check_point(model: &dyn ModelInfo, q: &[f64]) -> Result<(), ModalError> {
    if !model.constraint_names().is_empty() {
        return Err(ModalError::Constrained {
            model: model.name().to_string(),
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

/// The linearised equations `M δq̈ + C δq̇ + K δq = 0` at an operating point.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearization {
    /// The operating point's coordinates `q*` (length `n`).
    pub q: Vec<f64>,
    /// Its rates `q̇*` (length `n`; zero at an equilibrium).
    pub qdot: Vec<f64>,
    /// Its time (s).
    pub t: f64,
    /// `mass_matrix` `M(q*)`, `n × n`, symmetric positive definite.
    pub mass_matrix: DMatrix<f64>,
    /// `stiffness_matrix` `K`, `n × n`, as derived (not symmetrised).
    pub stiffness_matrix: DMatrix<f64>,
    /// `damping_matrix` `C = −∂F/∂q̇`, `n × n` (velocity-dependent gyroscopic terms make it
    /// non-symmetric).
    pub damping_matrix: DMatrix<f64>,
}

impl Linearization {
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
        let n = self.q.len();
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
}

fn asymmetry(k: &DMatrix<f64>) -> f64 {
    let scale = k.amax();
    if scale == 0.0 {
        return 0.0;
    }
    (k - k.transpose()).amax() / scale
}

/// Linearises `model` at `(q, q̇, t)` exactly, from the generated `M`, `∂F/∂q`, `∂F/∂q̇` and
/// `∂(M a)/∂q`.
///
/// # Errors
/// [`ModalError::Constrained`], [`ModalError::DimensionMismatch`],
/// [`ModalError::SingularMassMatrix`], [`ModalError::NonFinite`].
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
    let y: Vec<f64> = q.iter().chain(qdot).copied().collect();
    let (m, f) = model.mass_matrix_and_forcing(t, &y);
    let chol = m
        .clone()
        .cholesky()
        .ok_or_else(|| ModalError::SingularMassMatrix { q: q.to_vec() })?;
    let qdd = chol.solve(&f);
    let (jq, jqd) = model.forcing_jacobians(t, &y);
    let ma = model.mass_matrix_product_jacobian(t, &y, qdd.as_slice());
    let stiffness_matrix = ma - jq;
    let damping_matrix = -jqd;
    let finite = |a: &DMatrix<f64>| a.iter().all(|v| v.is_finite());
    if !(finite(&m) && finite(&stiffness_matrix) && finite(&damping_matrix)) {
        return Err(ModalError::NonFinite { q: q.to_vec() });
    }
    Ok(Linearization {
        q: q.to_vec(),
        qdot: qdot.to_vec(),
        t,
        mass_matrix: m,
        stiffness_matrix,
        damping_matrix,
    })
}

/// What a mode is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModeKind {
    /// `ω² > 0`: an oscillation at `ω` rad/s.
    Oscillatory,
    /// `ω² ≈ 0` (below `1e-9 max |ω²|`): a zero-frequency (rigid-body) mode (lecture 24).
    ZeroFrequency,
    /// `ω² < 0`: an unstable direction growing like `e^{σ t}`, `σ = √(−ω²)` (1/s).
    Unstable {
        /// The growth rate `σ` (1/s).
        growth_rate: f64,
    },
}

/// The undamped normal modes `K ψ = ω² M ψ` at an operating point.
#[derive(Debug, Clone, PartialEq)]
pub struct NormalModes {
    /// The eigenvalues `ω²` (1/s²), ascending; zero-frequency ones are set to 0.
    pub eigenvalues: Vec<f64>,
    /// `natural_frequencies` ω (rad/s), ascending with `eigenvalues`: `√ω²`, 0 for
    /// zero-frequency and unstable modes (see `kinds`).
    pub natural_frequencies: Vec<f64>,
    /// What each mode is.
    pub kinds: Vec<ModeKind>,
    /// `mode_shapes`, `n × n`, column `k` the shape of mode `k`, mass-normalised:
    /// `ΨᵀMΨ = I`; sign fixed so that the largest-magnitude entry is positive.
    pub mode_shapes: DMatrix<f64>,
    /// `‖K − Kᵀ‖_max / ‖K‖_max` before symmetrisation.
    pub stiffness_asymmetry: f64,
}

/// The normal modes of a linearisation, by Cholesky reduction to a symmetric eigenproblem.
///
/// # Errors
/// [`ModalError::SingularMassMatrix`] if `M` is not positive definite;
/// [`ModalError::NonFinite`] if the eigensolver fails.
pub fn normal_modes(lin: &Linearization) -> Result<NormalModes, ModalError> {
    let n = lin.q.len();
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
    let eigen = SymmetricEigen::new(y);
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
        let kind = if w2.abs() <= 1e-9 * largest || largest == 0.0 {
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
    })
}

/// The eigenvalues `ω²` of the non-symmetric `M⁻¹K` (lecture 22's route), real parts sorted
/// ascending, for comparison with [`normal_modes`] (lecture 24's symmetric route).
///
/// # Errors
/// [`ModalError::SingularMassMatrix`].
pub fn eigenvalues_of_m_inv_k(lin: &Linearization) -> Result<Vec<f64>, ModalError> {
    let chol = lin.mass_cholesky()?;
    let mk = chol.solve(&lin.stiffness_matrix);
    let mut values: Vec<f64> = mk.complex_eigenvalues().iter().map(|c| c.re).collect();
    values.sort_by(f64::total_cmp);
    Ok(values)
}

/// The eigenvalues `s` of the state matrix `A` (complex, `2n`), and from each oscillatory pair
/// the damped frequency `ω_d = |Im s|` and the `damping_ratios` `ζ = −Re s / |s|`.
///
/// Returns `(s, ζ, ω_d)` sorted by `|s|`, one entry per eigenvalue with `Im s ≥ 0` (so a
/// complex pair appears once; real eigenvalues each appear with `ω_d = 0`).
///
/// # Errors
/// [`ModalError::SingularMassMatrix`].
pub fn damped_modes(
    lin: &Linearization,
) -> Result<Vec<(nalgebra::Complex<f64>, f64, f64)>, ModalError> {
    let a = lin.state_matrix()?;
    let mut out: Vec<(nalgebra::Complex<f64>, f64, f64)> = a
        .complex_eigenvalues()
        .iter()
        .filter(|s| s.im >= 0.0)
        .map(|s| {
            let r = s.norm();
            let zeta = if r == 0.0 { 0.0 } else { -s.re / r };
            (*s, zeta, s.im.abs())
        })
        .collect();
    out.sort_by(|a, b| a.0.norm().total_cmp(&b.0.norm()));
    Ok(out)
}

/// The matrix exponential `e^A` by scaling and squaring with the degree-13 Padé approximant
/// (Higham's `expm`), for the free response `y(t) = e^{At} y(0)` of the linearised system
/// (lectures 30–32, HW32).
///
/// `A` is scaled by `2⁻ˢ` so that `‖A‖₁ 2⁻ˢ ≤ θ₁₃ = 5.37`, where the Padé approximant's
/// backward error is below the unit roundoff, and the result squared `s` times.
///
/// # Shapes
/// `a` is square, `n × n`; so is the result. A non-finite entry gives a non-finite result.
///
/// # References
/// N. J. Higham, "The scaling and squaring method for the matrix exponential revisited",
/// SIAM J. Matrix Anal. Appl. 26 (2005) 1179–1193, Algorithm 2.3 (m = 13).
pub fn matrix_exponential(a: &DMatrix<f64>) -> DMatrix<f64> {
    const B: [f64; 14] = [
        64_764_752_532_480_000.0,
        32_382_376_266_240_000.0,
        7_771_770_303_897_600.0,
        1_187_353_796_428_800.0,
        129_060_195_264_000.0,
        10_559_470_521_600.0,
        670_442_572_800.0,
        33_522_128_640.0,
        1_323_241_920.0,
        40_840_800.0,
        960_960.0,
        16_380.0,
        182.0,
        1.0,
    ];
    const THETA_13: f64 = 5.371_920_351_148_152;
    let n = a.nrows();
    let norm = (0..n)
        .map(|j| a.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0f64, f64::max);
    let s = if norm > THETA_13 {
        (norm / THETA_13).log2().ceil() as i32
    } else {
        0
    };
    let a = a * 2f64.powi(-s);
    let id = DMatrix::<f64>::identity(n, n);
    let a2 = &a * &a;
    let a4 = &a2 * &a2;
    let a6 = &a4 * &a2;
    let inner_u = &a6 * (&a6 * B[13] + &a4 * B[11] + &a2 * B[9]);
    let u = &a * (inner_u + &a6 * B[7] + &a4 * B[5] + &a2 * B[3] + &id * B[1]);
    let inner_v = &a6 * (&a6 * B[12] + &a4 * B[10] + &a2 * B[8]);
    let v = inner_v + &a6 * B[6] + &a4 * B[4] + &a2 * B[2] + &id * B[0];
    let p = &v + &u;
    let q = &v - &u;
    let mut r = match q.lu().solve(&p) {
        Some(r) => r,
        None => DMatrix::from_element(n, n, f64::NAN),
    };
    for _ in 0..s {
        r = &r * &r;
    }
    r
}
