//! `study expm` (HW32) and `study rayleigh` (lectures 35–37): the routes against each other
//! and against closed forms written here, the refusals, and the commands.

use crate::common;
use common::{eomgen, eomgen_ok, seeded_rng};

use eomgen::ModelInfo;
use eomgen::analysis::vibration::{
    EigenvectorOutcome, ExpmOptions, ExpmRoute, ExpmStudyError, PerturbationDirection,
    RayleighError, RayleighOptions, eigenvector_condition, expm_study, expm_study_of,
    random_problem, rayleigh_study,
};
use eomgen::nalgebra::{DMatrix, DVector};
use rand::RngExt;

fn model(name: &str) -> Box<dyn ModelInfo> {
    (eomgen::models::find(name).expect("bundled model").make)()
}

fn grid(t_end: f64, samples: usize) -> Vec<f64> {
    (0..samples)
        .map(|i| t_end * i as f64 / (samples - 1) as f64)
        .collect()
}

/// The largest `|z − exact(t)|` of `states` at `times`.
fn max_error(times: &[f64], states: &[Vec<f64>], exact: impl Fn(f64) -> Vec<f64>) -> f64 {
    times
        .iter()
        .zip(states)
        .flat_map(|(&t, z)| {
            let e = exact(t);
            z.iter()
                .zip(e)
                .map(|(a, b)| (a - b).abs())
                .collect::<Vec<_>>()
        })
        .fold(0.0, f64::max)
}

/// HW32 on six seeds: e^{At} z₀, the eigenvector superposition and DOP853 at 1e-13 agree,
/// exponential against eigenvectors to 1e-11 of the solution's scale (both exact up to
/// rounding times κ(V) ≲ 20; measured ≤ 7e-14), the integration to 1e-9 (measured ≤ 2e-13 on
/// seeds 1–12 over 5 s); the study's own verdict agrees.
#[test]
fn expm_routes_agree_for_several_seeds() {
    for seed in 1..=6 {
        let study = expm_study(&ExpmOptions {
            seed,
            ..ExpmOptions::default()
        })
        .unwrap();
        assert_eq!(study.eigenvalues.len(), 10);
        assert_eq!(
            study.differences.len(),
            3,
            "seed {seed}: a route is missing"
        );
        for d in &study.differences {
            let bound = if d.a == ExpmRoute::Integration || d.b == ExpmRoute::Integration {
                1e-9
            } else {
                1e-11
            };
            assert!(d.relative < bound, "seed {seed}: {d:?}");
            assert!(d.passed, "seed {seed}: {d:?}");
        }
        let kappa = study.eigenvector_condition.unwrap();
        assert!((1.0..1e4).contains(&kappa), "seed {seed}: κ = {kappa}");
        // The eigenvalues are those of A: det(A − λI) ≈ 0 relative to the scale, checked as
        // the smallest singular value of A − λI.
        let a = &study.state_matrix;
        for l in &study.eigenvalues {
            let shifted =
                a.map(|v| eomgen::nalgebra::Complex::new(v, 0.0)) - DMatrix::identity(10, 10) * *l;
            assert!(shifted.svd(false, false).singular_values.min() < 1e-12);
        }
    }
}

/// The default scaling `Aᵢⱼ ~ N(0, 1)/√n` puts the spectrum in about the unit disc (the
/// circular law): the spectral radius of eight 60 × 60 draws lies in [0.8, 1.3] (measured
/// 1.00–1.17), and the draws are reproducible and different per seed.
#[test]
fn random_problem_is_scaled_and_reproducible() {
    for seed in 0..8 {
        let p = random_problem(60, seed);
        let radius = p
            .state_matrix
            .complex_eigenvalues()
            .iter()
            .fold(0.0f64, |m, l| m.max(l.norm()));
        eprintln!("seed {seed}: spectral radius {radius:.3}");
        assert!((0.8..1.3).contains(&radius), "seed {seed}: {radius}");
        assert_eq!(p, random_problem(60, seed));
        let norm: f64 = p.initial_state.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-14);
    }
    assert_ne!(random_problem(10, 1), random_problem(10, 2));
}

