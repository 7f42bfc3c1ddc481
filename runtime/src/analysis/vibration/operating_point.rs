//! The operating point of a vibration analysis: an equilibrium `F(q*, 0, t) = 0` (with
//! holonomic constraints `F = Jᵀλ*`, `Φ(q*, t) = 0`) found by Newton's method from a named
//! guess of the model file's `equilibria:` or from explicit coordinates (lecture 25).

use std::collections::BTreeMap;

use serde::Serialize;

use crate::linear::modal::{Equilibrium, ModalError, find_equilibrium};
use crate::model_info::ModelInfo;

/// Where Newton's search for the equilibrium starts.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EquilibriumStart {
    /// The model file's first `equilibria:` entry; `q = 0` (named `q = 0`) when it has none
    /// (default).
    #[default]
    FirstNamed,
    /// The entry of this name in the model file's `equilibria:` (`hanging`, `upright`).
    Named(String),
    /// Explicit coordinates `q` (length `n`, m or rad) under a label for reports (the CLI
    /// uses the `--at` text, `theta=pi/2`).
    Guess {
        /// What to call the operating point.
        label: String,
        /// The starting coordinates (length `n = num_dofs()`).
        q: Vec<f64>,
    },
}

impl EquilibriumStart {
    /// The label and the starting coordinates (length `n`) of this start for `model`.
    ///
    /// # Errors
    /// [`OperatingPointError::UnknownEquilibrium`] for a name the file's `equilibria:` does
    /// not have; [`OperatingPointError::Modal`] with [`ModalError::DimensionMismatch`] for a
    /// guess of the wrong length.
    pub fn resolve(
        &self,
        model: &dyn ModelInfo,
    ) -> Result<(String, Vec<f64>), OperatingPointError> {
        self.resolve_any(model)
    }

    /// [`Self::resolve`] for an analysis about an equilibrium: an entry of `equilibria:`
    /// that holds rates (a steady motion) is refused.
    ///
    /// # Errors
    /// As [`Self::resolve`], and [`OperatingPointError::SteadyMotion`].
    pub fn resolve_equilibrium(
        &self,
        model: &dyn ModelInfo,
    ) -> Result<(String, Vec<f64>), OperatingPointError> {
        let (name, guess) = self.resolve_any(model)?;
        if held_rates(model, self).0.iter().any(|r| *r != 0.0) {
            return Err(OperatingPointError::SteadyMotion {
                model: model.description().name.to_string(),
                name,
            });
        }
        Ok((name, guess))
    }

    fn resolve_any(
        &self,
        model: &dyn ModelInfo,
    ) -> Result<(String, Vec<f64>), OperatingPointError> {
        let (name, guess) = self.resolve_unchecked(model)?;
        if let Some(i) = guess.iter().position(|v| !v.is_finite()) {
            return Err(OperatingPointError::GuessNotFinite {
                model: model.description().name.to_string(),
                name,
                coordinate: model.description().state_name(i),
                value: guess[i],
            });
        }
        Ok((name, guess))
    }

    fn resolve_unchecked(
        &self,
        model: &dyn ModelInfo,
    ) -> Result<(String, Vec<f64>), OperatingPointError> {
        let named = model.equilibrium_guesses();
        match self {
            Self::FirstNamed => Ok(match named.first() {
                Some((name, q)) => (name.to_string(), q.clone()),
                None => ("q = 0".to_string(), vec![0.0; model.num_dofs()]),
            }),
            Self::Named(name) => named
                .iter()
                .find(|(n, _)| n == name)
                .map(|(n, q)| (n.to_string(), q.clone()))
                .ok_or_else(|| OperatingPointError::UnknownEquilibrium {
                    model: model.description().name.to_string(),
                    name: name.clone(),
                    known: named.iter().map(|(n, _)| n.to_string()).collect(),
                }),
            Self::Guess { label, q } => {
                if q.len() != model.num_dofs() {
                    return Err(ModalError::DimensionMismatch {
                        expected: model.num_dofs(),
                        found: q.len(),
                    }
                    .into());
                }
                Ok((label.clone(), q.clone()))
            }
        }
    }
}

