//! `pt_spectra.LinearEmulator`: the linear spectra of a cosmology from its parameters
//! ([`pt_spectra::emulator`]).

use crate::{inputs, value_error};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The linear-spectrum emulator (CAMB-trained; see the documentation's "linear-spectrum emulator").
///
/// ``LinearEmulator()`` parses the embedded file once; ``spectra(cosmology, z)`` then costs ~0.1 ms:
/// a dict with ``k`` [h/Mpc], ``P_m`` and ``P_cb`` [(Mpc/h)^3] (all matter; cold dark matter +
/// baryons), ``f_cb`` (the scale-dependent growth rate), ``err_P_m``, ``err_P_cb`` (relative errors
/// per k), ``sigma8`` (of P_m at z), ``A_s``, ``neutrinos`` (the setting emulated: "three degenerate" or
/// "one massive") and ``worst_error`` (the measured worst |Δ ln P| of P_cb and P_m over the prior).
/// ``cosmology`` is a preset name, an ini path or a dict of CLASS/CAMB keys (``m_ncdm`` with ``N_ur``,
/// or ``mnu``, for massive neutrinos, each in its own code's convention: CAMB's ``mnu`` alone is one
/// massive species; ``w0_fld``, ``wa_fld``); a dict key that sets nothing raises ValueError naming it.
/// A parameter outside the prior (``prior``), or a neutrino setting that is not emulated, raises
/// ValueError naming it.
#[pyclass(name = "LinearEmulator", module = "pt_spectra._core")]
pub struct LinearEmulator {
    inner: pt_spectra::emulator::LinearEmulator,
}

#[pymethods]
impl LinearEmulator {
    #[new]
    fn new() -> PyResult<Self> {
        let inner = pt_spectra::emulator::LinearEmulator::embedded().map_err(value_error)?;
        Ok(Self { inner })
    }

    /// The spectra of `cosmology` at redshift `z` (see the class).
    #[pyo3(signature = (cosmology, z=0.0))]
    fn spectra<'py>(
        &self,
        py: Python<'py>,
        cosmology: &Bound<'py, PyAny>,
        z: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let c = inputs::cosmology_of(Some(cosmology))?;
        let s = self.inner.spectra(&c, z).map_err(value_error)?;
        let out = PyDict::new(py);
        out.set_item("k", s.k.into_pyarray(py))?;
        out.set_item("P_m", s.p_m.into_pyarray(py))?;
        out.set_item("P_cb", s.p_cb.into_pyarray(py))?;
        out.set_item("f_cb", s.f_cb.into_pyarray(py))?;
        out.set_item("err_P_m", s.error_m.into_pyarray(py))?;
        out.set_item("err_P_cb", s.error_cb.into_pyarray(py))?;
        out.set_item("sigma8", s.sigma8)?;
        out.set_item("A_s", s.a_s)?;
        out.set_item("neutrinos", s.neutrinos.name())?;
        out.set_item("worst_error", (s.worst[0], s.worst[1]))?;
        Ok(out)
    }

    /// The scale-dependent growth of cold dark matter + baryons at `z`: a dict with ``k`` [h/Mpc],
    /// ``D_cb`` (= sqrt(P_cb(k, z)/P_cb(k, 0)), 1 at z = 0) and ``f_cb``.
    #[pyo3(signature = (cosmology, z))]
    fn growth_cb<'py>(
        &self,
        py: Python<'py>,
        cosmology: &Bound<'py, PyAny>,
        z: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let c = inputs::cosmology_of(Some(cosmology))?;
        let g = self.inner.growth_cb(&c, z).map_err(value_error)?;
        let out = PyDict::new(py);
        out.set_item("k", g.k.into_pyarray(py))?;
        out.set_item("D_cb", g.d_cb.into_pyarray(py))?;
        out.set_item("f_cb", g.f_cb.into_pyarray(py))?;
        Ok(out)
    }

    /// {name: (min, max)} of the prior (Omega_b, Omega_m, h, m_nu [eV], w0, wa, and the tested range
    /// of ln10^{10}A_s and n_s, in which the emulator is exact).
    #[getter]
    fn prior<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for p in self.inner.prior() {
            out.set_item(p.name, (p.min, p.max))?;
        }
        Ok(out)
    }

    /// The redshift range (z_min, z_max).
    #[getter]
    fn z_range(&self) -> (f64, f64) {
        self.inner.z_range()
    }
}
