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
        assert!(
            !text.contains("panicked"),
            "eomgen {}: {text}",
            args.join(" ")
        );
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
    assert!(
        !line.is_empty(),
        "eomgen {} printed nothing",
        args.join(" ")
    );
    drop(reader);
    child.wait_with_output().expect("process ends")
}

#[test]
fn a_closed_pipe_ends_the_program_quietly_with_status_141() {
    let commands: &[&[&str]] = &[
        // About 400 kB of model file.
        &["new", "n-link-pendulum", "100"],
        // Every accepted step as a JSON sample: 10⁵ samples, about 18 MB.
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
        assert!(
            text.is_empty(),
            "eomgen {}: quiet, got {text}",
            args.join(" ")
        );
    }
}

/// A run that fails (output times out of order) writes nothing: the CSV of an earlier good
/// run stays as it was, byte for byte.
#[test]
fn a_failed_run_leaves_the_previous_csv_intact() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("f.csv");
    let csv = csv.to_str().unwrap();
    let good = run(&[
        "simulate",
        "simple_pendulum",
        "--t-out",
        "1,2,3",
        "--csv",
        csv,
    ]);
    assert!(good.status.success(), "{}", stderr(&good));
    let before = std::fs::read(csv).unwrap();
    assert_eq!(before.iter().filter(|b| **b == b'\n').count(), 4);
    let bad = run(&[
        "simulate",
        "simple_pendulum",
        "--t-out",
        "3,1,2",
        "--csv",
        csv,
    ]);
    assert_eq!(bad.status.code(), Some(2), "{}", stderr(&bad));
    assert_eq!(std::fs::read(csv).unwrap(), before);
}

/// A run killed while it writes a large CSV leaves either the previous file or the complete
/// new one: killed at once (before it writes), killed the moment its output appears in the
/// directory (a temporary file, or the CSV itself changing — mid-write), and not killed.
#[test]
fn a_killed_run_leaves_the_old_file_or_the_complete_new_one() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("big.csv");
    let csv_arg = csv.to_str().unwrap();
    let old = "old file\n";
    // rk4 at dt = 2e-5 over 2 s: 100001 rows (about 8 MB), every accepted step a sample.
    let args = [
        "simulate",
        "simple_pendulum",
        "--method",
        "rk4",
        "--dt",
        "2e-5",
        "--t-end",
        "2",
        "--csv",
        csv_arg,
    ];
    let rows = 100_001;
    let writing = || {
        let others = std::fs::read_dir(dir.path())
            .unwrap()
            .filter(|e| e.as_ref().unwrap().file_name() != "big.csv")
            .count();
        let len = std::fs::metadata(&csv).map_or(0, |m| m.len());
        others > 0 || len != old.len() as u64
    };
    let (mut kept_old, mut mid_write) = (0, 0);
    for kill in [
        "at once",
        "when writing",
        "when writing",
        "when writing",
        "never",
    ] {
        for entry in std::fs::read_dir(dir.path()).unwrap() {
            std::fs::remove_file(entry.unwrap().path()).unwrap();
        }
        std::fs::write(&csv, old).unwrap();
        let mut child = binary()
            .args(args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("binary runs");
        match kill {
            "at once" => child.kill().unwrap(),
            "when writing" => loop {
                if child.try_wait().unwrap().is_some() {
                    break;
                }
                if writing() {
                    let _ = child.kill();
                    mid_write += 1;
                    break;
                }
                std::thread::sleep(std::time::Duration::from_micros(200));
            },
            _ => {}
        }
        let status = child.wait().unwrap();
        let text = std::fs::read_to_string(&csv).unwrap();
        if text == old {
            kept_old += 1;
            assert_ne!(kill, "never", "a run to the end replaces the file");
            continue;
        }
        let lines: Vec<&str> = text.lines().collect();
        assert!(text.ends_with('\n'), "killed {kill}: cut file");
        assert_eq!(lines.len(), rows + 1, "killed {kill}: rows");
        assert!(lines[0].starts_with("t,q,q_dot,energy"), "{}", lines[0]);
        let t_last: f64 = lines[rows].split(',').next().unwrap().parse().unwrap();
        assert!((t_last - 2.0).abs() < 1e-9, "last t = {t_last}");
        if kill == "never" {
            assert!(status.success());
        }
    }
    assert!(kept_old >= 1, "the kill at once keeps the old file");
    assert!(mid_write >= 1, "no kill landed while the run was writing");
}

/// The model whose solution reaches infinity at t* < 2.45 s (tests/fixtures/blow_up.yaml).
const BLOW_UP: &str = "tests/fixtures/blow_up.yaml";

