//! Bindings for VectorNav parsing and writing: the parse runs with the GIL
//! released; the progress callback reacquires it only to be called.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, Weak};

use numpy::{IntoPyArray, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PySlice};

use crate::bindings::core_error_to_py;
use crate::error::CoreError;
use crate::vn::binary::{self, Layout};
use crate::vn::messages::MESSAGES;
use crate::vn::write::{self, AsciiCheck};
use crate::vn::{stream, IssueKind, Table, VnData, FIRST_KEEP};

/// Value buffers given back by the arrays of a stream's pieces, for its next
/// piece ([`StreamValues`]).
type GivenBack = Arc<Mutex<Vec<Vec<f64>>>>;

/// The values of a table handed out by `VnStream.feed`, owned by the arrays that
/// view them. When the last view goes, the buffer goes back to the stream and
/// the next piece is decoded into it: memory already mapped, where a fresh
/// buffer per piece is zeroed page by page by the kernel (a third of convert's
/// CPU on a 1 GB log).
#[pyclass(module = "imunoise._core.vn", frozen)]
struct StreamValues {
    /// Never changed while the object lives (the arrays point into it).
    values: Vec<f64>,
    back: Weak<Mutex<Vec<Vec<f64>>>>,
}

impl Drop for StreamValues {
    fn drop(&mut self) {
        // A stream that is gone, a poisoned lock or a full pool: the buffer is
        // freed as before.
        let Some(pool) = self.back.upgrade() else {
            return;
        };
        if let Ok(mut kept) = pool.lock() {
            if kept.len() < stream::HANDED_BACK {
                kept.push(std::mem::take(&mut self.values));
            }
        };
    }
}

/// The (rows, columns) array of `table`'s values: handed over without a copy,
/// owned by a [`StreamValues`] that gives the buffer back to `back` when it goes
/// (a stream's pieces), or by numpy (a whole parse).
fn values_to_py<'py>(
    py: Python<'py>,
    name: &str,
    table: &mut Table,
    back: Option<&GivenBack>,
) -> PyResult<Bound<'py, PyAny>> {
    let shape = (table.len, table.names.len());
    let values = std::mem::take(&mut table.values);
    let Some(back) = back else {
        return Ok(numpy::ndarray::Array2::from_shape_vec(shape, values)
            .map_err(|e| super::value_error(format!("table {name}: {e}")))?
            .into_pyarray(py)
            .into_any());
    };
    let owner = Bound::new(
        py,
        StreamValues {
            values,
            back: Arc::downgrade(back),
        },
    )?;
    let view = numpy::ndarray::ArrayView2::from_shape(shape, &owner.get().values)
        .map_err(|e| super::value_error(format!("table {name}: {e}")))?;
    // SAFETY: `owner` holds the values and becomes the array's base, so they live
    // as long as the array; it is frozen and its values are never changed or
    // reallocated (its Drop only runs once no array refers to it).
    let matrix = unsafe { PyArray2::borrow_from_array(&view, owner.clone().into_any()) };
    Ok(matrix.into_any())
}

/// Tables as `{name: {column: float64 array}}` and the damaged-record rows as
/// `{name: uint64 array}` (types with damaged records only); `back` as for
/// [`values_to_py`].
fn tables_to_py<'py>(
    py: Python<'py>,
    tables: BTreeMap<String, Table>,
    back: Option<&GivenBack>,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    let out = PyDict::new(py);
    let missing = PyDict::new(py);
    for (name, mut table) in tables {
        if !table.missing.is_empty() {
            missing.set_item(&name, std::mem::take(&mut table.missing).into_pyarray(py))?;
        }
        let cols = PyDict::new(py);
        // One (rows, columns) array, handed over without a copy; every column is
        // a strided view of it, so adjacent columns (x, y, z) form (n, 3) views.
        let matrix = values_to_py(py, &name, &mut table, back)?;
        let all = PySlice::full(py);
        for (k, col_name) in table.names.into_iter().enumerate() {
            cols.set_item(col_name, matrix.get_item((&all, k))?)?;
        }
        for (col_name, col) in table.extra {
            cols.set_item(col_name, col.into_pyarray(py))?;
        }
        out.set_item(name, cols)?;
    }
    Ok((out, missing))
}

