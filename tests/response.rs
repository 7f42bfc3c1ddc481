//! Free response three ways (HW28) and damping models compared (HW34): the routes against
//! each other and against closed forms written here from hand-derived M, C, K.

use crate::common;
use common::{eomgen, eomgen_ok};

use eomgen::{
    FreeResponse, Linearization, ModeKind, ModelInfo, RayleighDamping, exact_damped_modes,
    find_equilibrium, linearize, modal_damping, normal_modes, response_by_exponential,
    response_by_integration, response_by_m_inv_k_modes, response_by_normal_modes,
    response_with_modal_damping, state_response_by_eigenvectors,
};
use nalgebra::{Complex, Matrix2, Vector2};

fn model(name: &str) -> Box<dyn ModelInfo> {
    (eomgen::models::find(name).expect("bundled model").make)()
}

fn linearization(name: &str, at: &str) -> Linearization {
    let m = model(name);
    let guess = m
        .equilibrium_guesses()
        .into_iter()
        .find(|(n, _)| *n == at)
        .unwrap_or_else(|| panic!("{name} names `{at}`"))
        .1;
    let q = find_equilibrium(m.as_ref(), &guess, 0.0).unwrap().q;
    linearize(m.as_ref(), &q, &vec![0.0; q.len()], 0.0).unwrap()
}

fn grid(t_end: f64, samples: usize) -> Vec<f64> {
    (0..samples)
        .map(|i| t_end * i as f64 / (samples - 1) as f64)
        .collect()
}

/// Integration tolerance (DOP853, rtol = atol): 1e-13 keeps its global error near 1e-12 of
/// the solution's size over the spans below, two orders inside the 1e-10 the comparisons ask.
const TIGHT: f64 = 1e-13;

/// The four routes of the undamped free response; asserts every pair agrees to 1e-10 of the
/// largest |δq| (displacements) and |δq̇| (velocities), the issue's tolerance, and returns
/// them (integration, exponential, M⁻¹K modes, normal modes).
fn four_ways(lin: &Linearization, q0: &[f64], qdot0: &[f64], times: &[f64]) -> Vec<FreeResponse> {
    let all = vec![
        response_by_integration(lin, q0, qdot0, times, TIGHT).unwrap(),
        response_by_exponential(lin, q0, qdot0, times).unwrap(),
        response_by_m_inv_k_modes(lin, q0, qdot0, times).unwrap(),
        response_by_normal_modes(lin, q0, qdot0, times).unwrap(),
    ];
    let names = ["integration", "e^{At}", "M⁻¹K modes", "normal modes"];
    let (q_scale, v_scale) = (all[1].max_displacement(), all[1].max_velocity());
    for i in 0..4 {
        for j in i + 1..4 {
            let dq = all[i].max_displacement_difference(&all[j]).unwrap();
            let dv = all[i].max_velocity_difference(&all[j]).unwrap();
            eprintln!(
                "{} vs {}: {:.1e} (δq), {:.1e} (δq̇) relative",
                names[i],
                names[j],
                dq / q_scale,
                dv / v_scale
            );
            assert!(
                dq <= 1e-10 * q_scale,
                "{} vs {}: {dq:e}",
                names[i],
                names[j]
            );
            assert!(
                dv <= 1e-10 * v_scale,
                "{} vs {}: {dv:e}",
                names[i],
                names[j]
            );
        }
    }
    all
}

/// Max difference of `response` from `exact(t) -> (q, q̇)`, relative to the response's size.
fn against(response: &FreeResponse, exact: impl Fn(f64) -> (Vec<f64>, Vec<f64>)) -> f64 {
    let scale = response.max_displacement().max(response.max_velocity());
    let mut worst = 0.0f64;
    for (i, &t) in response.times.iter().enumerate() {
        let (q, v) = exact(t);
        for j in 0..q.len() {
            worst = worst
                .max((response.displacements[i][j] - q[j]).abs())
                .max((response.velocities[i][j] - v[j]).abs());
        }
    }
    worst / scale
}

