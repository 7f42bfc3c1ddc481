//! Printing expressions as plain text, Rust source, LaTeX and MathML.
//!
//! One printer serves the four syntaxes; they differ only in how atoms, powers, quotients
//! and calls are spelled. Sums print their non-constant terms first with negative
//! coefficients as subtraction (for display, a positive term leads where the first would be
//! negative); products print negative powers as a denominator.

use std::cell::RefCell;

use rustc_hash::FxHashMap;

use super::{Constant, ExprArena, ExprId, Func, Node, SymbolId};

/// Target syntax of a [`Printer`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Syntax {
    /// Model-file syntax (`m*l^2*theta_dot^2/2`); parses back with the model parser.
    Text,
    /// Rust `f64` source (`0.5 * m * l.powi(2)`); the helper functions `sign`, `step`, `sin`, `cos` and `powf`
    /// (and `sin_cos` for shared pairs) are called through [`Printer::with_rust_helpers`]'s path.
    Rust,
    /// LaTeX math (`\frac{m l^{2} \dot{\theta}^{2}}{2}`).
    Latex,
    /// MathML Core presentation markup, the content of a `<math>` element
    /// (`<mfrac><mrow><mi>m</mi>…</mrow><mn>2</mn></mfrac>`): every printed expression is one
    /// element (`<mrow>` around sequences), so it can be the child of `<msup>` or `<mfrac>`.
    /// Browsers render it without scripts or network.
    MathMl,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Prec {
    Sum = 1,
    Product = 2,
    Power = 3,
    Atom = 4,
}

/// Prints expressions of one arena in one syntax.
pub struct Printer<'a> {
    arena: &'a ExprArena,
    syntax: Syntax,
    symbol_name: Box<dyn Fn(SymbolId) -> String + 'a>,
    temporary: Box<dyn Fn(ExprId) -> Option<String> + 'a>,
    helpers: String,
    /// See [`Printer::for_display`].
    display_limit: Option<u64>,
    /// See [`Printer::with_memo`].
    memo: Option<&'a PrintMemo>,
}

/// Printed subexpressions kept between printers of one arena and syntax
/// ([`Printer::with_memo`]).
#[derive(Default)]
pub struct PrintMemo(RefCell<FxHashMap<ExprId, (String, Prec)>>);

/// The longest text of one subexpression a [`PrintMemo`] keeps: longer ones are printed
/// again, so that the memo holds at most this many bytes a node.
const MOST_MEMO_TEXT: usize = 1_000;

/// The most operations (as a tree, [`ExprArena::tree_operation_count`]) of an expression that
/// [`Printer::for_display`] prints: about 200 kB of text on one line. Past it a printed tree
/// is no use to a reader, and for a chain of 3-D bodies in relative rotations, whose
/// equations share subexpressions level by level, it costs time and memory exponential in
/// the chain (8 universal joints: 10⁸ operations as trees, 68,408 after CSE). Among the
/// bundled models only seven entries of the Whipple bicycle's `F` and `γ` pass it.
pub const DISPLAY_LIMIT: u64 = 20_000;

