//! The inputs every computation shares (linear spectrum, redshifts, cosmology), taken from Python
//! arguments into plain Rust values while the GIL is held, then turned into the library's inputs
//! ([`Inputs::prepare`]) with the GIL released, as part of the library call.

use crate::value_error;
use numpy::PyReadonlyArray1;
use pt_spectra::cosmology::{Cosmology, TransferKind};
use pt_spectra::linear::LinearSpectrum;
use pt_spectra::setup::{self, LinearSource, NamedCosmology, Prepared, Request};
use pt_spectra::table::KGrid;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::path::PathBuf;

/// The linear spectrum as given.
enum Linear {
    /// The embedded gm2012 spectra, or Eisenstein & Hu.
    Default(Option<TransferKind>),
    /// A table file.
    File(PathBuf),
    /// Arrays k [h/Mpc], P [(Mpc/h)^3].
    Arrays(Vec<f64>, Vec<f64>),
}

/// The cosmology as given.
enum CosmologyArg {
    Default,
    NameOrFile(String),
    Keys(Vec<(String, String)>),
}

/// The shared inputs of a call.
pub struct Inputs {
    linear: Linear,
    cosmology: CosmologyArg,
    z: f64,
    z_input: f64,
}

impl Inputs {
    /// Reads the Python arguments: `linear` (None, a path or (k, P)), `cosmology` (None, a name or
    /// path, or a dict of ini keys), `eh` (None, "wiggle" or "no-wiggle").
    pub fn extract(
        linear: Option<&Bound<'_, PyAny>>,
        z: f64,
        z_input: f64,
        cosmology: Option<&Bound<'_, PyAny>>,
        eh: Option<&str>,
    ) -> PyResult<Self> {
        let eh = match eh {
            None => None,
            Some("wiggle") => Some(TransferKind::Wiggle),
            Some("no-wiggle") => Some(TransferKind::NoWiggle),
            Some(other) => {
                return Err(PyValueError::new_err(format!(
                    "unknown eh `{other}`; available: wiggle, no-wiggle"
                )))
            }
        };
        let linear = match linear {
            None => Linear::Default(eh),
            Some(_) if eh.is_some() => {
                return Err(PyValueError::new_err("give either linear or eh, not both"))
            }
            Some(obj) if obj.is_instance_of::<PyString>() || obj.extract::<PathBuf>().is_ok() => {
                Linear::File(obj.extract()?)
            }
            Some(obj) => {
                let (k, p): (Bound<'_, PyAny>, Bound<'_, PyAny>) = obj.extract().map_err(|_| {
                    PyValueError::new_err(
                        "linear: expected a path or a pair (k [h/Mpc], P [(Mpc/h)^3])",
                    )
                })?;
                Linear::Arrays(
                    crate::k_array(&k, "linear k")?.into_vec(),
                    positive(crate::floats(&p, "linear P")?, "linear P")?,
                )
            }
        };
        let cosmology = match cosmology {
            None => CosmologyArg::Default,
            Some(obj) => match obj.cast::<PyDict>() {
                Ok(dict) => {
                    let mut pairs = Vec::new();
                    for (key, value) in dict.iter() {
                        // a list of numbers (CLASS's m_ncdm = [0.02, 0.02, 0.02]) as CLASS writes it
                        let text = match value.extract::<Vec<f64>>() {
                            Ok(list) if !value.is_instance_of::<PyString>() => list
                                .iter()
                                .map(f64::to_string)
                                .collect::<Vec<_>>()
                                .join(", "),
                            _ => value.str()?.to_string(),
                        };
                        pairs.push((key.str()?.to_string(), text))
                    }
                    CosmologyArg::Keys(pairs)
                }
                Err(_) => {
                    let name: PathBuf = obj.extract().map_err(|_| {
                        PyValueError::new_err(
                            "cosmology: expected a preset name, an ini path or a dict of ini keys",
                        )
                    })?;
                    CosmologyArg::NameOrFile(name.to_string_lossy().into_owned())
                }
            },
        };
        Ok(Self {
            linear,
            cosmology,
            z,
            z_input,
        })
    }

