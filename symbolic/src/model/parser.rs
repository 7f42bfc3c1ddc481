//! Expression text → [`Expr`], a hand-written recursive-descent parser.
//!
//! ```text
//! sum     := product (('+' | '-') product)*
//! product := unary (('*' | '/') unary)*
//! unary   := '-' unary | '+' unary | power
//! power   := atom ('^' unary)?          (right-associative; -x^2 = -(x^2); 2^-1 allowed)
//! atom    := number | name | name '(' sum (',' sum)* ')' | '(' sum ')'
//! ```

use super::ast::{BinOp, Expr, ExprKind, FUNCTIONS};
use super::diagnostic::Diagnostic;
use super::located::Location;

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(f64, String),
    Name(String),
    Op(char),
    End,
}

struct Lexer {
    toks: Vec<(Tok, usize)>,
}

fn lex(text: &str, start: Location) -> Result<Lexer, Diagnostic> {
    let chars: Vec<char> = text.chars().collect();
    let mut toks = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit()
            || (c == '.' && chars.get(i + 1).is_some_and(char::is_ascii_digit))
        {
            let s = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let lit: String = chars[s..i].iter().collect();
            match lit.parse::<f64>() {
                Ok(v) if v.is_finite() => toks.push((Tok::Num(v, lit), s)),
                _ => {
                    return Err(Diagnostic::new(
                        start.offset(s),
                        format!("`{lit}` is not a number"),
                    )
                    .with_help("write numbers like `2`, `0.5` or `1e-3`"));
                }
            }
        } else if c.is_ascii_alphabetic() || c == '_' {
            let s = i;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            toks.push((Tok::Name(chars[s..i].iter().collect()), s));
        } else if "+-*/^(),".contains(c) {
            toks.push((Tok::Op(c), i));
            i += 1;
        } else {
            let help = match c {
                '[' | ']' | '{' | '}' => "use `(` and `)` for grouping",
                '=' => "an expression has no `=`; write only its right-hand side",
                _ => "expressions use numbers, names, `+ - * / ^`, parentheses and functions",
            };
            return Err(Diagnostic::new(
                start.offset(i),
                format!("unexpected character `{c}` in an expression"),
            )
            .with_help(help));
        }
    }
    toks.push((Tok::End, chars.len()));
    Ok(Lexer { toks })
}

struct P<'a> {
    toks: &'a [(Tok, usize)],
    pos: usize,
    start: Location,
    depth: usize,
}

const MAX_DEPTH: usize = 200;

