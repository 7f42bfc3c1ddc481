//! Every bundled model: the generated code equals the symbolic engine's own evaluation of the
//! same expressions, the mass matrix is symmetric positive definite, and the model simulates.
//!
//! The engine side re-derives each model at test run time from its YAML file (load → lower →
//! Lagrange → Jacobians) and evaluates the expression DAG directly, with no code generation,
//! printing or CSE in between; the generated side is the model the program runs (its file
//! compiled at run time) and, for the models of `compiled_models`, the code of `model!` too.

use crate::common;
use common::seeded_rng;
use rand::RngExt;

use eomgen::models::ALL;
use eomgen::{DormandPrince54, Integrator, IntegratorOptions, OutputTimes};
use eomgen_symbolic::expr::SymbolKind;
use eomgen_symbolic::expr::eval::Evaluator;
use eomgen_symbolic::mechanics::{Formulation, Jacobians, Lagrange, SymbolicModel};

/// Agreement to 1e-9 relative to the larger magnitude (or 1): both sides evaluate the same
/// expressions in f64, differing only in the order of operations after CSE, so they agree to
/// a few ulps times the condition of the sums; any wrong term is off by O(1).
fn assert_close(what: &str, model: &str, generated: f64, engine: f64) {
    // Outside a model's domain (simple_pendulum_y at |y| > l) both sides are NaN.
    if generated.is_nan() && engine.is_nan() {
        return;
    }
    let scale = 1f64.max(generated.abs()).max(engine.abs());
    assert!(
        (generated - engine).abs() <= 1e-9 * scale,
        "{model}: {what}: generated {generated} vs engine {engine}"
    );
}

/// Whether `y` is outside the domain of the model's coordinates: some point does not exist
/// there (simple_pendulum_y at |y| > l). Expressions are meaningless there, and the two sides
/// may give NaN or a finite value depending on how `sqrt(x)²` was simplified.
fn outside_domain(model: &dyn eomgen::ModelInfo, t: f64, y: &[f64]) -> bool {
    model
        .point_positions(t, y)
        .iter()
        .flatten()
        .any(|v| !v.is_finite())
}

/// Every bundled model as the program runs it, and the models of `compiled_models` as
/// `model!` compiles them.
fn generated_models() -> Vec<(
    &'static eomgen::models::ModelEntry,
    Box<dyn eomgen::ModelInfo + Send>,
)> {
    let mut out: Vec<_> = ALL.iter().map(|e| (e, (e.make)())).collect();
    for entry in ALL {
        if let Some(compiled) = crate::compiled_models::make(entry.name) {
            out.push((entry, compiled));
        }
    }
    out
}

#[test]
fn generated_code_equals_engine_evaluation() {
    let mut rng = seeded_rng(0x9E37_79B9_7F4A_7C15);
    for (entry, generated) in generated_models() {
        let file =
            eomgen_symbolic::model::load(entry.file, entry.source()).expect("bundled model loads");
        let mut model = SymbolicModel::from_file(&file).expect("bundled model lowers");
        let eom = Lagrange.derive(&mut model);
        let jac = Jacobians::of(&mut model, &eom);
        let n = model.num_dofs();
        let roots: Vec<_> = [
            eom.mass_matrix.clone(),
            eom.forcing.clone(),
            jac.forcing_q.clone(),
            jac.forcing_qdot.clone(),
            jac.mass_product_q.clone(),
            vec![model.kinetic, model.potential],
        ]
        .concat();
        let mut evaluator = Evaluator::new(&model.arena, &roots);
        assert_eq!(generated.num_dofs(), n, "{}", entry.name);
        let params = generated.parameter_values();
        for _ in 0..50 {
            let t = rng.random_range(0.0..5.0);
            let y: Vec<f64> = (0..2 * n).map(|_| rng.random_range(-3.0..3.0)).collect();
            let a: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            if outside_domain(generated.as_ref(), t, &y) {
                continue;
            }
            let mut bindings = vec![0.0; model.arena.symbols().len()];
            for (i, s) in model.arena.symbols().iter().enumerate() {
                bindings[i] = match s.kind {
                    SymbolKind::Parameter => {
                        let k = model
                            .parameters
                            .iter()
                            .position(|p| p.name == s.name)
                            .expect("parameter");
                        params[k]
                    }
                    SymbolKind::Coordinate(j) => y[j as usize],
                    SymbolKind::Velocity(j) => y[n + j as usize],
                    SymbolKind::Acceleration(j) => a[j as usize],
                    SymbolKind::Time => t,
                    SymbolKind::Auxiliary | SymbolKind::Multiplier(_) | SymbolKind::Retired => 0.0,
                };
            }
            let e = evaluator.eval(&bindings);
            let (m, f) = generated.mass_matrix_and_forcing(t, &y);
            let (jq, jqd) = generated.forcing_jacobians(t, &y);
            let mp = generated.mass_matrix_product_jacobian(t, &y, &a);
            let nn = n * n;
            for i in 0..n {
                for j in 0..n {
                    assert_close("M", entry.name, m[(i, j)], e[i * n + j]);
                    assert_close("∂F/∂q", entry.name, jq[(i, j)], e[nn + n + i * n + j]);
                    assert_close("∂F/∂q̇", entry.name, jqd[(i, j)], e[2 * nn + n + i * n + j]);
                    assert_close(
                        "∂(Ma)/∂q",
                        entry.name,
                        mp[(i, j)],
                        e[3 * nn + n + i * n + j],
                    );
                }
                assert_close("F", entry.name, f[i], e[nn + i]);
            }
            assert_close(
                "T",
                entry.name,
                generated.kinetic_energy(t, &y),
                e[4 * nn + n],
            );
            assert_close(
                "V",
                entry.name,
                generated.potential_energy(t, &y),
                e[4 * nn + n + 1],
            );
        }
    }
}

