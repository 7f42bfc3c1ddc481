//! Where each integration method fails (issue 6; syllabus lecture 4, HW9): stability limits
//! measured by running the integrators against the theory of their stability functions, the
//! A-stable methods at large steps, Radau IIA on the stiff two-mass spring, HW1's round-off
//! study, and `stability_study` with the hand-written two-mass chain of `common/models.rs` as
//! its stiff model.
//!
//! Every tolerance is stated next to its assertion with the reason for its size. The heavy
//! variants are `#[ignore]`d:
//! `cargo test -p eomgen-runtime --release --test suite -- stability:: --ignored`.

use crate::common;

use std::f64::consts::E;

use common::models::{Pendulum, TwoMassChain, boxed};
use eomgen_runtime::analysis::vibration::{ModalOptions, modal_analysis};
use eomgen_runtime::analysis::{
    RoundoffOptions, StabilityError, StabilityOptions, StiffSpring, euler_roundoff, stability_study,
};
use eomgen_runtime::integrate::stability_function::{
    GrowthTest, StabilityPolynomial, TestEquation, amplification, explicit_tableau_methods,
    measured_limit, partitioned_oscillator_growth_limit, radau_iia5_stability,
};
use eomgen_runtime::{
    DormandPrince54, DormandPrince853, ExplicitEuler, ExplicitMidpoint, ImplicitMidpoint,
    Integrator, IntegratorOptions, ModeKind, OutputTimes, RadauIIA5, StormerVerlet,
    SymplecticEuler, Tableau, Verner76, Verner87,
};
use nalgebra::Complex;

/// The growth test of the limit measurements: 2000 steps and a threshold of 10⁴ detect a
/// per-step growth of 4.6e-3. One percent above each limit tested here the growth is at least
/// 7.8e-3 (BS32 on the imaginary axis; the others 2e-2 … 0.33), detected within 1184 steps,
/// so 2000 steps make the 1 % criterion valid. The threshold is far above symplectic Euler's
/// bounded transient while stable (`‖y‖ ≤ 1/√(1 − hω/2)` from `(1, 0)`: 300 at 10⁻⁵ below its
/// limit, the bisection's resolution).
const TEST: GrowthTest = GrowthTest {
    steps: 2000,
    threshold: 1e4,
};

/// Explicit stability limits match theory to 1 %: each method is run (constant steps,
/// the adaptive ones with `fixed_step`) on `ẍ = −x` and `ẋ = −x`, the largest stable `h` found
/// by bisection, and compared with the first crossing of `|R| = 1` of the stability polynomial
/// computed from the tableau (DOP853: read off one step, its tableau being private), and
/// with `hω = 2` for the partitioned methods.
///
/// Tolerances: 1 % against the strict limit, as the issue asks (the test's own resolution,
/// where `|R|` reaches `1 + 4.6e-3`, is 0.02 %–0.6 % above it); 1e-4 against `theory(N)`, the
/// crossing of that growth level, which the bisection (to 1e-5) must hit. Where `theory(N)`
/// lies more than 1 % beyond the strict limit, the theory predicts the exception:
/// Dormand–Prince 5(4) on the imaginary axis grows by only 5e-6 per step one percent beyond
/// its strict limit 0.997, which 2000 steps (or 10⁴) cannot see, and so do Verner 6(5) and
/// 9(8) there; their measurements must match `theory(N)` and exceed the strict limit.
#[test]
fn explicit_stability_limits_match_theory_to_one_percent() {
    let detected = TEST.smallest_detected_growth();
    let tableau_methods = explicit_tableau_methods();
    let mut methods: Vec<(StabilityPolynomial, Box<dyn Integrator>)> = tableau_methods
        .into_iter()
        .map(|(t, m)| (StabilityPolynomial::of_tableau(&t), m))
        .collect();
    let mut dop853 = DormandPrince853::new();
    methods.push((
        StabilityPolynomial::of_method(&mut dop853, 12).unwrap(),
        Box::new(dop853),
    ));
    let (mut checked, mut weak) = (0, Vec::new());
    for (r, mut method) in methods {
        let cases = [
            (
                TestEquation::Oscillator,
                r.imaginary_axis_limit(),
                r.imaginary_axis_growth_limit(detected),
            ),
            (
                TestEquation::Decay,
                r.real_axis_limit(),
                r.real_axis_growth_limit(detected),
            ),
        ];
        for (equation, theory, at_detection) in cases {
            if theory == 0.0 {
                // No interval from 0 (Euler, the midpoint rule, Verner 7(6) and 8(7) on the
                // imaginary axis): see the amplification test.
                continue;
            }
            let measured = measured_limit(method.as_mut(), equation, &TEST, 1e-5)
                .unwrap()
                .expect("an explicit method has a finite limit");
            let name = method.name();
            println!(
                "{name:>8} {equation:?}: theory {theory:.6}, theory(N) {at_detection:.6}, measured {measured:.6}"
            );
            assert!(
                ((measured - at_detection) / at_detection).abs() < 1e-4,
                "{name} {equation:?}: measured {measured} vs theory(N) {at_detection}"
            );
            if ((at_detection - theory) / theory).abs() >= 0.01 {
                // Growth too weak beyond the strict limit for the test to see (measured on the
                // imaginary axis below, where these cases are).
                assert_eq!(equation, TestEquation::Oscillator, "{name}");
                assert!(measured > theory);
                let beyond = r.eval(Complex::new(0.0, 1.01 * theory)).norm() - 1.0;
                assert!(TEST.steps_to_detect(beyond) > TEST.steps, "{beyond}");
                weak.push(format!("{name} {equation:?}"));
            } else {
                assert!(
                    ((measured - theory) / theory).abs() < 0.01,
                    "{name} {equation:?}: measured {measured} vs theory {theory}"
                );
                checked += 1;
            }
        }
    }
    // euler, midpoint (real); rk4, bs32, dop853 (both); dopri5 and Verner's four (real;
    // 7(6) and 8(7) have no interval on the imaginary axis).
    assert_eq!(checked, 13);
    assert_eq!(
        weak,
        ["dp54 Oscillator", "vern6 Oscillator", "vern9 Oscillator"],
        "the imaginary-axis limits where the growth beyond is too weak to see"
    );
    for mut method in [
        Box::new(SymplecticEuler::new()) as Box<dyn Integrator>,
        Box::new(StormerVerlet::new()),
    ] {
        let measured = measured_limit(method.as_mut(), TestEquation::Oscillator, &TEST, 1e-5)
            .unwrap()
            .unwrap();
        let at_detection = partitioned_oscillator_growth_limit(detected);
        println!(
            "{}: theory 2, theory(N) {at_detection:.6}, measured {measured:.6}",
            method.name()
        );
        assert!(
            (measured - 2.0).abs() < 0.02,
            "{}: {measured}",
            method.name()
        );
    }
}

