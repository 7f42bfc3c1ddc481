//! A run-time model's Taylor orders compiled to native code by Cranelift: the counterpart of
//! the `TaylorFunctions::orders` that `eomgen::model!` generates for a compiled model.
//!
//! # What is compiled
//! One function per order `k = 0 … H`, each with the signature [`OrderFn`] (the platform's
//! C calling convention):
//!
//! ```text
//! fn(series: *mut f64, scratch: *mut PairLanes, out: *mut f64, frame: *const OrderFrame) -> u8
//! ```
//!
//! with the step's solve in [`OrderFrame`] (`context`, `solve`, `lower`, `inverse_pivots`,
//! `factor`): four arguments, all in registers.
//!
//! Order `k`'s function computes order `k` of every op of the program (none at `k = 0`), then
//! order `k` of `M a = F` (the accelerations' order `k` into the series, the state's order
//! `k + 1` into `out`, `2n` values per order, and into the inputs' slots): in line with the
//! factor `factor` names ([`Factor`]: `L` and `D⁻¹` of a dense factor, of a small one with
//! zeros below its diagonal, or `D⁻¹` of a diagonal one: the operations of `motion_order`'s
//! solves), else by calling `solve(context, k)`
//! ([`eomgen_runtime::taylor::motion_order_at`]). It returns 0, or what `solve` returned
//! if that was not 0. The caller runs orders `0, 1, …` in turn. `H` is
//! [`TaylorProgram::highest_unrolled_order`], the orders whose code fits the instruction
//! cache, as for a compiled model; the series has the stride [`UNROLLED_CAPACITY`] (slot
//! `x`'s order `i` at `x · 25 + i`).
//!
//! Each op's order `k` is its kernel of `eomgen_runtime::taylor` (`mul`, `sin_cos`, …) with `k`
//! and every offset constants: the same operations in the same order, and Cranelift neither
//! reassociates nor contracts into fused multiply–adds, so the results are the kernels' to
//! the bit (`tests/taylor_coefficients.rs` compares them with the `model!`-compiled models'
//! and with the kernels on models using every op kind). The sine–cosine pairs sum as the
//! kernels do, two lanes of one vector, with their operands side by side in a scratch
//! ([`PairScratch`]).
//!
//! Each kernel's sums add their terms from the orders below `k` first (`Σ_{j=1}^{k−1}
//! a[j] b[k−j]`, then the terms with order `k`). Those first terms need nothing the order
//! computes, so order `k`'s function adds them for every sum before the ops, a few sums'
//! chains of additions interleaved (`Emitter::prefixes`), and each op continues its sum from
//! there: the same additions in the same order, so the same bits, but the long chains of
//! dependent additions overlap instead of each waiting for the ops before it. With the
//! orders laid out one after the other (`new_module`) and four arguments, whole runs of the
//! double pendulum and the heavy top went from 1.11–1.22× the time of `model!`'s to
//! 1.07–1.13× (docs/performance.md).
//!
//! Why one function per order: in one function for all orders every coefficient stayed in
//! a register (a Cranelift value) from the order that computed it to the last that read it,
//! and the register allocator spilled most of them (5,059 16-byte reloads in the double
//! pendulum's code) and took most of the compile. Per order, a coefficient of an earlier
//! order is loaded from the series where it is first used in that order (what the order
//! writes, it never reads back from memory: see [`settled`]). The double pendulum's 18
//! orders then compiled in 20–30 ms instead of 30–40 (14–16 ms since the partial sums below),
//! and ran in 1.15–1.2× the time of `model!`'s instead of 1.3–1.5× (docs/performance.md,
//! "Build and test cost"). Without Cranelift's
//! e-graph pass (`opt_level` `none`: the code repeats no work for it to remove) they compile
//! in three quarters of the time and run 2–5 % slower.
//!
//! With it, in the same module, order 0 ([`OrderZeroFn`], `fn(series: *mut f64, parameters:
//! *const f64)`): the extended tape of `M` and `F` (`TaylorPlan::order_zero`), instruction
//! `k`'s value into `series[k · 25]`, each with the operation or helper of [`crate::math`]
//! that the interpreter's `order_zero_in_place` uses (the same bits); the inputs `q`, `q̇`,
//! `t` are read from their slots, where the caller has written them.
//!
//! # Pairs
//! Two ops of the same kind that do not depend on each other run as the two lanes of one
//! 2-wide vector ([`pairing`]: a body's `x` and `y` components, found as an SLP vectoriser
//! finds them). Each lane runs its op's kernel, the same operations in the same order, so the
//! bits are the scalar code's; each lane is also stored to its own slot, for the ops, the
//! solve and the kernels of the orders above `H` that read it alone. The paired operands'
//! orders sit side by side in the scratch after the sine–cosine pairs' (the lane slots),
//! one 16-byte load a term. On the figure eight (36 of its 40 ops paired) whole runs took
//! 0.86–0.89× the time at tolerances 1e-6 to 1e-12 and 0.95× at 1e-3; over twelve models,
//! 0.78–0.98× at 1e-9 and 1e-12 and up to 1.09× at 1e-3, where a step computes orders 0–4
//! (docs/performance.md, "The panel"). With the environment variable
//! `EOMGEN_JIT_UNPAIRED` set, every op runs alone (the same bits), to measure what the pairs
//! buy.
//!
//! With the environment variable `EOMGEN_JIT_DISASM` set, each order's machine code is
//! printed to standard error as it is compiled, as [`crate::native`] prints the model's.
//!
//! # Memory
//! As for [`crate::native`]: the module owning the code lives in [`NativeOrders`] and is freed
//! with it.

