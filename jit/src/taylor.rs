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
//! orders compile in 20–30 ms instead of 30–40, and run in 1.15–1.2× the time of `model!`'s
//! instead of 1.3–1.5× (docs/performance.md, "Build and test cost"). Without Cranelift's
//! e-graph pass (`opt_level` `none`: the code repeats no work for it to remove) they compile
//! in three quarters of the time and run 2–5 % slower.
//!
//! With it, in the same module, order 0 ([`OrderZeroFn`], `fn(series: *mut f64, parameters:
//! *const f64)`): the extended tape of `M` and `F` (`TaylorPlan::order_zero`), instruction
//! `k`'s value into `series[k · 25]`, each with the operation or helper of [`crate::math`]
//! that the interpreter's `order_zero_in_place` uses (the same bits); the inputs `q`, `q̇`,
//! `t` are read from their slots, where the caller has written them.
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
    CompileError, Imports, ModuleMemory, declare_imports, enter, failure, new_module,
};

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
    /// What `solve` is called with.
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
    const CONTEXT: i32 = 0;
    const SOLVE: i32 = 8;
    const LOWER: i32 = 16;
    const INVERSE_PIVOTS: i32 = 24;
    const FACTOR: i32 = 32;
}

/// Two `f64`s aligned for one 16-byte load: the unit of [`PairScratch`].
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(16))]
pub(crate) struct PairLanes(pub(crate) [f64; 2]);

