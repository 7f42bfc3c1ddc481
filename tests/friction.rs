//! Friction at contacts, against closed forms: Coulomb's stick and slip on a floor and an
//! incline, a box on two feet, lift-off and Painlevé's paradox, a pendulum bob locked by
//! friction, a disc rolling or sliding, HW36's skipping cylinder, and blocks on a moving belt
//! (stick–slip with one coefficient and with a static one).

use crate::contacts::fixture_run;
use eomgen::JitModel;
use eomgen::hybrid::impact::ImpactMode;

/// The belt with a static coefficient above the kinetic one (`μ_s = 0.4`, `μ = 0.3`): a
/// stick–slip cycle. It sticks until the spring pulls `μ_s m g` (`x_s`), slips along the
/// swing about `x_k = μ m g/k` until its speed is the belt's again, at `2x_k − x_s` after
/// `(2π − 2 atan(A ω/v_b))/ω` (`A = x_s − x_k`), sticks, and rides to `x_s` in
/// `2A/v_b`: the switch times of three cycles to 1e-9.
#[test]
fn a_block_on_a_belt_with_static_friction_sticks_and_slips_in_a_cycle() {
    use eomgen::analysis::Method;
    use eomgen::hybrid::TransitionKind;
    let (k, g, mu, mus, vb) = (10.0_f64, 9.81, 0.3, 0.4, 0.5);
    let omega = k.sqrt();
    let (xk, xs) = (mu * g / k, mus * g / k);
    let t1 = (vb / (xk * omega)).asin() / omega;
    let x1 = xk * (1.0 - (omega * t1).cos());
    let a = xs - xk;
    let slipping = (2.0 * std::f64::consts::PI - 2.0 * (a * omega / vb).atan()) / omega;
    let sticking = 2.0 * a / vb;
    let mut expected = vec![
        (TransitionKind::Stick, t1),
        (TransitionKind::Slip, t1 + (xs - x1) / vb),
    ];
    for _ in 0..3 {
        let last = expected.last().unwrap().1;
        expected.push((TransitionKind::Stick, last + slipping));
        expected.push((TransitionKind::Slip, last + slipping + sticking));
    }
    let t_end = expected.last().unwrap().1 + 0.1;
    let run = fixture_run(
        "contacts_belt",
        Method::Dop853,
        (1e-12, t_end),
        &[("mus", mus)],
        None,
    );
    assert!(run.contact_stop.is_none(), "{:?}", run.contact_stop);
    let got: Vec<_> = run.transitions.iter().map(|tr| (tr.kind, tr.t)).collect();
    assert_eq!(got.len(), expected.len(), "{got:?}");
    for ((kind, t), (want, at)) in got.iter().zip(&expected) {
        assert_eq!(kind, want, "{got:?}");
        assert!((t - at).abs() < 1e-9, "{t} against {at}");
    }
}

/// HW36's eccentric cylinder (`models/eccentric_cylinder_skipping.yaml`) lifts off five times
/// in 8 s with `μ = 0.8`; with `μ = 2` it lands, rolls, and where its force leaves the cone
/// after the first landing the slide it would start has no bounded normal force (Painlevé):
/// the run stops there with that reason (it ended in a step size too small, its energy
/// rising 10⁹-fold, before), keeping the samples before it.
#[test]
fn the_skipping_cylinder_skips_or_stops_on_painleves_paradox() {
    use eomgen::analysis::Method;
    use eomgen::hybrid::{ContactStop, TransitionKind};
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/models/eccentric_cylinder_skipping.yaml"
    );
    let run = |mu: f64| {
        let mut model = eomgen::DynFirstOrder::new(JitModel::load(path).unwrap());
        eomgen::ModelInfo::set_parameter(&mut model, "mu", mu).unwrap();
        let options = eomgen::analysis::SimulationOptions {
            method: Method::Dp54,
            t_end: 8.0,
            ..Default::default()
        };
        eomgen::analysis::simulate(&mut model, &options).unwrap()
    };
    let skipping = run(0.8);
    assert!(
        skipping.contact_stop.is_none(),
        "{:?}",
        skipping.contact_stop
    );
    let lift_offs = (skipping.transitions.iter())
        .filter(|tr| tr.kind == TransitionKind::LiftOff)
        .count();
    assert_eq!(lift_offs, 5, "{:?}", skipping.transitions);
    let stopped = run(2.0);
    let Some(ContactStop::SlidingPainleve { contact, t }) = &stopped.contact_stop else {
        panic!("{:?}", stopped.contact_stop);
    };
    assert_eq!(contact, "floor");
    assert!(*t > 3.5 && *t < 4.5, "{t}");
    assert_eq!(stopped.solution.t.last(), Some(t));
}

