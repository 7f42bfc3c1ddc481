//! A model file as straight-line programs, one per generated function, with the data the
//! generated struct returns as constants: what a model compiled at run time is built from.
//!
//! [`ModelProgram::from_file`] runs the first steps of [`super::generate`] (lowering, the
//! formulation of [`crate::mechanics::preferred_equations`], the mass-matrix diagnostics),
//! then lowers to a [`Tape`] each plan of [`super::plan`] — the plans [`super::emit`] prints
//! as Rust. A backend that evaluates the tapes therefore computes what the `model!` macro's
//! code computes, operation for operation.

use crate::expr::SymbolId;
use crate::mechanics::{EquationsOfMotion, SymbolicModel};
use crate::model::ModelFile;
use eomgen_description::ModelDescription;

use super::GenerateError;
use super::plan::{ModelFunction, ModelPlans};
use super::tape::{Input, Instruction, Tape, Value};

/// One function of a model, as a tape and the layout of its outputs.
///
/// The tape's outputs go to the first output buffer up to `split`, the rest to the second
/// (only [`ModelProgram::mass_matrix_and_forcing`] has two: `M`, then `F`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FunctionTape {
    /// The program.
    pub tape: Tape,
    /// Outputs `..split` go to the first buffer, `split..` to the second.
    pub split: usize,
}

impl FunctionTape {
    fn single(tape: Tape) -> Self {
        let split = tape.outputs.len();
        Self { tape, split }
    }
}

/// Every function the `model!` macro generates for a model file, as tapes, and the constants
/// it returns (names, events, drawing data, the equations as text).
///
/// # Shapes
/// With `n` degrees of freedom, `m` constraints of which `m_h` holonomic, `p` points and `e`
/// events; the inputs of every tape are named by [`super::tape::Input`]. Matrices are written
/// **column-major** (entry `(i, j)` at `i + j n`) except the constraint Jacobian, row-major as
/// in `MechanicalSystem::constraint_jacobian`:
///
/// | function | outputs |
/// |---|---|
/// | `initial_state` | `q(0)` (n), then `q̇(0)` (n) |
/// | `mass_matrix_and_forcing` | `M` (n × n), then (second buffer) `F` (n) |
/// | ([`JacobianProgram`]) `forcing_jacobian_q`, `forcing_jacobian_qdot` | `∂F/∂q`, `∂F/∂q̇` (n × n) |
/// | ([`JacobianProgram`]) `mass_matrix_product_jacobian` | `∂(M a)/∂q` (n × n), `a` read as the acceleration inputs |
/// | `kinetic_energy`, `potential_energy` | `T`, `V` (1) |
/// | `point_positions` | `[x, y, z]` per point (3 p; `z = 0` in 2-D) |
/// | `constraint_residuals` | `Φ` (m_h) |
/// | `constraint_jacobian` | `J` (m × n, row-major) |
/// | `constraint_velocity_residuals`, `constraint_gamma` | (m) |
/// | `event_values` | `g` (e); `q̈` as the acceleration inputs, `λ` as the multipliers |
/// | `equilibrium_guesses` | `n` per named equilibrium |
/// | `contact_gaps` | `g`, `ġ`, `γ` of `G q̈ = γ`, `γ_T` of `T q̈ = γ_T`, then the surface's speed `v_s` (m_c each) |
/// | `contact_jacobian` | `G = ∂g/∂q` (m_c × n), then the slips' rows `T` (m_c × n), row-major |
/// | `contact_coefficients` | `e`, `μ` per contact (2 m_c) |
/// | `support_changes` | each change of support's values (`block` of [`crate::model::elements::support`]) |
/// | `coordinate_rates` | with generalized speeds, `q̇ = W (u − Z)` (n), the second inputs read as `u` |
/// | ([`JacobianProgram`]) `coordinate_rates_jacobian` | `∂q̇/∂q`, then (second buffer) `∂q̇/∂u` (n × n each) |
#[derive(Debug, Clone, PartialEq)]
pub struct ModelProgram {
    /// Everything about the model that is not a function of the state ([`super::describe`]).
    pub description: ModelDescription,
    /// `q(0)`, `q̇(0)`.
    pub initial_state: FunctionTape,
    /// `M`, `F`.
    pub mass_matrix_and_forcing: FunctionTape,
    /// `T`.
    pub kinetic_energy: FunctionTape,
    /// `V`.
    pub potential_energy: FunctionTape,
    /// Point positions.
    pub point_positions: FunctionTape,
    /// `Φ`.
    pub constraint_residuals: FunctionTape,
    /// `J`.
    pub constraint_jacobian: FunctionTape,
    /// Velocity residuals.
    pub constraint_velocity_residuals: FunctionTape,
    /// `γ`.
    pub constraint_gamma: FunctionTape,
    /// Event functions.
    pub event_values: FunctionTape,
    /// Equilibrium guesses.
    pub equilibrium_guesses: FunctionTape,
    /// The contacts' gaps and their rates.
    pub contact_gaps: FunctionTape,
    /// The contacts' Jacobian.
    pub contact_jacobian: FunctionTape,
    /// The contacts' coefficients of restitution and friction.
    pub contact_coefficients: FunctionTape,
    /// The changes of support's values.
    pub support_changes: FunctionTape,
    /// The kinematic equations of a model in generalized speeds (empty without speeds).
    pub coordinate_rates: FunctionTape,
}

