//! Naming a model: a bundled model's name, or the path of any model file, compiled at run
//! time.

use crate::models::ModelEntry;
use crate::{DynFirstOrder, JitModel, LoadError, LoadOptions, ModelInfo};

/// A model named by a user: bundled (its text embedded in the program) or a model file. Both
/// are compiled at run time ([`JitModel`]) and give the same [`ModelInfo`], so every
/// analysis takes either.
///
/// # Examples
/// ```
/// let bundled = eomgen::ModelSource::open("double_pendulum")?;
/// let model = bundled.instantiate();
/// assert_eq!(model.num_dofs(), 2);
/// # Ok::<(), eomgen::OpenError>(())
/// ```
#[derive(Debug, Clone)]
pub enum ModelSource {
    /// A model of `models/`, embedded.
    Bundled {
        /// Its name, file and text.
        entry: &'static ModelEntry,
        /// The compiled model (with the file's default parameters).
        model: JitModel,
    },
    /// A model file loaded, derived and compiled at run time.
    File {
        /// The path as the user gave it.
        path: String,
        /// The compiled model (with the file's default parameters).
        model: JitModel,
    },
}

/// Why a model could not be opened by [`ModelSource::open`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OpenError {
    /// Neither a bundled model nor a file.
    #[error(
        "no model named `{name}`: it is not a bundled model ({}models are: {}; see `eomgen list`) nor a file; a path to a model file (`path/to/model.yaml`) works too",
        suggestion.as_ref().map(|s| format!("did you mean `{s}`? ")).unwrap_or_default(),
        known.join(", ")
    )]
    UnknownModel {
        /// What was asked for.
        name: String,
        /// The closest bundled name, if one is close.
        suggestion: Option<String>,
        /// The bundled models' names.
        known: Vec<String>,
    },
    /// The file could not be loaded (read, checked or compiled).
    #[error(transparent)]
    Load(#[from] LoadError),
}

impl ModelSource {
    /// Opens `name_or_path`: a bundled model's name compiles its embedded text (once per
    /// process); a path (ending in `.yaml` or `.yml`, containing a `/`, or naming an existing
    /// file) loads that file — even if the file is a copy of a bundled model, its own
    /// equations run.
    ///
    /// # Errors
    /// [`OpenError::UnknownModel`] for a name that is neither bundled nor a file;
    /// [`OpenError::Load`] for a file that cannot be read, has mistakes (located
    /// diagnostics) or cannot be compiled.
    pub fn open(name_or_path: &str) -> Result<ModelSource, OpenError> {
        Self::open_with(name_or_path, LoadOptions::default())
    }

    /// [`Self::open`], compiled with `options`.
    ///
    /// # Errors
    /// As [`Self::open`].
    pub fn open_with(name_or_path: &str, options: LoadOptions) -> Result<ModelSource, OpenError> {
        match resolve(name_or_path)? {
            Resolved::Bundled(entry) => Ok(ModelSource::Bundled {
                entry,
                model: entry.load_with(options)?,
            }),
            Resolved::File(path) => {
                let model = JitModel::load_with(&path, options)?;
                Ok(ModelSource::File { path, model })
            }
        }
    }

    /// A new instance with the file's default parameters.
    pub fn instantiate(&self) -> Box<dyn ModelInfo> {
        self.instantiate_send()
    }

    /// [`Self::instantiate`] as a `Send` box, for an instance that moves between threads
    /// (a thread pool's task, an interpreter's objects).
    pub fn instantiate_send(&self) -> Box<dyn ModelInfo + Send> {
        Box::new(DynFirstOrder::new(self.model().clone()))
    }

    /// The model's name (its file's `name:`).
    pub fn name(&self) -> &str {
        match self {
            ModelSource::Bundled { entry, .. } => entry.name,
            ModelSource::File { model, .. } => &crate::DynMechanicalSystem::description(model).name,
        }
    }

    /// The model file as messages name it: `models/<file>` for a bundled model, or the path
    /// given.
    pub fn path(&self) -> &str {
        match self {
            ModelSource::Bundled { entry, .. } => entry.file,
            ModelSource::File { path, .. } => path,
        }
    }

