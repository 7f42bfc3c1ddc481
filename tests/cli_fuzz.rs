//! Command-line values a careful adversary would type, at every option that takes a value:
//! the binary must answer each with a usage error (exit 2), a failure (exit 1) or a result
//! (exit 0) — never a panic, never death by a signal, never exit 0 with a NaN printed.
//!
//! The harness mutates the value of one option of a valid command at a time: empty, text,
//! `nan`, `inf`, `-inf`, zero, negative, huge, tiny, an integer too large for `u64`, a
//! malformed list, a control character. The suite runs one value per option chosen by the
//! seeded generator of `tests/common` (about 100 runs); `cargo test --test suite -- cli_fuzz:: --ignored`
//! runs every value at every option (about 1,000 runs, a few minutes). A run still going after
//! `LIMIT` (a value such as `--t-end 1e300` asks for a long integration that the step limit
//! ends) is killed and not judged.

use crate::common;

use std::io::Read;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use rand::RngExt;

/// The longest a run may take before it is killed and left unjudged.
const LIMIT: Duration = Duration::from_secs(20);

/// Hostile values for an option.
const VALUES: &[&str] = &[
    "",
    "abc",
    "nan",
    "inf",
    "-inf",
    "0",
    "-1",
    "-0.5",
    "1e308",
    "1e-308",
    "99999999999999999999999",
    "1,,2",
    "1..",
    "..",
    "1e-3..",
    "x=",
    "=1",
    "\u{1}",
    // Issue 28: subnormal and absurd values, ranges that start with `-` (clap took them
    // for options), and paths that are not regular files.
    "1e-320",
    "-1..10",
    "1e-320..10",
    "-inf..1",
    ".",
    "/dev/null",
];

/// A valid command and the options of it that take a value.
struct Case {
    args: &'static [&'static str],
    options: &'static [&'static str],
}

const CASES: &[Case] = &[
    Case {
        args: &["simulate", "simple_pendulum", "--t-end", "1"],
        options: &[
            "--t-end",
            "--t-out",
            "--method",
            "--rtol",
            "--atol",
            "--dt",
            "--set",
            "--init",
            "--stabilization",
            "--baumgarte",
            "--stop-when",
            "--event",
            "--csv",
            "--plot",
            "--plot-phase",
        ],
    },
    Case {
        args: &["animate", "simple_pendulum", "-o", "a.html", "--t-end", "1"],
        options: &["--t-end", "--dt", "--fps", "--rtol", "-o", "--gif"],
    },
    Case {
        args: &["simulate", "simple_pendulum_cartesian", "--t-end", "1"],
        options: &["--stabilization", "--baumgarte", "--init"],
    },
    Case {
        args: &["check", "simple_pendulum"],
        options: &["--states"],
    },
    Case {
        args: &["equations", "simple_pendulum"],
        options: &["--method"],
    },
    Case {
        args: &["modes", "three_masses"],
        options: &["--at", "--set"],
    },
    Case {
        args: &["frf", "forced_oscillator", "--input", "A"],
        options: &[
            "--input",
            "--output",
            "--at",
            "--set",
            "--freqs",
            "--points",
            "--frequency",
            "--simulate",
            "--amplitude",
            "--rtol",
        ],
    },
    Case {
        args: &["study", "free-response", "three_masses", "--t-end", "1"],
        options: &["--at", "--set", "--init", "--t-end", "--samples", "--tol"],
    },
    Case {
        args: &["study", "modal-damping", "three_masses", "--t-end", "1"],
        options: &[
            "--rayleigh-modes",
            "--init",
            "--t-end",
            "--samples",
            "--tol",
        ],
    },
    Case {
        args: &["study", "floquet", "mathieu_pendulum"],
        options: &[
            "--at",
            "--period-parameter",
            "--set",
            "--sweep",
            "--tol",
            "--stability-tolerance",
        ],
    },
    Case {
        args: &[
            "study",
            "work-precision",
            "simple_pendulum",
            "--methods",
            "dp54",
            "--tols",
            "1e-3..1e-4",
            "--t-end",
            "1",
        ],
        options: &[
            "--methods",
            "--tols",
            "--steps",
            "--t-end",
            "--target-error",
            "--baseline-ms",
            "--min-time-ms",
            "--plot",
        ],
    },
    Case {
        args: &["study", "stability", "--steps", "100", "--periods", "10"],
        options: &["--steps", "--periods", "--stiffness", "--t-end", "--tol"],
    },
    Case {
        args: &["study", "euler-roundoff", "--max-n", "1000"],
        options: &["--max-n"],
    },
    Case {
        args: &[
            "study",
            "constraint-methods",
            "simple_pendulum_cartesian",
            "--t-end",
            "0.5",
        ],
        options: &["--t-end", "--tol", "--stiffness"],
    },
];

