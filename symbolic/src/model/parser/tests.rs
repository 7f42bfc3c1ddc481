//! The unit tests of `parser.rs`.

use super::*;

fn show(e: &Expr) -> String {
    match &e.kind {
        ExprKind::Number { text, .. } => text.clone(),
        ExprKind::Ident(n) => n.clone(),
        ExprKind::Neg(a) => format!("(-{})", show(a)),
        ExprKind::Binary { op, lhs, rhs, .. } => {
            format!("({} {} {})", show(lhs), op.symbol(), show(rhs))
        }
        ExprKind::Call { func, args } => format!(
            "{func}({})",
            args.iter().map(show).collect::<Vec<_>>().join(", ")
        ),
    }
}
fn p(s: &str) -> String {
    show(&parse_expr(s, Location { line: 1, column: 1 }).unwrap())
}
fn err(s: &str) -> Diagnostic {
    parse_expr(
        s,
        Location {
            line: 3,
            column: 10,
        },
    )
    .unwrap_err()
}

#[test]
fn precedence_and_associativity() {
    assert_eq!(p("-x^2"), "(-(x ^ 2))");
    assert_eq!(p("a^b^c"), "(a ^ (b ^ c))");
    assert_eq!(p("a-b-c"), "((a - b) - c)");
    assert_eq!(p("a/b/c"), "((a / b) / c)");
    assert_eq!(p("2^-1"), "(2 ^ (-1))");
    assert_eq!(p("-2^-x^2"), "(-(2 ^ (-(x ^ 2))))");
    assert_eq!(p("m*l^2*q_dot^2/2"), "(((m * (l ^ 2)) * (q_dot ^ 2)) / 2)");
    assert_eq!(p("atan2(y, x) + 1e-3"), "(atan2(y, x) + 1e-3)");
    assert_eq!(p("+a - -b"), "(a - (-b))");
    assert_eq!(p("(a+b)*c"), "((a + b) * c)");
}

#[test]
fn yaml_numbers() {
    assert_eq!(p("1.0"), "1.0");
    assert_eq!(p("-2"), "(-2)");
    assert_eq!(p("+3"), "3");
    assert_eq!(p(".5"), ".5");
    assert_eq!(p("6.02E23"), "6.02E23");
    assert_eq!(p("1."), "1.");
    assert_eq!(p("0x1F"), "31");
    assert_eq!(p("0o17"), "15");
    assert!(err("1e400").message.contains("too large"));
    assert!(err(".inf").message.contains("unexpected `.`"));
    assert!(err("1.2.3").message.contains("`1.2.3` is not a number"));
}

#[test]
fn every_node_is_located_at_its_first_character() {
    let e = parse_expr("2*(a + b)", Location { line: 4, column: 5 }).unwrap();
    assert_eq!(e.location.column, 5);
    let ExprKind::Binary { rhs, .. } = &e.kind else {
        panic!()
    };
    assert_eq!(rhs.location.column, 7);
    let ExprKind::Binary { lhs, rhs: b, .. } = &rhs.kind else {
        panic!()
    };
    assert_eq!((lhs.location.column, b.location.column), (8, 12));
    let mut ids = Vec::new();
    identifiers(&e, &mut ids);
    let cols: Vec<u32> = ids.iter().map(|(_, l)| l.column).collect();
    assert_eq!(cols, [8, 12]);
}

#[test]
fn errors_point_at_the_column() {
    let at = |d: &Diagnostic| (d.location.line, d.location.column);
    let e = err("m*");
    assert_eq!(at(&e), (3, 12));
    assert!(e.message.contains("expected an operand after `*`"));
    let e = err("sinn(x)");
    assert_eq!(at(&e), (3, 10));
    assert!(e.message.contains("unknown function `sinn`"));
    assert!(e.help.unwrap().contains("did you mean `sin`"));
    let e = err("1 + atan2(x)");
    assert_eq!(at(&e), (3, 14));
    assert!(e.message.contains("`atan2` takes 2 arguments, found 1"));
    let e = err("(a + b");
    assert_eq!(at(&e), (3, 16));
    assert!(e.message.contains("unclosed `(` opened at 3:10"));
    let e = err("sin(a");
    assert!(e.message.contains("unclosed `(` of `sin` opened at 3:13"));
    assert!(err("a b").message.contains("unexpected `b`"));
    let e = err("a)");
    assert_eq!(at(&e), (3, 11));
    assert!(e.message.contains("unexpected `)`"));
    assert!(err(")").message.contains("unexpected `)`"));
    let e = err("x $ 2");
    assert_eq!(at(&e), (3, 12));
    assert!(e.message.contains("unexpected character `$`"));
    assert!(err("x ** 2").help.unwrap().contains("`^`"));
    assert!(err("sin").message.contains("is a function"));
    assert!(err("()").message.contains("empty parentheses"));
    assert!(err("atan2(x,)").message.contains("expected an argument"));
    assert!(err("m(x+1)").help.unwrap().contains("`m*(…)`"));
    assert!(err("   ").message.contains("empty expression"));
    assert!(err("a, b").message.contains("unexpected `,`"));
    assert!(err("θ").help.unwrap().contains("theta"));
    assert!(err("x − 1").help.unwrap().contains("ASCII minus"));
    assert!(err("-").message.contains("expected an operand after `-`"));
}

#[test]
fn mapped_locations_are_used() {
    let locate = |i: usize| Location {
        line: 10 + i as u32,
        column: 1,
    };
    let e = parse_expr_mapped("a +", &locate).unwrap_err();
    assert_eq!(e.location.line, 13);
}

#[test]
fn deep_nesting_is_an_error_not_a_stack_overflow() {
    let s = "(".repeat(10_000) + "x" + &")".repeat(10_000);
    assert!(err(&s).message.contains("nested too deeply"));
    let s = "-".repeat(10_000) + "x";
    assert!(err(&s).message.contains("nested too deeply"));
    let s = "x^".repeat(10_000) + "x";
    assert!(err(&s).message.contains("nested too deeply"));
    let s = "sin(".repeat(10_000);
    assert!(err(&s).message.contains("nested too deeply"));
    // Moderate nesting is fine.
    let s = "(".repeat(50) + "x" + &")".repeat(50);
    assert_eq!(p(&s), "x");
}

#[test]
fn evaluation() {
    let e = parse_expr("2*pi - sqrt(4) + atan2(0, 1) + a^2", Location::default()).unwrap();
    let v = eval_expr(&e, &|n| (n == "a").then_some(3.0)).unwrap();
    assert!((v - (2.0 * std::f64::consts::PI - 2.0 + 9.0)).abs() < 1e-12);
    let e = parse_expr("b", Location::default()).unwrap();
    assert!(eval_expr(&e, &|_| None).is_err());
}

/// `log` is the natural logarithm's other name: the help says `ln`, not the nearest
/// spelling (`cos`).
#[test]
fn other_names_of_functions() {
    let e = err("log(x)");
    assert!(
        e.help.as_deref().unwrap().starts_with("did you mean `ln`"),
        "{e:?}"
    );
    let e = err("arctan(x)");
    assert!(
        e.help
            .as_deref()
            .unwrap()
            .starts_with("did you mean `atan`"),
        "{e:?}"
    );
}

#[test]
fn did_you_mean() {
    assert_eq!(closest("mas", &["mass", "at"]), Some("mass"));
    assert_eq!(closest("k", &["m"]), None);
    assert_eq!(edit_distance("kitten", "sitting"), 3);
}
