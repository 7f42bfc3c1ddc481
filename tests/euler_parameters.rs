//! Frames in Euler parameters (`quaternion: [e0, e1, e2, e3]`, issue 53 item 2): a free rigid
//! body oriented by them moves as the same body in z-x-y angles, and through the orientations
//! where those angles lose a degree of freedom.

use eomgen::ModelInfo;
use eomgen::analysis::{Method, SimulationOptions, simulate};
use eomgen::{OutputTimes, Stabilization};

fn fixture(name: &str) -> Box<dyn ModelInfo> {
    let path = format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    eomgen::ModelSource::open(&path)
        .expect("fixture loads")
        .instantiate()
}

/// The body's angular velocity from Euler parameters and their rates,
/// `w = 2 (e0 ė − ė0 e − e × ė)/|q|²` (Kane & Levinson 1985, eq. 2.1.9).
fn omega_from_quaternion(y: &[f64]) -> [f64; 3] {
    let (e0, e, d0, d) = (y[0], [y[1], y[2], y[3]], y[4], [y[5], y[6], y[7]]);
    let norm = e0 * e0 + e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    let cross = [
        e[1] * d[2] - e[2] * d[1],
        e[2] * d[0] - e[0] * d[2],
        e[0] * d[1] - e[1] * d[0],
    ];
    [0, 1, 2].map(|i| 2.0 * (e0 * d[i] - d0 * e[i] - cross[i]) / norm)
}

/// The body's angular velocity from the z-x-y angles of `free_rigid_body` (its header).
fn omega_from_angles(y: &[f64]) -> [f64; 3] {
    let (theta, psi) = (y[1], y[2]);
    let (phi_d, theta_d, psi_d) = (y[3], y[4], y[5]);
    [
        theta_d * psi.cos() - phi_d * theta.cos() * psi.sin(),
        phi_d * theta.sin() + psi_d,
        theta_d * psi.sin() + phi_d * theta.cos() * psi.cos(),
    ]
}

fn options(t_end: f64, times: Vec<f64>, initial: Option<Vec<f64>>) -> SimulationOptions {
    SimulationOptions {
        t_end,
        rtol: 1e-12,
        atol: 1e-12,
        method: Method::Dop853,
        output: OutputTimes::At(times),
        stabilization: Stabilization::Projection,
        initial_state: initial,
        ..SimulationOptions::default()
    }
}

/// Tumbling from `w = (0.3, 0.2, 1)`: the body's angular velocity from the Euler parameters
/// equals the one from the z-x-y angles of `free_rigid_body` at every 0.25 s over 10 s to
/// 1e-9 (two models, two integrations at rtol 1e-12), its kinetic energy is conserved to
/// 1e-10, and the unit-norm constraint `B_unit` holds to 1e-12.
#[test]
fn euler_parameters_tumble_as_the_angles_do() {
    let times: Vec<f64> = (0..=40).map(|k| 0.25 * f64::from(k)).collect();
    let mut q = fixture("free_rigid_body_quaternion.yaml");
    assert_eq!(q.description().constraints.len(), 1);
    assert_eq!(q.description().constraints[0], "B_unit");
    let quaternion = simulate(q.as_mut(), &options(10.0, times.clone(), None)).expect("runs");
    assert!(quaternion.failure.is_none(), "{:?}", quaternion.failure);
    let mut a = (eomgen::models::find("free_rigid_body")
        .expect("bundled")
        .make)();
    let angles = simulate(a.as_mut(), &options(10.0, times, None)).expect("runs");
    assert!(angles.failure.is_none(), "{:?}", angles.failure);
    let inertia = [1.0, 2.0, 3.0];
    for ((t, yq), (_, ya)) in quaternion.solution.iter().zip(angles.solution.iter()) {
        let (wq, wa) = (omega_from_quaternion(yq), omega_from_angles(ya));
        for i in 0..3 {
            assert!(
                (wq[i] - wa[i]).abs() < 1e-9,
                "t = {t}: {wq:?} against {wa:?}"
            );
        }
        let energy: f64 = (0..3).map(|i| inertia[i] * wq[i] * wq[i] / 2.0).sum();
        assert!((energy - 1.585).abs() < 1e-10, "t = {t}: {energy}");
        let norm: f64 = yq[..4].iter().map(|e| e * e).sum();
        assert!((norm - 1.0).abs() < 1e-12, "t = {t}: |q|² = {norm}");
    }
}

