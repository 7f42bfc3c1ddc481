//! Gaits through changes of support (`support:`): the rimless wheel's steady rolling and the
//! eigenvalue of its return map against their closed forms (two spoke counts and slopes), the
//! return map's Jacobian (variational equations and saltation matrices) against central
//! differences of the map itself, and Garcia's simplest walker against the limit equations
//! integrated by SciPy (tools/simplest_walker_reference.py).

use eomgen::analysis::{GaitOptions, Method, SimulationOptions, gait, return_map, simulate};
use eomgen::hybrid::TransitionKind;
use eomgen::{DynFirstOrder, JitModel, ModelInfo};

/// The bundled model `name` with `set` applied.
fn model(name: &str, set: &[(&str, f64)]) -> DynFirstOrder<JitModel> {
    let path = format!("{}/models/{name}.yaml", env!("CARGO_MANIFEST_DIR"));
    let mut model = DynFirstOrder::new(JitModel::load(&path).unwrap());
    for (k, v) in set {
        model.set_parameter(k, *v).unwrap();
    }
    model
}

/// The rimless wheel's steady rolling (a point-mass hub): each step starts at `θ = −α` with
/// `ω* = cot 2α √(4 (g/l) sin α sin γ)`, and the return map's eigenvalue is `cos² 2α`
/// (Coleman, Chatterjee & Ruina 1997), for eight spokes on γ = 0.1 and six on γ = 0.2, from
/// a start 30 % off. Tolerance 1e-9 (Newton's 1e-10, DOP853 at 1e-12).
#[test]
fn the_rimless_wheel_rolls_at_the_closed_form_rate_and_its_eigenvalue_is_cos_squared_two_alpha() {
    let (g, l) = (9.81, 1.0);
    for (spokes, gamma) in [(8.0, 0.1), (6.0, 0.2)] {
        let alpha = std::f64::consts::PI / spokes;
        let mut wheel = model("rimless_wheel", &[("alpha", alpha), ("gamma", gamma)]);
        let omega = (4.0 * g / l * alpha.sin() * gamma.sin()).sqrt() / (2.0 * alpha).tan();
        let options = GaitOptions {
            start: Some(vec![-alpha, 1.3 * omega]),
            ..GaitOptions::default()
        };
        let found = gait(&mut wheel, &options).unwrap();
        assert!((found.state[0] + alpha).abs() < 1e-9, "{:?}", found.state);
        assert!(
            (found.state[1] - omega).abs() < 1e-9 * omega,
            "{} vs {omega}",
            found.state[1]
        );
        let expected = (2.0 * alpha).cos().powi(2);
        let lambda = found.eigenvalues[0];
        assert!(
            (lambda.re - expected).abs() < 1e-9 && lambda.im.abs() < 1e-9,
            "{lambda}"
        );
        assert!(
            found.eigenvalues[1].norm() < 1e-9,
            "{:?}",
            found.eigenvalues
        );
        // The monodromy's multipliers: 1 (the flow) and the same cos² 2α.
        let mut moduli: Vec<f64> = found.floquet_multipliers.iter().map(|m| m.norm()).collect();
        moduli.sort_by(f64::total_cmp);
        assert!((moduli[0] - expected).abs() < 1e-9 && (moduli[1] - 1.0).abs() < 1e-9);
        assert!(found.stability.is_stable());
        // The landing loses what gravity gave over the step: m g sin γ · 2 l sin α.
        let work = g * gamma.sin() * 2.0 * l * alpha.sin();
        let lost = found.energy_lost[0];
        assert!((lost - work).abs() < 1e-9 * work, "{lost} vs {work}");
    }
}