/// A block dropped onto the moving belt (`e = 0.5`, from 0.2 m): each impact's friction
/// drags it towards the belt's speed, which can give it kinetic energy; what the impact
/// itself may not add is more than the belt's work `Λ_T v_s` (`v_s = −v_b` along the
/// floor's tangent `(−1, 0)`), and the run goes on through its bounces to rest on the belt.
#[test]
fn a_block_dropped_on_a_belt_gains_no_more_than_the_belts_work() {
    use eomgen::analysis::Method;
    let run = fixture_run(
        "contacts_belt",
        Method::Dop853,
        (1e-10, 2.0),
        &[("e", 0.5)],
        Some(vec![0.0, 0.2, 0.0, 0.0]),
    );
    assert!(run.contact_stop.is_none(), "{:?}", run.contact_stop);
    let impacts: Vec<_> = (run.transitions.iter())
        .filter(|tr| tr.normal_impulse > 0.0)
        .collect();
    assert!(impacts.len() > 5, "{impacts:?}");
    assert!(impacts.iter().any(|tr| tr.energy_lost < 0.0), "{impacts:?}");
    for tr in &impacts {
        let belt = tr.tangential_impulse * -0.5;
        assert!(-tr.energy_lost <= belt + 1e-12, "{tr:?}");
    }
}

/// A pendulum bob on its rod (`contacts_pendulum.yaml`) strikes a rough floor at
/// `θ_c = acos(h/l)`: with `μ = 0.4 < tan θ_c` its slip reverses and it rebounds at
/// `e` times its approach speed (1e-8, the rod's drift), and with `μ = 0.5` or 2 friction
/// locks it (`Jammed`): the contact closes, sticking, and the bob rests there to the end,
/// its energy `−m g h` (1e-8), the whole kinetic energy of the strike lost.
#[test]
fn friction_locks_a_pendulum_bob_on_a_rough_floor() {
    use eomgen::analysis::Method;
    use eomgen::hybrid::TransitionKind;
    let (g, h) = (9.81, 0.9_f64);
    let theta = h.acos();
    // The bob's speed at the floor, from its fall from 1.2 rad.
    let speed = (2.0 * g * (h - 1.2_f64.cos())).sqrt();
    let run = fixture_run(
        "contacts_pendulum",
        Method::Dp54,
        (1e-10, 0.5),
        &[("mu", 0.4)],
        None,
    );
    let first = &run.transitions[0];
    assert_eq!(first.mode, ImpactMode::Reversing, "{first:?}");
    let approach = speed * theta.sin();
    assert!(
        (first.normal_velocity[0] + approach).abs() < 1e-8,
        "{first:?}"
    );
    assert!(
        (first.normal_velocity[1] - 0.5 * approach).abs() < 1e-8,
        "{first:?}"
    );
    for mu in [0.5, 2.0] {
        let run = fixture_run(
            "contacts_pendulum",
            Method::Dp54,
            (1e-10, 2.0),
            &[("mu", mu)],
            None,
        );
        assert!(
            run.contact_stop.is_none(),
            "μ = {mu}: {:?}",
            run.contact_stop
        );
        let first = &run.transitions[0];
        assert_eq!(first.mode, ImpactMode::Jammed, "{first:?}");
        assert_eq!(first.kind, TransitionKind::Closes, "{first:?}");
        assert!(
            (first.energy_lost - 0.5 * speed * speed).abs() < 1e-8,
            "{first:?}"
        );
        let last = run.solution.iter().last().unwrap().1;
        assert!(last[2].abs() < 1e-8 && last[3].abs() < 1e-8, "{last:?}");
        assert!((last[1] + h).abs() < 1e-8, "{last:?}");
    }
}

