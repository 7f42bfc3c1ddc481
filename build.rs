//! Embeds every `models/*.yaml` into the crate, deflated (zlib; 156 KB of text in 46 KB):
//! writes each file's compressed text to `$OUT_DIR/models/` and `$OUT_DIR/models.rs` with one
//! [`ModelEntry`] per file (its name, its file and its text, inflated at its first use), so a
//! file dropped into `models/` is available at the next build with no code edited. Nothing
//! is derived or compiled here: a bundled model is compiled at run time at its first use, as
//! any model file is (`eomgen::models`).

use std::fmt::Write as _;
use std::path::Path;

/// The model's `name:` as the loader reads it from a bundled file: the value of the first
/// top-level `name:` line, without a trailing comment or quotes. A test
/// (`every_bundled_model_compiles`, tests/models.rs) checks it against the loader; a file
/// without one falls back to its stem, and its first use reports the loader's diagnostics.
fn model_name(source: &str, stem: &str) -> String {
    source
        .lines()
        .find_map(|l| l.strip_prefix("name:"))
        .and_then(|v| v.split('#').next())
        .map(|v| v.trim().trim_matches(|c| c == '"' || c == '\'').to_string())
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
    let out_dir = std::env::var("OUT_DIR").unwrap_or_default();
    let compressed_dir = Path::new(&out_dir).join("models");
    if let Err(e) = std::fs::create_dir_all(&compressed_dir) {
        println!(
            "cargo:warning=cannot create {}: {e}",
            compressed_dir.display()
        );
    }
    let mut registry = String::new();
    let mut texts = String::new();
    for (index, f) in files.iter().enumerate() {
        let stem = f.file_stem().and_then(|s| s.to_str()).unwrap_or("model");
        let source = std::fs::read_to_string(f).unwrap_or_default();
        let name = model_name(&source, stem);
        let compressed = compressed_dir.join(format!("{stem}.yaml.zlib"));
        let deflated = miniz_oxide::deflate::compress_to_vec_zlib(source.as_bytes(), 10);
        if let Err(e) = std::fs::write(&compressed, deflated) {
            println!("cargo:warning=cannot write {}: {e}", compressed.display());
        }
        let _ = writeln!(
            registry,
            "    ModelEntry {{ name: {name:?}, file: {file:?}, text: || text({index}), make: || instantiate({index}) }},",
            file = format!(
                "models/{}",
                f.file_name()
                    .and_then(|s| s.to_str())
                    .unwrap_or("model.yaml")
            ),
        );
        let _ = writeln!(
            texts,
            "    include_bytes!({:?}),",
            compressed.display().to_string()
        );
    }
    let out = format!(
        "/// Every bundled model, sorted by file name.\npub static ALL: &[ModelEntry] = &[\n{registry}];\n\
         /// How many models are bundled.\nconst COUNT: usize = {};\n\
         /// Each bundled model's text, deflated (zlib), in the order of [`ALL`].\nstatic DEFLATED: [&[u8]; COUNT] = [\n{texts}];\n",
        files.len()
    );
    if let Err(e) = std::fs::write(Path::new(&out_dir).join("models.rs"), out) {
        println!("cargo:warning=cannot write models.rs: {e}");
    }
}
