//! The one planner: a derived model's functions as CSE plans, which both the `model!`
//! macro's Rust ([`super::emit`]) and the run-time compiler's tapes
//! ([`super::program::ModelProgram`]) are made from.
//!
//! Each function is planned over exactly the expressions it returns, after the angle-sum
//! rewrite ([`crate::expr::trig::expand_angle_sums`]), by [`crate::expr::cse::plan`], one
//! after the other on one copy of the arena (the rewrite adds nodes, so a plan depends on
//! what was planned before it). Both consumers go through the same two steps:
//! [`plan_state`] plans the functions of the state ([`ModelFunction::STATE`], always first
//! and in this order) on a copy of the derived model's arena, and [`plan_jacobians`] derives
//! the exact Jacobians and plans them on the arena they were added to. The macro plans `mass_matrix`
//! and `forcing` apart after the others, which leaves their plans unchanged. So a model
//! compiled at build time and one compiled at run time compute the same operations in the
//! same order by construction (the bit-identity tests in `tests/runtime_models.rs` stay as a
//! guard).

use crate::expr::cse::{self, CsePlan};
use crate::expr::{ExprArena, ExprId, trig};
use crate::mechanics::{EquationsOfMotion, Jacobians, SymbolicModel};

/// A function of the model contract (`MechanicalSystem<N>`) that is generated from
/// expressions, in the order the macro emits them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ModelFunction {
    /// `q(0)` (n), then `q̇(0)` (n).
    InitialState,
    /// `M` (n × n, row-major).
    MassMatrix,
    /// `F` (n).
    Forcing,
    /// `M` (n × n, row-major), then `F` (n), in one plan.
    MassMatrixAndForcing,
    /// `∂F/∂q` (n × n, row-major).
    ForcingJacobianQ,
    /// `∂F/∂q̇` (n × n, row-major).
    ForcingJacobianQdot,
    /// `∂(M a)/∂q` (n × n, row-major), `a` read as the acceleration symbols.
    MassMatrixProductJacobian,
    /// `T` (1).
    KineticEnergy,
    /// `V` (1).
    PotentialEnergy,
    /// Every point's components in file order (2 or 3 per point).
    PointPositions,
    /// `Φ` (m_h).
    ConstraintResiduals,
    /// `J` (m × n, row-major).
    ConstraintJacobian,
    /// `J q̇ + b` (m).
    ConstraintVelocityResiduals,
    /// `γ` (m).
    ConstraintGamma,
    /// Event functions `g` (e); `q̈` as the acceleration symbols, `λ` as the multipliers.
    EventValues,
    /// `n` values per named equilibrium (`2 n`, coordinates then rates, when one is a steady
    /// motion).
    EquilibriumGuesses,
    /// The contacts' gaps `g` (m_c), their rates `ġ` (m_c), `γ` of `G q̈ = γ` (m_c), then
    /// `γ_T` of `T q̈ = γ_T` (m_c).
    ContactGaps,
    /// The contacts' Jacobian `G = ∂g/∂q` (m_c × n, row-major), then their slips' rows `T`
    /// (m_c × n; a row of zeros for a frictionless contact).
    ContactJacobian,
    /// Each contact's coefficient of restitution `e` and of friction `μ` (2 m_c).
    ContactCoefficients,
    /// Each change of support's values, in contact order
    /// (`block` of [`crate::model::elements::support`]).
    SupportChanges,
    /// With generalized speeds, the kinematic equations `q̇ = W (u − Z)` (n).
    CoordinateRates,
    /// With generalized speeds, `∂q̇/∂q` then `∂q̇/∂u` (2 × n × n, row-major each).
    CoordinateRatesJacobian,
}

