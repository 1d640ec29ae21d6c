//! The neutrino keys of a parameter file: how Σm_ν is shared among the species ([`Neutrinos`]) and
//! N_eff, each read by the convention of the code whose key it is.
//!
//! | code | keys | setting |
//! | --- | --- | --- |
//! | CAMB | `mnu` or `omnuh2` alone | one massive species (CAMB's default `num_massive_neutrinos = 1`) |
//! | CAMB | `num_massive_neutrinos` (`massive_neutrinos` in `params.ini`) = 1 or 3 | one, or three degenerate |
//! | CAMB | `neutrino_hierarchy` = `degenerate`, `normal`, `inverted` | as named (with `degenerate`, `num_massive_neutrinos` decides) |
//! | CAMB | `nnu` (or `params.ini`'s `massless_neutrinos` + `massive_neutrinos`) | N_eff |
//! | CLASS | `m_ncdm` with `N_ncdm`, `deg_ncdm` | one species of degeneracy 1: one massive; three equal masses (or `deg_ncdm = 3`): three degenerate |
//! | CLASS | `N_ur` | N_eff = `N_ur` + 1.0132 per massive species; CLASS keeps its default `N_ur` = 3.044 whatever `N_ncdm` is, so a file with `m_ncdm` must give `N_ur` (2.0328 for one species, 0.00641 for three) |
//! | pt-spectra | `m_nu` (Σm_ν), `neutrinos` = `three degenerate` or `one massive` | `m_nu` alone: three degenerate, as [`Cosmology::with_neutrinos`](crate::cosmology::Cosmology::with_neutrinos) |
//!
//! N_eff must be standard ([`standard_n_eff`]: 3.044 to 3.046); any other value, another number of
//! species, unequal CLASS masses, and keys of different codes that disagree are errors naming the key.

use super::{parse_number, quote, Entry};
use crate::cosmology::neutrinos::{standard_n_eff, N_EFF_PER_NCDM, N_EFF_STANDARD};
use crate::cosmology::Neutrinos;
use crate::error::{Error, Result};

/// The keys read here besides the masses (`m_ncdm`, `mnu`, `omnuh2`, `m_nu` are in the key table).
pub(super) const SPECIES_KEYS: [&str; 12] = [
    "N_ncdm",
    "deg_ncdm",
    "N_ur",
    "num_massive_neutrinos",
    "massive_neutrinos",
    "massless_neutrinos",
    "neutrino_hierarchy",
    "nnu",
    "neutrinos",
    "N_eff",
    "num_nu_massive",
    "num_nu_massless",
];