use cranelift_codegen::ir;
use cranelift_codegen::ir::condcodes::{FloatCC, IntCC};
use cranelift_codegen::ir::{AbiParam, InstBuilder, MemFlagsData, Signature, UserFuncName, types};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_module::{Linkage, Module};
use std::collections::HashMap;

use cranelift_jit::JITModule;
use eomgen_runtime::taylor::{SeriesOp, Slot, TaylorProgram, UNROLLED_CAPACITY};
use eomgen_symbolic::codegen::tape::{Input, Instruction, Tape};
use eomgen_symbolic::codegen::taylor::TaylorPlan;
use eomgen_symbolic::expr::Func;

use crate::native::{
    CodeLayout, CompileError, Imports, ModuleMemory, declare_imports, enter, failure, new_module,
};

mod kernels;
mod pairing;
mod prefixes;

use pairing::{LaneSlot, Pairing, Unit};

/// One compiled order `k`: see the module documentation for the arguments.
///
/// # Safety
/// `series` holds at least `(program.slots + n) · UNROLLED_CAPACITY` values with the orders
/// below `k` computed; `out` at least `(k + 2) · 2n`; `scratch` holds
/// [`NativeOrders::scratch_units`] units (16-byte aligned) with the orders below `k` written
/// by the orders' functions; `frame` is valid as [`OrderFrame`] says, and nothing writes it
/// during the call.
pub(crate) type OrderFn =
    unsafe extern "C" fn(*mut f64, *mut PairLanes, *mut f64, *const OrderFrame) -> u8;

/// How an order solves `M a = F` in a step (the orders' fourth argument, [`OrderFn`]).
#[derive(Debug)]
#[repr(C)]
pub(crate) struct OrderFrame {
    /// What `solve` is called with: null when `factor` names a factor solved in line, whose
    /// code never calls it.
    pub(crate) context: *mut u8,
    /// Order `k`'s solve when the code does not solve in line: 0, or a failure's status.
    pub(crate) solve: extern "C" fn(*mut u8, usize) -> u8,
    /// With `factor` [`FACTOR_DENSE`] or [`FACTOR_SMALL`], the `n · n` values of `L`
    /// (row-major), else unused.
    pub(crate) lower: *const f64,
    /// With `factor` [`FACTOR_DENSE`], [`FACTOR_SMALL`] or [`FACTOR_DIAGONAL`], the `n`
    /// values of `D⁻¹`, else unused.
    pub(crate) inverse_pivots: *const f64,
    /// Which solve ([`Factor`]'s codes; any other value: call `solve`).
    pub(crate) factor: i64,
}

impl OrderFrame {
    /// The byte offsets of the fields, as the code reads them.
    const CONTEXT: i32 = std::mem::offset_of!(OrderFrame, context) as i32;
    const SOLVE: i32 = std::mem::offset_of!(OrderFrame, solve) as i32;
    const LOWER: i32 = std::mem::offset_of!(OrderFrame, lower) as i32;
    const INVERSE_PIVOTS: i32 = std::mem::offset_of!(OrderFrame, inverse_pivots) as i32;
    const FACTOR: i32 = std::mem::offset_of!(OrderFrame, factor) as i32;
}