impl ModelProgram {
    /// Derives and plans the model of a loaded file, as `eomgen::model!` does, all but the
    /// exact Jacobians, which only the implicit integrators and the linearisation use: the
    /// returned [`Derivation`] plans them when they are needed ([`Derivation::jacobians`]).
    ///
    /// # Errors
    /// [`GenerateError::Diagnostics`] for a model that cannot be lowered or whose mass matrix
    /// is singular, with the same located diagnostics as the macro.
    pub fn from_file(file: &ModelFile) -> Result<(ModelProgram, Derivation), GenerateError> {
        let (model, eom) = super::derive(file)?;
        let program = Self::plan(&model, &eom);
        Ok((program, Derivation { model, eom }))
    }

    /// The tapes of a derived model but its Jacobians: the plans of
    /// [`super::plan::plan_state`] (the ones [`super::emit`] prints) lowered to tapes.
    pub fn plan(model: &SymbolicModel, eom: &EquationsOfMotion) -> ModelProgram {
        use ModelFunction as F;
        let plans = super::plan::plan_state(model, eom, &[]);
        let tapes = Tapes::new(model, &plans);
        let mass_matrix_and_forcing = mass_matrix_and_forcing_tape(model, &plans);
        let mut points = tapes.get(F::PointPositions);
        // `[x, y, z]` per point, `z = 0` for 2-D points.
        let zero = points.instructions.len() as u32;
        points.instructions.push(Instruction::Const(0.0));
        let mut components = points.outputs.iter().copied();
        let mut outputs = Vec::with_capacity(3 * model.points.len());
        for (_, r) in &model.points {
            for k in 0..3 {
                let v = if k < r.len() { components.next() } else { None };
                outputs.push(v.unwrap_or(zero));
            }
        }
        points.outputs = outputs;
        let single = |function| FunctionTape::single(tapes.get(function));
        ModelProgram {
            description: super::describe(model, eom, false),
            initial_state: single(F::InitialState),
            mass_matrix_and_forcing,
            kinetic_energy: single(F::KineticEnergy),
            potential_energy: single(F::PotentialEnergy),
            point_positions: FunctionTape::single(points),
            constraint_residuals: single(F::ConstraintResiduals),
            constraint_jacobian: single(F::ConstraintJacobian),
            constraint_velocity_residuals: single(F::ConstraintVelocityResiduals),
            constraint_gamma: single(F::ConstraintGamma),
            event_values: single(F::EventValues),
            equilibrium_guesses: single(F::EquilibriumGuesses),
            contact_gaps: single(F::ContactGaps),
            contact_jacobian: single(F::ContactJacobian),
            contact_coefficients: single(F::ContactCoefficients),
            support_changes: single(F::SupportChanges),
            coordinate_rates: single(F::CoordinateRates),
        }
    }

