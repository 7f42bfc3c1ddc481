//! Why an integration stopped, read off the model where it stopped: a mass matrix that is not
//! positive definite (a zero or negative mass, inertia or length, or coordinates that are
//! singular there) or a right-hand side that leaves a function's domain just ahead. A step-size
//! underflow says only that the integrator could not go on; these say what in the model made
//! it so, so that a front end does not blame stiffness for a negative mass.

use nalgebra::DMatrix;
use serde::Serialize;

use crate::integrate::IntegrationError;
use crate::model_info::ModelInfo;
use crate::ode::OdeSystem;

/// What the model shows at the state where an integration stopped
/// ([`failure_cause`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum FailureCause {
    /// `M(q, t)` is singular or indefinite at every configuration tried (the state where the
    /// run stopped, the start, and configurations around it): a parameter makes the kinetic
    /// energy degenerate for every motion — a zero mass, inertia or length, or a negative one.
    MassMatrixDegenerateEverywhere {
        /// The parameters whose value is zero or negative, `(name, value)`.
        suspects: Vec<(String, f64)>,
    },
    /// `M` has a negative eigenvalue where the run stopped (kinetic energy negative for some
    /// motion) while some parameters are negative: a negative mass or inertia.
    NegativeParameters {
        /// The time at which `M` was examined (s).
        t: f64,
        /// `M`'s smallest eigenvalue over its largest in magnitude there.
        eigenvalue_ratio: f64,
        /// The parameters whose value is negative, `(name, value)`.
        suspects: Vec<(String, f64)>,
    },
    /// `M` is singular (or not positive definite) where the run stopped but regular elsewhere,
    /// with no negative parameter: the coordinates are singular at that configuration (an
    /// angle at which two of them describe the same motion, a bar folded onto another).
    SingularCoordinates {
        /// The time at which `M` was examined (s).
        t: f64,
        /// `M`'s smallest eigenvalue over its largest in magnitude there.
        eigenvalue_ratio: f64,
    },
    /// A diagonal entry of `M` has collapsed where the run stopped (to a millionth of its
    /// value at the start or less) while `M` scaled to a unit diagonal stays regular: the
    /// coordinate moves (nearly) no mass or inertia there — an inertia `m (1 − x)²` at
    /// `x = 1`, a polar angle at the origin — and its speed grows without bound as it gets
    /// there. The scaled test cannot see it: it divides each row and column by that entry.
    InertiaVanishes {
        /// The time at which `M` was examined (s).
        t: f64,
        /// The coordinate whose diagonal entry collapsed (the one that fell furthest).
        coordinate: String,
        /// Its diagonal entry `Mᵢᵢ` there (units of that entry: kg, kg·m², …).
        diagonal: f64,
        /// Its diagonal entry at the start.
        start: f64,
    },
    /// `M` is regular, but the forcing is not finite at the state or a little ahead of it
    /// along the motion: a function leaves its domain there (`ln` or `sqrt` of a negative
    /// number, a division by zero).
    ForcingNotFinite {
        /// The time of the state examined (s).
        t: f64,
        /// Whether it is already not finite at that state (else only a little ahead).
        at_state: bool,
    },
    /// The step collapsed far below what stiffness would impose: with the fastest rate of the
    /// linearisation there, `ρ` (the spectral radius of `∂f/∂y`, 1/s), an explicit method is
    /// held to steps of order `1/ρ`, but the last step tried was `h ≪ 1/ρ`. The solution itself
    /// loses smoothness there: it blows up, or reaches the edge of a function's domain (a
    /// particle falling into `ln x` at `x = 0` with unbounded speed).
    NotStiffness {
        /// The time reached (s).
        t: f64,
        /// The last step size tried (s).
        step_size: f64,
        /// The spectral radius of the Jacobian of the first-order system there (1/s).
        spectral_radius: f64,
        /// The largest real part of its eigenvalues (1/s): a positive one is a mode that grows
        /// as `e^{growth t}`.
        growth_rate: f64,
    },
}

