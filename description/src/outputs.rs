//! The file's `outputs:`: named expressions of the state evaluated along a simulation
//! (`eomgen simulate` prints them in its CSV and JSON), some declared constants of the motion,
//! whose drift `eomgen simulate` prints beside the energy's and `eomgen report` checks
//! (docs/model-format.md, "outputs"; lectures 3–7: angular momentum of central forces and
//! many particles).
//!
//! The value is an expression in the model file's syntax, a function of the parameters,
//! coordinates, rates and `t`, kept as text: as written, or, when the file wrote it with the
//! vector functions of points (`m*cross(P - O, vel(P))`), with the points' positions and
//! velocities written out in the coordinates and rates, so that it is evaluated from the
//! state alone, the same for a compiled model and a file loaded at run time.

use serde::Serialize;

use crate::Text;

/// One `outputs:` entry.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OutputSpec {
    /// Its name (`L`).
    pub name: Text,
    /// The quantity: an expression of the parameters, coordinates, rates and `t`.
    pub value: Text,
    /// Whether the file declares it a constant of the motion (`conserved: true`).
    pub conserved: bool,
    /// For a conserved output: the bound on `max |Q(t) − Q(0)| / max(1, |Q(0)|)` (the file's
    /// `tolerance:`, 1e-9 by default, as a `checks: conserved:` entry's).
    pub tolerance: f64,
}
