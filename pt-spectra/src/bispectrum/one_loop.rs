//! The one-loop matter bispectrum in real space (standard perturbation theory), by direct integrals:
//! the first part of issue 50 (the basis tensors, redshift space and bias come later).
//!
//! Units: k, q in h/Mpc, P in (Mpc/h)³, B in (Mpc/h)⁶; ∫_q = ∫d³q/(2π)³. For sides k₁ + k₂ + k₃ = 0
//! (Scoccimarro 1997, arXiv:astro-ph/9612207; Sefusatti et al. 2010, arXiv:0909.1532, eqs. 17–21):
//!
//! ```text
//! B₁₁₂   = 2 F₂(k₁, k₂) P₁ P₂ + 2 cyclic,
//! B₂₂₂   = 8 ∫_q F₂(−q, q + k₁) F₂(−q − k₁, q − k₂) F₂(k₂ − q, q) P(q) P(|q + k₁|) P(|k₂ − q|),
//! B₃₂₁ᴵ  = 6 P(k_a) ∫_q F₃(−q, q − k_b, −k_a) F₂(q, k_b − q) P(q) P(|k_b − q|)  over the 6 ordered pairs a ≠ b,
//! B₃₂₁ᴵᴵ = 6 F₂(k_a, k_b) P(k_a) P(k_b) ∫_q F₃(k_a, q, −q) P(q)           over the 6 ordered pairs
//!        = F₂(k_a, k_b) P(k_b) P₁₃(k_a),
//! B₄₁₁   = 12 P(k_b) P(k_c) ∫_q F₄(q, −q, −k_b, −k_c) P(q)                 + 2 cyclic,
//! ```
//!
//! with the symmetrised kernels of `pt_kernels` (exact generated code, F₄ included), and the EFT
//! counterterms of [`COUNTERTERMS`] (four shapes whose coefficients the user fits).
//!
//! **Numerics.** Each integrand is non-smooth only where the argument of one of its spectra vanishes
//! (P(r) ∝ r^{n_s} at small r): q = 0, q = −k₁, q = k₂ for B₂₂₂, q = 0 and q = k_b for B₃₂₁ᴵ, q = 0
//! for the others. A smooth partition of unity w_j = r_j^{−a} / Σ_m r_m^{−a} (r_j the distance to the
//! j-th such point, a = [`PARTITION_POWER`]) splits B₂₂₂ into three pieces, each integrated in
//! spherical coordinates about its own point (the other points' cusps are multiplied by r^a); B₃₂₁ᴵ
//! is symmetric under q ↔ k_b − q, so it is twice its piece about q = 0. Each piece: Gauss–Legendre in
//! ln q on panels broken at every side and half side over [q_min, q_max], Gauss–Legendre in cos θ
//! (θ from k₁), the midpoint rule in φ ∈ [0, π] (the triangle lies in the x–z plane: the integrands
//! are even in φ and periodic). The error of every term is its difference from the rule with half as
//! many nodes in each dimension (so it bounds, rather than estimates, the error of the finer rule
//! while that converges).
//!
//! The loop terms are individually infrared sensitive (their sum is not) and cut at q_min, q_max: the
//! integrals over [q_min, q_max] are what is computed (stated in [`OneLoopRule`]), with the same
//! cut in the independent Monte Carlo reference of the tests.

use super::TriangleSet;
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::integrate::legendre_nodes;
use crate::linear::LinearSpectrum;
use crate::vec3::{add, neg, norm, sub};
use rayon::prelude::*;
use std::f64::consts::PI;

/// The power a of the partition of unity w_j = r_j^{−a} / Σ_m r_m^{−a} (module docs): the cusps
/// r^{n_s} of the other pieces become r^{n_s + a}, smooth enough for the Gauss rules.
pub const PARTITION_POWER: i32 = 6;

/// The quadrature of the loop integrals: `radial` Gauss–Legendre nodes per ln q panel, `mu` in
/// cos θ, `phi` midpoints in φ ∈ [0, π], over q_min ≤ |q − centre| ≤ q_max [h/Mpc].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneLoopRule {
    /// Nodes per ln q panel.
    pub radial: usize,
    /// Nodes in cos θ.
    pub mu: usize,
    /// Nodes in φ ∈ [0, π].
    pub phi: usize,
    /// The infrared cut [h/Mpc].
    pub q_min: f64,
    /// The ultraviolet cut [h/Mpc].
    pub q_max: f64,
}