/// Spun at 2 rad/s about the axis of least moment (body x = ground x), the body turns
/// through the orientations where the z-x-y angles are singular (θ = ±π/2, first at
/// t = π/4, where their mass matrix has rank 2): in Euler parameters it runs through them,
/// `q(t) = (cos t, sin t, 0, 0)` to 1e-9 over 10 s.
#[test]
fn euler_parameters_have_no_gimbal_lock() {
    let times: Vec<f64> = (0..=100).map(|k| 0.1 * f64::from(k)).collect();
    let mut q = fixture("free_rigid_body_quaternion.yaml");
    let start = vec![1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0];
    let run = simulate(q.as_mut(), &options(10.0, times.clone(), Some(start))).expect("runs");
    assert!(run.failure.is_none(), "{:?}", run.failure);
    assert_eq!(run.solution.len(), times.len());
    for (t, y) in run.solution.iter() {
        let want = [t.cos(), t.sin(), 0.0, 0.0];
        for i in 0..4 {
            assert!(
                (y[i] - want[i]).abs() < 1e-9,
                "t = {t}: {:?} against {want:?}",
                &y[..4]
            );
        }
    }
    // The angles' mass matrix at that orientation (θ = π/2) is singular: rank 2 of 3.
    let a = (eomgen::models::find("free_rigid_body")
        .expect("bundled")
        .make)();
    let y = [0.0, std::f64::consts::FRAC_PI_2, 0.0, 0.0, 2.0, 0.0];
    let (m, _) = a.mass_matrix_and_forcing(0.0, &y);
    let s = m.symmetric_eigenvalues();
    let (small, large) = (s.amin(), s.amax());
    assert!(small < 1e-12 * large, "eigenvalues of M at θ = π/2: {s}");
}

/// The Hamilton product `a ⊗ b` of two quaternions `(w, x, y, z)`.
fn product(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// The heavy top in Euler parameters (`tests/fixtures/heavy_top_quaternion.yaml`, its centre
/// of mass off the pivot) against `heavy_top` in z-x-z angles, both started from the angles'
/// steady precession at 30° with a nutation rate of 0.5 rad/s added: the Euler parameters
/// `q = q_z(φ) ⊗ q_x(θ) ⊗ q_z(ψ)` and their rates `½ q ⊗ (0, ω)`, `ω` the body's angular
/// velocity from the angles' rates. The centre of mass follows the same path over 2 s to
/// 1e-9 m (l = 0.1 m), and the generated constraint's multiplier stays at rounding.
#[test]
fn a_heavy_top_in_euler_parameters_follows_the_angles() {
    let mut angles = (eomgen::models::find("heavy_top").expect("bundled").make)();
    let times: Vec<f64> = (0..=40).map(|k| 0.05 * f64::from(k)).collect();
    let first = simulate(angles.as_mut(), &options(0.1, vec![0.0], None)).expect("starts");
    let mut y = first.initial_state.clone();
    y[4] += 0.5;
    let run = simulate(
        angles.as_mut(),
        &options(2.0, times.clone(), Some(y.clone())),
    )
    .expect("runs");
    assert!(run.failure.is_none(), "{:?}", run.failure);
    let (phi, theta, psi) = (y[0], y[1], y[2]);
    let (phi_d, theta_d, psi_d) = (y[3], y[4], y[5]);
    let half = |a: f64| ((a / 2.0).cos(), (a / 2.0).sin());
    let ((cf, sf), (ct, st), (cp, sp)) = (half(phi), half(theta), half(psi));
    let q = product(
        product([cf, 0.0, 0.0, sf], [ct, st, 0.0, 0.0]),
        [cp, 0.0, 0.0, sp],
    );
    let w = [
        phi_d * theta.sin() * psi.sin() + theta_d * psi.cos(),
        phi_d * theta.sin() * psi.cos() - theta_d * psi.sin(),
        phi_d * theta.cos() + psi_d,
    ];
    let qd = product(q, [0.0, w[0], w[1], w[2]]).map(|c| c / 2.0);
    let start: Vec<f64> = q.iter().chain(&qd).copied().collect();
    let mut top = fixture("heavy_top_quaternion.yaml");
    let quaternion = simulate(top.as_mut(), &options(2.0, times, Some(start))).expect("runs");
    assert!(quaternion.failure.is_none(), "{:?}", quaternion.failure);
    let l = 0.1;
    for ((t, ya), (_, yq)) in run.solution.iter().zip(quaternion.solution.iter()) {
        let (phi, theta) = (ya[0], ya[1]);
        let from_angles = [
            l * theta.sin() * phi.sin(),
            -l * theta.sin() * phi.cos(),
            l * theta.cos(),
        ];
        // B.z in N: the third column of R(q).
        let (e0, e1, e2, e3) = (yq[0], yq[1], yq[2], yq[3]);
        let norm = e0 * e0 + e1 * e1 + e2 * e2 + e3 * e3;
        let z = [
            2.0 * (e1 * e3 + e0 * e2) / norm,
            2.0 * (e2 * e3 - e0 * e1) / norm,
            (e0 * e0 - e1 * e1 - e2 * e2 + e3 * e3) / norm,
        ];
        for i in 0..3 {
            assert!(
                (l * z[i] - from_angles[i]).abs() < 1e-9,
                "t = {t}: {z:?} against {from_angles:?}"
            );
        }
    }
    let lambda = (quaternion.constraints.lagrange_multipliers.iter())
        .flatten()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(lambda < 1e-9, "the norm's multiplier is {lambda:e}");
}

/// `eomgen check` compares the derivations of a model in Euler parameters through the KKT
/// system (their mass matrix is singular along the parameters' norm, where nothing moves):
/// the heavy top's Lagrange and momentum balance agree.
#[test]
fn the_derivations_of_euler_parameters_are_cross_checked_through_the_constraints() {
    let path = format!(
        "{}/tests/fixtures/heavy_top_quaternion.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let out = crate::common::eomgen_ok(&["check", &path]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("ok   lagrange vs momentum"), "{text}");
}
