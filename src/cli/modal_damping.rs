//! `eomgen study modal-damping MODEL` (HW34, lectures 30–33): damping ratios and damped
//! frequencies of each mode three ways — exact (complex eigenvalues of A), the modal-damping
//! approximation (diagonal of Ĉ = ΨᵀCΨ) and Rayleigh damping C = αM + βK fitted to two modes —
//! and the free responses from each mode shape: exact (e^{At}, checked by DOP853) against the
//! two approximations, as a table, JSON and a chart.

use std::io::Write as _;

use clap::Args;
use eomgen::{FreeResponse, ModeKind, RayleighDamping};
use serde_json::json;

use super::CliError;
use super::free_response::{Panel, kind_json, panels, parse_init, study_failure};
use super::modes::{OperatingPointArgs, matrix_rows, point_json};
use super::plot::Series;

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
    #[arg(long)]
    pub t_end: Option<f64>,
    /// Number of output times, evenly spaced from 0 to the end time.
    #[arg(long, default_value_t = 801)]
    pub samples: usize,
    /// Relative and absolute tolerance of the DOP853 check of the exact response.
    #[arg(long, default_value_t = 1e-12)]
    pub tol: f64,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Chart of the first coordinate against time for each release, exact and both
    /// approximations overlaid (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
}

/// One release: its initial values and the four responses.
struct Case {
    name: String,
    q0: Vec<f64>,
    v0: Vec<f64>,
    exact: FreeResponse,
    integrated: FreeResponse,
    diagonal: FreeResponse,
    rayleigh: Option<FreeResponse>,
}

/// `ζ` and `ω_d = ω√(1 − ζ²)` of a mode of natural frequency `ω` (`None` when overdamped).
fn damped_frequency(omega: f64, zeta: f64) -> Option<f64> {
    (zeta.abs() < 1.0).then(|| omega * (1.0 - zeta * zeta).sqrt())
}

