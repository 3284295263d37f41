//! Bindings for the record file that `convert` writes its `.npy` data through:
//! float64 arrays (views of the parser's tables, any non-negative strides) are
//! gathered into records and written with the GIL released, without a copy
//! made in Python.

use std::path::PathBuf;

use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::records::{self, Columns};

/// RecordFile(path, width): appends records of `width` float64 values to the
/// existing file `path` (its header written by the caller).
#[pyclass(module = "imunoise._core.records")]
pub struct RecordFile {
    file: Option<records::RecordFile>,
}

/// The block of `a`: a 1-D array is one value per row, a 2-D one its columns.
fn block<'a>(a: &'a PyReadonlyArrayDyn<'_, f64>) -> PyResult<Columns<'a>> {
    let shape = a.shape();
    let strides = a.strides();
    let (rows, width, row_bytes, col_bytes) = match shape.len() {
        1 => (shape[0], 1, strides[0], 8),
        2 => (shape[0], shape[1], strides[0], strides[1]),
        n => {
            return Err(super::value_error(format!(
                "arrays must be 1-D or 2-D; got {n}-D"
            )))
        }
    };
    let stride = |bytes: isize| -> PyResult<usize> {
        usize::try_from(bytes)
            .ok()
            .filter(|b| b % 8 == 0)
            .map(|b| b / 8)
            .ok_or_else(|| {
                super::value_error(format!(
                    "array strides must be non-negative multiples of 8 bytes; got {strides:?}"
                ))
            })
    };
    let (row_stride, col_stride) = (stride(row_bytes)?, stride(col_bytes)?);
    let span = if rows == 0 || width == 0 {
        0
    } else {
        (rows - 1) * row_stride + (width - 1) * col_stride + 1
    };
    let data: &[f64] = if span == 0 {
        &[]
    } else {
        // SAFETY: the array (borrowed read-only for 'a) owns every value its
        // shape and non-negative strides name, the last at `span - 1` elements
        // past its data pointer, which is aligned for f64 (strides and pointer of
        // a float64 array from numpy; `Columns::new` checks the arithmetic).
        let ptr = a.as_array().as_ptr();
        if !(ptr as usize).is_multiple_of(std::mem::align_of::<f64>()) {
            return Err(super::value_error("array data must be aligned to 8 bytes"));
        }
        unsafe { std::slice::from_raw_parts(ptr, span) }
    };
    Ok(Columns::new(data, rows, width, row_stride, col_stride)?)
}

#[pymethods]
impl RecordFile {
    #[new]
    fn new(path: PathBuf, width: usize) -> PyResult<RecordFile> {
        Ok(RecordFile {
            file: Some(records::RecordFile::append_to(&path, width)?),
        })
    }

    /// Append one record per row: row r of every array in `arrays`, in order.
    fn append(&mut self, py: Python<'_>, arrays: Vec<PyReadonlyArrayDyn<'_, f64>>) -> PyResult<()> {
        let file = self
            .file
            .as_mut()
            .ok_or_else(|| super::value_error("RecordFile is closed"))?;
        let blocks = arrays.iter().map(block).collect::<PyResult<Vec<_>>>()?;
        py.detach(|| -> PyResult<()> {
            file.append(&blocks)?;
            file.start_writeback();
            Ok(())
        })
    }

    /// Rows appended so far.
    #[getter]
    fn rows(&self) -> u64 {
        self.file.as_ref().map_or(0, |f| f.rows())
    }

    /// The file's BLAKE3 digest (64 hex digits) with `head` as its first bytes
    /// (the header, as long as when the file was opened), then the records.
    fn digest(&self, head: &[u8]) -> PyResult<String> {
        let file = self
            .file
            .as_ref()
            .ok_or_else(|| super::value_error("RecordFile is closed"))?;
        Ok(file.digest(head)?.to_hex().to_string())
    }

    /// Close the file (every append is already written to it).
    fn close(&mut self) {
        self.file = None;
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<RecordFile>()?;
    Ok(())
}
