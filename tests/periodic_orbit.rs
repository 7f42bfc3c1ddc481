//! Periodic orbits by shooting (HW5, HW39; `eomgen study periodic-orbit`): the figure eight
//! from a perturbed start against Simó's period and the choreography, a Kepler circle and
//! Kepler's third law, a closed rosette of a non-Kepler central force against an independent
//! quadrature of the apsidal angle and the radial period, the pendulum against its elliptic
//! integral, the multipliers 1 each symmetry brings, the errors and the CLI.

use crate::common;
use common::{eomgen, seeded_rng};

use std::f64::consts::{PI, TAU};

use eomgen::analysis::{PeriodicOrbit, PeriodicOrbitError, PeriodicOrbitOptions, periodic_orbit};
use eomgen::{DormandPrince853, Integrator, IntegratorOptions, ModelInfo, OutputTimes};
use rand::RngExt;

fn model(name: &str) -> Box<dyn ModelInfo> {
    (eomgen::models::find(name).expect("bundled model").make)()
}

/// Simó's period of the figure eight (the model file's reference).
const SIMO_PERIOD: f64 = 6.325_913_98;

/// `max |φ_T(y₀) − y₀|` by a plain DOP853 run at 1e-13 (no variational equations): an
/// independent check that the orbit closes.
fn closure(model: &mut dyn ModelInfo, y0: &[f64], period: f64) -> f64 {
    let options = IntegratorOptions::default()
        .with_rtol(1e-13)
        .with_atol(1e-13);
    let solution = DormandPrince853::new()
        .integrate(
            model.as_ode_mut(),
            0.0,
            y0,
            period,
            &OutputTimes::At(vec![period]),
            &options,
        )
        .unwrap();
    let (_, end) = solution.last().unwrap();
    end.iter()
        .zip(y0)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// The figure eight from the model's initial state with every component moved by up to
/// ±1e-3 (which also gives the three bodies a net momentum), at the energy of the model's
/// initial state: Newton finds the eight again.
///
/// - The period agrees with Simó's 6.32591398 to 5e-8 (8 significant digits): the model's
///   initial state has 8 decimals, so its energy, which fixes the orbit's size and period
///   (`T ∝ |E|^{-3/2}`), is known to about 1e-8, i.e. `T` to about 1.5e-8 relative.
/// - The orbit closes in an independent integration to 1e-9 (Newton's tolerance 1e-10
///   relative; the two integrations differ by their ~1e-11 errors), with zero linear and
///   angular momentum to 1e-9 (both must vanish on the eight: a net momentum would carry it
///   away, and the eight has L = 0).
/// - It is a choreography: after T/3 each body is where the next one started (to 1e-8, the
///   sampling's integration error).
/// - The multipliers: 8 of them 1 (time shift/energy, two translations/linear momenta,
///   rotation/angular momentum) and three symmetries dropped (two translations, a rotation);
///   the other 4 on the unit circle to 1e-6: the eight is linearly stable (Simó 2002). (The
///   unit multipliers form Jordan blocks, which the integration error splits by its square
///   root, ~1e-5.)
#[test]
fn figure_eight_from_a_perturbed_start() {
    let mut m = model("figure_eight");
    let initial = m.initial_state();
    let energy = m.energy(0.0, &initial);
    let mut rng = seeded_rng(39);
    let start: Vec<f64> = initial
        .iter()
        .map(|v| v + rng.random_range(-1e-3..1e-3))
        .collect();
    let orbit = periodic_orbit(
        m.as_mut(),
        &PeriodicOrbitOptions {
            start: Some(start),
            energy: Some(energy),
            ..PeriodicOrbitOptions::new(6.3)
        },
    )
    .unwrap();
    assert!(
        (orbit.period - SIMO_PERIOD).abs() < 5e-8,
        "T = {}",
        orbit.period
    );
    assert!(orbit.iterations <= 10, "{} iterations", orbit.iterations);
    let y0 = &orbit.initial_state;
    assert!(closure(m.as_mut(), y0, orbit.period) < 1e-9);
    assert!((m.energy(0.0, y0) - energy).abs() < 1e-10);
    let momentum = [y0[6] + y0[8] + y0[10], y0[7] + y0[9] + y0[11]];
    let angular: f64 = (0..3)
        .map(|i| y0[2 * i] * y0[7 + 2 * i] - y0[2 * i + 1] * y0[6 + 2 * i])
        .sum();
    assert!(momentum.iter().all(|p| p.abs() < 1e-9), "{momentum:?}");
    assert!(angular.abs() < 1e-9, "L = {angular}");
    choreography(&orbit);
    assert_eq!(orbit.unit_multipliers, 8, "{:?}", orbit.multipliers);
    assert_eq!(orbit.symmetries, 3);
    let others = orbit
        .multipliers
        .iter()
        .filter(|mu| (*mu - 1.0).norm() > orbit.unit_multiplier_tolerance);
    for mu in others {
        assert!((mu.norm() - 1.0).abs() < 1e-6, "|μ| = {}", mu.norm());
    }
}

/// After a third of the period each body of the eight is at another's starting point.
fn choreography(orbit: &PeriodicOrbit) {
    let samples = orbit.orbit.t.len();
    assert_eq!((samples - 1) % 3, 0, "T/3 must be a sample");
    let third = &orbit.orbit.points[(samples - 1) / 3];
    let first = &orbit.orbit.points[0];
    for p in third {
        let nearest = first
            .iter()
            .map(|q| (p[0] - q[0]).hypot(p[1] - q[1]))
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest < 1e-8,
            "no body where this one is after T/3: {nearest}"
        );
    }
    // And not the same body: the three positions at T/3 are the three at 0, permuted.
    assert!((third[0][0] - first[0][0]).abs() > 0.1);
}

