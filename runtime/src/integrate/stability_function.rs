//! Linear stability of the integrators, in theory and measured.
//!
//! Applied to the test equation `ẏ = λy`, one step of a Runge–Kutta method of size `h`
//! multiplies `y` by its *stability function* `R(z)`, `z = hλ`:
//!
//! ```text
//! R(z) = 1 + z bᵀ(I − zA)⁻¹𝟙 = 1 + Σₖ≥₁ (bᵀAᵏ⁻¹𝟙) zᵏ
//! ```
//!
//! a polynomial of degree at most `s` (the number of stages) for an explicit method, whose
//! strictly lower-triangular `A` is nilpotent ([`StabilityPolynomial`]). The undamped
//! oscillator `ẍ = −ω²x` has `λ = ±iω`, so a method is stable on it for the `hω` with
//! `|R(ihω)| ≤ 1` ([`StabilityPolynomial::imaginary_axis_limit`]); the decay `ẋ = −λx` needs
//! `|R(−hλ)| ≤ 1` ([`StabilityPolynomial::real_axis_limit`]). The implicit methods have
//! rational `R` ([`implicit_midpoint_stability`], [`radau_iia5_stability`]); the partitioned
//! methods are not Runge–Kutta methods and have a `2 × 2` step matrix on the oscillator
//! ([`partitioned_oscillator_spectral_radius`]).
//!
//! The measured side runs a method itself, with constant steps, on a [`TestEquation`]:
//! [`amplification`] (the per-step growth of `‖y‖`) and [`measured_limit`] (the largest
//! stable `h`, by bisection on a [`GrowthTest`]).
//!
//! # References
//! E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer, 1996,
//! §IV.2 (stability functions, Prop. 2.11 `R(z) = 1 + z bᵀ(I − zA)⁻¹𝟙`), §IV.3 (A-stability),
//! §IV.5 (Radau IIA), doi:10.1007/978-3-642-05221-7; E. Hairer, C. Lubich, G. Wanner,
//! *Geometric Numerical Integration*, 2nd ed., Springer, 2006, §I.5 and §IX.8 (linear
//! stability of the Störmer–Verlet method), doi:10.1007/3-540-30666-8. Syllabus lecture 4
//! (integration methods).

use nalgebra::Complex;

use super::error::{IntegrationError, IntegrationFailure};
use super::options::{IntegratorOptions, OutputTimes};
use super::tableau::{StageSums, Tableau};
use super::{
    BogackiShampine32, DormandPrince54, ExplicitEuler, ExplicitMidpoint, Integrator, RungeKutta4,
    Verner65, Verner76, Verner87, Verner98,
};
use crate::ode::OdeFn;

/// Relative agreement with `1/k!` below which a coefficient `rₖ` counts as matching the
/// exponential (an order condition); real mismatches of these methods are of order 1.
const ORDER_MATCH: f64 = 1e-10;
/// Grid points of the scan for the first crossing of `|R| = 1`.
const SCAN_POINTS: usize = 100_000;

/// The stability function `R(z) = Σₖ rₖ zᵏ` of an explicit Runge–Kutta method.
///
/// # Shapes
/// `coefficients()` has `s + 1` entries `r₀ … rₛ` (`r₀ = 1`), `s` the number of stages;
/// trailing coefficients may be zero (Bogacki–Shampine's fourth stage has weight 0).
///
/// # Examples
/// ```
/// use eomgen_runtime::Tableau;
/// use eomgen_runtime::integrate::stability_function::StabilityPolynomial;
///
/// // RK4: R(z) = 1 + z + z²/2 + z³/6 + z⁴/24, stable on the imaginary axis up to 2√2.
/// let rk4 = StabilityPolynomial::of_tableau(&Tableau::rk4());
/// assert_eq!(rk4.order(), 4);
/// assert!((rk4.imaginary_axis_limit() - 8f64.sqrt()).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityPolynomial {
    coefficients: Vec<f64>,
}

impl StabilityPolynomial {
    /// The polynomial with coefficients `r₀ … r_d`.
    pub fn from_coefficients(coefficients: Vec<f64>) -> Self {
        Self { coefficients }
    }

    /// `R(z)` of an explicit tableau: `rₖ = bᵀAᵏ⁻¹𝟙` (Hairer–Wanner II, Prop. IV.2.11,
    /// expanded as a Neumann series, which terminates because `A` is strictly lower
    /// triangular).
    ///
    /// For a tableau whose stepper sums with differences (Verner's pairs), the products are
    /// taken in that form too, `(Av)ᵢ = cᵢ v₀ + Σⱼ≥₁ aᵢⱼ (vⱼ − v₀)` and
    /// `bᵀv = v₀ + Σⱼ≥₁ bⱼ (vⱼ − v₀)`, so that `A𝟙 = c` and `bᵀ𝟙 = 1` hold exactly (with the
    /// rounded coefficients summed plainly, `bᵀA𝟙` of Verner 6(5) is off by 6.5e-12).
    pub fn of_tableau(tableau: &Tableau) -> Self {
        let s = tableau.num_stages();
        let b = tableau.b();
        let c = tableau.c();
        let differences = tableau.sums() == StageSums::Differences;
        // `w · v` in the stepper's form; `total` is `Σ wⱼ` (`cᵢ` for a row of `A`).
        let product = |w: &[f64], total: f64, v: &[f64]| -> f64 {
            if differences {
                if w.is_empty() {
                    return 0.0;
                }
                total * v[0]
                    + w.iter()
                        .zip(v)
                        .skip(1)
                        .map(|(w, vj)| w * (vj - v[0]))
                        .sum::<f64>()
            } else {
                w.iter().zip(v).map(|(w, vj)| w * vj).sum()
            }
        };
        let mut power = vec![1.0; s]; // Aᵏ⁻¹𝟙
        let mut coefficients = vec![1.0];
        for _ in 0..s {
            coefficients.push(product(b, 1.0, &power));
            power = (0..s)
                .map(|i| product(tableau.a(i), c[i], &power))
                .collect();
        }
        Self { coefficients }
    }

