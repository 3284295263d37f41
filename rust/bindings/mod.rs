//! The pyo3 binding layer: borrows numpy arrays, releases the GIL around every
//! O(n) kernel, calls the pure core and converts `CoreError` into Python
//! exceptions. One file per concern, each a submodule of `_core` with the same
//! name (`_core.allan`, `_core.vn`, `_core.fit`, `_core.records`,
//! `_core.digest`), so the Python side mirrors this folder.

use pyo3::exceptions::{
    PyFileNotFoundError, PyKeyboardInterrupt, PyOSError, PyPermissionError, PyTypeError,
    PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::error::CoreError;

mod allan;
mod digest;
mod fit;
mod interrupt;
mod records;
mod simd;
mod vn;

impl From<CoreError> for PyErr {
    fn from(err: CoreError) -> PyErr {
        core_error_to_py(err, None)
    }
}

/// `err` as a Python exception; `source` (the file parsed, if any) goes into
/// `ParseError.source`. Parse failures become `imunoise.errors.ParseError`
/// with `kind`, `line`, `offset` and `reason` as attributes; I/O failures the
/// `OSError` subclass of their kind.
pub(crate) fn core_error_to_py(err: CoreError, source: Option<String>) -> PyErr {
    match err {
        CoreError::Parse {
            kind,
            line,
            offset,
            reason,
        } => Python::attach(|py| {
            let raised = || -> PyResult<PyErr> {
                let class = py.import("imunoise.errors")?.getattr("ParseError")?;
                let kwargs = PyDict::new(py);
                kwargs.set_item("kind", kind)?;
                kwargs.set_item("line", line)?;
                kwargs.set_item("offset", offset)?;
                kwargs.set_item("source", source)?;
                let instance = class.call((reason,), Some(&kwargs))?;
                Ok(PyErr::from_value(instance))
            };
            raised().unwrap_or_else(|e| e)
        }),
        CoreError::Io { kind, message } => match kind {
            std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
            std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
            _ => PyOSError::new_err(message),
        },
        CoreError::Interrupted => PyKeyboardInterrupt::new_err("interrupted"),
        other => value_error(other.to_string()),
    }
}

/// `imunoise.errors.<class>(message)`, the package's own error class (a subclass
/// of the built-in one), so that `except imunoise.ImunoiseError` catches what the
/// core raises too; the built-in `fallback` where the package cannot be imported.
fn package_error(class: &str, message: String, fallback: fn(String) -> PyErr) -> PyErr {
    Python::attach(|py| {
        let made = || -> PyResult<PyErr> {
            let cls = py.import("imunoise.errors")?.getattr(class)?;
            Ok(PyErr::from_value(cls.call1((message.clone(),))?))
        };
        made().unwrap_or_else(|_| fallback(message.clone()))
    })
}

/// A bad argument value: `imunoise.ImunoiseValueError` (a `ValueError`).
pub(crate) fn value_error(message: impl Into<String>) -> PyErr {
    package_error("ImunoiseValueError", message.into(), PyValueError::new_err)
}

/// An argument of the wrong type: `imunoise.ImunoiseTypeError` (a `TypeError`).
pub(crate) fn type_error(message: impl Into<String>) -> PyErr {
    package_error("ImunoiseTypeError", message.into(), PyTypeError::new_err)
}

/// Adds `imunoise._core.<name>` filled by `register`, and enters it in
/// `sys.modules` so that `import imunoise._core.<name>` works: an extension
/// module's submodules are plain attributes otherwise.
fn add_submodule(
    parent: &Bound<'_, PyModule>,
    name: &str,
    register: fn(&Bound<'_, PyModule>) -> PyResult<()>,
) -> PyResult<()> {
    let py = parent.py();
    let child = PyModule::new(py, name)?;
    register(&child)?;
    parent.add_submodule(&child)?;
    let qualified = format!("imunoise._core.{name}");
    child.setattr("__name__", &qualified)?;
    py.import("sys")?
        .getattr("modules")?
        .set_item(qualified, child)?;
    Ok(())
}

/// Loads NumPy's C API now, while `import imunoise._core` can still fail with
/// a Python exception. rust-numpy loads it on the first array it touches and
/// panics (`expect`) if that import raises: a Ctrl-C landing in it (NumPy's
/// version check runs Python code) would reach the CLI as a Rust panic, exit 1,
/// instead of an interrupt (`benches/faults.py` sends such a Ctrl-C). Here the
/// panic is caught and a KeyboardInterrupt raised again.
fn load_numpy_api(py: Python<'_>) -> PyResult<()> {
    let loaded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        numpy::PyArray1::<f64>::zeros(py, 0, false);
    }));
    match loaded {
        Ok(()) => Ok(()),
        Err(payload) => {
            let message = payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            Err(if message.contains("KeyboardInterrupt") {
                PyKeyboardInterrupt::new_err("interrupted while loading NumPy's C API")
            } else {
                pyo3::exceptions::PyImportError::new_err(format!(
                    "cannot load NumPy's C API: {message}"
                ))
            })
        }
    }
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    load_numpy_api(m.py())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    add_submodule(m, "allan", allan::register)?;
    add_submodule(m, "vn", vn::register)?;
    add_submodule(m, "fit", fit::register)?;
    add_submodule(m, "simd", simd::register)?;
    add_submodule(m, "records", records::register)?;
    add_submodule(m, "digest", digest::register)?;
    Ok(())
}
