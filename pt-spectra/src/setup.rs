//! From what a user gives (a cosmology, a linear spectrum at some redshift, the output redshift) to what
//! the computations need: the linear spectrum at the output redshift, D(z) and f(z) of the cosmology,
//! the warnings a user must see, and header lines saying what was used.
//!
//! The cosmology sets the growth: the rescaling of a spectrum from `z_input` to `z` by
//! [D(z)/D(z_input)]², the default growth rate f(z) of redshift-space models, the Fingers-of-God scale
//! σ = σ0 D(z) f and the no-wiggle reference spectrum. Its default is the gm2012 cosmology of the
//! embedded spectra; a spectrum of another cosmology with the default growth is warned about.
//!
//! ```
//! use pt_spectra::setup::{prepare, LinearSource, NamedCosmology, Request};
//! let request = Request {
//!     source: LinearSource::Embedded,
//!     cosmology: Some(NamedCosmology::parse("gm2012")?.0),
//!     z: 1.0,
//! };
//! let p = prepare(request)?;
//! assert!((p.growth_rate - 0.852).abs() < 1e-3 && p.warnings.is_empty());
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

use crate::cosmology::{Cosmology, TransferKind};
use crate::emulator::LinearEmulator;
use crate::error::{Error, Result};
use crate::linear::{LinearSpectrum, LogGrid, GM2012_REDSHIFTS};

pub mod radiation;

/// A cosmology with the name it was given by (a preset name or a parameter file).
#[derive(Debug, Clone, PartialEq)]
pub struct NamedCosmology {
    /// `gm2012`, `planck2018`, or the path of the parameter file.
    pub name: String,
    /// The parameters.
    pub cosmology: Cosmology,
}

impl NamedCosmology {
    /// The gm2012 cosmology of the embedded spectra (the default).
    pub fn gm2012() -> Self {
        Self {
            name: "gm2012".into(),
            cosmology: Cosmology::gm2012(),
        }
    }

    /// A preset name (`gm2012`, `planck2018`) or the path of a CLASS or CAMB parameter file, with the
    /// keys of the file that were ignored.
    ///
    /// # Errors
    /// As [`Cosmology::from_name_or_file`].
    pub fn parse(name_or_file: &str) -> Result<(Self, Vec<String>)> {
        let parsed = Cosmology::from_name_or_file(name_or_file)?;
        let named = Self {
            name: name_or_file.trim().to_string(),
            cosmology: parsed.cosmology,
        };
        Ok((named, parsed.ignored))
    }

    /// Whether this is the gm2012 cosmology of the embedded spectra.
    pub fn is_gm2012(&self) -> bool {
        self.cosmology == Cosmology::gm2012()
    }
}

/// Where the linear spectrum comes from.
#[derive(Debug, Clone)]
pub enum LinearSource {
    /// The embedded CAMB spectra of the gm2012 cosmology (z = 0, 0.5, 1, 1.5; other redshifts rescaled
    /// from z = 0). With another cosmology, [`LinearSource::Emulator`].
    Embedded,
    /// The linear-spectrum emulator ([`crate::emulator`]): P_m of the cosmology at z, and P_cb and the
    /// growth rate of cold dark matter + baryons with massive neutrinos. An error names a parameter
    /// outside its prior.
    Emulator,
    /// A tabulated spectrum (a file or arrays) at redshift `z_input`.
    Table {
        /// The spectrum.
        spectrum: Box<LinearSpectrum>,
        /// Its redshift.
        z_input: f64,
    },
    /// The Eisenstein & Hu (1998) fit of the cosmology, with or without BAO.
    EisensteinHu(TransferKind),
}

/// What the user asked for.
#[derive(Debug, Clone)]
pub struct Request {
    /// The linear spectrum.
    pub source: LinearSource,
    /// The cosmology; `None` is the gm2012 default.
    pub cosmology: Option<NamedCosmology>,
    /// The output redshift.
    pub z: f64,
}

