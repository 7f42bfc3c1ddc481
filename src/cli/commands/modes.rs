//! `eomgen modes MODEL`: equilibrium, exact linearisation `M δq̈ + C δq̇ + K δq = 0`, normal
//! modes and damping (issue 7; lectures 22–26, 30).

use std::io::Write as _;

use clap::Args;
use eomgen::analysis::vibration::{self, ModalAnalysis, ModalOptions};
use eomgen::{ModeKind, ModelInfo, Stability};
use nalgebra::DMatrix;

use crate::cli::error::CliError;
use crate::cli::json::print_json_sorted;
use crate::cli::operating_point::{OperatingPointArgs, point_failure};
use crate::cli::render::num;

/// Options of `eomgen modes`.
#[derive(Debug, Args)]
pub struct ModesArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any model file.
    pub model: String,
    #[command(flatten)]
    pub point: OperatingPointArgs,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Draw each mode shape on the mechanism: `PREFIX-mode<k>.svg` (`.png` when PREFIX ends
    /// in .png).
    #[arg(long, value_name = "PREFIX")]
    pub plot: Option<String>,
    /// Write the mode shapes moving, `q* + s ψₖ sin(ωₖ t)`, as one self-contained HTML page
    /// with a mode selector.
    #[arg(long, value_name = "FILE.html")]
    pub animate: Option<String>,
    /// Also give the state-space model `dy/dt = A y + B u`, `z = C y + D u` about the
    /// equilibrium found with the inputs at 0, for this input: a parameter that enters the
    /// forcing linearly (a load amplitude) or a coordinate's name (a unit generalized force on
    /// it); repeatable, one column of B each.
    #[arg(long, value_name = "NAME")]
    pub input: Vec<String>,
    /// An output of the state-space model: a coordinate, or its rate `NAME_dot`; repeatable
    /// (default: every coordinate). Needs --input.
    #[arg(long, value_name = "NAME", requires = "input")]
    pub output: Vec<String>,
}

/// Runs `modes`.
pub fn run(args: &ModesArgs) -> Result<(), CliError> {
    // The charts `PREFIX-mode<k>` (at most one per degree of freedom) and the page, checked
    // before the analysis.
    let mut model = args.point.model(&args.model)?;
    let num_dofs = model.num_dofs();
    let options = args.point.options(model.as_ref())?;
    if vibration::is_steady_motion(model.as_ref(), &options.start) {
        if !args.input.is_empty() {
            return Err(CliError::usage(format!(
                "--input: `{}` at this operating point is a steady motion (or has non-holonomic constraints); the state-space model is given about an equilibrium of an unconstrained model",
                model.description().name
            )));
        }
        if args.plot.is_some() || args.animate.is_some() {
            return Err(CliError::usage(format!(
                "`{}` at this operating point is a steady motion (or has non-holonomic constraints): its modes are eigenvectors of the reduced state matrix, which --plot and --animate do not draw",
                model.description().name
            )));
        }
        return steady(args, model.as_mut(), &options);
    }
    let charts: Vec<String> = match &args.plot {
        Some(prefix) => (1..=num_dofs)
            .map(|k| crate::cli::mode_plot::chart_path(prefix, k))
            .collect(),
        None => Vec::new(),
    };
    charts
        .iter()
        .fold(
            crate::cli::files::Outputs::new().input(&args.model),
            |outputs, path| outputs.chart("--plot", Some(path)),
        )
        .file("--animate", args.animate.as_deref())
        .check()?;
    let modal = vibration::modal_analysis(
        model.as_ref(),
        &ModalOptions {
            operating_point: options,
        },
    )
    .map_err(|e| point_failure(model.as_ref(), &e))?;
    if args.plot.is_some() {
        crate::cli::mode_plot::check_drawable(model.as_ref())?;
    }
    let modes = &modal.normal_modes;
    let equilibrium = &modal.operating_point.equilibrium;
    // Mode shapes in the model's coordinates (δq = N z with constraints).
    let shapes_q = modal.mode_shape_matrix();
    let summary = modal.summary(model.as_ref());
    let state_space = match args.input.is_empty() {
        true => None,
        false => Some(state_space(
            model.as_mut(),
            &modal.operating_point.guess,
            args,
        )?),
    };
    let charts = match &args.plot {
        Some(prefix) => {
            let charts = crate::cli::mode_plot::mode_charts(
                prefix,
                model.as_ref(),
                &equilibrium.q,
                modes,
                &shapes_q,
                !modal.is_undamped(),
            )?;
            crate::cli::mode_plot::remove_stale_charts(prefix, charts.len())?;
            charts
        }
        None => Vec::new(),
    };
    if let Some(path) = &args.animate {
        let page = crate::cli::animation::modes(
            model.as_ref(),
            &equilibrium.q,
            modes,
            &shapes_q,
            !modal.is_undamped(),
        )?;
        crate::cli::files::write(path, page.to_html().as_bytes())?;
    }
    let mut stdout = crate::cli::output::stdout();
    if args.json {
        print_json_sorted(&ModesJson {
            summary,
            state_space,
            charts: &charts,
            animation: &args.animate,
        })
    } else {
        print_text(
            &mut stdout,
            model.as_ref(),
            &modal,
            &summary.lagrange_multipliers,
            &charts,
            args,
        );
        if let Some(ss) = &state_space {
            print_state_space(&mut stdout, ss);
        }
        Ok(())
    }
}

