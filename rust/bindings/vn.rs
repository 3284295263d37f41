//! Bindings for VectorNav parsing and writing: the parse runs with the GIL
//! released; the progress callback reacquires it only to be called.

use std::path::PathBuf;

use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PySlice};

use crate::error::CoreError;
use crate::vn::ascii::MESSAGES;
use crate::vn::binary::Layout;
use crate::vn::write::{self, AsciiCheck};
use crate::vn::{stream, IssueKind, VnData};

fn to_dict<'py>(py: Python<'py>, data: VnData) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let tables = PyDict::new(py);
    let missing = PyDict::new(py);
    for (name, table) in data.tables {
        if !table.missing.is_empty() {
            missing.set_item(&name, table.missing.into_pyarray(py))?;
        }
        let cols = PyDict::new(py);
        // One (rows, columns) array, handed over without a copy; every column is
        // a strided view of it, so adjacent columns (x, y, z) form (n, 3) views.
        let shape = (table.len, table.names.len());
        let matrix = numpy::ndarray::Array2::from_shape_vec(shape, table.values)
            .map_err(|e| PyValueError::new_err(format!("table {name}: {e}")))?
            .into_pyarray(py);
        let all = PySlice::full(py);
        for (k, col_name) in table.names.into_iter().enumerate() {
            cols.set_item(col_name, matrix.get_item((&all, k))?)?;
        }
        for (col_name, col) in table.extra {
            cols.set_item(col_name, col.into_pyarray(py))?;
        }
        tables.set_item(name, cols)?;
    }
    out.set_item("tables", tables)?;
    out.set_item("missing", missing)?;
    let messages = PyDict::new(py);
    for (name, n) in data.messages {
        messages.set_item(name, n)?;
    }
    out.set_item("messages", messages)?;
    let counts = PyDict::new(py);
    let first = PyDict::new(py);
    for kind in IssueKind::ALL {
        counts.set_item(kind.name(), data.issues.counts[kind as usize])?;
        let locs: Vec<(u64, u64)> = data.issues.first[kind as usize]
            .iter()
            .map(|l| (l.offset, l.line))
            .collect();
        first.set_item(kind.name(), locs)?;
    }
    out.set_item("issues", counts)?;
    out.set_item("first", first)?;
    out.set_item("bytes_total", data.bytes_total)?;
    out.set_item("bytes_parsed", data.bytes_parsed)?;
    out.set_item("bytes_in_bad_records", data.bytes_in_bad_records)?;
    out.set_item("bytes_skipped", data.bytes_skipped)?;
    out.set_item("ascii_records", data.ascii_records)?;
    out.set_item("binary_records", data.binary_records)?;
    Ok(out)
}

/// parse_vn(source, strict=False, progress=None) -> dict
///
/// `source` is `bytes` (parsed in memory) or a path (read in chunks). Returns
/// tables of float64 columns per message type, message counts, issue counts and
/// first locations, byte accounting, and `missing`: per message type, the good
/// rows before each damaged record of that type (uint64). `progress(done, total)` is called after
/// every chunk of a file.
#[pyfunction]
#[pyo3(signature = (source, strict=false, progress=None))]
fn parse_vn<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    strict: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let data = if let Ok(bytes) = source.cast::<PyBytes>() {
        let slice: &[u8] = bytes.as_bytes();
        py.detach(|| stream::parse_bytes(slice, strict))?
    } else {
        let path: PathBuf = source.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "source must be bytes or a path; got {}",
                source
                    .get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            ))
        })?;
        let mut cb_err: Option<PyErr> = None;
        let result = py.detach(|| {
            let mut cb = |done: u64, total: u64| -> Result<(), CoreError> {
                if let Some(f) = &progress {
                    Python::attach(|py| f.bind(py).call1((done, total)).map(|_| ())).map_err(
                        |e| {
                            cb_err = Some(e);
                            CoreError::InvalidArgument("progress callback raised".into())
                        },
                    )?;
                }
                Ok(())
            };
            stream::parse_file(&path, strict, &mut cb)
        });
        if let Some(e) = cb_err {
            return Err(e);
        }
        result?
    };
    to_dict(py, data)
}

/// parse_vn_chunk(data, strict=False, fin=False) -> dict
///
/// Like `parse_vn` on `bytes`, for one piece of a longer stream: only complete
/// records are decoded (all of `data` when `fin`); `"bytes_consumed"` says how
/// far, so the caller can carry the rest into the next piece. Locations are
/// relative to `data`.
#[pyfunction]
#[pyo3(signature = (data, strict=false, fin=false))]
fn parse_vn_chunk<'py>(
    py: Python<'py>,
    data: &Bound<'py, PyBytes>,
    strict: bool,
    fin: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let slice: &[u8] = data.as_bytes();
    let (used, parsed) = py.detach(|| stream::parse_prefix(slice, strict, fin))?;
    let out = to_dict(py, parsed)?;
    out.set_item("bytes_consumed", used)?;
    Ok(out)
}

