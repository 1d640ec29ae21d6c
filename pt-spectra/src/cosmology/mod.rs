//! Background cosmology (matter, curvature, w0–wa dark energy), linear growth, and Eisenstein & Hu (1998)
//! linear spectra.
//!
//! * Expansion (radiation and massive neutrinos neglected): E(a) = H/H0 with
//!   E² = Ω_m a⁻³ + Ω_k a⁻² + Ω_DE a^{−3(1+w0+wa)} exp(−3 wa (1−a)), the dark energy of equation of state
//!   w(a) = w0 + wa (1 − a) (Chevallier & Polarski 2001, Linder 2003), and Ω_k = 1 − Ω_m − Ω_DE.
//! * Growth, for a cosmological constant (w0 = −1, wa = 0; flat or curved): the growing mode is Heath's
//!   (1977) integral D(a) ∝ E(a) ∫_0^a da′ / (a′E(a′))³, normalised to D(z=0) = 1, and
//!   f = d ln D/d ln a = −(3Ω_m a⁻³ + 2Ω_k a⁻²)/(2E²) + 1/(a²E³ I(a)) with I the integral. The integral
//!   is done in u = √a, where the integrand 2u⁴/(Ω_m + Ω_k u² + Ω_Λ u⁶)^{3/2} is smooth, by Simpson's rule
//!   (relative error < 1e-12). Not a fitting formula.
//! * Growth, for any other w0, wa: the linear growth equation in ln a (′ = d/d ln a),
//!   D″ + (2 + d ln E/d ln a) D′ − (3/2) Ω_m a⁻³/E² D = 0, for the growing mode started deep in matter
//!   domination (D = D′ = a at a = 1e-8, with the first-order corrections for curvature and dark energy),
//!   integrated by an adaptive Dormand–Prince 5(4) Runge–Kutta method to ~1e-11 relative; D is normalised to D(z=0) = 1 and f = D′/D. The tests check the ODE against
//!   Heath's integral (flat and curved), Einstein–de Sitter, the flat-ΛCDM hypergeometric closed form and
//!   w = −1/3 (which dilutes like curvature) to ≤ 1e-8. Scale-independent: dark energy is taken to be
//!   smooth (no perturbations), as in the CAMB "fluid"/PPF models on sub-horizon scales.
//! * Transfer functions: Eisenstein & Hu (1998, ApJ 496, 605; astro-ph/9709112), the full fit with baryon
//!   acoustic oscillations (their §3, eqs. 2–24) and the smooth "no-wiggle" fit (§4.2, eqs. 26–31), with
//!   T_CMB = [`T_CMB_K`]. [`Cosmology::eisenstein_hu_spectrum`] turns them into a [`LinearSpectrum`]
//!   normalised by the cosmology's [`Amplitude`]: P(k) = A k^{n_s} T²(k) with A fixed by σ8, or from the
//!   primordial amplitude A_s, P(k) = 2π²/k³ · (4/25) A_s (k/k_pivot)^{n_s−1} (k c/H0)⁴ T²(k) (D_md(1)/Ω_m)²
//!   with D_md the growing mode normalised to a deep in matter domination: on super-horizon scales in
//!   matter domination Φ = (3/5)ζ, and the Poisson equation k²Φ = (3/2) Ω_m H0² δ/a gives
//!   δ = (2/5) ζ (k/H0)² D_md/Ω_m, times T(k) on smaller scales.
//! * Exact derivatives: the expansion, the growth and the distances ([`distance`]) are written once
//!   over a [`Real`](crate::dual::Real) type, as methods of [`background::Background`]; the
//!   [`Cosmology`] methods run them on `f64` ([`Cosmology::background`]), and on the
//!   [`Dual`](crate::dual::Dual)s of [`Cosmology::seeded`] they give the exact derivatives with
//!   respect to the sampled parameters h, ω_b, ω_cdm, ln(10¹⁰A_s), n_s, Σm_ν, w0, wa (the ODE's on its
//!   mesh, see the growth module's code docs).
//! * Presets [`PRESETS`] ([`Cosmology::preset`]), and CLASS or CAMB parameter files ([`ini`]:
//!   [`Cosmology::from_ini_file`], [`Cosmology::from_name_or_file`]).
//!
//! Units: k in h/Mpc, P in (Mpc/h)^3, lengths in Mpc/h unless stated otherwise.

