//! Parts c and d: the stiff two-mass spring, explicit and implicit methods at one tolerance
//! against a tight DOP853 reference, and a step-size underflow as the integration reports it.

use serde::Serialize;

use crate::integrate::{
    BogackiShampine32, DormandPrince54, DormandPrince853, IntegrationFailure, Integrator,
    IntegratorOptions, OutputTimes, RadauIIA5, Solution,
};
use crate::model_info::ModelInfo;
use crate::ode::OdeFn;

use super::options::{Failure, StabilityError, StabilityOptions, StiffSpring};

/// Number of output times of the stiff runs (uniform in `(0, t_end]`).
pub const STIFF_OUTPUT_TIMES: usize = 100;

/// Tolerance of the DOP853 reference of the stiff runs.
pub const STIFF_REFERENCE_TOL: f64 = 1e-12;

/// One method on the stiff spring at one `k/m` (part c).
#[derive(Debug, Serialize)]
pub struct StiffRow {
    /// The stiffness ratio `k/m` (1/s²).
    pub k_over_m: f64,
    /// `"equilibrium"` (spring pre-stretched by the step force's static share: the stiff
    /// mode is not excited) or `"rest"` (the model's initial state, spring at rest length).
    pub start: &'static str,
    /// The integrator's name.
    pub method: &'static str,
    /// Steps.
    pub steps: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// RHS evaluations.
    pub rhs_evals: usize,
    /// Jacobian evaluations.
    pub jacobian_evals: usize,
    /// LU factorisations.
    pub lu_decompositions: usize,
    /// Largest position error (m) at the output times against the reference.
    pub position_error: Option<f64>,
    /// Largest velocity error (m/s) at the output times against the reference.
    pub velocity_error: Option<f64>,
    /// Why the run stopped early, if it did.
    pub failure: Option<Failure>,
}

/// The stiff mode at one `k/m` (part c).
#[derive(Debug, Serialize)]
pub struct StiffMode {
    /// The stiffness ratio `k/m` (1/s²).
    pub k_over_m: f64,
    /// `equilibrium` or `rest` (see [`StiffRow::start`]).
    pub start: &'static str,
    /// Its angular frequency `ω = √(k (m₁ + m₂)/(m₁ m₂))` (rad/s).
    pub omega: f64,
    /// Largest amplitude of a mass's oscillation about the slow motion (m): from rest with
    /// the spring at rest length, the static stretch `F₀ m₁/(k (m₁ + m₂))` times
    /// `max(m₁, m₂)/(m₁ + m₂)`; 0 from the equilibrium start.
    pub position_amplitude: f64,
    /// Its velocity amplitude `ω ·` that (m/s).
    pub velocity_amplitude: f64,
    /// Steps of the DOP853 reference.
    pub reference_steps: usize,
}

/// The runs of part d.
#[derive(Debug, Serialize)]
pub struct UnderflowRun {
    /// The problem, in words.
    pub problem: &'static str,
    /// The integrator's name.
    pub method: &'static str,
    /// End time (s).
    pub t_end: f64,
    /// Relative and absolute tolerance.
    pub tol: f64,
    /// Why the run stopped early, if it did.
    pub failure: Option<Failure>,
}

/// The stiff two-mass spring at every `k/m`: the mode's figures and every method's run.
pub(super) fn stiff_runs(
    model: &mut dyn ModelInfo,
    args: &StabilityOptions,
) -> Result<(Vec<StiffMode>, Vec<StiffRow>), StabilityError> {
    let times: Vec<f64> = (1..=STIFF_OUTPUT_TIMES)
        .map(|i| args.t_end * i as f64 / STIFF_OUTPUT_TIMES as f64)
        .collect();
    let output = OutputTimes::At(times);
    let mut modes = Vec::new();
    let mut rows = Vec::new();
    for &ratio in &args.stiffness {
        let spring = Spring::set_up(model, &args.stiff_spring, ratio)?;
        for start in ["equilibrium", "rest"] {
            let (mode, start_rows) = spring.runs(model, args, &output, start)?;
            modes.push(mode);
            rows.extend(start_rows);
        }
    }
    Ok((modes, rows))
}

/// The stiff spring at one `k/m`: the masses, the stiff mode and the stretched coordinate.
struct Spring {
    /// The stiffness ratio `k/m` (1/s²).
    ratio: f64,
    /// The first mass.
    m1: f64,
    /// The second mass.
    m2: f64,
    /// The stiff mode's angular frequency (rad/s).
    omega: f64,
    /// The spring's static stretch under the force (m).
    static_stretch: f64,
    /// The index of the stretched coordinate.
    x2: usize,
}

