//! `study rolling-contact` (HW36): the friction the eccentric cylinder needs up to its
//! lift-off, against the model's own `slip` event and Newton–Euler; the release from the
//! ground at the lift-off against its closed form; and the free flight after it against the
//! parabola, the constant spin and the energy.

use crate::common;
use common::{eomgen, eomgen_ok};

use eomgen::ModelInfo;
use eomgen::analysis::rolling_contact::{
    RollingContact, RollingContactError, RollingContactOptions, rolling_contact,
};
use eomgen::analysis::{SimulationOptions, simulate};

fn model(name: &str) -> Box<dyn ModelInfo> {
    (eomgen::models::find(name).expect("bundled model").make)()
}

/// Both models with the same parameters set.
fn models(sets: &[(&str, f64)]) -> (Box<dyn ModelInfo>, Box<dyn ModelInfo>) {
    let (mut rolling, mut flight) = (
        model("eccentric_cylinder"),
        model("eccentric_cylinder_flight"),
    );
    for (name, value) in sets {
        rolling.set_parameter(name, *value).unwrap();
        flight.set_parameter(name, *value).unwrap();
    }
    (rolling, flight)
}

fn study(sets: &[(&str, f64)], thresholds: Vec<f64>) -> RollingContact {
    let (mut rolling, mut flight) = models(sets);
    let options = RollingContactOptions {
        thresholds,
        ..RollingContactOptions::default()
    };
    rolling_contact(rolling.as_mut(), Some(flight.as_mut()), &options).expect("the study runs")
}

fn parameter(model: &dyn ModelInfo, name: &str) -> f64 {
    let index = model
        .description()
        .parameters
        .iter()
        .position(|p| p.name == name)
        .unwrap();
    model.parameter_values()[index]
}

/// A flight exists for a ring-like cylinder on a steep ramp (e = 0.2 m, I_G = 0.6 kg m²
/// ≤ M (R² − e²), γ = 0.9 rad): released at the lift-off, its lowest point accelerates away
/// from the ramp.
const FLYING: [(&str, f64); 3] = [("e", 0.2), ("IG", 0.6), ("gamma", 0.9)];

/// The lift-off and the friction thresholds agree with independent event functions: the
/// model's own run to `lift_off`, and its `slip` event (`λ_no_slip² − (μ λ_contact)²`,
/// written in the file with the multipliers' signs, where the study resolves `−Jᵀλ`). Both
/// are zeros located by Brent's method on DOP853's dense output at 1e-12: 1e-9 s leaves a
/// margin over their accuracy (~1e-12 s), while a wrong force would move them by ms.
#[test]
fn lift_off_and_slip_times_match_the_models_events() {
    let study = study(&[], vec![0.5]);
    let mut m = model("eccentric_cylinder");
    let options = SimulationOptions {
        method: eomgen::analysis::Method::Dop853,
        rtol: 1e-12,
        atol: 1e-12,
        ..SimulationOptions::default()
    };
    let run = simulate(m.as_mut(), &options).unwrap();
    let lift_off = run
        .solution
        .events
        .iter()
        .find(|e| e.name == "lift_off")
        .unwrap();
    let slip = run
        .solution
        .events
        .iter()
        .find(|e| e.name == "slip")
        .unwrap();
    assert!((study.rolling.lift_off_time - lift_off.t).abs() < 1e-9);
    let mu_half = study.rolling.exceedances[0];
    assert_eq!(mu_half.mu, 0.5);
    assert!(
        (mu_half.t.unwrap() - slip.t).abs() < 1e-9,
        "{:?} vs slip at {}",
        mu_half,
        slip.t
    );
    // The forces resolved as −Jᵀλ are the file's documented multipliers: N = λ_contact,
    // F_t = −λ_no_slip (at every tenth sample).
    for s in study.rolling.samples.iter().step_by(10) {
        let y: Vec<f64> = s.q.iter().chain(&s.qdot).copied().collect();
        let lambda = m.constraint_forces(s.t, &y).unwrap();
        assert!((s.normal_force - lambda[0]).abs() <= 1e-12 * lambda[0].abs().max(1.0));
        assert!((s.friction_force + lambda[1]).abs() <= 1e-12 * lambda[1].abs().max(1.0));
    }
}

