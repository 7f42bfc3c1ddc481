//! Steady motions of 3-D rigid bodies and non-holonomic models, their linearisation
//! restricted to the constraints, and the stability changes of a parameter sweep (issue 30,
//! items 4 and 5), against closed forms.

mod common;
use common::eomgen_ok;

use eomgen::ModelInfo;
use eomgen::analysis::vibration::{
    self, Crossing, Direction, EquilibriumStart, OperatingPointOptions, ParameterSweepOptions,
    SweepAxis,
};
use nalgebra::Complex;

fn model(name: &str) -> Box<dyn ModelInfo> {
    (eomgen::models::find(name).expect("bundled model").make)()
}

fn fixture(name: &str) -> String {
    format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn fixture_model(name: &str) -> Box<dyn ModelInfo> {
    eomgen::ModelSource::open(&fixture(name))
        .expect("fixture loads")
        .instantiate()
}

fn at(name: &str) -> OperatingPointOptions {
    OperatingPointOptions {
        start: EquilibriumStart::Named(name.to_string()),
        ..OperatingPointOptions::default()
    }
}

/// The eigenvalues of the steady motion `point` of `model`, with its reduced states.
fn steady(model: &mut dyn ModelInfo, point: &str) -> (Vec<Complex<f64>>, Vec<String>) {
    let a = vibration::steady_motion_analysis(model, &at(point)).expect("steady motion");
    (a.eigenvalues, a.linearization.states)
}

/// Whether `values` holds `s` to `tol` (absolute).
fn holds(values: &[Complex<f64>], s: Complex<f64>, tol: f64) -> bool {
    values.iter().any(|v| (v - s).norm() <= tol)
}

/// A torque-free body spinning at Ω about its z axis (`free_rigid_body --at spin_z`): about
/// the axis of largest or smallest moment it oscillates at `Ω √((I3 − I1)(I3 − I2)/(I1 I2))`,
/// about the intermediate one it diverges at `Ω √((I3 − I1)(I2 − I3)/(I1 I2))` (Euler's
/// equations; Landau & Lifshitz §37). The angles are measured from a frame turning with φ,
/// so a tilt of the spin axis fixed in space shows as a further pair `±iΩ`. The Jacobian is
/// exact, so 1e-12.
#[test]
fn a_spinning_body_is_stable_about_its_extreme_axes_only() {
    let mut m = model("free_rigid_body");
    let (i1, i2, omega): (f64, f64, f64) = (1.0, 2.0, 1.0);
    for i3 in [3.0, 0.5, 1.5] {
        m.set_parameter("I3", i3).unwrap();
        let (s, states) = steady(m.as_mut(), "spin_z");
        assert_eq!(states, ["theta", "psi", "theta_dot", "psi_dot"]);
        let product = (i3 - i1) * (i3 - i2) / (i1 * i2);
        let expected = if product > 0.0 {
            Complex::new(0.0, omega * product.sqrt())
        } else {
            Complex::new(omega * (-product).sqrt(), 0.0)
        };
        assert!(holds(&s, expected, 1e-12), "I3 = {i3}: {s:?}");
        assert!(
            holds(&s, Complex::new(0.0, omega), 1e-12),
            "I3 = {i3}: {s:?}"
        );
    }
}

/// The Chaplygin sleigh moving straight at v (`chaplygin_sleigh --at straight`): one
/// eigenvalue `−m d v/(I + m d²)` (Neimark & Fufaev), stable forward, unstable backward, the
/// position and heading left out as ignorable and the speed as constant. Differenced
/// Jacobian: 1e-9.
#[test]
fn the_sleigh_is_stable_forward_and_unstable_backward() {
    let mut m = model("chaplygin_sleigh");
    let (mass, inertia, d) = (1.0, 0.1, 0.5);
    for v in [1.0, 2.5, -1.0] {
        m.set_parameter("v0", v).unwrap();
        let a = vibration::steady_motion_analysis(m.as_mut(), &at("straight")).unwrap();
        assert_eq!(a.linearization.states, ["theta_dot"]);
        assert_eq!(a.linearization.ignorable_coordinates, ["x", "y", "theta"]);
        assert_eq!(a.linearization.constant_rates, ["x_dot"]);
        let expected = -mass * d * v / (inertia + mass * d * d);
        assert_eq!(a.eigenvalues.len(), 1);
        assert!(
            (a.eigenvalues[0].re - expected).abs() <= 1e-9 * expected.abs(),
            "v = {v}: {:?} against {expected}",
            a.eigenvalues
        );
        assert_eq!(
            a.stability.name(),
            if v > 0.0 { "stable" } else { "unstable" }
        );
    }
}

/// The heavy top in steady precession (`heavy_top --at precessing`): θ nutates at
/// `√(U''(θ₀)/I1)` of Routh's effective potential, 48.27354292655364 rad/s
/// (`tools/rigid_body_reference.py`, mpmath at 40 digits); the conserved momenta of φ and ψ
/// give two zeros. Exact Jacobian: 1e-9 relative.
#[test]
fn a_precessing_top_nutates_at_the_routh_frequency() {
    let mut m = model("heavy_top");
    let (s, _) = steady(m.as_mut(), "precessing");
    assert!(
        holds(&s, Complex::new(0.0, 48.27354292655364), 48.3e-9),
        "{s:?}"
    );
    assert_eq!(s.iter().filter(|v| v.norm() == 0.0).count(), 2, "{s:?}");
}

/// The sleeping top (`tests/fixtures/sleeping_top.yaml`): the sweep over the spin finds
/// the classical bound `ω₃ = 2 √(I1 m g l)/I3 = 28.014282071829 rad/s` (I1 about the point)
/// as one stabilising change where a complex quadruplet reaches the axis, to 1e-10
/// relative; at 40 rad/s the eigenvalues are `±i [I3 ω₃ ± √(I3² ω₃² − 4 I1 m g l)]/(2 I1)`.
#[test]
fn the_sleeping_top_bound_is_found_by_the_sweep() {
    let mut m = fixture_model("sleeping_top.yaml");
    let (mass, g, l, i1, i3): (f64, f64, f64, f64, f64) = (1.0, 9.81, 0.1, 0.02, 0.01);
    let (s, _) = steady(m.as_mut(), "sleeping");
    let w3: f64 = 40.0;
    let root = (i3 * i3 * w3 * w3 - 4.0 * i1 * mass * g * l).sqrt();
    for w in [(i3 * w3 + root) / (2.0 * i1), (i3 * w3 - root) / (2.0 * i1)] {
        assert!(holds(&s, Complex::new(0.0, w), 1e-12 * w), "{s:?}");
    }
    let options = ParameterSweepOptions {
        axis: SweepAxis::linear("w3", 10.0, 50.0, 9).unwrap(),
        operating_point: at("sleeping"),
        refine: true,
    };
    let sweep = vibration::parameter_sweep(m.as_mut(), &options, |_, _| {}).unwrap();
    let bound = 2.0 * (i1 * mass * g * l).sqrt() / i3;
    assert_eq!(
        sweep.stability_changes.len(),
        1,
        "{:?}",
        sweep.stability_changes
    );
    let change = &sweep.stability_changes[0];
    assert!(
        (change.value - bound).abs() <= 1e-10 * bound,
        "{} against {bound}",
        change.value
    );
    assert_eq!(change.eigenvalue, Crossing::Complex);
    assert_eq!(change.direction, Direction::Stabilising);
    // The parameter is back at its value.
    assert_eq!(m.parameter_values()[5], 40.0);
}

/// `study parameter-sweep --json` is the library's sweep: the sleigh's change of stability
/// at v0 = 0 (to the 1e-10 below which its turning rate counts as constant), real and
/// stabilising; `modes --json` at a steady motion reports `damped_modes` and the verdict.
#[test]
fn the_cli_reports_sweeps_and_steady_modes_as_json() {
    let out = eomgen_ok(&[
        "study",
        "parameter-sweep",
        "chaplygin_sleigh",
        "--at",
        "straight",
        "--parameter",
        "v0",
        "--values",
        "-1..1:4",
        "--json",
    ]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let changes = json["stability_changes"].as_array().unwrap();
    assert_eq!(changes.len(), 1, "{json}");
    assert!(changes[0]["value"].as_f64().unwrap().abs() < 1e-9, "{json}");
    assert_eq!(changes[0]["eigenvalue"], "real");
    assert_eq!(changes[0]["direction"], "stabilising");
    assert_eq!(json["points"].as_array().unwrap().len(), 4);
    let out = eomgen_ok(&["modes", "chaplygin_sleigh", "--at", "straight", "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let re = json["damped_modes"][0]["re"].as_f64().unwrap();
    assert!((re + 0.5 / 0.35).abs() < 1e-9, "{json}");
    assert_eq!(json["stability"]["verdict"], "stable");
    assert_eq!(json["operating_point"]["qdot"]["x_dot"], 1.0);
}
