//! Cosmologies from CLASS or CAMB parameter files (`.ini`), or from key–value pairs.
//!
//! Format: one `key = value` per line; `#` starts a comment (also after a value); blank lines are skipped.
//! Keys are case-sensitive, as in CLASS and CAMB; blanks around keys and values are trimmed. Values are
//! decimal numbers (a Fortran exponent `1.0d-9` is accepted too). Only the keys that set the background
//! and the growth are read; each row of the table sets one quantity, and giving two keys of a row is
//! accepted only when they agree to [`SYNONYM_TOL`] relative:
//!
//! | quantity | CLASS | CAMB: Python names; `params.ini` names |
//! | --- | --- | --- |
//! | h | `h`, `H0` (km/s/Mpc) | `H0`; `hubble` |
//! | ω_b = Ω_b h² | `omega_b`, `Omega_b` | `ombh2` |
//! | ω_cdm = Ω_cdm h² | `omega_cdm`, `Omega_cdm` | `omch2` |
//! | Ω_k (default 0) | `Omega_k` | `omk` |
//! | n_s | `n_s` | `ns`; `scalar_spectral_index(1)` |
//! | σ8 | `sigma8` | – |
//! | A_s | `A_s`, `ln10^{10}A_s` | `As`; `scalar_amp(1)` |
//! | k_pivot, 1/Mpc (default 0.05) | `k_pivot` | `pivot_scalar` |
//! | w0 (default −1) | `w0_fld` | `w` |
//! | wa (default 0) | `wa_fld` | `wa` |
//! | Σm_ν in eV (default 0) | `m_ncdm` (list, eV per species; with `N_ncdm`, `deg_ncdm`) | `mnu`; `omnuh2` (ω_ν, Σm_ν = 93.14 eV ω_ν) |
//! | Σm_ν in eV, pt-spectra's name | `m_nu` | |
//!
//! How Σm_ν is shared among the species ([`Neutrinos`](super::Neutrinos)) and N_eff follow the
//! convention of the code whose keys are given (`N_ncdm`, `deg_ncdm`, `N_ur`; `num_massive_neutrinos`,
//! `neutrino_hierarchy`, `nnu`; pt-spectra's `neutrinos`): CAMB's `mnu` alone is one massive species,
//! as in CAMB; the table is in the private module `ini::neutrinos` (and in `docs/emulator.md`).
//!
//! h, ω_b, ω_cdm, n_s and one of σ8 or A_s are needed; σ8 and A_s together are a conflict. Derived:
//! Ω_m = (ω_b + ω_cdm + ω_ν)/h² with ω_ν = Σm_ν/93.14 eV (all matter, as CLASS's `Omega_m`), and
//! Ω_DE = 1 − Ω_m − Ω_k. Massless species (`N_ur`) do not enter the background, like the photons; N_eff
//! must be the standard one.
//! Every key not in the table is ignored and listed in [`ParsedCosmology::ignored`], so that the caller
//! can say once which were ([`Cosmology::from_keys_strict`], for dicts, refuses them instead). Keys
//! that would change the spectrum in a way not modelled (`T_ncdm`, `alpha_s`, `omega_ncdm`, `Omega_m`
//! against the derived one, ...) are refused unless they state what is modelled, and a read key in the
//! wrong case (`M_ncdm`) is refused as a misspelling (private module `ini::unmodelled`). Not followed: CAMB's `DEFAULT(file)` and `INCLUDE(file)` lines (syntax
//! errors), CAMB's `use_physical = F` parameters, and CLASS's split of the dark energy into
//! `Omega_Lambda` and `Omega_fld`: `w0_fld` and `wa_fld` are taken as the equation of state of all the
//! dark energy (in CLASS they apply only when `Omega_Lambda = 0`).