use crate::error::{Error, Result};
use crate::linear::{LinearSpectrum, LogGrid};
use std::f64::consts::PI;

/// CMB temperature in K used by the Eisenstein & Hu transfer functions (the CAMB default).
pub const T_CMB_K: f64 = 2.7255;

/// The Hubble distance c/H0 in Mpc/h (c = 299792.458 km/s, H0 = 100 h km/s/Mpc).
pub const HUBBLE_DISTANCE_MPC_H: f64 = 2997.92458;

/// Σm_ν/ω_ν in eV: ω_ν = Ω_ν h² = Σm_ν/93.14 eV for neutrinos of the standard temperature.
pub const EV_PER_OMEGA_NU: f64 = 93.14;

/// Names accepted by [`Cosmology::preset`].
pub const PRESETS: [&str; 2] = ["gm2012", "planck2018"];

pub mod background;
pub mod distance;
mod eisenstein_hu;
#[cfg(test)]
pub(crate) mod finite_difference;
mod growth;
pub mod ini;
pub mod neutrinos;
mod plausible;

pub use eisenstein_hu::{EisensteinHu, TransferKind};
pub use ini::ParsedCosmology;
pub use neutrinos::Neutrinos;
pub use plausible::{
    check_growth_rate, plausible, sigma8_warning, Plausible, PLAUSIBLE, SIGMA8_TYPICAL,
};

/// How the amplitude of the linear spectrum is fixed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Amplitude {
    /// σ8: the RMS linear density fluctuation in spheres of 8 Mpc/h at z = 0.
    Sigma8(f64),
    /// The primordial curvature power spectrum Δ²_ζ(k) = A_s (k/k_pivot)^{n_s−1}.
    As {
        /// Amplitude A_s at the pivot.
        a_s: f64,
        /// Pivot wavenumber in 1/Mpc (not h/Mpc), [`Amplitude::DEFAULT_K_PIVOT`] in CAMB and CLASS.
        k_pivot: f64,
    },
}

impl Amplitude {
    /// The CAMB and CLASS default pivot, 0.05/Mpc.
    pub const DEFAULT_K_PIVOT: f64 = 0.05;

    /// A_s at the default pivot [`DEFAULT_K_PIVOT`](Self::DEFAULT_K_PIVOT).
    pub const fn a_s(a_s: f64) -> Self {
        Self::As {
            a_s,
            k_pivot: Self::DEFAULT_K_PIVOT,
        }
    }
}

/// Cosmological parameters: matter, curvature and w0–wa dark energy (massless neutrinos, radiation
/// neglected in the growth).
///
/// Ω_k = 1 − Ω_m − Ω_DE; the paper's models are flat ΛCDM. After changing fields, call
/// [`validate`](Self::validate).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Cosmology {
    /// Total matter density today Ω_m (CDM + baryons).
    pub omega_m: f64,
    /// Dark-energy density today Ω_DE: the cosmological constant Ω_Λ when w0 = −1 and wa = 0.
    pub omega_lambda: f64,
    /// Dimensionless Hubble constant h = H0 / (100 km/s/Mpc).
    pub h: f64,
    /// Physical baryon density Ω_b h².
    pub omega_b_h2: f64,
    /// Primordial spectral index n_s.
    pub n_s: f64,
    /// Amplitude of the linear spectrum: σ8 or the primordial A_s.
    pub amplitude: Amplitude,
    /// Dark-energy equation of state today, w0 (−1 for a cosmological constant).
    pub w0: f64,
    /// Dark-energy equation-of-state slope wa, w(a) = w0 + wa (1 − a) (0 for a cosmological constant).
    pub wa: f64,
    /// Sum of the neutrino masses Σm_ν in eV (0: massless). Their density ω_ν = Σm_ν/93.14 eV is part
    /// of Ω_m; the growth here treats them as matter (scale-independent), the emulator
    /// ([`crate::emulator`]) gives the scale-dependent growth of CDM + baryons.
    pub m_nu: f64,
    /// How Σm_ν is shared among the species ([`Neutrinos::ThreeDegenerate`] unless set by
    /// [`with_neutrino_species`](Self::with_neutrino_species) or a parameter file's keys, see
    /// [`ini`]); N_eff is the standard 3.046.
    pub neutrinos: Neutrinos,
}

