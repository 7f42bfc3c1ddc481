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
//! are compare-and-select, a power with a constant half-integer exponent is its square root
//! and products ([`crate::math::half_power`], the operations of the `powf` the code of
//! `eomgen::model!` calls), and the transcendentals are calls of the functions of
//! [`crate::math`] (the same library functions the code of `eomgen::model!` calls) through
//! absolute addresses; `sin_cos` returns its pair in two registers. Outputs are stores at
//! fixed offsets, except runs of [`ZERO_RUN`] or more consecutive outputs that are the
//! constant `+0.0` (the structural zeros of a sparse mass matrix or Jacobian), which are one
//! call of [`crate::math::fill_zero`] each, first thing in the function: the mass matrix of a
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

use cranelift_codegen::ir;
use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{AbiParam, InstBuilder, MemFlagsData, Signature, UserFuncName, types};
use cranelift_codegen::isa::CallConv;
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::JITModule;
use cranelift_module::{FuncId, Linkage, Module};

use eomgen_symbolic::codegen::program::FunctionTape;
use eomgen_symbolic::codegen::tape::{Input, Instruction};
use eomgen_symbolic::expr::Func;

mod module;
mod outputs;
pub use module::CompileError;
pub(crate) use module::{CodeLayout, Imports, ModuleMemory, declare_imports, failure, new_module};
use outputs::{OutputBuffers, ZERO_RUN, fill_zero_runs, output_destinations, scratch_slots};

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

/// A compiled right-hand side `ẏ = [q̇; M⁻¹F]` ([`crate::first_order`]): `(parameters, y, t,
/// ẏ)`, with `q` the first `n` values of `y` and `q̇` the next `n`; returns its verdict, 1 if
/// `M` is positive definite and `q̈` finite, else 0.
///
/// # Safety
/// As [`NativeFn`]: `y` and `ẏ` hold `2n` values.
pub(crate) type FirstOrderFn = unsafe extern "C" fn(*const f64, *const f64, f64, *mut f64) -> u8;

/// The arguments a compiled function takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Layout {
    /// [`NativeFn`]'s nine.
    Model,
    /// [`FirstOrderFn`]'s four, for a model of `n` degrees of freedom: no accelerations,
    /// multipliers or scratch space, and five arguments fewer to pass (the right-hand side is
    /// called millions of times, and on a model of one or two degrees of freedom the call is a
    /// good part of it).
    FirstOrder { n: usize },
}

/// Functions of more instructions than this keep their shared values in a scratch buffer
/// instead of registers (see [`build`]).
const SCRATCH_FROM_INSTRUCTIONS: usize = 1500;

/// The native code of a model's functions and the memory that holds it.
pub(crate) struct NativeCode {
    /// One entry per function compiled, `None` for an empty tape.
    pub(crate) functions: Vec<Option<NativeFn>>,
    /// Per function: how many `f64`s of scratch space it needs (0: none, pass null).
    pub(crate) scratch: Vec<usize>,
    /// The fused right-hand side, where one was given and compiled.
    pub(crate) first_order: Option<FirstOrderFn>,
    /// Bytes of machine code (without alignment padding and the module's bookkeeping).
    pub(crate) code_bytes: usize,
    /// The module that owns the executable memory, freed on drop.
    _memory: ModuleMemory,
}

impl std::fmt::Debug for NativeCode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NativeCode")
            .field("functions", &self.functions.len())
            .field("code_bytes", &self.code_bytes)
            .finish()
    }
}

