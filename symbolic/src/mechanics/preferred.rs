//! Which formulation's equations generated code uses, chosen without deriving.

use super::lagrange::Lagrange;
use super::lower::SymbolicModel;
use super::momentum::MomentumBalance;
use super::speeds::Kane;
use super::{EquationsOfMotion, Formulation};

/// The formulation whose equations generated code uses: Kane's for a model in generalized
/// speeds ([`Kane::applies_to`]), momentum balance for a model in the
/// kinematic form with no written energy or generalized forces
/// ([`MomentumBalance::applies_to`] and not [`SymbolicModel::uses_energy_form`]), Lagrange
/// otherwise. (A kinematic file with a written `potential:` or `generalized_forces:` is
/// cross-checked by momentum balance but generated from Lagrange's equations, as it was
/// before momentum balance took those terms: its generated code stays as it was.)
///
/// The rule needs no derivation, so a model is derived once however it is loaded (the
/// `model!` macro and the run-time loader both go through [`preferred_equations`]). Both
/// formulations give the same equations (the test suite and `eomgen check` compare them
/// symbolically and numerically); momentum balance is chosen because its projections on
/// shared partial velocities are never larger than Lagrange's derivatives of `T` on the
/// bundled models and are usually smaller, in `M` and `F` and more so in their Jacobians:
/// against deriving both and keeping the one with fewer operations of `M` and `F` after CSE
/// (the rule before issue 18), no bundled model gets more than one more operation, and the
/// 3-spring line loses 26 in its Jacobians for its one operation in `F`.
pub fn preferred_formulation(model: &SymbolicModel) -> &'static dyn Formulation {
    if Kane::applies_to(model) && !model.uses_energy_form {
        &Kane
    } else if MomentumBalance::applies_to(model) && !model.uses_energy_form {
        &MomentumBalance
    } else {
        &Lagrange
    }
}

/// The equations to generate code from, derived by [`preferred_formulation`] alone; returns
/// them and the formulation's name.
pub fn preferred_equations(model: &mut SymbolicModel) -> (EquationsOfMotion, &'static str) {
    let formulation = preferred_formulation(model);
    (formulation.derive(model), formulation.name())
}
