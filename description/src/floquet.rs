//! The reference results a model file gives for its Floquet stability charts (`floquet:`),
//! by equilibrium: stability thresholds (Kapitza's `a w > √(2 g l)` for the pendulum on a
//! vibrating support) and reference curves over two parameters (the edges of the Mathieu
//! chart). `eomgen study floquet` evaluates them at a model's parameters
//! (`eomgen::FloquetReferences`), prints them and draws them; the knowledge of the model
//! lives in its file, not in the program (lectures 19, 21).
//!
//! Values are expressions of the parameters in the model file's syntax, kept as text (see
//! [`crate::checks`]).

use serde::Serialize;

use crate::{List, Text};

/// The references at one equilibrium (`floquet:` → `upright:`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FloquetReference {
    /// The equilibrium (a name of [`crate::ModelDescription::equilibria`]).
    pub at: Text,
    /// Units shown on a chart's axes, by parameter (`a` → `m`).
    pub axis_units: List<(Text, Text)>,
    /// Predictions of stability by a threshold.
    pub thresholds: List<FloquetThreshold>,
    /// Curves drawn on a chart over two parameters.
    pub curves: List<ReferenceCurve>,
}

/// A prediction "stable when `value > critical`".
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FloquetThreshold {
    /// Its name, the JSON key of its object (`kapitza`).
    pub name: Text,
    /// The JSON name of the value (`a_w`); the critical value is `critical_<key>`.
    pub key: Text,
    /// How the text names the value (`a w`).
    pub label: Text,
    /// The value: an expression of the parameters.
    pub value: Text,
    /// The critical value: an expression of the parameters.
    pub critical: Text,
    /// How the text names the critical value (`√(2 g l)`).
    pub critical_label: Text,
    /// What predicts it (`averaging`).
    pub by: Text,
    /// When the prediction holds (`for a ≪ l`).
    pub note: Text,
}

/// A curve of a stability chart: the parameter `gives` as a function of the parameter
/// `along`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReferenceCurve {
    /// Its name in the file.
    pub name: Text,
    /// Its legend.
    pub label: Text,
    /// Its colour `[r, g, b]`: expressions, each evaluating to 0…255.
    pub color: List<Text>,
    /// The parameter the curve is sampled along.
    pub along: Text,
    /// The parameter it gives.
    pub gives: Text,
    /// The value of `gives`: an expression of the parameters, with `along` at each sample.
    pub value: Text,
    /// `where:` — the curve is drawn where this expression is ≥ 0 (`None`: everywhere).
    pub domain: Option<Text>,
}