/// With the period fixed at Simó's value, the energy is free: Newton from a perturbed start
/// finds the eight with the energy of the model's data to 1e-7 (the period given has 8
/// decimals; `δE/E = (2/3) δT/T`).
#[test]
fn figure_eight_with_the_period_fixed() {
    let mut m = model("figure_eight");
    let initial = m.initial_state();
    let energy = m.energy(0.0, &initial);
    let start: Vec<f64> = initial
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-3 * (0.7 * i as f64).sin())
        .collect();
    let orbit = periodic_orbit(
        m.as_mut(),
        &PeriodicOrbitOptions {
            start: Some(start),
            fix_period: true,
            ..PeriodicOrbitOptions::new(SIMO_PERIOD)
        },
    )
    .unwrap();
    assert_eq!(orbit.period, SIMO_PERIOD);
    assert_eq!(orbit.energy_level, None);
    assert!((orbit.energy - energy).abs() < 1e-7, "E = {}", orbit.energy);
    assert!(closure(m.as_mut(), &orbit.initial_state, orbit.period) < 1e-9);
}

/// The figure eight from the model's own data (within 1e-7 of the orbit) and from that data
/// moved by up to ±1e-6: Gauss–Newton must converge, and quadratically, from starts this close
/// (a regression: the first residual used to be evaluated at the loosest integration
/// tolerance, 1e-8, where the data's residual 7.5e-8 reads 3.7e-8, half of it integration
/// error; the step computed from it, and the damped steps compared with it, failed).
///
/// - The residual reported at the start is the data's own, `‖φ_T(y₀) − y₀‖` from an
///   independent plain DOP853 run at 1e-13, to 1e-9 (1 % of it; both integrations err by
///   ~1e-11), not the loose integration's.
/// - The data converges in one step (7.5e-8 to ~5e-12: the square of the residual is below
///   the integration's error), the 1e-6 start in at most two; both end below Newton's
///   allowed residual `tol (1 + ‖y₀‖)`, and close in the independent run to 1e-9.
/// - The two periods agree to 1e-8 (two Newton paths to one orbit at one energy; Newton's
///   tolerance 1e-10 on the state over `‖f‖ ≈ 1.6` bounds each period's error by about
///   1e-10), and with Simó's 6.32591398 to 5e-8 (the data's 8 decimals fix the energy, and
///   with it the period, to about 3e-8: the period at the data's energy is 6.3259140114).
/// - With the period fixed at Simó's value, the data also converges in one step.
/// - The sampled orbit ends at `T` itself (the last sample time used to round past it).
#[test]
fn figure_eight_from_its_own_data_and_a_start_within_1e_6() {
    let mut m = model("figure_eight");
    let initial = m.initial_state();
    let energy = m.energy(0.0, &initial);
    let solve = |m: &mut dyn ModelInfo, start: Vec<f64>, fix_period: bool| {
        periodic_orbit(
            m,
            &PeriodicOrbitOptions {
                start: Some(start),
                energy: Some(energy),
                fix_period,
                ..PeriodicOrbitOptions::new(SIMO_PERIOD)
            },
        )
        .unwrap_or_else(|e| panic!("{e}"))
    };
    let allowed = |orbit: &PeriodicOrbit| 1e-10 * (1.0 + norm(&orbit.initial_state));

    let data_closure = closure_norm(m.as_mut(), &initial, SIMO_PERIOD);
    let own = solve(m.as_mut(), initial.clone(), false);
    assert!(
        (own.history[0].residual - data_closure).abs() < 1e-9,
        "start residual {} against an independent {data_closure}",
        own.history[0].residual
    );
    assert!(data_closure > 1e-8, "the data is not exactly periodic");
    assert_eq!(own.iterations, 1, "{:?}", own.history);
    assert!(own.residual < allowed(&own), "residual {}", own.residual);
    assert!(closure(m.as_mut(), &own.initial_state, own.period) < 1e-9);
    assert_eq!(*own.orbit.t.last().unwrap(), own.period);

    let mut rng = seeded_rng(6);
    let near: Vec<f64> = initial
        .iter()
        .map(|v| v + rng.random_range(-1e-6..1e-6))
        .collect();
    let close = solve(m.as_mut(), near, false);
    assert!(close.iterations <= 2, "{:?}", close.history);
    assert!(
        close.residual < allowed(&close),
        "residual {}",
        close.residual
    );
    assert!(closure(m.as_mut(), &close.initial_state, close.period) < 1e-9);

    assert!(
        (own.period - close.period).abs() < 1e-8,
        "T = {} and {}",
        own.period,
        close.period
    );
    for orbit in [&own, &close] {
        assert!(
            (orbit.period - SIMO_PERIOD).abs() < 5e-8,
            "T = {}",
            orbit.period
        );
    }

    let fixed = solve(m.as_mut(), initial, true);
    assert_eq!(fixed.iterations, 1, "{:?}", fixed.history);
    assert!(
        fixed.residual < allowed(&fixed),
        "residual {}",
        fixed.residual
    );
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// `‖φ_T(y₀) − y₀‖₂` by a plain DOP853 run at 1e-13, like [`closure`].
fn closure_norm(model: &mut dyn ModelInfo, y0: &[f64], period: f64) -> f64 {
    let options = IntegratorOptions::default()
        .with_rtol(1e-13)
        .with_atol(1e-13);
    let solution = DormandPrince853::new()
        .integrate(
            model.as_ode_mut(),
            0.0,
            y0,
            period,
            &OutputTimes::At(vec![period]),
            &options,
        )
        .unwrap();
    let (_, end) = solution.last().unwrap();
    norm(&end.iter().zip(y0).map(|(a, b)| a - b).collect::<Vec<f64>>())
}

/// A Kepler circle (lecture 4, HW5): `central_force` at its defaults (μ = 4 m³/s²) started on
/// the circle r = 1.5 m (v0 = √(μ/r)) with a period guess 20 % short. Newton finds Kepler's
/// third law `T = 2π √(r³/μ)` to 1e-9 relative (Newton's tolerance 1e-10 on the state). A
/// Kepler circle is not isolated, though: at one energy every ellipse, of any eccentricity and
/// orientation, has the same period (the hidden symmetry of the Laplace–Runge–Lenz vector), so
/// two directions are dropped (the rotation and the eccentricity) and the minimum-norm steps
/// end on a nearby ellipse of the same semi-major axis a = r (checked from the sampled radii,
/// to the sampling's 1e-5) and small eccentricity. All four multipliers are 1 (time
/// shift/energy, rotation/angular momentum). The same from a start moved by 2e-3.
///
/// For the law n = −1.5 the circle is isolated (nearby orbits are rosettes that do not close)
/// and found exactly, radius constant to 1e-9, with `T = 2πr/v = 2π √(r^{1−n}/μ)` and the
/// multipliers of the radial epicycle `e^{±iκT}`, `κ/ω = √(n + 3)` (Goldstein §3.6), besides
/// the pair 1: rotating a circle is shifting it in time, so the rotation adds neither a pair
/// of unit multipliers nor a dropped direction (the phase condition fixes both at once).
#[test]
fn kepler_circle_and_the_third_law() {
    let mut m = model("central_force");
    let (mu, r) = (4.0, 1.5);
    m.set_parameter("rp", r).unwrap();
    m.set_parameter("v0", (mu / r).sqrt()).unwrap();
    let period = TAU * (r * r * r / mu).sqrt();
    let orbit = periodic_orbit(m.as_mut(), &PeriodicOrbitOptions::new(0.8 * period)).unwrap();
    assert!(
        (orbit.period / period - 1.0).abs() < 1e-9,
        "T = {} against {period}",
        orbit.period
    );
    let radii: Vec<f64> = orbit.orbit.y.iter().map(|y| y[0].hypot(y[1])).collect();
    let (r_min, r_max) = radii.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
        (lo.min(*r), hi.max(*r))
    });
    assert!(
        ((r_min + r_max) / 2.0 - r).abs() < 1e-5,
        "a = {}",
        (r_min + r_max) / 2.0
    );
    assert!(
        (r_max - r_min) / (r_max + r_min) < 0.05,
        "e = {}",
        (r_max - r_min) / (r_max + r_min)
    );
    assert_eq!(orbit.unit_multipliers, 4);
    assert_eq!(orbit.symmetries, 2);

    // From a perturbed start at the circle's energy E = −μ/(2r): an ellipse of semi-major
    // axis a = r, so again T = 2π √(r³/μ) whatever the eccentricity.
    let start = vec![r + 2e-3, 1e-3, 1e-3, (mu / r).sqrt() - 2e-3];
    let energy = m.energy(0.0, &m.initial_state());
    assert!((energy + mu / (2.0 * r)).abs() < 1e-12);
    let orbit = periodic_orbit(
        m.as_mut(),
        &PeriodicOrbitOptions {
            start: Some(start),
            energy: Some(energy),
            ..PeriodicOrbitOptions::new(period)
        },
    )
    .unwrap();
    assert!((orbit.period / period - 1.0).abs() < 1e-9);

    // n = −1.5: the circular speed v² = μ r^{n+1}.
    let n = -1.5f64;
    m.set_parameter("n", n).unwrap();
    m.set_parameter("v0", (mu * r.powf(n + 1.0)).sqrt())
        .unwrap();
    let period = TAU * (r.powf(1.0 - n) / mu).sqrt();
    let orbit = periodic_orbit(m.as_mut(), &PeriodicOrbitOptions::new(0.8 * period)).unwrap();
    assert!(
        (orbit.period / period - 1.0).abs() < 1e-9,
        "T = {}",
        orbit.period
    );
    for y in &orbit.orbit.y {
        assert!(
            (y[0].hypot(y[1]) - r).abs() < 1e-9,
            "r = {}",
            y[0].hypot(y[1])
        );
    }
    assert_eq!(orbit.symmetries, 0);
    assert_eq!(orbit.unit_multipliers, 2);
    let epicycle = (TAU * (n + 3.0).sqrt()).rem_euclid(TAU);
    let pair: Vec<_> = orbit
        .multipliers
        .iter()
        .filter(|mu| (*mu - 1.0).norm() > orbit.unit_multiplier_tolerance)
        .collect();
    assert_eq!(pair.len(), 2);
    for mu in pair {
        assert!((mu.norm() - 1.0).abs() < 1e-8);
        assert!(
            (mu.arg().abs() - epicycle.min(TAU - epicycle)).abs() < 1e-8,
            "{mu}"
        );
    }
}