/// Runs `study modal-damping`.
pub fn run(args: &ModalDampingArgs) -> Result<(), CliError> {
    let model = args.point.model(&args.model)?;
    let modal = eomgen::vibration::unconstrained_modal_analysis(
        model.as_ref(),
        &args.point.options(model.as_ref())?,
    )
    .map_err(|e| study_failure(model.as_ref(), &e))?;
    let (label, lin, modes) = (
        modal.operating_point.name,
        modal.linearization,
        modal.normal_modes,
    );
    let n = model.num_dofs();
    let names = model.coordinate_names();
    let fail =
        |e: eomgen::ResponseError| super::free_response::response_failure(model.as_ref(), &e);
    let approx = eomgen::modal_damping(&lin, &modes);
    let exact = eomgen::exact_damped_modes(&lin, &modes).map_err(fail)?;
    let oscillatory: Vec<usize> = (0..n)
        .filter(|&k| modes.kinds[k] == ModeKind::Oscillatory)
        .collect();

    // The Rayleigh fit: explicit modes must be usable; by default the slowest and fastest
    // oscillatory modes, if there are two with exact damping ratios.
    let chosen: Option<[usize; 2]> = match &args.rayleigh_modes {
        Some(list) => {
            let [a, b] = list.as_slice() else {
                return Err(CliError::usage(format!(
                    "--rayleigh-modes takes two modes (like 1,3), got {} numbers",
                    list.len()
                )));
            };
            for &k in [a, b] {
                if k == 0 || k > n {
                    return Err(CliError::usage(format!(
                        "--rayleigh-modes: mode {k} does not exist; `{}` has modes 1 to {n}",
                        model.name()
                    )));
                }
                if exact[k - 1].is_none() {
                    return Err(CliError::usage(format!(
                        "--rayleigh-modes: mode {k} is not an underdamped oscillation (no complex eigenvalue to fit)"
                    )));
                }
            }
            Some([*a, *b])
        }
        None => match (oscillatory.first(), oscillatory.last()) {
            (Some(&a), Some(&b)) if a != b && exact[a].is_some() && exact[b].is_some() => {
                Some([a + 1, b + 1])
            }
            _ => None,
        },
    };
    let rayleigh = match chosen {
        Some([a, b]) => {
            let zeta = |k: usize| exact[k - 1].map_or(f64::NAN, |d| d.damping_ratio);
            let fit = RayleighDamping::fit(
                [
                    modes.natural_frequencies[a - 1],
                    modes.natural_frequencies[b - 1],
                ],
                [zeta(a), zeta(b)],
            )
            .map_err(|e| CliError::usage(format!("--rayleigh-modes {a},{b}: {e}")))?;
            Some(([a, b], fit))
        }
        None => None,
    };

    // The releases: HW34's mode shapes (first coordinate 1, or the largest entry if the
    // first is zero), or one given deviation.
    if !(args.tol.is_finite() && args.tol > 0.0) {
        return Err(CliError::usage("--tol must be positive"));
    }
    let t_end = args
        .t_end
        .unwrap_or_else(|| eomgen::vibration::default_duration(&modes, 10.0, 5.0));
    let times = eomgen::vibration::uniform_times(t_end, args.samples)
        .map_err(|e| study_failure(model.as_ref(), &e))?;
    let mut releases: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
    if args.init.is_empty() {
        for k in 0..n {
            let shape = modes.mode_shapes.column(k);
            let largest = shape.amax();
            let j = if shape[0].abs() > 1e-8 * largest {
                0
            } else {
                shape.iamax()
            };
            let q0: Vec<f64> = shape.iter().map(|v| v / shape[j]).collect();
            releases.push((
                format!("mode {} shape, {} = 1", k + 1, names[j]),
                q0,
                vec![0.0; n],
            ));
        }
    } else {
        let init = parse_init(model.as_ref(), &args.init)?;
        let (q0, v0) = (init.q, init.qdot);
        releases.push(("given initial values".to_string(), q0, v0));
    }
    let diagonal_damping = approx.diagonal();
    let mut cases = Vec::new();
    for (name, q0, v0) in releases {
        let exact_response =
            eomgen::response_by_exponential(&lin, &q0, &v0, &times).map_err(fail)?;
        let integrated =
            eomgen::response_by_integration(&lin, &q0, &v0, &times, args.tol).map_err(fail)?;
        let diagonal =
            eomgen::response_with_modal_damping(&lin, &modes, &diagonal_damping, &q0, &v0, &times)
                .map_err(fail)?;
        let rayleigh_response = match &rayleigh {
            Some((_, fit)) => Some(
                eomgen::response_with_modal_damping(
                    &lin,
                    &modes,
                    &fit.modal_damping(&modes),
                    &q0,
                    &v0,
                    &times,
                )
                .map_err(fail)?,
            ),
            None => None,
        };
        cases.push(Case {
            name,
            q0,
            v0,
            exact: exact_response,
            integrated,
            diagonal,
            rayleigh: rayleigh_response,
        });
    }
    // Differences from the exact response, relative to its largest |δq|.
    let versus = |case: &Case, other: &FreeResponse| -> f64 {
        let scale = case.exact.max_displacement();
        let d = case
            .exact
            .max_displacement_difference(other)
            .unwrap_or(f64::INFINITY);
        if scale > 0.0 { d / scale } else { d }
    };

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
                if let (Some(r), Some(([a, b], _))) = (&c.rayleigh, &rayleigh) {
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
        let title = format!("{} at {label}: damped free response (HW34)", model.name());
        panels(path, &title, &panel_list).map_err(CliError::failure)?;
    }

    let mut stdout = std::io::stdout().lock();
    if args.json {
        let out = json!({
            "model": model.name(),
            "coordinates": names,
            "operating_point": point_json(&label, &names, &lin.q),
            "mass_matrix": matrix_rows(&lin.mass_matrix),
            "stiffness_matrix": matrix_rows(&lin.stiffness_matrix),
            "damping_matrix": matrix_rows(&lin.damping_matrix),
            "modal_damping_matrix": matrix_rows(&approx.modal_damping_matrix),
            "coupling": approx.coupling,
            "rayleigh": rayleigh.as_ref().map(|(m, fit)| json!({
                "modes": m,
                "alpha": fit.alpha,
                "beta": fit.beta,
            })),
            "modes": (0..n).map(|k| {
                let w = modes.natural_frequencies[k];
                json!({
                    "mode": k + 1,
                    "kind": kind_json(&modes.kinds[k]),
                    "natural_frequency": w,
                    "exact": exact[k].map(|d| json!({
                        "re": d.eigenvalue.re,
                        "im": d.eigenvalue.im,
                        "damping_ratio": d.damping_ratio,
                        "damped_frequency": d.damped_frequency,
                    })),
                    "diagonal": approx.damping_ratios[k].map(|z| json!({
                        "damping_ratio": z,
                        "damped_frequency": approx.damped_frequencies[k],
                    })),
                    "rayleigh": match (&rayleigh, modes.kinds[k]) {
                        (Some((_, fit)), ModeKind::Oscillatory) => {
                            let z = fit.damping_ratio(w);
                            json!({"damping_ratio": z, "damped_frequency": damped_frequency(w, z)})
                        }
                        _ => serde_json::Value::Null,
                    },
                })
            }).collect::<Vec<_>>(),
            "t_end": t_end,
            "samples": times.len(),
            "tol": args.tol,
            "cases": cases.iter().map(|c| json!({
                "name": c.name,
                "q0": c.q0,
                "qdot0": c.v0,
                "amplitude": c.exact.max_displacement(),
                "integration_vs_exact": versus(c, &c.integrated),
                "diagonal_vs_exact": versus(c, &c.diagonal),
                "rayleigh_vs_exact": c.rayleigh.as_ref().map(|r| versus(c, r)),
            })).collect::<Vec<_>>(),
        });
        let text =
            serde_json::to_string_pretty(&out).map_err(|e| CliError::failure(e.to_string()))?;
        let _ = writeln!(stdout, "{text}");
        return Ok(());
    }

    let _ = writeln!(
        stdout,
        "model      {} ({} dof) at {label}: M δq̈ + C δq̇ + K δq = 0",
        model.name(),
        n
    );
    let _ = writeln!(
        stdout,
        "Ĉ = ΨᵀCΨ  off-diagonal coupling max|Ĉᵢⱼ|/max|Ĉₖₖ| = {:.4e}{}",
        approx.coupling,
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
            .map(|v| format!("{:>12.5e}", v + 0.0)) // −0 prints as 0
            .collect();
        let _ = writeln!(stdout, "           [{}]", row.join(", "));
    }
    match &rayleigh {
        Some(([a, b], fit)) => {
            let _ = writeln!(
                stdout,
                "Rayleigh   C = αM + βK fitted to the exact ζ of modes {a} and {b}: α = {:.6e} 1/s, β = {:.6e} s",
                fit.alpha, fit.beta
            );
        }
        None => {
            let _ = writeln!(
                stdout,
                "Rayleigh   not fitted: fewer than two underdamped oscillatory modes"
            );
        }
    }
    let opt = |v: Option<f64>, width: usize| match v {
        Some(x) => format!("{:>width$.6e}", x + 0.0),
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
    for (k, exact_k) in exact.iter().enumerate() {
        let w = modes.natural_frequencies[k];
        let z_r = match (&rayleigh, modes.kinds[k]) {
            (Some((_, fit)), ModeKind::Oscillatory) => Some(fit.damping_ratio(w)),
            _ => None,
        };
        let _ = writeln!(
            stdout,
            "{:>4} {:>13.6e} | {} {} | {} {} | {} {}",
            k + 1,
            w,
            opt(exact_k.map(|d| d.damping_ratio), 13),
            opt(exact_k.map(|d| d.damped_frequency), 13),
            opt(approx.damping_ratios[k], 13),
            opt(approx.damped_frequencies[k], 13),
            opt(z_r, 13),
            opt(z_r.and_then(|z| damped_frequency(w, z)), 13),
        );
    }
    let _ = writeln!(
        stdout,
        "responses  0 ≤ t ≤ {t_end:.4} s, {} samples; max |δq| differences from e^{{At}}, relative to its largest |δq|:",
        times.len()
    );
    let _ = writeln!(
        stdout,
        "  {:<36} {:>12} {:>14} {:>12}",
        "release", "DOP853", "diagonal Ĉ", "Rayleigh"
    );
    for c in &cases {
        let _ = writeln!(
            stdout,
            "  {:<36} {:>12.2e} {:>14.2e} {:>12}",
            c.name,
            versus(c, &c.integrated),
            versus(c, &c.diagonal),
            c.rayleigh
                .as_ref()
                .map_or("-".to_string(), |r| format!("{:.2e}", versus(c, r)))
        );
    }
    Ok(())
}
