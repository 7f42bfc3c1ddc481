//! Library reports to Python objects: a report's `Serialize` (the same value `--json` prints)
//! turned into dicts, lists, floats and strings, with lists of numbers as numpy arrays when
//! asked.
//!
//! Kept here rather than taken from `pythonize`: no release of it follows pyo3 0.30, and it
//! would give lists where a notebook wants arrays (a study's error column, a matrix's rows).

use numpy::{PyArray1, PyArrayMethods};
use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde::Serialize;
use serde_json::Value;

/// How numeric lists come out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lists {
    /// As Python lists: the dict equals `json.loads` of the command line's `--json` output.
    Plain,
    /// A non-empty list of numbers as a 1-D array (`int64` when every entry is an integer,
    /// else `float64`, with `None` — a value not defined there — as NaN), a non-empty list of equal-length non-empty lists of numbers as a 2-D
    /// array (one row per inner list), and a table — a non-empty list of objects with the
    /// same keys and scalar values (a study's runs) — as a dict of columns (numbers as
    /// arrays, `None` in a column of numbers as NaN, booleans as a `bool` array, anything
    /// else as a list); anything else as in `Plain`.
    Arrays,
}

/// `report` as a Python object, through its `Serialize` (the JSON the command line prints:
/// non-finite numbers are `None`, as they are `null` there).
///
/// # Errors
/// A `RuntimeError` when the report cannot be serialised (a map with non-string keys: a
/// programming error of the report type).
pub fn to_python<'py, T: Serialize + ?Sized>(
    py: Python<'py>,
    report: &T,
    lists: Lists,
) -> PyResult<Bound<'py, PyAny>> {
    let value = serde_json::to_value(report).map_err(|e| {
        pyo3::exceptions::PyRuntimeError::new_err(format!("a report could not be serialised: {e}"))
    })?;
    value_to_python(py, &value, lists)
}

/// A report whose conversion to Python objects waits for its first use: what a call returns
/// beside arrays that are the result itself (a simulation's summary: names, parameters,
/// stats, events), so that a call whose caller reads only the arrays does not pay for the
/// dicts. Calling it gives the report as [`to_python`] with [`Lists::Plain`] does (a new
/// object at each call; the Python layer keeps the first).
#[pyclass(frozen, module = "eomgen._eomgen")]
pub struct DeferredReport {
    /// The report, serialised on call.
    report: Box<dyn ErasedReport>,
}

/// A report that can be held without its type: `Serialize` is not object safe.
trait ErasedReport: Send + Sync {
    /// The report as `to_python` gives it.
    fn to_python<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>>;
}

impl<T: Serialize + Send + Sync> ErasedReport for T {
    fn to_python<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, self, Lists::Plain)
    }
}

impl DeferredReport {
    /// `report`, converted when the Python layer first calls it.
    pub fn new<T: Serialize + Send + Sync + 'static>(report: T) -> DeferredReport {
        DeferredReport {
            report: Box::new(report),
        }
    }
}

#[pymethods]
impl DeferredReport {
    /// The report as dicts, lists, floats and strings.
    fn __call__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.report.to_python(py)
    }
}

/// A JSON value as a Python object (see [`Lists`]).
///
/// # Errors
/// Those of the Python objects' construction (out of memory).
pub fn value_to_python<'py>(
    py: Python<'py>,
    value: &Value,
    lists: Lists,
) -> PyResult<Bound<'py, PyAny>> {
    match value {
        Value::Null => Ok(py.None().into_bound(py)),
        Value::Bool(b) => b.into_bound_py_any(py),
        Value::Number(n) => number(py, n),
        Value::String(s) => s.into_bound_py_any(py),
        Value::Array(items) => {
            if lists == Lists::Arrays
                && let Some(array) = numeric_array(py, items)?
            {
                return Ok(array);
            }
            if lists == Lists::Arrays
                && let Some(columns) = table(py, items)?
            {
                return Ok(columns);
            }
            let list = PyList::empty(py);
            for item in items {
                list.append(value_to_python(py, item, lists)?)?;
            }
            Ok(list.into_any())
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (key, item) in map {
                dict.set_item(key, value_to_python(py, item, lists)?)?;
            }
            Ok(dict.into_any())
        }
    }
}

/// A JSON number as a Python `int` when it is one, else a `float`.
fn number<'py>(py: Python<'py>, n: &serde_json::Number) -> PyResult<Bound<'py, PyAny>> {
    if let Some(i) = n.as_i64() {
        i.into_bound_py_any(py)
    } else if let Some(u) = n.as_u64() {
        u.into_bound_py_any(py)
    } else {
        n.as_f64().unwrap_or(f64::NAN).into_bound_py_any(py)
    }
}

