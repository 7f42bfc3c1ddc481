//! What an integration is asked for: [`IntegratorOptions`], [`Tolerance`], [`OutputTimes`], and
//! the checks that reject bad input before any step is taken.

use serde::Serialize;

use super::error::IntegrationError;

/// A tolerance on the local error, the same for every state component or one per component.
///
/// Converts from `f64` ([`Tolerance::Scalar`]) and from `Vec<f64>`
/// ([`Tolerance::PerComponent`]), so builders accept either.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Tolerance {
    /// One value for every component of `y`.
    Scalar(f64),
    /// One value per component of `y`.
    ///
    /// # Shapes
    /// Length `dim` (the system's dimension); any other length is
    /// [`IntegrationError::ToleranceLengthMismatch`].
    PerComponent(Vec<f64>),
}

impl From<f64> for Tolerance {
    fn from(value: f64) -> Self {
        Tolerance::Scalar(value)
    }
}

impl From<Vec<f64>> for Tolerance {
    fn from(values: Vec<f64>) -> Self {
        Tolerance::PerComponent(values)
    }
}

/// Which samples a [`Solution`](super::Solution) records.
///
/// The choice never changes the steps an integrator takes: `At` samples are interpolated
/// from the steps that `Steps` would record, so the two agree exactly at common times.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub enum OutputTimes {
    /// `t0` and the end of every accepted step (the last sample is at `t_end`) (default).
    #[default]
    Steps,
    /// Exactly these times, in this order, evaluated by each method's dense output
    /// (never by the nearest step). A time equal to a step's end gets that step's state.
    ///
    /// The times must be sorted (non-decreasing; repeats are kept) and lie in `[t0, t_end]`,
    /// otherwise [`IntegrationError::OutputTimesNotSorted`] or
    /// [`IntegrationError::OutputTimeOutOfRange`].
    At(Vec<f64>),
}

/// How an [`Integrator`](super::Integrator) steps: tolerances, step sizes and limits.
///
/// Options a method does not use are still checked, so that one set of options is valid or
/// invalid for every method alike. The explicit fixed-step methods (Euler, midpoint,
/// [`RungeKutta4`](super::RungeKutta4), the partitioned methods, and the adaptive ones with
/// `fixed_step`) ignore `rtol` and `atol`; the implicit methods also use them, with fixed
/// steps, to stop their Newton iterations ([`RadauIIA5`](super::RadauIIA5): relative to
/// `atol + rtol |y|`; [`ImplicitMidpoint`](super::ImplicitMidpoint): `atol` as the scale of
/// components near zero).
///
/// # Units
/// `dt` and `dt_max` are in the units of `t` (s for mechanical models); `rtol` is
/// dimensionless; `atol` has the units of each state component.
///
/// # Solver limits
/// An integration stops with an [`IntegrationFailure`](super::IntegrationFailure) when
/// - `max_steps` step attempts (accepted and rejected) have not reached `t_end`
///   ([`IntegrationError::TooManySteps`]);
/// - the step size falls below `16 ε · max(|t|, t_end − t0)`, with `ε` the machine epsilon
///   ([`IntegrationError::StepSizeTooSmall`]); for fixed steps this is checked once, on `dt`;
/// - the right-hand side fails ([`IntegrationError::SingularMassMatrix`], and
///   [`IntegrationError::RhsNonFinite`], which adaptive methods first answer by shrinking the
///   step) or the state stops being finite ([`IntegrationError::NonFiniteState`]);
/// - the Newton iteration of an implicit method does not converge
///   ([`IntegrationError::NewtonDidNotConverge`]; adaptive methods first shrink the step) or
///   its iteration matrix is singular ([`IntegrationError::SingularIterationMatrix`]).
///
/// # Examples
/// ```
/// use eomgen_runtime::{IntegratorOptions, Tolerance};
///
/// let options = IntegratorOptions::default()
///     .with_rtol(1e-8)
///     .with_atol(vec![1e-10, 1e-8])
///     .with_dt_max(0.1);
/// assert_eq!(options.rtol, Tolerance::Scalar(1e-8));
/// assert_eq!(options.max_steps, 1_000_000);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IntegratorOptions {
    /// Relative tolerance on the local error, finite and `≥ 0` (default: 1e-6).
    pub rtol: Tolerance,
    /// Absolute tolerance on the local error, finite and `≥ 0`; `rtol` and `atol` must not
    /// both be zero for a component (default: 1e-9).
    pub atol: Tolerance,
    /// Fixed-step methods: the step, finite and `> 0`, the last step shortened to land exactly
    /// on `t_end` (default: `(t_end − t0) / 1000`). Adaptive methods: the first step tried
    /// (default: chosen automatically, Hairer–Nørsett–Wanner I, §II.4).
    pub dt: Option<f64>,
    /// Largest step, finite and `> 0`, for every method (default: `t_end − t0`).
    pub dt_max: Option<f64>,
    /// Most step attempts, accepted and rejected, before giving up (default: 1 000 000).
    pub max_steps: usize,
    /// Whether an adaptive method (Bogacki–Shampine, Dormand–Prince, DOP853, Radau IIA) takes
    /// constant steps `dt` with no error control, as convergence-order studies need
    /// (default: `false`).
    pub fixed_step: bool,
}

