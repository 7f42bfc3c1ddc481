//! Part a: the stability limits of every method, measured by bisection on constant-step runs of
//! `ẍ = −ω²x` and `ẋ = −λx` and against its stability function, and the per-step
//! amplification where the interval is empty or the method is A-stable.

use nalgebra::Complex;
use serde::Serialize;

use crate::integrate::stability_function::{
    GrowthTest, StabilityPolynomial, TestEquation, amplification, explicit_tableau_methods,
    implicit_midpoint_stability, measured_limit, partitioned_oscillator_growth_limit,
    partitioned_oscillator_spectral_radius, radau_iia5_stability,
};
use crate::integrate::{
    DormandPrince853, ImplicitMidpoint, IntegrationFailure, Integrator, RadauIIA5, StormerVerlet,
    SymplecticEuler, Tableau,
};

use super::options::StabilityError;

/// Growth of `‖y‖` that counts as unstable in the bisection: far above the bounded transient
/// of a stable non-normal step (symplectic Euler: `1/√(1 − hω/2)`, 100 at 10⁻⁴ below its
/// limit).
pub const GROWTH_THRESHOLD: f64 = 1e4;

/// Relative width of the final bisection bracket.
pub const BISECTION_TOLERANCE: f64 = 1e-6;

/// `hω` at which the per-step amplification of the methods with an empty imaginary interval
/// is measured.
pub const EMPTY_INTERVAL_STEPS: [f64; 4] = [0.1, 0.5, 1.0, 2.0];

/// Multiples of the imaginary limit at which a method too weakly unstable beyond it for the
/// bisection's `N` (Dormand–Prince 5(4)) is shown by its amplification.
pub const WEAK_INSTABILITY_FACTORS: [f64; 4] = [1.01, 1.2, 1.5, 2.0];

/// `hω` at which the A-stable methods are run.
pub const A_STABLE_STEPS: [f64; 3] = [10.0, 100.0, 1000.0];

/// Steps of each amplification run (`N` in `(‖y_N‖/‖y₀‖)^(1/N)`): few enough that Radau
/// IIA's amplitude (`≈ (3/hω)ᴺ`) stays above the `atol` of 1e-14 of its Newton iterations.
pub const AMPLIFICATION_STEPS: usize = 3;

/// Steps of the long run that shows the A-stable methods stable.
pub const LONG_RUN_STEPS: usize = 1000;

/// A stability interval, measured and in theory (part a).
#[derive(Debug, Serialize)]
pub struct LimitRow {
    /// The integrator's name.
    pub method: &'static str,
    /// `"imaginary"` (`hω` on `ẍ = −ω²x`) or `"real"` (`hλ` on `ẋ = −λx`).
    pub axis: &'static str,
    /// The value the stability function predicts.
    pub theory: f64,
    /// The measured value.
    pub measured: Option<f64>,
    /// `(measured − theory)/theory`.
    pub relative_difference: Option<f64>,
    /// The limit a run of `steps_used` steps can see: the first `h` where the per-step growth
    /// exceeds the smallest detected one (theory, for this `N`).
    pub theory_at_detection: f64,
    /// `(measured − theory_at_detection)/theory_at_detection`.
    pub relative_difference_at_detection: Option<f64>,
    /// Per-step growth `|R| − 1` one percent above the theoretical limit.
    pub growth_one_percent_above: f64,
    /// Steps needed to see that growth exceed the threshold.
    pub steps_needed_one_percent_above: usize,
    /// Steps `N` of each bisection run.
    pub steps_used: usize,
}

/// A measured per-step amplification against `|R(ihω)|` (part a).
#[derive(Debug, Serialize)]
pub struct AmplificationRow {
    /// The integrator's name.
    pub method: &'static str,
    /// `hω`.
    pub h_omega: f64,
    /// Steps.
    pub steps: usize,
    /// The measured value.
    pub measured: f64,
    /// The value the stability function predicts.
    pub theory: f64,
    /// `(measured − theory)/theory`.
    pub relative_difference: f64,
    /// `‖y‖` after 1000 steps, from 1 (A-stable methods only).
    pub norm_after_long_run: Option<f64>,
}

/// An explicit method with its stability polynomial.
pub struct ExplicitMethod {
    /// The integrator's name.
    pub name: &'static str,
    /// The integrator.
    pub method: Box<dyn Integrator>,
    /// Its stability polynomial `R(z)`.
    pub polynomial: StabilityPolynomial,
    /// Largest difference between the coefficients from the tableau and those read off one
    /// step of the implementation (`None` for DOP853, whose polynomial is the latter).
    pub implementation_difference: Option<f64>,
}