use super::{Amplitude, Cosmology, PRESETS};
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// Relative tolerance within which two keys for the same quantity (e.g. `h` and `H0`, `omega_b` and
/// `Omega_b`) must agree: parameter files give ~7 significant digits, so rounding stays well inside it.
pub const SYNONYM_TOL: f64 = 1e-6;

/// Longest line text quoted in an error message, in characters.
const QUOTE_MAX_CHARS: usize = 80;

/// A cosmology read from a parameter file, with the keys that did not enter it.
#[derive(Debug, Clone, PartialEq)]
pub struct ParsedCosmology {
    /// The validated cosmology.
    pub cosmology: Cosmology,
    /// The keys that were ignored, in the order of the input.
    pub ignored: Vec<String>,
}

/// The quantities that keys set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Quantity {
    Hubble,
    OmegaB,
    OmegaCdm,
    OmegaK,
    SpectralIndex,
    Sigma8,
    PrimordialAmplitude,
    Pivot,
    W0,
    Wa,
    NeutrinoMass,
}

impl Quantity {
    /// What the quantity is, for messages.
    fn description(self) -> &'static str {
        match self {
            Self::Hubble => "the Hubble constant",
            Self::OmegaB => "the baryon density",
            Self::OmegaCdm => "the cold-dark-matter density",
            Self::OmegaK => "the curvature density Omega_k",
            Self::SpectralIndex => "the spectral index n_s",
            Self::Sigma8 => "sigma8",
            Self::PrimordialAmplitude => "the primordial amplitude A_s",
            Self::Pivot => "the pivot scale of A_s",
            Self::W0 => "the dark-energy equation of state w0",
            Self::Wa => "the dark-energy equation-of-state slope wa",
            Self::NeutrinoMass => "the sum of the neutrino masses",
        }
    }

    /// The keys that set it, for messages (empty for the optional quantities, which are never missing).
    fn keys(self) -> &'static str {
        match self {
            Self::Hubble => "`h`, `H0` (CLASS, CAMB) or `hubble` (CAMB)",
            Self::OmegaB => "`omega_b`, `Omega_b` (CLASS) or `ombh2` (CAMB)",
            Self::OmegaCdm => "`omega_cdm`, `Omega_cdm` (CLASS) or `omch2` (CAMB)",
            Self::SpectralIndex => "`n_s` (CLASS), `ns` or `scalar_spectral_index(1)` (CAMB)",
            Self::Sigma8 | Self::PrimordialAmplitude => {
                "`sigma8`, `A_s`, `ln10^{10}A_s` (CLASS), `As` or `scalar_amp(1)` (CAMB)"
            }
            Self::OmegaK | Self::Pivot | Self::W0 | Self::Wa | Self::NeutrinoMass => "",
        }
    }

    /// The name of the quantity in [`PLAUSIBLE`](super::PLAUSIBLE).
    fn plausible_name(self) -> &'static str {
        match self {
            Self::Hubble => "h",
            Self::OmegaB => "omega_b",
            Self::OmegaCdm => "omega_cdm",
            Self::OmegaK => "Omega_k",
            Self::SpectralIndex => "n_s",
            Self::Sigma8 => "sigma8",
            Self::PrimordialAmplitude => "A_s",
            Self::Pivot => "k_pivot",
            Self::W0 => "w0",
            Self::Wa => "wa",
            Self::NeutrinoMass => "m_nu",
        }
    }
}

/// How a key's value converts to its quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Unit {
    /// The value is the quantity.
    Same,
    /// H0 in km/s/Mpc: h = H0/100.
    KmPerSecPerMpc,
    /// A density parameter Ω: ω = Ω h².
    TimesH2,
    /// ln(10¹⁰ A_s).
    Ln1e10,
    /// ω_ν = Ω_ν h²: Σm_ν = 93.14 eV ω_ν.
    OmegaNu,
    /// CLASS's masses of the `N_ncdm` species in eV, a comma-separated list, each times its
    /// `deg_ncdm` (default 1): Σm_ν is the sum.
    NcdmList,
}

