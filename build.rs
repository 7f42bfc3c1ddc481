//! Compiles every `models/*.yaml` into the crate: writes `$OUT_DIR/models.rs` with one
//! `model!` per file and a registry, so a file dropped into `models/` is available at the
//! next build with no code edited.

use std::fmt::Write as _;
use std::path::Path;

/// The model's `name` (for the struct the macro will generate), read with the same loader the
/// macro uses; a broken file falls back to its stem, and the macro then reports the errors.
fn model_name(path: &Path, source: &str, stem: &str) -> String {
    eomgen_symbolic::model::load(&path.display().to_string(), source)
        .map(|file| file.name.value)
        .unwrap_or_else(|_| stem.to_string())
}

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default();
    let dir = Path::new(&manifest).join("models");
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .map(|r| {
            r.filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "yaml" || x == "yml"))
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    let mut out = String::new();
    let mut registry = String::new();
    for f in &files {
        let stem = f.file_stem().and_then(|s| s.to_str()).unwrap_or("model");
        let module: String = stem
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() {
                    c.to_ascii_lowercase()
                } else {
                    '_'
                }
            })
            .collect();
        let source = std::fs::read_to_string(f).unwrap_or_default();
        let name = model_name(f, &source, stem);
        let ty = eomgen_symbolic::codegen::struct_name(&name);
        let _ = writeln!(
            out,
            "/// Generated from `models/{stem}.{ext}`.\npub mod {module} {{ ::eomgen::model!({path:?}); }}\npub use {module}::{ty};",
            ext = f.extension().and_then(|s| s.to_str()).unwrap_or("yaml"),
            path = f.display().to_string(),
        );
        let _ = writeln!(
            registry,
            "    ModelEntry {{ name: {name:?}, file: {file:?}, source: include_str!({path:?}), make: || ::std::boxed::Box::new(crate::FirstOrder::new({module}::{ty}::default())) }},",
            file = format!(
                "models/{}",
                f.file_name()
                    .and_then(|s| s.to_str())
                    .unwrap_or("model.yaml")
            ),
            path = f.display().to_string(),
        );
    }
    let _ = writeln!(
        out,
        "/// Every bundled model, sorted by file name.\npub const ALL: &[ModelEntry] = &[\n{registry}];"
    );
    let out_dir = std::env::var("OUT_DIR").unwrap_or_default();
    if let Err(e) = std::fs::write(Path::new(&out_dir).join("models.rs"), out) {
        println!("cargo:warning=cannot write models.rs: {e}");
    }
}
