//! Bindings for the noise-model fit: one channel per call (the problem has one
//! row per tau, so it is small next to the Allan computation), and the model's
//! per-term curves for plots and predictions. The model's constants (term kinds
//! and their parameters, most Gauss–Markov terms, flicker factor) are exported here so
//! Python never writes them again.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::fit::filter::OutputFilter;
use crate::fit::{self, Kind, Options, Term, FLICKER_FACTOR, IEEE_TERM_NAMES, MAX_GM, MAX_TONES};

/// The fit of one channel, as `_core.fit.NoiseFit`.
#[pyclass(name = "NoiseFit", module = "imunoise._core.fit", frozen, get_all)]
struct PyNoiseFit {
    /// (kind, parameters) of each term, in the model's order (`TERM_KINDS` names
    /// the parameters of each kind).
    terms: Vec<(&'static str, Vec<f64>)>,
    /// Covariance of the terms' coordinates, term after term (`TERM_KINDS` names
    /// the coordinates of each kind); NaN variance for a coordinate on a bound.
    cov: Py<PyArray2<f64>>,
    /// δ, the relative model discrepancy.
    discrepancy: f64,
    /// Octave-weighted residual sum with the sampling variance alone.
    chi2: f64,
    /// Octaves of evidence.
    n_eff: f64,
    /// Free parameters of the chosen structure.
    parameters: usize,
    /// Its Bayesian information criterion.
    bic: f64,
    /// (kind, alternative kind or None, ΔBIC) of each term of a selected
    /// structure that the alternative fits as well: not resolved by the data.
    ambiguous: Vec<(&'static str, Option<&'static str>, f64)>,
}

/// The output filter's gains, checked by the core.
fn output_filter(gain: Option<PyReadonlyArray1<'_, f64>>) -> PyResult<Option<OutputFilter>> {
    gain.map(|g| OutputFilter::new(g.as_array().to_vec()))
        .transpose()
        .map_err(PyErr::from)
}

/// The output filter a fit passes the white term through: its gains and the
/// relative standard uncertainty of the white level they were measured against.
fn measured_filter(
    gain: Option<PyReadonlyArray1<'_, f64>>,
    level_std: f64,
) -> PyResult<Option<OutputFilter>> {
    Ok(output_filter(gain)?
        .map(|f| f.with_level_std(level_std))
        .transpose()?)
}

fn to_matrix(rows: Vec<Vec<f64>>, cols: usize) -> PyResult<Array2<f64>> {
    let n = rows.len();
    Array2::from_shape_vec((n, cols), rows.into_iter().flatten().collect())
        .map_err(|e| super::value_error(e.to_string()))
}

/// fit_noise(taus, var, edf, fs, counts, select=True, filter=None, filter_level_std=0.0)
/// -> NoiseFit: `counts` the (kind, number) of each kind of term the model may use
/// (`select`, the most) or has (not `select`, exactly); kinds not named have none.
#[pyfunction]
#[allow(clippy::too_many_arguments)] // mirrors the Python keyword arguments
#[pyo3(signature = (taus, var, edf, fs, counts, select=true, filter=None, filter_level_std=0.0))]
fn fit_noise<'py>(
    py: Python<'py>,
    taus: PyReadonlyArray1<'py, f64>,
    var: PyReadonlyArray1<'py, f64>,
    edf: PyReadonlyArray1<'py, f64>,
    fs: f64,
    counts: Vec<(String, usize)>,
    select: bool,
    filter: Option<PyReadonlyArray1<'py, f64>>,
    filter_level_std: f64,
) -> PyResult<PyNoiseFit> {
    let filter = measured_filter(filter, filter_level_std)?;
    let kinds = (counts.iter())
        .map(|(name, n)| Ok((Kind::from_name(name)?, *n)))
        .collect::<Result<Vec<_>, crate::error::CoreError>>()?;
    let opts = Options {
        select,
        ..Options::exactly(&kinds)
    };
    let taus = taus.as_array().to_vec();
    let var = var.as_array().to_vec();
    let edf = edf.as_array().to_vec();
    let r = py.detach(|| fit::fit_noise(&taus, &var, &edf, fs, &opts, filter.as_ref()))?;
    noise_fit(py, r)
}

/// fit_noise_at(taus, var, edf, fs, terms, filter=None, filter_level_std=0.0) -> NoiseFit:
/// the structure of `terms` (kind, parameters) with their times and frequencies
/// held and their variances fitted again (no search, no ties).
#[pyfunction]
#[allow(clippy::too_many_arguments)] // mirrors the Python keyword arguments
#[pyo3(signature = (taus, var, edf, fs, terms, filter=None, filter_level_std=0.0))]
fn fit_noise_at<'py>(
    py: Python<'py>,
    taus: PyReadonlyArray1<'py, f64>,
    var: PyReadonlyArray1<'py, f64>,
    edf: PyReadonlyArray1<'py, f64>,
    fs: f64,
    terms: Vec<(String, Vec<f64>)>,
    filter: Option<PyReadonlyArray1<'py, f64>>,
    filter_level_std: f64,
) -> PyResult<PyNoiseFit> {
    let filter = measured_filter(filter, filter_level_std)?;
    let typed = typed_terms(&terms)?;
    let taus = taus.as_array().to_vec();
    let var = var.as_array().to_vec();
    let edf = edf.as_array().to_vec();
    let r = py.detach(|| fit::fit_noise_at(&taus, &var, &edf, fs, &typed, filter.as_ref()))?;
    noise_fit(py, r)
}

