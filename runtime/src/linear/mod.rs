//! The linear-algebra building blocks the analyses are made of, each a function of matrices
//! (or of a model at one operating point) with no options struct and no report:
//!
//! - [`modal`]: equilibria, the exact linearisation `M δq̈ + C δq̇ + K δq = 0` and its state
//!   matrix, undamped normal modes, damped modes, the matrix exponential;
//! - [`response`]: the free response of a linearisation computed several independent ways,
//!   and damping models (modal, Rayleigh) against the exact damped modes;
//! - [`frequency_response`]: input matrices of load parameters, `H(ω) = (K − ω²M + iωC)⁻¹ B`,
//!   resonance peaks, modal sums, and the steady state of the full model by simulation;
//! - [`monodromy`]: the monodromy matrix of a periodic linearisation, Floquet multipliers and
//!   the stability they imply.
//!
//! The analyses on top of them — typed options, a `Serialize` report and a typed error, one
//! call per CLI command — are in [`crate::analysis`] ([`crate::analysis::vibration`] for
//! these).

pub mod frequency_response;
pub mod modal;
pub mod monodromy;
pub mod response;
