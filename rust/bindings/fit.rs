//! Bindings for the noise-model fit: one channel per call (the problem has one
//! row per tau, so the cost is negligible next to the Allan computation).

use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::fit::{self, FitOptions, TERMS};

type FitArrays<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<bool>>,
    f64,
    usize,
);

/// fit_wls(taus, var, edf, terms, reweight, min_share, min_z) -> (coef, cov, supported, chi2, dof)
///
/// `coef` holds (Q², N², B², K², R²), `cov` their 5 × 5 covariance.
#[pyfunction]
#[allow(clippy::too_many_arguments)] // mirrors the Python keyword arguments
#[pyo3(signature = (taus, var, edf, terms, reweight=3, min_share=0.25, min_z=2.0))]
fn fit_wls<'py>(
    py: Python<'py>,
    taus: PyReadonlyArray1<'py, f64>,
    var: PyReadonlyArray1<'py, f64>,
    edf: PyReadonlyArray1<'py, f64>,
    terms: Vec<bool>,
    reweight: usize,
    min_share: f64,
    min_z: f64,
) -> PyResult<FitArrays<'py>> {
    if terms.len() != TERMS {
        return Err(PyValueError::new_err(format!(
            "terms must have {TERMS} flags (Q, N, B, K, R); got {}",
            terms.len()
        )));
    }
    let mut mask = [false; TERMS];
    mask.copy_from_slice(&terms);
    let opts = FitOptions {
        terms: mask,
        reweight,
        min_share,
        min_z,
    };
    let taus: Vec<f64> = taus.as_array().iter().copied().collect();
    let var: Vec<f64> = var.as_array().iter().copied().collect();
    let edf: Vec<f64> = edf.as_array().iter().copied().collect();
    let result = py.detach(|| fit::fit_wls(&taus, &var, &edf, &opts))?;
    let cov: Vec<f64> = result.cov.iter().flatten().copied().collect();
    let cov = numpy::ndarray::Array2::from_shape_vec((TERMS, TERMS), cov)
        .map_err(|e| PyValueError::new_err(e.to_string()))?
        .into_pyarray(py);
    Ok((
        result.coef.to_vec().into_pyarray(py),
        cov,
        result.supported.to_vec().into_pyarray(py),
        result.chi2,
        result.dof,
    ))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fit_wls, m)?)?;
    Ok(())
}
