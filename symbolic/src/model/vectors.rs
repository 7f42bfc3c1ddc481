//! The shapes of expressions that call the vector functions of [`VECTOR_FUNCTIONS`]
//! (`dot`, `cross`, `norm`, `distance`, `vel`): which parts are vectors, which numbers, and
//! the located errors of a vector where a number belongs or the reverse.
//!
//! A vector is a point's name (its position in the ground frame), `a ± b` of two vectors,
//! `-a`, `s*a`, `a*s`, `a/s` with `s` a number, `vel(a)` and, in a 3-D model, `cross(a, b)`.
//! Everything else is a number. An expression of the model file is a number: its value as a
//! whole, and every argument of [`super::ast::FUNCTIONS`], exponent and divisor.

use super::ast::{BinOp, Expr, ExprKind, VECTOR_FUNCTIONS};
use super::diagnostic::Diagnostic;
use super::located::Location;

/// Whether `name` is one of [`VECTOR_FUNCTIONS`].
pub fn is_vector_function(name: &str) -> bool {
    VECTOR_FUNCTIONS.iter().any(|(f, _)| *f == name)
}

/// Whether `e` calls a vector function anywhere.
pub fn uses_vectors(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::Number { .. } | ExprKind::Ident(_) => false,
        ExprKind::Neg(a) => uses_vectors(a),
        ExprKind::Binary { lhs, rhs, .. } => uses_vectors(lhs) || uses_vectors(rhs),
        ExprKind::Call { func, args } => is_vector_function(func) || args.iter().any(uses_vectors),
    }
}

/// Whether `e` calls `vel` anywhere (so depends on the rates).
pub fn uses_velocities(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::Number { .. } | ExprKind::Ident(_) => false,
        ExprKind::Neg(a) => uses_velocities(a),
        ExprKind::Binary { lhs, rhs, .. } => uses_velocities(lhs) || uses_velocities(rhs),
        ExprKind::Call { func, args } => func == "vel" || args.iter().any(uses_velocities),
    }
}

/// A part of an expression: a number or a vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// A number.
    Scalar,
    /// A vector of the model's dimension.
    Vector,
}

/// Checks the shapes of `e`, which must be a number, in a model whose points are `points`
/// (each a vector) in `dimension` (2 or 3) dimensions; `what` names the expression in
/// messages.
///
/// Returns the names of the points that `e` uses as vectors, with their locations (every
/// other name of `e` is a number, for the caller to resolve), or the located errors.
///
/// # Errors
/// A vector added to a number, multiplied by a vector (`dot` or `cross` are meant), divided
/// into or raised to a power, passed to a function of numbers, or left as the value of the
/// whole expression; a number passed where a vector function takes a vector.
pub fn check_shapes(
    e: &Expr,
    points: &[&str],
    dimension: usize,
    what: &str,
) -> Result<Vec<(String, Location)>, Vec<Diagnostic>> {
    let mut cx = Shapes {
        points,
        dimension,
        what,
        errors: Vec::new(),
        used: Vec::new(),
    };
    if cx.shape(e) == Some(Shape::Vector) {
        cx.errors.push(
            Diagnostic::new(
                e.location,
                format!("{what} is a vector, but it must be a number"),
            )
            .with_help(cx.reduce_help()),
        );
    }
    if cx.errors.is_empty() {
        Ok(cx.used)
    } else {
        Err(cx.errors)
    }
}

/// The shape of `e` ([`check_shapes`] without its errors): `None` where the shapes do not
/// fit.
pub fn shape_of(e: &Expr, points: &[&str], dimension: usize) -> Option<Shape> {
    let mut cx = Shapes {
        points,
        dimension,
        what: "",
        errors: Vec::new(),
        used: Vec::new(),
    };
    cx.shape(e)
}

struct Shapes<'a> {
    points: &'a [&'a str],
    dimension: usize,
    what: &'a str,
    errors: Vec<Diagnostic>,
    used: Vec<(String, Location)>,
}

