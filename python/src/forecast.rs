//! `pt_spectra.fisher`: Fisher forecasts of redshift surveys with the galaxy model
//! (`pt_spectra::forecast`).

use crate::value_error;
use pt_spectra::forecast::{fisher as lib_fisher, Parameters, SurveyBin};
use pt_spectra::progress::Silent;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// The keys of a bin dict that are not numbers (the numbers: `SurveyBin::keys` and the nuisance
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
    let d = result_dict(
        py,
        f.names,
        f.fiducial,
        [f.fisher, f.covariance],
        f.sigma,
        f.fsigma8,
    )?;
    d.set_item("derivative_error", f.derivative_error)?;
    d.set_item("points", f.points)?;
    Ok(d)
}

/// What every forecast returns: names, fiducial values, the Fisher matrix and its inverse, σ, and
/// (σ(fσ8), fσ8) per bin.
fn result_dict(
    py: Python<'_>,
    names: Vec<String>,
    fiducial: Vec<f64>,
    [fisher, covariance]: [Vec<Vec<f64>>; 2],
    sigma: Vec<f64>,
    fsigma8: Vec<(f64, f64)>,
) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("names", names)?;
    d.set_item("fiducial", fiducial)?;
    d.set_item("sigma", sigma)?;
    d.set_item("covariance", covariance)?;
    d.set_item("fisher", fisher)?;
    d.set_item("fsigma8", fsigma8)?;
    Ok(d)
}

/// The linear-Kaiser forecast of fσ8 with the spectrum's shape and the geometry fixed (White, Song &
/// Percival 2009; the DESI FDR's method; `pt_spectra::forecast::fisher_kaiser`): `bins` a list of
/// dicts (z, volume [(Mpc/h)^3], k_max [h/Mpc], k_min (0.001), and either n_bar [(h/Mpc)^3] and b1
/// for one tracer or tracers, a list of {n_bar, b1}, for several sharing the volume); the fiducial
/// `cosmology` (default planck2018). Returns a dict: names (f_i, b1_i or b1.t_i), fiducial, sigma,
/// covariance, fisher, fsigma8 ([(sigma, fsigma8)] per bin).
#[pyfunction]
#[pyo3(signature = (bins, cosmology=None))]
pub(crate) fn fisher_kaiser<'py>(
    py: Python<'py>,
    bins: &Bound<'py, PyList>,
    cosmology: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    use pt_spectra::forecast::{KaiserBin, KaiserTracer};
    let tracer = |what: &str, d: &Bound<'py, PyDict>| -> PyResult<KaiserTracer> {
        let get = |key: &str| -> PyResult<f64> {
            d.get_item(key)?
                .ok_or_else(|| value_error(format!("{what}: `{key}` is required")))?
                .extract()
        };
        Ok(KaiserTracer {
            n_bar: get("n_bar")?,
            b1: get("b1")?,
        })
    };
    let mut parsed = Vec::new();
    for (i, b) in bins.iter().enumerate() {
        let what = format!("Kaiser bin {}", i + 1);
        let d = b
            .cast::<PyDict>()
            .map_err(|_| value_error(format!("{what}: a dict is expected")))?;
        for (key, _) in d.iter() {
            let key: String = key.extract()?;
            if !["z", "volume", "k_min", "k_max", "n_bar", "b1", "tracers"].contains(&key.as_str())
            {
                return Err(value_error(format!(
                    "{what}: unknown key `{key}` (valid: z, volume, k_min, k_max, n_bar, b1, tracers)"
                )));
            }
        }
        let num = |key: &str| -> PyResult<Option<f64>> {
            d.get_item(key)?.map(|v| v.extract()).transpose()
        };
        let required = |key: &str| -> PyResult<f64> {
            num(key)?.ok_or_else(|| value_error(format!("{what}: `{key}` is required")))
        };
        let tracers = match d.get_item("tracers")? {
            Some(list) => list
                .cast::<PyList>()
                .map_err(|_| value_error(format!("{what}: `tracers` is a list of dicts")))?
                .iter()
                .enumerate()
                .map(|(t, x)| {
                    let w = format!("{what}, tracer {}", t + 1);
                    tracer(
                        &w,
                        x.cast::<PyDict>()
                            .map_err(|_| value_error(format!("{w}: a dict is expected")))?,
                    )
                })
                .collect::<PyResult<Vec<_>>>()?,
            None => vec![tracer(&what, d)?],
        };
        parsed.push(KaiserBin {
            z: required("z")?,
            volume: required("volume")?,
            k_min: num("k_min")?.unwrap_or(0.001),
            k_max: required("k_max")?,
            tracers,
        });
    }
    let fiducial = match cosmology {
        Some(c) => crate::inputs::cosmology_of(Some(c))?,
        None => pt_spectra::cosmology::Cosmology::planck2018(),
    };
    let (f, _) = crate::detached(py, || {
        pt_spectra::forecast::fisher_kaiser(&parsed, &fiducial)
    })?;
    result_dict(
        py,
        f.names,
        f.fiducial,
        [f.fisher, f.covariance],
        f.sigma,
        f.fsigma8,
    )
}
