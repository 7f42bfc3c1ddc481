//! Compile-fail tests of the `model!` macro's diagnostics: each `tests/ui/<category>/*.rs`
//! must fail to compile with the message recorded in its `.stderr` (`file:line:col`, what is
//! wrong, what would be right, and rustc's location of the `model!` call). Regenerate with
//! `TRYBUILD=overwrite cargo test --workspace --test compiletest -- --ignored` and review the diff. The messages
//! are rustc's rendering of our diagnostics, pinned to the toolchain the project builds with.
//!
//! The cases are the macro's own (`macro-input/`: its argument, a missing file, a broken file)
//! and one model file of each other category, which shows that the loader's diagnostics reach
//! rustc with their excerpt and help. The other broken files of each category keep their
//! `.yaml` and the `.stderr` of their diagnostics alone (the loader's, without rustc's
//! location): `tests/cli.rs` checks that `eomgen check` and `simulate` print each of them,
//! excerpt, caret and help, from the same loader.
//!
//! The test is `#[ignore]`d, so that the README's test command does not pay for trybuild's
//! second build of eomgen (about 90 processor-seconds from a fresh clone, whether it compiles
//! 9 cases or the 53 of before 2026-11-26): run it with
//! `cargo test --workspace --test compiletest -- --ignored`, as `.ci/run` does. With
//! `--workspace` the test binary is the one the test command built; `-p eomgen-compile-fail`
//! alone resolves eomgen's features for this crate only (no default features) and so builds
//! eomgen and its runtime a second time in target/debug (30-60 processor-seconds).
//!
//! The suite is a crate of its own so that trybuild, which builds the cases against the
//! test crate's dependencies, builds `eomgen` without default features and nothing else.

#[test]
#[ignore = "trybuild builds eomgen again under target/tests/trybuild (about 90 processor-seconds \
            from a fresh clone); CI runs it: cargo test --workspace --test compiletest -- --ignored"]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*/*.rs");
}
