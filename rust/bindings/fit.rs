//! Bindings for the noise-model fit: one channel per call (the problem has one
//! row per tau, so it is small next to the Allan computation), and the model's
//! per-term curves for plots and predictions. The model's constants (term names,
//! most Gauss–Markov terms, parameter slots, flicker factor) are exported here so
//! Python never writes them again.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::fit::filter::OutputFilter;
use crate::fit::{
    self, Options, FLICKER_FACTOR, IEEE_TERMS, IEEE_TERM_NAMES, MAX_GM, MAX_TONES, MOTION_SLOT,
    PARAMETERS, RESONANCE_SLOT, SINE_SLOT, SKEW_SLOT,
};

/// The fit of one channel, as `_core.fit.NoiseFit`.
#[pyclass(name = "NoiseFit", module = "imunoise._core.fit", frozen, get_all)]
struct PyNoiseFit {
    /// (Q², N², B², K², R²).
    ieee: Py<PyArray1<f64>>,
    /// (k, 2) rows of (q², τc), one per Gauss–Markov term.
    gm: Py<PyArray2<f64>>,
    /// (k, 2) rows of (s², f₀), k ≤ MAX_TONES: the tones.
    sine: Py<PyArray2<f64>>,
    /// (k, 4) rows of (r², f_r, τr, skew), k ≤ 1: the resonance.
    resonance: Py<PyArray2<f64>>,
    /// (k, 2) rows of (σθ², τc), k ≤ 1: the bounded motion.
    motion: Py<PyArray2<f64>>,
    /// PARAMETERS × PARAMETERS covariance of (Q²…R², then q², ln τc per slot,
    /// then s², ln f₀ per tone slot, then r², ln f_r, ln τr, skew, then σθ², ln τc;
    /// NaN variance of ln f_r at fs/2 and of the skew at ±1).
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
}

fn ieee_flags(terms: &[bool]) -> PyResult<[bool; IEEE_TERMS]> {
    if terms.len() != IEEE_TERMS {
        return Err(super::value_error(format!(
            "terms must have {IEEE_TERMS} flags (Q, N, B, K, R); got {}",
            terms.len()
        )));
    }
    let mut mask = [false; IEEE_TERMS];
    mask.copy_from_slice(terms);
    Ok(mask)
}

/// The output filter's gains, checked by the core.
fn output_filter(gain: Option<PyReadonlyArray1<'_, f64>>) -> PyResult<Option<OutputFilter>> {
    gain.map(|g| OutputFilter::new(g.as_array().to_vec()))
        .transpose()
        .map_err(PyErr::from)
}

fn to_matrix(rows: Vec<Vec<f64>>, cols: usize) -> PyResult<Array2<f64>> {
    let n = rows.len();
    Array2::from_shape_vec((n, cols), rows.into_iter().flatten().collect())
        .map_err(|e| super::value_error(e.to_string()))
}

/// fit_noise(taus, var, edf, fs, terms, gm, select, tones, resonance, motion, filter) -> NoiseFit
#[pyfunction]
#[allow(clippy::too_many_arguments)] // mirrors the Python keyword arguments
#[pyo3(signature = (taus, var, edf, fs, terms, gm=3, select=true, tones=2, resonance=true, motion=true, filter=None))]
fn fit_noise<'py>(
    py: Python<'py>,
    taus: PyReadonlyArray1<'py, f64>,
    var: PyReadonlyArray1<'py, f64>,
    edf: PyReadonlyArray1<'py, f64>,
    fs: f64,
    terms: Vec<bool>,
    gm: usize,
    select: bool,
    tones: usize,
    resonance: bool,
    motion: bool,
    filter: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<PyNoiseFit> {
    let filter = output_filter(filter)?;
    let opts = Options {
        ieee: ieee_flags(&terms)?,
        gm,
        tones,
        resonance,
        motion,
        select,
    };
    let taus = taus.as_array().to_vec();
    let var = var.as_array().to_vec();
    let edf = edf.as_array().to_vec();
    let r = py.detach(|| fit::fit_noise(&taus, &var, &edf, fs, &opts, filter.as_ref()))?;
    let gm_rows: Vec<Vec<f64>> = r.gm.iter().map(|&(q2, tc)| vec![q2, tc]).collect();
    let sine_rows: Vec<Vec<f64>> = r.sine.iter().map(|&(s2, f0)| vec![s2, f0]).collect();
    let res_rows: Vec<Vec<f64>> = (r.resonance.iter())
        .map(|&(a, f, t, skew)| vec![a, f, t, skew])
        .collect();
    let motion_rows: Vec<Vec<f64>> = r.motion.iter().map(|&(v, tc)| vec![v, tc]).collect();
    Ok(PyNoiseFit {
        ieee: r.ieee.to_vec().into_pyarray(py).unbind(),
        gm: to_matrix(gm_rows, 2)?.into_pyarray(py).unbind(),
        sine: to_matrix(sine_rows, 2)?.into_pyarray(py).unbind(),
        resonance: to_matrix(res_rows, 4)?.into_pyarray(py).unbind(),
        motion: to_matrix(motion_rows, 2)?.into_pyarray(py).unbind(),
        cov: to_matrix(r.cov, PARAMETERS)?.into_pyarray(py).unbind(),
        discrepancy: r.discrepancy,
        chi2: r.chi2,
        n_eff: r.n_eff,
        parameters: r.parameters,
        bic: r.bic,
    })
}