/// Compiles `functions` (named for errors) into one module, an empty tape getting no code,
/// and `first_order`, a fused right-hand side of a model of `n` degrees of freedom
/// ([`FirstOrderFn`]; not compiled if it would need scratch space, or if its tape is not `2n` values
/// of `ẏ` then `n` pivots).
///
/// # Errors
/// [`CompileError`] naming the host or the function Cranelift could not handle.
pub(crate) fn compile(
    functions: &[(&str, &FunctionTape)],
    first_order: Option<(&FunctionTape, usize)>,
) -> Result<NativeCode, CompileError> {
    let mut module = new_module(CodeLayout::Pages)?;
    let imports = declare_imports(&mut module)?;
    let (call_conv, pointer) = (
        module.isa().default_call_conv(),
        module.target_config().pointer_type(),
    );
    let signature = |layout: Layout| tape_signature(call_conv, pointer, layout);
    // Its shape checked here, so that `build` may index its pivots: `ẏ` (`2n` values stored),
    // then the `n` pivots its verdict tests (`crate::first_order`).
    let first_order = first_order.filter(|(f, n)| {
        f.tape.instructions.len() <= SCRATCH_FROM_INSTRUCTIONS
            && f.split == 2 * n
            && f.tape.outputs.len() == 3 * n
    });
    let all = functions
        .iter()
        .map(|&(name, f)| (name, f, Layout::Model))
        .chain(first_order.map(|(f, n)| ("first_order_rhs", f, Layout::FirstOrder { n })));

    let mut context = module.make_context();
    let mut builder_context = FunctionBuilderContext::new();
    let mut ids: Vec<Option<FuncId>> = Vec::new();
    let mut scratch = Vec::new();
    let mut code_bytes = 0usize;
    for (index, (name, function, layout)) in all.enumerate() {
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
            .declare_function(name, Linkage::Local, &signature(layout))
            .map_err(|e| failure(name, &e))?;
        context.func.signature = signature(layout);
        context.func.name = UserFuncName::user(0, index as u32);
        scratch.push(build(
            &mut module,
            &mut context.func,
            &mut builder_context,
            function,
            &imports,
            layout,
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
    // The fused right-hand side, if compiled, is the last.
    let fused = match first_order {
        Some(_) => ids.pop().flatten(),
        None => None,
    };
    scratch.truncate(functions.len());
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
    let first_order = fused.map(|id| {
        let address = module.get_finalized_function(id);
        // SAFETY: as above, with the signature of `FirstOrderFn` (`Layout::FirstOrder`).
        unsafe { std::mem::transmute::<*const u8, FirstOrderFn>(address) }
    });
    Ok(NativeCode {
        functions,
        first_order,
        scratch,
        code_bytes,
        _memory: ModuleMemory::new(module),
    })
}

/// The signature of a tape's function of `layout` ([`NativeFn`] or [`FirstOrderFn`]): its
/// pointers, then `t`, then its other pointers.
fn tape_signature(call_conv: CallConv, pointer: ir::Type, layout: Layout) -> Signature {
    let mut signature = Signature::new(call_conv);
    let (before, after) = match layout {
        Layout::Model => (5, 3),
        Layout::FirstOrder { .. } => (2, 1),
    };
    let pointers = |k: usize| (0..k).map(|_| AbiParam::new(pointer));
    signature.params.extend(pointers(before));
    signature.params.push(AbiParam::new(types::F64));
    signature.params.extend(pointers(after));
    if let Layout::FirstOrder { .. } = layout {
        // Zero-extended where the calling convention asks for a `u8` result to be.
        signature.returns.push(AbiParam::new(types::I8).uext());
    }
    signature
}

/// The function's arguments as Cranelift values.
struct Arguments {
    parameters: ir::Value,
    q: ir::Value,
    qdot: ir::Value,
    /// Bytes from `qdot` to `q̇₀` (`8n` in a [`Layout::FirstOrder`] function, whose `qdot` is
    /// `y`).
    qdot_offset: i32,
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
        let (base, offset, i) = match input {
            Input::Parameter(i) => (arguments.parameters, 0, i),
            Input::Coordinate(i) => (arguments.q, 0, i),
            Input::Velocity(i) => (arguments.qdot, arguments.qdot_offset, i),
            Input::Acceleration(i) => (arguments.acceleration, 0, i),
            Input::Multiplier(i) => (arguments.lambda, 0, i),
            Input::Time => return arguments.t,
        };
        // Inputs are aligned, in bounds (the caller's contract) and never alias the outputs.
        let value = b.ins().load(
            types::F64,
            MemFlagsData::trusted(),
            base,
            offset + (i as i32) * 8,
        );
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
///
/// The body is written in four steps, in this order (the order of the Cranelift instructions
/// and of the imported functions' references is part of the generated code): the calls that
/// zero long runs of outputs ([`fill_zero_runs`]), the tape's instructions one by one
/// ([`Emitter::instruction`]), then the outputs not stored yet ([`Emitter::store_inputs`] in
/// a large function, [`Emitter::store_output_pairs`] otherwise); a first-order function then
/// returns its verdict ([`Emitter::verdict`]) on the outputs it does not store, its pivots.
fn build(
    module: &mut JITModule,
    func: &mut ir::Function,
    builder_context: &mut FunctionBuilderContext,
    function: &FunctionTape,
    imports: &Imports,
    layout: Layout,
) -> usize {
    let mut b = FunctionBuilder::new(func, builder_context);
    let params = enter(&mut b);
    let (arguments, out0, out1, scratch_buffer) = match layout {
        Layout::Model => (
            Arguments {
                parameters: params[0],
                q: params[1],
                qdot: params[2],
                qdot_offset: 0,
                acceleration: params[3],
                lambda: params[4],
                t: params[5],
            },
            params[6],
            params[7],
            Some(params[8]),
        ),
        // The tape reads no accelerations or multipliers (its extent is checked before its
        // call): `y` stands in for their buffers.
        Layout::FirstOrder { n } => (
            Arguments {
                parameters: params[0],
                q: params[1],
                qdot: params[1],
                qdot_offset: (8 * n) as i32,
                acceleration: params[1],
                lambda: params[1],
                t: params[2],
            },
            params[3],
            params[3],
            None,
        ),
    };
    let tape = &function.tape;
    let outputs = OutputBuffers {
        out0,
        out1,
        split: function.split.min(tape.outputs.len()),
    };
    let count = tape.instructions.len();
    // A first-order function stores `ẏ` only (no run of zeros: it has at most `3n` outputs,
    // below `ZERO_RUN`); its pivots go into the verdict it returns.
    const _: () = assert!(3 * crate::first_order::FUSED_UP_TO < ZERO_RUN);
    let mut filled = fill_zero_runs(&mut b, module, imports, tape, &outputs);
    if let Layout::FirstOrder { n } = layout {
        filled[2 * n..].fill(true);
    }
    let (scratch, slots_used) = match scratch_buffer {
        Some(buffer) if count > SCRATCH_FROM_INSTRUCTIONS => {
            let (slots, used) = scratch_slots(tape);
            (Some((buffer, slots)), used)
        }
        _ => (None, 0),
    };
    // In a large function each output is stored as soon as it is computed (kept to the end,
    // every output would live through the rest of the function).
    let destinations = if scratch.is_some() {
        output_destinations(tape, &filled, &outputs)
    } else {
        Vec::new()
    };
    let mut emitter = Emitter {
        b,
        module,
        imports,
        tape,
        arguments,
        outputs,
        values: Values {
            values: vec![None; count],
            loaded: vec![None; count],
            calls: 0,
            scratch,
        },
        callees: Callees::default(),
        destinations,
    };
    for (k, instruction) in tape.instructions.iter().enumerate() {
        emitter.instruction(k, *instruction);
    }
    if emitter.values.scratch.is_some() {
        emitter.store_inputs(&filled);
    } else {
        emitter.store_output_pairs(&filled);
    }
    let verdict = match layout {
        Layout::FirstOrder { n } => vec![emitter.verdict(n)],
        Layout::Model => Vec::new(),
    };
    let Emitter { mut b, module, .. } = emitter;
    b.ins().return_(&verdict);
    b.finalize(module.target_config());
    slots_used
}

/// Opens the function's one entry block (sealed, current) and returns its parameters, the
/// function's arguments.
pub(crate) fn enter(b: &mut FunctionBuilder) -> Vec<ir::Value> {
    let entry = b.create_block();
    b.append_block_params_for_function_params(entry);
    b.switch_to_block(entry);
    b.seal_block(entry);
    b.block_params(entry).to_vec()
}

/// The imported helpers as references from the function being built, each declared at its
/// first call (in the order of the calls).
#[derive(Default)]
struct Callees {
    unary: Vec<(Func, ir::FuncRef)>,
    sin_cos: Option<ir::FuncRef>,
    powf: Option<ir::FuncRef>,
    atan2: Option<ir::FuncRef>,
}

/// The reference to the import `id` from `func`, declared on first use and kept in `cached`.
fn imported(
    module: &mut JITModule,
    func: &mut ir::Function,
    cached: &mut Option<ir::FuncRef>,
    id: FuncId,
) -> ir::FuncRef {
    *cached.get_or_insert_with(|| module.declare_func_in_func(id, func))
}

/// The state of [`build`] while it writes the instructions of one tape.
struct Emitter<'f, 'm> {
    b: FunctionBuilder<'f>,
    module: &'m mut JITModule,
    imports: &'m Imports,
    tape: &'m eomgen_symbolic::codegen::tape::Tape,
    arguments: Arguments,
    outputs: OutputBuffers,
    values: Values,
    callees: Callees,
    /// In a large function, per instruction, the outputs it is (see [`output_destinations`]);
    /// empty otherwise.
    destinations: Vec<Vec<(ir::Value, i32)>>,
}

impl Emitter<'_, '_> {
    /// The Cranelift value of tape value `x` (see [`Values::get`]).
    fn value(&mut self, x: u32) -> ir::Value {
        self.values.get(&mut self.b, self.tape, &self.arguments, x)
    }

    /// Calls `callee` with `arguments`, counting the call (inputs are reloaded after it).
    fn call(&mut self, callee: ir::FuncRef, arguments: &[ir::Value]) -> ir::Inst {
        let call = self.b.ins().call(callee, arguments);
        self.values.calls += 1;
        call
    }

    /// A call of the import `id`, its reference declared on first use and kept in the field
    /// of [`Callees`] that `cached` picks.
    fn call_import(
        &mut self,
        cached: fn(&mut Callees) -> &mut Option<ir::FuncRef>,
        id: FuncId,
        arguments: &[ir::Value],
    ) -> ir::Inst {
        let callee = imported(self.module, self.b.func, cached(&mut self.callees), id);
        self.call(callee, arguments)
    }

    /// The reference to the helper of the function of one argument `f`; every such function
    /// is imported, so it is always found.
    fn unary_callee(&mut self, f: Func) -> Option<ir::FuncRef> {
        match self.callees.unary.iter().find(|(g, _)| *g == f) {
            Some((_, r)) => Some(*r),
            None => self
                .imports
                .unary
                .iter()
                .find(|(g, _)| *g == f)
                .map(|(_, id)| {
                    let r = self.module.declare_func_in_func(*id, self.b.func);
                    self.callees.unary.push((f, r));
                    r
                }),
        }
    }

    /// Stores `value` (instruction `k`) to its scratch slot, if it has one, and to the outputs
    /// it is, in a large function.
    fn spill(&mut self, k: usize, value: ir::Value) {
        if let Some((buffer, slots)) = &self.values.scratch {
            if let Some(slot) = slots[k] {
                self.b
                    .ins()
                    .store(MemFlagsData::trusted(), value, *buffer, (slot as i32) * 8);
            }
            for &(base, offset) in &self.destinations[k] {
                self.b
                    .ins()
                    .store(MemFlagsData::trusted(), value, base, offset);
            }
        }
    }

    /// Writes instruction `k` of the tape (inputs are loaded at their uses instead).
    // Long: one arm per tape instruction, each a few lines of Cranelift code; the match is the
    // instruction set.
    fn instruction(&mut self, k: usize, instruction: Instruction) {
        let value = match instruction {
            // Loaded at its uses.
            Instruction::Input(_) => return,
            Instruction::Const(c) => self.b.ins().f64const(c),
            Instruction::Neg(x) => {
                let x = self.value(x);
                self.b.ins().fneg(x)
            }
            Instruction::Add(x, y) => {
                let (x, y) = (self.value(x), self.value(y));
                self.b.ins().fadd(x, y)
            }
            Instruction::Sub(x, y) => {
                let (x, y) = (self.value(x), self.value(y));
                self.b.ins().fsub(x, y)
            }
            Instruction::Mul(x, y) => {
                let (x, y) = (self.value(x), self.value(y));
                self.b.ins().fmul(x, y)
            }
            Instruction::Div(x, y) => {
                let (x, y) = (self.value(x), self.value(y));
                self.b.ins().fdiv(x, y)
            }
            Instruction::Sqrt(x) => {
                let x = self.value(x);
                self.b.ins().sqrt(x)
            }
            Instruction::Abs(x) | Instruction::Call(Func::Abs, x) => {
                let x = self.value(x);
                self.b.ins().fabs(x)
            }
            Instruction::Call(Func::Sign, x) => {
                // −1, 0 or 1; NaN compares false both ways and gives 0, as `sign` does.
                let x = self.value(x);
                let b = &mut self.b;
                let zero = b.ins().f64const(0.0);
                let one = b.ins().f64const(1.0);
                let minus_one = b.ins().f64const(-1.0);
                let positive = b.ins().fcmp(FloatCC::GreaterThan, x, zero);
                let negative = b.ins().fcmp(FloatCC::LessThan, x, zero);
                let low = b.ins().select(negative, minus_one, zero);
                b.ins().select(positive, one, low)
            }
            Instruction::Call(Func::Step, x) => {
                let x = self.value(x);
                let b = &mut self.b;
                let zero = b.ins().f64const(0.0);
                let one = b.ins().f64const(1.0);
                let nonnegative = b.ins().fcmp(FloatCC::GreaterThanOrEqual, x, zero);
                b.ins().select(nonnegative, one, zero)
            }
            Instruction::Call(f, x) => {
                let x = self.value(x);
                let Some(callee) = self.unary_callee(f) else {
                    return;
                };
                let call = self.call(callee, &[x]);
                self.b.inst_results(call)[0]
            }
            Instruction::Powf(x, y) => match crate::math::constant_half_power(self.tape, y) {
                Some(half) => {
                    let x = self.value(x);
                    crate::math::half_power(&mut self.b, x, half)
                }
                None => {
                    let (x, y) = (self.value(x), self.value(y));
                    let call = self.call_import(|c| &mut c.powf, self.imports.powf, &[x, y]);
                    self.b.inst_results(call)[0]
                }
            },
            Instruction::Atan2(y, x) => {
                let (y, x) = (self.value(y), self.value(x));
                let call = self.call_import(|c| &mut c.atan2, self.imports.atan2, &[y, x]);
                self.b.inst_results(call)[0]
            }
            Instruction::SinCos(x) => {
                let x = self.value(x);
                let call = self.call_import(|c| &mut c.sin_cos, self.imports.sin_cos, &[x]);
                let results = self.b.inst_results(call);
                let (s, c) = (results[0], results[1]);
                self.values.values[k] = Some(s);
                if let Some(slot) = self.values.values.get_mut(k + 1) {
                    *slot = Some(c);
                }
                self.spill(k, s);
                self.spill(k + 1, c);
                return;
            }
            // Set with its `SinCos`.
            Instruction::CosOfSinCos(_) => return,
        };
        self.values.values[k] = Some(value);
        self.spill(k, value);
    }

    /// A first-order function's verdict: 1 if every pivot (outputs `2n..3n`) is positive and
    /// every `q̈` (outputs `n..2n`) finite, else 0 (a NaN fails both). Tested two at a time
    /// (an odd `n`'s last value beside itself): for two masses one test at a time took 22
    /// instructions and 6.96–6.98 ns a right-hand side, two at a time 14 and 6.46–6.50 ns
    /// (`benches/runtime_model.rs`, docs/performance.md).
    fn verdict(&mut self, n: usize) -> ir::Value {
        let outputs = &self.tape.outputs;
        let zero = self.b.ins().f64const(0.0);
        let zero = self.b.ins().splat(types::F64X2, zero);
        let infinity = self.b.ins().f64const(f64::INFINITY);
        let infinity = self.b.ins().splat(types::F64X2, infinity);
        let mut all: Option<ir::Value> = None;
        for i in (0..n).step_by(2) {
            let j = (i + 1).min(n - 1);
            let pivots = self.pair(outputs[2 * n + i], outputs[2 * n + j]);
            let qdd = self.pair(outputs[n + i], outputs[n + j]);
            let positive = self.b.ins().fcmp(FloatCC::GreaterThan, pivots, zero);
            let magnitude = self.b.ins().fabs(qdd);
            let finite = self.b.ins().fcmp(FloatCC::LessThan, magnitude, infinity);
            let both = self.b.ins().band(positive, finite);
            all = Some(match all {
                Some(all) => self.b.ins().band(all, both),
                None => both,
            });
        }
        match all {
            Some(all) => self.b.ins().vall_true(all),
            None => self.b.ins().iconst(types::I8, 1),
        }
    }

    /// Tape values `first` and `second` as the lanes of one `f64x2` (`first` in both where
    /// they are the same value), built as [`Emitter::store_output_pairs`] builds a pair.
    fn pair(&mut self, first: u32, second: u32) -> ir::Value {
        let first_value = self.value(first);
        let vector = self.b.ins().splat(types::F64X2, first_value);
        if second == first {
            return vector;
        }
        let second = self.value(second);
        self.b.ins().insertlane(vector, second, 1)
    }

    /// In a large function, stores the outputs that are inputs: computed outputs and
    /// constants are stored already, where they are defined.
    fn store_inputs(&mut self, filled: &[bool]) {
        let tape = self.tape;
        for (j, &x) in tape.outputs.iter().enumerate() {
            if filled[j] || !matches!(tape.instructions[x as usize], Instruction::Input(_)) {
                continue;
            }
            let (base, slot) = self.outputs.slot(j);
            let value = self.value(x);
            self.b
                .ins()
                .store(MemFlagsData::trusted(), value, base, (slot as i32) * 8);
        }
    }

    /// The buffer and byte offset of tape values `first` and `second` when they are inputs
    /// one after the other in one buffer, else `None`.
    fn adjacent_inputs(&self, first: u32, second: u32) -> Option<(ir::Value, i32)> {
        let input = |x: u32| match self.tape.instructions[x as usize] {
            Instruction::Input(input) => Some(input),
            _ => None,
        };
        let a = &self.arguments;
        let (base, offset, i, j) = match (input(first)?, input(second)?) {
            (Input::Parameter(i), Input::Parameter(j)) => (a.parameters, 0, i, j),
            (Input::Coordinate(i), Input::Coordinate(j)) => (a.q, 0, i, j),
            (Input::Velocity(i), Input::Velocity(j)) => (a.qdot, a.qdot_offset, i, j),
            (Input::Acceleration(i), Input::Acceleration(j)) => (a.acceleration, 0, i, j),
            (Input::Multiplier(i), Input::Multiplier(j)) => (a.lambda, 0, i, j),
            _ => return None,
        };
        (j == i + 1).then_some((base, offset + (i as i32) * 8))
    }

    /// Stores the outputs of a small function two at a time (slots 2k and 2k + 1 of a buffer
    /// as one 16-byte store): the caller reads them back at once, often 16 bytes at a time
    /// (nalgebra's copies, the solve of `M q̈ = F`), and a 16-byte load of two 8-byte stores
    /// cannot be forwarded from the store buffer — it waits ~12 cycles for the stores to
    /// retire, while a load within one wider store is forwarded. On the double pendulum's
    /// right-hand side this was worth ~4 ns (`benches/runtime_model.rs`).
    fn store_output_pairs(&mut self, filled: &[bool]) {
        let tape = self.tape;
        let split = self.outputs.split;
        for (base, outputs, filled) in [
            (self.outputs.out0, &tape.outputs[..split], &filled[..split]),
            (self.outputs.out1, &tape.outputs[split..], &filled[split..]),
        ] {
            for (pair, (chunk, filled)) in outputs.chunks(2).zip(filled.chunks(2)).enumerate() {
                let offset = (pair as i32) * 16;
                // A pair half in a run of zeros: the other half alone.
                match filled {
                    [true] | [true, true] => continue,
                    [false, true] | [true, false] => {
                        let half = usize::from(filled[0]);
                        let value = self.value(chunk[half]);
                        let at = offset + 8 * half as i32;
                        self.b.ins().store(MemFlagsData::trusted(), value, base, at);
                        continue;
                    }
                    _ => {}
                }
                if let [first, second] = *chunk
                    && let Some((input, at)) = self.adjacent_inputs(first, second)
                {
                    // Two inputs side by side (a first-order function's `q̇`, the first half
                    // of its `ẏ`): one 16-byte load rather than two loads and the two
                    // instructions that pair them. Not `aligned`: `q̇` starts 8 bytes into a
                    // buffer for odd `n`.
                    let vector = self.b.ins().load(
                        types::F64X2,
                        MemFlagsData::new().with_notrap(),
                        input,
                        at,
                    );
                    self.b
                        .ins()
                        .store(MemFlagsData::trusted(), vector, base, offset);
                    continue;
                }
                let first = self.value(chunk[0]);
                match chunk.get(1) {
                    Some(&second) => {
                        let second = self.value(second);
                        let vector = self.b.ins().splat(types::F64X2, first);
                        let vector = self.b.ins().insertlane(vector, second, 1);
                        self.b
                            .ins()
                            .store(MemFlagsData::trusted(), vector, base, offset);
                    }
                    None => {
                        self.b
                            .ins()
                            .store(MemFlagsData::trusted(), first, base, offset);
                    }
                }
            }
        }
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
            let Err(error) = compile(
                &[("kinetic_energy", &good), ("potential_energy", bad)],
                None,
            ) else {
                panic!("a malformed tape does not compile");
            };
            let CompileError::Function { function, reason } = &error else {
                panic!("{error}");
            };
            assert_eq!(function, "potential_energy");
            assert!(reason.contains(what), "{reason}");
            assert!(error.to_string().contains("`potential_energy`"), "{error}");
        }
        let code = compile(&[("kinetic_energy", &good)], None).expect("a good tape compiles");
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

    /// A fused right-hand side of `n = 1` is compiled only with its shape, `ẏ` (2 values)
    /// then one pivot, and its verdict tests the pivot and `q̈`; with a pivot missing it is not
    /// compiled (no panic), and the model's other functions still are.
    #[test]
    fn a_fused_right_hand_side_needs_its_pivots_and_judges_them() {
        // ẏ = [q̇, q / m], pivot m (parameter 0).
        let instructions = vec![
            Instruction::Input(Input::Velocity(0)),
            Instruction::Input(Input::Coordinate(0)),
            Instruction::Input(Input::Parameter(0)),
            Instruction::Div(1, 2),
        ];
        let fused = |outputs: Vec<u32>| FunctionTape {
            tape: Tape {
                instructions: instructions.clone(),
                outputs,
            },
            split: 2,
        };
        let good = tape(vec![Instruction::Input(Input::Coordinate(0))], vec![0]);
        let whole = fused(vec![0, 3, 2]);
        let code = compile(&[("kinetic_energy", &good)], Some((&whole, 1))).expect("compiles");
        let f = code.first_order.expect("the fused function is compiled");
        let verdict = |m: f64, q: f64| {
            let (y, mut dy) = ([q, 2.0], [0.0; 2]);
            // SAFETY: the tape reads one parameter and 2 values of `y`, and writes 2 to `dy`.
            let verdict = unsafe { f([m].as_ptr(), y.as_ptr(), 0.0, dy.as_mut_ptr()) };
            (verdict, dy)
        };
        assert_eq!(verdict(4.0, 3.0), (1, [2.0, 0.75]));
        for (m, q) in [
            (0.0, 3.0),
            (-1.0, 3.0),
            (f64::NAN, 3.0),
            (4.0, f64::INFINITY),
        ] {
            assert_eq!(verdict(m, q).0, 0, "m = {m}, q = {q}");
        }
        let short = fused(vec![0, 3]);
        let code = compile(&[("kinetic_energy", &good)], Some((&short, 1))).expect("compiles");
        assert!(code.first_order.is_none());
        assert!(code.functions[0].is_some());
    }
}
