//! The typed `checks:` and `floquet:` of a model file: the closed forms, conserved quantities,
//! drifts and Floquet references a model states about itself, which `eomgen report` verifies.

use super::ast::Expr;
use super::located::{Located, Location};

/// `checks:` — what the file claims about its own model: hand-derived equations, verified by
/// `eomgen check`, and reference values, verified by `eomgen report`.
///
/// The reference vocabulary (every `tolerance` is optional, default 1e-9; a value passes when
/// `|computed − expected| ≤ tolerance · max(1, |expected|)`; expected values are expressions
/// of the parameters, evaluated at the parameters' values):
///
/// ```yaml
/// checks:
///   natural_frequencies: { at: hanging, values: [sqrt(g/l)], tolerance: 1e-9 }  # rad/s, ascending
///   damping_ratios: { at: rest, values: [0.5] }          # ζ of the linearisation, by |s|
///   period: { event: return, value: 2*pi*sqrt(l/g) }     # between the last two occurrences
///   final_state: { t: 2, values: { x: 1, x_dot: 0 } }    # coordinates and rates at t
///   conserved: { momentum: m*x_dot }                     # or { value: …, tolerance: … }
///   energy_drift: { max: 1e-9, method: dop853, rtol: 1e-12, t_end: 10 }
///   constraint_drift: { max: 1e-8 }
/// ```
///
/// `at:` names an entry of `equilibria:` (default: the first, else q = 0). Simulations start
/// from `initial:` and use `method` (default `dop853`), `rtol` = `atol` (default 1e-12) and
/// `t_end` (default 10 s) where the entry takes them (`period`, `final_state`,
/// `energy_drift`, `constraint_drift`); `conserved` uses the defaults. `energy_drift` is
/// `max |E − E(0)| / max(T + |V|)` and `constraint_drift` the largest `|Φ|` or velocity
/// residual over the run; `eomgen report` runs both by default (energy on conservative models,
/// drift on constrained ones), and these entries change their bounds and settings.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Checks {
    /// `equations_of_motion:` — the equations of motion as derived by hand, one per
    /// coordinate, linear in the accelerations (any combination of the true equations).
    pub equations_of_motion: Vec<HandEquation>,
    /// `natural_frequencies:` — the undamped natural frequencies (rad/s) at an equilibrium.
    pub natural_frequencies: Option<ModalCheck>,
    /// `damping_ratios:` — the damping ratios of the linearisation at an equilibrium.
    pub damping_ratios: Option<ModalCheck>,
    /// `period:` — the interval between occurrences of an event (s).
    pub period: Option<PeriodCheck>,
    /// `final_state:` — coordinates and rates at a time.
    pub final_state: Option<FinalStateCheck>,
    /// `conserved:` — constants of the motion, in file order.
    pub conserved: Vec<ConservedCheck>,
    /// `energy_drift:` — bound and settings of the energy-conservation check.
    pub energy_drift: Option<DriftCheck>,
    /// `constraint_drift:` — bound and settings of the constraint-drift check.
    pub constraint_drift: Option<DriftCheck>,
}

/// Default `tolerance` of a reference value in `checks:`.
pub const DEFAULT_CHECK_TOLERANCE: f64 = 1e-9;

/// Default `max` of `energy_drift:`: DOP853 at rtol = atol = 1e-12 keeps the relative drift
/// over 10 s near 1e-11 on every bundled conservative model; 1e-9 leaves a factor of 100.
pub const DEFAULT_ENERGY_DRIFT: f64 = 1e-9;

/// Default `max` of `constraint_drift:`: the unstabilised drift of `Φ` and `Φ̇` at
/// rtol = atol = 1e-12 over 10 s stays below 1e-10 on every bundled constrained model.
pub const DEFAULT_CONSTRAINT_DRIFT: f64 = 1e-8;

/// Integration methods a check may name (`method:`), as `eomgen simulate --method` spells
/// them.
pub const CHECK_METHODS: &[&str] = &[
    "euler",
    "midpoint",
    "rk4",
    "bs32",
    "dp54",
    "dop853",
    "symplectic-euler",
    "stormer-verlet",
    "implicit-midpoint",
    "radau5",
];

/// How a check integrates (`method:`, `rtol:`, `t_end:`); `None` means the default
/// (`dop853`, 1e-12, 10 s).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunSettings {
    /// One of [`CHECK_METHODS`].
    pub method: Option<Located<String>>,
    /// Relative and absolute tolerance.
    pub rtol: Option<f64>,
    /// End time (s).
    pub t_end: Option<f64>,
}

