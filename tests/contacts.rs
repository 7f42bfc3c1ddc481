//! Unilateral contacts (`contacts:`) as the model's functions: gaps, their rates, Jacobian and
//! coefficients against closed forms, the same bits from `model!`, the run-time compiler's
//! native code and its interpreter; an impact computed from them (`hybrid::impact`) against
//! Newton's law; and runs through impacts against closed forms (a bouncing ball and its Zeno
//! time, a ball in a loop, corners, a rimless wheel, Housner's rocking block). Friction's
//! runs are in friction.rs.

use eomgen::hybrid::impact;
use eomgen::hybrid::impact::{ContactFriction, ImpactContact, ImpactMode};
use eomgen::nalgebra::SVector;
use eomgen::{Backend, DynMechanicalSystem, JitModel, LoadOptions, MechanicalSystem};

mod compiled {
    eomgen::model!("fixtures/contacts_ball.yaml");
}

const FILE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/contacts_ball.yaml"
);

/// The file's parameters: `R` (m), `e`, `μ`.
const R: f64 = 2.0;
const E: f64 = 0.8;
const MU: f64 = 0.3;

/// `[g; ġ; γ; γ_T; v_s]`, `G` and the coefficients of a model at `(q, q̇)`.
fn contact_functions(model: &dyn DynMechanicalSystem, q: &[f64], qdot: &[f64]) -> [Vec<f64>; 3] {
    let m = model.description().contacts.len();
    let mut gaps = vec![f64::NAN; 5 * m];
    let mut jacobian = vec![f64::NAN; 2 * m * 2];
    let mut coefficients = vec![f64::NAN; 3 * m];
    model.contact_gaps(q, qdot, 0.0, &mut gaps);
    model.contact_jacobian(q, 0.0, &mut jacobian);
    model.contact_coefficients(&mut coefficients);
    [gaps, jacobian, coefficients]
}

