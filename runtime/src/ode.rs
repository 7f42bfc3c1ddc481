//! First-order ordinary differential equations `ẏ = F(t, y)`, the form every integrator takes,
//! and the event functions an integration locates on them ([`EventSpec`], [`EventDirection`],
//! [`Event`]; the root finding is in [`crate::integrate`]).

use serde::Serialize;

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
    /// Projection onto the constraints failed: Newton left residual `residual` in some
    /// constraint.
    #[error("projection onto the constraints failed (residual {residual:e})")]
    ProjectionFailed {
        /// The largest constraint residual left.
        residual: f64,
    },
    /// Event function `index` ([`OdeSystem::event_values`]) is NaN.
    #[error("event function {index} is NaN")]
    EventNotFinite {
        /// Index of the event function.
        index: usize,
    },
    /// The right-hand side produced NaN or ±∞ in component `index`.
    #[error("the right-hand side is not finite in component {index}")]
    NonFinite {
        /// Index into the state vector of the first non-finite component.
        index: usize,
    },
    /// The Jacobian `∂F/∂y` has NaN or ±∞ in row `row`, where `F` itself is finite (an
    /// implicit method then differences `F` instead, see
    /// [`OdeSystem::jacobian`]).
    #[error("the Jacobian of the right-hand side is not finite in row {row}")]
    JacobianNonFinite {
        /// The first row (the component of `F`) whose derivative is not finite.
        row: usize,
    },
}

/// A first-order system `ẏ = F(t, y)` of dimension `dim()`.
///
/// Implementations write into a caller-owned buffer so that integrators need no heap
/// allocation per step. Two optional pieces of structure serve particular methods:
///
/// - [`jacobian`](Self::jacobian), the exact `∂F/∂y`, for the implicit methods
///   ([`ImplicitMidpoint`](crate::ImplicitMidpoint), [`RadauIIA5`](crate::RadauIIA5)); without
///   it they difference `F`;
/// - [`second_order_dim`](Self::second_order_dim), the split `y = [q; q̇]` with `q̇' = q̈(t, q, q̇)`,
///   which the partitioned methods ([`SymplecticEuler`](crate::SymplecticEuler),
///   [`StormerVerlet`](crate::StormerVerlet)) require.
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

    /// Writes the Jacobian `∂F/∂y` at `(t, y)` into `jac` and returns `Ok(true)`, or returns
    /// `Ok(false)` without writing to ask the caller to approximate it by finite differences
    /// of [`rhs`](Self::rhs) (the default).
    ///
    /// The implicit integrators call this once per Jacobian they need; the finite-difference
    /// fallback costs `dim()` evaluations of `F` and uses the increments of Hairer's RADAU5,
    /// `δⱼ = √(ε · max(10⁻⁵, |yⱼ|))`.
    ///
    /// # Shapes
    /// `y` has length `dim()`; `jac` has `dim()²` entries, column-major (nalgebra's storage
    /// order): entry `(i, j) = ∂Fᵢ/∂yⱼ` is `jac[i + j · dim()]`.
    ///
    /// # Errors
    /// [`RhsError`] when the Jacobian cannot be evaluated at `(t, y)`.
    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        let _ = (t, y, jac);
        Ok(false)
    }

    /// `Some(n)` when the system is second order: `dim() = 2n`, `y = [q; q̇]` with `q` and `q̇`
    /// of length `n`, and `F(t, y) = [q̇; q̈(t, q, q̇)]`; `None` otherwise (the default).
    ///
    /// Partitioned methods rely on it: they advance `q` with `q̇` themselves and read only the
    /// accelerations, the lower half of `F`.
    fn second_order_dim(&self) -> Option<usize> {
        None
    }

    /// Called by every integrator after each accepted step, with the new state `y` at `t`;
    /// may change `y` (projection of a constrained system onto its constraint manifold) and
    /// returns whether it did, in which case the method restarts from the changed state. The
    /// default does nothing.
    ///
    /// # Errors
    /// [`RhsError`] when the state cannot be corrected (a projection whose Newton iteration
    /// fails).
    fn after_step(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RhsError> {
        let _ = (t, y);
        Ok(false)
    }

    /// Whether [`Self::after_step`] can change a state, asked once at the start of each
    /// integration. `false` lets the integrators skip the call after every step, with the copy
    /// of the state it is given (about 50 instructions a step on the double pendulum, 1–2 % of
    /// a Taylor step at 10⁻⁴). The default, `true`, always calls it: a system whose
    /// `after_step` never changes the state may say `false`.
    fn corrects_state(&self) -> bool {
        true
    }

    /// The event functions `gᵢ(t, y)` whose zeros every integrator locates, with their names,
    /// directions and whether they stop the integration ([`Solution::events`](crate::Solution::events));
    /// none by default.
    fn event_specs(&self) -> &[EventSpec] {
        &[]
    }

    /// Evaluates the event functions at `(t, y)` into `g` (one entry per
    /// [`event_specs`](Self::event_specs) entry). Called once per accepted step and during
    /// root finding, at states of the method's dense output.
    ///
    /// # Errors
    /// [`RhsError`] when they cannot be evaluated (a model event that needs `q̈` or the
    /// constraint forces at a state where `M` is singular).
    fn event_values(&mut self, t: f64, y: &[f64], g: &mut [f64]) -> Result<(), RhsError> {
        let _ = (t, y, g);
        Ok(())
    }

    /// Whether [`taylor_coefficients`](Self::taylor_coefficients) works: `Ok` for a model with
    /// generated Taylor recurrences ([`crate::taylor`]), else why not. The default (equations
    /// written as a closure) has none.
    ///
    /// # Errors
    /// [`TaylorUnsupported`](eomgen_description::taylor::TaylorUnsupported) naming what is missing.
    fn taylor_support(&self) -> Result<(), eomgen_description::taylor::TaylorUnsupported> {
        Err(eomgen_description::taylor::TaylorUnsupported::NotGenerated)
    }

    /// The Taylor coefficients of the solution through `(t, y)` up to `order`:
    /// `out[k · dim + i] = yᵢ^[k] = yᵢ⁽ᵏ⁾(t)/k!` for `k = 0 … order`, for the
    /// [`Taylor`](crate::Taylor) method ([`crate::taylor::series_of_motion`]).
    ///
    /// # Errors
    /// [`RhsError::SingularMassMatrix`], [`RhsError::SingularConstraintMatrix`],
    /// [`RhsError::NonFinite`] (a coefficient, by component); the default, for a system without recurrences, is
    /// [`RhsError::NonFinite`] at component 0 (the Taylor method checks
    /// [`taylor_support`](Self::taylor_support) before it asks).
    fn taylor_coefficients(
        &mut self,
        t: f64,
        y: &[f64],
        order: usize,
        out: &mut [f64],
    ) -> Result<(), RhsError> {
        let _ = (t, y, order, out);
        Err(RhsError::NonFinite { index: 0 })
    }

    /// The largest step `≤ h` over which the last [`taylor_coefficients`]' series stay on
    /// the principal branch of every square root and non-integer power
    /// ([`crate::taylor::branch_step`]); `h` for a system without recurrences.
    ///
    /// [`taylor_coefficients`]: Self::taylor_coefficients
    fn taylor_branch_step(&self, order: usize, h: f64) -> f64 {
        let _ = order;
        h
    }
}

