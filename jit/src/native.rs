//! Tapes compiled to native code by Cranelift.
//!
//! # What is compiled
//! Every [`FunctionTape`] of a model (`eomgen_symbolic::codegen::program::ModelProgram`, and
//! the Jacobians apart) becomes one function with the signature
//! [`NativeFn`] (the platform's C calling convention):
//!
//! ```text
//! fn(parameters, q, qdot, acceleration, lambda: *const f64, t: f64,
//!    out0, out1, scratch: *mut f64)
//! ```
//!
//! Its body is the tape, instruction for instruction, in one basic block: inputs are loads
//! at fixed offsets, arithmetic and `sqrt`/`abs` are the IEEE instructions, `sign` and `step`
//! are compare-and-select, and the transcendentals are calls of the functions of
//! [`crate::math`] (the same library functions the code of `eomgen::model!` calls) through
//! absolute addresses; `sin_cos` returns its pair in two registers. Outputs are stores at
//! fixed offsets, except runs of [`ZERO_RUN`] or more consecutive outputs that are the
//! constant `+0.0` (the structural zeros of a sparse mass matrix or Jacobian), which are one
//! call of [`math::fill_zero`] each, first thing in the function: the mass matrix of a
//! 1000-mass chain is a million outputs, and storing them one by one took Cranelift 6 s to
//! compile. Cranelift's optimiser (`opt_level = speed`) and register allocator do the
//! rest; nothing is reassociated or contracted into fused multiply–adds, so the results are
//! the interpreter's to the bit.
//!
//! With the environment variable `EOMGEN_JIT_DISASM` set, every function's machine code is
//! printed to standard error as it is compiled (`examples/disassemble.rs`).
//!
//! # Memory
//! All functions of a model live in one [`JITModule`]; [`NativeCode`] owns it and frees the
//! executable pages when it is dropped (the function pointers die with it: the run-time
//! model holds both in one `Arc`).

use std::sync::Mutex;

use cranelift_codegen::ir;
use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{AbiParam, InstBuilder, MemFlagsData, Signature, UserFuncName, types};
use cranelift_codegen::settings::{self, Configurable};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{FuncId, Linkage, Module, default_libcall_names};

use eomgen_symbolic::codegen::program::FunctionTape;
use eomgen_symbolic::codegen::tape::{Input, Instruction};
use eomgen_symbolic::expr::Func;

use crate::math;

/// A compiled function: see the module documentation for its arguments.
///
/// # Safety
/// Callers pass pointers to at least as many `f64`s as the tape reads from each input (its
/// largest index + 1) and writes to each output buffer.
pub(crate) type NativeFn = unsafe extern "C" fn(
    *const f64,
    *const f64,
    *const f64,
    *const f64,
    *const f64,
    f64,
    *mut f64,
    *mut f64,
    *mut f64,
);

/// Functions of more instructions than this keep their shared values in a scratch buffer
/// instead of registers (see [`build`]).
const SCRATCH_FROM_INSTRUCTIONS: usize = 1500;

/// Runs of at least this many consecutive outputs that are the constant `+0.0` are written by
/// one call of [`math::fill_zero`] (see [`zero_runs`]).
const ZERO_RUN: usize = 16;

/// Why the model's functions could not be compiled to native code.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CompileError {
    /// Cranelift has no code generator for this host (the run-time model then interprets
    /// its tapes).
    #[error("no native code generator for this host: {reason}")]
    UnsupportedHost {
        /// Cranelift's explanation.
        reason: String,
    },
    /// A function could not be compiled: Cranelift failed on it, or its program is
    /// malformed.
    #[error("could not compile `{function}` to native code: {reason}")]
    Function {
        /// The function of the model (`mass_matrix_and_forcing`, …).
        function: String,
        /// Cranelift's message.
        reason: String,
    },
    /// The compiled code could not be made executable (mapping or protecting memory failed).
    #[error("could not make the compiled code executable: {reason}")]
    Finalize {
        /// The operating system's or Cranelift's message.
        reason: String,
    },
}

