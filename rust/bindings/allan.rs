//! Bindings for the Allan family: one call computes variances, terms, noise
//! identification and EDF for every tau and channel with the GIL released, and
//! returns them as one frozen [`AnalysisArrays`] (`Analysis` in Python). Statistic
//! names come from the Rust table (`allan::Statistic`), exported as `STATISTICS`,
//! and those that can skip missing samples as `GAP_SKIPPING`.

use numpy::ndarray::Array2;
use numpy::{Element, IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use super::interrupt::run_interruptible;
use crate::allan::estimators::theobr;
use crate::allan::{self, Ladder, RatioOptions, Statistic};

/// The arrays of one analysis; 2-D arrays are (taus, channels).
#[pyclass(name = "Analysis", module = "imunoise._core.allan", frozen, get_all)]
struct AnalysisArrays {
    /// Variance at each tau and channel (NaN where gaps leave no term).
    var: Py<PyArray2<f64>>,
    /// Terms each estimate averages (with gaps: the terms used).
    terms: Py<PyArray2<u64>>,
    /// Noise type α used for the EDF.
    alpha: Py<PyArray2<i32>>,
    /// Whether α was identified at that tau (else taken from the nearest ones).
    alpha_identified: Py<PyArray2<bool>>,
    /// Equivalent degrees of freedom.
    edf: Py<PyArray2<f64>>,
    /// Missing samples (NaN) per channel, shape (channels,).
    missing: Py<PyArray1<u64>>,
}

fn parse_statistic(name: &str) -> PyResult<Statistic> {
    Ok(name.parse::<Statistic>()?)
}

/// analyse(x, statistic, ms) -> Analysis
///
/// `x` is a float64 array (n, channels) in any memory order, NaN where a sample
/// is missing; `ms` the averaging factors. 2-D outputs have shape (len(ms),
/// channels); `missing` counts the NaN of each channel. `ratio_ladder`
/// ("taylor-howe" or "sp1065") and `ratio_block` (≥ 1) choose how ThêoBR's bias
/// ratio is computed (`allan::RatioOptions`).
#[pyfunction]
#[pyo3(signature = (x, statistic, ms, ratio_ladder="taylor-howe", ratio_block=1))]
fn analyse<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    statistic: &str,
    ms: PyReadonlyArray1<'py, u64>,
    ratio_ladder: &str,
    ratio_block: usize,
) -> PyResult<AnalysisArrays> {
    let ratio = ratio_options(ratio_ladder, ratio_block)?;
    let statistic = parse_statistic(statistic)?;
    let plan: Vec<(Statistic, usize)> = ms
        .as_array()
        .iter()
        .map(|&m| (statistic, m as usize))
        .collect();
    run_plan(py, x, plan, ratio)
}

/// The bias ratio's options from their Python names.
fn ratio_options(ladder: &str, block: usize) -> PyResult<RatioOptions> {
    if block == 0 {
        return Err(super::value_error("ratio_block must be at least 1; got 0"));
    }
    Ok(RatioOptions {
        ladder: ladder.parse::<Ladder>()?,
        block,
    })
}

