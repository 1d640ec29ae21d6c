//! `pt_spectra.halo`: b(k) and P_εε(k) from measured P_mm, P_mh, P_hh, as `pt-spectra halo`.

use crate::{detached, floats, value_error, Table};
use pt_spectra::halo::MeasuredSpectrum;
use pt_spectra::jobs::{halo_table, HaloRequest};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// One measured spectrum from a tuple `(k, P)` or `(k, P, sigma)` of arrays.
fn measured(name: &'static str, obj: &Bound<'_, PyAny>) -> PyResult<MeasuredSpectrum> {
    let parts: Vec<Bound<'_, PyAny>> = obj.try_iter().and_then(|i| i.collect()).map_err(|_| {
        PyValueError::new_err(format!(
            "{name}: expected a tuple (k, P) or (k, P, sigma) of arrays"
        ))
    })?;
    if !(2..=3).contains(&parts.len()) {
        return Err(PyValueError::new_err(format!(
            "{name}: expected a tuple (k, P) or (k, P, sigma) of arrays, got {} items",
            parts.len()
        )));
    }
    let k = crate::k_array(&parts[0], &format!("{name} k"))?.into_vec();
    let p = floats(&parts[1], &format!("{name} P"))?;
    let error = match parts.get(2) {
        Some(e) => Some(floats(e, &format!("{name} sigma"))?),
        None => None,
    };
    MeasuredSpectrum::new(name, "arrays", k, p, error).map_err(value_error)
}

/// b = P_mh/P_mm and P_εε = P_hh − P_mh²/P_mm with propagated errors: see the Python wrapper.
#[pyfunction]
#[pyo3(signature = (pmm, pmh, phh, number_density=None))]
pub(crate) fn halo(
    py: Python<'_>,
    pmm: &Bound<'_, PyAny>,
    pmh: &Bound<'_, PyAny>,
    phh: &Bound<'_, PyAny>,
    number_density: Option<f64>,
) -> PyResult<Table> {
    let request = HaloRequest {
        pmm: measured("P_mm", pmm)?,
        pmh: measured("P_mh", pmh)?,
        phh: measured("P_hh", phh)?,
        number_density,
    };
    let (table, seconds) = detached(py, || halo_table(&request))?;
    Table::plain(py, table, "halo", seconds)
}
