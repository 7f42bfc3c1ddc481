//! Forcing: the input matrix of named load parameters, the frequency response
//! `H(ω) = (K − ω²M + iωC)⁻¹ B`, its resonance peaks, the same response assembled mode by mode
//! (modal forcing), and the steady state measured by simulating the full model (lecture 21,
//! HW21, HW34, HW37).
//!
//! long: the forced linearisation (the input matrix and its rates), the frequency response
//! with its peaks, and the modal sum share the scaled dynamic stiffness and the peak search;
//! the modal sum and the peak search could be rooms of their own, a split left to the issue on
//! the code's shape.
//!
//! # Inputs
//!
//! An *input* is a parameter `p` of the model that enters the forcing `F(q, q̇, t)` linearly:
//! a load amplitude, such as `A` in `models/forced_oscillator.yaml`, where
//! `F = −k x − c ẋ + A cos(w t) + B sin(w t)`. Its column of the input matrix is
//!
//! ```text
//! b_p = ∂F/∂p (q*, 0, t = 0) = F(q*, 0, 0; p = 1) − F(q*, 0, 0; p = 0)
//! ```
//!
//! exact for a linear input, which is verified: `F(p = 2) − F(p = 1)` must equal `b_p` to
//! rounding, else [`FrfError::NonlinearInput`]. The equilibrium `q*` is found with every input
//! set to 0, so the inputs are the whole of the load. The input `u(t)` multiplies whatever
//! time function the model attaches to `p`, *evaluated at `t = 0`*: for `A cos(w t)` that is 1,
//! so the frequency response from `A` to `x` is exactly the steady-state response to
//! `A cos(ω t)` with `w = ω`: `x(t) = x* + Re(H(ω) A e^{iωt})`. A time function that vanishes at
//! `t = 0` (`B sin(w t)`) gives a zero column: [`FrfError::InputNotInForcing`].
//!
//! # Inputs that enter through their rate (base excitation)
//!
//! A prescribed base motion `y_b = Y cos(w t)` acting through a spring `k` and a dashpot `c`
//! loads the mass with `k y_b + c ẏ_b = k Y cos(w t) − c Y w sin(w t)`: the input `Y` enters
//! through its value and its rate, `F = … + B₀ u + B₁ u̇` with `u = Y cos(w t)`. At `t = 0` only
//! `B₀ = k` is seen. [`linearize_with_input_rates`] also reads the load a quarter period later,
//! `t = π/(2w)` with `w` the model's frequency parameter, where `∂F/∂p = −w B₁`, and checks at a
//! second frequency `w' = 3w/2` that `B₁` does not change (else [`FrfError::InputRateNotConstant`]:
//! the time function is not `cos(w t)` and its rate). For `u = Re(û e^{iωt})` the load is then
//! `Re((B₀ + iω B₁) û e^{iωt})` and
//!
//! ```text
//! H(ω) = (K − ω²M + iωC)⁻¹ (B₀ + iω B₁)
//! ```
//!
//! — for the base-excited oscillator the transmissibility `(k + iωc)/(k − mω² + iωc)` (lecture
//! 38). A load `A cos(w t)` has `B₁ = 0` exactly (the quarter-period value, `cos(π/2) ≈ 6e-17`,
//! is below `1e-12` of the load and taken as 0), so its response is unchanged.
//!
//! # Frequency response
//!
//! Linearising `M q̈ = F + B u` at `q*` gives `M δq̈ + C δq̇ + K δq = B u`; for
//! `u = Re(û e^{iωt})` the steady state is `δq = Re(H(ω) û e^{iωt})` with
//!
//! ```text
//! H(ω) = (K − ω²M + iωC)⁻¹ B      (n × r, complex; units of q per unit input)
//! ```
//!
//! solved by complex LU with partial pivoting at each `ω`. The amplitude is `|Hᵢⱼ|` and the
//! phase `arg Hᵢⱼ` (a lag is negative). Without damping `H` is real and singular at every
//! natural frequency that the input excites and the output sees: those peaks are reported as
//! [`PeakAmplitude::Unbounded`], not as a large number.
//!
//! # Modal forcing
//!
//! With the mass-normalised mode shapes `Ψ` (`ΨᵀMΨ = I`, `ΨᵀKΨ = diag ω_k²`), the modal
//! coordinates `η = Ψ⁻¹ δq` obey `η̈_k + Ĉ_kk η̇_k + ω_k² η_k = ψ_kᵀ B u` when the modal damping
//! matrix `Ĉ = ΨᵀCΨ` is diagonal (`C = αM + βK`, proportional damping, or no damping), so
//!
//! ```text
//! δq = Σ_k ψ_k ψ_kᵀ B u / (ω_k² − ω² + 2iζ_k ω_k ω),   2ζ_k ω_k = Ĉ_kk
//! ```
//!
//! is exact (HW37 (c)). For a non-diagonal `Ĉ` the off-diagonal part is dropped (HW34's
//! approximation); [`ModalDamping::coupling`](crate::ModalDamping::coupling) says how large it was.

use nalgebra::{Complex, DMatrix, DVector};

use crate::integrate::{
    DormandPrince853, IntegrationError, Integrator, IntegratorOptions, OutputTimes, Solution,
};
use crate::linear::eigenvalues::damped_modes;
use crate::linear::modal::{
    Equilibrium, Linearization, ModalError, ModeKind, NormalModes, find_equilibrium, linearize,
    time_dependence,
};
use crate::linear::response::modal_damping;
use crate::model_info::ModelInfo;
use crate::system::UnknownParameter;

