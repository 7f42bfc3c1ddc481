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