/// The native code of a model's functions and the memory that holds it.
pub(crate) struct NativeCode {
    /// One entry per function compiled, `None` for an empty tape.
    pub(crate) functions: Vec<Option<NativeFn>>,
    /// Per function: how many `f64`s of scratch space it needs (0: none, pass null).
    pub(crate) scratch: Vec<usize>,
    /// Bytes of machine code (without alignment padding and the module's bookkeeping).
    pub(crate) code_bytes: usize,
    /// The module that owns the executable memory, freed on drop.
    module: Mutex<Option<JITModule>>,
}

impl std::fmt::Debug for NativeCode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NativeCode")
            .field("functions", &self.functions.len())
            .field("code_bytes", &self.code_bytes)
            .finish()
    }
}

// SAFETY: after `finalize_definitions` the module is never used again except to free its
// memory in `Drop`, which has exclusive access; the code itself is immutable and reentrant
// (it reads only its arguments and writes only its output buffers), so calling it from
// several threads at once is sound. The `Mutex` makes the module's own `Sync` moot.
unsafe impl Send for NativeCode {}
// SAFETY: as above.
unsafe impl Sync for NativeCode {}

impl Drop for NativeCode {
    fn drop(&mut self) {
        let module = match self.module.get_mut() {
            Ok(m) => m.take(),
            Err(poisoned) => poisoned.into_inner().take(),
        };
        if let Some(module) = module {
            // SAFETY: the function pointers into this memory are in `self.functions`, which
            // is being dropped with it; nothing else holds them (they never leave the crate).
            unsafe { module.free_memory() };
        }
    }
}

/// Which helper functions the code calls, by symbol name.
const HELPERS: [(&str, Func); 13] = [
    ("eomgen_sin", Func::Sin),
    ("eomgen_cos", Func::Cos),
    ("eomgen_tan", Func::Tan),
    ("eomgen_asin", Func::Asin),
    ("eomgen_acos", Func::Acos),
    ("eomgen_atan", Func::Atan),
    ("eomgen_sinh", Func::Sinh),
    ("eomgen_cosh", Func::Cosh),
    ("eomgen_tanh", Func::Tanh),
    ("eomgen_exp", Func::Exp),
    ("eomgen_ln", Func::Ln),
    ("eomgen_sign", Func::Sign),
    ("eomgen_step", Func::Step),
];

struct Imports {
    unary: Vec<(Func, FuncId)>,
    sin_cos: FuncId,
    powf: FuncId,
    atan2: FuncId,
    fill_zero: FuncId,
}

