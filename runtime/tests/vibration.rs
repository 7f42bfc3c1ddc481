//! The vibration analyses (`analysis::vibration`) and the blocks of `linear/` under them, on
//! the small hand-written models of `common/models.rs`, each against a closed form or an
//! independent computation. Every bound is stated next to its assertion with its reason.

use crate::common;

use std::f64::consts::{PI, TAU};

use common::models::{CartesianPendulum, ForcedOscillator, Pendulum, TwoMassChain, boxed};
use eomgen_runtime::analysis::vibration::{
    EquilibriumStart, FloquetStudyError, FloquetStudyOptions, FreeResponseMethod,
    FreeResponseOptions, FrfOptions, FrfSimulationOptions, InitialDeviation, ModalDampingOptions,
    ModalOptions, OperatingPointError, OperatingPointOptions, floquet_at_equilibrium, floquet_cell,
    free_response, frequency_response_analysis, max_simulation_error, modal_analysis,
    modal_damping_study, plan_simulation, simulate_point,
};
use eomgen_runtime::{
    FloquetOptions, FloquetStability, ForcedLinearization, ModalError, ModeKind, ModelInfo,
    OdeSystem, PeakAmplitude, ResonancePeak, RhsError, damped_modes, floquet_analysis,
    frequency_response, frequency_sweep, linearize, linearize_with_inputs, log_frequencies,
    matrix_exponential, phase_degrees,
};
use nalgebra::{Complex, DMatrix};

/// The linearisation of `model` at `q = 0` with the input `input`'s column `B`.
fn forced(model: &mut dyn ModelInfo, input: &str) -> ForcedLinearization {
    let n = model.num_dofs();
    linearize_with_inputs(model, &vec![0.0; n], &[input]).expect("linearises")
}

/// `|a − b| ≤ tol · max(|b|, 1)`.
fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

/// The chain with proportional damping `C = βK`, `β = 0.1` (`c1/k1 = c2/k2`).
fn proportionally_damped_chain() -> TwoMassChain {
    TwoMassChain {
        c1: 0.3,
        c2: 0.5,
        ..TwoMassChain::default()
    }
}

const BETA: f64 = 0.1;

/// `modal_analysis` of the chain: `ω²` of `det(K − ω²M) = 0` and the closed-form shapes,
/// `ΨᵀMΨ = I`, `ζ_k = β ω_k/2` of proportional damping, and the `M⁻¹K` route agreeing. 1e-12:
/// the symmetric eigensolver on a 2 × 2 problem of order 10 is accurate to ~1e-15; a
/// change of any parameter by 1e-10 fails.
#[test]
fn modal_analysis_of_the_chain_matches_the_closed_form() {
    let chain = proportionally_damped_chain();
    let model = boxed(chain.clone());
    let modal = modal_analysis(model.as_ref(), &ModalOptions::default()).unwrap();
    assert_eq!(modal.operating_point.name, "rest");
    let (w2, shapes) = chain.modes();
    let modes = &modal.normal_modes;
    for (k, &w2) in w2.iter().enumerate() {
        assert!(
            close(modes.eigenvalues[k], w2, 1e-12),
            "ω² {k}: {} vs {w2}",
            modes.eigenvalues[k]
        );
        assert!(close(modes.natural_frequencies[k], w2.sqrt(), 1e-12));
        assert_eq!(modes.kinds[k], ModeKind::Oscillatory);
        let zeta = BETA * w2.sqrt() / 2.0;
        assert!(
            close(modal.damping_ratios[k], zeta, 1e-12),
            "ζ {k}: {} vs {zeta}",
            modal.damping_ratios[k]
        );
    }
    let psi = modal.mode_shape_matrix();
    let m = DMatrix::from_column_slice(2, 2, chain.m().as_slice());
    let orthonormality = (psi.transpose() * &m * &psi - DMatrix::identity(2, 2)).amax();
    assert!(orthonormality < 1e-12, "ΨᵀMΨ − I = {orthonormality:e}");
    let shapes = DMatrix::from_column_slice(2, 2, shapes.as_slice());
    assert!(
        (&psi - &shapes).amax() < 1e-12,
        "Ψ = {psi}, closed form {shapes}"
    );
    assert!(modal.m_inv_k_relative_difference < 1e-12);
    assert!(!modal.is_undamped());
}

