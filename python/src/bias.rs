//! The bias convention of the Python faces (`bias_convention=`): one meaning of b2, bs, b3 for every
//! model ([`pt_spectra::bias`]).

use crate::value_error;
use pt_spectra::bias::BiasConvention;
use pyo3::prelude::*;

/// The convention named `name` (None: velocileptors'). With `warn_for` (a model whose bs and b3 were
/// FAST-PT's before they meant one thing), a `UserWarning` when bs or b3 is given without a name.
pub(crate) fn convention(
    py: Python<'_>,
    name: Option<&str>,
    bs: Option<f64>,
    b3: Option<f64>,
    warn_for: Option<&str>,
) -> PyResult<BiasConvention> {
    let given = |x: Option<f64>| x.is_some_and(|v| v != 0.0);
    if let (None, Some(model)) = (name, warn_for) {
        if given(bs) || given(b3) {
            let note = pt_spectra::bias::implicit_convention_warning(
                model,
                "bs and b3",
                "bias_convention='fastpt'",
            );
            let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
            PyErr::warn(py, &category, &std::ffi::CString::new(note)?, 2)?;
        }
    }
    name.map_or(Ok(BiasConvention::default()), |n| {
        n.parse().map_err(value_error)
    })
}

/// The bias `values` (a dict named as `from_convention` names them; a missing one is 0) in
/// `to_convention`, as a dict of its names.
#[pyfunction]
#[pyo3(signature = (values, from_convention, to_convention="velocileptors"))]
pub(crate) fn convert_bias(
    values: std::collections::BTreeMap<String, f64>,
    from_convention: &str,
    to_convention: &str,
) -> PyResult<Vec<(String, f64)>> {
    let from: BiasConvention = from_convention.parse().map_err(value_error)?;
    let to: BiasConvention = to_convention.parse().map_err(value_error)?;
    let names = from.names();
    if let Some(bad) = values.keys().find(|k| !names.contains(&k.as_str())) {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "`{bad}` is not a bias parameter of the {from} convention: its names are {}",
            names.join(", ")
        )));
    }
    let v = names.map(|n| values.get(n).copied().unwrap_or(0.0));
    let b = pt_spectra::bias::BiasParams::from_convention(from, v);
    Ok(to
        .names()
        .iter()
        .zip(b.in_convention(to))
        .map(|(n, x)| ((*n).to_string(), x))
        .collect())
}