impl<'a> Printer<'a> {
    /// A printer that names symbols by their declared name (LaTeX: [`latex_symbol`]).
    pub fn new(arena: &'a ExprArena, syntax: Syntax) -> Self {
        let symbol_name: Box<dyn Fn(SymbolId) -> String + 'a> = match syntax {
            Syntax::Latex => Box::new(move |s| latex_symbol(&arena.symbol_info(s).name)),
            Syntax::MathMl => Box::new(move |s| mathml_symbol(&arena.symbol_info(s).name)),
            _ => Box::new(move |s| arena.symbol_info(s).name.clone()),
        };
        Self {
            arena,
            syntax,
            symbol_name,
            temporary: Box::new(|_| None),
            helpers: "crate".to_string(),
            display_limit: None,
            memo: None,
        }
    }

    /// A printer for people to read (equation listings, reports): an expression of more than
    /// [`DISPLAY_LIMIT`] operations as a tree is printed as a note that says so and how many
    /// (the generated code, `equations --rust`, prints it with its shared subexpressions
    /// named). A sum whose first term is negative is printed with a positive term first, as
    /// a reader writes it (`R φ̇² cos θ − g`); the code printers keep the canonical order.
    pub fn for_display(arena: &'a ExprArena, syntax: Syntax) -> Self {
        Self {
            display_limit: Some(DISPLAY_LIMIT),
            ..Self::new(arena, syntax)
        }
    }

    /// Keeps the text of each subexpression printed in `memo` and reuses it: for printing
    /// many expressions that share subexpressions, by printers of the same syntax and
    /// configuration over the same arena (the readable forms' lengths).
    pub fn with_memo(mut self, memo: &'a PrintMemo) -> Self {
        self.memo = Some(memo);
        self
    }

    /// Names symbols with `f` instead.
    pub fn with_symbol_names(mut self, f: impl Fn(SymbolId) -> String + 'a) -> Self {
        self.symbol_name = Box::new(f);
        self
    }

    /// Refers to subexpressions for which `f` returns a name by that name (CSE temporaries).
    pub fn with_temporaries(mut self, f: impl Fn(ExprId) -> Option<String> + 'a) -> Self {
        self.temporary = Box::new(f);
        self
    }

    /// Path of the module that provides `sign(f64)`, `step(f64)` and `powf(f64, f64)` in Rust
    /// output.
    pub fn with_rust_helpers(mut self, path: &str) -> Self {
        self.helpers = path.to_string();
        self
    }

    /// `expr` printed in full (temporaries still referenced by name if configured).
    pub fn print(&self, expr: ExprId) -> String {
        // Code is printed whole, whatever its size.
        if let Some(limit) = self.display_limit.filter(|_| self.syntax != Syntax::Rust) {
            let operations = self.arena.tree_operation_count(&[expr]);
            if operations > limit {
                let note = format!(
                    "[not printed: {operations} operations as a tree; `equations --rust` prints it with its shared subexpressions]"
                );
                return match self.syntax {
                    // `--` would print as an en dash in LaTeX.
                    Syntax::Latex => {
                        format!("\\text{{{}}}", note.replace('`', "").replace("--", "-{}-"))
                    }
                    Syntax::MathMl => format!("<mtext>{}</mtext>", note.replace('`', "")),
                    Syntax::Text | Syntax::Rust => note,
                };
            }
        }
        self.operand(expr).0
    }

    /// The definition of `expr` itself: its node printed with its children referenced, even
    /// if `expr` is itself a temporary.
    pub fn print_definition(&self, expr: ExprId) -> String {
        self.node(expr).0
    }

    fn operand(&self, e: ExprId) -> (String, Prec) {
        if let Some(name) = (self.temporary)(e) {
            return (name, Prec::Atom);
        }
        let Some(memo) = self.memo else {
            return self.node(e);
        };
        if let Some(text) = memo.0.borrow().get(&e) {
            return text.clone();
        }
        let text = self.node(e);
        if text.0.len() <= MOST_MEMO_TEXT {
            memo.0.borrow_mut().insert(e, text.clone());
        }
        text
    }

    fn wrap(&self, (s, p): (String, Prec), min: Prec) -> String {
        if p >= min {
            s
        } else if self.syntax == Syntax::Latex {
            format!("\\left({s}\\right)")
        } else if self.syntax == Syntax::MathMl {
            format!("<mrow><mo>(</mo>{s}<mo>)</mo></mrow>")
        } else {
            format!("({s})")
        }
    }

    fn constant(&self, c: Constant) -> (String, Prec) {
        let negative = c.is_negative();
        let text = match (self.syntax, c) {
            (Syntax::Rust, _) => format!("{:?}_f64", c.to_f64().abs()),
            (Syntax::MathMl, Constant::Rational { num, den: 1 }) => {
                format!("<mn>{}</mn>", num.unsigned_abs())
            }
            (Syntax::MathMl, Constant::Rational { num, den }) => {
                format!(
                    "<mfrac><mn>{}</mn><mn>{den}</mn></mfrac>",
                    num.unsigned_abs()
                )
            }
            (Syntax::MathMl, Constant::Float(_)) => format!("<mn>{:?}</mn>", c.to_f64().abs()),
            (_, Constant::Rational { num, den: 1 }) => num.unsigned_abs().to_string(),
            (Syntax::Text, Constant::Rational { num, den }) => {
                format!("{}/{den}", num.unsigned_abs())
            }
            (Syntax::Latex, Constant::Rational { num, den }) => {
                format!("\\frac{{{}}}{{{den}}}", num.unsigned_abs())
            }
            (_, Constant::Float(_)) => format!("{:?}", c.to_f64().abs()),
        };
        let prec = match (self.syntax, c) {
            (Syntax::Text, Constant::Rational { den, .. }) if den != 1 => Prec::Product,
            _ => Prec::Atom,
        };
        if negative {
            (self.negated(&text), Prec::Product)
        } else {
            (text, prec)
        }
    }

    /// `-x` in the printer's syntax (`x` printed as a factor already).
    fn negated(&self, x: &str) -> String {
        if self.syntax == Syntax::MathMl {
            format!("<mrow><mo>\u{2212}</mo>{x}</mrow>")
        } else {
            format!("-{x}")
        }
    }

    /// A number in the printer's syntax (`<mn>2</mn>` in MathML).
    fn number(&self, text: String) -> String {
        if self.syntax == Syntax::MathMl {
            format!("<mn>{text}</mn>")
        } else {
            text
        }
    }

    fn node(&self, e: ExprId) -> (String, Prec) {
        match self.arena.node(e) {
            Node::Const(c) => self.constant(*c),
            Node::Pi => (
                match self.syntax {
                    Syntax::Text => "pi",
                    Syntax::Rust => "::core::f64::consts::PI",
                    Syntax::Latex => "\\pi",
                    Syntax::MathMl => "<mi>\u{3c0}</mi>",
                }
                .to_string(),
                Prec::Atom,
            ),
            Node::Symbol(s) => ((self.symbol_name)(*s), Prec::Atom),
            Node::Add(terms) => self.sum(terms),
            Node::Mul(factors) => {
                let (coefficient, rest) = self.split(factors);
                let (s, p) = self.product(coefficient.abs_constant(), rest);
                if coefficient.is_negative() {
                    (
                        self.negated(&self.wrap((s, p), Prec::Product)),
                        Prec::Product,
                    )
                } else {
                    (s, p)
                }
            }
            Node::Pow([b, x]) => self.power(*b, PowerExponent::Expr(*x)),
            Node::Func(f, u) => self.call(*f, *u),
            Node::Atan2([y, x]) => {
                let (ys, xs) = (self.operand(*y), self.operand(*x));
                match self.syntax {
                    Syntax::Text => (format!("atan2({}, {})", ys.0, xs.0), Prec::Atom),
                    Syntax::Rust => (
                        format!("{}.atan2({})", self.wrap(ys, Prec::Atom), xs.0),
                        Prec::Atom,
                    ),
                    Syntax::Latex => (
                        format!("\\operatorname{{atan2}}\\left({}, {}\\right)", ys.0, xs.0),
                        Prec::Atom,
                    ),
                    Syntax::MathMl => (
                        format!(
                            "<mrow><mi>atan2</mi><mo>\u{2061}</mo><mrow><mo>(</mo>{}<mo>,</mo>{}<mo>)</mo></mrow></mrow>",
                            ys.0, xs.0
                        ),
                        Prec::Atom,
                    ),
                }
            }
        }
    }

    fn split<'b>(&self, factors: &'b [ExprId]) -> (Constant, &'b [ExprId]) {
        match self.arena.as_constant(factors[0]) {
            Some(c) if (self.temporary)(factors[0]).is_none() => (c, &factors[1..]),
            _ => (Constant::ONE, factors),
        }
    }

    fn sum(&self, terms: &[ExprId]) -> (String, Prec) {
        let mut ordered: Vec<ExprId> = terms
            .iter()
            .copied()
            .filter(|t| self.arena.as_constant(*t).is_none())
            .collect();
        ordered.extend(
            terms
                .iter()
                .copied()
                .filter(|t| self.arena.as_constant(*t).is_some()),
        );
        // A reader's order: a positive term first where the first is negative (`R φ̇² cos θ − g`,
        // not `−g + R φ̇² cos θ`). Only for display: generated code keeps the canonical order,
        // the one its compiled twin evaluates.
        if self.display_limit.is_some()
            && self.syntax != Syntax::Rust
            && ordered.first().is_some_and(|&t| self.is_negative_term(t))
            && let Some(k) = ordered.iter().position(|&t| !self.is_negative_term(t))
        {
            let t = ordered.remove(k);
            ordered.insert(0, t);
        }
        let mathml = self.syntax == Syntax::MathMl;
        let (minus, plus, between_minus) = if mathml {
            ("<mo>\u{2212}</mo>", "<mo>+</mo>", "<mo>\u{2212}</mo>")
        } else {
            ("-", " + ", " - ")
        };
        let mut out = String::new();
        for (i, &t) in ordered.iter().enumerate() {
            let (negative, magnitude) = self.signed_term(t);
            let text = self.wrap(magnitude, Prec::Product);
            match (i, negative) {
                (0, false) => out.push_str(&text),
                (0, true) => {
                    out.push_str(minus);
                    out.push_str(&text);
                }
                (_, false) => {
                    out.push_str(plus);
                    out.push_str(&text);
                }
                (_, true) => {
                    out.push_str(between_minus);
                    out.push_str(&text);
                }
            }
        }
        if mathml {
            out = format!("<mrow>{out}</mrow>");
        }
        (out, Prec::Sum)
    }

    /// Whether [`Self::signed_term`] prints `t` with a minus sign (without printing it).
    fn is_negative_term(&self, t: ExprId) -> bool {
        if (self.temporary)(t).is_some() {
            return false;
        }
        match self.arena.node(t) {
            Node::Const(c) => c.is_negative(),
            Node::Mul(factors) => self.split(factors).0.is_negative(),
            _ => false,
        }
    }

    /// A term of a sum as (is negative, printed magnitude).
    fn signed_term(&self, t: ExprId) -> (bool, (String, Prec)) {
        if (self.temporary)(t).is_some() {
            return (false, self.operand(t));
        }
        match self.arena.node(t) {
            Node::Const(c) => (c.is_negative(), self.constant(c.abs_constant())),
            Node::Mul(factors) => {
                let (c, rest) = self.split(factors);
                (c.is_negative(), self.product(c.abs_constant(), rest))
            }
            _ => (false, self.operand(t)),
        }
    }

    /// `coefficient · Π factors` with `coefficient ≥ 0`.
    fn product(&self, coefficient: Constant, factors: &[ExprId]) -> (String, Prec) {
        let mut numerator: Vec<(String, Prec)> = Vec::new();
        let mut denominator: Vec<(String, Prec)> = Vec::new();
        match (self.syntax, coefficient) {
            (_, c) if c.is_one() => {}
            (Syntax::Rust, c) | (_, c @ Constant::Float(_)) => numerator.push(self.constant(c)),
            (_, Constant::Rational { num, den }) => {
                if num != 1 {
                    numerator.push((self.number(num.to_string()), Prec::Atom));
                }
                if den != 1 {
                    denominator.push((self.number(den.to_string()), Prec::Atom));
                }
            }
        }
        for &f in factors {
            if (self.temporary)(f).is_none()
                && let Node::Pow([b, x]) = self.arena.node(f)
                && let Some(c) = self.arena.as_constant(*x)
                && c.is_negative()
            {
                let power = c.negated();
                // `x^-1` is the denominator `x`, not `x^1`.
                denominator.push(if power.is_one() {
                    self.operand(*b)
                } else {
                    self.power(*b, PowerExponent::Constant(power))
                });
                continue;
            }
            numerator.push(self.operand(f));
        }
        let join = |items: &[(String, Prec)]| -> (String, Prec) {
            match items.len() {
                0 => (self.number("1".to_string()), Prec::Atom),
                1 => items[0].clone(),
                _ => {
                    let sep = match self.syntax {
                        Syntax::Text => "*",
                        Syntax::Rust => " * ",
                        Syntax::Latex => " ",
                        Syntax::MathMl => "<mo>\u{2062}</mo>",
                    };
                    let parts: Vec<String> = items
                        .iter()
                        .map(|it| self.wrap(it.clone(), Prec::Power))
                        .collect();
                    let mut s = String::new();
                    for (i, p) in parts.iter().enumerate() {
                        if i > 0 {
                            let digit_follows = p.starts_with(|c: char| c.is_ascii_digit());
                            s.push_str(match self.syntax {
                                Syntax::Latex if digit_follows => " \\cdot ",
                                Syntax::MathMl if p.starts_with("<mn>") => "<mo>\u{22c5}</mo>",
                                _ => sep,
                            });
                        }
                        s.push_str(p);
                    }
                    if self.syntax == Syntax::MathMl {
                        s = format!("<mrow>{s}</mrow>");
                    }
                    (s, Prec::Product)
                }
            }
        };
        let num = join(&numerator);
        if denominator.is_empty() {
            if self.syntax == Syntax::Rust && numerator.is_empty() {
                return ("1.0_f64".to_string(), Prec::Atom);
            }
            return num;
        }
        let den = join(&denominator);
        match self.syntax {
            Syntax::Latex => (format!("\\frac{{{}}}{{{}}}", num.0, den.0), Prec::Atom),
            Syntax::MathMl => (format!("<mfrac>{}{}</mfrac>", num.0, den.0), Prec::Atom),
            Syntax::Text | Syntax::Rust => {
                let one = if self.syntax == Syntax::Rust {
                    "1.0_f64"
                } else {
                    "1"
                };
                let n = if numerator.is_empty() {
                    one.to_string()
                } else {
                    self.wrap(num, Prec::Product)
                };
                let d = self.wrap(den, Prec::Power);
                let sep = if self.syntax == Syntax::Text {
                    "/"
                } else {
                    " / "
                };
                (format!("{n}{sep}{d}"), Prec::Product)
            }
        }
    }

    fn power(&self, base: ExprId, exponent: PowerExponent) -> (String, Prec) {
        let b = self.operand(base);
        let constant = match exponent {
            PowerExponent::Constant(c) => Some(c),
            PowerExponent::Expr(x) => self.arena.as_constant(x),
        };
        let half = Constant::Rational { num: 1, den: 2 };
        let minus_half = Constant::Rational { num: -1, den: 2 };
        match self.syntax {
            Syntax::Rust => {
                let argument = b.0.clone();
                let base = self.wrap(b, Prec::Atom);
                match constant {
                    Some(c) if c == half => (format!("{base}.sqrt()"), Prec::Atom),
                    Some(c) if c == minus_half => {
                        (format!("(1.0_f64 / {base}.sqrt())"), Prec::Atom)
                    }
                    Some(c)
                        if c.as_integer()
                            .is_some_and(|n| n.unsigned_abs() <= i32::MAX as u64) =>
                    {
                        (
                            format!("{base}.powi({})", c.as_integer().unwrap_or(1)),
                            Prec::Atom,
                        )
                    }
                    _ => {
                        let x = match exponent {
                            PowerExponent::Constant(c) => self.constant(c),
                            PowerExponent::Expr(x) => self.operand(x),
                        };
                        // The runtime's `powf`, which every backend evaluates alike (a
                        // half-integer exponent through a square root).
                        (
                            format!("{}::powf({argument}, {})", self.helpers, x.0),
                            Prec::Atom,
                        )
                    }
                }
            }
            Syntax::Text | Syntax::Latex | Syntax::MathMl => {
                if constant == Some(half) {
                    return match self.syntax {
                        Syntax::Latex => (format!("\\sqrt{{{}}}", b.0), Prec::Atom),
                        Syntax::MathMl => (format!("<msqrt>{}</msqrt>", b.0), Prec::Atom),
                        _ => (format!("sqrt({})", b.0), Prec::Atom),
                    };
                }
                let x = match exponent {
                    PowerExponent::Constant(c) => self.constant(c),
                    PowerExponent::Expr(x) => self.operand(x),
                };
                let base = self.wrap(b, Prec::Atom);
                match self.syntax {
                    Syntax::Latex => (format!("{base}^{{{}}}", x.0), Prec::Power),
                    Syntax::MathMl => (format!("<msup>{base}{}</msup>", x.0), Prec::Power),
                    _ => (format!("{base}^{}", self.wrap(x, Prec::Atom)), Prec::Power),
                }
            }
        }
    }

    fn call(&self, f: Func, u: ExprId) -> (String, Prec) {
        let arg = self.operand(u);
        match self.syntax {
            Syntax::Text => (format!("{}({})", f.name(), arg.0), Prec::Atom),
            Syntax::Rust => match f {
                Func::Sign | Func::Step | Func::Sin | Func::Cos => (
                    format!("{}::{}({})", self.helpers, f.name(), arg.0),
                    Prec::Atom,
                ),
                _ => (
                    format!("{}.{}()", self.wrap(arg, Prec::Atom), f.name()),
                    Prec::Atom,
                ),
            },
            Syntax::Latex => {
                let s = match f {
                    Func::Abs => format!("\\left|{}\\right|", arg.0),
                    Func::Sign | Func::Step | Func::Asin | Func::Acos | Func::Atan => {
                        format!("\\operatorname{{{}}}\\left({}\\right)", f.name(), arg.0)
                    }
                    _ => format!("\\{}\\left({}\\right)", f.name(), arg.0),
                };
                (s, Prec::Atom)
            }
            Syntax::MathMl => {
                let s = match f {
                    Func::Abs => format!("<mrow><mo>|</mo>{}<mo>|</mo></mrow>", arg.0),
                    _ => format!(
                        "<mrow><mi>{}</mi><mo>\u{2061}</mo><mrow><mo>(</mo>{}<mo>)</mo></mrow></mrow>",
                        f.name(),
                        arg.0
                    ),
                };
                (s, Prec::Atom)
            }
        }
    }
}

