//! The linear-spectrum emulator: P_lin(k, z) of all matter and of cold dark matter + baryons from the
//! cosmological parameters, without a Boltzmann code.
//!
//! * **What is emulated.** G = ln P_cb(k, z) − ln A_s − (n_s − 1) ln(k h/k_pivot) − 2 ln(D_md(z)/Ω_m)
//!   and ln(P_m/P_cb) (set to 0, exactly, without massive neutrinos), as functions of the six parameters that shape the transfer functions (Ω_b, Ω_m,
//!   h, Σm_ν, w0, wa), on nodes in x = k r_d (r_d, the drag sound horizon of Aubourg et al. 2015, eq. 16, in Mpc/h: the
//!   baryon oscillations then sit at the same x for every cosmology) and in redshift. A_s and n_s enter
//!   through the primordial factor, which is exact in linear theory, so any A_s and n_s are accepted.
//!   D_md(z) is the growing mode of the background ([`Cosmology::growth_md_and_rate`]: all matter as
//!   dust, normalised to a deep in matter domination); dividing it out takes the steep dependence of
//!   the amplitude on w0, wa and Ω_m out of what the polynomials must fit.
//! * **How.** Each quantity is the training mean plus its leading principal components; each component's
//!   coefficient is a polynomial (Legendre products, the terms listed in the file) of seven
//!   coordinates: the shape parameters mapped to [−1, 1] by the prior box, and the early dark-energy
//!   density ([`PriorPoint::coordinates`]). Between redshift nodes (uniform in ln(1 + z)) the four nearest
//!   nodes are joined by a cubic (Lagrange) polynomial in s = ln(1 + z), whose derivative gives the
//!   scale-dependent growth rate f_cb(k, z) = d ln D_cb/d ln a = f_md(z) − ½ ∂G/∂s. The computation
//!   is written once over [`Real`] (`nodes.rs`), the components summed in f64 so that the spectra
//!   are smooth functions of the parameters: on `f64` it is [`LinearEmulator::spectra`], on dual
//!   numbers it gives the exact derivatives with respect to the sampled parameters
//!   ([`LinearEmulator::tracer_tangent`], [`tangent`]).
//! * **Trained on** CAMB spectra (`pt-spectra/data/make_emulator_training.py`, fitted by
//!   `pt-spectra/data/fit_emulator.py`): three degenerate massive neutrinos of total mass Σm_ν,
//!   N_eff = 3.046, T_CMB = 2.7255 K, flat, w0–wa dark energy in CAMB's PPF model. Its accuracy on
//!   cosmologies it was not trained on is in the file (per k) and in `docs/emulator.md`.
//! * **Units:** k in h/Mpc, P in (Mpc/h)³; Σm_ν in eV.
//!
//! ```
//! use pt_spectra::{cosmology::Cosmology, emulator::LinearEmulator};
//! let emulator = LinearEmulator::embedded()?;
//! let spectra = emulator.spectra(&Cosmology::planck2018(), 0.0)?;
//! assert!((spectra.sigma8 / 0.821734 - 1.0).abs() < 2e-3); // CAMB, massless neutrinos
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

mod format;
use format::HeadOf;
mod nodes;
pub mod prior;
pub mod tangent;

use crate::cosmology::{Cosmology, Neutrinos, EV_PER_OMEGA_NU};
use crate::dual::Real;
use crate::error::Error;
use crate::error::Result;
use crate::linear::{top_hat, LinearSpectrum};
pub use prior::{PriorPoint, PriorRange, COORDINATES, PARAMETER_NAMES, SHAPE_PARAMETERS};
use std::f64::consts::PI;
pub use tangent::TracerTangent;

/// The wavenumber in h/Mpc at which the scale-dependent growth rate f_cb(k, z) of a cosmology with
/// massive neutrinos gives the scalar f of the redshift-space models ([`crate::setup::prepare`],
/// [`LinearEmulator::tracer_tangent`]).
pub const K_GROWTH_RATE: f64 = 0.1;

/// The emulator file shipped with the library.
const EMBEDDED: &[u8] = include_bytes!("../../data/linear_emulator.bin");

/// The drag sound horizon r_d in Mpc/h from the fit of Aubourg et al. (2015, eq. 16), accurate to ~0.1%
/// for massive neutrinos; here only a coordinate that aligns the baryon oscillations of all cosmologies.
/// Over any [`Real`] (Ω_b, Ω_m, h, Σm_ν in eV; its derivatives with [`crate::dual::Dual`]).
pub fn drag_horizon<T: Real>(omega_b: T, omega_m: T, h: T, m_nu: T) -> T {
    let w_nu = m_nu / EV_PER_OMEGA_NU;
    let w_b = omega_b * h * h;
    let w_cb = omega_m * h * h - w_nu;
    ((w_nu + 0.0006).powi(2) * -72.3).exp() * 55.154 / (w_cb.powf(0.25351) * w_b.powf(0.12807)) * h
}

