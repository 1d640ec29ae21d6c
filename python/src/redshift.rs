//! Redshift space from Python: `RsdPlan` (loop terms planned once per k grid), `RsdTerms` (the
//! terms of one linear spectrum, for cheap multipoles at other f, bias, σ0, noise) and the argument
//! conversions they share with `fit`.

use crate::inputs::Inputs;
use crate::tables::Table;
use crate::{detached, floats, value_error, Store};
use pt_spectra::halo::{Bias, Noise};
use pt_spectra::jobs::{self, RsdRequest};
use pt_spectra::progress::Silent;
use pt_spectra::rsd::{Fog, RsdModel, RsdPlan as LibRsdPlan, Sigma0};
use pt_spectra::setup::Prepared;
use pt_spectra::table::Tabulated;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// A function of k from a path (k in column 1, the value in the column named `column` on a `# k …`
/// line, else column 2) or a pair of arrays.
fn tabulated(obj: &Bound<'_, PyAny>, name: &'static str, column: &str) -> PyResult<Tabulated> {
    if let Ok(path) = obj.extract::<PathBuf>() {
        return Tabulated::read_column(&path, name, column, true).map_err(value_error);
    }
    let (k, v): (Bound<'_, PyAny>, Bound<'_, PyAny>) = obj.extract().map_err(|_| {
        PyValueError::new_err(format!(
            "{name}: expected a path or a pair (k [h/Mpc], values)"
        ))
    })?;
    Tabulated::new(
        name,
        "array",
        crate::k_array(&k, &format!("{name} k"))?.into_vec(),
        floats(&v, name)?,
        true,
        &[],
    )
    .map_err(value_error)
}

/// The bias and noise of the keyword arguments.
pub(crate) fn bias_and_noise(
    bias: &Bound<'_, PyAny>,
    shot_noise: Option<f64>,
    number_density: Option<f64>,
    noise_table: Option<&Bound<'_, PyAny>>,
) -> PyResult<(Bias, Noise)> {
    let bias = match bias.extract::<f64>() {
        Ok(b) => Bias::Constant(b),
        Err(_) => Bias::Table(tabulated(bias, "b(k)", "b")?),
    };
    let noise = match (noise_table, shot_noise, number_density) {
        (Some(t), None, None) => Noise::Table(tabulated(t, "P_eps(k)", "P_eps")?),
        (None, Some(p), None) => Noise::Constant(p),
        (None, None, Some(n)) => Noise::poisson(n).map_err(value_error)?,
        (None, None, None) => Noise::None,
        _ => {
            return Err(PyValueError::new_err(
                "give at most one of shot_noise, number_density, noise_table",
            ))
        }
    };
    Ok((bias, noise))
}

/// σ0 as a number or `lin` / `1l-spt`.
pub(crate) fn sigma0(obj: &Bound<'_, PyAny>) -> PyResult<Sigma0> {
    match obj.extract::<f64>() {
        Ok(v) => Sigma0::value(v).map_err(value_error),
        Err(_) => obj.extract::<String>()?.parse().map_err(value_error),
    }
}

/// Redshift-space loop terms planned once for one k grid.
#[pyclass(module = "pt_spectra._core", frozen)]
pub(crate) struct RsdPlan {
    plan: LibRsdPlan,
    rsd: RsdModel,
    /// The bias terms' plan, built at the first call with nonlinear bias.
    bias_plan: std::sync::OnceLock<pt_spectra::loops::bias::BiasPlan>,
}