#[derive(Clone, Copy)]
enum PowerExponent {
    Constant(Constant),
    Expr(ExprId),
}

impl Constant {
    /// `|c|`.
    pub(crate) fn abs_constant(self) -> Constant {
        if self.is_negative() {
            self.negated()
        } else {
            self
        }
    }
}

const GREEK: &[&str] = &[
    "alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "iota", "kappa",
    "lambda", "mu", "nu", "xi", "pi", "rho", "sigma", "tau", "upsilon", "phi", "chi", "psi",
    "omega", "Gamma", "Delta", "Theta", "Lambda", "Xi", "Pi", "Sigma", "Phi", "Psi", "Omega",
];

/// The parts of a symbol name: base, accent (`_dot` 1, `_ddot` 2) and subscript
/// (`theta1` → `theta`, 0, `1`; `x_dot` → `x`, 1, none; `m_cart` → `m`, 0, `cart`).
fn symbol_parts(name: &str) -> (String, u8, Option<String>) {
    let (stem, accent) = if let Some(s) = name.strip_suffix("_ddot") {
        (s, 2)
    } else if let Some(s) = name.strip_suffix("_dot") {
        (s, 1)
    } else {
        (name, 0)
    };
    let (base, subscript) = match stem.split_once('_') {
        Some((b, s)) => (b.to_string(), Some(s.to_string())),
        None => {
            let digits = stem.trim_start_matches(|c: char| !c.is_ascii_digit());
            let cut = stem.len() - digits.len();
            if cut > 0 && !digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit()) {
                (stem[..cut].to_string(), Some(digits.to_string()))
            } else {
                (stem.to_string(), None)
            }
        }
    };
    (base, accent, subscript)
}

