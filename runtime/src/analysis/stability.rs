//! Where each integration method fails (issue 6; syllabus lecture 4, HW9), measured by
//! running it, against the theory of its stability function:
//!
//! a. Stability limits on `ẍ = −ω²x` (`hω`) and `ẋ = −λx` (`hλ`), measured by bisection on
//!    constant-step runs, against the intervals of `R(z) = 1 + z bᵀ(I − zA)⁻¹𝟙`; per-step
//!    amplification where the interval is empty (explicit Euler and midpoint) and for the
//!    A-stable implicit methods at large `hω`.
//! b. Energy of explicit Euler, RK4 and Störmer–Verlet over many periods of the oscillator.
//! c. The stiff two-mass spring (HW9's `two_masses` with large `k/m`): steps of explicit and
//!    implicit methods at one tolerance, against a tight DOP853 reference.
//! d. A step-size underflow (`ẏ = y²` blows up at `t = 1`), reported as the integration
//!    reports it.
//!
//! References: E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed.,
//! Springer, 1996, §IV.2 (stability functions, A-stability); E. Hairer, C. Lubich,
//! G. Wanner, *Geometric Numerical Integration*, 2nd ed., Springer, 2006, §I.1 and §IX.8
//! (Störmer–Verlet's modified energy).

use serde::Serialize;

use crate::integrate::stability_function::GrowthTest;
use crate::model_info::ModelInfo;

mod energy;
mod limits;
mod options;
mod stiff;

use energy::energy_runs;
pub use energy::{EnergyRow, STEPS_PER_PERIOD};
use limits::stability_limits;
pub use limits::{
    A_STABLE_STEPS, AMPLIFICATION_STEPS, AmplificationRow, BISECTION_TOLERANCE,
    EMPTY_INTERVAL_STEPS, ExplicitMethod, GROWTH_THRESHOLD, LONG_RUN_STEPS, LimitRow, Limits,
    PolynomialRow, WEAK_INSTABILITY_FACTORS,
};
pub use options::{Failure, StabilityError, StabilityOptions, StiffSpring};
pub use stiff::{STIFF_OUTPUT_TIMES, STIFF_REFERENCE_TOL, StiffMode, StiffRow, UnderflowRun};
use stiff::{stiff_runs, underflow_run};

/// Everything [`stability_study`] measured (the parts a–d of the module docs).
#[derive(Serialize)]
pub struct StabilityStudy {
    /// The bisection's growth test (part a).
    #[serde(skip)]
    pub test: GrowthTest,
    /// Part a.
    pub limits: Limits,
    /// Part b: one row per run.
    pub energy: Vec<EnergyRow>,
    /// Part c: the stiff mode at every `k/m` and start.
    pub stiff_modes: Vec<StiffMode>,
    /// Part c: every method at every `k/m` and start.
    pub stiff: Vec<StiffRow>,
    /// Part d.
    pub underflow: UnderflowRun,
}

impl StabilityStudy {
    /// The study as `eomgen study stability --json` prints it ([`StabilitySummary`]);
    /// `stiff_model` is the two-mass spring of part c and `options` those the study ran with.
    pub fn summary<'a>(
        &'a self,
        stiff_model: &dyn ModelInfo,
        options: &StabilityOptions,
    ) -> StabilitySummary<'a> {
        StabilitySummary {
            limits: LimitsSummary {
                growth_threshold: GROWTH_THRESHOLD,
                steps: options.steps,
                smallest_detected_growth: self.test.smallest_detected_growth(),
                bisection_tolerance: BISECTION_TOLERANCE,
                rows: &self.limits.rows,
                amplification: &self.limits.amplification,
                polynomials: &self.limits.polynomials,
            },
            energy: EnergySummary {
                periods: options.periods,
                runs: &self.energy,
            },
            stiff: StiffSummary {
                model: stiff_model.description().name.to_string(),
                t_end: options.t_end,
                tol: options.tol,
                reference: StiffReferenceSummary {
                    method: "dop853",
                    tol: STIFF_REFERENCE_TOL,
                },
                modes: &self.stiff_modes,
                runs: &self.stiff,
            },
            underflow: &self.underflow,
        }
    }
}

/// A [`StabilityStudy`] as `eomgen study stability --json` prints it
/// ([`StabilityStudy::summary`]): each part with the settings it ran with.
#[derive(Debug, Serialize)]
pub struct StabilitySummary<'a> {
    /// Part a.
    pub limits: LimitsSummary<'a>,
    /// Part b.
    pub energy: EnergySummary<'a>,
    /// Part c.
    pub stiff: StiffSummary<'a>,
    /// Part d.
    pub underflow: &'a UnderflowRun,
}

