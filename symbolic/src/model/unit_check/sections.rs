//! The equations of dimension each section of the file states: energies, loads, constraints,
//! events, outputs and `checks:`, walked in file order.

use super::*;
use crate::model::elements::{self, body, energy, frame, gravity, point, shape};
use crate::model::located::Located;

impl Checker<'_> {
    /// Checks `e` against the unit its key requires; a value written with numbers only is
    /// in that unit.
    pub(super) fn key(
        &mut self,
        e: &Expr,
        want: Option<Dim>,
        what: &str,
        report: impl FnOnce(Dimension, Dimension) -> Diagnostic,
    ) {
        if numbers_only(e) {
            return;
        }
        self.top(e);
        let got = self.dim(e, what);
        self.require(got.as_ref(), want.as_ref(), (KEY, what, e.location), report);
    }

    /// Checks `e` against a fixed unit: "`what` is got, but `kind` is want_text" with `help`,
    /// plus the parameter's declaration when `e` is a lone parameter.
    fn fixed(
        &mut self,
        e: &Expr,
        want: Dimension,
        what: &str,
        kind: &str,
        want_text: &str,
        help: &str,
    ) {
        let lone = match &e.kind {
            ExprKind::Ident(n) => self.file.parameters.iter().find(|p| &p.name.value == n),
            _ => None,
        };
        let spelling = want_text.split(" (").next().unwrap_or(want_text);
        let advice = match lone {
            Some(p) => format!(
                "{help}; if `{n}` is one, declare it so: `{n}: {}  # {spelling}`",
                write_expr(&p.default, 0),
                n = p.name.value
            ),
            None => help.to_string(),
        };
        let at = e.location;
        self.spelling = lone.map(|_| spelling.to_string());
        self.key(e, Some(Dim::of(want)), what, |got, _| {
            Diagnostic::new(
                at,
                format!("{what} is {}, but {kind} is {want_text}", show(got)),
            )
            .with_help(advice)
        });
        self.spelling = None;
    }

    /// Checks a value of coordinate `name` or of its rate (`initial:`, `equilibria:`,
    /// `final_state:`).
    fn value_of(&mut self, name: &str, e: &Expr, what: &str) {
        let Some(want) = self.motion(name).flatten() else {
            return;
        };
        let at = e.location;
        let name = name.to_string();
        self.key(e, Some(want), what, |got, want| {
            Diagnostic::new(
                at,
                format!(
                    "{what} is {}, but `{name}` is {}",
                    show(got),
                    show_coordinate(want)
                ),
            )
            .with_help(format!(
                "write it in the unit of `{name}`, or fix the units of its parameters"
            ))
        });
    }

    /// Checks that `e` is consistent in itself (its sums, functions and powers).
    fn homogeneous(&mut self, e: &Expr, what: &str) {
        self.top(e);
        self.dim(e, what);
    }

    /// Both passes visit every expression of the file in the same order.
    // Long: one piece (about 100 lines): a list, one call per place in the file where an
    // expression stands, with the dimension it must have and how the message names it. Both
    // passes rely on this one order; split by section it would only be a longer list.
    pub(super) fn walk(&mut self) {
        let file = self.file;
        // A speed's unit is its definition's (`omega_B_x`: 1/s).
        self.speeds.clear();
        for sp in &file.speeds {
            self.top(&sp.value);
            let unit = self.dim(&sp.value, &format!("speed `{}`", sp.name.value));
            self.speeds.push((sp.name.value.clone(), unit));
        }
        energy::units(file.written_energies(), self);
        point::units(&file.points, self);
        frame::units(&file.frames, self);
        body::units(&file.bodies, self);
        if let Some(g) = &file.gravity {
            gravity::units(g, self);
        }
        for s in &file.springs {
            s.units(self);
        }
        for d in &file.dampers {
            d.units(self);
        }
        for f in &file.forces {
            f.units(self);
        }
        for i in &file.interactions {
            i.units(self);
        }
        for o in &file.outputs {
            self.homogeneous(&o.value, &format!("output `{}`", o.name.value));
        }
        for t in &file.torques {
            t.units(self);
        }
        shape::units(&file.draw.shapes, self);
        self.constraints.clear();
        for (holonomic, list) in [(true, &file.constraints), (false, &file.nonholonomic)] {
            for (k, e) in list {
                self.top(e);
                let unit = self.dim(e, &format!("constraint `{}`", k.value));
                self.constraints.push((k.value.clone(), unit, holonomic));
            }
        }
        // A constraint on a point is a length (m), a rolling contact's rows velocities (m/s).
        for c in &file.point_constraints {
            let length = Dim::of(Dimension::METRE);
            self.constraints
                .push((c.name.value.clone(), Some(length), true));
        }
        for r in &file.rolling {
            for k in r.constraint_names() {
                let velocity = Dim::of(Dimension::integers(1, 0, -1));
                self.constraints.push((k.value, Some(velocity), false));
            }
        }
        for c in &file.contacts {
            c.units(self);
        }
        for (k, e) in &file.initial {
            self.value_of(&k.value, e, &format!("the initial value of `{}`", k.value));
        }
        for q in &file.equilibria {
            for (c, e) in &q.values {
                self.value_of(
                    &c.value,
                    e,
                    &format!("`{}` of equilibrium `{}`", c.value, q.name.value),
                );
            }
        }
        for e in &file.events {
            self.homogeneous(
                &e.when,
                &format!("the function of event `{}`", e.name.value),
            );
        }
        for b in &file.balances {
            if let BalanceKind::Lmb { along } = &b.kind {
                for e in along {
                    self.homogeneous(e, "`along`");
                }
            }
        }
        self.checks();
    }

    pub(super) fn checks(&mut self) {
        let checks = &self.file.checks;
        for (i, eq) in checks.equations_of_motion.iter().enumerate() {
            let what = format!("equation of motion {}", i + 1);
            self.top(&eq.lhs);
            let lhs = self.dim(&eq.lhs, &what);
            let Some(rhs_expr) = &eq.rhs else { continue };
            if self.mode == Mode::Report {
                let mut ids = Vec::new();
                identifiers(rhs_expr, &mut ids);
                self.names.extend(ids.into_iter().map(|(n, _)| n));
            }
            let rhs = self.dim(rhs_expr, &what);
            if numbers_only(&eq.lhs) || numbers_only(rhs_expr) {
                continue;
            }
            let (l, r, at) = (text(&eq.lhs), text(rhs_expr), rhs_expr.location);
            self.require(rhs.as_ref(), lhs.as_ref(), (HOMOGENEITY, &what, at), |got, want| {
                Diagnostic::new(
                    at,
                    format!(
                        "the sides of {what} have unlike units: `{l}` is {} but `{r}` is {}",
                        show(want),
                        show(got)
                    ),
                )
                .with_help("both sides are a generalized force of one coordinate: N for a length, N*m for an angle")
            });
        }
        for (key, check, want, want_text) in [
            (
                "natural_frequencies",
                &checks.natural_frequencies,
                Dimension::FREQUENCY,
                "rad/s",
            ),
            (
                "damping_ratios",
                &checks.damping_ratios,
                Dimension::ONE,
                "1",
            ),
        ] {
            let Some(check) = check else { continue };
            for v in &check.values {
                self.fixed(
                    v,
                    want,
                    &format!("a value of `{key}`"),
                    "it",
                    want_text,
                    "natural frequencies are in rad/s, as in `sqrt(k/m)`; damping ratios are pure numbers, as in `c/(2*sqrt(k*m))`",
                );
            }
        }
        if let Some(p) = &checks.period {
            self.fixed(
                &p.value,
                Dimension::SECOND,
                "the `value` of `period`",
                "a period",
                "s",
                "a period is a time, as in `2*pi*sqrt(l/g)`",
            );
        }
        if let Some(state) = &checks.final_state {
            self.fixed(
                &state.t,
                Dimension::SECOND,
                "the time `t` of `final_state`",
                "a time",
                "s",
                "`t` is the time of the state, in s",
            );
            for (k, v) in &state.values {
                self.value_of(
                    &k.value,
                    v,
                    &format!("the value of `{}` in `final_state`", k.value),
                );
            }
        }
        for c in &checks.conserved {
            self.homogeneous(&c.value, &format!("conserved quantity `{}`", c.name.value));
        }
    }
}

