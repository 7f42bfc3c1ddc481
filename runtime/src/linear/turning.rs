//! Steady turns: steady motions whose translational rates are constant in a frame that turns
//! with the motion (relative equilibria), such as a coin or a bicycle rolling round a circle.
//!
//! In a steady turn the heading `ψ` turns at a constant rate `Ω = ψ̇`, and the rates
//! `v = (ȧ, ḃ)` of two Cartesian coordinates of the ground plane (the contact point's `x`,
//! `y`) turn with it: they are constant in the frame turned by `ψ`, not in the ground, so
//! `v̇ = Ω S v` with `S = [0 −1; 1 0]` (the acceleration of uniform circular motion). The
//! search for a steady motion then asks `v̇ − Ω S v = 0` of those two rows instead of `v̇ = 0`
//! ([`TurningFrame::residuals`]).
//!
//! The linearisation is taken in the turning frame (Marsden & Ratiu, *Introduction to
//! Mechanics and Symmetry*, 2nd ed., 1999, §9.8 on relative equilibria; Basu-Mandal,
//! Chatterjee & Papadopoulos, *Proc. R. Soc. A* 463:1983–2003, 2007, §4, for a bicycle's
//! turns): the state `z` replaces `v` by `u = R(ψ − ψ*)ᵀ v`, the rates seen from the turning
//! frame, whose equations `u̇ = Rᵀ (v̇ − ψ̇ S v)` do not depend on `ψ` when the model is
//! symmetric under turning about the plane's normal. At the turn `z* = y*`, and
//! `A_z = ∂ż/∂z = B T` ([`TurningFrame::state_matrix`]), where `B` is `A = ∂f/∂y` with
//! `−Ω S` added to the `v` columns and `−S v*` to the `ψ̇` column of the `v` rows (the term
//! `R'ᵀ(v̇ − Ω S v)` vanishes at the turn), and `T = ∂y/∂z` is the identity with `S v*` in
//! the `v` rows of the `ψ` column. The constraints' tangent space maps as `N_z = T⁻¹ N`.
//! Without this change of frame the linearised equations would change along the turn, and
//! `ψ` would not be ignorable.

use nalgebra::DMatrix;
use serde::Serialize;

/// The frame of a steady turn: the rates of the coordinates `plane = [a, b]` (indices into
/// `q`) are constant in the frame turned by the coordinate `angle` about their plane's
/// normal, a positive `angle` turning `a` toward `b`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct TurningFrame {
    /// The turning angle's index (a heading).
    pub angle: usize,
    /// The two Cartesian coordinates' indices.
    pub plane: [usize; 2],
}

impl TurningFrame {
    /// The turn's rate `Ω = ψ̇` (rad/s) at the state `y` (length `2n`, `n` coordinates).
    pub fn rate(&self, y: &[f64], n: usize) -> f64 {
        y[n + self.angle]
    }

    /// `S v`, the plane rates `v` of `y` turned by a right angle: `(−ḃ, ȧ)`.
    fn turned_rates(&self, y: &[f64], n: usize) -> [f64; 2] {
        [-y[n + self.plane[1]], y[n + self.plane[0]]]
    }

    /// Replaces the plane's accelerations in `accelerations` (`q̈`, length `n`) by their
    /// excess over the turn's `Ω S v`: the residuals of a steady turn at the state `y`.
    pub fn residuals(&self, y: &[f64], accelerations: &mut [f64]) {
        let n = accelerations.len();
        let omega = self.rate(y, n);
        let sv = self.turned_rates(y, n);
        for (k, &c) in self.plane.iter().enumerate() {
            accelerations[c] -= omega * sv[k];
        }
    }

    /// The state `y` (length `2n`) with its plane rates turned by the angle `s` (rad) and its
    /// turning angle moved by `s`: the symmetry of a model that can turn steadily.
    pub fn turn_state(&self, y: &[f64], n: usize, s: f64) -> Vec<f64> {
        let mut out = y.to_vec();
        out[self.angle] += s;
        let [a, b] = self.plane;
        let (c, sn) = (s.cos(), s.sin());
        out[n + a] = c * y[n + a] - sn * y[n + b];
        out[n + b] = sn * y[n + a] + c * y[n + b];
        out
    }

    /// `accelerations` (`q̈`, length `n`) with the plane's turned by the angle `s` (rad).
    pub fn turn_accelerations(&self, accelerations: &[f64], s: f64) -> Vec<f64> {
        let mut out = accelerations.to_vec();
        let [a, b] = self.plane;
        let (c, sn) = (s.cos(), s.sin());
        out[a] = c * accelerations[a] - sn * accelerations[b];
        out[b] = sn * accelerations[a] + c * accelerations[b];
        out
    }

