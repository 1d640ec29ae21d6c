//! `pt_spectra._core`: the Python face of the pt-spectra library entry points.
//!
//! Each function converts its arguments at the edge (numpy arrays, paths, names, dicts), calls the same
//! library function as the command line (`pt_spectra::jobs`), with the GIL released, and returns a
//! [`Table`] whose columns have the names the command line prints. Errors of the library become
//! `ValueError` with its message. The pure-Python package `pt_spectra` wraps these (warnings, docs).

use numpy::{IntoPyArray, PyArray1};
use pt_spectra::bias::BiasParams;
use pt_spectra::cosmology::TransferKind;
use pt_spectra::fit::{ContourGrid, MultipoleData, Parameter};
use pt_spectra::jobs::{self, BiasOutput, FitRequest, RsdRequest};
use pt_spectra::linear::LogGrid;
use pt_spectra::loops::bias::BiasPlan;
use pt_spectra::precision::Precision;
use pt_spectra::progress::Silent;
use pt_spectra::real::{Counterterms, RealPlan as LibRealPlan, RealSelection};
use pt_spectra::rsd::{RsdModel, RsdPlan as LibRsdPlan, Sigma0};
use pt_spectra::store::TableStore;
use pyo3::exceptions::{PyKeyError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::OnceLock;

mod batch;
mod bias;
mod bispectrum;
mod bispectrum_multipole_plan;
mod bispectrum_one_loop;
mod emulator;
mod ept;
mod forecast;
mod halo;
mod inputs;
mod joint;
mod kernel;
mod options;
mod pipeline;
mod redshift;
mod seam;
mod survey;
mod tables;
mod two_loop_rsd;

use inputs::Inputs;
pub(crate) use inputs::{floats, k_array};

pub use tables::Table;

/// A library error as a Python `ValueError` with the library's message.
pub(crate) fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// The table store of calls without `cache_dir`: the conventional cache directory
/// ($PT_SPECTRA_CACHE, $XDG_CACHE_HOME/pt-spectra or ~/.cache/pt-spectra), loaded tables kept for the
/// life of the process.
fn default_store() -> &'static TableStore {
    static STORE: OnceLock<TableStore> = OnceLock::new();
    STORE.get_or_init(TableStore::from_env)
}

/// The store of `cache_dir`, or the default one.
pub(crate) enum Store {
    Default,
    Own(TableStore),
}

impl Store {
    pub(crate) fn new(cache_dir: Option<PathBuf>) -> Self {
        match cache_dir {
            Some(dir) => Store::Own(TableStore::new(dir)),
            None => Store::Default,
        }
    }

    pub(crate) fn get(&self) -> &TableStore {
        match self {
            Store::Default => default_store(),
            Store::Own(s) => s,
        }
    }
}

/// The keyword arguments `kwargs` as (name, number) pairs; a value that is not a number is a
/// `ValueError` naming it.
pub(crate) fn number_kwargs(
    kwargs: Option<&Bound<'_, pyo3::types::PyDict>>,
) -> PyResult<Vec<(String, f64)>> {
    let Some(kw) = kwargs else {
        return Ok(Vec::new());
    };
    kw.iter()
        .map(|(key, value)| {
            let name: String = key.extract()?;
            let v: f64 = value
                .extract()
                .map_err(|_| PyValueError::new_err(format!("{name}: expected a number")))?;
            Ok((name, v))
        })
        .collect()
}

/// The precision preset `name`, with the q range, 2-loop tolerance and 2-loop method
/// (`auto`, `basis`, `direct`) if given.
pub(crate) fn precision(
    name: &str,
    q_range: Option<(f64, f64)>,
    two_loop_tolerance: Option<f64>,
    two_loop: Option<&str>,
) -> PyResult<Precision> {
    let mut p = Precision::preset(name).map_err(value_error)?;
    p.max_memory = pt_spectra::memory::env_max_memory().map_err(value_error)?;
    if let Some(method) = two_loop {
        p.two_loop = method.parse().map_err(value_error)?;
    }
    if let Some((lo, hi)) = q_range {
        p = p.with_q_range(lo, hi).map_err(value_error)?;
    }
    if let Some(t) = two_loop_tolerance {
        p.two_loop_tolerance = t;
        p.validate().map_err(value_error)?;
    }
    Ok(p)
}

