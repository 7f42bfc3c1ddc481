//! The JSON schemas of the commands stay as they are: every command that takes `--json` is run
//! on a representative model, and the *shape* of its output (the keys of every object and the
//! type of every value, recursively; an array by its first element) is compared with a golden
//! file in `tests/fixtures/json_schemas/`. A key removed, renamed or retyped fails the test; a
//! key added on purpose is added to the golden file too (`EOMGEN_UPDATE_SCHEMAS=1 cargo test
//! --test suite json_schemas::` rewrites the files from the current output, for review in the diff).
//!
//! The values themselves are the other tests' business; only the shapes are compared here, so
//! the runs are short (a second or less each in a debug build).

use std::path::PathBuf;

use serde_json::{Map, Value};

/// The shape of `value`: an object of the shapes of its keys, an array of the shape of its
/// first element (empty for an empty array), and a type name for the rest.
fn shape(value: &Value) -> Value {
    match value {
        Value::Null => Value::from("null"),
        Value::Bool(_) => Value::from("bool"),
        Value::Number(_) => Value::from("number"),
        Value::String(_) => Value::from("string"),
        Value::Array(items) => Value::Array(items.first().map(shape).into_iter().collect()),
        Value::Object(map) => Value::Object(
            map.iter()
                .map(|(k, v)| (k.clone(), shape(v)))
                .collect::<Map<_, _>>(),
        ),
    }
}

/// The paths where `golden` and `actual` differ (`$.key[0].key: golden X, actual Y`).
fn differences(path: &str, golden: &Value, actual: &Value, out: &mut Vec<String>) {
    match (golden, actual) {
        (Value::Object(g), Value::Object(a)) => {
            for (k, gv) in g {
                match a.get(k) {
                    Some(av) => differences(&format!("{path}.{k}"), gv, av, out),
                    None => out.push(format!("{path}.{k}: missing (golden {gv})")),
                }
            }
            for k in a.keys().filter(|k| !g.contains_key(*k)) {
                out.push(format!("{path}.{k}: not in the golden file (added?)"));
            }
        }
        (Value::Array(g), Value::Array(a)) => match (g.first(), a.first()) {
            (Some(gv), Some(av)) => differences(&format!("{path}[0]"), gv, av, out),
            (None, None) => {}
            _ => out.push(format!("{path}: golden {golden}, actual {actual}")),
        },
        _ if golden == actual => {}
        _ => out.push(format!("{path}: golden {golden}, actual {actual}")),
    }
}

/// Runs `eomgen ARGS` and returns its standard output as JSON (a command that fails prints
/// its error as JSON, whose shape differs from the golden one unless the failure is expected).
fn json_of(args: &[&str]) -> Value {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args(args)
        .output()
        .expect("binary runs");
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "eomgen {}: not JSON: {e}\n{}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// Compares the shape of `eomgen ARGS` with `tests/fixtures/json_schemas/NAME.json`.
fn compare(name: &str, args: &[&str]) -> Vec<String> {
    let actual = shape(&json_of(args));
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/json_schemas")
        .join(format!("{name}.json"));
    if std::env::var_os("EOMGEN_UPDATE_SCHEMAS").is_some() {
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        let text = serde_json::to_string_pretty(&actual).unwrap();
        std::fs::write(&file, format!("{text}\n")).unwrap();
        return Vec::new();
    }
    let golden: Value = serde_json::from_str(
        &std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display())),
    )
    .expect("golden file is JSON");
    let mut out = Vec::new();
    differences("$", &golden, &actual, &mut out);
    out.into_iter()
        .map(|d| format!("{name} (eomgen {}): {d}", args.join(" ")))
        .collect()
}