    /// The cosmology and the keys of its ini file or dict that were ignored.
    pub fn cosmology(&self) -> pt_spectra::error::Result<(Option<NamedCosmology>, Vec<String>)> {
        Ok(match &self.cosmology {
            CosmologyArg::Default => (None, Vec::new()),
            CosmologyArg::NameOrFile(s) => {
                let (named, ignored) = NamedCosmology::parse(s)?;
                (Some(named), ignored)
            }
            CosmologyArg::Keys(pairs) => {
                // strict: a key that sets nothing (a misspelt `m_ncmd`) is an error naming it, in
                // every face that takes a dict (it changed the result silently)
                let parsed = Cosmology::from_keys_strict(pairs.iter().cloned(), "cosmology dict")?;
                let named = NamedCosmology {
                    name: "dict".into(),
                    cosmology: parsed.cosmology,
                };
                (Some(named), parsed.ignored)
            }
        })
    }

    /// The linear spectrum at z with the growth of the cosmology, the warnings (ignored keys and
    /// output k beyond the linear table included).
    pub fn prepare(&self, k: &[f64]) -> pt_spectra::error::Result<Prepared> {
        self.prepare_at(k, self.z)
    }

    /// [`Self::prepare`] at the output redshift `z` in place of the arguments' (a joint fit's sets).
    pub fn prepare_at(&self, k: &[f64], z: f64) -> pt_spectra::error::Result<Prepared> {
        let source = match &self.linear {
            Linear::Default(None) => LinearSource::Embedded,
            Linear::Default(Some(kind)) => LinearSource::EisensteinHu(*kind),
            Linear::File(path) => LinearSource::Table {
                spectrum: Box::new(LinearSpectrum::from_file(path)?),
                z_input: self.z_input,
            },
            Linear::Arrays(k, p) => LinearSource::Table {
                spectrum: Box::new(LinearSpectrum::from_nodes(k.clone(), p.clone())?),
                z_input: self.z_input,
            },
        };
        let (cosmology, ignored) = self.cosmology()?;
        let mut prepared = setup::prepare(Request {
            source,
            cosmology,
            z,
        })?;
        let extra = setup::input_warnings(&prepared, &ignored, k);
        prepared.warnings.extend(extra);
        Ok(prepared)
    }
}

/// `values` if every one is finite and positive, else a `ValueError` naming `what` and the index.
fn positive(values: Vec<f64>, what: &str) -> PyResult<Vec<f64>> {
    match values.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
        None => Ok(values),
        Some(i) => Err(PyValueError::new_err(format!(
            "{what}[{i}] = {}: every P must be finite and positive",
            values[i]
        ))),
    }
}

/// The cosmology of a Python argument (for the small helpers and the emulator), gm2012 by default.
///
/// A dict is strict ([`Cosmology::from_keys_strict`], as in every face that takes one): a key that
/// sets nothing (a misspelt `m_ncmd`, say) is a ValueError naming it, since it would otherwise change
/// the result silently. An ini file's other keys (CLASS's `output`, ...) are normal there and are not
/// an error.
pub fn cosmology_of(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Cosmology> {
    let inputs = Inputs::extract(None, 0.0, 0.0, obj, None)?;
    let (named, _) = inputs.cosmology().map_err(value_error)?;
    Ok(named.map_or(Cosmology::gm2012(), |n| n.cosmology))
}

/// A float array from a numpy array or any sequence of numbers.
pub(crate) fn floats(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    // A numpy array of other than one dimension (whose elements would convert one by one).
    if let Ok(ndim) = obj.getattr("ndim").and_then(|n| n.extract::<usize>()) {
        if ndim != 1 {
            return Err(PyValueError::new_err(format!(
                "{what}: expected a 1-D array, got a {ndim}-D one"
            )));
        }
    }
    if let Ok(a) = obj.extract::<PyReadonlyArray1<'_, f64>>() {
        return Ok(a.as_array().to_vec());
    }
    obj.extract::<Vec<f64>>().map_err(|_| {
        PyValueError::new_err(format!(
            "{what}: expected a 1-D array or sequence of numbers"
        ))
    })
}

/// A k grid [h/Mpc] from the array argument `what` ([`floats`]), checked as every k grid is
/// ([`KGrid::from_values`]: non-empty, finite, positive, strictly increasing): a `ValueError` names the
/// argument, the index and the rule.
pub(crate) fn k_array(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<KGrid> {
    KGrid::from_values(what, floats(obj, what)?).map_err(value_error)
}