/// LaTeX for a symbol name: `theta1` → `\theta_{1}`, `x_dot` → `\dot{x}`,
/// `theta1_ddot` → `\ddot{\theta}_{1}`, `m_cart` → `m_{\mathrm{cart}}`.
pub fn latex_symbol(name: &str) -> String {
    let (base, accent, subscript) = symbol_parts(name);
    let base = if GREEK.contains(&base.as_str()) {
        format!("\\{base}")
    } else if base.chars().count() > 1 {
        format!("\\mathrm{{{base}}}")
    } else {
        base
    };
    let base = match accent {
        1 => format!("\\dot{{{base}}}"),
        2 => format!("\\ddot{{{base}}}"),
        _ => base,
    };
    match subscript {
        Some(s) if s.chars().all(|c| c.is_ascii_digit()) => format!("{base}_{{{s}}}"),
        Some(s) if s.chars().count() == 1 => format!("{base}_{{{s}}}"),
        Some(s) => format!("{base}_{{\\mathrm{{{s}}}}}"),
        None => base,
    }
}

/// Greek letters as characters, in the order of [`GREEK`].
const GREEK_LETTERS: &[char] = &[
    'α', 'β', 'γ', 'δ', 'ε', 'ζ', 'η', 'θ', 'ι', 'κ', 'λ', 'μ', 'ν', 'ξ', 'π', 'ρ', 'σ', 'τ', 'υ',
    'φ', 'χ', 'ψ', 'ω', 'Γ', 'Δ', 'Θ', 'Λ', 'Ξ', 'Π', 'Σ', 'Φ', 'Ψ', 'Ω',
];