/// The linear spectrum at the output redshift, with the growth of its cosmology.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The linear spectrum at `z` (all matter).
    pub spectrum: LinearSpectrum,
    /// The linear spectrum of cold dark matter + baryons at `z` when it differs from `spectrum` (the
    /// emulator with massive neutrinos); `None` otherwise.
    pub spectrum_cb: Option<LinearSpectrum>,
    /// The cosmology.
    pub cosmology: NamedCosmology,
    /// The output redshift.
    pub z: f64,
    /// D(z), normalised to D(0) = 1.
    pub growth_factor: f64,
    /// f(z) = d ln D/d ln a.
    pub growth_rate: f64,
    /// Things the user must be told (e.g. a default that may not fit the input); also in the header.
    pub warnings: Vec<String>,
    /// Header lines: the cosmology and its growth, the linear spectrum and how it was rescaled.
    pub description: Vec<String>,
}

/// Checks a redshift.
fn check_z(name: &'static str, z: f64) -> Result<()> {
    if z.is_finite() && z > -1.0 {
        return Ok(());
    }
    Err(Error::InvalidParameter {
        name,
        value: z,
        reason: "a redshift must be finite and > -1",
    })
}

/// The linear spectrum at the output redshift and the growth of the cosmology (see the module docs).
///
/// # Errors
/// [`Error::InvalidParameter`] for a redshift that is not finite and > −1; [`Error::InvalidChoice`]
/// for a rescaling from z_input to z that the radiation neglected in the growth puts more than
/// [`radiation::REFUSE_ABOVE`] off (a warning above [`radiation::WARN_ABOVE`]); as
/// [`Cosmology::eisenstein_hu_spectrum`] and [`LinearSpectrum::scaled`].
pub fn prepare(request: Request) -> Result<Prepared> {
    prepare_with_emulator(request, None)
}

/// [`prepare`] with an emulator parsed before (`None`: the embedded one, parsed at this call): what a
/// chain step that emulates at every call uses, since parsing costs more than an evaluation.
///
/// # Errors
/// As [`prepare`].
pub fn prepare_with_emulator(
    request: Request,
    emulator: Option<&LinearEmulator>,
) -> Result<Prepared> {
    check_z("z", request.z)?;
    let z = request.z;
    let defaulted = request.cosmology.is_none();
    let named = request.cosmology.unwrap_or_else(NamedCosmology::gm2012);
    let c = named.cosmology;
    let (d, mut f) = c.growth_factor_and_rate(z);
    let mut spectrum_cb = None;
    let mut warnings = Vec::new();
    let mut description = vec![format!(
        "cosmology: {}{} ({}); D(z)/D(0) = {d:.6}, f(z) = {f:.6} at z = {z}",
        named.name,
        if defaulted { " (the default)" } else { "" },
        c.describe()
    )];
    let eh = |kind: TransferKind| c.eisenstein_hu_spectrum(kind, z, &LogGrid::default());
    let spectrum = match request.source {
        LinearSource::Embedded if named.is_gm2012() => {
            let embedded = GM2012_REDSHIFTS.iter().any(|&zi| (zi - z).abs() < 1e-6);
            let (spectrum, how) = if embedded {
                (LinearSpectrum::gm2012(z)?, String::new())
            } else {
                let (note, warning) =
                    radiation::check_rescaling(&c, "the embedded gm2012 spectrum", 0.0, z)?;
                warnings.extend(warning);
                let ratio = d / c.growth_factor(0.0);
                let s = LinearSpectrum::gm2012(0.0)?.scaled(ratio * ratio)?;
                (
                    s,
                    format!(", rescaled by [D(z)/D(0)]^2 = {:.6}; {note}", ratio * ratio),
                )
            };
            description.push(format!(
                "linear spectrum: {} (embedded CAMB spectrum of gm2012{how})",
                spectrum.origin()
            ));
            spectrum
        }
        LinearSource::Embedded | LinearSource::Emulator => {
            let emulated = match emulator {
                Some(e) => emulate(e, &c, z, d)?,
                None => emulate(LinearEmulator::shared()?, &c, z, d)?,
            };
            description.extend(emulated.description);
            warnings.extend(emulated.warning);
            if let Some((cb, f_cb)) = emulated.cb {
                spectrum_cb = Some(cb);
                f = f_cb;
            }
            emulated.spectrum
        }
        LinearSource::EisensteinHu(kind) => {
            let what = match kind {
                TransferKind::Wiggle => "with BAO",
                TransferKind::NoWiggle => "no-wiggle",
            };
            let mut line = format!(
                "linear spectrum: Eisenstein & Hu (1998) {what} of cosmology {} at z = {z}",
                named.name
            );
            if z != 0.0 {
                let (note, warning) =
                    radiation::check_rescaling(&c, "the Eisenstein & Hu spectrum", 0.0, z)?;
                warnings.extend(warning);
                line += &format!(" (normalised at z = 0, rescaled by D(z)^2; {note})");
            }
            description.push(line);
            eh(kind)?
        }
        LinearSource::Table { spectrum, z_input } => {
            check_z("z_input", z_input)?;
            // A table already at z (the usual chain call) needs no second growth integral.
            let ratio = if z_input == z {
                1.0
            } else {
                d / c.growth_factor(z_input)
            };
            if defaulted {
                warnings.push(format!(
                    "no cosmology was given for the linear spectrum `{}`: the growth of the gm2012 \
                     cosmology is used (f = {f:.4}, D(z)/D(z_input) = {ratio:.6}); give --cosmology",
                    spectrum.origin()
                ));
            }
            let mut line = format!(
                "linear spectrum: {} at z_input = {z_input}, rescaled to z = {z} by [D(z)/D(z_input)]^2 = \
                 {:.6}",
                spectrum.origin(),
                ratio * ratio
            );
            if z_input != z {
                let what = format!("the linear spectrum `{}`", spectrum.origin());
                let (note, warning) = radiation::check_rescaling(&c, &what, z_input, z)?;
                warnings.extend(warning);
                line += &format!("; {note}");
            }
            description.push(line);
            if z_input == z {
                *spectrum
            } else {
                spectrum.scaled(ratio * ratio)?
            }
        }
    };
    for w in &warnings {
        description.push(format!("warning: {w}"));
    }
    Ok(Prepared {
        spectrum,
        spectrum_cb,
        cosmology: named,
        z,
        growth_factor: d,
        growth_rate: f,
        warnings,
        description,
    })
}

