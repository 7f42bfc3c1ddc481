//! Dense symmetric positive definite solves `M x = f` for the mass matrix: [`solve_spd`] with a
//! compile-time size (the compiled models' hot path) and [`solve_spd_in_place`] with a size
//! known at run time, the same operations in the same order; and [`forward_differences`], the
//! one difference Jacobian that stands in for an exact one that is not finite; and
//! [`eigenvalues`] and [`symmetric_eigen`], nalgebra's eigensolvers with a bound on their
//! iterations.

use nalgebra::{Complex, DMatrix, Dyn, SMatrix, SVector, SymmetricEigen};

/// QR sweeps allowed per row of a matrix in [`eigenvalues`] and [`symmetric_eigen`] (at least
/// ten rows' worth): the implicit QR algorithm takes two to three sweeps per eigenvalue
/// (Golub & Van Loan, *Matrix Computations*, 4th ed., §7.5.6 and §8.3.5), so this is never
/// reached by a matrix that converges.
const SWEEPS_PER_ROW: usize = 100;

/// The eigenvalues of the real square matrix `a` (`n × n`, any order), by nalgebra's real
/// Schur decomposition with at most `100·max(n, 10)` QR sweeps. nalgebra's own
/// `complex_eigenvalues` has no bound, and its QR iteration can cycle forever on some finite
/// matrices (nalgebra issues #611 and #1528); a non-finite entry would make it cycle too.
///
/// Returns `None` when `a` has an entry that is not finite, when the iteration does not
/// converge within the bound, or when an eigenvalue is not finite.
pub fn eigenvalues(a: &DMatrix<f64>) -> Option<Vec<Complex<f64>>> {
    if a.iter().any(|v| !v.is_finite()) {
        return None;
    }
    if a.is_empty() {
        return Some(Vec::new());
    }
    let sweeps = SWEEPS_PER_ROW * a.nrows().max(10);
    // The transpose has the same eigenvalues and other rounding: where the iteration cycles
    // on one (a matrix with Jordan blocks of zeros, as a free structure's state matrix has),
    // it converges on the other.
    // Then a reflection `H A H` (`H = I − 2 w wᵀ/wᵀw`, `w` irregular and fixed): the same
    // eigenvalues, without the structure that stalls the shifts (a gyroscopic `[[0, I],
    // [k I, g J]]` stalled on both `A` and `Aᵀ`).
    let reflected = || {
        let n = a.nrows();
        let w = nalgebra::DVector::from_fn(n, |i, _| {
            1.0 + ((i + 1) as f64 * 0.618_033_988_749_895).fract()
        });
        let h = DMatrix::identity(n, n) - (&w * w.transpose()) * (2.0 / w.norm_squared());
        &h * a * &h
    };
    let schur = nalgebra::Schur::try_new(a.clone(), f64::EPSILON, sweeps)
        .or_else(|| nalgebra::Schur::try_new(a.transpose(), f64::EPSILON, sweeps))
        .or_else(|| nalgebra::Schur::try_new(reflected(), f64::EPSILON, sweeps))?;
    let values: Vec<Complex<f64>> = schur.complex_eigenvalues().iter().copied().collect();
    values
        .iter()
        .all(|v| v.re.is_finite() && v.im.is_finite())
        .then_some(values)
}

/// The eigenvalues and eigenvectors of the symmetric matrix `a` (`n × n`, lower triangle
/// read), by nalgebra's symmetric QR algorithm with at most `100·max(n, 10)` sweeps (see
/// [`eigenvalues`]).
///
/// Returns `None` when `a` has an entry that is not finite, when the iteration does not
/// converge within the bound, or when a result is not finite.
pub fn symmetric_eigen(a: DMatrix<f64>) -> Option<SymmetricEigen<f64, Dyn>> {
    if a.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let sweeps = SWEEPS_PER_ROW * a.nrows().max(10);
    let eigen = SymmetricEigen::try_new(a, f64::EPSILON, sweeps)?;
    (eigen.eigenvalues.iter().all(|v| v.is_finite())
        && eigen.eigenvectors.iter().all(|v| v.is_finite()))
    .then_some(eigen)
}