/// Compiles `functions` (named for errors) into one module; an empty tape gets no code.
///
/// # Errors
/// [`CompileError`] naming the host or the function Cranelift could not handle.
pub(crate) fn compile(functions: &[(&str, &FunctionTape)]) -> Result<NativeCode, CompileError> {
    let mut flags = settings::builder();
    let set = |flags: &mut settings::Builder, name: &str, value: &str| {
        flags
            .set(name, value)
            .map_err(|e| CompileError::UnsupportedHost {
                reason: format!("setting {name}={value}: {e}"),
            })
    };
    set(&mut flags, "opt_level", "speed")?;
    set(&mut flags, "use_colocated_libcalls", "false")?;
    set(&mut flags, "is_pic", "false")?;
    // The tapes are built correct by construction; the verifier doubles compile time.
    set(
        &mut flags,
        "enable_verifier",
        if cfg!(debug_assertions) {
            "true"
        } else {
            "false"
        },
    )?;
    let isa = cranelift_native::builder()
        .map_err(|reason| CompileError::UnsupportedHost {
            reason: reason.to_string(),
        })?
        .finish(settings::Flags::new(flags))
        .map_err(|e| CompileError::UnsupportedHost {
            reason: e.to_string(),
        })?;
    let mut builder = JITBuilder::with_isa(isa, default_libcall_names());
    for (name, f) in HELPERS {
        builder.symbol(name, math::unary(f) as *const u8);
    }
    builder.symbol("eomgen_sin_cos", math::sin_cos as *const u8);
    builder.symbol("eomgen_powf", math::powf as *const u8);
    builder.symbol("eomgen_atan2", math::atan2 as *const u8);
    builder.symbol("eomgen_fill_zero", math::fill_zero as *const u8);
    let mut module = JITModule::new(builder);

    let failure = |function: &str, e: &dyn std::fmt::Display| CompileError::Function {
        function: function.to_string(),
        reason: e.to_string(),
    };
    let call_conv = module.isa().default_call_conv();
    let float_signature = |args: usize, returns: usize| {
        let mut s = Signature::new(call_conv);
        s.params
            .extend((0..args).map(|_| AbiParam::new(types::F64)));
        s.returns
            .extend((0..returns).map(|_| AbiParam::new(types::F64)));
        s
    };
    let declare = |module: &mut JITModule, name: &str, signature: &Signature| {
        module
            .declare_function(name, Linkage::Import, signature)
            .map_err(|e| failure(name, &e))
    };
    let mut unary = Vec::new();
    for (name, f) in HELPERS {
        unary.push((f, declare(&mut module, name, &float_signature(1, 1))?));
    }
    let pointer = module.target_config().pointer_type();
    let mut fill_signature = Signature::new(call_conv);
    fill_signature.params.push(AbiParam::new(pointer));
    fill_signature.params.push(AbiParam::new(pointer));
    let imports = Imports {
        unary,
        sin_cos: declare(&mut module, "eomgen_sin_cos", &float_signature(1, 2))?,
        powf: declare(&mut module, "eomgen_powf", &float_signature(2, 1))?,
        atan2: declare(&mut module, "eomgen_atan2", &float_signature(2, 1))?,
        fill_zero: declare(&mut module, "eomgen_fill_zero", &fill_signature)?,
    };

    let mut signature = Signature::new(call_conv);
    for _ in 0..5 {
        signature.params.push(AbiParam::new(pointer));
    }
    signature.params.push(AbiParam::new(types::F64));
    for _ in 0..3 {
        signature.params.push(AbiParam::new(pointer));
    }

    let mut context = module.make_context();
    let mut builder_context = FunctionBuilderContext::new();
    let mut ids: Vec<Option<FuncId>> = Vec::new();
    let mut scratch = Vec::new();
    let mut code_bytes = 0usize;
    for (index, &(name, function)) in functions.iter().enumerate() {
        if function.tape.outputs.is_empty() {
            ids.push(None);
            scratch.push(0);
            continue;
        }
        function
            .tape
            .validate()
            .map_err(|reason| failure(name, &reason))?;
        let id = module
            .declare_function(name, Linkage::Local, &signature)
            .map_err(|e| failure(name, &e))?;
        context.func.signature = signature.clone();
        context.func.name = UserFuncName::user(0, index as u32);
        scratch.push(build(
            &mut module,
            &mut context.func,
            &mut builder_context,
            function,
            &imports,
        ));
        if std::env::var_os("EOMGEN_JIT_DISASM").is_some() {
            context.set_disasm(true);
        }
        module
            .define_function(id, &mut context)
            .map_err(|e| failure(name, &e))?;
        if let Some(vcode) = context.compiled_code().and_then(|c| c.vcode.as_ref())
            && std::env::var_os("EOMGEN_JIT_DISASM").is_some()
        {
            eprintln!("== {name}\n{vcode}");
        }
        code_bytes += context
            .compiled_code()
            .map(|c| c.buffer.total_size() as usize)
            .unwrap_or(0);
        module.clear_context(&mut context);
        ids.push(Some(id));
    }
    module
        .finalize_definitions()
        .map_err(|e| CompileError::Finalize {
            reason: e.to_string(),
        })?;
    let functions = ids
        .iter()
        .map(|id| {
            id.map(|id| {
                let address = module.get_finalized_function(id);
                // SAFETY: `address` is the entry of a function compiled above with exactly the
                // signature of `NativeFn` in the platform's default (C) calling convention.
                unsafe { std::mem::transmute::<*const u8, NativeFn>(address) }
            })
        })
        .collect();
    Ok(NativeCode {
        functions,
        scratch,
        code_bytes,
        module: Mutex::new(Some(module)),
    })
}

/// The function's arguments as Cranelift values.
struct Arguments {
    parameters: ir::Value,
    q: ir::Value,
    qdot: ir::Value,
    acceleration: ir::Value,
    lambda: ir::Value,
    t: ir::Value,
}

