//! `pt.one_loop_bispectrum`, `pt.OneLoopBispectrumPlan`: the one-loop matter bispectrum in real
//! space ([`pt_spectra::bispectrum::one_loop`], its basis tensors
//! [`pt_spectra::bispectrum::one_loop_basis`]) from Python.

use crate::bispectrum::fixed_rows;
use crate::inputs::Inputs;
use crate::tables::Table;
use crate::{detached, library_error};
use numpy::IntoPyArray;
use pt_spectra::bispectrum::one_loop::{OneLoopMatter, OneLoopRule};
use pt_spectra::bispectrum::one_loop_basis::{BispectrumLoopSource, OneLoopMatterPlan};
use pt_spectra::precision::{Precision, TwoLoopMethod};
use pt_spectra::progress::Silent;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The one-loop matter bispectrum in real space (SPT) at the triangles (an (n, 3) array of k1 k2 k3
/// [h/Mpc], points, not bins) as a `Table` with columns k1 k2 k3 B_tree B222 B321_I B321_II B411
/// B_1loop and their `err_` columns [(Mpc/h)^6], for the all-matter linear spectrum of the inputs
/// (as `pt.bispectrum`). The loop integrals run over q_min <= |q| <= q_max [h/Mpc] with `radial`
/// x `mu` x `phi` nodes per panel; each error is the difference from half the nodes. `two_loop`
/// says how the loop terms are computed, as everywhere: "basis" (tensors built once per triangle
/// set and rule, ~0.7 s per triangle and core, cached in `cache_dir`; then ~10 us per triangle;
/// their projection error is in the errors), "direct" (~0.5 s per triangle), "auto" (the tensors if
/// cached, else direct). The header says which was used (its line `loop terms: ...`). With a bias
/// (`b1`, `b2`, `bs` in `bias_convention`, CLASS-PT's `b_gamma3`, `loop_bias` a dict of fourth-order
/// coefficients by name), the galaxy bispectrum ([`pt_spectra::jobs::one_loop_galaxy_table`]). With
/// `multipoles=True` the multipoles B0, B2, B4 in redshift space at `f` (default f(z)), the Legendre
/// polynomial on `legendre_side` ([`pt_spectra::jobs::one_loop_galaxy_multipoles_table`]; matter without a
/// bias; with `bin_width` [h/Mpc] averaged over the bins of that width centred on the triangles: the
/// effective triangle plus a coarse-rule correction, [`pt_spectra::jobs::one_loop_galaxy_binned_multipoles_table`]). `ir`:
/// the IR resummation of the BAO ([`pt_spectra::bispectrum::one_loop_ir`]) of the galaxy
/// bispectrum and the multipoles, on unless False (None: on there; the matter tables without a bias are
/// plain SPT, and `ir=True` there is refused).
#[pyfunction]
#[pyo3(signature = (triangles, linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None,
    q_min=1e-4, q_max=10.0, radial=12, mu=32, phi=24,
    two_loop=pt_spectra::jobs::defaults::TWO_LOOP, cache_dir=None, mu1=None, phi_los=0.0, f=None,
    b1=None, b2=0.0, bs=0.0, b_gamma3=0.0, bias_convention=None, loop_bias=None, multipoles=false,
    legendre_side="largest", ir=None, bin_width=None))]
