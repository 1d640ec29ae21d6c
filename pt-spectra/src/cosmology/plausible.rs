//! The ranges in which cosmological parameters are accepted ([`PLAUSIBLE`]).

use crate::error::{Error, Result};

/// The range in which a cosmological parameter is accepted, and what is said otherwise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plausible {
    /// The parameter: `h`, `omega_b` (Ω_b h²), `omega_cdm` (Ω_cdm h²), `Omega_m`, `Omega_k`, `n_s`,
    /// `sigma8`, `A_s`, `k_pivot` (1/Mpc), `w0`, `wa`, `m_nu` (Σm_ν, eV), `f` (the growth rate).
    pub name: &'static str,
    /// The smallest accepted value.
    pub min: f64,
    /// The largest accepted value.
    pub max: f64,
    /// The message of a value outside, with the range.
    pub reason: &'static str,
}

impl Plausible {
    /// Whether `v` is in [min, max].
    pub fn contains(&self, v: f64) -> bool {
        (self.min..=self.max).contains(&v)
    }

    /// The range as `[min, max]`.
    pub fn describe(&self) -> String {
        let n = crate::error::number;
        format!("[{}, {}]", n(&self.min), n(&self.max))
    }

    /// What a value outside may have meant (empty if nothing specific).
    pub fn hint(&self, v: f64) -> &'static str {
        match self.name {
            "h" if (20.0..=150.0).contains(&v) => {
                " (h is H0/100: this looks like H0 in km/s/Mpc; give `H0` or divide by 100)"
            }
            "A_s" if (0.1..=100.0).contains(&v) => {
                " (A_s is the amplitude itself, e.g. 2.1e-9; this looks like 1e9 A_s, or ln10^{10}A_s)"
            }
            "omega_b" | "omega_cdm" if v > self.max => {
                " (omega_b and omega_cdm are physical densities Omega h^2; Omega_b and Omega_cdm are \
                 the fractions)"
            }
            _ => "",
        }
    }
}

/// The plausible ranges of the cosmological parameters: wide enough for any model a survey analysis
/// explores (EuclidEmulator2's box is well inside), narrow enough that a value in the wrong units
/// (h = 67.66, A_s = 2.1, σ8 = 80) is refused rather than computed.
pub const PLAUSIBLE: [Plausible; 13] = [
    Plausible {
        name: "h",
        min: 0.2,
        max: 1.5,
        reason: "must be in [0.2, 1.5] (h = H0/(100 km/s/Mpc); a value in the tens is H0)",
    },
    Plausible {
        name: "omega_b",
        min: 0.005,
        max: 0.1,
        reason: "must be in [0.005, 0.1] (Omega_b h^2)",
    },
    Plausible {
        name: "omega_cdm",
        min: 0.0,
        max: 1.5,
        reason: "must be in [0, 1.5] (Omega_cdm h^2)",
    },
    Plausible {
        name: "Omega_m",
        min: 0.01,
        max: 2.0,
        reason: "must be in [0.01, 2]",
    },
    Plausible {
        name: "Omega_k",
        min: -1.0,
        max: 1.0,
        reason: "must be in [-1, 1]",
    },
    Plausible {
        name: "n_s",
        min: 0.5,
        max: 1.5,
        reason: "must be in [0.5, 1.5]",
    },
    Plausible {
        name: "sigma8",
        min: 0.05,
        max: 3.0,
        reason: "must be in [0.05, 3]",
    },
    Plausible {
        name: "A_s",
        min: 1e-11,
        max: 1e-7,
        reason: "must be in [1e-11, 1e-7] (e.g. 2.1e-9; ln10^{10}A_s is the logarithmic form)",
    },
    Plausible {
        name: "k_pivot",
        min: 1e-4,
        max: 10.0,
        reason: "must be in [1e-4, 10] 1/Mpc",
    },
    Plausible {
        name: "w0",
        min: -3.0,
        max: 0.0,
        reason: "must be in [-3, 0]",
    },
    Plausible {
        name: "wa",
        min: -5.0,
        max: 3.0,
        reason: "must be in [-5, 3]",
    },
    Plausible {
        name: "m_nu",
        min: 0.0,
        max: 3.0,
        reason: "Sigma m_nu must be in [0, 3] eV",
    },
    Plausible {
        name: "f",
        min: 0.0,
        max: 2.0,
        reason: "must be in [0, 2] (the linear growth rate dln D/dln a: ~0.5-1 for any plausible \
                 cosmology; 0 turns redshift-space distortions off)",
    },
];

/// The [`PLAUSIBLE`] range of the parameter `name`.
pub fn plausible(name: &str) -> Option<&'static Plausible> {
    PLAUSIBLE.iter().find(|p| p.name == name)
}

/// The growth rate `f` if finite and in its [`PLAUSIBLE`] range [0, 2].
///
/// # Errors
/// [`Error::InvalidParameter`] naming f, its value and the range.
pub fn check_growth_rate(f: f64) -> Result<()> {
    let range = plausible("f").expect("f has a plausible range");
    if !(f.is_finite() && range.contains(f)) {
        return Err(Error::InvalidParameter {
            name: "f",
            value: f,
            reason: range.reason,
        });
    }
    Ok(())
}

/// The range of σ8(z = 0) of all matter that cosmologies fitted to data have had (Planck, weak lensing,
/// clusters: 0.6–1.0), widened: a σ8 outside it follows from an A_s that is accepted (within
/// [`PLAUSIBLE`]) but most likely mistyped (A_s = 1e-7 gives σ8 = 5.7).
pub const SIGMA8_TYPICAL: (f64, f64) = (0.4, 1.3);

/// A warning for σ8(z = 0) = `sigma8` outside [`SIGMA8_TYPICAL`] when the amplitude was given as
/// A_s = `a_s`; `None` inside.
pub fn sigma8_warning(sigma8: f64, a_s: f64) -> Option<String> {
    let (lo, hi) = SIGMA8_TYPICAL;
    if (lo..=hi).contains(&sigma8) {
        return None;
    }
    Some(format!(
        "cosmology: A_s = {} gives sigma8(z = 0) = {sigma8:.3}, outside the range [{lo}, {hi}] of \
         cosmologies fitted to data: check A_s (e.g. 2.1e-9)",
        crate::error::number(&a_s)
    ))
}