/// The explicit methods, their polynomials from their tableaus (DOP853's from one step of it,
/// its tableau being private), each checked against one step of its implementation; DOP853
/// follows Dormand–Prince 5(4), before Verner's pairs.
fn explicit_methods() -> Result<Vec<ExplicitMethod>, StabilityError> {
    let failed = |e: IntegrationFailure| StabilityError::PolynomialStep {
        message: e.to_string(),
    };
    let mut methods = Vec::new();
    for (tableau, mut method) in explicit_tableau_methods() {
        let polynomial = StabilityPolynomial::of_tableau(&tableau);
        let stepped = StabilityPolynomial::of_method(method.as_mut(), tableau.num_stages())
            .map_err(failed)?;
        let difference = polynomial
            .coefficients()
            .iter()
            .zip(stepped.coefficients())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        methods.push(ExplicitMethod {
            name: method.name(),
            method,
            polynomial,
            implementation_difference: Some(difference),
        });
        if tableau.name() == Tableau::dopri5().name() {
            let mut dop853: Box<dyn Integrator> = Box::new(DormandPrince853::new());
            let polynomial = StabilityPolynomial::of_method(dop853.as_mut(), 12).map_err(failed)?;
            methods.push(ExplicitMethod {
                name: dop853.name(),
                method: dop853,
                polynomial,
                implementation_difference: None,
            });
        }
    }
    Ok(methods)
}

/// Everything part a measures.
#[derive(Serialize)]
pub struct Limits {
    /// The explicit methods with their stability polynomials.
    #[serde(skip)]
    pub explicit: Vec<ExplicitMethod>,
    /// The measured stability intervals against theory.
    pub rows: Vec<LimitRow>,
    /// The measured per-step amplifications against `|R(ihω)|`.
    pub amplification: Vec<AmplificationRow>,
    /// The explicit methods' polynomials (one entry per [`Limits::explicit`]).
    pub polynomials: Vec<PolynomialRow>,
}

/// An explicit method's stability polynomial `R(z) = Σ cₖ zᵏ`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PolynomialRow {
    /// The integrator's name.
    pub method: &'static str,
    /// The coefficients `c₀, c₁, …`.
    pub coefficients: Vec<f64>,
    /// The order `p` the coefficients match `e^z` to.
    pub order: usize,
    /// Largest difference between the coefficients from the tableau and those read off one
    /// step of the implementation (`None` for DOP853).
    pub implementation_difference: Option<f64>,
}

impl ExplicitMethod {
    /// The per-step amplification on `ẍ = −ω²x` measured over 10 steps at each `hω` of
    /// `h_omegas` (the points where the run fails are left out): `(hω, amplification)`.
    pub fn measured_amplifications(&mut self, h_omegas: &[f64]) -> Vec<(f64, f64)> {
        h_omegas
            .iter()
            .filter_map(|&h| {
                amplification(self.method.as_mut(), TestEquation::Oscillator, h, 10)
                    .ok()
                    .map(|a| (h, a))
            })
            .collect()
    }
}

/// The theoretical limits of one method on one axis: strict (`|R| ≤ 1`), at the test's
/// detection threshold, and the per-step growth one percent above the strict limit.
struct Theory {
    limit: f64,
    at_detection: f64,
    growth_one_percent_above: f64,
}

fn limit_row(
    method: &mut dyn Integrator,
    axis: &'static str,
    theory: Theory,
    test: &GrowthTest,
) -> Result<LimitRow, StabilityError> {
    let Theory {
        limit: theory,
        at_detection,
        growth_one_percent_above: growth,
    } = theory;
    let equation = if axis == "real" {
        TestEquation::Decay
    } else {
        TestEquation::Oscillator
    };
    let measured = measured_limit(method, equation, test, BISECTION_TOLERANCE).map_err(|e| {
        StabilityError::TestEquation {
            method: method.name(),
            message: e.to_string(),
        }
    })?;
    Ok(LimitRow {
        method: method.name(),
        axis,
        theory,
        measured,
        relative_difference: measured.map(|m| (m - theory) / theory),
        theory_at_detection: at_detection,
        relative_difference_at_detection: measured.map(|m| (m - at_detection) / at_detection),
        growth_one_percent_above: growth,
        steps_needed_one_percent_above: test.steps_to_detect(growth),
        steps_used: test.steps,
    })
}