/// `items` as a 1-D or 2-D numpy array, if it is a non-empty list of numbers or a non-empty
/// list of equal-length non-empty lists of numbers; `None` otherwise.
fn numeric_array<'py>(py: Python<'py>, items: &[Value]) -> PyResult<Option<Bound<'py, PyAny>>> {
    if items.is_empty() {
        return Ok(None);
    }
    // Numbers with `null` among them (a value that is not finite, or not defined there:
    // an unbounded resonance) are a float array with NaN there, as in a table's columns.
    if items.iter().all(|v| v.is_number() || v.is_null()) && items.iter().any(Value::is_number) {
        return flat(py, items).map(Some);
    }
    let rows: Option<Vec<&Vec<Value>>> = items.iter().map(Value::as_array).collect();
    let Some(rows) = rows else {
        return Ok(None);
    };
    let width = rows[0].len();
    if width == 0
        || rows
            .iter()
            .any(|r| r.len() != width || !r.iter().all(Value::is_number))
    {
        return Ok(None);
    }
    let cells: Vec<Value> = rows.into_iter().flatten().cloned().collect();
    let array = flat(py, &cells)?;
    Ok(Some(array.call_method1("reshape", (items.len(), width))?))
}

/// `items` as a dict of columns, if it is a non-empty list of objects with the same keys
/// whose values are all scalars (numbers, `null`, booleans, strings); `None` otherwise.
fn table<'py>(py: Python<'py>, items: &[Value]) -> PyResult<Option<Bound<'py, PyAny>>> {
    let rows: Option<Vec<&serde_json::Map<String, Value>>> =
        items.iter().map(Value::as_object).collect();
    let Some(rows) = rows else {
        return Ok(None);
    };
    let Some(first) = rows.first() else {
        return Ok(None);
    };
    let scalar = |v: &Value| !(v.is_array() || v.is_object());
    let same = rows.iter().all(|r| {
        r.len() == first.len() && r.iter().all(|(k, v)| first.contains_key(k) && scalar(v))
    });
    if !same {
        return Ok(None);
    }
    let dict = PyDict::new(py);
    for key in first.keys() {
        let column: Vec<&Value> = rows.iter().map(|r| &r[key]).collect();
        let numbers = column.iter().all(|v| v.is_number() || v.is_null())
            && column.iter().any(|v| v.is_number());
        if numbers && column.iter().all(|v| v.is_i64()) {
            let ints: Vec<i64> = column.iter().filter_map(|v| v.as_i64()).collect();
            dict.set_item(key, PyArray1::from_vec(py, ints))?;
        } else if numbers {
            let floats: Vec<f64> = column
                .iter()
                .map(|v| v.as_f64().unwrap_or(f64::NAN))
                .collect();
            dict.set_item(key, PyArray1::from_vec(py, floats))?;
        } else if column.iter().all(|v| v.is_boolean()) {
            let flags: Vec<bool> = column.iter().filter_map(|v| v.as_bool()).collect();
            dict.set_item(key, PyArray1::from_vec(py, flags))?;
        } else {
            let list = PyList::empty(py);
            for v in column {
                list.append(value_to_python(py, v, Lists::Plain)?)?;
            }
            dict.set_item(key, list)?;
        }
    }
    Ok(Some(dict.into_any()))
}

/// Numbers as a 1-D array: `int64` when every one is an integer, else `float64`.
fn flat<'py>(py: Python<'py>, numbers: &[Value]) -> PyResult<Bound<'py, PyAny>> {
    if numbers.iter().all(|v| v.is_i64()) {
        let ints: Vec<i64> = numbers.iter().filter_map(Value::as_i64).collect();
        return Ok(PyArray1::from_vec(py, ints).into_any());
    }
    let floats: Vec<f64> = numbers
        .iter()
        .map(|v| v.as_f64().unwrap_or(f64::NAN))
        .collect();
    Ok(PyArray1::from_vec(py, floats).into_any())
}

/// A flat row-major buffer as a `rows × columns` float array (no copy of the buffer).
///
/// # Errors
/// Numpy's, when `data.len() != rows · columns` (never, for the callers' buffers).
pub fn matrix<'py>(
    py: Python<'py>,
    data: Vec<f64>,
    rows: usize,
    columns: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let array = PyArray1::from_vec(py, data);
    Ok(array.reshape([rows, columns])?.into_any())
}