/// The pendulum: `ω = √(g/l)` hanging with `ζ = c/(2 m l² ω)`, an unstable mode growing at
/// `√(g/l)` upright (found by Newton from π − 0.2), both to 1e-12 (scalar arithmetic). With
/// the pivot shaken the stiffness changes with `t`, and modes are refused.
#[test]
fn modal_analysis_of_the_pendulum_hanging_upright_and_shaken() {
    let pendulum = Pendulum {
        c: 0.75,
        ..Pendulum::default()
    };
    let omega = pendulum.natural_frequency();
    let model = boxed(pendulum.clone());
    let hanging = modal_analysis(model.as_ref(), &ModalOptions::default()).unwrap();
    assert_eq!(hanging.operating_point.name, "hanging");
    assert!(close(
        hanging.normal_modes.natural_frequencies[0],
        omega,
        1e-12
    ));
    let zeta = pendulum.c / (2.0 * pendulum.m * pendulum.l * pendulum.l * omega);
    assert!(
        close(hanging.damping_ratios[0], zeta, 1e-12),
        "{} vs {zeta}",
        hanging.damping_ratios[0]
    );

    let options = ModalOptions {
        operating_point: OperatingPointOptions {
            start: EquilibriumStart::Guess {
                label: "near upright".into(),
                q: vec![PI - 0.2],
            },
            t: 0.0,
        },
    };
    let upright = modal_analysis(model.as_ref(), &options).unwrap();
    assert!(close(upright.operating_point.q()[0], PI, 1e-12));
    match upright.normal_modes.kinds[0] {
        ModeKind::Unstable { growth_rate } => {
            assert!(close(growth_rate, omega, 1e-12), "{growth_rate}")
        }
        kind => panic!("upright is {kind:?}"),
    }

    let shaken = boxed(Pendulum {
        a: 0.1,
        ..Pendulum::default()
    });
    let refused = modal_analysis(shaken.as_ref(), &ModalOptions::default());
    assert!(
        matches!(
            refused,
            Err(OperatingPointError::Modal(ModalError::TimeDependent { .. }))
        ),
        "{refused:?}"
    );
}

/// `modal_analysis` on a constrained model, the Cartesian pendulum: it hangs with the rod's
/// tension `λ = m g`, one minimal coordinate `x`, `ω = √(g/l)`, and its mass-normalised
/// shape in both coordinates `(1/√m, 0)` (`δy = 0` at the bottom). 1e-12: a 1 × 1
/// eigenproblem after the constraint's null space, all in a few roundings.
#[test]
fn modal_analysis_of_the_cartesian_pendulum_on_its_constraint() {
    let pendulum = CartesianPendulum::default();
    let model = boxed(pendulum.clone());
    let modal = modal_analysis(model.as_ref(), &ModalOptions::default()).unwrap();
    assert_eq!(modal.operating_point.name, "hanging");
    assert_eq!(modal.minimal_coordinates, ["x"]);
    let tension = pendulum.m * pendulum.g;
    let lambda = modal.linearization.lagrange_multipliers[0];
    assert!(close(lambda, tension, 1e-12), "λ = {lambda} vs {tension}");
    let omega = (pendulum.g / pendulum.l).sqrt();
    assert!(close(
        modal.normal_modes.natural_frequencies[0],
        omega,
        1e-12
    ));
    assert_eq!(modal.mode_shapes.len(), 1);
    let shape = &modal.mode_shapes[0];
    assert!(
        close(shape[0], 1.0 / pendulum.m.sqrt(), 1e-12) && shape[1].abs() < 1e-12,
        "{shape:?}"
    );
    assert!(modal.m_inv_k_relative_difference < 1e-12);
    assert!(modal.is_undamped());
    assert_eq!(modal.damping_ratios, [0.0]);
}

/// `linearize` and `damped_modes` on the forced oscillator: `C = c`, `K = k`, `M = m`, and
/// the eigenvalue's `ζ = c/(2√(km))` and `ω_d = ω_n √(1 − ζ²)`; 1e-12 (a 2 × 2 eigenproblem).
#[test]
fn damping_ratio_from_the_state_matrix() {
    let oscillator = ForcedOscillator {
        a: 0.0,
        ..ForcedOscillator::default()
    };
    let model = boxed(oscillator.clone());
    let lin = linearize(model.as_ref(), &[0.0], &[0.0], 0.0).unwrap();
    assert_eq!(lin.mass_matrix[(0, 0)], oscillator.m);
    assert_eq!(lin.damping_matrix[(0, 0)], oscillator.c);
    assert_eq!(lin.stiffness_matrix[(0, 0)], oscillator.k);
    let damped = damped_modes(&lin).unwrap();
    assert_eq!(damped.len(), 1);
    let zeta = oscillator.damping_ratio();
    assert!(close(damped[0].1, zeta, 1e-12), "{} vs {zeta}", damped[0].1);
    let wd = oscillator.natural_frequency() * (1.0 - zeta * zeta).sqrt();
    assert!(close(damped[0].2, wd, 1e-12), "{} vs {wd}", damped[0].2);
}

