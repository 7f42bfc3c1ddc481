//! The reference results a model file gives for its Floquet charts (`floquet:`), evaluated
//! at a model's parameters: stability thresholds (Kapitza's `a w > √(2 g l)`) and reference
//! curves over two swept parameters (the edges of the Mathieu chart). `eomgen study floquet`
//! draws and prints them; the model knowledge lives in the file, and reaches here through the
//! model's description ([`eomgen_runtime::description::floquet`]).

use eomgen_runtime::description::floquet::{FloquetReference, FloquetThreshold};
use eomgen_symbolic::model::Location;
use eomgen_symbolic::model::ast::Expr;
use eomgen_symbolic::model::parser::{eval_expr, parse_expr};

use crate::{ModelDescription, ModelInfo};

/// Why a model's `floquet:` references could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReferenceError {
    /// An expression of the references does not parse (the description was not printed
    /// from a parsed file).
    #[error("`{model}`: `floquet:` at `{at}`: `{text}`: {message}")]
    Expression {
        /// The model.
        model: String,
        /// The equilibrium the references hold at.
        at: String,
        /// The expression.
        text: String,
        /// The parser's message.
        message: String,
    },
}

/// A threshold with its expressions parsed.
#[derive(Debug, Clone, PartialEq)]
struct Threshold {
    spec: FloquetThreshold,
    value: Expr,
    critical: Expr,
}

/// A reference curve with its expressions parsed.
#[derive(Debug, Clone, PartialEq)]
struct Curve {
    label: String,
    color: Vec<Expr>,
    along: String,
    gives: String,
    value: Expr,
    domain: Option<Expr>,
}

/// A model's `floquet:` references at one equilibrium, their expressions parsed.
#[derive(Debug, Clone, PartialEq)]
pub struct FloquetReferences {
    axis_units: Vec<(String, String)>,
    thresholds: Vec<Threshold>,
    curves: Vec<Curve>,
}

/// A stability prediction evaluated at a model's parameters: stable when `value > critical`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ThresholdPrediction {
    /// Its name (`kapitza`).
    pub name: String,
    /// The JSON name of the value (`a_w`).
    pub key: String,
    /// How the text names the value (`a w`).
    pub label: String,
    /// The value.
    pub value: f64,
    /// The critical value.
    pub critical: f64,
    /// How the text names the critical value (`√(2 g l)`).
    pub critical_label: String,
    /// What predicts it (`averaging`).
    pub by: String,
    /// When the prediction holds (`for a ≪ l`).
    pub note: String,
    /// `value > critical`.
    pub predicts_stable: bool,
}

/// A reference curve sampled in a chart's coordinates.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ReferenceCurvePoints {
    /// Its legend.
    pub label: String,
    /// `[r, g, b]`.
    pub color: [u8; 3],
    /// The points `(x, y)` inside the chart, in the order sampled.
    pub points: Vec<(f64, f64)>,
}

/// One axis of a chart: the parameter and the range shown.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartAxis<'a> {
    /// The parameter.
    pub name: &'a str,
    /// The lower end of the range shown.
    pub lo: f64,
    /// The upper end.
    pub hi: f64,
}

/// Samples along a curve (4001 points, ends included).
const SAMPLES: u32 = 4000;

