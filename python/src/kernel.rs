//! `pt_spectra.kernel`: the symmetrised kernels F_n^s, G_n^s at given vectors.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::Zero;
use pt_kernels::exact::{check_exact_size, format_rational, parse_rational};
use pt_kernels::kernels;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyInt};
use std::str::FromStr;

/// One component as an exact rational: an int, a `fractions.Fraction`, a string (`p/q`, an integer
/// or a decimal, parsed as the command line does: `pt_kernels::exact`), or a float (its exact binary
/// value).
fn rational(c: &Bound<'_, PyAny>) -> PyResult<BigRational> {
    let bad = || PyValueError::new_err(format!("kernel: component {c} is not a number"));
    let int = |o: &Bound<'_, PyAny>| -> PyResult<BigInt> {
        BigInt::from_str(&o.str()?.to_string()).map_err(|_| bad())
    };
    if c.is_instance_of::<PyInt>() {
        return Ok(BigRational::from_integer(int(c)?));
    }
    if !c.is_instance_of::<PyFloat>() && c.hasattr("numerator")? && c.hasattr("denominator")? {
        let (n, d) = (
            int(&c.getattr("numerator")?)?,
            int(&c.getattr("denominator")?)?,
        );
        if d.is_zero() {
            return Err(bad());
        }
        return Ok(BigRational::new(n, d));
    }
    if let Ok(s) = c.extract::<String>() {
        return parse_rational(&s).map_err(|e| PyValueError::new_err(format!("kernel: {e}")));
    }
    let v: f64 = c.extract().map_err(|_| bad())?;
    BigRational::from_float(v).ok_or_else(bad)
}

/// The three components of one vector.
fn components<'py>(v: &Bound<'py, PyAny>) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let c: Vec<Bound<'py, PyAny>> = v.extract()?;
    if c.len() != 3 {
        return Err(PyValueError::new_err(format!(
            "kernel: vector {v} must have three components"
        )));
    }
    Ok(c)
}

/// One vector as three exact rationals.
fn rational_vector(v: &Bound<'_, PyAny>) -> PyResult<[BigRational; 3]> {
    let c = components(v)?;
    Ok([rational(&c[0])?, rational(&c[1])?, rational(&c[2])?])
}

/// One vector as three finite floats.
fn float_vector(v: &Bound<'_, PyAny>) -> PyResult<[f64; 3]> {
    let c = components(v)?;
    let x = |i: usize| finite_float(&c[i], "component");
    Ok([x(0)?, x(1)?, x(2)?])
}

/// A finite float, or an error naming `what`.
fn finite_float(c: &Bound<'_, PyAny>, what: &str) -> PyResult<f64> {
    let v: f64 = c.extract()?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(PyValueError::new_err(format!(
            "kernel: {what} {v} is not finite"
        )))
    }
}

/// F_n^s or G_n^s (`which` = "F" or "G") at the n = len(vectors) vectors (1 ≤ n ≤ 7), each [x, y, z]
/// in h/Mpc, or the redshift-space Z_n (`which` = "Z", n ≤ 5; Scoccimarro, Couchman & Frieman 1999)
/// with growth rate `f` (required) along the line of sight `los` (default [0, 0, 1]; only its
/// direction enters). With `exact`, in rational arithmetic (components, f and los as ints, Fractions,
/// "p/q" strings or floats taken exactly), returned as the string of the reduced fraction; otherwise a
/// float.
#[pyfunction]
#[pyo3(signature = (which, vectors, exact=false, f=None, los=None))]
pub fn kernel(
    which: &str,
    vectors: Vec<Bound<'_, PyAny>>,
    exact: bool,
    f: Option<Bound<'_, PyAny>>,
    los: Option<Bound<'_, PyAny>>,
) -> PyResult<Py<PyAny>> {
    let py = match vectors.first() {
        Some(v) => v.py(),
        None => {
            return Err(PyValueError::new_err(format!(
                "kernel: no vector given (1 to {})",
                pt_kernels::MAX_ORDER
            )))
        }
    };
    let index = match which {
        "F" | "f" => 0,
        "G" | "g" => 1,
        "Z" | "z" => 2,
        _ => {
            return Err(PyValueError::new_err(format!(
                "kernel: unknown kernel `{which}`; available: F, G, Z"
            )))
        }
    };
    let max = if index == 2 {
        pt_kernels::redshift::MAX_REDSHIFT_ORDER
    } else {
        pt_kernels::MAX_ORDER
    };
    if vectors.len() > max {
        return Err(PyValueError::new_err(format!(
            "kernel: order n = {} is not supported for {which}: at most {max} vectors",
            vectors.len()
        )));
    }
    let redshift = match (index, &f) {
        (2, None) => {
            return Err(PyValueError::new_err(
                "kernel: Z needs the growth rate f (f=...)",
            ))
        }
        (2, Some(f)) => Some((f.clone(), los.clone())),
        (_, Some(_)) => {
            return Err(PyValueError::new_err(format!(
                "kernel: f and los are for Z, not {which}"
            )))
        }
        _ => None,
    };
    if exact {
        let q: Vec<[BigRational; 3]> = vectors
            .iter()
            .map(rational_vector)
            .collect::<PyResult<_>>()?;
        check_exact_size(&q).map_err(|e| PyValueError::new_err(format!("kernel: {e}")))?;
        if let Some((f, los)) = &redshift {
            let f = rational(f)?;
            let los = match los {
                Some(v) => rational_vector(v)?,
                None => [
                    BigRational::zero(),
                    BigRational::zero(),
                    BigRational::from_integer(1.into()),
                ],
            };
            let value = py
                .detach(|| pt_kernels::redshift::redshift_kernel(&q, &f, &los))
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            return Ok(format_rational(&value)
                .into_pyobject(py)?
                .into_any()
                .unbind());
        }
        // The exact kernel can take seconds: without the GIL.
        let value = py
            .detach(|| kernels(&q))
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        return Ok(format_rational(&value[index])
            .into_pyobject(py)?
            .into_any()
            .unbind());
    }
    let q: Vec<[f64; 3]> = vectors.iter().map(float_vector).collect::<PyResult<_>>()?;
    if let Some(note) = pt_kernels::cancellation_note(&q) {
        let category = py.get_type::<pyo3::exceptions::PyRuntimeWarning>();
        PyErr::warn(py, &category, &std::ffi::CString::new(note)?, 1)?;
    }
    let value = match &redshift {
        Some((f, los)) => {
            let f = finite_float(f, "f")?;
            let los = match los {
                Some(v) => float_vector(v)?,
                None => [0.0, 0.0, 1.0],
            };
            pt_kernels::redshift::redshift_kernel(&q, &f, &los)
        }
        None => kernels(&q).map(|v| v[index]),
    }
    .map_err(|e| PyValueError::new_err(e.to_string()))?;
    if !value.is_finite() {
        return Err(PyValueError::new_err(format!(
            "kernel: the value overflows double precision ({value}); use exact=True"
        )));
    }
    Ok(value.into_pyobject(py)?.into_any().unbind())
}
