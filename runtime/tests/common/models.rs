//! Small hand-written models with closed-form answers, so that the analyses of the runtime
//! (`analysis/`, `analysis/vibration/`, the blocks of `linear/`) are tested in this crate,
//! on `FirstOrder::new(model)` held as `Box<dyn ModelInfo>`, without the bundled models.
//!
//! Each model is `M(q, t) q̈ = F(q, q̇, t)` written out by hand with its exact Jacobians; its
//! doc comment gives the closed forms the tests compare with and where they come from.
//! Parameters are fields named as in the description, so a test reads `chain.k2`.
//!
//! Included by the integration tests of `eomgen-runtime` (`mod common;`); each test file uses
//! some of it.
#![allow(dead_code)]

use std::borrow::Cow;

use eomgen_runtime::{
    FirstOrder, MechanicalSystem, ModelDescription, ModelInfo, Parameter, UnknownParameter,
};
use nalgebra::{Matrix1, Matrix2, SMatrix, SVector, Vector1, Vector2};

/// `&'static str` as the description's text.
const fn text(s: &'static str) -> Cow<'static, str> {
    Cow::Borrowed(s)
}

/// A parameter of a description, with its default.
const fn parameter(name: &'static str, default: f64) -> Parameter {
    Parameter {
        name: text(name),
        default,
    }
}

/// The error for a parameter `name` that `description` does not list.
fn unknown(description: &ModelDescription, name: &str) -> UnknownParameter {
    UnknownParameter {
        model: description.name.to_string(),
        name: name.to_string(),
        known: description.parameter_names().join(", "),
    }
}

/// `parameter_values` and `set_parameter` over the fields that hold the description's
/// parameters, in its order.
macro_rules! parameters {
    ($($name:literal => $field:ident),* $(,)?) => {
        fn parameter_values(&self) -> Vec<f64> {
            vec![$(self.$field),*]
        }

        fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter> {
            match name {
                $($name => self.$field = value,)*
                _ => return Err(unknown(self.description(), name)),
            }
            Ok(())
        }
    };
}

/// `mass_matrix_and_forcing` from `mass_matrix` and `forcing`, and the zero `∂(M a)/∂q` of a
/// mass matrix that does not depend on `q` (every model here).
macro_rules! constant_mass_matrix {
    ($n:literal) => {
        fn mass_matrix_and_forcing(
            &self,
            q: &SVector<f64, $n>,
            qdot: &SVector<f64, $n>,
            t: f64,
        ) -> (SMatrix<f64, $n, $n>, SVector<f64, $n>) {
            (self.mass_matrix(q, t), self.forcing(q, qdot, t))
        }

        fn mass_matrix_product_jacobian(
            &self,
            _q: &SVector<f64, $n>,
            _t: f64,
            _a: &SVector<f64, $n>,
        ) -> SMatrix<f64, $n, $n> {
            SMatrix::zeros()
        }
    };
}

/// The model as the analyses take it.
pub fn boxed<S: MechanicalSystem<N> + 'static, const N: usize>(system: S) -> Box<dyn ModelInfo> {
    Box::new(FirstOrder::new(system))
}

// ---------------------------------------------------------------------------------------------
// Two masses between springs and dampers
// ---------------------------------------------------------------------------------------------