impl ModelFunction {
    /// Every function, in the macro's order.
    pub const ALL: [ModelFunction; 22] = [
        ModelFunction::InitialState,
        ModelFunction::MassMatrix,
        ModelFunction::Forcing,
        ModelFunction::MassMatrixAndForcing,
        ModelFunction::ForcingJacobianQ,
        ModelFunction::ForcingJacobianQdot,
        ModelFunction::MassMatrixProductJacobian,
        ModelFunction::KineticEnergy,
        ModelFunction::PotentialEnergy,
        ModelFunction::PointPositions,
        ModelFunction::ConstraintResiduals,
        ModelFunction::ConstraintJacobian,
        ModelFunction::ConstraintVelocityResiduals,
        ModelFunction::ConstraintGamma,
        ModelFunction::EventValues,
        ModelFunction::EquilibriumGuesses,
        ModelFunction::ContactGaps,
        ModelFunction::ContactJacobian,
        ModelFunction::ContactCoefficients,
        ModelFunction::SupportChanges,
        ModelFunction::CoordinateRates,
        ModelFunction::CoordinateRatesJacobian,
    ];

    /// The functions of the state that every compilation plans, first and in this order
    /// ([`plan_state`]): all but the exact Jacobians and `mass_matrix` and `forcing` apart
    /// (a backend evaluates both in one).
    pub const STATE: [ModelFunction; 16] = [
        ModelFunction::InitialState,
        ModelFunction::MassMatrixAndForcing,
        ModelFunction::KineticEnergy,
        ModelFunction::PotentialEnergy,
        ModelFunction::PointPositions,
        ModelFunction::ConstraintResiduals,
        ModelFunction::ConstraintJacobian,
        ModelFunction::ConstraintVelocityResiduals,
        ModelFunction::ConstraintGamma,
        ModelFunction::EventValues,
        ModelFunction::EquilibriumGuesses,
        ModelFunction::ContactGaps,
        ModelFunction::ContactJacobian,
        ModelFunction::ContactCoefficients,
        ModelFunction::SupportChanges,
        ModelFunction::CoordinateRates,
    ];

    /// The exact Jacobians ([`plan_jacobians`]), which the run-time compiler plans only when
    /// first needed.
    pub const JACOBIANS: [ModelFunction; 4] = [
        ModelFunction::ForcingJacobianQ,
        ModelFunction::ForcingJacobianQdot,
        ModelFunction::MassMatrixProductJacobian,
        ModelFunction::CoordinateRatesJacobian,
    ];