/// `matrix_exponential` against closed forms, each to `8 ‖At‖₁ ε` relative (Frobenius): the
/// condition of `e^{At}` for these matrices is about `‖At‖₁` (Higham 2008, §10.2), and the
/// measured errors lie 1–2 orders of magnitude below the bound (docs/performance.md,
/// "Matrix exponential"); a stiff spring at a large `t`, to its closed form's accuracy. Then
/// the inputs an embedding program may pass by mistake: a
/// non-finite entry gives an all-NaN matrix, an empty matrix an empty one, and a huge norm
/// (`‖A‖₁ = 10⁴⁰`, where powers of `A` overflow) an exact answer rather than a hang.
#[test]
fn matrix_exponential_matches_closed_forms() {
    let check = |name: &str, a: DMatrix<f64>, exact: DMatrix<f64>| {
        let norm = a.column_iter().map(|c| c.lp_norm(1)).fold(1.0, f64::max);
        let error = (matrix_exponential(&a) - &exact).norm() / exact.norm();
        let bound = 8.0 * norm * f64::EPSILON;
        assert!(
            error < bound,
            "{name}: relative error {error:e}, bound {bound:e}"
        );
    };
    // Rotation generator [[0, w], [−w, 0]] t: a rotation by wt.
    for wt in [1.0f64, 100.0] {
        let (s, c) = wt.sin_cos();
        check(
            "rotation",
            DMatrix::from_row_slice(2, 2, &[0.0, wt, -wt, 0.0]),
            DMatrix::from_row_slice(2, 2, &[c, s, -s, c]),
        );
    }
    // Damped oscillator A = [[0, 1], [−ω², −2ζω]]:
    // e^{At} = e^{−ζωt} [cos(ω_d t) I + sin(ω_d t)/ω_d (A + ζω I)], ω_d = ω √(1 − ζ²).
    let (w, zeta, t) = (2.0 * std::f64::consts::PI, 0.05, 10.0);
    let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -w * w, -2.0 * zeta * w]);
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let id = DMatrix::<f64>::identity(2, 2);
    let exact = (&id * (wd * t).cos() + (&a + &id * (zeta * w)) * ((wd * t).sin() / wd))
        * (-zeta * w * t).exp();
    check("damped oscillator", a * t, exact);
    // Jordan block λ I + N (4 × 4): e^{Jt} = e^{λt} Σ_k (t^k / k!) N^k; λ = 0 is nilpotent.
    for (lambda, t) in [(-1.0f64, 5.0f64), (0.0, 10.0)] {
        let a = DMatrix::from_fn(4, 4, |i, j| match j as i64 - i as i64 {
            0 => lambda * t,
            1 => t,
            _ => 0.0,
        });
        let exact = DMatrix::from_fn(4, 4, |i, j| {
            if j < i {
                return 0.0;
            }
            let k = (j - i) as i32;
            (lambda * t).exp() * t.powi(k) / f64::from((1..=k).product::<i32>())
        });
        check("Jordan block", a, exact);
    }

    // Stiff two-mass spring (M = I, springs k to the walls and K between): K = [[k + K, −K],
    // [−K, k + K]] has the eigenvectors (1, ±1)/√2 exactly and ω₁² = k, ω₂² = k + 2K, so
    // e^{At} = [[P C Pᵀ, P Ω⁻¹S Pᵀ], [−P ΩS Pᵀ, P C Pᵀ]], C = cos Ωt, S = sin Ωt. At ω₂t = 1.4e5
    // the closed form itself is good to ω₂t ε ≈ 3e-11 (the rounding of ω₂t); 1e-9 is 80 times
    // the measured 1.2e-11 and fails an overscaled approximant (the fixed degree-13 Padé
    // eomgen had: 5e-9).
    let (k, big_k, t) = (1.0f64, 1e6f64, 100.0f64);
    let mut a = DMatrix::zeros(4, 4);
    a.view_mut((0, 2), (2, 2)).fill_with_identity();
    a.view_mut((2, 0), (2, 2))
        .copy_from(&DMatrix::from_row_slice(
            2,
            2,
            &[-k - big_k, big_k, big_k, -k - big_k],
        ));
    let r = std::f64::consts::FRAC_1_SQRT_2;
    let p = DMatrix::from_row_slice(2, 2, &[r, r, r, -r]);
    let omegas = [k.sqrt(), (k + 2.0 * big_k).sqrt()];
    let modal = |f: &dyn Fn(f64) -> f64| {
        &p * DMatrix::from_fn(2, 2, |i, j| if i == j { f(omegas[i]) } else { 0.0 }) * p.transpose()
    };
    let mut exact = DMatrix::zeros(4, 4);
    exact
        .view_mut((0, 0), (2, 2))
        .copy_from(&modal(&|w| (w * t).cos()));
    exact
        .view_mut((0, 2), (2, 2))
        .copy_from(&modal(&|w| (w * t).sin() / w));
    exact
        .view_mut((2, 0), (2, 2))
        .copy_from(&modal(&|w| -(w * t).sin() * w));
    exact
        .view_mut((2, 2), (2, 2))
        .copy_from(&modal(&|w| (w * t).cos()));
    let error = (matrix_exponential(&(a * t)) - &exact).norm() / exact.norm();
    assert!(
        error < 1e-9,
        "stiff two-mass spring: relative error {error:e}"
    );

    let nan = DMatrix::from_row_slice(2, 2, &[0.0, f64::NAN, 0.0, 0.0]);
    assert!(matrix_exponential(&nan).iter().all(|v| v.is_nan()));
    let inf = DMatrix::from_row_slice(2, 2, &[f64::INFINITY, 0.0, 0.0, 0.0]);
    assert!(matrix_exponential(&inf).iter().all(|v| v.is_nan()));
    assert_eq!(matrix_exponential(&DMatrix::zeros(0, 0)).shape(), (0, 0));
    // e^{−10⁴⁰ I} = 0 (underflow); e^N = I + N for N = [[0, 10⁴⁰], [0, 0]] (N² = 0), which
    // squaring (I + N/2ᵏ)^(2ᵏ) reproduces exactly.
    let decay = matrix_exponential(&(DMatrix::identity(2, 2) * -1e40));
    assert!(decay.iter().all(|&v| v == 0.0), "{decay}");
    let shear = DMatrix::from_row_slice(2, 2, &[0.0, 1e40, 0.0, 0.0]);
    let expected = DMatrix::from_row_slice(2, 2, &[1.0, 1e40, 0.0, 1.0]);
    let got = matrix_exponential(&shear);
    assert!(
        (&got - &expected).norm() <= 1e-15 * expected.norm(),
        "{got}"
    );
    // A nilpotent A (A² = 0) whose |A| is not: nalgebra's bound ‖|A|²⁷‖₁ on it overflows at
    // these entries, and its squaring loop then never ended (this call hung). It returns now,
    // finite; the value is not accurate (see `matrix_exponential`'s docs), so only that.
    let e = 1e12;
    let cancelling = DMatrix::from_row_slice(2, 2, &[e, -e, e, -e]);
    let got = matrix_exponential(&cancelling);
    assert!(got.iter().all(|v| v.is_finite()), "{got}");
}