/// Two `f64`s aligned for one 16-byte load: the unit of [`PairScratch`], in the workspace
/// of the step ([`eomgen_runtime::taylor::MotionSolve::lanes`]).
pub(crate) use eomgen_runtime::taylor::Lanes as PairLanes;

/// The layout of the orders' scratch: for the `p`-th sine–cosine or sinh–cosh op of the
/// program, [`UNROLLED_CAPACITY`] units `(y[i], z[i])` (its cosine and sine, or cosh and
/// sinh, order `i` side by side) then as many `(i x[i], i x[i])` (its argument's order `i`
/// weighted by `i`, in both lanes): what the kernels' `weighted_convolution_pair` reads as
/// vectors, each one 16-byte load here instead of two loads and two shuffles. Order `k`'s
/// function writes order `k` of each, order 0's function the pairs' order 0. After them,
/// [`UNROLLED_CAPACITY`] units for each lane slot of the paired ops ([`pairing`],
/// [`Layout::lane_offset`]).
pub(crate) struct PairScratch;

impl PairScratch {
    /// The units a program with `pairs` pair ops needs.
    pub(crate) fn units(pairs: usize) -> usize {
        pairs * 2 * UNROLLED_CAPACITY
    }

    /// The byte offset of pair `p`'s `(y[i], z[i])`.
    fn pair(p: usize, i: usize) -> i32 {
        ((p * 2 * UNROLLED_CAPACITY + i) * 16) as i32
    }

    /// The byte offset of pair `p`'s `(i x[i], i x[i])`.
    fn weighted(p: usize, i: usize) -> i32 {
        ((p * 2 * UNROLLED_CAPACITY + UNROLLED_CAPACITY + i) * 16) as i32
    }
}

/// The compiled order 0 (see the module documentation).
///
/// # Safety
/// `series` holds at least `order_zero.instructions.len() · UNROLLED_CAPACITY` values, with
/// the inputs' order 0 written; `parameters` holds the model's parameters (one per
/// `Input::Parameter` index of the tape).
pub(crate) type OrderZeroFn = unsafe extern "C" fn(*mut f64, *const f64);

/// A model's compiled Taylor orders and the memory that holds them.
pub(crate) struct NativeOrders {
    /// Order `k`'s function at index `k`, for `k = 0 … highest`.
    pub(crate) orders: Vec<OrderFn>,
    /// Order 0.
    pub(crate) order_zero: OrderZeroFn,
    /// The highest order it computes, `H`.
    pub(crate) highest: usize,
    /// The units of scratch the orders use: the sine–cosine pairs' and the lane slots'
    /// ([`PairScratch`]).
    pub(crate) scratch_units: usize,
    _memory: ModuleMemory,
}

impl std::fmt::Debug for NativeOrders {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NativeOrders")
            .field("highest", &self.highest)
            .finish()
    }
}

