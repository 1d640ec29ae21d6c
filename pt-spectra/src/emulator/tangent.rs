//! The exact derivatives of the emulated linear spectrum the pipeline uses, and of its growth rate,
//! with respect to the sampled parameters [`DERIVATIVE_NAMES`] (issue 47): what a gradient-based
//! sampler's chain step needs from the emulator.
//!
//! * **What.** [`crate::setup::prepare`] with the emulator gives the tracer spectrum (P_cb with massive
//!   neutrinos, P_m otherwise: equal when Σm_ν = 0) as a [`LinearSpectrum`] through the emulated
//!   nodes, and the growth rate f: f_cb(k = [`K_GROWTH_RATE`]) interpolated from the emulated f_cb
//!   nodes with massive neutrinos, the background's f(z) otherwise. [`TracerTangent`] holds exactly
//!   those (the same code builds them) and their derivatives.
//! * **How.** The emulator's computation runs once more over [`CosmoDual`] (from
//!   [`Cosmology::seeded`]): the derivatives of ln P_i and f_i at the fixed nodes x_i = k_i r_d and of
//!   ln r_d. The nodes k_i = x_i/r_d move with r_d, so at fixed k ([`crate::linear::NodeInterpolant`])
//!   ∂ ln P(k)/∂θ = S(k; ∂ ln P_i/∂θ) + (d ln P/d ln k)(k) ∂ ln r_d/∂θ, S the spectrum's own
//!   interpolation rule (spline between the nodes, end lines beyond) applied to the node
//!   derivatives; the same for f at K_GROWTH_RATE.
//! * **Where a derivative is one-sided.** At Σm_ν = 0 the spectrum's Σm_ν derivative is the
//!   derivative from above (the only side). There the pipeline's f switches, for any Σm_ν > 0, from the
//!   background's f to the emulated f_cb(0.1), which differs by the emulator's error: f jumps, and its
//!   Σm_ν derivative given is that of the background's f. Likewise the neutrino-setting head (one
//!   massive species) switches on at Σm_ν > 0; at exactly 0 its derivative is not included.
//! * **Units:** k in h/Mpc, P in (Mpc/h)³, derivatives per unit of each parameter (Σm_ν in eV).
//!
//! ```
//! use pt_spectra::cosmology::{background::DERIVATIVE_NAMES, Cosmology};
//! use pt_spectra::emulator::LinearEmulator;
//! let emulator = LinearEmulator::embedded()?;
//! let c = Cosmology::planck2018().with_neutrinos(0.06)?;
//! let t = emulator.tracer_tangent(&c, 0.5)?;
//! let p = t.eval(0.1);
//! assert_eq!(p.v, t.spectrum().eval(0.1));
//! let n_s = DERIVATIVE_NAMES.iter().position(|&n| n == "n_s").unwrap();
//! // P ∝ (k h/k_pivot)^(n_s − 1) at fixed everything else: ∂ ln P/∂n_s = ln(0.1 h/0.05)
//! assert!((p.d[n_s] / p.v - (0.1 * c.h / 0.05f64).ln()).abs() < 1e-9);
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

use super::LinearEmulator;
use super::K_GROWTH_RATE;
#[cfg(doc)]
use crate::cosmology::background::DERIVATIVE_NAMES;
use crate::cosmology::background::{CosmoDual, N_DERIVATIVES};
use crate::cosmology::Cosmology;
use crate::error::Result;
use crate::linear::{LinearSpectrum, NodeInterpolant};

/// The tracer spectrum and the growth rate the pipeline uses for one cosmology at one redshift
/// ([`LinearEmulator::tracer_tangent`]), with their derivatives with respect to
/// [`DERIVATIVE_NAMES`] (module docs).
#[derive(Debug, Clone)]
pub struct TracerTangent {
    /// The tracer spectrum, as [`crate::setup::prepare`] gives it.
    spectrum: LinearSpectrum,
    /// ∂ ln P_i/∂θ_j at the fixed x_i, interpolated by the spectrum's rule, per parameter j.
    d_ln_p: Vec<NodeInterpolant>,
    /// ∂ ln r_d/∂θ_j.
    d_ln_r_d: [f64; N_DERIVATIVES],
    /// f and its derivatives.
    growth_rate: CosmoDual,
}

