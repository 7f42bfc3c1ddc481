//! Hybrid motions: smooth phases joined by impacts at unilateral contacts.
//!
//! A unilateral contact has a gap `g(q, t) ≥ 0` with gradient `G = ∂g/∂q`; it closes with an
//! impact when `g` reaches 0 with `ġ = G q̇ < 0`. At the impact the velocities jump and the
//! configuration does not. [`impact()`] computes the jump from the same mass matrix and
//! constraint Jacobians as the smooth equations.
//!
//! # References
//! - F. Pfeiffer, C. Glocker, *Multibody Dynamics with Unilateral Contacts*, Wiley, 1996.
//! - W. J. Stronge, *Impact Mechanics*, Cambridge University Press, 2000 (frictional impacts).
//! - R. I. Leine, H. Nijmeijer, *Dynamics and Bifurcations of Non-smooth Mechanical Systems*,
//!   Springer, 2004, doi:10.1007/978-3-540-44398-8.

pub mod impact;
mod phase;
pub mod record;
pub mod run;
pub mod support;

pub use impact::{ImpactContact, ImpactError, ImpactMode, ImpactReport, impact};
pub use record::{ContactStop, HybridRecord, Transition, TransitionKind};
pub use run::integrate_through_impacts;
