//! What the `eomgen` binary does when its outputs cannot be written or its run fails (issue
//! 20): standard output to a full device or a closed pipe, files replaced atomically (a failed
//! or killed run leaves the previous file whole), files of a failed integration marked as
//! incomplete, and the documented upper limit of every size a user can type.

use std::io::{BufRead as _, BufReader};
use std::process::{Command, Output, Stdio};

fn binary() -> Command {
    Command::new(env!("CARGO_BIN_EXE_eomgen"))
}

/// Runs `eomgen args` with standard output to `/dev/full` (every write fails with ENOSPC).
fn to_full_device(args: &[&str]) -> Output {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .expect("/dev/full exists on Linux");
    binary()
        .args(args)
        .stdout(full)
        .stderr(Stdio::piped())
        .output()
        .expect("binary runs")
}

fn run(args: &[&str]) -> Output {
    binary().args(args).output().expect("binary runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Exit status 1 and one clear message, no panic, for each command whose output is lost.
#[test]
fn a_full_device_is_an_error_never_a_panic_or_a_success() {
    let commands: &[&[&str]] = &[
        &["list"],
        &["list", "--json"],
        &["new", "n-link-pendulum", "3"],
        &["equations", "double_pendulum", "--rust"],
        &["check", "simple_pendulum", "--states", "5", "--json"],
        &["simulate", "double_pendulum", "--t-end", "1"],
        &["simulate", "double_pendulum", "--t-end", "1", "--json"],
        &["modes", "three_masses", "--json"],
        &[
            "frf",
            "forced_oscillator",
            "--input",
            "A",
            "--output",
            "x",
            "--points",
            "20",
            "--json",
        ],
        &["--help"],
    ];
    for args in commands {
        let out = to_full_device(args);
        let text = stderr(&out);
        assert_eq!(
            out.status.code(),
            Some(1),
            "eomgen {}: {text}",
            args.join(" ")
        );
        assert!(
            text.contains("cannot write standard output: No space left on device"),
            "eomgen {}: {text}",
            args.join(" ")
        );
        assert!(!text.contains("panicked"), "eomgen {}: {text}", args.join(" "));
    }
}

/// The conventional status of a process whose reader closed the pipe (128 + SIGPIPE), as
/// docs/cli.md states it.
const BROKEN_PIPE_STATUS: i32 = 141;

/// Reads one line of `eomgen args`'s standard output, closes the pipe, and returns the end
/// of the process. The output must be larger than a pipe's buffer (64 KiB on Linux), so that
/// the process is still writing when the reader goes away.
fn read_one_line_then_close(args: &[&str]) -> Output {
    let mut child = binary()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary runs");
    let stdout = child.stdout.take().expect("piped");
    let mut reader = BufReader::new(stdout);
    let mut line = String::new();
    reader.read_line(&mut line).expect("one line");
    assert!(!line.is_empty(), "eomgen {} printed nothing", args.join(" "));
    drop(reader);
    child.wait_with_output().expect("process ends")
}

#[test]
fn a_closed_pipe_ends_the_program_quietly_with_status_141() {
    let commands: &[&[&str]] = &[
        // About 1.5 MB of model file.
        &["new", "n-link-pendulum", "200"],
        // Every accepted step as a JSON sample: about 10⁵ samples, several MB.
        &[
            "simulate",
            "simple_pendulum",
            "--method",
            "rk4",
            "--dt",
            "1e-4",
            "--t-end",
            "10",
            "--json",
        ],
    ];
    for args in commands {
        let out = read_one_line_then_close(args);
        let text = stderr(&out);
        assert_eq!(
            out.status.code(),
            Some(BROKEN_PIPE_STATUS),
            "eomgen {}: {text}",
            args.join(" ")
        );
        assert!(text.is_empty(), "eomgen {}: quiet, got {text}", args.join(" "));
    }
}