/// A closure `|t, y, dy| { … }` is an [`OdeSystem`] of a given dimension.
///
/// Used by tests and studies that integrate equations written by hand (`ẋ = x`, the test
/// oscillator). It has no exact Jacobian (implicit methods difference it).
pub struct OdeFn<F> {
    dim: usize,
    second_order_dim: Option<usize>,
    f: F,
}

impl<F: FnMut(f64, &[f64], &mut [f64])> OdeFn<F> {
    /// Wraps `f` as a system of dimension `dim`.
    pub fn new(dim: usize, f: F) -> Self {
        Self {
            dim,
            second_order_dim: None,
            f,
        }
    }

    /// Wraps `f` as a second-order system with `num_dofs` coordinates: `y = [q; q̇]` has
    /// `2 num_dofs` entries and `f` must write `dy = [q̇; q̈]`, as
    /// [`OdeSystem::second_order_dim`] states.
    ///
    /// # Examples
    /// ```
    /// use eomgen_runtime::{OdeFn, OdeSystem};
    ///
    /// // The pendulum q̈ = −sin q.
    /// let pendulum = OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
    ///     dy[0] = y[1];
    ///     dy[1] = -y[0].sin();
    /// });
    /// assert_eq!(pendulum.dim(), 2);
    /// assert_eq!(pendulum.second_order_dim(), Some(1));
    /// ```
    pub fn second_order(num_dofs: usize, f: F) -> Self {
        Self {
            dim: 2 * num_dofs,
            second_order_dim: Some(num_dofs),
            f,
        }
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

    fn second_order_dim(&self) -> Option<usize> {
        self.second_order_dim
    }
}

/// A system with event functions added to its own: `g` writes the added functions' values
/// and may read the system (for a model: `q̈` or the constraint forces).
///
/// The added events come after the system's own ([`OdeSystem::event_specs`]); everything
/// else is the system's.
///
/// # Examples
/// ```
/// use eomgen_runtime::{
///     DormandPrince853, EventDirection, EventSpec, Integrator, IntegratorOptions, OdeFn,
///     OutputTimes, WithEvents,
/// };
///
/// // A ball thrown up at 10 m/s under g = 10 m/s², stopped when it lands: t = 2 s.
/// let mut ball = OdeFn::second_order(1, |_t: f64, y: &[f64], dy: &mut [f64]| {
///     dy[0] = y[1];
///     dy[1] = -10.0;
/// });
/// let landing = EventSpec::new("landing", EventDirection::Falling, true);
/// let mut system = WithEvents::new(&mut ball, vec![landing], |_ball: &mut OdeFn<_>, _t, y: &[f64], g: &mut [f64]| {
///     g[0] = y[0];
///     Ok(())
/// });
/// let solution = DormandPrince853::new().integrate(
///     &mut system, 0.0, &[0.0, 10.0], 5.0, &OutputTimes::Steps, &IntegratorOptions::default(),
/// )?;
/// let landed = &solution.events[0];
/// assert!((landed.t - 2.0).abs() < 1e-12);
/// assert_eq!(solution.terminated_by_event, Some(0));
/// assert_eq!(solution.last().map(|(t, _)| t), Some(landed.t));
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
pub struct WithEvents<'a, S: ?Sized, G> {
    system: &'a mut S,
    specs: Vec<EventSpec>,
    own: usize,
    g: G,
}