/// The closed forms at `q = (x, y)`, `q̇ = (ẋ, ẏ)`: the floor `g = y` (its normal `[0, 2]`
/// scaled to unit length), the shelf `g = y + R/2`, the bowl `g = R − |P − C|`, `C = (0, R)`,
/// `ġ = −(P − C)·Ṗ/|P − C|`, `γ = |Ṗ|²/|P − C| − ((P − C)·Ṗ)²/|P − C|³`; the floor's slip `T = t̂ = (−1, 0)` (its normal turned a
/// quarter-turn), the others frictionless.
fn closed_forms(q: [f64; 2], qdot: [f64; 2]) -> [Vec<f64>; 3] {
    let [x, y] = q;
    let (dx, dy) = (x, y - R);
    let d = dx.hypot(dy);
    let bowl_row = [-dx / d, -dy / d];
    let bowl_rate = bowl_row[0] * qdot[0] + bowl_row[1] * qdot[1];
    // γ = −g̈ at q̈ = 0: 0 for the floor and the shelf; for the bowl
    // |Ṗ|²/|d| − (d·Ṗ)²/|d|³.
    let speed2 = qdot[0] * qdot[0] + qdot[1] * qdot[1];
    let along = dx * qdot[0] + dy * qdot[1];
    let bowl_gamma = speed2 / d - along * along / (d * d * d);
    [
        vec![
            y,
            y + R / 2.0,
            R - d,
            qdot[1],
            qdot[1],
            bowl_rate,
            0.0,
            0.0,
            bowl_gamma,
            0.0,
            0.0,
            0.0,
            // The surfaces' speeds: all fixed.
            0.0,
            0.0,
            0.0,
        ],
        vec![
            0.0,
            1.0,
            0.0,
            1.0,
            bowl_row[0],
            bowl_row[1],
            -1.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        vec![E, MU, MU, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    ]
}

/// At a few states, the contact functions of the file compiled at run time (native code and
/// interpreter) and by `model!` equal each other to the bit and the closed forms to 1e-14
/// relative (to 1 for values below 1).
#[test]
fn gaps_rates_jacobian_and_coefficients_match_closed_forms_on_every_backend() {
    let native = JitModel::load(FILE).unwrap();
    let interpreted = JitModel::load_with(
        FILE,
        LoadOptions {
            backend: Some(Backend::Interpreter),
            ..LoadOptions::default()
        },
    )
    .unwrap();
    let macro_model = compiled::ContactsBall::default();
    assert_eq!(
        native.description().contacts.as_ref(),
        ["floor", "shelf", "bowl"]
    );
    for (q, qdot) in [
        ([0.3, 1.0], [0.5, 0.0]),
        ([-0.7, 0.2], [0.1, -3.0]),
        ([1.1, 2.9], [-2.0, 0.4]),
    ] {
        let expected = closed_forms(q, qdot);
        let got = contact_functions(&native, &q, &qdot);
        for (part, (g, x)) in got.iter().zip(&expected).enumerate() {
            for (a, b) in g.iter().zip(x) {
                assert!(
                    (a - b).abs() <= 1e-14 * b.abs().max(1.0),
                    "part {part} at {q:?}: {g:?} vs {x:?}"
                );
            }
        }
        let mut from_macro = [vec![0.0; 15], vec![0.0; 12], vec![0.0; 9]];
        let (sq, sqdot) = (SVector::from(q), SVector::from(qdot));
        macro_model.contact_gaps(&sq, &sqdot, 0.0, &mut from_macro[0]);
        macro_model.contact_jacobian(&sq, 0.0, &mut from_macro[1]);
        macro_model.contact_coefficients(&mut from_macro[2]);
        for other in [contact_functions(&interpreted, &q, &qdot), from_macro] {
            for (a, b) in got.iter().zip(&other) {
                let (a, b): (Vec<u64>, Vec<u64>) = (
                    a.iter().map(|v| v.to_bits()).collect(),
                    b.iter().map(|v| v.to_bits()).collect(),
                );
                assert_eq!(a, b, "at {q:?}");
            }
        }
    }
}

/// The ball strikes the floor at `ẏ = −3 m/s`, `ẋ = 0.5 m/s`: from the model's own `M` and
/// floor rows of `G` and `T`, the impact law gives `ẏ⁺ = e · 3` and the energy lost
/// `½ m (1 − e²) 3²` without friction (the horizontal rate kept), and with the floor's
/// `μ = 0.3` a sticking impact (the impulse `m · 0.5` needed to stop the slip is inside
/// `μ Λ_N = 0.3 · m (1 + e) 3`): `ẋ⁺ = 0`, and `½ m 0.5²` more lost; to 1e-14.
#[test]
fn an_impact_from_the_models_own_rows_obeys_newtons_law() {
    let model = compiled::ContactsBall::default();
    let (q, qdot) = (SVector::from([0.3, 0.0]), SVector::from([0.5, -3.0]));
    let mass = model.mass_matrix(&q, 0.0);
    let mut jacobian = [0.0; 12];
    model.contact_jacobian(&q, 0.0, &mut jacobian);
    let mut coefficients = [0.0; 9];
    model.contact_coefficients(&mut coefficients);
    let contact = ImpactContact {
        normal: &jacobian[..2],
        restitution: coefficients[0],
        friction: None,
    };
    let r = impact(mass.as_slice(), qdot.as_slice(), &contact, &[]).unwrap();
    assert_eq!(r.mode, ImpactMode::Frictionless);
    let m = 2.0;
    assert!((r.qdot[0] - 0.5).abs() <= 1e-14, "{r:?}");
    assert!((r.qdot[1] - E * 3.0).abs() <= 1e-14, "{r:?}");
    let lost = 0.5 * m * (1.0 - E * E) * 9.0;
    assert!((r.energy_lost - lost).abs() <= 1e-14 * lost, "{r:?}");
    let contact = ImpactContact {
        friction: Some(ContactFriction {
            tangent: &jacobian[6..8],
            coefficient: coefficients[1],
            static_coefficient: coefficients[1],
            surface_velocity: 0.0,
        }),
        ..contact
    };
    let r = impact(mass.as_slice(), qdot.as_slice(), &contact, &[]).unwrap();
    assert_eq!(r.mode, ImpactMode::Sticking);
    assert!(
        r.qdot[0].abs() <= 1e-14 && (r.qdot[1] - E * 3.0).abs() <= 1e-14,
        "{r:?}"
    );
    let lost = lost + 0.5 * m * 0.25;
    assert!((r.energy_lost - lost).abs() <= 1e-14 * lost, "{r:?}");
}

const BALL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/bouncing_ball.yaml"
);

/// The bouncing ball's closed forms (`h = 1 m`, `g = 9.81 m/s²`): the `k`-th impact time
/// `t₁ + Σ_{j<k} 2 eʲ v₀/g` and the accumulation time `t∞ = t₁ + (2 e v₀/g)/(1 − e)`.
fn ball_times(e: f64, k: usize) -> (Vec<f64>, f64) {
    let (g, h) = (9.81_f64, 1.0_f64);
    let (t1, v0) = ((2.0 * h / g).sqrt(), (2.0 * g * h).sqrt());
    let mut times = vec![t1];
    for j in 1..k {
        let last = times[j - 1];
        times.push(last + 2.0 * e.powi(j as i32) * v0 / g);
    }
    (times, t1 + 2.0 * e * v0 / g / (1.0 - e))
}

/// A run of the ball to `t_end` with `method` at `rtol = atol = tol` and `e`, `μ` set.
fn ball_run(
    method: eomgen::analysis::Method,
    tol: f64,
    (e, mu): (f64, f64),
    t_end: f64,
) -> eomgen::analysis::Simulation {
    let mut model = eomgen::DynFirstOrder::new(JitModel::load(BALL).unwrap());
    eomgen::ModelInfo::set_parameter(&mut model, "e", e).unwrap();
    eomgen::ModelInfo::set_parameter(&mut model, "mu", mu).unwrap();
    let options = eomgen::analysis::SimulationOptions {
        method,
        t_end,
        rtol: tol,
        atol: tol,
        ..Default::default()
    };
    eomgen::analysis::simulate(&mut model, &options).unwrap()
}

/// Through impacts with every adaptive method (each restarted after every impact): the
/// first six impact times equal the closed form to 1e-7 s at tolerance 1e-10, each impact
/// reverses `ẏ` with the factor `e` (to 1e-12 relative: the impact law itself), the energy
/// lost at each is `½ m (1 − e²) ẏ⁻²`, and the drift of `E` plus the losses stays at the
/// integration's level (below 1e-8).
#[test]
fn a_bouncing_ball_strikes_at_the_closed_form_times_with_every_adaptive_method() {
    let (times, _) = ball_times(0.8, 6);
    for method in eomgen::analysis::Method::ALL {
        if !method.is_adaptive() {
            continue;
        }
        let run = ball_run(method, 1e-10, (0.8, 0.0), 3.0);
        assert!(
            run.failure.is_none() && run.contact_stop.is_none(),
            "{method:?}"
        );
        assert_eq!(run.transitions.len(), 6, "{method:?}");
        for (tr, t) in run.transitions.iter().zip(&times) {
            assert!((tr.t - t).abs() < 1e-7, "{method:?}: {} vs {t}", tr.t);
            let [before, after] = tr.normal_velocity;
            assert!(
                (after + 0.8 * before).abs() <= 1e-12 * before.abs(),
                "{tr:?}"
            );
            let lost = 0.5 * (1.0 - 0.64) * before * before;
            assert!((tr.energy_lost - lost).abs() <= 1e-12 * lost, "{tr:?}");
            // The sample before the impact and the one after share its time.
            assert_eq!(run.solution.t[tr.sample - 1], tr.t);
            assert_eq!(run.solution.t[tr.sample], tr.t);
        }
        assert!(
            run.energy.drift.unwrap() < 1e-8,
            "{method:?}: {:?}",
            run.energy.drift
        );
    }
}

/// Past the accumulation time the ball rests on the floor: the impact that closes the
/// contact (kind `closes`) comes at a time that, plus the closed form of the flights left
/// after it, `(2 e |ġ⁻|/g)/(1 − e)`, is `t∞` to 1e-8 s, for `e = 0.5` and `0.8`; from then on
/// the contact is held (its normal force `m g` pushes, so it never lifts off) and the run
/// reaches its end with `y = 0` and `ẏ = 0` to 1e-9 and `ẋ = 0.5`. A plastic ball (`e = 0`)
/// closes the contact at its first impact, at `t₁`, having lost all its vertical energy
/// `m g h`.
#[test]
fn impacts_accumulate_at_the_zeno_time_and_then_the_ball_rests() {
    use eomgen::hybrid::TransitionKind;
    for (e, tol) in [(0.5, 1e-12), (0.8, 1e-12), (0.0, 1e-12)] {
        let (times, t_inf) = ball_times(e, 1);
        let run = ball_run(eomgen::analysis::Method::Dp54, tol, (e, 0.0), 6.0);
        assert!(
            run.failure.is_none() && run.contact_stop.is_none(),
            "e = {e}: {:?}",
            run.contact_stop
        );
        let last = run.transitions.last().unwrap();
        assert_eq!(last.kind, TransitionKind::Closes, "e = {e}");
        assert!(
            run.transitions[..run.transitions.len() - 1]
                .iter()
                .all(|tr| tr.kind == TransitionKind::Impact)
        );
        let speed = -last.normal_velocity[0];
        let left = 2.0 * e * speed / 9.81 / (1.0 - e);
        let expected = if e == 0.0 { times[0] } else { t_inf };
        assert!(
            (last.t + left - expected).abs() < 1e-8,
            "e = {e}: {} + {left} vs {expected}",
            last.t
        );
        let lost: f64 = run.transitions.iter().map(|tr| tr.energy_lost).sum();
        assert!((lost - 9.81).abs() < 1e-8, "e = {e}: {lost}");
        let (t, y) = run.solution.last().unwrap();
        assert_eq!(t, 6.0);
        assert!(y[1].abs() < 1e-9 && y[3].abs() < 1e-9, "e = {e}: {y:?}");
        assert!(
            (y[2] - 0.5).abs() < 1e-12 && (y[0] - 3.0).abs() < 1e-9,
            "e = {e}: {y:?}"
        );
    }
}

/// With friction on the floor the first impact sticks: the impulse `m · 0.5` that stops the
/// slip is inside `μ Λ_N` for `μ = 0.3`, so `ẋ = 0` after it and the ball bounces in place;
/// with `μ = 0.05` it slides on the cone's edge, `ẋ⁺ = 0.5 − μ (1 + e) v₀`.
#[test]
fn friction_at_the_impact_sticks_or_slides() {
    let v0 = (2.0 * 9.81_f64).sqrt();
    let run = ball_run(eomgen::analysis::Method::Dp54, 1e-10, (0.8, 0.3), 1.0);
    let first = &run.transitions[0];
    assert_eq!(first.mode, ImpactMode::Sticking);
    assert!(first.qdot[1][0].abs() < 1e-14, "{first:?}");
    let run = ball_run(eomgen::analysis::Method::Dp54, 1e-10, (0.8, 0.05), 1.0);
    let first = &run.transitions[0];
    assert_eq!(first.mode, ImpactMode::Sliding);
    let slid = 0.5 - 0.05 * 1.8 * v0;
    assert!(
        (first.qdot[1][0] - slid).abs() < 1e-9,
        "{first:?} vs {slid}"
    );
}

/// A start inside the floor is refused, naming the contact.
#[test]
fn a_start_inside_a_contact_is_refused() {
    let mut model = eomgen::DynFirstOrder::new(JitModel::load(BALL).unwrap());
    let options = eomgen::analysis::SimulationOptions {
        initial_state: Some(vec![0.0, -0.01, 0.0, 0.0]),
        ..Default::default()
    };
    let error = eomgen::analysis::simulate(&mut model, &options).unwrap_err();
    assert!(
        matches!(&error, eomgen::analysis::SimulationError::StartsInsideContact { contact, gap } if contact == "floor" && *gap == -0.01),
        "{error}"
    );
}

/// Two sequences of bounces (`contacts_kicked_ball.yaml`: a ball rests, is lifted off by a
/// push and lands again at a thousandth of its first speed): each is taken as accumulated
/// at a millionth of its own first striking speed, so both take as many impacts (21 at
/// `e = 0.5`, to one), where measuring the second against the first drop's speed would end
/// it after half as many.
#[test]
fn a_contact_lifted_off_after_resting_starts_a_new_sequence_of_impacts() {
    use eomgen::analysis::Method;
    use eomgen::hybrid::TransitionKind;
    let run = fixture_run(
        "contacts_kicked_ball",
        Method::Dop853,
        (1e-12, 4.0),
        &[],
        None,
    );
    assert!(run.contact_stop.is_none(), "{:?}", run.contact_stop);
    let kinds: Vec<TransitionKind> = run.transitions.iter().map(|tr| tr.kind).collect();
    let lift = kinds
        .iter()
        .position(|k| *k == TransitionKind::LiftOff)
        .expect("a lift-off");
    let closes: Vec<usize> = (0..kinds.len())
        .filter(|&k| kinds[k] == TransitionKind::Closes)
        .collect();
    assert_eq!(closes.len(), 2, "{kinds:?}");
    let (first, second) = (closes[0] + 1, closes[1] - lift);
    assert!(first.abs_diff(second) <= 1, "{first} and {second} impacts");
    let speeds: Vec<f64> = (run.transitions[lift + 1..].iter())
        .map(|tr| -tr.normal_velocity[0])
        .collect();
    assert!(speeds[0] < 1e-2 && speeds[0] > 1e-3, "{speeds:?}");
}

/// A surface may move along itself (a belt), not across: a table shaken up and down is
/// refused where it is written, naming the contact, since Newton's law on a moving surface
/// needs the surface's speed in the impact law.
#[test]
fn a_surface_moving_across_itself_is_refused_where_it_is_written() {
    let text = "name: ball\nparameters: { m: 1.0, g: 9.81, e: 0.8, a: 0.01, w: 20.0 }\ncoordinates: [x, y]\npoints: { B: [x, y] }\nbodies: { ball: { mass: m, at: B } }\ngravity: [0, -g]\ncontacts:\n  table: { point: B, above: { normal: [0, 1], through: [0, a*sin(w*t)] }, restitution: e }\n";
    let Err(eomgen::LoadError::Diagnostics { diagnostics, .. }) =
        JitModel::from_source("shaken.yaml", text)
    else {
        panic!("a shaken table loaded");
    };
    assert_eq!(diagnostics.len(), 1, "{diagnostics:?}");
    let d = &diagnostics[0];
    assert_eq!((d.location.line, d.location.column), (8, 56));
    assert!(
        d.message
            .contains("contact `table`'s surface moves with `t` other than along itself"),
        "{}",
        d.message
    );
    let belt = text.replace("through: [0, a*sin(w*t)]", "through: [a*sin(w*t), 0]");
    assert!(JitModel::from_source("belt.yaml", &belt).is_ok());
}

/// A ball held inside a loop of radius `R` from its bottom at `v₀ = √(3.5 g R)` lifts off
/// where the track's normal force `m v²/R + m g cos φ` falls to 0: `φ = 120°`, at
/// `P = (R sin φ, R − R cos φ)` with `v² = 0.5 g R`, at the time `∫₀^φ R/v dφ` (Simpson's
/// rule, 20,000 panels, far below the tolerance). The run starts with the contact closed (it
/// touches and its force pushes) and matches to 1e-7 at tolerance 1e-12; the flight then
/// ends with an impact on the track.
#[test]
fn a_ball_in_a_loop_lifts_off_where_the_normal_force_vanishes() {
    use eomgen::hybrid::TransitionKind;
    let (g, r) = (9.81_f64, 1.0_f64);
    let v0 = (3.5 * g * r).sqrt();
    let phi = 2.0 * std::f64::consts::PI / 3.0;
    let speed = |p: f64| (v0 * v0 - 2.0 * g * r * (1.0 - p.cos())).sqrt();
    let panels = 20_000;
    let h = phi / panels as f64;
    let time = (0..=panels)
        .map(|k| {
            let weight = if k == 0 || k == panels {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            weight * r / speed(k as f64 * h)
        })
        .sum::<f64>()
        * h
        / 3.0;
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/loop_the_loop.yaml"
    );
    let mut model = eomgen::DynFirstOrder::new(JitModel::load(path).unwrap());
    let options = eomgen::analysis::SimulationOptions {
        t_end: 1.5,
        rtol: 1e-12,
        atol: 1e-12,
        ..Default::default()
    };
    let run = eomgen::analysis::simulate(&mut model, &options).unwrap();
    let off = &run.transitions[0];
    assert_eq!(off.kind, TransitionKind::LiftOff);
    assert!((off.t - time).abs() < 1e-7, "{} vs {time}", off.t);
    let y = run.solution.state(off.sample - 1);
    assert!((y[0] - r * phi.sin()).abs() < 1e-7 && (y[1] - r * (1.0 - phi.cos())).abs() < 1e-7);
    assert!(
        ((y[2] * y[2] + y[3] * y[3]) - 0.5 * g * r).abs() < 1e-7,
        "{y:?}"
    );
    assert!(
        run.transitions[1..]
            .iter()
            .all(|tr| tr.kind != TransitionKind::LiftOff)
    );
    assert!(run.transitions.len() >= 2, "{:?}", run.transitions);
}

/// A run of the model file `name` (under tests/fixtures/) with `method` at tolerance `tol`,
/// parameters `set`, from `initial` (or the file's) to `t_end`.
pub(crate) fn fixture_run(
    name: &str,
    method: eomgen::analysis::Method,
    (tol, t_end): (f64, f64),
    set: &[(&str, f64)],
    initial: Option<Vec<f64>>,
) -> eomgen::analysis::Simulation {
    let path = format!("{}/tests/fixtures/{name}.yaml", env!("CARGO_MANIFEST_DIR"));
    let mut model = eomgen::DynFirstOrder::new(JitModel::load(&path).unwrap());
    for (k, v) in set {
        eomgen::ModelInfo::set_parameter(&mut model, k, *v).unwrap();
    }
    let options = eomgen::analysis::SimulationOptions {
        method,
        t_end,
        rtol: tol,
        atol: tol,
        initial_state: initial,
        ..Default::default()
    };
    eomgen::analysis::simulate(&mut model, &options).unwrap()
}

/// No sample of a run is inside a contact beyond the tolerance's level (`g ≥ −1e-6` at
/// tolerance 1e-9), on runs that strike, close, lift off and strike two contacts at once,
/// with plastic and elastic impacts, for five methods (Runge–Kutta 4 at its default step):
/// a missed strike (a zero the event test cannot see, a closing decided by rounding) would
/// let the ball through.
#[test]
fn no_run_goes_through_a_contact() {
    use eomgen::analysis::Method;
    type Case<'a> = (&'a str, &'a [(&'a str, f64)], f64);
    let runs: [Case; 7] = [
        ("bouncing_ball", &[("e", 0.0)], 3.0),
        ("bouncing_ball", &[("e", 0.5)], 3.0),
        ("loop_the_loop", &[("e", 0.0)], 4.0),
        ("loop_the_loop", &[("e", 0.5)], 4.0),
        ("contacts_corner", &[], 6.0),
        ("contacts_ramp", &[], 2.0),
        ("rimless_wheel", &[], 3.0),
    ];
    for (name, set, t_end) in runs {
        for method in [
            Method::Dp54,
            Method::Dop853,
            Method::Vern7,
            Method::Radau5,
            Method::Rk4,
        ] {
            let run = fixture_run(name, method, (1e-9, t_end), set, None);
            assert!(
                run.failure.is_none() && run.contact_stop.is_none(),
                "{name} {method:?}: {:?} {:?}",
                run.failure,
                run.contact_stop
            );
            assert_eq!(run.solution.t.last(), Some(&t_end), "{name} {method:?}");
            let path = format!("{}/tests/fixtures/{name}.yaml", env!("CARGO_MANIFEST_DIR"));
            let model = eomgen::DynFirstOrder::new(JitModel::load(&path).unwrap());
            for (t, y) in run.solution.iter() {
                let gaps = eomgen::ModelInfo::contact_values(&model, t, y).gaps;
                let deepest = gaps.iter().copied().fold(f64::INFINITY, f64::min);
                assert!(
                    deepest >= -1e-6,
                    "{name} {method:?}: gap {deepest} at t = {t}"
                );
            }
        }
    }
}

