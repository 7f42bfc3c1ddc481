//! Floquet analysis and the Mathieu inverted pendulum (issue 7, item 7; lectures 19 and 21):
//! the monodromy matrix against `e^{AT}`, Liouville's formula, the analytic multipliers of the
//! unshaken pendulum, Kapitza's stability region confirmed by nonlinear simulation, the
//! computed stability boundary against Kapitza and the Mathieu series, and the CLI.

use crate::common;
use common::{eomgen, eomgen_ok};

use std::f64::consts::TAU;

use eomgen::{
    DormandPrince853, FloquetError, FloquetOptions, FloquetStability, Integrator,
    IntegratorOptions, ModelInfo, OutputTimes, check_periodic_equilibrium, find_equilibrium,
    floquet_analysis, linearize, matrix_exponential,
};

fn model(name: &str) -> Box<dyn ModelInfo> {
    (eomgen::models::find(name).expect("bundled model").make)()
}

/// Floquet analysis of `mathieu_pendulum` about `upright` with parameters `set`.
fn pendulum_floquet(set: &[(&str, f64)]) -> eomgen::FloquetAnalysis {
    let mut m = model("mathieu_pendulum");
    for (name, value) in set {
        m.set_parameter(name, *value).unwrap();
    }
    let w = parameter(m.as_ref(), "w");
    let q = find_equilibrium(m.as_ref(), &[0.0], 0.0).unwrap().q;
    check_periodic_equilibrium(m.as_ref(), &q, 0.0, TAU / w).unwrap();
    floquet_analysis(
        m.as_ode_mut(),
        &[q[0], 0.0],
        0.0,
        TAU / w,
        &FloquetOptions::default(),
    )
    .unwrap()
}

fn parameter(m: &dyn ModelInfo, name: &str) -> f64 {
    let i = m
        .description()
        .parameter_names()
        .iter()
        .position(|p| *p == name)
        .unwrap();
    m.parameter_values()[i]
}

/// For constant coefficients `Φ(T) = e^{AT}`: the double pendulum's generated Jacobian at
/// `hanging` against `e^{AT}` from its exact linearisation. Tolerance 1e-10 relative to
/// `‖Φ‖`: DOP853 at 1e-12 over one period leaves a global error of order 1e-11; Padé 13 is
/// exact to rounding. (A hand-written `A`: `runtime/tests/vibration.rs`.)
#[test]
fn monodromy_of_a_constant_coefficient_system_is_the_matrix_exponential() {
    let mut m = model("double_pendulum");
    let guess = m
        .equilibrium_guesses()
        .into_iter()
        .find(|(name, _)| *name == "hanging")
        .expect("the double pendulum names `hanging`")
        .1;
    let q = find_equilibrium(m.as_ref(), &guess, 0.0).unwrap().q;
    let a = linearize(m.as_ref(), &q, &[0.0, 0.0], 0.0)
        .unwrap()
        .state_matrix()
        .unwrap();
    let y0: Vec<f64> = q.iter().copied().chain([0.0, 0.0]).collect();
    let period = 0.9;
    let f = floquet_analysis(m.as_ode_mut(), &y0, 0.0, period, &FloquetOptions::default()).unwrap();
    let expected = matrix_exponential(&(&a * period));
    let err = (&f.monodromy_matrix - &expected).amax() / expected.amax();
    eprintln!("double pendulum at hanging: |Φ(T) − e^(AT)|/|e^(AT)| = {err:.1e}");
    assert!(err < 1e-10, "double pendulum: |Φ − e^(AT)| = {err:e}");
    // The equilibrium stays put up to the rounding of cos(−π/2) in its forcing.
    assert!(
        f.closure_error < 1e-12,
        "closure error {:e}",
        f.closure_error
    );
}

/// Liouville's formula `det Φ(T) = exp ∫ tr J dt`: 1 for the undamped `mathieu_pendulum`,
/// `e^{−cT/(m l²)}` with hinge damping. Tolerance 1e-10: the integration error of DOP853 at
/// 1e-12 over one period. (The hand-written Mathieu equation: `runtime/tests/vibration.rs`.)
#[test]
fn liouville_determinant_and_multiplier_product() {
    let f = pendulum_floquet(&[]);
    assert!((f.determinant - 1.0).abs() < 1e-10, "{}", f.determinant);
    let (c, m, l) = (0.3, 2.0, 0.8);
    let f = pendulum_floquet(&[("c", c), ("m", m), ("l", l)]);
    let det = (-c * f.period / (m * l * l)).exp();
    assert!(
        (f.determinant - det).abs() < 1e-10,
        "{} vs {det}",
        f.determinant
    );
}