impl Shapes<'_> {
    fn reduce_help(&self) -> &'static str {
        if self.dimension == 3 {
            "make a number of it with `dot(a, b)`, `norm(a)` or `distance(A, B)`; in 3-D `cross(a, b)` is a vector too"
        } else {
            "make a number of it with `dot(a, b)`, `cross(a, b)` (the z component), `norm(a)` or `distance(A, B)`"
        }
    }

    /// The shape of `e`, or `None` after an error in it.
    fn shape(&mut self, e: &Expr) -> Option<Shape> {
        match &e.kind {
            ExprKind::Number { .. } => Some(Shape::Scalar),
            ExprKind::Ident(n) if self.points.contains(&n.as_str()) => {
                self.used.push((n.clone(), e.location));
                Some(Shape::Vector)
            }
            ExprKind::Ident(_) => Some(Shape::Scalar),
            ExprKind::Neg(a) => self.shape(a),
            ExprKind::Binary {
                op,
                lhs,
                rhs,
                op_location,
            } => self.binary_shape(*op, lhs, rhs, *op_location),
            ExprKind::Call { func, args } if is_vector_function(func) => {
                self.vector_call_shape(func, args)
            }
            ExprKind::Call { func, args } => self.scalar_call_shape(func, args),
        }
    }

    /// The shape of `lhs op rhs` (the operator at `op_location`): numbers combine freely,
    /// vectors add to vectors and scale by numbers; anything else is an error.
    fn binary_shape(
        &mut self,
        op: BinOp,
        lhs: &Expr,
        rhs: &Expr,
        op_location: Location,
    ) -> Option<Shape> {
        let (a, b) = (self.shape(lhs), self.shape(rhs));
        let (a, b) = (a?, b?);
        use Shape::{Scalar, Vector};
        let what = self.what;
        let error = |message: String, help: &str| {
            Diagnostic::new(op_location, message).with_help(help.to_string())
        };
        let result = match (op, a, b) {
            (_, Scalar, Scalar) => Ok(Scalar),
            (BinOp::Add | BinOp::Sub, Vector, Vector) => Ok(Vector),
            (BinOp::Add | BinOp::Sub, _, _) => Err(error(
                format!("`{}` in {what} adds a vector and a number", op.symbol()),
                "vectors add to vectors (`P - O`), numbers to numbers; take `norm(…)` or `dot(…)` of the vector",
            )),
            (BinOp::Mul, Vector, Vector) => Err(error(
                format!("`*` in {what} multiplies two vectors"),
                "the scalar product is `dot(a, b)`, the cross product `cross(a, b)`",
            )),
            (BinOp::Mul, _, _) => Ok(Vector),
            (BinOp::Div, Vector, Scalar) => Ok(Vector),
            (BinOp::Div, _, Vector) => Err(error(
                format!("`/` in {what} divides by a vector"),
                "divide by a number, such as `norm(a)`",
            )),
            (BinOp::Pow, _, _) => Err(error(
                format!("`^` in {what} raises a vector to a power"),
                "the square of a vector's length is `dot(a, a)`",
            )),
        };
        match result {
            Ok(s) => Some(s),
            Err(d) => {
                self.errors.push(d);
                None
            }
        }
    }

    /// The shape of a call of the vector function `func`: its arguments must be vectors; `vel`
    /// (and `cross` in 3-D) gives a vector, the others a number.
    fn vector_call_shape(&mut self, func: &str, args: &[Expr]) -> Option<Shape> {
        let shapes: Vec<Option<Shape>> = args.iter().map(|a| self.shape(a)).collect();
        for (a, s) in args.iter().zip(&shapes) {
            if *s == Some(Shape::Scalar) {
                let help = match func {
                    "distance" => "`distance(A, B)` takes two points, as in `distance(P1, P2)`",
                    "vel" => "`vel(P)` takes a point (or a vector of points, `vel(P - O)`)",
                    _ => "its arguments are points or vectors of points, as in `P - O` or `vel(P)`",
                };
                self.errors.push(
                    Diagnostic::new(
                        a.location,
                        format!(
                            "`{func}` in {} takes vectors, but `{a}` is a number",
                            self.what
                        ),
                    )
                    .with_help(help),
                );
            }
        }
        if shapes.iter().any(|s| s != &Some(Shape::Vector)) {
            return None;
        }
        Some(match func {
            "vel" => Shape::Vector,
            "cross" if self.dimension == 3 => Shape::Vector,
            _ => Shape::Scalar,
        })
    }

    /// The shape of a call of the ordinary function `func`: a number, when its arguments are
    /// numbers.
    fn scalar_call_shape(&mut self, func: &str, args: &[Expr]) -> Option<Shape> {
        let mut fine = true;
        for a in args {
            match self.shape(a) {
                Some(Shape::Scalar) => {}
                Some(Shape::Vector) => {
                    self.errors.push(
                        Diagnostic::new(
                            a.location,
                            format!(
                                "`{func}` in {} takes a number, but `{a}` is a vector",
                                self.what
                            ),
                        )
                        .with_help(self.reduce_help()),
                    );
                    fine = false;
                }
                None => fine = false,
            }
        }
        fine.then_some(Shape::Scalar)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Location;
    use crate::model::parser::parse_expr;

    fn shapes(text: &str, dimension: usize) -> Result<Vec<String>, Vec<String>> {
        let e = parse_expr(text, Location { line: 1, column: 1 }).unwrap();
        check_shapes(&e, &["P", "O", "Q"], dimension, "output `L`")
            .map(|used| used.into_iter().map(|(n, _)| n).collect())
            .map_err(|ds| {
                ds.into_iter()
                    .map(|d| format!("{}: {}", d.location, d.message))
                    .collect()
            })
    }

    #[test]
    fn numbers_of_vectors_pass_and_name_their_points() {
        assert_eq!(
            shapes("m*cross(P - O, vel(P))", 2).unwrap(),
            ["P", "O", "P"]
        );
        assert_eq!(
            shapes("dot(P - O, Q - O)/norm(P)^2", 2).unwrap(),
            ["P", "O", "Q", "O", "P"]
        );
        assert_eq!(shapes("dot(cross(P, Q), O)", 3).unwrap(), ["P", "Q", "O"]);
        assert_eq!(shapes("distance(P, 2*O/3) + x", 2).unwrap(), ["P", "O"]);
        assert!(uses_vectors(
            &parse_expr("1 + sin(norm(P))", Location { line: 1, column: 1 }).unwrap()
        ));
    }

    #[test]
    fn misplaced_vectors_are_located() {
        assert_eq!(
            shapes("norm(P) + P", 2).unwrap_err(),
            ["1:9: `+` in output `L` adds a vector and a number"]
        );
        assert_eq!(
            shapes("dot(P, x)", 2).unwrap_err(),
            ["1:8: `dot` in output `L` takes vectors, but `x` is a number"]
        );
        assert_eq!(
            shapes("sin(P - O)", 2).unwrap_err(),
            ["1:5: `sin` in output `L` takes a number, but `P - O` is a vector"]
        );
        assert_eq!(
            shapes("cross(P, Q)", 3).unwrap_err(),
            ["1:1: output `L` is a vector, but it must be a number"]
        );
        assert_eq!(
            shapes("dot(P*Q, O)", 2).unwrap_err(),
            ["1:6: `*` in output `L` multiplies two vectors"]
        );
        assert_eq!(
            shapes("1/vel(P)", 2).unwrap_err(),
            ["1:2: `/` in output `L` divides by a vector"]
        );
    }
}
