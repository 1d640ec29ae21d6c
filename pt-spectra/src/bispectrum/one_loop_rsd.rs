//! The one-loop matter bispectrum in redshift space (standard perturbation theory) at one orientation
//! of the triangle to the line of sight, by direct integrals: the terms of [`super::one_loop`] with the
//! redshift-space kernels Z_n(f, n̂) of [`pt_kernels::redshift`] (exact generated code, Z₄ included) in
//! place of F_n, and Z₁(k) = 1 + fμ² on every linear leg (Scoccimarro, Couchman & Frieman 1999,
//! arXiv:astro-ph/9808305; e.g. Rampf & Wong 2012 for the one-loop terms):
//!
//! ```text
//! B₁₁₂   = Σ_{a<b} 2 Z₂(k_a, k_b) Z₁(k_a) Z₁(k_b) P_a P_b,
//! B₂₂₂   = 8 ∫_q Z₂(−q, q + k₁) Z₂(−q − k₁, q − k₂) Z₂(k₂ − q, q) P(q) P(|q + k₁|) P(|k₂ − q|),
//! B₃₂₁ᴵ  = Σ_{a≠b} 6 Z₁(k_a) P_a ∫_q Z₃(−q, q − k_b, −k_a) Z₂(q, k_b − q) P(q) P(|k_b − q|),
//! B₃₂₁ᴵᴵ = Σ_{a≠b} 6 Z₂(k_a, k_b) Z₁(k_b) P_a P_b ∫_q Z₃(k_a, q, −q) P(q),
//! B₄₁₁   = Σ_a 12 Z₁(k_b) Z₁(k_c) P_b P_c ∫_q Z₄(q, −q, −k_b, −k_c) P(q).
//! ```
//!
//! The orientation ([`Orientation`]): in the triangle's frame (k₁ along z, k₂ in the x–z plane with
//! positive x), n̂ = (sin θ cos φ, sin θ sin φ, cos θ), μ₁ = cos θ the cosine between k₁ and the line of
//! sight and φ the azimuth of n̂ about k₁ from the triangle's plane. The rule is that of the real-space
//! terms, with φ of the loop momentum over the whole circle (2 × `phi` nodes) unless the line of sight
//! lies in the triangle's plane (then the integrands are even in φ, as in real space). At f = 0 every
//! term is the real-space one.
//!
//! What is not here yet (issue 50): bias, the counterterms and stochastic terms of the redshift-space
//! EFT, IR resummation, the average over orientations (multipoles), basis tensors.

use super::one_loop::{loop_integrals, triangle_vectors, Kernels, OneLoopRule, Vec3};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::linear::LinearSpectrum;
use crate::vec3::norm;

/// The orientation of a triangle to the line of sight (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orientation {
    /// μ₁: the cosine between k₁ and the line of sight.
    pub mu1: f64,
    /// φ: the azimuth of the line of sight about k₁, from the triangle's plane (on the side of k₂)
    /// (radians).
    pub phi: f64,
}

impl Orientation {
    /// The growth rate and line of sight of `(f, orientation)`, both checked: what the redshift-space
    /// terms take (`Option::map` over an optional redshift-space setting).
    ///
    /// # Errors
    /// As [`crate::cosmology::check_growth_rate`] (f outside [0, 2]) and [`Self::line_of_sight`].
    pub fn checked_with((f, orientation): (f64, Orientation)) -> Result<(f64, Vec3)> {
        crate::cosmology::check_growth_rate(f)?;
        Ok((f, orientation.line_of_sight()?))
    }

    /// The line of sight in the triangle's frame.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for μ₁ outside [−1, 1] or a φ that is not finite.
    pub fn line_of_sight(&self) -> Result<Vec3> {
        if !(-1.0..=1.0).contains(&self.mu1) {
            return Err(Error::InvalidParameter {
                name: "mu1",
                value: self.mu1,
                reason: "the cosine between k1 and the line of sight must lie in [-1, 1]",
            });
        }
        if !self.phi.is_finite() {
            return Err(Error::InvalidParameter {
                name: "phi",
                value: self.phi,
                reason: "the azimuth of the line of sight must be finite",
            });
        }
        let s = (1.0 - self.mu1 * self.mu1).sqrt();
        // An exact zero for φ = 0 or π (sin π is 1.2e-16): the mirror symmetry is then used.
        let x = self.phi.rem_euclid(2.0 * std::f64::consts::PI);
        let (sin, cos) = if x == 0.0 {
            (0.0, 1.0)
        } else if x == std::f64::consts::PI {
            (0.0, -1.0)
        } else {
            x.sin_cos()
        };
        Ok([s * cos, s * sin, self.mu1])
    }
}

