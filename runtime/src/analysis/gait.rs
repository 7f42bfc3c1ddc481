//! Gaits: periodic motions through changes of support (a rimless wheel's steady rolling, a
//! walker's steady walk), found as fixed points of the return map, with their stability
//! from the variational equations and a saltation matrix at each landing
//! (`eomgen study periodic-orbit` on a model with `support:`).
//!
//! The return map `P` takes the state just after a change of support to the state just
//! after the `k`-th next one ([`GaitOptions::steps`]): each step integrates the model from
//! its start until the landing contact's gap falls through 0, and applies the change of
//! support `Δ` there ([`crate::hybrid::support`]). Along each step the variational
//! equations `Φ̇ = (∂f/∂y) Φ` are integrated with the state, and at the landing the
//! saltation matrix
//!
//! `S = Δ_y + (f⁺ − Δ_y f⁻) ∇hᵀ / (∇h · f⁻)`
//!
//! carries `Φ` through it (`h` the gap, `Δ_y` the reset's exact Jacobian, `f∓` the vector
//! fields before and after). The monodromy matrix is `∏ S Φ`; its eigenvalues are the
//! Floquet multipliers, one of them 1 (the flow's own direction). The return map's Jacobian,
//! the time of landing let move, is `∏ (S Φ − f⁺ ∇hᵀ Φ / (∇h · f⁻))`; its eigenvalues are
//! the others and 0 in place of the trivial one. The gait is a zero of `P(y) − y`, found by
//! Newton's method with that Jacobian (steps halved while the residual grows), and it is
//! stable when every eigenvalue of `∂P/∂y` has modulus below 1.
//!
//! Source: Leine & Nijmeijer, *Dynamics and Bifurcations of Non-smooth Mechanical Systems*
//! (2004), §3.5 (the saltation matrix) and §7.1 (the shooting method through events);
//! Garcia, Chatterjee, Ruina & Coleman, J. Biomech. Eng. 120 (1998) 281–288 (the simplest
//! walker's gait and its eigenvalues); Bhounsule, DCDIS B 21 (2014) (variational equations
//! against finite differences for the rimless wheel and the simplest walker).

mod sweep;

pub use sweep::{GaitBifurcation, GaitStabilityChange, GaitSweep, GaitSweepPoint, gait_sweep};

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

use crate::hybrid::support::{SupportError, SupportValues, change_support, reset_jacobian};
use crate::integrate::{DormandPrince853, Integrator, IntegratorOptions, OutputTimes, Stats};
use crate::linear::monodromy::{FloquetOptions, FloquetStability, Variational};
use crate::model_info::ModelInfo;
use crate::ode::{EventDirection, EventSpec, WithEvents};

/// The shortest step (s, relative to `1 + |t|`): a landing sooner is the foot striking where
/// the step starts, not a step.
const MIN_STEP: f64 = 1e-9;

/// Settings of [`gait`].
#[derive(Debug, Clone, PartialEq)]
pub struct GaitOptions {
    /// Newton's start, `[q; q̇]` just after a change of support; `None`: the model's initial
    /// state.
    pub start: Option<Vec<f64>>,
    /// The changes of support in one period of the gait (1 for a period-one gait, 2 for a
    /// period-two one after a period doubling).
    pub steps: usize,
    /// Newton's tolerance: `‖P(y) − y‖∞ ≤ tol · max(1, ‖y‖∞)`.
    pub tol: f64,
    /// Most Newton iterations.
    pub max_iterations: usize,
    /// The longest a step may take (s) before the run says the foot never lands.
    pub max_step_time: f64,
    /// Tolerances of the variational integration (DOP853 on `y` and `Φ`) and the tolerance
    /// on `|μ| = 1` of the stability verdict.
    pub floquet: FloquetOptions,
}

impl Default for GaitOptions {
    fn default() -> Self {
        Self {
            start: None,
            steps: 1,
            tol: 1e-10,
            max_iterations: 30,
            max_step_time: 1e3,
            floquet: FloquetOptions::default(),
        }
    }
}