/// Closed forms: the rotation ż = [[0, ω], [−ω, 0]] z is z(t) = (x₀ cos ωt + y₀ sin ωt,
/// −x₀ sin ωt + y₀ cos ωt); the damped oscillator ẍ + 2ζω ẋ + ω² x = 0 (ζ = 0.1, ω = 3) is
/// x = e^{−ζωt}(x₀ cos ω_d t + (v₀ + ζω x₀)/ω_d sin ω_d t). The exact routes match to 1e-13
/// (rounding of a few operations on O(1) values), DOP853 at 1e-13 to 1e-11.
#[test]
fn two_by_two_matches_closed_forms() {
    let times = grid(10.0, 41);
    let omega = 1.7;
    let rotation = DMatrix::from_row_slice(2, 2, &[0.0, omega, -omega, 0.0]);
    let (x0, y0) = (0.6, -0.8);
    let exact_rotation = |t: f64| {
        let (s, c) = (omega * t).sin_cos();
        vec![x0 * c + y0 * s, -x0 * s + y0 * c]
    };
    let (zeta, w) = (0.1, 3.0);
    let wd = w * (1.0f64 - zeta * zeta).sqrt();
    let damped = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -w * w, -2.0 * zeta * w]);
    let (p0, v0) = (1.0, 0.5);
    let exact_damped = |t: f64| {
        let (s, c) = (wd * t).sin_cos();
        let e = (-zeta * w * t).exp();
        let b = (v0 + zeta * w * p0) / wd;
        let x = e * (p0 * c + b * s);
        let v = e * (-zeta * w * (p0 * c + b * s) + (-p0 * wd * s + b * wd * c));
        vec![x, v]
    };
    for (a, z0, exact) in [
        (
            &rotation,
            [x0, y0],
            &exact_rotation as &dyn Fn(f64) -> Vec<f64>,
        ),
        (&damped, [p0, v0], &exact_damped),
    ] {
        let study = expm_study_of(a, &z0, &times, 1e-13).unwrap();
        assert!(study.passed());
        let e = max_error(&times, &study.exponential, exact);
        assert!(e < 1e-13, "exponential {e:e}");
        let e = max_error(
            &times,
            study.states(ExpmRoute::Eigenvectors).unwrap(),
            exact,
        );
        assert!(e < 1e-13, "eigenvectors {e:e}");
        let e = max_error(&times, &study.integration, exact);
        assert!(e < 1e-11, "integration {e:e}");
        // A normal matrix (the rotation) has orthogonal eigenvectors, κ = 1.
        if a == &rotation {
            assert!((study.eigenvector_condition.unwrap() - 1.0).abs() < 1e-12);
        }
    }
}

/// A defective A (a 3 × 3 Jordan block, λ = −0.5): the eigenvector route reports the problem
/// instead of a number, κ(V) is reported as infinite (None), and the two other routes match
/// the closed form e^{λt}(I + tN + t²N²/2) z₀ (to 1e-13 and 1e-11).
#[test]
fn jordan_block_is_refused_by_the_eigenvector_route() {
    let lambda = -0.5;
    let a = DMatrix::from_row_slice(
        3,
        3,
        &[lambda, 1.0, 0.0, 0.0, lambda, 1.0, 0.0, 0.0, lambda],
    );
    let z0 = [0.3, -0.2, 1.0];
    let times = grid(8.0, 33);
    let study = expm_study_of(&a, &z0, &times, 1e-13).unwrap();
    assert!(
        matches!(&study.eigenvectors, EigenvectorOutcome::Refused { reason } if reason.contains("defective")),
        "{:?}",
        study.eigenvectors
    );
    assert_eq!(study.eigenvector_condition, None);
    assert_eq!(study.differences.len(), 1);
    assert!(study.passed());
    let exact = |t: f64| {
        let e = (lambda * t).exp();
        vec![
            e * (z0[0] + t * z0[1] + t * t / 2.0 * z0[2]),
            e * (z0[1] + t * z0[2]),
            e * z0[2],
        ]
    };
    assert!(max_error(&times, &study.exponential, exact) < 1e-13);
    assert!(max_error(&times, &study.integration, exact) < 1e-11);
}

