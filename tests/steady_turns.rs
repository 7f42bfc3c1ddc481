//! Steady turns (relative equilibria): operating points whose plane rates are constant in a
//! frame turning with a heading, linearised in that frame (issue 53, item 1), against closed
//! forms, an independent derivation by Kane's method, a published steady turn of the
//! benchmark bicycle, and simulations of the nonlinear equations.

use crate::common;

use eomgen::ModelInfo;
use eomgen::analysis::vibration::{
    self, EquilibriumStart, OperatingPointOptions, ParameterSweepOptions, SweepAxis,
};
use eomgen::analysis::{SimulationOptions, simulate};
use eomgen::linear::eigenvalues::Stability;
use eomgen::{OutputTimes, Stabilization};

fn model(name: &str) -> Box<dyn ModelInfo> {
    (eomgen::models::find(name).expect("bundled model").make)()
}

fn file_model(path: &str) -> Box<dyn ModelInfo> {
    eomgen::ModelSource::open(path)
        .expect("model loads")
        .instantiate()
}

fn at(name: &str) -> OperatingPointOptions {
    OperatingPointOptions {
        start: EquilibriumStart::Named(name.to_string()),
        ..OperatingPointOptions::default()
    }
}

fn index(model: &dyn ModelInfo, name: &str) -> usize {
    let names = model.description().coordinate_names();
    names.iter().position(|c| *c == name).expect("a coordinate")
}