/// Two masses on a line: a spring `k1` and a damper `c1` from a wall to mass 1, a spring `k2`
/// and a damper `c2` between the masses, and a load `F0 + A cos(w t)` (N) on mass 2:
///
/// ```text
/// M = [m1 0; 0 m2],  K = [k1 + k2  −k2; −k2  k2],  C = [c1 + c2  −c2; −c2  c2],
/// M q̈ + C q̇ + K q = [0; F0 + A cos(w t)],   q = (x1, x2) (m).
/// ```
///
/// Closed forms (D. J. Inman, *Engineering Vibration*, 4th ed., Pearson, 2014, ch. 4: two
/// degrees of freedom, modal analysis, proportional damping):
/// - `det(K − ω²M) = 0`: `ω² = (a + b ∓ √((a − b)² + 4 k2²/(m1 m2)))/2` with
///   `a = (k1 + k2)/m1`, `b = k2/m2`; mode `k`'s shape is `(k2, k1 + k2 − m1 ω_k²)` up to scale
///   ([`Self::modes`]).
/// - With `c1/k1 = c2/k2 = β` the damping is proportional, `C = βK`, and `ζ_k = β ω_k/2`.
/// - `H(ω) = (K − ω²M + iωC)⁻¹ [0; 1]` from `A` (Cramer's rule, [`Self::receptance`]).
/// - With `k1 = c1 = c2 = 0` it is HW9's free two-mass spring of the stability study: one
///   zero-frequency mode and `ω² = k2 (m1 + m2)/(m1 m2)`.
///
/// The only equilibrium named is `rest` (`q = 0`; `F0` shifts it).
#[derive(Debug, Clone, PartialEq)]
pub struct TwoMassChain {
    pub m1: f64,
    pub m2: f64,
    pub k1: f64,
    pub k2: f64,
    pub c1: f64,
    pub c2: f64,
    pub f0: f64,
    pub a: f64,
    pub w: f64,
    /// The initial state `(q, q̇)` (default: at rest at `q = 0`).
    pub initial: ([f64; 2], [f64; 2]),
}

impl Default for TwoMassChain {
    /// Unequal masses and springs (so that neither shape is symmetric), undamped, unloaded.
    fn default() -> Self {
        Self {
            m1: 1.0,
            m2: 2.0,
            k1: 3.0,
            k2: 5.0,
            c1: 0.0,
            c2: 0.0,
            f0: 0.0,
            a: 0.0,
            w: 1.0,
            initial: ([0.0; 2], [0.0; 2]),
        }
    }
}

impl TwoMassChain {
    /// `M`.
    pub fn m(&self) -> Matrix2<f64> {
        Matrix2::new(self.m1, 0.0, 0.0, self.m2)
    }

    /// `K`.
    pub fn k(&self) -> Matrix2<f64> {
        Matrix2::new(self.k1 + self.k2, -self.k2, -self.k2, self.k2)
    }

    /// `C`.
    pub fn c(&self) -> Matrix2<f64> {
        Matrix2::new(self.c1 + self.c2, -self.c2, -self.c2, self.c2)
    }

    /// The state matrix `A = [0 I; −M⁻¹K −M⁻¹C]` (4 × 4), assembled from the closed-form
    /// matrices (not from a linearisation).
    pub fn state_matrix(&self) -> SMatrix<f64, 4, 4> {
        let m_inv = self.m().try_inverse().expect("positive masses");
        let mut a = SMatrix::<f64, 4, 4>::zeros();
        a.fixed_view_mut::<2, 2>(0, 2)
            .copy_from(&Matrix2::identity());
        a.fixed_view_mut::<2, 2>(2, 0)
            .copy_from(&(-m_inv * self.k()));
        a.fixed_view_mut::<2, 2>(2, 2)
            .copy_from(&(-m_inv * self.c()));
        a
    }

    /// The closed-form `ω²` (ascending) and mass-normalised shapes (columns, largest entry
    /// positive) of `K ψ = ω² M ψ` (the model's doc comment).
    pub fn modes(&self) -> ([f64; 2], Matrix2<f64>) {
        let (a, b) = ((self.k1 + self.k2) / self.m1, self.k2 / self.m2);
        let root = ((a - b).powi(2) + 4.0 * self.k2 * self.k2 / (self.m1 * self.m2)).sqrt();
        let w2 = [(a + b - root) / 2.0, (a + b + root) / 2.0];
        let mut shapes = Matrix2::zeros();
        for (k, w2) in w2.iter().enumerate() {
            let u = Vector2::new(self.k2, self.k1 + self.k2 - self.m1 * w2);
            let u = u / (u.dot(&(self.m() * u))).sqrt();
            let sign = if u[u.iamax()] < 0.0 { -1.0 } else { 1.0 };
            shapes.set_column(k, &(u * sign));
        }
        (w2, shapes)
    }

