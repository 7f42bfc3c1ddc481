//! `RadauIIA5` against Hairer and Wanner's `radau5.f`, step for step.
//!
//! Given `radau5.f`'s internal tolerances (it replaces `rtol` by `rtol' = 0.1 rtol^(2/3)` and
//! `atol` by `rtol' · atol/rtol`) and the same exact Jacobian, `RadauIIA5` makes the decisions
//! `radau5.f` makes: the same accepted steps, the same rejected attempts (error too large,
//! Newton too slow or diverging), the same evaluations of `F` (three per Newton iteration),
//! Jacobians and LU factorisations. Every heuristic of the method shows in these counts: the starting values
//! of the Newton iteration, its convergence-rate prediction and early exit, the reuse of the
//! Jacobian and of the factorised matrices, the Newton-dependent safety factor and
//! Gustafsson's predictive controller. A change to any of them changes some count on these
//! four runs.
//!
//! The reference figures are `radau5.f`'s statistics (`IWORK(14..18)`, `IWORK(19)`), printed
//! by `tools/radau5_reference/run.sh` (radau5.f version of July 9, 1996, last corrected
//! January 18, 2002, with `decsol.f` and `dc_decsol.f`; gfortran 12 gives the same figures
//! at `-O0`, `-O2` and `-O3 -march=native`). `RadauIIA5` evaluates `F` once more than
//! `radau5.f`: at the final state, which `radau5.f` does not need.
//!
//! Source: E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed.,
//! Springer, 1996, §IV.8 and the code `radau5.f`; the van der Pol case is the book's driver
//! `dr1_radau5.f`, Robertson's reaction its problem ROBER (§IV.1).
// The final states are written with the 17 digits radau5.f's driver prints.
#![allow(clippy::excessive_precision)]

use eomgen_runtime::{
    Integrator, IntegratorOptions, OdeSystem, OutputTimes, RadauIIA5, RhsError, Stats,
};

/// Van der Pol's equation in `radau5.f`'s scaling: `y₁' = y₂`,
/// `y₂' = ((1 − y₁²) y₂ − y₁)/ε`, written with the same operations as the Fortran driver.
struct VanDerPol {
    eps: f64,
}

impl OdeSystem for VanDerPol {
    fn dim(&self) -> usize {
        2
    }

    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = y[1];
        dy[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / self.eps;
        Ok(())
    }

    fn jacobian(&mut self, _t: f64, y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        // Column-major: [∂F/∂y₁, ∂F/∂y₂].
        jac.copy_from_slice(&[
            0.0,
            (-2.0 * y[0] * y[1] - 1.0) / self.eps,
            1.0,
            (1.0 - y[0] * y[0]) / self.eps,
        ]);
        Ok(true)
    }
}

/// Robertson's reaction: `y₁' = −0.04 y₁ + 10⁴ y₂ y₃`, `y₃' = 3·10⁷ y₂²`,
/// `y₂' = 0.04 y₁ − 10⁴ y₂ y₃ − y₃'`.
struct Robertson;

impl OdeSystem for Robertson {
    fn dim(&self) -> usize {
        3
    }

    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
        dy[2] = 3e7 * y[1] * y[1];
        dy[1] = 0.04 * y[0] - 1e4 * y[1] * y[2] - dy[2];
        Ok(())
    }

    fn jacobian(&mut self, _t: f64, y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        // Column-major: [∂F/∂y₁, ∂F/∂y₂, ∂F/∂y₃].
        jac.copy_from_slice(&[
            -0.04,
            0.04,
            0.0,
            1e4 * y[2],
            -1e4 * y[2] - 6e7 * y[1],
            6e7 * y[1],
            1e4 * y[1],
            -1e4 * y[1],
            0.0,
        ]);
        Ok(true)
    }
}

/// What `radau5.f` reports for one run.
struct Radau5f {
    /// `NFCN`: evaluations of `F`.
    nfcn: usize,
    /// `NJAC`: Jacobians.
    njac: usize,
    /// `NSTEP`: attempted steps.
    nstep: usize,
    /// `NACCPT`: accepted steps.
    naccpt: usize,
    /// `NDEC`: factorisations (of the real and the complex matrix together).
    ndec: usize,
    /// The state at the end.
    y: &'static [f64],
}

/// Runs `RadauIIA5` from `y0` at `t = 0` to `t_end` with `radau5.f`'s internal tolerances for
/// `rtol`, `atol` and its starting step `10⁻⁶`.
fn run(
    system: &mut dyn OdeSystem,
    y0: &[f64],
    t_end: f64,
    rtol: f64,
    atol: f64,
) -> (Stats, Vec<f64>) {
    let internal_rtol = 0.1 * rtol.powf(2.0 / 3.0);
    let internal_atol = internal_rtol * (atol / rtol);
    let options = IntegratorOptions::default()
        .with_rtol(internal_rtol)
        .with_atol(internal_atol)
        .with_dt(1e-6);
    let solution = RadauIIA5::new()
        .integrate(system, 0.0, y0, t_end, &OutputTimes::Steps, &options)
        .unwrap_or_else(|failure| panic!("{failure}"));
    let (_, y) = solution.last().expect("a solution has samples");
    (solution.stats, y.to_vec())
}

