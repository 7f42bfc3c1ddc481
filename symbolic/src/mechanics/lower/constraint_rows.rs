//! The lowering of `constraints:` and `nonholonomic:`: their rows, derivatives and the checks that
//! they are independent, linear in the rates and workless.

use super::*;
use crate::model::elements::{constraint, nonholonomic};

impl Lowering<'_> {
    /// Lowers `constraints:` and `nonholonomic:`, differentiates them, and reports a
    /// non-holonomic constraint that is not linear in the rates and constraints that are
    /// redundant (dependent Jacobian rows at every sampled configuration).
    pub(super) fn constraints(
        &mut self,
        file: &ModelFile,
        parameters: &[ParameterInfo],
    ) -> ConstraintEquations {
        let before = self.errors.len();
        let holonomic = constraint::rows(&file.constraints, &file.point_constraints, self);
        let nonholonomic = nonholonomic::rows(&file.nonholonomic, &file.rolling, self);
        if holonomic.is_empty() && nonholonomic.is_empty() {
            return ConstraintEquations::default();
        }
        let symbols: Vec<[SymbolId; 3]> = self.arena.coordinates().to_vec();
        for ((k, _), (_, g)) in file.nonholonomic.iter().zip(&nonholonomic) {
            if !linear_in_rates(&mut self.arena, *g, &symbols) {
                self.errors.push(
                    Diagnostic::new(k.location, format!("non-holonomic constraint `{}` is not linear in the rates", k.value))
                        .with_help("write it as A(q, t) q̇ + b(q, t) = 0: each `x_dot` to the first power, times a function of q and t"),
                );
            }
        }
        let eqs = ConstraintEquations::derive(&mut self.arena, &symbols, &holonomic, &nonholonomic);
        // (More constraints than coordinates is the loader's error; after an error in the
        // constraints themselves the rank test would only repeat it. An error elsewhere does
        // not stop it: every diagnostic at once.)
        if self.errors.len() > before {
            return eqs;
        }
        let samples = self.jacobian_samples(&eqs, parameters);
        self.report_dependent_rows(file, &eqs, parameters, &samples);
        eqs
    }

    /// The constraint Jacobian `J` evaluated at up to six random configurations where it is
    /// finite (of 60 tried; coordinates, rates and `t` uniform in `[−2, 2]`, parameters at
    /// their defaults), each row-major `m × n`.
    fn jacobian_samples(
        &mut self,
        eqs: &ConstraintEquations,
        parameters: &[ParameterInfo],
    ) -> Vec<Vec<f64>> {
        // Rank of J at a few random configurations (parameters at their defaults).
        let mut evaluator = crate::expr::eval::Evaluator::new(&self.arena, &eqs.jacobian);
        let mut rng = <rand::rngs::Xoshiro256PlusPlus as rand::SeedableRng>::seed_from_u64(
            0x9E37_79B9_7F4A_7C15,
        );
        let mut uniform = move || rand::RngExt::random_range(&mut rng, -2.0..2.0);
        let mut samples = Vec::new();
        for _ in 0..60 {
            if samples.len() == 6 {
                break;
            }
            let mut bindings = vec![0.0; self.arena.symbols().len()];
            for (i, s) in self.arena.symbols().iter().enumerate() {
                if s.kind != SymbolKind::Parameter {
                    bindings[i] = uniform();
                }
            }
            // Parameters at their defaults, by symbol (not a search by name per symbol).
            for p in parameters {
                bindings[p.symbol.index()] = p.default;
            }
            let values = evaluator.eval(&bindings).to_vec();
            if values.iter().all(|v| v.is_finite()) {
                samples.push(values);
            }
        }
        samples
    }

    /// Reports each constraint whose Jacobian row depends on the others' at every sampled
    /// configuration: contradictory where the others hold and it does not, else redundant.
    fn report_dependent_rows(
        &mut self,
        file: &ModelFile,
        eqs: &ConstraintEquations,
        parameters: &[ParameterInfo],
        samples: &[Vec<f64>],
    ) {
        let (m, n) = (eqs.len(), self.arena.coordinates().len());
        let all: Vec<Located<String>> = file.constraint_names();
        let dependent = redundant_rows(samples, m, n);
        let independent: Vec<usize> = (0..eqs.holonomic)
            .filter(|i| dependent.iter().all(|(d, _)| d != i))
            .collect();
        for (i, with) in dependent {
            let k = &all[i];
            let others: Vec<String> = with
                .iter()
                .map(|j| format!("`{}`", all[*j].value))
                .collect();
            // A holonomic constraint that repeats holonomic ones: redundant if it holds where
            // they hold, contradictory if not.
            // (The constraints it combines come before it, so they are holonomic too.)
            if i < eqs.holonomic
                && let Some(found) =
                    self.residual_where_others_hold(eqs, parameters, &independent, i)
                && found.contradicts()
            {
                let residual = found.residual;
                let message = if others.is_empty() {
                    format!(
                        "constraint `{}` can never hold: it does not depend on the coordinates, and it is {} (not 0)",
                        k.value,
                        short(residual)
                    )
                } else {
                    let hold = if others.len() == 1 { "holds" } else { "hold" };
                    format!(
                        "constraint `{}` contradicts {}: where {} {hold}, it is {} (not 0), so no configuration satisfies them all",
                        k.value,
                        others.join(", "),
                        others.join(" and "),
                        short(residual)
                    )
                };
                self.errors.push(Diagnostic::new(k.location, message).with_help(
                    "inconsistent constraints leave no motion to compute (with the parameters at their defaults); correct the value or remove the constraint",
                ));
                continue;
            }
            let message = if others.is_empty() {
                format!(
                    "constraint `{}` constrains nothing: its Jacobian row is zero",
                    k.value
                )
            } else {
                format!(
                    "constraint `{}` is redundant with {}: its Jacobian row is a combination of theirs at every configuration tried",
                    k.value,
                    others.join(", ")
                )
            };
            self.errors.push(
                Diagnostic::new(k.location, message)
                    .with_help("redundant constraints make the constraint forces indeterminate (the planar-loop trap); remove it"),
            );
        }
    }

    /// The residual of the dependent holonomic constraint `dependent` where the
    /// `independent` holonomic constraints hold (see
    /// [`crate::mechanics::constraints::residual_where_others_hold`]), from up to six random
    /// configurations at a random `t` (parameters at their defaults); `None` if Newton
    /// converges from none of them.
    fn residual_where_others_hold(
        &mut self,
        eqs: &ConstraintEquations,
        parameters: &[ParameterInfo],
        independent: &[usize],
        dependent: usize,
    ) -> Option<crate::mechanics::constraints::DependentResidual> {
        let n = self.arena.coordinates().len();
        let h = eqs.holonomic;
        let roots: Vec<ExprId> = eqs
            .phi
            .iter()
            .chain(&eqs.jacobian[..h * n])
            .copied()
            .collect();
        let mut evaluator = crate::expr::eval::Evaluator::new(&self.arena, &roots);
        let mut rng = <rand::rngs::Xoshiro256PlusPlus as rand::SeedableRng>::seed_from_u64(
            0xC0FF_EE15_5EED_1234,
        );
        let mut uniform = move || rand::RngExt::random_range(&mut rng, -2.0..2.0);
        let symbols = self.arena.symbols().to_vec();
        // Random values for t (and the rates, unused), the parameters' defaults.
        let mut bindings: Vec<f64> = symbols.iter().map(|_| uniform()).collect();
        for p in parameters {
            bindings[p.symbol.index()] = p.default;
        }
        let slots: Vec<usize> = (0..n)
            .map(|c| {
                symbols
                    .iter()
                    .position(|s| s.kind == SymbolKind::Coordinate(c as u32))
                    .unwrap_or(usize::MAX)
            })
            .collect();
        for _ in 0..6 {
            let q0: Vec<f64> = (0..n).map(|_| uniform()).collect();
            let mut eval = |q: &[f64]| {
                for (slot, v) in slots.iter().zip(q) {
                    if let Some(b) = bindings.get_mut(*slot) {
                        *b = *v;
                    }
                }
                let values = evaluator.eval(&bindings);
                (values[..h].to_vec(), values[h..].to_vec())
            };
            if let Some(r) = crate::mechanics::constraints::residual_where_others_hold(
                &mut eval,
                &q0,
                independent,
                dependent,
            ) {
                return Some(r);
            }
        }
        None
    }

    /// Whether `T` is a quadratic form in the rates (`T₀ = T(q, 0, t)` and
    /// `T₁ = ∂T/∂q̇ (q, 0, t)` vanish): otherwise, as for a point carried by a prescribed
    /// motion (`r cos ωt`), `T + V` is not conserved even without explicit `t` in `T` (the
    /// Jacobi integral `T₂ − T₀ + V` is).
    pub(super) fn kinetic_is_quadratic_in_rates(&mut self, kinetic: ExprId) -> bool {
        let symbols: Vec<[SymbolId; 3]> = self.arena.coordinates().to_vec();
        let zero = self.arena.int(0);
        let at_rest: FxHashMap<SymbolId, ExprId> = symbols.iter().map(|s| (s[1], zero)).collect();
        let mut parts = vec![kinetic];
        parts.extend(symbols.iter().map(|s| self.arena.diff(kinetic, s[1])));
        parts.into_iter().all(|p| {
            let p = self.arena.substitute(p, &at_rest);
            if self.arena.is_zero(p) {
                return true;
            }
            let p = self.arena.expand(p);
            self.arena.is_zero(p)
        })
    }

    /// Whether the constraint forces do no work on the motion: no holonomic `Φ` depends on
    /// `t` (the power of the constraint forces is `λᵀ Φ_t`) and every non-holonomic
    /// constraint has `b = 0` (power `−λᵀ b`). A rod spun at a prescribed rate drives its
    /// bead, and `T + V` is then not conserved.
    pub(super) fn constraints_are_workless(&mut self, c: &ConstraintEquations) -> bool {
        let time = self.arena.time_id();
        let symbols: Vec<[SymbolId; 3]> = self.arena.coordinates().to_vec();
        let zero = self.arena.int(0);
        let at_rest: FxHashMap<SymbolId, ExprId> = symbols.iter().map(|s| (s[1], zero)).collect();
        c.phi.iter().all(|&phi| !self.arena.depends_on(phi, time))
            && c.velocity[c.holonomic..].iter().all(|&g| {
                let b = self.arena.substitute(g, &at_rest);
                let b = self.arena.expand(b);
                self.arena.is_zero(b)
            })
    }
}