/// Why an input matrix, a frequency response or a steady-state simulation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FrfError {
    /// The equilibrium search or the linearisation failed.
    #[error(transparent)]
    Modal(#[from] ModalError),
    /// The model has constraints: its linearisation is in minimal coordinates, while inputs
    /// and outputs here are in the model's coordinates.
    #[error(
        "`{model}` has constraints; frequency responses are computed for unconstrained models (its modes: `eomgen modes {model}`)"
    )]
    Constrained {
        /// The model.
        model: String,
    },
    /// An input or frequency parameter the model does not have.
    #[error(transparent)]
    UnknownParameter(#[from] UnknownParameter),
    /// `F(p = 2) − F(p = 1)` differs from `F(p = 1) − F(p = 0)`: `p` is not a load amplitude.
    #[error(
        "input `{input}` does not enter the forcing linearly: F(p = 2) − F(p = 1) differs from F(p = 1) − F(p = 0) by {deviation:e} of max |F| (a load amplitude multiplies the forcing, like `A` in `A*cos(w*t)`)"
    )]
    NonlinearInput {
        /// The parameter.
        input: String,
        /// `max |(F₂ − F₁) − (F₁ − F₀)| / max |F|`.
        deviation: f64,
    },
    /// Changing `p` leaves `F(q*, 0, 0)` unchanged: its column of `B` would be zero.
    #[error(
        "input `{input}` does not change the forcing at the equilibrium at t = 0 (its column of the input matrix is zero): an input is a load amplitude whose time function is nonzero at t = 0, like `A` in `A*cos(w*t)` (not `B` in `B*sin(w*t)`, nor a stiffness, damping or frequency)"
    )]
    InputNotInForcing {
        /// The parameter.
        input: String,
    },
    /// Changing `p` changes the mass matrix: it is a property of the system, not a load.
    #[error(
        "input `{input}` changes the mass matrix: it is a property of the system, not a load amplitude"
    )]
    InputChangesMassMatrix {
        /// The parameter.
        input: String,
    },
    /// An output name that is not a coordinate of the model.
    #[error("`{output}` is not a coordinate of `{model}` (coordinates: {coordinates})")]
    UnknownOutput {
        /// The name asked for.
        output: String,
        /// The model.
        model: String,
        /// Its coordinates, comma separated.
        coordinates: String,
    },
    /// A frequency that is negative or not finite.
    #[error("the frequency {frequency} rad/s is not finite and ≥ 0")]
    InvalidFrequency {
        /// The frequency (rad/s).
        frequency: f64,
    },
    /// A frequency range that is not `0 < lo < hi < ∞`.
    #[error("the frequency range [{lo}, {hi}] rad/s is not 0 < lo < hi < ∞")]
    InvalidFrequencyRange {
        /// Lower end (rad/s).
        lo: f64,
        /// Upper end (rad/s).
        hi: f64,
    },
    /// `K − ω²M + iωC` is singular: an undamped resonance (or a rigid-body mode at `ω = 0`).
    #[error(
        "K − ω²M + iωC is singular at ω = {frequency} rad/s: an undamped resonance, where the steady-state response is unbounded"
    )]
    Singular {
        /// The frequency (rad/s).
        frequency: f64,
    },
    /// An entry of `H(ω)` is beyond the range of `f64` normal numbers (`2.2e-308` to
    /// `1.8e308`): far above the natural frequencies `|H| ≈ 1/(ω² m)` falls below it
    /// (`ω ≳ 1e154` for a unit mass).
    #[error(
        "the frequency response at ω = {frequency:e} rad/s is beyond the range of floating point: |H| of entry ({row}, {column}) is about 1e{log10_magnitude:.0} (normal f64 numbers lie between 2.2e-308 and 1.8e308)"
    )]
    ResponseOutOfRange {
        /// The frequency (rad/s).
        frequency: f64,
        /// The coordinate (row of `H`, from 0).
        row: usize,
        /// The input (column of `H`, from 0); for [`modal_frequency_response`], the mode
        /// (column of its contributions).
        column: usize,
        /// `log₁₀ |Hᵢⱼ|`, computed from the scaled solution.
        log10_magnitude: f64,
    },
    /// The load of an input read a quarter period after `t = 0` is not `−w B₁` with a `B₁`
    /// independent of the frequency: the input's time function is not `cos(w t)` (with its
    /// rate), so `B₀ + iω B₁` would not be its load at other frequencies.
    #[error(
        "input `{input}` does not enter as B₀ u + B₁ u̇ with u = {input} cos({frequency_parameter} t): its rate column changes by {deviation:e} (relative) between {frequency_parameter} and 3{frequency_parameter}/2 (a base motion `Y*cos(w*t)` through a spring and a dashpot does; so does a load `A*cos(w*t)`, with B₁ = 0)"
    )]
    InputRateNotConstant {
        /// The parameter.
        input: String,
        /// The frequency parameter.
        frequency_parameter: String,
        /// `max |B₁(3w/2) − B₁(w)| / max |B₁(w)|`.
        deviation: f64,
    },
    /// The input matrix has the wrong number of rows.
    #[error("the input matrix has {found} rows, the model {expected} coordinates")]
    DimensionMismatch {
        /// The degrees of freedom.
        expected: usize,
        /// Rows given.
        found: usize,
    },
    /// The free response does not decay, so no steady state is reached by simulation.
    #[error(
        "the free response does not decay (slowest decay rate {slowest_decay_rate:e} 1/s): without damping in every mode there is no steady state to simulate"
    )]
    NoSteadyState {
        /// `min −Re s` over the eigenvalues `s` of the state matrix (1/s).
        slowest_decay_rate: f64,
    },
    /// An option of the steady-state simulation is out of range.
    #[error("steady-state option `{option}` = {value} is out of range ({expected})")]
    InvalidOption {
        /// The option's name.
        option: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// The steady-state simulation failed.
    #[error("the steady-state simulation at ω = {frequency} rad/s failed: {error}")]
    Integration {
        /// The forcing frequency (rad/s).
        frequency: f64,
        /// Why.
        error: IntegrationError,
    },
    /// A terminal event of the model stopped the steady-state simulation.
    #[error(
        "a terminal event stopped the steady-state simulation at ω = {frequency} rad/s, t = {t} s"
    )]
    StoppedByEvent {
        /// The forcing frequency (rad/s).
        frequency: f64,
        /// When (s).
        t: f64,
    },
}

/// The linearisation of a forced model at its unforced equilibrium, with the input matrix of
/// its named load parameters (serialised with the input matrix as a list of rows).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ForcedLinearization {
    /// The equilibrium `q*`, found with every input set to 0.
    pub equilibrium: Equilibrium,
    /// `M`, `C`, `K` at `(q*, 0, t = 0)` with every input set to 0.
    pub linearization: Linearization,
    /// The input parameters, in the order of the columns of `input_matrix`.
    pub inputs: Vec<String>,
    /// `B = ∂F/∂u`, `n × r`: column `j` is the generalized force per unit of input `j` at
    /// `t = 0` (N or N·m per unit of the parameter). The state-space input matrix is
    /// [`ForcedLinearization::state_input_matrix`].
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub input_matrix: DMatrix<f64>,
    /// `B₁`, `n × r`: column `j` is the generalized force per unit *rate* of input `j` (N s or
    /// N·m·s per unit of the parameter), as for a base motion through a dashpot (see the
    /// [module](self) docs); zero unless found by [`linearize_with_input_rates`]. The input
    /// column at `ω` is `B₀ + iω B₁` ([`ForcedLinearization::input_at`]).
    #[serde(serialize_with = "crate::serde_matrix::rows")]
    pub input_rate_matrix: DMatrix<f64>,
}

impl ForcedLinearization {
    /// The state-space input matrix `[0; M⁻¹B]` (`2n × r`) of `δẏ = A δy + B_s u`,
    /// `y = [q; q̇]`.
    ///
    /// # Errors
    /// [`ModalError::SingularMassMatrix`] (as [`FrfError::Modal`]).
    pub fn state_input_matrix(&self) -> Result<DMatrix<f64>, FrfError> {
        let n = self.input_matrix.nrows();
        let r = self.input_matrix.ncols();
        let minv_b = self
            .linearization
            .mass_cholesky()?
            .solve(&self.input_matrix);
        let mut b = DMatrix::zeros(2 * n, r);
        b.view_mut((n, 0), (n, r)).copy_from(&minv_b);
        Ok(b)
    }

    /// The complex input matrix `B₀ + iω B₁` at `frequency` (rad/s), `n × r`: the complex
    /// amplitude of the generalized force per unit complex amplitude `û` of each input under
    /// `u = Re(û e^{iωt})`.
    pub fn input_at(&self, frequency: f64) -> DMatrix<Complex<f64>> {
        harmonic_input(&self.input_matrix, &self.input_rate_matrix, frequency)
    }

    /// Whether some input enters through its rate (`B₁ ≠ 0`).
    pub fn has_input_rates(&self) -> bool {
        self.input_rate_matrix.amax() > 0.0
    }
}

/// `B₀ + iω B₁` (`n × r`, complex) from the input matrix `B₀` and the input-rate matrix `B₁`
/// (both `n × r`) at `frequency` (rad/s).
///
/// # Panics
/// If the shapes of `input_matrix` and `input_rate_matrix` differ (a programmer error).
pub fn harmonic_input(
    input_matrix: &DMatrix<f64>,
    input_rate_matrix: &DMatrix<f64>,
    frequency: f64,
) -> DMatrix<Complex<f64>> {
    assert_eq!(input_matrix.shape(), input_rate_matrix.shape());
    input_matrix.zip_map(input_rate_matrix, |b0, b1| {
        Complex::new(b0, if b1 == 0.0 { 0.0 } else { frequency * b1 })
    })
}

/// Relative tolerance of the linearity test `F(2) − F(1) = F(1) − F(0)`, against `max |F|`:
/// rounding makes the two differences disagree by a few ulps of the largest force; a
/// parameter that enters nonlinearly (`p²`, `sin p`) disagrees at order 1.
const LINEARITY_TOLERANCE: f64 = 1e-10;

/// Finds the equilibrium of `model` near `guess` with the `inputs` set to 0, linearises there
/// at `t = 0`, and builds the input matrix `B` of the inputs (see the [module](self) docs).
///
/// An input is a parameter that enters the forcing linearly, or a coordinate's name: a unit
/// generalized force on that coordinate (column `eᵢ` of `B`; N or N·m per unit input), which
/// gives every model a frequency response (a parameter of the same name takes precedence).
///
/// The model's parameter values are restored before returning, on success and on error.
///
/// # Shapes
/// `guess` has `n = num_dofs()` entries; `input_matrix` is `n × r`, `r = inputs.len()`.
///
/// # Errors
/// [`FrfError::UnknownParameter`] for an input the model does not have;
/// [`FrfError::Modal`] if the equilibrium or the linearisation fails, or with
/// [`ModalError::TimeDependent`] when `M`, `C`, `K` or a constraint change with `t` (inputs at 0);
/// [`FrfError::NonlinearInput`], [`FrfError::InputNotInForcing`],
/// [`FrfError::InputChangesMassMatrix`] for a parameter that is not a load amplitude.
///
/// # References
/// Lecture 21 and HW21 (forced oscillator), HW37 (modal forcing).
pub fn linearize_with_inputs(
    model: &mut dyn ModelInfo,
    guess: &[f64],
    inputs: &[&str],
) -> Result<ForcedLinearization, FrfError> {
    let saved = model.parameter_values();
    let result = linearize_with_inputs_inner(model, guess, inputs);
    restore(model, &saved);
    result
}

