//! The survey layer from Python: `Observation`, the model's multipoles → window → bins (or → ξ_ℓ(s)),
//! planned once; what a likelihood of survey data applies to the theory's multipoles at every step.

use crate::{detached, floats, matrix_rows, value_error};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pt_spectra::survey::observe::{Bins, Observation as LibObservation, Window};
use pt_spectra::survey::{Mixing, WindowFormat};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};

/// The window file `path` mixed by `mixing` (a Python name) with its columns declared by `format`
/// (`None`: the file's names line; `"s,Q0,Q2,Q4"`, `"boss"`: as `--window-format`).
pub(crate) fn read_window(
    path: &Path,
    mixing_name: &str,
    format: Option<&str>,
) -> PyResult<Window> {
    let format = match format {
        None => WindowFormat::header(),
        Some(f) => {
            WindowFormat::parse(f).map_err(|e| value_error(format!("window_format: {e}")))?
        }
    };
    Window::read(path, mixing(mixing_name)?, &format).map_err(value_error)
}

/// The chain from model multipoles to a measured data vector (`pt_spectra.survey.observe`).
#[pyclass(module = "pt_spectra._core", frozen)]
pub(crate) struct Observation {
    pub(crate) inner: LibObservation,
}

/// The window mixing of its Python name.
pub(crate) fn mixing(name: &str) -> PyResult<Mixing> {
    match name {
        "wilson" => Ok(Mixing::Wilson),
        "classpt-boss" => Ok(Mixing::ClassPtBoss),
        other => Err(PyValueError::new_err(format!(
            "window_mixing {other:?}: expected 'wilson' or 'classpt-boss'"
        ))),
    }
}

#[pymethods]
impl Observation {
    /// The output multipoles `ells` at `k` [h/Mpc] (ignored with `k_edges`: the bins' effective k, or
    /// with a window matrix: its own k), through the window file `window` (Q_ℓ(s) multipoles or a
    /// matrix, as `rsd --window`) mixed by `window_mixing` ('wilson' or 'classpt-boss'), and averaged
    /// over the bins of `k_edges` [h/Mpc] (k² weight) or over the modes of a periodic box of side
    /// `box` [Mpc/h] in those bins. `window_format`: the columns of a Q_ℓ(s) file without a names
    /// line (`"s,Q0,Q2,Q4"`, `"boss"`), as `--window-format`.
    #[new]
    #[pyo3(signature = (ells, k=None, window=None, window_mixing="wilson", k_edges=None, r#box=None,
        window_format=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        ells: Vec<usize>,
        k: Option<&Bound<'_, PyAny>>,
        window: Option<PathBuf>,
        window_mixing: &str,
        k_edges: Option<&Bound<'_, PyAny>>,
        r#box: Option<f64>,
        window_format: Option<&str>,
    ) -> PyResult<Self> {
        let k = match k {
            Some(k) => crate::k_array(k, "k")?.into_vec(),
            None => Vec::new(),
        };
        if window.is_none() && window_format.is_some() {
            return Err(PyValueError::new_err("window_format needs a window"));
        }
        let window = window
            .map(|path| read_window(&path, window_mixing, window_format))
            .transpose()?;
        let bins = match (k_edges.map(|e| floats(e, "k_edges")).transpose()?, r#box) {
            (None, None) => None,
            (Some(edges), None) => Some(Bins::Edges(edges)),
            (Some(edges), Some(side)) => Some(Bins::Box { side, edges }),
            (None, Some(_)) => return Err(PyValueError::new_err("box needs k_edges")),
        };
        let inner = LibObservation::new(&ells, &k, window, bins).map_err(value_error)?;
        // what the header would warn about (a window whose Q0(0) is not 1), as a Python warning
        for line in inner.description() {
            if let Some(warning) = line.strip_prefix("warning: ") {
                PyErr::warn(
                    py,
                    &py.get_type::<pyo3::exceptions::PyUserWarning>(),
                    &std::ffi::CString::new(warning)?,
                    1,
                )?;
            }
        }
        Ok(Self { inner })
    }

    /// Correlation-function multipoles ξ_ℓ at `s` [Mpc/h], or averaged over the s bins of `s_edges`
    /// (s² weight): no window (a Landy–Szalay estimate divides it out).
    #[staticmethod]
    #[pyo3(signature = (ells, s=None, s_edges=None))]
    fn xi(
        ells: Vec<usize>,
        s: Option<&Bound<'_, PyAny>>,
        s_edges: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let s = s.map(|s| floats(s, "s")).transpose()?.unwrap_or_default();
        let edges = s_edges.map(|e| floats(e, "s_edges")).transpose()?;
        let inner = LibObservation::xi(&ells, &s, edges.as_deref()).map_err(value_error)?;
        Ok(Self { inner })
    }

    /// The output multipoles.
    #[getter]
    fn ells(&self) -> Vec<usize> {
        self.inner.ells().to_vec()
    }

    /// The model multipoles needed, in the order `apply` takes them.
    #[getter]
    fn model_ells(&self) -> Vec<usize> {
        self.inner.model_ells().to_vec()
    }

    /// The k [h/Mpc] at which the model is needed.
    #[getter]
    fn k_model<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.k_model().to_vec().into_pyarray(py)
    }

    /// The output k [h/Mpc] (s [Mpc/h] for ξ).
    #[getter]
    fn k_out<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.k_out().to_vec().into_pyarray(py)
    }

    /// Whether the output is ξ_ℓ(s).
    #[getter]
    fn is_xi(&self) -> bool {
        self.inner.is_xi()
    }

    /// Lines saying what the chain does (for a header).
    #[getter]
    fn description(&self) -> Vec<String> {
        self.inner.description().to_vec()
    }

    /// The values of `apply` without the error estimates (what a likelihood needs at every step;
    /// about half the transforms): shape (len(ells), len(k_out)).
    fn apply_values<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows = matrix_rows(
            model,
            "model: expected a 2-D array (len(model_ells), len(k_model))",
        )?;
        let (out, _) = detached(py, || self.inner.apply_values(&rows))?;
        PyArray2::from_vec2(py, &out).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The observed multipoles from the model's: `model` of shape (len(model_ells), len(k_model));
    /// returns (values, errors), each of shape (len(ells), len(k_out)).
    #[allow(clippy::type_complexity)]
    fn apply<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
        let rows = matrix_rows(
            model,
            "model: expected a 2-D array (len(model_ells), len(k_model))",
        )?;
        let (out, _) = detached(py, || self.inner.apply(&rows))?;
        let values: Vec<Vec<f64>> = out
            .iter()
            .map(|r| r.iter().map(|e| e.value).collect())
            .collect();
        let errors: Vec<Vec<f64>> = out
            .iter()
            .map(|r| r.iter().map(|e| e.error).collect())
            .collect();
        let to_array = |v: Vec<Vec<f64>>| {
            PyArray2::from_vec2(py, &v).map_err(|e| PyValueError::new_err(e.to_string()))
        };
        Ok((to_array(values)?, to_array(errors)?))
    }
}
