//! The numerical studies of `analysis/` that run on a model (`simulate`, the drift measures,
//! `work_precision`, `constraint_methods`; `stability_study` is in `stability.rs`), on the
//! small hand-written models of `common/models.rs`, each against a closed form or an
//! independent computation.
//! Every bound is stated next to its assertion with its reason.

use crate::common;

use common::models::{CartesianPendulum, Pendulum, TwoMassChain, boxed};
use eomgen_runtime::analysis::{
    ConstraintMethodsOptions, Method, SimulationOptions, SimulationWarning, WorkPrecisionOptions,
    constraint_methods, energy_drift_at, fixed_step_warnings, simulate, work_precision,
};
use eomgen_runtime::{OutputTimes, Stabilization};
use nalgebra::SMatrix;

/// `count` equally spaced times on `(0, t_end]`.
fn grid(t_end: f64, count: usize) -> Vec<f64> {
    (1..=count)
        .map(|k| t_end * k as f64 / count as f64)
        .collect()
}

/// The undamped chain released at rest from `Q0`.
const Q0: [f64; 2] = [0.1, -0.05];

fn released_chain() -> TwoMassChain {
    TwoMassChain {
        initial: (Q0, [0.0; 2]),
        ..TwoMassChain::default()
    }
}

/// `simulate` of the undamped chain with DOP853 at 1e-12: every sample against the
/// closed-form modal superposition (1e-9 of the amplitude: the tolerance times the growth
/// of the global error over ~10 periods of the fast mode and 3 of the slow one, with room), the energy `½ q0ᵀK q0` at the start
/// (1e-15 relative: one quadratic form) and its drift below 1e-10.
#[test]
fn simulation_of_the_chain_follows_the_closed_form() {
    let chain = released_chain();
    let mut model = boxed(chain.clone());
    let options = SimulationOptions {
        method: Method::Dop853,
        t_end: 20.0,
        rtol: 1e-12,
        atol: 1e-12,
        output: OutputTimes::At(grid(20.0, 100)),
        ..SimulationOptions::default()
    };
    let run = simulate(model.as_mut(), &options).unwrap();
    assert!(run.failure.is_none());
    assert_eq!(run.solution.len(), 100);
    let mut worst = 0.0f64;
    for (t, y) in run.solution.iter() {
        let exact = chain.undamped_response(Q0, t);
        for i in 0..4 {
            worst = worst.max((y[i] - exact[i]).abs());
        }
    }
    assert!(worst < 1e-9 * 0.1, "largest error {worst:e}");
    let q0 = nalgebra::Vector2::from(Q0);
    let energy = 0.5 * q0.dot(&(chain.k() * q0));
    assert!((run.energy.initial_energy - energy).abs() < 1e-15 * energy);
    let drift = run.energy.drift.unwrap();
    assert!(drift < 1e-10, "energy drift {drift:e}");
}

/// The rod's tension of the Cartesian pendulum along a swing from `θ0` at rest:
/// `λ = m g (3 cos θ − 2 cos θ0)` at every sample (1e-7 of `m g`: DP54 at rtol 1e-10 with
/// the multipliers solved from the state); its bob follows the minimal-coordinate pendulum
/// (an independent integration, to 1e-7 m), and projection holds the rod to 1e-12 where the
/// unstabilised DAE drifts above it.
#[test]
fn constrained_simulation_tension_twin_and_projection() {
    let cartesian = CartesianPendulum::default();
    let (m, g, l, theta0) = (cartesian.m, cartesian.g, cartesian.l, cartesian.theta0);
    let times = grid(3.0, 60);
    let options = SimulationOptions {
        t_end: 3.0,
        rtol: 1e-10,
        atol: 1e-12,
        output: OutputTimes::At(times),
        ..SimulationOptions::default()
    };
    let mut model = boxed(cartesian);
    let run = simulate(model.as_mut(), &options).unwrap();
    let forces = &run.constraints.lagrange_multipliers;
    assert_eq!(forces.len(), run.solution.len());
    for ((_, y), lambda) in run.solution.iter().zip(forces) {
        let cos_theta = -y[1] / l;
        let tension = m * g * (3.0 * cos_theta - 2.0 * theta0.cos());
        let lambda = lambda.as_ref().expect("the tension at every sample")[0];
        assert!(
            (lambda - tension).abs() < 1e-7 * m * g,
            "λ = {lambda} vs {tension}"
        );
    }

    let mut twin = boxed(Pendulum::default());
    let minimal = simulate(twin.as_mut(), &options).unwrap();
    for ((t, y), (_, theta)) in run.solution.iter().zip(minimal.solution.iter()) {
        let bob = [l * theta[0].sin(), -l * theta[0].cos()];
        let distance = ((y[0] - bob[0]).powi(2) + (y[1] - bob[1]).powi(2)).sqrt();
        assert!(distance < 1e-7, "t = {t}: {distance:e} m apart");
    }

    let drift = |stabilization| {
        let mut model = boxed(CartesianPendulum::default());
        let options = SimulationOptions {
            stabilization,
            rtol: 1e-6,
            atol: 1e-8,
            ..options.clone()
        };
        let run = simulate(model.as_mut(), &options).unwrap();
        run.constraints
            .drift
            .iter()
            .map(|d| d.0)
            .fold(0.0f64, f64::max)
    };
    let (free, projected) = (drift(Stabilization::None), drift(Stabilization::Projection));
    eprintln!("rod drift: {free:.1e} unstabilised, {projected:.1e} projected");
    assert!(projected < 1e-12 && free > 1e-12, "{free:e}, {projected:e}");
}

