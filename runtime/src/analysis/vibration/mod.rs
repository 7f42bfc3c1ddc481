//! The vibration analyses of a model, each one library call with typed options, a
//! `Serialize` report and a typed error, on the size-erased [`ModelInfo`](crate::ModelInfo):
//! the CLI (`eomgen modes`, `frf`, `study free-response`, `modal-damping`, `floquet`) and a
//! Rust program reach the same code.
//!
//! - [`operating_point()`]: the equilibrium an analysis linearises about, from a name in the
//!   model file's `equilibria:` or an explicit guess (Newton on `F(q, 0, t) = 0`).
//! - [`modal_analysis`]: the exact linearisation `M δq̈ + C δq̇ + K δq = 0` there, natural
//!   frequencies, mass-normalised mode shapes, damping ratios (`eomgen modes`).
//! - [`steady_motion_analysis`]: a steady motion (rates held, ignorable coordinates
//!   drifting), its linearisation restricted to the constraints and its stability
//!   (`eomgen modes` at a steady motion or on a non-holonomic model).
//! - [`parameter_sweep()`]: the eigenvalues of an operating point against one parameter and
//!   the values where the stability changes, refined by bisection (`eomgen study
//!   parameter-sweep`).
//! - [`free_response()`]: the undamped free response four ways and their differences (HW28).
//! - [`modal_damping_study`]: damping ratios exact, by the diagonal of `ΨᵀCΨ` and by a
//!   Rayleigh fit, and the damped responses from each mode shape (HW34).
//! - [`frequency_response_analysis`]: `H(ω)` from one input over a sweep, its peaks, its modal
//!   sum; [`plan_simulation`] and [`simulate_point`] check points of the curve by simulating
//!   the full model to steady state (lecture 21, HW37).
//! - [`expm_study()`]: `ż = A z` for a random `A` three ways (`e^{At}`, eigenvector
//!   superposition, DOP853), the eigenvalues and `κ(V)` (HW32).
//! - [`rayleigh_study`]: the Rayleigh quotient of a trial shape against the lowest natural
//!   frequency, the bound and its stationarity (lectures 35–37).
//! - [`convolution_response`]: the response to an impulse, a step or any `f(t)` through one
//!   input by Duhamel's integral over the impulse response, against DOP853 and the closed
//!   forms (lecture 21).
//! - [`floquet_at_equilibrium`]: the Floquet multipliers of a time-periodic model about an
//!   equilibrium; [`floquet_cell`], one cell of a stability chart over two parameters
//!   (lectures 19, 21).
//!
//! The building blocks (linearisation, normal modes, responses, `H(ω)`, monodromy) are in
//! [`linear::modal`](crate::linear::modal), [`linear::response`](crate::linear::response),
//! [`linear::frequency_response`](crate::linear::frequency_response) and
//! [`linear::monodromy`](crate::linear::monodromy).

pub mod convolution;
pub mod expm_study;
pub mod floquet;
pub mod free_response;
pub mod frf;
pub mod modal_damping;
pub mod modes;
pub mod operating_point;
pub mod parameter_sweep;
pub mod rayleigh;
pub mod steady;

pub use convolution::{
    ClosedForm, ConvolutionError, ConvolutionOptions, ConvolutionStudy, Forcing, Quadrature,
    convolution_response,
};
pub use expm_study::{
    EigenvectorOutcome, ExpmOptions, ExpmRoute, ExpmStudy, ExpmStudyError, RandomProblem,
    RouteDifference, eigenvector_condition, expected_difference, expm_study, expm_study_of,
    random_problem,
};
pub use floquet::{
    FailedCell, FloquetCell, FloquetChart, FloquetChartSummary, FloquetIntegrationSummary,
    FloquetPoint, FloquetStudyError, FloquetStudyOptions, FloquetSummary, MultiplierSummary,
    PredictionSummary, SweepAxis, floquet_at_equilibrium, floquet_at_equilibrium_for_sweep,
    floquet_cell,
};
pub use free_response::{
    FinalState, FreeResponseMethod, FreeResponseOptions, FreeResponseStudy, FreeResponseSummary,
    InitialDeviation, MethodSummary, ModeSummary, ResponseDifference, ResponseStudyError,
    default_duration, free_response, unconstrained_modal_analysis, uniform_times,
};
pub use frf::{
    FrfAnalysis, FrfAnalysisError, FrfEvaluation, FrfEvaluationSummary, FrfOptions, FrfOutput,
    FrfSimulationOptions, FrfSimulationPlan, FrfSimulationSummary, FrfSummary, FrfSweepSummary,
    ModalSumSummary, ModalTermSummary, PeakSummary, Phasor, SimulatedPoint, SimulatedPointSummary,
    SimulatedValue, SimulatedValueSummary, frequency_response_analysis, max_simulation_error,
    plan_simulation, simulate_point,
};
pub use modal_damping::{
    ModalDampingOptions, ModalDampingStudy, ModalDampingSummary, ModalRatio, ModeDamping,
    ModeDampingSummary, RayleighFit, Release, ReleaseSummary, modal_damping_study,
};
pub use modes::{
    DampedEigenvalue, DampedEigenvalueSummary, ModalAnalysis, ModalOptions, ModesSummary,
    modal_analysis,
};
pub use operating_point::{
    EquilibriumStart, OperatingPoint, OperatingPointError, OperatingPointOptions, PointSummary,
    held_rates, operating_point,
};
pub use parameter_sweep::{
    Crossing, Direction, ParameterSweep, ParameterSweepError, ParameterSweepOptions,
    PointEigenvalues, StabilityChange, SweepPoint, SweepPointError, eigenvalues_at,
    parameter_sweep,
};
pub use rayleigh::{
    PerturbationDirection, PerturbedQuotient, RayleighError, RayleighOptions, RayleighStudy,
    RayleighSummary, Stationarity, rayleigh_study,
};
pub use steady::{
    SteadyAnalysisError, SteadyMotionAnalysis, SteadyMotionSummary, SteadyPointSummary,
    damped_summaries, is_steady_motion, steady_motion_analysis,
};