/// Central differences of `P` about `y` (step `h`), column by column.
fn central_differences(model: &mut dyn ModelInfo, y: &[f64], h: f64) -> Vec<Vec<f64>> {
    let options = GaitOptions::default();
    let mut stats = Default::default();
    (0..y.len())
        .map(|k| {
            let mut shifted = [y.to_vec(), y.to_vec()];
            shifted[0][k] += h;
            shifted[1][k] -= h;
            let [plus, minus] = shifted.map(|s| {
                return_map(model, &s, &options, &mut stats)
                    .unwrap_or_else(|e| panic!("{s:?}: {e}"))
                    .end
            });
            plus.iter()
                .zip(&minus)
                .map(|(p, m)| (p - m) / (2.0 * h))
                .collect()
        })
        .collect()
}

/// The return map's Jacobian from the variational equations and the saltation matrices
/// agrees with central differences of the map (step 1e-5, error `O(h²)` and `ε/h`) to 1e-6
/// relative to its largest entry, off the gait and on it, for the rimless wheel and for the
/// simplest walker (whose step passes a scuff and lands at a heel strike).
#[test]
fn the_saltation_jacobian_matches_central_differences_of_the_return_map() {
    type Case<'a> = (&'a str, &'a [(&'a str, f64)], Vec<f64>);
    let cases: [Case; 3] = [
        ("rimless_wheel", &[], vec![-0.39, 1.5]),
        (
            "simplest_walker",
            &[],
            vec![0.2003, 0.4006, -0.1998, -0.0158],
        ),
        (
            "simplest_walker",
            &[("beta", 1e-3)],
            vec![0.1985, 0.3970, -0.1985, -0.0154],
        ),
    ];
    for (name, set, y) in cases {
        let mut m = model(name, set);
        let mut stats = Default::default();
        let exact = return_map(&mut m, &y, &GaitOptions::default(), &mut stats).unwrap();
        let differences = central_differences(&mut m, &y, 1e-5);
        let scale = exact.return_map.amax();
        for (k, column) in differences.iter().enumerate() {
            for (i, d) in column.iter().enumerate() {
                let e = exact.return_map[(i, k)];
                assert!(
                    (e - d).abs() < 1e-6 * scale,
                    "{name} {set:?}: ∂P{i}/∂y{k} = {e} by saltation, {d} by differences"
                );
            }
        }
    }
}

/// Garcia's simplest walker at γ = 0.009 (feet of mass 1e-9 of the hip's for the paper's
/// limit): the long-period gait and its eigenvalues against the limit's own equations
/// integrated by SciPy (tools/simplest_walker_reference.py, whose eigenvalues come from
/// central differences, good to about 1e-7): state to 1e-8, period to 1e-8, eigenvalues to
/// 1e-6.
#[test]
fn the_simplest_walker_walks_garcias_gait_with_its_eigenvalues() {
    let mut walker = model("simplest_walker", &[]);
    let found = gait(&mut walker, &GaitOptions::default()).unwrap();
    let reference = [
        0.2003109005442575,
        0.400621801088515,
        -0.1998324730049286,
        -0.015822999948309113,
    ];
    for (y, r) in found.state.iter().zip(reference) {
        assert!((y - r).abs() < 1e-8, "{:?}", found.state);
    }
    assert!(
        (found.period - 3.8824637528542985).abs() < 1e-8,
        "{}",
        found.period
    );
    let lambda = found.eigenvalues[0];
    assert!((lambda.re + 0.19009983955098966).abs() < 1e-6, "{lambda}");
    assert!(
        (lambda.im.abs() - 0.5575987834114509).abs() < 1e-6,
        "{lambda}"
    );
    assert!(
        found.eigenvalues[2].norm() < 1e-6,
        "{:?}",
        found.eigenvalues
    );
    assert!(found.stability.is_stable());
    // Over one step of a periodic gait the heel strike loses what gravity gave: the total
    // mass times g sin γ times the centre of mass's advance, one step length 2 l sin θ*.
    let (beta, gamma) = (1e-9, 0.009_f64);
    let work = (1.0 + 2.0 * beta) * gamma.sin() * 2.0 * found.state[0].sin();
    assert!(
        (found.energy_lost[0] - work).abs() < 1e-12,
        "{} vs {work}",
        found.energy_lost[0]
    );
}