/// Two walls struck at the same instant (a corner, `e = 1`, no gravity) are taken one after
/// the other: the ball leaves along the line it came in on, `(0.7, 0.7) → (−0.7, −0.7)`,
/// to 1e-12. At a ramp, the floor held through the impact would pull, so it is released:
/// `(2, 0) → (0, 2)` m/s.
#[test]
fn simultaneous_strikes_and_released_contacts() {
    use eomgen::analysis::Method;
    let run = fixture_run("contacts_corner", Method::Dop853, (1e-12, 2.0), &[], None);
    let at_corner: Vec<_> = run
        .transitions
        .iter()
        .filter(|tr| (tr.t - 1.0).abs() < 1e-9)
        .collect();
    assert_eq!(at_corner.len(), 2, "{:?}", run.transitions);
    let after = &at_corner[1].qdot[1];
    assert!(
        (after[0] + 0.7).abs() < 1e-12 && (after[1] + 0.7).abs() < 1e-12,
        "{after:?}"
    );
    let run = fixture_run("contacts_ramp", Method::Dop853, (1e-12, 0.6), &[], None);
    let ramp = &run.transitions[0];
    assert_eq!(ramp.contact, "ramp");
    assert!((ramp.t - 0.5).abs() < 1e-12);
    assert!(
        ramp.qdot[1][0].abs() < 1e-12 && (ramp.qdot[1][1] - 2.0).abs() < 1e-12,
        "{ramp:?}"
    );
}