    /// `H(ω) = (K − ω²M + iωC)⁻¹ [0; 1]`, the response of `(x1, x2)` to a unit force on mass
    /// 2 at `ω` (rad/s), by Cramer's rule: `H = (k2 + iωc2, k1 + k2 − ω²m1 + iω(c1 + c2))/D`,
    /// `D` the determinant.
    pub fn receptance(&self, omega: f64) -> [nalgebra::Complex<f64>; 2] {
        use nalgebra::Complex;
        let d11 = Complex::new(
            self.k1 + self.k2 - omega * omega * self.m1,
            omega * (self.c1 + self.c2),
        );
        let d12 = Complex::new(-self.k2, -omega * self.c2);
        let d22 = Complex::new(self.k2 - omega * omega * self.m2, omega * self.c2);
        let det = d11 * d22 - d12 * d12;
        [-d12 / det, d11 / det]
    }

    /// The free response `[q(t); q̇(t)]` of the undamped chain from `(q0, 0)`, by superposing
    /// the closed-form modes (Inman ch. 4, modal analysis): `q(t) = Σ_k ψ_k (ψ_kᵀ M q0) cos(ω_k t)`.
    pub fn undamped_response(&self, q0: [f64; 2], t: f64) -> SVector<f64, 4> {
        let (w2, shapes) = self.modes();
        let q0 = Vector2::from(q0);
        let mut y = SVector::<f64, 4>::zeros();
        for (k, w2) in w2.iter().enumerate() {
            let psi = shapes.column(k);
            let (w, eta) = (w2.sqrt(), psi.dot(&(self.m() * q0)));
            let (s, c) = (w * t).sin_cos();
            y.fixed_rows_mut::<2>(0).axpy(eta * c, &psi, 1.0);
            y.fixed_rows_mut::<2>(2).axpy(-eta * w * s, &psi, 1.0);
        }
        y
    }
}

impl MechanicalSystem<2> for TwoMassChain {
    fn description(&self) -> &ModelDescription {
        static DESCRIPTION: ModelDescription = ModelDescription {
            name: text("two_mass_chain"),
            summary: text("two masses between springs and dampers, loaded on mass 2"),
            coordinates: Cow::Borrowed(&[text("x1"), text("x2")]),
            parameters: Cow::Borrowed(&[
                parameter("m1", 1.0),
                parameter("m2", 2.0),
                parameter("k1", 3.0),
                parameter("k2", 5.0),
                parameter("c1", 0.0),
                parameter("c2", 0.0),
                parameter("F0", 0.0),
                parameter("A", 0.0),
                parameter("w", 1.0),
            ]),
            points: Cow::Borrowed(&[text("p1"), text("p2")]),
            equilibria: Cow::Borrowed(&[text("rest")]),
            ..ModelDescription::EMPTY
        };
        &DESCRIPTION
    }

    parameters!(
        "m1" => m1, "m2" => m2, "k1" => k1, "k2" => k2, "c1" => c1, "c2" => c2,
        "F0" => f0, "A" => a, "w" => w,
    );

    constant_mass_matrix!(2);

    fn initial_state(&self) -> (SVector<f64, 2>, SVector<f64, 2>) {
        (Vector2::from(self.initial.0), Vector2::from(self.initial.1))
    }

    fn mass_matrix(&self, _q: &SVector<f64, 2>, _t: f64) -> SMatrix<f64, 2, 2> {
        self.m()
    }

    fn forcing(&self, q: &SVector<f64, 2>, qdot: &SVector<f64, 2>, t: f64) -> SVector<f64, 2> {
        -self.k() * q - self.c() * qdot + Vector2::new(0.0, self.f0 + self.a * (self.w * t).cos())
    }

    fn forcing_jacobian_q(
        &self,
        _q: &SVector<f64, 2>,
        _qdot: &SVector<f64, 2>,
        _t: f64,
    ) -> SMatrix<f64, 2, 2> {
        -self.k()
    }

    fn forcing_jacobian_qdot(
        &self,
        _q: &SVector<f64, 2>,
        _qdot: &SVector<f64, 2>,
        _t: f64,
    ) -> SMatrix<f64, 2, 2> {
        -self.c()
    }

    fn kinetic_energy(&self, _q: &SVector<f64, 2>, qdot: &SVector<f64, 2>, _t: f64) -> f64 {
        0.5 * qdot.dot(&(self.m() * qdot))
    }

    /// The springs' energy and the constant load's potential `−F0 x2` (the harmonic part
    /// depends on `t` and has none).
    fn potential_energy(&self, q: &SVector<f64, 2>, _t: f64) -> f64 {
        0.5 * q.dot(&(self.k() * q)) - self.f0 * q[1]
    }

