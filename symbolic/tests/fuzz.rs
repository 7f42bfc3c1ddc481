//! Mutation fuzzing of the model loader and the expression parser (issue 8, item 4): the
//! corpus is every file in `models/`; each input is one of them with 1–8 random edits
//! (inserted YAML and expression tokens, deleted, duplicated, swapped or truncated spans,
//! replaced characters), loaded in full (YAML → schema → checks, every diagnostic rendered),
//! taken through the whole code generation of `eomgen::model!` when it loads
//! ([`codegen::generate`]: lowering, both derivations, the mass-matrix checks, the Jacobians,
//! the printer), each of its lines parsed as an expression and each comment as a unit. The
//! corpus declares `units: SI`, so the dimensional checks run too. A panic anywhere is a
//! failure, and so is generated code that is not a Rust file (the printer's own
//! [`GenerateError::Emit`], or tokens that `syn` does not parse as one); the count of inputs,
//! failures and how many still loaded is printed.
//!
//! Stable Rust has no coverage-guided fuzzer without extra tooling, so this is a seeded
//! mutation fuzzer (Xoshiro256++ from `rand`, deterministic for a seed). `cargo test` runs 3,000 inputs
//! (the generated code of the first 500 parsed by `syn`); the full run of 10⁶ is
//!
//! ```text
//! EOMGEN_FUZZ_CASES=1000000 cargo test --release -p eomgen-symbolic-tests --test suite -- fuzz:: --ignored --nocapture
//! ```

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::Mutex;

use eomgen_symbolic::codegen::{self, EmitOptions, GenerateError};
use eomgen_symbolic::model::{Location, load, parser::parse_expr, units::parse_unit};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

/// Tokens inserted by the mutator: YAML structure, expression syntax and names that occur
/// in the models, so that edits reach past the YAML layer.
const TOKENS: &[&str] = &[
    "",
    "[",
    "]",
    "{",
    "}",
    ":",
    ": ",
    "- ",
    "-",
    "*",
    "^",
    "(",
    ")",
    ",",
    "x",
    "theta1",
    "q",
    "0",
    "1e308",
    "-1",
    "0.0",
    "#",
    "\n",
    " ",
    "  ",
    "\t",
    "'",
    "\"",
    "&a ",
    "*a",
    "!!str ",
    "/0",
    "_dot",
    "_ddot",
    "sin(",
    "cos(",
    "atan2(",
    "sqrt(",
    "step(",
    "pi",
    "t",
    "m",
    "l",
    "g",
    "lambda_",
    "mass: ",
    "at: ",
    "between: ",
    "stiffness: ",
    "guess: ",
    "when: ",
    "direction: ",
    "rising",
    "terminal: true",
    "inertia: -1",
    "rest_length: ",
    "θ",
    "é",
    "\u{0}",
    "\r\n",
    "...",
    "---",
    "? ",
    "|",
    ">",
    "%",
    "@",
    "`",
    "~",
    "null",
    "true",
    "nan",
    "inf",
    "units: SI\n",
    "units: ",
    "  # N/m",
    "# kg*m^2, ",
    "^(1/",
    "^-",
    "/(",
    "²",
    "rad",
    "{ value: 1, unit: ",
    "{ name: x, unit: ",
];

/// Uniform in `0..n`; 0 when `n` is 0.
fn below(rng: &mut Xoshiro256PlusPlus, n: usize) -> usize {
    if n == 0 { 0 } else { rng.random_range(0..n) }
}

/// The nearest char boundary at or before `p`.
fn boundary(s: &str, mut p: usize) -> usize {
    p = p.min(s.len());
    while !s.is_char_boundary(p) {
        p -= 1;
    }
    p
}

