//! Constraints as the runtime needs them (lectures 8–11; docs/model-format.md, *Constraints*).
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
/// norm, or when the row itself is below `1e-12` of the largest row: a row that is zero in
/// exact arithmetic but evaluates to rounding (`x − (x + a) + a`, a rolling contact's row
/// along the ground normal, 1e-17) is a zero row, not a constraint. A constraint is reported
/// only if that holds at every sample, so a singular configuration that a random sample
/// happens to hit is not an error.
pub fn redundant_rows(samples: &[Vec<f64>], m: usize, n: usize) -> Vec<(usize, Vec<usize>)> {
    let mut found = Vec::new();
    let mut dependent_everywhere = vec![true; m];
    let mut combination: Vec<Vec<usize>> = vec![Vec::new(); m];
    for (k, jac) in samples.iter().enumerate() {
        let row = |i: usize| &jac[i * n..(i + 1) * n];
        // Against the largest row: a row in other units 1e12 times smaller (an angle beside a
        // length of 1e13 m) would be taken for zero, as the test below already takes rows
        // apart by 1e9 for dependent; column scaling cannot tell a row of rounding from one
        // of small units, since a column that only rounding fills is scaled up with it.
        let norm_of = |i: usize| row(i).iter().map(|x| x * x).sum::<f64>().sqrt();
        let largest = (0..m).map(norm_of).fold(0.0f64, f64::max);
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
            if norm0 <= 1e-12 * largest {
                // A zero row: it combines nothing.
                if k == 0 {
                    combination[i] = Vec::new();
                }
            } else if norm <= 1e-9 * norm0 {
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

/// The residual of a dependent holonomic constraint where the others hold, with the scale it
/// is measured against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DependentResidual {
    /// `Φ_dependent` at the point found on the others' solution set (the constraint's units).
    pub residual: f64,
    /// The size of the constraint's terms there, `max(1, Σⱼ |J_dependent,j qⱼ|)` (over the
    /// coordinates it uses only): a redundant constraint's residual is rounding and Newton's
    /// stopping error, far below `1e-8` of it.
    pub scale: f64,
}

impl DependentResidual {
    /// Whether the constraint contradicts the others: its residual is above `1e-8` of its
    /// scale (Newton stops at 1e-13 of the others' scales; a redundant constraint of a
    /// mechanism of 1e7 m is still redundant). At scales below 1 the bound is absolute, 1e-8
    /// in the model's units: a contradiction smaller than that is taken for redundancy.
    pub fn contradicts(&self) -> bool {
        self.residual.abs() > 1e-8 * self.scale
    }
}

/// The largest magnitude in `v` (0 for an empty slice).
fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Whether a holonomic constraint whose Jacobian row depends on those of `independent`
/// everywhere is consistent with them: Gauss–Newton (minimum-norm steps) puts `q` on
/// `Φ_independent = 0` from `q0`, and there the dependent constraint's residual is returned
/// (zero when it is redundant, non-zero when it contradicts them: its gradient lies in the
/// span of theirs, so it is constant along their solution set and no `q` satisfies all).
/// Newton stops when every `|Φᵢ|` is below `1e-13 max(1, Σⱼ |Jᵢⱼ qⱼ|)`, relative to the size
/// of the constraint's terms so that a mechanism of any size converges.
///
/// `eval(q)` gives `Φ` of every holonomic constraint and their Jacobian (row-major,
/// `holonomic × n`) at `q`. `None` when Newton does not converge from `q0` in 50 steps or
/// meets a non-finite value.
pub fn residual_where_others_hold(
    eval: &mut HolonomicValues<'_>,
    q0: &[f64],
    independent: &[usize],
    dependent: usize,
) -> Option<DependentResidual> {
    let n = q0.len();
    let mut q = q0.to_vec();
    for _ in 0..50 {
        let (phi, jac) = eval(&q);
        let r: Vec<f64> = independent.iter().map(|&i| phi[i]).collect();
        if !phi.iter().chain(&jac).all(|v| v.is_finite()) {
            return None;
        }
        let row = |i: usize| &jac[i * n..(i + 1) * n];
        // The size of constraint i's terms: Σⱼ |Jᵢⱼ qⱼ|, over the coordinates it uses.
        let scale = |i: usize| {
            row(i)
                .iter()
                .zip(&q)
                .map(|(j, x)| (j * x).abs())
                .sum::<f64>()
                .max(1.0)
        };
        if r.iter()
            .zip(independent)
            .all(|(v, &i)| v.abs() <= 1e-13 * scale(i))
        {
            return Some(DependentResidual {
                residual: phi[dependent],
                scale: scale(dependent),
            });
        }
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
    let scale = max_abs(&c);
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
        assert!((r.residual + 1.0).abs() < 1e-12 && r.contradicts(), "{r:?}");
        let r = residual_where_others_hold(&mut eval, &[0.3, -0.7], &[0], 2).unwrap();
        assert!(r.residual.abs() < 1e-12 && !r.contradicts(), "{r:?}");
    }

    use crate::expr::eval::Evaluator;
    use crate::expr::{ExprArena, SymbolKind};

    /// An arena with coordinates `x`, `y`, `θ` (and their rates and accelerations), time
    /// and a parameter `w`; returns the arena, the `(q, q̇, q̈)` symbols and the expressions
    /// `[x, y, θ, ẋ, ẏ, t, w]`.
    fn planar() -> (ExprArena, Vec<[SymbolId; 3]>, [ExprId; 7]) {
        let mut arena = ExprArena::new();
        let [x, y, th] = ["x", "y", "theta"].map(|name| arena.coordinate(name));
        let t = arena.time();
        let w = arena.symbol("w", SymbolKind::Parameter);
        let symbols = arena.coordinates().to_vec();
        (arena, symbols, [x[0], y[0], th[0], x[1], y[1], t, w])
    }

    /// Values of `roots` with `q = (x, y, θ)`, `q̇`, `q̈ = 0`, `t` and `w` bound.
    fn values(arena: &ExprArena, roots: &[ExprId], state: [f64; 6], t: f64, w: f64) -> Vec<f64> {
        let bindings: Vec<f64> = arena
            .symbols()
            .iter()
            .map(|s| match s.kind {
                SymbolKind::Coordinate(i) => state[i as usize],
                SymbolKind::Velocity(i) => state[3 + i as usize],
                SymbolKind::Time => t,
                SymbolKind::Parameter => w,
                _ => 0.0,
            })
            .collect();
        Evaluator::new(arena, roots).eval(&bindings).to_vec()
    }

    /// The bead on a rod spun at the rate ω, `Φ = x sin ωt − y cos ωt`, and a knife edge,
    /// `g = ẋ sin θ − ẏ cos θ`: `J`, the velocity residuals and `γ` against their closed forms
    /// (`γ = −Φ̈|q̈=0 = −2ω(ẋ cos ωt + ẏ sin ωt) + ω² (x sin ωt − y cos ωt)` and
    /// `γ = −θ̇ (ẋ cos θ + ẏ sin θ)`), to rounding (1e-14 relative).
    #[test]
    fn a_rheonomic_and_a_nonholonomic_constraint_against_their_closed_forms() {
        let (mut a, symbols, [x, y, th, xd, yd, t, w]) = planar();
        let wt = a.times(w, t);
        let (s, c) = (a.sin(wt), a.cos(wt));
        let xs = a.times(x, s);
        let yc = a.times(y, c);
        let phi = a.minus(xs, yc);
        let (st, ct) = (a.sin(th), a.cos(th));
        let xst = a.times(xd, st);
        let yct = a.times(yd, ct);
        let g = a.minus(xst, yct);
        let eqs = ConstraintEquations::derive(
            &mut a,
            &symbols,
            &[("rod".into(), phi)],
            &[("knife".into(), g)],
        );
        assert_eq!((eqs.len(), eqs.holonomic, eqs.is_empty()), (2, 1, false));
        assert_eq!(eqs.names, ["rod", "knife"]);
        let roots: Vec<ExprId> = eqs
            .jacobian
            .iter()
            .chain(&eqs.velocity)
            .chain(&eqs.gamma)
            .chain(&eqs.phi)
            .copied()
            .collect();
        let state = [0.7, -0.4, 1.1, 0.3, -1.3, 0.9];
        let (tv, wv) = (0.8, 2.5);
        let v = values(&a, &roots, state, tv, wv);
        let [xv, yv, thv, xdv, ydv, thdv] = state;
        let (sv, cv) = ((wv * tv).sin(), (wv * tv).cos());
        let expected = [
            sv,
            -cv,
            0.0,
            thv.sin(),
            -thv.cos(),
            0.0,
            xdv * sv + xv * wv * cv - ydv * cv + yv * wv * sv,
            xdv * thv.sin() - ydv * thv.cos(),
            -2.0 * wv * (xdv * cv + ydv * sv) + wv * wv * (xv * sv - yv * cv),
            -thdv * (xdv * thv.cos() + ydv * thv.sin()),
            xv * sv - yv * cv,
        ];
        for (k, (got, want)) in v.iter().zip(expected).enumerate() {
            assert!(
                (got - want).abs() <= 1e-14 * want.abs().max(1.0),
                "{k}: {got} vs {want}"
            );
        }
        assert!(ConstraintEquations::default().is_empty());
    }

    #[test]
    fn rates_enter_a_velocity_constraint_linearly_or_not() {
        let (mut a, symbols, [x, _, th, xd, yd, _, _]) = planar();
        let st = a.sin(th);
        let linear = a.times(xd, st);
        let linear = a.plus(linear, x);
        assert!(linear_in_rates(&mut a, linear, &symbols));
        let product = a.times(xd, yd);
        assert!(!linear_in_rates(&mut a, product, &symbols));
        let two = a.int(2);
        let square = a.pow(xd, two);
        assert!(!linear_in_rates(&mut a, square, &symbols));
    }

    /// Rows of unequal norms: the third is 2 r₀ + r₁, found by Gram–Schmidt with normalised
    /// basis vectors; the fourth, zero, constrains nothing (combines none); the fifth is
    /// independent.
    #[test]
    fn a_combination_of_rows_of_unequal_norms_is_found_with_its_rows() {
        let s = vec![
            3.0, 4.0, 0.0, //
            0.0, 0.0, 2.0, //
            6.0, 8.0, 2.0, //
            0.0, 0.0, 0.0, //
            0.0, 1.0, 0.0,
        ];
        assert_eq!(
            redundant_rows(&[s.clone(), s], 5, 3),
            vec![(2, vec![0, 1]), (3, vec![])]
        );
    }

    /// The constraints named in a combination are those whose coefficient is above 1e-8 of
    /// the largest: in `1e3 r₀ + 1e-6 r₁` (1e-9 relative) only `r₀`.
    #[test]
    fn a_negligible_coefficient_does_not_name_its_row() {
        let s = vec![1.0, 0.0, 0.0, 1.0, 1e3, 1e-6];
        assert_eq!(redundant_rows(&[s], 3, 2), vec![(2, vec![0])]);
        let s = vec![1.0, 0.0, 0.0, 1.0, 1e3, 1e-3];
        assert_eq!(redundant_rows(&[s], 3, 2), vec![(2, vec![0, 1])]);
    }

    /// Dependence is relative to the row's norm: at 1e5 a difference of 1e-6 (1e-11
    /// relative) is rounding, and at 1 a difference of 1e-6 is a different row.
    #[test]
    fn dependence_is_relative_to_the_norm_of_the_row() {
        let big = vec![1e5, 0.0, 2e5, 1e-6];
        assert_eq!(redundant_rows(&[big], 2, 2), vec![(1, vec![0])]);
        let small = vec![1.0, 0.0, 2.0, 1e-6];
        assert!(redundant_rows(&[small], 2, 2).is_empty());
    }

    /// The constraints a dependent row combines are named from the first sample.
    #[test]
    fn the_combination_is_named_from_the_first_sample() {
        let first = vec![1.0, 0.0, 0.0, 1.0, 1.0, 0.0];
        let second = vec![1.0, 0.0, 0.0, 1.0, 0.0, 1.0];
        assert_eq!(redundant_rows(&[first, second], 3, 2), vec![(2, vec![0])]);
    }

    /// The circle `x² + y² = 1` is reached by several Gauss–Newton steps from (0.3, −0.7);
    /// there `2 (x² + y²) − 2` vanishes (redundant) and `x² + y² − 4` is −3 (contradicts).
    /// Scaled by 1e7 (a mechanism of 1e7 m, or a constraint in other units) the answers stay.
    #[test]
    fn a_curved_dependent_constraint_is_tested_on_the_others_at_any_scale() {
        for scale in [1.0, 1e7] {
            let mut eval = |q: &[f64]| {
                let (x, y) = (q[0] / scale, q[1] / scale);
                let r2 = x * x + y * y;
                (
                    vec![
                        scale * (r2 - 1.0),
                        scale * (2.0 * r2 - 2.0),
                        scale * (r2 - 4.0),
                    ],
                    vec![2.0 * x, 2.0 * y, 4.0 * x, 4.0 * y, 2.0 * x, 2.0 * y],
                )
            };
            let q0 = [0.3 * scale, -0.7 * scale];
            let r = residual_where_others_hold(&mut eval, &q0, &[0], 1).unwrap();
            assert!(!r.contradicts(), "{scale}: {r:?}");
            let r = residual_where_others_hold(&mut eval, &q0, &[0], 2).unwrap();
            assert!(r.contradicts(), "{scale}: {r:?}");
            assert!((r.residual / scale + 3.0).abs() < 1e-9, "{scale}: {r:?}");
        }
    }

    /// Two lines `x + y = 1` and `x − y = 0` meet at (½, ½), which a step with the 2 × 2 Gram
    /// matrix reaches; a third line through that point is redundant there, one that misses it
    /// by 1e-3 contradicts (and is −1e-3 there).
    #[test]
    fn two_independent_constraints_are_solved_together() {
        let mut eval = |q: &[f64]| {
            (
                vec![
                    q[0] + q[1] - 1.0,
                    q[0] - q[1],
                    3.0 * q[0] - q[1] - 1.0,
                    3.0 * q[0] - q[1] - 1.001,
                ],
                vec![1.0, 1.0, 1.0, -1.0, 3.0, -1.0, 3.0, -1.0],
            )
        };
        let r = residual_where_others_hold(&mut eval, &[1.7, -0.2], &[0, 1], 2).unwrap();
        assert!(r.residual.abs() < 1e-13 && !r.contradicts(), "{r:?}");
        let r = residual_where_others_hold(&mut eval, &[1.7, -0.2], &[0, 1], 3).unwrap();
        assert!(
            (r.residual + 1e-3).abs() < 1e-12 && r.contradicts(),
            "{r:?}"
        );
    }

    /// The scale is the size of the constraint's terms, Σ |Jⱼ qⱼ|: written in other units,
    /// `1e-6 (x − 1e6)` has terms of size 1, and `1e-6 (x − 1e6 − 0.5)`, 0.5 m away, contradicts
    /// it (a scale of |J| + |q| = 1e6 would take its residual, 5e-7, for rounding).
    #[test]
    fn the_scale_is_the_size_of_the_terms() {
        let mut eval = |q: &[f64]| {
            (
                vec![1e-6 * (q[0] - 1e6), 1e-6 * (q[0] - 1e6 - 0.5)],
                vec![1e-6, 1e-6],
            )
        };
        let r = residual_where_others_hold(&mut eval, &[3.0], &[0], 1).unwrap();
        assert!((r.scale - 1.0).abs() < 1e-9 && r.contradicts(), "{r:?}");
    }

    /// Newton that meets a NaN, or does not converge, gives no answer rather than a wrong one.
    #[test]
    fn no_residual_without_a_converged_point() {
        let mut nan = |_: &[f64]| (vec![f64::NAN, 0.0], vec![1.0, 0.0]);
        assert!(residual_where_others_hold(&mut nan, &[0.0], &[0], 1).is_none());
        // x² + 1 = 0 has no real root: Gauss–Newton wanders and stops after 50 steps.
        let mut none = |q: &[f64]| (vec![q[0] * q[0] + 1.0, 0.0], vec![2.0 * q[0], 0.0]);
        assert!(residual_where_others_hold(&mut none, &[0.5], &[0], 1).is_none());
    }

    #[test]
    fn a_row_dependent_at_one_sample_only_is_not_redundant() {
        let a = vec![1.0, 0.0, 1.0, 0.0];
        let b = vec![1.0, 0.0, 0.0, 1.0];
        assert!(redundant_rows(&[a, b], 2, 2).is_empty());
    }
}
