//! `pt_spectra.Pipeline`: the chain step planned once (`pt_spectra::pipeline`), called with
//! cosmological parameters (through the emulator) or a linear spectrum and nuisance parameters by
//! name, returning the data vector as a numpy array.

use crate::inputs::Inputs;
use crate::survey::Observation;
use crate::value_error;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pt_spectra::cosmology::Cosmology;
use pt_spectra::pipeline::{
    CosmologyJacobian, Pipeline as LibPipeline, PipelineSettings, TermsSource, JACOBIAN_NAMES,
    PIPELINE_MAX_RESIDUAL,
};
use pt_spectra::progress::Silent;
use pt_spectra::setup::{LinearSource, NamedCosmology, Prepared};
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Mutex;

/// What a call did: the loop terms' source, f and the distortion (q∥, q⊥) if any.
type LastCall = (TermsSource, f64, Option<(f64, f64)>);
/// A data vector and, if asked for, its Jacobian (one row per nuisance parameter).
type VectorAndJacobian = (Vec<f64>, Option<Vec<Vec<f64>>>);

/// The chain step: observation, model, redshift and AP fiducial fixed at construction. The other
/// keywords are the blocks after the power spectrum ([`pt_spectra::blocks::AVAILABLE`]): a block's
/// name with a dict of its options, or its own keywords ([`pt_spectra::statistic::Faces::keywords`];
/// e.g. the bispectrum's `triangles`, an (n, 3) array of k1 k2 k3 [h/Mpc], with `bin_width`, `b_ells`,
/// `n_bar`, `fog`, `sigma_fog`); the data vector goes on with each block's entries, from the same
/// spectrum, f, distortion and IR, sharing b1, b2, bs and adding the block's own parameters.
/// `restrict_loops` (default True): the loop terms only where the observation weighs them, the range
/// chosen by measurement at construction (`meta["loop_range"]`: the range and the change it made,
/// at most 1e-5 of each multipole's largest value); False computes them on the whole window grid.
#[pyclass(module = "pt_spectra._core", frozen)]
pub(crate) struct Pipeline {
    inner: LibPipeline,
    /// What the last call did (the loop terms' source, f, the distortion).
    last: Mutex<Option<LastCall>>,
    /// The last cosmology given without a table, its prepared spectrum and, once a second call asks
    /// for it, its nuisance polynomial: a call with the same cosmology (and f) evaluates the
    /// polynomial (microseconds) instead of the step.
    repeat: Mutex<Option<Repeat>>,
}

/// The key of [`Pipeline::repeat`]: the cosmology and the bits of a given f.
type RepeatKey = (pt_spectra::cosmology::Cosmology, Option<u64>);

/// The cache of [`Pipeline::repeat`]: its key, the prepared spectrum, the polynomial.
type Repeat = (
    RepeatKey,
    Prepared,
    Option<pt_spectra::pipeline::Linearised>,
);