/// Known closed forms of the theory: RK4 `2√2` and `2.785293563…` (the real root of
/// `R(−x) = −1`), Bogacki–Shampine `√3`, explicit Euler real `2`, and the empty imaginary
/// intervals of explicit Euler and midpoint. To 1e-9: the bisection refines to rounding.
#[test]
fn stability_polynomials_give_the_textbook_intervals() {
    let rk4 = StabilityPolynomial::of_tableau(&Tableau::rk4());
    assert!((rk4.imaginary_axis_limit() - 8f64.sqrt()).abs() < 1e-9);
    assert!((rk4.real_axis_limit() - 2.785_293_563_405_282).abs() < 1e-9);
    let bs32 = StabilityPolynomial::of_tableau(&Tableau::bs32());
    assert!((bs32.imaginary_axis_limit() - 3f64.sqrt()).abs() < 1e-9);
    for tableau in [Tableau::euler(), Tableau::midpoint()] {
        let r = StabilityPolynomial::of_tableau(&tableau);
        assert_eq!(r.imaginary_axis_limit(), 0.0, "{}", tableau.name());
        assert!((r.real_axis_limit() - 2.0).abs() < 1e-9);
    }
    // DOP853 is of order 8: rₖ = 1/k! for k ≤ 8, and not for k = 9.
    let dop853 = StabilityPolynomial::of_method(&mut DormandPrince853::new(), 12).unwrap();
    assert_eq!(dop853.order(), 8);
}

/// The polynomial from each tableau equals the one read off a step of its implementation
/// (to 1e-14: a few roundings of coefficients of size ≤ 1), so the measured limits test the
/// implemented methods.
#[test]
fn tableau_polynomials_match_the_implementations() {
    for (tableau, mut method) in explicit_tableau_methods() {
        let from_tableau = StabilityPolynomial::of_tableau(&tableau);
        let stepped =
            StabilityPolynomial::of_method(method.as_mut(), tableau.num_stages()).unwrap();
        for (a, b) in from_tableau
            .coefficients()
            .iter()
            .zip(stepped.coefficients())
        {
            assert!((a - b).abs() < 1e-14, "{}: {a} vs {b}", tableau.name());
        }
    }
}

