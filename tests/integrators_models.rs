//! The integrators on the bundled models: the exact Jacobian `∂F/∂y` that `FirstOrder` builds
//! from the generated derivatives (and that the implicit methods use) agrees with finite
//! differences of the right-hand side for every model; the implicit methods with it agree
//! with a tight explicit reference and with themselves using differenced Jacobians; the
//! partitioned methods keep the energy of a constant-mass model bounded.

use crate::common;
use common::seeded_rng;
use rand::RngExt;

use eomgen::models::{ALL, find};
use eomgen::{
    DormandPrince54, ImplicitMidpoint, Integrator, IntegratorOptions, ModelInfo, OdeSystem,
    OutputTimes, RadauIIA5, RhsError, Solution, StormerVerlet, SymplecticEuler,
};

/// Builds the bundled model `name`.
fn model(name: &str) -> Box<dyn ModelInfo> {
    let entry = find(name).unwrap_or_else(|| panic!("model `{name}` is bundled"));
    (entry.make)()
}

/// `F` at `(t, y)`.
fn rhs(system: &mut dyn OdeSystem, t: f64, y: &[f64]) -> Result<Vec<f64>, RhsError> {
    let mut dy = vec![0.0; y.len()];
    system.rhs(t, y, &mut dy)?;
    Ok(dy)
}

/// For every unconstrained model, at 20 random states `q, q̇ ∈ [−1, 1]`, `t ∈ [0, 2]`, the
/// Jacobian from `∂F/∂q`, `∂F/∂q̇` and `∂(M a)/∂q` (`∂q̈/∂q = M⁻¹(∂F/∂q − ∂(M a)/∂q|ₐ₌q̈)`,
/// `∂q̈/∂q̇ = M⁻¹ ∂F/∂q̇`) equals central differences of `F`.
///
/// Tolerance: central differences with `δ = 10⁻⁶ max(1, |yⱼ|)` have truncation error
/// `~δ² |F'''| ≈ 1e-12` and rounding error `~ε |F| / δ ≈ 1e-10 |F|`; 1e-6 relative to the
/// larger of 1, the entry and the column's largest entry leaves room for models with large
/// third derivatives, while a missing term (`∂(M a)/∂q` forgotten, a sign, a transposition)
/// is off by O(1). Constrained models report no exact Jacobian (their `q̈` comes from the
/// KKT system) and the implicit methods difference them: checked as such.
#[test]
fn generated_jacobian_matches_finite_differences() {
    let mut checked = 0;
    for entry in ALL {
        // A stream of states per model (seeded by its name), so that adding a model changes
        // no other model's states.
        let seed = (entry.name.bytes()).fold(0x2545_F491_4F6C_DD1D_u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x100_0000_01B3)
        });
        let mut rng = seeded_rng(seed);
        let mut model = (entry.make)();
        // The simplest walker's feet weigh 1e-9 of its hip, so its mass matrix is that
        // ill-conditioned everywhere (the limit of massless legs); its Jacobian is checked
        // with feet of a tenth of it.
        if entry.name == "simplest_walker" {
            model.set_parameter("beta", 0.1).unwrap();
        }
        let constrained = !model.description().constraint_names().is_empty();
        let n = model.num_dofs();
        let dim = 2 * n;
        assert_eq!(
            model.as_ode_mut().second_order_dim(),
            Some(n),
            "{}",
            entry.name
        );
        let mut states = 0;
        for _ in 0..20 {
            let t = rng.random_range(0.0..2.0);
            let y: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
            // Near a singular configuration (Euler angles at θ = 0: heavy_top) `M⁻¹` turns
            // the rounding of `F` into differences of 1e-6 and more; those states test the
            // differences, not the Jacobian.
            let (mass, _) = model.mass_matrix_and_forcing(t, &y);
            let eigen = mass.symmetric_eigenvalues();
            if eigen.min() < 1e-3 * eigen.max() {
                continue;
            }
            let system = model.as_ode_mut();
            let mut jac = vec![f64::NAN; dim * dim];
            let exact = match system.jacobian(t, &y, &mut jac) {
                Ok(exact) => exact,
                // A random configuration may be singular for the model (M not positive
                // definite); the right-hand side reports the same there.
                Err(error) => {
                    assert!(rhs(system, t, &y).is_err(), "{}: {error}", entry.name);
                    continue;
                }
            };
            if constrained {
                assert!(!exact, "{}: constrained models difference", entry.name);
                break;
            }
            assert!(
                exact,
                "{}: unconstrained models have the exact Jacobian",
                entry.name
            );
            let mut differences = vec![0.0; dim * dim];
            let mut usable = true;
            for j in 0..dim {
                let delta = 1e-6 * y[j].abs().max(1.0);
                let (mut up, mut down) = (y.clone(), y.clone());
                up[j] += delta;
                down[j] -= delta;
                match (rhs(system, t, &up), rhs(system, t, &down)) {
                    (Ok(f_up), Ok(f_down)) => {
                        for i in 0..dim {
                            differences[i + j * dim] = (f_up[i] - f_down[i]) / (2.0 * delta);
                        }
                    }
                    _ => usable = false,
                }
            }
            if !usable {
                continue;
            }
            for j in 0..dim {
                let column = &jac[j * dim..(j + 1) * dim];
                let scale = column.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
                for i in 0..dim {
                    let (exact, fd) = (jac[i + j * dim], differences[i + j * dim]);
                    assert!(
                        (exact - fd).abs() <= 1e-6 * scale,
                        "{}: ∂F{i}/∂y{j} = {exact} but differences give {fd} at t = {t}, y = {y:?}",
                        entry.name
                    );
                }
            }
            states += 1;
        }
        if !constrained {
            assert!(states >= 10, "{}: only {states} usable states", entry.name);
            checked += 1;
        }
    }
    assert!(checked >= 10, "{checked} models checked");
}

