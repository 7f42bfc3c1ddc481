//! Expressions of any size either go through the whole pipeline or are a located error, on a
//! bounded stack (issue 20, item 1).
//!
//! A chain `a + b + c + …` parses to a left-deep tree as tall as it is long; every pass over
//! the tree (the load's checks, lowering, the derivations, code generation, dropping the
//! tree) must then fit on the smallest stack the pipeline runs on, a spawned thread's
//! default 2 MiB. The parser refuses a tree taller than `MAX_TREE_HEIGHT` at the operator
//! where it would become taller; below that, every pass must succeed. Each case runs on a
//! thread with exactly 2 MiB of stack, so a pass that recursed too deeply would abort the
//! test binary (a stack overflow is not a panic).

use eomgen_symbolic::codegen::{self, EmitOptions};
use eomgen_symbolic::mechanics::check::check_model;
use eomgen_symbolic::model::load;
use eomgen_symbolic::model::parser::MAX_TREE_HEIGHT;

/// Runs `f` on a thread with a 2 MiB stack.
fn on_small_stack<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(f)
        .expect("a thread")
        .join()
        .expect("no panic")
}

/// A one-coordinate model whose potential is `k*x^2/2` followed by `terms` more `+ x`
/// (a tree of height `terms + 3`), the same chain as a parameter's default and in `initial:`.
fn flat_model(terms: usize) -> String {
    let chain = " + x".repeat(terms);
    let constant = " + 1".repeat(terms);
    format!(
        "name: flat\ncoordinates: [x]\nparameters: {{ k: 1.0, c: 0{constant} }}\nkinetic: x_dot^2/2\npotential: k*x^2/2{chain}\ninitial: {{ x: 0{constant} }}\n"
    )
}

/// A chain a little below the limit goes through loading, the cross-checked derivations and
/// code generation, with the right value: the potential's derivative is `k x + terms`, so the
/// forcing at `x = 0` is `−terms`.
#[test]
fn a_chain_below_the_limit_goes_through_the_whole_pipeline() {
    let terms = MAX_TREE_HEIGHT - 10;
    on_small_stack(move || {
        let source = flat_model(terms);
        let file = load("flat.yaml", &source).expect("loads");
        let report = check_model(&file, 2, 1).expect("derives");
        assert!(report.passed(1e-9), "{report:?}");
        let code = codegen::generate(&file, &EmitOptions::default()).expect("generates");
        assert!(code.to_string().contains("fn mass_matrix_and_forcing"));
    });
}

/// Longer chains, up to 10⁶ operations, flat or inside parentheses, in every place an
/// expression goes: a located error at the operator where the tree would pass the limit.
#[test]
fn longer_chains_are_a_located_error() {
    for terms in [MAX_TREE_HEIGHT, 41_000, 1_000_000] {
        on_small_stack(move || {
            let source = flat_model(terms);
            let diagnostics = load("flat.yaml", &source).expect_err("too long");
            // The parameter's default (line 3), the potential (line 5) and `initial:` (line 6).
            let lines: Vec<u32> = diagnostics.iter().map(|d| d.location.line).collect();
            assert_eq!(lines, [3, 5, 6], "{diagnostics:?}");
            for d in &diagnostics {
                assert!(d.message.contains("too long"), "{}", d.message);
                assert!(d.location.column > 1000, "{d:?}");
            }
        });
    }
    // A chain nested in parentheses adds to the height of the chain around it.
    on_small_stack(|| {
        let half = " + x".repeat(MAX_TREE_HEIGHT / 2 + 10);
        let source = format!(
            "name: nested\ncoordinates: [x]\nkinetic: x_dot^2/2\npotential: (x{half}){half}\n"
        );
        let diagnostics = load("nested.yaml", &source).expect_err("too tall");
        assert_eq!(diagnostics.len(), 1, "{diagnostics:?}");
        assert_eq!(diagnostics[0].location.line, 4);
    });
}

/// `eomgen new` refuses sizes above its largest, and the largest files load: their longest
/// chains are below the parser's limit.
#[test]
fn the_largest_templates_load() {
    use eomgen_symbolic::model::templates::{MAX_SIZES, TEMPLATES, TemplateError, generate};
    for (template, max) in TEMPLATES.iter().zip(MAX_SIZES) {
        assert_eq!(
            generate(template, max + 1),
            Err(TemplateError::TooLarge {
                template: template.to_string(),
                n: max + 1,
                max
            })
        );
        assert_eq!(generate(template, 0), Err(TemplateError::Empty));
        on_small_stack(move || {
            let source = generate(template, max).unwrap();
            let file = load("p.yaml", &source).expect("loads");
            assert_eq!(file.coordinates.len(), max);
        });
    }
}

/// A file of 100,000 parameters (each with a unit comment) loads and is cross-checked, and
/// every parameter keeps its value and unit. Handling parameters was quadratic: the unit
/// comment and each expression's character locations were found by scanning the file from
/// its start, duplicate keys and names by scanning the earlier ones, and the checks' states
/// bound parameters by name: 10,000 parameters took 7.5 s and 30,000 over 60 s; this file
/// would take over ten minutes, where it now takes about a second (a debug build).
#[test]
fn a_hundred_thousand_parameters_load_in_linear_time() {
    const N: usize = 100_000;
    let mut text = String::from("name: many\ncoordinates: [x]\nparameters:\n");
    for i in 0..N {
        text.push_str(&format!("  p{i}: {}  # kg, number {i}\n", i + 1));
    }
    text.push_str("  k: 2.0  # N/m\nkinetic: x_dot^2/2\npotential: k*x^2/2\ninitial: { x: 1 }\n");
    let file = load("many.yaml", &text).expect("loads");
    assert_eq!(file.parameters.len(), N + 1);
    for i in [0, 1, N / 2, N - 1] {
        let p = &file.parameters[i];
        assert_eq!(p.name.value, format!("p{i}"));
        assert_eq!(p.value, (i + 1) as f64);
        assert_eq!(p.unit.as_ref().unwrap().value, format!("kg, number {i}"));
    }
    let report = check_model(&file, 20, 1).expect("checks");
    assert!(report.passed(1e-9), "{:?}", report.notes);
}