/// The keys that are read (see the module docs).
const KEYS: [(&str, Quantity, Unit); 29] = [
    ("h", Quantity::Hubble, Unit::Same),
    ("H0", Quantity::Hubble, Unit::KmPerSecPerMpc),
    ("hubble", Quantity::Hubble, Unit::KmPerSecPerMpc),
    ("omega_b", Quantity::OmegaB, Unit::Same),
    ("Omega_b", Quantity::OmegaB, Unit::TimesH2),
    ("ombh2", Quantity::OmegaB, Unit::Same),
    ("omega_cdm", Quantity::OmegaCdm, Unit::Same),
    ("Omega_cdm", Quantity::OmegaCdm, Unit::TimesH2),
    ("omch2", Quantity::OmegaCdm, Unit::Same),
    ("Omega_k", Quantity::OmegaK, Unit::Same),
    ("omk", Quantity::OmegaK, Unit::Same),
    ("n_s", Quantity::SpectralIndex, Unit::Same),
    ("ns", Quantity::SpectralIndex, Unit::Same),
    (
        "scalar_spectral_index(1)",
        Quantity::SpectralIndex,
        Unit::Same,
    ),
    ("sigma8", Quantity::Sigma8, Unit::Same),
    ("A_s", Quantity::PrimordialAmplitude, Unit::Same),
    ("ln10^{10}A_s", Quantity::PrimordialAmplitude, Unit::Ln1e10),
    ("As", Quantity::PrimordialAmplitude, Unit::Same),
    ("scalar_amp(1)", Quantity::PrimordialAmplitude, Unit::Same),
    ("k_pivot", Quantity::Pivot, Unit::Same),
    ("pivot_scalar", Quantity::Pivot, Unit::Same),
    ("w0_fld", Quantity::W0, Unit::Same),
    ("w", Quantity::W0, Unit::Same),
    ("wa_fld", Quantity::Wa, Unit::Same),
    ("wa", Quantity::Wa, Unit::Same),
    ("m_ncdm", Quantity::NeutrinoMass, Unit::NcdmList),
    ("mnu", Quantity::NeutrinoMass, Unit::Same),
    ("omnuh2", Quantity::NeutrinoMass, Unit::OmegaNu),
    ("m_nu", Quantity::NeutrinoMass, Unit::Same),
];

/// One `key = value` of the input.
#[derive(Debug, Clone, Copy)]
struct Entry<'a> {
    key: &'a str,
    value: &'a str,
    /// 1-based line of a file, or 1-based index of a key–value pair.
    line: usize,
}

impl Entry<'_> {
    fn text(&self) -> String {
        quote(&format!("{} = {}", self.key, self.value))
    }
}

/// A read key: its entry, quantity, unit and number as written.
#[derive(Debug, Clone, Copy)]
struct Found<'a> {
    entry: Entry<'a>,
    quantity: Quantity,
    unit: Unit,
    number: f64,
}

