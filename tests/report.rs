//! `eomgen report`: the page and the JSON are written, the bundled models' reference checks
//! pass, a file with wrong reference values fails (so the checks can fail), the MathML of a
//! known equation has the expected structure, the output is byte-identical across runs, and
//! `simulate` draws the phase portrait and the energy drift. The full report on every bundled
//! model runs too: about 6 s in a debug build.

use crate::common;
use common::{eomgen, eomgen_ok};

use std::path::{Path, PathBuf};

use eomgen_symbolic::codegen::equations_mathml;
use eomgen_symbolic::mechanics::{Formulation, Lagrange, SymbolicModel};

fn out_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("eomgen-report-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn read_json(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("report.json")).expect("report.json written");
    serde_json::from_str(&text).expect("report.json is JSON")
}

/// Runs `eomgen report [--models MODELS] -o DIR`, asserting success.
fn report_ok(models: Option<&str>, dir: &Path) {
    let mut args = vec!["report"];
    if let Some(models) = models {
        args.extend(["--models", models]);
    }
    args.extend(["-o", dir.to_str().expect("UTF-8 path")]);
    eomgen_ok(&args);
}

/// The rows of `model` in `report`.
fn checks<'a>(report: &'a serde_json::Value, model: &str) -> &'a Vec<serde_json::Value> {
    report["models"]
        .as_array()
        .expect("models")
        .iter()
        .find(|m| m["name"] == model)
        .unwrap_or_else(|| panic!("no section for {model}"))["checks"]
        .as_array()
        .expect("checks")
}

/// The row of `rows` whose check name starts with `prefix` (`what` names it in the panic).
fn row<'a>(
    rows: &'a [serde_json::Value],
    prefix: impl AsRef<str>,
    what: &str,
) -> &'a serde_json::Value {
    rows.iter()
        .find(|c| {
            c["check"]
                .as_str()
                .unwrap_or_default()
                .starts_with(prefix.as_ref())
        })
        .unwrap_or_else(|| panic!("{what}: no check starting `{}`", prefix.as_ref()))
}

