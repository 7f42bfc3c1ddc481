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

/// The vector functions an expression may call, with their number of arguments: functions of
/// the points' positions (docs/model-format.md, "Vector functions"). Their arguments are
/// vectors — a point's name (its position from the origin of the ground frame), sums and
/// differences of vectors, a vector times or divided by a number, `vel(v)` and, in 3-D,
/// `cross(a, b)` — and every other name is a number:
///
/// - `dot(a, b)`: the scalar product `a·b`;
/// - `cross(a, b)`: in the plane the scalar `a_x b_y − a_y b_x` (the `z` component of the
///   cross product), in 3-D the vector `a × b` (usable where a vector is expected, as in
///   `dot(cross(a, b), c)`);
/// - `norm(a)`: the length `|a|`;
/// - `distance(A, B)`: `|A − B|`;
/// - `vel(a)`: the time derivative of `a` (`vel(P)` is the velocity of point `P` in the
///   ground frame), a vector.
///
/// Unlike [`FUNCTIONS`] their names are not reserved: a parameter may be called `distance`,
/// since a call is told from a name by its parentheses.
pub const VECTOR_FUNCTIONS: &[(&str, usize)] = &[
    ("dot", 2),
    ("cross", 2),
    ("norm", 1),
    ("distance", 2),
    ("vel", 1),
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
    /// `f(a, …)` with `f` one of [`FUNCTIONS`] or [`VECTOR_FUNCTIONS`] and the right number
    /// of arguments.
    Call {
        /// Function name.
        func: String,
        /// Arguments.
        args: Vec<Expr>,
    },
}

impl BinOp {
    /// The operator as written: `+`, `-`, `*`, `/`, `^`.
    pub fn symbol(self) -> char {
        match self {
            BinOp::Add => '+',
            BinOp::Sub => '-',
            BinOp::Mul => '*',
            BinOp::Div => '/',
            BinOp::Pow => '^',
        }
    }
}

/// How tightly a form binds, loosest first, as the parser reads them: sums, products, unary
/// minus, powers, then numbers, names, calls and parenthesised expressions.
const SUM: u8 = 1;
const PRODUCT: u8 = 2;
const UNARY: u8 = 3;
const POWER: u8 = 4;
const ATOM: u8 = 5;

impl Expr {
    /// How tightly this expression's outermost form binds.
    fn binding(&self) -> u8 {
        match &self.kind {
            ExprKind::Number { .. } | ExprKind::Ident(_) | ExprKind::Call { .. } => ATOM,
            ExprKind::Neg(_) => UNARY,
            ExprKind::Binary { op, .. } => match op {
                BinOp::Add | BinOp::Sub => SUM,
                BinOp::Mul | BinOp::Div => PRODUCT,
                BinOp::Pow => POWER,
            },
        }
    }

    /// Writes `self`, in parentheses unless it binds at least as tightly as `least`.
    fn write_within(&self, least: u8, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.binding() >= least {
            write!(f, "{self}")
        } else {
            write!(f, "({self})")
        }
    }
}

/// The expression in the model file's syntax, parenthesised so that it parses back to the
/// same tree (locations aside): numbers as written, `+ -` and `* /` left-associative,
/// `^`'s base an atom, and a unary minus in parentheses where it is the right operand of a
/// product or power or is negated (`a*(-b)`, `a^(-2)`, `-(-x)`; `a - -b` reads as the parser
/// reads it). The parentheses add nesting: an expression within a few levels of the
/// parser's depth limit may print as one beyond it.
impl std::fmt::Display for Expr {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.kind {
            ExprKind::Number { text, .. } => f.write_str(text),
            ExprKind::Ident(name) => f.write_str(name),
            ExprKind::Neg(a) => {
                f.write_str("-")?;
                a.write_within(POWER, f)
            }
            ExprKind::Binary { op, lhs, rhs, .. } => {
                // The right operand of a left-associative operator binds one level tighter
                // (`a - (b - c)` keeps its parentheses); a unary minus on the right goes in
                // parentheses (`a*(-b)`), on the left it reads as the parser reads it
                // (`-a*b` is `(-a)*b`).
                let (left, right) = match op {
                    BinOp::Add | BinOp::Sub => (SUM, PRODUCT),
                    BinOp::Mul | BinOp::Div => (PRODUCT, POWER),
                    BinOp::Pow => (ATOM, POWER),
                };
                lhs.write_within(left, f)?;
                let spaced = matches!(op, BinOp::Add | BinOp::Sub);
                if spaced {
                    write!(f, " {} ", op.symbol())?;
                } else {
                    write!(f, "{}", op.symbol())?;
                }
                rhs.write_within(right, f)
            }
            ExprKind::Call { func, args } => {
                write!(f, "{func}(")?;
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        f.write_str(", ")?;
                    }
                    write!(f, "{a}")?;
                }
                f.write_str(")")
            }
        }
    }
}
