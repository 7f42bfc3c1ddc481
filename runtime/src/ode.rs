//! First-order ordinary differential equations `ẏ = F(t, y)`, the form every integrator takes.

/// Why a right-hand side could not be evaluated at a state.
///
/// The integrator wraps this into an [`crate::IntegrationError`] that also carries `t`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RhsError {
    /// The mass matrix `M(q, t)` is not symmetric positive definite at this state, so
    /// `M q̈ = F` has no unique solution (Cholesky factorisation failed).
    #[error("the mass matrix is not positive definite (Cholesky failed)")]
    SingularMassMatrix,
    /// The matrix `[M Jᵀ; J 0]` of a constrained system is singular at this state: redundant
    /// constraints, a singular configuration of the mechanism, or `M` singular on the
    /// motions the constraints allow.
    #[error(
        "the constrained system [M Jᵀ; J 0] is singular (redundant constraints or a singular configuration)"
    )]
    SingularConstraintMatrix,
    /// The right-hand side produced NaN or ±∞ in component `index`.
    #[error("the right-hand side is not finite in component {index}")]
    NonFinite {
        /// Index into the state vector of the first non-finite component.
        index: usize,
    },
}

/// A first-order system `ẏ = F(t, y)` of dimension `dim()`.
///
/// Implementations write into a caller-owned buffer so that integrators need no heap
/// allocation per step.
pub trait OdeSystem {
    /// Dimension of the state `y` (for a mechanical system with `n` DOF: `2n`).
    fn dim(&self) -> usize;

    /// Evaluates `dy = F(t, y)`.
    ///
    /// # Shapes
    /// `y` and `dy` both have length `dim()`.
    ///
    /// # Errors
    /// [`RhsError`] when the right-hand side cannot be evaluated at `(t, y)`.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError>;
}

/// A closure `|t, y, dy| { … }` is an [`OdeSystem`] of a given dimension.
///
/// Used by tests and studies that integrate equations written by hand (`ẋ = x`, the test
/// oscillator).
pub struct OdeFn<F> {
    dim: usize,
    f: F,
}

impl<F: FnMut(f64, &[f64], &mut [f64])> OdeFn<F> {
    /// Wraps `f` as a system of dimension `dim`.
    pub fn new(dim: usize, f: F) -> Self {
        Self { dim, f }
    }
}

impl<F: FnMut(f64, &[f64], &mut [f64])> OdeSystem for OdeFn<F> {
    fn dim(&self) -> usize {
        self.dim
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        (self.f)(t, y, dy);
        Ok(())
    }
}