/// MathML for a symbol name, one element: `theta1` → `<msub><mi>θ</mi><mn>1</mn></msub>`,
/// `x_dot` → `<mover accent="true"><mi>x</mi><mo>˙</mo></mover>`, `theta1_ddot` →
/// `<msub><mover accent="true"><mi>θ</mi><mo>¨</mo></mover><mn>1</mn></msub>`, `m_cart` →
/// `<msub><mi>m</mi><mi>cart</mi></msub>` (a multi-letter `<mi>` renders upright).
pub fn mathml_symbol(name: &str) -> String {
    let (base, accent, subscript) = symbol_parts(name);
    let base = match GREEK.iter().position(|g| *g == base) {
        Some(i) => format!("<mi>{}</mi>", GREEK_LETTERS[i]),
        None => format!("<mi>{base}</mi>"),
    };
    let base = match accent {
        1 => format!("<mover accent=\"true\">{base}<mo>\u{2d9}</mo></mover>"),
        2 => format!("<mover accent=\"true\">{base}<mo>\u{a8}</mo></mover>"),
        _ => base,
    };
    match subscript {
        Some(s) if s.chars().all(|c| c.is_ascii_digit()) => {
            format!("<msub>{base}<mn>{s}</mn></msub>")
        }
        Some(s) => format!("<msub>{base}<mi>{s}</mi></msub>"),
        None => base,
    }
}
