//! The galaxy model `ept` from Python: `EptPlan` (loop plan once per k grid) and `EptTerms` (the loop
//! terms of one linear spectrum, for cheap multipoles at other parameters: the nuisance steps of a
//! chain). Parameters by velocileptors' names as keyword arguments.

use crate::inputs::Inputs;
use crate::tables::Table;
use crate::{detached, floats, value_error};
use pt_spectra::bias::{BiasConvention, BiasParams};
use pt_spectra::jobs::ObservationSpec;
use pt_spectra::jobs::{self, EptRequest};
use pt_spectra::progress::Silent;
use pt_spectra::rsd::ap::{ApSpec, Distortion};
use pt_spectra::rsd::ept::{EptParams, EptPlan as LibEptPlan, EptTerms as LibEptTerms};
use pt_spectra::setup::Prepared;
use pt_spectra::survey::observe::Bins;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;

/// The distortion of `apar`, `aperp` (both or neither: [`ApSpec::from_options`]).
fn distortion(apar: Option<f64>, aperp: Option<f64>) -> PyResult<Option<Distortion>> {
    match ApSpec::from_options(apar, aperp, None).map_err(value_error)? {
        ApSpec::Scalings(d) => Ok(Some(d)),
        _ => Ok(None),
    }
}

/// The parameters of `kwargs` (velocileptors' names; f may be absent: f(z) of the cosmology).
fn params(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<EptParams> {
    Ok(params_given(kwargs)?.0)
}

/// The model's parameters of `kwargs` and the bias convention they were given in: with
/// `bias_convention=` the bias is named as that convention names it (classpt: b1, b2, bG2, bGamma3;
/// fastpt: b1, b2, bs, b3nl) and mapped to velocileptors' ([`pt_spectra::bias`]).
fn params_given(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<(EptParams, BiasConvention)> {
    let mut p = EptParams::new(1.0, f64::NAN);
    let numbers = match kwargs {
        Some(kw) if kw.contains("bias_convention")? => {
            let kw = kw.copy()?;
            let name: String = kw
                .get_item("bias_convention")?
                .map(|v| v.extract())
                .transpose()
                .map_err(|_| PyValueError::new_err("bias_convention: expected a name"))?
                .unwrap_or_default();
            kw.del_item("bias_convention")?;
            let convention: BiasConvention = name.parse().map_err(value_error)?;
            let names = convention.names();
            let mut bias = [1.0, 0.0, 0.0, 0.0];
            let mut rest = Vec::new();
            for (key, v) in crate::number_kwargs(Some(&kw))? {
                match names.iter().position(|n| *n == key) {
                    Some(i) => bias[i] = v,
                    None if ["b2", "bs", "b3"].contains(&key.as_str()) => {
                        return Err(PyValueError::new_err(format!(
                            "{key} is not a bias parameter of bias_convention='{convention}': its names are {}",
                            names.join(", ")
                        )))
                    }
                    None => rest.push((key, v)),
                }
            }
            let b = BiasParams::from_convention(convention, bias);
            p.set_bias(&b);
            for (key, v) in rest {
                p.set(&key, v).map_err(value_error)?;
            }
            return Ok((p, convention));
        }
        _ => crate::number_kwargs(kwargs)?,
    };
    for (name, v) in numbers {
        p.set(&name, v).map_err(value_error)?;
    }
    Ok((p, BiasConvention::Velocileptors))
}

/// The 1-loop galaxy model in redshift space planned for one k grid.
#[pyclass(module = "pt_spectra._core", frozen)]
pub(crate) struct EptPlan {
    plan: Arc<LibEptPlan>,
    precision: pt_spectra::precision::Precision,
}

#[pymethods]
impl EptPlan {
    /// What the plan computes, how a new spectrum's terms are computed (`method`: direct or basis)
    /// and its memory estimates in bytes (the plan, one spectrum's terms).
    #[getter]
    fn plan_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        crate::seam::plan_info(py, &*self.plan)
    }

    #[new]
    #[pyo3(signature = (k, ir=true, apar=None, aperp=None, precision=pt_spectra::jobs::defaults::PRECISION, q_range=None, free_ap=false, two_loop=pt_spectra::jobs::defaults::TWO_LOOP, cache_dir=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        k: &Bound<'_, PyAny>,
        ir: bool,
        apar: Option<f64>,
        aperp: Option<f64>,
        precision: &str,
        q_range: Option<(f64, f64)>,
        free_ap: bool,
        two_loop: &str,
        cache_dir: Option<std::path::PathBuf>,
    ) -> PyResult<Self> {
        let k = crate::k_array(k, "k")?;
        let ap = distortion(apar, aperp)?;
        let precision = crate::precision(precision, q_range, None, Some(two_loop))?;
        let store = crate::Store::new(cache_dir);
        let (plan, _) = detached(py, || {
            jobs::ept_plan(&k, ir, ap, free_ap, &precision, store.get(), &Silent)
        })?;
        Ok(Self {
            plan: Arc::new(plan),
            precision,
        })
    }

    /// The multipoles of the prepared spectrum at the parameters of `kwargs`.
    #[pyo3(signature = (linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None, ells=vec![0, 2, 4], **kwargs))]
    #[allow(clippy::too_many_arguments)]
    fn __call__(
        &self,
        py: Python<'_>,
        linear: Option<&Bound<'_, PyAny>>,
        z: f64,
        z_input: f64,
        cosmology: Option<&Bound<'_, PyAny>>,
        eh: Option<&str>,
        ells: Vec<usize>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Table> {
        let (params, bias_given) = params_given(kwargs)?;
        let request = EptRequest {
            params,
            ells,
            ap: None,
            bias_given,
        };
        let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
        let ((table, prepared), seconds) = detached(py, || {
            let prepared = inputs.prepare(self.plan.k())?;
            let table = jobs::ept_table(&self.plan, &request, &prepared, &self.precision)?;
            Ok((table, prepared))
        })?;
        Table::new(py, table, &prepared, &self.precision, "ept", seconds)
    }

    /// The loop terms of a linear spectrum, for many cheap evaluations ([`EptTerms::multipoles`]).
    #[pyo3(signature = (linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None))]
    fn terms(
        &self,
        py: Python<'_>,
        linear: Option<&Bound<'_, PyAny>>,
        z: f64,
        z_input: f64,
        cosmology: Option<&Bound<'_, PyAny>>,
        eh: Option<&str>,
    ) -> PyResult<EptTerms> {
        let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
        let ((terms, prepared), _) = detached(py, || {
            let prepared = inputs.prepare(self.plan.k())?;
            let terms = self.plan.terms(prepared.tracer_spectrum())?;
            Ok((terms, prepared))
        })?;
        Ok(EptTerms {
            plan: Arc::clone(&self.plan),
            terms,
            prepared,
            precision: self.precision.clone(),
        })
    }
}

/// The loop terms of one linear spectrum on an [`EptPlan`]'s grid.
#[pyclass(module = "pt_spectra._core", frozen)]
pub(crate) struct EptTerms {
    plan: Arc<LibEptPlan>,
    terms: LibEptTerms,
    prepared: Prepared,
    precision: pt_spectra::precision::Precision,
}

#[pymethods]
impl EptTerms {
    /// The multipoles at the parameters of `kwargs` (velocileptors' names; f default f(z)).
    #[pyo3(signature = (ells=vec![0, 2, 4], apar=None, aperp=None, **kwargs))]
    fn multipoles(
        &self,
        py: Python<'_>,
        ells: Vec<usize>,
        apar: Option<f64>,
        aperp: Option<f64>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Table> {
        let (params, bias_given) = params_given(kwargs)?;
        let request = EptRequest {
            params,
            ells,
            ap: distortion(apar, aperp)?,
            bias_given,
        };
        let (table, seconds) = detached(py, || {
            jobs::ept_table_from_terms(
                &self.plan,
                &self.terms,
                &request,
                &self.prepared,
                &self.precision,
            )
        })?;
        Table::new(py, table, &self.prepared, &self.precision, "ept", seconds)
    }
}

/// `pt-spectra fit --rsd ept` as a function: see the Python wrapper `pt_spectra.fit_ept`.
#[pyfunction]
#[pyo3(signature = (data, k_max, free=vec!["f".to_string(), "b1".to_string()], marginalise=vec![],
    priors=None, ells=vec![0, 2], data_ells=vec![0, 2, 4], data_columns=None, covariance=None, k_min=0.0,
    ir=true, apar=None, aperp=None, linear=None, z=0.0, z_input=0.0, cosmology=None, precision=pt_spectra::jobs::defaults::PRECISION,
    q_range=None, eh=None, n_mocks=None, k_ranges=None, window=None, window_mixing="wilson",
    k_edges=None, r#box=None, xi=false, s_edges=None, window_format=None, starts=pt_spectra::fit::galaxy::search::DEFAULT_STARTS,
    seed=1, profile_check=true, profile_linear=false, profile=None, profile_points=21, profile_span=3.0,
    model_out=false, basis="velocileptors", n_bar=None, satellites=None, desi_priors=false, **kwargs))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit_ept(
    py: Python<'_>,
    data: &Bound<'_, PyAny>,
    k_max: Vec<f64>,
    free: Vec<String>,
    marginalise: Vec<String>,
    priors: Option<&Bound<'_, PyDict>>,
    ells: Vec<usize>,
    data_ells: Vec<usize>,
    data_columns: Option<Vec<usize>>,
    covariance: Option<&Bound<'_, PyAny>>,
    k_min: f64,
    ir: bool,
    apar: Option<f64>,
    aperp: Option<f64>,
    linear: Option<&Bound<'_, PyAny>>,
    z: f64,
    z_input: f64,
    cosmology: Option<&Bound<'_, PyAny>>,
    precision: &str,
    q_range: Option<(f64, f64)>,
    eh: Option<&str>,
    n_mocks: Option<usize>,
    k_ranges: Option<std::collections::HashMap<usize, (f64, f64)>>,
    window: Option<std::path::PathBuf>,
    window_mixing: &str,
    k_edges: Option<&Bound<'_, PyAny>>,
    r#box: Option<f64>,
    xi: bool,
    s_edges: Option<&Bound<'_, PyAny>>,
    window_format: Option<&str>,
    starts: usize,
    seed: u64,
    profile_check: bool,
    profile_linear: bool,
    profile: Option<String>,
    profile_points: usize,
    profile_span: f64,
    model_out: bool,
    basis: &str,
    n_bar: Option<f64>,
    satellites: Option<(f64, f64)>,
    desi_priors: bool,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<(Table, Option<Table>)> {
    let (mut data, name, layout) = crate::data(data, data_columns, &data_ells, &ells)?;
    if let Some(c) = covariance {
        // A path (as the command line's --covariance), or a 2-D array.
        data = match c.extract::<std::path::PathBuf>() {
            Ok(path) if !c.hasattr("shape")? => layout
                .read_covariance(data, &path)
                .map_err(|e| value_error(format!("covariance: {e}")))?,
            _ => layout
                .attach_covariance(data, crate::covariance_rows(c)?)
                .map_err(value_error)?,
        };
    }
    if starts == 0 {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "starts = 0: the fit needs at least one start",
        ));
    }
    let search = pt_spectra::fit::galaxy::Search {
        starts,
        seed,
        profile_check,
        linear: if profile_linear {
            pt_spectra::fit::galaxy::Linear::Profiled
        } else {
            pt_spectra::fit::galaxy::Linear::Marginalised
        },
    };
    let mut prior_list = Vec::new();
    if let Some(p) = priors {
        for (key, value) in p.iter() {
            let name: String = key.extract()?;
            // (mean, sigma): Gaussian; ("flat", lo, hi) or ("lognormal", mu, sigma); or the
            // command line's text after the colon, e.g. "flat,0,2".
            let text = if let Ok((mean, sigma)) = value.extract::<(f64, f64)>() {
                format!("{name}:{mean},{sigma}")
            } else if let Ok((kind, a, b)) = value.extract::<(String, f64, f64)>() {
                format!("{name}:{kind},{a},{b}")
            } else if let Ok(t) = value.extract::<String>() {
                format!("{name}:{t}")
            } else {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "priors[{name}]: expected (mean, sigma), (\"flat\", lo, hi), \
                     (\"lognormal\", mu, sigma) or a text such as \"flat,0,2\""
                )));
            };
            prior_list
                .push(pt_spectra::fit::galaxy::Prior::parse(&text).map_err(|e| {
                    pyo3::exceptions::PyValueError::new_err(format!("priors: {e}"))
                })?);
        }
    }
    let mut start = params(kwargs)?;
    let ap = distortion(apar, aperp)?;
    let mut ell_ranges: Vec<(usize, f64, f64)> = k_ranges
        .unwrap_or_default()
        .into_iter()
        .map(|(l, (a, b))| (l, a, b))
        .collect();
    ell_ranges.sort_by_key(|r| r.0);
    if xi && (window.is_some() || k_edges.is_some() || r#box.is_some()) {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "xi=True takes s_edges, not window, k_edges or box (a Landy-Szalay xi has the window divided out)",
        ));
    }
    let s_edges = s_edges.map(|e| floats(e, "s_edges")).transpose()?;
    if window.is_none() && window_format.is_some() {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "window_format needs a window",
        ));
    }
    let window = window
        .map(|path| crate::survey::read_window(&path, window_mixing, window_format))
        .transpose()?;
    let bins =
        Bins::of(k_edges.map(|e| floats(e, "k_edges")).transpose()?, r#box).map_err(value_error)?;
    let spec = ObservationSpec {
        window,
        bins,
        xi,
        s_edges,
        ap: ap.map_or(ApSpec::None, ApSpec::Scalings),
    };
    let observation = spec.build(&ells, &data.k).map_err(value_error)?;
    let model_k = observation
        .as_ref()
        .map_or(data.k.clone(), |o| o.k_model().to_vec());
    let precision = crate::precision(precision, q_range, None, None)?;
    let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
    let ((table, model, prepared), seconds) = detached(py, || {
        let prepared = inputs.prepare(&model_k)?;
        if start.f().is_nan() {
            start.set_f(prepared.growth_rate);
        }
        let free_ap = ApSpec::check_free(ap.as_ref(), &free)?;
        let basis = jobs::fit_basis(
            basis,
            prepared.spectrum.sigma8(),
            n_bar,
            satellites,
            desi_priors,
        )?;
        if desi_priors {
            jobs::add_desi_priors(&mut prior_list, &free, &marginalise);
        }
        let request = pt_spectra::fit::galaxy::GalaxyFitRequest {
            start,
            ap,
            free,
            marginalise,
            priors: prior_list,
            ells,
            k_min,
            k_max: 0.0,
            ell_ranges,
            n_mocks,
            basis,
        };
        let store = crate::Store::new(None);
        let plan = jobs::ept_plan(&model_k, ir, ap, free_ap, &precision, store.get(), &Silent)?;
        let terms = plan.terms(prepared.tracer_spectrum())?;
        let header = vec![format!(
            "pt-spectra {} fit: ept ({}) to {name}",
            jobs::VERSION,
            if ir {
                "IR resummed"
            } else {
                "no IR resummation"
            }
        )];
        let context = jobs::FitContext {
            observation: observation.as_ref(),
            search,
            template: Some(pt_spectra::fit::galaxy::Template {
                sigma8_z: prepared.spectrum.sigma8(),
                z: prepared.z,
                cosmology: Some(prepared.cosmology.cosmology),
            }),
            header,
        };
        if let Some(name) = &profile {
            let [k] = k_max[..] else {
                return Err(pt_spectra::error::Error::InvalidChoice {
                    what: format!("the profile of {name}"),
                    reason: format!("needs one k_max, not {}", k_max.len()),
                });
            };
            let mut r = request.clone();
            r.k_max = k;
            let grid = pt_spectra::fit::galaxy::ProfileGrid {
                points: profile_points,
                span: profile_span,
            };
            let table = jobs::ept_profile_table(&plan, &terms, &data, &r, &context, name, &grid)?;
            return Ok((table, None, prepared));
        }
        let (table, fits) = jobs::ept_fit_table(&plan, &terms, &data, &request, &k_max, &context)?;
        let model = if model_out {
            Some(jobs::ept_model_table(
                &plan, &terms, &data, &request, &fits, &k_max, &context,
            )?)
        } else {
            None
        };
        Ok((table, model, prepared))
    })?;
    let what = if profile.is_some() {
        "ept profile"
    } else {
        "ept fit"
    };
    let model = model
        .map(|m| Table::new(py, m, &prepared, &precision, "ept fit model", seconds))
        .transpose()?;
    Ok((
        Table::new(py, table, &prepared, &precision, what, seconds)?,
        model,
    ))
}

