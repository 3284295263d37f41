//! The pyo3 binding layer: borrows numpy arrays, releases the GIL around every
//! O(n) kernel, calls the pure core and converts `CoreError` into Python
//! exceptions. One file per concern, each a submodule of `_core` with the same
//! name (`_core.allan`, `_core.vn`, `_core.fit`), so the Python side mirrors this
//! folder.

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;

use crate::error::CoreError;

mod allan;
mod fit;
mod vn;

impl From<CoreError> for PyErr {
    fn from(err: CoreError) -> PyErr {
        match err {
            CoreError::Io(msg) => PyOSError::new_err(msg),
            other => PyValueError::new_err(other.to_string()),
        }
    }
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

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    add_submodule(m, "allan", allan::register)?;
    add_submodule(m, "vn", vn::register)?;
    add_submodule(m, "fit", fit::register)?;
    Ok(())
}