/// `(q, q̇)` of one modal coordinate `r̈ + λ r = 0` by the sign of λ, written out again here.
fn mode_closed_form(lambda: f64, a: f64, b: f64, t: f64) -> (f64, f64) {
    if lambda > 0.0 {
        let w = lambda.sqrt();
        (
            a * (w * t).cos() + b * (w * t).sin() / w,
            -a * w * (w * t).sin() + b * (w * t).cos(),
        )
    } else if lambda < 0.0 {
        let s = (-lambda).sqrt();
        (
            a * (s * t).cosh() + b * (s * t).sinh() / s,
            a * s * (s * t).sinh() + b * (s * t).cosh(),
        )
    } else {
        (a + b * t, b)
    }
}

/// HW23/HW28: three equal masses (m = k = 1) between walls; the three routes against each
/// other and against the analytic modes ω² = 2 − √2, 2, 2 + √2 with shapes [1, √2, 1],
/// [1, 0, −1], [1, −√2, 1] (orthogonal since M = I: a_k = u_k·x₀/|u_k|²). 1e-10 relative: the
/// closed form is exact, the routes are exact to rounding except integration (1e-13 tol).
#[test]
fn three_masses_three_ways_and_closed_form() {
    let lin = linearization("three_masses", "rest");
    let (q0, v0) = ([0.3, -0.1, 0.2], [0.05, 0.1, -0.2]);
    let times = grid(20.0, 201);
    let all = four_ways(&lin, &q0, &v0, &times);
    let s2 = 2f64.sqrt();
    let modes = [
        (2.0 - s2, [1.0, s2, 1.0]),
        (2.0, [1.0, 0.0, -1.0]),
        (2.0 + s2, [1.0, -s2, 1.0]),
    ];
    let exact = |t: f64| {
        let (mut q, mut v) = (vec![0.0; 3], vec![0.0; 3]);
        for (lambda, u) in &modes {
            let norm2: f64 = u.iter().map(|x| x * x).sum();
            let a = u.iter().zip(&q0).map(|(x, y)| x * y).sum::<f64>() / norm2;
            let b = u.iter().zip(&v0).map(|(x, y)| x * y).sum::<f64>() / norm2;
            let (r, rdot) = mode_closed_form(*lambda, a, b, t);
            for i in 0..3 {
                q[i] += u[i] * r;
                v[i] += u[i] * rdot;
            }
        }
        (q, v)
    };
    for r in &all {
        let e = against(r, exact);
        assert!(e < 1e-10, "closed form: {e:e}");
    }
}

/// The closed form of a two-degree-of-freedom `M q̈ + K q = 0` from hand-derived 2 × 2
/// matrices: λ the roots of det(K − λM) = 0 (a quadratic), eigenvectors
/// u = [K₁₂ − λM₁₂, −(K₁₁ − λM₁₁)] (or from the second row when that vanishes), the initial
/// values expanded by inverting [u₁ u₂].
fn two_dof_closed_form(
    m: Matrix2<f64>,
    k: Matrix2<f64>,
    q0: [f64; 2],
    v0: [f64; 2],
) -> impl Fn(f64) -> (Vec<f64>, Vec<f64>) {
    let a = m.determinant();
    let b = -(k[(0, 0)] * m[(1, 1)] + k[(1, 1)] * m[(0, 0)]
        - k[(0, 1)] * m[(1, 0)]
        - k[(1, 0)] * m[(0, 1)]);
    let c = k.determinant();
    let disc = (b * b - 4.0 * a * c).sqrt();
    let lambdas = [(-b - disc) / (2.0 * a), (-b + disc) / (2.0 * a)];
    let vector = |l: f64| {
        let row0 = Vector2::new(k[(0, 1)] - l * m[(0, 1)], -(k[(0, 0)] - l * m[(0, 0)]));
        let row1 = Vector2::new(k[(1, 1)] - l * m[(1, 1)], -(k[(1, 0)] - l * m[(1, 0)]));
        if row0.norm() > row1.norm() {
            row0
        } else {
            row1
        }
    };
    let u = Matrix2::from_columns(&[vector(lambdas[0]), vector(lambdas[1])]);
    let inv = u.try_inverse().expect("independent modes");
    let ca = inv * Vector2::from(q0);
    let cb = inv * Vector2::from(v0);
    // A root that is zero in exact arithmetic (det K = 0) is zero here: c = 0 exactly.
    move |t| {
        let (mut q, mut v) = (vec![0.0; 2], vec![0.0; 2]);
        for mode in 0..2 {
            let (r, rdot) = mode_closed_form(lambdas[mode], ca[mode], cb[mode], t);
            for i in 0..2 {
                q[i] += u[(i, mode)] * r;
                v[i] += u[(i, mode)] * rdot;
            }
        }
        (q, v)
    }
}