/// `free_response` of the undamped chain: every route against the closed-form modal
/// superposition. The exact routes (`e^{At}` by Padé, the two modal sums) to 1e-11 of the
/// amplitude (rounding, `‖At‖₁ ≈ 105` at t = 10 s), DOP853 at its tolerance 1e-13 to 1e-9
/// over about five periods of the fast mode (ω₂ = √9.73 ≈ 3.12 rad/s); velocities are
/// compared divided by 4, about ω₂, so that both are errors in the same length scale; the
/// damping of a damped chain is reported as left out.
#[test]
fn free_response_routes_follow_the_closed_form() {
    let chain = proportionally_damped_chain();
    let model = boxed(chain.clone());
    let q0 = [0.1, -0.05];
    let options = FreeResponseOptions {
        initial: Some(InitialDeviation {
            q: q0.to_vec(),
            qdot: vec![0.0; 2],
        }),
        t_end: Some(10.0),
        samples: 201,
        ..FreeResponseOptions::default()
    };
    let study = free_response(model.as_ref(), &options).unwrap();
    assert_eq!(study.ignored_damping, chain.c1 + chain.c2);
    let undamped = TwoMassChain {
        c1: 0.0,
        c2: 0.0,
        ..chain
    };
    let amplitude = study.max_displacement;
    for (method, response) in &study.responses {
        let tol = if *method == FreeResponseMethod::Integration {
            1e-9
        } else {
            1e-11
        };
        let mut worst = 0.0f64;
        for (k, &t) in response.times.iter().enumerate() {
            let exact = undamped.undamped_response(q0, t);
            for i in 0..2 {
                worst = worst.max((response.displacements[k][i] - exact[i]).abs());
                worst = worst.max((response.velocities[k][i] - exact[2 + i]).abs() / 4.0);
            }
        }
        assert!(
            worst < tol * amplitude,
            "{}: {:e} of the amplitude",
            method.name(),
            worst / amplitude
        );
    }
    for d in &study.differences {
        assert!(d.displacement_relative < 1e-9, "{d:?}");
    }

    // Upright, released by 0.01 rad: δθ = 0.01 cosh(σt), σ = √(g/l), to its default end
    // time, when it has grown by e⁵.
    let pendulum = Pendulum::default();
    let sigma = pendulum.natural_frequency();
    let model = boxed(pendulum);
    let options = FreeResponseOptions {
        operating_point: OperatingPointOptions {
            start: EquilibriumStart::Named("upright".into()),
            t: 0.0,
        },
        initial: Some(InitialDeviation {
            q: vec![0.01],
            qdot: vec![0.0],
        }),
        ..FreeResponseOptions::default()
    };
    let study = free_response(model.as_ref(), &options).unwrap();
    assert!(close(study.t_end, 5.0 / sigma, 1e-12), "{}", study.t_end);
    for (method, response) in &study.responses {
        let worst = response
            .times
            .iter()
            .zip(&response.displacements)
            .map(|(t, q)| (q[0] - 0.01 * (sigma * t).cosh()).abs())
            .fold(0.0f64, f64::max);
        assert!(
            worst < 1e-9 * study.max_displacement,
            "{}: {worst:e}",
            method.name()
        );
    }
}