/// vn_message_fields() -> dict[str, list[str]]: field names of every ASCII message.
#[pyfunction]
fn vn_message_fields(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    for m in MESSAGES {
        out.set_item(m.id, PyList::new(py, m.fields)?)?;
    }
    Ok(out)
}

/// write_vn_ascii(message, columns, decimals=None, count=None, status=None,
/// crc=False, eol=b"\r\n") -> bytes
#[pyfunction]
#[pyo3(signature = (message, columns, decimals=None, count=None, status=None, crc=false, eol=b"\r\n".to_vec()))]
#[allow(clippy::too_many_arguments)]
fn write_vn_ascii<'py>(
    py: Python<'py>,
    message: &str,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    decimals: Option<Vec<usize>>,
    count: Option<PyReadonlyArray1<'py, f64>>,
    status: Option<PyReadonlyArray1<'py, f64>>,
    crc: bool,
    eol: Vec<u8>,
) -> PyResult<Bound<'py, PyBytes>> {
    let cols: Vec<&[f64]> = columns
        .iter()
        .map(|c| c.as_slice())
        .collect::<Result<_, _>>()?;
    let count = count.as_ref().map(|c| c.as_slice()).transpose()?;
    let status = status.as_ref().map(|c| c.as_slice()).transpose()?;
    let check = if crc {
        AsciiCheck::Crc16
    } else {
        AsciiCheck::Xor8
    };
    let out = py.detach(|| {
        write::write_ascii(
            message,
            &cols,
            decimals.as_deref(),
            count,
            status,
            check,
            &eol,
        )
    })?;
    Ok(PyBytes::new(py, &out))
}

/// vn_binary_columns(selection) -> list[str]: column names (payload order) of the
/// packets for `selection`, a list of (group index, field mask).
#[pyfunction]
fn vn_binary_columns(selection: Vec<(usize, u32)>) -> PyResult<(Vec<String>, String)> {
    let layout: Layout = write::binary_layout(&selection)?;
    Ok((layout.column_names(), layout.table_name()))
}

/// write_vn_binary(selection, columns) -> bytes; `columns` maps every name of
/// `vn_binary_columns(selection)` to a float64 array.
#[pyfunction]
fn write_vn_binary<'py>(
    py: Python<'py>,
    selection: Vec<(usize, u32)>,
    columns: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyBytes>> {
    let layout = write::binary_layout(&selection)?;
    let names = layout.column_names();
    let mut arrays: Vec<PyReadonlyArray1<'py, f64>> = Vec::with_capacity(names.len());
    for name in &names {
        let item = columns.get_item(name)?.ok_or_else(|| {
            PyValueError::new_err(format!(
                "columns is missing {name:?}; this selection needs {names:?}"
            ))
        })?;
        arrays.push(item.extract()?);
    }
    let cols: Vec<&[f64]> = arrays
        .iter()
        .map(|c| c.as_slice())
        .collect::<Result<_, _>>()?;
    let out = py.detach(|| write::write_binary(&layout, &cols))?;
    Ok(PyBytes::new(py, &out))
}

/// vn_binary_fields() -> dict[str, tuple[int, dict[str, int]]]: group name ->
/// (group index, field name -> field number) for the decodable groups.
#[pyfunction]
fn vn_binary_fields(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    for g in [0usize, 1, 2, 4] {
        let fields = PyDict::new(py);
        for k in 0..31 {
            if let Some(spec) = crate::vn::binary::field_spec(g, k) {
                if spec.name != "reserved" {
                    fields.set_item(spec.name, k)?;
                }
            }
        }
        out.set_item(crate::vn::binary::group_name(g), (g, fields))?;
    }
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(vn_binary_fields, m)?)?;
    m.add_function(wrap_pyfunction!(parse_vn, m)?)?;
    m.add_function(wrap_pyfunction!(parse_vn_chunk, m)?)?;
    m.add_function(wrap_pyfunction!(vn_message_fields, m)?)?;
    m.add_function(wrap_pyfunction!(write_vn_ascii, m)?)?;
    m.add_function(wrap_pyfunction!(vn_binary_columns, m)?)?;
    m.add_function(wrap_pyfunction!(write_vn_binary, m)?)?;
    Ok(())
}
