//! Expression text → [`Expr`], a hand-written recursive-descent parser.
//!
//! ```text
//! sum     := product (('+' | '-') product)*
//! product := unary (('*' | '/') unary)*
//! unary   := '-' unary | '+' unary | power
//! power   := atom ('^' unary)?          (right-associative; -x^2 = -(x^2); 2^-1 allowed)
//! atom    := number | name | function '(' sum (',' sum)* ')' | '(' sum ')'
//! number  := digits ('.' digits?)? (('e' | 'E') ('+' | '-')? digits)?  |  '.' digits …
//!          | '0x' hex digits | '0o' octal digits                        (YAML 1.2 numbers)
//! name    := [A-Za-z_][A-Za-z0-9_]*
//! ```
//!
//! Every node's location is the location of its first character (for a parenthesised
//! expression, its `(`). Errors point at the exact column of the problem and say what was
//! expected there.

use super::ast::{BinOp, Expr, ExprKind, FUNCTIONS, VECTOR_FUNCTIONS};
use super::diagnostic::Diagnostic;
use super::located::Location;
use crate::expr::{Constant, FoldError, Func, fold};

/// Parses one expression whose first character is at `start`; the expression is on one
/// line, so character `i` of `text` is at column `start.column + i`.
///
/// # Errors
/// A diagnostic at the exact column of the first problem, saying what was expected.
pub fn parse_expr(text: &str, start: Location) -> Result<Expr, Diagnostic> {
    parse_expr_mapped(text, &|i| start.offset(i))
}