fn restore(model: &mut dyn ModelInfo, values: &[f64]) {
    let names: Vec<String> = model
        .description()
        .parameter_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    for (name, value) in names.iter().zip(values) {
        // The names come from the model itself, so setting them cannot fail.
        let _ = model.set_parameter(name, *value);
    }
}

fn linearize_with_inputs_inner(
    model: &mut dyn ModelInfo,
    guess: &[f64],
    inputs: &[&str],
) -> Result<ForcedLinearization, FrfError> {
    if !model.description().constraint_names().is_empty() {
        return Err(FrfError::Constrained {
            model: model.description().name.to_string(),
        });
    }
    let coordinates: Vec<String> = model
        .description()
        .coordinate_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    for input in inputs {
        if model.description().parameter_names().contains(input)
            || !coordinates.iter().any(|c| c == input)
        {
            model.set_parameter(input, 0.0)?;
        }
    }
    let n = model.num_dofs();
    let equilibrium = find_equilibrium(&*model, guess, 0.0)?;
    let zeros = vec![0.0; n];
    let linearization = linearize(&*model, &equilibrium.q, &zeros, 0.0)?;
    // Coefficients that change with t (a shaken pivot) have no frequency response; a load
    // left in F that is not an input is the same at every frequency and stays out of H.
    time_dependence(&*model, &equilibrium.q, 0.0)?;
    let y = super::speeds::rest_state(&*model, &equilibrium.q, 0.0).map_err(ModalError::from)?;
    let mut input_matrix = DMatrix::zeros(n, inputs.len());
    for (j, input) in inputs.iter().enumerate() {
        if !model.description().parameter_names().contains(input)
            && let Some(i) = coordinates.iter().position(|c| c == input)
        {
            // A unit generalized force on coordinate `i` (N or N·m per unit input).
            input_matrix[(i, j)] = 1.0;
            continue;
        }
        let (m0, f0) = model.mass_matrix_and_forcing(0.0, &y);
        model.set_parameter(input, 1.0)?;
        let (m1, f1) = model.mass_matrix_and_forcing(0.0, &y);
        model.set_parameter(input, 2.0)?;
        let (_, f2) = model.mass_matrix_and_forcing(0.0, &y);
        model.set_parameter(input, 0.0)?;
        let d1 = &f1 - &f0;
        let d2 = &f2 - &f1;
        let scale = f0.amax().max(f1.amax()).max(f2.amax());
        let deviation = (&d2 - &d1).amax();
        if deviation.is_nan() || deviation > LINEARITY_TOLERANCE * scale {
            return Err(FrfError::NonlinearInput {
                input: input.to_string(),
                deviation: if scale > 0.0 {
                    deviation / scale
                } else {
                    deviation
                },
            });
        }
        if (&m1 - &m0).amax() > LINEARITY_TOLERANCE * m0.amax() {
            return Err(FrfError::InputChangesMassMatrix {
                input: input.to_string(),
            });
        }
        if d1.amax() == 0.0 {
            return Err(FrfError::InputNotInForcing {
                input: input.to_string(),
            });
        }
        let column = super::speeds::coordinate_force(&*model, &equilibrium.q, 0.0, d1)
            .map_err(ModalError::from)?;
        input_matrix.set_column(j, &column);
    }
    Ok(ForcedLinearization {
        equilibrium,
        linearization,
        inputs: inputs.iter().map(|s| s.to_string()).collect(),
        input_rate_matrix: DMatrix::zeros(n, inputs.len()),
        input_matrix,
    })
}

/// A quarter-period load below this fraction of the largest generalized force is rounding
/// (`cos(π/2)` evaluates to `6.1e-17`), not a rate term: its `B₁` column is 0.
const RATE_TOLERANCE: f64 = 1e-12;

/// A change of `B₁` between two frequencies above this fraction of `max |B₁|` means the input's
/// time function is not `cos(w t)` with its rate (rounding of `w t` near `π/2` gives ~1e-15).
const RATE_CONSTANCY_TOLERANCE: f64 = 1e-9;

/// [`linearize_with_inputs`], and the input-rate matrix `B₁` of the parameter inputs read from
/// the load a quarter period after `t = 0` (see the [module](self) docs): with
/// `w = frequency_parameter` (the model's value), column `j` is
///
/// ```text
/// B₁ = −(F(q*, 0, π/(2w); p = 1) − F(q*, 0, π/(2w); p = 0)) / w
/// ```
///
/// set to 0 where it is below `1e-12` of the load (a load `A cos(w t)`), and checked to be
/// the same at `3w/2`. Only a load that reverses over half a period
/// (`∂F/∂p(π/w) = −∂F/∂p(0)` to `1e-9`) is read so: a constant load, or one that `w` does not
/// time, keeps `B₁ = 0`, as does a coordinate input (a unit generalized force). When the
/// frequency parameter is not finite and `> 0` the load is read at `w = 1` rad/s.
///
/// The model's parameter values are restored before returning, on success and on error.
///
/// # Shapes
/// As [`linearize_with_inputs`]; `input_rate_matrix` is `n × r`.
///
/// # Errors
/// As [`linearize_with_inputs`]; [`FrfError::UnknownParameter`] for a frequency parameter the
/// model does not have; [`FrfError::InputRateNotConstant`] when `B₁` differs between `w` and
/// `3w/2`;
/// [`FrfError::NonlinearInput`] when the quarter-period load is not linear in the input.
///
/// # References
/// Lecture 38 (vibration isolation), HW21 (a): the base-excited oscillator
/// `m ẍ + c ẋ + k x = k y_b + c ẏ_b`; D. J. Inman, *Engineering Vibration*, chapter 2 (base
/// excitation).
pub fn linearize_with_input_rates(
    model: &mut dyn ModelInfo,
    guess: &[f64],
    inputs: &[&str],
    frequency_parameter: &str,
) -> Result<ForcedLinearization, FrfError> {
    let mut forced = linearize_with_inputs(model, guess, inputs)?;
    let saved = model.parameter_values();
    let result = input_rate_matrix(model, &forced, frequency_parameter);
    restore(model, &saved);
    forced.input_rate_matrix = result?;
    Ok(forced)
}

fn input_rate_matrix(
    model: &mut dyn ModelInfo,
    forced: &ForcedLinearization,
    frequency_parameter: &str,
) -> Result<DMatrix<f64>, FrfError> {
    let names: Vec<String> = model
        .description()
        .parameter_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let index = names
        .iter()
        .position(|p| p == frequency_parameter)
        .ok_or_else(|| UnknownParameter {
            name: frequency_parameter.to_string(),
            model: model.description().name.to_string(),
            known: names.join(", "),
        })?;
    // `B₁` does not depend on the frequency (checked below), so any positive one will do.
    let w = match model.parameter_values()[index] {
        w if w.is_finite() && w > 0.0 => w,
        _ => 1.0,
    };
    let n = forced.input_matrix.nrows();
    let q = &forced.equilibrium.q;
    let y = super::speeds::rest_state(&*model, q, 0.0).map_err(ModalError::from)?;
    for input in &forced.inputs {
        if names.iter().any(|p| p == input) {
            model.set_parameter(input, 0.0)?;
        }
    }
    let mut rates = DMatrix::zeros(n, forced.inputs.len());
    for (j, input) in forced.inputs.iter().enumerate() {
        if !names.iter().any(|p| p == input) || input == frequency_parameter {
            continue;
        }
        // The generalized force per unit input at time `t` with the frequency set to `w`. The
        // linearity test is against the larger of `max |F|` there and `floor` (the load's
        // size at t = 0): a quarter period on, a load `A cos(w t)` is rounding beside an
        // equilibrium where `F ≈ 0`, and `max |F|` alone would make that rounding look like
        // nonlinearity.
        let mut load = |w: f64, t: f64, floor: f64| -> Result<DVector<f64>, FrfError> {
            model.set_parameter(frequency_parameter, w)?;
            let mut f = Vec::with_capacity(3);
            for p in [0.0, 1.0, 2.0] {
                model.set_parameter(input, p)?;
                f.push(model.mass_matrix_and_forcing(t, &y).1);
            }
            model.set_parameter(input, 0.0)?;
            let d1 = &f[1] - &f[0];
            let scale = f.iter().fold(floor, |a, v| a.max(v.amax()));
            let deviation = (&(&f[2] - &f[1]) - &d1).amax();
            if deviation.is_nan() || deviation > LINEARITY_TOLERANCE * scale {
                return Err(FrfError::NonlinearInput {
                    input: input.clone(),
                    deviation: if scale > 0.0 {
                        deviation / scale
                    } else {
                        f64::INFINITY
                    },
                });
            }
            Ok(d1)
        };
        let quarter = std::f64::consts::FRAC_PI_2 / w;
        let start = load(w, 0.0, 0.0)?;
        let floor = start.amax();
        let half = load(w, 2.0 * quarter, floor)?;
        let at_quarter = load(w, quarter, floor)?;
        let scale = start.amax().max(half.amax()).max(at_quarter.amax());
        // Only a load that reverses over half a period (`cos(w t)` and its rate) has a rate
        // column; a constant load, or one that `w` does not time, keeps `B₁ = 0`.
        let reverses = (&start + &half).amax() <= RATE_CONSTANCY_TOLERANCE * scale;
        if !reverses || at_quarter.amax() <= RATE_TOLERANCE * scale {
            continue;
        }
        let b1 = -at_quarter / w;
        let other = 1.5 * w;
        let b1_other = -load(other, std::f64::consts::FRAC_PI_2 / other, floor)? / other;
        let deviation = (&b1_other - &b1).amax() / b1.amax();
        if deviation.is_nan() || deviation > RATE_CONSTANCY_TOLERANCE {
            return Err(FrfError::InputRateNotConstant {
                input: input.clone(),
                frequency_parameter: frequency_parameter.to_string(),
                deviation,
            });
        }
        let column =
            super::speeds::coordinate_force(&*model, q, 0.0, b1).map_err(ModalError::from)?;
        rates.set_column(j, &column);
    }
    Ok(rates)
}