    /// Drops the tapes, keeping the names and constants (for a backend that has taken its own
    /// copy of the functions).
    pub fn clear_tapes(&mut self) {
        for tape in [
            &mut self.initial_state,
            &mut self.mass_matrix_and_forcing,
            &mut self.kinetic_energy,
            &mut self.potential_energy,
            &mut self.point_positions,
            &mut self.constraint_residuals,
            &mut self.constraint_jacobian,
            &mut self.constraint_velocity_residuals,
            &mut self.constraint_gamma,
            &mut self.event_values,
            &mut self.equilibrium_guesses,
            &mut self.contact_gaps,
            &mut self.contact_jacobian,
            &mut self.contact_coefficients,
            &mut self.support_changes,
            &mut self.coordinate_rates,
        ] {
            *tape = FunctionTape::default();
        }
    }

    /// Number of degrees of freedom `n`.
    pub fn num_dofs(&self) -> usize {
        self.description.num_dofs()
    }

    /// The tape the Taylor recurrences are built from ([`super::taylor::model_taylor_plan`]):
    /// [`Self::mass_matrix_and_forcing`] without constraints, else [`constrained_motion_tape`]
    /// of it, of `J` and of `γ`.
    pub fn taylor_tape(&self) -> std::borrow::Cow<'_, FunctionTape> {
        if self.description.constraints.is_empty() {
            std::borrow::Cow::Borrowed(&self.mass_matrix_and_forcing)
        } else {
            std::borrow::Cow::Owned(constrained_motion_tape(
                &self.mass_matrix_and_forcing,
                &self.constraint_jacobian,
                &self.constraint_gamma,
                self.num_dofs(),
            ))
        }
    }

    /// Every function with its name, in the order of the table above (the Jacobians, planned
    /// apart, not among them).
    pub fn functions(&self) -> [(&'static str, &FunctionTape); 16] {
        [
            ("initial_state", &self.initial_state),
            ("mass_matrix_and_forcing", &self.mass_matrix_and_forcing),
            ("kinetic_energy", &self.kinetic_energy),
            ("potential_energy", &self.potential_energy),
            ("point_positions", &self.point_positions),
            ("constraint_residuals", &self.constraint_residuals),
            ("constraint_jacobian", &self.constraint_jacobian),
            (
                "constraint_velocity_residuals",
                &self.constraint_velocity_residuals,
            ),
            ("constraint_gamma", &self.constraint_gamma),
            ("event_values", &self.event_values),
            ("equilibrium_guesses", &self.equilibrium_guesses),
            ("contact_gaps", &self.contact_gaps),
            ("contact_jacobian", &self.contact_jacobian),
            ("contact_coefficients", &self.contact_coefficients),
            ("support_changes", &self.support_changes),
            ("coordinate_rates", &self.coordinate_rates),
        ]
    }
}

/// The derived equations of a model, kept so that its exact Jacobians can be derived and
/// planned when something first needs them ([`Derivation::jacobians`]): simulation with an
/// explicit method never does, and for a 40-link chain they are three quarters of the code.
#[derive(Debug, Clone)]
pub struct Derivation {
    model: SymbolicModel,
    eom: EquationsOfMotion,
}