/// Tape values as Cranelift values, inputs loaded where they are used.
///
/// Inputs are not loaded where the tape lists them (all at its top) but at their uses: every
/// floating-point register is caller-saved, so a value loaded before a call of `sin_cos` and
/// used after it would be spilled to the stack and reloaded, and a load from the input itself
/// is as cheap. An input is loaded once between two calls.
struct Values {
    values: Vec<Option<ir::Value>>,
    /// Per input instruction: its value and the number of calls emitted before its load.
    loaded: Vec<Option<(u32, ir::Value)>>,
    calls: u32,
    /// In a large function, the scratch buffer and each shared value's slot in it.
    scratch: Option<(ir::Value, Vec<Option<u32>>)>,
}

impl Values {
    fn get(
        &mut self,
        b: &mut FunctionBuilder,
        tape: &eomgen_symbolic::codegen::tape::Tape,
        arguments: &Arguments,
        x: u32,
    ) -> ir::Value {
        let x = x as usize;
        let Instruction::Input(input) = tape.instructions[x] else {
            if let Some((buffer, slots)) = &self.scratch
                && let Some(slot) = slots[x]
            {
                return b.ins().load(
                    types::F64,
                    MemFlagsData::trusted(),
                    *buffer,
                    (slot as i32) * 8,
                );
            }
            // Defined before use (the tape is validated), so never the placeholder.
            return self.values[x].unwrap_or(arguments.t);
        };
        // A large function loads an input at every use (a short live range each).
        if let Some((at, value)) = self.loaded[x]
            && at == self.calls
            && self.scratch.is_none()
        {
            return value;
        }
        let (base, i) = match input {
            Input::Parameter(i) => (arguments.parameters, i),
            Input::Coordinate(i) => (arguments.q, i),
            Input::Velocity(i) => (arguments.qdot, i),
            Input::Acceleration(i) => (arguments.acceleration, i),
            Input::Multiplier(i) => (arguments.lambda, i),
            Input::Time => return arguments.t,
        };
        // Inputs are aligned, in bounds (the caller's contract) and never alias the outputs.
        let value = b
            .ins()
            .load(types::F64, MemFlagsData::trusted(), base, (i as i32) * 8);
        self.loaded[x] = Some((self.calls, value));
        value
    }
}

