//! Derivations: from a lowered model to `M(q, t) q̈ = F(q, q̇, t)` and its exact Jacobians.
//!
//! One [`Formulation`] interface serves every derivation (Lagrange, momentum balance, the
//! file's own balances and hand-written equations), so the code generator and the
//! cross-checks treat them alike; [`preferred_formulation`] picks the one generated code
//! uses.

mod balances;
mod constraints;
pub mod cross_check;
mod energy;
pub mod frames;
mod kinematics;
mod lagrange;
mod limit;
mod lower;
mod mass;
mod momentum;
mod numeric;
mod preferred;
mod speeds;

pub use balances::{HandEquations, UserBalances};
pub use constraints::{ConstraintEquations, linear_in_rates, redundant_rows};
pub use energy::{EnergyRate, PowerRoute, energy_routes_skipped};
pub use kinematics::{FrameKinematics, PointKinematics, Reaction, ReactionError};
pub use lagrange::Lagrange;
pub use limit::{DERIVATION_OPERAND_LIMIT, finish_derivation, limit_derivation};
pub use lower::Speeds;
pub use lower::{
    BalanceInfo, BalanceSet, BodyInfo, Equilibrium, EventInfo, LoadInfo, ParameterInfo,
    SpatialBody, SymbolicModel,
};
pub use mass::mass_matrix_diagnostics;
pub use momentum::MomentumBalance;
pub use preferred::{preferred_equations, preferred_formulation};
pub use speeds::{Kane, on_the_constraints};

use crate::expr::ExprId;

/// `M(q, t) q̈ = F(q, q̇, t)` as expressions of one [`SymbolicModel`]'s arena.
#[derive(Debug, Clone, PartialEq)]
pub struct EquationsOfMotion {
    /// Number of degrees of freedom `n`.
    pub num_dofs: usize,
    /// Mass matrix, `n × n` row-major (entry `(i, j)` at `i n + j`).
    pub mass_matrix: Vec<ExprId>,
    /// Forcing `F`, length `n`.
    pub forcing: Vec<ExprId>,
}

impl EquationsOfMotion {
    /// Entry `(i, j)` of the mass matrix.
    pub fn mass(&self, i: usize, j: usize) -> ExprId {
        self.mass_matrix[i * self.num_dofs + j]
    }
}

/// A way of deriving equations of motion from a model.
pub trait Formulation {
    /// Short name (`lagrange`).
    fn name(&self) -> &'static str;
    /// Derives `M q̈ = F`, adding the expressions to the model's arena.
    fn derive(&self, model: &mut SymbolicModel) -> EquationsOfMotion;
}

/// Exact Jacobians of the equations of motion, for implicit integrators and linearisation.
#[derive(Debug, Clone, PartialEq)]
pub struct Jacobians {
    /// `∂F/∂q`, `n × n` row-major (entry `(i, j)` = `∂Fᵢ/∂qⱼ`).
    pub forcing_q: Vec<ExprId>,
    /// `∂F/∂q̇`, `n × n` row-major.
    pub forcing_qdot: Vec<ExprId>,
    /// `∂(M a)/∂q`, `n × n` row-major (entry `(i, k)` = `Σⱼ ∂Mᵢⱼ/∂qₖ aⱼ`), where the vector
    /// `a` is represented by the acceleration symbols `q̈ⱼ`.
    pub mass_product_q: Vec<ExprId>,
    /// With generalized speeds, the Jacobians of the kinematic equations `q̇ = K(q, u, t)`:
    /// `∂K/∂q`, then `∂K/∂u` (`W`), each `n × n` row-major; empty in the coordinates' rates.
    pub coordinate_rates: Vec<ExprId>,
}