/// What a parse produced (`parse_vn`, `VnStream.finish`).
#[pyclass(module = "imunoise._core.vn", frozen, get_all)]
pub struct VnResult {
    /// `{message: {column: float64 array}}`.
    tables: Py<PyDict>,
    /// `{message: uint64 array}`: the good rows before each damaged record.
    missing: Py<PyDict>,
    /// `{message: records}`, command responses included.
    messages: Py<PyDict>,
    /// `{kind: count}` for every name of `ISSUE_KINDS`.
    issues: Py<PyDict>,
    /// `{kind: [(byte_offset, line), ...]}`, at most `FIRST_KEEP` per kind.
    first: Py<PyDict>,
    bytes_total: u64,
    bytes_parsed: u64,
    bytes_in_bad_records: u64,
    bytes_skipped: u64,
    ascii_records: u64,
    binary_records: u64,
}

#[pymethods]
impl VnResult {
    /// `"vn-binary"` if binary packets outnumber sentences, else `"vn-ascii"`.
    #[getter]
    fn format(&self) -> &'static str {
        if self.binary_records > self.ascii_records {
            "vn-binary"
        } else {
            "vn-ascii"
        }
    }
}

fn to_result(py: Python<'_>, data: VnData) -> PyResult<VnResult> {
    let (tables, missing) = tables_to_py(py, data.tables, None)?;
    let messages = PyDict::new(py);
    for (name, n) in data.messages {
        messages.set_item(name, n)?;
    }
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
    Ok(VnResult {
        tables: tables.unbind(),
        missing: missing.unbind(),
        messages: messages.unbind(),
        issues: counts.unbind(),
        first: first.unbind(),
        bytes_total: data.bytes_total,
        bytes_parsed: data.bytes_parsed,
        bytes_in_bad_records: data.bytes_in_bad_records,
        bytes_skipped: data.bytes_skipped,
        ascii_records: data.ascii_records,
        binary_records: data.binary_records,
    })
}

/// The rows of one piece of a stream (`VnStream.feed`).
#[pyclass(module = "imunoise._core.vn", frozen, get_all)]
pub struct VnRows {
    /// `{message: {column: float64 array}}`: the records completed by the piece.
    tables: Py<PyDict>,
    /// `{message: uint64 array}`: good rows of this piece before each damaged record.
    missing: Py<PyDict>,
}

/// VnStream(strict=False): one VN parse fed piece by piece (a file larger than
/// memory). `feed(data)` returns the rows of the records the bytes so far
/// complete; `finish()` the summary of the whole stream (issues, byte
/// accounting, message counts; its tables hold the last rows only).
#[pyclass(module = "imunoise._core.vn")]
pub struct VnStream {
    pieces: Option<stream::Pieces>,
    /// Buffers of earlier pieces' arrays, no longer used, for the next piece.
    given_back: GivenBack,
}

impl VnStream {
    fn pieces(&mut self) -> PyResult<&mut stream::Pieces> {
        self.pieces
            .as_mut()
            .ok_or_else(|| super::value_error("VnStream is finished; feed must come before finish"))
    }
}

#[pymethods]
impl VnStream {
    #[new]
    #[pyo3(signature = (strict=false))]
    fn new(strict: bool) -> VnStream {
        VnStream {
            pieces: Some(stream::Pieces::new(strict)),
            given_back: GivenBack::default(),
        }
    }

