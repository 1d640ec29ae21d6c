//! `fit_joint`: the joint fit of the galaxy model to the data sets of an analysis file
//! (`pt-spectra fit --analysis`, docs/analysis.md).

use crate::inputs::Inputs;
use crate::tables::Table;
use crate::{detached, value_error};
use pt_spectra::progress::Silent;
use pyo3::prelude::*;

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
    let parsed = pt_spectra::jobs::analysis::read_analysis(&analysis).map_err(value_error)?;
    let precision = crate::precision(precision, q_range, None, None)?;
    let inputs = Inputs::extract(linear, parsed.sets[0].z, z_input, cosmology, eh)?;
    let ((table, prepared), seconds) = detached(py, || {
        let first = inputs.prepare(&[])?;
        let prepare = |z: f64| inputs.prepare_at(&[], z);
        let store = crate::Store::new(None);
        let job_inputs = pt_spectra::jobs::Inputs {
            prepare: &prepare,
            precision: &precision,
            store: store.get(),
            progress: &Silent,
        };
        let header = vec![format!(
            "pt-spectra {} fit_joint {}: ept (velocileptors' REPT conventions) jointly to every \
             data set of the file",
            pt_spectra::jobs::VERSION,
            analysis.display()
        )];
        let (table, _) = pt_spectra::jobs::joint_fit_table(&parsed, &job_inputs, header)?;
        Ok((table, first))
    })?;
    Table::new(py, table, &prepared, &precision, "ept joint fit", seconds)
}
