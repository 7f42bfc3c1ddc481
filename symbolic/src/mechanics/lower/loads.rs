//! The lowering of the loads: `interactions:`, `springs:`, `dampers:`, `forces:` and `torques:`,
//! each into its `LoadInfo` and its part of `V` or `Q`.

use super::*;
use crate::model::elements::interaction::{self, InteractionTerms};
use crate::model::elements::torque::TorqueInfo;

impl Lowering<'_> {
    /// Interactions (`elements::interaction`): their two forces for momentum balance, a power
    /// law's potential into `V`, any other magnitude's generalized forces into `Q`, and
    /// `(r, f)` of each for [`Self::check_interactions_at_start`].
    pub(super) fn interactions(
        &mut self,
        terms: &mut Terms,
    ) -> (Vec<LoadInfo>, Vec<(ExprId, ExprId)>) {
        let file = self.file;
        let mut loads = Vec::new();
        let mut at_start = Vec::new();
        for it in interaction::lower(self, &file.interactions) {
            let [a, b] = it.between;
            loads.push(LoadInfo::Force {
                point: b,
                vector: it.on_b,
            });
            loads.push(LoadInfo::Force {
                point: a,
                vector: it.on_a,
            });
            at_start.push(it.at_start);
            match it.lagrange {
                InteractionTerms::Potential(v) => terms.potential.push(v),
                InteractionTerms::Forces(forces) => {
                    for (terms, q) in terms.forces.iter_mut().zip(forces) {
                        terms.extend(q);
                    }
                }
            }
        }
        (loads, at_start)
    }

    /// Reports an interaction whose points coincide at the initial state (`r = 0`: no
    /// direction), or whose magnitude is not a finite number there; the parameters at
    /// their defaults.
    pub(super) fn check_interactions_at_start(
        &mut self,
        at_start: &[(ExprId, ExprId)],
        parameters: &[ParameterInfo],
        initial: (&[ExprId], &[ExprId]),
    ) {
        if at_start.is_empty() {
            return;
        }
        let mut bindings = vec![0.0; self.arena.symbols().len()];
        for p in parameters {
            bindings[p.symbol.index()] = p.default;
        }
        let starts: Vec<ExprId> = initial.0.iter().chain(initial.1).copied().collect();
        let start = crate::expr::eval::Evaluator::new(&self.arena, &starts).eval(&bindings);
        let n = initial.0.len();
        for (i, s) in self.arena.symbols().iter().enumerate() {
            match s.kind {
                SymbolKind::Coordinate(k) => bindings[i] = start[k as usize],
                SymbolKind::Velocity(k) => bindings[i] = start[n + k as usize],
                _ => {}
            }
        }
        let roots: Vec<ExprId> = at_start.iter().flat_map(|(r, f)| [*r, *f]).collect();
        let values = crate::expr::eval::Evaluator::new(&self.arena, &roots).eval(&bindings);
        for (it, v) in self.file.interactions.iter().zip(values.chunks(2)) {
            let (r, f) = (v[0], v[1]);
            let [a, b] = &it.between;
            if r == 0.0 {
                self.errors.push(
                    Diagnostic::new(
                        b.location,
                        format!(
                            "the points `{}` and `{}` of interaction `{}` coincide at the initial state (r = 0): the line of its force is undefined there",
                            a.value, b.value, it.name.value
                        ),
                    )
                    .with_help("start the points apart (`initial:`), or check their positions under `points:`"),
                );
            } else if !f.is_finite() && r.is_finite() {
                self.errors.push(
                    Diagnostic::new(
                        it.magnitude.location,
                        format!(
                            "the magnitude of interaction `{}` is {f} at the initial state (r = {})",
                            it.name.value,
                            short(r)
                        ),
                    )
                    .with_help("a magnitude must be a finite number where the motion starts; check the formula and the initial state"),
                );
            }
        }
    }

    /// Springs (`elements::spring`): their potentials into `V`.
    pub(super) fn springs(&mut self, terms: &mut Terms) -> Vec<LoadInfo> {
        let file = self.file;
        let mut loads = Vec::new();
        for s in file.springs.iter().filter_map(|s| s.lower(self)) {
            terms.potential.push(s.potential);
            loads.push(LoadInfo::Spring {
                between: s.between,
                stiffness: s.stiffness,
                rest_length: s.rest_length,
            });
        }
        loads
    }

    /// Dampers (`elements::damper`): their generalized forces into `Q`.
    pub(super) fn dampers(&mut self, terms: &mut Terms) -> Vec<LoadInfo> {
        let file = self.file;
        let mut loads = Vec::new();
        for d in file.dampers.iter().filter_map(|d| d.lower(self)) {
            for (forces, q) in terms.forces.iter_mut().zip(d.generalized_forces) {
                forces.extend(q);
            }
            loads.push(LoadInfo::Damper {
                between: d.between,
                coefficient: d.coefficient,
            });
        }
        loads
    }

    /// Forces at points (`elements::force`): their generalized forces into `Q`.
    pub(super) fn forces(&mut self, terms: &mut Terms) -> Vec<LoadInfo> {
        let file = self.file;
        let mut loads = Vec::new();
        for f in file.forces.iter().filter_map(|f| f.lower(self)) {
            loads.push(LoadInfo::Force {
                point: f.point,
                vector: f.vector,
            });
            for (forces, q) in terms.forces.iter_mut().zip(f.generalized_forces) {
                forces.extend(q);
            }
        }
        loads
    }

    /// Torques on rigid bodies (`elements::torque`): their generalized forces into `Q`.
    pub(super) fn torques(&mut self, terms: &mut Terms) -> Vec<LoadInfo> {
        let file = self.file;
        let mut loads = Vec::new();
        for t in file.torques.iter().filter_map(|t| t.lower(self)) {
            for (forces, q) in terms.forces.iter_mut().zip(t.generalized_forces()) {
                forces.extend(*q);
            }
            loads.push(match t {
                TorqueInfo::Planar {
                    body, angle, value, ..
                } => LoadInfo::Torque { body, angle, value },
                TorqueInfo::Spatial { body, vector, .. } => {
                    LoadInfo::SpatialTorque { body, vector }
                }
            });
        }
        loads
    }
}