impl Default for Cosmology {
    /// [`Cosmology::gm2012`].
    fn default() -> Self {
        Self::gm2012()
    }
}

impl Cosmology {
    /// The cosmology of Gil-Marín et al. (2012, arXiv:1209.3771): Ω_m = 0.27, Ω_Λ = 0.73, h = 0.7,
    /// Ω_b h² = 0.023, n_s = 0.95, σ8 = 0.8.
    pub const fn gm2012() -> Self {
        Self {
            omega_m: 0.27,
            omega_lambda: 0.73,
            h: 0.7,
            omega_b_h2: 0.023,
            n_s: 0.95,
            amplitude: Amplitude::Sigma8(0.8),
            w0: -1.0,
            wa: 0.0,
            m_nu: 0.0,
            neutrinos: Neutrinos::ThreeDegenerate,
        }
    }

    /// Planck 2018 best fit as in the CAMB reference tables of the tests (`pt-spectra/tests/data/make_planck2018.py`):
    /// h = 0.6766, Ω_b h² = 0.02242, Ω_c h² = 0.11933, n_s = 0.9665, A_s = 2.105209e-9 at k_pivot = 0.05/Mpc,
    /// flat, Λ. Ω_m = (Ω_b h² + Ω_c h²)/h² = 0.309641: neutrinos are massless (their radiation is
    /// neglected in the growth, as is the photons').
    pub const fn planck2018() -> Self {
        let h = 0.6766;
        let (omega_b_h2, omega_c_h2) = (0.02242, 0.11933);
        let omega_m = (omega_b_h2 + omega_c_h2) / (h * h);
        Self {
            omega_m,
            omega_lambda: 1.0 - omega_m,
            h,
            omega_b_h2,
            n_s: 0.9665,
            amplitude: Amplitude::a_s(2.105209e-9),
            w0: -1.0,
            wa: 0.0,
            m_nu: 0.0,
            neutrinos: Neutrinos::ThreeDegenerate,
        }
    }

    /// The preset called `name`, one of [`PRESETS`].
    ///
    /// # Errors
    /// [`Error::UnknownCosmology`] (listing the presets) for any other name.
    pub fn preset(name: &str) -> Result<Self> {
        match name {
            "gm2012" => Ok(Self::gm2012()),
            "planck2018" => Ok(Self::planck2018()),
            _ => Err(Error::UnknownCosmology {
                name: name.to_string(),
                available: PRESETS.join(", "),
            }),
        }
    }

    /// A validated cosmology with a cosmological constant Ω_Λ (w0 = −1, wa = 0); see
    /// [`with_dark_energy`](Self::with_dark_energy) for other dark energy.
    ///
    /// # Errors
    /// As [`validate`](Self::validate).
    pub fn new(
        omega_m: f64,
        omega_lambda: f64,
        h: f64,
        omega_b_h2: f64,
        n_s: f64,
        sigma8: f64,
    ) -> Result<Self> {
        let c = Self {
            omega_m,
            omega_lambda,
            h,
            omega_b_h2,
            n_s,
            amplitude: Amplitude::Sigma8(sigma8),
            w0: -1.0,
            wa: 0.0,
            m_nu: 0.0,
            neutrinos: Neutrinos::ThreeDegenerate,
        };
        c.validate()?;
        Ok(c)
    }

    /// A flat cosmology, Ω_Λ = 1 − Ω_m.
    ///
    /// # Errors
    /// As [`validate`](Self::validate).
    pub fn flat(omega_m: f64, h: f64, omega_b_h2: f64, n_s: f64, sigma8: f64) -> Result<Self> {
        Self::new(omega_m, 1.0 - omega_m, h, omega_b_h2, n_s, sigma8)
    }

    /// The same cosmology with dark energy of equation of state w(a) = w0 + wa (1 − a) and the same
    /// density today Ω_DE (= `omega_lambda`), so the same Ω_k.
    ///
    /// # Errors
    /// As [`validate`](Self::validate), e.g. unless w0 + wa < 0.
    pub fn with_dark_energy(self, w0: f64, wa: f64) -> Result<Self> {
        let c = Self { w0, wa, ..self };
        c.validate()?;
        Ok(c)
    }