#[test]
fn the_csv_of_a_failed_integration_says_so_on_its_first_line() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("f.csv");
    let csv = csv.to_str().unwrap();
    let out = run(&["simulate", BLOW_UP, "--t-end", "10", "--csv", csv]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let first = lines.next().unwrap();
    assert!(first.starts_with("# incomplete: "), "{first}");
    let t: f64 = first
        .rsplit_once("at t = ")
        .map(|(_, t)| t.trim_end_matches(')').parse().unwrap())
        .unwrap_or_else(|| panic!("no time in {first}"));
    assert!(
        t > 1.0 && t < 2.45,
        "the blow-up lies in (1, 2.45) s, got {t}"
    );
    assert_eq!(lines.next(), Some("t,x,x_dot,energy"));
    // The samples before the failure follow, the last one before the reported time.
    let last: f64 = text
        .lines()
        .last()
        .and_then(|l| l.split(',').next())
        .unwrap()
        .parse()
        .unwrap();
    assert!(last <= t, "last sample {last} after the failure at {t}");
    // A complete run has no such line.
    let ok = run(&["simulate", BLOW_UP, "--t-end", "0.5", "--csv", csv]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    assert!(std::fs::read_to_string(csv).unwrap().starts_with("t,x"));
}

#[test]
fn the_json_of_a_failed_integration_has_an_error_key() {
    let out = run(&["simulate", BLOW_UP, "--t-end", "10", "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let t = v["error"]["t"].as_f64().unwrap();
    assert!(t > 1.0 && t < 2.45, "{t}");
    assert!(v["error"]["message"].is_string());
    assert!(!v["samples"].as_array().unwrap().is_empty());
    let ok = run(&["simulate", BLOW_UP, "--t-end", "0.5", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&ok.stdout).unwrap();
    assert!(v.get("error").is_none());
}

#[test]
fn the_charts_of_a_failed_integration_carry_a_visible_note() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let (svg, phase, energy) = (path("q.svg"), path("phase.svg"), path("e.svg"));
    let out = run(&[
        "simulate",
        BLOW_UP,
        "--t-end",
        "10",
        "--plot",
        &svg,
        "--plot-phase",
        &phase,
        "--plot-energy",
        &energy,
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    for file in [&svg, &phase, &energy] {
        let text = std::fs::read_to_string(file).unwrap();
        // A red `<text>` element whose content is the note.
        let note = text
            .split("<text")
            .find(|element| element.contains("incomplete: "))
            .unwrap_or_else(|| panic!("{file} has no note"));
        assert!(note.contains("fill=\"#FF0000\""), "{note}");
        assert!(note.contains("at t = "), "{note}");
    }
    // PNG: the note is red text in the band above the chart, which a complete run leaves
    // white.
    let red_in_band = |file: &str| {
        let decoder = png::Decoder::new(std::fs::File::open(file).unwrap());
        let mut reader = decoder.read_info().unwrap();
        let mut buffer = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buffer).unwrap();
        let channels = info.color_type.samples();
        (0..24 * info.width as usize)
            .map(|k| &buffer[k * channels..k * channels + 3])
            .filter(|p| p[0] > 200 && p[1] < 80 && p[2] < 80)
            .count()
    };
    let png = path("q.png");
    let failed = run(&["simulate", BLOW_UP, "--t-end", "10", "--plot", &png]);
    assert_eq!(failed.status.code(), Some(1));
    let red_failed = red_in_band(&png);
    let ok = run(&["simulate", BLOW_UP, "--t-end", "0.5", "--plot", &png]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    let red_ok = red_in_band(&png);
    assert!(
        red_failed > 50 && red_ok == 0,
        "red pixels {red_failed}, {red_ok}"
    );
}

/// Every size a user can type has an upper limit: a value over it is a usage error (exit 2)
/// whose message names the limit.
#[test]
fn sizes_over_their_limit_are_usage_errors() {
    // 100001 output times in two arguments (one argument may hold at most 128 KiB on Linux).
    let times = vec!["1"; 50_001].join(",");
    let cases: &[(&[&str], &str)] = &[
        (&["check", "simple_pendulum", "--states", "0"], "1..=100000"),
        (
            &["check", "simple_pendulum", "--states", "100001"],
            "1..=100000",
        ),
        (
            &[
                "frf",
                "forced_oscillator",
                "--input",
                "A",
                "--output",
                "x",
                "--points",
                "100001",
            ],
            "1..=100000",
        ),
        (
            &[
                "frf",
                "forced_oscillator",
                "--input",
                "A",
                "--output",
                "x",
                "--simulate",
                "1001",
            ],
            "1..=1000",
        ),
        (
            &[
                "study",
                "free-response",
                "three_masses",
                "--samples",
                "1000001",
            ],
            "2..=1000000",
        ),
        (
            &[
                "study",
                "modal-damping",
                "three_masses_damped",
                "--samples",
                "1000001",
            ],
            "2..=1000000",
        ),
        (
            &[
                "study",
                "work-precision",
                "simple_pendulum",
                "--samples",
                "100001",
            ],
            "1..=100000",
        ),
        (
            &[
                "study",
                "work-precision",
                "simple_pendulum",
                "--repeats",
                "1001",
            ],
            "1..=1000",
        ),
        (
            &[
                "study",
                "floquet",
                "mathieu_pendulum",
                "--sweep",
                "a=0..0.3:1001,w=10..100:1000",
            ],
            "at most 1000000",
        ),
        (&["study", "euler-roundoff", "--max-n", "9"], "at most 8"),
        (&["study", "stability", "--steps", "10000000"], "10⁶"),
        (&["new", "n-link-pendulum", "101"], "100"),
        (
            &[
                "animate",
                "simple_pendulum",
                "-o",
                "unwritten.html",
                "--fps",
                "100000",
            ],
            "more than 100000 frames",
        ),
        (
            &[
                "simulate",
                "simple_pendulum",
                "--t-out",
                &times,
                "--t-out",
                &times,
            ],
            "at most 100000",
        ),
    ];
    for (args, limit) in cases {
        let out = run(args);
        let text = stderr(&out);
        let shown: Vec<&str> = args.iter().map(|a| &a[..a.len().min(40)]).collect();
        assert_eq!(
            out.status.code(),
            Some(2),
            "eomgen {}: {text}",
            shown.join(" ")
        );
        assert!(text.contains(limit), "eomgen {}: {text}", shown.join(" "));
        assert!(!text.contains("panicked"), "{text}");
    }
}