/// Housner's rocking block (`models/rocking_block.yaml`), two shapes: the first impact comes
/// at `ω₁² = (3g/2R)(cos(α − θ₀) − cos α)` (1e-9), every impact multiplies the rate by
/// `1 − (3/2) sin² α` with the corner behind released (1e-12, over the first ten), and
/// once the impacts have accumulated the block stands on both corners where it was flat,
/// at rest (1e-8).
#[test]
fn a_rocking_block_loses_housners_ratio_at_each_impact_and_comes_to_rest() {
    use eomgen::analysis::Method;
    use eomgen::hybrid::TransitionKind;
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/models/rocking_block.yaml");
    for (b, h, theta0) in [(0.2, 0.5, 0.2), (0.3, 0.4, 0.5)] {
        let mut model = eomgen::DynFirstOrder::new(JitModel::load(path).unwrap());
        for (k, v) in [("b", b), ("h", h), ("theta0", theta0)] {
            eomgen::ModelInfo::set_parameter(&mut model, k, v).unwrap();
        }
        let options = eomgen::analysis::SimulationOptions {
            method: Method::Dop853,
            t_end: 6.0,
            rtol: 1e-12,
            atol: 1e-12,
            ..Default::default()
        };
        let run = eomgen::analysis::simulate(&mut model, &options).unwrap();
        assert!(run.contact_stop.is_none(), "{:?}", run.contact_stop);
        let (alpha, radius) = (f64::atan2(b, h), f64::hypot(b, h));
        let ratio = 1.0 - 1.5 * alpha.sin().powi(2);
        let strikes: Vec<_> = (run.transitions.iter())
            .filter(|tr| tr.normal_impulse > 0.0)
            .collect();
        let first = -(1.5 * 9.81 / radius * ((alpha - theta0).cos() - alpha.cos())).sqrt();
        assert!(
            (strikes[0].qdot[0][2] - first).abs() < 1e-9,
            "{:?}",
            strikes[0]
        );
        for (k, strike) in strikes.iter().take(10).enumerate() {
            assert_eq!(strike.kind, TransitionKind::Closes, "{strike:?}");
            let [before, after] = [strike.qdot[0][2], strike.qdot[1][2]];
            assert!(
                (after / before - ratio).abs() < 1e-12,
                "impact {k}: {} against {ratio}",
                after / before
            );
        }
        let last = run.solution.iter().last().unwrap().1;
        let rest = [b, h, 0.0, 0.0, 0.0, 0.0];
        for (value, expected) in last.iter().zip(rest) {
            assert!((value - expected).abs() < 1e-8, "{last:?}");
        }
    }
}

