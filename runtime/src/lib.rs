//! The numeric half of eomgen.
//!
//! Generated code (from `eomgen::model!`) implements [`MechanicalSystem`]; the runtime turns
//! `M(q, t) q̈ = F(q, q̇, t)` into the first-order system `ẏ = [q̇; M⁻¹F]` ([`FirstOrder`]) and
//! integrates it with any [`Integrator`].
#![warn(missing_docs)]

pub mod constrained;
pub mod floquet;
pub mod integrate;
pub mod modal;
pub mod ode;
pub mod system;

pub use constrained::{ConstraintWorkspace, ProjectionError, Stabilization};
pub use floquet::{
    FloquetAnalysis, FloquetError, FloquetOptions, FloquetStability, check_periodic_equilibrium,
    floquet_analysis, floquet_multipliers, monodromy_matrix,
};
pub use integrate::{
    BogackiShampine32, DormandPrince54, DormandPrince853, Event, EventDirection, EventSpec,
    ExplicitEuler, ExplicitMidpoint, ImplicitMidpoint, IntegrationError, IntegrationFailure,
    Integrator, IntegratorOptions, OutputTimes, PiController, PredictiveController, RadauIIA5,
    RungeKutta4, Solution, Stats, StepOutcome, StepSizeController, StormerVerlet, SymplecticEuler,
    Tableau, Tolerance,
};
pub use modal::{
    Equilibrium, Linearization, ModalError, ModeKind, NormalModes, damped_modes,
    eigenvalues_of_m_inv_k, find_equilibrium, linearize, matrix_exponential, normal_modes,
};
pub use ode::{OdeFn, OdeSystem, RhsError, WithEvents};
pub use system::{ConstraintValues, FirstOrder, MechanicalSystem, ModelInfo, UnknownParameter};