/// The index of the coordinate `output` of `model`.
///
/// # Errors
/// [`FrfError::UnknownOutput`].
pub fn output_index(model: &dyn ModelInfo, output: &str) -> Result<usize, FrfError> {
    let names = model.description().coordinate_names();
    names
        .iter()
        .position(|c| *c == output)
        .ok_or_else(|| FrfError::UnknownOutput {
            output: output.to_string(),
            model: model.description().name.to_string(),
            coordinates: names.join(", "),
        })
}

/// The dynamic stiffness `Z(ω) = K − ω²M + iωC` (`n × n`, complex). Beyond `ω ≈ 1.3e154`
/// rad/s `ω²` overflows; [`frequency_response`] solves with `Z(ω)/ω²` instead.
pub fn dynamic_stiffness(lin: &Linearization, frequency: f64) -> DMatrix<Complex<f64>> {
    scaled_dynamic_stiffness(lin, frequency, 1.0)
}

/// `Z(ω)/s² = K/s² − (ω/s)²M + i(ω/s)C/s`, each term formed without overflow for `s ≥ 1`.
fn scaled_dynamic_stiffness(lin: &Linearization, frequency: f64, s: f64) -> DMatrix<Complex<f64>> {
    let w = frequency / s;
    DMatrix::from_fn(lin.mass_matrix.nrows(), lin.mass_matrix.ncols(), |i, j| {
        Complex::new(
            lin.stiffness_matrix[(i, j)] / s / s - w * w * lin.mass_matrix[(i, j)],
            w * lin.damping_matrix[(i, j)] / s,
        )
    })
}

/// The factor `s` by which [`frequency_response`] and [`modal_frequency_response`] scale
/// `ω`: `max(ω, 1)`, so that `ω/s ≤ 1` and `ω²` is never formed above 1 rad/s.
fn frequency_scale(frequency: f64) -> f64 {
    frequency.max(1.0)
}

/// `x/s²` (the response from the solution `x` of the scaled system). A result below the
/// smallest normal `f64` (`2.2e-308`) is flushed to 0 — physically no response, such as the far
/// end of a long chain forced above its pass band — unless the entry was requested: then its
/// size and phase would be lost, and [`FrfError::ResponseOutOfRange`] says so. A result that
/// is not finite is always refused (it cannot happen for `s ≥ 1` and a finite `x`, but a
/// silent infinity is never returned).
fn descale(
    x: Complex<f64>,
    s: f64,
    frequency: f64,
    (row, column): (usize, usize),
    requested: bool,
) -> Result<Complex<f64>, FrfError> {
    let h = x / s / s;
    let size = h.norm();
    if x.norm() == 0.0 || (size.is_finite() && size >= f64::MIN_POSITIVE) {
        return Ok(h);
    }
    if size.is_finite() && !requested {
        return Ok(Complex::new(0.0, 0.0));
    }
    Err(FrfError::ResponseOutOfRange {
        frequency,
        row,
        column,
        log10_magnitude: x.norm().log10() - 2.0 * s.log10(),
    })
}

/// A pivot of the LU factors of `K − ω²M + iωC` below this fraction of its largest entry
/// makes it singular to rounding: the response would be `≳ 10¹³` times the static one, an
/// undamped resonance hit to within rounding (`ω = √2` evaluated in floating point is
/// `√2 (1 + 1.6e-16)`, and would otherwise give `|H| ≈ 10¹⁵`).
const SINGULAR_PIVOT: f64 = 1e-13;

/// The frequency response `H(ω) = (K − ω²M + iωC)⁻¹ B` at one frequency, by complex LU with
/// partial pivoting.
///
/// Above 1 rad/s the system is solved as `(Z(ω)/ω²) X = B`, `H = X/ω²`: `ω²` overflows beyond
/// `ω ≈ 1.3e154` (an infinite `ω²M` made every damped model look undamped there), and the
/// scaled matrix keeps the dominant `M` at its own size. An entry whose size falls below the
/// smallest normal `f64` (`2.2e-308`) is returned as 0: a coordinate the forcing does not
/// reach to within the range of floating point (the far masses of a long chain above its
/// pass band). To refuse such an entry instead, where it is the one asked for, use
/// [`frequency_response_of`].
///
/// # Shapes
/// `input_matrix` is `n × r`; the result is `n × r` (complex): entry `(i, j)` is the complex
/// amplitude of coordinate `i` per unit amplitude of input `j` (m or rad per unit input).
///
/// # Units
/// `frequency` in rad/s.
///
/// # Errors
/// [`FrfError::InvalidFrequency`]; [`FrfError::DimensionMismatch`];
/// [`FrfError::Singular`] at an undamped resonance (or `ω = 0` with a rigid-body mode): when
/// a pivot of the LU factors is below `1e-13` of the largest entry of `K − ω²M + iωC`.
///
/// # References
/// Lecture 21 (one degree of freedom), HW37 (three masses).
pub fn frequency_response(
    lin: &Linearization,
    input_matrix: &DMatrix<f64>,
    frequency: f64,
) -> Result<DMatrix<Complex<f64>>, FrfError> {
    frequency_response_of(lin, input_matrix, frequency, &[])
}

/// [`frequency_response`], refusing the frequency when an entry in one of the `outputs` rows
/// (the coordinates asked for) leaves the normal `f64` range; entries of the other rows that
/// underflow are returned as 0.
///
/// # Shapes
/// As [`frequency_response`]; `outputs` are row indices `< n` (others are ignored).
///
/// # Errors
/// As [`frequency_response`], and [`FrfError::ResponseOutOfRange`] when a non-zero entry
/// `(i, j)` with `i` in `outputs` is not a finite normal `f64` (`|H| ≈ 1/(mω²) < 2.2e-308`):
/// its size and phase cannot be given.
pub fn frequency_response_of(
    lin: &Linearization,
    input_matrix: &DMatrix<f64>,
    frequency: f64,
    outputs: &[usize],
) -> Result<DMatrix<Complex<f64>>, FrfError> {
    let b = input_matrix.map(|v| Complex::new(v, 0.0));
    frequency_response_to(lin, &b, frequency, outputs)
}