/// Explicit Euler and midpoint have no stable `hω > 0` on the oscillator, and Verner 7(6) and
/// 8(7) none near 0: their measured per-step amplification over 50 steps equals
/// `|R(ihω)| > 1` (`√(1 + θ²)`, `√(1 + θ⁴/4)` for the first two; for Verner's, 1 + 1.7e-9 and
/// 1 + 5.4e-7 at 0.5 and 1 for 7(6), 1 + 6.7e-9 and 1 + 9.9e-7 at 1 and 2 for 8(7), where
/// their growth is large enough for the bound to resolve) to 1e-12 relative (the step matrix
/// is `|R|` times a rotation, so the only error is rounding, ~ε per step, and the 50th root
/// divides it by 50). (Verner 7(6) is stable again at 2, `|R| = 1 − 1.5e-5`.)
#[test]
fn methods_without_an_imaginary_interval_amplify_by_their_stability_function() {
    for (tableau, mut method, steps) in [
        (
            Tableau::euler(),
            Box::new(ExplicitEuler::new()) as Box<dyn Integrator>,
            &[0.1, 0.5, 1.0, 2.0][..],
        ),
        (
            Tableau::midpoint(),
            Box::new(ExplicitMidpoint::new()),
            &[0.1, 0.5, 1.0, 2.0],
        ),
        (Tableau::vern7(), Box::new(Verner76::new()), &[0.5, 1.0]),
        (Tableau::vern8(), Box::new(Verner87::new()), &[1.0, 2.0]),
    ] {
        let r = StabilityPolynomial::of_tableau(&tableau);
        for &h in steps {
            let measured = amplification(method.as_mut(), TestEquation::Oscillator, h, 50).unwrap();
            let theory = r.eval(Complex::new(0.0, h)).norm();
            assert!(theory > 1.0);
            assert!(
                (measured / theory - 1.0).abs() < 1e-12,
                "{} at {h}: {measured} vs {theory}",
                tableau.name()
            );
        }
    }
}

/// Implicit midpoint and Radau IIA are A-stable: at `hω = 10, 100, 1000` the amplitude after
/// 200 steps has not grown (implicit midpoint keeps it to 1e-7: 200 steps of Newton iterations
/// stopped at 1e-10 relative, with a factor 5 to spare; Radau's decays), and Radau's per-step amplification over 3 steps is
/// the Padé `|R(ihω)| ≈ 3/(hω)` to 1e-8 relative (L-stable: it damps the unresolved
/// oscillation).
#[test]
fn implicit_methods_are_stable_at_large_steps() {
    let mut midpoint = ImplicitMidpoint::new().with_newton_tolerance(1e-10);
    let mut radau = RadauIIA5::new();
    for h in [10.0, 100.0, 1000.0] {
        let norm = TestEquation::Oscillator
            .final_norm(&mut midpoint, h, 200)
            .unwrap();
        assert!(
            (norm - 1.0).abs() < 1e-7,
            "implicit midpoint at {h}: {norm}"
        );
        let norm = TestEquation::Oscillator
            .final_norm(&mut radau, h, 200)
            .unwrap();
        assert!(norm < 1e-10, "radau5 at {h}: {norm}");
        let measured = amplification(&mut radau, TestEquation::Oscillator, h, 3).unwrap();
        let theory = radau_iia5_stability(Complex::new(0.0, h)).norm();
        assert!(
            (measured / theory - 1.0).abs() < 1e-8,
            "{measured} vs {theory}"
        );
    }
}

