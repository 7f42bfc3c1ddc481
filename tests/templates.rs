//! `eomgen new` templates name their equilibria and state their checks: for N = 1..6 the
//! generated files load, `modes --at hanging` / `--at rest` give the closed-form (or
//! independently computed) natural frequencies, `upright` is unstable and the files' own
//! `checks:` pass (the pendulum chain is lecture 25 and HW19/HW39, the mass chain lecture 30
//! and HW23).

use crate::common;
use common::eomgen_ok;

use eomgen::analysis::vibration::{
    EquilibriumStart, ModalAnalysis, ModalOptions, OperatingPointOptions, modal_analysis,
};
use eomgen::{ModelSource, Stability};
use eomgen_symbolic::model::templates::generate;
use nalgebra::DMatrix;

/// Sizes checked.
const SIZES: std::ops::RangeInclusive<usize> = 1..=6;

/// Relative tolerance on a frequency: the linearisation is exact (generated Jacobians) and
/// the eigenvalues come from a Cholesky reduction of matrices of order ≤ 6 with entries of
/// order 1–50, so the frequencies agree to rounding (~1e-14); 1e-10 leaves a wide margin
/// while a wrong formula, entry or ordering is off by far more than 1e-3.
const FREQUENCY_TOLERANCE: f64 = 1e-10;

/// Writes template `name` of size `n` into `dir` and opens it (compiled at run time).
fn generated(dir: &std::path::Path, name: &str, n: usize) -> (std::path::PathBuf, String) {
    let text = generate(name, n).unwrap_or_else(|e| panic!("{name} {n}: {e}"));
    let path = dir.join(format!("{name}_{n}.yaml"));
    std::fs::write(&path, &text).expect("the temporary directory is writable");
    (path, text)
}

fn modes_at(source: &ModelSource, at: &str) -> ModalAnalysis {
    let model = source.instantiate();
    let options = ModalOptions {
        operating_point: OperatingPointOptions {
            start: EquilibriumStart::Named(at.to_string()),
            ..OperatingPointOptions::default()
        },
    };
    modal_analysis(model.as_ref(), &options)
        .unwrap_or_else(|e| panic!("{} at {at}: {e}", source.name()))
}

fn assert_frequencies(label: &str, computed: &[f64], expected: &[f64]) {
    assert_eq!(computed.len(), expected.len(), "{label}: {computed:?}");
    for (j, (c, e)) in computed.iter().zip(expected).enumerate() {
        assert!(
            (c - e).abs() <= FREQUENCY_TOLERANCE * e.abs().max(1.0),
            "{label}: ω{} = {c}, expected {e}",
            j + 1
        );
    }
}

/// The natural frequencies of `n` equal uniform bars (m = ℓ = 1, g = 10) hanging, computed
/// independently of the model file: `M` and `K` written by hand (`M_ii = m ℓ² (1/3 + bars
/// below i)`, `M_ij = m ℓ² (1/2 + bars below j)` for `j > i`, `K = m g ℓ diag(bars below i +
/// 1/2)`: each bar's centre of mass carries the bars below it, HW39) and `K v = ω² M v`
/// solved by nalgebra's symmetric eigensolver on `L⁻¹ K L⁻ᵀ`.
fn pendulum_frequencies_by_hand(n: usize) -> Vec<f64> {
    let (m, l, g) = (1.0, 1.0, 10.0);
    let below = |i: usize| (n - 1 - i) as f64;
    let mass = DMatrix::from_fn(n, n, |i, j| {
        let k = i.max(j);
        m * l
            * l
            * if i == j {
                1.0 / 3.0 + below(k)
            } else {
                0.5 + below(k)
            }
    });
    let stiffness = DMatrix::from_fn(n, n, |i, j| {
        if i == j {
            m * g * l * (below(i) + 0.5)
        } else {
            0.0
        }
    });
    let chol = mass.cholesky().expect("M is positive definite");
    let l_inv = chol.l().try_inverse().expect("L is invertible");
    let reduced = &l_inv * stiffness * l_inv.transpose();
    let mut squares: Vec<f64> = reduced
        .symmetric_eigen()
        .eigenvalues
        .iter()
        .copied()
        .collect();
    squares.sort_by(f64::total_cmp);
    squares.iter().map(|w2| w2.sqrt()).collect()
}

