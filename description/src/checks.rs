//! The reference results a model file states about its own model (`checks:`), kept with the
//! model so that a compiled model carries them as well as a file loaded at run time:
//! natural frequencies and damping ratios at an equilibrium, a period between events, the
//! state at a time, constants of the motion, and bounds on the drift of energy and
//! constraints. `eomgen report` and `eomgen::checks::motion_checks` verify them.
//!
//! Values are expressions in the model file's syntax (`2*pi*sqrt(l/g)`), functions of the
//! parameters (and, for [`ConservedCheck`], of the coordinates, rates and `t`), kept as text:
//! the printing of the parsed expression, which parses back to the same expression.
//!
//! The file's hand-derived `equations_of_motion:` are not here: they are compared with the
//! symbolic derivation, which needs the file.

use serde::Serialize;

use crate::{List, Text};

/// The file's `checks:` reference results (docs/model-format.md); every entry optional.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Checks {
    /// `natural_frequencies:` — the undamped natural frequencies (rad/s), ascending, at an
    /// equilibrium.
    pub natural_frequencies: Option<ModalCheck>,
    /// `damping_ratios:` — the damping ratios of the linearisation at an equilibrium.
    pub damping_ratios: Option<ModalCheck>,
    /// `period:` — the interval between the last two occurrences of an event (s).
    pub period: Option<PeriodCheck>,
    /// `final_state:` — coordinates and rates at a time.
    pub final_state: Option<FinalStateCheck>,
    /// `conserved:` — constants of the motion, in file order.
    pub conserved: List<ConservedCheck>,
    /// `energy_drift:` — bound and settings of the energy-conservation check.
    pub energy_drift: Option<DriftCheck>,
    /// `constraint_drift:` — bound and settings of the constraint-drift check.
    pub constraint_drift: Option<DriftCheck>,
}

impl Checks {
    /// No reference results.
    pub const NONE: Checks = Checks {
        natural_frequencies: None,
        damping_ratios: None,
        period: None,
        final_state: None,
        conserved: List::Borrowed(&[]),
        energy_drift: None,
        constraint_drift: None,
    };
}

/// How a check integrates; `None` means the default (`dop853`, `rtol` = `atol` = 1e-12,
/// 10 s).
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct RunSettings {
    /// The method as `eomgen simulate --method` spells it (`dop853`).
    pub method: Option<Text>,
    /// Relative and absolute tolerance.
    pub rtol: Option<f64>,
    /// End time (s).
    pub t_end: Option<f64>,
}

impl RunSettings {
    /// Every setting at its default.
    pub const DEFAULT: RunSettings = RunSettings {
        method: None,
        rtol: None,
        t_end: None,
    };
}

/// `natural_frequencies:` or `damping_ratios:` at an equilibrium.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModalCheck {
    /// The equilibrium (a name of [`crate::ModelDescription::equilibria`]); `None`: the
    /// first, else `q = 0`.
    pub at: Option<Text>,
    /// Expected values, ascending as computed: expressions of the parameters.
    pub values: List<Text>,
    /// Relative tolerance.
    pub tolerance: f64,
}

/// `period:` — the interval between the last two occurrences of an event.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PeriodCheck {
    /// The event (a name of [`crate::ModelDescription::events`]).
    pub event: Text,
    /// Expected period (s): an expression of the parameters.
    pub value: Text,
    /// Relative tolerance.
    pub tolerance: f64,
    /// Integration settings.
    pub run: RunSettings,
}

/// `final_state:` — coordinates and rates at a time.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FinalStateCheck {
    /// The time (s): an expression of the parameters.
    pub t: Text,
    /// Expected values by coordinate or rate name (`x`, `x_dot`): expressions of the
    /// parameters.
    pub values: List<(Text, Text)>,
    /// Relative tolerance.
    pub tolerance: f64,
    /// Integration settings (`t_end` is `t`).
    pub run: RunSettings,
}

/// One `conserved:` entry: a function of the parameters, coordinates, rates and `t` that
/// stays constant along the motion.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConservedCheck {
    /// Its name (`momentum`).
    pub name: Text,
    /// The quantity: an expression.
    pub value: Text,
    /// Bound on `max |Q(t) − Q(0)| / max(1, |Q(0)|)`.
    pub tolerance: f64,
}

/// `energy_drift:` or `constraint_drift:` — a bound and how to integrate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriftCheck {
    /// The bound.
    pub max: f64,
    /// Integration settings.
    pub run: RunSettings,
}