/// The state-space model of `args`' inputs and outputs about the equilibrium near `guess`
/// ([`eomgen::state_space`]).
fn state_space(
    model: &mut dyn ModelInfo,
    guess: &[f64],
    args: &ModesArgs,
) -> Result<eomgen::StateSpace, CliError> {
    let inputs: Vec<&str> = args.input.iter().map(String::as_str).collect();
    let outputs: Vec<&str> = args.output.iter().map(String::as_str).collect();
    eomgen::state_space(model, guess, &inputs, &outputs).map_err(|e| match e {
        eomgen::FrfError::Modal(m) => crate::cli::operating_point::modal_failure(model, &m),
        e @ eomgen::FrfError::UnknownOutput { .. } => CliError::usage(format!("--output: {e}")),
        eomgen::FrfError::Constrained { .. } => CliError::usage(format!(
            "--input: `{}` has constraints; the state-space model is given for unconstrained models (write the model in independent coordinates, or see `eomgen reduce`)",
            model.description().name
        )),
        e => CliError::usage(format!("--input: {e}")),
    })
}

/// The state-space model's text: what the state, inputs and outputs are, then A, B, C, D.
fn print_state_space(stdout: &mut impl std::io::Write, ss: &eomgen::StateSpace) {
    let _ = writeln!(
        stdout,
        "state space  dx/dt = A x + B u, z = C x + D u about q* = [{}] (the inputs at 0)",
        ss.equilibrium
            .iter()
            .map(|x| format!("{:.10e}", num(*x)))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(stdout, "             x = [{}]", ss.states.join(", "));
    let _ = writeln!(stdout, "             u = [{}]", ss.inputs.join(", "));
    let _ = writeln!(stdout, "             z = [{}]", ss.outputs.join(", "));
    for (name, matrix) in [("A", &ss.a), ("B", &ss.b), ("C", &ss.c), ("D", &ss.d)] {
        print_matrix(stdout, name, matrix);
    }
}

/// `modes` at a steady motion: the steady motion, the reduced state, the eigenvalues and the
/// verdict.
fn steady(
    args: &ModesArgs,
    model: &mut dyn ModelInfo,
    options: &eomgen::analysis::vibration::OperatingPointOptions,
) -> Result<(), CliError> {
    let analysis = vibration::steady_motion_analysis(model, options).map_err(|e| match e {
        vibration::SteadyAnalysisError::OperatingPoint(e) => point_failure(model, &e),
        e => CliError::failure(format!("`{}`: {e}", model.description().name)),
    })?;
    let summary = analysis.summary(model);
    if args.json {
        return print_json_sorted(&summary);
    }
    let mut out = crate::cli::output::stdout();
    let p = &summary.operating_point;
    let show = |values: &std::collections::BTreeMap<String, f64>| {
        values
            .iter()
            .map(|(k, v)| format!("{k} = {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let lin = &summary.linearization;
    let (found, held): (std::collections::BTreeMap<String, f64>, _) =
        (p.qdot.clone().into_iter()).partition(|(k, _)| p.found_rates.contains(k));
    let held_text = match held.is_empty() {
        true => String::new(),
        false => format!("; rates held {}", show(&held)),
    };
    let _ = writeln!(out, "steady motion  {}: {}{held_text}", p.name, show(&p.q));
    if !found.is_empty() {
        let _ = writeln!(out, "rates found    {}", show(&found));
    }
    if !p.held_coordinates.is_empty() {
        let _ = writeln!(
            out,
            "held           {} (at the value given, not found)",
            p.held_coordinates.join(", ")
        );
    }
    if let Some(turn) = &p.turning {
        let [a, b] = &turn.plane;
        let radius = turn
            .radius
            .map_or_else(|| "infinite (straight)".to_string(), |r| r.to_string());
        let _ = writeln!(
            out,
            "turning frame  {a}_dot, {b}_dot constant in the frame turned by {}: Ω = {}_dot = {} rad/s, radius {radius}; linearised in that frame",
            turn.angle, turn.angle, turn.rate
        );
    }
    let _ = writeln!(
        out,
        "found          {} Gauss–Newton iterations, largest residual {:.3e}",
        p.iterations, p.residual
    );
    let _ = writeln!(out, "reduced state  {}", lin.states.join(", "));
    for (what, list) in [
        (
            "left out: ignorable coordinates",
            &lin.ignorable_coordinates,
        ),
        (
            "left out: rates constant to first order",
            &lin.constant_rates,
        ),
        ("solved: dependent coordinates", &lin.dependent_coordinates),
        ("solved: dependent rates", &lin.dependent_rates),
    ] {
        if !list.is_empty() {
            let _ = writeln!(out, "               {what}: {}", list.join(", "));
        }
    }
    let _ = writeln!(
        out,
        "jacobian       {}",
        if lin.exact_jacobian {
            "exact (generated)"
        } else {
            "central differences with Richardson extrapolation"
        }
    );
    let _ = writeln!(
        out,
        "eigenvalue           Re s (1/s)           Im s (rad/s)        ζ"
    );
    for (k, d) in summary.damped_modes.iter().enumerate() {
        let _ = writeln!(
            out,
            "{:>4}  {:>20.12}  {:>20}  {:>8.4}",
            k + 1,
            d.re,
            if d.im == 0.0 {
                "0".to_string()
            } else {
                format!("±{:.12}", d.im)
            },
            d.damping_ratio
        );
    }
    let verdict = match summary.stability {
        Stability::Stable { decay_rate } => {
            format!("stable: the slowest decays as e^(-{decay_rate:.6} t)")
        }
        Stability::MarginallyStable => format!(
            "marginally stable{}: no eigenvalue has a positive real part (stable to linear order only)",
            within_rounding(summary.rounded_real_part)
        ),
        Stability::Unstable { growth_rate } => format!("unstable: grows as e^({growth_rate:.6} t)"),
    };
    let _ = writeln!(out, "stability      {verdict}");
    Ok(())
}

/// What `modes --json` prints (see docs/cli.md): the library's summary with the files this
/// run wrote.
#[derive(serde::Serialize)]
struct ModesJson<'a> {
    #[serde(flatten)]
    summary: eomgen::analysis::vibration::ModesSummary,
    /// The state-space model of `--input` and `--output` (absent without `--input`).
    #[serde(skip_serializing_if = "Option::is_none")]
    state_space: Option<eomgen::StateSpace>,
    /// The mode-shape charts written (`--plot`).
    charts: &'a [String],
    /// The animation page written (`--animate`).
    animation: &'a Option<String>,
}

/// The text of `modes`: the equilibrium, M, K, C, the modes, the check, the files written.
fn print_text(
    stdout: &mut impl std::io::Write,
    model: &dyn ModelInfo,
    modal: &ModalAnalysis,
    multipliers: &std::collections::BTreeMap<String, f64>,
    charts: &[String],
    args: &ModesArgs,
) {
    let ModalAnalysis {
        linearization: lin,
        normal_modes: modes,
        m_inv_k_relative_difference: route_difference,
        stability,
        ..
    } = modal;
    let undamped = modal.is_undamped();
    print_operating_point(stdout, model, modal, multipliers);
    print_matrix(stdout, "M", &lin.mass_matrix);
    print_matrix(stdout, "K", &lin.stiffness_matrix);
    if !undamped {
        print_matrix(stdout, "C", &lin.damping_matrix);
    }
    print_mode_table(stdout, model, modal);
    write_stability(stdout, stability);
    // With a non-symmetric K the table is M⁻¹K's own (or its symmetric part's, under
    // flutter): the two routes do not compute the same thing, and no check is printed.
    if modes.stiffness_asymmetry <= 1e-12 {
        let _ = writeln!(
            stdout,
            "check      eigenvalues of M⁻¹K (lecture 22) vs the symmetric Cholesky route (lecture 24): max difference {route_difference:.1e} of max |ω²|",
            route_difference = num(route_difference)
        );
    }
    for path in charts {
        let _ = writeln!(stdout, "chart      {path}");
    }
    if let Some(path) = &args.animate {
        let _ = writeln!(stdout, "animation  {path}");
    }
}

/// The operating point of `modes`: the model, the equilibrium and Newton's work, a load set
/// aside, the constraint forces at rest and the entries of the Jacobians that were differenced.
fn print_operating_point(
    stdout: &mut impl std::io::Write,
    model: &dyn ModelInfo,
    modal: &ModalAnalysis,
    multipliers: &std::collections::BTreeMap<String, f64>,
) {
    let ModalAnalysis {
        operating_point: point,
        linearization: lin,
        minimal_coordinates: minimal,
        time_dependent_forcing: forcing,
        ..
    } = modal;
    let (label, equilibrium) = (&point.name, &point.equilibrium);
    let names = model.description().coordinate_names();
    let n = model.num_dofs();
    let _ = writeln!(
        stdout,
        "model      {} ({} dof)",
        model.description().name,
        n
    );
    let point: Vec<String> = names
        .iter()
        .zip(&equilibrium.q)
        .map(|(c, v)| format!("{c} = {v:.12e}", v = num(v)))
        .collect();
    let _ = writeln!(
        stdout,
        "equilibrium {label}: {} (Newton: {} iterations, max |F| = {:.1e})",
        point.join(", "),
        equilibrium.iterations,
        num(equilibrium.residual)
    );
    if let Some(forcing) = forcing {
        let _ = writeln!(
            stdout,
            "note       F depends on t through a load that enters neither M, C nor K: F(q*, 0, t) − F(q*, 0, t₀) reaches {change:.3e} on {coordinate} (t = {t:.6e} s, t₀ = {t0} s); its variation is set aside: the operating point above is the equilibrium under the load's value at t₀ (deflected by it where that value is not 0), and the modes below are those of the equations linearised there",
            change = num(forcing.largest_change),
            coordinate = forcing.coordinate,
            t = num(forcing.t),
            t0 = forcing.t0,
        );
    }
    if !lin.lagrange_multipliers.is_empty() {
        let forces: Vec<String> = multipliers
            .iter()
            .map(|(c, v)| format!("λ_{c} = {:.6e}", num(v)))
            .collect();
        let _ = writeln!(
            stdout,
            "constraints {} at rest; M, K, C below are in the minimal coordinates {} (δq = N z, N spanning the null space of J)",
            forces.join(", "),
            minimal.join(", ")
        );
    }
    if lin.differenced_entries > 0 {
        let _ = writeln!(
            stdout,
            "note       {} entries of ∂F/∂q, ∂F/∂q̇ are not finite here while F is (a removable singularity, such as d|v|/dv = 0/0 of quadratic drag at rest): K and C use forward differences of F there, as the implicit integrators do",
            lin.differenced_entries
        );
    }
}

/// The modes of `modes`: the notes on a non-symmetric `K`, then one row per mode (ω, f, ζ and
/// the mass-normalised shape, with what a zero or unstable mode means).
fn print_mode_table(
    stdout: &mut impl std::io::Write,
    model: &dyn ModelInfo,
    modal: &ModalAnalysis,
) {
    let ModalAnalysis {
        normal_modes: modes,
        mode_shapes: shapes,
        damping_ratios,
        ..
    } = modal;
    let names = model.description().coordinate_names();
    let undamped = modal.is_undamped();
    if modes.symmetric_part_only {
        let _ = writeln!(
            stdout,
            "note       K is not symmetric (‖K − Kᵀ‖/‖K‖ = {:.2e}) and M⁻¹K has complex eigenvalues (flutter): the table is of K's symmetric part, not the system's modes; the stability line is the system's",
            num(modes.stiffness_asymmetry)
        );
    } else if modes.stiffness_asymmetry > 1e-12 {
        let _ = writeln!(
            stdout,
            "note       K is not symmetric (‖K − Kᵀ‖/‖K‖ = {:.2e}): the modes are those of M⁻¹K (K ψ = ω² M ψ, each ψᵀMψ = 1; they are not M-orthogonal)",
            num(modes.stiffness_asymmetry)
        );
    }
    let _ = writeln!(
        stdout,
        "{:>4}  {:>18}  {:>14}  {:>10}  mode shape (mass-normalised; {})",
        "mode",
        "undamped ω (rad/s)",
        "f (Hz)",
        "ζ",
        names.join(", ")
    );
    for (k, shape) in shapes.iter().enumerate() {
        let w = modes.natural_frequencies[k];
        let note = match modes.kinds[k] {
            ModeKind::Oscillatory => String::new(),
            ModeKind::ZeroFrequency => "  zero-frequency".to_string(),
            // Of K's symmetric part only: no verdict at all.
            ModeKind::Unstable { .. } if modes.symmetric_part_only => {
                "  ω² < 0 for K's symmetric part (no verdict: see the stability line)".to_string()
            }
            // From K alone: the verdict of the whole linearisation only when C = 0.
            ModeKind::Unstable { growth_rate } if undamped => {
                format!(
                    "  unstable, grows as e^({growth_rate:.6e} t)",
                    growth_rate = num(growth_rate)
                )
            }
            ModeKind::Unstable { growth_rate } => {
                format!(
                    "  ω² < 0: without C it would grow as e^({growth_rate:.6e} t)",
                    growth_rate = num(growth_rate)
                )
            }
        };
        let shape: Vec<String> = shape
            .iter()
            .map(|v| format!("{:>11.4e}", num(v + 0.0)))
            .collect();
        let zeta = damping_ratios
            .get(k)
            .map_or("-".to_string(), |z| format!("{z:.4e}", z = num(z)));
        let _ = writeln!(
            stdout,
            "{:>4}  {:>18.10e}  {:>14.6e}  {:>10}  [{}]{note}",
            k + 1,
            num(w),
            num(w / std::f64::consts::TAU),
            zeta,
            shape.join(", ")
        );
    }
}

/// ` (within rounding: |Re s| ≤ 3.2e-15 1/s set to 0)` when a marginal verdict was decided
/// by setting real parts at rounding to 0, nothing otherwise.
fn within_rounding(rounded_real_part: f64) -> String {
    if rounded_real_part > 0.0 {
        format!(
            " (within rounding: |Re s| ≤ {:.1e} 1/s set to 0)",
            num(rounded_real_part)
        )
    } else {
        String::new()
    }
}

/// The verdict of the whole linearisation (`C` included) and, with a gyroscopic part, its
/// size and the frequencies with it.
fn write_stability(out: &mut impl std::io::Write, s: &eomgen::LinearStability) {
    let on_axis = s.eigenvalues.iter().filter(|e| e.re == 0.0).count();
    let verdict = match s.stability {
        Stability::Stable { decay_rate } => format!(
            "stable: every eigenvalue of the linearisation has Re s < 0, the slowest decaying as e^(-{:.6e} t)",
            num(decay_rate)
        ),
        Stability::MarginallyStable => format!(
            "marginally stable{}: no eigenvalue of the linearisation has Re s > 0, {on_axis} of {} lie on the imaginary axis",
            within_rounding(s.rounded_real_part),
            s.eigenvalues.len()
        ),
        Stability::Unstable { growth_rate } => format!(
            "unstable: the largest Re s of the linearisation grows as e^({:.6e} t)",
            num(growth_rate)
        ),
    };
    let _ = writeln!(out, "stability  {verdict}");
    if let Some(frequencies) = &s.gyroscopic_frequencies {
        let w: Vec<String> = frequencies
            .iter()
            .map(|w| format!("{:.10e}", num(w)))
            .collect();
        let listed = if w.is_empty() {
            "none on the imaginary axis".to_string()
        } else {
            format!("{} rad/s", w.join(", "))
        };
        let _ = writeln!(
            out,
            "gyroscopic C has a skew part G = (C − Cᵀ)/2 (max |G| = {:.6e}); the frequencies of M q̈ + G q̇ + K q = 0: {listed}",
            num(s.gyroscopic_part.amax())
        );
    }
}

fn print_matrix(out: &mut impl std::io::Write, name: &str, m: &DMatrix<f64>) {
    for i in 0..m.nrows() {
        let row: Vec<String> = m
            .row(i)
            .iter()
            .map(|v| format!("{v:>13.6e}", v = num(v)))
            .collect();
        let label = if i == 0 {
            format!("{name} =")
        } else {
            String::new()
        };
        let _ = writeln!(out, "{label:<10} [{}]", row.join(", "));
    }
}