/// `natural_frequencies:` or `damping_ratios:` — `{ at: hanging, values: [...], tolerance }`.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalCheck {
    /// The equilibrium (an `equilibria:` name); `None`: the first, else q = 0.
    pub at: Option<Located<String>>,
    /// Expected values, ascending as computed (expressions of the parameters).
    pub values: Vec<Expr>,
    /// Relative tolerance (see [`Checks`]).
    pub tolerance: f64,
    /// Where the entry's key is.
    pub location: Location,
}

/// `period:` — `{ event: return, value: 2*pi*sqrt(l/g), tolerance, method, rtol, t_end }`:
/// the interval between the last two occurrences of the event within `t_end`.
#[derive(Debug, Clone, PartialEq)]
pub struct PeriodCheck {
    /// The event (an `events:` name).
    pub event: Located<String>,
    /// Expected period (s), an expression of the parameters.
    pub value: Expr,
    /// Relative tolerance.
    pub tolerance: f64,
    /// Integration settings.
    pub run: RunSettings,
    /// Where the entry's key is.
    pub location: Location,
}

/// `final_state:` — `{ t: 2, values: { x: 1, x_dot: 0 }, tolerance, method, rtol }`.
#[derive(Debug, Clone, PartialEq)]
pub struct FinalStateCheck {
    /// The time (s), an expression of the parameters.
    pub t: Expr,
    /// Expected values by coordinate or rate name (expressions of the parameters).
    pub values: Vec<(Located<String>, Expr)>,
    /// Relative tolerance.
    pub tolerance: f64,
    /// Integration settings (`t_end` is `t`).
    pub run: RunSettings,
    /// Where the entry's key is.
    pub location: Location,
}

/// One `conserved:` entry: `name: expr` or `name: { value: expr, tolerance: 1e-9 }`, a
/// function of the parameters, coordinates, rates and `t` that stays constant.
#[derive(Debug, Clone, PartialEq)]
pub struct ConservedCheck {
    /// Its name (`momentum`).
    pub name: Located<String>,
    /// The quantity.
    pub value: Expr,
    /// Bound on `max |Q(t) − Q(0)| / max(1, |Q(0)|)`.
    pub tolerance: f64,
}

/// `energy_drift:` or `constraint_drift:` — `{ max: 1e-9, method, rtol, t_end }`.
#[derive(Debug, Clone, PartialEq)]
pub struct DriftCheck {
    /// The bound.
    pub max: f64,
    /// Integration settings.
    pub run: RunSettings,
    /// Where the entry's key is.
    pub location: Location,
}

/// One entry of `floquet:`: the reference results that `eomgen study floquet` draws on its
/// stability chart and prints at the equilibrium `at` (lectures 19, 21), such as the
/// Mathieu pendulum's Kapitza condition and the edges of its stable band:
///
/// ```yaml
/// floquet:
///   upright:
///     axis_units: { a: m }
///     thresholds:
///       kapitza: { key: a_w, label: a w, value: a*w, critical: sqrt(2*g*l),
///                  critical_label: √(2 g l), by: averaging, note: for a ≪ l }
///     curves:
///       kapitza: { label: Kapitza a w = √(2 g l), color: [0, 0, 0], along: a, gives: w,
///                  value: sqrt(2*g*l)/a }
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct FloquetReference {
    /// The equilibrium (a name of `equilibria:`) the references hold at.
    pub at: Located<String>,
    /// Units shown on the chart's axes for these parameters (`a: m`).
    pub axis_units: Vec<(Located<String>, Located<String>)>,
    /// Predictions of stability by a threshold, printed and in the JSON.
    pub thresholds: Vec<FloquetThreshold>,
    /// Curves drawn on a chart over the two parameters `along` and `gives`.
    pub curves: Vec<ReferenceCurve>,
}

/// A stability prediction `value > critical` at an equilibrium (`floquet:` … `thresholds:`).
#[derive(Debug, Clone, PartialEq)]
pub struct FloquetThreshold {
    /// Its name, the JSON key of its object and the label of its text line (`kapitza`).
    pub name: Located<String>,
    /// The JSON name of the value (`a_w`); the critical value is `critical_<key>`.
    pub key: Located<String>,
    /// How the text names the value (`a w`).
    pub label: String,
    /// The value, an expression of the parameters.
    pub value: Expr,
    /// The critical value above which the equilibrium is predicted stable.
    pub critical: Expr,
    /// How the text names the critical value (`√(2 g l)`).
    pub critical_label: String,
    /// What predicts it (`averaging`).
    pub by: String,
    /// When the prediction holds (`for a ≪ l`).
    pub note: String,
}

