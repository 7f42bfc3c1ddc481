//! The momentum balances chosen for a model's equations (the model elements, points, frames,
//! bodies, constraints and loads among them: their modules in `model/elements/`).

use super::walk::{Fields, Need};
use super::write::{NotRewritten, Writer};
use super::*;
use crate::model::elements::read_in;

/// The names of the other derivations that `eomgen check` lists beside a named set of
/// balances, which a set may not take.
const RESERVED_SET_NAMES: [&str; 5] = ["lagrange", "momentum", "by_hand", "energy", "power"];

/// The keys of an angular momentum balance.
const AMB: Fields = Fields {
    kind: "angular momentum balance",
    keys: &[
        ("about", Need::Required),
        ("bodies", Need::Required),
        ("form", Need::Optional),
        ("axis", Need::Optional),
        ("in", Need::Optional),
    ],
    example: "{ about: O, bodies: [upper, fore] }",
};

/// The keys of a linear momentum balance.
const LMB: Fields = Fields {
    kind: "linear momentum balance",
    keys: &[("bodies", Need::Required), ("along", Need::Required)],
    example: "{ bodies: [slider], along: [cos(theta), sin(theta)] }",
};

impl Ctx<'_> {
    /// `balances:` — a list of `amb: { about, bodies, form }` (angular momentum balance) and
    /// `lmb: { bodies, along }` (linear momentum balance), one set; or a map of named sets,
    /// `{ NAME: [ … ], … }`, each such a list (several derivations of the same equations).
    pub(super) fn balances(&mut self, node: &YamlNode) -> Vec<Balance> {
        let YamlKind::Map(sets) = &node.kind else {
            return self.balance_list(node, None);
        };
        let mut out = Vec::new();
        for (name, value) in sets {
            // A set's name labels its derivation beside the others in `eomgen check`.
            if RESERVED_SET_NAMES.contains(&name.value.as_str()) {
                self.error(
                    Diagnostic::new(
                        name.location,
                        format!(
                            "`{}` names another derivation of the equations of motion; a set of balances needs its own name",
                            name.value
                        ),
                    )
                    .with_help(format!(
                        "`{}` are the other derivations' names; call the set after its form, such as `r_x_ma` or `about_E`",
                        RESERVED_SET_NAMES.join("`, `")
                    )),
                );
            }
            // `NAME: [...]`, or `NAME: { expect: disagree, balances: [...] }`.
            let (list, expect_disagreement) = match &value.kind {
                YamlKind::Map(entries) => {
                    let expect = entries.iter().find(|(k, _)| k.value == "expect");
                    let list = entries.iter().find(|(k, _)| k.value == "balances");
                    let unknown = entries
                        .iter()
                        .find(|(k, _)| !matches!(k.value.as_str(), "expect" | "balances"));
                    let disagree = expect.is_some_and(|(_, v)| {
                        matches!(&v.kind, YamlKind::Scalar { text, .. } if text == "disagree")
                    });
                    if let Some((k, _)) = unknown {
                        self.error(
                            Diagnostic::new(k.location, format!("unknown key `{}` in the set of balances `{}`", k.value, name.value))
                                .with_help("a set is a list of balances, or `{ expect: disagree, balances: [...] }` for a set kept to show a wrong form"),
                        );
                    }
                    if let Some((_, v)) = expect.filter(|_| !disagree) {
                        self.error(
                            Diagnostic::new(
                                v.location,
                                "`expect` of a set of balances is `disagree`",
                            )
                            .with_help(
                                "leave `expect` out for a set that must agree with Lagrange",
                            ),
                        );
                    }
                    let Some((_, list)) = list else {
                        self.error(
                            Diagnostic::new(name.location, format!("the set of balances `{}` has no `balances:` list", name.value))
                                .with_help("write `{ expect: disagree, balances: [ { amb: { about: E, bodies: [fore], form: h_dot } } ] }`"),
                        );
                        continue;
                    };
                    (list, disagree)
                }
                _ => (value, false),
            };
            let mut set = self.balance_list(list, Some(name.clone()));
            if matches!(&list.kind, YamlKind::Seq(items) if items.is_empty()) {
                self.error(
                    Diagnostic::new(
                        name.location,
                        format!("the set of balances `{}` is empty", name.value),
                    )
                    .with_help("a set gives one balance per coordinate; remove the set or list its balances"),
                );
            }
            for b in &mut set {
                b.expect_disagreement = expect_disagreement;
            }
            out.extend(set);
        }
        out
    }

    /// One set of balances, a list, as [`Self::balances`] reads it.
    fn balance_list(&mut self, node: &YamlNode, set: Option<Located<String>>) -> Vec<Balance> {
        const EXAMPLE: &str = "balances:\n  - { amb: { about: O, bodies: [upper, fore] } }\n  - { lmb: { bodies: [slider], along: [cos(theta), sin(theta)] } }";
        let Some(items) = self.seq(node, "`balances`", EXAMPLE) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for item in items {
            let Some(entries) = self.map(
                item,
                "a balance",
                "{ amb: { about: O, bodies: [upper, fore] } }",
            ) else {
                continue;
            };
            if entries.len() != 1 || !matches!(entries[0].0.value.as_str(), "amb" | "lmb") {
                self.error(
                    Diagnostic::new(item.location, "a balance is one of `amb: {…}` (angular momentum balance) or `lmb: {…}` (linear momentum balance)")
                        .with_help("write `{ amb: { about: O, bodies: [upper, fore] } }` or `{ lmb: { bodies: [slider], along: [1, 0] } }`"),
                );
                continue;
            }
            let (key, value) = &entries[0];
            let amb = key.value == "amb";
            let Some(f) = self.fields(key, value, if amb { &AMB } else { &LMB }) else {
                continue;
            };
            let mut bodies = Vec::new();
            if let Some(list) =
                get(f, "bodies").and_then(|n| self.seq(n, "`bodies`", "bodies: [upper, fore]"))
            {
                for b in list {
                    if let Some(name) = self.name(b, "a body") {
                        bodies.push(name);
                    }
                }
            }
            let kind = if amb {
                let form = match get(f, "form") {
                    None => Some(AmbForm::RCrossMa),
                    Some(n) => match &n.kind {
                        YamlKind::Scalar { text, .. } if text == "r_x_ma" => {
                            Some(AmbForm::RCrossMa)
                        }
                        YamlKind::Scalar { text, .. } if text == "h_dot" => Some(AmbForm::HDot),
                        YamlKind::Scalar { text, .. } if text == "h_rel_dot" => {
                            Some(AmbForm::HRelDot)
                        }
                        _ => {
                            self.error(
                                Diagnostic::new(n.location, "`form` of an angular momentum balance is `r_x_ma`, `h_dot` or `h_rel_dot`")
                                    .with_help("`r_x_ma` (the default): Σ M_A = Σ r_G/A × m a_G + I θ̈, valid about any point; `h_dot`: Σ M_A = dH_A/dt with absolute velocities, valid when v_A × v_G = 0; `h_rel_dot`: Σ M_A = dH_A/rel/dt with velocities relative to A, valid when r_G/A × a_A = 0"),
                            );
                            None
                        }
                    },
                };
                get(f, "about")
                    .and_then(|n| self.name(n, "`about`"))
                    .zip(form)
                    .zip(match get(f, "axis") {
                        Some(n) => self
                            .vector(n, "`axis`", "axis: [0, 0, 1]")
                            .map(|v| Some(Located::new(v, n.location))),
                        None => Some(None),
                    })
                    .zip(read_in(self, f))
                    .map(|(((about, form), axis), frame)| BalanceKind::Amb {
                        about,
                        form,
                        axis,
                        frame,
                    })
            } else {
                get(f, "along")
                    .and_then(|n| self.vector(n, "`along`", "along: [cos(theta), sin(theta)]"))
                    .map(|along| BalanceKind::Lmb { along })
            };
            if let Some(kind) = kind
                && !bodies.is_empty()
            {
                out.push(Balance {
                    kind,
                    bodies,
                    set: set.clone(),
                    expect_disagreement: false,
                    location: item.location,
                });
            }
        }
        out
    }
}

/// The writer of the balances.
impl Writer<'_> {
    /// `balances:` is not written: the model is derived by Lagrange's equations, noted.
    pub(super) fn write_balances(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        if !file.balances.is_empty() {
            self.notes.push(
                "`balances:` left out: the reduced model is derived by Lagrange's equations"
                    .to_string(),
            );
        }
        Ok(())
    }
}