impl P<'_> {
    fn peek(&self) -> &Tok {
        &self.toks[self.pos].0
    }
    fn at(&self) -> Location {
        self.start.offset(self.toks[self.pos].1)
    }
    fn bump(&mut self) {
        if self.pos + 1 < self.toks.len() {
            self.pos += 1;
        }
    }
    fn describe(&self) -> String {
        match self.peek() {
            Tok::Num(_, s) | Tok::Name(s) => format!("`{s}`"),
            Tok::Op(c) => format!("`{c}`"),
            Tok::End => "the end of the expression".to_string(),
        }
    }

    fn enter(&mut self) -> Result<(), Diagnostic> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(Diagnostic::new(
                self.at(),
                "expression is nested too deeply",
            ));
        }
        Ok(())
    }

    fn sum(&mut self) -> Result<Expr, Diagnostic> {
        self.enter()?;
        let mut lhs = self.product()?;
        loop {
            let op = match self.peek() {
                Tok::Op('+') => BinOp::Add,
                Tok::Op('-') => BinOp::Sub,
                _ => break,
            };
            self.bump();
            let rhs = self.operand_after(op, Self::product)?;
            lhs = binary(op, lhs, rhs);
        }
        self.depth -= 1;
        Ok(lhs)
    }

    fn product(&mut self) -> Result<Expr, Diagnostic> {
        let mut lhs = self.unary()?;
        loop {
            let op = match self.peek() {
                Tok::Op('*') => BinOp::Mul,
                Tok::Op('/') => BinOp::Div,
                _ => break,
            };
            self.bump();
            let rhs = self.operand_after(op, Self::unary)?;
            lhs = binary(op, lhs, rhs);
        }
        Ok(lhs)
    }

    fn operand_after(
        &mut self,
        op: BinOp,
        f: fn(&mut Self) -> Result<Expr, Diagnostic>,
    ) -> Result<Expr, Diagnostic> {
        if matches!(
            self.peek(),
            Tok::End | Tok::Op(')') | Tok::Op(',') | Tok::Op('*') | Tok::Op('/') | Tok::Op('^')
        ) {
            let sym = match op {
                BinOp::Add => '+',
                BinOp::Sub => '-',
                BinOp::Mul => '*',
                BinOp::Div => '/',
                BinOp::Pow => '^',
            };
            return Err(Diagnostic::new(
                self.at(),
                format!(
                    "expected an operand after `{sym}`, found {}",
                    self.describe()
                ),
            ));
        }
        f(self)
    }

    fn unary(&mut self) -> Result<Expr, Diagnostic> {
        self.enter()?;
        let r = match self.peek() {
            Tok::Op('-') => {
                let loc = self.at();
                self.bump();
                let inner = self.unary()?;
                Ok(Expr {
                    kind: ExprKind::Neg(Box::new(inner)),
                    location: loc,
                })
            }
            Tok::Op('+') => {
                self.bump();
                self.unary()
            }
            _ => self.power(),
        };
        self.depth -= 1;
        r
    }

    fn power(&mut self) -> Result<Expr, Diagnostic> {
        let base = self.atom()?;
        if matches!(self.peek(), Tok::Op('^')) {
            self.bump();
            let exponent = self.operand_after(BinOp::Pow, Self::unary)?;
            return Ok(binary(BinOp::Pow, base, exponent));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Expr, Diagnostic> {
        let loc = self.at();
        match self.peek().clone() {
            Tok::Num(value, text) => {
                self.bump();
                Ok(Expr {
                    kind: ExprKind::Number { value, text },
                    location: loc,
                })
            }
            Tok::Name(name) => {
                self.bump();
                if matches!(self.peek(), Tok::Op('(')) {
                    let open = self.at();
                    self.bump();
                    let mut args = Vec::new();
                    if !matches!(self.peek(), Tok::Op(')')) {
                        loop {
                            args.push(self.sum()?);
                            match self.peek() {
                                Tok::Op(',') => self.bump(),
                                Tok::Op(')') => break,
                                _ => {
                                    return Err(Diagnostic::new(self.at(), format!("expected `,` or `)` in the arguments of `{name}`, found {}", self.describe()))
                                        .with_help(format!("the call opened at column {} is not closed", open.column)));
                                }
                            }
                        }
                    }
                    self.bump();
                    match FUNCTIONS.iter().find(|(f, _)| *f == name) {
                        None => {
                            let known: Vec<&str> = FUNCTIONS.iter().map(|(f, _)| *f).collect();
                            let mut d = Diagnostic::new(loc, format!("unknown function `{name}`"));
                            d = match closest(&name, &known) {
                                Some(c) => d.with_help(format!(
                                    "did you mean `{c}`? known functions: {}",
                                    known.join(", ")
                                )),
                                None => {
                                    d.with_help(format!("known functions: {}", known.join(", ")))
                                }
                            };
                            Err(d)
                        }
                        Some((_, arity)) if *arity != args.len() => Err(Diagnostic::new(
                            loc,
                            format!(
                                "`{name}` takes {arity} argument{}, found {}",
                                if *arity == 1 { "" } else { "s" },
                                args.len()
                            ),
                        )),
                        Some(_) => Ok(Expr {
                            kind: ExprKind::Call { func: name, args },
                            location: loc,
                        }),
                    }
                } else {
                    Ok(Expr {
                        kind: ExprKind::Ident(name),
                        location: loc,
                    })
                }
            }
            Tok::Op('(') => {
                self.bump();
                let inner = self.sum()?;
                if !matches!(self.peek(), Tok::Op(')')) {
                    return Err(Diagnostic::new(
                        self.at(),
                        format!("expected `)`, found {}", self.describe()),
                    )
                    .with_help(format!("unclosed `(` opened at column {}", loc.column)));
                }
                self.bump();
                Ok(inner)
            }
            Tok::Op(')') => {
                Err(Diagnostic::new(loc, "unexpected `)`").with_help("it closes no `(`"))
            }
            _ => Err(Diagnostic::new(
                loc,
                format!(
                    "expected a number, a name or `(`, found {}",
                    self.describe()
                ),
            )),
        }
    }
}

fn binary(op: BinOp, lhs: Expr, rhs: Expr) -> Expr {
    let location = lhs.location;
    Expr {
        kind: ExprKind::Binary {
            op,
            lhs: Box::new(lhs),
            rhs: Box::new(rhs),
        },
        location,
    }
}

/// The nearest candidate within edit distance 2 of `word` and closer than `word`'s own
/// length (so `k` does not suggest `m`), if any (for "did you mean").
pub fn closest<'a>(word: &str, candidates: &[&'a str]) -> Option<&'a str> {
    let len = word.chars().count();
    candidates
        .iter()
        .map(|c| (edit_distance(word, c), *c))
        .filter(|(d, _)| *d <= 2 && *d < len)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// Levenshtein distance in characters.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            cur[j] = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// Parses one expression whose first character is at `start`.