#[test]
fn report_on_three_models_writes_the_page_and_json_and_passes() {
    let dir = out_dir("three");
    report_ok(Some("three_masses,simple_pendulum,dumbbell"), &dir);
    let report = read_json(&dir);
    let names: Vec<&str> = report["models"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        ["dumbbell", "simple_pendulum", "three_masses"],
        "sorted"
    );
    for name in names {
        let rows = checks(&report, name);
        assert!(!rows.is_empty());
        for c in rows {
            assert_eq!(c["passed"], true, "{name}: {c}");
        }
        // The generic checks are there for every model.
        assert!(
            rows.iter().any(|c| c["check"]
                .as_str()
                .unwrap()
                .starts_with("derivations agree")),
            "{name}"
        );
    }
    assert_eq!(report["summary"]["failed"], 0);
    // The expected values are the files' expressions evaluated at the defaults; recompute
    // them here: sqrt(g/l) with g = 10, l = 1, and omega^2 = (2 -+ sqrt 2, 2) k/m for the
    // three masses (k = m = 1), to 1e-15 (only the evaluation order differs).
    let pendulum = checks(&report, "simple_pendulum");
    let w = row(pendulum, "natural_frequencies[1]", "natural frequency row");
    assert!((w["expected"].as_f64().unwrap() - 10f64.sqrt()).abs() < 1e-15);
    let masses = checks(&report, "three_masses");
    let s2 = 2f64.sqrt();
    for (k, w2) in [2.0 - s2, 2.0, 2.0 + s2].iter().enumerate() {
        let row = row(masses, format!("natural_frequencies[{}]", k + 1), "row");
        assert!((row["expected"].as_f64().unwrap() - w2.sqrt()).abs() < 1e-15);
    }
    // The dumbbell is constrained and conservative: energy and constraint drift both run.
    let dumbbell = checks(&report, "dumbbell");
    for what in [
        "energy drift",
        "constraint drift",
        "conserved `angular_momentum`",
    ] {
        assert!(
            dumbbell
                .iter()
                .any(|c| c["check"].as_str().unwrap().starts_with(what)),
            "{what}"
        );
    }
    // The page: a section per model, MathML equations, figures that exist next to it.
    let html = std::fs::read_to_string(dir.join("index.html")).expect("index.html written");
    for id in ["dumbbell", "simple_pendulum", "three_masses"] {
        assert!(html.contains(&format!("<section id=\"{id}\">")), "{id}");
    }
    assert!(html.contains("<math display=\"block\">"));
    // Each section titles its equations by the derivation they come from: Lagrange's for the
    // pendulum's energies, momentum balance for the masses' points.
    for (id, derivation) in [
        ("simple_pendulum", "Lagrange"),
        ("three_masses", "momentum balance"),
    ] {
        let start = html.find(&format!("<section id=\"{id}\">")).unwrap();
        let section = &html[start..start + html[start..].find("</section>").unwrap()];
        assert!(
            section.contains(&format!("<h3>Equations of motion ({derivation})</h3>")),
            "{id}: {derivation}"
        );
    }
    assert!(
        !html.contains("http://") && !html.contains("https://"),
        "no network"
    );
    for m in report["models"].as_array().unwrap() {
        let figures = m["figures"].as_array().unwrap();
        assert!(figures.len() >= 3, "{}: time, phase, energy", m["name"]);
        for f in figures {
            let file = f["file"].as_str().unwrap();
            assert!(
                html.contains(&format!("src=\"{file}\"")),
                "{file} on the page"
            );
            let svg = std::fs::read_to_string(dir.join(file)).expect("figure written");
            assert!(svg.starts_with("<svg"), "{file}");
        }
        // A model whose file draws something has its animation next to the page, shown in
        // an iframe; the others have none.
        let name = m["name"].as_str().unwrap();
        let drawn = eomgen::models::find(name).is_some_and(|entry| {
            let model = (entry.make)();
            !model.description().draw_line_names().is_empty()
                || !model.description().trace_point_names().is_empty()
        });
        match m["animation"].as_str() {
            Some(file) => {
                assert!(drawn, "{name}: animated without draw:");
                assert!(html.contains(&format!("<iframe class=\"animation\" src=\"{file}\"")));
                let page = std::fs::read_to_string(dir.join(file)).expect("animation written");
                assert!(
                    page.starts_with("<!DOCTYPE html>") && page.contains(name),
                    "{file}"
                );
            }
            None => assert!(!drawn, "{name}: draws but has no animation"),
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A file whose `checks:` state a wrong natural frequency (4 rad/s against the true √15) and a
/// quantity that is not conserved: both rows fail, the others pass, and the command exits 1.
#[test]
fn wrong_reference_values_fail_the_report() {
    let dir = out_dir("wrong");
    let fixture = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/report_wrong_values.yaml"
    );
    let out = eomgen(&["report", "--models", fixture, "-o", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "a failed check exits 1");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("2 of"), "{stderr}");
    assert!(stderr.contains("natural_frequencies[1]"), "{stderr}");
    let report = read_json(&dir);
    assert_eq!(report["summary"]["failed"], 2);
    let rows = checks(&report, "compound_pendulum");
    let w = row(rows, "natural_frequencies[1]", "row");
    assert_eq!(w["passed"], false);
    assert_eq!(w["expected"], 4.0);
    // What was computed is the true √(m g d/(I + m d²)) = √15 (to 1e-12: the eigenvalue of
    // a 1 × 1 problem, exact to rounding).
    assert!((w["computed"].as_f64().unwrap() - 15f64.sqrt()).abs() < 1e-12);
    let rate = row(rows, "conserved `rate`", "row");
    assert_eq!(rate["passed"], false);
    assert!(
        rate["computed"].as_f64().unwrap() > 0.1,
        "θ̇ swings through 0"
    );
    for c in rows {
        let check = c["check"].as_str().unwrap();
        if !check.starts_with("natural_frequencies") && !check.starts_with("conserved") {
            assert_eq!(c["passed"], true, "{c}");
        }
    }
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    assert!(html.contains("FAIL"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A file naming a model that is not bundled is reported on its own equations, compiled at
/// run time (issue 18; it used to be refused); a name that is neither bundled nor a file is a
/// usage error (exit 2) that says a path works too.
#[test]
fn a_file_of_an_unbundled_model_is_reported_and_an_unknown_name_is_a_usage_error() {
    let dir = out_dir("unbundled");
    let fixture = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/frf_loads.yaml");
    eomgen_ok(&["report", "--models", fixture, "-o", dir.to_str().unwrap()]);
    let report = read_json(&dir);
    assert_eq!(report["models"].as_array().map(Vec::len), Some(1));
    let out = eomgen(&[
        "report",
        "--models",
        "no_such_model",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("no model named `no_such_model`"),
        "{stderr}"
    );
    assert!(stderr.contains("a path to a model file"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A tiny XML tree of MathML: tag and children, or text.
#[derive(Debug, PartialEq)]
enum Node {
    Element(String, Vec<Node>),
    Text(String),
}

/// Parses well-formed MathML as written by the printer (no attributes other than
/// `display` and `accent`, no self-closing tags); panics on mismatched tags.
fn parse(s: &str) -> Node {
    fn element(s: &str, i: &mut usize) -> Node {
        assert_eq!(&s[*i..*i + 1], "<");
        let end = s[*i..].find('>').unwrap() + *i;
        let tag = s[*i + 1..end].split(' ').next().unwrap().to_string();
        *i = end + 1;
        let mut children = Vec::new();
        loop {
            if s[*i..].starts_with("</") {
                let close = s[*i..].find('>').unwrap() + *i;
                assert_eq!(&s[*i + 2..close], tag, "mismatched close tag");
                *i = close + 1;
                return Node::Element(tag, children);
            } else if s[*i..].starts_with('<') {
                children.push(element(s, i));
            } else {
                let next = s[*i..].find('<').unwrap() + *i;
                children.push(Node::Text(s[*i..next].to_string()));
                *i = next;
            }
        }
    }
    let mut i = 0;
    let node = element(s, &mut i);
    assert_eq!(i, s.len(), "one root element");
    node
}

fn tag(n: &Node) -> &str {
    match n {
        Node::Element(t, _) => t,
        Node::Text(_) => "#text",
    }
}

fn children(n: &Node) -> &[Node] {
    match n {
        Node::Element(_, c) => c,
        Node::Text(_) => &[],
    }
}

/// The text of a leaf element (`<mi>m</mi>` → `m`).
fn text(n: &Node) -> String {
    match children(n) {
        [Node::Text(t)] => t.clone(),
        _ => String::new(),
    }
}

/// The factors of a product `<mrow>a<mo>⁢</mo>b…</mrow>`, printed back compactly, sorted.
fn factors(n: &Node) -> Vec<String> {
    assert_eq!(tag(n), "mrow");
    let mut out: Vec<String> = children(n)
        .iter()
        .filter(|c| !(tag(c) == "mo" && text(c) == "\u{2062}"))
        .map(compact)
        .collect();
    out.sort();
    out
}

/// `n` printed as `tag(children)` or leaf text, for comparisons.
fn compact(n: &Node) -> String {
    match n {
        Node::Text(t) => t.clone(),
        Node::Element(t, c) if c.len() == 1 && matches!(c[0], Node::Text(_)) => {
            format!("{t}:{}", text(n))
        }
        Node::Element(t, c) => format!(
            "{t}({})",
            c.iter().map(compact).collect::<Vec<_>>().join(",")
        ),
    }
}

/// Lecture 10's pendulum in the energy form, T = m l² q̇²/2, V = m g l sin q: Lagrange gives
/// m l² q̈ = −m g l cos q. Its MathML line is `<math>` with the product m·q̈·l², `=`, and minus
/// the product m·l·g·cos(q), every accent and power in its own element.
#[test]
fn mathml_of_the_simple_pendulum_equation() {
    let entry = eomgen::models::find("simple_pendulum").expect("bundled");
    let file = eomgen_symbolic::model::load(entry.file, entry.source()).expect("loads");
    let mut model = SymbolicModel::from_file(&file).expect("lowers");
    let eom = Lagrange.derive(&mut model);
    let lines = equations_mathml(&model, &eom);
    assert_eq!(lines.len(), 3, "T, V and one equation: {lines:#?}");
    let root = parse(&lines[2]);
    assert_eq!(tag(&root), "math");
    assert!(lines[2].starts_with("<math display=\"block\">"));
    let parts = children(&root);
    assert_eq!(parts.len(), 3, "lhs = rhs");
    assert_eq!(compact(&parts[1]), "mo:=");
    assert_eq!(
        factors(&parts[0]),
        ["mi:m", "mover(mi:q,mo:\u{a8})", "msup(mi:l,mn:2)"],
        "m q̈ l²"
    );
    let rhs = children(&parts[2]);
    assert_eq!(tag(&parts[2]), "mrow");
    assert_eq!(rhs.len(), 2, "minus, product");
    assert_eq!(compact(&rhs[0]), "mo:\u{2212}");
    assert_eq!(
        factors(&rhs[1]),
        [
            "mi:g",
            "mi:l",
            "mi:m",
            "mrow(mi:cos,mo:\u{2061},mrow(mo:(,mi:q,mo:)))"
        ],
        "m l g cos(q)"
    );
    // The accent is declared as one, so browsers stack it over the q.
    assert!(lines[2].contains("<mover accent=\"true\"><mi>q</mi><mo>\u{a8}</mo></mover>"));
}

/// Two runs of the same report give byte-identical files (no timings, no hash order).
#[test]
fn report_is_byte_identical_across_runs() {
    let a = out_dir("det-a");
    let b = out_dir("det-b");
    for dir in [&a, &b] {
        report_ok(Some("cart_pendulum,two_masses_rod"), dir);
    }
    // Every file under `root`, relative to it, sorted.
    let listing = |root: &std::path::Path| {
        let mut files = Vec::new();
        let mut stack = vec![root.to_path_buf()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).unwrap().flatten() {
                let p = e.path();
                if p.is_dir() {
                    stack.push(p);
                } else {
                    files.push(p.strip_prefix(root).unwrap().to_path_buf());
                }
            }
        }
        files.sort();
        files
    };
    let files = listing(&a);
    assert!(files.len() >= 8, "{files:?}");
    assert_eq!(files, listing(&b), "the runs wrote different files");
    for f in &files {
        let x = std::fs::read(a.join(f)).unwrap();
        let y = std::fs::read(b.join(f)).unwrap();
        assert!(x == y, "{} differs between runs", f.display());
    }
    let _ = std::fs::remove_dir_all(&a);
    let _ = std::fs::remove_dir_all(&b);
}

/// `simulate --plot-phase` and `--plot-energy` write SVG charts with labelled axes.
#[test]
fn simulate_draws_phase_portrait_and_energy_drift() {
    let dir = out_dir("simulate");
    std::fs::create_dir_all(&dir).unwrap();
    let phase = dir.join("phase.svg");
    let energy = dir.join("energy.svg");
    let out = eomgen(&[
        "simulate",
        "simple_pendulum",
        "--t-end",
        "2",
        "--plot-phase",
        phase.to_str().unwrap(),
        "--plot-energy",
        energy.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let phase = std::fs::read_to_string(&phase).expect("phase portrait written");
    assert!(phase.starts_with("<svg") && phase.contains("phase portrait"));
    assert!(phase.contains("q̇ (m/s or rad/s)") && phase.contains("q (m or rad)"));
    let energy = std::fs::read_to_string(&energy).expect("energy chart written");
    assert!(energy.contains("E − E(0) (J)") && energy.contains("t (s)"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every bundled model's report passes: the catalogue's reference values, conservation and
/// drift checks.
#[test]
fn full_report_passes_on_every_model() {
    let dir = out_dir("all");
    report_ok(None, &dir);
    let report = read_json(&dir);
    assert_eq!(
        report["summary"]["models"].as_u64().unwrap() as usize,
        eomgen::models::ALL.len()
    );
    assert_eq!(report["summary"]["failed"], 0);
    let _ = std::fs::remove_dir_all(&dir);
    every_golden_row_is_present_and_passes(&report);
}

/// The report's rows stay as they are: every `(model, check)` of
/// `tests/fixtures/report_checks.txt` (one `model<TAB>check` a line, sorted) is in the report
/// and passes. A new bundled model or check may add rows: they are printed so that they can be
/// added to the file (`EOMGEN_UPDATE_SCHEMAS=1` rewrites it from the report).
fn every_golden_row_is_present_and_passes(report: &serde_json::Value) {
    let mut rows: Vec<(String, bool)> = Vec::new();
    for model in report["models"].as_array().expect("models") {
        let name = model["name"].as_str().expect("name");
        for c in model["checks"].as_array().expect("checks") {
            let check = c["check"].as_str().expect("check");
            rows.push((format!("{name}\t{check}"), c["passed"] == true));
        }
    }
    rows.sort();
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/report_checks.txt"
    );
    if std::env::var_os("EOMGEN_UPDATE_SCHEMAS").is_some() {
        let text: String = rows.iter().map(|(r, _)| format!("{r}\n")).collect();
        std::fs::write(file, text).unwrap();
        return;
    }
    let golden = std::fs::read_to_string(file).expect("golden rows");
    let golden: Vec<&str> = golden.lines().filter(|l| !l.is_empty()).collect();
    let missing: Vec<&&str> = golden
        .iter()
        .filter(|g| !rows.iter().any(|(r, passed)| r == **g && *passed))
        .collect();
    let added: Vec<&String> = rows
        .iter()
        .map(|(r, _)| r)
        .filter(|r| !golden.contains(&r.as_str()))
        .collect();
    if !added.is_empty() {
        println!(
            "rows not in report_checks.txt (add them if intended):\n{}",
            added
                .iter()
                .map(|r| r.as_str())
                .collect::<Vec<_>>()
                .join("\n")
        );
    }
    assert!(
        missing.is_empty(),
        "{} of {} golden rows missing or failing:\n{}",
        missing.len(),
        golden.len(),
        missing.iter().map(|r| **r).collect::<Vec<_>>().join("\n")
    );
}

/// `report --models FILE` runs the file's own equations, compiled at run time, even when the
/// file is a copy of a bundled model (issue 18): a copy of `double_pendulum.yaml` with
/// `g: 1000` reports natural frequencies √100 = 10 times the bundled model's (ω ∝ √g), and
/// its `checks:`, whose reference values are expressions of `g`, pass.
#[test]
fn report_on_a_file_runs_the_files_own_equations() {
    let source = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/models/double_pendulum.yaml"
    ))
    .unwrap();
    assert!(source.contains("  g: 10.0"));
    let dir = out_dir("file-model");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("heavy_gravity.yaml");
    std::fs::write(&file, source.replace("  g: 10.0", "  g: 1000.0")).unwrap();
    let bundled = out_dir("file-model-bundled");
    report_ok(Some("double_pendulum"), &bundled);
    let copied = dir.join("report");
    report_ok(Some(file.to_str().unwrap()), &copied);
    let frequency = |dir: &Path| -> Vec<f64> {
        let report = read_json(dir);
        checks(&report, "double_pendulum")
            .iter()
            .filter(|c| {
                c["check"]
                    .as_str()
                    .unwrap_or_default()
                    .starts_with("natural_frequencies")
            })
            .map(|c| c["computed"].as_f64().expect("computed"))
            .collect()
    };
    let (slow, fast) = (frequency(&bundled), frequency(&copied));
    assert!(
        !slow.is_empty() && slow.len() == fast.len(),
        "{slow:?} {fast:?}"
    );
    for (s, f) in slow.iter().zip(&fast) {
        assert!(
            (f / s - 10.0).abs() < 1e-9,
            "ω ratio {} (bundled {s}, file {f})",
            f / s
        );
    }
    let report = read_json(&copied);
    assert!(
        checks(&report, "double_pendulum")
            .iter()
            .all(|c| c["passed"] == true),
        "{report}"
    );
}

/// The rows of the wrong-values file through the library the report calls
/// (`eomgen::checks`): the derivations agree; the natural frequency is the true
/// `√(m g d/(I + m d²)) = √15` (to 1e-12) against the stated 4, so it fails; `θ̇` is not
/// conserved; the energy is (DOP853 at 1e-12 keeps the drift below 1e-9).
#[test]
fn checks_of_a_file_through_the_library() {
    use eomgen::checks::{ModesAt, Simulations, derivation_checks, motion_checks};
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/report_wrong_values.yaml"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let file = eomgen_symbolic::model::load(path, &text).expect("loads");
    let (rows, _notes) = derivation_checks(&file).expect("derives");
    assert!(
        !rows.is_empty() && rows.iter().all(|r| r.passed),
        "{rows:?}"
    );
    let source = eomgen::ModelSource::open(path).expect("compiles");
    let mut model = source.instantiate();
    let y0 = model.consistent_initial_state().unwrap();
    let modes_model = source.instantiate();
    let mut modes = |at: Option<&str>| {
        assert_eq!(at, Some("hanging"));
        let eq = eomgen::find_equilibrium(modes_model.as_ref(), &[0.0], 0.0).unwrap();
        let lin = eomgen::linearize(modes_model.as_ref(), &eq.q, &[0.0], 0.0).unwrap();
        let modes = eomgen::normal_modes(&lin).unwrap();
        Ok(ModesAt {
            label: "hanging".to_string(),
            natural_frequencies: modes.natural_frequencies.clone(),
            linearization: lin,
        })
    };
    let mut simulations = Simulations::new(source);
    let rows = motion_checks(model.as_mut(), &y0, &mut simulations, &mut modes);
    let find = |prefix: &str| rows.iter().find(|r| r.check.starts_with(prefix)).unwrap();
    let w = find("natural_frequencies[1] at hanging");
    assert!(!w.passed);
    assert_eq!(w.expected, 4.0);
    assert!((w.computed.unwrap() - 15f64.sqrt()).abs() < 1e-12);
    let rate = find("conserved `rate`");
    assert!(!rate.passed && rate.computed.unwrap() > 0.1);
    let energy = find("energy drift");
    assert!(energy.passed && energy.computed.unwrap() < 1e-9);
    assert_eq!(rows.iter().filter(|r| !r.passed).count(), 2);
}

/// Issue 28: `report` printed only the names of the failed checks on the terminal (the
/// reasons were in report.json only). Each failed check is now printed with its reason: the
/// computed value against the expected one and the tolerance, or why it was not computed.
#[test]
fn issue_28_failed_checks_are_printed_with_their_reasons() {
    let dir = out_dir("reasons");
    let fixture = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/report_wrong_values.yaml"
    );
    let out = eomgen(&["report", "--models", fixture, "-o", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(
            "compound_pendulum: natural_frequencies[1] at hanging (rad/s): computed 3.87298334620741"
        ) && stderr.contains(
            ", expected 4, |difference| 1.270e-1 > tolerance 1e-9 × max(1, |expected|)"
        ),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 28: a `checks: period` longer than 10 s failed ("occurred 0 time(s) in 10 s")
/// unless the file gave an undocumented `t_end:`. Without `t_end:` the check now integrates
/// three expected periods: the 100 m pendulum of `tests/fixtures/long_period_pendulum.yaml`,
/// period 4 √(l/g) K(1/√2) = 23.452395… s, is measured over 70.357 s to the check's 1e-9.
#[test]
fn issue_28_a_long_period_is_integrated_long_enough() {
    let dir = out_dir("long-period");
    let fixture = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/long_period_pendulum.yaml"
    );
    report_ok(Some(fixture), &dir);
    let report = read_json(&dir);
    let rows = checks(&report, "long_period_pendulum");
    let period = row(rows, "period between the last two `return` events", "row");
    assert_eq!(period["passed"], true, "{period}");
    assert!(
        period["check"].as_str().unwrap().contains("70.357187 s"),
        "{period}"
    );
    let expected = 4.0 * 10f64.sqrt() * 1.8540746773013719;
    assert!((period["computed"].as_f64().unwrap() - expected).abs() < 1e-9 * expected);
    let _ = std::fs::remove_dir_all(&dir);
}
