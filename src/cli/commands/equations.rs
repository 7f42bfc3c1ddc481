//! `eomgen equations MODEL|FILE [--method lagrange|momentum] [--latex|--json|--rust|--c|--matlab|--python]`,
//! `eomgen kinematics MODEL|FILE [--frame F]… [--point P]… [--partial] [--latex|--json]` and
//! `eomgen new TEMPLATE N`.

use clap::{Args, ValueEnum};

use crate::cli::error::CliError;
use crate::cli::model::{diagnostics_error, read_model};
use crate::cli::output::out;
use eomgen::listing::{
    Derivation, KinematicsOptions, Language, ListingError, ReactionRequest, equations, export,
    kinematics,
};
use eomgen_symbolic::codegen::GenerateError;
use eomgen_symbolic::model::templates;

/// Which derivation to print.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Lagrange's equations (from T, V and Q).
    Lagrange,
    /// Momentum balance projected on the partial velocities (kinematic form only).
    Momentum,
}

/// Options of `eomgen equations`.
#[derive(Debug, Args)]
pub struct EquationsArgs {
    /// A bundled model's name, or the path of a model file.
    pub model: String,
    /// Derivation.
    #[arg(long, value_enum, default_value_t = Method::Lagrange)]
    pub method: Method,
    /// Print LaTeX (amsmath) instead of text.
    #[arg(long, conflicts_with = "rust")]
    pub latex: bool,
    /// Print JSON: `{"model", "method", "equations", "latex"}`, the equations (T, V, Q, M, F
    /// and each constraint's equation, Jacobian row and γ) as text and as LaTeX.
    #[arg(long, conflicts_with_all = ["rust", "latex"])]
    pub json: bool,
    /// Print the Rust that `eomgen::model!` generates for the file (formatted; the same
    /// pipeline as the macro, with the file tracked by its path as shown).
    #[arg(long, conflicts_with_all = ["method", "latex", "json"])]
    pub rust: bool,
    /// Print the equations as C99 (`<math.h>`): M and F, the right-hand side of the
    /// first-order form, the exact Jacobians, T, V, the points and the constraints, as
    /// functions of (t, q, qd, p) prefixed with the model's name, matrices row-major.
    #[arg(long = "c", conflicts_with_all = ["method", "latex", "json", "rust", "matlab", "python"])]
    pub c: bool,
    /// Print the same as a MATLAB/Octave function file (save it as NAME.m; `NAME()` returns
    /// the functions as handles: `ode45(model.rhs, [0 10], model.initial_state())`).
    #[arg(long, conflicts_with_all = ["method", "latex", "json", "rust", "python"])]
    pub matlab: bool,
    /// Print the same as a Python module (NumPy).
    #[arg(long, conflicts_with_all = ["method", "latex", "json", "rust"])]
    pub python: bool,
}

/// Options of `eomgen kinematics`.
#[derive(Debug, Args)]
pub struct KinematicsArgs {
    /// A bundled model's name, or the path of a model file.
    pub model: String,
    /// A frame to list (repeatable; default: every frame of the file's `frames:`).
    #[arg(long = "frame", value_name = "FRAME")]
    pub frames: Vec<String>,
    /// A point to list (repeatable; default: every point of the file's `points:`).
    #[arg(long = "point", value_name = "POINT")]
    pub points: Vec<String>,
    /// Also list the partial velocities ∂v/∂q̇ᵢ and ∂ω/∂q̇ᵢ.
    #[arg(long)]
    pub partial: bool,
    /// A reaction to list, `BODY@POINT` or `BODY+BODY@POINT` (repeatable): the force and the
    /// moment about POINT that act on the bodies besides gravity and their own torques (a
    /// pivot the model leaves implicit), in terms of q, q̇ and q̈.
    #[arg(long = "reaction", value_name = "BODIES@POINT")]
    pub reactions: Vec<String>,
    /// Print LaTeX (amsmath) instead of text.
    #[arg(long)]
    pub latex: bool,
    /// Print JSON: `{"model", "coordinates", "frames", "points", "latex"}`.
    #[arg(long, conflicts_with = "latex")]
    pub json: bool,
}

