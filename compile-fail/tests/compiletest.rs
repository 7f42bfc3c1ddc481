//! Compile-fail tests: every broken model file in `tests/ui/<category>/` must fail to compile
//! with the message recorded in its `.stderr` (`file:line:col`, what is wrong, what would be
//! right). Regenerate with `TRYBUILD=overwrite cargo test -p eomgen-compile-fail` and review
//! the diff. The messages are rustc's rendering of our diagnostics, pinned to the toolchain
//! the project builds with.
//!
//! The suite is a crate of its own so that trybuild, which builds the cases against the
//! test crate's dependencies, builds `eomgen` without default features and nothing else.

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*/*.rs");
}