/// Below this Σm_ν (eV) the emulated ln(P_m/P_cb) is tapered to 0 at Σm_ν = 0 and the massless head
/// tapered in (continuity of P_m and P_cb; [`LinearEmulator::spectra`]): a tenth of the smallest mass
/// the oscillations allow (0.059 eV), so no physical cosmology is touched.
pub const RATIO_TAPER: f64 = 0.005;

/// The emulator: parsed once, then [`spectra`](Self::spectra) per cosmology.
#[derive(Debug, Clone)]
pub struct LinearEmulator {
    file: format::Parsed,
    max_degree: usize,
    origin: String,
    /// [`Self::describe`]'s line, made on first use (every emulated spectrum's header carries it).
    description: std::sync::OnceLock<String>,
}

/// The emulated linear spectra of one cosmology at one redshift.
#[derive(Debug, Clone)]
pub struct EmulatedSpectra {
    /// The redshift.
    pub z: f64,
    /// Wavenumbers in h/Mpc (uniform in ln k; the range depends on r_d).
    pub k: Vec<f64>,
    /// P of all matter (CDM, baryons and massive neutrinos) in (Mpc/h)³.
    pub p_m: Vec<f64>,
    /// P of cold dark matter + baryons in (Mpc/h)³ (equal to `p_m` for massless neutrinos).
    pub p_cb: Vec<f64>,
    /// Growth rate of cold dark matter + baryons, f_cb(k, z) = d ln D_cb(k, z)/d ln a.
    pub f_cb: Vec<f64>,
    /// Estimated relative error of `p_cb` per k (the test set's 99th percentile of |Δ ln P|).
    pub error_cb: Vec<f64>,
    /// Estimated relative error of `p_m` per k.
    pub error_m: Vec<f64>,
    /// The neutrino setting emulated (the cosmology's).
    pub neutrinos: Neutrinos,
    /// The measured worst |Δ ln P| of P_cb and of P_m against CAMB over the whole stated prior
    /// (corners included, 1e-3 ≤ k ≤ 1 h/Mpc, 0 ≤ z ≤ 3) for this neutrino setting.
    pub worst: [f64; 2],
    /// σ8 of all matter at `z`.
    pub sigma8: f64,
    /// A_s at the pivot (given, or set by σ8).
    pub a_s: f64,
}

/// The growth of cold dark matter + baryons with massive neutrinos ([`LinearEmulator::growth_cb`]).
#[derive(Debug, Clone)]
pub struct ScaleDependentGrowth {
    /// The redshift.
    pub z: f64,
    /// Wavenumbers in h/Mpc.
    pub k: Vec<f64>,
    /// D_cb(k, z), normalised to 1 at z = 0 at every k.
    pub d_cb: Vec<f64>,
    /// f_cb(k, z) = d ln D_cb/d ln a.
    pub f_cb: Vec<f64>,
}

impl EmulatedSpectra {
    /// P_m as a [`LinearSpectrum`] (power-law extrapolation beyond the nodes).
    ///
    /// # Errors
    /// As [`LinearSpectrum::from_nodes`].
    pub fn matter(&self) -> Result<LinearSpectrum> {
        LinearSpectrum::from_nodes(self.k.clone(), self.p_m.clone())
    }

    /// P_cb as a [`LinearSpectrum`].
    ///
    /// # Errors
    /// As [`LinearSpectrum::from_nodes`].
    pub fn cb(&self) -> Result<LinearSpectrum> {
        LinearSpectrum::from_nodes(self.k.clone(), self.p_cb.clone())
    }

    /// f_cb(k) as a function of k [h/Mpc], interpolated as a spectrum is (log-log spline, power laws
    /// beyond the nodes): what [`crate::setup::prepare`] evaluates at
    /// [`K_GROWTH_RATE`] for the growth rate with massive neutrinos.
    ///
    /// # Errors
    /// As [`LinearSpectrum::from_nodes`].
    pub fn growth_rate_cb(&self) -> Result<LinearSpectrum> {
        LinearSpectrum::from_nodes(self.k.clone(), self.f_cb.clone())
    }
}

impl LinearEmulator {
    /// The emulator shipped with the library (`pt-spectra/data/linear_emulator.bin`).
    ///
    /// # Errors
    /// [`Error::BadDataFile`] if the embedded file is malformed (a build error, tested).
    pub fn embedded() -> Result<Self> {
        Self::from_bytes(EMBEDDED, "embedded linear-spectrum emulator")
    }

