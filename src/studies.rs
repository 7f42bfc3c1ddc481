//! What the studies need from a model's file beyond its compiled equations: the model it
//! names as its minimal-coordinate twin (`minimal_twin:`), for
//! [`analysis::constraint_methods`](crate::analysis::constraint_methods()).

use crate::{ModelSource, OpenError};

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
    let path = match source {
        ModelSource::Bundled(entry) => entry.path,
        ModelSource::File { path, .. } => path.as_str(),
    };
    let text = std::fs::read_to_string(path).map_err(|e| TwinError::Read {
        path: path.to_string(),
        message: e.to_string(),
    })?;
    let file = eomgen_symbolic::model::load(path, &text).map_err(|d| TwinError::Diagnostics {
        path: path.to_string(),
        count: d.len(),
    })?;
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