    fn point_positions(&self, q: &SVector<f64, 2>, _t: f64, out: &mut [[f64; 3]]) {
        out[0] = [q[0], 0.0, 0.0];
        out[1] = [1.0 + q[1], 0.0, 0.0];
    }

    fn equilibrium_guesses(&self, out: &mut [f64]) {
        out.fill(0.0);
    }
}

// ---------------------------------------------------------------------------------------------
// A forced single-degree-of-freedom oscillator
// ---------------------------------------------------------------------------------------------

/// `m ẍ + c ẋ + k x = A cos(w t)` (lecture 21, HW21).
///
/// Closed forms (Inman ch. 2, harmonic excitation of damped systems): `ω_n = √(k/m)`, `ζ = c/(2√(k m))`; the receptance from the
/// load amplitude `A` is `H(ω) = 1/(k − mω² + icω)` ([`Self::receptance`]), whose modulus
/// peaks at `ω_n √(1 − 2ζ²)` with `|H| = 1/(2ζ√(1 − ζ²) k)` (for `ζ < 1/√2`).
#[derive(Debug, Clone, PartialEq)]
pub struct ForcedOscillator {
    pub m: f64,
    pub c: f64,
    pub k: f64,
    pub a: f64,
    pub w: f64,
}

impl Default for ForcedOscillator {
    /// `ω_n = 2` rad/s, `ζ = 0.1`.
    fn default() -> Self {
        Self {
            m: 2.0,
            c: 0.8,
            k: 8.0,
            a: 1.0,
            w: 1.5,
        }
    }
}

impl ForcedOscillator {
    /// `ω_n = √(k/m)` (rad/s).
    pub fn natural_frequency(&self) -> f64 {
        (self.k / self.m).sqrt()
    }

    /// `ζ = c/(2√(k m))`.
    pub fn damping_ratio(&self) -> f64 {
        self.c / (2.0 * (self.k * self.m).sqrt())
    }

    /// `H(ω) = 1/(k − mω² + icω)` (m/N).
    pub fn receptance(&self, omega: f64) -> nalgebra::Complex<f64> {
        nalgebra::Complex::new(self.k - self.m * omega * omega, self.c * omega).inv()
    }
}

impl MechanicalSystem<1> for ForcedOscillator {
    fn description(&self) -> &ModelDescription {
        static DESCRIPTION: ModelDescription = ModelDescription {
            name: text("forced_oscillator"),
            summary: text("a damped mass on a spring under A cos(w t)"),
            coordinates: Cow::Borrowed(&[text("x")]),
            parameters: Cow::Borrowed(&[
                parameter("m", 2.0),
                parameter("c", 0.8),
                parameter("k", 8.0),
                parameter("A", 1.0),
                parameter("w", 1.5),
            ]),
            points: Cow::Borrowed(&[text("mass")]),
            ..ModelDescription::EMPTY
        };
        &DESCRIPTION
    }

    parameters!("m" => m, "c" => c, "k" => k, "A" => a, "w" => w);

    constant_mass_matrix!(1);

    fn initial_state(&self) -> (SVector<f64, 1>, SVector<f64, 1>) {
        (Vector1::new(0.0), Vector1::new(0.0))
    }

    fn mass_matrix(&self, _q: &SVector<f64, 1>, _t: f64) -> SMatrix<f64, 1, 1> {
        Matrix1::new(self.m)
    }

    fn forcing(&self, q: &SVector<f64, 1>, qdot: &SVector<f64, 1>, t: f64) -> SVector<f64, 1> {
        Vector1::new(-self.k * q[0] - self.c * qdot[0] + self.a * (self.w * t).cos())
    }

    fn forcing_jacobian_q(
        &self,
        _q: &SVector<f64, 1>,
        _qdot: &SVector<f64, 1>,
        _t: f64,
    ) -> SMatrix<f64, 1, 1> {
        Matrix1::new(-self.k)
    }

    fn forcing_jacobian_qdot(
        &self,
        _q: &SVector<f64, 1>,
        _qdot: &SVector<f64, 1>,
        _t: f64,
    ) -> SMatrix<f64, 1, 1> {
        Matrix1::new(-self.c)
    }