/// HW28's case: the cart–pendulum (m1 = m2 = 1, ℓ = 1, g = 10) hanging has a zero-frequency
/// mode (the cart drifts as a + b t) and upright an unstable one (cosh/sinh, K indefinite):
/// M = [[m1+m2, m2 ℓ cos θ*], [m2 ℓ cos θ*, m2 ℓ²]], K = diag(0, m2 g ℓ cos θ*). The routes
/// agree with each other and with the closed form to 1e-10 of the largest value.
#[test]
fn cart_pendulum_zero_mode_and_upright() {
    for (at, cos, t_end) in [("hanging", 1.0, 10.0), ("upright", -1.0, 2.0)] {
        let lin = linearization("cart_pendulum", at);
        let (q0, v0) = ([0.1, 0.05], [0.2, -0.1]);
        let times = grid(t_end, 101);
        let all = four_ways(&lin, &q0, &v0, &times);
        let m = Matrix2::new(2.0, cos, cos, 1.0);
        let k = Matrix2::new(0.0, 0.0, 0.0, 10.0 * cos);
        let exact = two_dof_closed_form(m, k, q0, v0);
        for r in &all {
            let e = against(r, &exact);
            assert!(e < 1e-10, "{at}: closed form {e:e}");
        }
        // The cart's drift: the momentum (m1+m2) ẋ + m2 ℓ cos θ* θ̇ is constant.
        let p0 = 2.0 * v0[0] + cos * v0[1];
        for v in &all[3].velocities {
            assert!((2.0 * v[0] + cos * v[1] - p0).abs() < 1e-12);
        }
    }
}

/// The double pendulum of uniform bars hanging and upright (angles from +x; hand M, K as in
/// tests/modes.rs: M = [[(m1/3 + m2) ℓ1², m2 ℓ1 ℓ2/2 cos(θ1−θ2)], …], K = diag((m1/2 + m2) g ℓ1,
/// m2 g ℓ2/2) · (−sin θ*)): both modes unstable upright. 1e-10 relative.
#[test]
fn double_pendulum_hanging_and_upright_three_ways() {
    for (at, sign, t_end) in [("hanging", 1.0, 10.0), ("upright", -1.0, 1.0)] {
        let lin = linearization("double_pendulum", at);
        let (q0, v0) = ([0.02, -0.03], [0.1, 0.0]);
        let times = grid(t_end, 101);
        let all = four_ways(&lin, &q0, &v0, &times);
        let m = Matrix2::new(4.0 / 3.0, 0.5, 0.5, 1.0 / 3.0);
        let k = Matrix2::new(15.0 * sign, 0.0, 0.0, 5.0 * sign);
        let exact = two_dof_closed_form(m, k, q0, v0);
        for r in &all {
            let e = against(r, &exact);
            assert!(e < 1e-10, "{at}: closed form {e:e}");
        }
    }
}

/// One degree of freedom: the compound pendulum (ω² = 15) hanging and upright (σ² = 15),
/// against q₀ cos ωt + q̇₀ sin ωt/ω and q₀ cosh σt + q̇₀ sinh σt/σ. 1e-10 relative.
#[test]
fn single_dof_closed_forms() {
    for (at, lambda, t_end) in [("hanging", 15.0, 10.0), ("upright", -15.0, 2.0)] {
        let lin = linearization("compound_pendulum", at);
        let times = grid(t_end, 101);
        let all = four_ways(&lin, &[0.1], &[-0.2], &times);
        for r in &all {
            let e = against(r, |t| {
                let (q, v) = mode_closed_form(lambda, 0.1, -0.2, t);
                (vec![q], vec![v])
            });
            assert!(e < 1e-10, "{at}: {e:e}");
        }
    }
}

