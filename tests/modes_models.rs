//! The modal-analysis catalogue (issue 7): natural frequencies of HW24, HW29, HW30, HW31's
//! spring networks and the discrete string against closed forms derived by hand (including the
//! number of zero-frequency modes), the string's convergence to the wave equation at the rate
//! theory gives, the Rayleigh quotient of lecture 37, HW24's synchronous motion in the
//! nonlinear simulator, and the mode-shape charts of `eomgen modes --plot`.
//!
//! Tolerances: frequencies from the exact linearisation and a symmetric eigensolver agree with
//! closed forms to a few ulps times the condition of the eigenproblem; 1e-12 relative (to the
//! largest frequency) covers every model here. Zero-frequency modes are those with
//! `|ω²| ≤ 1e-9 max |ω²|` (the library's rule); the exact ones come out at ~1e-16.

use crate::common;
use common::eomgen_ok;

use std::f64::consts::PI;

use crate::compiled_models::double_pendulum_points::DoublePendulumPoints;
use eomgen::{
    DormandPrince853, EventDirection, EventSpec, FirstOrder, Integrator, IntegratorOptions,
    Linearization, ModeKind, ModelInfo, NormalModes, OutputTimes, WithEvents, find_equilibrium,
    linearize, normal_modes,
};
use eomgen_symbolic::expr::SymbolKind;
use eomgen_symbolic::expr::eval::Evaluator;
use eomgen_symbolic::mechanics::{Formulation, Jacobians, Lagrange, SymbolicModel};
use nalgebra::{DMatrix, DVector};

fn model(name: &str, set: &[(&str, f64)]) -> Box<dyn ModelInfo> {
    let mut m = (eomgen::models::find(name)
        .unwrap_or_else(|| panic!("bundled model {name}"))
        .make)();
    for (p, v) in set {
        m.set_parameter(p, *v).unwrap();
    }
    m
}

/// Linearisation and normal modes at the model's named equilibrium `at`.
fn modes_at(m: &dyn ModelInfo, at: &str) -> (Linearization, NormalModes) {
    let guess = m
        .equilibrium_guesses()
        .into_iter()
        .find(|(n, _)| *n == at)
        .unwrap_or_else(|| panic!("{} names `{at}`", m.description().name))
        .1;
    let q = find_equilibrium(m, &guess, 0.0).unwrap().q;
    let lin = linearize(m, &q, &vec![0.0; q.len()], 0.0).unwrap();
    let modes = normal_modes(&lin).unwrap();
    (lin, modes)
}

fn zero_modes(modes: &NormalModes) -> usize {
    modes
        .kinds
        .iter()
        .filter(|k| **k == ModeKind::ZeroFrequency)
        .count()
}

/// The computed frequencies equal `exact` (ascending) to `tol` relative to the largest.
fn assert_frequencies(name: &str, computed: &[f64], exact: &[f64], tol: f64) {
    assert_eq!(computed.len(), exact.len(), "{name}");
    let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (k, (c, e)) in computed.iter().zip(exact).enumerate() {
        assert!(
            (c - e).abs() <= tol * scale,
            "{name}: mode {}: ω = {c} vs analytic {e}",
            k + 1
        );
    }
}

fn assert_matrix(name: &str, what: &str, a: &DMatrix<f64>, b: &DMatrix<f64>, tol: f64) {
    let scale = b.amax().max(1.0);
    let err = (a - b).amax();
    assert!(
        err <= tol * scale,
        "{name}: {what} differs by {err:e}:\n{a}\nvs\n{b}"
    );
}

/// `‖K v‖ ≤ 1e-12 ‖K‖ ‖v‖`: v costs no strain energy (K is exact, so only rounding).
fn assert_null(name: &str, k: &DMatrix<f64>, v: &[f64]) {
    let v = DVector::from_column_slice(v);
    let r = (k * &v).amax();
    assert!(
        r <= 1e-12 * k.amax() * v.amax(),
        "{name}: K v = {r:e} for v = {v}"
    );
}

/// The roots ω² of `det(K − ω² M) = 0` for 2 × 2 matrices, ascending.
fn two_by_two(m: [[f64; 2]; 2], k: [[f64; 2]; 2]) -> [f64; 2] {
    let a = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let b = -(k[0][0] * m[1][1] + k[1][1] * m[0][0] - k[0][1] * m[1][0] - k[1][0] * m[0][1]);
    let c = k[0][0] * k[1][1] - k[0][1] * k[1][0];
    let disc = (b * b - 4.0 * a * c).sqrt();
    [(-b - disc) / (2.0 * a), (-b + disc) / (2.0 * a)]
}

fn mat2(a: [[f64; 2]; 2]) -> DMatrix<f64> {
    DMatrix::from_row_slice(2, 2, &[a[0][0], a[0][1], a[1][0], a[1][1]])
}