/// The index of `start`'s entry in the file's `equilibria:` (`None` for a guess, or a name
/// not there).
fn entry_index(model: &dyn ModelInfo, start: &EquilibriumStart) -> Option<usize> {
    let d = model.description();
    match start {
        EquilibriumStart::FirstNamed => (!d.equilibria.is_empty()).then_some(0),
        EquilibriumStart::Named(name) => d.equilibria.iter().position(|e| e == name),
        EquilibriumStart::Guess { .. } => None,
    }
}

/// The rates an operating point holds and the coordinates it declares ignorable: those of
/// its entry of `equilibria:` (none for a guess).
pub fn held_rates(model: &dyn ModelInfo, start: &EquilibriumStart) -> (Vec<f64>, Vec<usize>) {
    let n = model.num_dofs();
    let d = model.description();
    match entry_index(model, start) {
        Some(k) => (
            model
                .equilibrium_rates()
                .get(k)
                .cloned()
                .unwrap_or_else(|| vec![0.0; n]),
            d.ignorable_coordinates
                .iter()
                .filter(|[e, _]| *e == k)
                .map(|[_, c]| *c)
                .collect(),
        ),
        None => (vec![0.0; n], Vec::new()),
    }
}

/// What the operating point `start` holds and finds as a steady motion: its entry's rates,
/// ignorable and held coordinates, found rates and turning frame
/// ([`crate::linear::steady::SteadyMotionSpec`]); only rates of 0 for a guess.
pub fn steady_motion_spec(
    model: &dyn ModelInfo,
    start: &EquilibriumStart,
) -> crate::linear::steady::SteadyMotionSpec {
    let (rates, ignorable) = held_rates(model, start);
    let d = model.description();
    let entry = entry_index(model, start);
    let of_entry = |pairs: &[[usize; 2]]| -> Vec<usize> {
        (pairs.iter())
            .filter(|[e, _]| Some(*e) == entry)
            .map(|[_, c]| *c)
            .collect()
    };
    crate::linear::steady::SteadyMotionSpec {
        rates,
        ignorable,
        held_coordinates: of_entry(&d.held_coordinates),
        solved_rates: of_entry(&d.solved_rates),
        turning: (d.turning_frames.iter())
            .find(|[e, ..]| Some(*e) == entry)
            .map(|&[_, angle, a, b]| crate::linear::turning::TurningFrame {
                angle,
                plane: [a, b],
            }),
    }
}

/// Options of [`operating_point`].
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct OperatingPointOptions {
    /// Where Newton starts (default: the file's first named equilibrium, else `q = 0`).
    pub start: EquilibriumStart,
    /// The time `t` (s) at which `F(q, 0, t) = 0` is solved (default: 0).
    pub t: f64,
}

/// An operating point: the equilibrium found and what it is called.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OperatingPoint {
    /// The equilibrium's name from `equilibria:`, the guess's label, or `q = 0`.
    pub name: String,
    /// The model's coordinates (`description().coordinates`, length `n`), the order of `q` and `guess`.
    pub coordinates: Vec<String>,
    /// Newton's starting coordinates (length `n`).
    pub guess: Vec<f64>,
    /// The time (s) of the equilibrium equations.
    pub t: f64,
    /// The equilibrium `q*`, `λ*`, Newton's iterations and residual.
    pub equilibrium: Equilibrium,
}

impl OperatingPoint {
    /// The equilibrium's coordinates `q*` (length `n`).
    pub fn q(&self) -> &[f64] {
        &self.equilibrium.q
    }

    /// The point as the studies' reports print it, at the coordinates `q` (length `n`; the
    /// equilibrium's, or a linearisation's taken there), without Newton's figures.
    pub fn summary_at(&self, q: &[f64]) -> PointSummary {
        PointSummary::new(&self.name, &self.coordinates, q)
    }

    /// The point as `eomgen modes` prints it: name, `q*`, Newton's iterations and residual.
    pub fn summary(&self) -> PointSummary {
        PointSummary {
            newton_iterations: Some(self.equilibrium.iterations),
            residual: Some(self.equilibrium.residual),
            ..self.summary_at(&self.equilibrium.q)
        }
    }
}

/// An operating point in a report: `{"name", "q": {coordinate: value}}`, with Newton's
/// figures where the report gives them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointSummary {
    /// The equilibrium's name ([`OperatingPoint::name`]).
    pub name: String,
    /// The coordinates' values by name (m or rad).
    pub q: BTreeMap<String, f64>,
    /// Newton iterations used (left out when `None`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub newton_iterations: Option<usize>,
    /// The residual Newton left ([`Equilibrium::residual`]; left out when `None`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual: Option<f64>,
    /// `max |F(q*, 0, t)|` over a forcing period (a time-periodic model's Floquet analysis;
    /// left out when `None`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_forcing_residual: Option<f64>,
}