    /// The same cosmology with neutrinos of total mass `m_nu` eV (shared as [`neutrinos`](Self::neutrinos)
    /// says: three degenerate species unless set otherwise), at the same Ω_m:
    /// the cold dark matter gives way to them, ω_cdm = Ω_m h² − ω_b − Σm_ν/93.14 eV.
    ///
    /// # Errors
    /// As [`validate`](Self::validate), e.g. if ω_cdm would not stay positive.
    pub fn with_neutrinos(self, m_nu: f64) -> Result<Self> {
        let c = Self { m_nu, ..self };
        c.validate()?;
        Ok(c)
    }

    /// The same cosmology with Σm_ν shared among the neutrino species as `neutrinos` says (Σm_ν and Ω_m
    /// unchanged). [`with_neutrinos`](Self::with_neutrinos) keeps the setting, three degenerate species
    /// by default.
    ///
    /// ```
    /// use pt_spectra::cosmology::{Cosmology, Neutrinos};
    /// // Planck's and DESI's baseline (and CAMB's default): one massive species of 0.06 eV
    /// let c = Cosmology::planck2018().with_neutrinos(0.06)?.with_neutrino_species(Neutrinos::OneMassive);
    /// assert!(c.describe().contains("one massive"));
    /// # Ok::<(), pt_spectra::error::Error>(())
    /// ```
    pub fn with_neutrino_species(self, neutrinos: Neutrinos) -> Self {
        Self { neutrinos, ..self }
    }

