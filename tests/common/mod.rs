//! Helpers shared by the end-to-end tests (each test file uses some of them).
#![allow(dead_code)]

/// Deterministic xorshift64 generator, so every run checks the same states.
pub struct Rng(pub u64);

impl Rng {
    /// A uniform sample in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// Runs the `eomgen` binary built for the tests with `args`.
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
