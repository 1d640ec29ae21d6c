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
//! * Growth, for any other w0, wa: the linear growth equation in ln a (e.g. Linder & Jenkins 2003),
//!   D″ + (2 + d ln E/d ln a) D′ − (3/2) Ω_m a⁻³/E² D = 0, for the growing mode started deep in matter
//!   domination (D = D′ = a at a = 1e-8), integrated by an adaptive Dormand–Prince 5(4) Runge–Kutta method
//!   to ~1e-11 relative; D is normalised to D(z=0) = 1 and f = D′/D. The tests check the ODE against
//!   Heath's integral (flat and curved), Einstein–de Sitter, the flat-ΛCDM hypergeometric closed form and
//!   w = −1/3 (which dilutes like curvature) to ≤ 1e-8. Scale-independent: dark energy is taken to be
//!   smooth (no perturbations), as in the CAMB "fluid"/PPF models on sub-horizon scales.
//! * Transfer functions: Eisenstein & Hu (1998, ApJ 496, 605; astro-ph/9709112), the full fit with baryon
//!   acoustic oscillations (their §3, eqs. 2–24) and the smooth "no-wiggle" fit (§4.2, eqs. 26–31), with
//!   T_CMB = [`T_CMB_K`]. [`Cosmology::eisenstein_hu_spectrum`] turns them into P(k) = A k^{n_s} T²(k)
//!   normalised to σ8, as a [`LinearSpectrum`].
//!
//! Units: k in h/Mpc, P in (Mpc/h)^3, lengths in Mpc/h unless stated otherwise.

use crate::error::{Error, Result};
use crate::linear::{LinearSpectrum, LogGrid};

/// CMB temperature in K used by the Eisenstein & Hu transfer functions (the CAMB default).
pub const T_CMB_K: f64 = 2.7255;

mod eisenstein_hu;
mod growth;