/// `energy_drift_at` on samples of a known motion: the chain's closed-form response keeps
/// its energy (drift at rounding, 1e-15), and with every velocity scaled by `s = 1.001` the
/// drift is `max_k (s² − 1) T_k / max(T + |V|)` (1e-12: a few roundings of each energy).
#[test]
fn energy_drift_of_known_samples() {
    let chain = released_chain();
    let model = boxed(chain.clone());
    let y0 = chain.undamped_response(Q0, 0.0);
    let samples: Vec<(f64, Vec<f64>)> = grid(5.0, 50)
        .into_iter()
        .map(|t| (t, chain.undamped_response(Q0, t).as_slice().to_vec()))
        .collect();
    let exact = energy_drift_at(
        model.as_ref(),
        y0.as_slice(),
        samples.iter().map(|(t, y)| (*t, y.as_slice())),
    );
    assert!(exact.drift.unwrap() < 1e-15, "{:e}", exact.drift.unwrap());

    let s = 1.001;
    let faster: Vec<(f64, Vec<f64>)> = samples
        .iter()
        .map(|(t, y)| (*t, vec![y[0], y[1], s * y[2], s * y[3]]))
        .collect();
    let drifted = energy_drift_at(
        model.as_ref(),
        y0.as_slice(),
        faster.iter().map(|(t, y)| (*t, y.as_slice())),
    );
    let kinetic: Vec<f64> = samples
        .iter()
        .map(|(t, y)| model.kinetic_energy(*t, y))
        .collect();
    let scale = samples
        .iter()
        .zip(&kinetic)
        .map(|((t, y), k)| s * s * k + model.potential_energy(*t, y).abs())
        .fold(model.energy(0.0, y0.as_slice()), f64::max);
    let expected = kinetic
        .iter()
        .map(|k| (s * s - 1.0) * k)
        .fold(0.0f64, f64::max)
        / scale;
    let drift = drifted.drift.unwrap();
    assert!((drift - expected).abs() < 1e-12, "{drift} vs {expected}");
}

/// `work_precision` with RK4 on the chain: the reported error of each step count `N` is
/// the closed form `max_k |R(hA)^{n_k} y0 − y(t_k)|`, `R(z) = 1 + z + z²/2 + z³/6 + z⁴/24`
/// the method's stability function on `ẏ = A y` (Hairer, Nørsett, Wanner I, §II.1 and
/// §IV.2), `y(t)` the modal superposition. 1e-5 relative: the DOP853 reference at 1e-14
/// is good to ~1e-12 over the run, 1e-5 of the smallest RK4 error (1e-7), and the powers of
/// `R` are exact to rounding. An RK4 of order 3 (or a wrong `h`) misses by far more.
#[test]
fn work_precision_of_rk4_is_its_stability_function() {
    let chain = released_chain();
    let mut model = boxed(chain.clone());
    let (t_end, samples) = (5.0, 10);
    let steps = vec![100, 200, 400];
    let options = WorkPrecisionOptions {
        methods: vec![Method::Rk4],
        steps: Some(steps.clone()),
        t_end,
        samples,
        repeats: 1,
        min_time_s: 0.0,
        ..WorkPrecisionOptions::default()
    };
    let study = work_precision(model.as_mut(), &options, &mut |_, _| {}).unwrap();
    let a = chain.state_matrix();
    let y0 = chain.undamped_response(Q0, 0.0);
    for (run, n) in study.results[0].runs.iter().zip(steps) {
        let z = a * (t_end / n as f64);
        let z2 = z * z;
        let r = SMatrix::<f64, 4, 4>::identity() + z + z2 / 2.0 + z2 * z / 6.0 + z2 * z2 / 24.0;
        let mut y = y0;
        let mut expected = 0.0f64;
        for k in 1..=samples {
            for _ in 0..n / samples {
                y = r * y;
            }
            let exact = chain.undamped_response(Q0, t_end * k as f64 / samples as f64);
            expected = expected.max((y - exact).amax());
        }
        let error = run.outcome.as_ref().unwrap().error;
        eprintln!("rk4, N = {n}: error {error:.6e}, closed form {expected:.6e}");
        assert!(
            (error - expected).abs() < 1e-5 * expected,
            "N = {n}: {error:e} vs {expected:e}"
        );
    }
}