impl Cosmology {
    /// Reads a CLASS or CAMB parameter file (see the [module docs](crate::cosmology::ini) for the keys).
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read, otherwise as [`from_ini_str`](Self::from_ini_str) with the
    /// path as origin.
    pub fn from_ini_file(path: impl AsRef<Path>) -> Result<ParsedCosmology> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_ini_str(
            &String::from_utf8_lossy(&bytes),
            &path.display().to_string(),
        )
    }

    /// Parses the text of a CLASS or CAMB parameter file; `origin` names it in error messages.
    ///
    /// # Errors
    /// [`Error::IniSyntax`] for a line that is not `key = value`, otherwise as
    /// [`from_keys`](Self::from_keys), with line numbers of the text.
    ///
    /// ```
    /// use pt_spectra::cosmology::Cosmology;
    /// let text = "h = 0.6766\nomega_b = 0.02242\nomega_cdm = 0.11933 # CDM\nn_s = 0.9665\n\
    ///             A_s = 2.105209e-9\noutput = mPk\n";
    /// let parsed = Cosmology::from_ini_str(text, "class.ini")?;
    /// assert!((parsed.cosmology.omega_m - 0.309641).abs() < 1e-6);
    /// assert_eq!(parsed.ignored, ["output"]);
    /// # Ok::<(), pt_spectra::error::Error>(())
    /// ```
    pub fn from_ini_str(text: &str, origin: &str) -> Result<ParsedCosmology> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut entries = Vec::new();
        for (index, raw) in text.lines().enumerate() {
            let line = index + 1;
            let content = raw.split_once('#').map_or(raw, |(before, _)| before).trim();
            if content.is_empty() {
                continue;
            }
            let syntax = || Error::IniSyntax {
                origin: origin.to_string(),
                line,
                text: quote(raw.trim()),
            };
            let (key, value) = content.split_once('=').ok_or_else(syntax)?;
            let key = key.trim();
            if key.is_empty() {
                return Err(syntax());
            }
            entries.push(Entry {
                key,
                value: value.trim(),
                line,
            });
        }
        resolve(&entries, origin, false)
    }

    /// A cosmology from key–value pairs with the keys and values of a parameter file (e.g. a Python
    /// dict's items); `origin` names them in error messages, where "line" is the 1-based index of the pair.
    /// Takes pairs by value (`Vec<(String, String)>`, a `HashMap` or `&HashMap`, an array of `(&str, &str)`);
    /// for a slice `s` of pairs pass `s.iter().map(|(k, v)| (k, v))`.
    ///
    /// # Errors
    /// * [`Error::IniSyntax`] for an empty key;
    /// * [`Error::DuplicateKey`] for a key given twice;
    /// * [`Error::IniValue`] for a value of a read key that is not a finite number;
    /// * [`Error::ConflictingKeys`] for two keys that set the same quantity to values that differ by more
    ///   than [`SYNONYM_TOL`] relative, or for both σ8 and A_s;
    /// * [`Error::MissingKey`] without h, ω_b, ω_cdm, n_s, or σ8/A_s;
    /// * [`Error::InvalidCosmology`] if the values do not pass [`validate`](Self::validate).
    pub fn from_keys<K: AsRef<str>, V: AsRef<str>>(
        pairs: impl IntoIterator<Item = (K, V)>,
        origin: &str,
    ) -> Result<ParsedCosmology> {
        from_pairs(pairs, origin, false)
    }

    /// As [`from_keys`](Self::from_keys), for a dict a program builds (Python's `cosmology=dict(...)`):
    /// every key must be read, so a misspelling (`m_ncmd`) is an error naming it instead of a key
    /// listed as ignored; [`ParsedCosmology::ignored`] then holds only keys that are read but do not
    /// matter (a pivot with σ8, the species of zero masses, a default stated).
    ///
    /// # Errors
    /// As [`from_keys`](Self::from_keys), and [`Error::InvalidChoice`] naming the unknown keys.
    pub fn from_keys_strict<K: AsRef<str>, V: AsRef<str>>(
        pairs: impl IntoIterator<Item = (K, V)>,
        origin: &str,
    ) -> Result<ParsedCosmology> {
        from_pairs(pairs, origin, true)
    }

    /// A preset (one of [`PRESETS`]), or else the parameter file at the path `name_or_path`.
    ///
    /// # Errors
    /// [`Error::UnknownCosmology`] for a name that is neither a preset nor an existing path and has no
    /// `/`, `\` or `.` (so does not look like a path); otherwise as
    /// [`from_ini_file`](Self::from_ini_file).
    pub fn from_name_or_file(name_or_path: &str) -> Result<ParsedCosmology> {
        if PRESETS.contains(&name_or_path) {
            return Ok(ParsedCosmology {
                cosmology: Self::preset(name_or_path)?,
                ignored: Vec::new(),
            });
        }
        let path = Path::new(name_or_path);
        if path.exists() || name_or_path.contains(['/', '\\', '.']) {
            return Self::from_ini_file(path);
        }
        Self::preset(name_or_path).map(|cosmology| ParsedCosmology {
            cosmology,
            ignored: Vec::new(),
        })
    }
}