/// Forwards a system's right-hand side but hides its Jacobian, so that the implicit methods
/// difference `F`.
struct Differenced<'a>(&'a mut dyn OdeSystem);

impl OdeSystem for Differenced<'_> {
    fn dim(&self) -> usize {
        self.0.dim()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        self.0.rhs(t, y, dy)
    }

    fn second_order_dim(&self) -> Option<usize> {
        self.0.second_order_dim()
    }
}

fn solve(
    method: &mut dyn Integrator,
    system: &mut dyn OdeSystem,
    y0: &[f64],
    t_end: f64,
    output: &OutputTimes,
    options: &IntegratorOptions,
) -> Solution {
    method
        .integrate(system, 0.0, y0, t_end, output, options)
        .unwrap_or_else(|failure| panic!("{}: {failure}", method.name()))
}

/// Largest relative deviation of two solutions sampled at the same times.
fn deviation(a: &Solution, b: &Solution) -> f64 {
    a.y.iter()
        .zip(&b.y)
        .map(|(x, y)| (x - y).abs() / y.abs().max(1.0))
        .fold(0.0, f64::max)
}

/// Radau IIA and implicit midpoint on the double pendulum (a configuration-dependent `M(q)`),
/// with the generated Jacobian and with differenced ones, against DOPRI5 at `rtol = atol =
/// 1e-12` (whose own error, ~1e-10 over these 5 s, is negligible against the bounds below).
///
/// Radau IIA at `rtol = atol = 1e-8` stays within 1e-5 of it at the sample times (local
/// errors of 1e-8 grow on this fast, nearly chaotic motion; observed 7e-8); implicit midpoint
/// with `dt = 2.5 · 10⁻⁴` within 1e-3 (second order: observed 6.6e-3 at `dt = 10⁻³`, so
/// ~4e-4 here). With the exact Jacobian the results agree with the differenced ones to 1e-7
/// and 1e-9 respectively (only the Newton iterates differ, and they converge to the same
/// stage values; observed ~1e-12), while differencing costs `2n` more evaluations of `F` per
/// Jacobian.
#[test]
fn implicit_methods_use_the_generated_jacobian() {
    let mut pendulum = model("double_pendulum");
    let y0 = pendulum.initial_state();
    let t_end = 5.0;
    let times: Vec<f64> = (1..=10).map(|k| 0.5 * f64::from(k)).collect();
    let output = OutputTimes::At(times);
    let reference_options = IntegratorOptions::default()
        .with_rtol(1e-12)
        .with_atol(1e-12);
    let reference = solve(
        &mut DormandPrince54::new(),
        pendulum.as_ode_mut(),
        &y0,
        t_end,
        &output,
        &reference_options,
    );
    let cases: [(Box<dyn Integrator>, IntegratorOptions, f64, f64); 2] = [
        (
            Box::new(RadauIIA5::new()),
            IntegratorOptions::default().with_rtol(1e-8).with_atol(1e-8),
            1e-5,
            1e-7,
        ),
        (
            Box::new(ImplicitMidpoint::new()),
            IntegratorOptions::default().with_dt(2.5e-4),
            1e-3,
            1e-9,
        ),
    ];
    for (mut method, options, bound, agreement) in cases {
        let exact = solve(
            method.as_mut(),
            pendulum.as_ode_mut(),
            &y0,
            t_end,
            &output,
            &options,
        );
        let differenced = solve(
            method.as_mut(),
            &mut Differenced(pendulum.as_ode_mut()),
            &y0,
            t_end,
            &output,
            &options,
        );
        let (e, d) = (exact.stats, differenced.stats);
        let error = deviation(&exact, &reference);
        let between = deviation(&exact, &differenced);
        println!(
            "{} on double_pendulum: deviation from the reference {error:.2e}; exact Jacobian: {} steps, {} F, {} Jacobians; differenced: {} steps, {} F, {} Jacobians; results differ by {between:.2e}",
            method.name(),
            e.steps,
            e.rhs_evals,
            e.jacobian_evals,
            d.steps,
            d.rhs_evals,
            d.jacobian_evals,
        );
        assert!(error < bound, "{}: {error:e}", method.name());
        assert!(between < agreement, "{}: {between:e}", method.name());
        assert!(e.jacobian_evals >= 1 && d.jacobian_evals >= 1);
        // Each differenced Jacobian costs 2n = 4 evaluations of F that the exact one does not.
        assert!(
            d.rhs_evals > e.rhs_evals,
            "{}: {e:?} vs {d:?}",
            method.name()
        );
    }
}

