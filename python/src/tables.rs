//! [`Table`]: a table of the library (`pt_spectra::output::Table`) seen from Python: named numpy
//! columns, units, header lines and metadata.

use numpy::{IntoPyArray, PyArray1};
use pt_spectra::output;
use pt_spectra::precision::Precision;
use pt_spectra::setup::Prepared;
use pyo3::exceptions::PyKeyError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A table of results: `t.columns` (names as the command line prints them), `t["P_dd"]` (a numpy
/// array), `t.units`, `t.header`, `t.meta` (z, f, D, cosmology, neutrinos, precision, q range, model), and
/// `t.to_text()` (the command line's output).
#[pyclass(module = "pt_spectra._core", frozen)]
pub struct Table {
    table: output::Table,
    meta: Py<PyDict>,
    warnings: Vec<String>,
}

impl Table {
    /// The table with the metadata of the run that made it.
    pub fn new(
        py: Python<'_>,
        table: output::Table,
        prepared: &Prepared,
        precision: &Precision,
        model: &str,
        seconds: f64,
    ) -> PyResult<Self> {
        checked(&table)?;
        let meta = PyDict::new(py);
        meta.set_item("z", prepared.z)?;
        meta.set_item("f", prepared.growth_rate)?;
        meta.set_item("D", prepared.growth_factor)?;
        meta.set_item("cosmology", &prepared.cosmology.name)?;
        meta.set_item(
            "cosmology_parameters",
            prepared.cosmology.cosmology.describe(),
        )?;
        let c = &prepared.cosmology.cosmology;
        let neutrinos = if c.m_nu > 0.0 {
            c.neutrinos.name()
        } else {
            "massless"
        };
        meta.set_item("neutrinos", neutrinos)?;
        meta.set_item("precision", precision.label())?;
        meta.set_item("q_range", (precision.q_min, precision.q_max))?;
        meta.set_item("model", model)?;
        meta.set_item("linear", prepared.spectrum.origin())?;
        // The wall time of the library call alone (GIL released), to measure the Python overhead.
        meta.set_item("seconds", seconds)?;
        let mut warnings = prepared.warnings.clone();
        set_methods(&meta, &table, &mut warnings)?;
        Ok(Self {
            table,
            meta: meta.unbind(),
            warnings,
        })
    }

    /// Adds a warning that the Python wrapper raises as a `PtSpectraWarning`.
    pub fn warn(&mut self, message: String) {
        self.warnings.push(message);
    }

    /// A table of a job without a cosmology (`halo`): `meta` has the model and the seconds.
    pub fn plain(
        py: Python<'_>,
        table: output::Table,
        model: &str,
        seconds: f64,
    ) -> PyResult<Self> {
        checked(&table)?;
        let meta = PyDict::new(py);
        meta.set_item("model", model)?;
        meta.set_item("seconds", seconds)?;
        let mut warnings = Vec::new();
        set_methods(&meta, &table, &mut warnings)?;
        Ok(Self {
            table,
            meta: meta.unbind(),
            warnings,
        })
    }
}

/// `meta["methods"]`: how each part of `table` was computed (`{"1-loop terms": "basis", …}`, the
/// library's [`output::MethodNote`]s, which the header states with figures); a fallback to a slower
/// path because the spectrum is not one the basis represents is also a warning (not `auto` without
/// cached tensors: that is what `auto` says it does).
fn set_methods(
    meta: &Bound<'_, PyDict>,
    table: &output::Table,
    warnings: &mut Vec<String>,
) -> PyResult<()> {
    let methods = PyDict::new(meta.py());
    for note in &table.methods {
        methods.set_item(&note.part, &note.method)?;
        if note.method.contains("fallback") {
            warnings.push(format!("{}: {} (see the header)", note.part, note.method));
        }
    }
    meta.set_item("methods", methods)
}

/// A `ValueError` if a value of `table` is not finite (the check the command line makes before it
/// writes a table).
fn checked(table: &output::Table) -> PyResult<()> {
    table
        .checked()
        .map(|_| ())
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))
}

#[pymethods]
impl Table {
    /// The column names.
    #[getter]
    fn columns(&self) -> Vec<String> {
        self.table.columns.iter().map(|c| c.name.clone()).collect()
    }

    /// The column names (so that `dict(t)` works).
    fn keys(&self) -> Vec<String> {
        self.columns()
    }

    /// The unit of each column.
    #[getter]
    fn units<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for c in &self.table.columns {
            d.set_item(&c.name, c.unit)?;
        }
        Ok(d)
    }

    /// The header lines (what was computed, with which cosmology, spectrum, q range and precision).
    #[getter]
    fn header(&self) -> Vec<String> {
        self.table.header.clone()
    }

    /// z, f, D, cosmology, precision, q range, model, linear spectrum, seconds (of the library call),
    /// methods (how each part was computed: `{"1-loop terms": "basis", …}`).
    #[getter]
    fn meta<'py>(&self, py: Python<'py>) -> Bound<'py, PyDict> {
        self.meta.bind(py).clone()
    }

    /// What the user should know about the inputs (also in the header).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    fn __getitem__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.table
            .column(name)
            .map(|v| v.to_vec().into_pyarray(py))
            .ok_or_else(|| {
                PyKeyError::new_err(format!(
                    "no column `{name}`; columns: {}",
                    self.table.names().join(" ")
                ))
            })
    }

    fn __contains__(&self, name: &str) -> bool {
        self.table.column(name).is_some()
    }

    fn __len__(&self) -> usize {
        self.table.rows()
    }

    /// The table as the command line writes it.
    fn to_text(&self) -> String {
        self.table.to_text()
    }

    fn __repr__(&self) -> String {
        format!(
            "Table({} rows: {})",
            self.table.rows(),
            self.table.names().join(" ")
        )
    }
}