/// Runs `kinematics`.
pub fn run_kinematics(args: &KinematicsArgs) -> Result<(), CliError> {
    let (display, source) = read_model(&args.model)?;
    let reactions = (args.reactions.iter())
        .map(|r| match r.split_once('@') {
            Some((bodies, at)) if !bodies.is_empty() && !at.is_empty() => Ok(ReactionRequest {
                bodies: bodies.split('+').map(|b| b.trim().to_string()).collect(),
                at: at.trim().to_string(),
            }),
            _ => Err(CliError::usage(format!(
                "--reaction `{r}`: write the bodies and the point as `BODY@POINT` or `BODY+BODY@POINT`"
            ))),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let options = KinematicsOptions {
        frames: args.frames.clone(),
        points: args.points.clone(),
        partial: args.partial,
        reactions,
    };
    let listing = kinematics(&display, &source, &options).map_err(|e| match e {
        ListingError::Diagnostics(d) => diagnostics_error(&display, &source, &d),
        e @ (ListingError::UnknownName { .. } | ListingError::Reaction(_)) => {
            CliError::usage(e.to_string())
        }
        e => CliError::failure(e.to_string()),
    })?;
    show(
        &listing,
        args.json,
        args.latex,
        &listing.text,
        &listing.latex_document,
    )
}

/// Prints a listing as JSON, as its LaTeX document or as its text.
fn show(
    listing: &impl serde::Serialize,
    json: bool,
    latex: bool,
    text: &str,
    latex_document: &str,
) -> Result<(), CliError> {
    if json {
        crate::cli::json::print_json(listing)?;
    } else if latex {
        out!("{latex_document}");
    } else {
        out!("{text}");
    }
    Ok(())
}

/// Options of `eomgen new`.
#[derive(Debug, Args)]
pub struct NewArgs {
    /// `n-link-pendulum`, `n-mass-chain` or `universal-joint-chain`.
    pub template: String,
    /// Size (number of bars, masses or joints), at least 1.
    pub n: usize,
}

/// Runs `equations`.
pub fn run(args: &EquationsArgs) -> Result<(), CliError> {
    let (display, source) = read_model(&args.model)?;
    if args.rust {
        let file = eomgen_symbolic::model::load(&display, &source)
            .map_err(|d| diagnostics_error(&display, &source, &d))?;
        let options = eomgen_symbolic::codegen::EmitOptions {
            crate_path: "::eomgen".to_string(),
            tracked_files: vec![display.clone()],
            source_display: display.clone(),
        };
        let tokens = eomgen_symbolic::codegen::generate(&file, &options).map_err(|e| match e {
            GenerateError::Diagnostics(d) => diagnostics_error(&display, &source, &d),
            GenerateError::Emit(message) => CliError::failure(message),
        })?;
        let code = syn::parse2::<syn::File>(tokens)
            .map_err(|e| CliError::failure(format!("the generated code does not parse: {e}")))?;
        out!("{}", prettyplease::unparse(&code));
        return Ok(());
    }
    let language = if args.c {
        Some(Language::C)
    } else if args.matlab {
        Some(Language::Matlab)
    } else if args.python {
        Some(Language::Python)
    } else {
        None
    };
    if let Some(language) = language {
        let code = export(&display, &source, language).map_err(|e| match e {
            ListingError::Diagnostics(d) => diagnostics_error(&display, &source, &d),
            e => CliError::failure(e.to_string()),
        })?;
        out!("{code}");
        return Ok(());
    }
    let derivation = match args.method {
        Method::Lagrange => Derivation::Lagrange,
        Method::Momentum => Derivation::Momentum,
    };
    let listing = equations(&display, &source, derivation).map_err(|e| match e {
        ListingError::Diagnostics(d) => diagnostics_error(&display, &source, &d),
        ListingError::NoMomentumForm { model } => CliError::usage(format!(
            "`{model}` has no bodies or writes `kinetic:`, which momentum balance cannot derive from; try --method lagrange"
        )),
        e => CliError::failure(e.to_string()),
    })?;
    show(
        &listing,
        args.json,
        args.latex,
        &listing.text,
        &listing.latex_document,
    )
}

/// Runs `new`: prints the generated file, which names its equilibria (`hanging` and
/// `upright`, or `rest`) and states its `checks:` ([`templates::generate`]).
pub fn new(args: &NewArgs) -> Result<(), CliError> {
    let text =
        templates::generate(&args.template, args.n).map_err(|e| CliError::usage(e.to_string()))?;
    out!("{text}");
    Ok(())
}
