//! Lagrange's equations (syllabus lecture 9; HW11 g, HW19 b).

use super::{EquationsOfMotion, Formulation, SymbolicModel};
use crate::expr::{ExprArena, ExprId};

/// Lagrange's equations of the second kind with non-potential generalized forces:
///
/// ```text
/// d/dt ∂T/∂q̇ − ∂T/∂q + ∂V/∂q = Q
/// ⇒ M = ∂²T/∂q̇∂q̇ᵀ,
///   F = ∂T/∂q − ∂V/∂q − (∂²T/∂q̇∂qᵀ) q̇ − ∂²T/∂q̇∂t + Q
/// ```
///
/// `M` is built from the upper triangle and mirrored, so it is exactly symmetric. Nothing is
/// inverted symbolically.
///
/// `T` is first multiplied out where it changes in time and collected by its time-varying
/// factors ([`crate::expr::ExprArena::collect_time_varying`]): a quadratic form in `q̇` with
/// one coefficient per distinct product of rates and functions of `q`, the masses of every
/// body that contributes to it summed into that coefficient. For an `n`-link chain this is
/// `O(n²)` terms (the `O(n³)` terms of `Σ ½ m v·v` multiplied out are summed once, here), so
/// each `∂T/∂q̇ᵢ` has `O(n)` terms and every later step works on expressions of the size of
/// the result. Differentiating the multiplied-out form instead built the `O(n³)` terms again
/// for every derivative.
///
/// `∂T/∂qᵢ` and the `(∂pᵢ/∂qⱼ) q̇ⱼ` terms share products that cancel exactly; they meet as like
/// terms once multiplied out. So `M` and `F` are then kept as derived or multiplied out and
/// collected again, entry by entry, whichever costs fewer operations after CSE (see
/// `cheapest_forms`): the collected form removes the cancelling terms and shares the mass
/// sums between entries, the derived one keeps a spring's `∂V/∂q` in its compact form.
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
        // In generalized speeds: the equations derived in the rates before the switch,
        // carried into the speeds (`super::speeds`).
        if let Some(speeds) = &model.speeds {
            let (mass_matrix, forcing) = speeds.lagrange.clone();
            return EquationsOfMotion {
                num_dofs: forcing.len(),
                mass_matrix,
                forcing,
            };
        }
        let n = model.num_dofs();
        let (mass_matrix, inertial, applied) = parts(model);
        let (mass_matrix, forcing) =
            cheapest_forms(&mut model.arena, mass_matrix, inertial, applied);
        EquationsOfMotion {
            num_dofs: n,
            mass_matrix,
            forcing,
        }
    }
}

/// `M` (`n × n` row-major) and the two parts of `F = K + P` as derived: `K` from `T` (the
/// terms that cancel), `P = −∂V/∂q + Q`.
fn parts(model: &mut SymbolicModel) -> (Vec<ExprId>, Vec<ExprId>, Vec<ExprId>) {
    {
        let n = model.num_dofs();
        let symbols: Vec<_> = (0..n).map(|i| model.coordinate_symbols(i)).collect();
        let ts = model.time_symbol();
        let arena = &mut model.arena;
        let kinetic = compact(arena, model.kinetic);
        let potential = model.potential;
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
        // F = K + P: the terms from T (where the cancellations are) and those from V and Q.
        let mut inertial = Vec::with_capacity(n);
        let mut applied = Vec::with_capacity(n);
        for i in 0..n {
            let mut terms = Vec::new();
            terms.push(arena.diff(kinetic, symbols[i][0]));
            for j in 0..n {
                let dp = arena.diff(momenta[i], symbols[j][0]);
                if !arena.is_zero(dp) {
                    let term = arena.times(dp, rates[j]);
                    terms.push(arena.neg(term));
                }
            }
            let dpt = arena.diff(momenta[i], ts);
            terms.push(arena.neg(dpt));
            inertial.push(arena.sum(&terms));
            let dv = arena.diff(potential, symbols[i][0]);
            let ndv = arena.neg(dv);
            applied.push(arena.plus(ndv, model.generalized_forces[i]));
        }
        (mass_matrix, inertial, applied)
    }
}

/// `e` multiplied out where it changes in time and collected by its time-varying factors.
fn compact(arena: &mut ExprArena, e: ExprId) -> ExprId {
    let x = arena.expand_time_varying(e);
    arena.collect_time_varying(x)
}

