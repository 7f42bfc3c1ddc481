//! The linearisation about an equilibrium as a state-space model for control design:
//! `δẏ = A δy + B u`, `z = C δy + D u`, with `y = [q; q̇]`, named inputs `u` (load parameters
//! or unit generalized forces, as [`linearize_with_inputs`] reads them) and named outputs `z`
//! (coordinates and rates).
//!
//! # Source
//! Lecture 21 (the forced linearisation `M δq̈ + C δq̇ + K δq = B u`); the first-order form is
//! the standard one of linear control (K. Ogata, *Modern Control Engineering*, 5th ed., §2-4).

use nalgebra::DMatrix;
use serde::Serialize;

use super::frequency_response::{FrfError, linearize_with_inputs, output_index};
use crate::ModelInfo;

/// A state-space model `δẏ = A δy + B u`, `z = C δy + D u` of a model about an equilibrium,
/// found with every input at 0.
///
/// # Shapes
/// `n` coordinates, `r` inputs, `o` outputs: `A` is `2n × 2n`, `B` `2n × r`, `C` `o × 2n`,
/// `D` `o × r` (zero: no output here reads an input directly).
///
/// # Units
/// The state's are the coordinates' and their rates'; a column of `B` is the acceleration
/// per unit of its input; `C` is dimensionless (it selects components of the state).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StateSpace {
    /// The state's components: the coordinates, then their rates (`theta1_dot`).
    pub states: Vec<String>,
    /// The inputs, in the order of `B`'s columns.
    pub inputs: Vec<String>,
    /// The outputs, in the order of `C`'s rows.
    pub outputs: Vec<String>,
    /// The equilibrium `q*` the model is linearised about (inputs at 0).
    pub equilibrium: Vec<f64>,
    /// `A = [0 I; −M⁻¹K −M⁻¹C]`.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub a: DMatrix<f64>,
    /// `B = [0; M⁻¹B_q]`, `B_q = ∂F/∂u` ([`linearize_with_inputs`]).
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub b: DMatrix<f64>,
    /// One row per output, `1` at its component of the state.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub c: DMatrix<f64>,
    /// Zero.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub d: DMatrix<f64>,
}

/// The state-space model of `model` about its equilibrium near `guess`, found with every
/// input at 0, from `inputs` (parameters that enter the forcing linearly, or coordinates'
/// names: a unit generalized force) to `outputs` (coordinates, or their rates written
/// `NAME_dot`; empty: every coordinate).
///
/// The model's parameters are left as they were.
///
/// # Errors
/// As [`linearize_with_inputs`] (an unconstrained model, inputs that are load amplitudes, an
/// equilibrium, a positive definite `M`); [`FrfError::UnknownOutput`] for an output that is
/// neither a coordinate nor a rate.
///
/// # References
/// Lecture 21 (forced linearisation); K. Ogata, *Modern Control Engineering*, 5th ed., §2-4.
pub fn state_space(
    model: &mut dyn ModelInfo,
    guess: &[f64],
    inputs: &[&str],
    outputs: &[&str],
) -> Result<StateSpace, FrfError> {
    let coordinates: Vec<String> = model
        .description()
        .coordinate_names()
        .iter()
        .map(|c| c.to_string())
        .collect();
    let n = coordinates.len();
    let rows: Vec<(String, usize)> = if outputs.is_empty() {
        coordinates.iter().cloned().zip(0..n).collect()
    } else {
        outputs
            .iter()
            .map(|&name| {
                let index = match name.strip_suffix("_dot") {
                    Some(c) if coordinates.iter().any(|x| x == c) => n + output_index(model, c)?,
                    _ => output_index(model, name)?,
                };
                Ok((name.to_string(), index))
            })
            .collect::<Result<_, FrfError>>()?
    };
    let forced = linearize_with_inputs(model, guess, inputs)?;
    let a = forced.linearization.state_matrix()?;
    let b = forced.state_input_matrix()?;
    let mut c = DMatrix::zeros(rows.len(), 2 * n);
    for (row, (_, index)) in rows.iter().enumerate() {
        c[(row, *index)] = 1.0;
    }
    let states = coordinates
        .iter()
        .cloned()
        .chain(coordinates.iter().map(|c| format!("{c}_dot")))
        .collect();
    Ok(StateSpace {
        states,
        inputs: forced.inputs.clone(),
        outputs: rows.into_iter().map(|(name, _)| name).collect(),
        equilibrium: forced.equilibrium.q.clone(),
        d: DMatrix::zeros(c.nrows(), b.ncols()),
        a,
        b,
        c,
    })
}