pub use crate::emulator::K_GROWTH_RATE;

/// What [`prepare`] takes from the emulator.
struct Emulated {
    spectrum: LinearSpectrum,
    /// P_cb and f_cb(K_GROWTH_RATE) with massive neutrinos.
    cb: Option<(LinearSpectrum, f64)>,
    description: Vec<String>,
    /// σ8(z = 0) outside the typical range for an A_s input (a likely mistyped A_s).
    warning: Option<String>,
}

/// The emulated spectra of `c` at `z` (where D(z)/D(0) = `growth`), with the header lines that say
/// so.
fn emulate(emulator: &LinearEmulator, c: &Cosmology, z: f64, growth: f64) -> Result<Emulated> {
    let e = emulator.spectra(c, z)?;
    let spectrum = e.matter()?;
    let mut description = vec![
        format!(
            "linear spectrum: P_m at z = {z} from the {} (sigma8(z) = {:.6}, A_s = {:.6e}); error \
             (worst |Delta ln P| measured against CAMB over the whole prior with these neutrinos, its \
             corners included, 1e-3 <= k <= 1 h/Mpc, 0 <= z <= 3) {:.1e}",
            emulator.describe(),
            e.sigma8,
            e.a_s,
            e.worst[1]
        ),
        format!(
            "neutrinos: {}",
            if c.m_nu > 0.0 {
                c.neutrinos.describe()
            } else {
                "massless, N_eff = 3.046"
            }
        ),
        format!(
            "linear spectrum: emulated for {:.4e} <= k <= {:.4e} h/Mpc, power laws beyond",
            e.k[0],
            e.k[e.k.len() - 1]
        ),
    ];
    let cb = if c.m_nu > 0.0 {
        let cb = e.cb()?;
        let f_of_k = e.growth_rate_cb()?;
        let f = f_of_k.eval(K_GROWTH_RATE);
        description.push(format!(
            "massive neutrinos: P_cb (cold dark matter + baryons) emulated too (error {:.1e}): the \
             redshift-space and galaxy models use P_cb, with the growth rate f = f_cb(k = \
             {K_GROWTH_RATE} h/Mpc, z) = {f:.6} (scale-dependent: {:.6} at k = 0.01, {:.6} at k = 0.3)",
            e.worst[0],
            f_of_k.eval(0.01),
            f_of_k.eval(0.3)
        ));
        Some((cb, f))
    } else {
        None
    };
    let warning = match c.amplitude {
        crate::cosmology::Amplitude::As { a_s, .. } => {
            // σ8(0) ≈ σ8(z)/[D(z)/D(0)] (to ~1% with massive neutrinos, whose growth depends on
            // k): a second emulation at z = 0 (as much as the first) only near the typical range's
            // edges, where the warning's text must be exact
            let approx = e.sigma8 / growth;
            let (lo, hi) = crate::cosmology::SIGMA8_TYPICAL;
            let near_edge = [lo, hi]
                .iter()
                .any(|edge| (approx / edge - 1.0).abs() < 0.05);
            let today = if z == 0.0 {
                e.sigma8
            } else if near_edge {
                emulator.spectra(c, 0.0)?.sigma8
            } else {
                approx
            };
            crate::cosmology::sigma8_warning(today, a_s)
        }
        crate::cosmology::Amplitude::Sigma8(_) => None,
    };
    Ok(Emulated {
        spectrum,
        cb,
        description,
        warning,
    })
}