impl std::fmt::Display for FailureCause {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let list = |suspects: &[(String, f64)]| {
            suspects
                .iter()
                .map(|(name, value)| format!("{name} = {value}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        match self {
            FailureCause::MassMatrixDegenerateEverywhere { suspects } if suspects.is_empty() => {
                write!(
                    f,
                    "the mass matrix is singular at every configuration tried: some coordinate has no inertia (no mass, inertia or length moves with it)"
                )
            }
            FailureCause::MassMatrixDegenerateEverywhere { suspects } => write!(
                f,
                "the mass matrix is singular at every configuration tried: a mass, inertia or length of zero or below gives some motion no kinetic energy ({})",
                list(suspects)
            ),
            FailureCause::NegativeParameters {
                t,
                eigenvalue_ratio,
                suspects,
            } => write!(
                f,
                "the mass matrix becomes singular or indefinite at t = {t} (smallest over largest eigenvalue {eigenvalue_ratio:.3e}): a negative mass or inertia lets the kinetic energy vanish or turn negative for some motion ({})",
                list(suspects)
            ),
            FailureCause::SingularCoordinates {
                t,
                eigenvalue_ratio,
            } => write!(
                f,
                "the mass matrix loses rank at t = {t} (smallest over largest eigenvalue {eigenvalue_ratio:.3e}) though it is regular elsewhere: the coordinates are singular at that configuration"
            ),
            FailureCause::InertiaVanishes {
                t,
                coordinate,
                diagonal,
                start,
            } => write!(
                f,
                "the inertia of `{coordinate}` vanishes at t = {t}: its diagonal entry of the mass matrix fell to {diagonal:.3e} from {start:.3e} at the start, so `{coordinate}` moves (nearly) no mass there and its speed grows without bound (a coordinate singular at that configuration, or a mass or length that goes to zero with it)"
            ),
            FailureCause::ForcingNotFinite { t, at_state: true } => write!(
                f,
                "the forcing is not finite at t = {t}: a function is evaluated outside its domain there (ln or sqrt of a negative number, a division by zero)"
            ),
            FailureCause::NotStiffness {
                t,
                step_size,
                spectral_radius,
                growth_rate,
            } => write!(
                f,
                "not stiffness: steps of {step_size:.1e} s failed at t = {t}, where the linearisation's fastest rate is {spectral_radius:.3e}/s and its fastest growth {growth_rate:.3e}/s; stiffness holds steps near 1/rate with decaying modes, so the solution itself loses smoothness there (it blows up, or reaches the edge of a function's domain)"
            ),
            FailureCause::ForcingNotFinite { t, at_state: false } => write!(
                f,
                "the forcing stops being finite just after t = {t}, along the motion: a function leaves its domain there (ln or sqrt of a negative number, a division by zero)"
            ),
        }
    }
}

/// Below this ratio of `M`'s smallest eigenvalue to its largest magnitude, `M` counts as
/// singular: a few hundred roundings of a well-scaled matrix stay far above it, and an
/// integration stalls long before an `M` this close to singular is reached.
const SINGULAR_RATIO: f64 = 1e-10;

/// A drop of `M`'s eigenvalue ratio by this factor from the start (or, elsewhere, a ratio this
/// factor above the one where the run stopped) tells a configuration where `M` becomes
/// singular: an explicit method stalls when M's ratio is still ~1e-9 (the double pendulum with
/// a negative upper mass stopped at 3.8e-9, from 0.5 at the start).
const DROP: f64 = 1e-6;

/// The smallest eigenvalue of `M` scaled to a unit diagonal, `D^-½ M D^-½` with
/// `D = diag |Mᵢᵢ|`, over its largest magnitude at `(t, y)` (`-∞` when `M` is not finite or a
/// diagonal entry is 0 or negative), for `y = [q; q̇]`; `None`, no verdict, where the
/// eigenvalue solver does not converge. The scaling makes the ratio independent of the
/// coordinates' units (a mass in kg beside an inertia in kg·m² of 1e-11).
fn eigenvalue_ratio(model: &dyn ModelInfo, t: f64, y: &[f64]) -> Option<f64> {
    let (m, _) = model.mass_matrix_and_forcing(t, y);
    if m.iter().any(|v| !v.is_finite()) {
        return Some(f64::NEG_INFINITY);
    }
    let n = m.nrows();
    let diagonal: Vec<f64> = (0..n).map(|i| m[(i, i)]).collect();
    if diagonal.iter().any(|d| *d <= 0.0) {
        return Some(f64::NEG_INFINITY);
    }
    // √dᵢ √dⱼ rather than √(dᵢ dⱼ), which overflows or underflows for entries beyond 1e±154.
    let root: Vec<f64> = diagonal.iter().map(|d| d.sqrt()).collect();
    let scaled = DMatrix::from_fn(n, n, |i, j| {
        0.5 * (m[(i, j)] + m[(j, i)]) / (root[i] * root[j])
    });
    let eigenvalues = crate::linalg::symmetric_eigen(scaled)?.eigenvalues;
    let largest = eigenvalues.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    let smallest = eigenvalues.iter().fold(f64::INFINITY, |a, &v| a.min(v));
    Some(if largest == 0.0 {
        f64::NEG_INFINITY
    } else {
        smallest / largest
    })
}

/// What the model shows at the state `(t, y)` where an integration stopped (`y = [q; q̇]`,
/// length `2n`; `y0` the start), or `None` when `M` is positive definite and the forcing is
/// finite there and a little ahead: then the integrator's own reason (stiffness, a
/// singularity of the solution) stands.
///
/// `M` is examined at `y`; each diagonal entry against its value at the start (a collapsed
/// one is named, [`FailureCause::InertiaVanishes`]: the unit-diagonal test below cannot see
/// it); if it is not positive definite (its smallest eigenvalue at most
/// `1e-10` of its largest magnitude, or a millionfold smaller in ratio than at the start),
/// also at the start and at eight configurations `q ± δ`
/// around `y` (δ = 0.3 in every coordinate, alternating signs), to tell a parameter (singular
/// everywhere), a negative parameter, and coordinates singular at one configuration apart. The
/// forcing is evaluated at `y` and at `y + s ẏ` for `s` from 1e-9 to 1e-3 s.
///
/// # Shapes
/// `y` and `y0` have length `2n`, `n = model.num_dofs()`; other lengths give `None`.
pub fn failure_cause(
    model: &mut dyn ModelInfo,
    error: &IntegrationError,
    t: f64,
    y: &[f64],
    y0: &[f64],
) -> Option<FailureCause> {
    let n = model.num_dofs();
    if y.len() != 2 * n || y0.len() != 2 * n {
        return None;
    }
    let parameters: Vec<(String, f64)> = model
        .description()
        .parameter_names()
        .iter()
        .map(|s| s.to_string())
        .zip(model.parameter_values())
        .collect();
    // A run out of steps stopped for its settings, not at a configuration.
    if matches!(error, IntegrationError::TooManySteps { .. }) {
        return None;
    }
    let ratio = eigenvalue_ratio(model, t, y)?;
    let start_ratio = eigenvalue_ratio(model, 0.0, y0)?;
    // Singular: below an absolute floor, or a millionfold below its value at the start (a
    // badly scaled but regular M keeps its ratio along the motion).
    if singular(ratio) || ratio < DROP * start_ratio {
        return Some(singular_mass_cause(
            model,
            t,
            y,
            n,
            (ratio, start_ratio),
            parameters,
        ));
    }
    if let Some(cause) = vanishing_inertia(model, t, y, y0) {
        return Some(cause);
    }
    if let Some(cause) = forcing_not_finite(model, t, y, n) {
        return Some(cause);
    }
    if let IntegrationError::StepSizeTooSmall { dt, .. } = *error
        && let Some((rho, growth)) = spectral_radius(model.as_ode_mut(), t, y)
        && (dt * rho < NOT_STIFF || dt * growth > NOT_STIFF)
    {
        return Some(FailureCause::NotStiffness {
            t,
            step_size: dt,
            spectral_radius: rho,
            growth_rate: growth,
        });
    }
    None
}

/// Whether the eigenvalue ratio `r` of `M` ([`eigenvalue_ratio`]) is that of a singular `M`:
/// not a number, or at most [`SINGULAR_RATIO`].
fn singular(r: f64) -> bool {
    r.is_nan() || r <= SINGULAR_RATIO
}

/// The cause of [`failure_cause`] when `M` is singular at `(t, y)` (its eigenvalue `ratio`
/// there, `start_ratio` at the start): a parameter when `M` is singular at the start and at
/// eight configurations around `y` too, else negative `parameters` when turning their sign
/// makes it regular, else the coordinates.
fn singular_mass_cause(
    model: &mut dyn ModelInfo,
    t: f64,
    y: &[f64],
    n: usize,
    (ratio, start_ratio): (f64, f64),
    parameters: Vec<(String, f64)>,
) -> FailureCause {
    let elsewhere = (0..8).filter_map(|k| {
        let mut other = y.to_vec();
        for (i, q) in other.iter_mut().take(n).enumerate() {
            let sign = if (i + k) % 2 == 0 { 1.0 } else { -1.0 };
            *q += sign * 0.3 * (1.0 + k as f64 / 4.0);
        }
        eigenvalue_ratio(model, t, &other)
    });
    let regular_somewhere = std::iter::once(start_ratio)
        .chain(elsewhere)
        .any(|r| !singular(r) && r > ratio / DROP);
    // A negative parameter is a suspect only if M is regular there with its sign turned
    // (a negative offset or a gravity of -9.81 is not a negative mass).
    let negative: Vec<(String, f64)> = parameters
        .iter()
        .filter(|(_, v)| *v < 0.0)
        .filter(|(name, value)| {
            if model.set_parameter(name, -value).is_err() {
                return false;
            }
            let flipped = eigenvalue_ratio(model, t, y);
            let _ = model.set_parameter(name, *value);
            flipped.is_some_and(|f| !singular(f) && f > ratio / DROP)
        })
        .cloned()
        .collect();
    if !regular_somewhere {
        FailureCause::MassMatrixDegenerateEverywhere {
            suspects: parameters.into_iter().filter(|(_, v)| *v <= 0.0).collect(),
        }
    } else if !negative.is_empty() {
        FailureCause::NegativeParameters {
            t,
            eigenvalue_ratio: ratio,
            suspects: negative,
        }
    } else {
        FailureCause::SingularCoordinates {
            t,
            eigenvalue_ratio: ratio,
        }
    }
}

/// [`FailureCause::ForcingNotFinite`] if the forcing at `(t, y)`, or `M` or the forcing a
/// little ahead along the motion, is not finite.
fn forcing_not_finite(
    model: &mut dyn ModelInfo,
    t: f64,
    y: &[f64],
    n: usize,
) -> Option<FailureCause> {
    let (_, forcing) = model.mass_matrix_and_forcing(t, y);
    if forcing.iter().any(|v| !v.is_finite()) {
        return Some(FailureCause::ForcingNotFinite { t, at_state: true });
    }
    // Ahead along the motion: q + s q̇ (and the second half unchanged, to first order as good
    // as any); `q̇` from the kinematic equations in generalized speeds.
    let rates = model.coordinate_rates(t, y);
    for exponent in [-9, -7, -5, -3] {
        let s = 10f64.powi(exponent);
        let mut ahead = y.to_vec();
        for i in 0..n {
            ahead[i] += s * rates[i];
        }
        let (m, forcing) = model.mass_matrix_and_forcing(t + s, &ahead);
        if forcing.iter().chain(m.iter()).any(|v| !v.is_finite()) {
            return Some(FailureCause::ForcingNotFinite { t, at_state: false });
        }
    }
    None
}

/// The coordinate whose diagonal entry of `M` at `(t, y)` fell furthest below its value at
/// the start `(0, y0)`, if it fell to [`DROP`] of it or less ([`FailureCause::InertiaVanishes`]).
/// Relative to its own value at the start, so that units decide nothing (a mass in kg beside
/// an inertia of 1e-11 kg·m²); entries that were not positive at the start, or are not
/// finite, are left to the other tests.
fn vanishing_inertia(model: &dyn ModelInfo, t: f64, y: &[f64], y0: &[f64]) -> Option<FailureCause> {
    let (now, _) = model.mass_matrix_and_forcing(t, y);
    let (start, _) = model.mass_matrix_and_forcing(0.0, y0);
    let (i, fraction) = (0..now.nrows())
        .filter(|&i| start[(i, i)] > 0.0 && start[(i, i)].is_finite() && now[(i, i)].is_finite())
        .map(|i| (i, now[(i, i)] / start[(i, i)]))
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    (fraction <= DROP).then(|| FailureCause::InertiaVanishes {
        t,
        coordinate: model.description().coordinates[i].to_string(),
        diagonal: now[(i, i)],
        start: start[(i, i)],
    })
}

/// Below this product of the failed step and the Jacobian's spectral radius, stiffness cannot
/// explain the failure: an explicit method's stability region reaches `|h λ|` of order 1
/// (2 to 6 for the methods here), so a step a thousand times shorter than `1/ρ` failed for
/// accuracy, not stability. Above it in `h Re λ` for a growing mode, the solution grows by
/// `e^{10⁻³}` or more within a step that already underflowed: it blows up.
const NOT_STIFF: f64 = 1e-3;

/// The largest state dimension for which the Jacobian's eigenvalues are computed here (a dense
/// `O(dim³)` eigenvalue problem: 0.1 s at 400).
const MAX_SPECTRAL_DIM: usize = 400;

/// The spectral radius and the largest real part of the eigenvalues of `∂f/∂y` at `(t, y)`:
/// the system's exact Jacobian where it has one, else forward differences of the right-hand
/// side ([`forward_differences`](crate::linalg::forward_differences)); `None` when it is not finite or the system is too large
/// ([`MAX_SPECTRAL_DIM`]).
fn spectral_radius(system: &mut dyn OdeSystem, t: f64, y: &[f64]) -> Option<(f64, f64)> {
    let dim = system.dim();
    if dim != y.len() || dim > MAX_SPECTRAL_DIM {
        return None;
    }
    let mut jac = vec![0.0; dim * dim];
    if !system.jacobian(t, y, &mut jac).ok()? {
        let mut f0 = vec![0.0; dim];
        system.rhs(t, y, &mut f0).ok()?;
        let (mut shifted, mut f1) = (vec![0.0; dim], vec![0.0; dim]);
        crate::linalg::forward_differences(y, &f0, &mut jac, &mut shifted, &mut f1, |y, f| {
            system.rhs(t, y, f)
        })
        .ok()?;
    }
    if jac.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let matrix = DMatrix::from_column_slice(dim, dim, &jac);
    let eigenvalues = crate::linalg::eigenvalues(&matrix)?;
    let rho = eigenvalues.iter().fold(0.0_f64, |a, z| a.max(z.norm()));
    let growth = eigenvalues
        .iter()
        .fold(f64::NEG_INFINITY, |a, z| a.max(z.re));
    (rho.is_finite() && rho > 0.0).then_some((rho, growth))
}
