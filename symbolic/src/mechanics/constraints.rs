//! Constraints as the runtime needs them (lectures 8–11; DESIGN.md "Constraints").
//!
//! Holonomic constraints `Φ(q, t) = 0` (`constraints:`) and non-holonomic constraints
//! `g(q, q̇, t) = A(q, t) q̇ + b(q, t) = 0` (`nonholonomic:`) are both differentiated to the
//! acceleration level, `J q̈ = γ`, for the index-1 form
//!
//! ```text
//! [ M  Jᵀ ] [ q̈ ]   [ F ]
//! [ J  0  ] [ λ ] = [ γ ]
//! ```
//!
//! - holonomic: `J = ∂Φ/∂q`, the velocity residual `Φ̇ = J q̇ + Φ_t`, and
//!   `γ = −(J q̇)_q q̇ − 2 J_t q̇ − Φ_tt`, obtained as `−Φ̈` with `q̈ = 0`;
//! - non-holonomic: `J = A = ∂g/∂q̇`, the velocity residual `g` itself, and `γ = −ġ` with
//!   `q̈ = 0` (that is `−(Ȧ q̇ + ḃ)`).
//!
//! With `M q̈ = F − Jᵀ λ`, `λᵢ` is the generalized force that constraint `i` exerts along
//! `−∇Φᵢ`: for a rod written in distance form `Φ = |r_A − r_B| − ℓ`, `λ` is the rod's tension
//! in N, positive in tension (the force on A is `−λ (r_A − r_B)/|r_A − r_B|`).

use rustc_hash::FxHashMap;

use crate::expr::{ExprArena, ExprId, SymbolId};

/// The constraints of a model at the acceleration level. Holonomic constraints come first.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ConstraintEquations {
    /// Constraint names, holonomic then non-holonomic (`m` in all).
    pub names: Vec<String>,
    /// How many of them are holonomic (the first ones).
    pub holonomic: usize,
    /// `Φ(q, t)` of the holonomic constraints (length `holonomic`).
    pub phi: Vec<ExprId>,
    /// `J`, `m × n` row-major: `∂Φ/∂q` rows, then `A` rows.
    pub jacobian: Vec<ExprId>,
    /// Velocity residuals (length `m`): `Φ̇ = J q̇ + Φ_t`, then `A q̇ + b`.
    pub velocity: Vec<ExprId>,
    /// `γ` of `J q̈ = γ` (length `m`).
    pub gamma: Vec<ExprId>,
}

impl ConstraintEquations {
    /// Number of constraints `m`.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether the model has no constraints.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Differentiates the constraints; `symbols` are the `(q, q̇, q̈)` symbols per coordinate,
    /// `holonomic` the `(name, Φ)` and `nonholonomic` the `(name, g)` pairs.
    pub fn derive(
        arena: &mut ExprArena,
        symbols: &[[SymbolId; 3]],
        holonomic: &[(String, ExprId)],
        nonholonomic: &[(String, ExprId)],
    ) -> Self {
        let zero = arena.int(0);
        let at_rest: FxHashMap<SymbolId, ExprId> = symbols.iter().map(|s| (s[2], zero)).collect();
        let mut out = Self {
            holonomic: holonomic.len(),
            ..Self::default()
        };
        for (name, phi) in holonomic {
            out.names.push(name.clone());
            out.phi.push(*phi);
            for s in symbols {
                out.jacobian.push(arena.diff(*phi, s[0]));
            }
            let rate = arena.time_derivative(*phi);
            out.velocity.push(rate);
            let second = arena.time_derivative(rate);
            let rest = arena.substitute(second, &at_rest);
            out.gamma.push(arena.neg(rest));
        }
        for (name, g) in nonholonomic {
            out.names.push(name.clone());
            for s in symbols {
                out.jacobian.push(arena.diff(*g, s[1]));
            }
            out.velocity.push(*g);
            let rate = arena.time_derivative(*g);
            let rest = arena.substitute(rate, &at_rest);
            out.gamma.push(arena.neg(rest));
        }
        out
    }
}

/// Whether `g` is linear (affine) in the rates: every `∂²g/∂q̇ᵢ∂q̇ⱼ` expands to zero.
pub fn linear_in_rates(arena: &mut ExprArena, g: ExprId, symbols: &[[SymbolId; 3]]) -> bool {
    symbols.iter().all(|a| {
        let d = arena.diff(g, a[1]);
        symbols.iter().all(|b| {
            let dd = arena.diff(d, b[1]);
            let dd = arena.expand(dd);
            arena.is_zero(dd)
        })
    })
}

/// Constraints whose Jacobian rows depend on earlier rows at every sampled configuration:
/// for each, its index and the indices of the earlier constraints it combines (least-squares
/// coefficients above `1e-8` relative).
///
/// `rows` holds, per sample, the `m × n` Jacobian row-major. A row is dependent at a sample
/// when its component orthogonal to the earlier independent rows is below `1e-9` of its
/// norm (or the row is zero); a constraint is reported only if that holds at every sample, so
/// a singular configuration that a random sample happens to hit is not an error.
pub fn redundant_rows(samples: &[Vec<f64>], m: usize, n: usize) -> Vec<(usize, Vec<usize>)> {
    let mut found = Vec::new();
    let mut dependent_everywhere = vec![true; m];
    let mut combination: Vec<Vec<usize>> = vec![Vec::new(); m];
    for (k, jac) in samples.iter().enumerate() {
        let row = |i: usize| &jac[i * n..(i + 1) * n];
        // Orthonormal basis of the independent rows so far (modified Gram–Schmidt).
        let mut basis: Vec<Vec<f64>> = Vec::new();
        let mut independent: Vec<usize> = Vec::new();
        for i in 0..m {
            let mut r = row(i).to_vec();
            let norm0 = r.iter().map(|x| x * x).sum::<f64>().sqrt();
            for b in &basis {
                let c: f64 = r.iter().zip(b).map(|(x, y)| x * y).sum();
                for (x, y) in r.iter_mut().zip(b) {
                    *x -= c * y;
                }
            }
            let norm = r.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm0 == 0.0 || norm <= 1e-9 * norm0 {
                if k == 0 {
                    combination[i] = involved(row(i), &independent, &row, n);
                }
            } else {
                dependent_everywhere[i] = false;
                for x in &mut r {
                    *x /= norm;
                }
                basis.push(r);
                independent.push(i);
            }
        }
    }
    for i in 0..m {
        if dependent_everywhere[i] && !samples.is_empty() {
            found.push((i, std::mem::take(&mut combination[i])));
        }
    }
    found
}