/// Compiles the orders `1 …` [`TaylorProgram::highest_unrolled_order`] of `plan`'s program and
/// its order 0 (see the module documentation), for a model of `parameters` parameters; `None`
/// when no order fits the cache.
///
/// # Errors
/// [`CompileError`] if Cranelift has no code generator for the host or fails on the code.
pub(crate) fn compile_orders(
    plan: &TaylorPlan,
    parameters: usize,
) -> Result<Option<NativeOrders>, CompileError> {
    const ORDER_ZERO: &str = "taylor_order_zero";
    let program = &plan.program;
    let highest = program.highest_unrolled_order().min(UNROLLED_CAPACITY - 1);
    if highest == 0 {
        return Ok(None);
    }
    // The order-0 code indexes the series by the tape's operands unchecked: each must be an
    // earlier instruction.
    plan.order_zero
        .validate()
        .map_err(|reason| failure(ORDER_ZERO, &reason))?;
    // Its slots' byte offsets are 32-bit immediates.
    if plan.order_zero.instructions.len() > i32::MAX as usize / (UNROLLED_CAPACITY * 8) {
        return Err(failure(
            ORDER_ZERO,
            &"the tape has too many instructions for 32-bit offsets",
        ));
    }
    // Order k's code adds about k terms per sum (up to five sums an op, and 3n² in its
    // solve, n the unknowns): 8 (ops + n²) (H + 1)² items, 1 KiB each, is ample.
    let n = program.forcing.len();
    let items = (program.ops.len() + n * n)
        .saturating_mul(8 * (highest + 1) * (highest + 1))
        .saturating_add(plan.order_zero.instructions.len());
    let mut module = new_module(CodeLayout::Contiguous(items))?;
    let imports = declare_imports(&mut module)?;
    let call_conv = module.isa().default_call_conv();
    let pointer = module.target_config().pointer_type();
    let mut context = module.make_context();
    let mut builder_context = FunctionBuilderContext::new();
    let layout = Layout::new(program, &plan.order_zero);
    let ids = define_orders(
        &mut module,
        (&mut context, &mut builder_context),
        (program, &layout),
        highest,
    )?;
    let mut zero_signature = Signature::new(call_conv);
    zero_signature.params.push(AbiParam::new(pointer));
    zero_signature.params.push(AbiParam::new(pointer));
    let zero_id = module
        .declare_function(ORDER_ZERO, Linkage::Local, &zero_signature)
        .map_err(|e| failure(ORDER_ZERO, &e))?;
    context.func.signature = zero_signature;
    context.func.name = UserFuncName::user(0, 0);
    build_order_zero(
        &mut module,
        &mut context.func,
        &mut builder_context,
        &plan.order_zero,
        parameters,
        &imports,
    );
    module
        .define_function(zero_id, &mut context)
        .map_err(|e| failure(ORDER_ZERO, &e))?;
    module.clear_context(&mut context);
    module
        .finalize_definitions()
        .map_err(|e| CompileError::Finalize {
            reason: e.to_string(),
        })?;
    let orders = ids
        .into_iter()
        .map(|id| {
            let address = module.get_finalized_function(id);
            // SAFETY: `address` is the entry of a function compiled above with exactly the
            // signature of `OrderFn` in the platform's default (C) calling convention.
            unsafe { std::mem::transmute::<*const u8, OrderFn>(address) }
        })
        .collect();
    let address = module.get_finalized_function(zero_id);
    // SAFETY: as above, with the signature of `OrderZeroFn`.
    let order_zero = unsafe { std::mem::transmute::<*const u8, OrderZeroFn>(address) };
    Ok(Some(NativeOrders {
        orders,
        order_zero,
        highest,
        scratch_units: layout.scratch_units(),
        _memory: ModuleMemory::new(module),
    }))
}

/// Defines the functions of orders `0 …= highest` of `program` in `module` ([`OrderFn`],
/// see the module documentation), printing each one's machine code with `EOMGEN_JIT_DISASM`
/// set; returns their ids, order by order.
///
/// # Errors
/// [`CompileError::Function`] naming the order Cranelift failed on.
fn define_orders(
    module: &mut JITModule,
    (context, builder_context): (&mut cranelift_codegen::Context, &mut FunctionBuilderContext),
    (program, layout): (&TaylorProgram, &Layout),
    highest: usize,
) -> Result<Vec<cranelift_module::FuncId>, CompileError> {
    const NAME: &str = "taylor_orders";
    let call_conv = module.isa().default_call_conv();
    let pointer = module.target_config().pointer_type();
    let mut solve_signature = Signature::new(call_conv);
    solve_signature.params.push(AbiParam::new(pointer));
    solve_signature.params.push(AbiParam::new(pointer));
    solve_signature.returns.push(AbiParam::new(types::I8));
    let mut signature = Signature::new(call_conv);
    for _ in 0..4 {
        signature.params.push(AbiParam::new(pointer));
    }
    signature.returns.push(AbiParam::new(types::I8));
    let disassemble = std::env::var_os("EOMGEN_JIT_DISASM").is_some();
    let mut ids = Vec::with_capacity(highest + 1);
    for k in 0..=highest {
        let name = format!("{NAME}_{k}");
        let id = module
            .declare_function(&name, Linkage::Local, &signature)
            .map_err(|e| failure(&name, &e))?;
        context.func.signature = signature.clone();
        context.func.name = UserFuncName::user(0, k as u32 + 1);
        build_order(
            &mut context.func,
            builder_context,
            (program, layout),
            k,
            solve_signature.clone(),
            module.target_config(),
        );
        context.set_disasm(disassemble);
        module
            .define_function(id, context)
            .map_err(|e| failure(&name, &e))?;
        if let Some(vcode) = context.compiled_code().and_then(|c| c.vcode.as_ref())
            && disassemble
        {
            eprintln!("== {name}\n{vcode}");
        }
        module.clear_context(context);
        ids.push(id);
    }
    Ok(ids)
}