#[allow(clippy::too_many_arguments)]
pub fn one_loop_bispectrum(
    py: Python<'_>,
    triangles: &Bound<'_, PyAny>,
    linear: Option<&Bound<'_, PyAny>>,
    z: f64,
    z_input: f64,
    cosmology: Option<&Bound<'_, PyAny>>,
    eh: Option<&str>,
    q_min: f64,
    q_max: f64,
    radial: usize,
    mu: usize,
    phi: usize,
    two_loop: &str,
    cache_dir: Option<std::path::PathBuf>,
    mu1: Option<f64>,
    phi_los: f64,
    f: Option<f64>,
    b1: Option<f64>,
    b2: f64,
    bs: f64,
    b_gamma3: f64,
    bias_convention: Option<&str>,
    loop_bias: Option<std::collections::BTreeMap<String, f64>>,
    multipoles: bool,
    legendre_side: &str,
    ir: Option<bool>,
    bin_width: Option<f64>,
) -> PyResult<Table> {
    let rows = fixed_rows::<3>(triangles, "triangles", "k1, k2, k3")?;
    let method: TwoLoopMethod = two_loop.parse().map_err(library_error)?;
    let bias = galaxy_bias(py, b1, [b2, bs, b_gamma3], bias_convention, loop_bias)?;
    let galaxy = bias.is_some();
    let store = crate::Store::new(cache_dir);
    let rule = rule_of(q_min, q_max, radial, mu, phi);
    let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
    let side =
        pt_spectra::bispectrum::LegendreSide::by_name(legendre_side).map_err(library_error)?;
    if ir == Some(true) && !galaxy && !multipoles {
        return Err(crate::value_error(
            "ir=True: the one-loop matter tables (no bias, no multipoles) are plain SPT; the IR resummation is \
             the galaxy bispectrum's (give b1=1 for matter through the galaxy code) and the multipoles'",
        ));
    }
    let ir = ir.unwrap_or(true);
    if multipoles && mu1.is_some() {
        return Err(crate::value_error(
            "multipoles=True averages over the orientations (no mu1)",
        ));
    }
    if !multipoles && legendre_side != "largest" {
        return Err(crate::value_error(
            "legendre_side is the multipoles' (multipoles=True)",
        ));
    }
    if bin_width.is_some() && !multipoles {
        return Err(crate::value_error(
            "bin_width: the one-loop bispectrum's bin averages are the multipoles' (multipoles=True)",
        ));
    }
    if multipoles {
        let bias = bias.unwrap_or_else(pt_spectra::bispectrum::bias_kernels::LoopBias::matter);
        // over bins of `bin_width` around each triangle, or at the triangles
        let set = bin_width
            .map(|width| pt_spectra::bispectrum::TriangleSet::shells(rows.clone(), width))
            .transpose()
            .map_err(library_error)?;
        let ((prepared, table), seconds) = detached(py, || {
            let prepared = inputs.prepare(&[])?;
            let table = match &set {
                Some(set) => pt_spectra::jobs::one_loop_galaxy_binned_multipoles_table(
                    &prepared,
                    set,
                    &bias,
                    f,
                    side,
                    ir,
                    &rule,
                    (method, store.get()),
                    &Silent,
                )?,
                None => pt_spectra::jobs::one_loop_galaxy_multipoles_table(
                    &prepared,
                    &rows,
                    &bias,
                    f,
                    side,
                    ir,
                    &rule,
                    (method, store.get()),
                    &Silent,
                )?,
            };
            Ok((prepared, table))
        })?;
        let title = if set.is_some() {
            "bispectrum one-loop galaxy multipoles over bins"
        } else {
            "bispectrum one-loop galaxy multipoles"
        };
        return Table::new(py, table, &prepared, &Precision::default(), title, seconds);
    }
    if mu1.is_none() && f.is_some() {
        return Err(crate::value_error(
            "f is the growth rate of the redshift-space one-loop bispectrum: give mu1 too",
        ));
    }
    if mu1.is_some() && method == TwoLoopMethod::Basis {
        return Err(crate::value_error(
            "two_loop=\"basis\": the one-loop bispectrum's tensors are built for real space only",
        ));
    }
    let ((prepared, table), seconds) = detached(py, || {
        let prepared = inputs.prepare(&[])?;
        if let Some(bias) = &bias {
            let redshift = mu1.map(|mu1| {
                let orientation =
                    pt_spectra::bispectrum::one_loop_rsd::Orientation { mu1, phi: phi_los };
                (f, orientation)
            });
            let table = pt_spectra::jobs::one_loop_galaxy_table(
                &prepared,
                &rows,
                bias,
                redshift,
                ir,
                &rule,
                method,
                store.get(),
                &Silent,
            )?;
            return Ok((prepared, table));
        }
        if let Some(mu1) = mu1 {
            let orientation =
                pt_spectra::bispectrum::one_loop_rsd::Orientation { mu1, phi: phi_los };
            let table = pt_spectra::jobs::one_loop_redshift_table(
                &prepared,
                &rows,
                f,
                orientation,
                &rule,
                &Silent,
            )?;
            return Ok((prepared, table));
        }
        let table = pt_spectra::jobs::one_loop_bispectrum_table(
            &prepared,
            &rows,
            &rule,
            method,
            store.get(),
            &Silent,
        )?;
        Ok((prepared, table))
    })?;
    Table::new(
        py,
        table,
        &prepared,
        &Precision::default(),
        if bias.is_some() {
            "bispectrum one-loop galaxy"
        } else {
            "bispectrum one-loop matter"
        },
        seconds,
    )
}