/// Without shaking the upright pendulum is the unstable `θ̈ = (g/l) θ`, whose multipliers over
/// any `T` are `e^{±√(g/l) T}`; relative tolerance 1e-8 (rtol 1e-12 of DOP853, with room).
#[test]
fn unshaken_upright_pendulum_has_analytic_multipliers() {
    let (g, l, w) = (10.0, 0.5, 7.0);
    let f = pendulum_floquet(&[("a", 0.0), ("g", g), ("l", l), ("w", w)]);
    let growth = (g / l).sqrt() * TAU / w;
    eprintln!(
        "unshaken: μ₁ = {:.12e} against e^(√(g/l) T) = {:.12e}",
        f.multipliers[0].re,
        growth.exp()
    );
    for (mu, exact) in f.multipliers.iter().zip([growth.exp(), (-growth).exp()]) {
        assert!(
            mu.im.abs() < 1e-12 && (mu.re - exact).abs() < 1e-8 * exact,
            "{mu} vs {exact}"
        );
    }
    assert!((f.exponents[0].re - (g / l).sqrt()).abs() < 1e-8);
    assert_eq!(f.stability, FloquetStability::Unstable);
}

/// Largest `|θ|` (rad) of the nonlinear `mathieu_pendulum` released at rest from `θ₀` near
/// upright, over `t_end` seconds (DOP853 at 1e-10, every step recorded).
fn largest_angle(set: &[(&str, f64)], theta0: f64, t_end: f64) -> f64 {
    let mut m = model("mathieu_pendulum");
    for (name, value) in set {
        m.set_parameter(name, *value).unwrap();
    }
    let options = IntegratorOptions::default()
        .with_rtol(1e-10)
        .with_atol(1e-10);
    let solution = DormandPrince853::new()
        .integrate(
            m.as_ode_mut(),
            0.0,
            &[theta0, 0.0],
            t_end,
            &OutputTimes::Steps,
            &options,
        )
        .unwrap();
    solution.iter().map(|(_, y)| y[0].abs()).fold(0.0, f64::max)
}

/// Kapitza's pendulum: with `a = 0.1 l`, `w = 60` rad/s (`a w = 6` against `√(2gl) = 4.47`,
/// `q = 0.2`, well inside the band) the multipliers lie on the unit circle, and the nonlinear
/// pendulum released 0.1 rad from upright stays within 0.2 rad over 10 s (about 95 forcing
/// periods and 4 slow oscillations at `Ω = √(a²w²/2l² − g/l) = 2.83` rad/s; averaging
/// predicts an amplitude of 0.1 rad plus a fast jitter of about `(a/l) θ = 0.01`). Without
/// shaking, or shaken below Kapitza's condition (`w = 30`, `a w = 3`), Floquet says unstable
/// and the pendulum falls past 1 rad within 10 s.
#[test]
fn kapitza_region_is_stable_and_confirmed_by_simulation() {
    let inside = pendulum_floquet(&[]);
    assert!(inside.stability.is_stable(), "{:?}", inside.multipliers);
    assert!((inside.spectral_radius - 1.0).abs() < 1e-9);
    let theta = largest_angle(&[], 0.1, 10.0);
    eprintln!(
        "a = 0.1, w = 60: μ = {:.10}, slow frequency Im ln(μ)/T = {:.6} rad/s (Kapitza √8 = {:.6}); largest |θ| over 10 s = {theta:.4} rad",
        inside.multipliers[0],
        inside.exponents[0].im,
        8f64.sqrt()
    );
    assert!(
        theta < 0.2,
        "inside Kapitza's region the pendulum reached {theta} rad"
    );

    for set in [[("a", 0.0)], [("w", 30.0)]] {
        let f = pendulum_floquet(&set);
        assert_eq!(f.stability, FloquetStability::Unstable, "{set:?}");
        let theta = largest_angle(&set, 0.1, 10.0);
        eprintln!(
            "{set:?}: ρ = {:.6}, largest |θ| over 10 s = {theta:.3} rad",
            f.spectral_radius
        );
        assert!(
            theta > 1.0,
            "{set:?}: the pendulum stayed within {theta} rad"
        );
    }
}