/// Bad input to the modal routes is a typed error, not a panic or NaN.
#[test]
fn modal_routes_refuse_damping_and_bad_input() {
    let lin = linearization("three_masses_damped", "rest");
    let err = response_by_normal_modes(&lin, &[1.0, 0.0, 0.0], &[0.0; 3], &[0.0, 1.0]);
    assert!(matches!(err, Err(eomgen::ResponseError::Damped { .. })));
    let err = response_by_m_inv_k_modes(&lin, &[1.0, 0.0], &[0.0; 3], &[0.0]);
    assert!(matches!(
        err,
        Err(eomgen::ResponseError::DimensionMismatch { .. })
    ));
    let undamped = linearization("three_masses", "rest");
    let err = response_by_exponential(&undamped, &[1.0, 0.0, 0.0], &[0.0; 3], &[0.0, f64::NAN]);
    assert!(matches!(
        err,
        Err(eomgen::ResponseError::InvalidTimes { .. })
    ));
    // The cart–pendulum's state matrix has a Jordan block at 0 (the drifting cart): complex
    // eigenvector superposition cannot represent a + b t, and says so.
    let cart = linearization("cart_pendulum", "hanging");
    let err = state_response_by_eigenvectors(
        &cart.state_matrix().unwrap(),
        &[0.0, 0.0, 1.0, 0.0],
        &[1.0],
    );
    assert!(
        matches!(err, Err(eomgen::ResponseError::Defective { .. })),
        "{err:?}"
    );
}

/// det(s² M + s C + K) for HW34 (m = k = 1, c = 0.1): with p = s² + 2 the tridiagonal
/// determinant is (p + c s)(p² − 1) − p; its derivative by the product rule.
fn hw34_characteristic(s: Complex<f64>, c: f64) -> (Complex<f64>, Complex<f64>) {
    let one = Complex::new(1.0, 0.0);
    let p = s * s + 2.0;
    let f = (p + s * c) * (p * p - one) - p;
    let df = (s * 2.0 + c) * (p * p - one) + (p + s * c) * (p * s * 4.0) - s * 2.0;
    (f, df)
}

/// HW34: the modal damping matrix of one dashpot at the left wall is analytic,
/// Ĉ = c ψ₁ψ₁ᵀ with the first components ψ₁ = [1/2, 1/√2, 1/2] (up to signs): diagonal
/// ζ_k = c/(8ω₁), c/(4ω₂), c/(8ω₃), coupling max|Ĉᵢⱼ|/max|Ĉ_kk| = 1/√2. The exact ζ come
/// from the complex eigenvalues, checked against Newton on the hand-written determinant
/// (converged to 1e-15). The diagonal approximation is close but not exact because Ĉ is not
/// diagonal: the measured relative differences are 1.8e-4, 2.5e-3 and 4.9e-3 (second order in
/// c); the test asserts each lies between 1e-5 and 1e-2.
#[test]
fn three_masses_damped_modal_approximation_against_exact() {
    let lin = linearization("three_masses_damped", "rest");
    let c = 0.1;
    let modes = normal_modes(&lin).unwrap();
    let approx = modal_damping(&lin, &modes);
    let s2 = 2f64.sqrt();
    let w = [(2.0 - s2).sqrt(), s2, (2.0 + s2).sqrt()];
    let analytic = [c / (8.0 * w[0]), c / (4.0 * w[1]), c / (8.0 * w[2])];
    for (k, expected) in analytic.iter().enumerate() {
        let z = approx.damping_ratios[k].unwrap();
        assert!((z - expected).abs() < 1e-14, "mode {k}: {z} vs {expected}");
    }
    assert!(
        (approx.coupling - 1.0 / s2).abs() < 1e-12,
        "{}",
        approx.coupling
    );
    let exact = exact_damped_modes(&lin, &modes).unwrap();
    for k in 0..3 {
        let e = exact[k].unwrap();
        // Newton on the determinant from the modal-damping estimate.
        let zeta = analytic[k];
        let mut s = Complex::new(-zeta * w[k], w[k] * (1.0 - zeta * zeta).sqrt());
        for _ in 0..50 {
            let (f, df) = hw34_characteristic(s, c);
            s -= f / df;
        }
        assert!(hw34_characteristic(s, c).0.norm() < 1e-13);
        assert!(
            (e.eigenvalue - s).norm() < 1e-12,
            "mode {k}: {} vs {s}",
            e.eigenvalue
        );
        let z = approx.damping_ratios[k].unwrap();
        let relative = (z - e.damping_ratio).abs() / e.damping_ratio;
        eprintln!(
            "mode {}: ζ exact {:.9}, diagonal Ĉ {:.9}, relative difference {relative:.2e}",
            k + 1,
            e.damping_ratio,
            z
        );
        assert!(relative > 1e-5 && relative < 1e-2, "mode {k}: {relative:e}");
    }
}

