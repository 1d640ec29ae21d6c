//! The cosmological parameters over a [`Real`] type: `f64` for values, [`Dual`] for values with their
//! exact derivatives with respect to the sampled parameters [`DERIVATIVE_NAMES`].
//!
//! A sampler varies h, ω_b, ω_cdm, ln(10¹⁰A_s), n_s, Σm_ν, w0, wa (CLASS's names; cobaya's H0/100,
//! ombh2, omch2, logA, ns, mnu, w, wa) with the curvature Ω_k held fixed. [`Cosmology`] stores the
//! derived Ω_m = (ω_b + ω_cdm + ω_ν)/h² and Ω_DE = 1 − Ω_m − Ω_k, so [`Cosmology::seeded`] builds
//! those from the seeded inputs: every quantity computed from a [`Background`] of [`Dual`]s then
//! carries its derivatives with respect to the eight sampled parameters.
//!
//! The expansion and the linear growth (E(z), D(z), f(z), D_md(z): `growth.rs`) and the distances
//! (H(z), D_M(z), D_A(z): [`super::distance`]) are methods of [`Background`] over any [`Real`], the
//! one implementation that the [`Cosmology`] methods call on [`Cosmology::background`]:
//!
//! ```
//! use pt_spectra::cosmology::Cosmology;
//! let c = Cosmology::planck2018().with_dark_energy(-0.9, -0.3)?;
//! let (d_md, f) = c.seeded()?.growth_md_and_rate(1.0);
//! let (d_md_f64, f_f64) = c.background().growth_md_and_rate(1.0);
//! assert!((d_md.v / d_md_f64 - 1.0).abs() < 1e-12 && (f.v / f_f64 - 1.0).abs() < 1e-12);
//! // ∂f/∂w0 at z = 1 (slot 6 of DERIVATIVE_NAMES): a larger w0 leaves more dark energy at z = 1,
//! // so a lower Ω_m(z) and a lower f.
//! assert!(f.d[6] < 0.0);
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

use super::{Amplitude, Cosmology, Neutrinos, EV_PER_OMEGA_NU};
use crate::dual::{Dual, Real};
use crate::error::{Error, Result};

/// The sampled parameters the cosmological derivatives are taken with respect to, in the order of
/// the derivative slots of [`CosmoDual`]: h, ω_b = Ω_b h², ω_cdm = Ω_cdm h², ln(10¹⁰ A_s), n_s,
/// Σm_ν \[eV\], w0, wa.
pub const DERIVATIVE_NAMES: [&str; 8] = [
    "h",
    "omega_b",
    "omega_cdm",
    "ln10^{10}A_s",
    "n_s",
    "m_nu",
    "w0",
    "wa",
];

/// The number of sampled parameters ([`DERIVATIVE_NAMES`]).
pub const N_DERIVATIVES: usize = DERIVATIVE_NAMES.len();

/// A value with its derivatives with respect to [`DERIVATIVE_NAMES`].
pub type CosmoDual = Dual<N_DERIVATIVES>;

/// A cosmology's parameters over `T` (module docs). The fields mirror [`Cosmology`]'s.
#[derive(Debug, Clone, Copy)]
pub struct Background<T> {
    /// Ω_m (CDM + baryons + massive neutrinos).
    pub omega_m: T,
    /// Ω_DE.
    pub omega_lambda: T,
    /// Ω_k = 1 − Ω_m − Ω_DE.
    pub omega_k: T,
    /// h.
    pub h: T,
    /// ω_b = Ω_b h².
    pub omega_b_h2: T,
    /// Σm_ν \[eV\].
    pub m_nu: T,
    /// w0.
    pub w0: T,
    /// wa.
    pub wa: T,
    /// n_s.
    pub n_s: T,
    /// ln A_s (`None` for a σ8 amplitude).
    pub ln_a_s: Option<T>,
    /// The pivot of A_s [1/Mpc] (`None` for a σ8 amplitude).
    pub k_pivot: Option<f64>,
    /// How Σm_ν is shared.
    pub neutrinos: Neutrinos,
}