/// `q ↦ (Φ, J)` of the holonomic constraints: `Φ` (one per constraint) and `J` (row-major,
/// constraints × coordinates).
pub type HolonomicValues<'a> = dyn FnMut(&[f64]) -> (Vec<f64>, Vec<f64>) + 'a;

/// Whether a holonomic constraint whose Jacobian row depends on those of `independent`
/// everywhere is consistent with them: Gauss–Newton (minimum-norm steps) puts `q` on
/// `Φ_independent = 0` from `q0`, and there the dependent constraint's residual is returned
/// (zero when it is redundant, non-zero when it contradicts them: its gradient lies in the
/// span of theirs, so it is constant along their solution set and no `q` satisfies all).
///
/// `eval(q)` gives `Φ` of every holonomic constraint and their Jacobian (row-major,
/// `holonomic × n`) at `q`. `None` when Newton does not converge from `q0` in 50 steps or
/// meets a non-finite value.
pub fn residual_where_others_hold(
    eval: &mut HolonomicValues<'_>,
    q0: &[f64],
    independent: &[usize],
    dependent: usize,
) -> Option<f64> {
    let n = q0.len();
    let mut q = q0.to_vec();
    for _ in 0..50 {
        let (phi, jac) = eval(&q);
        let r: Vec<f64> = independent.iter().map(|&i| phi[i]).collect();
        if !phi.iter().chain(&jac).all(|v| v.is_finite()) {
            return None;
        }
        let scale = q.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        if r.iter().all(|v| v.abs() <= 1e-13 * scale) {
            return Some(phi[dependent]);
        }
        let row = |i: usize| &jac[i * n..(i + 1) * n];
        let k = independent.len();
        let mut gram = vec![0.0; k * k];
        for (a, &i) in independent.iter().enumerate() {
            for (b, &j) in independent.iter().enumerate() {
                gram[a * k + b] = row(i).iter().zip(row(j)).map(|(x, y)| x * y).sum();
            }
        }
        let y = super::numeric::solve(gram, r)?;
        for (a, &i) in independent.iter().enumerate() {
            for (qc, jc) in q.iter_mut().zip(row(i)) {
                *qc -= jc * y[a];
            }
        }
    }
    None
}

/// The earlier rows (`among`) with a non-negligible least-squares coefficient in `target`.
fn involved<'a>(
    target: &[f64],
    among: &[usize],
    row: &dyn Fn(usize) -> &'a [f64],
    n: usize,
) -> Vec<usize> {
    let k = among.len();
    if k == 0 {
        return Vec::new();
    }
    // Normal equations (R Rᵀ) c = R target.
    let mut gram = vec![0.0; k * k];
    let mut rhs = vec![0.0; k];
    for (a, &i) in among.iter().enumerate() {
        for (b, &j) in among.iter().enumerate() {
            gram[a * k + b] = (0..n).map(|c| row(i)[c] * row(j)[c]).sum();
        }
        rhs[a] = (0..n).map(|c| row(i)[c] * target[c]).sum();
    }
    let Some(c) = super::numeric::solve(gram, rhs) else {
        return among.to_vec();
    };
    let scale = c.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    among
        .iter()
        .zip(&c)
        .filter(|(_, x)| x.abs() > 1e-8 * scale)
        .map(|(i, _)| *i)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_repeated_row_is_redundant_with_the_first() {
        // Rows: (1, 0), (0, 1), (2, 0) at two samples; (2, 0) = 2 (1, 0).
        let s = vec![vec![1.0, 0.0, 0.0, 1.0, 2.0, 0.0]; 2];
        assert_eq!(redundant_rows(&s, 3, 2), vec![(2, vec![0])]);
    }

    /// `x = 1` and `x = 2` (with `y` free): the rows are equal, and where the first holds
    /// the second is −1, not 0; `2 x = 2` is redundant with `x = 1` (residual 0).
    #[test]
    fn a_contradicting_repetition_keeps_its_residual_and_a_redundant_one_vanishes() {
        let mut eval = |q: &[f64]| {
            (
                vec![q[0] - 1.0, q[0] - 2.0, 2.0 * q[0] - 2.0],
                vec![1.0, 0.0, 1.0, 0.0, 2.0, 0.0],
            )
        };
        let r = residual_where_others_hold(&mut eval, &[0.3, -0.7], &[0], 1).unwrap();
        assert!((r + 1.0).abs() < 1e-12, "{r}");
        let r = residual_where_others_hold(&mut eval, &[0.3, -0.7], &[0], 2).unwrap();
        assert!(r.abs() < 1e-12, "{r}");
    }

    #[test]
    fn a_row_dependent_at_one_sample_only_is_not_redundant() {
        let a = vec![1.0, 0.0, 1.0, 0.0];
        let b = vec![1.0, 0.0, 0.0, 1.0];
        assert!(redundant_rows(&[a, b], 2, 2).is_empty());
    }
}
