//! The tree-level galaxy bispectrum in redshift space, its multipoles and their averages over the
//! triangle bins of a measurement.
//!
//! Units: k in h/Mpc, P in (Mpc/h)³, B in (Mpc/h)⁶, n̄ in (h/Mpc)³, σ and lengths in Mpc/h.
//!
//! **Model** (Scoccimarro, Couchman & Frieman 1999; bias and stochastic terms as the EFT analyses,
//! Ivanov et al. 2022, arXiv:2110.10161, eq. 2.5), for sides k₁ + k₂ + k₃ = 0 and μᵢ = n̂·k̂ᵢ:
//!
//! ```text
//! B = 2 Z₁(k₁) Z₁(k₂) Z₂(k₁, k₂) P(k₁) P(k₂) + 2 cyclic
//!   + (1/n̄) [b₁ B_shot + f μ₁² (1 + P_shot)] Z₁(k₁) P(k₁) + 2 cyclic  +  (1 + A_shot)/n̄²,
//! Z₁(k) = b₁ + f μ² − c₁ k² μ²,
//! Z₂(k₁, k₂) = b₁ F₂ + f μ₁₂² G₂ + (f μ₁₂ k₁₂ / 2) [μ₁/k₁ (b₁ + f μ₂²) + μ₂/k₂ (b₁ + f μ₁²)]
//!              + b₂/2 + b_s S₂,   S₂ = (k̂₁·k̂₂)² − 1/3,
//! ```
//!
//! with k₁₂ = k₁ + k₂, μ₁₂ its cosine with the line of sight, F₂, G₂ the SPT kernels. The bias is
//! velocileptors' (δ_g ⊃ (b₂/2)δ² + b_s s²), the same as the galaxy power spectrum `ept`
//! ([`crate::rsd::ept`]); CLASS-PT's b_G2 and b₂ map as b_s = b_G2, b₂ = b₂^CLASS-PT − (4/3) b_G2
//! ([`BispectrumParams::from_class_pt`]), and the DESI "physical" basis (b₁σ₈, b₂σ₈², b_sσ₈²) by
//! [`BispectrumParams::from_physical`]. Poisson shot noise is B_shot = 1, P_shot = A_shot = 0 (it gives
//! (1/n̄)Σ P_g(kᵢ) + 1/n̄² with P_g = Z₁²P). FolpsD and PyBird write the same two stochastic shapes
//! with their own amplitudes: their (1 + P_shot)/n̄ and B_shot/n̄ are these.
//! c₁ [(Mpc/h)²] is the leading counterterm of the EFT analyses, k²μ² in each leg.
//!
//! **Infrared resummation** (optional, as the galaxy power spectrum): in every leg P → P_nw +
//! e^{−k²Σ²_tot(μ)} P_w, Σ²_tot(μ) = [1 + fμ²(2 + f)]Σ² + f²μ²(μ² − 1)δΣ² ([`crate::ir`]).
//! **Fingers of God** ([`Fog`]): a factor D(Σᵢ kᵢ²μᵢ² σ²/2) on every term but 1/n̄²: none, Lorentzian
//! D(x) = (1 + x)⁻², or Gaussian e^{−x} (Gil-Marín et al. 2014, arXiv:1407.5668).
//! **Alcock–Paczynski**: sides observed in the fiducial cosmology are k∥/q∥, k⊥/q⊥ in the true one and
//! B_obs = B_true/(q∥² q⊥⁴).
//!
//! **Multipoles** (Scoccimarro et al. 1999): B_ℓ(k₁, k₂, k₃) = (2ℓ + 1) ⟨B L_ℓ(μ_a)⟩ over the
//! orientations of the triangle (μ_a and the azimuth about k_a), with the Legendre polynomial
//! on the side a of the largest bin (default, as the window-free estimator of Philcox 2021,
//! arXiv:2107.06287) or a chosen one. Orientation rule: Gauss–Legendre in μ_a ∈ [0, 1], trapezoid in
//! the azimuth (B is even in n̂; the rule is exact for the polynomial part, degree ≤ 12 in n̂).
//!
//! **Bins** ([`TriangleSet`]): at the given triangles, or averaged over all closed triangles of three
//! shells of width Δk, weight k₁k₂k₃ (the number of closed triangles of modes, per dk₁dk₂dk₃), with k₃
//! integrated over the part of its shell where the triangle closes, on panels split where that part
//! changes form. Every B_ℓ carries an error: the
//! difference from a coarser rule (orientation and shells).

pub mod bias_kernels;
pub mod bias_poly;
mod bin_rows;
pub mod block;
mod box_modes;
pub mod counterterm_plan;
pub mod galaxy_counterterms;
pub mod galaxy_counterterms_rsd;
mod geometry;
mod ir_legs;
mod lanes;
pub mod loop_block;
pub mod loop_tensors;
mod measured;
mod multipole_acc;
pub mod multipole_basis;
pub mod multipole_bins;
mod multipole_cache;
mod multipole_tensors;
mod observed;
pub mod one_loop;
pub mod one_loop_basis;
pub mod one_loop_bins;
pub mod one_loop_galaxy;
pub mod one_loop_galaxy_basis;
pub mod one_loop_galaxy_multipoles;
pub mod one_loop_galaxy_poly;
pub mod one_loop_ir;
pub mod one_loop_rsd;
mod redshift_weights;
mod resum;
mod sampled;
pub mod seam;
mod sugiyama;
mod terms;
#[cfg(test)]
mod tests;

