//! The non-smooth functions of model files, shared by the code `eomgen::model!` generates
//! (through `eomgen::__private`) and the code compiled at run time, so that both evaluate the
//! very same function.

/// Sign of `x`: −1, 0 or 1 (unlike `f64::signum`, 0 at 0; 0 for NaN).
#[inline]
pub fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Heaviside step: 1 for `x ≥ 0`, else 0 (also for NaN).
#[inline]
pub fn step(x: f64) -> f64 {
    if x >= 0.0 { 1.0 } else { 0.0 }
}