impl Spring {
    /// Reads the masses and the force of `model` (the parameters `names`), sets its
    /// stiffness to `ratio · m₁` and finds the stretched coordinate.
    ///
    /// # Errors
    /// [`StabilityError::MissingParameter`], an error of setting the stiffness,
    /// [`StabilityError::MissingCoordinate`].
    fn set_up(
        model: &mut dyn ModelInfo,
        names: &StiffSpring,
        ratio: f64,
    ) -> Result<Self, StabilityError> {
        let parameter = |name: &str, role: &'static str| {
            model
                .description()
                .parameter_names()
                .iter()
                .position(|p| *p == name)
                .map(|i| model.parameter_values()[i])
                .ok_or_else(|| StabilityError::MissingParameter {
                    model: model.description().name.to_string(),
                    name: name.to_string(),
                    role,
                })
        };
        let m1 = parameter(&names.mass_1, "first mass")?;
        let m2 = parameter(&names.mass_2, "second mass")?;
        let force = parameter(&names.force, "force")?;
        parameter(&names.stiffness, "spring stiffness")?;
        model.set_parameter(&names.stiffness, ratio * m1)?;
        let k = ratio * m1;
        let omega = (k * (m1 + m2) / (m1 * m2)).sqrt();
        let static_stretch = force * m1 / (k * (m1 + m2));
        let x2 = model
            .description()
            .coordinate_names()
            .iter()
            .position(|c| *c == names.stretched)
            .ok_or_else(|| StabilityError::MissingCoordinate {
                model: model.description().name.to_string(),
                name: names.stretched.clone(),
            })?;
        Ok(Self {
            ratio,
            m1,
            m2,
            omega,
            static_stretch,
            x2,
        })
    }

    /// The mode's figures and every method's row from `start` (`"equilibrium"` or `"rest"`),
    /// measured against a DOP853 reference at [`STIFF_REFERENCE_TOL`].
    ///
    /// # Errors
    /// [`StabilityError::Reference`] when the reference fails.
    fn runs(
        &self,
        model: &mut dyn ModelInfo,
        args: &StabilityOptions,
        output: &OutputTimes,
        start: &'static str,
    ) -> Result<(StiffMode, Vec<StiffRow>), StabilityError> {
        let (ratio, m1, m2, omega) = (self.ratio, self.m1, self.m2, self.omega);
        let static_stretch = self.static_stretch;
        let mut y0 = model.initial_state();
        let position_amplitude = if start == "equilibrium" {
            y0[self.x2] += static_stretch;
            0.0
        } else {
            static_stretch * m1.max(m2) / (m1 + m2)
        };
        let run = |method: &mut dyn Integrator,
                   model: &mut dyn ModelInfo,
                   tol: f64|
         -> Result<Solution, IntegrationFailure> {
            let options = IntegratorOptions::default()
                .with_rtol(tol)
                .with_atol(tol)
                .with_max_steps(20_000_000);
            method.integrate(model.as_ode_mut(), 0.0, &y0, args.t_end, output, &options)
        };
        let reference = run(
            &mut DormandPrince853::new(),
            &mut *model,
            STIFF_REFERENCE_TOL,
        )
        .map_err(|e| StabilityError::Reference {
            k_over_m: ratio,
            start,
            message: e.to_string(),
        })?;
        let mode = StiffMode {
            k_over_m: ratio,
            start,
            omega,
            position_amplitude,
            velocity_amplitude: omega * position_amplitude,
            reference_steps: reference.stats.steps,
        };
        let methods: [Box<dyn Integrator>; 4] = [
            Box::new(BogackiShampine32::new()),
            Box::new(DormandPrince54::new()),
            Box::new(DormandPrince853::new()),
            Box::new(RadauIIA5::new()),
        ];
        let mut rows = Vec::new();
        for mut method in methods {
            let result = run(method.as_mut(), &mut *model, args.tol);
            rows.push(stiff_row(ratio, start, method.name(), result, &reference));
        }
        Ok((mode, rows))
    }
}

/// The row of the method `method` from `start` at `k/m = ratio`: its run's `result`, its
/// errors against `reference` (`None` when it failed).
fn stiff_row(
    ratio: f64,
    start: &'static str,
    method: &'static str,
    result: Result<Solution, IntegrationFailure>,
    reference: &Solution,
) -> StiffRow {
    let (solution, failure) = match result {
        Ok(s) => (s, None),
        Err(f) => {
            let failure = Failure::of(&f);
            (*f.partial, Some(failure))
        }
    };
    let error = |offset: usize| {
        failure.is_none().then(|| {
            solution
                .iter()
                .zip(reference.iter())
                .flat_map(|((_, y), (_, r))| (offset..offset + 2).map(move |i| (y[i] - r[i]).abs()))
                .fold(0.0, f64::max)
        })
    };
    StiffRow {
        k_over_m: ratio,
        start,
        method,
        steps: solution.stats.steps,
        rejected: solution.stats.rejected,
        rhs_evals: solution.stats.rhs_evals,
        jacobian_evals: solution.stats.jacobian_evals,
        lu_decompositions: solution.stats.lu_decompositions,
        position_error: error(0),
        velocity_error: error(2),
        failure,
    }
}

/// `ẏ = y²`, `y(0) = 1` (`y = 1/(1 − t)`, infinite at `t = 1`) asked for on `[0, 2]` with
/// Dormand–Prince 5(4): the step size must shrink to nothing at the singularity.
pub(super) fn underflow_run(tol: f64) -> UnderflowRun {
    let mut blow_up = OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = y[0] * y[0]);
    let options = IntegratorOptions::default().with_rtol(tol).with_atol(tol);
    let mut method = DormandPrince54::new();
    let result = method.integrate(
        &mut blow_up,
        0.0,
        &[1.0],
        2.0,
        &OutputTimes::Steps,
        &options,
    );
    UnderflowRun {
        problem: "y' = y², y(0) = 1 on [0, 2] (y = 1/(1 − t) blows up at t = 1)",
        method: method.name(),
        t_end: 2.0,
        tol,
        failure: result.err().as_ref().map(Failure::of),
    }
}
