//! Unilateral contacts (`contacts:`) as the model's functions: gaps, their rates, Jacobian and
//! coefficients against closed forms, the same bits from `model!`, the run-time compiler's
//! native code and its interpreter; and an impact computed from them
//! (`hybrid::impact`) against Newton's law.

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

/// `[g; ġ]`, `G` and the coefficients of a model at `(q, q̇)`.
fn contact_functions(model: &dyn DynMechanicalSystem, q: &[f64], qdot: &[f64]) -> [Vec<f64>; 3] {
    let m = model.description().contacts.len();
    let mut gaps = vec![f64::NAN; 2 * m];
    let mut jacobian = vec![f64::NAN; 2 * m * 2];
    let mut coefficients = vec![f64::NAN; 2 * m];
    model.contact_gaps(q, qdot, 0.0, &mut gaps);
    model.contact_jacobian(q, 0.0, &mut jacobian);
    model.contact_coefficients(&mut coefficients);
    [gaps, jacobian, coefficients]
}

/// The closed forms at `q = (x, y)`, `q̇ = (ẋ, ẏ)`: the floor `g = y` (its normal `[0, 2]`
/// scaled to unit length), the shelf `g = y + R/2`, the bowl `g = R − |P − C|`, `C = (0, R)`,
/// `ġ = −(P − C)·Ṗ/|P − C|`; the floor's slip `T = t̂ = (−1, 0)` (its normal turned a
/// quarter-turn), the others frictionless.
fn closed_forms(q: [f64; 2], qdot: [f64; 2]) -> [Vec<f64>; 3] {
    let [x, y] = q;
    let (dx, dy) = (x, y - R);
    let d = dx.hypot(dy);
    let bowl_row = [-dx / d, -dy / d];
    let bowl_rate = bowl_row[0] * qdot[0] + bowl_row[1] * qdot[1];
    [
        vec![y, y + R / 2.0, R - d, qdot[1], qdot[1], bowl_rate],
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
        vec![E, MU, 1.0, 0.0, 0.0, 0.0],
    ]
}

/// At a few states, the contact functions of the file compiled at run time (native code and
/// interpreter) and by `model!` equal each other to the bit and the closed forms to 1e-15
/// (relative to 1, the size of the terms).
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
                    (a - b).abs() <= 1e-15,
                    "part {part} at {q:?}: {g:?} vs {x:?}"
                );
            }
        }
        let mut from_macro = [vec![0.0; 6], vec![0.0; 12], vec![0.0; 6]];
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
    let mut coefficients = [0.0; 6];
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

/// Past the accumulation time the run stops at the contact, where the impacts accumulate:
/// the stop time plus the closed form of the flights left after it, `(2 e |ġ⁻|/g)/(1 − e)`,
/// is `t∞` to 1e-8 s, for `e = 0.5` and `0.8`. A plastic ball (`e = 0`) stops at its first
/// impact, at `t₁`, having lost all its vertical energy `m g h`.
#[test]
fn impacts_accumulate_at_the_zeno_time_and_a_plastic_ball_stays_down() {
    for e in [0.5, 0.8] {
        let (_, t_inf) = ball_times(e, 1);
        let run = ball_run(eomgen::analysis::Method::Dp54, 1e-12, (e, 0.0), 6.0);
        let Some(eomgen::hybrid::ContactStop::Closed {
            t,
            speed,
            accumulating: true,
            ..
        }) = run.contact_stop
        else {
            panic!("{:?}", run.contact_stop);
        };
        let left = 2.0 * e * speed / 9.81 / (1.0 - e);
        assert!(
            (t + left - t_inf).abs() < 1e-8,
            "e = {e}: {t} + {left} vs {t_inf}"
        );
    }
    let (times, _) = ball_times(0.0, 1);
    let run = ball_run(eomgen::analysis::Method::Dp54, 1e-12, (0.0, 0.0), 3.0);
    assert!(matches!(
        run.contact_stop,
        Some(eomgen::hybrid::ContactStop::Closed {
            accumulating: false,
            ..
        })
    ));
    assert_eq!(run.transitions.len(), 1);
    assert!((run.transitions[0].t - times[0]).abs() < 1e-9);
    assert!((run.transitions[0].energy_lost - 9.81).abs() < 1e-9);
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