/// The unit check as an element's context ([`elements::Units`]).
impl elements::Units for Checker<'_> {
    fn fixed(
        &mut self,
        e: &Expr,
        want: Dimension,
        what: &str,
        kind: &str,
        want_text: &str,
        help: &str,
    ) {
        Checker::fixed(self, e, want, what, kind, want_text, help);
    }
    fn generalized_force(&mut self, k: &Located<String>, q: &Expr) {
        let j = Dimension::JOULE;
        let Some(coordinate) = self.motion(&k.value).flatten() else {
            self.homogeneous(q, &format!("the generalized force of `{}`", k.value));
            return;
        };
        let want = Dim::of(j).div(&coordinate);
        let (name, at) = (k.value.clone(), q.location);
        let what = format!("the generalized force of `{name}`");
        self.key(q, want, &what, |got, want| {
            Diagnostic::new(
                at,
                format!(
                    "{what} is {}, but `{name}` is {}, so it must be {}",
                    show(got),
                    show_coordinate(j.checked_div(want).unwrap_or(Dimension::ONE)),
                    show_load(want)
                ),
            )
            .with_help(format!(
                "the virtual work `Q δ{name}` is an energy (J), so a generalized force is J per unit of its coordinate: N for a length, N*m for an angle"
            ))
        });
    }
    fn distance(&mut self, on: bool) {
        self.interaction = on;
    }
}
