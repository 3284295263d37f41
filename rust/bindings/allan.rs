//! Bindings for the Allan family: one call computes variances, terms, noise
//! identification and EDF for every tau and channel with the GIL released.

use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::allan::{self, Statistic};

fn parse_statistic(name: &str) -> PyResult<Statistic> {
    Ok(match name {
        "adev" => Statistic::Allan { overlapping: false },
        "oadev" => Statistic::Allan { overlapping: true },
        "mdev" => Statistic::Modified,
        "hdev" => Statistic::Hadamard { overlapping: false },
        "ohdev" => Statistic::Hadamard { overlapping: true },
        "totdev" => Statistic::Total,
        "mtotdev" => Statistic::ModifiedTotal,
        "htotdev" => Statistic::HadamardTotal,
        "theo1" => Statistic::Theo1,
        "theobr" => Statistic::TheoBR,
        other => {
            return Err(PyValueError::new_err(format!(
                "statistic must be one of adev, oadev, mdev, hdev, ohdev, totdev, mtotdev, \
                 htotdev, theo1, theobr; got {other:?}"
            )))
        }
    })
}

type AnalysisArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<u64>>,
    Bound<'py, PyArray2<i32>>,
    Bound<'py, PyArray2<bool>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<u64>>,
);

/// analyse(x, statistic, ms) -> (var, terms, alpha, alpha_identified, edf, missing)
///
/// `x` is a float64 array (n, channels) in any memory order, NaN where a sample
/// is missing; `ms` the averaging factors. 2-D outputs have shape (len(ms),
/// channels); `missing` counts the NaN of each channel.
#[pyfunction]
fn analyse<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    statistic: &str,
    ms: PyReadonlyArray1<'py, u64>,
) -> PyResult<AnalysisArrays<'py>> {
    let statistic = parse_statistic(statistic)?;
    let plan: Vec<(Statistic, usize)> = ms
        .as_array()
        .iter()
        .map(|&m| (statistic, m as usize))
        .collect();
    run_plan(py, x, plan)
}

/// analyse_plan(x, statistics, ms) -> as `analyse`, with one statistic per tau
/// (`statistics[t]` at `ms[t]`; ThêoH is oadev then theobr, ordered by tau).
#[pyfunction]
fn analyse_plan<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    statistics: Vec<String>,
    ms: PyReadonlyArray1<'py, u64>,
) -> PyResult<AnalysisArrays<'py>> {
    let ms = ms.as_array();
    if statistics.len() != ms.len() {
        return Err(PyValueError::new_err(format!(
            "statistics and ms must have the same length; got {} and {}",
            statistics.len(),
            ms.len()
        )));
    }
    let plan = statistics
        .iter()
        .zip(ms.iter())
        .map(|(s, &m)| Ok((parse_statistic(s)?, m as usize)))
        .collect::<PyResult<Vec<_>>>()?;
    run_plan(py, x, plan)
}

fn run_plan<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    plan: Vec<(Statistic, usize)>,
) -> PyResult<AnalysisArrays<'py>> {
    let view = x.as_array();
    let result = py.detach(|| {
        // A C-ordered array with several channels is scattered row by row in one
        // pass, one contiguous channel is copied as a slice; anything else
        // (Fortran order, strided views) is gathered column by column.
        let phases = match view.as_slice() {
            Some(data) if view.ncols() > 1 => allan::row_major_phases(data, view.ncols())?,
            Some(data) => allan::column_phases(vec![data.iter().copied()])?,
            _ => {
                let columns: Vec<_> = view
                    .columns()
                    .into_iter()
                    .map(|c| c.into_iter().copied())
                    .collect();
                allan::column_phases(columns)?
            }
        };
        allan::analyse_plan(&phases, &plan)
    })?;
    let shape = (plan.len(), result.channels);
    let reshape_err = |e: numpy::ndarray::ShapeError| PyValueError::new_err(e.to_string());
    let to2 = |v: Vec<f64>| numpy::ndarray::Array2::from_shape_vec(shape, v).map_err(reshape_err);
    let var = to2(result.var)?.into_pyarray(py);
    let edf = to2(result.edf)?.into_pyarray(py);
    let alpha = numpy::ndarray::Array2::from_shape_vec(shape, result.alpha)
        .map_err(reshape_err)?
        .into_pyarray(py);
    let identified = numpy::ndarray::Array2::from_shape_vec(shape, result.alpha_identified)
        .map_err(reshape_err)?
        .into_pyarray(py);
    let terms: Vec<u64> = result.terms.iter().map(|&t| t as u64).collect();
    let terms = numpy::ndarray::Array2::from_shape_vec(shape, terms)
        .map_err(reshape_err)?
        .into_pyarray(py);
    let missing: Vec<u64> = result.missing.iter().map(|&t| t as u64).collect();
    Ok((var, terms, alpha, identified, edf, missing.into_pyarray(py)))
}

/// theobr_work(n_phase, ms) -> (direct steps, fast units) of ThêoBR's bias ratio and
/// Theo1 at `ms`, per channel (see `allan::theo::theo1_work`)
#[pyfunction]
fn theobr_work(n_phase: usize, ms: Vec<usize>) -> (f64, f64) {
    allan::theo::theobr_work(n_phase, &ms)
}

/// estimator_terms(statistic, n_phase, ms) -> terms per averaging factor (0: does not fit)
#[pyfunction]
fn estimator_terms<'py>(
    py: Python<'py>,
    statistic: &str,
    n_phase: usize,
    ms: PyReadonlyArray1<'py, u64>,
) -> PyResult<Bound<'py, PyArray1<u64>>> {
    let statistic = parse_statistic(statistic)?;
    let terms: Vec<u64> = ms
        .as_array()
        .iter()
        .map(|&m| statistic.terms(n_phase, m as usize) as u64)
        .collect();
    Ok(terms.into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(analyse, m)?)?;
    m.add_function(wrap_pyfunction!(estimator_terms, m)?)?;
    m.add_function(wrap_pyfunction!(analyse_plan, m)?)?;
    m.add_function(wrap_pyfunction!(theobr_work, m)?)?;
    Ok(())
}
