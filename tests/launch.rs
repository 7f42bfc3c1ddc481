//! `eomgen study launch` (lecture 2, HW2) on `projectile_drag`: ranges and best launch
//! angles against closed forms — the parabola without drag, and with linear drag the landing
//! time of a transcendental equation solved here by bisection (and by Lambert's W) and θ*
//! from the zero of the closed form's dR/dθ — and the limits as v0 → ∞.
//!
//! Tolerances: every flight is integrated by DOP853 at rtol = atol = 1e-12 and its landing
//! located on the dense output to a few ulps of t, so ranges agree with the closed forms to
//! about 1e-11 relative (asserted: 1e-9). The range is flat at its maximum,
//! R(θ* + δ) ≈ R* − ½|R''| δ², so a relative error ε in R moves the maximiser by up to
//! √(2 ε R*/|R''|) ≈ 1e-6 rad at ε = 1e-12 (|R''| ≈ 4 R* without drag); θ* is asserted to
//! 5e-6 rad, the golden-section bracket being 1e-7 rad.

use crate::common;
use common::eomgen;

use eomgen::ModelInfo;
use eomgen::analysis::launch::{LaunchError, LaunchOptions, LaunchStudy, launch_study};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

/// `projectile_drag` with `sets` applied.
fn model(sets: &[(&str, f64)]) -> Box<dyn ModelInfo> {
    let mut m = (eomgen::models::find("projectile_drag")
        .expect("bundled")
        .make)();
    for (name, value) in sets {
        m.set_parameter(name, *value).unwrap();
    }
    m
}

fn parameter(m: &dyn ModelInfo, name: &str) -> f64 {
    let i = m
        .description()
        .parameters
        .iter()
        .position(|p| p.name == name)
        .unwrap();
    m.parameter_values()[i]
}

fn study(m: &mut dyn ModelInfo, speeds: &[f64], angles: usize) -> LaunchStudy {
    let options = LaunchOptions {
        speeds: speeds.to_vec(),
        angles,
        ..LaunchOptions::default()
    };
    launch_study(m, &options).unwrap()
}

