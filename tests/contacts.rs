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