    /// The bytes of the model file: a bundled model's text as embedded in the program (no
    /// file is read, so an installed program needs no source tree), or the file read again.
    ///
    /// # Errors
    /// The operating system's error when the file cannot be read.
    pub fn bytes(&self) -> std::io::Result<std::borrow::Cow<'static, [u8]>> {
        match self {
            ModelSource::Bundled { entry, .. } => {
                Ok(std::borrow::Cow::Borrowed(entry.source().as_bytes()))
            }
            ModelSource::File { path, .. } => read_file(path).map(std::borrow::Cow::Owned),
        }
    }

    /// How to name this model again on a command line or to [`ModelSource::open`]: a bundled
    /// model's name, or the file's path.
    pub fn argument(&self) -> &str {
        match self {
            ModelSource::Bundled { entry, .. } => entry.name,
            ModelSource::File { path, .. } => path,
        }
    }

    /// The compiled model.
    pub fn model(&self) -> &JitModel {
        match self {
            ModelSource::Bundled { model, .. } | ModelSource::File { model, .. } => model,
        }
    }

    /// Whether the model was read from a file (not bundled).
    pub fn is_file(&self) -> bool {
        matches!(self, ModelSource::File { .. })
    }
}

/// What a model name on a command line names, before anything is loaded.
#[derive(Debug, Clone)]
pub enum Resolved {
    /// A bundled model.
    Bundled(&'static ModelEntry),
    /// A model file, by the path given.
    File(String),
}

impl Resolved {
    /// The model file as messages name it: `models/<file>` for a bundled model, or the path
    /// given.
    pub fn path(&self) -> &str {
        match self {
            Resolved::Bundled(entry) => entry.file,
            Resolved::File(path) => path,
        }
    }

    /// The bytes of the model file, as [`ModelSource::bytes`].
    ///
    /// # Errors
    /// The operating system's error when the file cannot be read.
    pub fn bytes(&self) -> std::io::Result<std::borrow::Cow<'static, [u8]>> {
        match self {
            Resolved::Bundled(entry) => Ok(std::borrow::Cow::Borrowed(entry.source().as_bytes())),
            Resolved::File(path) => read_file(path).map(std::borrow::Cow::Owned),
        }
    }
}

/// Reads a model file named on a command line, through the loader's size limit
/// ([`eomgen_symbolic::model::read_model_file`]: a device or FIFO is bounded too).
fn read_file(path: &str) -> std::io::Result<Vec<u8>> {
    use eomgen_symbolic::model::ReadError;
    match eomgen_symbolic::model::read_model_file(std::path::Path::new(path)) {
        Ok(text) => Ok(text.into_bytes()),
        Err(ReadError::Io(e)) => Err(e),
        Err(e) => Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            e.to_string(),
        )),
    }
}

/// Resolves `name_or_path` as [`ModelSource::open`] does, without loading anything: a path
/// (ending in `.yaml` or `.yml`, containing a path separator, or naming an existing file) is
/// a file, else a bundled model's name.
///
/// # Errors
/// [`OpenError::UnknownModel`] for a name that is neither bundled nor a file.
pub fn resolve(name_or_path: &str) -> Result<Resolved, OpenError> {
    let looks_like_path = name_or_path.ends_with(".yaml")
        || name_or_path.ends_with(".yml")
        || name_or_path.contains('/')
        || name_or_path.contains(std::path::MAIN_SEPARATOR);
    if !looks_like_path && let Some(entry) = crate::models::find(name_or_path) {
        return Ok(Resolved::Bundled(entry));
    }
    if looks_like_path || std::path::Path::new(name_or_path).is_file() {
        return Ok(Resolved::File(name_or_path.to_string()));
    }
    let known: Vec<&str> = crate::models::ALL.iter().map(|e| e.name).collect();
    Err(OpenError::UnknownModel {
        name: name_or_path.to_string(),
        suggestion: eomgen_symbolic::model::parser::closest(name_or_path, &known)
            .map(str::to_string),
        known: known.iter().map(|s| s.to_string()).collect(),
    })
}

/// Opens `name_or_path` ([`ModelSource::open`]) and instantiates it with its default
/// parameters.
///
/// # Errors
/// As [`ModelSource::open`].
pub fn open_model(name_or_path: &str) -> Result<Box<dyn ModelInfo>, OpenError> {
    Ok(ModelSource::open(name_or_path)?.instantiate())
}
