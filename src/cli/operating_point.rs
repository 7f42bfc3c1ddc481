//! The operating point of the modal commands (`modes`, `frf`, and the studies
//! `free-response`, `modal-damping`, `floquet`): `--at` and `--set`, the start of the
//! equilibrium search, its JSON, and the errors of a failed search or modal analysis with
//! what to try.

use clap::Args;
use eomgen::ModelInfo;
use eomgen::analysis::vibration::{EquilibriumStart, OperatingPointError, OperatingPointOptions};

use super::error::CliError;
use super::model::find_smooth_model;
use super::values::{evaluate, parameter_lookup, set_parameters, split_assignment};

/// `--at` and `--set`, the same in `modes`, `frf` and the modal studies (`free-response`,
/// `modal-damping`, `floquet`).
#[derive(Debug, Args)]
pub struct OperatingPointArgs {
    /// Operating point: a name from the model's `equilibria:` (`hanging`, `upright`), or
    /// guesses `q1=VALUE,q2=VALUE` (others 0). Default: the model's first equilibrium, else
    /// q = 0. Newton on F(q, 0) = 0 starts there.
    #[arg(long)]
    pub at: Option<String>,
    /// Set a parameter, `NAME=VALUE`; repeatable.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
}

impl OperatingPointArgs {
    /// The bundled model `name` with `--set` applied.
    ///
    /// # Errors
    /// An unknown model, or a bad `--set` (see [`set_parameters`]).
    pub(super) fn model(&self, name: &str) -> Result<Box<dyn ModelInfo>, CliError> {
        let mut model = find_smooth_model(name, "a linearisation")?;
        set_parameters(model.as_mut(), &self.set)?;
        Ok(model)
    }

    /// The label and starting guess of `--at` for `model` (see [`equilibrium_start`]).
    ///
    /// # Errors
    /// An unknown equilibrium name or a bad guess.
    pub(super) fn guess(&self, model: &dyn ModelInfo) -> Result<(String, Vec<f64>), CliError> {
        equilibrium_start(model, self.at.as_deref())?
            .resolve(model)
            .map_err(|e| point_failure(model, &e))
    }

    /// The library's options for `--at` on `model`.
    ///
    /// # Errors
    /// A bad guess (usage).
    pub(super) fn options(&self, model: &dyn ModelInfo) -> Result<OperatingPointOptions, CliError> {
        Ok(OperatingPointOptions {
            start: equilibrium_start(model, self.at.as_deref())?,
            ..OperatingPointOptions::default()
        })
    }
}

/// The error of a failed equilibrium search, linearisation or modal analysis of `model`: the
/// reason, then a `help:` line with what to try (issue 8's numerical failures).
pub(super) fn modal_failure(model: &dyn ModelInfo, e: &eomgen::ModalError) -> CliError {
    CliError::failure(format!(
        "`{}`: {e}\nhelp: {}",
        model.description().name,
        modal_hint(model, e)
    ))
}

