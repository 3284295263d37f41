//! Bindings for the instruction-set level of the dispatched kernels: which one
//! runs, which the CPU has, and forcing a lower one (the tests run every path;
//! `IMUNOISE_SIMD` pins one for a reproducible run).

use pyo3::prelude::*;

use crate::simd::{self, Level};

/// The level the kernels use now.
#[pyfunction]
fn level() -> &'static str {
    simd::level().name()
}

/// The best level this CPU has.
#[pyfunction]
fn detected() -> &'static str {
    simd::detected().name()
}

/// Every level name, lowest first.
#[pyfunction]
fn levels() -> Vec<&'static str> {
    Level::ALL.iter().map(|l| l.name()).collect()
}

/// Forces the kernels down to `name` (None: the CPU's best); a level above the
/// CPU's runs as the CPU's.
#[pyfunction]
#[pyo3(signature = (name))]
fn force(name: Option<&str>) -> PyResult<()> {
    let wanted = match name {
        None => None,
        Some(n) => Some(Level::from_name(n).ok_or_else(|| {
            let known: Vec<&str> = Level::ALL.iter().map(|l| l.name()).collect();
            super::value_error(format!(
                "SIMD level must be one of {}; got {n:?}",
                known.join(", ")
            ))
        })?),
    };
    simd::force(wanted);
    Ok(())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(level, m)?)?;
    m.add_function(wrap_pyfunction!(detected, m)?)?;
    m.add_function(wrap_pyfunction!(levels, m)?)?;
    m.add_function(wrap_pyfunction!(force, m)?)?;
    Ok(())
}