/// A nearly defective A = [[−1, 1], [0, −1 − δ]]: eigenvectors (1, 0) and (1, −δ)/√(1 + δ²),
/// so with c = 1/√(1 + δ²) the unit-column V has κ = √((1 + c)/(1 − c)) ≈ 2/δ, matched to
/// 1e-6 relative (the computed vectors carry ~ε/δ error). The route's error stays within its
/// bound 100 κ ε; past κ = 1e6 the route refuses.
#[test]
fn near_defective_condition_number_matches_closed_form() {
    for delta in [1e-2f64, 1e-4, 1e-5] {
        let a = DMatrix::from_row_slice(2, 2, &[-1.0, 1.0, 0.0, -1.0 - delta]);
        let c = 1.0 / (1.0 + delta * delta).sqrt();
        let expected = ((1.0 + c) / (1.0 - c)).sqrt();
        let study = expm_study_of(&a, &[0.4, 0.9], &grid(5.0, 11), 1e-13).unwrap();
        let kappa = study.eigenvector_condition.unwrap();
        assert!(
            (kappa / expected - 1.0).abs() < 1e-6,
            "δ = {delta}: κ = {kappa}, expected {expected}"
        );
        assert!(study.passed(), "δ = {delta}: {:?}", study.differences);
    }
    let a = DMatrix::from_row_slice(2, 2, &[-1.0, 1.0, 0.0, -1.0 - 1e-7]);
    let study = expm_study_of(&a, &[0.4, 0.9], &grid(5.0, 11), 1e-13).unwrap();
    assert!(matches!(
        study.eigenvectors,
        EigenvectorOutcome::Refused { .. }
    ));
    // A diagonalizable matrix with a repeated eigenvalue (2 I) is not defective: κ = 1.
    let kappa = eigenvector_condition(
        &(DMatrix::identity(3, 3) * 2.0),
        &[eomgen::nalgebra::Complex::new(2.0, 0.0); 3],
    )
    .unwrap();
    assert!((kappa - 1.0).abs() < 1e-12);
}

#[test]
fn expm_refuses_bad_input() {
    let bad = |options: ExpmOptions| expm_study(&options).unwrap_err();
    assert!(matches!(
        bad(ExpmOptions {
            n: 0,
            ..ExpmOptions::default()
        }),
        ExpmStudyError::InvalidSize { .. }
    ));
    assert!(matches!(
        bad(ExpmOptions {
            matrix: Some(vec![vec![1.0, 2.0], vec![3.0]]),
            ..ExpmOptions::default()
        }),
        ExpmStudyError::MatrixNotSquare { row: 2, .. }
    ));
    assert!(matches!(
        bad(ExpmOptions {
            t_end: f64::NAN,
            ..ExpmOptions::default()
        }),
        ExpmStudyError::InvalidEndTime { .. }
    ));
    let a = DMatrix::identity(2, 2);
    assert!(matches!(
        expm_study_of(&a, &[0.0, 0.0], &[0.0, 1.0], 1e-13),
        Err(ExpmStudyError::ZeroSolution)
    ));
    assert!(matches!(
        expm_study_of(&a, &[1.0], &[0.0, 1.0], 1e-13),
        Err(ExpmStudyError::DimensionMismatch { .. })
    ));
    assert!(matches!(
        expm_study_of(&a, &[1.0, 0.0], &[0.0, 1.0], 0.0),
        Err(ExpmStudyError::InvalidTolerance { .. })
    ));
}

