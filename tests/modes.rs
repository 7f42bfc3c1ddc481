//! Equilibria, exact linearisation and normal modes (issue 7, items 1–3) against analytic
//! frequencies and independent hand derivations.

use crate::common;
use common::{eomgen, eomgen_ok};
use rand::RngExt;

use eomgen::{
    ModalError, ModeKind, ModelInfo, eigenvalues_of_m_inv_k, find_equilibrium, linearize,
    normal_modes,
};
use nalgebra::{DMatrix, Matrix2};

fn model(name: &str) -> Box<dyn ModelInfo> {
    (eomgen::models::find(name).expect("bundled model").make)()
}

fn guess(model: &dyn ModelInfo, name: &str) -> Vec<f64> {
    model
        .equilibrium_guesses()
        .into_iter()
        .find(|(n, _)| *n == name)
        .unwrap_or_else(|| panic!("{} names `{name}`", model.description().name))
        .1
}

/// Natural frequencies (rad/s), mode shapes and the linearisation at a named equilibrium.
fn modes_at(
    name: &str,
    at: &str,
) -> (
    Vec<f64>,
    DMatrix<f64>,
    eomgen::Linearization,
    eomgen::NormalModes,
) {
    let m = model(name);
    let q = find_equilibrium(m.as_ref(), &guess(m.as_ref(), at), 0.0)
        .unwrap()
        .q;
    let lin = linearize(m.as_ref(), &q, &vec![0.0; q.len()], 0.0).unwrap();
    let modes = normal_modes(&lin).unwrap();
    (
        modes.natural_frequencies.clone(),
        modes.mode_shapes.clone(),
        lin,
        modes,
    )
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

/// ΨᵀMΨ = I to 1e-12 (Cholesky reduction in double precision on matrices of order 1).
fn assert_mass_normalised(shapes: &DMatrix<f64>, m: &DMatrix<f64>) {
    let g = shapes.transpose() * m * shapes;
    let err = (g - DMatrix::identity(m.nrows(), m.nrows())).amax();
    assert!(err < 1e-12, "ΨᵀMΨ − I = {err:e}");
}

/// HW23: three equal masses, four springs: ω = √(2 − √2), √2, √(2 + √2) · √(k/m) with shapes
/// [1, √2, 1], [1, 0, −1], [1, −√2, 1]. Exact arithmetic would give equality; 1e-12 allows
/// for the symmetric eigensolver's rounding.
#[test]
fn three_masses_analytic_frequencies_and_shapes() {
    let (w, shapes, lin, _) = modes_at("three_masses", "rest");
    let s2 = 2f64.sqrt();
    for (wi, exact) in w.iter().zip([(2.0 - s2).sqrt(), s2, (2.0 + s2).sqrt()]) {
        assert!(close(*wi, exact, 1e-12), "{wi} vs {exact}");
    }
    assert_mass_normalised(&shapes, &lin.mass_matrix);
    for (k, exact) in [[1.0, s2, 1.0], [1.0, 0.0, -1.0], [1.0, -s2, 1.0]]
        .iter()
        .enumerate()
    {
        let psi = shapes.column(k);
        let ratio = psi[0] / exact[0];
        for i in 0..3 {
            assert!(
                (psi[i] - ratio * exact[i]).abs() < 1e-12,
                "mode {k}: {psi:?}"
            );
        }
    }
}

/// HW27–28: the cart–pendulum has one zero-frequency mode (the cart's free translation) and
/// ω² = g (m1 + m2)/(m1 ℓ) = 20 1/s².
#[test]
fn cart_pendulum_zero_mode_and_swing() {
    let (w, shapes, lin, modes) = modes_at("cart_pendulum", "hanging");
    assert_eq!(modes.kinds[0], ModeKind::ZeroFrequency);
    assert_eq!(w[0], 0.0);
    assert!(close(w[1], 20f64.sqrt(), 1e-12));
    assert_mass_normalised(&shapes, &lin.mass_matrix);
    // The zero mode is a pure translation of the whole (θ = 0).
    assert!(shapes[(1, 0)].abs() < 1e-12);
}

/// The double pendulum of two uniform bars (m = 1, ℓ = 1, g = 10) hanging: M and K derived by
/// hand (T = ½(m1/3 + m2) ℓ1² θ̇1² + ½ m2 ℓ1 ℓ2 cos(θ1 − θ2) θ̇1 θ̇2 + ⅙ m2 ℓ2² θ̇2², V from the
/// bars' centres), ω² the roots of det(K − ω² M) = 0; upright, K changes sign so the same
/// numbers become growth rates.
#[test]
fn double_pendulum_hanging_and_upright() {
    let (m1, m2, l1, l2, g): (f64, f64, f64, f64, f64) = (1.0, 1.0, 1.0, 1.0, 10.0);
    let mh = Matrix2::new(
        (m1 / 3.0 + m2) * l1 * l1,
        m2 * l1 * l2 / 2.0,
        m2 * l1 * l2 / 2.0,
        m2 * l2 * l2 / 3.0,
    );
    let kh = Matrix2::new((m1 / 2.0 + m2) * g * l1, 0.0, 0.0, m2 * g * l2 / 2.0);
    // det(K − λM) = a λ² + b λ + c.
    let a = mh.determinant();
    let b = -(kh[(0, 0)] * mh[(1, 1)] + kh[(1, 1)] * mh[(0, 0)]);
    let c = kh.determinant();
    let disc = (b * b - 4.0 * a * c).sqrt();
    let exact = [
        ((-b - disc) / (2.0 * a)).sqrt(),
        ((-b + disc) / (2.0 * a)).sqrt(),
    ];
    let (w, shapes, lin, _) = modes_at("double_pendulum", "hanging");
    for (wi, e) in w.iter().zip(exact) {
        assert!(close(*wi, e, 1e-12), "{wi} vs {e}");
    }
    assert!(
        (lin.mass_matrix.clone() - DMatrix::from_row_slice(2, 2, mh.as_slice())).amax() < 1e-14
    );
    assert_mass_normalised(&shapes, &lin.mass_matrix);
    let (_, _, _, upright) = modes_at("double_pendulum", "upright");
    let mut rates: Vec<f64> = upright
        .kinds
        .iter()
        .map(|k| match k {
            ModeKind::Unstable { growth_rate } => *growth_rate,
            other => panic!("upright should be unstable: {other:?}"),
        })
        .collect();
    rates.sort_by(f64::total_cmp);
    for (r, e) in rates.iter().zip(exact) {
        assert!(close(*r, e, 1e-12));
    }
}

/// One-degree-of-freedom classics: compound pendulum ω² = m g d/(I + m d²) = 15; bead on
/// y = c x², ω = √(2 g c); cylinder rolling in a cylinder (HW26), ω² = 2 g/(3 (R − r)).
#[test]
fn single_dof_frequencies() {
    for (name, at, exact) in [
        ("compound_pendulum", "hanging", 15f64.sqrt()),
        ("bead_parabola", "bottom", 20f64.sqrt()),
        (
            "rolling_in_cylinder",
            "bottom",
            (2.0 * 10.0 / (3.0 * 0.8f64)).sqrt(),
        ),
        ("simple_pendulum", "hanging", 10f64.sqrt()),
    ] {
        let (w, _, _, _) = modes_at(name, at);
        assert!(close(w[0], exact, 1e-12), "{name}: {} vs {exact}", w[0]);
    }
}

/// Both routes to the frequencies agree: eigenvalues of the non-symmetric M⁻¹K (lecture 22)
/// and the symmetric Cholesky reduction (lecture 24), to 1e-12 of the largest.
#[test]
fn m_inverse_k_and_symmetric_routes_agree() {
    for (name, at) in [
        ("triple_pendulum", "hanging"),
        ("double_pendulum", "upright"),
        ("three_masses", "rest"),
    ] {
        let (_, _, lin, modes) = modes_at(name, at);
        let other = eigenvalues_of_m_inv_k(&lin).unwrap();
        let scale = modes.eigenvalues.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, b) in modes.eigenvalues.iter().zip(&other) {
            assert!((a - b).abs() < 1e-12 * scale, "{name}: {a} vs {b}");
        }
        assert!(modes.stiffness_asymmetry < 1e-14, "{name}");
    }
}

