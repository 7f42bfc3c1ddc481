//! Model files compiled at run time: any file runs through every analysis with no rebuild.
//!
//! [`JitModel::load`] runs the pipeline of the `eomgen::model!` macro on a model file — load
//! and check it (the same located diagnostics), derive the equations of motion, constraints,
//! exact Jacobians, events, energies and points, plan each function with the same
//! common-subexpression elimination — and turns every function into native code with
//! [Cranelift](https://cranelift.dev) in-process, in a few milliseconds for a double pendulum.
//! The model implements [`DynMechanicalSystem`](eomgen_runtime::DynMechanicalSystem); its
//! first-order form [`DynFirstOrder`](eomgen_runtime::DynFirstOrder) implements
//! [`ModelInfo`](eomgen_runtime::ModelInfo), which every analysis takes.
//!
//! The compiled code computes each operation in the order of the Rust code the macro
//! generates and calls the same library functions (the `libm` crate's sine and cosine, the
//! platform's other transcendentals), so a model compiled at run time and the same file
//! compiled by the macro agree to the last bit. An interpreter over the same straight-line
//! programs ([`Backend::Interpreter`]) is the reference the native code is tested against and
//! the fallback on a host Cranelift has no code generator for ([`JitModel::backend`] says
//! which one runs, and [`JitModel::fallback_reason`] why).
//!
//! # Memory
//! The machine code of a model is a few kilobytes for a double pendulum
//! ([`JitModel::code_bytes`]); it is mapped when the model is loaded and unmapped when the
//! last clone of the model is dropped.
//!
//! # Examples
//! ```
//! use eomgen_jit::JitModel;
//! use eomgen_runtime::{DynMechanicalSystem, DynFirstOrder, ModelInfo};
//!
//! let source = "
//! name: spring_mass
//! description: A mass on a spring.
//! parameters: { m: 2.0, k: 8.0 }
//! coordinates: [x]
//! kinetic: m*x_dot^2/2
//! potential: k*x^2/2
//! initial: { x: 0.1 }
//! ";
//! let model = JitModel::from_source("spring_mass.yaml", source)?;
//! let (mut mass, mut forcing) = ([0.0], [0.0]);
//! model.mass_matrix_and_forcing(&[0.1], &[0.0], 0.0, &mut mass, &mut forcing);
//! assert_eq!((mass[0], forcing[0]), (2.0, -0.8));
//! let system = DynFirstOrder::new(model);
//! assert_eq!(system.initial_state(), vec![0.1, 0.0]);
//! # Ok::<(), eomgen_jit::LoadError>(())
//! ```
#![warn(missing_docs)]

mod compiled;
mod first_order;
mod interpret;
mod math;
mod model;
mod native;
mod taylor;

pub use model::{COMPILE_TAYLOR_AFTER, JitModel, LoadError, LoadOptions};
pub use native::CompileError;

/// Which evaluator runs a run-time model's functions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Backend {
    /// Native code compiled by Cranelift.
    Native,
    /// The interpreter over the same straight-line programs (the reference, and the fallback
    /// where Cranelift cannot compile for the host).
    Interpreter,
}

/// The inputs of one evaluation of a model function.
///
/// # Shapes
/// `parameters`: one per model parameter (file order); `q`, `qdot`, `acceleration`: `n`;
/// `lambda`: `m` (only event functions read it); `t` in s. A function reads only the inputs
/// its expressions contain.
#[derive(Debug, Clone, Copy)]
pub struct Inputs<'a> {
    /// Parameter values, in file order.
    pub parameters: &'a [f64],
    /// Generalized coordinates `q`.
    pub q: &'a [f64],
    /// Generalized velocities `q̇`.
    pub qdot: &'a [f64],
    /// The vector `a` of `∂(M a)/∂q`, or `q̈` for event functions.
    pub acceleration: &'a [f64],
    /// Lagrange multipliers `λ` (event functions).
    pub lambda: &'a [f64],
    /// Time `t` (s).
    pub t: f64,
}

