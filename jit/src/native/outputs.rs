//! Where a compiled function's outputs go: its two output buffers, the runs of zero outputs
//! written by one call each, and, in a large function, the scratch slots of its shared values
//! and the buffer slots of its outputs.

use cranelift_codegen::ir::{self, InstBuilder};
use cranelift_frontend::FunctionBuilder;
use cranelift_jit::JITModule;
use cranelift_module::Module;

use eomgen_symbolic::codegen::tape::{Instruction, Tape};

use super::module::Imports;

/// Runs of at least this many consecutive outputs that are the constant `+0.0` are written by
/// one call of [`crate::math::fill_zero`] (see [`zero_runs`]).
pub(super) const ZERO_RUN: usize = 16;

/// The two output buffers of a function: outputs before `split` go to `out0`, the others to
/// `out1`.
pub(super) struct OutputBuffers {
    pub(super) out0: ir::Value,
    pub(super) out1: ir::Value,
    pub(super) split: usize,
}

impl OutputBuffers {
    /// The buffer of output `j` and its index in that buffer.
    pub(super) fn slot(&self, j: usize) -> (ir::Value, usize) {
        if j < self.split {
            (self.out0, j)
        } else {
            (self.out1, j - self.split)
        }
    }
}

/// Writes the long runs of zero outputs ([`zero_runs`]) first, one call of
/// [`crate::math::fill_zero`] each; returns `filled`, where `filled[j]` says output `j` is written.
pub(super) fn fill_zero_runs(
    b: &mut FunctionBuilder,
    module: &mut JITModule,
    imports: &Imports,
    tape: &Tape,
    outputs: &OutputBuffers,
) -> Vec<bool> {
    let mut filled = vec![false; tape.outputs.len()];
    let runs = zero_runs(tape, outputs.split);
    if !runs.is_empty() {
        let callee = module.declare_func_in_func(imports.fill_zero, b.func);
        let pointer = module.target_config().pointer_type();
        for (start, end) in runs {
            let (base, slot) = outputs.slot(start);
            let address = b.ins().iadd_imm_s(base, (slot as i64) * 8);
            let length = b.ins().iconst(pointer, (end - start) as i64);
            b.ins().call(callee, &[address, length]);
            filled[start..end].fill(true);
        }
    }
    filled
}

/// The scratch slot of each instruction of a large function (a value used more than once, or
/// a `sin_cos`, that is neither an input nor a constant), and how many slots there are.
pub(super) fn scratch_slots(tape: &Tape) -> (Vec<Option<u32>>, usize) {
    let mut uses = vec![0u32; tape.instructions.len()];
    for instruction in &tape.instructions {
        for x in operands(instruction) {
            uses[x as usize] += 1;
        }
    }
    for &x in &tape.outputs {
        uses[x as usize] += 1;
    }
    let mut slots_used = 0u32;
    let slots: Vec<Option<u32>> = tape
        .instructions
        .iter()
        .zip(&uses)
        .map(|(instruction, &n)| {
            let shared = n >= 2 || matches!(instruction, Instruction::SinCos(_));
            let kept = !matches!(instruction, Instruction::Input(_) | Instruction::Const(_));
            (shared && kept).then(|| {
                slots_used += 1;
                slots_used - 1
            })
        })
        .collect();
    (slots, slots_used as usize)
}

/// Per instruction, the (buffer, byte offset) of the outputs it is, leaving out the outputs
/// a run of zeros writes (`filled`).
pub(super) fn output_destinations(
    tape: &Tape,
    filled: &[bool],
    outputs: &OutputBuffers,
) -> Vec<Vec<(ir::Value, i32)>> {
    let mut destinations = vec![Vec::new(); tape.instructions.len()];
    for (j, &x) in tape.outputs.iter().enumerate() {
        if filled[j] {
            continue;
        }
        let (base, slot) = outputs.slot(j);
        destinations[x as usize].push((base, (slot as i32) * 8));
    }
    destinations
}

/// The runs `[start, end)` of at least [`ZERO_RUN`] consecutive outputs of one buffer (the
/// outputs before `split` or those after) that are the constant `+0.0` (a `-0.0` keeps its
/// own store, its sign bit set).
fn zero_runs(tape: &Tape, split: usize) -> Vec<(usize, usize)> {
    let zero = |j: usize| matches!(tape.instructions[tape.outputs[j] as usize], Instruction::Const(c) if c.to_bits() == 0);
    let mut runs = Vec::new();
    for (from, to) in [(0, split), (split, tape.outputs.len())] {
        let mut j = from;
        while j < to {
            if !zero(j) {
                j += 1;
                continue;
            }
            let start = j;
            while j < to && zero(j) {
                j += 1;
            }
            if j - start >= ZERO_RUN {
                runs.push((start, j));
            }
        }
    }
    runs
}

/// The values an instruction reads (none for a `CosOfSinCos`, whose value is its `SinCos`'s
/// second result).
fn operands(instruction: &Instruction) -> Vec<u32> {
    let mut read = Vec::new();
    if !matches!(instruction, Instruction::CosOfSinCos(_)) {
        instruction.map_operands(|x| {
            read.push(x);
            x
        });
    }
    read
}
