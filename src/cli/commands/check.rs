//! `eomgen check MODEL|FILE.yaml`: derive a model two ways at run time and cross-check.

use clap::Args;

use crate::cli::error::CliError;
use crate::cli::json::print_json_sorted;
use crate::cli::output::outln;
use crate::cli::render::num;
use eomgen_symbolic::mechanics::cross_check::{
    CHECK_SEED, CHECK_TOLERANCE as TOLERANCE, CheckReport, DEFAULT_CHECK_STATES,
    INITIAL_CONSTRAINT_TOLERANCE, check_model,
};

/// Options of `eomgen check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// A bundled model's name, or the path of any model file (`path/to/x.yaml`).
    pub model: String,
    /// Number of random states (1 to 100000).
    #[arg(long, default_value_t = DEFAULT_CHECK_STATES, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=100_000))]
    pub states: usize,
    /// Print the report as JSON (byte-identical across runs: derivation times are left out
    /// unless `--timing` is given).
    #[arg(long)]
    pub json: bool,
    /// Add the derivation times (`derivation.<name>.time_s`) to the JSON output.
    #[arg(long)]
    pub timing: bool,
}

/// Runs `check`.
pub fn run(args: &CheckArgs) -> Result<(), CliError> {
    let (display, source) = crate::cli::model::read_model(&args.model)?;
    let file = eomgen_symbolic::model::load(&display, &source)
        .map_err(|d| crate::cli::model::diagnostics_error(&display, &source, &d))?;
    let report = check_model(&file, args.states, CHECK_SEED).map_err(|diagnostics| {
        crate::cli::model::diagnostics_error(&display, &source, &diagnostics)
    })?;
    if args.json {
        print_json_sorted(&report.summary(TOLERANCE, args.timing))?;
    } else {
        print_report(&report);
    }
    if report.passed(TOLERANCE) {
        Ok(())
    } else if let Some(reason) = report.states.nothing_compared() {
        Err(CliError::failure(format!(
            "`{}` failed: {reason}",
            report.model
        )))
    } else {
        Err(CliError::failure(format!(
            "`{}` failed a check (tolerance {TOLERANCE:e})",
            report.model,
            TOLERANCE = num(TOLERANCE)
        )))
    }
}

fn print_report(r: &CheckReport) {
    let mark = |ok: bool| if ok { "ok  " } else { "FAIL" };
    outln!("model {}", r.model);
    if let Some(reason) = r.states.nothing_compared() {
        // A residual over no state measured nothing: no 0.00 for it.
        outln!("FAIL {reason}");
        for c in &r.comparisons {
            outln!("FAIL {} vs {}: not compared", c.a, c.b);
        }
        if r.power_balance.is_some() {
            outln!("FAIL power balance dE/dt = Q·q': not compared");
        }
    }
    let sampled = r.states.compared > 0;
    for c in r.comparisons.iter().filter(|_| sampled) {
        // NaN: `b` was not finite at a state where `a` was (the note says more).
        let residual = if c.max_rel_residual.is_nan() {
            "not finite".to_string()
        } else {
            format!("{:.2e}", num(c.max_rel_residual))
        };
        let symbolic = if c.expect_disagreement {
            "expected to disagree"
        } else {
            match c.symbolic_equal {
                Some(true) => "symbolically equal: yes",
                Some(false) => "symbolically equal: no",
                None => "symbolically equal: not applicable",
            }
        };
        // Kane's equations are in generalized speeds, whose rates the comparison solves for.
        let accelerations = if c.b == "kane" { "u'" } else { "q''" };
        outln!(
            "{} {a} vs {b}: relative residual of {b} at {a}'s {accelerations} {residual}, the worst of {} states; {symbolic}",
            mark(c.passed(TOLERANCE)),
            c.states,
            a = c.a,
            b = c.b,
        );
    }
    if let Some(p) = r.power_balance.as_ref().filter(|_| sampled) {
        outln!(
            "{} power balance dE/dt = Q·q': max relative residual {:.2e}",
            mark(p.max_rel_residual <= TOLERANCE),
            num(p.max_rel_residual)
        );
    }
    if let Some(c) = &r.initial_constraints {
        outln!(
            "{} initial state satisfies the constraints: largest residual {:.2e} ({} of `{}`, tolerance {INITIAL_CONSTRAINT_TOLERANCE:e})",
            mark(c.passed()),
            num(c.residual),
            if c.velocity {
                "velocity residual"
            } else {
                "residual"
            },
            c.constraint
        );
        if !c.passed() {
            outln!(
                "     correct `initial:`, or in the rates mark the dependent coordinates as `{{ guess: … }}` to have them solved from the constraints (in generalized speeds, give the speeds, and coordinates on the holonomic constraints: the auxiliary speeds start at 0)"
            );
        }
    }
    let width = r
        .derivations
        .iter()
        .map(|d| d.name.chars().count())
        .max()
        .unwrap_or(0)
        .max(9);
    for d in &r.derivations {
        outln!(
            "     {:<width$} derived in {:.3} ms: {} operations, {} after CSE",
            d.name,
            d.time_s * 1e3,
            d.ops,
            d.ops_after_cse
        );
    }
    for n in &r.notes {
        outln!("note {n}");
    }
}