/// The model's parameters (velocileptors' names) of values in the DESI DR1 physical basis
/// (`rsd::ept::physical`): `physical` a dict of b1p, b2p, bsp, b3p, alpha0p, alpha2p, alpha4p, sn0p,
/// sn2p, sn4p and f (missing ones 0; f required), at σ8(z) `sigma8`, number density `n_bar`
/// [(h/Mpc)^3] and satellites (f_sat, σ_v [Mpc/h]).
#[pyfunction]
#[pyo3(signature = (physical, sigma8, n_bar, satellites=None))]
pub(crate) fn from_desi_physical(
    physical: &Bound<'_, PyDict>,
    sigma8: f64,
    n_bar: f64,
    satellites: Option<(f64, f64)>,
) -> PyResult<std::collections::HashMap<String, f64>> {
    use pt_spectra::rsd::ept::physical::{
        check_physical_name, PhysicalBasis, DEFAULT_F_SAT, DEFAULT_SIGMA_V, PHYSICAL_NAMES,
    };
    let (f_sat, sigma_v) = satellites.unwrap_or((DEFAULT_F_SAT, DEFAULT_SIGMA_V));
    let basis = PhysicalBasis::new(sigma8, n_bar, f_sat, sigma_v).map_err(value_error)?;
    let mut v = [0.0; 12];
    let mut has_f = false;
    for (key, value) in physical.iter() {
        let name: String = key.extract()?;
        check_physical_name(&name).map_err(value_error)?;
        let i = PHYSICAL_NAMES
            .iter()
            .position(|&n| n == name)
            .ok_or_else(|| {
                value_error(format!(
                    "`{name}` is not a parameter of the physical basis: {}",
                    PHYSICAL_NAMES.join(", ")
                ))
            })?;
        v[i] = value.extract()?;
        has_f |= name == "f";
    }
    if !has_f {
        return Err(value_error(
            "the physical basis's counterterms need f (the growth rate)",
        ));
    }
    let p = basis.to_ept(&v);
    Ok(pt_spectra::rsd::ept::PARAM_NAMES
        .iter()
        .zip(p.values)
        .map(|(n, v)| (n.to_string(), v))
        .collect())
}