/// What to try after `e` (see [`modal_failure`]).
pub(super) fn modal_hint(model: &dyn ModelInfo, e: &eomgen::ModalError) -> String {
    use eomgen::{ModalError, NewtonStop};
    let name = &model.description().name;
    let named: Vec<&str> = model
        .equilibrium_guesses()
        .iter()
        .map(|(n, _)| *n)
        .collect();
    let start = if named.is_empty() {
        format!(
            "--at {}=…, one value per coordinate",
            model.description().coordinate_names().join("=…,")
        )
    } else {
        format!(
            "--at NAME with one of the file's `equilibria:` ({}), or --at {}=…",
            named.join(", "),
            model.description().coordinate_names().join("=…,")
        )
    };
    match e {
        ModalError::EquilibriumNotFound {
            reason: NewtonStop::ZeroJacobian,
            ..
        } => format!(
            "nothing here depends on the configuration, so nothing can balance the loads: a body in free fall or under a constant load has no equilibrium, and modes need one; to linearise along a motion, simulate it (`eomgen simulate {name}`); if the model has an equilibrium elsewhere, start there: {start}"
        ),
        ModalError::EquilibriumNotFound { .. } => format!(
            "start Newton nearer an equilibrium: {start}; a model whose loads cannot be balanced (a driven or falling body) has none"
        ),
        ModalError::EquilibriumAtInfinity { .. } => format!(
            "the forces fade with distance without balancing (an attraction with nothing to oppose it: an orbit has no equilibrium at rest); start Newton nearer an equilibrium if there is one: {start}"
        ),
        ModalError::DegenerateCoordinates { .. } => format!(
            "the coordinates are (nearly) degenerate at this configuration (Euler angles at θ = 0, an angle of a point at its pivot, a mass negligible beside the one it moves with): choose an operating point away from it, {start}, other coordinates or less extreme parameters"
        ),
        ModalError::TimeDependent {
            part:
                eomgen::TimeDependentPart::Constraint {
                    jacobian_changes: false,
                    ..
                },
            ..
        } => format!(
            "the constraint prescribes a motion with a constant Jacobian (base excitation, like `x − a*cos(w*t)`): the modes are those of the system relative to the moving base, which are not computed from this form; write the model in coordinates relative to the base (the base's acceleration then enters as a load, which `modes` sets aside), or simulate it (`eomgen simulate {name}`)"
        ),
        ModalError::TimeDependent {
            part: eomgen::TimeDependentPart::Constraint { .. },
            ..
        } => format!(
            "a constraint that moves with t (a rod spun at a given rate) has no modes at rest; write the model in coordinates that move with it (the distance along a spun rod), where the equations no longer contain t, or simulate it (`eomgen simulate {name}`)"
        ),
        ModalError::TimeDependentLoad { .. } => format!(
            "a load that changes with t is an input, not part of the modes: `eomgen frf {name}` gives the response to a harmonic load, `eomgen simulate {name}` follows the motion; if the equations balance the load elsewhere, start Newton there: {start}"
        ),
        ModalError::NoRealModes { .. } => format!(
            "the system flutters here (`eomgen modes {name}` gives its eigenvalues): its response is computed without modes, by `eomgen frf {name}` without --modal or `eomgen simulate {name}`"
        ),
        ModalError::NotFiniteAtTime { .. } => format!(
            "a load that changes with t is an input, not part of the modes: `eomgen frf {name}` gives the response to a harmonic load, `eomgen simulate {name}` follows the motion from a time where the load is defined"
        ),
        ModalError::TimeDependent { .. } => format!(
            "for a periodic dependence, its stability about this operating point is given by `eomgen study floquet {name}` (Floquet multipliers over one period); `eomgen simulate {name}` follows the motion"
        ),
        ModalError::SingularMassMatrix { .. } => format!(
            "a coordinate has no inertia at this configuration (the mass matrix loses rank there, e.g. an angle of a point at its pivot): choose another operating point, {start}"
        ),
        ModalError::NonFinite { .. } => format!(
            "the model's forces, mass matrix or constraints are singular at this configuration (a division by zero such as the direction between two points that coincide, a root of a negative number): choose another operating point, {start}"
        ),
        ModalError::NonHolonomic { .. } => format!(
            "its motion is computed by `eomgen simulate {name}`; the stability of its steady motions is not a normal-mode problem"
        ),
        ModalError::OffConstraints { .. } => format!(
            "give an operating point that satisfies the constraints, or a guess from which Newton finds one: {start}"
        ),
        ModalError::ConstrainedMotion { .. } => {
            "linearise the constrained model at rest (all rates 0)".to_string()
        }
        ModalError::SpeedsInMotion { .. } => {
            "linearise the model at rest (all coordinates' rates 0), or remove `speeds` to linearise it in the rates".to_string()
        }
        ModalError::SpeedsBesideConstraints { .. } => format!(
            "`eomgen simulate {name}` follows its motion; remove `speeds` to find its equilibria and modes in the coordinates' rates"
        ),
        ModalError::SpeedsDependOnTime => {
            "remove `speeds` to find its equilibria and modes in the coordinates' rates".to_string()
        }
        ModalError::SingularKinematics { .. } => format!(
            "the speeds do not determine the rates at this configuration: choose another operating point ({start}), angles whose singularity lies elsewhere (another `axes:` order), or remove `speeds`"
        ),
        ModalError::DimensionMismatch { .. } => format!(
            "give one value per coordinate ({})",
            model.description().coordinate_names().join(", ")
        ),
        _ => format!("choose another operating point: {start}"),
    }
}

/// The start of the equilibrium search that `--at` names: a name from the file's
/// `equilibria:`, guesses `q1=VALUE,…` (expressions of the parameters; others 0), or the
/// default (the file's first equilibrium, else q = 0).
///
/// # Errors
/// A usage error for a bad guess (an unknown coordinate, a bad expression).
pub(super) fn equilibrium_start(
    model: &dyn ModelInfo,
    at: Option<&str>,
) -> Result<EquilibriumStart, CliError> {
    let Some(at) = at else {
        return Ok(EquilibriumStart::FirstNamed);
    };
    if !at.contains('=')
        || model
            .equilibrium_guesses()
            .iter()
            .any(|(name, _)| *name == at)
    {
        return Ok(EquilibriumStart::Named(at.to_string()));
    }
    let lookup = parameter_lookup(model);
    let mut q = vec![0.0; model.num_dofs()];
    for part in at.split(',') {
        let (name, text) = split_assignment(part, "--at")?;
        let index = model
            .description()
            .coordinate_names()
            .iter()
            .position(|c| *c == name)
            .ok_or_else(|| {
                CliError::usage(format!(
                    "--at: `{name}` is not a coordinate of `{}` (coordinates: {})",
                    model.description().name,
                    model.description().coordinate_names().join(", ")
                ))
            })?;
        q[index] = evaluate(text, &format!("--at {name}"), &lookup)?;
    }
    Ok(EquilibriumStart::Guess {
        label: at.to_string(),
        q,
    })
}

/// The error of a failed operating point of `model`: an unknown `--at` name is a usage error,
/// a failed search gets its hint ([`modal_failure`]).
pub(super) fn point_failure(model: &dyn ModelInfo, e: &OperatingPointError) -> CliError {
    match e {
        OperatingPointError::UnknownEquilibrium { name, .. } => CliError::usage(format!(
            "--at {name}: {e}; or give guesses like `--at {}=0`",
            model
                .description()
                .coordinate_names()
                .first()
                .copied()
                .unwrap_or("q")
        )),
        OperatingPointError::Modal(m) => modal_failure(model, m),
        e => CliError::failure(format!("`{}`: {e}", model.description().name)),
    }
}