    /// `data`: bytes, or any C-contiguous buffer of bytes (a reused `bytearray`,
    /// a read-only `mmap`), parsed in place; the caller must not change it during
    /// the call.
    fn feed<'py>(&mut self, py: Python<'py>, data: &Bound<'py, PyAny>) -> PyResult<VnRows> {
        // bytes as they are; any other buffer of bytes (bytearray, memoryview, a
        // uint8 array) through numpy.frombuffer, without a copy. (pyo3's own
        // buffer protocol is not in the stable ABI of CPython 3.10, abi3-py310.)
        let viewed;
        let slice: &[u8] = if let Ok(bytes) = data.cast::<PyBytes>() {
            bytes.as_bytes()
        } else {
            let view = py
                .import("builtins")?
                .getattr("memoryview")?
                .call1((data,))
                .map_err(|_| {
                    super::type_error(format!(
                        "data must be bytes or a buffer of bytes; got {}",
                        data.get_type()
                            .name()
                            .map(|n| n.to_string())
                            .unwrap_or_default()
                    ))
                })?;
            if !view.getattr("c_contiguous")?.extract::<bool>()? {
                return Err(super::value_error(
                    "data must be a C-contiguous buffer of bytes",
                ));
            }
            viewed = py
                .import("numpy")?
                .call_method1("frombuffer", (view, "u1"))?
                .extract::<PyReadonlyArray1<'py, u8>>()?;
            viewed.as_slice()?
        };
        let given_back = match self.given_back.lock() {
            Ok(mut pool) => std::mem::take(&mut *pool),
            Err(_) => Vec::new(),
        };
        let back = Arc::clone(&self.given_back);
        let pieces = self.pieces()?;
        for buffer in given_back {
            pieces.give_back(buffer);
        }
        let tables = py.detach(|| pieces.feed(slice))?;
        let (tables, missing) = tables_to_py(py, tables, Some(&back))?;
        Ok(VnRows {
            tables: tables.unbind(),
            missing: missing.unbind(),
        })
    }

    fn finish(&mut self, py: Python<'_>) -> PyResult<VnResult> {
        let pieces = self.pieces.take().ok_or_else(|| {
            super::value_error("VnStream is finished; finish must be called once")
        })?;
        // No piece follows: buffers of arrays still alive are then freed, not kept.
        self.given_back = GivenBack::default();
        let data = py.detach(|| pieces.finish())?;
        to_result(py, data)
    }
}

/// parse_vn(source, strict=False, progress=None) -> VnResult
///
/// `source` is `bytes` (parsed in memory) or a path (read in chunks).
/// `progress(done, total)` is called after every chunk of a file.
#[pyfunction]
#[pyo3(signature = (source, strict=false, progress=None))]
fn parse_vn<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    strict: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<VnResult> {
    let data = if let Ok(bytes) = source.cast::<PyBytes>() {
        let slice: &[u8] = bytes.as_bytes();
        py.detach(|| stream::parse_bytes(slice, strict))?
    } else {
        let path: PathBuf = source.extract().map_err(|_| {
            super::value_error(format!(
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
        result.map_err(|e| core_error_to_py(e, Some(path.display().to_string())))?
    };
    to_result(py, data)
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
/// crc=False, line_ending=b"\r\n") -> bytes
#[pyfunction]
#[pyo3(signature = (message, columns, decimals=None, count=None, status=None, crc=false, line_ending=b"\r\n".to_vec()))]
#[pyo3(
    text_signature = "(message, columns, decimals=None, count=None, status=None, crc=False, line_ending=b'\\r\\n')"
)]
#[allow(clippy::too_many_arguments)]
fn write_vn_ascii<'py>(
    py: Python<'py>,
    message: &str,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    decimals: Option<Vec<usize>>,
    count: Option<PyReadonlyArray1<'py, f64>>,
    status: Option<PyReadonlyArray1<'py, f64>>,
    crc: bool,
    line_ending: Vec<u8>,
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
            &line_ending,
        )
    })?;
    Ok(PyBytes::new(py, &out))
}

/// vn_binary_columns(selection) -> (list[str], str): column names (payload order)
/// and table name of the packets for `selection`, a list of (group index, field
/// mask).
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
            super::value_error(format!(
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
    for g in binary::DECODABLE_GROUPS {
        let fields = PyDict::new(py);
        for (k, spec) in binary::named_fields(g) {
            fields.set_item(spec.name, k)?;
        }
        out.set_item(binary::group_name(g), (g, fields))?;
    }
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // The parser's issue kinds in order (the index of each count) and how many
    // first locations it keeps per kind: one source for the Python readers.
    let kinds: Vec<&str> = IssueKind::ALL.iter().map(|k| k.name()).collect();
    m.add("ISSUE_KINDS", pyo3::types::PyTuple::new(m.py(), kinds)?)?;
    m.add("FIRST_KEEP", FIRST_KEEP)?;
    m.add_function(wrap_pyfunction!(vn_binary_fields, m)?)?;
    m.add_function(wrap_pyfunction!(parse_vn, m)?)?;
    m.add_class::<VnResult>()?;
    m.add_class::<VnRows>()?;
    m.add_class::<VnStream>()?;
    m.add_function(wrap_pyfunction!(vn_message_fields, m)?)?;
    m.add_function(wrap_pyfunction!(write_vn_ascii, m)?)?;
    m.add_function(wrap_pyfunction!(vn_binary_columns, m)?)?;
    m.add_function(wrap_pyfunction!(write_vn_binary, m)?)?;
    Ok(())
}