/// A run of the rimless wheel through its landings (`simulate`): each landing keeps the
/// angular momentum about the new foot (`θ̇⁺ = cos 2α θ̇⁻` for a point-mass hub, to 1e-12),
/// loses `½ m l² (1 − cos² 2α) θ̇⁻²`, and `T + V` with the losses and the datum's moves
/// added is conserved to the tolerance's level.
#[test]
fn a_run_of_the_rimless_wheel_keeps_the_angular_momentum_about_each_new_foot() {
    let mut wheel = model("rimless_wheel", &[]);
    let alpha = std::f64::consts::PI / 8.0;
    let options = SimulationOptions {
        method: Method::Dop853,
        t_end: 5.0,
        rtol: 1e-10,
        atol: 1e-10,
        ..Default::default()
    };
    let run = simulate(&mut wheel, &options).unwrap();
    let landings: Vec<_> = (run.transitions.iter())
        .filter(|tr| tr.kind == TransitionKind::SupportChange)
        .collect();
    assert_eq!(landings.len(), 6);
    for tr in landings {
        let (before, after) = (tr.qdot[0][0], tr.qdot[1][0]);
        assert!((after - (2.0 * alpha).cos() * before).abs() < 1e-12 * before);
        let lost = 0.5 * (1.0 - (2.0 * alpha).cos().powi(2)) * before * before;
        assert!(
            (tr.energy_lost - lost).abs() < 1e-12,
            "{} vs {lost}",
            tr.energy_lost
        );
    }
    assert!(run.energy.drift.unwrap() < 1e-8, "{:?}", run.energy.drift);
}

/// The simplest walker's gait followed over the slope loses its stability by a period
/// doubling (an eigenvalue through −1) at γ = 0.0150884 (Garcia et al. 1998: "about
/// 0.0151"), located by bisection to 1e-7 of the limit equations' own (SciPy, with
/// eigenvalues by central differences: tools/simplest_walker_reference.py).
#[test]
fn the_simplest_walkers_gait_period_doubles_near_gamma_0_0151() {
    use eomgen::analysis::vibration::SweepAxis;
    use eomgen::analysis::{GaitBifurcation, gait_sweep};
    let mut walker = model("simplest_walker", &[]);
    let axis = SweepAxis::linear("gamma", 0.009, 0.017, 5).unwrap();
    let sweep = gait_sweep(&mut walker, &axis, &GaitOptions::default(), |_, _| {}).unwrap();
    assert!(
        sweep.points.iter().all(|p| p.error.is_none()),
        "{:?}",
        sweep.points
    );
    let [change] = sweep.stability_changes.as_slice() else {
        panic!("{:?}", sweep.stability_changes);
    };
    assert_eq!(change.kind, GaitBifurcation::PeriodDoubling);
    assert!(change.stable_below);
    assert!(
        (change.value - 0.015088438009377567).abs() < 1e-7,
        "{}",
        change.value
    );
    assert!(
        (change.eigenvalue[0] + 1.0).abs() < 1e-4,
        "{:?}",
        change.eigenvalue
    );
    // The parameter is restored.
    assert_eq!(walker.parameter_values()[4], 0.009);
}

/// Mistakes a change of support can only show once the model is lowered get located
/// errors: a `relabel` that is not an invertible affine map, and a model with constraints.
#[test]
fn a_change_of_support_that_cannot_be_derived_is_refused_where_it_is_written() {
    for (name, line, column, message) in [
        (
            "broken-support-relabel-not-affine",
            10,
            73,
            "its `relabel` is not an invertible affine map of the coordinates",
        ),
        (
            "broken-support-with-constraints",
            10,
            73,
            "but the model has constraints",
        ),
    ] {
        let path = format!("{}/tests/fixtures/{name}.yaml", env!("CARGO_MANIFEST_DIR"));
        let Err(eomgen::LoadError::Diagnostics { diagnostics, .. }) = JitModel::load(&path) else {
            panic!("{name} loaded");
        };
        assert_eq!(diagnostics.len(), 1, "{diagnostics:?}");
        let d = &diagnostics[0];
        assert!(d.message.contains(message), "{name}: {}", d.message);
        assert_eq!(
            (d.location.line, d.location.column),
            (line, column),
            "{name}"
        );
    }
}

