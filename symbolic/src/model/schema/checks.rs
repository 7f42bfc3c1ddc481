//! `checks:` — the reference values a model file states about itself (hand-written
//! equations of motion, natural frequencies, a period, a final state, conserved quantities,
//! drifts), one reader per key from one table ([`CHECKS`]).

use super::walk::{Fields, Keyed, Need};
use super::write::{NotRewritten, Writer, flow, list};
use super::*;

/// How one key of `checks:` is read into [`Checks`].
struct CheckKey {
    /// The key.
    key: &'static str,
    /// Reads the entry `key: value` into the checks.
    read: fn(&mut Ctx<'_>, &Located<String>, &YamlNode, &mut Checks),
}

/// Every key of `checks:`, in the order of [`CHECK_KEYS`].
const CHECKS: &[CheckKey] = &[
    CheckKey {
        key: "equations_of_motion",
        read: |cx, _, v, checks| checks.equations_of_motion = cx.hand_equations(v),
    },
    CheckKey {
        key: "natural_frequencies",
        read: |cx, k, v, checks| checks.natural_frequencies = cx.modal_check(k, v),
    },
    CheckKey {
        key: "damping_ratios",
        read: |cx, k, v, checks| checks.damping_ratios = cx.modal_check(k, v),
    },
    CheckKey {
        key: "period",
        read: |cx, k, v, checks| checks.period = cx.period_check(k, v),
    },
    CheckKey {
        key: "final_state",
        read: |cx, k, v, checks| checks.final_state = cx.final_state_check(k, v),
    },
    CheckKey {
        key: "conserved",
        read: |cx, _, v, checks| checks.conserved = cx.conserved_checks(v),
    },
    CheckKey {
        key: "energy_drift",
        read: |cx, k, v, checks| {
            checks.energy_drift = cx.drift_check(k, v, DEFAULT_ENERGY_DRIFT);
        },
    },
    CheckKey {
        key: "constraint_drift",
        read: |cx, k, v, checks| {
            checks.constraint_drift = cx.drift_check(k, v, DEFAULT_CONSTRAINT_DRIFT);
        },
    },
];

/// The keys of `natural_frequencies:` and `damping_ratios:`.
const MODAL_CHECK: Fields = Fields {
    kind: "check",
    keys: &[
        ("at", Need::Optional),
        ("values", Need::Required),
        ("tolerance", Need::Optional),
    ],
    example: "{ at: hanging, values: [sqrt(g/l)], tolerance: 1e-9 }",
};

/// The keys of `period:`.
const PERIOD_CHECK: Fields = Fields {
    kind: "check",
    keys: &[
        ("event", Need::Required),
        ("value", Need::Required),
        ("tolerance", Need::Optional),
        ("method", Need::Optional),
        ("rtol", Need::Optional),
        ("t_end", Need::Optional),
    ],
    example: "{ event: return, value: 2*pi*sqrt(l/g), tolerance: 1e-9 }",
};

/// The keys of `final_state:`.
const FINAL_STATE_CHECK: Fields = Fields {
    kind: "check",
    keys: &[
        ("t", Need::Required),
        ("values", Need::Required),
        ("tolerance", Need::Optional),
        ("method", Need::Optional),
        ("rtol", Need::Optional),
    ],
    example: "{ t: 2, values: { x: 1, x_dot: 0 }, tolerance: 1e-9 }",
};

/// The keys of `energy_drift:` and `constraint_drift:`.
const DRIFT_CHECK: Fields = Fields {
    kind: "check",
    keys: &[
        ("max", Need::Optional),
        ("method", Need::Optional),
        ("rtol", Need::Optional),
        ("t_end", Need::Optional),
    ],
    example: "{ max: 1e-9, method: dop853, rtol: 1e-12, t_end: 10 }",
};

/// The keys of a conserved quantity written as a map.
const CONSERVED: Fields = Fields {
    kind: "conserved quantity",
    keys: &[("value", Need::Required), ("tolerance", Need::Optional)],
    example: "{ value: m*x_dot, tolerance: 1e-9 }",
};

impl Ctx<'_> {
    /// `checks:` — reports its unknown keys and reads each known one with its reader from
    /// [`CHECKS`], in file order.
    pub(super) fn checks(&mut self, node: &YamlNode) -> Checks {
        const EXAMPLE: &str =
            "checks:\n  natural_frequencies: { at: hanging, values: [sqrt(g/l)] }";
        let mut checks = Checks::default();
        let Some(entries) = self.map(node, "`checks`", EXAMPLE) else {
            return checks;
        };
        self.unknown_keys(entries, "`checks`", CHECK_KEYS, CHECK_KEYS);
        for (k, v) in entries {
            if let Some(check) = CHECKS.iter().find(|c| c.key == k.value) {
                (check.read)(self, k, v, &mut checks);
            }
        }
        checks
    }

