//! The library functions a tape calls, as C-ABI functions: the interpreter calls them
//! directly, the compiled code through their addresses.
//!
//! They are `extern "C-unwind"` rather than `extern "C"`: the same calling convention, but
//! without the guard that aborts if a panic would leave the function, so each compiles to a
//! single jump into the library function (none of them can panic: they are pure arithmetic
//! over `f64`). The guard cost ~0.2 ns per call on the double pendulum's right-hand side
//! (`benches/runtime_model.rs`).
//!
//! Each is exactly the call the code of `eomgen::model!` makes (`eomgen::__private::{sin, cos,
//! sin_cos, sign, step, powf}` and the `f64` methods), so a run-time model computes the same bits as
//! the compiled one: sine and cosine from the `libm` crate, the other transcendentals from
//! the platform's libm behind `f64::exp` and friends.

use cranelift_codegen::ir::{self, InstBuilder};
use cranelift_frontend::FunctionBuilder;
use eomgen_symbolic::codegen::tape::{Instruction, Tape};
use eomgen_symbolic::expr::Func;

/// `sin x` and `cos x` of one `libm::sincos` call, returned in two floating-point registers
/// (the C ABI of a struct of two `double`s on x86-64 System V and AArch64).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub(crate) struct SinCos {
    pub(crate) sin: f64,
    pub(crate) cos: f64,
}

pub(crate) extern "C-unwind" fn sin_cos(x: f64) -> SinCos {
    let (sin, cos) = libm::sincos(x);
    SinCos { sin, cos }
}

extern "C-unwind" fn sin(x: f64) -> f64 {
    libm::sin(x)
}
extern "C-unwind" fn cos(x: f64) -> f64 {
    libm::cos(x)
}
extern "C-unwind" fn tan(x: f64) -> f64 {
    x.tan()
}
extern "C-unwind" fn asin(x: f64) -> f64 {
    x.asin()
}
extern "C-unwind" fn acos(x: f64) -> f64 {
    x.acos()
}
extern "C-unwind" fn atan(x: f64) -> f64 {
    x.atan()
}
extern "C-unwind" fn sinh(x: f64) -> f64 {
    x.sinh()
}
extern "C-unwind" fn cosh(x: f64) -> f64 {
    x.cosh()
}
extern "C-unwind" fn tanh(x: f64) -> f64 {
    x.tanh()
}
extern "C-unwind" fn exp(x: f64) -> f64 {
    x.exp()
}
extern "C-unwind" fn ln(x: f64) -> f64 {
    x.ln()
}
/// `eomgen::__private::sign`, which is this very function.
extern "C-unwind" fn sign(x: f64) -> f64 {
    eomgen_runtime::functions::sign(x)
}
/// `eomgen::__private::step`, which is this very function.
extern "C-unwind" fn step(x: f64) -> f64 {
    eomgen_runtime::functions::step(x)
}
extern "C-unwind" fn abs(x: f64) -> f64 {
    x.abs()
}
/// `eomgen::__private::powf`, which is this very function (the code compiled at run time
/// computes a constant half-integer exponent's in line, with the same operations).
pub(crate) extern "C-unwind" fn powf(x: f64, y: f64) -> f64 {
    eomgen_runtime::functions::powf(x, y)
}
pub(crate) extern "C-unwind" fn atan2(y: f64, x: f64) -> f64 {
    y.atan2(x)
}

/// Sets `count` `f64`s from `out` on to `+0.0` (all bits zero): the long runs of zero outputs
/// of a sparse matrix (a chain's mass matrix and Jacobians), one call each instead of one
/// store per entry.
///
/// # Safety
/// `out` points to at least `count` writable `f64`s.
pub(crate) unsafe extern "C-unwind" fn fill_zero(out: *mut f64, count: usize) {
    // SAFETY: guaranteed by the caller (the compiled code passes a range of an output buffer
    // whose length was checked against the function's extent).
    unsafe { std::ptr::write_bytes(out, 0, count) }
}

/// The function of one argument behind `function`.
pub(crate) fn unary(function: Func) -> extern "C-unwind" fn(f64) -> f64 {
    match function {
        Func::Sin => sin,
        Func::Cos => cos,
        Func::Tan => tan,
        Func::Asin => asin,
        Func::Acos => acos,
        Func::Atan => atan,
        Func::Sinh => sinh,
        Func::Cosh => cosh,
        Func::Tanh => tanh,
        Func::Exp => exp,
        Func::Ln => ln,
        Func::Sign => sign,
        Func::Step => step,
        Func::Abs => abs,
    }
}

/// `(m, negative)` when the exponent `y` of a tape's `Powf` is a constant that
/// `eomgen_runtime::functions::powf` takes through a square root (`±(m + ½)`), for
/// [`half_power`] to compute in line.
pub(crate) fn constant_half_power(tape: &Tape, y: u32) -> Option<(u32, bool)> {
    match tape.instructions.get(y as usize) {
        Some(&Instruction::Const(c)) => eomgen_runtime::functions::half_power(c),
        _ => None,
    }
}

/// `eomgen_runtime::functions::powf(x, ±(m + ½))` in line, with its operations in its order
/// (so its bits): `p = |xᵐ √x|`, `xᵐ` by repeated squaring from the lowest bit, and `p` or
/// `1/p`. No call, so no registers saved around one.
pub(crate) fn half_power(
    b: &mut FunctionBuilder,
    x: ir::Value,
    (m, negative): (u32, bool),
) -> ir::Value {
    let result = eomgen_runtime::functions::squaring(x, m, |r, s| b.ins().fmul(r, s));
    let root = b.ins().sqrt(x);
    let power = match result {
        Some(r) => b.ins().fmul(r, root),
        None => root,
    };
    let p = b.ins().fabs(power);
    if negative {
        let one = b.ins().f64const(1.0);
        b.ins().fdiv(one, p)
    } else {
        p
    }
}