/// Writes the body of one tape into `func`; returns how many `f64`s of scratch space it needs.
///
/// A large function (more than [`SCRATCH_FROM_INSTRUCTIONS`] instructions: a chain of dozens
/// of links) keeps every value used more than once in a scratch buffer the caller passes,
/// stored once and loaded at each use, and loads its inputs at each use: every value then
/// lives for a few instructions, and the register allocator's work grows linearly with the
/// function. With the values in registers, as for small functions, the allocator spends
/// quadratic time on the long, overlapping live ranges (a 60-link pendulum: 64 % of 4.1 s in
/// `try_to_allocate_bundle_to_reg`).
fn build(
    module: &mut JITModule,
    func: &mut ir::Function,
    builder_context: &mut FunctionBuilderContext,
    function: &FunctionTape,
    imports: &Imports,
) -> usize {
    let mut b = FunctionBuilder::new(func, builder_context);
    let block = b.create_block();
    b.append_block_params_for_function_params(block);
    b.switch_to_block(block);
    b.seal_block(block);
    let params = b.block_params(block).to_vec();
    let arguments = Arguments {
        parameters: params[0],
        q: params[1],
        qdot: params[2],
        acceleration: params[3],
        lambda: params[4],
        t: params[5],
    };
    let (out0, out1, buffer) = (params[6], params[7], params[8]);
    let mut unary_refs: Vec<(Func, ir::FuncRef)> = Vec::new();
    let mut sin_cos_ref = None;
    let mut powf_ref = None;
    let mut atan2_ref = None;
    let tape = &function.tape;
    let count = tape.instructions.len();
    let split = function.split.min(tape.outputs.len());
    // Long runs of zero outputs first, one call each; `filled[j]`: output `j` is written.
    let mut filled = vec![false; tape.outputs.len()];
    let runs = zero_runs(tape, split);
    if !runs.is_empty() {
        let callee = module.declare_func_in_func(imports.fill_zero, b.func);
        let pointer = module.target_config().pointer_type();
        for (start, end) in runs {
            let (base, slot) = if start < split {
                (out0, start)
            } else {
                (out1, start - split)
            };
            let address = b.ins().iadd_imm_s(base, (slot as i64) * 8);
            let length = b.ins().iconst(pointer, (end - start) as i64);
            b.ins().call(callee, &[address, length]);
            filled[start..end].fill(true);
        }
    }
    let mut slots_used = 0u32;
    let scratch = (count > SCRATCH_FROM_INSTRUCTIONS).then(|| {
        let mut uses = vec![0u32; count];
        for instruction in &tape.instructions {
            for x in operands(instruction) {
                uses[x as usize] += 1;
            }
        }
        for &x in &tape.outputs {
            uses[x as usize] += 1;
        }
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
        (buffer, slots)
    });
    let mut values = Values {
        values: vec![None; count],
        loaded: vec![None; count],
        calls: 0,
        scratch,
    };
    // In a large function each output is stored as soon as it is computed (kept to the end,
    // every output would live through the rest of the function): per instruction, the
    // (buffer, byte offset) of the outputs it is.
    let mut destinations: Vec<Vec<(ir::Value, i32)>> = Vec::new();
    if values.scratch.is_some() {
        destinations = vec![Vec::new(); count];
        for (j, &x) in tape.outputs.iter().enumerate() {
            if filled[j] {
                continue;
            }
            let (base, slot) = if j < split {
                (out0, j)
            } else {
                (out1, j - split)
            };
            destinations[x as usize].push((base, (slot as i32) * 8));
        }
    }
    // Stores `value` (instruction `k`) to its scratch slot, if it has one, and to the outputs
    // it is, in a large function.
    let spill = |b: &mut FunctionBuilder, values: &Values, k: usize, value: ir::Value| {
        if let Some((buffer, slots)) = &values.scratch {
            if let Some(slot) = slots[k] {
                b.ins()
                    .store(MemFlagsData::trusted(), value, *buffer, (slot as i32) * 8);
            }
            for &(base, offset) in &destinations[k] {
                b.ins().store(MemFlagsData::trusted(), value, base, offset);
            }
        }
    };
    for (k, instruction) in tape.instructions.iter().enumerate() {
        let mut v = |b: &mut FunctionBuilder, x: u32| values.get(b, tape, &arguments, x);
        let value = match *instruction {
            // Loaded at its uses.
            Instruction::Input(_) => continue,
            Instruction::Const(c) => b.ins().f64const(c),
            Instruction::Neg(x) => {
                let x = v(&mut b, x);
                b.ins().fneg(x)
            }
            Instruction::Add(x, y) => {
                let (x, y) = (v(&mut b, x), v(&mut b, y));
                b.ins().fadd(x, y)
            }
            Instruction::Sub(x, y) => {
                let (x, y) = (v(&mut b, x), v(&mut b, y));
                b.ins().fsub(x, y)
            }
            Instruction::Mul(x, y) => {
                let (x, y) = (v(&mut b, x), v(&mut b, y));
                b.ins().fmul(x, y)
            }
            Instruction::Div(x, y) => {
                let (x, y) = (v(&mut b, x), v(&mut b, y));
                b.ins().fdiv(x, y)
            }
            Instruction::Sqrt(x) => {
                let x = v(&mut b, x);
                b.ins().sqrt(x)
            }
            Instruction::Abs(x) | Instruction::Call(Func::Abs, x) => {
                let x = v(&mut b, x);
                b.ins().fabs(x)
            }
            Instruction::Call(Func::Sign, x) => {
                // −1, 0 or 1; NaN compares false both ways and gives 0, as `sign` does.
                let x = v(&mut b, x);
                let zero = b.ins().f64const(0.0);
                let one = b.ins().f64const(1.0);
                let minus_one = b.ins().f64const(-1.0);
                let positive = b.ins().fcmp(FloatCC::GreaterThan, x, zero);
                let negative = b.ins().fcmp(FloatCC::LessThan, x, zero);
                let low = b.ins().select(negative, minus_one, zero);
                b.ins().select(positive, one, low)
            }
            Instruction::Call(Func::Step, x) => {
                let x = v(&mut b, x);
                let zero = b.ins().f64const(0.0);
                let one = b.ins().f64const(1.0);
                let nonnegative = b.ins().fcmp(FloatCC::GreaterThanOrEqual, x, zero);
                b.ins().select(nonnegative, one, zero)
            }
            Instruction::Call(f, x) => {
                let x = v(&mut b, x);
                let callee = match unary_refs.iter().find(|(g, _)| *g == f) {
                    Some((_, r)) => Some(*r),
                    None => imports.unary.iter().find(|(g, _)| *g == f).map(|(_, id)| {
                        let r = module.declare_func_in_func(*id, b.func);
                        unary_refs.push((f, r));
                        r
                    }),
                };
                // Every function of one argument is imported, so `callee` is always found.
                let Some(callee) = callee else {
                    continue;
                };
                let call = b.ins().call(callee, &[x]);
                values.calls += 1;
                b.inst_results(call)[0]
            }
            Instruction::Powf(x, y) => {
                let (x, y) = (v(&mut b, x), v(&mut b, y));
                let callee = *powf_ref
                    .get_or_insert_with(|| module.declare_func_in_func(imports.powf, b.func));
                let call = b.ins().call(callee, &[x, y]);
                values.calls += 1;
                b.inst_results(call)[0]
            }
            Instruction::Atan2(y, x) => {
                let (y, x) = (v(&mut b, y), v(&mut b, x));
                let callee = *atan2_ref
                    .get_or_insert_with(|| module.declare_func_in_func(imports.atan2, b.func));
                let call = b.ins().call(callee, &[y, x]);
                values.calls += 1;
                b.inst_results(call)[0]
            }
            Instruction::SinCos(x) => {
                let x = v(&mut b, x);
                let callee = *sin_cos_ref
                    .get_or_insert_with(|| module.declare_func_in_func(imports.sin_cos, b.func));
                let call = b.ins().call(callee, &[x]);
                values.calls += 1;
                let results = b.inst_results(call);
                let (s, c) = (results[0], results[1]);
                values.values[k] = Some(s);
                if let Some(slot) = values.values.get_mut(k + 1) {
                    *slot = Some(c);
                }
                spill(&mut b, &values, k, s);
                spill(&mut b, &values, k + 1, c);
                continue;
            }
            // Set with its `SinCos`.
            Instruction::CosOfSinCos(_) => continue,
        };
        values.values[k] = Some(value);
        spill(&mut b, &values, k, value);
    }
    // Outputs are stored two at a time (slots 2k and 2k + 1 of a buffer as one 16-byte
    // store): the caller reads them back at once, often 16 bytes at a time (nalgebra's
    // copies, the solve of `M q̈ = F`), and a 16-byte load of two 8-byte stores cannot be
    // forwarded from the store buffer — it waits ~12 cycles for the stores to retire, while a
    // load within one wider store is forwarded. On the double pendulum's right-hand side this
    // was worth ~4 ns (`benches/runtime_model.rs`).
    if values.scratch.is_some() {
        // Computed outputs and constants are stored already (where they are defined); inputs
        // still are to be.
        for (j, &x) in tape.outputs.iter().enumerate() {
            if filled[j] || !matches!(tape.instructions[x as usize], Instruction::Input(_)) {
                continue;
            }
            let (base, slot) = if j < split {
                (out0, j)
            } else {
                (out1, j - split)
            };
            let value = values.get(&mut b, tape, &arguments, x);
            b.ins()
                .store(MemFlagsData::trusted(), value, base, (slot as i32) * 8);
        }
        b.ins().return_(&[]);
        b.finalize(module.target_config());
        return slots_used as usize;
    }
    for (base, outputs, filled) in [
        (out0, &tape.outputs[..split], &filled[..split]),
        (out1, &tape.outputs[split..], &filled[split..]),
    ] {
        for (pair, (chunk, filled)) in outputs.chunks(2).zip(filled.chunks(2)).enumerate() {
            let offset = (pair as i32) * 16;
            // A pair half in a run of zeros: the other half alone.
            match filled {
                [true] | [true, true] => continue,
                [false, true] | [true, false] => {
                    let half = usize::from(filled[0]);
                    let value = values.get(&mut b, tape, &arguments, chunk[half]);
                    let at = offset + 8 * half as i32;
                    b.ins().store(MemFlagsData::trusted(), value, base, at);
                    continue;
                }
                _ => {}
            }
            let first = values.get(&mut b, tape, &arguments, chunk[0]);
            match chunk.get(1) {
                Some(&second) => {
                    let second = values.get(&mut b, tape, &arguments, second);
                    let vector = b.ins().splat(types::F64X2, first);
                    let vector = b.ins().insertlane(vector, second, 1);
                    b.ins().store(MemFlagsData::trusted(), vector, base, offset);
                }
                None => {
                    b.ins().store(MemFlagsData::trusted(), first, base, offset);
                }
            }
        }
    }
    b.ins().return_(&[]);
    b.finalize(module.target_config());
    slots_used as usize
}