impl Default for OneLoopRule {
    /// 12 × 32 × 24 nodes per panel and piece, q from 1e-4 to 10 h/Mpc.
    fn default() -> Self {
        Self {
            radial: 12,
            mu: 32,
            phi: 24,
            q_min: 1e-4,
            q_max: 10.0,
        }
    }
}

impl OneLoopRule {
    /// Checks the rule: at least 2 nodes in each direction and 0 < q_min < q_max.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] naming what is wrong.
    pub fn validate(&self) -> Result<()> {
        if self.radial < 2 || self.mu < 2 || self.phi < 2 {
            return Err(Error::InvalidChoice {
                what: format!(
                    "a one-loop bispectrum rule of {} x {} x {} nodes",
                    self.radial, self.mu, self.phi
                ),
                reason: "every dimension needs at least 2 nodes (the error compares with half)"
                    .into(),
            });
        }
        if !(self.q_min > 0.0 && self.q_max > self.q_min && self.q_max.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "q_min, q_max [h/Mpc]",
                value: self.q_min,
                reason: "need 0 < q_min < q_max < infinity",
            });
        }
        Ok(())
    }

    /// The rule with half as many nodes in each dimension (the error's comparison).
    pub(super) fn half(&self) -> Self {
        Self {
            radial: (self.radial / 2).max(1),
            mu: (self.mu / 2).max(1),
            phi: (self.phi / 2).max(1),
            ..*self
        }
    }
}

/// The terms of the one-loop matter bispectrum of one triangle [(Mpc/h)⁶] (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneLoopMatter {
    /// The sides [h/Mpc].
    pub k: [f64; 3],
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
    /// The four counterterm shapes [(Mpc/h)⁴] of [`COUNTERTERMS`] (exact), which multiply coefficients
    /// in (Mpc/h)².
    pub counterterm_shapes: [f64; 4],
}

/// The names of the counterterm coefficients [(Mpc/h)²] of the one-loop matter bispectrum, in the
/// order of [`OneLoopMatter::counterterm_shapes`]:
///
/// ```text
/// B_ct = Σ_cyc 2 P(k_i) P(k_j) [ ct_f2 F₂(k_i, k_j)(k_i² + k_j²) + ct_k3 k_l² + ct_tidal k_l² (μ_ij² − 1/3)
///                                + ct_f2k3 F₂(k_i, k_j) k_l² ],
/// ```
///
/// l the third side, μ_ij the cosine between k_i and k_j: the first-order counterterm −c_s²k²δ in the
/// legs of the tree (ct_f2) and the k² operators of second order, ∇²δ², ∇²s², ∇²δ⁽²⁾ (Baldauf, Mercolli,
/// Mirbabayi & Pajer 2015, arXiv:1406.4135; Angulo et al. 2015, arXiv:1406.4143: four independent
/// operators in an Einstein–de Sitter-like growth). These four shapes absorb the change of the loop
/// cut-off: moving q_max from 1 to 10 h/Mpc changes B by up to 2.4e6 (Mpc/h)⁶ and the least-squares
/// combination of the shapes takes it out to 0.36% over 16 triangles (`tests/tests/suite/bispectrum_one_loop.rs`).
/// The B₃₂₁ᴵᴵ part of ct_f2 is −c_s² of the power spectrum's P_ct = −2c_s²k²P; B₄₁₁ adds its own, so ct_f2
/// is not fixed by the power spectrum alone.
pub const COUNTERTERMS: [&str; 4] = ["ct_f2", "ct_k3", "ct_tidal", "ct_f2k3"];

impl OneLoopMatter {
    /// The one-loop correction B₂₂₂ + B₃₂₁ᴵ + B₃₂₁ᴵᴵ + B₄₁₁ (errors added).
    pub fn loop_correction(&self) -> Estimate {
        self.b222 + self.b321_i + self.b321_ii + self.b411
    }

    /// Tree level plus the one-loop correction.
    pub fn total(&self) -> Estimate {
        self.tree + self.loop_correction()
    }

    /// The counterterms of coefficients `c` [(Mpc/h)²] (order of [`COUNTERTERMS`]) [(Mpc/h)⁶].
    pub fn counterterms(&self, c: &[f64; 4]) -> f64 {
        self.counterterm_shapes
            .iter()
            .zip(c)
            .map(|(s, c)| s * c)
            .sum()
    }
}

