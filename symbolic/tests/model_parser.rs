//! The expression parser through its public API: precedence, locations, errors, and never a
//! panic.

use eomgen_symbolic::model::parser::{parse_expr, parse_expr_mapped};
use eomgen_symbolic::model::{BinOp, Expr, ExprKind, Location};
use proptest::prelude::*;

fn show(e: &Expr) -> String {
    match &e.kind {
        ExprKind::Number { text, .. } => text.clone(),
        ExprKind::Ident(n) => n.clone(),
        ExprKind::Neg(a) => format!("(-{})", show(a)),
        ExprKind::Binary { op, lhs, rhs, .. } => {
            let op = match op {
                BinOp::Add => "+",
                BinOp::Sub => "-",
                BinOp::Mul => "*",
                BinOp::Div => "/",
                BinOp::Pow => "^",
            };
            format!("({} {op} {})", show(lhs), show(rhs))
        }
        ExprKind::Call { func, args } => format!(
            "{func}({})",
            args.iter().map(show).collect::<Vec<_>>().join(", ")
        ),
    }
}

fn p(s: &str) -> String {
    show(&parse_expr(s, Location { line: 1, column: 1 }).expect("parses"))
}

#[test]
fn unary_minus_binds_looser_than_power() {
    assert_eq!(p("-x^2"), "(-(x ^ 2))");
    assert_eq!(p("-2^2"), "(-(2 ^ 2))");
    assert_eq!(p("(-x)^2"), "((-x) ^ 2)");
}

#[test]
fn power_is_right_associative_and_takes_a_signed_exponent() {
    assert_eq!(p("a^b^c"), "(a ^ (b ^ c))");
    assert_eq!(p("2^-1"), "(2 ^ (-1))");
    assert_eq!(p("x^-y^2"), "(x ^ (-(y ^ 2)))");
}

#[test]
fn subtraction_and_division_are_left_associative() {
    assert_eq!(p("a-b-c"), "((a - b) - c)");
    assert_eq!(p("a/b/c"), "((a / b) / c)");
    assert_eq!(p("a/b*c"), "((a / b) * c)");
    assert_eq!(p("a - b + c"), "((a - b) + c)");
}

#[test]
fn products_bind_tighter_than_sums() {
    assert_eq!(p("a + b*c"), "(a + (b * c))");
    assert_eq!(p("a*b + c/d - e^f"), "(((a * b) + (c / d)) - (e ^ f))");
    assert_eq!(p("-a*b"), "((-a) * b)");
}

#[test]
fn functions_numbers_and_names() {
    assert_eq!(
        p("m*l^2*theta_dot^2/2 - m*g*l*cos(theta)"),
        "((((m * (l ^ 2)) * (theta_dot ^ 2)) / 2) - (((m * g) * l) * cos(theta)))"
    );
    assert_eq!(p("atan2(y, x)"), "atan2(y, x)");
    assert_eq!(
        p("1e-3 + 2.5E+2 + .5 + 10"),
        "(((1e-3 + 2.5E+2) + .5) + 10)"
    );
    assert_eq!(p("_x1"), "_x1");
    assert_eq!(
        p("sqrt(abs(sign(step(t - 1))))"),
        "sqrt(abs(sign(step((t - 1)))))"
    );
}

#[test]
fn locations_are_the_first_character_of_each_node() {
    let e = parse_expr(
        "a + sin(bb)",
        Location {
            line: 7,
            column: 12,
        },
    )
    .expect("parses");
    let ExprKind::Binary { lhs, rhs, .. } = &e.kind else {
        panic!("a sum")
    };
    assert_eq!(
        e.location,
        Location {
            line: 7,
            column: 12
        }
    );
    assert_eq!(lhs.location.column, 12);
    assert_eq!(rhs.location.column, 16);
    let ExprKind::Call { args, .. } = &rhs.kind else {
        panic!("a call")
    };
    assert_eq!(args[0].location.column, 20);
}

