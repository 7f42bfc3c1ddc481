//! `eomgen study modal-damping MODEL` (HW34, lectures 30–33): damping ratios and damped
//! frequencies of each mode three ways — exact (complex eigenvalues of A), the modal-damping
//! approximation (diagonal of Ĉ = ΨᵀCΨ) and Rayleigh damping C = αM + βK fitted to two modes —
//! and the free responses from each mode shape: exact (e^{At}, checked by DOP853) against the
//! two approximations, as a table, JSON and a chart.

use clap::Args;
use eomgen::ModelInfo;
use eomgen::analysis::StudyRuns;
use eomgen::analysis::vibration::{
    ModalDampingOptions, ModalDampingStudy, ModeDamping, RayleighFit,
};

use crate::cli::error::CliError;
use crate::cli::files::Outputs;
use crate::cli::json::print_json_sorted;
use crate::cli::operating_point::OperatingPointArgs;
use crate::cli::plot::Series;
use crate::cli::render::num;
use crate::cli::response_study::{Panel, panels, parse_init, study_failure};

/// Options of `eomgen study modal-damping`.
#[derive(Debug, Args)]
pub struct ModalDampingArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any model file, with a
    /// damping matrix (`three_masses_damped`).
    pub model: String,
    #[command(flatten)]
    pub point: OperatingPointArgs,
    /// The two modes (1-based, ascending frequency) whose exact damping ratios the Rayleigh
    /// damping C = αM + βK reproduces. Default: the slowest and the fastest oscillatory modes
    /// (HW34).
    #[arg(long, value_delimiter = ',', value_name = "K1,K2")]
    pub rayleigh_modes: Option<Vec<usize>>,
    /// One initial deviation instead of HW34's releases from each mode shape: `NAME=VALUE`
    /// for a coordinate or a rate (`x1_dot`), comma separated or repeated; the others 0.
    #[arg(long, value_name = "NAME=VALUE,…")]
    pub init: Vec<String>,
    /// End time (s). Default: ten periods of the slowest oscillatory mode.
    #[arg(long, value_parser = crate::cli::values::study_end_time, allow_hyphen_values = true)]
    pub t_end: Option<f64>,
    /// Number of output times, evenly spaced from 0 to the end time (2 to 1000000).
    #[arg(long, default_value_t = ModalDampingOptions::DEFAULT_SAMPLES, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(2..=1_000_000))]
    pub samples: usize,
    /// Relative and absolute tolerance of the DOP853 check of the exact response.
    #[arg(long, default_value_t = ModalDampingOptions::DEFAULT_TOL, value_parser = crate::cli::values::relative_tolerance, allow_hyphen_values = true)]
    pub tol: f64,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Chart of the first coordinate against time for each release, exact and both
    /// approximations overlaid (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
}

/// Runs `study modal-damping`.
pub fn run(args: &ModalDampingArgs) -> Result<(), CliError> {
    Outputs::new()
        .input(&args.model)
        .chart("--plot", args.plot.as_deref())
        .check()?;
    let model = args.point.model(&args.model)?;
    let rayleigh_modes = match &args.rayleigh_modes {
        Some(list) => match list.as_slice() {
            [a, b] => Some([*a, *b]),
            _ => {
                return Err(CliError::usage(format!(
                    "--rayleigh-modes takes two modes (like 1,3), got {} numbers",
                    list.len()
                )));
            }
        },
        None => None,
    };
    let options = ModalDampingOptions {
        operating_point: args.point.options(model.as_ref())?,
        rayleigh_modes,
        initial: parse_init(model.as_ref(), &args.init)?,
        t_end: args.t_end,
        samples: args.samples,
        tol: args.tol,
    };
    let study = eomgen::analysis::vibration::modal_damping_study(model.as_ref(), &options)
        .map_err(|e| study_failure(model.as_ref(), &e))?;
    study
        .check_measured()
        .map_err(|e| CliError::failure(e.to_string()))?;
    let ModalDampingStudy {
        operating_point: point,
        rayleigh,
        releases: cases,
        ..
    } = &study;
    let label = &point.name;
    let names = model.description().coordinate_names();
    if let Some(path) = &args.plot {
        let panel_list: Vec<Panel> = cases
            .iter()
            .map(|c| {
                let mut series = vec![
                    Series {
                        name: "exact, e^{At}".to_string(),
                        points: c.exact.coordinate_history(0),
                    },
                    Series {
                        name: "DOP853".to_string(),
                        points: c.integrated.coordinate_history(0),
                    },
                    Series {
                        name: "diagonal of Ĉ".to_string(),
                        points: c.diagonal.coordinate_history(0),
                    },
                ];
                if let (Some(r), Some(RayleighFit { modes: [a, b], .. })) = (&c.rayleigh, rayleigh)
                {
                    series.push(Series {
                        name: format!("Rayleigh, modes {a} and {b}"),
                        points: r.coordinate_history(0),
                    });
                }
                Panel {
                    caption: Some(format!("release from {}, at rest", c.name)),
                    y_desc: format!("δ{} (m or rad)", names[0]),
                    series,
                }
            })
            .collect();
        let title = format!(
            "{} at {label}: damped free response (HW34)",
            model.description().name
        );
        panels(path, &title, &panel_list).map_err(CliError::failure)?;
    }

    let mut stdout = crate::cli::output::stdout();
    if args.json {
        print_json_sorted(&study.summary(model.as_ref()))?;
        return Ok(());
    }
    print_report(&mut stdout, model.as_ref(), &study);
    Ok(())
}