/// A gait found by [`gait`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gait {
    /// The model's name.
    pub model: String,
    /// `q` and `q̇` names, in state order.
    pub state_names: Vec<String>,
    /// The gait's state just after a change of support, `[q; q̇]` (the fixed point of `P`).
    pub state: Vec<f64>,
    /// The period (s): the time of its `steps` steps.
    pub period: f64,
    /// Each step's duration (s).
    pub step_times: Vec<f64>,
    /// The kinetic energy lost at each landing (J).
    pub energy_lost: Vec<f64>,
    /// `‖P(y) − y‖∞` per Newton iteration, at its start, then at the solution.
    pub residuals: Vec<f64>,
    /// Newton iterations taken.
    pub iterations: usize,
    /// The monodromy matrix `∏ S Φ` (`2n × 2n`).
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub monodromy_matrix: DMatrix<f64>,
    /// The Floquet multipliers (its eigenvalues), largest modulus first; one is 1 along the
    /// flow.
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub floquet_multipliers: Vec<Complex<f64>>,
    /// The return map's Jacobian `∂P/∂y` (`2n × 2n`).
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub return_map_jacobian: DMatrix<f64>,
    /// Its eigenvalues, largest modulus first: the nontrivial multipliers, and 0 for the
    /// flow's direction.
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub eigenvalues: Vec<Complex<f64>>,
    /// The largest `|λ|` of [`Self::eigenvalues`].
    pub spectral_radius: f64,
    /// The verdict, with [`FloquetOptions::stability_tolerance`] on `|λ| = 1`.
    pub stability: FloquetStability,
    /// The variational integrations' work, all iterations together.
    pub stats: Stats,
}

/// Why no gait was found.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum GaitError {
    /// The model has no change of support (`support:` on a contact).
    #[error(
        "`{model}` has no change of support: a gait is a periodic motion through landings, written as `support:` on a contact"
    )]
    NoSupport {
        /// The model.
        model: String,
    },
    /// The swept parameter is not the model's.
    #[error("the model has no parameter `{name}`; its parameters are {parameters}")]
    UnknownParameter {
        /// The name given.
        name: String,
        /// The model's parameters.
        parameters: String,
    },
    /// The model has what a gait's return map does not take: another contact, or a
    /// dependence on `t` (the map restarts each step at `t = 0`).
    #[error(
        "`{model}` {what}: a gait's return map takes an autonomous model whose only contacts change its support"
    )]
    Unsupported {
        /// The model.
        model: String,
        /// What it has.
        what: String,
    },
    /// Newton's matrix `∂P/∂y − I` is singular (a multiplier at 1: a fold, or a family of
    /// gaits).
    #[error(
        "no gait: Newton's matrix ∂P/∂y − I is singular at iteration {iteration} (‖P(y) − y‖ = {residual:.3e}): the return map has an eigenvalue at 1 there"
    )]
    Singular {
        /// The iteration.
        iteration: usize,
        /// The residual there.
        residual: f64,
    },
    /// No value of a sweep has a gait.
    #[error("no value of the sweep has a gait; at the first, {value}: {reason}")]
    NothingFound {
        /// The first value.
        value: f64,
        /// Why no gait was found there.
        reason: String,
    },
    /// The settings are out of range.
    #[error("{what}")]
    InvalidOptions {
        /// What is wrong.
        what: String,
    },
    /// The start has the wrong length.
    #[error("the start has {found} entries, but the model's state has {expected}")]
    DimensionMismatch {
        /// `2n`.
        expected: usize,
        /// Given.
        found: usize,
    },
    /// A step ended without a landing: the foot never came down, or the integration failed.
    #[error("step {step} from t = {t} has no landing within {within} s{}", reason.as_ref().map(|r| format!(" ({r})")).unwrap_or_default())]
    NoLanding {
        /// The step (1-based) in the period.
        step: usize,
        /// Its start (s).
        t: f64,
        /// The longest a step may take (s).
        within: f64,
        /// The integration's failure, if it failed.
        reason: Option<String>,
    },
    /// The change of support at a landing has no answer.
    #[error("the landing of step {step} at t = {t}: {error}")]
    Support {
        /// The step (1-based).
        step: usize,
        /// Time (s).
        t: f64,
        /// Why.
        error: SupportError,
    },
    /// The landing is grazing (`ḣ = 0`) or the reset's Jacobian cannot be formed: no
    /// saltation matrix.
    #[error(
        "the landing of step {step} at t = {t} has no saltation matrix (the foot's gap closes at rate {rate:e})"
    )]
    Saltation {
        /// The step (1-based).
        step: usize,
        /// Time (s).
        t: f64,
        /// `∇h · f⁻`.
        rate: f64,
    },
    /// Newton's method did not reach the tolerance.
    #[error(
        "no gait: after {iterations} Newton iterations ‖P(y) − y‖ is {residual:.3e} (allowed {allowed:.3e}); start nearer the gait (--guess) or check that one exists at these parameters"
    )]
    NoConvergence {
        /// Iterations taken.
        iterations: usize,
        /// The last residual.
        residual: f64,
        /// The tolerance.
        allowed: f64,
    },
}

