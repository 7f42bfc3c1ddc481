//! Compile-fail tests: every broken model file in `tests/ui/<category>/` must fail to compile
//! with the message recorded in its `.stderr` (`file:line:col`, what is wrong, what would be
//! right). Regenerate with `TRYBUILD=overwrite cargo test --test compiletest` and review the
//! diff. The messages are rustc's rendering of our diagnostics, pinned to the toolchain the
//! project builds with.

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*/*.rs");
}
