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
use eomgen_symbolic::codegen::taylor::{TaylorPlan, model_taylor_plan};

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

/// The model's program and its Taylor plan (`None` with functions without a recurrence).
fn plan(source: &str) -> (ModelProgram, Option<TaylorPlan>) {
    let file = eomgen_symbolic::model::load("m.yaml", source).unwrap();
    let program = ModelProgram::from_file(&file).unwrap().0;
    let taylor = model_taylor_plan(&program).ok();
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
        let tape = &program.taylor_tape().tape;
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

/// What may and may not be merged, on a tape written by hand: only `Add` and `Mul` are
/// commutative, so `x − y`, `x / y`, `xʸ` and `atan2(x, y)` stay apart from their operands
/// swapped; calls of different functions on one operand stay apart, and from the `sin_cos`
/// of it; a repeated `sin_cos` goes with its cosine, the pair adjacent, and its users are
/// renumbered to the first. (No bundled model has a swapped quotient, power or `atan2`, or
/// two functions of one operand, so the bundled-model tests would not see such a merge.)
#[test]
fn only_the_same_operation_on_the_same_operands_is_merged() {
    use Instruction as I;
    use eomgen_symbolic::codegen::tape::Input;
    use eomgen_symbolic::expr::Func;
    let (x, y) = (0, 1);
    let tape = Tape {
        instructions: vec![
            I::Input(Input::Coordinate(0)), // 0: x
            I::Input(Input::Velocity(0)),   // 1: y
            I::Sub(x, y),                   // 2
            I::Sub(y, x),                   // 3: kept
            I::Div(x, y),                   // 4
            I::Div(y, x),                   // 5: kept
            I::Powf(x, y),                  // 6
            I::Powf(y, x),                  // 7: kept
            I::Atan2(x, y),                 // 8
            I::Atan2(y, x),                 // 9: kept
            I::Call(Func::Sin, x),          // 10
            I::Call(Func::Tan, x),          // 11: kept
            I::SinCos(x),                   // 12: kept (not the call of sin)
            I::CosOfSinCos(12),             // 13
            I::Add(x, y),                   // 14
            I::Add(y, x),                   // 15: merged with 14
            I::Mul(x, y),                   // 16
            I::Mul(y, x),                   // 17: merged with 16
            I::SinCos(x),                   // 18: merged with 12
            I::CosOfSinCos(18),             // 19: merged with 13
            I::Mul(15, 19),                 // 20: (x + y) cos x, read through the merged values
            I::Div(17, 18),                 // 21: x y / sin x
        ],
        outputs: vec![15, 17, 19, 20, 21, 3, 5, 7, 9, 11],
    };
    tape.validate().unwrap();
    let numbered = tape.numbered();
    numbered.validate().unwrap();
    assert_eq!(numbered.instructions.len(), tape.instructions.len() - 4);
    assert_eq!(numbered.instructions[..15], tape.instructions[..15]);
    assert_eq!(
        numbered.instructions[15..],
        [I::Mul(x, y), I::Mul(14, 13), I::Div(15, 12)]
    );
    assert_eq!(numbered.outputs, [14, 15, 13, 16, 17, 3, 5, 7, 9, 11]);
}