/// Radau IIA on the stiff spring (HW9's free two-mass spring: the chain with `k1 = 0`,
/// `m1 = m2 = 1 kg`, `F0 = 1 N`, `k/m = 10⁶`, started at the equilibrium stretch so that the stiff mode, `ω = 1414 rad/s`, is not excited): at
/// `rtol = atol = 1e-6` over 1 s it matches DOP853 at 1e-12 in the positions to 1e-6 (the
/// tolerance; observed ~1e-14) and in the velocities to 1e-5, with at least 10× fewer steps
/// than Dormand–Prince 5(4), whose steps stability bounds (`hω ≲ 1`–`3.3`).
#[test]
fn radau_on_the_stiff_spring_matches_dop853_with_ten_times_fewer_steps() {
    let mut model = boxed(TwoMassChain {
        m1: 1.0,
        m2: 1.0,
        k1: 0.0,
        k2: 1e6,
        f0: 1.0,
        ..TwoMassChain::default()
    });
    let mut y0 = model.initial_state();
    // F₀ m₁/(k (m₁ + m₂)) with m₁ = m₂ = 1 kg, F₀ = 1 N: the static stretch of the spring.
    y0[1] += 1.0 / 2e6;
    let times: Vec<f64> = (1..=20).map(|i| f64::from(i) / 20.0).collect();
    let output = OutputTimes::At(times);
    let mut run = |method: &mut dyn Integrator, tol: f64| {
        let options = IntegratorOptions::default()
            .with_rtol(tol)
            .with_atol(tol)
            .with_max_steps(1_000_000);
        method
            .integrate(model.as_ode_mut(), 0.0, &y0, 1.0, &output, &options)
            .unwrap()
    };
    let reference = run(&mut DormandPrince853::new(), 1e-12);
    let radau = run(&mut RadauIIA5::new(), 1e-6);
    let dopri5 = run(&mut DormandPrince54::new(), 1e-6);
    let mut position_error: f64 = 0.0;
    let mut velocity_error: f64 = 0.0;
    for ((_, y), (_, r)) in radau.iter().zip(reference.iter()) {
        position_error = position_error
            .max((y[0] - r[0]).abs())
            .max((y[1] - r[1]).abs());
        velocity_error = velocity_error
            .max((y[2] - r[2]).abs())
            .max((y[3] - r[3]).abs());
    }
    println!(
        "radau5 {} steps, dopri5 {} steps, reference {} steps; radau position error {position_error:.2e} m, velocity {velocity_error:.2e} m/s",
        radau.stats.steps, dopri5.stats.steps, reference.stats.steps
    );
    assert!(position_error < 1e-6);
    assert!(velocity_error < 1e-5);
    assert!(10 * radau.stats.steps <= dopri5.stats.steps);
}

/// `euler_roundoff` with `max_n = 6`: the error of explicit Euler falls with slope 1
/// per decade of `h` (`≈ e h/2 (1 − 11h/12)`: the ratio of successive errors is 10 to within
/// 2 % for n = 2 … 6, the `O(h)` relative correction being 0.9 % at n = 2, 8 % at n = 1,
/// which is left out); the truncation column matches `e h/2` to 2 % at n ≥ 2; RK4's error has its minimum inside the range (truncation
/// `e h⁴/120` meets roundoff near n = 3 … 6) and rises after it by more than 10× at
/// some n (roundoff).
#[test]
fn euler_roundoff_study_shows_truncation_and_roundoff() {
    let study = euler_roundoff(&RoundoffOptions { max_n: 6 }).unwrap();
    let rows = &study.rows;
    assert_eq!(rows.len(), 7);
    let error = |n: usize, method: usize| rows[n].runs[method].error;
    for (n, row) in rows.iter().enumerate().take(6).skip(2) {
        let ratio = error(n, 0) / error(n + 1, 0);
        assert!((ratio / 10.0 - 1.0).abs() < 0.02, "n = {n}: {ratio}");
        let truncation = row.runs[0].truncation;
        assert!((truncation / (-E * row.h / 2.0) - 1.0).abs() < 0.02);
    }
    let rk4 = study.summary.iter().find(|s| s.method == "rk4").unwrap();
    assert!(rk4.first_n_at_rounding_level.unwrap() <= 4, "{rk4:?}");
    let single = |n: usize| rows[n].single_precision_euler.error.abs();
    let optimum = (0..=6)
        .min_by(|&a, &b| single(a).total_cmp(&single(b)))
        .unwrap();
    assert!((4..=5).contains(&optimum), "{optimum}");
    assert!(single(6) > 2.0 * single(optimum));
    assert!(!study.notes.is_empty());
}

/// Heavier: the full default range in release, with Euler's roundoff growing.
/// `cargo test -p eomgen-runtime --release --test suite -- stability:: --ignored`.
#[test]
#[ignore = "10⁸ steps per method; run in release"]
fn euler_roundoff_full_range() {
    let rows = euler_roundoff(&RoundoffOptions { max_n: 8 }).unwrap().rows;
    // Euler's roundoff at n = 8 (1e-12 observed) exceeds its value at n = 4 (1e-15).
    let roundoff = |n: usize| rows[n].runs[0].roundoff.abs();
    assert!(roundoff(8) > 10.0 * roundoff(4));
}

