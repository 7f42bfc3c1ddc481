//! Dense output: the solution inside the last accepted step, from data the step computed,
//! used for [`OutputTimes::At`](super::OutputTimes::At) (and, later, event location).

/// An interpolant of the solution over the last accepted step.
///
/// Valid from one accepted step until the next step attempt, which overwrites the stage data
/// it is built from.
pub(crate) trait DenseOutput {
    /// The interval `[t_prev, t]` of the last accepted step (`t_prev = t` before the first).
    fn interval(&self) -> (f64, f64);

    /// Writes the interpolated state at `t` (in [`Self::interval`]) into `out` (`dim`
    /// entries).
    fn interpolate(&self, t: f64, out: &mut [f64]);
}

/// One component of the cubic Hermite interpolant over a step, plus a quartic correction.
///
/// With `θ = (t − t₀)/h`, `Δ = y₁ − y₀`, `B = h f₀ − Δ`, `C = Δ − h f₁ − B`:
///
/// ```text
/// y(t₀ + θh) = y₀ + θ(Δ + (1 − θ)(B + θ(C + (1 − θ) D)))
///            = (1 − 3θ² + 2θ³) y₀ + (3θ² − 2θ³) y₁ + θ(1 − θ)² h f₀ − θ²(1 − θ) h f₁
///              + θ²(1 − θ)² D
/// ```
///
/// `D = 0` gives the cubic Hermite interpolant of the end values and derivatives (local
/// error `O(h⁴)`: a continuous extension of order 3); `D = h Σ dᵢ kᵢ` with Shampine's weights
/// gives the fourth-order dense output of Dormand–Prince 5(4) (Hairer, Nørsett, Wanner I,
/// §II.6, and `dopri5.f`'s `CONTD5`). `θ = 0` gives `y₀` and `θ = 1` gives `y₁` whatever `D`.
///
/// # Arguments
/// * `theta` - position in the step, in `[0, 1]`.
/// * `y0`, `y1` - the component at the start and end of the step.
/// * `hf0`, `hf1` - the step size times the derivative at the start and end.
/// * `correction` - `D`, or 0.
#[inline]
pub(crate) fn hermite(theta: f64, y0: f64, y1: f64, hf0: f64, hf1: f64, correction: f64) -> f64 {
    let delta = y1 - y0;
    let b = hf0 - delta;
    let c = delta - hf1 - b;
    y0 + theta * (delta + (1.0 - theta) * (b + theta * (c + (1.0 - theta) * correction)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::tableau::Tableau;
    use crate::integrate::tableau::tests::order_conditions;

    #[test]
    fn hermite_reproduces_cubics() {
        let y = |t: f64| t * t * t - 2.0 * t * t + t + 1.0;
        let dy = |t: f64| 3.0 * t * t - 4.0 * t + 1.0;
        let (t0, h) = (0.3, 0.8);
        for k in 0..=10 {
            let theta = f64::from(k) / 10.0;
            let value = hermite(theta, y(t0), y(t0 + h), h * dy(t0), h * dy(t0 + h), 0.0);
            assert!((value - y(t0 + theta * h)).abs() < 1e-14, "θ = {theta}");
        }
    }

    #[test]
    fn hermite_ends_are_exact() {
        assert_eq!(hermite(0.0, 1.5, -2.0, 3.0, 4.0, 5.0), 1.5);
        assert_eq!(hermite(1.0, 1.5, -2.0, 3.0, 4.0, 5.0), -2.0);
    }

    /// The weights `bᵢ(θ)` of the dense output `y₀ + h Σ bᵢ(θ) kᵢ` of an FSAL tableau with
    /// correction `d` (the expansion in the doc of [`hermite`]).
    fn dense_weights(tableau: &Tableau, d: &[f64], theta: f64) -> Vec<f64> {
        let s = tableau.num_stages();
        let cubic = 3.0 * theta * theta - 2.0 * theta.powi(3);
        let bump = theta * theta * (1.0 - theta) * (1.0 - theta);
        (0..s)
            .map(|i| {
                let mut w = cubic * tableau.b()[i] + bump * d[i];
                if i == 0 {
                    w += theta * (1.0 - theta) * (1.0 - theta);
                }
                if i == s - 1 {
                    w -= theta * theta * (1.0 - theta);
                }
                w
            })
            .collect()
    }

    /// Shampine's continuous extension has order 4 at every θ: `Σ bᵢ(θ) Φᵢ(τ) = θ^|τ|/γ(τ)`
    /// for the 8 trees with at most 4 vertices. This checks the `d` coefficients.
    #[test]
    fn dopri5_dense_output_has_order_4() {
        let tableau = Tableau::dopri5();
        let d = tableau.dense_correction().unwrap();
        let tree_orders = [1, 2, 3, 3, 4, 4, 4, 4];
        for k in 1..10 {
            let theta = f64::from(k) / 10.0;
            let weights = dense_weights(&tableau, d, theta);
            let conditions = order_conditions(&tableau, &weights, 4);
            for ((weight, inverse_gamma), order) in conditions.into_iter().zip(tree_orders) {
                let expected = theta.powi(order) * inverse_gamma;
                assert!(
                    (weight - expected).abs() < 1e-14,
                    "θ = {theta}: {weight} != {expected}"
                );
            }
        }
    }
}
