//! The pyo3 binding layer: borrows numpy arrays, releases the GIL around every
//! O(n) kernel, calls the pure core and converts `CoreError` into Python
//! exceptions. One file per concern; each registers its functions here.

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

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    allan::register(m)?;
    vn::register(m)?;
    fit::register(m)?;
    Ok(())
}