    /// The method's name in `MechanicalSystem<N>`.
    pub fn name(self) -> &'static str {
        match self {
            ModelFunction::InitialState => "initial_state",
            ModelFunction::MassMatrix => "mass_matrix",
            ModelFunction::Forcing => "forcing",
            ModelFunction::MassMatrixAndForcing => "mass_matrix_and_forcing",
            ModelFunction::ForcingJacobianQ => "forcing_jacobian_q",
            ModelFunction::ForcingJacobianQdot => "forcing_jacobian_qdot",
            ModelFunction::MassMatrixProductJacobian => "mass_matrix_product_jacobian",
            ModelFunction::KineticEnergy => "kinetic_energy",
            ModelFunction::PotentialEnergy => "potential_energy",
            ModelFunction::PointPositions => "point_positions",
            ModelFunction::ConstraintResiduals => "constraint_residuals",
            ModelFunction::ConstraintJacobian => "constraint_jacobian",
            ModelFunction::ConstraintVelocityResiduals => "constraint_velocity_residuals",
            ModelFunction::ConstraintGamma => "constraint_gamma",
            ModelFunction::EventValues => "event_values",
            ModelFunction::EquilibriumGuesses => "equilibrium_guesses",
            ModelFunction::ContactGaps => "contact_gaps",
            ModelFunction::ContactJacobian => "contact_jacobian",
            ModelFunction::ContactCoefficients => "contact_coefficients",
            ModelFunction::SupportChanges => "support_changes",
            ModelFunction::CoordinateRates => "coordinate_rates",
            ModelFunction::CoordinateRatesJacobian => "coordinate_rates_jacobian",
        }
    }

    /// The expressions the function returns, in output order, or `None` where the model has
    /// no such function and the trait's default stands for it (constraints, events and
    /// equilibria of a model without any), or where the Jacobians were not derived.
    fn roots(
        self,
        model: &SymbolicModel,
        eom: &EquationsOfMotion,
        jacobians: Option<&Jacobians>,
    ) -> Option<Vec<ExprId>> {
        let c = &model.constraints;
        let constrained = |roots: &[ExprId]| (!c.is_empty()).then(|| roots.to_vec());
        let unless_empty = |roots: Vec<ExprId>| (!roots.is_empty()).then_some(roots);
        match self {
            ModelFunction::InitialState => {
                Some([model.initial_q.clone(), model.initial_qdot.clone()].concat())
            }
            ModelFunction::MassMatrix => Some(eom.mass_matrix.clone()),
            ModelFunction::Forcing => Some(eom.forcing.clone()),
            ModelFunction::MassMatrixAndForcing => {
                Some([eom.mass_matrix.clone(), eom.forcing.clone()].concat())
            }
            ModelFunction::ForcingJacobianQ => jacobians.map(|j| j.forcing_q.clone()),
            ModelFunction::ForcingJacobianQdot => jacobians.map(|j| j.forcing_qdot.clone()),
            ModelFunction::MassMatrixProductJacobian => jacobians.map(|j| j.mass_product_q.clone()),
            ModelFunction::CoordinateRates => {
                (model.speeds.as_ref()).map(|s| s.kinematic_equations.clone())
            }
            ModelFunction::CoordinateRatesJacobian => {
                jacobians.and_then(|j| unless_empty(j.coordinate_rates.clone()))
            }
            ModelFunction::KineticEnergy => Some(vec![model.kinetic]),
            ModelFunction::PotentialEnergy => Some(vec![model.potential]),
            ModelFunction::PointPositions => Some(
                model
                    .points
                    .iter()
                    .flat_map(|(_, r)| r.iter().copied())
                    .collect(),
            ),
            ModelFunction::ConstraintResiduals => constrained(&c.phi),
            ModelFunction::ConstraintJacobian => constrained(&c.jacobian),
            ModelFunction::ConstraintVelocityResiduals => constrained(&c.velocity),
            ModelFunction::ConstraintGamma => constrained(&c.gamma),
            ModelFunction::EventValues => {
                unless_empty(model.events.iter().map(|e| e.function).collect())
            }
            ModelFunction::ContactGaps => unless_empty(
                (model.contacts.iter().map(|c| c.gap))
                    .chain(model.contacts.iter().map(|c| c.rate))
                    .chain(model.contacts.iter().map(|c| c.gamma))
                    .chain(model.contacts.iter().map(|c| c.tangent_gamma))
                    .chain(model.contacts.iter().map(|c| c.surface_velocity))
                    .collect(),
            ),
            ModelFunction::ContactJacobian => unless_empty(
                (model.contacts.iter())
                    .flat_map(|c| c.jacobian.iter().copied())
                    .chain(
                        model
                            .contacts
                            .iter()
                            .flat_map(|c| c.tangent.iter().copied()),
                    )
                    .collect(),
            ),
            ModelFunction::ContactCoefficients => unless_empty(
                (model.contacts.iter())
                    .flat_map(|c| [c.restitution, c.friction, c.static_friction])
                    .collect(),
            ),
            ModelFunction::SupportChanges => unless_empty(
                (model.contacts.iter())
                    .filter_map(|c| c.support.as_ref())
                    .flat_map(|s| s.block.iter().copied())
                    .collect(),
            ),
            // With a steady motion among them, each entry's rates follow its coordinates
            // ([`ModelDescription::equilibrium_rates`](eomgen_description::ModelDescription)).
            ModelFunction::EquilibriumGuesses => unless_empty(
                model
                    .equilibria
                    .iter()
                    .flat_map(|e| {
                        let rates = model.has_steady_motions().then_some(&e.rates);
                        e.guess.iter().chain(rates.into_iter().flatten()).copied()
                    })
                    .collect(),
            ),
        }
    }
}

/// One planned function: its CSE plan, whose roots are the function's outputs after the
/// angle-sum rewrite.
#[derive(Debug, Clone)]
pub struct FunctionPlan {
    /// Which function.
    pub function: ModelFunction,
    /// The plan, on [`ModelPlans::arena`].
    pub plan: CsePlan,
}