/// The closed forms the pendulum files state for n ≤ 3, written here again (g = 10, ℓ = 1).
fn pendulum_closed_form(n: usize) -> Option<Vec<f64>> {
    let g: f64 = 10.0;
    match n {
        1 => Some(vec![(1.5 * g).sqrt()]),
        2 => Some(vec![
            (g * (3.0 - 6.0 / 7f64.sqrt())).sqrt(),
            (g * (3.0 + 6.0 / 7f64.sqrt())).sqrt(),
        ]),
        3 => Some(vec![
            (g * (291.0 - 3.0 * 7849f64.sqrt()) / 52.0).sqrt(),
            (3.0 * g).sqrt(),
            (g * (291.0 + 3.0 * 7849f64.sqrt()) / 52.0).sqrt(),
        ]),
        _ => None,
    }
}

/// The pendulum chains: `hanging` has the closed-form frequencies (n ≤ 3) and those of the
/// hand-written `M`, `K` (every n); `upright` is unstable with every mode growing (`K`
/// negative definite there: each bar's weight pulls it over).
#[test]
fn pendulum_chains_hang_stably_and_topple_from_upright() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for n in SIZES {
        let (path, _) = generated(dir.path(), "n-link-pendulum", n);
        let source = ModelSource::open(path.to_str().unwrap()).expect("the file loads");
        let equilibria: Vec<String> = source
            .instantiate()
            .description()
            .equilibria
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(equilibria, ["hanging", "upright"], "n = {n}");

        let hanging = modes_at(&source, "hanging");
        let label = format!("n = {n} hanging");
        assert!(
            hanging
                .operating_point
                .q()
                .iter()
                .all(|q| (q + std::f64::consts::FRAC_PI_2).abs() < 1e-12),
            "{label}: q* = {:?}",
            hanging.operating_point.q()
        );
        let computed = &hanging.normal_modes.natural_frequencies;
        assert_frequencies(&label, computed, &pendulum_frequencies_by_hand(n));
        if let Some(closed) = pendulum_closed_form(n) {
            assert_frequencies(&label, computed, &closed);
        }
        assert!(
            matches!(hanging.stability.stability, Stability::MarginallyStable),
            "{label}: {:?}",
            hanging.stability.stability
        );

        let upright = modes_at(&source, "upright");
        assert!(
            upright
                .operating_point
                .q()
                .iter()
                .all(|q| (q - std::f64::consts::FRAC_PI_2).abs() < 1e-12),
            "n = {n} upright: q* = {:?}",
            upright.operating_point.q()
        );
        let Stability::Unstable { growth_rate } = upright.stability.stability else {
            panic!("n = {n}: upright is {:?}", upright.stability.stability);
        };
        // Upright, K → −K: the growth rates are the hanging frequencies (M is the same).
        let fastest = computed.last().unwrap();
        assert!(
            (growth_rate - fastest).abs() <= FREQUENCY_TOLERANCE * fastest,
            "n = {n}: growth rate {growth_rate}, hanging's largest ω {fastest}"
        );
    }
}

/// The mass chains: `rest` has `ω_j = 2√(k/m) sin(jπ/(2(n + 1)))` (k = m = 1).
#[test]
fn mass_chains_have_the_closed_form_frequencies() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for n in SIZES {
        let (path, _) = generated(dir.path(), "n-mass-chain", n);
        let source = ModelSource::open(path.to_str().unwrap()).expect("the file loads");
        let rest = modes_at(&source, "rest");
        let expected: Vec<f64> = (1..=n)
            .map(|j| 2.0 * (j as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64)).sin())
            .collect();
        assert_frequencies(
            &format!("n = {n} rest"),
            &rest.normal_modes.natural_frequencies,
            &expected,
        );
        assert!(rest.operating_point.q().iter().all(|q| q.abs() < 1e-12));
    }
}

