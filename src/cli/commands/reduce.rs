//! `eomgen reduce MODEL --keep x [-o OUT.yaml]`: method II.2 of the constraint methods
//! (lectures 8–10, HW13), the holonomic constraints solved for the dependent coordinates and
//! substituted, which leaves a model file in minimal coordinates. The reduction is
//! [`eomgen_symbolic::model::reduce::reduce`]; this module reads the file, parses the options
//! and writes the text (to standard output, or replacing `-o`'s file atomically).

use clap::Args;
use eomgen_symbolic::model::reduce::{Branch, BranchReason, ReduceError, ReduceOptions, reduce};

use crate::cli::error::CliError;
use crate::cli::files::{self, Outputs};
use crate::cli::output::{errln, outln};

/// Options of `eomgen reduce`.
#[derive(Debug, Args)]
pub struct ReduceArgs {
    /// A model with holonomic constraints: a bundled name (`simple_pendulum_cartesian`) or
    /// the path of any model file.
    pub model: String,
    /// A coordinate to keep (repeat, or comma separated); the others are eliminated, one per
    /// holonomic constraint.
    #[arg(
        long,
        required = true,
        value_delimiter = ',',
        value_name = "COORDINATE"
    )]
    pub keep: Vec<String>,
    /// The branch of a quadratic solution, `y=-` or `y=+` (default: the one the initial
    /// state lies on, else the one of the first equilibrium that decides).
    #[arg(long, value_name = "COORDINATE=SIGN", allow_hyphen_values = true)]
    pub branch: Vec<String>,
    /// A new initial value of a kept coordinate or rate, `x=l/2` (an expression of the
    /// parameters): a start away from where the reduced coordinates are singular.
    #[arg(long, value_name = "NAME=VALUE", allow_hyphen_values = true)]
    pub initial: Vec<String>,
    /// The reduced model's name (default: `<name>_in_<kept coordinates>`).
    #[arg(long)]
    pub name: Option<String>,
    /// The file to write (default: standard output).
    #[arg(short = 'o', long = "output", value_name = "OUT.yaml")]
    pub output: Option<String>,
    /// Print the reduction as JSON (`ReducedModel`: the text, the eliminations with their
    /// branches, the notes) instead of the text; the file is still written with `-o`.
    #[arg(long)]
    pub json: bool,
}

/// Runs `reduce`.
pub fn run(args: &ReduceArgs) -> Result<(), CliError> {
    Outputs::new()
        .input(&args.model)
        .file("--output", args.output.as_deref())
        .check()?;
    let mut options = ReduceOptions {
        name: args.name.clone(),
        ..ReduceOptions::default()
    };
    for b in &args.branch {
        let (name, sign) = split(b, "--branch")?;
        let sign: Branch = sign
            .parse()
            .map_err(|e| CliError::usage(format!("--branch `{b}`: {e}")))?;
        options.branches.push((name, sign));
    }
    for i in &args.initial {
        options.initial.push(split(i, "--initial")?);
    }
    let (path, text) = crate::cli::model::read_model(&args.model)?;
    let file = eomgen_symbolic::model::load(&path, &text)
        .map_err(|d| crate::cli::model::diagnostics_error(&path, &text, &d))?;
    let keep: Vec<&str> = args.keep.iter().map(String::as_str).collect();
    let reduced = reduce(&file, &keep, &options).map_err(|e| match e {
        ReduceError::UnknownCoordinate { .. }
        | ReduceError::WrongCount { .. }
        | ReduceError::UnusedBranch { .. }
        | ReduceError::RepeatedBranch { .. }
        | ReduceError::BadName { .. }
        | ReduceError::BadInitial { .. } => CliError::usage(e.to_string()),
        // A start the user gave is their usage error; the file's own is the model's.
        ReduceError::SingularStart { .. } if !args.initial.is_empty() => {
            CliError::usage(format!("--initial: {e}"))
        }
        ReduceError::SingularStart { .. } => CliError::failure(format!(
            "{path}: {e} (--initial {}=VALUE)",
            keep.first().copied().unwrap_or("q")
        )),
        e => CliError::failure(format!("{path}: {e}")),
    })?;
    if args.json {
        if let Some(out) = &args.output {
            files::write(out, reduced.text.as_bytes())?;
        }
        return crate::cli::json::print_json_sorted(&reduced);
    }
    // The summary goes to standard error when the file goes to standard output.
    let mut summary = Vec::new();
    for e in &reduced.eliminations {
        let branch = match &e.branch {
            None => String::new(),
            Some((b, BranchReason::Option)) => format!("; branch {} as asked", b.sign()),
            Some((b, BranchReason::InitialState)) => {
                format!("; branch {}: the initial state's", b.sign())
            }
            Some((b, BranchReason::Equilibrium(q))) => format!(
                "; branch {}: the equilibrium `{q}`'s (the initial state is where the branches meet)",
                b.sign()
            ),
        };
        let squared = if e.squared { ", squared" } else { "" };
        summary.push(format!(
            "eliminated {} = {}  (constraint `{}`, degree {}{squared}{branch})",
            e.coordinate, e.solution, e.constraint, e.degree
        ));
        summary.push(format!("           {}_dot = {}", e.coordinate, e.rate));
    }
    for n in &reduced.notes {
        summary.push(format!("note: {n}"));
    }
    match &args.output {
        Some(out) => {
            files::write(out, reduced.text.as_bytes())?;
            for line in &summary {
                outln!("{line}");
            }
            outln!(
                "wrote {out} ({} in {})",
                reduced.file.name.value,
                reduced.kept.join(", ")
            );
        }
        None => {
            for line in &summary {
                errln!("{line}");
            }
            files::write("-", reduced.text.as_bytes())?;
        }
    }
    Ok(())
}

/// `name=value` of `option`.
fn split(text: &str, option: &str) -> Result<(String, String), CliError> {
    match text.split_once('=') {
        Some((n, v)) if !n.trim().is_empty() && !v.trim().is_empty() => {
            Ok((n.trim().to_string(), v.trim().to_string()))
        }
        _ => Err(CliError::usage(format!(
            "{option} `{text}`: write NAME=VALUE"
        ))),
    }
}