/// The text of `study`.
fn print_report(
    stdout: &mut impl std::io::Write,
    model: &dyn ModelInfo,
    study: &ModalDampingStudy,
) {
    let ModalDampingStudy {
        operating_point: point,
        modal_damping: approx,
        rayleigh,
        modes: per_mode,
        t_end,
        releases: cases,
        normal_modes,
        ..
    } = study;
    let label = &point.name;
    let n = model.num_dofs();
    let samples = cases.first().map_or(0, |c| c.exact.times.len());
    let _ = writeln!(
        stdout,
        "model      {} ({} dof) at {label}: M δq̈ + C δq̇ + K δq = 0",
        model.description().name,
        n
    );
    let _ = writeln!(
        stdout,
        "Ĉ = {}CΨ  off-diagonal coupling max|Ĉᵢⱼ|/max|Ĉₖₖ| = {:.4e}{}",
        normal_modes.projector_label(),
        num(approx.coupling),
        if approx.coupling == 0.0 {
            " (diagonal: the modal approximation is exact)"
        } else {
            ""
        }
    );
    for i in 0..n {
        let row: Vec<String> = approx
            .modal_damping_matrix
            .row(i)
            .iter()
            .map(|v| format!("{:>12.5e}", num(v + 0.0))) // −0 prints as 0
            .collect();
        let _ = writeln!(stdout, "           [{}]", row.join(", "));
    }
    match rayleigh {
        Some(RayleighFit {
            modes: [a, b],
            damping: fit,
        }) => {
            let _ = writeln!(
                stdout,
                "Rayleigh   C = αM + βK fitted to the exact ζ of modes {a} and {b}: α = {:.6e} 1/s, β = {:.6e} s",
                num(fit.alpha),
                num(fit.beta)
            );
        }
        None => {
            let _ = writeln!(
                stdout,
                "Rayleigh   not fitted: fewer than two underdamped oscillatory modes"
            );
        }
    }
    print_mode_table(stdout, per_mode);
    let _ = writeln!(
        stdout,
        "responses  0 ≤ t ≤ {t_end:.4} s, {samples} samples; max |δq| differences from e^{{At}}, relative to its largest |δq|:"
    );
    let _ = writeln!(
        stdout,
        "  {:<36} {:>12} {:>14} {:>12}",
        "release", "DOP853", "diagonal Ĉ", "Rayleigh"
    );
    for c in cases {
        let _ = writeln!(
            stdout,
            "  {:<36} {:>12.2e} {:>14.2e} {:>12}",
            c.name,
            num(c.integration_vs_exact),
            num(c.diagonal_vs_exact),
            c.rayleigh_vs_exact
                .map_or("-".to_string(), |r| format!("{r:.2e}", r = num(r)))
        );
    }
}

/// Each mode's `ω`, and its `ζ` and `ω_d` exactly, with the diagonal of `Ĉ` and with the
/// Rayleigh fit.
fn print_mode_table(stdout: &mut impl std::io::Write, per_mode: &[ModeDamping]) {
    let opt = |v: Option<f64>, width: usize| match v {
        Some(x) => format!("{:>width$.6e}", num(x + 0.0)),
        None => format!("{:>width$}", "-"),
    };
    let _ = writeln!(
        stdout,
        "{:>4} {:>13} | {:>13} {:>13} | {:>13} {:>13} | {:>13} {:>13}",
        "mode",
        "ω (rad/s)",
        "ζ exact",
        "ω_d exact",
        "ζ diag Ĉ",
        "ω_d diag Ĉ",
        "ζ Rayleigh",
        "ω_d Rayleigh"
    );
    for m in per_mode {
        let _ = writeln!(
            stdout,
            "{:>4} {:>13.6e} | {} {} | {} {} | {} {}",
            m.mode,
            num(m.natural_frequency),
            opt(m.exact.map(|d| d.damping_ratio), 13),
            opt(m.exact.map(|d| d.damped_frequency), 13),
            opt(m.diagonal.map(|d| d.damping_ratio), 13),
            opt(m.diagonal.and_then(|d| d.damped_frequency), 13),
            opt(m.rayleigh.map(|d| d.damping_ratio), 13),
            opt(m.rayleigh.and_then(|d| d.damped_frequency), 13),
        );
    }
}