/// Newton finds the equilibrium from a rough guess; a model without one (the cannonball
/// falls forever) and a constrained one are clear errors.
#[test]
fn equilibrium_search_and_its_errors() {
    let m = model("triple_pendulum");
    let e = find_equilibrium(m.as_ref(), &[-1.2, -2.0, -1.3], 0.0).unwrap();
    for q in &e.q {
        assert!((q + std::f64::consts::FRAC_PI_2).abs() < 1e-12, "{:?}", e.q);
    }
    assert!(e.iterations > 0 && e.residual < 1e-10);
    // The cannonball's forces at rest, [0, −mg], do not depend on q: Newton says so.
    let ball = model("cannonball");
    let err = find_equilibrium(ball.as_ref(), &vec![0.0; ball.num_dofs()], 0.0).unwrap_err();
    assert!(
        matches!(
            err,
            ModalError::EquilibriumNotFound {
                reason: eomgen::NewtonStop::ZeroJacobian,
                ..
            }
        ),
        "{err}"
    );
    let bar = model("four_bar");
    let err = find_equilibrium(bar.as_ref(), &vec![0.0; bar.num_dofs()], 0.0).unwrap_err();
    assert!(
        matches!(err, ModalError::EquilibriumNotFound { .. }),
        "{err}"
    );
    let sleigh = model("chaplygin_sleigh");
    let err = find_equilibrium(sleigh.as_ref(), &vec![0.0; sleigh.num_dofs()], 0.0).unwrap_err();
    assert!(matches!(err, ModalError::NonHolonomic { .. }), "{err}");
}

/// The library's operating point: the file's first name by default, a named equilibrium, an
/// explicit guess, and its typed errors (an unknown name lists the known ones).
#[test]
fn operating_point_from_names_and_guesses() {
    use eomgen::analysis::vibration::{
        EquilibriumStart, OperatingPointError, OperatingPointOptions, operating_point,
    };
    let m = model("double_pendulum");
    let at = |start: EquilibriumStart| {
        operating_point(
            m.as_ref(),
            &OperatingPointOptions {
                start,
                ..OperatingPointOptions::default()
            },
        )
    };
    let half_pi = std::f64::consts::FRAC_PI_2;
    let first = at(EquilibriumStart::FirstNamed).unwrap();
    assert_eq!(first.name, "hanging");
    assert_eq!(first.coordinates, ["theta1", "theta2"]);
    assert!(first.q().iter().all(|q| (q + half_pi).abs() < 1e-12));
    let up = at(EquilibriumStart::Named("upright".into())).unwrap();
    assert!(up.q().iter().all(|q| (q - half_pi).abs() < 1e-12));
    let guessed = at(EquilibriumStart::Guess {
        label: "near upright".into(),
        q: vec![1.4, 1.7],
    })
    .unwrap();
    assert_eq!(guessed.name, "near upright");
    assert_eq!(guessed.guess, [1.4, 1.7]);
    assert!(guessed.q().iter().all(|q| (q - half_pi).abs() < 1e-12));
    let err = at(EquilibriumStart::Named("sideways".into())).unwrap_err();
    assert_eq!(
        err,
        OperatingPointError::UnknownEquilibrium {
            model: "double_pendulum".into(),
            name: "sideways".into(),
            known: vec!["hanging".into(), "upright".into()],
        }
    );
    let err = at(EquilibriumStart::Guess {
        label: "short".into(),
        q: vec![0.0],
    })
    .unwrap_err();
    assert!(matches!(
        err,
        OperatingPointError::Modal(ModalError::DimensionMismatch {
            expected: 2,
            found: 1
        })
    ));
    // No `equilibria:` in the file: Newton from q = 0, under that name.
    let mut oscillator = model("forced_oscillator");
    oscillator.set_parameter("A", 0.0).unwrap();
    let point = operating_point(oscillator.as_ref(), &OperatingPointOptions::default()).unwrap();
    assert_eq!(point.name, "q = 0");
    assert_eq!(point.q(), [0.0]);
    let json = serde_json::to_value(&point).unwrap();
    assert_eq!(json["equilibrium"]["q"], serde_json::json!([0.0]));
}

/// `modal_analysis` (what `eomgen modes` prints) on three_masses_damped: the damping ratios
/// are the file's reference values (numpy, 1e-7). (A constrained model:
/// `runtime/tests/vibration.rs`.)
#[test]
fn modal_analysis_damped() {
    use eomgen::analysis::vibration::{ModalOptions, modal_analysis};
    let m = model("three_masses_damped");
    let modal = modal_analysis(m.as_ref(), &ModalOptions::default()).unwrap();
    assert!(!modal.is_undamped());
    for (zeta, reference) in modal
        .damping_ratios
        .iter()
        .zip([0.0163291, 0.0177219, 0.00673228])
    {
        assert!((zeta - reference).abs() < 1e-7, "{zeta} vs {reference}");
    }
    // ΨᵀMΨ = I in the model's coordinates (no constraints: N = I).
    assert_mass_normalised(&modal.mode_shape_matrix(), &modal.linearization.mass_matrix);
    let json = serde_json::to_value(&modal).unwrap();
    assert_eq!(json["normal_modes"]["kinds"][0]["kind"], "oscillatory");
    assert_eq!(json["linearization"]["mass_matrix"][1][1], 1.0);
}