    /// The embedded emulator, parsed once per process and shared (parsing its 2 MB costs about
    /// 0.15 ms, twice an emulation: callers that emulate one cosmology per call, such as
    /// [`crate::setup::prepare`], take it from here). A read-only cache of constant bytes, not
    /// state: every call sees the same parsed file.
    ///
    /// # Errors
    /// As [`Self::embedded`] (each call reports the same failure).
    pub fn shared() -> Result<&'static Self> {
        static PARSED: std::sync::OnceLock<
            std::result::Result<LinearEmulator, (usize, &'static str)>,
        > = std::sync::OnceLock::new();
        let parsed = PARSED.get_or_init(|| {
            Self::embedded().map_err(|e| match e {
                Error::BadDataFile { offset, reason, .. } => (offset, reason),
                _ => (0, "the embedded emulator could not be read"),
            })
        });
        parsed
            .as_ref()
            .map_err(|&(offset, reason)| Error::BadDataFile {
                what: "embedded linear-spectrum emulator".into(),
                offset,
                reason,
            })
    }

    /// An emulator from the bytes of a file written by `fit_emulator.py`; `origin` names it.
    ///
    /// # Errors
    /// [`Error::BadDataFile`] naming the byte where the layout breaks.
    pub fn from_bytes(bytes: &[u8], origin: &str) -> Result<Self> {
        let file = format::parse(bytes, origin)?;
        let max_degree = file
            .exponents
            .iter()
            .chain(file.heads.iter().flat_map(|h| h.exponents.iter()))
            .flat_map(|e| e.iter())
            .map(|&d| usize::from(d))
            .max()
            .unwrap_or(0);
        Ok(Self {
            file,
            max_degree,
            origin: origin.to_string(),
            description: std::sync::OnceLock::new(),
        })
    }

    /// The prior: the range of each of the eight parameters it was trained or tested on. The six shape
    /// parameters must lie inside; A_s and n_s may lie outside (their dependence is exact).
    pub fn prior(&self) -> Vec<PriorRange> {
        let mut out = self.file.stated.clone();
        out.extend_from_slice(&self.file.prior[SHAPE_PARAMETERS..]);
        out
    }

    /// The redshift range, [z_min, z_max].
    pub fn z_range(&self) -> (f64, f64) {
        let z = &self.file.z_nodes;
        (z[0], z[z.len() - 1])
    }

    /// One line for output headers: what the emulator is and where it is valid.
    pub fn describe(&self) -> String {
        self.description
            .get_or_init(|| self.make_description())
            .clone()
    }

    fn make_description(&self) -> String {
        let prior: Vec<String> = self
            .file
            .stated
            .iter()
            .map(|p| format!("{} in [{}, {}]", p.name, p.min, p.max))
            .collect();
        let (z0, z1) = self.z_range();
        let settings: Vec<&str> = self
            .neutrino_settings()
            .into_iter()
            .map(Neutrinos::name)
            .collect();
        format!(
            "{} (trained on CAMB; prior {}, {} <= {}; z in [{z0}, {z1}]; neutrinos: {}; N_eff 3.046, \
             PPF dark energy, flat)",
            self.origin,
            prior.join(", "),
            prior::EARLY_DE_NAME,
            crate::error::number(&(self.file.q_bound * self.file.q_max)),
            settings.join(" or ")
        )
    }

    /// The neutrino settings emulated: three degenerate species and those of the file's heads.
    pub fn neutrino_settings(&self) -> Vec<Neutrinos> {
        std::iter::once(Neutrinos::ThreeDegenerate)
            .chain(self.file.heads.iter().filter_map(|h| match h.of {
                HeadOf::Setting(s) => Some(s),
                HeadOf::Massless => None,
            }))
            .collect()
    }

    /// The largest early dark-energy density q = ρ_DE/ρ_m at a = 0.1 of the prior
    /// ([`PriorPoint::coordinates`]).
    pub fn q_limit(&self) -> f64 {
        self.file.q_bound * self.file.q_max
    }

    /// The measured worst |Δ ln P| of P_cb and of P_m over the prior with massless neutrinos (Σm_ν =
    /// 0), if the file has a massless head (else the spectra at Σm_ν = 0 carry [`Self::worst`]'s
    /// figure of three degenerate species).
    pub fn worst_massless(&self) -> Option<[f64; 2]> {
        self.head_of(HeadOf::Massless).map(|h| h.worst)
    }

    /// The measured worst |Δ ln P| of P_cb and of P_m over the prior with Σm_ν > 0 shared as
    /// `neutrinos`, if emulated.
    pub fn worst(&self, neutrinos: Neutrinos) -> Option<[f64; 2]> {
        if neutrinos == Neutrinos::ThreeDegenerate {
            return Some(self.file.worst);
        }
        self.head_of(HeadOf::Setting(neutrinos)).map(|h| h.worst)
    }

