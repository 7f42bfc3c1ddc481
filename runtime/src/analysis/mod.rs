//! Analyses on the size-erased model ([`ModelInfo`](crate::ModelInfo)) that the CLI and an
//! embedding Rust program share: the method registry, drift measures, simulation, the
//! numerical studies, and the vibration analyses ([`vibration`]), which are built on the
//! linear-algebra blocks of [`crate::linear`].
//!
//! Every analysis is a function with a typed options struct, a `Serialize` report and a
//! typed error, so that a front end only parses its input and renders the report. Every
//! study's report implements [`StudyRuns`]: a study whose every run failed measured nothing,
//! and [`StudyRuns::check_measured`] says so with the first failure's reason.

pub mod constraint_methods;
pub mod drift;
pub mod failure;
pub mod fixed_step;
pub mod gait;
pub mod launch;
pub mod methods;
pub mod outcome;
pub mod periodic_orbit;
pub mod rolling_contact;
pub mod roundoff;
pub mod simulation;
pub mod stability;
pub mod vibration;
pub mod work_precision;

pub use constraint_methods::{
    ConstraintMethodRow, ConstraintMethodSummary, ConstraintMethods, ConstraintMethodsError,
    ConstraintMethodsOptions, ConstraintMethodsSummary, ConstraintReferenceSummary,
    constraint_methods, constraint_methods_with_reduced,
};
pub use drift::{ConstraintDrift, EnergyDrift, constraint_drift, energy_drift, energy_drift_at};
pub use failure::{FailureCause, failure_cause};
pub use fixed_step::{ENERGY_DRIFT_LIMIT, SimulationWarning, fixed_step_warnings};
pub use gait::{
    Gait, GaitBifurcation, GaitError, GaitOptions, GaitStabilityChange, GaitSweep, GaitSweepPoint,
    ReturnMap, gait, gait_sweep, return_map,
};
pub use methods::{Amplification, Constructor, Method, MethodInfo, UnknownMethod};
pub use outcome::{NothingMeasured, RunTally, StudyRuns};
pub use periodic_orbit::{
    NewtonStep, OrbitSamples, PeriodicOrbit, PeriodicOrbitError, PeriodicOrbitOptions,
    periodic_orbit,
};
pub use rolling_contact::{
    RollingContact, RollingContactError, RollingContactOptions, rolling_contact,
};
pub use roundoff::{EulerRoundoff, RoundoffError, RoundoffOptions, euler_roundoff};
pub use simulation::{
    AddedEvents, DriftPair, EventSummary, FailureSummary, Simulation, SimulationError,
    SimulationOptions, SimulationSample, SimulationSummary, WarningSummary, check_initial_state,
    simulate, simulate_with_events,
};
pub use stability::{
    StabilityError, StabilityOptions, StabilityStudy, StiffSpring, stability_study,
};
pub use work_precision::{
    AtTarget, Measured, MethodRuns, MethodRunsSummary, ReferenceSummary, RunFailure, RunSummary,
    Setting, SettingRun, TargetSummary, TimingSummary, WorkPrecision, WorkPrecisionError,
    WorkPrecisionOptions, WorkPrecisionSummary, work_precision,
};