impl<'a, S, G> WithEvents<'a, S, G>
where
    S: OdeSystem + ?Sized,
    G: FnMut(&mut S, f64, &[f64], &mut [f64]) -> Result<(), RhsError>,
{
    /// `system` with the events `added`, whose values `g(system, t, y, out)` writes into
    /// `out` (one entry per added spec).
    pub fn new(system: &'a mut S, added: Vec<EventSpec>, g: G) -> Self {
        let mut specs = system.event_specs().to_vec();
        let own = specs.len();
        specs.extend(added);
        Self {
            system,
            specs,
            own,
            g,
        }
    }
}

impl<S, G> OdeSystem for WithEvents<'_, S, G>
where
    S: OdeSystem + ?Sized,
    G: FnMut(&mut S, f64, &[f64], &mut [f64]) -> Result<(), RhsError>,
{
    fn dim(&self) -> usize {
        self.system.dim()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        self.system.rhs(t, y, dy)
    }

    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        self.system.jacobian(t, y, jac)
    }

    fn second_order_dim(&self) -> Option<usize> {
        self.system.second_order_dim()
    }

    fn after_step(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RhsError> {
        self.system.after_step(t, y)
    }

    fn corrects_state(&self) -> bool {
        self.system.corrects_state()
    }

    fn event_specs(&self) -> &[EventSpec] {
        &self.specs
    }

    fn event_values(&mut self, t: f64, y: &[f64], g: &mut [f64]) -> Result<(), RhsError> {
        let (own, added) = g.split_at_mut(self.own.min(g.len()));
        self.system.event_values(t, y, own)?;
        (self.g)(self.system, t, y, added)
    }

    fn taylor_support(&self) -> Result<(), eomgen_description::taylor::TaylorUnsupported> {
        self.system.taylor_support()
    }

    fn taylor_coefficients(
        &mut self,
        t: f64,
        y: &[f64],
        order: usize,
        out: &mut [f64],
    ) -> Result<(), RhsError> {
        self.system.taylor_coefficients(t, y, order, out)
    }

    fn taylor_branch_step(&self, order: usize, h: f64) -> f64 {
        self.system.taylor_branch_step(order, h)
    }
}

pub use eomgen_description::{EventDirection, EventSpec};