/// The output k grid: `k` if given, else `nk` log-spaced values in [k_min, k_max].
fn k_grid(k: Option<&Bound<'_, PyAny>>, k_min: f64, k_max: f64, nk: usize) -> PyResult<Vec<f64>> {
    match k {
        Some(k) => Ok(k_array(k, "k")?.into_vec()),
        None => Ok(LogGrid::new(k_min, k_max, nk)
            .map_err(value_error)?
            .points()),
    }
}

/// Runs `f` with the GIL released.
pub(crate) fn detached<T: Send>(
    py: Python<'_>,
    f: impl FnOnce() -> pt_spectra::error::Result<T> + Send,
) -> PyResult<(T, f64)> {
    let (result, seconds) = py.detach(|| {
        let start = std::time::Instant::now();
        let result = f();
        (result, start.elapsed().as_secs_f64())
    });
    Ok((result.map_err(library_error)?, seconds))
}

/// A library error as a Python exception: `MemoryError` for a memory limit or a failed allocation
/// (a plan or batch refused before it allocates), `ValueError` for everything else.
pub(crate) fn library_error(e: pt_spectra::error::Error) -> PyErr {
    match e {
        pt_spectra::error::Error::MemoryLimit { .. } => {
            pyo3::exceptions::PyMemoryError::new_err(e.to_string())
        }
        e => value_error(e),
    }
}

/// A real-space model prepared for one k grid (cosmology-independent work done once); calling it
/// evaluates any linear spectrum.
#[pyclass(module = "pt_spectra._core", frozen)]
struct RealPlan {
    plan: LibRealPlan,
    pub(crate) selection: RealSelection,
    /// The bias terms' plan, built at the first call that asks for them.
    bias_plan: OnceLock<BiasPlan>,
}