/// The apsidal angle `Θ` (periapsis to apoapsis) and the radial period `T_r` of an orbit of the
/// power-law force `F = −m μ r^n` (r0 = 1 m) started at the periapsis `rp` with speed `v0`, by
/// quadrature, independent of the shooting: with `P(r) = 2(E − V(r)) − L²/r²`,
/// `Θ = ∫ L/(r² √P) dr` and `T_r = 2 ∫ dr/√P` from `rp` to the apoapsis (the root of `P` by
/// bisection); `r = c − h cos φ` makes both integrands smooth and even in `φ`, so the midpoint
/// rule in `φ` converges geometrically (Goldstein, *Classical Mechanics*, §3.5–3.6).
fn apsidal_angle_and_radial_period(mu: f64, n: f64, rp: f64, v0: f64) -> (f64, f64) {
    let potential = |r: f64| mu * r.powf(n + 1.0) / (n + 1.0);
    let (energy, l) = (v0 * v0 / 2.0 + potential(rp), rp * v0);
    let p = |r: f64| 2.0 * (energy - potential(r)) - l * l / (r * r);
    let mut b = rp * 1.01;
    while p(b) > 0.0 {
        b *= 1.01;
    }
    let mut a = b / 1.01;
    for _ in 0..200 {
        let mid = 0.5 * (a + b);
        if p(mid) > 0.0 { a = mid } else { b = mid }
    }
    let apoapsis = 0.5 * (a + b);
    let (c, h) = (0.5 * (rp + apoapsis), 0.5 * (apoapsis - rp));
    let nodes = 4000;
    let (mut theta, mut radial) = (0.0, 0.0);
    for k in 0..nodes {
        let phi = (k as f64 + 0.5) * PI / nodes as f64;
        let r = c - h * phi.cos();
        let g = h * phi.sin() / p(r).abs().sqrt() * PI / nodes as f64;
        theta += l / (r * r) * g;
        radial += 2.0 * g;
    }
    (theta, radial)
}

