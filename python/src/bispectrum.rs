//! `pt.bispectrum`, `pt.BispectrumPlan`, `pt.SugiyamaPlan`: the tree-level galaxy bispectrum
//! multipoles, Scoccimarro's and Sugiyama's ([`pt_spectra::bispectrum`]), from Python.

use crate::inputs::Inputs;
use crate::tables::Table;
use crate::{detached, library_error, matrix_rows};
use numpy::{IntoPyArray, PyArray2, PyArrayMethods};
use pt_spectra::bias::{BiasConvention, BiasParams};
use pt_spectra::bispectrum::{
    self as bk, BispectrumParams, Fog, LegendreSide, PlanRules, Settings, SugiyamaRules,
    TriangleSet,
};
use pt_spectra::estimate::Estimate;
use pt_spectra::jobs::{bispectrum_table, sugiyama_table, BispectrumRequest, SugiyamaRequest};
use pt_spectra::linear::LinearSpectrum;
use pt_spectra::precision::Precision;
use pyo3::prelude::*;

/// The rows of an (n, N) array `what` of `columns` [h/Mpc].
pub(crate) fn fixed_rows<const N: usize>(
    array: &Bound<'_, PyAny>,
    what: &str,
    columns: &str,
) -> PyResult<Vec<[f64; N]>> {
    let rows = matrix_rows(
        array,
        &format!("{what} must be an (n, {N}) array of {columns} [h/Mpc]"),
    )?;
    rows.iter()
        .enumerate()
        .map(|(i, r)| {
            <[f64; N]>::try_from(&r[..]).map_err(|_| {
                crate::value_error(format!(
                    "{what}[{i}] has {} values: each row is {columns} [h/Mpc]",
                    r.len()
                ))
            })
        })
        .collect()
}

/// The triangle set of a (n, 3) array of k1 k2 k3 [h/Mpc], bins of `bin_width` if given.
pub(crate) fn triangle_set(
    triangles: &Bound<'_, PyAny>,
    bin_width: Option<f64>,
) -> PyResult<TriangleSet> {
    let t = fixed_rows::<3>(triangles, "triangles", "k1, k2, k3")?;
    match bin_width {
        Some(w) => TriangleSet::shells(t, w),
        None => TriangleSet::points(t),
    }
    .map_err(library_error)
}

/// The parameters of the keyword arguments, with b1, b2, bs in `convention` (velocileptors' if
/// None; CLASS-PT's third slot is b_G2): the parameters in velocileptors' convention, and the header
/// line stating the conversion (None for velocileptors').
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
    convention: Option<&str>,
) -> PyResult<(BispectrumParams, Option<String>)> {
    let convention: BiasConvention = match convention {
        Some(c) => c.parse().map_err(library_error)?,
        None => BiasConvention::Velocileptors,
    };
    // the cubic slot does not enter the tree level: given as 0 in the convention
    let bias = BiasParams::from_convention(convention, [b1, b2, bs, 0.0]);
    let params = BispectrumParams {
        b1: bias.b1,
        b2: bias.b2,
        bs: bias.bs,
        c1,
        b_shot,
        p_shot,
        a_shot,
        n_bar: n_bar.unwrap_or(f64::INFINITY),
    };
    let note = (convention != BiasConvention::Velocileptors).then(|| bias.describe(convention));
    Ok((params, note))
}

/// B0, B2, B4 [(Mpc/h)^6] of the triangles (an (n, 3) array of k1 k2 k3 [h/Mpc]; bins of `bin_width`
/// if given) as a `Table` with columns k1 k2 k3 B0 B2 B4 err_B0 err_B2 err_B4, its header and `meta`;
/// with `basis="sugiyama"` the Sugiyama multipoles at `pairs` (an (n, 2) array of k1 k2 [h/Mpc]),
/// columns k1 k2 B000 B110 B202 B022 B112 B220 err_B000 …. With `box_size` L [Mpc/h] the bins are
/// averaged exactly over the discrete modes of a periodic box of side L (line of sight z).
#[pyfunction]
#[pyo3(signature = (triangles=None, bin_width=None, linear=None, z=0.0, z_input=0.0, cosmology=None,
    eh=None, b1=1.0, b2=0.0, bs=0.0, c1=0.0, n_bar=None, b_shot=1.0, p_shot=0.0, a_shot=0.0, f=None,
    q_par=1.0, q_perp=1.0, fog="none", sigma_fog=0.0, ir=true, legendre_side="largest",
    basis="scoccimarro", pairs=None, box_size=None, bias_convention=None))]