    /// `R(z)` of an explicit method read off one step of its implementation, for methods whose
    /// tableau is not public (DOP853).
    ///
    /// On `ẏ = Jy` with `J` the `(s + 1) × (s + 1)` shift (`(Jy)ᵢ = yᵢ₊₁`, nilpotent), one step
    /// of size 1 from the last unit vector `e_s` gives `R(J) e_s = Σₖ rₖ e_{s−k}`: the
    /// coefficients appear in reverse order in the new state, exactly, since `Jˢ⁺¹ = 0`.
    /// The method is run with [`IntegratorOptions::fixed_step`].
    ///
    /// # Errors
    /// The [`IntegrationFailure`] of that step (none for an explicit method).
    pub fn of_method(
        method: &mut dyn Integrator,
        num_stages: usize,
    ) -> Result<Self, IntegrationFailure> {
        let dim = num_stages + 1;
        let mut shift = OdeFn::new(dim, |_t: f64, y: &[f64], dy: &mut [f64]| {
            for (i, d) in dy.iter_mut().enumerate() {
                *d = y.get(i + 1).copied().unwrap_or(0.0);
            }
        });
        let mut y0 = vec![0.0; dim];
        y0[num_stages] = 1.0;
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(1.0);
        let solution = method.integrate(
            &mut shift,
            0.0,
            &y0,
            1.0,
            &OutputTimes::At(vec![1.0]),
            &options,
        )?;
        let coefficients = solution.state(0).iter().rev().copied().collect();
        Ok(Self { coefficients })
    }

    /// The coefficients `r₀ … r_d`.
    pub fn coefficients(&self) -> &[f64] {
        &self.coefficients
    }

    /// `R(z)` at a complex `z` (Horner).
    pub fn eval(&self, z: Complex<f64>) -> Complex<f64> {
        self.coefficients
            .iter()
            .rev()
            .fold(Complex::new(0.0, 0.0), |acc, &r| acc * z + r)
    }

    /// `R(x)` at a real `x` (Horner).
    pub fn eval_real(&self, x: f64) -> f64 {
        self.coefficients
            .iter()
            .rev()
            .fold(0.0, |acc, &r| acc * x + r)
    }

    /// The order `p` of `R` as an approximation of `eᶻ`: the largest `p` with
    /// `rₖ = 1/k!` for every `k ≤ p` (to 1e-10 relative). For a Runge–Kutta method this is at
    /// least the method's order.
    pub fn order(&self) -> usize {
        let mut factorial = 1.0;
        let mut p = 0;
        for (k, &r) in self.coefficients.iter().enumerate().skip(1) {
            factorial *= k as f64;
            if (r * factorial - 1.0).abs() > ORDER_MATCH {
                break;
            }
            p = k;
        }
        p
    }

    /// Degree `d` of `R` (highest non-zero coefficient).
    pub fn degree(&self) -> usize {
        self.coefficients
            .iter()
            .rposition(|&r| r != 0.0)
            .unwrap_or(0)
    }

    /// The coefficients `e₀ … e_2d` of `E(y) = |R(iy)|² − 1`, an even polynomial in `y`.
    ///
    /// The order conditions make `E(y) = O(y^(p+1))`: the coefficients up to `y^p` cancel
    /// exactly in theory and are set to zero here rather than left as rounding noise, whose
    /// sign would decide the stability near `y = 0`.
    pub fn imaginary_axis_excess(&self) -> Vec<f64> {
        let d = self.degree();
        let r = &self.coefficients[..=d];
        // R(iy) = Σ rₖ iᵏ yᵏ: real part from even k (sign (−1)^(k/2)), imaginary from odd k.
        let signed = |k: usize| {
            if (k / 2).is_multiple_of(2) {
                r[k]
            } else {
                -r[k]
            }
        };
        let mut e = vec![0.0; 2 * d + 1];
        for j in 0..=d {
            for k in 0..=d {
                if j % 2 == k % 2 {
                    e[j + k] += signed(j) * signed(k);
                }
            }
        }
        // r₀² − 1: exactly 0 for r₀ = 1, so only the terms in y¹ … yᵖ need clearing.
        e[0] -= 1.0;
        let p = self.order();
        for coefficient in e.iter_mut().take(p + 1).skip(1) {
            *coefficient = 0.0;
        }
        e
    }

