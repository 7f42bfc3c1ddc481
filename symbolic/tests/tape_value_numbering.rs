//! The lowering to tapes numbers its values (`codegen::tape`, `Lowering::push`): no tape of a
//! bundled model computes the same operation on the same operands twice (`x + y` and
//! `y + x`, `x · y` and `y · x` counted as the same), and the three-body figure eight computes
//! each pair's pull once, not once per body with the opposite sign.
//!
//! That the shared values are the same bits as the ones they replace is the business of the
//! bit-identity tests of the run-time compiler against the printed code (`jit` and
//! `tests/taylor_coefficients.rs`): an operation on the same operands rounds the same way.

use eomgen_symbolic::codegen::program::ModelProgram;
use eomgen_symbolic::codegen::tape::{Instruction, Tape};

/// An operation's kind and operands, commutative ones sorted; `None` for inputs and
/// constants.
fn key(instruction: &Instruction) -> Option<String> {
    let sorted = |x: u32, y: u32| (x.min(y), x.max(y));
    Some(match *instruction {
        Instruction::Input(_) | Instruction::Const(_) => return None,
        Instruction::Add(x, y) => format!("Add{:?}", sorted(x, y)),
        Instruction::Mul(x, y) => format!("Mul{:?}", sorted(x, y)),
        other => format!("{other:?}"),
    })
}

/// The first operation of `tape` computed twice: `(its first index, the repeat's)`.
fn repeated(tape: &Tape) -> Option<(usize, usize)> {
    let mut seen = std::collections::HashMap::new();
    for (i, instruction) in tape.instructions.iter().enumerate() {
        if let Some(k) = key(instruction)
            && let Some(&first) = seen.get(&k)
        {
            return Some((first, i));
        }
        if let Some(k) = key(instruction) {
            seen.insert(k, i);
        }
    }
    None
}

fn program(source: &str) -> ModelProgram {
    let file = eomgen_symbolic::model::load("m.yaml", source).unwrap();
    ModelProgram::from_file(&file).unwrap().0
}

#[test]
fn no_tape_of_a_bundled_model_repeats_an_operation() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    paths.sort();
    let mut tapes = 0;
    for path in &paths {
        let program = program(&std::fs::read_to_string(path).unwrap());
        for (name, function) in program.functions() {
            if let Some((first, repeat)) = repeated(&function.tape) {
                panic!(
                    "{}: {name}: instruction {repeat} ({:?}) repeats instruction {first}",
                    path.display(),
                    function.tape.instructions[repeat]
                );
            }
            tapes += 1;
        }
    }
    assert!(
        paths.len() >= 40 && tapes >= 40 * 11,
        "{} models, {tapes} tapes",
        paths.len()
    );
}

/// `F` of the figure eight: each of the three pairs' pull along x and y (`G m² Δ · r⁻³`) is
/// one product with the pair's `r⁻³`, used with both signs; before the numbering, each body's
/// equation formed its own (12 such products, 6 of them repeats).
#[test]
fn the_figure_eight_forms_each_pull_once() {
    let program = program(include_str!("../../models/figure_eight.yaml"));
    let tape = &program.mass_matrix_and_forcing.tape;
    let is_power = |v: u32| matches!(tape.instructions[v as usize], Instruction::Powf(..));
    let powers = tape
        .instructions
        .iter()
        .filter(|i| matches!(i, Instruction::Powf(..)));
    assert_eq!(
        powers.count(),
        3,
        "one r⁻³ per pair: {:#?}",
        tape.instructions
    );
    // Every pull is a product with a distance's power.
    let pulls = tape
        .instructions
        .iter()
        .filter(|i| matches!(**i, Instruction::Mul(x, y) if is_power(x) || is_power(y)))
        .count();
    assert_eq!(pulls, 6, "{:#?}", tape.instructions);
}