    fn kinetic_energy(&self, _q: &SVector<f64, 1>, qdot: &SVector<f64, 1>, _t: f64) -> f64 {
        0.5 * self.m * qdot[0] * qdot[0]
    }

    fn potential_energy(&self, q: &SVector<f64, 1>, _t: f64) -> f64 {
        0.5 * self.k * q[0] * q[0]
    }

    fn point_positions(&self, q: &SVector<f64, 1>, _t: f64, out: &mut [[f64; 3]]) {
        out[0] = [q[0], 0.0, 0.0];
    }
}

// ---------------------------------------------------------------------------------------------
// A pendulum whose pivot may be shaken vertically
// ---------------------------------------------------------------------------------------------

/// A point mass `m` on a massless rod `l` from a pivot at height `a cos(w t)`, with a hinge
/// damper `c`; `θ` from straight down (rad), bob at `(l sin θ, a cos(w t) − l cos θ)`:
///
/// ```text
/// m l² θ̈ = −m l (g − a w² cos(w t)) sin θ − c θ̇
/// ```
///
/// (Lagrange's equations with `T = ½ m |ṙ|²`, `V = m g y`; the pivot's acceleration acts as
/// extra gravity, as in `models/mathieu_pendulum.yaml`, lectures 19 and 21.)
///
/// Closed forms: with `a = 0`, the simple pendulum: equilibria `θ = 0` (`hanging`) and `π`
/// (`upright`), `ω = √(g/l)` hanging, an unstable mode growing at `σ = √(g/l)` upright,
/// `ζ = c/(2 m l² ω)` (Inman ch. 1). Shaken, its linearisation about `hanging` is
/// Mathieu's equation `θ'' + (δ − 2q cos 2τ) θ = 0` in `τ = w t/2`, `δ = 4g/(l w²)`,
/// `q = 2a/l` (M. Abramowitz, I. A. Stegun, *Handbook of Mathematical Functions*, 1964,
/// 20.1.1): unstable in the first tongue of the Ince–Strutt chart, between its characteristic
/// values `b₁(q) = 1 − q − q²/8 + …` and `a₁(q) = 1 + q − q²/8 − …` (A&S 20.2.25), where to
/// first order in `q` (averaging) the multiplier over one period `2π/w` is `e^{π μ}` with
/// `μ = ½ √(q² − (δ − 1)²)`; stable (marginal) between the tongues (`δ = 1/4`, `q = 0.1`).
/// Liouville's formula `det Φ(T) = exp ∫₀ᵀ tr(∂f/∂y) dt` gives `det Φ(T) = e^{−c T/(m l²)}`
/// (1 undamped) for any `a` (as in `FloquetAnalysis::determinant`).
#[derive(Debug, Clone, PartialEq)]
pub struct Pendulum {
    pub m: f64,
    pub l: f64,
    pub g: f64,
    pub c: f64,
    pub a: f64,
    pub w: f64,
    /// The initial state `(θ, θ̇)` (default: released at rest from 0.5 rad).
    pub initial: (f64, f64),
}

impl Default for Pendulum {
    /// `√(g/l) = 2` rad/s, undamped, not shaken.
    fn default() -> Self {
        Self {
            m: 1.5,
            l: 2.5,
            g: 10.0,
            c: 0.0,
            a: 0.0,
            w: 4.0,
            initial: (0.5, 0.0),
        }
    }
}

impl Pendulum {
    /// `√(g/l)` (rad/s).
    pub fn natural_frequency(&self) -> f64 {
        (self.g / self.l).sqrt()
    }

    /// The pivot's height and vertical acceleration at `t`.
    fn pivot(&self, t: f64) -> (f64, f64) {
        let c = (self.w * t).cos();
        (self.a * c, -self.a * self.w * self.w * c)
    }
}

impl MechanicalSystem<1> for Pendulum {
    fn description(&self) -> &ModelDescription {
        static DESCRIPTION: ModelDescription = ModelDescription {
            name: text("pendulum"),
            summary: text("a pendulum whose pivot moves as a cos(w t), with a hinge damper"),
            coordinates: Cow::Borrowed(&[text("theta")]),
            parameters: Cow::Borrowed(&[
                parameter("m", 1.5),
                parameter("l", 2.5),
                parameter("g", 10.0),
                parameter("c", 0.0),
                parameter("a", 0.0),
                parameter("w", 4.0),
            ]),
            points: Cow::Borrowed(&[text("pivot"), text("bob")]),
            equilibria: Cow::Borrowed(&[text("hanging"), text("upright")]),
            ..ModelDescription::EMPTY
        };
        &DESCRIPTION
    }