/// HW5's non-Kepler closed orbit: the force `F = −m μ r^{−3/2}` (`central_force` with
/// n = −1.5, potential `∝ r^α`, α = n + 1 = −1/2), whose apsidal angle runs from `π/√(α + 2) =
/// 0.8165 π` for a circle down to `π/(α + 2) = 2π/3` as the energy rises to escape (V. I.
/// Arnold, *Mathematical Methods of Classical Mechanics*, §8D, the proof of Bertrand's
/// theorem). Where it is `4π/5` the orbit closes after
/// 5 radial oscillations and 4 revolutions. The speed at periapsis `rp = 1 m` for which
/// `Θ = 4π/5` is found here by bisection on the quadrature (2.871901833689464 m/s; mpmath at
/// 30 digits: 2.87190183368946391932), and the period is `5 T_r` (37.56578056706528 s; mpmath
/// 37.5657805670652788807). From a start moved by 1e-3 and a period guess 2 % off, at the
/// reference energy, Newton finds that period to 1e-9 relative (the quadrature is exact to
/// about 1e-12 and Newton's tolerance is 1e-10), an orbit with 5 periapses, turning 4 times
/// around the centre, and all 4 multipliers 1 with one symmetry (the rotation).
#[test]
fn closed_rosette_of_a_non_kepler_force() {
    let (mu, n, rp) = (4.0, -1.5, 1.0);
    let theta = |v0: f64| apsidal_angle_and_radial_period(mu, n, rp, v0).0;
    let (mut lo, mut hi) = (2.05, 3.9);
    assert!(theta(lo) > 0.8 * PI && theta(hi) < 0.8 * PI);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if theta(mid) > 0.8 * PI {
            lo = mid
        } else {
            hi = mid
        }
    }
    let v0 = 0.5 * (lo + hi);
    assert!((v0 - 2.871_901_833_689_464).abs() < 1e-10, "v0 = {v0}");
    let period = 5.0 * apsidal_angle_and_radial_period(mu, n, rp, v0).1;
    assert!(
        (period - 37.565_780_567_065_28).abs() < 1e-9,
        "T = {period}"
    );

    let mut m = model("central_force");
    m.set_parameter("n", n).unwrap();
    m.set_parameter("v0", v0).unwrap();
    let energy = m.energy(0.0, &m.initial_state());
    let start = vec![rp + 1e-3, -1e-3, 1e-3, v0 + 1e-3];
    let orbit = periodic_orbit(
        m.as_mut(),
        &PeriodicOrbitOptions {
            start: Some(start),
            energy: Some(energy),
            ..PeriodicOrbitOptions::new(1.02 * period)
        },
    )
    .unwrap();
    assert!(
        (orbit.period / period - 1.0).abs() < 1e-9,
        "T = {} against {period}",
        orbit.period
    );
    let ys = &orbit.orbit.y;
    let radius: Vec<f64> = ys.iter().map(|y| y[0].hypot(y[1])).collect();
    // Periapses: local minima of r, the start (an end of the sampled period) counted once.
    let minima = (0..radius.len() - 1)
        .filter(|&k| {
            let before = radius[if k == 0 { radius.len() - 2 } else { k - 1 }];
            radius[k] < before && radius[k] <= radius[k + 1]
        })
        .count();
    assert_eq!(minima, 5, "periapses per period");
    let mut turned = 0.0;
    for w in ys.windows(2) {
        let d = w[1][1].atan2(w[1][0]) - w[0][1].atan2(w[0][0]);
        turned += (d + PI).rem_euclid(TAU) - PI;
    }
    assert!(
        (turned / TAU - 4.0).abs() < 1e-9,
        "revolutions {}",
        turned / TAU
    );
    assert_eq!(orbit.unit_multipliers, 4);
    assert_eq!(orbit.symmetries, 1);
}