/// string_chain (N = 8, its file: ω_k = 18 sin(kπ/18)): the exact first mode shape
/// sin(iπ/9) gives √R = ω₁ to rounding (1e-14 relative); the parabola x(L − x), i.e.
/// i(9 − i), gives the file's R = 10 c²/(L² + a²) = 810/82 (to 1e-13) and its relative error
/// √R/ω₁ − 1 = 0.55 %.
#[test]
fn string_chain_sine_is_exact_and_parabola_has_the_documented_error() {
    let chain = model("string_chain");
    let omega1 = 18.0 * (std::f64::consts::PI / 18.0).sin();
    let sine: Vec<f64> = (1..=8)
        .map(|i| (std::f64::consts::PI * i as f64 / 9.0).sin())
        .collect();
    let study = rayleigh_study(chain.as_ref(), &RayleighOptions::new(sine)).unwrap();
    assert!((study.natural_frequency / omega1 - 1.0).abs() < 1e-14);
    assert!(
        (study.frequency_estimate / omega1 - 1.0).abs() < 1e-14,
        "{}",
        study.frequency_estimate
    );
    assert!(study.shape_error.unwrap() < 1e-14);
    assert!(study.bound_holds);
    // v is ψ₁: the stationarity test perturbs along the next mode, ω₂² = (18 sin(2π/18))².
    let s = study.stationarity.unwrap();
    assert_eq!(s.direction, PerturbationDirection::NextMode);
    let omega2 = 18.0 * (2.0 * std::f64::consts::PI / 18.0).sin();
    assert!((s.direction_quotient / (omega2 * omega2) - 1.0).abs() < 1e-13);

    let parabola: Vec<f64> = (1..=8).map(|i| (i * (9 - i)) as f64).collect();
    let study = rayleigh_study(chain.as_ref(), &RayleighOptions::new(parabola)).unwrap();
    let expected = 810.0 / 82.0;
    assert!((study.rayleigh_quotient / expected - 1.0).abs() < 1e-13);
    let error = expected.sqrt() / omega1 - 1.0;
    assert!((study.relative_error - error).abs() < 1e-13);
    assert!((study.relative_error - 0.005525).abs() < 1e-6);
}

/// R ≥ ω₁² for 200 random shapes on string_chain and three_masses (up to 1e-13 of ω_max²:
/// rounding), R ≤ ω_max², and R equals the modal average Σ ω_k² η_k² / Σ η_k², η = ΨᵀMv,
/// computed here from the modal analysis (to 1e-12 relative).
#[test]
fn rayleigh_bounds_hold_for_random_shapes() {
    let mut rng = seeded_rng(35);
    for name in ["string_chain", "three_masses"] {
        let m = model(name);
        let n = m.num_dofs();
        for _ in 0..100 {
            let shape: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let study = rayleigh_study(m.as_ref(), &RayleighOptions::new(shape.clone())).unwrap();
            let w2 = &study.normal_modes.eigenvalues;
            let (w1, wmax) = (w2[0], w2[n - 1]);
            assert!(study.rayleigh_quotient >= w1 - 1e-13 * wmax, "{name}");
            assert!(study.rayleigh_quotient <= wmax * (1.0 + 1e-13), "{name}");
            assert!(study.bound_holds && study.relative_error >= -1e-13);
            let mass = &study.linearization.mass_matrix;
            let eta = study.normal_modes.mode_shapes.transpose()
                * (mass * DVector::from_column_slice(&shape));
            let average =
                eta.iter().zip(w2).map(|(e, w)| w * e * e).sum::<f64>() / eta.norm_squared();
            assert!((study.rayleigh_quotient / average - 1.0).abs() < 1e-12);
        }
    }
}

/// three_masses (m = k = 1): the exact ψ₁ ∝ (1, √2, 1) gives √R = √(2 − √2) to 1e-15; the
/// uniform shape gives R = 2/3; its stationarity samples match the closed form
/// ε² (R(w) − ω₁²)/(1 + ε²) to 1e-8 relative and the fitted order is 2 within 0.01 (the
/// (1 + ε²) factor moves it by ~ε²).
#[test]
fn three_masses_rayleigh() {
    let m = model("three_masses");
    let omega1 = (2.0 - 2f64.sqrt()).sqrt();
    let exact = RayleighOptions::new(vec![1.0, 2f64.sqrt(), 1.0]);
    let study = rayleigh_study(m.as_ref(), &exact).unwrap();
    assert!((study.frequency_estimate - omega1).abs() < 1e-15);
    let study = rayleigh_study(m.as_ref(), &RayleighOptions::new(vec![1.0; 3])).unwrap();
    assert!((study.rayleigh_quotient - 2.0 / 3.0).abs() < 1e-15);
    let s = study.stationarity.unwrap();
    assert_eq!(s.direction, PerturbationDirection::ShapeError);
    // The uniform shape's error lies in mode 3 alone (mode 2 is antisymmetric): R(w) = ω₃².
    assert!((s.direction_quotient - (2.0 + 2f64.sqrt())).abs() < 1e-13);
    for p in &s.samples {
        assert!((p.excess / p.predicted_excess - 1.0).abs() < 1e-8, "{p:?}");
    }
    assert!((s.fitted_order.unwrap() - 2.0).abs() < 0.01);
}