impl Cosmology {
    /// The cosmology's parameters as plain values.
    pub fn background(&self) -> Background<f64> {
        let (ln_a_s, k_pivot) = match self.amplitude {
            Amplitude::As { a_s, k_pivot } => (Some(a_s.ln()), Some(k_pivot)),
            Amplitude::Sigma8(_) => (None, None),
        };
        Background {
            omega_m: self.omega_m,
            omega_lambda: self.omega_lambda,
            omega_k: self.omega_k(),
            h: self.h,
            omega_b_h2: self.omega_b_h2,
            m_nu: self.m_nu,
            w0: self.w0,
            wa: self.wa,
            n_s: self.n_s,
            ln_a_s,
            k_pivot,
            neutrinos: self.neutrinos,
        }
    }

    /// The cosmology's parameters with their derivatives with respect to [`DERIVATIVE_NAMES`]
    /// seeded (module docs): Ω_m and Ω_DE are built from h, ω_b, ω_cdm and Σm_ν at fixed Ω_k.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a cosmology normalised by σ8 (its derivatives are taken with
    /// respect to ln(10¹⁰A_s): give A_s).
    pub fn seeded(&self) -> Result<Background<CosmoDual>> {
        let Amplitude::As { a_s, k_pivot } = self.amplitude else {
            return Err(Error::InvalidChoice {
                what: "derivatives with respect to the cosmological parameters of a cosmology \
                       normalised by sigma8"
                    .into(),
                reason: "they are taken with respect to ln10^{10}A_s: give A_s (or \
                         ln10^{10}A_s) instead of sigma8"
                    .into(),
            });
        };
        let s = |v: f64, j: usize| CosmoDual::seed(v, j);
        let h = s(self.h, 0);
        let omega_b = s(self.omega_b_h2, 1);
        let omega_cdm_value = self.omega_m * self.h * self.h - self.omega_b_h2 - self.omega_nu();
        let omega_cdm = s(omega_cdm_value, 2);
        let ln_a_s = s(a_s.ln(), 3);
        let n_s = s(self.n_s, 4);
        let m_nu = s(self.m_nu, 5);
        let omega_m = (omega_b + omega_cdm + m_nu / EV_PER_OMEGA_NU) / (h * h);
        let omega_k = CosmoDual::cst(self.omega_k());
        Ok(Background {
            omega_m,
            omega_lambda: -omega_m - omega_k + 1.0,
            omega_k,
            h,
            omega_b_h2: omega_b,
            m_nu,
            w0: s(self.w0, 6),
            wa: s(self.wa, 7),
            n_s,
            ln_a_s: Some(ln_a_s),
            k_pivot: Some(k_pivot),
            neutrinos: self.neutrinos,
        })
    }
}

impl<T: Real> Background<T> {
    /// The neutrino density ω_ν = Σm_ν/93.14 eV.
    pub fn omega_nu(&self) -> T {
        self.m_nu / EV_PER_OMEGA_NU
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The seeded values are the cosmology's, and the derived densities carry the derivatives of
    /// Ω_m = (ω_b + ω_cdm + Σm_ν/93.14)/h², Ω_DE = 1 − Ω_k − Ω_m.
    #[test]
    fn seeded_values_and_density_derivatives() {
        let c = Cosmology::planck2018().with_neutrinos(0.06).unwrap();
        let c = c.with_amplitude(Amplitude::As {
            a_s: 2.1e-9,
            k_pivot: 0.05,
        });
        let c = c.unwrap();
        let b = c.seeded().unwrap();
        assert!((b.omega_m.v - c.omega_m).abs() < 1e-15);
        assert!((b.omega_lambda.v - c.omega_lambda).abs() < 1e-15);
        let h2 = c.h * c.h;
        assert!((b.omega_m.d[0] + 2.0 * c.omega_m / c.h).abs() < 1e-14);
        assert!((b.omega_m.d[1] - 1.0 / h2).abs() < 1e-14);
        assert!((b.omega_m.d[2] - 1.0 / h2).abs() < 1e-14);
        assert!((b.omega_m.d[5] - 1.0 / (EV_PER_OMEGA_NU * h2)).abs() < 1e-14);
        assert!(b.omega_m.d[3..5]
            .iter()
            .chain(&b.omega_m.d[6..])
            .all(|&d| d == 0.0));
        assert!((0..N_DERIVATIVES).all(|j| b.omega_lambda.d[j] == -b.omega_m.d[j]));
        let sigma8 = Cosmology::gm2012();
        assert!(sigma8.seeded().is_err());
        assert_eq!(c.background().omega_m, c.omega_m);
    }
}
