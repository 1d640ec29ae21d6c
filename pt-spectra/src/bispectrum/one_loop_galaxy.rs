//! The one-loop GALAXY bispectrum (biased tracers), real space and redshift space at one orientation, by
//! direct integrals: the terms of [`super::one_loop`] and [`super::one_loop_rsd`] with the galaxy kernels
//! K_n (real space) or Z_n^g (redshift space) of [`super::bias_kernels`] (the bias basis of Eggemeier,
//! Scoccimarro & Smith 2019, [`LoopBias`], with G₂(φ₂, φ₁) and G₂(φ₃, φ₁) in the Lagrangian convention, in
//! which it holds Γ₃ and δ − θ at fourth order) in place of F_n or Z_n, and K₁ = b1 (Z₁ = b1 + fμ²) on every
//! linear leg; the same quadrature, partition of unity and error estimates:
//!
//! ```text
//! B₁₁₂   = Σ_{a<b} 2 K₂(k_a, k_b) K₁(k_a) K₁(k_b) P_a P_b,
//! B₂₂₂   = 8 ∫_q K₂(−q, q + k₁) K₂(−q − k₁, q − k₂) K₂(k₂ − q, q) P(q) P(|q + k₁|) P(|k₂ − q|),
//! B₃₂₁ᴵ  = Σ_{a≠b} 6 K₁(k_a) P_a ∫_q K₃(−q, q − k_b, −k_a) K₂(q, k_b − q) P(q) P(|k_b − q|),
//! B₃₂₁ᴵᴵ = Σ_{a≠b} 6 K₂(k_a, k_b) K₁(k_b) P_a P_b ∫_q [K₃(k_a, q, −q) − c₃(k_a)] P(q),
//! B₄₁₁   = Σ_a 12 K₁(k_b) K₁(k_c) P_b P_c ∫_q [K₄(q, −q, −k_b, −k_c) − c₄(k_b, k_c)] P(q),
//! ```
//!
//! (K → Z^g in redshift space). **Renormalisation.** The bias operators' kernels tend to constants as
//! q → ∞: c₃(k) = lim ⟨K₃(k, q, −q)⟩_q̂ and c₄ = lim ⟨K₄(q, −q, −k_b, −k_c)⟩_q̂ (angular averages over the
//! direction of q; in redshift space they depend on the orientation). Their integrals c σ², σ² = ∫_q P(q)
//! over the rule's [q_min, q_max], are the k → 0 limits of the loops, which renormalise b1 (B₃₂₁ᴵᴵ) and b2,
//! g2 (B₄₁₁) (Assassi et al. 2014, arXiv:1402.5916; ESS19; Philcox et al. 2022): they are subtracted, so the
//! coefficients are the renormalised ones, and the terms no longer depend on the cut through σ². The
//! subtracted amounts are [`OneLoopGalaxy::uv_b321_ii`], [`OneLoopGalaxy::uv_b411`] (bare = renormalised +
//! them). Only the bias operators' limits are subtracted: b1's part of the kernels (the matter's structure)
//! tends to zero like k²/q², so matter (b1 = 1, the others 0) is exactly [`super::one_loop`]'s. c₃, c₄ are
//! computed from the kernels on the angular rule at q = 10³ and 2 × 10³ times the largest side, with the 1/q²
//! term extrapolated away (Richardson). Not subtracted: the q → ∞ constants of B₂₂₂ and B₃₂₁ᴵ (∝ ∫P², ∫P³
//! times b2², …), which have the shapes of the stochastic terms (1/n̄² and P(k_a)/n̄) and renormalise them.
//!
//! The terms per bias monomial (every term a polynomial of degree 3 in the coefficients, computed in one pass
//! and evaluated for a new bias in microseconds): [`super::one_loop_galaxy_poly`], equal to these to
//! round-off. Elsewhere: the counterterms and stochastic terms ([`super::galaxy_counterterms`],
//! [`super::galaxy_counterterms_rsd`]), the multipoles ([`super::one_loop_galaxy_multipoles`]), the real-space
//! basis tensors ([`super::one_loop_galaxy_basis`]), the infrared resummation of the BAO
//! ([`super::one_loop_ir`]). Not yet (issue 50): bins, basis tensors in redshift space.

use super::bias_kernels::{loop_kernel_parts, LoopBias, N_PARTS};
use super::ir_legs::{leading_order_spectrum, tree_legs};
use super::one_loop::{
    angular_nodes, breaks, loop_integrals, radial_nodes, triangle_vectors, Kernels, OneLoopRule,
    Vec3,
};
use super::one_loop_rsd::Orientation;
use super::resum::IrInputs;
use crate::error::Result;
use crate::estimate::Estimate;
use crate::linear::LinearSpectrum;
use crate::vec3::{neg, norm};

