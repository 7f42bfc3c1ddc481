//! `floquet:` — per equilibrium, the units of the axes of its stability charts and the
//! reference thresholds and curves drawn on them.

use super::walk::{Fields, Keyed, Need};
use super::write::{NotRewritten, Writer};
use super::*;

/// The keys of a `floquet:` entry.
const FLOQUET: Fields = Fields {
    kind: "the Floquet references at",
    keys: &[
        ("axis_units", Need::Optional),
        ("thresholds", Need::Optional),
        ("curves", Need::Optional),
    ],
    example: "{ axis_units: { a: m }, curves: { kapitza: { label: Kapitza, color: [0, 0, 0], along: a, gives: w, value: sqrt(2*g*l)/a } } }",
};

/// The keys of a threshold.
const THRESHOLD: Fields = Fields {
    kind: "threshold",
    keys: &[
        ("key", Need::Required),
        ("label", Need::Required),
        ("value", Need::Required),
        ("critical", Need::Required),
        ("critical_label", Need::Required),
        ("by", Need::Required),
        ("note", Need::Required),
    ],
    example: "{ key: a_w, label: a w, value: a*w, critical: sqrt(2*g*l), critical_label: √(2 g l), by: averaging, note: for a ≪ l }",
};

/// The keys of a reference curve.
const CURVE: Fields = Fields {
    kind: "curve",
    keys: &[
        ("label", Need::Required),
        ("color", Need::Required),
        ("along", Need::Required),
        ("gives", Need::Required),
        ("value", Need::Required),
        ("where", Need::Optional),
    ],
    example: "{ label: Kapitza, color: [0, 0, 0], along: a, gives: w, value: sqrt(2*g*l)/a }",
};

impl Ctx<'_> {
    /// `floquet:` — `equilibrium: { axis_units: { p: unit }, thresholds: { name: { … } },
    /// curves: { name: { … } } }`.
    pub(super) fn floquet(&mut self, node: &YamlNode) -> Vec<FloquetReference> {
        let example = format!("floquet: {{ upright: {} }}", FLOQUET.example);
        let spec = Keyed {
            what: "`floquet`",
            example: &example,
            names: Some("equilibrium"),
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let f = cx.fields(k, v, &FLOQUET)?;
            let axis_units = get(f, "axis_units")
                .and_then(|n| cx.map(n, "`axis_units`", "axis_units: { a: m, w: rad/s }"))
                .map(|units| {
                    units
                        .iter()
                        .filter_map(|(p, u)| {
                            let u = cx.text(u, &format!("the unit of `{}`", p.value), "m")?;
                            Some((p.clone(), u))
                        })
                        .collect()
                })
                .unwrap_or_default();
            let thresholds = get(f, "thresholds")
                .map(|n| cx.floquet_thresholds(n))
                .unwrap_or_default();
            let curves = get(f, "curves")
                .map(|n| cx.reference_curves(n))
                .unwrap_or_default();
            Some(FloquetReference {
                at: k.clone(),
                axis_units,
                thresholds,
                curves,
            })
        })
    }

    /// `thresholds:` of a `floquet:` entry.
    fn floquet_thresholds(&mut self, node: &YamlNode) -> Vec<FloquetThreshold> {
        let example = format!("thresholds: {{ kapitza: {} }}", THRESHOLD.example);
        let spec = Keyed {
            what: "`thresholds`",
            example: &example,
            names: Some("threshold"),
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let f = cx.fields(k, v, &THRESHOLD)?;
            let what = |field: &str| format!("`{field}` of threshold `{}`", k.value);
            let key = get(f, "key").and_then(|n| cx.name(n, &what("key")));
            let mut texts = ["label", "critical_label", "by", "note"]
                .map(|field| get(f, field).and_then(|n| cx.text(n, &what(field), "a w")));
            let value = get(f, "value").and_then(|n| cx.expr(n, &what("value")));
            let critical = get(f, "critical").and_then(|n| cx.expr(n, &what("critical")));
            let [Some(label), Some(critical_label), Some(by), Some(note)] =
                texts.each_mut().map(Option::take)
            else {
                return None;
            };
            Some(FloquetThreshold {
                name: k.clone(),
                key: key?,
                label: label.value,
                value: value?,
                critical: critical?,
                critical_label: critical_label.value,
                by: by.value,
                note: note.value,
            })
        })
    }

    /// `curves:` of a `floquet:` entry.
    fn reference_curves(&mut self, node: &YamlNode) -> Vec<ReferenceCurve> {
        let example = format!("curves: {{ kapitza: {} }}", CURVE.example);
        let spec = Keyed {
            what: "`curves`",
            example: &example,
            names: Some("curve"),
            drop: false,
        };
        self.keyed(node, spec, |cx, k, v| {
            let f = cx.fields(k, v, &CURVE)?;
            let what = |field: &str| format!("`{field}` of curve `{}`", k.value);
            let label = get(f, "label").and_then(|n| cx.text(n, &what("label"), "Kapitza"));
            let color = get(f, "color").and_then(|n| {
                let items = cx.seq(n, &what("color"), "color: [0, 150, 60]")?;
                if items.len() != 3 {
                    cx.error(
                        Diagnostic::new(
                            n.location,
                            format!("{} has {} entries, not 3", what("color"), items.len()),
                        )
                        .with_help(
                            "write red, green and blue from 0 to 255: `color: [0, 150, 60]`",
                        ),
                    );
                    return None;
                }
                items
                    .iter()
                    .map(|c| cx.expr(c, &what("color")))
                    .collect::<Option<Vec<Expr>>>()
            });
            let along = get(f, "along").and_then(|n| cx.name(n, &what("along")));
            let gives = get(f, "gives").and_then(|n| cx.name(n, &what("gives")));
            let value = get(f, "value").and_then(|n| cx.expr(n, &what("value")));
            let domain = get(f, "where").and_then(|n| cx.expr(n, &what("where")));
            Some(ReferenceCurve {
                name: k.clone(),
                label: label?.value,
                color: color?,
                along: along?,
                gives: gives?,
                value: value?,
                domain,
            })
        })
    }
}

impl Writer<'_> {
    /// `floquet:` is not written (its orbits are the file's), noted.
    pub(super) fn write_floquet(&mut self, file: &ModelFile) -> Result<(), NotRewritten> {
        if !file.floquet.is_empty() {
            self.notes.push("`floquet:` left out".to_string());
        }
        Ok(())
    }
}