#[pymethods]
impl RsdPlan {
    /// What the plan computes, how a new spectrum's terms are computed (`method`: direct or basis)
    /// and its memory estimates in bytes (the plan, one spectrum's terms).
    #[getter]
    fn plan_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        crate::seam::plan_info(py, &self.plan)
    }

    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (k, real=pt_spectra::jobs::defaults::RSD_REAL_MODEL, rsd=pt_spectra::jobs::defaults::RSD_MODEL, precision=pt_spectra::jobs::defaults::PRECISION, q_range=None, cache_dir=None, two_loop=pt_spectra::jobs::defaults::TWO_LOOP))]
    fn new(
        py: Python<'_>,
        k: &Bound<'_, PyAny>,
        real: &str,
        rsd: &str,
        precision: &str,
        q_range: Option<(f64, f64)>,
        cache_dir: Option<PathBuf>,
        two_loop: &str,
    ) -> PyResult<Self> {
        let k = crate::k_array(k, "k")?;
        let real = real.parse().map_err(value_error)?;
        let rsd: RsdModel = rsd.parse().map_err(value_error)?;
        let precision = crate::precision(precision, q_range, None, Some(two_loop))?;
        let store = Store::new(cache_dir);
        let (plan, _) = detached(py, || {
            LibRsdPlan::new(&k, real, rsd, &precision, store.get(), &Silent)
        })?;
        Ok(Self {
            plan,
            rsd,
            bias_plan: std::sync::OnceLock::new(),
        })
    }

    /// The multipoles of the prepared spectrum: see the Python wrapper `pt_spectra.rsd`.
    #[pyo3(signature = (linear=None, z=0.0, z_input=0.0, cosmology=None, f=None, bias=None, amplitude=1.0,
        fog="none", sigma0=None, shot_noise=None, number_density=None, noise_table=None, ells=vec![0, 2, 4],
        terms=false, eh=None, growth_factor=None, no_wiggle=false, cs2=0.0, b2=None, bs=None, b3=None,
        bias_convention=None))]
    #[allow(clippy::too_many_arguments)]
    fn __call__(
        &self,
        py: Python<'_>,
        linear: Option<&Bound<'_, PyAny>>,
        z: f64,
        z_input: f64,
        cosmology: Option<&Bound<'_, PyAny>>,
        f: Option<f64>,
        bias: Option<&Bound<'_, PyAny>>,
        amplitude: f64,
        fog: &str,
        sigma0: Option<&Bound<'_, PyAny>>,
        shot_noise: Option<f64>,
        number_density: Option<f64>,
        noise_table: Option<&Bound<'_, PyAny>>,
        ells: Vec<usize>,
        terms: bool,
        eh: Option<&str>,
        growth_factor: Option<f64>,
        no_wiggle: bool,
        cs2: f64,
        b2: Option<f64>,
        bs: Option<f64>,
        b3: Option<f64>,
        bias_convention: Option<&str>,
    ) -> PyResult<Table> {
        let model = format!("rsd='{}'", self.rsd);
        let given = crate::bias::convention(py, bias_convention, bs, b3, Some(&model))?;
        let settings = (
            f,
            amplitude,
            fog,
            shot_noise,
            number_density,
            ells,
            terms,
            no_wiggle,
            cs2,
        );
        let mut request = rsd_request(py, self.rsd, bias, sigma0, noise_table, settings)?;
        if b2.is_some() || bs.is_some() || b3.is_some() {
            request.galaxy = Some(jobs::NonlinearBias::new(
                given,
                b2.unwrap_or(0.0),
                bs.unwrap_or(0.0),
                b3.unwrap_or(0.0),
            ));
        }
        request.validate_galaxy().map_err(value_error)?;
        let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
        let ((table, prepared), seconds) = detached(py, || {
            let prepared = with_growth(inputs.prepare(self.plan.real().k())?, growth_factor)?;
            let table = if request.galaxy.is_some() {
                let real = self.plan.real();
                if self.bias_plan.get().is_none() {
                    let plan = pt_spectra::loops::bias::BiasPlan::new(real.k(), real.precision())?;
                    let _ = self.bias_plan.set(plan);
                }
                let (spectra, tns) = self.plan.evaluate(prepared.tracer_spectrum(), &Silent)?;
                let terms = self
                    .bias_plan
                    .get()
                    .map(|p| p.evaluate(prepared.tracer_spectrum()));
                let precision = real.precision();
                jobs::rsd_table_with_bias_terms(
                    &spectra,
                    tns.as_ref(),
                    terms,
                    precision,
                    &request,
                    &prepared,
                )?
            } else {
                jobs::rsd_table(&self.plan, &request, &prepared, &Silent)?
            };
            Ok((table, prepared))
        })?;
        let model = format!("{} + {}", self.rsd, self.plan.real().model());
        let precision = self.plan.real().precision();
        Table::new(py, table, &prepared, precision, &model, seconds)
    }

    /// The loop terms of a linear spectrum, for many cheap multipole evaluations
    /// ([`RsdTerms::multipoles`]) at other f, bias, σ0 and noise.
    #[pyo3(signature = (linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None))]
    fn terms(
        &self,
        py: Python<'_>,
        linear: Option<&Bound<'_, PyAny>>,
        z: f64,
        z_input: f64,
        cosmology: Option<&Bound<'_, PyAny>>,
        eh: Option<&str>,
    ) -> PyResult<RsdTerms> {
        let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
        let ((spectra, tns, prepared), _) = detached(py, || {
            let prepared = inputs.prepare(self.plan.real().k())?;
            let (spectra, tns) = self.plan.evaluate(prepared.tracer_spectrum(), &Silent)?;
            Ok((spectra, tns, prepared))
        })?;
        Ok(RsdTerms {
            spectra,
            tns,
            prepared,
            precision: self.plan.real().precision().clone(),
            rsd: self.rsd,
            dispersions: pt_spectra::rsd::Dispersions::default(),
        })
    }
}