#[pymethods]
impl RealPlan {
    /// What the plan computes, how a new spectrum's terms are computed (`method`: direct or basis)
    /// and its memory estimates in bytes (the plan, one spectrum's terms).
    #[getter]
    fn plan_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        crate::seam::plan_info(py, &self.plan)
    }

    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (k, model=pt_spectra::jobs::defaults::REAL_MODEL, precision=pt_spectra::jobs::defaults::PRECISION, q_range=None, two_loop_tolerance=None, cache_dir=None, two_loop=pt_spectra::jobs::defaults::TWO_LOOP))]
    fn new(
        py: Python<'_>,
        k: &Bound<'_, PyAny>,
        model: &str,
        precision: &str,
        q_range: Option<(f64, f64)>,
        two_loop_tolerance: Option<f64>,
        cache_dir: Option<PathBuf>,
        two_loop: &str,
    ) -> PyResult<Self> {
        let k = crate::k_array(k, "k")?;
        let selection: RealSelection = model.parse().map_err(value_error)?;
        let precision = self::precision(precision, q_range, two_loop_tolerance, Some(two_loop))?;
        let store = Store::new(cache_dir);
        let (plan, _) = detached(py, || {
            LibRealPlan::for_selection(&k, selection, &precision, store.get(), &Silent)
        })?;
        Ok(Self {
            plan,
            selection,
            bias_plan: OnceLock::new(),
        })
    }

    /// The k grid [h/Mpc].
    #[getter]
    fn k<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.plan.k().to_vec().into_pyarray(py)
    }

    /// The spectra of `linear` (None: the embedded gm2012 spectrum; a path; or (k, P)) at z, with the
    /// EFT counterterm c_s² = `cs2` [(Mpc/h)²], and the galaxy bias terms and spectra if asked for.
    #[pyo3(signature = (linear=None, z=0.0, z_input=0.0, cosmology=None, terms=false, eh=None, cs2=0.0,
        bias_terms=false, bias=None, b2=0.0, bs=0.0, b3=0.0, ct=None, bias_convention=None))]
    #[allow(clippy::too_many_arguments)]
    fn __call__(
        &self,
        py: Python<'_>,
        linear: Option<&Bound<'_, PyAny>>,
        z: f64,
        z_input: f64,
        cosmology: Option<&Bound<'_, PyAny>>,
        terms: bool,
        eh: Option<&str>,
        cs2: f64,
        bias_terms: bool,
        bias: Option<f64>,
        b2: f64,
        bs: f64,
        b3: f64,
        ct: Option<std::collections::BTreeMap<String, f64>>,
        bias_convention: Option<&str>,
    ) -> PyResult<Table> {
        let given = bias::convention(py, bias_convention, Some(bs), Some(b3), Some("real"))?;
        let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
        let assignments = ct
            .iter()
            .flatten()
            .map(|(name, value)| format!("{name}={value}"));
        let counterterms = Counterterms::from_assignments(assignments)
            .and_then(|c| c.with_cs2(cs2))
            .map_err(value_error)?;
        let output = BiasOutput {
            terms: bias_terms,
            galaxy: bias.map(|b1| BiasParams::from_convention(given, [b1, b2, bs, b3])),
            given,
        };
        if bias.is_none() && (b2 != 0.0 || bs != 0.0 || b3 != 0.0) {
            return Err(PyValueError::new_err(
                "b2, bs and b3 need bias (b1): the galaxy spectra are those of the bias expansion",
            ));
        }
        let ((table, prepared), seconds) = detached(py, || {
            output.validate(self.selection)?;
            if output.any() && self.bias_plan.get().is_none() {
                let plan = BiasPlan::new(self.plan.k(), self.plan.precision())?;
                let _ = self.bias_plan.set(plan);
            }
            let prepared = inputs.prepare(self.plan.k())?;
            let table = jobs::real_table_with_bias(
                &self.plan,
                self.bias_plan.get(),
                self.selection,
                &prepared,
                terms,
                &counterterms,
                output,
                &Silent,
            )?;
            Ok((table, prepared))
        })?;
        let mut table = Table::new(
            py,
            table,
            &prepared,
            self.plan.precision(),
            &self.selection.plan_model().to_string(),
            seconds,
        )?;
        if let RealSelection::One(model) = self.selection {
            if model.is_eft() && counterterms.is_zero() {
                table.warn(format!(
                    "every counterterm of {model} is 0 (it is then 2-loop SPT): set them with ct={{...}} \
                     or fit them with the T_ columns of terms=True"
                ));
            }
        }
        Ok(table)
    }
}

/// `pt-spectra real` as a function: see the Python wrapper's docstring.
#[pyfunction]
#[pyo3(signature = (model=pt_spectra::jobs::defaults::REAL_MODEL, k=None, linear=None, z=0.0, z_input=0.0, cosmology=None, terms=false,
    precision=pt_spectra::jobs::defaults::PRECISION, q_range=None, two_loop_tolerance=None, cache_dir=None, eh=None, k_min=1e-3,
    k_max=1.0, nk=100, cs2=0.0, two_loop=pt_spectra::jobs::defaults::TWO_LOOP, bias_terms=false, bias=None, b2=0.0, bs=0.0, b3=0.0,
    ct=None, bias_convention=None))]
