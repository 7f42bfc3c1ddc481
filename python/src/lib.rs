//! The Python package `eomgen`'s compiled module, `eomgen._eomgen`: a thin layer over the
//! library. Every computation is a library call (`eomgen::analysis`, `eomgen::listing`, the
//! cross-check of `eomgen_symbolic`); this crate converts arguments, releases the
//! interpreter while the call runs, and turns the report (the same `Serialize` value the
//! command line prints with `--json`) into dicts and numpy arrays. The Python package
//! (`python/python/eomgen`) adds docstrings, result objects and exceptions.

mod animate;
mod batch;
mod convert;
mod course;
mod errors;
mod model;
mod studies;

use pyo3::prelude::*;

/// The compiled half of the `eomgen` package.
#[pymodule]
fn _eomgen(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // NumPy's C API is looked up at the first array made; made here, at import, rather than
    // in a call that Ctrl-C interrupts, where the lookup failed and rust-numpy panicked
    // ("Failed to access NumPy array API capsule … KeyboardInterrupt").
    let _ = numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
    m.add_class::<model::CoreModel>()?;
    m.add_function(wrap_pyfunction!(batch::simulate_many, m)?)?;
    m.add_function(wrap_pyfunction!(animate::animate_simulation, m)?)?;
    m.add_function(wrap_pyfunction!(animate::animate_modes, m)?)?;
    m.add_function(wrap_pyfunction!(bundled_models, m)?)?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(simulation_defaults, m)?)?;
    studies::register(m)?;
    course::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

/// The bundled models' names, in the order `eomgen list` shows them.
#[pyfunction]
fn bundled_models() -> Vec<&'static str> {
    eomgen::models::ALL.iter().map(|e| e.name).collect()
}

/// The integration methods' names and one-line summaries, from the library's method table
/// (`Method::table`, in its order).
#[pyfunction]
fn methods() -> Vec<(&'static str, &'static str)> {
    eomgen::Method::table()
        .iter()
        .map(|row| (row.name, row.summary))
        .collect()
}

/// The defaults of a simulation, those of `eomgen simulate` without options:
/// `(t_end, method, rtol, atol, (alpha, beta))`.
#[pyfunction]
fn simulation_defaults() -> (f64, &'static str, f64, f64, (f64, f64)) {
    use eomgen::analysis::SimulationOptions as Defaults;
    let [alpha, beta] = eomgen::Stabilization::DEFAULT_BAUMGARTE_GAINS;
    (
        Defaults::DEFAULT_T_END,
        Defaults::DEFAULT_METHOD.name(),
        Defaults::DEFAULT_RTOL,
        Defaults::DEFAULT_ATOL,
        (alpha, beta),
    )
}