    /// `equations_of_motion:` — a list of `lhs = rhs`, the equations that are read.
    fn hand_equations(&mut self, node: &YamlNode) -> Vec<HandEquation> {
        let Some(list) = self.seq(
            node,
            "`equations_of_motion`",
            "equations_of_motion: [m*x_ddot + k*x = 0]",
        ) else {
            return Vec::new();
        };
        list.iter().filter_map(|item| self.equation(item)).collect()
    }

    /// `method:`, `rtol:` and `t_end:` of a check, each optional.
    pub(super) fn run_settings(&mut self, f: &Entries, what: &str) -> Option<RunSettings> {
        let method = match get(f, "method") {
            None => Some(None),
            Some(n) => {
                let options: Vec<(&str, usize)> = CHECK_METHODS
                    .iter()
                    .enumerate()
                    .map(|(i, m)| (*m, i))
                    .collect();
                self.choice(n, &format!("`method` of {what}"), &options)
                    .map(|i| Some(Located::new(CHECK_METHODS[i].to_string(), n.location)))
            }
        };
        let rtol = match get(f, "rtol") {
            None => Some(None),
            Some(n) => self
                .positive_number(n, &format!("`rtol` of {what}"))
                .map(Some),
        };
        let t_end = match get(f, "t_end") {
            None => Some(None),
            Some(n) => self
                .positive_number(n, &format!("`t_end` of {what}"))
                .map(Some),
        };
        Some(RunSettings {
            method: method?,
            rtol: rtol?,
            t_end: t_end?,
        })
    }

    /// `natural_frequencies:` or `damping_ratios:` — `{ at, values, tolerance }`.
    pub(super) fn modal_check(&mut self, k: &Located<String>, v: &YamlNode) -> Option<ModalCheck> {
        let what = format!("check `{}`", k.value);
        let f = self.fields(k, v, &MODAL_CHECK)?;
        let at = match get(f, "at") {
            None => Some(None),
            Some(n) => self.name(n, &format!("`at` of {what}")).map(Some),
        };
        let values = get(f, "values")
            .and_then(|n| self.expr_list(n, &format!("`values` of {what}"), "values: [sqrt(g/l)]"));
        let tolerance = self.number_or(f, "tolerance", &what, DEFAULT_CHECK_TOLERANCE);
        Some(ModalCheck {
            at: at?,
            values: values?,
            tolerance: tolerance?,
            location: k.location,
        })
    }

    /// `period:` — `{ event, value, tolerance, method, rtol, t_end }`.
    pub(super) fn period_check(
        &mut self,
        k: &Located<String>,
        v: &YamlNode,
    ) -> Option<PeriodCheck> {
        let what = format!("check `{}`", k.value);
        let f = self.fields(k, v, &PERIOD_CHECK)?;
        let event = get(f, "event").and_then(|n| self.name(n, &format!("`event` of {what}")));
        let value = get(f, "value").and_then(|n| self.expr(n, &format!("`value` of {what}")));
        let tolerance = self.number_or(f, "tolerance", &what, DEFAULT_CHECK_TOLERANCE);
        let run = self.run_settings(f, &what);
        Some(PeriodCheck {
            event: event?,
            value: value?,
            tolerance: tolerance?,
            run: run?,
            location: k.location,
        })
    }

