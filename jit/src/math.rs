//! The library functions a tape calls, as `extern "C"` functions: the interpreter calls them
//! directly, the compiled code through their addresses.
//!
//! Each is exactly the call the code of `eomgen::model!` makes (`eomgen::__private::{sin, cos,
//! sin_cos, sign, step}` and the `f64` methods), so a run-time model computes the same bits as
//! the compiled one: sine and cosine from the `libm` crate, the other transcendentals from
//! the platform's libm behind `f64::exp` and friends.

use eomgen_symbolic::expr::Func;

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
/// `eomgen::__private::sign`, which is this very function.
extern "C" fn sign(x: f64) -> f64 {
    eomgen_runtime::functions::sign(x)
}
/// `eomgen::__private::step`, which is this very function.
extern "C" fn step(x: f64) -> f64 {
    eomgen_runtime::functions::step(x)
}
extern "C" fn abs(x: f64) -> f64 {
    x.abs()
}
pub(crate) extern "C" fn powf(x: f64, y: f64) -> f64 {
    x.powf(y)
}
pub(crate) extern "C" fn atan2(y: f64, x: f64) -> f64 {
    y.atan2(x)
}

/// The function of one argument behind `function`.
pub(crate) fn unary(function: Func) -> extern "C" fn(f64) -> f64 {
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
