//! The lowering of expressions: names, operators, function calls and the vector functions of
//! points, with the checks of constant arithmetic.

use super::*;

impl Lowering<'_> {
    /// The expression `e` of the model file in the arena. Constants must come out exact or
    /// not at all: an operation on constants that is undefined (division by zero, `0^0`, the
    /// logarithm of a non-positive number, a root of a negative one), that overflows `f64`
    /// or that underflows from non-zero numbers (`1e-300*1e-300`, `exp(-1000)`) is a located
    /// error at its operator (see [`Self::check_constants`] and [`crate::expr::fold`]), never
    /// a silent 0, NaN or ∞ in the equations.
    pub(super) fn expr(&mut self, e: &Expr) -> ExprId {
        // The record may be left from an expression built outside a model file's.
        self.arena.take_fold_error();
        self.lower(e)
    }

    /// [`Self::expr`] of a sub-expression.
    // Long: one arm per kind of expression node of the file's syntax; the match is the syntax.
    pub(super) fn lower(&mut self, e: &Expr) -> ExprId {
        match &e.kind {
            ExprKind::Number { value, text } => {
                let c = Constant::parse_decimal(text)
                    .or_else(|| Constant::float(*value))
                    .unwrap_or(Constant::ZERO);
                self.arena.constant(c)
            }
            ExprKind::Ident(name) => match name.as_str() {
                // `t` is the first symbol declared (in `run`), so it is found like the others.
                "pi" => self.arena.pi(),
                _ if self.locals.iter().any(|(n, _)| n == name) => self
                    .locals
                    .iter()
                    .rev()
                    .find(|(n, _)| n == name)
                    .map_or_else(|| self.arena.int(0), |(_, e)| *e),
                _ if self.arena.symbol_id(name).is_none()
                    && self.angular_velocities.contains_key(name) =>
                {
                    self.angular_velocities[name]
                }
                _ if self.arena.symbol_id(name).is_none() && self.speeds.contains_key(name) => {
                    self.speeds[name]
                }
                _ => match self.arena.symbol_id(name) {
                    Some(s)
                        if self.allow_accelerations
                            || !matches!(
                                self.arena.symbol_info(s).kind,
                                SymbolKind::Acceleration(_)
                            ) =>
                    {
                        self.arena.symbol_expr(s)
                    }
                    _ => {
                        self.errors.push(Diagnostic::new(
                            e.location,
                            format!("unknown name `{name}` in an expression"),
                        ));
                        self.arena.int(0)
                    }
                },
            },
            ExprKind::Neg(a) => {
                let a = self.lower(a);
                self.arena.neg(a)
            }
            ExprKind::Binary {
                op,
                lhs,
                rhs,
                op_location,
            } => {
                let before = self.errors.len();
                let (a, b) = (self.lower(lhs), self.lower(rhs));
                // Folds of the operands were reported there, and what follows from a mistake
                // in an operand (`10^400/10^399` is then `10^400 · 10^-399`) is not another.
                self.arena.take_fold_error();
                let reported = self.errors.len() > before;
                let undefined = reported || self.check_constants(*op_location, *op, a, b);
                let result = match op {
                    BinOp::Add => self.arena.plus(a, b),
                    BinOp::Sub => self.arena.minus(a, b),
                    BinOp::Mul => self.arena.times(a, b),
                    BinOp::Div => self.arena.divide(a, b),
                    BinOp::Pow => self.arena.pow(a, b),
                };
                // The arena did not form a number it could not hold; that is an error of the
                // file only if the numbers written in this operation alone fail.
                if self.arena.take_fold_error().is_some()
                    && !undefined
                    && let Some(error) = crate::model::parser::written_fold_error(*op, lhs, rhs)
                {
                    self.errors.push(crate::model::parser::fold_diagnostic(
                        *op_location,
                        *op,
                        error,
                    ));
                }
                result
            }
            ExprKind::Call { func, args } if crate::model::vectors::is_vector_function(func) => {
                self.vector_call(e, func, args)
            }
            ExprKind::Call { func, args } => {
                let args: Vec<ExprId> = args.iter().map(|a| self.lower(a)).collect();
                if let [a] = args.as_slice()
                    && let Some(x) = self.arena.as_constant(*a).map(Constant::to_f64)
                    && let Some(Err(error)) = crate::model::parser::fold_call(func, x)
                {
                    self.errors.push(crate::model::parser::call_fold_diagnostic(
                        e.location, func, x, error,
                    ));
                }
                match (func.as_str(), args.as_slice()) {
                    ("sqrt", [a]) => self.arena.sqrt(*a),
                    ("atan2", [y, x]) => self.arena.atan2(*y, *x),
                    (name, [a]) => match Func::from_name(name) {
                        Some(f) => self.arena.func(f, *a),
                        None => self.unknown_function(e, name),
                    },
                    (name, _) => self.unknown_function(e, name),
                }
            }
        }
    }

    /// Reports `a op b` (its operator at `at`) when its value is undefined for the numbers it
    /// is given: `a / 0`, `0 ^ b` with `b ≤ 0`, a negative number to a non-integer power;
    /// whether it did. (Overflow and underflow are the arena's fold errors.)
    fn check_constants(&mut self, at: Location, op: BinOp, a: ExprId, b: ExprId) -> bool {
        let (x, y) = (
            self.arena.as_constant(a).map(Constant::to_f64),
            self.arena.as_constant(b).map(Constant::to_f64),
        );
        match (op, x, y) {
            (BinOp::Div, _, Some(0.0)) => {
                self.undefined(at, "division by zero", "the divisor is 0 here");
            }
            (BinOp::Pow, Some(x), Some(y)) if x == 0.0 && y <= 0.0 => {
                self.undefined(
                    at,
                    &format!("`0^{y}` is undefined"),
                    "zero has no power of a non-positive exponent",
                );
            }
            (BinOp::Pow, Some(x), Some(y)) if x < 0.0 && y.fract() != 0.0 => {
                self.undefined(
                    at,
                    &format!("`({x})^{y}` is not a real number"),
                    "a negative number has only integer powers",
                );
            }
            _ => return false,
        }
        true
    }

    /// A located error: an operation on numbers whose result is undefined.
    pub(super) fn undefined(&mut self, at: Location, what: &str, help: &str) {
        self.errors
            .push(Diagnostic::new(at, what.to_string()).with_help(help.to_string()));
    }

    fn unknown_function(&mut self, e: &Expr, name: &str) -> ExprId {
        self.errors.push(Diagnostic::new(
            e.location,
            format!("unknown function or wrong number of arguments in `{name}(…)`"),
        ));
        self.arena.int(0)
    }

    /// A call of a vector function that gives a number: `dot(a, b)`, `cross(a, b)` in the
    /// plane (`a_x b_y − a_y b_x`), `norm(a)`, `distance(A, B)`.
    fn vector_call(&mut self, e: &Expr, func: &str, args: &[Expr]) -> ExprId {
        let vectors: Vec<Vec<ExprId>> = args.iter().map(|a| self.vector(a)).collect();
        match (func, vectors.as_slice()) {
            ("dot", [a, b]) => self.dot(a, b),
            ("cross", [a, b]) if a.len() == 2 && b.len() == 2 => {
                let ab = self.arena.times(a[0], b[1]);
                let ba = self.arena.times(a[1], b[0]);
                self.arena.minus(ab, ba)
            }
            ("norm", [a]) => {
                let a2 = self.dot(a, a);
                self.arena.sqrt(a2)
            }
            ("distance", [a, b]) => {
                let d = self.difference(a, b);
                let d2 = self.dot(&d, &d);
                self.arena.sqrt(d2)
            }
            _ => {
                self.errors.push(Diagnostic::new(
                    e.location,
                    format!("`{func}(…)` is a vector here, where a number is expected"),
                ));
                self.arena.int(0)
            }
        }
    }

    /// A vector expression of the points' positions (ground-frame components), as the
    /// rules of [`crate::model::vectors`] shape it.
    pub(super) fn vector(&mut self, e: &Expr) -> Vec<ExprId> {
        let names: Vec<&str> = self.points.iter().map(|(n, _)| n.as_str()).collect();
        let dimension = self.points.first().map_or(2, |(_, r)| r.len());
        let is_vector = |e: &Expr| {
            crate::model::vectors::shape_of(e, &names, dimension)
                == Some(crate::model::vectors::Shape::Vector)
        };
        let (lhs_vector, rhs_vector) = match &e.kind {
            ExprKind::Binary { lhs, rhs, .. } => (is_vector(lhs), is_vector(rhs)),
            _ => (false, false),
        };
        match &e.kind {
            ExprKind::Ident(n) if point(&self.points, n).is_some() => self.points
                [point(&self.points, n).unwrap_or_default()]
            .1
            .clone(),
            ExprKind::Neg(a) => {
                let a = self.vector(a);
                a.iter().map(|c| self.arena.neg(*c)).collect()
            }
            ExprKind::Binary {
                op: op @ (BinOp::Add | BinOp::Sub),
                lhs,
                rhs,
                ..
            } => {
                let (a, b) = (self.vector(lhs), self.vector(rhs));
                a.iter()
                    .zip(&b)
                    .map(|(x, y)| match op {
                        BinOp::Add => self.arena.plus(*x, *y),
                        _ => self.arena.minus(*x, *y),
                    })
                    .collect()
            }
            ExprKind::Binary {
                op: op @ (BinOp::Mul | BinOp::Div),
                lhs,
                rhs,
                ..
            } if lhs_vector || rhs_vector => {
                let (v, s) = if lhs_vector {
                    (self.vector(lhs), self.lower(rhs))
                } else {
                    (self.vector(rhs), self.lower(lhs))
                };
                v.iter()
                    .map(|c| match op {
                        BinOp::Mul => self.arena.times(*c, s),
                        _ => self.arena.divide(*c, s),
                    })
                    .collect()
            }
            ExprKind::Call { func, args } if func == "vel" && args.len() == 1 => {
                let v = self.vector(&args[0]);
                v.iter().map(|c| self.arena.time_derivative(*c)).collect()
            }
            ExprKind::Call { func, args } if func == "cross" && args.len() == 2 => {
                let (a, b) = (self.vector(&args[0]), self.vector(&args[1]));
                if let ([a0, a1, a2], [b0, b1, b2]) = (&a[..], &b[..]) {
                    let mut component = |p: ExprId, q: ExprId, u: ExprId, v: ExprId| {
                        let pq = self.arena.times(p, q);
                        let uv = self.arena.times(u, v);
                        self.arena.minus(pq, uv)
                    };
                    vec![
                        component(*a1, *b2, *a2, *b1),
                        component(*a2, *b0, *a0, *b2),
                        component(*a0, *b1, *a1, *b0),
                    ]
                } else {
                    self.errors.push(Diagnostic::new(
                        e.location,
                        "`cross(a, b)` is a number in the plane, where a vector is expected",
                    ));
                    vec![self.arena.int(0); dimension]
                }
            }
            _ => {
                self.errors.push(Diagnostic::new(
                    e.location,
                    format!("`{e}` is a number, where a vector of points is expected"),
                ));
                vec![self.arena.int(0); dimension]
            }
        }
    }

    /// The expression as the model's description keeps it: as written, or, when it uses
    /// the vector functions or a frame's angular velocity (`omega_B_x`), lowered (the points'
    /// positions and velocities written out in the coordinates and rates) and printed back in
    /// the file's syntax, so that it is evaluated from the state alone.
    pub(super) fn state_text(&mut self, e: &Expr) -> String {
        // A frame's angular velocity (`omega_B_x`) is no name of the state either.
        let mut ids = Vec::new();
        crate::model::parser::identifiers(e, &mut ids);
        let reads_angular_velocity = ids.iter().any(|(n, _)| {
            self.arena.symbol_id(n).is_none() && self.angular_velocities.contains_key(n)
        });
        if !crate::model::vectors::uses_vectors(e) && !reads_angular_velocity {
            return e.to_string();
        }
        let lowered = self.expr(e);
        crate::expr::print::Printer::new(&self.arena, crate::expr::print::Syntax::Text)
            .print(lowered)
    }

    pub(super) fn dot(&mut self, a: &[ExprId], b: &[ExprId]) -> ExprId {
        let terms: Vec<ExprId> = a
            .iter()
            .zip(b)
            .map(|(x, y)| self.arena.times(*x, *y))
            .collect();
        self.arena.sum(&terms)
    }

    pub(super) fn difference(&mut self, a: &[ExprId], b: &[ExprId]) -> Vec<ExprId> {
        a.iter()
            .zip(b)
            .map(|(x, y)| self.arena.minus(*x, *y))
            .collect()
    }
}
