//! What every Python plan says about itself, from the library's [`Plan`] seam.

use pt_spectra::plan::Plan;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `{"what": …, "method": "direct" | "basis", "memory_bytes": …, "terms_bytes": …}` of `plan`: what
/// it computes, how a new spectrum's terms are computed, and its memory estimates \[bytes\] (the plan,
/// one spectrum's terms).
pub(crate) fn plan_info<'py, P: Plan>(py: Python<'py>, plan: &P) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("what", plan.describe())?;
    d.set_item("method", plan.method().name())?;
    d.set_item("memory_bytes", plan.bytes())?;
    d.set_item("terms_bytes", plan.terms_bytes())?;
    Ok(d)
}