/// The warnings both faces add to those of [`prepare`], in the same words: the keys of a cosmology
/// file that were ignored (`ignored_keys`, from [`NamedCosmology::parse`]) and, for output wavenumbers
/// `k` [h/Mpc] (any order; none: no check), a range that reaches the power-law extrapolation of the
/// linear table.
pub fn input_warnings(prepared: &Prepared, ignored_keys: &[String], k: &[f64]) -> Vec<String> {
    let mut out = Vec::new();
    if !ignored_keys.is_empty() {
        out.push(format!(
            "cosmology: keys ignored (they do not set the background or growth): {}",
            ignored_keys.join(", ")
        ));
    }
    if !k.is_empty() {
        let lo = k.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = k.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if let Some(ext) = prepared.spectrum.extrapolation_in(lo, hi) {
            out.push(format!("output {ext}"));
        }
    }
    out
}

impl Prepared {
    /// These inputs with the growth factor D(z) replaced by `d` (e.g. a Boltzmann code's σ8(z)/σ8(0)),
    /// stated in the header lines.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `d` is finite and positive.
    pub fn with_growth_factor(mut self, d: f64) -> Result<Self> {
        if !(d.is_finite() && d > 0.0) {
            return Err(Error::InvalidParameter {
                name: "growth_factor",
                value: d,
                reason: "must be finite and positive",
            });
        }
        self.growth_factor = d;
        self.description
            .push(format!("growth factor D(z) = {d} given by the caller"));
        Ok(self)
    }

    /// The linear spectrum that haloes and galaxies trace, and that the redshift-space models use: that of
    /// cold dark matter + baryons with massive neutrinos ([`spectrum_cb`](Self::spectrum_cb)),
    /// otherwise [`spectrum`](Self::spectrum).
    pub fn tracer_spectrum(&self) -> &LinearSpectrum {
        self.spectrum_cb.as_ref().unwrap_or(&self.spectrum)
    }

    /// The share of cold dark matter + baryons in the matter density, f_cb = 1 − ω_ν/ω_m.
    pub fn cold_fraction(&self) -> f64 {
        let c = &self.cosmology.cosmology;
        1.0 - c.omega_nu() / (c.omega_m * c.h * c.h)
    }