/// The arguments of an order's function ([`OrderFn`]), and the factor's code read from its
/// frame.
#[derive(Clone, Copy)]
struct OrderArgs {
    series: ir::Value,
    scratch: ir::Value,
    out: ir::Value,
    frame: ir::Value,
    mode: ir::Value,
}

impl OrderArgs {
    fn new(b: &mut FunctionBuilder, params: &[ir::Value]) -> Self {
        let frame = params[3];
        let mode = b
            .ins()
            .load(types::I64, settled(), frame, OrderFrame::FACTOR);
        OrderArgs {
            series: params[0],
            scratch: params[1],
            out: params[2],
            frame,
            mode,
        }
    }

    /// The pointer at byte `offset` of the frame.
    fn pointer(&self, b: &mut FunctionBuilder, offset: i32) -> ir::Value {
        let pointer = b.func.dfg.value_type(self.frame);
        b.ins().load(pointer, settled(), self.frame, offset)
    }
}

/// Writes order `k`'s function (see the module documentation): its ops, then its solve.
fn build_order(
    func: &mut ir::Function,
    builder_context: &mut FunctionBuilderContext,
    (program, layout): (&TaylorProgram, &Layout),
    k: usize,
    solve_signature: Signature,
    target: cranelift_codegen::isa::TargetFrontendConfig,
) {
    let mut b = FunctionBuilder::new(func, builder_context);
    let params = enter(&mut b);
    let args = OrderArgs::new(&mut b, &params);
    let solve_signature = b.import_signature(solve_signature);
    let done = b.create_block();
    let status = b.append_block_param(done, types::I8);
    let mut emitter = Emitter::new(args, layout);
    emit_order(
        &mut b,
        &mut emitter,
        program,
        k,
        (args, solve_signature, done),
    );
    let ok = b.ins().iconst(types::I8, 0);
    b.ins().jump(done, &[ir::BlockArg::Value(ok)]);
    b.switch_to_block(done);
    b.seal_block(done);
    b.ins().return_(&[status]);
    b.finalize(target);
}

/// Writes order `k`: its ops, then its solve, continuing in a new block (the current one on
/// return); a failed call of `solve` jumps to `done` with its status.
fn emit_order(
    b: &mut FunctionBuilder,
    emitter: &mut Emitter,
    program: &TaylorProgram,
    k: usize,
    (args, solve_signature, done): (OrderArgs, ir::SigRef, ir::Block),
) {
    let n = program.coordinates.len();
    emitter.begin_order(b);
    if k > 1 {
        emitter.prefixes(b, program, k);
    }
    if k > 0 {
        let layout = emitter.layout;
        for unit in &layout.pairing.units {
            match *unit {
                Unit::Single(op) => emitter.op(b, op, k),
                Unit::Pair { op, gathered } => emitter.paired(b, op, gathered, k),
            }
        }
    } else {
        // The pairs' and the lane slots' order 0, from the series (order 0 wrote them
        // there).
        for op in program.ops.iter() {
            if let SeriesOp::SinCos { sin: z, cos: y, .. }
            | SeriesOp::SinhCosh {
                sinh: z, cosh: y, ..
            } = *op
            {
                let p = emitter.pair_of(z);
                let (y0, z0) = (emitter.at(b, y, 0), emitter.at(b, z, 0));
                emitter.store_pair(b, p, 0, (y0, z0));
            }
        }
        for v in 0..emitter.layout.pairing.lanes.len() {
            emitter.gather(b, emitter.layout.pairing.base + v as Slot, 0);
        }
    }
    // Order k of M a = F: in line with the factor `mode` names, else by `solve` (always with
    // constraints: the unknowns `[q̈; λ]` of `[M Jᵀ; J 0]` are not the in-line solves').
    let after = b.create_block();
    let mut test = b.create_block();
    b.ins().jump(test, &[]);
    let inline: &[(i64, Factor)] = if program.multipliers() == 0 {
        &[
            (FACTOR_DENSE, Factor::Dense),
            (FACTOR_SMALL, Factor::Small),
            (FACTOR_DIAGONAL, Factor::Diagonal),
        ]
    } else {
        &[]
    };
    for &(code, factor) in inline {
        b.switch_to_block(test);
        b.seal_block(test);
        let (inline, next) = (b.create_block(), b.create_block());
        let is = b.ins().icmp_imm_s(IntCC::Equal, args.mode, code);
        b.ins().brif(is, inline, &[], next, &[]);
        b.switch_to_block(inline);
        b.seal_block(inline);
        // What the branches write differs (and the values of one do not reach the others).
        let before = emitter.known.clone();
        let lower = args.pointer(b, OrderFrame::LOWER);
        let inverse_pivots = args.pointer(b, OrderFrame::INVERSE_PIVOTS);
        emitter.dense_solve(
            b,
            program,
            (n, k),
            args.out,
            factor,
            (lower, inverse_pivots),
        );
        emitter.known = before;
        b.ins().jump(after, &[]);
        test = next;
    }
    let call = test;
    b.switch_to_block(call);
    b.seal_block(call);
    let pointer = b.func.dfg.value_type(args.frame);
    let (context, solve) = (
        args.pointer(b, OrderFrame::CONTEXT),
        args.pointer(b, OrderFrame::SOLVE),
    );
    let kv = b.ins().iconst(pointer, k as i64);
    let called = b
        .ins()
        .call_indirect(solve_signature, solve, &[context, kv]);
    let status = b.inst_results(called)[0];
    b.ins()
        .brif(status, done, &[ir::BlockArg::Value(status)], after, &[]);
    b.switch_to_block(after);
    b.seal_block(after);
}