/// The universal-joint chains (issue 52): about `hanging` (every angle 0) a chain of slender
/// bars in universal joints is two planar chains of uniform bars, one per joint axis (the
/// spin about a bar's axis and its inertia `m w²/6` enter at second order), so its
/// frequencies are [`pendulum_frequencies_by_hand`]'s, each twice; the hanging chain is
/// stable. For N = 1…4 (8 coordinates): the derivation of 3-D bodies nested `2N` rotations
/// deep, linearised, against `M` and `K` written by hand for the planar chain.
#[test]
fn universal_joint_chains_hang_with_the_planar_chains_frequencies_twice() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for n in 1..=4 {
        let (path, _) = generated(dir.path(), "universal-joint-chain", n);
        let source = ModelSource::open(path.to_str().unwrap()).expect("the file loads");
        let hanging = modes_at(&source, "hanging");
        let label = format!("n = {n} hanging");
        assert!(hanging.operating_point.q().iter().all(|q| q.abs() < 1e-12));
        let twice: Vec<f64> = pendulum_frequencies_by_hand(n)
            .into_iter()
            .flat_map(|w| [w, w])
            .collect();
        assert_frequencies(&label, &hanging.normal_modes.natural_frequencies, &twice);
        assert!(
            matches!(hanging.stability.stability, Stability::MarginallyStable),
            "{label}: {:?}",
            hanging.stability.stability
        );
    }
}

/// Every generated file's own checks pass (`eomgen report`'s rows: the derivations agree,
/// energy is conserved, the stated frequencies are met), and each states what it should: the
/// frequencies where a closed form exists, else the energy drift.
#[test]
fn generated_files_pass_their_checks() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    // The universal-joint chain to 3 joints (6 coordinates of 3-D bodies: its energy-drift
    // run is the slowest of these in a debug build).
    for (template, sizes) in [
        ("n-link-pendulum", SIZES),
        ("n-mass-chain", SIZES),
        ("universal-joint-chain", 1..=3),
    ] {
        for n in sizes {
            let (path, text) = generated(dir.path(), template, n);
            let path = path.to_str().unwrap();
            let file = eomgen_symbolic::model::load(path, &text).expect("the file loads");
            let source = ModelSource::open(path).expect("the file compiles");
            let report = eomgen::checks::model_report(path, &text, &file, &source);
            for row in &report.rows {
                assert!(
                    row.passed,
                    "{template} {n}: {}: {:?}",
                    row.check,
                    row.failure_reason()
                );
            }
            let frequencies = report
                .rows
                .iter()
                .filter(|r| r.check.starts_with("natural_frequencies"))
                .count();
            let closed_form = template == "n-mass-chain" || n <= 3;
            // Two angles per universal joint.
            let coordinates = if template == "universal-joint-chain" {
                2 * n
            } else {
                n
            };
            assert_eq!(
                frequencies,
                if closed_form { coordinates } else { 0 },
                "{template} {n}: frequency rows"
            );
            assert!(
                report
                    .rows
                    .iter()
                    .any(|r| r.check.starts_with("energy drift")),
                "{template} {n}: no energy drift row"
            );
        }
    }
}

/// The CLI: `eomgen new` prints the file, and `eomgen modes FILE` on it needs no `--at`
/// (the first named equilibrium is `hanging`).
#[test]
fn modes_runs_on_a_generated_file_without_at() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let out = eomgen_ok(&["new", "n-link-pendulum", "2"]);
    let path = dir.path().join("pendulum_2.yaml");
    std::fs::write(&path, &out.stdout).unwrap();
    let out = eomgen_ok(&["modes", path.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let omega: Vec<f64> = v["natural_frequencies"]
        .as_array()
        .expect("natural_frequencies")
        .iter()
        .map(|w| w.as_f64().unwrap())
        .collect();
    assert_frequencies("CLI n = 2", &omega, &pendulum_closed_form(2).unwrap());
    assert_eq!(v["operating_point"]["name"], "hanging", "{v}");
}
