//! The linear-algebra building blocks the analyses are made of: functions of matrices, or of
//! a model about one operating point (the steady state and the monodromy matrix integrate
//! it, with their own small options), each with a typed error and results that are plain
//! values (serialisable where a report embeds them):
//!
//! - [`eigenvalues`]: the eigenvalues of the whole state matrix (damping and gyroscopic
//!   terms), accurate on badly scaled models, the damped modes and the stability verdict
//!   from them;
//! - [`equilibrium`]: equilibria by damped Newton;
//! - [`modal`]: the exact linearisation `M δq̈ + C δq̇ + K δq = 0` and its state
//!   matrix, undamped normal modes, the matrix exponential (a model in generalized speeds
//!   is linearised in its coordinates by the private `speeds` module);
//! - [`response`]: the free response of a linearisation computed several independent ways,
//!   and damping models (modal, Rayleigh) against the exact damped modes;
//! - [`frequency_response`]: input matrices of load parameters, `H(ω) = (K − ω²M + iωC)⁻¹ B`,
//!   resonance peaks, modal sums, and the steady state of the full model by simulation;
//! - [`state_space`]: the forced linearisation as `δẏ = A δy + B u`, `z = C δy + D u` with
//!   named inputs and outputs, for control design;
//! - [`steady`]: steady motions (constant rates, ignorable coordinates drifting) and their
//!   linearisation restricted to the constraints, holonomic and non-holonomic;
//! - [`turning`]: steady turns, whose rates are constant in a frame turning with the motion,
//!   and their linearisation in that frame;
//! - [`monodromy`]: the monodromy matrix of a periodic linearisation, Floquet multipliers and
//!   the stability they imply.
//!
//! The analyses on top of them — one call per CLI command or study, with its options, a
//! `Serialize` report and a typed error — are in [`crate::analysis`]
//! ([`crate::analysis::vibration`] for these).

pub mod eigenvalues;
pub mod equilibrium;
pub mod frequency_response;
pub mod modal;
pub mod monodromy;
pub mod response;
pub(crate) mod speeds;
pub mod state_space;
pub mod steady;
mod stops;
pub mod time_dependence;
pub mod turning;