    /// The stability interval on the imaginary axis: the largest `y` with `|R(iy)| ≤ 1` on all
    /// of `[0, y]`; `0` when `|R(iy)| > 1` for every small `y > 0` (explicit Euler, explicit
    /// midpoint); `∞` only for `R ≡ 1`.
    ///
    /// The first non-zero coefficient of [`imaginary_axis_excess`](Self::imaginary_axis_excess)
    /// decides the sign near 0. Otherwise `E(y)` is scanned on 10⁵ points of `[0, d + 1]`
    /// (an explicit method whose `R` has degree `d` has an imaginary interval of at most
    /// `d − 1`: I. P. E. Kinnmark, W. G. Gray, "One step integration methods with maximum
    /// stability regions", Math. Comput. Simul. 26, 87–92, 1984) for its first positive value,
    /// and the crossing is refined by bisection to rounding. A tangency `E = 0⁺` narrower than
    /// the grid spacing would be missed.
    pub fn imaginary_axis_limit(&self) -> f64 {
        self.imaginary_axis_growth_limit(0.0)
    }

    /// The first `y > 0` with `|R(iy)| > 1 + growth` (`growth ≥ 0`): the limit a measurement
    /// that detects a per-step growth above `growth` finds ([`GrowthTest`]); for `growth = 0`,
    /// [`imaginary_axis_limit`](Self::imaginary_axis_limit). Scanned on `[0, 2(d + 1)]` for
    /// `growth > 0`; that bound is returned if there is no crossing below it.
    pub fn imaginary_axis_growth_limit(&self, growth: f64) -> f64 {
        let e = self.imaginary_axis_excess();
        if growth <= 0.0 {
            match e.iter().find(|&&c| c != 0.0) {
                None => return f64::INFINITY,
                Some(&c) if c > 0.0 => return 0.0,
                Some(_) => {}
            }
        }
        let level = growth.max(0.0) * (2.0 + growth.max(0.0));
        let excess = |y: f64| e.iter().rev().fold(0.0, |acc, &c| acc * y + c) - level;
        let bound = self.degree() as f64 + 1.0;
        first_crossing(excess, if growth > 0.0 { 2.0 * bound } else { bound })
    }

    /// The stability interval on the negative real axis: the largest `x` with `|R(−x)| ≤ 1` on
    /// all of `[0, x]` (the stable `hλ` for `ẋ = −λx`).
    ///
    /// `R(−x)² − 1` is scanned on 10⁵ points of `[0, 2d² + 1]` (an explicit method of degree
    /// `d` has a real interval of at most `2d²`, reached by shifted Chebyshev polynomials:
    /// Hairer–Wanner II, §IV.2, stabilized explicit methods) for its first positive value;
    /// the crossing is refined by bisection.
    pub fn real_axis_limit(&self) -> f64 {
        self.real_axis_growth_limit(0.0)
    }

    /// The first `x > 0` with `|R(−x)| > 1 + growth` (`growth ≥ 0`), scanned on
    /// `[0, 2d² + 1]` like [`real_axis_limit`](Self::real_axis_limit).
    pub fn real_axis_growth_limit(&self, growth: f64) -> f64 {
        let d = self.degree() as f64;
        let level = (1.0 + growth.max(0.0)).powi(2);
        first_crossing(|x| self.eval_real(-x).powi(2) - level, 2.0 * d * d + 1.0)
    }
}

/// The explicit Runge–Kutta methods whose tableau is public, each with its integrator:
/// explicit Euler, explicit midpoint, RK4, Bogacki–Shampine 3(2), Dormand–Prince 5(4), and
/// Verner's 6(5), 7(6), 8(7) and 9(8), in that order.
pub fn explicit_tableau_methods() -> [(Tableau, Box<dyn Integrator>); 9] {
    [
        (Tableau::euler(), Box::new(ExplicitEuler::new())),
        (Tableau::midpoint(), Box::new(ExplicitMidpoint::new())),
        (Tableau::rk4(), Box::new(RungeKutta4::new())),
        (Tableau::bs32(), Box::new(BogackiShampine32::new())),
        (Tableau::dopri5(), Box::new(DormandPrince54::new())),
        (Tableau::vern6(), Box::new(Verner65::new())),
        (Tableau::vern7(), Box::new(Verner76::new())),
        (Tableau::vern8(), Box::new(Verner87::new())),
        (Tableau::vern9(), Box::new(Verner98::new())),
    ]
}

