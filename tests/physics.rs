//! Course results checked against closed forms, hand derivations and conservation laws.
//!
//! Each test states its tolerance and why. References are computed here from formulas, never
//! copied from a previous run.

use crate::common;
use common::seeded_rng;
use rand::RngExt;

use std::f64::consts::PI;

use eomgen::analysis::energy_drift;
use eomgen::models;
use eomgen::{
    DormandPrince54, Integrator, IntegratorOptions, ModelInfo, OutputTimes, RungeKutta4, Solution,
};

fn model(name: &str) -> Box<dyn ModelInfo> {
    (models::find(name)
        .unwrap_or_else(|| panic!("model {name}"))
        .make)()
}

fn tight() -> IntegratorOptions {
    IntegratorOptions::default()
        .with_rtol(1e-12)
        .with_atol(1e-12)
}

fn solve(
    m: &mut dyn ModelInfo,
    y0: &[f64],
    t_end: f64,
    times: Vec<f64>,
    options: &IntegratorOptions,
) -> Solution {
    DormandPrince54::new()
        .integrate(
            m.as_ode_mut(),
            0.0,
            y0,
            t_end,
            &OutputTimes::At(times),
            options,
        )
        .unwrap_or_else(|e| panic!("{} failed: {e}", m.description().name))
}

/// HW2: the closed form with linear drag, tau = m/c:
/// x = v0x tau (1 − e^{−t/tau}), y = tau (v0y + g tau)(1 − e^{−t/tau}) − g tau t.
/// At rtol = atol = 1e-12 the global error over 2 s is ~1e-11; tolerance 1e-9.
#[test]
fn cannonball_matches_closed_form() {
    let mut m = model("cannonball");
    let p = |name: &str| {
        m.parameter_values()[m
            .description()
            .parameter_names()
            .iter()
            .position(|n| *n == name)
            .unwrap()]
    };
    let (mass, g, c, v0, th) = (p("m"), p("g"), p("c"), p("v0"), p("theta0"));
    assert_eq!(th, PI / 4.0);
    let y0 = m.initial_state();
    let times = vec![0.5, 1.0, 2.0];
    let s = solve(m.as_mut(), &y0, 2.0, times.clone(), &tight());
    let tau = mass / c;
    for (i, t) in times.iter().enumerate() {
        let e = 1.0 - (-t / tau).exp();
        let x = v0 * th.cos() * tau * e;
        let y = tau * (v0 * th.sin() + g * tau) * e - g * tau * t;
        let st = s.state(i);
        assert!(
            (st[0] - x).abs() < 1e-9 && (st[1] - y).abs() < 1e-9,
            "t={t}: {st:?} vs ({x}, {y})"
        );
    }
}

/// Time in (a, b) where `g(state at t)` changes sign, by bisection on dense output of
/// fresh integrations from 0 (each to 1e-13 in time).
fn crossing(
    m: &mut dyn ModelInfo,
    y0: &[f64],
    mut a: f64,
    mut b: f64,
    g: &dyn Fn(&[f64]) -> f64,
) -> f64 {
    let value = |m: &mut dyn ModelInfo, t: f64| {
        let s = solve(m, y0, t, vec![t], &tight());
        g(s.state(0))
    };
    let ga = value(m, a);
    assert!(ga * value(m, b) < 0.0, "no sign change in ({a}, {b})");
    while b - a > 1e-13 {
        let mid = 0.5 * (a + b);
        if value(m, mid) * ga > 0.0 {
            a = mid
        } else {
            b = mid
        }
    }
    0.5 * (a + b)
}

/// Lecture 10: small-angle period 2π√(l/g). Released from rest at amplitude θ0 = 1e-3 about
/// the hanging position q = −π/2, the exact period is 2π√(l/g)(1 + θ0²/16 + …), a relative
/// correction of 6e-8; integration and root finding add < 1e-10. Tolerance 1e-6 relative.
#[test]
fn simple_pendulum_small_angle_period() {
    let mut m = model("simple_pendulum");
    let (l, g) = (1.0, 10.0);
    assert_eq!(m.parameter_values(), vec![1.0, l, g]);
    let y0 = vec![-PI / 2.0 + 1e-3, 0.0];
    let period = 2.0 * PI * (l / g).sqrt();
    let offset = |y: &[f64]| y[0] + PI / 2.0;
    let t1 = crossing(m.as_mut(), &y0, 0.1 * period, 0.5 * period, &offset);
    let t3 = crossing(m.as_mut(), &y0, 0.6 * period, 0.9 * period, &offset);
    let measured = 2.0 * (t3 - t1);
    assert!(
        (measured / period - 1.0).abs() < 1e-6,
        "period {measured} vs {period}"
    );
}