/// The simple pendulum released at amplitude a = 1.5 rad about hanging (q = −π/2): its period is
/// `T = 2π √(l/g) / AGM(1, cos(a/2))` (the complete elliptic integral `4 K(sin(a/2))` by the
/// arithmetic–geometric mean). From the small-amplitude guess `2π √(l/g)` (14 % short) Newton
/// finds it to 1e-9; one degree of freedom has only the pair of multipliers 1 of time shift and
/// energy, and no symmetry.
#[test]
fn pendulum_period_against_the_elliptic_integral() {
    let mut m = model("simple_pendulum");
    let (l, g, a) = (1.0f64, 10.0f64, 1.5f64);
    let (mut x, mut y) = (1.0f64, (a / 2.0).cos());
    for _ in 0..10 {
        (x, y) = (0.5 * (x + y), (x * y).sqrt());
    }
    let period = TAU * (l / g).sqrt() / x;
    let start = vec![-PI / 2.0 + a, 0.0];
    let orbit = periodic_orbit(
        m.as_mut(),
        &PeriodicOrbitOptions {
            start: Some(start),
            ..PeriodicOrbitOptions::new(TAU * (l / g).sqrt())
        },
    )
    .unwrap();
    assert!(
        (orbit.period / period - 1.0).abs() < 1e-9,
        "T = {} against {period}",
        orbit.period
    );
    assert_eq!(orbit.unit_multipliers, 2);
    assert_eq!(orbit.symmetries, 0);
}