    /// The same cosmology normalised by `amplitude` instead.
    ///
    /// # Errors
    /// As [`validate`](Self::validate).
    pub fn with_amplitude(self, amplitude: Amplitude) -> Result<Self> {
        let c = Self { amplitude, ..self };
        c.validate()?;
        Ok(c)
    }

    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless all are finite, Ω_m > 0, Ω_DE ≥ 0, h > 0,
    /// 0 < Ω_b h² < Ω_m h², σ8 > 0 or A_s > 0 and k_pivot > 0, w0 + wa < 0 (so that w(a → 0) < 0 and dark energy is subdominant at
    /// early times, as the growth's start in matter domination needs), and E²(a) > 0 for all 0 < a ≤ 1
    /// (no bounce); and unless each parameter is in its [`PLAUSIBLE`] range (h, ω_b, ω_cdm, Ω_m, Ω_k,
    /// n_s, σ8 or A_s and k_pivot, w0, wa).
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value, reason| {
            Err(Error::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        let positive = "must be finite and positive";
        let amplitude = match self.amplitude {
            Amplitude::Sigma8(s) => [("sigma8", s), ("sigma8", s)],
            Amplitude::As { a_s, k_pivot } => [("A_s", a_s), ("k_pivot [1/Mpc]", k_pivot)],
        };
        for (name, v) in [("Omega_m", self.omega_m), ("h", self.h)]
            .into_iter()
            .chain(amplitude)
        {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, positive);
            }
        }
        if !(self.omega_lambda.is_finite() && self.omega_lambda >= 0.0) {
            return bad(
                "Omega_DE",
                self.omega_lambda,
                "must be finite and non-negative",
            );
        }
        if !(self.omega_b_h2 > 0.0 && self.omega_b_h2 < self.omega_m * self.h * self.h) {
            return bad(
                "Omega_b h^2",
                self.omega_b_h2,
                "must be positive and below Omega_m h^2",
            );
        }
        if !(self.m_nu.is_finite() && self.m_nu >= 0.0) {
            return bad("m_nu [eV]", self.m_nu, "must be finite and non-negative");
        }
        for (name, v) in [("n_s", self.n_s), ("w0", self.w0), ("wa", self.wa)] {
            if !v.is_finite() {
                return bad(name, v, "must be finite");
            }
        }
        if self.w0 + self.wa >= 0.0 {
            return bad(
                "w0 + wa",
                self.w0 + self.wa,
                "must be negative: w(a -> 0) = w0 + wa >= 0 makes dark energy as important as matter \
                 at early times, where the growth starts in matter domination",
            );
        }
        let background = self.background();
        if (1..=1000).any(|i| background.a2e2(f64::from(i) / 1000.0) <= 0.0) {
            return bad(
                "Omega_k",
                self.omega_k(),
                "H^2 vanishes for some a <= 1 (bouncing model)",
            );
        }
        let (sigma8, a_s, k_pivot) = match self.amplitude {
            Amplitude::Sigma8(s) => (Some(s), None, None),
            Amplitude::As { a_s, k_pivot } => (None, Some(a_s), Some(k_pivot)),
        };
        let omega_cdm = self.omega_m * self.h * self.h - self.omega_b_h2 - self.omega_nu();
        for (name, v) in [
            ("h", Some(self.h)),
            ("omega_b", Some(self.omega_b_h2)),
            ("omega_cdm", Some(omega_cdm)),
            ("Omega_m", Some(self.omega_m)),
            ("Omega_k", Some(self.omega_k())),
            ("n_s", Some(self.n_s)),
            ("sigma8", sigma8),
            ("A_s", a_s),
            ("k_pivot", k_pivot),
            ("w0", Some(self.w0)),
            ("wa", Some(self.wa)),
            ("m_nu", Some(self.m_nu)),
        ] {
            let (Some(v), Some(range)) = (v, plausible(name)) else {
                continue;
            };
            if v.is_finite() && !range.contains(v) {
                return bad(range.name, v, range.reason);
            }
        }
        Ok(())
    }

    /// The neutrino density ω_ν = Ω_ν h² = Σm_ν/93.14 eV.
    pub fn omega_nu(&self) -> f64 {
        self.m_nu / EV_PER_OMEGA_NU
    }

    /// Curvature density Ω_k = 1 − Ω_m − Ω_DE.
    pub fn omega_k(&self) -> f64 {
        1.0 - self.omega_m - self.omega_lambda
    }

    /// `spectrum`, given at redshift `z_in`, rescaled to redshift `z`: P × [D(z)/D(z_in)]².
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a redshift is not finite or ≤ −1.
    pub fn rescale(&self, spectrum: &LinearSpectrum, z_in: f64, z: f64) -> Result<LinearSpectrum> {
        for (name, v) in [("z_in", z_in), ("z", z)] {
            if !(v.is_finite() && v > -1.0) {
                let reason = "redshift must be finite and > -1";
                return Err(Error::InvalidParameter {
                    name,
                    value: v,
                    reason,
                });
            }
        }
        spectrum.scaled((self.growth_factor(z) / self.growth_factor(z_in)).powi(2))
    }

    /// Eisenstein & Hu (1998) linear spectrum P(k, z) on `grid`, normalised by [`amplitude`](Self::amplitude):
    /// for σ8, P = A k^{n_s} T²(k) D²(z) with A set so that σ(8 Mpc/h) = σ8 at z = 0 (top hat,
    /// [`LinearSpectrum::sigma_r`]); for A_s, P(k, z = 0) = 2π²/k³ · (4/25) A_s (k/k_pivot)^{n_s−1}
    /// (k c/H0)⁴ T²(k) (D_md(1)/Ω_m)² (module docs), then × D²(z).
    ///
    /// [`TransferKind::NoWiggle`] gives the smooth spectrum by which BAO features are divided out
    /// (P_lin/P_nw); with the same σ8 it matches the broadband of the [`TransferKind::Wiggle`] one. With
    /// A_s both share the large-scale amplitude, and their σ8 differ by the wiggles' share (~0.5%).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an invalid cosmology or redshift.
    ///
    /// ```
    /// use pt_spectra::{cosmology::{Cosmology, TransferKind}, linear::LogGrid};
    /// let p = Cosmology::gm2012().eisenstein_hu_spectrum(TransferKind::NoWiggle, 0.0, &LogGrid::default())?;
    /// assert!((p.sigma8() - 0.8).abs() < 1e-9);
    /// // Planck 2018 is normalised by A_s: σ8 follows (CAMB: 0.8217; EH is a fit).
    /// let p = Cosmology::planck2018().eisenstein_hu_spectrum(TransferKind::Wiggle, 0.0, &LogGrid::default())?;
    /// assert!((p.sigma8() / 0.8217 - 1.0).abs() < 0.03);
    /// # Ok::<(), pt_spectra::error::Error>(())
    /// ```
    pub fn eisenstein_hu_spectrum(
        &self,
        kind: TransferKind,
        z: f64,
        grid: &LogGrid,
    ) -> Result<LinearSpectrum> {
        let eh = EisensteinHu::new(self)?;
        let t2 = |k: f64| eh.transfer(kind, k).powi(2);
        let today = match self.amplitude {
            Amplitude::Sigma8(sigma8) => {
                let shape = LinearSpectrum::from_fn(grid, |k| k.powf(self.n_s) * t2(k))?;
                let sigma = shape.sigma_r(8.0)?.0;
                shape.scaled((sigma8 / sigma).powi(2))?
            }
            Amplitude::As { a_s, k_pivot } => {
                let k_pivot_h = k_pivot / self.h;
                let growth = self.growth_md(1.0, self.method()) / self.omega_m;
                LinearSpectrum::from_fn(grid, |k| {
                    let primordial = a_s * (k / k_pivot_h).powf(self.n_s - 1.0);
                    2.0 * PI * PI / k.powi(3)
                        * 0.16
                        * primordial
                        * (k * HUBBLE_DISTANCE_MPC_H).powi(4)
                        * t2(k)
                        * growth
                        * growth
                })?
            }
        };
        self.rescale(&today, 0.0, z)
    }

    /// One line describing the cosmology, for output headers, e.g. `Omega_m = 0.309641, Omega_DE =
    /// 0.690359, Omega_k = 0, h = 0.6766, omega_b = 0.02242, n_s = 0.9665, A_s = 2.105209e-09, w0 = -1,
    /// wa = 0`.
    ///
    /// Input values are printed exactly (shortest form that reads back to the same number), the derived
    /// densities to 6 significant digits; |Ω_k| < 1e-12 (rounding of 1 − Ω_m − Ω_DE) prints as 0. The
    /// pivot is shown when it is not the default 0.05/Mpc.
    pub fn describe(&self) -> String {
        let amplitude = match self.amplitude {
            Amplitude::Sigma8(s) => format!("sigma8 = {}", number(s)),
            Amplitude::As { a_s, k_pivot } if k_pivot == Amplitude::DEFAULT_K_PIVOT => {
                format!("A_s = {}", number(a_s))
            }
            Amplitude::As { a_s, k_pivot } => {
                format!("A_s = {}, k_pivot = {}/Mpc", number(a_s), number(k_pivot))
            }
        };
        let omega_k = self.omega_k();
        let omega_k = if omega_k.abs() < 1e-12 { 0.0 } else { omega_k };
        let neutrinos = if self.m_nu > 0.0 {
            format!(", m_nu = {} eV ({})", number(self.m_nu), self.neutrinos)
        } else {
            String::new()
        };
        format!(
            "Omega_m = {}, Omega_DE = {}, Omega_k = {}, h = {}, omega_b = {}, n_s = {}, {amplitude}, \
             w0 = {}, wa = {}{neutrinos}",
            significant(self.omega_m),
            significant(self.omega_lambda),
            significant(omega_k),
            number(self.h),
            number(self.omega_b_h2),
            number(self.n_s),
            number(self.w0),
            number(self.wa),
        )
    }
}

/// `x` in its shortest exact form, in exponent notation with a two-digit exponent (`2.105209e-09`, as
/// C's `%e`) outside 1e-4 ≤ |x| < 1e6.
fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e6).contains(&x.abs()) {
        return format!("{x}");
    }
    let text = format!("{x:e}");
    match text.split_once('e') {
        Some((mantissa, exponent)) => {
            let (sign, digits) = match exponent.strip_prefix('-') {
                Some(digits) => ("-", digits),
                None => ("+", exponent),
            };
            format!("{mantissa}e{sign}{digits:0>2}")
        }
        None => text,
    }
}

/// `x` rounded to 6 significant digits, printed by [`number`].
fn significant(x: f64) -> String {
    number(format!("{x:.5e}").parse().unwrap_or(x))
}

#[cfg(test)]
mod tests;