/// HW23d: released from rest in a mode shape, the three masses stay in it:
/// x(t) = x0 cos(ω t) with ω² = (2 − √2), 2, (2 + √2) times k/m for the shapes
/// [1, √2, 1], [1, 0, −1], [1, −√2, 1]. The springs have rest length a and the masses stay
/// apart, so the model is exactly linear. Tolerance 1e-8 (integration at 1e-12 over 10 s).
#[test]
fn three_masses_released_in_a_mode_stay_in_it() {
    let s2 = 2f64.sqrt();
    let modes = [
        ([1.0, s2, 1.0], 2.0 - s2),
        ([1.0, 0.0, -1.0], 2.0),
        ([1.0, -s2, 1.0], 2.0 + s2),
    ];
    for (shape, w2) in modes {
        let mut m = model("three_masses");
        let x0: Vec<f64> = shape.iter().map(|v| 0.5 * v).collect();
        let y0 = [x0.clone(), vec![0.0; 3]].concat();
        let times: Vec<f64> = (1..=10).map(f64::from).collect();
        let s = solve(m.as_mut(), &y0, 10.0, times.clone(), &tight());
        let w = f64::sqrt(w2);
        for (i, t) in times.iter().enumerate() {
            for (k, x0k) in x0.iter().enumerate() {
                let exact = x0k * (w * t).cos();
                assert!(
                    (s.state(i)[k] - exact).abs() < 1e-8,
                    "mode ω²={w2}, t={t}, x{k}: {} vs {exact}",
                    s.state(i)[k]
                );
            }
        }
    }
}