    /// The Eisenstein & Hu (1998) no-wiggle spectrum of the cosmology at the output redshift, scaled to
    /// the σ8 of the linear spectrum: the smooth reference by which BAO are divided out.
    ///
    /// # Errors
    /// As [`Cosmology::eisenstein_hu_spectrum`].
    pub fn no_wiggle(&self) -> Result<LinearSpectrum> {
        let c = &self.cosmology.cosmology;
        let eh = c.eisenstein_hu_spectrum(TransferKind::NoWiggle, 0.0, &LogGrid::default())?;
        eh.scaled((self.spectrum.sigma8() / eh.sigma8()).powi(2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// CAMB's own growth includes radiation and baryons, which the growth ODE neglects: 2e-3 is the
    /// issue's acceptance (measured: ≤ 1.7e-4 for Planck 2018).
    const CAMB_TOL: f64 = 2e-3;

    fn planck(z: f64) -> LinearSpectrum {
        let path = format!(
            "{}/tests/data/linear_pk_planck2018_z{z:.1}.dat",
            env!("CARGO_MANIFEST_DIR")
        );
        LinearSpectrum::from_file(path).unwrap()
    }

    fn table(z_input: f64) -> LinearSource {
        LinearSource::Table {
            spectrum: Box::new(planck(z_input)),
            z_input,
        }
    }

    /// The growth without radiation rescales a spectrum far in z only with a warning (more than
    /// 1e-3 off) or not at all (more than 1e-2): `real --model linear --z 1000` once gave a spectrum
    /// ~40% off with exit 0 (3-4% at z = 100).
    #[test]
    fn rescaling_far_in_z_is_warned_about_or_refused() {
        let request = |source: LinearSource, z: f64| Request {
            source,
            cosmology: Some(NamedCosmology::gm2012()),
            z,
        };
        let p = prepare(request(LinearSource::Embedded, 2.0)).unwrap();
        assert!(p.warnings.is_empty(), "{:?}", p.warnings);
        assert!(p
            .description
            .iter()
            .any(|l| l.contains("radiation neglected")));
        let p = prepare(request(LinearSource::Embedded, 5.0)).unwrap();
        assert!(
            p.warnings.len() == 1 && p.warnings[0].contains("growth without radiation"),
            "{:?}",
            p.warnings
        );
        for z in [100.0, 1000.0] {
            let e = prepare(request(LinearSource::Embedded, z)).unwrap_err();
            assert!(e.to_string().contains("neglects radiation"), "{e}");
        }
        let eh = LinearSource::EisensteinHu(TransferKind::Wiggle);
        assert!(prepare(request(eh, 100.0)).is_err());
        // A table at z needs no rescaling, however far.
        let at_z = |z_input: f64| LinearSource::Table {
            spectrum: Box::new(LinearSpectrum::gm2012_z0()),
            z_input,
        };
        assert!(prepare(request(at_z(100.0), 100.0)).is_ok());
        assert!(prepare(request(at_z(0.0), 100.0)).is_err());
    }

    #[test]
    fn a_table_is_rescaled_with_the_growth_of_its_cosmology() {
        let named = NamedCosmology::parse("planck2018").unwrap().0;
        let p = prepare(Request {
            source: table(0.0),
            cosmology: Some(named),
            z: 1.0,
        })
        .unwrap();
        assert!(p.warnings.is_empty(), "{:?}", p.warnings);
        assert!(
            (p.growth_rate / 0.873875 - 1.0).abs() < CAMB_TOL,
            "{}",
            p.growth_rate
        );
        let camb = planck(1.0);
        for k in LogGrid::new(0.01, 0.3, 30).unwrap().points() {
            let rel = p.spectrum.eval(k) / camb.eval(k) - 1.0;
            assert!(rel.abs() < CAMB_TOL, "k = {k}: {rel:e}");
        }
        assert!(p
            .description
            .iter()
            .any(|l| l.starts_with("cosmology: planck2018")));
    }

    #[test]
    fn the_default_growth_is_warned_about_and_other_cosmologies_without_a_table_are_emulated() {
        let p = prepare(Request {
            source: table(0.0),
            cosmology: None,
            z: 1.0,
        })
        .unwrap();
        assert!(p.warnings[0].contains("gm2012"), "{:?}", p.warnings);
        assert_eq!(p.growth_rate, Cosmology::gm2012().growth_rate(1.0));
        let p = prepare(Request {
            source: LinearSource::Embedded,
            cosmology: Some(NamedCosmology::parse("planck2018").unwrap().0),
            z: 0.5,
        })
        .unwrap();
        assert!(p.warnings.is_empty(), "{:?}", p.warnings);
        assert!(p.description.iter().any(|l| l.contains("emulator")));
        // the header states the measured worst case over the prior with these neutrinos (Planck 2018
        // here is massless: the massless head's figure)
        let emulator = LinearEmulator::embedded().unwrap();
        let worst = emulator.worst_massless().unwrap();
        assert_ne!(
            Some(worst),
            emulator.worst(crate::cosmology::Neutrinos::ThreeDegenerate)
        );
        let line = p
            .description
            .iter()
            .find(|l| l.contains("worst |Delta ln P| measured against CAMB over the whole prior"))
            .expect("the emulator's line");
        assert!(line.contains(&format!("{:.1e}", worst[1])), "{line}");
        assert!(p
            .description
            .iter()
            .any(|l| l == "neutrinos: massless, N_eff = 3.046"));
        // an accepted but mistyped A_s (σ8 = 5.7) is warned about
        let big = NamedCosmology {
            name: "big".into(),
            cosmology: Cosmology::planck2018()
                .with_amplitude(crate::cosmology::Amplitude::a_s(1e-7))
                .unwrap(),
        };
        let mistyped = prepare(Request {
            source: LinearSource::Emulator,
            cosmology: Some(big),
            z: 0.5,
        })
        .unwrap();
        assert!(
            mistyped
                .warnings
                .iter()
                .any(|w| w.contains("A_s = 1e-7") && w.contains("sigma8(z = 0) = 5.66")),
            "{:?}",
            mistyped.warnings
        );
        // near the typical range's edge (σ8 ≈ 0.39 < 0.4) the value is the emulation's at z = 0
        let low = Cosmology::planck2018()
            .with_amplitude(crate::cosmology::Amplitude::a_s(4.9e-10))
            .unwrap();
        let exact = LinearEmulator::embedded()
            .unwrap()
            .spectra(&low, 0.0)
            .unwrap()
            .sigma8;
        let warned = prepare(Request {
            source: LinearSource::Emulator,
            cosmology: Some(NamedCosmology {
                name: "low".into(),
                cosmology: low,
            }),
            z: 0.5,
        })
        .unwrap()
        .warnings;
        let text = format!("sigma8(z = 0) = {exact:.3}");
        assert!(
            exact < 0.4 && warned.iter().any(|w| w.contains(&text)),
            "{warned:?}"
        );
        // The emulated spectrum is CAMB's to its error (1e-3 here, k in [0.01, 0.3]).
        let camb = planck(0.0);
        for k in LogGrid::new(0.01, 0.3, 30).unwrap().points() {
            let rel = p.spectrum.eval(k) / (camb.eval(k) * p.growth_factor.powi(2)) - 1.0;
            assert!(rel.abs() < 3e-3, "k = {k}: {rel:e}");
        }
        assert!(p.spectrum_cb.is_none());
        // with massive neutrinos: P_cb too, the scale-dependent f at k = 0.1, and P_cb ≥ P_m
        let c = Cosmology::planck2018().with_neutrinos(0.3).unwrap();
        let named = NamedCosmology {
            name: "nu".into(),
            cosmology: c,
        };
        let p = prepare(Request {
            source: LinearSource::Emulator,
            cosmology: Some(named),
            z: 0.5,
        })
        .unwrap();
        assert!(
            p.description
                .iter()
                .any(|l| l.starts_with("neutrinos: three degenerate massive species")),
            "{:?}",
            p.description
        );
        let cb = p.spectrum_cb.as_ref().unwrap();
        assert!(cb.eval(0.5) > p.spectrum.eval(0.5) * 1.02);
        assert!((p.growth_rate - c.growth_rate(0.5)).abs() < 0.02);
        assert!(p.growth_rate < c.growth_rate(0.5));
        // outside the prior: an error naming the parameter
        let far = NamedCosmology {
            name: "far".into(),
            cosmology: Cosmology::planck2018().with_neutrinos(1.0).unwrap(),
        };
        let e = prepare(Request {
            source: LinearSource::Emulator,
            cosmology: Some(far),
            z: 0.0,
        })
        .unwrap_err();
        assert!(e.to_string().contains("m_nu = 1"), "{e}");
        let e = prepare(Request {
            source: LinearSource::Embedded,
            cosmology: None,
            z: -1.0,
        })
        .unwrap_err();
        assert!(e.to_string().contains("z = -1"), "{e}");
    }

    #[test]
    fn a_given_growth_factor_replaces_d_and_is_stated() {
        let p = prepare(Request {
            source: LinearSource::Embedded,
            cosmology: None,
            z: 0.5,
        })
        .unwrap();
        let q = p.clone().with_growth_factor(0.7).unwrap();
        assert_eq!(q.growth_factor, 0.7);
        assert!(q
            .description
            .last()
            .unwrap()
            .contains("D(z) = 0.7 given by the caller"));
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(p.clone().with_growth_factor(bad).is_err(), "{bad}");
        }
    }
}