/// With proportional damping C = αM + βK, Ĉ = αI + βΛ is diagonal and the modal-damping
/// approximation is exact: its ζ equal the exact complex eigenvalues' to 1e-12, and its
/// response equals e^{At}'s to 1e-12 of the largest displacement (both exact to rounding).
/// The Rayleigh fit reproduces the two chosen ζ (to 1e-15, rounding of a 2 × 2 solve) and
/// its prediction α/(2ω) + βω/2 for the third mode is what the exact eigenvalues of the
/// Rayleigh-damped system give.
#[test]
fn rayleigh_damping_is_exact_in_modal_coordinates() {
    let mut lin = linearization("three_masses_damped", "rest");
    let modes = normal_modes(&lin).unwrap();
    let real = exact_damped_modes(&lin, &modes).unwrap();
    let (z1, z3) = (
        real[0].unwrap().damping_ratio,
        real[2].unwrap().damping_ratio,
    );
    let w = &modes.natural_frequencies;
    let fit = RayleighDamping::fit([w[0], w[2]], [z1, z3]).unwrap();
    assert!((fit.damping_ratio(w[0]) - z1).abs() < 1e-15);
    assert!((fit.damping_ratio(w[2]) - z3).abs() < 1e-15);
    lin.damping_matrix = fit.damping_matrix(&lin);
    let approx = modal_damping(&lin, &modes);
    assert!(approx.coupling < 1e-12, "{}", approx.coupling);
    let exact = exact_damped_modes(&lin, &modes).unwrap();
    for k in 0..3 {
        let formula = fit.alpha / (2.0 * w[k]) + fit.beta * w[k] / 2.0;
        let e = exact[k].unwrap().damping_ratio;
        assert!((e - formula).abs() < 1e-12, "mode {k}: {e} vs {formula}");
        assert!((approx.damping_ratios[k].unwrap() - e).abs() < 1e-12);
    }
    eprintln!(
        "Rayleigh fit to modes 1, 3: α = {:.6e} 1/s, β = {:.6e} s; ζ₂ predicted {:.6} vs the dashpot's exact {:.6}",
        fit.alpha,
        fit.beta,
        fit.damping_ratio(w[1]),
        real[1].unwrap().damping_ratio
    );
    let times = grid(60.0, 301);
    let q0 = [1.0, 0.5, -0.2];
    let v0 = [0.0, 0.3, 0.0];
    let by_modes =
        response_with_modal_damping(&lin, &modes, &fit.modal_damping(&modes), &q0, &v0, &times)
            .unwrap();
    let by_exp = response_by_exponential(&lin, &q0, &v0, &times).unwrap();
    let d = by_modes.max_displacement_difference(&by_exp).unwrap();
    assert!(d < 1e-12 * by_exp.max_displacement(), "{d:e}");
    // The diagonal of Ĉ is the same modal damping.
    let diagonal = approx.diagonal();
    for (a, b) in diagonal.iter().zip(fit.modal_damping(&modes)) {
        assert!((a - b).abs() < 1e-14);
    }
}

/// HW34's experiment: release from each mode shape (first mass at 1, at rest). Exact
/// responses three ways (e^{At}, DOP853 at 1e-13, complex eigenvector superposition) agree to
/// 1e-10 of the amplitude; the modal-damping approximation departs from them because Ĉ
/// couples the modes (a release in one mode shape leaks into the others through the
/// dashpot): measured 2.7e-2, 1.40e-1 and 1.09e-1 of the amplitude over 60 s for the releases
/// in modes 1, 2, 3 (the same figures from scipy's expm against the diagonal closed form);
/// asserted between 1e-3 and 0.3.
#[test]
fn three_masses_damped_responses_from_each_mode() {
    let lin = linearization("three_masses_damped", "rest");
    let modes = normal_modes(&lin).unwrap();
    let approx = modal_damping(&lin, &modes);
    let times = grid(60.0, 301);
    let a = lin.state_matrix().unwrap();
    for k in 0..3 {
        let shape = modes.mode_shapes.column(k);
        let q0: Vec<f64> = shape.iter().map(|v| v / shape[0]).collect();
        let v0 = [0.0; 3];
        let exact = response_by_exponential(&lin, &q0, &v0, &times).unwrap();
        let integrated = response_by_integration(&lin, &q0, &v0, &times, TIGHT).unwrap();
        let y0: Vec<f64> = q0.iter().chain(&v0).copied().collect();
        let vectors = state_response_by_eigenvectors(&a, &y0, &times).unwrap();
        let scale = exact.max_displacement();
        assert!(exact.max_displacement_difference(&integrated).unwrap() < 1e-10 * scale);
        for (e, v) in exact.displacements.iter().zip(&vectors) {
            for i in 0..3 {
                assert!((e[i] - v[i]).abs() < 1e-10 * scale);
            }
        }
        let diagonal =
            response_with_modal_damping(&lin, &modes, &approx.diagonal(), &q0, &v0, &times)
                .unwrap();
        let d = diagonal.max_displacement_difference(&exact).unwrap() / scale;
        eprintln!(
            "mode {}: diagonal Ĉ vs exact, max |δq| difference {d:.2e} of the amplitude",
            k + 1
        );
        assert!(d > 1e-3 && d < 0.3, "mode {k}: {d:e}");
    }
}