/// Part a of a [`StabilitySummary`]: the bisection's settings and the limits found.
#[derive(Debug, Serialize)]
pub struct LimitsSummary<'a> {
    /// [`GROWTH_THRESHOLD`].
    pub growth_threshold: f64,
    /// Steps of each growth test.
    pub steps: usize,
    /// [`GrowthTest::smallest_detected_growth`].
    pub smallest_detected_growth: f64,
    /// [`BISECTION_TOLERANCE`].
    pub bisection_tolerance: f64,
    /// [`Limits::rows`].
    pub rows: &'a [LimitRow],
    /// [`Limits::amplification`].
    pub amplification: &'a [AmplificationRow],
    /// [`Limits::polynomials`].
    pub polynomials: &'a [PolynomialRow],
}

/// Part b of a [`StabilitySummary`].
#[derive(Debug, Serialize)]
pub struct EnergySummary<'a> {
    /// Periods integrated.
    pub periods: usize,
    /// One row per run.
    pub runs: &'a [EnergyRow],
}

/// Part c of a [`StabilitySummary`].
#[derive(Debug, Serialize)]
pub struct StiffSummary<'a> {
    /// The two-mass spring's name.
    pub model: String,
    /// The end time (s).
    pub t_end: f64,
    /// The adaptive methods' tolerance.
    pub tol: f64,
    /// The reference solution.
    pub reference: StiffReferenceSummary,
    /// The stiff mode at every `k/m` and start.
    pub modes: &'a [StiffMode],
    /// Every method at every `k/m` and start.
    pub runs: &'a [StiffRow],
}

/// The reference of part c: DOP853 at [`STIFF_REFERENCE_TOL`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StiffReferenceSummary {
    /// `"dop853"`.
    pub method: &'static str,
    /// Its tolerance.
    pub tol: f64,
}

// Not a `StudyRuns` report: the rule that a study whose every run failed measured nothing
// cannot apply here. Part a always measures: its methods are a fixed list, run on test
// equations the options do not reach (only the number of steps), and a failure there fails
// the whole study (`StabilityError::TestEquation`, …) rather than a row, so every report
// holds the limits. Parts b and c record a failed run in its row (`failure`), which the
// tables print as `failed` with its reason; part d demonstrates a failure.

/// Runs the stability study (see the module docs); `stiff_model` is a two-mass spring (HW9's)
/// with the names of [`StabilityOptions::stiff_spring`], whose stiffness is set to each
/// `k/m · m₁` of part c.
///
/// # Errors
/// The errors of [`StabilityOptions::validate`]; [`StabilityError::PolynomialStep`],
/// [`StabilityError::TestEquation`] and [`StabilityError::Amplification`] when a method fails
/// on the test equations; [`StabilityError::MissingParameter`],
/// [`StabilityError::MissingCoordinate`] or [`StabilityError::UnknownParameter`] for a
/// stiff model without those names; [`StabilityError::Reference`] when a stiff
/// reference fails.
///
/// # Examples
/// ```
/// use eomgen::analysis::{StabilityOptions, stability_study};
///
/// let mut two_masses = (eomgen::models::find("two_masses").unwrap().make)();
/// let options = StabilityOptions { steps: 200, periods: 2, stiffness: vec![1e2], ..Default::default() };
/// let study = stability_study(two_masses.as_mut(), &options)?;
/// let rk4 = study.limits.rows.iter().find(|r| r.method == "rk4" && r.axis == "imaginary").unwrap();
/// assert!((rk4.theory - 2.0 * 2f64.sqrt()).abs() < 1e-9); // |R(iy)| = 1 at y = 2√2
/// # Ok::<(), eomgen::analysis::StabilityError>(())
/// ```
pub fn stability_study(
    stiff_model: &mut dyn ModelInfo,
    options: &StabilityOptions,
) -> Result<StabilityStudy, StabilityError> {
    options.validate()?;
    let test = GrowthTest {
        steps: options.steps,
        threshold: GROWTH_THRESHOLD,
    };
    let limits = stability_limits(&test)?;
    let energy = energy_runs(options.periods);
    let (stiff_modes, stiff) = stiff_runs(stiff_model, options)?;
    let underflow = underflow_run(options.tol);
    Ok(StabilityStudy {
        test,
        limits,
        energy,
        stiff_modes,
        stiff,
        underflow,
    })
}