/// The runs `[start, end)` of at least [`ZERO_RUN`] consecutive outputs of one buffer (the
/// outputs before `split` or those after) that are the constant `+0.0` (a `-0.0` keeps its
/// own store, its sign bit set).
fn zero_runs(tape: &eomgen_symbolic::codegen::tape::Tape, split: usize) -> Vec<(usize, usize)> {
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

/// The values an instruction reads.
fn operands(instruction: &Instruction) -> Vec<u32> {
    match *instruction {
        Instruction::Input(_) | Instruction::Const(_) | Instruction::CosOfSinCos(_) => Vec::new(),
        Instruction::Neg(x)
        | Instruction::Sqrt(x)
        | Instruction::Abs(x)
        | Instruction::Call(_, x)
        | Instruction::SinCos(x) => vec![x],
        Instruction::Add(x, y)
        | Instruction::Sub(x, y)
        | Instruction::Mul(x, y)
        | Instruction::Div(x, y)
        | Instruction::Powf(x, y)
        | Instruction::Atan2(x, y) => vec![x, y],
    }
}

#[cfg(test)]
mod tests {
    use eomgen_symbolic::codegen::program::FunctionTape;
    use eomgen_symbolic::codegen::tape::{Input, Instruction, Tape};

    use super::*;

    fn tape(instructions: Vec<Instruction>, outputs: Vec<u32>) -> FunctionTape {
        let split = outputs.len();
        FunctionTape {
            tape: Tape {
                instructions,
                outputs,
            },
            split,
        }
    }

    /// A function whose program cannot be compiled is an error that names it — never a panic
    /// — and the functions before it do not leak (the module is dropped with the error).
    #[test]
    fn a_function_that_cannot_be_compiled_is_an_error_naming_it() {
        let good = tape(
            vec![
                Instruction::Input(Input::Coordinate(0)),
                Instruction::Mul(0, 0),
            ],
            vec![1],
        );
        let forward_reference = tape(
            vec![
                Instruction::Input(Input::Coordinate(0)),
                Instruction::Add(0, 2),
                Instruction::Const(1.0),
            ],
            vec![1],
        );
        let lone_cosine = tape(
            vec![Instruction::Input(Input::Time), Instruction::CosOfSinCos(0)],
            vec![1],
        );
        let missing_output = tape(vec![Instruction::Const(1.0)], vec![3]);
        for (bad, what) in [
            (&forward_reference, "not computed before"),
            (&lone_cosine, "sin_cos"),
            (&missing_output, "instructions"),
        ] {
            let Err(error) = compile(&[("kinetic_energy", &good), ("potential_energy", bad)])
            else {
                panic!("a malformed tape does not compile");
            };
            let CompileError::Function { function, reason } = &error else {
                panic!("{error}");
            };
            assert_eq!(function, "potential_energy");
            assert!(reason.contains(what), "{reason}");
            assert!(error.to_string().contains("`potential_energy`"), "{error}");
        }
        let code = compile(&[("kinetic_energy", &good)]).expect("a good tape compiles");
        let f = code.functions[0].expect("compiled");
        let (q, mut out) = ([3.0], [0.0]);
        // SAFETY: the tape reads q[0] and writes out[0].
        unsafe {
            f(
                [].as_ptr(),
                q.as_ptr(),
                [].as_ptr(),
                [].as_ptr(),
                [].as_ptr(),
                0.0,
                out.as_mut_ptr(),
                [].as_mut_ptr(),
                std::ptr::null_mut(),
            )
        };
        assert_eq!(out[0], 9.0);
    }
}