/// Writes order 0's body (see the module documentation): each instruction's value stored to
/// its slot at the stride [`UNROLLED_CAPACITY`] and kept as a Cranelift value for its uses
/// (the inputs loaded from their slots at each use); a parameter index beyond `parameters`
/// reads NaN, as the interpreter's.
// Long: one arm per tape instruction of order 0, each calling the interpreter's helper (or, for a
// constant half-integer power, computing its operations in line) for the same bits; the match is
// the instruction set.
fn build_order_zero(
    module: &mut JITModule,
    func: &mut ir::Function,
    builder_context: &mut FunctionBuilderContext,
    tape: &Tape,
    parameters: usize,
    imports: &Imports,
) {
    let target = module.target_config();
    let mut b = FunctionBuilder::new(func, builder_context);
    let params = enter(&mut b);
    let (series, parameter_values) = (params[0], params[1]);
    let offset = |k: u32| (k as usize * UNROLLED_CAPACITY * 8) as i32;
    let flags = MemFlagsData::trusted();
    let count = tape.instructions.len();
    let mut values: Vec<Option<ir::Value>> = vec![None; count];
    let mut unary: Vec<(Func, ir::FuncRef)> = Vec::new();
    let (mut sin_cos, mut powf, mut atan2) = (None, None, None);
    for (k, instruction) in tape.instructions.iter().enumerate() {
        let value = |b: &mut FunctionBuilder, x: u32| match values[x as usize] {
            Some(v) => v,
            None => b.ins().load(types::F64, flags, series, offset(x)),
        };
        let v = match *instruction {
            Instruction::Input(Input::Parameter(i)) if (i as usize) < parameters => {
                b.ins()
                    .load(types::F64, flags, parameter_values, (i as i32) * 8)
            }
            Instruction::Input(Input::Parameter(_)) => b.ins().f64const(f64::NAN),
            // Written by the caller: loaded at each use.
            Instruction::Input(_) => continue,
            Instruction::Const(x) => b.ins().f64const(x),
            Instruction::Neg(x) => {
                let x = value(&mut b, x);
                b.ins().fneg(x)
            }
            Instruction::Add(x, y) => {
                let (x, y) = (value(&mut b, x), value(&mut b, y));
                b.ins().fadd(x, y)
            }
            Instruction::Sub(x, y) => {
                let (x, y) = (value(&mut b, x), value(&mut b, y));
                b.ins().fsub(x, y)
            }
            Instruction::Mul(x, y) => {
                let (x, y) = (value(&mut b, x), value(&mut b, y));
                b.ins().fmul(x, y)
            }
            Instruction::Div(x, y) => {
                let (x, y) = (value(&mut b, x), value(&mut b, y));
                b.ins().fdiv(x, y)
            }
            Instruction::Sqrt(x) => {
                let x = value(&mut b, x);
                b.ins().sqrt(x)
            }
            Instruction::Abs(x) | Instruction::Call(Func::Abs, x) => {
                let x = value(&mut b, x);
                b.ins().fabs(x)
            }
            Instruction::Call(f, x) => {
                let x = value(&mut b, x);
                let callee = match unary.iter().find(|(g, _)| *g == f) {
                    Some(&(_, r)) => r,
                    None => {
                        // Every other function of one argument is imported; were one not,
                        // its value would be NaN, never the last series' value.
                        let Some(&(_, id)) = imports.unary.iter().find(|(g, _)| *g == f) else {
                            let nan = b.ins().f64const(f64::NAN);
                            b.ins().store(flags, nan, series, offset(k as u32));
                            values[k] = Some(nan);
                            continue;
                        };
                        let r = module.declare_func_in_func(id, b.func);
                        unary.push((f, r));
                        r
                    }
                };
                let call = b.ins().call(callee, &[x]);
                b.inst_results(call)[0]
            }
            Instruction::Powf(x, y)
                if let Some(half) = crate::math::constant_half_power(tape, y) =>
            {
                let x = value(&mut b, x);
                crate::math::half_power(&mut b, x, half)
            }
            Instruction::Powf(x, y) => {
                let (x, y) = (value(&mut b, x), value(&mut b, y));
                let callee =
                    *powf.get_or_insert_with(|| module.declare_func_in_func(imports.powf, b.func));
                let call = b.ins().call(callee, &[x, y]);
                b.inst_results(call)[0]
            }
            Instruction::Atan2(y, x) => {
                let (y, x) = (value(&mut b, y), value(&mut b, x));
                let callee = *atan2
                    .get_or_insert_with(|| module.declare_func_in_func(imports.atan2, b.func));
                let call = b.ins().call(callee, &[y, x]);
                b.inst_results(call)[0]
            }
            Instruction::SinCos(x) => {
                let x = value(&mut b, x);
                let callee = *sin_cos
                    .get_or_insert_with(|| module.declare_func_in_func(imports.sin_cos, b.func));
                let call = b.ins().call(callee, &[x]);
                let (s, c) = (b.inst_results(call)[0], b.inst_results(call)[1]);
                if k + 1 < count {
                    b.ins().store(flags, c, series, offset(k as u32 + 1));
                    values[k + 1] = Some(c);
                }
                s
            }
            // Stored with its `SinCos`.
            Instruction::CosOfSinCos(_) => continue,
        };
        b.ins().store(flags, v, series, offset(k as u32));
        values[k] = Some(v);
    }
    b.ins().return_(&[]);
    b.finalize(target);
}