pub use box_modes::BoxPlan;
pub use geometry::{LegendreSide, TriangleSet};
pub use resum::IrInputs;
pub use sugiyama::{SugiyamaPlan, SugiyamaRules, SugiyamaTerms, SUGIYAMA_MULTIPOLES};
pub use terms::{tree_level_at, BispectrumPlan, BispectrumTerms, PlanRules};

use crate::error::{Error, Result};

/// Multipoles ℓ of the bispectrum that plans compute.
pub const ELLS: [usize; 3] = [0, 2, 4];

/// The Fingers-of-God damping of the bispectrum, σ in Mpc/h.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fog {
    /// No damping.
    None,
    /// (1 + Σᵢkᵢ²μᵢ²σ²/2)⁻².
    Lorentzian {
        /// σ_B [Mpc/h].
        sigma: f64,
    },
    /// exp(−Σᵢkᵢ²μᵢ²σ²/2).
    Gaussian {
        /// σ_B [Mpc/h].
        sigma: f64,
    },
}

impl Fog {
    /// The choices by name, as the CLI and Python take them.
    pub const NAMES: [&'static str; 3] = ["none", "lorentzian", "gaussian"];

    /// The damping by name with σ_B [Mpc/h].
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for an unknown name (listing [`Fog::NAMES`]) or σ_B < 0 / not finite.
    pub fn by_name(name: &str, sigma: f64) -> Result<Self> {
        if !(sigma.is_finite() && sigma >= 0.0) {
            return Err(Error::InvalidChoice {
                what: format!("sigma_fog = {sigma}"),
                reason: "σ_B must be finite and >= 0 [Mpc/h]".into(),
            });
        }
        match name.to_ascii_lowercase().as_str() {
            "none" => Ok(Self::None),
            "lorentzian" => Ok(Self::Lorentzian { sigma }),
            "gaussian" => Ok(Self::Gaussian { sigma }),
            _ => Err(Error::InvalidChoice {
                what: format!("fog = {name}"),
                reason: format!("valid: {}", Self::NAMES.join(", ")),
            }),
        }
    }

    /// The factor at x = Σᵢkᵢ²μᵢ² [(h/Mpc)²].
    pub(crate) fn factor(&self, x: f64) -> f64 {
        match *self {
            Self::None => 1.0,
            Self::Lorentzian { sigma } => {
                let d = 1.0 + 0.5 * x * sigma * sigma;
                1.0 / (d * d)
            }
            Self::Gaussian { sigma } => (-0.5 * x * sigma * sigma).exp(),
        }
    }

    /// One line for a table header.
    pub fn describe(&self) -> String {
        match self {
            Self::None => "none".into(),
            Self::Lorentzian { sigma } => {
                format!("Lorentzian (1 + Σk²μ²σ²/2)^-2, σ_B = {sigma} Mpc/h")
            }
            Self::Gaussian { sigma } => format!("Gaussian exp(-Σk²μ²σ²/2), σ_B = {sigma} Mpc/h"),
        }
    }
}

/// The parameters the bispectrum is a polynomial in (velocileptors' bias convention, see the module
/// docs). Stochastic amplitudes are dimensionless; Poisson is b_shot = 1, p_shot = a_shot = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BispectrumParams {
    /// Linear bias b₁.
    pub b1: f64,
    /// Quadratic bias b₂ ((b₂/2)δ²).
    pub b2: f64,
    /// Tidal bias b_s (b_s s², s² kernel (k̂₁·k̂₂)² − 1/3).
    pub bs: f64,
    /// Counterterm c₁ [(Mpc/h)²]: Z₁ → Z₁ − c₁k²μ².
    pub c1: f64,
    /// B_shot: (1/n̄) b₁ B_shot Z₁(kᵢ)P(kᵢ) + cyclic.
    pub b_shot: f64,
    /// P_shot: (1/n̄)(1 + P_shot) fμᵢ² Z₁(kᵢ)P(kᵢ) + cyclic.
    pub p_shot: f64,
    /// A_shot: (1 + A_shot)/n̄².
    pub a_shot: f64,
    /// Number density n̄ [(h/Mpc)³]; infinite for no stochastic terms.
    pub n_bar: f64,
}

impl Default for BispectrumParams {
    /// Matter: b₁ = 1, no higher bias, no counterterm, no shot noise (n̄ = ∞).
    fn default() -> Self {
        Self {
            b1: 1.0,
            b2: 0.0,
            bs: 0.0,
            c1: 0.0,
            b_shot: 1.0,
            p_shot: 0.0,
            a_shot: 0.0,
            n_bar: f64::INFINITY,
        }
    }
}