/// The terms of the one-loop galaxy bispectrum of one triangle [(Mpc/h)⁶] (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneLoopGalaxy {
    /// The sides [h/Mpc].
    pub k: [f64; 3],
    /// The bias coefficients.
    pub bias: LoopBias,
    /// (f, orientation) in redshift space; None in real space.
    pub redshift: Option<(f64, Orientation)>,
    /// The tree level B₁₁₂ (exact).
    pub tree: Estimate,
    /// B₂₂₂.
    pub b222: Estimate,
    /// B₃₂₁ᴵ.
    pub b321_i: Estimate,
    /// B₃₂₁ᴵᴵ, renormalised (c₃σ² subtracted).
    pub b321_ii: Estimate,
    /// B₄₁₁, renormalised (c₄σ² subtracted).
    pub b411: Estimate,
    /// The amount subtracted from the bare B₃₂₁ᴵᴵ.
    pub uv_b321_ii: f64,
    /// The amount subtracted from the bare B₄₁₁.
    pub uv_b411: f64,
}

impl OneLoopGalaxy {
    /// The one-loop correction B₂₂₂ + B₃₂₁ᴵ + B₃₂₁ᴵᴵ + B₄₁₁ (renormalised; errors added).
    pub fn loop_correction(&self) -> Estimate {
        self.b222 + self.b321_i + self.b321_ii + self.b411
    }

    /// Tree level plus the one-loop correction.
    pub fn total(&self) -> Estimate {
        self.tree + self.loop_correction()
    }

    /// The bare B₃₂₁ᴵᴵ (nothing subtracted, at the rule's cut).
    pub fn bare_b321_ii(&self) -> Estimate {
        Estimate::new(self.b321_ii.value + self.uv_b321_ii, self.b321_ii.error)
    }

    /// The bare B₄₁₁ (nothing subtracted, at the rule's cut).
    pub fn bare_b411(&self) -> Estimate {
        Estimate::new(self.b411.value + self.uv_b411, self.b411.error)
    }
}

/// σ² = ∫_q P(q) on the radial and angular nodes of the loop terms about q = 0.
pub(super) fn sigma2(p: &LinearSpectrum, k: &[f64; 3], rule: &OneLoopRule, mirror: bool) -> f64 {
    let angular: f64 = angular_nodes(rule, mirror).iter().map(|(_, w)| w).sum();
    let radial: f64 = radial_nodes(rule, &breaks(k))
        .iter()
        .map(|&(q, w)| w * p.eval(q))
        .sum();
    radial * angular
}

/// The UV constants [c₃(k_a); 3] and [c₄(k_b, k_c); 3] of the bias operators (module docs): the
/// parts' ([`uv_parts`]) at the coefficients `bias`.
fn uv_constants(
    bias: &LoopBias,
    redshift: Option<(f64, Vec3)>,
    kv: &[Vec3; 3],
    rule: &OneLoopRule,
) -> ([f64; 3], [f64; 3]) {
    let mirror = redshift.is_none_or(|(_, los)| los[1] == 0.0);
    let (c3, c4) = uv_parts(redshift, kv, rule, mirror);
    let mut x = [1.0; N_PARTS];
    x[1..].copy_from_slice(&bias.values());
    let at = |c: &[f64; N_PARTS]| c.iter().zip(&x).map(|(c, x)| c * x).sum::<f64>();
    (c3.map(|c| at(&c)), c4.map(|c| at(&c)))
}

/// c₃(k_a)[p] and c₄(k_b, k_c)[p] of [`uv_parts`].
pub(super) type UvParts = ([[f64; N_PARTS]; 3], [[f64; N_PARTS]; 3]);

/// The UV constants per part, c₃(k_a)[p] and c₄(k_b, k_c)[p], of the bias operators' parts (p ≥ 2; zero for
/// the constant and b1), each the angular average at q = 10³ and 2 × 10³ times the largest side, the 1/q² term extrapolated away.
pub(super) fn uv_parts(
    redshift: Option<(f64, Vec3)>,
    kv: &[Vec3; 3],
    rule: &OneLoopRule,
    mirror: bool,
) -> UvParts {
    let angular = angular_nodes(rule, mirror);
    let total: f64 = angular.iter().map(|(_, w)| w).sum();
    let k_max = kv.iter().map(|v| norm(*v)).fold(0.0, f64::max);
    let average = |big: f64, args: &dyn Fn(Vec3) -> Vec<Vec3>| {
        let mut s = [0.0; N_PARTS];
        for &(u, w) in &angular {
            let parts = loop_kernel_parts(redshift, &args(u.map(|x| x * big)));
            for (s, x) in s.iter_mut().zip(parts).skip(2) {
                *s += w * x;
            }
        }
        s.map(|x| x / total)
    };
    let limit = |args: &dyn Fn(Vec3) -> Vec<Vec3>| {
        let (a, b) = (average(1e3 * k_max, args), average(2e3 * k_max, args));
        std::array::from_fn(|p| (4.0 * b[p] - a[p]) / 3.0)
    };
    let mut c3 = [[0.0; N_PARTS]; 3];
    let mut c4 = [[0.0; N_PARTS]; 3];
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        c3[a] = limit(&|q| vec![kv[a], q, neg(q)]);
        c4[a] = limit(&|q| vec![q, neg(q), neg(kv[b]), neg(kv[c])]);
    }
    (c3, c4)
}