impl LinearEmulator {
    /// The tracer spectrum and growth rate of `cosmology` at `z` as [`crate::setup::prepare`] gives
    /// them with this emulator, with their exact derivatives with respect to [`DERIVATIVE_NAMES`]
    /// (h, ω_b, ω_cdm, ln(10¹⁰A_s), n_s, Σm_ν, w0, wa at fixed Ω_k; module docs). About the cost of
    /// ten [`spectra`](Self::spectra).
    ///
    /// # Errors
    /// [`crate::error::Error::InvalidChoice`] for a cosmology normalised by σ8 (as
    /// [`Cosmology::seeded`]); otherwise as [`spectra`](Self::spectra) (parameters outside the
    /// prior, a curved cosmology, a redshift outside the range, a neutrino setting not emulated).
    pub fn tracer_tangent(&self, cosmology: &Cosmology, z: f64) -> Result<TracerTangent> {
        let seeded = cosmology.seeded()?;
        let e = self.spectra(cosmology, z)?;
        let nodes = self.nodes(cosmology, &seeded, z)?;
        let d_ln_r_d = nodes.ln_r_d.d;
        // as crate::setup::prepare: P_cb and f_cb(K_GROWTH_RATE) with massive neutrinos
        let massive = cosmology.m_nu > 0.0;
        let (spectrum, ln_p) = if massive {
            (e.cb()?, nodes.ln_p_cb)
        } else {
            let ln_p_m = (nodes.ln_p_cb.iter().zip(&nodes.ln_ratio))
                .map(|(&p, &r)| p + r)
                .collect();
            (e.matter()?, ln_p_m)
        };
        let d_ln_p = (0..N_DERIVATIVES)
            .map(|j| spectrum.interpolant(ln_p.iter().map(|y| y.d[j]).collect()))
            .collect::<Result<Vec<_>>>()?;
        let growth_rate = if massive {
            let f_of_k = e.growth_rate_cb()?;
            let d_ln_f: Vec<NodeInterpolant> = (0..N_DERIVATIVES)
                .map(|j| f_of_k.interpolant(nodes.f_cb.iter().map(|f| f.d[j] / f.v).collect()))
                .collect::<Result<_>>()?;
            at_fixed_k(&f_of_k, &d_ln_f, &d_ln_r_d, K_GROWTH_RATE)
        } else {
            let f = cosmology.growth_factor_and_rate(z).1;
            CosmoDual::new(f, seeded.growth_factor_and_rate(z).1.d)
        };
        Ok(TracerTangent {
            spectrum,
            d_ln_p,
            d_ln_r_d,
            growth_rate,
        })
    }
}

impl TracerTangent {
    /// The tracer spectrum, identical to what [`crate::setup::prepare`] gives as
    /// [`tracer_spectrum`](crate::setup::Prepared::tracer_spectrum) for this cosmology, redshift and
    /// emulator.
    pub fn spectrum(&self) -> &LinearSpectrum {
        &self.spectrum
    }

    /// The growth rate f the pipeline uses ([`crate::setup::Prepared::growth_rate`]; module docs),
    /// with its derivatives with respect to [`DERIVATIVE_NAMES`].
    pub fn growth_rate(&self) -> CosmoDual {
        self.growth_rate
    }

    /// P(k) in (Mpc/h)³ at a fixed k in h/Mpc ([`LinearSpectrum::eval`] of
    /// [`spectrum`](Self::spectrum)), with ∂P(k)/∂θ_j for θ = [`DERIVATIVE_NAMES`] (module docs).
    /// For k ≤ 0, P = 0 with no derivative; NaN for NaN.
    pub fn eval(&self, k: f64) -> CosmoDual {
        if k.is_nan() || k <= 0.0 {
            let v = self.spectrum.eval(k);
            return CosmoDual::new(v, [v; N_DERIVATIVES]);
        }
        at_fixed_k(&self.spectrum, &self.d_ln_p, &self.d_ln_r_d, k)
    }

    /// [`eval`](Self::eval) at each of `k` [h/Mpc].
    pub fn eval_many(&self, k: &[f64]) -> Vec<CosmoDual> {
        k.iter().map(|&k| self.eval(k)).collect()
    }
}

/// The value of `spectrum` at k > 0 [h/Mpc] with its derivatives: ∂ ln P/∂θ_j =
/// `d_ln_nodes[j]`(k) + (d ln P/d ln k)(k) ∂ ln r_d/∂θ_j (module docs).
fn at_fixed_k(
    spectrum: &LinearSpectrum,
    d_ln_nodes: &[NodeInterpolant],
    d_ln_r_d: &[f64; N_DERIVATIVES],
    k: f64,
) -> CosmoDual {
    let p = spectrum.eval(k);
    let slope = spectrum.log_slope(k);
    CosmoDual::new(
        p,
        std::array::from_fn(|j| p * (d_ln_nodes[j].eval(k) + slope * d_ln_r_d[j])),
    )
}

#[cfg(test)]
mod tests;
