//! `pt.OneLoopMultipolePlan`: the one-loop galaxy multipoles B0, B2, B4 planned for a triangle set, from the
//! multipole tensors ([`pt_spectra::jobs::one_loop_multipole_tensors`], built once and cached), so that a
//! call per spectrum, f and bias costs ~0.07 ms per triangle; over bins the multipole bin tensors
//! ([`pt_spectra::jobs::one_loop_multipole_bin_tensors`]).

use crate::bispectrum::fixed_rows;
use crate::bispectrum_one_loop::{galaxy_bias, rule_of};
use crate::inputs::Inputs;
use crate::{detached, library_error};
use numpy::IntoPyArray;
use pt_spectra::bispectrum::bias_kernels::LoopBias;
use pt_spectra::bispectrum::multipole_basis::MultipoleLoopBasis;
use pt_spectra::bispectrum::multipole_bins::MultipoleBinBasis;
use pt_spectra::bispectrum::one_loop_galaxy::OneLoopGalaxy;
use pt_spectra::bispectrum::TriangleSet;
use pt_spectra::precision::TwoLoopMethod;
use pt_spectra::progress::Silent;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;

/// The one-loop galaxy multipoles B0, B2, B4 in redshift space planned for a set of triangles (points,
/// [h/Mpc]) with the Legendre polynomial on `legendre_side`: the multipole tensors (16 SVD templates, f free;
/// built once on the loop rule, ~190 s per triangle and core at the default rule, cached in `cache_dir`),
/// then a call per linear spectrum, growth rate and bias costs ~0.07 ms per triangle. Where the tensors do
/// not represent the spectrum (projection residual above the basis's limit: 2e-3 for P, 1e-2 for the
/// resummed P_LO with `ir=True`) the call integrates directly and `loop_terms` says so.
///
/// `bin_width` [h/Mpc]: bins of three shells of that width centred on each triangle instead (the bin
/// averages of `pt.one_loop_bispectrum(..., bin_width=...)`: each bin's effective triangle from the multipole
/// tensors plus the bin average's departure from it from folded tensors, `k1_eff k2_eff k3_eff` in the
/// result; ~0.13 ms per bin).
#[pyclass(module = "pt_spectra._core", frozen)]
pub struct OneLoopMultipolePlan {
    tensors: Tensors,
}

/// The plan's tensors: of triangles, or of bins.
enum Tensors {
    Points(Arc<MultipoleLoopBasis>),
    Bins(Arc<MultipoleBinBasis>),
}