/// HW9b: F = (m1 + m2) a_G. Directly from the equations at random states (only rounding
/// differs: tolerance 1e-12 relative to F0), and along a simulation:
/// x_G(t) = m2 l0/(m1+m2) + F0 t²/(2(m1+m2)) (tolerance 1e-8 at rtol 1e-12).
#[test]
fn two_masses_centre_of_mass_obeys_total_force() {
    let mut m = model("two_masses");
    let names = m.description().parameter_names();
    let p = m.parameter_values();
    let get = |n: &str| p[names.iter().position(|x| *x == n).unwrap()];
    let (m1, m2, l0, f0) = (get("m1"), get("m2"), get("l0"), get("F0"));
    let mut rng = seeded_rng(42);
    let mut dy = vec![0.0; 4];
    for _ in 0..100 {
        let y: Vec<f64> = vec![
            rng.random_range(-1.0..0.5),
            rng.random_range(1.0..2.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
        ];
        let t = rng.random_range(0.0..5.0);
        m.rhs(t, &y, &mut dy).unwrap();
        let total = m1 * dy[2] + m2 * dy[3];
        assert!(
            (total - f0).abs() < 1e-12 * f0.abs().max(1.0) * 10.0,
            "m1 a1 + m2 a2 = {total}, F0 = {f0}"
        );
    }
    let y0 = m.initial_state();
    let times: Vec<f64> = vec![0.5, 1.0, 2.0, 3.0];
    let s = solve(m.as_mut(), &y0, 3.0, times.clone(), &tight());
    for (i, t) in times.iter().enumerate() {
        let st = s.state(i);
        let xg = (m1 * st[0] + m2 * st[1]) / (m1 + m2);
        let exact = m2 * l0 / (m1 + m2) + f0 * t * t / (2.0 * (m1 + m2));
        assert!((xg - exact).abs() < 1e-8, "t={t}: x_G {xg} vs {exact}");
    }
}

/// Lecture 21: steady-state amplitude X = (F0/k)/√((1 − r²)² + (2ζr)²). The transient decays
/// as e^{−ζ ω_n t} = e^{−30} by t = 60 s; the amplitude is (max − min)/2 over one forcing
/// period sampled at 20000 points (sampling error ≈ (2π/20000)²/8 ≈ 1.2e-8). Tolerance 1e-6
/// relative.
#[test]
fn forced_oscillator_steady_amplitude() {
    for (w, a_amp, b_amp) in [(0.8, 1.0, 0.0), (1.5, 0.0, 1.0), (0.3, 0.6, 0.8)] {
        let mut m = model("forced_oscillator");
        m.set_parameter("w", w).unwrap();
        m.set_parameter("A", a_amp).unwrap();
        m.set_parameter("B", b_amp).unwrap();
        let (mass, c, k) = (1.0, 1.0, 1.0);
        let wn = f64::sqrt(k / mass);
        let zeta = c / (2.0 * (k * mass).sqrt());
        let r = w / wn;
        let f0 = f64::hypot(a_amp, b_amp);
        let exact = (f0 / k) / ((1.0 - r * r).powi(2) + (2.0 * zeta * r).powi(2)).sqrt();
        let t0 = 60.0;
        let period = 2.0 * PI / w;
        let times: Vec<f64> = (0..20000)
            .map(|i| t0 + period * f64::from(i) / 20000.0)
            .collect();
        let y0 = m.initial_state();
        let s = solve(m.as_mut(), &y0, t0 + period, times, &tight());
        let xs: Vec<f64> = s.iter().map(|(_, y)| y[0]).collect();
        let amp = (xs.iter().cloned().fold(f64::MIN, f64::max)
            - xs.iter().cloned().fold(f64::MAX, f64::min))
            / 2.0;
        assert!(
            (amp / exact - 1.0).abs() < 1e-6,
            "w={w}: amplitude {amp} vs {exact}"
        );
    }
}

/// Energy of every conservative model is constant: at rtol = atol = 1e-12 over 10 s the
/// drift relative to the energy scale max(T + |V|) stays below 1e-10.
#[test]
fn conservative_models_conserve_energy() {
    let mut checked = 0;
    for entry in models::ALL {
        let mut m = (entry.make)();
        if !m.description().conservative {
            continue;
        }
        checked += 1;
        let y0 = m
            .consistent_initial_state()
            .unwrap_or_else(|e| panic!("{}: {e}", entry.name));
        let times: Vec<f64> = (1..=100).map(|i| 0.1 * f64::from(i)).collect();
        let s = solve(m.as_mut(), &y0, 10.0, times, &tight());
        let drift = energy_drift(m.as_ref(), &y0, &s);
        assert!(
            drift.scale > 0.0,
            "{}: motion has no energy scale",
            entry.name
        );
        let relative = drift.drift.expect("samples");
        assert!(
            relative <= 1e-10,
            "{}: relative energy drift {relative}",
            entry.name,
        );
    }
    assert!(
        checked >= 4,
        "expected the pendulums and the spring chain to be conservative"
    );
}

/// The drift measure itself, on samples of the simple pendulum (m = l = 1, g = 10,
/// `E = q̇²/2 + 10 sin q`) chosen by hand: from `E(0) = 0` the largest deviation is 10 (at
/// `q = π/2`) and the largest `T + |V|` is 10.5 (at `q = −π/2, q̇ = 1`), so the drift is
/// 10/10.5 (to rounding, 1e-15).
#[test]
fn energy_drift_is_the_largest_deviation_over_the_energy_scale() {
    let m = model("simple_pendulum");
    let samples = [[0.0, 2.0], [PI / 2.0, 0.0], [-PI / 2.0, 1.0]];
    let solution = Solution {
        t: vec![1.0, 2.0, 3.0],
        y: samples.concat(),
        dim: 2,
        stats: Default::default(),
        events: Vec::new(),
        terminated_by_event: None,
    };
    let drift = energy_drift(m.as_ref(), &[0.0, 0.0], &solution);
    assert_eq!(drift.initial_energy, 0.0);
    let expected = [2.0, 10.0, -9.5];
    for (e, x) in drift.energy.iter().zip(expected) {
        assert!((e - x).abs() < 1e-14, "E = {e}, expected {x}");
    }
    assert!((drift.scale - 10.5).abs() < 1e-14);
    assert!((drift.drift.unwrap() - 10.0 / 10.5).abs() < 1e-15);
}

/// HW19b: the generated double pendulum equals equations derived by hand for two uniform bars
/// with absolute angles: M11 = m1 l1²/3 + m2 l1², M12 = m2 l1 l2/2 cos(θ1 − θ2),
/// M22 = m2 l2²/3, F1 = −m2 l1 l2/2 sin(θ1 − θ2) θ̇2² − (m1/2 + m2) g l1 cos θ1,
/// F2 = m2 l1 l2/2 sin(θ1 − θ2) θ̇1² − m2 g l2/2 cos θ2. Tolerance 1e-12 relative.
#[test]
fn double_pendulum_matches_hand_derivation() {
    let mut m = model("double_pendulum");
    let (m1, m2, l1, l2, g) = (1.3, 0.7, 1.1, 0.9, 9.81);
    for (n, v) in [("m1", m1), ("m2", m2), ("l1", l1), ("l2", l2), ("g", g)] {
        m.set_parameter(n, v).unwrap();
    }
    let mut rng = seeded_rng(99);
    for _ in 0..100 {
        let y: Vec<f64> = (0..4).map(|_| rng.random_range(-4.0..4.0)).collect();
        let (t1, t2, w1, w2) = (y[0], y[1], y[2], y[3]);
        let c = 0.5 * m2 * l1 * l2;
        let mh = [
            m1 * l1 * l1 / 3.0 + m2 * l1 * l1,
            c * (t1 - t2).cos(),
            m2 * l2 * l2 / 3.0,
        ];
        let fh = [
            -c * (t1 - t2).sin() * w2 * w2 - (0.5 * m1 + m2) * g * l1 * t1.cos(),
            c * (t1 - t2).sin() * w1 * w1 - 0.5 * m2 * g * l2 * t2.cos(),
        ];
        let (mg, fg) = m.mass_matrix_and_forcing(0.0, &y);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0);
        assert!(
            close(mg[(0, 0)], mh[0])
                && close(mg[(0, 1)], mh[1])
                && close(mg[(1, 0)], mh[1])
                && close(mg[(1, 1)], mh[2]),
            "M {mg} vs {mh:?}"
        );
        assert!(
            close(fg[0], fh[0]) && close(fg[1], fh[1]),
            "F {fg} vs {fh:?}"
        );
    }
}