    /// `final_state:` — `{ t, values: { x: …, x_dot: … }, tolerance, method, rtol }`.
    pub(super) fn final_state_check(
        &mut self,
        k: &Located<String>,
        v: &YamlNode,
    ) -> Option<FinalStateCheck> {
        let what = format!("check `{}`", k.value);
        let f = self.fields(k, v, &FINAL_STATE_CHECK)?;
        let t = get(f, "t").and_then(|n| self.expr(n, &format!("`t` of {what}")));
        let values = get(f, "values").and_then(|n| {
            self.keyed_exprs(
                n,
                &format!("`values` of {what}"),
                "values: { x: 1, x_dot: 0 }",
                "an expected value",
            )
            .into()
        });
        let tolerance = self.number_or(f, "tolerance", &what, DEFAULT_CHECK_TOLERANCE);
        let run = self.run_settings(f, &what);
        Some(FinalStateCheck {
            t: t?,
            values: values?,
            tolerance: tolerance?,
            run: run?,
            location: k.location,
        })
    }

    /// `conserved:` — `name: expr` or `name: { value: expr, tolerance: 1e-9 }`.
    pub(super) fn conserved_checks(&mut self, node: &YamlNode) -> Vec<ConservedCheck> {
        let spec = Keyed {
            what: "`conserved`",
            example: "conserved: { momentum: (m1 + m2)*x_dot }",
            names: Some("conserved quantity"),
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let what = format!("conserved quantity `{}`", k.value);
            if !matches!(v.kind, YamlKind::Map(_)) {
                let value = cx.expr(v, &what)?;
                return Some(ConservedCheck {
                    name: k.clone(),
                    value,
                    tolerance: DEFAULT_CHECK_TOLERANCE,
                });
            }
            let f = cx.fields(k, v, &CONSERVED)?;
            let value = get(f, "value").and_then(|n| cx.expr(n, &what));
            let tolerance = cx.number_or(f, "tolerance", &what, DEFAULT_CHECK_TOLERANCE);
            Some(ConservedCheck {
                name: k.clone(),
                value: value?,
                tolerance: tolerance?,
            })
        })
    }

    /// `energy_drift:` or `constraint_drift:` — `{ max, method, rtol, t_end }`.
    pub(super) fn drift_check(
        &mut self,
        k: &Located<String>,
        v: &YamlNode,
        default: f64,
    ) -> Option<DriftCheck> {
        let what = format!("check `{}`", k.value);
        let f = self.fields(k, v, &DRIFT_CHECK)?;
        let max = self.number_or(f, "max", &what, default);
        let run = self.run_settings(f, &what);
        Some(DriftCheck {
            max: max?,
            run: run?,
            location: k.location,
        })
    }

    /// One `lhs = rhs` equation (or an expression meaning `= 0`).
    pub(super) fn equation(&mut self, node: &YamlNode) -> Option<HandEquation> {
        let (lhs, rhs) = self.sides(
            node,
            "an equation of motion",
            "write one equation per entry, such as `m*x_ddot + k*x = F`",
        )?;
        Some(HandEquation {
            lhs,
            rhs,
            location: node.location,
        })
    }
}

