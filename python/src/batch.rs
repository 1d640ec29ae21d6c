//! Arrays for chains: `RealPlan.batch` (many linear spectra on one k table at once, over rayon's
//! threads, returned as arrays with a leading spectrum axis: no header, no per-spectrum Table) and
//! `read_multipoles` (a likelihood's data file through the library's reader).

use crate::{detached, value_error, RealPlan};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray2};
use pt_spectra::jobs::{self, BatchRows};
use pt_spectra::real::RealSelection;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The plan's model for every row of `p` (n_spectra, len(k_lin)) [(Mpc/h)^3] tabulated at
/// `k_lin` [h/Mpc], each already at the output redshift: a dict of the columns `real` prints
/// (`P_lin`, `P_dd`, … and with `terms` their errors and the loop terms), each an array of shape
/// (n_spectra, n_k), and `k`.
#[pyfunction]
#[pyo3(signature = (plan, k_lin, p, terms=false))]
pub(crate) fn real_batch<'py>(
    py: Python<'py>,
    plan: &RealPlan,
    k_lin: &Bound<'py, PyAny>,
    p: PyReadonlyArray2<'py, f64>,
    terms: bool,
) -> PyResult<Bound<'py, PyDict>> {
    if plan.selection == RealSelection::All {
        return Err(PyValueError::new_err(
            "batch: a plan of model `all` computes several models; plan one model for batches",
        ));
    }
    let k_lin = crate::k_array(k_lin, "k_lin")?.into_vec();
    let p = p.as_array();
    if p.ncols() != k_lin.len() {
        return Err(PyValueError::new_err(format!(
            "batch: P has {} columns but k_lin has {} values (P is (n_spectra, len(k_lin)))",
            p.ncols(),
            k_lin.len()
        )));
    }
    // Planned against the memory limit ($PT_SPECTRA_MAX_MEMORY as now set, else the plan's) before
    // anything per spectrum is allocated; each row is copied by its own task.
    let max_memory = pt_spectra::memory::env_max_memory().map_err(value_error)?;
    let (view, n_rows) = (&p, p.nrows());
    let row = |i: usize| view.row(i).to_vec();
    let rows = BatchRows {
        k_lin: &k_lin,
        spectra: n_rows,
        row: &row,
        name: "P",
    };
    let (columns, _) = detached(py, || {
        jobs::real_batch(&plan.plan, &rows, terms, max_memory)
    })?;
    let out = PyDict::new(py);
    out.set_item("k", columns.k.into_pyarray(py))?;
    let n_k = plan.plan.k().len();
    for (name, values) in columns.columns {
        let array = Array2::from_shape_vec((n_rows, n_k), values).map_err(value_error)?;
        out.set_item(name, array.into_pyarray(py))?;
    }
    Ok(out)
}

/// The measured multipoles of a text file with exactly the columns k, then (P_ℓ, σ_ℓ) for each of
/// `data_ells` (the library's reader, `fit::DataLayout::read_exact`): (k, {ℓ: P_ℓ}, {ℓ: σ_ℓ}).
#[pyfunction]
pub(crate) fn read_multipoles<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
    data_ells: Vec<usize>,
) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
    let data = pt_spectra::fit::DataLayout::new(&data_ells, None)
        .and_then(|layout| layout.read_exact(&path))
        .map_err(value_error)?;
    let (values, sigma) = (PyDict::new(py), PyDict::new(py));
    for (j, &ell) in data.ells.iter().enumerate() {
        values.set_item(ell, data.values[j].clone().into_pyarray(py))?;
        sigma.set_item(ell, data.sigma[j].clone().into_pyarray(py))?;
    }
    pyo3::types::PyTuple::new(
        py,
        [
            data.k.into_pyarray(py).into_any(),
            values.into_any(),
            sigma.into_any(),
        ],
    )
}

/// Refuses `bytes` of arrays for `what` above the memory limit ($PT_SPECTRA_MAX_MEMORY, else half the
/// machine's memory) or the address space the process has left (`ulimit -v`): `MemoryError` with
/// both figures. For the grid runner (`pt_spectra.batch`), before it allocates its arrays.
#[pyfunction]
pub(crate) fn check_memory(bytes: f64, what: &str) -> PyResult<()> {
    let mut precision = pt_spectra::precision::Precision::default();
    precision.max_memory = pt_spectra::memory::env_max_memory().map_err(value_error)?;
    pt_spectra::memory::check_allocation(bytes, &precision, what).map_err(crate::library_error)
}

/// The covariance `c` (2-D array) of the data vector made of the multipole blocks `values` (one array
/// per ℓ, ℓ-major), checked as a whole (`fit::covariance::validate_whole`: finite, symmetric,
/// positive definite, not nearly singular, no variance absurdly small for its data; a fit checks the
/// degeneracy on the points it fits only) and returned symmetrised; `origin` names it in the
/// `ValueError`.
#[pyfunction]
#[pyo3(signature = (c, values, origin="covariance matrix"))]
pub(crate) fn check_covariance<'py>(
    py: Python<'py>,
    c: &Bound<'py, PyAny>,
    values: Vec<Vec<f64>>,
    origin: &str,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let rows = crate::covariance_rows(c)?;
    let checked = pt_spectra::fit::covariance::validate_whole(rows, &values, origin, &[])
        .map_err(value_error)?;
    numpy::PyArray2::from_vec2(py, &checked).map_err(value_error)
}
