//! The compile-time half of eomgen: expression DAG, model files, derivations, code generation.
#![warn(missing_docs)]

pub mod codegen;
pub mod expr;
pub mod mechanics;
pub mod model;