/// analyse_plan(x, statistics, ms) -> as `analyse`, with one statistic per tau
/// (`statistics[t]` at `ms[t]`; ThêoH is oadev then theobr, ordered by tau).
#[pyfunction]
#[pyo3(signature = (x, statistics, ms, ratio_ladder="taylor-howe", ratio_block=1))]
fn analyse_plan<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    statistics: Vec<String>,
    ms: PyReadonlyArray1<'py, u64>,
    ratio_ladder: &str,
    ratio_block: usize,
) -> PyResult<AnalysisArrays> {
    let ratio = ratio_options(ratio_ladder, ratio_block)?;
    let ms = ms.as_array();
    if statistics.len() != ms.len() {
        return Err(super::value_error(format!(
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
    run_plan(py, x, plan, ratio)
}

fn run_plan<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    plan: Vec<(Statistic, usize)>,
    ratio: RatioOptions,
) -> PyResult<AnalysisArrays> {
    let view = x.as_array();
    let result = run_interruptible(py, |stop| {
        // A C-ordered array with several channels is scattered row by row in one
        // pass, one contiguous channel is copied and summed on all cores;
        // anything else (Fortran order, strided views) is gathered column by column.
        let phases = match view.as_slice() {
            Some(data) if view.ncols() > 1 => allan::row_major_phases(data, view.ncols())?,
            Some(data) => vec![allan::contiguous_phase(data)?],
            _ => {
                let columns: Vec<_> = view
                    .columns()
                    .into_iter()
                    .map(|c| c.into_iter().copied())
                    .collect();
                allan::column_phases(columns)?
            }
        };
        allan::analyse_plan_with(&phases, &plan, ratio, stop)
    })?;
    let shape = (plan.len(), result.channels);
    let as_u64 = |v: &[usize]| v.iter().map(|&t| t as u64).collect::<Vec<u64>>();
    Ok(AnalysisArrays {
        var: table(py, shape, result.var)?,
        terms: table(py, shape, as_u64(&result.terms))?,
        alpha: table(py, shape, result.alpha)?,
        alpha_identified: table(py, shape, result.alpha_identified)?,
        edf: table(py, shape, result.edf)?,
        missing: as_u64(&result.missing).into_pyarray(py).unbind(),
    })
}

/// A tau-major vector as a (taus, channels) array.
fn table<T: Element>(
    py: Python<'_>,
    shape: (usize, usize),
    values: Vec<T>,
) -> PyResult<Py<PyArray2<T>>> {
    let array =
        Array2::from_shape_vec(shape, values).map_err(|e| super::value_error(e.to_string()))?;
    Ok(array.into_pyarray(py).unbind())
}

/// theobr_seconds(n_phase, ms, ratio_ladder="taylor-howe", ratio_block=1) -> rough
/// seconds of ThêoBR's bias ratio plus Theo1 at `ms` on one channel (see
/// `allan::estimators::theobr::estimated_seconds`)
#[pyfunction]
#[pyo3(signature = (n_phase, ms, ratio_ladder="taylor-howe", ratio_block=1))]
fn theobr_seconds(
    n_phase: usize,
    ms: Vec<usize>,
    ratio_ladder: &str,
    ratio_block: usize,
) -> PyResult<f64> {
    let ratio = ratio_options(ratio_ladder, ratio_block)?;
    Ok(theobr::estimated_seconds(n_phase, &ms, ratio))
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

/// estimator_edf(statistic, n_phase, alphas, ms) -> the EDF of a gap-free record of
/// `n_phase` phase points for noise type `alphas[i]` at averaging factor `ms[i]`
/// (the statistic's own EDF model, as `analyse` uses it)
#[pyfunction]
fn estimator_edf<'py>(
    py: Python<'py>,
    statistic: &str,
    n_phase: usize,
    alphas: PyReadonlyArray1<'py, i32>,
    ms: PyReadonlyArray1<'py, u64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let statistic = parse_statistic(statistic)?;
    let (alphas, ms) = (alphas.as_array(), ms.as_array());
    if alphas.len() != ms.len() {
        return Err(super::value_error(format!(
            "alphas and ms must have the same length; got {} and {}",
            alphas.len(),
            ms.len()
        )));
    }
    let model = statistic.spec().edf;
    let edf: Vec<f64> = alphas
        .iter()
        .zip(ms.iter())
        .map(|(&alpha, &m)| model.edf(alpha, m as usize, n_phase))
        .collect();
    Ok(edf.into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let names = |keep: fn(&Statistic) -> bool| -> Vec<&'static str> {
        Statistic::ALL
            .iter()
            .filter(|s| keep(s))
            .map(|s| s.name())
            .collect()
    };
    m.add("STATISTICS", PyTuple::new(m.py(), names(|_| true))?)?;
    m.add(
        "GAP_SKIPPING",
        PyTuple::new(m.py(), names(|s| s.skips_gaps()))?,
    )?;
    m.add("THEOBR_MIN_SAMPLES", theobr::MIN_SAMPLES)?;
    m.add_class::<AnalysisArrays>()?;
    m.add_function(wrap_pyfunction!(analyse, m)?)?;
    m.add_function(wrap_pyfunction!(estimator_terms, m)?)?;
    m.add_function(wrap_pyfunction!(estimator_edf, m)?)?;
    m.add_function(wrap_pyfunction!(analyse_plan, m)?)?;
    m.add_function(wrap_pyfunction!(theobr_seconds, m)?)?;
    Ok(())
}
