//! Bindings for the fingerprint of a file's content (`rust/digest.rs`): the
//! hash runs without the GIL, and Ctrl-C stops it between blocks.

use std::path::PathBuf;

use pyo3::prelude::*;

use crate::digest;

/// fingerprint(path) -> (bytes, mtime_ns, blake3): the size, modification time
/// (ns since the epoch) and BLAKE3 digest (64 hex digits) of the file at `path`.
#[pyfunction]
fn fingerprint(py: Python<'_>, path: PathBuf) -> PyResult<(u64, i128, String)> {
    let mark = super::interrupt::run_interruptible(py, |stop| digest::fingerprint(&path, stop))?;
    Ok((mark.bytes, mark.mtime_ns, mark.blake3))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fingerprint, m)?)?;
    Ok(())
}