/// Goswami, Thuilot & Espiau's compass gait (m = 5 kg legs, M = 10 kg hip, a = b = 0.5 m) on
/// 3°: its stable period-one gait and eigenvalues against a derivation of its own (SymPy's
/// Lagrange equations and the heel strike from the two angular-momentum conditions written
/// by hand, SciPy's DOP853 at 1e-13: tools/compass_gait_reference.py, whose eigenvalues are by
/// central differences), from a start off it with Newton to 1e-12: the state and period to
/// 1e-10, the eigenvalues to 1e-7, the energy lost to 1e-10 (it is also the work of gravity
/// over the step). Goswami et al. give the
/// gait's leg angles from the vertical as 0.218 and −0.323 rad, and its rates −1.091 and
/// −0.377 rad/s.
#[test]
fn the_compass_gait_walks_goswamis_gait() {
    let mut walker = model("compass_gait", &[]);
    // From a start off the gait (the file starts on it).
    let options = GaitOptions {
        start: Some(vec![0.26, 0.53, -1.0, -0.6]),
        tol: 1e-12,
        ..GaitOptions::default()
    };
    let found = gait(&mut walker, &options).unwrap();
    assert!(found.iterations >= 3, "{:?}", found.residuals);
    let reference = [
        0.2710286804988182,
        0.5420573609976364,
        -1.092383589883546,
        -0.7150096409764602,
    ];
    for (y, r) in found.state.iter().zip(reference) {
        assert!((y - r).abs() < 1e-10, "{:?}", found.state);
    }
    assert!(
        (found.period - 0.7343463911587371).abs() < 1e-10,
        "{}",
        found.period
    );
    let expected = [
        (-0.19972612605643097, 0.5444760621133835),
        (0.131572622356698, 0.0),
    ];
    let lambda = found.eigenvalues[0];
    assert!((lambda.re - expected[0].0).abs() < 1e-7, "{lambda}");
    assert!((lambda.im.abs() - expected[0].1).abs() < 1e-7, "{lambda}");
    let third = found.eigenvalues[2];
    assert!(
        (third.re - expected[1].0).abs() < 1e-7 && third.im == 0.0,
        "{third}"
    );
    assert!(
        (found.energy_lost[0] - 5.498121984723131).abs() < 1e-10,
        "{:?}",
        found.energy_lost
    );
    // The leg angles from the vertical: θ − γ and −θ − γ (γ = 3°).
    let gamma = std::f64::consts::PI / 60.0;
    assert!(
        (found.state[0] - gamma - 0.218).abs() < 1e-3
            && (-found.state[0] - gamma + 0.323).abs() < 1e-3
    );
    assert!(found.stability.is_stable());
}

/// Past the period doubling the simplest walker's swing foot can pass over the stance foot
/// with the stance leg past the normal (the legs crossing at φ = 0): that zero of the foot's
/// height is no landing (a foot within 1e-6 of the walker's size of the stance foot passes),
/// so the walk goes on, every landing a step of at least 0.3 leg lengths.
#[test]
fn a_swing_foot_passing_over_the_stance_foot_does_not_land() {
    let mut walker = model("simplest_walker", &[("gamma", 0.0165)]);
    let options = SimulationOptions {
        method: Method::Dop853,
        t_end: 30.0,
        rtol: 1e-10,
        atol: 1e-10,
        ..Default::default()
    };
    let run = simulate(&mut walker, &options).unwrap();
    assert!(run.contact_stop.is_none(), "{:?}", run.contact_stop);
    let steps: Vec<f64> = (run.transitions.iter())
        .filter_map(|tr| tr.foot.map(|f| f[0].hypot(f[1])))
        .collect();
    assert!(steps.len() >= 6, "{steps:?}");
    assert!(steps.iter().all(|&s| s > 0.3), "{steps:?}");
}