pub(super) type Vec3 = [f64; 3];

/// F_n^s of the vectors; 0 where a vector is zero (a node never is: the rules avoid the centres).
pub(super) fn f_n(q: &[Vec3]) -> f64 {
    pt_kernels::kernels(q).map_or(0.0, |[f, _]| f)
}

/// The sides as vectors: k₁ along z, k₂ in the x–z plane, k₃ = −k₁ − k₂.
///
/// # Errors
/// As [`TriangleSet::points`] (the one check of sides): a side that is not finite and > 0, or sides
/// that do not close.
pub fn triangle_vectors(k: [f64; 3]) -> Result<[Vec3; 3]> {
    TriangleSet::points(vec![k])?;
    let [k1, k2, k3] = k;
    let cos12 = (k3 * k3 - k1 * k1 - k2 * k2) / (2.0 * k1 * k2);
    let c = cos12.clamp(-1.0, 1.0);
    let s = (1.0 - c * c).sqrt();
    let v1 = [0.0, 0.0, k1];
    let v2 = [k2 * s, 0.0, k2 * c];
    Ok([v1, v2, neg(add(v1, v2))])
}

/// The radial nodes (q, weight) of one piece's rule: Gauss–Legendre in ln q on panels of at most a
/// factor 3 in q, broken at `breaks` inside [q_min, q_max]; the weight includes q³ (q² dq = q³ d ln q).
pub(super) fn radial_nodes(rule: &OneLoopRule, breaks: &[f64]) -> Vec<(f64, f64)> {
    let mut edges: Vec<f64> = breaks
        .iter()
        .copied()
        .filter(|b| *b > rule.q_min && *b < rule.q_max)
        .chain([rule.q_min, rule.q_max])
        .map(f64::ln)
        .collect();
    edges.sort_by(f64::total_cmp);
    let (xr, wr) = legendre_nodes(rule.radial);
    let mut out = Vec::new();
    for w in edges.windows(2) {
        let n = ((w[1] - w[0]) / 3f64.ln()).ceil().max(1.0) as usize;
        let h = (w[1] - w[0]) / n as f64;
        for i in 0..n {
            let (a, half) = (w[0] + i as f64 * h, 0.5 * h);
            for (x, wx) in xr.iter().zip(&wr) {
                let q = (a + half * (x + 1.0)).exp();
                out.push((q, wx * half * q.powi(3)));
            }
        }
    }
    out
}

/// The angular nodes (unit vector, weight) of one piece's rule: Gauss–Legendre in cos θ, midpoints
/// in φ ∈ [0, π] (counted twice) if the integrands are even in φ (`mirror`: the triangle's plane is a
/// mirror of the integrand, as in real space), else `2 phi` midpoints in φ ∈ [0, 2π); the weights
/// include 1/(2π)³.
pub(super) fn angular_nodes(rule: &OneLoopRule, mirror: bool) -> Vec<(Vec3, f64)> {
    let (xm, wm) = legendre_nodes(rule.mu);
    let (n_phi, copies) = if mirror {
        (rule.phi, 2.0)
    } else {
        (2 * rule.phi, 1.0)
    };
    let dphi = PI / rule.phi as f64;
    let norm = copies / (2.0 * PI).powi(3);
    let mut out = Vec::with_capacity(rule.mu * n_phi);
    for (mu, wmu) in xm.iter().zip(&wm) {
        let s = (1.0 - mu * mu).sqrt();
        for j in 0..n_phi {
            let phi = (j as f64 + 0.5) * dphi;
            out.push(([s * phi.cos(), s * phi.sin(), *mu], norm * wmu * dphi));
        }
    }
    out
}

/// The panel breaks of a triangle: every side, half side and double side.
pub(super) fn breaks(k: &[f64; 3]) -> Vec<f64> {
    let mut b: Vec<f64> = k.iter().flat_map(|&v| [v, 0.5 * v, 2.0 * v]).collect();
    b.sort_by(f64::total_cmp);
    b
}

/// The nodes q and weights of one piece's rule (weights include q² dq dΩ/(2π)³ and the φ symmetry):
/// the product of [`radial_nodes`] and [`angular_nodes`].
pub(super) fn nodes(rule: &OneLoopRule, breaks: &[f64], mirror: bool) -> Vec<(Vec3, f64)> {
    let angular = angular_nodes(rule, mirror);
    radial_nodes(rule, breaks)
        .into_iter()
        .flat_map(|(q, wq)| angular.iter().map(move |&(u, wu)| (scale(u, q), wq * wu)))
        .collect()
}