/// The first `x > 0` in `(0, bound]` where `f` turns positive (`f ≤ 0` just above 0), refined
/// by bisection to adjacent floating-point numbers; `bound` if there is none.
fn first_crossing(f: impl Fn(f64) -> f64, bound: f64) -> f64 {
    let step = bound / SCAN_POINTS as f64;
    let Some(index) = (1..=SCAN_POINTS).find(|&i| f(i as f64 * step) > 0.0) else {
        return bound;
    };
    let (mut lo, mut hi) = ((index - 1) as f64 * step, index as f64 * step);
    while hi - lo > 4.0 * f64::EPSILON * hi {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The stability function of the implicit midpoint rule (the one-stage Gauss method),
/// `R(z) = (1 + z/2)/(1 − z/2)`: `|R(iy)| = 1` for every real `y` (A-stable, and it keeps the
/// oscillator's amplitude exactly).
///
/// # References
/// Hairer–Wanner II, §IV.3 (the diagonal Padé approximants are A-stable).
pub fn implicit_midpoint_stability(z: Complex<f64>) -> Complex<f64> {
    (1.0 + z / 2.0) / (1.0 - z / 2.0)
}

/// The stability function of Radau IIA of order 5, the (2,3) Padé approximant of `eᶻ`,
/// `R(z) = (1 + 2z/5 + z²/20)/(1 − 3z/5 + 3z²/20 − z³/60)`: `|R(iy)| < 1` for `y ≠ 0`
/// (A-stable) and `R(∞) = 0` (L-stable), so `|R(iy)| ≈ 3/y` for large `y`.
///
/// # References
/// Hairer–Wanner II, §IV.3 (Padé approximations of `eᶻ`) and §IV.5 (the stability function
/// of the `s`-stage Radau IIA method is the `(s − 1, s)` Padé approximant: L-stable).
pub fn radau_iia5_stability(z: Complex<f64>) -> Complex<f64> {
    let numerator = 1.0 + z * 2.0 / 5.0 + z * z / 20.0;
    let denominator = 1.0 - z * 3.0 / 5.0 + z * z * 3.0 / 20.0 - z * z * z / 60.0;
    numerator / denominator
}

/// The spectral radius of the step matrix of symplectic Euler and of Störmer–Verlet on
/// `ẍ = −ω²x`, as a function of `θ = hω`.
///
/// Both step matrices (on `(x, ẋ/ω)`) have determinant 1 (they are symplectic) and trace
/// `2 − θ²`, so their eigenvalues lie on the unit circle while `|2 − θ²| ≤ 2`, that is for
/// `θ ≤ 2`, and are real with `ρ = |tr|/2 + √(tr²/4 − 1) > 1` beyond. At `θ = 2` the
/// eigenvalue `−1` is double and the amplitude grows linearly.
///
/// # References
/// Hairer–Lubich–Wanner, *Geometric Numerical Integration*, §I.5.2 and §IX.8 (the
/// Störmer–Verlet method is stable for `hω < 2`).
pub fn partitioned_oscillator_spectral_radius(h_omega: f64) -> f64 {
    let half_trace = 1.0 - h_omega * h_omega / 2.0;
    if half_trace.abs() <= 1.0 {
        1.0
    } else {
        half_trace.abs() + (half_trace * half_trace - 1.0).sqrt()
    }
}

/// The `hω` beyond which [`partitioned_oscillator_spectral_radius`] exceeds `1 + growth`
/// (`growth ≥ 0`): `hω = √(2 + ρ + 1/ρ)` with `ρ = 1 + growth`, 2 for `growth = 0`.
pub fn partitioned_oscillator_growth_limit(growth: f64) -> f64 {
    let rho = 1.0 + growth.max(0.0);
    (2.0 + rho + 1.0 / rho).sqrt()
}

/// A linear test equation for the measurements, with `ω = λ = 1` so that the step `h` is `hω`
/// (or `hλ`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TestEquation {
    /// The undamped oscillator `ẍ = −x` as the second-order system `y = [x, ẋ]` (which the
    /// partitioned methods need), from `(1, 0)`. A Runge–Kutta method multiplies
    /// `‖y‖ = √(x² + ẋ²)` by exactly `|R(ih)|` per step (its step matrix is `|R|` times a
    /// rotation); a partitioned method keeps `‖y‖ ≤ 1` from this start while `h < 2` (its
    /// modified energy `(1 − h²/4)x² + ẋ²` is conserved: Störmer–Verlet), or bounded by
    /// `1/√(1 − h/2)` (symplectic Euler).
    Oscillator,
    /// The decay `ẋ = −x`, from `x = 1`: multiplied by `R(−h)` per step.
    Decay,
}

impl TestEquation {
    /// Integrates `steps` constant steps of size `h` and returns `‖y‖` at the end (the initial
    /// state has `‖y‖ = 1`).
    ///
    /// The tolerances are `rtol = 1e-10`, `atol = 1e-14`: only the implicit methods use them,
    /// to stop their Newton iterations, so their `‖y‖` is accurate to about 1e-10 relative
    /// while it stays above 1e-14.
    ///
    /// # Errors
    /// The [`IntegrationFailure`] of the run.
    pub fn final_norm(
        self,
        method: &mut dyn Integrator,
        h: f64,
        steps: usize,
    ) -> Result<f64, IntegrationFailure> {
        let t_end = h * steps as f64;
        // The tolerances only stop the Newton iterations of the implicit methods: their
        // amplitudes are accurate to about 1e-10 relative while above 1e-14.
        let options = IntegratorOptions::default()
            .with_fixed_step(true)
            .with_dt(h)
            .with_rtol(1e-10)
            .with_atol(1e-14)
            .with_max_steps(steps + 2);
        let output = OutputTimes::At(vec![t_end]);
        let solution = match self {
            TestEquation::Oscillator => {
                let mut system = OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
                    dy[0] = y[1];
                    dy[1] = -y[0];
                });
                method.integrate(&mut system, 0.0, &[1.0, 0.0], t_end, &output, &options)?
            }
            TestEquation::Decay => {
                let mut system = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0]);
                method.integrate(&mut system, 0.0, &[1.0], t_end, &output, &options)?
            }
        };
        Ok(solution.state(0).iter().map(|v| v * v).sum::<f64>().sqrt())
    }
}

