//! What the `eomgen` binary does when its outputs cannot be written or its run fails (issue
//! 20): standard output to a full device or a closed pipe, files replaced atomically (a failed
//! or killed run leaves the previous file whole), files of a failed integration marked as
//! incomplete, and the documented upper limit of every size a user can type.
//!
//! Unix only: the tests use `/dev/full`, FIFOs, descriptors, modes and owners.
#![cfg(unix)]

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
        (
            &[
                "study",
                "work-precision",
                "simple_pendulum",
                "--min-time-ms",
                "10001",
            ],
            "[0, 10000]",
        ),
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

// Issue 28, item 1: an output path that is not a regular file is never replaced by one.

/// Runs `eomgen args` in `dir` (so that relative output paths land there).
fn run_in(dir: &std::path::Path, args: &[&str]) -> Output {
    binary()
        .args(args)
        .current_dir(dir)
        .output()
        .expect("binary runs")
}

/// Runs `eomgen args` in `dir`, requires success and returns its standard error (the
/// warnings).
fn succeeds_in(dir: &std::path::Path, args: &[&str]) -> String {
    let out = run_in(dir, args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    stderr(&out)
}

/// Runs `eomgen args` in `dir`, requires a usage error (status 2) and returns its message.
fn refused_in(dir: &std::path::Path, args: &[&str]) -> String {
    let out = run_in(dir, args);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
    stderr(&out)
}

/// The text of the bundled model file `models/NAME.yaml`.
fn bundled_file(name: &str) -> String {
    std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("models/{name}.yaml")),
    )
    .unwrap()
}

/// Writes the companions `CSV-events.csv` and `PLOT-drift.*` in `dir` (a pendulum that
/// crosses q = 0, and the Cartesian pendulum's drift chart) with two runs of eomgen.
fn write_companions(dir: &std::path::Path, csv: &str, plot: &str) {
    let events = ["--init", "q=1", "--event", "q = 0", "--csv", csv];
    succeeds_in(dir, &[&PENDULUM[..], &events].concat());
    succeeds_in(
        dir,
        &[
            "simulate",
            "simple_pendulum_cartesian",
            "--t-end",
            "1",
            "--plot",
            plot,
        ],
    );
}

/// A one-second run of the bundled pendulum, to which a test adds its outputs.
const PENDULUM: [&str; 4] = ["simulate", "simple_pendulum", "--t-end", "1"];

/// The pendulum's CSV output at `t = 1` only, to which a test adds `--csv PATH`.
const PENDULUM_AT_1: [&str; 4] = ["simulate", "simple_pendulum", "--t-out", "1"];

/// The first line of the pendulum's CSV.
const PENDULUM_CSV_HEADER: &str = "t,q,q_dot,energy\n";

/// Whether the file at `path` holds the pendulum's CSV.
fn holds_pendulum_csv(path: &std::path::Path) -> bool {
    std::fs::read_to_string(path)
        .unwrap()
        .starts_with(PENDULUM_CSV_HEADER)
}

/// The files of `dir` whose names start with `.eomgen-`: temporary files left behind.
fn temporaries(dir: &std::path::Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.starts_with(".eomgen-"))
        .collect()
}

