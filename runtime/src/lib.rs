//! The numeric half of eomgen.
//!
//! Generated code (from `eomgen::model!`) implements [`MechanicalSystem`]; the runtime turns
//! `M(q, t) q̈ = F(q, q̇, t)` into the first-order system `ẏ = [q̇; M⁻¹F]` ([`FirstOrder`]) and
//! integrates it with any [`Integrator`].
//!
//! # Which model type to use
//!
//! | name | what it is | use it to |
//! |---|---|---|
//! | [`MechanicalSystem<N>`] | the equations of a model compiled by `eomgen::model!`, `N` known at build time, on stack vectors | write a model by hand, or call a compiled model's functions directly |
//! | [`DynMechanicalSystem`] | the same equations with `n` known at run time, on slices | implement a run-time backend (the JIT's models do) |
//! | [`FirstOrder<S, N>`] | a compiled model as `ẏ = f(t, y)`, allocation-free, with constraints solved | integrate a compiled model at full speed |
//! | [`DynFirstOrder<S>`] | a run-time model as `ẏ = f(t, y)`, the same solves in the same order | integrate a run-time model |
//! | [`ModelInfo`] | either first-order form with its size erased (`Box<dyn ModelInfo>`) | pass a model to an analysis; what the CLI holds |
//! | [`OdeSystem`] | any first-order system `ẏ = f(t, y)`, with optional Jacobian and events | write an integrator, or integrate an ODE that is not a mechanism |
//!
//! Everything about a model that is not a function of the state (names, parameters, points,
//! constraints, equilibria, events, the equations as text) is its [`ModelDescription`],
//! returned by `description()` of each of the first five.
//!
//! # Layout
//!
//! - the model types above: [`system`], [`dynamic`], [`first_order`], [`model_info`], [`ode`],
//!   [`constrained`] (the index-1 solve with constraints and drift control);
//! - [`integrate`]: the integrators, step-size control, events and dense output;
//! - [`hybrid`]: motions through impacts at unilateral contacts ([`hybrid::impact()`]);
//! - [`linear`]: the building blocks of the linear analyses (linearisation and modes,
//!   responses, `H(ω)`, monodromy), functions of matrices;
//! - [`analysis`]: the analyses, each one call with typed options, a `Serialize` report and a
//!   typed error ([`analysis::vibration`] for the vibration analyses, the rest for the
//!   numerical studies).
#![warn(missing_docs)]

/// Defines `fn $name` whose body runs in one of two copies: the code compiled for any
/// processor of the target, or — on x86-64, when [`taylor::host_features`] says the processor
/// has AVX2 and FMA — the same body compiled a second time with those instruction sets
/// enabled. The body is inlined into both copies (functions it calls that are not inlined run
/// their one copy, compiled for any x86-64); both compute the same bits (see
/// `host_features`). The choice between them is inlined into the caller and each copy is out
/// of line, so a call of `$name` on a processor with AVX2 is one call, not a call of a function
/// that calls the copy. For the Taylor method's hot functions.
macro_rules! with_host_features {
    ($(#[$meta:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block) => {
        $(#[$meta])*
        #[inline(always)]
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[inline(always)]
            fn body($($arg: $ty),*) $(-> $ret)? $body
            #[cfg(target_arch = "x86_64")]
            if $crate::taylor::host_features() {
                #[target_feature(enable = "avx2,fma")]
                #[inline(never)]
                unsafe fn with_avx2($($arg: $ty),*) $(-> $ret)? {
                    body($($arg),*)
                }
                // SAFETY: the processor has AVX2 and FMA (`host_features`).
                return unsafe { with_avx2($($arg),*) };
            }
            #[inline(never)]
            fn for_any_processor($($arg: $ty),*) $(-> $ret)? {
                body($($arg),*)
            }
            for_any_processor($($arg),*)
        }
    };
}

pub mod analysis;
pub mod constrained;
pub mod dynamic;
pub mod first_order;
pub mod functions;
pub mod hybrid;
pub mod integrate;
pub mod linalg;
pub mod linear;
pub mod model_info;
pub mod ode;
pub(crate) mod serde_matrix;
pub mod system;
pub mod taylor;

pub use analysis::{Method, UnknownMethod};
pub use constrained::{
    ConstraintWorkspace, MAX_BAUMGARTE_GAIN, ProjectionError, Stabilization, StabilizationError,
};
pub use dynamic::DynMechanicalSystem;
/// The model description's crate: [`ModelDescription`] and the file's reference results it
/// carries ([`description::checks`], [`description::floquet`]).
pub use eomgen_description as description;
pub use eomgen_description::Parameter;
pub use first_order::{DynFirstOrder, FirstOrder};
pub use integrate::{
    BogackiShampine32, DormandPrince54, DormandPrince853, Event, EventDirection, EventSpec,
    ExplicitEuler, ExplicitMidpoint, ImplicitMidpoint, IntegrationError, IntegrationFailure,
    Integrator, IntegratorOptions, NewtonWork, OutputTimes, PiController, PredictiveController,
    RadauIIA5, RungeKutta4, Solution, Stats, StepOutcome, StepSizeController, StormerVerlet,
    SymplecticEuler, Tableau, Taylor, Tolerance, Verner65, Verner76, Verner87, Verner98,
};
pub use linalg::{solve_spd, solve_spd_in_place};
pub use linear::eigenvalues::{
    LinearStability, Stability, damped_modes, linear_stability, state_eigenvalues, verdict,
};
pub use linear::frequency_response::{
    ForcedLinearization, FrequencySweep, FrfError, HarmonicForcing, ModalResponse, PeakAmplitude,
    ResonancePeak, SteadyState, SteadyStateOptions, frequency_response, frequency_response_of,
    frequency_sweep, linearize_with_inputs, log_frequencies, modal_frequency_response,
    phase_degrees, settling_time, simulate_steady_state,
};
pub use linear::frequency_response::{
    frequency_response_to, frequency_sweep_with_rates, harmonic_input, linearize_with_input_rates,
};
pub use linear::modal::{
    Equilibrium, Linearization, MASS_MATRIX_SINGULARITY, ModalError, ModeKind, NewtonStop,
    NormalModes, TimeDependentForcing, TimeDependentPart, constraint_hessians,
    eigenvalues_of_m_inv_k, find_equilibrium, linearize, matrix_exponential, normal_modes,
    time_dependence,
};
pub use linear::monodromy::{
    FloquetAnalysis, FloquetError, FloquetOptions, FloquetStability, LARGEST_STABILITY_TOLERANCE,
    check_periodic_equilibrium, floquet_analysis, floquet_multipliers, monodromy_matrix,
};
pub use linear::response::{
    DampedMode, FreeResponse, LinearOde, MInvKModes, ModalDamping, RayleighDamping, ResponseError,
    exact_damped_modes, modal_damping, modes_of_m_inv_k, response_by_exponential,
    response_by_integration, response_by_m_inv_k_modes, response_by_normal_modes,
    response_with_modal_damping, state_response_by_eigenvectors, state_response_by_exponential,
    state_response_by_integration,
};
pub use linear::state_space::{StateSpace, state_space};
pub use linear::steady::{
    SteadyLinearization, SteadyMotion, SteadyMotionError, find_steady_motion, general_eigenvalues,
    linearize_steady_motion, steady_stability,
};
pub use model_info::{ConstraintValues, ContactValues, ModelInfo, ModelSummary};
pub use ode::{OdeFn, OdeSystem, RhsError, WithEvents};
pub use system::{
    BodyCentre, FrameSpec, MechanicalSystem, ModelDescription, RotationSpec, Shape,
    UnknownParameter,
};
