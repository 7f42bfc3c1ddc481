//! Helpers shared by the end-to-end tests (each test file uses some of them).
#![allow(dead_code)]

/// The tests' random-number source, seeded so that every run checks the same states:
/// Xoshiro256++ from `rand` (portable: the same draws on every platform), the generator of
/// `eomgen check`'s random states too. Draw with `rand::RngExt::random_range(lo..hi)`.
pub fn seeded_rng(seed: u64) -> rand::rngs::Xoshiro256PlusPlus {
    rand::SeedableRng::seed_from_u64(seed)
}

/// Runs the `eomgen` binary built for the tests with `args`.
///
/// When an argument names a bundled model, the command is run a second time with that
/// argument replaced by the model's file (`models/NAME.yaml`), which the CLI compiles at run
/// time (issue 18), and the two runs must agree: same exit status, same standard output —
/// byte for byte, or, where a number differs, to 1e-12 relative (the two evaluate the same
/// operations in the same order and agree to the bit; the tolerance only keeps a formatting
/// difference of the last digit from failing). Commands that print wall times are compared
/// by status only.
pub fn eomgen(args: &[&str]) -> std::process::Output {
    let out = run(args);
    if let Some(with_files) = with_model_files(args) {
        let again = run(&with_files.iter().map(String::as_str).collect::<Vec<_>>());
        assert_eq!(
            out.status.code(),
            again.status.code(),
            "eomgen {} and with the model's file: exit status differs\n{}",
            args.join(" "),
            String::from_utf8_lossy(&again.stderr)
        );
        if !prints_wall_times(args) {
            assert_same_output(args, &out.stdout, &again.stdout);
        }
    }
    out
}

fn run(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args(args)
        .output()
        .expect("binary runs")
}

/// `args` with every bundled model name replaced by its file's path, if any is one.
fn with_model_files(args: &[&str]) -> Option<Vec<String>> {
    let mut replaced = false;
    let out = args
        .iter()
        .enumerate()
        .map(|(i, a)| {
            // The first argument is the command; `--models a,b` lists names.
            let names: Vec<&str> = a.split(',').collect();
            if i > 0
                && names
                    .iter()
                    .all(|n| eomgen::models::find(n.trim()).is_some())
            {
                replaced = true;
                names
                    .iter()
                    .map(|n| format!("models/{}.yaml", n.trim()))
                    .collect::<Vec<_>>()
                    .join(",")
            } else {
                a.to_string()
            }
        })
        .collect();
    replaced.then_some(out)
}

/// Commands whose output has wall times in it.
fn prints_wall_times(args: &[&str]) -> bool {
    args.contains(&"work-precision") || args.contains(&"--timing")
}

/// Standard outputs equal byte for byte, or token for token with numbers to 1e-12 relative.
fn assert_same_output(args: &[&str], a: &[u8], b: &[u8]) {
    if a == b {
        return;
    }
    let (a, b) = (String::from_utf8_lossy(a), String::from_utf8_lossy(b));
    let split = |s: &str| -> Vec<String> {
        s.split(|c: char| c.is_whitespace() || ",[]{}():\"".contains(c))
            .filter(|t| !t.is_empty())
            .map(str::to_string)
            .collect()
    };
    let (ta, tb) = (split(&a), split(&b));
    // A wall time (`… 0.36 ms`, `"wall_time_s": 0.0016`, `time_s`) differs from run to run.
    let wall_time = |k: usize| {
        ta.get(k + 1)
            .is_some_and(|next| next == "ms" || next == "s")
            || k.checked_sub(1)
                .and_then(|p| ta.get(p))
                .is_some_and(|previous| previous.ends_with("time_s"))
    };
    let same = ta.len() == tb.len()
        && ta.iter().zip(&tb).enumerate().all(|(k, (x, y))| {
            x == y
                || match (x.parse::<f64>(), y.parse::<f64>()) {
                    (Ok(u), Ok(v)) => wall_time(k) || (u - v).abs() <= 1e-12 * u.abs().max(v.abs()),
                    _ => false,
                }
        });
    assert!(
        same,
        "eomgen {}: the bundled model and its file compiled at run time print different \
         output:\n--- bundled\n{a}\n--- file\n{b}",
        args.join(" ")
    );
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