/// HW24: point masses m at elbow and hand, links ℓ, angles from straight down. By hand,
/// T = ½ m ℓ² (2 θ̇1² + 2 cos(θ1 − θ2) θ̇1 θ̇2 + θ̇2²), V = −m g ℓ (2 cos θ1 + cos θ2), so at
/// θ = 0: M = m ℓ² [[2, 1], [1, 1]], K = m g ℓ [[2, 0], [0, 1]], ω² = (2 ∓ √2) g/ℓ with
/// θ2/θ1 = ±√2. Checked at the homework's ℓ = 1, g = 10 and at other parameters; upright
/// (θ = π), K changes sign and the same numbers are growth rates.
#[test]
fn double_pendulum_points_hw24() {
    let s2 = 2f64.sqrt();
    for (m, l, g) in [(1.0, 1.0, 10.0), (0.3, 0.7, 9.81)] {
        let model = model("double_pendulum_points", &[("m", m), ("l", l), ("g", g)]);
        let (lin, modes) = modes_at(model.as_ref(), "hanging");
        let name = "double_pendulum_points";
        assert_matrix(
            name,
            "M",
            &lin.mass_matrix,
            &(mat2([[2.0, 1.0], [1.0, 1.0]]) * (m * l * l)),
            1e-14,
        );
        assert_matrix(
            name,
            "K",
            &lin.stiffness_matrix,
            &(mat2([[2.0, 0.0], [0.0, 1.0]]) * (m * g * l)),
            1e-14,
        );
        let exact = [((2.0 - s2) * g / l).sqrt(), ((2.0 + s2) * g / l).sqrt()];
        assert_frequencies(name, &modes.natural_frequencies, &exact, 1e-12);
        for (k, ratio) in [s2, -s2].into_iter().enumerate() {
            let psi = modes.mode_shapes.column(k);
            assert!(
                (psi[1] / psi[0] - ratio).abs() < 1e-12,
                "mode {k}: θ2/θ1 = {}",
                psi[1] / psi[0]
            );
        }
        let (_, upright) = modes_at(model.as_ref(), "upright");
        let mut rates: Vec<f64> = upright
            .kinds
            .iter()
            .map(|k| match k {
                ModeKind::Unstable { growth_rate } => *growth_rate,
                other => panic!("upright must be unstable, got {other:?}"),
            })
            .collect();
        rates.sort_by(f64::total_cmp);
        assert_frequencies("double_pendulum_points upright", &rates, &exact, 1e-12);
    }
}

/// HW30: with the slot on a diameter (d = 0) the modes decouple, ω = √(k_t/I_t) and √(k/m_s).
/// With an offset d (HW20's geometry) the hand-derived M = [[I_t + m_s d², m_s d],
/// [m_s d, m_s]], K = diag(k_t, k) (the zero-rest-length spring's energy ½ k (d² + s²) does
/// not depend on θ) couple them; ω² the roots of det(K − ω² M) = 0.
#[test]
fn turntable_slot_spring_hw30() {
    let name = "turntable_slot_spring";
    let (i_t, k_t, m_s, k): (f64, f64, f64, f64) = (0.5, 2.0, 1.0, 9.0);
    let (_, modes) = modes_at(model(name, &[]).as_ref(), "rest");
    let mut exact = [(k_t / i_t).sqrt(), (k / m_s).sqrt()];
    exact.sort_by(f64::total_cmp);
    assert_frequencies(name, &modes.natural_frequencies, &exact, 1e-12);
    // The turning mode moves only θ, the sliding mode only s.
    let shapes = &modes.mode_shapes;
    assert!(shapes[(1, 0)].abs() < 1e-14 && shapes[(0, 1)].abs() < 1e-14);

    let (i_t, k_t, m_s, k, d) = (0.8, 3.0, 0.6, 5.0, 0.4);
    let m = model(
        name,
        &[("I_t", i_t), ("k_t", k_t), ("m_s", m_s), ("k", k), ("d", d)],
    );
    let (lin, modes) = modes_at(m.as_ref(), "rest");
    let mh = [[i_t + m_s * d * d, m_s * d], [m_s * d, m_s]];
    let kh = [[k_t, 0.0], [0.0, k]];
    assert_matrix(name, "M", &lin.mass_matrix, &mat2(mh), 1e-14);
    assert_matrix(name, "K", &lin.stiffness_matrix, &mat2(kh), 1e-14);
    let exact = two_by_two(mh, kh).map(f64::sqrt);
    assert_frequencies(name, &modes.natural_frequencies, &exact, 1e-12);
}

