//! The linearisation about an equilibrium as a state-space model for control design:
//! `ẋ = A x + B u`, `z = C x + D u`, with `x = [δq; δq̇]`, named inputs `u` (load parameters
//! or unit generalized forces, as [`linearize_with_input_rates`] reads them) and named
//! outputs `z` (coordinates and rates).
//!
//! An input that also enters through its rate, `M δq̈ + C δq̇ + K δq = B₀ u + B₁ u̇` (a base
//! motion through a dashpot), takes the state `x = [δq; δq̇ − M⁻¹B₁u]`, so that no `u̇`
//! appears: `B = [M⁻¹B₁; M⁻¹(B₀ − C M⁻¹B₁)]`, and a rate output reads `D = M⁻¹B₁` beside
//! its row of `C`.
//!
//! # Source
//! Lecture 21 (the forced linearisation `M δq̈ + C δq̇ + K δq = B u`), lecture 38 (base
//! excitation); the first-order form with an input's derivative is the standard realisation
//! of linear control (K. Ogata, *Modern Control Engineering*, 5th ed., §2-4).

use nalgebra::DMatrix;
use serde::Serialize;

use super::frequency_response::{FrfError, linearize_with_input_rates, output_index};
use crate::ModelInfo;

/// A state-space model `ẋ = A x + B u`, `z = C x + D u` of a model about an equilibrium,
/// found with every input at 0 (see the [module](self) docs for an input with a rate).
///
/// # Shapes
/// `n` coordinates, `r` inputs, `o` outputs: `A` is `2n × 2n`, `B` `2n × r`, `C` `o × 2n`,
/// `D` `o × r` (zero unless a rate output reads an input's rate column).
///
/// # Units
/// The state's are the coordinates' and their rates'; a column of `B` is the acceleration
/// (or, with a rate column, the velocity) per unit of its input; `C` is dimensionless (it
/// selects components of the state).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StateSpace {
    /// The state's components: the coordinates, then their rates (`theta1_dot`; with an
    /// input rate, `theta1_dot - (M⁻¹B₁u)_theta1`).
    pub states: Vec<String>,
    /// Whether some input enters through its rate (`B₁ ≠ 0`, [`linearize_with_input_rates`]
    /// with the model's `w`).
    pub input_rates: bool,
    /// The inputs, in the order of `B`'s columns.
    pub inputs: Vec<String>,
    /// The outputs, in the order of `C`'s rows.
    pub outputs: Vec<String>,
    /// The equilibrium `q*` the model is linearised about (inputs at 0).
    pub equilibrium: Vec<f64>,
    /// `A = [0 I; −M⁻¹K −M⁻¹C]`.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub a: DMatrix<f64>,
    /// `B = [0; M⁻¹B₀]`, `B₀ = ∂F/∂u` ([`linearize_with_input_rates`]); with rate columns
    /// `B₁`, `[M⁻¹B₁; M⁻¹(B₀ − C M⁻¹B₁)]`.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub b: DMatrix<f64>,
    /// One row per output, `1` at its component of the state.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub c: DMatrix<f64>,
    /// Zero, but for a rate output with rate columns: its row of `M⁻¹B₁`.
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub d: DMatrix<f64>,
}

/// The state-space model of `model` about its equilibrium near `guess`, found with every
/// input at 0, from `inputs` (parameters that enter the forcing linearly, or coordinates'
/// names: a unit generalized force) to `outputs` (coordinates, or their rates written
/// `NAME_dot`; empty: every coordinate).
///
/// A parameter input's load is read at `t = 0` (for `A*cos(w*t)` the input is the load's
/// value); one that reverses over half a period of the model's parameter `w` is also read a
/// quarter period later for its rate column, as `frf` reads it. The model's parameters are
/// left as they were.
///
/// # Errors
/// As [`linearize_with_input_rates`] (an unconstrained model, inputs that are load
/// amplitudes, an equilibrium, a positive definite `M`); [`FrfError::UnknownOutput`] for an
/// output that is neither a coordinate nor a rate.
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
    // The rate columns are read as `frf` reads them by default: with the model's `w`.
    let has_w = model.description().parameter_names().contains(&"w");
    let forced = if has_w {
        linearize_with_input_rates(model, guess, inputs, "w")?
    } else {
        super::frequency_response::linearize_with_inputs(model, guess, inputs)?
    };
    let lin = &forced.linearization;
    let a = lin.state_matrix()?;
    let chol = lin.mass_cholesky()?;
    let rates = chol.solve(&forced.input_rate_matrix);
    let input_rates = forced.has_input_rates();
    let r = forced.inputs.len();
    let mut b = DMatrix::zeros(2 * n, r);
    let velocity = chol.solve(&(&forced.input_matrix - &lin.damping_matrix * &rates));
    b.view_mut((0, 0), (n, r)).copy_from(&rates);
    b.view_mut((n, 0), (n, r)).copy_from(&velocity);
    let mut c = DMatrix::zeros(rows.len(), 2 * n);
    let mut d = DMatrix::zeros(rows.len(), r);
    for (row, (_, index)) in rows.iter().enumerate() {
        c[(row, *index)] = 1.0;
        if *index >= n {
            d.row_mut(row).copy_from(&rates.row(index - n));
        }
    }
    let states = coordinates
        .iter()
        .cloned()
        .chain(coordinates.iter().map(|c| match input_rates {
            true => format!("{c}_dot - (M⁻¹B₁u)_{c}"),
            false => format!("{c}_dot"),
        }))
        .collect();
    Ok(StateSpace {
        states,
        input_rates,
        inputs: forced.inputs.clone(),
        outputs: rows.into_iter().map(|(name, _)| name).collect(),
        equilibrium: forced.equilibrium.q.clone(),
        a,
        b,
        c,
        d,
    })
}