/// Index of the first entry of `values` that is NaN or infinite, if any.
///
/// The common case (all finite) takes one branch. An entry's exponent field alone (sign and
/// mantissa cleared) plus one unit of that field reaches the sign bit exactly when the field is
/// all ones, that is when the entry is infinite or NaN (of either sign); the OR of those sums
/// over the entries has its sign bit set exactly when an entry is not finite, and only then is
/// the entry searched for. An AND, an addition and an OR an entry, all on integers, so the
/// compiler may split the OR over several vector accumulators (four in the build measured):
/// no chain runs from one entry to the next. (The largest exponent field taken as an `f64`
/// in one vector of four lanes, as before, was a chain of a comparison and a blend every
/// four entries: about three quarters of the Taylor series' driver in `perf` on the figure
/// eight at 10⁻⁹, whose 156 coefficients it checks each step; docs/performance.md, "Where a
/// figure-eight step's time goes against heyoka's".)
#[inline]
pub(crate) fn first_non_finite(values: &[f64]) -> Option<usize> {
    const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
    // One unit of the exponent field: `EXPONENT + UNIT` is the sign bit, and any smaller
    // field plus `UNIT` stays below it (no overflow: the sum is at most `1 << 63`).
    const UNIT: u64 = 1 << 52;
    const SIGN: u64 = 1 << 63;
    let flags = values
        .iter()
        .fold(0u64, |any, v| any | ((v.to_bits() & EXPONENT) + UNIT));
    if flags & SIGN == 0 {
        None
    } else {
        values.iter().position(|v| !v.is_finite())
    }
}

/// A located zero of an event function.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Event {
    /// Index of the event function (into the system's [`EventSpec`]s).
    pub index: usize,
    /// Its name.
    pub name: String,
    /// Time of the zero (units of `t`).
    pub t: f64,
    /// State at `t` from the dense output (`dim` entries).
    pub y: Vec<f64>,
    /// The crossing's direction: [`EventDirection::Rising`] or [`EventDirection::Falling`].
    pub direction: EventDirection,
    /// Whether it ended the integration.
    pub terminal: bool,
}

#[cfg(test)]
pub(crate) mod tests {
    #[test]
    fn first_non_finite_finds_the_first_nan_or_infinity_in_any_position() {
        for len in 0..11 {
            let finite: Vec<f64> = (0..len).map(|i| i as f64 * 1e300 - 3e300).collect();
            assert_eq!(first_non_finite(&finite), None, "{finite:?}");
            for at in 0..len {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut v = finite.clone();
                    v[at] = bad;
                    if at + 1 < len {
                        v[len - 1] = f64::NAN;
                    }
                    assert_eq!(first_non_finite(&v), Some(at), "{v:?}");
                }
            }
        }
        // The edges of the finite: the largest, the smallest normal and subnormal, zeros of
        // either sign, alone and among others of every length up to 40 (past the vectors'
        // unrolled widths).
        let edges = [
            f64::MAX,
            -f64::MAX,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            f64::from_bits(1),
            -f64::from_bits(1),
            0.0,
            -0.0,
            1.0,
        ];
        for len in 0..=40 {
            let v: Vec<f64> = (0..len).map(|i| edges[i % edges.len()]).collect();
            assert_eq!(first_non_finite(&v), None, "{v:?}");
            for at in [0, len / 2, len.saturating_sub(1)] {
                if at < len {
                    // NaNs quiet and signalling, with the smallest and largest payloads.
                    for bad in [
                        f64::NAN,
                        -f64::NAN,
                        f64::from_bits(0x7ff0_0000_0000_0001),
                        f64::from_bits(0xfff7_ffff_ffff_ffff),
                        f64::from_bits(0x7fff_ffff_ffff_ffff),
                        f64::INFINITY,
                        f64::NEG_INFINITY,
                    ] {
                        let mut w = v.clone();
                        w[at] = bad;
                        assert_eq!(first_non_finite(&w), Some(at), "{w:?}");
                    }
                }
            }
        }
    }

    use super::*;

    /// `ẏ = λy` with its exact Jacobian, for tests of the implicit methods (one Newton
    /// correction then solves a linear stage equation to rounding).
    pub(crate) struct Linear(pub(crate) f64);

    impl OdeSystem for Linear {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
            dy[0] = self.0 * y[0];
            Ok(())
        }
        fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
            jac[0] = self.0;
            Ok(true)
        }
    }

    #[test]
    fn directions_count_the_right_crossings() {
        use EventDirection::*;
        assert!(Rising.crosses(-1.0, 1.0) && Rising.crosses(-1.0, 0.0));
        assert!(!Rising.crosses(1.0, -1.0) && !Rising.crosses(0.0, 1.0));
        assert!(Falling.crosses(1.0, -1.0) && Falling.crosses(2.0, 0.0));
        assert!(!Falling.crosses(-1.0, 1.0) && !Falling.crosses(0.0, -1.0));
        assert!(Both.crosses(1.0, -1.0) && Both.crosses(-1.0, 1.0));
        assert!(!Both.crosses(1.0, 2.0) && !Both.crosses(f64::NAN, 1.0));
        for d in [Rising, Falling, Both] {
            assert_eq!(EventDirection::from_name(d.name()), Some(d));
        }
        assert_eq!(EventDirection::from_name("up"), None);
    }
}