/// The masses of CLASS's `m_ncdm` list (eV per species), each repeated by its `deg_ncdm` (a number for
/// all species or a list, default 1).
///
/// # Errors
/// Why the list is refused: a number that does not parse (the list is comma-separated, as in
/// CLASS), a degeneracy that is not a positive integer, lengths that disagree with each other or
/// with `N_ncdm`, or masses without `N_ncdm` (CLASS reads `m_ncdm` only when `N_ncdm` > 0: its
/// default `N_ncdm = 0` leaves the neutrinos massless).
pub(super) fn ncdm_masses(
    m_ncdm: Entry<'_>,
    entries: &[Entry<'_>],
) -> std::result::Result<Vec<f64>, String> {
    let list = |e: Entry<'_>| -> std::result::Result<Vec<f64>, String> {
        e.value
            .split(',')
            .map(|v| {
                parse_number(v.trim()).ok_or_else(|| {
                    format!(
                        "`{}` in `{}` is not a finite number ({} is a comma-separated list, as in \
                         CLASS: e.g. `0.02, 0.02, 0.02`)",
                        quote(v.trim()),
                        e.key,
                        e.key
                    )
                })
            })
            .collect()
    };
    let masses = list(m_ncdm)?;
    match find(entries, "N_ncdm") {
        Some(n) => {
            let count = parse_number(n.value)
                .filter(|c| *c >= 0.0 && c.fract() == 0.0)
                .ok_or_else(|| {
                    format!(
                        "N_ncdm = {} (line {}) is not a number of species",
                        quote(n.value),
                        n.line
                    )
                })?;
            if count != masses.len() as f64 {
                return Err(format!(
                    "N_ncdm = {} (line {}) but m_ncdm lists {} mass(es): CLASS reads N_ncdm masses \
                     (and none with N_ncdm = 0)",
                    n.value,
                    n.line,
                    masses.len()
                ));
            }
        }
        None if masses.iter().any(|&m| m != 0.0) => {
            return Err(format!(
                "N_ncdm is not given: CLASS reads m_ncdm only when N_ncdm > 0 (its default N_ncdm = 0 \
                 leaves the neutrinos massless); give N_ncdm = {}",
                masses.len()
            ));
        }
        None => {}
    }
    let degeneracy = match find(entries, "deg_ncdm") {
        None => vec![1.0; masses.len()],
        Some(e) => {
            let d = list(e)?;
            match d.len() {
                1 => vec![d[0]; masses.len()],
                n if n == masses.len() => d,
                n => {
                    return Err(format!(
                        "deg_ncdm (line {}) lists {n} degeneracies for {} mass(es)",
                        e.line,
                        masses.len()
                    ))
                }
            }
        }
    };
    let mut out = Vec::new();
    for (&m, &g) in masses.iter().zip(&degeneracy) {
        if !(g >= 1.0 && g.fract() == 0.0 && g <= 10.0) {
            return Err(format!(
                "deg_ncdm = {g}: a degeneracy is a whole number of species from 1 to 10"
            ));
        }
        out.extend(std::iter::repeat_n(m, g as usize));
    }
    Ok(out)
}

/// Σm_ν of [`ncdm_masses`], rounded to 1e-12 eV (3 × 0.1 is 0.3, not 0.30000000000000004).
///
/// # Errors
/// As [`ncdm_masses`], as an [`Error::InvalidChoice`] naming the file, line and key.
pub(super) fn ncdm_sum(m_ncdm: Entry<'_>, entries: &[Entry<'_>], origin: &str) -> Result<f64> {
    let masses = ncdm_masses(m_ncdm, entries).map_err(|reason| refuse(origin, m_ncdm, reason))?;
    let sum: f64 = masses.iter().sum();
    let sum = (sum * 1e12).round() / 1e12;
    if sum.is_finite() {
        Ok(sum)
    } else {
        Err(refuse(origin, m_ncdm, "the masses must be finite".into()))
    }
}

fn find<'a>(entries: &[Entry<'a>], key: &str) -> Option<Entry<'a>> {
    entries.iter().find(|e| e.key == key).copied()
}

/// The refusal of `entry`: the file, line, `key = value` and why.
fn refuse(origin: &str, entry: Entry<'_>, reason: String) -> Error {
    Error::InvalidChoice {
        what: format!("{origin}:{}: `{}`", entry.line, entry.text()),
        reason,
    }
}

/// The number of `entry` (an [`Error::IniValue`] naming it otherwise).
fn number(origin: &str, entry: Entry<'_>) -> Result<f64> {
    parse_number(entry.value).ok_or_else(|| Error::IniValue {
        origin: origin.to_string(),
        line: entry.line,
        key: entry.key.to_string(),
        value: quote(entry.value),
    })
}

/// What the supported settings are, for refusals.
const SUPPORTED: &str = "supported: one massive species (CAMB num_massive_neutrinos = 1, its default; \
     CLASS N_ncdm = 1 with N_ur = 2.0328) or three degenerate (CAMB num_massive_neutrinos = 3; CLASS \
     three equal m_ncdm or deg_ncdm = 3 with N_ur = 0.00641), with the standard N_eff = 3.044-3.046";

/// The N_eff check of one key.
fn check_n_eff(origin: &str, entry: Entry<'_>, n_eff: f64, how: &str) -> Result<()> {
    if standard_n_eff(n_eff) {
        return Ok(());
    }
    Err(refuse(
        origin,
        entry,
        format!(
            "N_eff = {n_eff:.4}{how}: only the standard N_eff = {N_EFF_STANDARD} (3.044 accepted as \
             equivalent) is supported; {SUPPORTED}"
        ),
    ))
}