/// The one-loop bias of the keyword arguments (`b1`, then `b2`, `bs` in `bias_convention` and CLASS-PT's
/// `b_gamma3`, `loop_bias` the fourth-order coefficients by name), `None` if none is given (matter).
pub(crate) fn galaxy_bias(
    py: Python<'_>,
    b1: Option<f64>,
    [b2, bs, b_gamma3]: [f64; 3],
    bias_convention: Option<&str>,
    loop_bias: Option<std::collections::BTreeMap<String, f64>>,
) -> PyResult<Option<pt_spectra::bispectrum::bias_kernels::LoopBias>> {
    let galaxy = b1.is_some()
        || b2 != 0.0
        || bs != 0.0
        || b_gamma3 != 0.0
        || bias_convention.is_some()
        || loop_bias.is_some();
    if !galaxy {
        return Ok(None);
    }
    let convention = crate::bias::convention(py, bias_convention, None, None, None)?;
    let given = [b1.unwrap_or(1.0), b2, bs, 0.0];
    let bias = pt_spectra::bias::BiasParams::from_convention(convention, given);
    let overrides: Vec<(String, f64)> = loop_bias.unwrap_or_default().into_iter().collect();
    Ok(Some(
        pt_spectra::jobs::loop_bias(&bias, b_gamma3, &overrides).map_err(library_error)?,
    ))
}

/// The rule of the keyword arguments (checked where it is used).
pub(crate) fn rule_of(q_min: f64, q_max: f64, radial: usize, mu: usize, phi: usize) -> OneLoopRule {
    OneLoopRule {
        radial,
        mu,
        phi,
        q_min,
        q_max,
    }
}

/// A one-loop matter bispectrum planned for a set of triangles (points): the plan and, with
/// `two_loop="basis"`, its basis tensors (built once, ~0.7 s per triangle and core, cached in
/// `cache_dir`), so that a call per linear spectrum costs ~10 us per triangle.
#[pyclass(module = "pt_spectra._core", frozen)]
pub struct OneLoopBispectrumPlan {
    plan: OneLoopMatterPlan,
    uncached: bool,
}

#[pymethods]
impl OneLoopBispectrumPlan {
    /// What the plan computes, how a new spectrum's terms are computed (`method`: direct or basis)
    /// and its memory estimates in bytes (the plan, one spectrum's terms).
    #[getter]
    fn plan_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        crate::seam::plan_info(py, &self.plan)
    }

    #[new]
    #[pyo3(signature = (triangles, q_min=1e-4, q_max=10.0, radial=12, mu=32, phi=24,
        two_loop="basis", cache_dir=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        triangles: &Bound<'_, PyAny>,
        q_min: f64,
        q_max: f64,
        radial: usize,
        mu: usize,
        phi: usize,
        two_loop: &str,
        cache_dir: Option<std::path::PathBuf>,
    ) -> PyResult<Self> {
        let rows = fixed_rows::<3>(triangles, "triangles", "k1, k2, k3")?;
        let rule = rule_of(q_min, q_max, radial, mu, phi);
        let method: TwoLoopMethod = two_loop.parse().map_err(library_error)?;
        let store = crate::Store::new(cache_dir);
        let ((plan, uncached), _) = detached(py, || {
            pt_spectra::jobs::one_loop_bispectrum_plan(&rows, &rule, method, store.get(), &Silent)
        })?;
        Ok(Self { plan, uncached })
    }

    /// The terms at every triangle for the linear spectrum of the inputs (as `pt.bispectrum`: all
    /// matter), as a dict of arrays: k1 k2 k3, B_tree B222 B321_I B321_II B411 B_1loop and their
    /// err_ [(Mpc/h)^6], and `loop_terms` (how they were computed: basis, or direct and why).
    #[pyo3(signature = (linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None))]
    fn __call__<'py>(
        &self,
        py: Python<'py>,
        linear: Option<&Bound<'py, PyAny>>,
        z: f64,
        z_input: f64,
        cosmology: Option<&Bound<'py, PyAny>>,
        eh: Option<&str>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
        let ((rows, mut source), _) = detached(py, || {
            let prepared = inputs.prepare(&[])?;
            self.plan.evaluate(&prepared.spectrum)
        })?;
        if self.uncached && source == BispectrumLoopSource::Direct {
            source = BispectrumLoopSource::DirectUncached;
        }
        let out = PyDict::new(py);
        for (i, name) in ["k1", "k2", "k3"].iter().enumerate() {
            let v: Vec<f64> = rows.iter().map(|b| b.k[i]).collect();
            out.set_item(*name, v.into_pyarray(py))?;
        }
        let terms = |b: &OneLoopMatter| [b.tree, b.b222, b.b321_i, b.b321_ii, b.b411, b.total()];
        let names = ["B_tree", "B222", "B321_I", "B321_II", "B411", "B_1loop"];
        for (j, name) in names.iter().enumerate() {
            let v: Vec<f64> = rows.iter().map(|b| terms(b)[j].value).collect();
            let e: Vec<f64> = rows.iter().map(|b| terms(b)[j].error).collect();
            out.set_item(*name, v.into_pyarray(py))?;
            out.set_item(format!("err_{name}"), e.into_pyarray(py))?;
        }
        out.set_item("loop_terms", source.describe())?;
        Ok(out)
    }
}