/// HW29: pipe (M, R, thin-walled) rolling on the ground, disk (m, r) rolling inside. With
/// ρ = R − r, at φ = 0 the pipe's T = ½ M ẋ² + ½ M R² (ẋ/R)² = M ẋ², and the disk's centre moves
/// at u = ẋ + ρ φ̇ with spin u/r, so T = M ẋ² + ¾ m u²; V = m g ρ (1 − cos φ). Hence
/// M = [[2M + 3m/2, 3mρ/2], [3mρ/2, 3mρ²/2]], K = diag(0, m g ρ): one zero-frequency mode (the
/// whole rolls along, shape (1, 0)) and, as det M = 3 M m ρ², ω² = g (4M + 3m)/(6 M ρ).
/// Special cases: a heavy pipe (M → ∞) is HW26's fixed pipe, ω² → 2g/(3ρ).
#[test]
fn cylinder_in_pipe_hw29() {
    let name = "cylinder_in_pipe";
    for (pm, pr, m, r, g) in [(2.0, 1.0, 1.0, 0.4, 10.0), (3.0, 1.2, 0.5, 0.3, 9.81)] {
        let model = model(name, &[("M", pm), ("R", pr), ("m", m), ("r", r), ("g", g)]);
        let (lin, modes) = modes_at(model.as_ref(), "bottom");
        let rho = pr - r;
        let mh = [
            [2.0 * pm + 1.5 * m, 1.5 * m * rho],
            [1.5 * m * rho, 1.5 * m * rho * rho],
        ];
        assert_matrix(name, "M", &lin.mass_matrix, &mat2(mh), 1e-14);
        assert_matrix(
            name,
            "K",
            &lin.stiffness_matrix,
            &mat2([[0.0, 0.0], [0.0, m * g * rho]]),
            1e-14,
        );
        assert_eq!(modes.kinds[0], ModeKind::ZeroFrequency);
        assert!(
            modes.mode_shapes[(1, 0)].abs() < 1e-14,
            "rolling mode: φ = 0"
        );
        let exact = (g * (4.0 * pm + 3.0 * m) / (6.0 * pm * rho)).sqrt();
        assert_frequencies(name, &modes.natural_frequencies, &[0.0, exact], 1e-12);
    }
    // M = 1e6 M: ω² = g (4M + 3m)/(6 M ρ) = 2g/(3ρ) (1 + 3m/(4M)), within 1e-6 of HW26.
    let heavy = model(name, &[("M", 1e6)]);
    let (_, modes) = modes_at(heavy.as_ref(), "bottom");
    let hw26 = (2.0 * 10.0 / (3.0 * 0.6_f64)).sqrt();
    assert!((modes.natural_frequencies[1] / hw26 - 1.0).abs() < 1e-6);
}

/// HW31, 1-D: three free masses, two springs. M = m I, K = k [[1,−1,0],[−1,2,−1],[0,−1,1]]:
/// ω² = 0 (translation [1,1,1]), k/m ([1,0,−1]) and 3k/m ([1,−2,1]); one zero mode.
#[test]
fn spring_line_three_hw31() {
    let (m, k) = (0.8, 2.5);
    let name = "spring_line_three";
    let (lin, modes) = modes_at(model(name, &[("m", m), ("k", k)]).as_ref(), "rest");
    let kh = DMatrix::from_row_slice(3, 3, &[1.0, -1.0, 0.0, -1.0, 2.0, -1.0, 0.0, -1.0, 1.0]) * k;
    assert_matrix(name, "K", &lin.stiffness_matrix, &kh, 1e-14);
    assert_eq!(zero_modes(&modes), 1);
    let w = (k / m).sqrt();
    assert_frequencies(
        name,
        &modes.natural_frequencies,
        &[0.0, w, 3f64.sqrt() * w],
        1e-12,
    );
    for (col, shape) in [[1.0, 1.0, 1.0], [1.0, 0.0, -1.0], [1.0, -2.0, 1.0]]
        .iter()
        .enumerate()
    {
        let psi = modes.mode_shapes.column(col);
        let c = psi[0] / shape[0];
        for i in 0..3 {
            assert!((psi[i] - c * shape[i]).abs() < 1e-12, "mode {col}: {psi}");
        }
    }
}

/// HW31, 3-D: two masses, one spring along e = (2, 1, 2)/3. Five zero modes: the three
/// translations and the two rotations about axes perpendicular to e (δr1 = 0 at the origin,
/// δr2 = ℓ ω × e) cost no energy and are independent, and there are exactly five; the axial
/// mode ψ ∝ [−e/m1; e/m2] has ω² = k (1/m1 + 1/m2).
#[test]
fn spring_pair_3d_hw31() {
    let (m1, m2, k, l) = (0.7, 1.9, 4.0, 1.3);
    let name = "spring_pair_3d";
    let model = model(name, &[("m1", m1), ("m2", m2), ("k", k), ("l", l)]);
    let (lin, modes) = modes_at(model.as_ref(), "rest");
    let e = [2.0 / 3.0, 1.0 / 3.0, 2.0 / 3.0];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let mut rigid: Vec<Vec<f64>> = (0..3)
        .map(|i| {
            let mut v = vec![0.0; 6];
            v[i] = 1.0;
            v[3 + i] = 1.0;
            v
        })
        .collect();
    for axis in [[1.0, -2.0, 0.0], cross(e, [1.0, -2.0, 0.0])] {
        let d = cross(axis, e);
        rigid.push(vec![0.0, 0.0, 0.0, l * d[0], l * d[1], l * d[2]]);
    }
    for v in &rigid {
        assert_null(name, &lin.stiffness_matrix, v);
    }
    let span = DMatrix::from_fn(6, 5, |i, j| rigid[j][i]);
    assert_eq!(
        span.rank(1e-10),
        5,
        "the five rigid motions are independent"
    );
    assert_eq!(zero_modes(&modes), 5);
    let w2 = k * (1.0 / m1 + 1.0 / m2);
    assert_frequencies(
        name,
        &modes.natural_frequencies,
        &[0.0, 0.0, 0.0, 0.0, 0.0, w2.sqrt()],
        1e-12,
    );
    let psi = modes.mode_shapes.column(5);
    let axial = [
        -e[0] / m1,
        -e[1] / m1,
        -e[2] / m1,
        e[0] / m2,
        e[1] / m2,
        e[2] / m2,
    ];
    let c = psi[3] / axial[3];
    for i in 0..6 {
        assert!((psi[i] - c * axial[i]).abs() < 1e-12, "axial mode: {psi}");
    }
}