/// The errors: a constrained model is refused, a start at rest at the equilibrium collapses,
/// an energy that is not finite cannot be fixed, a time-dependent model with the period free
/// is refused, and too few iterations report the residual and the count.
#[test]
fn errors() {
    let mut four_bar = model("four_bar");
    assert!(matches!(
        periodic_orbit(four_bar.as_mut(), &PeriodicOrbitOptions::new(1.0)),
        Err(PeriodicOrbitError::Constrained { .. })
    ));
    let mut pendulum = model("simple_pendulum");
    let at_rest = PeriodicOrbitOptions {
        start: Some(vec![-PI / 2.0, 0.0]),
        ..PeriodicOrbitOptions::new(2.0)
    };
    assert!(matches!(
        periodic_orbit(pendulum.as_mut(), &at_rest),
        Err(PeriodicOrbitError::Collapsed { .. })
    ));
    // Issue 49: a damped model has no periodic orbit but its equilibrium. Newton shrank y₀
    // to ~8e-10, where every state closes to the residual it accepts, and the study reported
    // "T = 4.432 s, asymptotically stable" (exit 0). No multiplier is 1 there, as the flow's
    // direction of an autonomous orbit would give.
    let mut damped = model("three_masses_damped");
    match periodic_orbit(damped.as_mut(), &PeriodicOrbitOptions::new(4.0)) {
        Err(PeriodicOrbitError::NoUnitMultiplier {
            spectral_radius, ..
        }) => assert!(spectral_radius < 0.99, "{spectral_radius}"),
        other => panic!("{other:?}"),
    }
    // A small swing with a loose tolerance is an orbit (refused by the first version of the
    // check above, which required a travel of 1000 accepted residuals): 0.03 rad, tol 1e-3.
    let mut pendulum = model("simple_pendulum");
    let swing = PeriodicOrbitOptions {
        start: Some(vec![-PI / 2.0 + 0.03, 0.0]),
        tol: 1e-3,
        ..PeriodicOrbitOptions::new(2.0)
    };
    let orbit = periodic_orbit(pendulum.as_mut(), &swing).unwrap();
    assert!(orbit.unit_multipliers >= 1, "{:?}", orbit.multipliers);
    // Near the separatrix (1e-3 rad from upright, T = 11.368 s) the pair at 1 is a Jordan
    // block with a large shear, split by rounding beyond 1e-3, but Φ f = f holds: an orbit
    // (the second review found it refused).
    let near_top = PeriodicOrbitOptions {
        start: Some(vec![PI / 2.0 - 1e-3, 0.0]),
        energy: Some(pendulum.energy(0.0, &[PI / 2.0 - 1e-3, 0.0])),
        ..PeriodicOrbitOptions::new(11.368005377845044)
    };
    let orbit = periodic_orbit(pendulum.as_mut(), &near_top).unwrap();
    assert!((orbit.period - 11.368005).abs() < 1e-4, "{}", orbit.period);
    // n = −1: the file's potential divides by n + 1, so the energy cannot be fixed.
    let mut log_force = model("central_force");
    log_force.set_parameter("n", -1.0).unwrap();
    assert!(matches!(
        periodic_orbit(log_force.as_mut(), &PeriodicOrbitOptions::new(3.0)),
        Err(PeriodicOrbitError::InvalidEnergy { .. })
    ));
    let mut mathieu = model("mathieu_pendulum");
    assert!(matches!(
        periodic_orbit(mathieu.as_mut(), &PeriodicOrbitOptions::new(1.0)),
        Err(PeriodicOrbitError::TimeDependent { .. })
    ));
    let mut eight = model("figure_eight");
    let mut start = eight.initial_state();
    start[0] += 0.05;
    let energy = eight.energy(0.0, &eight.initial_state());
    let one = PeriodicOrbitOptions {
        start: Some(start),
        energy: Some(energy),
        max_iterations: 1,
        ..PeriodicOrbitOptions::new(6.3)
    };
    match periodic_orbit(eight.as_mut(), &one) {
        Err(e @ PeriodicOrbitError::NotConverged { iterations: 1, .. }) => {
            assert!(e.to_string().contains("after 1 Newton iterations"), "{e}");
        }
        other => panic!("{other:?}"),
    }
}