/// `modal_damping_study` with proportional damping: exact, diagonal and Rayleigh ratios all
/// `β ω_k/2` (1e-12), the fit `α = 0`, `β` (1e-12), and the modal responses equal to `e^{At}`
/// (1e-9: rounding of `e^{At}` over 10 periods; DOP853 at 1e-12, 1e-8). Non-proportional
/// damping (`c2 = 0`): the exact eigenvalues are those of the state matrix assembled from the
/// closed-form `M`, `C`, `K` (1e-10), and the diagonal approximation, which drops the modal
/// coupling, visibly departs from the exact response.
#[test]
fn modal_damping_study_proportional_and_not() {
    let chain = proportionally_damped_chain();
    let model = boxed(chain.clone());
    let study = modal_damping_study(model.as_ref(), &ModalDampingOptions::default()).unwrap();
    let (w2, _) = chain.modes();
    for (k, mode) in study.modes.iter().enumerate() {
        let zeta = BETA * w2[k].sqrt() / 2.0;
        let exact = mode.exact.unwrap().damping_ratio;
        let diagonal = mode.diagonal.unwrap().damping_ratio;
        let rayleigh = mode.rayleigh.unwrap().damping_ratio;
        for (name, value) in [
            ("exact", exact),
            ("diagonal", diagonal),
            ("rayleigh", rayleigh),
        ] {
            assert!(
                close(value, zeta, 1e-12),
                "mode {k} {name}: {value} vs {zeta}"
            );
        }
    }
    let fit = study.rayleigh.unwrap();
    assert_eq!(fit.modes, [1, 2]);
    assert!(
        fit.damping.alpha.abs() < 1e-12 && close(fit.damping.beta, BETA, 1e-12),
        "{fit:?}"
    );
    assert_eq!(study.releases.len(), 2);
    for release in &study.releases {
        assert!(
            release.diagonal_vs_exact < 1e-9,
            "{}: {}",
            release.name,
            release.diagonal_vs_exact
        );
        assert!(
            release.integration_vs_exact < 1e-8,
            "{}: {}",
            release.name,
            release.integration_vs_exact
        );
    }

    let chain = TwoMassChain {
        c1: 0.4,
        ..TwoMassChain::default()
    };
    let model = boxed(chain.clone());
    let study = modal_damping_study(model.as_ref(), &ModalDampingOptions::default()).unwrap();
    let a = chain.state_matrix();
    let mut eigenvalues: Vec<Complex<f64>> = a
        .complex_eigenvalues()
        .iter()
        .copied()
        .filter(|s| s.im > 0.0)
        .collect();
    eigenvalues.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
    assert_eq!(eigenvalues.len(), 2, "{eigenvalues:?}");
    assert_eq!(study.modes.len(), 2);
    for (mode, s) in study.modes.iter().zip(&eigenvalues) {
        let exact = mode.exact.unwrap();
        assert!(
            (exact.eigenvalue - s).norm() < 1e-10 * s.norm(),
            "{} vs {s}",
            exact.eigenvalue
        );
        assert!(close(exact.damping_ratio, -s.re / s.norm(), 1e-10));
    }
    let coupled = study
        .releases
        .iter()
        .map(|r| r.diagonal_vs_exact)
        .fold(0.0f64, f64::max);
    eprintln!("non-proportional damping: diagonal approximation off by {coupled:.2e}");
    assert!(
        coupled > 1e-3,
        "the modal coupling left no mark: {coupled:e}"
    );
}

/// Lecture 21: `H(ω) = 1/(k − mω² + icω)` for `m ẍ + c ẋ + k x = A cos(ω t)`. Both sides are a
/// few floating-point operations on the same numbers, so 1e-12 relative leaves room only for
/// rounding.
#[test]
fn forced_oscillator_frf_matches_closed_form() {
    let mut m = boxed(ForcedOscillator::default());
    for (mass, c, k) in [(1.0, 1.0, 1.0), (2.0, 0.05, 7.0), (0.3, 3.0, 0.5)] {
        m.set_parameter("m", mass).unwrap();
        m.set_parameter("c", c).unwrap();
        m.set_parameter("k", k).unwrap();
        let f = forced(m.as_mut(), "A");
        assert_eq!(f.input_matrix, DMatrix::from_element(1, 1, 1.0));
        for w in [0.0, 0.1, 0.9, (k / mass).sqrt(), 3.0, 40.0] {
            let h = frequency_response(&f.linearization, &f.input_matrix, w).unwrap()[(0, 0)];
            let exact = Complex::new(1.0, 0.0) / Complex::new(k - mass * w * w, c * w);
            assert!(
                (h - exact).norm() <= 1e-12 * exact.norm(),
                "m = {mass}, c = {c}, k = {k}, ω = {w}: {h} vs {exact}"
            );
        }
        // The peak of |H|: ω_n √(1 − 2ζ²), height 1/(2ζ k √(1 − ζ²)) when ζ < 1/√2. The
        // height is exact to rounding; the location of a flat maximum only to ~√ε.
        let wn = (k / mass).sqrt();
        let zeta = c / (2.0 * (k * mass).sqrt());
        let freqs = log_frequencies(wn / 10.0, wn * 10.0, 200).unwrap();
        let sweep = frequency_sweep(&f.linearization, &f.input_matrix, 0, 0, &freqs).unwrap();
        if zeta < std::f64::consts::FRAC_1_SQRT_2 {
            assert_eq!(sweep.peaks.len(), 1, "{:?}", sweep.peaks);
            let peak = sweep.peaks[0];
            let w_peak = wn * (1.0 - 2.0 * zeta * zeta).sqrt();
            let h_peak = 1.0 / (2.0 * zeta * k * (1.0 - zeta * zeta).sqrt());
            assert!((peak.frequency - w_peak).abs() < 1e-7 * w_peak, "{peak:?}");
            assert_eq!(peak.amplitude, PeakAmplitude::Finite(peak_value(&peak)));
            assert!((peak_value(&peak) - h_peak).abs() < 1e-12 * h_peak);
        } else {
            assert!(sweep.peaks.is_empty(), "overdamped: {:?}", sweep.peaks);
        }
    }
}

fn peak_value(peak: &ResonancePeak) -> f64 {
    match peak.amplitude {
        PeakAmplitude::Finite(a) => a,
        PeakAmplitude::Unbounded => f64::INFINITY,
    }
}