/// The terms of the one-loop matter bispectrum in redshift space of one triangle and orientation
/// [(Mpc/h)⁶].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneLoopRedshift {
    /// The sides [h/Mpc].
    pub k: [f64; 3],
    /// The growth rate.
    pub f: f64,
    /// The orientation to the line of sight.
    pub orientation: Orientation,
    /// The tree level B₁₁₂ (exact).
    pub tree: Estimate,
    /// B₂₂₂.
    pub b222: Estimate,
    /// B₃₂₁ᴵ (the six ordered pairs).
    pub b321_i: Estimate,
    /// B₃₂₁ᴵᴵ (the six ordered pairs).
    pub b321_ii: Estimate,
    /// B₄₁₁ (the three legs).
    pub b411: Estimate,
}

impl OneLoopRedshift {
    /// The one-loop correction B₂₂₂ + B₃₂₁ᴵ + B₃₂₁ᴵᴵ + B₄₁₁ (errors added).
    pub fn loop_correction(&self) -> Estimate {
        self.b222 + self.b321_i + self.b321_ii + self.b411
    }

    /// Tree level plus the one-loop correction.
    pub fn total(&self) -> Estimate {
        self.tree + self.loop_correction()
    }
}

/// The one-loop matter bispectrum terms in redshift space of the triangle of sides `k` [h/Mpc] at
/// growth rate `f` and `orientation`, for the linear spectrum `p` (at its redshift), with `rule`;
/// every error is the difference from the rule with half the nodes.
///
/// # Errors
/// As [`triangle_vectors`] for sides that do not close; a bad rule; [`Error::InvalidParameter`] for
/// f outside [0, 2] and a bad orientation ([`Orientation::line_of_sight`]).
pub fn one_loop_matter_redshift(
    p: &LinearSpectrum,
    k: [f64; 3],
    f: f64,
    orientation: Orientation,
    rule: &OneLoopRule,
) -> Result<OneLoopRedshift> {
    rule.validate()?;
    crate::cosmology::check_growth_rate(f)?;
    let kv = triangle_vectors(k)?;
    let kernels = Kernels::Redshift {
        f,
        los: orientation.line_of_sight()?,
    };
    let pk = kv.map(|v| p.eval(norm(v)));
    let z1 = kv.map(|v| kernels.eval(&[v]));
    let z2 = |a: usize, b: usize| kernels.eval(&[kv[a], kv[b]]);
    let tree: f64 = [(0, 1), (1, 2), (2, 0)]
        .iter()
        .map(|&(a, b)| 2.0 * z2(a, b) * z1[a] * z1[b] * pk[a] * pk[b])
        .sum();
    let fine = loop_integrals(p, &kv, rule, &kernels);
    let coarse = loop_integrals(p, &kv, &rule.half(), &kernels);
    let estimate = |i: usize| Estimate::new(fine[i], (fine[i] - coarse[i]).abs());
    // B321ᴵᴵ from J_a = ∫ Z₃(k_a, q, −q) P(q) over the ordered pairs.
    let b321_ii = |j: &[f64; 6]| {
        let mut s = 0.0;
        for a in 0..3 {
            for b in (0..3).filter(|&b| b != a) {
                s += 6.0 * z2(a, b) * z1[b] * pk[a] * pk[b] * j[3 + a];
            }
        }
        s
    };
    let (ii_fine, ii_coarse) = (b321_ii(&fine), b321_ii(&coarse));
    Ok(OneLoopRedshift {
        k,
        f,
        orientation,
        tree: Estimate::exact(tree),
        b222: estimate(0),
        b321_i: estimate(1),
        b321_ii: Estimate::new(ii_fine, (ii_fine - ii_coarse).abs()),
        b411: estimate(2),
    })
}
