//! Helpers shared by the end-to-end tests (each test file uses some of them).
#![allow(dead_code)]

/// The tests' random-number source, seeded so that every run checks the same states:
/// Xoshiro256++ from `rand` (portable: the same draws on every platform), the generator of
/// `eomgen check`'s random states too. Draw with `rand::RngExt::random_range(lo..hi)`.
pub fn seeded_rng(seed: u64) -> rand::rngs::Xoshiro256PlusPlus {
    rand::SeedableRng::seed_from_u64(seed)
}

/// Runs the `eomgen` binary built for the tests with `args`. (A bundled model and its file
/// run through the same path, the model compiled at run time from its text, so a run with the
/// model's name stands for both.)
pub fn eomgen(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args(args)
        .output()
        .expect("binary runs")
}

/// [`eomgen`], asserting that it succeeds (the message names the arguments and has stderr).
pub fn eomgen_ok(args: &[&str]) -> std::process::Output {
    let out = eomgen(args);
    assert!(
        out.status.success(),
        "eomgen {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A bundled model's file (`models/NAME.yaml`) with each `(from, to)` replaced once, written
/// into a new temporary folder: the folder (removed when dropped) and the file's path. Panics
/// if a `from` is not in the text, so that an edit that no longer applies fails its test.
pub fn edited_model(name: &str, edits: &[(&str, &str)]) -> (tempfile::TempDir, String) {
    let path = format!("{}/models/{name}.yaml", env!("CARGO_MANIFEST_DIR"));
    let mut text = std::fs::read_to_string(&path).expect("bundled model file");
    for (from, to) in edits {
        assert!(text.contains(from), "`{from}` is not in {path}");
        text = text.replacen(from, to, 1);
    }
    let dir = tempfile::tempdir().expect("temporary folder");
    let file = dir.path().join(format!("{name}.yaml"));
    std::fs::write(&file, text).expect("written");
    let file = file.to_str().expect("a UTF-8 path").to_string();
    (dir, file)
}