/// The exact Jacobians of a model as tapes (column-major `n × n` outputs).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JacobianProgram {
    /// `∂F/∂q`.
    pub forcing_jacobian_q: FunctionTape,
    /// `∂F/∂q̇`.
    pub forcing_jacobian_qdot: FunctionTape,
    /// `∂(M a)/∂q`, `a` read as the acceleration inputs.
    pub mass_matrix_product_jacobian: FunctionTape,
    /// With generalized speeds, `∂q̇/∂q`, then `∂q̇/∂u` (empty without speeds).
    pub coordinate_rates_jacobian: FunctionTape,
}

impl JacobianProgram {
    /// The four functions with their names.
    pub fn functions(&self) -> [(&'static str, &FunctionTape); 4] {
        [
            ("forcing_jacobian_q", &self.forcing_jacobian_q),
            ("forcing_jacobian_qdot", &self.forcing_jacobian_qdot),
            (
                "mass_matrix_product_jacobian",
                &self.mass_matrix_product_jacobian,
            ),
            ("coordinate_rates_jacobian", &self.coordinate_rates_jacobian),
        ]
    }
}

impl Derivation {
    /// The equations as MathML ([`super::equations_mathml`]), for a description that was
    /// planned without them.
    pub fn equations_mathml(&self) -> Vec<String> {
        super::equations_mathml(&self.model, &self.eom)
    }

    /// Derives the exact Jacobians `∂F/∂q`, `∂F/∂q̇`, `∂(M a)/∂q`
    /// ([`crate::mechanics::Jacobians::of`]) and lowers their plans
    /// ([`super::plan::plan_jacobians`], as [`super::emit`] prints them) to tapes.
    pub fn jacobians(self) -> JacobianProgram {
        use ModelFunction as F;
        let n = self.eom.num_dofs;
        let parameters = self.model.parameters.iter().map(|p| p.symbol).collect();
        let plans = super::plan::plan_jacobians(self.model, &self.eom);
        let tapes = Tapes {
            plans: &plans,
            parameters,
        };
        let column_major = |function| {
            let mut tape = tapes.get(function);
            tape.outputs = column_major_order(&tape.outputs, n);
            FunctionTape::single(tape)
        };
        JacobianProgram {
            forcing_jacobian_q: column_major(F::ForcingJacobianQ),
            forcing_jacobian_qdot: column_major(F::ForcingJacobianQdot),
            mass_matrix_product_jacobian: column_major(F::MassMatrixProductJacobian),
            coordinate_rates_jacobian: {
                let mut tape = tapes.get(F::CoordinateRatesJacobian);
                let (d_q, d_u) = tape.outputs.split_at((n * n).min(tape.outputs.len()));
                let mut outputs = column_major_order(d_q, n);
                outputs.extend(column_major_order(d_u, n));
                let split = (n * n).min(outputs.len());
                tape.outputs = outputs;
                FunctionTape { tape, split }
            },
        }
    }
}

/// Lowers the plans of one [`ModelPlans`] to tapes.
struct Tapes<'a> {
    plans: &'a ModelPlans,
    parameters: Vec<SymbolId>,
}

impl<'a> Tapes<'a> {
    fn new(model: &SymbolicModel, plans: &'a ModelPlans) -> Self {
        let parameters = model.parameters.iter().map(|p| p.symbol).collect();
        Self { plans, parameters }
    }

    /// The tape of `function`; empty where the model has no such function.
    fn get(&self, function: ModelFunction) -> Tape {
        self.plans
            .get(function)
            .map(|plan| Tape::from_plan(&self.plans.arena, plan, &self.parameters))
            .unwrap_or_default()
    }
}

/// The tape of [`ModelFunction::MassMatrixAndForcing`] of `plans` (as
/// [`super::plan::plan_state`] made them): `M` column-major, then `F` — what the run-time
/// compiler evaluates, and what the Taylor recurrences ([`super::taylor`]) are built from
/// by both backends.
pub fn mass_matrix_and_forcing_tape(model: &SymbolicModel, plans: &ModelPlans) -> FunctionTape {
    let n = model.num_dofs();
    let tapes = Tapes::new(model, plans);
    let mut tape = tapes.get(ModelFunction::MassMatrixAndForcing);
    let (mass, forcing) = tape.outputs.split_at((n * n).min(tape.outputs.len()));
    let mut outputs = column_major_order(mass, n);
    outputs.extend_from_slice(forcing);
    tape.outputs = outputs;
    FunctionTape { tape, split: n * n }
}