/// HW27a: the generated cart–pendulum equals the hand derivation
/// M = [[m1+m2, m2 l cos θ], [m2 l cos θ, m2 l²]], F = [m2 l sin θ θ̇², −m2 g l sin θ];
/// and the horizontal momentum (m1+m2) ẋ + m2 l cos θ θ̇ is conserved in a simulation
/// (tolerance 1e-10 at rtol 1e-12).
#[test]
fn cart_pendulum_matches_hand_derivation_and_conserves_momentum() {
    let mut m = model("cart_pendulum");
    let (m1, m2, l, g) = (2.0, 0.5, 0.8, 9.81);
    for (n, v) in [("m1", m1), ("m2", m2), ("l", l), ("g", g)] {
        m.set_parameter(n, v).unwrap();
    }
    let mut rng = seeded_rng(5);
    for _ in 0..100 {
        let y: Vec<f64> = (0..4).map(|_| rng.random_range(-4.0..4.0)).collect();
        let (th, w) = (y[1], y[3]);
        let (mg, fg) = m.mass_matrix_and_forcing(0.0, &y);
        let expect_m = [m1 + m2, m2 * l * th.cos(), m2 * l * l];
        let expect_f = [m2 * l * th.sin() * w * w, -m2 * g * l * th.sin()];
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0);
        assert!(
            close(mg[(0, 0)], expect_m[0])
                && close(mg[(0, 1)], expect_m[1])
                && close(mg[(1, 1)], expect_m[2])
        );
        assert!(close(fg[0], expect_f[0]) && close(fg[1], expect_f[1]));
    }
    let y0 = vec![0.0, 1.0, 0.3, -0.5];
    let momentum = |y: &[f64]| (m1 + m2) * y[2] + m2 * l * y[1].cos() * y[3];
    let p0 = momentum(&y0);
    let s = solve(
        m.as_mut(),
        &y0,
        10.0,
        (1..=10).map(f64::from).collect(),
        &tight(),
    );
    for (t, y) in s.iter() {
        assert!(
            (momentum(y) - p0).abs() < 1e-10,
            "t={t}: momentum {} vs {p0}",
            momentum(y)
        );
    }
}

