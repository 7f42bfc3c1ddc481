//! eomgen facade.
pub use eomgen_runtime::*;
