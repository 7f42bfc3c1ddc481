//! Lagrange's equations (syllabus lecture 9; HW11 g, HW19 b).

use super::{EquationsOfMotion, Formulation, SymbolicModel};
use crate::expr::ExprId;

/// Lagrange's equations of the second kind with non-potential generalized forces:
///
/// ```text
/// d/dt ∂T/∂q̇ − ∂T/∂q + ∂V/∂q = Q
/// ⇒ M = ∂²T/∂q̇∂q̇ᵀ,
///   F = ∂T/∂q − ∂V/∂q − (∂²T/∂q̇∂qᵀ) q̇ − ∂²T/∂q̇∂t + Q
/// ```
///
/// `M` is built from the upper triangle and mirrored, so it is exactly symmetric. Nothing is
/// inverted symbolically. `M` and `F` are multiplied out ([`crate::expr::ExprArena::expand`])
/// when that lowers their operation count after common-subexpression elimination, which
/// removes the exactly cancelling terms of Lagrange's equations.
///
/// # References
/// D. T. Greenwood, *Advanced Dynamics*, Cambridge University Press, 2003, §1.4.
#[derive(Debug, Clone, Copy, Default)]
pub struct Lagrange;

impl Formulation for Lagrange {
    fn name(&self) -> &'static str {
        "lagrange"
    }

    fn derive(&self, model: &mut SymbolicModel) -> EquationsOfMotion {
        let n = model.num_dofs();
        let symbols: Vec<_> = (0..n).map(|i| model.coordinate_symbols(i)).collect();
        let ts = model.time_symbol();
        let (kinetic, potential) = (model.kinetic, model.potential);
        let arena = &mut model.arena;
        let rates: Vec<ExprId> = symbols.iter().map(|s| arena.symbol_expr(s[1])).collect();
        let momenta: Vec<ExprId> = symbols.iter().map(|s| arena.diff(kinetic, s[1])).collect();

        let mut mass_matrix = vec![arena.int(0); n * n];
        for i in 0..n {
            for j in i..n {
                let m = arena.diff(momenta[i], symbols[j][1]);
                mass_matrix[i * n + j] = m;
                mass_matrix[j * n + i] = m;
            }
        }

        // F from T multiplied out (v·v as a sum of monomials): its derivatives are sums of
        // monomials too, in which the terms of F that cancel meet at once.
        let kinetic = arena.expand_time_varying(kinetic);
        let momenta: Vec<ExprId> = symbols.iter().map(|s| arena.diff(kinetic, s[1])).collect();
        let mut forcing = Vec::with_capacity(n);
        for i in 0..n {
            let mut terms = Vec::new();
            terms.push(arena.diff(kinetic, symbols[i][0]));
            let dv = arena.diff(potential, symbols[i][0]);
            terms.push(arena.neg(dv));
            for j in 0..n {
                let dp = arena.diff(momenta[i], symbols[j][0]);
                if !arena.is_zero(dp) {
                    let term = arena.times(dp, rates[j]);
                    terms.push(arena.neg(term));
                }
            }
            let dpt = arena.diff(momenta[i], ts);
            terms.push(arena.neg(dpt));
            terms.push(model.generalized_forces[i]);
            forcing.push(arena.sum(&terms));
        }
        // ∂T/∂qᵢ and the (∂pᵢ/∂qⱼ) q̇ⱼ terms share products that cancel exactly; they only
        // meet as like terms once multiplied out.
        let (mass_matrix, forcing) =
            super::cheaper_of_raw_and_expanded(arena, mass_matrix, forcing);
        EquationsOfMotion {
            num_dofs: n,
            mass_matrix,
            forcing,
        }
    }
}