/// One pass of the return map from `y0` ([`return_map`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReturnMap {
    /// `P(y0)`, `[q; q̇]` just after the last landing.
    pub end: Vec<f64>,
    /// `∂P/∂y` at `y0` (`2n × 2n`).
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub return_map: DMatrix<f64>,
    /// The monodromy matrix `∏ S Φ` from `y0` (`2n × 2n`).
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub monodromy: DMatrix<f64>,
    /// Each step's duration (s).
    pub step_times: Vec<f64>,
    /// The kinetic energy lost at each landing (J).
    pub energy_lost: Vec<f64>,
}

/// Finds the gait of `model` near [`GaitOptions::start`]: the fixed point of its return map
/// through [`GaitOptions::steps`] changes of support, and its stability (see the module
/// documentation).
///
/// # Shapes
/// `start`: `2n`. The matrices are `2n × 2n`.
///
/// # Errors
/// [`GaitError`]: no change of support, settings out of range, a step without a landing, a
/// landing without an answer or a saltation matrix, or Newton's method not converging.
pub fn gait(model: &mut dyn ModelInfo, options: &GaitOptions) -> Result<Gait, GaitError> {
    let name = model.description().name.to_string();
    if model.description().supports.is_empty() {
        return Err(GaitError::NoSupport { model: name });
    }
    validate(options)?;
    let dim = 2 * model.num_dofs();
    let mut y = options
        .start
        .clone()
        .unwrap_or_else(|| model.initial_state());
    if y.len() != dim {
        return Err(GaitError::DimensionMismatch {
            expected: dim,
            found: y.len(),
        });
    }
    supported(model, &y, name.clone())?;
    let mut stats = Stats::default();
    let mut residuals = Vec::new();
    let allowed = |y: &[f64]| options.tol * y.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let mut pass = return_map(model, &y, options, &mut stats)?;
    let mut residual = distance(&pass.end, &y);
    for iteration in 0..=options.max_iterations {
        residuals.push(residual);
        if residual <= allowed(&y) {
            return Ok(report(
                model,
                (name, y),
                pass,
                (residuals, iteration),
                options,
                stats,
            ));
        }
        if iteration == options.max_iterations {
            break;
        }
        // Newton on `P(y) − y = 0`: `(∂P/∂y − I) δ = −(P(y) − y)`, halved while it does not
        // lower the residual.
        let r = DVector::from_iterator(dim, pass.end.iter().zip(&y).map(|(p, y)| p - y));
        let a = &pass.return_map - DMatrix::identity(dim, dim);
        let solved = a.lu().solve(&(-r));
        let Some(step) = solved.filter(|s| s.iter().all(|v| v.is_finite())) else {
            return Err(GaitError::Singular {
                iteration,
                residual,
            });
        };
        let mut damping = 1.0;
        loop {
            let trial: Vec<f64> = y
                .iter()
                .zip(step.iter())
                .map(|(y, d)| y + damping * d)
                .collect();
            let next = return_map(model, &trial, options, &mut stats);
            match next {
                Ok(next) if distance(&next.end, &trial) < residual || damping < 1e-3 => {
                    residual = distance(&next.end, &trial);
                    (y, pass) = (trial, next);
                    break;
                }
                Err(e) if damping < 1e-3 => return Err(e),
                _ => damping *= 0.5,
            }
        }
    }
    Err(GaitError::NoConvergence {
        iterations: options.max_iterations,
        residual,
        allowed: allowed(&y),
    })
}