/// (f, A_b, FoG, shot noise, number density, ells, parts, no-wiggle multipoles, c_s²) of an RSD call.
type RsdSettingsArgs<'a> = (
    Option<f64>,
    f64,
    &'a str,
    Option<f64>,
    Option<f64>,
    Vec<usize>,
    bool,
    bool,
    f64,
);

/// The redshift-space request of the keyword arguments.
fn rsd_request(
    py: Python<'_>,
    rsd: RsdModel,
    bias: Option<&Bound<'_, PyAny>>,
    sigma0: Option<&Bound<'_, PyAny>>,
    noise_table: Option<&Bound<'_, PyAny>>,
    (f, amplitude, fog, shot_noise, number_density, ells, terms, no_wiggle, cs2): RsdSettingsArgs<
        '_,
    >,
) -> PyResult<RsdRequest> {
    let one = 1.0f64.into_pyobject(py)?.into_any();
    let zero = 0.0f64.into_pyobject(py)?.into_any();
    let (bias, noise) = bias_and_noise(
        bias.unwrap_or(&one),
        shot_noise,
        number_density,
        noise_table,
    )?;
    Ok(RsdRequest {
        rsd,
        f,
        bias,
        amplitude,
        fog: fog.parse::<Fog>().map_err(value_error)?,
        sigma0: self::sigma0(sigma0.unwrap_or(&zero))?,
        noise,
        ells,
        terms,
        no_wiggle,
        cs2,
        galaxy: None,
        ap: None,
    })
}

/// `prepared` with its growth factor D(z) replaced, if given ([`Prepared::with_growth_factor`]).
fn with_growth(
    prepared: Prepared,
    growth_factor: Option<f64>,
) -> pt_spectra::error::Result<Prepared> {
    match growth_factor {
        Some(d) => prepared.with_growth_factor(d),
        None => Ok(prepared),
    }
}

/// The loop terms of one linear spectrum on an [`RsdPlan`]'s grid; [`multipoles`](Self::multipoles)
/// then costs microseconds per call (the fast nuisance parameters of a chain).
#[pyclass(module = "pt_spectra._core", frozen)]
pub(crate) struct RsdTerms {
    spectra: pt_spectra::real::RealSpectra,
    tns: Option<pt_spectra::loops::TnsTerms>,
    prepared: Prepared,
    precision: pt_spectra::precision::Precision,
    rsd: RsdModel,
    /// The theory σ0 of this spectrum, computed at the first call that asks for it.
    dispersions: pt_spectra::rsd::Dispersions,
}

#[pymethods]
impl RsdTerms {
    /// The multipoles at f, bias, A_b, FoG, σ0 and noise: see the Python wrapper.
    #[pyo3(signature = (f=None, bias=None, amplitude=1.0, fog="none", sigma0=None, shot_noise=None,
        number_density=None, noise_table=None, ells=vec![0, 2, 4], terms=false, growth_factor=None,
        no_wiggle=false, cs2=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn multipoles(
        &self,
        py: Python<'_>,
        f: Option<f64>,
        bias: Option<&Bound<'_, PyAny>>,
        amplitude: f64,
        fog: &str,
        sigma0: Option<&Bound<'_, PyAny>>,
        shot_noise: Option<f64>,
        number_density: Option<f64>,
        noise_table: Option<&Bound<'_, PyAny>>,
        ells: Vec<usize>,
        terms: bool,
        growth_factor: Option<f64>,
        no_wiggle: bool,
        cs2: f64,
    ) -> PyResult<Table> {
        let settings = (
            f,
            amplitude,
            fog,
            shot_noise,
            number_density,
            ells,
            terms,
            no_wiggle,
            cs2,
        );
        let request = rsd_request(py, self.rsd, bias, sigma0, noise_table, settings)?;
        let ((table, prepared), seconds) = detached(py, || {
            let prepared = with_growth(self.prepared.clone(), growth_factor)?;
            let table = jobs::rsd_table_from_terms_memo(
                &self.spectra,
                self.tns.as_ref(),
                &self.precision,
                &request,
                &prepared,
                &self.dispersions,
            )?;
            Ok((table, prepared))
        })?;
        let model = format!("{} + {}", self.rsd, self.spectra.model);
        Table::new(py, table, &prepared, &self.precision, &model, seconds)
    }
}