/// Solves `M x = f` for a symmetric positive definite `M` (`N × N`, lower triangle read) by
/// the square-root-free factorisation `M = L D Lᵀ` (`L` unit lower triangular, `D` diagonal;
/// Golub & Van Loan, *Matrix Computations*, 4th ed., §4.1.2), the hot path of every
/// unconstrained right-hand side ([`FirstOrder::rhs`](crate::OdeSystem::rhs) of [`FirstOrder`](crate::FirstOrder)).
///
/// Returns `None` when a pivot `dⱼ` is not positive (or is NaN): `M` is not positive definite.
/// Like Cholesky, it needs no pivoting for a positive definite `M` and is backward stable;
/// unlike nalgebra's Cholesky it takes no square roots and one division per column (the
/// reciprocal pivots are reused), which on the double pendulum shortened the dependency chain
/// of `q̈ = M⁻¹F` from two square roots and five divisions to two divisions.
///
/// One and two degrees of freedom are solved in closed form instead: `x = f/m`, and for
/// `M = [a b; b c]` Cramer's rule `x = [c f₀ − b f₁, a f₁ − b f₀] / (a c − b²)`, positive
/// definite exactly when `a > 0` and `a c − b² > 0` (Sylvester's criterion). Its determinant
/// is the product `a · d₁` of the two pivots above, so it is as accurate, but the two
/// numerators are formed while the one division runs, where the factorisation divides twice
/// in sequence; an integration waits for each right-hand side before the next stage can
/// start, and this shorter chain made a DOP853 run of the double pendulum ~4 % faster.
///
/// From [`ENVELOPE_FROM`] degrees of freedom on, the factorisation skips the zeros left of
/// each row's first non-zero entry (`solve_in_envelope`): the same result (to the sign of
/// zeros) in `O(n)` for a diagonal `M` instead of `O(n³)`.
pub fn solve_spd<const N: usize>(
    m: &SMatrix<f64, N, N>,
    f: &SVector<f64, N>,
) -> Option<SVector<f64, N>> {
    match N {
        1 => {
            let a = m[(0, 0)];
            // Not positive, or NaN.
            return (a > 0.0).then(|| f / a);
        }
        2 => {
            let (a, b, c) = (m[(0, 0)], m[(1, 0)], m[(1, 1)]);
            let det = a * c - b * b;
            // Not positive definite, or NaN.
            if a.is_nan() || a <= 0.0 || det.is_nan() || det <= 0.0 {
                return None;
            }
            let inverse = 1.0 / det;
            let mut x = *f;
            x[0] = (c * f[0] - b * f[1]) * inverse;
            x[1] = (a * f[1] - b * f[0]) * inverse;
            return Some(x);
        }
        _ => {}
    }
    let mut l = [[0.0f64; N]; N];
    let mut inv_d = [0.0f64; N];
    let mut d = [0.0f64; N];
    if N >= ENVELOPE_FROM {
        let mut x = *f;
        let mut envelope = [[0usize; N]; 2];
        return solve_in_envelope(
            N,
            |i, j| m[(i, j)],
            x.as_mut_slice(),
            l.as_flattened_mut(),
            &mut d,
            &mut inv_d,
            envelope.as_flattened_mut(),
        )
        .map(|()| x);
    }
    for j in 0..N {
        let mut dj = m[(j, j)];
        for k in 0..j {
            dj -= l[j][k] * l[j][k] * d[k];
        }
        // Not positive, or NaN.
        if dj.is_nan() || dj <= 0.0 {
            return None;
        }
        d[j] = dj;
        inv_d[j] = 1.0 / dj;
        for i in j + 1..N {
            let mut v = m[(i, j)];
            for k in 0..j {
                v -= l[i][k] * l[j][k] * d[k];
            }
            l[i][j] = v * inv_d[j];
        }
    }
    let mut x = *f;
    for i in 0..N {
        for k in 0..i {
            x[i] -= l[i][k] * x[k];
        }
    }
    for i in 0..N {
        x[i] *= inv_d[i];
    }
    for i in (0..N).rev() {
        for k in i + 1..N {
            x[i] -= l[k][i] * x[k];
        }
    }
    Some(x)
}