/// [`frequency_response_of`] for a complex input matrix: `H(ω) = (K − ω²M + iωC)⁻¹ B(ω)`,
/// such as `B₀ + iω B₁` of an input that enters through its rate
/// ([`ForcedLinearization::input_at`]).
///
/// # Shapes
/// `input_matrix` is `n × r` (complex); the result is `n × r`.
///
/// # Errors
/// As [`frequency_response_of`].
pub fn frequency_response_to(
    lin: &Linearization,
    input_matrix: &DMatrix<Complex<f64>>,
    frequency: f64,
    outputs: &[usize],
) -> Result<DMatrix<Complex<f64>>, FrfError> {
    check_forcing(lin, input_matrix.nrows(), frequency)?;
    let b = input_matrix;
    let s = frequency_scale(frequency);
    let z = scaled_dynamic_stiffness(lin, frequency, s);
    let scale = z.iter().map(|v| v.norm()).fold(0.0f64, f64::max);
    let lu = z.lu();
    let smallest_pivot = lu
        .u()
        .diagonal()
        .iter()
        .map(|v| v.norm())
        .fold(f64::INFINITY, f64::min);
    if smallest_pivot.is_nan() || smallest_pivot <= SINGULAR_PIVOT * scale {
        return Err(FrfError::Singular { frequency });
    }
    let x = lu.solve(b).ok_or(FrfError::Singular { frequency })?;
    if !x.iter().all(|v| v.re.is_finite() && v.im.is_finite()) {
        return Err(FrfError::Singular { frequency });
    }
    let mut h = DMatrix::zeros(x.nrows(), x.ncols());
    for i in 0..x.nrows() {
        let requested = outputs.contains(&i);
        for j in 0..x.ncols() {
            h[(i, j)] = descale(x[(i, j)], s, frequency, (i, j), requested)?;
        }
    }
    Ok(h)
}

/// The height of a resonance peak.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PeakAmplitude {
    /// A damped peak: the largest `|H|` nearby (output units per unit input).
    Finite(f64),
    /// An undamped resonance that the input excites and the output sees: `|H| → ∞`.
    Unbounded,
}

/// A resonance peak of one entry of `H(ω)`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ResonancePeak {
    /// Where `|H|` is largest (rad/s); for an unbounded peak, the undamped natural frequency.
    pub frequency: f64,
    /// `|H|` there.
    pub amplitude: PeakAmplitude,
    /// `arg H` there (degrees, in `[−180, 180)`); `None` for an unbounded peak.
    pub phase_deg: Option<f64>,
}

/// One entry `H_ij(ω)` of the frequency response over a list of frequencies, with its peaks
/// (serialised with each `H` as `{"re", "im"}` or `null`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FrequencySweep {
    /// The frequencies (rad/s), as given.
    pub frequencies: Vec<f64>,
    /// `H(ω)` at each; `None` where `K − ω²M + iωC` is singular (an undamped resonance hit
    /// exactly).
    #[serde(serialize_with = "crate::serde_matrix::option_complex_list")]
    pub response: Vec<Option<Complex<f64>>>,
    /// `arg H` in degrees, unwrapped along the sweep so that it is continuous where the
    /// response is (starts in `[−180, 180)`; `None` where `response` is).
    pub phases_deg: Vec<Option<f64>>,
    /// The resonance peaks inside `[min ω, max ω]`, ascending.
    pub peaks: Vec<ResonancePeak>,
}

impl FrequencySweep {
    /// `|H|` at each frequency; `None` where the response is unbounded.
    pub fn amplitudes(&self) -> Vec<Option<f64>> {
        self.response.iter().map(|h| h.map(|h| h.norm())).collect()
    }
}

/// `n` frequencies spaced evenly in `ln ω` from `lo` to `hi` inclusive (rad/s).
///
/// # Errors
/// [`FrfError::InvalidFrequencyRange`] unless `0 < lo < hi < ∞`.
pub fn log_frequencies(lo: f64, hi: f64, n: usize) -> Result<Vec<f64>, FrfError> {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return Err(FrfError::InvalidFrequencyRange { lo, hi });
    }
    Ok(match n {
        0 => Vec::new(),
        1 => vec![(lo * hi).sqrt()],
        _ => (0..n)
            .map(|i| {
                if i + 1 == n {
                    hi
                } else {
                    lo * (hi / lo).powf(i as f64 / (n - 1) as f64)
                }
            })
            .collect(),
    })
}

/// `arg z` in degrees in `[−180, 180)`: a negative real number (an undamped response in
/// antiphase) is at `−180`, a lag, as the damped response approaches it; `−0` is `0`.
pub fn phase_degrees(z: Complex<f64>) -> f64 {
    if z.im == 0.0 && z.re < 0.0 {
        return -180.0;
    }
    let p = z.im.atan2(z.re).to_degrees() + 0.0;
    if p == 180.0 { -180.0 } else { p }
}

/// The frequency response from input column `input` of `input_matrix` to coordinate
/// `output` at `frequencies`, and its resonance peaks inside their range.
///
/// Peaks: a damped peak is an interior local maximum of `|H|` on the frequencies merged with
/// the natural and damped frequencies (so that a sharp peak between two grid points is not
/// missed), refined by golden-section search on `ln ω` over the bracket of its two
/// neighbours to a bracket of `1e-13` (the maximum is flat, so its location is good to about
/// `√ε ≈ 1e-8` relative and its height to rounding). An undamped mode (a pair of eigenvalues
/// of the state matrix on the imaginary axis, `ζ ≤ 1e-9`, or any mode when `C = 0`) at `ω_k`
/// is an [`PeakAmplitude::Unbounded`] peak when the output sees it: `|H|` grows like
/// `1/|ω − ω_k|`, tested as `|H(ω_k(1 + 10⁻⁹))| > 100 |H(ω_k(1 + 10⁻⁴))|` (a simple pole gives
/// a ratio near `10⁵`, a mode the input does not excite or the output does not see gives
/// about 1).
///
/// # Shapes
/// `input_matrix` is `n × r`, `input < r`, `output < n`; the sweep has one entry per
/// frequency.
///
/// # Errors
/// [`FrfError::InvalidFrequency`], [`FrfError::DimensionMismatch`] (also for `input ≥ r` or
/// `output ≥ n`), and [`FrfError::Modal`] from the modal analysis behind the peak search.
pub fn frequency_sweep(
    lin: &Linearization,
    input_matrix: &DMatrix<f64>,
    input: usize,
    output: usize,
    frequencies: &[f64],
) -> Result<FrequencySweep, FrfError> {
    let rates = DMatrix::zeros(input_matrix.nrows(), input_matrix.ncols());
    frequency_sweep_with_rates(lin, input_matrix, &rates, input, output, frequencies)
}

/// [`frequency_sweep`] for an input that also enters through its rate: the input column at
/// `ω` is `B₀ + iω B₁` (column `input` of `input_matrix` and of `input_rate_matrix`), as
/// [`linearize_with_input_rates`] finds for a base motion.
///
/// # Shapes
/// `input_matrix` and `input_rate_matrix` are `n × r`; otherwise as [`frequency_sweep`].
///
/// # Errors
/// As [`frequency_sweep`]; [`FrfError::DimensionMismatch`] also when the two matrices differ
/// in shape.
///
/// # References
/// Lecture 38 (transmissibility), HW21 (a).
pub fn frequency_sweep_with_rates(
    lin: &Linearization,
    input_matrix: &DMatrix<f64>,
    input_rate_matrix: &DMatrix<f64>,
    input: usize,
    output: usize,
    frequencies: &[f64],
) -> Result<FrequencySweep, FrfError> {
    let n = lin.mass_matrix.nrows();
    if input_rate_matrix.shape() != input_matrix.shape() {
        return Err(FrfError::DimensionMismatch {
            expected: input_matrix.nrows(),
            found: input_rate_matrix.nrows(),
        });
    }
    if input_matrix.nrows() != n {
        return Err(FrfError::DimensionMismatch {
            expected: n,
            found: input_matrix.nrows(),
        });
    }
    if input >= input_matrix.ncols() || output >= n {
        return Err(FrfError::DimensionMismatch {
            expected: n,
            found: output.max(input),
        });
    }
    let b = DMatrix::from_column_slice(n, 1, input_matrix.column(input).as_slice());
    let b1 = DMatrix::from_column_slice(n, 1, input_rate_matrix.column(input).as_slice());
    let column = Column { b0: &b, b1: &b1 };
    let entry = |w: f64| -> Result<Option<Complex<f64>>, FrfError> {
        match column.response(lin, w, &[output]) {
            Ok(h) => Ok(Some(h[(output, 0)])),
            Err(FrfError::Singular { .. }) => Ok(None),
            Err(e) => Err(e),
        }
    };
    let mut response = Vec::with_capacity(frequencies.len());
    for &w in frequencies {
        response.push(entry(w)?);
    }
    let mut phases_deg = Vec::with_capacity(frequencies.len());
    let mut previous: Option<f64> = None;
    for h in &response {
        let phase = h.map(|h| {
            let mut p = phase_degrees(h);
            if let Some(prev) = previous {
                while p - prev > 180.0 {
                    p -= 360.0;
                }
                while p - prev < -180.0 {
                    p += 360.0;
                }
            }
            p
        });
        if phase.is_some() {
            previous = phase;
        }
        phases_deg.push(phase);
    }
    let (lo, hi) = frequencies
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &w| {
            (a.min(w), b.max(w))
        });
    let peaks = if lo < hi {
        find_peaks(lin, column, output, frequencies, lo, hi)?
    } else {
        Vec::new()
    };
    Ok(FrequencySweep {
        frequencies: frequencies.to_vec(),
        response,
        phases_deg,
        peaks,
    })
}

