//! The equations of motion of a model file as text and LaTeX, or as code for other tools
//! (C, MATLAB/Octave, Python): what `eomgen equations` prints, and what the Python package's
//! `Model.equations` and `Model.export` return; and its kinematics (`eomgen kinematics`).

use eomgen_symbolic::codegen::{EquationsListing, equations_latex, equations_text};
use eomgen_symbolic::expr::print::Syntax;
use eomgen_symbolic::mechanics::{Formulation, Kane, Lagrange, MomentumBalance, SymbolicModel};
use serde::Serialize;

pub use eomgen_symbolic::codegen::export::Language;

mod error;
mod kinematics;

pub use error::ListingError;

pub use kinematics::{
    FrameListing, Kinematics, KinematicsListing, KinematicsOptions, PointListing, ReactionListing,
    ReactionRequest, kinematics,
};

/// Which derivation to list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Derivation {
    /// Lagrange's equations, from `T`, `V` and `Q`.
    Lagrange,
    /// Momentum balance projected on the partial velocities (a model given by the
    /// kinematics of its bodies only).
    Momentum,
}

impl Derivation {
    /// `lagrange` or `momentum`.
    pub fn name(self) -> &'static str {
        match self {
            Derivation::Lagrange => "lagrange",
            Derivation::Momentum => "momentum",
        }
    }
}

/// The equations of a model by one derivation: `{"model", "method", "equations", "latex"}`
/// as `eomgen equations --json` prints them, and the whole listing as text and as LaTeX.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Equations {
    /// The model's name.
    pub model: String,
    /// `lagrange` or `momentum`.
    pub method: &'static str,
    /// `T`, `V`, `Q`, `M`, `F` and each constraint's equation, Jacobian row and `γ`, in the
    /// model file's syntax (they parse back with the model parser).
    pub equations: EquationsListing,
    /// The same in LaTeX.
    pub latex: EquationsListing,
    /// The listing as `eomgen equations` prints it (not serialised).
    #[serde(skip)]
    pub text: String,
    /// The listing as `eomgen equations --latex` prints it: an amsmath document body (not
    /// serialised).
    #[serde(skip)]
    pub latex_document: String,
}

/// Loads the model file `text` (`path` names it in diagnostics) and derives its equations
/// by `derivation`.
///
/// # Errors
/// [`ListingError::Diagnostics`] for a file with mistakes, [`ListingError::NoMomentumForm`]
/// for momentum balance on a model written in energy form or without bodies.
///
/// # Examples
/// ```
/// use eomgen::listing::{Derivation, equations};
/// let Some(pendulum) = eomgen::models::find("simple_pendulum") else { return Ok(()) };
/// let text = pendulum.source();
/// let listing = equations("simple_pendulum.yaml", text, Derivation::Lagrange)?;
/// assert_eq!(listing.equations.coordinates, ["q"]);
/// # Ok::<(), eomgen::listing::ListingError>(())
/// ```
///
/// # References
/// Lectures 8–10 (Lagrange's equations and momentum balance as two routes to one equation).
pub fn equations(
    path: &str,
    text: &str,
    derivation: Derivation,
) -> Result<Equations, ListingError> {
    let file = eomgen_symbolic::model::load(path, text).map_err(ListingError::Diagnostics)?;
    let mut model = SymbolicModel::from_file(&file).map_err(ListingError::Diagnostics)?;
    eomgen_symbolic::mechanics::limit_derivation(&mut model);
    let eom = match derivation {
        Derivation::Lagrange => Lagrange.derive(&mut model),
        Derivation::Momentum if Kane::applies_to(&model) => Kane.derive(&mut model),
        Derivation::Momentum => {
            if !MomentumBalance::applies_to(&model) {
                return Err(ListingError::NoMomentumForm {
                    model: model.name.clone(),
                });
            }
            MomentumBalance.derive(&mut model)
        }
    };
    eomgen_symbolic::mechanics::finish_derivation(&mut model, &file)
        .map_err(ListingError::Diagnostics)?;
    // Read on the constraints: a model in speeds beside non-holonomic constraints lists
    // Kane's non-holonomic equations (its auxiliary speeds at 0).
    let eom = eomgen_symbolic::mechanics::on_the_constraints(&mut model, &eom);
    let eom = eomgen_symbolic::codegen::readable_equations(&mut model, &eom);
    Ok(Equations {
        model: model.name.clone(),
        method: derivation.name(),
        equations: EquationsListing::of(&model, &eom, Syntax::Text),
        latex: EquationsListing::of(&model, &eom, Syntax::Latex),
        text: equations_text(&model, &eom),
        latex_document: equations_latex(&model, &eom),
    })
}

/// Loads the model file `text` (`path` names it in diagnostics and in the code's header) and
/// prints its equations as source code in `language`: `M` and `F`, the right-hand side of
/// the first-order form (with constraints, through the index-1 system and its multipliers),
/// the exact Jacobians `∂F/∂q`, `∂F/∂q̇` and `∂(M a)/∂q`, `T`, `V`, the points' positions
/// and the constraints' `Φ`, `J` and `γ`, each as a function of `(t, q, q̇, p)` with the
/// parameters' file values exported beside them
/// ([`eomgen_symbolic::codegen::export`] gives the shapes). The functions compute what the
/// model compiled at run time computes, operation by operation, with the target language's
/// own `sin`, `sqrt`, …: `tests/export.rs` holds the C and the Python to eomgen within
/// `1e-13` (relative) at random states.
///
/// # Errors
/// [`ListingError::Diagnostics`] for a file with mistakes (as `eomgen::model!` reports
/// them); [`ListingError::Export`] if a function cannot be written.
///
/// # Examples
/// ```
/// use eomgen::listing::{Language, export};
/// let Some(pendulum) = eomgen::models::find("simple_pendulum") else { return Ok(()) };
/// let text = pendulum.source();
/// let code = export("simple_pendulum.yaml", text, Language::Python)?;
/// assert!(code.contains("def rhs(t, y, p=PARAMETERS):"));
/// # Ok::<(), eomgen::listing::ListingError>(())
/// ```
///
/// # References
/// Lectures 8–11 (`M q̈ = F`, and the index-1 system of a constrained model).
pub fn export(path: &str, text: &str, language: Language) -> Result<String, ListingError> {
    export_with_parameters(path, text, language, &[])
}

/// [`export`] with the parameters `values` names set to those values in the exported
/// defaults (the file's values otherwise): what a model whose parameters were set after
/// loading exports (the Python package's `Model.with_parameters(...).export(...)`).
///
/// # Errors
/// As [`export`]; [`ListingError::Export`] for a name that is not a parameter.
pub fn export_with_parameters(
    path: &str,
    text: &str,
    language: Language,
    values: &[(String, f64)],
) -> Result<String, ListingError> {
    use eomgen_symbolic::codegen::GenerateError;
    let file = eomgen_symbolic::model::load(path, text).map_err(ListingError::Diagnostics)?;
    eomgen_symbolic::codegen::export::export(&file, path, language, values).map_err(|e| match e {
        GenerateError::Diagnostics(d) => ListingError::Diagnostics(d),
        GenerateError::Emit(reason) => ListingError::Export { reason },
    })
}
