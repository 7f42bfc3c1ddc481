//! The integration tests, one module per file, built as one test binary (a test binary links
//! the whole crate, so one binary is built once rather than once per file).

mod codegen;
mod common;
mod derivations;
mod fuzz;
mod hand_derivations;
mod large_inputs;
mod model_errors;
mod model_load;
mod model_parser;
mod model_pipeline;
mod model_units;
mod routes;
mod speeds;
mod tape_value_numbering;
mod taylor_angle_sums;