impl PointSummary {
    /// The point `name` at `q`, one value per name of `coordinates` (`n` each).
    pub fn new(name: &str, coordinates: &[impl AsRef<str>], q: &[f64]) -> Self {
        Self {
            name: name.to_string(),
            q: coordinates
                .iter()
                .zip(q)
                .map(|(c, &v)| (c.as_ref().to_string(), v))
                .collect(),
            newton_iterations: None,
            residual: None,
            max_forcing_residual: None,
        }
    }
}

/// Why no operating point was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OperatingPointError {
    /// [`EquilibriumStart::Named`] names no entry of the file's `equilibria:`.
    #[error("`{model}` has no equilibrium `{name}` ({})", if known.is_empty() { "it names none".to_string() } else { format!("it names: {}", known.join(", ")) })]
    UnknownEquilibrium {
        /// The model.
        model: String,
        /// The name asked for.
        name: String,
        /// The names the file gives, in its order.
        known: Vec<String>,
    },
    /// The operating point is a steady motion (it holds rates), which an analysis about an
    /// equilibrium cannot take.
    #[error(
        "`{name}` of `{model}` is a steady motion (it holds rates): this analysis linearises about an equilibrium; `eomgen modes --at {name}` and `study parameter-sweep` analyse steady motions"
    )]
    SteadyMotion {
        /// The model.
        model: String,
        /// The entry's name.
        name: String,
    },
    /// The start has an entry that is not finite: the `equilibria:` entry's expression is
    /// outside its domain at these parameters (or the guess given has it).
    #[error(
        "the start `{name}` of `{model}` has {coordinate} = {value}: its expression is outside its domain at these parameters (a root or logarithm of a negative number, a division by zero)"
    )]
    GuessNotFinite {
        /// The model.
        model: String,
        /// The entry's name (or the guess's label).
        name: String,
        /// The coordinate (or rate) that is not finite.
        coordinate: String,
        /// Its value.
        value: f64,
    },
    /// The search or a later linearisation failed.
    #[error(transparent)]
    Modal(#[from] ModalError),
}

/// Finds the equilibrium of `model` from `options.start` by Newton's method with the exact
/// Jacobians ([`find_equilibrium`]): the start of `eomgen modes`, `frf`, the modal studies and
/// the `checks:` of a model file that name an operating point (`at: hanging`).
///
/// # Errors
/// [`OperatingPointError::UnknownEquilibrium`]; [`OperatingPointError::SteadyMotion`] for an
/// entry that holds rates; [`OperatingPointError::Modal`] with
/// [`ModalError::EquilibriumNotFound`], [`ModalError::NonHolonomic`] or
/// [`ModalError::DimensionMismatch`].
///
/// # Examples
/// ```
/// use eomgen_runtime::analysis::vibration::{EquilibriumStart, OperatingPointOptions, operating_point};
/// let mut model = (eomgen::models::find("double_pendulum").unwrap().make)();
/// let options = OperatingPointOptions {
///     start: EquilibriumStart::Named("hanging".to_string()),
///     ..OperatingPointOptions::default()
/// };
/// let point = operating_point(model.as_mut(), &options)?;
/// // Both bars straight down (angles from +x).
/// for theta in point.q() {
///     assert!((theta + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
/// }
/// # Ok::<(), eomgen_runtime::analysis::vibration::OperatingPointError>(())
/// ```
///
/// # References
/// Lecture 25 (equilibria and linearisation); Newton's method as in [`find_equilibrium`].
pub fn operating_point(
    model: &dyn ModelInfo,
    options: &OperatingPointOptions,
) -> Result<OperatingPoint, OperatingPointError> {
    let (name, guess) = options.start.resolve_equilibrium(model)?;
    let equilibrium = find_equilibrium(model, &guess, options.t)?;
    Ok(OperatingPoint {
        name,
        coordinates: model
            .description()
            .coordinate_names()
            .iter()
            .map(|c| c.to_string())
            .collect(),
        guess,
        t: options.t,
        equilibrium,
    })
}