/// The writer of `checks:`: the reference values that still apply to what is written.
impl Writer<'_> {
    /// `checks:`, after the equilibria and events it may name; `equations_of_motion` is
    /// left out (noted), and so is each value whose equilibrium or event is.
    pub(super) fn write_checks(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        let c = &file.checks;
        let mut block = String::new();
        if !c.equations_of_motion.is_empty() {
            self.notes.push(if self.preserve() {
                "`checks: equations_of_motion` left out".to_string()
            } else {
                "`checks: equations_of_motion` left out (written in the eliminated coordinates)"
                    .to_string()
            });
        }
        self.modal_checks(&mut block, file);
        self.run_checks(&mut block, c);
        if !c.conserved.is_empty() {
            let mut conserved = String::new();
            for q in &c.conserved {
                let place = format!("conserved quantity `{}`", q.name.value);
                let v = self.expr(&q.value, &place)?;
                conserved.push_str(&format!(
                    "    {}: {{ value: {}, tolerance: {:e} }}\n",
                    q.name.value,
                    flow(&v),
                    q.tolerance
                ));
            }
            block.push_str("  conserved:\n");
            block.push_str(&conserved);
        }
        if let Some(d) = &c.energy_drift {
            block.push_str(&format!(
                "  energy_drift: {{ max: {:e}{} }}\n",
                d.max,
                run_settings(&d.run, true)
            ));
        }
        match &c.constraint_drift {
            Some(d) if self.preserve() => block.push_str(&format!(
                "  constraint_drift: {{ max: {:e}{} }}\n",
                d.max,
                run_settings(&d.run, true)
            )),
            Some(_) => self
                .notes
                .push("`checks: constraint_drift` left out (no constraints)".to_string()),
            None => {}
        }
        self.block("checks", &block);
        Ok(())
    }

    /// `natural_frequencies` and `damping_ratios` into `block` when their equilibrium is
    /// written (the first one when they name none), noting each left out.
    fn modal_checks(&mut self, block: &mut String, file: &ModelFile) {
        let c = &file.checks;
        let first_written = file
            .equilibria
            .first()
            .is_none_or(|e| self.kept_equilibria.contains(&e.name.value));
        for (key, modal) in [
            ("natural_frequencies", &c.natural_frequencies),
            ("damping_ratios", &c.damping_ratios),
        ] {
            let Some(m) = modal else { continue };
            let written = match &m.at {
                Some(a) => self.kept_equilibria.contains(&a.value),
                None => first_written,
            };
            if !written {
                self.notes.push(format!(
                    "`checks: {key}` left out: its equilibrium is left out"
                ));
                continue;
            }
            let values: Vec<String> = m.values.iter().map(|e| e.to_string()).collect();
            block.push_str(&format!("  {key}: {{ "));
            if let Some(a) = &m.at {
                block.push_str(&format!("at: {}, ", a.value));
            }
            block.push_str(&format!(
                "values: {}, tolerance: {:e} }}\n",
                list(&values),
                m.tolerance
            ));
        }
    }

    /// The `period` (when its event is written) and the `final_state` (its values of the
    /// kept coordinates and rates) into `block`, noting what is left out.
    fn run_checks(&mut self, block: &mut String, c: &Checks) {
        if let Some(p) = &c.period {
            if self.kept_events.contains(&p.event.value) {
                block.push_str(&format!(
                    "  period: {{ event: {}, value: {}, tolerance: {:e}{} }}\n",
                    p.event.value,
                    flow(&p.value.to_string()),
                    p.tolerance,
                    run_settings(&p.run, true)
                ));
            } else {
                self.notes
                    .push("`checks: period` left out: its event is left out".to_string());
            }
        }
        if let Some(f) = &c.final_state {
            let values: Vec<String> = f
                .values
                .iter()
                .filter(|(n, _)| self.is_kept_name(&n.value))
                .map(|(n, e)| format!("{}: {}", n.value, flow(&e.to_string())))
                .collect();
            if values.len() < f.values.len() {
                self.notes.push(
                    "`checks: final_state` keeps only the values of the kept coordinates"
                        .to_string(),
                );
            }
            if !values.is_empty() {
                block.push_str(&format!(
                    "  final_state: {{ t: {}, values: {{ {} }}, tolerance: {:e}{} }}\n",
                    flow(&f.t.to_string()),
                    values.join(", "),
                    f.tolerance,
                    run_settings(&f.run, false)
                ));
            }
        }
    }
}

/// `, method: …, rtol: …, t_end: …` of the settings given.
fn run_settings(run: &RunSettings, t_end: bool) -> String {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The readers of `checks:` are those of the keys listed to the user, in the same order.
    #[test]
    fn every_check_key_has_one_reader() {
        let read: Vec<&str> = CHECKS.iter().map(|c| c.key).collect();
        assert_eq!(read, CHECK_KEYS);
    }
}