/// The frequencies (rad/s, ascending) of the undamped modes: all oscillatory natural
/// frequencies when `C = 0`, else those of eigenvalue pairs of `A` with `ζ ≤ 1e-9`; and the
/// damped frequencies of the others (where their peaks lie).
fn mode_frequencies(lin: &Linearization) -> Result<(Vec<f64>, Vec<f64>), FrfError> {
    let mut undamped = Vec::new();
    let mut damped = Vec::new();
    if lin.damping_matrix.amax() == 0.0 {
        let modes = crate::linear::modal::normal_modes(lin)?;
        for (w, kind) in modes.natural_frequencies.iter().zip(&modes.kinds) {
            if *kind == ModeKind::Oscillatory {
                undamped.push(*w);
            }
        }
    } else {
        for (s, zeta, wd) in damped_modes(lin)? {
            if wd <= 0.0 {
                continue;
            }
            if zeta.abs() <= 1e-9 {
                undamped.push(wd);
            } else {
                damped.push(wd);
                damped.push(s.norm());
            }
        }
    }
    undamped.sort_by(f64::total_cmp);
    damped.sort_by(f64::total_cmp);
    Ok((undamped, damped))
}

/// One input column `B₀ + iω B₁` (`n × 1` each).
#[derive(Clone, Copy)]
struct Column<'a> {
    b0: &'a DMatrix<f64>,
    b1: &'a DMatrix<f64>,
}

impl Column<'_> {
    fn response(
        &self,
        lin: &Linearization,
        frequency: f64,
        outputs: &[usize],
    ) -> Result<DMatrix<Complex<f64>>, FrfError> {
        let b = harmonic_input(self.b0, self.b1, frequency);
        frequency_response_to(lin, &b, frequency, outputs)
    }
}

fn find_peaks(
    lin: &Linearization,
    column: Column<'_>,
    output: usize,
    frequencies: &[f64],
    lo: f64,
    hi: f64,
) -> Result<Vec<ResonancePeak>, FrfError> {
    let magnitude = |w: f64| -> Option<f64> {
        column
            .response(lin, w, &[])
            .ok()
            .map(|h| h[(output, 0)].norm())
    };
    let (undamped, damped) = mode_frequencies(lin)?;
    let mut peaks = Vec::new();
    // Undamped resonances the output sees.
    let mut poles = Vec::new();
    for &wk in &undamped {
        if !(lo..=hi).contains(&wk) {
            continue;
        }
        let near = magnitude(wk * (1.0 + 1e-9));
        let far = magnitude(wk * (1.0 + 1e-4));
        let seen = match (near, far) {
            (None, _) => true,
            (Some(a), Some(b)) => a > 100.0 * b && a > 0.0,
            (Some(_), None) => false,
        };
        if seen {
            poles.push(wk);
            peaks.push(ResonancePeak {
                frequency: wk,
                amplitude: PeakAmplitude::Unbounded,
                phase_deg: None,
            });
        }
    }
    // Damped peaks: interior local maxima on the merged grid.
    let mut grid: Vec<f64> = frequencies
        .iter()
        .copied()
        .chain(damped.iter().copied().filter(|w| (lo..=hi).contains(w)))
        .collect();
    grid.sort_by(f64::total_cmp);
    grid.dedup();
    let values: Vec<f64> = grid
        .iter()
        .map(|&w| magnitude(w).unwrap_or(f64::INFINITY))
        .collect();
    for i in 1..grid.len().saturating_sub(1) {
        let (a, m, c) = (values[i - 1], values[i], values[i + 1]);
        if !(m.is_finite() && m > a && m >= c) {
            continue;
        }
        let (w_lo, w_hi) = (grid[i - 1], grid[i + 1]);
        if poles.iter().any(|&p| p >= w_lo && p <= w_hi) {
            continue; // the side of an unbounded peak
        }
        let w = golden_section_max(|x| magnitude(x.exp()).unwrap_or(0.0), w_lo.ln(), w_hi.ln());
        let w = w.exp();
        if let Ok(h) = column.response(lin, w, &[]) {
            let h = h[(output, 0)];
            // Two grid maxima can refine to the same peak.
            if peaks
                .iter()
                .any(|p: &ResonancePeak| (p.frequency - w).abs() <= 1e-7 * w)
            {
                continue;
            }
            peaks.push(ResonancePeak {
                frequency: w,
                amplitude: PeakAmplitude::Finite(h.norm()),
                phase_deg: Some(phase_degrees(h)),
            });
        }
    }
    peaks.sort_by(|a, b| a.frequency.total_cmp(&b.frequency));
    Ok(peaks)
}

/// The maximiser of `f` on `[a, b]` by golden-section search, to a bracket of `1e-13 (1 + |x|)`
/// (at most 200 iterations).
fn golden_section_max(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let mut x1 = b - r * (b - a);
    let mut x2 = a + r * (b - a);
    let mut f1 = f(x1);
    let mut f2 = f(x2);
    for _ in 0..200 {
        if (b - a).abs() <= 1e-13 * (1.0 + a.abs().max(b.abs())) {
            break;
        }
        if f1 >= f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - r * (b - a);
            f1 = f(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + r * (b - a);
            f2 = f(x2);
        }
    }
    if f1 >= f2 { x1 } else { x2 }
}

/// The steady-state response assembled mode by mode at one frequency (modal forcing;
/// serialised with complex numbers as `{"re", "im"}`, matrices as lists of rows).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ModalResponse {
    /// The frequency (rad/s).
    pub frequency: f64,
    /// The modal forces `ψ_kᵀ b` per unit input, one per mode.
    pub modal_forces: Vec<f64>,
    /// The modal coordinates `η_k = ψ_kᵀ b / (ω_k² − ω² + iω Ĉ_kk)` per unit input (complex).
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub modal_coordinates: Vec<Complex<f64>>,
    /// `n × k` (complex): column `k` is mode `k`'s contribution `ψ_k η_k` to the coordinates.
    #[serde(serialize_with = "crate::serde_matrix::complex_rows")]
    pub contributions: DMatrix<Complex<f64>>,
    /// `Σ_k ψ_k η_k` (length `n`, complex): the response per unit input.
    #[serde(serialize_with = "crate::serde_matrix::complex_vector")]
    pub response: DVector<Complex<f64>>,
}

