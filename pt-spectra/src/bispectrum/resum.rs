//! The inputs of the infrared resummation of every leg: the no-wiggle spectrum and Σ², δΣ², either
//! from the project's wiggle split ([`IrInputs::split`], the default) or given explicitly
//! ([`IrInputs::new`], e.g. another code's no-wiggle spectrum to compare with).

use crate::error::{Error, Result};
use crate::ir::{bao_damping, sigma2_total, WiggleSplit};
use crate::linear::LinearSpectrum;

/// The no-wiggle spectrum P_nw and the BAO damping scales Σ², δΣ² [(Mpc/h)²] of the resummation
/// P(k, μ) → P_nw(k) + e^{−k²Σ²_tot(μ)} [P(k) − P_nw(k)], Σ²_tot(μ) = [1 + fμ²(2 + f)]Σ² + f²μ²(μ² − 1)δΣ²
/// (Ivanov & Sibiryakov 2018, arXiv:1804.05080; [`crate::ir::sigma2_total`]).
#[derive(Debug, Clone)]
pub struct IrInputs {
    /// The no-wiggle spectrum, at the redshift of the prediction.
    pub no_wiggle: LinearSpectrum,
    /// Σ² [(Mpc/h)²].
    pub sigma2: f64,
    /// δΣ² [(Mpc/h)²].
    pub delta_sigma2: f64,
}

impl IrInputs {
    /// Explicit inputs.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] naming Σ² or δΣ² if not finite and ≥ 0.
    pub fn new(no_wiggle: LinearSpectrum, sigma2: f64, delta_sigma2: f64) -> Result<Self> {
        for (name, v) in [("sigma2", sigma2), ("delta_sigma2", delta_sigma2)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::InvalidChoice {
                    what: format!("{name} = {v}"),
                    reason: "the BAO damping scales must be finite and >= 0 [(Mpc/h)^2]".into(),
                });
            }
        }
        Ok(Self {
            no_wiggle,
            sigma2,
            delta_sigma2,
        })
    }

    /// The inputs of P(s k) ([`LinearSpectrum::dilated`]): the no-wiggle spectrum dilated alike, Σ² and δΣ²
    /// times s² (the damping e^{−k²Σ²} of a side s k is that of a side k with s²Σ²).
    ///
    /// # Errors
    /// As [`LinearSpectrum::dilated`].
    pub fn dilated(&self, s: f64) -> Result<Self> {
        Self::new(
            self.no_wiggle.dilated(s)?,
            self.sigma2 * s * s,
            self.delta_sigma2 * s * s,
        )
    }

    /// The project's split of `spectrum` ([`WiggleSplit`]) and its Σ², δΣ² with the integrals from
    /// `q_min` [h/Mpc] (as the galaxy power spectrum does it).
    ///
    /// # Errors
    /// As [`WiggleSplit::no_wiggle`].
    pub fn split(spectrum: &LinearSpectrum, split: &WiggleSplit, q_min: f64) -> Result<Self> {
        let no_wiggle = split.no_wiggle(spectrum)?;
        let (sigma2, delta_sigma2) = bao_damping(&no_wiggle, q_min);
        let (sigma2, delta_sigma2) = (sigma2.value, delta_sigma2.value);
        Ok(Self {
            no_wiggle,
            sigma2,
            delta_sigma2,
        })
    }

    /// The resummed power at true k [h/Mpc] and μ from P(k) = `p` and P_nw(k) = `p_nw`, growth rate `f`.
    pub fn resum(&self, p: f64, p_nw: f64, k: f64, mu: f64, f: f64) -> f64 {
        let x = k * k * sigma2_total(self.sigma2, self.delta_sigma2, f, mu);
        p_nw + (-x).exp() * (p - p_nw)
    }
}
