//! Helpers shared by the integration tests of `eomgen-runtime`.

pub mod models;
pub mod problems;
