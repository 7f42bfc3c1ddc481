//! The dimension of an expression: names, sums, powers, vectors and function calls, each unknown
//! unit an unknown of the equations the file's uses give.

use super::*;

impl Checker<'_> {
    /// The unit of `e`, checking its sums, function arguments and powers; `None` when it
    /// can be anything (`0`, a name already reported, an inconsistent sum).
    pub(super) fn dim(&mut self, e: &Expr, what: &str) -> Option<Dim> {
        match &e.kind {
            ExprKind::Number { value, .. } => (*value != 0.0).then(|| Dim::of(Dimension::ONE)),
            ExprKind::Ident(n) => self.name(n),
            ExprKind::Neg(a) => self.dim(a, what),
            ExprKind::Binary {
                op: BinOp::Add | BinOp::Sub,
                ..
            } => self.sum(e, what),
            ExprKind::Binary {
                op: op @ (BinOp::Mul | BinOp::Div),
                lhs,
                rhs,
                ..
            } => {
                let a = self.dim(lhs, what);
                let b = self.dim(rhs, what);
                match op {
                    BinOp::Mul => a?.mul(&b?),
                    _ => a?.div(&b?),
                }
            }
            ExprKind::Binary { lhs, rhs, .. } => self.power(e, lhs, rhs, what),
            ExprKind::Call { func, args } => self.call(func, args, what),
        }
    }

    pub(super) fn sum(&mut self, e: &Expr, what: &str) -> Option<Dim> {
        let mut parts = Vec::new();
        terms(e, &mut parts);
        let dims: Vec<Option<Dim>> = parts.iter().map(|t| self.dim(t, what)).collect();
        let (first, reference) = parts
            .iter()
            .zip(&dims)
            .find_map(|(t, d)| d.as_ref().map(|d| (*t, d.clone())))?;
        let before = self.diagnostics.len();
        for (t, d) in parts.iter().zip(&dims) {
            if std::ptr::eq(*t, first) {
                continue;
            }
            let (first_text, term_text, at) = (text(first), text(t), t.location);
            self.require(d.as_ref(), Some(&reference), (HOMOGENEITY, what, at), |got, want| {
                Diagnostic::new(
                    at,
                    format!(
                        "sum of unlike units in {what}: `{first_text}` is {} but `{term_text}` is {}",
                        show(want),
                        show(got)
                    ),
                )
                .with_help("every term of a sum has the same unit; check the formula and the units of its parameters")
            });
        }
        // An inconsistent sum has no unit: no second message about the same mistake.
        (self.diagnostics.len() == before).then_some(reference)
    }

    pub(super) fn power(
        &mut self,
        e: &Expr,
        base: &Expr,
        exponent: &Expr,
        what: &str,
    ) -> Option<Dim> {
        let b = self.dim(base, what);
        if let Some(p) = numeric_exponent(exponent) {
            return b?.pow(p);
        }
        let x = self.dim(exponent, what);
        let one = Dim::of(Dimension::ONE);
        let before = self.diagnostics.len();
        let (exponent_text, power_text, at) = (text(exponent), text(e), exponent.location);
        self.require(x.as_ref(), Some(&one), (HOMOGENEITY, what, at), |got, _| {
            Diagnostic::new(
                at,
                format!("the exponent `{exponent_text}` in {what} is {}, but an exponent is a pure number", show(got)),
            )
            .with_help("divide it by a quantity of the same unit")
        });
        let base_text = text(base);
        self.require(b.as_ref(), Some(&one), (HOMOGENEITY, what, base.location), |got, _| {
            Diagnostic::new(
                base.location,
                format!("`{power_text}` in {what} raises `{base_text}`, which is {}, to a power that is not a number", show(got)),
            )
            .with_help("only a pure number can be raised to a symbolic power; write the exponent as a number, as in `x^2` or `x^(1/2)`")
        });
        // A wrong power has no unit: no second message about the same mistake.
        (self.diagnostics.len() == before).then_some(one)
    }

    /// The unit of a vector expression of the points (their positions in m): a sum takes
    /// the unit of its terms, `vel` divides by s, `cross` multiplies; anything else is
    /// [`Self::dim`]. (The rules checked the shapes: vectors and numbers are where they
    /// belong.)
    fn vector_dim(&mut self, e: &Expr, what: &str) -> Option<Dim> {
        let vector = |cx: &Self, e: &Expr| {
            let points: Vec<&str> = cx
                .file
                .points
                .iter()
                .map(|p| p.name.value.as_str())
                .collect();
            crate::model::vectors::shape_of(e, &points, cx.file.dimension.unwrap_or(2))
                == Some(crate::model::vectors::Shape::Vector)
        };
        match &e.kind {
            ExprKind::Ident(n) if self.file.points.iter().any(|p| p.name.value == *n) => {
                Some(Dim::of(Dimension::METRE))
            }
            ExprKind::Neg(a) => self.vector_dim(a, what),
            ExprKind::Binary {
                op: BinOp::Add | BinOp::Sub,
                lhs,
                rhs,
                ..
            } => {
                let (a, b) = (self.vector_dim(lhs, what), self.vector_dim(rhs, what));
                let (l, r, at) = (text(lhs), text(rhs), rhs.location);
                self.require(
                    b.as_ref(),
                    a.as_ref(),
                    (HOMOGENEITY, what, at),
                    |got, want| {
                        Diagnostic::new(
                            at,
                            format!(
                                "sum of unlike units in {what}: `{l}` is {} but `{r}` is {}",
                                show(want),
                                show(got)
                            ),
                        )
                        .with_help("every term of a sum of vectors has the same unit")
                    },
                );
                a.or(b)
            }
            ExprKind::Binary {
                op: op @ (BinOp::Mul | BinOp::Div),
                lhs,
                rhs,
                ..
            } => {
                let a = if vector(self, lhs) {
                    self.vector_dim(lhs, what)
                } else {
                    self.dim(lhs, what)
                };
                let b = if vector(self, rhs) {
                    self.vector_dim(rhs, what)
                } else {
                    self.dim(rhs, what)
                };
                match op {
                    BinOp::Mul => a?.mul(&b?),
                    _ => a?.div(&b?),
                }
            }
            ExprKind::Call { func, args } if func == "vel" => {
                let a = self.vector_dim(args.first()?, what);
                a?.div(&Dim::of(Dimension::SECOND))
            }
            ExprKind::Call { func, args } if func == "cross" => {
                let dims: Vec<Option<Dim>> =
                    args.iter().map(|a| self.vector_dim(a, what)).collect();
                match dims.as_slice() {
                    [Some(a), Some(b)] => a.mul(b),
                    _ => None,
                }
            }
            _ => self.dim(e, what),
        }
    }

    pub(super) fn call(&mut self, func: &str, args: &[Expr], what: &str) -> Option<Dim> {
        if crate::model::vectors::is_vector_function(func) {
            let dims: Vec<Option<Dim>> = args.iter().map(|a| self.vector_dim(a, what)).collect();
            return match (func, dims.as_slice()) {
                ("dot" | "cross", [Some(a), Some(b)]) => a.mul(b),
                ("norm", [a]) => a.clone(),
                ("distance", [a, b]) => {
                    let (l, r, at) = (text(&args[0]), text(&args[1]), args[1].location);
                    self.require(b.as_ref(), a.as_ref(), (HOMOGENEITY, what, at), |got, want| {
                        Diagnostic::new(
                            at,
                            format!("the arguments of `distance` in {what} have unlike units: `{l}` is {} but `{r}` is {}", show(want), show(got)),
                        )
                        .with_help("`distance(A, B)` is the length of `A - B`: both are positions")
                    });
                    a.clone().or_else(|| b.clone())
                }
                _ => None,
            };
        }
        let dims: Vec<Option<Dim>> = args.iter().map(|a| self.dim(a, what)).collect();
        let one = Dim::of(Dimension::ONE);
        match (func, args, dims.as_slice()) {
            ("sqrt", _, [d]) => d.as_ref()?.pow(Rational::new(1, 2)?),
            ("abs", _, [d]) => d.clone(),
            ("sign" | "step", _, _) => Some(one),
            ("atan2", [y, x], [dy, dx]) => {
                let (y_text, x_text, at) = (text(y), text(x), x.location);
                self.require(dx.as_ref(), dy.as_ref(), (HOMOGENEITY, what, at), |got, want| {
                    Diagnostic::new(
                        at,
                        format!(
                            "the arguments of `atan2` in {what} have unlike units: `{y_text}` is {} but `{x_text}` is {}",
                            show(want),
                            show(got)
                        ),
                    )
                    .with_help("`atan2(y, x)` is the angle of the vector (x, y): both components have one unit")
                });
                Some(one)
            }
            (_, [a], [d]) => {
                let (arg_text, at) = (text(a), a.location);
                self.require(d.as_ref(), Some(&one), (HOMOGENEITY, what, at), |got, _| {
                    Diagnostic::new(
                        at,
                        format!(
                            "the argument of `{func}` in {what} is {}, but it must be a pure number (rad)",
                            show(got)
                        ),
                    )
                    .with_help(format!(
                        "`{func}` takes a pure number, such as an angle in rad: `{arg_text}` lacks a factor of unit {}, or a parameter in it has the wrong unit",
                        Dimension::ONE.checked_div(got).map_or_else(|| "?".to_string(), show)
                    ))
                });
                Some(one)
            }
            _ => None,
        }
    }
}