/// `vibration::free_response` (what `eomgen study free-response` prints) on the cart
/// pendulum upright, an unstable and a zero-frequency mode: the four routes agree to 1e-10 of
/// the largest |δq|, the defaults are HW28's, and the initial deviation is kept.
#[test]
fn free_response_study_routes_agree() {
    use eomgen::analysis::vibration::{
        EquilibriumStart, FreeResponseMethod, FreeResponseOptions, InitialDeviation,
        OperatingPointOptions, ResponseStudyError, free_response,
    };
    let m = model("cart_pendulum");
    let options = FreeResponseOptions {
        operating_point: OperatingPointOptions {
            start: EquilibriumStart::Named("upright".into()),
            ..OperatingPointOptions::default()
        },
        initial: Some(InitialDeviation {
            q: vec![0.1, 0.05],
            qdot: vec![0.2, 0.0],
        }),
        t_end: Some(2.0),
        ..FreeResponseOptions::default()
    };
    let study = free_response(m.as_ref(), &options).unwrap();
    assert_eq!(study.operating_point.name, "upright");
    assert!(matches!(
        study.normal_modes.kinds[0],
        ModeKind::Unstable { .. }
    ));
    assert_eq!(study.normal_modes.kinds[1], ModeKind::ZeroFrequency);
    assert_eq!(study.differences.len(), 6);
    for d in &study.differences {
        assert!(d.displacement_relative < 1e-10, "{d:?}");
    }
    let methods: Vec<_> = study.responses.iter().map(|(m, _)| *m).collect();
    assert_eq!(methods, FreeResponseMethod::ALL);
    assert_eq!(study.responses[1].1.times.len(), 401);
    assert_eq!(study.responses[1].1.displacements[0], [0.1, 0.05]);
    // Errors: a constrained model, a bad tolerance, too few samples.
    let pendulum = model("simple_pendulum_cartesian");
    let err = free_response(pendulum.as_ref(), &FreeResponseOptions::default()).unwrap_err();
    assert!(
        matches!(err, ResponseStudyError::Constrained { .. }),
        "{err}"
    );
    let bad = FreeResponseOptions {
        tol: 0.0,
        ..FreeResponseOptions::default()
    };
    let err = free_response(m.as_ref(), &bad).unwrap_err();
    assert_eq!(err, ResponseStudyError::InvalidTolerance { tol: 0.0 });
    let bad = FreeResponseOptions {
        samples: 1,
        ..FreeResponseOptions::default()
    };
    let err = free_response(m.as_ref(), &bad).unwrap_err();
    assert_eq!(err, ResponseStudyError::TooFewSamples { samples: 1 });
}

