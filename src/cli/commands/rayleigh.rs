//! `eomgen study rayleigh MODEL --shape SHAPE` (lectures 35–37): the Rayleigh quotient
//! `R(v) = vᵀKv / vᵀMv` of a trial shape at an equilibrium, `√R` against the exact lowest
//! natural frequency, the bound `R ≥ ω₁²` and the stationarity of `R` (its error second order
//! in the shape's error).
//!
//! The numbers come from [`eomgen::analysis::vibration::rayleigh_study`]; this module parses
//! `--shape` (with the model files' expression parser) and renders them. Exit 1 if the bound
//! fails (it cannot, up to rounding).

use clap::Args;
use eomgen::ModelInfo;
use eomgen::analysis::vibration::{
    self, PerturbationDirection, RayleighError, RayleighOptions, RayleighStudy, Stationarity,
};

use crate::cli::error::CliError;
use crate::cli::json::print_json_sorted;
use crate::cli::operating_point::{OperatingPointArgs, point_failure};
use crate::cli::render::num;
use crate::cli::values::{evaluate, parameter_lookup};

/// Options of `eomgen study rayleigh`.
#[derive(Debug, Args)]
pub struct RayleighArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any model file.
    pub model: String,
    /// The trial shape: one number or expression per coordinate, comma separated
    /// (`1,1.4,1`), or one expression of the 1-based coordinate index `i` and the number of
    /// coordinates `n`, evaluated for i = 1 … n (`sin(pi*i/(n+1))`, `i*(n+1-i)`). Expressions
    /// may use `pi` and the model's parameters (`i` and `n` hide parameters of those names).
    #[arg(long, value_name = "SHAPE", allow_hyphen_values = true)]
    pub shape: String,
    #[command(flatten)]
    pub point: OperatingPointArgs,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// `--shape` for `model`: a list of one entry per coordinate, or one expression of `i`, `n`.
fn parse_shape(model: &dyn ModelInfo, text: &str) -> Result<Vec<f64>, CliError> {
    let items = eomgen::expressions::split_list(text);
    let parameters = parameter_lookup(model);
    if items.len() > 1 {
        return items
            .iter()
            .enumerate()
            .map(|(k, item)| evaluate(item, &format!("--shape entry {}", k + 1), &parameters))
            .collect();
    }
    let Some(expression) = items.first() else {
        return Err(CliError::usage(
            "--shape is empty: give one value per coordinate, or an expression of i and n",
        ));
    };
    let n = model.num_dofs();
    (1..=n)
        .map(|i| {
            let lookup = |name: &str| match name {
                "i" => Some(i as f64),
                "n" => Some(n as f64),
                other => parameters(other),
            };
            evaluate(expression, &format!("--shape at i = {i}"), &lookup)
        })
        .collect()
}

/// Runs `study rayleigh`.
pub fn run(args: &RayleighArgs) -> Result<(), CliError> {
    let model = args.point.model(&args.model)?;
    let options = RayleighOptions {
        operating_point: args.point.options(model.as_ref())?,
        ..RayleighOptions::new(parse_shape(model.as_ref(), &args.shape)?)
    };
    let study = vibration::rayleigh_study(model.as_ref(), &options).map_err(|e| match &e {
        RayleighError::OperatingPoint(p) => point_failure(model.as_ref(), p),
        RayleighError::DimensionMismatch { .. }
        | RayleighError::NonFinite { .. }
        | RayleighError::ZeroShape
        | RayleighError::OnlyZeroModes { .. } => CliError::usage(format!("--shape: {e}")),
        RayleighError::Constrained { model: name } => CliError::usage(format!(
            "{e} (`eomgen modes {name}` gives its modes in minimal coordinates)"
        )),
        RayleighError::Unstable { .. } => {
            CliError::failure(format!("`{}`: {e}", model.description().name))
        }
        e => CliError::failure(format!("`{}`: {e}", model.description().name)),
    })?;
    if args.json {
        print_json_sorted(&study.summary(model.as_ref()))?;
    } else {
        print_text(&mut crate::cli::output::stdout(), model.as_ref(), &study);
    }
    if study.bound_holds {
        Ok(())
    } else {
        Err(CliError::failure(format!(
            "study rayleigh: R = {:e} is below ω₁² = {:e}, against the bound R ≥ ω₁²",
            num(study.rayleigh_quotient),
            num(study.natural_frequency.powi(2))
        )))
    }
}