/// Newton–Euler, `(F_t, N) = m a_G − m g` from the trajectory alone, agrees with the
/// multipliers; the mass and gravity it used are the file's (M = 1 kg, g (sin γ, −cos γ)).
#[test]
fn newton_euler_agrees_with_the_multipliers() {
    let study = study(&[], vec![]);
    let ne = &study.rolling.newton_euler;
    assert!(ne.passed, "{ne:?}");
    // 1e-6 of max N: measured 9e-9, the rounding of the dense output differenced in time.
    assert!(ne.relative < 1e-6, "{ne:?}");
    let (g, gamma) = (10.0_f64, 0.3_f64);
    assert!((ne.mass - 1.0).abs() < 1e-12);
    assert!((ne.gravity[0] - g * gamma.sin()).abs() < 1e-9);
    assert!((ne.gravity[1] + g * gamma.cos()).abs() < 1e-9);
    let interior = study
        .rolling
        .samples
        .iter()
        .filter(|s| s.normal_force_newton_euler.is_some())
        .count();
    assert_eq!(interior, study.rolling.samples.len() - 2);
}

/// μ(t) → ∞ at the lift-off, as |F_t|/(|Ṅ| (t_lift − t)); its peaks before the final rise
/// are local maxima of the samples, and the largest is below the μ the file's `slip` event
/// is reached at (0.5, reached only in the final rise).
#[test]
fn mu_diverges_at_the_lift_off() {
    let study = study(&[], vec![0.5]);
    let r = &study.rolling;
    assert!(r.mu_diverges);
    assert!(r.normal_force_at_lift_off.abs() < 1e-10);
    assert!(r.friction_force_at_lift_off.abs() > 0.5);
    // μ (t_lift − t) → |F_t/Ṅ|, linearly in t_lift − t: extrapolated (Richardson) from the
    // last two samples before the lift-off, against Ṅ from a one-sided difference; both are
    // second order in Δt = 1.1 ms (measured 1.3e-4 apart), so 1e-3, where a wrong power of
    // (t_lift − t) or a wrong force would be off by O(1).
    let count = r.samples.len();
    let product = |s: &eomgen::analysis::rolling_contact::ContactSample| {
        s.mu.unwrap() * (r.lift_off_time - s.t)
    };
    let limit = 2.0 * product(&r.samples[count - 2]) - product(&r.samples[count - 3]);
    let asymptote = (r.friction_force_at_lift_off / r.normal_force_rate_at_lift_off).abs();
    assert!(
        (limit - asymptote).abs() < 1e-3 * asymptote,
        "{limit} vs {asymptote}"
    );
    let max = r.max_peak.unwrap();
    assert!(max.mu < 0.5 && max.t < r.final_rise_from.unwrap());
    let sampled_max = r
        .samples
        .iter()
        .filter(|s| s.t < r.final_rise_from.unwrap())
        .filter_map(|s| s.mu)
        .fold(0.0_f64, f64::max);
    // The refined peak is at least the sampled maximum and above it by a parabola's
    // correction only (samples 1.1 ms apart).
    assert!(
        max.mu >= sampled_max && max.mu - sampled_max < 1e-5,
        "{max:?} {sampled_max}"
    );
    assert!(r.exceedances[0].t.unwrap() > r.final_rise_from.unwrap());
}