#[test]
fn errors_name_what_was_expected_at_the_exact_column() {
    let err = |s: &str| parse_expr(s, Location { line: 2, column: 5 }).expect_err("an error");
    let cases = [
        ("m*", 7, "expected an operand after `*`"),
        ("(a + b", 11, "unclosed `(` opened at 2:5"),
        ("a + b)", 10, "unexpected `)`"),
        ("coss(x)", 5, "unknown function `coss`"),
        ("atan2(x)", 5, "`atan2` takes 2 arguments, found 1"),
        ("sin(x, y)", 5, "`sin` takes 1 argument, found 2"),
        ("2 x", 7, "unexpected `x` after a complete expression"),
        ("x @ y", 7, "unexpected character `@`"),
        ("", 5, "empty expression"),
    ];
    for (text, column, message) in cases {
        let d = err(text);
        assert_eq!(
            (d.location.line, d.location.column),
            (2, column),
            "{text}: {d:?}"
        );
        assert!(d.message.contains(message), "{text}: {d:?}");
    }
    assert!(
        err("coss(x)")
            .help
            .is_some_and(|h| h.contains("did you mean `cos`?"))
    );
}

#[test]
fn a_location_map_places_errors_on_later_lines() {
    // `a +` folded from "a\n  +": the `+` is on the next line.
    let locations = [
        Location { line: 1, column: 4 },
        Location { line: 1, column: 5 },
        Location { line: 2, column: 3 },
        Location { line: 2, column: 4 },
    ];
    let d = parse_expr_mapped("a +", &|i| locations[i.min(3)]).expect_err("an error");
    assert_eq!(d.location, Location { line: 2, column: 4 });
}

/// An expression printed in the file's syntax parses back to the same tree, with no more
/// parentheses than the grammar needs: the model description keeps the file's `checks:` and
/// `floquet:` expressions as this text.
#[test]
fn printed_expressions_parse_back_with_few_parentheses() {
    let printed = |s: &str| {
        parse_expr(s, Location { line: 1, column: 1 })
            .unwrap()
            .to_string()
    };
    for (text, expected) in [
        ("2*pi*sqrt(l/g)", "2*pi*sqrt(l/g)"),
        ("a - (b - c)", "a - (b - c)"),
        ("(a - b) - c", "a - b - c"),
        ("a/(b*c)", "a/(b*c)"),
        ("-x^2", "-x^2"),
        ("(-x)^2", "(-x)^2"),
        ("a*-b", "a*(-b)"),
        ("2^-1", "2^(-1)"),
        ("a^b^c", "a^b^c"),
        ("(a^b)^c", "(a^b)^c"),
        ("--x", "-(-x)"),
        ("-a*b + atan2(-1, 0)", "-a*b + atan2(-1, 0)"),
        ("1e-3*x_dot", "1e-3*x_dot"),
    ] {
        let out = printed(text);
        assert_eq!(out, expected, "{text}");
        assert_eq!(p(&out), p(text), "{text} → {out}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, .. ProptestConfig::default() })]

    /// Whatever parses, printed, parses back to the same tree.
    #[test]
    fn printed_expressions_round_trip(text in "([a-z]{1,3}|[0-9]{1,3}(\\.[0-9])?(e-?[0-9])?|[-+*/^(),]| |sin\\(|atan2\\(|_dot){0,40}") {
        if let Ok(e) = parse_expr(&text, Location { line: 1, column: 1 }) {
            let out = e.to_string();
            let back = parse_expr(&out, Location { line: 1, column: 1 });
            prop_assert!(back.is_ok(), "{} printed as {} does not parse: {:?}", text, out, back);
            prop_assert_eq!(show(&back.unwrap()), show(&e), "{} printed as {}", text, out);
        }
    }

    /// Arbitrary text never panics the parser, and an error is located on the line.
    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,200}") {
        if let Err(d) = parse_expr(&text, Location { line: 3, column: 4 }) {
            prop_assert_eq!(d.location.line, 3);
            prop_assert!(d.location.column >= 4);
        }
    }

    /// Expression-like text never panics the parser; what parses has every node located
    /// within the text.
    #[test]
    fn expression_like_text_never_panics(text in "([a-z]{1,3}|[0-9]{1,3}(\\.[0-9])?(e-?[0-9])?|[-+*/^(),]| |sin\\(|atan2\\(|_dot){0,40}") {
        let start = Location { line: 1, column: 1 };
        if let Ok(e) = parse_expr(&text, start) {
            fn walk(e: &Expr, len: u32) -> bool {
                let here = e.location.column >= 1 && e.location.column <= len;
                here && match &e.kind {
                    ExprKind::Number { .. } | ExprKind::Ident(_) => true,
                    ExprKind::Neg(a) => walk(a, len),
                    ExprKind::Binary { lhs, rhs, .. } => walk(lhs, len) && walk(rhs, len),
                    ExprKind::Call { args, .. } => args.iter().all(|a| walk(a, len)),
                }
            }
            prop_assert!(walk(&e, text.chars().count() as u32));
        }
    }
}