/// What one run did.
enum Verdict {
    /// Exited with this status; standard output and error.
    Exited(i32, String, String),
    /// Ended by a signal (a crash).
    Signalled(String),
    /// Still running after [`LIMIT`]; killed, not judged.
    TimedOut,
}

fn run(args: &[String]) -> Verdict {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut child = Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args(args)
        .current_dir(dir.path())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    // Read both pipes on threads so that a full pipe cannot stall the child.
    let mut out = child.stdout.take().expect("stdout");
    let mut err = child.stderr.take().expect("stderr");
    let out = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = out.read_to_end(&mut s);
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = err.read_to_end(&mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break Some(status);
        }
        if start.elapsed() > LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let out = String::from_utf8_lossy(&out.join().unwrap_or_default()).into_owned();
    let err = String::from_utf8_lossy(&err.join().unwrap_or_default()).into_owned();
    match status {
        None => Verdict::TimedOut,
        Some(s) => match s.code() {
            Some(code) => Verdict::Exited(code, out, err),
            None => Verdict::Signalled(err),
        },
    }
}

/// The command of `case` with `option` set to `value` (replacing the case's own value of it,
/// if it has one).
fn mutated(case: &Case, option: &str, value: &str) -> Vec<String> {
    let mut args: Vec<String> = Vec::new();
    let mut skip = false;
    for a in case.args {
        if skip {
            skip = false;
            continue;
        }
        if *a == option {
            skip = true;
            continue;
        }
        args.push(a.to_string());
    }
    args.push(option.to_string());
    args.push(value.to_string());
    args
}

/// Whether `text` prints a NaN or an infinity (`NaN`, `inf`, `-inf`, `∞` as a word).
fn prints_non_finite(text: &str) -> bool {
    text.split(|c: char| !c.is_alphanumeric())
        .any(|word| matches!(word, "NaN" | "nan" | "inf" | "Infinity"))
        || text.contains('∞')
}

/// Options whose value is a file name, which the command may print back (`animation  nan`):
/// the name is not a number it computed.
const PATH_OPTIONS: &[&str] = &["--csv", "--plot", "--plot-phase", "-o", "--gif"];

/// Judges one run; `Err` with the reason when it is a defect. `echoed` is a value the command
/// may print back as it was given (a file name), left out of the search for NaN.
fn judge(args: &[String], echoed: Option<&str>) -> Result<(), String> {
    match run(args) {
        Verdict::TimedOut => Ok(()),
        Verdict::Signalled(err) => Err(format!("killed by a signal\n{err}")),
        Verdict::Exited(code, out, err) => {
            if err.contains("panicked") {
                Err(format!("panicked (exit {code})\n{err}"))
            } else if !matches!(code, 0..=2) {
                Err(format!("exit {code}\n{err}"))
            } else if code == 0
                && prints_non_finite(&echoed.map_or_else(|| out.clone(), |v| out.replace(v, "")))
            {
                Err(format!("exit 0 with a non-finite number printed\n{out}"))
            } else if code != 0 && err.trim().is_empty() {
                Err(format!("exit {code} without a message"))
            } else {
                Ok(())
            }
        }
    }
}

fn sweep(all: bool) {
    let mut rng = common::seeded_rng(20_261_122);
    let mut defects = Vec::new();
    let mut runs = 0;
    for case in CASES {
        for option in case.options {
            let values: Vec<&str> = if all {
                VALUES.to_vec()
            } else {
                vec![VALUES[rng.random_range(0..VALUES.len())]]
            };
            for value in values {
                let args = mutated(case, option, value);
                runs += 1;
                let echoed = PATH_OPTIONS.contains(option).then_some(value);
                if let Err(why) = judge(&args, echoed) {
                    defects.push(format!("eomgen {:?}: {why}", args));
                }
            }
        }
    }
    eprintln!("{runs} runs, {} defects", defects.len());
    assert!(defects.is_empty(), "{}", defects.join("\n\n"));
}

/// One hostile value per option (seeded): no panic, no signal, no silent NaN.
#[test]
fn hostile_option_values_get_an_answer() {
    sweep(false);
}

/// Every hostile value at every option.
#[test]
#[ignore = "about 1,000 runs of the binary; run with --ignored"]
fn every_hostile_value_at_every_option_gets_an_answer() {
    sweep(true);
}
