//! The library's typed errors as the package's exceptions (defined in Python, in
//! `eomgen/errors.py`, so that they pickle between Dask workers and the client with their
//! attributes).

use eomgen::{LoadError, OpenError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

pyo3::import_exception!(eomgen.errors, ModelError);
pyo3::import_exception!(eomgen.errors, ParameterError);
pyo3::import_exception!(eomgen.errors, AnalysisError);

/// A model that could not be opened as `eomgen.ModelError(message, diagnostics)`: a file
/// with mistakes carries one `{"file", "line", "column", "message", "help"}` dict per
/// located diagnostic (the objects of the command line's `--json` error), an unknown name
/// or an unreadable file none.
pub fn open_error(py: Python<'_>, error: OpenError) -> PyErr {
    match error {
        OpenError::Load(LoadError::Diagnostics {
            path,
            text,
            diagnostics,
        }) => model_error(py, &path, &text, &diagnostics),
        other => ModelError::new_err((other.to_string(), PyList::empty(py).unbind())),
    }
}

/// A file's located diagnostics as `eomgen.ModelError`: the message is every diagnostic
/// rendered on its source line, as the command line prints them.
pub fn model_error(
    py: Python<'_>,
    path: &str,
    text: &str,
    diagnostics: &[eomgen_symbolic::model::Diagnostic],
) -> PyErr {
    let rendered: Vec<String> = diagnostics.iter().map(|d| d.render(path, text)).collect();
    let message = format!(
        "{} error(s) in the model file `{path}`\n{}",
        diagnostics.len(),
        rendered.join("\n")
    );
    let list = PyList::empty(py);
    for d in diagnostics {
        let item = PyDict::new(py);
        let filled = item
            .set_item("file", path)
            .and_then(|()| item.set_item("line", d.location.line))
            .and_then(|()| item.set_item("column", d.location.column))
            .and_then(|()| item.set_item("message", &d.message))
            .and_then(|()| item.set_item("help", &d.help))
            .and_then(|()| list.append(item));
        if let Err(e) = filled {
            return e;
        }
    }
    ModelError::new_err((message, list.unbind()))
}

/// An analysis that could not be done (no equilibrium, a failed eigenproblem, options out of
/// range) as `eomgen.AnalysisError(message)`.
pub fn analysis_error(message: impl std::fmt::Display) -> PyErr {
    AnalysisError::new_err(message.to_string())
}

/// An unknown or unusable parameter as `eomgen.ParameterError(message)`.
pub fn parameter_error(message: impl std::fmt::Display) -> PyErr {
    ParameterError::new_err(message.to_string())
}
