//! The lowering of the loads: `interactions:`, `springs:`, `dampers:`, `forces:` and `torques:`,
//! each into its `LoadInfo` and its part of `V` or `Q`.

use super::*;
use crate::model::elements::torque::TorqueInfo;

impl Lowering<'_> {
    /// `interactions:` — equal and opposite forces `f e` on `B` and `−f e` on `A` along
    /// `e = d/r`, `d = r_B − r_A`, `r = |d|`, `ṙ = d·ḋ/r`. A magnitude that is a sum of
    /// powers of `r` times factors constant in the motion (parameters, `t`) is integrated to
    /// a potential, `V(r) = −∫ f dr` (`−c ln r` for `c/r`), so that `T + V` stays the
    /// energy; any other enters `Q` as `Qᵢ = f d·∂d/∂qᵢ / r` (its virtual work `f e·δd`).
    /// Either way momentum balance gets the two forces at the points.
    ///
    /// Returns the loads and, per interaction, `(r, f)` at the points' positions, for the
    /// check of the initial state.
    pub(super) fn interactions(
        &mut self,
        points: &Points,
        q_symbols: &[SymbolId],
        terms: &mut Terms,
    ) -> (Vec<LoadInfo>, Vec<(ExprId, ExprId)>) {
        let mut loads = Vec::new();
        let mut at_start = Vec::new();
        if self.file.interactions.is_empty() {
            return (loads, at_start);
        }
        // Names no model symbol can have (a space is not in a name), substituted away below.
        let r_symbol = self.arena.declare("interaction r", SymbolKind::Auxiliary);
        let rdot_symbol = self
            .arena
            .declare("interaction r_dot", SymbolKind::Auxiliary);
        for it in &self.file.interactions {
            let (Some(a), Some(b)) = (
                point(points, &it.between[0].value),
                point(points, &it.between[1].value),
            ) else {
                self.errors.push(Diagnostic::new(
                    it.name.location,
                    format!("interaction `{}` names an unknown point", it.name.value),
                ));
                continue;
            };
            let d = self.difference(&points[b].1, &points[a].1);
            let dd: Vec<ExprId> = d.iter().map(|c| self.arena.time_derivative(*c)).collect();
            let d2 = self.dot(&d, &d);
            let r = self.arena.sqrt(d2);
            let d_dd = self.dot(&d, &dd);
            let rdot = self.arena.divide(d_dd, r);
            let (r_local, rdot_local) = (
                self.arena.symbol_expr(r_symbol),
                self.arena.symbol_expr(rdot_symbol),
            );
            self.locals = vec![
                ("r".to_string(), r_local),
                ("r_dot".to_string(), rdot_local),
            ];
            let f_of_r = self.expr(&it.magnitude);
            self.locals.clear();
            let mut values = FxHashMap::default();
            values.insert(r_symbol, r);
            values.insert(rdot_symbol, rdot);
            let f = self.arena.substitute(f_of_r, &values);
            // f e on B, −f e on A.
            let scale = self.arena.divide(f, r);
            let on_b: Vec<ExprId> = d.iter().map(|c| self.arena.times(scale, *c)).collect();
            let on_a: Vec<ExprId> = on_b.iter().map(|c| self.arena.neg(*c)).collect();
            loads.push(LoadInfo::Force {
                point: b,
                vector: on_b,
            });
            loads.push(LoadInfo::Force {
                point: a,
                vector: on_a,
            });
            at_start.push((r, f));
            match self.power_law_potential(f_of_r, r_symbol, rdot_symbol) {
                Some(v_of_r) => {
                    let v = self.arena.substitute(v_of_r, &values);
                    terms.potential.push(v);
                }
                None => {
                    for (i, qs) in q_symbols.iter().enumerate() {
                        let partial: Vec<ExprId> =
                            d.iter().map(|x| self.arena.diff(*x, *qs)).collect();
                        let proj = self.dot(&d, &partial);
                        if !self.arena.is_zero(proj) {
                            terms.forces[i].push(self.arena.times(scale, proj));
                        }
                    }
                }
            }
        }
        (loads, at_start)
    }

    /// `V(r) = −∫ f dr` of a magnitude `f` that is a sum of terms `c rᵏ`, `k` a number and
    /// `c` free of `r`, `ṙ`, the coordinates and the rates: `−c r^(k+1)/(k+1)`, or `−c ln r`
    /// for `k = −1`. `None` for any other magnitude (it is not, or not visibly, the
    /// derivative of a potential of `r`).
    fn power_law_potential(
        &mut self,
        f: ExprId,
        r_symbol: SymbolId,
        rdot_symbol: SymbolId,
    ) -> Option<ExprId> {
        use crate::expr::Node;
        if self.arena.depends_on(f, rdot_symbol) {
            return None;
        }
        let motion: Vec<SymbolId> = self
            .arena
            .coordinates()
            .iter()
            .flat_map(|c| [c[0], c[1]])
            .collect();
        let f = self.arena.expand(f);
        let terms: Vec<ExprId> = match self.arena.node(f) {
            Node::Add(ts) => ts.to_vec(),
            _ => vec![f],
        };
        let mut potential = Vec::new();
        for term in terms {
            let factors: Vec<ExprId> = match self.arena.node(term) {
                Node::Mul(fs) => fs.to_vec(),
                _ => vec![term],
            };
            let mut power = vec![self.arena.int(0)];
            let mut coefficient = Vec::new();
            for factor in factors {
                if !self.arena.depends_on(factor, r_symbol) {
                    if motion.iter().any(|s| self.arena.depends_on(factor, *s)) {
                        return None;
                    }
                    coefficient.push(factor);
                    continue;
                }
                match self.arena.node(factor).clone() {
                    Node::Symbol(s) if s == r_symbol => power.push(self.arena.int(1)),
                    Node::Pow([base, exponent])
                        if matches!(self.arena.node(base), Node::Symbol(s) if *s == r_symbol)
                            && self.arena.as_constant(exponent).is_some() =>
                    {
                        power.push(exponent);
                    }
                    _ => return None,
                }
            }
            let c = self.arena.product(&coefficient);
            let k = self.arena.sum(&power);
            let one = self.arena.int(1);
            let k1 = self.arena.plus(k, one);
            let r = self.arena.symbol_expr(r_symbol);
            let integral = if self.arena.is_zero(k1) {
                let ln = self.arena.func(Func::Ln, r);
                self.arena.times(c, ln)
            } else {
                let rk1 = self.arena.pow(r, k1);
                let crk1 = self.arena.times(c, rk1);
                self.arena.divide(crk1, k1)
            };
            potential.push(self.arena.neg(integral));
        }
        Some(self.arena.sum(&potential))
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