/// [`solve_spd`] for a size known at run time: solves `M x = f` in place (`f` becomes `x`)
/// for a symmetric positive definite `M` (`n × n`, column-major, lower triangle read), with
/// the same closed forms for `n = 1, 2` and the same `L D Lᵀ` factorisation in the same
/// operation order (within the envelope of `M` from [`ENVELOPE_FROM`] on, as `solve_spd`), so
/// the two agree to the bit; `work` holds at least `n² + 2n` values and `envelope` `2n`
/// indices (from [`ENVELOPE_FROM`] on; unused below).
/// No heap allocation.
///
/// `solve_spd` keeps its own copy with stack arrays and a compile-time `N`, which the
/// compiler unrolls for the hot path of the compiled models (`benches/rhs.rs`).
///
/// Returns `None` when `M` is not positive definite (a pivot is not positive, or is NaN).
///
/// # Panics
/// If `mass` has fewer than `n²` entries, `f` fewer than `n`, `work` fewer than `n² + 2n` or,
/// from [`ENVELOPE_FROM`] on, `envelope` fewer than `2n`.
pub fn solve_spd_in_place(
    n: usize,
    mass: &[f64],
    f: &mut [f64],
    work: &mut [f64],
    envelope: &mut [usize],
) -> Option<()> {
    let m = |i: usize, j: usize| mass[i + j * n];
    match n {
        1 => {
            let a = m(0, 0);
            // Not positive, or NaN.
            if a.is_nan() || a <= 0.0 {
                return None;
            }
            f[0] /= a;
            return Some(());
        }
        2 => {
            let (a, b, c) = (m(0, 0), m(1, 0), m(1, 1));
            let det = a * c - b * b;
            // Not positive definite, or NaN.
            if a.is_nan() || a <= 0.0 || det.is_nan() || det <= 0.0 {
                return None;
            }
            let inverse = 1.0 / det;
            let (f0, f1) = (f[0], f[1]);
            f[0] = (c * f0 - b * f1) * inverse;
            f[1] = (a * f1 - b * f0) * inverse;
            return Some(());
        }
        _ => {}
    }
    let (l, rest) = work.split_at_mut(n * n);
    let (d, inv_d) = rest.split_at_mut(n);
    if n >= ENVELOPE_FROM {
        return solve_in_envelope(n, m, f, l, d, inv_d, envelope);
    }
    // `l[i][k]` of `solve_spd` is `l[i * n + k]`.
    for j in 0..n {
        let mut dj = m(j, j);
        for k in 0..j {
            dj -= l[j * n + k] * l[j * n + k] * d[k];
        }
        // Not positive, or NaN.
        if dj.is_nan() || dj <= 0.0 {
            return None;
        }
        d[j] = dj;
        inv_d[j] = 1.0 / dj;
        for i in j + 1..n {
            let mut v = m(i, j);
            for k in 0..j {
                v -= l[i * n + k] * l[j * n + k] * d[k];
            }
            l[i * n + j] = v * inv_d[j];
        }
    }
    for i in 0..n {
        for k in 0..i {
            f[i] -= l[i * n + k] * f[k];
        }
    }
    for i in 0..n {
        f[i] *= inv_d[i];
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            f[i] -= l[k * n + i] * f[k];
        }
    }
    Some(())
}

/// The size from which [`solve_spd`] and [`solve_spd_in_place`] factorise within the envelope
/// of `M` (`solve_in_envelope`); smaller systems take every row whole, which the compiler
/// unrolls for the compiled models' hot path.
pub const ENVELOPE_FROM: usize = 9;