/// [`Cosmology::from_keys`] and [`Cosmology::from_keys_strict`].
fn from_pairs<K: AsRef<str>, V: AsRef<str>>(
    pairs: impl IntoIterator<Item = (K, V)>,
    origin: &str,
    strict: bool,
) -> Result<ParsedCosmology> {
    let pairs: Vec<(K, V)> = pairs.into_iter().collect();
    let mut entries = Vec::with_capacity(pairs.len());
    for (index, (key, value)) in pairs.iter().enumerate() {
        let (key, value) = (key.as_ref().trim(), value.as_ref().trim());
        if key.is_empty() {
            return Err(Error::IniSyntax {
                origin: origin.to_string(),
                line: index + 1,
                text: quote(&format!("= {value}")),
            });
        }
        entries.push(Entry {
            key,
            value,
            line: index + 1,
        });
    }
    resolve(&entries, origin, strict)
}

/// `text`, cut to [`QUOTE_MAX_CHARS`] characters (with `…`) for messages.
fn quote(text: &str) -> String {
    match text.char_indices().nth(QUOTE_MAX_CHARS) {
        Some((end, _)) => format!("{}…", &text[..end]),
        None => text.to_string(),
    }
}

/// The quantity and unit of a read key.
fn lookup(key: &str) -> Option<(Quantity, Unit)> {
    KEYS.iter()
        .find(|(name, _, _)| *name == key)
        .map(|&(_, quantity, unit)| (quantity, unit))
}

/// A finite number, also with a Fortran exponent (`1.0d-9`).
fn parse_number(text: &str) -> Option<f64> {
    let value = text
        .parse::<f64>()
        .ok()
        .or_else(|| text.replace(['d', 'D'], "e").parse().ok())?;
    value.is_finite().then_some(value)
}

/// Whether two values of the same quantity agree to [`SYNONYM_TOL`].
fn agree(x: f64, y: f64) -> bool {
    (x - y).abs() <= SYNONYM_TOL * x.abs().max(y.abs())
}