#[cfg(test)]
mod tests {
    use eomgen_symbolic::codegen::program::{FunctionTape, JacobianProgram, ModelProgram};
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};

    use super::*;

    /// `len` numbers uniform in `[low, high)`.
    fn vector(random: &mut Xoshiro256PlusPlus, len: usize, low: f64, high: f64) -> Vec<f64> {
        (0..len).map(|_| random.random_range(low..high)).collect()
    }

    /// Random inputs of a model: each parameter its default scaled by a factor in
    /// `[0.5, 1.5)` and moved by up to ±0.1, `q`, `q̇`, the acceleration inputs and `λ` in
    /// `[−2, 2)`, `t` in `[0, 10)`.
    struct Drawn {
        parameters: Vec<f64>,
        q: Vec<f64>,
        qdot: Vec<f64>,
        acceleration: Vec<f64>,
        lambda: Vec<f64>,
        t: f64,
    }

    impl Drawn {
        fn new(random: &mut Xoshiro256PlusPlus, program: &ModelProgram) -> Self {
            let (n, m) = (program.num_dofs(), program.description.constraints.len());
            let parameters = program
                .description
                .parameters
                .iter()
                .map(|p| p.default)
                .map(|v| v * random.random_range(0.5..1.5) + random.random_range(-0.1..0.1))
                .collect();
            Self {
                parameters,
                q: vector(random, n, -2.0, 2.0),
                qdot: vector(random, n, -2.0, 2.0),
                acceleration: vector(random, n, -2.0, 2.0),
                lambda: vector(random, m, -2.0, 2.0),
                t: random.random_range(0.0..10.0),
            }
        }

        fn inputs(&self) -> Inputs<'_> {
            Inputs {
                parameters: &self.parameters,
                q: &self.q,
                qdot: &self.qdot,
                acceleration: &self.acceleration,
                lambda: &self.lambda,
                t: self.t,
            }
        }
    }

    pub(crate) fn bundled_programs() -> Vec<(String, ModelProgram, JacobianProgram)> {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");
        let mut paths: Vec<_> = std::fs::read_dir(dir)
            .expect("models/ is readable")
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
            .collect();
        paths.sort();
        paths
            .into_iter()
            .map(|path| {
                let display = path.display().to_string();
                let source = std::fs::read_to_string(&path).expect("model file is readable");
                let file = eomgen_symbolic::model::load(&display, &source)
                    .unwrap_or_else(|d| panic!("{display}: {d:?}"));
                let (program, derivation) =
                    ModelProgram::from_file(&file).unwrap_or_else(|e| panic!("{display}: {e:?}"));
                (display, program, derivation.jacobians())
            })
            .collect()
    }

    /// A numbered tape (`Tape::numbered`, each operation on the same operands once: the
    /// input of the Taylor recurrences) computes the bits of the tape it numbers, on every
    /// function of every bundled model at 20 random inputs each, and is never longer; the
    /// models whose equations repeat a product chain (the figure eight's pulls, with both
    /// signs) get shorter. A `Sub` merged with its operands swapped changes a value here (five
    /// bundled tapes have such a pair); the bundled models have no swapped quotient, power or
    /// `atan2` and no two functions of one operand, which `eomgen_symbolic`'s
    /// `only_the_same_operation_on_the_same_operands_is_merged` checks on a tape by hand.
    #[test]
    fn numbered_tapes_compute_the_same_bits_on_every_bundled_model() {
        let mut random = Xoshiro256PlusPlus::seed_from_u64(0x5DEE_CE66_D1CE_4E5B);
        let (mut compared, mut shortened) = (0usize, 0usize);
        for (display, program, jacobians) in bundled_programs() {
            let functions: Vec<_> = program
                .functions()
                .into_iter()
                .chain(jacobians.functions())
                .collect();
            for (name, function) in functions {
                let numbered = FunctionTape {
                    tape: function.tape.numbered(),
                    split: function.split,
                };
                let (before, after) = (
                    function.tape.instructions.len(),
                    numbered.tape.instructions.len(),
                );
                assert!(after <= before, "{display}: {name}: {before} -> {after}");
                shortened += usize::from(after < before);
                let split = function.split.min(function.tape.outputs.len());
                let rest = function.tape.outputs.len() - split;
                let mut values = Vec::new();
                for _ in 0..20 {
                    let drawn = Drawn::new(&mut random, &program);
                    let inputs = drawn.inputs();
                    let (mut a0, mut a1) = (vec![0.0; split], vec![0.0; rest]);
                    interpret::evaluate(function, &inputs, &mut values, &mut a0, &mut a1);
                    let (mut b0, mut b1) = (vec![f64::NAN; split], vec![f64::NAN; rest]);
                    interpret::evaluate(&numbered, &inputs, &mut values, &mut b0, &mut b1);
                    for (k, (a, b)) in a0.iter().chain(&a1).zip(b0.iter().chain(&b1)).enumerate() {
                        assert!(
                            a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                            "{display}: {name}[{k}]: tape {a:e}, numbered {b:e}"
                        );
                        compared += 1;
                    }
                }
            }
        }
        assert!(compared > 10_000, "only {compared} values compared");
        assert!(shortened > 20, "only {shortened} tapes shortened");
    }

    /// Native code and the interpreter agree to the bit on every function of every bundled
    /// model at 50 random inputs each: both compute the same IEEE operations in the same
    /// order and call the same library functions, so any difference is a miscompilation
    /// (an operand swapped, a load from the wrong offset, a wrong register for `cos` of a
    /// `sin_cos` pair).
    ///
    /// The 15-link pendulum and the 40-mass chain of `eomgen new` are compared too: their
    /// larger functions keep shared values in the scratch buffer (`native::build`).
    #[test]
    fn native_code_equals_the_interpreter_bit_for_bit_on_every_bundled_model() {
        let mut random = Xoshiro256PlusPlus::seed_from_u64(0x9E37_79B9_7F4A_7C15);
        let mut compared = 0usize;
        let mut scratched = 0usize;
        let generated = [
            eomgen_symbolic::model::templates::n_link_pendulum(15),
            eomgen_symbolic::model::templates::n_mass_chain(40),
        ]
        .map(|source| {
            let file = eomgen_symbolic::model::load("generated.yaml", &source).expect("loads");
            let (program, derivation) = ModelProgram::from_file(&file).expect("derives");
            (
                "generated.yaml".to_string(),
                program,
                derivation.jacobians(),
            )
        });
        for (display, program, jacobians) in bundled_programs().into_iter().chain(generated) {
            let functions: Vec<_> = program
                .functions()
                .into_iter()
                .chain(jacobians.functions())
                .collect();
            let code =
                native::compile(&functions, None).unwrap_or_else(|e| panic!("{display}: {e}"));
            for (index, (name, function)) in functions.into_iter().enumerate() {
                let Some(compiled) = code.functions[index] else {
                    assert!(function.tape.outputs.is_empty(), "{display}: {name}");
                    continue;
                };
                let split = function.split.min(function.tape.outputs.len());
                let rest = function.tape.outputs.len() - split;
                let mut values = Vec::new();
                for _ in 0..50 {
                    let drawn = Drawn::new(&mut random, &program);
                    let inputs = drawn.inputs();
                    let (mut a0, mut a1) = (vec![0.0; split], vec![0.0; rest]);
                    interpret::evaluate(function, &inputs, &mut values, &mut a0, &mut a1);
                    let (mut b0, mut b1) = (vec![f64::NAN; split], vec![f64::NAN; rest]);
                    let mut scratch = vec![f64::NAN; code.scratch[index]];
                    // SAFETY: every input has the model's full length, the outputs the tape's
                    // and the scratch the length the compiler asked for, so the code reads
                    // and writes in bounds.
                    unsafe {
                        compiled(
                            drawn.parameters.as_ptr(),
                            drawn.q.as_ptr(),
                            drawn.qdot.as_ptr(),
                            drawn.acceleration.as_ptr(),
                            drawn.lambda.as_ptr(),
                            drawn.t,
                            b0.as_mut_ptr(),
                            b1.as_mut_ptr(),
                            scratch.as_mut_ptr(),
                        )
                    };
                    scratched += usize::from(!scratch.is_empty());
                    for (k, (a, b)) in a0.iter().chain(&a1).zip(b0.iter().chain(&b1)).enumerate() {
                        assert!(
                            a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                            "{display}: {name}[{k}]: interpreter {a:e}, native {b:e}"
                        );
                        compared += 1;
                    }
                }
            }
        }
        assert!(compared > 10_000, "only {compared} values compared");
        assert!(
            scratched > 100,
            "the scratch buffer was used {scratched} times"
        );
    }
}
