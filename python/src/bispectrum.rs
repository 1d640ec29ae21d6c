//! `pt.bispectrum`, `pt.BispectrumPlan`: the tree-level galaxy bispectrum multipoles
//! ([`pt_spectra::bispectrum`]) from Python.

use crate::inputs::Inputs;
use crate::tables::Table;
use crate::{detached, library_error, matrix_rows};
use numpy::{IntoPyArray, PyArray2, PyArrayMethods};
use pt_spectra::bispectrum::{
    self as bk, BispectrumParams, Fog, LegendreSide, PlanRules, Settings, TriangleSet,
};
use pt_spectra::jobs::{bispectrum_table, BispectrumRequest};
use pt_spectra::precision::Precision;
use pyo3::prelude::*;

/// The triangle set of a (n, 3) array of k1 k2 k3 [h/Mpc], bins of `bin_width` if given.
fn triangle_set(triangles: &Bound<'_, PyAny>, bin_width: Option<f64>) -> PyResult<TriangleSet> {
    let rows = matrix_rows(
        triangles,
        "triangles must be an (n, 3) array of k1, k2, k3 [h/Mpc]",
    )?;
    let mut t = Vec::with_capacity(rows.len());
    for (i, r) in rows.iter().enumerate() {
        match r[..] {
            [a, b, c] => t.push([a, b, c]),
            _ => {
                return Err(crate::value_error(format!(
                    "triangles[{i}] has {} values: each row is k1, k2, k3 [h/Mpc]",
                    r.len()
                )))
            }
        }
    }
    match bin_width {
        Some(w) => TriangleSet::shells(t, w),
        None => TriangleSet::points(t),
    }
    .map_err(library_error)
}

/// The parameters of the keyword arguments.
#[allow(clippy::too_many_arguments)]
fn params(
    b1: f64,
    b2: f64,
    bs: f64,
    c1: f64,
    n_bar: Option<f64>,
    b_shot: f64,
    p_shot: f64,
    a_shot: f64,
) -> BispectrumParams {
    BispectrumParams {
        b1,
        b2,
        bs,
        c1,
        b_shot,
        p_shot,
        a_shot,
        n_bar: n_bar.unwrap_or(f64::INFINITY),
    }
}

/// B0, B2, B4 [(Mpc/h)^6] of the triangles (an (n, 3) array of k1 k2 k3 [h/Mpc]; bins of `bin_width`
/// if given) as a `Table` with columns k1 k2 k3 B0 B2 B4 err_B0 err_B2 err_B4, its header and `meta`.
#[pyfunction]
#[pyo3(signature = (triangles, bin_width=None, linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None,
    b1=1.0, b2=0.0, bs=0.0, c1=0.0, n_bar=None, b_shot=1.0, p_shot=0.0, a_shot=0.0, f=None, q_par=1.0,
    q_perp=1.0, fog="none", sigma_fog=0.0, ir=true, legendre_side="largest"))]
#[allow(clippy::too_many_arguments)]
pub fn bispectrum(
    py: Python<'_>,
    triangles: &Bound<'_, PyAny>,
    bin_width: Option<f64>,
    linear: Option<&Bound<'_, PyAny>>,
    z: f64,
    z_input: f64,
    cosmology: Option<&Bound<'_, PyAny>>,
    eh: Option<&str>,
    b1: f64,
    b2: f64,
    bs: f64,
    c1: f64,
    n_bar: Option<f64>,
    b_shot: f64,
    p_shot: f64,
    a_shot: f64,
    f: Option<f64>,
    q_par: f64,
    q_perp: f64,
    fog: &str,
    sigma_fog: f64,
    ir: bool,
    legendre_side: &str,
) -> PyResult<Table> {
    let request = BispectrumRequest {
        triangles: triangle_set(triangles, bin_width)?,
        side: LegendreSide::by_name(legendre_side).map_err(library_error)?,
        rules: PlanRules::default(),
        params: params(b1, b2, bs, c1, n_bar, b_shot, p_shot, a_shot),
        f,
        q: (q_par, q_perp),
        fog: Fog::by_name(fog, sigma_fog).map_err(library_error)?,
        ir,
    };
    let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
    let ((prepared, table), seconds) = detached(py, || {
        let prepared = inputs.prepare(&[])?;
        let table = bispectrum_table(&prepared, &request)?;
        Ok((prepared, table))
    })?;
    Table::new(
        py,
        table,
        &prepared,
        &Precision::default(),
        "bispectrum tree",
        seconds,
    )
}

