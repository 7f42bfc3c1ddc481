//! The compile-time half of eomgen: expression DAG, model files, derivations, code generation.
#![warn(missing_docs)]

pub mod codegen;
pub mod expr;
pub mod mechanics;
pub mod model;

/// The bundled models' folder, `models/` at the workspace's root, for the unit tests: found
/// from the manifest of the package that compiles them (`symbolic-tests/Cargo.toml`).
#[cfg(test)]
pub(crate) fn bundled_models_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|dir| dir.join("models"))
        .find(|dir| dir.is_dir())
        .expect("the workspace's models/ folder")
}