fn amplification_row(
    method: &mut dyn Integrator,
    h_omega: f64,
    theory: f64,
    long_run: bool,
) -> Result<AmplificationRow, StabilityError> {
    let name = method.name();
    let failed = |e: IntegrationFailure| StabilityError::Amplification {
        method: name,
        h_omega,
        message: e.to_string(),
    };
    let measured = amplification(
        method,
        TestEquation::Oscillator,
        h_omega,
        AMPLIFICATION_STEPS,
    )
    .map_err(failed)?;
    let norm_after_long_run = if long_run {
        Some(
            TestEquation::Oscillator
                .final_norm(method, h_omega, LONG_RUN_STEPS)
                .map_err(failed)?,
        )
    } else {
        None
    };
    Ok(AmplificationRow {
        norm_after_long_run,
        method: name,
        h_omega,
        steps: AMPLIFICATION_STEPS,
        measured,
        theory,
        relative_difference: (measured - theory) / theory,
    })
}

pub(super) fn stability_limits(test: &GrowthTest) -> Result<Limits, StabilityError> {
    let mut explicit = explicit_methods()?;
    let mut rows = Vec::new();
    let mut amplification = Vec::new();
    let detected = test.smallest_detected_growth();
    for m in &mut explicit {
        let r = &m.polynomial;
        let imaginary = r.imaginary_axis_limit();
        if imaginary == 0.0 {
            for h in EMPTY_INTERVAL_STEPS {
                let theory = r.eval(Complex::new(0.0, h)).norm();
                amplification.push(amplification_row(m.method.as_mut(), h, theory, false)?);
            }
        } else {
            let growth = r.eval(Complex::new(0.0, 1.01 * imaginary)).norm() - 1.0;
            let theory = Theory {
                limit: imaginary,
                at_detection: r.imaginary_axis_growth_limit(detected),
                growth_one_percent_above: growth,
            };
            rows.push(limit_row(m.method.as_mut(), "imaginary", theory, test)?);
            if test.steps_to_detect(growth) > test.steps {
                // Too weakly unstable just beyond the limit for N steps to see: show the
                // growth there directly.
                for factor in WEAK_INSTABILITY_FACTORS {
                    let h = factor * imaginary;
                    let theory = r.eval(Complex::new(0.0, h)).norm();
                    amplification.push(amplification_row(m.method.as_mut(), h, theory, false)?);
                }
            }
        }
        let real = r.real_axis_limit();
        let theory = Theory {
            limit: real,
            at_detection: r.real_axis_growth_limit(detected),
            growth_one_percent_above: r.eval_real(-1.01 * real).abs() - 1.0,
        };
        rows.push(limit_row(m.method.as_mut(), "real", theory, test)?);
    }
    let partitioned: [Box<dyn Integrator>; 2] = [
        Box::new(SymplecticEuler::new()),
        Box::new(StormerVerlet::new()),
    ];
    for mut method in partitioned {
        let theory = Theory {
            limit: 2.0,
            at_detection: partitioned_oscillator_growth_limit(detected),
            growth_one_percent_above: partitioned_oscillator_spectral_radius(2.02) - 1.0,
        };
        rows.push(limit_row(method.as_mut(), "imaginary", theory, test)?);
    }
    let implicit: [(Box<dyn Integrator>, StabilityFunction); 2] = [
        // Its default Newton tolerance (1e-12 relative) is below the rounding of h·F at
        // h = 1000 (about 1000 ε), where Newton would report non-convergence.
        (
            Box::new(ImplicitMidpoint::new().with_newton_tolerance(1e-10)),
            implicit_midpoint_stability,
        ),
        (Box::new(RadauIIA5::new()), radau_iia5_stability),
    ];
    for (mut method, stability) in implicit {
        for h in A_STABLE_STEPS {
            let theory = stability(Complex::new(0.0, h)).norm();
            amplification.push(amplification_row(method.as_mut(), h, theory, true)?);
        }
    }
    let polynomials = explicit
        .iter()
        .map(|m| PolynomialRow {
            method: m.name,
            coefficients: m.polynomial.coefficients().to_vec(),
            order: m.polynomial.order(),
            implementation_difference: m.implementation_difference,
        })
        .collect();
    Ok(Limits {
        explicit,
        rows,
        amplification,
        polynomials,
    })
}

/// A stability function `R(z)`.
type StabilityFunction = fn(Complex<f64>) -> Complex<f64>;
