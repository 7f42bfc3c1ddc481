//! The library functions a tape calls, as `extern "C"` functions: the interpreter calls them
//! directly, the compiled code through their addresses.
//!
//! Each is exactly the call the code of `eomgen::model!` makes (`eomgen::__private::{sin, cos,
//! sin_cos, sign, step}` and the `f64` methods), so a run-time model computes the same bits as
//! the compiled one: sine and cosine from the `libm` crate, the other transcendentals from
//! the platform's libm behind `f64::exp` and friends.

use eomgen_symbolic::codegen::tape::Function;

/// `sin x` and `cos x` of one `libm::sincos` call, returned in two floating-point registers
/// (the C ABI of a struct of two `double`s on x86-64 System V and AArch64).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub(crate) struct SinCos {
    pub(crate) sin: f64,
    pub(crate) cos: f64,
}

pub(crate) extern "C" fn sin_cos(x: f64) -> SinCos {
    let (sin, cos) = libm::sincos(x);
    SinCos { sin, cos }
}

extern "C" fn sin(x: f64) -> f64 {
    libm::sin(x)
}
extern "C" fn cos(x: f64) -> f64 {
    libm::cos(x)
}
extern "C" fn tan(x: f64) -> f64 {
    x.tan()
}
extern "C" fn asin(x: f64) -> f64 {
    x.asin()
}
extern "C" fn acos(x: f64) -> f64 {
    x.acos()
}
extern "C" fn atan(x: f64) -> f64 {
    x.atan()
}
extern "C" fn sinh(x: f64) -> f64 {
    x.sinh()
}
extern "C" fn cosh(x: f64) -> f64 {
    x.cosh()
}
extern "C" fn tanh(x: f64) -> f64 {
    x.tanh()
}
extern "C" fn exp(x: f64) -> f64 {
    x.exp()
}
extern "C" fn ln(x: f64) -> f64 {
    x.ln()
}
/// −1, 0 or 1 (0 at 0 and for NaN), as `eomgen::__private::sign`.
extern "C" fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}
/// 1 for `x ≥ 0`, else 0 (also for NaN), as `eomgen::__private::step`.
extern "C" fn step(x: f64) -> f64 {
    if x >= 0.0 { 1.0 } else { 0.0 }
}
pub(crate) extern "C" fn powf(x: f64, y: f64) -> f64 {
    x.powf(y)
}
pub(crate) extern "C" fn atan2(y: f64, x: f64) -> f64 {
    y.atan2(x)
}

/// The function of one argument behind `function`.
pub(crate) fn unary(function: Function) -> extern "C" fn(f64) -> f64 {
    match function {
        Function::Sin => sin,
        Function::Cos => cos,
        Function::Tan => tan,
        Function::Asin => asin,
        Function::Acos => acos,
        Function::Atan => atan,
        Function::Sinh => sinh,
        Function::Cosh => cosh,
        Function::Tanh => tanh,
        Function::Exp => exp,
        Function::Ln => ln,
        Function::Sign => sign,
        Function::Step => step,
    }
}