/// The `L D Lᵀ` solve of [`solve_spd`] restricted to the envelope of `M`: row `i` of `L` starts
/// at the first non-zero entry `fᵢ` of row `i` of `M` (a NaN counts as non-zero), since `L`
/// has no fill-in left of it (Golub & Van Loan, *Matrix Computations*, 4th ed., §4.3.5, on
/// the profile of a Cholesky factor). Inside the envelope the operations are the dense ones in
/// the same order, and every term left out is a product with an exact zero of `L`, so the
/// result is the dense factorisation's up to the sign of zeros, and a dense `M` gives it to
/// the bit. A diagonal `M` (a chain of point masses) is solved in `O(n)` after the `O(n²)`
/// scan for the envelope, a banded one in `O(n b²)`, where the dense solve takes `n³/6`
/// multiply–adds: 1.7 × 10⁸ per right-hand side for a chain of 1000 masses.
///
/// `m(i, j)` is entry `(i, j)` of `M` (lower triangle read); `l` holds `n²` values
/// (row-major), `d` and `inv_d` `n` each, `envelope` `2n` (each row's `fᵢ`, then each
/// column's last row in the envelope); `f` becomes `x`. `None` when a pivot is
/// not positive or is NaN.
#[inline]
fn solve_in_envelope(
    n: usize,
    m: impl Fn(usize, usize) -> f64,
    f: &mut [f64],
    l: &mut [f64],
    d: &mut [f64],
    inv_d: &mut [f64],
    envelope: &mut [usize],
) -> Option<()> {
    let (first, reach) = envelope.split_at_mut(n);
    // fᵢ, found column by column (contiguous in a column-major `M`): the first column whose
    // entry is non-zero; a row with none starts at its diagonal.
    for (i, fi) in first.iter_mut().enumerate().take(n) {
        *fi = i;
    }
    for j in 0..n {
        for (i, fi) in first.iter_mut().enumerate().skip(j + 1) {
            if *fi == i && m(i, j) != 0.0 {
                *fi = j;
            }
        }
    }
    // reachⱼ = the last row `i` with `fᵢ ≤ j` (at least `j`): the rows below it have no entry
    // in column `j` of `L`, so the loops over a column stop there.
    for (j, r) in reach.iter_mut().enumerate().take(n) {
        *r = j;
    }
    for i in 0..n {
        reach[first[i]] = reach[first[i]].max(i);
    }
    for j in 1..n {
        reach[j] = reach[j].max(reach[j - 1]);
    }
    for j in 0..n {
        let fj = first[j];
        let mut dj = m(j, j);
        for k in fj..j {
            dj -= l[j * n + k] * l[j * n + k] * d[k];
        }
        // Not positive, or NaN.
        if dj.is_nan() || dj <= 0.0 {
            return None;
        }
        d[j] = dj;
        inv_d[j] = 1.0 / dj;
        for i in j + 1..=reach[j] {
            let fi = first[i];
            if fi > j {
                continue;
            }
            let mut v = m(i, j);
            for k in fi.max(fj)..j {
                v -= l[i * n + k] * l[j * n + k] * d[k];
            }
            l[i * n + j] = v * inv_d[j];
        }
    }
    for i in 0..n {
        for k in first[i]..i {
            f[i] -= l[i * n + k] * f[k];
        }
    }
    for i in 0..n {
        f[i] *= inv_d[i];
    }
    for i in (0..n).rev() {
        for k in i + 1..=reach[i] {
            if first[k] <= i {
                f[i] -= l[k * n + i] * f[k];
            }
        }
    }
    Some(())
}