/// The setting of the CAMB keys, if any is given; `mass_key` is the key that gave Σm_ν (`mnu` or
/// `omnuh2` alone mean CAMB's default, one massive species, unless `explicit`: pt-spectra's own key
/// `neutrinos` is given).
fn camb(
    entries: &[Entry<'_>],
    origin: &str,
    mass_key: Option<&str>,
    explicit: bool,
) -> Result<Option<Neutrinos>> {
    let count = find(entries, "num_massive_neutrinos")
        .or(find(entries, "massive_neutrinos"))
        .or(find(entries, "num_nu_massive"));
    let hierarchy = find(entries, "neutrino_hierarchy");
    if let Some(nnu) = find(entries, "nnu") {
        check_n_eff(origin, nnu, number(origin, nnu)?, "")?;
    }
    if let Some(massless) = find(entries, "massless_neutrinos").or(find(entries, "num_nu_massless"))
    {
        let massive = count.map(|c| number(origin, c)).transpose()?.unwrap_or(1.0);
        let how = format!(" (massless_neutrinos + {massive} massive)");
        check_n_eff(origin, massless, number(origin, massless)? + massive, &how)?;
    }
    // CAMB's mass keys mean CAMB's default (one massive species) wherever they are given: beside
    // CLASS's keys too, whose setting must then agree (`mnu = 0.06` with three equal `m_ncdm` is two
    // settings, not one)
    let camb_mass = mass_key.is_some()
        && entries.iter().any(|e| matches!(e.key, "mnu" | "omnuh2"))
        && !explicit;
    if count.is_none() && hierarchy.is_none() && !camb_mass {
        return Ok(None);
    }
    if let Some(h) = hierarchy {
        match h.value.trim_matches(['"', '\'']) {
            "normal" => return Ok(Some(Neutrinos::NormalHierarchy)),
            "inverted" => return Ok(Some(Neutrinos::InvertedHierarchy)),
            "degenerate" => {}
            _ => {
                return Err(refuse(
                    origin,
                    h,
                    "CAMB's neutrino_hierarchy is degenerate, normal or inverted".into(),
                ))
            }
        }
    }
    match count.map(|c| (c, number(origin, c))) {
        None => Ok(Some(Neutrinos::OneMassive)),
        Some((_, Ok(1.0))) => Ok(Some(Neutrinos::OneMassive)),
        Some((_, Ok(3.0))) => Ok(Some(Neutrinos::ThreeDegenerate)),
        Some((c, n)) => {
            n?;
            Err(refuse(
                origin,
                c,
                format!(
                    "{} degenerate massive species are not emulated; {SUPPORTED}",
                    c.value
                ),
            ))
        }
    }
}

/// The setting of the CLASS keys, if `m_ncdm` or `N_ur` is given.
fn class(entries: &[Entry<'_>], origin: &str) -> Result<Option<Neutrinos>> {
    let m_ncdm = find(entries, "m_ncdm");
    let n_ur = find(entries, "N_ur");
    let masses = match m_ncdm {
        // (a list that does not parse was refused with the masses)
        Some(m) => ncdm_masses(m, entries).unwrap_or_default(),
        None => Vec::new(),
    };
    let n_eff = n_ur.map(|e| number(origin, e)).transpose()?;
    let Some(m) = m_ncdm else {
        if let (Some(entry), Some(n)) = (n_ur, n_eff) {
            check_n_eff(origin, entry, n, " (N_ur, no massive species)")?;
        }
        return Ok(None);
    };
    let species = masses.len() as f64;
    let Some(n_ur_value) = n_eff else {
        return Err(refuse(
            origin,
            m,
            format!(
                "N_ur is not given: CLASS then keeps its default N_ur = 3.044 massless species beside \
                 the {species} massive one(s), N_eff = {:.3}; give N_ur = 2.0328 with one massive \
                 species or 0.00641 with three (N_eff = 3.046); {SUPPORTED}",
                3.044 + N_EFF_PER_NCDM * species
            ),
        ));
    };
    let how = format!(" (N_ur + {species} x {N_EFF_PER_NCDM} for the massive species)");
    check_n_eff(
        origin,
        n_ur.expect("read"),
        n_ur_value + N_EFF_PER_NCDM * species,
        &how,
    )?;
    match masses.as_slice() {
        [_] => Ok(Some(Neutrinos::OneMassive)),
        [a, b, c] if a == b && b == c => Ok(Some(Neutrinos::ThreeDegenerate)),
        _ => Err(refuse(
            origin,
            m,
            format!(
                "{} massive species of masses {masses:?} eV are not emulated; {SUPPORTED}",
                masses.len()
            ),
        )),
    }
}

/// The setting of pt-spectra's own key `neutrinos`, if given.
fn own(entries: &[Entry<'_>], origin: &str) -> Result<Option<Neutrinos>> {
    let Some(e) = find(entries, "neutrinos") else {
        return Ok(None);
    };
    let setting = match e.value.trim_matches(['"', '\'']) {
        "three degenerate" | "three_degenerate" | "degenerate" | "3" => Neutrinos::ThreeDegenerate,
        "one massive" | "one_massive" | "one" | "1" => Neutrinos::OneMassive,
        "normal" | "normal hierarchy" => Neutrinos::NormalHierarchy,
        "inverted" | "inverted hierarchy" => Neutrinos::InvertedHierarchy,
        _ => {
            return Err(refuse(
                origin,
                e,
                "neutrinos is `three degenerate`, `one massive`, `normal` or `inverted`".into(),
            ))
        }
    };
    Ok(Some(setting))
}

/// The neutrino setting of the entries (see the module docs); `mass_key` is the key that set Σm_ν
/// (`None` for Σm_ν = 0: then only N_eff is checked and the default setting returned).
///
/// # Errors
/// [`Error::InvalidChoice`] naming the key for an unsupported setting or N_eff, or for keys of
/// different codes that disagree; [`Error::IniValue`] for a value that is not a number.
pub(super) fn setting(
    entries: &[Entry<'_>],
    origin: &str,
    mass_key: Option<&str>,
) -> Result<Neutrinos> {
    if find(entries, "m_ncdm").is_none() {
        if let Some(n) = find(entries, "N_ncdm") {
            if number(origin, n)? != 0.0 {
                return Err(refuse(
                    origin,
                    n,
                    "N_ncdm > 0 without m_ncdm: CLASS's masses then default to 0 (massless non-cold \
                     species, which add to N_eff); give the masses in m_ncdm (omega_ncdm and \
                     Omega_ncdm are not read)"
                        .into(),
                ));
            }
        }
    }
    if let Some(e) = find(entries, "N_eff") {
        check_n_eff(origin, e, number(origin, e)?, "")?;
    }
    if mass_key.is_none() {
        // massless: only N_eff matters (CLASS's N_ur counts massless ncdm species too, so it is
        // checked only without them)
        if let Some(e) = find(entries, "nnu") {
            check_n_eff(origin, e, number(origin, e)?, "")?;
        }
        if let (Some(e), None, None) = (
            find(entries, "N_ur"),
            find(entries, "N_ncdm"),
            find(entries, "m_ncdm"),
        ) {
            check_n_eff(origin, e, number(origin, e)?, " (N_ur, no massive species)")?;
        }
        return Ok(Neutrinos::default());
    }
    let own = own(entries, origin)?;
    let found = [
        own,
        camb(entries, origin, mass_key, own.is_some())?,
        class(entries, origin)?,
    ];
    let mut chosen: Option<Neutrinos> = None;
    for s in found.into_iter().flatten() {
        match chosen {
            Some(c) if c != s => {
                let keys: Vec<String> = entries
                    .iter()
                    .filter(|e| {
                        SPECIES_KEYS.contains(&e.key)
                            || matches!(e.key, "m_ncdm" | "mnu" | "omnuh2" | "m_nu")
                    })
                    .map(|e| format!("`{}` (line {})", e.text(), e.line))
                    .collect();
                return Err(Error::InvalidChoice {
                    what: format!("{origin}: {}", keys.join(", ")),
                    reason: format!(
                        "these keys give different neutrino settings ({c} and {s}); give one"
                    ),
                });
            }
            _ => chosen = Some(s),
        }
    }
    Ok(chosen.unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use crate::cosmology::{Cosmology, Neutrinos};

    const CLASS: &str = "h = 0.67\nomega_b = 0.022\nomega_cdm = 0.12\nn_s = 0.96\nA_s = 2.1e-9\n";
    const CAMB: &str = "H0 = 67\nombh2 = 0.022\nomch2 = 0.12\nns = 0.96\nAs = 2.1e-9\n";

    fn parse(base: &str, extra: &str) -> crate::error::Result<Cosmology> {
        Cosmology::from_ini_str(&format!("{base}{extra}"), "nu.ini").map(|p| p.cosmology)
    }

    fn setting(base: &str, extra: &str) -> Neutrinos {
        let c = parse(base, extra).unwrap_or_else(|e| panic!("{extra}: {e}"));
        assert!(c.m_nu > 0.0, "{extra}");
        c.neutrinos
    }

    /// The refusal of `extra`, which must name `key`.
    fn refused(base: &str, extra: &str, key: &str) -> String {
        let e = parse(base, extra).unwrap_err().to_string();
        assert!(e.contains(key), "{extra}: {e}");
        e
    }

    #[test]
    fn every_key_form_gives_the_setting_of_its_own_code() {
        use Neutrinos::{InvertedHierarchy, NormalHierarchy, OneMassive, ThreeDegenerate};
        // CLASS: one species (N_ur 2.0328 or 2.0308), three equal masses, deg_ncdm = 3
        for extra in [
            "N_ncdm = 1\nm_ncdm = 0.39\nN_ur = 2.0328\n",
            "N_ncdm = 1\nm_ncdm = 0.06\nN_ur = 2.0308\n",
        ] {
            assert_eq!(setting(CLASS, extra), OneMassive, "{extra}");
        }
        for extra in [
            "N_ncdm = 3\nm_ncdm = 0.13, 0.13, 0.13\nN_ur = 0.00641\n",
            "N_ncdm = 1\nm_ncdm = 0.13\ndeg_ncdm = 3\nN_ur = 0.00641\n",
            "N_ncdm = 1\nm_ncdm = 0.13\ndeg_ncdm = 3\nN_ur = 0.00441\n",
        ] {
            assert_eq!(setting(CLASS, extra), ThreeDegenerate, "{extra}");
        }
        // CAMB: mnu or omnuh2 alone is CAMB's default, one massive species
        assert_eq!(setting(CAMB, "mnu = 0.06\n"), OneMassive);
        assert_eq!(setting(CAMB, "omnuh2 = 0.00064\n"), OneMassive);
        assert_eq!(
            setting(CAMB, "mnu = 0.06\nnum_massive_neutrinos = 1\n"),
            OneMassive
        );
        assert_eq!(
            setting(CAMB, "mnu = 0.06\nnum_massive_neutrinos = 3\n"),
            ThreeDegenerate
        );
        assert_eq!(
            setting(CAMB, "mnu = 0.06\nnum_massive_neutrinos = 3\nneutrino_hierarchy = degenerate\nnnu = 3.046\n"),
            ThreeDegenerate
        );
        assert_eq!(
            setting(CAMB, "mnu = 0.1\nneutrino_hierarchy = normal\n"),
            NormalHierarchy
        );
        assert_eq!(
            setting(CAMB, "mnu = 0.1\nneutrino_hierarchy = inverted\n"),
            InvertedHierarchy
        );
        // CAMB params.ini: massive_neutrinos, massless_neutrinos
        assert_eq!(
            setting(
                CAMB,
                "omnuh2 = 0.00064\nmassless_neutrinos = 2.046\nmassive_neutrinos = 1\n"
            ),
            OneMassive
        );
        assert_eq!(
            setting(
                CAMB,
                "omnuh2 = 0.00064\nmassless_neutrinos = 0.046\nmassive_neutrinos = 3\n"
            ),
            ThreeDegenerate
        );
        // pt-spectra's own: m_nu is three degenerate (as with_neutrinos), `neutrinos` sets it
        assert_eq!(setting(CLASS, "m_nu = 0.06\n"), ThreeDegenerate);
        assert_eq!(
            setting(CLASS, "m_nu = 0.06\nneutrinos = one massive\n"),
            OneMassive
        );
        assert_eq!(
            setting(CAMB, "mnu = 0.06\nneutrinos = three degenerate\n"),
            ThreeDegenerate
        );
        // the same from key-value pairs (a Python dict)
        let pairs = [
            ("H0", "67"),
            ("ombh2", "0.022"),
            ("omch2", "0.12"),
            ("ns", "0.96"),
            ("As", "2.1e-9"),
            ("mnu", "0.06"),
        ];
        let c = Cosmology::from_keys(pairs, "dict").unwrap().cosmology;
        assert_eq!(c.neutrinos, OneMassive);
        assert!(
            c.describe().contains("m_nu = 0.06 eV (one massive)"),
            "{}",
            c.describe()
        );
        // the default of the library's own constructor is unchanged
        let c = Cosmology::planck2018().with_neutrinos(0.06).unwrap();
        assert_eq!(c.neutrinos, ThreeDegenerate);
    }

    #[test]
    fn unsupported_settings_and_n_eff_are_refused_naming_the_key() {
        // CLASS keeps N_ur = 3.044 when it is not given: N_eff = 4.057 with one massive species
        let e = refused(CLASS, "N_ncdm = 1\nm_ncdm = 0.39\n", "m_ncdm = 0.39");
        assert!(
            e.contains("N_ur") && e.contains("4.057") && e.contains("nu.ini:7"),
            "{e}"
        );
        refused(
            CLASS,
            "N_ncdm = 1\nm_ncdm = 0.06\nN_ur = 3.046\n",
            "N_ur = 3.046",
        );
        refused(
            CLASS,
            "N_ncdm = 2\nm_ncdm = 0.03, 0.03\nN_ur = 1.02\n",
            "m_ncdm",
        );
        refused(
            CLASS,
            "N_ncdm = 3\nm_ncdm = 0.01, 0.02, 0.05\nN_ur = 0.00641\n",
            "m_ncdm",
        );
        refused(
            CAMB,
            "mnu = 0.06\nnum_massive_neutrinos = 2\n",
            "num_massive_neutrinos = 2",
        );
        refused(CAMB, "mnu = 0.06\nnnu = 3.3\n", "nnu = 3.3");
        refused(
            CAMB,
            "mnu = 0.06\nneutrino_hierarchy = sideways\n",
            "neutrino_hierarchy",
        );
        refused(CAMB, "mnu = 0\nnnu = 4\n", "nnu = 4");
        refused(CLASS, "N_ur = 2.0328\n", "N_ur = 2.0328");
        refused(CLASS, "m_nu = 0.06\nneutrinos = two\n", "neutrinos = two");
        refused(CLASS, "m_nu = 0.06\nN_eff = 3.2\n", "N_eff = 3.2");
        // keys of two codes that disagree
        let e = refused(
            CAMB,
            "mnu = 0.06\nnum_massive_neutrinos = 3\nneutrinos = one massive\n",
            "num_massive_neutrinos = 3",
        );
        assert!(e.contains("different neutrino settings"), "{e}");
        // massless: the species keys do not matter (listed as ignored), N_eff does
        let p =
            Cosmology::from_ini_str(&format!("{CAMB}mnu = 0\nnum_massive_neutrinos = 1\n"), "x")
                .unwrap();
        assert_eq!(p.ignored, ["num_massive_neutrinos"]);
        assert!(parse(CLASS, "N_ur = 3.046\n").is_ok());
        assert!(parse(CLASS, "N_ur = 3.044\n").is_ok());
    }
}
