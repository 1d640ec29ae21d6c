//! The cosmological parameters of a forecast ([`super::COSMOLOGY_NAMES`]): their values in a
//! [`Cosmology`] and a cosmology with one of them changed (flat; ω_cdm, ω_b and ω_ν kept where not
//! varied).

use crate::cosmology::{Amplitude, Cosmology, EV_PER_OMEGA_NU};
use crate::error::{Error, Result};

/// Checks the fiducial can be varied: flat and A_s-normalised.
///
/// # Errors
/// [`Error::InvalidChoice`] naming what is not.
pub(super) fn check_cosmology(c: &Cosmology) -> Result<()> {
    if (c.omega_m + c.omega_lambda - 1.0).abs() > 1e-9 {
        return Err(Error::InvalidChoice {
            what: "the forecast's fiducial cosmology".into(),
            reason: "cosmological forecasts vary a flat cosmology (Omega_k = 0)".into(),
        });
    }
    if !matches!(c.amplitude, Amplitude::As { .. }) {
        return Err(Error::InvalidChoice {
            what: "the forecast's fiducial cosmology".into(),
            reason:
                "cosmological forecasts vary ln(10^10 A_s): give the fiducial by A_s, not sigma8"
                    .into(),
        });
    }
    Ok(())
}

/// ω_ν of the fiducial's neutrinos.
fn omega_nu(c: &Cosmology) -> f64 {
    c.m_nu / EV_PER_OMEGA_NU
}

/// The value of cosmological parameter `name` ([`COSMOLOGY_NAMES`]) of `c`.
pub(super) fn cosmology_value(c: &Cosmology, name: &str) -> f64 {
    let h2 = c.h * c.h;
    match name {
        "omega_cdm" => c.omega_m * h2 - c.omega_b_h2 - omega_nu(c),
        "omega_b" => c.omega_b_h2,
        "h" => c.h,
        "logA" => match c.amplitude {
            Amplitude::As { a_s, .. } => (1e10 * a_s).ln(),
            Amplitude::Sigma8(_) => f64::NAN,
        },
        _ => c.n_s,
    }
}

/// `c` with cosmological parameter `name` set to `x`, ω_cdm, ω_b and ω_ν kept where not varied (flat).
pub(super) fn with_cosmology_value(c: &Cosmology, name: &str, x: f64) -> Result<Cosmology> {
    let mut out = *c;
    let (mut w_cdm, mut w_b, mut h) = (cosmology_value(c, "omega_cdm"), c.omega_b_h2, c.h);
    match name {
        "omega_cdm" => w_cdm = x,
        "omega_b" => w_b = x,
        "h" => h = x,
        "logA" => {
            if let Amplitude::As { k_pivot, .. } = c.amplitude {
                out.amplitude = Amplitude::As {
                    a_s: x.exp() * 1e-10,
                    k_pivot,
                };
            }
        }
        _ => out.n_s = x,
    }
    out.h = h;
    out.omega_b_h2 = w_b;
    out.omega_m = (w_cdm + w_b + omega_nu(c)) / (h * h);
    out.omega_lambda = 1.0 - out.omega_m;
    out.validate()?;
    Ok(out)
}