/// Parses one expression, with `locate(i)` giving the file location of character `i` of
/// `text` (and `locate(text.chars().count())` the location just after it). Used for YAML
/// scalars that span several lines.
///
/// # Errors
/// As [`parse_expr`].
pub fn parse_expr_mapped(
    text: &str,
    locate: &dyn Fn(usize) -> Location,
) -> Result<Expr, Diagnostic> {
    let toks = lex(text, locate)?;
    let mut p = P {
        toks: &toks,
        pos: 0,
        locate,
        depth: 0,
    };
    if matches!(p.peek(), Tok::End) {
        return Err(Diagnostic::new(locate(0), "empty expression")
            .with_help("write a number or an expression such as `m*g*l`"));
    }
    let (e, _) = p.sum()?;
    match p.peek() {
        Tok::End => Ok(e),
        Tok::Op(')') => Err(Diagnostic::new(p.at(), "unexpected `)`: it closes no `(`")
            .with_help("remove it, or add the `(` it should close")),
        Tok::Op(',') => Err(
            Diagnostic::new(p.at(), "unexpected `,` after a complete expression")
                .with_help("a `,` separates the arguments of a function such as `atan2(y, x)`"),
        ),
        Tok::Num(..) | Tok::Name(_) | Tok::Op('(') => Err(Diagnostic::new(
            p.at(),
            format!("unexpected {} after a complete expression", p.describe()),
        )
        .with_help("did you forget an operator? products are written with `*`, as in `2*x`")),
        _ => Err(Diagnostic::new(
            p.at(),
            format!("unexpected {} after a complete expression", p.describe()),
        )),
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(f64, String),
    Name(String),
    Op(char),
    End,
}

/// Help for a character that cannot appear in an expression.
fn help_for_character(c: char) -> String {
    match c {
        '[' | ']' | '{' | '}' => "use `(` and `)` for grouping".to_string(),
        '=' => "an expression has no `=`; write only its right-hand side".to_string(),
        '−' | '–' => "this is a typographic dash; type the ASCII minus `-`".to_string(),
        '×' | '·' | '⋅' => "write products with `*`".to_string(),
        '÷' => "write quotients with `/`".to_string(),
        '²' => "write powers with `^`, as in `x^2`".to_string(),
        '³' => "write powers with `^`, as in `x^3`".to_string(),
        'π' => "write `pi`".to_string(),
        c if c.is_alphabetic() => {
            "names use ASCII letters, digits and `_`: write `theta` for θ".to_string()
        }
        _ => "expressions use numbers, names, `+ - * / ^`, parentheses and functions".to_string(),
    }
}

fn lex(text: &str, locate: &dyn Fn(usize) -> Location) -> Result<Vec<(Tok, usize)>, Diagnostic> {
    let chars: Vec<char> = text.chars().collect();
    let mut toks = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        if c.is_whitespace() {
            i += 1;
        } else if c == '0' && matches!(next, Some('x' | 'o')) {
            // YAML 1.2 hexadecimal and octal integers.
            let s = i;
            let radix = if next == Some('x') { 16 } else { 8 };
            i += 2;
            while i < chars.len() && chars[i].is_ascii_alphanumeric() {
                i += 1;
            }
            let lit: String = chars[s..i].iter().collect();
            match u64::from_str_radix(&lit[2..], radix) {
                Ok(v) => toks.push((Tok::Num(v as f64, v.to_string()), s)),
                Err(_) => {
                    return Err(
                        Diagnostic::new(locate(s), format!("`{lit}` is not a number"))
                            .with_help("write numbers like `2`, `0.5`, `1e-3` or `0x1F`"),
                    );
                }
            }
        } else if c.is_ascii_digit() || (c == '.' && next.is_some_and(|d| d.is_ascii_digit())) {
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
            // A literal with a non-zero digit that reads as 0 or subnormal (`1e-400`) is
            // refused by the rule of folding, as a product that underflows is.
            let zero = lit
                .split(['e', 'E'])
                .next()
                .is_some_and(|m| m.chars().all(|c| matches!(c, '0' | '.')));
            match lit.parse::<f64>() {
                Ok(v) if v.is_finite() && fold(v, zero).is_err() => {
                    return Err(Diagnostic::new(
                        locate(s),
                        format!("the number `{lit}` is too small: {}", FoldError::Underflow),
                    )
                    .with_help("write 0 if 0 is meant; rescale the units if the value is real"));
                }
                Ok(v) if v.is_finite() => toks.push((Tok::Num(v, lit), s)),
                Ok(_) => {
                    return Err(Diagnostic::new(
                        locate(s),
                        format!("the number `{lit}` is too large"),
                    )
                    .with_help("numbers must be finite 64-bit floating-point values"));
                }
                Err(_) => {
                    return Err(
                        Diagnostic::new(locate(s), format!("`{lit}` is not a number"))
                            .with_help("write numbers like `2`, `0.5` or `1e-3`"),
                    );
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
        } else if c == '.' && next.is_some_and(|d| d.is_ascii_alphabetic()) {
            return Err(Diagnostic::new(
                locate(i),
                "unexpected `.` in an expression",
            )
            .with_help("infinite values (`.inf`) and `.nan` are not allowed; decimals are written `0.5`"));
        } else {
            return Err(Diagnostic::new(
                locate(i),
                format!("unexpected character `{c}` in an expression"),
            )
            .with_help(help_for_character(c)));
        }
    }
    toks.push((Tok::End, chars.len()));
    Ok(toks)
}

struct P<'a> {
    toks: &'a [(Tok, usize)],
    pos: usize,
    locate: &'a dyn Fn(usize) -> Location,
    depth: usize,
}

/// Nesting limit (parentheses, unary signs, powers), so that no input overflows the stack.
const MAX_DEPTH: usize = 100;

/// Height limit of an expression's tree. A chain `a + b + c + …` is a left-deep tree as tall
/// as it is long, and the passes over the tree (the load's evaluation and unit checks,
/// lowering, dropping it) recurse along it, so an expression of any length must not make a
/// tree that outgrows the stack. The deepest pass takes ~240 bytes a level (evaluation
/// overflowed a 2 MiB stack at ~8,600 levels), so 2,000 levels take about a quarter of the
/// smallest stack the pipeline runs on (2 MiB, a spawned thread's default), leaving the rest
/// to the caller. Two thousand operations in one chain are beyond any hand-written model, and
/// `eomgen new` keeps its chains shorter; the limit is a located error, not a crash.
pub const MAX_TREE_HEIGHT: usize = 2_000;

/// A parsed sub-expression and the height of its tree (1 for a leaf).
type Parsed = Result<(Expr, usize), Diagnostic>;

/// `lhs op rhs`, with its height; an error at `at` (the operator) when it would be taller
/// than [`MAX_TREE_HEIGHT`].
fn binary(op: BinOp, (lhs, lh): (Expr, usize), (rhs, rh): (Expr, usize), at: Location) -> Parsed {
    let height = 1 + lh.max(rh);
    if height > MAX_TREE_HEIGHT {
        return Err(Diagnostic::new(
            at,
            format!(
                "expression is too long: its operations chain more than {MAX_TREE_HEIGHT} deep here"
            ),
        )
        .with_help(
            "spread a long sum over several entries (springs, dampers, forces, points), or shorten it",
        ));
    }
    let location = lhs.location;
    Ok((
        Expr {
            kind: ExprKind::Binary {
                op,
                lhs: Box::new(lhs),
                rhs: Box::new(rhs),
                op_location: at,
            },
            location,
        },
        height,
    ))
}

impl P<'_> {
    fn peek(&self) -> &Tok {
        self.toks.get(self.pos).map_or(&Tok::End, |t| &t.0)
    }

    fn at(&self) -> Location {
        let i = self.toks.get(self.pos).map_or(0, |t| t.1);
        (self.locate)(i)
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

    /// Runs `f` one nesting level deeper.
    fn nested(&mut self, f: fn(&mut Self) -> Parsed) -> Parsed {
        if self.depth >= MAX_DEPTH {
            return Err(
                Diagnostic::new(self.at(), "expression is nested too deeply").with_help(
                    "split it with parameters, or remove redundant parentheses and signs",
                ),
            );
        }
        self.depth += 1;
        let r = f(self);
        self.depth -= 1;
        r
    }

    fn sum(&mut self) -> Parsed {
        let mut lhs = self.product()?;
        loop {
            let op = match self.peek() {
                Tok::Op('+') => BinOp::Add,
                Tok::Op('-') => BinOp::Sub,
                _ => break,
            };
            let at = self.at();
            self.bump();
            let rhs = self.operand_after(op, Self::product)?;
            lhs = binary(op, lhs, rhs, at)?;
        }
        Ok(lhs)
    }

    fn product(&mut self) -> Parsed {
        let mut lhs = self.unary()?;
        loop {
            let op = match self.peek() {
                Tok::Op('*') => BinOp::Mul,
                Tok::Op('/') => BinOp::Div,
                _ => break,
            };
            let at = self.at();
            self.bump();
            let rhs = self.operand_after(op, Self::unary)?;
            lhs = binary(op, lhs, rhs, at)?;
        }
        Ok(lhs)
    }

    /// The right operand of `op`, with a clear error when there is none.
    fn operand_after(&mut self, op: BinOp, f: fn(&mut Self) -> Parsed) -> Parsed {
        if matches!(self.peek(), Tok::End | Tok::Op(')' | ',' | '*' | '/' | '^')) {
            let d = Diagnostic::new(
                self.at(),
                format!(
                    "expected an operand after `{}`, found {}",
                    op.symbol(),
                    self.describe()
                ),
            );
            return Err(match (op, self.peek()) {
                (BinOp::Mul, Tok::Op('*')) => {
                    d.with_help("powers are written with `^`, as in `x^2`")
                }
                _ => d.with_help(format!(
                    "write a number, a name or a parenthesised expression after `{}`",
                    op.symbol()
                )),
            });
        }
        f(self)
    }

    fn unary(&mut self) -> Parsed {
        match self.peek() {
            Tok::Op('-') => {
                let loc = self.at();
                self.bump();
                let (inner, height) = self.operand_after(BinOp::Sub, |p| p.nested(Self::unary))?;
                Ok((
                    Expr {
                        kind: ExprKind::Neg(Box::new(inner)),
                        location: loc,
                    },
                    height + 1,
                ))
            }
            Tok::Op('+') => {
                self.bump();
                self.operand_after(BinOp::Add, |p| p.nested(Self::unary))
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Parsed {
        let base = self.atom()?;
        if matches!(self.peek(), Tok::Op('^')) {
            let at = self.at();
            self.bump();
            let exponent = self.operand_after(BinOp::Pow, |p| p.nested(Self::unary))?;
            return binary(BinOp::Pow, base, exponent, at);
        }
        Ok(base)
    }

    fn atom(&mut self) -> Parsed {
        let loc = self.at();
        match self.peek().clone() {
            Tok::Num(value, text) => {
                self.bump();
                Ok((
                    Expr {
                        kind: ExprKind::Number { value, text },
                        location: loc,
                    },
                    1,
                ))
            }
            Tok::Name(name) => {
                self.bump();
                let function = FUNCTIONS.iter().find(|(f, _)| *f == name);
                if matches!(self.peek(), Tok::Op('(')) {
                    let callable =
                        function.or_else(|| VECTOR_FUNCTIONS.iter().find(|(f, _)| *f == name));
                    let Some(&(_, arity)) = callable else {
                        return Err(unknown_function(&name, loc));
                    };
                    self.call(name, arity, loc)
                } else if function.is_some() {
                    Err(Diagnostic::new(
                        loc,
                        format!("`{name}` is a function; its argument goes in parentheses"),
                    )
                    .with_help(format!("write `{name}(x)`")))
                } else {
                    Ok((
                        Expr {
                            kind: ExprKind::Ident(name),
                            location: loc,
                        },
                        1,
                    ))
                }
            }
            Tok::Op('(') => {
                self.bump();
                if matches!(self.peek(), Tok::Op(')')) {
                    return Err(Diagnostic::new(loc, "empty parentheses `()`")
                        .with_help("write an expression between `(` and `)`"));
                }
                let (mut inner, height) = self.nested(Self::sum)?;
                match self.peek() {
                    Tok::Op(')') => {}
                    Tok::End => {
                        return Err(Diagnostic::new(
                            self.at(),
                            format!(
                                "unclosed `(` opened at {loc}: expected `)`, found the end of the expression"
                            ),
                        )
                        .with_help("add the missing `)`"));
                    }
                    _ => {
                        return Err(Diagnostic::new(
                            self.at(),
                            format!("expected an operator or `)`, found {}", self.describe()),
                        )
                        .with_help(format!(
                            "the `(` opened at {loc} is still open; products are written with `*`"
                        )));
                    }
                }
                self.bump();
                // The parenthesised expression starts at its `(`.
                inner.location = loc;
                Ok((inner, height))
            }
            Tok::Op(')') => Err(Diagnostic::new(loc, "unexpected `)`: it closes no `(`")
                .with_help("remove it, or add the `(` it should close")),
            _ => Err(Diagnostic::new(
                loc,
                format!(
                    "expected a number, a name or `(`, found {}",
                    self.describe()
                ),
            )
            .with_help("an expression such as `m*g*l*cos(theta)`")),
        }
    }

    /// The arguments of `name(`, with `(` the current token.
    fn call(&mut self, name: String, arity: usize, loc: Location) -> Parsed {
        let open = self.at();
        self.bump();
        let mut args = Vec::new();
        let mut height = 0;
        if !matches!(self.peek(), Tok::Op(')')) {
            loop {
                if matches!(self.peek(), Tok::Op(')' | ',')) {
                    return Err(Diagnostic::new(
                        self.at(),
                        format!(
                            "expected an argument of `{name}`, found {}",
                            self.describe()
                        ),
                    )
                    .with_help(format!("`{name}` takes {}", arguments(arity))));
                }
                let (arg, h) = self.nested(Self::sum)?;
                args.push(arg);
                height = height.max(h);
                match self.peek() {
                    Tok::Op(',') => self.bump(),
                    Tok::Op(')') => break,
                    Tok::End => {
                        return Err(Diagnostic::new(
                            self.at(),
                            format!(
                                "unclosed `(` of `{name}` opened at {open}: expected `,` or `)`, found the end of the expression"
                            ),
                        )
                        .with_help("add the missing `)`"));
                    }
                    _ => {
                        return Err(Diagnostic::new(
                            self.at(),
                            format!(
                                "expected `,` or `)` in the arguments of `{name}`, found {}",
                                self.describe()
                            ),
                        )
                        .with_help(format!(
                            "the `(` of `{name}` opened at {open} is still open"
                        )));
                    }
                }
            }
        }
        self.bump();
        if args.len() != arity {
            return Err(Diagnostic::new(
                loc,
                format!("`{name}` takes {}, found {}", arguments(arity), args.len()),
            )
            .with_help(match name.as_str() {
                "atan2" => "write `atan2(y, x)`".to_string(),
                "dot" | "cross" => {
                    format!("write `{name}(a, b)` of two vectors, as in `{name}(P - O, vel(P))`")
                }
                "distance" => "write `distance(A, B)` of two points".to_string(),
                "norm" | "vel" => format!("write `{name}(a)` of a vector, as in `{name}(P - O)`"),
                _ => format!("write `{name}(x)`"),
            }));
        }
        Ok((
            Expr {
                kind: ExprKind::Call { func: name, args },
                location: loc,
            },
            height + 1,
        ))
    }
}

fn arguments(n: usize) -> String {
    if n == 1 {
        "1 argument".to_string()
    } else {
        format!("{n} arguments")
    }
}

fn unknown_function(name: &str, loc: Location) -> Diagnostic {
    let known: Vec<&str> = FUNCTIONS
        .iter()
        .chain(VECTOR_FUNCTIONS)
        .map(|(f, _)| *f)
        .collect();
    let d = Diagnostic::new(loc, format!("unknown function `{name}`"));
    // Other names of the same functions, which spelling distance would not find.
    let alias = match name {
        "log" | "log10" | "log2" => Some("ln"),
        "arcsin" => Some("asin"),
        "arccos" => Some("acos"),
        "arctan" => Some("atan"),
        "sgn" | "signum" => Some("sign"),
        "heaviside" => Some("step"),
        _ => None,
    };
    if let Some(alias) = alias {
        let note = if name == "log" {
            " (the natural logarithm)"
        } else {
            ""
        };
        return d.with_help(format!(
            "did you mean `{alias}`{note}? functions are: {}",
            known.join(", ")
        ));
    }
    match closest(name, &known) {
        Some(c) => d.with_help(format!(
            "did you mean `{c}`? functions are: {}",
            known.join(", ")
        )),
        None => d.with_help(format!(
            "functions are: {}; to multiply, write `{name}*(…)`",
            known.join(", ")
        )),
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

/// The located error of an operation on numbers that the rule of folding refuses
/// ([`crate::expr::fold`]): "the numbers in this product underflow: …" at the operator.
pub fn fold_diagnostic(at: Location, op: BinOp, error: FoldError) -> Diagnostic {
    let kind = match op {
        BinOp::Add | BinOp::Sub => "sum",
        BinOp::Mul | BinOp::Div => "product",
        BinOp::Pow => "power",
    };
    let verb = match error {
        FoldError::Overflow => "overflow",
        FoldError::Underflow => "underflow",
        FoldError::Undefined => "have no value",
    };
    Diagnostic::new(at, format!("the numbers in this {kind} {verb}: {error}"))
        .with_help("check the exponents of the numbers; rescale the units if the values are real")
}

/// How the numbers written in `lhs op rhs` fail the rule of folding ([`crate::expr::fold`]),
/// if they do: a model file is refused for an operation on numbers written in it, never for a
/// number that only a rewrite would form.
///
/// The numbers of a product are its factors that are numbers, through its chain of `*`, `/`
/// and signs, folded in the order written (the arena gathers them into one coefficient):
/// `k*x^2/2*1e-300*1e-300` fails at its second `*1e-300`. Likewise the number terms of a
/// sum's chain of `+` and `-`, and a power of two numbers (`10^400`). `(x*1e-20)^16` has no
/// operation on numbers alone: the arena keeps it as written rather than form
/// `1e-320 · x^16`, and evaluating it as written is fine for `x` near 1e20.
pub fn written_fold_error(op: BinOp, lhs: &Expr, rhs: &Expr) -> Option<FoldError> {
    let result = match op {
        BinOp::Mul | BinOp::Div => {
            let (a, b) = (numbers_of_product(lhs).ok()?, numbers_of_product(rhs).ok()?);
            combine(op, a, b)
        }
        BinOp::Add | BinOp::Sub => {
            let (a, b) = (numbers_of_sum(lhs).ok()?, numbers_of_sum(rhs).ok()?);
            combine(op, a, b)
        }
        BinOp::Pow => combine(op, number(lhs)?.ok()?, number(rhs)?.ok()?),
    };
    result.err()
}

/// `a op b` of two numbers as the arena folds it (a power that would not be exact is no
/// number, and no error).
fn combine(op: BinOp, a: Constant, b: Constant) -> Result<Constant, FoldError> {
    match op {
        BinOp::Add => a.checked_add(b),
        BinOp::Sub => a.checked_add(b.negated()),
        BinOp::Mul => a.checked_mul(b),
        BinOp::Div if b.is_zero() => Err(FoldError::Undefined),
        BinOp::Div => a.checked_mul(b.pow(Constant::MINUS_ONE)?.unwrap_or(Constant::ONE)),
        BinOp::Pow => Ok(a.pow(b)?.unwrap_or(Constant::ONE)),
    }
}

/// The value of `e` if it is written with numbers alone (no name, no function call), folded
/// as the arena folds it; `None` for any other expression.
fn number(e: &Expr) -> Option<Result<Constant, FoldError>> {
    match &e.kind {
        ExprKind::Number { value, text } => Some(Ok(
            Constant::parse_decimal(text).or_else(|| Constant::float(*value))?
        )),
        ExprKind::Neg(a) => Some(number(a)?.map(Constant::negated)),
        ExprKind::Binary { op, lhs, rhs, .. } => {
            let (a, b) = (number(lhs)?, number(rhs)?);
            if *op == BinOp::Pow
                && let (Ok(a), Ok(b)) = (a, b)
                && matches!(a.pow(b), Ok(None))
            {
                // An irrational power of numbers stays a power in the arena.
                return None;
            }
            Some(a.and_then(|a| combine(*op, a, b?)))
        }
        ExprKind::Ident(_) | ExprKind::Call { .. } => None,
    }
}

/// The product of the numbers among the factors of the product `e` (see
/// [`written_fold_error`]); 1 if it has none.
fn numbers_of_product(e: &Expr) -> Result<Constant, FoldError> {
    match &e.kind {
        ExprKind::Binary {
            op: op @ (BinOp::Mul | BinOp::Div),
            lhs,
            rhs,
            ..
        } => combine(*op, numbers_of_product(lhs)?, numbers_of_product(rhs)?),
        ExprKind::Neg(a) => numbers_of_product(a).map(Constant::negated),
        _ => number(e).unwrap_or(Ok(Constant::ONE)),
    }
}

/// The sum of the numbers among the terms of the sum `e` (see [`written_fold_error`]); 0
/// if it has none.
fn numbers_of_sum(e: &Expr) -> Result<Constant, FoldError> {
    match &e.kind {
        ExprKind::Binary {
            op: op @ (BinOp::Add | BinOp::Sub),
            lhs,
            rhs,
            ..
        } => combine(*op, numbers_of_sum(lhs)?, numbers_of_sum(rhs)?),
        _ => number(e).unwrap_or(Ok(Constant::ZERO)),
    }
}

/// The located error of a function of a number that the rule of folding refuses
/// ([`Func::fold`]): `exp(-1000)` underflows.
pub fn call_fold_diagnostic(at: Location, func: &str, x: f64, error: FoldError) -> Diagnostic {
    let (what, help) = match (error, func) {
        (FoldError::Underflow, _) => (
            format!("`{func}({x})` underflows: {error}"),
            "check the argument; rescale the units if the values are real",
        ),
        (_, "ln") => (
            format!("`{func}({x})` is not a finite real number"),
            "the logarithm takes a positive argument",
        ),
        (_, "sqrt") => (
            format!("`{func}({x})` is not a finite real number"),
            "the square root takes a non-negative argument",
        ),
        (_, "asin" | "acos") => (
            format!("`{func}({x})` is not a finite real number"),
            "the argument must lie in [-1, 1]",
        ),
        _ => (
            format!("`{func}({x})` is not a finite real number"),
            "check the argument",
        ),
    };
    Diagnostic::new(at, what).with_help(help)
}

/// `func(x)` (`sqrt` included, which is not a [`Func`]); `None` for a name that is no
/// function of one argument.
fn apply_call(func: &str, x: f64) -> Option<f64> {
    match func {
        "sqrt" => Some(x.sqrt()),
        name => Func::from_name(name).map(|f| f.apply(x)),
    }
}

/// `func(x)` of a number by the rule of folding (`sqrt` included, which is not a
/// [`Func`]); `None` for a name that is no function of one argument.
pub fn fold_call(func: &str, x: f64) -> Option<Result<f64, FoldError>> {
    match func {
        "sqrt" => Some(fold(x.sqrt(), x == 0.0)),
        name => Func::from_name(name).map(|f| f.fold(x)),
    }
}

/// Evaluates an expression with names resolved by `lookup` (`pi` is built in).
///
/// Functions and powers are evaluated exactly as the expression DAG evaluates them
/// (`crate::expr`), so that a value checked here is the value used later. A result of
/// non-zero numbers that underflows (`1e-300*1e-300`, `exp(-1000)`) is an error, as the rule
/// of folding has it ([`crate::expr::fold`]); an overflow or an undefined operation gives ∞
/// or NaN, for the caller to report with its context.
///
/// # Errors
/// A diagnostic at the first name `lookup` does not know (message `unknown name `x``), or at
/// the first operation that underflows.
pub fn eval_expr(e: &Expr, lookup: &dyn Fn(&str) -> Option<f64>) -> Result<f64, Diagnostic> {
    Ok(match &e.kind {
        ExprKind::Number { value, .. } => *value,
        ExprKind::Ident(n) if n == "pi" => std::f64::consts::PI,
        ExprKind::Ident(n) => {
            lookup(n).ok_or_else(|| Diagnostic::new(e.location, format!("unknown name `{n}`")))?
        }
        ExprKind::Neg(a) => -eval_expr(a, lookup)?,
        ExprKind::Binary {
            op,
            lhs,
            rhs,
            op_location,
        } => {
            let (a, b) = (eval_expr(lhs, lookup)?, eval_expr(rhs, lookup)?);
            let (value, exact_zero) = match op {
                BinOp::Add => (a + b, a == -b),
                BinOp::Sub => (a - b, a == b),
                BinOp::Mul => (a * b, a == 0.0 || b == 0.0),
                BinOp::Div => (a / b, a == 0.0),
                BinOp::Pow => (crate::expr::eval::pow(a, b), a == 0.0),
            };
            if let Err(error @ FoldError::Underflow) = fold(value, exact_zero) {
                return Err(fold_diagnostic(*op_location, *op, error));
            }
            value
        }
        ExprKind::Call { func, args } => {
            let v: Vec<f64> = args
                .iter()
                .map(|a| eval_expr(a, lookup))
                .collect::<Result<_, _>>()?;
            match (func.as_str(), v.as_slice()) {
                ("atan2", [y, x]) => y.atan2(*x),
                (name, [x]) => match (apply_call(name, *x), fold_call(name, *x)) {
                    (_, Some(Err(error @ FoldError::Underflow))) => {
                        return Err(call_fold_diagnostic(e.location, name, *x, error));
                    }
                    (Some(value), _) => value,
                    (None, _) => {
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
mod tests;