#[pymethods]
impl OneLoopMultipolePlan {
    #[new]
    #[pyo3(signature = (triangles, legendre_side="largest", q_min=1e-4, q_max=10.0, radial=12, mu=32, phi=24,
        cache_dir=None, bin_width=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        triangles: &Bound<'_, PyAny>,
        legendre_side: &str,
        q_min: f64,
        q_max: f64,
        radial: usize,
        mu: usize,
        phi: usize,
        cache_dir: Option<std::path::PathBuf>,
        bin_width: Option<f64>,
    ) -> PyResult<Self> {
        let rows = fixed_rows::<3>(triangles, "triangles", "k1, k2, k3")?;
        let rule = rule_of(q_min, q_max, radial, mu, phi);
        let side =
            pt_spectra::bispectrum::LegendreSide::by_name(legendre_side).map_err(library_error)?;
        let store = crate::Store::new(cache_dir);
        let set = bin_width
            .map(|width| TriangleSet::shells(rows.clone(), width))
            .transpose()
            .map_err(library_error)?;
        let (tensors, _) = detached(py, || match &set {
            None => pt_spectra::jobs::one_loop_multipole_tensors(
                &rows,
                side,
                &rule,
                store.get(),
                &Silent,
            )
            .map(Tensors::Points),
            Some(set) => pt_spectra::jobs::one_loop_multipole_bin_tensors(
                set,
                side,
                &rule,
                TwoLoopMethod::Basis,
                store.get(),
                &Silent,
            )
            .map(|t| Tensors::Bins(t.expect("method basis reads or builds"))),
        })?;
        Ok(Self { tensors })
    }

    /// The number of triangles (or bins).
    fn __len__(&self) -> usize {
        self.triangles().len()
    }

    /// B0, B2, B4 at every triangle for the linear spectrum of the inputs (all matter, as
    /// `pt.one_loop_bispectrum`), growth rate `f` (default f(z)) and bias (`b1`, `b2`, `bs` in
    /// `bias_convention`, `b_gamma3`, `loop_bias`; matter without one), as a dict of arrays: k1 k2 k3, per
    /// ℓ `B{ℓ}_tree B{ℓ}_222 B{ℓ}_321_I B{ℓ}_321_II B{ℓ}_411 B{ℓ}` and their `err_` [(Mpc/h)^6], `f`, and
    /// `loop_terms` (tensors with their residual, or direct and why). `ir=True`: the BAO resummed (off by
    /// default here: the tensors represent the resummed spectrum's loops less often).
    #[pyo3(signature = (linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None, f=None, b1=None, b2=0.0,
        bs=0.0, b_gamma3=0.0, bias_convention=None, loop_bias=None, ir=false))]
    #[allow(clippy::too_many_arguments)]
    fn __call__<'py>(
        &self,
        py: Python<'py>,
        linear: Option<&Bound<'py, PyAny>>,
        z: f64,
        z_input: f64,
        cosmology: Option<&Bound<'py, PyAny>>,
        eh: Option<&str>,
        f: Option<f64>,
        b1: Option<f64>,
        b2: f64,
        bs: f64,
        b_gamma3: f64,
        bias_convention: Option<&str>,
        loop_bias: Option<std::collections::BTreeMap<String, f64>>,
        ir: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let bias = galaxy_bias(py, b1, [b2, bs, b_gamma3], bias_convention, loop_bias)?
            .unwrap_or_else(LoopBias::matter);
        let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
        let (((rows, effective, source), f), _) = detached(py, || {
            let prepared = inputs.prepare(&[])?;
            let f = f.unwrap_or(prepared.growth_rate);
            let ir = ir
                .then(|| pt_spectra::jobs::one_loop_ir_inputs(&prepared))
                .transpose()?;
            let p = &prepared.spectrum;
            let out = match &self.tensors {
                Tensors::Points(t) => {
                    let (rows, source) =
                        pt_spectra::jobs::multipole_plan_rows(t, p, &bias, f, ir.as_ref())?;
                    (rows, None, source)
                }
                Tensors::Bins(t) => {
                    let main = t.effective();
                    let (binned, source) = pt_spectra::jobs::binned_plan_multipoles(
                        Some(t),
                        false,
                        p,
                        ir.as_ref(),
                        t.set(),
                        f,
                        main.side(),
                        main.rule(),
                        &|_, _| {},
                    )?;
                    (binned.evaluate(&bias)?, Some(binned.effective), source)
                }
            };
            Ok((out, f))
        })?;
        let out = PyDict::new(py);
        let columns =
            |out: &Bound<'py, PyDict>, names: [&str; 3], k: &[[f64; 3]]| -> PyResult<()> {
                for (i, name) in names.iter().enumerate() {
                    let v: Vec<f64> = k.iter().map(|k| k[i]).collect();
                    out.set_item(*name, v.into_pyarray(py))?;
                }
                Ok(())
            };
        columns(&out, ["k1", "k2", "k3"], self.triangles())?;
        if let Some(k) = &effective {
            columns(&out, ["k1_eff", "k2_eff", "k3_eff"], k)?;
        }
        let terms = |b: &OneLoopGalaxy| [b.tree, b.b222, b.b321_i, b.b321_ii, b.b411, b.total()];
        for (ell, l) in [0, 2, 4].iter().enumerate() {
            for (j, name) in ["_tree", "_222", "_321_I", "_321_II", "_411", ""]
                .iter()
                .enumerate()
            {
                let v: Vec<f64> = rows.iter().map(|b| terms(&b[ell])[j].value).collect();
                let e: Vec<f64> = rows.iter().map(|b| terms(&b[ell])[j].error).collect();
                out.set_item(format!("B{l}{name}"), v.into_pyarray(py))?;
                out.set_item(format!("err_B{l}{name}"), e.into_pyarray(py))?;
            }
        }
        out.set_item("f", f)?;
        let loop_terms = match self.tensors {
            Tensors::Points(_) => pt_spectra::jobs::describe_multipole_source(&source),
            Tensors::Bins(_) => pt_spectra::jobs::describe_bin_source(&source),
        };
        out.set_item("loop_terms", loop_terms)?;
        Ok(out)
    }
}

impl OneLoopMultipolePlan {
    /// The triangles, or the bins' centres [h/Mpc].
    fn triangles(&self) -> &[[f64; 3]] {
        match &self.tensors {
            Tensors::Points(t) => t.triangles(),
            Tensors::Bins(t) => t.set().triangles(),
        }
    }
}