/// The steady-state response to the input column `b` at `frequency`, assembled mode by mode:
/// `δq = Σ_k ψ_k ψ_kᵀ b / (ω_k² − ω² + iω Ĉ_kk)` with `Ĉ = ΨᵀCΨ` (`Ĉ_kk = 2ζ_k ω_k`).
///
/// Exact — equal to [`frequency_response`] to rounding — when `Ĉ` is diagonal (no damping,
/// or proportional damping `C = αM + βK`); otherwise the coupling of the modes through the
/// off-diagonal `Ĉ` is dropped (see [`ModalDamping::coupling`](crate::ModalDamping::coupling)). Zero-frequency modes enter
/// with `ω_k = 0`, unstable ones with their negative `ω_k²`.
///
/// # Shapes
/// `b` has `n` entries; `contributions` is `n × k`, `response` `n`.
///
/// # Errors
/// [`FrfError::InvalidFrequency`]; [`FrfError::DimensionMismatch`];
/// [`FrfError::Singular`] when a mode's denominator is below `1e-13 max(|ω_k²|, ω²)` (an
/// undamped resonance to rounding); [`FrfError::ResponseOutOfRange`] (entry `(coordinate,
/// mode)`) when a contribution is not finite. The denominators are scaled by `ω²` above
/// 1 rad/s, as in [`frequency_response`], and a contribution below the smallest normal `f64`
/// is 0, as there.
///
/// # References
/// HW37 (c): modal forcing of the three-mass system; HW34 (modal damping).
pub fn modal_frequency_response(
    lin: &Linearization,
    modes: &NormalModes,
    b: &DVector<f64>,
    frequency: f64,
) -> Result<ModalResponse, FrfError> {
    check_forcing(lin, b.len(), frequency)?;
    modes.require_real()?;
    let n = b.len();
    let damping = modal_damping(lin, modes);
    let psi = &modes.mode_shapes;
    let k = psi.ncols();
    // `ψ_kᵀ b`, or the left eigenvectors' for the modes of a non-symmetric K.
    let forces = crate::linear::response::modal_projector(lin, modes) * b;
    // Scaled by s² as in `frequency_response`: the denominator divided by s².
    let s = frequency_scale(frequency);
    let w = frequency / s;
    let mut modal_forces = Vec::with_capacity(k);
    let mut modal_coordinates = Vec::with_capacity(k);
    let mut contributions = DMatrix::zeros(n, k);
    for mode in 0..k {
        let shape = psi.column(mode);
        let force = forces[mode];
        let stiffness = modes.eigenvalues[mode] / s / s;
        let denominator = Complex::new(
            stiffness - w * w,
            w * damping.modal_damping_matrix[(mode, mode)] / s,
        );
        let floor = SINGULAR_PIVOT * stiffness.abs().max(w * w);
        if denominator.norm().is_nan() || denominator.norm() <= floor {
            return Err(FrfError::Singular { frequency });
        }
        let eta_scaled = Complex::new(force, 0.0) / denominator;
        let eta = eta_scaled / s / s;
        for i in 0..n {
            // Only a non-finite contribution is refused, reported as entry (coordinate, mode).
            contributions[(i, mode)] =
                descale(eta_scaled * shape[i], s, frequency, (i, mode), false)?;
        }
        modal_forces.push(force);
        modal_coordinates.push(eta);
    }
    let response = contributions.column_sum();
    Ok(ModalResponse {
        frequency,
        modal_forces,
        modal_coordinates,
        contributions,
        response,
    })
}

/// The checks shared by [`frequency_response`] and [`modal_frequency_response`]: a finite
/// `frequency ≥ 0` and a forcing with `rows` entries per input for the `n` coordinates of
/// `lin`.
fn check_forcing(lin: &Linearization, rows: usize, frequency: f64) -> Result<(), FrfError> {
    let n = lin.mass_matrix.nrows();
    if !(frequency.is_finite() && frequency >= 0.0) {
        return Err(FrfError::InvalidFrequency { frequency });
    }
    if rows != n {
        return Err(FrfError::DimensionMismatch {
            expected: n,
            found: rows,
        });
    }
    Ok(())
}

/// The time for the slowest free decay to shrink by `reduction`: `ln(1/reduction) / σ_min`
/// with `σ_min = min −Re s` over the eigenvalues `s` of the state matrix (s), as
/// [`crate::linear::eigenvalues::linear_stability`] computes them.
///
/// # Errors
/// [`FrfError::NoSteadyState`] if some eigenvalue has `Re s ≥ 0` (an undamped or unstable
/// mode, or a rigid-body mode); [`FrfError::InvalidOption`] unless `0 < reduction < 1`;
/// [`FrfError::Modal`].
pub fn settling_time(lin: &Linearization, reduction: f64) -> Result<f64, FrfError> {
    if !(reduction > 0.0 && reduction < 1.0) {
        return Err(FrfError::InvalidOption {
            option: "reduction",
            value: reduction,
            expected: "0 < reduction < 1",
        });
    }
    // The verdict of `modes`: a steady state exists exactly when the equilibrium is stable.
    let stability = crate::linear::eigenvalues::linear_stability(lin)?;
    match stability.stability {
        crate::linear::eigenvalues::Stability::Stable { decay_rate } => {
            Ok((1.0 / reduction).ln() / decay_rate)
        }
        _ => Err(FrfError::NoSteadyState {
            slowest_decay_rate: stability
                .eigenvalues
                .iter()
                .map(|s| -s.re)
                .fold(f64::INFINITY, f64::min),
        }),
    }
}

/// A harmonic load for [`simulate_steady_state`]: the input parameter's value and the forcing
/// frequency.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicForcing<'a> {
    /// The input parameter (a load amplitude, like `A` in `A*cos(w*t)`).
    pub input: &'a str,
    /// Its value during the simulation (units of the parameter); small for a nonlinear model.
    pub amplitude: f64,
    /// The parameter that sets the forcing frequency (`w`).
    pub frequency_parameter: &'a str,
    /// The forcing frequency `ω` (rad/s), `> 0`.
    pub frequency: f64,
}

/// Options of [`simulate_steady_state`].
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyStateOptions {
    /// Relative tolerance of DOP853, `> 0` (default: 1e-11).
    pub rtol: f64,
    /// Absolute tolerance of DOP853 on `q` and `q̇`, `> 0`: set it well below the response
    /// amplitude (default: 1e-13).
    pub atol: f64,
    /// Whole forcing periods over which the response is projected, `≥ 1` (default: 4).
    pub periods: usize,
    /// Samples per period, `≥ 8` (default: 64; harmonics below half of it are resolved
    /// exactly by the discrete projection).
    pub samples_per_period: usize,
}

impl Default for SteadyStateOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-11,
            atol: 1e-13,
            periods: 4,
            samples_per_period: 64,
        }
    }
}

/// The steady-state response measured by simulation (complex amplitudes serialised as
/// `{"re", "im"}`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SteadyState {
    /// The forcing frequency (rad/s).
    pub frequency: f64,
    /// The input's value during the simulation (units of the parameter).
    pub amplitude: f64,
    /// Where the projection window starts (s).
    pub settling_time: f64,
    /// The complex amplitudes `Xᵢ` of the coordinates at the forcing frequency, one per
    /// coordinate: `qᵢ(t) ≈ q̄ᵢ + Re(Xᵢ e^{iωt})` (m or rad). `Xᵢ / amplitude` estimates
    /// `Hᵢ(ω)`.
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub complex_amplitudes: Vec<Complex<f64>>,
    /// The means `q̄ᵢ` over the window (m or rad).
    pub means: Vec<f64>,
    /// Steps taken by DOP853.
    pub steps: usize,
    /// Right-hand-side evaluations.
    pub rhs_evals: usize,
}

/// Simulates the full (nonlinear) model forced at one frequency and measures the steady
/// response at that frequency: the input set to its amplitude, the frequency parameter to
/// the frequency, start at rest at `equilibrium`, DOP853 to `settling_time`, then the
/// coordinates are sampled `samples_per_period` times per period over `periods` whole
/// periods and projected on `e^{−iωt}`:
///
/// ```text
/// Xᵢ = (2/N) Σⱼ qᵢ(tⱼ) e^{−iω tⱼ},   q̄ᵢ = (1/N) Σⱼ qᵢ(tⱼ)
/// ```
///
/// (the discrete projection over whole periods is exact for the harmonics below
/// `samples_per_period / 2`). When the model attaches `cos(w t)` to the input, `Xᵢ ≈ Hᵢ(ω)
/// amplitude` up to the transient left (`e^{−σ_min settling_time}`, see [`settling_time`]),
/// the integration error and terms of order `amplitude²` from the nonlinearity.
///
/// The model's parameter values are restored before returning.
///
/// # Shapes
/// `equilibrium` has `n` entries; `complex_amplitudes` and `means` have `n`.
///
/// # Errors
/// [`FrfError::UnknownParameter`]; [`FrfError::InvalidFrequency`] (`ω ≤ 0` too);
/// [`FrfError::InvalidOption`]; [`FrfError::DimensionMismatch`];
/// [`FrfError::Integration`]; [`FrfError::StoppedByEvent`].
///
/// # References
/// Lecture 21 (steady state of the forced oscillator), HW37 (a)–(b).
pub fn simulate_steady_state(
    model: &mut dyn ModelInfo,
    equilibrium: &[f64],
    forcing: &HarmonicForcing<'_>,
    settling_time: f64,
    options: &SteadyStateOptions,
) -> Result<SteadyState, FrfError> {
    let saved = model.parameter_values();
    let result = simulate_inner(model, equilibrium, forcing, settling_time, options);
    restore(model, &saved);
    result
}

