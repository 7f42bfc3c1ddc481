//! The lowering of the file's other sections: `balances:`, equations written by hand, `events:`,
//! `equilibria:` and `initial:`.

use super::*;

impl Lowering<'_> {
    /// The momentum balances chosen in `balances:`, with their points and bodies by index.
    pub(super) fn balances(
        &mut self,
        points: &Points,
        body_infos: &[BodyInfo],
        frames: &Frames,
    ) -> Vec<BalanceInfo> {
        let mut balances = Vec::new();
        for b in &self.file.balances {
            let bodies: Vec<usize> = b
                .bodies
                .iter()
                .filter_map(|name| body_infos.iter().position(|x| x.name == name.value))
                .collect();
            match &b.kind {
                crate::model::file::BalanceKind::Amb {
                    about,
                    form,
                    axis,
                    frame,
                } => {
                    // A 3-D axis, carried into the ground frame's components.
                    let axis = axis.as_ref().and_then(|axis| {
                        let [x, y, z] = &axis.value[..] else {
                            return None;
                        };
                        let e = [x, y, z].map(|c| self.expr(c));
                        let from = match frame {
                            Some(f) => frames.index(&f.value)?,
                            None => 0,
                        };
                        Some(frames.express(&mut self.arena, e, from, 0).to_vec())
                    });
                    match point(points, &about.value) {
                        Some(about) => balances.push(BalanceInfo::Amb {
                            about,
                            bodies,
                            form: *form,
                            axis,
                        }),
                        None => self.errors.push(Diagnostic::new(
                            about.location,
                            format!("unknown point `{}`", about.value),
                        )),
                    }
                }
                crate::model::file::BalanceKind::Lmb { along } => {
                    let along = along.iter().map(|e| self.expr(e)).collect();
                    balances.push(BalanceInfo::Lmb { along, bodies });
                }
            }
        }
        balances
    }

    /// The equations of motion written by hand in `checks:`, each as `lhs − rhs`; reports one
    /// that is not linear in the accelerations.
    pub(super) fn hand_equations(&mut self) -> Vec<ExprId> {
        let file = self.file;
        self.allow_accelerations = true;
        let hand_equations: Vec<ExprId> = file
            .checks
            .equations_of_motion
            .iter()
            .map(|e| {
                let lhs = self.expr(&e.lhs);
                match &e.rhs {
                    Some(rhs) => {
                        let rhs = self.expr(rhs);
                        self.arena.minus(lhs, rhs)
                    }
                    None => lhs,
                }
            })
            .collect();
        self.allow_accelerations = false;
        // Each must be linear in the accelerations: no coefficient of a q̈ⱼ may depend on one.
        let accelerations: Vec<SymbolId> = self.arena.coordinates().iter().map(|c| c[2]).collect();
        for (e, r) in file.checks.equations_of_motion.iter().zip(&hand_equations) {
            let nonlinear = accelerations.iter().any(|a| {
                let c = self.arena.diff(*r, *a);
                let c = self.arena.expand(c);
                accelerations.iter().any(|b| self.arena.depends_on(c, *b))
            });
            if nonlinear {
                self.errors.push(
                    Diagnostic::new(e.location, "this equation of motion is not linear in the accelerations")
                        .with_help("equations of motion are M(q, t) q̈ = f(q, q̇, t): each `x_ddot` appears only to the first power, times a function of q, q̇ and t"),
                );
            }
        }
        hand_equations
    }

    /// The events' functions, which may use the accelerations.
    pub(super) fn events(&mut self) -> Vec<EventInfo> {
        self.allow_accelerations = true;
        let events = self
            .file
            .events
            .iter()
            .map(|e| EventInfo {
                name: e.name.value.clone(),
                function: self.expr(&e.when),
                direction: e.direction,
                terminal: e.terminal,
            })
            .collect();
        self.allow_accelerations = false;
        events
    }

    /// The named equilibria, each a value per coordinate (0 for one it does not give), with
    /// the rates of a steady motion (0 where not given) and its ignorable coordinates.
    pub(super) fn equilibria(&mut self, coordinate_names: &[String]) -> Vec<Equilibrium> {
        self.file
            .equilibria
            .iter()
            .map(|q| {
                let mut guess = vec![self.arena.int(0); coordinate_names.len()];
                let mut rates = guess.clone();
                for (c, e) in &q.values {
                    let value = self.expr(e);
                    if let Some(i) = coordinate_names.iter().position(|x| *x == c.value) {
                        guess[i] = value;
                    } else if let Some(i) = coordinate_names
                        .iter()
                        .position(|x| c.value.strip_suffix("_dot") == Some(x.as_str()))
                    {
                        rates[i] = value;
                    }
                }
                let index = |c: &str| coordinate_names.iter().position(|x| *x == c);
                let indices = |names: &[Located<String>]| -> Vec<usize> {
                    names.iter().filter_map(|c| index(&c.value)).collect()
                };
                // A solved rate is named `q_dot`: the index of `q`.
                let rate_indices = |names: &[Located<String>]| -> Vec<usize> {
                    (names.iter())
                        .filter_map(|c| index(c.value.strip_suffix("_dot")?))
                        .collect()
                };
                let turning = q.turning.as_ref().and_then(|t| {
                    Some([
                        index(&t.angle.value)?,
                        index(&t.plane.first()?.value)?,
                        index(&t.plane.get(1)?.value)?,
                    ])
                });
                Equilibrium {
                    name: q.name.value.clone(),
                    guess,
                    rates,
                    ignorable: indices(&q.ignorable),
                    held: indices(&q.held),
                    solved: rate_indices(&q.solved),
                    turning,
                }
            })
            .collect()
    }

    /// The initial coordinates and rates of `initial:` (0 for one it does not give).
    pub(super) fn initial_state(
        &mut self,
        coordinate_names: &[String],
    ) -> (Vec<ExprId>, Vec<ExprId>) {
        let n = coordinate_names.len();
        let mut initial_q = vec![self.arena.int(0); n];
        let mut initial_qdot = vec![self.arena.int(0); n];
        for (name, value) in &self.file.initial {
            let e = self.expr(value);
            if let Some(i) = coordinate_names.iter().position(|c| *c == name.value) {
                initial_q[i] = e;
            } else if let Some(i) = coordinate_names
                .iter()
                .position(|c| name.value.strip_suffix("_dot") == Some(c.as_str()))
            {
                initial_qdot[i] = e;
            } else if !self.speeds.contains_key(&name.value) {
                self.errors.push(Diagnostic::new(
                    name.location,
                    format!("`{}` is neither a coordinate nor a rate", name.value),
                ));
            }
        }
        (initial_q, initial_qdot)
    }
}