/// The one-loop galaxy bispectrum terms of the triangle of sides `k` [h/Mpc] with the bias `bias`, in real
/// space (`redshift` None) or in redshift space at growth rate f and an orientation, for the linear
/// spectrum `p` (at its redshift), with `rule`; every error is the difference from the rule with half the
/// nodes.
///
/// # Errors
/// As [`triangle_vectors`] for sides that do not close; a bad rule; [`crate::error::Error::InvalidParameter`] for a bias
/// coefficient that is not finite, f outside [0, 2] or a bad orientation.
pub fn one_loop_galaxy(
    p: &LinearSpectrum,
    k: [f64; 3],
    bias: &LoopBias,
    redshift: Option<(f64, Orientation)>,
    rule: &OneLoopRule,
) -> Result<OneLoopGalaxy> {
    galaxy_terms(p, None, k, bias, redshift, rule)
}

/// [`one_loop_galaxy`] without (`ir` None) or with the infrared resummation of
/// [`super::one_loop_ir`]: the loops on P_LO, the tree level's legs P_NLO.
pub(super) fn galaxy_terms(
    p: &LinearSpectrum,
    ir: Option<&IrInputs>,
    k: [f64; 3],
    bias: &LoopBias,
    redshift: Option<(f64, Orientation)>,
    rule: &OneLoopRule,
) -> Result<OneLoopGalaxy> {
    rule.validate()?;
    bias.check_finite()?;
    let kv = triangle_vectors(k)?;
    let rsd = redshift.map(Orientation::checked_with).transpose()?;
    let kernels = Kernels::Galaxy {
        bias: bias.values(),
        redshift: rsd,
    };
    let resummed = ir.map(|ir| leading_order_spectrum(p, ir)).transpose()?;
    let (tree_pk, p) = match (ir, &resummed) {
        (Some(ir), Some(lo)) => (Some(tree_legs(p, ir, &kv, rsd)), lo),
        _ => (None, p),
    };
    let pk = kv.map(|v| p.eval(norm(v)));
    let pk_tree = tree_pk.unwrap_or(pk);
    let z1 = kv.map(|v| kernels.eval(&[v]));
    let z2 = |a: usize, b: usize| kernels.eval(&[kv[a], kv[b]]);
    let tree: f64 = [(0, 1), (1, 2), (2, 0)]
        .iter()
        .map(|&(a, b)| 2.0 * z2(a, b) * z1[a] * z1[b] * pk_tree[a] * pk_tree[b])
        .sum();
    let (c3, c4) = uv_constants(bias, rsd, &kv, rule);
    let mirror = kernels.mirror();
    let half = rule.half();
    let fine = loop_integrals(p, &kv, rule, &kernels);
    let coarse = loop_integrals(p, &kv, &half, &kernels);
    let (s_fine, s_coarse) = (sigma2(p, &k, rule, mirror), sigma2(p, &k, &half, mirror));
    // B321ᴵᴵ's sum over ordered pairs of J_a (or c₃(k_a)), B411's UV part from c₄.
    let pairs = |j: &dyn Fn(usize) -> f64| {
        let mut s = 0.0;
        for a in 0..3 {
            for b in (0..3).filter(|&b| b != a) {
                s += 6.0 * z2(a, b) * z1[b] * pk[a] * pk[b] * j(a);
            }
        }
        s
    };
    let legs: f64 = (0..3)
        .map(|a| {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            12.0 * z1[b] * z1[c] * pk[b] * pk[c] * c4[a]
        })
        .sum();
    let uv_ii = |s2: f64| pairs(&|a| c3[a]) * s2;
    let ii_fine = pairs(&|a| fine[3 + a]) - uv_ii(s_fine);
    let ii_coarse = pairs(&|a| coarse[3 + a]) - uv_ii(s_coarse);
    let b411_fine = fine[2] - legs * s_fine;
    let b411_coarse = coarse[2] - legs * s_coarse;
    let estimate = |i: usize| Estimate::new(fine[i], (fine[i] - coarse[i]).abs());
    Ok(OneLoopGalaxy {
        k,
        bias: *bias,
        redshift,
        tree: Estimate::exact(tree),
        b222: estimate(0),
        b321_i: estimate(1),
        b321_ii: Estimate::new(ii_fine, (ii_fine - ii_coarse).abs()),
        b411: Estimate::new(b411_fine, (b411_fine - b411_coarse).abs()),
        uv_b321_ii: uv_ii(s_fine),
        uv_b411: legs * s_fine,
    })
}