    parameters!("m" => m, "l" => l, "g" => g, "c" => c, "a" => a, "w" => w);

    constant_mass_matrix!(1);

    fn initial_state(&self) -> (SVector<f64, 1>, SVector<f64, 1>) {
        (Vector1::new(self.initial.0), Vector1::new(self.initial.1))
    }

    fn mass_matrix(&self, _q: &SVector<f64, 1>, _t: f64) -> SMatrix<f64, 1, 1> {
        Matrix1::new(self.m * self.l * self.l)
    }

    fn forcing(&self, q: &SVector<f64, 1>, qdot: &SVector<f64, 1>, t: f64) -> SVector<f64, 1> {
        let (_, acceleration) = self.pivot(t);
        Vector1::new(-self.m * self.l * (self.g + acceleration) * q[0].sin() - self.c * qdot[0])
    }

    fn forcing_jacobian_q(
        &self,
        q: &SVector<f64, 1>,
        _qdot: &SVector<f64, 1>,
        t: f64,
    ) -> SMatrix<f64, 1, 1> {
        let (_, acceleration) = self.pivot(t);
        Matrix1::new(-self.m * self.l * (self.g + acceleration) * q[0].cos())
    }

    fn forcing_jacobian_qdot(
        &self,
        _q: &SVector<f64, 1>,
        _qdot: &SVector<f64, 1>,
        _t: f64,
    ) -> SMatrix<f64, 1, 1> {
        Matrix1::new(-self.c)
    }

    /// `½ m |ṙ|²` of the bob, pivot motion included.
    fn kinetic_energy(&self, q: &SVector<f64, 1>, qdot: &SVector<f64, 1>, t: f64) -> f64 {
        let pivot_speed = -self.a * self.w * (self.w * t).sin();
        let (s, c) = q[0].sin_cos();
        let (vx, vy) = (self.l * c * qdot[0], pivot_speed + self.l * s * qdot[0]);
        0.5 * self.m * (vx * vx + vy * vy)
    }

    fn potential_energy(&self, q: &SVector<f64, 1>, t: f64) -> f64 {
        let (height, _) = self.pivot(t);
        self.m * self.g * (height - self.l * q[0].cos())
    }

    fn point_positions(&self, q: &SVector<f64, 1>, t: f64, out: &mut [[f64; 3]]) {
        let (height, _) = self.pivot(t);
        out[0] = [0.0, height, 0.0];
        out[1] = [self.l * q[0].sin(), height - self.l * q[0].cos(), 0.0];
    }

    fn equilibrium_guesses(&self, out: &mut [f64]) {
        out.copy_from_slice(&[0.0, std::f64::consts::PI]);
    }
}

// ---------------------------------------------------------------------------------------------
// The same pendulum in Cartesian coordinates, held by its rod
// ---------------------------------------------------------------------------------------------

/// The bob of [`Pendulum`] (pivot fixed, undamped) in Cartesian coordinates `(x, y)` (m), held
/// by the rod `Φ = √(x² + y²) − l = 0`: `m q̈ = (0, −m g) − Jᵀλ`, `J = (x, y)/r`, so `λ` is
/// the rod's tension (N). The index-1 form needs `γ = −q̇ᵀ(∇²Φ)q̇ = −(|q̇|² − (r̂·q̇)²)/r`.
///
/// Closed forms (lectures 8–11): released at rest from `θ0`, energy conservation gives
/// `v² = 2 g l (cos θ − cos θ0)` and the radial balance `λ − m g cos θ = m v²/l` the tension
/// at angle `θ`, `λ = m g (3 cos θ − 2 cos θ0)` (`cos θ = −y/l`), `m g` hanging at rest;
/// linearised on the constraint about `hanging`, `ω = √(g/l)` in the one minimal coordinate
/// `x`. Its minimal-coordinate twin is `Pendulum` (point `bob` the same).
#[derive(Debug, Clone, PartialEq)]
pub struct CartesianPendulum {
    pub m: f64,
    pub l: f64,
    pub g: f64,
    /// The angle from straight down of the release at rest (rad).
    pub theta0: f64,
}

