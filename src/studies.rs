//! What the studies need from a model's file beyond its compiled equations: the model it
//! names as its minimal-coordinate twin (`minimal_twin:`), for
//! [`analysis::constraint_methods`](crate::analysis::constraint_methods()), and the declared
//! unit of a Floquet study's period parameter ([`check_period_parameter_unit`]).

use eomgen_symbolic::model::file::{ModelFile, UnitSystem};
use eomgen_symbolic::model::units::{Dimension, parse_unit};

use crate::{ModelSource, OpenError};

/// The model file behind `source`, loaded (with its path).
fn load_file(source: &ModelSource) -> Result<(String, ModelFile), TwinError> {
    let path = source.path();
    let read = |message: String| TwinError::Read {
        path: path.to_string(),
        message,
    };
    let bytes = source.bytes().map_err(|e| read(e.to_string()))?;
    let text = eomgen_symbolic::model::decode(&bytes).map_err(|d| read(d.message))?;
    let file = eomgen_symbolic::model::load(path, text).map_err(|d| TwinError::Diagnostics {
        path: path.to_string(),
        count: d.len(),
    })?;
    Ok((path.to_string(), file))
}

/// Why a Floquet study's period parameter is not an angular frequency by its declared unit.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PeriodUnitError {
    /// The model file could not be read or loaded.
    #[error(transparent)]
    File(#[from] TwinError),
    /// The file declares `units: SI` and the parameter's unit is not a frequency.
    #[error(
        "{path}:{line}:{column}: the period parameter `{name}` is in {unit}, not a frequency; the period is T = 2π/{name}, so {name} must be an angular frequency in rad/s"
    )]
    NotAFrequency {
        /// The model file.
        path: String,
        /// The parameter.
        name: String,
        /// Its declared unit.
        unit: String,
        /// Where the unit is written (1-based).
        line: u32,
        /// Column (1-based).
        column: u32,
    },
    /// The parameter is declared in Hz (cycles per second), while `T = 2π/w` needs rad/s.
    #[error(
        "{path}:{line}:{column}: the period parameter `{name}` is in Hz (cycles per second), but the period is T = 2π/{name}, which needs rad/s; declare it in rad/s (2π times the value in Hz)"
    )]
    Hertz {
        /// The model file.
        path: String,
        /// The parameter.
        name: String,
        /// Where the unit is written (1-based).
        line: u32,
        /// Column (1-based).
        column: u32,
    },
}

/// Checks, where the model file declares `units: SI`, that the period parameter `name` of a
/// Floquet study is an angular frequency: its unit is `rad/s` or `1/s` (rad is a pure
/// number), not `Hz` (the study's period is `T = 2π/w`). A file without declared units, or
/// a parameter it does not have, passes (the study checks the name and, numerically, the
/// periodicity itself: [`vibration::floquet_at_equilibrium`](crate::analysis::vibration::floquet_at_equilibrium)).
///
/// # Errors
/// [`PeriodUnitError::NotAFrequency`], [`PeriodUnitError::Hertz`] (located at the unit), and
/// [`PeriodUnitError::File`] when the file cannot be read.
///
/// # Examples
/// ```
/// use eomgen::ModelSource;
/// use eomgen::studies::check_period_parameter_unit;
/// let mathieu = ModelSource::open("mathieu_pendulum").unwrap();
/// assert!(check_period_parameter_unit(&mathieu, "w").is_ok());
/// let err = check_period_parameter_unit(&mathieu, "a").unwrap_err();
/// assert!(err.to_string().contains("is in m, not a frequency"), "{err}");
/// ```
pub fn check_period_parameter_unit(
    source: &ModelSource,
    name: &str,
) -> Result<(), PeriodUnitError> {
    let (path, file) = load_file(source)?;
    if !matches!(file.units.as_ref().map(|u| &u.value), Some(UnitSystem::Si)) {
        return Ok(());
    }
    let Some(parameter) = file.parameters.iter().find(|p| p.name.value == name) else {
        return Ok(());
    };
    let Some(unit) = &parameter.unit else {
        return Ok(());
    };
    let text = unit.value.split(',').next().unwrap_or("").trim();
    let (line, column) = (unit.location.line, unit.location.column);
    if text == "Hz" {
        return Err(PeriodUnitError::Hertz {
            path,
            name: name.to_string(),
            line,
            column,
        });
    }
    match parse_unit(text) {
        Ok(d) if d == Dimension::FREQUENCY => Ok(()),
        _ => Err(PeriodUnitError::NotAFrequency {
            path,
            name: name.to_string(),
            unit: text.to_string(),
            line,
            column,
        }),
    }
}

/// Why a model's twin could not be found.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TwinError {
    /// The model file could not be read.
    #[error("cannot read `{path}`: {message}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
    /// The model file has mistakes.
    #[error("{count} error(s) in the model file `{path}`")]
    Diagnostics {
        /// The file.
        path: String,
        /// How many.
        count: usize,
    },
    /// The twin the file names cannot be opened.
    #[error("the minimal twin `{name}` of `{model}`: {source}")]
    Open {
        /// The model.
        model: String,
        /// The twin's name.
        name: String,
        /// Why (boxed: an open error carries the file's diagnostics).
        source: Box<OpenError>,
    },
}

/// The model `source`'s file names as its minimal twin (`minimal_twin: simple_pendulum`),
/// with that name, opened; `None` if the file names none.
///
/// # Errors
/// [`TwinError::Read`] or [`TwinError::Diagnostics`] when the model's file cannot be read or
/// loaded, [`TwinError::Open`] when the twin is not a bundled model.
///
/// # Examples
/// ```
/// use eomgen::ModelSource;
/// use eomgen::studies::minimal_twin;
///
/// let cartesian = ModelSource::open("simple_pendulum_cartesian").unwrap();
/// let (name, twin) = minimal_twin(&cartesian).unwrap().expect("a twin");
/// assert_eq!((name.as_str(), twin.name()), ("simple_pendulum", "simple_pendulum"));
/// assert!(minimal_twin(&ModelSource::open("two_masses_rod").unwrap()).unwrap().is_none());
/// ```
pub fn minimal_twin(source: &ModelSource) -> Result<Option<(String, ModelSource)>, TwinError> {
    let (_, file) = load_file(source)?;
    let Some(name) = file.minimal_twin else {
        return Ok(None);
    };
    let twin = ModelSource::open(&name.value).map_err(|e| TwinError::Open {
        model: file.name.value.clone(),
        name: name.value.clone(),
        source: Box::new(e),
    })?;
    Ok(Some((name.value, twin)))
}