/// Every command's `--json` output has the golden shape.
#[test]
fn json_output_keeps_its_schema() {
    let report_dir = std::env::temp_dir().join(format!("eomgen-schemas-{}", std::process::id()));
    let report_dir = report_dir.to_str().expect("UTF-8 path").to_string();
    let wrong = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/compile-fail/tests/ui/semantics/division-by-zero.yaml"
    );
    let commands: Vec<(&str, Vec<&str>)> = vec![
        ("list", vec!["list", "--json"]),
        (
            "check",
            vec!["check", "double_pendulum", "--states", "5", "--json"],
        ),
        // A model file with mistakes: its diagnostics as JSON.
        ("check_diagnostics", vec!["check", wrong, "--json"]),
        (
            "simulate",
            vec!["simulate", "double_pendulum", "--t-end", "0.5", "--json"],
        ),
        (
            "simulate_constrained",
            vec![
                "simulate",
                "simple_pendulum_cartesian",
                "--t-end",
                "0.5",
                "--stop-when",
                "y = 0",
                "--json",
            ],
        ),
        (
            "equations_constrained",
            vec!["equations", "simple_pendulum_cartesian", "--json"],
        ),
        ("modes", vec!["modes", "three_masses_damped", "--json"]),
        (
            "modes_constrained",
            vec!["modes", "simple_pendulum_cartesian", "--json"],
        ),
        (
            "frf",
            vec![
                "frf",
                "forced_oscillator",
                "--input",
                "A",
                "--output",
                "x",
                "--points",
                "20",
                "--frequency",
                "2",
                "--modal",
                "--simulate",
                "2",
                "--json",
            ],
        ),
        (
            "free_response",
            vec![
                "study",
                "free-response",
                "three_masses",
                "--t-end",
                "1",
                "--samples",
                "11",
                "--json",
            ],
        ),
        (
            "modal_damping",
            vec![
                "study",
                "modal-damping",
                "three_masses_damped",
                "--t-end",
                "1",
                "--samples",
                "11",
                "--json",
            ],
        ),
        (
            "stability",
            vec![
                "study",
                "stability",
                "--steps",
                "200",
                "--periods",
                "20",
                "--json",
            ],
        ),
        (
            "euler_roundoff",
            vec!["study", "euler-roundoff", "--max-n", "3", "--json"],
        ),
        (
            "constraint_methods",
            vec![
                "study",
                "constraint-methods",
                "two_masses_rod",
                "--t-end",
                "0.5",
                "--json",
            ],
        ),
        (
            "work_precision",
            vec![
                "study",
                "work-precision",
                "simple_pendulum",
                "--t-end",
                "1",
                "--tols",
                "1e-3..1e-5",
                "--steps",
                "64..128",
                "--repeats",
                "1",
                "--min-time-ms",
                "0",
                "--json",
            ],
        ),
        (
            "floquet",
            vec!["study", "floquet", "mathieu_pendulum", "--json"],
        ),
        (
            "floquet_sweep",
            vec![
                "study",
                "floquet",
                "mathieu_pendulum",
                "--sweep",
                "a=0..0.2:3,w=40..60:2",
                "--json",
            ],
        ),
        ("expm", vec!["study", "expm", "--n", "3", "--json"]),
        (
            "rayleigh",
            vec![
                "study",
                "rayleigh",
                "three_masses",
                "--shape",
                "1,1,1",
                "--json",
            ],
        ),
        (
            "convolution",
            vec![
                "study",
                "convolution",
                "forced_oscillator",
                "--input",
                "A",
                "--forcing",
                "step",
                "--t-end",
                "1",
                "--json",
            ],
        ),
        (
            "launch",
            vec![
                "study",
                "launch",
                "projectile_drag",
                "--speeds",
                "1",
                "--json",
            ],
        ),
        (
            "periodic_orbit",
            vec!["study", "periodic-orbit", "simple_pendulum", "--json"],
        ),
        (
            "rolling_contact",
            vec!["study", "rolling-contact", "eccentric_cylinder", "--json"],
        ),
        (
            "report",
            vec![
                "report",
                "--models",
                "dumbbell,simple_pendulum",
                "-o",
                &report_dir,
                "--json",
            ],
        ),
    ];
    let mut failures = Vec::new();
    for (name, args) in &commands {
        failures.extend(compare(name, args));
    }
    let _ = std::fs::remove_dir_all(&report_dir);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Whether `a` and `b` have the same keys, strings, booleans and nulls everywhere and
/// numbers equal to a relative 1e-9: the command and this test compile the numerical code
/// apart (the command's model from its file at run time), so a last bit may differ.
fn same_up_to_rounding(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            (x - y).abs() <= 1e-9 * x.abs().max(y.abs()).max(1e-300)
        }
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(x, y)| same_up_to_rounding(x, y))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len()
                && x.iter()
                    .all(|(k, v)| y.get(k).is_some_and(|w| same_up_to_rounding(v, w)))
        }
        _ => a == b,
    }
}

/// The JSON of `simulate`, `modes` and `study euler-roundoff` is the library's summary of
/// the same call, key for key and value for value (to rounding): a Rust program (or another
/// front end) that calls the library gets what the command prints.
#[test]
fn command_json_is_the_library_summary() {
    use eomgen::analysis::vibration::{ModalOptions, modal_analysis};
    use eomgen::analysis::{RoundoffOptions, SimulationOptions, euler_roundoff, simulate};

    let make = |name: &str| (eomgen::models::find(name).expect("bundled model").make)();

    // A constrained model with an event, so that the optional keys are there.
    let mut model = make("simple_pendulum_cartesian");
    let options = SimulationOptions {
        t_end: 0.5,
        ..SimulationOptions::default()
    };
    let run = simulate(model.as_mut(), &options).expect("simulates");
    let mut library = serde_json::to_value(run.summary(model.as_ref())).unwrap();
    // The CLI prints the wall time only with `--timing`.
    library["stats"]
        .as_object_mut()
        .unwrap()
        .remove("wall_time_s");
    let printed = json_of(&[
        "simulate",
        "simple_pendulum_cartesian",
        "--t-end",
        "0.5",
        "--json",
    ]);
    assert!(
        same_up_to_rounding(&printed, &library),
        "{printed}\n{library}"
    );

    let mut model = make("three_masses_damped");
    let modal = modal_analysis(model.as_mut(), &ModalOptions::default()).expect("modes");
    let mut library = serde_json::to_value(modal.summary(model.as_ref())).unwrap();
    // What the command adds: the files it wrote (none here).
    library["charts"] = serde_json::json!([]);
    library["animation"] = Value::Null;
    let printed = json_of(&["modes", "three_masses_damped", "--json"]);
    assert!(
        same_up_to_rounding(&printed, &library),
        "{printed}\n{library}"
    );

    let study = euler_roundoff(&RoundoffOptions { max_n: 3 }).expect("runs");
    let library = serde_json::to_value(study.summary()).unwrap();
    let printed = json_of(&["study", "euler-roundoff", "--max-n", "3", "--json"]);
    assert!(
        same_up_to_rounding(&printed, &library),
        "{printed}\n{library}"
    );
}
