//! A gait followed over a parameter (`eomgen study parameter-sweep` on a model with a change
//! of support): at each value Newton starts from the gait found at the values before
//! (extrapolated along the branch), and where the stability changes between two values the
//! change is located by bisection and named by the eigenvalue that left the unit circle:
//! through −1 a period doubling, through +1 a fold, as a complex pair a Neimark–Sacker
//! bifurcation (Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., §4.4–4.7;
//! Garcia et al. 1998, Fig. 4, for the simplest walker's period doublings).

use nalgebra::Complex;
use serde::Serialize;

use super::{GaitError, GaitOptions, gait};
use crate::analysis::vibration::SweepAxis;
use crate::linear::monodromy::FloquetStability;
use crate::model_info::ModelInfo;

/// Bisections of a stability change: its bracket shrinks to `2⁻²⁴` of the step between the
/// two values that straddle it.
const BISECTIONS: usize = 24;

/// The gait at one value of the parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GaitSweepPoint {
    /// The parameter's value.
    pub value: f64,
    /// The gait's state just after a landing (`2n`), if one was found.
    pub state: Option<Vec<f64>>,
    /// Its period (s).
    pub period: Option<f64>,
    /// The return map's eigenvalues, largest modulus first (empty where no gait was found).
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub eigenvalues: Vec<Complex<f64>>,
    /// The largest `|λ|`.
    pub spectral_radius: Option<f64>,
    /// The verdict.
    pub stability: Option<FloquetStability>,
    /// Why no gait was found here.
    pub error: Option<String>,
}

/// How a gait loses (or gains) its stability.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GaitBifurcation {
    /// A real eigenvalue through −1: a gait of twice the steps appears (or disappears).
    PeriodDoubling,
    /// A real eigenvalue through +1: the gait meets another and both end (a fold).
    Fold,
    /// A complex pair through the unit circle (Neimark–Sacker).
    NeimarkSacker,
}

/// A change of stability between two values, located by bisection.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GaitStabilityChange {
    /// The value where the largest `|λ|` reaches 1 (the middle of the bracket where
    /// `ρ − 1` changes sign).
    pub value: f64,
    /// The bracket `[lo, hi]` it is in.
    pub bracket: [f64; 2],
    /// Whether the gait is stable below it (and unstable above), or the reverse.
    pub stable_below: bool,
    /// How.
    pub kind: GaitBifurcation,
    /// The eigenvalue that crosses, `[re, im]`, at the unstable end of the bracket.
    pub eigenvalue: [f64; 2],
}

/// A gait followed over a parameter ([`gait_sweep`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GaitSweep {
    /// The model.
    pub model: String,
    /// The parameter.
    pub parameter: String,
    /// Landings per period.
    pub steps: usize,
    /// One entry per value, ascending.
    pub points: Vec<GaitSweepPoint>,
    /// Every change of stability between two values where a gait was found.
    pub stability_changes: Vec<GaitStabilityChange>,
}

/// Follows the gait of `model` over `axis` from [`GaitOptions::start`] at its first value
/// (see the module documentation); `progress(done, total)` after each value. The parameter
/// is restored afterwards.
///
/// # Errors
/// [`GaitError::UnknownParameter`]; [`GaitError::NoSupport`] and the settings' errors as
/// [`gait`]. A value without a gait is recorded in its point, not an error.
pub fn gait_sweep(
    model: &mut dyn ModelInfo,
    axis: &SweepAxis,
    options: &GaitOptions,
    mut progress: impl FnMut(usize, usize),
) -> Result<GaitSweep, GaitError> {
    let names = model.description().parameter_names();
    let Some(index) = names.iter().position(|p| *p == axis.name) else {
        return Err(GaitError::UnknownParameter {
            name: axis.name.clone(),
            parameters: names.join(", "),
        });
    };
    let original = model.parameter_values()[index];
    let mut branch: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut points = Vec::with_capacity(axis.values.len());
    let mut first_error = None;
    for (k, &value) in axis.values.iter().enumerate() {
        let start = predict(&branch, value).or_else(|| options.start.clone());
        let found = at(model, &axis.name, value, start, options);
        match &found {
            Ok(g) => branch.push((value, g.state.clone())),
            Err(
                GaitError::NoSupport { .. }
                | GaitError::InvalidOptions { .. }
                | GaitError::Unsupported { .. },
            ) => {
                first_error = found.as_ref().err().cloned();
            }
            Err(_) => {}
        }
        if let Some(e) = first_error.take() {
            let _ = model.set_parameter(&axis.name, original);
            return Err(e);
        }
        points.push(point(value, found));
        progress(k + 1, axis.values.len());
    }
    if let Some(first) = points.first().filter(|_| branch.is_empty()) {
        let _ = model.set_parameter(&axis.name, original);
        return Err(GaitError::NothingFound {
            value: first.value,
            reason: first.error.clone().unwrap_or_default(),
        });
    }
    let stability_changes = (0..points.len().saturating_sub(1))
        .filter_map(|k| change(model, &axis.name, (&points[k], &points[k + 1]), options))
        .collect();
    let _ = model.set_parameter(&axis.name, original);
    Ok(GaitSweep {
        model: model.description().name.to_string(),
        parameter: axis.name.clone(),
        steps: options.steps,
        points,
        stability_changes,
    })
}