/// The exact Jacobians agree with central differences of the generated `F` and `M a`
/// (h = 1e-6: truncation O(h²) ≈ 1e-12 times third derivatives, roundoff ≈ 1e-10; tolerance
/// 1e-6 relative to the entry scale).
#[test]
fn jacobians_match_finite_differences() {
    let mut rng = seeded_rng(12345);
    let h = 1e-6;
    for entry in ALL {
        let model = (entry.make)();
        let n = model.num_dofs();
        for _ in 0..10 {
            let t = rng.random_range(0.0..5.0);
            let y: Vec<f64> = (0..2 * n).map(|_| rng.random_range(-2.0..2.0)).collect();
            let a: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let (jq, jqd) = model.forcing_jacobians(t, &y);
            let mp = model.mass_matrix_product_jacobian(t, &y, &a);
            if jq.iter().chain(jqd.iter()).any(|v| !v.is_finite()) {
                continue; // outside the coordinates' domain (simple_pendulum_y at |y| > l)
            }
            for k in 0..2 * n {
                let mut yp = y.clone();
                let mut ym = y.clone();
                yp[k] += h;
                ym[k] -= h;
                let (mpl, fp) = model.mass_matrix_and_forcing(t, &yp);
                let (mmi, fm) = model.mass_matrix_and_forcing(t, &ym);
                if fp.iter().chain(fm.iter()).any(|v| !v.is_finite()) {
                    continue;
                }
                let av = nalgebra::DVector::from_column_slice(&a);
                let map = &mpl * &av;
                let mam = &mmi * &av;
                for i in 0..n {
                    let fd = (fp[i] - fm[i]) / (2.0 * h);
                    let exact = if k < n { jq[(i, k)] } else { jqd[(i, k - n)] };
                    let scale = 1f64.max(exact.abs());
                    assert!(
                        (fd - exact).abs() <= 1e-6 * scale,
                        "{}: ∂F{i}/∂y{k}: exact {exact} vs fd {fd}",
                        entry.name
                    );
                    if k < n {
                        let fd = (map[i] - mam[i]) / (2.0 * h);
                        let exact = mp[(i, k)];
                        assert!(
                            (fd - exact).abs() <= 1e-6 * 1f64.max(exact.abs()),
                            "{}: ∂(Ma){i}/∂q{k}: exact {exact} vs fd {fd}",
                            entry.name
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn mass_matrices_are_symmetric_positive_definite() {
    let mut rng = seeded_rng(777);
    for entry in ALL {
        let model = (entry.make)();
        let n = model.num_dofs();
        for _ in 0..50 {
            let y: Vec<f64> = (0..2 * n).map(|_| rng.random_range(-3.0..3.0)).collect();
            let (m, _) = model.mass_matrix_and_forcing(rng.random_range(0.0..5.0), &y);
            // Outside the coordinates' domain the points do not exist (simple_pendulum_y at
            // |y| > l, where T is still finite but M is negative).
            let points = model.point_positions(0.0, &y);
            if m.iter().any(|v| !v.is_finite()) || points.iter().flatten().any(|v| !v.is_finite()) {
                continue;
            }
            assert_eq!(
                m,
                m.transpose(),
                "{}: M is exactly symmetric by construction",
                entry.name
            );
            assert!(
                m.clone().cholesky().is_some(),
                "{}: M not positive definite at {y:?}",
                entry.name
            );
        }
    }
}

#[test]
fn every_model_simulates_from_its_initial_state() {
    for entry in ALL {
        let mut model = (entry.make)();
        let y0 = model
            .consistent_initial_state()
            .unwrap_or_else(|e| panic!("{}: {e}", entry.name));
        assert!(y0.iter().all(|v| v.is_finite()), "{}", entry.name);
        let options = IntegratorOptions::default()
            .with_rtol(1e-8)
            .with_atol(1e-10);
        let solution = DormandPrince54::new()
            .integrate(
                model.as_ode_mut(),
                0.0,
                &y0,
                5.0,
                &OutputTimes::At(vec![1.0, 5.0]),
                &options,
            )
            .unwrap_or_else(|e| panic!("{} failed: {e}", entry.name));
        // A terminal event (eccentric_cylinder's lift-off) ends the run early.
        let sampled = match solution.terminated_by_event {
            Some(k) => [1.0, 5.0]
                .iter()
                .filter(|t| **t <= solution.events[k].t)
                .count(),
            None => 2,
        };
        assert_eq!(solution.len(), sampled, "{}", entry.name);
        assert!(solution.y.iter().all(|v| v.is_finite()), "{}", entry.name);
    }
}

/// Point positions from the generated code equal the engine's evaluation of the file's point
/// expressions (2-D points have z = 0).
#[test]
fn point_positions_equal_engine_evaluation() {
    let mut rng = seeded_rng(2024);
    for (entry, generated) in generated_models() {
        let file = eomgen_symbolic::model::load(entry.file, entry.source()).expect("loads");
        let model = SymbolicModel::from_file(&file).expect("lowers");
        assert_eq!(
            generated.description().point_names().len(),
            model.points.len(),
            "{}",
            entry.name
        );
        let n = model.num_dofs();
        let params = generated.parameter_values();
        for _ in 0..10 {
            let t = rng.random_range(0.0..5.0);
            let y: Vec<f64> = (0..2 * n).map(|_| rng.random_range(-3.0..3.0)).collect();
            let mut bindings = vec![0.0; model.arena.symbols().len()];
            for (i, s) in model.arena.symbols().iter().enumerate() {
                bindings[i] = match s.kind {
                    SymbolKind::Parameter => {
                        params[model
                            .parameters
                            .iter()
                            .position(|p| p.name == s.name)
                            .expect("parameter")]
                    }
                    SymbolKind::Coordinate(j) => y[j as usize],
                    SymbolKind::Velocity(j) => y[n + j as usize],
                    SymbolKind::Time => t,
                    _ => 0.0,
                };
            }
            let positions = generated.point_positions(t, &y);
            for ((name, r), p) in model.points.iter().zip(&positions) {
                for (k, pk) in p.iter().enumerate() {
                    let expected = r.get(k).map_or(0.0, |c| model.arena.eval(*c, &bindings));
                    assert_close(&format!("point {name}[{k}]"), entry.name, *pk, expected);
                }
            }
        }
    }
}

/// The generated constraint functions are consistent with one another, by central
/// differences (h = 1e-5; tolerance 1e-6 relative, far above the O(h²) truncation and the
/// roundoff of 1e-16/h): `J = ∂Φ/∂q`, the velocity residual is `dΦ/dt = J q̇ + Φ_t` along any
/// motion, and `d/dt` of the velocity residual along a motion with accelerations `a` is
/// `J a − γ` (so `J q̈ = γ` keeps it constant), for holonomic and non-holonomic rows alike.
#[test]
fn constraint_functions_match_finite_differences() {
    let mut rng = seeded_rng(4242);
    let h = 1e-5;
    let mut checked = 0;
    for entry in ALL {
        let model = (entry.make)();
        let m = model.description().constraint_names().len();
        if m == 0 {
            continue;
        }
        let n = model.num_dofs();
        let mh = model.description().holonomic_constraints;
        for _ in 0..10 {
            let t = rng.random_range(0.0..5.0);
            let y: Vec<f64> = (0..2 * n).map(|_| rng.random_range(-2.0..2.0)).collect();
            let a: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let c = model.constraint_equations(t, &y);
            // Move along q(t + s) = q + s q̇ + s²/2 a, q̇(t + s) = q̇ + s a.
            let along = |s: f64| -> Vec<f64> {
                (0..2 * n)
                    .map(|k| {
                        if k < n {
                            y[k] + s * y[n + k] + 0.5 * s * s * a[k]
                        } else {
                            y[k] + s * a[k - n]
                        }
                    })
                    .collect()
            };
            let (yp, ym) = (along(h), along(-h));
            let cp = model.constraint_equations(t + h, &yp);
            let cm = model.constraint_equations(t - h, &ym);
            for i in 0..m {
                let ja: f64 = (0..n).map(|k| c.jacobian[(i, k)] * a[k]).sum();
                let expected = ja - c.gamma[i];
                let fd = (cp.velocity[i] - cm.velocity[i]) / (2.0 * h);
                assert!(
                    (fd - expected).abs() <= 1e-6 * 1f64.max(expected.abs()),
                    "{} {}: d/dt velocity residual {fd} vs J a − γ {expected}",
                    entry.name,
                    model.description().constraints[i]
                );
                if i < mh {
                    let fd = (cp.phi[i] - cm.phi[i]) / (2.0 * h);
                    assert!(
                        (fd - c.velocity[i]).abs() <= 1e-6 * 1f64.max(fd.abs()),
                        "{} {}: dΦ/dt {fd} vs velocity residual {}",
                        entry.name,
                        model.description().constraints[i],
                        c.velocity[i]
                    );
                    for k in 0..n {
                        let (mut qp, mut qm) = (y.clone(), y.clone());
                        qp[k] += h;
                        qm[k] -= h;
                        let fd = (model.constraint_equations(t, &qp).phi[i]
                            - model.constraint_equations(t, &qm).phi[i])
                            / (2.0 * h);
                        assert!(
                            (fd - c.jacobian[(i, k)]).abs() <= 1e-6 * 1f64.max(fd.abs()),
                            "{}: ∂Φ{i}/∂q{k}",
                            entry.name
                        );
                    }
                }
            }
            checked += 1;
        }
    }
    assert!(checked >= 60, "only {checked} constrained states checked");
}

/// Every bundled file compiles at run time (native code, not the interpreter fallback), so
/// `ModelEntry::make` never meets an error, and the name `build.rs` reads from the file's
/// `name:` line is the name the loader reads.
#[test]
fn every_bundled_model_compiles() {
    assert!(ALL.len() >= 50, "{} bundled models", ALL.len());
    for entry in ALL {
        let model = entry
            .model()
            .unwrap_or_else(|e| panic!("{}: {e}", entry.file));
        assert_eq!(model.backend(), eomgen::Backend::Native, "{}", entry.name);
        let file = eomgen_symbolic::model::load(entry.file, entry.source()).expect("loads");
        assert_eq!(file.name.value, entry.name, "{}", entry.file);
        assert_eq!(
            eomgen::models::find(entry.name).map(|e| e.file),
            Some(entry.file)
        );
        let compiled = eomgen::ModelSummary::of(&eomgen::DynFirstOrder::new(model));
        assert_eq!(entry.summary().expect("reads"), compiled, "{}", entry.name);
    }
}

/// A bundled model opened with options is compiled with them (the interpreter; the equations
/// as MathML), and with the default options it is native code without the MathML.
#[test]
fn a_bundled_model_is_compiled_with_the_options_it_is_opened_with() {
    let interpreted = eomgen::LoadOptions {
        backend: Some(eomgen::Backend::Interpreter),
        ..eomgen::LoadOptions::default()
    };
    let source = eomgen::ModelSource::open_with("double_pendulum", interpreted).expect("opens");
    assert_eq!(source.model().backend(), eomgen::Backend::Interpreter);
    assert!(!source.is_file());
    let source = eomgen::ModelSource::open("double_pendulum").expect("opens");
    assert_eq!(source.model().backend(), eomgen::Backend::Native);
    assert_eq!(source.path(), "models/double_pendulum.yaml");
    let mathml = eomgen::LoadOptions {
        equations_mathml: true,
        ..eomgen::LoadOptions::default()
    };
    let with = eomgen::ModelSource::open_with("double_pendulum", mathml).expect("opens");
    assert!(
        eomgen::DynMechanicalSystem::description(with.model())
            .equations_mathml
            .is_some()
    );
    assert!(
        eomgen::DynMechanicalSystem::description(source.model())
            .equations_mathml
            .is_none()
    );
}