#[allow(clippy::too_many_arguments)]
pub fn bispectrum(
    py: Python<'_>,
    triangles: Option<&Bound<'_, PyAny>>,
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
    basis: &str,
    pairs: Option<&Bound<'_, PyAny>>,
    box_size: Option<f64>,
    bias_convention: Option<&str>,
) -> PyResult<Table> {
    let (params, bias_note) = params(
        b1,
        b2,
        bs,
        c1,
        n_bar,
        b_shot,
        p_shot,
        a_shot,
        bias_convention,
    )?;
    let fog = Fog::by_name(fog, sigma_fog).map_err(library_error)?;
    let sugiyama = match basis.to_ascii_lowercase().as_str() {
        "scoccimarro" => None,
        "sugiyama" => {
            if triangles.is_some()
                || bin_width.is_some()
                || legendre_side != "largest"
                || box_size.is_some()
            {
                return Err(crate::value_error(
                    "basis='sugiyama' takes pairs (k1, k2), not triangles, bin_width, legendre_side or \
                     box_size",
                ));
            }
            let Some(pairs) = pairs else {
                return Err(crate::value_error(
                    "basis='sugiyama' needs pairs: an (n, 2) array of k1, k2 [h/Mpc]",
                ));
            };
            Some(SugiyamaRequest {
                pairs: fixed_rows::<2>(pairs, "pairs", "k1, k2")?,
                rules: SugiyamaRules::default(),
                params,
                f,
                q: (q_par, q_perp),
                fog,
                ir,
            })
        }
        other => {
            return Err(crate::value_error(format!(
                "basis = {other}: valid: scoccimarro, sugiyama"
            )))
        }
    };
    let scoccimarro = match (&sugiyama, triangles) {
        (Some(_), _) => None,
        (None, None) => {
            return Err(crate::value_error(
                "give triangles: an (n, 3) array of k1, k2, k3 [h/Mpc] (or basis='sugiyama' with pairs)",
            ))
        }
        (None, Some(triangles)) => {
            if pairs.is_some() {
                return Err(crate::value_error("pairs are for basis='sugiyama'"));
            }
            Some(BispectrumRequest {
                triangles: triangle_set(triangles, bin_width)?,
                side: LegendreSide::by_name(legendre_side).map_err(library_error)?,
                rules: PlanRules::default(),
                params,
                f,
                q: (q_par, q_perp),
                fog,
                ir,
                box_size,
            })
        }
    };
    let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
    let ((prepared, table), seconds) = detached(py, || {
        let prepared = inputs.prepare(&[])?;
        let mut table = match (&scoccimarro, &sugiyama) {
            (Some(request), _) => bispectrum_table(&prepared, request)?,
            (None, Some(request)) => sugiyama_table(&prepared, request)?,
            (None, None) => unreachable!("one request is made above"),
        };
        table.header.extend(bias_note);
        Ok((prepared, table))
    })?;
    let model = if sugiyama.is_some() {
        "bispectrum tree sugiyama"
    } else {
        "bispectrum tree"
    };
    Table::new(py, table, &prepared, &Precision::default(), model, seconds)
}

/// Runs `compute` on the tracer spectrum of the inputs with the settings of the keyword arguments
/// (f defaults to f(z)) without the GIL; returns its result and f.
#[allow(clippy::too_many_arguments)]
fn with_spectrum<T: Send>(
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
    compute: impl FnOnce(&LinearSpectrum, &Settings) -> pt_spectra::error::Result<T> + Send,
) -> PyResult<(T, f64)> {
    let fog = Fog::by_name(fog, sigma_fog).map_err(library_error)?;
    let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
    let (out, _) = detached(py, || {
        let prepared = inputs.prepare(&[])?;
        let f = f.unwrap_or(prepared.growth_rate);
        let settings = Settings {
            f,
            q_par,
            q_perp,
            fog,
            ir,
        };
        Ok((compute(prepared.tracer_spectrum(), &settings)?, f))
    })?;
    Ok(out)
}

/// A tree-level bispectrum planned for a set of triangles: `plan.terms(...)` per linear spectrum (f,
/// AP, FoG, IR), then `terms.multipoles(b1=..., ...)` per parameter step (microseconds). A subclass in
/// Python (`pt.BispectrumPlan`) adds `loop=1`.
#[pyclass(module = "pt_spectra._core", frozen, subclass)]
pub struct BispectrumPlan {
    plan: bk::BispectrumPlan,
}