impl IntegratorOptions {
    /// The default relative tolerance of an integrator used on its own (tighter than SciPy's
    /// `solve_ivp` and MATLAB's `ode45`, whose defaults are 1e-3 and 1e-6); a simulation of a
    /// model uses
    /// `SimulationOptions::DEFAULT_RTOL` (1e-8) instead.
    pub const DEFAULT_RTOL: f64 = 1e-6;
    /// The default absolute tolerance of an integrator used on its own.
    pub const DEFAULT_ATOL: f64 = 1e-9;
    /// Number of fixed steps over `[t0, t_end]` when a fixed-step method is given no `dt`.
    pub const DEFAULT_FIXED_STEPS: u32 = 1000;
    /// The default limit on step attempts.
    pub const DEFAULT_MAX_STEPS: usize = 1_000_000;
}

impl Default for IntegratorOptions {
    fn default() -> Self {
        Self {
            rtol: Tolerance::Scalar(Self::DEFAULT_RTOL),
            atol: Tolerance::Scalar(Self::DEFAULT_ATOL),
            dt: None,
            dt_max: None,
            max_steps: Self::DEFAULT_MAX_STEPS,
            fixed_step: false,
        }
    }
}

impl IntegratorOptions {
    /// Sets the relative tolerance (a scalar `f64` or one value per component), each in
    /// `[0, 1)`.
    pub fn with_rtol(mut self, rtol: impl Into<Tolerance>) -> Self {
        self.rtol = rtol.into();
        self
    }

    /// Sets the absolute tolerance (a scalar `f64` or one value per component).
    pub fn with_atol(mut self, atol: impl Into<Tolerance>) -> Self {
        self.atol = atol.into();
        self
    }

    /// Sets the fixed step, or the first step of an adaptive method.
    pub fn with_dt(mut self, dt: f64) -> Self {
        self.dt = Some(dt);
        self
    }

    /// Sets the largest step.
    pub fn with_dt_max(mut self, dt_max: f64) -> Self {
        self.dt_max = Some(dt_max);
        self
    }

    /// Sets the most step attempts.
    pub fn with_max_steps(mut self, max_steps: usize) -> Self {
        self.max_steps = max_steps;
        self
    }

    /// Sets whether an adaptive method takes constant steps `dt` without error control.
    pub fn with_fixed_step(mut self, fixed_step: bool) -> Self {
        self.fixed_step = fixed_step;
        self
    }
}

/// The tolerances resolved to one `(rtol, atol)` pair per component, so the error norm of a
/// step needs no branching.
#[derive(Debug, Clone)]
pub(crate) struct ErrorWeights {
    pub(crate) rtol: Vec<f64>,
    pub(crate) atol: Vec<f64>,
}

impl ErrorWeights {
    /// The same `rtol` and `atol` for each of `dim` components (for unit tests of steppers).
    #[cfg(test)]
    pub(crate) fn uniform(dim: usize, rtol: f64, atol: f64) -> Self {
        Self {
            rtol: vec![rtol; dim],
            atol: vec![atol; dim],
        }
    }

    /// The error scale `atol_i + rtol_i · |y_i|` of component `index` at a magnitude `|y_i|`.
    #[inline]
    pub(crate) fn scale(&self, index: usize, magnitude: f64) -> f64 {
        self.atol[index] + self.rtol[index] * magnitude
    }
}