/// `(M, F)` from `M`, the inertial part `K` and the applied part `P` of `F = K + P`, in the
/// combination that costs the fewest operations after CSE (the first of the cheapest, in the
/// order below): `M` [`compact`]ed or as derived; `F` compacted as a whole, or as `K + P`
/// with each part compacted or as derived.
///
/// Compacting removes the cancelling terms of `K` and factors the sums of masses of a chain,
/// but it multiplies out `P`, which for a spring (`∂V/∂q` of `½ k (|d| − ℓ₀)²`) is smaller as
/// derived; trying the parts separately keeps the better form of each.
fn cheapest_forms(
    arena: &mut ExprArena,
    mass_matrix: Vec<ExprId>,
    inertial: Vec<ExprId>,
    applied: Vec<ExprId>,
) -> (Vec<ExprId>, Vec<ExprId>) {
    let compact_all = |arena: &mut ExprArena, v: &[ExprId]| -> Vec<ExprId> {
        v.iter().map(|&e| compact(arena, e)).collect()
    };
    let add = |arena: &mut ExprArena, a: &[ExprId], b: &[ExprId]| -> Vec<ExprId> {
        a.iter().zip(b).map(|(x, y)| arena.plus(*x, *y)).collect()
    };
    let compact_mass = compact_all(arena, &mass_matrix);
    let compact_inertial = compact_all(arena, &inertial);
    let compact_applied = compact_all(arena, &applied);
    let raw_forcing = add(arena, &inertial, &applied);
    let mut masses = [compact_mass, mass_matrix];
    let mut forcings = [
        compact_all(arena, &raw_forcing),
        add(arena, &compact_inertial, &compact_applied),
        add(arena, &compact_inertial, &applied),
        add(arena, &inertial, &compact_applied),
        raw_forcing,
    ];
    let mut best = (u64::MAX, 0, 0);
    for (a, m) in masses.iter().enumerate() {
        for (b, f) in forcings.iter().enumerate() {
            let roots: Vec<ExprId> = m.iter().chain(f).copied().collect();
            let cost = crate::expr::cse::operation_count(arena, &roots);
            if cost < best.0 {
                best = (cost, a, b);
            }
        }
    }
    let (_, a, b) = best;
    (
        std::mem::take(&mut masses[a]),
        std::mem::take(&mut forcings[b]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::cse::operation_count;

    fn cost(arena: &ExprArena, m: &[ExprId], f: &[ExprId]) -> u64 {
        let roots: Vec<ExprId> = m.iter().chain(f).copied().collect();
        operation_count(arena, &roots)
    }

    /// Lagrange keeps the cheapest of the forms it tries: on every bundled model with a
    /// `kinetic:` or bodies its `(M, F)` costs no more after CSE than all compacted or all as
    /// derived, and on the spring models (whose `∂V/∂q` grows when multiplied out) strictly
    /// less than all compacted.
    #[test]
    fn the_equations_cost_no_more_than_either_uniform_form() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");
        let mut cheaper_than_compact = Vec::new();
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for path in entries {
            let source = std::fs::read_to_string(&path).unwrap();
            let file = crate::model::load("m.yaml", &source).unwrap();
            let mut model = SymbolicModel::from_file(&file).unwrap();
            let eom = Lagrange.derive(&mut model);
            let chosen = cost(&model.arena, &eom.mass_matrix, &eom.forcing);
            let (m, k, p) = parts(&mut model);
            let arena = &mut model.arena;
            let f: Vec<ExprId> = k.iter().zip(&p).map(|(a, b)| arena.plus(*a, *b)).collect();
            let raw = cost(arena, &m, &f);
            let cm: Vec<ExprId> = m.iter().map(|&e| compact(arena, e)).collect();
            let cf: Vec<ExprId> = f.iter().map(|&e| compact(arena, e)).collect();
            let compacted = cost(arena, &cm, &cf);
            assert!(
                chosen <= raw && chosen <= compacted,
                "{}: {chosen} vs {raw} as derived, {compacted} compacted",
                path.display()
            );
            if chosen < compacted {
                cheaper_than_compact.push(path.file_stem().unwrap().to_string_lossy().to_string());
            }
        }
        assert!(
            cheaper_than_compact.iter().any(|m| m.starts_with("spring")),
            "{cheaper_than_compact:?}"
        );
    }
}