fn scale(u: Vec3, q: f64) -> Vec3 {
    u.map(|x| x * q)
}

/// The partition weight of the point at distance `r[j]` among the distances `r`.
pub(super) fn partition(r: &[f64], j: usize) -> f64 {
    let rj = r[j];
    1.0 / r
        .iter()
        .map(|&rm| (rj / rm).powi(PARTITION_POWER))
        .sum::<f64>()
}

/// The kernels of the loop terms: F_n in real space (1 on a linear leg), or Z_n(f, n̂) of the
/// redshift-space mapping ([`pt_kernels::redshift`]; Z₁ = 1 + fμ² on a linear leg).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Kernels {
    /// F_n.
    Real,
    /// Z_n at growth rate `f` and line of sight `los` (a unit vector in the triangle's frame).
    Redshift {
        /// The growth rate.
        f: f64,
        /// The line of sight.
        los: Vec3,
    },
    /// The galaxy kernels of [`super::bias_kernels`] with the coefficients `bias` (order of
    /// [`super::bias_kernels::LoopBias::NAMES`]): K_n in real space (`redshift` None, K₁ = b1 on a
    /// linear leg), Z_n^g at (f, line of sight) in redshift space.
    Galaxy {
        /// The bias coefficients.
        bias: [f64; super::bias_kernels::N_BIAS],
        /// (f, line of sight) in redshift space.
        redshift: Option<(f64, Vec3)>,
    },
}

impl Kernels {
    /// The kernel of order `q.len()` at the vectors `q` (0 where a vector is zero).
    pub(super) fn eval(&self, q: &[Vec3]) -> f64 {
        match *self {
            Kernels::Real if q.len() == 1 => 1.0,
            Kernels::Real => f_n(q),
            Kernels::Redshift { f, los } => {
                pt_kernels::redshift::redshift_kernel(q, &f, &los).unwrap_or(0.0)
            }
            Kernels::Galaxy { bias, redshift } => {
                super::bias_kernels::loop_kernel(&bias, redshift, q)
            }
        }
    }

    /// Whether the triangle's plane (x–z) is a mirror of the integrands: in real space, and in
    /// redshift space for a line of sight in that plane.
    pub(super) fn mirror(&self) -> bool {
        match *self {
            Kernels::Real => true,
            Kernels::Redshift { los, .. } => los[1] == 0.0,
            Kernels::Galaxy { redshift, .. } => redshift.is_none_or(|(_, los)| los[1] == 0.0),
        }
    }
}

/// The loop terms [b222, b321_i, b411, J_a (3)] on one rule, with `kernels` (module docs; in redshift
/// space with Z₁ on the linear legs of B₃₂₁ᴵ and B₄₁₁).
pub(super) fn loop_integrals(
    p: &LinearSpectrum,
    kv: &[Vec3; 3],
    rule: &OneLoopRule,
    kernels: &Kernels,
) -> [f64; 6] {
    let k = kv.map(norm);
    let pk = k.map(|v| p.eval(v));
    let z1 = kv.map(|v| kernels.eval(&[v]));
    let z = |q: &[Vec3]| kernels.eval(q);
    let grid = nodes(rule, &breaks(&k), kernels.mirror());
    let (k1, k2) = (kv[0], kv[1]);
    grid.par_iter()
        .map(|&(v, w)| {
            let mut out = [0.0; 6];
            // B222: the pieces about q = 0, q = −k₁, q = k₂ (partition weights w_j).
            let b222 = |q: Vec3, j: usize| {
                let (a, b) = (add(q, k1), sub(k2, q));
                let r = [norm(q), norm(a), norm(b)];
                let kern = z(&[neg(q), a]) * z(&[neg(a), neg(b)]) * z(&[b, q]);
                8.0 * partition(&r, j) * kern * p.eval(r[0]) * p.eval(r[1]) * p.eval(r[2])
            };
            out[0] = b222(v, 0) + b222(sub(v, k1), 1) + b222(sub(k2, v), 2);
            // B321ᴵ: ordered pairs (a outer, b in the loop), twice the piece about q = 0; the loop
            // leg's F₂, spectra and partition weight depend on b only.
            let pq = p.eval(norm(v));
            for b in 0..3 {
                let d = sub(kv[b], v);
                let r = [norm(v), norm(d)];
                let leg = 2.0 * 6.0 * partition(&r, 0) * z(&[v, d]) * pq * p.eval(r[1]);
                for a in (0..3).filter(|&a| a != b) {
                    out[1] += leg * z1[a] * pk[a] * z(&[neg(v), neg(d), neg(kv[a])]);
                }
            }
            // B411 and the P13-type integrals J_a = ∫ F₃(k_a, q, −q) P(q).
            for a in 0..3 {
                let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                let kern = z(&[v, neg(v), neg(kv[b]), neg(kv[c])]);
                out[2] += 12.0 * z1[b] * z1[c] * pk[b] * pk[c] * kern * pq;
                out[3 + a] = z(&[kv[a], v, neg(v)]) * pq;
            }
            out.map(|x| x * w)
        })
        .reduce(|| [0.0; 6], |a, b| std::array::from_fn(|i| a[i] + b[i]))
}