/// The Python view of a core fit.
fn noise_fit(py: Python<'_>, r: fit::NoiseFit) -> PyResult<PyNoiseFit> {
    let size = r.cov.len();
    Ok(PyNoiseFit {
        terms: (r.terms.iter())
            .map(|t| (t.kind().name(), t.parameters()))
            .collect(),
        cov: to_matrix(r.cov, size)?.into_pyarray(py).unbind(),
        discrepancy: r.discrepancy,
        chi2: r.chi2,
        n_eff: r.n_eff,
        parameters: r.parameters,
        bic: r.bic,
        ambiguous: (r.ambiguous.iter())
            .map(|a| (a.kind.name(), a.alternative.map(Kind::name), a.delta_bic))
            .collect(),
    })
}

/// allan_terms(taus, fs, terms, filter=None) -> (len(taus), len(terms)): the
/// Allan variance of each term, given as (kind, parameters).
#[pyfunction]
#[pyo3(signature = (taus, fs, terms, filter=None))]
fn allan_terms<'py>(
    py: Python<'py>,
    taus: PyReadonlyArray1<'py, f64>,
    fs: f64,
    terms: Vec<(String, Vec<f64>)>,
    filter: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    if !(fs.is_finite() && fs > 0.0) {
        return Err(super::value_error(format!(
            "fs must be finite and > 0; got {fs}"
        )));
    }
    let filter = output_filter(filter)?;
    let typed = typed_terms(&terms)?;
    let taus = taus.as_array().to_vec();
    let rows = py.detach(|| fit::allan_terms(&taus, fs, &typed, filter.as_ref()));
    Ok(to_matrix(rows, typed.len())?.into_pyarray(py))
}

/// The core's typed terms of (kind, parameters) pairs.
fn typed_terms(terms: &[(String, Vec<f64>)]) -> PyResult<Vec<Term>> {
    (terms.iter())
        .map(|(kind, p)| Term::new(Kind::from_name(kind)?, p))
        .collect::<Result<Vec<Term>, _>>()
        .map_err(PyErr::from)
}

fn check_model(taus: &[f64], fs: f64) -> PyResult<()> {
    if !(fs.is_finite() && fs > 0.0) {
        return Err(super::value_error(format!(
            "fs must be finite and > 0; got {fs}"
        )));
    }
    if taus.is_empty() {
        return Err(super::value_error("taus must not be empty".to_string()));
    }
    if let Some(t) = taus.iter().find(|t| !(t.is_finite() && **t > 0.0)) {
        return Err(super::value_error(format!(
            "taus must be finite and > 0; got {t}"
        )));
    }
    Ok(())
}

/// A record's duration: `record` (finite, at least the longest tau) or the longest tau.
fn record_length(record: Option<f64>, taus: &[f64]) -> PyResult<f64> {
    let longest = taus[taus.len() - 1];
    match record {
        None => Ok(longest),
        Some(r) if r.is_finite() && r >= longest => Ok(r),
        Some(r) => Err(super::value_error(format!(
            "record must be finite and at least the longest tau ({longest} s); got {r}"
        ))),
    }
}

/// datasheet(terms, cov, taus, fs, record=None, filter=None) -> {"N"|"B"|"K": (value, std)}:
/// the datasheet values of a model (NaN where not resolved) with their
/// uncertainty propagated from `cov`, the covariance of the terms' coordinates;
/// `record` the record's duration (s; default the longest tau).
#[pyfunction]
#[pyo3(signature = (terms, cov, taus, fs, record=None, filter=None))]
#[allow(clippy::too_many_arguments)] // mirrors the Python keyword arguments
fn datasheet<'py>(
    py: Python<'py>,
    terms: Vec<(String, Vec<f64>)>,
    cov: PyReadonlyArray2<'py, f64>,
    taus: PyReadonlyArray1<'py, f64>,
    fs: f64,
    record: Option<f64>,
    filter: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Vec<(&'static str, (f64, f64))>> {
    let typed = typed_terms(&terms)?;
    let taus = taus.as_array().to_vec();
    check_model(&taus, fs)?;
    let record = record_length(record, &taus)?;
    let filter = output_filter(filter)?;
    let size: usize = typed
        .iter()
        .map(|t| t.kind().coordinate_names().len())
        .sum();
    let cov = cov.as_array();
    if cov.shape() != [size, size] {
        return Err(super::value_error(format!(
            "cov must be {size} x {size} (the terms' coordinates); got {:?}",
            cov.shape()
        )));
    }
    let cov: Vec<Vec<f64>> = cov.rows().into_iter().map(|r| r.to_vec()).collect();
    let model = fit::datasheet::Model {
        terms: &typed,
        taus: &taus,
        record,
        fs,
        filter: filter.as_ref(),
    };
    Ok(py.detach(|| {
        (fit::datasheet::Datasheet::ALL.iter())
            .map(|&d| {
                let v = fit::datasheet::propagated(d, &model, &cov);
                (d.name(), (v.value, v.std))
            })
            .collect()
    }))
}

