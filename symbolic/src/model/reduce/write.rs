//! The reduced model file's text: every section rewritten in the kept coordinates, with its header
//! of eliminations, and the `checks:` that carry over.

use super::*;

impl Reducer<'_> {
    /// The reduced file's YAML text.
    pub(super) fn write(
        &mut self,
        name: &str,
        kept: &[String],
        eliminations: &[Elimination],
        initial: &[(String, Expr)],
        notes: &mut Vec<String>,
    ) -> Result<String, ReduceError> {
        use std::fmt::Write as _;
        let plan = Plan {
            name,
            kept,
            eliminations,
            initial,
            // A file written as it is ([`write_model`]) keeps its constraints and twin.
            preserve: eliminations.is_empty(),
        };
        let mut w = String::new();
        if !plan.preserve {
            self.write_header(&mut w, &plan)?;
        }
        self.write_identity(&mut w, &plan, notes)?;
        self.write_energies(&mut w, &plan)?;
        self.write_mechanism(&mut w)?;
        self.write_loads(&mut w)?;
        self.write_outputs_and_constraints(&mut w, &plan, notes)?;
        self.write_initial_and_draw(&mut w, &plan, notes)?;
        let kept_equilibria = self.write_equilibria(&mut w, &plan, notes)?;
        let kept_events = self.write_events(&mut w, notes)?;
        if !self.file.floquet.is_empty() {
            notes.push("`floquet:` left out".to_string());
        }
        let checks = self.checks(&kept_equilibria, &kept_events, kept, plan.preserve, notes)?;
        if !checks.is_empty() {
            let _ = writeln!(w, "checks:");
            w.push_str(&checks);
        }
        Ok(w)
    }

    /// The header of a reduced file: each elimination, its branch and where the kept
    /// coordinates no longer determine an eliminated one.
    fn write_header(&mut self, w: &mut String, p: &Plan<'_>) -> Result<(), ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        let kept = p.kept;
        let eliminations = p.eliminations;
        let preserve = p.preserve;
        // Header.
        if !preserve {
            let _ = writeln!(
                w,
                "# `{}` reduced to the coordinates {} by eliminating the holonomic constraints",
                file.name.value,
                kept.join(", ")
            );
            let _ = writeln!(
                w,
                "# (method II.2, lectures 8-10, HW13; written by `eomgen reduce`):"
            );
            for e in eliminations {
                let how = match &e.branch {
                    None => String::new(),
                    Some((b, BranchReason::Option)) => format!(", branch {} as asked", b.sign()),
                    Some((b, BranchReason::InitialState)) => {
                        format!(", branch {} of the initial state", b.sign())
                    }
                    Some((b, BranchReason::Equilibrium(q))) => {
                        format!(", branch {} of the equilibrium `{q}`", b.sign())
                    }
                };
                let _ = writeln!(
                    w,
                    "#   {} = {}  (from `{}`{how})",
                    e.coordinate, e.solution, e.constraint
                );
                let _ = writeln!(w, "#   {}_dot = {}", e.coordinate, e.rate);
            }
            for (coordinate, e, event) in self.moving_singularities() {
                let _ = writeln!(
                    w,
                    "#   singular where {e} = 0: the kept coordinates do not determine {coordinate} there{}",
                    if event.is_some() {
                        format!(" (event `{coordinate}_singular` ends runs)")
                    } else {
                        String::new()
                    }
                );
            }
        }
        Ok(())
    }

    /// `name:` … `coordinates:`: the model's name, description, units, twin, parameters and the
    /// kept coordinates.
    fn write_identity(
        &mut self,
        w: &mut String,
        p: &Plan<'_>,
        notes: &mut Vec<String>,
    ) -> Result<(), ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        let name = p.name;
        let kept = p.kept;
        let preserve = p.preserve;
        let is_kept = |n: &str| p.is_kept(n);
        let _ = writeln!(w, "name: {name}");
        let description = if preserve {
            file.description.clone()
        } else {
            format!(
                "{} Reduced to {} (constraints eliminated).",
                file.description.trim_end(),
                kept.join(", ")
            )
        };
        let _ = writeln!(w, "description: {}", scalar(&description));
        if file.units.is_some() {
            let _ = writeln!(w, "units: SI");
        }
        if let Some(twin) = file.minimal_twin.as_ref().filter(|_| preserve) {
            let _ = writeln!(w, "minimal_twin: {}", twin.value);
        } else if file.minimal_twin.is_some() {
            notes.push("`minimal_twin:` left out (the reduced model is minimal)".to_string());
        }
        if !file.parameters.is_empty() {
            let _ = writeln!(w, "parameters:");
            for p in &file.parameters {
                let _ = write!(w, "  {}: {}", p.name.value, scalar(&p.default.to_string()));
                match &p.unit {
                    Some(u) => {
                        let _ = writeln!(w, "  # {}", u.value);
                    }
                    None => w.push('\n'),
                }
            }
        }
        let _ = writeln!(w, "coordinates:");
        for c in file.coordinates.iter().filter(|c| is_kept(&c.name.value)) {
            match (&c.unit, &c.comment) {
                (Some(u), _) => {
                    let _ = writeln!(w, "  - {{ name: {}, unit: {} }}", c.name.value, u.value);
                }
                (None, Some(comment)) => {
                    let _ = writeln!(w, "  - {}  # {}", c.name.value, comment.trim());
                }
                (None, None) => {
                    let _ = writeln!(w, "  - {}", c.name.value);
                }
            }
        }
        Ok(())
    }

    /// `kinetic:`, `potential:` and `generalized_forces:`, rewritten in the kept coordinates.
    fn write_energies(&mut self, w: &mut String, p: &Plan<'_>) -> Result<(), ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        let kept = p.kept;
        if let Some(t) = &file.kinetic {
            let t = self.rewrite(t, "`kinetic:`")?;
            let _ = writeln!(w, "kinetic: {}", scalar(&t));
        }
        if let Some(v) = &file.potential {
            let v = self.rewrite(v, "`potential:`")?;
            let _ = writeln!(w, "potential: {}", scalar(&v));
        }
        if !file.generalized_forces.is_empty() {
            let forces = self.generalized_forces(kept)?;
            if !forces.is_empty() {
                let _ = writeln!(w, "generalized_forces:");
                for (k, q) in forces {
                    let _ = writeln!(w, "  {k}: {}", scalar(&q));
                }
            }
        }
        Ok(())
    }

    /// `points:`, `bodies:` and `gravity:`.
    fn write_mechanism(&mut self, w: &mut String) -> Result<(), ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        self.write_frames(w)?;
        if !file.points.is_empty() {
            let _ = writeln!(w, "points:");
            for p in &file.points {
                let text = self.point_text(p)?;
                let _ = writeln!(w, "  {}: {text}", p.name.value);
            }
        }
        if !file.bodies.is_empty() {
            let _ = writeln!(w, "bodies:");
            for b in &file.bodies {
                let place = format!("body `{}`", b.name.value);
                match &b.kind {
                    BodyKind::Particle { mass, at } => {
                        let m = self.rewrite(mass, &place)?;
                        let _ = writeln!(
                            w,
                            "  {}: {{ mass: {}, at: {} }}",
                            b.name.value,
                            flow(&m),
                            at.value
                        );
                    }
                    BodyKind::Rigid {
                        mass,
                        inertia,
                        com,
                        angle,
                    } => {
                        let m = self.rewrite(mass, &place)?;
                        let i = self.rewrite(inertia, &place)?;
                        let a = self.rewrite(angle, &place)?;
                        let _ = writeln!(
                            w,
                            "  {}: {{ mass: {}, inertia: {}, com: {}, angle: {} }}",
                            b.name.value,
                            flow(&m),
                            flow(&i),
                            com.value,
                            flow(&a)
                        );
                    }
                    BodyKind::Spatial {
                        mass,
                        com,
                        frame,
                        inertia,
                    } => {
                        let text = self
                            .spatial_body_text(&place, (mass, &com.value, &frame.value, inertia))?;
                        let _ = writeln!(w, "  {}: {text}", b.name.value);
                    }
                }
            }
        }
        if let Some(g) = &file.gravity {
            let parts = g
                .value
                .iter()
                .map(|e| self.rewrite(e, "`gravity:`"))
                .collect::<Result<Vec<_>, _>>()?;
            let _ = writeln!(w, "gravity: {}", list(&parts));
        }
        Ok(())
    }

    /// `springs:` and `dampers:`, then [`Self::write_forces_and_torques`].
    fn write_loads(&mut self, w: &mut String) -> Result<(), ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        if !file.springs.is_empty() {
            let _ = writeln!(w, "springs:");
            for s in &file.springs {
                let place = format!("spring `{}`", s.name.value);
                let k = self.rewrite(&s.stiffness, &place)?;
                let _ = write!(
                    w,
                    "  {}: {{ between: [{}, {}], stiffness: {}",
                    s.name.value,
                    s.between[0].value,
                    s.between[1].value,
                    flow(&k)
                );
                if let Some(l0) = &s.rest_length {
                    let l0 = self.rewrite(l0, &place)?;
                    let _ = write!(w, ", rest_length: {}", flow(&l0));
                }
                let _ = writeln!(w, " }}");
            }
        }
        if !file.dampers.is_empty() {
            let _ = writeln!(w, "dampers:");
            for d in &file.dampers {
                let place = format!("damper `{}`", d.name.value);
                let c = self.rewrite(&d.coefficient, &place)?;
                let _ = writeln!(
                    w,
                    "  {}: {{ between: [{}, {}], coefficient: {} }}",
                    d.name.value,
                    d.between[0].value,
                    d.between[1].value,
                    flow(&c)
                );
            }
        }
        self.write_forces_and_torques(w)
    }

    /// `forces:` and `torques:` (3-D ones and those written in frames included) and
    /// `interactions:`.
    fn write_forces_and_torques(&mut self, w: &mut String) -> Result<(), ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        if !file.forces.is_empty() {
            let _ = writeln!(w, "forces:");
            for f in &file.forces {
                let place = format!("force `{}`", f.name.value);
                let parts = f
                    .vector
                    .iter()
                    .map(|e| self.rewrite(e, &place))
                    .collect::<Result<Vec<_>, _>>()?;
                let _ = writeln!(
                    w,
                    "  {}: {{ at: {}, vector: {}{} }}",
                    f.name.value,
                    f.at.value,
                    list(&parts),
                    spatial::in_frame(f.frame.as_ref())
                );
            }
        }
        if !file.torques.is_empty() {
            let _ = writeln!(w, "torques:");
            for t in &file.torques {
                let place = format!("torque `{}`", t.name.value);
                match &t.value {
                    TorqueValue::Planar(e) => {
                        let v = self.rewrite(e, &place)?;
                        let _ = writeln!(
                            w,
                            "  {}: {{ body: {}, value: {} }}",
                            t.name.value,
                            t.body.value,
                            flow(&v)
                        );
                    }
                    TorqueValue::Spatial { vector, frame, .. } => {
                        let parts = vector
                            .iter()
                            .map(|e| self.rewrite(e, &place))
                            .collect::<Result<Vec<_>, _>>()?;
                        let _ = writeln!(
                            w,
                            "  {}: {{ body: {}, vector: {}{} }}",
                            t.name.value,
                            t.body.value,
                            list(&parts),
                            spatial::in_frame(frame.as_ref())
                        );
                    }
                }
            }
        }
        if !file.interactions.is_empty() {
            let _ = writeln!(w, "interactions:");
            for f in &file.interactions {
                let place = format!("interaction `{}`", f.name.value);
                let magnitude = self.rewrite(&f.magnitude, &place)?;
                let _ = writeln!(
                    w,
                    "  {}: {{ between: [{}, {}], magnitude: {} }}",
                    f.name.value,
                    f.between[0].value,
                    f.between[1].value,
                    flow(&magnitude)
                );
            }
        }
        Ok(())
    }

    /// `outputs:`, and the constraints of a file written as it is (`balances:` is left out).
    fn write_outputs_and_constraints(
        &mut self,
        w: &mut String,
        p: &Plan<'_>,
        notes: &mut Vec<String>,
    ) -> Result<(), ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        let eliminations = p.eliminations;
        let preserve = p.preserve;
        if !file.outputs.is_empty() {
            let mut block = String::new();
            for o in &file.outputs {
                let place = format!("output `{}`", o.name.value);
                match self.rewrite(&o.value, &place) {
                    Ok(v) if o.conserved => {
                        let _ = writeln!(
                            block,
                            "  {}: {{ value: {}, conserved: true, tolerance: {:e} }}",
                            o.name.value,
                            flow(&v),
                            o.tolerance
                        );
                    }
                    Ok(v) => {
                        let _ = writeln!(block, "  {}: {}", o.name.value, scalar(&v));
                    }
                    Err(e) => notes.push(format!("output `{}` left out: {e}", o.name.value)),
                }
            }
            if !block.is_empty() {
                let _ = writeln!(w, "outputs:");
                w.push_str(&block);
            }
        }
        if !file.balances.is_empty() {
            notes.push(
                "`balances:` left out: the reduced model is derived by Lagrange's equations"
                    .to_string(),
            );
        }
        if preserve && !(file.constraints.is_empty() && file.point_constraints.is_empty()) {
            let _ = writeln!(w, "constraints:");
            for (name, e) in &file.constraints {
                let _ = writeln!(w, "  {}: {}", name.value, scalar(&e.to_string()));
            }
            self.point_constraint_lines(w);
        }
        if preserve {
            self.write_nonholonomic(w)?;
        }
        if !preserve {
            notes.push(format!(
                "`constraints:` eliminated: {}",
                eliminations
                    .iter()
                    .map(|e| format!("`{}` gives {}", e.constraint, e.coordinate))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        Ok(())
    }

    /// `initial:` (the kept coordinates' values and rates) and `draw:`.
    fn write_initial_and_draw(
        &mut self,
        w: &mut String,
        p: &Plan<'_>,
        notes: &mut Vec<String>,
    ) -> Result<(), ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        let initial = p.initial;
        let preserve = p.preserve;
        let is_kept = |n: &str| p.is_kept(n);
        let is_kept_name = |n: &str| p.is_kept_name(n);
        // Initial values.
        if !initial.is_empty() {
            let parts: Vec<String> = initial
                .iter()
                .map(|(n, e)| {
                    if preserve && file.initial_guesses.iter().any(|g| g.value == *n) {
                        format!("{n}: {{ guess: {} }}", flow(&e.to_string()))
                    } else {
                        format!("{n}: {}", flow(&e.to_string()))
                    }
                })
                .collect();
            let _ = writeln!(w, "initial: {{ {} }}", parts.join(", "));
        }
        let dropped: Vec<&str> = file
            .initial
            .iter()
            .map(|(n, _)| n.value.as_str())
            .filter(|n| !is_kept_name(n))
            .collect();
        if dropped.iter().any(|n| n.ends_with("_dot")) {
            notes.push(format!(
                "the initial rates of eliminated coordinates ({}) are left out: the kept rates \
                 alone set the motion",
                dropped
                    .iter()
                    .filter(|n| n.ends_with("_dot"))
                    .copied()
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        if !preserve && file.initial_guesses.iter().any(|g| is_kept(&g.value)) {
            notes.push(
                "a kept coordinate's initial value was a guess; the reduced file starts at \
                 the guess"
                    .to_string(),
            );
        }
        // Drawing.
        let wheels = self.drawn_wheels()?;
        if !file.draw.lines.is_empty() || !file.draw.trace.is_empty() || wheels.is_some() {
            let lines: Vec<String> = file
                .draw
                .lines
                .iter()
                .map(|[a, b]| format!("[{}, {}]", a.value, b.value))
                .collect();
            let trace: Vec<&str> = file.draw.trace.iter().map(|p| p.value.as_str()).collect();
            let mut parts = Vec::new();
            if !lines.is_empty() {
                parts.push(format!("lines: [{}]", lines.join(", ")));
            }
            if !trace.is_empty() {
                parts.push(format!("trace: [{}]", trace.join(", ")));
            }
            parts.extend(wheels);
            let _ = writeln!(w, "draw: {{ {} }}", parts.join(", "));
        }
        Ok(())
    }

    /// `equilibria:` on the chosen branches; returns the names of those kept.
    fn write_equilibria(
        &mut self,
        w: &mut String,
        p: &Plan<'_>,
        notes: &mut Vec<String>,
    ) -> Result<Vec<String>, ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        let is_kept = |n: &str| p.is_kept(n);
        let is_kept_name = |n: &str| p.is_kept_name(n);
        // Equilibria on the chosen branches.
        let mut kept_equilibria: Vec<String> = Vec::new();
        let mut equilibria = String::new();
        for eq in &file.equilibria {
            if let Some(off) = self.off_branch(&eq.values) {
                notes.push(format!(
                    "equilibrium `{}` left out: it is not on the chosen branch ({off})",
                    eq.name.value
                ));
                continue;
            }
            if let Some(singular) = self.singular_at(&eq.values) {
                notes.push(format!(
                    "equilibrium `{}` left out: the reduced coordinates are singular there ({singular})",
                    eq.name.value
                ));
                continue;
            }
            let mut parts: Vec<String> = eq
                .values
                .iter()
                .filter(|(n, _)| is_kept_name(&n.value))
                .map(|(n, e)| format!("{}: {}", n.value, flow(&e.to_string())))
                .collect();
            let ignorable: Vec<&str> = eq
                .ignorable
                .iter()
                .map(|n| n.value.as_str())
                .filter(|n| is_kept(n))
                .collect();
            if !ignorable.is_empty() {
                parts.push(format!("ignorable: [{}]", ignorable.join(", ")));
            }
            let _ = writeln!(
                equilibria,
                "  {}: {{ {} }}",
                eq.name.value,
                parts.join(", ")
            );
            kept_equilibria.push(eq.name.value.clone());
        }
        if !equilibria.is_empty() {
            let _ = writeln!(w, "equilibria:");
            w.push_str(&equilibria);
        }
        Ok(kept_equilibria)
    }

    /// `events:`: the file's, rewritten, and one that ends runs where a linear solution's slope
    /// crosses 0; returns the names of those kept.
    fn write_events(
        &mut self,
        w: &mut String,
        notes: &mut Vec<String>,
    ) -> Result<Vec<String>, ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        // Events: the file's, rewritten, and one that ends runs where a linear solution's
        // slope crosses 0.
        let mut kept_events: Vec<String> = Vec::new();
        let mut events = String::new();
        for (coordinate, e, event) in self.moving_singularities() {
            let name = format!("{coordinate}_singular");
            notes.push(format!(
                "the reduced model is singular where {e} = 0 (`{coordinate}` is solved by dividing by it, or by a square root of it): the kept coordinates do not determine `{coordinate}` there, and the motion past it is not unique{}",
                if event.is_some() {
                    format!("; the event `{name}` ends runs there")
                } else {
                    "; a run that reaches it fails there".to_string()
                }
            ));
            if let Some(when) = event
                && !file.events.iter().any(|ev| ev.name.value == name)
            {
                let _ = writeln!(
                    events,
                    "  {name}: {{ when: {}, direction: both, terminal: true }}",
                    flow(&when)
                );
            }
        }
        for ev in &file.events {
            let place = format!("event `{}`", ev.name.value);
            match self.rewrite(&ev.when, &place) {
                Ok(g) => {
                    let _ = writeln!(
                        events,
                        "  {}: {{ when: {}, direction: {}, terminal: {} }}",
                        ev.name.value,
                        flow(&g),
                        match ev.direction {
                            Crossing::Rising => "rising",
                            Crossing::Falling => "falling",
                            Crossing::Both => "both",
                        },
                        ev.terminal
                    );
                    kept_events.push(ev.name.value.clone());
                }
                Err(e) => notes.push(format!("event `{}` left out: {e}", ev.name.value)),
            }
        }
        if !events.is_empty() {
            let _ = writeln!(w, "events:");
            w.push_str(&events);
        }
        Ok(kept_events)
    }

    /// The energy form's generalized forces moved onto the kept coordinates by virtual work:
    /// `Q_k + Σ_d Q_d ∂d/∂k`.
    fn generalized_forces(
        &mut self,
        kept: &[String],
    ) -> Result<Vec<(String, String)>, ReduceError> {
        let mut by_coordinate: Vec<(usize, ExprId)> = Vec::new();
        for (name, e) in &self.file.generalized_forces {
            let place = format!("generalized force `{}`", name.value);
            let q = self.lower_in(e, &place)?;
            if let Some(i) = self
                .file
                .coordinates
                .iter()
                .position(|c| c.name.value == name.value)
            {
                by_coordinate.push((i, q));
            }
        }
        let mut out = Vec::new();
        for (k, c) in self.file.coordinates.iter().enumerate() {
            if !kept.contains(&c.name.value) {
                continue;
            }
            let xk = self.coordinates[k][0];
            let mut terms = Vec::new();
            for &(i, q) in &by_coordinate {
                if i == k {
                    terms.push(q);
                } else if let Some(&root) = self.values.get(&self.coordinates[i][0]) {
                    let partial = self.arena.diff(root, xk);
                    terms.push(self.arena.times(q, partial));
                }
            }
            if terms.is_empty() {
                continue;
            }
            let sum = self.arena.sum(&terms);
            let sum = self.arena.substitute(sum, &self.values);
            let sum = self.arena.expand_if_cheaper(sum);
            if !self.arena.is_zero(sum) {
                out.push((c.name.value.clone(), self.print(sum)));
            }
        }
        Ok(out)
    }

    /// The `checks:` block of the reduced file: the reference values that still apply.
    pub(super) fn checks(
        &mut self,
        equilibria: &[String],
        events: &[String],
        kept: &[String],
        preserve: bool,
        notes: &mut Vec<String>,
    ) -> Result<String, ReduceError> {
        use std::fmt::Write as _;
        let c = &self.file.checks;
        let mut w = String::new();
        if !c.equations_of_motion.is_empty() {
            notes.push(if preserve {
                "`checks: equations_of_motion` left out".to_string()
            } else {
                "`checks: equations_of_motion` left out (written in the eliminated coordinates)"
                    .to_string()
            });
        }
        self.write_modal_checks(&mut w, equilibria, notes);
        self.write_run_checks(&mut w, events, kept, notes);
        if !c.conserved.is_empty() {
            let mut block = String::new();
            for q in &c.conserved {
                let place = format!("conserved quantity `{}`", q.name.value);
                let v = self.rewrite(&q.value, &place)?;
                let _ = writeln!(
                    block,
                    "    {}: {{ value: {}, tolerance: {:e} }}",
                    q.name.value,
                    flow(&v),
                    q.tolerance
                );
            }
            let _ = writeln!(w, "  conserved:");
            w.push_str(&block);
        }
        if let Some(d) = &c.energy_drift {
            let _ = writeln!(
                w,
                "  energy_drift: {{ max: {:e}{} }}",
                d.max,
                run_settings(&d.run, true)
            );
        }
        if let Some(d) = c.constraint_drift.as_ref().filter(|_| preserve) {
            let _ = writeln!(
                w,
                "  constraint_drift: {{ max: {:e}{} }}",
                d.max,
                run_settings(&d.run, true)
            );
        } else if c.constraint_drift.is_some() {
            notes.push("`checks: constraint_drift` left out (no constraints)".to_string());
        }
        Ok(w)
    }

    /// Writes `natural_frequencies` and `damping_ratios` of `checks:` into `w` when their
    /// equilibrium is kept (the first one when they name none), noting each left out.
    fn write_modal_checks(&self, w: &mut String, equilibria: &[String], notes: &mut Vec<String>) {
        use std::fmt::Write as _;
        let c = &self.file.checks;
        let first_kept = self
            .file
            .equilibria
            .first()
            .is_none_or(|e| equilibria.contains(&e.name.value));
        for (key, modal) in [
            ("natural_frequencies", &c.natural_frequencies),
            ("damping_ratios", &c.damping_ratios),
        ] {
            let Some(m) = modal else { continue };
            let at_ok = match &m.at {
                Some(a) => equilibria.contains(&a.value),
                None => first_kept,
            };
            if !at_ok {
                notes.push(format!(
                    "`checks: {key}` left out: its equilibrium is left out"
                ));
                continue;
            }
            let values: Vec<String> = m.values.iter().map(|e| e.to_string()).collect();
            let _ = write!(w, "  {key}: {{ ");
            if let Some(a) = &m.at {
                let _ = write!(w, "at: {}, ", a.value);
            }
            let _ = writeln!(
                w,
                "values: {}, tolerance: {:e} }}",
                list(&values),
                m.tolerance
            );
        }
    }

    /// Writes the `period` (when its event is kept) and the `final_state` (its values of the
    /// kept coordinates and rates) of `checks:` into `w`, noting what is left out.
    fn write_run_checks(
        &self,
        w: &mut String,
        events: &[String],
        kept: &[String],
        notes: &mut Vec<String>,
    ) {
        use std::fmt::Write as _;
        let c = &self.file.checks;
        if let Some(p) = &c.period {
            if events.contains(&p.event.value) {
                let _ = writeln!(
                    w,
                    "  period: {{ event: {}, value: {}, tolerance: {:e}{} }}",
                    p.event.value,
                    flow(&p.value.to_string()),
                    p.tolerance,
                    run_settings(&p.run, true)
                );
            } else {
                notes.push("`checks: period` left out: its event is left out".to_string());
            }
        }
        if let Some(f) = &c.final_state {
            let is_kept_name = |n: &str| {
                kept.iter()
                    .any(|k| k == n || n.strip_suffix("_dot") == Some(k.as_str()))
            };
            let values: Vec<String> = f
                .values
                .iter()
                .filter(|(n, _)| is_kept_name(&n.value))
                .map(|(n, e)| format!("{}: {}", n.value, flow(&e.to_string())))
                .collect();
            if values.len() < f.values.len() {
                notes.push(
                    "`checks: final_state` keeps only the values of the kept coordinates"
                        .to_string(),
                );
            }
            if !values.is_empty() {
                let _ = writeln!(
                    w,
                    "  final_state: {{ t: {}, values: {{ {} }}, tolerance: {:e}{} }}",
                    flow(&f.t.to_string()),
                    values.join(", "),
                    f.tolerance,
                    run_settings(&f.run, false)
                );
            }
        }
    }
}

/// `, method: …, rtol: …, t_end: …` of the settings given.
fn run_settings(run: &crate::model::checks::RunSettings, t_end: bool) -> String {
    let mut s = String::new();
    if let Some(m) = &run.method {
        s.push_str(&format!(", method: {}", m.value));
    }
    if let Some(r) = run.rtol {
        s.push_str(&format!(", rtol: {r:e}"));
    }
    if t_end && let Some(t) = run.t_end {
        s.push_str(&format!(", t_end: {t:e}"));
    }
    s
}

/// What writing one file needs beside the reducer: its name, the coordinates kept, the
/// eliminations and initial values, and whether it is written as it is (nothing eliminated).
struct Plan<'a> {
    name: &'a str,
    kept: &'a [String],
    eliminations: &'a [Elimination],
    initial: &'a [(String, Expr)],
    preserve: bool,
}

impl Plan<'_> {
    /// Whether `n` is a kept coordinate.
    fn is_kept(&self, n: &str) -> bool {
        self.kept.iter().any(|k| k == n)
    }

    /// Whether `n` is a kept coordinate or its rate.
    fn is_kept_name(&self, n: &str) -> bool {
        self.is_kept(n) || n.strip_suffix("_dot").is_some_and(|c| self.is_kept(c))
    }
}
