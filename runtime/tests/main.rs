//! The integration tests, one module per file, built as one test binary (a test binary links
//! the whole crate, so one binary is built once rather than once per file).

mod common;
mod events;
mod impacts;
mod integrators;
mod methods;
mod radau5_reference;
mod stability;
mod studies;
mod verner;
mod vibration;