/// With the file's parameters the cylinder does not fly: released at the lift-off, its
/// lowest point accelerates into the ramp, by the closed form: removing the friction force
/// F_t (the torque (R + e sin θ) F_t about G) changes ÿ_C from 0 to
/// e cos θ (R + e sin θ) F_t / I_G.
#[test]
fn the_release_acceleration_has_its_closed_form() {
    for sets in [&[][..], &FLYING[..]] {
        let study = study(sets, vec![]);
        let (rolling, _) = models(sets);
        let (e, r, ig) = (
            parameter(rolling.as_ref(), "e"),
            parameter(rolling.as_ref(), "R"),
            parameter(rolling.as_ref(), "IG"),
        );
        let theta = study.rolling.lift_off_state[2];
        let expected =
            e * theta.cos() * (r + e * theta.sin()) * study.rolling.friction_force_at_lift_off / ig;
        let flight = study.flight.as_ref().unwrap();
        assert!(
            (flight.release_normal_acceleration - expected).abs() < 1e-9 * expected.abs(),
            "{sets:?}: {} vs {expected}",
            flight.release_normal_acceleration
        );
        assert_eq!(flight.flies, expected > 0.0, "{sets:?}");
    }
    let study = study(&[], vec![]);
    let flight = study.flight.unwrap();
    assert!(flight.release_normal_acceleration < -1.0);
    assert!(flight.samples.is_empty() && flight.landing_time.is_none());
    assert!(flight.checks.iter().all(|c| c.passed));
}

/// The flight: off the ground between the lift-off and the landing, G on the closed-form
/// parabola, θ̇ constant, T + V continuous across the join and conserved; it stops where
/// the circle touches the ramp (y = R), coming down.
#[test]
fn the_flight_is_a_parabola_and_lands() {
    let study = study(&FLYING, vec![]);
    assert!(
        study.failed_checks().is_empty(),
        "{:?}",
        study.failed_checks()
    );
    let r = &study.rolling;
    let f = study.flight.as_ref().unwrap();
    assert!(f.flies);
    let landing = f.landing_state.as_ref().unwrap();
    let radius = 1.0;
    assert!(
        (landing[1] - radius).abs() < 1e-9,
        "y at landing {}",
        landing[1]
    );
    assert!(f.landing_normal_velocity.unwrap() < -0.1);
    assert!((f.landing_time.unwrap() - r.lift_off_time - f.flight_time.unwrap()).abs() < 1e-12);
    assert!(f.flight_time.unwrap() > 0.1 && f.max_height > 0.01);
    // In the air in between (the first and last samples are on the ramp).
    for s in &f.samples[1..f.samples.len() - 1] {
        assert!(s.q[1] > radius, "t = {}: y = {}", s.t, s.q[1]);
    }
    // The joined trajectory is continuous: the flight starts at the lift-off state.
    let first = &f.samples[0];
    assert_eq!(first.t, r.lift_off_time);
    let start: Vec<f64> = first.q.iter().chain(&first.qdot).copied().collect();
    assert_eq!(start, r.lift_off_state);
    // Closed forms, recomputed here from the parameters (g = 10, γ = 0.9, e = 0.2).
    let (g, gamma, e) = (10.0_f64, 0.9_f64, 0.2_f64);
    let gravity = [g * gamma.sin(), -g * gamma.cos()];
    let (x, y, th) = (start[0], start[1], start[2]);
    let (vx, vy, w) = (start[3], start[4], start[5]);
    let g0 = [x + e * th.cos(), y + e * th.sin()];
    let v0 = [vx - e * th.sin() * w, vy + e * th.cos() * w];
    for s in &f.samples {
        let tau = s.t - r.lift_off_time;
        for k in 0..2 {
            let closed = g0[k] + v0[k] * tau + gravity[k] * tau * tau / 2.0;
            // DOP853 at 1e-12 over half a second: positions to ~1e-11 m.
            assert!((s.centre_of_mass[k] - closed).abs() < 1e-9, "t = {}", s.t);
        }
        assert!((s.qdot[2] - w).abs() < 1e-10, "spin at t = {}", s.t);
        assert!((s.energy - r.samples[0].energy).abs() < 1e-9 * r.samples[0].energy.abs().max(1.0));
    }
}