/// The ring formula (HW31; derived in models/spring_hexagon.yaml): N equal masses on a
/// regular N-gon with N edge springs (no pretension) have N zero modes (3 rigid, N − 3
/// mechanisms) and ω² = (k/m)(2 − 2 cos(2π/N) cos(2πp/N)), p = 0…N−1.
fn ring_frequencies(n: usize, k: f64, m: f64) -> Vec<f64> {
    let nf = n as f64;
    let mut w: Vec<f64> = (0..n)
        .map(|_| 0.0)
        .chain((0..n).map(|p| {
            let c = (2.0 * PI / nf).cos() * (2.0 * PI * p as f64 / nf).cos();
            (k / m * (2.0 - 2.0 * c)).sqrt()
        }))
        .collect();
    w.sort_by(f64::total_cmp);
    w
}

/// Rigid motions of a planar point set at `points`: two translations and the rotation.
fn planar_rigid(points: &[(f64, f64)]) -> Vec<Vec<f64>> {
    let tx = points.iter().flat_map(|_| [1.0, 0.0]).collect();
    let ty = points.iter().flat_map(|_| [0.0, 1.0]).collect();
    let rot = points.iter().flat_map(|(x, y)| [-y, *x]).collect();
    vec![tx, ty, rot]
}

/// HW31, the square: each spring joins two masses along x or along y, so K splits into four
/// 1-D two-mass oscillators: four zero modes (3 rigid + 1 mechanism, the shear into a rhombus)
/// and ω² = 2k/m four times — the ring formula with N = 4.
#[test]
fn spring_square_hw31() {
    let (m, k, a) = (0.8, 2.5, 1.5);
    let name = "spring_square";
    let (lin, modes) = modes_at(
        model(name, &[("m", m), ("k", k), ("a", a)]).as_ref(),
        "rest",
    );
    let corners = [(0.0, 0.0), (a, 0.0), (a, a), (0.0, a)];
    let mut null = planar_rigid(&corners);
    // The mechanism: the top edge slides along x, the square shears.
    null.push(vec![0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0]);
    for v in &null {
        assert_null(name, &lin.stiffness_matrix, v);
    }
    assert_eq!(DMatrix::from_fn(8, 4, |i, j| null[j][i]).rank(1e-10), 4);
    assert_eq!(zero_modes(&modes), 4, "3 rigid-body modes + 1 mechanism");
    let w = (2.0 * k / m).sqrt();
    assert_frequencies(
        name,
        &modes.natural_frequencies,
        &[0.0, 0.0, 0.0, 0.0, w, w, w, w],
        1e-12,
    );
    assert_frequencies(
        name,
        &modes.natural_frequencies,
        &ring_frequencies(4, k, m),
        1e-12,
    );
}

/// HW31, the hexagon: 6 zero modes (3 rigid + 3 mechanisms), the breathing mode by inspection
/// (every corner radially outward, ω² = k/m) and the rest by the ring formula:
/// ω² = (k/m) {1, 3/2, 3/2, 5/2, 5/2, 3}.
#[test]
fn spring_hexagon_hw31() {
    let (m, k, a) = (0.8, 2.5, 1.5);
    let name = "spring_hexagon";
    let (lin, modes) = modes_at(
        model(name, &[("m", m), ("k", k), ("a", a)]).as_ref(),
        "rest",
    );
    let corners: Vec<(f64, f64)> = (0..6)
        .map(|i| {
            let t = f64::from(i) * PI / 3.0;
            (a * t.cos(), a * t.sin())
        })
        .collect();
    for v in planar_rigid(&corners) {
        assert_null(name, &lin.stiffness_matrix, &v);
    }
    assert_eq!(zero_modes(&modes), 6, "3 rigid-body modes + 3 mechanisms");
    let exact: Vec<f64> = [0.0; 6]
        .into_iter()
        .chain([1.0, 1.5, 1.5, 2.5, 2.5, 3.0])
        .map(|c: f64| (c * k / m).sqrt())
        .collect();
    assert_frequencies(name, &modes.natural_frequencies, &exact, 1e-12);
    assert_frequencies(
        name,
        &modes.natural_frequencies,
        &ring_frequencies(6, k, m),
        1e-12,
    );
    // The breathing mode: K ψ = (k/m) M ψ for the radial unit vectors.
    let radial: Vec<f64> = corners.iter().flat_map(|(x, y)| [x / a, y / a]).collect();
    let psi = DVector::from_vec(radial);
    let r = &lin.stiffness_matrix * &psi - &lin.mass_matrix * &psi * (k / m);
    assert!(r.amax() < 1e-12 * k, "breathing mode residual {r}");
    // It is the lowest nonzero mode (a simple eigenvalue): the computed shape is radial.
    let shape = modes.mode_shapes.column(6);
    let c = shape.dot(&psi) / psi.dot(&psi);
    assert!((shape - psi * c).amax() < 1e-12);
}