#[pymethods]
impl BispectrumPlan {
    /// What the plan computes, how a new spectrum's terms are computed (`method`: direct or basis)
    /// and its memory estimates in bytes (the plan, one spectrum's terms).
    #[getter]
    fn plan_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        crate::seam::plan_info(py, &self.plan)
    }

    #[new]
    #[pyo3(signature = (triangles, bin_width=None, legendre_side="largest", effective=false))]
    fn new(
        triangles: &Bound<'_, PyAny>,
        bin_width: Option<f64>,
        legendre_side: &str,
        effective: bool,
    ) -> PyResult<Self> {
        let set = triangle_set(triangles, bin_width)?;
        if effective && set.width().is_none() {
            return Err(crate::value_error(
                "effective=True is the effective-triangle shortcut for bins: give bin_width",
            ));
        }
        let side = LegendreSide::by_name(legendre_side).map_err(library_error)?;
        let rules = PlanRules {
            effective,
            ..PlanRules::default()
        };
        let plan = bk::BispectrumPlan::new(set, side, rules).map_err(library_error)?;
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
        let plan = &self.plan;
        let (terms, f) = with_spectrum(
            py,
            linear,
            z,
            z_input,
            cosmology,
            eh,
            f,
            q_par,
            q_perp,
            fog,
            sigma_fog,
            ir,
            |p, settings| plan.terms(p, settings),
        )?;
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
    /// (B, err): (n, 3) arrays of B0, B2, B4 [(Mpc/h)^6] and their quadrature errors; b1, b2, bs in
    /// `bias_convention` (velocileptors' by default; "classpt": bs is b_G2, "fastpt").
    #[pyo3(signature = (b1=1.0, b2=0.0, bs=0.0, c1=0.0, n_bar=None, b_shot=1.0, p_shot=0.0, a_shot=0.0,
        bias_convention=None))]
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
        bias_convention: Option<&str>,
    ) -> PyResult<ValuesAndErrors<'py>> {
        let (params, _) = params(
            b1,
            b2,
            bs,
            c1,
            n_bar,
            b_shot,
            p_shot,
            a_shot,
            bias_convention,
        )?;
        let b = self.terms.multipoles(&params).map_err(library_error)?;
        values_and_errors(py, &b)
    }
}

/// (values, errors) of rows of estimates as (n, N) arrays.
fn values_and_errors<'py, const N: usize>(
    py: Python<'py>,
    b: &[[Estimate; N]],
) -> PyResult<ValuesAndErrors<'py>> {
    let n = b.len();
    let values: Vec<f64> = b.iter().flat_map(|r| r.map(|e| e.value)).collect();
    let errors: Vec<f64> = b.iter().flat_map(|r| r.map(|e| e.error)).collect();
    let shape = |v: Vec<f64>| v.into_pyarray(py).reshape([n, N]);
    Ok((shape(values)?, shape(errors)?))
}

/// The Sugiyama et al. (2019) multipoles planned for (k1, k2) pairs (an (n, 2) array [h/Mpc]):
/// `plan.terms(...)` per linear spectrum, then `terms.multipoles(b1=..., ...)` per parameter step.
#[pyclass(module = "pt_spectra._core", frozen)]
pub struct SugiyamaPlan {
    plan: bk::SugiyamaPlan,
}

#[pymethods]
impl SugiyamaPlan {
    /// What the plan computes, how a new spectrum's terms are computed (`method`: direct or basis)
    /// and its memory estimates in bytes (the plan, one spectrum's terms).
    #[getter]
    fn plan_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        crate::seam::plan_info(py, &self.plan)
    }

    #[new]
    fn new(pairs: &Bound<'_, PyAny>) -> PyResult<Self> {
        let pairs = fixed_rows::<2>(pairs, "pairs", "k1, k2")?;
        let plan = bk::SugiyamaPlan::new(pairs, SugiyamaRules::default()).map_err(library_error)?;
        Ok(Self { plan })
    }

    /// The multipoles' names in the order of the columns: 000 110 202 022 112 220.
    #[classattr]
    fn multipole_names() -> Vec<&'static str> {
        bk::SUGIYAMA_MULTIPOLES.to_vec()
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
    ) -> PyResult<SugiyamaTerms> {
        let plan = &self.plan;
        let (terms, f) = with_spectrum(
            py,
            linear,
            z,
            z_input,
            cosmology,
            eh,
            f,
            q_par,
            q_perp,
            fog,
            sigma_fog,
            ir,
            |p, settings| plan.terms(p, settings),
        )?;
        Ok(SugiyamaTerms { terms, f })
    }
}

/// The Sugiyama terms of one spectrum: `multipoles(...)` returns (B, err), (n, 6) arrays of B000, B110,
/// B202, B022, B112, B220.
#[pyclass(module = "pt_spectra._core", frozen)]
pub struct SugiyamaTerms {
    terms: bk::SugiyamaTerms,
    /// The growth rate used.
    #[pyo3(get)]
    f: f64,
}

#[pymethods]
impl SugiyamaTerms {
    /// (B, err): (n, 6) arrays of B000 B110 B202 B022 B112 B220 [(Mpc/h)^6] and their quadrature
    /// errors; the bias as `BispectrumTerms.multipoles` takes it.
    #[pyo3(signature = (b1=1.0, b2=0.0, bs=0.0, c1=0.0, n_bar=None, b_shot=1.0, p_shot=0.0, a_shot=0.0,
        bias_convention=None))]
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
        bias_convention: Option<&str>,
    ) -> PyResult<ValuesAndErrors<'py>> {
        let (params, _) = params(
            b1,
            b2,
            bs,
            c1,
            n_bar,
            b_shot,
            p_shot,
            a_shot,
            bias_convention,
        )?;
        let b = self.terms.multipoles(&params).map_err(library_error)?;
        values_and_errors(py, &b)
    }
}
