//! `fit_joint`: the joint fit of the galaxy model to the data sets of an analysis file
//! (`pt-spectra fit --analysis`, docs/analysis.md).

use crate::inputs::Inputs;
use crate::tables::Table;
use crate::{detached, value_error};
use pt_spectra::progress::Silent;
use pyo3::prelude::*;

/// The analysis file `analysis`, the precision and the spectrum's inputs of the arguments (at the
/// first set's z; each set is prepared at its own).
fn read(
    analysis: &std::path::Path,
    linear: Option<&Bound<'_, PyAny>>,
    z_input: f64,
    cosmology: Option<&Bound<'_, PyAny>>,
    precision: &str,
    q_range: Option<(f64, f64)>,
    eh: Option<&str>,
) -> PyResult<(
    pt_spectra::jobs::Analysis,
    pt_spectra::precision::Precision,
    Inputs,
)> {
    let parsed = pt_spectra::jobs::analysis::read_analysis(analysis).map_err(value_error)?;
    let precision = crate::precision(precision, q_range, None, None)?;
    let inputs = Inputs::extract(linear, parsed.sets[0].z, z_input, cosmology, eh)?;
    Ok((parsed, precision, inputs))
}

/// `f` with the library's inputs of an analysis: the spectrum at each set's z, `precision`, the
/// cache, no progress.
fn with_job_inputs<T>(
    inputs: &Inputs,
    precision: &pt_spectra::precision::Precision,
    f: impl FnOnce(&pt_spectra::jobs::Inputs) -> pt_spectra::error::Result<T>,
) -> pt_spectra::error::Result<T> {
    let prepare = |z: f64| inputs.prepare_at(&[], z);
    let store = crate::Store::new(None);
    f(&pt_spectra::jobs::Inputs {
        prepare: &prepare,
        precision,
        store: store.get(),
        progress: &Silent,
    })
}

/// The joint fit of the analysis file `analysis` (TOML: the data sets and the shared parameters)
/// with the cosmology and linear spectrum of the arguments, each set at its own z: a table with a
/// row per data set, as `pt-spectra fit --analysis`.
#[pyfunction]
#[pyo3(signature = (analysis, linear=None, z_input=0.0, cosmology=None,
    precision=pt_spectra::jobs::defaults::PRECISION, q_range=None, eh=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit_joint(
    py: Python<'_>,
    analysis: std::path::PathBuf,
    linear: Option<&Bound<'_, PyAny>>,
    z_input: f64,
    cosmology: Option<&Bound<'_, PyAny>>,
    precision: &str,
    q_range: Option<(f64, f64)>,
    eh: Option<&str>,
) -> PyResult<Table> {
    let (parsed, precision, inputs) = read(
        &analysis, linear, z_input, cosmology, precision, q_range, eh,
    )?;
    let ((table, prepared), seconds) = detached(py, || {
        let first = inputs.prepare(&[])?;
        let header = vec![format!(
            "pt-spectra {} fit_joint {}: ept (velocileptors' REPT conventions) jointly to every \
             data set of the file",
            pt_spectra::jobs::VERSION,
            analysis.display()
        )];
        let (table, _) = with_job_inputs(&inputs, &precision, |job_inputs| {
            pt_spectra::jobs::joint_fit_table(&parsed, job_inputs, header)
        })?;
        Ok((table, first))
    })?;
    Table::new(py, table, &prepared, &precision, "ept joint fit", seconds)
}

/// The likelihood of an analysis file, kept between calls: see the Python wrapper
/// `pt_spectra.AnalysisLikelihood`.
#[pyclass(module = "pt_spectra._core", frozen)]
pub(crate) struct AnalysisLikelihood {
    inner: std::sync::Mutex<pt_spectra::jobs::AnalysisLikelihood>,
}

impl AnalysisLikelihood {
    fn with<T>(&self, f: impl FnOnce(&pt_spectra::jobs::AnalysisLikelihood) -> T) -> T {
        let guard = self
            .inner
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        f(&guard)
    }
}

#[pymethods]
impl AnalysisLikelihood {
    #[new]
    #[pyo3(signature = (analysis, linear=None, z_input=0.0, cosmology=None,
        precision=pt_spectra::jobs::defaults::PRECISION, q_range=None, eh=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        analysis: std::path::PathBuf,
        linear: Option<&Bound<'_, PyAny>>,
        z_input: f64,
        cosmology: Option<&Bound<'_, PyAny>>,
        precision: &str,
        q_range: Option<(f64, f64)>,
        eh: Option<&str>,
    ) -> PyResult<Self> {
        let (parsed, precision, inputs) = read(
            &analysis, linear, z_input, cosmology, precision, q_range, eh,
        )?;
        let (inner, _) = detached(py, || {
            with_job_inputs(&inputs, &precision, |job_inputs| {
                pt_spectra::jobs::AnalysisLikelihood::new(&parsed, job_inputs)
            })
        })?;
        Ok(Self {
            inner: std::sync::Mutex::new(inner),
        })
    }

    /// The free parameters, in the order of the values the calls take.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.with(|l| l.names())
    }

    /// Their (lower, upper) bounds.
    #[getter]
    fn bounds(&self) -> Vec<(f64, f64)> {
        self.with(|l| l.bounds())
    }

    /// Their start values.
    #[getter]
    fn start(&self) -> Vec<f64> {
        self.with(|l| l.start())
    }

    /// Whether the exact gradient is available.
    #[getter]
    fn exact_gradient(&self) -> bool {
        self.with(|l| l.exact_gradient())
    }

    /// The fitted points of all sets.
    #[getter]
    fn points(&self) -> usize {
        self.with(|l| l.points())
    }

    /// Per data set label: σ8(z) of its template.
    #[getter]
    fn sigma8_z(&self) -> Vec<(String, f64)> {
        self.with(|l| l.sigma8_z())
    }

    /// What the likelihood is.
    #[getter]
    fn header(&self) -> Vec<String> {
        self.with(|l| l.header().to_vec())
    }

    /// −2 ln L at the values `x`.
    fn minus_two_log_l(&self, py: Python<'_>, x: Vec<f64>) -> PyResult<f64> {
        Ok(detached(py, || self.with(|l| l.minus_two_log_l(&x)))?.0)
    }

    /// (−2 ln L, its gradient) at `x`, or None without an exact gradient.
    fn value_and_gradient(&self, py: Python<'_>, x: Vec<f64>) -> PyResult<Option<(f64, Vec<f64>)>> {
        Ok(detached(py, || self.with(|l| l.value_and_gradient(&x)))?.0)
    }
}