/// The flags of a load of a value that order `k`'s function reads and does not write: a
/// series' coefficient of an order below `k` (or an input's or time's order `k`, which order
/// `k − 1` wrote), order `k` of the state's series in `out`, and the pair scratch's orders
/// below `k`. Such a load is pure to Cranelift (with its e-graph pass, it may be merged with
/// another of the same address or moved next to its use); the memory is always there (the
/// series, `out`, the scratch: never behind a null pointer), so moving the load across the
/// function's branches is sound. What order `k` writes it never loads: its values are
/// Cranelift values from where they are computed.
fn settled() -> MemFlagsData {
    MemFlagsData::trusted().with_readonly().with_can_move()
}

/// How order `k`'s function solves `M a = F` (its last argument): with a dense factor
/// ([`FACTOR_DENSE`]: `L`, row-major `n × n`, and `D⁻¹`), with the factor of a small `M`
/// that has zeros below its diagonal ([`FACTOR_SMALL`]: the same arrays, each zero entry's
/// update skipped as the runtime's solve over the non-zero entries skips it), with a diagonal
/// one ([`FACTOR_DIAGONAL`]: `D⁻¹` alone), or by calling `solve` (any other value).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Factor {
    Dense,
    Small,
    Diagonal,
}

/// [`Factor::Dense`]'s code.
pub(crate) const FACTOR_DENSE: i64 = 1;
/// [`Factor::Small`]'s code.
pub(crate) const FACTOR_SMALL: i64 = 2;
/// [`Factor::Diagonal`]'s code.
pub(crate) const FACTOR_DIAGONAL: i64 = 3;