/// noise_terms(taus, fs, ieee, gm, sine, resonance, motion) -> (len(taus), 5 + k + j + l + n)
/// Allan variance of each term
#[pyfunction]
#[allow(clippy::too_many_arguments)] // mirrors the Python keyword arguments
#[pyo3(signature = (taus, fs, ieee, gm, sine=Vec::new(), resonance=Vec::new(), motion=Vec::new(), filter=None))]
fn noise_terms<'py>(
    py: Python<'py>,
    taus: PyReadonlyArray1<'py, f64>,
    fs: f64,
    ieee: Vec<f64>,
    gm: Vec<(f64, f64)>,
    sine: Vec<(f64, f64)>,
    resonance: Vec<(f64, f64, f64, f64)>,
    motion: Vec<(f64, f64)>,
    filter: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let filter = output_filter(filter)?;
    if ieee.len() != IEEE_TERMS {
        return Err(super::value_error(format!(
            "ieee must have {IEEE_TERMS} values (Q², N², B², K², R²); got {}",
            ieee.len()
        )));
    }
    if !(fs.is_finite() && fs > 0.0) {
        return Err(super::value_error(format!(
            "fs must be finite and > 0; got {fs}"
        )));
    }
    let mut coef = [0.0; IEEE_TERMS];
    coef.copy_from_slice(&ieee);
    if let Some(&(_, f0)) = sine.iter().find(|s| !(s.1.is_finite() && s.1 > 0.0)) {
        return Err(super::value_error(format!(
            "sine frequencies must be finite and > 0 Hz; got {f0}"
        )));
    }
    if let Some(&(_, f, t, _)) = resonance
        .iter()
        .find(|r| !(r.1.is_finite() && r.1 > 0.0 && r.2.is_finite() && r.2 > 0.0))
    {
        return Err(super::value_error(format!(
            "resonance frequency and damping time must be finite and > 0; got {f} Hz, {t} s"
        )));
    }
    if let Some(&(_, _, _, skew)) = resonance.iter().find(|r| r.3.is_nan() || r.3.abs() > 1.0) {
        return Err(super::value_error(format!(
            "resonance skew must be in [-1, 1] (a non-negative spectrum); got {skew}"
        )));
    }
    if let Some(&(_, t)) = motion.iter().find(|m| !(m.1.is_finite() && m.1 > 0.0)) {
        return Err(super::value_error(format!(
            "motion correlation times must be finite and > 0 s; got {t}"
        )));
    }
    let cols = IEEE_TERMS + gm.len() + sine.len() + resonance.len() + motion.len();
    let taus = taus.as_array().to_vec();
    let oscillators = (sine.as_slice(), resonance.as_slice(), motion.as_slice());
    let rows = fit::terms(&taus, fs, &coef, &gm, oscillators, filter.as_ref());
    Ok(to_matrix(rows, cols)?.into_pyarray(py))
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
    if !(fs.is_finite() && fs > 0.0) {
        return Err(super::value_error(format!(
            "fs must be finite and > 0; got {fs}"
        )));
    }
    let filter = OutputFilter::new(filter.as_array().to_vec())?;
    let taus = taus.as_array().to_vec();
    if let Some(t) = taus.iter().find(|t| !(t.is_finite() && **t > 0.0)) {
        return Err(super::value_error(format!(
            "taus must be finite and > 0; got {t}"
        )));
    }
    let factors = py.detach(|| {
        taus.iter()
            .map(|t| filter.white_factor(t * fs))
            .collect::<Vec<f64>>()
    });
    Ok(factors.into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("IEEE_TERM_NAMES", IEEE_TERM_NAMES.to_vec())?;
    m.add("MAX_GAUSS_MARKOV", MAX_GM)?;
    m.add("MAX_TONES", MAX_TONES)?;
    m.add("PARAMETERS", PARAMETERS)?;
    m.add("SINE_SLOT", SINE_SLOT)?;
    m.add("RESONANCE_SLOT", RESONANCE_SLOT)?;
    m.add("SKEW_SLOT", SKEW_SLOT)?;
    m.add("MOTION_SLOT", MOTION_SLOT)?;
    m.add("FLICKER_FACTOR", FLICKER_FACTOR)?;
    m.add_class::<PyNoiseFit>()?;
    m.add_function(wrap_pyfunction!(fit_noise, m)?)?;
    m.add_function(wrap_pyfunction!(noise_terms, m)?)?;
    m.add_function(wrap_pyfunction!(filter_factor, m)?)?;
    Ok(())
}