/// `vibration::frequency_response_analysis` (what `eomgen frf` prints) on the forced
/// oscillator (m = k = 1, c = 1, ζ = 1/2): the peak at the closed-form √(1 − 2ζ²) = 1/√2
/// (1e-7: the maximum is flat) with height 1/(2ζ√(1 − ζ²)) = 2/√3 (1e-12); at ω = ω_n,
/// |H| = 1/(cω) = 1 and phase −90° (1e-12, 1e-10); one mode, so the modal sum is the response
/// (1e-14); two simulated points within 1e-6 of H (`plan_simulation`, `simulate_point`).
#[test]
fn frequency_response_analysis_of_the_forced_oscillator() {
    let mut m = boxed(ForcedOscillator {
        m: 1.0,
        c: 1.0,
        k: 1.0,
        a: 1.0,
        w: 1.0,
    });
    let simulation = FrfSimulationOptions {
        count: 2,
        ..FrfSimulationOptions::default()
    };
    let options = FrfOptions {
        input: "A".into(),
        outputs: vec!["x".into()],
        points: 60,
        frequencies: vec![1.0],
        modal: true,
        simulation: Some(simulation.clone()),
        ..FrfOptions::default()
    };
    let frf = frequency_response_analysis(m.as_mut(), &options).unwrap();
    assert_eq!(frf.frequencies.len(), 60);
    assert_eq!(frf.outputs[0].index, 0);
    let peak = frf.sweeps[0].peaks[0];
    assert!((peak.frequency - 0.5f64.sqrt()).abs() < 1e-7);
    assert!((peak_value(&peak) - 2.0 / 3f64.sqrt()).abs() < 1e-12);
    let at = &frf.evaluations[0];
    let h = at.response.as_ref().unwrap()[0];
    assert!((h.norm() - 1.0).abs() < 1e-12);
    assert!((phase_degrees(h) + 90.0).abs() < 1e-10);
    assert!(at.modal_difference.unwrap() < 1e-14);
    let plan = plan_simulation(m.as_ref(), &frf, &simulation).unwrap();
    assert_eq!(plan.frequency_parameter, "w");
    assert_eq!(plan.frequencies.len(), 2);
    let points: Vec<_> = plan
        .frequencies
        .iter()
        .map(|&w| simulate_point(m.as_mut(), &frf, &plan, w).unwrap())
        .collect();
    assert!(max_simulation_error(&points) < 1e-6);
    for p in &points {
        assert!(p.values[0].relative_error() < 1e-6, "{p:?}");
    }
}

/// The chain forced on mass 2: `H(ω)` of both masses against Cramer's rule (1e-12 of the
/// largest entry), the same from the load `A` and from a unit force on the coordinate `x2`,
/// and each peak of `x2` a local maximum of the closed-form `|H|` with its height.
#[test]
fn frequency_response_of_the_chain_against_cramer() {
    let chain = proportionally_damped_chain();
    let mut model = boxed(chain.clone());
    let frequencies = vec![0.5, 1.7, 4.0];
    for input in ["A", "x2"] {
        let options = FrfOptions {
            input: input.into(),
            frequencies: frequencies.clone(),
            ..FrfOptions::default()
        };
        let frf = frequency_response_analysis(model.as_mut(), &options).unwrap();
        assert_eq!(frf.evaluations.len(), frequencies.len());
        for e in &frf.evaluations {
            let h = e.response.as_ref().unwrap();
            let exact = chain.receptance(e.frequency);
            let scale = exact[0].norm().max(exact[1].norm());
            for i in 0..2 {
                assert!(
                    (h[i] - exact[i]).norm() < 1e-12 * scale,
                    "{input}, ω = {}, x{}: {} vs {}",
                    e.frequency,
                    i + 1,
                    h[i],
                    exact[i]
                );
            }
        }
        let peaks = &frf.sweeps[1].peaks;
        assert_eq!(peaks.len(), 2, "{peaks:?}");
        for peak in peaks {
            let w = peak.frequency;
            let height = chain.receptance(w)[1].norm();
            assert!(
                matches!(peak.amplitude, PeakAmplitude::Finite(h) if close(h, height, 1e-12)),
                "{peak:?}"
            );
            for side in [w * (1.0 - 1e-4), w * (1.0 + 1e-4)] {
                assert!(
                    chain.receptance(side)[1].norm() < height,
                    "not a maximum at {w}"
                );
            }
        }
    }
}

/// `ẏ = A y` with the exact Jacobian `A`.
struct Linear(DMatrix<f64>);

impl OdeSystem for Linear {
    fn dim(&self) -> usize {
        self.0.nrows()
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        for (i, d) in dy.iter_mut().enumerate() {
            *d = self.0.row(i).iter().zip(y).map(|(a, b)| a * b).sum();
        }
        Ok(())
    }
    fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        jac.copy_from_slice(self.0.as_slice());
        Ok(true)
    }
}

/// The damped Mathieu equation `ẍ + 2ζ ẋ + (δ + ε cos t) x = 0`, period 2π, written by hand.
struct Mathieu {
    delta: f64,
    epsilon: f64,
    zeta: f64,
}

impl OdeSystem for Mathieu {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = y[1];
        dy[1] = -2.0 * self.zeta * y[1] - (self.delta + self.epsilon * t.cos()) * y[0];
        Ok(())
    }
    fn jacobian(&mut self, t: f64, _y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        // Column-major [0 1; −(δ + ε cos t) −2ζ].
        jac.copy_from_slice(&[
            0.0,
            -(self.delta + self.epsilon * t.cos()),
            1.0,
            -2.0 * self.zeta,
        ]);
        Ok(true)
    }
}