/// Convergence orders on the generated double pendulum (a nonlinear problem with a variable
/// mass matrix): error at t = 1 against a DP54 reference at 1e-13, for fixed steps halved
/// twice; log2 of successive error ratios must be within 0.3 of 4 (RK4) and 5 (DP54 without
/// error control). The falling forearm makes the motion violent: RK4 reaches its asymptotic
/// range only below h ≈ 1/500 (observed orders 4.2, 3.2, 3.7, 3.9 from h = 1/80), so each
/// method gets steps inside its asymptotic range, with errors far above the reference error.
#[test]
fn convergence_orders_on_the_double_pendulum() {
    let mut m = model("double_pendulum");
    let y0 = m.initial_state();
    let reference = solve(
        m.as_mut(),
        &y0,
        1.0,
        vec![1.0],
        &IntegratorOptions::default()
            .with_rtol(1e-13)
            .with_atol(1e-13),
    );
    let exact = reference.state(0).to_vec();
    let methods: Vec<(Box<dyn Integrator>, f64, [f64; 3])> = vec![
        (Box::new(RungeKutta4::new()), 4.0, [640.0, 1280.0, 2560.0]),
        (Box::new(DormandPrince54::new()), 5.0, [80.0, 160.0, 320.0]),
    ];
    for (mut integrator, order, steps) in methods {
        let errors: Vec<f64> = steps
            .iter()
            .map(|steps| {
                let options = IntegratorOptions::default()
                    .with_dt(1.0 / steps)
                    .with_fixed_step(true);
                let s = integrator
                    .integrate(m.as_ode_mut(), 0.0, &y0, 1.0, &OutputTimes::Steps, &options)
                    .unwrap();
                assert_eq!(s.t[s.len() - 1], 1.0);
                s.state(s.len() - 1)
                    .iter()
                    .zip(&exact)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
            })
            .collect();
        eprintln!("{}: {errors:?}", integrator.name());
        for w in errors.windows(2) {
            let observed = (w[0] / w[1]).log2();
            assert!(
                (observed - order).abs() < 0.3,
                "{}: observed order {observed}, errors {errors:?}",
                integrator.name()
            );
        }
        assert!(
            errors[2] > 1e-10,
            "{}: errors {errors:?} too close to the reference error",
            integrator.name()
        );
    }
}

/// HW19a: the double pendulum from θ1 = 0, θ2 = π/2 at rest, against an independent reference:
/// SciPy's DOP853 at rtol = atol = 1e-13 on equations derived by hand
/// (`tools/double_pendulum_reference.py`). The motion is chaotic, so differences of order the
/// tolerances grow by about 10 per second: tolerances 1e-10 at t = 1 and 2 s and 1e-8 at 5 s
/// (measured agreement: 8e-13, 5e-11, 7e-10).
#[test]
fn double_pendulum_matches_independent_reference() {
    let reference: [(f64, [f64; 4]); 3] = [
        (
            1.0,
            [
                -2.4346347465484177,
                -3.5256578683766038,
                -4.65303793204223,
                2.225577024679411,
            ],
        ),
        (
            2.0,
            [
                -0.9624245797025264,
                -1.5743151433361477,
                7.256250864964657,
                -10.528015768045275,
            ],
        ),
        (
            5.0,
            [
                -0.5682551931790055,
                -10.795630666362937,
                -2.2414721815321084,
                -8.200781422704171,
            ],
        ),
    ];
    let mut m = model("double_pendulum");
    let y0 = m.initial_state();
    let s = solve(
        m.as_mut(),
        &y0,
        5.0,
        reference.iter().map(|r| r.0).collect(),
        &tight(),
    );
    for (i, (t, y)) in reference.iter().enumerate() {
        let tol = if *t < 3.0 { 1e-10 } else { 1e-8 };
        let err = s
            .state(i)
            .iter()
            .zip(y)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < tol, "t = {t}: max difference {err}");
    }
}

