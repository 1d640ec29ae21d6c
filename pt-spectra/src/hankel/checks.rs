//! Checks of the input of the Hankel transforms, and their errors.

use super::{Direction, HankelOptions, MAX_ELL};
use crate::error::{number, Error, Result};

pub(super) fn invalid(name: &'static str, value: f64, reason: &'static str) -> Error {
    Error::InvalidParameter {
        name,
        value,
        reason,
    }
}

pub(super) fn check_ell(ell: usize) -> Result<()> {
    if ell > MAX_ELL {
        return Err(invalid("ell (multipole)", ell as f64, "must be at most 8"));
    }
    Ok(())
}

pub(super) fn check_options(o: &HankelOptions) -> Result<()> {
    if !(o.points_per_decade.is_finite() && o.points_per_decade >= 10.0) {
        let reason = "must be finite and at least 10";
        return Err(invalid("points_per_decade", o.points_per_decade, reason));
    }
    if !(0.0..=10.0).contains(&o.pad_decades) {
        let reason = "must be between 0 and 10";
        return Err(invalid("pad_decades", o.pad_decades, reason));
    }
    match o.k_damp {
        Some(k) if !(k.is_finite() && k > 0.0) => Err(invalid(
            "k_damp [h/Mpc]",
            k,
            "must be a finite positive number",
        )),
        _ => Ok(()),
    }
}

pub(super) fn check_finite(origin: &str, name: &'static str, f: &[f64]) -> Result<()> {
    match f.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(Error::InvalidValue {
            origin: origin.into(),
            line: i + 1,
            name,
            value: f[i],
            reason: "must be finite",
        }),
        None => Ok(()),
    }
}

/// A point of a grid or of the requested output: finite and positive.
pub(super) fn check_point(origin: &str, i: usize, v: f64, name: &'static str) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else if name.starts_with('k') {
        Err(Error::InvalidK {
            origin: origin.into(),
            line: i + 1,
            k: v,
        })
    } else {
        Err(Error::InvalidValue {
            origin: origin.into(),
            line: i + 1,
            name,
            value: v,
            reason: "must be a finite positive number",
        })
    }
}

/// The input grid: finite, positive, strictly increasing.
pub(super) fn check_grid(origin: &str, direction: Direction, x: &[f64]) -> Result<()> {
    let name = direction.names()[0];
    for (i, &v) in x.iter().enumerate() {
        check_point(origin, i, v, name)?;
        if i > 0 && v <= x[i - 1] {
            return Err(match direction {
                Direction::PkToXi => Error::NonIncreasingK {
                    origin: origin.into(),
                    line: i + 1,
                    k: v,
                    previous: x[i - 1],
                },
                Direction::XiToPk => Error::InvalidValue {
                    origin: origin.into(),
                    line: i + 1,
                    name,
                    value: v,
                    reason: "must exceed the previous s (s must be strictly increasing)",
                },
            });
        }
    }
    Ok(())
}

pub(super) fn out_of_range(direction: Direction, y: f64, lo: f64, hi: f64, x_name: &str) -> Error {
    match direction {
        Direction::XiToPk => Error::OutOfRange {
            what: "the Hankel transform of xi_ell(s)".into(),
            k: y,
            min: lo,
            max: hi,
        },
        Direction::PkToXi => Error::InvalidChoice {
            what: format!("s = {} Mpc/h", number(&y)),
            reason: format!(
                "outside the range {} <= s <= {} Mpc/h reciprocal to the input {x_name}",
                number(&lo),
                number(&hi)
            ),
        },
    }
}