/// `floquet_analysis` for constant coefficients: `Φ(T) = e^{AT}` for a hand-written 4 × 4 `A`
/// (a damped, gyroscopic two-mass system), with `det Φ = e^{T tr A}`. Tolerance 1e-10
/// relative to `‖Φ‖`: DOP853 at 1e-12 over one period leaves a global error of order 1e-11;
/// the scaled Padé approximant is exact to rounding.
#[test]
fn monodromy_of_a_constant_coefficient_system_is_the_matrix_exponential() {
    #[rustfmt::skip]
    let a = DMatrix::from_row_slice(4, 4, &[
        0.0, 0.0, 1.0, 0.0,
        0.0, 0.0, 0.0, 1.0,
        -3.0, 1.0, -0.2, 0.5,
        1.0, -2.0, -0.5, -0.1,
    ]);
    let period = 1.7;
    let f = floquet_analysis(
        &mut Linear(a.clone()),
        &[0.0; 4],
        0.3,
        period,
        &FloquetOptions::default(),
    )
    .unwrap();
    let expected = matrix_exponential(&(&a * period));
    let err = (&f.monodromy_matrix - &expected).amax() / expected.amax();
    eprintln!("hand-written A: |Φ(T) − e^(AT)|/|e^(AT)| = {err:.1e}");
    assert!(err < 1e-10, "hand-written A: |Φ − e^(AT)| = {err:e}");
    // Liouville: det e^{AT} = e^{T tr A}.
    let det = (period * a.trace()).exp();
    assert!(
        (f.determinant - det).abs() < 1e-10 * det,
        "{} vs {det}",
        f.determinant
    );
    assert_eq!(f.stability, FloquetStability::AsymptoticallyStable);
}

/// Liouville's formula `det Φ(T) = exp ∫ tr J dt` for `floquet_analysis` of the Mathieu
/// equation written by hand: 1 undamped (the product of its multipliers), `e^{−2ζT}` with
/// damping. Tolerance 1e-10: the integration error of DOP853 at 1e-12 over one period.
#[test]
fn liouville_determinant_of_the_mathieu_equation() {
    for (delta, epsilon) in [(0.3, 0.2), (1.0, 0.5), (-0.2, 1.0), (2.5, 3.0)] {
        let f = floquet_analysis(
            &mut Mathieu {
                delta,
                epsilon,
                zeta: 0.0,
            },
            &[0.0, 0.0],
            0.0,
            TAU,
            &FloquetOptions::default(),
        )
        .unwrap();
        let product = f.multipliers[0] * f.multipliers[1];
        eprintln!(
            "Mathieu δ = {delta}, ε = {epsilon}: μ = {:.6}, {:.6}; |μ₁μ₂ − 1| = {:.1e}",
            f.multipliers[0],
            f.multipliers[1],
            (product - 1.0).norm()
        );
        assert!(
            (product.re - 1.0).abs() < 1e-10 && product.im.abs() < 1e-10,
            "δ = {delta}, ε = {epsilon}: μ₁μ₂ = {product}"
        );
        assert!((f.determinant - 1.0).abs() < 1e-10);
        assert!(f.stability != FloquetStability::AsymptoticallyStable);
    }
    let zeta = 0.05;
    let f = floquet_analysis(
        &mut Mathieu {
            delta: 0.3,
            epsilon: 0.2,
            zeta,
        },
        &[0.0, 0.0],
        0.0,
        TAU,
        &FloquetOptions::default(),
    )
    .unwrap();
    let det = (-2.0 * zeta * TAU).exp();
    assert!(
        (f.determinant - det).abs() < 1e-10,
        "{} vs {det}",
        f.determinant
    );
}

