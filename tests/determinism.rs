//! Determinism (issue 8, item 5): `--json` output and charts are byte-identical across two
//! runs of the binary (separate processes, so nothing is shared but the build), and the
//! generated code is the same for two derivations in separate processes. Timing is the one
//! thing that differs between runs; it is only in the JSON with `--timing`.

use crate::common;
use common::eomgen;

/// Runs `args` twice and returns both outputs' stdout, asserting success.
fn twice(args: &[&str]) -> (Vec<u8>, Vec<u8>) {
    let run = || {
        let out = eomgen(args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        out.stdout
    };
    (run(), run())
}

#[test]
fn json_outputs_are_byte_identical_across_runs() {
    for args in [
        &["simulate", "double_pendulum", "--json"][..],
        &["simulate", "four_bar", "--json", "--t-end", "1"],
        &[
            "simulate",
            "simple_pendulum",
            "--method",
            "radau5",
            "--json",
            "--t-end",
            "2",
        ],
        &["modes", "triple_pendulum", "--json"],
        &["modes", "four_bar", "--json"],
        &[
            "frf",
            "three_masses_forced",
            "--input",
            "A",
            "--json",
            "--points",
            "40",
        ],
        &["study", "free-response", "three_masses", "--json"],
        &["check", "double_pendulum", "--json"],
        &["list", "--json"],
    ] {
        let (a, b) = twice(args);
        assert!(!a.is_empty(), "{args:?}");
        assert!(a == b, "{args:?}: two runs differ");
    }
    // With --timing the wall time is there (and is what differs).
    let out = eomgen(&["simulate", "simple_pendulum", "--json", "--timing"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["stats"]["wall_time_s"].as_f64().unwrap() > 0.0);
}

#[test]
fn charts_are_byte_identical_across_runs() {
    let dir = std::env::temp_dir().join(format!("eomgen-determinism-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let read = |name: &str| std::fs::read(dir.join(name)).unwrap();
    let mut first = Vec::new();
    for round in 0..2 {
        let sim = dir.join("dp.svg");
        let sim_png = dir.join("dp.png");
        let modes = dir.join("tp");
        let frf = dir.join("bode.svg");
        for args in [
            vec![
                "simulate",
                "double_pendulum",
                "--plot",
                sim.to_str().unwrap(),
            ],
            vec![
                "simulate",
                "double_pendulum",
                "--plot",
                sim_png.to_str().unwrap(),
            ],
            vec![
                "modes",
                "triple_pendulum",
                "--plot",
                modes.to_str().unwrap(),
            ],
            vec![
                "frf",
                "forced_oscillator",
                "--input",
                "A",
                "--plot",
                frf.to_str().unwrap(),
            ],
        ] {
            let out = eomgen(&args);
            assert!(
                out.status.success(),
                "{args:?}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        let files = [
            "dp.svg",
            "dp.png",
            "tp-mode1.svg",
            "tp-mode2.svg",
            "tp-mode3.svg",
            "bode.svg",
        ];
        let contents: Vec<Vec<u8>> = files.iter().map(|f| read(f)).collect();
        if round == 0 {
            first = contents;
        } else {
            for (f, (a, b)) in files.iter().zip(first.iter().zip(&contents)) {
                assert!(!a.is_empty() && a == b, "{f} differs between runs");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The generated code of every bundled model (`eomgen equations NAME --rust`, the pipeline of
/// `eomgen::model!`) is byte-identical across two processes, each deriving it from scratch
/// (no hash-map order, address or seed of one run reaches the output).
#[test]
fn generated_code_is_byte_identical_across_processes() {
    for entry in eomgen::models::ALL {
        let (a, b) = twice(&["equations", entry.name, "--rust"]);
        let code = String::from_utf8_lossy(&a);
        assert!(
            code.contains("impl ::eomgen::MechanicalSystem<"),
            "{}: {code}",
            entry.name
        );
        assert!(
            a == b,
            "{}: the generated code differs between runs",
            entry.name
        );
    }
}