/// A free structure (spring_line_three, HW31: ω² = 0, k/m, 3k/m): the translation is
/// projected out of (1, 2, 3), leaving (−1, 0, 1), the k/m mode itself, so √R = 1 rad/s to
/// rounding; a pure translation is refused; so are a zero shape, a wrong count, a non-finite
/// entry, a constrained model and an unstable equilibrium.
#[test]
fn rayleigh_zero_modes_and_refusals() {
    let line = model("spring_line_three");
    let study = rayleigh_study(line.as_ref(), &RayleighOptions::new(vec![1.0, 2.0, 3.0])).unwrap();
    assert_eq!(study.zero_modes_removed, 1);
    assert_eq!(study.lowest_mode, 2);
    for (a, b) in study.projected_shape.iter().zip([-1.0, 0.0, 1.0]) {
        assert!((a - b).abs() < 1e-14);
    }
    assert!((study.frequency_estimate - 1.0).abs() < 1e-14);
    let err =
        |m: &dyn ModelInfo, options: RayleighOptions| rayleigh_study(m, &options).unwrap_err();
    assert!(matches!(
        err(line.as_ref(), RayleighOptions::new(vec![2.0; 3])),
        RayleighError::OnlyZeroModes { count: 1, .. }
    ));
    let three = model("three_masses");
    assert!(matches!(
        err(three.as_ref(), RayleighOptions::new(vec![0.0; 3])),
        RayleighError::ZeroShape
    ));
    assert!(matches!(
        err(three.as_ref(), RayleighOptions::new(vec![1.0; 2])),
        RayleighError::DimensionMismatch {
            expected: 3,
            found: 2,
            ..
        }
    ));
    assert!(matches!(
        err(
            three.as_ref(),
            RayleighOptions::new(vec![1.0, f64::NAN, 1.0])
        ),
        RayleighError::NonFinite { index: 2, .. }
    ));
    assert!(matches!(
        err(
            model("simple_pendulum_cartesian").as_ref(),
            RayleighOptions::new(vec![1.0; 2])
        ),
        RayleighError::Constrained { .. }
    ));
    let pendulum = model("simple_pendulum");
    let upright = RayleighOptions {
        operating_point: eomgen::analysis::vibration::OperatingPointOptions {
            start: eomgen::analysis::vibration::EquilibriumStart::Named("upright".into()),
            ..Default::default()
        },
        ..RayleighOptions::new(vec![1.0])
    };
    assert!(matches!(
        err(pendulum.as_ref(), upright),
        RayleighError::Unstable { mode: 1, .. }
    ));
}