/// The text of `study rayleigh`.
fn print_text(stdout: &mut impl std::io::Write, model: &dyn ModelInfo, study: &RayleighStudy) {
    let names = model.description().coordinate_names();
    let list = |v: &[f64]| {
        names
            .iter()
            .zip(v)
            .map(|(c, x)| format!("{c} = {x:.6e}", x = num(x)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let _ = writeln!(
        stdout,
        "model      {} ({} dof) at {}: R(v) = vᵀKv / vᵀMv",
        model.description().name,
        names.len(),
        study.operating_point.name
    );
    let _ = writeln!(stdout, "shape v    {}", list(&study.shape));
    if study.zero_modes_removed > 0 {
        let _ = writeln!(
            stdout,
            "projected  {} zero-frequency mode(s) removed ({:.3e} of ‖v‖_M): {}",
            study.zero_modes_removed,
            num(study.zero_mode_fraction),
            list(&study.projected_shape)
        );
    }
    let _ = writeln!(
        stdout,
        "R          {:.12e} 1/s²   √R = {:.12e} rad/s",
        num(study.rayleigh_quotient),
        num(study.frequency_estimate)
    );
    let _ = writeln!(
        stdout,
        "exact      ω₁ = {:.12e} rad/s, ω₁² = {:.12e} 1/s² (mode {}{}, modal analysis)",
        num(study.natural_frequency),
        num(study.natural_frequency.powi(2)),
        study.lowest_mode,
        if study.zero_modes_removed > 0 {
            ", the lowest non-zero"
        } else {
            ""
        }
    );
    let _ = writeln!(
        stdout,
        "error      (√R − ω₁)/ω₁ = {:.3e};  R − ω₁² = {:.3e} 1/s²: R ≥ ω₁² {}",
        num(study.relative_error),
        num(study.excess),
        if study.bound_holds { "holds" } else { "FAILS" }
    );
    match study.shape_error {
        Some(e) => {
            let _ = writeln!(
                stdout,
                "shape      tan θ = ‖v − (ψ₁ᵀMv)ψ₁‖_M / |ψ₁ᵀMv| = {:.3e}",
                num(e)
            );
        }
        None => {
            let _ = writeln!(stdout, "shape      v is M-orthogonal to ψ₁");
        }
    }
    let participation: Vec<String> = study
        .modal_participation
        .iter()
        .map(|p| format!("{:.3e}", num(p)))
        .collect();
    let _ = writeln!(
        stdout,
        "modes      ηₖ²/Ση² (η = ΨᵀMv): {}",
        participation.join(", ")
    );
    if let Some(s) = &study.stationarity {
        print_stationarity(stdout, s);
    }
}

/// The stationarity of `R` at the first mode: `R(ψ₁ + ε w)` against its closed form for each
/// `ε`, and the fitted order of `R − ω₁²` in `ε`.
fn print_stationarity(stdout: &mut impl std::io::Write, s: &Stationarity) {
    let from = match s.direction {
        PerturbationDirection::ShapeError => "the shape's own error",
        PerturbationDirection::NextMode => "the next mode",
    };
    let _ = writeln!(
        stdout,
        "stationarity: v = ψ₁ + ε w, w = {from} (‖w‖_M = 1, R(w) = {:.6e}):",
        num(s.direction_quotient)
    );
    let _ = writeln!(
        stdout,
        "  {:>8}  {:>20}  {:>11}  {:>11}  {:>11}",
        "ε", "R", "R − ω₁²", "closed form", "(√R−ω₁)/ω₁"
    );
    for p in &s.samples {
        let _ = writeln!(
            stdout,
            "  {:>8.1e}  {:>20.12e}  {:>11.3e}  {:>11.3e}  {:>11.3e}",
            num(p.epsilon),
            num(p.rayleigh_quotient),
            num(p.excess),
            num(p.predicted_excess),
            num(p.relative_error)
        );
    }
    match s.fitted_order {
        Some(order) => {
            let _ = writeln!(
                stdout,
                "  fitted order of R − ω₁² in ε: {order:.3} (2: R is stationary at ψ₁)"
            );
        }
        None => {
            let _ = writeln!(
                stdout,
                "  no order fitted: R − ω₁² is at rounding for every ε"
            );
        }
    }
}