/// Bisection to the last bit on `[lo, hi]` for `f` with `f(lo) > 0 > f(hi)`.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    assert!(f(lo) > 0.0 && f(hi) < 0.0, "not a bracket: [{lo}, {hi}]");
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if f(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Linear drag −c₁v, launch from the origin: with τ = m/c₁ and k = 1 + v0 sin θ/(g τ), the
/// landing time is T = τ u, u > 0 the root of k (1 − e^{−u}) = u (from y(T) = 0), found by
/// bisection; returns `(u, k)`.
fn linear_drag_landing(v0: f64, theta: f64, g: f64, tau: f64) -> (f64, f64) {
    let k = 1.0 + v0 * theta.sin() / (g * tau);
    let f = |u: f64| -k * (-u).exp_m1() - u;
    // f(0) = 0, f'(0) = k − 1 > 0 and f is concave: positive just right of 0.
    let mut lo = k - 1.0;
    while f(lo) <= 0.0 {
        lo *= 0.5;
    }
    if f(k) >= 0.0 {
        // k e^{−k} below the rounding of k: u = k + W₀(−k e^{−k}) = k − k e^{−k} + O(k² e^{−2k}).
        return (k - k * (-k).exp(), k);
    }
    (bisect(f, lo, k), k)
}

/// The closed-form range `R = v0 cos θ τ (1 − e^{−u}) = v0 cos θ τ u/k` and time of flight.
fn linear_drag_range(v0: f64, theta: f64, g: f64, tau: f64) -> (f64, f64) {
    let (u, k) = linear_drag_landing(v0, theta, g, tau);
    (v0 * theta.cos() * tau * u / k, tau * u)
}

/// θ* of the closed-form range, as the zero of dR/dθ by bisection (independent of the
/// study's golden-section search and of any integration). With V = v0/(g τ),
/// dk/dθ = V cos θ and du/dk = (u/k)/(1 − k + u) (implicit differentiation, using
/// k e^{−u} = k − u), so dR/dθ ∝ −sin θ + V cos²θ (k − u)/(k (1 − k + u)).
fn linear_drag_best_angle(v0: f64, g: f64, tau: f64) -> f64 {
    let v = v0 / (g * tau);
    let slope = |theta: f64| {
        let (u, k) = linear_drag_landing(v0, theta, g, tau);
        -theta.sin() + v * theta.cos().powi(2) * (k - u) / (k * (1.0 - k + u))
    };
    bisect(slope, 1e-9, FRAC_PI_2)
}

/// Lambert's W₀ on (−1/e, 0) by Halley's iteration from the branch-point series.
fn lambert_w0(z: f64) -> f64 {
    let p = (2.0 * (std::f64::consts::E * z + 1.0)).max(0.0).sqrt();
    let mut w = -1.0 + p - p * p / 3.0;
    for _ in 0..50 {
        let e = w.exp();
        let f = w * e - z;
        let step = f / (e * (w + 1.0) - (w + 2.0) * f / (2.0 * w + 2.0));
        w -= step;
        if step.abs() <= 1e-16 * w.abs() {
            break;
        }
    }
    w
}

/// Lambert's W₀ for a large argument, by Newton's iteration on w + ln w = ln z.
fn lambert_w0_large(z: f64) -> f64 {
    let mut w = z.ln();
    for _ in 0..50 {
        w -= (w + w.ln() - z.ln()) / (1.0 + 1.0 / w);
    }
    w
}

#[test]
fn without_drag_the_best_angle_is_45_degrees_and_the_range_v0_squared_over_g() {
    let mut m = model(&[("c1", 0.0), ("c2", 0.0)]);
    let g = parameter(m.as_ref(), "g");
    let s = study(m.as_mut(), &[1.0, 10.0, 100.0], 29);
    for sp in &s.speeds {
        let v0 = sp.speed;
        for p in &sp.curve {
            let exact = v0 * v0 * (2.0 * p.angle).sin() / g;
            assert!(
                (p.range - exact).abs() <= 1e-9 * exact,
                "v0 = {v0}, θ = {}: R = {} against {exact}",
                p.angle,
                p.range
            );
        }
        let b = &sp.best;
        eprintln!(
            "no drag, v0 = {v0}: θ* − 45° = {:.2e} rad, R*/(v0²/g) − 1 = {:.2e}",
            b.angle - FRAC_PI_4,
            b.range / (v0 * v0 / g) - 1.0
        );
        assert!((b.angle - FRAC_PI_4).abs() < 5e-6, "θ* = {}", b.angle);
        assert!((b.range - v0 * v0 / g).abs() <= 1e-9 * v0 * v0 / g);
        // A parabola: the apex halfway, landing at the launch angle, after 2 v0 sin θ/g.
        assert!((b.apex_fraction.unwrap() - 0.5).abs() < 1e-9);
        assert!((b.landing_angle - b.angle).abs() < 1e-9);
        let t = 2.0 * v0 * b.angle.sin() / g;
        assert!((b.flight_time - t).abs() <= 1e-9 * t);
        assert_eq!(b.path.len(), LaunchOptions::DEFAULT_PATH_SAMPLES);
        assert!(sp.bracket[1] - sp.bracket[0] <= s.angle_tol);
        let fixed = sp.at_shape_angle.as_ref().unwrap();
        assert!((fixed.range - v0 * v0 / g).abs() <= 1e-9 * v0 * v0 / g);
    }
}

#[test]
fn the_linear_drag_landing_time_agrees_with_lambert_w() {
    // T = τ (k + W₀(−k e^{−k})) (Warburton & Wang 2004) against the bisection, away from
    // the branch point k = 1 where W₀ is ill-conditioned.
    for (v0, theta) in [(10.0, 1.0), (100.0, 0.3), (1000.0, 0.1), (30.0, 1.5)] {
        let (g, tau) = (9.81, 10.0);
        let (u, k) = linear_drag_landing(v0, theta, g, tau);
        let w = lambert_w0(-k * (-k).exp());
        assert!(
            (k + w - u).abs() <= 1e-12 * u,
            "k = {k}: {} against {u}",
            k + w
        );
    }
}

#[test]
fn with_linear_drag_ranges_and_best_angles_match_the_closed_form() {
    let mut m = model(&[("c2", 0.0)]);
    let (g, tau) = (
        parameter(m.as_ref(), "g"),
        parameter(m.as_ref(), "m") / parameter(m.as_ref(), "c1"),
    );
    let speeds = [1.0, 10.0, 100.0, 1000.0, 10000.0, 100000.0];
    let s = study(m.as_mut(), &speeds, 29);
    let mut previous = FRAC_PI_4;
    for sp in &s.speeds {
        let v0 = sp.speed;
        for p in &sp.curve {
            let (range, time) = linear_drag_range(v0, p.angle, g, tau);
            assert!(
                (p.range - range).abs() <= 1e-9 * range,
                "v0 = {v0}, θ = {}: R = {} against {range}",
                p.angle,
                p.range
            );
            assert!((p.flight_time - time).abs() <= 1e-9 * time);
        }
        let expected = linear_drag_best_angle(v0, g, tau);
        let b = &sp.best;
        let x_inf = v0 * b.angle.cos() * tau;
        // θ* ≈ W₀(V²/e)/V for large V = v0/(g τ) (the module documentation).
        let v = v0 / (g * tau);
        let asymptotic = if v > 10.0 {
            lambert_w0_large(v * v / std::f64::consts::E) / v
        } else {
            f64::NAN
        };
        eprintln!(
            "linear drag, v0 = {v0:>6}: θ* = {:.9} rad ({:.5}°), independent {expected:.9}, \
             W₀(V²/e)/V = {asymptotic:.6}, R* = {:.6e} m, R*/x∞ = {:.9}, x_apex/R* = {:.6}, \
             landing at {:.4}°",
            b.angle,
            b.angle.to_degrees(),
            b.range,
            b.range / x_inf,
            b.apex_fraction.unwrap(),
            b.landing_angle.to_degrees()
        );
        assert!(
            (b.angle - expected).abs() < 5e-6,
            "v0 = {v0}: θ* = {} against {expected}",
            b.angle
        );
        // θ* falls below 45° and keeps falling as v0 grows.
        assert!(
            b.angle < previous,
            "v0 = {v0}: θ* = {} ≥ {previous}",
            b.angle
        );
        previous = b.angle;
        if v0 >= 10000.0 {
            assert!((b.angle / asymptotic - 1.0).abs() < 0.02);
        }
        // The range never reaches the vertical asymptote x∞ = v0 cos θ m/c₁.
        assert!(b.range < x_inf);
        // At the fixed angle 45°, the same closed form.
        let fixed = sp.at_shape_angle.as_ref().unwrap();
        let (range, _) = linear_drag_range(v0, FRAC_PI_4, g, tau);
        assert!((fixed.range - range).abs() <= 1e-9 * range);
    }
    // As v0 → ∞ at a fixed angle (45°): the range fills the asymptote x∞, and the path is a
    // straight rise at 45° (apex height over apex distance → tan 45° = 1) and a vertical
    // fall (apex over the landing point, landing at 90°).
    let fast = s.speeds.last().unwrap();
    let shape = fast.at_shape_angle.as_ref().unwrap();
    let apex = shape.apex.unwrap();
    eprintln!(
        "linear drag, v0 = {} at 45°: R/x∞ = {:.9}, x_apex/R = {:.6}, y_apex/x_apex = {:.6}, \
         landing at {:.6}°",
        fast.speed,
        shape.range / (fast.speed * FRAC_PI_4.cos() * tau),
        shape.apex_fraction.unwrap(),
        apex.y / apex.x,
        shape.landing_angle.to_degrees()
    );
    assert!(shape.range / (fast.speed * FRAC_PI_4.cos() * tau) > 1.0 - 1e-9);
    assert!(shape.apex_fraction.unwrap() > 0.998);
    assert!((apex.y / apex.x - 1.0).abs() < 0.01);
    assert!(shape.landing_angle > 89.99f64.to_radians());
    // And θ* → 0.
    assert!(fast.best.angle < 0.011, "θ*(10⁵ m/s) = {}", fast.best.angle);
    // The study restores the parameters it varied.
    assert_eq!(parameter(m.as_ref(), "theta0"), FRAC_PI_2);
    assert_eq!(parameter(m.as_ref(), "v0"), 20.0);
}

#[test]
fn with_quadratic_drag_the_best_angle_is_below_45_degrees_and_the_range_grows_logarithmically() {
    let mut m = model(&[("c1", 0.0)]);
    let (g, mass, c2) = (
        parameter(m.as_ref(), "g"),
        parameter(m.as_ref(), "m"),
        parameter(m.as_ref(), "c2"),
    );
    let speeds = [1000.0, 10000.0, 100000.0, 1000000.0];
    let s = study(m.as_mut(), &speeds, 29);
    let mut previous = FRAC_PI_4;
    for sp in &s.speeds {
        let (b, fixed) = (&sp.best, sp.at_shape_angle.as_ref().unwrap());
        eprintln!(
            "quadratic drag, v0 = {:>7}: θ* = {:.6}°, R* = {:.6} m, x_apex/R* = {:.6}, \
             landing at {:.4}°; at 45°: R = {:.6} m, x_apex/R = {:.6}, landing at {:.4}°",
            sp.speed,
            b.angle.to_degrees(),
            b.range,
            b.apex_fraction.unwrap(),
            b.landing_angle.to_degrees(),
            fixed.range,
            fixed.apex_fraction.unwrap(),
            fixed.landing_angle.to_degrees()
        );
        assert!(b.angle < previous, "θ*({}) = {}", sp.speed, b.angle);
        previous = b.angle;
        assert!(b.range < sp.speed * sp.speed / g);
    }
    // The speed decays as v0 e^{−c₂ s/m} along the path length s until it nears the terminal
    // speed, so at a fixed angle θ each tenfold speed adds (m/c₂) cos θ ln 10 to the range:
    // logarithmic growth. At 45°, the last decade within 1 %:
    let gains = |shot: fn(&eomgen::analysis::launch::SpeedStudy) -> f64| -> Vec<f64> {
        s.speeds
            .windows(2)
            .map(|w| shot(&w[1]) - shot(&w[0]))
            .collect()
    };
    let fixed = gains(|sp| sp.at_shape_angle.as_ref().unwrap().range);
    let predicted = mass / c2 * FRAC_PI_4.cos() * 10f64.ln();
    eprintln!("gains per decade at 45°: {fixed:?} m; (m/c2) cos 45° ln 10 = {predicted:.4} m");
    assert!((fixed.last().unwrap() / predicted - 1.0).abs() < 0.01);
    // At θ* too the gains per decade are nearly equal (θ* drifts slowly).
    let best = gains(|sp| sp.best.range);
    eprintln!("gains per decade at θ*: {best:?} m");
    for w in best.windows(2) {
        assert!((w[1] / w[0] - 1.0).abs() < 0.05, "{best:?}");
    }
    // The fall becomes vertical at 45°.
    let last = s.speeds.last().unwrap().at_shape_angle.as_ref().unwrap();
    assert!(last.landing_angle > 89.9f64.to_radians());
}

#[test]
fn bad_options_are_refused() {
    let mut m = model(&[]);
    let run = |m: &mut dyn ModelInfo, o: LaunchOptions| launch_study(m, &o).unwrap_err();
    let e = run(
        m.as_mut(),
        LaunchOptions {
            angle_parameter: "alpha".into(),
            ..Default::default()
        },
    );
    assert!(
        matches!(e, LaunchError::UnknownParameter { role: "angle", .. }),
        "{e}"
    );
    let e = run(
        m.as_mut(),
        LaunchOptions {
            event: "impact".into(),
            ..Default::default()
        },
    );
    assert!(matches!(e, LaunchError::UnknownEvent { .. }), "{e}");
    let e = run(
        m.as_mut(),
        LaunchOptions {
            height_coordinate: "z".into(),
            ..Default::default()
        },
    );
    assert!(
        matches!(e, LaunchError::UnknownCoordinate { role: "height", .. }),
        "{e}"
    );
    let e = run(
        m.as_mut(),
        LaunchOptions {
            speeds: vec![1.0, f64::NAN],
            ..Default::default()
        },
    );
    assert!(matches!(e, LaunchError::InvalidSpeed { .. }), "{e}");
    let e = run(
        m.as_mut(),
        LaunchOptions {
            angles: 2,
            ..Default::default()
        },
    );
    assert_eq!(e, LaunchError::TooFewAngles { angles: 2 });
}

#[test]
fn a_flight_that_never_lands_fails() {
    // Without gravity the ball coasts to a stop above the ground.
    let mut m = model(&[("g", 0.0)]);
    let options = LaunchOptions {
        speeds: vec![10.0],
        angles: 5,
        t_max: 100.0,
        ..LaunchOptions::default()
    };
    let e = launch_study(m.as_mut(), &options).unwrap_err();
    assert!(
        matches!(e, LaunchError::NoLanding { t_max: 100.0, .. }),
        "{e}"
    );
    // A drag that pushes (c₂ < 0) blows up in finite time: the integration fails.
    let mut m = model(&[("c2", -1.0)]);
    let e = launch_study(m.as_mut(), &options).unwrap_err();
    assert!(matches!(e, LaunchError::IntegrationFailed { .. }), "{e}");
}

#[test]
fn the_command_prints_the_study_as_json_and_text() {
    let out = eomgen(&[
        "study",
        "launch",
        "projectile_drag",
        "--set",
        "c1=0",
        "--set",
        "c2=0",
        "--speeds",
        "10",
        "--angles",
        "9",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let best = &json["speeds"][0]["best"];
    let angle = best["angle"].as_f64().unwrap();
    let range = best["range"].as_f64().unwrap();
    assert!((angle - FRAC_PI_4).abs() < 5e-6);
    assert!((range - 100.0 / 9.81).abs() < 1e-9 * range);
    assert_eq!(json["speeds"][0]["curve"].as_array().unwrap().len(), 9);
    let out = eomgen(&[
        "study",
        "launch",
        "projectile_drag",
        "--speeds",
        "5,50",
        "--angles",
        "9",
    ]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    // Two rows per speed: θ* and the shape angle, 45°.
    assert_eq!(
        text.lines()
            .filter(|l| l.trim_start().starts_with('5'))
            .count(),
        4,
        "{text}"
    );
}

#[test]
fn the_command_refuses_what_it_cannot_study() {
    let code = |args: &[&str]| {
        let out = eomgen(args);
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    // cannonball has no landing event.
    let (status, err) = code(&["study", "launch", "cannonball"]);
    assert_eq!(status, Some(2), "{err}");
    assert!(err.contains("no event `ground`"), "{err}");
    let (status, err) = code(&[
        "study",
        "launch",
        "projectile_drag",
        "--angle-parameter",
        "alpha",
    ]);
    assert_eq!(status, Some(2), "{err}");
    assert!(err.contains("--angle-parameter"), "{err}");
    let (status, err) = code(&["study", "launch", "projectile_drag", "--speeds", "-1"]);
    assert_eq!(status, Some(2), "{err}");
    let (status, err) = code(&[
        "study",
        "launch",
        "projectile_drag",
        "--set",
        "g=0",
        "--t-max",
        "100",
        "--angles",
        "3",
    ]);
    assert_eq!(status, Some(1), "{err}");
    assert!(err.contains("never reaches the ground"), "{err}");
}

#[test]
fn the_study_works_on_any_model_that_names_its_parameters() {
    // A vacuum shot in other names: angle `alpha`, speed `speed`, event `impact`, coordinates
    // (u, w).
    let dir = std::env::temp_dir().join(format!("eomgen-launch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("shot.yaml");
    std::fs::write(
        &path,
        "name: shot\nparameters: { g: 2.0, alpha: 0.3, speed: 3.0 }\ncoordinates: [u, w]\n\
         points: { P: [u, w] }\nbodies: { ball: { mass: 1, at: P } }\ngravity: [0, -g]\n\
         initial: { u: 1, w: 0, u_dot: speed*cos(alpha), w_dot: speed*sin(alpha) }\n\
         events: { impact: { when: w, direction: falling } }\n",
    )
    .unwrap();
    let out = eomgen(&[
        "study",
        "launch",
        path.to_str().unwrap(),
        "--angle-parameter",
        "alpha",
        "--speed-parameter",
        "speed",
        "--event",
        "impact",
        "--range-coordinate",
        "u",
        "--height-coordinate",
        "w",
        "--angles",
        "9",
        "--json",
    ]);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let best = &json["speeds"][0]["best"];
    assert_eq!(json["speeds"][0]["speed"].as_f64(), Some(3.0));
    assert!((best["angle"].as_f64().unwrap() - FRAC_PI_4).abs() < 5e-6);
    // The range is measured from the launch point u = 1: v0²/g = 4.5.
    assert!((best["range"].as_f64().unwrap() - 4.5).abs() < 1e-9);
}