/// datasheet_shares(terms, fs, record) -> [(white, walk)]: what each term adds to
/// the datasheet's N² (`Term::white_share`) and to its K² over a record of `record`
/// seconds (`Term::walk_share`), the rules `datasheet` sums.
#[pyfunction]
fn datasheet_shares(
    terms: Vec<(String, Vec<f64>)>,
    fs: f64,
    record: f64,
) -> PyResult<Vec<(f64, f64)>> {
    let typed = typed_terms(&terms)?;
    for (name, v) in [("fs", fs), ("record", record)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(super::value_error(format!(
                "{name} must be finite and > 0; got {v}"
            )));
        }
    }
    Ok((typed.iter())
        .map(|t| (t.white_share(fs), t.walk_share(record)))
        .collect())
}

/// model_floor(terms, taus, fs, filter=None) -> (τ, σ) or None: the floor of the
/// model's deviation over `taus`, where B is read.
#[pyfunction]
#[pyo3(signature = (terms, taus, fs, filter=None))]
fn model_floor<'py>(
    terms: Vec<(String, Vec<f64>)>,
    taus: PyReadonlyArray1<'py, f64>,
    fs: f64,
    filter: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Option<(f64, f64)>> {
    let typed = typed_terms(&terms)?;
    let taus = taus.as_array().to_vec();
    check_model(&taus, fs)?;
    let filter = output_filter(filter)?;
    let record = taus[taus.len() - 1];
    Ok(fit::datasheet::floor(&fit::datasheet::Model {
        terms: &typed,
        taus: &taus,
        record,
        fs,
        filter: filter.as_ref(),
    }))
}

/// filter_factor(taus, fs, filter) -> c(τ): the white term's Allan variance
/// through the output filter over the one without.
#[pyfunction]
fn filter_factor<'py>(
    py: Python<'py>,
    taus: PyReadonlyArray1<'py, f64>,
    fs: f64,
    filter: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let taus = taus.as_array().to_vec();
    check_model(&taus, fs)?;
    let filter = OutputFilter::new(filter.as_array().to_vec())?;
    let ms: Vec<f64> = taus.iter().map(|t| t * fs).collect();
    let factors = py.detach(|| filter.white_factors(&ms));
    Ok(factors.into_pyarray(py))
}

/// density_allan(taus, fs, density) -> the Allan variance at `taus` of a process
/// whose one-sided density (units²/Hz, any sign) is `density` on the output
/// filter's grid, from 0 Hz to fs/2, linear between its points.
#[pyfunction]
fn density_allan<'py>(
    py: Python<'py>,
    taus: PyReadonlyArray1<'py, f64>,
    fs: f64,
    density: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let taus = taus.as_array().to_vec();
    check_model(&taus, fs)?;
    let density = density.as_array().to_vec();
    let out = py.detach(|| fit::filter::density_allan(&density, &taus, fs))?;
    Ok(out.into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("IEEE_TERM_NAMES", IEEE_TERM_NAMES.to_vec())?;
    m.add("MAX_GAUSS_MARKOV", MAX_GM)?;
    m.add("MAX_TONES", MAX_TONES)?;
    let kinds: Vec<(&str, Vec<&str>, Vec<&str>)> = (Kind::ALL.iter())
        .map(|k| {
            (
                k.name(),
                k.parameter_names().to_vec(),
                k.coordinate_names().to_vec(),
            )
        })
        .collect();
    m.add("TERM_KINDS", kinds)?;
    let most: Vec<(&str, usize)> = Kind::ALL.iter().map(|k| (k.name(), k.most())).collect();
    m.add("TERM_MOST", most)?;
    m.add("FLICKER_FACTOR", FLICKER_FACTOR)?;
    m.add("GM_PEAK", fit::term::GM_PEAK)?;
    m.add("FLAT_SLOPE", fit::datasheet::FLAT_SLOPE)?;
    m.add_class::<PyNoiseFit>()?;
    m.add_function(wrap_pyfunction!(fit_noise, m)?)?;
    m.add_function(wrap_pyfunction!(fit_noise_at, m)?)?;
    m.add_function(wrap_pyfunction!(allan_terms, m)?)?;
    m.add_function(wrap_pyfunction!(filter_factor, m)?)?;
    m.add_function(wrap_pyfunction!(density_allan, m)?)?;
    m.add_function(wrap_pyfunction!(datasheet, m)?)?;
    m.add_function(wrap_pyfunction!(model_floor, m)?)?;
    m.add_function(wrap_pyfunction!(datasheet_shares, m)?)?;
    Ok(())
}