/// One random edit of `src`.
fn mutate(src: &mut String, rng: &mut Xoshiro256PlusPlus) {
    let len = src.len();
    let a = boundary(src, below(rng, len + 1));
    let b = boundary(src, a + below(rng, 40));
    match below(rng, 7) {
        0 | 1 => src.insert_str(a, TOKENS[below(rng, TOKENS.len())]),
        2 => src.replace_range(a..b, ""),
        3 => {
            let span = src[a..b].to_string();
            src.insert_str(b, &span);
        }
        4 => {
            // Swap two lines.
            let mut lines: Vec<&str> = src.split('\n').collect();
            let (i, j) = (below(rng, lines.len()), below(rng, lines.len()));
            lines.swap(i, j);
            *src = lines.join("\n");
        }
        5 => {
            let c = char::from_u32(below(rng, 0x250) as u32).unwrap_or('?');
            src.replace_range(a..boundary(src, a + 1).max(a), &c.to_string());
        }
        _ => src.truncate(b),
    }
}

/// Runs `target` on one input; `Err` with the panic's message if it panicked, else what
/// `target` returned (whether the input loaded).
fn run_one(src: &str, target: fn(&str) -> bool) -> Result<bool, String> {
    catch_unwind(AssertUnwindSafe(|| target(src))).map_err(|payload| {
        payload
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()
    })
}

/// The code under test: the loader, code generation and the expression and unit parsers on
/// one input. Returns whether the input loaded; panics (a failure of the run) if the generated
/// code is not a Rust file.
fn load_everything(src: &str) -> bool {
    load_and_generate(src, true)
}

/// [`load_everything`] without `syn`'s parse of the generated code (the printer's own check
/// that it tokenizes stays). In the unoptimised test build that parse is most of the time
/// of an input that loads: 3,000 inputs took 16.7 s with it and 4.8 s without (2026-11-29).
fn load_without_parsing_the_code(src: &str) -> bool {
    load_and_generate(src, false)
}

fn load_and_generate(src: &str, parse_the_code: bool) -> bool {
    let loaded = match load("fuzz.yaml", src) {
        Ok(file) => {
            match codegen::generate(&file, &EmitOptions::default()) {
                Ok(tokens) => {
                    if parse_the_code && let Err(e) = syn::parse2::<syn::File>(tokens) {
                        panic!("generated code does not parse: {e}");
                    }
                }
                Err(GenerateError::Diagnostics(diagnostics)) => {
                    for d in &diagnostics {
                        let _ = d.render("fuzz.yaml", src);
                    }
                }
                Err(GenerateError::Emit(message)) => {
                    panic!("generated code does not tokenize: {message}")
                }
            }
            true
        }
        Err(diagnostics) => {
            for d in &diagnostics {
                let _ = d.render("fuzz.yaml", src);
            }
            false
        }
    };
    for line in src.lines() {
        let text = line.split_once(':').map_or(line, |(_, v)| v);
        let _ = parse_expr(text, Location { line: 1, column: 1 });
        if let Some((_, comment)) = line.split_once('#')
            && let Ok(d) = parse_unit(comment.trim())
        {
            let _ = d.to_string();
        }
    }
    loaded
}

/// Every model file of the project.
fn corpus() -> Vec<(String, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../models");
    let mut files: Vec<(String, String)> = std::fs::read_dir(&dir)
        .expect("models/ is readable")
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("a model file is readable");
            (p.display().to_string(), text)
        })
        .collect();
    files.sort();
    files
}

/// Held while a fuzzing run has replaced the panic hook (tests run in parallel threads).
static SILENCED: Mutex<()> = Mutex::new(());