/// The measured per-step amplification `(‖y_N‖/‖y₀‖)^(1/N)` of `method` with `N = steps`
/// constant steps of size `h` on `equation`. For a Runge–Kutta method on the oscillator it
/// is `|R(ih)|`, on the decay `|R(−h)|`.
///
/// # Errors
/// The [`IntegrationFailure`] of the run, e.g. [`IntegrationError::NonFiniteState`] when
/// `‖y‖` overflows (`steps` too large for the growth).
pub fn amplification(
    method: &mut dyn Integrator,
    equation: TestEquation,
    h: f64,
    steps: usize,
) -> Result<f64, IntegrationFailure> {
    let norm = equation.final_norm(method, h, steps)?;
    Ok(norm.powf(1.0 / steps as f64))
}

/// When a constant-step run counts as unstable: `‖y‖` grows beyond `threshold` (from 1)
/// within `steps` steps, or overflows.
///
/// A per-step growth `1 + δ` is detected when `(1 + δ)^steps > threshold`, that is for
/// `δ ≳ ln(threshold)/steps` ([`GrowthTest::smallest_detected_growth`]). `threshold` must
/// exceed the bounded transient of a stable but non-normal step matrix (symplectic Euler:
/// `1/√(1 − h/2)` from `(1, 0)`, 100 at 0.01 % below its limit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthTest {
    /// Number of constant steps of each run.
    pub steps: usize,
    /// Growth of `‖y‖` that counts as unstable (dimensionless, `> 1`).
    pub threshold: f64,
}

impl GrowthTest {
    /// The smallest per-step growth `δ` this test detects: `threshold^(1/steps) − 1`.
    pub fn smallest_detected_growth(&self) -> f64 {
        self.threshold.powf(1.0 / self.steps as f64) - 1.0
    }

    /// The number of steps needed to detect a per-step growth `1 + δ`:
    /// `⌈ln(threshold)/ln(1 + δ)⌉` (`usize::MAX` for `δ ≤ 0`).
    pub fn steps_to_detect(&self, growth: f64) -> usize {
        if growth > 0.0 {
            (self.threshold.ln() / growth.ln_1p()).ceil() as usize
        } else {
            usize::MAX
        }
    }

    /// Whether `method` with step `h` on `equation` stays within `threshold` for `steps` steps.
    ///
    /// # Errors
    /// The [`IntegrationFailure`] of the run, unless it is an overflow
    /// ([`IntegrationError::NonFiniteState`], [`IntegrationError::RhsNonFinite`]), which
    /// counts as unstable.
    pub fn is_stable(
        &self,
        method: &mut dyn Integrator,
        equation: TestEquation,
        h: f64,
    ) -> Result<bool, IntegrationFailure> {
        match equation.final_norm(method, h, self.steps) {
            Ok(norm) => Ok(norm <= self.threshold),
            Err(IntegrationFailure {
                error:
                    IntegrationError::NonFiniteState { .. }
                    | IntegrationError::RhsNonFinite { .. }
                    | IntegrationError::JacobianNonFinite { .. },
                ..
            }) => Ok(false),
            Err(failure) => Err(failure),
        }
    }
}

