//! `pt_spectra.fisher`: Fisher forecasts of redshift surveys with the galaxy model
//! (`pt_spectra::forecast`).

use crate::value_error;
use pt_spectra::forecast::{fisher as lib_fisher, Parameters, SurveyBin};
use pt_spectra::progress::Silent;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// The keys of a bin dict that are not numbers (the numbers: `SurveyBin::KEYS` and the nuisance
/// parameters).
const LIST_KEYS: [&str; 3] = ["ells", "free", "priors"];

fn bin_of(i: usize, d: &Bound<'_, PyDict>) -> PyResult<SurveyBin> {
    let mut values = Vec::new();
    for (key, value) in d.iter() {
        let key: String = key.extract()?;
        if !LIST_KEYS.contains(&key.as_str()) {
            values.push((key, value.extract::<f64>()?));
        }
    }
    let mut bin =
        SurveyBin::from_values(&format!("survey bin {}", i + 1), &values).map_err(value_error)?;
    if let Some(v) = d.get_item("ells")? {
        bin.ells = v.extract()?;
    }
    if let Some(v) = d.get_item("free")? {
        bin.free = v.extract()?;
    }
    if let Some(v) = d.get_item("priors")? {
        bin.priors = v
            .extract::<std::collections::BTreeMap<String, f64>>()?
            .into_iter()
            .collect();
    }
    Ok(bin)
}

/// The Fisher forecast of a survey: `bins` a list of dicts (z, volume [(Mpc/h)^3], n_bar
/// [(h/Mpc)^3], k_max [h/Mpc], b1, and optionally k_min (0.01), dk (0.01), ells ([0, 2]), free
/// (["b1", "b2", "bs", "alpha0", "alpha2", "sn"], and "c1", "b_shot", "a_shot" with B0), priors
/// ({name: sigma}), b_k_max (the bispectrum monopole of the shells' triangle bins up to it, Gaussian
/// variance, no P-B cross-covariance), other nuisance values by name); `parameters` "template" (f, apar, aperp per bin) or "cosmology" (omega_cdm, omega_b, h,
/// logA, n_s shared, with `priors` {name: sigma} on them, e.g. {"omega_b": 0.00037}); the fiducial
/// `cosmology` (a preset or dict; default planck2018). Returns a dict: names, fiducial, sigma,
/// covariance, fisher, fsigma8 ([(sigma, fsigma8)] per bin), derivative_error, points.
#[pyfunction]
#[pyo3(signature = (bins, parameters="template", cosmology=None, priors=None, cache_dir=None))]
pub(crate) fn fisher<'py>(
    py: Python<'py>,
    bins: &Bound<'py, PyList>,
    parameters: &str,
    cosmology: Option<&Bound<'py, PyAny>>,
    priors: Option<std::collections::BTreeMap<String, f64>>,
    cache_dir: Option<std::path::PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let parameters = match parameters {
        "template" => Parameters::Template,
        "cosmology" => Parameters::Cosmology,
        other => {
            return Err(value_error(format!(
                "parameters = {other:?}: valid are \"template\", \"cosmology\""
            )))
        }
    };
    let bins: Vec<SurveyBin> = bins
        .iter()
        .enumerate()
        .map(|(i, b)| {
            bin_of(
                i,
                b.cast::<PyDict>().map_err(|_| {
                    value_error(format!("survey bin {}: a dict is expected", i + 1))
                })?,
            )
        })
        .collect::<PyResult<_>>()?;
    let fiducial = match cosmology {
        Some(c) => crate::inputs::cosmology_of(Some(c))?,
        None => pt_spectra::cosmology::Cosmology::planck2018(),
    };
    let priors: Vec<(String, f64)> = priors.unwrap_or_default().into_iter().collect();
    let store = crate::Store::new(cache_dir);
    let (f, _) = crate::detached(py, || {
        lib_fisher(&bins, &fiducial, parameters, &priors, store.get(), &Silent)
    })?;
    let d = PyDict::new(py);
    d.set_item("names", f.names)?;
    d.set_item("fiducial", f.fiducial)?;
    d.set_item("sigma", f.sigma)?;
    d.set_item("covariance", f.covariance)?;
    d.set_item("fisher", f.fisher)?;
    d.set_item("fsigma8", f.fsigma8)?;
    d.set_item("derivative_error", f.derivative_error)?;
    d.set_item("points", f.points)?;
    Ok(d)
}