#[allow(clippy::too_many_arguments)]
fn real(
    py: Python<'_>,
    model: &str,
    k: Option<&Bound<'_, PyAny>>,
    linear: Option<&Bound<'_, PyAny>>,
    z: f64,
    z_input: f64,
    cosmology: Option<&Bound<'_, PyAny>>,
    terms: bool,
    precision: &str,
    q_range: Option<(f64, f64)>,
    two_loop_tolerance: Option<f64>,
    cache_dir: Option<PathBuf>,
    eh: Option<&str>,
    k_min: f64,
    k_max: f64,
    nk: usize,
    cs2: f64,
    two_loop: &str,
    bias_terms: bool,
    bias: Option<f64>,
    b2: f64,
    bs: f64,
    b3: f64,
    ct: Option<std::collections::BTreeMap<String, f64>>,
    bias_convention: Option<&str>,
) -> PyResult<Table> {
    let k = k_grid(k, k_min, k_max, nk)?;
    let plan = RealPlan::new(
        py,
        &k.clone().into_pyarray(py).into_any(),
        model,
        precision,
        q_range,
        two_loop_tolerance,
        cache_dir,
        two_loop,
    )?;
    plan.__call__(
        py,
        linear,
        z,
        z_input,
        cosmology,
        terms,
        eh,
        cs2,
        bias_terms,
        bias,
        b2,
        bs,
        b3,
        ct,
        bias_convention,
    )
}

/// A covariance matrix from a 2-D numpy array or nested lists.
pub(crate) fn covariance_rows(c: &Bound<'_, PyAny>) -> PyResult<Vec<Vec<f64>>> {
    matrix_rows(c, "covariance: expected a square 2-D array")
}

/// The rows of a 2-D numpy array or nested lists (`message` if it is neither).
pub(crate) fn matrix_rows(c: &Bound<'_, PyAny>, message: &str) -> PyResult<Vec<Vec<f64>>> {
    match c.extract::<numpy::PyReadonlyArray2<'_, f64>>() {
        Ok(a) => Ok(a
            .as_array()
            .rows()
            .into_iter()
            .map(|r| r.to_vec())
            .collect()),
        Err(_) => c
            .extract()
            .map_err(|_| PyValueError::new_err(message.to_string())),
    }
}

/// Measured multipoles from a path (with columns) or a dict {"k", "P0", "s0", "P2", "s2", …}, and the
/// layout they were read with (for a covariance over all the file's multipoles).
pub(crate) fn data(
    data: &Bound<'_, PyAny>,
    data_columns: Option<Vec<usize>>,
    data_ells: &[usize],
    ells: &[usize],
) -> PyResult<(MultipoleData, String, pt_spectra::fit::DataLayout)> {
    if let Ok(dict) = data.cast::<PyDict>() {
        let get = |name: &str| -> PyResult<Vec<f64>> {
            let v = dict
                .get_item(name)?
                .ok_or_else(|| PyKeyError::new_err(format!("data: no `{name}`")))?;
            floats(&v, name)
        };
        let k = match dict.get_item("k")? {
            Some(k) => k_array(&k, "data['k']")?.into_vec(),
            None => return Err(PyKeyError::new_err("data: no `k`")),
        };
        let values = ells
            .iter()
            .map(|l| get(&format!("P{l}")))
            .collect::<PyResult<_>>()?;
        let sigma = ells
            .iter()
            .map(|l| get(&format!("s{l}")))
            .collect::<PyResult<_>>()?;
        let d =
            MultipoleData::from_arrays(k, ells, values, sigma, "data dict").map_err(value_error)?;
        let layout = pt_spectra::fit::DataLayout::new(ells, None).map_err(value_error)?;
        return Ok((d, "dict".into(), layout));
    }
    let path: PathBuf = data
        .extract()
        .map_err(|_| PyValueError::new_err("data: expected a path or a dict of arrays"))?;
    let layout = pt_spectra::fit::DataLayout::new(data_ells, data_columns.as_deref())
        .map_err(value_error)?;
    let d = layout.read(&path, ells).map_err(value_error)?;
    Ok((d, path.display().to_string(), layout))
}