/// The layout of the orders' scratch: for the `p`-th sine–cosine or sinh–cosh op of the
/// program, [`UNROLLED_CAPACITY`] units `(y[i], z[i])` (its cosine and sine, or cosh and
/// sinh, order `i` side by side) then as many `(i x[i], i x[i])` (its argument's order `i`
/// weighted by `i`, in both lanes): what the kernels' `weighted_convolution_pair` reads as
/// vectors, each one 16-byte load here instead of two loads and two shuffles. Order `k`'s
/// function writes order `k` of each, order 0's function the pairs' order 0.
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
    /// The units of scratch the orders use ([`PairScratch::units`]).
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
    const NAME: &str = "taylor_orders";
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
    // Order k's code adds about k terms per op: the ops times (H + 1)² bound the terms.
    let terms = program
        .ops
        .len()
        .saturating_mul((highest + 1) * (highest + 1));
    let mut module = new_module(terms.saturating_add(plan.order_zero.instructions.len()))?;
    let imports = declare_imports(&mut module)?;
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
    let mut context = module.make_context();
    let mut builder_context = FunctionBuilderContext::new();
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
            &mut builder_context,
            program,
            k,
            solve_signature.clone(),
            module.target_config(),
        );
        let disassemble = std::env::var_os("EOMGEN_JIT_DISASM").is_some();
        context.set_disasm(disassemble);
        module
            .define_function(id, &mut context)
            .map_err(|e| failure(&name, &e))?;
        if let Some(vcode) = context.compiled_code().and_then(|c| c.vcode.as_ref())
            && disassemble
        {
            eprintln!("== {name}\n{vcode}");
        }
        module.clear_context(&mut context);
        ids.push(id);
    }
    let pairs = program
        .ops
        .iter()
        .filter(|op| matches!(op, SeriesOp::SinCos { .. } | SeriesOp::SinhCosh { .. }))
        .count();
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
        scratch_units: PairScratch::units(pairs),
        _memory: ModuleMemory::new(module),
    }))
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
    program: &TaylorProgram,
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
    let mut emitter = Emitter::new(args);
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
        for op in program.ops.iter() {
            emitter.op(b, *op, k);
        }
    } else {
        // The pairs' order 0, from the series (order 0 wrote them there).
        for op in program.ops.iter() {
            if let SeriesOp::SinCos { sin: z, cos: y, .. }
            | SeriesOp::SinhCosh {
                sinh: z, cosh: y, ..
            } = *op
            {
                let p = emitter.next_pair();
                let (y0, z0) = (emitter.at(b, y, 0), emitter.at(b, z, 0));
                emitter.store_pair(b, p, 0, (y0, z0));
            }
        }
    }
    // Order k of M a = F: in line with the factor `mode` names, else by `solve`.
    let after = b.create_block();
    let mut test = b.create_block();
    b.ins().jump(test, &[]);
    for (code, factor) in [
        (FACTOR_DENSE, Factor::Dense),
        (FACTOR_SMALL, Factor::Small),
        (FACTOR_DIAGONAL, Factor::Diagonal),
    ] {
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

/// Writes the kernels' arithmetic, with the coefficients known in registers.
struct Emitter {
    series: ir::Value,
    /// The scratch of the pair ops ([`PairScratch`]).
    scratch: ir::Value,
    /// Pair ops met so far in this order.
    pairs: usize,
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
    /// [`Emitter::weighted_pair`] of pair `p`.
    Pair(usize),
    /// The sum of the power `out = a^exponent` with a constant exponent.
    Power { out: Slot, a: Slot, exponent: Slot },
    /// The sum of the varying mass entry at this index.
    Mass(usize),
}

impl Emitter {
    fn new(args: OrderArgs) -> Self {
        Emitter {
            series: args.series,
            scratch: args.scratch,
            pairs: 0,
            known: HashMap::default(),
            prefixes: HashMap::default(),
            prefix_base: args.series,
            prefix_scratch: args.scratch,
        }
    }

    /// Starts an order: nothing known, no pair met, and the bases of [`Self::prefixes`]'
    /// loads: the series' and the scratch's addresses plus a constant, so that Cranelift,
    /// for which both loads are pure, does not merge a load of a partial sum's terms with the
    /// ops' load of the same coefficient (one value used in both places would keep a register
    /// from the top of the function to the op).
    fn begin_order(&mut self, b: &mut FunctionBuilder) {
        self.known.clear();
        self.prefixes.clear();
        self.pairs = 0;
        self.prefix_base = b.ins().iadd_imm_s(self.series, PREFIX_BIAS as i64);
        self.prefix_scratch = b.ins().iadd_imm_s(self.scratch, PREFIX_BIAS as i64);
    }

    /// Adds, before the order's ops, the terms of each of their sums that read only orders
    /// below `k` (the terms each kernel adds first), and keeps each partial sum in a stack
    /// slot where the op continues it: the same operations in the same order, but the long
    /// chains of additions start at the top of the function, where they overlap with each
    /// other instead of waiting behind the ops whose order `k` they do not need.
    fn prefixes(&mut self, b: &mut FunctionBuilder, program: &TaylorProgram, k: usize) {
        let products = |x: Slot, y: Slot, weighted: bool| Sum::Products { x, y, weighted };
        let mut pair = 0;
        let mut all: Vec<Sum> = Vec::new();
        for op in program.ops.iter() {
            let sums: Vec<Sum> = match *op {
                SeriesOp::Mul { a, b: y, .. } => vec![products(a, y, false)],
                SeriesOp::Div { out, b: y, .. } | SeriesOp::ConstantDiv { out, b: y } => {
                    vec![products(y, out, false)]
                }
                SeriesOp::Sqrt { out, .. } => vec![products(out, out, false)],
                SeriesOp::PowConstant { out, a, exponent } => {
                    vec![Sum::Power { out, a, exponent }]
                }
                SeriesOp::Exp { out, a } => vec![products(a, out, true)],
                SeriesOp::Ln { out, a } => vec![products(out, a, true)],
                SeriesOp::SinCos { .. } | SeriesOp::SinhCosh { .. } => {
                    pair += 1;
                    vec![Sum::Pair(pair - 1)]
                }
                SeriesOp::Tan { out, a, square } | SeriesOp::Tanh { out, a, square } => {
                    vec![products(a, square, true), products(out, out, false)]
                }
                SeriesOp::Asin { out, a, root, .. } => vec![
                    products(a, a, false),
                    products(root, root, false),
                    products(out, root, true),
                ],
                SeriesOp::Atan { out, a, square } => {
                    vec![products(a, a, false), products(out, square, true)]
                }
                SeriesOp::Atan2 { out, y, x, norm } => vec![
                    products(x, x, false),
                    products(y, y, false),
                    products(y, x, true),
                    products(x, y, true),
                    products(out, norm, true),
                ],
                _ => vec![],
            };
            for sum in sums {
                if !all.contains(&sum) {
                    all.push(sum);
                }
            }
        }
        for e in 0..program.derived.varying_mass_entries.len() {
            all.push(Sum::Mass(e));
        }
        for sums in all.chunks(INTERLEAVED_SUMS) {
            self.prefix_group(b, program, sums, k);
        }
    }

    /// Term `t` (in the order of addition) of `sum`'s terms of orders below `k`, read through
    /// the prefix base (see [`Self::prefixes`]).
    fn prefix_term(
        &self,
        b: &mut FunctionBuilder,
        program: &TaylorProgram,
        sum: Sum,
        (k, t): (usize, usize),
    ) -> ir::Value {
        let flags = settled();
        let series = self.prefix_base;
        let older = move |b: &mut FunctionBuilder, slot: Slot, i: usize| {
            let offset = ((slot as usize * UNROLLED_CAPACITY + i) * 8) as i32 - PREFIX_BIAS;
            b.ins().load(types::F64, flags, series, offset)
        };
        match sum {
            Sum::Products { x, y, weighted } => {
                let j = t + 1;
                let (u, v) = (older(b, x, j), older(b, y, k - j));
                Self::product_term(b, (u, v), j, weighted)
            }
            Sum::Pair(p) => {
                let j = t + 1;
                let w = b.ins().load(
                    types::F64X2,
                    flags,
                    self.prefix_scratch,
                    PairScratch::weighted(p, j) - PREFIX_BIAS,
                );
                let pair = b.ins().load(
                    types::F64X2,
                    flags,
                    self.prefix_scratch,
                    PairScratch::pair(p, k - j) - PREFIX_BIAS,
                );
                b.ins().fmul(w, pair)
            }
            Sum::Power { out, a, exponent } => {
                let j = k - 1 - t;
                let alpha = older(b, exponent, 0);
                let (xv, ov) = (older(b, a, k - j), older(b, out, j));
                Self::power_term(b, (alpha, k, j), xv, ov)
            }
            Sum::Mass(e) => {
                let (_, l, slot) = program.derived.varying_mass_entries[e];
                let accelerations = program.acceleration_slot();
                let j = t;
                let m = older(b, slot, 1 + j);
                let a = older(b, accelerations + l, k - 1 - j);
                b.ins().fmul(m, a)
            }
        }
    }

    /// Writes the `k − 1` terms of orders below `k` of each of `sums` ([`INTERLEAVED_SUMS`] or
    /// fewer), term `t` of every sum before term `t + 1` of any, each partial sum into a stack
    /// slot of its own.
    fn prefix_group(
        &mut self,
        b: &mut FunctionBuilder,
        program: &TaylorProgram,
        sums: &[Sum],
        k: usize,
    ) {
        let zero = Self::constant(b, 0.0);
        let mut totals: Vec<ir::Value> = sums
            .iter()
            .map(|s| {
                if matches!(s, Sum::Pair(_)) {
                    b.ins().splat(types::F64X2, zero)
                } else {
                    zero
                }
            })
            .collect();
        for t in 0..k - 1 {
            for (i, &sum) in sums.iter().enumerate() {
                let term = self.prefix_term(b, program, sum, (k, t));
                totals[i] = b.ins().fadd(totals[i], term);
            }
        }
        for (&sum, &value) in sums.iter().zip(&totals) {
            let size = if matches!(sum, Sum::Pair(_)) { 16 } else { 8 };
            let slot = b.create_sized_stack_slot(ir::StackSlotData::new(
                ir::StackSlotKind::ExplicitSlot,
                size,
                4,
            ));
            b.ins().stack_store(types::I64, value, slot, 0);
            self.prefixes.insert(sum, slot);
        }
    }

    /// The partial sum [`Self::prefix`] kept for `sum`, if any.
    fn started(&self, b: &mut FunctionBuilder, sum: Sum, ty: ir::Type) -> Option<ir::Value> {
        let slot = *self.prefixes.get(&sum)?;
        Some(b.ins().stack_load(types::I64, ty, slot, 0))
    }

    /// A term `(kα − j(α + 1)) x[k − j] y[j]` of the power with constant exponent `α`, as
    /// the kernel `pow_constant` computes it.
    fn power_term(
        b: &mut FunctionBuilder,
        (alpha, k, j): (ir::Value, usize, usize),
        xv: ir::Value,
        ov: ir::Value,
    ) -> ir::Value {
        let kc = Self::constant(b, k as f64);
        let one = Self::constant(b, 1.0);
        let ka = b.ins().fmul(alpha, kc);
        let jc = Self::constant(b, j as f64);
        let a1 = b.ins().fadd(alpha, one);
        let ja = b.ins().fmul(a1, jc);
        let weight = b.ins().fsub(ka, ja);
        let t = b.ins().fmul(weight, xv);
        b.ins().fmul(t, ov)
    }

    /// The index of the next pair op in the program's order (see [`PairScratch`]).
    fn next_pair(&mut self) -> usize {
        self.pairs += 1;
        self.pairs - 1
    }

    /// `motion_order`'s solve of order `k` with `factor` (`dense_order`, or `sparse_order`,
    /// then `next_order`), the same operations in the same order: `b = F^[k]`, minus each
    /// varying entry's sum `Σⱼ₌₁ᵏ M_il^[j] a_l^[k−j]` (increasing `j`, from `0.0`), `L z = b`,
    /// `z ← D⁻¹ z`, `Lᵀ x = z` (each update by a zero entry of `L` skipped for
    /// [`Factor::Small`], as `sparse_order` visits only the non-zero ones; a diagonal factor:
    /// `x = D⁻¹ b` alone, as `sparse_order` over no non-zero entries); then `a^[k] = x` into the series, `q^[k+1] = q̇^[k]/(k+1)` and
    /// `q̇^[k+1] = x/(k+1)` into `out` (`2n` per order) and the inputs' and time's order
    /// `k + 1` into the series.
    #[allow(clippy::too_many_arguments)]
    fn dense_solve(
        &mut self,
        b: &mut FunctionBuilder,
        program: &TaylorProgram,
        (n, k): (usize, usize),
        out: ir::Value,
        factor: Factor,
        (lower, inverse_pivots): (ir::Value, ir::Value),
    ) {
        let flags = MemFlagsData::trusted();
        let accelerations = program.acceleration_slot();
        let mut x: Vec<ir::Value> = program
            .forcing
            .iter()
            .map(|&slot| self.at(b, slot, k))
            .collect();
        if k > 0 {
            for (e, &(i, l, slot)) in program.derived.varying_mass_entries.iter().enumerate() {
                let (mut sum, from) = match self.started(b, Sum::Mass(e), types::F64) {
                    Some(sum) => (sum, k - 1),
                    None => (Self::constant(b, 0.0), 0),
                };
                for j in from..k {
                    let m = self.at(b, slot, 1 + j);
                    let a = self.at(b, accelerations + l, k - 1 - j);
                    let term = b.ins().fmul(m, a);
                    sum = b.ins().fadd(sum, term);
                }
                x[i as usize] = b.ins().fsub(x[i as usize], sum);
            }
        }
        let entry = |b: &mut FunctionBuilder, lower: ir::Value, i: usize, j: usize| {
            b.ins()
                .load(types::F64, flags, lower, ((i * n + j) * 8) as i32)
        };
        // `x − l·y`, or `x` where a factor with zeros has `l = 0` (the runtime's solve over
        // the non-zero entries skips them; `x − 0·y` is not `x` for `x = −0` or `y` infinite).
        let update = |b: &mut FunctionBuilder, x: ir::Value, l: ir::Value, y: ir::Value| {
            let t = b.ins().fmul(l, y);
            let updated = b.ins().fsub(x, t);
            if factor == Factor::Small {
                let zero = b.ins().f64const(0.0);
                let skip = b.ins().fcmp(FloatCC::Equal, l, zero);
                b.ins().select(skip, x, updated)
            } else {
                updated
            }
        };
        if factor != Factor::Diagonal {
            for i in 0..n {
                for j in 0..i {
                    let l = entry(b, lower, i, j);
                    x[i] = update(b, x[i], l, x[j]);
                }
            }
        }
        for (i, xi) in x.iter_mut().enumerate() {
            let d = b
                .ins()
                .load(types::F64, flags, inverse_pivots, (i * 8) as i32);
            *xi = b.ins().fmul(*xi, d);
        }
        if factor != Factor::Diagonal {
            for i in (0..n).rev() {
                for j in 0..i {
                    let l = entry(b, lower, i, j);
                    x[j] = update(b, x[j], l, x[i]);
                }
            }
        }
        let inverse = Self::constant(b, 1.0 / (k + 1) as f64);
        let dim = 2 * n;
        let mut next = Vec::with_capacity(dim);
        for i in 0..n {
            let now = b
                .ins()
                .load(types::F64, settled(), out, ((k * dim + n + i) * 8) as i32);
            next.push(b.ins().fmul(now, inverse));
        }
        for (i, &xi) in x.iter().enumerate() {
            self.put(b, accelerations + i as Slot, k, xi);
            next.push(b.ins().fmul(xi, inverse));
        }
        for (i, &v) in next.iter().enumerate() {
            b.ins()
                .store(flags, v, out, (((k + 1) * dim + i) * 8) as i32);
        }
        if k + 1 < UNROLLED_CAPACITY {
            for &(slot, index) in program.derived.inputs.iter() {
                self.put(b, slot, k + 1, next[index as usize]);
            }
            if let Some(slot) = program.time {
                let v = Self::constant(b, if k == 0 { 1.0 } else { 0.0 });
                self.put(b, slot, k + 1, v);
            }
        }
    }

    /// Order `i` of `slot`.
    fn at(&mut self, b: &mut FunctionBuilder, slot: Slot, i: usize) -> ir::Value {
        if let Some(&v) = self.known.get(&(slot, i)) {
            return v;
        }
        let offset = ((slot as usize * UNROLLED_CAPACITY + i) * 8) as i32;
        let v = b.ins().load(types::F64, settled(), self.series, offset);
        self.known.insert((slot, i), v);
        v
    }

    /// Writes `v` as order `k` of `slot`.
    fn put(&mut self, b: &mut FunctionBuilder, slot: Slot, k: usize, v: ir::Value) {
        let offset = ((slot as usize * UNROLLED_CAPACITY + k) * 8) as i32;
        b.ins()
            .store(MemFlagsData::trusted(), v, self.series, offset);
        self.known.insert((slot, k), v);
    }

    fn constant(b: &mut FunctionBuilder, x: f64) -> ir::Value {
        b.ins().f64const(x)
    }

    /// The kernels' `convolution` (`Σ_{j ∈ range} a[j] b[k − j]`) or, if `weighted`, their
    /// `weighted_convolution` (each term `(j a[j]) b[k − j]`), summed from `0.0` in increasing
    /// `j`.
    fn sum_of_products(
        &mut self,
        b: &mut FunctionBuilder,
        (x, y, k): (Slot, Slot, usize),
        range: std::ops::RangeInclusive<usize>,
        weighted: bool,
    ) -> ir::Value {
        let started = if *range.start() == 1 {
            self.started(b, Sum::Products { x, y, weighted }, types::F64)
        } else {
            None
        };
        let (mut sum, from) = match started {
            Some(sum) => (sum, k),
            None => (Self::constant(b, 0.0), *range.start()),
        };
        for j in from.max(*range.start())..=*range.end() {
            let (u, v) = (self.at(b, x, j), self.at(b, y, k - j));
            let term = Self::product_term(b, (u, v), j, weighted);
            sum = b.ins().fadd(sum, term);
        }
        sum
    }

    /// A term of [`Self::sum_of_products`]: `u v`, or `(u j) v` if `weighted`.
    fn product_term(
        b: &mut FunctionBuilder,
        (u, v): (ir::Value, ir::Value),
        j: usize,
        weighted: bool,
    ) -> ir::Value {
        let u = if weighted {
            let weight = Self::constant(b, j as f64);
            b.ins().fmul(u, weight)
        } else {
            u
        };
        b.ins().fmul(u, v)
    }

    /// The kernels' `weighted_convolution_pair` of pair `p` (a sine–cosine or sinh–cosh op
    /// over `x`): `Σ_{j=1}^{k} (j x[j]) y[k − j]` and the same with `z`, as the two lanes of
    /// one 2-wide vector sum. Each lane adds the same products in the same order as its
    /// scalar sum, so the bits are the kernels'. The lanes' operands come from the scratch
    /// ([`PairScratch`]): `(j x[j], j x[j])` and `(y[i], z[i])` as one 16-byte load each;
    /// `(k x[k], k x[k])` is stored there for the orders above.
    fn weighted_pair(
        &mut self,
        b: &mut FunctionBuilder,
        p: usize,
        x: Slot,
        k: usize,
    ) -> (ir::Value, ir::Value) {
        let xk = self.at(b, x, k);
        let kc = Self::constant(b, k as f64);
        let weighted = b.ins().fmul(xk, kc);
        let newest = b.ins().splat(types::F64X2, weighted);
        b.ins().store(
            MemFlagsData::trusted(),
            newest,
            self.scratch,
            PairScratch::weighted(p, k),
        );
        let (mut sum, from) = match self.started(b, Sum::Pair(p), types::F64X2) {
            Some(sum) => (sum, k),
            None => {
                let zero = Self::constant(b, 0.0);
                (b.ins().splat(types::F64X2, zero), 1)
            }
        };
        for j in from..=k {
            let w = if j == k {
                newest
            } else {
                b.ins().load(
                    types::F64X2,
                    settled(),
                    self.scratch,
                    PairScratch::weighted(p, j),
                )
            };
            let pair = b.ins().load(
                types::F64X2,
                settled(),
                self.scratch,
                PairScratch::pair(p, k - j),
            );
            let term = b.ins().fmul(w, pair);
            sum = b.ins().fadd(sum, term);
        }
        (b.ins().extractlane(sum, 0), b.ins().extractlane(sum, 1))
    }

    /// Stores `(y[k], z[k])` as pair `p`'s order `k` in the scratch ([`PairScratch`]).
    fn store_pair(
        &mut self,
        b: &mut FunctionBuilder,
        p: usize,
        k: usize,
        (y, z): (ir::Value, ir::Value),
    ) {
        let flags = MemFlagsData::trusted();
        let offset = PairScratch::pair(p, k);
        b.ins().store(flags, y, self.scratch, offset);
        b.ins().store(flags, z, self.scratch, offset + 8);
    }

    /// `cauchy`: `(Σ_{j=1}^{k−1} a[j] b[k − j] + a[0] b[k]) + a[k] b[0]`.
    fn cauchy(&mut self, b: &mut FunctionBuilder, x: Slot, y: Slot, k: usize) -> ir::Value {
        let older = if k > 1 {
            self.sum_of_products(b, (x, y, k), 1..=k - 1, false)
        } else {
            Self::constant(b, 0.0)
        };
        let (x0, yk, xk, y0) = (
            self.at(b, x, 0),
            self.at(b, y, k),
            self.at(b, x, k),
            self.at(b, y, 0),
        );
        let first = b.ins().fmul(x0, yk);
        let sum = b.ins().fadd(older, first);
        let last = b.ins().fmul(xk, y0);
        b.ins().fadd(sum, last)
    }

    /// `v · (1/k)`.
    fn over_k(b: &mut FunctionBuilder, v: ir::Value, k: usize) -> ir::Value {
        let r = Self::constant(b, 1.0 / k as f64);
        b.ins().fmul(v, r)
    }

    /// Order `k ≥ 1` of `op`: the kernel of `eomgen_runtime::taylor` of its kind.
    fn op(&mut self, b: &mut FunctionBuilder, op: SeriesOp, k: usize) {
        let kf = k as f64;
        match op {
            SeriesOp::Neg { out, a } => {
                let x = self.at(b, a, k);
                let v = b.ins().fneg(x);
                self.put(b, out, k, v);
            }
            SeriesOp::Copy { out, a } => {
                let v = self.at(b, a, k);
                self.put(b, out, k, v);
            }
            SeriesOp::Add { out, a, b: y } => {
                let (u, w) = (self.at(b, a, k), self.at(b, y, k));
                let v = b.ins().fadd(u, w);
                self.put(b, out, k, v);
            }
            SeriesOp::Sub { out, a, b: y } => {
                let (u, w) = (self.at(b, a, k), self.at(b, y, k));
                let v = b.ins().fsub(u, w);
                self.put(b, out, k, v);
            }
            SeriesOp::Mul { out, a, b: y } => {
                let v = self.cauchy(b, a, y, k);
                self.put(b, out, k, v);
            }
            SeriesOp::Scale { out, a, constant } => {
                let (u, c) = (self.at(b, a, k), self.at(b, constant, 0));
                let v = b.ins().fmul(u, c);
                self.put(b, out, k, v);
            }
            SeriesOp::Div { out, a, b: y } => {
                let sum = self.sum_of_products(b, (y, out, k), 1..=k, false);
                let (ak, y0) = (self.at(b, a, k), self.at(b, y, 0));
                let d = b.ins().fsub(ak, sum);
                let v = b.ins().fdiv(d, y0);
                self.put(b, out, k, v);
            }
            SeriesOp::DivByConstant { out, a, constant } => {
                let (u, c) = (self.at(b, a, k), self.at(b, constant, 0));
                let v = b.ins().fdiv(u, c);
                self.put(b, out, k, v);
            }
            SeriesOp::ConstantDiv { out, b: y } => {
                let sum = self.sum_of_products(b, (y, out, k), 1..=k, false);
                let y0 = self.at(b, y, 0);
                let minus = b.ins().fneg(sum);
                let v = b.ins().fdiv(minus, y0);
                self.put(b, out, k, v);
            }
            SeriesOp::Sqrt { out, a } => {
                let sum = if k > 1 {
                    self.sum_of_products(b, (out, out, k), 1..=k - 1, false)
                } else {
                    Self::constant(b, 0.0)
                };
                let (ak, o0) = (self.at(b, a, k), self.at(b, out, 0));
                let d = b.ins().fsub(ak, sum);
                let two = Self::constant(b, 2.0);
                let twice = b.ins().fmul(o0, two);
                let v = b.ins().fdiv(d, twice);
                self.put(b, out, k, v);
            }
            SeriesOp::PowConstant { out, a, exponent } => {
                let alpha = self.at(b, exponent, 0);
                let kc = Self::constant(b, kf);
                let power = Sum::Power { out, a, exponent };
                let (mut sum, from) = match self.started(b, power, types::F64) {
                    Some(sum) => (sum, 0),
                    None => (Self::constant(b, 0.0), k - 1),
                };
                for j in (0..=from).rev() {
                    let (xv, ov) = (self.at(b, a, k - j), self.at(b, out, j));
                    let term = Self::power_term(b, (alpha, k, j), xv, ov);
                    sum = b.ins().fadd(sum, term);
                }
                let x0 = self.at(b, a, 0);
                let d = b.ins().fmul(x0, kc);
                let v = b.ins().fdiv(sum, d);
                self.put(b, out, k, v);
            }
            SeriesOp::Exp { out, a } => {
                let w = self.sum_of_products(b, (a, out, k), 1..=k, true);
                let v = Self::over_k(b, w, k);
                self.put(b, out, k, v);
            }
            SeriesOp::Ln { out, a } => {
                let sum = if k > 1 {
                    self.sum_of_products(b, (out, a, k), 1..=k - 1, true)
                } else {
                    Self::constant(b, 0.0)
                };
                let kc = Self::constant(b, kf);
                let (xk, x0) = (self.at(b, a, k), self.at(b, a, 0));
                let kx = b.ins().fmul(xk, kc);
                let n = b.ins().fsub(kx, sum);
                let d = b.ins().fmul(x0, kc);
                let v = b.ins().fdiv(n, d);
                self.put(b, out, k, v);
            }
            SeriesOp::SinCos { sin, cos, a } => {
                let p = self.next_pair();
                let (ws, wc) = self.weighted_pair(b, p, a, k);
                let vs = Self::over_k(b, ws, k);
                let minus = b.ins().fneg(wc);
                let vc = Self::over_k(b, minus, k);
                self.put(b, sin, k, vs);
                self.put(b, cos, k, vc);
                self.store_pair(b, p, k, (vc, vs));
            }
            SeriesOp::SinhCosh { sinh, cosh, a } => {
                let p = self.next_pair();
                let (ws, wc) = self.weighted_pair(b, p, a, k);
                let vs = Self::over_k(b, ws, k);
                let vc = Self::over_k(b, wc, k);
                self.put(b, sinh, k, vs);
                self.put(b, cosh, k, vc);
                self.store_pair(b, p, k, (vc, vs));
            }
            SeriesOp::Tan { out, a, square } => self.tan_or_tanh(b, k, out, a, square, 1.0),
            SeriesOp::Tanh { out, a, square } => self.tan_or_tanh(b, k, out, a, square, -1.0),
            SeriesOp::Asin { out, a, root, acos } => {
                let a2 = self.cauchy(b, a, a, k);
                let sum = if k > 1 {
                    self.sum_of_products(b, (root, root, k), 1..=k - 1, false)
                } else {
                    Self::constant(b, 0.0)
                };
                let r0 = self.at(b, root, 0);
                let minus = b.ins().fneg(a2);
                let n = b.ins().fsub(minus, sum);
                let two = Self::constant(b, 2.0);
                let twice = b.ins().fmul(r0, two);
                let rk = b.ins().fdiv(n, twice);
                let sign = if acos { -1.0 } else { 1.0 };
                let sum = if k > 1 {
                    self.sum_of_products(b, (out, root, k), 1..=k - 1, true)
                } else {
                    Self::constant(b, 0.0)
                };
                let sk = Self::constant(b, sign * kf);
                let xk = self.at(b, a, k);
                let sx = b.ins().fmul(xk, sk);
                let n = b.ins().fsub(sx, sum);
                let kc = Self::constant(b, kf);
                let d = b.ins().fmul(r0, kc);
                let v = b.ins().fdiv(n, d);
                self.put(b, root, k, rk);
                self.put(b, out, k, v);
            }
            SeriesOp::Atan { out, a, square } => {
                let q = self.cauchy(b, a, a, k);
                self.put(b, square, k, q);
                let sum = if k > 1 {
                    self.sum_of_products(b, (out, square, k), 1..=k - 1, true)
                } else {
                    Self::constant(b, 0.0)
                };
                let kc = Self::constant(b, kf);
                let xk = self.at(b, a, k);
                let kx = b.ins().fmul(xk, kc);
                let n = b.ins().fsub(kx, sum);
                let one = Self::constant(b, 1.0);
                let sq0 = self.at(b, square, 0);
                let s = b.ins().fadd(one, sq0);
                let d = b.ins().fmul(s, kc);
                let v = b.ins().fdiv(n, d);
                self.put(b, out, k, v);
            }
            SeriesOp::Atan2 { out, y, x, norm } => {
                let xx = self.cauchy(b, x, x, k);
                let yy = self.cauchy(b, y, y, k);
                let nk = b.ins().fadd(xx, yy);
                let wy = self.sum_of_products(b, (y, x, k), 1..=k, true);
                let wx = self.sum_of_products(b, (x, y, k), 1..=k, true);
                let cross = b.ins().fsub(wy, wx);
                self.put(b, norm, k, nk);
                let sum = if k > 1 {
                    self.sum_of_products(b, (out, norm, k), 1..=k - 1, true)
                } else {
                    Self::constant(b, 0.0)
                };
                let n = b.ins().fsub(cross, sum);
                let kc = Self::constant(b, kf);
                let n0 = self.at(b, norm, 0);
                let d = b.ins().fmul(n0, kc);
                let v = b.ins().fdiv(n, d);
                self.put(b, out, k, v);
            }
            SeriesOp::Zero { out } => {
                let v = Self::constant(b, 0.0);
                self.put(b, out, k, v);
            }
        }
    }

    /// `tan_or_tanh`.
    fn tan_or_tanh(
        &mut self,
        b: &mut FunctionBuilder,
        k: usize,
        out: Slot,
        a: Slot,
        square: Slot,
        sign: f64,
    ) {
        let w = self.sum_of_products(b, (a, square, k), 1..=k, true);
        let scaled = Self::over_k(b, w, k);
        let s = Self::constant(b, sign);
        let signed = b.ins().fmul(scaled, s);
        let xk = self.at(b, a, k);
        let v = b.ins().fadd(xk, signed);
        self.put(b, out, k, v);
        let q = self.cauchy(b, out, out, k);
        self.put(b, square, k, q);
    }
}