/// Refuses a model with a contact that does not change its support (the return map watches
/// only the landings) or whose equations depend on `t` (probed at `y` at three times).
fn supported(model: &mut dyn ModelInfo, y: &[f64], name: String) -> Result<(), GaitError> {
    let d = model.description();
    if d.contacts.len() > d.supports.len() {
        let other: Vec<String> = (d.contacts.iter())
            .filter(|c| !d.supports.contains(c))
            .map(|c| format!("`{c}`"))
            .collect();
        return Err(GaitError::Unsupported {
            model: name,
            what: format!(
                "has contacts that do not change its support ({})",
                other.join(", ")
            ),
        });
    }
    let ode = model.as_ode_mut();
    let mut at = |t: f64| {
        let mut f = vec![0.0; y.len()];
        ode.rhs(t, y, &mut f).ok().map(|()| f)
    };
    if let (Some(f0), Some(f1), Some(f2)) = (at(0.0), at(0.37), at(1.3)) {
        let scale = 1.0 + f0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if distance(&f0, &f1).max(distance(&f0, &f2)) > 1e-12 * scale {
            return Err(GaitError::Unsupported {
                model: name,
                what: "depends on t".into(),
            });
        }
    }
    Ok(())
}

/// The settings in range.
fn validate(options: &GaitOptions) -> Result<(), GaitError> {
    let invalid = |what: String| Err(GaitError::InvalidOptions { what });
    if options.steps == 0 {
        return invalid("a gait takes at least one step per period".into());
    }
    if !(1e-14..=1e-3).contains(&options.tol) {
        return invalid(format!(
            "Newton's tolerance {} is outside [1e-14, 1e-3]",
            options.tol
        ));
    }
    if !(options.max_step_time.is_finite() && options.max_step_time > 0.0) {
        return invalid(format!(
            "the longest step time {} s is not a positive number",
            options.max_step_time
        ));
    }
    options
        .floquet
        .validate()
        .or_else(|e| invalid(e.to_string()))
}

/// `‖a − b‖∞`.
fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
}

/// The report at the solution `y` (with its pass).
fn report(
    model: &dyn ModelInfo,
    (name, y): (String, Vec<f64>),
    pass: ReturnMap,
    (residuals, iterations): (Vec<f64>, usize),
    options: &GaitOptions,
    stats: Stats,
) -> Gait {
    let floquet_multipliers = eigenvalues(&pass.monodromy);
    let eigenvalues = eigenvalues(&pass.return_map);
    let spectral_radius = eigenvalues.first().map_or(0.0, |l| l.norm());
    let coordinates = model.description().coordinate_names();
    let state_names = (coordinates.iter().map(|c| c.to_string()))
        .chain(coordinates.iter().map(|c| format!("{c}_dot")))
        .collect();
    Gait {
        model: name,
        state_names,
        state: y,
        period: pass.step_times.iter().sum(),
        step_times: pass.step_times,
        energy_lost: pass.energy_lost,
        residuals,
        iterations,
        monodromy_matrix: pass.monodromy,
        floquet_multipliers,
        return_map_jacobian: pass.return_map,
        eigenvalues,
        spectral_radius,
        stability: FloquetStability::of(spectral_radius, options.floquet.stability_tolerance),
        stats,
    }
}

/// The eigenvalues of `m`, largest modulus first (ties: larger imaginary part first).
fn eigenvalues(m: &DMatrix<f64>) -> Vec<Complex<f64>> {
    let mut values: Vec<Complex<f64>> = m.complex_eigenvalues().iter().copied().collect();
    values.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
    values
}