/// A tree-level bispectrum planned for a set of triangles: `plan.terms(...)` per linear spectrum (f,
/// AP, FoG, IR), then `terms.multipoles(b1=..., ...)` per parameter step (microseconds).
#[pyclass(module = "pt_spectra._core", frozen)]
pub struct BispectrumPlan {
    plan: bk::BispectrumPlan,
}

#[pymethods]
impl BispectrumPlan {
    #[new]
    #[pyo3(signature = (triangles, bin_width=None, legendre_side="largest"))]
    fn new(
        triangles: &Bound<'_, PyAny>,
        bin_width: Option<f64>,
        legendre_side: &str,
    ) -> PyResult<Self> {
        let set = triangle_set(triangles, bin_width)?;
        let side = LegendreSide::by_name(legendre_side).map_err(library_error)?;
        let plan =
            bk::BispectrumPlan::new(set, side, PlanRules::default()).map_err(library_error)?;
        Ok(Self { plan })
    }

    /// The terms of one linear spectrum (as `pt.bispectrum` takes it); f defaults to f(z).
    #[pyo3(signature = (linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None, f=None, q_par=1.0,
        q_perp=1.0, fog="none", sigma_fog=0.0, ir=true))]
    #[allow(clippy::too_many_arguments)]
    fn terms(
        &self,
        py: Python<'_>,
        linear: Option<&Bound<'_, PyAny>>,
        z: f64,
        z_input: f64,
        cosmology: Option<&Bound<'_, PyAny>>,
        eh: Option<&str>,
        f: Option<f64>,
        q_par: f64,
        q_perp: f64,
        fog: &str,
        sigma_fog: f64,
        ir: bool,
    ) -> PyResult<BispectrumTerms> {
        let fog = Fog::by_name(fog, sigma_fog).map_err(library_error)?;
        let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
        let plan = &self.plan;
        let ((terms, f), _) = detached(py, || {
            let prepared = inputs.prepare(&[])?;
            let f = f.unwrap_or(prepared.growth_rate);
            let settings = Settings {
                f,
                q_par,
                q_perp,
                fog,
                ir,
            };
            Ok((plan.terms(prepared.tracer_spectrum(), &settings)?, f))
        })?;
        Ok(BispectrumTerms { terms, f })
    }
}

/// B and its errors, (n, 3) arrays.
type ValuesAndErrors<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// The terms of one spectrum: `multipoles(...)` returns (B, err), (n, 3) arrays of B0, B2, B4.
#[pyclass(module = "pt_spectra._core", frozen)]
pub struct BispectrumTerms {
    terms: bk::BispectrumTerms,
    /// The growth rate used.
    #[pyo3(get)]
    f: f64,
}

#[pymethods]
impl BispectrumTerms {
    /// (B, err): (n, 3) arrays of B0, B2, B4 [(Mpc/h)^6] and their quadrature errors.
    #[pyo3(signature = (b1=1.0, b2=0.0, bs=0.0, c1=0.0, n_bar=None, b_shot=1.0, p_shot=0.0, a_shot=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn multipoles<'py>(
        &self,
        py: Python<'py>,
        b1: f64,
        b2: f64,
        bs: f64,
        c1: f64,
        n_bar: Option<f64>,
        b_shot: f64,
        p_shot: f64,
        a_shot: f64,
    ) -> PyResult<ValuesAndErrors<'py>> {
        let b = self
            .terms
            .multipoles(&params(b1, b2, bs, c1, n_bar, b_shot, p_shot, a_shot))
            .map_err(library_error)?;
        let n = b.len();
        let values: Vec<f64> = b.iter().flat_map(|r| r.map(|e| e.value)).collect();
        let errors: Vec<f64> = b.iter().flat_map(|r| r.map(|e| e.error)).collect();
        let shape = |v: Vec<f64>| v.into_pyarray(py).reshape([n, 3]);
        Ok((shape(values)?, shape(errors)?))
    }
}