/// Where a program's orders keep what they share: the sine–cosine pairs' operands
/// ([`PairScratch`]) and, after them, the lane slots' orders ([`pairing`]).
struct Layout {
    /// The ops as they run, alone or paired.
    pairing: Pairing,
    /// The index among the pair ops of each sine–cosine or sinh–cosh op, by its `sin` slot.
    pair_ops: HashMap<Slot, usize>,
    /// The value of each slot that order 0 sets to a constant of the tape (not a parameter
    /// nor an input): the exponents of most powers, whose weights are then constants of the
    /// code (`Emitter::power_term`).
    constants: HashMap<Slot, f64>,
}

impl Layout {
    fn new(program: &TaylorProgram, order_zero: &Tape) -> Self {
        let constants = order_zero
            .instructions
            .iter()
            .enumerate()
            .filter_map(|(slot, instruction)| match *instruction {
                Instruction::Const(x) => Some((slot as Slot, x)),
                _ => None,
            })
            .collect();
        let pair_ops = program
            .ops
            .iter()
            .filter_map(|op| match *op {
                SeriesOp::SinCos { sin, .. } | SeriesOp::SinhCosh { sinh: sin, .. } => Some(sin),
                _ => None,
            })
            .enumerate()
            .map(|(p, sin)| (sin, p))
            .collect();
        let base = (program.slots + program.forcing.len()) as Slot;
        let pairing = if std::env::var_os("EOMGEN_JIT_UNPAIRED").is_some() {
            Pairing::none(program)
        } else {
            Pairing::new(program, base)
        };
        Layout {
            pairing,
            pair_ops,
            constants,
        }
    }

    /// The units of scratch the orders use.
    fn scratch_units(&self) -> usize {
        PairScratch::units(self.pair_ops.len()) + self.pairing.lanes.len() * UNROLLED_CAPACITY
    }

    /// The byte offset in the scratch of order `i` of the lane slot `slot`.
    fn lane_offset(&self, slot: Slot, i: usize) -> i32 {
        let v = (slot - self.pairing.base) as usize;
        ((PairScratch::units(self.pair_ops.len()) + v * UNROLLED_CAPACITY + i) * 16) as i32
    }
}

/// Writes the kernels' arithmetic, with the coefficients known in registers.
struct Emitter<'a> {
    series: ir::Value,
    /// The scratch of the pair ops ([`PairScratch`]) and the lane slots.
    scratch: ir::Value,
    layout: &'a Layout,
    /// 2 while a paired op is written (its values are 2-wide vectors), else 1.
    width: usize,
    /// `(slot, order) → value` loaded or stored in this order's function.
    known: HashMap<(Slot, usize), ir::Value>,
    /// The sums whose terms from orders below `k` were added before the ops
    /// ([`Emitter::prefixes`]), each in a stack slot.
    prefixes: HashMap<Sum, ir::StackSlot>,
    /// The bases of [`Emitter::prefixes`]' loads: of the series, of the pair scratch.
    prefix_base: ir::Value,
    prefix_scratch: ir::Value,
}

/// What [`Emitter::prefixes`]' bases add to the series' and the scratch's addresses (16: the
/// scratch's vector loads stay aligned).
const PREFIX_BIAS: i32 = 16;

/// How many of [`Emitter::prefixes`]' sums are added term by term in turn: independent
/// chains of additions that overlap in the processor. The double pendulum's orders ran 3 %
/// faster with 4 than with 1 (one sum after the other), and no faster with 6, 8, 16 or all.
const INTERLEAVED_SUMS: usize = 8;

/// A sum of an order's kernels, named for [`Emitter::prefixes`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Sum {
    /// [`Emitter::sum_of_products`] over `(x, y)` from `j = 1`, weighted or not.
    Products { x: Slot, y: Slot, weighted: bool },
    /// [`Emitter::square`]'s half sum over `x`: `j = 1 … ⌊(k − 1)/2⌋`.
    Square { x: Slot },
    /// [`Emitter::weighted_pair`] of pair `p`.
    Pair(usize),
    /// The sum of the power `out = a^exponent` with a constant exponent.
    Power { out: Slot, a: Slot, exponent: Slot },
    /// The sum of the varying mass entry at this index.
    Mass(usize),
}

impl<'a> Emitter<'a> {
    fn new(args: OrderArgs, layout: &'a Layout) -> Self {
        Emitter {
            series: args.series,
            scratch: args.scratch,
            layout,
            width: 1,
            known: HashMap::default(),
            prefixes: HashMap::default(),
            prefix_base: args.series,
            prefix_scratch: args.scratch,
        }
    }
}