/// The CLI: the eight from a perturbed guess in JSON, with a chart; an unknown coordinate in
/// --guess is a usage error (exit 2) naming the coordinates; a constrained model is refused.
#[test]
fn cli() {
    let dir = tempfile::tempdir().unwrap();
    let chart = dir.path().join("eight.svg");
    let out = eomgen(&[
        "study",
        "periodic-orbit",
        "figure_eight",
        "--guess",
        "x1=-0.971,y3_dot=0.8657",
        "--json",
        "--plot",
        chart.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let period = report["period"].as_f64().unwrap();
    assert!((period - SIMO_PERIOD).abs() < 5e-8, "T = {period}");
    assert_eq!(report["unit_multipliers"], 8);
    let svg = std::fs::read_to_string(&chart).unwrap();
    assert!(svg.contains("<svg") && svg.contains("P3"));

    let out = eomgen(&["study", "periodic-orbit", "figure_eight", "--guess", "z1=0"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("z1") && err.contains("x1, y1"), "{err}");

    let out = eomgen(&["study", "periodic-orbit", "four_bar", "--period", "1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("constraints"));

    // The damped masses' equilibrium is no orbit: exit 1, as docs/cli.md promises.
    let out = eomgen(&[
        "study",
        "periodic-orbit",
        "three_masses_damped",
        "--period",
        "4",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no Floquet multiplier is within"));
}
