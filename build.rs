//! Compiles every `models/*.yaml` into the crate: writes `$OUT_DIR/models.rs` with one
//! `model!` per file and a registry, so a file dropped into `models/` is available at the
//! next build with no code edited.

use std::fmt::Write as _;
use std::path::Path;

fn struct_name(model_name: &str) -> String {
    model_name
        .split('_')
        .filter(|p| !p.is_empty())
        .map(|p| {
            let mut c = p.chars();
            match c.next() {
                Some(f) => f.to_ascii_uppercase().to_string() + c.as_str(),
                None => String::new(),
            }
        })
        .collect()
}

/// The `name:` of a model file, read from its top-level `name:` line (the macro validates
/// the file properly; this only has to find the struct it will generate).
fn model_name(source: &str, stem: &str) -> String {
    source
        .lines()
        .find_map(|l| l.strip_prefix("name:"))
        .map(|v| {
            v.split('#')
                .next()
                .unwrap_or("")
                .trim()
                .trim_matches(['"', '\''])
                .to_string()
        })
        .filter(|v| !v.is_empty())
        .unwrap_or_else(|| stem.to_string())
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
        let name = model_name(&source, stem);
        let ty = struct_name(&name);
        let _ = writeln!(
            out,
            "/// Generated from `models/{stem}.{ext}`.\npub mod {module} {{ ::eomgen::model!({path:?}); }}\npub use {module}::{ty};",
            ext = f.extension().and_then(|s| s.to_str()).unwrap_or("yaml"),
            path = f.display().to_string(),
        );
        let _ = writeln!(
            registry,
            "    ModelEntry {{ name: {name:?}, path: {path:?}, make: || ::std::boxed::Box::new(crate::FirstOrder::new({module}::{ty}::default())) }},",
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