/// `pt-spectra fit` as a function: see the Python wrapper's docstring.
#[pyfunction]
#[pyo3(signature = (data, k_max, free=vec!["f".to_string(), "sigma0".to_string()], ells=vec![0],
    data_ells=vec![0, 2, 4], data_columns=None, covariance=None, rsd=pt_spectra::jobs::defaults::RSD_MODEL, real=pt_spectra::jobs::defaults::FIT_REAL_MODEL, fog=pt_spectra::jobs::defaults::FIT_FOG,
    f=None, sigma0=None, bias=None, amplitude=1.0, shot_noise=None, number_density=None, noise_table=None,
    k_min=0.0, linear=None, z=0.0, z_input=0.0, cosmology=None, precision=pt_spectra::jobs::defaults::PRECISION, q_range=None,
    cache_dir=None, eh=None, cs2=0.0, model_out=false, contour=None, contour_points=41, contour_span=2.5))]
#[allow(clippy::too_many_arguments)]
fn fit(
    py: Python<'_>,
    data: &Bound<'_, PyAny>,
    k_max: Vec<f64>,
    free: Vec<String>,
    ells: Vec<usize>,
    data_ells: Vec<usize>,
    data_columns: Option<Vec<usize>>,
    covariance: Option<&Bound<'_, PyAny>>,
    rsd: &str,
    real: &str,
    fog: &str,
    f: Option<f64>,
    sigma0: Option<&Bound<'_, PyAny>>,
    bias: Option<&Bound<'_, PyAny>>,
    amplitude: f64,
    shot_noise: Option<f64>,
    number_density: Option<f64>,
    noise_table: Option<&Bound<'_, PyAny>>,
    k_min: f64,
    linear: Option<&Bound<'_, PyAny>>,
    z: f64,
    z_input: f64,
    cosmology: Option<&Bound<'_, PyAny>>,
    precision: &str,
    q_range: Option<(f64, f64)>,
    cache_dir: Option<PathBuf>,
    eh: Option<&str>,
    cs2: f64,
    model_out: bool,
    contour: Option<Vec<String>>,
    contour_points: usize,
    contour_span: f64,
) -> PyResult<(Table, Option<Table>, Option<Table>)> {
    let (mut data, data_name, layout) = self::data(data, data_columns, &data_ells, &ells)?;
    if let Some(c) = covariance {
        data = layout
            .attach_covariance(data, covariance_rows(c)?)
            .map_err(value_error)?;
    }
    let one = 1.0f64.into_pyobject(py)?.into_any();
    let (bias, noise) = redshift::bias_and_noise(
        bias.unwrap_or(&one),
        shot_noise,
        number_density,
        noise_table,
    )?;
    let rsd_model: RsdModel = rsd.parse().map_err(value_error)?;
    let free = free
        .iter()
        .map(|p| p.parse::<Parameter>())
        .collect::<Result<Vec<_>, _>>()
        .map_err(value_error)?;
    let request = FitRequest {
        model: RsdRequest {
            rsd: rsd_model,
            f,
            bias,
            amplitude,
            fog: fog.parse().map_err(value_error)?,
            sigma0: match sigma0 {
                Some(s) => redshift::sigma0(s)?,
                None => Sigma0::Value(3.0),
            },
            noise,
            ells,
            terms: false,
            no_wiggle: false,
            cs2,
            galaxy: None,
            ap: None,
        },
        free,
        k_min,
        k_max,
        data_name,
    };
    let precision = self::precision(precision, q_range, None, None)?;
    let store = Store::new(cache_dir);
    let real = real.parse().map_err(value_error)?;
    let inputs = Inputs::extract(linear, z, z_input, cosmology, eh)?;
    let k = data.k.clone();
    let outputs = jobs::FitOutputs {
        model: model_out,
        contour: match contour {
            None => None,
            Some(pair) => {
                let [x, y] = &pair[..] else {
                    return Err(PyValueError::new_err(format!(
                        "contour: expected two parameter names, got {pair:?}"
                    )));
                };
                let (x, y) = (
                    x.parse().map_err(value_error)?,
                    y.parse().map_err(value_error)?,
                );
                let grid = ContourGrid::new(x, y, contour_points, contour_span, &request.free);
                Some(grid.map_err(value_error)?)
            }
        },
    };
    let ((tables, prepared), seconds) = detached(py, || {
        let prepared = inputs.prepare(&k)?;
        let plan = LibRsdPlan::new(&k, real, rsd_model, &precision, store.get(), &Silent)?;
        let tables = jobs::fit_tables(&plan, data, &request, outputs, &prepared, &Silent)?;
        Ok((tables, prepared))
    })?;
    let model = format!("{rsd_model} + {real}");
    let table =
        |t: pt_spectra::output::Table| Table::new(py, t, &prepared, &precision, &model, seconds);
    Ok((
        table(tables.fit)?,
        tables.model.map(table).transpose()?,
        tables.contour.map(table).transpose()?,
    ))
}