/// The rolling disc's steady turn (`rolling_disc --at turning`: heading rate −1 rad/s, spin
/// rate 7.5 rad/s held): its lean satisfies the closed form
/// `g tan φ = v² (3/(2 R_G) + r sin φ/(4 R_G²))` (v and R_G the centre's speed and radius) to
/// rounding, and agrees with `tools/coin_turn_reference.py` (Kane's method in SymPy, the
/// contact eliminated by the rolling constraints, at 30 digits) to 1e-14; the linearisation
/// in the turning frame has that derivation's `s = ±9.6499221962793447639 i` to 1e-9
/// (central differences with Richardson extrapolation) and two exact zeros (the family of
/// turns), so the turn is stable to linear order. The contact point's rates are found from
/// the constraints: `x_dot = r · spin_dot`, on a circle of 1.5 m.
#[test]
#[allow(clippy::excessive_precision)]
fn a_rolling_coins_turn_has_the_closed_forms_lean_and_kanes_eigenvalues() {
    let mut m = model("rolling_disc");
    let a = vibration::steady_motion_analysis(m.as_mut(), &at("turning")).expect("turns");
    let (r, g) = (0.2, 9.81);
    let lean = a.steady_motion.q[index(m.as_ref(), "lean")];
    assert!((lean - 0.2201646358312328062697032).abs() < 1e-14, "{lean}");
    let turn = a.turning.as_ref().expect("a steady turn");
    assert_eq!((turn.angle.as_str(), turn.rate), ("yaw", -1.0));
    let radius = turn.radius.expect("a circle");
    assert!((radius - 1.5).abs() < 1e-13, "{radius}");
    let radius_g = radius - r * lean.sin();
    let v = turn.rate.abs() * radius_g;
    let closed = v * v * (1.5 / radius_g + r * lean.sin() / (4.0 * radius_g * radius_g));
    assert!((g * lean.tan() - closed).abs() < 1e-13 * closed, "{closed}");
    assert_eq!(a.found_rates, ["x_dot", "y_dot"]);
    assert!((a.steady_motion.qdot[index(m.as_ref(), "x")] - 1.5).abs() < 1e-14);
    assert_eq!(a.eigenvalues.iter().filter(|s| s.norm() == 0.0).count(), 2);
    for s in a.eigenvalues.iter().filter(|s| s.norm() > 0.0) {
        assert!(
            s.re == 0.0 && (s.im.abs() - 9.6499221962793447639).abs() < 1e-9,
            "{s}"
        );
    }
    assert!(matches!(a.stability, Stability::MarginallyStable));
    // The text says what was held and in which frame.
    let out = common::eomgen_ok(&["modes", "rolling_disc", "--at", "turning"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("rates found    x_dot = 1.5"), "{text}");
    assert!(
        text.contains("x_dot, y_dot constant in the frame turned by yaw: Ω = yaw_dot = -1 rad/s"),
        "{text}"
    );
}

/// The rolling disc run from its steady turn by the nonlinear equations: the lean stays at
/// the turn's to 1e-9 over 4 s (the turn is steady in the full model, not only in the
/// residuals the search zeroed), and from the turn with the lean rate nudged by 1e-4 rad/s
/// the lean oscillates at the linearisation's 9.6499 rad/s (its period from the zero
/// crossings, within 1e-5).
#[test]
fn the_coin_stays_in_its_turn_and_nods_at_the_linearisations_frequency() {
    let mut m = model("rolling_disc");
    let a = vibration::steady_motion_analysis(m.as_mut(), &at("turning")).expect("turns");
    let lean = index(m.as_ref(), "lean");
    let n = m.num_dofs();
    let times: Vec<f64> = (0..=4000).map(|k| f64::from(k) * 1e-3).collect();
    let run = |m: &mut dyn ModelInfo, nudge: f64| {
        let mut y = a.steady_motion.state();
        y[n + lean] += nudge;
        let options = SimulationOptions {
            t_end: 4.0,
            rtol: 1e-12,
            atol: 1e-12,
            output: OutputTimes::At(times.clone()),
            stabilization: Stabilization::Projection,
            initial_state: Some(y),
            ..SimulationOptions::default()
        };
        let sim = simulate(m, &options).expect("runs");
        assert!(sim.failure.is_none(), "{:?}", sim.failure);
        (sim.solution.iter())
            .map(|(_, y)| y[lean] - a.steady_motion.q[lean])
            .collect::<Vec<f64>>()
    };
    let still = run(m.as_mut(), 0.0);
    let drift = still.iter().fold(0.0f64, |w, d| w.max(d.abs()));
    assert!(drift < 1e-9, "the lean drifts by {drift:e}");
    let nodding = run(m.as_mut(), 1e-4);
    let mean = nodding.iter().sum::<f64>() / nodding.len() as f64;
    // Upward zero crossings of the lean about its mean, by linear interpolation.
    let crossings: Vec<f64> = (1..nodding.len())
        .filter(|&k| nodding[k - 1] - mean < 0.0 && nodding[k] - mean >= 0.0)
        .map(|k| {
            let (d0, d1) = (nodding[k - 1] - mean, nodding[k] - mean);
            times[k - 1] + 1e-3 * d0 / (d0 - d1)
        })
        .collect();
    assert!(crossings.len() >= 5, "{crossings:?}");
    let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    let omega = std::f64::consts::TAU / period;
    assert!(
        (omega - 9.649922196279345).abs() < 1e-5 * 9.65,
        "ω = {omega}"
    );
}

/// A rigid body in the plane driven by body-fixed forces linear in its body-frame velocities
/// (`tests/fixtures/cornering_body.yaml`): nothing is constrained, so the contact point's
/// rates are states of their own, measured in the turning frame. The turn found satisfies
/// the body-frame balances `−m v r = k (u0 − u)`, `m u r = Fs − cv v − cr r`,
/// `0 = Ms − dv v − dr r` to 1e-13, and the reduced state matrix equals the body-frame
/// Jacobian `[−k/m, r, v; −r, −cv/m, −cr/m − u; 0, −dv/Iz, −dr/Iz]` to 1e-13 (exact
/// generated Jacobians).
#[test]
fn a_body_cornering_without_constraints_is_linearised_in_its_body_frame() {
    let path = format!(
        "{}/tests/fixtures/cornering_body.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut m = file_model(&path);
    let a = vibration::steady_motion_analysis(m.as_mut(), &at("cornering")).expect("corners");
    let (mass, iz, k, u0, cv, cr, fs, dv, dr, ms) =
        (2.0, 0.5, 3.0, 2.0, 4.0, 0.7, 1.5, 0.3, 0.8, 0.2);
    let qd = &a.steady_motion.qdot;
    let (u, v, r) = (qd[0], qd[1], qd[2]);
    for residual in [
        -mass * v * r - k * (u0 - u),
        mass * u * r - (fs - cv * v - cr * r),
        ms - dv * v - dr * r,
    ] {
        assert!(
            residual.abs() < 1e-13,
            "{residual:e} at u = {u}, v = {v}, r = {r}"
        );
    }
    assert!(r > 0.1 && u > 1.0, "a turn: u = {u}, r = {r}");
    let lin = &a.linearization;
    assert_eq!(lin.states, ["x_dot", "y_dot", "psi_dot"]);
    assert!(lin.exact_jacobian);
    let closed = [
        [-k / mass, r, v],
        [-r, -cv / mass, -cr / mass - u],
        [0.0, -dv / iz, -dr / iz],
    ];
    for (i, row) in closed.iter().enumerate() {
        for (j, want) in row.iter().enumerate() {
            let got = lin.state_matrix[(i, j)];
            assert!(
                (got - want).abs() < 1e-13,
                "A[{i}, {j}] = {got}, closed form {want}"
            );
        }
    }
}

/// The benchmark bicycle with a steer torque: D. L. Peterson's steady turn to the right
/// ("Precise steady turning conditions", UC Davis Sports Biomechanics Lab, 2011; his own
/// derivation) at lean 5°, steer 0.0249931148885184 rad and steer torque
/// 0.002386180613544564 N·m runs at 6.047634145797575 m/s (front wheel rate × r_F) with
/// pitch π/10 − 0.3139899180509261. eomgen, holding the lean and steer and finding the
/// speed and every rate the contacts fix, finds both to 1e-12. (Peterson also lists
/// eigenvalues, −0.000896, −1.5654 ± 5.9405 i, −16.116; they are not those of the free
/// motion, whose speed may change.) eomgen's linearisation in the turning frame has one
/// real eigenvalue s₁ ≈ +0.018: the nonlinear equations, run from the turn with the torque
/// raised by 1e-4 of itself, depart from it as `e^{s₁ t} − 1`, the lean's offset growing
/// from t = 100 s to 200 s by the ratio `(e^{200 s₁} − 1)/(e^{100 s₁} − 1)` within 2 %.
#[test]
#[allow(clippy::excessive_precision)]
fn the_bicycle_turns_as_petersons_steady_turn_and_departs_at_its_eigenvalue() {
    let torque = 0.002386180613544564;
    let (_dir, path) = common::edited_model(
        "whipple_bicycle",
        &[
            (
                "gravity: [0, 0, -g]\n",
                "gravity: [0, 0, -g]\ntorques:\n  steer_front: { body: front_frame, vector: [0, 0, -T], in: H }\n  steer_rear: { body: rear_frame, vector: [0, 0, T], in: H }\n",
            ),
            ("  v: 5.0 ", "  T: 0.002386180613544564  # N*m\n  v: 5.0 "),
            (
                "    lean: { held: 0.1 }\n    steer: -0.03\n",
                "    lean: { held: 0.08726646259971647 }\n    steer: { held: -0.0249931148885184 }\n",
            ),
        ],
    );
    let mut m = file_model(&path);
    let a = vibration::steady_motion_analysis(m.as_mut(), &at("turning")).expect("turns");
    let front = a.steady_motion.qdot[index(m.as_ref(), "front_wheel")];
    let speed = 0.35 * front;
    assert!((speed - 6.047634145797575).abs() < 1e-12 * 6.05, "{speed}");
    let pitch = a.steady_motion.q[index(m.as_ref(), "pitch")];
    let peterson = std::f64::consts::PI / 10.0 - 0.3139899180509261;
    assert!(
        (pitch - peterson).abs() < 1e-12,
        "{pitch} against {peterson}"
    );
    let s1 = a
        .eigenvalues
        .iter()
        .find(|s| s.im == 0.0 && s.re > 0.0)
        .expect("one unstable real root")
        .re;
    assert!(s1 > 0.01 && s1 < 0.03, "{s1}");
    // The nonlinear equations from the turn, the torque raised.
    m.set_parameter("T", torque * (1.0 + 1e-4)).expect("T");
    let lean = index(m.as_ref(), "lean");
    let options = SimulationOptions {
        t_end: 200.0,
        rtol: 1e-12,
        atol: 1e-12,
        output: OutputTimes::At(vec![0.0, 100.0, 200.0]),
        stabilization: Stabilization::Projection,
        initial_state: Some(a.steady_motion.state()),
        method: eomgen::analysis::Method::Dop853,
        ..SimulationOptions::default()
    };
    let sim = simulate(m.as_mut(), &options).expect("runs");
    assert!(sim.failure.is_none(), "{:?}", sim.failure);
    let offset = |k: usize| sim.solution.state(k)[lean] - a.steady_motion.q[lean];
    let seen = offset(2) / offset(1);
    let linear = ((200.0 * s1).exp() - 1.0) / ((100.0 * s1).exp() - 1.0);
    assert!(
        (seen / linear - 1.0).abs() < 0.02,
        "grew ×{seen}, e^(s₁ t) says ×{linear}"
    );
}

/// The hands-free turns of the benchmark bicycle (Basu-Mandal, Chatterjee & Papadopoulos,
/// *Proc. R. Soc. A* 463:1983–2003, 2007): the family with the handlebar forward branches
/// off straight running at the capsize speed (Meijaard et al. 2007, 6.02426201538837 m/s,
/// which `tests/steady_motions.rs` finds by its sweep). With the lean held at 0.0025 and
/// 0.005 rad, the speeds found extrapolate (as `v_c − a φ²`) to it within 1e-8, and the
/// turn there is unstable by a slow real root. Followed by a sweep of the held steer
/// towards a quarter turn, the same kind of family ends in a static equilibrium with the
/// frame upright: the speed and lean go to 0 as the front wheel turns across.
#[test]
fn hands_free_turns_branch_off_at_the_capsize_speed_and_end_at_rest() {
    let (_dir, path) = common::edited_model(
        "whipple_bicycle",
        &[
            ("    lean: { held: 0.1 }\n", "    lean: { held: phi }\n"),
            ("  v: 5.0 ", "  phi: 0.1  # rad\n  v: 5.0 "),
        ],
    );
    let mut m = file_model(&path);
    let x = index(m.as_ref(), "x");
    let speed = |m: &mut dyn ModelInfo, phi: f64| {
        m.set_parameter("phi", phi).expect("phi");
        let a = vibration::steady_motion_analysis(m, &at("turning")).expect("turns");
        assert_eq!(a.held_coordinates, ["lean"]);
        assert!(
            matches!(a.stability, Stability::Unstable { .. }),
            "{:?}",
            a.stability
        );
        a.steady_motion.qdot[x]
    };
    let (fine, coarse) = (speed(m.as_mut(), 0.0025), speed(m.as_mut(), 0.005));
    let capsize = (4.0 * fine - coarse) / 3.0;
    assert!((capsize - 6.02426201538837).abs() < 1e-8, "{capsize}");
    // The steer held instead, from 1.18 rad to 1.555 rad to the right.
    let (_dir2, path2) = common::edited_model(
        "whipple_bicycle",
        &[
            ("    steer: -0.03\n", "    steer: { held: -delta }\n"),
            ("    lean: { held: 0.1 }\n", "    lean: 0.15\n"),
            (
                "    yaw_dot: { guess: -0.16 }\n",
                "    yaw_dot: { guess: -2 }\n",
            ),
            ("    x_dot: { guess: v }\n", "    x_dot: { guess: 0.9 }\n"),
            (
                "    rear_wheel_dot: { guess: v/rR }\n",
                "    rear_wheel_dot: { guess: 3 }\n",
            ),
            (
                "    front_wheel_dot: { guess: v/rF }\n",
                "    front_wheel_dot: { guess: 1 }\n",
            ),
            ("  v: 5.0 ", "  delta: 1.18  # rad\n  v: 5.0 "),
        ],
    );
    let mut m = file_model(&path2);
    let options = ParameterSweepOptions {
        axis: SweepAxis {
            name: "delta".to_string(),
            values: (0..=25).map(|k| 1.18 + 0.015 * f64::from(k)).collect(),
        },
        operating_point: at("turning"),
        refine: false,
    };
    let sweep = vibration::parameter_sweep(m.as_mut(), &options, |_, _| {}).expect("sweeps");
    let found: Vec<(f64, f64)> = (sweep.points.iter())
        .map(|p| {
            assert!(p.error.is_none(), "{:?}", p.error);
            (p.found["lean"], p.found["x_dot"])
        })
        .collect();
    let (lean_end, speed_end) = found[found.len() - 1];
    assert!(lean_end > 0.0 && lean_end < 0.05, "{found:?}");
    assert!(speed_end > 0.0 && speed_end < 0.3, "{found:?}");
    // Lean and speed fall together toward the quarter turn.
    assert!(
        found.windows(2).all(|w| w[0].0 > w[1].0 && w[0].1 > w[1].1),
        "{found:?}"
    );
}

/// A turn whose equations are not symmetric under turning is refused, naming the turning
/// angle: a yaw moment that depends on the heading itself (`Ms (1 + cos psi)`).
#[test]
fn a_turn_the_model_is_not_symmetric_under_is_refused() {
    let (_dir, path) = {
        let text = std::fs::read_to_string(format!(
            "{}/tests/fixtures/cornering_body.yaml",
            env!("CARGO_MANIFEST_DIR")
        ))
        .expect("fixture");
        let text = text.replace(
            "  psi: Ms - dv*(y_dot*cos(psi)",
            "  psi: Ms*(1 + cos(psi)) - dv*(y_dot*cos(psi)",
        );
        let dir = tempfile::tempdir().expect("folder");
        let file = dir.path().join("cornering_body.yaml");
        std::fs::write(&file, text).expect("written");
        let file = file.to_str().expect("UTF-8").to_string();
        (dir, file)
    };
    let mut m = file_model(&path);
    let error = vibration::steady_motion_analysis(m.as_mut(), &at("cornering"))
        .expect_err("not a steady turn")
        .to_string();
    assert!(
        error.contains("turns `x` and `y` with `psi`, but the equations are not symmetric"),
        "{error}"
    );
}

/// A Chaplygin sleigh turning under a body-fixed thrust and yaw moment
/// (`tests/fixtures/sleigh_turn.yaml`): its knife edge makes one of the contact point's
/// rates dependent and leaves the other a state measured in the turning frame, which one
/// depending on the heading. Linearised at the headings 0, 1, π/2 and 3 rad, the
/// eigenvalues equal those of the body-frame closed form
/// `[−k/m, 2 d w; −m d w/(I + m d²), −(m d u + dr)/(I + m d²)]` at the turn's `u` and `w`
/// to 1e-9 (central differences), and the turn satisfies `u = u0 + m d w²/k` and
/// `m d u w = Ms − dr w` to 1e-12.
#[test]
fn a_sleigh_turning_with_one_plane_rate_constrained_has_its_closed_form_at_every_heading() {
    let path = format!(
        "{}/tests/fixtures/sleigh_turn.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let (m_, i_, d, k, u0, ms, dr) = (1.0, 0.1, 0.5, 3.0, 2.0, 0.4, 0.3);
    for heading in [0.0, 1.0, std::f64::consts::FRAC_PI_2, 3.0] {
        let mut m = file_model(&path);
        m.set_parameter("heading", heading).expect("heading");
        let a = vibration::steady_motion_analysis(m.as_mut(), &at("turn")).expect("turns");
        let qd = &a.steady_motion.qdot;
        let (c, s) = (heading.cos(), heading.sin());
        let (u, w) = (qd[0] * c + qd[1] * s, qd[2]);
        assert!(
            (-qd[0] * s + qd[1] * c).abs() < 1e-12,
            "side slip at {heading}"
        );
        assert!((u - u0 - m_ * d * w * w / k).abs() < 1e-12, "{u}, {w}");
        assert!((m_ * d * u * w - (ms - dr * w)).abs() < 1e-12, "{u}, {w}");
        let j = i_ + m_ * d * d;
        let closed = nalgebra::Matrix2::new(
            -k / m_,
            2.0 * d * w,
            -m_ * d * w / j,
            -(m_ * d * u + dr) / j,
        );
        let mut want: Vec<f64> = closed.complex_eigenvalues().iter().map(|z| z.re).collect();
        want.sort_by(f64::total_cmp);
        let mut got: Vec<f64> = a.eigenvalues.iter().map(|z| z.re).collect();
        got.sort_by(f64::total_cmp);
        assert_eq!(
            a.linearization.states.len(),
            2,
            "{:?}",
            a.linearization.states
        );
        for (g, w) in got.iter().zip(&want) {
            assert!(
                (g - w).abs() < 1e-9,
                "heading {heading}: {got:?} against {want:?}"
            );
        }
    }
}

/// The cornering body linearised at a heading of 1 rad instead of 0: the turning frame's
/// rates are then the ground-aligned components at that instant, not the body frame's, and
/// the eigenvalues are the same to 1e-12.
#[test]
fn a_turn_linearised_at_another_heading_has_the_same_eigenvalues() {
    let (_dir, path) = {
        let text = std::fs::read_to_string(format!(
            "{}/tests/fixtures/cornering_body.yaml",
            env!("CARGO_MANIFEST_DIR")
        ))
        .expect("fixture");
        let text = text
            .replace(
                "    x_dot: { guess: 2 }\n",
                "    psi: 1\n    x_dot: { guess: 2*cos(1) }\n",
            )
            .replace(
                "    y_dot: { guess: 0 }\n",
                "    y_dot: { guess: 2*sin(1) }\n",
            );
        let dir = tempfile::tempdir().expect("folder");
        let file = dir.path().join("cornering_body.yaml");
        std::fs::write(&file, text).expect("written");
        let file = file.to_str().expect("UTF-8").to_string();
        (dir, file)
    };
    let base = format!(
        "{}/tests/fixtures/cornering_body.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let eigen = |path: &str| {
        let mut m = file_model(path);
        let a = vibration::steady_motion_analysis(m.as_mut(), &at("cornering")).expect("turns");
        let mut s = a.eigenvalues.clone();
        s.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        (s, a.steady_motion.q[2])
    };
    let ((zero, psi0), (one, psi1)) = (eigen(&base), eigen(&path));
    assert_eq!((psi0, psi1), (0.0, 1.0));
    for (a, b) in zero.iter().zip(&one) {
        assert!((a - b).norm() < 1e-12, "{zero:?} against {one:?}");
    }
}

/// Sweeps of steady motions that hold no value of a family start every value from the
/// entry's own guess, as before continuation existed: the heavy top's precession over its
/// nutation angle is found at every value (marginally stable), the spun hoop's sweep stays on
/// its branch (no stability change), and every value of the conical spring's sweep is the
/// motion found from the entry's guess alone.
#[test]
fn sweeps_of_entries_without_held_values_start_from_the_entrys_guess() {
    let sweep = |m: &mut dyn ModelInfo, point: &str, name: &str, values: Vec<f64>| {
        let options = ParameterSweepOptions {
            axis: SweepAxis {
                name: name.to_string(),
                values,
            },
            operating_point: at(point),
            refine: true,
        };
        vibration::parameter_sweep(m, &options, |_, _| {}).expect("sweeps")
    };
    let mut top = model("heavy_top");
    let values = (0..10).map(|k| 0.1 + 0.13 * f64::from(k)).collect();
    let s = sweep(top.as_mut(), "precessing", "theta0", values);
    for p in &s.points {
        assert!(p.error.is_none(), "θ0 = {}: {:?}", p.value, p.error);
        assert!(
            matches!(p.stability, Some(Stability::MarginallyStable)),
            "{p:?}"
        );
    }
    let fixture = |name: &str| {
        file_model(&format!(
            "{}/tests/fixtures/{name}",
            env!("CARGO_MANIFEST_DIR")
        ))
    };
    let mut hoop = fixture("spun_hoop.yaml");
    let s = sweep(
        hoop.as_mut(),
        "spinning",
        "w",
        (0..6).map(|k| 5.0 + 5.0 * f64::from(k)).collect(),
    );
    assert!(s.stability_changes.is_empty(), "{:?}", s.stability_changes);
    // Each value as `modes --set k=…` finds it alone.
    let mut spring = fixture("conical_spring.yaml");
    let values: Vec<f64> = (0..10).map(|k| 20.0 + 20.0 * f64::from(k)).collect();
    let s = sweep(spring.as_mut(), "conical", "k", values);
    for p in &s.points {
        let mut alone = fixture("conical_spring.yaml");
        alone.set_parameter("k", p.value).expect("k");
        let a = vibration::steady_motion_analysis(alone.as_mut(), &at("conical")).expect("found");
        assert_eq!(p.eigenvalues, a.eigenvalues, "k = {}", p.value);
    }
}

/// A bicycle's turn at a lean of 1e-7 rad, so near straight running that its accelerations
/// at the turn are of the size of rounding, is still recognised as symmetric under turning;
/// and a coin "turning" at a heading rate of 0 is straight rolling, reported with no radius.
#[test]
fn nearly_straight_turns_are_turns_and_a_straight_one_has_no_radius() {
    let (_dir, path) = common::edited_model(
        "whipple_bicycle",
        &[("    lean: { held: 0.1 }\n", "    lean: { held: 1e-7 }\n")],
    );
    let mut m = file_model(&path);
    let a = vibration::steady_motion_analysis(m.as_mut(), &at("turning")).expect("a turn");
    let v = a.steady_motion.qdot[index(m.as_ref(), "x")];
    assert!((v - 6.02426201538837).abs() < 1e-6, "{v}");
    let (_dir2, path2) = common::edited_model(
        "rolling_disc",
        &[(
            "    lean: 0.3\n    yaw_dot: -1\n",
            "    lean: 0\n    yaw_dot: 0\n",
        )],
    );
    let out = common::eomgen_ok(&["modes", &path2, "--at", "turning", "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let turning = &json["operating_point"]["turning"];
    assert_eq!(turning["rate"], 0.0);
    assert!(turning.get("radius").is_none(), "{turning}");
    let text = common::eomgen_ok(&["modes", &path2, "--at", "turning"]);
    assert!(String::from_utf8_lossy(&text.stdout).contains("radius infinite (straight)"));
}
