//! Keys of CLASS and CAMB that change the linear spectrum or the background in ways pt-spectra does
//! not model. Listing them as ignored (with a note) gave a wrong spectrum with exit 0 (issue 45):
//! `Omega_ncdm` or `T_ncdm` dropped the neutrinos' mass or temperature, `alpha_s` the running,
//! `Omega_m = 0.5` beside `omega_cdm` was left for the derived 0.31. Each is now read and refused
//! unless it states what is modelled anyway (`T_ncdm = 0.71611`, `alpha_s = 0`, an `Omega_m` equal to
//! the derived one, ...), with an error naming the line, the key and the rule.
//!
//! A key that matches a read key but for case (`M_ncdm`, `OMEGA_B`) is a misspelling, not another
//! code's parameter, and is refused naming the key meant.

use super::{parse_number, quote, Entry, KEYS};
use crate::error::{Error, Result};

/// What a key states and how it is checked.
#[derive(Debug, Clone, Copy)]
enum Rule {
    /// A number that must equal the modelled value to the tolerance (absolute).
    Default {
        value: f64,
        tol: f64,
        what: &'static str,
    },
    /// Never read: give the named key instead.
    Instead(&'static str),
    /// The total matter density Ω_m (or ω_m = Ω_m h² with `physical`), which must equal the derived
    /// one to [`OMEGA_M_TOL`] relative.
    OmegaM { physical: bool },
    /// CAMB's number of mass eigenstates, which must be 1 (one mass shared by the massive species).
    Eigenstates,
    /// CAMB's fractions of Σm_ν per eigenstate, which must be the single fraction 1.
    Fractions,
}

/// Relative tolerance of a given Ω_m against the derived one: parameter files round to 4–6 digits.
pub(super) const OMEGA_M_TOL: f64 = 1e-3;

/// CLASS's default temperature of the non-cold relics in units of T_CMB, which makes m/ω = 93.14 eV
/// and the N_eff contributions of [`N_EFF_PER_NCDM`](crate::cosmology::neutrinos::N_EFF_PER_NCDM).
const T_NCDM: f64 = 0.71611;

/// The CMB temperature of the background (photons), K.
const T_CMB: f64 = 2.7255;

const KEYS_CHECKED: [(&str, Rule); 22] = [
    (
        "T_ncdm",
        Rule::Default {
            value: T_NCDM,
            tol: 1e-4,
            what: "the temperature of the massive neutrinos is CLASS's default 0.71611 T_cmb",
        },
    ),
    (
        "ksi_ncdm",
        Rule::Default {
            value: 0.0,
            tol: 0.0,
            what: "the neutrinos have no chemical potential",
        },
    ),
    (
        "alpha_s",
        Rule::Default {
            value: 0.0,
            tol: 0.0,
            what: "the primordial spectrum is a power law (no running)",
        },
    ),
    (
        "beta_s",
        Rule::Default {
            value: 0.0,
            tol: 0.0,
            what: "the primordial spectrum is a power law (no running of the running)",
        },
    ),
    (
        "nrun",
        Rule::Default {
            value: 0.0,
            tol: 0.0,
            what: "the primordial spectrum is a power law (no running)",
        },
    ),
    (
        "nrunrun",
        Rule::Default {
            value: 0.0,
            tol: 0.0,
            what: "the primordial spectrum is a power law (no running of the running)",
        },
    ),
    (
        "scalar_nrun(1)",
        Rule::Default {
            value: 0.0,
            tol: 0.0,
            what: "the primordial spectrum is a power law (no running)",
        },
    ),
    (
        "T_cmb",
        Rule::Default {
            value: T_CMB,
            tol: 1e-3,
            what: "the photons are at T_cmb = 2.7255 K",
        },
    ),
    (
        "TCMB",
        Rule::Default {
            value: T_CMB,
            tol: 1e-3,
            what: "the photons are at T_cmb = 2.7255 K",
        },
    ),
    (
        "temp_cmb",
        Rule::Default {
            value: T_CMB,
            tol: 1e-3,
            what: "the photons are at T_cmb = 2.7255 K",
        },
    ),
    (
        "omega_ncdm",
        Rule::Instead("m_ncdm (eV per species, m = 93.14 eV x omega_ncdm)"),
    ),
    (
        "Omega_ncdm",
        Rule::Instead("m_ncdm (eV per species, m = 93.14 eV x Omega_ncdm h^2)"),
    ),
    (
        "omega_ur",
        Rule::Instead("N_ur (the number of massless species)"),
    ),
    (
        "Omega_ur",
        Rule::Instead("N_ur (the number of massless species)"),
    ),
    (
        "100*theta_s",
        Rule::Instead("h or H0 (the sound horizon's angle is not converted to h)"),
    ),
    (
        "theta_s_100",
        Rule::Instead("h or H0 (the sound horizon's angle is not converted to h)"),
    ),
    (
        "cosmomc_theta",
        Rule::Instead("H0 (the sound horizon's angle is not converted to h)"),
    ),
    (
        "thetastar",
        Rule::Instead("H0 (the sound horizon's angle is not converted to h)"),
    ),
    ("Omega_m", Rule::OmegaM { physical: false }),
    ("omega_m", Rule::OmegaM { physical: true }),
    ("nu_mass_eigenstates", Rule::Eigenstates),
    ("nu_mass_fractions", Rule::Fractions),
];

/// The refusal of `entry`: the file, line, `key = value` and why.
fn refuse(origin: &str, entry: Entry<'_>, reason: String) -> Error {
    Error::InvalidChoice {
        what: format!("{origin}:{}: `{}`", entry.line, entry.text()),
        reason,
    }
}

/// The keys of this module that were given and accepted (they state what is modelled), to be listed
/// as ignored; refuses the others and the misspellings (module docs). `omega_m` is the derived
/// Ω_m (all matter) and `h` the Hubble parameter.
///
/// # Errors
/// [`Error::InvalidChoice`] naming the line and key and the rule broken; [`Error::IniValue`] for a
/// value that is not a number.
pub(super) fn check(
    entries: &[Entry<'_>],
    origin: &str,
    omega_m: f64,
    h: f64,
    massive: bool,
) -> Result<()> {
    for &e in entries {
        let Some((_, rule)) = KEYS_CHECKED.iter().find(|(k, _)| *k == e.key) else {
            continue;
        };
        let number = || {
            parse_number(e.value).ok_or_else(|| Error::IniValue {
                origin: origin.to_string(),
                line: e.line,
                key: e.key.to_string(),
                value: quote(e.value),
            })
        };
        match *rule {
            Rule::Default { value, tol, what } => {
                let v = number()?;
                if (v - value).abs() > tol {
                    return Err(refuse(
                        origin,
                        e,
                        format!(
                            "not modelled: pt-spectra's spectra and background assume that {what} \
                             ({} = {value}); give a linear spectrum computed with this setting \
                             (--linear, Python linear=)",
                            e.key
                        ),
                    ));
                }
            }
            Rule::Instead(key) => {
                return Err(refuse(
                    origin,
                    e,
                    format!("`{}` is not read: give {key} instead", e.key),
                ))
            }
            Rule::OmegaM { physical } => {
                let v = number()?;
                let derived = if physical { omega_m * h * h } else { omega_m };
                if (v - derived).abs() > OMEGA_M_TOL * derived.abs() {
                    return Err(refuse(
                        origin,
                        e,
                        format!(
                            "{} = {v} disagrees with the {} derived from the other keys, {derived:.6} \
                             ((omega_b + omega_cdm + m_nu/93.14 eV){}; more than {OMEGA_M_TOL:e} \
                             apart): the matter density is set by omega_b, omega_cdm and the \
                             neutrino masses; give those",
                            e.key,
                            if physical { "omega_m" } else { "Omega_m" },
                            if physical { "" } else { "/h^2" },
                        ),
                    ));
                }
            }
            Rule::Eigenstates => {
                if massive && number()? != 1.0 {
                    return Err(refuse(
                        origin,
                        e,
                        "CAMB's mass eigenstates of different masses are not emulated: only one \
                         eigenstate (nu_mass_eigenstates = 1: massive_neutrinos species of equal \
                         mass) is supported"
                            .into(),
                    ));
                }
            }
            Rule::Fractions => {
                let fractions: Option<Vec<f64>> = e
                    .value
                    .split([',', ' ', '\t'])
                    .filter(|s| !s.is_empty())
                    .map(parse_number)
                    .collect();
                if massive && fractions.as_deref() != Some(&[1.0]) {
                    return Err(refuse(
                        origin,
                        e,
                        "CAMB's fractions of Sigma m_nu per mass eigenstate: only one eigenstate \
                         carrying it all (nu_mass_fractions = 1) is supported"
                            .into(),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The keys given in the wrong case: a key that is not read but equals a read key (or one of this
/// module's, or a neutrino species key) ignoring case is refused naming the key meant.
///
/// # Errors
/// [`Error::InvalidChoice`] naming the line, the key and the keys it may mean.
pub(super) fn check_case(entries: &[Entry<'_>], origin: &str, species: &[&str]) -> Result<()> {
    let known = || {
        KEYS.iter()
            .map(|(k, _, _)| *k)
            .chain(KEYS_CHECKED.iter().map(|(k, _)| *k))
            .chain(species.iter().copied())
    };
    for &e in entries {
        if known().any(|k| k == e.key) {
            continue;
        }
        let lower = e.key.to_lowercase();
        let meant: Vec<String> = known()
            .filter(|k| k.to_lowercase() == lower)
            .map(|k| format!("`{k}`"))
            .collect();
        if !meant.is_empty() {
            return Err(refuse(
                origin,
                e,
                format!(
                    "unknown key `{}`: keys are case-sensitive (as in CLASS and CAMB); did you mean {}?",
                    e.key,
                    meant.join(" or ")
                ),
            ));
        }
    }
    Ok(())
}

/// Whether `key` is one of this module's (read here, so never a misspelling).
pub(super) fn is_checked(key: &str) -> bool {
    KEYS_CHECKED.iter().any(|(k, _)| *k == key)
}
