//! `eomgen equations MODEL|FILE [--method lagrange|momentum] [--latex|--rust]` and
//! `eomgen new TEMPLATE N`.

use clap::{Args, ValueEnum};

use crate::cli::error::CliError;
use crate::cli::model::{diagnostics_error, read_model};
use crate::cli::output::out;
use eomgen_symbolic::codegen::{EquationsListing, GenerateError, equations_latex, equations_text};
use eomgen_symbolic::expr::print::Syntax;
use eomgen_symbolic::mechanics::{Formulation, Lagrange, MomentumBalance, SymbolicModel};
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
    #[arg(long, conflicts_with = "method")]
    pub rust: bool,
}

/// Options of `eomgen new`.
#[derive(Debug, Args)]
pub struct NewArgs {
    /// `n-link-pendulum` or `n-mass-chain`.
    pub template: String,
    /// Size (number of bars or masses), at least 1.
    pub n: usize,
}

/// What `eomgen equations --json` prints.
#[derive(serde::Serialize)]
struct EquationsReport<'a> {
    /// The model's name.
    model: &'a str,
    /// `lagrange` or `momentum`.
    method: &'static str,
    /// The equations in the model file's syntax.
    equations: EquationsListing,
    /// The same in LaTeX.
    latex: EquationsListing,
}

/// Runs `equations`.
pub fn run(args: &EquationsArgs) -> Result<(), CliError> {
    let (display, source) = read_model(&args.model)?;
    let file = eomgen_symbolic::model::load(&display, &source)
        .map_err(|d| diagnostics_error(&display, &source, &d))?;
    if args.rust {
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
    let mut model =
        SymbolicModel::from_file(&file).map_err(|d| diagnostics_error(&display, &source, &d))?;
    let eom = match args.method {
        Method::Lagrange => Lagrange.derive(&mut model),
        Method::Momentum => {
            if !MomentumBalance::applies_to(&model) {
                return Err(CliError::usage(format!(
                    "`{}` has no bodies or writes `kinetic:`, which momentum balance cannot derive from; try --method lagrange",
                    model.name
                )));
            }
            MomentumBalance.derive(&mut model)
        }
    };
    if args.json {
        let report = EquationsReport {
            model: &model.name,
            method: match args.method {
                Method::Lagrange => "lagrange",
                Method::Momentum => "momentum",
            },
            equations: EquationsListing::of(&model, &eom, Syntax::Text),
            latex: EquationsListing::of(&model, &eom, Syntax::Latex),
        };
        crate::cli::json::print_json(&report)?;
    } else if args.latex {
        out!("{}", equations_latex(&model, &eom));
    } else {
        out!("{}", equations_text(&model, &eom));
    }
    Ok(())
}

/// Runs `new`.
pub fn new(args: &NewArgs) -> Result<(), CliError> {
    let text =
        templates::generate(&args.template, args.n).map_err(|e| CliError::usage(e.to_string()))?;
    out!("{text}");
    Ok(())
}