/// `floquet_at_equilibrium` on the shaken pendulum hanging (Mathieu's equation, `q = 2a/l =
/// 0.1`): at `δ = 1` (`w = 2√(g/l)`, the first Ince–Strutt tongue) unstable with
/// `ln ρ = π q/2` to 2 % (first-order perturbation theory, next terms `O(q²)` relative); at
/// `δ = 1/4` marginal, `|ρ − 1| < 1e-6` (the stability tolerance); Liouville's
/// `det Φ(T) = 1` undamped and `e^{−cT/(m l²)}` damped, to 1e-10 (DOP853 at 1e-12 over one
/// period). Unshaken, the model has no period and is refused as a point; as a chart's cell
/// it is analysed.
#[test]
fn floquet_multipliers_of_the_shaken_pendulum() {
    let base = Pendulum::default();
    let omega = base.natural_frequency();
    let q = 0.1;
    let shaken = |w: f64, c: f64| {
        boxed(Pendulum {
            a: q * base.l / 2.0,
            w,
            c,
            ..base.clone()
        })
    };
    let options = FloquetStudyOptions::default();

    let mut resonant = shaken(2.0 * omega, 0.0);
    let point = floquet_at_equilibrium(resonant.as_mut(), &options).unwrap();
    assert_eq!(point.name, "hanging");
    let f = &point.floquet;
    assert_eq!(f.stability, FloquetStability::Unstable);
    let expected = PI * q / 2.0;
    eprintln!(
        "δ = 1, q = {q}: ln ρ = {:.6}, first order {expected:.6}",
        f.spectral_radius.ln()
    );
    assert!(
        (f.spectral_radius.ln() - expected).abs() < 0.02 * expected,
        "ln ρ = {}",
        f.spectral_radius.ln()
    );
    assert!(
        (f.determinant - 1.0).abs() < 1e-10,
        "det Φ = {}",
        f.determinant
    );

    let mut detuned = shaken(4.0 * omega, 0.0);
    let f = floquet_at_equilibrium(detuned.as_mut(), &options)
        .unwrap()
        .floquet;
    assert_eq!(f.stability, FloquetStability::Marginal);
    assert!(
        (f.spectral_radius - 1.0).abs() < 1e-6,
        "ρ = {}",
        f.spectral_radius
    );
    assert!(
        (f.determinant - 1.0).abs() < 1e-10,
        "det Φ = {}",
        f.determinant
    );

    let c = 0.5;
    let mut damped = shaken(4.0 * omega, c);
    let f = floquet_at_equilibrium(damped.as_mut(), &options)
        .unwrap()
        .floquet;
    let det = (-c * TAU / (4.0 * omega) / (base.m * base.l * base.l)).exp();
    assert!(
        (f.determinant - det).abs() < 1e-10,
        "det Φ = {} vs {det}",
        f.determinant
    );
    assert_eq!(f.stability, FloquetStability::AsymptoticallyStable);

    let mut still = boxed(base.clone());
    let refused = floquet_at_equilibrium(still.as_mut(), &options);
    assert!(
        matches!(refused, Err(FloquetStudyError::TimeIndependent { .. })),
        "{refused:?}"
    );

    // A chart's cells: the unshaken column (`a = 0`) is analysed as it is, its upright
    // multiplier `e^{σT}`, `σ = √(g/l)`, `T = 2π/w` (1e-8 relative: DOP853 at 1e-12 over a
    // growth of e^{1.6}); the resonant cell is unstable as the point above.
    let w = 4.0 * omega;
    let cell = floquet_cell(still.as_mut(), &[PI], &[("a", 0.0), ("w", w)], &options).unwrap();
    let growth = (omega * TAU / w).exp();
    assert!(
        (cell.spectral_radius - growth).abs() < 1e-8 * growth,
        "ρ = {} vs {growth}",
        cell.spectral_radius
    );
    assert_eq!(cell.stability, FloquetStability::Unstable);
    let values = [("a", q * base.l / 2.0), ("w", 2.0 * omega)];
    let cell = floquet_cell(still.as_mut(), &[0.0], &values, &options).unwrap();
    assert_eq!(cell.stability, FloquetStability::Unstable);
    assert!((cell.spectral_radius.ln() - expected).abs() < 0.02 * expected);
}

/// The eigenvalues of a badly scaled chain (masses 1e-3…2 kg, springs 0.5…1e6 N/m, between
/// two walls; undamped, then with a dashpot beside each spring) against 60-digit references
/// (`tools/scaled_chain_eigenvalues.py`, mpmath). Each computed eigenvalue is within 1e-12
/// of its reference's own size — the refinement's accuracy; the Schur values alone err by
/// `ε ‖A‖`, 4e-8 of the slowest mode here — and the undamped ones lie on the imaginary
/// axis, so the verdict is "marginally stable", the damped one "stable".
#[test]
fn scaled_chain_eigenvalues_match_a_high_precision_reference() {
    use eomgen_runtime::{Linearization, Stability, linear_stability};
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/scaled_chain.json"
    ))
    .unwrap();
    let data: serde_json::Value = serde_json::from_str(&text).unwrap();
    let matrix = |key: &str| {
        let rows: Vec<Vec<f64>> = serde_json::from_value(data[key].clone()).unwrap();
        DMatrix::from_fn(rows.len(), rows.len(), |i, j| rows[i][j])
    };
    let masses: Vec<f64> = serde_json::from_value(data["masses"].clone()).unwrap();
    let m = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(masses));
    let (k, c) = (matrix("stiffness_matrix"), matrix("damping_matrix"));
    let n = m.nrows();
    for (case, damping) in [("undamped", DMatrix::zeros(n, n)), ("damped", c)] {
        let reference: Vec<[f64; 2]> = serde_json::from_value(data[case].clone()).unwrap();
        let lin = Linearization::from_matrices(m.clone(), k.clone(), damping);
        let s = linear_stability(&lin).unwrap();
        assert_eq!(s.eigenvalues.len(), reference.len(), "{case}");
        let mut worst: f64 = 0.0;
        for [re, im] in &reference {
            let r = Complex::new(*re, *im);
            let nearest = s
                .eigenvalues
                .iter()
                .map(|e| (e - r).norm() / r.norm())
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(nearest);
        }
        assert!(worst <= 1e-12, "{case}: worst relative error {worst:e}");
        match (case, s.stability) {
            ("undamped", Stability::MarginallyStable) => {
                assert!(s.eigenvalues.iter().all(|e| e.re == 0.0))
            }
            ("damped", Stability::Stable { decay_rate }) => {
                // The slowest decay, to 1e-12 of its eigenvalue's modulus (as every value).
                let (slowest, size) = reference
                    .iter()
                    .map(|e| (-e[0], e[0].hypot(e[1])))
                    .fold((f64::INFINITY, 0.0), |a, b| if b.0 < a.0 { b } else { a });
                assert!(
                    (decay_rate - slowest).abs() <= 1e-12 * size,
                    "{decay_rate} {slowest}"
                );
            }
            other => panic!("{other:?}"),
        }
    }
}