/// A disc on a line (`disc:`), as a uniform disc (`models/eccentric_cylinder_skipping.yaml`
/// with its centre of mass at its centre, `I = M R²/2`) released on the ramp `γ = 0.3`: with
/// `μ = 2` it sticks, which is rolling, `ẍ = (2/3) g sin γ` and `x + R θ` constant; with
/// `μ = 0.05 < (1/3) tan γ` it slides from the start, `ẍ = g (sin γ − μ cos γ)` and
/// `θ̈ = −2 μ g cos γ/R`; each over 1 s, to 1e-9 (tolerance 1e-12).
#[test]
fn a_disc_on_a_ramp_rolls_or_slides_by_its_friction() {
    use eomgen::analysis::Method;
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/models/eccentric_cylinder_skipping.yaml"
    );
    let (g, gamma, r) = (10.0, 0.3_f64, 1.0);
    for mu in [2.0, 0.05] {
        let mut model = eomgen::DynFirstOrder::new(JitModel::load(path).unwrap());
        for (k, v) in [("e", 0.0), ("IG", 0.5), ("mu", mu)] {
            eomgen::ModelInfo::set_parameter(&mut model, k, v).unwrap();
        }
        let options = eomgen::analysis::SimulationOptions {
            method: Method::Dop853,
            t_end: 1.0,
            rtol: 1e-12,
            atol: 1e-12,
            ..Default::default()
        };
        let run = eomgen::analysis::simulate(&mut model, &options).unwrap();
        assert!(run.contact_stop.is_none(), "{:?}", run.contact_stop);
        let (x0, theta0) = (
            -r * std::f64::consts::FRAC_PI_2,
            std::f64::consts::FRAC_PI_2,
        );
        let (along, turning) = if mu > gamma.tan() / 3.0 {
            let a = 2.0 / 3.0 * g * gamma.sin();
            (a, -a / r)
        } else {
            (
                g * (gamma.sin() - mu * gamma.cos()),
                -2.0 * mu * g * gamma.cos() / r,
            )
        };
        for (t, y) in run.solution.iter() {
            let x = x0 + 0.5 * along * t * t;
            let theta = theta0 + 0.5 * turning * t * t;
            assert!(
                (y[0] - x).abs() < 1e-9 && (y[2] - theta).abs() < 1e-9 && (y[1] - r).abs() < 1e-9,
                "μ = {mu}, t = {t}: {y:?} against x = {x}, θ = {theta}"
            );
        }
    }
}

/// A block on a spring riding a belt (`contacts_belt.yaml`: the floor a line moving along
/// itself at `v_b`): it slides, sticks where its speed reaches the belt's at
/// `ω t₁ = asin(v_b/(x_k ω))`, slips at `t₂ = t₁ + (x_k − x₁)/v_b` where the spring pulls
/// `μ m g`, and from there swings as `x_k + (v_b/ω) sin ω(t − t₂)`, its speed touching the
/// belt's once a period without sticking again (`x_k = μ m g/k`): the switch times to 1e-9,
/// the motion to 1e-8 over 10 s, with three methods.
#[test]
fn a_block_on_a_moving_belt_sticks_and_slips_at_the_closed_form_times() {
    use eomgen::analysis::Method;
    use eomgen::hybrid::TransitionKind;
    let (k, g, mu, vb) = (10.0_f64, 9.81, 0.3, 0.5);
    let omega = k.sqrt();
    let xk = mu * g / k;
    let t1 = (vb / (xk * omega)).asin() / omega;
    let x1 = xk * (1.0 - (omega * t1).cos());
    let t2 = t1 + (xk - x1) / vb;
    let x = |t: f64| -> f64 {
        if t <= t1 {
            xk * (1.0 - (omega * t).cos())
        } else if t <= t2 {
            x1 + vb * (t - t1)
        } else {
            xk + vb / omega * (omega * (t - t2)).sin()
        }
    };
    for method in [Method::Dop853, Method::Dp54, Method::Radau5] {
        let run = fixture_run("contacts_belt", method, (1e-12, 10.0), &[], None);
        assert!(
            run.contact_stop.is_none(),
            "{method:?}: {:?}",
            run.contact_stop
        );
        let kinds: Vec<_> = run.transitions.iter().map(|tr| (tr.kind, tr.t)).collect();
        assert_eq!(kinds.len(), 2, "{method:?}: {kinds:?}");
        assert_eq!(kinds[0].0, TransitionKind::Stick);
        assert_eq!(kinds[1].0, TransitionKind::Slip);
        assert!(
            (kinds[0].1 - t1).abs() < 1e-9 && (kinds[1].1 - t2).abs() < 1e-9,
            "{method:?}: {kinds:?}"
        );
        for (t, y) in run.solution.iter() {
            assert!(
                (y[0] - x(t)).abs() < 1e-8,
                "{method:?}, t = {t}: {} against {}",
                y[0],
                x(t)
            );
        }
    }
}