impl FloquetReferences {
    /// The references `description` carries (the model file's `floquet:`) at the
    /// equilibrium named `equilibrium` (`None` when the file gives none there).
    ///
    /// # Errors
    /// [`ReferenceError::Expression`] when an expression does not parse (never for a
    /// description built from a model file).
    ///
    /// # Examples
    /// ```
    /// let model = eomgen::ModelSource::open("mathieu_pendulum")?.instantiate();
    /// let refs = eomgen::FloquetReferences::of(model.description(), "upright")?.unwrap();
    /// let kapitza = &refs.thresholds(model.as_ref())[0];
    /// // a w = 0.1 × 60 = 6 against √(2 g l) = √20.
    /// assert_eq!(kapitza.value, 6.0);
    /// assert!((kapitza.critical - 20f64.sqrt()).abs() < 1e-15 && kapitza.predicts_stable);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn of(
        description: &ModelDescription,
        equilibrium: &str,
    ) -> Result<Option<Self>, ReferenceError> {
        let Some(entry) = description.floquet.iter().find(|e| e.at == equilibrium) else {
            return Ok(None);
        };
        Self::parse(&description.name, entry).map(Some)
    }

    /// `entry` with its expressions parsed.
    fn parse(model: &str, entry: &FloquetReference) -> Result<Self, ReferenceError> {
        let parse = |text: &str| {
            parse_expr(text, Location { line: 1, column: 1 }).map_err(|d| {
                ReferenceError::Expression {
                    model: model.to_string(),
                    at: entry.at.to_string(),
                    text: text.to_string(),
                    message: d.message,
                }
            })
        };
        let thresholds = entry
            .thresholds
            .iter()
            .map(|t| {
                Ok(Threshold {
                    spec: t.clone(),
                    value: parse(&t.value)?,
                    critical: parse(&t.critical)?,
                })
            })
            .collect::<Result<_, ReferenceError>>()?;
        let curves = entry
            .curves
            .iter()
            .map(|c| {
                Ok(Curve {
                    label: c.label.to_string(),
                    color: c.color.iter().map(|e| parse(e)).collect::<Result<_, _>>()?,
                    along: c.along.to_string(),
                    gives: c.gives.to_string(),
                    value: parse(&c.value)?,
                    domain: c.domain.as_deref().map(parse).transpose()?,
                })
            })
            .collect::<Result<_, ReferenceError>>()?;
        Ok(Self {
            axis_units: entry
                .axis_units
                .iter()
                .map(|(p, u)| (p.to_string(), u.to_string()))
                .collect(),
            thresholds,
            curves,
        })
    }

    /// The unit the file gives for `parameter` on a chart's axis.
    pub fn axis_unit(&self, parameter: &str) -> Option<&str> {
        self.axis_units
            .iter()
            .find(|(p, _)| p == parameter)
            .map(|(_, u)| u.as_str())
    }

    /// The thresholds evaluated at `model`'s parameters (a value that cannot be evaluated is
    /// NaN, and predicts nothing stable).
    pub fn thresholds(&self, model: &dyn ModelInfo) -> Vec<ThresholdPrediction> {
        let lookup = parameters(model);
        self.thresholds
            .iter()
            .map(|t| {
                let value = eval(&t.value, &lookup);
                let critical = eval(&t.critical, &lookup);
                let spec = &t.spec;
                ThresholdPrediction {
                    name: spec.name.to_string(),
                    key: spec.key.to_string(),
                    label: spec.label.to_string(),
                    value,
                    critical,
                    critical_label: spec.critical_label.to_string(),
                    by: spec.by.to_string(),
                    note: spec.note.to_string(),
                    predicts_stable: value > critical,
                }
            })
            .collect()
    }

    /// The curves whose two parameters are the chart's axes (in either order), sampled at
    /// 4001 values of `along` evenly spaced over the positive part of its range, at `model`'s
    /// other parameters; samples outside the chart, where the value is not finite or where
    /// `where:` is negative, are left out.
    pub fn curves(
        &self,
        model: &dyn ModelInfo,
        x: ChartAxis<'_>,
        y: ChartAxis<'_>,
    ) -> Vec<ReferenceCurvePoints> {
        let values = parameters(model);
        let mut out = Vec::new();
        for c in &self.curves {
            let (along, gives) = (c.along.as_str(), c.gives.as_str());
            let along_x = if (x.name, y.name) == (along, gives) {
                true
            } else if (x.name, y.name) == (gives, along) {
                false
            } else {
                continue;
            };
            let (a, b) = if along_x { (x, y) } else { (y, x) };
            let inside =
                |s: f64, v: f64| s > 0.0 && s >= a.lo && s <= a.hi && v >= b.lo && v <= b.hi;
            let place = |s: f64, v: f64| if along_x { (s, v) } else { (v, s) };
            let start = a.lo.max(0.0);
            let points = (0..=SAMPLES)
                .filter_map(|i| {
                    let s = start + (a.hi - start) * f64::from(i) / f64::from(SAMPLES);
                    let lookup = |n: &str| if n == along { Some(s) } else { values(n) };
                    // Drawn where `where:` is ≥ 0; a NaN there is no point either.
                    if let Some(domain) = &c.domain
                        && eval(domain, &lookup)
                            .partial_cmp(&0.0)
                            .is_none_or(|o| o.is_lt())
                    {
                        return None;
                    }
                    let v = eval(&c.value, &lookup);
                    (v.is_finite() && inside(s, v)).then(|| place(s, v))
                })
                .collect();
            let component = |e: &Expr| eval(e, &values).clamp(0.0, 255.0) as u8;
            let color = match c.color.as_slice() {
                [r, g, b] => [component(r), component(g), component(b)],
                _ => [0, 0, 0],
            };
            out.push(ReferenceCurvePoints {
                label: c.label.clone(),
                color,
                points,
            });
        }
        out
    }
}

/// `model`'s current parameter values by name.
fn parameters(model: &dyn ModelInfo) -> impl Fn(&str) -> Option<f64> {
    let names: Vec<String> = model
        .description()
        .parameter_names()
        .iter()
        .map(|n| n.to_string())
        .collect();
    let values = model.parameter_values();
    move |n: &str| names.iter().position(|p| p == n).map(|i| values[i])
}

/// `e` at `lookup` (NaN where a name is unknown).
fn eval(e: &Expr, lookup: &dyn Fn(&str) -> Option<f64>) -> f64 {
    eval_expr(e, lookup).unwrap_or(f64::NAN)
}