/// `P(y0)` through [`GaitOptions::steps`] steps, with its Jacobian and the monodromy matrix
/// (see the module documentation), the integrations' work added to `stats`.
///
/// # Shapes
/// `y0`: `2n`, just after a landing.
///
/// # Errors
/// [`GaitError::NoLanding`], [`GaitError::Support`], [`GaitError::Saltation`].
pub fn return_map(
    model: &mut dyn ModelInfo,
    y0: &[f64],
    options: &GaitOptions,
    stats: &mut Stats,
) -> Result<ReturnMap, GaitError> {
    let dim = y0.len();
    let mut pass = ReturnMap {
        end: y0.to_vec(),
        return_map: DMatrix::identity(dim, dim),
        monodromy: DMatrix::identity(dim, dim),
        step_times: Vec::new(),
        energy_lost: Vec::new(),
    };
    let mut t = 0.0;
    for step in 1..=options.steps {
        let (landing, y, phi) = flow_to_landing(model, (t, &pass.end), step, options, stats)?;
        let (c, which) = landing;
        let (t_hit, n) = (t + phi.1, model.num_dofs());
        let phi = phi.0;
        let values = model.contact_values(t_hit, &y);
        let law = (values.restitution[c], values.static_friction[c]);
        let s = SupportValues::of(model, which, t_hit, &y[..n]);
        let change =
            change_support(model, &s, (t_hit, &y), law).map_err(|error| GaitError::Support {
                step,
                t: t_hit,
                error,
            })?;
        let after: Vec<f64> = change.q.iter().chain(&change.qdot).copied().collect();
        let saltation_error = |rate| GaitError::Saltation {
            step,
            t: t_hit,
            rate,
        };
        let reset = reset_jacobian(&s, &y).ok_or(saltation_error(f64::NAN))?;
        let (mut before_field, mut after_field) = (vec![0.0; dim], vec![0.0; dim]);
        let ode = model.as_ode_mut();
        let fields = (ode.rhs(t_hit, &y, &mut before_field))
            .and_then(|()| ode.rhs(t_hit, &after, &mut after_field));
        if fields.is_err() {
            return Err(saltation_error(f64::NAN));
        }
        let (f_minus, f_plus) = (
            DVector::from_vec(before_field),
            DVector::from_vec(after_field),
        );
        let mut gradient = DVector::zeros(dim);
        for j in 0..n {
            gradient[j] = values.normal[c * n + j];
        }
        let rate = gradient.dot(&f_minus);
        if !(rate.is_finite() && rate.abs() > f64::EPSILON * f_minus.norm()) {
            return Err(saltation_error(rate));
        }
        // `S = Δ_y + (f⁺ − Δ_y f⁻) ∇hᵀ / (∇h · f⁻)`.
        let jump = &f_plus - &reset * &f_minus;
        let saltation = &reset + (&jump * gradient.transpose()) / rate;
        let through = &saltation * &phi;
        let timing = (&f_plus * (gradient.transpose() * &phi)) / rate;
        pass.return_map = (&through - timing) * &pass.return_map;
        pass.monodromy = through * &pass.monodromy;
        pass.step_times.push(t_hit - t);
        pass.energy_lost.push(change.energy_lost);
        pass.end = after;
        t = t_hit;
    }
    Ok(pass)
}

/// The landing contact `(c, which)` (an index into the contacts and one into the supports),
/// the state there, and `(Φ, duration)` of the step from `(t0, y0)`: the model and its
/// variational equations integrated until the first change of support's gap falls through 0.
type Landing = ((usize, usize), Vec<f64>, (DMatrix<f64>, f64));

/// A zero of a landing gap along the variational flow: the landing `(contact, support)`, and
/// the time and `[y; vec Φ]` there.
type Zero = ((usize, usize), (f64, Vec<f64>));