impl BispectrumParams {
    /// The parameter names, as the CLI flags and Python keywords.
    pub const NAMES: [&'static str; 8] = [
        "b1", "b2", "bs", "c1", "b_shot", "p_shot", "a_shot", "n_bar",
    ];

    /// Velocileptors' b₂, b_s from CLASS-PT's b₂, b_G2 (same b₁): b_s = b_G2, b₂ = b₂^CLASS-PT − (4/3)b_G2.
    pub fn from_class_pt(b1: f64, b2_class_pt: f64, b_g2: f64) -> Self {
        Self {
            b1,
            b2: b2_class_pt - 4.0 / 3.0 * b_g2,
            bs: b_g2,
            ..Self::default()
        }
    }

    /// CLASS-PT's (b₂, b_G2) of these parameters.
    pub fn to_class_pt(&self) -> (f64, f64) {
        (self.b2 + 4.0 / 3.0 * self.bs, self.bs)
    }

    /// From the DESI physical basis (b₁σ₈, b₂σ₈², b_sσ₈²) at σ₈(z) `sigma8_z`.
    pub fn from_physical(
        b1_sigma8: f64,
        b2_sigma8_sq: f64,
        bs_sigma8_sq: f64,
        sigma8_z: f64,
    ) -> Self {
        let s2 = sigma8_z * sigma8_z;
        Self {
            b1: b1_sigma8 / sigma8_z,
            b2: b2_sigma8_sq / s2,
            bs: bs_sigma8_sq / s2,
            ..Self::default()
        }
    }

    /// (b₁σ₈, b₂σ₈², b_sσ₈²) at σ₈(z) `sigma8_z`.
    pub fn to_physical(&self, sigma8_z: f64) -> (f64, f64, f64) {
        let s2 = sigma8_z * sigma8_z;
        (self.b1 * sigma8_z, self.b2 * s2, self.bs * s2)
    }

    /// Checks every value is finite and n̄ > 0.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] naming the parameter.
    pub fn validate(&self) -> Result<()> {
        let values = [
            self.b1,
            self.b2,
            self.bs,
            self.c1,
            self.b_shot,
            self.p_shot,
            self.a_shot,
        ];
        for (name, v) in Self::NAMES.iter().zip(values) {
            if !v.is_finite() {
                return Err(Error::InvalidChoice {
                    what: format!("{name} = {v}"),
                    reason: "bispectrum parameters must be finite".into(),
                });
            }
        }
        if self.n_bar.is_nan() || self.n_bar <= 0.0 {
            return Err(Error::InvalidChoice {
                what: format!("n_bar = {}", self.n_bar),
                reason: "the number density must be > 0 [(h/Mpc)^3] (inf for no shot noise)".into(),
            });
        }
        Ok(())
    }

    /// One line for a table header.
    pub fn describe(&self) -> String {
        format!(
            "b1 = {}, b2 = {}, bs = {}, c1 = {} (Mpc/h)^2, b_shot = {}, p_shot = {}, a_shot = {}, n_bar = {} (h/Mpc)^3",
            self.b1, self.b2, self.bs, self.c1, self.b_shot, self.p_shot, self.a_shot, self.n_bar
        )
    }
}

/// What the bispectrum of one spectrum depends on beyond the linear spectrum and the polynomial
/// parameters: the growth rate, AP and Fingers of God.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Growth rate f.
    pub f: f64,
    /// q∥ = α∥ (1 for no AP).
    pub q_par: f64,
    /// q⊥ = α⊥ (1 for no AP).
    pub q_perp: f64,
    /// Fingers of God.
    pub fog: Fog,
    /// Infrared resummation of the BAO in every leg.
    pub ir: bool,
}

impl Settings {
    /// Checks f is finite and plausible ([`crate::cosmology::check_growth_rate`]), q∥, q⊥ finite and > 0.
    ///
    /// # Errors
    /// As [`crate::cosmology::check_growth_rate`]; [`Error::InvalidChoice`] naming q∥ or q⊥.
    pub fn validate(&self) -> Result<()> {
        crate::cosmology::check_growth_rate(self.f)?;
        for (name, q) in [("q_par", self.q_par), ("q_perp", self.q_perp)] {
            if !(q.is_finite() && q > 0.0) {
                return Err(Error::InvalidChoice {
                    what: format!("{name} = {q}"),
                    reason: "AP scalings must be finite and > 0".into(),
                });
            }
        }
        Ok(())
    }
    /// Checks the IR resummation is on (for inputs given explicitly).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] if `ir` is false.
    pub(crate) fn require_ir(&self) -> Result<()> {
        if self.ir {
            Ok(())
        } else {
            Err(Error::InvalidChoice {
                what: "IR inputs with ir = false".into(),
                reason: "explicit IR inputs (no-wiggle spectrum, Sigma^2) need the resummation on"
                    .into(),
            })
        }
    }
}