/// The commands: `--shape` as an expression of i and n, as a list, with a wrong count (usage,
/// exit 2); `study expm` exits 0 with all three routes, and reports a Jordan block's refusal.
#[test]
fn commands() {
    let out = eomgen_ok(&[
        "study",
        "rayleigh",
        "string_chain",
        "--shape",
        "sin(pi*i/(n+1))",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let omega1 = 18.0 * (std::f64::consts::PI / 18.0).sin();
    assert!((v["frequency_estimate"].as_f64().unwrap() / omega1 - 1.0).abs() < 1e-14);
    assert!(v["bound_holds"].as_bool().unwrap());
    let out = eomgen_ok(&["study", "rayleigh", "three_masses", "--shape", "1, 1, k/m"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("0.6666666666667 1/s²"), "{text}");
    let out = eomgen(&["study", "rayleigh", "three_masses", "--shape", "1,2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("has 3 coordinates"));
    let out = eomgen(&["study", "rayleigh", "three_masses", "--shape", "j"]);
    assert_eq!(out.status.code(), Some(2));

    let out = eomgen_ok(&["study", "expm", "--seed", "3", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["differences"].as_array().unwrap().len(), 3);
    assert_eq!(v["eigenvalues"].as_array().unwrap().len(), 10);
    let out = eomgen_ok(&["study", "expm", "--matrix", "-1,1;0,-1", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["eigenvectors"]["status"], "refused");
    assert!(v["eigenvector_condition"].is_null());
    let out = eomgen(&["study", "expm", "--matrix", "1,2;3"]);
    assert_eq!(out.status.code(), Some(2));
}

/// `R(v)` does not depend on the shape's scale: `(1, 1, 1)` on three masses gives `2/3`
/// (to 1e-13, as at scale 1) at 1e300 and 1e-300 too — not NaN (and a failed bound) from
/// overflowing `vᵀKv`, nor a zero shape from underflowing `vᵀMv`; the forms scale by the
/// square of the scale (checked where it is representable) and the projected shape by the
/// scale.
#[test]
fn rayleigh_quotient_is_independent_of_the_shape_scale() {
    let masses = model("three_masses");
    let unit = rayleigh_study(masses.as_ref(), &RayleighOptions::new(vec![1.0; 3])).unwrap();
    for scale in [1e300, 1e-300, -3.5] {
        let study = rayleigh_study(masses.as_ref(), &RayleighOptions::new(vec![scale; 3])).unwrap();
        assert!(
            (study.rayleigh_quotient - 2.0 / 3.0).abs() < 1e-13,
            "{scale}: R = {}",
            study.rayleigh_quotient
        );
        assert!(study.bound_holds, "{scale}");
        assert!(
            study.modal_participation.iter().all(|p| p.is_finite()),
            "{scale}: {:?}",
            study.modal_participation
        );
        for (p, u) in study.projected_shape.iter().zip(&unit.projected_shape) {
            assert!((p / scale - u).abs() < 1e-13, "{scale}: {p} vs {u}");
        }
        if (1e-100..1e100).contains(&scale.abs()) {
            // (vᵀMv itself is beyond f64 at 1e±300.)
            assert!(
                (study.mass_form / (scale * scale) - unit.mass_form).abs() < 1e-12 * unit.mass_form
            );
        }
    }
    eomgen_ok(&[
        "study",
        "rayleigh",
        "three_masses",
        "--shape",
        "1e300,1e300,1e300",
    ]);
}

/// With a repeated lowest frequency (the ring of eight springs: `cos(2πi/n)` and
/// `sin(2πi/n)` share `ω₁`), any shape in that eigenspace is a lowest mode: its `tan θ` is 0
/// to rounding (not 1, its angle to the one `ψ₁` the solver returned), and a shape `0.01`
/// off it along a higher mode has `tan θ = 0.01` with `R − ω₁² = tan²θ (R(w) − ω₁²)/(1 +
/// tan²θ)` (1e-9 relative: rounding of the forms).
#[test]
fn rayleigh_shape_error_is_measured_from_a_repeated_lowest_eigenspace() {
    let ring = model("spring_ring");
    let n = ring.num_dofs();
    let tau = std::f64::consts::TAU;
    let shape = |f: &dyn Fn(f64) -> f64| -> Vec<f64> { (1..=n).map(|i| f(i as f64)).collect() };
    let exact = rayleigh_study(
        ring.as_ref(),
        &RayleighOptions::new(shape(&|i| (tau * i / n as f64).cos())),
    )
    .unwrap();
    let w = exact.natural_frequency;
    let repeated = exact
        .normal_modes
        .natural_frequencies
        .iter()
        .filter(|x| (*x - w).abs() < 1e-9 * w)
        .count();
    assert_eq!(repeated, 2, "{:?}", exact.normal_modes.natural_frequencies);
    assert!(
        exact.shape_error.unwrap() < 1e-12,
        "{:?}",
        exact.shape_error
    );
    let off = rayleigh_study(
        ring.as_ref(),
        &RayleighOptions::new(shape(&|i| {
            (tau * i / n as f64).sin() + 0.01 * (2.0 * tau * i / n as f64).cos()
        })),
    )
    .unwrap();
    let tan = off.shape_error.unwrap();
    // The part along cos(4πi/n) over the part along sin(2πi/n): equal norms, so 0.01.
    assert!((tan - 0.01).abs() < 1e-12, "tan θ = {tan}");
    let rw = off.stationarity.as_ref().unwrap().direction_quotient;
    let predicted = tan * tan * (rw - w * w) / (1.0 + tan * tan);
    assert!(
        (off.excess - predicted).abs() < 1e-9 * predicted,
        "{} vs {predicted}",
        off.excess
    );
}

/// The bounds grow with the number of time scales the samples span (`‖A‖_F t`): a rotation
/// followed for 10⁵ s loses about 1e-9 of its size to DOP853's global error at tolerance
/// 1e-12 — an accurate integration, which a fixed bound of 1e-9 would fail — while the bound
/// stays far below an O(1) error, which it still catches.
#[test]
fn expm_bounds_grow_with_the_time_scales_spanned() {
    let rotation = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, 0.0]);
    let times: Vec<f64> = (0..=10).map(|k| 1e4 * k as f64).collect();
    let study = expm_study_of(&rotation, &[1.0, 0.0], &times, 1e-12).unwrap();
    assert!(study.passed(), "{:?}", study.differences);
    for d in &study.differences {
        // ρ(A) t = 1e5 (a rotation: no transient amplification).
        assert!(d.tolerance < 1e-2 && d.relative < 1e-6, "{d:?}");
    }
    // Over 5 s (ρ(A) t = 5) the bounds stay at their base times 5, times the amplification
    // bound √2 (the Frobenius norm of a rotation, an upper bound of its 2-norm 1).
    let short: Vec<f64> = (0..=10).map(|k| 0.5 * k as f64).collect();
    let study = expm_study_of(&rotation, &[1.0, 0.0], &short, 1e-12).unwrap();
    let most = 1e-8 * 5.0 * 2f64.sqrt() * (1.0 + 1e-12);
    assert!(study.differences.iter().all(|d| d.tolerance <= most));
}

/// Issue 49: a strongly non-normal `A = [[1, 1e10], [0, 1]]` (eigenvalues 1, 1: one time
/// scale per second). The bound grew with `‖A‖_F t = 5e10` to 50, which no relative
/// difference can exceed; with `ρ(A) t` and the sampled amplification of `e^{At}` it is
/// 5.6e-9, and the routes agree to 7e-14. A bound of 1e-2 or more is never a pass: with
/// `tol = 1e-5` and a horizon of 5, the integration pair's bound is 0.5, unchecked.
#[test]
fn expm_bounds_are_never_vacuous() {
    let a = DMatrix::from_row_slice(2, 2, &[1.0, 1e10, 0.0, 1.0]);
    let times: Vec<f64> = (0..=20).map(|k| 0.25 * k as f64).collect();
    let study = expm_study_of(&a, &[0.6, 0.8], &times, 1e-13).unwrap();
    assert!(study.passed(), "{:?}", study.differences);
    for d in &study.differences {
        assert!(d.checked && d.tolerance < 1e-7, "{d:?}");
    }
    let study = expm_study_of(&a, &[0.6, 0.8], &times, 1e-5).unwrap();
    let integration = study
        .differences
        .iter()
        .find(|d| d.tolerance >= 1e-2)
        .expect("a pair with a bound that tests nothing");
    assert!(
        !integration.checked && !integration.passed,
        "{integration:?}"
    );
    assert!(!study.passed());
}

/// Under a follower load `K` is not symmetric, and Rayleigh's principle does not hold: on
/// Ziegler's pendulum at P = 1 the quotient of the shape (1, 1) of `K`'s symmetric part is
/// 0.1667 against the system's ω₁² = 0.2192, which the study reported as a failed bound with
/// a stationarity table. It is refused, naming the asymmetry, and nothing is printed on
/// standard output.
#[test]
fn a_rayleigh_study_refuses_a_non_symmetric_stiffness() {
    let ziegler = format!(
        "{}/tests/fixtures/ziegler_pendulum.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let out = eomgen(&[
        "study", "rayleigh", &ziegler, "--set", "P=1", "--shape", "1,1",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("not symmetric"), "{err}");
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
}
