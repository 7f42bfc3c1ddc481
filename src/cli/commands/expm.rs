//! `eomgen study expm` (HW32, lectures 30–33): `ż = A z` for a random real `n × n` `A`
//! (or one given with `--matrix`) solved three ways — `e^{At} z₀`, the superposition of the
//! complex eigenvector solutions and DOP853 — with the eigenvalues, the condition number of
//! the eigenvector matrix and the largest differences between the routes.
//!
//! The numbers come from [`eomgen::analysis::vibration::expm_study()`]; this module renders
//! them. Exit 1 when two routes differ by more than their stated bound.

use clap::Args;
use eomgen::analysis::StudyRuns;
use eomgen::analysis::vibration::{
    self, EigenvectorOutcome, ExpmOptions, ExpmRoute, ExpmStudy, ExpmStudyError,
};

use crate::cli::error::CliError;
use crate::cli::json::print_json_sorted;
use crate::cli::render::num;
use crate::cli::values::evaluate;

/// Options of `eomgen study expm`.
#[derive(Debug, Args)]
pub struct ExpmArgs {
    /// Size of the random A (entries N(0, 1)/√n, spectrum in about the unit disc); 1 to 150
    /// (the eigenvector route costs O(n⁴): 4 processor-seconds at 150).
    #[arg(long, default_value_t = ExpmOptions::DEFAULT_N, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=ExpmOptions::LARGEST_SIZE as u64))]
    pub n: usize,
    /// Seed of the random A and z₀ (SplitMix64; the same numbers on every platform).
    #[arg(long, default_value_t = ExpmOptions::DEFAULT_SEED)]
    pub seed: u64,
    /// End time (s), in [1e-6, 1e6].
    #[arg(long = "t", default_value_t = ExpmOptions::DEFAULT_T_END, value_parser = crate::cli::values::study_end_time, allow_hyphen_values = true)]
    pub t_end: f64,
    /// Number of sample times, evenly spaced from 0 to the end time (2 to 100000).
    #[arg(long, default_value_t = ExpmOptions::DEFAULT_SAMPLES, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(2..=100_000))]
    pub samples: usize,
    /// Relative and absolute tolerance of the DOP853 integration.
    #[arg(long, default_value_t = ExpmOptions::DEFAULT_TOL, value_parser = crate::cli::values::relative_tolerance, allow_hyphen_values = true)]
    pub tol: f64,
    /// A given instead of the random one: rows separated by `;`, entries by `,`, each a
    /// number or an expression (`0,1;-1,0`); `--n` is then its size, z₀ still the seed's.
    #[arg(long, value_name = "ROWS", allow_hyphen_values = true)]
    pub matrix: Option<String>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// `--matrix` as rows of numbers.
fn parse_matrix(text: &str) -> Result<Vec<Vec<f64>>, CliError> {
    text.split(';')
        .enumerate()
        .map(|(i, row)| {
            row.split(',')
                .enumerate()
                .map(|(j, entry)| {
                    evaluate(
                        entry.trim(),
                        &format!("--matrix row {}, entry {}", i + 1, j + 1),
                        &|_| None,
                    )
                })
                .collect()
        })
        .collect()
}

/// Runs `study expm`.
pub fn run(args: &ExpmArgs) -> Result<(), CliError> {
    let options = ExpmOptions {
        n: args.n,
        seed: args.seed,
        t_end: args.t_end,
        samples: args.samples,
        tol: args.tol,
        matrix: args.matrix.as_deref().map(parse_matrix).transpose()?,
    };
    let study = vibration::expm_study(&options).map_err(|e| match e {
        ExpmStudyError::MatrixNotSquare { .. } | ExpmStudyError::InvalidSize { .. } => {
            CliError::usage(format!("--matrix: {e}"))
        }
        ExpmStudyError::ZeroSolution => CliError::usage(format!("{e}; try another --seed")),
        e => CliError::failure(format!("study expm: {e}")),
    })?;
    study
        .check_measured()
        .map_err(|e| CliError::failure(e.to_string()))?;
    if args.json {
        print_json_sorted(&study)?;
    } else {
        print_text(&mut crate::cli::output::stdout(), &options, &study);
    }
    match study.differences.iter().find(|d| !d.passed) {
        None => Ok(()),
        Some(d) if !d.checked => Err(CliError::failure(format!(
            "study expm: the bound {:.1e} on {} against {} tests nothing (at or above {:.0e}: the tolerance, the time scales the samples span or the transient growth of a non-normal A make it that large), so the routes are not compared; tighten --tol or shorten --t",
            num(d.tolerance),
            d.a.name(),
            d.b.name(),
            ExpmOptions::LARGEST_BOUND
        ))),
        Some(d) => Err(CliError::failure(format!(
            "study expm: {} and {} differ by {:.2e} of the solution's scale, above the bound {:.1e}",
            d.a.name(),
            d.b.name(),
            num(d.relative),
            num(d.tolerance)
        ))),
    }
}

/// The text of `study expm`: the problem, the eigenvalues, `κ(V)`, the routes and their
/// largest differences.
fn print_text(stdout: &mut impl std::io::Write, options: &ExpmOptions, study: &ExpmStudy) {
    let n = study.initial_state.len();
    let what = if options.matrix.is_some() {
        "given".to_string()
    } else {
        format!("random, Aᵢⱼ ~ N(0, 1)/√n, seed {}", options.seed)
    };
    let t_end = study.times.last().copied().unwrap_or(0.0);
    let _ = writeln!(
        stdout,
        "A          {n} × {n} {what}; z₀ random (seed {}), |z₀| = 1",
        options.seed
    );
    let _ = writeln!(
        stdout,
        "times      0 ≤ t ≤ {t_end:e} s, {} samples; largest |zᵢ| = {:.6e}, |z({t_end:e})|/|z₀| = {:.6e}",
        study.times.len(),
        num(study.scale),
        num(study.final_growth),
        t_end = num(t_end)
    );
    let _ = writeln!(stdout, "eigenvalues λ of A (1/s):");
    for l in study.eigenvalues.iter().filter(|l| l.im >= 0.0) {
        if l.im > 0.0 {
            let _ = writeln!(stdout, "  {:>+.10e} ± {:.10e} i", num(l.re), num(l.im));
        } else {
            let _ = writeln!(stdout, "  {:>+.10e}", num(l.re));
        }
    }
    match study.eigenvector_condition {
        Some(k) => {
            let _ = writeln!(
                stdout,
                "κ(V)       {:.3e}: condition number of the eigenvector matrix (unit columns); the eigenvector route loses about {:.1} digits",
                num(k),
                k.log10().max(0.0)
            );
        }
        None => {
            let _ = writeln!(
                stdout,
                "κ(V)       ∞: A is defective (a repeated eigenvalue with too few eigenvectors, a Jordan block)"
            );
        }
    }
    for (i, route) in ExpmRoute::ALL.iter().enumerate() {
        let _ = writeln!(
            stdout,
            "route {}    {}: {}",
            i + 1,
            route.name(),
            route.description()
        );
    }
    if let EigenvectorOutcome::Refused { reason } = &study.eigenvectors {
        let _ = writeln!(stdout, "refused    eigenvectors: {reason}");
    }
    let _ = writeln!(
        stdout,
        "largest differences over the samples, relative to the largest |zᵢ| (bound):"
    );
    for d in &study.differences {
        let _ = writeln!(
            stdout,
            "  {:<12} vs {:<12} {:>9.2e} (≤ {:.1e})  {}",
            d.a.name(),
            d.b.name(),
            num(d.relative),
            num(d.tolerance),
            match (d.checked, d.passed) {
                (false, _) => "unchecked (the bound tests nothing)",
                (true, true) => "ok",
                (true, false) => "FAILED",
            }
        );
    }
}