/// Period of small oscillations of a 1-DOF model about the equilibrium `q_eq`, released from
/// rest at `q_eq + amplitude`: twice the time between the first two crossings of `q_eq`.
fn small_oscillation_period(name: &str, q_eq: f64, amplitude: f64, omega_guess: f64) -> f64 {
    let mut m = model(name);
    let y0 = vec![q_eq + amplitude, 0.0];
    let period = 2.0 * PI / omega_guess;
    let offset = |y: &[f64]| y[0] - q_eq;
    let t1 = crossing(m.as_mut(), &y0, 0.1 * period, 0.5 * period, &offset);
    let t3 = crossing(m.as_mut(), &y0, 0.6 * period, 0.9 * period, &offset);
    2.0 * (t3 - t1)
}

/// Lecture 14: compound pendulum, ω² = m g d/(I + m d²) = 15 for a unit bar hinged at its end.
/// Amplitude 1e-3: the nonlinear correction is θ0²/16 ≈ 6e-8; tolerance 1e-6 relative.
/// HW22: bead on y = c x², ω = √(2 g c); the correction is O(c² x0²) = 1e-8 at x0 = 1e-4.
/// HW26: rolling cylinder, ω² = 2 g/(3 (R − r)); amplitude 1e-3.
#[test]
fn small_oscillation_frequencies() {
    let cases = [
        (
            "compound_pendulum",
            0.0,
            1e-3,
            f64::sqrt(10.0 * 0.5 / (1.0 / 12.0 + 0.25)),
        ),
        ("bead_parabola", 0.0, 1e-4, (2.0f64 * 10.0 * 1.0).sqrt()),
        (
            "rolling_in_cylinder",
            0.0,
            1e-3,
            (2.0 * 10.0 / (3.0 * (1.0 - 0.2f64))).sqrt(),
        ),
    ];
    for (name, q_eq, amplitude, omega) in cases {
        let measured = small_oscillation_period(name, q_eq, amplitude, omega);
        let expected = 2.0 * PI / omega;
        assert!(
            (measured / expected - 1.0).abs() < 1e-6,
            "{name}: period {measured} vs {expected}"
        );
    }
}

/// HW20: on the free turntable the angular momentum about O,
/// H = I_t θ̇ + m_s (x ẏ − y ẋ) of the slider, is conserved (no external moment about the
/// hinge). Tolerance 1e-10 at rtol 1e-12 over 10 s.
#[test]
fn turntable_conserves_angular_momentum() {
    let mut m = model("turntable_slot");
    let names = m.description().parameter_names();
    let p = m.parameter_values();
    let get = |n: &str| p[names.iter().position(|x| *x == n).unwrap()];
    let (it, ms, d) = (get("I_t"), get("m_s"), get("d"));
    let h = |y: &[f64]| {
        let (th, s, w, sd) = (y[0], y[1], y[2], y[3]);
        let (x, yy) = (d * th.sin() + s * th.cos(), -d * th.cos() + s * th.sin());
        // Velocity of the slider by the chain rule.
        let xd = d * th.cos() * w - s * th.sin() * w + sd * th.cos();
        let yd = d * th.sin() * w + s * th.cos() * w + sd * th.sin();
        it * w + ms * (x * yd - yy * xd)
    };
    let y0 = m.initial_state();
    let h0 = h(&y0);
    let s = solve(
        m.as_mut(),
        &y0,
        10.0,
        (1..=10).map(f64::from).collect(),
        &tight(),
    );
    for (t, y) in s.iter() {
        assert!((h(y) - h0).abs() < 1e-10, "t={t}: H {} vs {h0}", h(y));
    }
}