/// The linear growth factor D(z) (D(0) = 1) and rate f(z) of a cosmology.
#[pyfunction]
#[pyo3(signature = (z, cosmology=None))]
fn growth(py: Python<'_>, z: f64, cosmology: Option<&Bound<'_, PyAny>>) -> PyResult<(f64, f64)> {
    let c = inputs::cosmology_of(cosmology)?;
    if !(z.is_finite() && z > -1.0) {
        return Err(PyValueError::new_err(format!(
            "z = {z}: a redshift must be finite and > -1"
        )));
    }
    // radiation is neglected: refused far in z, a warning where it exceeds 1e-3 (issue 45)
    if let Some(w) = pt_spectra::setup::radiation::check_growth(&c, z).map_err(value_error)? {
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        PyErr::warn(py, &category, &std::ffi::CString::new(w)?, 1)?;
    }
    Ok((c.growth_factor(z), c.growth_rate(z)))
}

/// The background of a cosmology at z: (H(z) [h km/s/Mpc], D_M(z) [Mpc/h]), with radiation (photons,
/// and massless neutrinos unless m_nu > 0) as CAMB and CLASS close the budget; for the
/// Alcock–Paczynski ratios α∥ = H_fid/H, α⊥ = D_M/D_M,fid.
#[pyfunction]
#[pyo3(signature = (z, cosmology=None))]
fn distances(z: f64, cosmology: Option<&Bound<'_, PyAny>>) -> PyResult<(f64, f64)> {
    let c = inputs::cosmology_of(cosmology)?;
    if !(z.is_finite() && z >= 0.0) {
        return Err(PyValueError::new_err(format!(
            "z = {z}: a redshift must be finite and >= 0"
        )));
    }
    Ok((c.hubble(z), c.transverse_comoving_distance(z)))
}

/// The Eisenstein & Hu (1998) linear spectrum of a cosmology at `k` [h/Mpc] and z.
#[pyfunction]
#[pyo3(signature = (k, z=0.0, cosmology=None, wiggle=true))]
fn eisenstein_hu<'py>(
    py: Python<'py>,
    k: &Bound<'py, PyAny>,
    z: f64,
    cosmology: Option<&Bound<'py, PyAny>>,
    wiggle: bool,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let k = crate::k_array(k, "k")?;
    let c = inputs::cosmology_of(cosmology)?;
    let kind = if wiggle {
        TransferKind::Wiggle
    } else {
        TransferKind::NoWiggle
    };
    let lo = k.iter().copied().fold(1e-4, f64::min) * 0.5;
    let hi = k.iter().copied().fold(50.0, f64::max) * 2.0;
    let grid = LogGrid::new(lo, hi, 2000).map_err(value_error)?;
    let p = c
        .eisenstein_hu_spectrum(kind, z, &grid)
        .map_err(value_error)?;
    Ok(k.iter()
        .map(|&k| p.eval(k))
        .collect::<Vec<f64>>()
        .into_pyarray(py))
}