/// The gait at `value` of `name`, Newton from `start`.
fn at(
    model: &mut dyn ModelInfo,
    name: &str,
    value: f64,
    start: Option<Vec<f64>>,
    options: &GaitOptions,
) -> Result<super::Gait, GaitError> {
    model
        .set_parameter(name, value)
        .map_err(|_| GaitError::UnknownParameter {
            name: name.to_string(),
            parameters: String::new(),
        })?;
    let options = GaitOptions {
        start,
        ..options.clone()
    };
    gait(model, &options)
}

/// Newton's start at `value` from the branch so far: the last gait, or the line through the
/// last two.
fn predict(branch: &[(f64, Vec<f64>)], value: f64) -> Option<Vec<f64>> {
    match branch {
        [.., (v0, y0), (v1, y1)] if v1 != v0 => {
            let s = (value - v1) / (v1 - v0);
            Some(y1.iter().zip(y0).map(|(a, b)| a + s * (a - b)).collect())
        }
        [.., (_, y)] => Some(y.clone()),
        [] => None,
    }
}

/// The point of a sweep at `value`.
fn point(value: f64, found: Result<super::Gait, GaitError>) -> GaitSweepPoint {
    match found {
        Ok(g) => GaitSweepPoint {
            value,
            state: Some(g.state),
            period: Some(g.period),
            eigenvalues: g.eigenvalues,
            spectral_radius: Some(g.spectral_radius),
            stability: Some(g.stability),
            error: None,
        },
        Err(e) => GaitSweepPoint {
            value,
            state: None,
            period: None,
            eigenvalues: Vec::new(),
            spectral_radius: None,
            stability: None,
            error: Some(e.to_string()),
        },
    }
}

/// The change of stability between two neighbouring points where both have a gait and one
/// is stable and the other not, located by bisection from the nearer gait.
fn change(
    model: &mut dyn ModelInfo,
    name: &str,
    (a, b): (&GaitSweepPoint, &GaitSweepPoint),
    options: &GaitOptions,
) -> Option<GaitStabilityChange> {
    let (sa, sb) = (a.stability?, b.stability?);
    if sa.is_stable() == sb.is_stable() {
        return None;
    }
    let stable_below = sa.is_stable();
    let (mut lo, mut hi) = ((a.value, a.state.clone()?), (b.value, b.state.clone()?));
    let mut unstable = if stable_below {
        b.eigenvalues[0]
    } else {
        a.eigenvalues[0]
    };
    // On the sign of `ρ − 1` (the verdict's tolerance would move the point by it).
    let below = a.spectral_radius? < 1.0;
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (lo.0 + hi.0);
        let Ok(g) = at(model, name, mid, Some(lo.1.clone()), options) else {
            break;
        };
        let inside = g.spectral_radius < 1.0;
        if inside != stable_below {
            unstable = g.eigenvalues[0];
        }
        if inside == below {
            lo = (mid, g.state);
        } else {
            hi = (mid, g.state);
        }
    }
    let kind = if unstable.im.abs() > 1e-9 * unstable.norm() {
        GaitBifurcation::NeimarkSacker
    } else if unstable.re < 0.0 {
        GaitBifurcation::PeriodDoubling
    } else {
        GaitBifurcation::Fold
    };
    Some(GaitStabilityChange {
        value: 0.5 * (lo.0 + hi.0),
        bracket: [lo.0, hi.0],
        stable_below,
        kind,
        eigenvalue: [unstable.re, unstable.im],
    })
}