/// `--csv /dev/null` used to rename a temporary file over the device (as root, the system's
/// /dev/null became a CSV file). It is now written in place and stays a character device.
#[test]
fn issue_28_dev_null_stays_a_character_device() {
    use std::os::unix::fs::FileTypeExt as _;
    let out = run(&[
        "simulate",
        "simple_pendulum",
        "--t-end",
        "1",
        "--csv",
        "/dev/null",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let kind = std::fs::metadata("/dev/null").unwrap().file_type();
    assert!(kind.is_char_device(), "/dev/null is now {kind:?}");
}

/// Makes a FIFO at `path` (with the system's `mkfifo`).
fn mkfifo(path: &std::path::Path) {
    let made = Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
}

/// A FIFO given as `--csv` or `--plot` receives the bytes (a reader on the other end sees the
/// whole CSV, or the whole SVG) and is still a FIFO afterwards: it used to be replaced by a
/// regular file, and its reader waited forever.
#[test]
fn issue_28_a_fifo_is_written_in_place() {
    use std::os::unix::fs::FileTypeExt as _;
    let dir = tempfile::tempdir().unwrap();
    for (option, name, starts) in [
        ("--csv", "pipe.csv", "t,q,q_dot,energy"),
        ("--plot", "pipe.svg", "<svg"),
    ] {
        let fifo = dir.path().join(name);
        mkfifo(&fifo);
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
        };
        let out = run(&[
            "simulate",
            "simple_pendulum",
            "--init",
            "q=1",
            "--t-out",
            "0.5,1",
            option,
            fifo.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{option}: {}", stderr(&out));
        // Checked before the reader is joined: a FIFO replaced by a file leaves it waiting.
        let kind = std::fs::symlink_metadata(&fifo).unwrap().file_type();
        assert!(kind.is_fifo(), "{name} is now {kind:?}");
        let text = reader.join().unwrap();
        assert!(
            text.starts_with(starts),
            "{option}: {}",
            &text[..text.len().min(80)]
        );
        if option == "--csv" {
            assert_eq!(text.lines().count(), 3, "{text}");
        } else {
            assert!(text.trim_end().ends_with("</svg>"));
        }
    }
    assert!(temporaries(dir.path()).is_empty());
}

/// `--csv link.csv` used to replace the symbolic link by a regular file and leave its target
/// stale. The link now stays a link, and its target (in another directory) is the new file,
/// written through a temporary file in the target's directory.
#[test]
fn issue_28_a_symbolic_link_is_followed_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    std::fs::create_dir(&data).unwrap();
    let target = data.join("target.csv");
    std::fs::write(&target, "old\n").unwrap();
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink("data/target.csv", &link).unwrap();
    // A chain of two links, and a link to a file that does not exist yet.
    let chain = dir.path().join("chain.csv");
    std::os::unix::fs::symlink("link.csv", &chain).unwrap();
    let dangling = dir.path().join("new.csv");
    std::os::unix::fs::symlink("data/created.csv", &dangling).unwrap();
    for path in [&link, &chain, &dangling] {
        let out = run(&[
            "simulate",
            "simple_pendulum",
            "--t-out",
            "1,2",
            "--csv",
            path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        let kind = std::fs::symlink_metadata(path).unwrap().file_type();
        assert!(kind.is_symlink(), "{} is now {kind:?}", path.display());
    }
    for file in [&target, &data.join("created.csv")] {
        let text = std::fs::read_to_string(file).unwrap();
        assert!(text.starts_with("t,q,q_dot,energy\n"), "{text}");
        assert_eq!(text.lines().count(), 3);
    }
    assert!(temporaries(dir.path()).is_empty() && temporaries(&data).is_empty());
}

/// A 0600 file came back 0644 (the temporary file's mode). An existing file now keeps its
/// permissions exactly (0600, 0640, 0444 — the umask does not apply to them), and a new file
/// gets the mode any new file gets (0666 less the umask, as `File::create` makes it here:
/// the child inherits the test's umask). The owner and group are kept too where the process
/// may set them.
#[test]
fn issue_28_an_existing_file_keeps_its_mode() {
    use std::os::unix::fs::PermissionsExt as _;
    let dir = tempfile::tempdir().unwrap();
    let mode =
        |path: &std::path::Path| std::fs::metadata(path).unwrap().permissions().mode() & 0o7777;
    for (name, kept) in [("a.csv", 0o600), ("b.svg", 0o640), ("c.csv", 0o444)] {
        let path = dir.path().join(name);
        std::fs::write(&path, "old\n").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(kept)).unwrap();
        let option = if name.ends_with(".svg") {
            "--plot"
        } else {
            "--csv"
        };
        let out = run(&[
            "simulate",
            "simple_pendulum",
            "--t-out",
            "1",
            option,
            path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert_ne!(std::fs::read(&path).unwrap(), b"old\n");
        assert_eq!(mode(&path), kept, "{name}");
    }
    let reference = dir.path().join("reference");
    std::fs::File::create(&reference).unwrap();
    let new = dir.path().join("new.csv");
    let out = run(&[
        "simulate",
        "simple_pendulum",
        "--t-out",
        "1",
        "--csv",
        new.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(mode(&new), mode(&reference));

    // The owner and group are kept where the writer may set them: run as root (the only
    // user that may give a file away, and so the only one that can set this case up).
    use std::os::unix::fs::MetadataExt as _;
    let owned = dir.path().join("owned.csv");
    std::fs::write(&owned, "old\n").unwrap();
    if std::os::unix::fs::chown(&owned, Some(4321), Some(4321)).is_ok() {
        let out = run(&[
            "simulate",
            "simple_pendulum",
            "--t-out",
            "1",
            "--csv",
            owned.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        let metadata = std::fs::metadata(&owned).unwrap();
        assert_eq!((metadata.uid(), metadata.gid()), (4321, 4321));
        assert_ne!(std::fs::read(&owned).unwrap(), b"old\n");
    } else {
        eprintln!("skipped: the owner-kept case needs root (only root may give a file away)");
    }
}

/// `--csv /dev/stdout` writes the CSV into standard output, in order with the summary, both
/// into a pipe and into a regular file that standard output is redirected to (which a rename
/// would have replaced, losing the summary).
#[test]
fn issue_28_dev_stdout_is_standard_output() {
    let args = [
        "simulate",
        "simple_pendulum",
        "--t-out",
        "1,2",
        "--csv",
        "/dev/stdout",
    ];
    let out = run(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("t,q,q_dot,energy\n"), "{text}");
    assert!(text.contains("\nmodel      simple_pendulum"), "{text}");

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("out.txt");
    let out = binary()
        .args(args)
        .stdout(std::fs::File::create(&file).unwrap())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.starts_with("t,q,q_dot,energy\n"), "{text}");
    assert!(text.contains("\nmodel      simple_pendulum"), "{text}");
    assert!(temporaries(dir.path()).is_empty());
}

// Issue 28, items 6 and 7: outputs checked before any work, companions, statuses, messages.

/// A chart's bad extension was found after integrating, with the CSV already written; the
/// same path given to two outputs kept one of them; a missing directory was found at the
/// end. Each is now a usage error before any work, and no file is written.
#[test]
fn issue_28_outputs_are_checked_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &[
                "simulate",
                "simple_pendulum",
                "--csv",
                "a.csv",
                "--plot",
                "a.pdf",
            ],
            "--plot `a.pdf`: a chart file must end in .svg or .png",
        ),
        (
            &[
                "simulate",
                "simple_pendulum",
                "--csv",
                "a.csv",
                "--plot",
                "q.svg",
                "--plot-phase",
                "./q.svg",
            ],
            "--plot and --plot-phase both write `./q.svg`",
        ),
        (
            &[
                "simulate",
                "simple_pendulum",
                "--csv",
                "a.csv",
                "--plot",
                "q.svg",
                "--plot-energy",
                "q.svg",
            ],
            "both write `q.svg`",
        ),
        (
            // A companion: `--plot q.svg` owns `q-drift.svg`.
            &[
                "simulate",
                "simple_pendulum_cartesian",
                "--csv",
                "a.csv",
                "--plot",
                "q.svg",
                "--plot-phase",
                "q-drift.svg",
            ],
            "--plot (its constraint drift chart) and --plot-phase both write `q-drift.svg`",
        ),
        (
            &[
                "simulate",
                "simple_pendulum",
                "--csv",
                "a.csv",
                "--plot-phase",
                "missing/p.svg",
            ],
            "the directory `missing` does not exist",
        ),
        (
            &[
                "simulate",
                "simple_pendulum",
                "--csv",
                "a.csv",
                "--plot",
                ".",
            ],
            "a chart file must end in .svg or .png",
        ),
        (
            &["simulate", "simple_pendulum", "--csv", "."],
            "is a directory",
        ),
        (
            &["simulate", "simple_pendulum", "--csv", ""],
            "--csv `` names no file",
        ),
        (
            &[
                "animate",
                "simple_pendulum",
                "-o",
                "a.html",
                "--gif",
                "./a.html",
            ],
            "--output and --gif both write `./a.html`",
        ),
        (
            &[
                "frf",
                "forced_oscillator",
                "--input",
                "F0",
                "--plot",
                "bode.txt",
            ],
            "a chart file must end in .svg or .png",
        ),
        (
            &[
                "modes",
                "double_pendulum",
                "--plot",
                "dp",
                "--animate",
                "dp-mode2.svg",
            ],
            "both write `dp-mode2.svg`",
        ),
        (
            &["study", "free-response", "three_masses", "--plot", "r.eps"],
            "a chart file must end in .svg or .png",
        ),
        (
            &["study", "euler-roundoff", "--plot", "missing/e.svg"],
            "does not exist",
        ),
    ];
    for (args, says) in cases {
        let text = refused_in(dir.path(), args);
        assert!(text.contains(says), "{args:?}: {text}");
        let written: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(written.is_empty(), "{args:?} wrote {written:?}");
    }
    // `report -o` names a directory (created if needed), not a file.
    let file = dir.path().join("not-a-directory");
    std::fs::write(&file, "x").unwrap();
    let out = run(&[
        "report",
        "--models",
        "simple_pendulum",
        "-o",
        file.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("is not a directory"),
        "{}",
        stderr(&out)
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
}

/// A previous run's `FILE-events.csv` and `FILE-drift.svg` stayed beside the new outputs of
/// a run that wrote none. A run now writes each companion it has something for and removes a
/// regular file of that name otherwise; a companion that is not a regular file (a link, a
/// FIFO) is left alone.
#[test]
fn issue_28_stale_companions_are_removed() {
    let dir = tempfile::tempdir().unwrap();
    let events = dir.path().join("e-events.csv");
    let drift = dir.path().join("d-drift.svg");
    write_companions(dir.path(), "e.csv", "d.svg");
    assert!(
        std::fs::read_to_string(&events)
            .unwrap()
            .starts_with("event,direction")
    );
    assert!(drift.exists());

    succeeds_in(
        dir.path(),
        &[&PENDULUM[..], &["--csv", "e.csv", "--plot", "d.svg"]].concat(),
    );
    assert!(!events.exists(), "a stale events file stayed");
    assert!(!drift.exists(), "a stale drift chart stayed");

    std::os::unix::fs::symlink("elsewhere.csv", &events).unwrap();
    succeeds_in(dir.path(), &[&PENDULUM[..], &["--csv", "e.csv"]].concat());
    assert!(
        std::fs::symlink_metadata(&events)
            .unwrap()
            .file_type()
            .is_symlink()
    );
}

/// A chart written to a full disk said `plotting failed: ImageError(IoError(Custom {…}))`
/// without the file's name, and the `modes --plot` error repeated the path. Each write
/// error now names the file once, with the operating system's reason, and exits 1.
#[test]
fn issue_28_a_failed_chart_write_names_the_file_and_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let full = |name: &str| {
        let path = dir.path().join(name);
        std::os::unix::fs::symlink("/dev/full", &path).unwrap();
        path.to_str().unwrap().to_string()
    };
    let (png, svg, csv) = (full("q.png"), full("p.svg"), full("f.csv"));
    let mode = full("dp-mode1.svg");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "simulate",
                "simple_pendulum",
                "--t-end",
                "1",
                "--plot",
                &png,
            ],
            &png,
        ),
        (
            vec![
                "simulate",
                "simple_pendulum",
                "--t-end",
                "1",
                "--plot-phase",
                &svg,
            ],
            &svg,
        ),
        (
            vec!["simulate", "simple_pendulum", "--t-end", "1", "--csv", &csv],
            &csv,
        ),
        (
            vec![
                "modes",
                "double_pendulum",
                "--plot",
                &mode[..mode.len() - "-mode1.svg".len()],
            ],
            &mode,
        ),
    ];
    for (args, path) in cases {
        let out = run(&args);
        let text = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {text}");
        assert!(
            text.contains(&format!("cannot write `{path}`: No space left on device")),
            "{args:?}: {text}"
        );
        assert_eq!(text.matches(path).count(), 1, "{text}");
        assert!(
            !text.contains("ImageError") && !text.contains("Custom"),
            "{text}"
        );
        // The link is still a link to the device.
        assert!(
            std::fs::symlink_metadata(path)
                .unwrap()
                .file_type()
                .is_symlink()
        );
    }
}

/// A model file's diagnostics as JSON (`check --json bad.yaml`) on a full device exited 2;
/// a failed write is status 1, as docs/reliability.md says.
#[test]
fn issue_28_diagnostics_json_on_a_full_device_is_status_1() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.yaml");
    std::fs::write(&bad, "name: bad\nbogus: 1\n").unwrap();
    let out = to_full_device(&["check", "--json", bad.to_str().unwrap()]);
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(
        text.contains("cannot write standard output: No space left on device"),
        "{text}"
    );
    // Written where it can be, the same error is a usage error (2).
    let out = run(&["check", "--json", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(serde_json::from_slice::<serde_json::Value>(&out.stdout).is_ok());
}

// Issue 28, review of the output writer: inputs, companions, descriptors, links, arguments.

/// `simulate pend.yaml --csv pend.yaml` replaced the model file with the CSV and exited 0.
/// An output that is the model file the command reads — by the same name, another spelling,
/// a symbolic link or a hard link to it — is now a usage error before any work, and the
/// model file is left as it was.
#[test]
fn issue_28_an_output_naming_the_model_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let model = bundled_file("simple_pendulum");
    std::fs::write(dir.path().join("pend.yaml"), &model).unwrap();
    std::os::unix::fs::symlink("pend.yaml", dir.path().join("link.csv")).unwrap();
    std::fs::hard_link(dir.path().join("pend.yaml"), dir.path().join("hard.csv")).unwrap();
    let run = ["simulate", "pend.yaml", "--t-end", "1", "--csv"];
    let cases: &[&[&str]] = &[
        &[&run[..], &["pend.yaml"]].concat(),
        &[&run[..], &["./pend.yaml"]].concat(),
        &[
            "simulate",
            "./pend.yaml",
            "--t-end",
            "1",
            "--csv",
            "link.csv",
        ],
        &[&run[..], &["hard.csv"]].concat(),
        &["animate", "pend.yaml", "--t-end", "1", "-o", "pend.yaml"],
        &["modes", "pend.yaml", "--animate", "pend.yaml"],
    ];
    for args in cases {
        let text = refused_in(dir.path(), args);
        assert!(
            text.contains("is the model file") && text.contains("pend.yaml"),
            "{args:?}: {text}"
        );
        assert_eq!(
            std::fs::read_to_string(dir.path().join("pend.yaml")).unwrap(),
            model,
            "{args:?} changed the model file"
        );
    }
}

/// `study constraint-methods` reads a second model, the minimal twin its file names
/// (`minimal_twin:`), which was not protected: `--plot out.svg`, a link to the twin's file,
/// replaced the twin with the chart. The twin's file is now an input like the model's (a
/// usage error before any work, the twin left as it was).
#[test]
fn issue_28_an_output_naming_the_minimal_twin_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    // A name that is no bundled model opens the file of that name.
    let twin = bundled_file("simple_pendulum");
    std::fs::write(dir.path().join("pendulum_twin"), &twin).unwrap();
    let cartesian = bundled_file("simple_pendulum_cartesian").replace(
        "minimal_twin: simple_pendulum",
        "minimal_twin: pendulum_twin",
    );
    std::fs::write(dir.path().join("cart.yaml"), cartesian).unwrap();
    std::os::unix::fs::symlink("pendulum_twin", dir.path().join("out.svg")).unwrap();
    let study = ["study", "constraint-methods", "cart.yaml", "--t-end", "0.1"];
    let text = refused_in(dir.path(), &[&study[..], &["--plot", "out.svg"]].concat());
    assert!(
        text.contains("is the model file") && text.contains("pendulum_twin"),
        "{text}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.path().join("pendulum_twin")).unwrap(),
        twin
    );
    // The twin is read and compared with: another chart name is written.
    succeeds_in(dir.path(), &[&study[..], &["--plot", "chart.svg"]].concat());
    assert!(dir.path().join("chart.svg").exists());
}

/// Issue 49: `study rolling-contact --after-lift-off --flight F --plot F` (or `--plot out.svg`,
/// a link to F) replaced the flight model with the chart and exited 0. The flight model is an
/// input like the rolling one: a usage error before any work, the file left as it was.
#[test]
fn an_output_naming_the_flight_model_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let flight = bundled_file("eccentric_cylinder_flight");
    std::fs::write(dir.path().join("flight.yaml"), &flight).unwrap();
    std::fs::write(dir.path().join("F.svg"), &flight).unwrap();
    std::os::unix::fs::symlink("flight.yaml", dir.path().join("out.svg")).unwrap();
    let study = [
        "study",
        "rolling-contact",
        "eccentric_cylinder",
        "--after-lift-off",
    ];
    for (model, plot) in [("flight.yaml", "out.svg"), ("F.svg", "F.svg")] {
        let args = [&study[..], &["--flight", model, "--plot", plot]].concat();
        let text = refused_in(dir.path(), &args);
        assert!(
            text.contains("is the model file") && text.contains(model),
            "{text}"
        );
        assert_eq!(
            std::fs::read_to_string(dir.path().join(model)).unwrap(),
            flight
        );
    }
    let args = [
        &study[..],
        &["--flight", "flight.yaml", "--plot", "chart.svg"],
    ]
    .concat();
    succeeds_in(dir.path(), &args);
    assert!(dir.path().join("chart.svg").exists());
}

/// Issue 49: `report --models out/simple_pendulum/phase.svg -o out` drew the phase portrait
/// over the model it read (the figures of each model's folder were never checked), and
/// `--models "two_masses, out/report.json"` wrote the report over its model (the check saw
/// the name with its space, the command read it without). Both are usage errors now.
#[test]
fn report_outputs_never_replace_a_model_it_reads() {
    let dir = tempfile::tempdir().unwrap();
    succeeds_in(
        dir.path(),
        &["report", "--models", "simple_pendulum", "-o", "out"],
    );
    let model = bundled_file("simple_pendulum");
    for (file, models) in [
        (
            "out/simple_pendulum/phase.svg",
            "out/simple_pendulum/phase.svg",
        ),
        (
            "out/simple_pendulum/shape-mode1.svg",
            "out/simple_pendulum/shape-mode1.svg",
        ),
        ("out/report.json", "two_masses, out/report.json"),
    ] {
        std::fs::write(dir.path().join(file), &model).unwrap();
        let text = refused_in(dir.path(), &["report", "--models", models, "-o", "out"]);
        assert!(text.contains("is the model file"), "{models}: {text}");
        assert_eq!(
            std::fs::read_to_string(dir.path().join(file)).unwrap(),
            model
        );
    }
}

/// `modes --plot PREFIX` of a model with fewer modes than an earlier run left the earlier
/// run's `PREFIX-mode<k>` charts beside the new ones. The charts of modes this run does not
/// have are removed when eomgen wrote them (the Software mark and a mode chart's title) and
/// kept with a warning otherwise, as stale companions are.
#[test]
fn issue_28_stale_mode_charts_are_removed() {
    let dir = tempfile::tempdir().unwrap();
    let chart = |k: usize| dir.path().join(format!("m-mode{k}.svg"));
    succeeds_in(dir.path(), &["modes", "double_pendulum", "--plot", "m"]);
    assert!(chart(1).exists() && chart(2).exists());
    std::fs::write(chart(3), "mine\n").unwrap();
    let text = succeeds_in(dir.path(), &["modes", "simple_pendulum", "--plot", "m"]);
    assert!(chart(1).exists(), "this run's chart");
    assert!(!chart(2).exists(), "a stale mode chart stayed");
    assert_eq!(std::fs::read_to_string(chart(3)).unwrap(), "mine\n");
    assert!(
        text.contains("warning: `m-mode3.svg` is not from this run"),
        "{text}"
    );
}

/// With `echo mine > run-events.csv`, `simulate … --csv run.csv` deleted the user's file as
/// a stale companion. A companion is removed only when eomgen wrote it (the events CSV's
/// header, the drift chart's title or PNG marker); another file of that name is kept, with a
/// warning that it is stale.
#[test]
fn issue_28_a_stale_companion_is_removed_only_when_eomgen_wrote_it() {
    let dir = tempfile::tempdir().unwrap();
    let companions = ["run-events.csv", "p-drift.svg", "p-drift.png"];
    for name in companions {
        std::fs::write(dir.path().join(name), "mine\n").unwrap();
    }
    for plot in ["p.svg", "p.png"] {
        let text = succeeds_in(
            dir.path(),
            &[&PENDULUM[..], &["--csv", "run.csv", "--plot", plot]].concat(),
        );
        assert!(
            text.contains("warning: `run-events.csv` is not from this run"),
            "{text}"
        );
        let drift = plot.replace('.', "-drift.");
        assert!(text.contains(&format!("warning: `{drift}`")), "{text}");
    }
    for name in companions {
        assert_eq!(
            std::fs::read_to_string(dir.path().join(name)).unwrap(),
            "mine\n",
            "{name}"
        );
    }
    // The same names written by eomgen are removed by a run that has nothing for them.
    for name in companions {
        std::fs::remove_file(dir.path().join(name)).unwrap();
    }
    for plot in ["p.svg", "p.png"] {
        write_companions(dir.path(), "run.csv", plot);
    }
    for name in companions {
        assert!(dir.path().join(name).exists(), "{name}");
    }
    let text = succeeds_in(
        dir.path(),
        &[&PENDULUM[..], &["--csv", "run.csv", "--plot", "p.svg"]].concat(),
    );
    let text = text + &succeeds_in(dir.path(), &[&PENDULUM[..], &["--plot", "p.png"]].concat());
    assert!(!text.contains("warning"), "{text}");
    for name in companions {
        assert!(!dir.path().join(name).exists(), "{name} stayed");
    }
}

/// Runs `eomgen args` in `dir` through `sh -c`, with `redirection` (`3>>log.csv`) applied to
/// it: how a user hands the program a descriptor.
fn run_redirected(dir: &std::path::Path, redirection: &str, args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("\"$@\" {redirection}"))
        .arg("sh")
        .arg(env!("CARGO_BIN_EXE_eomgen"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sh runs")
}

/// `--csv /dev/fd/3 3>>log.csv` reopened the descriptor's file with O_TRUNC and destroyed
/// the log. A descriptor of the program is now written through a duplicate of it (appended
/// to, as its redirection says, and never truncated); a descriptor that is not open is a
/// usage error; `/proc/self/cwd/…` is an ordinary path (replaced by rename, like any file).
#[test]
fn issue_28_an_open_descriptor_is_written_through_not_reopened() {
    use std::os::unix::fs::MetadataExt as _;
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("log.csv");
    let pendulum = PENDULUM_AT_1;
    for (k, path) in ["/dev/fd/3", "/proc/self/fd/3"].into_iter().enumerate() {
        std::fs::write(&log, "keep\n").unwrap();
        let out = run_redirected(
            dir.path(),
            "3>>log.csv",
            &[&pendulum[..], &["--csv", path]].concat(),
        );
        assert!(out.status.success(), "{path}: {}", stderr(&out));
        let text = std::fs::read_to_string(&log).unwrap();
        assert!(
            text.starts_with("keep\nt,q,q_dot,energy\n"),
            "{path}: {text}"
        );
        assert_eq!(text.matches("keep").count(), 1, "{path}: {text}");
        assert!(temporaries(dir.path()).is_empty(), "{k}");
    }
    // Not open: nothing to write to.
    let text = refused_in(
        dir.path(),
        &[&pendulum[..], &["--csv", "/dev/fd/9"]].concat(),
    );
    assert!(text.contains("no such open file descriptor"), "{text}");
    // Any other path under /proc is a path like any other.
    let file = dir.path().join("cwd.csv");
    std::fs::write(&file, "old\n").unwrap();
    let before = std::fs::metadata(&file).unwrap().ino();
    succeeds_in(
        dir.path(),
        &[&pendulum[..], &["--csv", "/proc/self/cwd/cwd.csv"]].concat(),
    );
    assert!(holds_pendulum_csv(&file));
    assert_ne!(
        std::fs::metadata(&file).unwrap().ino(),
        before,
        "replaced by rename, as an ordinary file"
    );
}

/// As root, a link that another user planted in a sticky world-writable directory was
/// followed and its target replaced, which the kernel's fs.protected_symlinks forbids. Such
/// a link is now refused before any work (the target is untouched); a link of the caller in
/// the same directory is followed. Only root can give a link to another user, so the test
/// says it was skipped otherwise.
#[test]
fn issue_28_a_planted_link_in_a_sticky_directory_is_not_followed() {
    use std::os::unix::fs::PermissionsExt as _;
    let dir = tempfile::tempdir().unwrap();
    let sticky = dir.path().join("shared");
    std::fs::create_dir(&sticky).unwrap();
    std::fs::set_permissions(&sticky, std::fs::Permissions::from_mode(0o1777)).unwrap();
    let victim = dir.path().join("victim.csv");
    std::fs::write(&victim, "precious\n").unwrap();
    let planted = sticky.join("planted.csv");
    std::os::unix::fs::symlink(&victim, &planted).unwrap();
    if std::os::unix::fs::lchown(&planted, Some(4321), Some(4321)).is_err() {
        eprintln!("skipped: only root can give a link to another user");
        return;
    }
    let text = refused_in(
        dir.path(),
        &[&PENDULUM_AT_1[..], &["--csv", planted.to_str().unwrap()]].concat(),
    );
    assert!(text.contains("fs.protected_symlinks"), "{text}");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious\n");

    let own = sticky.join("own.csv");
    std::os::unix::fs::symlink(&victim, &own).unwrap();
    succeeds_in(
        dir.path(),
        &[&PENDULUM_AT_1[..], &["--csv", own.to_str().unwrap()]].concat(),
    );
    assert!(holds_pendulum_csv(&victim));
}

/// With `mkdir -p R/index.html`, `report -o R` wrote report.json and the model's folder, then
/// exited 2 naming an option "output". The report's files are now checked before any work
/// like every command's outputs (status 2, nothing written); so is a file where a model's
/// folder goes.
#[test]
fn issue_28_report_outputs_are_checked_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("R");
    std::fs::create_dir_all(out.join("index.html")).unwrap();
    let report = || {
        run(&[
            "report",
            "--models",
            "simple_pendulum",
            "-o",
            out.to_str().unwrap(),
        ])
    };
    let result = report();
    let text = stderr(&result);
    assert_eq!(result.status.code(), Some(2), "{text}");
    assert!(
        text.contains("--out (its index.html)") && text.contains("is a directory"),
        "{text}"
    );
    let written: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(written, ["index.html"], "written before the refusal");

    std::fs::remove_dir(out.join("index.html")).unwrap();
    std::fs::write(out.join("simple_pendulum"), "mine\n").unwrap();
    let result = report();
    let text = stderr(&result);
    assert_eq!(result.status.code(), Some(2), "{text}");
    assert!(text.contains("is not a directory"), "{text}");
    assert!(!out.join("report.json").exists());
}

/// `--csv new/` (a directory's name) wrote a file `new`; `--csv -` wrote a file named `-`
/// and a companion `--events.csv`. A file output ending in `/` is refused before any work,
/// and `-` is standard output.
#[test]
fn issue_28_a_trailing_slash_is_refused_and_dash_is_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let text = refused_in(dir.path(), &[&PENDULUM[..], &["--csv", "new/"]].concat());
    assert!(text.contains("--csv `new/` names no file"), "{text}");

    let out = run_in(
        dir.path(),
        &[
            "simulate",
            "simple_pendulum",
            "--t-out",
            "1",
            "--init",
            "q=1",
            "--event",
            "q = 0",
            "--csv",
            "-",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("t,q,q_dot,energy\n"), "{text}");
    assert!(text.contains("\nmodel      simple_pendulum"), "{text}");
    let written: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(written.is_empty(), "wrote {written:?}");
}

/// `simulate --plot` draws one panel per coordinate, each on its own scale, and
/// `--plot-coordinates` chooses coordinates, rates and outputs in order (issue 53: a spin of
/// hundreds of radians no longer flattens a nutation); an unknown name is a usage error before
/// any file is written.
#[test]
fn time_charts_have_a_panel_per_coordinate_and_draw_what_is_asked() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("top.svg").to_string_lossy().to_string();
    let labels = |file: &str| {
        let text = std::fs::read_to_string(file).unwrap();
        ["phi", "theta", "psi", "psi_dot"]
            .into_iter()
            .filter(|name| text.contains(&format!(">\n{name}\n</text>")))
            .collect::<Vec<_>>()
    };
    let out = run(&["simulate", "heavy_top", "--t-end", "0.5", "--plot", &svg]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(labels(&svg), ["phi", "theta", "psi"]);
    let out = run(&[
        "simulate",
        "heavy_top",
        "--t-end",
        "0.5",
        "--plot",
        &svg,
        "--plot-coordinates",
        "theta,psi_dot",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(labels(&svg), ["theta", "psi_dot"]);
    let other = dir.path().join("other.svg").to_string_lossy().to_string();
    let bad = run(&[
        "simulate",
        "heavy_top",
        "--plot",
        &other,
        "--plot-coordinates",
        "nope",
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(stderr(&bad).contains("`nope` is neither a coordinate, a rate nor an output"));
    assert!(!std::path::Path::new(&other).exists());
    // The file's outputs have panels too: the central force's radius beside x.
    let orbit = dir.path().join("orbit.svg").to_string_lossy().to_string();
    let out = run(&[
        "simulate",
        "central_force",
        "--t-end",
        "1",
        "--plot",
        &orbit,
        "--plot-coordinates",
        "radius,x",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(&orbit).unwrap();
    let at = |name: &str| text.find(&format!(">\n{name}\n</text>"));
    assert!(
        at("radius").is_some() && at("x").is_some() && at("y").is_none(),
        "panels"
    );
    assert!(at("radius") < at("x"), "in the order asked");
    // A 20-mass chain: the first 12 coordinates, and a warning that says so.
    let chain = dir.path().join("chain.yaml");
    let text = run(&["new", "n-mass-chain", "20"]);
    std::fs::write(&chain, &text.stdout).unwrap();
    let chain = chain.to_string_lossy().to_string();
    let out = run(&["simulate", &chain, "--t-end", "0.1", "--plot", &svg]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("the first 12 of the 20 coordinates"),
        "{}",
        stderr(&out)
    );
    let many: Vec<String> = (1..=13).map(|i| format!("x{i}")).collect();
    let bad = run(&[
        "simulate",
        &chain,
        "--plot",
        &other,
        "--plot-coordinates",
        &many.join(","),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(
        stderr(&bad).contains("at most 12 panels"),
        "{}",
        stderr(&bad)
    );
}