/// The stability study with small sizes, the free two-mass chain (`k1 = 0`, `F0 = 1 N`) its
/// stiff model: the limits within 1 % of theory where the run length resolves 1 % (see
/// `explicit_stability_limits_match_theory_to_one_percent`), and against their closed forms
/// (RK4 `2√2` on the imaginary axis and the root `2.7853` of `|R(−x)| = 1` on the real one,
/// explicit Euler 2 on the real axis, Störmer–Verlet `hω = 2`) to 1 %; the energy failure of
/// Euler at `h = T/32` is not hidden (1200 periods overflow it: 1 + h² per step); the stiff
/// rows, with each stiff mode's `ω = √(k (m1 + m2)/(m1 m2))` equal to the non-zero natural
/// frequency of `modal_analysis` of the same chain (1e-12); the blow-up of `ẏ = y²` reported
/// with its `t` within 1e-3 of 1.
#[test]
fn stability_study_through_the_library() {
    let chain = TwoMassChain {
        k1: 0.0,
        f0: 1.0,
        ..TwoMassChain::default()
    };
    let mut model = boxed(chain.clone());
    let options = StabilityOptions {
        steps: 2000,
        periods: 1200,
        stiffness: vec![1e2, 1e4],
        stiff_spring: StiffSpring {
            stiffness: "k2".into(),
            ..StiffSpring::default()
        },
        ..StabilityOptions::default()
    };
    let study = stability_study(model.as_mut(), &options).unwrap();
    // Both axes for the explicit methods with an interval on the imaginary axis (RK4,
    // BS32, DP5(4), DOP853 and two of the Verner pairs), the real axis alone for the other
    // four, the imaginary axis for each of the 2 partitioned methods.
    assert_eq!(study.limits.rows.len(), 18);
    for r in &study.limits.rows {
        let resolved = r.steps_needed_one_percent_above <= r.steps_used;
        let d = r.relative_difference.unwrap();
        assert!(!resolved || d.abs() < 0.01, "{r:?}");
    }
    let euler = &study.energy[0];
    assert_eq!(euler.method, "euler");
    let failure = euler.failure.as_ref().expect("Euler overflows");
    assert!(failure.error.contains("not finite"), "{}", failure.error);
    assert!(failure.t.unwrap() > 0.0);
    assert!(euler.final_energy_ratio.is_none());
    assert_eq!(study.stiff.len(), 2 * 2 * 4);
    for (method, axis, limit) in [
        ("rk4", "imaginary", 2.0 * 2f64.sqrt()),
        ("rk4", "real", 2.785_293_563_405_282),
        ("euler", "real", 2.0),
        ("stormer-verlet", "imaginary", 2.0),
    ] {
        let row = study
            .limits
            .rows
            .iter()
            .find(|r| r.method == method && r.axis == axis)
            .unwrap_or_else(|| panic!("no {method} row on the {axis} axis"));
        let measured = row.measured.expect("a measured limit");
        assert!(
            (measured - limit).abs() < 0.01 * limit,
            "{method} {axis}: {measured} vs {limit}"
        );
    }
    assert_eq!(study.stiff_modes.len(), 2 * 2);
    for mode in &study.stiff_modes {
        let unloaded = TwoMassChain {
            k2: mode.k_over_m * chain.m1,
            f0: 0.0,
            ..chain.clone()
        };
        let modal = modal_analysis(boxed(unloaded).as_ref(), &ModalOptions::default()).unwrap();
        assert_eq!(modal.normal_modes.kinds[0], ModeKind::ZeroFrequency);
        let omega = modal.normal_modes.natural_frequencies[1];
        assert!(
            (mode.omega - omega).abs() < 1e-12 * omega,
            "{} vs {omega}",
            mode.omega
        );
    }
    let underflow = study.underflow.failure.as_ref().expect("underflow");
    assert!(underflow.error.contains("step size"), "{}", underflow.error);
    assert!((underflow.t.unwrap() - 1.0).abs() < 1e-3);
}

/// The stiff model's names come from the options (the library names no model): a name the
/// model lacks is an error naming the model, the name and its role.
#[test]
fn the_stiff_spring_names_come_from_the_options() {
    let mut pendulum = boxed(Pendulum::default());
    let options = StabilityOptions {
        steps: 200,
        periods: 2,
        stiffness: vec![1e2],
        ..StabilityOptions::default()
    };
    let error = stability_study(pendulum.as_mut(), &options)
        .err()
        .expect("the pendulum has no m1");
    assert!(
        matches!(&error, StabilityError::MissingParameter { model, name, .. } if model == "pendulum" && name == "m1"),
        "{error}"
    );
    let mut two_masses = boxed(TwoMassChain {
        k1: 0.0,
        ..TwoMassChain::default()
    });
    let options = StabilityOptions {
        stiff_spring: StiffSpring {
            stiffness: "k2".to_string(),
            stretched: "x3".to_string(),
            ..StiffSpring::default()
        },
        ..options
    };
    let error = stability_study(two_masses.as_mut(), &options)
        .err()
        .expect("no x3");
    assert_eq!(
        error.to_string(),
        "the stiff model `two_mass_chain` has no coordinate `x3` (its stretched coordinate)"
    );
}