/// The nuisance parameters of `kwargs` as (name, value) pairs.
fn pairs(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<(String, f64)>> {
    let mut out = Vec::new();
    if let Some(kw) = kwargs {
        for (k, v) in kw.iter() {
            out.push((k.extract::<String>()?, v.extract::<f64>()?));
        }
    }
    Ok(out)
}

impl Pipeline {
    /// The prepared spectrum: `linear` (arrays or a file) with the growth of `cosmology`, else the
    /// cosmology's spectrum through the pipeline's emulator (gm2012: its embedded CAMB table).
    fn prepared(
        &self,
        linear: Option<&Bound<'_, PyAny>>,
        z_input: Option<f64>,
        cosmology: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Prepared> {
        let z = self.inner.settings().z;
        let inputs = Inputs::extract(linear, z, z_input.unwrap_or(z), cosmology, None)?;
        if linear.is_some() {
            return inputs
                .prepare(self.inner.observation().k_model())
                .map_err(value_error);
        }
        let (named, _) = inputs.cosmology().map_err(value_error)?;
        self.prepared_named(named)
    }

    /// The cosmological derivatives along `derivatives` (names; `None`: all) at `cosmology` (a preset,
    /// ini path or dict) and `params`, with the nuisance rows of the same step if `nuisance`
    /// (`cosmology_jacobian`, `full_jacobian`).
    fn jacobians(
        &self,
        py: Python<'_>,
        cosmology: &Bound<'_, PyAny>,
        derivatives: Option<Vec<String>>,
        params: Option<&Bound<'_, PyDict>>,
        nuisance: bool,
    ) -> PyResult<(CosmologyJacobian, Option<Vec<Vec<f64>>>)> {
        let params = pairs(params)?;
        let z = self.inner.settings().z;
        let inputs = Inputs::extract(None, z, z, Some(cosmology), None)?;
        let (named, _) = inputs.cosmology().map_err(value_error)?;
        let c = named.map_or_else(Cosmology::gm2012, |n| n.cosmology);
        let named: Vec<(&str, f64)> = params.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        let derivatives: Vec<&str> = match &derivatives {
            Some(d) => d.iter().map(String::as_str).collect(),
            None => pt_spectra::cosmology::background::DERIVATIVE_NAMES.to_vec(),
        };
        let (result, _) = crate::detached(py, || {
            if nuisance {
                let (c, n) = self.inner.full_jacobian_of(&c, &named, &derivatives)?;
                Ok((c, Some(n)))
            } else {
                Ok((
                    self.inner.cosmology_jacobian_of(&c, &named, &derivatives)?,
                    None,
                ))
            }
        })?;
        Ok(result)
    }

    /// The emulated spectrum of a cosmology already parsed (`None`: the default).
    fn prepared_named(&self, named: Option<NamedCosmology>) -> PyResult<Prepared> {
        self.inner
            .prepare_source(LinearSource::Embedded, named)
            .map_err(value_error)
    }

    /// The data vector (and with `jacobian` d/d of each nuisance parameter) of one parameter set.
    fn one(
        &self,
        py: Python<'_>,
        prepared: &Prepared,
        params: &[(String, f64)],
        jacobian: bool,
    ) -> PyResult<VectorAndJacobian> {
        // with a block after the power spectrum a given f makes the step at that f (a block's terms
        // are not a polynomial in f, e.g. the IR damping)
        let f_given = params.iter().find(|(n, _)| n == "f").map(|p| p.1);
        let step = match f_given {
            Some(f) if self.inner.has_blocks() => self.inner.step_at_growth_rate(prepared, f),
            _ => self.inner.step(prepared),
        }
        .map_err(value_error)?;
        if let TermsSource::DirectFallback { .. } = step.source {
            let text = step.source.describe(self.inner.settings().max_residual);
            PyErr::warn(
                py,
                &py.get_type::<PyUserWarning>(),
                &std::ffi::CString::new(text)?,
                1,
            )?;
        }
        *self.last.lock().expect("not poisoned") = Some((
            step.source,
            step.growth_rate,
            step.ap.map(|d| (d.apar, d.aperp)),
        ));
        let named: Vec<(&str, f64)> = params.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        if jacobian {
            // the data vector from the nuisance polynomial too (the same numbers to rounding)
            let (values, rows) = step.jacobian(&named).map_err(value_error)?;
            return Ok((values, Some(rows)));
        }
        Ok((step.data_vector(&named).map_err(value_error)?, None))
    }

    /// The cache key of a call: (cosmology, f given) when it names a cosmology without a table and
    /// the pipeline has no block after the power spectrum (whose f is not a polynomial), else `None`.
    fn repeat_key(
        &self,
        linear: Option<&Bound<'_, PyAny>>,
        z_input: Option<f64>,
        cosmology: Option<&Bound<'_, PyAny>>,
        params: &[(String, f64)],
    ) -> PyResult<Option<(RepeatKey, Option<NamedCosmology>)>> {
        if linear.is_some() || z_input.is_some() || self.inner.has_blocks() {
            return Ok(None);
        }
        let z = self.inner.settings().z;
        let inputs = Inputs::extract(None, z, z, cosmology, None)?;
        let (named, _) = inputs.cosmology().map_err(value_error)?;
        let c = named
            .as_ref()
            .map_or_else(Cosmology::gm2012, |n| n.cosmology);
        let f = params.iter().find(|(n, _)| n == "f").map(|p| p.1.to_bits());
        Ok(Some(((c, f), named)))
    }

    /// The data vector (and Jacobian) of a call repeating the last cosmology, from its nuisance
    /// polynomial (made on the first repeat: the same numbers to rounding, ~1e-13); `None` otherwise.
    fn repeated(
        &self,
        key: Option<&RepeatKey>,
        params: &[(String, f64)],
        jacobian: bool,
    ) -> PyResult<Option<VectorAndJacobian>> {
        let Some(key) = key else {
            return Ok(None);
        };
        let mut cache = self.repeat.lock().expect("not poisoned");
        let Some((cached, prepared, lin)) = cache.as_mut() else {
            return Ok(None);
        };
        if cached != key {
            return Ok(None);
        }
        if lin
            .as_ref()
            .is_none_or(|l| jacobian && l.names().len() < JACOBIAN_NAMES.len())
        {
            // the power spectrum's terms do not depend on f (no block after them here): the step of
            // the cosmology, linearised at the given f (with the f-derivative for a Jacobian)
            let step = self.inner.step(prepared).map_err(value_error)?;
            let f = key.1.map(f64::from_bits);
            *lin = Some(
                if jacobian {
                    step.linearise_with_df(f)
                } else {
                    step.linearise(f)
                }
                .map_err(value_error)?,
            );
        }
        let lin = lin.as_ref().expect("made above");
        let named: Vec<(&str, f64)> = params.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        let values = lin.data_vector(&named).map_err(value_error)?;
        let jac = if jacobian {
            Some(lin.jacobian(&named).map_err(value_error)?)
        } else {
            None
        };
        Ok(Some((values, jac)))
    }
}

#[pymethods]
impl Pipeline {
    #[new]
    #[pyo3(signature = (observation, z, fiducial=None, ir=true, precision=pt_spectra::jobs::defaults::PRECISION,
        max_residual=PIPELINE_MAX_RESIDUAL, cache_dir=None, restrict_loops=true, **blocks))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        observation: &Bound<'_, Observation>,
        z: f64,
        fiducial: Option<&Bound<'_, PyAny>>,
        ir: bool,
        precision: &str,
        max_residual: f64,
        cache_dir: Option<std::path::PathBuf>,
        restrict_loops: bool,
        blocks: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let blocks = crate::options::pipeline_blocks(blocks)?;
        let fiducial = match fiducial {
            Some(f) => Some(crate::inputs::cosmology_of(Some(f))?),
            None => None,
        };
        let precision = crate::precision(precision, None, None, Some("basis"))?;
        let observation = observation.get().inner.clone();
        let store = crate::Store::new(cache_dir);
        let settings = PipelineSettings {
            ir,
            max_residual,
            blocks,
            restrict_loops,
            ..PipelineSettings::ept(z, fiducial)
        };
        let (inner, _) = crate::detached(py, || {
            LibPipeline::new(observation, settings, &precision, store.get(), &Silent)
        })?;
        Ok(Self {
            inner,
            last: Mutex::new(None),
            repeat: Mutex::new(None),
        })
    }

    /// The data vector (output ℓ's, then k) at `cosmology` (a preset, an ini file or a dict of
    /// CLASS/CAMB names; through the emulator) or at the spectrum `linear` ((k, P) arrays or a file
    /// at `z_input`, the growth and distances of `cosmology`), with the nuisance parameters by
    /// name (`pt_spectra.Pipeline.parameters`; `f` defaults to f(z)). With `jacobian=True`:
    /// (data vector, d data/d θ as an array of shape (12, n) in the order of `nuisance`: the 11
    /// nuisance parameters, then f; all exact). A call that repeats the last call's cosmology (no
    /// `linear`, no block after the power spectrum) evaluates that cosmology's nuisance polynomial (made at the
    /// first repeat, ~1.5 ms; then microseconds): the same numbers to rounding (~1e-13 relative).
    #[pyo3(signature = (cosmology=None, linear=None, z_input=None, jacobian=false, **params))]
    fn __call__<'py>(
        &self,
        py: Python<'py>,
        cosmology: Option<&Bound<'py, PyAny>>,
        linear: Option<&Bound<'py, PyAny>>,
        z_input: Option<f64>,
        jacobian: bool,
        params: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let params = pairs(params)?;
        // the cosmology parsed once: the key of a repeated call and, if new, what is emulated
        let (key, named) = match self.repeat_key(linear, z_input, cosmology, &params)? {
            Some((key, named)) => (Some(key), Some(named)),
            None => (None, None),
        };
        let (values, jac) = match self.repeated(key.as_ref(), &params, jacobian)? {
            Some(result) => result,
            None => {
                let prepared = match named {
                    Some(named) => self.prepared_named(named)?,
                    None => self.prepared(linear, z_input, cosmology)?,
                };
                let result = self.one(py, &prepared, &params, jacobian)?;
                *self.repeat.lock().expect("not poisoned") = key.map(|k| (k, prepared, None));
                result
            }
        };
        let v = values.into_pyarray(py).into_any();
        match jac {
            None => Ok(v),
            Some(j) => {
                let j = PyArray2::from_vec2(py, &j)?;
                Ok((v, j).into_pyobject(py)?.into_any())
            }
        }
    }

    /// Many parameter sets in one call: `cosmologies[i]` with the nuisance dict `params[i]`; an
    /// array of shape (len, n).
    fn batch<'py>(
        &self,
        py: Python<'py>,
        cosmologies: Vec<Bound<'py, PyAny>>,
        params: Vec<Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        if cosmologies.len() != params.len() {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "batch: {} cosmologies but {} parameter dicts",
                cosmologies.len(),
                params.len()
            )));
        }
        let mut rows = Vec::with_capacity(params.len());
        for (c, p) in cosmologies.iter().zip(&params) {
            let prepared = self.prepared(None, None, Some(c))?;
            rows.push(self.one(py, &prepared, &pairs(Some(p))?, false)?.0);
        }
        Ok(PyArray2::from_vec2(py, &rows)?)
    }

    /// The exact derivatives of the data vector with respect to the template parameters f, apar,
    /// aperp (rows in that order; an array of shape (3, n)) at `cosmology` or `linear` as a call
    /// takes them, with the nuisance parameters by name (`f` defaults to f(z); the distortion is the
    /// cosmology's against the fiducial, none without one: the derivatives at apar = aperp = 1). For
    /// template fits and forecasts: the power spectrum only (no block after it).
    #[pyo3(signature = (cosmology=None, linear=None, z_input=None, **params))]
    fn template_jacobian<'py>(
        &self,
        py: Python<'py>,
        cosmology: Option<&Bound<'py, PyAny>>,
        linear: Option<&Bound<'py, PyAny>>,
        z_input: Option<f64>,
        params: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let params = pairs(params)?;
        let prepared = self.prepared(linear, z_input, cosmology)?;
        let step = self.inner.step(&prepared).map_err(value_error)?;
        let named: Vec<(&str, f64)> = params.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        let rows = step.template_jacobian(&named).map_err(value_error)?;
        Ok(PyArray2::from_vec2(py, &rows)?)
    }

    /// The data vector at `cosmology` (a preset, an ini file or a dict of CLASS/CAMB names, given
    /// with A_s or ln10^{10}A_s) with the nuisance parameters by name (`f` defaults to f(z) and
    /// then varies with the cosmology), and its exact derivatives with respect to the sampled
    /// cosmological parameters `cosmological_parameters` (h, omega_b, omega_cdm, ln10^{10}A_s, n_s,
    /// m_nu, w0, wa; Omega_k held): (data vector, array of shape (8, n)). Through the emulator, the
    /// growth, the loop terms on the basis, the AP distortion, the window and bins; no finite
    /// differences. The nuisance parameters' derivatives are `__call__(..., jacobian=True)`'s.
    /// `derivatives`: the names of the rows wanted, in that order (default all eight); each row costs
    /// its own loop-terms tangent and projection (five rows take 13–20% less time than eight), so a
    /// flat-ΛCDM sampler asks for its five. The array then has shape (len(derivatives), n).
    #[pyo3(signature = (cosmology, derivatives=None, **params))]
    fn cosmology_jacobian<'py>(
        &self,
        py: Python<'py>,
        cosmology: &Bound<'py, PyAny>,
        derivatives: Option<Vec<String>>,
        params: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (result, _) = self.jacobians(py, cosmology, derivatives, params, false)?;
        let v = result.data_vector.into_pyarray(py).into_any();
        let j = PyArray2::from_vec2(py, &result.cosmological)?;
        Ok((v, j).into_pyobject(py)?.into_any())
    }

    /// `cosmology_jacobian` and the nuisance rows of `__call__(..., jacobian=True)` (`nuisance`:
    /// the nuisance parameters, then f) of one step, made once: (data vector, array (12, n),
    /// array (8, n)). The whole Jacobian of a sampler over cosmological and nuisance parameters.
    /// `derivatives` as `cosmology_jacobian`'s (the last array then has one row per name).
    #[pyo3(signature = (cosmology, derivatives=None, **params))]
    fn full_jacobian<'py>(
        &self,
        py: Python<'py>,
        cosmology: &Bound<'py, PyAny>,
        derivatives: Option<Vec<String>>,
        params: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (result, nuisance) = self.jacobians(py, cosmology, derivatives, params, true)?;
        let v = result.data_vector.into_pyarray(py).into_any();
        let n = PyArray2::from_vec2(py, &nuisance.unwrap_or_default())?;
        let j = PyArray2::from_vec2(py, &result.cosmological)?;
        Ok((v, n, j).into_pyobject(py)?.into_any())
    }

    /// The names of the rows of `cosmology_jacobian` (CLASS's names).
    #[getter]
    fn cosmological_parameters(&self) -> Vec<&'static str> {
        pt_spectra::cosmology::background::DERIVATIVE_NAMES.to_vec()
    }

    /// The parameter names a call takes.
    #[getter]
    fn parameters(&self) -> Vec<&'static str> {
        self.inner.parameters()
    }

    /// The parameters of the Jacobian's rows, in order: the nuisance parameters, then f.
    #[getter]
    fn nuisance(&self) -> Vec<&'static str> {
        JACOBIAN_NAMES.to_vec()
    }

    /// The output k [h/Mpc].
    #[getter]
    fn k<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.observation().k_out().to_vec().into_pyarray(py)
    }

    /// What the pipeline is and what its last call did: model, z, ells, k, the fiducial, the
    /// largest projection residual, the loop range (``((lo, hi), change)`` or None: where the loop
    /// terms are computed and what that changed at build), and the loop terms' source of the last call.
    #[getter]
    fn meta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.inner.settings();
        let d = PyDict::new(py);
        d.set_item("model", "ept")?;
        d.set_item("z", s.z)?;
        d.set_item("ells", self.inner.observation().ells().to_vec())?;
        d.set_item("len", self.inner.len())?;
        d.set_item("power_len", self.inner.power_len())?;
        // per registered kind: whether the data vector holds its block
        for kind in pt_spectra::blocks::AVAILABLE {
            let held = self
                .inner
                .blocks()
                .iter()
                .any(|b| b.kind().name == kind.name);
            d.set_item(kind.name, held)?;
        }
        // what each block is and how it is computed (its header line)
        let blocks: Vec<String> = self.inner.blocks().iter().map(|b| b.describe()).collect();
        d.set_item("blocks", blocks)?;
        d.set_item("ap", s.fiducial.is_some())?;
        d.set_item("ir", s.ir)?;
        d.set_item("max_residual", s.max_residual)?;
        d.set_item("basis", self.inner.has_basis())?;
        // where the loop terms are computed: the true k range and its measured change, or None
        d.set_item("loop_range", self.inner.loop_range())?;
        d.set_item("loop_range_note", self.inner.describe_loop_range())?;
        d.set_item("mu_rule_note", self.inner.describe_mu_rule())?;
        d.set_item(
            "observation",
            self.inner.observation().description().to_vec(),
        )?;
        if let Some((source, f, ap)) = *self.last.lock().expect("not poisoned") {
            d.set_item("loop_terms", source.describe(s.max_residual))?;
            let residual = match source {
                TermsSource::Basis { residual } | TermsSource::DirectFallback { residual } => {
                    Some(residual)
                }
                TermsSource::Direct => None,
            };
            d.set_item("residual", residual)?;
            d.set_item(
                "fallback",
                matches!(source, TermsSource::DirectFallback { .. }),
            )?;
            d.set_item("f", f)?;
            d.set_item("apar_aperp", ap)?;
        }
        Ok(d)
    }
}
