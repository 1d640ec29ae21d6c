//! How the sum of the neutrino masses Σm_ν is shared among the species ([`Neutrinos`]), and the
//! effective number of relativistic species N_eff.
//!
//! The setting matters for the linear spectra (one massive species of 0.39 eV suppresses P(k = 0.02)
//! 3.7% less than three of 0.13 eV), so the emulator ([`crate::emulator`]) emulates each setting it
//! accepts and refuses the others; the background and the scale-independent growth of
//! [`Cosmology`](super::Cosmology) depend on Σm_ν alone (ω_ν = Σm_ν/93.14 eV).

use std::fmt;

/// The standard effective number of relativistic species (three neutrinos with the standard
/// non-instantaneous decoupling), CAMB's default; CLASS's default is 3.044 (see [`N_EFF_TOL`]).
pub const N_EFF_STANDARD: f64 = 3.046;

/// Largest |N_eff − 3.045| accepted as the standard N_eff: CAMB's 3.046 and CLASS's 3.044 (with
/// `N_ur` 2.0308 for one massive species) both count as standard; their difference changes the
/// linear spectrum by ~1e-4, a tenth of the emulator's error. Rounded inputs (`N_ur = 2.0328`, `nnu =
/// 3.046`) sit well inside.
pub const N_EFF_TOL: f64 = 0.0015 + 1e-6;

/// The contribution of one massive species of CLASS's default temperature T_ncdm = 0.71611 T_CMB to
/// N_eff while relativistic: (T_ncdm/(4/11)^{1/3})⁴ = 1.0132 (so that `N_ur` = 2.0328 and one massive
/// species make N_eff = 3.046).
pub const N_EFF_PER_NCDM: f64 = 1.0132;

/// Whether `n_eff` counts as the standard N_eff ([`N_EFF_TOL`]).
pub fn standard_n_eff(n_eff: f64) -> bool {
    (n_eff - (N_EFF_STANDARD - 0.001)).abs() <= N_EFF_TOL
}

/// How Σm_ν is shared among the neutrino species; N_eff is standard ([`N_EFF_STANDARD`]) in all.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Neutrinos {
    /// Three degenerate massive species of Σm_ν/3 each: pt-spectra's own default
    /// ([`Cosmology::with_neutrinos`](super::Cosmology::with_neutrinos), the key `m_nu`), CAMB's
    /// `num_massive_neutrinos = 3` (`neutrino_hierarchy = degenerate`), CLASS's three equal `m_ncdm` or
    /// `deg_ncdm = 3`.
    #[default]
    ThreeDegenerate,
    /// One massive species of mass Σm_ν and the rest massless (N_eff − 1.0132 of them): CAMB's default
    /// (`mnu` alone, `num_massive_neutrinos = 1`), CLASS's `N_ncdm = 1` (with `N_ur = 2.0328`), and
    /// the baseline of Planck and DESI for Σm_ν = 0.06 eV.
    OneMassive,
    /// CAMB's `neutrino_hierarchy = normal`: three species with the measured mass splittings, m1
    /// smallest.
    NormalHierarchy,
    /// CAMB's `neutrino_hierarchy = inverted`: m3 smallest.
    InvertedHierarchy,
}

impl Neutrinos {
    /// The name used in headers, Python's `meta` and the CLI.
    pub fn name(self) -> &'static str {
        match self {
            Self::ThreeDegenerate => "three degenerate",
            Self::OneMassive => "one massive",
            Self::NormalHierarchy => "normal hierarchy",
            Self::InvertedHierarchy => "inverted hierarchy",
        }
    }

    /// A sentence for output headers: the setting and how CAMB and CLASS spell it.
    pub fn describe(self) -> &'static str {
        match self {
            Self::ThreeDegenerate => {
                "three degenerate massive species of Sigma m_nu/3 each, N_eff = 3.046 (CAMB \
                 num_massive_neutrinos = 3; CLASS N_ncdm = 1, deg_ncdm = 3, N_ur = 0.00641)"
            }
            Self::OneMassive => {
                "one massive species of mass Sigma m_nu and 2.0328 massless, N_eff = 3.046 (CAMB's \
                 default num_massive_neutrinos = 1; CLASS N_ncdm = 1, N_ur = 2.0328)"
            }
            Self::NormalHierarchy => "three species in the normal hierarchy (CAMB)",
            Self::InvertedHierarchy => "three species in the inverted hierarchy (CAMB)",
        }
    }
}

impl fmt::Display for Neutrinos {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