/// `fixed_step_warnings` on the undamped chain: RK4 is stable on `ẍ = −ω²x` for
/// `hω ≤ 2√2` (Hairer, Wanner II, §IV.2), so a step 5 % past `2√2/ω₂` (the fast mode) is
/// warned about, naming the eigenvalue `±iω₂` (1e-6: central differences of a linear
/// right-hand side) and the amplification `|R(ihω₂)|`, `|R(iy)|² = 1 − y⁶/72 + y⁸/576`
/// (1e-6); a step 5 % inside the limit is not.
#[test]
fn fixed_step_warnings_at_the_rk4_limit() {
    let chain = released_chain();
    let mut model = boxed(chain.clone());
    let y0 = model.initial_state();
    let (w2, _) = chain.modes();
    let fast = w2[1].sqrt();
    let limit = 2.0 * 2f64.sqrt() / fast;
    let inside = fixed_step_warnings(model.as_mut(), Method::Rk4, &y0, Some(0.95 * limit), 50.0);
    assert!(inside.is_empty(), "{inside:?}");
    let past = fixed_step_warnings(model.as_mut(), Method::Rk4, &y0, Some(1.05 * limit), 50.0);
    assert_eq!(past.len(), 1, "{past:?}");
    let SimulationWarning::StepPastStabilityLimit {
        eigenvalue,
        amplification,
        ..
    } = past[0]
    else {
        panic!("{:?}", past[0]);
    };
    assert!(
        eigenvalue[0].abs() < 1e-6 * fast && (eigenvalue[1].abs() - fast).abs() < 1e-6 * fast,
        "{eigenvalue:?}"
    );
    let y = 1.05 * limit * fast;
    let expected = (1.0 - y.powi(6) / 72.0 + y.powi(8) / 576.0).sqrt();
    assert!(
        (amplification - expected).abs() < 1e-6 * expected,
        "{amplification} vs {expected}"
    );
}

/// `constraint_methods` on the Cartesian pendulum with its minimal twin: the DAE rows and
/// the minimal coordinates follow the reference to 1e-6 m (DP54 at 1e-8 over 1 s), and a
/// stiff spring lets the rod stretch by its tension over `k`: the spring's error lies
/// between the largest static stretch `m g (3 − 2 cos θ0)/k` and three times it (the rod
/// also oscillates about its stretch and lags in phase), and falls tenfold from `k = 1e3`
/// to `1e4` (between 5 and 20 times: the stretch, not the integration, sets it).
#[test]
fn constraint_methods_of_the_cartesian_pendulum() {
    let cartesian = CartesianPendulum::default();
    let tension = cartesian.m * cartesian.g * (3.0 - 2.0 * cartesian.theta0.cos());
    let twin = boxed(Pendulum::default());
    let options = ConstraintMethodsOptions {
        t_end: 1.0,
        stiffness: vec![1e3, 1e4],
        ..ConstraintMethodsOptions::default()
    };
    let study = constraint_methods(
        &mut || boxed(CartesianPendulum::default()),
        Some(("pendulum", twin)),
        &options,
    )
    .unwrap();
    assert!(
        study.agreement < 1e-9,
        "reference agreement {:e}",
        study.agreement
    );
    assert_eq!(study.rows.len(), 5);
    for row in &study.rows {
        eprintln!("{}: {:.2e} m", row.method, row.position_error);
        assert!(row.failure.is_none(), "{}: {:?}", row.method, row.failure);
    }
    for row in &study.rows[2..] {
        assert!(
            row.position_error < 1e-6,
            "{}: {:e}",
            row.method,
            row.position_error
        );
    }
    for (row, k) in study.rows.iter().zip(&options.stiffness) {
        let stretch = tension / k;
        assert!(
            row.position_error > stretch && row.position_error < 3.0 * stretch,
            "{}: {:e} against a stretch of {stretch:e}",
            row.method,
            row.position_error
        );
    }
    let ratio = study.rows[0].position_error / study.rows[1].position_error;
    assert!(
        (5.0..20.0).contains(&ratio),
        "spring errors fall by {ratio}"
    );
}