/// The partitioned methods on `three_masses` (constant `M = m I`, springs only: a linear,
/// conservative model) keep `T + V` within their modified-energy bounds over 1000 s (~190
/// periods of the slowest mode, 550 of the fastest) with `dt = 0.05`, without drift; the
/// largest mode has `ω dt = 0.092`.
///
/// Bounds, relative to `E₀`: Störmer–Verlet `(ω dt)²/4 / (1 − (ω dt)²/4) ≈ 2.2e-3`, symplectic
/// Euler `(ω dt/2)/(1 − ω dt/2) ≈ 0.049` (the same modified energies as the scalar oscillator
/// in `runtime/tests/methods.rs`, for the fastest mode); no drift: the largest error over the
/// last tenth of the run is within 5 % of that over the first tenth (the mix of modes makes
/// the two windows sample different phases).
#[test]
fn partitioned_methods_keep_the_energy_of_a_constant_mass_model() {
    let mut masses = model("three_masses");
    assert!(masses.description().conservative);
    let mut y0 = masses.initial_state();
    if y0.iter().all(|v| *v == 0.0) {
        // Start away from equilibrium, exciting every mode.
        y0[0] = 0.5;
        y0[1] = -0.2;
        y0[5] = 0.3;
    }
    let e0 = masses.energy(0.0, &y0);
    assert!(e0 > 0.0);
    let omega_max = (2.0 + 2.0_f64.sqrt()).sqrt(); // k = m = 1 in the file
    let dt = 0.05;
    let wdt = omega_max * dt;
    let options = IntegratorOptions::default().with_dt(dt);
    let methods: [(Box<dyn Integrator>, f64); 2] = [
        (
            Box::new(StormerVerlet::new()),
            (wdt * wdt / 4.0) / (1.0 - wdt * wdt / 4.0),
        ),
        (
            Box::new(SymplecticEuler::new()),
            (wdt / 2.0) / (1.0 - wdt / 2.0),
        ),
    ];
    for (mut method, bound) in methods {
        let solution = solve(
            method.as_mut(),
            masses.as_ode_mut(),
            &y0,
            1000.0,
            &OutputTimes::Steps,
            &options,
        );
        let errors: Vec<f64> = solution
            .iter()
            .map(|(t, y)| (masses.energy(t, y) - e0).abs() / e0)
            .collect();
        let tenth = errors.len() / 10;
        let first = errors[..tenth].iter().copied().fold(0.0, f64::max);
        let last = errors[errors.len() - tenth..]
            .iter()
            .copied()
            .fold(0.0, f64::max);
        println!(
            "{} on three_masses, dt = {dt}: max |ΔE|/E₀ first tenth {first:.3e}, last tenth {last:.3e} (bound {bound:.3e})",
            method.name()
        );
        assert!(first <= bound && last <= bound, "{}", method.name());
        assert!(
            last <= 1.05 * first,
            "{}: drift {first:e} → {last:e}",
            method.name()
        );
    }
}