/// Fuzzes `target` with `cases` inputs from `seed`; returns (inputs that still loaded,
/// panics with their inputs).
fn fuzz(cases: usize, seed: u64, target: fn(&str) -> bool) -> (usize, Vec<(String, String)>) {
    let corpus = corpus();
    assert!(corpus.len() >= 20, "the corpus is every file in models/");
    // The corpus itself loads (so mutations start from valid files).
    for (path, text) in &corpus {
        assert_eq!(run_one(text, target), Ok(true), "{path}");
    }
    // The panic hook is the process's, shared with every other test of the binary: one
    // fuzzing run at a time silences it, on its own thread only (another test's panic is
    // still reported by the previous hook).
    let _silenced = SILENCED.lock().unwrap_or_else(|e| e.into_inner());
    let previous = std::sync::Arc::new(std::panic::take_hook());
    let fuzzing = std::thread::current().id();
    {
        let previous = std::sync::Arc::clone(&previous);
        std::panic::set_hook(Box::new(move |info| {
            if std::thread::current().id() != fuzzing {
                previous(info);
            }
        }));
    }
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut loaded = 0;
    let mut panics = Vec::new();
    for _ in 0..cases {
        let mut src = corpus[below(&mut rng, corpus.len())].1.clone();
        for _ in 0..1 + below(&mut rng, 8) {
            mutate(&mut src, &mut rng);
        }
        match run_one(&src, target) {
            Ok(true) => loaded += 1,
            Ok(false) => {}
            Err(message) => panics.push((message, src)),
        }
    }
    // The hook set above holds the other reference; taking it back releases it.
    drop(std::panic::take_hook());
    match std::sync::Arc::try_unwrap(previous) {
        Ok(previous) => std::panic::set_hook(previous),
        Err(previous) => std::panic::set_hook(Box::new(move |info| previous(info))),
    }
    (loaded, panics)
}

fn report(cases: usize, loaded: usize, panics: &[(String, String)]) {
    println!(
        "fuzzed {cases} inputs: {} panics, {loaded} still loaded ({:.1} %)",
        panics.len(),
        100.0 * loaded as f64 / cases.max(1) as f64
    );
    if let Some((message, src)) = panics.first() {
        panic!("panic `{message}` on input:\n{src}");
    }
}

/// 3,000 inputs in every `cargo test`: no panic, and the mutations are not all fatal (some
/// inputs still load, so lowering is exercised too). The generated code of the first 500 of
/// them is also parsed as a Rust file ([`mutated_models_generate_rust_files`]); the full run
/// parses it for every input.
#[test]
fn mutated_models_never_panic() {
    let cases = 3000;
    let (loaded, panics) = fuzz(cases, SEED, load_without_parsing_the_code);
    report(cases, loaded, &panics);
    assert!(loaded > cases / 50, "only {loaded} of {cases} loaded");
}

/// The first 500 inputs of [`mutated_models_never_panic`] (the same seed), with the generated
/// code of each one that loads parsed by `syn` as a Rust file.
#[test]
fn mutated_models_generate_rust_files() {
    let cases = 500;
    let (loaded, panics) = fuzz(cases, SEED, load_everything);
    report(cases, loaded, &panics);
    assert!(loaded > cases / 50, "only {loaded} of {cases} loaded");
}

/// The seed of the inputs of every `cargo test`.
const SEED: u64 = 0x5eed_2026_1121;

/// The full run (`EOMGEN_FUZZ_CASES`, default 10⁶; see the module docs).
#[test]
#[ignore = "10⁶ inputs: run with --ignored in release"]
fn a_million_mutated_models_never_panic() {
    let cases = std::env::var("EOMGEN_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000);
    let seed = std::env::var("EOMGEN_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1);
    let start = std::time::Instant::now();
    let (loaded, panics) = fuzz(cases, seed, load_everything);
    println!("{:.1} s", start.elapsed().as_secs_f64());
    report(cases, loaded, &panics);
}

/// The harness can fail: a target that panics on some mutated inputs (those that gained a
/// NUL, one of the mutator's tokens and in no model file) is caught, its panic reported with
/// the input, and `report` fails.
#[test]
fn a_panicking_target_is_caught_and_reported() {
    // The target does no work of its own: what is tested is the harness, not the loader.
    fn panics_on_nul(src: &str) -> bool {
        assert!(!src.contains('\0'), "NUL in the input");
        true
    }
    let cases = 1000;
    let (_, panics) = fuzz(cases, 0x5eed_2026_1121, panics_on_nul);
    assert!(!panics.is_empty(), "no input of {cases} gained a NUL");
    for (message, src) in &panics {
        assert_eq!(message, "NUL in the input");
        assert!(src.contains('\0'));
    }
    let reported = catch_unwind(|| report(cases, 0, &panics));
    assert!(
        reported.is_err(),
        "report passed with {} panics",
        panics.len()
    );
}