/// A reference curve of a stability chart (`floquet:` … `curves:`): the parameter `gives` as
/// a function of the parameter `along`, sampled over the positive part of `along`'s axis.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceCurve {
    /// Its name in the file.
    pub name: Located<String>,
    /// Its legend.
    pub label: String,
    /// Its colour `[r, g, b]`, each 0 to 255 (constant expressions).
    pub color: Vec<Expr>,
    /// The parameter the curve is sampled along.
    pub along: Located<String>,
    /// The parameter it gives.
    pub gives: Located<String>,
    /// The value of `gives`, an expression of the parameters (with `along` at each sample);
    /// samples where it is not finite are left out.
    pub value: Expr,
    /// `where:` — the curve is drawn where this expression is ≥ 0 (default: everywhere).
    pub domain: Option<Expr>,
}

/// Owned text of a description.
fn owned(s: &str) -> eomgen_description::Text {
    std::borrow::Cow::Owned(s.to_string())
}

/// An expression as description text ([`Expr`]'s `Display`, which parses back to it).
fn expression(e: &Expr) -> eomgen_description::Text {
    std::borrow::Cow::Owned(e.to_string())
}

impl RunSettings {
    /// The settings as the model's description keeps them.
    pub fn describe(&self) -> eomgen_description::checks::RunSettings {
        eomgen_description::checks::RunSettings {
            method: self.method.as_ref().map(|m| owned(&m.value)),
            rtol: self.rtol,
            t_end: self.t_end,
        }
    }
}

impl Checks {
    /// The reference results as the model's description keeps them: every expression as
    /// text, locations dropped; the hand-derived `equations_of_motion` left out (they are
    /// compared with the derivation, from the file).
    pub fn describe(&self) -> eomgen_description::checks::Checks {
        use eomgen_description::checks as d;
        let modal = |c: &ModalCheck| d::ModalCheck {
            at: c.at.as_ref().map(|a| owned(&a.value)),
            values: c.values.iter().map(expression).collect(),
            tolerance: c.tolerance,
        };
        let drift = |c: &DriftCheck| d::DriftCheck {
            max: c.max,
            run: c.run.describe(),
        };
        d::Checks {
            natural_frequencies: self.natural_frequencies.as_ref().map(modal),
            damping_ratios: self.damping_ratios.as_ref().map(modal),
            period: self.period.as_ref().map(|c| d::PeriodCheck {
                event: owned(&c.event.value),
                value: expression(&c.value),
                tolerance: c.tolerance,
                run: c.run.describe(),
            }),
            final_state: self.final_state.as_ref().map(|c| d::FinalStateCheck {
                t: expression(&c.t),
                values: c
                    .values
                    .iter()
                    .map(|(k, e)| (owned(&k.value), expression(e)))
                    .collect(),
                tolerance: c.tolerance,
                run: c.run.describe(),
            }),
            conserved: self
                .conserved
                .iter()
                .map(|c| d::ConservedCheck {
                    name: owned(&c.name.value),
                    value: expression(&c.value),
                    tolerance: c.tolerance,
                })
                .collect(),
            energy_drift: self.energy_drift.as_ref().map(drift),
            constraint_drift: self.constraint_drift.as_ref().map(drift),
        }
    }
}

impl FloquetReference {
    /// The references as the model's description keeps them: every expression as text,
    /// locations dropped.
    pub fn describe(&self) -> eomgen_description::floquet::FloquetReference {
        use eomgen_description::floquet as d;
        d::FloquetReference {
            at: owned(&self.at.value),
            axis_units: self
                .axis_units
                .iter()
                .map(|(p, u)| (owned(&p.value), owned(&u.value)))
                .collect(),
            thresholds: self
                .thresholds
                .iter()
                .map(|t| d::FloquetThreshold {
                    name: owned(&t.name.value),
                    key: owned(&t.key.value),
                    label: owned(&t.label),
                    value: expression(&t.value),
                    critical: expression(&t.critical),
                    critical_label: owned(&t.critical_label),
                    by: owned(&t.by),
                    note: owned(&t.note),
                })
                .collect(),
            curves: self
                .curves
                .iter()
                .map(|c| d::ReferenceCurve {
                    name: owned(&c.name.value),
                    label: owned(&c.label),
                    color: c.color.iter().map(expression).collect(),
                    along: owned(&c.along.value),
                    gives: owned(&c.gives.value),
                    value: expression(&c.value),
                    domain: c.domain.as_ref().map(expression),
                })
                .collect(),
        }
    }
}

/// One equation of motion derived by hand (`checks: { equations_of_motion: [...] }`),
/// `lhs = rhs` in the coordinates, their rates (`x_dot`) and accelerations (`x_ddot`), `t`
/// and the parameters. `eomgen check` compares the set with Lagrange's equations; the
/// generated code never uses them.
#[derive(Debug, Clone, PartialEq)]
pub struct HandEquation {
    /// Left-hand side.
    pub lhs: Expr,
    /// Right-hand side (`0` when the entry has no `=`).
    pub rhs: Option<Expr>,
    /// Where the entry starts.
    pub location: Location,
}
