//! Small numerical helpers of the derivation checks and the rank tests: a dense solve
//! ([`solve`]), below every file that uses it.

/// Solves `m x = f` (`m` is `n × n` row-major) by Gaussian elimination with partial pivoting;
/// `None` if a pivot vanishes or is not finite.
pub fn solve(mut m: Vec<f64>, mut f: Vec<f64>) -> Option<Vec<f64>> {
    let n = f.len();
    for c in 0..n {
        let p = (c..n).max_by(|a, b| m[a * n + c].abs().total_cmp(&m[b * n + c].abs()))?;
        if m[p * n + c] == 0.0 || !m[p * n + c].is_finite() {
            return None;
        }
        for k in 0..n {
            m.swap(c * n + k, p * n + k);
        }
        f.swap(c, p);
        for r in c + 1..n {
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
}