/// The forward-difference Jacobian `∂f/∂y` of a function `f: ℝᵈ → ℝᵏ` at `y`, from
/// `f0 = f(y)`, into `jac` (`k × d`, column-major), with RADAU5's increments
/// `δⱼ = √(ε · max(10⁻⁵, |yⱼ|))` (`d` evaluations of `f`).
///
/// This is the one fallback for an exact Jacobian that is not finite where `f` is: a
/// derivative can have a removable singularity that the function has not (quadratic drag
/// `|v| v`, with `|v| = √(vₓ² + v_y²)`, has `vₓ²/|v|`, 0/0 at rest, where the derivative is
/// 0; its difference is `c δ`, of the order of 1e-11 c). The implicit integrators' Newton
/// iteration ([`RadauIIA5`](crate::RadauIIA5), [`ImplicitMidpoint`](crate::ImplicitMidpoint)),
/// the linearisation of [`modal`](crate::linear::modal) and the failure diagnosis all use it.
///
/// # Arguments
/// * `y`      - the point (length `d`).
/// * `f0`     - `f(y)` (length `k`).
/// * `jac`    - the result, `k × d` column-major (length `k d`).
/// * `work_y` - scratch of length `d`; holds `y` on return.
/// * `work_f` - scratch of length `k`.
/// * `eval`   - evaluates `f` at its first argument into its second.
///
/// # Errors
/// The first error of `eval`; `jac` is then partly written.
///
/// # Panics
/// If the lengths do not match (a programmer error).
pub fn forward_differences<E>(
    y: &[f64],
    f0: &[f64],
    jac: &mut [f64],
    work_y: &mut [f64],
    work_f: &mut [f64],
    mut eval: impl FnMut(&[f64], &mut [f64]) -> Result<(), E>,
) -> Result<(), E> {
    let (d, k) = (y.len(), f0.len());
    assert!(jac.len() == k * d && work_y.len() == d && work_f.len() == k);
    work_y.copy_from_slice(y);
    for j in 0..d {
        let delta = (f64::EPSILON * y[j].abs().max(1e-5)).sqrt();
        work_y[j] = y[j] + delta;
        let result = eval(&*work_y, &mut *work_f);
        work_y[j] = y[j];
        result?;
        for i in 0..k {
            jac[i + j * k] = (work_f[i] - f0[i]) / delta;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

    use super::*;

    /// The closed forms for 1 × 1 and 2 × 2 against nalgebra's Cholesky solve, well and badly
    /// conditioned (κ ≈ 4e8): both are backward stable, so they agree to a few ulps of κ, and
    /// the residual is within a few ulps of κ |f|; `None` for indefinite, singular, negative
    /// and NaN matrices.
    #[test]
    fn solve_spd_closed_forms_match_cholesky_and_refuse_what_is_not_positive_definite() {
        for (m, f) in [
            (Matrix2::new(2.3, -0.7, -0.7, 0.9), Vector2::new(0.4, -1.1)),
            (
                Matrix2::new(1.0, 0.99999999, 0.99999999, 1.0),
                Vector2::new(1.0, 2.0),
            ),
        ] {
            let x = solve_spd(&m, &f).unwrap();
            let expected = nalgebra::Cholesky::new(m).unwrap().solve(&f);
            let condition = m.norm() * m.try_inverse().unwrap().norm();
            assert!(
                (x - expected).amax() <= 8.0 * f64::EPSILON * condition * expected.amax(),
                "{x} vs {expected}"
            );
            assert!(
                (m * x - f).amax() <= 16.0 * f64::EPSILON * f.amax() * condition,
                "residual"
            );
        }
        for bad in [
            Matrix2::new(1.0, 2.0, 2.0, 1.0),
            Matrix2::new(1.0, 1.0, 1.0, 1.0),
            Matrix2::new(-1.0, 0.0, 0.0, -1.0),
            Matrix2::new(f64::NAN, 0.0, 0.0, 1.0),
            Matrix2::new(1.0, 0.0, 0.0, f64::NAN),
        ] {
            assert_eq!(solve_spd(&bad, &Vector2::new(1.0, 1.0)), None, "{bad}");
        }
        let one = nalgebra::Matrix1::new(4.0);
        assert_eq!(
            solve_spd(&one, &nalgebra::Vector1::new(2.0)),
            Some(nalgebra::Vector1::new(0.5))
        );
        for bad in [0.0, -1.0, f64::NAN] {
            let m = nalgebra::Matrix1::new(bad);
            assert_eq!(solve_spd(&m, &nalgebra::Vector1::new(1.0)), None);
        }
    }

    /// `solve_spd` (the `L D Lᵀ` path) against nalgebra's Cholesky solve on a positive
    /// definite `M = BᵀB + I` (condition ~10): the two backward-stable solves agree to a few
    /// ulps of `|x|`, so 1e-13 relative; and `None` for an indefinite, a singular and a NaN
    /// matrix.
    #[test]
    fn solve_spd_matches_cholesky_and_refuses_what_is_not_positive_definite() {
        let b = Matrix3::new(1.0, 0.3, -0.7, 0.2, 1.5, 0.4, -0.6, 0.1, 0.9);
        let m = b.transpose() * b + Matrix3::identity();
        let f = Vector3::new(0.7, -1.3, 2.1);
        let x = solve_spd(&m, &f).unwrap();
        let expected = nalgebra::Cholesky::new(m).unwrap().solve(&f);
        assert!(
            (x - expected).amax() <= 1e-13 * expected.amax(),
            "{x} vs {expected}"
        );
        let indefinite = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert_eq!(solve_spd(&indefinite, &f), None);
        let singular = Matrix3::new(1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert_eq!(solve_spd(&singular, &f), None);
        let mut nan = m;
        nan[(1, 1)] = f64::NAN;
        assert_eq!(solve_spd(&nan, &f), None);
    }

    /// The `L D Lᵀ` solve taking every row whole (the factorisation below
    /// [`ENVELOPE_FROM`]), written out for any size: the reference the envelope must match.
    fn dense_ldlt(n: usize, m: &[f64], f: &[f64]) -> Option<Vec<f64>> {
        let mut l = vec![0.0; n * n];
        let (mut d, mut x) = (vec![0.0; n], f.to_vec());
        for j in 0..n {
            let mut dj = m[j + j * n];
            for k in 0..j {
                dj -= l[j * n + k] * l[j * n + k] * d[k];
            }
            if dj.is_nan() || dj <= 0.0 {
                return None;
            }
            d[j] = dj;
            let inv = 1.0 / dj;
            for i in j + 1..n {
                let mut v = m[i + j * n];
                for k in 0..j {
                    v -= l[i * n + k] * l[j * n + k] * d[k];
                }
                l[i * n + j] = v * inv;
            }
        }
        for i in 0..n {
            for k in 0..i {
                x[i] -= l[i * n + k] * x[k];
            }
        }
        for i in 0..n {
            x[i] *= 1.0 / d[i];
        }
        for i in (0..n).rev() {
            for k in i + 1..n {
                x[i] -= l[k * n + i] * x[k];
            }
        }
        Some(x)
    }

    /// From [`ENVELOPE_FROM`] on, the solve skips the zeros left of each row's first entry:
    /// on a dense, a banded (bandwidth 2, with a full last row and column, which fills the
    /// whole bottom row), a block-diagonal and a diagonal `M` of sizes 9–40 its result equals
    /// the dense factorisation's to the bit (the skipped terms are exact zeros), the
    /// compile-time and run-time entry points agree to the bit, and the residual is at
    /// rounding level (1e-12 relative; the matrices are diagonally dominant, κ < 10).
    /// Indefinite and NaN matrices are refused as before.
    #[test]
    fn the_envelope_solve_is_the_dense_one_on_sparse_and_dense_matrices() {
        // Whether entry (i, j) of an n × n matrix is in the pattern.
        type Pattern = fn(usize, usize, usize) -> bool;
        let shapes: [(&str, Pattern); 4] = [
            ("dense", |_, _, _| true),
            ("banded", |i, j, n| {
                i.abs_diff(j) <= 2 || i == n - 1 || j == n - 1
            }),
            ("blocks", |i, j, _| i / 5 == j / 5),
            ("diagonal", |i, j, _| i == j),
        ];
        for n in [ENVELOPE_FROM, 12, 40] {
            for (name, shape) in shapes {
                // Symmetric entries in (−1, 1) on the pattern, diagonal n + 1: dominant.
                let mut m = vec![0.0; n * n];
                for i in 0..n {
                    for j in 0..=i {
                        if shape(i, j, n) {
                            let v = if i == j {
                                n as f64 + 1.0
                            } else {
                                ((i * 7 + j * 3) % 11) as f64 / 11.0 - 0.45
                            };
                            m[i + j * n] = v;
                            m[j + i * n] = v;
                        }
                    }
                }
                let f: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
                let expected = dense_ldlt(n, &m, &f).unwrap();
                let mut x = f.clone();
                let mut work = vec![0.0; n * n + 2 * n];
                let mut envelope = vec![0; 2 * n];
                solve_spd_in_place(n, &m, &mut x, &mut work, &mut envelope).unwrap();
                for (a, b) in x.iter().zip(&expected) {
                    assert_eq!(a.to_bits(), b.to_bits(), "{name} {n}: {x:?} {expected:?}");
                }
                for i in 0..n {
                    let r: f64 = (0..n).map(|j| m[i + j * n] * x[j]).sum::<f64>() - f[i];
                    assert!(r.abs() < 1e-12 * (n as f64), "{name} {n}: residual {r}");
                }
                if n == 12 {
                    let sm = nalgebra::SMatrix::<f64, 12, 12>::from_column_slice(&m);
                    let sf = nalgebra::SVector::<f64, 12>::from_column_slice(&f);
                    let sx = solve_spd(&sm, &sf).unwrap();
                    assert!(sx.iter().zip(&x).all(|(a, b)| a.to_bits() == b.to_bits()));
                }
                let mut indefinite = m.clone();
                indefinite[(n - 1) + (n - 1) * n] = -1.0;
                let mut nan = m.clone();
                nan[(n - 1) + (n / 2) * n] = f64::NAN;
                for bad in [indefinite, nan] {
                    let mut x = f.clone();
                    assert_eq!(
                        solve_spd_in_place(n, &bad, &mut x, &mut work, &mut envelope),
                        None,
                        "{name} {n}"
                    );
                }
            }
        }
    }
}

#[cfg(test)]
mod bounded_eigen_tests {
    use super::*;

    /// The companion matrix of `x¹¹ − 770.97/434.4` from nalgebra issue #611, on which its
    /// unbounded Schur iteration cycled forever in 2019 (nalgebra 0.35 converges on it, and on
    /// a NaN entry, so this cannot show the bound biting): the bounded one returns (the test
    /// runs it on a thread and waits 20 s at most), with eigenvalues or with `None`; the 11
    /// roots, where given, have modulus `(770.97/434.4)^(1/11)` to 1e-10. A non-finite entry
    /// gives `None` without iterating.
    #[test]
    fn the_bounded_eigenvalues_return_on_a_matrix_that_cycles_nalgebra() {
        let n = 11;
        let mut a = DMatrix::zeros(n, n);
        for i in 1..n {
            a[(i, i - 1)] = 1.0;
        }
        a[(0, n - 1)] = 770.970_005_929_470_1 / 434.395_990_908_145_9;
        let (send, receive) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let _ = send.send(eigenvalues(&a));
        });
        let values = receive
            .recv_timeout(std::time::Duration::from_secs(20))
            .expect("the bounded Schur iteration returns");
        if let Some(values) = values {
            let r = (770.970_005_929_470_1f64 / 434.395_990_908_145_9).powf(1.0 / 11.0);
            for v in values {
                assert!((v.norm() - r).abs() < 1e-10, "{v}");
            }
        }
        let mut bad = DMatrix::identity(3, 3);
        bad[(0, 1)] = f64::NAN;
        assert!(eigenvalues(&bad).is_none());
        assert!(symmetric_eigen(bad).is_none());
    }
}