/// Integrates step `step` from `(t0, y0)` to its landing (see [`Landing`]). A zero of a
/// landing gap where the file's `when:` is not positive is passed (the foot scuffs), and the
/// integration goes on from it.
fn flow_to_landing(
    model: &mut dyn ModelInfo,
    (t0, y0): (f64, &[f64]),
    step: usize,
    options: &GaitOptions,
    stats: &mut Stats,
) -> Result<Landing, GaitError> {
    let dim = y0.len();
    let n = dim / 2;
    let description = model.description().clone();
    let supports: Vec<(usize, usize)> = (description.supports.iter().enumerate())
        .filter_map(|(which, s)| {
            let c = description.contacts.iter().position(|c| c == s)?;
            Some((c, which))
        })
        .collect();
    let no_landing = |reason: Option<String>| GaitError::NoLanding {
        step,
        t: t0,
        within: options.max_step_time,
        reason,
    };
    let integrator_options = IntegratorOptions::default()
        .with_rtol(options.floquet.rtol)
        .with_atol(options.floquet.atol)
        .with_max_steps(options.floquet.max_steps);
    let t_end = t0 + options.max_step_time;
    let mut flow = Variational::new(model);
    let (mut t, mut state) = (t0, flow.start(y0));
    // At most this many passes (scuffs) in one step.
    for _ in 0..100 {
        let (landing, event) = next_zero(
            &mut flow,
            &supports,
            (t, &state),
            (t_end, options.floquet.atol),
            &integrator_options,
            stats,
        )
        .map_err(|reason| no_landing(Some(reason)))?
        .ok_or_else(|| no_landing(None))?;
        let (_, which) = landing;
        let passes = !SupportValues::of(&*flow.system, which, event.0, &event.1[..n]).lands();
        if !passes {
            // A landing where the step starts is no step: the foot is on the ground,
            // moving into it (a start on the guard, or a walker that has fallen).
            if event.0 - t0 <= MIN_STEP * (1.0 + t0.abs()) {
                return Err(no_landing(Some(
                    "the foot lands where the step starts: a step of no time".into(),
                )));
            }
            let phi = DMatrix::from_column_slice(dim, dim, &event.1[dim..]);
            return Ok((landing, event.1[..dim].to_vec(), (phi, event.0 - t0)));
        }
        (t, state) = event;
    }
    Err(no_landing(Some(
        "the foot passed through the ground 100 times".into(),
    )))
}

/// The first falling zero after `t0` of a landing gap (`supports`: `(contact, support)`
/// pairs) along the variational flow from `state` (`[y; vec Φ]`), with the time and the flow's
/// state there; `None` if none comes before `t_end`. A gap at a zero at `t0` (the step's
/// start, or a foot that passed: within `touch` of 0) is watched as `(g − g₀)/(t − t₀)`, as a run through impacts
/// does (`hybrid::run`), so that the zero it leaves is not found again.
///
/// # Errors
/// The integration's failure, as text.
fn next_zero<'m>(
    flow: &mut Variational<'_, dyn ModelInfo + 'm>,
    supports: &[(usize, usize)],
    (t0, state): (f64, &[f64]),
    (t_end, touch): (f64, f64),
    options: &IntegratorOptions,
    stats: &mut Stats,
) -> Result<Option<Zero>, String> {
    let contacts = flow.system.description().contacts.len();
    let dim = 2 * flow.system.num_dofs();
    let mut gaps = vec![0.0; 5 * contacts];
    flow.system.contact_gaps(t0, &state[..dim], &mut gaps);
    let starting: Vec<Option<f64>> = (supports.iter())
        .map(|&(c, _)| (gaps[c].abs() <= touch).then_some(gaps[c]))
        .collect();
    let specs = (supports.iter())
        .map(|&(c, _)| {
            let name = flow.system.description().contacts[c].to_string();
            EventSpec::new(name, EventDirection::Falling, true)
        })
        .collect();
    let own = crate::ode::OdeSystem::event_specs(&*flow).len();
    let mut system = WithEvents::new(
        flow,
        specs,
        |v: &mut Variational<'_, dyn ModelInfo + 'm>, t: f64, y: &[f64], g: &mut [f64]| {
            v.system.contact_gaps(t, &y[..dim], &mut gaps);
            for ((out, &(c, _)), start) in g.iter_mut().zip(supports).zip(&starting) {
                *out = match start {
                    Some(g0) if t > t0 => (gaps[c] - g0) / (t - t0),
                    Some(_) => gaps[contacts + c],
                    None => gaps[c],
                };
            }
            Ok(())
        },
    );
    let solution = DormandPrince853::new()
        .integrate(
            &mut system,
            t0,
            state,
            t_end,
            &OutputTimes::At(vec![t_end]),
            options,
        )
        .map_err(|f| f.error.to_string())?;
    add(stats, &solution.stats);
    let Some(k) = solution.terminated_by_event else {
        return Ok(None);
    };
    let event = &solution.events[k];
    Ok((supports.get(event.index.wrapping_sub(own)))
        .map(|&landing| (landing, (event.t, event.y.clone()))))
}

/// Adds `more`'s work to `stats`.
fn add(stats: &mut Stats, more: &Stats) {
    stats.steps += more.steps;
    stats.rejected += more.rejected;
    stats.rhs_evals += more.rhs_evals;
    stats.event_evals += more.event_evals;
    stats.wall_time_s += more.wall_time_s;
}