/// A spring of rest length 0 pulls with `−k·d`, smooth where its ends meet: a mass on such a
/// spring to a fixed point, at that point and away from it, has `q̈ = −(k/m) q` (to 1e-15
/// relative: one division and one product), its equations finite at rest, and the same bits
/// whether the file writes `rest_length: 0`, a rest length that is 0 as written (`0*k`), or
/// none. (A rest length that is a parameter of value 0 still gives `0/0` where the ends meet:
/// the force `−k(1 − ℓ₀/|d|) d` is compiled for any `ℓ₀`.)
#[test]
fn a_zero_rest_length_spring_is_smooth_where_its_ends_meet() {
    use eomgen::{DynFirstOrder, JitModel, OdeSystem};
    let (m, k) = (2.0, 5.0);
    let states = [
        [0.0, 0.0, 0.0, 0.0],
        [0.3, -0.2, 0.1, 0.4],
        [1e-9, 0.0, 0.0, 0.0],
    ];
    let mut by_rest: Vec<Vec<u64>> = Vec::new();
    for rest in ["", ", rest_length: 0", ", rest_length: 0*k"] {
        let text = format!(
            "name: zero_rest_length\nparameters: {{ m: {m}, k: {k} }}\ncoordinates: [x, y]\n\
             points:\n  O: [0, 0]\n  P: [x, y]\nbodies:\n  mass: {{ mass: m, at: P }}\n\
             springs:\n  s: {{ between: [P, O], stiffness: k{rest} }}\n"
        );
        let model =
            JitModel::from_source("zero.yaml", &text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        let mut system = DynFirstOrder::new(model);
        let mut bits = Vec::new();
        for y in states {
            let mut dy = [f64::NAN; 4];
            system
                .rhs(0.0, &y, &mut dy)
                .unwrap_or_else(|e| panic!("{rest:?} at {y:?}: {e}"));
            for i in 0..2 {
                let expected = -k / m * y[i];
                assert!(
                    (dy[2 + i] - expected).abs() <= 1e-15 * expected.abs(),
                    "{rest:?} at {y:?}: q̈{i} = {} against {expected}",
                    dy[2 + i]
                );
            }
            bits.extend(dy.map(f64::to_bits));
        }
        by_rest.push(bits);
    }
    assert_eq!(by_rest[1], by_rest[0], "`rest_length: 0` differs from none");
    assert_eq!(
        by_rest[2], by_rest[0],
        "`rest_length: 0*k` differs from none"
    );
}

/// The sign conventions the Whipple bicycle's file states in its comments: axes with `x` ahead
/// at zero yaw, `y` to the left and `z` up; a positive lean tilts the frame to the right (the
/// rear hub, at height `rR`, moves to `y = −rR sin(lean)`, to 1e-12 m: one sine and one
/// product), and a positive steer turns the front wheel to the left (its hub, ahead of the
/// steer axis by the fork offset, moves to `+y`).
#[test]
fn the_whipple_bicycles_stated_sign_conventions_hold() {
    let model = model("whipple_bicycle");
    let description = model.description();
    let names: Vec<&str> = description.points.iter().map(|p| &**p).collect();
    let index = |name: &str| {
        names
            .iter()
            .position(|p| *p == name)
            .unwrap_or_else(|| panic!("point {name} in {names:?}"))
    };
    let coordinate = |name: &str| {
        description
            .coordinates
            .iter()
            .position(|c| &**c == name)
            .unwrap_or_else(|| panic!("coordinate {name}"))
    };
    let rr = model.parameter_values()[description
        .parameter_index("rR")
        .expect("the rear wheel's radius")];
    let n = description.coordinates.len();
    let at = |name: &str, value: f64| {
        let mut y = vec![0.0; 2 * n];
        y[coordinate(name)] = value;
        model.point_positions(0.0, &y)
    };
    let upright = at("lean", 0.0);
    let leaning = at("lean", 0.1);
    let hub = index("RH");
    assert!(
        upright[hub][1].abs() < 1e-15,
        "the rear hub upright: {:?}",
        upright[hub]
    );
    let expected = -rr * 0.1f64.sin();
    assert!(
        (leaning[hub][1] - expected).abs() < 1e-12,
        "lean = 0.1 puts the rear hub at y = {}, not {expected} (to the right)",
        leaning[hub][1]
    );
    let steered = at("steer", 0.1);
    let front = index("FH");
    assert!(
        steered[front][1] > upright[front][1] + 1e-3,
        "steer = 0.1 moves the front hub from y = {} to {}, not to the left",
        upright[front][1],
        steered[front][1]
    );
}