impl Default for CartesianPendulum {
    /// As [`Pendulum::default`].
    fn default() -> Self {
        Self {
            m: 1.5,
            l: 2.5,
            g: 10.0,
            theta0: 0.5,
        }
    }
}

impl MechanicalSystem<2> for CartesianPendulum {
    fn description(&self) -> &ModelDescription {
        static DESCRIPTION: ModelDescription = ModelDescription {
            name: text("cartesian_pendulum"),
            summary: text("a pendulum's bob in x and y, held by its rod"),
            coordinates: Cow::Borrowed(&[text("x"), text("y")]),
            parameters: Cow::Borrowed(&[
                parameter("m", 1.5),
                parameter("l", 2.5),
                parameter("g", 10.0),
            ]),
            points: Cow::Borrowed(&[text("pivot"), text("bob")]),
            constraints: Cow::Borrowed(&[text("rod")]),
            holonomic_constraints: 1,
            equilibria: Cow::Borrowed(&[text("hanging")]),
            conservative: true,
            ..ModelDescription::EMPTY
        };
        &DESCRIPTION
    }

    parameters!("m" => m, "l" => l, "g" => g);

    constant_mass_matrix!(2);

    fn initial_state(&self) -> (SVector<f64, 2>, SVector<f64, 2>) {
        let (s, c) = self.theta0.sin_cos();
        (Vector2::new(self.l * s, -self.l * c), Vector2::zeros())
    }

    fn mass_matrix(&self, _q: &SVector<f64, 2>, _t: f64) -> SMatrix<f64, 2, 2> {
        Matrix2::identity() * self.m
    }

    fn forcing(&self, _q: &SVector<f64, 2>, _qdot: &SVector<f64, 2>, _t: f64) -> SVector<f64, 2> {
        Vector2::new(0.0, -self.m * self.g)
    }

    fn forcing_jacobian_q(
        &self,
        _q: &SVector<f64, 2>,
        _qdot: &SVector<f64, 2>,
        _t: f64,
    ) -> SMatrix<f64, 2, 2> {
        Matrix2::zeros()
    }

    fn forcing_jacobian_qdot(
        &self,
        _q: &SVector<f64, 2>,
        _qdot: &SVector<f64, 2>,
        _t: f64,
    ) -> SMatrix<f64, 2, 2> {
        Matrix2::zeros()
    }

    fn kinetic_energy(&self, _q: &SVector<f64, 2>, qdot: &SVector<f64, 2>, _t: f64) -> f64 {
        0.5 * self.m * qdot.norm_squared()
    }

    fn potential_energy(&self, q: &SVector<f64, 2>, _t: f64) -> f64 {
        self.m * self.g * q[1]
    }

    fn point_positions(&self, q: &SVector<f64, 2>, _t: f64, out: &mut [[f64; 3]]) {
        out[0] = [0.0; 3];
        out[1] = [q[0], q[1], 0.0];
    }

    fn constraint_residuals(&self, q: &SVector<f64, 2>, _t: f64, out: &mut [f64]) {
        out[0] = q.norm() - self.l;
    }

    fn constraint_jacobian(&self, q: &SVector<f64, 2>, _t: f64, out: &mut [f64]) {
        let r = q.norm();
        out.copy_from_slice(&[q[0] / r, q[1] / r]);
    }

    fn constraint_velocity_residuals(
        &self,
        q: &SVector<f64, 2>,
        qdot: &SVector<f64, 2>,
        _t: f64,
        out: &mut [f64],
    ) {
        out[0] = q.dot(qdot) / q.norm();
    }

    fn constraint_gamma(
        &self,
        q: &SVector<f64, 2>,
        qdot: &SVector<f64, 2>,
        _t: f64,
        out: &mut [f64],
    ) {
        let r = q.norm();
        let radial = q.dot(qdot) / r;
        out[0] = -(qdot.norm_squared() - radial * radial) / r;
    }

    fn equilibrium_guesses(&self, out: &mut [f64]) {
        out.copy_from_slice(&[0.0, -self.l]);
    }
}