/// Coulomb friction in a closed contact. A block at rest on an incline sticks while
/// `tan β ≤ μ`: at `β = 0.3`, `μ = 0.5` it stays where it is (within 1e-12 after 2 s). At
/// `β = 0.6` (`tan β = 0.68`) the cone cannot hold it: it slips at once and slides with
/// `ẍ = g (sin β − μ cos β)`, `x = ½ ẍ t²` to 1e-9. On a level floor, pushed at `v₀ = 2 m/s`,
/// it slides to a stop at `t = v₀/(μ g)`, `x = v₀²/(2 μ g)`, and sticks there (to 1e-9).
#[test]
fn a_block_sticks_slips_and_stops_with_coulomb_friction() {
    use eomgen::analysis::Method;
    use eomgen::hybrid::TransitionKind;
    let (g, mu) = (9.81_f64, 0.5_f64);
    let run = fixture_run("contacts_incline", Method::Dop853, (1e-10, 2.0), &[], None);
    assert!(
        run.failure.is_none() && run.contact_stop.is_none(),
        "{:?}",
        run.contact_stop
    );
    assert!(run.transitions.is_empty(), "{:?}", run.transitions);
    let (t, y) = run.solution.last().unwrap();
    assert_eq!(t, 2.0);
    assert!(y.iter().all(|v| v.abs() < 1e-12), "{y:?}");
    let beta = 0.6_f64;
    let run = fixture_run(
        "contacts_incline",
        Method::Dop853,
        (1e-12, 2.0),
        &[("beta", beta)],
        None,
    );
    assert_eq!(
        run.transitions[0].kind,
        TransitionKind::Slip,
        "{:?}",
        run.transitions
    );
    assert_eq!(run.transitions[0].t, 0.0);
    let a = g * (beta.sin() - mu * beta.cos());
    let (t, y) = run.solution.last().unwrap();
    assert!(
        (y[0] - 0.5 * a * t * t).abs() < 1e-9 && y[1].abs() < 1e-9,
        "{y:?}"
    );
    let v0 = 2.0;
    let run = fixture_run(
        "contacts_incline",
        Method::Dop853,
        (1e-12, 1.0),
        &[("beta", 0.0)],
        Some(vec![0.0, 0.0, v0, 0.0]),
    );
    let stop = (run.transitions.iter())
        .find(|tr| tr.kind == TransitionKind::Stick)
        .unwrap_or_else(|| panic!("{:?}", run.transitions));
    assert!((stop.t - v0 / (mu * g)).abs() < 1e-9, "{stop:?}");
    let (_, y) = run.solution.last().unwrap();
    assert!(
        (y[0] - v0 * v0 / (2.0 * mu * g)).abs() < 1e-9 && y[2].abs() < 1e-9,
        "{y:?}"
    );
}