    /// `A_z = B T` and `T⁻¹` (both `2n × 2n`) from the state matrix `a = ∂f/∂y` at the
    /// steady turn `y` (length `2n`): the linearisation in the turning frame (see the module
    /// documentation).
    pub fn state_matrix(&self, a: &DMatrix<f64>, y: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
        let dim = a.nrows();
        let n = dim / 2;
        let omega = self.rate(y, n);
        let sv = self.turned_rates(y, n);
        let [ra, rb] = [n + self.plane[0], n + self.plane[1]];
        let mut b = a.clone();
        // −Ω S on the plane's rate columns: S = [0 −1; 1 0].
        b[(ra, rb)] += omega;
        b[(rb, ra)] -= omega;
        // −S v* on the turning rate's column.
        b[(ra, n + self.angle)] -= sv[0];
        b[(rb, n + self.angle)] -= sv[1];
        let mut t = DMatrix::identity(dim, dim);
        t[(ra, self.angle)] = sv[0];
        t[(rb, self.angle)] = sv[1];
        let mut t_inverse = DMatrix::identity(dim, dim);
        t_inverse[(ra, self.angle)] = -sv[0];
        t_inverse[(rb, self.angle)] = -sv[1];
        (b * t, t_inverse)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point mass on a circle of radius `r` at speed `V`, in the plane, with `ψ` its
    /// heading: `f` is the uniform circular motion's, so the turning frame's state matrix
    /// has every column of `ψ` and the plane rates zero where the turn is steady.
    #[test]
    fn the_turning_frame_removes_the_turn_from_circular_motion() {
        // y = (x, y, ψ, ẋ, ẏ, ψ̇); a model whose accelerations are ẍ = −Ω ẏ, ÿ = Ω ẋ with
        // Ω = ψ̇: linearised at ψ = 0, v = (V, 0), Ω = w.
        let (speed, w) = (2.0, 0.5);
        let y = [0.0, 0.0, 0.0, speed, 0.0, w];
        let mut a = DMatrix::zeros(6, 6);
        a[(0, 3)] = 1.0;
        a[(1, 4)] = 1.0;
        a[(2, 5)] = 1.0;
        // ∂ẍ/∂ẏ = −Ω, ∂ẍ/∂ψ̇ = −ẏ = 0; ∂ÿ/∂ẋ = Ω, ∂ÿ/∂ψ̇ = ẋ = V.
        a[(3, 4)] = -w;
        a[(4, 3)] = w;
        a[(4, 5)] = speed;
        let frame = TurningFrame {
            angle: 2,
            plane: [0, 1],
        };
        let mut acc = [-w * 0.0, w * speed, 0.0];
        frame.residuals(&y, &mut acc);
        assert_eq!(acc, [0.0, 0.0, 0.0]);
        let (a_z, t_inverse) = frame.state_matrix(&a, &y);
        // In the turning frame the rates u are constant whatever ψ̇ and u are: rows 3 and 4
        // vanish.
        for r in 3..5 {
            for c in 0..6 {
                assert!(a_z[(r, c)].abs() < 1e-15, "A_z[{r}, {c}] = {}", a_z[(r, c)]);
            }
        }
        // T⁻¹ T = I, T having S v* = (0, V) in the ψ column.
        let mut t = DMatrix::<f64>::identity(6, 6);
        t[(4, 2)] = speed;
        assert!(((&t_inverse * t) - DMatrix::<f64>::identity(6, 6)).amax() < 1e-15);
    }

    #[test]
    fn turning_a_state_turns_its_plane_rates_and_angle() {
        let frame = TurningFrame {
            angle: 0,
            plane: [1, 2],
        };
        let y = [0.1, 5.0, 6.0, 0.0, 1.0, 0.0];
        let turned = frame.turn_state(&y, 3, std::f64::consts::FRAC_PI_2);
        assert!((turned[0] - 0.1 - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert!(turned[4].abs() < 1e-15 && (turned[5] - 1.0).abs() < 1e-15);
        assert_eq!(&turned[1..3], &[5.0, 6.0]);
        let acc = frame.turn_accelerations(&[3.0, 1.0, 0.0], std::f64::consts::FRAC_PI_2);
        assert!(acc[1].abs() < 1e-15 && (acc[2] - 1.0).abs() < 1e-15 && acc[0] == 3.0);
    }
}