/// The discrete string: `n` beads between walls, M = m I, K = (T/a) tridiag(−1, 2, −1) with
/// a = L/(n + 1), m = ρ a.
fn assembled_chain(n: usize, tension: f64, rho: f64, length: f64) -> Linearization {
    let a = length / (n as f64 + 1.0);
    let mut k = DMatrix::zeros(n, n);
    for i in 0..n {
        k[(i, i)] = 2.0 * tension / a;
        if i + 1 < n {
            k[(i, i + 1)] = -tension / a;
            k[(i + 1, i)] = -tension / a;
        }
    }
    Linearization::from_matrices(DMatrix::identity(n, n) * (rho * a), k, DMatrix::zeros(n, n))
}

/// The exact frequencies of the discrete string: ω_k = 2 √(T/(m a)) sin(kπ/(2(n + 1))).
fn chain_exact(n: usize, tension: f64, rho: f64, length: f64) -> Vec<f64> {
    let a = length / (n as f64 + 1.0);
    let m = rho * a;
    (1..=n)
        .map(|k| {
            2.0 * (tension / (m * a)).sqrt() * (k as f64 * PI / (2.0 * (n as f64 + 1.0))).sin()
        })
        .collect()
}

/// The model file of a string of `n` beads, written as models/string_chain.yaml is for n = 8.
fn chain_file(n: usize) -> String {
    let p = |i: usize| {
        if i == 0 {
            "W0".to_string()
        } else if i == n + 1 {
            "W1".to_string()
        } else {
            format!("P{i}")
        }
    };
    let mut s = format!(
        "name: string_chain_{n}\ndescription: beads on a string\nparameters: {{ tension: 1.0, rho: 1.0, L: 1.0 }}\ncoordinates: [{}]\npoints:\n  W0: [0, 0]\n",
        (1..=n)
            .map(|i| format!("y{i}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    for i in 1..=n {
        s += &format!("  P{i}: [{i}*L/{}, y{i}]\n", n + 1);
    }
    s += "  W1: [L, 0]\nbodies:\n";
    for i in 1..=n {
        s += &format!("  bead{i}: {{ mass: rho*L/{}, at: P{i} }}\n", n + 1);
    }
    s += "springs:\n";
    for i in 0..=n {
        s += &format!(
            "  s{i}: {{ between: [{}, {}], stiffness: {}*tension/L }}\n",
            p(i),
            p(i + 1),
            n + 1
        );
    }
    s
}

/// M and K = −∂F/∂q at rest of a model file derived at run time (Lagrange, exact Jacobians,
/// evaluated on the expression DAG), with its default parameters.
fn derived_at_rest(source: &str) -> (DMatrix<f64>, DMatrix<f64>) {
    let file = eomgen_symbolic::model::load("string_chain_n.yaml", source).expect("file loads");
    let mut model = SymbolicModel::from_file(&file).expect("file lowers");
    let eom = Lagrange.derive(&mut model);
    let jac = Jacobians::of(&mut model, &eom);
    let n = model.num_dofs();
    let roots = [eom.mass_matrix.clone(), jac.forcing_q.clone()].concat();
    let mut evaluator = Evaluator::new(&model.arena, &roots);
    let bindings: Vec<f64> = model
        .arena
        .symbols()
        .iter()
        .map(|s| match s.kind {
            SymbolKind::Parameter => {
                model
                    .parameters
                    .iter()
                    .find(|p| p.name == s.name)
                    .expect("parameter")
                    .default
            }
            _ => 0.0,
        })
        .collect();
    let e = evaluator.eval(&bindings);
    let m = DMatrix::from_row_slice(n, n, &e[..n * n]);
    let k = -DMatrix::from_row_slice(n, n, &e[n * n..2 * n * n]);
    (m, k)
}

/// The bundled string (N = 8) is the discrete string: its M and K equal the assembled ones
/// (to rounding, 1e-14), and its frequencies the exact discrete ω_k (1e-12), also at other
/// parameters. Chains of 4 and 16 beads derived at run time from a file of the same form
/// give the same assembly, so the assembled chain stands for the model at every N below.
#[test]
fn string_chain_is_the_discrete_string() {
    let name = "string_chain";
    for (tension, rho, length) in [(1.0, 1.0, 1.0), (4.0, 0.25, 2.0)] {
        let m = model(name, &[("tension", tension), ("rho", rho), ("L", length)]);
        let (lin, modes) = modes_at(m.as_ref(), "rest");
        let chain = assembled_chain(8, tension, rho, length);
        assert_matrix(name, "M", &lin.mass_matrix, &chain.mass_matrix, 1e-14);
        assert_matrix(
            name,
            "K",
            &lin.stiffness_matrix,
            &chain.stiffness_matrix,
            1e-14,
        );
        let exact = chain_exact(8, tension, rho, length);
        assert_frequencies(name, &modes.natural_frequencies, &exact, 1e-12);
        // Mode k has the shape sin(i k π/(N + 1)).
        for k in 1..=8 {
            let psi = modes.mode_shapes.column(k - 1);
            let s: Vec<f64> = (1..=8)
                .map(|i| (f64::from(i) * k as f64 * PI / 9.0).sin())
                .collect();
            let c = psi.dot(&DVector::from_vec(s.clone())) / s.iter().map(|v| v * v).sum::<f64>();
            for i in 0..8 {
                assert!((psi[i] - c * s[i]).abs() < 1e-12, "mode {k}: {psi}");
            }
        }
    }
    let bundled = model(name, &[]);
    let (lin8, _) = modes_at(bundled.as_ref(), "rest");
    for n in [4, 8, 16] {
        let (m, k) = derived_at_rest(&chain_file(n));
        let chain = assembled_chain(n, 1.0, 1.0, 1.0);
        assert_matrix("string_chain_n", "M", &m, &chain.mass_matrix, 1e-14);
        assert_matrix("string_chain_n", "K", &k, &chain.stiffness_matrix, 1e-14);
        if n == 8 {
            assert_matrix("string_chain_n", "K", &k, &lin8.stiffness_matrix, 1e-14);
        }
    }
}

/// Lectures 35–37: ω_k → kπc/L. With h = kπ/(2(N + 1)), ω_k/(kπc/L) = sin(h)/h, so the
/// relative error is e = 1 − sin(h)/h = h²/6 − h⁴/120 + h⁶/5040 − …, to leading order
/// (kπ/(N + 1))²/24: second order in the bead spacing a = L/(N + 1). Measured on the chain's
/// eigenvalues (not the formula) for N + 1 = 8 … 128 and k = 1, 2, 3:
/// - e/(leading term) = 1 − h²/20 + h⁴/840 − …: within h²/20 of 1, plus the rounding of the
///   eigenvalues (bounded below);
/// - the observed order p = log₂(e(N)/e(2N + 1)) is 2 up to the h² correction: with h the
///   coarser chain's, e(h)/e(h/2) = 4 (1 − h²/20)/(1 − h²/80) + O(h⁴), so
///   p − 2 ≈ log₂(1 − 3h²/80) ≈ −0.054 h² (bound 0.06 h² + 1e-6, for N + 1 ≥ 16).
#[test]
fn string_chain_converges_to_the_wave_equation_at_second_order() {
    let (tension, rho, length): (f64, f64, f64) = (1.0, 1.0, 1.0);
    let c = (tension / rho).sqrt();
    let sizes = [8usize, 16, 32, 64, 128];
    let mut errors = vec![Vec::new(); 3];
    for &cells in &sizes {
        let n = cells - 1;
        let modes = normal_modes(&assembled_chain(n, tension, rho, length)).unwrap();
        for (k, errs) in errors.iter_mut().enumerate() {
            let k1 = (k + 1) as f64;
            let continuum = k1 * PI * c / length;
            let e = 1.0 - modes.natural_frequencies[k] / continuum;
            let h = k1 * PI / (2.0 * cells as f64);
            let leading = (k1 * PI / cells as f64).powi(2) / 24.0;
            // Rounding: the eigensolver's absolute error on ω² is a small multiple of ε λ_max,
            // λ_max < 4 T/(ρ a²), i.e. ε λ_max/(2 ω²) relative on ω; divided by e, times 8.
            // It grows like N⁴ against e's N⁻², which is why N + 1 stops at 128 (there it is
            // a quarter of the h² term for k = 1).
            let a = length / cells as f64;
            let omega2 = modes.natural_frequencies[k].powi(2);
            let rounding = 8.0 * f64::EPSILON * 4.0 * tension / (rho * a * a) / (2.0 * omega2) / e;
            assert!(
                (e / leading - 1.0).abs() <= h * h / 20.0 + rounding,
                "k = {k1}, N + 1 = {cells}: e = {e:e}, leading term {leading:e}"
            );
            errs.push((e, h));
        }
    }
    for (k, errs) in errors.iter().enumerate() {
        for pair in errs.windows(2).skip(1) {
            let ((e1, h1), (e2, _)) = (pair[0], pair[1]);
            let order = (e1 / e2).log2();
            assert!(
                (order - 2.0).abs() <= 0.06 * h1 * h1 + 1e-6,
                "k = {}: observed order {order}",
                k + 1
            );
        }
    }
}

/// Lecture 37: the Rayleigh quotient of the guess y = x(L − x). In the continuum,
/// ω² = (T ∫ y′²)/(ρ ∫ y²) = T (L³/3)/(ρ L⁵/30) = 10 c²/L², so ω = √10 c/L, 0.66 % above πc/L.
/// On the chain of N beads (spacing a), yᵀKy = T a Σ (L − 2 x_mid)² = T (L³ − L a²)/3 (the
/// midpoint rule of a quadratic) and yᵀMy = ρ a Σ y(x_i)² = ρ (L⁵ − L a⁴)/30 (the trapezoidal
/// rule of a quartic whose y′ vanishes at both ends: Euler–Maclaurin leaves only the a⁴ term),
/// so R = 10 c²/(L² + a²) exactly: it approaches √10 c/L from below at second order, and stays
/// above the chain's own ω₁² (Rayleigh's principle). Tolerances: 1e-13 (a sum of N squares).
#[test]
fn rayleigh_quotient_of_the_parabola() {
    let (tension, rho, length): (f64, f64, f64) = (4.0, 0.25, 2.0);
    let c = (tension / rho).sqrt();
    let continuum = 10f64.sqrt() * c / length;
    assert!((continuum / (PI * c / length) - 1.0 - 0.006_585).abs() < 1e-6);
    let bundled = model(
        "string_chain",
        &[("tension", tension), ("rho", rho), ("L", length)],
    );
    let (lin8, modes8) = modes_at(bundled.as_ref(), "rest");
    let mut previous_gap = f64::INFINITY;
    for n in [8usize, 17, 35, 71] {
        let lin = if n == 8 {
            lin8.clone()
        } else {
            assembled_chain(n, tension, rho, length)
        };
        let a = length / (n as f64 + 1.0);
        let y = DVector::from_fn(n, |i, _| {
            let x = (i + 1) as f64 * a;
            x * (length - x)
        });
        let quotient = y.dot(&(&lin.stiffness_matrix * &y)) / y.dot(&(&lin.mass_matrix * &y));
        let exact = 10.0 * c * c / (length * length + a * a);
        assert!(
            (quotient / exact - 1.0).abs() < 1e-13,
            "N = {n}: R = {quotient} vs {exact}"
        );
        let w1 = if n == 8 {
            modes8.natural_frequencies[0]
        } else {
            chain_exact(n, tension, rho, length)[0]
        };
        assert!(quotient >= w1 * w1, "Rayleigh's principle at N = {n}");
        let gap = continuum - quotient.sqrt();
        assert!(gap > 0.0 && gap < previous_gap);
        previous_gap = gap;
    }
}

/// HW24 d: released from rest in the slow mode shape (θ2 = √2 θ1) with a small amplitude A,
/// the *nonlinear* double pendulum moves synchronously. The nonlinear terms are cubic in the
/// angles (sin θ − θ, (cos(θ1 − θ2) − 1) θ̈, sin(θ1 − θ2) θ̇²), so the motion leaves the linear
/// mode by a relative O(A²): measured by (a) max |θ2 − √2 θ1|/A over ten periods and (b) the
/// phase lag ω max |t₁ − t₂| between the zeros of θ1 and θ2 (located by event detection on
/// DOP853's dense output at tol 1e-12, so to ~1e-10 s). Both must be below 2 A² (a coefficient
/// of order one, as the cubic terms' are: sin θ = θ − θ³/6, cos Δ = 1 − Δ²/2) and scale like A²: doubling A multiplies them by
/// 4 ± 0.5 (the next correction is relative O(A²) ≈ 1e-3 here, the integration error
/// ~1e-10 against measured values ≥ 1e-6). A start off the mode (θ2 = 0) gives an O(1)
/// shape error, so the measure can fail.
#[test]
fn double_pendulum_points_mode_gives_synchronous_motion() {
    let ratio = 2f64.sqrt();
    let omega = (10.0 * (2.0 - ratio)).sqrt();
    let period = 2.0 * PI / omega;
    let run = |theta1: f64, theta2: f64| -> (f64, f64) {
        let mut system = FirstOrder::new(DoublePendulumPoints::default());
        let specs = vec![
            EventSpec::new("theta1", EventDirection::Both, false),
            EventSpec::new("theta2", EventDirection::Both, false),
        ];
        let mut with = WithEvents::new(
            &mut system,
            specs,
            |_: &mut FirstOrder<DoublePendulumPoints, 2>, _t, y: &[f64], g: &mut [f64]| {
                g[0] = y[0];
                g[1] = y[1];
                Ok(())
            },
        );
        let t_end = 10.0 * period;
        let times: Vec<f64> = (1..=2000).map(|i| t_end * f64::from(i) / 2000.0).collect();
        let options = IntegratorOptions::default()
            .with_rtol(1e-12)
            .with_atol(1e-12);
        let solution = DormandPrince853::new()
            .integrate(
                &mut with,
                0.0,
                &[theta1, theta2, 0.0, 0.0],
                t_end,
                &OutputTimes::At(times),
                &options,
            )
            .expect("the double pendulum integrates");
        let shape_error = solution
            .iter()
            .map(|(_, y)| (y[1] - ratio * y[0]).abs())
            .fold(0.0f64, f64::max)
            / theta1;
        let zeros = |i: usize| -> Vec<f64> {
            solution
                .events
                .iter()
                .filter(|e| e.index == i)
                .map(|e| e.t)
                .collect()
        };
        let (z1, z2) = (zeros(0), zeros(1));
        let phase = if z1.len() == z2.len() {
            z1.iter()
                .zip(&z2)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0f64, f64::max)
                * omega
        } else {
            f64::INFINITY
        };
        (shape_error, phase)
    };
    let amplitudes = [0.01, 0.02, 0.04];
    let measured: Vec<(f64, f64)> = amplitudes.iter().map(|a| run(*a, ratio * a)).collect();
    for (a, (shape, phase)) in amplitudes.iter().zip(&measured) {
        assert!(
            *shape < 2.0 * a * a && *phase < 2.0 * a * a,
            "A = {a}: shape error {shape:e}, phase error {phase:e} rad"
        );
    }
    for pair in measured.windows(2) {
        let (s_ratio, p_ratio) = (pair[1].0 / pair[0].0, pair[1].1 / pair[0].1);
        assert!(
            (s_ratio - 4.0).abs() < 0.5 && (p_ratio - 4.0).abs() < 0.5,
            "doubling A: shape error ×{s_ratio}, phase error ×{p_ratio}"
        );
    }
    let (off_mode, _) = run(0.01, 0.0);
    assert!(off_mode > 0.5, "off the mode: shape error {off_mode}");
}

/// `eomgen modes MODEL --plot PREFIX` writes one valid SVG per mode: for every one of the
/// three configurations (equilibrium in grey, ± the scaled shape in red and blue) one
/// polyline per `draw:` line plus one legend entry, a title with ω and the kind; `.png`
/// prefixes write PNG files.
#[test]
fn mode_charts_are_written() {
    // The generated `draw:` accessors the charts use, as in the model file.
    let dp = model("double_pendulum_points", &[]);
    assert_eq!(
        dp.description().draw_line_names(),
        &[["O", "E"], ["E", "H"]]
    );
    assert_eq!(dp.description().trace_point_names(), &["H"]);
    let dir = std::env::temp_dir().join(format!("eomgen-mode-charts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, lines, modes) in [
        ("double_pendulum_points", 2, 2),
        ("spring_line_three", 2, 3),
    ] {
        let prefix = dir.join(name);
        let out = eomgen_ok(&["modes", name, "--plot", prefix.to_str().unwrap(), "--json"]);
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let charts = json["charts"].as_array().unwrap();
        assert_eq!(charts.len(), modes);
        for k in 1..=modes {
            let path = format!("{}-mode{k}.svg", prefix.to_str().unwrap());
            assert_eq!(charts[k - 1].as_str(), Some(path.as_str()));
            let svg = std::fs::read_to_string(&path).unwrap();
            assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
            assert_eq!(svg.matches("<svg").count(), 1);
            for colour in ["#969696", "#D62728", "#1F77B4"] {
                let count = svg
                    .match_indices("<polyline")
                    .filter(|(i, _)| {
                        let end = svg[*i..].find("/>").unwrap();
                        svg[*i..*i + end].contains(&format!("stroke=\"{colour}\""))
                    })
                    .count();
                assert_eq!(count, lines + 1, "{path}: {colour} polylines");
            }
            assert!(svg.contains(&format!("mode {k}:")), "{path}: title");
        }
    }
    let dp = std::fs::read_to_string(dir.join("double_pendulum_points-mode1.svg")).unwrap();
    assert!(dp.contains("ω = 2.42030 rad/s") && dp.contains("oscillatory"));
    let line = std::fs::read_to_string(dir.join("spring_line_three-mode1.svg")).unwrap();
    assert!(line.contains("zero-frequency"));

    // A 3-D model is drawn in an isometric view.
    let prefix = dir.join("pair");
    eomgen_ok(&[
        "modes",
        "spring_pair_3d",
        "--plot",
        prefix.to_str().unwrap(),
    ]);
    let pair = std::fs::read_to_string(dir.join("pair-mode6.svg")).unwrap();
    assert!(pair.contains("isometric view"));

    let png = dir.join("pipe.png");
    eomgen_ok(&["modes", "cylinder_in_pipe", "--plot", png.to_str().unwrap()]);
    for k in 1..=2 {
        let bytes = std::fs::read(dir.join(format!("pipe-mode{k}.png"))).unwrap();
        assert!(
            bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
            "mode {k}: a PNG file"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