/// Contacts with friction in harder cases. A box standing on two rough feet (their slip rows
/// repeat each other) stays at rest, and pushed at 1 m/s it slides to a stop at
/// `v₀/(μ g)` and stays there, its energy never growing (to 1e-9). A block on a rough floor
/// (`μ = 2`) pulled up by `k t` lifts off at `t = m g/k` (a lift-off, not a slip, though
/// `μ > 1`). A rod sliding on a very rough floor has no consistent mode (Painlevé), and the
/// run stops at once saying so.
#[test]
fn friction_with_repeated_rows_lift_off_and_painleve() {
    use eomgen::analysis::Method;
    use eomgen::hybrid::{ContactStop, TransitionKind};
    let g = 9.81_f64;
    let run = fixture_run("contacts_box", Method::Dp54, (1e-10, 1.0), &[], None);
    assert!(
        run.failure.is_none() && run.contact_stop.is_none(),
        "{:?} {:?}",
        run.failure,
        run.contact_stop
    );
    let (_, y) = run.solution.last().unwrap();
    assert!(
        y.iter().enumerate().all(|(i, v)| if i == 1 {
            (v - 0.2).abs() < 1e-12
        } else {
            v.abs() < 1e-12
        }),
        "{y:?}"
    );
    let run = fixture_run(
        "contacts_box",
        Method::Dp54,
        (1e-12, 3.0),
        &[],
        Some(vec![0.0, 0.2, 0.0, 1.0, 0.0, 0.0]),
    );
    assert!(
        run.failure.is_none() && run.contact_stop.is_none(),
        "{:?} {:?}",
        run.failure,
        run.contact_stop
    );
    let stop = run
        .transitions
        .iter()
        .find(|tr| tr.kind == TransitionKind::Stick)
        .unwrap();
    assert!((stop.t - 1.0 / (0.5 * g)).abs() < 1e-9, "{stop:?}");
    let (_, y) = run.solution.last().unwrap();
    assert!(
        (y[0] - 1.0 / (2.0 * 0.5 * g)).abs() < 1e-9 && y[3].abs() < 1e-9,
        "{y:?}"
    );
    assert!(
        run.energy.energy.windows(2).all(|w| w[1] <= w[0] + 1e-9),
        "the energy grew"
    );
    let run = fixture_run(
        "contacts_lifted",
        Method::Dop853,
        (1e-12, 6.0),
        &[("mu", 2.0), ("k", 2.0)],
        None,
    );
    let off = &run.transitions[0];
    assert_eq!(off.kind, TransitionKind::LiftOff, "{:?}", run.transitions);
    assert!((off.t - g / 2.0).abs() < 1e-9, "{off:?}");
    let run = fixture_run("contacts_painleve", Method::Dp54, (1e-10, 1.0), &[], None);
    assert!(
        matches!(&run.contact_stop, Some(ContactStop::NoConsistentMode { contact, t }) if contact == "floor" && *t == 0.0),
        "{:?}",
        run.contact_stop
    );
}

/// Smoothing is a modelling choice: the belt's block with its friction written as the force
/// `μ m g tanh((v_b − ẋ)/ε)` (tests/fixtures/belt_smoothed.yaml) creeps where the exact
/// switching sticks, so at t = 5 s it is off the closed form `x_k + (v_b/ω) sin ω(t − t₂)` by
/// between ε/2 and 2ε (m, for ε in m/s, at ε = 1e-2 and 1e-3), while the exact run
/// (tests/fixtures/contacts_belt.yaml) meets it to 1e-8, all at tolerance 1e-10
/// (docs/course/impacts.md charts both and their steps).
#[test]
fn smoothed_friction_misses_the_exact_switching_by_its_smoothing_speed() {
    use eomgen::analysis::Method;
    let (k, g, mu, vb, t) = (10.0_f64, 9.81, 0.3, 0.5, 5.0);
    let omega = k.sqrt();
    let xk = mu * g / k;
    let t1 = (vb / (xk * omega)).asin() / omega;
    let x1 = xk * (1.0 - (omega * t1).cos());
    let t2 = t1 + (xk - x1) / vb;
    let exact = xk + vb / omega * (omega * (t - t2)).sin();
    let last_x = |name: &str, set: &[(&str, f64)]| {
        let run = fixture_run(name, Method::Dop853, (1e-10, t), set, None);
        run.solution.last().unwrap().1[0]
    };
    let switched = last_x("contacts_belt", &[]);
    assert!((switched - exact).abs() < 1e-8, "{switched} vs {exact}");
    for eps in [1e-2, 1e-3] {
        let error = (last_x("belt_smoothed", &[("eps", eps)]) - exact).abs();
        assert!(error > 0.5 * eps && error < 2.0 * eps, "eps {eps}: {error}");
    }
}
