//! The 2-loop matter multipoles in redshift space from Python: `TwoLoopRsdPlan` (the plan and, with
//! `two_loop="basis"`, the basis tensors once per k grid) for `spt2` and `eft2` (IR resummation,
//! counterterms by name as keyword arguments).

use crate::inputs::Inputs;
use crate::tables::Table;
use crate::{detached, value_error};
use pt_spectra::progress::Silent;
use pt_spectra::rsd::eft2::{Eft2Plan, RsdCounterterms};
use pt_spectra::rsd::spt2::Spt2Plan;
use pyo3::prelude::*;
use pyo3::types::PyDict;

enum Plan {
    Spt2(Box<Spt2Plan>),
    Eft2(Box<Eft2Plan>),
}

/// `spt2` or `eft2` planned for one k grid.
#[pyclass(module = "pt_spectra._core", frozen)]
pub(crate) struct TwoLoopRsdPlan {
    plan: Plan,
    precision: pt_spectra::precision::Precision,
}

/// The counterterms of `kwargs` as `NAME=VALUE` assignments (values must be numbers).
fn counterterms(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<RsdCounterterms> {
    let assignments: Vec<String> = crate::number_kwargs(kwargs)?
        .into_iter()
        .map(|(name, v)| format!("{name}={v}"))
        .collect();
    RsdCounterterms::from_assignments(&assignments).map_err(value_error)
}

#[pymethods]
impl TwoLoopRsdPlan {
    /// What the plan computes, how a new spectrum's terms are computed (`method`: direct or basis)
    /// and its memory estimates in bytes (the plan, one spectrum's terms).
    #[getter]
    fn plan_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        match &self.plan {
            Plan::Spt2(p) => crate::seam::plan_info(py, &**p),
            Plan::Eft2(p) => crate::seam::plan_info(py, &**p),
        }
    }

    #[new]
    #[pyo3(signature = (k, model="eft2", ir=true, precision=pt_spectra::jobs::defaults::PRECISION, q_range=None, two_loop=pt_spectra::jobs::defaults::TWO_LOOP, cache_dir=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        k: &Bound<'_, PyAny>,
        model: &str,
        ir: bool,
        precision: &str,
        q_range: Option<(f64, f64)>,
        two_loop: &str,
        cache_dir: Option<std::path::PathBuf>,
    ) -> PyResult<Self> {
        let k = crate::k_array(k, "k")?;
        let precision = crate::precision(precision, q_range, None, Some(two_loop))?;
        let store = crate::Store::new(cache_dir);
        let model = model.to_ascii_lowercase();
        if model != "spt2" && model != "eft2" {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "model '{model}': expected spt2 or eft2"
            )));
        }
        if model == "spt2" && !ir {
            return Err(pyo3::exceptions::PyValueError::new_err(
                "ir is an option of eft2 (spt2 has no IR resummation)",
            ));
        }
        let (plan, _) = detached(py, || {
            Ok(if model == "spt2" {
                Plan::Spt2(Box::new(
                    Spt2Plan::new(&k, &precision)?.with_basis(store.get(), &Silent)?,
                ))
            } else {
                Plan::Eft2(Box::new(
                    Eft2Plan::new(&k, ir, &precision)?.with_basis(store.get(), &Silent)?,
                ))
            })
        })?;
        Ok(Self { plan, precision })
    }

    /// The multipoles `ells` of the prepared spectrum at growth rate `f` (None: f(z)), with the
    /// counterterms of `kwargs` (eft2), and with `terms` the parts (spt2) or templates (eft2).
    #[pyo3(signature = (linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None, f=None, ells=vec![0, 2, 4], terms=false, **kwargs))]
    #[allow(clippy::too_many_arguments)]
    fn __call__(
        &self,
        py: Python<'_>,
        linear: Option<&Bound<'_, PyAny>>,
        z: f64,
        z_input: f64,
        cosmology: Option<&Bound<'_, PyAny>>,
        eh: Option<&str>,
        f: Option<f64>,
        ells: Vec<usize>,
        terms: bool,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Table> {
        let ct = counterterms(kwargs)?;
        let (k, name) = match &self.plan {
            Plan::Spt2(p) => {
                if ct.values.iter().any(|&v| v != 0.0) {
                    return Err(pyo3::exceptions::PyValueError::new_err(
                        "counterterms are options of eft2 (spt2 has none)",
                    ));
                }
                (p.k().to_vec(), "spt2")
            }
            Plan::Eft2(p) => (p.k().to_vec(), "eft2"),
        };
        pt_spectra::rsd::MultipoleRule::new(&ells).map_err(value_error)?;
        // f is checked before the loop terms are computed (seconds without the basis).
        if let Some(f) = f {
            pt_spectra::cosmology::check_growth_rate(f).map_err(value_error)?;
        }
        let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
        let ((table, prepared), seconds) = detached(py, || {
            let prepared = inputs.prepare(&k)?;
            let spectrum = prepared.tracer_spectrum();
            let table = match &self.plan {
                Plan::Spt2(p) => {
                    let t = p.terms(spectrum, &Silent)?;
                    pt_spectra::jobs::spt2_table(
                        p,
                        &t,
                        f,
                        &ells,
                        terms,
                        &prepared,
                        &self.precision,
                    )?
                }
                Plan::Eft2(p) => {
                    let t = p.terms(spectrum, &Silent)?;
                    pt_spectra::jobs::eft2_table(
                        p,
                        &t,
                        f,
                        &ells,
                        &ct,
                        terms,
                        &prepared,
                        &self.precision,
                    )?
                }
            };
            Ok((table, prepared))
        })?;
        let mut table = Table::new(py, table, &prepared, &self.precision, name, seconds)?;
        if name == "eft2" && ct.values.iter().all(|&v| v == 0.0) {
            table.warn(
                "every counterterm of eft2 is 0 (it is then IR-resummed 2-loop SPT): pass them by \
                 name, e.g. c0=3.0"
                    .into(),
            );
        }
        Ok(table)
    }

    /// The eft2 counterterms `free` fitted to measured multipoles `data` ({ell: (values, sigma)} at
    /// the plan's k) over k <= `k_max`, the others at `kwargs`' values: {name: (value, error)}.
    #[pyo3(signature = (data, free, k_max, linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None, f=None, **kwargs))]
    #[allow(clippy::too_many_arguments)]
    fn fit_counterterms(
        &self,
        py: Python<'_>,
        data: std::collections::BTreeMap<usize, (Vec<f64>, Vec<f64>)>,
        free: Vec<String>,
        k_max: f64,
        linear: Option<&Bound<'_, PyAny>>,
        z: f64,
        z_input: f64,
        cosmology: Option<&Bound<'_, PyAny>>,
        eh: Option<&str>,
        f: Option<f64>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<std::collections::BTreeMap<String, (f64, f64)>> {
        use pt_spectra::rsd::eft2::{fit_counterterms, MeasuredMultipole, RsdCounterterm};
        let Plan::Eft2(plan) = &self.plan else {
            return Err(pyo3::exceptions::PyValueError::new_err(
                "counterterms are options of eft2 (spt2 has none)",
            ));
        };
        let fixed = counterterms(kwargs)?;
        let free: Vec<RsdCounterterm> = free
            .iter()
            .map(|n| n.parse().map_err(value_error))
            .collect::<PyResult<_>>()?;
        let measured: Vec<MeasuredMultipole> = data
            .into_iter()
            .map(|(ell, (values, sigma))| MeasuredMultipole { ell, values, sigma })
            .collect();
        let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
        let ((values, errors), _) = detached(py, || {
            let prepared = inputs.prepare(plan.k())?;
            let terms = plan.terms(prepared.tracer_spectrum(), &Silent)?;
            let f = f.unwrap_or(prepared.growth_rate);
            fit_counterterms(&terms, f, &measured, &free, &fixed, k_max)
        })?;
        Ok(RsdCounterterm::ALL
            .iter()
            .enumerate()
            .map(|(j, c)| (c.name().to_string(), (values.values[j], errors.values[j])))
            .collect())
    }
}