/// The stability boundary at small amplitude, by bisection on `w` with the Floquet
/// classification, against
/// - the exact edge `δ = a₀(q)` of the Mathieu chart from its series (Abramowitz & Stegun
///   20.2.25, terms to `q⁸`; truncation below 1e-13 at `q ≤ 0.1`), to 1e-8 relative — the
///   bisection is converged to 1e-12 and the classification near a double multiplier is
///   blurred only over a parameter range of order (1e-6)²;
/// - Kapitza's averaging condition `a w = √(2 g l)`, which the series shows to be right to
///   relative order `(a/l)²`: `a w_c = √(2gl) (1 + (7/32)(a/l)² + O((a/l)⁴))`. Checked: the
///   relative difference is `(7/32)(a/l)²` within 1 %.
#[test]
fn stability_boundary_at_small_amplitude_agrees_with_kapitza() {
    let (g, l): (f64, f64) = (10.0, 1.0);
    let kapitza = (2.0 * g * l).sqrt();
    for a in [0.02, 0.05] {
        let stable = |w: f64| {
            pendulum_floquet(&[("a", a), ("w", w)])
                .stability
                .is_stable()
        };
        let (mut lo, mut hi) = (0.9 * kapitza / a, 1.1 * kapitza / a);
        assert!(
            !stable(lo) && stable(hi),
            "a = {a}: no boundary in [{lo}, {hi}]"
        );
        while hi - lo > 1e-12 * hi {
            let mid = 0.5 * (lo + hi);
            if stable(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let w_c = 0.5 * (lo + hi);
        // δ = −4g/(l w²) = a₀(q), q = 2a/l.
        let q: f64 = 2.0 * a / l;
        let a0 = -q.powi(2) / 2.0 + 7.0 * q.powi(4) / 128.0 - 29.0 * q.powi(6) / 2304.0
            + 68_687.0 * q.powi(8) / 18_874_368.0;
        let w_series = (-4.0 * g / (l * a0)).sqrt();
        assert!(
            (w_c - w_series).abs() < 1e-8 * w_series,
            "a = {a}: Floquet boundary w = {w_c}, series {w_series}"
        );
        let relative = a * w_c / kapitza - 1.0;
        let predicted = 7.0 / 32.0 * (a / l).powi(2);
        eprintln!(
            "a = {a}: Floquet w_c = {w_c:.12}, series a₀ {w_series:.12}, Kapitza {:.12}; a w_c/√(2gl) − 1 = {relative:.6e} against (7/32)(a/l)² = {predicted:.6e}",
            kapitza / a
        );
        assert!(
            (relative - predicted).abs() < 0.01 * predicted,
            "a = {a}: a w_c/√(2gl) − 1 = {relative:e}, averaging correction {predicted:e}"
        );
    }
}

/// Inside the band the multipliers are `e^{±iνπ}`, with `ν` the characteristic exponent of the
/// Mathieu equation in `τ = w t/2`, so the slow oscillation has `Ω = Im ln(μ)/T = ν w/2`.
/// Against `ν` from the series `δ = ν² + q²/(2(ν²−1)) + (5ν²+7)q⁴/(32(ν²−1)³(ν²−4)) +
/// (9ν⁴+58ν²+29)q⁶/(64(ν²−1)⁵(ν²−4)(ν²−9))` (DLMF 28.15.1), solved for `ν²` by bisection:
/// agreement to 1e-5 relative (the omitted `q⁸` term is of order 1e-7 in `δ` at `q = 0.2`).
/// Kapitza's averaging keeps only `δ = ν² − q²/2`, `Ω = √(a²w²/(2l²) − g/l)`, and is off
/// by a relative `O((a/l)²)` (0.5 % at `a = 0.1 l`).
#[test]
fn slow_frequency_matches_the_mathieu_characteristic_exponent() {
    let (g, l): (f64, f64) = (10.0, 1.0);
    for (a, w) in [(0.1, 60.0), (0.05, 150.0)] {
        let f = pendulum_floquet(&[("a", a), ("w", w)]);
        let omega = f.exponents[0].im;
        let (delta, q) = (-4.0 * g / (l * w * w), 2.0 * a / l);
        let series = |x: f64| {
            x + q.powi(2) / (2.0 * (x - 1.0))
                + (5.0 * x + 7.0) * q.powi(4) / (32.0 * (x - 1.0).powi(3) * (x - 4.0))
                + (9.0 * x * x + 58.0 * x + 29.0) * q.powi(6)
                    / (64.0 * (x - 1.0).powi(5) * (x - 4.0) * (x - 9.0))
        };
        let (mut lo, mut hi) = (0.0, 0.5);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if series(mid) < delta {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let omega_series = (0.5 * (lo + hi)).sqrt() * w / 2.0;
        let omega_kapitza = (a * a * w * w / (2.0 * l * l) - g / l).sqrt();
        eprintln!(
            "a = {a}, w = {w}: Ω = {omega:.9} rad/s, DLMF 28.15.1 series {omega_series:.9}, Kapitza {omega_kapitza:.9}"
        );
        assert!(
            (omega - omega_series).abs() < 1e-5 * omega_series,
            "Ω = {omega}, series {omega_series}"
        );
        let off = (omega / omega_kapitza - 1.0).abs();
        assert!(off < (a / l).powi(2), "Kapitza is off by {off:e}");
    }
}

/// Hanging, the pendulum shaken at twice its natural frequency `2√(g/l)` is in the first
/// parametric-resonance tongue (`δ = 1` lies between `b₁(q)` and `a₁(q)` for `q = 2a/l =
/// 0.1`), and unstable; far from resonance (`w = 3√(g/l)`) it is stable. The equilibrium
/// check refuses a point that is not at rest for all `t`.
#[test]
fn hanging_parametric_resonance_and_bad_operating_points() {
    let mut m = model("mathieu_pendulum");
    m.set_parameter("a", 0.05).unwrap();
    for (w, unstable) in [(2.0 * 10f64.sqrt(), true), (3.0 * 10f64.sqrt(), false)] {
        m.set_parameter("w", w).unwrap();
        let f = floquet_analysis(
            m.as_ode_mut(),
            &[std::f64::consts::PI, 0.0],
            0.0,
            TAU / w,
            &FloquetOptions::default(),
        )
        .unwrap();
        assert_eq!(
            f.stability == FloquetStability::Unstable,
            unstable,
            "w = {w}: {:?}",
            f.multipliers
        );
    }
    // θ = 0.3 at rest is no equilibrium: F = m l (g − a w² cos wt) sin 0.3 ≠ 0.
    assert!(matches!(
        check_periodic_equilibrium(m.as_ref(), &[0.3], 0.0, 1.0),
        Err(FloquetError::NotAnEquilibrium { .. })
    ));
    // The forced oscillator's static deflection under A cos(w t) at t = 0 moves with t.
    let forced = model("forced_oscillator");
    let q = find_equilibrium(forced.as_ref(), &[0.0], 0.0).unwrap().q;
    assert!(matches!(
        check_periodic_equilibrium(forced.as_ref(), &q, 0.0, TAU / 0.8),
        Err(FloquetError::NotAnEquilibrium { .. })
    ));
    assert!(matches!(
        floquet_analysis(
            m.as_ode_mut(),
            &[0.0, 0.0],
            0.0,
            -1.0,
            &FloquetOptions::default()
        ),
        Err(FloquetError::InvalidPeriod { .. })
    ));
    assert!(matches!(
        floquet_analysis(m.as_ode_mut(), &[0.0], 0.0, 1.0, &FloquetOptions::default()),
        Err(FloquetError::DimensionMismatch {
            expected: 2,
            found: 1
        })
    ));
}

/// The library's study (what `eomgen study floquet` prints): at `upright` with the defaults
/// (Kapitza's region) the multipliers lie on the unit circle (marginal, 1e-6); chart cells
/// without shaking (`a = 0`) have ρ = e^{√(g/l) T} at every `w` (1e-8 relative, DOP853 at
/// 1e-12); typed errors for a missing period parameter, bad tolerances, an unknown swept
/// parameter and an operating point that moves with `t`.
#[test]
fn floquet_study_point_and_cells() {
    use eomgen::analysis::vibration::{
        EquilibriumStart, FloquetStudyError, FloquetStudyOptions, SweepAxis,
        floquet_at_equilibrium, floquet_cell,
    };
    let mut m = model("mathieu_pendulum");
    let options = FloquetStudyOptions::default();
    let point = floquet_at_equilibrium(m.as_mut(), &options).unwrap();
    assert_eq!(point.name, "upright");
    assert_eq!(point.floquet.stability, FloquetStability::Marginal);
    assert!((point.floquet.spectral_radius - 1.0).abs() < 1e-6);
    assert_eq!(point.frequency, 60.0);
    let (_, guess) = EquilibriumStart::Named("upright".into())
        .resolve(m.as_ref())
        .unwrap();
    let w_axis = SweepAxis::linear("w", 30.0, 60.0, 2).unwrap();
    assert_eq!(w_axis.values, [30.0, 60.0]);
    for &w in &w_axis.values {
        let mut fresh = model("mathieu_pendulum");
        let cell = floquet_cell(fresh.as_mut(), &guess, &[("a", 0.0), ("w", w)], &options).unwrap();
        let exact = (10f64.sqrt() * TAU / w).exp();
        assert!(
            (cell.spectral_radius - exact).abs() < 1e-8 * exact,
            "{} vs {exact}",
            cell.spectral_radius
        );
        assert_eq!(cell.stability, FloquetStability::Unstable);
    }
    assert!(SweepAxis::linear("a", 0.3, 0.1, 3).is_err());
    let err = floquet_cell(m.as_mut(), &guess, &[("zz", 1.0)], &options).unwrap_err();
    assert!(matches!(err, FloquetStudyError::Parameter(_)), "{err}");
    let mut pendulum = model("simple_pendulum");
    let err = floquet_at_equilibrium(pendulum.as_mut(), &options).unwrap_err();
    assert!(
        matches!(err, FloquetStudyError::UnknownPeriodParameter { .. }),
        "{err}"
    );
    let mut bad = options.clone();
    bad.floquet.rtol = 0.0;
    let err = floquet_at_equilibrium(m.as_mut(), &bad).unwrap_err();
    assert!(
        matches!(err, FloquetStudyError::InvalidTolerance { .. }),
        "{err}"
    );
    let mut forced = model("forced_oscillator");
    let err = floquet_at_equilibrium(forced.as_mut(), &options).unwrap_err();
    assert!(
        matches!(
            err,
            FloquetStudyError::Floquet(FloquetError::NotAnEquilibrium { .. })
        ),
        "{err}"
    );
}

/// `eomgen study floquet --json --sweep --plot`: the documented keys, a grid of the right
/// shape with the unshaken column unstable, and the chart file; clear errors (exit codes) for
/// a model without the period parameter and for an operating point that moves with `t`.
#[test]
fn cli_study_floquet_json_and_chart() {
    let dir = std::env::temp_dir().join(format!("eomgen-floquet-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let chart = dir.join("chart.svg");
    let out = eomgen_ok(&[
        "study",
        "floquet",
        "mathieu_pendulum",
        "--at",
        "upright",
        "--json",
        "--sweep",
        "a=0..0.2:3,w=30..60:2",
        "--plot",
        chart.to_str().unwrap(),
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "model",
        "operating_point",
        "period",
        "monodromy_matrix",
        "multipliers",
        "exponents",
        "spectral_radius",
        "determinant",
        "stability",
        "stable",
        "kapitza",
        "sweep",
    ] {
        assert!(v.get(key).is_some(), "missing `{key}` in {v}");
    }
    assert_eq!(v["model"], "mathieu_pendulum");
    assert!((v["period"].as_f64().unwrap() - TAU / 60.0).abs() < 1e-15);
    assert_eq!(v["multipliers"].as_array().unwrap().len(), 2);
    assert_eq!(v["stable"], true);
    let rho = v["sweep"]["spectral_radius"].as_array().unwrap();
    assert_eq!(rho.len(), 3);
    assert_eq!(rho[0].as_array().unwrap().len(), 2);
    for j in 0..2 {
        assert!(rho[0][j].is_f64());
        assert_eq!(v["sweep"]["stability"][0][j], "unstable");
    }
    let svg = std::fs::read_to_string(&chart).unwrap();
    assert!(svg.contains("<svg") && svg.contains("Kapitza"));

    let out = eomgen(&["study", "floquet", "simple_pendulum"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no parameter `w`"));
    let out = eomgen(&["study", "floquet", "forced_oscillator"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not an equilibrium for all t"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The upper edge of the stable band: at `w = 400` rad/s (`δ = −2.5e-4`) shaking harder than
/// `a ≈ 0.454 l` destabilises upright again; the Floquet edge (bisection on `a`) against the
/// root of `δ = b₁(q)` from the series of Abramowitz & Stegun 20.2.25 (truncated after `q⁵`;
/// the next term is of order `q⁶/10⁵`, so 1e-4 in `a`).
#[test]
fn upper_edge_of_the_stable_band() {
    let w = 400.0;
    let stable = |a: f64| {
        pendulum_floquet(&[("a", a), ("w", w)])
            .stability
            .is_stable()
    };
    let (mut lo, mut hi) = (0.3, 0.6);
    assert!(stable(lo) && !stable(hi));
    while hi - lo > 1e-9 {
        let mid = 0.5 * (lo + hi);
        if stable(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // δ = −4g/(l w²) = b₁(q): solve the series for q by bisection too.
    let delta = -4.0 * 10.0 / 400.0f64.powi(2);
    let b1 = |q: f64| {
        1.0 - q - q * q / 8.0 + q.powi(3) / 64.0 - q.powi(4) / 1536.0 - 11.0 * q.powi(5) / 36_864.0
    };
    let (mut qa, mut qb) = (0.5, 1.2);
    for _ in 0..60 {
        let mid = 0.5 * (qa + qb);
        if b1(mid) > delta {
            qa = mid;
        } else {
            qb = mid;
        }
    }
    let a_series = 0.5 * (qa + qb) / 2.0;
    eprintln!("upper edge at w = 400: Floquet a = {lo:.8}, b₁ series a = {a_series:.8}");
    // The b₁ series is truncated at q⁵: its next term is of order q⁶/10⁵ ≈ 1e-5.
    assert!(
        (lo - a_series).abs() < 1e-4,
        "Floquet {lo}, series {a_series}"
    );
}

/// The Mathieu pendulum file's `floquet:` references, evaluated by the library, against the
/// formulas written here: Kapitza's threshold `a w > √(2 g l)` and curve `w = √(2 g l)/a`,
/// and the A&S 20.2.25 series edges `δ = a₀(q)`, `b₁(q)` (upright, `δ = −4g/(l w²)`) and
/// `b₁(q)`, `a₁(q)` (hanging, `δ = 4g/(l w²)`) with `q = 2a/l`, each point to 1e-12
/// relative; points stay inside the chart, and the upper edge stops at `q = 1.5`.
#[test]
fn mathieu_pendulum_references_from_its_file() {
    use eomgen::{ChartAxis, FloquetReferences, ModelSource};
    let source = ModelSource::open("mathieu_pendulum").unwrap();
    let model = source.instantiate();
    let (g, l) = (10.0f64, 1.0f64);
    let upright = FloquetReferences::of(model.description(), "upright")
        .unwrap()
        .unwrap();
    assert_eq!(upright.axis_unit("a"), Some("m"));
    assert_eq!(upright.axis_unit("w"), None);
    let t = &upright.thresholds(model.as_ref())[0];
    assert_eq!((t.name.as_str(), t.key.as_str()), ("kapitza", "a_w"));
    assert_eq!(t.value, 0.1 * 60.0);
    assert_eq!(t.critical, (2.0 * g * l).sqrt());
    assert!(t.predicts_stable);
    let a0 = |q: f64| {
        let q2 = q * q;
        -q2 / 2.0 + 7.0 * q2 * q2 / 128.0 - 29.0 * q2 * q2 * q2 / 2304.0
            + 68_687.0 * q2.powi(4) / 18_874_368.0
    };
    let a1 = |q: f64| {
        1.0 + q - q * q / 8.0 - q.powi(3) / 64.0 - q.powi(4) / 1536.0 + 11.0 * q.powi(5) / 36_864.0
    };
    let b1 = |q: f64| {
        1.0 - q - q * q / 8.0 + q.powi(3) / 64.0 - q.powi(4) / 1536.0 - 11.0 * q.powi(5) / 36_864.0
    };
    let w_of = move |sign: f64, delta: f64| (sign * 4.0 * g / (l * delta)).sqrt();
    let (x, y) = (
        ChartAxis {
            name: "a",
            lo: 0.0,
            hi: 1.0,
        },
        ChartAxis {
            name: "w",
            lo: 1.0,
            hi: 500.0,
        },
    );
    let curves = upright.curves(model.as_ref(), x, y);
    assert_eq!(curves.len(), 3);
    type Exact = Box<dyn Fn(f64) -> f64>;
    let exact: [Exact; 3] = [
        Box::new(move |a| (2.0 * g * l).sqrt() / a),
        Box::new(move |a| w_of(-1.0, a0(2.0 * a / l))),
        Box::new(move |a| w_of(-1.0, b1(2.0 * a / l))),
    ];
    for (curve, f) in curves.iter().zip(&exact) {
        assert!(curve.points.len() > 10, "{}", curve.label);
        for &(a, w) in &curve.points {
            assert!((w - f(a)).abs() <= 1e-12 * w, "{}: a = {a}", curve.label);
            assert!(a > 0.0 && a <= 1.0 && (1.0..=500.0).contains(&w));
        }
    }
    assert!(curves[2].points.iter().all(|(a, _)| 2.0 * a / l <= 1.5));
    // Axes swapped: the same curve with x and y exchanged.
    let swapped = upright.curves(model.as_ref(), y, x);
    assert_eq!(
        swapped[0].points[0],
        (curves[0].points[0].1, curves[0].points[0].0)
    );
    // Other axes: no curve.
    let other = ChartAxis {
        name: "l",
        lo: 0.5,
        hi: 2.0,
    };
    assert!(upright.curves(model.as_ref(), other, y).is_empty());

    let hanging = FloquetReferences::of(model.description(), "hanging")
        .unwrap()
        .unwrap();
    assert!(hanging.thresholds(model.as_ref()).is_empty());
    let curves = hanging.curves(model.as_ref(), x, y);
    assert_eq!(curves.len(), 2);
    for (curve, f) in curves.iter().zip([b1, a1]) {
        assert!(curve.points.len() > 10, "{}", curve.label);
        for &(a, w) in &curve.points {
            let expected = w_of(1.0, f(2.0 * a / l));
            assert!(
                (w - expected).abs() <= 1e-12 * w,
                "{}: a = {a}",
                curve.label
            );
        }
    }
    assert!(
        FloquetReferences::of(model.description(), "sideways")
            .unwrap()
            .is_none()
    );
}

/// The period parameter is checked to be the forcing frequency: a model whose equations do
/// not depend on `t` (the double pendulum, "period" g) is refused at the user's parameters;
/// naming a parameter that is not the frequency (the Mathieu pendulum's `m`, or `a`) is
/// refused because `M`, `F` are not `2π/m`-periodic, even where `m` happens to equal `w`
/// (the check is repeated at a value 1/64 above); its `w`, whose forcing amplitude `a w²`
/// depends on `w` too (so `F` is not a function of `w t` alone), passes. These runs used to
/// report "marginal" or "unstable" multipliers of a wrong period.
#[test]
fn floquet_period_parameter_must_be_the_forcing_frequency() {
    use eomgen::analysis::vibration::{
        FloquetStudyError, FloquetStudyOptions, floquet_at_equilibrium,
    };
    let named = |p: &str| FloquetStudyOptions {
        period_parameter: p.to_string(),
        ..FloquetStudyOptions::default()
    };
    let mut pendulum = model("double_pendulum");
    let err = floquet_at_equilibrium(pendulum.as_mut(), &named("g")).unwrap_err();
    assert!(
        matches!(err, FloquetStudyError::TimeIndependent { .. }),
        "{err}"
    );
    for (set, name) in [(None, "m"), (Some(60.0), "m"), (None, "a")] {
        let mut m = model("mathieu_pendulum");
        if let Some(v) = set {
            m.set_parameter(name, v).unwrap();
        }
        let err = floquet_at_equilibrium(m.as_mut(), &named(name)).unwrap_err();
        assert!(
            matches!(err, FloquetStudyError::NotPeriodic { .. }),
            "{name}: {err}"
        );
        assert_eq!(
            parameter(m.as_ref(), name),
            set.unwrap_or(if name == "m" { 1.0 } else { 0.1 }),
            "the parameter is restored"
        );
    }
    let mut m = model("mathieu_pendulum");
    assert!(floquet_at_equilibrium(m.as_mut(), &named("w")).is_ok());
    assert_eq!(parameter(m.as_ref(), "w"), 60.0);
    // Without shaking the Mathieu pendulum does not depend on t: refused as a point, but a
    // chart's a = 0 cell is analysed (checked in `floquet_study_point_and_cells`).
    m.set_parameter("a", 0.0).unwrap();
    let err = floquet_at_equilibrium(m.as_mut(), &named("w")).unwrap_err();
    assert!(
        matches!(err, FloquetStudyError::TimeIndependent { .. }),
        "{err}"
    );
}

/// Issue 28: the tolerance on `|μ| = 1` had no range: `--stability-tolerance 1e9` called
/// ρ = 1.64 "marginal", and 0 called a conservative system (multipliers on the unit circle
/// only to the integration error) "asymptotically stable". It must lie in
/// `[√max(rtol, atol), 0.1]` (`FloquetOptions::validate`): in the library a typed error, in
/// the CLI a usage error (status 2); the ends of the range are accepted.
#[test]
fn issue_28_stability_tolerance_has_a_meaningful_range() {
    let mut pendulum = model("mathieu_pendulum");
    let options =
        |stability_tolerance: f64, tol: f64| eomgen::analysis::vibration::FloquetStudyOptions {
            floquet: FloquetOptions {
                rtol: tol,
                atol: tol,
                stability_tolerance,
                ..FloquetOptions::default()
            },
            ..Default::default()
        };
    for (st, tol) in [
        (1e9, 1e-12),
        (0.0, 1e-12),
        (1e-7, 1e-12),
        (0.2, 1e-12),
        (1e-4, 1e-6),
    ] {
        let refused = eomgen::analysis::vibration::floquet_at_equilibrium(
            pendulum.as_mut(),
            &options(st, tol),
        );
        assert!(
            matches!(
                refused,
                Err(eomgen::analysis::vibration::FloquetStudyError::Floquet(
                    FloquetError::InvalidStabilityTolerance { .. }
                ))
            ),
            "{st} at tol {tol}: {refused:?}"
        );
    }
    for (st, tol) in [(1e-6, 1e-12), (0.1, 1e-12), (1e-3, 1e-6)] {
        let point = eomgen::analysis::vibration::floquet_at_equilibrium(
            pendulum.as_mut(),
            &options(st, tol),
        )
        .unwrap_or_else(|e| panic!("{st} at tol {tol}: {e}"));
        // Upright and shaken at the file's a, w: stable, on the unit circle.
        assert_eq!(point.floquet.stability, FloquetStability::Marginal, "{st}");
    }
    for st in ["1e9", "0", "1e-7", "0.5"] {
        let out = eomgen(&[
            "study",
            "floquet",
            "mathieu_pendulum",
            "--stability-tolerance",
            st,
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{st}: {err}");
        assert!(
            err.contains(
                "--stability-tolerance: the stability tolerance must be in [1.000e-6, 0.1]"
            ),
            "{st}: {err}"
        );
    }
}

/// Issue 28: a `--sweep` was refused when the model did not depend on t at the parameters'
/// own values (the Mathieu pendulum with `a = 0`), although the swept values do. The time
/// dependence is now checked at the swept values (the grid's corners, side middles and
/// centre): the chart is drawn, the point at the own values analysed as a cell and marked as
/// independent of t; a sweep none of whose values makes the model depend on t is still
/// refused. A chart every cell of which failed measured nothing.
#[test]
fn issue_28_floquet_sweep_checks_time_dependence_at_the_swept_values() {
    let out = eomgen_ok(&[
        "study",
        "floquet",
        "mathieu_pendulum",
        "--set",
        "a=0",
        "--sweep",
        "a=0..0.3:4,w=40..60:3",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["time_dependent"], false, "{v}");
    // Unshaken upright: unstable (ρ = e^{√(g/l) T}); shaken at a = 0.3, w ≥ 40: stable.
    assert_eq!(v["stability"], "unstable");
    let sweep = &v["sweep"];
    assert_eq!(sweep["failures"].as_array().unwrap().len(), 0, "{sweep}");
    assert_eq!(sweep["stability"][3][2], "marginal", "{sweep}");
    assert_eq!(sweep["stability"][0][0], "unstable", "{sweep}");

    let out = eomgen(&[
        "study",
        "floquet",
        "mathieu_pendulum",
        "--set",
        "a=0",
        "--sweep",
        "g=9..10:2,w=40..60:3",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("does not depend on t"), "{err}");

    use eomgen::analysis::StudyRuns;
    use eomgen::analysis::vibration::{FloquetChart, SweepAxis};
    let chart = FloquetChart {
        x: SweepAxis::linear("a", 0.0, 0.1, 2).unwrap(),
        y: SweepAxis::linear("w", 40.0, 40.0, 1).unwrap(),
        cells: vec![vec![Err("no equilibrium".to_string())]; 2],
    };
    let nothing = chart.check_measured().expect_err("measured nothing");
    assert_eq!(nothing.failed, 2);
    assert_eq!(nothing.first_failure, "a = 0, w = 40: no equilibrium");
}
