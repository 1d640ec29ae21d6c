//! The keywords of the blocks after the power spectrum ([`pt_spectra::blocks::AVAILABLE`]) as their
//! options ([`pt_spectra::statistic::Options`]): a block's name with a dict, or the block's own
//! keywords ([`pt_spectra::statistic::Faces::keywords`]), converted without knowing the block.

use crate::library_error;
use pt_spectra::blocks::AVAILABLE;
use pt_spectra::statistic::{Kind, OptionValue, Options, Spec};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyString};
use std::sync::Arc;

/// `v` as an option value: bool, int, float, str, or a sequence (a list, a tuple, a numpy array) of
/// those.
fn option_value(v: &Bound<'_, PyAny>) -> PyResult<OptionValue> {
    if v.is_instance_of::<PyBool>() {
        return Ok(OptionValue::Flag(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(OptionValue::Text(v.extract()?));
    }
    if !v.is_instance_of::<PyFloat>() {
        if let Ok(n) = v.extract::<i64>() {
            return Ok(OptionValue::Integer(n));
        }
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok(OptionValue::Number(x));
    }
    match v.try_iter() {
        Ok(items) => items
            .map(|x| option_value(&x?))
            .collect::<PyResult<Vec<_>>>()
            .map(OptionValue::List),
        Err(_) => Ok(OptionValue::Other(v.get_type().name()?.to_string())),
    }
}

/// The entries of `(key, value)` pairs, those of value None left out.
fn push(options: &mut Options, key: String, v: &Bound<'_, PyAny>) -> PyResult<()> {
    if !v.is_none() {
        let value = option_value(v)?;
        options.entries.push((key, value));
    }
    Ok(())
}

/// The keywords of the registered blocks, for messages.
fn valid() -> String {
    AVAILABLE
        .iter()
        .map(|k| {
            format!(
                "{} (or its keywords {})",
                k.name,
                k.faces.keywords.join(", ")
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The options of each registered kind among `kwargs` (a keyword is the first kind's whose name or
/// keyword it is).
///
/// # Errors
/// TypeError for a keyword of no block (naming the valid ones), a block's name without a dict.
pub(crate) fn block_options(
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<(&'static Kind, Options)>> {
    let mut out: Vec<(&'static Kind, Options)> =
        AVAILABLE.iter().map(|&k| (k, Options::default())).collect();
    let Some(kw) = kwargs else {
        return Ok(Vec::new());
    };
    for (k, v) in kw.iter() {
        let key: String = k.extract()?;
        if let Some((kind, options)) = out.iter_mut().find(|(kind, _)| kind.name == key) {
            if v.is_none() {
                continue;
            }
            let dict = v.cast::<PyDict>().map_err(|_| {
                PyTypeError::new_err(format!(
                    "{key}: the options of the {} block are a dict",
                    kind.name
                ))
            })?;
            for (k, v) in dict.iter() {
                push(options, k.extract()?, &v)?;
            }
        } else if let Some((_, options)) = out
            .iter_mut()
            .find(|(kind, _)| kind.faces.keywords.contains(&key.as_str()))
        {
            push(options, key, &v)?;
        } else {
            return Err(PyTypeError::new_err(format!(
                "unexpected keyword argument '{key}': the other keywords are the blocks' ({})",
                valid()
            )));
        }
    }
    out.retain(|(_, o)| !o.entries.is_empty());
    Ok(out)
}

/// The blocks of a pipeline from `kwargs` ([`block_options`], each planned by its kind's
/// [`pt_spectra::statistic::Faces::pipeline`]), in the order of the registration.
///
/// # Errors
/// As [`block_options`]; ValueError as the block's options.
pub(crate) fn pipeline_blocks(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<Arc<dyn Spec>>> {
    let mut out = Vec::new();
    for (kind, options) in block_options(kwargs)? {
        if let Some(spec) = (kind.faces.pipeline)(&options).map_err(library_error)? {
            out.push(spec);
        }
    }
    Ok(out)
}