///
/// # Errors
/// A diagnostic at the exact column of the first problem, saying what was expected.
pub fn parse_expr(text: &str, start: Location) -> Result<Expr, Diagnostic> {
    let lexer = lex(text, start)?;
    let mut p = P {
        toks: &lexer.toks,
        pos: 0,
        start,
        depth: 0,
    };
    if matches!(p.peek(), Tok::End) {
        return Err(Diagnostic::new(start, "empty expression")
            .with_help("write a number or an expression such as `m*g*l`"));
    }
    let e = p.sum()?;
    if !matches!(p.peek(), Tok::End) {
        let help = if matches!(p.peek(), Tok::Op(')')) {
            "it closes no `(`".to_string()
        } else {
            "did you forget an operator such as `*`?".to_string()
        };
        return Err(Diagnostic::new(
            p.at(),
            format!("unexpected {} after a complete expression", p.describe()),
        )
        .with_help(help));
    }
    Ok(e)
}

/// Evaluates an expression with names resolved by `lookup` (`pi` is built in).
///
/// # Errors
/// A diagnostic at the first name `lookup` does not know.
pub fn eval_expr(e: &Expr, lookup: &dyn Fn(&str) -> Option<f64>) -> Result<f64, Diagnostic> {
    Ok(match &e.kind {
        ExprKind::Number { value, .. } => *value,
        ExprKind::Ident(n) if n == "pi" => std::f64::consts::PI,
        ExprKind::Ident(n) => {
            lookup(n).ok_or_else(|| Diagnostic::new(e.location, format!("unknown name `{n}`")))?
        }
        ExprKind::Neg(a) => -eval_expr(a, lookup)?,
        ExprKind::Binary { op, lhs, rhs } => {
            let (a, b) = (eval_expr(lhs, lookup)?, eval_expr(rhs, lookup)?);
            match op {
                BinOp::Add => a + b,
                BinOp::Sub => a - b,
                BinOp::Mul => a * b,
                BinOp::Div => a / b,
                BinOp::Pow => crate::expr::eval::pow(a, b),
            }
        }
        ExprKind::Call { func, args } => {
            let v: Vec<f64> = args
                .iter()
                .map(|a| eval_expr(a, lookup))
                .collect::<Result<_, _>>()?;
            match (func.as_str(), v.as_slice()) {
                ("sqrt", [x]) => x.sqrt(),
                ("atan2", [y, x]) => y.atan2(*x),
                (name, [x]) => match crate::expr::Func::from_name(name) {
                    Some(f) => f.apply(*x),
                    None => {
                        return Err(Diagnostic::new(
                            e.location,
                            format!("unknown function `{name}`"),
                        ));
                    }
                },
                (name, _) => {
                    return Err(Diagnostic::new(
                        e.location,
                        format!("unknown function `{name}`"),
                    ));
                }
            }
        }
    })
}

/// Every identifier in `e` (not function names), with its location, in order.
pub fn identifiers(e: &Expr, out: &mut Vec<(String, Location)>) {
    match &e.kind {
        ExprKind::Number { .. } => {}
        ExprKind::Ident(n) => out.push((n.clone(), e.location)),
        ExprKind::Neg(a) => identifiers(a, out),
        ExprKind::Binary { lhs, rhs, .. } => {
            identifiers(lhs, out);
            identifiers(rhs, out);
        }
        ExprKind::Call { args, .. } => args.iter().for_each(|a| identifiers(a, out)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn show(e: &Expr) -> String {
        match &e.kind {
            ExprKind::Number { text, .. } => text.clone(),
            ExprKind::Ident(n) => n.clone(),
            ExprKind::Neg(a) => format!("(-{})", show(a)),
            ExprKind::Binary { op, lhs, rhs } => {
                let o = match op {
                    BinOp::Add => "+",
                    BinOp::Sub => "-",
                    BinOp::Mul => "*",
                    BinOp::Div => "/",
                    BinOp::Pow => "^",
                };
                format!("({} {o} {})", show(lhs), show(rhs))
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
        assert_eq!(p("m*l^2*q_dot^2/2"), "(((m * (l ^ 2)) * (q_dot ^ 2)) / 2)");
        assert_eq!(p("atan2(y, x) + 1e-3"), "(atan2(y, x) + 1e-3)");
    }

    #[test]
    fn errors_point_at_the_column() {
        let e = err("m*");
        assert_eq!(
            e.location,
            Location {
                line: 3,
                column: 12
            }
        );
        assert!(e.message.contains("expected an operand after `*`"));
        let e = err("sinn(x)");
        assert_eq!(e.location.column, 10);
        assert!(e.help.unwrap().contains("did you mean `sin`"));
        assert!(err("atan2(x)").message.contains("takes 2 arguments"));
        let e = err("(a + b");
        assert!(e.message.contains("expected `)`"));
        assert_eq!(e.location.column, 16);
        assert!(err("a b").message.contains("unexpected `b`"));
        assert!(err("a)").message.contains("unexpected `)`"));
        assert!(err("x $ 2").message.contains("unexpected character `$`"));
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_stack_overflow() {
        let s = "(".repeat(10_000) + "x" + &")".repeat(10_000);
        assert!(err(&s).message.contains("nested too deeply"));
        let s = "-".repeat(10_000) + "x";
        assert!(err(&s).message.contains("nested too deeply"));
    }
}
