//! Parsed expressions, before names are resolved: the output of the expression parser.
//!
//! Grammar (docs/model-format.md): numbers, identifiers (parameters, coordinates, rates
//! `x_dot`, `t`, `pi`), `+ - * / ^` with `^` right-associative and binding tighter than unary
//! minus (`-x^2 = -(x^2)`), parentheses, and calls of the functions in [`FUNCTIONS`].

use super::located::Location;

/// The functions an expression may call, with their number of arguments.
pub const FUNCTIONS: &[(&str, usize)] = &[
    ("sin", 1),
    ("cos", 1),
    ("tan", 1),
    ("asin", 1),
    ("acos", 1),
    ("atan", 1),
    ("atan2", 2),
    ("sinh", 1),
    ("cosh", 1),
    ("tanh", 1),
    ("exp", 1),
    ("ln", 1),
    ("sqrt", 1),
    ("abs", 1),
    ("sign", 1),
    ("step", 1),
];

/// A binary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    /// `a + b`
    Add,
    /// `a - b`
    Sub,
    /// `a * b`
    Mul,
    /// `a / b`
    Div,
    /// `a ^ b`
    Pow,
}

/// A parsed expression with the location of its first character in the model file.
#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    /// What the expression is.
    pub kind: ExprKind,
    /// Where it starts in the file.
    pub location: Location,
}

/// The forms of [`Expr`].
#[derive(Debug, Clone, PartialEq)]
pub enum ExprKind {
    /// A number literal; `text` is the literal as written (`0.5`, `1e-3`), kept so that
    /// decimal literals become exact rationals.
    Number {
        /// The value as `f64`.
        value: f64,
        /// The literal as written.
        text: String,
    },
    /// A name: parameter, coordinate, rate (`theta_dot`), `t` or `pi`.
    Ident(String),
    /// `-a`
    Neg(Box<Expr>),
    /// `a op b`
    Binary {
        /// The operator.
        op: BinOp,
        /// Left operand.
        lhs: Box<Expr>,
        /// Right operand.
        rhs: Box<Expr>,
        /// Where the operator is (the `*` of `a * b`): errors of the operation point here.
        op_location: Location,
    },
    /// `f(a, …)` with `f` one of [`FUNCTIONS`] and the right number of arguments.
    Call {
        /// Function name.
        func: String,
        /// Arguments.
        args: Vec<Expr>,
    },
}
