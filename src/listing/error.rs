//! Why a listing could not be made: [`ListingError`], shared by the equations, the exported
//! code and the kinematics.

use eomgen_symbolic::model::Diagnostic;

/// Why [`super::equations`], [`super::export`] or [`super::kinematics`] could not list a
/// model.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum ListingError {
    /// The file has mistakes (located diagnostics).
    #[error("{} error(s) in the model file", .0.len())]
    Diagnostics(Vec<Diagnostic>),
    /// Momentum balance was asked of a model it cannot derive.
    #[error(
        "`{model}` has no bodies or writes `kinetic:`, which momentum balance cannot derive from; use the Lagrange derivation"
    )]
    NoMomentumForm {
        /// The model's name.
        model: String,
    },
    /// A reaction asked for names a body or point the model does not have, or the model has
    /// loads that cannot be attributed to bodies.
    #[error(transparent)]
    Reaction(#[from] eomgen_symbolic::mechanics::ReactionError),
    /// A frame or point asked for is not in the model file.
    #[error("the model has no {kind} `{name}` (its {kind}s: {})", known.join(", "))]
    UnknownName {
        /// `frame` or `point`.
        kind: &'static str,
        /// The name asked for.
        name: String,
        /// The file's names of that kind.
        known: Vec<String>,
    },
    /// The exporter could not write a function (a bug of the exporter: the reason names the
    /// function).
    #[error("the model's code could not be exported: {reason}")]
    Export {
        /// Why.
        reason: String,
    },
}
