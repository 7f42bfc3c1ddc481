//! eomgen: declarative models of mechanisms compiled into equations of motion, simulated and
//! analysed.
//!
//! A model file (YAML) is turned at compile time by [`model!`] into a struct with an
//! implementation of [`MechanicalSystem`]: mass matrix, forcing, exact Jacobians, energies,
//! point positions, derived symbolically: by momentum balance for a model given by the
//! kinematics of its bodies, by Lagrange's equations for one given by its energies
//! (`eomgen_symbolic::mechanics::preferred_formulation`). The runtime integrates them.
//!
//! ```rust,standalone_crate
//! use eomgen::{DormandPrince54, FirstOrder, Integrator, IntegratorOptions, MechanicalSystem,
//!              OdeSystem, OutputTimes};
//!
//! eomgen::model!("../models/double_pendulum.yaml");
//!
//! let pendulum = DoublePendulum::default();
//! let (q0, qdot0) = pendulum.initial_state();
//! let mut system = FirstOrder::new(pendulum);
//! let y0: Vec<f64> = q0.iter().chain(qdot0.iter()).copied().collect();
//! let options = IntegratorOptions::default().with_rtol(1e-10).with_atol(1e-10);
//! let solution = DormandPrince54::new()
//!     .integrate(&mut system, 0.0, &y0, 1.0, &OutputTimes::At(vec![1.0]), &options)
//!     .expect("the double pendulum integrates");
//! assert_eq!(solution.len(), 1);
//! ```
#![warn(missing_docs)]

extern crate self as eomgen;

#[cfg(feature = "jit")]
pub use eomgen_jit::{
    Backend, COMPILE_TAYLOR_AFTER, CompileError, JitModel, LoadError, LoadOptions,
};
pub use eomgen_macros::model;
pub use eomgen_runtime::*;
#[cfg(feature = "jit")]
pub use source::{ModelSource, OpenError, Resolved, open_model, resolve};

/// nalgebra, the linear algebra of the generated code and the runtime (`SVector`, `SMatrix`,
/// `DMatrix`, …), re-exported so that a program using eomgen needs no dependency of its own
/// on a matching version.
pub use nalgebra;

#[cfg(feature = "jit")]
mod source;

pub mod animation;
#[cfg(feature = "batch")]
pub mod batch;
// The rows of a model file's `checks:` need the run-time loader for the file's model.
#[cfg(feature = "jit")]
pub mod checks;
pub mod expressions;
pub mod listing;
pub mod outputs;
// Method II.2 for the studies: a reduced model file compiled at run time.
#[cfg(feature = "jit")]
pub mod reduction;
#[cfg(feature = "jit")]
pub mod studies;
pub mod text;

#[cfg(feature = "jit")]
pub use floquet_references::{
    ChartAxis, FloquetReferences, ReferenceCurvePoints, ReferenceError, ThresholdPrediction,
};

#[cfg(feature = "jit")]
mod floquet_references;

// Rustdoc compiles the doctests of this crate into one program; an example that calls
// `model!` (here, in the README and in docs/rust.md) is marked `standalone_crate` (compiled
// on its own, about 0.8 processor-seconds each), since the macro reads its file relative to
// the invoking source file, which in the merged program is a temporary file. Merged, the
// other 21 take one compilation rather than 21 (2026-11-29: the one merge failure made every
// one of the 24 standalone, 13.2 s against 3.6 s).

/// The README's Rust examples, compiled and run by `cargo test --doc`.
#[cfg(all(doctest, feature = "jit"))]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

/// The examples of `docs/rust.md`, compiled and run by `cargo test --doc`.
#[cfg(all(doctest, feature = "jit"))]
#[doc = include_str!("../docs/rust.md")]
pub struct RustPageDoctests;

#[cfg(feature = "jit")]
pub mod models;

/// Support for generated code. Not part of the public API.
#[doc(hidden)]
pub mod __private {
    pub use nalgebra;

    pub use eomgen_runtime::functions::{powf, sign, step};

    // The Taylor recurrences the generated `TaylorFunctions::order` calls (`eomgen_runtime::taylor::{mul, …}`).
    pub use eomgen_runtime::taylor;

    // The generated code's sine and cosine come from the `libm` crate (a pure-Rust port of
    // musl's correctly range-reduced fdlibm kernels, < 1 ulp) rather than the platform's libm
    // behind `f64::sin`: the same bits on every platform, inlinable, and a `sincos` that
    // shares one range reduction. On the double pendulum the right-hand side's four calls
    // (cos θ1, cos θ2, sin and cos of θ1 − θ2; two `sin_cos` since the codegen expands angle
    // sums) took 40 % of an integration through glibc.

    /// `sin x` (`libm::sin`).
    #[inline]
    pub fn sin(x: f64) -> f64 {
        libm::sin(x)
    }

    /// `cos x` (`libm::cos`).
    #[inline]
    pub fn cos(x: f64) -> f64 {
        libm::cos(x)
    }

    /// `(sin x, cos x)` with one range reduction (`libm::sincos`).
    #[inline]
    pub fn sin_cos(x: f64) -> (f64, f64) {
        libm::sincos(x)
    }

    pub use super::model_with_errors::ModelWithErrors;
}

mod model_with_errors;