/// The planned functions of a model on one arena (a copy of the model's, with the nodes the
/// angle-sum rewrite added).
#[derive(Debug, Clone)]
pub struct ModelPlans {
    /// The arena the plans refer to.
    pub arena: ExprArena,
    /// The functions the model has among those asked for, in the order asked.
    pub functions: Vec<FunctionPlan>,
}

impl ModelPlans {
    /// The plan of `function`, if it was planned.
    pub fn get(&self, function: ModelFunction) -> Option<&CsePlan> {
        self.functions
            .iter()
            .find(|f| f.function == function)
            .map(|f| &f.plan)
    }
}

/// Plans [`ModelFunction::STATE`], then `extra`, of a derived model (its equations, not yet
/// differentiated by [`Jacobians::of`]) on one copy of its arena. The plans of
/// [`ModelFunction::STATE`] do not depend on `extra`, which is planned after them.
pub fn plan_state(
    model: &SymbolicModel,
    eom: &EquationsOfMotion,
    extra: &[ModelFunction],
) -> ModelPlans {
    let functions: Vec<ModelFunction> = ModelFunction::STATE.iter().chain(extra).copied().collect();
    plan_functions(model.arena.clone(), model, eom, None, &functions)
}

/// Derives the exact Jacobians of a derived model ([`Jacobians::of`], which adds their nodes
/// to its arena) and plans [`ModelFunction::JACOBIANS`] on that arena, which the plans keep
/// (the model is consumed: nothing else needs it once its Jacobians are planned).
pub fn plan_jacobians(mut model: SymbolicModel, eom: &EquationsOfMotion) -> ModelPlans {
    let jacobians = Jacobians::of(&mut model, eom);
    let arena = std::mem::take(&mut model.arena);
    plan_functions(
        arena,
        &model,
        eom,
        Some(&jacobians),
        &ModelFunction::JACOBIANS,
    )
}

/// Every plan the `model!` macro's code is printed from: [`plan_state`] with `mass_matrix`
/// and `forcing` apart, and [`plan_jacobians`] on a copy of the model.
#[derive(Debug, Clone)]
pub struct EmitPlans {
    /// The functions of the state.
    pub state: ModelPlans,
    /// The exact Jacobians.
    pub jacobians: ModelPlans,
}

impl EmitPlans {
    /// Plans every generated function of a derived model (its equations, not yet
    /// differentiated).
    pub fn of(model: &SymbolicModel, eom: &EquationsOfMotion) -> Self {
        let state = plan_state(
            model,
            eom,
            &[ModelFunction::MassMatrix, ModelFunction::Forcing],
        );
        let jacobians = plan_jacobians(model.clone(), eom);
        Self { state, jacobians }
    }

    /// The plan of `function` and the arena it refers to, if the model has the function.
    pub fn get(&self, function: ModelFunction) -> Option<(&ExprArena, &CsePlan)> {
        [&self.state, &self.jacobians]
            .into_iter()
            .find_map(|plans| Some((&plans.arena, plans.get(function)?)))
    }
}

/// Plans `functions` of a derived model, in the order given, one after the other on `arena`
/// (the model's arena or a copy of it; the roots are looked up in the model, never its
/// arena). A function the model does not have ([`ModelFunction`]'s constraint, event
/// and equilibrium functions of a model without any; the Jacobians when `jacobians` is
/// `None`) is left out.
fn plan_functions(
    mut arena: ExprArena,
    model: &SymbolicModel,
    eom: &EquationsOfMotion,
    jacobians: Option<&Jacobians>,
    functions: &[ModelFunction],
) -> ModelPlans {
    let functions = functions
        .iter()
        .filter_map(|&function| {
            let roots = function.roots(model, eom, jacobians)?;
            let roots = trig::expand_angle_sums(&mut arena, &roots);
            let plan = cse::plan(&arena, &roots, "__e");
            Some(FunctionPlan { function, plan })
        })
        .collect();
    ModelPlans { arena, functions }
}