/// Checks the entries and builds the cosmology (see [`Cosmology::from_keys`]); with `strict`, a key
/// that is not read is an error naming it (a dict's misspelling) rather than listed as ignored.
fn resolve(entries: &[Entry<'_>], origin: &str, strict: bool) -> Result<ParsedCosmology> {
    unmodelled::check_case(entries, origin, &neutrinos::SPECIES_KEYS)?;
    let mut first_line: HashMap<&str, usize> = HashMap::new();
    let mut found: Vec<Found<'_>> = Vec::new();
    let mut ignored: Vec<(usize, &str)> = Vec::new();
    for &entry in entries {
        if let Some(&first) = first_line.get(entry.key) {
            return Err(Error::DuplicateKey {
                origin: origin.to_string(),
                key: quote(entry.key),
                first_line: first,
                line: entry.line,
            });
        }
        first_line.insert(entry.key, entry.line);
        if neutrinos::SPECIES_KEYS.contains(&entry.key) {
            continue; // read with the masses
        }
        let Some((quantity, unit)) = lookup(entry.key) else {
            ignored.push((entry.line, entry.key));
            continue;
        };
        let number = if unit == Unit::NcdmList {
            neutrinos::ncdm_sum(entry, entries, origin)?
        } else {
            parse_number(entry.value).ok_or_else(|| Error::IniValue {
                origin: origin.to_string(),
                line: entry.line,
                key: entry.key.to_string(),
                value: quote(entry.value),
            })?
        };
        found.push(Found {
            entry,
            quantity,
            unit,
            number,
        });
    }
    let values = Values { origin, found };
    let h = values.required(Quantity::Hubble, 1.0)?;
    let h2 = h * h;
    let omega_b = values.required(Quantity::OmegaB, h2)?;
    let omega_cdm = values.required(Quantity::OmegaCdm, h2)?;
    let n_s = values.required(Quantity::SpectralIndex, h2)?;
    let omega_k = values.get(Quantity::OmegaK, h2)?.unwrap_or(0.0);
    let w0 = values.get(Quantity::W0, h2)?.unwrap_or(-1.0);
    let wa = values.get(Quantity::Wa, h2)?.unwrap_or(0.0);
    let sigma8 = values.get(Quantity::Sigma8, h2)?;
    let a_s = values.get(Quantity::PrimordialAmplitude, h2)?;
    let k_pivot = values.get(Quantity::Pivot, h2)?;
    let amplitude = match (sigma8, a_s) {
        (Some(_), Some(_)) => {
            let first = values.first(Quantity::Sigma8);
            let other = values.first(Quantity::PrimordialAmplitude);
            let (first, second) = if first.line < other.line {
                (first, other)
            } else {
                (other, first)
            };
            return Err(Error::ConflictingKeys {
                origin: origin.to_string(),
                quantity: "the amplitude (give sigma8 or A_s, not both)",
                first: first.text(),
                first_line: first.line,
                second: second.text(),
                line: second.line,
            });
        }
        (Some(sigma8), None) => {
            // The pivot only matters for A_s.
            ignored.extend(values.entries(Quantity::Pivot).map(|e| (e.line, e.key)));
            Amplitude::Sigma8(sigma8)
        }
        (None, Some(a_s)) => Amplitude::As {
            a_s,
            k_pivot: k_pivot.unwrap_or(Amplitude::DEFAULT_K_PIVOT),
        },
        (None, None) => {
            return Err(Error::MissingKey {
                origin: origin.to_string(),
                quantity: "the amplitude (sigma8 or A_s)",
                keys: Quantity::Sigma8.keys(),
            })
        }
    };
    let m_nu = values.get(Quantity::NeutrinoMass, h2)?.unwrap_or(0.0);
    let mass_key = (m_nu > 0.0).then(|| values.first(Quantity::NeutrinoMass).key);
    let neutrinos = neutrinos::setting(entries, origin, mass_key)?;
    if m_nu == 0.0 {
        // how a zero mass is shared does not matter (N_eff was checked)
        let checked = ["N_eff", "nnu", "N_ur"];
        ignored.extend(
            entries
                .iter()
                .filter(|e| neutrinos::SPECIES_KEYS.contains(&e.key) && !checked.contains(&e.key))
                .map(|e| (e.line, e.key)),
        );
    }
    let omega_m = (omega_b + omega_cdm + m_nu / super::EV_PER_OMEGA_NU) / h2;
    unmodelled::check(entries, origin, omega_m, h, m_nu > 0.0)?;
    if strict {
        let unknown: Vec<String> = ignored
            .iter()
            .filter(|(_, key)| {
                lookup(key).is_none()
                    && !neutrinos::SPECIES_KEYS.contains(key)
                    && !unmodelled::is_checked(key)
            })
            .map(|(line, key)| format!("`{}` ({origin}:{line})", quote(key)))
            .collect();
        if !unknown.is_empty() {
            return Err(Error::InvalidChoice {
                what: format!("{origin}: unknown key(s) {}", unknown.join(", ")),
                reason: "they set nothing (a misspelling?); the keys read are CLASS's and CAMB's \
                         names of h, omega_b, omega_cdm, n_s, A_s or sigma8, Omega_k, w0, wa, the \
                         neutrino masses and species (pt_spectra::cosmology::ini)"
                    .into(),
            });
        }
    }
    let cosmology = Cosmology {
        omega_m,
        omega_lambda: 1.0 - omega_m - omega_k,
        h,
        omega_b_h2: omega_b,
        n_s,
        amplitude,
        w0,
        wa,
        m_nu,
        neutrinos,
    };
    cosmology
        .validate()
        .map_err(|source| Error::InvalidCosmology {
            origin: origin.to_string(),
            source: Box::new(source),
        })?;
    ignored.sort_by_key(|&(line, _)| line);
    Ok(ParsedCosmology {
        cosmology,
        ignored: ignored
            .into_iter()
            .map(|(_, key)| key.to_string())
            .collect(),
    })
}

/// The read keys of one input.
struct Values<'a> {
    origin: &'a str,
    found: Vec<Found<'a>>,
}