/// Rule: an integration runs forward over a non-empty finite interval, `t0 < t_end`
/// (integrating backwards is not supported).
pub(crate) fn check_time_span(t0: f64, t_end: f64) -> Result<(), IntegrationError> {
    if t0.is_finite() && t_end.is_finite() && t0 < t_end {
        Ok(())
    } else {
        Err(IntegrationError::InvalidTimeSpan { t0, t_end })
    }
}

/// Rule: the initial state has the system's dimension and every component is finite (a NaN
/// put in is reported, not integrated).
pub(crate) fn check_initial_state(dim: usize, t0: f64, y0: &[f64]) -> Result<(), IntegrationError> {
    if y0.len() != dim {
        return Err(IntegrationError::DimensionMismatch {
            expected: dim,
            found: y0.len(),
        });
    }
    match y0.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(IntegrationError::NonFiniteState { t: t0, index }),
        None => Ok(()),
    }
}

/// Rule: a tolerance has one value or `dim` values, each finite and non-negative, `rtol` below
/// 1 (a relative tolerance of 1 asks for no correct digit); and for
/// every component `rtol` and `atol` are not both zero, else the error scale of a component
/// that passes through zero is zero and no step could be accepted.
pub(crate) fn check_tolerances(
    options: &IntegratorOptions,
    dim: usize,
) -> Result<ErrorWeights, IntegrationError> {
    let rtol = resolve_tolerance(&options.rtol, "rtol", dim)?;
    let atol = resolve_tolerance(&options.atol, "atol", dim)?;
    if let Some(index) = (0..dim).find(|&i| rtol[i] == 0.0 && atol[i] == 0.0) {
        return Err(IntegrationError::ZeroTolerance { index });
    }
    Ok(ErrorWeights { rtol, atol })
}

/// Rule: a method that iterates Newton's method to a tolerance measured in the error weights
/// has `atol > 0` for every component (radau5.f's rule), since a component at 0 has weight 0.
pub(crate) fn check_absolute_tolerance(
    options: &IntegratorOptions,
    dim: usize,
    method: &'static str,
) -> Result<(), IntegrationError> {
    let atol = resolve_tolerance(&options.atol, "atol", dim)?;
    match atol.iter().position(|&a| a == 0.0) {
        Some(index) => Err(IntegrationError::AbsoluteToleranceRequired { method, index }),
        None => Ok(()),
    }
}

/// One value per component of a tolerance named `option`, each checked.
fn resolve_tolerance(
    tolerance: &Tolerance,
    option: &'static str,
    dim: usize,
) -> Result<Vec<f64>, IntegrationError> {
    let values = match tolerance {
        Tolerance::Scalar(value) => std::slice::from_ref(value),
        Tolerance::PerComponent(values) if values.len() == dim => values.as_slice(),
        Tolerance::PerComponent(values) => {
            return Err(IntegrationError::ToleranceLengthMismatch {
                option,
                expected: dim,
                found: values.len(),
            });
        }
    };
    if let Some((index, &value)) = values.iter().enumerate().find(|(_, value)| {
        // A relative tolerance of 1 or more asks for no correct digit: the error estimate
        // then no longer steers the step (it grows until the solution is lost).
        !(value.is_finite() && **value >= 0.0) || (option == "rtol" && **value >= 1.0)
    }) {
        return Err(IntegrationError::InvalidTolerance {
            option,
            index,
            value,
        });
    }
    Ok(match tolerance {
        Tolerance::Scalar(value) => vec![*value; dim],
        Tolerance::PerComponent(values) => values.clone(),
    })
}

/// Rule: `dt` and `dt_max`, when given, are finite and positive.
pub(crate) fn check_step_sizes(options: &IntegratorOptions) -> Result<(), IntegrationError> {
    for (option, value) in [("dt", options.dt), ("dt_max", options.dt_max)] {
        if let Some(value) = value
            && !(value.is_finite() && value > 0.0)
        {
            return Err(IntegrationError::InvalidStepSize { option, value });
        }
    }
    Ok(())
}