/// Compares a run with `radau5.f`'s: the counts exactly, each component of the final state
/// (none is zero) to `10⁻⁹` relative. The two codes round differently (their LU factorisations and
/// complex arithmetic order operations differently), and on these stiff problems the
/// differences grow over hundreds of steps to at most 4·10⁻¹¹ (observed), far below the
/// tolerances, and never enough to change a decision.
fn assert_repeats(name: &str, (stats, y): (Stats, Vec<f64>), reference: &Radau5f) {
    println!(
        "{name}: {} accepted, {} attempted, {} F, {} Jacobians, {} LU; radau5.f: {}, {}, {} (+1 at the end), {}, {}",
        stats.steps,
        stats.steps + stats.rejected,
        stats.rhs_evals,
        stats.jacobian_evals,
        stats.lu_decompositions,
        reference.naccpt,
        reference.nstep,
        reference.nfcn,
        reference.njac,
        reference.ndec,
    );
    assert_eq!(stats.steps, reference.naccpt, "{name}: accepted steps");
    assert_eq!(
        stats.steps + stats.rejected,
        reference.nstep,
        "{name}: attempted steps"
    );
    assert_eq!(
        stats.rhs_evals,
        reference.nfcn + 1,
        "{name}: evaluations of F"
    );
    assert_eq!(stats.jacobian_evals, reference.njac, "{name}: Jacobians");
    assert_eq!(
        stats.lu_decompositions, reference.ndec,
        "{name}: factorisations"
    );
    for (i, (ours, theirs)) in y.iter().zip(reference.y).enumerate() {
        let deviation = (ours - theirs).abs() / theirs.abs();
        assert!(
            deviation <= 1e-9,
            "{name}: y{} = {ours:e}, radau5.f {theirs:e}",
            i + 1
        );
    }
}

/// `dr1_radau5.f`: van der Pol, `ε = 10⁻⁶`, `y(0) = (2, −0.66)` on `[0, 2]`, tolerances
/// `10⁻⁴`: eight rejections by the error test and 29 attempts cut short by Newton.
#[test]
fn van_der_pol_at_1e_4_takes_radau5s_steps() {
    let run = run(&mut VanDerPol { eps: 1e-6 }, &[2.0, -0.66], 2.0, 1e-4, 1e-4);
    let reference = Radau5f {
        nfcn: 2218,
        njac: 161,
        nstep: 275,
        naccpt: 238,
        ndec: 248,
        y: &[1.7061611005587547, -0.89280747768156532],
    };
    assert_repeats("van der Pol, 1e-4", run, &reference);
}

/// The same at tolerances `10⁻⁷`: nearly three times the steps.
#[test]
fn van_der_pol_at_1e_7_takes_radau5s_steps() {
    let run = run(&mut VanDerPol { eps: 1e-6 }, &[2.0, -0.66], 2.0, 1e-7, 1e-7);
    let reference = Radau5f {
        nfcn: 5647,
        njac: 431,
        nstep: 702,
        naccpt: 693,
        ndec: 582,
        y: &[1.7061674214684552, -0.89281003179968810],
    };
    assert_repeats("van der Pol, 1e-7", run, &reference);
}

/// The same at tolerances `10⁻²`, where the steps are long and the Newton iteration often
/// too slow: 37 of 171 attempts fail.
#[test]
fn van_der_pol_at_1e_2_takes_radau5s_steps() {
    let run = run(&mut VanDerPol { eps: 1e-6 }, &[2.0, -0.66], 2.0, 1e-2, 1e-2);
    let reference = Radau5f {
        nfcn: 1337,
        njac: 95,
        nstep: 171,
        naccpt: 134,
        ndec: 155,
        y: &[1.7060887766624711, -0.89236054060649161],
    };
    assert_repeats("van der Pol, 1e-2", run, &reference);
}

/// Robertson's reaction from `(1, 0, 0)` to `t = 10⁵`, `rtol = 10⁻⁶`, `atol = 10⁻¹⁰`: step
/// sizes over eleven decades.
#[test]
fn robertson_takes_radau5s_steps() {
    let run = run(&mut Robertson, &[1.0, 0.0, 0.0], 1e5, 1e-6, 1e-10);
    let reference = Radau5f {
        nfcn: 758,
        njac: 100,
        nstep: 109,
        naccpt: 107,
        ndec: 109,
        y: &[
            1.7865922200674698e-2,
            7.2747519073843829e-8,
            9.8213400505180593e-1,
        ],
    };
    assert_repeats("Robertson", run, &reference);
}