impl<'a> Values<'a> {
    /// The entries that set `quantity`, in input order.
    fn entries(&self, quantity: Quantity) -> impl Iterator<Item = Entry<'a>> + '_ {
        self.found
            .iter()
            .filter(move |f| f.quantity == quantity)
            .map(|f| f.entry)
    }

    /// The first entry that sets `quantity` (which must be present).
    fn first(&self, quantity: Quantity) -> Entry<'a> {
        self.entries(quantity)
            .next()
            .expect("the caller checked that the quantity is given")
    }

    /// The value of `quantity` (converted with `h2` = h² where a key gives Ω rather than ω), if any key
    /// sets it.
    ///
    /// # Errors
    /// [`Error::Implausible`] for a value outside the quantity's [`PLAUSIBLE`](super::PLAUSIBLE)
    /// range; [`Error::ConflictingKeys`] if two keys for it disagree.
    fn get(&self, quantity: Quantity, h2: f64) -> Result<Option<f64>> {
        let mut first: Option<(Entry<'a>, f64)> = None;
        for f in self.found.iter().filter(|f| f.quantity == quantity) {
            let value = match f.unit {
                Unit::Same => f.number,
                Unit::KmPerSecPerMpc => f.number / 100.0,
                Unit::TimesH2 => f.number * h2,
                Unit::Ln1e10 => f.number.exp() * 1e-10,
                Unit::OmegaNu => f.number * super::EV_PER_OMEGA_NU,
                Unit::NcdmList => f.number,
            };
            if let Some(range) = super::plausible(quantity.plausible_name()) {
                if !range.contains(value) {
                    return Err(Error::Implausible {
                        origin: self.origin.to_string(),
                        line: f.entry.line,
                        key: match f.unit {
                            Unit::Same => format!("`{}`", f.entry.text()),
                            _ => format!(
                                "`{}` ({} = {})",
                                f.entry.text(),
                                range.name,
                                crate::error::number(&value)
                            ),
                        },
                        quantity: range.name,
                        range: range.describe(),
                        hint: range.hint(value),
                    });
                }
            }
            match first {
                None => first = Some((f.entry, value)),
                Some((entry, v)) if !agree(v, value) => {
                    return Err(Error::ConflictingKeys {
                        origin: self.origin.to_string(),
                        quantity: quantity.description(),
                        first: entry.text(),
                        first_line: entry.line,
                        second: f.entry.text(),
                        line: f.entry.line,
                    })
                }
                Some(_) => {}
            }
        }
        Ok(first.map(|(_, v)| v))
    }

    /// As [`get`](Self::get), for a quantity that must be given.
    ///
    /// # Errors
    /// [`Error::MissingKey`] if no key sets it, or as [`get`](Self::get).
    fn required(&self, quantity: Quantity, h2: f64) -> Result<f64> {
        self.get(quantity, h2)?.ok_or_else(|| Error::MissingKey {
            origin: self.origin.to_string(),
            quantity: quantity.description(),
            keys: quantity.keys(),
        })
    }
}

mod neutrinos;
#[cfg(test)]
mod tests;
mod unmodelled;