    /// P_m, P_cb and f_cb of `cosmology` at redshift `z`.
    ///
    /// # Errors
    /// [`Error::OutsidePrior`] naming a shape parameter outside the prior, or the early dark-energy
    /// density beyond its bound; [`Error::InvalidParameter`] for a curved cosmology or a redshift
    /// outside [`z_range`](Self::z_range); [`Error::InvalidChoice`] for a neutrino setting that is not
    /// emulated ([`neutrino_settings`](Self::neutrino_settings)).
    pub fn spectra(&self, cosmology: &Cosmology, z: f64) -> Result<EmulatedSpectra> {
        let nodes = self.nodes(cosmology, &cosmology.background(), z)?;
        // the exponentials of 500 nodes in one vectorised pass (2 ulp of the library's)
        let mut p_cb = nodes.ln_p_cb.clone();
        crate::simd::exp_in_place(&mut p_cb);
        // without massive neutrinos the ratio is zero and P_m is P_cb to the bit (no second
        // exponential per node)
        let p_m: Vec<f64> = if nodes.ln_ratio.iter().all(|&r| r == 0.0) {
            p_cb.clone()
        } else {
            let mut p_m: Vec<f64> = (nodes.ln_p_cb.iter().zip(&nodes.ln_ratio))
                .map(|(p, r)| p + r)
                .collect();
            crate::simd::exp_in_place(&mut p_m);
            p_m
        };
        let sigma8 = sigma8(&nodes.sigma8_weights, nodes.step, |i| p_m[i]);
        Ok(EmulatedSpectra {
            z: nodes.z,
            k: nodes.k,
            p_m,
            p_cb,
            f_cb: nodes.f_cb,
            error_cb: self.file.error[0].clone(),
            error_m: self.file.error[1].clone(),
            neutrinos: cosmology.neutrinos,
            worst: self.worst_of(cosmology.neutrinos, nodes.m_nu),
            sigma8,
            a_s: nodes.ln_a_s.exp(),
        })
    }

    /// The scale-dependent growth of cold dark matter + baryons at `z`: D_cb(k, z) = T_cb(k, z)/T_cb(k, 0)
    /// = √(P_cb(k, z)/P_cb(k, 0)) and f_cb(k, z), on the nodes of [`spectra`](Self::spectra) (two
    /// evaluations; with massless neutrinos D_cb is the scale-independent D(z)/D(0) to the emulator's
    /// accuracy).
    ///
    /// # Errors
    /// As [`spectra`](Self::spectra).
    pub fn growth_cb(&self, cosmology: &Cosmology, z: f64) -> Result<ScaleDependentGrowth> {
        let at_z = self.spectra(cosmology, z)?;
        let today = self.spectra(cosmology, self.z_range().0)?;
        let d_cb = at_z
            .p_cb
            .iter()
            .zip(&today.p_cb)
            .map(|(p, p0)| (p / p0).sqrt())
            .collect();
        Ok(ScaleDependentGrowth {
            z: at_z.z,
            k: at_z.k,
            d_cb,
            f_cb: at_z.f_cb,
        })
    }

    /// The file's head that corrects `of`, if it has one.
    fn head_of(&self, of: HeadOf) -> Option<&format::Head> {
        self.file.heads.iter().find(|h| h.of == of)
    }

    /// The measured worst error of a cosmology's spectra: the massless head's at Σm_ν = 0, else
    /// that of its neutrino setting.
    fn worst_of(&self, setting: Neutrinos, m_nu: f64) -> [f64; 2] {
        let massless = (m_nu == 0.0).then(|| self.worst_massless()).flatten();
        massless
            .or_else(|| self.worst(setting))
            .unwrap_or(self.file.worst)
    }
}

/// σ8 from P on k uniform in ln k with spacing `step`: σ² = (1/2π²) ∫ k³ P W²(8k) d ln k by the
/// trapezoidal rule (the integrand vanishes at both ends of the emulator's range).
fn sigma8(weights: &[(f64, f64)], step: f64, p: impl Fn(usize) -> f64) -> f64 {
    let sum: f64 = weights
        .iter()
        .enumerate()
        .map(|(i, (end_k3, w2))| end_k3 * p(i) * w2)
        .sum();
    (sum * step / (2.0 * PI * PI)).sqrt()
}

/// The factors of [`sigma8`]'s trapezoid sum at the nodes `k`: (end weight × k³, W²(8k)), made once
/// per emulation (the top hat's sine and cosine per node) for both of its σ8 integrals.
fn sigma8_weights(k: &[f64]) -> Vec<(f64, f64)> {
    let last = k.len() - 1;
    k.iter()
        .enumerate()
        .map(|(i, &k)| {
            let end = if i == 0 || i == last { 0.5 } else { 1.0 };
            (end * k.powi(3), top_hat(8.0 * k).powi(2))
        })
        .collect()
}

#[cfg(test)]
mod tests;