impl Jacobians {
    /// Differentiates `eom` exactly (symbolically) with respect to `q` and `q̇`.
    pub fn of(model: &mut SymbolicModel, eom: &EquationsOfMotion) -> Self {
        let n = eom.num_dofs;
        let symbols: Vec<[crate::expr::SymbolId; 3]> =
            (0..n).map(|i| model.coordinate_symbols(i)).collect();
        let arena = &mut model.arena;
        let mut forcing_q = Vec::with_capacity(n * n);
        let mut forcing_qdot = Vec::with_capacity(n * n);
        for &f in &eom.forcing {
            for s in &symbols {
                forcing_q.push(arena.diff(f, s[0]));
            }
            for s in &symbols {
                forcing_qdot.push(arena.diff(f, s[1]));
            }
        }
        let accelerations: Vec<ExprId> = symbols.iter().map(|s| arena.symbol_expr(s[2])).collect();
        let mut mass_product_q = Vec::with_capacity(n * n);
        for i in 0..n {
            let terms: Vec<ExprId> = (0..n)
                .map(|j| arena.times(eom.mass(i, j), accelerations[j]))
                .collect();
            let row = arena.sum(&terms);
            for s in &symbols {
                mass_product_q.push(arena.diff(row, s[0]));
            }
        }
        let mut coordinate_rates = Vec::new();
        let kinematic = model.speeds.as_ref().map(|s| &s.kinematic_equations);
        for k in [0, 1] {
            for &rate in kinematic.into_iter().flatten() {
                for s in &symbols {
                    coordinate_rates.push(model.arena.diff(rate, s[k]));
                }
            }
        }
        Self {
            forcing_q,
            forcing_qdot,
            mass_product_q,
            coordinate_rates,
        }
    }
}

/// `(M, F)` as given or multiplied out entry by entry (where that is cheaper as a tree),
/// whichever costs fewer operations after CSE as a whole: expansion exposes exact
/// cancellations and angle-difference identities but can destroy sharing between entries.
pub(crate) fn cheaper_of_raw_and_expanded(
    arena: &mut crate::expr::ExprArena,
    mass_matrix: Vec<ExprId>,
    forcing: Vec<ExprId>,
) -> (Vec<ExprId>, Vec<ExprId>) {
    let expanded_mass: Vec<ExprId> = mass_matrix
        .iter()
        .map(|&m| arena.expand_if_cheaper(m))
        .collect();
    let expanded_forcing: Vec<ExprId> = forcing
        .iter()
        .map(|&f| arena.expand_if_cheaper(f))
        .collect();
    let cost = |arena: &crate::expr::ExprArena, m: &[ExprId], f: &[ExprId]| {
        let roots: Vec<ExprId> = m.iter().chain(f).copied().collect();
        crate::expr::cse::operation_count(arena, &roots)
    };
    if cost(arena, &expanded_mass, &expanded_forcing) < cost(arena, &mass_matrix, &forcing) {
        (expanded_mass, expanded_forcing)
    } else {
        (mass_matrix, forcing)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::ExprArena;
    use crate::expr::cse::operation_count;

    /// `(x + 1)² − x² − 2x` multiplies out to 1, so the expanded form is kept; of `(x + 1)⁵`
    /// and its expansion the cheaper is kept. (On a tie the raw form is kept; keeping the
    /// expanded one would be as good: that choice is not tested.)
    /// An arena with the coordinate `x`; returns it with `x`, `x + 1` and
    /// `(x + 1)² − x² − 2x` (which multiplies out to 1), for the tests of the form choices.
    pub(in crate::mechanics) fn cancelling_square() -> (ExprArena, ExprId, ExprId, ExprId) {
        let mut a = ExprArena::new();
        let [x, _, _] = a.coordinate("x");
        let (one, two) = (a.int(1), a.int(2));
        let x1 = a.plus(x, one);
        let square = a.pow(x1, two);
        let x2 = a.pow(x, two);
        let two_x = a.times(two, x);
        let (nx2, n2x) = (a.neg(x2), a.neg(two_x));
        let cancelling = a.sum(&[square, nx2, n2x]);
        (a, x, x1, cancelling)
    }

    #[test]
    fn the_cheaper_of_the_raw_and_the_expanded_form_is_kept() {
        let (mut a, x, x1, cancelling) = cancelling_square();
        let (one, five) = (a.int(1), a.int(5));
        let fifth = a.pow(x1, five);
        let (m, f) = cheaper_of_raw_and_expanded(&mut a, vec![cancelling], vec![x]);
        let d = a.minus(m[0], one);
        assert!(a.is_zero(d) && f == [x], "{m:?}");
        // Whichever it keeps costs no more than the other form.
        let expanded = a.expand(fifth);
        let (m, _) = cheaper_of_raw_and_expanded(&mut a, vec![fifth], vec![x]);
        let kept = operation_count(&a, &m);
        assert!(kept <= operation_count(&a, &[fifth]) && kept <= operation_count(&a, &[expanded]));
    }
}