fn simulate_inner(
    model: &mut dyn ModelInfo,
    equilibrium: &[f64],
    forcing: &HarmonicForcing<'_>,
    settling_time: f64,
    options: &SteadyStateOptions,
) -> Result<SteadyState, FrfError> {
    let HarmonicForcing {
        input,
        amplitude,
        frequency_parameter,
        frequency,
    } = *forcing;
    let n = model.num_dofs();
    check_steady_state(frequency, amplitude, settling_time, options)?;
    if equilibrium.len() != n {
        return Err(FrfError::DimensionMismatch {
            expected: n,
            found: equilibrium.len(),
        });
    }
    model.set_parameter(input, amplitude)?;
    model.set_parameter(frequency_parameter, frequency)?;
    let period = std::f64::consts::TAU / frequency;
    let samples = options.periods * options.samples_per_period;
    let times: Vec<f64> = (0..samples)
        .map(|j| settling_time + period * j as f64 / options.samples_per_period as f64)
        .collect();
    let t_end = settling_time + period * options.periods as f64;
    // At rest at the equilibrium (in generalized speeds `u = Z(q)`).
    let y0 = super::speeds::rest_state(&*model, equilibrium, 0.0).map_err(ModalError::from)?;
    let integrator_options = IntegratorOptions::default()
        .with_rtol(options.rtol)
        .with_atol(options.atol)
        .with_max_steps(10_000_000);
    let solution = DormandPrince853::new()
        .integrate(
            model.as_ode_mut(),
            0.0,
            &y0,
            t_end,
            &OutputTimes::At(times),
            &integrator_options,
        )
        .map_err(|failure| FrfError::Integration {
            frequency,
            error: failure.error,
        })?;
    if solution.terminated_by_event.is_some() || solution.len() != samples {
        return Err(FrfError::StoppedByEvent {
            frequency,
            t: solution.last().map_or(0.0, |(t, _)| t),
        });
    }
    let (complex_amplitudes, means) = harmonic_content(&solution, frequency, n, samples);
    Ok(SteadyState {
        frequency,
        amplitude,
        settling_time,
        complex_amplitudes,
        means,
        steps: solution.stats.steps,
        rhs_evals: solution.stats.rhs_evals,
    })
}

/// The checks of [`simulate_steady_state`]'s numbers, in its order: a positive finite
/// `frequency`, a finite `amplitude`, a finite non-negative `settling_time`, positive finite
/// tolerances and at least 8 samples per period over at least one period.
///
/// # Errors
/// [`FrfError::InvalidFrequency`], [`FrfError::InvalidOption`].
fn check_steady_state(
    frequency: f64,
    amplitude: f64,
    settling_time: f64,
    options: &SteadyStateOptions,
) -> Result<(), FrfError> {
    if !(frequency.is_finite() && frequency > 0.0) {
        return Err(FrfError::InvalidFrequency { frequency });
    }
    let checks: [(&'static str, f64, bool, &'static str); 5] = [
        ("amplitude", amplitude, amplitude.is_finite(), "finite"),
        (
            "settling_time",
            settling_time,
            settling_time.is_finite() && settling_time >= 0.0,
            "finite and ≥ 0",
        ),
        (
            "rtol",
            options.rtol,
            options.rtol > 0.0 && options.rtol.is_finite(),
            "finite and > 0",
        ),
        (
            "atol",
            options.atol,
            options.atol > 0.0 && options.atol.is_finite(),
            "finite and > 0",
        ),
        (
            "samples_per_period",
            options.samples_per_period as f64,
            options.samples_per_period >= 8 && options.periods >= 1,
            "≥ 8, with periods ≥ 1",
        ),
    ];
    for (option, value, ok, expected) in checks {
        if !ok {
            return Err(FrfError::InvalidOption {
                option,
                value,
                expected,
            });
        }
    }
    Ok(())
}

/// The complex amplitudes (the first harmonic at `frequency`, `2/samples Σ y e^{−iωt}`) and
/// the means of the `n` coordinates over the `samples` steady-state samples of `solution`.
fn harmonic_content(
    solution: &Solution,
    frequency: f64,
    n: usize,
    samples: usize,
) -> (Vec<Complex<f64>>, Vec<f64>) {
    let mut complex_amplitudes = vec![Complex::new(0.0, 0.0); n];
    let mut means = vec![0.0; n];
    for (t, y) in solution.iter() {
        let e = Complex::from_polar(1.0, -frequency * t);
        for i in 0..n {
            complex_amplitudes[i] += e * y[i];
            means[i] += y[i];
        }
    }
    let scale = 2.0 / samples as f64;
    for i in 0..n {
        complex_amplitudes[i] *= scale;
        means[i] /= samples as f64;
    }
    (complex_amplitudes, means)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lin_1dof(m: f64, c: f64, k: f64) -> Linearization {
        Linearization::from_matrices(
            DMatrix::from_element(1, 1, m),
            DMatrix::from_element(1, 1, k),
            DMatrix::from_element(1, 1, c),
        )
    }

    /// Lecture 21: `|H|` peaks at `ω_n √(1 − 2ζ²)` with height `1/(2ζ k √(1 − ζ²))`. The
    /// height is exact to rounding (the maximum of a smooth function is found to `ε`); the
    /// location only to about `√ε` since `|H|` is flat there.
    #[test]
    fn damped_peak_of_one_degree_of_freedom() {
        let (m, c, k) = (2.0, 0.3, 5.0);
        let lin = lin_1dof(m, c, k);
        let b = DMatrix::from_element(1, 1, 1.0);
        let freqs = log_frequencies(0.1, 10.0, 50).unwrap();
        let sweep = frequency_sweep(&lin, &b, 0, 0, &freqs).unwrap();
        let wn = (k / m).sqrt();
        let zeta = c / (2.0 * (k * m).sqrt());
        assert_eq!(sweep.peaks.len(), 1, "{:?}", sweep.peaks);
        let peak = sweep.peaks[0];
        let w_peak = wn * (1.0 - 2.0 * zeta * zeta).sqrt();
        let h_peak = 1.0 / (2.0 * zeta * k * (1.0 - zeta * zeta).sqrt());
        assert!((peak.frequency - w_peak).abs() < 1e-7 * w_peak, "{peak:?}");
        let PeakAmplitude::Finite(h) = peak.amplitude else {
            panic!("finite peak expected: {peak:?}")
        };
        assert!((h - h_peak).abs() < 1e-13 * h_peak, "{h} vs {h_peak}");
    }

    /// Without damping the response is singular at `ω_n`: an unbounded peak, and `None` where
    /// the grid hits `ω_n = 1` exactly.
    #[test]
    fn undamped_peak_is_unbounded() {
        let lin = lin_1dof(1.0, 0.0, 1.0);
        let b = DMatrix::from_element(1, 1, 1.0);
        let freqs = log_frequencies(0.1, 10.0, 3).unwrap();
        assert_eq!(freqs[1], 1.0);
        let sweep = frequency_sweep(&lin, &b, 0, 0, &freqs).unwrap();
        assert_eq!(sweep.response[1], None);
        assert_eq!(sweep.peaks.len(), 1);
        assert_eq!(sweep.peaks[0].amplitude, PeakAmplitude::Unbounded);
        assert_eq!(sweep.peaks[0].frequency, 1.0);
        assert!(matches!(
            frequency_response(&lin, &b, 1.0),
            Err(FrfError::Singular { .. })
        ));
        // Below resonance in phase, above in antiphase (a lag of 180°).
        assert_eq!(sweep.phases_deg[0], Some(0.0));
        assert_eq!(sweep.phases_deg[2], Some(-180.0));
    }

    #[test]
    fn golden_section_finds_a_parabola_maximum() {
        let x = golden_section_max(|x| -(x - 0.3) * (x - 0.3), -1.0, 2.0);
        assert!((x - 0.3).abs() < 1e-7);
    }

    #[test]
    fn bad_ranges_are_errors() {
        assert!(matches!(
            log_frequencies(0.0, 1.0, 10),
            Err(FrfError::InvalidFrequencyRange { .. })
        ));
        assert!(matches!(
            log_frequencies(2.0, 1.0, 10),
            Err(FrfError::InvalidFrequencyRange { .. })
        ));
        let lin = lin_1dof(1.0, 0.1, 1.0);
        assert!(matches!(
            frequency_response(&lin, &DMatrix::from_element(1, 1, 1.0), f64::NAN),
            Err(FrfError::InvalidFrequency { .. })
        ));
        assert!(matches!(
            settling_time(&lin_1dof(1.0, 0.0, 1.0), 1e-8),
            Err(FrfError::NoSteadyState { .. })
        ));
    }
}
