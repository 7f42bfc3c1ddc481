//! Embedding eomgen in a Rust program: a model file of your own compiled into the program by
//! `model!`, simulated, and analysed through the library alone (no command line).
//!
//! ```sh
//! cargo run -p eomgen-embed
//! ```
//!
//! A crate of its own (`examples/embed/Cargo.toml`), which depends on eomgen with
//! `default-features = false` as a user's program would: the macro, the runtime and the
//! analyses; the command line and its dependencies (arguments, charts, progress bars), the
//! run-time compiler and eomgen's own test dependencies are not built.

use eomgen::nalgebra::DMatrix;
use eomgen::{
    DormandPrince54, FirstOrder, Integrator, IntegratorOptions, MechanicalSystem, ModelInfo,
    OutputTimes, linearize, normal_modes,
};

// The struct `WallSprings` and its `MechanicalSystem<2>` implementation, derived from the
// file at build time (a mistake in the file is a compile error at its line and column).
eomgen::model!("wall_springs.yaml");

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = WallSprings { m: 2.0, k: 50.0 };
    let (m, k) = (model.m, model.k);
    let (q0, qdot0) = model.initial_state();
    let mut system = FirstOrder::new(model);

    // A simulation: Dormand–Prince 5(4) to t = 10 s, the energy checked at the end.
    let y0: Vec<f64> = q0.iter().chain(qdot0.iter()).copied().collect();
    let options = IntegratorOptions::default()
        .with_rtol(1e-10)
        .with_atol(1e-12);
    let solution = DormandPrince54::new().integrate(
        &mut system,
        0.0,
        &y0,
        10.0,
        &OutputTimes::At(vec![10.0]),
        &options,
    )?;
    let energy = |y: &[f64]| system.kinetic_energy(0.0, y) + system.potential_energy(0.0, y);
    let (t1, y1) = solution.last().ok_or("no output")?;
    let (e0, e1) = (energy(&y0), energy(y1));
    println!(
        "x({t1} s) = [{:.6}, {:.6}] m, energy {e0:.9} J -> {e1:.9} J (relative drift {:.1e})",
        y1[0],
        y1[1],
        ((e1 - e0) / e0).abs()
    );

    // Normal modes at rest: the exact linearisation M, C, K and its eigenproblem.
    let linearization = linearize(&system, &[0.0, 0.0], &[0.0, 0.0], 0.0)?;
    let modes = normal_modes(&linearization)?;
    let expected = [(k / m).sqrt(), (3.0 * k / m).sqrt()];
    for (i, (w, w_exact)) in modes.natural_frequencies.iter().zip(expected).enumerate() {
        println!("mode {}: ω = {w:.12} rad/s (exact {w_exact:.12})", i + 1);
        if ((w - w_exact) / w_exact).abs() > 1e-12 {
            return Err(format!("mode {}: {w} rad/s, expected {w_exact}", i + 1).into());
        }
    }
    // Mass-normalised: Ψᵀ M Ψ = I.
    let psi: &DMatrix<f64> = &modes.mode_shapes;
    let orthonormality = psi.transpose() * &linearization.mass_matrix * psi;
    println!("ΨᵀMΨ = {orthonormality:.12}");
    if (orthonormality - DMatrix::identity(2, 2)).amax() > 1e-12 {
        return Err("the mode shapes are not mass-normalised".into());
    }
    if ((e1 - e0) / e0).abs() > 1e-8 {
        return Err("the energy of a conservative system drifted".into());
    }
    Ok(())
}