/// The tree level B₁₁₂ and the four counterterm shapes of [`COUNTERTERMS`] of the triangle `kv` with
/// the spectrum `pk` at its sides.
pub(super) fn tree_and_counterterms(kv: &[Vec3; 3], pk: &[f64; 3]) -> (f64, [f64; 4]) {
    let k = kv.map(norm);
    let f2 = |a: usize, b: usize| f_n(&[kv[a], kv[b]]);
    let tree =
        2.0 * (f2(0, 1) * pk[0] * pk[1] + f2(1, 2) * pk[1] * pk[2] + f2(2, 0) * pk[2] * pk[0]);
    let mut shapes = [0.0; 4];
    for i in 0..3 {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        let pp = 2.0 * pk[i] * pk[j];
        let mu = (k[l] * k[l] - k[i] * k[i] - k[j] * k[j]) / (2.0 * k[i] * k[j]);
        let (f, kl2, kij2) = (f2(i, j), k[l] * k[l], k[i] * k[i] + k[j] * k[j]);
        shapes[0] += pp * f * kij2;
        shapes[1] += pp * kl2;
        shapes[2] += pp * kl2 * (mu * mu - 1.0 / 3.0);
        shapes[3] += pp * f * kl2;
    }
    (tree, shapes)
}

/// The one-loop matter bispectrum terms of the triangle of sides `k` [h/Mpc] of the linear spectrum
/// `p` (at the redshift of `p`: the terms scale as D⁴ and D⁶ of the tree), with `rule`.
///
/// # Errors
/// As [`triangle_vectors`] for sides that do not close; [`Error::InvalidChoice`] for a bad rule.
pub fn one_loop_matter(
    p: &LinearSpectrum,
    k: [f64; 3],
    rule: &OneLoopRule,
) -> Result<OneLoopMatter> {
    rule.validate()?;
    let kv = triangle_vectors(k)?;
    let pk = k.map(|v| p.eval(v));
    let f2 = |a: usize, b: usize| f_n(&[kv[a], kv[b]]);
    let (tree, counterterm_shapes) = tree_and_counterterms(&kv, &pk);
    let fine = loop_integrals(p, &kv, rule, &Kernels::Real);
    let coarse = loop_integrals(p, &kv, &rule.half(), &Kernels::Real);
    let estimate = |i: usize| Estimate::new(fine[i], (fine[i] - coarse[i]).abs());
    // B321ᴵᴵ from J_a: 6 F₂(k_a, k_b) P(k_a) P(k_b) J_a over the ordered pairs.
    let b321_ii = |j: &[f64; 6]| {
        let mut s = 0.0;
        for a in 0..3 {
            for b in (0..3).filter(|&b| b != a) {
                s += 6.0 * f2(a, b) * pk[a] * pk[b] * j[3 + a];
            }
        }
        s
    };
    let (ii_fine, ii_coarse) = (b321_ii(&fine), b321_ii(&coarse));
    Ok(OneLoopMatter {
        k,
        tree: Estimate::exact(tree),
        b222: estimate(0),
        b321_i: estimate(1),
        b321_ii: Estimate::new(ii_fine, (ii_fine - ii_coarse).abs()),
        b411: estimate(2),
        counterterm_shapes,
    })
}