/// The largest stable step `h` (in units of `1/ω` or `1/λ`) of `method` on `equation`, as
/// measured by `test`: steps `h = 0.1 · 1.25ᵏ` are tried until one is unstable, then the
/// bracket is bisected until its width is below `relative_tolerance · h`; the midpoint is
/// returned. `None` if every `h ≤ 1000` is stable (A-stable methods); `Some(0.0)` if already
/// `h = 0.1` is unstable.
///
/// With a per-step growth `1 + δ(h)` above the limit, the result exceeds the true limit by
/// the `Δh` at which `δ` reaches [`GrowthTest::smallest_detected_growth`].
///
/// # Errors
/// An [`IntegrationFailure`] other than an overflow (see [`GrowthTest::is_stable`]).
pub fn measured_limit(
    method: &mut dyn Integrator,
    equation: TestEquation,
    test: &GrowthTest,
    relative_tolerance: f64,
) -> Result<Option<f64>, IntegrationFailure> {
    let mut lo = 0.0;
    let mut hi = 0.1;
    while test.is_stable(method, equation, hi)? {
        lo = hi;
        hi *= 1.25;
        if hi > 1000.0 {
            return Ok(None);
        }
    }
    if lo == 0.0 {
        return Ok(Some(0.0));
    }
    while hi - lo > relative_tolerance * hi {
        let mid = 0.5 * (lo + hi);
        if test.is_stable(method, equation, mid)? {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(Some(0.5 * (lo + hi)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stability polynomials read off one step of each explicit method equal the known
    /// ones (Hairer–Wanner II, §IV.2): `Σₖ≤ₚ zᵏ/k!` for Euler, the midpoint rule and RK4;
    /// BS3's of degree 3 (its fourth stage has no weight); DP5(4)'s with `r₆ = 1/600`; and
    /// DOP853's `1/k!` up to `k = 8` (to 1e-14: its coefficients, up to 44 in size, leave
    /// rounding of a few 1e-16 in each sum; the exact ones to 1e-15). Each equals the
    /// tableau's `bᵀAᵏ⁻¹𝟙` where the tableau is public, and `order()` counts the leading
    /// `1/k!`.
    #[test]
    fn polynomials_of_the_methods_are_the_known_ones() {
        let taylor = |p: usize| -> Vec<f64> {
            (0..=p)
                .map(|k| 1.0 / (1..=k).map(|i| i as f64).product::<f64>())
                .collect()
        };
        let mut dopri5 = taylor(5);
        dopri5.extend([1.0 / 600.0, 0.0]);
        let mut bs3 = taylor(3);
        bs3.push(0.0);
        // (method, stages, its tableau, the expected coefficients, the expected order)
        type Case<'a> = (&'a mut dyn Integrator, usize, Tableau, Vec<f64>, usize);
        let cases: [Case; 5] = [
            (&mut ExplicitEuler::new(), 1, Tableau::euler(), taylor(1), 1),
            (
                &mut ExplicitMidpoint::new(),
                2,
                Tableau::midpoint(),
                taylor(2),
                2,
            ),
            (&mut RungeKutta4::new(), 4, Tableau::rk4(), taylor(4), 4),
            (&mut BogackiShampine32::new(), 4, Tableau::bs32(), bs3, 3),
            (&mut DormandPrince54::new(), 7, Tableau::dopri5(), dopri5, 5),
        ];
        for (method, stages, tableau, expected, order) in cases {
            let name = method.name();
            let read = StabilityPolynomial::of_method(method, stages).unwrap();
            assert_eq!(read.coefficients().len(), expected.len(), "{name}");
            for (r, e) in read.coefficients().iter().zip(&expected) {
                assert!((r - e).abs() < 1e-15, "{name}: {:?}", read.coefficients());
            }
            assert_eq!(read.order(), order, "{name}");
            let from_tableau = StabilityPolynomial::of_tableau(&tableau);
            for (r, e) in from_tableau.coefficients().iter().zip(&expected) {
                assert!(
                    (r - e).abs() < 1e-15,
                    "{name}: {:?}",
                    from_tableau.coefficients()
                );
            }
        }
        let dop853 =
            StabilityPolynomial::of_method(&mut crate::integrate::DormandPrince853::new(), 12)
                .unwrap();
        for (r, e) in dop853.coefficients().iter().zip(taylor(8)) {
            assert!((r - e).abs() < 1e-14, "dop853: {:?}", dop853.coefficients());
        }
        assert_eq!(dop853.order(), 8);
    }

    /// RK4's limits: on the imaginary axis `|R(iy)|² = 1 − y⁶/72 + y⁸/576`, so `2√2`
    /// (the rounding noise of +7e-18 left in its `y⁴` coefficient would make it 0, which is
    /// why the coefficients up to `yᵖ` are cleared); on the real axis the root of
    /// `R(−x) = 1`, `x(−1 + x/2 − x²/6 + x³/24) = 0`, found by plain bisection of the cubic:
    /// 2.7852935634052813. Bogacki–Shampine's and DP5(4)'s real limits, where `R(−x)`
    /// reaches −1 and +1 (2.5127453266183286 and 3.306567892634946, by scan and bisection of
    /// the polynomials in plain code). And `E(y)` of an inconsistent `R = 2 + z` keeps `r₀² − 1 = 3`.
    #[test]
    fn limits_of_rk4_and_bs3() {
        let rk4 = StabilityPolynomial::of_tableau(&Tableau::rk4());
        assert!((rk4.imaginary_axis_limit() - 8f64.sqrt()).abs() < 1e-12);
        assert!((rk4.real_axis_limit() - 2.785_293_563_405_281_3).abs() < 1e-12);
        let bs3 = StabilityPolynomial::of_tableau(&Tableau::bs32());
        assert!((bs3.real_axis_limit() - 2.512_745_326_618_328_6).abs() < 1e-12);
        // DP5(4)'s lies beyond 3 (the scan covers [0, 2 · 6² + 1] for its degree 6).
        let dopri5 = StabilityPolynomial::of_tableau(&Tableau::dopri5());
        assert!((dopri5.real_axis_limit() - 3.306_567_892_634_946).abs() < 1e-12);
        let excess = StabilityPolynomial::from_coefficients(vec![2.0, 1.0]).imaginary_axis_excess();
        assert_eq!(excess, [3.0, 0.0, 1.0]);
    }

    /// Growth limits in closed form: explicit Euler `|1 + iy|² = 1 + y²` and the midpoint
    /// rule `|R(iy)|² = 1 + y⁴/4` exceed `(1 + g)²` from `y = √(g(2 + g))` and
    /// `y = (4g(2 + g))^(1/4)`; Euler's `|1 − x|` exceeds `1 + g` from `x = 2 + g`.
    #[test]
    fn growth_limits_of_closed_forms() {
        let euler = StabilityPolynomial::of_tableau(&Tableau::euler());
        let midpoint = StabilityPolynomial::of_tableau(&Tableau::midpoint());
        // g = 14 puts the midpoint rule's crossing at 5.47, inside its scanned [0, 2(d + 1)].
        for g in [0.01_f64, 0.1, 0.5, 14.0] {
            let level = g * (2.0 + g);
            let close = |a: f64, b: f64| (a - b).abs() < 1e-12 * b;
            // Beyond the scanned [0, 2(d + 1)] = [0, 4] (g = 14: 15.0), the bound.
            let euler_limit = if g < 4.0 { level.sqrt() } else { 4.0 };
            assert!(
                close(euler.imaginary_axis_growth_limit(g), euler_limit),
                "{g}"
            );
            assert!(
                close(
                    midpoint.imaginary_axis_growth_limit(g),
                    (4.0 * level).powf(0.25)
                ),
                "{g}"
            );
            // Its real crossing, 2 + g, is scanned for on [0, 2d² + 1] = [0, 3].
            let real_limit = (2.0 + g).min(3.0);
            assert!(close(euler.real_axis_growth_limit(g), real_limit), "{g}");
        }
    }

    /// The scan finds the first of several crossings (`sin 10x = 1/2` at `π/60`, then
    /// again every `2π/10`), refined to rounding; none gives the bound.
    #[test]
    fn the_first_crossing_is_found() {
        let x = first_crossing(|x| (10.0 * x).sin() - 0.5, 3.0);
        assert!((x - std::f64::consts::PI / 60.0).abs() < 1e-15, "{x}");
        assert_eq!(first_crossing(|x| -1.0 - x, 2.0), 2.0);
    }

    /// The implicit methods' stability functions are their steps: one step of size 1 of
    /// implicit midpoint and of RADAU5 on `ẏ = zy` multiplies `y` by `R(z)` (to 1e-9, the
    /// Newton iterations' tolerance), for mild and stiff real `z`; at complex `z` they equal
    /// the Padé forms written over a common denominator, `(2 + z)/(2 − z)` and
    /// `(60 + 24z + 3z²)/(60 − 36z + 9z² − z³)`.
    #[test]
    fn implicit_stability_functions_are_one_step_of_the_methods() {
        use crate::integrate::{ImplicitMidpoint, RadauIIA5};
        for z in [-0.5, -3.0, -40.0] {
            let options = IntegratorOptions::default()
                .with_fixed_step(true)
                .with_dt(1.0)
                .with_rtol(1e-12)
                .with_atol(1e-14);
            let step = |method: &mut dyn Integrator| {
                let mut system = OdeFn::new(1, move |_t: f64, y: &[f64], dy: &mut [f64]| {
                    dy[0] = z * y[0]
                });
                method
                    .integrate(&mut system, 0.0, &[1.0], 1.0, &OutputTimes::Steps, &options)
                    .unwrap()
                    .y[1]
            };
            let midpoint = step(&mut ImplicitMidpoint::new());
            let expected = implicit_midpoint_stability(Complex::new(z, 0.0)).re;
            assert!(
                (midpoint - expected).abs() < 1e-9 * expected.abs(),
                "{z}: {midpoint} vs {expected}"
            );
            let radau = step(&mut RadauIIA5::new());
            let expected = radau_iia5_stability(Complex::new(z, 0.0)).re;
            assert!(
                (radau - expected).abs() < 1e-9 * expected.abs().max(1e-3),
                "{z}: {radau} vs {expected}"
            );
        }
        for z in [
            Complex::new(0.3, 2.0),
            Complex::new(-5.0, -1.0),
            Complex::new(0.0, 50.0),
        ] {
            let midpoint = (2.0 + z) / (2.0 - z);
            assert!((implicit_midpoint_stability(z) - midpoint).norm() < 1e-14 * midpoint.norm());
            let radau =
                (60.0 + 24.0 * z + 3.0 * z * z) / (60.0 - 36.0 * z + 9.0 * z * z - z * z * z);
            assert!(
                (radau_iia5_stability(z) - radau).norm() < 1e-14 * radau.norm(),
                "{z}"
            );
        }
    }

    /// The measurements against the theory: the per-step amplification of RK4 is `|R(ih)|`
    /// on the oscillator and `|R(−h)|` on the decay (to rounding over 20 steps); explicit
    /// Euler's norm on the oscillator after 10 steps of 0.1 is `(1 + h²)^(10/2)`; a growth
    /// test of 100 steps and threshold 10 detects `δ ≥ 10^(1/100) − 1` and needs
    /// `⌈ln 10 / ln 1.05⌉ = 48` steps for `δ = 0.05`; and the measured limit of RK4 on the
    /// oscillator lies just above `2√2`, by the `Δh` at which `|R(ih)| − 1` reaches the
    /// smallest detected growth, while RADAU5 (A-stable) has none on the decay.
    #[test]
    fn measurements_match_the_theory() {
        let rk4 = StabilityPolynomial::of_tableau(&Tableau::rk4());
        for h in [0.5, 2.0, 3.0] {
            let oscillator =
                amplification(&mut RungeKutta4::new(), TestEquation::Oscillator, h, 20).unwrap();
            let expected = rk4.eval(Complex::new(0.0, h)).norm();
            assert!(
                (oscillator - expected).abs() < 1e-13,
                "{h}: {oscillator} vs {expected}"
            );
            let decay = amplification(&mut RungeKutta4::new(), TestEquation::Decay, h, 20).unwrap();
            let expected = rk4.eval_real(-h).abs();
            assert!(
                (decay - expected).abs() < 1e-13,
                "{h}: {decay} vs {expected}"
            );
        }
        let euler = TestEquation::Oscillator
            .final_norm(&mut ExplicitEuler::new(), 0.1, 10)
            .unwrap();
        assert!((euler - 1.01f64.powi(5)).abs() < 1e-14, "{euler}");
        let test = GrowthTest {
            steps: 100,
            threshold: 10.0,
        };
        assert!((test.smallest_detected_growth() - (10f64.powf(0.01) - 1.0)).abs() < 1e-15);
        assert_eq!(test.steps_to_detect(0.05), 48);
        assert_eq!(test.steps_to_detect(0.0), usize::MAX);
        let measured = measured_limit(
            &mut RungeKutta4::new(),
            TestEquation::Oscillator,
            &test,
            1e-6,
        )
        .unwrap()
        .unwrap();
        let detected = rk4.imaginary_axis_growth_limit(test.smallest_detected_growth());
        assert!(
            measured > 8f64.sqrt() && (measured - detected).abs() < 1e-4,
            "{measured} vs {detected}"
        );
        // An A-stable method is stable at every h tried, up to 1000.
        let radau = measured_limit(
            &mut crate::integrate::RadauIIA5::new(),
            TestEquation::Decay,
            &test,
            1e-6,
        );
        assert_eq!(radau.unwrap(), None);
    }

    /// Horner's evaluation equals the sum `Σ rₖ zᵏ`, at a complex and at a real point.
    #[test]
    fn evaluation_is_the_sum_of_the_terms() {
        let p = StabilityPolynomial::from_coefficients(vec![1.0, -2.0, 0.5, 3.0]);
        let z = Complex::new(0.3, -0.7);
        let sum: Complex<f64> = p
            .coefficients()
            .iter()
            .enumerate()
            .map(|(k, &r)| z.powi(k as i32) * r)
            .sum();
        assert!((p.eval(z) - sum).norm() < 1e-15);
        let x: f64 = -0.7;
        let sum: f64 = p
            .coefficients()
            .iter()
            .enumerate()
            .map(|(k, &r)| r * x.powi(k as i32))
            .sum();
        assert!((p.eval_real(x) - sum).abs() < 1e-15);
    }

    /// `|R(iy)|²` from the excess polynomial agrees with direct evaluation of `R`.
    #[test]
    fn excess_is_the_squared_modulus_minus_one() {
        for tableau in [
            Tableau::euler(),
            Tableau::midpoint(),
            Tableau::bs32(),
            Tableau::dopri5(),
        ] {
            let r = StabilityPolynomial::of_tableau(&tableau);
            let e = r.imaginary_axis_excess();
            for y in [0.3, 1.0, 2.5] {
                let direct = r.eval(Complex::new(0.0, y)).norm_sqr() - 1.0;
                let from_e = e.iter().rev().fold(0.0, |acc, &c| acc * y + c);
                assert!((direct - from_e).abs() < 1e-12, "{} at {y}", tableau.name());
            }
        }
    }

    /// Closed forms: Euler `R = 1 + z` (real interval 2, imaginary empty), RK4 imaginary `2√2`,
    /// Bogacki–Shampine (`R = 1 + z + z²/2 + z³/6`) imaginary `√3`.
    #[test]
    fn limits_of_closed_forms() {
        let euler = StabilityPolynomial::of_tableau(&Tableau::euler());
        assert_eq!(euler.imaginary_axis_limit(), 0.0);
        assert!((euler.real_axis_limit() - 2.0).abs() < 1e-12);
        let bs32 = StabilityPolynomial::of_tableau(&Tableau::bs32());
        assert_eq!(bs32.degree(), 3);
        assert!((bs32.imaginary_axis_limit() - 3f64.sqrt()).abs() < 1e-12);
        assert_eq!(partitioned_oscillator_spectral_radius(1.99), 1.0);
        assert_eq!(partitioned_oscillator_growth_limit(0.0), 2.0);
        let beyond = partitioned_oscillator_growth_limit(0.1);
        assert!((partitioned_oscillator_spectral_radius(beyond) - 1.1).abs() < 1e-12);
        assert!(partitioned_oscillator_spectral_radius(2.01) > 1.0);
    }
}