#[test]
fn modes_cli_json_contract_and_errors() {
    let out = eomgen_ok(&["modes", "cart_pendulum", "--at", "hanging", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["model"], "cart_pendulum");
    assert_eq!(v["operating_point"]["name"], "hanging");
    assert_eq!(v["natural_frequencies"].as_array().unwrap().len(), 2);
    assert_eq!(v["damping_ratios"].as_array().unwrap().len(), 2);
    assert_eq!(v["mode_shapes"].as_array().unwrap().len(), 2);
    assert_eq!(v["kinds"][0]["kind"], "zero_frequency");
    let out = eomgen(&["modes", "double_pendulum", "--at", "sideways"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("it names: hanging, upright"));
    let out = eomgen(&[
        "modes",
        "double_pendulum",
        "--at",
        "theta1=-1.4,theta2=-1.7",
    ]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("theta1 = -1.570796326795,"));
    // A constrained model: shapes in all n coordinates, one per minimal coordinate.
    let out = eomgen(&["modes", "simple_pendulum_cartesian", "--json"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["minimal_coordinates"], serde_json::json!(["x"]));
    assert_eq!(v["mode_shapes"].as_array().unwrap().len(), 1);
    assert_eq!(v["mode_shapes"][0].as_array().unwrap().len(), 2);
    assert!(v["lagrange_multipliers"]["rod"].is_number());
}

/// HW32: e^{At} against an independent closed form and against integration. A = S D S⁻¹ with
/// a random well-conditioned S and eigenvalues D (complex pairs written as 2 × 2 real
/// blocks [σ ω; −ω σ], whose exponential is e^{σt}[cos ωt sin ωt; −sin ωt cos ωt]) gives
/// e^{At} = S e^{Dt} S⁻¹ exactly; DOP853 at tol 1e-13 integrates ẏ = A y; the eigenvectors of
/// A superpose e^{λt} v (`state_response_by_eigenvectors`). All four agree to
/// 1e-10 relative to the largest entry (the issue's tolerance; the Padé approximant is
/// accurate to ~1e-15 times the condition of S).
#[test]
fn matrix_exponential_against_closed_form_and_integration() {
    use eomgen::{DormandPrince853, Integrator, IntegratorOptions, OdeFn, OutputTimes};
    let mut rng = common::seeded_rng(0x2545_f491_4f6c_dd1d);
    let mut uniform = move || rng.random_range(-1.0..1.0);
    let n = 10;
    let s = DMatrix::from_fn(n, n, |i, j| uniform() + if i == j { 3.0 } else { 0.0 });
    let s_inv = s.clone().try_inverse().unwrap();
    let t = 1.7;
    let mut d = DMatrix::zeros(n, n);
    let mut exp_dt = DMatrix::zeros(n, n);
    for b in 0..n / 2 {
        let (sigma, omega) = (-0.3 * b as f64 + 0.2 * uniform(), 1.0 + 2.0 * b as f64);
        let k = 2 * b;
        d[(k, k)] = sigma;
        d[(k + 1, k + 1)] = sigma;
        d[(k, k + 1)] = omega;
        d[(k + 1, k)] = -omega;
        let e = (sigma * t).exp();
        exp_dt[(k, k)] = e * (omega * t).cos();
        exp_dt[(k + 1, k + 1)] = e * (omega * t).cos();
        exp_dt[(k, k + 1)] = e * (omega * t).sin();
        exp_dt[(k + 1, k)] = -e * (omega * t).sin();
    }
    let a = &s * &d * &s_inv;
    let exact = &s * &exp_dt * &s_inv;
    let expm = eomgen::matrix_exponential(&(&a * t));
    let scale = exact.amax();
    assert!(
        (&expm - &exact).amax() < 1e-10 * scale,
        "{:e}",
        (&expm - &exact).amax()
    );
    // Superposition of the complex eigenvector solutions e^{λt} v (lectures 32–33), with
    // eigenvectors computed from A alone, column by column of e^{At}.
    for j in 0..n {
        let y0: Vec<f64> = (0..n).map(|i| if i == j { 1.0 } else { 0.0 }).collect();
        let y = eomgen::state_response_by_eigenvectors(&a, &y0, &[t]).unwrap();
        for i in 0..n {
            assert!(
                (y[0][i] - exact[(i, j)]).abs() < 1e-10 * scale,
                "eigenvectors ({i}, {j})"
            );
        }
    }
    let a_rhs = a.clone();
    let mut system = OdeFn::new(n, move |_t: f64, y: &[f64], dy: &mut [f64]| {
        let v = &a_rhs * nalgebra::DVector::from_column_slice(y);
        dy.copy_from_slice(v.as_slice());
    });
    let options = IntegratorOptions::default()
        .with_rtol(1e-13)
        .with_atol(1e-13);
    for j in [0, 5, 9] {
        let y0: Vec<f64> = (0..n).map(|i| if i == j { 1.0 } else { 0.0 }).collect();
        let sol = DormandPrince853::new()
            .integrate(
                &mut system,
                0.0,
                &y0,
                t,
                &OutputTimes::At(vec![t]),
                &options,
            )
            .unwrap();
        for i in 0..n {
            assert!(
                (sol.state(0)[i] - expm[(i, j)]).abs() < 1e-10 * scale,
                "({i}, {j})"
            );
        }
    }
}

/// The Cartesian pendulum (HW12) linearised on its constraint: the rod tension's curvature
/// term λ∇²Φ is the whole stiffness, so ω = √(g/l) hanging and a growth rate √(g/l) upright;
/// λ = ±m g (tension hanging, compression upright). Exact in floating point up to rounding.
#[test]
fn cartesian_pendulum_linearised_on_its_constraint() {
    let m = model("simple_pendulum_cartesian");
    let (g, l, mass) = (10.0f64, 1.0f64, 1.0f64);
    let w = (g / l).sqrt();
    for (at, sign) in [("hanging", 1.0), ("upright", -1.0)] {
        let e = find_equilibrium(m.as_ref(), &guess(m.as_ref(), at), 0.0).unwrap();
        assert!((e.lagrange_multipliers[0] - sign * mass * g).abs() < 1e-12);
        let lin = linearize(m.as_ref(), &e.q, &[0.0, 0.0], 0.0).unwrap();
        assert_eq!(
            lin.independent_coordinates,
            vec![0],
            "x is the minimal coordinate"
        );
        let modes = normal_modes(&lin).unwrap();
        match (at, modes.kinds[0]) {
            ("hanging", ModeKind::Oscillatory) => {
                assert!((modes.natural_frequencies[0] - w).abs() < 1e-12 * w);
            }
            ("upright", ModeKind::Unstable { growth_rate }) => {
                assert!((growth_rate - w).abs() < 1e-12 * w);
            }
            other => panic!("unexpected mode {other:?}"),
        }
        // The shape in (x, y): horizontal, mass-normalised with the full M = m I.
        let psi = lin.to_coordinates(&modes.mode_shapes);
        assert!((psi[(0, 0)] - 1.0 / mass.sqrt()).abs() < 1e-12 && psi[(1, 0)].abs() < 1e-12);
    }
    // Off the constraint, the linearisation refuses.
    let err = linearize(m.as_ref(), &[0.0, -1.1], &[0.0, 0.0], 0.0).unwrap_err();
    assert!(matches!(err, ModalError::OffConstraints { .. }), "{err}");
}

/// The four-bar (HW39) at rest under gravity: its one mode from the projected linearisation
/// against an independent energy method written here by hand — the loop closed by Newton for
/// the coupler and rocker angles given the crank's, `V(θ1)` and the effective inertia
/// `m_eff(θ1) = Σ m|v_G|² + Iω²` per unit crank rate from the closure's derivative, and
/// `ω² = V''/m_eff` with `V''` by central differences (h = 1e-4: truncation ~1e-9, rounding
/// ~1e-8 relative), so the bound is 1e-6. `V'(θ1*) = 0` checks the equilibrium itself.
#[test]
fn four_bar_mode_matches_an_energy_method() {
    let m = model("four_bar");
    let e = find_equilibrium(m.as_ref(), &guess(m.as_ref(), "hanging"), 0.0).unwrap();
    let lin = linearize(m.as_ref(), &e.q, &[0.0; 3], 0.0).unwrap();
    assert_eq!(lin.num_minimal_coordinates(), 1);
    let modes = normal_modes(&lin).unwrap();
    let (l1, l2, l3, d, rho, g) = (0.2f64, 0.6f64, 0.5f64, 0.6f64, 1.0f64, 9.81f64);
    // Coupler and rocker angles closing the loop for crank angle a, from the guess (b, c).
    let close = |a: f64, mut b: f64, mut c: f64| -> (f64, f64) {
        for _ in 0..50 {
            let r1 = l1 * a.cos() + l2 * b.cos() - d - l3 * c.cos();
            let r2 = l1 * a.sin() + l2 * b.sin() - l3 * c.sin();
            let (j11, j12, j21, j22) = (-l2 * b.sin(), l3 * c.sin(), l2 * b.cos(), -l3 * c.cos());
            let det = j11 * j22 - j12 * j21;
            b -= (j22 * r1 - j12 * r2) / det;
            c -= (-j21 * r1 + j11 * r2) / det;
        }
        (b, c)
    };
    let potential = |a: f64| -> f64 {
        let (b, c) = close(a, e.q[1], e.q[2]);
        let y1 = l1 / 2.0 * a.sin();
        let y2 = l1 * a.sin() + l2 / 2.0 * b.sin();
        let y3 = l3 / 2.0 * c.sin();
        g * rho * (l1 * y1 + l2 * y2 + l3 * y3)
    };
    let a = e.q[0];
    let (b, c) = close(a, e.q[1], e.q[2]);
    // Rates per unit crank rate: l2 sin b ḃ − l3 sin c ċ = −l1 sin a, −l2 cos b ḃ + l3 cos c ċ = l1 cos a.
    let (j11, j12, j21, j22) = (l2 * b.sin(), -l3 * c.sin(), -l2 * b.cos(), l3 * c.cos());
    let (r1, r2) = (-l1 * a.sin(), l1 * a.cos());
    let det = j11 * j22 - j12 * j21;
    let bd = (j22 * r1 - j12 * r2) / det;
    let cd = (-j21 * r1 + j11 * r2) / det;
    let v1 = (l1 / 2.0).powi(2);
    let v2 = (l1 * a.sin() + l2 / 2.0 * b.sin() * bd).powi(2)
        + (l1 * a.cos() + l2 / 2.0 * b.cos() * bd).powi(2);
    let v3 = (l3 / 2.0 * cd).powi(2);
    let bar = |l: f64, v2: f64, w: f64| rho * l * v2 + rho * l.powi(3) / 12.0 * w * w;
    let m_eff = bar(l1, v1, 1.0) + bar(l2, v2, bd) + bar(l3, v3, cd);
    let h = 1e-4;
    let dv = (potential(a + h) - potential(a - h)) / (2.0 * h);
    let ddv = (potential(a + h) - 2.0 * potential(a) + potential(a - h)) / (h * h);
    assert!(dv.abs() < 1e-9, "V'(θ1*) = {dv:e}");
    let w_energy = (ddv / m_eff).sqrt();
    let w = modes.natural_frequencies[0];
    assert!(
        (w - w_energy).abs() < 1e-6 * w_energy,
        "{w} vs energy method {w_energy}"
    );
    // The minimal-coordinate mass is the effective inertia of the crank coordinate.
    assert_eq!(lin.independent_coordinates, vec![0]);
    assert!((lin.mass_matrix[(0, 0)] - m_eff).abs() < 1e-12 * m_eff);
}

eomgen::model!("fixtures/kepler_orbit.yaml");
eomgen::model!("fixtures/euler_top.yaml");

/// The path of a test fixture, for the CLI.
fn fixture(name: &str) -> String {
    format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Issue 28, item 2: `modes mathieu_pendulum --set a=0.01` froze t = 0 and reported an
/// oscillation at 5.10 rad/s where Floquet finds ρ = 1.39. The stiffness
/// `m l (g − a w² cos wt)` changes with t: refused, naming it. Without the shaking (a = 0)
/// nothing depends on t and upright grows as `e^{√(g/l) t}` (√10, to 1e-12).
#[test]
fn issue_28_parametric_excitation_is_refused() {
    use eomgen::analysis::vibration::{ModalOptions, OperatingPointError, modal_analysis};
    let mut m = model("mathieu_pendulum");
    m.set_parameter("a", 0.01).unwrap();
    let err = modal_analysis(m.as_ref(), &ModalOptions::default()).unwrap_err();
    assert!(
        matches!(
            err,
            OperatingPointError::Modal(ModalError::TimeDependent {
                part: eomgen::TimeDependentPart::StiffnessMatrix,
                ..
            })
        ),
        "{err}"
    );
    m.set_parameter("a", 0.0).unwrap();
    let modal = modal_analysis(m.as_ref(), &ModalOptions::default()).unwrap();
    assert!(modal.time_dependent_forcing.is_none());
    let ModeKind::Unstable { growth_rate } = modal.normal_modes.kinds[0] else {
        panic!("{:?}", modal.normal_modes.kinds)
    };
    assert!((growth_rate - 10f64.sqrt()).abs() < 1e-12);
    let out = eomgen(&["modes", "mathieu_pendulum", "--set", "a=0.01"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("depend on t") && err.contains("study floquet"),
        "{err}"
    );
}

/// Issue 28, item 2: `modes bead_spinning_rod` reported a zero frequency for a bead whose
/// distance grows as `cosh ωt`. Its rod is the rheonomic constraint `x sin wt − y cos wt`:
/// frozen at t = 0 it is a fixed frictionless rod (no stiffness), which drops the
/// centrifugal effect of the rotation. Refused, naming the constraint; the same bead in its
/// distance along the rod (`bead_spinning_rod_polar`, `r̈ = w² r`, no t in the equations)
/// has the unstable mode with growth rate `w` (to 1e-12).
#[test]
fn issue_28_rheonomic_constraint_is_refused() {
    use eomgen::analysis::vibration::{ModalOptions, OperatingPointError, modal_analysis};
    let m = model("bead_spinning_rod");
    let err = modal_analysis(m.as_ref(), &ModalOptions::default()).unwrap_err();
    let OperatingPointError::Modal(ModalError::TimeDependent {
        part:
            eomgen::TimeDependentPart::Constraint {
                name,
                jacobian_changes: true,
            },
        ..
    }) = &err
    else {
        panic!("{err}")
    };
    assert_eq!(name, "rod");
    let mut polar = model("bead_spinning_rod_polar");
    for w in [1.0, 2.5] {
        polar.set_parameter("w", w).unwrap();
        let modal = modal_analysis(polar.as_ref(), &ModalOptions::default()).unwrap();
        assert!(modal.time_dependent_forcing.is_none());
        let ModeKind::Unstable { growth_rate } = modal.normal_modes.kinds[0] else {
            panic!("{:?}", modal.normal_modes.kinds)
        };
        assert!((growth_rate - w).abs() < 1e-12 * w, "{growth_rate} vs {w}");
    }
    let out = eomgen(&["modes", "bead_spinning_rod"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("constraint `rod`"));
}

/// Issue 28, item 2: a load `A cos wt + B sin wt` enters neither M, C nor K, so the modes of
/// the unforced equations stand (`forced_oscillator`: ω = √(k/m), ζ = c/(2√(km)), to 1e-12;
/// HW37's three masses: ω² = (2 ∓ √2) k/m, 2k/m) and the load is reported as set aside:
/// its change `A (cos wt − 1) + B sin wt` is at most `|A| + √(A² + B²)`, and the equilibrium
/// balances its t = 0 value, `x* = A/k`.
#[test]
fn issue_28_time_dependent_load_is_set_aside() {
    use eomgen::analysis::vibration::{ModalOptions, modal_analysis};
    let mut m = model("forced_oscillator");
    for (mass, c, k, a, b) in [(1.0, 1.0, 1.0, 1.0, 0.0), (2.0, 0.3, 7.0, 0.5, 2.0)] {
        for (name, value) in [("m", mass), ("c", c), ("k", k), ("A", a), ("B", b)] {
            m.set_parameter(name, value).unwrap();
        }
        let modal = modal_analysis(m.as_ref(), &ModalOptions::default()).unwrap();
        let forcing = modal.time_dependent_forcing.as_ref().expect("a load in t");
        assert_eq!(forcing.coordinate, "x");
        assert!(forcing.largest_change > 0.1 && forcing.largest_change <= a + a.hypot(b) + 1e-12);
        assert!((modal.operating_point.q()[0] - a / k).abs() < 1e-12);
        let w = modal.normal_modes.natural_frequencies[0];
        assert!((w - (k / mass).sqrt()).abs() < 1e-12 * w);
        let zeta = c / (2.0 * (k * mass).sqrt());
        assert!((modal.damping_ratios[0] - zeta).abs() < 1e-12);
    }
    let forced = model("three_masses_forced");
    let modal = modal_analysis(forced.as_ref(), &ModalOptions::default()).unwrap();
    assert_eq!(
        modal.time_dependent_forcing.as_ref().unwrap().coordinate,
        "x1"
    );
    for (w, w2) in modal.normal_modes.natural_frequencies.iter().zip([
        2.0 - 2f64.sqrt(),
        2.0,
        2.0 + 2f64.sqrt(),
    ]) {
        assert!((w - w2.sqrt()).abs() < 1e-12);
    }
    // A model without t has nothing set aside.
    let plain = model("three_masses");
    let modal = modal_analysis(plain.as_ref(), &ModalOptions::default()).unwrap();
    assert!(modal.time_dependent_forcing.is_none());
    let out = eomgen_ok(&["modes", "forced_oscillator", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["time_dependent_forcing"]["coordinate"], "x");
    let out = eomgen_ok(&["modes", "forced_oscillator"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("set aside"));
}

/// Issue 28, item 8: Kepler's problem at rest (`tests/fixtures/kepler_orbit.yaml`,
/// `F_r = −μm/r²`) has no equilibrium; from r = 1 Newton's steps are `r/2` outwards and |F|
/// fell below the absolute tolerance at r = 9.7e5 m, which `modes --at r=1` reported as an
/// equilibrium. Refused as walking away; a spring (a true root) still converges.
#[test]
fn issue_28_equilibrium_at_infinity_is_refused() {
    let kepler: Box<dyn ModelInfo> = Box::new(eomgen::FirstOrder::new(KeplerOrbit::default()));
    let err = find_equilibrium(kepler.as_ref(), &[1.0, 0.0], 0.0).unwrap_err();
    let ModalError::EquilibriumAtInfinity { q, step, .. } = &err else {
        panic!("{err}")
    };
    assert!(q[0] > 1e3 && *step > 0.1 * q[0], "{err}");
    let out = eomgen(&["modes", &fixture("kepler_orbit.yaml"), "--at", "r=1"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("walked away"));
    let e = find_equilibrium(model("three_masses").as_ref(), &[0.3, -0.2, 0.1], 0.0).unwrap();
    assert!(e.q.iter().all(|v| v.abs() < 1e-12));
}

eomgen::model!("fixtures/quartic_well.yaml");

/// Issue 28 review: the residual tolerance is relative to the model's force scale. A
/// milligram pendulum (m = 1e-9 kg, l = 1e-3 m: torques of 1e-11 N·m) from 0.5 rad off
/// hanging stopped at 0.046 rad from it under the old absolute tolerance and was called
/// "walked away"; it converges to −π/2 (1e-12). The quartic well `V = k x⁴/4` from x = 1e-3
/// (a degenerate root, linear convergence) shrinks towards 0 instead of being refused; Kepler
/// is still refused (`issue_28_equilibrium_at_infinity_is_refused`).
#[test]
fn issue_28_equilibrium_of_small_scale_and_degenerate_models() {
    let mut pendulum = model("simple_pendulum");
    pendulum.set_parameter("m", 1e-9).unwrap();
    pendulum.set_parameter("l", 1e-3).unwrap();
    let hanging = -std::f64::consts::FRAC_PI_2;
    let e = find_equilibrium(pendulum.as_ref(), &[hanging + 0.5], 0.0).unwrap();
    assert!((e.q[0] - hanging).abs() < 1e-12, "{:?}", e.q);
    let quartic: Box<dyn ModelInfo> = Box::new(eomgen::FirstOrder::new(QuarticWell::default()));
    let e = find_equilibrium(quartic.as_ref(), &[1e-3], 0.0).unwrap();
    // |F| = x³ down by 1e-12 from the force scale at the guess, the size of its terms
    // |J x| = 3 x₀³ = 3e-9: x ≤ (3e-21)^(1/3) = 1.44e-7.
    assert!(e.q[0].abs() <= 1.45e-7, "{:?}", e.q);
    let out = eomgen_ok(&["modes", &fixture("quartic_well.yaml"), "--at", "x=0.001"]);
    assert!(out.status.success());
    let out = eomgen_ok(&[
        "modes",
        "simple_pendulum",
        "--set",
        "m=1e-9",
        "--set",
        "l=1e-3",
        "--at",
        "q=-1.07",
    ]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("-1.5707963"));
}

eomgen::model!("fixtures/shaken_pendulum_stiff.yaml");

/// Issue 28 review: a shaken 10 g pendulum (`K_θθ = m l (g − a w² cos wt)` changes by
/// `m l a w² = 0.36` N·m/rad) beside an uncoupled 1e9 N/m spring. Measured against the
/// largest entry of K the change was 3.6e-10, below the 1e-9 tolerance, and the frozen
/// t = 0 mode (5.10 rad/s) was reported; against its own diagonal it is of order 1: refused.
/// Without the shaking (a = 0) nothing depends on t.
#[test]
fn issue_28_time_dependence_beside_a_stiff_coordinate() {
    let mut m: Box<dyn ModelInfo> =
        Box::new(eomgen::FirstOrder::new(ShakenPendulumStiff::default()));
    let err = eomgen::time_dependence(m.as_ref(), &[0.0, 0.0], 0.0).unwrap_err();
    let ModalError::TimeDependent {
        part: eomgen::TimeDependentPart::StiffnessMatrix,
        relative_change,
        ..
    } = err
    else {
        panic!("{err}")
    };
    // |ΔK_θθ| ≤ 2 m l a w² = 0.72 against max |K_θθ| ≤ m l (g + a w²) = 0.46.
    assert!(relative_change > 0.1, "{relative_change}");
    let out = eomgen(&[
        "modes",
        &fixture("shaken_pendulum_stiff.yaml"),
        "--at",
        "theta=0,x=0",
    ]);
    assert_eq!(out.status.code(), Some(1));
    // With a torque T0 = 1 N·m, beyond what the pendulum can balance, Newton fails on the
    // equations frozen at t = 0; the error names the time dependence, not Newton.
    use eomgen::analysis::vibration::{
        EquilibriumStart, ModalOptions, OperatingPointError, OperatingPointOptions, modal_analysis,
    };
    m.set_parameter("T0", 1.0).unwrap();
    let options = ModalOptions {
        operating_point: OperatingPointOptions {
            start: EquilibriumStart::Guess {
                label: "theta=0.3".to_string(),
                q: vec![0.3, 0.0],
            },
            ..OperatingPointOptions::default()
        },
    };
    let err = modal_analysis(m.as_ref(), &options).unwrap_err();
    assert!(
        matches!(
            err,
            OperatingPointError::Modal(ModalError::TimeDependent {
                part: eomgen::TimeDependentPart::StiffnessMatrix,
                ..
            })
        ),
        "{err}"
    );
    m.set_parameter("T0", 0.0).unwrap();
    m.set_parameter("a", 0.0).unwrap();
    assert_eq!(
        eomgen::time_dependence(m.as_ref(), &[0.0, 0.0], 0.0).unwrap(),
        None
    );
}

/// Issue 28 review: a base driven as `x = a cos wt` by a constraint (constant Jacobian
/// [1, 0]) is base excitation, not a rod spun with t: the error says the Jacobian is
/// constant, and the hint no longer says such constraints have no modes but points to
/// coordinates relative to the base; the spun rod keeps its own hint.
#[test]
fn issue_28_prescribed_translation_has_a_truthful_hint() {
    let out = eomgen(&["modes", &fixture("shaken_base.yaml"), "--at", "x=0.01,y=0"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("constant Jacobian")
            && err.contains("relative to the moving base")
            && !err.contains("has no modes"),
        "{err}"
    );
    let out = eomgen(&["modes", "bead_spinning_rod"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("its Jacobian J") && err.contains("spun"),
        "{err}"
    );
}

/// Issue 28, item 8: a top in Euler angles at θ = 0 or π (`tests/fixtures/euler_top.yaml`),
/// where precession and spin turn the body about the same axis: `det M = I1² I3 sin²θ`
/// vanishes (to rounding at θ = π, where `sin π = 1.2e-16` left a pivot of 1e-33 and mode
/// shapes of 7.6e8). Refused, naming φ and ψ; at θ = 0.5 M is accepted and its determinant
/// is the closed form (1e-12); at θ = 1e-7 the unit-diagonal M has smallest eigenvalue
/// `≈ I1 θ²/(2 I3) = 1.5e-14`, below the 1e-13 bound, and at θ = 1e-6 (1.5e-12) above it.
/// `cart_pendulum` with m1 = 1e-10 kg (ratio ≈ m1/(2 m2) = 5e-11, det M ≠ 0) is accepted.
#[test]
fn issue_28_singular_mass_matrix_names_the_coordinates() {
    let top: Box<dyn ModelInfo> = Box::new(eomgen::FirstOrder::new(EulerTop::default()));
    for at in ["upright", "hanging"] {
        let q = guess(top.as_ref(), at);
        let err = linearize(top.as_ref(), &q, &[0.0; 3], 0.0).unwrap_err();
        let ModalError::DegenerateCoordinates { coordinates, .. } = &err else {
            panic!("{at}: {err}")
        };
        assert_eq!(coordinates, &["phi", "psi"], "{at}");
    }
    assert!(matches!(
        linearize(top.as_ref(), &[0.0, 1e-7, 0.0], &[0.0; 3], 0.0),
        Err(ModalError::DegenerateCoordinates { .. })
    ));
    linearize(top.as_ref(), &[0.0, 1e-6, 0.0], &[0.0; 3], 0.0).unwrap();
    eomgen_ok(&["modes", "cart_pendulum", "--set", "m1=1e-10"]);
    let theta: f64 = 0.5;
    let lin = linearize(top.as_ref(), &[0.0, theta, 0.0], &[0.0; 3], 0.0).unwrap();
    let (i1, i3) = (0.3, 0.1);
    let det = i1 * i1 * i3 * theta.sin().powi(2);
    assert!((lin.mass_matrix.determinant() - det).abs() < 1e-12 * det);
    let out = eomgen(&["modes", &fixture("euler_top.yaml"), "--at", "hanging"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("phi, psi") && !err.contains("e8"), "{err}");
}

/// A model file of `tests/fixtures`, compiled at run time.
fn fixture_model(name: &str) -> Box<dyn ModelInfo> {
    eomgen::ModelSource::open(&fixture(name))
        .expect("fixture loads")
        .instantiate()
}

/// Issue 28 (left open by its first round): quadratic drag `c |v| v` at rest
/// (`tests/fixtures/drag_oscillator.yaml`). The exact `∂F/∂q̇` has `vₓ²/|v|`, 0/0 at rest,
/// and `modes` read that NaN as a damping matrix changing with t ("changes by inf between
/// t = 0 s and t = 0 s"). The entries that are not finite are now differenced, as the
/// implicit integrators difference them, and counted: the linearised drag is 0 (its
/// difference `c δ`, `δ = √(ε 1e-5) ≈ 4.7e-11`), so the modes are the undamped ones,
/// ω = √(kx/m) = 2 and √(ky/m) = 3 rad/s (to 1e-12), with `K` exact.
#[test]
fn issue_28_quadratic_drag_at_rest_has_the_undamped_modes() {
    use eomgen::analysis::vibration::{ModalOptions, modal_analysis};
    let m = fixture_model("drag_oscillator.yaml");
    let modal = modal_analysis(m.as_ref(), &ModalOptions::default()).unwrap();
    assert!(modal.time_dependent_forcing.is_none());
    for (w, expected) in modal
        .normal_modes
        .natural_frequencies
        .iter()
        .zip([2.0, 3.0])
    {
        assert!((w - expected).abs() < 1e-12 * expected, "{w} vs {expected}");
    }
    let lin = &modal.linearization;
    assert!(lin.differenced_entries > 0);
    assert_eq!(
        lin.stiffness_matrix,
        DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![4.0, 9.0]))
    );
    let c = 0.5;
    assert!(
        lin.damping_matrix.amax() <= 1e-10 * c,
        "{}",
        lin.damping_matrix
    );
    assert!(
        modal.damping_ratios.iter().all(|z| z.abs() < 1e-10),
        "{:?}",
        modal.damping_ratios
    );
    // A model whose Jacobians are finite is exact, and says so.
    let exact = modal_analysis(model("three_masses").as_ref(), &ModalOptions::default()).unwrap();
    assert_eq!(exact.linearization.differenced_entries, 0);
    let out = eomgen_ok(&["modes", &fixture("drag_oscillator.yaml")]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("forward differences of F"));
    let out = eomgen_ok(&["modes", &fixture("drag_oscillator.yaml"), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["differenced_jacobian_entries"].as_u64().unwrap() > 0);
    assert!((v["natural_frequencies"][1].as_f64().unwrap() - 3.0).abs() < 1e-12);
}

/// Issue 28 (left open): the zero-frequency test was global, `|ω²| ≤ 1e-9 max |ω²|`, so a
/// soft but real mode beside a stiff one (ω² = 1e-3 next to 1e8, M = I) was called a
/// rigid-body mode. Each eigenvalue is now judged against the stiffness acting on its own
/// coordinates: the soft mode oscillates at √1e-3 (to 1e-12), while the rigid-body mode of a
/// free–free chain (K = k [1 −1 0; −1 2 −1; 0 −1 1]) is still zero, also beside a grounded
/// mass 1e12 times stiffer, whose rounding (ε 1e12 ≈ 1e-4 in absolute terms) would otherwise
/// pass for a frequency of 0.01 rad/s.
#[test]
fn issue_28_zero_frequency_is_judged_on_each_mode_s_own_scale() {
    use eomgen::Linearization;
    let soft = Linearization::from_matrices(
        DMatrix::identity(2, 2),
        DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1e-3, 1e8])),
        DMatrix::zeros(2, 2),
    );
    let modes = normal_modes(&soft).unwrap();
    assert_eq!(modes.kinds, [ModeKind::Oscillatory, ModeKind::Oscillatory]);
    assert!((modes.natural_frequencies[0] - 1e-3f64.sqrt()).abs() < 1e-12 * 1e-3f64.sqrt());
    for (k, grounded) in [(1.0, None), (3.0, None), (1.0, Some(1e12))] {
        let n = if grounded.is_some() { 4 } else { 3 };
        let mut stiffness = DMatrix::zeros(n, n);
        for i in 0..2 {
            stiffness[(i, i)] += k;
            stiffness[(i + 1, i + 1)] += k;
            stiffness[(i, i + 1)] -= k;
            stiffness[(i + 1, i)] -= k;
        }
        if let Some(stiff) = grounded {
            stiffness[(3, 3)] = stiff;
        }
        let chain =
            Linearization::from_matrices(DMatrix::identity(n, n), stiffness, DMatrix::zeros(n, n));
        let modes = normal_modes(&chain).unwrap();
        assert_eq!(
            modes.kinds[0],
            ModeKind::ZeroFrequency,
            "{k} {grounded:?}: {:?}",
            modes.eigenvalues
        );
        assert!(
            modes.kinds[1..]
                .iter()
                .all(|kind| *kind == ModeKind::Oscillatory)
        );
        // ω² = k, 3k for the free–free chain of unit masses (to rounding of the largest
        // entry, 1e12 beside it).
        let tol = if grounded.is_some() { 1e-3 } else { 1e-12 };
        assert!(
            (modes.eigenvalues[1] - k).abs() < tol * k,
            "{:?}",
            modes.eigenvalues
        );
        assert!(
            (modes.eigenvalues[2] - 3.0 * k).abs() < tol * k,
            "{:?}",
            modes.eigenvalues
        );
    }
}

/// Issue 28 (left open): a load that depends on t and has no equilibrium at t₀ reported
/// Newton's failure ("start Newton nearer an equilibrium"), though the time dependence is
/// what stands between the model and its modes. A pendulum driven by `A cos wt` with
/// `A = 20 N·m` above `m g l = 9.81 N·m` (`tests/fixtures/overdriven_pendulum.yaml`) is now
/// refused as a time-dependent load, naming it and Newton's failure; with `A = 5 N·m` the
/// load is set aside as before and the pendulum leaning at `sin θ* = A/(m g l)` has
/// `ω² = (g/l) cos θ*` (to 1e-10, Newton's tolerance).
#[test]
fn issue_28_time_dependent_load_without_equilibrium_is_refused_as_such() {
    use eomgen::analysis::vibration::{ModalOptions, OperatingPointError, modal_analysis};
    let mut m = fixture_model("overdriven_pendulum.yaml");
    let err = modal_analysis(m.as_ref(), &ModalOptions::default()).unwrap_err();
    let OperatingPointError::Modal(ModalError::TimeDependentLoad {
        forcing,
        equilibrium,
    }) = &err
    else {
        panic!("{err}")
    };
    assert_eq!(forcing.coordinate, "theta");
    assert!(
        matches!(**equilibrium, ModalError::EquilibriumNotFound { .. }),
        "{equilibrium}"
    );
    let out = eomgen(&["modes", &fixture("overdriven_pendulum.yaml")]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(
        text.contains("load on `theta` depends on t") && text.contains("eomgen frf"),
        "{text}"
    );
    m.set_parameter("A", 5.0).unwrap();
    let modal = modal_analysis(m.as_ref(), &ModalOptions::default()).unwrap();
    assert!(modal.time_dependent_forcing.is_some());
    let theta = (5.0f64 / 9.81).asin();
    assert!((modal.operating_point.q()[0] - theta).abs() < 1e-10);
    let w2 = 9.81 * theta.cos();
    assert!((modal.normal_modes.eigenvalues[0] - w2).abs() < 1e-10 * w2);
}

/// Issue 30: the particle in a spinning bowl (tests/fixtures/spinning_bowl.yaml) has `K`
/// negative definite — `K` alone calls both modes unstable, with growth rates √15.19 and
/// √5.38 — while its whole linearisation, Coriolis terms included, is stable: the library's
/// verdict is "marginally stable" with the closed-form gyroscopic frequencies (roots of
/// `s⁴ + (k_a + k_b + 4W²) s² + k_a k_b`, to 1e-12), `C` is all gyroscopic and the
/// eigenvalues lie on the imaginary axis. Spun slower (W = 3.5, between √(g a) and √(g b)
/// the roots leave the axis), it is unstable with the closed-form growth rate.
#[test]
fn spinning_bowl_is_stable_by_its_whole_linearisation() {
    use eomgen::analysis::vibration::{ModalOptions, modal_analysis};
    use eomgen::{ModeKind, Stability};
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/spinning_bowl.yaml"
    );
    let source = eomgen::ModelSource::open(path).unwrap();
    let (g, a, b) = (9.81f64, 1.0, 2.0);
    for w in [5.0f64, 3.5] {
        let mut model = source.instantiate();
        model.set_parameter("W", w).unwrap();
        let analysis = modal_analysis(model.as_ref(), &ModalOptions::default()).unwrap();
        let (ka, kb) = (g * a - w * w, g * b - w * w);
        // s² = x, x² + (ka + kb + 4W²) x + ka kb = 0.
        let p = ka + kb + 4.0 * w * w;
        let disc = p * p - 4.0 * ka * kb;
        let s = &analysis.stability;
        assert_eq!(s.gyroscopic_part[(1, 0)], 2.0 * w);
        assert_eq!(s.damping_part.amax(), 0.0);
        if disc >= 0.0 && p > 0.0 && ka * kb > 0.0 {
            assert!(matches!(
                analysis.normal_modes.kinds[0],
                ModeKind::Unstable { .. }
            ));
            assert_eq!(s.stability, Stability::MarginallyStable, "W = {w}");
            let mut expected = [
                ((p - disc.sqrt()) / 2.0).sqrt(),
                ((p + disc.sqrt()) / 2.0).sqrt(),
            ];
            expected.sort_by(f64::total_cmp);
            let got = s.gyroscopic_frequencies.as_ref().unwrap();
            assert_eq!(got.len(), 2);
            for (x, e) in got.iter().zip(expected) {
                assert!((x - e).abs() <= 1e-12 * e, "W = {w}: {x} against {e}");
            }
            assert!(s.eigenvalues.iter().all(|e| e.re == 0.0));
        } else {
            // Not both roots x = s² negative (here real, of opposite signs): s = ±√x, the
            // growth rate the largest Re √x.
            let roots = [
                nalgebra::Complex::new(-p, 0.0) / 2.0
                    + nalgebra::Complex::new(disc, 0.0).sqrt() / 2.0,
                nalgebra::Complex::new(-p, 0.0) / 2.0
                    - nalgebra::Complex::new(disc, 0.0).sqrt() / 2.0,
            ];
            let growth = roots
                .iter()
                .map(|x| x.sqrt().re.abs())
                .fold(0.0f64, f64::max);
            match s.stability {
                Stability::Unstable { growth_rate } => {
                    assert!(
                        (growth_rate - growth).abs() <= 1e-12 * growth,
                        "{growth_rate} {growth}"
                    )
                }
                other => panic!("W = {w}: {other:?}"),
            }
        }
    }
}

/// Issue 30: `modes` printed both modes of the spinning bowl "unstable, grows as e^(3.897 t)"
/// (from K alone) and exited 0. Its text now gives the verdict of the whole linearisation
/// and the gyroscopic frequencies, and labels K's modes as what they are; the JSON carries
/// the same verdict and eigenvalues under `stability`.
#[test]
fn modes_cli_gives_the_gyroscopic_verdict() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/spinning_bowl.yaml"
    );
    let text = String::from_utf8(eomgen_ok(&["modes", path]).stdout).unwrap();
    assert!(!text.contains("unstable, grows"), "{text}");
    assert!(text.contains("stability  marginally stable"), "{text}");
    assert!(text.contains("1.0210493510, 8.8536691955 rad/s"), "{text}");
    let json: serde_json::Value =
        serde_json::from_slice(&eomgen_ok(&["modes", path, "--json"]).stdout).unwrap();
    let s = &json["stability"];
    assert_eq!(s["verdict"], "marginally_stable", "{s}");
    assert_eq!(s["gyroscopic_part"][1][0], 10.0, "{s}");
    assert_eq!(s["eigenvalues"].as_array().unwrap().len(), 4, "{s}");
}

/// A guess that is the equilibrium to rounding is accepted: a weight hung on two inclined
/// springs whose rest lengths put it in balance at `x = z = 0`, where the residual is 8.5e-14
/// N against the 118 N weight that the springs balance, and Newton cannot reduce it further.
/// From the exact guess and from a guess 1 mm off, the same point (to 1e-12 m) with residuals
/// at rounding (below 1e-12 N). A residual no step reduces but that is not rounding is still
/// refused: a cart pushed by a constant 1e-4 N beside a 1e9 N/m spring (the push's row of
/// `∂F/∂q` is zero, so the stiffness of the other row must not excuse it).
#[test]
fn a_guess_that_is_the_equilibrium_to_rounding_is_accepted() {
    use eomgen::JitModel;
    use eomgen::find_equilibrium;
    let text = "name: block\nparameters: { m: 12, g: 9.81, k: 4000, a: 0.3, h: 0.4 }\n\
                coordinates: [x, z]\npoints:\n  P: [x, z]\n  A: [-a, h]\n  B: [a, h]\n\
                bodies:\n  block: { mass: m, at: P }\ngravity: [0, -g]\nsprings:\n  \
                left: { between: [P, A], stiffness: k, rest_length: sqrt(a^2 + h^2) - m*g*sqrt(a^2 + h^2)/(2*k*h) }\n  \
                right: { between: [P, B], stiffness: k, rest_length: sqrt(a^2 + h^2) - m*g*sqrt(a^2 + h^2)/(2*k*h) }\n";
    let model = eomgen::DynFirstOrder::new(
        JitModel::from_source("block.yaml", text).unwrap_or_else(|e| panic!("{e}")),
    );
    for guess in [[0.0, 0.0], [0.0, 1e-3]] {
        let found =
            find_equilibrium(&model, &guess, 0.0).unwrap_or_else(|e| panic!("from {guess:?}: {e}"));
        assert!(
            found.q.iter().all(|v| v.abs() < 1e-12),
            "from {guess:?}: {:?}",
            found.q
        );
        assert!(
            found.residual < 1e-12,
            "from {guess:?}: |F| = {}",
            found.residual
        );
    }
    let pushed = "name: pushed\nparameters: { m: 1, k: 1e9, F: 1e-4 }\ncoordinates: [x, y]\n\
                  points:\n  P: [x, 0]\n  Q: [0, y]\n  O: [0, 0]\nbodies:\n  cart: { mass: m, at: P }\n  \
                  bob: { mass: m, at: Q }\nsprings:\n  s: { between: [Q, O], stiffness: k }\n\
                  forces:\n  push: { at: P, vector: [F, 0] }\n";
    let model = eomgen::DynFirstOrder::new(
        JitModel::from_source("pushed.yaml", pushed).unwrap_or_else(|e| panic!("{e}")),
    );
    let result = find_equilibrium(&model, &[0.0, 0.0], 0.0);
    assert!(result.is_err(), "a pushed cart at rest: {result:?}");
}

/// Issue 49: where the equations are singular at the operating point itself (0/0), the error
/// says so rather than that they depend on `t`. The dumbbell's rod and the Cartesian
/// pendulum's rod at q = 0 (both ends at one point) have a Jacobian `d/|d|` that is 0/0, and a
/// zero-rest-length spring whose length is a parameter of value 0 has a force
/// `k (1 − ℓ₀/|d|) d` that is 0·∞ where its ends meet. Before, each was "the linearised
/// equations depend on t … changes by inf between t = 0 s and t = 0 s".
#[test]
fn a_singularity_at_the_operating_point_is_not_called_a_time_dependence() {
    for (name, n) in [("dumbbell", 4), ("simple_pendulum_cartesian", 2)] {
        let m = model(name);
        assert_eq!(m.num_dofs(), n, "{name}");
        let err = eomgen::time_dependence(m.as_ref(), &vec![0.0; n], 0.0).unwrap_err();
        assert!(matches!(err, ModalError::NonFinite { .. }), "{name}: {err}");
    }
    let text = "name: zero_rest\nparameters:\n  m: 1.0   # kg\n  k: 20.0  # N/m\n  r0: 0.0  # m\n\
                coordinates: [x]\npoints:\n  O: [0, 0]\n  P: [x, 0]\n\
                bodies:\n  mass: { mass: m, at: P }\n\
                springs:\n  s: { between: [P, O], stiffness: k, rest_length: r0 }\n";
    let m = eomgen::DynFirstOrder::new(
        eomgen::JitModel::from_source("zero_rest.yaml", text).unwrap_or_else(|e| panic!("{e}")),
    );
    let err = eomgen::time_dependence(&m, &[0.0], 0.0).unwrap_err();
    assert!(matches!(err, ModalError::NonFinite { .. }), "{err}");
    let out = eomgen(&["modes", "dumbbell"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("not finite") && !stderr.contains("depend on t"),
        "{stderr}"
    );
}

/// Issue 49: a parameter sweep refuses what `modes` refuses. The shaken pendulum's stiffness
/// changes with t (the sweep over `a` reported a change at `a = 0.0027778`, "stabilising":
/// the frozen `K = g/l − a w²/l` at t = 0 through 0, which has nothing to do with the Kapitza
/// boundary), and the spun rod's constraint does; the same error and hint as `modes`, exit 1.
#[test]
fn parameter_sweeps_refuse_time_dependent_equations() {
    for (args, hint) in [
        (
            &[
                "study",
                "parameter-sweep",
                "mathieu_pendulum",
                "--at",
                "upright",
                "--parameter",
                "a",
                "--values",
                "0..0.5:6",
            ][..],
            "eomgen study floquet mathieu_pendulum",
        ),
        (
            &[
                "study",
                "parameter-sweep",
                "bead_spinning_rod",
                "--parameter",
                "w",
                "--values",
                "1..3:3",
            ][..],
            "a constraint that moves with t",
        ),
    ] {
        let out = eomgen(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("the linearised equations depend on t") && err.contains(hint),
            "{err}"
        );
    }
}

/// Issue 49: the rigid-body modes of a free structure, which no single coordinate is (the
/// translations and rotations of the spring square and of the 3-D spring pair), are double
/// zero eigenvalues exactly; rounding split them into real pairs and `modes` said "unstable,
/// grows as e^(1.3e-9 t)" (spring_square) and "e^(4.7e-9 t)" (spring_pair_3d), both bundled.
/// The square has 4 zero-frequency modes (two translations, the rotation and its shear), the
/// pair 5 (three translations and the two rotations about axes across the spring).
#[test]
fn rigid_body_modes_are_exact_double_zeros() {
    for (name, zero_frequencies) in [("spring_square", 4), ("spring_pair_3d", 5)] {
        let m = model(name);
        let n = m.num_dofs();
        let q = find_equilibrium(m.as_ref(), &guess(m.as_ref(), "rest"), 0.0)
            .unwrap()
            .q;
        let lin = linearize(m.as_ref(), &q, &vec![0.0; n], 0.0).unwrap();
        let s = eomgen::linear_stability(&lin).unwrap();
        assert_eq!(
            s.stability,
            eomgen::Stability::MarginallyStable,
            "{name}: {:?}",
            s.eigenvalues
        );
        let zeros = s.eigenvalues.iter().filter(|v| v.norm() == 0.0).count();
        assert_eq!(zeros, 2 * zero_frequencies, "{name}: {:?}", s.eigenvalues);
        assert!(s.eigenvalues.iter().all(|v| v.re == 0.0), "{name}");
    }
}

/// The review of issue 49: a sweep of the spring square's stiffness (a free structure, four
/// rigid-body modes) counted the rounding of its double zeros, 149–276 false changes of
/// stability in 400 values, and 17 values failed when the bounded Schur iteration cycled on
/// the state matrix's Jordan blocks. Every value is marginally stable, with no change.
#[test]
fn a_sweep_of_a_free_structure_finds_no_change() {
    use eomgen::analysis::vibration::{self, ParameterSweepOptions, SweepAxis};
    let mut m = model("spring_square");
    let options = ParameterSweepOptions {
        axis: SweepAxis::linear("k", 0.5, 5.0, 120).unwrap(),
        operating_point: named("rest"),
        refine: true,
    };
    let sweep = vibration::parameter_sweep(m.as_mut(), &options, |_, _| {}).unwrap();
    assert!(
        sweep.stability_changes.is_empty(),
        "{:?}",
        sweep.stability_changes
    );
    for point in &sweep.points {
        assert_eq!(
            point.stability,
            Some(eomgen::Stability::MarginallyStable),
            "{point:?}"
        );
    }
}

/// Issue 49's review: a swept value whose state matrix has entries beyond 1e154 hung in
/// nalgebra's balancing (its squared column norms are infinite and its scaling loop never
/// ends). The pendulum with g = 1e200 is marginally stable, `±1e100 i` to 1e-14, and its
/// table prints 1e200 in exponent form, not 200 digits.
#[test]
fn a_sweep_of_huge_values_is_answered() {
    use eomgen::analysis::vibration::{self, ParameterSweepOptions, SweepAxis};
    let mut m = model("simple_pendulum");
    let options = ParameterSweepOptions {
        axis: SweepAxis::linear("g", 1e200, 2e200, 1).unwrap(),
        operating_point: named("hanging"),
        refine: true,
    };
    let sweep = vibration::parameter_sweep(m.as_mut(), &options, |_, _| {}).unwrap();
    let point = &sweep.points[0];
    assert_eq!(
        point.stability,
        Some(eomgen::Stability::MarginallyStable),
        "{point:?}"
    );
    let l = m.parameter_values()[1];
    let omega = (1e200f64 / l).sqrt();
    assert!(
        point
            .eigenvalues
            .iter()
            .all(|s| (s.im.abs() - omega).abs() <= 1e-14 * omega),
        "{point:?}"
    );
    let out = eomgen_ok(&[
        "study",
        "parameter-sweep",
        "simple_pendulum",
        "--parameter",
        "g",
        "--values=1e200..2e200:1",
        "--at",
        "hanging",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("1.00000000e200  marginal"), "{text}");
}

/// The second review of issue 49: a soft spring beside a stiff one is no rigid-body mode. With
/// `k = −1e-3` beside `1e10` (undamped), the first version of the rigid-mode elimination
/// (singular values below 1e-13 of the largest) made the soft mode two exact zeros and said
/// "marginally stable"; it grows as `e^(√1e-3 t)`. A candidate is confirmed on its own scale.
#[test]
fn a_soft_mode_beside_a_stiff_one_keeps_its_growth() {
    let path = format!(
        "{}/tests/fixtures/slow_and_stiff.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut m = eomgen::ModelSource::open(&path).unwrap().instantiate();
    m.set_parameter("c", 0.0).unwrap();
    m.set_parameter("p", -1e-3).unwrap();
    let lin = linearize(m.as_ref(), &[0.0; 3], &[0.0; 3], 0.0).unwrap();
    let s = eomgen::linear_stability(&lin).unwrap();
    let eomgen::Stability::Unstable { growth_rate } = s.stability else {
        panic!("{:?}", s.eigenvalues)
    };
    assert!(
        (growth_rate - 1e-3f64.sqrt()).abs() <= 1e-12,
        "{growth_rate}"
    );
}

/// The operating point of the file's `equilibria:` entry `name`, for a sweep.
fn named(name: &str) -> eomgen::analysis::vibration::OperatingPointOptions {
    eomgen::analysis::vibration::OperatingPointOptions {
        start: eomgen::analysis::vibration::EquilibriumStart::Named(name.to_string()),
        ..Default::default()
    }
}

/// A rotation about an oblique axis (`axis: [0, 0.6, 0.8]`, issue 53): a pendulum hinged
/// about an axis at `a` from the vertical (`cos a = 0.8`) swings under `g sin a`, so
/// `ω = √(0.6 g / L)` (`tests/fixtures/oblique_hinge_pendulum.yaml`), to 1e-12; both
/// derivations agree (`check`), and an axis of two components is a located model-file error.
#[test]
fn an_oblique_hinge_axis_gives_the_tilted_pendulums_frequency() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/oblique_hinge_pendulum.yaml"
    );
    let m = eomgen::DynFirstOrder::new(eomgen::JitModel::load(path).unwrap());
    let q = find_equilibrium(&m, &[0.1], 0.0).unwrap().q;
    assert!(q[0].abs() < 1e-12, "{q:?}");
    let lin = linearize(&m, &q, &[0.0], 0.0).unwrap();
    let w = normal_modes(&lin).unwrap().natural_frequencies[0];
    let expected = (0.6 * 9.81_f64 / 0.5).sqrt();
    assert!(
        (w - expected).abs() <= 1e-12 * expected,
        "{w} vs {expected}"
    );
    eomgen_ok(&["check", path]);
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.yaml");
    let text = std::fs::read_to_string(path).unwrap();
    std::fs::write(
        &bad,
        text.replace("axis: [0, 0.6, 0.8]", "axis: [0.6, 0.8]"),
    )
    .unwrap();
    let out = eomgen(&["check", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(
        message.contains("bad.yaml:15:25:") && message.contains("3 components"),
        "{message}"
    );
    std::fs::write(&bad, text.replace("axis: [0, 0.6, 0.8]", "axis: [0, 0, 0]")).unwrap();
    let out = eomgen(&["check", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(
        message.contains("bad.yaml:15:25:") && message.contains("zero vector"),
        "{message}"
    );
}
