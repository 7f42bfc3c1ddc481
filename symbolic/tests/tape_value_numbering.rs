//! Value numbering for the Taylor recurrences (`Tape::numbered`, used by `taylor_program`):
//! the order-0 tape of no bundled model's Taylor program computes the same operation on the
//! same operands twice among the tape's own instructions (`x + y` and `y + x`, `x · y` and
//! `y · x` counted as the same), and the three-body figure eight forms each pair's pull once,
//! not once per body with the opposite sign.
//!
//! That the numbered tape computes the same bits is `eomgen_jit`'s
//! `numbered_tapes_compute_the_same_bits_on_every_bundled_model` (it has the evaluator).

use eomgen_symbolic::codegen::program::ModelProgram;
use eomgen_symbolic::codegen::tape::{Instruction, Tape};
use eomgen_symbolic::codegen::taylor::{TaylorPlan, taylor_program};

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

/// The first operation among the first `len` instructions of `tape` computed twice: `(its
/// first index, the repeat's)`.
fn repeated(tape: &Tape, len: usize) -> Option<(usize, usize)> {
    let mut seen = std::collections::HashMap::new();
    for (i, instruction) in tape.instructions[..len].iter().enumerate() {
        if let Some(k) = key(instruction) {
            if let Some(&first) = seen.get(&k) {
                return Some((first, i));
            }
            seen.insert(k, i);
        }
    }
    None
}

/// The model's program and its Taylor plan (`None` with constraints or functions without a
/// recurrence).
fn plan(source: &str) -> (ModelProgram, Option<TaylorPlan>) {
    let file = eomgen_symbolic::model::load("m.yaml", source).unwrap();
    let program = ModelProgram::from_file(&file).unwrap().0;
    let n = program.num_dofs();
    let constraints = program.description.constraints.len();
    let taylor = taylor_program(&program.mass_matrix_and_forcing, n, constraints).ok();
    (program, taylor)
}

#[test]
fn no_taylor_program_of_a_bundled_model_repeats_an_operation_of_its_tape() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    paths.sort();
    let (mut checked, mut shortened) = (0, 0);
    for path in &paths {
        let (program, Some(taylor)) = plan(&std::fs::read_to_string(path).unwrap()) else {
            continue;
        };
        let tape = &program.mass_matrix_and_forcing.tape;
        // The tape's own instructions come first in order 0, the auxiliary ones after.
        let own = tape.numbered().instructions.len();
        if let Some((first, repeat)) = repeated(&taylor.order_zero, own) {
            panic!(
                "{}: order-0 instruction {repeat} ({:?}) repeats instruction {first}",
                path.display(),
                taylor.order_zero.instructions[repeat]
            );
        }
        assert_eq!(
            taylor.order_zero.outputs.len(),
            tape.outputs.len(),
            "{}",
            path.display()
        );
        checked += 1;
        shortened += usize::from(own < tape.instructions.len());
    }
    assert!(checked >= 35, "{checked} programs checked");
    assert!(shortened >= 10, "{shortened} of {checked} tapes shortened");
}

/// `F` of the figure eight: each of the three pairs' pull along x and y (`G m² Δ · r⁻³`) is
/// one product with the pair's `r⁻³`, used with both signs; as lowered, each body's equation
/// forms its own (12 such products, 6 of them repeats).
#[test]
fn the_figure_eight_forms_each_pull_once() {
    let (program, taylor) = plan(include_str!("../../models/figure_eight.yaml"));
    let pulls = |tape: &Tape| {
        let is_power = |v: u32| matches!(tape.instructions[v as usize], Instruction::Powf(..));
        let powers = tape
            .instructions
            .iter()
            .filter(|i| matches!(i, Instruction::Powf(..)))
            .count();
        let products = tape
            .instructions
            .iter()
            .filter(|i| matches!(**i, Instruction::Mul(x, y) if is_power(x) || is_power(y)))
            .count();
        (powers, products)
    };
    assert_eq!(pulls(&program.mass_matrix_and_forcing.tape), (3, 12));
    assert_eq!(pulls(&taylor.unwrap().order_zero), (3, 6));
}