pub use eisenstein_hu::{EisensteinHu, TransferKind};

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
    /// RMS linear density fluctuation in spheres of 8 Mpc/h at z = 0.
    pub sigma8: f64,
    /// Dark-energy equation of state today, w0 (−1 for a cosmological constant).
    pub w0: f64,
    /// Dark-energy equation-of-state slope wa, w(a) = w0 + wa (1 − a) (0 for a cosmological constant).
    pub wa: f64,
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
            sigma8: 0.8,
            w0: -1.0,
            wa: 0.0,
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
            sigma8,
            w0: -1.0,
            wa: 0.0,
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

    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless all are finite, Ω_m > 0, Ω_DE ≥ 0, h > 0,
    /// 0 < Ω_b h² < Ω_m h², σ8 > 0, w0 + wa < 0 (so that w(a → 0) < 0 and dark energy is subdominant at
    /// early times, as the growth's start in matter domination needs), and E²(a) > 0 for all 0 < a ≤ 1
    /// (no bounce).
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value, reason| {
            Err(Error::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        let positive = "must be finite and positive";
        for (name, v) in [
            ("Omega_m", self.omega_m),
            ("h", self.h),
            ("sigma8", self.sigma8),
        ] {
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
        if (1..=1000).any(|i| self.a2e2(f64::from(i) / 1000.0) <= 0.0) {
            return bad(
                "Omega_k",
                self.omega_k(),
                "H^2 vanishes for some a <= 1 (bouncing model)",
            );
        }
        Ok(())
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

    /// Eisenstein & Hu (1998) linear spectrum P(k, z) = A k^{n_s} T²(k) D²(z) on `grid`, with A set so that
    /// σ(8 Mpc/h) = `self.sigma8` at z = 0 (top hat, [`LinearSpectrum::sigma_r`]).
    ///
    /// [`TransferKind::NoWiggle`] gives the smooth spectrum by which BAO features are divided out
    /// (P_lin/P_nw); with the same σ8 it matches the broadband of the [`TransferKind::Wiggle`] one.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an invalid cosmology or redshift.
    ///
    /// ```
    /// use pt_spectra::{cosmology::{Cosmology, TransferKind}, linear::LogGrid};
    /// let p = Cosmology::gm2012().eisenstein_hu_spectrum(TransferKind::NoWiggle, 0.0, &LogGrid::default())?;
    /// assert!((p.sigma8() - 0.8).abs() < 1e-9);
    /// # Ok::<(), pt_spectra::error::Error>(())
    /// ```
    pub fn eisenstein_hu_spectrum(
        &self,
        kind: TransferKind,
        z: f64,
        grid: &LogGrid,
    ) -> Result<LinearSpectrum> {
        let eh = EisensteinHu::new(self)?;
        let shape =
            LinearSpectrum::from_fn(grid, |k| k.powf(self.n_s) * eh.transfer(kind, k).powi(2))?;
        let sigma = shape.sigma_r(8.0)?.0;
        let normalised = shape.scaled((self.sigma8 / sigma).powi(2))?;
        self.rescale(&normalised, 0.0, z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// CAMB includes radiation and scale-dependent baryon effects that the ΛCDM growth integral neglects.
    const CAMB_GROWTH_TOL: f64 = 1e-3;

    #[test]
    fn rescaling_follows_growth_squared() {
        let c = Cosmology::gm2012();
        let p0 = LinearSpectrum::gm2012_z0();
        let p1 = c.rescale(&p0, 0.0, 1.0).unwrap();
        let camb1 = LinearSpectrum::gm2012(1.0).unwrap();
        for k in [1e-3, 0.05, 0.2] {
            assert!(
                (p1.eval(k) / camb1.eval(k) - 1.0).abs() < 2.0 * CAMB_GROWTH_TOL,
                "k {k}"
            );
        }
        assert!(c.rescale(&p0, -1.0, 0.0).is_err());
    }

    #[test]
    fn invalid_cosmologies_are_rejected() {
        assert!(Cosmology::gm2012().validate().is_ok());
        assert!(Cosmology::flat(-0.1, 0.7, 0.02, 0.96, 0.8).is_err());
        assert!(Cosmology::flat(0.3, 0.7, 0.5, 0.96, 0.8).is_err());
        assert!(Cosmology::flat(0.3, f64::NAN, 0.02, 0.96, 0.8).is_err());
        assert!(Cosmology::new(0.1, 3.0, 0.7, 0.002, 0.96, 0.8).is_err()); // bounce
        let e = Cosmology::flat(0.3, 0.7, 0.02, 0.96, -0.8).unwrap_err();
        assert!(e.to_string().contains("sigma8 = -0.8"), "{e}");
        let flat = Cosmology::flat(0.3, 0.7, 0.02, 0.96, 0.8).unwrap();
        assert!(flat.with_dark_energy(-0.9, 0.3).is_ok());
        let e = flat.with_dark_energy(-0.5, 0.75).unwrap_err();
        assert!(e.to_string().contains("w0 + wa = 0.25"), "{e}");
        assert!(flat.with_dark_energy(f64::INFINITY, -2.0).is_err());
        // Closed: with Λ, a²E² = 0.3/a − 0.8 + 1.5a² > 0.16; with phantom w = −2 dark energy,
        // a²E² = 0.3/a − 0.8 + 1.5a⁵ < 0 near a = 0.5.
        let closed = Cosmology::new(0.3, 1.5, 0.7, 0.02, 0.96, 0.8).unwrap();
        let e = closed.with_dark_energy(-2.0, 0.0).unwrap_err();
        assert!(e.to_string().contains("bouncing"), "{e}");
    }

    fn ratios(kind: TransferKind) -> (LinearSpectrum, LinearSpectrum) {
        let c = Cosmology::gm2012();
        let eh = c
            .eisenstein_hu_spectrum(kind, 0.0, &LogGrid::default())
            .unwrap();
        (eh, LinearSpectrum::gm2012_z0())
    }

    #[test]
    fn eisenstein_hu_broadband_matches_camb() {
        let (nw, camb) = ratios(TransferKind::NoWiggle);
        let (w, _) = ratios(TransferKind::Wiggle);
        assert!((nw.sigma8() - 0.8).abs() < 1e-9 && (w.sigma8() - 0.8).abs() < 1e-9);
        let (mut worst_nw, mut worst_w) = (0.0_f64, 0.0_f64);
        for k in LogGrid::new(0.01, 0.3, 100).unwrap().points() {
            worst_nw = worst_nw.max((nw.eval(k) / camb.eval(k) - 1.0).abs());
            worst_w = worst_w.max((w.eval(k) / camb.eval(k) - 1.0).abs());
        }
        println!("max |P_EH/P_CAMB - 1| on 0.01-0.3: no-wiggle {worst_nw:.4}, wiggle {worst_w:.4}");
        assert!(worst_nw < 0.08, "{worst_nw}");
        assert!(worst_w < 0.05, "{worst_w}");
    }
}