/// A start on the floor moving into it is an impact at the start; a run whose end time is an
/// impact's ends there (it failed on an empty time span once).
#[test]
fn an_impact_at_the_start_or_at_the_end_time() {
    use eomgen::analysis::Method;
    let run = fixture_run(
        "bouncing_ball",
        Method::Dp54,
        (1e-10, 0.1),
        &[],
        Some(vec![0.0, 0.0, 0.0, -1.0]),
    );
    let first = &run.transitions[0];
    assert_eq!(first.t, 0.0);
    assert!((first.qdot[1][1] - 0.8).abs() < 1e-14, "{first:?}");
    let t1 = (2.0_f64 / 9.81).sqrt();
    let run = ball_run(Method::Dop853, 1e-12, (0.8, 0.0), 3.0);
    let impact = run.transitions[0].t;
    assert!((impact - t1).abs() < 1e-12);
    let ended = ball_run(Method::Dop853, 1e-12, (0.8, 0.0), impact);
    assert!(ended.failure.is_none(), "{:?}", ended.failure);
    // (At the end time the gap is 0 to rounding: the impact is there or just after.)
    let (t, y) = ended.solution.last().unwrap();
    assert_eq!(t, impact);
    assert!(y[1].abs() < 1e-12, "{y:?}");
}

