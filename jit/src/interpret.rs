//! The reference evaluator of a tape: one pass over its instructions, each computed with the
//! operation or library function the compiled code uses, so its results are the compiled
//! code's to the bit. It is what the native code is tested against, and what a run-time
//! model falls back to on a host Cranelift cannot compile for.

use eomgen_symbolic::codegen::program::FunctionTape;
use eomgen_symbolic::codegen::tape::{Input, Instruction};

use crate::math;

/// The inputs of one evaluation; see [`crate::Inputs`] for shapes.
pub(crate) fn evaluate(
    function: &FunctionTape,
    inputs: &crate::Inputs<'_>,
    values: &mut Vec<f64>,
    out0: &mut [f64],
    out1: &mut [f64],
) {
    let tape = &function.tape;
    values.clear();
    values.resize(tape.instructions.len(), 0.0);
    let read = |slice: &[f64], i: u32| slice.get(i as usize).copied().unwrap_or(f64::NAN);
    for (k, instruction) in tape.instructions.iter().enumerate() {
        let v = |x: u32| values[x as usize];
        let value = match *instruction {
            Instruction::Input(input) => match input {
                Input::Parameter(i) => read(inputs.parameters, i),
                Input::Coordinate(i) => read(inputs.q, i),
                Input::Velocity(i) => read(inputs.qdot, i),
                Input::Acceleration(i) => read(inputs.acceleration, i),
                Input::Multiplier(i) => read(inputs.lambda, i),
                Input::Time => inputs.t,
            },
            Instruction::Const(c) => c,
            Instruction::Neg(x) => -v(x),
            Instruction::Add(x, y) => v(x) + v(y),
            Instruction::Sub(x, y) => v(x) - v(y),
            Instruction::Mul(x, y) => v(x) * v(y),
            Instruction::Div(x, y) => v(x) / v(y),
            Instruction::Sqrt(x) => v(x).sqrt(),
            Instruction::Abs(x) => v(x).abs(),
            Instruction::Call(f, x) => math::unary(f)(v(x)),
            Instruction::Powf(x, y) => math::powf(v(x), v(y)),
            Instruction::Atan2(y, x) => math::atan2(v(y), v(x)),
            Instruction::SinCos(x) => {
                let pair = math::sin_cos(v(x));
                // The next instruction is this pair's cosine.
                if let Some(c) = values.get_mut(k + 1) {
                    *c = pair.cos;
                }
                pair.sin
            }
            Instruction::CosOfSinCos(_) => values[k],
        };
        values[k] = value;
    }
    let (first, second) = tape
        .outputs
        .split_at(function.split.min(tape.outputs.len()));
    for (o, &x) in out0.iter_mut().zip(first) {
        *o = values[x as usize];
    }
    for (o, &x) in out1.iter_mut().zip(second) {
        *o = values[x as usize];
    }
}

/// Order 0 of a model's Taylor series ([`eomgen_symbolic::codegen::taylor`]): the extended
/// tape of `M` and `F` evaluated in place, instruction `k`'s value into `series[k · capacity]`,
/// each with the operation or library function [`evaluate`] uses (so the compiled model's
/// `TaylorFunctions::order_zero` gets the same bits). The inputs `q`, `q̇`, `t` are read from their
/// slots, where the caller has written them; parameters from `parameters`.
///
/// # Panics
/// If `series` has fewer than `tape.instructions.len() · capacity` entries.
pub(crate) fn order_zero_in_place(
    tape: &eomgen_symbolic::codegen::tape::Tape,
    parameters: &[f64],
    capacity: usize,
    series: &mut [f64],
) {
    let c = capacity;
    for (k, instruction) in tape.instructions.iter().enumerate() {
        let v = |x: u32| series[x as usize * c];
        let value = match *instruction {
            Instruction::Input(Input::Parameter(i)) => {
                parameters.get(i as usize).copied().unwrap_or(f64::NAN)
            }
            // Written by the caller.
            Instruction::Input(_) => continue,
            Instruction::Const(x) => x,
            Instruction::Neg(x) => -v(x),
            Instruction::Add(x, y) => v(x) + v(y),
            Instruction::Sub(x, y) => v(x) - v(y),
            Instruction::Mul(x, y) => v(x) * v(y),
            Instruction::Div(x, y) => v(x) / v(y),
            Instruction::Sqrt(x) => v(x).sqrt(),
            Instruction::Abs(x) => v(x).abs(),
            Instruction::Call(f, x) => math::unary(f)(v(x)),
            Instruction::Powf(x, y) => math::powf(v(x), v(y)),
            Instruction::Atan2(y, x) => math::atan2(v(y), v(x)),
            Instruction::SinCos(x) => {
                let pair = math::sin_cos(v(x));
                if let Some(cos) = series.get_mut((k + 1) * c) {
                    *cos = pair.cos;
                }
                pair.sin
            }
            Instruction::CosOfSinCos(_) => continue,
        };
        series[k * c] = value;
    }
}
