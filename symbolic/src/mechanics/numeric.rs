//! Small numerical helpers of the derivation checks and the rank tests: a dense solve
//! ([`solve`]), below every file that uses it.

/// Solves `m x = f` (`m` is `n × n` row-major) by Gaussian elimination with partial pivoting;
/// `None` if a pivot vanishes or is not finite.
///
/// A row whose entry in the pivot column is exactly zero is left as it is when the pivot row
/// is finite (subtracting `0 ×` a finite row changes at most the sign of a zero), so a sparse
/// matrix costs what its fill-in costs: the diagonal mass matrix of a 1000-mass chain is
/// solved in `O(n²)` instead of `n³/3` operations (`eomgen check` solves it hundreds of times).
pub fn solve(mut m: Vec<f64>, mut f: Vec<f64>) -> Option<Vec<f64>> {
    let n = f.len();
    for c in 0..n {
        let p = (c..n).max_by(|a, b| m[a * n + c].abs().total_cmp(&m[b * n + c].abs()))?;
        if m[p * n + c] == 0.0 || !m[p * n + c].is_finite() {
            return None;
        }
        if p != c {
            for k in 0..n {
                m.swap(c * n + k, p * n + k);
            }
            f.swap(c, p);
        }
        // With a non-finite entry in the pivot row, `0 × ∞` must still give its NaN.
        let finite_row =
            f[c].is_finite() && m[c * n + c..(c + 1) * n].iter().all(|x| x.is_finite());
        for r in c + 1..n {
            if finite_row && m[r * n + c] == 0.0 {
                continue;
            }
            let factor = m[r * n + c] / m[c * n + c];
            for k in c..n {
                m[r * n + k] -= factor * m[c * n + k];
            }
            f[r] -= factor * f[c];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| m[r * n + k] * x[k]).sum();
        x[r] = (f[r] - s) / m[r * n + r];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 × 4 system that needs row exchanges (a zero at the first pivot), against its
    /// known solution (residual of rounding, 1e-14).
    #[test]
    fn a_system_needing_pivoting_is_solved() {
        let m = vec![
            0.0, 2.0, 1.0, -1.0, //
            3.0, 1.0, 0.0, 2.0, //
            1.0, -1.0, 4.0, 0.5, //
            2.0, 0.0, -2.0, 5.0,
        ];
        let x = [1.0, -2.0, 0.5, 3.0];
        let f: Vec<f64> = (0..4)
            .map(|r| (0..4).map(|k| m[r * 4 + k] * x[k]).sum())
            .collect();
        let got = solve(m, f).unwrap();
        for (a, b) in got.iter().zip(x) {
            assert!((a - b).abs() < 1e-14, "{got:?}");
        }
    }

    /// A singular matrix (at the first or a later pivot), a zero one or one with a NaN has
    /// no solution.
    #[test]
    fn singular_or_non_finite_matrices_have_no_solution() {
        assert!(solve(vec![1.0, 2.0, 2.0, 4.0], vec![1.0, 1.0]).is_none());
        assert!(solve(vec![0.0; 4], vec![1.0, 1.0]).is_none());
        let singular_last = vec![1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0];
        assert!(solve(singular_last, vec![1.0; 3]).is_none());
        assert!(solve(vec![f64::NAN, 0.0, 0.0, 1.0], vec![1.0, 1.0]).is_none());
        assert!(solve(vec![1.0, 0.0, 0.0, f64::INFINITY], vec![1.0, 1.0]).is_none());
    }

    /// A tridiagonal 200 × 200 system (most rows skipped at every column) against its known
    /// solution, to rounding (1e-13: diagonally dominant, κ < 3); and a zero below a pivot
    /// row holding ∞ still meets `0 × ∞` (the elimination gives NaN, and the solve fails as
    /// the dense one does) rather than being skipped into a finite answer.
    #[test]
    fn sparse_rows_are_skipped_without_changing_the_solution() {
        let n = 200;
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            m[i * n + i] = 4.0;
            if i > 0 {
                m[i * n + i - 1] = -1.0;
                m[(i - 1) * n + i] = -1.5;
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).cos()).collect();
        let f: Vec<f64> = (0..n)
            .map(|r| (0..n).map(|k| m[r * n + k] * x[k]).sum())
            .collect();
        let got = solve(m, f).unwrap();
        for (a, b) in got.iter().zip(&x) {
            assert!((a - b).abs() < 1e-13, "{a} {b}");
        }
        assert!(solve(vec![1.0, f64::INFINITY, 0.0, 1.0], vec![1.0, 1.0]).is_none());
    }
}