/// A rimless wheel (six spokes, hub inertia `I`) stepping on a slope in full coordinates:
/// each foot lands plastically and sticks, and the foot behind is released (held, sticking,
/// it would fix the wheel, so the active set starts with all released). Angular momentum about the new foot is
/// kept: `θ̇⁺/θ̇⁻ = (I + m l² cos 2α)/(I + m l²)` at every landing, to 1e-12, for `I = 0.1`
/// and `0.4` (Coleman, Chatterjee & Ruina 1997 for `I = 0`). Between landings the wheel
/// pivots on its foot: `E` plus the losses holds to 1e-9, and no foot goes below the slope.
#[test]
fn a_rimless_wheel_keeps_its_angular_momentum_about_the_new_foot() {
    use eomgen::hybrid::TransitionKind;
    let alpha = std::f64::consts::PI / 6.0;
    for inertia in [0.1, 0.4] {
        let run = fixture_run(
            "rimless_wheel",
            eomgen::analysis::Method::Dop853,
            (1e-12, 3.0),
            &[("I", inertia)],
            None,
        );
        assert!(
            run.failure.is_none() && run.contact_stop.is_none(),
            "{:?}",
            run.contact_stop
        );
        let landings: Vec<_> = (run.transitions.iter())
            .filter(|tr| tr.kind == TransitionKind::Closes)
            .collect();
        assert!(landings.len() >= 2, "{:?}", run.transitions);
        let ratio = (inertia + (2.0 * alpha).cos()) / (inertia + 1.0);
        for tr in &landings {
            let [before, after] = &tr.qdot;
            assert!((after[2] / before[2] - ratio).abs() < 1e-12, "{tr:?}");
            let released = (run.transitions.iter())
                .filter(|r| r.t == tr.t && r.kind == TransitionKind::LiftOff)
                .count();
            assert_eq!(released, 1, "{:?}", run.transitions);
        }
        assert!(run.energy.drift.unwrap() < 1e-9, "{:?}", run.energy.drift);
    }
}