/// Rule: requested output times lie in `[t0, t_end]` and are sorted (non-decreasing), so that
/// one forward pass over the steps serves them all.
pub(crate) fn check_output_times(
    output: &OutputTimes,
    t0: f64,
    t_end: f64,
) -> Result<(), IntegrationError> {
    let OutputTimes::At(times) = output else {
        return Ok(());
    };
    for (index, &t) in times.iter().enumerate() {
        if !(t0 <= t && t <= t_end) {
            return Err(IntegrationError::OutputTimeOutOfRange {
                index,
                t,
                t0,
                t_end,
            });
        }
        if index > 0 && t < times[index - 1] {
            return Err(IntegrationError::OutputTimesNotSorted {
                index,
                t,
                previous: times[index - 1],
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_documented_ones() {
        let options = IntegratorOptions::default();
        assert_eq!(options.rtol, Tolerance::Scalar(1e-6));
        assert_eq!(options.atol, Tolerance::Scalar(1e-9));
        assert_eq!(options.dt, None);
        assert_eq!(options.dt_max, None);
        assert_eq!(options.max_steps, 1_000_000);
        assert!(!options.fixed_step);
    }

    #[test]
    fn tolerances_resolve_per_component() {
        let options = IntegratorOptions::default()
            .with_rtol(1e-3)
            .with_atol(vec![1.0, 2.0]);
        let weights = check_tolerances(&options, 2).unwrap();
        assert_eq!(weights.rtol, vec![1e-3, 1e-3]);
        assert_eq!(weights.atol, vec![1.0, 2.0]);
        assert_eq!(weights.scale(1, 10.0), 2.0 + 1e-2);
    }

    #[test]
    fn bad_tolerances_are_errors() {
        let wrong_length = IntegratorOptions::default().with_atol(vec![1e-9; 3]);
        assert_eq!(
            check_tolerances(&wrong_length, 2).unwrap_err(),
            IntegrationError::ToleranceLengthMismatch {
                option: "atol",
                expected: 2,
                found: 3
            }
        );
        let negative = IntegratorOptions::default().with_rtol(vec![1e-6, -1e-6]);
        assert!(matches!(
            check_tolerances(&negative, 2).unwrap_err(),
            IntegrationError::InvalidTolerance {
                option: "rtol",
                index: 1,
                ..
            }
        ));
        let loose = IntegratorOptions::default().with_rtol(1.0);
        assert!(matches!(
            check_tolerances(&loose, 2).unwrap_err(),
            IntegrationError::InvalidTolerance { option: "rtol", .. }
        ));
        assert!(check_tolerances(&IntegratorOptions::default().with_rtol(0.99), 2).is_ok());
        let nan_scalar = IntegratorOptions::default().with_atol(f64::NAN);
        assert!(matches!(
            check_tolerances(&nan_scalar, 0).unwrap_err(),
            IntegrationError::InvalidTolerance { option: "atol", .. }
        ));
        let both_zero = IntegratorOptions::default()
            .with_rtol(0.0)
            .with_atol(vec![1e-9, 0.0]);
        assert_eq!(
            check_tolerances(&both_zero, 2).unwrap_err(),
            IntegrationError::ZeroTolerance { index: 1 }
        );
    }

    #[test]
    fn output_times_must_be_sorted_and_in_range() {
        let sorted = OutputTimes::At(vec![0.0, 0.5, 0.5, 1.0]);
        assert!(check_output_times(&sorted, 0.0, 1.0).is_ok());
        let unsorted = OutputTimes::At(vec![0.0, 0.6, 0.5]);
        assert_eq!(
            check_output_times(&unsorted, 0.0, 1.0).unwrap_err(),
            IntegrationError::OutputTimesNotSorted {
                index: 2,
                t: 0.5,
                previous: 0.6
            }
        );
        let outside = OutputTimes::At(vec![0.5, 1.5]);
        assert!(matches!(
            check_output_times(&outside, 0.0, 1.0).unwrap_err(),
            IntegrationError::OutputTimeOutOfRange { index: 1, .. }
        ));
        let nan = OutputTimes::At(vec![f64::NAN]);
        assert!(check_output_times(&nan, 0.0, 1.0).is_err());
    }

    #[test]
    fn time_span_and_steps_are_checked() {
        assert!(check_time_span(0.0, 1.0).is_ok());
        assert!(check_time_span(1.0, 1.0).is_err());
        assert!(check_time_span(0.0, f64::INFINITY).is_err());
        let bad_dt = IntegratorOptions::default().with_dt(-0.1);
        assert_eq!(
            check_step_sizes(&bad_dt).unwrap_err(),
            IntegrationError::InvalidStepSize {
                option: "dt",
                value: -0.1
            }
        );
        let nan_dt_max = IntegratorOptions::default().with_dt_max(f64::NAN);
        assert!(check_step_sizes(&nan_dt_max).is_err());
    }
}