/// Sets the number of threads of the computations (rayon's global pool); call it before any
/// computation. The environment variable RAYON_NUM_THREADS does the same.
#[pyfunction]
fn set_num_threads(n: usize) -> PyResult<()> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .map_err(|e| {
            PyRuntimeError::new_err(format!(
                "cannot set the number of threads to {n}: {e} (call set_num_threads before any computation)"
            ))
        })
}

/// The number of threads the computations use.
#[pyfunction]
fn num_threads() -> usize {
    rayon::current_num_threads()
}

/// `nk` log-spaced wavenumbers in [k_min, k_max] [h/Mpc], the grid of the command line's
/// `--k-min --k-max --nk`.
#[pyfunction]
fn log_grid<'py>(
    py: Python<'py>,
    k_min: f64,
    k_max: f64,
    nk: usize,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    Ok(k_grid(None, k_min, k_max, nk)?.into_pyarray(py))
}

/// The `pt_spectra._core` module.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    let defaults = PyDict::new(m.py());
    for (name, value) in pt_spectra::jobs::defaults::ALL {
        defaults.set_item(name, value)?;
    }
    m.add("DEFAULTS", defaults)?;
    m.add("K_GROWTH_RATE", pt_spectra::setup::K_GROWTH_RATE)?;
    m.add_class::<Table>()?;
    m.add_class::<RealPlan>()?;
    m.add_class::<emulator::LinearEmulator>()?;
    m.add_class::<redshift::RsdPlan>()?;
    m.add_class::<redshift::RsdTerms>()?;
    m.add_class::<ept::EptPlan>()?;
    m.add_class::<bispectrum::BispectrumPlan>()?;
    m.add_class::<bispectrum::BispectrumTerms>()?;
    m.add_class::<bispectrum::SugiyamaPlan>()?;
    m.add_class::<bispectrum::SugiyamaTerms>()?;
    m.add_function(wrap_pyfunction!(bispectrum::bispectrum, m)?)?;
    m.add_function(wrap_pyfunction!(
        bispectrum_one_loop::one_loop_bispectrum,
        m
    )?)?;
    m.add_class::<bispectrum_one_loop::OneLoopBispectrumPlan>()?;
    m.add_class::<bispectrum_multipole_plan::OneLoopMultipolePlan>()?;
    m.add_class::<ept::EptTerms>()?;
    m.add_class::<two_loop_rsd::TwoLoopRsdPlan>()?;
    m.add_class::<survey::Observation>()?;
    m.add_class::<pipeline::Pipeline>()?;
    m.add_function(wrap_pyfunction!(ept::fit_ept, m)?)?;
    m.add_function(wrap_pyfunction!(ept::from_desi_physical, m)?)?;
    m.add_function(wrap_pyfunction!(joint::fit_joint, m)?)?;
    m.add_class::<joint::AnalysisLikelihood>()?;
    m.add_function(wrap_pyfunction!(bias::convert_bias, m)?)?;
    m.add_function(wrap_pyfunction!(forecast::fisher, m)?)?;
    m.add_function(wrap_pyfunction!(forecast::fisher_kaiser, m)?)?;
    m.add_function(wrap_pyfunction!(batch::real_batch, m)?)?;
    m.add_function(wrap_pyfunction!(batch::read_multipoles, m)?)?;
    m.add_function(wrap_pyfunction!(batch::check_memory, m)?)?;
    m.add_function(wrap_pyfunction!(batch::check_covariance, m)?)?;
    m.add_function(wrap_pyfunction!(real, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(growth, m)?)?;
    m.add_function(wrap_pyfunction!(distances, m)?)?;
    m.add_function(wrap_pyfunction!(eisenstein_hu, m)?)?;
    m.add_function(wrap_pyfunction!(kernel::kernel, m)?)?;
    m.add_function(wrap_pyfunction!(halo::halo, m)?)?;
    m.add_function(wrap_pyfunction!(set_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(log_grid, m)?)?;
    Ok(())
}