/// `eomgen study free-response`: JSON contract, the chart and a usage error.
#[test]
fn free_response_cli() {
    let dir = std::env::temp_dir().join(format!("eomgen-free-response-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let chart = dir.join("free.svg");
    let out = eomgen_ok(&[
        "study",
        "free-response",
        "cart_pendulum",
        "--at",
        "upright",
        "--init",
        "x=0.1,theta=0.05,x_dot=0.2",
        "--t-end",
        "2",
        "--json",
        "--plot",
        chart.to_str().unwrap(),
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["model"], "cart_pendulum");
    assert_eq!(v["operating_point"]["name"], "upright");
    assert_eq!(v["methods"].as_array().unwrap().len(), 4);
    // Ascending ω²: the unstable mode (ω² = −20) first, then the cart's zero mode.
    assert_eq!(v["modes"][0]["kind"], "unstable");
    assert_eq!(v["modes"][1]["kind"], "zero_frequency");
    let diffs = v["max_differences"].as_array().unwrap();
    assert_eq!(diffs.len(), 6);
    assert_eq!(diffs[0]["a"], "integration");
    assert_eq!(diffs[5]["b"], "normal_modes");
    assert_eq!(v["initial"]["q"][0], 0.1);
    assert_eq!(v["initial"]["qdot"][0], 0.2);
    let svg = std::fs::read_to_string(&chart).unwrap();
    assert!(svg.contains("<svg") && svg.contains("theta"));
    // A bad --init name is a usage error.
    let out = eomgen(&["study", "free-response", "cart_pendulum", "--init", "y=1"]);
    assert_eq!(out.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `vibration::modal_damping_study` (what `eomgen study modal-damping` prints) on HW34's
/// three masses (c = 0.1): Rayleigh damping fitted to modes 1 and 3 reproduces their exact ζ
/// (1e-14), the diagonal of Ĉ gives mode 2 ζ = 0.1/(4√2) (1e-14), DOP853 matches e^{At} to
/// 1e-9 of the amplitude, and the diagonal approximation's response differs from the exact
/// one by 0.1 % to 30 % (the coupling of Ĉ). Bad Rayleigh modes are typed errors.
#[test]
fn modal_damping_study_three_ways() {
    use eomgen::analysis::vibration::{
        InitialDeviation, ModalDampingOptions, ResponseStudyError, modal_damping_study,
    };
    let m = model("three_masses_damped");
    let options = ModalDampingOptions {
        rayleigh_modes: Some([1, 3]),
        ..ModalDampingOptions::default()
    };
    let study = modal_damping_study(m.as_ref(), &options).unwrap();
    assert_eq!(study.modes.len(), 3);
    for k in [0, 2] {
        let mode = &study.modes[k];
        let exact = mode.exact.unwrap().damping_ratio;
        let rayleigh = mode.rayleigh.unwrap().damping_ratio;
        assert!((exact - rayleigh).abs() < 1e-14, "{mode:?}");
    }
    let diag = study.modes[1].diagonal.unwrap().damping_ratio;
    assert!((diag - 0.1 / (4.0 * 2f64.sqrt())).abs() < 1e-14);
    assert_eq!(study.rayleigh.unwrap().modes, [1, 3]);
    assert_eq!(study.releases.len(), 3);
    for c in &study.releases {
        assert!(c.integration_vs_exact < 1e-9, "{}", c.name);
        assert!(
            c.diagonal_vs_exact > 1e-3 && c.diagonal_vs_exact < 0.3,
            "{}",
            c.name
        );
    }
    // One given release instead of the mode shapes.
    let given = ModalDampingOptions {
        initial: Some(InitialDeviation {
            q: vec![0.1, 0.0, 0.0],
            qdot: vec![0.0; 3],
        }),
        samples: 101,
        ..ModalDampingOptions::default()
    };
    let study = modal_damping_study(m.as_ref(), &given).unwrap();
    assert_eq!(study.releases.len(), 1);
    assert_eq!(study.releases[0].exact.times.len(), 101);
    assert!((study.releases[0].amplitude - 0.1).abs() < 1e-12);
    // Rayleigh modes that cannot be fitted.
    for (pair, expected) in [
        (
            [1, 7],
            ResponseStudyError::NoSuchMode {
                model: "three_masses_damped".into(),
                mode: 7,
                count: 3,
            },
        ),
        (
            [0, 2],
            ResponseStudyError::NoSuchMode {
                model: "three_masses_damped".into(),
                mode: 0,
                count: 3,
            },
        ),
    ] {
        let options = ModalDampingOptions {
            rayleigh_modes: Some(pair),
            ..ModalDampingOptions::default()
        };
        assert_eq!(
            modal_damping_study(m.as_ref(), &options).unwrap_err(),
            expected
        );
    }
    let same = ModalDampingOptions {
        rayleigh_modes: Some([1, 1]),
        ..ModalDampingOptions::default()
    };
    let err = modal_damping_study(m.as_ref(), &same).unwrap_err();
    assert!(
        matches!(err, ResponseStudyError::RayleighFit { modes: [1, 1], .. }),
        "{err}"
    );
}

/// `eomgen study modal-damping`: JSON contract, the chart and a usage error.
#[test]
fn modal_damping_cli() {
    let dir = std::env::temp_dir().join(format!("eomgen-modal-damping-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let chart = dir.join("damping.png");
    let out = eomgen(&[
        "study",
        "modal-damping",
        "three_masses_damped",
        "--rayleigh-modes",
        "1,3",
        "--json",
        "--plot",
        chart.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["model"], "three_masses_damped");
    let modes = v["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 3);
    for m in modes {
        assert!(m["exact"]["damping_ratio"].is_f64(), "{m}");
        assert!(m["diagonal"]["damped_frequency"].is_f64(), "{m}");
        assert!(m["rayleigh"]["damping_ratio"].is_f64(), "{m}");
    }
    assert_eq!(v["rayleigh"]["modes"], serde_json::json!([1, 3]));
    assert!(v["rayleigh"]["alpha"].is_f64() && v["rayleigh"]["beta"].is_f64());
    assert!(v["modal_damping_matrix"].as_array().unwrap().len() == 3);
    let cases = v["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 3);
    for c in cases {
        assert!(c["integration_vs_exact"].is_f64(), "{c}");
        assert!(c["rayleigh_vs_exact"].is_f64(), "{c}");
    }
    let png = std::fs::read(&chart).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let out = eomgen(&[
        "study",
        "modal-damping",
        "three_masses_damped",
        "--rayleigh-modes",
        "1,1",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 28: the isotropic 3-D oscillator (`tests/fixtures/isotropic_oscillator.yaml`,
/// `M = 2I`, `K = 50I`) has ω = 5 rad/s three times and a full set of eigenvectors (every
/// direction is a mode): not defective, though `M⁻¹K − 25I` is rounding in every direction.
/// Every route matches the closed form `x(t) = x₀ cos 5t + v₀ sin 5t/5` to 1e-10 (the
/// routes' own tolerance); with `C = I` the eigenvectors of `A` (`s = −1/4 ± i√(25 − 1/16)`,
/// three times each) give `x = e^{−t/4}(x₀ cos ω_d t + (v₀ + x₀/4) sin ω_d t/ω_d)` to 1e-10.
#[test]
fn issue_28_isotropic_oscillator_is_not_defective() {
    let i3 = nalgebra::DMatrix::<f64>::identity(3, 3);
    let undamped = Linearization::from_matrices(&i3 * 2.0, &i3 * 50.0, &i3 * 0.0);
    let (q0, v0) = ([0.1, 0.05, -0.02], [0.3, -0.2, 0.0]);
    let times = grid(4.0, 81);
    for response in four_ways(&undamped, &q0, &v0, &times) {
        let error = against(&response, |t| {
            let (s, c) = (5.0 * t).sin_cos();
            (
                (0..3).map(|i| q0[i] * c + v0[i] * s / 5.0).collect(),
                (0..3).map(|i| -5.0 * q0[i] * s + v0[i] * c).collect(),
            )
        });
        assert!(error < 1e-10, "{error:e}");
    }
    let damped = Linearization::from_matrices(&i3 * 2.0, &i3 * 50.0, i3.clone());
    let y0: Vec<f64> = q0.iter().chain(&v0).copied().collect();
    let states =
        state_response_by_eigenvectors(&damped.state_matrix().unwrap(), &y0, &times).unwrap();
    let (h, wd) = (0.25, (25.0f64 - 0.0625).sqrt());
    let mut worst = 0.0f64;
    for (y, &t) in states.iter().zip(&times) {
        let (s, c) = (wd * t).sin_cos();
        let e = (-h * t).exp();
        for i in 0..3 {
            let b = (v0[i] + h * q0[i]) / wd;
            let x = e * (q0[i] * c + b * s);
            let v = e * (-h * (q0[i] * c + b * s) + wd * (-q0[i] * s + b * c));
            worst = worst.max((y[i] - x).abs()).max((y[3 + i] - v).abs());
        }
    }
    assert!(worst < 1e-10, "{worst:e}");
    // The study (`eomgen study free-response`) on the model file itself.
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/isotropic_oscillator.yaml"
    );
    let out = eomgen_ok(&["study", "free-response", path, "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["methods"].as_array().unwrap().len(), 4);
}
