//! Helpers shared by the integration tests of `eomgen-runtime`.

pub mod problems;
