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
use eomgen_symbolic::mechanics::cross_check::check_model;
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

/// A one-coordinate model — a unit mass at `(x, 0)`, so that momentum balance cross-checks
/// Lagrange — whose potential is `k*x^2/2` followed by `terms` more `+ x` (a tree of height
/// `terms + 3`), the same chain as a parameter's default and in `initial:`.
fn flat_model(terms: usize) -> String {
    let chain = " + x".repeat(terms);
    let constant = " + 1".repeat(terms);
    format!(
        "name: flat\ncoordinates: [x]\nparameters: {{ k: 1.0, c: 0{constant} }}\npoints: {{ P: [x, 0] }}\nbodies: {{ b: {{ mass: 1, at: P }} }}\npotential: k*x^2/2{chain}\ninitial: {{ x: 0{constant} }}\n"
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
            // The parameter's default (line 3), the potential (line 6) and `initial:` (line 7).
            let lines: Vec<u32> = diagnostics.iter().map(|d| d.location.line).collect();
            assert_eq!(lines, [3, 6, 7], "{diagnostics:?}");
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
            // Two angles per universal joint.
            let per = if *template == "universal-joint-chain" {
                2
            } else {
                1
            };
            assert_eq!(file.coordinates.len(), per * max);
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
    text.push_str("  k: 2.0  # N/m\npoints: { P: [x, 0] }\nbodies: { b: { mass: 1, at: P } }\npotential: k*x^2/2\ninitial: { x: 1 }\n");
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

/// A one-line list of coordinates is read in linear time: whether a coordinate is alone on
/// its line (so that a trailing comment describes it) was counted over the whole list for
/// each coordinate, and every name in an expression was looked up by a scan of the
/// coordinates, rates and parameters; both were quadratic (a list of 100,000 took 43 s in a
/// debug build). A list of `MAX_COORDINATES` loads, the coordinate alone on its line keeping
/// its comment and those on the shared line, which ends in a comment too, having none. A list
/// of 100,000 is refused by the limit on coordinates, as the one error of the file, at the
/// list: the whole file is still read and checked against the list, in about a second. `T`
/// is a sum of parenthesised groups, to stay below the parser's height limit.
#[test]
fn a_long_one_line_coordinate_list_is_read_in_linear_time() {
    use eomgen_symbolic::model::schema::MAX_COORDINATES;
    let source = |n: usize| {
        let names: Vec<String> = (0..n).map(|i| format!("q{i}")).collect();
        let groups: Vec<String> = names
            .chunks(500)
            .map(|g| {
                let terms: Vec<String> = g.iter().map(|q| format!("{q}_dot^2")).collect();
                format!("({})", terms.join(" + "))
            })
            .collect();
        format!(
            "name: wide\ncoordinates: [a,  # m, alone\n  {}]  # m, shared\nkinetic: a_dot^2/2 + ({})/2\npotential: a^2/2\n",
            names.join(", "),
            groups.join(" + ")
        )
    };
    let n = MAX_COORDINATES - 1;
    let file = load("wide.yaml", &source(n)).expect("loads");
    assert_eq!(file.coordinates.len(), n + 1);
    let comment = |i: usize| file.coordinates[i].comment.clone();
    assert_eq!(comment(0).as_deref(), Some("m, alone"));
    assert_eq!((comment(1), comment(n)), (None, None));

    let diagnostics = load("wide.yaml", &source(100_000)).expect_err("too many coordinates");
    assert_eq!(diagnostics.len(), 1, "{diagnostics:?}");
    assert_eq!(diagnostics[0].location.to_string(), "2:14");
    assert!(
        diagnostics[0]
            .message
            .starts_with("the model has 100001 generalized coordinates, more than the"),
        "{}",
        diagnostics[0].message
    );
}

/// An expression tree drawn at random: `ops` binary operations (`+ - * /`, and `^2` at
/// leaves) over `x`, `k` and small numbers, each operand a chain (left-deep, as written
/// without parentheses) or a parenthesised subtree, so that heights range from `log₂ ops` to
/// `ops`.
fn random_expression(rng: &mut impl rand::Rng, ops: usize) -> String {
    use rand::RngExt;
    fn leaf(rng: &mut impl rand::Rng) -> String {
        match rng.random_range(0..4) {
            0 => "x".to_string(),
            1 => "k".to_string(),
            2 => "x^2".to_string(),
            _ => format!("{}", rng.random_range(1..10)),
        }
    }
    fn build(rng: &mut impl rand::Rng, ops: usize, out: &mut String) {
        if ops == 0 {
            out.push_str(&leaf(rng));
            return;
        }
        let operator = ["+", "-", "*", "+"][rng.random_range(0..4)];
        if rng.random_bool(0.5) {
            // A chain: `ops` operations written one after the other.
            out.push_str(&leaf(rng));
            for _ in 0..ops {
                out.push_str(&format!(" {operator} {}", leaf(rng)));
            }
        } else {
            // A balanced split in parentheses.
            let left = (ops - 1) / 2;
            out.push('(');
            build(rng, left, out);
            out.push_str(&format!(") {operator} ("));
            build(rng, ops - 1 - left, out);
            out.push(')');
        }
    }
    let mut out = String::new();
    build(rng, ops, &mut out);
    out
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 24, .. Default::default() })]

    /// Random expressions of 1 to 10⁶ operations as a potential, on a 2 MiB stack: the file
    /// loads, or every diagnostic is located on the potential's line with a message; a file
    /// that loads with under 10⁴ operations also derives, cross-checked (the derivations of
    /// larger ones are left to the chain test above, for time).
    #[test]
    fn random_expressions_load_or_are_a_located_error(
        seed in proptest::prelude::any::<u64>(),
        log_ops in 0.0f64..6.0,
    ) {
        let ops = 10f64.powf(log_ops) as usize;
        let verdict = on_small_stack(move || {
            let mut rng = <rand::rngs::Xoshiro256PlusPlus as rand::SeedableRng>::seed_from_u64(seed);
            let expression = random_expression(&mut rng, ops);
            let source = format!(
                "name: random\ncoordinates: [x]\nparameters: {{ k: 2.0 }}\nkinetic: x_dot^2/2\npotential: {expression}\n"
            );
            match load("random.yaml", &source) {
                Ok(file) => {
                    if ops < 10_000 {
                        // A potential whose x-derivative is singular somewhere is a model
                        // error, not a crash: either way the call returns.
                        let _ = check_model(&file, 2, 1);
                    }
                    Ok(())
                }
                Err(diagnostics) => {
                    for d in &diagnostics {
                        if d.location.line != 5 || d.message.is_empty() {
                            return Err(format!("{d:?}"));
                        }
                    }
                    if diagnostics.is_empty() {
                        return Err("an error without a diagnostic".to_string());
                    }
                    Ok(())
                }
            }
        });
        proptest::prop_assert!(verdict.is_ok(), "{:?}", verdict);
    }
}
