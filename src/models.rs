//! The bundled models: every file of `models/`, embedded as deflated text and compiled at run time
//! (Cranelift) at its first use in a process, as any model file is.
//!
//! Nothing of a bundled model is compiled into the library: a program that wants a model's
//! equations compiled into its own crate names the file in [`eomgen::model!`](crate::model).
//! The text is compiled once per process and model; each [`ModelEntry::make`] is a fresh
//! instance of the same code (a [`JitModel`] clone, with its own parameter values).

use std::sync::OnceLock;

use crate::{DynFirstOrder, JitModel, LoadError, LoadOptions, ModelInfo, ModelSummary};

/// A bundled model: its name, its file's text (embedded, so an installed or moved program
/// needs no source tree), and a constructor of its first-order form with the file's default
/// parameters.
#[derive(Debug, Clone, Copy)]
pub struct ModelEntry {
    /// The model's `name`.
    pub name: &'static str,
    /// The file as it is shown in messages and diagnostics: `models/<file name>`.
    pub file: &'static str,
    /// The text of the model file ([`ModelEntry::source`]): for a bundled model, inflated
    /// from the program at its first use (the same address at every call).
    pub text: fn() -> &'static str,
    /// Builds the model with its default parameters (`Send`, so that a thread pool or
    /// another language's threads may own it), compiling the file at the first call in the
    /// process ([`ModelEntry::model`]).
    ///
    /// # Panics
    /// If the bundled file does not compile (a defect of the bundle, which the test
    /// `every_bundled_model_compiles` rules out; use [`ModelEntry::load_with`] for the error).
    pub make: fn() -> Box<dyn ModelInfo + Send>,
}

impl ModelEntry {
    /// The text of the model file.
    pub fn source(&self) -> &'static str {
        (self.text)()
    }

    /// The model compiled with the default [`LoadOptions`]: compiled at the first call in
    /// the process, then a clone of the same code (cheap: clones share the compiled code),
    /// for an entry of [`ALL`] or a copy of one.
    ///
    /// # Errors
    /// As [`JitModel::from_source`]: a bundled file always compiles (the test
    /// `every_bundled_model_compiles`), so an error here is a defect of the bundle.
    pub fn model(&self) -> Result<JitModel, LoadError> {
        let Some(index) = self.index() else {
            return self.compile(LoadOptions::default());
        };
        let cached = COMPILED[index].get_or_init(|| {
            self.compile(LoadOptions::default())
                .map_err(|e| e.to_string())
        });
        match cached {
            Ok(model) => Ok(model.clone()),
            // Not cached: the error compiled again to return it typed (a defect of the
            // bundle, which the test rules out).
            Err(_) => self.compile(LoadOptions::default()),
        }
    }

    /// The model compiled with `options`: with the defaults, [`ModelEntry::model`] (compiled
    /// once per process); with any other options, a new compilation.
    ///
    /// # Errors
    /// As [`JitModel::from_source`] (with `Some(Backend::Native)`, a host that Cranelift
    /// cannot compile for).
    pub fn load_with(&self, options: LoadOptions) -> Result<JitModel, LoadError> {
        if options == LoadOptions::default() {
            self.model()
        } else {
            self.compile(options)
        }
    }

    /// This entry's index in [`ALL`]: an entry of the registry or a copy of one (the same
    /// embedded text, by its address, and the same file). A `ModelEntry` written elsewhere
    /// is compiled, never served from the cache.
    fn index(&self) -> Option<usize> {
        let text = self.source();
        ALL.iter()
            .position(|e| e.file == self.file && std::ptr::eq(e.source(), text))
    }

    fn compile(&self, options: LoadOptions) -> Result<JitModel, LoadError> {
        JitModel::from_source_with(self.file, self.source(), options)
    }
}

impl ModelEntry {
    /// The model's name, degrees of freedom and one-line description, read from its file
    /// without deriving or compiling it (what `eomgen list` shows: 0.2 s for the 51 models
    /// compiled, against 3 ms read). Equal to [`ModelSummary::of`] the compiled model (the
    /// test `every_bundled_model_compiles`).
    ///
    /// # Errors
    /// [`LoadError::Diagnostics`] if the file has mistakes (a defect of the bundle).
    pub fn summary(&self) -> Result<ModelSummary, LoadError> {
        let file =
            eomgen_symbolic::model::load(self.file, self.source()).map_err(|diagnostics| {
                LoadError::Diagnostics {
                    path: self.file.to_string(),
                    text: self.source().to_string(),
                    diagnostics,
                }
            })?;
        Ok(ModelSummary {
            name: file.name.value,
            dof: file.coordinates.len(),
            description: file.description,
        })
    }
}

/// The bundled model named `name`.
pub fn find(name: &str) -> Option<&'static ModelEntry> {
    ALL.iter().find(|e| e.name == name)
}

/// The compiled code of each bundled model, by its index in [`ALL`], once compiled (the
/// error as text if it could not be).
static COMPILED: [OnceLock<Result<JitModel, String>>; COUNT] = [const { OnceLock::new() }; COUNT];

/// The text of the `index`-th bundled model, inflated at the first call (empty if the
/// embedded data were corrupt, which the bundled models' tests exclude: loading it then
/// reports an empty file).
fn text(index: usize) -> &'static str {
    static TEXTS: [OnceLock<String>; COUNT] = [const { OnceLock::new() }; COUNT];
    TEXTS[index].get_or_init(|| {
        miniz_oxide::inflate::decompress_to_vec_zlib(DEFLATED[index])
            .ok()
            .and_then(|bytes| String::from_utf8(bytes).ok())
            .unwrap_or_default()
    })
}

/// [`ModelEntry::make`] of the `index`-th bundled model.
fn instantiate(index: usize) -> Box<dyn ModelInfo + Send> {
    let entry = &ALL[index];
    match entry.model() {
        Ok(model) => Box::new(DynFirstOrder::new(model)),
        // Unreachable from a model file or the command line: the CLI and the Python package
        // open bundled models through `ModelEntry::model` and `load_with`, which return the
        // error; only `make`, which library users and tests call, lands here, and only for a
        // bundled file that does not compile, which `every_bundled_model_compiles` rules out.
        Err(e) => panic!("the bundled model `{}` does not compile: {e}", entry.name),
    }
}

include!(concat!(env!("OUT_DIR"), "/models.rs"));