/// The tape of a constrained model's index-1 system for the Taylor recurrences
/// ([`super::taylor::taylor_program`]): `[M Jᵀ; J 0]` column-major (`(n + m) × (n + m)`),
/// then `[F; γ]` (`n + m`), from the tapes of `M` and `F` (`motion`, as
/// [`mass_matrix_and_forcing_tape`] gives it), of `J` (`m × n`, row-major) and of `γ` (`m`).
///
/// The three tapes are concatenated, each input read once (the later tapes' reads of an input
/// become the first's), so that value numbering ([`Tape::numbered`]) shares what `M`, `F`,
/// `J` and `γ` compute alike (the sines and cosines of the coordinates): every output keeps
/// the bits of the tape it comes from.
pub fn constrained_motion_tape(
    motion: &FunctionTape,
    jacobian: &FunctionTape,
    gamma: &FunctionTape,
    n: usize,
) -> FunctionTape {
    let m = gamma.tape.outputs.len();
    let k = n + m;
    let mut tape = motion.tape.clone();
    let mut inputs: rustc_hash::FxHashMap<Input, Value> = tape
        .instructions
        .iter()
        .enumerate()
        .filter_map(|(v, i)| match i {
            Instruction::Input(input) => Some((*input, v as Value)),
            _ => None,
        })
        .collect();
    let jacobian = append(&mut tape, &mut inputs, &jacobian.tape);
    let gamma = append(&mut tape, &mut inputs, &gamma.tape);
    tape.instructions.push(Instruction::Const(0.0));
    let zero = (tape.instructions.len() - 1) as Value;
    let (mass, forcing) = motion
        .tape
        .outputs
        .split_at((n * n).min(motion.tape.outputs.len()));
    let mut outputs = Vec::with_capacity(k * k + k);
    for c in 0..k {
        for r in 0..k {
            outputs.push(match (r < n, c < n) {
                (true, true) => mass[r + c * n],
                (false, true) => jacobian[(r - n) * n + c],
                (true, false) => jacobian[(c - n) * n + r],
                (false, false) => zero,
            });
        }
    }
    outputs.extend_from_slice(forcing);
    outputs.extend_from_slice(&gamma);
    tape.outputs = outputs;
    FunctionTape { tape, split: k * k }
}

/// Appends `other`'s instructions to `tape`, an input `tape` reads already (listed in
/// `inputs`) read from there; the values of `other`'s outputs in `tape`.
fn append(
    tape: &mut Tape,
    inputs: &mut rustc_hash::FxHashMap<Input, Value>,
    other: &Tape,
) -> Vec<Value> {
    let mut values: Vec<Value> = Vec::with_capacity(other.instructions.len());
    for instruction in &other.instructions {
        let value = match *instruction {
            Instruction::Input(input) => *inputs.entry(input).or_insert_with(|| {
                tape.instructions.push(*instruction);
                (tape.instructions.len() - 1) as Value
            }),
            _ => {
                let renumbered = instruction.map_operands(|v| values[v as usize]);
                tape.instructions.push(renumbered);
                (tape.instructions.len() - 1) as Value
            }
        };
        values.push(value);
    }
    other.outputs.iter().map(|&v| values[v as usize]).collect()
}

/// The outputs of a row-major `n × n` matrix in column-major order.
fn column_major_order(row_major: &[u32], n: usize) -> Vec<u32> {
    (0..n * n)
        .filter_map(|k| row_major.get((k % n) * n + k / n).copied())
        .collect()
}