/// The typed errors: a name the model lacks, a flight model with other coordinates, a
/// rolling model without constraints, options out of range.
#[test]
fn errors_are_typed() {
    let (mut rolling, _) = models(&[]);
    let bad = RollingContactOptions {
        normal: "z".to_string(),
        ..Default::default()
    };
    assert!(matches!(
        rolling_contact(rolling.as_mut(), None, &bad),
        Err(RollingContactError::UnknownCoordinate { role: "normal", .. })
    ));
    let mut pendulum = model("simple_pendulum");
    assert!(matches!(
        rolling_contact(
            rolling.as_mut(),
            Some(pendulum.as_mut()),
            &Default::default()
        ),
        Err(RollingContactError::CoordinatesDiffer { .. })
    ));
    let mut flight = model("eccentric_cylinder_flight");
    let options = RollingContactOptions {
        lift_off: "landing".to_string(),
        ..Default::default()
    };
    assert!(matches!(
        rolling_contact(flight.as_mut(), None, &options),
        Err(RollingContactError::NoConstraints { .. })
    ));
    let options = RollingContactOptions {
        t_end: 1.0,
        ..Default::default()
    };
    assert!(matches!(
        rolling_contact(rolling.as_mut(), None, &options),
        Err(RollingContactError::NoLiftOff { .. })
    ));
}

/// The CLI: the table, the JSON and the chart; a usage error for a coordinate the model
/// lacks.
#[test]
fn cli_prints_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let chart = dir.path().join("rolling.svg");
    let out = eomgen_ok(&[
        "study",
        "rolling-contact",
        "eccentric_cylinder",
        "--after-lift-off",
        "--set",
        "e=0.2",
        "--set",
        "IG=0.6",
        "--set",
        "gamma=0.9",
        "--samples",
        "401",
        "--plot",
        chart.to_str().unwrap(),
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("lift-off   t = 1.43901"), "{text}");
    assert!(text.contains("stopped at the landing"), "{text}");
    assert!(std::fs::metadata(&chart).unwrap().len() > 1000);
    let out = eomgen_ok(&[
        "study",
        "rolling-contact",
        "eccentric_cylinder",
        "--json",
        "--samples",
        "201",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["rolling"]["mu_diverges"].as_bool().unwrap());
    assert!(v["flight"].is_null());
    let out = eomgen(&[
        "study",
        "rolling-contact",
        "eccentric_cylinder",
        "--normal",
        "z",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

/// A friction coefficient below `μ(0) = |F_t(0)|/N(0)` is reached at the start — the body
/// slips from the first instant — not at a later rising crossing after `μ` dips (nor never,
/// for μ = 0): `F_t² − μ² N²` is already ≥ 0 at t = 0, where a rising event cannot fire.
/// Above `μ(0)` (and below the first peak) the time is the event's, after the start, where
/// `μ(t)` computed from the samples has reached the threshold.
#[test]
fn a_threshold_below_the_initial_mu_is_reached_at_the_start() {
    let first = study(&[], vec![]);
    let mu0 = first.rolling.samples[0].mu.expect("N(0) > 0");
    assert!(mu0 > 0.0, "μ(0) = {mu0}");
    let s = study(&[], vec![0.0, 0.5 * mu0, 1.5 * mu0]);
    let e = &s.rolling.exceedances;
    assert_eq!(e[0].t, Some(0.0), "{e:?}");
    assert_eq!(e[1].t, Some(0.0), "{e:?}");
    let later = e[2].t.expect("reached before the lift-off");
    assert!(later > 0.0, "{e:?}");
    let reached = s
        .rolling
        .samples
        .iter()
        .filter(|x| x.t <= later)
        .all(|x| x.mu.is_some_and(|m| m <= 1.5 * mu0 * (1.0 + 1e-9)));
    assert!(reached, "μ(t) exceeds 1.5 μ(0) before {later} s");
}
